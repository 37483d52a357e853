//! Drawing the creatures from their current model, coloured by level (paper figures 5, 6).
//!
//! A simulated creature has no transform; each gets a drawing of its own: a root entity
//! with a body and its legs as children. Drawing is two steps. First, the draw system of
//! each level writes the [`CreaturePose`] of the creatures at that level from what that
//! model knows: the point mass (here) from its planar state and hop phase, with the leg at
//! a constant angle; a rigid level would copy its rapier bodies, a hybrid level would look
//! its pose up in the gait table. Then [`apply_poses`] moves the meshes, whatever the level.

use bevy::camera::visibility::RenderLayers;
use bevy::prelude::*;

use super::GameSettings;
use super::player::Round;
use super::scene::Palette;
use crate::SimEntity;
use crate::config::SimConfig;
use crate::creature::{Creature, GaitPhase, KindTable, PlanarState};
use crate::lod::Lod;
use crate::models::rigid::{RigidHopper, RigidPart};

/// Gravity for the drawn hop of a point mass, which has no vertical motion of its own.
const GRAVITY_M_PER_S2: f32 = 9.81;

/// The two steps of drawing, in `Update`.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DrawCreatures {
    /// Each level's draw system writes the poses of its creatures.
    Pose,
    /// The meshes follow the poses.
    Apply,
}

/// The drawing of one simulated creature.
#[derive(Component, Debug)]
pub struct CreatureVisual {
    pub creature: Entity,
    body: Entity,
    legs: Vec<Entity>,
    /// Its dot in the overhead view.
    dot: Entity,
}

/// The render layer only the overhead view sees: dots and the view cone.
pub const OVERHEAD_ONLY: usize = 1;

/// Where a creature's parts are this frame, in world space.
#[derive(Component, Debug, Default, Clone, PartialEq)]
pub struct CreaturePose {
    /// The body's centre and orientation (`-z` forward).
    pub body: Transform,
    /// Body radius, for the body mesh's scale.
    pub body_radius_m: f32,
    /// Hip and foot of each leg.
    pub legs: Vec<(Vec3, Vec3)>,
    /// The level the pose was drawn from, for the body's colour.
    pub level: Lod,
}

/// A unit sphere and a unit cylinder, scaled per part.
#[derive(Resource)]
struct PartMeshes {
    sphere: Handle<Mesh>,
    cylinder: Handle<Mesh>,
    ring: Handle<Mesh>,
    disc: Handle<Mesh>,
}

/// A ring on the ground under the player's creature, this many footprint radii across: a
/// small one for the player's view, a big one for the overhead view.
#[derive(Component)]
struct PlayerMarker {
    radii: f32,
}

fn spawn_visuals(
    mut commands: Commands,
    config: Res<SimConfig>,
    settings: Res<GameSettings>,
    meshes: Res<PartMeshes>,
    palette: Res<Palette>,
    creatures: Query<(Entity, &Creature, &Lod), Added<Creature>>,
) {
    for (entity, creature, lod) in &creatures {
        let name = &config.kinds[creature.kind].name;
        let leg_count = if settings.creature_look.two_legged_kinds.contains(name) {
            2
        } else {
            1
        };
        let body = commands
            .spawn((Mesh3d(meshes.sphere.clone()), MeshMaterial3d(palette.body(*lod))))
            .id();
        let dot = commands
            .spawn((
                Mesh3d(meshes.disc.clone()),
                MeshMaterial3d(palette.body(*lod)),
                RenderLayers::layer(OVERHEAD_ONLY),
            ))
            .id();
        let legs: Vec<Entity> = (0..leg_count)
            .map(|_| {
                commands
                    .spawn((Mesh3d(meshes.cylinder.clone()), MeshMaterial3d(palette.leg.clone())))
                    .id()
            })
            .collect();
        commands
            .spawn((
                Name::new(format!("{name} {}", creature.serial)),
                SimEntity,
                Transform::default(),
                Visibility::default(),
                CreaturePose::default(),
            ))
            .add_children(&[body, dot])
            .add_children(&legs)
            .insert(CreatureVisual {
                creature: entity,
                body,
                legs,
                dot,
            });
    }
}

