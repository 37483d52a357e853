//! The budget experiment (beyond the paper): the budget policy against the paper's
//! fixed radii on figure 10's axes, and the frame times of a crowded game.
//!
//! 1. The trade-off: trials of a game from their own seeds, each all rigid, under the influence
//!    policy at each fixed puck radius (figure 10's rule), and under the budget policy at each
//!    frame budget; for each, the mean change in creatures that collided with the puck or a
//!    wall against all rigid, and three speed-ups: of the wall time on average (figure 10's); of
//!    the slowest frame as the cost model predicts it from the levels simulated (what a policy
//!    guarantees: the frame rate it holds is set by its slowest frame); and of the 99th
//!    percentile of the frames' measured wall times (figure 8's lowest frame rate, less the
//!    start-up frame and the machine's hiccups). Each budget is weighed against the radii at
//!    its speed-up twice: on figure 10's count, and on the error by obstacle (the change at the
//!    puck and at the walls, each without its sign, added), where errors of opposite sign at
//!    the two obstacles cannot cancel.
//! 2. The crowd: one game of many creatures under all rigid, the influence policy and the
//!    budget policy, every frame timed (can it hold 30 frames a second?).
//!
//! Over 600 lines: the trials, the crowd, their files and the report share the rows read and
//! written here; the comparison against the radii is in `compare.rs`.

mod compare;

use crate::error::LabError;
use compare::{Against, Axis, Comparison, Measure, against_fixed, mean_sd_se};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

use super::plot::{self, Mark, Panel, Series};
use super::{ExperimentRecord, Options, command, load_settings, p99_ms, run_parallel, timed_game, trials};
use simlod::config::{LevelRules, SimConfig, Validate, Validator, load_costs, load_file};
use simlod::lod::{LevelPolicy, Lod};
use simlod::outcome::{Counts, Obstacle};

/// `assets/experiments/budget.ron`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetSettings {
    /// The budget policy's settings: each a frame budget, as a target or as a ceiling.
    pub budgets: Vec<BudgetPoint>,
    /// The puck radii the fixed-radius curve runs at, under `fixed_rules`.
    pub radii_m: Vec<f32>,
    /// The level rules of the fixed-radius curve (figure 10's: the puck's area only).
    pub fixed_rules: String,
    /// The level rules of the budget policy (its weights; its cost model).
    pub budget_rules: String,
    /// Length of each trial.
    pub seconds: f32,
    /// Trials of the trade-off (each setting runs every trial); `--trials` overrides it.
    pub trials: u32,
    /// Trial `i` runs with seed `first_seed + i`.
    pub first_seed: u64,
    /// The crowded game: creatures (the scenario's mix, its court grown to the same density).
    pub crowd_creatures: u32,
    /// Length of the crowded game, s (each policy's game is this long).
    pub crowd_seconds: f32,
    /// The frame budget of the crowded game's budget policy.
    pub crowd_budget_ms: f32,
}

impl Validate for BudgetSettings {
    fn validate(&self, v: &mut Validator) {
        v.require(!self.budgets.is_empty(), "budgets", "must list at least one budget");
        for (i, b) in self.budgets.iter().enumerate() {
            v.range(
                &format!("budgets[{i}].frame_budget_ms"),
                b.frame_budget_ms,
                0.0,
                10_000.0,
            );
            v.range(
                &format!("budgets[{i}].least_benefit_per_ms"),
                b.least_benefit_per_ms,
                0.0,
                1e6,
            );
        }
        v.require(!self.radii_m.is_empty(), "radii_m", "must list at least one radius");
        for (i, r) in self.radii_m.iter().enumerate() {
            v.within(&format!("radii_m[{i}]"), *r, 0.0, 1e4);
        }
        v.asset_path("fixed_rules", &self.fixed_rules);
        v.asset_path("budget_rules", &self.budget_rules);
        v.within("seconds", self.seconds, 1.0 / 30.0, simlod::config::MAX_DURATION_S);
        v.require(self.trials >= 1, "trials", "must be at least 1");
        v.require(
            (1..=100_000).contains(&self.crowd_creatures),
            "crowd_creatures",
            format!("must be between 1 and 100000, got {}", self.crowd_creatures),
        );
        v.within("crowd_seconds", self.crowd_seconds, 1.0 / 30.0, 600.0);
        v.range("crowd_budget_ms", self.crowd_budget_ms, 0.0, 10_000.0);
    }
}

