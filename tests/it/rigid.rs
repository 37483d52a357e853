//! The rigid-body hopper and biped (paper 3.1): hop or run, track speeds, turn, recover and
//! fall like dynamic creatures. The biped runs Raibert's "one-foot" gait, its legs in turn; the
//! kangaroo and the quadruped (asset files alone) run it on virtual legs.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;

use crate::support::*;
use simlod::config::{RigidJoints, SimConfig};
use simlod::creature::{DesiredVelocity, GaitPhase, PlanarState};
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelPolicy, Lod};
use simlod::models::rigid::{RigidBodies, RigidPart, Shove};
use simlod_lab::experiments::{lone_creature, stand};

/// One rigid hopper steered from outside at `desired`, far from the walls and the parked puck.
pub fn lone_hopper(desired: Vec2) -> (HeadlessSim, Entity) {
    lone("hopper", desired)
}

/// One rigid creature of `kind` steered from outside at `desired`, facing it, far from the
/// walls and the parked puck.
pub fn lone(kind: &str, desired: Vec2) -> (HeadlessSim, Entity) {
    lone_in(&config_having(kind), kind, desired)
}

/// As [`lone`], in the world of `config`.
fn lone_in(config: &SimConfig, kind: &str, desired: Vec2) -> (HeadlessSim, Entity) {
    let (mut sim, hopper) = lone_creature(config, kind, LevelPolicy::AllRigid, Vec2::new(-180.0, 100.0), 420.0);
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
        assert!(!t.is_nan(), "it fell at {:.2} s", sim.clock().seconds());
        if t != last && sim.clock().seconds() >= from {
            out.push((t, state(sim, entity).unwrap().position));
        }
        last = t;
    }
    out
}

/// A kind's whole mass, from its file.
fn mass_kg(name: &str) -> f32 {
    let config = config_having(name);
    let kind = config.kinds.iter().find(|k| k.name == name).unwrap();
    kind.legs
        .iter()
        .fold(kind.body.mass_kg, |m, l| m + l.upper_mass_kg + l.lower_mass_kg)
}

fn falls(sim: &mut HeadlessSim) -> u64 {
    sim.summary(0.0).falls
}

/// Runs `kind` in place for 60 s: no fall, about two steps a second all the while, and a
/// drift under `max_drift_m`.
fn runs_in_place_for_sixty_seconds(kind: &str, max_drift_m: f32) {
    let (mut sim, creature) = lone(kind, Vec2::ZERO);
    let start = state(&mut sim, creature).unwrap().position;
    let hops = touchdowns(&mut sim, creature, 0.0, 60.0);
    assert_eq!(falls(&mut sim), 0);
    assert!(hops.len() > 90, "{} touchdowns in 60 s", hops.len());
    assert!(hops.last().unwrap().0 > 59.0);
    let drift = state(&mut sim, creature).unwrap().position.distance(start);
    assert!(drift < max_drift_m, "drifted {drift} m while running in place");
}

#[test]
fn hops_in_place_for_sixty_seconds_without_falling() {
    runs_in_place_for_sixty_seconds("hopper", 0.5);
}

#[test]
fn the_biped_runs_in_place_for_sixty_seconds_without_falling() {
    // Its steps sway it side to side; the integral speed correction holds it near its spot.
    runs_in_place_for_sixty_seconds("biped", BIPED_IN_PLACE_DRIFT_M);
}

const BIPED_IN_PLACE_DRIFT_M: f32 = 3.0;

#[test]
fn tracks_commanded_speeds_of_zero_to_three_metres_a_second() {
    tracks_speeds("hopper", &[0.0, 1.0, 2.0, 3.0]);
}

#[test]
fn the_biped_tracks_commanded_speeds_of_zero_to_two_and_a_half_metres_a_second() {
    // Its top speed (biped.ron) is 2.5 m/s.
    tracks_speeds("biped", &[0.0, 1.0, 2.0, 2.5]);
}

fn tracks_speeds(kind: &str, speeds: &[f32]) {
    tracks_speeds_in(&config_having(kind), kind, speeds);
}

