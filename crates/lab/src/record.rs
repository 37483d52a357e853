//! `simlod record-gait`: records a gait table from the rigid model (paper 3.2: "we recorded
//! motion from the dynamic simulation with forward velocities of 0, 1, 2, and 3 m/s ... at a
//! rate of 30 samples/second for the period of time from one touchdown to the next").
//!
//! At each speed the rigid model runs until its gait is steady, then several strides (a hop of
//! the hopper; a step of each leg of a biped) are each resampled at 30 Hz from the first leg's
//! touchdown and averaged. It reads only what every level publishes (pose, gait phase, planar
//! state). A second run from standing to the top
//! speed measures the acceleration the point mass must match. The world is seeded, so the
//! same files give the same table.

use crate::error::LabError;
use bevy::prelude::*;
use std::fmt::Write as _;

use crate::scene::{EXPERIMENT_COURT_M, lone_creature, stand};
use simlod::config::{CreatureDef, SimConfig};
use simlod::creature::{DesiredVelocity, GaitPhase, PlanarState};
use simlod::gait::{GaitPose, GaitRow, GaitTable, columns};
use simlod::headless::HeadlessSim;
use simlod::lod::LevelPolicy;

/// How a table is recorded.
#[derive(Clone, Debug)]
pub struct RecordSettings {
    /// Steady forward speeds to record, increasing.
    pub speeds_m_per_s: Vec<f32>,
    /// Running time before recording starts at each speed.
    pub settle_s: f32,
    /// Strides averaged per speed.
    pub hops: usize,
    /// The strides are steady when their periods differ by at most this share of their mean,
    /// and their mean speeds by at most `steady_speed_m_per_s`.
    pub steady_period_share: f32,
    /// Steady strides' mean speeds differ by at most this (see `steady_period_share`).
    pub steady_speed_m_per_s: f32,
    /// Running time after `settle_s` within which the hops must become steady.
    pub steady_within_s: f32,
    /// Samples per second of the recorded pose.
    pub sample_hz: f32,
}

impl RecordSettings {
    /// The default recording of a kind whose top speed is `top_m_per_s`: every whole metre a
    /// second below it, and the top speed itself (the paper's 0, 1, 2, 3 m/s for a top speed of
    /// 3 m/s).
    pub fn up_to(top_m_per_s: f32) -> Self {
        let whole = (0..).map(|v| v as f32).take_while(|&v| v < top_m_per_s - 0.05);
        Self {
            speeds_m_per_s: whole.chain([top_m_per_s]).collect(),
            ..Self::default()
        }
    }
}

impl Default for RecordSettings {
    fn default() -> Self {
        Self {
            speeds_m_per_s: vec![0.0, 1.0, 2.0, 3.0],
            settle_s: 15.0,
            hops: 4,
            steady_period_share: 0.05,
            steady_speed_m_per_s: 0.1,
            steady_within_s: 10.0,
            sample_hz: 30.0,
        }
    }
}

/// One tick's record of a running creature: what every level publishes.
#[derive(Clone, Copy)]
struct Tick {
    t: f32,
    pose: GaitPose,
    position: Vec2,
}

/// A creature commanded along +x, stepped one tick per update and watched, so that a fall can
/// be explained.
struct Runner<'a> {
    sim: HeadlessSim,
    creature: Entity,
    def: &'a CreatureDef,
    /// The commanded speed.
    speed: f32,
    /// The last tick seen, its gait phase and velocity: what the creature did before it fell.
    seen: Option<(Tick, GaitPhase, Vec2)>,
}

impl<'a> Runner<'a> {
    /// The creature of `def` in `config`, commanded at `speed`.
    fn new(config: &SimConfig, def: &'a CreatureDef, speed: f32) -> Self {
        let mut config = config.clone();
        config.scenario.decision_hz = config.scenario.tick_hz;
        // From near one wall toward the other: the longest straight run the court allows.
        let start = Vec2::new(10.0 - EXPERIMENT_COURT_M / 2.0, 0.0);
        let (mut sim, creature) = lone_creature(&config, &def.name, LevelPolicy::AllRigid, start, EXPERIMENT_COURT_M);
        let world = sim.app.world_mut();
        world
            .entity_mut(creature)
            .insert(DesiredVelocity(Vec2::new(speed, 0.0)));
        // Facing its course from the start: the recording is of running, not of turning.
        stand(world, creature, start, Some(Vec2::X));
        Self {
            sim,
            creature,
            def,
            speed,
            seen: None,
        }
    }