/// One setting of the budget policy: a frame budget (ms of simulation per 1/30 s), and the
/// least benefit per ms a level must bring to be bought (the budget rules'
/// `least_benefit_per_ms`): at 0 the budget is a target, spent whenever anything gains; above,
/// a ceiling, spent only where a contact is near, in bursts as a radius spends.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetPoint {
    /// The frame budget: ms of simulation per 1/30 s frame.
    pub frame_budget_ms: f32,
    /// The least benefit per ms a level must bring to be bought: 0 (the default) makes the budget
    /// a target, above 0 a ceiling.
    #[serde(default)]
    pub least_benefit_per_ms: f32,
}

/// One policy's setting in the trade-off: a fixed radius or a frame budget.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Setting {
    Radius(f32),
    Budget(BudgetPoint),
}

impl Setting {
    fn policy(self) -> &'static str {
        match self {
            Setting::Radius(_) => "influence",
            Setting::Budget(_) => "budget",
        }
    }

    /// The radius (m) or the frame budget (ms).
    fn value(self) -> f32 {
        match self {
            Setting::Radius(r) => r,
            Setting::Budget(b) => b.frame_budget_ms,
        }
    }

    fn least_benefit_per_ms(self) -> f32 {
        match self {
            Setting::Radius(_) => 0.0,
            Setting::Budget(b) => b.least_benefit_per_ms,
        }
    }

    /// As the report and the plot name it.
    fn label(self) -> String {
        match self {
            Setting::Radius(r) => format!("{r} m"),
            Setting::Budget(b) if b.least_benefit_per_ms > 0.0 => {
                format!("{} ms from {}/ms", b.frame_budget_ms, b.least_benefit_per_ms)
            }
            Setting::Budget(b) => format!("{} ms", b.frame_budget_ms),
        }
    }
}

const HEADER: &str = "policy,setting,least_benefit_per_ms,trial,seed,seconds,collided,collided_all_rigid,difference,puck,puck_all_rigid,wall,wall_all_rigid,mean_rigid,wall_s,wall_s_all_rigid,slowest_ms,slowest_ms_all_rigid,p99_ms,p99_ms_all_rigid";

/// One trial under one setting, beside the identical trial all rigid.
struct Row {
    setting: Setting,
    trial: u32,
    seed: u64,
    collided: u64,
    collided_all_rigid: u64,
    /// The same by obstacle: the creatures that hit the puck, a wall, another creature.
    collided_with: Counts<Obstacle, u64>,
    collided_with_all_rigid: Counts<Obstacle, u64>,
    mean_rigid: f64,
    wall_s: f64,
    wall_s_all_rigid: f64,
    /// The trial's slowest frame, as the cost model predicts it from the levels simulated.
    slowest_ms: f64,
    slowest_ms_all_rigid: f64,
    /// The 99th percentile of the trial's frames, measured.
    p99_ms: f64,
    p99_ms_all_rigid: f64,
}

impl Row {
    fn difference(&self) -> f64 {
        self.collided as f64 - self.collided_all_rigid as f64
    }

    /// The difference in the creatures that hit `obstacle`.
    fn difference_with(&self, obstacle: Obstacle) -> f64 {
        self.collided_with[obstacle] as f64 - self.collided_with_all_rigid[obstacle] as f64
    }
}

/// The two rules files, read from the assets folder with the budget rules' cost model.
struct Rules {
    fixed: LevelRules,
    budget: (LevelRules, simlod::config::CostModel),
}

fn run_trial(config: &SimConfig, rules: &Rules, s: &BudgetSettings, settings: &[Setting], trial: u32) -> Vec<Row> {
    let seed = s.first_seed + u64::from(trial);
    let seconds = f64::from(s.seconds);
    let mut c = config.clone();
    c.scenario.seed = seed;
    c.rules = rules.fixed.clone();
    c.scenario.level_policy = LevelPolicy::AllRigid;
    let rigid = timed_game(c.clone(), seconds);
    settings
        .iter()
        .map(|&setting| {
            match setting {
                Setting::Radius(r) => {
                    c.rules = rules.fixed.clone();
                    c.rules.influence.puck_radius_m = r;
                    c.scenario.level_policy = LevelPolicy::Influence;
                }
                Setting::Budget(b) => {
                    (c.rules, c.costs) = rules.budget.clone();
                    c.rules.budget.frame_budget_ms = b.frame_budget_ms;
                    c.rules.budget.least_benefit_per_ms = b.least_benefit_per_ms;
                    c.scenario.level_policy = LevelPolicy::Budget;
                }
            }
            let run = timed_game(c.clone(), seconds);
            Row {
                setting,
                trial,
                seed,
                collided: run.1.creatures_collided,
                collided_all_rigid: rigid.1.creatures_collided,
                collided_with: run.1.creatures_collided_with,
                collided_with_all_rigid: rigid.1.creatures_collided_with,
                mean_rigid: run.1.levels_mean[Lod::Rigid],
                wall_s: run.1.wall_seconds,
                wall_s_all_rigid: rigid.1.wall_seconds,
                slowest_ms: run.1.predicted_frame.slowest_ms,
                slowest_ms_all_rigid: rigid.1.predicted_frame.slowest_ms,
                p99_ms: p99_ms(&run.0),
                p99_ms_all_rigid: p99_ms(&rigid.0),
            }
        })
        .collect()
}

