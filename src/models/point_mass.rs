//! The point-mass model (paper section 3.3): the body's position on the plane integrated
//! with an acceleration limit and a top speed; the body faces its direction of travel; the
//! leg is held at a constant angle (the kind's standing pose), so there is nothing of it to
//! compute. The hybrid level (3.2) is this same model plus the gait table.
//!
//! Between two steering decisions the desired velocity holds, so the motion is known in
//! closed form: the velocity moves straight toward its target at the acceleration limit, the
//! position is the sum of the ticks' velocities, the gait's cycle runs at its rhythm. A
//! creature's state at any tick is worked out from where its stretch of motion began
//! ([`PlanarSegment`]), in one step however many ticks have passed: stepped a tick at a time or
//! a frame at once ([`FrameStep`]), it holds the same bits at every tick something reads.

use bevy::prelude::*;

use super::hybrid;
use crate::config::SimConfig;
use crate::config::gait::{AtSpeed, GaitTable};
use crate::contract::GaitPose;
use crate::contract::{AtPointMass, AtRigid, Lod};
use crate::contract::{DENSE, SimClock, SimStage, chunk_len, run_chunks};
use crate::contract::{DesiredVelocity, GaitPhase, PlanarState};
use crate::kind::{Creature, KindParams, KindTable};

/// Below this speed the heading is left where it was (no spinning in place).
const HEADING_MIN_SPEED_M_PER_S: f32 = 0.05;

/// The most a body of a kind turns in some number of ticks, as its cosine and the rotations
/// either way: the same for every creature of the kind, so worked out once, not once a creature.
#[derive(Clone, Copy, Debug)]
pub struct TurnLimit {
    cos: f32,
    left: Vec2,
    right: Vec2,
}

impl TurnLimit {
    /// The turn a creature of `kind` may make in `seconds`.
    pub fn new(kind: &KindParams, seconds: f32) -> Self {
        let max_turn = (kind.turn_rate_rad_per_s * seconds).abs();
        Self {
            // Half a turn or more reaches any direction (a cosine never below -1 says so).
            cos: if max_turn >= std::f32::consts::PI {
                -2.0
            } else {
                max_turn.cos()
            },
            left: Vec2::from_angle(max_turn),
            right: Vec2::from_angle(-max_turn),
        }
    }
}

/// The planar point mass `ticks` ticks of `dt` on from `start` toward `desired`. The target is
/// the desired velocity within the top speed; the velocity moves straight toward it by the
/// acceleration limit each tick until it is there (a body faster than its top speed, shoved or
/// just switched from the rigid level, slows at the limit: no pop in velocity), so each tick's
/// velocity, and their sum, the way travelled, are known without stepping the ticks. The body
/// turns toward its travel by at most `turn` (the turn rate over those ticks): no pop when it
/// came from a level that faced elsewhere.
pub fn planar_after(
    start: &PlanarState,
    desired: Vec2,
    kind: &KindParams,
    turn: &TurnLimit,
    ticks: u32,
    dt: f32,
) -> PlanarState {
    let target = desired.clamp_length_max(kind.top_speed_m_per_s);
    let gap = target - start.velocity;
    let gap_m_per_s = gap.length();
    let per_tick = kind.acceleration_limit_m_per_s2 * dt;
    let k = ticks as f32;
    let (velocity, velocity_sum) = if gap_m_per_s > 0.0 {
        let toward = gap / gap_m_per_s;
        // Ticks that gain the whole limit; the target is reached on the tick after them.
        let full = ((gap_m_per_s / per_tick) as u32).min(ticks) as f32;
        let gained = per_tick * full * (full + 1.0) * 0.5 + (k - full) * gap_m_per_s;
        let velocity = if full < k {
            target
        } else {
            start.velocity + toward * (per_tick * k)
        };
        (velocity, start.velocity * k + toward * gained)
    } else {
        (start.velocity, start.velocity * k)
    };
    let speed = velocity.length();
    let heading = if speed > HEADING_MIN_SPEED_M_PER_S {
        let travel = velocity / speed;
        if start.heading.dot(travel) >= turn.cos {
            travel
        } else if start.heading.perp_dot(travel).is_sign_negative() {
            turn.right.rotate(start.heading)
        } else {
            turn.left.rotate(start.heading)
        }
    } else {
        start.heading
    };
    PlanarState {
        position: start.position + velocity_sum * dt,
        velocity,
        heading,
    }
}

