//! The point-mass model (paper section 3.3): the body's position on the plane integrated
//! with an acceleration limit and a top speed; the body faces its direction of travel; the
//! leg is held at a constant angle (the kind's standing pose), so there is nothing of it to
//! compute. The hybrid level (3.2) is this same model plus the gait table.

use bevy::prelude::*;

use super::hybrid;
use crate::config::SimConfig;
use crate::config::gait::GaitTable;
use crate::contract::GaitPose;
use crate::contract::{AtPointMass, AtRigid, Lod};
use crate::contract::{DENSE, SimClock, SimStage, chunk_len, run_chunks};
use crate::contract::{DesiredVelocity, GaitPhase, PlanarState};
use crate::kind::{Creature, KindParams, KindTable};

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
/// or just switched from the rigid level) slows at the limit: no pop in velocity. Returns
/// whether the body is steady: at the velocity it wants and facing its travel, so that the
/// next tick at the same desired velocity only moves it on.
pub fn step_planar(state: &mut PlanarState, desired: Vec2, kind: &KindParams, turn: &TurnLimit, dt: f32) -> bool {
    let target = desired.clamp_length_max(kind.top_speed_m_per_s);
    state.velocity += (target - state.velocity).clamp_length_max(kind.acceleration_limit_m_per_s2 * dt);
    state.position += state.velocity * dt;
    let speed = state.velocity.length();
    let mut facing = true;
    if speed > HEADING_MIN_SPEED_M_PER_S {
        // Turn toward the direction of travel at the turn rate: no pop when the body came
        // from a level that faced elsewhere.
        let travel = state.velocity / speed;
        state.heading = if state.heading.dot(travel) >= turn.cos {
            travel
        } else {
            facing = false;
            if state.heading.perp_dot(travel).is_sign_negative() {
                turn.right.rotate(state.heading)
            } else {
                turn.left.rotate(state.heading)
            }
        };
    }
    facing && state.velocity == target
}

/// The hop cycle's rhythm at a level: the step's period and its part on the ground, and the
/// steps in a stride. A hybrid's comes from its table at its speed; a point mass keeps its
/// kind's own ("holds the leg at a constant angle", 3.3).
fn rhythm(kind: &KindParams, table: Option<&GaitTable>, velocity: Vec2) -> (f32, f32, u32) {
    match table {
        Some(table) => {
            let (period, stance) = table.rhythm(velocity.length());
            (period, stance, table.steps_per_stride)
        }
        None => (1.0 / kind.cycles_per_s, kind.stance_fraction, kind.steps_per_stride()),
    }
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

/// Whether a planar creature is behind its frame. A creature that nothing reads between two
/// steering decisions (far from the puck and the walls, not waiting to switch, not steered
/// by a player: decided with the contacts at each decision) keeps the decision's state while
/// the frame's ticks go by, and is stepped through all of them at once at the frame's last
/// tick, or as soon as something needs it sooner. It is the same arithmetic in the same
/// order, so the same state bit for bit; a crowd's frame was spent moving every creature's
/// components through memory once a tick, and this moves them once a frame.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameStep {
    /// Holds the state of its frame's decision tick: the frame's ticks since are still to step.
    pub behind: bool,
}

/// Whether planar creatures may fall behind their frame ([`FrameStep`]); absent, they may.
/// Off where something outside the simulation reads every creature at every tick: the game
/// draws them at its own frame rate. (Not a resource of the simulation's own: one more
/// entity in every world would move the rigid level's rounding, see `NearPuckOrWall`.)
#[derive(Resource, Clone, Copy, Debug)]
pub struct FrameStepping {
    /// Whether they may.
    pub enabled: bool,
}

/// Steps planar creatures: what a tick of each kind needs, worked out once a tick.
pub struct PlanarStepper<'a> {
    kinds: &'a KindTable,
    turns: Vec<TurnLimit>,
    clock: SimClock,
}

impl<'a> PlanarStepper<'a> {
    /// A stepper for the tick `clock` is at.
    pub fn new(kinds: &'a KindTable, clock: &SimClock) -> Self {
        Self {
            kinds,
            turns: kinds.0.iter().map(|k| TurnLimit::new(k, clock.dt)).collect(),
            clock: *clock,
        }
    }

