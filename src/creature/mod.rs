//! Creatures: the components every level of detail shares, spawning and respawning.

pub mod steering;

use bevy::prelude::*;
use rand::RngExt;
use std::ops::Index;

use crate::config::{CreatureDef, LegConfig, MAX_LEGS, RigidConfig, SimConfig, SteeringConfig};
use crate::gait::{GaitPose, GaitTable, LegPose};
use crate::lod::{DrawnBefore, LevelChoice, Lod};
use crate::models::point_mass::FrameStep;
use crate::outcome::CollisionRecord;
use crate::{SimEntity, SimStart, WorldRng};
use std::collections::HashMap;

/// A legged creature. Its level of detail is the [`Lod`] component beside it.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
#[require(
    Lod,
    LevelChoice,
    PlanarState,
    GaitPhase,
    GaitPose,
    DesiredVelocity,
    CollisionRecord,
    DrawnBefore,
    FrameStep,
    SimEntity
)]
pub struct Creature {
    /// Index into [`KindTable`] (and [`SimConfig::kinds`]).
    pub kind: usize,
    /// Spawn number, unique over the run: a respawned creature is a new creature.
    pub serial: u32,
}

/// The body's state on the ground plane, shared by every level (plane x, y = world x, z).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct PlanarState {
    /// Metres, on the ground plane.
    pub position: Vec2,
    /// Metres per second, on the ground plane.
    pub velocity: Vec2,
    /// Direction the body faces: a unit vector (an angle would cost an `atan2` per tick).
    pub heading: Vec2,
}

impl Default for PlanarState {
    fn default() -> Self {
        Self {
            position: Vec2::ZERO,
            velocity: Vec2::ZERO,
            heading: Vec2::X,
        }
    }
}

impl PlanarState {
    /// The heading as an angle, radians from +x towards +y (world +z).
    pub fn heading_angle(&self) -> f32 {
        self.heading.to_angle()
    }
}

/// Where the creature is in its gait, kept at every level so that a level switch can wait for
/// the flight window (paper 3.4): read from the controller at the rigid level, advanced by
/// time at the others. A step runs from one touchdown to the next (a hop of the hopper); a
/// stride is one step of each virtual leg in turn (one step when the legs share the ground together).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct GaitPhase {
    /// Fraction of the step since the last touchdown, in `[0, 1)`.
    pub cycle: f32,
    /// Whether every foot is off the ground (the flight phase: where a switch may happen).
    pub in_flight: bool,
    /// Simulated time of the last touchdown, s.
    pub last_touchdown_s: f32,
    /// Touchdown to touchdown, s.
    pub hop_period_s: f32,
    /// Part of the step on the ground, from touchdown.
    pub stance_fraction: f32,
    /// Which step of the stride this is: the virtual leg that touched down last.
    pub step: u8,
}

impl GaitPhase {
    /// At `cycle` of the first step of a stride, steps of `hop_period_s`, at time `now_s`.
    pub fn at(cycle: f32, hop_period_s: f32, stance_fraction: f32, now_s: f32) -> Self {
        Self {
            cycle,
            in_flight: cycle >= stance_fraction,
            last_touchdown_s: now_s - cycle * hop_period_s,
            hop_period_s,
            stance_fraction,
            step: 0,
        }
    }

    /// Advances the cycle by `dt` from `now_s` at the given rhythm: stance first, then flight;
    /// a touchdown starts the next of `steps_per_stride` steps.
    pub fn advance(&mut self, hop_period_s: f32, stance_fraction: f32, steps_per_stride: u32, now_s: f32, dt: f32) {
        let cycle = self.cycle + dt / hop_period_s;
        *self = if cycle >= 1.0 {
            Self {
                step: ((u32::from(self.step) + 1) % steps_per_stride.max(1)) as u8,
                ..Self::at(cycle.fract(), hop_period_s, stance_fraction, now_s + dt)
            }
        } else {
            Self {
                cycle,
                in_flight: cycle >= stance_fraction,
                hop_period_s,
                stance_fraction,
                ..*self
            }
        };
    }

