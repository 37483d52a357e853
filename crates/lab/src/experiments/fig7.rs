//! Figure 7: how many creatures run at 30 frames a second, headless, as a function of the
//! percentage of them that are rigid (the rest hybrid; no point masses, every creature in
//! the game's steering and collisions). Levels are set by the experiment and held.

use crate::error::LabError;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

use super::plot::{self, Mark, Panel, Series};
use super::{ExperimentRecord, Options, check_kind, command, hold_levels, load_settings, median_of, only_kind, trials};
use crate::bench::{median_frame_seconds_of, most_within_budget, scaled};
use simlod::config::{SimConfig, Validate, Validator};
use simlod::creature::Creature;
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelChoice, LevelPolicy, Lod};

/// The paper's figure 7 without graphics: 112 creatures all hybrid, 12 all rigid.
pub const PAPER_ENDS: [(f64, f64); 2] = [(0.0, 112.0), (100.0, 12.0)];

/// `assets/experiments/fig7.ron`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fig7Settings {
    /// The creature kind measured (the scenario's creatures are all made this kind).
    pub creature: String,
    /// The percentages of rigid creatures measured.
    pub rigid_percent: Vec<u32>,
    /// The first count tried when searching for the most creatures at 30 fps.
    pub search_from: u32,
    /// Halvings of the search's last gap (it stops within 3 %).
    pub search_steps: u32,
    /// Frames run before timing starts, in each run of a count.
    pub warmup_frames: u32,
    /// Frames timed in each run; the run's measure is their median.
    pub frames: u32,
    /// Runs per count tried; a count fits when the median of their median frames does.
    pub trials: u32,
}

impl Validate for Fig7Settings {
    fn validate(&self, v: &mut Validator) {
        v.require(!self.creature.is_empty(), "creature", "must name a creature kind");
        v.require(
            !self.rigid_percent.is_empty(),
            "rigid_percent",
            "must list at least one percentage",
        );
        for (i, p) in self.rigid_percent.iter().enumerate() {
            v.require(
                *p <= 100,
                &format!("rigid_percent[{i}]"),
                format!("must be at most 100, got {p}"),
            );
        }
        v.require(self.search_from >= 1, "search_from", "must be at least 1");
        v.require(self.frames >= 1, "frames", "must be at least 1");
        v.require(self.trials >= 1, "trials", "must be at least 1");
    }
}

/// Median frame of `n` creatures of which `percent` % (the lowest serials) are rigid.
fn mixed_frame_seconds(base: &SimConfig, n: u32, percent: u32, warmup: usize, frames: usize) -> f64 {
    let mut sim = HeadlessSim::new(scaled(base, n, LevelPolicy::AllHybrid));
    hold_levels(&mut sim, &[]);
    let rigid = (u64::from(n) * u64::from(percent)).div_ceil(100) as u32;
    let world = sim.app.world_mut();
    let chosen: Vec<Entity> = world
        .query::<(Entity, &Creature)>()
        .iter(world)
        .filter(|(_, c)| c.serial < rigid)
        .map(|(e, _)| e)
        .collect();
    for entity in chosen {
        // Entering the rigid level builds its bodies (the level's observers).
        let mut e = world.entity_mut(entity);
        e.insert(Lod::Rigid);
        e.get_mut::<LevelChoice>()
            .expect("a creature has a level choice")
            .wanted = Lod::Rigid;
    }
    world.flush();
    median_frame_seconds_of(&mut sim, warmup, frames)
}

/// Runs figure 7 from `file`: for each rigid percentage, searches for the most creatures at
/// 30 fps; writes its CSV, plot, JSON and report and returns what it says.
pub fn run(config: &SimConfig, file: &Path, options: &Options) -> Result<String, LabError> {
    let s: Fig7Settings = load_settings(file, options)?;
    check_kind(config, file, "creature", &s.creature, &[Lod::Hybrid, Lod::Rigid])?;
    let base = only_kind(config, &s.creature);
    let n_trials = trials(options, s.trials);
    let mut csv = String::from("rigid_percent,creatures_30fps,rigid_creatures,hybrid_creatures\n");
    let mut progress = super::Progress::new("fig7", s.rigid_percent.len() as u64);
    let mut points = Vec::new();
    for &percent in &s.rigid_percent {
        let most = most_within_budget(s.search_from, s.search_steps, |n| {
            median_of(
                (0..n_trials)
                    .map(|_| mixed_frame_seconds(&base, n, percent, s.warmup_frames as usize, s.frames as usize)),
            )
        });
        let rigid = (u64::from(most) * u64::from(percent)).div_ceil(100);
        let _ = writeln!(csv, "{percent},{most},{rigid},{}", u64::from(most) - rigid);
        points.push((f64::from(percent), f64::from(most)));
        progress.inc();
    }
    drop(progress);
    plot::draw(
        &options.out.join("fig7.png"),
        900,
        600,
        &[Panel {
            title: "Figure 7: creatures at 30 fps without graphics".into(),
            x_label: "rigid creatures (%), the rest hybrid".into(),
            y_label: "creatures at 30 fps (log)".into(),
            log_y: true,
            series: vec![
                Series::new("simlod, headless", points.clone(), Mark::Line, 0),
                Series::new("paper, without graphics", PAPER_ENDS.to_vec(), Mark::Points, 1),
            ],
            ..Panel::default()
        }],
        options.quick,
    )?;
    let at = |p: f64| points.iter().find(|q| q.0 == p).map(|q| q.1);
    let mut report = format!(
        "The most creatures whose median frame of 1/30 s of motion takes at most 1/30 s of wall time, headless, as the share of rigid ones grows \
         (the rest hybrid; steering and collisions on; levels held). Each count tried is the median of {n_trials} run(s) of {} frames; \
         the search doubles and then halves the gap to within 3 %. Loops over more than {} creatures run on both cores.\n\n\
         | rigid (%) | creatures at 30 fps |\n|---|---|\n",
        s.frames,
        simlod::PARALLEL_MIN_CREATURES
    );
    for (p, n) in &points {
        let _ = writeln!(report, "| {p} | {n} |");
    }
    if let (Some(hybrid), Some(rigid)) = (at(0.0), at(100.0)) {
        let _ = write!(
            report,
            "\nAll hybrid: {hybrid} creatures, all rigid: {rigid} ({:.0} times as many); the paper without graphics: 112 and 12 ({:.1} times).\n",
            hybrid / rigid.max(1.0),
            112.0 / 12.0
        );
    }
    ExperimentRecord {
        experiment: "fig7".into(),
        command: command("fig7", options),
        summary: serde_json::json!({ "creatures_30fps": points, "paper": PAPER_ENDS, "trials": n_trials }),
        report,
        smoke_test: options.quick,
    }
    .finish(&options.out, &csv)
}
