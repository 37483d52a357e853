//! Choosing and switching levels (paper 3.4): influence areas, the camera rule, the
//! flight-phase window, hysteresis, and a soak of many switches.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use std::collections::HashMap;

use crate::support::*;
use simlod::SimStage;
use simlod::config::SimConfig;
use simlod::creature::{Creature, PlanarState};
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelPolicy, LevelSwitched, Lod};
use simlod::models::rigid::RigidPart;

/// A switch as the test saw it: the message and the creature's state at the end of the tick
/// before and of the tick it switched in.
#[derive(Clone, Debug)]
struct Observed {
    switch: LevelSwitched,
    before: PlanarState,
    after: PlanarState,
}

#[derive(Resource, Default)]
struct Watch {
    last: HashMap<Entity, PlanarState>,
    seen: Vec<Observed>,
}

fn remember(mut watch: ResMut<Watch>, creatures: Query<(Entity, &PlanarState)>) {
    watch.last = creatures.iter().map(|(e, s)| (e, *s)).collect();
}

fn observe(mut watch: ResMut<Watch>, mut switched: MessageReader<LevelSwitched>, creatures: Query<&PlanarState>) {
    for s in switched.read() {
        let (Some(before), Ok(after)) = (watch.last.get(&s.creature).copied(), creatures.get(s.creature)) else {
            continue;
        };
        watch.seen.push(Observed {
            switch: *s,
            before,
            after: *after,
        });
    }
}

/// A simulation stepped one tick per update, watching every switch.
fn watched(mut config: SimConfig) -> HeadlessSim {
    config.scenario.decision_hz = config.scenario.tick_hz;
    let mut sim = HeadlessSim::new(config);
    sim.app
        .init_resource::<Watch>()
        .add_systems(FixedUpdate, remember.before(SimStage::Sense))
        .add_systems(FixedUpdate, observe.after(SimStage::Outcome));
    sim
}

fn influence_config() -> SimConfig {
    let mut config = default_config();
    config.scenario.level_policy = LevelPolicy::Influence;
    config
}

#[test]
fn switches_happen_only_inside_the_flight_window_unless_a_collision_forces_them() {
    let config = influence_config();
    let (open, close) = config.rules.flight_window;
    let mut sim = watched(config);
    sim.run_for(20.0);
    let seen = &sim.app.world().resource::<Watch>().seen;
    let (windowed, forced): (Vec<_>, Vec<_>) = seen.iter().partition(|o| o.switch.flight_progress.is_some());
    assert!(windowed.len() >= 30, "{} switches in the window", windowed.len());
    for o in &windowed {
        let p = o.switch.flight_progress.unwrap();
        assert!(
            (open..=close).contains(&p),
            "switched at {p} of the flight phase: {:?}",
            o.switch
        );
    }
    for o in &forced {
        assert_eq!(
            o.switch.to,
            Lod::Rigid,
            "only a collision skips the window, and it goes rigid"
        );
    }
}

#[test]
fn at_a_switch_the_body_does_not_jump() {
    let mut sim = watched(influence_config());
    sim.run_for(20.0);
    let dt = sim.clock().dt;
    let seen = sim.app.world().resource::<Watch>().seen.clone();
    assert!(seen.len() >= 30);
    for o in seen.iter().filter(|o| o.switch.flight_progress.is_some()) {
        // Where the body would have been after one more tick of its own motion.
        let expected = o.before.position + o.before.velocity * dt;
        let jump = o.after.position.distance(expected);
        assert!(jump < 0.01, "{:?}: position jumped {jump} m", o.switch);
        let turn = o.after.heading.angle_to(o.before.heading).abs().to_degrees();
        assert!(turn < 2.0, "{:?}: heading turned {turn} degrees", o.switch);
        // In flight the planar velocity of a hopper is nearly constant; within a hop the
        // rigid body's planar speed varies by about 0.2 m/s, so more than 0.3 m/s is a pop.
        let kick = o.after.velocity.distance(o.before.velocity);
        assert!(
            kick < 0.3,
            "{:?}: velocity changed by {kick} m/s: {:?} {:?}",
            o.switch,
            o.before,
            o.after
        );
    }
}

