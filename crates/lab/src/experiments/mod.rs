//! The paper's experiments (section 4): `simlod experiment <name> --out DIR` writes for each
//! `<name>.csv` (one row per measurement), `<name>.png` (the plot), `<name>.json` (its summary
//! figures) and `report.md` (every experiment in that folder beside the paper's numbers).
//!
//! Timing experiments (table1, fig7, fig8, fig9) take one measurement at a time in one
//! process. Outcome trials (fig10) are independent and run on `--jobs` threads, each trial's
//! simulation on one thread; they can be split into shards and merged.

pub mod budget;
pub mod budget_scale;
pub mod crowd;
pub mod fig10;
pub mod fig7;
pub mod frame_rate;
pub mod plot;
mod progress;
pub mod report;
pub mod step_response;
pub mod table1;

pub use progress::Progress;

use crate::error::{LabError, io_error};
pub use crate::scene::{EXPERIMENT_COURT_M, lone_creature, only_kind, stand};
use bevy::prelude::*;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use simlod::SimStage;
use simlod::config::{SimConfig, Validate, Validator, load_file};
use simlod::creature::KindTable;
use simlod::headless::HeadlessSim;
use simlod::lod::Lod;
use simlod::outcome::Summary;

/// How an experiment is run: flags of `simlod experiment`.
#[derive(Clone, Debug)]
pub struct Options {
    /// The folder the experiment's CSV, plot, JSON and `report.md` are written into (`--out`).
    pub out: PathBuf,
    /// The `quick` settings of the experiment's file: small counts, seconds of work.
    pub quick: bool,
    /// Overrides the file's trial count.
    pub trials: Option<u32>,
    /// Threads for independent trials.
    pub jobs: usize,
    /// Run only this part of the trials.
    pub shard: Shard,
    /// The assets folder (experiment files name rules files under it).
    pub assets: PathBuf,
    /// The scenario file, as given on the command line (for the commands in the report).
    pub scenario: PathBuf,
}

/// The `k`-th (from 1) of `n` disjoint parts of an experiment's trials.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// Which part this is, counting from 1.
    pub k: u32,
    /// How many parts the trials are split into.
    pub n: u32,
}

impl Shard {
    /// All the trials: the one part of one (`--shard 1/1`).
    pub const WHOLE: Shard = Shard { k: 1, n: 1 };

    /// Whether unit `i` of the experiment belongs to this shard.
    pub fn owns(self, i: u32) -> bool {
        i % self.n == self.k - 1
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let parsed = s
            .split_once('/')
            .and_then(|(k, n)| Some((k.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?)));
        match parsed {
            Some((k, n)) if n >= 1 && (1..=n).contains(&k) => Ok(Shard { k, n }),
            _ => Err(format!("must be K/N with 1 <= K <= N, got {s:?}")),
        }
    }
}

/// An experiment's asset file: the settings of a full run and of `--quick`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentFile<S> {
    /// The settings of a full run.
    pub full: S,
    /// The settings of a `--quick` run: small counts, seconds of work.
    pub quick: S,
}

impl<S: Validate> Validate for ExperimentFile<S> {
    fn validate(&self, v: &mut Validator) {
        v.nested("full", |v| self.full.validate(v));
        v.nested("quick", |v| self.quick.validate(v));
    }
}

/// The settings `options` ask for from an experiment file, validated.
pub fn load_settings<S: DeserializeOwned + Validate>(file: &Path, options: &Options) -> Result<S, LabError> {
    let f: ExperimentFile<S> = load_file(file)?;
    Ok(if options.quick { f.quick } else { f.full })
}

/// The trial count: `--trials`, else the file's.
pub fn trials(options: &Options, from_file: u32) -> u32 {
    options.trials.unwrap_or(from_file)
}

/// Checks that a creature kind named in experiment `file` is one the scenario has, with every
/// level in `levels`.
pub fn check_kind(config: &SimConfig, file: &Path, field: &str, kind: &str, levels: &[Lod]) -> Result<(), LabError> {
    let Some(i) = config.kind_index(kind) else {
        return Err(LabError::Invalid(format!(
            "{}: field `{field}`: the scenario has no creature kind {kind:?}",
            file.display()
        )));
    };
    lacking_level(config, i, levels).map_or(Ok(()), |why| {
        Err(LabError::Invalid(format!("{}: field `{field}`: {why}", file.display())))
    })
}

