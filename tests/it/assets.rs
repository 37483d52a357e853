//! The asset files: the shipped ones load, broken ones give an error that names the file,
//! the field and what is wrong, through both the file path and the asset server.

use bevy::asset::{AssetPlugin, LoadState};
use bevy::prelude::*;
use std::path::{Path, PathBuf};

use crate::support::*;
use simlod::config::{ArenaConfig, ConfigError, CreatureDef, RigidJoints, Scenario, SimConfig, load_file};

/// A copy of the shipped assets in a scratch folder, with one file replaced.
pub(crate) fn assets_with(test: &str, file: &str, contents: &[u8]) -> PathBuf {
    let dir = scratch_dir(test);
    for sub in ["", "creatures", "scenarios", "rules", "gaits", "experiments"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        for entry in std::fs::read_dir(assets_root().join(sub)).unwrap().flatten() {
            if entry.path().is_file() {
                std::fs::copy(entry.path(), dir.join(sub).join(entry.file_name())).unwrap();
            }
        }
    }
    std::fs::write(dir.join(file), contents).unwrap();
    dir
}

/// Where a recorded gait table's first sample starts (it does not depend on the values).
const FIRST_SAMPLE: &str = "samples: [\n                [";

/// The shipped file with `from` replaced by `to`.
pub(crate) fn edited(file: &str, from: &str, to: &str) -> Vec<u8> {
    let text = std::fs::read_to_string(assets_root().join(file)).unwrap();
    assert!(text.contains(from), "{file} has no {from:?}");
    text.replacen(from, to, 1).into_bytes()
}

fn load_error(test: &str, file: &str, contents: &[u8]) -> ConfigError {
    let root = assets_with(test, file, contents);
    SimConfig::load(&root.join("scenarios/default.ron"), &root).expect_err("a broken file must not load")
}

fn assert_names(err: &ConfigError, file: &str, field: &str, words: &str) {
    let text = err.to_string();
    assert!(err.file.ends_with(file), "error should name {file}: {text}");
    assert!(
        text.contains(&format!("`{field}`")) || field.is_empty(),
        "error should name field {field}: {text}"
    );
    assert!(
        text.to_lowercase().contains(words),
        "error should say {words:?}: {text}"
    );
}

#[test]
fn the_crowd_scenario_runs_thousands_of_creatures_at_every_level_inside_its_larger_court() {
    let root = assets_root();
    let config = SimConfig::load(&root.join("scenarios/crowd.ron"), &root).unwrap();
    let default = default_config();
    assert!(
        config.scenario.creature_count() >= 2000,
        "{}",
        config.scenario.creature_count()
    );
    let (half, default_half) = (config.arena.half_extents(), default.arena.half_extents());
    assert!(half.x * half.y >= 10.0 * default_half.x * default_half.y);
    let mut sim = simlod::headless::HeadlessSim::new(config.clone());
    sim.run_for(1.0);
    let summary = sim.summary(0.0);
    // The camera rule: detailed where the camera looks, point masses elsewhere.
    for level in simlod::lod::Lod::ALL {
        assert!(summary.levels[level] > 0, "{level:?}: {summary:?}");
    }
    for (_, state) in creatures(&mut sim) {
        assert!(state.position.abs().cmple(half).all(), "{state:?}");
    }
}

#[test]
fn shipped_assets_load_and_validate() {
    let config = default_config();
    assert_eq!(config.kinds.len(), 2);
    assert!(config.arena.puck.speed_m_per_s > config.kinds.iter().map(|k| k.top_speed_m_per_s).fold(0.0, f32::max));
}

#[test]
fn a_missing_field_is_named() {
    let err = load_error(
        "missing_field",
        "creatures/hopper.ron",
        &edited("creatures/hopper.ron", "mass_kg: 10.0,", ""),
    );
    assert_names(&err, "creatures/hopper.ron", "body.mass_kg", "missing");
}

#[test]
fn a_value_of_the_wrong_type_is_named_by_its_whole_path() {
    let err = load_error(
        "wrong_type",
        "creatures/hopper.ron",
        &edited("creatures/hopper.ron", "mass_kg: 10.0,", "mass_kg: \"heavy\","),
    );
    assert_names(&err, "creatures/hopper.ron", "body.mass_kg", "line");
}