    /// Commands `speed` from now on.
    fn command(&mut self, speed: f32) {
        self.speed = speed;
        self.sim
            .app
            .world_mut()
            .entity_mut(self.creature)
            .insert(DesiredVelocity(Vec2::new(speed, 0.0)));
    }

    /// This tick's pose and position, and the gait phase; once the creature has fallen (and
    /// was removed), an error that says how.
    fn sample(&mut self) -> Result<(Tick, GaitPhase), LabError> {
        let t = self.sim.clock().seconds() as f32;
        let world = self.sim.app.world();
        let e = self.creature;
        let (Some(pose), Some(state), Some(gait)) = (
            world.get::<GaitPose>(e),
            world.get::<PlanarState>(e),
            world.get::<GaitPhase>(e),
        ) else {
            return Err(LabError::Invalid(fall_report(self.def, self.speed, t, self.seen)));
        };
        let tick = Tick {
            t,
            pose: *pose,
            position: state.position,
        };
        self.seen = Some((tick, *gait, state.velocity));
        Ok((tick, *gait))
    }

    /// One tick on.
    fn advance(&mut self) -> Result<(Tick, GaitPhase), LabError> {
        self.sim.advance_frame();
        self.sample()
    }

    /// `seconds` on, watching every tick.
    fn run_for(&mut self, seconds: f32) -> Result<(), LabError> {
        let end = self.sim.clock().seconds() + f64::from(seconds);
        while self.sim.clock().seconds() < end {
            self.advance()?;
        }
        Ok(())
    }

    fn seconds(&self) -> f64 {
        self.sim.clock().seconds()
    }
}

/// Why a kind's rigid model fell, and where in its file to look first: the body's height and
/// tilt against the fall limits, the virtual leg in stance, the speeds, the tick before.
fn fall_report(def: &CreatureDef, commanded: f32, t: f32, seen: Option<(Tick, GaitPhase, Vec2)>) -> String {
    let head = format!(
        "the rigid model of {:?} fell at {t:.2} s, commanded {commanded} m/s",
        def.name
    );
    let (Some((tick, gait, velocity)), Some(r)) = (seen, &def.rigid) else {
        return format!("{head}, before its first tick");
    };
    let pose = &tick.pose;
    let (roll, pitch) = (pose.roll_rad.to_degrees(), pose.pitch_rad.to_degrees());
    let tilt = roll.hypot(pitch);
    let groups = def.stance.groups(def.legs.len());
    let step = groups.get(usize::from(gait.step)).cloned().unwrap_or_default();
    let where_in_step = if gait.in_flight {
        format!("in flight after virtual leg {} (legs {step:?})", gait.step)
    } else {
        format!("in stance on virtual leg {} (legs {step:?})", gait.step)
    };
    let speed = velocity.length();
    // Each limit's share used: the nearest to 1 is what tripped.
    let low = (def.body.hip_height_m - pose.body_height_m) / (def.body.hip_height_m - r.fall.body_min_height_m);
    let tilted = tilt / r.fall.max_tilt_deg;
    let look = if speed > 0.5 * r.fall.blow_up_speed_m_per_s || !pose.body_height_m.is_finite() {
        "The numbers blew up: look first at rigid.joints (Multibody holds the joints exactly), the scenario's \
         solver_iterations, legs much lighter than the body (legs[].upper_mass_kg, lower_mass_kg)"
    } else if low >= tilted {
        "The legs did not hold the body up: look first at legs[].spring_n_per_m (stiffer), \
         rigid.controller.thrust_initial_m and thrust_max_m, body.mass_kg, legs[].min_length_m"
    } else if roll.abs() >= pitch.abs() {
        "It rolled over: look first at rigid.controller.attitude_kp_nm_per_rad and attitude_kd_nm_s_per_rad, the \
         hips' side spacing (legs[].hip_m.2: a virtual leg's thrust off the centre line rolls the \
         body), idle_leg_retract_m (a swinging foot that scuffs)"
    } else {
        "It pitched over: look first at rigid.controller.attitude_kp_nm_per_rad and attitude_kd_nm_s_per_rad, \
         foot placement (speed_gain_s, max_foot_offset_fraction), the hips' fore-aft spacing \
         (legs[].hip_m.0)"
    };
    format!(
        "{head}. At {:.3} s its body was {:.2} m high (it falls below rigid.fall.body_min_height_m, \
         {} m) and tilted {tilt:.0} degrees (roll {roll:.0}, pitch {pitch:.0}; it falls past \
         rigid.fall.max_tilt_deg, {}), moving at {speed:.2} m/s, {where_in_step}. {look}.",
        tick.t, pose.body_height_m, r.fall.body_min_height_m, r.fall.max_tilt_deg
    )
}

