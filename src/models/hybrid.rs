//! The hybrid kinematic/dynamic level (paper section 3.2): the point mass of
//! [`super::point_mass`] moves the body on the plane; height, roll, pitch, leg length and
//! hip angles come from the gait table by linear interpolation in speed and in phase. The
//! hop cycle advances at the table's hop period for the current speed ("the running
//! frequency is nearly independent of forward velocity").

use crate::creature::GaitPhase;
use crate::gait::{GaitPose, GaitTable};

/// Advances the gait at the table's rhythm for `speed` and poses the body and legs from it.
pub fn play_gait(gait: &mut GaitPhase, pose: &mut GaitPose, table: &GaitTable, speed: f32, now_s: f32, dt: f32) {
    let (period, stance) = table.rhythm(speed);
    gait.advance(period, stance, table.steps_per_stride, now_s, dt);
    *pose = table.pose(speed, gait.stride(table.steps_per_stride));
}
