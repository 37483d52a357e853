//! Switch: a change of level waits for the flight-phase window (paper 3.4: "we achieve a
//! smooth transition by allowing switching only during a particular part of the flight phase
//! of the running cycle"). A collision cannot wait: a creature below the rigid level that
//! collides switches to rigid at once. Nor need a point mass off screen wait: no one sees it
//! switch, and the view may be turning toward it.
//!
//! The state every level shares is carried across: position, velocity, heading, gait phase
//! and pose (they live on the creature entity, not in a model). The switch knows nothing of
//! what a level is made of: it inserts the new [`Lod`], whose hooks move the level markers,
//! and each level's observers build or tear down its model (see [`crate::models`]).

use bevy::prelude::*;

use super::blend::{Drawn, DrawnBefore, SwitchBlend, SwitchProbe};
use super::select::{LevelChoice, SimCamera, levels_may_change};
use super::{LevelPolicy, Lod};
use crate::contract::GaitPose;
use crate::contract::{CollisionRecord, Counts, SwitchCounts};
use crate::contract::{DENSE, SimClock, SimStage, SimStart};
use crate::contract::{GaitPhase, PlanarState};
use crate::kind::{Creature, KindParams, KindTable};
use crate::models::point_mass::FrameStep;

/// A creature changed level.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct LevelSwitched {
    /// The creature's entity.
    pub creature: Entity,
    /// The creature's serial.
    pub serial: u32,
    /// The level it left.
    pub from: Lod,
    /// The level it entered.
    pub to: Lod,
    /// How far through its flight phase it was (0 lift-off, 1 touchdown); `None` when the
    /// switch did not wait for the window (a collision, or a point mass off screen).
    pub flight_progress: Option<f32>,
    /// Simulated seconds at the switch.
    pub at_s: f32,
}

/// Switches and creatures per level over the run.
#[derive(Resource, Clone, Debug, Default)]
pub struct SwitchTally {
    /// Switches by where they came from and went to.
    pub switches: SwitchCounts,
    /// Of those, the switches off screen that no collision forced: not drawn, so neither
    /// blended nor measured for their pop.
    pub unseen: u64,
    /// Sums and peaks of the creatures at each level, sampled at each decision.
    pub level_sums: Counts<Lod, u64>,
    /// The most creatures at each level at any sampled decision.
    pub level_peaks: Counts<Lod, u64>,
    /// How many decisions were sampled.
    pub samples: u64,
    /// The cost model's prediction of each sampled frame from the levels simulated in it (the
    /// fixed cost and each creature's level; not the policy's own choice): its sum and the
    /// slowest, in microseconds. Every policy's, so they compare on what they guarantee.
    /// (Summed in f64, where the f32 costs add exactly: the same whatever the creatures' order.)
    pub predicted_frame_sum_us: f64,
    /// The slowest predicted frame, us (see `predicted_frame_sum_us`).
    pub predicted_frame_max_us: f64,
}