/// The levels experiment `name` compares across the scenario's whole mix. A kind without one
/// would run at the level below it and be reported under the wrong level's name.
fn compared_levels(name: &str) -> &'static [Lod] {
    match name {
        "fig8" | "fig10" | "budget" | "budget-scale" => &[Lod::Hybrid, Lod::Rigid],
        "fig9" | "crowd" => &Lod::ALL,
        // table1 measures each kind at the levels it has; fig7 and step-response run one kind
        // from their own file and check it there.
        _ => &[],
    }
}

/// Why kind `i` cannot be run at every level of `levels`, if it cannot.
fn lacking_level(config: &SimConfig, i: usize, levels: &[Lod]) -> Option<String> {
    let has = &KindTable::of(config)[i].levels;
    let missing = levels.iter().find(|l| !has.contains(l))?;
    let file_lacks = match missing {
        Lod::Rigid => "its file has no `rigid` section",
        _ => "its file names no `gait_table`; `simlod record-gait` records one",
    };
    Some(format!(
        "creature kind {:?} has no {} level ({file_lacks}), and the experiment compares the {} levels",
        config.kinds[i].name,
        missing.name().replace('_', " "),
        levels
            .iter()
            .map(|l| l.name().replace('_', " "))
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// Stops the rules and the stages that are not the models' own: levels stay as they are set,
/// and `stages` (for example steering and collisions) do not run.
pub fn hold_levels(sim: &mut HeadlessSim, stages: &[SimStage]) {
    for &stage in [SimStage::SelectLod, SimStage::Switch].iter().chain(stages) {
        let schedule = simlod::contract::SimClock::schedule_of(&sim.app);
        sim.app.configure_sets(schedule, stage.run_if(|| false));
    }
}

/// Runs `config` for `seconds` (whole frames of one steering decision), timing each frame.
pub fn timed_game(config: SimConfig, seconds: f64) -> (Vec<f64>, Summary) {
    let mut sim = HeadlessSim::new(config);
    let frames = timed_frames(&mut sim, seconds);
    let wall = frames.iter().sum();
    (frames, sim.summary(wall))
}

/// Each frame of `sim` until its clock reaches `seconds`, in seconds of wall time.
pub fn timed_frames(sim: &mut HeadlessSim, seconds: f64) -> Vec<f64> {
    let mut frames = Vec::new();
    while sim.clock().seconds() < seconds - 1e-9 {
        let start = Instant::now();
        sim.advance_frame();
        frames.push(start.elapsed().as_secs_f64());
    }
    frames
}

/// Runs `work` on every item on `jobs` threads and hands each result to `done` on this
/// thread, in the order they finish.
pub fn run_parallel<T: Sync, R: Send>(
    items: &[T],
    jobs: usize,
    work: impl Fn(&T) -> R + Sync,
    mut done: impl FnMut(&T, R),
) {
    let next = AtomicUsize::new(0);
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, items.len().max(1)) {
            let send = send.clone();
            let (next, work) = (&next, &work);
            scope.spawn(move || {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(item) = items.get(i) else { break };
                    if send.send((i, work(item))).is_err() {
                        break;
                    }
                }
            });
        }
        drop(send);
        for (i, result) in receive {
            done(&items[i], result);
        }
    });
}

/// Writes one of an experiment's files into the output folder.
pub fn write_out(out: &Path, file: &str, text: &str) -> Result<PathBuf, LabError> {
    std::fs::create_dir_all(out).map_err(io_error("create", out))?;
    let path = out.join(file);
    std::fs::write(&path, text).map_err(io_error("write", &path))?;
    Ok(path)
}

