//! The paper's experiments write their data.

use crate::support::*;
use simlod_lab::experiments::step_response;

#[test]
fn step_response_writes_velocities_and_paths_that_follow_the_steps() {
    let out = scratch_dir("step_response");
    let file = assets_root().join("experiments/step_response.ron");
    let summary = step_response::run(&default_config(), &file, &out).unwrap();
    assert!(
        summary.contains("rigid: 240 samples") && summary.contains("hybrid: 240 samples"),
        "{summary}"
    );
    assert!(summary.contains("the models are"), "{summary}");
    every_file_it_says_it_wrote_exists(&summary, &out);
    let velocity = std::fs::read_to_string(out.join("velocity.csv")).unwrap();
    let path = std::fs::read_to_string(out.join("path.csv")).unwrap();
    assert_eq!(velocity.lines().count(), 1 + 2 * 240);
    assert_eq!(path.lines().count(), 1 + 2 * 240);
    let vx_at = |model: &str, t: f32| -> f32 {
        let row = velocity
            .lines()
            .skip(1)
            .filter(|l| l.starts_with(model))
            .find(|l| l.split(',').nth(1).unwrap().parse::<f32>().unwrap() >= t)
            .unwrap();
        row.split(',').nth(4).unwrap().parse().unwrap()
    };
    for model in ["rigid", "hybrid"] {
        // The 2 m/s step at 1 s: still at rest before it, past 1.5 m/s by 3.5 s.
        assert!(
            vx_at(model, 0.9).abs() < 0.05,
            "{model} still at rest before the first step"
        );
        assert!(
            vx_at(model, 3.45) > 1.5,
            "{model} sped up after the step: {}",
            vx_at(model, 3.45)
        );
    }
    // Figure 4: where the paths end, and how far apart: the last rows of path.csv.
    let end_of = |model: &str| -> (f32, f32) {
        let row = path.lines().rfind(|l| l.starts_with(model)).unwrap();
        let v: Vec<f32> = row.split(',').skip(2).map(|x| x.parse().unwrap()).collect();
        (v[0], v[1])
    };
    let last = std::fs::read_to_string(out.join("final.csv")).unwrap();
    let v: Vec<f32> = last
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    let ((rx, rz), (hx, hz)) = (end_of("rigid"), end_of("hybrid"));
    assert_eq!((v[0], v[1], v[2], v[3]), (rx, rz, hx, hz), "{last}");
    let apart = ((rx - hx).powi(2) + (rz - hz).powi(2)).sqrt();
    assert!((v[4] - apart).abs() < 1e-3 && apart > 0.0, "{last}");
    // Figure 3: the hybrid responds to the step with less delay.
    assert!(
        vx_at("hybrid", 1.5) > vx_at("rigid", 1.5),
        "{} vs {}",
        vx_at("hybrid", 1.5),
        vx_at("rigid", 1.5)
    );
}

#[test]
fn step_response_refuses_a_broken_experiment_file() {
    let dir = scratch_dir("step_response_bad");
    let file = dir.join("bad.ron");
    std::fs::write(
        &file,
        "(creature: \"hopper\", duration_s: -1.0, start_m: (0.0, 0.0), steps: [])",
    )
    .unwrap();
    let err = step_response::run(&default_config(), &file, &dir).unwrap_err();
    assert!(
        matches!(err, simlod_lab::LabError::Config(_)),
        "a bad file is a config error: {err:?}"
    );
    let err = err.to_string();
    assert!(err.contains("`duration_s`") && err.contains("`steps`"), "{err}");
}

use simlod::headless::HeadlessSim;
use simlod::lod::LevelPolicy;
use simlod_lab::experiments::{self, Options, Shard};
use std::path::{Path, PathBuf};

/// Each file an experiment's output says it wrote ("wrote a.csv, b.png and report.md in DIR",
/// or "wrote /path/file") is there.
fn every_file_it_says_it_wrote_exists(said: &str, out: &Path) {
    let mut named = 0;
    for line in said.lines().filter_map(|l| l.strip_prefix("wrote ")) {
        let (files, dir) = line.rsplit_once(" in ").map_or((line, None), |(f, d)| (f, Some(d)));
        for file in files.split(", ").flat_map(|f| f.split(" and ")) {
            let path = dir.map_or_else(|| Path::new(file).to_path_buf(), |d| Path::new(d).join(file));
            assert!(
                path.is_file(),
                "it says it wrote {}, which is not there: {said}",
                path.display()
            );
            assert!(path.starts_with(out), "{} is in the output folder", path.display());
            named += 1;
        }
    }
    assert!(named >= 3, "it names what it wrote: {said}");
}

