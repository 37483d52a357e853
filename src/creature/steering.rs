//! Steer: each creature's desired planar velocity (paper section 3: the creatures "attempt
//! to avoid the puck, the walls, and other creatures").
//!
//! The sum of four urges, scaled by the weights in the creature file and clipped to the top
//! speed: wander at cruise speed, flee the puck's predicted path, keep off the walls, keep
//! apart from neighbours. Runs at the decision rate (`decision_hz`), like the paper's
//! higher-level behaviours that run once per frame.

use bevy::prelude::*;

use super::{Creature, DesiredVelocity, KindParams, KindTable, PlanarState, PlayerControlled};
use crate::config::SimConfig;
use crate::contract::{DENSE, SimClock, SimStage, chunk_len, run_chunks};
use crate::sense::NeighbourGrid;
use crate::sense::{Court, PuckState};

/// A deterministic random number in `[-1, 1]` for one creature at one decision: a
/// counter-based stream keyed by the world seed, so parallel steering stays reproducible.
fn wander_noise(seed: u64, serial: u32, decision: u64) -> f32 {
    let mut z = seed ^ (u64::from(serial) << 32) ^ decision.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    // splitmix64 finaliser
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 23) as f32 - 1.0
}

/// The point of the segment `a..b` nearest to `p`.
fn nearest_on_segment(p: Vec2, a: Vec2, b: Vec2) -> Vec2 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 <= f32::EPSILON {
        return a;
    }
    a + ab * ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
}

/// Everything steering reads besides the creature itself.
pub struct Surroundings<'a> {
    /// The puck now.
    pub puck: &'a PuckState,
    /// The court's walls.
    pub court: &'a Court,
    /// The creatures nearby.
    pub grid: &'a NeighbourGrid,
    /// The world's seed: each creature's wandering is drawn from it, its serial and the decision.
    pub seed: u64,
    /// Index of this steering decision.
    pub decision: u64,
    /// Seconds between decisions.
    pub decision_dt: f32,
}

/// How far from a creature, at its last decision, no other creature's centre was: what steering
/// saw of its neighbours as it kept apart from them, looking as far as its separation distance
/// (0 where it did not look). The contact check between creatures need not search again
/// where this is wider than any contact the creature could make before it is checked.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct Clearance {
    /// Metres between the creature's centre and the nearest other centre, or how far it looked.
    pub clear_m: f32,
}

/// The velocity a creature wants, given where it is and what is around it; and its
/// [`Clearance`] there.
pub fn desired_velocity(
    creature: &Creature,
    state: &PlanarState,
    kind: &KindParams,
    around: &Surroundings,
) -> (Vec2, Clearance) {
    let s = &kind.steering;
    let p = state.position;
    let top = kind.top_speed_m_per_s;

    // Wander: keep going the way it faces, drifting a little.
    let turn =
        wander_noise(around.seed, creature.serial, around.decision) * s.wander_turn_rad_per_s * around.decision_dt;
    let mut desired = Vec2::from_angle(turn).rotate(state.heading) * s.cruise_speed_m_per_s;

    // Flee the puck: away from the nearest point of its path over the look-ahead, harder
    // the closer. Dodging sideways out of its path beats outrunning it.
    let puck = around.puck;
    let path_end = puck.position + puck.velocity * s.puck_lookahead_s;
    let from_path = p - nearest_on_segment(p, puck.position, path_end);
    let gap = from_path.length() - puck.radius_m - kind.radius_m;
    if s.puck_alert_distance_m > 0.0 && gap < s.puck_alert_distance_m {
        let urgency = (1.0 - gap / s.puck_alert_distance_m).clamp(0.0, 1.0);
        let away = from_path
            .try_normalize()
            .unwrap_or_else(|| puck.velocity.perp().normalize_or(Vec2::X));
        desired += away * (top * s.puck_weight * urgency);
    }

    // Keep apart from neighbours.
    let mut clear_m = s.separation_distance_m;
    if s.separation_distance_m > 0.0 {
        let mut push = Vec2::ZERO;
        around.grid.for_each_within(p, s.separation_distance_m, |n| {
            if n.serial != creature.serial {
                let d = p - n.position;
                let len = d.length();
                clear_m = clear_m.min(len);
                if len > 1e-4 {
                    push += d / len * (1.0 - len / s.separation_distance_m);
                }
            }
        });
        desired += push * (top * s.separation_weight);
    }

    // Keep off the walls: a push inward, and no motion outward right at the wall.
    if s.wall_avoid_distance_m > 0.0 {
        let half = around.court.half_extents - Vec2::splat(kind.radius_m);
        for axis in 0..2 {
            for sign in [-1.0f32, 1.0] {
                let gap = half[axis] - sign * p[axis];
                if gap < s.wall_avoid_distance_m {
                    let closeness = (1.0 - gap / s.wall_avoid_distance_m).clamp(0.0, 1.0);
                    desired[axis] -= sign * top * s.wall_weight * closeness * closeness;
                    let outward = desired[axis] * sign;
                    if outward > 0.0 {
                        desired[axis] -= sign * outward * closeness;
                    }
                }
            }
        }
    }

    (desired.clamp_length_max(top), Clearance { clear_m })
}

