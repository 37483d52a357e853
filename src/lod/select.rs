//! SelectLod: the level each creature should be at (paper 3.4).
//!
//! Areas of influence (figure 5): the puck and every creature have a circle of influence
//! stretched in the direction of travel; a wall's area is every point within a band of it.
//! A creature inside any area but its own should be rigid: "the areas of influence represent an
//! approximate measure of the probability of a collision occurring within a short period of
//! time". Otherwise hybrid.
//!
//! The stretched circle: for a body at `p` moving at `v`, with radius `r` and look-ahead `T`,
//! the area is the ellipse centred at `p + v T / 2` with semi-axis `r + |v| T / 2` along `v`
//! and `r` across it: it covers the circle around the body now and around where it will be
//! `T` later.
//!
//! The camera rule (figure 6): out of view, point mass; in view but further than the
//! camera's radius, hybrid; in view and within it, rigid. "In view" is the camera's real
//! frustum against a sphere around the creature's body and legs, grown by one hop's travel:
//! a switch waits up to a hop for its flight window, and nothing on screen may be a point
//! mass. The headless camera rides behind a creature (the player's, else the lowest serial)
//! looking at the puck, as in figure 9; the game's is the window's own.
//!
//! Hysteresis: entering an area or the view uses its size; leaving it takes
//! `release_margin_m` more, and a creature keeps a new level at least `min_dwell_s`.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_rapier3d::prelude::Velocity;

use super::{LevelPolicy, Lod};
use crate::config::{LevelRules, SimConfig};
use crate::contract::GaitPose;
use crate::contract::{GaitPhase, PlanarState, PlayerControlled};
use crate::contract::{SimClock, SimStage, SimStart, StartStage};
use crate::kind::{Creature, KindParams, KindTable, starting_gait};
use crate::sense::NeighbourGrid;
use crate::sense::{Court, PuckState};

/// The level the rules want for a creature, and when it last switched.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct LevelChoice {
    /// The level the policy wants now; the switch waits for the flight window.
    pub wanted: Lod,
    /// Simulated time of the last switch (for `min_dwell_s`).
    pub last_switch_s: f32,
    /// Whether it has switched since it was spawned.
    pub switched: bool,
    /// The budget policy's last search for its soonest contact with another creature: how
    /// urgent it was (0 to 1), and when (simulated seconds).
    pub crowding: Option<(f32, f32)>,
}

/// The camera of the camera rule: its eye and its view's frustum. Headless it follows a
/// creature (figure 9's set-up); a window's camera sets it itself (see [`CameraFromView`]).
/// The default sees everything.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct SimCamera {
    /// The eye.
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// The frustum's left, right, bottom, top, near and far half-spaces: `(n, w)` holds the
    /// points `p` with `n . p + w >= 0`, `n` a unit vector.
    pub frustum: [Vec4; 6],
    /// How fast the view turns, radians per second: a creature a switch keeps waiting for
    /// its flight window may be swept into view meanwhile.
    pub turn_rate_rad_per_s: f32,
    /// The creature it follows.
    pub following: Option<Entity>,
}

impl SimCamera {
    /// The camera whose projection and view give `clip_from_world`, with its eye at
    /// `world_from_view`'s origin (Gribb and Hartmann's planes, for Bevy's reversed depth), and
    /// its far plane `far_m` deep along the view, where Bevy culls (its projections' depth
    /// has no far plane: infinite reversed depth).
    pub fn new(clip_from_world: Mat4, world_from_view: Mat4, far_m: f32, following: Option<Entity>) -> Self {
        let row = |i| clip_from_world.row(i);
        let half_space = |h: Vec4| h / h.truncate().length().max(f32::MIN_POSITIVE);
        let (eye, forward) = (
            world_from_view.w_axis.truncate(),
            -world_from_view.z_axis.truncate().normalize_or(Vec3::NEG_Z),
        );
        Self {
            eye,
            forward,
            frustum: [
                half_space(row(3) + row(0)),
                half_space(row(3) - row(0)),
                half_space(row(3) + row(1)),
                half_space(row(3) - row(1)),
                half_space(row(3) - row(2)),
                (-forward).extend(far_m + forward.dot(eye)),
            ],
            turn_rate_rad_per_s: 0.0,
            following,
        }
    }

