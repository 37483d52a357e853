//! Observe and Outcome: collisions, falls, respawns and the counts the paper's experiments
//! read (figure 10 counts the creatures that collided with the puck or a wall).
//!
//! What a collision does at the point-mass and hybrid levels, where there is no balance to lose: the
//! bodies are pushed apart and the normal part of their relative velocity is removed (kept
//! in part by the creature's `collision_restitution`). The puck is far heavier and is not
//! slowed; it shoves the creature along. A creature falls when the normal speed of an impact
//! exceeds its `fall_impact_speed_m_per_s`. A fallen creature is removed and a new one of
//! its kind respawns in a free part of the court, so the count stays constant (section 3).
//! Puck and wall contacts are checked every tick, for the creatures that could reach either
//! before the next decision (chosen at each decision); contacts between creatures at each
//! steering decision, through the spatial index.

pub use crate::contract::{CollisionRecord, Counts, FallQueue, Key, Obstacle, SwitchCounts};

use bevy::prelude::*;
use bevy::utils::Parallel;
use serde::Serialize;

use crate::config::LevelPolicy;
use crate::config::SimConfig;
use crate::contract::GaitPose;
use crate::contract::{AtRigid, Lod};
use crate::contract::{DENSE, SimClock, SimStage, SimStart, WorldRng, chunk_len, run_chunks};
use crate::contract::{DesiredVelocity, GaitPhase, PlanarState, PlayerControlled};
use crate::creature::steering::REACH_SLACK_M;
use crate::creature::{Clearance, Newcomers, creature_bundle, find_free_spot};
use crate::kind::{Creature, KindParams, KindTable};
use crate::lod::{
    BudgetSummary, BudgetTally, LevelChoice, LevelSwitched, PopSummary, PopTally, SimCamera, SwitchProbe, SwitchTally,
};
use crate::models::point_mass::{FrameStep, FrameStepping, PlanarSegment, PlanarStepper, step_point_masses};
use crate::sense::NeighbourGrid;
use crate::sense::{Court, PuckState};

/// Creatures' collision records added up.
#[derive(Clone, Copy, Debug, Default)]
pub struct CollisionTotals {
    /// Collisions with each obstacle.
    pub collisions: Counts<Obstacle, u64>,
    /// Creatures that collided with each obstacle at least once.
    pub collided_with: Counts<Obstacle, u64>,
    /// Creatures that collided with the puck or a wall.
    pub collided: u64,
}

impl CollisionTotals {
    fn add(&mut self, record: &CollisionRecord) {
        for o in Obstacle::ALL {
            self.collisions[o] += u64::from(record.count[o as usize]);
            self.collided_with[o] += u64::from(record.count[o as usize] > 0);
        }
        self.collided += u64::from(record.hit_puck_or_wall());
    }
}

/// Counts kept for the whole run, beyond those of the creatures alive now.
#[derive(Resource, Clone, Debug, Default)]
pub struct Tally {
    /// The collision records of creatures already removed.
    pub removed: CollisionTotals,
    /// Falls of creatures already removed.
    pub falls: u64,
    /// Falls by the level the creature was at.
    pub falls_by_level: Counts<Lod, u64>,
    /// Falls within one step of a switch into the rigid level.
    pub falls_after_switch: u64,
    /// Creatures respawned after a fall.
    pub respawns: u64,
}

/// Resolves a contact along `normal` (pointing from the obstacle to the creature), where
/// the obstacle moves at `other_velocity` and takes `share` of the push (0 = immovable).
/// Returns the normal speed of the impact.
fn resolve_contact(
    state: &mut PlanarState,
    normal: Vec2,
    depth: f32,
    other_velocity: Vec2,
    share: f32,
    restitution: f32,
) -> f32 {
    state.position += normal * depth * share;
    let approach = (state.velocity - other_velocity).dot(normal);
    if approach < 0.0 {
        state.velocity -= normal * approach * (1.0 + restitution) * share;
        -approach
    } else {
        0.0
    }
}

