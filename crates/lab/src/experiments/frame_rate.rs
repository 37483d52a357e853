//! Figures 8 and 9: the average and the lowest frame rate of a 20 s game as a radius of
//! influence grows: the puck's (figure 8: rigid inside its area, else hybrid) or the camera's
//! (figure 9: out of view point mass, in view hybrid, in view and near rigid). A frame is
//! 1/30 s of motion; its rate is frames per second of wall time, headless.

use crate::error::LabError;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::plot::{self, Mark, Panel, Series};
use super::{ExperimentRecord, Options, command, load_settings, median_of, timed_game, trials};
use simlod::config::{LevelRules, SimConfig, Validate, Validator, load_file};
use simlod::lod::{LevelPolicy, Lod};

/// The radius an experiment sweeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SweptRadius {
    /// The puck's radius of influence (figure 8).
    Puck,
    /// The camera's radius of influence (figure 9).
    Camera,
}

/// A level-rules file the sweep runs under, by a name for the plot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RulesVariant {
    /// The variant's name in the plot's legend and the CSV's `rules` column.
    pub name: String,
    /// Under the assets folder.
    pub file: String,
}

/// `assets/experiments/fig8.ron` and `fig9.ron`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameRateSettings {
    /// Which radius of influence is swept: the puck's (figure 8) or the camera's (figure 9).
    pub swept: SweptRadius,
    /// The level policy the games run under.
    pub policy: LevelPolicy,
    /// The radii swept, metres.
    pub radii_m: Vec<f32>,
    /// The level-rules files each radius runs under, one curve each.
    pub rules: Vec<RulesVariant>,
    /// Length of each game.
    pub seconds: f32,
    /// Games per radius and rules (seeds from the scenario's on); the plot has their median.
    pub trials: u32,
}

impl Validate for FrameRateSettings {
    fn validate(&self, v: &mut Validator) {
        v.require(!self.radii_m.is_empty(), "radii_m", "must list at least one radius");
        for (i, r) in self.radii_m.iter().enumerate() {
            v.within(&format!("radii_m[{i}]"), *r, 0.0, 1e4);
        }
        v.require(!self.rules.is_empty(), "rules", "must list at least one rules file");
        for (i, r) in self.rules.iter().enumerate() {
            v.require(
                !r.file.is_empty(),
                &format!("rules[{i}].file"),
                "must name a rules file",
            );
        }
        v.within("seconds", self.seconds, 1.0 / 30.0, simlod::config::MAX_DURATION_S);
        v.require(self.trials >= 1, "trials", "must be at least 1");
    }
}

/// Seconds of the untimed game that warms the process before the first measured one.
const WARM_UP_S: f64 = 2.0;

/// The game of one trial: the scenario under `rules` with the swept radius set.
pub fn trial_config(
    config: &SimConfig,
    rules: &LevelRules,
    s: &FrameRateSettings,
    radius: f32,
    seed: u64,
) -> SimConfig {
    let mut c = config.clone();
    c.rules = rules.clone();
    match s.swept {
        SweptRadius::Puck => c.rules.influence.puck_radius_m = radius,
        SweptRadius::Camera => c.rules.camera.radius_m = radius,
    }
    c.scenario.level_policy = s.policy;
    c.scenario.seed = seed;
    c
}

/// One figure's median figures at one radius under one rules file.
#[derive(Clone, Debug, Default, Serialize)]
struct Point {
    mean_fps: f64,
    lowest_fps: f64,
    mean_rigid: f64,
}