    /// How far through the stride (0..1 from the first leg's touchdown): the gait table's phase.
    pub fn stride(&self, steps_per_stride: u32) -> f32 {
        (f32::from(self.step) + self.cycle) / steps_per_stride.max(1) as f32
    }

    /// How far through its flight the creature is (0 lift-off, 1 touchdown), if in flight.
    pub fn flight_progress(&self) -> Option<f32> {
        self.in_flight
            .then(|| ((self.cycle - self.stance_fraction) / (1.0 - self.stance_fraction).max(1e-3)).clamp(0.0, 1.0))
    }
}

/// A creature whose desired velocity comes from outside (the player's keyboard, a test, an
/// experiment): steering leaves it alone.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct PlayerControlled;

/// The planar velocity steering asks for.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct DesiredVelocity(pub Vec2);

/// Per-kind constants, derived once from the creature files.
#[derive(Clone, Debug)]
pub struct KindParams {
    /// The footprint's radius: the collision circle below the rigid level.
    pub radius_m: f32,
    /// What the camera rule tests against the view: the height of a sphere's centre and its
    /// radius, holding the body and legs from the ground to a body's radius above the hips.
    pub view_sphere_m: (f32, f32),
    /// The whole creature's mass.
    pub mass_kg: f32,
    /// The point mass's limits: the gait table's measured ones when there is a table.
    pub top_speed_m_per_s: f32,
    /// The point mass's acceleration limit (see `top_speed_m_per_s`).
    pub acceleration_limit_m_per_s2: f32,
    /// How fast the rigid model's command follows the desired velocity.
    pub command_acceleration_m_per_s2: f32,
    /// How fast the body turns to face its course.
    pub turn_rate_rad_per_s: f32,
    /// Standing pose: the point-mass level holds it (the legs straight down).
    pub standing_pose: GaitPose,
    /// Where each leg's hip sits on the body (x forward, y up, z to the right).
    pub hips_m: Vec<Vec3>,
    /// Each leg's parts, spring and foot, in the kind's order.
    pub legs: Vec<LegConfig>,
    /// The legs grouped into virtual legs, in the order they take stance.
    pub virtual_legs: VirtualLegs,
    /// Hop cycles per second.
    pub cycles_per_s: f32,
    /// Part of the cycle before lift-off.
    pub stance_fraction: f32,
    /// Below the rigid level, an impact with a greater normal speed is a fall.
    pub fall_impact_speed_m_per_s: f32,
    /// Share of the approaching speed kept when a point mass bounces off something.
    pub collision_restitution: f32,
    /// How this kind steers: wandering, fleeing the puck, avoiding walls and others.
    pub steering: SteeringConfig,
    /// The rigid model and its controller, if the kind has the rigid level.
    pub rigid: Option<RigidConfig>,
    /// The gait table, if the kind has the hybrid level.
    pub gait: Option<GaitTable>,
    /// The levels this kind has a model for, cheapest first.
    pub levels: Vec<Lod>,
}

impl KindParams {
    /// Steps in a stride: one stance of each virtual leg.
    pub fn steps_per_stride(&self) -> u32 {
        self.virtual_legs.count as u32
    }

    /// The most detailed level this kind has a model for, at or below `wanted`.
    pub fn best_level(&self, wanted: Lod) -> Lod {
        self.levels
            .iter()
            .copied()
            .filter(|&l| l <= wanted)
            .max()
            .unwrap_or(Lod::PointMass)
    }