fn quick(out: &Path) -> Options {
    Options {
        out: out.to_owned(),
        quick: true,
        trials: None,
        jobs: 2,
        shard: Shard::WHOLE,
        assets: assets_root(),
        scenario: assets_root().join("scenarios/default.ron"),
    }
}

fn run(name: &str, options: &Options) -> Result<String, simlod_lab::LabError> {
    experiments::run_named(
        name,
        &default_config(),
        &experiments::default_file(&assets_root(), name),
        options,
    )
}

/// Share of pixels that are not the background, and how many colours there are.
fn ink(png: &Path) -> (f64, usize) {
    let img = image::open(png)
        .unwrap_or_else(|e| panic!("{}: {e}", png.display()))
        .to_rgb8();
    let white = image::Rgb([255u8, 255, 255]);
    let inked = img.pixels().filter(|p| **p != white).count();
    let colours: std::collections::BTreeSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    (inked as f64 / img.pixels().len() as f64, colours.len())
}

#[test]
fn every_experiment_quick_writes_its_files_and_a_plot_that_is_not_blank() {
    let out = scratch_dir("experiments_quick");
    for name in ["table1", "fig7", "fig8", "fig9", "fig10"] {
        let said = run(name, &quick(&out)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(said.contains(&format!("wrote {name}.csv")), "{said}");
        every_file_it_says_it_wrote_exists(&said, &out);
        for ext in ["csv", "png", "json"] {
            assert!(out.join(format!("{name}.{ext}")).is_file(), "{name}.{ext}");
        }
        let csv = std::fs::read_to_string(out.join(format!("{name}.csv"))).unwrap();
        assert!(csv.lines().count() >= 2, "{name}.csv has rows: {csv}");
        let (share, colours) = ink(&out.join(format!("{name}.png")));
        assert!(
            share > 0.01 && colours > 8,
            "{name}.png is blank: {share} inked, {colours} colours"
        );
        let record: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join(format!("{name}.json"))).unwrap()).unwrap();
        assert_eq!(record["experiment"], name);
        assert_eq!(record["smoke_test"], true, "a quick {name} says it is a smoke test");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for name in ["table1", "fig7", "fig8", "fig9", "fig10"] {
        assert!(
            report.contains(&format!("![{name}]({name}.png)")),
            "report.md shows {name}"
        );
        assert!(
            report.contains(&format!("## {name} (smoke test)")),
            "report.md marks the quick {name} as a smoke test"
        );
    }
    assert!(!report.contains("at no radius"), "a smoke test draws no conclusion");
    assert!(
        report.contains("2.4") && report.contains("112"),
        "the paper's numbers: {report}"
    );
}

#[test]
fn table1_measures_every_kind_it_names_at_every_level() {
    let out = scratch_dir("table1_kinds");
    run("table1", &quick(&out)).unwrap();
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("table1.json")).unwrap()).unwrap();
    for kind in ["hopper", "biped"] {
        let model = &record["summary"]["kinds"][kind]["ms_per_creature_per_frame"]["model"];
        let ms = |level: &str| {
            model[level]
                .as_f64()
                .unwrap_or_else(|| panic!("{kind} {level}: {model}"))
        };
        for level in ["point_mass", "hybrid", "rigid"] {
            assert!(ms(level) > 0.0 && ms(level).is_finite(), "{kind} {level}: {model}");
        }
    }
    let csv = std::fs::read_to_string(out.join("table1.csv")).unwrap();
    assert_eq!(csv.lines().filter(|l| l.starts_with("biped,")).count(), 6, "{csv}");
}

/// The paper's fig10 set-up at a puck radius that covers the whole court: every creature is
/// rigid from the start, so the game is the all-rigid one, bit for bit.
#[test]
fn a_puck_area_covering_the_court_is_the_all_rigid_game_from_the_first_tick() {
    let mut config = default_config();
    config.rules.influence.puck_radius_m = 1000.0;
    config.scenario.level_policy = LevelPolicy::Influence;
    let mut rigid = config.clone();
    rigid.scenario.level_policy = LevelPolicy::AllRigid;
    let (mut a, mut b) = (HeadlessSim::new(config), HeadlessSim::new(rigid));
    for frame in 0..90 {
        assert_eq!(a.state_digest(), b.state_digest(), "frame {frame}");
        a.advance_frame();
        b.advance_frame();
    }
    let (sa, sb) = (a.summary(0.0), b.summary(0.0));
    assert_eq!(sa.levels, sb.levels);
    assert_eq!(sa.switches.total(), 0, "nobody waited for a flight window");
}

