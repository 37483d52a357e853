//! Simulation levels of detail (paper section 3): the level each creature is simulated at,
//! and the policy that picks it.
//!
//! Only levels with a working model behind them exist: the point mass (section 3.3), the
//! hybrid (3.2) and the rigid body (3.1).

mod blend;
mod budget;
mod select;
mod switch;

pub use crate::config::LevelPolicy;
pub use crate::contract::{AtHybrid, AtPointMass, AtRigid, Lod};
use crate::kind::Creature;
pub use blend::{Drawn, DrawnBefore, Pop, PopSummary, PopTally, Spread, SwitchBlend, SwitchProbe, drawn};
pub use budget::{
    Allocation, BudgetSummary, BudgetTally, Candidate, RecentFrames, allocate, choice_now, nearest_rank,
    percentile_window,
};
pub use select::{CameraFromView, InfluenceArea, LevelChoice, LevelsSettled, SimCamera, ViewReach, in_influence};
pub use switch::{LevelSwitched, SwitchTally};

use bevy::prelude::*;

pub(super) fn plugin(app: &mut App) {
    // What this layer keeps of each creature: the level it wants, and how it was last drawn.
    app.register_required_components::<Creature, LevelChoice>()
        .register_required_components::<Creature, DrawnBefore>();
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
