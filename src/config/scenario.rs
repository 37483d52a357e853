//! A scenario: which creatures, how many, the seed and the level policy.

use super::{Validate, Validator};
use crate::contract::Lod;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// A scenario file, `assets/scenarios/<name>.ron`: what one run is made of.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Seeds the world's one RNG: same seed and files, same game.
    pub seed: u64,
    /// Length of a run when the command line does not say; 0.001 to 10,000 s.
    pub duration_s: f32,
    /// Simulation ticks per second (the physics step); 30 to 2000, a multiple of `decision_hz`.
    pub tick_hz: u32,
    /// Steering decisions per second, any that divides `tick_hz` (1 Hz up); the paper's frame
    /// rate is 30.
    pub decision_hz: u32,
    /// Rapier's solver iterations per tick, 1 to 16 (each is a substep of the tick; 8 when
    /// left out). Impulse joints hold the hopper's gait steady at its top speed from 8 (at
    /// rapier's default of 4 its hops vary by 10 %); a multibody's cost grows with them: see
    /// docs/guide/performance.md.
    #[serde(default = "default_solver_iterations")]
    pub solver_iterations: u32,
    /// The arena file, relative to the assets folder and inside it.
    pub arena: String,
    /// The creatures, by kind.
    pub creatures: Vec<CreatureGroup>,
    /// How each creature's level of detail is chosen (paper 3.4).
    pub level_policy: LevelPolicy,
    /// The level rules file (relative to the assets folder and inside it): influence areas, camera rule,
    /// switching window.
    pub level_rules: String,
}

/// So many creatures of one kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreatureGroup {
    /// A creature kind: the file `creatures/<kind>.ron` under the assets folder; letters,
    /// digits, '-' and '_' only.
    pub kind: String,
    /// 0 (the group is left out) to 2,000,000, and at least one creature in all.
    pub count: u32,
}

impl Scenario {
    /// Creatures in all groups.
    pub fn creature_count(&self) -> u32 {
        self.creatures.iter().map(|g| g.count).sum()
    }

    /// Simulation ticks per steering decision.
    pub fn ticks_per_decision(&self) -> u32 {
        self.tick_hz / self.decision_hz
    }
}

fn default_solver_iterations() -> u32 {
    8
}

/// Most creatures a scenario may hold.
pub const MAX_CREATURES: u32 = 2_000_000;

/// The longest run: the models keep time in f32 seconds, and past this their steps grow
/// toward a tick's length.
pub const MAX_DURATION_S: f32 = 10_000.0;

impl Validate for Scenario {
    fn validate(&self, v: &mut Validator) {
        v.within("duration_s", self.duration_s, 1e-3, MAX_DURATION_S);
        v.require(
            (30..=2000).contains(&self.tick_hz),
            "tick_hz",
            format!("must be between 30 and 2000, got {}", self.tick_hz),
        );
        v.require(
            self.decision_hz > 0 && self.decision_hz <= self.tick_hz && self.tick_hz.is_multiple_of(self.decision_hz),
            "decision_hz",
            format!(
                "must divide tick_hz ({}) evenly, got {}",
                self.tick_hz, self.decision_hz
            ),
        );
        v.require(
            (1..=16).contains(&self.solver_iterations),
            "solver_iterations",
            format!("must be between 1 and 16, got {}", self.solver_iterations),
        );
        v.asset_path("arena", &self.arena);
        v.asset_path("level_rules", &self.level_rules);
        v.require(!self.creatures.is_empty(), "creatures", "must list at least one group");
        for (i, g) in self.creatures.iter().enumerate() {
            v.kind_name(&format!("creatures[{i}].kind"), &g.kind);
        }
        let total: u64 = self.creatures.iter().map(|g| u64::from(g.count)).sum();
        v.require(
            (1..=u64::from(MAX_CREATURES)).contains(&total),
            "creatures",
            format!("must hold between 1 and {MAX_CREATURES} creatures in all, got {total}"),
        );
    }
}

