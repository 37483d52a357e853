use bevy::prelude::*;
use std::path::{Path, PathBuf};

use simlod::config::SimConfig;
use simlod::creature::{Creature, PlanarState};
use simlod::headless::HeadlessSim;

/// The `simlod` binary, built by the CLI crate beside these tests (`cargo test` at the
/// workspace's root builds it first).
pub fn simlod_bin() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    // target/<profile>/deps/it-<hash>: the binary is in target/<profile>.
    let bin = exe
        .parent()
        .and_then(Path::parent)
        .expect("a target folder")
        .join("simlod");
    assert!(
        bin.exists(),
        "{} is not built: run the tests from the workspace's root (`cargo test --release`)",
        bin.display()
    );
    bin
}

pub fn assets_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets")
}

pub fn default_config() -> SimConfig {
    let root = assets_root();
    SimConfig::load(&root.join("scenarios/default.ron"), &root).expect("the shipped assets load")
}

/// A scenario that has `kind`: the default one, or the one of every shipped kind.
pub fn config_having(kind: &str) -> SimConfig {
    let config = default_config();
    if config.kind_index(kind).is_some() {
        return config;
    }
    let root = assets_root();
    SimConfig::load(&root.join("scenarios/all-kinds.ron"), &root).expect("the shipped assets load")
}

/// The default scenario with `count` hoppers.
pub fn config_with_hoppers(count: u32) -> SimConfig {
    let mut config = default_config();
    config.scenario.creatures.retain(|g| g.kind == "hopper");
    config.scenario.creatures[0].count = count;
    config
}

/// Every creature's serial, kind and planar state.
pub fn creatures(sim: &mut HeadlessSim) -> Vec<(Creature, PlanarState)> {
    let world = sim.app.world_mut();
    world
        .query::<(&Creature, &PlanarState)>()
        .iter(world)
        .map(|(c, s)| (*c, *s))
        .collect()
}

/// A scratch folder for one test's files.
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[allow(dead_code)]
pub fn vec2_in_court(p: Vec2, half: Vec2) -> bool {
    p.x.abs() <= half.x && p.y.abs() <= half.y
}

/// The shipped kinds and arena in a scene set here: `groups` of (kind, count) under `policy`,
/// seed 7, so that tests do not move when `default.ron` is retuned.
pub fn scene(groups: &[(&str, u32)], policy: simlod::lod::LevelPolicy) -> SimConfig {
    scene_in(default_config(), groups, policy)
}

/// As [`scene`], from `config`'s files (its kinds, arena and rules).
pub fn scene_in(mut config: SimConfig, groups: &[(&str, u32)], policy: simlod::lod::LevelPolicy) -> SimConfig {
    config.scenario.seed = 7;
    config.scenario.creatures = groups
        .iter()
        .map(|&(kind, count)| simlod::config::CreatureGroup {
            kind: kind.to_owned(),
            count,
        })
        .collect();
    config.scenario.level_policy = policy;
    config
}

/// The state digest and summary (wall time aside) after `seconds` of `config`.
pub fn digest_after(config: SimConfig, seconds: f64) -> (u64, simlod::outcome::Summary) {
    let mut sim = HeadlessSim::new(config);
    sim.run_for(seconds);
    (sim.state_digest(), sim.summary(0.0).without_wall_clock())
}

/// A copy of the shipped assets folder in a scratch folder of the test's own.
pub fn copy_assets(test: &str) -> std::path::PathBuf {
    fn copy_dir(from: &Path, to: &Path) {
        std::fs::create_dir_all(to).unwrap();
        for entry in std::fs::read_dir(from).unwrap().flatten() {
            let (path, target) = (entry.path(), to.join(entry.file_name()));
            if path.is_dir() {
                copy_dir(&path, &target);
            } else {
                std::fs::copy(&path, &target).unwrap();
            }
        }
    }
    let dir = scratch_dir(test);
    copy_dir(&assets_root(), &dir);
    dir
}
