//! The court and the puck: the puck keeps bouncing at its speed, nobody leaves the court.

use bevy::prelude::*;

use crate::support::*;
use simlod::arena::PuckState;
use simlod::creature::{Creature, PlanarState};
use simlod::headless::HeadlessSim;
use simlod::lod::Lod;

#[test]
fn puck_keeps_bouncing_inside_the_court_at_its_speed_for_sixty_seconds() {
    let config = default_config();
    let half = config.arena.half_extents();
    let radius = config.arena.puck.radius_m;
    let speed = config.arena.puck.speed_m_per_s;
    let mut sim = HeadlessSim::new(config);
    let mut last = Vec2::ZERO;
    let mut bounces = [0; 2];
    while sim.clock().seconds() < 60.0 {
        sim.advance_frame();
        let puck = *sim.app.world().resource::<PuckState>();
        // A contact may sink a few millimetres into a wall within a tick.
        let reach = half - Vec2::splat(radius) + Vec2::splat(0.05);
        assert!(
            vec2_in_court(puck.position, reach),
            "puck at {} left the court",
            puck.position
        );
        assert!(
            (puck.velocity.length() - speed).abs() < 1e-3 * speed,
            "puck speed {}",
            puck.velocity.length()
        );
        for axis in 0..2 {
            if last[axis] * puck.velocity[axis] < 0.0 {
                bounces[axis] += 1;
            }
        }
        last = puck.velocity;
    }
    // The puck is launched 25-65 degrees off the axes, so each component of its 5 m/s is at
    // least 2.1 m/s: over 60 s, 127 m along x (56 m free) and along z (36 m free).
    assert!(
        bounces[0] >= 2 && bounces[1] >= 3,
        "bounces off the x and z walls: {bounces:?}"
    );
}

#[test]
fn no_creature_ever_leaves_the_court() {
    // A crowded court, so creatures are shoved into the walls by the puck and each other.
    let config = config_with_hoppers(400);
    let half = config.arena.half_extents();
    let radius = config.kinds[0].body.radius_m;
    let mut sim = HeadlessSim::new(config);
    let mut deepest = [0.0f32; 3];
    while sim.clock().seconds() < 30.0 {
        sim.advance_frame();
        let puck = *sim.app.world().resource::<PuckState>();
        let t = sim.clock().seconds();
        let world = sim.app.world_mut();
        for (c, lod, s) in world.query::<(&Creature, &Lod, &PlanarState)>().iter(world) {
            let into_wall = (s.position.abs() - (half - Vec2::splat(radius))).max_element();
            deepest[*lod as usize] = deepest[*lod as usize].max(into_wall);
            // The kinematic levels resolve a wall contact on the footprint circle exactly. The
            // rigid body is a box, narrower across than that circle, and a falling one leans
            // on the wall: its centre stays inside the walls' faces.
            let allowed = if *lod == Lod::Rigid { radius } else { 1e-4 };
            assert!(
                into_wall <= allowed,
                "creature {} ({lod:?}) at {} is {into_wall} m nearer the wall than its footprint radius; t {t} puck {:?}",
                c.serial,
                s.position,
                puck
            );
        }
    }
    eprintln!("deepest into a wall, by level: {deepest:?}");
}
