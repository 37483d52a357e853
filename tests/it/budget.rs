//! The budget policy: the predicted frame stays within the budget, the budget goes where a
//! contact comes soonest, the same files give the same run, and a budget too small for even
//! the cheapest levels is said, not refused.

use bevy::ecs::message::Messages;
use bevy::prelude::*;
use std::cell::Cell;
use std::collections::HashSet;

use crate::support::*;
use simlod::arena::PuckState;
use simlod::config::{CostModel, CrowdShares, LevelCosts, RigidShare, SimConfig};
use simlod::contract::SwitchCounts;
use simlod::creature::{Creature, PlanarState};
use simlod::headless::HeadlessSim;
use simlod::lod::{BudgetTally, LevelChoice, LevelPolicy, LevelSwitched, Lod};

/// Costs set here, so that the tests do not move with the machine's calibration.
const COSTS: LevelCosts = LevelCosts {
    point_mass_us_per_frame: 1.0,
    hybrid_us_per_frame: 2.0,
    rigid_us_per_frame: 100.0,
    switch_to_rigid_us: 50.0,
    cheap_switch_us: 0.0,
};

/// `hoppers` hoppers under the budget policy with `budget_ms` and the costs above.
fn budget_scene(hoppers: u32, budget_ms: f32) -> SimConfig {
    let mut config = scene(&[("hopper", hoppers)], LevelPolicy::Budget);
    config.costs = CostModel {
        kinds: vec![],
        other_kinds: COSTS,
        fixed_us_per_frame: 0.0,
        decision_us_per_creature: 0.0,
        floors_only_us_per_creature: 0.0,
        contact_search_us: 0.0,
        crowd_shares: None,
        larger_crowd_shares: Vec::new(),
        rigid_shares: Vec::new(),
    };
    config.rules.budget.frame_budget_ms = budget_ms;
    config
}

/// The rigid creatures on average over a game of `seconds` under the budget, whose every
/// decision it kept.
fn rigid_on_average_within_budget(config: SimConfig, seconds: f64) -> f64 {
    let mut sim = HeadlessSim::new(config);
    sim.run_for(seconds);
    let summary = sim.summary(0.0);
    assert_eq!(summary.budget.unwrap().decisions_over_budget, 0);
    summary.levels_mean[Lod::Rigid]
}

/// What the creatures' levels cost now, by the cost model.
fn cost_of_levels_us(sim: &mut HeadlessSim) -> f32 {
    let world = sim.app.world_mut();
    world
        .query_filtered::<&Lod, With<Creature>>()
        .iter(world)
        .map(|&l| COSTS.per_frame_us(l))
        .sum()
}

#[test]
fn the_predicted_cost_never_exceeds_the_budget() {
    // 30 hoppers and room for four or five rigid ones.
    let budget_ms = 0.6;
    let mut sim = HeadlessSim::new(budget_scene(30, budget_ms));
    let mut rigid_seen = 0;
    for _ in 0..(15 * 30) {
        sim.advance_frame();
        let tally = sim.app.world().resource::<BudgetTally>().clone();
        assert!(
            tally.predicted_us() <= budget_ms * 1e3,
            "predicted {} us at {} s",
            tally.predicted_us(),
            sim.clock().seconds()
        );
        assert_eq!(tally.over_budget, 0);
        let levels_us = cost_of_levels_us(&mut sim);
        assert!(levels_us <= budget_ms * 1e3, "the levels cost {levels_us} us");
        let world = sim.app.world_mut();
        rigid_seen = rigid_seen.max(world.query::<&Lod>().iter(world).filter(|&&l| l == Lod::Rigid).count());
    }
    // The budget is spent, not hoarded: some creatures were rigid.
    assert!(rigid_seen >= 3, "at most {rigid_seen} rigid");
    let summary = sim.summary(0.0);
    // The slowest frame, predicted from the levels simulated, is the frame rate guaranteed.
    assert!(
        summary.predicted_frame.slowest_ms <= f64::from(budget_ms),
        "{:?}",
        summary.predicted_frame
    );
    let budget = summary.budget.expect("a budget summary");
    assert_eq!(budget.decisions_over_budget, 0);
    assert!(budget.predicted_ms_max <= budget_ms);
}