#[test]
fn hysteresis_keeps_a_creature_on_a_boundary_from_flickering() {
    let config = influence_config();
    let dwell = config.rules.min_dwell_s;
    let mut sim = watched(config);
    sim.run_for(30.0);
    // Going up is never delayed (a creature entering an area must be rigid in time); coming
    // down waits at least the dwell time after the creature's last switch.
    let mut last: HashMap<u32, f32> = HashMap::new();
    for o in &sim.app.world().resource::<Watch>().seen {
        if let Some(t) = last.get(&o.switch.serial)
            && o.switch.to < o.switch.from
        {
            let gap = o.switch.at_s - t;
            assert!(
                gap >= dwell,
                "creature {} came down again after {gap} s",
                o.switch.serial
            );
        }
        last.insert(o.switch.serial, o.switch.at_s);
    }
    // And no creature switches more than a few times a second on average.
    let summary = sim.summary(0.0);
    let per_creature_per_s = summary.switches["total"] as f64 / 40.0 / 30.0;
    assert!(
        per_creature_per_s < 0.5,
        "{per_creature_per_s} switches per creature per second"
    );
}

#[test]
fn the_camera_rule_keeps_creatures_out_of_view_at_the_point_mass_level() {
    let mut config = default_config();
    config.scenario.level_policy = LevelPolicy::Camera;
    let summary = simlod::headless::run(config, 10.0);
    // A 60 degree cone behind one creature sees a minority of the court.
    assert!(summary.levels_mean["point_mass"] > 15.0, "{:?}", summary.levels_mean);
    assert!(
        summary.levels_mean["rigid"] > 0.0 && summary.levels_mean["hybrid"] > 0.0,
        "{:?}",
        summary.levels_mean
    );
}

#[test]
fn a_larger_puck_radius_makes_more_creatures_rigid() {
    let mean_rigid = |r: f32| {
        let mut config = influence_config();
        config.rules.influence.puck_radius_m = r;
        config.rules.influence.creature_radius_m = 0.0;
        config.rules.influence.wall_band_m = 0.0;
        simlod::headless::run(config, 10.0).levels_mean["rigid"]
    };
    let (small, large) = (mean_rigid(3.0), mean_rigid(15.0));
    assert!(
        large > small + 2.0,
        "rigid on average: radius 3 m {small}, radius 15 m {large}"
    );
}

#[test]
fn switching_is_deterministic() {
    let run = || {
        let mut sim = HeadlessSim::new(influence_config());
        sim.run_for(10.0);
        let mut s = sim.summary(0.0);
        s.realtime_factor = 0.0;
        (sim.state_digest(), s)
    };
    let a = run();
    assert!(a.1.switches["total"] > 10);
    assert_eq!(a, run());
}

#[test]
fn a_soak_of_ten_minutes_and_thousands_of_switches_leaks_nothing() {
    let mut config = influence_config();
    config.scenario.creatures.retain(|g| g.kind == "hopper");
    config.scenario.creatures[0].count = 100;
    // Small areas, a thin margin and a short dwell: creatures cross boundaries often.
    config.rules.influence.creature_radius_m = 0.8;
    config.rules.influence.puck_radius_m = 4.0;
    config.rules.min_dwell_s = 0.1;
    config.rules.release_margin_m = 0.3;
    let mut sim = HeadlessSim::new(config);
    while sim.clock().seconds() < 600.0 {
        sim.run_for(60.0);
        let world = sim.app.world_mut();
        let creatures: Vec<Lod> = world
            .query_filtered::<&Lod, With<Creature>>()
            .iter(world)
            .copied()
            .collect();
        assert_eq!(creatures.len(), 100);
        let rigid = creatures.iter().filter(|l| **l == Lod::Rigid).count();
        let parts = world.query::<&RigidPart>().iter(world).count();
        let bodies = world.query::<&RigidBody>().iter(world).count();
        let rapier_bodies = world.query::<&RapierRigidBodySet>().single(world).unwrap().bodies.len();
        assert_eq!(
            parts,
            3 * rigid,
            "bodies of rigid creatures at {} s",
            sim.clock().seconds()
        );
        assert_eq!(bodies, parts + 6, "plus ground, four walls and the puck");
        assert_eq!(rapier_bodies, bodies, "rapier holds exactly the bodies the world has");
    }
    let summary = sim.summary(0.0);
    eprintln!("soak: {:?} switches, {} falls", summary.switches, summary.falls);
    assert!(summary.switches["total"] >= 10_000, "{:?}", summary.switches);
}
