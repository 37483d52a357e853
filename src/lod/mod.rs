//! Simulation levels of detail (paper section 3): the level each creature is simulated at,
//! and the policy that picks it.
//!
//! Only levels with a working model behind them exist: the point mass (section 3.3), the
//! hybrid (3.2) and the rigid body (3.1).

mod blend;
mod budget;
mod select;
mod switch;

pub use blend::{Drawn, DrawnBefore, Pop, PopSummary, PopTally, Spread, SwitchBlend, SwitchProbe, drawn};
pub use budget::{Allocation, BudgetSummary, BudgetTally, Candidate, allocate, corrected};
pub use select::{CameraFromView, LevelChoice, SimCamera, in_influence};
pub use switch::{LevelSwitched, SwitchTally};

use bevy::ecs::lifecycle::HookContext;
use bevy::ecs::world::DeferredWorld;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// The level of detail a creature is simulated at; ordered from the cheapest to the most
/// detailed. Inserting a new `Lod` is the switch: its hooks move the creature's level marker
/// ([`AtPointMass`], [`AtHybrid`], [`AtRigid`]), and each level's observers on its marker
/// build and tear down what that level is made of. Nothing else knows what a level holds.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[component(on_insert = Lod::mark, on_discard = Lod::unmark)]
pub enum Lod {
    /// A point mass on the plane with an acceleration limit; the leg held at a constant
    /// angle (section 3.3).
    #[default]
    PointMass,
    /// The same point mass, with the body and leg posed from the gait table recorded from the
    /// rigid model (section 3.2).
    Hybrid,
    /// Rapier rigid bodies and joints driven by Raibert's controller (section 3.1).
    Rigid,
}

impl Lod {
    /// From the cheapest to the most detailed.
    pub const ALL: [Lod; 3] = [Lod::PointMass, Lod::Hybrid, Lod::Rigid];

    /// The point-mass and hybrid levels share one planar body (and its collisions).
    pub fn moves_as_point_mass(self) -> bool {
        self != Lod::Rigid
    }

    /// The name used in summaries and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Lod::PointMass => "point_mass",
            Lod::Hybrid => "hybrid",
            Lod::Rigid => "rigid",
        }
    }

    /// What the level is, in a line.
    pub fn describe(self) -> &'static str {
        match self {
            Lod::PointMass => {
                "A point mass on the plane with an acceleration limit; the leg held at a constant angle (section 3.3)"
            }
            Lod::Hybrid => {
                "The same point mass, with the body and leg posed from the gait table recorded from the rigid model (section 3.2)"
            }
            Lod::Rigid => "Rapier rigid bodies and joints driven by Raibert's controller (section 3.1)",
        }
    }

    /// Entering a level: the creature gets that level's marker.
    fn mark(mut world: DeferredWorld, context: HookContext) {
        let Some(&lod) = world.get::<Lod>(context.entity) else {
            return;
        };
        let mut commands = world.commands();
        let mut entity = commands.entity(context.entity);
        match lod {
            Lod::PointMass => entity.try_insert(AtPointMass),
            Lod::Hybrid => entity.try_insert(AtHybrid),
            Lod::Rigid => entity.try_insert(AtRigid),
        };
    }

    /// Leaving a level (or the world): the level's marker goes.
    fn unmark(mut world: DeferredWorld, context: HookContext) {
        let Some(&lod) = world.get::<Lod>(context.entity) else {
            return;
        };
        let mut commands = world.commands();
        let mut entity = commands.entity(context.entity);
        match lod {
            Lod::PointMass => entity.try_remove::<AtPointMass>(),
            Lod::Hybrid => entity.try_remove::<AtHybrid>(),
            Lod::Rigid => entity.try_remove::<AtRigid>(),
        };
    }
}

/// Marks a creature at the point-mass level (paper 3.3). The level markers make the queries
/// of different levels provably disjoint, so their systems cannot race.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct AtPointMass;

/// Marks a creature at the hybrid level (paper 3.2).
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct AtHybrid;

/// Marks a creature at the rigid level (paper 3.1): adding it builds the bodies, removing it
/// (a switch down, or a fall) takes them away.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct AtRigid;

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

pub(super) fn plugin(app: &mut App) {
    select::plugin(app);
    budget::plugin(app);
    switch::plugin(app);
    blend::plugin(app);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_kind_without_the_wanted_model_gets_the_most_detailed_level_below_it() {
        assert_eq!(
            LevelPolicy::AllRigid.initial_level(&[Lod::PointMass, Lod::Hybrid]),
            Lod::Hybrid
        );
        assert_eq!(LevelPolicy::AllRigid.initial_level(&[Lod::PointMass]), Lod::PointMass);
        assert_eq!(LevelPolicy::AllHybrid.initial_level(&Lod::ALL), Lod::Hybrid);
        assert_eq!(LevelPolicy::AllPointMass.initial_level(&Lod::ALL), Lod::PointMass);
    }
}
