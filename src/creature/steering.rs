//! Steer: each creature's desired planar velocity (paper section 3: the creatures "attempt
//! to avoid the puck, the walls, and other creatures").
//!
//! The sum of four urges, scaled by the weights in the creature file and clipped to the top
//! speed: wander at cruise speed, flee the puck's predicted path, keep off the walls, keep
//! apart from neighbours. Runs at the decision rate (`decision_hz`), like the paper's
//! higher-level behaviours that run once per frame.

use bevy::prelude::*;

use super::{Creature, DesiredVelocity, KindParams, KindTable, Newcomers, PlanarState, PlayerControlled};
use crate::config::SimConfig;
use crate::contract::{DENSE, Lod, SimClock, SimStage, chunk_len, run_chunks};
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

/// Slack on each reach for the rounding of positions summed over a frame's ticks (an f32
/// position 1,500 m from the centre rounds by about 0.1 mm a tick).
pub const REACH_SLACK_M: f32 = 0.01;

/// How far from a creature no other creature's centre can be: what steering saw of its
/// neighbours as it kept apart from them, looking as far as its separation distance (0 where it
/// did not look), less how far it and any other creature could have closed in since. The
/// contact check between creatures need not search again where this is wider than any contact
/// the creature could make before it is checked.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct Clearance {
    /// Metres: at most the distance between the creature's centre and the nearest other centre.
    pub clear_m: f32,
    /// The decision at which steering looks around the creature again (steering's level of
    /// detail: a creature with nothing within reach looks around once in
    /// `look_every_decisions_when_clear`). Until then it keeps its desired velocity. Counted
    /// modulo 2^32 (four years at 30 decisions a second): a wrong wait after the count wraps
    /// round is bounded by `clear_m` all the same.
    pub look_again: u32,
}

impl Clearance {
    /// Whether no other creature is near enough to touch this one at the decision's contact
    /// check: `clear_m` is wider than any footprint's reach and a tick of its motion at
    /// `speed_m_per_s` (the index holds where the creatures were before it).
    pub fn clear_of_creatures(&self, kind: &KindParams, widest_m: f32, speed_m_per_s: f32, dt: f32) -> bool {
        self.clear_m > kind.radius_m + widest_m + speed_m_per_s * dt + REACH_SLACK_M
    }
}

