//! The two views of paper figure 6: the player's view, a camera that follows the player's
//! creature from the side away from the puck so the puck stays in view; and an overhead
//! view of the whole court, inset in a corner of the window.

use bevy::camera::visibility::RenderLayers;
use bevy::camera::{ScalingMode, Viewport};
use bevy::prelude::*;
use bevy::window::PrimaryWindow;

use super::GameSettings;
use super::creatures::OVERHEAD_ONLY;
use super::player::Round;
use super::scene::srgb;
use crate::arena::{Court, PuckState};
use crate::config::SimConfig;
use crate::creature::PlanarState;
use crate::lod::{CameraFromView, SimCamera};

/// The player's view. The HUD is drawn on it.
#[derive(Component)]
pub struct FollowCamera;

/// The overhead view of the whole court.
#[derive(Component)]
struct OverheadCamera;

/// The frame around the overhead view.
#[derive(Component)]
struct InsetFrame;

/// The player's view seen from above: a fan from the follow camera, as wide as its view.
#[derive(Component)]
struct ViewCone {
    /// Length and half angle of the fan its mesh was made for.
    shape: (f32, f32),
}

/// Where the follow camera is headed: the eye and the point it looks at.
#[derive(Resource, Default)]
struct FollowTarget {
    eye: Vec3,
    aim: Vec3,
    /// Where the player's creature was last seen (the view stays there after a fall).
    player: Vec2,
    placed: bool,
}

