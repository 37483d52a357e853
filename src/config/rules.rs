//! The level rules (paper 3.4): `assets/rules/levels.ron`.

use super::{Validate, Validator};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// The rules that choose each creature's level of detail: `assets/rules/levels.ron`.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelRules {
    /// Areas of influence around the puck, the walls and the creatures.
    pub influence: InfluenceRules,
    /// The camera's view.
    pub camera: CameraRules,
    /// To leave an area a creature must be this much further out than to enter it; 0 to 1000 m.
    pub release_margin_m: f32,
    /// After a switch a creature keeps its level at least this long; 0 to 3600 s.
    pub min_dwell_s: f32,
    /// Start and end of the switching window, as parts of the flight phase (0 to 1).
    pub flight_window: (f32, f32),
    /// How long what is drawn takes to blend from the old level's motion into the new one's
    /// after a switch (inertialization); 0 draws the switch as it happens. 0 to 2 s.
    pub blend_s: f32,
    /// The `budget` policy: a frame budget spent where it changes the outcome most.
    pub budget: BudgetRules,
}

/// Areas of influence (figure 5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InfluenceRules {
    /// The puck's radius of influence, beyond its rim; 0 to 10,000 m.
    pub puck_radius_m: f32,
    /// A creature's radius of influence on the others; 0 to 1000 m.
    pub creature_radius_m: f32,
    /// Each area is stretched along its body's velocity to cover where it will be this long from now; 0 to 60 s.
    pub lookahead_s: f32,
    /// A wall's area: the band this wide along it; 0 to 10,000 m.
    pub wall_band_m: f32,
}

/// The camera rule (figure 6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraRules {
    /// The camera's radius of influence: in view and nearer than this, rigid; 0 to 10,000 m.
    pub radius_m: f32,
    /// Headless, the camera's vertical opening angle; 1 to 179 degrees (the game uses its
    /// window's camera).
    pub field_of_view_deg: f32,
    /// Headless, the view's width over its height; 0.1 to 10.
    pub aspect_ratio: f32,
    /// Headless, the camera rides this far behind the creature it follows, on the side away
    /// from the puck; 0 to 1000 m.
    pub follow_distance_m: f32,
    /// ... this high; 0.1 to 1000 m.
    pub follow_height_m: f32,
    /// ... and aims at a point between the creature (0) and the puck (1); 0 to 1.
    pub aim_toward_puck_fraction: f32,
    /// ... at this height (below the ice tilts the view down); -1000 to 1000 m.
    pub aim_height_m: f32,
    /// Headless, the view's far plane: nothing deeper along the view is drawn (Bevy's camera
    /// culls there, at 1000 m by default, as a file without it has); 1 to 1,000,000 m.
    #[serde(default = "default_far_m")]
    pub far_m: f32,
}

fn default_far_m() -> f32 {
    1000.0
}

