//! The `simlod` command line: the game (the default), the headless simulation and its
//! measurements.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use simlod::config::{
    CreatureDef, CreatureGroup, MAX_DURATION_S, MeasuredAnew, SimConfig, Validate, Validator, load_costs, load_file,
};
use simlod::gait::GaitTable;
use simlod::headless;
use simlod::lod::{LevelPolicy, Lod};
use simlod::outcome::{Counts, Key, Summary};
use simlod_lab::record::{RecordSettings, record, to_file_text};
use simlod_lab::{bench, experiments};

#[derive(Parser)]
#[command(
    name = "simlod",
    version,
    about = "Simulation levels of detail for real-time animation (Carlson & Hodgins, GI '97)"
)]
struct Cli {
    /// Without a command: `play` (in a build with the `game` feature).
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Play the game in a window (the default).
    #[cfg(feature = "game")]
    Play(PlayArgs),
    /// Simulate a scenario without a window, as fast as the machine allows, and summarise it.
    Run(RunArgs),
    /// Measure the cost per creature per 1/30 s of motion and the most creatures at 30 fps.
    Bench(BenchArgs),
    /// Run one of the paper's experiments and write its data as CSV.
    Experiment(ExperimentArgs),
    /// Record a creature's gait table from its rigid model (paper 3.2).
    RecordGait(RecordGaitArgs),
}

#[derive(Args)]
struct RecordGaitArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The creature file; it must have a `rigid` section.
    #[arg(long)]
    creature: PathBuf,
    /// Steady forward speeds to record, increasing (default: each whole m/s below the kind's
    /// top speed, and the top speed).
    #[arg(long, value_delimiter = ',')]
    speeds: Option<Vec<f32>>,
    /// Where to write the table (default: the creature's `gait_table`, or gaits/<kind>.ron
    /// under the assets folder).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write the table even where a table of another kind is: that kind loses its table.
    #[arg(long)]
    replace_other_kind: bool,
}

impl RecordGaitArgs {
    fn run(&self) -> Result<(), String> {
        self.scenario
            .refuse_level_flags("record-gait", "it runs the kind's rigid model alone, at steady speeds")?;
        let def: CreatureDef = load_file(&self.creature).map_err(|e| e.to_string())?;
        let mut config = self.scenario.load_measuring(MeasuredAnew {
            gait_table_of: Some(&def.name),
            ..MeasuredAnew::default()
        })?;
        if def.rigid.is_none() {
            return Err(format!(
                "{}: the creature has no `rigid` section to record from",
                self.creature.display()
            ));
        }
        let defaults = RecordSettings::up_to(def.top_speed_m_per_s);
        let speeds = self.speeds.clone().unwrap_or_else(|| defaults.speeds_m_per_s.clone());
        if speeds.is_empty()
            || speeds.windows(2).any(|w| w[0] >= w[1])
            || speeds.iter().any(|v| !(0.0..=10.0).contains(v))
        {
            return Err(format!(
                "--speeds must be increasing speeds between 0 and 10 m/s, got {speeds:?}"
            ));
        }
        // The recording never depends on a table recorded before.
        let index = config.kind_index(&def.name).unwrap_or_else(|| {
            config.kinds.push(def.clone());
            config.gaits.push(None);
            config.kinds.len() - 1
        });
        config.kinds[index] = def.clone();
        config.gaits[index] = None;
        config.scenario.creatures = vec![CreatureGroup {
            kind: def.name.clone(),
            count: 1,
        }];
        let settings = RecordSettings {
            speeds_m_per_s: speeds.clone(),
            ..defaults
        };
        let out = self.out.clone().unwrap_or_else(|| {
            self.scenario.assets.join(
                def.gait_table
                    .clone()
                    .unwrap_or_else(|| format!("gaits/{}.ron", def.name)),
            )
        });
        // Another kind's table is never overwritten by accident (a copied creature file
        // that kept its original's `gait_table` line names the original's table).
        if !self.replace_other_kind
            && let Ok(old) = load_file::<GaitTable>(&out)
            && old.creature != def.name
        {
            return Err(format!(
                "{path} holds the gait table of `{other}`, not of `{kind}`: recording `{kind}` there would \
                 take `{other}`'s table away. Give `{kind}` its own `gait_table` (or --out FILE), or pass \
                 --replace-other-kind",
                path = out.display(),
                other = old.creature,
                kind = def.name,
            ));
        }
        let table = record(&config, &def.name, &settings)?;
        let speeds: Vec<String> = speeds.iter().map(f32::to_string).collect();
        // The files are found again from the command alone: the assets folder where it is not
        // the default, and the scenario where one was given.
        let mut command = format!(
            "simlod record-gait --creature {} --speeds {}",
            self.creature.display(),
            speeds.join(",")
        );
        if self.scenario.assets != Path::new("assets") || self.scenario.scenario.is_some() {
            command += &format!(" {}", self.scenario.file_flags());
        }
        // A table the loader would refuse is not written: the old one stays.
        let mut check = Validator::default();
        table.validate(&mut check);
        check
            .finish(&out)
            .map_err(|e| format!("the recording is not a usable gait table, so it was not written:\n{e}"))?;
        if let Some(dir) = out.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        }
        std::fs::write(&out, to_file_text(&table, &command))
            .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
        println!("recorded {} from its rigid model into {}", def.name, out.display());
        for row in &table.rows {
            println!(
                "  {:.3} m/s: hop {:.3} s, stance {:.0} %, {} samples",
                row.speed_m_per_s,
                row.hop_period_s,
                row.stance_fraction * 100.0,
                row.samples.len()
            );
        }
        println!(
            "  effective limits for the point mass: top speed {:.3} m/s, acceleration {:.3} m/s^2",
            table.top_speed_m_per_s, table.acceleration_limit_m_per_s2
        );
        Ok(())
    }
}