fn tracks_speeds_in(config: &SimConfig, kind: &str, speeds: &[f32]) {
    for &speed in speeds {
        let (mut sim, hopper) = lone_in(config, kind, Vec2::new(speed, 0.0));
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
fn on_a_multibody_the_hopper_is_one_joint_tree_and_tracks_its_speeds_too() {
    let mut config = default_config();
    let hopper = config.kind_index("hopper").unwrap();
    config.kinds[hopper].rigid.as_mut().unwrap().joints = RigidJoints::Multibody;
    let (mut sim, creature) = lone_in(&config, "hopper", Vec2::ZERO);
    sim.advance_frame();
    let world = sim.app.world_mut();
    let bodies = world.get::<RigidBodies>(creature).unwrap().clone();
    let joined: Vec<(bool, bool)> = bodies
        .parts()
        .map(|p| {
            (
                world.get::<ImpulseJoint>(p).is_some(),
                world.get::<MultibodyJoint>(p).is_some(),
            )
        })
        .collect();
    assert_eq!(
        joined,
        [(false, false), (false, true), (false, true)],
        "body, upper leg, lower leg"
    );
    tracks_speeds_in(&config, "hopper", &[0.0, 1.0, 2.0, 3.0]);
}

#[test]
fn turns_to_a_new_heading_and_holds_it() {
    turns_a_quarter_turn("hopper");
}

#[test]
fn the_biped_turns_to_a_new_heading_and_holds_it() {
    turns_a_quarter_turn("biped");
}

fn turns_a_quarter_turn(kind: &str) {
    let (mut sim, hopper) = lone(kind, Vec2::new(1.5, 0.0));
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

/// Runs at 1 m/s for 5 s, then takes a sideways impulse on the body.
fn pushed(kind: &str, impulse_n_s: f32) -> (HeadlessSim, Entity) {
    let (mut sim, hopper) = lone(kind, Vec2::new(1.0, 0.0));
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
    recovers_from_a_push("hopper", 10.0);
}

#[test]
fn the_biped_recovers_from_a_moderate_push() {
    // 16 N s on the 17.5 kg biped: the hopper's sudden 0.9 m/s sideways.
    recovers_from_a_push("biped", 16.0);
}

fn recovers_from_a_push(kind: &str, impulse_n_s: f32) {
    let (mut sim, hopper) = pushed(kind, impulse_n_s);
    sim.advance_frame();
    let sideways = state(&mut sim, hopper).unwrap().velocity.y;
    assert!(
        sideways > 0.5 * impulse_n_s / mass_kg(kind),
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
    falls_from_a_push("hopper", 60.0, 3);
}

#[test]
fn a_large_push_makes_the_biped_fall_and_it_is_respawned_without_leaking_bodies() {
    // 100 N s on 17.5 kg: the same 5.7 m/s sideways. A body and two legs of two parts.
    falls_from_a_push("biped", 100.0, 5);
}

fn falls_from_a_push(kind: &str, impulse_n_s: f32, parts_each: usize) {
    let (mut sim, hopper) = pushed(kind, impulse_n_s);
    sim.run_for(8.0);
    assert_eq!(falls(&mut sim), 1);
    let world = sim.app.world_mut();
    assert!(world.get_entity(hopper).is_err(), "the fallen creature is removed");
    let creatures: Vec<Lod> = world.query::<&Lod>().iter(world).copied().collect();
    assert_eq!(creatures, vec![Lod::Rigid], "a new rigid creature took its place");
    let parts = world.query::<&RigidPart>().iter(world).count();
    let bodies = world.query::<&RigidBody>().iter(world).count();
    assert_eq!(parts, parts_each, "only the new creature's bodies remain");
    assert_eq!(bodies, parts_each + 1 + 4 + 1, "creature, puck, walls and ground");
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
fn hoppers_and_bipeds_run_all_rigid_with_steering() {
    let config = scene(&[("hopper", 30), ("biped", 10)], LevelPolicy::AllRigid);
    let summary = simlod::headless::run(config, 10.0);
    // Hoppers and bipeds both have a rigid model.
    assert_eq!(summary.levels[Lod::Rigid], 40);
    assert_eq!(summary.creatures, 40);
}

/// The kinds that run on virtual legs, made of asset files alone: the kangaroo's two legs land
/// together, the quadruped trots on its diagonal pairs.
const ON_VIRTUAL_LEGS: [&str; 2] = ["kangaroo", "quadruped"];

#[test]
fn kinds_on_virtual_legs_track_speeds_of_zero_to_two_metres_a_second() {
    for kind in ON_VIRTUAL_LEGS {
        tracks_speeds(kind, &[0.0, 1.0, 2.0]);
    }
}

#[test]
fn kinds_on_virtual_legs_run_in_place_for_sixty_seconds_without_falling() {
    for kind in ON_VIRTUAL_LEGS {
        runs_in_place_for_sixty_seconds(kind, 0.5);
    }
}

#[test]
fn kinds_on_virtual_legs_turn_to_a_new_heading_and_hold_it() {
    for kind in ON_VIRTUAL_LEGS {
        turns_a_quarter_turn(kind);
    }
}

#[test]
fn kinds_on_virtual_legs_recover_from_a_moderate_push_and_fall_from_a_hard_one() {
    // The hopper's sudden 0.94 m/s sideways, and its 5.7 m/s; a body and two parts a leg.
    for kind in ON_VIRTUAL_LEGS {
        let mass = mass_kg(kind);
        recovers_from_a_push(kind, 0.94 * mass);
        let legs = config_having(kind)
            .kinds
            .iter()
            .find(|k| k.name == kind)
            .unwrap()
            .legs
            .len();
        falls_from_a_push(kind, 5.7 * mass, 1 + 2 * legs);
    }
}

#[test]
fn the_quadruped_paces_on_a_line_of_its_file_and_bounds_in_place() {
    // Its file's stance line, changed: the legs of one side together (the pace), or the front
    // legs and then the back legs (the bound; it holds its pitch in place, not yet running).
    for (stance, speeds) in [
        (vec![vec![0, 2], vec![1, 3]], &[0.0, 1.0, 2.0][..]),
        (vec![vec![0, 1], vec![2, 3]], &[0.0][..]),
    ] {
        let mut config = config_having("quadruped");
        let quadruped = config.kind_index("quadruped").unwrap();
        config.kinds[quadruped].stance = simlod::config::Stance::VirtualLegs(stance);
        config.gaits[quadruped] = None;
        tracks_speeds_in(&config, "quadruped", speeds);
    }
}

#[test]
fn kinds_on_virtual_legs_turn_about_and_run_off_without_falling() {
    // Facing away from a command of 1.5 m/s, as a creature fleeing the puck behind it is.
    for kind in ON_VIRTUAL_LEGS {
        let (mut sim, creature) = lone(kind, Vec2::new(1.5, 0.0));
        let world = sim.app.world_mut();
        let at = world.get::<PlanarState>(creature).unwrap().position;
        stand(world, creature, at, Some(Vec2::NEG_X));
        sim.run_for(15.0);
        assert_eq!(falls(&mut sim), 0, "{kind}");
        let s = state(&mut sim, creature).unwrap();
        assert!(s.velocity.distance(Vec2::new(1.5, 0.0)) < 0.5, "{kind}: {}", s.velocity);
    }
}
