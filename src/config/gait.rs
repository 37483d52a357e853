//! The gait table (paper section 3.2): body and leg pose recorded from the rigid model at a
//! few steady speeds, one hop from touchdown to touchdown at 30 samples a second, and looked
//! up by linear interpolation in speed and in phase.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::config::{Validate, Validator, number};

pub use crate::contract::{GaitPose, LegPose, MAX_LEGS};

/// The body's columns of a sample, in order; each leg's [`LEG_COLUMNS`] follow.
pub const BODY_COLUMNS: [&str; 3] = ["body_height_m", "roll_rad", "pitch_rad"];
/// Each leg's columns of a sample, in order, named `legs[i].<column>`.
pub const LEG_COLUMNS: [&str; 3] = ["length_m", "forward_rad", "sideways_rad"];

/// The columns of a gait table for a kind with `legs` legs.
pub fn columns(legs: usize) -> Vec<String> {
    BODY_COLUMNS
        .iter()
        .map(|c| (*c).to_owned())
        .chain((0..legs).flat_map(|i| LEG_COLUMNS.iter().map(move |c| format!("legs[{i}].{c}"))))
        .collect()
}

/// The range a column is checked against: heights and lengths 0 to 20 m, angles within a
/// half turn.
fn column_range(column: &str) -> std::ops::RangeInclusive<f32> {
    if column.ends_with("_m") {
        0.0..=20.0
    } else {
        -std::f32::consts::PI..=std::f32::consts::PI
    }
}

/// One steady speed's stride: one hop of a hopper, a step of each leg of a biped.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaitRow {
    /// The steady forward speed the rigid model ran at (measured); 0 to 50 m/s.
    pub speed_m_per_s: f32,
    /// Touchdown to touchdown: one step; 0.05 to 10 s.
    pub hop_period_s: f32,
    /// Part of each step on the ground, from touchdown; 0 to 1.
    pub stance_fraction: f32,
    /// Poses from the first leg's touchdown on, over the stride, at `sample_hz`; each has the
    /// table's `columns`: heights and lengths 0 to 20 m, angles -pi to pi rad.
    pub samples: Vec<Vec<f32>>,
}

/// A creature kind's gait table: `assets/gaits/<kind>.ron`, written by `simlod record-gait`.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaitTable {
    /// The creature kind it was recorded from.
    pub creature: String,
    /// 1 to 1000 Hz.
    pub sample_hz: f32,
    /// Steps in a stride: one for each of the kind's virtual legs (1 for legs in stance together).
    pub steps_per_stride: u32,
    /// The names of a sample's values, in order: [`columns`] of the kind's leg count.
    pub columns: Vec<String>,
    /// The rigid model's effective limits, which the point mass of the lower levels matches:
    /// 0.01 to 1000 m/s^2 and 0.01 to 50 m/s.
    pub acceleration_limit_m_per_s2: f32,
    /// The rigid model's top speed (see `acceleration_limit_m_per_s2`).
    pub top_speed_m_per_s: f32,
    /// In increasing order of speed.
    pub rows: Vec<GaitRow>,
}

impl Validate for GaitTable {
    fn validate(&self, v: &mut Validator) {
        v.range("sample_hz", self.sample_hz, 1.0, 1000.0);
        v.range(
            "acceleration_limit_m_per_s2",
            self.acceleration_limit_m_per_s2,
            0.01,
            1000.0,
        );
        v.range("top_speed_m_per_s", self.top_speed_m_per_s, 0.01, 50.0);
        let legs = self.leg_count();
        v.require(
            (1..=MAX_LEGS).contains(&legs) && self.columns == columns(legs),
            "columns",
            format!(
                "must be the body's then each leg's columns ({:?} for one leg), got {:?}",
                columns(1),
                self.columns
            ),
        );
        v.require(
            (1..=MAX_LEGS as u32).contains(&self.steps_per_stride),
            "steps_per_stride",
            format!("must be 1 to {MAX_LEGS}, got {}", self.steps_per_stride),
        );
        v.require(
            !self.rows.is_empty(),
            "rows",
            "the table is empty: it needs at least one speed",
        );
        for (i, row) in self.rows.iter().enumerate() {
            v.nested(&format!("rows[{i}]"), |v| {
                v.range("speed_m_per_s", row.speed_m_per_s, 0.0, 50.0);
                v.range("hop_period_s", row.hop_period_s, 0.05, 10.0);
                v.range("stance_fraction", row.stance_fraction, 0.0, 1.0);
                v.require(!row.samples.is_empty(), "samples", "has no samples");
                for (j, sample) in row.samples.iter().enumerate() {
                    if sample.len() != self.columns.len() {
                        v.fail(
                            &format!("samples[{j}]"),
                            format!(
                                "has {} values; every sample has {} ({})",
                                sample.len(),
                                self.columns.len(),
                                self.columns.join(", ")
                            ),
                        );
                    } else if let Some((k, r)) = self
                        .columns
                        .iter()
                        .map(|c| column_range(c))
                        .enumerate()
                        .find(|(k, r)| !r.contains(&sample[*k]))
                    {
                        v.fail(
                            &format!("samples[{j}]"),
                            format!(
                                "{} is {}: must be between {} and {}",
                                self.columns[k],
                                number(sample[k]),
                                number(*r.start()),
                                number(*r.end())
                            ),
                        );
                    }
                }
            });
        }
        v.require(
            self.rows.windows(2).all(|w| w[0].speed_m_per_s < w[1].speed_m_per_s),
            "rows",
            "speeds must be in increasing order",
        );
    }
}

