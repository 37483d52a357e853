//! The overhead view of paper figure 6: the whole court, inset in a corner of the window,
//! with the player's view (`view.rs`) drawn on it as a fan.

use bevy::camera::visibility::RenderLayers;
use bevy::camera::{ScalingMode, Viewport};
use bevy::prelude::*;
use bevy::window::PrimaryWindow;

use super::GameSettings;
use super::creatures::OVERHEAD_ONLY;
use super::scene::srgb;
use super::view::{FollowCamera, ViewSystems};
use simlod::arena::Court;
use simlod::config::SimConfig;

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

fn spawn_cameras(mut commands: Commands, mut materials: ResMut<Assets<StandardMaterial>>) {
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
    app.add_systems(Startup, spawn_cameras)
        .add_systems(Update, (place_overhead, draw_view_cone).chain().after(ViewSystems));
}