/// Figures per setting.
#[derive(Clone, Debug, Serialize)]
struct Point {
    #[serde(skip)]
    of: Setting,
    policy: &'static str,
    setting: f32,
    least_benefit_per_ms: f32,
    trials: usize,
    mean_difference: f64,
    /// The mean of each trial's difference, without its sign: how far a trial's outcome moves.
    mean_abs_difference: f64,
    sd_difference: f64,
    /// The standard error of the mean difference.
    se_difference: f64,
    /// The mean difference in the creatures that hit the puck, and in those that hit a wall,
    /// each with its standard error: whether the two cancel in `mean_difference`.
    puck_difference: (f64, f64),
    wall_difference: (f64, f64),
    mean_rigid: f64,
    /// All rigid's wall time over the policy's.
    speedup: f64,
    /// The trials' slowest frames as the cost model predicts them, on average, and all rigid's
    /// over it.
    slowest_ms: f64,
    slowest_speedup: f64,
    /// The trials' 99th-percentile frames, measured, on average, and all rigid's over it.
    p99_ms: f64,
    p99_speedup: f64,
}

fn summarise(rows: &[Row], settings: &[Setting]) -> Vec<Point> {
    settings
        .iter()
        .map(|&setting| {
            let at: Vec<&Row> = rows.iter().filter(|r| r.setting == setting).collect();
            let n = at.len() as f64;
            let mean = |f: &dyn Fn(&Row) -> f64| at.iter().map(|r| f(r)).sum::<f64>() / n;
            let (mean_difference, sd_difference, se_difference) =
                mean_sd_se(&at.iter().map(|r| r.difference()).collect::<Vec<_>>());
            let with = |o: Obstacle| {
                let (mean, _, se) = mean_sd_se(&at.iter().map(|r| r.difference_with(o)).collect::<Vec<_>>());
                (mean, se)
            };
            Point {
                of: setting,
                policy: setting.policy(),
                setting: setting.value(),
                least_benefit_per_ms: setting.least_benefit_per_ms(),
                trials: at.len(),
                mean_difference,
                mean_abs_difference: mean(&|r| r.difference().abs()),
                sd_difference,
                se_difference,
                puck_difference: with(Obstacle::Puck),
                wall_difference: with(Obstacle::Wall),
                mean_rigid: mean(&|r| r.mean_rigid),
                speedup: at.iter().map(|r| r.wall_s_all_rigid).sum::<f64>() / at.iter().map(|r| r.wall_s).sum::<f64>(),
                slowest_ms: mean(&|r| r.slowest_ms),
                slowest_speedup: mean(&|r| r.slowest_ms_all_rigid) / mean(&|r| r.slowest_ms),
                p99_ms: mean(&|r| r.p99_ms),
                p99_speedup: mean(&|r| r.p99_ms_all_rigid) / mean(&|r| r.p99_ms),
            }
        })
        .collect()
}

/// The crowded game under one policy: each frame's wall time.
#[derive(Clone, Debug, Serialize)]
struct Crowd {
    policy: &'static str,
    #[serde(skip)]
    level_policy: LevelPolicy,
    frames: usize,
    median_frame_ms: f64,
    slowest_frame_ms: f64,
    lowest_fps: f64,
    mean_rigid: f64,
    #[serde(skip)]
    frame_ms: Vec<f64>,
}