#[test]
fn the_rigid_joints_are_impulse_joints_unless_the_file_says_multibody_and_others_are_named() {
    let kinds = |config: &SimConfig| -> Vec<RigidJoints> {
        config.kinds.iter().map(|k| k.rigid.as_ref().unwrap().joints).collect()
    };
    assert_eq!(kinds(&default_config()), [RigidJoints::Impulse; 2]);
    for (to, joints) in [
        ("", RigidJoints::Impulse),
        ("joints: Multibody,", RigidJoints::Multibody),
    ] {
        let root = assets_with(
            &format!("joints_{joints:?}"),
            "creatures/hopper.ron",
            &edited("creatures/hopper.ron", "joints: Impulse,", to),
        );
        let config = SimConfig::load(&root.join("scenarios/default.ron"), &root).unwrap();
        assert_eq!(kinds(&config)[config.kind_index("hopper").unwrap()], joints);
    }
    let err = load_error(
        "joints_unknown",
        "creatures/hopper.ron",
        &edited("creatures/hopper.ron", "joints: Impulse,", "joints: Springs,"),
    );
    assert_names(&err, "creatures/hopper.ron", "rigid.joints", "`multibody` or `impulse`");
}

#[test]
fn a_negative_mass_is_refused() {
    let err = load_error(
        "negative_mass",
        "creatures/hopper.ron",
        &edited("creatures/hopper.ron", "mass_kg: 10.0", "mass_kg: -10.0"),
    );
    assert_names(
        &err,
        "creatures/hopper.ron",
        "body.mass_kg",
        "between 0.01 and 10000 kg, got -10",
    );
}

#[test]
fn solver_iterations_default_to_eight_and_out_of_range_are_refused() {
    assert_eq!(default_config().scenario.solver_iterations, 8);
    let err = load_error(
        "solver_iterations",
        "scenarios/default.ron",
        &edited(
            "scenarios/default.ron",
            "decision_hz: 30,",
            "decision_hz: 30, solver_iterations: 0,",
        ),
    );
    assert_names(
        &err,
        "scenarios/default.ron",
        "solver_iterations",
        "between 1 and 16, got 0",
    );
}

#[test]
fn an_emergency_line_under_the_budget_is_refused() {
    let err = load_error(
        "emergency_over",
        "rules/levels.ron",
        &edited("rules/levels.ron", "emergency_over: 0.0", "emergency_over: 0.5"),
    );
    assert_names(
        &err,
        "rules/levels.ron",
        "budget.emergency_over",
        "must be 0 (none) or between 1 and 100, got 0.5",
    );
}

#[test]
fn a_percentile_limit_under_the_budget_is_refused() {
    let err = load_error(
        "adaptive_percentile_limit",
        "rules/levels.ron",
        &edited(
            "rules/levels.ron",
            "adaptive_percentile_limit: 1.0",
            "adaptive_percentile_limit: 0.9",
        ),
    );
    assert_names(
        &err,
        "rules/levels.ron",
        "budget.adaptive_percentile_limit",
        "must be between 1 and 10, got 0.9",
    );
}

#[test]
fn a_percentile_under_the_median_for_the_adaptive_mode_is_refused() {
    let err = load_error(
        "adaptive_percentile",
        "rules/levels.ron",
        &edited(
            "rules/levels.ron",
            "adaptive_percentile: 0.0",
            "adaptive_percentile: 20.0",
        ),
    );
    assert_names(
        &err,
        "rules/levels.ron",
        "budget.adaptive_percentile",
        "must be 0 (the mean) or between 50 and 100, got 20",
    );
}

#[test]
fn a_nan_is_refused() {
    let err = load_error(
        "nan",
        "arena.ron",
        &edited("arena.ron", "speed_m_per_s: 5.0", "speed_m_per_s: NaN"),
    );
    assert_names(&err, "arena.ron", "puck.speed_m_per_s", "finite");
}

#[test]
fn an_unknown_creature_kind_is_named_with_the_known_ones() {
    let err = load_error(
        "unknown_kind",
        "scenarios/default.ron",
        &edited("scenarios/default.ron", "\"biped\"", "\"tripod\""),
    );
    assert_names(
        &err,
        "scenarios/default.ron",
        "creatures[1].kind",
        "unknown creature kind \"tripod\"",
    );
    assert!(err.to_string().contains("biped, hopper"), "{err}");
}

#[test]
fn a_court_smaller_than_the_puck_is_refused() {
    let err = load_error(
        "small_court",
        "arena.ron",
        &edited("arena.ron", "court_width_m: 40.0", "court_width_m: 3.0"),
    );
    assert_names(&err, "arena.ron", "puck.radius_m", "does not fit in the court");
}