/// Every number in `value` that is an `f32` widened (`serde_json` keeps its numbers as `f64`, so
/// an `f32` of 1.2 would print as 1.2000000476837158) written as the `f32` prints: the figures
/// in a JSON summary read as they were set and measured. A number exactly an `f32` is taken for
/// one; its shortest form as an `f32` is the same value to within an `f32`'s precision.
pub fn shortest_floats(value: &mut serde_json::Value) {
    use serde_json::Value;
    match value {
        Value::Number(n) => {
            let Some(x) = n.as_f64().filter(|_| n.is_f64()) else {
                return;
            };
            let narrow = x as f32;
            if f64::from(narrow) == x
                && let Some(short) = (narrow.to_string().parse::<f64>().ok()).and_then(serde_json::Number::from_f64)
            {
                *n = short;
            }
        }
        Value::Array(items) => items.iter_mut().for_each(shortest_floats),
        Value::Object(fields) => fields.values_mut().for_each(shortest_floats),
        Value::Null | Value::Bool(_) | Value::String(_) => {}
    }
}

/// What an experiment leaves in its `<name>.json`: its summary figures and the report's
/// section on it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExperimentRecord {
    /// The experiment's name, as `simlod experiment` takes it (e.g. `fig10`).
    pub experiment: String,
    /// The command that regenerates it.
    pub command: String,
    /// Its summary figures, as the experiment wrote them (different for each experiment).
    pub summary: serde_json::Value,
    /// Markdown: what the paper reports, what we measured, how they compare.
    pub report: String,
    /// A `--quick` run: small counts and short games that check the pipeline, not findings.
    #[serde(default)]
    pub smoke_test: bool,
}

impl ExperimentRecord {
    /// Writes `<name>.csv`, `<name>.json` and the report (the plot is drawn before).
    pub fn finish(&self, out: &Path, csv: &str) -> Result<String, LabError> {
        let name = &self.experiment;
        write_out(out, &format!("{name}.csv"), csv)?;
        self.save(out, &[&format!("{name}.csv"), &format!("{name}.png")])
    }

    /// Writes `<name>.json` and the report, and says so with the `other` files the experiment
    /// wrote before.
    pub fn save(&self, out: &Path, other: &[&str]) -> Result<String, LabError> {
        let name = &self.experiment;
        let mut record = serde_json::to_value(self).expect("a record serialises");
        shortest_floats(&mut record);
        let json = serde_json::to_string_pretty(&record).expect("a record serialises");
        write_out(out, &format!("{name}.json"), &(json + "\n"))?;
        let report = report::write(out)?;
        let report = report
            .file_name()
            .map_or_else(String::new, |f| f.to_string_lossy().into_owned());
        let written: Vec<String> = other
            .iter()
            .map(|f| f.to_string())
            .chain([format!("{name}.json")])
            .collect();
        let smoke_test = if self.smoke_test {
            format!(
                "{name}: SMOKE TEST (--quick): small counts that check the pipeline; its numbers are not findings\n"
            )
        } else {
            String::new()
        };
        Ok(format!(
            "{smoke_test}{}\nwrote {} and {report} in {}\n",
            self.report.trim_end(),
            written.join(", "),
            out.display()
        ))
    }
}

