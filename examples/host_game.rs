//! simlod as a guest in a game of your own: the game has rapier already, bodies of its own and
//! its own executor; simlod's creatures run beside them in the game's `FixedUpdate`, and a new
//! round takes away only simlod's bodies.
//!
//! ```sh
//! cargo run --release --example host_game
//! ```

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use std::path::Path;

use simlod::prelude::*;

/// A body of the game's own: a crate dropped from high above the court.
#[derive(Component)]
struct GameCrate;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let config = SimConfig::load(Path::new("assets/scenarios/default.ron"), Path::new("assets"))?;
    let ticks_per_frame = config.scenario.ticks_per_decision();

    let mut app = App::new();
    // The game's own physics, in its fixed schedule, before simlod is added.
    app.add_plugins((
        MinimalPlugins,
        TransformPlugin,
        RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule(),
    ));
    app.world_mut().spawn((
        GameCrate,
        RigidBody::Dynamic,
        Collider::cuboid(0.5, 0.5, 0.5),
        Transform::from_xyz(0.0, 40.0, 0.0),
    ));
    // simlod finds rapier there and uses it; it leaves the game's executor as it is.
    app.add_plugins(SimPlugin::new(config.clone()).keep_host_executor());
    app.finish();
    app.cleanup();
    app.update();
    run_ticks_per_update(app.world_mut(), ticks_per_frame);
    for _ in 0..60 {
        app.update();
    }
    let height = |app: &mut App| {
        let world = app.world_mut();
        world
            .query_filtered::<&Transform, With<GameCrate>>()
            .single(world)
            .map(|t| t.translation.y)
    };
    println!("after 2 s: the game's crate at {:.2} m", height(&mut app)?);

    // A new round: simlod's creatures, court and puck are built again; the crate, still in the
    // air, falls on and lands on the new court.
    start_over(app.world_mut(), config);
    for _ in 0..45 {
        app.update();
    }
    let world = app.world_mut();
    let rigid = world.query_filtered::<(), With<AtRigid>>().iter(world).count();
    let creatures = world.query::<&Creature>().iter(world).count();
    let contexts = world.query::<&RapierContextSimulation>().iter(world).count();
    println!(
        "after a new round and 1.5 s: the crate at {:.2} m; {creatures} creatures, {rigid} rigid; rapier worlds: {contexts}",
        height(&mut app)?
    );
    Ok(())
}