    /// A kind's constants from its file and its gait table (whose limits the point mass takes).
    pub fn new(d: &CreatureDef, gait: Option<&GaitTable>) -> Self {
        let hips_m: Vec<Vec3> = d.legs.iter().map(|l| Vec3::from(l.hip_m)).collect();
        let standing: Vec<LegPose> = hips_m
            .iter()
            .map(|hip| LegPose::straight(d.body.hip_height_m + hip.y))
            .collect();
        let half_height = (d.body.hip_height_m + d.body.radius_m) / 2.0;
        let top_speed_m_per_s = gait.map_or(d.top_speed_m_per_s, |g| g.top_speed_m_per_s);
        Self {
            radius_m: d.body.radius_m,
            view_sphere_m: (half_height, half_height.hypot(d.body.radius_m)),
            mass_kg: d.body.mass_kg,
            top_speed_m_per_s,
            acceleration_limit_m_per_s2: gait.map_or(d.acceleration_limit_m_per_s2, |g| g.acceleration_limit_m_per_s2),
            command_acceleration_m_per_s2: d.acceleration_limit_m_per_s2,
            turn_rate_rad_per_s: d.turn_rate_deg_per_s.to_radians(),
            standing_pose: GaitPose::new(d.body.hip_height_m, 0.0, 0.0, &standing),
            hips_m,
            legs: d.legs.clone(),
            virtual_legs: VirtualLegs::new(&d.stance.groups(d.legs.len())),
            cycles_per_s: 1.0 / d.hop_period_s,
            stance_fraction: 1.0 - d.flight_fraction,
            fall_impact_speed_m_per_s: d.fall_impact_speed_m_per_s,
            collision_restitution: d.collision_restitution,
            steering: d.steering.clone(),
            rigid: d.rigid.clone(),
            gait: gait.cloned(),
            levels: Lod::ALL
                .into_iter()
                .filter(|l| match l {
                    Lod::PointMass => true,
                    Lod::Hybrid => gait.is_some(),
                    Lod::Rigid => d.rigid.is_some(),
                })
                .collect(),
        }
    }
}

/// A kind's legs grouped into virtual legs (its file's `stance`), kept in fixed arrays: the
/// controller looks them up each tick without allocating.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VirtualLegs {
    /// How many virtual legs: the steps in a stride.
    pub count: usize,
    /// Each leg's virtual leg.
    pub of_leg: [usize; MAX_LEGS],
    /// Each virtual leg's first leg: its compression ends the virtual leg's, and the legs that
    /// swing mirror it.
    pub first_leg: [usize; MAX_LEGS],
    /// How many legs each virtual leg has.
    pub legs: [usize; MAX_LEGS],
}

impl VirtualLegs {
    /// From a validated grouping: every leg in exactly one group.
    pub fn new(groups: &[Vec<usize>]) -> Self {
        let mut v = Self {
            count: groups.len(),
            of_leg: [0; MAX_LEGS],
            first_leg: [0; MAX_LEGS],
            legs: [0; MAX_LEGS],
        };
        for (g, group) in groups.iter().enumerate().take(MAX_LEGS) {
            v.first_leg[g] = group.first().copied().unwrap_or(0);
            v.legs[g] = group.len();
            for &leg in group.iter().filter(|&&l| l < MAX_LEGS) {
                v.of_leg[leg] = g;
            }
        }
        v
    }

    /// One virtual leg of every leg: they all hop together.
    pub fn together(&self) -> bool {
        self.count == 1
    }
}

/// The creature kinds of this run, indexed by [`Creature::kind`].
#[derive(Resource, Clone, Debug)]
pub struct KindTable(pub Vec<KindParams>);

impl KindTable {
    /// The kinds of a run's config.
    pub fn of(config: &SimConfig) -> Self {
        Self(
            config
                .kinds
                .iter()
                .zip(&config.gaits)
                .map(|(d, g)| KindParams::new(d, g.as_ref()))
                .collect(),
        )
    }
}

impl Index<usize> for KindTable {
    type Output = KindParams;
    fn index(&self, kind: usize) -> &KindParams {
        &self.0[kind]
    }
}

/// Hands out creature serials.
#[derive(Resource, Debug, Default)]
pub struct SerialCounter(pub u32);

impl SerialCounter {
    /// The next serial.
    pub fn take(&mut self) -> u32 {
        self.0 += 1;
        self.0 - 1
    }
}