fn steer(
    clock: Res<SimClock>,
    config: Res<SimConfig>,
    kinds: Res<KindTable>,
    puck: Res<PuckState>,
    court: Res<Court>,
    grid: Res<NeighbourGrid>,
    mut creatures: Query<(&Creature, &PlanarState, &mut DesiredVelocity, &mut Clearance), Without<PlayerControlled>>,
) {
    if !clock.is_decision_tick() {
        return;
    }
    let around = Surroundings {
        puck: &puck,
        court: &court,
        grid: &grid,
        seed: config.scenario.seed,
        decision: clock.decision(),
        decision_dt: clock.dt * clock.ticks_per_decision as f32,
    };
    let steer_one = |creature: &Creature, state: &PlanarState, desired: &mut DesiredVelocity, clear: &mut Clearance| {
        (desired.0, *clear) = desired_velocity(creature, state, &kinds[creature.kind], &around);
    };
    for (creature, state, mut desired, mut clear) in creatures.contiguous_iter_mut().expect(DENSE) {
        let n = chunk_len(config.scenario.creature_count(), creature.len());
        let (desired, clear) = (desired.bypass_change_detection(), clear.bypass_change_detection());
        let chunks = (creature.chunks(n).zip(state.chunks(n))).zip(desired.chunks_mut(n).zip(clear.chunks_mut(n)));
        run_chunks(chunks.map(|((c, s), (d, cl))| {
            move || {
                for ((c, s), (d, cl)) in c.iter().zip(s).zip(d.iter_mut().zip(cl)) {
                    steer_one(c, s, d, cl);
                }
            }
        }));
    }
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.register_required_components::<Creature, Clearance>()
        .add_systems(schedule, steer.in_set(SimStage::Steer));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wander_noise_is_spread_over_minus_one_to_one() {
        let samples: Vec<f32> = (0..10_000).map(|d| wander_noise(7, 3, d)).collect();
        assert!(samples.iter().all(|x| (-1.0..=1.0).contains(x)));
        let mean = samples.iter().sum::<f32>() / samples.len() as f32;
        assert!(mean.abs() < 0.05, "mean {mean}");
        assert!(samples.iter().any(|&x| x > 0.9) && samples.iter().any(|&x| x < -0.9));
    }

    #[test]
    fn nearest_point_on_a_segment_is_clamped_to_its_ends() {
        let (a, b) = (Vec2::ZERO, Vec2::new(10.0, 0.0));
        assert_eq!(nearest_on_segment(Vec2::new(5.0, 3.0), a, b), Vec2::new(5.0, 0.0));
        assert_eq!(nearest_on_segment(Vec2::new(-5.0, 3.0), a, b), a);
        assert_eq!(nearest_on_segment(Vec2::new(15.0, 3.0), a, b), b);
        assert_eq!(nearest_on_segment(Vec2::ONE, a, a), a);
    }
}
