//! How the game looks: `assets/game.ron` (cameras, colours, light, HUD, creature drawing).
//! Read by the game only; the simulation never sees it.

use super::{Validate, Validator};
use crate::contract::Lod;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A colour as sRGB components in `[0, 1]`.
pub type Srgb = [f32; 3];

/// The game's looks and feel: `assets/game.ron`.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GameConfig {
    /// The player's view.
    pub camera: CameraConfig,
    /// The overhead view of the court.
    pub inset: InsetConfig,
    /// The colour of each level of detail (paper figures 5 and 6: rigid yellow, hybrid blue);
    /// every level needs one.
    pub level_colours_srgb: BTreeMap<Lod, Srgb>,
    /// The colours of everything but the creatures' bodies.
    pub scene_colours: SceneColours,
    /// How the puck is drawn.
    pub puck_look: PuckLook,
    /// The sun and the fill light.
    pub lighting: LightingConfig,
    /// The text over the game.
    pub hud: HudConfig,
    /// How creatures are drawn.
    pub creature_look: CreatureLook,
    /// How `--record` writes its animated picture.
    pub recording: RecordingConfig,
    /// The budget policy in the game. A file without it leaves the rules as they are.
    #[serde(default)]
    pub frame_budget: FrameBudgetInGame,
}

/// The budget policy in the game, where the frame rate matters more than a reproducible run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameBudgetInGame {
    /// Where the rules leave the adaptive mode off (`budget.adaptive_frames` at 0), the game
    /// corrects the cost model by its measured frames, smoothed over this many; 0 leaves it
    /// off. 0 to 10,000 frames.
    pub adaptive_frames: f32,
    /// With it, the percentile of the last frames the game keeps within the budget (see the
    /// rules' `budget.adaptive_percentile`, which says how many); 0, as a file without it,
    /// their mean.
    #[serde(default)]
    pub adaptive_percentile: f32,
    /// With a percentile, how many times the budget it is kept within, the mean frame within
    /// the budget itself (see the rules' `budget.adaptive_percentile_limit`); 1, as a file
    /// without it, the budget. 1 to 10.
    #[serde(default = "super::BudgetRules::percentile_within_the_budget")]
    pub adaptive_percentile_limit: f32,
    /// Whether the game measures the cost model on the machine that plays before its window
    /// opens (a second or two), in place of the file's, for the whole session. A file without
    /// it leaves the file's model.
    #[serde(default)]
    pub calibrate_at_start: bool,
}

/// A file without `frame_budget`: the rules as they are.
impl Default for FrameBudgetInGame {
    fn default() -> Self {
        Self {
            adaptive_frames: 0.0,
            adaptive_percentile: 0.0,
            adaptive_percentile_limit: super::BudgetRules::percentile_within_the_budget(),
            calibrate_at_start: false,
        }
    }
}

impl FrameBudgetInGame {
    /// The rules the game runs: `rules` as the files say them, with the adaptive mode on
    /// where they leave it off.
    pub fn apply(&self, rules: &mut super::LevelRules) {
        if rules.budget.adaptive_frames == 0.0 {
            rules.budget.adaptive_frames = self.adaptive_frames;
            rules.budget.adaptive_percentile = self.adaptive_percentile;
            rules.budget.adaptive_percentile_limit = self.adaptive_percentile_limit;
        }
    }
}

/// The player's view (paper figure 6, bottom): behind the player on the line from the puck,
/// so that the puck stays in view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    /// How far behind the player the camera sits, away from the puck; 0.1 to 1000 m.
    pub follow_distance_m: f32,
    /// Height of the camera above the ice; 0.1 to 1000 m.
    pub follow_height_m: f32,
    /// Where the camera aims: 0 at the player, 1 at the puck.
    pub aim_toward_puck_fraction: f32,
    /// Height of the point aimed at; below the ice (negative) tilts the view down, so the
    /// court fills more of it and the sky less.
    pub aim_height_m: f32,
    /// How fast the camera catches up with where it wants to be; 0.01 to 1000 per second.
    pub follow_rate_per_s: f32,
    /// Vertical field of view.
    pub field_of_view_deg: f32,
}

/// The overhead view of the whole court (paper figures 5 and 6, top), in a window corner.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InsetConfig {
    /// Width of the inset as a share of the window's width.
    pub width_fraction: f32,
    /// Gap between the inset and the window's edges.
    pub margin_px: f32,
    /// Ground shown around the court; 0 to 10,000 m.
    pub border_m: f32,
    /// Creatures are tiny seen from above: each gets a dot this big, seen only from above;
    /// 0.01 to 100 m.
    pub creature_dot_radius_m: f32,
    /// The player's view, drawn from above as a fan out to the camera's radius of influence
    /// (paper figure 6, top).
    pub view_cone_opacity: f32,
}