#[test]
fn a_court_too_large_to_index_is_refused() {
    let err = load_error(
        "huge_court",
        "arena.ron",
        &edited("arena.ron", "court_width_m: 40.0", "court_width_m: 1e6"),
    );
    assert_names(&err, "arena.ron", "court_width_m", "between 1 and 10000 m, got 1e6");
}

#[test]
fn a_leg_shorter_than_it_is_thick_is_refused() {
    let err = load_error(
        "stub_leg",
        "creatures/hopper.ron",
        &edited("creatures/hopper.ron", "upper_length_m: 0.45", "upper_length_m: 0.05"),
    );
    assert_names(
        &err,
        "creatures/hopper.ron",
        "legs[0].upper_length_m",
        "longer than it is thick",
    );
}

#[test]
fn a_creature_that_cannot_exist_is_refused_naming_the_fields_that_disagree() {
    for (from, to, field, words) in [
        (
            "hip_height_m: 0.8",
            "hip_height_m: 1.5",
            "body.hip_height_m",
            "where the leg cannot stand",
        ),
        (
            "rest_length_m: 0.75",
            "rest_length_m: 0.9",
            "legs[0].rest_length_m",
            "upper_length_m + lower_length_m",
        ),
        (
            "hip_m: (0.0, 0.0, 0.0)",
            "hip_m: (0.0, 0.0, 0.5)",
            "legs[0].hip_m",
            "outside body.radius_m",
        ),
        (
            "hip_m: (0.0, 0.0, 0.0)",
            "hip_m: (0.0, 0.0, 0.25)",
            "rigid.body_half_extents_m",
            "outside the body box",
        ),
        ("stance: Together", "stance: Alternating", "stance", "at least 2"),
        (
            "stance: Together",
            "stance: VirtualLegs([[0], [0]])",
            "stance",
            "exactly one virtual leg",
        ),
        (
            "stance: Together",
            "stance: VirtualLegs([[0, 1]])",
            "stance",
            "numbered 0 to 0",
        ),
        (
            "body_min_height_m: 0.4",
            "body_min_height_m: 0.85",
            "rigid.fall.body_min_height_m",
            "below body.hip_height_m",
        ),
    ] {
        let file = "creatures/hopper.ron";
        let err = load_error("impossible_creature", file, &edited(file, from, to));
        assert_names(&err, file, field, words);
    }
}

#[test]
fn garbage_bytes_are_refused() {
    let err = load_error("garbage", "creatures/biped.ron", &[0xff, 0xfe, 0x00, 0x13, 0x37, 0x80]);
    assert_names(&err, "creatures/biped.ron", "", "not a ron text file");
    let err = load_error("garbage_text", "creatures/biped.ron", b"{{ this is not ron ]");
    assert_names(&err, "creatures/biped.ron", "", "line 1");
}

#[test]
fn an_empty_file_is_refused() {
    let err = load_error("empty", "scenarios/default.ron", b"  \n");
    assert_names(&err, "scenarios/default.ron", "", "empty");
}

#[test]
fn a_misspelt_field_is_refused_not_ignored() {
    let err = load_error(
        "typo",
        "arena.ron",
        &edited("arena.ron", "wall_height_m", "wall_hieght_m"),
    );
    assert_names(&err, "arena.ron", "wall_hieght_m", "not a known field");
}

#[test]
fn every_problem_in_a_file_is_reported_at_once() {
    let bytes = edited(
        "creatures/hopper.ron",
        "top_speed_m_per_s: 3.0",
        "top_speed_m_per_s: -3.0",
    );
    let bytes = String::from_utf8(bytes)
        .unwrap()
        .replacen("hop_period_s: 0.5", "hop_period_s: 0.0", 1);
    let err = load_error("two_problems", "creatures/hopper.ron", bytes.as_bytes());
    let fields: Vec<&str> = err.problems.iter().map(|p| p.field.as_str()).collect();
    assert!(
        fields.contains(&"top_speed_m_per_s") && fields.contains(&"hop_period_s"),
        "{err}"
    );
}

