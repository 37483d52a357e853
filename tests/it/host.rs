//! simlod as a guest in an app of someone else's: the host's rapier, bodies and schedule.

use bevy::ecs::schedule::ScheduleLabel;
use bevy::prelude::*;
use bevy_rapier3d::prelude::*;

use crate::support::*;
use simlod::prelude::*;

/// A body of the host's own.
#[derive(Component)]
struct HostBody;

/// A host app with its own rapier and a ball of its own, 20 m above the court; simlod added after.
fn host_with_rapier() -> App {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        TransformPlugin,
        RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule(),
    ));
    app.world_mut().spawn((
        HostBody,
        RigidBody::Dynamic,
        Collider::ball(0.5),
        Transform::from_xyz(0.0, 20.0, 0.0),
    ));
    app.add_plugins(SimPlugin::new(default_config()).keep_host_executor());
    app.finish();
    app.cleanup();
    app.update();
    run_ticks_per_update(app.world_mut(), 8);
    app
}

fn host_body_height(app: &mut App) -> f32 {
    let world = app.world_mut();
    let (height, handle) = world
        .query_filtered::<(&Transform, &RapierRigidBodyHandle), With<HostBody>>()
        .single(world)
        .map(|(t, h)| (t.translation.y, h.0))
        .expect("the host's body is still there");
    let in_rapier = world
        .query::<&RapierRigidBodySet>()
        .iter(world)
        .any(|set| set.bodies.get(handle).is_some());
    assert!(in_rapier, "the host's body is in rapier's set");
    height
}

#[test]
fn a_host_with_its_own_rapier_keeps_its_bodies_through_a_new_round() {
    let mut app = host_with_rapier();
    assert_eq!(
        app.world_mut()
            .query::<&RapierContextSimulation>()
            .iter(app.world())
            .count(),
        1,
        "simlod used the host's rapier, not one of its own"
    );
    for _ in 0..15 {
        app.update();
    }
    let before = host_body_height(&mut app);
    assert!(before < 19.0, "the host's ball falls under the host's rapier: {before}");
    let creatures = |app: &mut App| {
        let world = app.world_mut();
        world.query::<&Creature>().iter(world).count()
    };
    assert_eq!(creatures(&mut app), 40);
    start_over(app.world_mut(), default_config());
    for _ in 0..5 {
        app.update();
    }
    let after = host_body_height(&mut app);
    assert!(after < before, "the ball went on falling: {before} then {after}");
    assert_eq!(creatures(&mut app), 40);
    assert!(app.world().resource::<SimClock>().tick > 0);
}

/// A schedule of the host's own, run by the host.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
struct HostTick;

#[test]
fn the_simulation_runs_in_the_schedule_the_host_gives_it_and_only_there() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, SimPlugin::new(default_config()).in_schedule(HostTick)));
    app.finish();
    app.cleanup();
    app.update();
    run_ticks_per_update(app.world_mut(), 8);
    for _ in 0..10 {
        app.update();
    }
    assert_eq!(
        app.world().resource::<SimClock>().tick,
        0,
        "FixedUpdate runs none of simlod's systems"
    );
    let start: Vec<Vec2> = {
        let world = app.world_mut();
        world.query::<&PlanarState>().iter(world).map(|s| s.position).collect()
    };
    for _ in 0..240 {
        app.world_mut().run_schedule(HostTick);
    }
    assert_eq!(app.world().resource::<SimClock>().tick, 240);
    let world = app.world_mut();
    let moved = world
        .query::<&PlanarState>()
        .iter(world)
        .zip(&start)
        .filter(|(s, p)| s.position.distance(**p) > 0.1)
        .count();
    assert!(moved > 30, "a simulated second moved the creatures: {moved} of 40");
}

#[test]
fn an_area_of_influence_of_the_hosts_own_makes_a_creature_in_it_rigid() {
    let mut config = default_config();
    config.scenario.level_policy = LevelPolicy::Influence;
    // After 4 s, the creature the rule wants hybrid that is farthest from the puck; then the
    // level the rule wants for it a frame later, with or without an area of the host's there.
    let wanted_after = |area: bool| {
        let mut sim = HeadlessSim::new(config.clone());
        sim.run_for(4.0);
        let world = sim.app.world_mut();
        let puck = world.resource::<simlod::arena::PuckState>().position;
        let (serial, at) = world
            .query::<(&Creature, &PlanarState, &LevelChoice)>()
            .iter(world)
            .filter(|(_, _, choice)| choice.wanted == Lod::Hybrid)
            .max_by(|a, b| a.1.position.distance(puck).total_cmp(&b.1.position.distance(puck)))
            .map(|(c, s, _)| (c.serial, s.position))
            .expect("a hybrid creature");
        if area {
            world.spawn((InfluenceArea { radius_m: 1.0 }, Transform::from_xyz(at.x, 0.0, at.y)));
        }
        sim.advance_frame();
        let world = sim.app.world_mut();
        world
            .query::<(&Creature, &LevelChoice)>()
            .iter(world)
            .find(|(c, _)| c.serial == serial)
            .map(|(_, choice)| choice.wanted)
            .expect("the creature is still there")
    };
    assert_eq!(wanted_after(false), Lod::Hybrid);
    assert_eq!(wanted_after(true), Lod::Rigid);
}
