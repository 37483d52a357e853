//! Switch: a change of level waits for the flight-phase window (paper 3.4: "we achieve a
//! smooth transition by allowing switching only during a particular part of the flight phase
//! of the running cycle"). A collision cannot wait: a creature below the rigid level that
//! collides switches to rigid at once.
//!
//! The state every level shares is carried across: position, velocity, heading and hop phase
//! (they live on the creature entity, not in a model). Going rigid builds the bodies at the
//! planar position and heading, the body at the height the gait table gives for that speed
//! and phase, moving at the planar velocity (see [`crate::models::rigid`]). Leaving the rigid
//! level removes its bodies.

use bevy::prelude::*;

use super::Lod;
use super::select::{LevelChoice, levels_may_change};
use crate::creature::{Creature, GaitPhase, KindTable, PlanarState};
use crate::gait::GaitPose;
use crate::models::rigid::{Raibert, RigidHopper};
use crate::outcome::CollisionRecord;
use crate::{SimClock, SimStage, SimStart};

/// A creature changed level.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct LevelSwitched {
    pub creature: Entity,
    pub serial: u32,
    pub from: Lod,
    pub to: Lod,
    /// How far through its flight phase it was (0 lift-off, 1 touchdown); `None` when a
    /// collision forced the switch.
    pub flight_progress: Option<f32>,
    pub at_s: f32,
}

/// Switches and creatures per level over the run.
#[derive(Resource, Clone, Debug, Default)]
pub struct SwitchTally {
    /// Switches by [from][to] level.
    pub switches: [[u64; 3]; 3],
    /// Sums and peaks of the creatures at each level, sampled at each decision.
    pub level_sums: [u64; 3],
    pub level_peaks: [u64; 3],
    pub samples: u64,
}

impl SwitchTally {
    pub fn total(&self) -> u64 {
        self.switches.iter().flatten().sum()
    }
}

/// How far through its flight the creature is, if it is in flight.
fn flight_progress(lod: Lod, gait: &GaitPhase, raibert: Option<&Raibert>, stance: f32, now: f32) -> Option<f32> {
    if !gait.in_flight {
        return None;
    }
    Some(match (lod, raibert) {
        (Lod::Rigid, Some(r)) => ((now - r.last_liftoff_s) / (r.hop_period_s - r.stance_s).max(1e-3)).clamp(0.0, 1.0),
        _ => ((gait.cycle - stance) / (1.0 - stance).max(1e-3)).clamp(0.0, 1.0),
    })
}

fn switch_levels(
    mut commands: Commands,
    clock: Res<SimClock>,
    config: Res<crate::config::SimConfig>,
    kinds: Res<KindTable>,
    mut tally: ResMut<SwitchTally>,
    mut switched: MessageWriter<LevelSwitched>,
    mut creatures: Query<(
        Entity,
        &Creature,
        &mut Lod,
        &mut LevelChoice,
        &GaitPhase,
        &PlanarState,
        &CollisionRecord,
        &mut GaitPose,
        Option<&Raibert>,
    )>,
) {
    let now = clock.seconds() as f32;
    let (open, close) = config.rules.flight_window;
    for (entity, creature, mut lod, mut choice, gait, state, record, mut pose, raibert) in &mut creatures {
        let kind = &kinds[creature.kind];
        let forced =
            *lod != Lod::Rigid && record.touching.iter().any(|&t| t) && kind.best_level(Lod::Rigid) == Lod::Rigid;
        let target = if forced { Lod::Rigid } else { choice.wanted };
        if target == *lod {
            continue;
        }
        let stance = match &kind.gait {
            Some(table) if *lod == Lod::Hybrid => table.rhythm(state.velocity.length()).1,
            _ => kind.stance_fraction,
        };
        let progress = flight_progress(*lod, gait, raibert, stance, now);
        if !forced && !progress.is_some_and(|p| (open..=close).contains(&p)) {
            continue;
        }
        if *lod == Lod::Rigid {
            commands.entity(entity).remove::<(RigidHopper, Raibert)>();
        }
        if target == Lod::PointMass {
            *pose = kind.standing_pose;
        }
        tally.switches[*lod as usize][target as usize] += 1;
        switched.write(LevelSwitched {
            creature: entity,
            serial: creature.serial,
            from: *lod,
            to: target,
            flight_progress: if forced { None } else { progress },
            at_s: now,
        });
        *lod = target;
        *choice = LevelChoice {
            wanted: target,
            last_switch_s: now,
        };
    }
}

/// Samples the creatures per level at each decision.
fn count_levels(clock: Res<SimClock>, mut tally: ResMut<SwitchTally>, levels: Query<&Lod>) {
    if !clock.is_decision_tick() {
        return;
    }
    let mut counts = [0u64; 3];
    for lod in &levels {
        counts[*lod as usize] += 1;
    }
    tally.samples += 1;
    for (i, n) in counts.into_iter().enumerate() {
        tally.level_sums[i] += n;
        tally.level_peaks[i] = tally.level_peaks[i].max(n);
    }
}

fn reset_switch_tally(mut tally: ResMut<SwitchTally>) {
    *tally = SwitchTally::default();
}

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<SwitchTally>()
        .add_message::<LevelSwitched>()
        .add_systems(SimStart, reset_switch_tally)
        .add_systems(
            FixedUpdate,
            switch_levels.in_set(SimStage::Switch).run_if(levels_may_change),
        )
        .add_systems(FixedUpdate, count_levels.in_set(SimStage::Observe));
}