#[derive(Args)]
struct ExperimentArgs {
    #[command(subcommand)]
    which: ExperimentKind,
}

#[derive(Subcommand)]
enum ExperimentKind {
    /// Figures 3 and 4: velocity and ground path under step changes in desired velocity.
    StepResponse(ExperimentRun),
    /// Table 1: cost per creature per 1/30 s at each level (the model alone, and in a game).
    Table1(ExperimentRun),
    /// Figure 7: creatures at 30 fps against the percentage of rigid ones.
    Fig7(ExperimentRun),
    /// Figure 8: average and lowest frame rate against the puck's radius of influence.
    Fig8(ExperimentRun),
    /// Figure 9: average and lowest frame rate against the camera's radius of influence.
    Fig9(ExperimentRun),
    /// Figure 10: the change in creatures that hit the puck or a wall, against all rigid.
    Fig10(ExperimentRun),
    /// Beyond the paper: the budget policy against fixed radii on figure 10's axes, and the
    /// frame times of a crowded game.
    Budget(ExperimentRun),
    /// Beyond the paper: figure 7 taken to crowds, every policy's frame time from a hundred
    /// creatures to a million.
    Crowd(ExperimentRun),
    /// Every experiment, into one folder.
    All(ExperimentRun),
    /// Combine fig10 shards (`--shard K/N` runs) into the files of one unsharded run.
    Merge {
        /// The shards' output folders.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Folder the merged files are written to.
        #[arg(long)]
        out: PathBuf,
    },
}

#[derive(Args)]
struct ExperimentRun {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The experiment's file (default: experiments/<name>.ron under the assets folder).
    #[arg(long)]
    experiment: Option<PathBuf>,
    /// Folder the CSV, PNG, JSON and report.md files are written to.
    #[arg(long)]
    out: PathBuf,
    /// The experiment file's `quick` settings: small counts, seconds of work.
    #[arg(long)]
    quick: bool,
    /// Overrides the experiment file's trial count.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    trials: Option<u32>,
    /// Threads for independent trials (default: every core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    jobs: Option<u32>,
    /// Run only the K-th of N disjoint parts of the trials (fig10), e.g. 2/4.
    #[arg(long)]
    shard: Option<experiments::Shard>,
}