/// The hop cycle's rhythm at the end of a stretch: the step's period and its part on the
/// ground, and the steps in a stride.
#[derive(Clone, Copy, Debug)]
struct Rhythm {
    period_s: f32,
    /// `1 / period_s`, worked out where the rhythm is made (a kind's, once a system run).
    cycles_per_s: f32,
    stance: f32,
    steps: u32,
}

impl Rhythm {
    /// A point mass keeps its kind's own ("holds the leg at a constant angle", 3.3).
    fn of_kind(kind: &KindParams) -> Self {
        Self::new(1.0 / kind.cycles_per_s, kind.stance_fraction, kind.steps_per_stride())
    }

    /// Steps of `period_s`, `stance` of each on the ground, `steps` to a stride.
    fn new(period_s: f32, stance: f32, steps: u32) -> Self {
        Self {
            period_s,
            cycles_per_s: 1.0 / period_s,
            stance,
            steps,
        }
    }

    /// A hybrid's comes from its table at its speed.
    fn of_table(table: &GaitTable, at: &AtSpeed) -> Self {
        let (period_s, stance) = at.rhythm();
        Self::new(period_s, stance, table.steps_per_stride)
    }

    /// The gait `seconds` on from `start`; `end_s` is the simulated time then. The cycle runs at
    /// the mean of the rate it had and this one (the table's hop period changes little with
    /// speed, "the running frequency is nearly independent of forward velocity"; from the rigid
    /// level, the rigid hop's).
    fn advance(&self, start: &GaitPhase, seconds: f32, end_s: f32) -> GaitPhase {
        let rate = self.cycles_per_s;
        // At the rhythm it had, the mean is that rate to the bit: no second division.
        let rate = if start.hop_period_s > 0.0 && start.hop_period_s != self.period_s {
            0.5 * (1.0 / start.hop_period_s + rate)
        } else {
            rate
        };
        start.advanced(seconds * rate, self.period_s, self.stance, self.steps, end_s)
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

/// Whether a planar creature is behind its frame. A creature that nothing reads before the next
/// steering decision (far from the puck and the walls, clear of other creatures, not waiting to
/// switch, neither steered by a player nor followed by the headless camera: planned at each
/// decision before anything moves, see `outcome::plan_frames`) keeps the state of its frame's
/// start while the frame's ticks go by, and is moved on to the frame's last tick in one step at
/// that tick, or as soon as something needs it sooner: the same closed form from the same start
/// as a tick at a time, so the same state bit for bit, for one pass over a crowd a frame.
///
/// A hybrid caught up this way is not posed: its pose is worked out from its gait and speed
/// (a function of the two alone) when something may next read it, at a switch or when it is
/// next stepped; until then [`GaitPose`] holds an older pose and `pose_stale` says so.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::NoUninit)]
#[repr(C)]
pub struct FrameStep {
    /// Holds the state of its frame's start: the frame's ticks are still to step.
    pub behind: bool,
    /// Its pose was left at its last catch-up: see [`FrameStep::pose_now`].
    pub pose_stale: bool,
}

impl FrameStep {
    /// The first of `frames` from `from` on that is not behind its frame. In a crowd nearly all
    /// are: the flags are tested a run at a time, four creatures' in a word read as bytes (a
    /// loop over the flags one by one gathers every other byte), and only a run that has one is
    /// searched.
    pub fn next_not_behind(frames: &[FrameStep], from: usize) -> Option<usize> {
        const RUN: usize = 64;
        // `behind` is the first byte of each two, and a `bool` is 0 or 1.
        const BEHIND_BYTES: u64 = 0x00FF_00FF_00FF_00FF;
        const ALL_BEHIND: u64 = 0x0001_0001_0001_0001;
        // At a decision's tick none is behind yet: the first is tested alone before a run.
        if frames.get(from).is_some_and(|f| !f.behind) {
            return Some(from);
        }
        let mut start = from;
        while start < frames.len() {
            let run = &frames[start..(start + RUN).min(frames.len())];
            let words = bytemuck::cast_slice::<FrameStep, u8>(run).chunks_exact(8);
            let rest = &run[run.len() - words.remainder().len() / 2..];
            let missing = words.fold(0, |m, w| {
                m | ((u64::from_le_bytes(w.try_into().expect("eight bytes")) & BEHIND_BYTES) ^ ALL_BEHIND)
            });
            if missing != 0 || rest.iter().any(|f| !f.behind) {
                return run.iter().position(|f| !f.behind).map(|i| start + i);
            }
            start += run.len();
        }
        None
    }

    /// Works out a pose left stale by a catch-up, for a reader that needs it now: the same
    /// pose, bit for bit, as stepping the creature there would have published.
    pub fn pose_now(
        &mut self,
        kind: &KindParams,
        lod: Lod,
        state: &PlanarState,
        gait: &GaitPhase,
        pose: &mut GaitPose,
    ) {
        if std::mem::take(&mut self.pose_stale)
            && lod == Lod::Hybrid
            && let Some(table) = &kind.gait
        {
            *pose = hybrid::pose(gait, &table.at(state.velocity.length()), table.steps_per_stride);
        }
    }
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

/// Where a planar creature's current stretch of motion began: the state and gait it started
/// from, its first tick, and the velocity and level it moves at; and what was worked out from
/// it last. A stretch begins at each decision's tick (from the frame's start, with the new
/// desired velocity), and again wherever anything else has written the state since (a
/// collision, a switch, a player's new velocity): each tick's state is worked out from the
/// stretch's start, not from the tick before.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct PlanarSegment {
    start: PlanarState,
    start_gait: GaitPhase,
    /// The stretch's first tick: `start` is the state at its beginning.
    first_tick: u64,
    desired: Vec2,
    lod: Lod,
    published: PlanarState,
    published_gait: GaitPhase,
}

impl PlanarSegment {
    /// A stretch starting from the creature as it is, at the beginning of tick `first_tick`.
    fn begin(state: &PlanarState, gait: &GaitPhase, desired: Vec2, lod: Lod, first_tick: u64) -> Self {
        Self {
            start: *state,
            start_gait: *gait,
            first_tick,
            desired,
            lod,
            published: *state,
            published_gait: *gait,
        }
    }

    /// Whether the creature is still on this stretch: nothing but the stepper moved it.
    fn holds(&self, state: &PlanarState, gait: &GaitPhase, desired: Vec2, lod: Lod) -> bool {
        self.published == *state && self.published_gait == *gait && self.desired == desired && self.lod == lod
    }
}

/// What moving a planar creature writes: its body on the plane, its gait and its pose.
pub type Moving<'a> = (&'a mut PlanarState, &'a mut GaitPhase, &'a mut GaitPose);

/// Works out planar creatures' states: what each kind needs, once per system run.
pub struct PlanarStepper<'a> {
    kinds: &'a KindTable,
    /// Each kind's turn limit over 1, 2, ... ticks, up to a decision's, and its point mass's rhythm.
    per_kind: Vec<(Vec<TurnLimit>, Rhythm)>,
    clock: SimClock,
    /// Simulated time at the end of this tick.
    end_s: f32,
}

