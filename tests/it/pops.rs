//! Invisible switches: every switch's pop in what is drawn is measured, the blend hides what the
//! models leave, the blend never changes the simulation, and falls right after going rigid are
//! counted apart.

use bevy::prelude::*;

use crate::support::*;
use simlod::config::{SimConfig, load_file};
use simlod::creature::DesiredVelocity;
use simlod::lod::{LevelPolicy, Lod};
use simlod::models::rigid::Shove;
use simlod_lab::experiments::lone_creature;
use std::path::Path;

/// A game of the shipped kinds under the combined policy, blended as the shipped rules say or
/// not at all.
fn game(blended: bool) -> SimConfig {
    let mut config = scene(&[("hopper", 30), ("biped", 10)], LevelPolicy::Combined);
    if !blended {
        config.rules.blend_s = 0.0;
    }
    config
}

#[test]
fn over_whole_games_every_switch_is_drawn_under_the_bars() {
    // The paper's rules, the camera rule (its point masses out of view), areas of influence
    // shrunk to nothing, so that creatures go rigid only when a collision forces it, and the
    // frame budget (which moves creatures between levels as contacts near).
    let mut camera = game(true);
    camera.scenario.level_policy = LevelPolicy::Camera;
    let mut collisions_only = game(true);
    collisions_only.scenario.level_policy = LevelPolicy::Influence;
    let influence = &mut collisions_only.rules.influence;
    (
        influence.puck_radius_m,
        influence.creature_radius_m,
        influence.wall_band_m,
    ) = (0.0, 0.0, 0.0);
    let mut budget = game(true);
    budget.scenario.level_policy = LevelPolicy::Budget;
    // A calibration kept for the tests: which switches the budget makes moves with the costs
    // (the one of 2026-11-26 10:55 UTC made a rigid-to-hybrid switch drawn at 2.11 degrees).
    budget.costs = load_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/it/fixtures/costs-measured.ron"))
        .expect("the tests' cost model loads");
    let mut pops = Vec::new();
    let (mut switches, mut unseen, mut falls) = (0, 0, 0);
    for config in [game(true), camera, collisions_only, budget] {
        let (_, summary) = digest_after(config, 20.0);
        switches += summary.switches.total();
        unseen += summary.switches_unseen;
        falls += summary.falls;
        pops.extend(summary.pops);
    }
    for p in &pops {
        eprintln!(
            "{} -> {}{}: {} switches; drawn: {:.2} cm, {:.2} deg, {:.3} m/s (largest; 95 %: {:.2} cm, {:.2} deg, {:.3} m/s); models alone: {:.1} cm, {:.1} deg",
            p.from,
            p.to,
            if p.forced { " forced" } else { "" },
            p.count,
            p.metres.max * 100.0,
            p.degrees.max,
            p.velocity_m_per_s.max,
            p.metres.p95 * 100.0,
            p.degrees.p95,
            p.velocity_m_per_s.p95,
            p.model_metres.max * 100.0,
            p.model_degrees.max
        );
    }
    let kinds: Vec<(&str, &str, bool)> = pops.iter().map(|p| (p.from, p.to, p.forced)).collect();
    for wanted in [
        ("hybrid", "rigid", false),
        ("rigid", "hybrid", false),
        ("hybrid", "rigid", true),
    ] {
        assert!(kinds.contains(&wanted), "no {wanted:?} switch in {kinds:?}");
    }
    // Every switch drawn is measured, but for those whose creature fell, or whose game ended,
    // within the three ticks the measure takes. A switch off screen (the camera rule's to and
    // from the point mass) is not drawn: it is counted apart, not measured.
    assert!(unseen > 0, "the camera rule switches off screen");
    let measured = pops.iter().map(|p| p.count as u64).sum::<u64>();
    let drawn = switches - unseen;
    assert!(
        measured <= drawn && drawn - measured <= falls + 3,
        "{measured} of {drawn} switches drawn measured ({unseen} unseen, {falls} falls)"
    );
    for p in &pops {
        // The bars, as drawn: in the flight window under 1 cm and 2 degrees, forced by
        // a collision under 2 cm and 5 degrees, the body's velocity within 0.1 m/s; and the
        // blend at least halves each kind's largest jump in metres.
        let (metres, degrees) = if p.forced { (0.02, 5.0) } else { (0.01, 2.0) };
        assert!(p.metres.max < metres && p.degrees.max < degrees, "{p:?}");
        assert!(p.velocity_m_per_s.max < 0.1, "{p:?}");
        assert!(p.metres.max * 2.0 < p.model_metres.max, "{p:?}");
    }
    // The models alone do pop: that is what the blend hides.
    assert!(pops.iter().any(|p| p.model_degrees.max > 2.0), "{pops:?}");
}

#[test]
fn kinds_on_virtual_legs_switch_under_the_same_bars() {
    // The kangaroo's two legs and the quadruped's four, switched by the game's rules.
    let groups = [("hopper", 10), ("kangaroo", 15), ("quadruped", 15)];
    let config = scene_in(config_having("quadruped"), &groups, LevelPolicy::Combined);
    let (_, summary) = digest_after(config, 20.0);
    let switched = summary
        .pops
        .iter()
        .filter(|p| !p.forced)
        .map(|p| p.count)
        .sum::<usize>();
    assert!(switched >= 20, "{:?}", summary.pops);
    for p in &summary.pops {
        let (metres, degrees) = if p.forced { (0.02, 5.0) } else { (0.01, 2.0) };
        assert!(p.metres.max < metres && p.degrees.max < degrees, "{p:?}");
        assert!(p.velocity_m_per_s.max < 0.1, "{p:?}");
    }
}

#[test]
fn blending_changes_what_is_drawn_never_the_outcome() {
    let (blended, mut a) = digest_after(game(true), 15.0);
    let (unblended, mut b) = digest_after(game(false), 15.0);
    assert_eq!(blended, unblended, "the simulated state, bit for bit");
    assert!(a.switches.total() > 10);
    // Only the pops as drawn differ.
    let drawn_without_blend: Vec<f32> = b.pops.iter().map(|p| p.degrees.max).collect();
    assert!(drawn_without_blend.iter().any(|d| *d > 2.0), "{drawn_without_blend:?}");
    a.pops.clear();
    b.pops.clear();
    assert_eq!(a, b);
}

#[test]
fn a_fall_right_after_going_rigid_is_counted_apart() {
    let fall_after = |wait_s: f64| {
        let config = scene(&[("hopper", 1)], LevelPolicy::AllHybrid);
        let (mut sim, hopper) = lone_creature(&config, "hopper", LevelPolicy::AllHybrid, Vec2::new(-100.0, 0.0), 300.0);
        sim.app
            .world_mut()
            .entity_mut(hopper)
            .insert(DesiredVelocity(Vec2::new(1.0, 0.0)));
        sim.run_for(2.0);
        sim.app.world_mut().resource_mut::<SimConfig>().scenario.level_policy = LevelPolicy::AllRigid;
        while sim.app.world().get::<Lod>(hopper) != Some(&Lod::Rigid) {
            sim.advance_frame();
        }
        sim.run_for(wait_s);
        // 60 N s sideways: more than any foot placement catches (see the rigid tests).
        sim.app.world_mut().entity_mut(hopper).insert(Shove(Vec3::Z * 60.0));
        sim.run_for(3.0);
        let s = sim.summary(0.0);
        (s.falls, s.falls_after_switch)
    };
    assert_eq!(fall_after(0.0), (1, 1), "pushed over in its first step as a rigid body");
    assert_eq!(fall_after(3.0), (1, 0), "pushed over long after the switch");
}