impl ExperimentRun {
    fn run(&self, name: &str) -> Result<(), String> {
        self.scenario.refuse_level_flags(
            "experiment",
            "each experiment sets its own level policy, rules and radii from its file (assets/experiments/<name>.ron; --experiment FILE reads another)",
        )?;
        let config = self.scenario.load()?;
        let options = experiments::Options {
            out: self.out.clone(),
            quick: self.quick,
            trials: self.trials,
            jobs: self.jobs.map_or_else(
                || std::thread::available_parallelism().map_or(1, |n| n.get()),
                |j| j as usize,
            ),
            shard: self.shard.unwrap_or(experiments::Shard::WHOLE),
            assets: self.scenario.assets.clone(),
            scenario: self.scenario.scenario_file(),
        };
        let names: Vec<&str> = if name == "all" {
            if self.experiment.is_some() {
                return Err("--experiment names one experiment's file; `all` reads each from the assets folder".into());
            }
            experiments::ALL.to_vec()
        } else {
            vec![name]
        };
        for name in names {
            let file = self
                .experiment
                .clone()
                .unwrap_or_else(|| experiments::default_file(&self.scenario.assets, name));
            print!("{}", experiments::run_named(name, &config, &file, &options)?);
        }
        Ok(())
    }
}

#[derive(Args)]
struct ScenarioArgs {
    /// The scenario file (default: scenarios/default.ron in the assets folder); a relative
    /// path not found as given is looked up in the assets folder.
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// The assets folder: the default scenario, and the files every scenario names (arena,
    /// rules, cost model, creature kinds, gait tables).
    #[arg(long, default_value = "assets")]
    assets: PathBuf,
    /// Overrides the scenario's seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Overrides the scenario's level policy.
    #[arg(long, value_parser = policy_parser())]
    policy: Option<LevelPolicy>,
    /// Overrides the radius of the puck's area of influence (metres).
    #[arg(long, allow_negative_numbers = true, value_parser = non_negative_metres)]
    puck_radius: Option<f32>,
    /// Overrides the camera's radius of influence (metres).
    #[arg(long, allow_negative_numbers = true, value_parser = non_negative_metres)]
    camera_radius: Option<f32>,
    /// Overrides the budget policy's frame budget (ms of simulation per 1/30 s, 0 to 10000).
    #[arg(long, allow_negative_numbers = true, value_parser = frame_budget_ms)]
    frame_budget: Option<f32>,
    /// Overrides the scenario's level rules file.
    #[arg(long)]
    rules: Option<PathBuf>,
    /// Overrides the scenario's rapier solver iterations per tick (1 to 16).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16))]
    solver_iterations: Option<u32>,
}

/// A number from 0 to 10000 `unit`.
fn up_to_ten_thousand(s: &str, unit: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("not a number: {s:?}"))?;
    if v.is_finite() && (0.0..=1e4).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be between 0 and 10000 {unit}, got {v}"))
    }
}

fn non_negative_metres(s: &str) -> Result<f32, String> {
    up_to_ten_thousand(s, "metres")
}

fn frame_budget_ms(s: &str) -> Result<f32, String> {
    up_to_ten_thousand(s, "ms")
}

/// The scenario file a command reads: `scenario` as given, or, if a relative path is not found
/// there, the same path in the assets folder; without one, the assets folder's default.
fn scenario_file(assets: &Path, scenario: Option<&Path>) -> PathBuf {
    match scenario {
        None => assets.join(DEFAULT_SCENARIO),
        Some(path) if path.is_relative() && !path.exists() && assets.join(path).exists() => assets.join(path),
        Some(path) => path.to_path_buf(),
    }
}

/// The scenario every command runs without `--scenario`, in the assets folder.
const DEFAULT_SCENARIO: &str = "scenarios/default.ron";

impl ScenarioArgs {
    /// Refuses the level flags (policy, rules, radii, budget) for a command that never reads
    /// them, saying `why`, rather than let them be ignored without a word.
    fn refuse_level_flags(&self, command: &str, why: &str) -> Result<(), String> {
        let given = [
            ("--policy", self.policy.is_some()),
            ("--puck-radius", self.puck_radius.is_some()),
            ("--camera-radius", self.camera_radius.is_some()),
            ("--frame-budget", self.frame_budget.is_some()),
            ("--rules", self.rules.is_some()),
        ];
        match given.iter().find(|(_, given)| *given) {
            Some((flag, _)) => Err(format!("{flag} does not apply to `simlod {command}`: {why}")),
            None => Ok(()),
        }
    }

    fn scenario_file(&self) -> PathBuf {
        scenario_file(&self.assets, self.scenario.as_deref())
    }