#[test]
fn every_policy_reports_its_frames_as_the_cost_model_predicts_them_from_the_levels() {
    // 10 hoppers, a court costing 30 us: 1.03 ms all rigid, 0.04 ms all point masses.
    for (policy, frame_ms) in [(LevelPolicy::AllRigid, 1.03), (LevelPolicy::AllPointMass, 0.04)] {
        let mut config = budget_scene(10, 0.0);
        config.scenario.level_policy = policy;
        config.costs.fixed_us_per_frame = 30.0;
        let mut sim = HeadlessSim::new(config);
        sim.run_for(2.0);
        let frame = sim.summary(0.0).predicted_frame;
        assert!(
            (frame.mean_ms - frame_ms).abs() < 1e-6 && (frame.slowest_ms - frame_ms).abs() < 1e-6,
            "{policy:?}: {frame:?}"
        );
    }
}

#[test]
fn the_rigid_level_is_priced_at_its_share_among_as_many_rigid_creatures_as_there_are() {
    // 10 hoppers all rigid, a court costing 30 us, the rigid level at half its figure among
    // 10 or more: 0.53 ms.
    let shares = |share: f32| vec![RigidShare { rigid: 2, share: 1.0 }, RigidShare { rigid: 10, share }];
    let mut config = budget_scene(10, 0.0);
    (config.scenario.level_policy, config.costs.fixed_us_per_frame) = (LevelPolicy::AllRigid, 30.0);
    config.costs.rigid_shares = shares(0.5);
    let mut sim = HeadlessSim::new(config);
    sim.run_for(2.0);
    let frame = sim.summary(0.0).predicted_frame;
    assert!((frame.mean_ms - 0.53).abs() < 1e-6, "{frame:?}");
    // The budget buys at the same price: among 30 hoppers with room for some five rigid at
    // the figure, more once they are rigid at a third of it among ten.
    let rigid_on_average = |rigid_shares: Vec<RigidShare>| {
        let mut config = budget_scene(30, 0.6);
        config.costs.rigid_shares = rigid_shares;
        rigid_on_average_within_budget(config, 10.0)
    };
    let (at_figure, cheaper) = (rigid_on_average(Vec::new()), rigid_on_average(shares(1.0 / 3.0)));
    assert!(
        cheaper > 1.5 * at_figure,
        "{cheaper} rigid on average against {at_figure}"
    );
}

#[test]
fn among_a_crowd_the_rigid_level_is_priced_at_the_crowds_share_too() {
    // A crowd stepped across the cores in a court grown to the same density, with room for
    // every creature at the hybrid level (2 us) and some thirty rigid steps at the figure:
    // fewer once a rigid creature costs three times as much among the crowd.
    let creatures = simlod::PARALLEL_MIN_CREATURES;
    let budget_ms = (f64::from(creatures) * 2e-3 + 3.0) as f32;
    let rigid_on_average = |rigid: f32| {
        let mut config = simlod_lab::scene::scaled(&budget_scene(40, budget_ms), creatures, LevelPolicy::Budget);
        config.costs.crowd_shares = Some(CrowdShares {
            creatures,
            point_mass: 1.0,
            hybrid: 1.0,
            choice: 1.0,
            floors_only: 1.0,
            rigid,
        });
        rigid_on_average_within_budget(config, 5.0)
    };
    let (at_figure, dearer) = (rigid_on_average(1.0), rigid_on_average(3.0));
    assert!(
        at_figure > 1.5 * dearer && dearer > 0.0,
        "{dearer} rigid on average at three times the figure against {at_figure}"
    );
}

#[test]
fn with_a_least_benefit_per_cost_the_budget_is_a_ceiling_not_a_target() {
    // Room for all 20 hoppers rigid: spent on all of them with no least benefit, on only the
    // few near a contact with one.
    let rigid_on_average = |least_benefit_per_ms: f32| {
        let mut config = budget_scene(20, 100.0);
        config.rules.budget.least_benefit_per_ms = least_benefit_per_ms;
        rigid_on_average_within_budget(config, 10.0)
    };
    let (all, some) = (rigid_on_average(0.0), rigid_on_average(5.0));
    assert!(all > 19.0, "{all} rigid on average with no least benefit");
    assert!(some > 0.0 && some < 10.0, "{some} rigid on average at 5 per ms");
}

