//! The level contract: what every level of detail publishes and the rest of the program reads
//! (the level, the body on the plane, the gait's phase and pose, contacts and falls), the
//! stages of a tick and the clock. The bottom layer: it imports nothing of simlod.

mod contact;
pub mod counts;
mod level;
mod motion;
mod pose;

use bevy::ecs::schedule::{InternedScheduleLabel, ScheduleLabel};
use bevy::prelude::*;
use rand::rngs::StdRng;

pub use contact::{CollisionRecord, FallQueue, Ground, Obstacle, Puck, Wall};
pub use counts::{Counts, Key, SwitchCounts};
pub use level::{AtHybrid, AtPointMass, AtRigid, Lod};
pub use motion::{DesiredVelocity, GaitPhase, PlanarState, PlayerControlled};
pub use pose::{GaitPose, LegPose, MAX_LEGS};

/// Below this many creatures a loop over them stays on one thread.
pub const PARALLEL_MIN_CREATURES: u32 = 2048;

/// Why a loop's query can be iterated column by column (Bevy's contiguous iteration).
pub const DENSE: &str = "table components and archetype filters only: a dense query";

/// How many of `len` items (a table's column) each thread takes in a loop over creatures: all
/// of them below [`PARALLEL_MIN_CREATURES`], or where there is no compute pool (outside an app).
pub fn chunk_len(population: u32, len: usize) -> usize {
    len.div_ceil(threads_for(population)).max(1)
}

/// The threads a loop over a `population` of creatures runs on: one below
/// [`PARALLEL_MIN_CREATURES`] or where there is no compute pool (outside an app).
pub fn threads_for(population: u32) -> usize {
    if population < PARALLEL_MIN_CREATURES {
        1
    } else {
        bevy::tasks::ComputeTaskPool::try_get().map_or(1, |pool| pool.thread_num().max(1))
    }
}

/// Runs one job per chunk of [`chunk_len`] across the compute pool; a lone job runs here.
pub fn run_chunks<J: FnOnce() + Send>(jobs: impl Iterator<Item = J>) {
    let mut jobs = jobs.peekable();
    let Some(first) = jobs.next() else { return };
    if jobs.peek().is_none() {
        return first();
    }
    bevy::tasks::ComputeTaskPool::get().scope(|scope| {
        for job in std::iter::once(first).chain(jobs) {
            scope.spawn(async move { job() });
        }
    });
}

/// The stages of one simulation tick, in the paper's order. Declared once, here.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimStage {
    /// Spatial index of creatures; the puck's state (runs at each decision).
    Sense,
    /// Each creature's desired velocity: flee the puck, avoid walls and others (at each decision).
    Steer,
    /// The level each creature wants: areas of influence, the camera rule, or the budget (paper 3.4).
    SelectLod,
    /// A change of level, in the flight window or at once on a collision.
    Switch,
    /// Each creature's model at its level (paper 3.1-3.3).
    Step,
    /// Collisions with the puck, walls and other creatures; falls.
    Observe,
    /// Fallen creatures removed and respawned; the counters.
    Outcome,
    /// The tick ends: the clock moves on.
    Clock,
}

/// Builds the simulated world from [`crate::config::SimConfig`]: run once at `Startup`, and again by
/// [`crate::start_over`]. Each module adds the systems that set up its part of the world here.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct SimStart;

/// Part of the simulated world (court, puck, creatures): removed when the world starts over.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct SimEntity;

/// The world's one random number generator, seeded from the scenario (or `--seed`).
#[derive(Resource)]
pub struct WorldRng(pub StdRng);

/// Simulated time, counted in fixed ticks. The simulation never reads the wall clock.
#[derive(Resource, Clone, Copy, Debug)]
pub struct SimClock {
    /// Ticks completed so far; during a tick, the index of that tick.
    pub tick: u64,
    /// Seconds per tick (1 / `tick_hz`).
    pub dt: f32,
    /// Ticks per simulated second.
    pub tick_hz: u32,
    /// Ticks per steering decision (`tick_hz / decision_hz`).
    pub ticks_per_decision: u32,
    /// The schedule the ticks run in (`FixedUpdate` unless the host chose another).
    pub schedule: InternedScheduleLabel,
}

impl SimClock {
    /// The schedule a layer adds its tick's systems to: the clock's, else `FixedUpdate`.
    pub fn schedule_of(app: &App) -> InternedScheduleLabel {
        app.world()
            .get_resource::<SimClock>()
            .map_or_else(|| FixedUpdate.intern(), |clock| clock.schedule)
    }

    /// Steering and the spatial index run on these ticks only (the decision rate).
    pub fn is_decision_tick(&self) -> bool {
        self.tick.is_multiple_of(u64::from(self.ticks_per_decision))
    }

    /// Index of the current steering decision.
    pub fn decision(&self) -> u64 {
        self.tick / u64::from(self.ticks_per_decision)
    }

    /// Simulated seconds so far.
    pub fn seconds(&self) -> f64 {
        self.seconds_at(self.tick)
    }

    /// Simulated seconds at the start of `tick`.
    pub fn seconds_at(&self, tick: u64) -> f64 {
        tick as f64 / f64::from(self.tick_hz)
    }

    /// Which tick of its decision's frame this is: 0 at the decision.
    pub fn tick_in_frame(&self) -> u64 {
        self.tick % u64::from(self.ticks_per_decision)
    }
}

/// The steps of building the world at [`SimStart`], in order. Declared once, with the tick's
/// stages, by [`crate::SimPlugin`].
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StartStage {
    /// The court, its walls and the puck.
    Arena,
    /// The creatures, placed.
    Creatures,
    /// The spatial index of the creatures as placed.
    Index,
    /// Each creature's first level, chosen by the rules.
    Levels,
}
