//! Drawing the creatures from their current model, coloured by level (paper figures 5, 6).
//!
//! A simulated creature has no transform; each gets a drawing of its own: a root entity
//! with a body and its legs as children. Drawing is two steps. First, [`pose_creatures`]
//! writes each creature's [`CreaturePose`] from what every level publishes: its planar state
//! and its [`GaitPose`] (read back from the rapier bodies at the rigid level, played from the
//! gait table at the hybrid one, the standing pose at the point mass). Then [`apply_poses`]
//! moves the meshes.

use bevy::camera::visibility::{RenderLayers, VisibilityRange};
use bevy::prelude::*;

use super::GameSettings;
use super::player::Round;
use super::scene::{Palette, srgb};
use simlod::SimClock;
use simlod::SimEntity;
use simlod::config::SimConfig;
use simlod::creature::{Creature, KindTable, PlanarState};
use simlod::gait::GaitPose;
use simlod::lod::{Lod, SwitchBlend, drawn};
use simlod::models::point_mass::FrameStepping;

/// Rapier's bodies face +x; a pose faces -z.
const RAPIER_TO_POSE: Quat = Quat::from_xyzw(
    0.0,
    std::f32::consts::FRAC_1_SQRT_2,
    0.0,
    std::f32::consts::FRAC_1_SQRT_2,
);

/// The two steps of drawing, in `Update`.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DrawCreatures {
    /// The poses of the creatures, from what every level publishes.
    Pose,
    /// The meshes follow the poses.
    Apply,
}

/// The drawing of one simulated creature.
#[derive(Component, Debug)]
pub struct CreatureVisual {
    /// The simulated creature drawn; the drawing is despawned when it is gone.
    pub creature: Entity,
    body: Entity,
    /// At the front of the body: which way the creature faces.
    nose: Entity,
    /// On top of the body, in the kind's colour.
    crest: Entity,
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

/// Where a creature's details (crest, nose, legs) are drawn: near the camera only.
fn detail_range(settings: &GameSettings) -> VisibilityRange {
    VisibilityRange::abrupt(0.0, settings.creature_look.detail_distance_m)
}

fn spawn_visuals(
    mut commands: Commands,
    config: Res<SimConfig>,
    settings: Res<GameSettings>,
    kinds: Res<KindTable>,
    meshes: Res<PartMeshes>,
    palette: Res<Palette>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    // One material per marking colour, shared by every creature wearing it.
    mut markings: Local<Vec<([f32; 3], Handle<StandardMaterial>)>>,
    creatures: Query<(Entity, &Creature, &Lod), Added<Creature>>,
) {
    for (entity, creature, lod) in &creatures {
        let def = &config.kinds[creature.kind];
        let leg_count = kinds[creature.kind].legs.len();
        let colour = def.look.marking_srgb;
        let marking = match markings.iter().find(|(c, _)| *c == colour) {
            Some((_, m)) => m.clone(),
            None => {
                let m = materials.add(StandardMaterial {
                    base_color: srgb(colour),
                    perceptual_roughness: 0.5,
                    ..default()
                });
                markings.push((colour, m.clone()));
                m
            }
        };
        let body = commands
            .spawn((Mesh3d(meshes.sphere.clone()), MeshMaterial3d(palette.body(*lod))))
            .id();
        let details = detail_range(&settings);
        let nose = commands
            .spawn((
                Mesh3d(meshes.sphere.clone()),
                MeshMaterial3d(marking.clone()),
                details.clone(),
            ))
            .id();
        let crest = commands
            .spawn((Mesh3d(meshes.sphere.clone()), MeshMaterial3d(marking), details.clone()))
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
                    .spawn((
                        Mesh3d(meshes.cylinder.clone()),
                        MeshMaterial3d(palette.leg.clone()),
                        details.clone(),
                    ))
                    .id()
            })
            .collect();
        commands
            .spawn((
                Name::new(format!("{} {}", def.name, creature.serial)),
                SimEntity,
                Transform::default(),
                Visibility::default(),
                CreaturePose::default(),
            ))
            .add_children(&[body, nose, crest, dot])
            .add_children(&legs)
            .insert(CreatureVisual {
                creature: entity,
                body,
                nose,
                crest,
                legs,
                dot,
            });
    }
}

/// An edited `game.ron` moves every creature's detail range.
fn range_details(
    settings: Res<GameSettings>,
    visuals: Query<&CreatureVisual>,
    mut ranges: Query<&mut VisibilityRange>,
) {
    let range = detail_range(&settings);
    for visual in &visuals {
        for part in [visual.nose, visual.crest].iter().chain(&visual.legs) {
            if let Ok(mut r) = ranges.get_mut(*part) {
                *r = range.clone();
            }
        }
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

/// Every level publishes where the body stands and its [`GaitPose`]: the body faces its
/// heading at its planar position, each leg from its hip on the body to its foot; a creature
/// that just switched is drawn blended ([`SwitchBlend`]).
fn pose_creatures(
    kinds: Res<KindTable>,
    settings: Res<GameSettings>,
    clock: Res<SimClock>,
    creatures: Query<(&Creature, &Lod, &PlanarState, &GaitPose, Option<&SwitchBlend>)>,
    mut visuals: Query<(&CreatureVisual, &mut CreaturePose)>,
) {
    let now = clock.seconds() as f32;
    for (visual, mut pose) in &mut visuals {
        let Ok((creature, &level, state, gait, blend)) = creatures.get(visual.creature) else {
            continue;
        };
        let kind = &kinds[creature.kind];
        // Blended from the old level's motion for a moment after a switch.
        let seen = drawn(state, gait, blend, now);
        pose.body = Transform::from_translation(seen.body).with_rotation(seen.rotation * RAPIER_TO_POSE);
        pose.body_radius_m = kind.radius_m * settings.creature_look.body_radius_fraction;
        pose.legs = seen.hips_and_feet(&kind.hips_m).collect();
        pose.level = level;
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
    // Sunk a little into the front of the ellipsoid.
    let nose_at = Vec3::new(0.0, 0.0, -0.9 * look.body_length_ratio);
    // Sunk a little into the top, flattened.
    let crest_at = Vec3::new(0.0, 0.85 * look.body_height_ratio, 0.0);
    let crest_shape = look.crest_radius_fraction * Vec3::new(1.0, 0.45, 1.0);
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
        if let Ok((mut nose, _)) = parts.get_mut(visual.nose) {
            *nose = Transform::from_translation(nose_at * pose.body_radius_m)
                .with_scale(Vec3::splat(look.nose_radius_fraction * pose.body_radius_m));
        }
        if let Ok((mut crest, _)) = parts.get_mut(visual.crest) {
            *crest =
                Transform::from_translation(crest_at * pose.body_radius_m).with_scale(crest_shape * pose.body_radius_m);
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
    // Drawn at the display's frame rate, every creature is read between steering decisions:
    // none may fall behind its frame.
    app.insert_resource(FrameStepping { enabled: false });
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
                (
                    despawn_orphans,
                    spawn_visuals,
                    range_details.run_if(resource_changed::<GameSettings>),
                )
                    .chain()
                    .before(DrawCreatures::Pose),
                pose_creatures.in_set(DrawCreatures::Pose),
                (apply_poses, mark_player).in_set(DrawCreatures::Apply),
            ),
        );
}