/// Runs figure 8 or 9 (`name`) from `file`: timed games at each radius under each rules file;
/// writes its CSV, plot, JSON and report and returns what it says.
pub fn run(name: &str, config: &SimConfig, file: &Path, options: &Options) -> Result<String, LabError> {
    let s: FrameRateSettings = load_settings(file, options)?;
    let mut variants = Vec::new();
    for (i, v) in s.rules.iter().enumerate() {
        let rules: LevelRules = load_file(&options.assets.join(&v.file))
            .map_err(|e| LabError::Invalid(format!("{} (named by {}: field `rules[{i}].file`)", e, file.display())))?;
        variants.push((v, rules));
    }
    let n_trials = trials(options, s.trials);
    let flag = match s.swept {
        SweptRadius::Puck => "puck",
        SweptRadius::Camera => "camera",
    };
    let mut csv = format!(
        "rules,{flag}_radius_m,trial,seed,frames,mean_fps,lowest_fps,mean_rigid,mean_hybrid,mean_point_mass,wall_s\n"
    );
    let total = variants.len() * s.radii_m.len() * n_trials as usize;
    let mut progress = super::Progress::new(name, total as u64);
    let mut points: BTreeMap<(usize, usize), Point> = BTreeMap::new();
    // The first game in a process runs cold (caches, allocator, thread pool): one game of the
    // first setting, untimed, warms them, so that the first radius is measured as the others.
    if let (Some((_, rules)), Some(&radius)) = (variants.first(), s.radii_m.first()) {
        let warm_up = trial_config(config, rules, &s, radius, config.scenario.seed);
        timed_game(warm_up, f64::from(s.seconds).min(WARM_UP_S));
    }
    for (vi, (variant, rules)) in variants.iter().enumerate() {
        for (ri, &radius) in s.radii_m.iter().enumerate() {
            let mut runs = Vec::new();
            for trial in 0..n_trials {
                let seed = config.scenario.seed + u64::from(trial);
                let (frames, summary) = timed_game(trial_config(config, rules, &s, radius, seed), f64::from(s.seconds));
                let wall: f64 = frames.iter().sum();
                let slowest = frames.iter().copied().fold(0.0, f64::max);
                let p = Point {
                    mean_fps: frames.len() as f64 / wall,
                    lowest_fps: 1.0 / slowest,
                    mean_rigid: summary.levels_mean[Lod::Rigid],
                };
                let _ = writeln!(
                    csv,
                    "{},{radius},{trial},{seed},{},{:.3},{:.3},{:.3},{:.3},{:.3},{wall:.4}",
                    variant.name,
                    frames.len(),
                    p.mean_fps,
                    p.lowest_fps,
                    p.mean_rigid,
                    summary.levels_mean[Lod::Hybrid],
                    summary.levels_mean[Lod::PointMass],
                );
                runs.push(p);
                progress.inc();
            }
            points.insert(
                (vi, ri),
                Point {
                    mean_fps: median_of(runs.iter().map(|p| p.mean_fps)),
                    lowest_fps: median_of(runs.iter().map(|p| p.lowest_fps)),
                    mean_rigid: median_of(runs.iter().map(|p| p.mean_rigid)),
                },
            );
        }
    }
    drop(progress);
    let curve = |vi: usize, f: fn(&Point) -> f64| -> Vec<(f64, f64)> {
        (0..s.radii_m.len())
            .map(|ri| (f64::from(s.radii_m[ri]), f(&points[&(vi, ri)])))
            .collect()
    };
    let mut fps = Vec::new();
    let mut rigid = Vec::new();
    for (vi, (v, _)) in variants.iter().enumerate() {
        fps.push(Series::new(
            format!("average, {}", v.name),
            curve(vi, |p| p.mean_fps),
            Mark::Line,
            vi,
        ));
        fps.push(Series::new(
            format!("lowest, {}", v.name),
            curve(vi, |p| p.lowest_fps),
            Mark::Dashed,
            vi,
        ));
        rigid.push(Series::new(v.name.clone(), curve(vi, |p| p.mean_rigid), Mark::Line, vi));
    }
    let (figure, what) = match s.swept {
        SweptRadius::Puck => ("Figure 8", "puck's"),
        SweptRadius::Camera => ("Figure 9", "camera's"),
    };
    let x_label = format!("the {what} radius of influence (m)");
    plot::draw(
        &options.out.join(format!("{name}.png")),
        1400,
        600,
        &[
            Panel {
                title: format!("{figure}: frame rate of a {} s game, headless", s.seconds),
                x_label: x_label.clone(),
                y_label: "frames of 1/30 s per second of wall time".into(),
                series: fps,
                ..Panel::default()
            },
            Panel {
                title: "rigid creatures, mean over the game".into(),
                x_label,
                y_label: "rigid creatures".into(),
                series: rigid,
                ..Panel::default()
            },
        ],
        options.quick,
    )?;
    let creatures = config.scenario.creature_count();
    let mut report = format!(
        "The scenario's game ({creatures} creatures, policy `{:?}`) for {} s at each radius, {n_trials} game(s) per radius (seeds {} on; the table has their medians), \
         one at a time in one process. The average frame rate is frames of 1/30 s of motion per second of wall time; the lowest is the slowest frame's. \
         The paper plots the same two curves with graphics on its 1997 workstation and gives no numbers in the text; its frame rate falls as the radius grows \
         and more creatures are rigid.\n\n| rules | radius (m) | average fps | lowest fps | rigid creatures (mean) |\n|---|---|---|---|---|\n",
        s.policy, s.seconds, config.scenario.seed
    );
    let mut summary = Vec::new();
    for (vi, (v, _)) in variants.iter().enumerate() {
        for (ri, r) in s.radii_m.iter().enumerate() {
            let p = &points[&(vi, ri)];
            let _ = writeln!(
                report,
                "| {} | {r} | {:.0} | {:.0} | {:.1} |",
                v.name, p.mean_fps, p.lowest_fps, p.mean_rigid
            );
            summary.push(serde_json::json!({ "rules": v.name, "radius_m": r, "median": p }));
        }
    }
    for (vi, (v, _)) in variants.iter().enumerate() {
        let (first, last) = (&points[&(vi, 0)], &points[&(vi, s.radii_m.len() - 1)]);
        let _ = write!(
            report,
            "\n{}: from {} m to {} m the average frame rate goes from {:.0} to {:.0} fps ({:.2} times) and the mean rigid creatures from {:.1} to {:.1}.",
            v.name,
            s.radii_m[0],
            s.radii_m[s.radii_m.len() - 1],
            first.mean_fps,
            last.mean_fps,
            last.mean_fps / first.mean_fps,
            first.mean_rigid,
            last.mean_rigid
        );
    }
    let _ = write!(
        report,
        "\n\nAny row reruns alone: `simlod run --scenario {} --seed SEED --policy {} --rules RULES --{flag}-radius R --seconds {}` prints the same level counts.\n",
        options.scenario.display(),
        s.policy.name(),
        s.seconds
    );
    ExperimentRecord {
        experiment: name.into(),
        command: command(name, options),
        summary: serde_json::json!({ "points": summary, "trials": n_trials, "seconds": s.seconds }),
        report,
        smoke_test: options.quick,
    }
    .finish(&options.out, &csv)
}
