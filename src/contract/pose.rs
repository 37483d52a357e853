//! The pose every level publishes: the body's height and attitude and each leg's pose, drawn
//! the same way whatever the level.

use bevy::prelude::*;

/// The most legs a kind may have (the pose keeps them in a fixed array: no allocation per tick).
pub const MAX_LEGS: usize = 4;

/// One leg's pose, from its hip.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegPose {
    /// Hip to foot centre.
    pub length_m: f32,
    /// Leg angle from vertical toward the body's front, and toward its left side.
    pub forward_rad: f32,
    /// Leg angle from vertical toward the body's left side.
    pub sideways_rad: f32,
}

impl LegPose {
    /// Hanging straight down at `length_m`.
    pub fn straight(length_m: f32) -> Self {
        Self { length_m, ..default() }
    }

    /// Unit vector from hip to foot in the body's frame.
    pub fn direction(&self) -> Vec3 {
        Vec3::new(self.forward_rad.tan(), -1.0, -self.sideways_rad.tan()).normalize()
    }

    /// The leg's rotation at the hip from hanging straight down, in the body's frame.
    pub fn hip_rotation(&self) -> Quat {
        Quat::from_rotation_arc(Vec3::NEG_Y, self.direction())
    }

    /// The pose of a leg whose foot is at `to_foot` from its hip, in the body's frame.
    pub fn toward(to_foot: Vec3) -> Self {
        Self {
            length_m: to_foot.length(),
            forward_rad: to_foot.x.atan2(-to_foot.y),
            sideways_rad: (-to_foot.z).atan2(-to_foot.y),
        }
    }

    /// The pose a fraction `t` of the way from this one to `other`.
    pub fn lerp(self, other: Self, t: f32) -> Self {
        Self {
            length_m: self.length_m + (other.length_m - self.length_m) * t,
            forward_rad: self.forward_rad + (other.forward_rad - self.forward_rad) * t,
            sideways_rad: self.sideways_rad + (other.sideways_rad - self.sideways_rad) * t,
        }
    }
}

/// The pose every level publishes: the body, then each leg. What the game draws, the
/// recorder records, the hybrid plays back and the rigid level starts from.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct GaitPose {
    /// Height of the body's centre above the ground.
    pub body_height_m: f32,
    /// Body roll and pitch about its forward and sideways axes.
    pub roll_rad: f32,
    /// Body pitch about its sideways axis.
    pub pitch_rad: f32,
    /// The legs in the kind's order: the first `leg_count` are its legs (a fixed array, so a
    /// pose is copied, never allocated).
    legs: [LegPose; MAX_LEGS],
    leg_count: u8,
}

impl GaitPose {
    /// The body at `body_height_m`, level, on `legs` (at most [`MAX_LEGS`]; more are dropped).
    pub fn new(body_height_m: f32, roll_rad: f32, pitch_rad: f32, legs: &[LegPose]) -> Self {
        let n = legs.len().min(MAX_LEGS);
        let mut pose = Self {
            body_height_m,
            roll_rad,
            pitch_rad,
            legs: [LegPose::default(); MAX_LEGS],
            leg_count: n as u8,
        };
        pose.legs[..n].copy_from_slice(&legs[..n]);
        pose
    }

    /// The creature's legs, in its kind's order.
    pub fn legs(&self) -> &[LegPose] {
        &self.legs[..usize::from(self.leg_count)]
    }

    /// The creature's legs, to change.
    pub fn legs_mut(&mut self) -> &mut [LegPose] {
        &mut self.legs[..usize::from(self.leg_count)]
    }

    /// From a table's sample: the [`crate::config::gait::BODY_COLUMNS`], then each leg's [`crate::config::gait::LEG_COLUMNS`].
    pub fn from_row(row: &[f32]) -> Self {
        let mut pose = Self::new(row[0], row[1], row[2], &[]);
        for leg in row[3..].chunks_exact(3).take(MAX_LEGS) {
            pose.legs[usize::from(pose.leg_count)] = LegPose {
                length_m: leg[0],
                forward_rad: leg[1],
                sideways_rad: leg[2],
            };
            pose.leg_count += 1;
        }
        pose
    }

    /// As a table's sample (see [`crate::config::gait::columns`]).
    pub fn to_row(&self) -> Vec<f32> {
        [self.body_height_m, self.roll_rad, self.pitch_rad]
            .into_iter()
            .chain(
                self.legs()
                    .iter()
                    .flat_map(|l| [l.length_m, l.forward_rad, l.sideways_rad]),
            )
            .collect()
    }

    /// The body's rotation when it faces `heading` on the plane: yaw, then pitch, then roll
    /// (what [`GaitPose::of_bodies`] reads back). Rapier's body frame: x forward, y up, z to
    /// the right.
    pub fn body_rotation(&self, heading: Vec2) -> Quat {
        Quat::from_euler(
            EulerRot::YZX,
            -heading.y.atan2(heading.x),
            self.pitch_rad,
            self.roll_rad,
        )
    }

    /// The pose of a body at `body` whose legs, with hips at `hips` on the body, reach their
    /// feet at `feet` (world positions).
    pub fn of_bodies(body: &Transform, hips: &[Vec3], feet: impl IntoIterator<Item = Vec3>) -> Self {
        let (_, pitch, roll) = body.rotation.to_euler(EulerRot::YZX);
        let to_body = body.rotation.inverse();
        let mut pose = Self::new(body.translation.y, roll, pitch, &[]);
        for (hip, foot) in hips.iter().zip(feet).take(MAX_LEGS) {
            pose.legs[usize::from(pose.leg_count)] = LegPose::toward(to_body * (foot - body.translation) - *hip);
            pose.leg_count += 1;
        }
        pose
    }

    /// The pose a fraction `t` of the way from this one to `other`, leg by leg.
    pub fn lerp(self, other: Self, t: f32) -> Self {
        let mut pose = Self {
            body_height_m: self.body_height_m + (other.body_height_m - self.body_height_m) * t,
            roll_rad: self.roll_rad + (other.roll_rad - self.roll_rad) * t,
            pitch_rad: self.pitch_rad + (other.pitch_rad - self.pitch_rad) * t,
            ..self
        };
        for (leg, o) in pose.legs_mut().iter_mut().zip(other.legs()) {
            *leg = leg.lerp(*o, t);
        }
        pose
    }
}