/// Contacts of one point-mass creature this tick; returns the hardest impact's speed.
fn collide_point_mass(
    creature: &Creature,
    state: &mut PlanarState,
    record: &mut CollisionRecord,
    kind: &KindParams,
    puck: &PuckState,
    court: &Court,
    grid: Option<&NeighbourGrid>,
) -> f32 {
    let e = kind.collision_restitution;
    let r = kind.radius_m;
    let mut impact: f32 = 0.0;

    if let Some(grid) = grid {
        let mut touching = false;
        // The neighbours it could touch where it stands: none is wider than the widest.
        grid.for_each_within(state.position, r + grid.fastest_and_widest().1, |n| {
            let d = state.position - n.position;
            let depth = r + n.radius - d.length();
            if n.serial != creature.serial && depth > 0.0 {
                touching = true;
                let normal = d.try_normalize().unwrap_or(Vec2::X);
                let share = n.mass / (n.mass + kind.mass_kg);
                impact = impact.max(resolve_contact(state, normal, depth, n.velocity, share, e));
            }
        });
        record.note(Obstacle::Creature, touching);
    }

    let d = state.position - puck.position;
    let depth = puck.radius_m + r - d.length();
    if depth > 0.0 {
        let normal = d
            .try_normalize()
            .unwrap_or_else(|| puck.velocity.perp().normalize_or(Vec2::X));
        impact = impact.max(resolve_contact(state, normal, depth, puck.velocity, 1.0, e));
    }
    record.note(Obstacle::Puck, depth > 0.0);

    let half = court.half_extents - Vec2::splat(r);
    let mut at_wall = false;
    for axis in 0..2 {
        let over = state.position[axis].abs() - half[axis];
        if over >= 0.0 {
            at_wall = true;
            let mut normal = Vec2::ZERO;
            normal[axis] = -state.position[axis].signum();
            impact = impact.max(resolve_contact(state, normal, over, Vec2::ZERO, 1.0, e));
            state.position[axis] = state.position[axis].clamp(-half[axis], half[axis]);
        }
    }
    record.note(Obstacle::Wall, at_wall);
    impact
}

/// The planar creatures that could reach the puck or a wall before the next decision, chosen
/// at each decision; between decisions only these are checked. The others cannot touch
/// either in that time, so the outcome is the one of checking every creature every tick.
/// Kept by the system itself: a resource or an observer would be one more entity, and the
/// rigid level's rounding depends on the entities' ids.
#[derive(Default)]
struct NearPuckOrWall {
    /// Chosen at the decision, sorted; creatures switched down from rigid since are added.
    near: Vec<Entity>,
    /// The puck's position at the decision, and how far it can go before the next one.
    puck_from: Vec2,
    puck_reach_m: f32,
    /// Respawns counted so far: a creature respawned since the decision starts anywhere.
    respawns: u64,
    /// A respawn, or the puck going farther than its reach (shoved in rapier): every creature
    /// is checked until the next decision.
    check_all: bool,
}

/// Whether a creature, at its state at a frame's start, could reach the puck or a wall within
/// `frame_s`. A planar body's speed between decisions stays below the larger of its speed now
/// and its top speed (`planar_after` moves it toward a target within the top speed).
fn could_reach_puck_or_wall(
    state: &PlanarState,
    record: &CollisionRecord,
    kind: &KindParams,
    puck: &PuckState,
    puck_reach_m: f32,
    half: Vec2,
    frame_s: f32,
) -> bool {
    let reach = state.velocity.length().max(kind.top_speed_m_per_s) * frame_s + REACH_SLACK_M;
    let r = kind.radius_m;
    record.touching[Obstacle::Puck as usize]
        || record.touching[Obstacle::Wall as usize]
        || state.position.distance(puck.position) - puck.radius_m - r <= reach + puck_reach_m
        || (state.position.abs() + Vec2::splat(reach + r)).cmpge(half).any()
}

/// What says whether anything reads a planar creature before the next decision.
type FramePlan<'a> = (
    &'a Creature,
    &'a PlanarState,
    &'a CollisionRecord,
    &'a Clearance,
    &'a Lod,
    &'a LevelChoice,
    Has<PlayerControlled>,
);

