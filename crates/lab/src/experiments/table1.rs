//! Table 1: the cost of one creature for 1/30 s of motion at each level. Measured as the
//! paper does, the model and its low-level control alone (no steering, no collisions, no
//! rendering: every creature runs at a set speed in its own direction), and, in a second
//! column, the whole per-creature cost of a game (steering, level rules and collisions).

use crate::error::LabError;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

use super::plot::{self, Mark, Panel, Series};
use super::{ExperimentRecord, Options, check_kind, command, hold_levels, load_settings, median_of, only_kind, trials};
use crate::bench::{median_frame_seconds, median_frame_seconds_of, scaled};
use simlod::SimStage;
use simlod::config::{SimConfig, Validate, Validator};
use simlod::creature::KindTable;
use simlod::creature::{DesiredVelocity, PlanarState};
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelPolicy, Lod};

/// The paper's Table 1 (SGI R10000): ms per creature per 1/30 s, point mass, hybrid, rigid.
pub const PAPER_MS: [f64; 3] = [0.0025, 0.024, 2.4];

/// `assets/experiments/table1.ron` (its `full` and `quick` sections).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Table1Settings {
    /// The creature kinds measured, each at every level it has.
    pub kinds: Vec<String>,
    /// Creatures in the measured world, at each level: point mass, hybrid, rigid.
    pub creatures: (u32, u32, u32),
    /// Speed every creature runs at while its model alone is measured.
    pub model_speed_m_per_s: f32,
    /// Frames run before timing starts, in each run.
    pub warmup_frames: u32,
    /// Frames timed per run; a run's figure is its median frame.
    pub frames: u32,
    /// Fresh runs per level and measure; the table has their median.
    pub trials: u32,
}

impl Validate for Table1Settings {
    fn validate(&self, v: &mut Validator) {
        v.require(!self.kinds.is_empty(), "kinds", "must name at least one creature kind");
        for (i, kind) in self.kinds.iter().enumerate() {
            v.require(!kind.is_empty(), &format!("kinds[{i}]"), "must name a creature kind");
        }
        for (i, n) in [self.creatures.0, self.creatures.1, self.creatures.2]
            .into_iter()
            .enumerate()
        {
            v.require(
                (1..=100_000).contains(&n),
                &format!("creatures.{i}"),
                format!("must be between 1 and 100000, got {n}"),
            );
        }
        v.within("model_speed_m_per_s", self.model_speed_m_per_s, 0.0, 10.0);
        v.require(self.frames >= 1, "frames", "must be at least 1");
        v.require(self.trials >= 1, "trials", "must be at least 1");
    }
}

const LEVELS: [(Lod, LevelPolicy); 3] = [
    (Lod::PointMass, LevelPolicy::AllPointMass),
    (Lod::Hybrid, LevelPolicy::AllHybrid),
    (Lod::Rigid, LevelPolicy::AllRigid),
];

/// Median frame of the models alone: levels held, no sensing, steering or collisions;
/// every creature runs at `speed` the way it faces.
fn model_frame_seconds(config: SimConfig, speed: f32, warmup: usize, frames: usize) -> f64 {
    let mut sim = HeadlessSim::new(config);
    hold_levels(&mut sim, &[SimStage::Sense, SimStage::Steer, SimStage::Observe]);
    let world = sim.app.world_mut();
    for (state, mut desired) in world.query::<(&PlanarState, &mut DesiredVelocity)>().iter_mut(world) {
        desired.0 = state.heading * speed;
    }
    median_frame_seconds_of(&mut sim, warmup, frames)
}

/// ms per creature per frame, model alone and game, at each level of `LEVELS`; `None` where
/// the kind has no such level.
type KindCosts = [Option<[f64; 2]>; 3];

