//! The budget at every crowd size: the budget policy under the scenario's own rules and cost
//! model (the game's, or one measured on this machine just before each crowd size's games, as the
//! game does at start-up), for each crowd size and each frame budget, with the cost model alone
//! and corrected by the measured frames (the adaptive mode, keeping their mean or a percentile
//! of them at the budget). Each game's frames are timed: the mean and the 99th percentile
//! against the budget, and what the policy predicted, after the game's first moments (its
//! warm-up), whose slowest frame is reported apart.

use crate::error::LabError;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

use super::plot::{self, Mark, Panel, Series};
use super::{ExperimentRecord, Options, command, load_settings, p99_ms, percentile_ms, timed_frames};
use crate::bench::{Calibration, calibrate, cost_model_lines, scaled};
use simlod::config::{SimConfig, Validate, Validator};
use simlod::contract::threads_for;
use simlod::headless::HeadlessSim;
use simlod::lod::{BudgetTally, LevelPolicy, Lod};
use simlod::{PARALLEL_MIN_CREATURES, run_chunks};
use std::time::Instant;

/// `assets/experiments/budget_scale.ron`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetScaleSettings {
    /// The crowd sizes, smallest first (the scenario's mix, its court grown to its density).
    pub creatures: Vec<u32>,
    /// The frame budgets, ms of simulation per 1/30 s.
    pub budgets_ms: Vec<f32>,
    /// The adaptive mode's settings: 0 is the cost model alone; above, the frames over which
    /// the correction by measured frames is smoothed (and at least those the percentile is
    /// taken of).
    pub adaptive_frames: Vec<f32>,
    /// What each adaptive setting above 0 keeps at the budget, each a game: 0 the mean frame,
    /// 50 to 100 that percentile of the frames (a file without it: the mean only).
    #[serde(default = "BudgetScaleSettings::mean_only")]
    pub adaptive_percentiles: Vec<f32>,
    /// What each percentile above 0 is kept within, each a game: times the budget, the mean
    /// frame within the budget itself (1 to 10; a file without it: the budget only).
    #[serde(default = "BudgetScaleSettings::within_the_budget")]
    pub adaptive_percentile_limits: Vec<f32>,
    /// Simulated seconds of each game.
    pub seconds: f32,
    /// Simulated seconds at the start of each game left out of its mean, its 99th percentile
    /// and its prediction (0 to under `seconds`; a file without it: none).
    #[serde(default)]
    pub warm_up_s: f32,
    /// The games' seed.
    pub seed: u64,
    /// Whether each crowd size's games are priced by a cost model measured on this machine just
    /// before them, in that crowd, as the game does at start-up (`frame_budget.calibrate_at_start`
    /// in `game.ron`), not the one the rules name (a file without it: the rules').
    #[serde(default)]
    pub calibrate_at_start: bool,
}

impl BudgetScaleSettings {
    fn mean_only() -> Vec<f32> {
        vec![0.0]
    }

    fn within_the_budget() -> Vec<f32> {
        vec![1.0]
    }

    /// The adaptive mode's settings, each a game at every size and budget: (frames,
    /// percentile, its limit), the cost model alone once, the mean once.
    fn adaptive_settings(&self) -> Vec<Adaptive> {
        let mut settings = Vec::new();
        for &frames in &self.adaptive_frames {
            let percentiles: &[f32] = if frames > 0.0 {
                &self.adaptive_percentiles
            } else {
                &[0.0]
            };
            for &p in percentiles {
                let limits: &[f32] = if p > 0.0 {
                    &self.adaptive_percentile_limits
                } else {
                    &[1.0]
                };
                settings.extend(limits.iter().map(|&limit| (frames, p, limit)));
            }
        }
        settings
    }
}