    /// This camera, turning at the rate it turned since `before`, `dt_s` earlier.
    pub fn turned_since(mut self, before: &SimCamera, dt_s: f32) -> Self {
        if dt_s > 0.0 && before.forward != Vec3::ZERO {
            self.turn_rate_rad_per_s = before.forward.angle_between(self.forward) / dt_s;
        }
        self
    }

    /// A perspective camera at `eye` looking at `aim`, as Bevy's (near plane 0.1 m, far plane
    /// `far_m`).
    pub fn looking_at(
        eye: Vec3,
        aim: Vec3,
        (vertical_fov_rad, aspect_ratio, far_m): (f32, f32, f32),
        following: Option<Entity>,
    ) -> Self {
        let view_from_world = Mat4::look_at_rh(eye, aim, Vec3::Y);
        let clip_from_view = Mat4::perspective_infinite_reverse_rh(vertical_fov_rad, aspect_ratio, 0.1);
        Self::new(
            clip_from_view * view_from_world,
            view_from_world.inverse(),
            far_m,
            following,
        )
    }

    /// Whether any of the sphere at `centre` of `radius` is in view.
    pub fn sees(&self, centre: Vec3, radius: f32) -> bool {
        self.frustum
            .iter()
            .all(|h| h.truncate().dot(centre) + h.w + radius >= 0.0)
    }

    /// Whether any of a creature of this kind at `s` is on screen now.
    pub fn shows(&self, kind: &KindParams, s: &PlanarState) -> bool {
        let (height, radius) = kind.view_sphere_m;
        self.sees(s.position.extend(height).xzy(), radius)
    }

    /// Whether any of a creature of this kind at `s`, grown by `margin_m`, may be on screen
    /// within a hop, the longest a switch waits for its flight window: the creature covers
    /// up to a hop at top speed, and the view sweeps `distance x turn` meanwhile.
    pub fn sees_creature(&self, kind: &KindParams, s: &PlanarState, margin_m: f32) -> bool {
        let reach = self.view_reach(kind, margin_m);
        self.sees_within(&reach, s.position, self.ground_distance(s.position))
    }

    /// What [`SimCamera::sees_creature`] needs of a kind and margin: the same for each of its
    /// creatures, so worked out once for a crowd.
    pub fn view_reach(&self, kind: &KindParams, margin_m: f32) -> ViewReach {
        let (height_m, radius) = kind.view_sphere_m;
        let hop_s = 1.0 / kind.cycles_per_s;
        let sweep = (self.turn_rate_rad_per_s * hop_s).min(std::f32::consts::FRAC_PI_2);
        ViewReach {
            height_m,
            radius_m: radius + margin_m,
            hop_m: kind.top_speed_m_per_s * hop_s,
            sweep: sweep.sin(),
        }
    }

    /// [`SimCamera::sees_creature`] for a creature at `position`, `ground_distance_m` from the eye.
    pub fn sees_within(&self, reach: &ViewReach, position: Vec2, ground_distance_m: f32) -> bool {
        let moved = reach.hop_m + ground_distance_m * reach.sweep;
        self.sees(position.extend(reach.height_m).xzy(), reach.radius_m + moved)
    }