    /// Steps one creature through the last `ticks` ticks up to and including this one, at its
    /// desired velocity: the plane, the gait's rhythm, and (for a hybrid) the pose at the end,
    /// which depends on the speed and the gait's place alone.
    pub fn step(
        &self,
        creature: &Creature,
        lod: Lod,
        desired: Vec2,
        state: &mut PlanarState,
        gait: &mut GaitPhase,
        pose: &mut GaitPose,
        ticks: u64,
    ) {
        let kind = &self.kinds[creature.kind];
        let (turn, dt) = (&self.turns[creature.kind], self.clock.dt);
        let table = match (lod, &kind.gait) {
            (Lod::Hybrid, Some(table)) => Some(table),
            // A hybrid whose kind has no table is not made: `KindParams::best_level`.
            (Lod::Hybrid, None) => return,
            _ => None,
        };
        // Once steady, a tick only moves the body on and the gait along at a rhythm that no
        // longer changes: the same arithmetic as a whole tick, without what comes out the same.
        let mut steady = None;
        for tick in self.clock.tick + 1 - ticks..=self.clock.tick {
            let (period, stance, steps) = match steady {
                Some(rhythm) => {
                    state.position += state.velocity * dt;
                    rhythm
                }
                None => {
                    let now_steady = step_planar(state, desired, kind, turn, dt);
                    let rhythm = rhythm(kind, table, state.velocity);
                    steady = now_steady.then_some(rhythm);
                    rhythm
                }
            };
            gait.advance(period, stance, steps, self.clock.seconds_at(tick) as f32, dt);
        }
        if let Some(table) = table {
            *pose = hybrid::pose(gait, table, state.velocity.length());
        }
    }
}

/// The point-mass and hybrid levels: one planar model; the hybrid also plays the gait table.
/// A creature behind its frame waits for the frame's last tick.
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
            &mut FrameStep,
        ),
        Without<AtRigid>,
    >,
) {
    let stepper = PlanarStepper::new(&kinds, &clock);
    let in_frame = clock.tick_in_frame();
    let last_of_frame = in_frame + 1 == u64::from(clock.ticks_per_decision);
    let step = |creature: &Creature,
                lod: Lod,
                desired: &DesiredVelocity,
                state: &mut PlanarState,
                gait: &mut GaitPhase,
                pose: &mut GaitPose,
                frame: &mut FrameStep| {
        let ticks = match (frame.behind, last_of_frame) {
            (false, _) => 1,
            (true, false) => return,
            (true, true) => {
                frame.behind = false;
                in_frame
            }
        };
        stepper.step(creature, lod, desired.0, state, gait, pose, ticks);
    };
    // Whole columns of components, run in one tight loop per thread: every tick, Bevy's fetch
    // of each creature's components one by one cost more than the step itself.
    for (creature, lod, desired, mut state, mut gait, mut pose, mut frame) in
        creatures.contiguous_iter_mut().expect(DENSE)
    {
        let n = chunk_len(config.scenario.creature_count(), creature.len());
        // Nothing watches these components' change ticks: writing them is a pass of its own.
        let (state, gait) = (state.bypass_change_detection(), gait.bypass_change_detection());
        let (pose, frame) = (pose.bypass_change_detection(), frame.bypass_change_detection());
        let chunks = (creature.chunks(n).zip(lod.chunks(n)).zip(desired.chunks(n)))
            .zip((state.chunks_mut(n).zip(gait.chunks_mut(n))).zip(pose.chunks_mut(n).zip(frame.chunks_mut(n))));
        run_chunks(chunks.map(|(((c, l), d), ((s, g), (p, f)))| {
            move || {
                for (((c, l), d), ((s, g), (p, f))) in
                    (c.iter().zip(l).zip(d)).zip((s.iter_mut().zip(g)).zip(p.iter_mut().zip(f)))
                {
                    step(c, *l, d, s, g, p, f);
                }
            }
        }));
    }
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.register_required_components::<Creature, FrameStep>()
        .add_observer(enter_point_mass)
        .add_systems(schedule, step_point_masses.in_set(SimStage::Step));
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::config::SteeringConfig;
    use crate::kind::VirtualLegs;

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
            virtual_legs: VirtualLegs::new(&[vec![0]]),
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
            let (period, stance, steps) = rhythm(&k, None, Vec2::ZERO);
            g.advance(period, stance, steps, i as f32 * 0.001, 0.001);
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