impl Validate for BudgetScaleSettings {
    fn validate(&self, v: &mut Validator) {
        super::validate_crowd_sizes(v, &self.creatures);
        v.require(
            !self.budgets_ms.is_empty(),
            "budgets_ms",
            "must list at least one budget",
        );
        for (i, &b) in self.budgets_ms.iter().enumerate() {
            v.range(&format!("budgets_ms[{i}]"), b, 0.01, 10_000.0);
        }
        v.require(
            !self.adaptive_frames.is_empty(),
            "adaptive_frames",
            "must list at least one setting",
        );
        for (i, &a) in self.adaptive_frames.iter().enumerate() {
            v.within(&format!("adaptive_frames[{i}]"), a, 0.0, 10_000.0);
        }
        v.require(
            !self.adaptive_percentiles.is_empty(),
            "adaptive_percentiles",
            "must list at least one setting (0: the mean)",
        );
        for (i, &p) in self.adaptive_percentiles.iter().enumerate() {
            simlod::config::validate_adaptive_percentile(v, &format!("adaptive_percentiles[{i}]"), p);
        }
        v.require(
            !self.adaptive_percentile_limits.is_empty(),
            "adaptive_percentile_limits",
            "must list at least one limit (1: the budget)",
        );
        for (i, &limit) in self.adaptive_percentile_limits.iter().enumerate() {
            let field = format!("adaptive_percentile_limits[{i}]");
            simlod::config::validate_adaptive_percentile_limit(v, &field, limit);
        }
        v.range("seconds", self.seconds, 1.0 / 30.0, 600.0);
        v.require(
            (0.0..self.seconds).contains(&self.warm_up_s),
            "warm_up_s",
            format!(
                "must be 0 or more and under `seconds` ({}), got {}",
                self.seconds, self.warm_up_s
            ),
        );
    }
}

/// A setting of the adaptive mode: the frames its correction is smoothed over (0: off), the
/// percentile it keeps (0: the mean) and how many times the budget it keeps it within.
type Adaptive = (f32, f32, f32);

/// One game: a crowd size, a budget, a setting of the adaptive mode.
#[derive(Clone, Debug, Serialize)]
struct Game {
    creatures: u32,
    budget_ms: f32,
    adaptive_frames: f32,
    /// 0: the adaptive mode keeps the mean frame at the budget; else this percentile.
    adaptive_percentile: f32,
    /// The percentile kept within this many times the budget (the mean within the budget).
    adaptive_percentile_limit: f32,
    /// The frames after the warm-up.
    frames: usize,
    mean_frame_ms: f64,
    /// The cost model is of median frames (its figures are medians): where the prediction is of
    /// the mean, this beside it tells the model's error from the machine's slow frames.
    median_frame_ms: f64,
    p99_frame_ms: f64,
    /// The frame the prediction is of: the mean, or in the percentile mode that percentile
    /// (the cost model's prediction, corrected by the mean, with its headroom).
    held_frame_ms: f64,
    predicted_mean_ms: f64,
    /// Decisions where even the cheapest levels allowed were predicted over the budget.
    decisions_over_budget: u64,
    decisions: u64,
    rigid: f64,
    hybrid: f64,
    /// The slowest frame of the warm-up, ms (0 without one).
    warm_up_slowest_ms: f64,
}

impl Game {
    fn setting(&self) -> Adaptive {
        (
            self.adaptive_frames,
            self.adaptive_percentile,
            self.adaptive_percentile_limit,
        )
    }

    fn mean_over_budget(&self) -> f64 {
        self.mean_frame_ms / f64::from(self.budget_ms)
    }

    /// Whether the budget was kept: the mean frame no more than 10 % over it, the 99th
    /// percentile no more than 25 % over.
    fn kept(&self) -> bool {
        self.mean_frame_ms <= 1.1 * f64::from(self.budget_ms) && self.p99_frame_ms <= 1.25 * f64::from(self.budget_ms)
    }

    /// Whether the budget was kept and spent: kept, and the mean frame no more than 10 % under
    /// it either.
    fn kept_and_spent(&self) -> bool {
        self.kept_and_spent_what_it_could(None)
    }