    /// Whether [`SimCamera::sees_within`] is false for every creature of `reach` on the ground
    /// in `min..max`: the box at the reach's height, grown by it at the box's farthest ground
    /// distance, lies wholly behind one of the frustum's planes. The view cone tested once for
    /// a tile of the court, not once for each creature in it.
    pub fn sees_none_within(&self, reach: &ViewReach, min: Vec2, max: Vec2) -> bool {
        let corners =
            [min, Vec2::new(min.x, max.y), Vec2::new(max.x, min.y), max].map(|c| c.extend(reach.height_m).xzy());
        let farthest = corners.iter().map(|c| self.ground_distance(c.xz())).fold(0.0, f32::max);
        // A millimetre a metre more, so that rounding never parts it from the creature's test.
        let radius = reach.radius_m + reach.hop_m + farthest * reach.sweep + 1e-3 * (1.0 + farthest);
        self.frustum.iter().any(|h| {
            let nearest = corners
                .iter()
                .map(|&c| h.truncate().dot(c))
                .fold(f32::NEG_INFINITY, f32::max);
            nearest + h.w + radius < 0.0
        })
    }

    /// Distance on the ground from the eye.
    pub fn ground_distance(&self, q: Vec2) -> f32 {
        self.eye.xz().distance(q)
    }
}

/// A kind's sphere against the frustum, and how far it and the view can move within a hop:
/// [`SimCamera::view_reach`].
#[derive(Clone, Copy, Debug)]
pub struct ViewReach {
    height_m: f32,
    /// The sphere's radius and the margin.
    radius_m: f32,
    /// A hop at top speed.
    hop_m: f32,
    /// How far the view sweeps within a hop, per metre from the eye.
    sweep: f32,
}

/// Present when a window's camera writes [`SimCamera`] (the game): the camera rule then
/// uses what the player sees, and the headless placement stands aside.
#[derive(Resource, Debug, Default)]
pub struct CameraFromView;

/// Whether `q` lies in the stretched circle of a body at `p` moving at `v`.
pub fn in_influence(q: Vec2, p: Vec2, v: Vec2, radius: f32, lookahead_s: f32) -> bool {
    let reach = v * (lookahead_s / 2.0);
    let d = q - (p + reach);
    let Some(along) = v.try_normalize() else {
        return d.length_squared() <= radius * radius;
    };
    let a = radius + reach.length();
    let (x, y) = (d.dot(along) / a, d.perp_dot(along) / radius.max(1e-6));
    x * x + y * y <= 1.0
}

/// An area of influence of the host's own, beside the puck's and each creature's (figure 5):
/// under the influence rule a creature inside it, or about to be within the rules' lookahead,
/// is simulated rigid, as near the puck; the budget spends on it as on the puck. Put it on any
/// entity with a `Transform`; a rapier `Velocity` beside it is its motion on the ground plane.
#[derive(Component, Clone, Copy, Debug)]
pub struct InfluenceArea {
    /// The area's radius on the ground plane, metres.
    pub radius_m: f32,
}

/// A host's area of influence at one decision, on the ground plane.
#[derive(Clone, Copy, Debug)]
pub(super) struct Area {
    pub position: Vec2,
    pub velocity: Vec2,
    pub radius_m: f32,
}

