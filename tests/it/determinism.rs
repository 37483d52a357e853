//! Same seed, same files, same result, bit for bit.

use crate::support::*;
use bevy::prelude::*;
use simlod::creature::PlanarState;
use simlod::lod::Lod;
use simlod::models::point_mass::{FrameStep, FrameStepping};

#[test]
fn two_runs_with_one_seed_end_in_identical_states() {
    let a = digest_after(default_config(), 20.0);
    let b = digest_after(default_config(), 20.0);
    assert_eq!(a, b);
    assert!(
        a.1.respawns > 0 || a.1.collisions.iter().map(|(_, n)| n).sum::<u64>() > 0,
        "the run should have events: {:?}",
        a.1
    );
}

#[test]
fn a_crowd_large_enough_to_run_in_parallel_is_deterministic_too() {
    let config = config_with_hoppers(simlod::PARALLEL_MIN_CREATURES * 2);
    assert_eq!(digest_after(config.clone(), 3.0), digest_after(config.clone(), 3.0));
    // The budget policy too, with room for more than point masses: its benefits are worked out
    // across the cores.
    let mut config = config;
    config.scenario.level_policy = simlod::lod::LevelPolicy::Budget;
    config.rules.budget.frame_budget_ms = 40.0;
    let run = digest_after(config.clone(), 2.0);
    assert_eq!(run, digest_after(config, 2.0));
    assert!(run.1.levels_peak[Lod::Rigid] > 0, "{:?}", run.1);
}

#[test]
fn another_seed_gives_another_game() {
    let mut other = default_config();
    other.scenario.seed += 1;
    assert_ne!(digest_after(default_config(), 5.0).0, digest_after(other, 5.0).0);
}

#[test]
fn the_rigid_level_is_deterministic_too() {
    let config = scene(&[("hopper", 30), ("biped", 10)], simlod::lod::LevelPolicy::AllRigid);
    let a = digest_after(config.clone(), 5.0);
    assert_eq!(a, digest_after(config, 5.0));
    assert_eq!(a.1.levels[Lod::Rigid], 40);
}

/// Runs `config` for `seconds` with frame stepping on or off, then `then` on the world at a
/// decision; its state digest and summary.
fn stepped(
    config: &simlod::config::SimConfig,
    enabled: bool,
    seconds: f64,
    then: impl FnOnce(&mut simlod::headless::HeadlessSim),
) -> (u64, simlod::outcome::Summary) {
    let mut sim = simlod::headless::HeadlessSim::new(config.clone());
    sim.app.insert_resource(FrameStepping { enabled });
    sim.run_for(seconds);
    then(&mut sim);
    (sim.state_digest(), sim.summary(0.0).without_wall_clock())
}

/// Runs the rest of a frame, one tick at a time, from its decision's tick.
fn finish_frame(sim: &mut simlod::headless::HeadlessSim) {
    let ticks = sim
        .app
        .world()
        .resource::<simlod::contract::SimClock>()
        .ticks_per_decision;
    for _ in 1..ticks {
        tick_and_count_behind(sim);
    }
}

/// Runs one tick; how many creatures are behind their frame after it.
fn tick_and_count_behind(sim: &mut simlod::headless::HeadlessSim) -> usize {
    simlod::headless::run_ticks_per_update(sim.app.world_mut(), 1);
    sim.app.update();
    let world = sim.app.world_mut();
    world.query::<&FrameStep>().iter(world).filter(|f| f.behind).count()
}

#[test]
fn creatures_stepped_a_frame_at_a_time_end_where_they_would_a_tick_at_a_time() {
    use simlod::lod::LevelPolicy::*;
    for policy in [AllPointMass, AllHybrid, Influence, Combined, Budget] {
        let config = scene(&[("hopper", 90), ("biped", 30)], policy);
        // After 4 s, the decision's tick: the creatures behind their frame. Compared at the
        // frame's end (mid-frame, one behind holds the frame's start).
        let mut behind = 0;
        let on = stepped(&config, true, 4.0, |sim| {
            behind = tick_and_count_behind(sim);
            finish_frame(sim);
        });
        let off = stepped(&config, false, 4.0, |sim| {
            assert_eq!(
                tick_and_count_behind(sim),
                0,
                "{policy:?}: none falls behind when it is off"
            );
            finish_frame(sim);
        });
        assert_eq!(on, off, "{policy:?}");
        assert!(on.1.collisions.iter().any(|(_, n)| n > 0), "{policy:?}: {:?}", on.1);
        assert!(behind > 30, "{policy:?}: only {behind} of 120 behind their frame");
    }
}

