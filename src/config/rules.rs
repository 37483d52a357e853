//! The level rules (paper 3.4): `assets/rules/levels.ron`.

use super::{Validate, Validator};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelRules {
    pub influence: InfluenceRules,
    pub camera: CameraRules,
    pub release_margin_m: f32,
    /// To leave the camera's view a creature must be this much further outside its cone.
    pub release_margin_deg: f32,
    pub min_dwell_s: f32,
    /// Start and end of the switching window, as parts of the flight phase.
    pub flight_window: (f32, f32),
    /// How long what is drawn takes to blend from the old level's motion into the new one's
    /// after a switch (inertialization); 0 draws the switch as it happens.
    pub blend_s: f32,
}

/// Areas of influence (figure 5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InfluenceRules {
    pub puck_radius_m: f32,
    pub creature_radius_m: f32,
    pub lookahead_s: f32,
    pub wall_band_m: f32,
}

/// The camera rule (figure 6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraRules {
    pub radius_m: f32,
    pub field_of_view_deg: f32,
    pub follow_distance_m: f32,
}

impl Validate for LevelRules {
    fn validate(&self, v: &mut Validator) {
        v.nested("influence", |v| {
            v.non_negative("puck_radius_m", self.influence.puck_radius_m);
            v.non_negative("creature_radius_m", self.influence.creature_radius_m);
            v.non_negative("lookahead_s", self.influence.lookahead_s);
            v.non_negative("wall_band_m", self.influence.wall_band_m);
        });
        v.nested("camera", |v| {
            v.non_negative("radius_m", self.camera.radius_m);
            v.within("field_of_view_deg", self.camera.field_of_view_deg, 1.0, 179.0);
            v.non_negative("follow_distance_m", self.camera.follow_distance_m);
        });
        v.non_negative("release_margin_m", self.release_margin_m);
        v.within("release_margin_deg", self.release_margin_deg, 0.0, 90.0);
        v.non_negative("min_dwell_s", self.min_dwell_s);
        v.within("blend_s", self.blend_s, 0.0, 2.0);
        let (a, b) = self.flight_window;
        v.within("flight_window.0", a, 0.0, 1.0);
        v.within("flight_window.1", b, 0.0, 1.0);
        v.require(
            a < b,
            "flight_window",
            format!("must start before it ends, got ({a}, {b})"),
        );
    }
}