#[test]
fn the_creature_about_to_be_hit_is_rigid_before_the_one_far_from_everything() {
    // Two hoppers, and only the contact counts (no view, no followed creature). With no
    // budget both start at the point mass; then one is put just ahead of the puck, the other
    // far from the puck and the walls, and the budget made room for one rigid creature.
    let mut config = budget_scene(2, 0.0);
    let b = &mut config.rules.budget;
    (b.view_hybrid_weight, b.view_rigid_weight, b.player_rigid_weight) = (0.0, 0.0, 0.0);
    let mut sim = HeadlessSim::new(config);
    sim.advance_frame();
    let world = sim.app.world_mut();
    let puck = *world.resource::<PuckState>();
    let half = world.resource::<simlod::arena::Court>().half_extents;
    let ahead = puck.position + puck.velocity.normalize() * (puck.radius_m + 2.5);
    let far = [Vec2::new(-12.0, 0.0), Vec2::new(12.0, 0.0), Vec2::ZERO]
        .into_iter()
        .max_by(|a, b| a.distance(puck.position).total_cmp(&b.distance(puck.position)))
        .unwrap();
    assert!(far.distance(puck.position) > 12.0 && (half - far.abs()).min_element() > 8.0);
    assert!(
        (half - ahead.abs()).min_element() > 1.0,
        "the puck is too near a wall: {puck:?}"
    );
    let mut serials = Vec::new();
    for (c, mut s) in world.query::<(&Creature, &mut PlanarState)>().iter_mut(world) {
        s.position = if serials.is_empty() { ahead } else { far };
        s.velocity = Vec2::ZERO;
        serials.push(c.serial);
    }
    let (threatened, safe) = (serials[0], serials[1]);
    // One going rigid (100 + 50 us) and one point mass fit; two rigid do not.
    world.resource_mut::<SimConfig>().rules.budget.frame_budget_ms = 0.2;
    let level_of = |sim: &mut HeadlessSim, serial: u32| {
        let world = sim.app.world_mut();
        world
            .query::<(&Creature, &Lod, &LevelChoice)>()
            .iter(world)
            .find(|(c, ..)| c.serial == serial)
            .map(|(_, &l, choice)| (l, choice.wanted))
            .unwrap()
    };
    sim.advance_frame();
    assert_eq!(level_of(&mut sim, threatened).1, Lod::Rigid);
    assert_eq!(level_of(&mut sim, safe).1, Lod::PointMass);
    // It becomes rigid (in its flight window, or at once if the puck reaches it first).
    for _ in 0..15 {
        sim.advance_frame();
    }
    assert_eq!(level_of(&mut sim, threatened).0, Lod::Rigid);
    assert_eq!(level_of(&mut sim, safe).0, Lod::PointMass);
}

#[test]
fn the_budget_policy_with_its_cost_model_is_deterministic() {
    let run = || {
        let mut sim = HeadlessSim::new(budget_scene(30, 0.5));
        sim.run_for(10.0);
        (sim.state_digest(), sim.summary(0.0).without_wall_clock())
    };
    let (a, b) = (run(), run());
    assert_eq!(a, b);
    assert!(a.1.switches.total() > 10, "levels should move: {:?}", a.1.switches);
}

#[test]
fn a_budget_too_small_for_the_cheapest_levels_gives_them_and_says_it_was_exceeded() {
    // 20 point masses alone cost 20 us; the budget is 10.
    let mut sim = HeadlessSim::new(budget_scene(20, 0.01));
    sim.run_for(5.0);
    let summary = sim.summary(0.0);
    assert_eq!(summary.levels[Lod::PointMass], 20, "{:?}", summary.levels);
    assert_eq!(summary.switches.total(), 0);
    let budget = summary.budget.expect("a budget summary");
    assert!(budget.decisions > 0);
    assert_eq!(budget.decisions_over_budget, budget.decisions);
    assert!(budget.predicted_ms_max >= 0.02 - 1e-6, "{budget:?}");
}