impl<'a> PlanarStepper<'a> {
    /// A stepper for the tick `clock` is at.
    pub fn new(kinds: &'a KindTable, clock: &SimClock) -> Self {
        let ticks = clock.ticks_per_decision.max(1);
        Self {
            kinds,
            per_kind: (kinds.0.iter())
                .map(|k| {
                    let turns = (1..=ticks).map(|n| TurnLimit::new(k, n as f32 * clock.dt)).collect();
                    (turns, Rhythm::of_kind(k))
                })
                .collect(),
            clock: *clock,
            end_s: clock.seconds_at(clock.tick + 1) as f32,
        }
    }

    /// Moves one creature from the state and gait it holds, `ticks` ticks before the end of
    /// this tick, to the end of this tick at its desired velocity: the plane, the gait's
    /// rhythm, and (for a hybrid, if `posed`) the pose, which depends on the speed and the
    /// gait's place alone.
    fn advance(
        &self,
        creature: &Creature,
        lod: Lod,
        desired: Vec2,
        (state, gait, pose): Moving,
        ticks: u64,
        posed: bool,
    ) {
        self.move_plane(creature, lod, desired, state, ticks);
        self.move_gait(creature, lod, (state, gait, pose), ticks, posed);
    }

    /// `ticks` of a stretch as the step takes them: a stretch ends at the next decision, so
    /// never more than a decision's.
    fn stretch_ticks(&self, ticks: u64) -> u32 {
        let most = self.clock.ticks_per_decision.max(1);
        debug_assert!((1..=u64::from(most)).contains(&ticks), "{ticks} ticks");
        ticks.clamp(1, u64::from(most)) as u32
    }