#[test]
fn a_creature_starts_at_the_level_the_rules_give_it_where_it_stands() {
    let mut config = default_config();
    config.scenario.level_policy = LevelPolicy::Influence;
    config.rules.influence.puck_radius_m = 6.0;
    let mut sim = HeadlessSim::new(config);
    let world = sim.app.world_mut();
    let levels: Vec<simlod::lod::Lod> = world.query::<&simlod::lod::Lod>().iter(world).copied().collect();
    // Before any tick: hoppers near the puck, a wall or another creature rigid, the rest hybrid.
    let rigid = levels.iter().filter(|l| **l == simlod::lod::Lod::Rigid).count();
    let hybrid = levels.iter().filter(|l| **l == simlod::lod::Lod::Hybrid).count();
    assert!(rigid > 0 && hybrid > 0, "{rigid} rigid, {hybrid} hybrid at the start");
}

fn fig10_file(dir: &Path, radii: &str, seconds: f32, trials: u32) -> PathBuf {
    let file = dir.join("fig10.ron");
    let s = format!(
        "(radii_m: [{radii}], rules: \"rules/puck-only.ron\", seconds: {seconds}, trials: {trials}, first_seed: 40)"
    );
    std::fs::write(&file, format!("(full: {s}, quick: {s})")).unwrap();
    file
}

fn fig10(file: &Path, options: &Options) -> Vec<Vec<String>> {
    experiments::fig10::run(&default_config(), file, options).unwrap();
    table(&options.out.join("fig10.csv"))
}

fn table(csv: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(csv)
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect()
}

/// Everything but the wall times (the last two columns), which are measurements.
fn outcomes(rows: &[Vec<String>]) -> Vec<Vec<String>> {
    rows.iter().map(|r| r[..r.len() - 2].to_vec()).collect()
}

#[test]
fn fig10_at_a_radius_covering_the_court_differs_from_all_rigid_by_zero_in_every_trial() {
    let dir = scratch_dir("fig10_court");
    let file = fig10_file(&dir, "1000.0", 6.0, 3);
    let rows = fig10(&file, &quick(&dir.join("out")));
    let header = &rows[0];
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(rows.len(), 4);
    let mut collided = 0;
    for r in &rows[1..] {
        assert_eq!(r[col("difference")], "0", "{r:?}");
        assert_eq!(r[col("falls")], r[col("falls_all_rigid")], "{r:?}");
        collided += r[col("collided_all_rigid")].parse::<u64>().unwrap();
    }
    assert!(collided > 0, "the trials saw collisions, so 0 is not for want of any");
}