/// Loads one asset through Bevy's asset server, as the game does.
fn load_through_asset_server<A: Asset + Clone>(root: &Path, file: &str) -> Result<A, String> {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin {
            file_path: root.to_string_lossy().into_owned(),
            ..default()
        },
    ))
    .add_plugins(simlod::config::plugin);
    app.finish();
    app.cleanup();
    let handle: Handle<A> = app.world().resource::<AssetServer>().load(file.to_owned());
    for _ in 0..2000 {
        app.update();
        match app.world().resource::<AssetServer>().load_state(&handle) {
            LoadState::Loaded => {
                return Ok(app.world().resource::<Assets<A>>().get(&handle).unwrap().clone());
            }
            LoadState::Failed(e) => return Err(e.to_string()),
            _ => std::thread::sleep(std::time::Duration::from_millis(1)),
        }
    }
    panic!("{file} neither loaded nor failed");
}

#[test]
fn the_asset_server_loads_the_same_values_as_the_file_path() {
    let root = assets_root();
    let scenario: Scenario = load_through_asset_server(&root, "scenarios/default.ron").unwrap();
    assert_eq!(
        scenario,
        load_file::<Scenario>(&root.join("scenarios/default.ron")).unwrap()
    );
    let arena: ArenaConfig = load_through_asset_server(&root, "arena.ron").unwrap();
    assert_eq!(arena, load_file::<ArenaConfig>(&root.join("arena.ron")).unwrap());
    let hopper: CreatureDef = load_through_asset_server(&root, "creatures/hopper.ron").unwrap();
    assert_eq!(
        hopper,
        load_file::<CreatureDef>(&root.join("creatures/hopper.ron")).unwrap()
    );
}

#[test]
fn the_asset_server_reports_a_broken_file_with_the_same_message() {
    let root = assets_with(
        "asset_server_nan",
        "arena.ron",
        &edited("arena.ron", "mass_kg: 5000.0", "mass_kg: -1.0"),
    );
    let err = load_through_asset_server::<ArenaConfig>(&root, "arena.ron").unwrap_err();
    assert!(
        err.contains("`puck.mass_kg`") && err.contains("between 0.1 and 1e6 kg, got -1"),
        "{err}"
    );
}

#[test]
fn absurd_sizes_masses_speeds_and_rates_are_refused_with_the_unit() {
    for (file, from, to, field, says) in [
        (
            "arena.ron",
            "wall_thickness_m: 0.5",
            "wall_thickness_m: 1e30",
            "wall_thickness_m",
            "between 0.01 and 100 m, got 1e30",
        ),
        (
            "arena.ron",
            "mass_kg: 5000.0",
            "mass_kg: 1e12",
            "puck.mass_kg",
            "kg, got 1e12",
        ),
        (
            "arena.ron",
            "speed_m_per_s: 5.0",
            "speed_m_per_s: 1e5",
            "puck.speed_m_per_s",
            "m/s, got 100000",
        ),
        (
            "creatures/biped.ron",
            "radius_m: 0.35",
            "radius_m: 1e30",
            "body.radius_m",
            "between 0.01 and 10 m",
        ),
        (
            "creatures/biped.ron",
            "hop_period_s: 0.4",
            "hop_period_s: 1e-9",
            "hop_period_s",
            "0.05 and 10 s",
        ),
        (
            "creatures/biped.ron",
            "separation_distance_m: 1.6",
            "separation_distance_m: 1e9",
            "steering.separation_distance_m",
            "0 and 100 m",
        ),
        (
            "creatures/biped.ron",
            "look_every_decisions_when_clear: 4",
            "look_every_decisions_when_clear: 0",
            "steering.look_every_decisions_when_clear",
            "1 to 64, not 0",
        ),
        (
            "rules/levels.ron",
            "lookahead_s: 1.0",
            "lookahead_s: 1e20",
            "influence.lookahead_s",
            "0 and 60 s",
        ),
        (
            "rules/levels.ron",
            "far_m: 1000.0,",
            "far_m: 0.0,",
            "camera.far_m",
            "between 1 and 1e6 m, got 0",
        ),
        (
            "gaits/hopper.ron",
            "sample_hz: 30.0",
            "sample_hz: 1e9",
            "sample_hz",
            "1 and 1000 hz",
        ),
        (
            "gaits/hopper.ron",
            FIRST_SAMPLE,
            "samples: [\n                [1e30, 0.0, 0.0, 0.7, 0.0, 0.0],\n                [",
            "rows[0].samples[0]",
            "body_height_m is 1e30",
        ),
    ] {
        let err = load_error("absurd", file, &edited(file, from, to));
        assert_names(&err, file, field, says);
    }
}