fn crowd(config: &SimConfig, rules: &Rules, s: &BudgetSettings) -> Vec<Crowd> {
    let mut base = crate::bench::scaled(config, s.crowd_creatures, LevelPolicy::AllRigid);
    base.scenario.seed = s.first_seed;
    [
        ("all-rigid", LevelPolicy::AllRigid),
        ("influence", LevelPolicy::Influence),
        ("budget", LevelPolicy::Budget),
    ]
    .into_iter()
    .map(|(name, policy)| {
        let mut c = base.clone();
        (c.rules, c.costs) = rules.budget.clone();
        c.rules.budget.frame_budget_ms = s.crowd_budget_ms;
        c.scenario.level_policy = policy;
        let (frames, summary) = timed_game(c, f64::from(s.crowd_seconds));
        let frame_ms: Vec<f64> = frames.iter().map(|f| f * 1e3).collect();
        let slowest = frame_ms.iter().copied().fold(0.0, f64::max);
        eprintln!("budget: the crowd of {} under {name}: done", s.crowd_creatures);
        Crowd {
            policy: name,
            level_policy: policy,
            frames: frame_ms.len(),
            median_frame_ms: super::median_of(frame_ms.iter().copied()),
            slowest_frame_ms: slowest,
            lowest_fps: 1e3 / slowest,
            mean_rigid: summary.levels_mean[Lod::Rigid],
            frame_ms,
        }
    })
    .collect()
}

/// Runs the budget experiment from `file`: the trade-off trials on `--jobs` threads, then the
/// crowded game; writes its CSV, plot, JSON and report and returns what it says.
pub fn run(config: &SimConfig, file: &Path, options: &Options) -> Result<String, LabError> {
    let s: BudgetSettings = load_settings(file, options)?;
    let s = BudgetSettings {
        trials: trials(options, s.trials),
        ..s
    };
    let read = |field: &str, name: &str| -> Result<LevelRules, LabError> {
        load_file(&options.assets.join(name))
            .map_err(|e| LabError::Invalid(format!("{e} (named by {}: field `{field}`)", file.display())))
    };
    let budget_rules = read("budget_rules", &s.budget_rules)?;
    let costs = load_costs(&options.assets, &options.assets.join(&s.budget_rules), &budget_rules)?;
    let rules = Rules {
        fixed: read("fixed_rules", &s.fixed_rules)?,
        budget: (budget_rules, costs),
    };
    let settings: Vec<Setting> = s
        .radii_m
        .iter()
        .map(|&r| Setting::Radius(r))
        .chain(s.budgets.iter().map(|&b| Setting::Budget(b)))
        .collect();
    let todo: Vec<u32> = (0..s.trials).collect();
    let mut rows = Vec::new();
    let mut progress = super::Progress::new("budget trials", todo.len() as u64);
    run_parallel(
        &todo,
        options.jobs,
        |&t| run_trial(config, &rules, &s, &settings, t),
        |_, r| {
            rows.extend(r);
            progress.inc();
        },
    );
    drop(progress);
    rows.sort_by_key(|r| r.trial);
    let points = summarise(&rows, &settings);
    let crowd = crowd(config, &rules, &s);
    finish(&rows, &points, &crowd, &s, options)
}