#[test]
fn the_fixed_cost_and_the_choice_come_off_the_budget_before_any_creature() {
    // 30 hoppers, 0.6 ms: room for four or five rigid ones. With a frame's fixed cost of
    // 0.3 ms and a choice of 5 us per creature the levels have 0.15 ms: one going rigid
    // (100 + 50 us) does not fit beside 29 point masses, and the prediction counts both.
    let budget_ms = 0.6;
    let mut config = budget_scene(30, budget_ms);
    config.costs.fixed_us_per_frame = 300.0;
    config.costs.decision_us_per_creature = 5.0;
    // Every creature worked out: a quiet one's choice would not be charged (the incremental
    // choice, tested apart).
    config.rules.budget.incremental_choice = false;
    let mut sim = HeadlessSim::new(config.clone());
    let mut rigid_seen = 0;
    for _ in 0..(10 * 30) {
        sim.advance_frame();
        let tally = sim.app.world().resource::<BudgetTally>().clone();
        assert!(
            tally.predicted_us() >= 450.0 && tally.predicted_us() <= budget_ms * 1e3,
            "{tally:?}"
        );
        let world = sim.app.world_mut();
        rigid_seen = rigid_seen.max(world.query::<&Lod>().iter(world).filter(|&&l| l == Lod::Rigid).count());
    }
    assert!(rigid_seen <= 1, "{rigid_seen} rigid at once");
    assert_eq!(sim.summary(0.0).budget.unwrap().decisions_over_budget, 0);
    // An overhead that leaves no room for a step leaves every creature at its cheapest; the
    // choice is then only its pass over the crowd, charged at its own cost: over budget where
    // the fixed cost, the 30 point masses and the pass are (550 + 30 + 15 us is not, 550 + 30
    // + 30 and 580 + 30 are).
    for (fixed_us, pass_us, over) in [(550.0, 0.5, false), (550.0, 1.0, true), (580.0, 0.0, true)] {
        config.costs.fixed_us_per_frame = fixed_us;
        config.costs.floors_only_us_per_creature = pass_us;
        let mut sim = HeadlessSim::new(config.clone());
        sim.run_for(3.0);
        let summary = sim.summary(0.0);
        assert_eq!(summary.levels[Lod::PointMass], 30, "{:?}", summary.levels);
        let budget = summary.budget.unwrap();
        let expected = if over { budget.decisions } else { 0 };
        assert_eq!(budget.decisions_over_budget, expected, "{fixed_us} us: {budget:?}");
        let predicted_us = fixed_us + 30.0 * (1.0 + pass_us);
        assert!(
            (budget.predicted_ms_max * 1e3 - predicted_us).abs() < 0.01,
            "{predicted_us} us: {budget:?}"
        );
        assert!(budget.searched_per_decision == 0.0, "{budget:?}");
    }
}

/// Runs `seconds` of a budget scene, telling the policy after each frame that it took
/// `measured(tally)` microseconds: frame times set here, not the machine's.
fn with_frames_measured(config: SimConfig, seconds: f64, measured: impl Fn(&BudgetTally) -> f32) -> HeadlessSim {
    let mut sim = HeadlessSim::new(config);
    let frames = (seconds * 30.0) as usize;
    for _ in 0..frames {
        sim.advance_frame();
        let us = measured(sim.app.world().resource::<BudgetTally>());
        sim.app.world_mut().resource_mut::<BudgetTally>().measured_us = Some(us);
    }
    sim
}

#[test]
fn the_adaptive_mode_spends_less_where_frames_measure_dearer_than_the_cost_model() {
    let budget_ms = 0.6;
    let mut config = budget_scene(30, budget_ms);
    config.rules.budget.adaptive_frames = 10.0;
    // Every frame measures three times what the cost model predicted for it.
    let mut sim = with_frames_measured(config.clone(), 8.0, |t| 3.0 * t.model_us);
    let tally = sim.app.world().resource::<BudgetTally>().clone();
    assert!((tally.correction - 3.0).abs() < 0.05, "{tally:?}");
    // The model's prediction now fits a third of the budget; the corrected one the budget.
    assert!(tally.model_us <= budget_ms * 1e3 / 3.0 + 1e-3, "{tally:?}");
    assert!(tally.predicted_us() <= budget_ms * 1e3 + 1e-3, "{tally:?}");
    let summary = sim.summary(0.0);
    let budget = summary.budget.expect("a budget summary");
    assert!(budget.adaptive && (budget.correction - 3.0).abs() < 0.05, "{budget:?}");
    // Off, the same measurements change nothing: fewer rigid creatures only with it on.
    config.rules.budget.adaptive_frames = 0.0;
    let mut off = with_frames_measured(config, 8.0, |t| 3.0 * t.model_us);
    let off_summary = off.summary(0.0);
    assert_eq!(off_summary.budget.unwrap().correction, 1.0);
    assert!(
        summary.levels_mean[Lod::Rigid] < off_summary.levels_mean[Lod::Rigid],
        "rigid on average: adaptive {} against {}",
        summary.levels_mean[Lod::Rigid],
        off_summary.levels_mean[Lod::Rigid]
    );
}