#[test]
fn a_reference_out_of_the_assets_folder_is_refused_naming_the_field() {
    let scenario = "scenarios/default.ron";
    let hopper = "creatures/hopper.ron";
    for (file, from, to, field, says) in [
        (
            scenario,
            "\"arena.ron\"",
            "\"../arena.ron\"",
            "arena",
            "inside the assets folder",
        ),
        (
            scenario,
            "\"arena.ron\"",
            "\"/etc/passwd\"",
            "arena",
            "relative to the assets folder",
        ),
        (
            scenario,
            "\"rules/levels.ron\"",
            "\"rules/../../x.ron\"",
            "level_rules",
            "inside the assets folder",
        ),
        (
            scenario,
            "\"biped\"",
            "\"../../x\"",
            "creatures[1].kind",
            "letters, digits",
        ),
        (
            hopper,
            "\"gaits/hopper.ron\"",
            "\"../gaits/hopper.ron\"",
            "gait_table",
            "inside the assets folder",
        ),
    ] {
        let err = load_error("outside", file, &edited(file, from, to));
        assert_names(&err, file, field, says);
    }
}

#[cfg(unix)]
#[test]
fn a_symbolic_link_out_of_the_assets_folder_is_refused() {
    let root = assets_with("symlink_out", "arena.ron", b"");
    let outside = root.parent().unwrap().join("symlink_out_secret.ron");
    std::fs::copy(assets_root().join("arena.ron"), &outside).unwrap();
    std::fs::remove_file(root.join("arena.ron")).unwrap();
    std::os::unix::fs::symlink(&outside, root.join("arena.ron")).unwrap();
    let err = SimConfig::load(&root.join("scenarios/default.ron"), &root).unwrap_err();
    assert_names(
        &err,
        "scenarios/default.ron",
        "arena",
        "leads outside the assets folder",
    );
    // A link that stays inside the folder is followed.
    std::fs::remove_file(root.join("arena.ron")).unwrap();
    std::fs::copy(&outside, root.join("rules/arena.ron")).unwrap();
    std::os::unix::fs::symlink(root.join("rules/arena.ron"), root.join("arena.ron")).unwrap();
    SimConfig::load(&root.join("scenarios/default.ron"), &root).unwrap();
}

#[test]
fn the_asset_server_refuses_a_reference_out_of_the_folder_as_the_file_path_does() {
    let root = assets_with(
        "asset_server_outside",
        "scenarios/default.ron",
        &edited("scenarios/default.ron", "\"arena.ron\"", "\"../arena.ron\""),
    );
    let err = load_through_asset_server::<Scenario>(&root, "scenarios/default.ron").unwrap_err();
    assert!(
        err.contains("`arena`") && err.contains("inside the assets folder"),
        "{err}"
    );
}

#[test]
fn an_empty_gait_table_name_is_named_in_the_creature_file() {
    let err = load_error(
        "empty_gait",
        "creatures/hopper.ron",
        &edited("creatures/hopper.ron", "\"gaits/hopper.ron\"", "\"\""),
    );
    assert_names(&err, "creatures/hopper.ron", "gait_table", "must name a file");
}

#[test]
fn a_missing_referenced_file_names_the_file_and_field_that_refer_to_it() {
    let err = load_error(
        "missing_ref",
        "scenarios/default.ron",
        &edited("scenarios/default.ron", "\"rules/levels.ron\"", "\"rules/gone.ron\""),
    );
    assert_names(&err, "scenarios/default.ron", "level_rules", "cannot read");
    assert!(err.to_string().contains("rules/gone.ron"), "{err}");
    let err = load_error(
        "missing_gait",
        "creatures/hopper.ron",
        &edited("creatures/hopper.ron", "\"gaits/hopper.ron\"", "\"gaits/gone.ron\""),
    );
    assert_names(&err, "creatures/hopper.ron", "gait_table", "cannot read");
    assert!(err.to_string().contains("gaits/gone.ron"), "{err}");
}

#[test]
fn a_file_starting_with_a_byte_order_mark_loads() {
    let marked = [
        &[0xef, 0xbb, 0xbf][..],
        &edited("scenarios/default.ron", "seed: 7", "seed: 7"),
    ]
    .concat();
    let root = assets_with("bom", "scenarios/default.ron", &marked);
    let config = SimConfig::load(&root.join("scenarios/default.ron"), &root).unwrap();
    assert_eq!(config.scenario, default_config().scenario);
}

