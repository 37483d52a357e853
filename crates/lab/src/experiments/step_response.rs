//! Figures 3 and 4: velocity and ground path of a creature under step changes in desired
//! velocity, for each model; and how far apart the models end up after the run (section
//! 3.2: "even small differences in velocity can result in substantial changes in final
//! position").

use crate::error::LabError;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

use super::plot::{self, Mark, Panel, Series};
use super::{EXPERIMENT_COURT_M, ExperimentRecord, lone_creature, write_out};

/// A run starts at least this far inside the experiment's court: 8 s at 3 m/s is 24 m.
const START_MARGIN_M: f32 = 50.0;
use simlod::config::{SimConfig, Validate, Validator, load_file};
use simlod::creature::{DesiredVelocity, PlanarState};
use simlod::lod::{LevelPolicy, Lod};

/// `assets/experiments/step_response.ron`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepResponseConfig {
    /// The creature kind run (it must have the hybrid and the rigid level).
    pub creature: String,
    /// Length of each model's run, simulated seconds.
    pub duration_s: f32,
    /// Where the creature starts on the court, (x, z) metres from its centre.
    pub start_m: (f32, f32),
    /// The desired-velocity schedule, in increasing order of `at_s`.
    pub steps: Vec<VelocityStep>,
}

/// One step of figure 3's schedule: a new desired velocity from a time on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VelocityStep {
    /// When the step happens, seconds from the start of the run.
    pub at_s: f32,
    /// Desired planar velocity (x, z) from `at_s` on.
    pub velocity_m_per_s: (f32, f32),
}

impl Validate for StepResponseConfig {
    fn validate(&self, v: &mut Validator) {
        v.within(
            "duration_s",
            self.duration_s,
            1.0 / 30.0,
            simlod::config::MAX_DURATION_S,
        );
        // The run must stay in the experiment's court: a start well inside it.
        let reach = EXPERIMENT_COURT_M / 2.0 - START_MARGIN_M;
        v.within("start_m.0", self.start_m.0, -reach, reach);
        v.within("start_m.1", self.start_m.1, -reach, reach);
        v.require(!self.steps.is_empty(), "steps", "must hold at least one step");
        for (i, s) in self.steps.iter().enumerate() {
            v.non_negative(&format!("steps[{i}].at_s"), s.at_s);
            v.within(
                &format!("steps[{i}].velocity_m_per_s.0"),
                s.velocity_m_per_s.0,
                -10.0,
                10.0,
            );
            v.within(
                &format!("steps[{i}].velocity_m_per_s.1"),
                s.velocity_m_per_s.1,
                -10.0,
                10.0,
            );
        }
        v.require(
            self.steps.windows(2).all(|w| w[0].at_s < w[1].at_s),
            "steps",
            "must be in increasing order of at_s",
        );
    }
}

impl StepResponseConfig {
    /// The desired velocity at time `t`.
    pub fn desired_at(&self, t: f32) -> Vec2 {
        let step = self.steps.iter().rev().find(|s| s.at_s <= t).unwrap_or(&self.steps[0]);
        Vec2::new(step.velocity_m_per_s.0, step.velocity_m_per_s.1)
    }
}

/// One model's run, sampled once a frame (30 Hz).
#[derive(Clone, Debug)]
pub struct Trace {
    /// The model's name in the CSVs and plots: `rigid` or `hybrid`.
    pub model: &'static str,
    /// (time, desired velocity, state)
    pub samples: Vec<(f32, Vec2, PlanarState)>,
}

/// Runs the schedule on one model.
pub fn trace(
    sim_config: &SimConfig,
    experiment: &StepResponseConfig,
    model: &'static str,
    policy: LevelPolicy,
) -> Trace {
    let start = Vec2::new(experiment.start_m.0, experiment.start_m.1);
    let (mut sim, creature) = lone_creature(sim_config, &experiment.creature, policy, start, EXPERIMENT_COURT_M);
    let mut samples = Vec::new();
    while sim.clock().seconds() < f64::from(experiment.duration_s) {
        let t = sim.clock().seconds() as f32;
        let desired = experiment.desired_at(t);
        let world = sim.app.world_mut();
        let Some(mut d) = world.get_mut::<DesiredVelocity>(creature) else {
            break;
        };
        d.0 = desired;
        sim.advance_frame();
        let Some(state) = sim.app.world().get::<PlanarState>(creature) else {
            break;
        };
        samples.push((sim.clock().seconds() as f32, desired, *state));
    }
    Trace { model, samples }
}