#[test]
fn fig10_does_not_depend_on_jobs_and_shards_merged_equal_one_run() {
    let dir = scratch_dir("fig10_shards");
    let file = fig10_file(&dir, "0.0, 6.0", 1.0, 5);
    let mut options = quick(&dir.join("one_job"));
    options.jobs = 1;
    let one = fig10(&file, &options);
    options.out = dir.join("two_jobs");
    options.jobs = 2;
    let two = fig10(&file, &options);
    assert_eq!(outcomes(&one), outcomes(&two));
    let mut parts = Vec::new();
    for k in 1..=3 {
        options.out = dir.join(format!("shard{k}"));
        options.shard = Shard { k, n: 3 };
        fig10(&file, &options);
        parts.push(options.out.clone());
    }
    experiments::fig10::merge(&parts, &dir.join("merged")).unwrap();
    let merged = table(&dir.join("merged/fig10.csv"));
    assert_eq!(outcomes(&merged), outcomes(&one));
    // The merged rows are the shards' rows, byte for byte (wall times included).
    let mut from_parts: Vec<Vec<String>> = parts
        .iter()
        .flat_map(|p| table(&p.join("fig10.csv")).split_off(1))
        .collect();
    from_parts.sort_by(|a, b| {
        (a[0].parse::<f32>().unwrap(), a[1].parse::<u32>().unwrap())
            .partial_cmp(&(b[0].parse::<f32>().unwrap(), b[1].parse::<u32>().unwrap()))
            .unwrap()
    });
    assert_eq!(merged[1..], from_parts[..]);
    // Overlapping parts are refused.
    let err = experiments::fig10::merge(&[parts[0].clone(), parts[0].clone()], &dir.join("bad"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("overlap"), "{err}");
}

#[test]
fn an_interrupted_fig10_resumes_without_redoing_finished_trials() {
    let dir = scratch_dir("fig10_resume");
    let file = fig10_file(&dir, "0.0, 6.0", 1.0, 4);
    let options = quick(&dir.join("out"));
    let whole = fig10(&file, &options);
    // As if stopped after trials 0 and 2: their rows in the journal, nothing else.
    let keep: Vec<String> = std::fs::read_to_string(options.out.join("fig10.csv"))
        .unwrap()
        .lines()
        .enumerate()
        .filter(|(i, l)| *i == 0 || [",0,", ",2,"].iter().any(|t| l.contains(t)))
        .map(|(_, l)| l.to_owned())
        .collect();
    // An interrupted run leaves its journal, the plan it was made by, and perhaps a line cut
    // short by the interruption (trial 1's, here: it runs again).
    let part: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(options.out.join("fig10.part.json")).unwrap()).unwrap();
    let cut = whole.iter().find(|r| r[1] == "1").unwrap().join(",");
    std::fs::remove_file(options.out.join("fig10.csv")).unwrap();
    std::fs::write(
        options.out.join("fig10.partial.csv"),
        keep.join("\n") + "\n" + &cut[..cut.len() / 2],
    )
    .unwrap();
    std::fs::write(
        options.out.join("fig10.partial.plan"),
        format!(
            "{} {}\n",
            part["version"].as_str().unwrap(),
            part["plan"].as_str().unwrap()
        ),
    )
    .unwrap();
    let resumed = fig10(&file, &options);
    assert_eq!(outcomes(&resumed), outcomes(&whole));
    // The finished trials were not run again: their wall times are the first run's.
    for (a, b) in whole.iter().zip(&resumed) {
        if a[1] == "0" || a[1] == "2" {
            assert_eq!(a, b);
        }
    }
    assert!(!options.out.join("fig10.partial.csv").exists());
    assert!(!options.out.join("fig10.partial.plan").exists());
}

#[test]
fn a_resume_refuses_rows_made_with_other_settings() {
    let dir = scratch_dir("fig10_resume_other");
    let options = quick(&dir.join("out"));
    fig10(&fig10_file(&dir, "0.0", 1.0, 2), &options);
    // The same radii, trials and seeds, but trials of another length: none of its rows count.
    let longer = fig10_file(&dir, "0.0", 2.0, 2);
    let err = experiments::fig10::run(&default_config(), &longer, &options)
        .unwrap_err()
        .to_string();
    assert!(err.contains("fig10.csv") && err.contains("other settings"), "{err}");
    // Another scenario is another plan too.
    let mut fewer = default_config();
    fewer.scenario.creatures[0].count -= 1;
    let same = dir.join("fig10.ron");
    fig10_file(&dir, "0.0", 1.0, 2);
    let err = experiments::fig10::run(&fewer, &same, &options)
        .unwrap_err()
        .to_string();
    assert!(err.contains("other settings"), "{err}");
    // A run of the same plan with more trials takes up the finished ones.
    fig10(&fig10_file(&dir, "0.0", 1.0, 3), &options);
}