/// Runs table 1 from `file`: ms per creature per 1/30 s at each level, model alone and in the
/// game; writes its CSV, plot, JSON and report and returns what it says.
pub fn run(config: &SimConfig, file: &Path, options: &Options) -> Result<String, LabError> {
    let s: Table1Settings = load_settings(file, options)?;
    for (i, kind) in s.kinds.iter().enumerate() {
        check_kind(config, file, &format!("kinds[{i}]"), kind, &[])?;
    }
    let kinds = KindTable::of(config);
    let n_trials = trials(options, s.trials);
    let (warmup, frames) = (s.warmup_frames as usize, s.frames as usize);
    let counts = [s.creatures.0, s.creatures.1, s.creatures.2];
    let mut csv = String::from("kind,level,measure,trial,creatures,frame_ms_median,ms_per_creature_per_frame\n");
    let has = |kind: &str, level: Lod| kinds[config.kind_index(kind).expect("checked")].levels.contains(&level);
    let measured = s
        .kinds
        .iter()
        .map(|k| LEVELS.iter().filter(|(l, _)| has(k, *l)).count() as u64)
        .sum::<u64>();
    let mut progress = super::Progress::new("table1", measured * 2 * u64::from(n_trials));
    let mut costs: Vec<KindCosts> = Vec::new();
    for kind in &s.kinds {
        let base = only_kind(config, kind);
        let mut ms: KindCosts = [None; 3];
        for (i, (level, policy)) in LEVELS.into_iter().enumerate() {
            if !has(kind, level) {
                continue;
            }
            let n = counts[i];
            let world = scaled(&base, n, policy);
            let mut both = [0.0; 2];
            for (m, measure) in ["model", "game"].into_iter().enumerate() {
                let mut per_creature = Vec::new();
                for trial in 0..n_trials {
                    let frame_s = if m == 0 {
                        model_frame_seconds(world.clone(), s.model_speed_m_per_s, warmup, frames)
                    } else {
                        median_frame_seconds(world.clone(), warmup, frames)
                    };
                    let each = frame_s * 1e3 / f64::from(n);
                    let _ = writeln!(
                        csv,
                        "{kind},{},{measure},{trial},{n},{:.6},{each:.8}",
                        level.name(),
                        frame_s * 1e3
                    );
                    per_creature.push(each);
                    progress.inc();
                }
                both[m] = median_of(per_creature);
            }
            ms[i] = Some(both);
        }
        costs.push(ms);
    }
    drop(progress);
    let names = ["point mass", "hybrid", "rigid"];
    let mut series: Vec<Series> = Vec::new();
    // The levels are categories: no line joins them, and each series sits a little apart
    // within its level so that none hides another.
    let columns = 2 * s.kinds.len() + 1;
    let offset = |j: usize| (j as f64 - (columns - 1) as f64 / 2.0) * 0.6 / columns as f64;
    for (k, (kind, ms)) in s.kinds.iter().zip(&costs).enumerate() {
        for (m, (measure, mark)) in [("model and control alone", Mark::Dots), ("whole game", Mark::Rings)]
            .into_iter()
            .enumerate()
        {
            let points = (0..3)
                .filter_map(|i| ms[i].map(|c| (i as f64 + offset(2 * k + m), c[m])))
                .collect();
            series.push(Series::new(
                format!("{kind}: {measure}"),
                points,
                mark,
                k + usize::from(k > 0),
            ));
        }
    }
    series.push(Series::new(
        "paper's hopper (SGI R10000, 1997)",
        PAPER_MS
            .iter()
            .enumerate()
            .map(|(i, &v)| (i as f64 + offset(columns - 1), v))
            .collect(),
        Mark::Points,
        1,
    ));
    plot::draw(
        &options.out.join("table1.png"),
        900,
        600,
        &[Panel {
            title: "Table 1: cost per creature per 1/30 s of motion".into(),
            x_label: "level of detail".into(),
            y_label: "ms per creature per 1/30 s (log)".into(),
            log_y: true,
            x_names: names.iter().map(|s| s.to_string()).collect(),
            series,
            ..Panel::default()
        }],
        options.quick,
    )?;
    let cell = |c: Option<[f64; 2]>, m: usize| c.map_or("-".to_string(), |c| format!("{:.5}", c[m]));
    let ratio = |ms: &KindCosts, m: usize, cheap: usize| match (ms[2], ms[cheap]) {
        (Some(rigid), Some(low)) => Some(rigid[m] / low[m]),
        _ => None,
    };
    let times = |r: Option<f64>| r.map_or("-".to_string(), |r| format!("{r:.0}"));
    let mut report = format!(
        "The cost of one creature for 1/30 s of motion, the median over {n_trials} fresh runs of each run's median of {frames} frames \
         (after {warmup} warm-up frames), one measurement at a time in one process, {} creatures of one kind at the point-mass and hybrid levels and {} rigid. \
         *Model alone* is the paper's measure (simulation and low-level control; no steering, collisions or rendering); *game* adds steering, the level rules and collisions. \
         The paper measured its hopper only. In ms:\n\n| level | paper's hopper |",
        counts[0], counts[2],
    );
    for kind in &s.kinds {
        let _ = write!(report, " {kind}, model alone | {kind}, game |");
    }
    let _ = write!(report, "\n|---|---|{}\n", "---|---|".repeat(s.kinds.len()));
    for i in 0..3 {
        let _ = write!(report, "| {} | {} |", names[i], PAPER_MS[i]);
        for ms in &costs {
            let _ = write!(report, " {} | {} |", cell(ms[i], 0), cell(ms[i], 1));
        }
        report.push('\n');
    }
    let _ = writeln!(
        report,
        "\nThe paper: a rigid hopper costs {:.0} times a hybrid one and {:.0} times a point mass.",
        PAPER_MS[2] / PAPER_MS[1],
        PAPER_MS[2] / PAPER_MS[0],
    );
    for (kind, ms) in s.kinds.iter().zip(&costs) {
        let _ = writeln!(
            report,
            "A rigid {kind} costs {} times a hybrid one and {} times a point mass (model alone; in the game {} and {}).",
            times(ratio(ms, 0, 1)),
            times(ratio(ms, 0, 0)),
            times(ratio(ms, 1, 1)),
            times(ratio(ms, 1, 0)),
        );
    }
    let json_level = |ms: &KindCosts, m: usize| serde_json::json!({ "point_mass": ms[0].map(|c| c[m]), "hybrid": ms[1].map(|c| c[m]), "rigid": ms[2].map(|c| c[m]) });
    let by_kind: serde_json::Map<String, serde_json::Value> = s
        .kinds
        .iter()
        .zip(&costs)
        .map(|(kind, ms)| {
            let value = serde_json::json!({
                "ms_per_creature_per_frame": { "model": json_level(ms, 0), "game": json_level(ms, 1) },
                "ratio": {
                    "rigid/hybrid": ratio(ms, 0, 1), "rigid/point_mass": ratio(ms, 0, 0),
                    "game rigid/hybrid": ratio(ms, 1, 1), "game rigid/point_mass": ratio(ms, 1, 0),
                },
            });
            (kind.clone(), value)
        })
        .collect();
    let summary = serde_json::json!({
        "kinds": by_kind,
        "paper": { "point_mass": PAPER_MS[0], "hybrid": PAPER_MS[1], "rigid": PAPER_MS[2] },
        "creatures": counts, "trials": n_trials, "frames": frames,
    });
    ExperimentRecord {
        experiment: "table1".into(),
        command: command("table1", options),
        summary,
        report,
        smoke_test: options.quick,
    }
    .finish(&options.out, &csv)
}
