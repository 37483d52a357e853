//! A creature definition: `assets/creatures/<kind>.ron`.

use super::{Validate, Validator};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// One kind of legged creature (the one-legged hopper, the biped, or a modder's own).
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreatureDef {
    /// The kind's name; must match the file name (`creatures/<name>.ron`).
    pub name: String,
    pub body: BodyConfig,
    /// Planar speed limit of the point mass (paper 3.2).
    pub top_speed_m_per_s: f32,
    /// Planar acceleration limit of the point mass (paper 3.2).
    pub acceleration_limit_m_per_s2: f32,
    /// Touchdown to touchdown.
    pub hop_period_s: f32,
    /// Part of the hop cycle spent in the air, after stance (0..1).
    pub flight_fraction: f32,
    /// At the point-mass level there is no balance to lose: a creature falls when an impact's
    /// normal speed exceeds this.
    pub fall_impact_speed_m_per_s: f32,
    /// Share of the normal impact speed kept after a point-mass collision (0 = dead stop).
    pub collision_restitution: f32,
    pub steering: SteeringConfig,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyConfig {
    /// Radius of the creature's footprint on the ground: its collision circle.
    pub radius_m: f32,
    /// Height of the hip above the ground while standing.
    pub hip_height_m: f32,
    pub mass_kg: f32,
}

/// How the creature picks its desired velocity (paper 3: escape the puck, avoid walls and
/// other creatures). Weights are relative; the sum is scaled to the top speed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteeringConfig {
    /// Speed of undisturbed wandering.
    pub cruise_speed_m_per_s: f32,
    /// Largest rate at which the wandering heading drifts.
    pub wander_turn_rad_per_s: f32,
    /// The creature flees when this close to the puck's path over the look-ahead.
    pub puck_alert_distance_m: f32,
    /// How far ahead the puck's path is predicted.
    pub puck_lookahead_s: f32,
    pub puck_weight: f32,
    /// Walls repel within this distance.
    pub wall_avoid_distance_m: f32,
    pub wall_weight: f32,
    /// Other creatures repel within this distance (centre to centre).
    pub separation_distance_m: f32,
    pub separation_weight: f32,
}

impl Validate for CreatureDef {
    fn validate(&self, v: &mut Validator) {
        v.require(
            !self.name.is_empty()
                && self
                    .name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-'),
            "name",
            format!(
                "must be a non-empty name of letters, digits, '-' or '_', got {:?}",
                self.name
            ),
        );
        v.nested("body", |v| {
            v.positive("radius_m", self.body.radius_m);
            v.positive("hip_height_m", self.body.hip_height_m);
            v.positive("mass_kg", self.body.mass_kg);
        });
        v.positive("top_speed_m_per_s", self.top_speed_m_per_s);
        v.positive("acceleration_limit_m_per_s2", self.acceleration_limit_m_per_s2);
        v.positive("hop_period_s", self.hop_period_s);
        v.within("flight_fraction", self.flight_fraction, 0.05, 0.95);
        v.positive("fall_impact_speed_m_per_s", self.fall_impact_speed_m_per_s);
        v.within("collision_restitution", self.collision_restitution, 0.0, 1.0);
        let s = &self.steering;
        v.nested("steering", |v| {
            v.non_negative("cruise_speed_m_per_s", s.cruise_speed_m_per_s);
            v.non_negative("wander_turn_rad_per_s", s.wander_turn_rad_per_s);
            v.non_negative("puck_alert_distance_m", s.puck_alert_distance_m);
            v.non_negative("puck_lookahead_s", s.puck_lookahead_s);
            v.non_negative("puck_weight", s.puck_weight);
            v.non_negative("wall_avoid_distance_m", s.wall_avoid_distance_m);
            v.non_negative("wall_weight", s.wall_weight);
            v.non_negative("separation_distance_m", s.separation_distance_m);
            v.non_negative("separation_weight", s.separation_weight);
            v.require(
                s.cruise_speed_m_per_s.is_nan() || s.cruise_speed_m_per_s <= self.top_speed_m_per_s,
                "cruise_speed_m_per_s",
                format!("must not exceed top_speed_m_per_s ({})", self.top_speed_m_per_s),
            );
        });
    }
}
