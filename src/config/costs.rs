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
    /// of the search for contacts with other creatures, and the knapsack), in microseconds, as
    /// it plays: with the writing of the levels, the switch stage's passes and the switches
    /// between the cheaper levels, in a world of a table for each level. Taken from the budget
    /// with the fixed cost. A file without it predicts 0.
    #[serde(default)]
    pub decision_us_per_creature: f32,
    /// What the budget policy costs per creature where not one step up fits beside the
    /// creatures' floors, in microseconds: a pass over the crowd that gives each its floor, no
    /// benefit worked out, and the writing of the levels and the switch stage's passes that a
    /// fixed policy does without. Charged then in place of `decision_us_per_creature`. A file
    /// without it predicts 0.
    #[serde(default)]
    pub floors_only_us_per_creature: f32,
    /// What the choice's search for one creature's soonest contact with another costs, in
    /// microseconds: taken from the budget for each creature searched (only those that could
    /// still buy a level are). A file without it predicts 0.
    #[serde(default)]
    pub contact_search_us: f32,
    /// What the point-mass and hybrid levels and the choice cost per creature in a crowd, where
    /// they run across the cores, and the rigid level among the crowd, as shares of the figures
    /// above (measured on one thread, the choice at 2,000 creatures, the rigid level at its
    /// `rigid_shares`): at the smallest crowd measured. A file without it predicts a
    /// crowd at those figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crowd_shares: Option<CrowdShares>,
    /// The same shares measured at larger crowds, smallest first: a crowd's share is
    /// interpolated on the logarithm of its count between the two measured nearest it (a
    /// creature costs less the larger the crowd); a crowd beyond the largest measured, or
    /// short of the smallest, takes its share. A file without them takes `crowd_shares` for
    /// every crowd.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub larger_crowd_shares: Vec<CrowdShares>,
    /// What the rigid level costs per creature in play among as many rigid creatures as each
    /// entry counts (those the budget picks: about to touch something, or in view), as a share
    /// of the figures above (measured in open court among a few tens of one kind). Rapier works
    /// through its contacts across the cores once it has more than 64 to update, so that a
    /// rigid creature among one or two hundred costs about two thirds of one among ten; among
    /// more, its work per body grows again. Smallest count first: a count between two measured
    /// takes a share between theirs on the logarithm of the count; one short of the smallest,
    /// or beyond the largest, takes its share. A file without them predicts any count at the
    /// figures.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rigid_shares: Vec<RigidShare>,
}

/// The rigid level's cost per creature among `rigid` rigid creatures, as a share of its
/// figure; 0.01 to 10.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidShare {
    /// The rigid creatures it was measured among, 1 or more.
    pub rigid: u32,
    /// Of the rigid level's cost.
    pub share: f32,
}

/// The cheap levels' cost per creature in a crowd of [`PARALLEL_MIN_CREATURES`] or more, as
/// shares of their cost on one thread; each 0.01 to 10.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrowdShares {
    /// The crowd they were measured at, [`PARALLEL_MIN_CREATURES`] or more (a file without it
    /// was measured at 16,384, as every calibration was before it).
    #[serde(default = "CrowdShares::first_measured_at")]
    pub creatures: u32,
    /// Of the point-mass level's cost.
    pub point_mass: f32,
    /// Of the hybrid level's cost.
    pub hybrid: f32,
    /// Of the budget policy's choice per creature (a file without it: 1).
    #[serde(default = "CrowdShares::whole")]
    pub choice: f32,
    /// Of the choice's pass where only the floors fit (a file without it: 1). The pass runs
    /// on one thread in any crowd, so its share stays near 1.
    #[serde(default = "CrowdShares::whole")]
    pub floors_only: f32,
    /// Of the rigid level's cost at its share among as many rigid creatures (`rigid_shares`,
    /// measured in crowds of four times the rigid ones): among tens of thousands of cheaper
    /// creatures, a rigid one costs more in the stages beside rapier's (a file without it: 1).
    #[serde(default = "CrowdShares::whole")]
    pub rigid: f32,
}