    /// The flags that find these files again from anywhere: `--assets`, and `--scenario`
    /// where it is not the default.
    fn file_flags(&self) -> String {
        let mut flags = format!("--assets {}", self.assets.display());
        if let Some(scenario) = &self.scenario {
            flags += &format!(" --scenario {}", scenario.display());
        }
        flags
    }

    fn what_ran(&self, config: &SimConfig) -> WhatRan {
        WhatRan {
            policy: config.scenario.level_policy.name().to_owned(),
            rules: self
                .rules
                .clone()
                .unwrap_or_else(|| self.assets.join(&config.scenario.level_rules)),
            cost_model: self.assets.join(&config.rules.budget.cost_model),
        }
    }

    fn load(&self) -> Result<SimConfig, String> {
        self.load_measuring(MeasuredAnew::default())
    }

    /// The scenario with its overrides, without what is about to be measured anew (see
    /// [`SimConfig::load_measuring`]).
    fn load_measuring(&self, anew: MeasuredAnew) -> Result<SimConfig, String> {
        let mut config =
            SimConfig::load_measuring(&self.scenario_file(), &self.assets, anew).map_err(|e| e.to_string())?;
        if let Some(rules) = &self.rules {
            config.rules = load_file(rules).map_err(|e| e.to_string())?;
            if !anew.cost_model {
                config.costs = load_costs(&self.assets, rules, &config.rules).map_err(|e| e.to_string())?;
            }
        }
        if let Some(seed) = self.seed {
            config.scenario.seed = seed;
        }
        if let Some(policy) = self.policy {
            config.scenario.level_policy = policy;
        }
        if let Some(r) = self.puck_radius {
            config.rules.influence.puck_radius_m = r;
        }
        if let Some(r) = self.camera_radius {
            config.rules.camera.radius_m = r;
        }
        if let Some(ms) = self.frame_budget {
            config.rules.budget.frame_budget_ms = ms;
        }
        if let Some(n) = self.solver_iterations {
            config.scenario.solver_iterations = n;
        }
        Ok(config)
    }
}

/// `Parser` too, so that `simlod` alone plays with the defaults.
#[cfg(feature = "game")]
#[derive(Parser)]
struct PlayArgs {
    /// The scenario file (default: scenarios/default.ron in the assets folder); it must be
    /// inside the assets folder, which the game watches. A relative path not found as given
    /// is looked up in the assets folder.
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// The assets folder: the scenario's arena and creature kinds, and `game.ron`.
    #[arg(long, default_value = "assets")]
    assets: PathBuf,
    /// Overrides the scenario's level policy (L switches it while playing).
    #[arg(long, value_parser = policy_parser())]
    policy: Option<LevelPolicy>,
    /// Overrides the budget policy's frame budget (ms of simulation per 1/30 s, 0 to 10000; 9
    /// and 0 change it while playing).
    #[arg(long, allow_negative_numbers = true, value_parser = frame_budget_ms)]
    frame_budget: Option<f32>,
    /// Render `--frames` frames, save the window to this PNG file and quit.
    #[arg(long, group = "capture", requires = "frames")]
    screenshot: Option<PathBuf>,
    /// Render `--frames` frames and save them to this file as an animated GIF (every
    /// `recording.every_nth_frame`-th of them, `recording.width_px` wide: `game.ron`), then quit.
    #[arg(long, group = "capture", requires = "frames")]
    record: Option<PathBuf>,
    /// Frames to render (each 1/30 s of the game) for `--screenshot` or `--record`.
    #[arg(long, requires = "capture", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: Option<u32>,
}

#[cfg(feature = "game")]
impl PlayArgs {
    fn play(self) -> Result<(), String> {
        let runtime_dir = private_runtime_dir();
        let played = simlod_game::play(simlod_game::PlayOptions {
            scenario: scenario_file(&self.assets, self.scenario.as_deref()),
            assets: self.assets,
            policy: self.policy,
            frame_budget_ms: self.frame_budget,
            capture: self.frames.and_then(|frames| {
                let (path, kind) = match (self.screenshot, self.record) {
                    (Some(path), _) => (path, simlod_game::Capture::Screenshot),
                    (None, Some(path)) => (path, simlod_game::Capture::Recording),
                    (None, None) => return None,
                };
                Some(simlod_game::CapturePlan { path, frames, kind })
            }),
        });
        if let Some(dir) = runtime_dir {
            let _ = std::fs::remove_dir_all(dir);
        }
        played
    }
}

