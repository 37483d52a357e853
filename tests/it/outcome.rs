//! Collisions, falls and respawns.

use crate::support::*;
use simlod::arena::PuckState;
use simlod::headless::HeadlessSim;
use simlod::lod::LevelPolicy;
use simlod::outcome::Obstacle;

#[test]
fn respawning_keeps_the_creature_count_constant() {
    // Creatures so fragile that any bump is a fall: many removals.
    let mut config = config_with_hoppers(120);
    config.kinds[0].fall_impact_speed_m_per_s = 0.05;
    let n = config.scenario.creature_count() as usize;
    let keep_out = config.arena.puck.radius_m + config.kinds[0].body.radius_m;
    let mut sim = HeadlessSim::new(config);
    let mut last_max_serial = 0;
    let mut respawned = 0;
    while sim.clock().seconds() < 30.0 {
        sim.advance_frame();
        let all = creatures(&mut sim);
        assert_eq!(all.len(), n, "creature count at {} s", sim.clock().seconds());
        let puck = *sim.app.world().resource::<PuckState>();
        for (c, s) in &all {
            if c.serial > last_max_serial && c.serial >= n as u32 {
                respawned += 1;
                // A newcomer does not start under the puck.
                assert!(
                    s.position.distance(puck.position) > keep_out,
                    "respawned at {} under the puck",
                    s.position
                );
            }
        }
        last_max_serial = all.iter().map(|(c, _)| c.serial).max().unwrap();
    }
    let summary = sim.summary(0.0);
    assert!(summary.respawns >= 10, "respawns {}", summary.respawns);
    assert_eq!(summary.respawns, summary.falls);
    assert!(respawned > 0);
    assert_eq!(summary.creatures as usize, n);
}

#[test]
fn a_creature_in_the_pucks_path_is_hit_and_counted() {
    // One creature standing still right in front of the puck, steering off.
    let mut config = config_with_hoppers(1);
    // At the point-mass level, whose position the test sets directly (a rigid creature's
    // bodies would stay where they were).
    config.scenario.level_policy = LevelPolicy::AllPointMass;
    config.kinds[0].steering.cruise_speed_m_per_s = 0.0;
    config.kinds[0].steering.puck_weight = 0.0;
    config.kinds[0].steering.wall_weight = 0.0;
    let mut sim = HeadlessSim::new(config);
    sim.advance_frame();
    let puck = *sim.app.world().resource::<PuckState>();
    {
        let world = sim.app.world_mut();
        let mut q = world.query::<&mut simlod::creature::PlanarState>();
        // Its centre 4 m ahead of the puck's: the rims 1.7 m apart, met in about 0.3 s.
        q.single_mut(world).unwrap().position = puck.position + puck.velocity.normalize() * 4.0;
    }
    let v = puck.velocity;
    let mut hit = false;
    for _ in 0..30 {
        sim.advance_frame();
        let s = sim.summary(0.0);
        if s.collisions[Obstacle::Puck] > 0 {
            hit = true;
            // At 5 m/s the puck's impact beats the hopper's fall threshold of 2 m/s.
            assert_eq!(s.falls, 1);
            assert_eq!(s.creatures_collided, 1);
            // Counted by obstacle too, after the fallen creature was removed.
            assert_eq!(s.creatures_collided_with[Obstacle::Puck], 1);
            assert_eq!(s.creatures_collided_with[Obstacle::Wall], 0);
            break;
        }
    }
    assert!(hit, "the puck moving at {v} never hit the creature in its path");
}
