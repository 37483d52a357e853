//! The two views of paper figure 6: the player's view, a camera that follows the player's
//! creature from the side away from the puck so the puck stays in view; and an overhead
//! view of the whole court, inset in a corner of the window.

use bevy::camera::{ScalingMode, Viewport};
use bevy::prelude::*;
use bevy::window::PrimaryWindow;

use super::GameSettings;
use super::player::Round;
use crate::arena::{Court, PuckState};
use crate::creature::PlanarState;

/// The player's view. The HUD is drawn on it.
#[derive(Component)]
pub struct FollowCamera;

/// The overhead view of the whole court.
#[derive(Component)]
struct OverheadCamera;

/// The frame around the overhead view.
#[derive(Component)]
struct InsetFrame;

/// Where the follow camera is headed: the eye and the point it looks at.
#[derive(Resource, Default)]
struct FollowTarget {
    eye: Vec3,
    aim: Vec3,
    /// Where the player's creature was last seen (the view stays there after a fall).
    player: Vec2,
    placed: bool,
}

fn spawn_cameras(mut commands: Commands) {
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
    let aim = at(target.player.lerp(puck.position, c.aim_toward_puck_fraction), 0.5);
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

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<FollowTarget>()
        .add_systems(Startup, spawn_cameras)
        .add_systems(Update, (follow_player, place_overhead));
}
