//! The player's view of paper figure 6: a camera that follows the player's creature from the
//! side away from the puck, so the puck stays in view. The camera rule sees what it shows.

use bevy::prelude::*;

use super::GameSettings;
use super::player::Round;
use simlod::arena::PuckState;
use simlod::creature::PlanarState;
use simlod::lod::{CameraFromView, SimCamera};

/// The player's view. The HUD is drawn on it.
#[derive(Component)]
pub struct FollowCamera;

/// Places the player's view and shares it with the camera rule.
#[derive(SystemSet, Clone, Debug, PartialEq, Eq, Hash)]
pub struct ViewSystems;

/// Where the follow camera is headed: the eye and the point it looks at.
#[derive(Resource, Default)]
struct FollowTarget {
    eye: Vec3,
    aim: Vec3,
    /// Where the player's creature was last seen (the view stays there after a fall).
    player: Vec2,
    placed: bool,
}

fn spawn_follow_camera(mut commands: Commands) {
    commands.spawn((
        Name::new("follow camera"),
        FollowCamera,
        Camera3d::default(),
        Camera { order: 0, ..default() },
        IsDefaultUiCamera,
        Transform::from_xyz(0.0, 30.0, 40.0).looking_at(Vec3::ZERO, Vec3::Y),
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

/// The camera rule (paper figure 6) sees what the player sees: the follow camera's own
/// projection and place, the frustum the renderer culls with.
fn share_view(
    time: Res<Time>,
    round: Res<Round>,
    camera: Single<(&Transform, &Projection), With<FollowCamera>>,
    mut view: ResMut<SimCamera>,
) {
    let (transform, projection) = *camera;
    let world_from_view = transform.to_matrix();
    let clip_from_world = projection.get_clip_from_view() * world_from_view.inverse();
    let far_m = match projection {
        Projection::Perspective(p) => p.far,
        Projection::Orthographic(p) => p.far,
        Projection::Custom(_) => f32::INFINITY,
    };
    let shared =
        SimCamera::new(clip_from_world, world_from_view, far_m, round.player).turned_since(&view, time.delta_secs());
    view.set_if_neq(shared);
}

/// The player's view, for the game and for a test of the camera rule in the game's App.
pub fn plugin(app: &mut App) {
    app.init_resource::<FollowTarget>()
        .init_resource::<CameraFromView>()
        .add_systems(Startup, spawn_follow_camera)
        .add_systems(Update, (follow_player, share_view).chain().in_set(ViewSystems));
}
