//! The hybrid kinematic/dynamic level (paper section 3.2): the point mass of
//! [`super::point_mass`] moves the body on the plane; height, roll, pitch, leg length and
//! hip angles come from the gait table by linear interpolation in speed and in phase. The
//! hop cycle advances at the table's hop period for the current speed ("the running
//! frequency is nearly independent of forward velocity").

use crate::config::gait::AtSpeed;
use crate::contract::GaitPhase;
use crate::contract::GaitPose;

/// The body and legs at the table's speed and the gait's place in its stride: a function of
/// the two alone, so it is worked out only for the ticks something reads it.
pub fn pose(gait: &GaitPhase, table: &AtSpeed, steps_per_stride: u32) -> GaitPose {
    table.pose(gait.stride(steps_per_stride))
}
