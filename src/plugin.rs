//! The plugin that puts the layers together: the stages of a tick in the paper's order, the
//! world built at [`SimStart`], and each layer's systems.

use bevy::ecs::schedule::SingleThreadedExecutor;
use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use rand::SeedableRng;
use rand::rngs::StdRng;

use crate::config::{self, SimConfig};
use crate::contract::{SimClock, SimEntity, SimStage, SimStart, StartStage, WorldRng};
use crate::{arena, creature, lod, models, outcome, sense, third_party};

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
                (SimStage::Observe, SimStage::Outcome, SimStage::Clock)
                    .chain()
                    .after(PhysicsSet::Writeback),
            );
        // The stages are one chain: running it on one thread saves the wake-ups of the others
        // (~20 us each on a small VM); the loops over creatures still spread over threads.
        app.edit_schedule(FixedUpdate, |s| {
            s.set_executor(SingleThreadedExecutor::new());
        });
        config::plugin(app);
        arena::plugin(app);
        creature::plugin(app);
        lod::plugin(app);
        sense::plugin(app);
        models::plugin(app);
        outcome::plugin(app);
    }
}
