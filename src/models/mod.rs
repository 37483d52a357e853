//! Step: the model behind each level of detail.

pub mod hybrid;
pub mod point_mass;
pub mod rigid;

use bevy::prelude::*;

pub(super) fn plugin(app: &mut App) {
    point_mass::plugin(app);
    rigid::plugin(app);
}