/// Colours of the scene, each sRGB in `[0, 1]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneColours {
    /// The sky, behind everything.
    pub sky_srgb: Srgb,
    /// The ice of the court.
    pub floor_srgb: Srgb,
    /// The lines drawn on the ice.
    pub court_lines_srgb: Srgb,
    /// The walls.
    pub wall_srgb: Srgb,
    /// The puck and the wedge ahead of it.
    pub puck_srgb: Srgb,
    /// Every creature's legs.
    pub leg_srgb: Srgb,
    /// Creature bodies when colouring by level is off.
    pub uncoloured_srgb: Srgb,
    /// The ring under the player's creature.
    pub player_marker_srgb: Srgb,
}

/// The puck, drawn to read as the threat: its colour is `scene_colours.puck_srgb`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PuckLook {
    /// A wedge on the ice ahead of the puck points where it goes; its tip is where the puck's
    /// front will be this long from now (0 hides it).
    pub path_ahead_s: f32,
    /// Opacity of the wedge; 0 to 1.
    pub path_opacity: f32,
}

/// The light of the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingConfig {
    /// Brightness of the sunlight; 0 to 200,000 lux.
    pub sun_illuminance_lux: f32,
    /// Height of the sun above the horizon.
    pub sun_elevation_deg: f32,
    /// Direction the sunlight comes from, around the vertical, from +x towards +z.
    pub sun_azimuth_deg: f32,
    /// Fill light everywhere, so shadows are not black; 0 to 100,000 cd/m^2.
    pub ambient_brightness_cd_per_m2: f32,
    /// Shadows are cast up to this far from the camera; 1 to 100,000 m.
    pub shadow_distance_m: f32,
}

/// The text over the game.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HudConfig {
    /// Size of the HUD's text.
    pub font_size_px: f32,
    /// The game-over banner.
    pub banner_font_size_px: f32,
    /// The HUD's frame rate and simulation time are averaged over this long; 0.01 to 60 s.
    pub smoothing_s: f32,
    /// One press of `[` `]` or `-` `=` changes a radius of influence by this much.
    pub radius_step_m: f32,
    /// One press of `9` `0` changes the budget policy's frame budget by this much.
    pub budget_step_ms: f32,
}

/// How a creature is drawn from its body size in its creature file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreatureLook {
    /// Body radius as a share of the creature's footprint radius (`body.radius_m`).
    pub body_radius_fraction: f32,
    /// The body is an ellipsoid: its length (along the heading) as a share of its width.
    pub body_length_ratio: f32,
    /// The body's height as a share of its width.
    pub body_height_ratio: f32,
    /// Thickness of the legs as drawn; 0.001 to 1 m.
    pub leg_thickness_m: f32,
    /// A nose at the front of the body shows which way a creature faces: its radius as a
    /// share of the body's.
    pub nose_radius_fraction: f32,
    /// A crest on top of the body, in the kind's colour (its file's `look`), tells the kinds
    /// apart: its radius as a share of the body's.
    pub crest_radius_fraction: f32,
    /// The crest, nose and legs are drawn within this distance of the camera, and the body
    /// alone beyond it: a crowd's far creatures cost a mesh each. 1 to 100,000 m.
    pub detail_distance_m: f32,
}

/// `simlod play --record FILE.gif --frames N`: the animated picture of a round.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordingConfig {
    /// The picture's width; its height keeps the window's shape. 64 to 4096 px.
    pub width_px: u32,
    /// One picture every this many frames (each frame is one steering decision, 1/30 s by
    /// default); 1 to 30. The picture plays at the simulation's speed either way.
    pub every_nth_frame: u32,
}

fn colour(v: &mut Validator, field: &str, c: Srgb) {
    v.nested(field, |v| {
        for (i, x) in c.into_iter().enumerate() {
            v.within(&i.to_string(), x, 0.0, 1.0);
        }
    });
}

