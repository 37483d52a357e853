//! The rigid-body hopper (paper 3.1): hops, runs, turns, recovers and falls like a dynamic
//! creature.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;

use crate::support::*;
use simlod::creature::{DesiredVelocity, GaitPhase, PlanarState};
use simlod::experiments::{lone_creature, stand};
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelPolicy, Lod};
use simlod::models::rigid::{RigidBodies, RigidPart, Shove};

/// One rigid hopper steered from outside at `desired`, far from the walls and the parked puck.
pub fn lone_hopper(desired: Vec2) -> (HeadlessSim, Entity) {
    let (mut sim, hopper) = lone_creature(
        &default_config(),
        "hopper",
        LevelPolicy::AllRigid,
        Vec2::new(-180.0, 100.0),
        420.0,
    );
    let world = sim.app.world_mut();
    world.entity_mut(hopper).insert(DesiredVelocity(desired));
    let at = world.get::<PlanarState>(hopper).unwrap().position;
    stand(world, hopper, at, Some(desired.try_normalize().unwrap_or(Vec2::X)));
    (sim, hopper)
}

fn state(sim: &mut HeadlessSim, entity: Entity) -> Option<PlanarState> {
    sim.app.world().get::<PlanarState>(entity).copied()
}

fn touchdown(sim: &mut HeadlessSim, entity: Entity) -> f32 {
    sim.app
        .world()
        .get::<GaitPhase>(entity)
        .map_or(f32::NAN, |g| g.last_touchdown_s)
}

/// Runs until `seconds`, returning the positions and times at each touchdown after `from`.
fn touchdowns(sim: &mut HeadlessSim, entity: Entity, from: f64, seconds: f64) -> Vec<(f32, Vec2)> {
    let mut out = Vec::new();
    let mut last = touchdown(sim, entity);
    while sim.clock().seconds() < seconds {
        sim.advance_frame();
        let t = touchdown(sim, entity);
        assert!(!t.is_nan(), "the hopper fell at {:.2} s", sim.clock().seconds());
        if t != last && sim.clock().seconds() >= from {
            out.push((t, state(sim, entity).unwrap().position));
        }
        last = t;
    }
    out
}

/// The hopper's whole mass, from its file.
fn hopper_mass_kg() -> f32 {
    let kind = &config_with_hoppers(1).kinds[0];
    kind.legs
        .iter()
        .fold(kind.body.mass_kg, |m, l| m + l.upper_mass_kg + l.lower_mass_kg)
}

fn falls(sim: &mut HeadlessSim) -> u64 {
    sim.summary(0.0).falls
}

#[test]
fn hops_in_place_for_sixty_seconds_without_falling() {
    let (mut sim, hopper) = lone_hopper(Vec2::ZERO);
    let start = state(&mut sim, hopper).unwrap().position;
    let hops = touchdowns(&mut sim, hopper, 0.0, 60.0);
    assert_eq!(falls(&mut sim), 0);
    // About two hops a second, all the while.
    assert!(hops.len() > 90, "{} touchdowns in 60 s", hops.len());
    assert!(hops.last().unwrap().0 > 59.0);
    let drift = state(&mut sim, hopper).unwrap().position.distance(start);
    assert!(drift < 0.5, "drifted {drift} m while hopping in place");
}

#[test]
fn tracks_commanded_speeds_of_zero_to_three_metres_a_second() {
    for speed in [0.0, 1.0, 2.0, 3.0] {
        let (mut sim, hopper) = lone_hopper(Vec2::new(speed, 0.0));
        // Settled after 8 s; averaged over the whole hops between touchdowns up to 20 s.
        let hops = touchdowns(&mut sim, hopper, 8.0, 20.0);
        let ((t0, p0), (t1, p1)) = (hops[0], *hops.last().unwrap());
        let average = (p1 - p0) / (t1 - t0);
        assert!(
            (average.x - speed).abs() <= 0.25 && average.y.abs() <= 0.25,
            "commanded {speed} m/s along x, averaged {average} over {} hops",
            hops.len() - 1
        );
    }
}

