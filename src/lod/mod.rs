//! Simulation levels of detail (paper section 3): the level each creature is simulated at,
//! and the policy that picks it.
//!
//! Only levels with a working model behind them exist. The point-mass level (section 3.3) is
//! here; the hybrid and rigid levels arrive with their models.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// The level of detail a creature is simulated at.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Lod {
    /// A point mass on the plane with an acceleration limit; the leg held at a constant
    /// angle (section 3.3).
    #[default]
    PointMass,
}

impl Lod {
    pub const ALL: [Lod; 1] = [Lod::PointMass];

    /// The name used in summaries and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Lod::PointMass => "point_mass",
        }
    }
}

/// How levels are chosen (a scenario's `level_policy`, or `--policy`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
pub enum LevelPolicy {
    /// Every creature at the point-mass level.
    #[default]
    AllPointMass,
}

impl LevelPolicy {
    /// The level a newly spawned creature starts at.
    pub fn initial_level(self) -> Lod {
        match self {
            LevelPolicy::AllPointMass => Lod::PointMass,
        }
    }
}