    /// Whether the budget was kept and as much of it spent as the crowd could use: kept, and the
    /// mean frame no more than 10 % under the budget or under `usable_ms`, the most the crowd
    /// was seen to use (see [`usable_by_size`]).
    fn kept_and_spent_what_it_could(&self, usable_ms: Option<f64>) -> bool {
        let budget_ms = f64::from(self.budget_ms);
        self.kept() && self.mean_frame_ms >= 0.9 * usable_ms.map_or(budget_ms, |u| u.min(budget_ms))
    }

    /// The frame predicted (the mean, or the percentile the adaptive mode keeps) as measured,
    /// over the prediction (which can be well under the budget: the choice buys no level worth
    /// less than its least benefit per microsecond, and none above a creature's dearest).
    fn measured_over_predicted(&self) -> f64 {
        self.held_frame_ms / self.predicted_mean_ms
    }

    /// The median frame over the prediction, where that is of the mean frame (not in the
    /// percentile mode).
    fn median_over_predicted(&self) -> Option<f64> {
        self.predicts_the_mean()
            .then(|| self.median_frame_ms / self.predicted_mean_ms)
    }

    /// Whether the frame predicted is the mean (else a percentile the adaptive mode keeps).
    fn predicts_the_mean(&self) -> bool {
        !keeps_a_percentile(self.adaptive_frames, self.adaptive_percentile)
    }

    /// How the adaptive mode ran, in words.
    fn adaptive(&self) -> String {
        match (self.adaptive_frames, self.adaptive_percentile) {
            (0.0, _) => "off".into(),
            (frames, 0.0) => format!("{frames} frames"),
            (frames, p) => format!(
                "{frames} frames, {p}th percentile of {}{}",
                simlod::lod::percentile_window(frames, p),
                match self.adaptive_percentile_limit {
                    1.0 => String::new(),
                    limit => format!(" within {limit} times the budget"),
                }
            ),
        }
    }

    /// Whether the prediction was honest: the frame predicted within 10 % of it, either way.
    fn predicted_within_10_percent(&self) -> bool {
        (self.measured_over_predicted() - 1.0).abs() <= 0.1
    }
}

/// The most each crowd size was seen to use, ms a frame: the mean frame of its game on the cost
/// model alone (reproducible, no headroom kept) at the largest budget, where that left more than
/// a tenth of it unspent (every creature at its dearest level, or no level left worth its cost);
/// none where it spent it, or no such game was played.
fn usable_by_size(games: &[Game]) -> std::collections::BTreeMap<u32, f64> {
    let largest = games.iter().map(|g| g.budget_ms).fold(0.0, f32::max);
    (games.iter())
        .filter(|g| g.adaptive_frames == 0.0 && g.budget_ms == largest)
        .filter(|g| g.mean_frame_ms < 0.9 * f64::from(largest))
        .map(|g| (g.creatures, g.mean_frame_ms))
        .collect()
}

/// Whether the adaptive mode, so set, keeps a percentile of the frames at the budget (else the
/// mean frame: its prediction is of the mean).
fn keeps_a_percentile(adaptive_frames: f32, adaptive_percentile: f32) -> bool {
    adaptive_frames > 0.0 && adaptive_percentile > 0.0
}

