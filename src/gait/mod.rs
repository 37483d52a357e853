//! The gait table (paper section 3.2): body and leg pose recorded from the rigid model at a
//! few steady speeds, one hop from touchdown to touchdown at 30 samples a second, and looked
//! up by linear interpolation in speed and in phase.

pub mod record;

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::config::{RonAssetLoader, Validate, Validator, number};

/// The pose columns of a sample, in order.
pub const COLUMNS: [&str; 6] = [
    "body_height_m",
    "roll_rad",
    "pitch_rad",
    "leg_length_m",
    "leg_forward_rad",
    "leg_sideways_rad",
];

/// The range each column is checked against: heights and lengths 0 to 20 m, angles within a
/// half turn.
const COLUMN_RANGES: [std::ops::RangeInclusive<f32>; 6] = [
    0.0..=20.0,
    -std::f32::consts::PI..=std::f32::consts::PI,
    -std::f32::consts::PI..=std::f32::consts::PI,
    0.0..=20.0,
    -std::f32::consts::PI..=std::f32::consts::PI,
    -std::f32::consts::PI..=std::f32::consts::PI,
];

/// A body and leg pose: what the hybrid level draws and the rigid level starts from.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct GaitPose {
    /// Height of the hip (body centre) above the ground.
    pub body_height_m: f32,
    /// Body roll and pitch about its forward and sideways axes.
    pub roll_rad: f32,
    pub pitch_rad: f32,
    /// Hip to foot centre.
    pub leg_length_m: f32,
    /// Leg angle from vertical toward the body's front, and toward its left side.
    pub leg_forward_rad: f32,
    pub leg_sideways_rad: f32,
}

impl GaitPose {
    fn from_row(row: &[f32]) -> Self {
        Self {
            body_height_m: row[0],
            roll_rad: row[1],
            pitch_rad: row[2],
            leg_length_m: row[3],
            leg_forward_rad: row[4],
            leg_sideways_rad: row[5],
        }
    }

    pub fn to_row(self) -> [f32; 6] {
        [
            self.body_height_m,
            self.roll_rad,
            self.pitch_rad,
            self.leg_length_m,
            self.leg_forward_rad,
            self.leg_sideways_rad,
        ]
    }

    /// The body's rotation when it faces `heading` on the plane: yaw, then pitch, then roll
    /// (what [`crate::models::rigid::rigid_pose`] reads back). Rapier's body frame: x forward,
    /// y up, z to the right.
    pub fn body_rotation(&self, heading: Vec2) -> Quat {
        Quat::from_euler(
            EulerRot::YZX,
            -heading.y.atan2(heading.x),
            self.pitch_rad,
            self.roll_rad,
        )
    }

    /// Unit vector from hip to foot in the body's frame.
    pub fn leg_direction(&self) -> Vec3 {
        Vec3::new(self.leg_forward_rad.tan(), -1.0, -self.leg_sideways_rad.tan()).normalize()
    }

    /// The leg's rotation at the hip from hanging straight down, in the body's frame.
    pub fn hip_rotation(&self) -> Quat {
        Quat::from_rotation_arc(Vec3::NEG_Y, self.leg_direction())
    }

    fn lerp(self, other: Self, t: f32) -> Self {
        let (a, b) = (self.to_row(), other.to_row());
        Self::from_row(&std::array::from_fn::<f32, 6, _>(|i| a[i] + (b[i] - a[i]) * t))
    }
}

/// One steady speed's hop.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaitRow {
    /// The steady forward speed the rigid model ran at (measured); 0 to 50 m/s.
    pub speed_m_per_s: f32,
    /// Touchdown to touchdown; 0.05 to 10 s.
    pub hop_period_s: f32,
    /// Part of the hop on the ground, from touchdown; 0 to 1.
    pub stance_fraction: f32,
    /// Poses from touchdown on, at `sample_hz`; each has the [`COLUMNS`], heights and lengths
    /// 0 to 20 m, angles -pi to pi rad.
    pub samples: Vec<Vec<f32>>,
}

/// A creature kind's gait table: `assets/gaits/<kind>.ron`, written by `simlod record-gait`.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaitTable {
    pub creature: String,
    /// 1 to 1000 Hz.
    pub sample_hz: f32,
    /// The names of a sample's values, in order: must be [`COLUMNS`].
    pub columns: Vec<String>,
    /// The rigid model's effective limits, which the point mass of the lower levels matches:
    /// 0.01 to 1000 m/s^2 and 0.01 to 50 m/s.
    pub acceleration_limit_m_per_s2: f32,
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
        v.require(
            self.columns.iter().map(String::as_str).eq(COLUMNS),
            "columns",
            format!("must be {COLUMNS:?}, got {:?}", self.columns),
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
                    if sample.len() != COLUMNS.len() {
                        v.fail(
                            &format!("samples[{j}]"),
                            format!(
                                "has {} values; every sample has {} ({})",
                                sample.len(),
                                COLUMNS.len(),
                                COLUMNS.join(", ")
                            ),
                        );
                    } else if let Some(k) = (0..COLUMNS.len()).find(|&k| !(COLUMN_RANGES[k].contains(&sample[k]))) {
                        let r = &COLUMN_RANGES[k];
                        v.fail(
                            &format!("samples[{j}]"),
                            format!(
                                "{} is {}: must be between {} and {}",
                                COLUMNS[k],
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
    /// The pose at `cycle` (0..1 from touchdown), between samples and across the wrap.
    fn pose(&self, cycle: f32, sample_hz: f32) -> GaitPose {
        let n = self.samples.len();
        // Sample k was taken at k / sample_hz; as a share of the hop that is k / (period * hz).
        let per_hop = self.hop_period_s * sample_hz;
        let x = (cycle.rem_euclid(1.0) * per_hop).min(n as f32);
        let k = (x.floor() as usize).min(n - 1);
        let next = (k + 1) % n;
        // The last interval runs from the last sample to the next touchdown (sample 0).
        let width = if next == 0 { (per_hop - k as f32).max(1e-3) } else { 1.0 };
        let t = ((x - k as f32) / width).clamp(0.0, 1.0);
        GaitPose::from_row(&self.samples[k]).lerp(GaitPose::from_row(&self.samples[next]), t)
    }
}

impl GaitTable {
    /// The pose at `speed` and hop `cycle` (0..1 from touchdown).
    pub fn pose(&self, speed: f32, cycle: f32) -> GaitPose {
        let (a, b, t) = bracket(&self.rows, speed);
        a.pose(cycle, self.sample_hz).lerp(b.pose(cycle, self.sample_hz), t)
    }

    /// Hop period and stance share at `speed`.
    pub fn rhythm(&self, speed: f32) -> (f32, f32) {
        let (a, b, t) = bracket(&self.rows, speed);
        (
            a.hop_period_s + (b.hop_period_s - a.hop_period_s) * t,
            a.stance_fraction + (b.stance_fraction - a.stance_fraction) * t,
        )
    }
}

pub(super) fn plugin(app: &mut App) {
    if app.is_plugin_added::<bevy::asset::AssetPlugin>() {
        app.init_asset::<GaitTable>()
            .init_asset_loader::<RonAssetLoader<GaitTable>>();
    }
}
