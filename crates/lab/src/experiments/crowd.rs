//! The crowd: figure 7 taken to crowds. For each policy and each crowd size (the scenario's
//! mix, the court grown with the count so the density stays the default game's), a game of a
//! few seconds with every frame's simulation timed: the mean and slowest frame, and the
//! creatures at each level. A policy stops at the first size where a frame passes the limit.

use crate::error::LabError;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use super::plot::{self, Mark, Panel, Series};
use super::{ExperimentRecord, Options, command, load_settings};
use crate::bench::scaled;
use simlod::config::{SimConfig, Validate, Validator};
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelPolicy, Lod};

/// `assets/experiments/crowd.ron`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrowdSettings {
    /// The policies measured, each at every size until a frame passes `stop_frame_ms`.
    pub policies: Vec<LevelPolicy>,
    /// The crowd sizes, smallest first.
    pub creatures: Vec<u32>,
    /// Simulated seconds of each game.
    pub seconds: f32,
    /// A policy stops at the first size where a frame takes longer than this; 1 to 600,000 ms.
    pub stop_frame_ms: f32,
    /// The games' seed.
    pub seed: u64,
}

impl Validate for CrowdSettings {
    fn validate(&self, v: &mut Validator) {
        v.require(!self.policies.is_empty(), "policies", "must list at least one policy");
        super::validate_crowd_sizes(v, &self.creatures);
        v.range("seconds", self.seconds, 1.0 / 30.0, 600.0);
        v.range("stop_frame_ms", self.stop_frame_ms, 1.0, 600_000.0);
    }
}

/// One policy's game at one crowd size.
#[derive(Clone, Debug, Serialize)]
struct Game {
    policy: String,
    creatures: u32,
    /// Frames timed (the first, which builds the world, left out).
    frames: usize,
    mean_frame_ms: f64,
    slowest_frame_ms: f64,
    /// Whether a frame passed the limit, which ended the game there and the policy's sizes.
    stopped: bool,
    /// Mean creatures at each level over the game.
    point_mass: f64,
    hybrid: f64,
    rigid: f64,
}

/// The policy's name on the command line (`all-rigid`).
/// A game of `config` for `seconds`, each frame timed, ended early by a frame over `stop_ms`.
fn game(config: SimConfig, seconds: f32, stop_ms: f64) -> Game {
    let (policy, creatures) = (config.scenario.level_policy.name(), config.scenario.creature_count());
    let mut sim = HeadlessSim::new(config);
    // The first frame builds the world: not a frame of the game.
    sim.advance_frame();
    let mut frames_ms = Vec::new();
    while sim.clock().seconds() < f64::from(seconds) - 1e-9 {
        let start = Instant::now();
        sim.advance_frame();
        frames_ms.push(start.elapsed().as_secs_f64() * 1e3);
        if frames_ms.last().is_some_and(|&ms| ms > stop_ms) {
            break;
        }
    }
    let summary = sim.summary(frames_ms.iter().sum::<f64>() / 1e3);
    let slowest = frames_ms.iter().copied().fold(0.0, f64::max);
    Game {
        policy: policy.to_owned(),
        creatures,
        frames: frames_ms.len(),
        mean_frame_ms: frames_ms.iter().sum::<f64>() / frames_ms.len().max(1) as f64,
        slowest_frame_ms: slowest,
        stopped: slowest > stop_ms,
        point_mass: summary.levels_mean[Lod::PointMass],
        hybrid: summary.levels_mean[Lod::Hybrid],
        rigid: summary.levels_mean[Lod::Rigid],
    }
}

