//! The `run` command: a scenario simulated without a window, and its summary.

use crate::Failure;
use clap::Args;
use std::path::PathBuf;

use crate::scenario::*;
use simlod::config::{MAX_DURATION_S, MeasuredAnew, SimConfig};
use simlod::headless;
use simlod::outcome::{Counts, Key, Summary};
use simlod_lab::bench::calibrate_at_start_up;

#[derive(Args)]
pub(crate) struct RunArgs {
    #[command(flatten)]
    pub(crate) scenario: ScenarioArgs,
    /// Simulated seconds (default: the scenario's duration).
    #[arg(long, allow_negative_numbers = true, value_parser = positive_seconds)]
    pub(crate) seconds: Option<f64>,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub(crate) json: bool,
    /// Measure the budget policy's cost model on this machine, in this run's crowd, before
    /// the run (a second or two, up to about 5 s for 100,000 creatures, as the game does at
    /// start-up), in place of the rules' file. The run's choices then depend on the machine:
    /// not reproducible.
    #[arg(long)]
    pub(crate) calibrate: bool,
    /// The budget policy's adaptive mode: its cost model corrected by the frames measured,
    /// over about this many (1 to 10000). It reads the clock: not reproducible.
    #[arg(long, allow_negative_numbers = true, value_parser = adaptive_frames)]
    pub(crate) adaptive: Option<f32>,
    /// With `--adaptive`, keep this percentile of the last frames within the budget, not their
    /// mean (50 to 100; 99: the fourth slowest of the last 300).
    #[arg(long, requires = "adaptive", allow_negative_numbers = true, value_parser = adaptive_percentile)]
    pub(crate) adaptive_percentile: Option<f32>,
    /// With `--adaptive-percentile`, how many times the budget that percentile is kept within,
    /// the mean within the budget itself (1 to 10; 1 without it: the budget).
    #[arg(long, requires = "adaptive_percentile", allow_negative_numbers = true, value_parser = adaptive_percentile_limit)]
    pub(crate) adaptive_percentile_limit: Option<f32>,
}

fn adaptive_frames(s: &str) -> Result<f32, String> {
    let v = up_to_ten_thousand(s, "frames")?;
    if v >= 1.0 {
        Ok(v)
    } else {
        Err(format!("must be between 1 and 10000 frames, got {v}"))
    }
}

fn adaptive_percentile(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("not a number: {s:?}"))?;
    if (50.0..=100.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be between 50 and 100, got {v}"))
    }
}

fn adaptive_percentile_limit(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("not a number: {s:?}"))?;
    if (1.0..=10.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be between 1 and 10 times the budget, got {v}"))
    }
}

impl RunArgs {
    /// Simulates the scenario and prints what happened. A flag the run's policy never reads is
    /// refused rather than ignored.
    pub(crate) fn run(&self) -> Result<(), Failure> {
        let mut config = self.scenario.load_measuring(MeasuredAnew {
            cost_model: self.calibrate,
            ..MeasuredAnew::default()
        })?;
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
            ("--adaptive", self.adaptive.is_some() && !policy.uses_frame_budget()),
        ];
        if let Some((flag, _)) = unread.iter().find(|(_, unread)| *unread) {
            return Err(Failure::from(format!(
                "{flag} does not apply to the {} policy, which never reads it (choose a policy that does with --policy)",
                policy.name()
            )));
        }
        if let Some(frames) = self.adaptive {
            config.rules.budget.adaptive_frames = frames;
            config.rules.budget.adaptive_percentile = self.adaptive_percentile.unwrap_or(0.0);
            config.rules.budget.adaptive_percentile_limit = self.adaptive_percentile_limit.unwrap_or(1.0);
        }
        let mut ran = self.scenario.what_ran(&config);
        if self.calibrate {
            config.costs = measure_costs(&config);
            ran.cost_model = MEASURED_BEFORE_THE_RUN.to_owned();
        }
        let seconds = self.seconds.unwrap_or(f64::from(config.scenario.duration_s));
        let summary = headless::run(config.clone(), seconds);
        if self.json {
            let mut json = serde_json::to_value(&summary).expect("a summary serialises");
            json["policy"] = ran.policy.into();
            json["rules"] = ran.rules.display().to_string().into();
            json["cost_model"] = ran.cost_model.into();
            simlod_lab::experiments::shortest_floats(&mut json);
            println!("{json}");
        } else {
            print_summary(self, &summary, &config, &ran);
        }
        Ok(())
    }
}

