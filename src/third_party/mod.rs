//! Third-party plugins, set up in one place: what the rest of the program needs from them is
//! named here, and their quirks are handled here.

pub mod rapier;

use bevy::prelude::*;

pub(super) fn plugin(app: &mut App) {
    rapier::plugin(app);
}