/// How unsteady a run of strides is: the spread of their periods as a share of the mean, and
/// the spread of their mean speeds.
fn unsteadiness(strides: &[(f32, f32)], ticks: &[Tick]) -> (f32, f32) {
    let at = |t: f32| ticks.iter().find(|tk| tk.t >= t).map_or(Vec2::ZERO, |tk| tk.position);
    let periods: Vec<f32> = strides.iter().map(|(a, b)| b - a).collect();
    let speeds: Vec<f32> = strides
        .iter()
        .map(|&(a, b)| (at(b) - at(a)).length() / (b - a))
        .collect();
    let spread = |v: &[f32]| v.iter().copied().fold(f32::MIN, f32::max) - v.iter().copied().fold(f32::MAX, f32::min);
    let mean = periods.iter().sum::<f32>() / periods.len() as f32;
    (spread(&periods) / mean, spread(&speeds))
}

/// Records `hops` steady strides at `speed` and averages them into a row: after settling,
/// the last `hops` strides (each from the first leg's touchdown), once they are steady.
fn record_row(
    config: &SimConfig,
    def: &CreatureDef,
    steps: u32,
    speed: f32,
    s: &RecordSettings,
) -> Result<GaitRow, LabError> {
    let mut run = Runner::new(config, def, speed);
    run.run_for(s.settle_s)?;
    let mut ticks: Vec<Tick> = Vec::new();
    let mut stride_starts: Vec<f32> = Vec::new();
    // The stance share of each step, known at the touchdown that ends it.
    let mut stance_shares: Vec<(f32, f32)> = Vec::new();
    let (_, mut last) = run.sample()?;
    // The steadiest run of strides seen, for the error if none is steady enough.
    let mut steadiest = (f32::INFINITY, f32::INFINITY);
    let strides = loop {
        let (tick, gait) = run.advance()?;
        let touched_down = gait.last_touchdown_s != last.last_touchdown_s;
        let stride_starts_now = touched_down && gait.step == 0;
        if touched_down {
            let stance_s = last.stance_fraction * last.hop_period_s;
            let step_s = gait.last_touchdown_s - last.last_touchdown_s;
            stance_shares.push((gait.last_touchdown_s, stance_s / step_s.max(1e-3)));
        }
        last = gait;
        if stride_starts_now {
            stride_starts.push(gait.last_touchdown_s);
        }
        if !stride_starts.is_empty() {
            ticks.push(tick);
        }
        if stride_starts_now && stride_starts.len() > s.hops {
            let recent = &stride_starts[stride_starts.len() - s.hops - 1..];
            let strides: Vec<(f32, f32)> = recent.windows(2).map(|w| (w[0], w[1])).collect();
            let (period_share, speed_spread) = unsteadiness(&strides, &ticks);
            // Each spread as a share of its limit: steady when neither passes 1.
            let excess = |(p, v): (f32, f32)| (p / s.steady_period_share).max(v / s.steady_speed_m_per_s);
            if excess((period_share, speed_spread)) < excess(steadiest) {
                steadiest = (period_share, speed_spread);
            }
            if period_share <= s.steady_period_share && speed_spread <= s.steady_speed_m_per_s {
                break strides;
            }
        }
        if run.seconds() > f64::from(s.settle_s + s.steady_within_s) {
            let steadiest = if steadiest.0.is_finite() {
                format!(
                    "; the steadiest {} had periods {:.1} % apart (at most {:.1} %) and speeds {:.3} m/s apart (at most {})",
                    s.hops,
                    steadiest.0 * 100.0,
                    s.steady_period_share * 100.0,
                    steadiest.1,
                    s.steady_speed_m_per_s
                )
            } else {
                format!(", too few to judge {} of them", s.hops)
            };
            return Err(LabError::Invalid(format!(
                "no steady gait at {speed} m/s within {} s: {} strides{steadiest}",
                s.steady_within_s,
                stride_starts.len()
            )));
        }
    };
    let period = strides.iter().map(|(a, b)| b - a).sum::<f32>() / strides.len() as f32;
    let n = (period * s.sample_hz).ceil() as usize;
    let mut sums = vec![vec![0.0f32; ticks[0].pose.to_row().len()]; n];
    for &(start, end) in &strides {
        for (k, sum) in sums.iter_mut().enumerate() {
            // The same share of each stride as sample k is of the mean stride.
            let t = start + (k as f32 / s.sample_hz) / period * (end - start);
            for (acc, x) in sum.iter_mut().zip(pose_at(&ticks, t).to_row()) {
                *acc += x;
            }
        }
    }
    let (first, last) = (strides[0].0, strides[strides.len() - 1].1);
    // The steps that end inside the recorded strides.
    let shares: Vec<f32> = stance_shares
        .iter()
        .filter(|(end, _)| *end > first && *end <= last)
        .map(|(_, share)| *share)
        .collect();
    let count = strides.len() as f32;
    let at = |t: f32| ticks.iter().find(|tk| tk.t >= t).map_or(Vec2::ZERO, |tk| tk.position);
    Ok(GaitRow {
        speed_m_per_s: (at(last) - at(first)).length() / (last - first),
        hop_period_s: period / steps as f32,
        stance_fraction: shares.iter().sum::<f32>() / shares.len().max(1) as f32,
        samples: sums
            .into_iter()
            .map(|sum| sum.iter().map(|x| x / count).collect())
            .collect(),
    })
}

