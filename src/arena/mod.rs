//! The court, its walls and the giant puck (paper section 3): rapier bodies.
//!
//! The puck "slides passively around a rectangular court bouncing off the walls": a
//! frictionless dynamic body, elastic against the walls. Rapier's solver loses a little
//! energy at each bounce, so the puck is held at its configured speed, direction free.

pub use crate::contract::{Ground, Puck, Wall};
pub use crate::sense::{Court, PuckState};

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use rand::RngExt;

use crate::config::SimConfig;
use crate::contract::SimClock;
use crate::contract::{SimEntity, SimStage, SimStart, StartStage, WorldRng};

/// A launch direction away from the axes, so the puck does not bounce forever on one line.
fn launch_direction(rng: &mut WorldRng) -> Vec2 {
    let quadrant = rng.0.random_range(0..4) as f32;
    let angle = (quadrant * 90.0 + rng.0.random_range(25.0..65.0f32)).to_radians();
    Vec2::from_angle(angle)
}

fn spawn_arena(mut commands: Commands, config: Res<SimConfig>, mut rng: ResMut<WorldRng>) {
    let arena = &config.arena;
    let half = arena.half_extents();
    commands.insert_resource(Court { half_extents: half });
    commands.insert_resource(PuckState {
        radius_m: arena.puck.radius_m,
        ..default()
    });
    let (t, h) = (arena.wall_thickness_m, arena.wall_height_m);
    // Ground: a slab whose top is y = 0.
    commands.spawn((
        Name::new("ground"),
        Ground,
        Friction::coefficient(1.0),
        SimEntity,
        RigidBody::Fixed,
        Collider::cuboid(half.x + t, 0.5, half.y + t),
        Transform::from_xyz(0.0, -0.5, 0.0),
    ));
    for (name, centre, extents) in [
        (
            "wall +x",
            Vec3::new(half.x + t / 2.0, h / 2.0, 0.0),
            Vec3::new(t / 2.0, h / 2.0, half.y + t),
        ),
        (
            "wall -x",
            Vec3::new(-half.x - t / 2.0, h / 2.0, 0.0),
            Vec3::new(t / 2.0, h / 2.0, half.y + t),
        ),
        (
            "wall +z",
            Vec3::new(0.0, h / 2.0, half.y + t / 2.0),
            Vec3::new(half.x + t, h / 2.0, t / 2.0),
        ),
        (
            "wall -z",
            Vec3::new(0.0, h / 2.0, -half.y - t / 2.0),
            Vec3::new(half.x + t, h / 2.0, t / 2.0),
        ),
    ] {
        commands.spawn((
            Name::new(name),
            Wall,
            SimEntity,
            RigidBody::Fixed,
            Collider::cuboid(extents.x, extents.y, extents.z),
            Restitution {
                coefficient: 1.0,
                combine_rule: CoefficientCombineRule::Max,
            },
            Transform::from_translation(centre),
        ));
    }
    let puck = &arena.puck;
    let velocity = launch_direction(&mut rng) * puck.speed_m_per_s;
    commands.spawn((
        Name::new("puck"),
        Puck,
        SimEntity,
        RigidBody::Dynamic,
        Collider::cylinder(puck.height_m / 2.0, puck.radius_m),
        ColliderMassProperties::Mass(puck.mass_kg),
        // It slides: no friction, no bounce losses, held at its height.
        Friction {
            coefficient: 0.0,
            combine_rule: CoefficientCombineRule::Min,
        },
        Restitution {
            coefficient: 1.0,
            combine_rule: CoefficientCombineRule::Max,
        },
        LockedAxes::ROTATION_LOCKED | LockedAxes::TRANSLATION_LOCKED_Y,
        Velocity::linear(Vec3::new(velocity.x, 0.0, velocity.y)),
        Transform::from_xyz(0.0, puck.height_m / 2.0 + 0.01, 0.0),
    ));
}

/// Holds the puck at its speed and publishes its state for this tick.
fn drive_puck(
    config: Res<SimConfig>,
    mut state: ResMut<PuckState>,
    mut puck: Query<(&Transform, &mut Velocity), With<Puck>>,
) {
    let Ok((transform, mut velocity)) = puck.single_mut() else {
        return;
    };
    let planar = Vec2::new(velocity.linear.x, velocity.linear.z);
    let speed = config.arena.puck.speed_m_per_s;
    let planar = planar.try_normalize().map_or(planar, |d| d * speed);
    if velocity.linear.x != planar.x || velocity.linear.z != planar.y {
        velocity.linear = Vec3::new(planar.x, 0.0, planar.y);
    }
    *state = PuckState {
        position: Vec2::new(transform.translation.x, transform.translation.z),
        velocity: planar,
        radius_m: config.arena.puck.radius_m,
    };
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.add_systems(SimStart, spawn_arena.in_set(StartStage::Arena))
        .add_systems(schedule, drive_puck.in_set(SimStage::Sense));
}