/// A creature removed by the simulation (it fell) takes its drawing with it.
fn despawn_orphans(
    mut commands: Commands,
    visuals: Query<(Entity, &CreatureVisual)>,
    creatures: Query<(), With<Creature>>,
) {
    for (visual, v) in &visuals {
        if creatures.get(v.creature).is_err() {
            commands.entity(visual).despawn();
        }
    }
}

/// Height of the drawn hop at `cycle`: a ballistic arc over the flight part of the cycle.
fn hop_height_m(cycle: f32, stance_fraction: f32, cycles_per_s: f32) -> f32 {
    if cycle < stance_fraction {
        return 0.0;
    }
    let flight_s = (1.0 - stance_fraction) / cycles_per_s;
    let t = (cycle - stance_fraction) / cycles_per_s;
    0.5 * GRAVITY_M_PER_S2 * t * (flight_s - t)
}

/// The point-mass level (paper 3.3): the body where the point mass is, facing its heading,
/// hopping with the gait phase; the leg held at a constant angle.
fn pose_point_masses(
    config: Res<SimConfig>,
    kinds: Res<KindTable>,
    settings: Res<GameSettings>,
    creatures: Query<(&Creature, &Lod, &PlanarState, &GaitPhase)>,
    mut visuals: Query<(&CreatureVisual, &mut CreaturePose)>,
) {
    let look = &settings.creature_look;
    let (sin, cos) = look.point_mass_leg_angle_deg.to_radians().sin_cos();
    for (visual, mut pose) in &mut visuals {
        let Ok((creature, &Lod::PointMass, state, gait)) = creatures.get(visual.creature) else {
            continue;
        };
        let kind = &kinds[creature.kind];
        let body_radius = kind.radius_m * look.body_radius_fraction;
        let hip_height = config.kinds[creature.kind].body.hip_height_m;
        let hop = hop_height_m(gait.cycle, kind.stance_fraction, kind.cycles_per_s);
        let forward = Vec3::new(state.heading.x, 0.0, state.heading.y);
        let centre = Vec3::new(state.position.x, hip_height + hop, state.position.y);
        let body = Transform::from_translation(centre).looking_to(forward, Vec3::Y);
        let side = body.right().as_vec3() * body_radius * 0.5;
        let hip_drop = Vec3::Y * body_radius * 0.5;
        // Long enough that the foot is on the ground in stance.
        let leg_length = (hip_height - body_radius * 0.5) / cos;
        let leg = (forward * sin - Vec3::Y * cos) * leg_length;
        let hips: &[Vec3] = if visual.legs.len() == 2 {
            &[centre - hip_drop - side, centre - hip_drop + side]
        } else {
            &[centre - hip_drop]
        };
        pose.body = body;
        pose.body_radius_m = body_radius;
        pose.legs = hips.iter().map(|&hip| (hip, hip + leg)).collect();
        pose.level = Lod::PointMass;
    }
}

/// The rigid level (paper 3.1): the body and the leg where rapier has them.
fn pose_rigid_hoppers(
    kinds: Res<KindTable>,
    settings: Res<GameSettings>,
    creatures: Query<(&Creature, &Lod, &RigidHopper)>,
    parts: Query<&Transform, With<RigidPart>>,
    mut visuals: Query<(&CreatureVisual, &mut CreaturePose)>,
) {
    // Rapier's body faces +x; a pose faces -z.
    let to_pose = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    for (visual, mut pose) in &mut visuals {
        let Ok((creature, &Lod::Rigid, hopper)) = creatures.get(visual.creature) else {
            continue;
        };
        let (Ok(body), Ok(hip), Ok(foot)) = (
            parts.get(hopper.body),
            parts.get(hopper.upper_leg),
            parts.get(hopper.lower_leg),
        ) else {
            continue;
        };
        pose.body = Transform::from_translation(body.translation).with_rotation(body.rotation * to_pose);
        pose.body_radius_m = kinds[creature.kind].radius_m * settings.creature_look.body_radius_fraction;
        pose.legs = vec![(hip.translation, foot.translation)];
        pose.level = Lod::Rigid;
    }
}