#[test]
fn a_merge_takes_only_whole_parts_of_one_run() {
    let dir = scratch_dir("fig10_merge_checked");
    let file = fig10_file(&dir, "0.0", 1.0, 4);
    let mut options = quick(&dir.join("x"));
    let mut parts = Vec::new();
    for k in 1..=2 {
        options.out = dir.join(format!("shard{k}"));
        options.shard = Shard { k, n: 2 };
        fig10(&file, &options);
        parts.push(options.out.clone());
    }
    let merge = |parts: &[PathBuf]| experiments::fig10::merge(parts, &dir.join("merged"));
    merge(&parts).expect("two whole parts of one run merge");

    let err = merge(&parts[..1]).unwrap_err().to_string();
    assert!(err.contains("shard 2/2 is missing"), "{err}");

    // A part made by another plan (trials of another length).
    let other = fig10_file(&dir, "0.0", 2.0, 4);
    options.out = dir.join("other2");
    fig10(&other, &options);
    let err = merge(&[parts[0].clone(), options.out.clone()]).unwrap_err().to_string();
    assert!(
        err.contains("other2") && err.contains("plan") && err.contains("not parts of one run"),
        "{err}"
    );

    // A part cut short, or edited, since it was written.
    let csv = parts[1].join("fig10.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    std::fs::write(&csv, &text[..text.len() - 10]).unwrap();
    let err = merge(&parts).unwrap_err().to_string();
    assert!(
        err.contains("shard2/fig10.csv") && err.contains("changed since it was written"),
        "{err}"
    );
    let edited = text.replacen(",41,", ",42,", 1);
    assert_ne!(edited, text, "shard 2 holds trial 1, seed 41");
    std::fs::write(&csv, edited).unwrap();
    let err = merge(&parts).unwrap_err().to_string();
    assert!(err.contains("changed since it was written"), "{err}");

    // A folder without its part record says what is missing.
    std::fs::write(&csv, &text).unwrap();
    std::fs::remove_file(parts[1].join("fig10.part.json")).unwrap();
    let err = merge(&parts).unwrap_err().to_string();
    assert!(err.contains("fig10.part.json"), "{err}");
}

#[test]
fn a_broken_experiment_file_is_refused_with_the_file_and_the_field() {
    let dir = scratch_dir("experiment_bad");
    let file = dir.join("fig10.ron");
    let good = "(radii_m: [1.0], rules: \"rules/puck-only.ron\", seconds: 1.0, trials: 1, first_seed: 1)";
    let bad = "(radii_m: [], rules: \"rules/puck-only.ron\", seconds: -1.0, trials: 0, first_seed: 1)";
    std::fs::write(&file, format!("(full: {good}, quick: {bad})")).unwrap();
    let err = experiments::run_named("fig10", &default_config(), &file, &quick(&dir))
        .unwrap_err()
        .to_string();
    for field in ["`quick.radii_m`", "`quick.seconds`", "`quick.trials`"] {
        assert!(err.contains(field) && err.contains("fig10.ron"), "{field}: {err}");
    }
    std::fs::write(&file, format!("(full: {good}, quick: (radii_m: [1.0]))")).unwrap();
    let err = experiments::run_named("fig10", &default_config(), &file, &quick(&dir))
        .unwrap_err()
        .to_string();
    assert!(err.contains("fig10.ron") && err.contains("quick"), "{err}");
}

#[test]
fn an_experiment_refuses_a_kind_without_the_levels_it_compares_rather_than_mislabel_them() {
    let dir = scratch_dir("experiment_missing_level");
    let mut no_table = default_config();
    let biped = no_table.kind_index("biped").unwrap();
    no_table.gaits[biped] = None;
    let mut no_rigid = default_config();
    no_rigid.kinds[biped].rigid = None;

    let file = assets_root().join("experiments/step_response.ron");
    let steps = std::fs::read_to_string(&file).unwrap();
    let biped_steps = dir.join("step_response.ron");
    std::fs::write(
        &biped_steps,
        steps.replacen("creature: \"hopper\"", "creature: \"biped\"", 1),
    )
    .unwrap();
    let err = step_response::run(&no_table, &biped_steps, &dir)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("`creature`") && err.contains("\"biped\" has no hybrid level") && err.contains("gait_table"),
        "{err}"
    );
    let err = step_response::run(&no_rigid, &biped_steps, &dir)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("no rigid level") && err.contains("`rigid` section"),
        "{err}"
    );
    step_response::run(&no_table, &file, &dir).expect("the hopper has both levels");

    for (name, config, missing) in [
        ("fig10", &no_table, "no hybrid level"),
        ("fig8", &no_rigid, "no rigid level"),
        ("fig9", &no_table, "no hybrid level"),
        ("budget", &no_rigid, "no rigid level"),
    ] {
        let err = experiments::run_named(
            name,
            config,
            &experiments::default_file(&assets_root(), name),
            &quick(&dir),
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains(name) && err.contains("\"biped\"") && err.contains(missing),
            "{err}"
        );
    }
    assert!(!dir.join("fig10.csv").exists(), "nothing is written");
}

#[test]
fn a_step_response_longer_than_the_models_keep_time_is_refused_not_shortened() {
    let dir = scratch_dir("step_response_long");
    let file = dir.join("long.ron");
    let steps = std::fs::read_to_string(assets_root().join("experiments/step_response.ron")).unwrap();
    let at = steps.find("duration_s:").unwrap();
    let end = at + steps[at..].find(',').unwrap();
    std::fs::write(&file, format!("{}duration_s: 1e9{}", &steps[..at], &steps[end..])).unwrap();
    let err = step_response::run(&default_config(), &file, &dir)
        .unwrap_err()
        .to_string();
    assert!(err.contains("`duration_s`") && err.contains("10000"), "{err}");
}