/// The recorded pose at time `t`, interpolated between ticks.
fn pose_at(ticks: &[Tick], t: f32) -> GaitPose {
    let i = ticks.partition_point(|tk| tk.t < t).clamp(1, ticks.len() - 1);
    let (a, b) = (ticks[i - 1], ticks[i]);
    let w = ((t - a.t) / (b.t - a.t).max(1e-6)).clamp(0.0, 1.0);
    a.pose.lerp(b.pose, w)
}

/// From standing, commanded to `top`: the acceleration of the hop-averaged speed while it
/// rises from 10 % to 70 % of `top` (the saturated part a limit describes).
fn measure_acceleration(config: &SimConfig, def: &CreatureDef, top: f32) -> Result<f32, LabError> {
    let mut run = Runner::new(config, def, 0.0);
    run.run_for(3.0)?;
    let start = run.seconds() as f32;
    run.command(top);
    let (_, gait) = run.sample()?;
    let mut last = gait.last_touchdown_s;
    let mut previous: Option<(f32, Vec2)> = None;
    let mut rising_from: Option<(f32, f32)> = None;
    while run.seconds() < f64::from(start) + 20.0 {
        let (tick, gait) = run.advance()?;
        if gait.last_touchdown_s == last {
            continue;
        }
        last = gait.last_touchdown_s;
        if let Some((t0, p0)) = previous {
            // The step-averaged speed belongs to the middle of the hop.
            let (t, speed) = ((t0 + tick.t) / 2.0, (tick.position.x - p0.x) / (tick.t - t0));
            match rising_from {
                None if speed >= 0.1 * top => rising_from = Some((t, speed)),
                Some((ta, va)) if speed >= 0.7 * top => return Ok((speed - va) / (t - ta)),
                _ => {}
            }
        }
        previous = Some((tick.t, tick.position));
    }
    Err(LabError::Invalid(format!(
        "the rigid model never reached 70 % of {top} m/s in 20 s"
    )))
}

/// Records the table of `kind` (which must have a rigid model in `config`).
pub fn record(config: &SimConfig, kind: &str, settings: &RecordSettings) -> Result<GaitTable, LabError> {
    let def = &config.kinds[config
        .kind_index(kind)
        .ok_or_else(|| LabError::Invalid(format!("no creature kind {kind:?} in the scenario")))?];
    let steps = def.stance.steps_per_stride(def.legs.len());
    let rows = settings
        .speeds_m_per_s
        .iter()
        .map(|&v| record_row(config, def, steps, v, settings))
        .collect::<Result<Vec<_>, _>>()?;
    let top = rows.iter().map(|r| r.speed_m_per_s).fold(0.0, f32::max);
    Ok(GaitTable {
        creature: kind.to_owned(),
        sample_hz: settings.sample_hz,
        steps_per_stride: steps,
        columns: columns(def.legs.len()),
        acceleration_limit_m_per_s2: measure_acceleration(config, def, top)?,
        top_speed_m_per_s: top,
        rows,
    })
}

/// The table as a RON file, with a header saying how it was made.
pub fn to_file_text(table: &GaitTable, command: &str) -> String {
    let pretty = ron::ser::PrettyConfig::new().depth_limit(4).struct_names(false);
    let body = ron::ser::to_string_pretty(table, pretty).expect("a gait table serialises");
    let mut text = String::new();
    let _ = writeln!(text, "// Gait table recorded from the rigid model by:");
    let _ = writeln!(text, "//     {command}");
    let _ = writeln!(
        text,
        "// Do not edit by hand: run the command again (same files, same table)."
    );
    let _ = writeln!(text, "// Columns of each sample: {}.", table.columns.join(", "));
    text.push_str(&body);
    text.push('\n');
    text
}