/// Where `XDG_RUNTIME_DIR` is not set (a virtual X server, a bare session), the Vulkan driver's
/// probe for Wayland prints "error: XDG_RUNTIME_DIR is invalid" although nothing failed. The
/// game runs on X11: a private empty folder answers the probe quietly. Set here, before any
/// thread starts; removed when the game ends.
#[cfg(feature = "game")]
fn private_runtime_dir() -> Option<PathBuf> {
    use std::os::unix::fs::DirBuilderExt;
    if std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return None;
    }
    let dir = std::env::temp_dir().join(format!("simlod-runtime-{}", std::process::id()));
    std::fs::DirBuilder::new().mode(0o700).create(&dir).ok()?;
    // SAFETY: main's thread is the only one yet: nothing reads the environment concurrently.
    unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    Some(dir)
}

#[derive(Args)]
struct RunArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Simulated seconds (default: the scenario's duration).
    #[arg(long, allow_negative_numbers = true, value_parser = positive_seconds)]
    seconds: Option<f64>,
    /// Print the summary as one JSON object.
    #[arg(long)]
    json: bool,
}

impl RunArgs {
    /// Simulates the scenario and prints what happened. A flag the run's policy never reads is
    /// refused rather than ignored.
    fn run(&self) -> Result<(), String> {
        let config = self.scenario.load()?;
        let policy = config.scenario.level_policy;
        let unread = [
            (
                "--puck-radius",
                self.scenario.puck_radius.is_some() && !policy.uses_puck_radius(),
            ),
            (
                "--camera-radius",
                self.scenario.camera_radius.is_some() && !policy.uses_camera_radius(),
            ),
            (
                "--frame-budget",
                self.scenario.frame_budget.is_some() && !policy.uses_frame_budget(),
            ),
        ];
        if let Some((flag, _)) = unread.iter().find(|(_, unread)| *unread) {
            return Err(format!(
                "{flag} does not apply to the {} policy, which never reads it (choose a policy that does with --policy)",
                policy.name()
            ));
        }
        let seconds = self.seconds.unwrap_or(f64::from(config.scenario.duration_s));
        let summary = headless::run(config.clone(), seconds);
        let ran = self.scenario.what_ran(&config);
        if self.json {
            let mut json = serde_json::to_value(&summary).expect("a summary serialises");
            json["policy"] = ran.policy.into();
            json["rules"] = ran.rules.display().to_string().into();
            json["cost_model"] = ran.cost_model.display().to_string().into();
            println!("{json}");
        } else {
            print_summary(self, &summary, &config, &ran);
        }
        Ok(())
    }
}

/// What a run ran under: its level policy, as the command line names it, and the files of its
/// level rules and cost model.
struct WhatRan {
    policy: String,
    rules: PathBuf,
    cost_model: PathBuf,
}

/// `--policy`: a policy by its name, each listed with its line of help.
fn policy_parser() -> impl TypedValueParser<Value = LevelPolicy> {
    PossibleValuesParser::new(LevelPolicy::ALL.map(|p| PossibleValue::new(p.name()).help(p.describe()))).map(|name| {
        *LevelPolicy::ALL
            .iter()
            .find(|p| p.name() == name)
            .expect("a listed name")
    })
}

/// `--level`: a level by its name (`point-mass`), each listed with its line of help.
fn level_parser() -> impl TypedValueParser<Value = Lod> {
    let flag = |l: Lod| l.name().replace('_', "-");
    PossibleValuesParser::new(Lod::ALL.map(|l| PossibleValue::new(flag(l)).help(l.describe())))
        .map(move |name| *Lod::ALL.iter().find(|&&l| flag(l) == name).expect("a listed name"))
}