fn switch_levels(
    mut commands: Commands,
    clock: Res<SimClock>,
    config: Res<crate::config::SimConfig>,
    kinds: Res<KindTable>,
    camera: Res<SimCamera>,
    mut tally: ResMut<SwitchTally>,
    mut switched: MessageWriter<LevelSwitched>,
    mut kept: Local<(Vec<Entity>, Vec<Entity>)>,
    mut creatures: Query<(
        Entity,
        &Creature,
        &Lod,
        &mut LevelChoice,
        &GaitPhase,
        &CollisionRecord,
        (&PlanarState, &mut GaitPose, &mut DrawnBefore),
        &mut FrameStep,
    )>,
    blends: Query<&SwitchBlend>,
) {
    let now = clock.seconds() as f32;
    let (open, close) = config.rules.flight_window;
    let policy = config.scenario.level_policy;
    let rules_move_levels = policy.is_dynamic();
    // Most ticks nothing switches: one pass over the columns finds the creatures that want
    // another level or might be forced to rigid, then they switch in the order of their ids, not
    // the query's: the tables' order moves with components that change nothing simulated (a
    // blend's), and the order of switches is the order rigid bodies are built and numbered in
    // rapier, whose rounding follows it. A creature behind its frame is passed by:
    // it wanted its level and touched nothing at the decision, and until the frame's last tick
    // nothing changes either (the choice is made at decisions, and a contact check that finds
    // it first catches it up). Of those that waited for their window last tick, the others let
    // go of the drawing they kept.
    let attends = |lod: Lod, choice: &LevelChoice, record: &CollisionRecord| {
        let may_be_forced = rules_move_levels && lod != Lod::Rigid && record.touching.iter().any(|&t| t);
        choice.wanted != lod || may_be_forced
    };
    // Under a fixed policy ("every creature at the point-mass level") a collision does not
    // overrule it; under the budget policy only a rigid level the budget paid for skips the
    // window.
    let forced = |kind: &KindParams, lod: Lod, choice: &LevelChoice, record: &CollisionRecord| {
        rules_move_levels
            && lod != Lod::Rigid
            && record.touching.iter().any(|&t| t)
            && kind.best_level(Lod::Rigid) == Lod::Rigid
            && (policy != LevelPolicy::Budget || choice.wanted == Lod::Rigid)
    };
    let unseen = |kind: &KindParams, state: &PlanarState| !camera.shows(kind, state);
    let in_window = |gait: &GaitPhase| gait.flight_progress().is_some_and(|p| (open..=close).contains(&p));
    // A creature waiting out of view for its window is passed by until it is in it: no one
    // sees its switch, so no drawing is kept for its blend. A crowd's hybrids leaving the view
    // wait by the hundred: 20,000 sent to the point mass at once took 590 ms of frames until
    // the last had switched when each was looked up and drawn at every tick, 316 ms passed by
    // (2026-11-29).
    let waits_unseen =
        |kind: &KindParams, lod: Lod, choice: &LevelChoice, gait, record, state, before: &DrawnBefore| {
            let forced = forced(kind, lod, choice, record);
            !forced
                && choice.wanted != lod
                && before.0.is_none()
                && lod != Lod::PointMass
                && !in_window(gait)
                && unseen(kind, state)
        };
    let (attend, waiting) = &mut *kept;
    attend.clear();
    for (entity, creature, lod, choice, gait, record, (state, _, before), frame) in
        creatures.as_readonly().contiguous_iter().expect(DENSE)
    {
        let mut i = 0;
        while let Some(next) = FrameStep::next_not_behind(frame, i) {
            i = next;
            let (lod, choice, record) = (lod[i], &choice[i], &record[i]);
            if attends(lod, choice, record) {
                let kind = &kinds[creature[i].kind];
                if !waits_unseen(kind, lod, choice, &gait[i], record, &state[i], &before[i]) {
                    attend.push(entity[i]);
                }
            }
            i += 1;
        }
    }
    attend.sort_unstable();
    for entity in waiting.drain(..) {
        if let Ok((_, _, &lod, choice, _, record, (_, _, mut before), _)) = creatures.get_mut(entity)
            && !attends(lod, &choice, record)
        {
            before.0 = None;
        }
    }
    for &entity in attend.iter() {
        let Ok((entity, creature, &lod, mut choice, gait, record, (state, mut pose, mut before), mut frame)) =
            creatures.get_mut(entity)
        else {
            continue;
        };
        let kind = &kinds[creature.kind];
        let forced = forced(kind, lod, &choice, record);
        let target = if forced { Lod::Rigid } else { choice.wanted };
        if target == lod {
            if before.0.is_some() {
                before.0 = None;
            }
            continue;
        }
        let unseen = unseen(kind, state);
        let skips_window = forced || (unseen && lod == Lod::PointMass);
        if !skips_window && !in_window(gait) && unseen {
            // Out of view since it last waited in it: its drawing is let go.
            before.0 = None;
            continue;
        }
        // Left unposed at its frame's catch-up, if nothing read it then.
        if frame.pose_stale {
            frame.pose_now(kind, lod, state, gait, &mut pose);
        }
        // What is drawn now (as the last tick left it), blended and by the model alone.
        let model = Drawn::of(state, &pose);
        let seen = (blends.get(entity).map_or(model, |b| b.apply(&model, now)), model);
        let progress = gait.flight_progress();
        if !skips_window && !in_window(gait) {
            before.0 = Some(seen);
            waiting.push(entity);
            continue;
        }
        // A creature that switches without waiting (a collision) has no drawing kept from
        // the tick before: its body is taken to have moved at its velocity, its legs to have
        // held still.
        let earlier = before.0.take().unwrap_or_else(|| {
            let back = |d: Drawn| Drawn {
                body: d.body - Vec3::new(state.velocity.x, 0.0, state.velocity.y) * clock.dt,
                ..d
            };
            (back(seen.0), back(seen.1))
        });
        // A switch no one sees is neither blended nor measured for its pop: a crowd's point
        // masses coming into the view's reach switch by the thousand in one frame, and the
        // probe and the blend doubled what each cost.
        if unseen && !forced {
            commands.entity(entity).insert(target);
            tally.unseen += 1;
        } else {
            commands.entity(entity).insert((
                target,
                SwitchProbe::new(lod, target, forced, [earlier.0, seen.0], [earlier.1, seen.1]),
            ));
        }
        tally.switches.count(lod, target);
        switched.write(LevelSwitched {
            creature: entity,
            serial: creature.serial,
            from: lod,
            to: target,
            flight_progress: if skips_window { None } else { progress },
            at_s: now,
        });
        *choice = LevelChoice {
            wanted: target,
            last_switch_s: now,
            switched: true,
            ..*choice
        };
    }
}

/// Samples the creatures per level at each decision, and what the cost model predicts the
/// frame costs.
fn count_levels(
    clock: Res<SimClock>,
    config: Res<crate::config::SimConfig>,
    mut tally: ResMut<SwitchTally>,
    levels: Query<(&Lod, &Creature)>,
) {
    if !clock.is_decision_tick() {
        return;
    }
    let mut counts: Counts<Lod, u64> = Counts::default();
    let mut per_kind = vec![Counts::<Lod, u64>::default(); config.kinds.len()];
    for (&lod, c) in &levels {
        counts[lod] += 1;
        per_kind[c.kind][lod] += 1;
    }
    let costs = config.costs_by_kind(counts[Lod::Rigid] as u32);
    let mut frame_us = f64::from(config.costs.fixed_us_per_frame);
    for (costs, n) in costs.iter().zip(&per_kind) {
        for (lod, n) in n.iter() {
            frame_us += f64::from(costs.per_frame_us(lod)) * n as f64;
        }
    }
    tally.samples += 1;
    tally.predicted_frame_sum_us += frame_us;
    tally.predicted_frame_max_us = tally.predicted_frame_max_us.max(frame_us);
    for (lod, n) in counts.iter() {
        tally.level_sums[lod] += n;
        tally.level_peaks[lod] = tally.level_peaks[lod].max(n);
    }
}

fn reset_switch_tally(mut tally: ResMut<SwitchTally>) {
    *tally = SwitchTally::default();
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.init_resource::<SwitchTally>()
        .add_message::<LevelSwitched>()
        .add_systems(SimStart, reset_switch_tally)
        .add_systems(
            schedule,
            switch_levels.in_set(SimStage::Switch).run_if(levels_may_change),
        )
        .add_systems(schedule, count_levels.in_set(SimStage::Observe));
}
