//! simlod: simulation levels of detail for real-time animation.
//!
//! After Carlson & Hodgins, *Simulation Levels of Detail for Real-time Animation*
//! (Graphics Interface '97). Legged creatures try to escape a giant puck in a walled court;
//! each is simulated at a level of detail ([`lod::Lod`]) chosen per creature.
//!
//! The paper's pipeline is the layout. Once per simulation tick, in `FixedUpdate`:
//!
//! | stage | module | what |
//! |---|---|---|
//! | [`SimStage::Sense`] | [`sense`] | spatial index of creatures; the puck's state |
//! | [`SimStage::Steer`] | [`creature::steering`] | desired velocity: flee the puck, avoid walls and others |
//! | [`SimStage::SelectLod`] | [`lod`] | the level each creature should be at: influence areas, camera rule |
//! | [`SimStage::Switch`] | [`lod`] | a change of level, inside the flight-phase window |
//! | [`SimStage::Step`] | [`models`] | the model of each creature's level |
//! | rapier's `PhysicsSet`s | [`arena`] | the puck and walls (rapier bodies) |
//! | [`SimStage::Observe`] | [`outcome`] | collisions with the puck, walls and other creatures |
//! | [`SimStage::Outcome`] | [`outcome`] | fallen creatures removed and respawned; the clock |
//!
//! # Where to start
//!
//! - [`config::SimConfig::load`] reads a scenario and every file it names from an assets
//!   folder, checked; [`SimPlugin`] adds the simulation it describes to an `App`.
//! - [`headless::HeadlessSim`] drives that app a frame at a time without a window, and
//!   [`headless::run`] runs a scenario and returns its [`outcome::Summary`].
//! - Each creature is an entity with a [`creature::Creature`] and its level, [`lod::Lod`];
//!   every level publishes [`creature::PlanarState`], [`creature::GaitPhase`] and
//!   [`gait::GaitPose`], which is all the rest of the program reads.
//! - The level policy and rules are fields of the [`config::SimConfig`] resource, read at
//!   every steering decision: [`lod::LevelPolicy`], [`config::LevelRules`].
//!
//! The `examples/` folder has four runnable programs, and `docs/guide/` the user guide.

#![warn(missing_docs)]

/// Runs a closure over every item of a query, across threads only when there are enough
/// creatures to pay for waking them.
macro_rules! for_each_creature {
    ($population:expr, $query:expr, $f:expr) => {{
        let f = $f;
        if $population < $crate::PARALLEL_MIN_CREATURES {
            $query.iter_mut().for_each(f)
        } else {
            $query.par_iter_mut().for_each(f)
        }
    }};
}

/// Below this many creatures a loop over them stays on one thread.
pub const PARALLEL_MIN_CREATURES: u32 = 2048;

/// Why a loop's query can be iterated column by column (Bevy's contiguous iteration).
pub(crate) const DENSE: &str = "table components and archetype filters only: a dense query";

/// How many of `len` items (a table's column) each thread takes in a loop over creatures: all
/// of them below [`PARALLEL_MIN_CREATURES`].
pub fn chunk_len(population: u32, len: usize) -> usize {
    let threads = if population < PARALLEL_MIN_CREATURES {
        1
    } else {
        bevy::tasks::ComputeTaskPool::get().thread_num().max(1)
    };
    len.div_ceil(threads).max(1)
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

pub mod arena;
pub mod config;
pub mod creature;
pub mod gait;
pub mod headless;
pub mod lod;
pub mod models;
pub mod outcome;
pub mod sense;
pub mod third_party;

use bevy::ecs::schedule::{ScheduleLabel, SingleThreadedExecutor};
use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use rand::SeedableRng;
use rand::rngs::StdRng;

use config::SimConfig;

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
    /// Fallen creatures removed and respawned; the counters and the clock.
    Outcome,
}

/// Builds the simulated world from [`SimConfig`]: run once at `Startup`, and again by
/// [`start_over`]. Each module adds the systems that set up its part of the world here.
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
}

impl SimClock {
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

/// The headless simulation core: add it to any `App` (the game's or a test's).
pub struct SimPlugin {
    /// The scenario, loaded and checked, with every file it names.
    pub config: SimConfig,
}

/// The resources a run starts from: the config, its seeded RNG, a clock at tick 0, and the
/// fixed timestep (rapier keeps its own copy).
fn insert_run_resources(world: &mut World, config: SimConfig) {
    let scenario = &config.scenario;
    let dt = 1.0 / scenario.tick_hz as f32;
    world.insert_resource(WorldRng(StdRng::seed_from_u64(scenario.seed)));
    world.insert_resource(SimClock {
        tick: 0,
        dt,
        tick_hz: scenario.tick_hz,
        ticks_per_decision: scenario.ticks_per_decision(),
    });
    world.insert_resource(Time::<Fixed>::from_seconds(f64::from(dt)));
    third_party::rapier::set_timestep(world, dt);
    world.insert_resource(config);
}

/// Starts the simulation over from `config`, as if the app had just been built with it:
/// every [`SimEntity`] is removed and [`SimStart`] builds the world again. The game calls it
/// for a new round and when an asset file is edited; call it between ticks.
pub fn start_over(world: &mut World, config: SimConfig) {
    let old: Vec<Entity> = world.query_filtered::<Entity, With<SimEntity>>().iter(world).collect();
    for entity in old {
        world.despawn(entity);
    }
    third_party::rapier::empty_world(world);
    insert_run_resources(world, config);
    world.run_schedule(SimStart);
}

fn run_sim_start(world: &mut World) {
    world.run_schedule(SimStart);
}

impl Plugin for SimPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<TransformPlugin>() {
            app.add_plugins(TransformPlugin);
        }
        insert_run_resources(app.world_mut(), self.config.clone());
        third_party::plugin(app);
        app.init_schedule(SimStart)
            .add_systems(Startup, run_sim_start)
            .configure_sets(
                FixedUpdate,
                (
                    SimStage::Sense,
                    SimStage::Steer,
                    SimStage::SelectLod,
                    SimStage::Switch,
                    SimStage::Step,
                )
                    .chain()
                    .before(PhysicsSet::SyncBackend),
            )
            .configure_sets(
                FixedUpdate,
                (SimStage::Observe, SimStage::Outcome)
                    .chain()
                    .after(PhysicsSet::Writeback),
            );
        // The stages are one chain: running it on one thread saves the wake-ups of the others
        // (~20 us each on a small VM); the loops over creatures still spread over threads.
        app.edit_schedule(FixedUpdate, |s| {
            s.set_executor(SingleThreadedExecutor::new());
        });
        config::plugin(app);
        gait::plugin(app);
        arena::plugin(app);
        creature::plugin(app);
        lod::plugin(app);
        sense::plugin(app);
        models::plugin(app);
        outcome::plugin(app);
    }
}
