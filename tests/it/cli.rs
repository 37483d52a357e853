//! The headless command line as a user runs it: the binary, its output and exit status.

use std::process::{Command, Output};

fn simlod(args: &[&str]) -> Output {
    Command::new(crate::support::simlod_bin())
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the simlod binary runs")
}

#[test]
fn run_json_has_the_keys_of_the_summary() {
    let out = simlod(&[
        "run",
        "--seconds",
        "2",
        "--seed",
        "3",
        "--policy",
        "influence",
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    for key in [
        "collisions",
        "creatures_collided",
        "creatures_collided_with",
        "respawns",
        "falls_by_level",
        "levels",
        "levels_mean",
        "switches",
        "sim_seconds",
        "wall_seconds",
    ] {
        assert!(summary.get(key).is_some(), "no {key:?} in {summary}");
    }
    for kind in ["puck", "wall", "creature"] {
        assert!(summary["collisions"][kind].is_u64(), "{summary}");
    }
    assert_eq!(summary["seed"], 3);
    // It names what ran: the policy, its rules and its cost model.
    assert_eq!(summary["policy"], "influence");
    assert_eq!(summary["rules"], "assets/rules/levels.ron");
    assert_eq!(summary["cost_model"], "assets/costs.ron");
    assert!((summary["sim_seconds"].as_f64().unwrap() - 2.0).abs() < 1e-9);
    let total = |key: &str| -> u64 {
        summary[key]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap())
            .sum()
    };
    let creatures = summary["creatures"].as_u64().unwrap();
    assert_eq!(total("levels"), creatures, "every creature is at one level: {summary}");
    let with = |obstacle: &str| summary["creatures_collided_with"][obstacle].as_u64().unwrap();
    let (puck, wall, collided) = (
        with("puck"),
        with("wall"),
        summary["creatures_collided"].as_u64().unwrap(),
    );
    assert!(
        puck.max(wall) <= collided && collided <= puck + wall,
        "figure 10's count is the creatures that hit the puck or a wall: {summary}"
    );
    let by_level = total("falls_by_level");
    assert_eq!(by_level, summary["falls"], "every fall is at one level: {summary}");
}

#[test]
fn the_frame_budget_flag_sets_the_budget_the_run_keeps_to() {
    let out = simlod(&[
        "run",
        "--seconds",
        "2",
        "--policy",
        "budget",
        "--frame-budget",
        "0.5",
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let budget = &summary["budget"];
    assert!(
        (budget["frame_budget_ms"].as_f64().unwrap() - 0.5).abs() < 1e-6,
        "{budget}"
    );
    assert!(budget["predicted_ms_max"].as_f64().unwrap() <= 0.5 + 1e-6, "{budget}");
    // Beside a frame's fixed cost, room for a few rigid creatures of the 40 at the shipped cost
    // model's cheapest (a 4 ms budget makes all 40 rigid). A creature going down still runs
    // rigid until its flight window, and a collision forces a switch up: three more at most.
    let costs = crate::support::default_config().costs;
    let cheapest_rigid_us = (costs.kinds.iter().map(|k| k.costs.rigid_us_per_frame)).fold(f32::INFINITY, f32::min);
    let room_for = ((500.0 - costs.fixed_us_per_frame) / cheapest_rigid_us).floor();
    assert!(
        room_for < 10.0,
        "the shipped cost model leaves room for {room_for} rigid creatures"
    );
    let rigid = summary["levels_mean"]["rigid"].as_f64().unwrap();
    assert!(rigid <= f64::from(room_for) + 3.0, "room for {room_for}: {summary}");
}

/// A user's mistake is one clear message and exit status 2, never a panic.
#[test]
fn calibrating_writes_a_cost_model_that_loads_even_for_rules_whose_model_is_not_measured_yet() {
    let dir = std::env::temp_dir().join(format!("simlod-calibrate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Rules naming a cost model that does not exist yet: running under them is refused, and
    // calibrating them measures it.
    let levels = std::fs::read_to_string("assets/rules/levels.ron").unwrap();
    let rules = dir.join("new-rules.ron");
    std::fs::write(
        &rules,
        levels.replace("\"costs.ron\"", "\"costs-not-measured-yet.ron\""),
    )
    .unwrap();
    let rules = rules.to_str().unwrap();
    let refused = simlod(&["run", "--seconds", "1", "--rules", rules]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("costs-not-measured-yet.ron"));
    let file = dir.join("costs.ron");
    let out = simlod(&[
        "bench",
        "--calibrate",
        "--quick",
        "--rules",
        rules,
        "--out",
        file.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let model: simlod::config::CostModel = simlod::config::load_file(&file).expect("a valid cost model");
    std::fs::remove_dir_all(&dir).ok();
    // The court and the puck cost something whatever the creatures; a rigid creature far more
    // than a hybrid one, of every kind the scenario has.
    assert!(model.fixed_us_per_frame > 0.0, "{model:?}");
    assert_eq!(model.kinds.len(), 2, "{model:?}");
    for k in &model.kinds {
        assert!(k.costs.rigid_us_per_frame > 10.0 * k.costs.hybrid_us_per_frame, "{k:?}");
    }
    // The rigid level in play, among few rigid creatures and among many (the file loaded, so
    // the counts rise).
    assert_eq!(model.rigid_shares.len(), 2, "{model:?}");
    // The quick calibration's one crowd: the choice and the rigid level among it
    // measured (a share left unmeasured is exactly 1).
    let crowd = model.crowd_shares.expect("a crowd measured");
    assert!(model.larger_crowd_shares.is_empty(), "{model:?}");
    assert!(crowd.choice != 1.0 && crowd.rigid != 1.0, "{crowd:?}");
}

#[test]
fn bench_choice_times_the_budgets_choice_as_it_plays_and_with_room_for_every_step() {
    let out = simlod(&["bench", "--choice", "--quick", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let timed: Vec<serde_json::Value> = (String::from_utf8_lossy(&out.stdout).lines())
        .map(|line| serde_json::from_str(line).expect("a JSON object a line"))
        .collect();
    let [tight, played, every_step] = &timed[..] else {
        panic!("three objects: {timed:?}")
    };
    assert_eq!(played["creatures"], 20_000);
    for (at, budget_ms) in [(tight, 10.0), (played, 30.0)] {
        assert_eq!(
            (&at["frame_budget_ms"], &at["searches"]),
            (&budget_ms.into(), &true.into())
        );
    }
    assert_eq!(
        (
            &every_step["frame_budget_ms"],
            &every_step["searches"],
            &every_step["searched"]
        ),
        (&serde_json::Value::Null, &false.into(), &0.into())
    );
    for t in &timed {
        assert!(t["us_per_creature_per_frame"].as_f64().unwrap() > 0.0, "{t}");
    }
}

fn refused(args: &[&str], says: &str) {
    let out = simlod(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(says), "{args:?} should say {says:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

#[test]
fn a_bad_flag_or_file_is_a_clear_error_with_status_2() {
    refused(&["run", "--policy", "sometimes"], "sometimes");
    refused(&["run", "--seconds", "soon"], "soon");
    refused(&["run", "--seconds", "1e6"], "10000");
    // A negative number reaches the range check, with or without `=`.
    refused(&["run", "--puck-radius", "-3"], "between 0 and 10000 metres, got -3");
    refused(&["run", "--frame-budget", "-1"], "10000 ms");
    refused(&["run", "--seconds", "-2"], "more than 0");
    refused(&["bench", "--choice", "--level", "rigid"], "cannot be used with");
    // A flag the run's policy never reads is refused, not ignored.
    refused(
        &["run", "--policy", "combined", "--frame-budget", "1"],
        "--frame-budget does not apply to the combined policy",
    );
    refused(
        &["run", "--policy", "camera", "--puck-radius", "3"],
        "--puck-radius does not apply to the camera policy",
    );
    refused(
        &["run", "--policy", "influence", "--camera-radius", "3"],
        "--camera-radius does not apply",
    );
    // Experiments and the recorder set their own policy and rules: the flags are refused there.
    refused(
        &[
            "experiment",
            "fig10",
            "--quick",
            "--out",
            "target/never",
            "--puck-radius",
            "3",
        ],
        "--puck-radius does not apply to `simlod experiment`",
    );
    refused(
        &["experiment", "table1", "--out", "target/never", "--policy", "all-rigid"],
        "--policy does not apply to `simlod experiment`",
    );
    refused(
        &[
            "record-gait",
            "--creature",
            "assets/creatures/hopper.ron",
            "--rules",
            "rules/levels.ron",
        ],
        "--rules does not apply to `simlod record-gait`",
    );
    refused(
        &["run", "--policy", "influence", "--adaptive", "30"],
        "--adaptive does not apply to the influence policy",
    );
    refused(
        &["run", "--policy", "budget", "--adaptive", "0"],
        "between 1 and 10000 frames",
    );
    refused(
        &[
            "run",
            "--policy",
            "budget",
            "--adaptive",
            "30",
            "--adaptive-percentile",
            "40",
        ],
        "between 50 and 100, got 40",
    );
    refused(
        &["run", "--policy", "budget", "--adaptive-percentile", "99"],
        "--adaptive",
    );
    refused(
        &[
            "run",
            "--policy",
            "budget",
            "--adaptive",
            "30",
            "--adaptive-percentile",
            "99",
            "--adaptive-percentile-limit",
            "0.8",
        ],
        "between 1 and 10 times the budget, got 0.8",
    );
    refused(
        &[
            "run",
            "--policy",
            "budget",
            "--adaptive",
            "30",
            "--adaptive-percentile-limit",
            "1.2",
        ],
        "--adaptive-percentile",
    );
    refused(&["run", "--frame-budget=-1"], "10000 ms");
    refused(&["run", "--frame-budget", "lots"], "lots");
    refused(&["play", "--frame-budget=-1"], "10000 ms");
    refused(&["run", "--scenario", "assets/scenarios/nowhere.ron"], "nowhere.ron");
    refused(
        &[
            "record-gait",
            "--creature",
            "assets/creatures/hopper.ron",
            "--speeds",
            "2,1",
        ],
        "--speeds",
    );
}

#[test]
fn experiment_flags_are_checked() {
    refused(
        &["experiment", "fig10", "--quick", "--out", "/tmp/x", "--shard", "3/2"],
        "K/N",
    );
    refused(
        &["experiment", "fig8", "--quick", "--out", "/tmp/x", "--shard", "1/2"],
        "--shard",
    );
    refused(
        &["experiment", "fig10", "--quick", "--out", "/tmp/x", "--jobs", "0"],
        "--jobs",
    );
    refused(&["experiment", "merge", "/nowhere", "--out", "/tmp/x"], "/nowhere");
}

#[test]
fn record_gait_refuses_to_overwrite_another_kinds_table_unless_told_to() {
    // A copy of the hopper's file renamed, its `gait_table` line left in: it names the
    // hopper's table.
    let assets = crate::support::copy_assets("record_gait_other_kind");
    let hopper = std::fs::read_to_string(assets.join("creatures/hopper.ron")).unwrap();
    let copycat = hopper.replacen("name: \"hopper\"", "name: \"copycat\"", 1);
    assert_ne!(copycat, hopper, "the hopper's file names its kind");
    let file = assets.join("creatures/copycat.ron");
    std::fs::write(&file, copycat).unwrap();
    let table = assets.join("gaits/hopper.ron");
    let before = std::fs::read(&table).unwrap();
    let scenario = assets.join("scenarios/default.ron");
    let args = [
        "record-gait",
        "--assets",
        assets.to_str().unwrap(),
        "--scenario",
        scenario.to_str().unwrap(),
        "--creature",
        file.to_str().unwrap(),
        "--speeds",
        "0,1",
    ];
    refused(&args, "holds the gait table of `hopper`, not of `copycat`");
    assert_eq!(
        std::fs::read(&table).unwrap(),
        before,
        "the hopper's table is untouched"
    );
    // Told to, it records there.
    let out = simlod(&[&args[..], &["--replace-other-kind"]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let written: simlod::gait::GaitTable = simlod::config::load_file(&table).unwrap();
    assert_eq!(written.creature, "copycat");
}

#[test]
fn the_budget_line_says_when_the_measured_frame_is_over_the_budget() {
    // 10 us cannot hold even the court: both the policy's choice and the wall time are over.
    let out = simlod(&["run", "--policy", "budget", "--frame-budget", "0.01", "--seconds", "1"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("frame budget"))
        .expect("a budget line");
    assert!(line.contains("over it at 30 of 30 decisions"), "{line}");
    assert!(line.contains("% over the budget") && !line.contains("within"), "{line}");
    assert!(line.contains("at the 99th percentile"), "{line}");
}

#[test]
fn run_says_each_frame_measured_and_when_the_cost_model_is_not_this_machines() {
    // The shipped model at a hundredth of its figures: frames run far over its prediction.
    let assets = crate::support::copy_assets("run_stale_cost_model");
    let file = assets.join("costs.ron");
    let mut model: simlod::config::CostModel = simlod::config::load_file(&file).unwrap();
    for costs in model
        .kinds
        .iter_mut()
        .map(|k| &mut k.costs)
        .chain([&mut model.other_kinds])
    {
        costs.point_mass_us_per_frame /= 100.0;
        costs.hybrid_us_per_frame /= 100.0;
        costs.rigid_us_per_frame /= 100.0;
    }
    model.fixed_us_per_frame /= 100.0;
    std::fs::write(&file, ron::ser::to_string(&model).unwrap()).unwrap();
    let assets = assets.to_str().unwrap();
    let out = simlod(&["run", "--assets", assets, "--seconds", "1", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let frame = &summary["measured_frame"];
    let ms = |key: &str| frame[key].as_f64().unwrap_or_else(|| panic!("no {key}: {frame}"));
    assert_eq!(frame["frames"], 30, "one a 1/30 s: {frame}");
    assert!(
        0.0 < ms("median_ms") && ms("median_ms") <= ms("p99_ms") && ms("p99_ms") <= ms("slowest_ms"),
        "{frame}"
    );
    let predicted = summary["predicted_frame"]["mean_ms"].as_f64().unwrap();
    assert!(ms("median_ms") > 1.25 * predicted, "{predicted} ms predicted: {frame}");
    let out = simlod(&["run", "--assets", assets, "--seconds", "1"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("frame as measured (the wall time of each of its 30 frames)"),
        "{stdout}"
    );
    let hint = stdout
        .lines()
        .find(|l| l.contains("times the cost model's prediction"))
        .unwrap_or_else(|| panic!("no word of the model: {stdout}"));
    assert!(hint.contains("--calibrate") && hint.contains("costs.ron"), "{hint}");
}

#[test]
fn run_with_calibrate_plays_by_a_model_measured_before_it_even_where_the_rules_have_none_yet() {
    // The rules' model file is gone: a run needs it, a run that measures its own does not.
    let assets = crate::support::copy_assets("run_calibrate");
    std::fs::remove_file(assets.join("costs.ron")).unwrap();
    let assets = assets.to_str().unwrap();
    let args = [
        "run",
        "--assets",
        assets,
        "--seconds",
        "1",
        "--policy",
        "budget",
        "--frame-budget",
        "1",
        "--json",
    ];
    refused(&args, "costs.ron");
    let out = simlod(
        &[
            &args[..],
            &[
                "--calibrate",
                "--adaptive",
                "30",
                "--adaptive-percentile",
                "99",
                "--adaptive-percentile-limit",
                "1.2",
            ],
        ]
        .concat(),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("the rigid level in play among this many rigid creatures"),
        "{stderr}"
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(
        summary["cost_model"],
        "measured on this machine before the run, not reproducible"
    );
    let budget = &summary["budget"];
    assert_eq!(budget["adaptive"], true, "{budget}");
    assert_eq!(budget["adaptive_percentile"], 99.0, "{budget}");
    // The limit as it was given, not as an f32 widened to 1.2000000476837158.
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains(r#""adaptive_percentile_limit":1.2,"#), "{stdout}");
    // A model of zeros would make every creature rigid: the measured one prices them, and a
    // millisecond holds a few at most.
    let rigid = summary["levels_mean"]["rigid"].as_f64().unwrap();
    assert!(rigid < 40.0, "{summary}");
}

#[test]
fn assets_moves_everything_the_default_scenario_included_and_scenarios_are_found_inside_it() {
    let assets = crate::support::copy_assets("assets_moves_everything");
    // The copy's default game has 7 hoppers: a run that read the repository's would have 40.
    let default = std::fs::read_to_string(assets.join("scenarios/default.ron")).unwrap();
    let seven = default
        .replace("(kind: \"hopper\", count: 30)", "(kind: \"hopper\", count: 7)")
        .replace("(kind: \"biped\", count: 10),", "");
    assert_ne!(seven, default, "the default scenario names its groups");
    std::fs::write(assets.join("scenarios/default.ron"), seven).unwrap();
    let elsewhere = std::env::temp_dir();
    let run = |args: &[&str]| {
        let out = Command::new(crate::support::simlod_bin())
            .args(args)
            .current_dir(&elsewhere)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let dir = assets.to_str().unwrap();
    let summary = run(&["run", "--assets", dir, "--seconds", "1", "--json"]);
    assert_eq!(
        summary["creatures"], 7,
        "run outside the repository, on the copy's default game"
    );
    let summary = run(&[
        "run",
        "--assets",
        dir,
        "--scenario",
        "scenarios/hoppers.ron",
        "--seconds",
        "1",
        "--json",
    ]);
    assert_eq!(summary["rules"], format!("{dir}/rules/levels.ron"));
    let hoppers: simlod::config::Scenario = simlod::config::load_file(&assets.join("scenarios/hoppers.ron")).unwrap();
    let count: u32 = hoppers.creatures.iter().map(|g| g.count).sum();
    assert_eq!(summary["creatures"], count, "--scenario is looked up in --assets");
}
