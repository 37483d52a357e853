//! The court and the puck (paper section 3): `assets/arena.ron`.

use super::{Validate, Validator};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// A rectangular court closed by walls, with one giant puck in it.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArenaConfig {
    /// Inside length of the court along x.
    pub court_length_m: f32,
    /// Inside width of the court along z.
    pub court_width_m: f32,
    pub wall_height_m: f32,
    pub wall_thickness_m: f32,
    pub puck: PuckConfig,
    /// A respawned creature starts at least this far from the puck's rim when it can.
    pub respawn_puck_clearance_m: f32,
    /// ... and at least this far from any other creature when it can.
    pub respawn_creature_clearance_m: f32,
}

/// The giant puck: a frictionless rapier body that keeps its speed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PuckConfig {
    pub radius_m: f32,
    pub height_m: f32,
    pub mass_kg: f32,
    /// Constant sliding speed; above the creatures' top speed, so it is a threat.
    pub speed_m_per_s: f32,
}

impl ArenaConfig {
    /// Half the inside extents of the court on the ground plane (x, z).
    pub fn half_extents(&self) -> Vec2 {
        Vec2::new(self.court_length_m, self.court_width_m) * 0.5
    }
}

/// The longest side of a court: the neighbour grid covers the whole court with cells of a
/// few metres, so a larger one would take gigabytes (10 km holds a million creatures at the
/// default scenario's density).
pub const MAX_COURT_SIDE_M: f32 = 10_000.0;

impl Validate for ArenaConfig {
    fn validate(&self, v: &mut Validator) {
        for (field, side) in [
            ("court_length_m", self.court_length_m),
            ("court_width_m", self.court_width_m),
        ] {
            v.positive(field, side);
            v.require(
                side.is_nan() || side <= MAX_COURT_SIDE_M,
                field,
                format!("must be at most {MAX_COURT_SIDE_M} m, got {side}"),
            );
        }
        v.positive("wall_height_m", self.wall_height_m);
        v.positive("wall_thickness_m", self.wall_thickness_m);
        v.non_negative("respawn_puck_clearance_m", self.respawn_puck_clearance_m);
        v.non_negative("respawn_creature_clearance_m", self.respawn_creature_clearance_m);
        v.nested("puck", |v| {
            v.positive("radius_m", self.puck.radius_m);
            v.positive("height_m", self.puck.height_m);
            v.positive("mass_kg", self.puck.mass_kg);
            v.positive("speed_m_per_s", self.puck.speed_m_per_s);
        });
        let smallest_side = self.court_length_m.min(self.court_width_m);
        v.require(
            !(smallest_side > 0.0 && self.puck.radius_m > 0.0) || smallest_side > 2.0 * self.puck.radius_m,
            "puck.radius_m",
            format!(
                "the puck (diameter {} m) does not fit in the court ({} x {} m)",
                2.0 * self.puck.radius_m,
                self.court_length_m,
                self.court_width_m
            ),
        );
    }
}