/// How levels are chosen (a scenario's `level_policy`, or `--policy`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum LevelPolicy {
    /// Every creature at the point-mass level.
    #[default]
    AllPointMass,
    /// Every creature at the hybrid level.
    AllHybrid,
    /// Every creature at the rigid level.
    AllRigid,
    /// Areas of influence (figure 5): rigid inside another's area, else hybrid.
    Influence,
    /// The camera rule (figure 6): rigid in view and near, hybrid in view, else point mass.
    Camera,
    /// The more detailed of the two.
    Combined,
    /// A frame budget: each creature's level chosen so that the predicted cost stays within
    /// it, spent where a contact is soonest and the view nearest (beyond the paper).
    Budget,
}

impl LevelPolicy {
    /// Every policy, in the order the command line lists them.
    pub const ALL: [LevelPolicy; 7] = [
        LevelPolicy::AllPointMass,
        LevelPolicy::AllHybrid,
        LevelPolicy::AllRigid,
        LevelPolicy::Influence,
        LevelPolicy::Camera,
        LevelPolicy::Combined,
        LevelPolicy::Budget,
    ];

    /// The name used on the command line, in reports and in the game (`all-point-mass`).
    pub fn name(self) -> &'static str {
        match self {
            LevelPolicy::AllPointMass => "all-point-mass",
            LevelPolicy::AllHybrid => "all-hybrid",
            LevelPolicy::AllRigid => "all-rigid",
            LevelPolicy::Influence => "influence",
            LevelPolicy::Camera => "camera",
            LevelPolicy::Combined => "combined",
            LevelPolicy::Budget => "budget",
        }
    }

    /// What the policy does, in a line.
    pub fn describe(self) -> &'static str {
        match self {
            LevelPolicy::AllPointMass => "Every creature at the point-mass level",
            LevelPolicy::AllHybrid => "Every creature at the hybrid level",
            LevelPolicy::AllRigid => "Every creature at the rigid level",
            LevelPolicy::Influence => "Areas of influence (figure 5): rigid inside another's area, else hybrid",
            LevelPolicy::Camera => {
                "The camera rule (figure 6): rigid in view and near, hybrid in view, else point mass"
            }
            LevelPolicy::Combined => "The more detailed of the two",
            LevelPolicy::Budget => {
                "A frame budget: each creature's level chosen so that the predicted cost stays within it, spent where a contact is soonest and the view nearest (beyond the paper)"
            }
        }
    }

    /// Whether the policy reads the puck's radius of influence (figure 8).
    pub fn uses_puck_radius(self) -> bool {
        matches!(self, Self::Influence | Self::Combined)
    }

    /// Whether the policy reads the camera's radius of influence (figure 9).
    pub fn uses_camera_radius(self) -> bool {
        matches!(self, Self::Camera | Self::Combined)
    }

    /// Whether the policy reads the frame budget.
    pub fn uses_frame_budget(self) -> bool {
        self == Self::Budget
    }

    /// Whether levels change during a game under this policy.
    pub fn is_dynamic(self) -> bool {
        matches!(
            self,
            LevelPolicy::Influence | LevelPolicy::Camera | LevelPolicy::Combined | LevelPolicy::Budget
        )
    }

    /// The level a creature starts at, given the levels its kind has models for: the policy's
    /// level (hybrid for the rules, which then move it; the cheapest for the budget, which
    /// then spends it), or the most detailed one below it that the kind has.
    pub fn initial_level(self, available: &[Lod]) -> Lod {
        let wanted = match self {
            LevelPolicy::AllPointMass | LevelPolicy::Budget => Lod::PointMass,
            LevelPolicy::AllHybrid | LevelPolicy::Influence | LevelPolicy::Camera | LevelPolicy::Combined => {
                Lod::Hybrid
            }
            LevelPolicy::AllRigid => Lod::Rigid,
        };
        available
            .iter()
            .copied()
            .filter(|&l| l <= wanted)
            .max()
            .unwrap_or(Lod::PointMass)
    }
}
