//! Rapier (bevy_rapier3d): the physics of the court, the puck and the rigid creatures, stepped
//! in the fixed schedule at the simulation's tick.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;

use crate::SimStart;
use crate::config::SimConfig;

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

/// The scenario's solver iterations per tick.
fn set_solver_iterations(config: Res<SimConfig>, mut contexts: Query<&mut RapierContextSimulation>) {
    for mut simulation in &mut contexts {
        simulation.integration_parameters.num_solver_iterations = config.scenario.solver_iterations as usize;
    }
}

pub(super) fn plugin(app: &mut App) {
    app.add_plugins(RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule())
        .add_systems(SimStart, set_solver_iterations);
}
