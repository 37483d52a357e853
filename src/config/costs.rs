//! The cost model of the budget policy: `assets/costs.ron`, written by `simlod bench
//! --calibrate` from measured medians. What each level of each kind is predicted to cost, so
//! that the budget is spent before the frame (Funkhouser & Sequin's predictive choice), not
//! corrected after a slow one.

use super::{Validate, Validator};
use crate::contract::{Lod, PARALLEL_MIN_CREATURES};
use serde::{Deserialize, Serialize};

/// Predicted costs per kind and level.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CostModel {
    /// One entry per calibrated kind.
    pub kinds: Vec<KindCosts>,
    /// What a kind without an entry is predicted to cost.
    pub other_kinds: LevelCosts,
    /// What a frame costs whatever its creatures (the court, the puck, the schedule's ticks),
    /// in microseconds per 1/30 s: taken from the budget before any creature's level. A file
    /// without it predicts 0.
    #[serde(default)]
    pub fixed_us_per_frame: f32,
    /// What the budget policy's own choice costs per creature per 1/30 s (its benefits short
    /// of the search for contacts with other creatures, and the knapsack), in microseconds:
    /// taken from the budget with the fixed cost. A file without it predicts 0.
    #[serde(default)]
    pub decision_us_per_creature: f32,
    /// What the choice's search for one creature's soonest contact with another costs, in
    /// microseconds: taken from the budget for each creature searched (only those that could
    /// still buy a level are). A file without it predicts 0.
    #[serde(default)]
    pub contact_search_us: f32,
    /// What the point-mass and hybrid levels cost per creature in a crowd, where they are
    /// stepped across the cores, as shares of the figures above (measured on one thread). A
    /// file without it predicts a crowd at those figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crowd_shares: Option<CrowdShares>,
}

/// The cheap levels' cost per creature in a crowd of [`PARALLEL_MIN_CREATURES`] or more, as
/// shares of their cost on one thread; each 0.01 to 10.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrowdShares {
    /// Of the point-mass level's cost.
    pub point_mass: f32,
    /// Of the hybrid level's cost.
    pub hybrid: f32,
}

/// A kind's costs, by name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KindCosts {
    /// The creature kind, as named in a scenario.
    pub kind: String,
    /// Its costs at each level.
    pub costs: LevelCosts,
}

/// Wall time of one creature's 1/30 s of simulated motion at each level (steering, collisions
/// and its model), and of a switch into the rigid level (building its bodies), in
/// microseconds; each 0 to 1,000,000 us (as is the model's fixed cost of a frame).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelCosts {
    /// At the point-mass level.
    pub point_mass_us_per_frame: f32,
    /// At the hybrid level.
    pub hybrid_us_per_frame: f32,
    /// At the rigid level.
    pub rigid_us_per_frame: f32,
    /// Once, for a switch into the rigid level.
    pub switch_to_rigid_us: f32,
}

impl LevelCosts {
    /// Predicted microseconds per 1/30 s at `level`.
    pub fn per_frame_us(&self, level: Lod) -> f32 {
        match level {
            Lod::PointMass => self.point_mass_us_per_frame,
            Lod::Hybrid => self.hybrid_us_per_frame,
            Lod::Rigid => self.rigid_us_per_frame,
        }
    }

    /// Whether each level costs no less than the one below (a crowd's shares can make a
    /// hybrid cheaper than a point mass).
    pub fn rise_with_level(&self) -> bool {
        self.point_mass_us_per_frame <= self.hybrid_us_per_frame && self.hybrid_us_per_frame <= self.rigid_us_per_frame
    }

    /// The most any cost may be, in microseconds.
    const MOST_US: f32 = 1_000_000.0;

    fn validate(&self, v: &mut Validator) {
        v.within(
            "point_mass_us_per_frame",
            self.point_mass_us_per_frame,
            0.0,
            Self::MOST_US,
        );
        v.within("hybrid_us_per_frame", self.hybrid_us_per_frame, 0.0, Self::MOST_US);
        v.within("rigid_us_per_frame", self.rigid_us_per_frame, 0.0, Self::MOST_US);
        v.within("switch_to_rigid_us", self.switch_to_rigid_us, 0.0, Self::MOST_US);
    }
}

impl CostModel {
    /// Predicted microseconds of a frame of `creatures` before any creature's level: the
    /// fixed cost and the budget policy's choice.
    pub fn overhead_us(&self, creatures: usize) -> f32 {
        self.fixed_us_per_frame + self.decision_us_per_creature * creatures as f32
    }