    /// [`PlanarStepper::advance`]'s first half: the body on the plane.
    fn move_plane(&self, creature: &Creature, lod: Lod, desired: Vec2, state: &mut PlanarState, ticks: u64) {
        let kind = &self.kinds[creature.kind];
        // A hybrid whose kind has no table is not made: `KindParams::best_level`.
        if lod == Lod::Hybrid && kind.gait.is_none() {
            return;
        }
        let ticks = self.stretch_ticks(ticks);
        let turn = &self.per_kind[creature.kind].0[ticks as usize - 1];
        *state = planar_after(state, desired, kind, turn, ticks, self.clock.dt);
    }

    /// [`PlanarStepper::advance`]'s second half, once the body has moved: the gait's rhythm at
    /// the body's new speed, and the pose.
    fn move_gait(&self, creature: &Creature, lod: Lod, (state, gait, pose): Moving, ticks: u64, posed: bool) {
        let kind = &self.kinds[creature.kind];
        let point_mass = &self.per_kind[creature.kind].1;
        let seconds = self.stretch_ticks(ticks) as f32 * self.clock.dt;
        match (lod, &kind.gait) {
            (Lod::Hybrid, Some(table)) => {
                let at = table.at(state.velocity.length());
                *gait = Rhythm::of_table(table, &at).advance(gait, seconds, self.end_s);
                if posed {
                    *pose = hybrid::pose(gait, &at, table.steps_per_stride);
                }
            }
            (Lod::Hybrid, None) => {}
            _ => *gait = point_mass.advance(gait, seconds, self.end_s),
        }
    }

    /// Moves a creature on its stretch to the end of this tick, posed: it is up to date. A new
    /// stretch begins from where the creature is: with its first tick `first_tick` where given
    /// (a decision's tick; a creature behind its frame, held at the frame's start), else with
    /// this tick if anything but the stepper has moved it since the last.
    pub fn follow(
        &self,
        creature: &Creature,
        lod: Lod,
        desired: Vec2,
        (state, gait, pose): Moving,
        (frame, segment): (&mut FrameStep, &mut PlanarSegment),
        first_tick: Option<u64>,
    ) {
        match first_tick {
            Some(tick) => *segment = PlanarSegment::begin(state, gait, desired, lod, tick),
            None if !segment.holds(state, gait, desired, lod) => {
                *segment = PlanarSegment::begin(state, gait, desired, lod, self.clock.tick);
            }
            None => {}
        }
        (*state, *gait) = (segment.start, segment.start_gait);
        let ticks = self.clock.tick + 1 - segment.first_tick;
        self.advance(creature, lod, desired, (state, gait, pose), ticks, true);
        (segment.published, segment.published_gait) = (*state, *gait);
        *frame = FrameStep::default();
    }
}