#[test]
fn the_percentile_mode_keeps_that_share_of_the_frames_within_the_budget_not_their_mean() {
    let budget_ms = 0.6;
    let mut config = budget_scene(30, budget_ms);
    config.rules.budget.adaptive_frames = 30.0;
    // One frame in five measures three times what the cost model predicted, the rest as
    // predicted.
    let spiky = |t: &BudgetTally| if t.decisions.is_multiple_of(5) { 3.0 } else { 1.0 } * t.model_us;
    let run = |percentile: f32| {
        let mut config = config.clone();
        config.rules.budget.adaptive_percentile = percentile;
        let mut sim = with_frames_measured(config, 6.0, spiky);
        let tally = sim.app.world().resource::<BudgetTally>().clone();
        (tally, sim.summary(0.0).levels_mean[Lod::Rigid])
    };
    // The correction follows the mean frame, about 1.4 times the model, either way.
    let (mean, rigid_mean) = run(0.0);
    let (p90, rigid_p90) = run(90.0);
    for tally in [&mean, &p90] {
        assert!((1.2..1.7).contains(&tally.correction), "{tally:?}");
    }
    // The 90th percentile of the last 30 frames is a slow one: what it took beyond the mean is
    // kept free, so that the slow frames too fit the budget. It buys fewer rigid creatures.
    assert_eq!(mean.headroom_us, 0.0);
    assert!(p90.headroom_us > 0.0, "{p90:?}");
    assert!(p90.predicted_us() <= budget_ms * 1e3 + 1e-3, "{p90:?}");
    assert!(
        rigid_p90 < rigid_mean,
        "rigid on average: {rigid_p90} keeping the 90th percentile, {rigid_mean} the mean"
    );
    // Their median is a frame as predicted, under the mean: it leaves room for more.
    let (p50, _) = run(50.0);
    assert!(p50.headroom_us < 0.0, "{p50:?}");
}

/// A budget scene in the percentile mode at the 99th percentile, kept within `limit` times a
/// budget of 0.6 ms, whose frames take 0.3 ms more than the cost model predicts one in 60 and
/// the rest as predicted: too common for the 99th percentile to leave over its limit, too rare
/// for the last 30 frames to hold one at every decision. Once the percentile's window has
/// filled: the frames over that limit, and the mean frame, ms; and the tally at the end.
fn slow_frames_one_in_60(limit: f32) -> (u32, f32, BudgetTally) {
    let budget_ms = 0.6;
    let mut config = budget_scene(30, budget_ms);
    config.rules.budget.adaptive_frames = 30.0;
    config.rules.budget.adaptive_percentile = 99.0;
    config.rules.budget.adaptive_percentile_limit = limit;
    let (frame, over, sum_us) = (Cell::new(0u32), Cell::new(0u32), Cell::new(0.0f32));
    let measured = |t: &BudgetTally| {
        let n = frame.get();
        frame.set(n + 1);
        let us = t.model_us + if n % 60 == 59 { 300.0 } else { 0.0 };
        if n >= 300 {
            over.set(over.get() + u32::from(us > limit * budget_ms * 1e3));
            sum_us.set(sum_us.get() + us);
        }
        us
    };
    let sim = with_frames_measured(config, 20.0, measured);
    let mean_ms = sum_us.get() / (frame.get() - 300) as f32 / 1e3;
    (over.get(), mean_ms, sim.app.world().resource::<BudgetTally>().clone())
}

#[test]
fn the_percentile_mode_keeps_slow_frames_as_rare_as_its_percentile_allows_within_the_budget() {
    // Of the last 300 frames, 3 may be over the budget at the 99th percentile: none is, since
    // the slow frames' excess is kept free of it throughout.
    let (over, _, tally) = slow_frames_one_in_60(1.0);
    assert_eq!(over, 0, "slow frames over the budget");
    assert!(tally.headroom_us >= 290.0, "{tally:?}");
}

#[test]
fn a_rounds_first_second_of_slow_frames_is_left_out_of_the_percentile() {
    let mut config = budget_scene(30, 0.6);
    config.rules.budget.adaptive_frames = 30.0;
    config.rules.budget.adaptive_percentile = 99.0;
    // The first 30 frames (the world built, every creature's first search) take 5 ms more than
    // predicted, the rest as predicted.
    let frame = Cell::new(0u32);
    let measured = |t: &BudgetTally| {
        frame.set(frame.get() + 1);
        t.model_us + if frame.get() <= 30 { 5000.0 } else { 0.0 }
    };
    let sim = with_frames_measured(config, 3.0, measured);
    // Counted, the 99th percentile of the last 300 frames would be one of them, 5 ms over, for
    // 10 s. Left out, it is a frame as predicted (under the correction they left, still
    // settling back: below it).
    let tally = sim.app.world().resource::<BudgetTally>();
    assert!(tally.frames_measured > 60, "{tally:?}");
    assert!(tally.headroom_us < 100.0, "{tally:?}");
}