fn game(
    config: &SimConfig,
    s: &BudgetScaleSettings,
    creatures: u32,
    budget_ms: f32,
    (adaptive_frames, adaptive_percentile, adaptive_percentile_limit): Adaptive,
) -> Game {
    let mut c = scaled(config, creatures, LevelPolicy::Budget);
    c.scenario.seed = s.seed;
    let budget = &mut c.rules.budget;
    (
        budget.frame_budget_ms,
        budget.adaptive_frames,
        budget.adaptive_percentile,
        budget.adaptive_percentile_limit,
    ) = (
        budget_ms,
        adaptive_frames,
        adaptive_percentile,
        adaptive_percentile_limit,
    );
    let mut sim = HeadlessSim::new(c);
    // The first moments build the world's bodies and search every creature for contacts once.
    let warm_up = timed_frames(&mut sim, f64::from(s.warm_up_s));
    let tally = |sim: &HeadlessSim| sim.app.world().resource::<BudgetTally>().clone();
    let before = tally(&sim);
    let frames = timed_frames(&mut sim, f64::from(s.seconds));
    let after = tally(&sim);
    let summary = sim.summary(frames.iter().sum());
    let decisions = after.decisions - before.decisions;
    let mean_frame_ms = frames.iter().sum::<f64>() * 1e3 / frames.len().max(1) as f64;
    Game {
        creatures,
        budget_ms,
        adaptive_frames,
        adaptive_percentile,
        adaptive_percentile_limit,
        frames: frames.len(),
        mean_frame_ms,
        p99_frame_ms: p99_ms(&frames),
        held_frame_ms: if keeps_a_percentile(adaptive_frames, adaptive_percentile) {
            percentile_ms(&frames, adaptive_percentile)
        } else {
            mean_frame_ms
        },
        median_frame_ms: crate::bench::median(frames.clone()) * 1e3,
        predicted_mean_ms: (after.predicted_sum_us - before.predicted_sum_us) / decisions.max(1) as f64 / 1e3,
        decisions_over_budget: after.over_budget - before.over_budget,
        decisions,
        rigid: summary.levels_mean[Lod::Rigid],
        hybrid: summary.levels_mean[Lod::Hybrid],
        warm_up_slowest_ms: warm_up.iter().copied().fold(0.0, f64::max) * 1e3,
    }
}

/// A cost model measured before a crowd size's games (`calibrate_at_start`).
#[derive(Clone, Debug, Serialize)]
struct MeasuredModel {
    creatures: u32,
    /// How long measuring it took, s: the game's wait at start-up for that crowd.
    seconds: f64,
    /// What it says, a line each (see [`cost_model_lines`]).
    lines: Vec<String>,
}

/// The machine's own spread at one budget: a fixed job on as many threads as a game's loops run
/// on (one below a crowd, each of the compute pool's in one: see [`threads_for`]), its length set
/// to about the budget, timed as many times as a game has frames. Where its 99th percentile is
/// over 1.25 times its median, no game that spends the budget on as many cores keeps its 99th
/// percentile within 25 % of it on this machine, whatever the policy.
#[derive(Clone, Debug, Serialize)]
struct MachineSpread {
    budget_ms: f32,
    threads: usize,
    median_ms: f64,
    mean_ms: f64,
    p99_ms: f64,
}

impl MachineSpread {
    fn p99_over_median(&self) -> f64 {
        self.p99_ms / self.median_ms
    }
}

/// Each thread's memory in the fixed job, 8-byte words: 16 MiB, beyond the caches, since a
/// frame's work reads and writes memory and meets the machine's other tenants there. Walked
/// ALU-only, the job ran 1.04 to 1.4 times its median at its 99th percentile on one core here,
/// and through memory 1.6 to 1.7, as the games did.
const JOB_WORDS: usize = 2 << 20;

/// `steps` reads and writes, a large odd stride apart, of each thread's memory in `memory`.
fn fixed_job(memory: &mut [Vec<u64>], steps: u64) {
    run_chunks(memory.iter_mut().map(|words| {
        move || {
            let (len, mut at, mut sum) = (words.len(), 0, 0u64);
            for _ in 0..steps {
                sum = sum.wrapping_add(words[at]);
                words[at] = sum;
                at = (at + 4099) % len;
            }
            std::hint::black_box(sum);
        }
    }));
}

/// The fixed job of about `budget_ms` on `threads`, timed `frames` times. Its length is found
/// first: doubled until a job takes half the budget, then scaled twice by the median of five (a
/// job's start on the threads costs a little whatever its length).
fn machine_spread(budget_ms: f32, threads: usize, frames: usize) -> MachineSpread {
    let mut memory = vec![vec![1u64; JOB_WORDS]; threads];
    let mut timed = |steps| {
        let start = Instant::now();
        fixed_job(&mut memory, steps);
        start.elapsed().as_secs_f64()
    };
    let budget_s = f64::from(budget_ms) / 1e3;
    let mut steps = 1024u64;
    while timed(steps) < budget_s / 2.0 {
        steps *= 2;
    }
    for _ in 0..2 {
        let median_s = crate::bench::median((0..5).map(|_| timed(steps)).collect());
        steps = ((steps as f64 * budget_s / median_s.max(1e-9)) as u64).max(1);
    }
    let times: Vec<f64> = (0..frames.max(1)).map(|_| timed(steps)).collect();
    MachineSpread {
        budget_ms,
        threads,
        median_ms: crate::bench::median(times.clone()) * 1e3,
        mean_ms: times.iter().sum::<f64>() * 1e3 / times.len() as f64,
        p99_ms: p99_ms(&times),
    }
}