/// The mean of `values` and their sample variance (0 for a single value).
pub fn mean_and_variance(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = if values.len() > 1 {
        values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (mean, variance)
}

/// Checks a list of crowd sizes: at least one, smallest first, each a creature count the
/// simulation takes.
pub fn validate_crowd_sizes(v: &mut Validator, creatures: &[u32]) {
    v.require(
        !creatures.is_empty() && creatures.windows(2).all(|w| w[0] < w[1]),
        "creatures",
        "must list crowd sizes, smallest first",
    );
    for (i, &n) in creatures.iter().enumerate() {
        v.require(
            (1..=simlod::config::MAX_CREATURES).contains(&n),
            &format!("creatures[{i}]"),
            format!(
                "must be between 1 and {} creatures, got {n}",
                simlod::config::MAX_CREATURES
            ),
        );
    }
}

/// The smallest and largest of validated crowd sizes, as log10: a plot's span.
pub fn log10_span(creatures: &[u32]) -> (f64, f64) {
    let log = |n: &u32| f64::from(*n).log10();
    (creatures.first().map_or(0.0, log), creatures.last().map_or(0.0, log))
}

/// The 99th percentile of frame times given in seconds, in ms.
pub fn p99_ms(frames_s: &[f64]) -> f64 {
    percentile_ms(frames_s, 99.0)
}

/// The `percentile` of frame times given in seconds (by nearest rank, as the adaptive mode
/// takes it), in ms; 0 without any.
pub fn percentile_ms(frames_s: &[f64], percentile: f32) -> f64 {
    let mut sorted = frames_s.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted
        .get(simlod::lod::nearest_rank(sorted.len(), percentile))
        .map_or(0.0, |s| s * 1e3)
}

/// The median of some values (NaN if there are none).
pub fn median_of(values: impl IntoIterator<Item = f64>) -> f64 {
    let v: Vec<f64> = values.into_iter().collect();
    if v.is_empty() {
        f64::NAN
    } else {
        crate::bench::median(v)
    }
}

/// The command line that reruns experiment `name` as `options` ran it.
pub fn command(name: &str, options: &Options) -> String {
    let mut c = format!("simlod experiment {name} --out {}", options.out.display());
    if options.assets != Path::new("assets") {
        c += &format!(" --assets {}", options.assets.display());
    }
    if options.scenario != options.assets.join("scenarios/default.ron") {
        c += &format!(" --scenario {}", options.scenario.display());
    }
    if options.quick {
        c += " --quick";
    }
    if let Some(t) = options.trials {
        c += &format!(" --trials {t}");
    }
    if options.shard != Shard::WHOLE {
        c += &format!(" --shard {}/{}", options.shard.k, options.shard.n);
    }
    c
}

/// The experiments `simlod experiment all` runs, in the report's order.
pub const ALL: [&str; 9] = report::ORDER;

/// The experiment file `name` reads unless told otherwise: under the assets folder.
pub fn default_file(assets: &Path, name: &str) -> PathBuf {
    assets
        .join("experiments")
        .join(format!("{}.ron", name.replace('-', "_")))
}

/// Runs experiment `name` from `file` into `options.out`; returns what it says.
pub fn run_named(name: &str, config: &SimConfig, file: &Path, options: &Options) -> Result<String, LabError> {
    if options.shard != Shard::WHOLE && name != "fig10" {
        return Err(LabError::Invalid(format!(
            "--shard splits fig10's trials only; {name} measures one thing at a time on one machine"
        )));
    }
    for group in &config.scenario.creatures {
        let i = config.kind_index(&group.kind).expect("a loaded scenario's kinds exist");
        if let Some(why) = lacking_level(config, i, compared_levels(name)) {
            return Err(LabError::Invalid(format!("{name} cannot run this scenario: {why}")));
        }
    }
    std::fs::create_dir_all(&options.out).map_err(io_error("create", &options.out))?;
    match name {
        "step-response" => step_response::run(config, file, &options.out),
        "table1" => table1::run(config, file, options),
        "fig7" => fig7::run(config, file, options),
        "fig8" | "fig9" => frame_rate::run(name, config, file, options),
        "fig10" => fig10::run(config, file, options),
        "budget" => budget::run(config, file, options),
        "crowd" => crowd::run(config, file, options),
        "budget-scale" => budget_scale::run(config, file, options),
        _ => Err(LabError::Invalid(format!(
            "no experiment {name:?}; there are {}",
            ALL.join(", ")
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::shortest_floats;

    #[test]
    fn an_f32_in_a_summary_prints_as_it_was_set_and_an_f64_is_left_whole() {
        let mut v = serde_json::json!({ "limit": 1.2f32, "ms": [0.4f32, 1.0f32], "exact": 0.1f64, "n": 3 });
        shortest_floats(&mut v);
        assert_eq!(v.to_string(), r#"{"exact":0.1,"limit":1.2,"ms":[0.4,1.0],"n":3}"#);
        let third = 1.0f64 / 3.0;
        let mut w = serde_json::json!(third);
        shortest_floats(&mut w);
        assert_eq!(w.as_f64(), Some(third));
    }
}
