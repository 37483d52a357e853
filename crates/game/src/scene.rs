//! The court as a player sees it: ice, lines, walls, the puck and where it is going,
//! sunlight and shadows. The
//! court's meshes are built with the simulated world ([`SimStart`]), so they follow an
//! edited arena file.

use bevy::light::CascadeShadowConfigBuilder;
use bevy::prelude::*;
use bevy_rapier3d::prelude::Collider;

use super::GameSettings;
use simlod::arena::{Puck, PuckState, Wall};
use simlod::config::{SimConfig, Srgb};
use simlod::lod::Lod;
use simlod::{SimEntity, SimStart, StartStage};

/// A colour from `game.ron` (sRGB, each channel 0 to 1) as Bevy's.
pub fn srgb(c: Srgb) -> Color {
    Color::srgb(c[0], c[1], c[2])
}

/// The materials of the scene, recoloured in place when `game.ron` changes.
#[derive(Resource)]
pub struct Palette {
    /// The ice of the court.
    pub floor: Handle<StandardMaterial>,
    /// The court's markings on the ice.
    pub lines: Handle<StandardMaterial>,
    /// The walls round the court.
    pub wall: Handle<StandardMaterial>,
    /// The puck.
    pub puck: Handle<StandardMaterial>,
    /// The wedge ahead of the puck: its colour, see-through.
    pub puck_path: Handle<StandardMaterial>,
    /// Every creature's legs, whatever its level.
    pub leg: Handle<StandardMaterial>,
    /// The ring round the player's creature (unlit), in both views.
    pub player_marker: Handle<StandardMaterial>,
    /// A creature's body, by level ([`Lod::ALL`] order).
    pub bodies: Vec<Handle<StandardMaterial>>,
}

impl Palette {
    /// The body material of a creature at `level`.
    pub fn body(&self, level: Lod) -> Handle<StandardMaterial> {
        let i = Lod::ALL
            .iter()
            .position(|&l| l == level)
            .expect("every level is in Lod::ALL");
        self.bodies[i].clone()
    }
}

/// Whether bodies are coloured by their level of detail (toggled by a key).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ColourByLevel(pub bool);

fn matte(materials: &mut Assets<StandardMaterial>, roughness: f32) -> Handle<StandardMaterial> {
    materials.add(StandardMaterial {
        perceptual_roughness: roughness,
        ..default()
    })
}

fn make_palette(materials: &mut Assets<StandardMaterial>) -> Palette {
    Palette {
        floor: matte(materials, 0.35),
        lines: matte(materials, 0.5),
        wall: matte(materials, 0.7),
        puck: matte(materials, 0.3),
        puck_path: materials.add(StandardMaterial {
            unlit: true,
            alpha_mode: AlphaMode::Blend,
            cull_mode: None,
            ..default()
        }),
        leg: matte(materials, 0.6),
        player_marker: materials.add(StandardMaterial {
            unlit: true,
            ..default()
        }),
        bodies: Lod::ALL.iter().map(|_| matte(materials, 0.55)).collect(),
    }
}

/// Gives every material its colour from the settings and the colouring toggle.
fn recolour(
    settings: Res<GameSettings>,
    colour_by_level: Res<ColourByLevel>,
    palette: Res<Palette>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut clear: ResMut<ClearColor>,
) {
    if !settings.is_changed() && !colour_by_level.is_changed() {
        return;
    }
    let s = &settings.scene_colours;
    clear.0 = srgb(s.sky_srgb);
    let mut paint = |handle: &Handle<StandardMaterial>, c: Srgb| {
        if let Some(mut m) = materials.get_mut(handle) {
            m.base_color = srgb(c);
        }
    };
    paint(&palette.floor, s.floor_srgb);
    paint(&palette.lines, s.court_lines_srgb);
    paint(&palette.wall, s.wall_srgb);
    paint(&palette.puck, s.puck_srgb);
    paint(&palette.leg, s.leg_srgb);
    paint(&palette.player_marker, s.player_marker_srgb);
    for (level, body) in Lod::ALL.iter().zip(&palette.bodies) {
        let c = if colour_by_level.0 {
            settings.level_colours_srgb[level]
        } else {
            s.uncoloured_srgb
        };
        paint(body, c);
    }
    if let Some(mut m) = materials.get_mut(&palette.puck_path) {
        m.base_color = srgb(s.puck_srgb).with_alpha(settings.puck_look.path_opacity);
    }
}