#[test]
fn a_percentile_limit_over_the_budget_spends_nearer_it_and_keeps_the_slow_frames_within_the_limit() {
    let (_, within_the_budget_ms, _) = slow_frames_one_in_60(1.0);
    // Within 1.5 times the 0.6 ms budget, the slow frames' 0.3 ms fits above a mean at the
    // budget itself: the mean comes nearer it, no slow frame past 0.9 ms.
    let (over, mean_ms, _) = slow_frames_one_in_60(1.5);
    assert_eq!(over, 0, "slow frames over 1.5 times the budget");
    assert!(
        mean_ms > within_the_budget_ms + 0.1 && mean_ms <= 0.6 * 1.01,
        "mean {mean_ms} ms, at a limit of the budget {within_the_budget_ms} ms"
    );
}

#[test]
fn in_the_adaptive_mode_a_frame_far_over_the_budget_cuts_the_next_decision_at_once() {
    let budget_ms = 0.6;
    let mut config = budget_scene(30, budget_ms);
    config.rules.budget.adaptive_frames = 30.0;
    // No dwell: each decision may take back any level at once.
    config.rules.min_dwell_s = 0.0;
    let wanted_rigid = |sim: &mut HeadlessSim| {
        let world = sim.app.world_mut();
        let mut choices = world.query::<&LevelChoice>();
        choices.iter(world).filter(|c| c.wanted == Lod::Rigid).count()
    };
    // Frames measure as predicted for 2 s, then one three times its prediction: the creatures
    // wanted rigid before the spike, and the tally and creatures wanted rigid after the
    // decision that follows it.
    let spike = |emergency_over: f32| {
        let mut config = config.clone();
        config.rules.budget.emergency_over = emergency_over;
        let mut sim = with_frames_measured(config, 2.0, |t| t.model_us);
        let before = wanted_rigid(&mut sim);
        let model_us = sim.app.world().resource::<BudgetTally>().model_us;
        assert!(
            3.0 * model_us > 1.5 * budget_ms * 1e3,
            "the spike is over the line: {model_us} us"
        );
        sim.app.world_mut().resource_mut::<BudgetTally>().measured_us = Some(3.0 * model_us);
        sim.advance_frame();
        let tally = sim.app.world().resource::<BudgetTally>().clone();
        (before, tally, wanted_rigid(&mut sim))
    };
    // With the emergency tier, the next decision spends as if every frame cost three times the
    // model: it wants fewer creatures rigid at once.
    let (before, at_once, rigid_at_once) = spike(1.5);
    assert!((at_once.correction - 3.0).abs() < 0.05, "{at_once:?}");
    assert!(rigid_at_once < before, "rigid wanted: {before}, then {rigid_at_once}");
    // Without it, the spike moves the correction a thirtieth of the way, and the next decision
    // keeps more of them.
    let (_, smoothed, rigid_smoothed) = spike(0.0);
    assert!(smoothed.correction < 1.1, "{smoothed:?}");
    assert!(
        rigid_smoothed > rigid_at_once,
        "rigid wanted: {rigid_smoothed} smoothed, {rigid_at_once} at once"
    );
}

#[test]
fn with_the_adaptive_mode_off_measured_frame_times_do_not_change_the_run() {
    let config = budget_scene(30, 0.5);
    let mut slow = with_frames_measured(config.clone(), 5.0, |_| 1e6);
    let mut fast = with_frames_measured(config, 5.0, |_| 1.0);
    assert_eq!(slow.state_digest(), fast.state_digest());
}

#[test]
fn a_bad_cost_model_or_a_missing_one_is_refused_naming_the_file_and_the_field() {
    use crate::assets::{assets_with, edited};
    let load = |root: std::path::PathBuf| SimConfig::load(&root.join("scenarios/default.ron"), &root).unwrap_err();
    let negative = edited("costs.ron", "rigid_us_per_frame: ", "rigid_us_per_frame: -");
    let err = load(assets_with("budget_negative_cost", "costs.ron", &negative));
    let text = err.to_string();
    assert!(err.file.ends_with("costs.ron"), "{text}");
    assert!(
        text.contains("`kinds[0].costs.rigid_us_per_frame`") && text.contains("got -"),
        "{text}"
    );
    let gone = edited("rules/levels.ron", "\"costs.ron\"", "\"gone.ron\"");
    let err = load(assets_with("budget_missing_costs", "rules/levels.ron", &gone));
    let text = err.to_string();
    assert!(err.file.ends_with("rules/levels.ron"), "{text}");
    assert!(
        text.contains("`budget.cost_model`") && text.contains("gone.ron"),
        "{text}"
    );
}

