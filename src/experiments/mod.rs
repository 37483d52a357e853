//! The paper's experiments: `simlod experiment <name> --out DIR` writes their data as CSV.

pub mod step_response;

/// The side of the square court the single-creature experiments and the gait recorder run
/// in: room for a long run without meeting a wall.
pub const EXPERIMENT_COURT_M: f32 = 300.0;

use bevy::prelude::*;

use crate::config::SimConfig;
use crate::creature::{Creature, DesiredVelocity, PlanarState, PlayerControlled};
use crate::headless::HeadlessSim;
use crate::lod::{LevelPolicy, Lod};

/// A world with one creature of `kind` at the level `policy` gives it, standing at `start`,
/// steered from outside, the puck parked. The court is grown to `court_m` square so it can
/// run for a while.
pub fn lone_creature(
    config: &SimConfig,
    kind: &str,
    policy: LevelPolicy,
    start: Vec2,
    court_m: f32,
) -> (HeadlessSim, Entity) {
    let mut config = config.clone();
    config.scenario.creatures.retain(|g| g.kind == kind);
    config.scenario.creatures[0].count = 1;
    config.scenario.level_policy = policy;
    config.arena.court_length_m = config.arena.court_length_m.max(court_m);
    config.arena.court_width_m = config.arena.court_width_m.max(court_m);
    // Parked: too slow to reach anyone during an experiment.
    config.arena.puck.speed_m_per_s = 1e-3;
    let mut sim = HeadlessSim::new(config);
    let world = sim.app.world_mut();
    let entity = world
        .query_filtered::<Entity, With<Creature>>()
        .single(world)
        .expect("one creature");
    world
        .entity_mut(entity)
        .insert((PlayerControlled, DesiredVelocity(Vec2::ZERO)));
    stand(world, entity, start, None);
    (sim, entity)
}

/// Moves a creature to `position` (and turns it to `heading`, if given) between ticks, and
/// enters its level again there, so that its model (a rigid creature's bodies) stands there too.
pub fn stand(world: &mut World, entity: Entity, position: Vec2, heading: Option<Vec2>) {
    let mut e = world.entity_mut(entity);
    let mut state = e.get_mut::<PlanarState>().expect("a creature has a planar state");
    state.position = position;
    if let Some(heading) = heading {
        state.heading = heading;
    }
    let level = *e.get::<Lod>().expect("a creature has a level");
    e.insert(level);
    world.flush();
}
