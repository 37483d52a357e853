//! The plugin that puts the layers together: the stages of a tick in the paper's order, the
//! world built at [`SimStart`], and each layer's systems.

use bevy::ecs::schedule::{InternedScheduleLabel, ScheduleLabel, SingleThreadedExecutor};
use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use rand::SeedableRng;
use rand::rngs::StdRng;

use crate::config::{self, SimConfig};
use crate::contract::{SimClock, SimEntity, SimStage, SimStart, StartStage, WorldRng};
use crate::models::rigid::RigidPart;
use crate::{arena, creature, lod, models, outcome, sense, third_party};

/// The simulation: add it to any `App` (the game's, a test's, your own).
///
/// What it asks of the app, plainly:
/// - **Its schedule** runs once per tick of `1 / tick_hz` seconds (the scenario's). By default
///   that is `FixedUpdate`, and the plugin sets `Time<Fixed>` to the tick; in a schedule of your
///   own ([`SimPlugin::in_schedule`]) it leaves `Time<Fixed>` alone and you run the schedule.
///   [`SimClock::schedule`] says which it is.
/// - **Rapier** runs in the same schedule, stepping once a tick with the scenario's solver
///   iterations. Add rapier yourself first (then put it in that schedule) or let the plugin add
///   it. A new round ([`start_over`]) removes only simlod's bodies where rapier holds bodies of
///   yours; where it holds only simlod's, it empties rapier's world, so that the round plays bit
///   for bit like a fresh start.
/// - **The executor**: by default it runs its schedule on one thread, which saves the wake-ups
///   of the others on small machines (its loops over creatures still use every core);
///   [`SimPlugin::keep_host_executor`] leaves yours.
///
/// Everything it spawns carries [`SimEntity`]. Of what the app already has, it sets `Time<Fixed>`
/// (in `FixedUpdate`), rapier's `TimestepMode` and solver parameters, and, unless told to keep
/// it, its schedule's executor.
pub struct SimPlugin {
    /// The scenario, loaded and checked, with every file it names.
    pub config: SimConfig,
    /// The schedule each tick's systems run in.
    pub schedule: InternedScheduleLabel,
    /// Whether the plugin may run its schedule on one thread.
    pub single_threaded: bool,
}

impl SimPlugin {
    /// The simulation of `config`, in `FixedUpdate`.
    pub fn new(config: SimConfig) -> Self {
        Self {
            config,
            schedule: FixedUpdate.intern(),
            single_threaded: true,
        }
    }

    /// Runs each tick's systems in `schedule`, which the host runs once per tick.
    pub fn in_schedule(mut self, schedule: impl ScheduleLabel) -> Self {
        self.schedule = schedule.intern();
        self
    }

    /// Leaves the executor of the schedule as the host set it.
    pub fn keep_host_executor(mut self) -> Self {
        self.single_threaded = false;
        self
    }
}

/// The resources a run starts from: the config, its seeded RNG and a clock at tick 0 in
/// `schedule`; the fixed timestep where that is `FixedUpdate` (rapier keeps its own copy).
fn insert_run_resources(world: &mut World, config: SimConfig, schedule: InternedScheduleLabel) {
    let scenario = &config.scenario;
    let dt = 1.0 / scenario.tick_hz as f32;
    world.insert_resource(WorldRng(StdRng::seed_from_u64(scenario.seed)));
    world.insert_resource(SimClock {
        tick: 0,
        dt,
        tick_hz: scenario.tick_hz,
        ticks_per_decision: scenario.ticks_per_decision(),
        schedule,
    });
    if schedule == FixedUpdate.intern() {
        world.insert_resource(Time::<Fixed>::from_seconds(f64::from(dt)));
    }
    third_party::rapier::set_timestep(world, dt);
    world.insert_resource(config);
}

/// Starts the simulation over from `config`, as if the app had just been built with it:
/// every [`SimEntity`] is removed and [`SimStart`] builds the world again. The game calls it
/// for a new round and when an asset file is edited; call it between ticks.
pub fn start_over(world: &mut World, config: SimConfig) {
    let hosts_bodies = holds_others(world);
    let old: Vec<Entity> = world.query_filtered::<Entity, With<SimEntity>>().iter(world).collect();
    for entity in old {
        world.despawn(entity);
    }
    // With no body of the host's in rapier, its world is emptied: the round then plays bit for
    // bit like a fresh start. Bodies of the host's stay where they are.
    if !hosts_bodies {
        third_party::rapier::empty_world(world);
    }
    let schedule = world.resource::<SimClock>().schedule;
    insert_run_resources(world, config, schedule);
    world.run_schedule(SimStart);
}

/// Whether rapier holds a body or collider that is not the simulation's (the host's own).
fn holds_others(world: &mut World) -> bool {
    let mut others = world.query_filtered::<(), (
        Or<(With<RapierRigidBodyHandle>, With<RapierColliderHandle>)>,
        Without<SimEntity>,
        Without<RigidPart>,
    )>();
    others.iter(world).next().is_some()
}

fn run_sim_start(world: &mut World) {
    world.run_schedule(SimStart);
}

impl Plugin for SimPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<TransformPlugin>() {
            app.add_plugins(TransformPlugin);
        }
        let schedule = self.schedule;
        insert_run_resources(app.world_mut(), self.config.clone(), schedule);
        third_party::plugin(app);
        app.init_schedule(SimStart)
            .configure_sets(
                SimStart,
                (
                    StartStage::Arena,
                    StartStage::Creatures,
                    StartStage::Index,
                    StartStage::Levels,
                )
                    .chain(),
            )
            .add_systems(Startup, run_sim_start)
            .configure_sets(
                schedule,
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
                schedule,
                (SimStage::Observe, SimStage::Outcome, SimStage::Clock)
                    .chain()
                    .after(PhysicsSet::Writeback),
            );
        if self.single_threaded {
            // The stages are one chain: running it on one thread saves the wake-ups of the
            // others (~20 us each on a small VM); the loops over creatures still spread.
            app.edit_schedule(schedule, |s| {
                s.set_executor(SingleThreadedExecutor::new());
            });
        }
        config::plugin(app);
        arena::plugin(app);
        creature::plugin(app);
        lod::plugin(app);
        sense::plugin(app);
        models::plugin(app);
        outcome::plugin(app);
    }
}