#[test]
fn every_figure_keeps_its_legend_and_labels_inside_and_off_the_data() {
    // What `plot::draw` finds in each figure it draws (a label or the legend outside the
    // figure, over another label or over a data marker) it says on standard error.
    let out = scratch_dir("experiments_layout");
    for name in experiments::report::ORDER {
        let run = std::process::Command::new(crate::support::simlod_bin())
            .args(["experiment", name, "--quick", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{name}: {stderr}");
        assert!(!stderr.contains("warning: the layout"), "{name}: {stderr}");
    }
}

#[test]
fn the_crowd_stops_a_policy_at_the_first_size_whose_frame_passes_the_limit() {
    let dir = scratch_dir("crowd_stops");
    let file = dir.join("crowd.ron");
    // No frame of 3000 rigid creatures takes under a millisecond.
    let settings =
        "(policies: [AllRigid, AllPointMass], creatures: [3000, 6000], seconds: 0.2, stop_frame_ms: 1.0, seed: 1)";
    std::fs::write(&file, format!("(full: {settings}, quick: {settings})")).unwrap();
    let said = experiments::run_named("crowd", &default_config(), &file, &quick(&dir)).unwrap();
    every_file_it_says_it_wrote_exists(&said, &dir);
    let rows = table(&dir.join("crowd.csv"));
    let rigid: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == "all-rigid").collect();
    assert_eq!(rigid.len(), 1, "all rigid stops at its first size: {rows:?}");
    assert_eq!((rigid[0][1].as_str(), rigid[0][5].as_str()), ("3000", "true"));
    assert_eq!(rigid[0][2], "1", "the game ends at the frame over the limit");
    // Every creature is where its policy puts it.
    let point_masses: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == "all-point-mass").collect();
    assert!(!point_masses.is_empty());
    for r in point_masses {
        let number = |i: usize| r[i].parse::<f64>().unwrap();
        assert_eq!(number(6), number(1), "all {} at the point-mass level", r[1]);
    }
}

#[test]
fn the_budget_at_every_crowd_size_can_price_each_sizes_games_by_a_model_measured_just_before_them() {
    let dir = scratch_dir("budget_scale_calibrated");
    let file = dir.join("budget_scale.ron");
    let predicted = |calibrate: bool| {
        let settings = format!(
            "(creatures: [12, 30], budgets_ms: [3.0], adaptive_frames: [0.0], seconds: 0.3, warm_up_s: 0.1, seed: 3, calibrate_at_start: {calibrate})"
        );
        std::fs::write(&file, format!("(full: {settings}, quick: {settings})")).unwrap();
        let said = experiments::run_named("budget-scale", &default_config(), &file, &quick(&dir)).unwrap();
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("budget-scale.json")).unwrap()).unwrap();
        let summary = &json["summary"];
        let game = &summary["games"][1];
        (
            said,
            summary["calibrated_at_start"].clone(),
            game["predicted_mean_ms"].as_f64().unwrap(),
        )
    };
    let (said, models, measured) = predicted(true);
    assert!(
        said.contains("a cost model measured on this machine just before each crowd size's games"),
        "{said}"
    );
    // A model for each crowd size is in the record, a line for each kind and one for the
    // frame, and the report lists it.
    let models = models.as_array().unwrap_or_else(|| panic!("{models}"));
    let sizes: Vec<u64> = models.iter().map(|m| m["creatures"].as_u64().unwrap()).collect();
    assert_eq!(sizes, [12, 30]);
    for model in models {
        let lines = model["lines"].as_array().unwrap_or_else(|| panic!("{model}"));
        assert!(
            lines.iter().any(|l| l.as_str().unwrap().starts_with("hopper")),
            "{model}"
        );
        let first = format!("\n- {}\n", lines[0].as_str().unwrap());
        assert!(said.contains(&first), "the report lists it: {said}");
        // With how long the game would wait for it at start-up.
        let seconds = model["seconds"].as_f64().unwrap_or_else(|| panic!("{model}"));
        let heading = format!("games of {} creatures, in {seconds:.1} s (", model["creatures"]);
        assert!(seconds > 0.0 && said.contains(&heading), "{heading}: {said}");
        // Its rigid level measured among that crowd's own creatures: never more rigid ones
        // than it has.
        let rigid = lines.last().unwrap().as_str().unwrap();
        let most: u64 = (rigid.split(": ").nth(1).unwrap().split(", "))
            .map(|r| r.split(" x ").next().unwrap().parse::<u64>().unwrap())
            .max()
            .unwrap();
        assert!(most <= model["creatures"].as_u64().unwrap(), "{rigid}");
    }
    let (said, models, shipped) = predicted(false);
    assert!(said.contains("rules and cost model (the game's)"), "{said}");
    assert!(models.is_null(), "{models}");
    // The same game priced by the two models: its prediction is the measured model's.
    assert_ne!(measured, shipped);
}