/// Tries for a free spot before settling for the best one seen.
const PLACEMENT_ATTEMPTS: usize = 24;

/// A random spot in the court at least `wanted` clear by `clearance`, or the clearest of
/// `PLACEMENT_ATTEMPTS` tries. `margin` keeps the spot off the walls.
pub fn find_free_spot(
    rng: &mut WorldRng,
    half: Vec2,
    margin: f32,
    wanted: f32,
    clearance: impl Fn(Vec2) -> f32,
) -> Vec2 {
    let inner = (half - Vec2::splat(margin)).max(Vec2::ZERO);
    let mut best = (f32::NEG_INFINITY, Vec2::ZERO);
    for _ in 0..PLACEMENT_ATTEMPTS {
        let p = Vec2::new(rng.0.random_range(-1.0..=1.0), rng.0.random_range(-1.0..=1.0)) * inner;
        let c = clearance(p);
        if c >= wanted {
            return p;
        }
        if c > best.0 {
            best = (c, p);
        }
    }
    best.1
}

/// What a new creature starts with, apart from where it stands.
pub fn creature_bundle(
    kind: usize,
    params: &KindParams,
    serial: u32,
    level: Lod,
    position: Vec2,
    now_s: f32,
    rng: &mut WorldRng,
) -> (Creature, Lod, PlanarState, GaitPhase, GaitPose) {
    let heading = Vec2::from_angle(rng.0.random_range(-std::f32::consts::PI..std::f32::consts::PI));
    let cycle = rng.0.random_range(0.0..1.0);
    let (gait, pose) = starting_gait(level, params, cycle, now_s);
    (
        Creature { kind, serial },
        level,
        PlanarState {
            position,
            velocity: Vec2::ZERO,
            heading,
        },
        gait,
        pose,
    )
}

/// The rhythm and pose a standing creature starts in at `level`, `cycle` into its hop: what
/// its level shows from the first frame (a hybrid's are its table's).
pub fn starting_gait(level: Lod, params: &KindParams, cycle: f32, now_s: f32) -> (GaitPhase, GaitPose) {
    let (hop_period_s, stance_fraction, pose) = match (level, &params.gait) {
        (Lod::Hybrid, Some(table)) => {
            let (period, stance) = table.rhythm(0.0);
            (
                period,
                stance,
                table.pose(0.0, cycle / params.steps_per_stride() as f32),
            )
        }
        _ => (1.0 / params.cycles_per_s, params.stance_fraction, params.standing_pose),
    };
    (GaitPhase::at(cycle, hop_period_s, stance_fraction, now_s), pose)
}

/// Who stands where while the scenario is being placed: a grid that grows one creature at
/// a time, so placing N creatures costs O(N).
struct Occupancy {
    cell_m: f32,
    cells: HashMap<(i32, i32), Vec<(Vec2, f32)>>,
}

impl Occupancy {
    fn key(&self, p: Vec2) -> (i32, i32) {
        let c = (p / self.cell_m).floor();
        (c.x as i32, c.y as i32)
    }

    fn insert(&mut self, p: Vec2, radius: f32) {
        let key = self.key(p);
        self.cells.entry(key).or_default().push((p, radius));
    }

    /// Distance from `p` to the nearest rim within one cell's reach, else `cell_m`.
    fn clearance(&self, p: Vec2) -> f32 {
        let (x, y) = self.key(p);
        let mut best = self.cell_m;
        for dy in -1..=1 {
            for dx in -1..=1 {
                for (q, r) in self.cells.get(&(x + dx, y + dy)).into_iter().flatten() {
                    best = best.min(q.distance(p) - r);
                }
            }
        }
        best
    }
}