impl CrowdShares {
    fn first_measured_at() -> u32 {
        16_384
    }

    fn whole() -> f32 {
        1.0
    }
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
/// and its model), of a switch into the rigid level (building its bodies) and of one between
/// the point-mass and hybrid levels, in microseconds; each 0 to 1,000,000 us (as is the
/// model's fixed cost of a frame).
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
    /// Once, for a switch between the point-mass and hybrid levels (the level's markers moved,
    /// the model entered, the switch told). It is hundreds of times a frame at either level,
    /// so the budget keeps a creature at the dearer of the two where going down would cost more
    /// this frame than staying. A file without it predicts 0.
    #[serde(default)]
    pub cheap_switch_us: f32,
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

    /// What a switch from `from` to `to` costs once: building the bodies of the rigid level,
    /// or moving between the cheap ones. Leaving the rigid level is not charged: until its
    /// window the creature is charged the rigid level's frame, the dearer.
    pub fn switch_us(&self, from: Lod, to: Lod) -> f32 {
        match (from, to) {
            _ if from == to => 0.0,
            (_, Lod::Rigid) => self.switch_to_rigid_us,
            (Lod::Rigid, _) => 0.0,
            _ => self.cheap_switch_us,
        }
    }

    /// Whether a creature at `level` costs less this frame kept there than sent down to
    /// `lowest` with its switch: a hybrid whose step is about a point mass's, where a switch
    /// costs hundreds of frames of either. The budget then keeps it at its level: sending the
    /// crowd's hybrids down as they leave the view's reach, to bring them up again as it sweeps
    /// back, traded 38,459 levels in 270 frames of 40,000 creatures at 10 ms (2026-11-29).
    pub fn holds(&self, level: Lod, lowest: Lod) -> bool {
        level != lowest && self.per_frame_us(level) < self.per_frame_us(lowest) + self.switch_us(level, lowest)
    }

    /// Whether each level costs no less than the one below (as [`CostModel::in_crowd`] gives
    /// them, [`LevelCosts::rising`]).
    pub fn rise_with_level(&self) -> bool {
        self.point_mass_us_per_frame <= self.hybrid_us_per_frame && self.hybrid_us_per_frame <= self.rigid_us_per_frame
    }

    /// Each level at no less than the one below: a hybrid is a point mass posed from its gait
    /// table (section 3.2), so where one measures cheaper, in a crowd's shares or a calibration
    /// on a busy machine, the difference is noise. The budget's choice also needs it: with any
    /// level cheaper than the one below, its queue can pass no list of steps by and sorts every
    /// step (at 100,000 creatures, a hybrid 0.1 % cheaper than a point mass made the choice 1.8
    /// times slower, 2026-11-29).
    pub fn rising(self) -> Self {
        let hybrid_us_per_frame = self.hybrid_us_per_frame.max(self.point_mass_us_per_frame);
        Self {
            hybrid_us_per_frame,
            rigid_us_per_frame: self.rigid_us_per_frame.max(hybrid_us_per_frame),
            ..self
        }
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
        v.within("cheap_switch_us", self.cheap_switch_us, 0.0, Self::MOST_US);
    }
}

impl CostModel {
    /// Predicted microseconds of a frame of `creatures` before any creature's level: the
    /// fixed cost and the budget policy's choice (in a crowd, at its share).
    pub fn overhead_us(&self, creatures: usize) -> f32 {
        self.overhead_at_us(creatures, self.decision_us_per_creature, |s| s.choice)
    }

    /// [`CostModel::overhead_us`] where not one step up fits beside the floors: the choice is
    /// then its pass over the crowd.
    pub fn floors_only_overhead_us(&self, creatures: usize) -> f32 {
        self.overhead_at_us(creatures, self.floors_only_us_per_creature, |s| s.floors_only)
    }

    /// What the choice adds for each creature of `creatures` whose benefits it works out,
    /// beyond its pass over it (a creature it leaves quiet costs only the pass: the budget
    /// policy's incremental choice).
    pub fn evaluation_us(&self, creatures: usize) -> f32 {
        let n = creatures.max(1);
        ((self.overhead_us(n) - self.floors_only_overhead_us(n)) / n as f32).max(0.0)
    }