impl Validate for GameConfig {
    fn validate(&self, v: &mut Validator) {
        let c = &self.camera;
        v.nested("camera", |v| {
            v.range("follow_distance_m", c.follow_distance_m, 0.1, 1000.0);
            v.range("follow_height_m", c.follow_height_m, 0.1, 1000.0);
            v.within("aim_toward_puck_fraction", c.aim_toward_puck_fraction, 0.0, 1.0);
            v.within("aim_height_m", c.aim_height_m, -20.0, 20.0);
            v.range("follow_rate_per_s", c.follow_rate_per_s, 0.01, 1000.0);
            v.within("field_of_view_deg", c.field_of_view_deg, 10.0, 150.0);
        });
        let i = &self.inset;
        v.nested("inset", |v| {
            v.within("width_fraction", i.width_fraction, 0.05, 0.9);
            v.within("margin_px", i.margin_px, 0.0, 200.0);
            v.range("border_m", i.border_m, 0.0, 10_000.0);
            v.range("creature_dot_radius_m", i.creature_dot_radius_m, 0.01, 100.0);
            v.within("view_cone_opacity", i.view_cone_opacity, 0.0, 1.0);
        });
        v.nested("level_colours_srgb", |v| {
            for level in Lod::ALL {
                match self.level_colours_srgb.get(&level) {
                    Some(&c) => colour(v, &format!("{level:?}"), c),
                    None => v.fail(&format!("{level:?}"), "every level needs a colour"),
                }
            }
        });
        let s = &self.scene_colours;
        v.nested("scene_colours", |v| {
            for (field, c) in [
                ("sky_srgb", s.sky_srgb),
                ("floor_srgb", s.floor_srgb),
                ("court_lines_srgb", s.court_lines_srgb),
                ("wall_srgb", s.wall_srgb),
                ("puck_srgb", s.puck_srgb),
                ("leg_srgb", s.leg_srgb),
                ("uncoloured_srgb", s.uncoloured_srgb),
                ("player_marker_srgb", s.player_marker_srgb),
            ] {
                colour(v, field, c);
            }
        });
        let p = &self.puck_look;
        v.nested("puck_look", |v| {
            v.within("path_ahead_s", p.path_ahead_s, 0.0, 10.0);
            v.within("path_opacity", p.path_opacity, 0.0, 1.0);
        });
        let l = &self.lighting;
        v.nested("lighting", |v| {
            v.range("sun_illuminance_lux", l.sun_illuminance_lux, 0.0, 200_000.0);
            v.within("sun_elevation_deg", l.sun_elevation_deg, 1.0, 90.0);
            v.within("sun_azimuth_deg", l.sun_azimuth_deg, -360.0, 360.0);
            v.range(
                "ambient_brightness_cd_per_m2",
                l.ambient_brightness_cd_per_m2,
                0.0,
                100_000.0,
            );
            v.range("shadow_distance_m", l.shadow_distance_m, 1.0, 100_000.0);
        });
        let h = &self.hud;
        v.nested("hud", |v| {
            v.within("font_size_px", h.font_size_px, 6.0, 200.0);
            v.within("banner_font_size_px", h.banner_font_size_px, 6.0, 400.0);
            v.range("smoothing_s", h.smoothing_s, 0.01, 60.0);
            v.within("radius_step_m", h.radius_step_m, 0.1, 10.0);
            v.range("budget_step_ms", h.budget_step_ms, 0.01, 100.0);
        });
        v.nested("frame_budget", |v| {
            v.within("adaptive_frames", self.frame_budget.adaptive_frames, 0.0, 10_000.0);
            let f = &self.frame_budget;
            super::validate_adaptive_percentile(v, "adaptive_percentile", f.adaptive_percentile);
            super::validate_adaptive_percentile_limit(v, "adaptive_percentile_limit", f.adaptive_percentile_limit);
        });
        let k = &self.creature_look;
        v.nested("creature_look", |v| {
            v.within("body_radius_fraction", k.body_radius_fraction, 0.1, 3.0);
            v.within("body_length_ratio", k.body_length_ratio, 0.2, 5.0);
            v.within("body_height_ratio", k.body_height_ratio, 0.2, 5.0);
            v.range("leg_thickness_m", k.leg_thickness_m, 0.001, 1.0);
            v.within("nose_radius_fraction", k.nose_radius_fraction, 0.05, 1.0);
            v.within("crest_radius_fraction", k.crest_radius_fraction, 0.05, 1.0);
            v.within("detail_distance_m", k.detail_distance_m, 1.0, 100_000.0);
        });
        let r = &self.recording;
        v.nested("recording", |v| {
            v.within("width_px", r.width_px as f32, 64.0, 4096.0);
            v.within("every_nth_frame", r.every_nth_frame as f32, 1.0, 30.0);
        });
    }
}
