//! simlod: simulation levels of detail for real-time animation.
//!
//! After Carlson & Hodgins, *Simulation Levels of Detail for Real-time Animation*
//! (Graphics Interface '97). Legged creatures try to escape a giant puck in a walled court;
//! each is simulated at a level of detail ([`lod::Lod`]) chosen per creature.
//!
//! The paper's pipeline is the layout. Once per simulation tick, in `FixedUpdate` (or the
//! schedule given to [`SimPlugin::in_schedule`]):
//!
//! | stage | module | what |
//! |---|---|---|
//! | [`SimStage::Sense`] | [`sense`] | spatial index of creatures; the puck's state |
//! | [`SimStage::Steer`] | [`creature::steering`] | desired velocity: flee the puck, avoid walls and others |
//! | [`SimStage::SelectLod`] | [`lod`] | the level each creature should be at: influence areas, camera rule |
//! | [`SimStage::Switch`] | [`lod`] | a change of level, inside the flight-phase window |
//! | [`SimStage::Step`] | [`models`] | the model of each creature's level |
//! | rapier's `PhysicsSet`s | [`third_party`] | the puck, the walls and the rigid creatures (rapier bodies) |
//! | [`SimStage::Observe`] | [`outcome`] | collisions with the puck, walls and other creatures |
//! | [`SimStage::Outcome`] | [`outcome`], [`lod`] | fallen creatures removed and respawned; what is drawn across a switch |
//! | [`SimStage::Clock`] | [`outcome`] | the tick ends: the clock moves on |
//!
//! # Where to start
//!
//! - [`config::SimConfig::load`] reads a scenario and every file it names from an assets
//!   folder, checked; [`SimPlugin`] adds the simulation it describes to an `App`.
//! - [`headless::HeadlessSim`] drives that app a frame at a time without a window, and
//!   [`headless::run`] runs a scenario and returns its [`outcome::Summary`].
//! - Each creature is an entity with a [`creature::Creature`] and its level, [`lod::Lod`];
//!   every level publishes [`creature::PlanarState`], [`creature::GaitPhase`] and
//!   [`gait::GaitPose`], which is all the rest of the program reads.
//! - The level policy and rules are fields of the [`config::SimConfig`] resource, read at
//!   every steering decision: [`lod::LevelPolicy`], [`config::LevelRules`].
//!
//! [`prelude`] holds what a host app usually needs. The `examples/` folder has runnable
//! programs (`host_game.rs` adds simlod to an app that has rapier and bodies of its own), and
//! `docs/guide/` the user guide; its architecture page draws the layers of this crate.

#![warn(missing_docs)]

/// Runs a closure over every item of a query, across threads only when there are enough
/// creatures to pay for waking them.
macro_rules! for_each_creature {
    ($population:expr, $query:expr, $f:expr) => {{
        let f = $f;
        if $population < $crate::PARALLEL_MIN_CREATURES {
            $query.iter_mut().for_each(f)
        } else {
            $query.par_iter_mut().for_each(f)
        }
    }};
}

pub mod arena;
pub mod config;
pub mod contract;
pub mod creature;
pub mod headless;
pub mod kind;
pub mod lod;
pub mod models;
pub mod outcome;
pub mod plugin;
pub mod sense;
pub mod third_party;

pub use config::gait;
pub use contract::{
    DENSE, PARALLEL_MIN_CREATURES, SimClock, SimEntity, SimStage, SimStart, StartStage, WorldRng, chunk_len, run_chunks,
};
pub use plugin::{SimPlugin, start_over};

/// What a game or tool that adds simlod to its app usually needs, in one import:
/// `use simlod::prelude::*;`.
pub mod prelude {
    pub use crate::config::{LevelPolicy, SimConfig};
    pub use crate::contract::{
        AtHybrid, AtPointMass, AtRigid, CollisionRecord, DesiredVelocity, GaitPhase, GaitPose, Lod, Obstacle,
        PlanarState, PlayerControlled, SimClock, SimEntity, SimStage, SimStart, StartStage,
    };
    pub use crate::headless::{HeadlessSim, run_ticks_per_update};
    pub use crate::kind::{Creature, KindTable};
    pub use crate::lod::{InfluenceArea, LevelChoice};
    pub use crate::outcome::{Summary, summarize};
    pub use crate::plugin::{SimPlugin, start_over};
}