/// The two rows around `speed` and the weight of the second (clamped to the table's range).
fn bracket(rows: &[GaitRow], speed: f32) -> (&GaitRow, &GaitRow, f32) {
    let upper = rows
        .iter()
        .position(|r| r.speed_m_per_s >= speed)
        .unwrap_or(rows.len() - 1);
    let lower = upper.saturating_sub(1);
    let (a, b) = (&rows[lower], &rows[upper]);
    let span = b.speed_m_per_s - a.speed_m_per_s;
    let t = if span > 0.0 {
        ((speed - a.speed_m_per_s) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a, b, t)
}

impl GaitRow {
    /// The two samples around `stride` (0..1 from the first leg's touchdown, across the
    /// wrap) and the weight of the second.
    fn samples_at(&self, stride: f32, steps: u32, sample_hz: f32) -> (&[f32], &[f32], f32) {
        let n = self.samples.len();
        // Sample k was taken at k / sample_hz; as a share of the stride that is
        // k / (stride period * hz).
        let per_hop = self.hop_period_s * steps as f32 * sample_hz;
        // Both as the wrap and the floor would give, without their library calls (a hybrid
        // looks its pose up every tick).
        let stride = if (0.0..1.0).contains(&stride) {
            stride
        } else {
            stride.rem_euclid(1.0)
        };
        let x = (stride * per_hop).min(n as f32);
        let k = (x as usize).min(n - 1);
        let next = (k + 1) % n;
        // The last interval runs from the last sample to the next touchdown (sample 0).
        let width = if next == 0 { (per_hop - k as f32).max(1e-3) } else { 1.0 };
        let t = ((x - k as f32) / width).clamp(0.0, 1.0);
        (&self.samples[k], &self.samples[next], t)
    }
}

impl GaitTable {
    /// The legs its samples pose.
    pub fn leg_count(&self) -> usize {
        self.columns.len().saturating_sub(BODY_COLUMNS.len()) / LEG_COLUMNS.len()
    }

    /// The pose at `speed` and `stride` phase (0..1 from the first leg's touchdown; see
    /// [`crate::creature::GaitPhase::stride`]): each column interpolated in phase within the
    /// two rows around `speed`, then in speed between them.
    pub fn pose(&self, speed: f32, stride: f32) -> GaitPose {
        self.at(speed).pose(stride)
    }

    /// Hop period and stance share at `speed`.
    pub fn rhythm(&self, speed: f32) -> (f32, f32) {
        self.at(speed).rhythm()
    }

    /// The table at `speed`: the rows around it, found once for both its rhythm and its pose.
    pub fn at(&self, speed: f32) -> AtSpeed<'_> {
        let (lower, upper, t) = bracket(&self.rows, speed);
        AtSpeed {
            table: self,
            lower,
            upper,
            t,
        }
    }
}

/// A gait table at one speed: the two rows around it and the weight of the upper.
#[derive(Clone, Copy, Debug)]
pub struct AtSpeed<'a> {
    table: &'a GaitTable,
    lower: &'a GaitRow,
    upper: &'a GaitRow,
    t: f32,
}

impl AtSpeed<'_> {
    /// Hop period and stance share.
    pub fn rhythm(&self) -> (f32, f32) {
        let (a, b, t) = (self.lower, self.upper, self.t);
        (
            a.hop_period_s + (b.hop_period_s - a.hop_period_s) * t,
            a.stance_fraction + (b.stance_fraction - a.stance_fraction) * t,
        )
    }

    /// The pose at `stride` phase: each column interpolated in phase within the two rows, then
    /// in speed between them.
    pub fn pose(&self, stride: f32) -> GaitPose {
        let (a, b, t) = (self.lower, self.upper, self.t);
        let (steps, hz) = (self.table.steps_per_stride, self.table.sample_hz);
        let (a0, a1, ta) = a.samples_at(stride, steps, hz);
        let (b0, b1, tb) = b.samples_at(stride, steps, hz);
        let mut row = [0.0; BODY_COLUMNS.len() + LEG_COLUMNS.len() * MAX_LEGS];
        let columns = a0.len().min(row.len());
        let samples = a0.iter().zip(a1).zip(b0.iter().zip(b1));
        for (value, ((a0, a1), (b0, b1))) in row.iter_mut().zip(samples) {
            let at_a = a0 + (a1 - a0) * ta;
            let at_b = b0 + (b1 - b0) * tb;
            *value = at_a + (at_b - at_a) * t;
        }
        GaitPose::from_row(&row[..columns])
    }
}