const HEADER: &str = "creatures,budget_ms,adaptive_frames,adaptive_percentile,frames,mean_frame_ms,p99_frame_ms,held_frame_ms,predicted_mean_ms,decisions_over_budget,decisions,hybrid,rigid,warm_up_slowest_ms,median_frame_ms,adaptive_percentile_limit";

/// Runs the experiment from `file`: every game, one at a time; writes its CSV, plot, JSON and
/// report and returns what it says.
pub fn run(config: &SimConfig, file: &Path, options: &Options) -> Result<String, LabError> {
    let s: BudgetScaleSettings = load_settings(file, options)?;
    let adaptive = s.adaptive_settings();
    let total = s.creatures.len() * s.budgets_ms.len() * adaptive.len();
    let mut progress = super::Progress::new("budget at every crowd size", total as u64);
    let mut games = Vec::with_capacity(total);
    // With `calibrate_at_start`, each crowd size's model, as its lines.
    let mut measured_models = Vec::new();
    for &n in &s.creatures {
        let measured;
        let config = if s.calibrate_at_start {
            // Measured as the game would for this crowd, its rigid shares up to what the
            // largest budget holds.
            let mut largest = config.clone();
            largest.rules.budget.frame_budget_ms = s.budgets_ms.iter().copied().fold(0.0, f32::max);
            let start = Instant::now();
            measured = SimConfig {
                costs: calibrate(&largest, Calibration::AtStartUp { creatures: n }),
                ..config.clone()
            };
            measured_models.push(MeasuredModel {
                creatures: n,
                seconds: start.elapsed().as_secs_f64(),
                lines: cost_model_lines(&measured.costs),
            });
            &measured
        } else {
            config
        };
        for &b in &s.budgets_ms {
            for &a in &adaptive {
                games.push(game(config, &s, n, b, a));
                progress.inc();
            }
        }
    }
    // The machine's spread, after the games (so that their compute pool is the one measured).
    let frames = games.first().map_or(1, |g| g.frames);
    let mut cores: Vec<usize> = s.creatures.iter().map(|&n| threads_for(n)).collect();
    cores.dedup();
    let machine: Vec<MachineSpread> = (cores.iter())
        .flat_map(|&threads| s.budgets_ms.iter().map(move |&b| machine_spread(b, threads, frames)))
        .collect();
    drop(progress);
    let mut csv = format!("{HEADER}\n");
    for g in &games {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{:.4},{:.4},{:.4},{:.4},{},{},{:.1},{:.1},{:.4},{:.4},{}",
            g.creatures,
            g.budget_ms,
            g.adaptive_frames,
            g.adaptive_percentile,
            g.frames,
            g.mean_frame_ms,
            g.p99_frame_ms,
            g.held_frame_ms,
            g.predicted_mean_ms,
            g.decisions_over_budget,
            g.decisions,
            g.hybrid,
            g.rigid,
            g.warm_up_slowest_ms,
            g.median_frame_ms,
            g.adaptive_percentile_limit
        );
    }
    draw(&games, &s, options)?;
    ExperimentRecord {
        experiment: "budget-scale".into(),
        command: command("budget-scale", options),
        summary: serde_json::json!({
            "games": games,
            "machine": machine,
            "calibrated_at_start": s.calibrate_at_start.then_some(&measured_models),
        }),
        report: report(&games, &machine, &s, &measured_models),
        smoke_test: options.quick,
    }
    .finish(&options.out, &csv)
}