/// Every creature's pose after `seconds` (a frame's end) with frame stepping on or off, each
/// stale one worked out on demand, by serial; and how many were stale and how many of those
/// held a pose other than their own.
fn poses_at_frame_end(
    config: &simlod::config::SimConfig,
    enabled: bool,
    seconds: f64,
) -> (Vec<(u32, simlod::gait::GaitPose)>, usize, usize) {
    use simlod::creature::{Creature, GaitPhase, KindTable};
    use simlod::gait::GaitPose;
    let mut sim = simlod::headless::HeadlessSim::new(config.clone());
    sim.app.insert_resource(FrameStepping { enabled });
    sim.run_for(seconds);
    let (mut stale, mut moved) = (0, 0);
    let mut poses = sim.app.world_mut().resource_scope(|world, kinds: Mut<KindTable>| {
        world
            .query::<(&Creature, &Lod, &PlanarState, &GaitPhase, &mut GaitPose, &mut FrameStep)>()
            .iter_mut(world)
            .map(|(c, &lod, state, gait, mut pose, mut frame)| {
                let held = *pose;
                if frame.pose_stale {
                    stale += 1;
                    frame.pose_now(&kinds[c.kind], lod, state, gait, &mut pose);
                    moved += usize::from(*pose != held);
                }
                (c.serial, *pose)
            })
            .collect::<Vec<_>>()
    });
    poses.sort_by_key(|p| p.0);
    (poses, stale, moved)
}

#[test]
fn a_hybrid_left_unposed_behind_its_frame_is_posed_on_demand_as_a_tick_at_a_time_poses_it() {
    let config = scene(&[("hopper", 90), ("biped", 30)], simlod::lod::LevelPolicy::AllHybrid);
    let (on, stale, moved) = poses_at_frame_end(&config, true, 4.0);
    let (off, none, _) = poses_at_frame_end(&config, false, 4.0);
    assert_eq!(none, 0, "stepped a tick at a time, every pose is worked out");
    assert!(
        stale > 30 && moved > 30,
        "{stale} of 120 left unposed, {moved} of them out of date"
    );
    assert_eq!(on, off);
}

#[test]
fn creatures_behind_their_frame_are_caught_up_when_the_puck_goes_farther_than_it_could() {
    let config = scene(&[("hopper", 200)], simlod::lod::LevelPolicy::AllPointMass);
    let half = config.arena.half_extents();
    // The creature farthest from the puck (and from the walls), chosen at the frame's start,
    // where every creature is up to date; on the decision's tick, the puck is put down touching
    // where it was then: it and the others behind their frame are stepped to the tick before
    // any is checked against the puck.
    let teleport = |sim: &mut simlod::headless::HeadlessSim, was_behind: &mut bool| {
        let world = sim.app.world_mut();
        let puck = *world.resource::<simlod::arena::PuckState>();
        let (serial, target) = world
            .query::<(&simlod::kind::Creature, &PlanarState)>()
            .iter(world)
            .filter(|(_, s)| (half - s.position.abs()).min_element() > 3.0)
            .map(|(c, s)| (c.serial, s.position))
            .max_by(|a, b| a.1.distance(puck.position).total_cmp(&b.1.distance(puck.position)))
            .unwrap();
        tick_and_count_behind(sim);
        let world = sim.app.world_mut();
        *was_behind = world
            .query::<(&simlod::kind::Creature, &FrameStep)>()
            .iter(world)
            .any(|(c, f)| c.serial == serial && f.behind);
        let mut puck = world.query_filtered::<&mut Transform, With<simlod::arena::Puck>>();
        let mut transform = puck.single_mut(world).unwrap();
        transform.translation.x = target.x + 2.2;
        transform.translation.z = target.y;
        (0..3).map(|_| tick_and_count_behind(sim)).collect()
    };
    let mut was_behind = false;
    let mut behind_after = Vec::new();
    let on = stepped(&config, true, 2.0, |sim| behind_after = teleport(sim, &mut was_behind));
    assert!(
        was_behind,
        "the creature beside which the puck lands was behind its frame"
    );
    // The tick it lands, the puck has not gone anywhere yet in rapier; the tick after, every
    // creature has been caught up.
    assert_eq!(behind_after[1], 0, "{behind_after:?}");
    let off = stepped(&config, false, 2.0, |sim| {
        teleport(sim, &mut false);
    });
    assert_eq!(on, off);
    assert!(
        on.1.collisions
            .iter()
            .any(|(o, n)| o == simlod::outcome::Obstacle::Puck && n > 0)
    );
}

#[test]
fn the_headless_camera_follows_its_creature_at_every_tick_with_frame_stepping_on() {
    // The budget (its levels may change, so the camera is placed at every tick), small and with
    // no rigid level bought for being seen or followed: the followed creature stays planar.
    let mut config = scene(&[("hopper", 90), ("biped", 30)], simlod::lod::LevelPolicy::Budget);
    config.rules.budget.player_rigid_weight = 0.0;
    config.rules.budget.view_rigid_weight = 0.0;
    config.rules.budget.frame_budget_ms = 0.5;
    // A second's ticks after 2 s: where the camera is at each, and how many are behind.
    let watch = |enabled: bool| {
        let (mut eyes, mut behind) = (Vec::new(), 0);
        stepped(&config, enabled, 2.0, |sim| {
            for _ in 0..240 {
                behind = behind.max(tick_and_count_behind(sim));
                eyes.push(sim.app.world().resource::<simlod::lod::SimCamera>().eye);
            }
        });
        (eyes, behind)
    };
    let (on, behind) = watch(true);
    assert!(behind > 30, "only {behind} of 120 behind their frame");
    assert_eq!(on, watch(false).0);
}