/// The point-mass and hybrid levels: one planar model; the hybrid also plays the gait table.
/// Each creature follows its stretch, begun at the decision's tick from the frame's start; a
/// creature behind its frame waits for the frame's last tick and is moved the whole frame then.
pub(crate) fn step_point_masses(
    clock: Res<SimClock>,
    config: Res<SimConfig>,
    kinds: Res<KindTable>,
    mut creatures: Query<
        (
            (&Creature, &Lod, &DesiredVelocity),
            (&mut PlanarState, &mut GaitPhase, &mut GaitPose),
            (&mut FrameStep, &mut PlanarSegment),
        ),
        Without<AtRigid>,
    >,
) {
    let stepper = PlanarStepper::new(&kinds, &clock);
    let in_frame = clock.tick_in_frame();
    let last_of_frame = in_frame + 1 == u64::from(clock.ticks_per_decision);
    let follow = |creature: &Creature,
                  lod: Lod,
                  desired: Vec2,
                  moving: Moving<'_>,
                  frame: &mut FrameStep,
                  segment: &mut PlanarSegment| {
        let first_tick = (in_frame == 0).then_some(clock.tick);
        stepper.follow(creature, lod, desired, moving, (frame, segment), first_tick);
    };
    let (stepper, follow) = (&stepper, &follow);
    // Whole columns of components, run in one tight loop per thread: every tick, Bevy's fetch
    // of each creature's components one by one cost more than the step itself.
    // Every table's chunks in one scope (see `steer`).
    let mut tables: Vec<_> = creatures.contiguous_iter_mut().expect(DENSE).collect();
    let mut jobs = Vec::new();
    for ((creature, lod, desired), (state, gait, pose), (frame, segment)) in &mut tables {
        let n = chunk_len(config.scenario.creature_count(), creature.len());
        // Nothing watches these components' change ticks: writing them is a pass of its own.
        let (state, gait) = (state.bypass_change_detection(), gait.bypass_change_detection());
        let (pose, frame) = (pose.bypass_change_detection(), frame.bypass_change_detection());
        let segment = segment.bypass_change_detection();
        let chunks = (creature.chunks(n).zip(lod.chunks(n)).zip(desired.chunks(n)))
            .zip((state.chunks_mut(n).zip(gait.chunks_mut(n))).zip(pose.chunks_mut(n)))
            .zip(frame.chunks_mut(n).zip(segment.chunks_mut(n)));
        jobs.extend(chunks.map(|((((c, l), d), ((s, g), p)), (f, seg))| {
            move || {
                if !last_of_frame {
                    // Only the creatures not behind move: found by a scan of their flags alone,
                    // not a walk over every column (in a crowd nearly all are behind).
                    let mut i = 0;
                    while let Some(next) = FrameStep::next_not_behind(f, i) {
                        i = next;
                        let moving = (&mut s[i], &mut g[i], &mut p[i]);
                        follow(&c[i], l[i], d[i].0, moving, &mut f[i], &mut seg[i]);
                        i += 1;
                    }
                    return;
                }
                // The frame's last tick: the creatures behind move the whole frame (nothing reads
                // their poses before the next decision: they wait for a reader), the others their
                // stretch. A block at a time, every body on the plane first, then every gait: a
                // hybrid's gait waits on its new speed, and so one creature's roots and divisions
                // run beside the next's, not after them.
                let blocks = (c.chunks(CATCH_UP_BLOCK).zip(l.chunks(CATCH_UP_BLOCK)))
                    .zip(d.chunks(CATCH_UP_BLOCK).zip(s.chunks_mut(CATCH_UP_BLOCK)))
                    .zip(g.chunks_mut(CATCH_UP_BLOCK).zip(p.chunks_mut(CATCH_UP_BLOCK)))
                    .zip(f.chunks_mut(CATCH_UP_BLOCK).zip(seg.chunks_mut(CATCH_UP_BLOCK)));
                let ticks = in_frame + 1;
                for ((((c, l), (d, s)), (g, p)), (f, seg)) in blocks {
                    for (((c, l), (d, s)), f) in c.iter().zip(l).zip(d.iter().zip(s.iter_mut())).zip(f.iter()) {
                        if f.behind {
                            stepper.move_plane(c, *l, d.0, s, ticks);
                        }
                    }
                    let rows = (c.iter().zip(l).zip(d))
                        .zip((s.iter_mut().zip(g)).zip(p.iter_mut()))
                        .zip(f.iter_mut().zip(seg));
                    for ((((c, l), d), ((s, g), p)), (f, seg)) in rows {
                        if f.behind {
                            *f = FrameStep {
                                behind: false,
                                pose_stale: true,
                            };
                            stepper.move_gait(c, *l, (s, g, p), ticks, false);
                        } else {
                            follow(c, *l, d.0, (s, g, p), f, seg);
                        }
                    }
                }
            }
        }));
    }
    run_chunks(jobs.into_iter());
}