/// The measured mean frame and 99th percentile over the budget against the crowd size, a panel
/// each: one line per budget and setting of the adaptive mode, the budget itself at 1.
fn draw(games: &[Game], s: &BudgetScaleSettings, options: &Options) -> Result<(), LabError> {
    let (lo, hi) = super::log10_span(&s.creatures);
    let panel = |what: &str, line: (&str, f64), over_budget: fn(&Game) -> f64| {
        let mut series = Vec::new();
        for (i, &b) in s.budgets_ms.iter().enumerate() {
            for setting in s.adaptive_settings() {
                let (frames, percentile, limit) = setting;
                let these: Vec<&Game> = (games.iter())
                    .filter(|g| g.budget_ms == b && g.setting() == setting)
                    .collect();
                let points = these
                    .iter()
                    .map(|g| (f64::from(g.creatures).log10(), over_budget(g)))
                    .collect();
                let mark = match (frames, percentile) {
                    (0.0, _) => Mark::Line,
                    (_, 0.0) => Mark::Dashed,
                    _ if limit == 1.0 => Mark::Points,
                    _ => Mark::Rings,
                };
                let setting = these.first().map_or_else(String::new, |g| g.adaptive());
                let label = if frames > 0.0 {
                    format!("{b} ms, adaptive ({setting})")
                } else {
                    format!("{b} ms, the cost model alone")
                };
                series.push(Series::new(label, points, mark, i));
            }
        }
        for (label, y) in [("the budget", 1.0), line] {
            series.push(Series::new(
                label,
                vec![(lo, y), (hi, y)],
                Mark::Dashed,
                plot::REFERENCE,
            ));
        }
        Panel {
            title: format!("the budget policy's {what}"),
            x_label: format!(
                "creatures, log10 (2 is 100, 5 is 100,000): games of {} s, the first {} s left out",
                s.seconds, s.warm_up_s
            ),
            y_label: format!("{what} over the budget (log)"),
            log_y: true,
            series,
            ..Panel::default()
        }
    };
    plot::draw(
        &options.out.join("budget-scale.png"),
        1700,
        750,
        &[
            panel("mean frame", ("10 % over", 1.1), Game::mean_over_budget),
            panel("99th-percentile frame", ("25 % over", 1.25), |g| {
                g.p99_frame_ms / f64::from(g.budget_ms)
            }),
        ],
        options.quick,
    )?;
    Ok(())
}

