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
    /// Rapier rigid bodies and joints driven by Raibert's controller (section 3.1).
    Rigid,
}

impl Lod {
    pub const ALL: [Lod; 2] = [Lod::PointMass, Lod::Rigid];

    /// The name used in summaries and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Lod::PointMass => "point_mass",
            Lod::Rigid => "rigid",
        }
    }
}

/// How levels are chosen (a scenario's `level_policy`, or `--policy`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
pub enum LevelPolicy {
    /// Every creature at the point-mass level.
    #[default]
    AllPointMass,
    /// Every creature whose kind has a rigid model at the rigid level; the others at the
    /// point-mass level.
    AllRigid,
}

impl LevelPolicy {
    /// The level a newly spawned creature of a kind starts at.
    pub fn initial_level(self, has_rigid_model: bool) -> Lod {
        match self {
            LevelPolicy::AllRigid if has_rigid_model => Lod::Rigid,
            LevelPolicy::AllPointMass | LevelPolicy::AllRigid => Lod::PointMass,
        }
    }
}
