//! Rapier (bevy_rapier3d): the physics of the court, the puck and the rigid creatures, stepped
//! in the fixed schedule at the simulation's tick.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;

use crate::config::SimConfig;
use crate::contract::{SimClock, SimStart};

/// Rapier steps once per simulation tick of `dt` seconds (it keeps its own copy of the step).
pub fn set_timestep(world: &mut World, dt: f32) {
    world.insert_resource(TimestepMode::Fixed { dt, substeps: 1 });
}

/// Empties rapier's world rather than letting it remove the old bodies one by one: freed
/// handles would be reused in another order, and with them the solver's order, so a new
/// round would not match a fresh start with the same seed.
pub fn empty_world(world: &mut World) {
    let mut contexts = world.query::<(
        &mut RapierContextSimulation,
        &mut RapierContextColliders,
        &mut RapierRigidBodySet,
        &mut RapierContextJoints,
    )>();
    for (mut simulation, mut colliders, mut bodies, mut joints) in contexts.iter_mut(world) {
        let parameters = simulation.integration_parameters;
        *simulation = default();
        simulation.integration_parameters = parameters;
        *colliders = default();
        *bodies = default();
        *joints = default();
    }
}

/// The scenario's solver iterations per tick, and fresh contacts every tick: rapier's contact
/// recycling keeps a pair's contact points while the pair has moved less than 5 cm, and a foot
/// in stance moves less than that, so its depth went stale and a hop in place could land 12 cm
/// off the table's height (fresh contacts cost 1 % more instructions).
fn set_integration_parameters(config: Res<SimConfig>, mut contexts: Query<&mut RapierContextSimulation>) {
    for mut simulation in &mut contexts {
        let parameters = &mut simulation.integration_parameters;
        parameters.num_solver_iterations = config.scenario.solver_iterations as usize;
        parameters.contact_recycling = false;
    }
}

pub(super) fn plugin(app: &mut App) {
    // The host's rapier, where it has one.
    if !app.is_plugin_added::<RapierPhysicsPlugin<NoUserData>>() {
        let schedule = SimClock::schedule_of(app);
        app.add_plugins(RapierPhysicsPlugin::<NoUserData>::default().in_schedule(schedule));
    }
    app.add_systems(SimStart, set_integration_parameters);
}