    /// The fixed cost, and the choice at `per_creature_us` and its `share` in a crowd.
    fn overhead_at_us(&self, creatures: usize, per_creature_us: f32, share: fn(&CrowdShares) -> f32) -> f32 {
        let share = self.shares_in_crowd(creatures as u32).map_or(1.0, |s| share(&s));
        self.fixed_us_per_frame + per_creature_us * share * creatures as f32
    }

    /// The costs of the kind named `kind` in a world of `creatures`, `rigid` of them rigid: in
    /// a crowd, each level at its crowd share; the rigid level also at its share among that
    /// many rigid creatures.
    pub fn in_crowd(&self, kind: &str, creatures: u32, rigid: u32) -> LevelCosts {
        let mut costs = *self.of(kind);
        if let Some(shares) = self.shares_in_crowd(creatures) {
            costs.point_mass_us_per_frame *= shares.point_mass;
            costs.hybrid_us_per_frame *= shares.hybrid;
            costs.rigid_us_per_frame *= shares.rigid;
        }
        costs.rigid_us_per_frame *= self.rigid_share(rigid);
        costs.rising()
    }

    /// The rigid level's share of its cost among `rigid` rigid creatures (see
    /// `rigid_shares`): 1 without any measured.
    pub fn rigid_share(&self, rigid: u32) -> f32 {
        let Some(first) = self.rigid_shares.first() else {
            return 1.0;
        };
        let mut below = first;
        for above in &self.rigid_shares {
            if above.rigid >= rigid {
                let t = along_log(rigid, below.rigid, above.rigid);
                return below.share + (above.share - below.share) * t;
            }
            below = above;
        }
        below.share
    }

    /// The cheap levels' and the choice's shares in a world of `creatures` (see
    /// `larger_crowd_shares`): none short of a crowd.
    pub fn shares_in_crowd(&self, creatures: u32) -> Option<CrowdShares> {
        let first = self.crowd_shares.filter(|_| creatures >= PARALLEL_MIN_CREATURES)?;
        let measured = std::iter::once(&first).chain(&self.larger_crowd_shares);
        let (mut below, n) = (first, creatures as f32);
        for above in measured {
            if above.creatures as f32 >= n {
                let t = along_log(creatures, below.creatures, above.creatures);
                let at = |b: f32, a: f32| b + (a - b) * t;
                return Some(CrowdShares {
                    creatures,
                    point_mass: at(below.point_mass, above.point_mass),
                    hybrid: at(below.hybrid, above.hybrid),
                    choice: at(below.choice, above.choice),
                    floors_only: at(below.floors_only, above.floors_only),
                    rigid: at(below.rigid, above.rigid),
                });
            }
            below = *above;
        }
        Some(CrowdShares { creatures, ..below })
    }

    /// The costs of the kind named `kind`.
    pub fn of(&self, kind: &str) -> &LevelCosts {
        self.kinds
            .iter()
            .find(|k| k.kind == kind)
            .map_or(&self.other_kinds, |k| &k.costs)
    }
}

