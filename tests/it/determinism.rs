//! Same seed, same files, same result, bit for bit.

use crate::support::*;
use simlod::lod::Lod;

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
    assert_eq!(digest_after(config.clone(), 3.0), digest_after(config, 3.0));
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