    /// The costs of the kind named `kind` in a world of `creatures`: in a crowd, the cheap
    /// levels at their crowd shares.
    pub fn in_crowd(&self, kind: &str, creatures: u32) -> LevelCosts {
        let mut costs = *self.of(kind);
        if let Some(shares) = self.crowd_shares.filter(|_| creatures >= PARALLEL_MIN_CREATURES) {
            costs.point_mass_us_per_frame *= shares.point_mass;
            costs.hybrid_us_per_frame *= shares.hybrid;
        }
        costs
    }

    /// The costs of the kind named `kind`.
    pub fn of(&self, kind: &str) -> &LevelCosts {
        self.kinds
            .iter()
            .find(|k| k.kind == kind)
            .map_or(&self.other_kinds, |k| &k.costs)
    }
}

impl Validate for CostModel {
    fn validate(&self, v: &mut Validator) {
        for (i, k) in self.kinds.iter().enumerate() {
            v.nested(&format!("kinds[{i}]"), |v| {
                v.kind_name("kind", &k.kind);
                v.nested("costs", |v| k.costs.validate(v));
            });
            if self.kinds[..i].iter().any(|o| o.kind == k.kind) {
                v.fail(&format!("kinds[{i}].kind"), format!("{:?} is listed twice", k.kind));
            }
        }
        v.nested("other_kinds", |v| self.other_kinds.validate(v));
        v.within("fixed_us_per_frame", self.fixed_us_per_frame, 0.0, LevelCosts::MOST_US);
        v.within(
            "decision_us_per_creature",
            self.decision_us_per_creature,
            0.0,
            LevelCosts::MOST_US,
        );
        v.within("contact_search_us", self.contact_search_us, 0.0, LevelCosts::MOST_US);
        if let Some(shares) = self.crowd_shares {
            v.nested("crowd_shares", |v| {
                v.within("point_mass", shares.point_mass, 0.01, 10.0);
                v.within("hybrid", shares.hybrid, 0.01, 10.0);
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::parse_ron;
    use std::path::Path;

    const COSTS: &str =
        "(point_mass_us_per_frame: 1, hybrid_us_per_frame: 2, rigid_us_per_frame: 100, switch_to_rigid_us: 50)";

    #[test]
    fn a_cost_model_written_before_the_fixed_cost_loads_with_none() {
        let old = format!("(kinds: [], other_kinds: {COSTS})");
        let model: CostModel = parse_ron(old.as_bytes(), Path::new("costs.ron")).unwrap();
        assert_eq!(model.overhead_us(100), 0.0);
        let negative = format!("(kinds: [], other_kinds: {COSTS}, fixed_us_per_frame: -3)");
        let err = parse_ron::<CostModel>(negative.as_bytes(), Path::new("costs.ron")).unwrap_err();
        assert!(err.to_string().contains("`fixed_us_per_frame`"), "{err}");
    }

    #[test]
    fn in_a_crowd_the_cheap_levels_cost_their_shares_and_a_share_out_of_range_is_refused() {
        let text = format!("(kinds: [], other_kinds: {COSTS}, crowd_shares: Some((point_mass: 0.5, hybrid: 0.25)))");
        let model: CostModel = parse_ron(text.as_bytes(), Path::new("costs.ron")).unwrap();
        let (few, crowd) = (
            model.in_crowd("hopper", PARALLEL_MIN_CREATURES - 1),
            model.in_crowd("hopper", PARALLEL_MIN_CREATURES),
        );
        assert_eq!((few.point_mass_us_per_frame, few.hybrid_us_per_frame), (1.0, 2.0));
        assert_eq!((crowd.point_mass_us_per_frame, crowd.hybrid_us_per_frame), (0.5, 0.5));
        assert_eq!(crowd.rigid_us_per_frame, few.rigid_us_per_frame);
        // Without shares a crowd costs what one thread measured.
        let plain: CostModel = parse_ron(
            format!("(kinds: [], other_kinds: {COSTS})").as_bytes(),
            Path::new("costs.ron"),
        )
        .unwrap();
        assert_eq!(plain.in_crowd("hopper", 1_000_000), *plain.of("hopper"));
        let bad = text.replace("0.25", "0");
        let err = parse_ron::<CostModel>(bad.as_bytes(), Path::new("costs.ron")).unwrap_err();
        assert!(err.to_string().contains("`crowd_shares.hybrid`"), "{err}");
    }
}