/// Peak resident memory of this process so far, in MB, where the system says (Linux).
fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Runs the crowd experiment from `file`; writes its CSV, plot, JSON and report and returns
/// what it says.
pub fn run(config: &SimConfig, file: &Path, options: &Options) -> Result<String, LabError> {
    let s: CrowdSettings = load_settings(file, options)?;
    let stop_ms = f64::from(s.stop_frame_ms);
    let mut progress = super::Progress::new("crowd", (s.policies.len() * s.creatures.len()) as u64);
    let mut games = Vec::new();
    for &policy in &s.policies {
        for &n in &s.creatures {
            let mut c = scaled(config, n, policy);
            c.scenario.seed = s.seed;
            let g = game(c, s.seconds, stop_ms);
            let stopped = g.stopped;
            games.push(g);
            progress.inc();
            if stopped {
                break;
            }
        }
    }
    drop(progress);
    let peak_mb = peak_memory_mb();
    let mut csv =
        String::from("policy,creatures,frames,mean_frame_ms,slowest_frame_ms,stopped,point_mass,hybrid,rigid\n");
    for g in &games {
        let _ = writeln!(
            csv,
            "{},{},{},{:.4},{:.4},{},{:.1},{:.1},{:.1}",
            g.policy,
            g.creatures,
            g.frames,
            g.mean_frame_ms,
            g.slowest_frame_ms,
            g.stopped,
            g.point_mass,
            g.hybrid,
            g.rigid
        );
    }
    let curve = |policy: &str, of: fn(&Game) -> f64| -> Vec<(f64, f64)> {
        games
            .iter()
            .filter(|g| g.policy == policy)
            .map(|g| (f64::from(g.creatures).log10(), of(g)))
            .collect()
    };
    let mut series = Vec::new();
    for &policy in &s.policies {
        let (name, colour) = (policy.name(), plot::policy_colour(policy));
        series.push(Series::new(
            format!("{name}, mean"),
            curve(name, |g| g.mean_frame_ms),
            Mark::Line,
            colour,
        ));
        series.push(Series::new(
            format!("{name}, slowest"),
            curve(name, |g| g.slowest_frame_ms),
            Mark::Dashed,
            colour,
        ));
    }
    let (lo, hi) = super::log10_span(&s.creatures);
    series.push(Series::new(
        "1/30 s: 30 fps",
        vec![(lo, 1e3 / 30.0), (hi, 1e3 / 30.0)],
        Mark::Dashed,
        plot::REFERENCE,
    ));
    plot::draw(
        &options.out.join("crowd.png"),
        1000,
        650,
        &[Panel {
            title: format!("frame time against crowd size: games of {} s", s.seconds),
            x_label: "creatures, log10 (2 is 100, 6 is 1,000,000)".into(),
            y_label: "wall time of a frame's simulation (ms, log)".into(),
            log_y: true,
            series,
            ..Panel::default()
        }],
        options.quick,
    )?;
    let mut report = format!(
        "Each policy's game at each crowd size: the scenario's mix, the court grown by the square root of the count (the default game's density), \
         seed {}, {} s of simulated time; every frame's simulation timed on this machine's cores, the first (which builds the world) left out. \
         A policy stops at the first size where a frame takes over {} ms.\n\n\
         | policy | creatures | mean frame (ms) | slowest frame (ms) | mean within 1/30 s | point mass | hybrid | rigid |\n|---|---|---|---|---|---|---|---|\n",
        s.seed, s.seconds, s.stop_frame_ms
    );
    for g in &games {
        let _ = writeln!(
            report,
            "| {} | {} | {:.2} | {:.2}{} | {} | {:.0} | {:.0} | {:.0} |",
            g.policy,
            g.creatures,
            g.mean_frame_ms,
            g.slowest_frame_ms,
            if g.stopped { " (stopped)" } else { "" },
            if g.mean_frame_ms <= 1e3 / 30.0 { "yes" } else { "no" },
            g.point_mass,
            g.hybrid,
            g.rigid
        );
    }
    if let Some(mb) = peak_mb {
        let _ = write!(report, "\nPeak memory of the process over all the games: {mb:.0} MB.\n");
    }
    ExperimentRecord {
        experiment: "crowd".into(),
        command: command("crowd", options),
        summary: serde_json::json!({ "games": games, "peak_memory_mb": peak_mb }),
        report,
        smoke_test: options.quick,
    }
    .finish(&options.out, &csv)
}