/// At each decision, before anything moves: the planar creatures that nothing reads before the
/// next decision fall behind their frame ([`FrameStep`]). Those are the ones that touch
/// nothing, that no other creature is near enough to touch at this decision's check (steering's
/// [`Clearance`]), that cannot reach the puck or a wall within the frame, and that do not wait
/// to switch, are not measured after a switch, are not steered by a player and are not the
/// one the headless camera follows (it is placed at every tick). Every contact check until the
/// next decision would find nothing, so each passes them by.
#[allow(clippy::too_many_arguments)]
fn plan_frames(
    clock: Res<SimClock>,
    config: Res<SimConfig>,
    kinds: Res<KindTable>,
    puck: Res<PuckState>,
    court: Res<Court>,
    grid: Res<NeighbourGrid>,
    camera: Res<SimCamera>,
    stepping: Option<Res<FrameStepping>>,
    mut creatures: Query<(FramePlan, &mut FrameStep), Without<AtRigid>>,
    probed: Query<Entity, With<SwitchProbe>>,
) {
    // A frame of one or two ticks has nothing to gain.
    if !clock.is_decision_tick() || stepping.is_some_and(|s| !s.enabled) || clock.ticks_per_decision <= 2 {
        return;
    }
    let frame_s = clock.dt * clock.ticks_per_decision as f32;
    let puck_reach_m = config.arena.puck.speed_m_per_s * frame_s;
    let widest_m = grid.fastest_and_widest().1;
    let plan = |creature: &Creature,
                state: &PlanarState,
                record: &CollisionRecord,
                clearance: &Clearance,
                lod: Lod,
                choice: &LevelChoice,
                frame: &mut FrameStep| {
        let kind = &kinds[creature.kind];
        // It moves a tick before the decision's check: at most at this speed.
        let speed = state.velocity.length().max(kind.top_speed_m_per_s);
        frame.behind = choice.wanted == lod
            && !record.touching.iter().any(|&t| t)
            && clearance.clear_of_creatures(kind, widest_m, speed, clock.dt)
            && !could_reach_puck_or_wall(state, record, kind, &puck, puck_reach_m, court.half_extents, frame_s);
    };
    // Every table's chunks in one scope (see `steer`).
    let mut tables: Vec<_> = creatures.contiguous_iter_mut().expect(DENSE).collect();
    let mut jobs = Vec::new();
    for ((creature, state, record, clearance, lod, choice, player), frame) in &mut tables {
        let frame = frame.bypass_change_detection();
        if *player {
            frame.iter_mut().for_each(|f| f.behind = false);
            continue;
        }
        let n = chunk_len(config.scenario.creature_count(), creature.len());
        let chunks = (creature.chunks(n).zip(state.chunks(n)).zip(record.chunks(n)))
            .zip((clearance.chunks(n).zip(lod.chunks(n)).zip(choice.chunks(n))).zip(frame.chunks_mut(n)));
        jobs.extend(chunks.map(|(((c, s), r), (((cl, l), ch), f))| {
            move || {
                let rows = (c.iter().zip(s).zip(r)).zip((cl.iter().zip(l).zip(ch)).zip(f));
                for (((c, s), r), (((cl, l), ch), f)) in rows {
                    plan(c, s, r, cl, *l, ch, f);
                }
            }
        }));
    }
    run_chunks(jobs.into_iter());
    drop(tables);
    for entity in probed.iter().chain(camera.following) {
        if let Ok((_, mut frame)) = creatures.get_mut(entity) {
            frame.behind = false;
        }
    }
}

/// What catching up a planar creature behind its frame takes.
type CatchUp<'a> = (
    &'a Lod,
    &'a DesiredVelocity,
    &'a mut GaitPhase,
    &'a mut GaitPose,
    (&'a mut FrameStep, &'a mut PlanarSegment),
);