/// Ice, centre lines and walls as meshes; the puck's rapier body gets its mesh.
fn dress_court(
    mut commands: Commands,
    config: Res<SimConfig>,
    palette: Res<Palette>,
    mut meshes: ResMut<Assets<Mesh>>,
    walls: Query<(Entity, &Collider), With<Wall>>,
    puck: Query<Entity, With<Puck>>,
) {
    let arena = &config.arena;
    let half = arena.half_extents();
    let t = arena.wall_thickness_m;
    commands.spawn((
        Name::new("ice"),
        SimEntity,
        Mesh3d(meshes.add(Plane3d::default().mesh().size(2.0 * (half.x + t), 2.0 * (half.y + t)))),
        MeshMaterial3d(palette.floor.clone()),
    ));
    // A centre line and a centre circle, as on a rink: they give the eye a scale.
    let line_w = 0.25;
    commands.spawn((
        Name::new("centre line"),
        SimEntity,
        Mesh3d(meshes.add(Plane3d::default().mesh().size(line_w, 2.0 * half.y))),
        MeshMaterial3d(palette.lines.clone()),
        Transform::from_xyz(0.0, 0.005, 0.0),
    ));
    let circle_r = half.min_element() * 0.3;
    commands.spawn((
        Name::new("centre circle"),
        SimEntity,
        Mesh3d(meshes.add(Annulus::new(circle_r - line_w, circle_r))),
        MeshMaterial3d(palette.lines.clone()),
        Transform::from_xyz(0.0, 0.005, 0.0).with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)),
    ));
    // The walls and the puck are rapier bodies with transforms: each gets a mesh its shape.
    for (wall, collider) in &walls {
        if let Some(cuboid) = collider.as_cuboid() {
            commands.entity(wall).insert((
                Mesh3d(meshes.add(Cuboid::from_size(2.0 * cuboid.half_extents()))),
                MeshMaterial3d(palette.wall.clone()),
            ));
        }
    }
    for puck in &puck {
        commands.entity(puck).insert((
            Mesh3d(meshes.add(Cylinder::new(arena.puck.radius_m, arena.puck.height_m))),
            MeshMaterial3d(palette.puck.clone()),
        ));
    }
}

#[derive(Component)]
struct PuckPath;

/// A unit wedge flat on the ice: base 1 wide across the origin, tip 1 ahead (-z).
fn spawn_puck_path(mut commands: Commands, palette: Res<Palette>, mut meshes: ResMut<Assets<Mesh>>) {
    let wedge = Triangle2d::new(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0), Vec2::Y);
    commands.spawn((
        Name::new("puck path"),
        PuckPath,
        Mesh3d(meshes.add(Mesh::from(wedge).rotated_by(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)))),
        MeshMaterial3d(palette.puck_path.clone()),
    ));
}

/// The wedge as wide as the puck from its centre, its tip where the puck's front will be
/// `path_ahead_s` from now: which way the threat comes, and how fast.
fn point_puck_path(
    settings: Res<GameSettings>,
    puck: Res<PuckState>,
    mut path: Single<(&mut Transform, &mut Visibility), With<PuckPath>>,
) {
    let (transform, visibility) = &mut *path;
    let ahead = puck.velocity * settings.puck_look.path_ahead_s;
    let Some(direction) = ahead.try_normalize() else {
        **visibility = Visibility::Hidden;
        return;
    };
    **visibility = Visibility::Inherited;
    let length = puck.radius_m + ahead.length();
    **transform = Transform::from_xyz(puck.position.x, 0.02, puck.position.y)
        .looking_to(Vec3::new(direction.x, 0.0, direction.y), Vec3::Y)
        .with_scale(Vec3::new(2.0 * puck.radius_m, 1.0, length));
}

/// The sun, casting shadows; [`aim_the_sun`] sets it and the fill light from the settings.
fn light_the_court(mut commands: Commands) {
    commands.spawn((Name::new("sun"), Sun, DirectionalLight::default(), Transform::default()));
}

#[derive(Component)]
struct Sun;

/// Keeps the sun and fill light as `game.ron` says.
fn aim_the_sun(
    settings: Res<GameSettings>,
    mut ambient: ResMut<GlobalAmbientLight>,
    mut sun: Query<(Entity, &mut DirectionalLight, &mut Transform), With<Sun>>,
    mut commands: Commands,
) {
    if !settings.is_changed() {
        return;
    }
    let l = &settings.lighting;
    ambient.brightness = l.ambient_brightness_cd_per_m2;
    for (entity, mut light, mut transform) in &mut sun {
        light.illuminance = l.sun_illuminance_lux;
        light.shadow_maps_enabled = true;
        let (el, az) = (l.sun_elevation_deg.to_radians(), l.sun_azimuth_deg.to_radians());
        let towards_sun = Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin());
        *transform = Transform::from_translation(towards_sun).looking_at(Vec3::ZERO, Vec3::Y);
        commands.entity(entity).insert(
            CascadeShadowConfigBuilder {
                num_cascades: 2,
                first_cascade_far_bound: l.shadow_distance_m * 0.3,
                maximum_distance: l.shadow_distance_m,
                ..default()
            }
            .build(),
        );
    }
}

pub(super) fn plugin(app: &mut App) {
    let palette = make_palette(&mut app.world_mut().resource_mut::<Assets<StandardMaterial>>());
    app.insert_resource(palette)
        .insert_resource(ColourByLevel(true))
        .add_systems(SimStart, dress_court.after(StartStage::Arena))
        .add_systems(Startup, (light_the_court, spawn_puck_path))
        .add_systems(Update, (recolour, aim_the_sun, point_puck_path));
}
