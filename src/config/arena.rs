//! The court and the puck (paper section 3): `assets/arena.ron`.

use super::{Validate, Validator};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// A rectangular court closed by walls, with one giant puck in it. Each field's comment
/// gives the range it is checked against when loaded: what makes physical sense here.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArenaConfig {
    /// Inside length of the court along x; 1 to 10,000 m.
    pub court_length_m: f32,
    /// Inside width of the court along z; 1 to 10,000 m.
    pub court_width_m: f32,
    /// Height of the walls; 0.1 to 100 m.
    pub wall_height_m: f32,
    /// Thickness of the walls; 0.01 to 100 m.
    pub wall_thickness_m: f32,
    /// The giant puck.
    pub puck: PuckConfig,
    /// A respawned creature starts at least this far from the puck's rim when it can; 0 to
    /// 10,000 m.
    pub respawn_puck_clearance_m: f32,
    /// ... and at least this far from any other creature when it can; 0 to 100 m.
    pub respawn_creature_clearance_m: f32,
}

/// The giant puck: a frictionless rapier body that keeps its speed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PuckConfig {
    /// 0.05 to 1000 m.
    pub radius_m: f32,
    /// 0.01 to 100 m.
    pub height_m: f32,
    /// 0.1 to 1,000,000 kg (a creature weighs about 10).
    pub mass_kg: f32,
    /// Constant sliding speed; above the creatures' top speed, so it is a threat. 0.01 to 50
    /// m/s: at the slowest tick (30 Hz) it then moves at most 1.7 m a tick.
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
        v.range("court_length_m", self.court_length_m, 1.0, MAX_COURT_SIDE_M);
        v.range("court_width_m", self.court_width_m, 1.0, MAX_COURT_SIDE_M);
        v.range("wall_height_m", self.wall_height_m, 0.1, 100.0);
        v.range("wall_thickness_m", self.wall_thickness_m, 0.01, 100.0);
        v.range(
            "respawn_puck_clearance_m",
            self.respawn_puck_clearance_m,
            0.0,
            MAX_COURT_SIDE_M,
        );
        v.range(
            "respawn_creature_clearance_m",
            self.respawn_creature_clearance_m,
            0.0,
            100.0,
        );
        v.nested("puck", |v| {
            v.range("radius_m", self.puck.radius_m, 0.05, 1000.0);
            v.range("height_m", self.puck.height_m, 0.01, 100.0);
            v.range("mass_kg", self.puck.mass_kg, 0.1, 1e6);
            v.range("speed_m_per_s", self.puck.speed_m_per_s, 0.01, 50.0);
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