/// Puck, wall and (at each decision) creature contacts of the planar creatures. The creatures
/// behind their frame ([`plan_frames`]) are passed by, as nothing can touch them before the next
/// decision, unless the puck went farther than its reach: then they are caught up first.
#[allow(clippy::too_many_arguments)]
fn detect_collisions(
    clock: Res<SimClock>,
    config: Res<SimConfig>,
    kinds: Res<KindTable>,
    puck: Res<PuckState>,
    court: Res<Court>,
    grid: Res<NeighbourGrid>,
    falls: Res<FallQueue>,
    tally: Res<Tally>,
    mut switched: MessageReader<LevelSwitched>,
    mut watch: Local<NearPuckOrWall>,
    mut chosen: Local<Parallel<Vec<Entity>>>,
    mut creatures: Query<
        (
            Entity,
            &Creature,
            &mut PlanarState,
            &mut CollisionRecord,
            &Clearance,
            Has<PlayerControlled>,
            CatchUp,
        ),
        Without<AtRigid>,
    >,
) {
    let collide = |entity, creature: &Creature, state: &mut PlanarState, record: &mut CollisionRecord, grid| {
        let kind = &kinds[creature.kind];
        let impact = collide_point_mass(creature, state, record, kind, &puck, &court, grid);
        if impact > kind.fall_impact_speed_m_per_s {
            falls.push(creature.serial, entity);
        }
    };
    let decision = clock.is_decision_tick();
    let puck_outran = !decision && puck.position.distance(watch.puck_from) > watch.puck_reach_m;
    if !decision {
        let watch = &mut *watch;
        watch.check_all |= tally.respawns != watch.respawns || puck_outran;
        let down = switched.read().filter(|s| s.from == Lod::Rigid).map(|s| s.creature);
        let before = watch.near.len();
        watch.near.extend(down);
        if watch.near.len() > before {
            watch.near.sort_unstable();
            watch.near.dedup();
        }
        if !watch.check_all {
            for &entity in &watch.near {
                if let Ok((entity, creature, mut state, mut record, ..)) = creatures.get_mut(entity) {
                    collide(entity, creature, &mut state, &mut record, None);
                }
            }
            return;
        }
    }
    let frame_s = clock.dt * clock.ticks_per_decision as f32;
    let puck_reach_m = config.arena.puck.speed_m_per_s * frame_s;
    let stepper = PlanarStepper::new(&kinds, &clock);
    let in_frame = clock.tick_in_frame();
    let widest_m = grid.fastest_and_widest().1;
    let chosen_now = &*chosen;
    let check = |entity: Entity,
                 creature: &Creature,
                 state: &mut PlanarState,
                 record: &mut CollisionRecord,
                 clearance: &Clearance,
                 player: bool,
                 (lod, desired, gait, pose, (frame, segment)): CatchUpItem| {
        if frame.behind {
            // The puck outran its reach (else the scan passed the creature by). Moved from the
            // frame's start: its stretch begins at the decision's tick.
            let first_tick = Some(clock.tick - in_frame);
            stepper.follow(
                creature,
                *lod,
                desired.0,
                (state, gait, pose),
                (frame, segment),
                first_tick,
            );
        }
        let kind = &kinds[creature.kind];
        // A contact may move it: a pose its catch-up left is that of where it was stepped to
        // (only when every creature is checked, after a respawn or a shove of the puck).
        frame.pose_now(kind, *lod, state, gait, pose);
        // Steering saw no creature near enough to touch now (but a player's creature does not steer).
        let clear = !player && clearance.clear_of_creatures(kind, widest_m, state.velocity.length(), clock.dt);
        collide(entity, creature, state, record, (decision && !clear).then_some(&*grid));
        if decision && clear {
            record.note(Obstacle::Creature, false);
        }
        if decision && could_reach_puck_or_wall(state, record, kind, &puck, puck_reach_m, court.half_extents, frame_s) {
            chosen_now.borrow_local_mut().push(entity);
        }
    };
    // Nothing watches these components' change ticks: the loops leave them alone (writing
    // them is a pass over a column of its own).
    // Every table's chunks in one scope (see `steer`).
    let mut tables: Vec<_> = creatures.contiguous_iter_mut().expect(DENSE).collect();
    let mut jobs = Vec::new();
    for (entity, creature, state, record, clearance, player, (lod, desired, gait, pose, (frame, segment))) in
        &mut tables
    {
        let player = *player;
        let n = chunk_len(config.scenario.creature_count(), entity.len());
        let (state, record) = (state.bypass_change_detection(), record.bypass_change_detection());
        let (gait, pose, frame) = (
            gait.bypass_change_detection(),
            pose.bypass_change_detection(),
            frame.bypass_change_detection(),
        );
        let segment = segment.bypass_change_detection();
        let chunks = ((entity.chunks(n).zip(creature.chunks(n)).zip(clearance.chunks(n)))
            .zip(state.chunks_mut(n).zip(record.chunks_mut(n))))
        .zip(
            (lod.chunks(n).zip(desired.chunks(n)))
                .zip((gait.chunks_mut(n).zip(pose.chunks_mut(n))).zip(frame.chunks_mut(n).zip(segment.chunks_mut(n)))),
        );
        jobs.extend(chunks.map(|((((e, c), cl), (s, r)), ((l, d), ((g, p), (f, seg))))| {
            move || {
                // A creature behind its frame is passed by unless the puck outran its reach: the
                // others are found by a scan of the flags alone (in a crowd nearly all are behind).
                let next = |f: &[FrameStep], i: usize| {
                    if puck_outran {
                        (i < f.len()).then_some(i)
                    } else {
                        FrameStep::next_not_behind(f, i)
                    }
                };
                let mut i = 0;
                while let Some(found) = next(f, i) {
                    i = found;
                    let catch_up = (&l[i], &d[i], &mut g[i], &mut p[i], (&mut f[i], &mut seg[i]));
                    check(e[i], &c[i], &mut s[i], &mut r[i], &cl[i], player, catch_up);
                    i += 1;
                }
            }
        }));
    }
    run_chunks(jobs.into_iter());
    drop(tables);
    if decision {
        switched.clear();
        let watch = &mut *watch;
        watch.near.clear();
        chosen.drain_into(&mut watch.near);
        watch.near.sort_unstable();
        watch.puck_from = puck.position;
        watch.puck_reach_m = puck_reach_m;
        watch.respawns = tally.respawns;
        watch.check_all = false;
    }
}