/// The `budget` policy (beyond the paper's conclusion: "cost/benefit heuristics might be
/// designed to assign a switching priority for each creature").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetRules {
    /// Wall time of simulation allowed per 1/30 s of motion, predicted from the cost model;
    /// 0 to 10,000 ms.
    pub frame_budget_ms: f32,
    /// The cost model's file, under the assets folder (`simlod bench --calibrate` writes it).
    pub cost_model: String,
    /// A contact this many seconds away is worth 1/e of one now; 0.01 to 60 s.
    pub contact_horizon_s: f32,
    /// A creature's search for its soonest contact with another creature stands this long
    /// before it is searched again (the choice's dearest part, in a crowd); 0 searches at every
    /// decision, as a file without it does; 0 to 10 s.
    #[serde(default)]
    pub contact_recheck_s: f32,
    /// Bodies count as touching this much before their footprints meet; 0 to 100 m.
    pub contact_margin_m: f32,
    /// The earliest contact possible (both turning toward each other at full speed) counts
    /// this much of a contact on the present course; 0 to 1.
    pub worst_case_share: f32,
    /// Benefit of the rigid level for a contact now with the puck; 0 to 1000.
    pub puck_weight: f32,
    /// ... with a wall; 0 to 1000.
    pub wall_weight: f32,
    /// ... with another creature; 0 to 1000.
    pub creature_weight: f32,
    /// In view, the benefit of seeing a creature halves at this distance from the camera;
    /// 0.01 to 10,000 m.
    pub view_half_distance_m: f32,
    /// Benefit of the hybrid level (legs seen) for a creature in view at the camera; 0 to 1000.
    pub view_hybrid_weight: f32,
    /// Benefit of the rigid level for a creature in view at the camera; 0 to 1000.
    pub view_rigid_weight: f32,
    /// Benefit of the rigid level for the creature the camera follows (the player's); 0 to 1000.
    pub player_rigid_weight: f32,
    /// A creature's last chosen level counts this share more benefit, so one near the cut-off
    /// does not flicker; 0 to 10.
    pub hysteresis: f32,
    /// A level is bought only for at least this much benefit per ms of its predicted cost:
    /// what would gain less is left unspent, so the budget is a ceiling, not a target.
    /// 0 (the default) spends the budget wherever anything gains; 0 to 10^6.
    #[serde(default)]
    pub least_benefit_per_ms: f32,
    /// 0 (the default): the cost model alone predicts, and the same files give the same run.
    /// Above 0, the adaptive mode: the predictions are corrected by the measured simulation
    /// time of each frame, smoothed over about this many frames; it reads the wall clock, so
    /// runs are not reproducible. 0 to 10,000 frames.
    #[serde(default)]
    pub adaptive_frames: f32,
    /// The adaptive mode's emergency tier (after Unreal's Animation Budget Allocator): a frame
    /// measured over this many times the budget sets the correction at once to what that frame
    /// measured, rather than over `adaptive_frames`, so the next decision already spends less.
    /// 0 (the default) has none; else 1 to 100.
    #[serde(default)]
    pub emergency_over: f32,
    /// 0 (the default): the adaptive mode keeps the mean frame at the budget. 50 to 100: it
    /// keeps this percentile of the last frames within it, so that a slow frame is as rare as
    /// that says, not only the mean right: on a machine whose frames vary, the mean then sits
    /// under the budget by as much as they vary. The percentile is of as many frames as three
    /// lie beyond (99: the last 300), or of the last `adaptive_frames` where those are more.
    #[serde(default)]
    pub adaptive_percentile: f32,
    /// In the percentile mode, the frame at the percentile is kept within this many times the
    /// budget, and the mean frame within the budget itself: 1 (the default) keeps the percentile
    /// within the budget, its mean under it by as much as the frames vary; 1.15 (the game's) lets
    /// it run 15 % over, so the mean comes nearer the budget. 1 to 10.
    #[serde(default = "BudgetRules::percentile_within_the_budget")]
    pub adaptive_percentile_limit: f32,
    /// true (the default): the incremental choice. A crowd's quiet creatures (out of view in a
    /// tile of the court the view cone misses, at their floor, not followed) wait in groups,
    /// their benefits worked out only for a group that reaches the front with room for a step:
    /// the same levels as working out every creature, at the cost of the few, where working out
    /// every creature would leave no room for a step beside the floors. false: every creature's
    /// benefits are worked out at every decision.
    #[serde(default = "BudgetRules::incremental")]
    pub incremental_choice: bool,
}

impl BudgetRules {
    /// `incremental_choice` where a file leaves it out.
    fn incremental() -> bool {
        true
    }

    /// `adaptive_percentile_limit` where a file leaves it out: the budget itself.
    pub(crate) fn percentile_within_the_budget() -> f32 {
        1.0
    }
}

/// The percentile mode's limit, in the rules or the game's file: 1 to 10 times the budget.
pub fn validate_adaptive_percentile_limit(v: &mut Validator, field: &str, limit: f32) {
    v.within(field, limit, 1.0, 10.0);
}