/// What a run ran under: its level policy, as the command line names it, the file of its level
/// rules, and its cost model's (or [`MEASURED_BEFORE_THE_RUN`]).
pub(crate) struct WhatRan {
    pub(crate) policy: String,
    pub(crate) rules: PathBuf,
    pub(crate) cost_model: String,
}

/// How far the median frame may run from the cost model's prediction, either way, before the
/// summary says the model is not this machine's.
const STALE_MODEL: f64 = 1.25;

/// The cost model of a run with `--calibrate`, as its summary names it.
const MEASURED_BEFORE_THE_RUN: &str = "measured on this machine before the run, not reproducible";

/// The cost model measured on this machine in the run's crowd, as the game measures it at
/// start-up; what it says goes to stderr, so that `--json` stays one object on stdout.
fn measure_costs(config: &SimConfig) -> simlod::config::CostModel {
    eprintln!("measuring the budget policy's cost model on this machine, in this run's crowd (--calibrate)");
    let (model, said) = calibrate_at_start_up(config);
    eprintln!("{said}");
    model
}

pub(crate) fn positive_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("not a number: {s:?}"))?;
    if v.is_finite() && v > 0.0 && v <= f64::from(MAX_DURATION_S) {
        Ok(v)
    } else {
        Err(format!(
            "must be more than 0 and at most {MAX_DURATION_S} seconds, got {v}"
        ))
    }
}

pub(crate) fn print_summary(args: &RunArgs, s: &Summary, config: &SimConfig, ran: &WhatRan) {
    pub(crate) fn join<K: Key, T: std::fmt::Display + Copy>(counts: &Counts<K, T>) -> String {
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
        ran.cost_model
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
    if let Some(m) = &s.measured_frame {
        println!(
            "frame as measured (the wall time of each of its {} frames): {:.2} ms on average, {:.2} ms the median, {:.2} ms at the 99th percentile, {:.2} ms at the slowest",
            m.frames, m.mean_ms, m.median_ms, m.p99_ms, m.slowest_ms
        );
        let off = m.median_ms / s.predicted_frame.mean_ms.max(1e-9);
        if !(1.0 / STALE_MODEL..=STALE_MODEL).contains(&off) && ran.cost_model != MEASURED_BEFORE_THE_RUN {
            println!(
                "  the median frame ran {off:.2} times the cost model's prediction: the model was measured on another machine or day; --calibrate measures it on this one before the run, and `simlod bench --calibrate` writes it to {}",
                ran.cost_model
            );
        }
    }
    let switches: Vec<String> = s
        .switches
        .directions()
        .map(|(from, to, n)| format!("{}->{} {n}", from.name(), to.name()))
        .chain([format!("total {}", s.switches.total())])
        .collect();
    println!("level switches: {}", switches.join(", "));
    if s.switches_unseen > 0 {
        println!(
            "  {} of them off screen: not drawn, so neither blended nor measured for their pops",
            s.switches_unseen
        );
    }
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
            let keeps = match b.adaptive_percentile {
                0.0 => String::new(),
                p => format!(
                    " keeping the {p}th percentile of the last {} frames within {} and the mean within the budget",
                    simlod::lod::percentile_window(config.rules.budget.adaptive_frames, p),
                    match config.rules.budget.adaptive_percentile_limit {
                        1.0 => "it".to_owned(),
                        limit => format!("{limit} times it"),
                    }
                ),
            };
            format!(
                " (adaptive{keeps}, not reproducible: the cost model corrected x {:.2} at the end)",
                b.correction
            )
        } else {
            String::new()
        };
        // The wall clock, read outside the simulation: what the prediction is measured against.
        let (mean_ms, p99_ms) = s.measured_frame.map_or((0.0, 0.0), |m| (m.mean_ms, m.p99_ms));
        let against = |measured_ms: f64| {
            if measured_ms > f64::from(b.frame_budget_ms) {
                format!(
                    "{:.0} % over the budget",
                    (measured_ms / f64::from(b.frame_budget_ms).max(1e-9) - 1.0) * 100.0
                )
            } else {
                "within the budget".to_owned()
            }
        };
        println!(
            "frame budget {} ms of simulation per 1/30 s: as the policy chose, predicted {:.3} ms on average and {:.3} ms at most, {chosen}{adaptive}; {:.1} creatures searched for contacts a decision, {:.0} left quiet; measured {mean_ms:.3} ms of wall time on average, {}, and {p99_ms:.3} ms at the 99th percentile, {}",
            b.frame_budget_ms,
            b.predicted_ms_mean,
            b.predicted_ms_max,
            b.searched_per_decision,
            b.quiet_per_decision,
            against(mean_ms),
            against(p99_ms)
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