#[derive(Args)]
struct BenchArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Print one JSON object per level, one per line.
    #[arg(long)]
    json: bool,
    /// Fewer, shorter repetitions: a rough figure in seconds.
    #[arg(long)]
    quick: bool,
    /// Only this level (no cost ratios, no game).
    #[arg(long, value_parser = level_parser(), conflicts_with = "calibrate")]
    level: Option<Lod>,
    /// Only the scenario's creatures of this kind (for example `biped`): its cost at each level.
    #[arg(long, conflicts_with = "calibrate")]
    kind: Option<String>,
    /// Measure the budget policy's cost model (each kind's levels and its switch into rigid)
    /// and write it to the file the level rules name (`budget.cost_model`), or to `--out`.
    #[arg(long)]
    calibrate: bool,
    /// Where `--calibrate` writes the cost model.
    #[arg(long, requires = "calibrate")]
    out: Option<PathBuf>,
}

impl BenchArgs {
    fn run(&self) -> Result<(), String> {
        let mut config = self.scenario.load_measuring(MeasuredAnew {
            cost_model: self.calibrate,
            ..MeasuredAnew::default()
        })?;
        if let Some(kind) = &self.kind {
            let all: Vec<String> = config.scenario.creatures.iter().map(|g| g.kind.clone()).collect();
            config.scenario.creatures.retain(|g| &g.kind == kind);
            if config.scenario.creatures.is_empty() {
                return Err(format!(
                    "--kind {kind}: the scenario has no creatures of that kind (it has {})",
                    all.join(", ")
                ));
            }
        }
        if self.calibrate {
            return self.calibrate(&config);
        }
        bench::run(&config, self.quick, self.json, self.level);
        Ok(())
    }

    fn calibrate(&self, config: &SimConfig) -> Result<(), String> {
        let out = self
            .out
            .clone()
            .unwrap_or_else(|| self.scenario.assets.join(&config.rules.budget.cost_model));
        let model = bench::calibrate(config, self.quick);
        let rules = self
            .scenario
            .rules
            .as_ref()
            .map(|r| format!(" --rules {}", r.display()));
        let command = format!(
            "simlod bench --calibrate {}{}{}",
            self.scenario.file_flags(),
            rules.unwrap_or_default(),
            if self.quick { " --quick" } else { "" }
        );
        if let Some(dir) = out.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        }
        std::fs::write(&out, bench::costs_file_text(&model, &command))
            .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
        if self.json {
            println!("{}", serde_json::to_string(&model).expect("a cost model serialises"));
        } else {
            println!(
                "wrote the cost model to {} (us per creature per 1/30 s; us per switch into rigid):",
                out.display()
            );
            for k in &model.kinds {
                let c = &k.costs;
                println!(
                    "  {:<8} point mass {:.3}, hybrid {:.3}, rigid {:.1}; switch to rigid {:.1}",
                    k.kind,
                    c.point_mass_us_per_frame,
                    c.hybrid_us_per_frame,
                    c.rigid_us_per_frame,
                    c.switch_to_rigid_us
                );
            }
            println!(
                "  a frame whatever its creatures (court, puck, schedule): {:.1}; the budget policy's choice per creature: {:.2}",
                model.fixed_us_per_frame, model.decision_us_per_creature
            );
        }
        Ok(())
    }
}

fn positive_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("not a number: {s:?}"))?;
    if v.is_finite() && v > 0.0 && v <= f64::from(MAX_DURATION_S) {
        Ok(v)
    } else {
        Err(format!(
            "must be more than 0 and at most {MAX_DURATION_S} seconds, got {v}"
        ))
    }
}