#[test]
fn a_search_for_contacts_with_other_creatures_stands_for_the_recheck_time_and_is_paid_from_the_budget() {
    // 60 hoppers, room for about twenty rigid: searches per decision and rigid creatures.
    let run = |recheck_s: f32, search_us: f32| {
        let mut config = budget_scene(60, 3.0);
        config.rules.budget.contact_recheck_s = recheck_s;
        config.costs.contact_search_us = search_us;
        let mut sim = HeadlessSim::new(config);
        sim.run_for(5.0);
        let summary = sim.summary(0.0);
        let budget = summary.budget.expect("a budget summary");
        assert_eq!(budget.decisions_over_budget, 0);
        (budget.searched_per_decision, summary.levels_mean[Lod::Rigid])
    };
    let (every_decision, rigid) = run(0.0, 0.0);
    let (standing, _) = run(0.5, 0.0);
    assert!(every_decision > 10.0, "{every_decision} searched a decision");
    assert!(standing < every_decision / 3.0, "{standing} against {every_decision}");
    // Searches at 50 us each leave less of the budget for rigid creatures.
    let (_, rigid_with_dear_searches) = run(0.0, 50.0);
    assert!(
        rigid_with_dear_searches < rigid,
        "{rigid_with_dear_searches} against {rigid}"
    );
}

#[test]
fn a_budget_cut_below_the_cheapest_levels_sends_the_rigid_to_their_floors_and_holds_the_rest() {
    // Room for a few rigid creatures: the levels move.
    let mut sim = HeadlessSim::new(budget_scene(30, 0.5));
    let min_dwell_s = sim.app.world().resource::<SimConfig>().rules.min_dwell_s;
    assert!(min_dwell_s >= 0.2, "{min_dwell_s}");
    // Until a creature has just switched up: it dwells at its level through the next decision.
    let levels = |sim: &mut HeadlessSim| {
        let world = sim.app.world_mut();
        let now = world.resource::<simlod::contract::SimClock>().seconds() as f32;
        let mut rows: Vec<_> = world
            .query::<(&Creature, &Lod, &LevelChoice)>()
            .iter(world)
            .map(|(c, &l, choice)| (c.serial, l, *choice, now))
            .collect();
        rows.sort_by_key(|r| r.0);
        rows
    };
    let just_up = |rows: &[(u32, Lod, LevelChoice, f32)]| -> Vec<u32> {
        rows.iter()
            .filter(|(_, l, choice, now)| *l > Lod::PointMass && choice.switched && now - choice.last_switch_s < 0.1)
            .map(|r| r.0)
            .collect()
    };
    let mut dwelling = Vec::new();
    for _ in 0..300 {
        sim.advance_frame();
        dwelling = just_up(&levels(&mut sim));
        if !dwelling.is_empty() {
            break;
        }
    }
    assert!(!dwelling.is_empty(), "no creature went above the point mass");
    let before = levels(&mut sim);
    let hybrids = |rows: &[(u32, Lod, LevelChoice, f32)]| rows.iter().filter(|r| r.1 == Lod::Hybrid).count();
    assert!(hybrids(&before) > 0, "no hybrid to hold");
    // Now not one step up fits beside the floors: the choice gives them at once, but a
    // creature below the rigid level keeps its level (its switch would cost more than it saves).
    sim.app
        .world_mut()
        .resource_mut::<SimConfig>()
        .rules
        .budget
        .frame_budget_ms = 0.001;
    sim.advance_frame();
    for ((serial, level, ..), (_, _, choice, _)) in before.iter().zip(levels(&mut sim)) {
        let floor = if dwelling.contains(serial) || *level < Lod::Rigid {
            *level
        } else {
            Lod::PointMass
        };
        assert_eq!(choice.wanted, floor, "creature {serial}");
    }
    let tally = sim.app.world().resource::<BudgetTally>().clone();
    assert!(tally.over_budget > 0 && tally.model_us > 100.0, "{tally:?}");
    // Once the dwell is over, no creature wants the rigid level, and the hybrids are held.
    sim.run_for(f64::from(min_dwell_s) + 0.2);
    let after = levels(&mut sim);
    assert!(after.iter().all(|(_, _, choice, _)| choice.wanted != Lod::Rigid));
    for ((serial, level, ..), (_, _, choice, _)) in before.iter().zip(&after) {
        if *level == Lod::Hybrid {
            assert_eq!(choice.wanted, Lod::Hybrid, "creature {serial}");
        }
    }
}

