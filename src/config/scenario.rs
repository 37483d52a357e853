//! A scenario: which creatures, how many, the seed and the level policy.

use super::{Validate, Validator};
use crate::lod::LevelPolicy;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Seeds the world's one RNG: same seed and files, same game.
    pub seed: u64,
    /// Length of a run when the command line does not say.
    pub duration_s: f32,
    /// Simulation ticks per second (the physics step); a multiple of `decision_hz`.
    pub tick_hz: u32,
    /// Steering decisions per second; the paper's frame rate is 30.
    pub decision_hz: u32,
    /// The arena file, relative to the assets folder.
    pub arena: String,
    pub creatures: Vec<CreatureGroup>,
    pub level_policy: LevelPolicy,
    /// The level rules file (relative to the assets folder): influence areas, camera rule,
    /// switching window.
    pub level_rules: String,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreatureGroup {
    /// A creature kind: the file `creatures/<kind>.ron` under the assets folder.
    pub kind: String,
    pub count: u32,
}

impl Scenario {
    pub fn creature_count(&self) -> u32 {
        self.creatures.iter().map(|g| g.count).sum()
    }

    /// Simulation ticks per steering decision.
    pub fn ticks_per_decision(&self) -> u32 {
        self.tick_hz / self.decision_hz
    }
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
        v.require(!self.arena.is_empty(), "arena", "must name the arena file");
        v.require(!self.creatures.is_empty(), "creatures", "must list at least one group");
        for (i, g) in self.creatures.iter().enumerate() {
            v.require(
                !g.kind.is_empty(),
                &format!("creatures[{i}].kind"),
                "must name a creature kind",
            );
        }
        let total: u64 = self.creatures.iter().map(|g| u64::from(g.count)).sum();
        v.require(
            (1..=u64::from(MAX_CREATURES)).contains(&total),
            "creatures",
            format!("must hold between 1 and {MAX_CREATURES} creatures in all, got {total}"),
        );
    }
}