fn finish(
    rows: &[Row],
    points: &[Point],
    crowd: &[Crowd],
    s: &BudgetSettings,
    options: &Options,
) -> Result<String, LabError> {
    let out = &options.out;
    let mut csv = format!("{HEADER}\n");
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{:.3},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
            r.setting.policy(),
            r.setting.value(),
            r.setting.least_benefit_per_ms(),
            r.trial,
            r.seed,
            s.seconds,
            r.collided,
            r.collided_all_rigid,
            r.difference(),
            r.collided_with[Obstacle::Puck],
            r.collided_with_all_rigid[Obstacle::Puck],
            r.collided_with[Obstacle::Wall],
            r.collided_with_all_rigid[Obstacle::Wall],
            r.mean_rigid,
            r.wall_s,
            r.wall_s_all_rigid,
            r.slowest_ms,
            r.slowest_ms_all_rigid,
            r.p99_ms,
            r.p99_ms_all_rigid
        );
    }
    let curve = |policy: &str| -> Vec<&Point> { points.iter().filter(|p| p.policy == policy).collect() };
    let (fixed, budget) = (curve("influence"), curve("budget"));
    let against = Axis::ALL.map(|axis| (axis, against_fixed(rows, &fixed, &budget, axis)));
    let (ceilings, targets): (Vec<&Point>, Vec<&Point>) = budget.iter().partition(|p| p.least_benefit_per_ms > 0.0);
    let trade_off = |(axis, measure): (Axis, Measure)| {
        let (title, y_label) = axis.panel();
        // Along the speed-up, so that a curve does not zigzag back on itself.
        let trade = |ps: &[&Point]| {
            let mut ps = ps.to_vec();
            ps.sort_by(|a, b| axis.of(a).total_cmp(&axis.of(b)));
            Series {
                x_errors: Some(ps.iter().map(|p| measure.standard_error(p)).collect()),
                ..Series::new(
                    "",
                    ps.iter().map(|p| (measure.of(p), axis.of(p))).collect(),
                    Mark::Line,
                    0,
                )
            }
        };
        let notes = fixed
            .iter()
            .chain(&budget)
            .map(|p| (measure.of(p), axis.of(p), p.of.label()))
            .collect();
        let by = if measure == Measure::ByObstacle {
            "by obstacle, "
        } else {
            ""
        };
        Panel {
            title: format!("{by}{title}: {} trials of {} s, bars +- 1 s.e.", s.trials, s.seconds),
            x_label: measure.x_label().into(),
            y_label: y_label.into(),
            series: [
                (
                    "fixed puck radius (figure 10's rule)",
                    &fixed,
                    plot::policy_colour(LevelPolicy::Influence),
                ),
                (
                    "budget policy, the budget a target",
                    &targets,
                    plot::policy_colour(LevelPolicy::Budget),
                ),
                (
                    "budget policy, a ceiling: bought from a least benefit per ms",
                    &ceilings,
                    plot::BUDGET_CEILING,
                ),
            ]
            .into_iter()
            .filter(|(_, ps, _)| !ps.is_empty())
            .map(|(label, ps, colour)| Series {
                label: label.into(),
                colour,
                ..trade(ps)
            })
            .collect(),
            notes,
            ..Panel::default()
        }
    };
    let mut trace_series = Vec::new();
    for c in crowd {
        let points = c
            .frame_ms
            .iter()
            .enumerate()
            .map(|(f, &ms)| (f as f64 / 30.0, ms))
            .collect();
        trace_series.push(Series::new(
            format!("{} (slowest {:.0} ms)", c.policy, c.slowest_frame_ms),
            points,
            Mark::Line,
            plot::policy_colour(c.level_policy),
        ));
    }
    let frames = crowd.first().map_or(0, |c| c.frames);
    trace_series.push(Series::new(
        "1/30 s: 30 fps",
        vec![(0.0, 1e3 / 30.0), (frames as f64 / 30.0, 1e3 / 30.0)],
        Mark::Dashed,
        plot::REFERENCE,
    ));
    // Each figure stands alone, at a size that reads at a page's width.
    let (width, height) = (1000, 650);
    let mut figures: Vec<(&str, Panel)> = Axis::ALL
        .into_iter()
        .map(|axis| (axis.figure(), trade_off((axis, Measure::Count))))
        .collect();
    figures.push(("budget-by-obstacle.png", trade_off((Axis::Mean, Measure::ByObstacle))));
    figures.push((
        "budget-crowd.png",
        Panel {
            title: format!("frame times of a game of {} creatures", s.crowd_creatures),
            x_label: "simulated time (s)".into(),
            y_label: "wall time of the frame's simulation (ms)".into(),
            log_y: true,
            series: trace_series,
            ..Panel::default()
        },
    ));
    for (file, panel) in &figures {
        plot::draw(
            &out.join(file),
            width,
            height,
            std::slice::from_ref(panel),
            options.quick,
        )?;
    }
    let mut report = format!(
        "The budget policy (beyond the paper) against figure 10's fixed radii: {} trials of {} s from seeds {} on, each beside the identical \
         trial all rigid; the fixed radii under `{}` with the influence policy, the budgets under `{}` (its weights and cost model). \
         The difference is the policy's creatures that collided with the puck or a wall minus all rigid's; \
         the difference without its sign is averaged too, and the difference is split by obstacle (the creatures that hit the puck, those that hit a wall; \
         one that hit both counts in each): two errors of opposite sign cancel in the difference; the speed-up the all-rigid trials' wall time over the policy's (trials ran in parallel, `--jobs`); \
         the slowest frame each trial's slowest as the cost model predicts it from the levels simulated (the court's fixed cost and each creature's level), \
         and its speed-up all rigid's over the policy's: the frame rate a policy holds is set by its slowest frame; \
         the 99th-percentile frame each trial's measured wall times' (all but its slowest hundredth of frames, 6 of a 20 s trial's 600: the first, which builds the world, and the machine's hiccups), \
         and its speed-up likewise.\n\n\
         | policy | setting | difference: mean +- s.e. | difference without sign: mean | s.d. | hit the puck: difference | hit a wall: difference | rigid creatures (mean) | speed-up | slowest frame (ms, cost model) | its speed-up | 99th-percentile frame (ms, measured) | its speed-up |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        s.trials, s.seconds, s.first_seed, s.fixed_rules, s.budget_rules
    );
    for p in points {
        let _ = writeln!(
            report,
            "| {} | {} | {:+.2} +- {:.2} | {:.2} | {:.2} | {:+.2} +- {:.2} | {:+.2} +- {:.2} | {:.1} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
            p.policy,
            p.of.label(),
            p.mean_difference,
            p.se_difference,
            p.mean_abs_difference,
            p.sd_difference,
            p.puck_difference.0,
            p.puck_difference.1,
            p.wall_difference.0,
            p.wall_difference.1,
            p.mean_rigid,
            p.speedup,
            p.slowest_ms,
            p.slowest_speedup,
            p.p99_ms,
            p.p99_speedup
        );
    }
    let _ = write!(
        report,
        "\nEach budget against the fixed radii at the same speed-up (their curve interpolated in log speed-up; a budget faster \
         than every radius against the fastest radius, which is slower; one slower than every radius left out). Nearer zero is nearer all rigid's outcome. The gap is how much nearer the budget's \
         is, taken trial by trial: each trial's budget game against its fixed-radius games, so that the all-rigid game's chance \
         cancels where both differences have the same sign. Each on figure 10's count, and by obstacle: the change at the puck \
         and at the walls each without its sign, added (each part of a trial's change taken with the sign of its mean), \
         where two errors of opposite sign do not cancel. First at the same speed-up on average (figure 10's), then at the \
         same speed-up of the slowest frame (the frame rate guaranteed), then of the 99th-percentile frame measured.\n"
    );
    for (axis, against) in &against {
        against_table(&mut report, axis.name(), against);
    }
    let _ = write!(
        report,
        "\nThe trade-off by obstacle, and at the frame rate guaranteed and the frame rate held:\n\n\
         ![by obstacle](budget-by-obstacle.png)\n\n![slowest frame](budget-slowest.png)\n\n![99th-percentile frame](budget-p99.png)\n"
    );
    let _ = write!(
        report,
        "\nThe crowd: one game of {} creatures (the scenario's mix, the court grown to its density), {} s, seed {}, the budget policy at {} ms; \
         every frame's simulation timed, one process, one policy after the other.\n\n\
         | policy | frames | median frame (ms) | slowest frame (ms) | lowest fps | rigid creatures (mean) |\n|---|---|---|---|---|---|\n",
        s.crowd_creatures, s.crowd_seconds, s.first_seed, s.crowd_budget_ms
    );
    for c in crowd {
        let _ = writeln!(
            report,
            "| {} | {} | {:.2} | {:.2} | {:.1} | {:.1} |",
            c.policy, c.frames, c.median_frame_ms, c.slowest_frame_ms, c.lowest_fps, c.mean_rigid
        );
    }
    let _ = write!(report, "\n![the crowd's frames](budget-crowd.png)\n");
    let record = ExperimentRecord {
        experiment: "budget".into(),
        command: command("budget", options),
        summary: {
            let mut summary = serde_json::json!({ "points": points, "crowd": crowd });
            for (axis, against) in &against {
                summary[axis.key()] = serde_json::json!(against);
            }
            summary
        },
        report,
        smoke_test: options.quick,
    };
    super::write_out(out, "budget.csv", &csv)?;
    let mut files = vec!["budget.csv"];
    files.extend(figures.iter().map(|(file, _)| *file));
    record.save(out, &files)
}