#[test]
fn a_hybrid_whose_switch_down_costs_more_than_it_saves_is_kept_hybrid_as_the_view_moves_on() {
    // 30 hoppers with room for a few rigid ones: the creatures in the view's reach are given
    // the hybrid level, and the view follows one creature about the court. Counted: the
    // switches of creatures the budget has chosen for (a creature respawned after a fall
    // keeps the level it fell at and has no choice until the next decision).
    let switches = |cheap_switch_us: f32| {
        let mut config = budget_scene(30, 0.5);
        config.costs.other_kinds.cheap_switch_us = cheap_switch_us;
        let mut sim = HeadlessSim::new(config);
        let (mut chosen, mut counts) = (HashSet::new(), SwitchCounts::default());
        for _ in 0..(15 * 30) {
            sim.advance_frame();
            let world = sim.app.world_mut();
            for s in world
                .resource::<Messages<LevelSwitched>>()
                .iter_current_update_messages()
            {
                if chosen.contains(&s.serial) {
                    counts.count(s.from, s.to);
                }
            }
            chosen = world.query::<&Creature>().iter(world).map(|c| c.serial).collect();
        }
        counts
    };
    // Free, a switch down saves the hybrid's 1 us over the point mass's: hybrids leaving the
    // view's reach go down.
    let free = switches(0.0);
    assert!(free.between(Lod::Hybrid, Lod::PointMass) > 0, "{free:?}");
    // At 5 us, it costs more than the 1 us it saves: not one goes down, and fewer come up.
    let priced = switches(5.0);
    assert_eq!(priced.between(Lod::Hybrid, Lod::PointMass), 0, "{priced:?}");
    assert!(priced.between(Lod::PointMass, Lod::Hybrid) > 0, "{priced:?}");
    assert!(
        priced.between(Lod::PointMass, Lod::Hybrid) < free.between(Lod::PointMass, Lod::Hybrid),
        "{priced:?} against {free:?}"
    );
}

#[test]
fn in_a_crowd_at_a_tight_budget_the_quiet_creatures_are_left_unworked_and_their_cost_buys_levels() {
    // 3,000 hoppers at the default game's density, weighed by their contacts alone; working out
    // a creature costs 0.9 us beyond the pass over it, so that the choice working out every
    // creature (3 ms) leaves no room beside the floors (3 ms) in 5.5 ms.
    let run = |incremental: bool| {
        let mut config = budget_scene(3000, 5.5);
        let grow = (3000.0f32 / 40.0).sqrt();
        (config.arena.court_length_m, config.arena.court_width_m) =
            (config.arena.court_length_m * grow, config.arena.court_width_m * grow);
        let costs = &mut config.costs;
        (
            costs.decision_us_per_creature,
            costs.floors_only_us_per_creature,
            costs.contact_search_us,
        ) = (1.0, 0.1, 2.0);
        // The camera sees 100 m deep: most of the court is out of view.
        config.rules.camera.far_m = 100.0;
        let budget = &mut config.rules.budget;
        (
            budget.view_hybrid_weight,
            budget.view_rigid_weight,
            budget.incremental_choice,
        ) = (0.0, 0.0, incremental);
        let mut sim = HeadlessSim::new(config);
        sim.run_for(3.0);
        (sim.state_digest(), sim.summary(0.0).without_wall_clock())
    };
    let (incremental, every_creature) = (run(true), run(false));
    let (quiet, whole) = (
        incremental.1.budget.clone().unwrap(),
        every_creature.1.budget.clone().unwrap(),
    );
    // Most of the court is out of view: most of the crowd is never worked out.
    assert!(quiet.quiet_per_decision > 1000.0, "{quiet:?}");
    assert_eq!(whole.quiet_per_decision, 0.0);
    // Within the budget; where the room it saves shrinks (fewer quiet), the creatures it
    // bought still run their levels until their flight windows.
    for b in [&quiet, &whole] {
        assert!(b.predicted_ms_max <= 5.5 * 1.01, "{b:?}");
    }
    // What it saves buys rigid creatures the full choice had no room for: it buys none.
    let rigid = |s: &simlod::outcome::Summary| s.levels_mean[Lod::Rigid];
    let (more, fewer) = (rigid(&incremental.1), rigid(&every_creature.1));
    assert!(more > fewer + 1.5, "{more} against {fewer}: {quiet:?}");
    // The same files give the same run.
    assert_eq!(run(true), incremental);
}
