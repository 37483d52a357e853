//! Every input runs exactly what it asked for: every tick at every rate the checks allow,
//! every creature counted, placed in bounded time.

use crate::support::*;
use simlod::config::{Validate, Validator};
use simlod::headless::HeadlessSim;
use simlod::lod::LevelPolicy;
use simlod_lab::bench::scaled;

/// Whether the scenario's checks accept these rates.
fn allowed(tick_hz: u32, decision_hz: u32) -> bool {
    let mut scenario = default_config().scenario;
    scenario.tick_hz = tick_hz;
    scenario.decision_hz = decision_hz;
    let mut v = Validator::default();
    scenario.validate(&mut v);
    v.finish(std::path::Path::new("scenario")).is_ok()
}

#[test]
fn every_tick_asked_for_runs_at_every_allowed_rate() {
    let mut checked = 0;
    // The slowest, the default and the fastest tick, each with every decision rate the checks
    // allow (down to 1 Hz: a frame of a whole second, more than Bevy's 250 ms clock cap).
    for tick_hz in [30, 240, 2000] {
        for decision_hz in (1..=tick_hz).filter(|&d| allowed(tick_hz, d)) {
            let mut config = config_with_hoppers(1);
            config.scenario.level_policy = LevelPolicy::AllPointMass;
            config.scenario.tick_hz = tick_hz;
            config.scenario.decision_hz = decision_hz;
            let mut sim = HeadlessSim::new(config);
            sim.run_for(2.0);
            assert_eq!(
                sim.clock().tick,
                2 * u64::from(tick_hz),
                "{tick_hz} Hz ticks, {decision_hz} Hz decisions: 2 s asked"
            );
            assert_eq!(sim.clock().seconds(), 2.0);
            checked += 1;
        }
    }
    assert!(!allowed(240, 7) && !allowed(240, 0) && !allowed(29, 1) && !allowed(2001, 1));
    assert_eq!(checked, 8 + 20 + 20, "every divisor of 30, 240 and 2000");
}

#[test]
fn the_bench_scales_a_scenario_with_an_empty_group() {
    let mut config = default_config();
    config.scenario.creatures[0].count = 0;
    let bench = scaled(&config, 50, LevelPolicy::AllPointMass);
    assert_eq!(bench.scenario.creature_count(), 50);
    assert!(bench.arena.court_length_m.is_finite() && bench.arena.court_length_m < 1000.0);
    let mut sim = HeadlessSim::new(bench);
    sim.advance_frame();
    assert_eq!(creatures(&mut sim).len(), 50);
    // No creature at all: the first group gets them, in a court of finite size.
    config.scenario.creatures[1].count = 0;
    let bench = scaled(&config, 20, LevelPolicy::AllPointMass);
    assert_eq!(bench.scenario.creature_count(), 20);
    assert!(bench.arena.court_width_m.is_finite());
    HeadlessSim::new(bench).advance_frame();
}

#[test]
fn a_court_filled_to_the_limit_is_placed_in_full_and_the_same_every_time() {
    let mut config = config_with_hoppers(1);
    config.scenario.level_policy = LevelPolicy::AllPointMass;
    config.scenario.creatures[0].count = config.fit().most as u32;
    assert!(config.fit().needed_m2 <= config.fit().room_m2);
    assert!(
        config.scenario.creature_count() > 1000,
        "{}",
        config.scenario.creature_count()
    );
    let digest = |config| {
        let mut sim = HeadlessSim::new(config);
        sim.advance_frame();
        let placed = creatures(&mut sim);
        let half = sim
            .app
            .world()
            .resource::<simlod::config::SimConfig>()
            .arena
            .half_extents();
        assert!(placed.iter().all(|(_, s)| vec2_in_court(s.position, half)));
        (placed.len(), sim.state_digest())
    };
    let first = digest(config.clone());
    assert_eq!(first.0 as u32, config.scenario.creature_count());
    assert_eq!(first, digest(config), "one seeded RNG: the same placement");
}