/// A table of the budgets against the fixed radii at the same `axis`.
fn against_table(report: &mut String, axis: &str, against: &[Against]) {
    let _ = write!(
        report,
        "\n| budget | {axis} | difference +- s.e. | fixed radii at that {axis} | gap +- s.e. (trial by trial) | nearer all rigid by over 2 s.e. \
         | by obstacle: budget | fixed radii | gap +- s.e. | nearer by over 2 s.e. |\n|---|---|---|---|---|---|---|---|---|---|\n"
    );
    let yes = |c: &Comparison| if c.nearer_beyond_2_se { "yes" } else { "no" };
    for a in against {
        let (c, o) = (&a.count, &a.by_obstacle);
        let _ = writeln!(
            report,
            "| {} | {:.2} | {:+.2} +- {:.2} | {:+.2} +- {:.2}{} | {:+.2} +- {:.2} | {} | {:.2} +- {:.2} | {:.2} +- {:.2} | {:+.2} +- {:.2} | {} |",
            a.label,
            a.speedup,
            c.difference,
            c.se_difference,
            c.fixed_difference,
            c.fixed_se_difference,
            if a.beyond_fastest_radius {
                " (the fastest radius, slower)"
            } else {
                ""
            },
            c.gap,
            c.se_gap,
            yes(c),
            o.difference,
            o.se_difference,
            o.fixed_difference,
            o.fixed_se_difference,
            o.gap,
            o.se_gap,
            yes(o)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Trials whose all-rigid games collide 0, 10, 0, 10 times; the game at `setting` collides
    /// `collided` each time, its wall time over all rigid's 8 s giving the speed-up, and its
    /// slowest frame over all rigid's 8 ms giving the slowest frame's, `slowdown` times it.
    fn trials(setting: Setting, collided: u64, wall_s: f64, slowdown: f64) -> Vec<Row> {
        (0..4)
            .map(|trial| Row {
                setting,
                trial,
                seed: u64::from(trial),
                collided,
                collided_all_rigid: 10 * u64::from(trial % 2),
                collided_with: Counts::from_fn(|o| if o == Obstacle::Wall { collided } else { 0 }),
                collided_with_all_rigid: Counts::default(),
                mean_rigid: 0.0,
                wall_s,
                wall_s_all_rigid: 8.0,
                slowest_ms: wall_s * slowdown,
                slowest_ms_all_rigid: 8.0,
                p99_ms: wall_s,
                p99_ms_all_rigid: 8.0,
            })
            .collect()
    }

    #[test]
    fn a_budget_is_weighed_against_the_fixed_radii_at_its_speedup_trial_by_trial() {
        let budget = |frame_budget_ms, least_benefit_per_ms| {
            Setting::Budget(BudgetPoint {
                frame_budget_ms,
                least_benefit_per_ms,
            })
        };
        let settings = [
            Setting::Radius(8.0),
            Setting::Radius(0.0),
            budget(1.0, 0.0),
            budget(2.0, 0.0),
            budget(0.5, 0.0),
            budget(4.0, 3.0),
        ];
        // Speed-ups 2 and 8; the budgets at 4 (halfway in log speed-up), 4, 16 (past the
        // fastest radius) and 1 (slower than every radius). Of the slowest frame: 1 and 4; the
        // budgets at 4 (the curve's end), 4, 2 (the third one's slowest frame dear) and 0.5.
        let rows: Vec<Row> = [
            (2, 4.0, 2.0),
            (2, 1.0, 2.0),
            (3, 2.0, 1.0),
            (14, 2.0, 1.0),
            (3, 0.5, 8.0),
            (5, 8.0, 2.0),
        ]
        .into_iter()
        .zip(settings)
        .flat_map(|((collided, wall_s, slowdown), setting)| trials(setting, collided, wall_s, slowdown))
        .collect();
        let points = summarise(&rows, &settings);
        // By obstacle: here every collided creature hit a wall and none the puck.
        assert_eq!(
            (points[0].wall_difference.0, points[0].puck_difference),
            (2.0, (0.0, 0.0))
        );
        let [fixed, budget] =
            ["influence", "budget"].map(|p| points.iter().filter(|q| q.policy == p).collect::<Vec<_>>());
        let against = against_fixed(&rows, &fixed, &budget, Axis::Mean);
        let labels: Vec<&str> = against.iter().map(|a| a.label.as_str()).collect();
        assert_eq!(labels, ["1 ms", "2 ms", "0.5 ms"], "{against:?}");
        // Differences of -3 and -2 on average, each with a standard error of 2.9 from the
        // all-rigid games alone; trial by trial the budget is 1 nearer every time.
        let (one_ms, two_ms) = (&against[0], &against[1]);
        assert!((one_ms.count.fixed_difference + 3.0).abs() < 1e-9, "{one_ms:?}");
        assert!((one_ms.count.difference + 2.0).abs() < 1e-9);
        assert!(one_ms.count.se_difference > 2.0);
        assert!((one_ms.count.gap - 1.0).abs() < 1e-9 && one_ms.count.se_gap < 1e-9);
        assert!(one_ms.count.nearer_beyond_2_se);
        // +9 against -3: farther.
        assert!((two_ms.count.gap + 6.0).abs() < 1e-9, "{two_ms:?}");
        assert!(!two_ms.count.nearer_beyond_2_se && !two_ms.beyond_fastest_radius);
        // Faster than every radius, against the fastest (0 m, -3): 1 nearer every time.
        let fastest = &against[2];
        assert!(fastest.beyond_fastest_radius && (fastest.count.fixed_difference + 3.0).abs() < 1e-9);
        assert!(
            (fastest.count.gap - 1.0).abs() < 1e-9 && fastest.count.nearer_beyond_2_se,
            "{fastest:?}"
        );
        // Of the slowest frame, the half-millisecond budget falls within the curve too.
        let slowest = against_fixed(&rows, &fixed, &budget, Axis::Slowest);
        let budgets: Vec<f32> = slowest.iter().map(|a| a.budget_ms).collect();
        assert_eq!(budgets, [1.0, 2.0, 0.5]);
        assert!((slowest[2].speedup - 2.0).abs() < 1e-6 && (slowest[2].count.gap - 1.0).abs() < 1e-9);
        // The 99th-percentile frames here are the wall times: the same as on average.
        let p99 = against_fixed(&rows, &fixed, &budget, Axis::P99);
        assert_eq!(format!("{p99:?}"), format!("{against:?}"));
        assert_eq!(settings[5].label(), "4 ms from 3/ms");
    }

    #[test]
    fn errors_of_opposite_sign_cancel_in_the_count_but_not_by_obstacle() {
        let budget = Setting::Budget(BudgetPoint {
            frame_budget_ms: 1.0,
            least_benefit_per_ms: 0.0,
        });
        let settings = [Setting::Radius(8.0), Setting::Radius(0.0), budget];
        // All rigid: one creature hits the puck and another a wall in every trial. The radii
        // do the same (speed-ups 2 and 8); the budget (4) puts both on the puck, or on a wall
        // in one trial of four.
        let rows: Vec<Row> = settings
            .iter()
            .zip([4.0, 1.0, 2.0])
            .flat_map(|(&setting, wall_s)| trials(setting, 2, wall_s, 1.0))
            .map(|r| {
                let on_puck = if r.setting == budget {
                    2 - 2 * u64::from(r.trial == 3)
                } else {
                    1
                };
                Row {
                    collided_all_rigid: 2,
                    collided_with: Counts::from_fn(|o| match o {
                        Obstacle::Puck => on_puck,
                        Obstacle::Wall => 2 - on_puck,
                        Obstacle::Creature => 0,
                    }),
                    collided_with_all_rigid: Counts::from_fn(|o| u64::from(o != Obstacle::Creature)),
                    ..r
                }
            })
            .collect();
        let points = summarise(&rows, &settings);
        let [fixed, budgets] =
            ["influence", "budget"].map(|p| points.iter().filter(|q| q.policy == p).collect::<Vec<_>>());
        let a = &against_fixed(&rows, &fixed, &budgets, Axis::Mean)[0];
        // The count: no change on either side, no gap.
        assert_eq!(
            (a.count.difference, a.count.fixed_difference, a.count.gap),
            (0.0, 0.0, 0.0)
        );
        // By obstacle: +0.5 at the puck, -0.5 at the walls on average. Taken with the means'
        // signs a trial's error is (+1) - (-1) = 2 three times and (-1) - (+1) = -2 once: 1 on
        // average, against the radii's 0.
        assert!((Measure::ByObstacle.of(&points[2]) - 1.0).abs() < 1e-9);
        let o = &a.by_obstacle;
        assert!((o.difference - 1.0).abs() < 1e-9 && o.fixed_difference == 0.0, "{o:?}");
        assert!((o.gap + 1.0).abs() < 1e-9 && !o.nearer_beyond_2_se, "{o:?}");
    }

    #[test]
    fn the_99th_percentile_frame_leaves_out_the_slowest_hundredth() {
        // 600 frames of 1 to 600 ms, shuffled: the six slowest are left out.
        let frames: Vec<f64> = (1..=600).map(|i| f64::from((i * 7) % 601) * 1e-3).collect();
        assert!((p99_ms(&frames) - 594.0).abs() < 1e-9, "{}", p99_ms(&frames));
        assert_eq!(p99_ms(&[]), 0.0);
    }
}