/// The velocity a creature wants, given where it is and what is around it; and its
/// [`Clearance`] there, with the decision it looks around again: the next of its turns (one
/// decision in `look_every_decisions_when_clear`, staggered by serial) if nothing is within
/// reach until then, at the speeds of now, else the next decision.
pub fn desired_velocity(
    creature: &Creature,
    state: &PlanarState,
    kind: &KindParams,
    around: &Surroundings,
) -> (Vec2, Clearance) {
    let s = &kind.steering;
    let p = state.position;
    let top = kind.top_speed_m_per_s;
    // How far it could go before its next turn to look around.
    let every = s.look_every_decisions_when_clear;
    let wait_s = (every - 1) as f32 * around.decision_dt;
    let own_reach_m = state.velocity.length().max(top) * wait_s;
    let mut clear_until_turn = true;

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
    clear_until_turn &= gap >= s.puck_alert_distance_m + own_reach_m + puck.velocity.length() * wait_s;
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
    clear_until_turn &= clear_m >= s.separation_distance_m;

    // Keep off the walls: a push inward, and no motion outward right at the wall.
    if s.wall_avoid_distance_m > 0.0 {
        let half = around.court.half_extents - Vec2::splat(kind.radius_m);
        for axis in 0..2 {
            for sign in [-1.0f32, 1.0] {
                let gap = half[axis] - sign * p[axis];
                clear_until_turn &= gap >= s.wall_avoid_distance_m + own_reach_m;
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

    let decision = around.decision as u32;
    let look_again = if clear_until_turn && every > 1 {
        decision.wrapping_add(every - decision.wrapping_add(creature.serial) % every)
    } else {
        decision.wrapping_add(1)
    };
    (desired.clamp_length_max(top), Clearance { clear_m, look_again })
}

/// More placements than this in a frame wake every creature: each would otherwise test them all.
const MOST_PLACEMENTS_TESTED: usize = 16;

/// The puck's heading moving by more than this (the square of the chord between unit headings)
/// since every creature last looked around wakes them all: a bounce swings its predicted path
/// farther than any creature could go.
const PUCK_TURN_WAKES: f32 = 3.0e-4; // about one degree

/// What steering remembers from one decision to the next.
#[derive(Default)]
struct LookAround {
    /// The puck's heading when every creature last looked around.
    puck_heading: Vec2,
    /// The fastest creature at the last decision, m/s.
    fastest_m_per_s: f32,
}

#[allow(clippy::too_many_arguments)]
fn steer(
    clock: Res<SimClock>,
    config: Res<SimConfig>,
    kinds: Res<KindTable>,
    puck: Res<PuckState>,
    court: Res<Court>,
    grid: Res<NeighbourGrid>,
    mut newcomers: ResMut<Newcomers>,
    mut memory: Local<LookAround>,
    mut creatures: Query<
        (&Creature, &PlanarState, &Lod, &mut DesiredVelocity, &mut Clearance),
        Without<PlayerControlled>,
    >,
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
    // How far any two creatures could have closed in since the last decision: each moves below
    // the larger of its speed at a frame's start and its top speed.
    let (fastest, widest_m) = grid.fastest_and_widest();
    let speed_bound = (kinds.0.iter().map(|k| k.top_speed_m_per_s)).fold(fastest.max(memory.fastest_m_per_s), f32::max);
    let closed_m = 2.0 * speed_bound * around.decision_dt + REACH_SLACK_M;
    memory.fastest_m_per_s = fastest;
    let heading = puck.velocity.normalize_or_zero();
    let wake_all = heading.distance_squared(memory.puck_heading) > PUCK_TURN_WAKES
        || newcomers.placed_at.len() > MOST_PLACEMENTS_TESTED;
    if wake_all {
        memory.puck_heading = heading;
    }
    let placed_at = std::mem::take(&mut newcomers.placed_at);
    let decision = around.decision as u32;
    let steer_one =
        |creature: &Creature, state: &PlanarState, lod: Lod, desired: &mut DesiredVelocity, clear: &mut Clearance| {
            let kind = &kinds[creature.kind];
            // A rigid creature looks at every decision: beside its dynamics steering costs nothing.
            if lod != Lod::Rigid && decision < clear.look_again && !wake_all {
                // Not its turn: nothing was within reach, and its clearance still keeps it clear.
                let kept = Clearance {
                    clear_m: clear.clear_m - closed_m,
                    ..*clear
                };
                let woken = placed_at
                    .iter()
                    .any(|a| a.distance(state.position) < clear.clear_m + closed_m);
                if !woken && kept.clear_of_creatures(kind, widest_m, speed_bound, clock.dt) {
                    *clear = kept;
                    return;
                }
            }
            (desired.0, *clear) = desired_velocity(creature, state, kind, &around);
        };
    // Every table's chunks in one scope: a scope a table cost a world of mixed levels (a table
    // for each) more than the tables' steering.
    let mut tables: Vec<_> = creatures.contiguous_iter_mut().expect(DENSE).collect();
    let mut jobs = Vec::new();
    for (creature, state, lod, desired, clear) in &mut tables {
        let n = chunk_len(config.scenario.creature_count(), creature.len());
        let (desired, clear) = (desired.bypass_change_detection(), clear.bypass_change_detection());
        let chunks = (creature.chunks(n).zip(state.chunks(n)).zip(lod.chunks(n)))
            .zip(desired.chunks_mut(n).zip(clear.chunks_mut(n)));
        jobs.extend(chunks.map(|(((c, s), l), (d, cl))| {
            move || {
                for (((c, s), l), (d, cl)) in c.iter().zip(s).zip(l).zip(d.iter_mut().zip(cl)) {
                    steer_one(c, s, *l, d, cl);
                }
            }
        }));
    }
    run_chunks(jobs.into_iter());
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