/// Moves the meshes of every creature to its pose, and colours its body by its level.
fn apply_poses(
    settings: Res<GameSettings>,
    palette: Res<Palette>,
    mut roots: Query<(&CreatureVisual, &CreaturePose, &mut Transform)>,
    mut parts: Query<(&mut Transform, Option<&mut MeshMaterial3d<StandardMaterial>>), Without<CreatureVisual>>,
) {
    let look = &settings.creature_look;
    let thickness = look.leg_thickness_m;
    let body_shape = Vec3::new(1.0, look.body_height_ratio, look.body_length_ratio);
    let dot_radius = settings.inset.creature_dot_radius_m;
    for (visual, pose, mut root) in &mut roots {
        *root = pose.body;
        let to_local = pose.body.to_matrix().inverse();
        let level = palette.body(pose.level);
        if let Ok((mut body, material)) = parts.get_mut(visual.body) {
            *body = Transform::from_scale(body_shape * pose.body_radius_m);
            if let Some(mut material) = material
                && material.0 != level
            {
                material.0 = level.clone();
            }
        }
        if let Ok((mut dot, material)) = parts.get_mut(visual.dot) {
            let ground = to_local.transform_point3(pose.body.translation.with_y(0.05));
            *dot = Transform::from_translation(ground).with_scale(Vec3::splat(dot_radius));
            if let Some(mut material) = material
                && material.0 != level
            {
                material.0 = level;
            }
        }
        for (&leg, &(hip, foot)) in visual.legs.iter().zip(&pose.legs) {
            if let Ok((mut transform, _)) = parts.get_mut(leg) {
                let (hip, foot) = (to_local.transform_point3(hip), to_local.transform_point3(foot));
                let along = foot - hip;
                *transform = Transform::from_translation((hip + foot) / 2.0)
                    .with_rotation(Quat::from_rotation_arc(Vec3::Y, along.normalize_or(Vec3::NEG_Y)))
                    .with_scale(Vec3::new(thickness / 2.0, along.length(), thickness / 2.0));
            }
        }
    }
}

/// Keeps the ring under the player's creature, hidden when there is none.
fn mark_player(
    round: Res<Round>,
    kinds: Res<KindTable>,
    creatures: Query<(&Creature, &PlanarState)>,
    mut markers: Query<(&PlayerMarker, &mut Transform, &mut Visibility)>,
) {
    let player = round.player.and_then(|p| creatures.get(p).ok());
    for (marker, mut transform, mut visibility) in &mut markers {
        match player {
            Some((creature, state)) => {
                let r = kinds[creature.kind].radius_m * marker.radii;
                *transform =
                    Transform::from_xyz(state.position.x, 0.03, state.position.y).with_scale(Vec3::new(r, 1.0, r));
                *visibility = Visibility::Inherited;
            }
            None => *visibility = Visibility::Hidden,
        }
    }
}

fn spawn_player_markers(mut commands: Commands, meshes: Res<PartMeshes>, palette: Res<Palette>) {
    let marker = |radii| {
        (
            PlayerMarker { radii },
            Mesh3d(meshes.ring.clone()),
            MeshMaterial3d(palette.player_marker.clone()),
            Visibility::Hidden,
        )
    };
    commands.spawn((Name::new("player marker"), marker(1.8)));
    commands.spawn((
        Name::new("player marker, overhead"),
        marker(5.0),
        RenderLayers::layer(OVERHEAD_ONLY),
    ));
}

pub(super) fn plugin(app: &mut App) {
    let mut assets = app.world_mut().resource_mut::<Assets<Mesh>>();
    let part_meshes = PartMeshes {
        sphere: assets.add(Sphere::new(1.0)),
        cylinder: assets.add(Cylinder::new(1.0, 1.0)),
        ring: assets.add(Torus::new(0.85, 1.0)),
        // Flat on the ground, facing up.
        disc: assets.add(Mesh::from(Circle::new(1.0)).rotated_by(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2))),
    };
    app.insert_resource(part_meshes)
        .configure_sets(Update, (DrawCreatures::Pose, DrawCreatures::Apply).chain())
        .add_systems(Startup, spawn_player_markers)
        .add_systems(
            Update,
            (
                (despawn_orphans, spawn_visuals).chain().before(DrawCreatures::Pose),
                (pose_point_masses, pose_rigid_hoppers).in_set(DrawCreatures::Pose),
                (apply_poses, mark_player).in_set(DrawCreatures::Apply),
            ),
        );
}