/// Creatures a catch-up moves on the plane before it moves their gaits: a few lines of the
/// cache of each column.
const CATCH_UP_BLOCK: usize = 64;

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.register_required_components::<Creature, FrameStep>()
        .register_required_components::<Creature, PlanarSegment>()
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
                look_every_decisions_when_clear: 1,
            },
            rigid: None,
            gait: None,
            levels: vec![Lod::PointMass],
        }
    }

    const DT: f32 = 1.0 / 240.0;

    /// `ticks` ticks of the closed form one at a time.
    fn tick_by_tick(start: PlanarState, desired: Vec2, k: &KindParams, ticks: u32) -> PlanarState {
        let turn = TurnLimit::new(k, DT);
        (0..ticks).fold(start, |s, _| planar_after(&s, desired, k, &turn, 1, DT))
    }

    #[test]
    fn speed_rises_no_faster_than_the_acceleration_limit_and_stops_at_top_speed() {
        let k = kind();
        let after = |ticks: u32| {
            let turn = TurnLimit::new(&k, ticks as f32 * DT);
            planar_after(&PlanarState::default(), Vec2::new(10.0, 0.0), &k, &turn, ticks, DT)
        };
        let s = after(240);
        assert!(
            (s.velocity.x - 2.0).abs() < 1e-3,
            "after 1 s at 2 m/s^2: {}",
            s.velocity.x
        );
        // Travelled: 1/2 a t^2, to within the half tick the ticks' sum adds.
        assert!((s.position.x - 1.0).abs() < 5e-3, "{}", s.position.x);
        let s = after(720);
        assert_eq!(s.velocity, Vec2::new(3.0, 0.0));
        assert_eq!(s.heading, Vec2::X);
        // 1.5 s to reach 3 m/s (2.25 m), then 1.5 s at it (4.5 m).
        assert!((s.position.x - 6.75).abs() < 2e-2, "{}", s.position.x);
    }

    #[test]
    fn a_body_faster_than_its_top_speed_slows_at_the_acceleration_limit() {
        let k = kind();
        let start = PlanarState {
            velocity: Vec2::new(4.0, 0.0),
            ..default()
        };
        let s = planar_after(&start, Vec2::new(10.0, 0.0), &k, &TurnLimit::new(&k, 0.25), 60, DT);
        assert!(
            (s.velocity.x - 3.5).abs() < 1e-3,
            "after 0.25 s at 2 m/s^2: {}",
            s.velocity.x
        );
        assert_eq!(
            tick_by_tick(start, Vec2::new(10.0, 0.0), &k, 120).velocity,
            Vec2::new(3.0, 0.0)
        );
    }

    #[test]
    fn a_stretch_worked_out_at_once_ends_where_its_ticks_one_by_one_do() {
        let k = kind();
        let start = PlanarState {
            position: Vec2::new(-3.0, 7.0),
            velocity: Vec2::new(1.0, -0.5),
            heading: Vec2::new(1.0, -0.5).normalize(),
        };
        // Reaching the target within the stretch, not reaching it, and already there.
        for desired in [Vec2::new(1.02, -0.45), Vec2::new(-2.0, 1.0), Vec2::new(1.0, -0.5)] {
            for ticks in [1, 3, 8] {
                let whole = planar_after(&start, desired, &k, &TurnLimit::new(&k, ticks as f32 * DT), ticks, DT);
                let steps = tick_by_tick(start, desired, &k, ticks);
                assert!(
                    whole.position.distance(steps.position) < 1e-5,
                    "{desired} {ticks}: {whole:?} {steps:?}"
                );
                assert!(
                    whole.velocity.distance(steps.velocity) < 1e-5,
                    "{desired} {ticks}: {whole:?} {steps:?}"
                );
            }
        }
    }

    #[test]
    fn the_body_turns_toward_its_travel_no_faster_than_its_turn_rate() {
        let mut k = kind();
        let start = PlanarState {
            velocity: Vec2::new(0.0, 1.0),
            ..default()
        };
        let s = planar_after(&start, Vec2::new(0.0, 1.0), &k, &TurnLimit::new(&k, 0.01), 1, 0.01);
        assert!((s.heading_angle() - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        k.turn_rate_rad_per_s = 1.0;
        let s = planar_after(&start, Vec2::new(0.0, 1.0), &k, &TurnLimit::new(&k, 0.5), 50, 0.01);
        assert!((s.heading_angle() - 0.5).abs() < 1e-6, "{}", s.heading_angle());
    }

    #[test]
    fn the_scan_for_creatures_not_behind_finds_each_in_order_across_its_runs() {
        // The last run's 11 flags are two words and three left over.
        let not_behind = [0, 5, 63, 64, 65, 130, 199, 201];
        let frames: Vec<FrameStep> = (0..203)
            .map(|i| FrameStep {
                behind: !not_behind.contains(&i),
                pose_stale: i % 3 == 0,
            })
            .collect();
        let found: Vec<usize> = std::iter::successors(FrameStep::next_not_behind(&frames, 0), |&i| {
            FrameStep::next_not_behind(&frames, i + 1)
        })
        .collect();
        assert_eq!(found, not_behind);
        assert_eq!(FrameStep::next_not_behind(&frames[66..130], 0), None);
        // A whole run behind, then one found among the flags left over after the words.
        assert_eq!(FrameStep::next_not_behind(&frames[131..202], 0), Some(199 - 131));
        assert_eq!(FrameStep::next_not_behind(&[], 0), None);
    }

    #[test]
    fn flight_follows_stance_in_each_hop_cycle() {
        let k = kind();
        let mut g = GaitPhase::default();
        let mut flight_ticks = 0;
        let mut touchdowns = Vec::new();
        for i in 0..1100 {
            g = Rhythm::of_kind(&k).advance(&g, 0.001, (i + 1) as f32 * 0.001);
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
        // The same second and a tenth at once: the same place in the cycle.
        let once = Rhythm::of_kind(&k).advance(&GaitPhase::default(), 1.1, 1.1);
        assert!(
            (once.cycle - g.cycle).abs() < 1e-3 && (once.last_touchdown_s - 1.0).abs() < 1e-3,
            "{once:?}"
        );
    }
}