fn spawn_cameras(mut commands: Commands, mut materials: ResMut<Assets<StandardMaterial>>) {
    commands.spawn((
        Name::new("follow camera"),
        FollowCamera,
        Camera3d::default(),
        Camera { order: 0, ..default() },
        IsDefaultUiCamera,
        Transform::from_xyz(0.0, 30.0, 40.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Name::new("overhead camera"),
        OverheadCamera,
        Camera3d::default(),
        Camera { order: 1, ..default() },
        Projection::from(OrthographicProjection::default_3d()),
        Transform::from_xyz(0.0, 60.0, 0.0).looking_at(Vec3::ZERO, Vec3::NEG_Z),
        RenderLayers::from_layers(&[0, OVERHEAD_ONLY]),
    ));
    commands.spawn((
        Name::new("view cone"),
        ViewCone { shape: (0.0, 0.0) },
        Mesh3d::default(),
        MeshMaterial3d(materials.add(StandardMaterial {
            unlit: true,
            alpha_mode: AlphaMode::Blend,
            ..default()
        })),
        RenderLayers::layer(OVERHEAD_ONLY),
    ));
    commands.spawn((
        Name::new("overhead frame"),
        InsetFrame,
        Node {
            position_type: PositionType::Absolute,
            border: UiRect::all(px(2)),
            ..default()
        },
        BorderColor::all(Color::WHITE),
    ));
}

/// Behind the player on the line from the puck, aiming between the two; eased, so the view
/// does not jerk with every hop.
fn follow_player(
    time: Res<Time>,
    settings: Res<GameSettings>,
    round: Res<Round>,
    puck: Res<PuckState>,
    creatures: Query<&PlanarState>,
    mut target: ResMut<FollowTarget>,
    mut camera: Single<(&mut Transform, &mut Projection), With<FollowCamera>>,
) {
    let c = &settings.camera;
    if let Some(state) = round.player.and_then(|p| creatures.get(p).ok()) {
        target.player = state.position;
    }
    let at = |p: Vec2, y: f32| Vec3::new(p.x, y, p.y);
    let away = (target.player - puck.position).normalize_or(Vec2::Y);
    let eye = at(target.player + away * c.follow_distance_m, c.follow_height_m);
    let aim = at(
        target.player.lerp(puck.position, c.aim_toward_puck_fraction),
        c.aim_height_m,
    );
    let ease = if target.placed {
        1.0 - (-c.follow_rate_per_s * time.delta_secs()).exp()
    } else {
        1.0
    };
    target.eye = target.eye.lerp(eye, ease);
    target.aim = target.aim.lerp(aim, ease);
    target.placed = true;
    let (transform, projection) = &mut *camera;
    **transform = Transform::from_translation(target.eye).looking_at(target.aim, Vec3::Y);
    if let Projection::Perspective(p) = &mut **projection {
        p.fov = c.field_of_view_deg.to_radians();
    }
}

/// Sizes the overhead view to the court, in the window's top right corner.
fn place_overhead(
    settings: Res<GameSettings>,
    court: Res<Court>,
    window: Single<&Window, With<PrimaryWindow>>,
    mut camera: Single<(&mut Camera, &mut Projection), With<OverheadCamera>>,
    mut frame: Single<&mut Node, With<InsetFrame>>,
) {
    let inset = &settings.inset;
    let shown = 2.0 * (court.half_extents + Vec2::splat(inset.border_m));
    let size = window.physical_size().as_vec2();
    let scale = window.scale_factor();
    let width = (size.x * inset.width_fraction).max(1.0);
    let extent = Vec2::new(width, (width * shown.y / shown.x).min(size.y * 0.9).max(1.0));
    let corner = Vec2::new(size.x - extent.x - inset.margin_px * scale, inset.margin_px * scale).max(Vec2::ZERO);
    let (camera, projection) = &mut *camera;
    let viewport = Viewport {
        physical_position: corner.as_uvec2(),
        physical_size: extent.as_uvec2(),
        ..default()
    };
    let placed = camera.viewport.as_ref().map(|v| (v.physical_position, v.physical_size));
    if placed != Some((viewport.physical_position, viewport.physical_size)) {
        camera.viewport = Some(viewport);
    }
    if let Projection::Orthographic(o) = &mut **projection {
        o.scaling_mode = ScalingMode::AutoMin {
            min_width: shown.x,
            min_height: shown.y,
        };
    }
    let border = 2.0;
    frame.left = px(corner.x / scale - border);
    frame.top = px(corner.y / scale - border);
    frame.width = px(extent.x / scale + 2.0 * border);
    frame.height = px(extent.y / scale + 2.0 * border);
}

/// The camera rule (paper figure 6) sees what the player sees: the follow camera's place,
/// direction and horizontal opening on the ground.
fn share_view(
    settings: Res<GameSettings>,
    round: Res<Round>,
    window: Single<&Window, With<PrimaryWindow>>,
    camera: Single<&Transform, With<FollowCamera>>,
    mut view: ResMut<SimCamera>,
) {
    let forward = camera.forward().as_vec3();
    let shared = SimCamera {
        position: camera.translation.xz(),
        facing: forward.xz().normalize_or(Vec2::NEG_Y),
        half_view_rad: horizontal_half_view(&settings, &window),
        following: round.player,
    };
    view.set_if_neq(shared);
}

/// The horizontal half angle of the view, from the vertical field of view and the window.
fn horizontal_half_view(settings: &GameSettings, window: &Window) -> f32 {
    let aspect = window.width() / window.height().max(1.0);
    ((settings.camera.field_of_view_deg.to_radians() / 2.0).tan() * aspect).atan()
}

/// Lays the fan on the ground under the follow camera, pointing where it looks, as long as
/// the camera's radius of influence: the creatures inside it are the rigid ones of the
/// camera rule.
fn draw_view_cone(
    settings: Res<GameSettings>,
    config: Res<SimConfig>,
    window: Single<&Window, With<PrimaryWindow>>,
    camera: Single<&Transform, With<FollowCamera>>,
    mut cone: Single<
        (
            &mut ViewCone,
            &mut Mesh3d,
            &MeshMaterial3d<StandardMaterial>,
            &mut Transform,
        ),
        Without<FollowCamera>,
    >,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let inset = &settings.inset;
    let (cone, mesh, material, transform) = &mut *cone;
    let half = horizontal_half_view(&settings, &window);
    let shape = (config.rules.camera.radius_m, half);
    if cone.shape != shape {
        cone.shape = shape;
        // The sector points along +y in its plane; laid flat, along -z, the view's forward.
        mesh.0 = meshes.add(
            Mesh::from(CircularSector::new(shape.0, half))
                .rotated_by(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)),
        );
    }
    if settings.is_changed()
        && let Some(mut m) = materials.get_mut(&material.0)
    {
        m.base_color = srgb(settings.scene_colours.player_marker_srgb).with_alpha(inset.view_cone_opacity);
    }
    let forward = camera.forward().as_vec3().with_y(0.0).normalize_or(Vec3::NEG_Z);
    **transform = Transform::from_translation(camera.translation.with_y(0.04)).looking_to(forward, Vec3::Y);
}

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<FollowTarget>()
        .add_systems(Startup, spawn_cameras)
        .init_resource::<CameraFromView>()
        .add_systems(
            Update,
            (follow_player, share_view, place_overhead, draw_view_cone).chain(),
        );
}