fn print_summary(args: &RunArgs, s: &Summary, config: &SimConfig, ran: &WhatRan) {
    fn join<K: Key, T: std::fmt::Display + Copy>(counts: &Counts<K, T>) -> String {
        counts
            .iter()
            .map(|(k, v)| format!("{} {v}", k.name()))
            .collect::<Vec<_>>()
            .join(", ")
    }
    println!(
        "simlod run: {}, seed {}, {} creatures",
        args.scenario.scenario_file().display(),
        s.seed,
        s.creatures
    );
    println!(
        "level policy {} (rules {}, cost model {})",
        ran.policy,
        ran.rules.display(),
        ran.cost_model.display()
    );
    println!(
        "simulated {:.2} s in {:.3} s of wall time ({:.1}x real time); {} Hz ticks, {} Hz steering",
        s.sim_seconds, s.wall_seconds, s.realtime_factor, config.scenario.tick_hz, config.scenario.decision_hz
    );
    println!("collisions: {}", join(&s.collisions));
    println!(
        "creatures that collided with the puck or a wall: {} (by what they hit, one creature counted under each it hit: {})",
        s.creatures_collided,
        join(&s.creatures_collided_with)
    );
    println!(
        "falls: {} ({} within a step of going rigid), respawns: {}",
        s.falls, s.falls_after_switch, s.respawns
    );
    println!("creatures per level at the end: {}", join(&s.levels));
    let mean: Vec<String> = s
        .levels_mean
        .iter()
        .map(|(k, v)| format!("{} {v:.1} (peak {})", k.name(), s.levels_peak[k]))
        .collect();
    println!("creatures per level on average: {}", mean.join(", "));
    println!(
        "frame as the cost model predicts it from the levels simulated: {:.2} ms on average, {:.2} ms at the slowest",
        s.predicted_frame.mean_ms, s.predicted_frame.slowest_ms
    );
    let switches: Vec<String> = s
        .switches
        .directions()
        .map(|(from, to, n)| format!("{}->{} {n}", from.name(), to.name()))
        .chain([format!("total {}", s.switches.total())])
        .collect();
    println!("level switches: {}", switches.join(", "));
    if let Some(b) = &s.budget {
        let chosen = if b.decisions_over_budget == 0 {
            "within it at every decision".to_owned()
        } else {
            format!(
                "over it at {} of {} decisions (even the cheapest levels did not fit)",
                b.decisions_over_budget, b.decisions
            )
        };
        let adaptive = if b.adaptive {
            format!(
                " (adaptive, not reproducible: the cost model corrected x {:.2} at the end)",
                b.correction
            )
        } else {
            String::new()
        };
        // The wall clock, read outside the simulation: what the prediction is measured against.
        let measured_ms = s.wall_seconds * 1e3 / b.decisions.max(1) as f64;
        let kept = if measured_ms > f64::from(b.frame_budget_ms) {
            format!(
                "{:.0} % over the budget",
                (measured_ms / f64::from(b.frame_budget_ms).max(1e-9) - 1.0) * 100.0
            )
        } else {
            "within the budget".to_owned()
        };
        println!(
            "frame budget {} ms of simulation per 1/30 s: as the policy chose, predicted {:.3} ms on average and {:.3} ms at most, {chosen}{adaptive}; measured {measured_ms:.3} ms of wall time on average, {kept}",
            b.frame_budget_ms, b.predicted_ms_mean, b.predicted_ms_max
        );
    }
    for p in &s.pops {
        println!(
            "  pops {}->{}{}: as drawn {:.2} cm, {:.2} deg, {:.3} m/s; models alone {:.1} cm, {:.1} deg (largest of {})",
            p.from,
            p.to,
            if p.forced { " (forced)" } else { "" },
            p.metres.max * 100.0,
            p.degrees.max,
            p.velocity_m_per_s.max,
            p.model_metres.max * 100.0,
            p.model_degrees.max,
            p.count
        );
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        #[cfg(feature = "game")]
        None => PlayArgs::parse_from(["play"]).play(),
        #[cfg(not(feature = "game"))]
        None => Err(
            "this build has no game window (built without the `game` feature); `simlod run` simulates without one"
                .to_owned(),
        ),
        #[cfg(feature = "game")]
        Some(Command::Play(args)) => args.play(),
        Some(Command::Run(args)) => args.run(),
        Some(Command::RecordGait(args)) => args.run(),
        Some(Command::Bench(args)) => args.run(),
        Some(Command::Experiment(ExperimentArgs { which })) => match which {
            ExperimentKind::StepResponse(run) => run.run("step-response"),
            ExperimentKind::Table1(run) => run.run("table1"),
            ExperimentKind::Fig7(run) => run.run("fig7"),
            ExperimentKind::Fig8(run) => run.run("fig8"),
            ExperimentKind::Fig9(run) => run.run("fig9"),
            ExperimentKind::Fig10(run) => run.run("fig10"),
            ExperimentKind::Budget(run) => run.run("budget"),
            ExperimentKind::Crowd(run) => run.run("crowd"),
            ExperimentKind::All(run) => run.run("all"),
            ExperimentKind::Merge { dirs, out } => {
                experiments::fig10::merge(&dirs, &out).map(|summary| print!("{summary}"))
            }
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}