/// The host's areas of influence (none in simlod's own game).
pub(super) type Areas<'w, 's> = Query<'w, 's, (&'static InfluenceArea, &'static Transform, Option<&'static Velocity>)>;

/// Where each of the host's areas is now.
pub(super) fn areas_now(areas: &Areas) -> Vec<Area> {
    areas
        .iter()
        .map(|(area, transform, velocity)| Area {
            position: transform.translation.xz(),
            velocity: velocity.map_or(Vec2::ZERO, |v| v.linear.xz()),
            radius_m: area.radius_m,
        })
        .collect()
}

/// The areas' radii and the view's margin, to enter them or, grown by the release margin,
/// to stay in them (the hysteresis).
struct Radii {
    /// What the release margin adds (0 to enter).
    grow: f32,
    puck: f32,
    creature: f32,
    wall: f32,
    camera: f32,
    /// Added to each creature's sphere against the frustum.
    view: f32,
}

impl Radii {
    fn of(rules: &LevelRules, staying: bool) -> Self {
        let grow = if staying { rules.release_margin_m } else { 0.0 };
        Self {
            grow,
            puck: rules.influence.puck_radius_m + grow,
            creature: rules.influence.creature_radius_m + grow,
            wall: rules.influence.wall_band_m + grow,
            camera: rules.camera.radius_m + grow,
            view: grow,
        }
    }
}

/// What a decision on levels reads besides the creatures (every policy's).
#[derive(SystemParam)]
pub(super) struct DecisionInputs<'w, 's> {
    pub clock: Res<'w, SimClock>,
    pub config: Res<'w, SimConfig>,
    pub kinds: Res<'w, KindTable>,
    pub puck: Res<'w, PuckState>,
    pub court: Res<'w, Court>,
    pub grid: Res<'w, NeighbourGrid>,
    pub camera: Res<'w, SimCamera>,
    pub areas: Areas<'w, 's>,
}

impl DecisionInputs<'_, '_> {
    /// The areas of influence and the camera rule, over these inputs.
    fn rules(&self) -> LevelInputs<'_> {
        let rules = &self.config.rules;
        let top_speed = self.kinds.0.iter().map(|k| k.top_speed_m_per_s).fold(0.0, f32::max);
        LevelInputs {
            rules,
            puck: &self.puck,
            court: &self.court,
            grid: &self.grid,
            camera: &self.camera,
            kinds: &self.kinds,
            areas: areas_now(&self.areas),
            reach_m: rules.release_margin_m + top_speed * rules.influence.lookahead_s,
        }
    }
}

struct LevelInputs<'a> {
    rules: &'a LevelRules,
    puck: &'a PuckState,
    court: &'a Court,
    grid: &'a NeighbourGrid,
    camera: &'a SimCamera,
    kinds: &'a KindTable,
    areas: Vec<Area>,
    reach_m: f32,
}

impl LevelInputs<'_> {
    fn influence_level(&self, c: &Creature, s: &PlanarState, r: &Radii) -> Lod {
        let la = self.rules.influence.lookahead_s;
        let near_wall = (self.court.half_extents - s.position.abs()).min_element() <= r.wall;
        let in_puck = in_influence(
            s.position,
            self.puck.position,
            self.puck.velocity,
            r.puck + self.puck.radius_m,
            la,
        );
        // The host's areas only where the puck and walls have not decided already.
        let in_area = !(near_wall || in_puck)
            && (self.areas.iter()).any(|a| in_influence(s.position, a.position, a.velocity, a.radius_m + r.grow, la));
        let mut in_creature = false;
        if !(near_wall || in_puck || in_area) {
            self.grid.for_each_within(s.position, self.reach_m + r.creature, |n| {
                in_creature |= n.serial != c.serial && in_influence(s.position, n.position, n.velocity, r.creature, la);
            });
        }
        if near_wall || in_puck || in_area || in_creature {
            Lod::Rigid
        } else {
            Lod::Hybrid
        }
    }

    fn camera_level(&self, c: &Creature, s: &PlanarState, r: &Radii) -> Lod {
        let in_view = self.camera.sees_creature(&self.kinds[c.kind], s, r.view);
        match (in_view, self.camera.ground_distance(s.position) <= r.camera) {
            (false, _) => Lod::PointMass,
            (true, false) => Lod::Hybrid,
            (true, true) => Lod::Rigid,
        }
    }

    fn level(&self, policy: LevelPolicy, c: &Creature, s: &PlanarState, r: &Radii) -> Lod {
        match policy {
            LevelPolicy::Influence => self.influence_level(c, s, r),
            LevelPolicy::Camera => self.camera_level(c, s, r),
            LevelPolicy::Combined => self.influence_level(c, s, r).max(self.camera_level(c, s, r)),
            fixed => fixed.initial_level(&Lod::ALL),
        }
    }
}

/// A new world's headless camera starts afresh: it has not turned, nor followed anyone.
fn forget_camera(mut camera: ResMut<SimCamera>) {
    *camera = SimCamera::default();
}