/// The report: the games, how many kept the budget, the machine's own spread, and the cost
/// models measured before each crowd size's games, if they were.
fn report(games: &[Game], machine: &[MachineSpread], s: &BudgetScaleSettings, measured: &[MeasuredModel]) -> String {
    // The frames a game holds after its warm-up, and which of them, slowest first, is its 99th
    // percentile: the slowest of all in a game under 100 frames.
    let frames = games.first().map_or(0, |g| g.frames);
    let p99_is = match frames - (frames as f64 * 0.99).ceil() as usize {
        0 => "its slowest frame".to_owned(),
        slower => format!("the slowest after the {slower} slowest"),
    };
    let rules = if s.calibrate_at_start {
        "rules (the game's) and a cost model measured on this machine just before each crowd size's games, as the game does \
         at start-up (its shares in that crowd, the rigid level's up to what the largest budget holds)"
    } else {
        "rules and cost model (the game's)"
    };
    let mut report = format!(
        "The budget policy under the scenario's own {rules}, seed {}, games of {} s: the scenario's mix, \
         the court grown with the count to the default game's density. Every frame's simulation timed on this machine's cores. \
         The first {} s of each game, its warm-up (the world's bodies built, every creature searched for contacts once), is left \
         out of the mean, the 99th percentile and the prediction; its slowest frame is in the last column. \
         The budget is kept where the mean frame is no more than 10 % over it and the 99th percentile no more than 25 % over: a game is {frames} frames \
         after its warm-up, and its 99th percentile is {p99_is}. \
         Measured / predicted: the frame predicted over its prediction, honest within 10 % either way: the mean frame, or where \
         the adaptive mode keeps a percentile of the frames at the budget, that percentile (its prediction is the cost model's, \
         corrected by the mean, with that percentile of what the last frames took beyond it kept free). \
         Median / predicted: where the prediction is of the mean, the median frame over it: the cost model's figures are \
         medians, and the mean also carries the machine's slow frames (see its spread below). \
         Over budget: the decisions where even the cheapest levels were predicted over it.\n\n\
         | creatures | budget (ms) | adaptive | mean frame (ms) | 99th percentile (ms) | predicted (ms) | measured / predicted | median / predicted | kept | over budget | hybrid | rigid | warm-up's slowest (ms) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        s.seed, s.seconds, s.warm_up_s
    );
    for g in games {
        let _ = writeln!(
            report,
            "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} | {} of {} | {:.0} | {:.0} | {:.2} |",
            g.creatures,
            g.budget_ms,
            g.adaptive(),
            g.mean_frame_ms,
            g.p99_frame_ms,
            g.predicted_mean_ms,
            g.measured_over_predicted(),
            g.median_over_predicted().map_or("-".into(), |r| format!("{r:.2}")),
            if g.kept() { "yes" } else { "no" },
            g.decisions_over_budget,
            g.decisions,
            g.hybrid,
            g.rigid,
            g.warm_up_slowest_ms
        );
    }
    let kept = games.iter().filter(|g| g.kept()).count();
    let spent = games.iter().filter(|g| g.kept_and_spent()).count();
    let usable = usable_by_size(games);
    let could = (games.iter())
        .filter(|g| g.kept_and_spent_what_it_could(usable.get(&g.creatures).copied()))
        .count();
    let usable_words = if usable.is_empty() {
        String::new()
    } else {
        let sizes: Vec<String> = (usable.iter())
            .map(|(n, ms)| format!("{n} creatures {ms:.2} ms"))
            .collect();
        format!(
            " Spent as much as the crowd could use (where its game on the cost model alone at the largest budget left more than \
             a tenth of it unspent, no more than 10 % under what that game spent: {}) in {could}.",
            sizes.join(", ")
        )
    };
    let honest = games.iter().filter(|g| g.predicted_within_10_percent()).count();
    let of_the_mean = games.iter().filter(|g| g.predicts_the_mean()).count();
    let median_honest = (games.iter())
        .filter_map(Game::median_over_predicted)
        .filter(|r| (r - 1.0).abs() <= 0.1)
        .count();
    let _ = write!(
        report,
        "\nKept in {kept} of {} games, and spent too (the mean frame also no more than 10 % under the budget) in {spent}; the frame predicted within 10 % of its prediction in {honest}. Of the \
         {of_the_mean} games whose prediction is of the mean, the median frame within 10 % of it in {median_honest}.{usable_words}\n",
        games.len()
    );
    let _ = write!(
        report,
        "\nThe machine's own spread: a fixed job of about each budget, reading and writing memory beyond the caches as a \
         frame does, timed {} times (as many as a game's frames), on as many cores as a game's loops run on: one below \
         {PARALLEL_MIN_CREATURES} creatures, every core of the compute pool in a crowd. Where its 99th percentile is over \
         1.25 times its median, no game on as many cores that spends the budget keeps its 99th percentile within 25 % of \
         it on this machine, whatever the policy.\n\n\
         | budget (ms) | cores | median (ms) | mean (ms) | 99th percentile (ms) | 99th percentile / median |\n\
         |---|---|---|---|---|---|\n",
        frames
    );
    for m in machine {
        let _ = writeln!(
            report,
            "| {} | {} | {:.2} | {:.2} | {:.2} | {:.2} |",
            m.budget_ms,
            m.threads,
            m.median_ms,
            m.mean_ms,
            m.p99_ms,
            m.p99_over_median()
        );
    }
    for model in measured {
        let _ = write!(
            report,
            "\nThe cost model measured before the games of {} creatures, in {:.1} s (us per creature per 1/30 s):\n\n",
            model.creatures, model.seconds
        );
        for line in &model.lines {
            let _ = writeln!(report, "- {line}");
        }
    }
    report
}
