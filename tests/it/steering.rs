//! Steering: creatures escape the puck and keep off the walls and each other.

use crate::support::*;
use simlod::config::SimConfig;
use simlod::headless;
use simlod::outcome::Obstacle;

const SEEDS: std::ops::Range<u64> = 1..11;

/// Collisions with the puck and walls, and creatures that had one, summed over seeds.
fn hits(config: &SimConfig, seconds: f64) -> (u64, u64, u64) {
    let mut totals = (0, 0, 0);
    for seed in SEEDS {
        let mut c = config.clone();
        c.scenario.seed = seed;
        let s = headless::run(c, seconds);
        totals.0 += s.collisions[Obstacle::Puck];
        totals.1 += s.collisions[Obstacle::Wall];
        totals.2 += s.creatures_collided;
    }
    totals
}

/// The same creatures with every steering urge but wandering switched off.
fn without_steering(mut config: SimConfig) -> SimConfig {
    for k in &mut config.kinds {
        k.steering.puck_weight = 0.0;
        k.steering.wall_weight = 0.0;
        k.steering.wall_avoid_distance_m = 0.0;
        k.steering.separation_weight = 0.0;
    }
    config
}

#[test]
fn creatures_do_not_run_into_walls_on_their_own() {
    // A puck too small and slow to chase anyone: only wandering and wall avoidance remain.
    let mut config = default_config();
    config.arena.puck.radius_m = 0.05;
    config.arena.puck.speed_m_per_s = 0.01;
    let (_, wall, _) = hits(&config, 60.0);
    let (_, wall_unsteered, _) = hits(&without_steering(config), 60.0);
    eprintln!("wall collisions over 10 x 60 s of wandering: {wall} steered, {wall_unsteered} unsteered");
    // Steered, a wall is touched at most a few times in 400 creature-minutes (a rigid foot
    // swinging out near it); without steering, over ten times as often.
    assert!(
        wall_unsteered > 10 && wall * 10 < wall_unsteered,
        "wall collisions: {wall} steered, {wall_unsteered} without steering"
    );
}

#[test]
fn steering_keeps_collisions_with_the_puck_and_walls_low_in_the_default_scenario() {
    let config = default_config();
    let creatures = u64::from(config.scenario.creature_count());
    let (puck, wall, collided) = hits(&config, 20.0);
    let (puck_unsteered, wall_unsteered, collided_unsteered) = hits(&without_steering(config), 20.0);
    eprintln!(
        "steered: puck {puck} wall {wall} creatures {collided}; unsteered: puck {puck_unsteered} wall {wall_unsteered} creatures {collided_unsteered}"
    );
    // "Creatures mostly survive": over ten 20 s trials, fewer than one creature in ten
    // collides with the puck or a wall in a trial ...
    assert!(
        collided * 10 < creatures * SEEDS.count() as u64,
        "{collided} of {creatures} x 10 collided"
    );
    // ... and steering, not luck, is why: without it at least three times as many do.
    assert!(
        collided_unsteered >= 3 * collided.max(1),
        "unsteered {collided_unsteered} vs steered {collided}"
    );
}