/// Moves the headless camera behind the creature it follows, facing the puck.
fn place_camera(
    clock: Res<SimClock>,
    config: Res<SimConfig>,
    puck: Res<PuckState>,
    mut camera: ResMut<SimCamera>,
    player: Query<(Entity, &PlanarState), With<PlayerControlled>>,
    creatures: Query<(Entity, &Creature, &PlanarState)>,
) {
    let followed = match camera.following.and_then(|e| creatures.get(e).ok()) {
        Some((e, _, s)) if player.is_empty() || player.contains(e) => Some((e, *s)),
        _ => player.iter().next().map(|(e, s)| (e, *s)).or_else(|| {
            creatures
                .iter()
                .min_by_key(|(_, c, _)| c.serial)
                .map(|(e, _, s)| (e, *s))
        }),
    };
    let Some((entity, state)) = followed else { return };
    let c = &config.rules.camera;
    let facing = (puck.position - state.position)
        .try_normalize()
        .unwrap_or(state.heading);
    let at = |p: Vec2, y: f32| Vec3::new(p.x, y, p.y);
    let placed = SimCamera::looking_at(
        at(state.position - facing * c.follow_distance_m, c.follow_height_m),
        at(
            state.position.lerp(puck.position, c.aim_toward_puck_fraction),
            c.aim_height_m,
        ),
        (c.field_of_view_deg.to_radians(), c.aspect_ratio, c.far_m),
        Some(entity),
    );
    *camera = placed.turned_since(&camera, 1.0 / clock.tick_hz as f32);
}

/// Whether every creature is at the level a fixed policy gives it, so that selecting and
/// switching can rest. Under a rule-based policy levels keep changing.
#[derive(Resource, Default)]
pub struct LevelsSettled(bool);

impl LevelsSettled {
    /// Whether selecting and switching rest: a fixed policy's levels are all reached.
    pub fn at_rest(&self) -> bool {
        self.0
    }
}

/// Levels may change: under a rule-based policy always; under a fixed one until every
/// creature has reached it (at the start, or after the policy changed during a game).
pub fn levels_may_change(config: Res<SimConfig>, settled: Res<LevelsSettled>) -> bool {
    config.scenario.level_policy.is_dynamic() || !settled.0
}

fn unsettle_levels(mut settled: ResMut<LevelsSettled>) {
    settled.0 = false;
}

/// At each decision, the level the policy wants for every creature, with hysteresis.
pub(super) fn select_levels(
    inputs: DecisionInputs,
    mut settled: ResMut<LevelsSettled>,
    mut creatures: Query<(&Creature, &Lod, &PlanarState, &mut LevelChoice)>,
) {
    let (clock, config, kinds) = (&inputs.clock, &inputs.config, &inputs.kinds);
    let policy = config.scenario.level_policy;
    // The budget policy chooses for all creatures at once (`budget.rs`).
    if !clock.is_decision_tick() || policy == LevelPolicy::Budget {
        return;
    }
    let rules = &config.rules;
    let levels = inputs.rules();
    let (enter, leave) = (Radii::of(rules, false), Radii::of(rules, true));
    let now = clock.seconds() as f32;
    for_each_creature!(config.scenario.creature_count(), creatures, |(
        c,
        lod,
        s,
        mut choice,
    ): (
        &Creature,
        &Lod,
        &PlanarState,
        Mut<LevelChoice>
    )| {
        let kind = &kinds[c.kind];
        let up = kind.best_level(levels.level(policy, c, s, &enter));
        let down = kind.best_level(levels.level(policy, c, s, &leave));
        let dwelling = now - choice.last_switch_s < rules.min_dwell_s;
        let wanted = if up > *lod {
            up
        } else if down < *lod && !dwelling {
            down
        } else {
            *lod
        };
        if choice.wanted != wanted {
            choice.wanted = wanted;
        }
    });
    // Under a fixed policy levels rest once every creature is at the policy's level for its
    // kind: none can want another then (a dwell only holds back a creature not yet there, and
    // a world starts at its levels).
    settled.0 = !policy.is_dynamic()
        && creatures
            .iter()
            .all(|(c, lod, s, _)| *lod == kinds[c.kind].best_level(levels.level(policy, c, s, &enter)));
}