#[test]
fn the_budget_at_every_crowd_size_plays_each_size_budget_and_correction_and_buys_more_with_more() {
    let dir = scratch_dir("budget_scale");
    let file = dir.join("budget_scale.ron");
    let settings = "(creatures: [30, 90], budgets_ms: [0.4, 3.0], adaptive_frames: [0.0, 20.0], adaptive_percentiles: [0.0, 99.0], adaptive_percentile_limits: [1.0, 1.5], seconds: 0.4, warm_up_s: 0.1, seed: 3)";
    std::fs::write(&file, format!("(full: {settings}, quick: {settings})")).unwrap();
    let said = experiments::run_named("budget-scale", &default_config(), &file, &quick(&dir)).unwrap();
    every_file_it_says_it_wrote_exists(&said, &dir);
    let rows = table(&dir.join("budget-scale.csv"));
    let games: Vec<[&str; 5]> = (rows[1..].iter())
        .map(|r| [0, 1, 2, 3, 15].map(|i| r[i].as_str()))
        .collect();
    let mut want = Vec::new();
    for n in ["30", "90"] {
        for b in ["0.4", "3"] {
            // The cost model alone once; the adaptive mode keeping the mean, then the 99th
            // percentile within the budget and within 1.5 times it.
            for (a, p, limit) in [
                ("0", "0", "1"),
                ("20", "0", "1"),
                ("20", "99", "1"),
                ("20", "99", "1.5"),
            ] {
                want.push([n, b, a, p, limit]);
            }
        }
    }
    assert_eq!(games, want);
    // Each game's figures are of its frames after the warm-up; the warm-up's slowest is apart.
    // The frame predicted is the mean, or where a percentile is kept, that percentile (of 9
    // frames, the 99th is the slowest).
    let number = |r: &Vec<String>, i: usize| r[i].parse::<f64>().unwrap();
    for r in &rows[1..] {
        assert_eq!(r[4], "9", "{r:?}");
        assert!(number(r, 13) > 0.0, "{r:?}");
        let held = if r[3] == "99" { 6 } else { 5 };
        assert_eq!(r[7], r[held], "{r:?}");
    }
    assert!(said.contains("The first 0.1 s of each game"), "{said}");
    // The cost model alone is reproducible: a larger budget buys more rigid creatures.
    let rigid = |n: &str, b: &str| {
        let r = rows.iter().find(|r| r[0] == n && r[1] == b && r[2] == "0").unwrap();
        number(r, 12)
    };
    assert!(rigid("90", "3") > rigid("90", "0.4"), "{rows:?}");
    assert_eq!(
        said.matches("\n| 30 |").count() + said.matches("\n| 90 |").count(),
        16,
        "{said}"
    );
    assert!(said.contains("of 16 games"), "{said}");
    // Kept: the mean no more than 10 % over the budget, the 99th percentile no more than 25 %;
    // spent too: the mean no more than 10 % under it either.
    let (mut kept, mut spent) = (0, 0);
    for r in &rows[1..] {
        let (budget, mean, p99) = (number(r, 1), number(r, 5), number(r, 6));
        let within = mean <= 1.1 * budget && p99 <= 1.25 * budget;
        kept += usize::from(within);
        spent += usize::from(within && mean >= 0.9 * budget);
    }
    let counts = format!(
        "Kept in {kept} of 16 games, and spent too (the mean frame also no more than 10 % under the budget) in {spent};"
    );
    assert!(said.contains(&counts), "{counts} in {said}");
    // As much as the crowd could use: where the size's game on the cost model alone at the
    // largest budget (3 ms) left more than a tenth of it, no more than 10 % under what it spent.
    let usable: Vec<(&str, f64)> = (rows[1..].iter())
        .filter(|r| r[2] == "0" && r[1] == "3" && number(r, 5) < 0.9 * 3.0)
        .map(|r| (r[0].as_str(), number(r, 5)))
        .collect();
    let could = (rows[1..].iter())
        .filter(|r| {
            let (budget, mean, p99) = (number(r, 1), number(r, 5), number(r, 6));
            let used = usable
                .iter()
                .find(|(n, _)| *n == r[0])
                .map_or(budget, |u| u.1.min(budget));
            mean <= 1.1 * budget && p99 <= 1.25 * budget && mean >= 0.9 * used
        })
        .count();
    if usable.is_empty() {
        assert!(!said.contains("as much as the crowd could use"), "{said}");
    } else {
        let sizes: Vec<String> = (usable.iter())
            .map(|(n, ms)| format!("{n} creatures {ms:.2} ms"))
            .collect();
        let words = format!("spent: {}) in {could}.", sizes.join(", "));
        assert!(said.contains(&words), "{words} in {said}");
    }
    // The 99th percentile among the last 300 frames, where three lie beyond it.
    assert!(said.contains("| 20 frames, 99th percentile of 300 |"), "{said}");
    assert!(
        said.contains("| 20 frames, 99th percentile of 300 within 1.5 times the budget |"),
        "{said}"
    );
    // Each game's frame predicted over its prediction, in its row in the games' order, and how
    // many were within 10 % of it either way.
    let reported: Vec<f64> = (said.lines())
        .filter(|l| l.starts_with("| 30 |") || l.starts_with("| 90 |"))
        .map(|l| l.split('|').nth(7).unwrap().trim().parse().unwrap())
        .collect();
    let mut honest = 0;
    for (r, reported) in rows[1..].iter().zip(&reported) {
        let ratio = number(r, 7) / number(r, 8);
        assert!((reported - ratio).abs() < 0.006, "{reported} for {r:?}");
        honest += usize::from((ratio - 1.0).abs() <= 0.1);
    }
    assert_eq!(reported.len(), 16, "{said}");
    assert!(
        said.contains(&format!("within 10 % of its prediction in {honest}.")),
        "{said}"
    );
    // Beside it, where the prediction is of the mean, the median frame over it (the model's
    // figures are medians): no slower than the slowest frame, none where a percentile is kept.
    let medians: Vec<&str> = (said.lines())
        .filter(|l| l.starts_with("| 30 |") || l.starts_with("| 90 |"))
        .map(|l| l.split('|').nth(8).unwrap().trim())
        .collect();
    let mut median_honest = 0;
    for (r, reported) in rows[1..].iter().zip(&medians) {
        let median = number(r, 14);
        assert!(median > 0.0 && median <= number(r, 6) + 1e-9, "{r:?}");
        if r[3] == "99" {
            assert_eq!(*reported, "-", "{r:?}");
        } else {
            let ratio = median / number(r, 8);
            assert!(
                (reported.parse::<f64>().unwrap() - ratio).abs() < 0.006,
                "{reported} for {r:?}"
            );
            median_honest += usize::from((ratio - 1.0).abs() <= 0.1);
        }
    }
    assert!(
        said.contains(&format!(
            "Of the 8 games whose prediction is of the mean, the median frame within 10 % of it in {median_honest}."
        )),
        "{said}"
    );
    // The machine's own spread at each budget, as many times as a game has frames: a fixed job
    // of about the budget (its median within a factor of three of it, whatever the machine's
    // spells), its 99th percentile over its median in the report; on one core, as games short
    // of a crowd run.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("budget-scale.json")).unwrap()).unwrap();
    let machine = json["summary"]["machine"].as_array().unwrap();
    assert_eq!(machine.len(), 2, "{json}");
    assert!(said.contains("timed 9 times"), "{said}");
    for (m, budget) in machine.iter().zip([0.4, 3.0]) {
        let figure = |name: &str| m[name].as_f64().unwrap();
        assert!((figure("budget_ms") - budget).abs() < 1e-6, "{m}");
        assert!((budget / 3.0..budget * 3.0).contains(&figure("median_ms")), "{m}");
        assert!(figure("p99_ms") >= figure("median_ms"), "{m}");
        assert_eq!(m["threads"], 1, "{m}");
        let row = format!("\n| {budget} | 1 | {:.2} |", figure("median_ms"));
        assert!(said.contains(&row), "{row} in {said}");
    }
    // Settings out of range are refused with the field named: sizes out of order, a warm-up as
    // long as the game, a percentile under 50, a limit under the budget.
    for (from, to, named) in [
        ("[30, 90]", "[90, 30]", "creatures"),
        ("warm_up_s: 0.1", "warm_up_s: 0.4", "warm_up_s"),
        ("99.0]", "30.0]", "adaptive_percentiles[1]`: must be 0"),
        ("1.5]", "0.5]", "adaptive_percentile_limits[1]`: must be"),
    ] {
        std::fs::write(&file, format!("(full: {0}, quick: {0})", settings.replace(from, to))).unwrap();
        let err = experiments::run_named("budget-scale", &default_config(), &file, &quick(&dir)).unwrap_err();
        assert!(err.to_string().contains(named), "{err}");
    }
}