/// A row of [`CatchUp`] as the loop hands it on.
type CatchUpItem<'a> = (
    &'a Lod,
    &'a DesiredVelocity,
    &'a mut GaitPhase,
    &'a mut GaitPose,
    (&'a mut FrameStep, &'a mut PlanarSegment),
);

/// Removes the fallen and starts a new creature of the same kind in a free spot.
fn respawn_fallen(
    mut commands: Commands,
    clock: Res<SimClock>,
    config: Res<SimConfig>,
    kinds: Res<KindTable>,
    puck: Res<PuckState>,
    grid: Res<NeighbourGrid>,
    falls: Res<FallQueue>,
    mut tally: ResMut<Tally>,
    mut rng: ResMut<WorldRng>,
    mut newcomers: ResMut<Newcomers>,
    creatures: Query<(&Creature, &Lod, &CollisionRecord, &LevelChoice, &GaitPhase)>,
) {
    let mut fallen = falls.take();
    if fallen.is_empty() {
        return;
    }
    // A creature can be reported twice in a tick (a blow-up and a tilt): one removal.
    fallen.sort_unstable();
    fallen.dedup();
    let half = config.arena.half_extents();
    let clear = config.arena.respawn_creature_clearance_m;
    let puck_keep_out = puck.radius_m + config.arena.respawn_puck_clearance_m;
    for (_, entity) in fallen {
        let Ok((creature, lod, record, choice, gait)) = creatures.get(entity) else {
            continue;
        };
        let now = clock.seconds() as f32;
        tally.falls_after_switch +=
            u64::from(*lod == Lod::Rigid && choice.switched && now - choice.last_switch_s < gait.hop_period_s);
        tally.removed.add(record);
        tally.falls += 1;
        tally.falls_by_level[*lod] += 1;
        tally.respawns += 1;
        let radius = config.kinds[creature.kind].body.radius_m;
        let spot = find_free_spot(&mut rng, half, radius + clear, radius + clear, |p| {
            grid.clearance(p, radius + clear)
                .min(p.distance(puck.position) - puck_keep_out)
        });
        newcomers.placed_at.push(spot);
        commands.entity(entity).despawn();
        commands.spawn(creature_bundle(
            creature.kind,
            &kinds[creature.kind],
            newcomers.take(),
            *lod,
            spot,
            clock.seconds() as f32,
            &mut rng,
        ));
    }
}

pub(crate) fn advance_clock(mut clock: ResMut<SimClock>) {
    clock.tick += 1;
}

/// Milliseconds of simulation per 1/30 s, as the cost model predicts them from the levels
/// simulated (the court's fixed cost and each creature's level).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PredictedFrame {
    /// The predicted frame on average.
    pub mean_ms: f64,
    /// The slowest predicted frame: the frame rate a policy can promise.
    pub slowest_ms: f64,
}

