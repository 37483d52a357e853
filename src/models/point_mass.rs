//! The point-mass model (paper section 3.3): the body's position on the plane integrated
//! with an acceleration limit and a top speed; the body faces its direction of travel; the
//! leg is held at a constant angle (the kind's standing pose), so there is nothing of it to
//! compute. The hybrid level (3.2) is this same model plus the gait table.

use bevy::prelude::*;

use super::hybrid;
use crate::config::SimConfig;
use crate::creature::{Creature, DesiredVelocity, GaitPhase, KindParams, KindTable, PlanarState};
use crate::gait::GaitPose;
use crate::lod::{AtPointMass, AtRigid, Lod};
use crate::{DENSE, SimClock, SimStage, chunk_len, run_chunks};

/// Below this speed the heading is left where it was (no spinning in place).
const HEADING_MIN_SPEED_M_PER_S: f32 = 0.05;

/// The most a body of a kind turns in one tick, as its cosine and the rotations either way:
/// the same for every creature of the kind, so worked out once a tick, not once a creature.
#[derive(Clone, Copy, Debug)]
pub struct TurnLimit {
    cos: f32,
    left: Vec2,
    right: Vec2,
}

impl TurnLimit {
    /// The turn a creature of `kind` may make in a tick of `dt` seconds.
    pub fn new(kind: &KindParams, dt: f32) -> Self {
        let max_turn = kind.turn_rate_rad_per_s * dt;
        Self {
            cos: max_turn.cos(),
            left: Vec2::from_angle(max_turn.abs()),
            right: Vec2::from_angle(-max_turn.abs()),
        }
    }
}

/// One tick of the planar point mass: velocity moves toward the desired one, clipped to the
/// top speed, by at most the acceleration limit. A body faster than its top speed (shoved,
/// or just switched from the rigid level) slows at the limit: no pop in velocity.
pub fn step_planar(state: &mut PlanarState, desired: Vec2, kind: &KindParams, turn: &TurnLimit, dt: f32) {
    let target = desired.clamp_length_max(kind.top_speed_m_per_s);
    state.velocity += (target - state.velocity).clamp_length_max(kind.acceleration_limit_m_per_s2 * dt);
    state.position += state.velocity * dt;
    let speed = state.velocity.length();
    if speed > HEADING_MIN_SPEED_M_PER_S {
        // Turn toward the direction of travel at the turn rate: no pop when the body came
        // from a level that faced elsewhere.
        let travel = state.velocity / speed;
        state.heading = if state.heading.dot(travel) >= turn.cos {
            travel
        } else if state.heading.perp_dot(travel).is_sign_negative() {
            turn.right.rotate(state.heading)
        } else {
            turn.left.rotate(state.heading)
        };
    }
}

/// Advances the hop cycle by time at the kind's own rhythm.
pub fn advance_gait(gait: &mut GaitPhase, kind: &KindParams, now_s: f32, dt: f32) {
    gait.advance(
        1.0 / kind.cycles_per_s,
        kind.stance_fraction,
        kind.steps_per_stride,
        now_s,
        dt,
    );
}

/// Entering the point-mass level: the legs go to the kind's standing pose (paper 3.3: "holds
/// the leg at a constant angle").
fn enter_point_mass(
    add: On<Add, AtPointMass>,
    kinds: Res<KindTable>,
    mut creatures: Query<(&Creature, &mut GaitPose)>,
) {
    if let Ok((creature, mut pose)) = creatures.get_mut(add.entity) {
        *pose = kinds[creature.kind].standing_pose;
    }
}

/// The point-mass and hybrid levels: one planar model; the hybrid also plays the gait table.
fn step_point_masses(
    clock: Res<SimClock>,
    config: Res<SimConfig>,
    kinds: Res<KindTable>,
    mut creatures: Query<
        (
            &Creature,
            &Lod,
            &DesiredVelocity,
            &mut PlanarState,
            &mut GaitPhase,
            &mut GaitPose,
        ),
        Without<AtRigid>,
    >,
) {
    let (dt, now) = (clock.dt, clock.seconds() as f32);
    let turns: Vec<TurnLimit> = kinds.0.iter().map(|k| TurnLimit::new(k, dt)).collect();
    let step = |creature: &Creature,
                lod: Lod,
                desired: &DesiredVelocity,
                state: &mut PlanarState,
                gait: &mut GaitPhase,
                pose: &mut GaitPose| {
        let kind = &kinds[creature.kind];
        match (lod, &kind.gait) {
            (Lod::PointMass, _) => {
                step_planar(state, desired.0, kind, &turns[creature.kind], dt);
                advance_gait(gait, kind, now, dt);
            }
            (Lod::Hybrid, Some(table)) => {
                step_planar(state, desired.0, kind, &turns[creature.kind], dt);
                hybrid::play_gait(gait, pose, table, state.velocity.length(), now, dt);
            }
            // A hybrid whose kind has no table is not made: `KindParams::best_level`.
            _ => {}
        }
    };
    // Whole columns of components, run in one tight loop per thread: every tick, Bevy's fetch
    // of each creature's components one by one cost more than the step itself.
    for (creature, lod, desired, mut state, mut gait, mut pose) in creatures.contiguous_iter_mut().expect(DENSE) {
        let n = chunk_len(config.scenario.creature_count(), creature.len());
        let chunks = (creature.chunks(n).zip(lod.chunks(n)).zip(desired.chunks(n)))
            .zip(state.chunks_mut(n).zip(gait.chunks_mut(n)).zip(pose.chunks_mut(n)));
        run_chunks(chunks.map(|(((c, l), d), ((s, g), p))| {
            move || {
                for (((c, l), d), ((s, g), p)) in (c.iter().zip(l).zip(d)).zip(s.iter_mut().zip(g).zip(p)) {
                    step(c, *l, d, s, g, p);
                }
            }
        }));
    }
}

