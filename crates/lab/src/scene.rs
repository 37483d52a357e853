//! The scenes the lab's tools run: a scenario scaled to a creature count, one kind alone, and a
//! lone creature standing in a court too big to reach a wall. The bottom of the lab: the
//! recorder, the bench and the experiments build on it.

use bevy::prelude::*;

use simlod::config::SimConfig;
use simlod::creature::{Creature, DesiredVelocity, PlanarState, PlayerControlled};
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelPolicy, Lod};

/// The side of the square court the single-creature experiments and the gait recorder run
/// in: room for a long run without meeting a wall.
pub const EXPERIMENT_COURT_M: f32 = 300.0;

/// The scenario with only creatures of `kind`, `count` of them.
pub fn only_kind(config: &SimConfig, kind: &str) -> SimConfig {
    let mut c = config.clone();
    let count = c.scenario.creature_count();
    c.scenario.creatures.retain(|g| g.kind == kind);
    c.scenario.creatures[0].count = count;
    c
}

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

/// The scenario with `count` creatures of the same mix, in a court grown to the same density.
/// A scenario of no creatures at all has no density: its first group gets them all, in the
/// court as if the scenario had one.
pub fn scaled(config: &SimConfig, count: u32, policy: LevelPolicy) -> SimConfig {
    let mut c = config.clone();
    let base = config.scenario.creature_count().max(1);
    let mut left = count;
    for (i, g) in c.scenario.creatures.iter_mut().enumerate().rev() {
        g.count = if i == 0 {
            left
        } else {
            (u64::from(g.count) * u64::from(count) / u64::from(base)) as u32
        };
        left -= g.count;
    }
    c.scenario.creatures.retain(|g| g.count > 0);
    let grow = (count as f32 / base as f32).max(1.0).sqrt();
    c.arena.court_length_m *= grow;
    c.arena.court_width_m *= grow;
    c.scenario.level_policy = policy;
    c
}
