//! Starting the world over (`simlod::start_over`): the game's new rounds and hot reload.

use bevy_rapier3d::prelude::RigidBody;

use crate::support::*;
use simlod::headless::HeadlessSim;
use simlod::lod::LevelPolicy;
use simlod::models::rigid::RigidPart;
use simlod::start_over;

/// Under every policy: the rigid ones rebuild rapier's world, which must start empty too.
#[test]
fn starting_over_gives_the_same_world_as_a_fresh_start() {
    for policy in LevelPolicy::ALL {
        let mut config = default_config();
        config.scenario.level_policy = policy;
        let mut fresh = HeadlessSim::new(config.clone());
        let mut restarted = HeadlessSim::new(config.clone());
        for _ in 0..90 {
            restarted.advance_frame();
        }
        start_over(restarted.app.world_mut(), config);
        assert_eq!(restarted.clock().tick, 0);
        assert_eq!(restarted.summary(0.0).falls, 0, "the counts start from zero");
        assert_eq!(restarted.summary(0.0).switches.total(), 0, "the switch counts too");
        for _ in 0..90 {
            fresh.advance_frame();
            restarted.advance_frame();
        }
        assert_eq!(fresh.state_digest(), restarted.state_digest(), "{policy:?}");
        assert_eq!(fresh.summary(0.0).collisions, restarted.summary(0.0).collisions);
    }
}

#[test]
fn starting_over_a_rigid_world_leaks_no_bodies() {
    let mut config = config_with_hoppers(12);
    config.scenario.level_policy = LevelPolicy::AllRigid;
    let mut sim = HeadlessSim::new(config.clone());
    for round in 0..5 {
        for _ in 0..15 {
            sim.advance_frame();
        }
        let mut next = config.clone();
        next.scenario.seed += round;
        start_over(sim.app.world_mut(), next);
    }
    sim.advance_frame();
    let world = sim.app.world_mut();
    assert_eq!(world.query::<&RigidPart>().iter(world).count(), 3 * 12);
    assert_eq!(
        world.query::<&RigidBody>().iter(world).count(),
        3 * 12 + 6,
        "the parts, ground, 4 walls, puck"
    );
}