/// Milliseconds of wall time each frame (1/30 s) took, as the headless runner measured them
/// outside the simulation: what the prediction is measured against. They differ between
/// identical runs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MeasuredFrame {
    /// The frames measured.
    pub frames: u64,
    /// Their mean.
    pub mean_ms: f64,
    /// Their median (the upper middle one of an even count).
    pub median_ms: f64,
    /// Their 99th percentile, by nearest rank: the slowest of every hundred.
    pub p99_ms: f64,
    /// The slowest of them.
    pub slowest_ms: f64,
}

impl MeasuredFrame {
    /// Of frames given in seconds; `None` without any.
    pub fn of(frames_s: &[f64]) -> Option<Self> {
        let mut sorted = frames_s.to_vec();
        sorted.sort_by(f64::total_cmp);
        let ms = |rank: usize| sorted[rank] * 1e3;
        let last = sorted.len().checked_sub(1)?;
        Some(Self {
            frames: sorted.len() as u64,
            mean_ms: sorted.iter().sum::<f64>() * 1e3 / sorted.len() as f64,
            median_ms: ms(sorted.len() / 2),
            p99_ms: ms(crate::lod::nearest_rank(sorted.len(), 99.0)),
            slowest_ms: ms(last),
        })
    }
}

/// What a run did, as the command line prints it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// The seed the run started from.
    pub seed: u64,
    /// Creatures in the world (constant: a fallen one is respawned).
    pub creatures: u64,
    /// Collisions by obstacle (`puck`, `wall`, `creature`); a contact between two creatures
    /// counts once for each.
    pub collisions: Counts<Obstacle, u64>,
    /// Creatures that collided with the puck or a wall (the paper's figure 10 measure).
    pub creatures_collided: u64,
    /// Creatures that collided with each obstacle at least once (figure 10's measure by
    /// obstacle: a creature that hit both counts under each).
    pub creatures_collided_with: Counts<Obstacle, u64>,
    /// Creatures that fell (knocked down, or at the rigid level, lost their balance).
    pub falls: u64,
    /// Falls by the level the creature was at when it fell.
    pub falls_by_level: Counts<Lod, u64>,
    /// Falls within one step (touchdown to touchdown) of a switch into the rigid level.
    pub falls_after_switch: u64,
    /// Creatures respawned after a fall.
    pub respawns: u64,
    /// Creatures at each level at the end.
    pub levels: Counts<Lod, u64>,
    /// Level switches: `total`, and by direction (`"hybrid->rigid"`, ...).
    pub switches: SwitchCounts,
    /// Of those, the switches off screen that no collision forced: not drawn, so not in
    /// `pops`.
    pub switches_unseen: u64,
    /// Creatures at each level, averaged over the run's steering decisions, and the peak.
    pub levels_mean: Counts<Lod, f64>,
    /// The most creatures at each level at any decision.
    pub levels_peak: Counts<Lod, u64>,
    /// The cost model's prediction of a frame from the levels simulated in it, whatever the
    /// policy: on average and the slowest.
    pub predicted_frame: PredictedFrame,
    /// The pops of the switches in what is drawn (all but `switches_unseen`), by kind of
    /// switch (from, to, forced by a collision or not): the largest and the 95th percentile.
    pub pops: Vec<PopSummary>,
    /// Under the budget policy: the budget, the predicted frame and the decisions over it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub budget: Option<BudgetSummary>,
    /// Simulated seconds.
    pub sim_seconds: f64,
    /// Each frame's wall time, where a headless runner measured it (`None` in the game); it
    /// differs between identical runs, as the two fields after it do.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_frame: Option<MeasuredFrame>,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// Simulated seconds per wall-clock second.
    pub realtime_factor: f64,
}

impl Summary {
    /// The summary without what the wall clock measured: identical runs give identical ones.
    pub fn without_wall_clock(self) -> Self {
        Self {
            measured_frame: None,
            wall_seconds: 0.0,
            realtime_factor: 0.0,
            ..self
        }
    }
}