/// Places the scenario's creatures in free parts of the court, numbered from 0.
pub(crate) fn spawn_creatures(mut commands: Commands, config: Res<SimConfig>, mut rng: ResMut<WorldRng>) {
    let kinds = KindTable::of(&config);
    let mut serials = SerialCounter::default();
    let half = config.arena.half_extents();
    let clear = config.arena.respawn_creature_clearance_m;
    let biggest = config.kinds.iter().map(|k| k.body.radius_m).fold(0.0, f32::max);
    let mut placed = Occupancy {
        cell_m: 2.0 * biggest + clear,
        cells: HashMap::new(),
    };
    let puck_keep_out = config.arena.puck.radius_m + config.arena.respawn_puck_clearance_m;
    let mut batch = Vec::with_capacity(config.scenario.creature_count() as usize);
    for group in &config.scenario.creatures {
        let kind = config
            .kind_index(&group.kind)
            .expect("kinds are resolved when the config loads");
        let radius = config.kinds[kind].body.radius_m;
        // As point masses: each enters its level once all are placed (`lod::select`).
        let level = Lod::PointMass;
        for _ in 0..group.count {
            // The puck starts at the centre.
            let spot = find_free_spot(&mut rng, half, radius + clear, radius + clear, |p| {
                placed.clearance(p).min(p.length() - puck_keep_out)
            });
            placed.insert(spot, radius);
            batch.push(creature_bundle(
                kind,
                &kinds[kind],
                serials.take(),
                level,
                spot,
                0.0,
                &mut rng,
            ));
        }
    }
    // Spawned in bands across the court, each band along x: creatures near in the court are
    // then near in memory, and every loop that asks a creature's neighbours (steering, contacts,
    // the spatial index) reads what the creature before it just read. A crowd of a million
    // spawned in random order spends most of each frame waiting on memory.
    let band_m = placed.cell_m;
    batch.sort_by(|a, b| {
        let key = |s: &PlanarState| ((s.position.y / band_m).floor() as i32, s.position.x);
        let ((ya, xa), (yb, xb)) = (key(&a.2), key(&b.2));
        ya.cmp(&yb).then(xa.total_cmp(&xb))
    });
    // The kinds first: a creature's level builds its model from them as it is spawned.
    commands.insert_resource(kinds);
    commands.insert_resource(serials);
    commands.spawn_batch(batch);
}

pub(super) fn plugin(app: &mut App) {
    app.add_systems(SimStart, spawn_creatures.after(crate::arena::spawn_arena));
    steering::plugin(app);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use std::cell::Cell;

    #[test]
    fn a_full_court_gives_a_spot_after_a_bounded_number_of_tries() {
        let mut rng = WorldRng(rand::rngs::StdRng::seed_from_u64(1));
        let asked = Cell::new(0);
        let half = Vec2::new(3.0, 2.0);
        // Nowhere is clear enough: the clearest of the tries is taken.
        let spot = find_free_spot(&mut rng, half, 0.5, 1.0, |p| {
            asked.set(asked.get() + 1);
            -p.length()
        });
        assert_eq!(asked.get(), PLACEMENT_ATTEMPTS);
        assert!(spot.x.abs() <= 2.5 && spot.y.abs() <= 1.5, "{spot}");
        // A margin wider than the court leaves only its centre line, still without a loop.
        let spot = find_free_spot(&mut rng, half, 10.0, 1.0, |_| 0.0);
        assert_eq!(spot, Vec2::ZERO);
    }

    #[test]
    fn hop_run_and_trot_are_groupings_of_legs_into_virtual_legs() {
        use crate::config::Stance;
        let hop = VirtualLegs::new(&Stance::Together.groups(2));
        assert!(hop.together());
        assert_eq!((hop.of_leg, hop.legs[0]), ([0; MAX_LEGS], 2));
        let run = VirtualLegs::new(&Stance::Alternating.groups(2));
        assert_eq!((run.count, run.of_leg[1], run.first_leg[1]), (2, 1, 1));
        let trot = VirtualLegs::new(&Stance::VirtualLegs(vec![vec![0, 3], vec![1, 2]]).groups(4));
        assert_eq!((trot.count, trot.of_leg, trot.first_leg[1]), (2, [0, 1, 1, 0], 1));
        assert_eq!(trot.legs[..2], [2, 2]);
    }
}