/// Writes `velocity.csv` (figure 3), `path.csv` (figure 4) and `final.csv` (where each model
/// ended, and how far apart) into `out`; returns a summary.
pub fn run(sim_config: &SimConfig, experiment_file: &Path, out: &Path) -> Result<String, LabError> {
    let experiment: StepResponseConfig = load_file(experiment_file)?;
    super::check_kind(
        sim_config,
        experiment_file,
        "creature",
        &experiment.creature,
        &[Lod::Hybrid, Lod::Rigid],
    )?;
    let traces = [
        trace(sim_config, &experiment, "rigid", LevelPolicy::AllRigid),
        trace(sim_config, &experiment, "hybrid", LevelPolicy::AllHybrid),
    ];
    let mut velocity = String::from(
        "model,t_s,desired_vx_m_per_s,desired_vz_m_per_s,vx_m_per_s,vz_m_per_s,desired_speed_m_per_s,speed_m_per_s\n",
    );
    let mut path = String::from("model,t_s,x_m,z_m\n");
    let mut summary = String::new();
    for tr in &traces {
        for (t, d, s) in &tr.samples {
            let _ = writeln!(
                velocity,
                "{},{t:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
                tr.model,
                d.x,
                d.y,
                s.velocity.x,
                s.velocity.y,
                d.length(),
                s.velocity.length()
            );
            let _ = writeln!(path, "{},{t:.4},{:.4},{:.4}", tr.model, s.position.x, s.position.y);
        }
        let end = tr.samples.last().map_or(Vec2::ZERO, |s| s.2.position);
        let _ = writeln!(
            summary,
            "{}: {} samples over {:.2} s, final position ({:.3}, {:.3}) m",
            tr.model,
            tr.samples.len(),
            tr.samples.last().map_or(0.0, |s| s.0),
            end.x,
            end.y
        );
    }
    let ends: Vec<Vec2> = traces
        .iter()
        .filter_map(|tr| tr.samples.last().map(|s| s.2.position))
        .collect();
    let mut last = String::from("rigid_x_m,rigid_z_m,hybrid_x_m,hybrid_z_m,distance_m\n");
    if let [rigid, hybrid] = ends[..] {
        let apart = rigid.distance(hybrid);
        let _ = writeln!(
            summary,
            "after {:.1} s the models are {apart:.3} m apart",
            experiment.duration_s
        );
        let _ = writeln!(
            last,
            "{:.4},{:.4},{:.4},{:.4},{apart:.4}",
            rigid.x, rigid.y, hybrid.x, hybrid.y
        );
    }
    for (name, text) in [("velocity.csv", &velocity), ("path.csv", &path), ("final.csv", &last)] {
        let file = write_out(out, name, text)?;
        let _ = writeln!(summary, "wrote {}", file.display());
    }
    draw(&traces, &out.join("step-response.png"))?;
    let apart = match ends[..] {
        [rigid, hybrid] => rigid.distance(hybrid),
        _ => f32::NAN,
    };
    let record = ExperimentRecord {
        experiment: "step-response".into(),
        command: format!("simlod experiment step-response --out {}", out.display()),
        summary: serde_json::json!({ "distance_apart_m": apart, "duration_s": experiment.duration_s }),
        report: format!(
            "Figures 3 and 4: both models through the same steps of desired velocity (`velocity.csv`, `path.csv`; `final.csv` where they end). \
             The paper's rigid hopper changes speed only in stance, a hop at a time, while the hybrid answers a step at once and linearly; \
             \"even small differences in velocity can result in substantial changes in final position\". After {:.1} s ours end {apart:.2} m apart.\n",
            experiment.duration_s
        ),
        smoke_test: false,
    };
    summary += &record.save(out, &["step-response.png"])?;
    Ok(summary)
}

/// Figure 3 (speed against time) and figure 4 (the paths on the ground) side by side.
fn draw(traces: &[Trace], file: &Path) -> Result<(), LabError> {
    let mut speed = Vec::new();
    let mut path = Vec::new();
    if let Some(first) = traces.first() {
        let desired = first
            .samples
            .iter()
            .map(|(t, d, _)| (f64::from(*t), f64::from(d.length())))
            .collect();
        speed.push(Series::new("desired", desired, Mark::Dashed, plot::REFERENCE));
    }
    for (i, tr) in traces.iter().enumerate() {
        let points = |f: &dyn Fn(&(f32, Vec2, PlanarState)) -> (f32, f32)| -> Vec<(f64, f64)> {
            tr.samples
                .iter()
                .map(f)
                .map(|(x, y)| (f64::from(x), f64::from(y)))
                .collect()
        };
        speed.push(Series::new(
            tr.model,
            points(&|(t, _, s)| (*t, s.velocity.length())),
            Mark::Line,
            i,
        ));
        // The first model's path is drawn dashed and last, over the other: where the two
        // paths run together, both stay in sight.
        path.insert(
            0,
            Series::new(
                tr.model,
                points(&|(_, _, s)| (s.position.x, s.position.y)),
                if i == 0 { Mark::Dashed } else { Mark::Line },
                i,
            ),
        );
    }
    let ends: Vec<(f64, f64, String)> = traces
        .iter()
        .filter_map(|tr| {
            let (t, _, s) = tr.samples.last()?;
            Some((
                f64::from(s.position.x),
                f64::from(s.position.y),
                format!("  {} at {t:.1} s", tr.model),
            ))
        })
        .collect();
    plot::draw(
        file,
        1400,
        600,
        &[
            Panel {
                title: "Figure 3: speed under steps of desired velocity".into(),
                x_label: "time (s)".into(),
                y_label: "speed (m/s)".into(),
                series: speed,
                ..Panel::default()
            },
            Panel {
                title: "Figure 4: paths on the ground".into(),
                x_label: "x (m)".into(),
                y_label: "z (m)".into(),
                series: path,
                notes: ends,
                to_scale: true,
                ..Panel::default()
            },
        ],
        false,
    )
    .map(drop)
}