/// A new world's creatures, placed as point masses, start at the level the policy gives them
/// where they stand, in the rhythm and pose of that level, not at a default level they would
/// leave in their first flight window. Every policy's levels are entered here, in one order,
/// so that a puck area covering the court is the all-rigid game bit for bit.
pub(super) fn start_at_selected_levels(
    mut commands: Commands,
    inputs: DecisionInputs,
    mut creatures: Query<(
        Entity,
        &Creature,
        &Lod,
        &PlanarState,
        &mut GaitPhase,
        &mut GaitPose,
        &mut LevelChoice,
    )>,
) {
    let (clock, config, kinds) = (&inputs.clock, &inputs.config, &inputs.kinds);
    let policy = config.scenario.level_policy;
    let levels = inputs.rules();
    let enter = Radii::of(&config.rules, false);
    for (entity, c, &lod, s, mut gait, mut pose, mut choice) in &mut creatures {
        let kind = &kinds[c.kind];
        let level = if policy.is_dynamic() {
            kind.best_level(levels.level(policy, c, s, &enter))
        } else {
            policy.initial_level(&kind.levels)
        };
        if level != lod {
            (*gait, *pose) = starting_gait(level, kind, gait.cycle, clock.seconds() as f32);
            // Its new level's model is built as it enters it (the level's observers).
            commands.entity(entity).insert(level);
        }
        choice.wanted = level;
    }
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.init_resource::<SimCamera>()
        .init_resource::<LevelsSettled>()
        .add_systems(
            SimStart,
            (
                (forget_camera, place_camera)
                    .chain()
                    .run_if(not(resource_exists::<CameraFromView>)),
                start_at_selected_levels,
            )
                .chain()
                .in_set(StartStage::Levels),
        )
        .add_systems(
            schedule,
            (
                unsettle_levels.run_if(resource_changed::<SimConfig>),
                (
                    place_camera.run_if(not(resource_exists::<CameraFromView>)),
                    select_levels,
                )
                    .chain()
                    .run_if(levels_may_change),
            )
                .chain()
                .in_set(SimStage::SelectLod),
        );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tile_the_view_cone_misses_holds_no_creature_the_camera_could_see() {
        let mut camera = SimCamera::looking_at(
            Vec3::new(-20.0, 5.5, 3.0),
            Vec3::new(10.0, -1.5, -4.0),
            (60f32.to_radians(), 1.78, 300.0),
            None,
        );
        camera.turn_rate_rad_per_s = 0.3;
        let reach = ViewReach {
            height_m: 0.6,
            radius_m: 0.8,
            hop_m: 1.2,
            sweep: 0.15f32.sin(),
        };
        let mut seed = 12345u64;
        let mut next = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 40) as f32 / (1u64 << 24) as f32
        };
        let (tile, mut missed, mut seen) = (8.0, 0, 0);
        for y in -30..30 {
            for x in -30..30 {
                let min = Vec2::new(x as f32, y as f32) * tile;
                let max = min + Vec2::splat(tile);
                // Its corners and edges, and within.
                let points: Vec<Vec2> = (0..64)
                    .map(|i| match i {
                        0..4 => Vec2::new([min.x, max.x][i & 1], [min.y, max.y][i >> 1]),
                        _ => min + Vec2::new(next(), next()) * tile,
                    })
                    .collect();
                let any_seen = points
                    .iter()
                    .any(|&p| camera.sees_within(&reach, p, camera.ground_distance(p)));
                if camera.sees_none_within(&reach, min, max) {
                    assert!(!any_seen, "a creature in view in the tile at {min}");
                    missed += 1;
                } else {
                    seen += usize::from(any_seen);
                }
            }
        }
        // Most of the court lies behind the eye or beside the view, and the view holds tiles.
        assert!(missed > 3600 / 2 && seen > 100, "{missed} missed, {seen} seen");
    }

    #[test]
    fn a_creature_in_view_stays_in_view_until_it_is_the_margin_outside_the_frustum() {
        // Eye 1.5 m up looking along +x; 90 degrees wide at aspect 1.
        let camera = SimCamera::looking_at(
            Vec3::new(0.0, 1.5, 0.0),
            Vec3::new(10.0, 1.5, 0.0),
            (90f32.to_radians(), 1.0, 2000.0),
            None,
        );
        let side = |z: f32| Vec3::new(10.0, 1.5, z);
        // The right edge is at z = 10 m at x = 10 m; the plane's distance is (z - 10) / sqrt 2.
        assert!(camera.sees(side(9.9), 0.0));
        assert!(!camera.sees(side(10.1), 0.0));
        assert!(camera.sees(side(10.0 + 1.4), 1.0));
        assert!(!camera.sees(side(10.0 + 1.5), 1.0));
        assert!(camera.sees(side(-9.9), 0.0) && !camera.sees(side(-10.1), 0.0));
        // Above and below, and behind the eye.
        assert!(!camera.sees(Vec3::new(10.0, 12.0, 0.0), 0.0));
        assert!(!camera.sees(Vec3::new(10.0, -9.0, 0.0), 0.0));
        assert!(!camera.sees(Vec3::new(-1.0, 1.5, 0.0), 0.5));
        assert!(camera.sees(Vec3::new(1000.0, 1.5, 0.0), 0.0));
        // Beyond the far plane, as the renderer culls: 2,000 m deep along the view, wherever
        // across it.
        assert!(camera.sees(Vec3::new(1999.0, 1.5, 1500.0), 0.0));
        assert!(!camera.sees(Vec3::new(2001.0, 1.5, 1500.0), 0.0));
        assert!(camera.sees(Vec3::new(2001.0, 1.5, 0.0), 1.5));
        // A default camera sees everything.
        assert!(SimCamera::default().sees(Vec3::new(-1e4, 5.0, 3.0), 0.0));
    }

    #[test]
    fn staying_in_view_takes_the_release_margin_more_than_entering() {
        let rules: LevelRules = ron::from_str(include_str!("../../assets/rules/levels.ron")).unwrap();
        let (enter, leave) = (Radii::of(&rules, false), Radii::of(&rules, true));
        assert_eq!(enter.view, 0.0);
        assert_eq!(leave.view, rules.release_margin_m);
        assert_eq!(leave.camera - enter.camera, rules.release_margin_m);
    }

    #[test]
    fn the_area_of_influence_stretches_ahead_of_a_moving_body() {
        let (p, v) = (Vec2::ZERO, Vec2::new(4.0, 0.0));
        // Radius 2, 1 s ahead: reaches from x = -2 to x = 2 + 4 = 6, and 2 across.
        assert!(in_influence(Vec2::new(5.9, 0.0), p, v, 2.0, 1.0));
        assert!(!in_influence(Vec2::new(6.1, 0.0), p, v, 2.0, 1.0));
        assert!(in_influence(Vec2::new(-1.9, 0.0), p, v, 2.0, 1.0));
        assert!(!in_influence(Vec2::new(-2.1, 0.0), p, v, 2.0, 1.0));
        assert!(in_influence(Vec2::new(2.0, 1.9), p, v, 2.0, 1.0));
        assert!(!in_influence(Vec2::new(2.0, 2.1), p, v, 2.0, 1.0));
        // At rest it is a plain circle.
        assert!(in_influence(Vec2::new(0.0, 1.9), p, Vec2::ZERO, 2.0, 1.0));
        assert!(!in_influence(Vec2::new(2.1, 0.0), p, Vec2::ZERO, 2.0, 1.0));
    }
}