#[test]
fn a_kind_whose_file_is_a_folder_is_refused_as_a_folder() {
    let root = assets_with(
        "kind_folder",
        "scenarios/default.ron",
        &edited("scenarios/default.ron", "\"biped\"", "\"tripod\""),
    );
    std::fs::create_dir_all(root.join("creatures/tripod.ron")).unwrap();
    let err = SimConfig::load(&root.join("scenarios/default.ron"), &root).unwrap_err();
    assert_names(
        &err,
        "scenarios/default.ron",
        "creatures[1].kind",
        "is a folder, not a file",
    );
    std::fs::remove_dir(root.join("creatures/tripod.ron")).unwrap();
    std::fs::create_dir_all(root.join("creatures/quad.ron")).unwrap();
    let err = SimConfig::load(&root.join("scenarios/default.ron"), &root).unwrap_err();
    let mut kinds: Vec<String> = std::fs::read_dir(assets_root().join("creatures"))
        .unwrap()
        .flatten()
        .filter_map(|e| e.path().file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    kinds.sort();
    let known = format!("known kinds: {}", kinds.join(", "));
    assert!(err.to_string().ends_with(&known), "{err}");
}

#[test]
fn values_of_the_wrong_type_are_named_by_their_whole_path() {
    for (file, from, to, field) in [
        (
            "creatures/hopper.ron",
            "max_tilt_deg: 45.0",
            "max_tilt_deg: [1]",
            "rigid.fall.max_tilt_deg",
        ),
        (
            "creatures/hopper.ron",
            "Some(\"gaits/hopper.ron\")",
            "Some(3)",
            "gait_table",
        ),
        ("scenarios/default.ron", "count: 10", "count: -1", "creatures[1].count"),
        (
            "scenarios/default.ron",
            "(kind: \"biped\"",
            "(kind: 3",
            "creatures[1].kind",
        ),
        (
            "rules/levels.ron",
            "flight_window: (0.1",
            "flight_window: (\"a\"",
            "flight_window[0]",
        ),
        (
            "gaits/hopper.ron",
            FIRST_SAMPLE,
            "samples: [\n                [\"x\", ",
            "rows[0].samples[0][0]",
        ),
    ] {
        let err = load_error("wrong_types", file, &edited(file, from, to));
        assert_names(&err, file, field, "line");
    }
}

#[test]
fn a_value_of_the_wrong_type_says_what_was_expected_and_what_was_found() {
    for (file, from, to, field, said) in [
        (
            "scenarios/default.ron",
            "count: 30",
            "count: 10.5",
            "creatures[0].count",
            "expected a whole number, found 10.5",
        ),
        (
            "scenarios/default.ron",
            "tick_hz: 240",
            "tick_hz: 240.5",
            "tick_hz",
            "expected a whole number, found 240.5",
        ),
        (
            "creatures/hopper.ron",
            "mass_kg: 10.0,",
            "mass_kg: \"heavy\",",
            "body.mass_kg",
            "expected a number, found \"heavy\"",
        ),
        (
            "rules/levels.ron",
            "min_dwell_s: 0.5",
            "min_dwell_s: yes",
            "min_dwell_s",
            "expected a number, found yes",
        ),
    ] {
        let err = load_error("wrong_type_found", file, &edited(file, from, to));
        assert_names(&err, file, field, said);
    }
}

#[test]
fn more_creatures_than_the_court_can_hold_are_refused_at_once_with_the_numbers() {
    let err = load_error(
        "too_many",
        "scenarios/default.ron",
        &edited("scenarios/default.ron", "count: 30", "count: 100000"),
    );
    assert_names(
        &err,
        "scenarios/default.ron",
        "creatures",
        "100010 creatures do not fit",
    );
    assert!(err.to_string().contains("at most about 1032"), "{err}");
}

#[test]
fn the_scenarios_solver_iterations_reach_rapier_which_recycles_no_contacts() {
    let mut config = config_with_hoppers(1);
    config.scenario.solver_iterations = 2;
    let mut sim = simlod::headless::HeadlessSim::new(config);
    let world = sim.app.world_mut();
    let parameters: Vec<(usize, bool)> = world
        .query::<&bevy_rapier3d::prelude::RapierContextSimulation>()
        .iter(world)
        .map(|s| {
            (
                s.integration_parameters.num_solver_iterations,
                s.integration_parameters.contact_recycling,
            )
        })
        .collect();
    assert_eq!(parameters, [(2, false)]);
}