pub(super) fn plugin(app: &mut App) {
    app.add_observer(enter_point_mass)
        .add_systems(FixedUpdate, step_point_masses.in_set(SimStage::Step));
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::config::SteeringConfig;

    /// A hopper-sized kind: 0.3 m, 10 kg, 3 m/s, 2 m/s^2.
    pub(crate) fn kind() -> KindParams {
        KindParams {
            radius_m: 0.3,
            view_sphere_m: (0.6, 2.2),
            mass_kg: 10.0,
            top_speed_m_per_s: 3.0,
            acceleration_limit_m_per_s2: 2.0,
            cycles_per_s: 2.0,
            stance_fraction: 0.4,
            fall_impact_speed_m_per_s: 2.0,
            collision_restitution: 0.0,
            command_acceleration_m_per_s2: 2.0,
            turn_rate_rad_per_s: 1000.0,
            standing_pose: GaitPose::default(),
            hips_m: vec![Vec3::ZERO],
            legs: Vec::new(),
            steps_per_stride: 1,
            steering: SteeringConfig {
                cruise_speed_m_per_s: 1.0,
                wander_turn_rad_per_s: 0.0,
                puck_alert_distance_m: 0.0,
                puck_lookahead_s: 0.0,
                puck_weight: 0.0,
                wall_avoid_distance_m: 0.0,
                wall_weight: 0.0,
                separation_distance_m: 0.0,
                separation_weight: 0.0,
            },
            rigid: None,
            gait: None,
            levels: vec![Lod::PointMass],
        }
    }

    #[test]
    fn speed_rises_no_faster_than_the_acceleration_limit_and_stops_at_top_speed() {
        let k = kind();
        let mut s = PlanarState::default();
        let dt = 1.0 / 240.0;
        for _ in 0..240 {
            step_planar(&mut s, Vec2::new(10.0, 0.0), &k, &TurnLimit::new(&k, dt), dt);
        }
        assert!(
            (s.velocity.x - 2.0).abs() < 1e-3,
            "after 1 s at 2 m/s^2: {}",
            s.velocity.x
        );
        for _ in 0..480 {
            step_planar(&mut s, Vec2::new(10.0, 0.0), &k, &TurnLimit::new(&k, dt), dt);
        }
        assert!((s.velocity.length() - 3.0).abs() < 1e-4);
        assert_eq!(s.heading, Vec2::X);
    }

    #[test]
    fn a_body_faster_than_its_top_speed_slows_at_the_acceleration_limit() {
        let k = kind();
        let mut s = PlanarState {
            velocity: Vec2::new(4.0, 0.0),
            ..default()
        };
        let dt = 1.0 / 240.0;
        for _ in 0..120 {
            step_planar(&mut s, Vec2::new(10.0, 0.0), &k, &TurnLimit::new(&k, dt), dt);
        }
        assert!(
            (s.velocity.x - 3.0).abs() < 1e-3,
            "after 0.5 s at 2 m/s^2: {}",
            s.velocity.x
        );
    }

    #[test]
    fn the_body_turns_to_face_its_direction_of_travel() {
        let k = kind();
        let mut s = PlanarState {
            velocity: Vec2::new(0.0, 1.0),
            ..default()
        };
        step_planar(&mut s, Vec2::new(0.0, 1.0), &k, &TurnLimit::new(&k, 0.01), 0.01);
        assert!((s.heading_angle() - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    }

    #[test]
    fn flight_follows_stance_in_each_hop_cycle() {
        let k = kind();
        let mut g = GaitPhase::default();
        let mut flight_ticks = 0;
        let mut touchdowns = Vec::new();
        for i in 0..1100 {
            advance_gait(&mut g, &k, i as f32 * 0.001, 0.001);
            flight_ticks += g.in_flight as u32;
            if touchdowns.last() != Some(&g.last_touchdown_s) {
                touchdowns.push(g.last_touchdown_s);
            }
        }
        // 1.1 s at 2 cycles/s with 60 % flight (the last 0.1 s in stance): touchdowns at 0
        // (the start), 0.5 and 1 s.
        assert!((flight_ticks as i32 - 600).abs() <= 2, "{flight_ticks}");
        assert_eq!(g.hop_period_s, 0.5);
        assert_eq!(touchdowns.len(), 3, "{touchdowns:?}");
        assert!(
            (touchdowns[1] - 0.5).abs() < 2e-3 && (touchdowns[2] - 1.0).abs() < 2e-3,
            "{touchdowns:?}"
        );
    }
}