#[test]
fn turns_to_a_new_heading_and_holds_it() {
    let (mut sim, hopper) = lone_hopper(Vec2::new(1.5, 0.0));
    sim.run_for(6.0);
    let turned = Vec2::new(0.0, -1.5); // from +x to world -z: a quarter turn
    sim.app.world_mut().get_mut::<DesiredVelocity>(hopper).unwrap().0 = turned;
    sim.run_for(6.0);
    let mut worst_heading: f32 = 0.0;
    let hops = {
        let mut headings = Vec::new();
        while sim.clock().seconds() < 18.0 {
            sim.advance_frame();
            headings.push(state(&mut sim, hopper).expect("still standing").heading);
        }
        headings
    };
    for h in hops {
        worst_heading = worst_heading.max(h.angle_to(turned.normalize()).abs().to_degrees());
    }
    assert!(
        worst_heading < 15.0,
        "the body strayed {worst_heading} degrees from its new heading"
    );
    assert_eq!(falls(&mut sim), 0);
}

/// Hops at 1 m/s for 5 s, then takes a sideways impulse on the body.
fn pushed(impulse_n_s: f32) -> (HeadlessSim, Entity) {
    let (mut sim, hopper) = lone_hopper(Vec2::new(1.0, 0.0));
    sim.run_for(5.0);
    sim.app
        .world_mut()
        .entity_mut(hopper)
        .insert(Shove(Vec3::Z * impulse_n_s));
    (sim, hopper)
}

#[test]
fn recovers_from_a_moderate_push() {
    // 10 N s on the 10.6 kg hopper: a sudden 0.94 m/s sideways.
    let (mut sim, hopper) = pushed(10.0);
    sim.advance_frame();
    let sideways = state(&mut sim, hopper).unwrap().velocity.y;
    assert!(
        sideways > 0.5 * 10.0 / hopper_mass_kg(),
        "the push took: {sideways} m/s sideways"
    );
    sim.run_for(15.0);
    assert_eq!(falls(&mut sim), 0);
    let s = state(&mut sim, hopper).expect("the hopper is still there");
    assert!(
        (s.velocity.x - 1.0).abs() < 0.6 && s.velocity.y.abs() < 0.6,
        "back on course: {}",
        s.velocity
    );
}

#[test]
fn a_large_push_makes_it_fall_and_it_is_respawned_without_leaking_bodies() {
    // 60 N s: a sudden 5.7 m/s sideways, more than any foot placement can catch.
    let (mut sim, hopper) = pushed(60.0);
    sim.run_for(8.0);
    assert_eq!(falls(&mut sim), 1);
    let world = sim.app.world_mut();
    assert!(world.get_entity(hopper).is_err(), "the fallen creature is removed");
    let creatures: Vec<Lod> = world.query::<&Lod>().iter(world).copied().collect();
    assert_eq!(creatures, vec![Lod::Rigid], "a new rigid creature took its place");
    let parts = world.query::<&RigidPart>().iter(world).count();
    let bodies = world.query::<&RigidBody>().iter(world).count();
    assert_eq!(parts, 3, "only the new hopper's three bodies remain");
    assert_eq!(bodies, 3 + 1 + 4 + 1, "hopper, puck, walls and ground");
}

#[test]
fn a_numerical_blow_up_is_handled_as_a_fall() {
    let (mut sim, hopper) = lone_hopper(Vec2::ZERO);
    sim.run_for(2.0);
    let leg = sim.app.world().get::<RigidBodies>(hopper).unwrap().legs[0].lower;
    sim.app.world_mut().get_mut::<Velocity>(leg).unwrap().linear = Vec3::NAN;
    sim.run_for(1.0);
    assert_eq!(falls(&mut sim), 1);
    let world = sim.app.world_mut();
    assert_eq!(world.query::<&RigidPart>().iter(world).count(), 3);
}

#[test]
fn the_default_scenario_runs_all_rigid_with_steering() {
    let mut config = default_config();
    config.scenario.level_policy = LevelPolicy::AllRigid;
    let summary = simlod::headless::run(config, 10.0);
    // Hoppers have a rigid model; bipeds do not yet and stay point masses.
    assert_eq!(summary.levels[Lod::Rigid], 30);
    assert_eq!(summary.levels[Lod::PointMass], 10);
    assert_eq!(summary.creatures, 40);
}