/// The adaptive mode's percentile, in the rules or the game's file: 0 (the mean) or 50 to 100.
pub fn validate_adaptive_percentile(v: &mut Validator, field: &str, p: f32) {
    if !(p == 0.0 || (50.0..=100.0).contains(&p)) {
        v.fail(field, format!("must be 0 (the mean) or between 50 and 100, got {p}"));
    }
}

impl Validate for LevelRules {
    fn validate(&self, v: &mut Validator) {
        v.nested("influence", |v| {
            v.range("puck_radius_m", self.influence.puck_radius_m, 0.0, 10_000.0);
            v.range("creature_radius_m", self.influence.creature_radius_m, 0.0, 1000.0);
            v.range("lookahead_s", self.influence.lookahead_s, 0.0, 60.0);
            v.range("wall_band_m", self.influence.wall_band_m, 0.0, 10_000.0);
        });
        v.nested("camera", |v| {
            v.range("radius_m", self.camera.radius_m, 0.0, 10_000.0);
            let c = &self.camera;
            v.range("field_of_view_deg", c.field_of_view_deg, 1.0, 179.0);
            v.range("aspect_ratio", c.aspect_ratio, 0.1, 10.0);
            v.range("follow_distance_m", c.follow_distance_m, 0.0, 1000.0);
            v.range("follow_height_m", c.follow_height_m, 0.1, 1000.0);
            v.within("aim_toward_puck_fraction", c.aim_toward_puck_fraction, 0.0, 1.0);
            v.range("aim_height_m", c.aim_height_m, -1000.0, 1000.0);
            v.range("far_m", c.far_m, 1.0, 1_000_000.0);
        });
        v.range("release_margin_m", self.release_margin_m, 0.0, 1000.0);
        v.range("min_dwell_s", self.min_dwell_s, 0.0, 3600.0);
        v.range("blend_s", self.blend_s, 0.0, 2.0);
        v.nested("budget", |v| {
            let b = &self.budget;
            v.range("frame_budget_ms", b.frame_budget_ms, 0.0, 10_000.0);
            v.asset_path("cost_model", &b.cost_model);
            v.range("contact_horizon_s", b.contact_horizon_s, 0.01, 60.0);
            v.range("contact_recheck_s", b.contact_recheck_s, 0.0, 10.0);
            v.range("contact_margin_m", b.contact_margin_m, 0.0, 100.0);
            v.within("worst_case_share", b.worst_case_share, 0.0, 1.0);
            for (field, w) in [
                ("puck_weight", b.puck_weight),
                ("wall_weight", b.wall_weight),
                ("creature_weight", b.creature_weight),
                ("view_hybrid_weight", b.view_hybrid_weight),
                ("view_rigid_weight", b.view_rigid_weight),
                ("player_rigid_weight", b.player_rigid_weight),
            ] {
                v.within(field, w, 0.0, 1000.0);
            }
            v.range("view_half_distance_m", b.view_half_distance_m, 0.01, 10_000.0);
            v.within("hysteresis", b.hysteresis, 0.0, 10.0);
            v.within("least_benefit_per_ms", b.least_benefit_per_ms, 0.0, 1e6);
            v.within("adaptive_frames", b.adaptive_frames, 0.0, 10_000.0);
            let e = b.emergency_over;
            if !(e == 0.0 || (1.0..=100.0).contains(&e)) {
                v.fail(
                    "emergency_over",
                    format!("must be 0 (none) or between 1 and 100, got {e}"),
                );
            }
            validate_adaptive_percentile(v, "adaptive_percentile", b.adaptive_percentile);
            validate_adaptive_percentile_limit(v, "adaptive_percentile_limit", b.adaptive_percentile_limit);
        });
        let (a, b) = self.flight_window;
        v.range("flight_window.0", a, 0.0, 1.0);
        v.range("flight_window.1", b, 0.0, 1.0);
        v.require(
            a < b,
            "flight_window",
            format!("must start before it ends, got ({a}, {b})"),
        );
    }
}