/// How far `n` lies from `lo` to `hi` on the logarithm of the count, 0 to 1 (1 where they are
/// the same).
fn along_log(n: u32, lo: u32, hi: u32) -> f32 {
    let (n, lo, hi) = ((n.max(1) as f32).ln(), (lo as f32).ln(), (hi as f32).ln());
    if hi > lo {
        ((n - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        1.0
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
        v.within(
            "floors_only_us_per_creature",
            self.floors_only_us_per_creature,
            0.0,
            LevelCosts::MOST_US,
        );
        let shares = |v: &mut Validator, shares: &CrowdShares, smallest: u32, why: &str| {
            v.require(
                shares.creatures >= smallest,
                "creatures",
                format!("must be at least {smallest} ({why}), got {}", shares.creatures),
            );
            v.within("point_mass", shares.point_mass, 0.01, 10.0);
            v.within("hybrid", shares.hybrid, 0.01, 10.0);
            v.within("choice", shares.choice, 0.01, 10.0);
            v.within("floors_only", shares.floors_only, 0.01, 10.0);
            v.within("rigid", shares.rigid, 0.01, 10.0);
        };
        if let Some(first) = &self.crowd_shares {
            v.nested("crowd_shares", |v| {
                shares(
                    v,
                    first,
                    PARALLEL_MIN_CREATURES,
                    "the smallest crowd stepped across the cores",
                )
            });
        } else if !self.larger_crowd_shares.is_empty() {
            v.fail(
                "larger_crowd_shares",
                "needs crowd_shares, the shares at the smallest crowd",
            );
        }
        let mut before = self.crowd_shares.map_or(0, |s| s.creatures);
        for (i, larger) in self.larger_crowd_shares.iter().enumerate() {
            let smallest = before.saturating_add(1);
            v.nested(&format!("larger_crowd_shares[{i}]"), |v| {
                shares(v, larger, smallest, "larger than the crowd before")
            });
            before = larger.creatures;
        }
        let mut fewer = 0;
        for (i, r) in self.rigid_shares.iter().enumerate() {
            v.nested(&format!("rigid_shares[{i}]"), |v| {
                v.require(
                    r.rigid > fewer,
                    "rigid",
                    format!(
                        "must be more than {fewer} (more than the count before), got {}",
                        r.rigid
                    ),
                );
                v.within("share", r.share, 0.01, 10.0);
            });
            fewer = r.rigid;
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
    fn a_cheap_level_is_held_only_where_its_switch_down_costs_more_than_the_frame_it_saves() {
        let costs = |hybrid_us_per_frame, cheap_switch_us| LevelCosts {
            point_mass_us_per_frame: 1.0,
            hybrid_us_per_frame,
            rigid_us_per_frame: 100.0,
            switch_to_rigid_us: 50.0,
            cheap_switch_us,
        };
        assert!(costs(2.0, 5.0).holds(Lod::Hybrid, Lod::PointMass));
        // Going down saves more than its switch, or its switch is free.
        assert!(!costs(7.0, 5.0).holds(Lod::Hybrid, Lod::PointMass));
        assert!(!costs(1.0, 0.0).holds(Lod::Hybrid, Lod::PointMass));
        // Leaving the rigid level is not a cheap switch; the lowest level is no hold.
        assert!(!costs(2.0, 5.0).holds(Lod::Rigid, Lod::PointMass));
        assert!(!costs(2.0, 5.0).holds(Lod::PointMass, Lod::PointMass));
        assert_eq!(costs(2.0, 5.0).switch_us(Lod::PointMass, Lod::Hybrid), 5.0);
        assert_eq!(costs(2.0, 5.0).switch_us(Lod::Hybrid, Lod::Rigid), 50.0);
    }

    #[test]
    fn a_level_measured_cheaper_than_the_one_below_is_priced_as_that_one() {
        // Alone, the hybrid measured cheaper; in a crowd, its share made it so.
        let text = "(kinds: [(kind: \"hopper\", costs: (point_mass_us_per_frame: 1, hybrid_us_per_frame: 0.9, \
            rigid_us_per_frame: 0.5, switch_to_rigid_us: 50))], other_kinds: (point_mass_us_per_frame: 1, \
            hybrid_us_per_frame: 1.2, rigid_us_per_frame: 100, switch_to_rigid_us: 50), \
            crowd_shares: Some((point_mass: 1, hybrid: 0.5)))";
        let model: CostModel = parse_ron(text.as_bytes(), Path::new("costs.ron")).unwrap();
        let alone = model.in_crowd("hopper", 1, 0);
        assert_eq!(
            (
                alone.point_mass_us_per_frame,
                alone.hybrid_us_per_frame,
                alone.rigid_us_per_frame
            ),
            (1.0, 1.0, 1.0)
        );
        let crowd = model.in_crowd("biped", PARALLEL_MIN_CREATURES, 0);
        assert_eq!((crowd.hybrid_us_per_frame, crowd.rigid_us_per_frame), (1.0, 100.0));
        assert!(alone.rise_with_level() && crowd.rise_with_level());
    }

    #[test]
    fn in_a_crowd_the_cheap_levels_cost_their_shares_and_a_share_out_of_range_is_refused() {
        let text = format!("(kinds: [], other_kinds: {COSTS}, crowd_shares: Some((point_mass: 0.5, hybrid: 0.25)))");
        let model: CostModel = parse_ron(text.as_bytes(), Path::new("costs.ron")).unwrap();
        let (few, crowd) = (
            model.in_crowd("hopper", PARALLEL_MIN_CREATURES - 1, 0),
            model.in_crowd("hopper", PARALLEL_MIN_CREATURES, 0),
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
        assert_eq!(plain.in_crowd("hopper", 1_000_000, 0), *plain.of("hopper"));
        let bad = text.replace("0.25", "0");
        let err = parse_ron::<CostModel>(bad.as_bytes(), Path::new("costs.ron")).unwrap_err();
        assert!(err.to_string().contains("`crowd_shares.hybrid`"), "{err}");
    }

    #[test]
    fn a_crowd_between_two_measured_takes_a_share_between_theirs_on_the_logarithm_of_its_count() {
        let text = format!(
            "(kinds: [], other_kinds: {COSTS}, crowd_shares: Some((creatures: 4096, point_mass: 1.0, hybrid: 1.0)), \
             larger_crowd_shares: [(creatures: 16384, point_mass: 0.5, hybrid: 0.75), (creatures: 65536, point_mass: 0.25, hybrid: 0.75, choice: 0.5, floors_only: 2.0, rigid: 3.0)])"
        );
        let mut model: CostModel = parse_ron(text.as_bytes(), Path::new("costs.ron")).unwrap();
        // The choice's share too (a share left out is 1): none short of a crowd.
        (model.fixed_us_per_frame, model.decision_us_per_creature) = (0.0, 2.0);
        assert_eq!(model.overhead_us(100), 200.0);
        assert_eq!(model.overhead_us(16_384), 2.0 * 16_384.0);
        assert!(
            (model.overhead_us(32_768) - 0.75 * 2.0 * 32_768.0).abs() < 1.0,
            "{}",
            model.overhead_us(32_768)
        );
        assert_eq!(model.overhead_us(1_000_000), 0.5 * 2.0 * 1e6);
        // Where only the floors fit, the choice is its pass, at its own share.
        model.floors_only_us_per_creature = 0.25;
        assert_eq!(model.floors_only_overhead_us(100), 25.0);
        assert_eq!(model.floors_only_overhead_us(1_000_000), 2.0 * 0.25 * 1e6);
        assert_eq!(model.floors_only_overhead_us(16_384), 0.25 * 16_384.0);
        let point_mass = |n| model.in_crowd("hopper", n, 0).point_mass_us_per_frame;
        // The smallest crowd's share down to the smallest crowd, the largest's beyond it.
        assert_eq!(point_mass(PARALLEL_MIN_CREATURES), 1.0);
        assert_eq!(point_mass(4096), 1.0);
        assert_eq!(point_mass(1_000_000), 0.25);
        // Halfway on the logarithm: 8,192 between 4,096 and 16,384; 32,768 past 16,384.
        assert!((point_mass(8192) - 0.75).abs() < 1e-5, "{}", point_mass(8192));
        assert!((point_mass(32_768) - 0.375).abs() < 1e-5, "{}", point_mass(32_768));
        assert_eq!(point_mass(16_384), 0.5);
        assert!((model.in_crowd("hopper", 8192, 0).hybrid_us_per_frame - 1.75).abs() < 1e-5);
        // The rigid level among the crowd: its share left out is 1, and 3 at the largest.
        let rigid = |n| model.in_crowd("hopper", n, 0).rigid_us_per_frame;
        assert_eq!(rigid(4096), 100.0);
        assert!((rigid(32_768) - 200.0).abs() < 1e-3, "{}", rigid(32_768));
        assert_eq!(rigid(1_000_000), 300.0);
        // A file of one share, from before the counts: measured at 16,384, for every crowd.
        let old: CostModel = parse_ron(
            format!("(kinds: [], other_kinds: {COSTS}, crowd_shares: Some((point_mass: 0.5, hybrid: 0.5)))").as_bytes(),
            Path::new("costs.ron"),
        )
        .unwrap();
        assert_eq!(old.crowd_shares.unwrap().creatures, 16_384);
        assert_eq!(old.in_crowd("hopper", 3000, 0).point_mass_us_per_frame, 0.5);
        assert_eq!(old.in_crowd("hopper", 1_000_000, 0).point_mass_us_per_frame, 0.5);
        // Counts out of order are refused, and named.
        let unordered = text.replace("creatures: 65536", "creatures: 8192");
        let err = parse_ron::<CostModel>(unordered.as_bytes(), Path::new("costs.ron")).unwrap_err();
        assert!(err.to_string().contains("`larger_crowd_shares[1].creatures`"), "{err}");
        let pass = text.replace("floors_only: 2.0", "floors_only: 0");
        let err = parse_ron::<CostModel>(pass.as_bytes(), Path::new("costs.ron")).unwrap_err();
        assert!(
            err.to_string().contains("`larger_crowd_shares[1].floors_only`"),
            "{err}"
        );
        let rigid_out = text.replace("rigid: 3.0", "rigid: 11");
        let err = parse_ron::<CostModel>(rigid_out.as_bytes(), Path::new("costs.ron")).unwrap_err();
        assert!(err.to_string().contains("`larger_crowd_shares[1].rigid`"), "{err}");
        let last = text.replace("creatures: 4096", &format!("creatures: {}", u32::MAX));
        let err = parse_ron::<CostModel>(last.as_bytes(), Path::new("costs.ron")).unwrap_err();
        assert!(err.to_string().contains("`larger_crowd_shares[0].creatures`"), "{err}");
    }

    #[test]
    fn the_rigid_level_costs_its_share_at_the_count_of_rigid_creatures_between_two_measured() {
        let text = format!(
            "(kinds: [], other_kinds: {COSTS}, rigid_shares: [(rigid: 10, share: 1.2), (rigid: 160, share: 0.6), (rigid: 640, share: 0.9)])"
        );
        let model: CostModel = parse_ron(text.as_bytes(), Path::new("costs.ron")).unwrap();
        let rigid = |n| model.in_crowd("hopper", 40, n).rigid_us_per_frame;
        // The smallest count's share below it, the largest's beyond it; the cheap levels
        // untouched.
        assert!((rigid(0) - 120.0).abs() < 1e-3, "{}", rigid(0));
        assert!((rigid(10) - 120.0).abs() < 1e-3, "{}", rigid(10));
        assert!((rigid(10_000) - 90.0).abs() < 1e-3, "{}", rigid(10_000));
        assert_eq!(model.in_crowd("hopper", 40, 160).hybrid_us_per_frame, 2.0);
        // Halfway on the logarithm: 40 between 10 and 160, 320 between 160 and 640.
        assert!((rigid(40) - 90.0).abs() < 1e-3, "{}", rigid(40));
        assert!((rigid(320) - 75.0).abs() < 1e-3, "{}", rigid(320));
        // A file without them prices every count at the figure.
        let plain: CostModel = parse_ron(
            format!("(kinds: [], other_kinds: {COSTS})").as_bytes(),
            Path::new("costs.ron"),
        )
        .unwrap();
        assert_eq!(plain.in_crowd("hopper", 40, 500).rigid_us_per_frame, 100.0);
        // Counts out of order, and shares out of range, are refused and named.
        for (bad, field) in [
            (text.replace("rigid: 640", "rigid: 160"), "`rigid_shares[2].rigid`"),
            (text.replace("rigid: 10,", "rigid: 0,"), "`rigid_shares[0].rigid`"),
            (text.replace("share: 0.6", "share: 0"), "`rigid_shares[1].share`"),
        ] {
            let err = parse_ron::<CostModel>(bad.as_bytes(), Path::new("costs.ron")).unwrap_err();
            assert!(err.to_string().contains(field), "{err}");
        }
    }
}