/// Reads the counts out of a world (creatures alive now plus those removed).
pub fn summarize(world: &mut World, wall_seconds: f64) -> Summary {
    let tally = world.resource::<Tally>().clone();
    let clock = *world.resource::<SimClock>();
    let config = world.resource::<SimConfig>();
    let seed = config.scenario.seed;
    let budget = (config.scenario.level_policy == LevelPolicy::Budget)
        .then(|| world.resource::<BudgetTally>().summary(&config.rules.budget));
    let mut totals = tally.removed;
    let mut levels: Counts<Lod, u64> = Counts::default();
    let mut creatures = 0;
    let mut query = world.query::<(&Lod, &CollisionRecord)>();
    for (&lod, record) in query.iter(world) {
        creatures += 1;
        levels[lod] += 1;
        totals.add(record);
    }
    let sim_seconds = clock.seconds();
    let switching = world.resource::<SwitchTally>().clone();
    let pops = world.resource::<PopTally>().summary();
    let samples = switching.samples.max(1) as f64;
    Summary {
        switches: switching.switches,
        switches_unseen: switching.unseen,
        levels_mean: Counts::from_fn(|l| switching.level_sums[l] as f64 / samples),
        levels_peak: switching.level_peaks,
        predicted_frame: PredictedFrame {
            mean_ms: switching.predicted_frame_sum_us / samples / 1e3,
            slowest_ms: switching.predicted_frame_max_us / 1e3,
        },
        pops,
        budget,
        seed,
        creatures,
        collisions: totals.collisions,
        creatures_collided: totals.collided,
        creatures_collided_with: totals.collided_with,
        falls: tally.falls,
        falls_by_level: tally.falls_by_level,
        falls_after_switch: tally.falls_after_switch,
        respawns: tally.respawns,
        levels,
        sim_seconds,
        measured_frame: None,
        wall_seconds,
        realtime_factor: if wall_seconds > 0.0 {
            sim_seconds / wall_seconds
        } else {
            f64::INFINITY
        },
    }
}

/// A new run counts from zero.
fn reset_tally(mut tally: ResMut<Tally>) {
    *tally = Tally::default();
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.init_resource::<FallQueue>()
        .init_resource::<Tally>()
        .add_systems(SimStart, reset_tally)
        .add_systems(schedule, detect_collisions.in_set(SimStage::Observe))
        .add_systems(schedule, plan_frames.in_set(SimStage::Step).before(step_point_masses))
        .add_systems(
            schedule,
            (
                respawn_fallen.in_set(SimStage::Outcome),
                advance_clock.in_set(SimStage::Clock),
            ),
        );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::point_mass::tests::kind;

    #[test]
    fn only_a_creature_that_could_reach_the_puck_or_a_wall_within_a_frame_is_watched() {
        // 3 m/s top speed and a 5 m/s puck for 1/30 s: 0.1 + 0.167 m, and 1 cm of slack.
        let (k, frame_s, puck_reach) = (kind(), 1.0 / 30.0, 5.0 / 30.0);
        let puck = PuckState {
            position: Vec2::ZERO,
            velocity: Vec2::X * 5.0,
            radius_m: 2.0,
        };
        let half = Vec2::new(30.0, 20.0);
        let near = |x: f32, y: f32, speed: f32| {
            let state = PlanarState {
                position: Vec2::new(x, y),
                velocity: Vec2::Y * speed,
                ..default()
            };
            could_reach_puck_or_wall(
                &state,
                &CollisionRecord::default(),
                &k,
                &puck,
                puck_reach,
                half,
                frame_s,
            )
        };
        // The rims 0.26 m apart: met within the frame; 0.3 m apart: not.
        assert!(near(2.56, 0.0, 0.0));
        assert!(!near(2.6, 0.0, 0.0));
        // The wall 0.1 m away: reached at top speed; 0.2 m: not, unless shoved faster.
        assert!(near(0.0, 19.6, 0.0));
        assert!(!near(0.0, 19.5, 0.0));
        assert!(near(0.0, 19.5, 7.0));
        // Touching one already: watched, to note the contact's end.
        let record = CollisionRecord {
            touching: [false, true, false],
            ..default()
        };
        let far = PlanarState {
            position: Vec2::splat(10.0),
            ..default()
        };
        assert!(could_reach_puck_or_wall(
            &far, &record, &k, &puck, puck_reach, half, frame_s
        ));
    }
}
