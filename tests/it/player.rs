//! The player-control hook of the core: a `PlayerControlled` creature moves as its desired
//! velocity says, and steering leaves that velocity alone.

use bevy::prelude::*;

use crate::support::*;
use simlod::creature::{Creature, DesiredVelocity, PlanarState, PlayerControlled};
use simlod::headless::HeadlessSim;
use simlod::lod::LevelPolicy;

#[test]
fn steering_leaves_a_player_controlled_creature_to_the_velocity_set_for_it() {
    // At the point-mass level, which takes its velocity straight from the desired one
    // within its acceleration limit (the rigid hopper's tracking is tested in `rigid`).
    let mut config = config_with_hoppers(20);
    config.scenario.level_policy = LevelPolicy::AllPointMass;
    let mut sim = HeadlessSim::new(config);
    let world = sim.app.world_mut();
    let (player, serial) = world
        .query::<(Entity, &Creature)>()
        .iter(world)
        .min_by_key(|(_, c)| c.serial)
        .map(|(e, c)| (e, c.serial))
        .unwrap();
    // Toward the court's centre, slowly: the puck starts there but moves off.
    let start = world.get::<PlanarState>(player).unwrap().position;
    let wanted = -start.normalize() * 0.8;
    world
        .entity_mut(player)
        .insert((PlayerControlled, DesiredVelocity(wanted)));
    for _ in 0..60 {
        sim.advance_frame();
    }
    let world = sim.app.world_mut();
    let (c, state, desired) = world
        .query::<(&Creature, &PlanarState, &DesiredVelocity)>()
        .get(world, player)
        .expect("the player's creature is still there");
    assert_eq!(c.serial, serial);
    assert_eq!(desired.0, wanted, "steering changed the player's desired velocity");
    assert!(
        state.velocity.distance(wanted) < 0.05,
        "after 2 s the creature moves at the velocity set for it: {} vs {wanted}",
        state.velocity
    );
    // The others are still steered.
    let steered = world
        .query_filtered::<&DesiredVelocity, Without<PlayerControlled>>()
        .iter(world)
        .filter(|d| d.0 != Vec2::ZERO)
        .count();
    assert_eq!(steered, 19);
}
