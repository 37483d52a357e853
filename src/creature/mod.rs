//! Creatures: the components every level of detail shares, spawning and respawning.

pub mod steering;
pub use steering::Clearance;

pub use crate::contract::{DesiredVelocity, GaitPhase, PlanarState, PlayerControlled};
pub use crate::kind::{Creature, KindParams, KindTable, VirtualLegs, starting_gait};

use bevy::prelude::*;
use rand::RngExt;

use crate::config::SimConfig;

use crate::contract::GaitPose;
use crate::contract::{AtPointMass, Lod};
use crate::contract::{SimStart, StartStage, WorldRng};

/// Hands out creature serials, and keeps where creatures were placed since the last steering
/// decision: steering wakes a creature that looks around rarely when one lands near it.
#[derive(Resource, Debug, Default)]
pub struct Newcomers {
    next_serial: u32,
    /// Where creatures were put since the last decision, other than by their own motion: each
    /// respawn, and any creature a system of yours moves (push where it put it).
    pub placed_at: Vec<Vec2>,
}

impl Newcomers {
    /// The next serial.
    pub fn take(&mut self) -> u32 {
        self.next_serial += 1;
        self.next_serial - 1
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

/// Who stands where while the scenario is being placed: a grid that grows one creature at
/// a time, so placing N creatures costs O(N).
struct Occupancy {
    cell_m: f32,
    /// The cell of the court's corner, and the court's cells along x and y: every spot placed
    /// lies in the court. Cells start at whole multiples of `cell_m` from the centre.
    corner: IVec2,
    cols: i32,
    rows: i32,
    /// Each cell's last creature placed, and each creature's previous one in its cell (`NONE`
    /// ends a cell): a dense grid, not a hash map, since placing a crowd asks nine cells per
    /// try (a map's hashing was two thirds of building 20,000 point masses, 2026-11-29).
    last_in_cell: Vec<u32>,
    placed: Vec<(Vec2, f32, u32)>,
}

impl Occupancy {
    const NONE: u32 = u32::MAX;

    fn over(half: Vec2, cell_m: f32) -> Self {
        let corner = (-half / cell_m).floor().as_ivec2();
        let (cols, rows) = ((half / cell_m).floor().as_ivec2() - corner + IVec2::ONE).into();
        Self {
            cell_m,
            corner,
            cols,
            rows,
            last_in_cell: vec![Self::NONE; (cols * rows) as usize],
            placed: Vec::new(),
        }
    }

    fn cell(&self, p: Vec2) -> (i32, i32) {
        let c = (p / self.cell_m).floor().as_ivec2() - self.corner;
        (c.x.clamp(0, self.cols - 1), c.y.clamp(0, self.rows - 1))
    }

    fn insert(&mut self, p: Vec2, radius: f32) {
        let (x, y) = self.cell(p);
        let head = &mut self.last_in_cell[(y * self.cols + x) as usize];
        self.placed.push((p, radius, *head));
        *head = (self.placed.len() - 1) as u32;
    }

    /// Distance from `p` to the nearest rim within one cell's reach, else `cell_m`.
    fn clearance(&self, p: Vec2) -> f32 {
        let (x, y) = self.cell(p);
        let mut best = self.cell_m;
        for cy in (y - 1).max(0)..=(y + 1).min(self.rows - 1) {
            for cx in (x - 1).max(0)..=(x + 1).min(self.cols - 1) {
                let mut i = self.last_in_cell[(cy * self.cols + cx) as usize];
                while i != Self::NONE {
                    let (q, r, before) = self.placed[i as usize];
                    best = best.min(q.distance(p) - r);
                    i = before;
                }
            }
        }
        best
    }
}

/// Places the scenario's creatures in free parts of the court, numbered from 0.
pub(crate) fn spawn_creatures(mut commands: Commands, config: Res<SimConfig>, mut rng: ResMut<WorldRng>) {
    let kinds = KindTable::of(&config);
    let mut newcomers = Newcomers::default();
    let half = config.arena.half_extents();
    let clear = config.arena.respawn_creature_clearance_m;
    let biggest = config.kinds.iter().map(|k| k.body.radius_m).fold(0.0, f32::max);
    let mut placed = Occupancy::over(half, 2.0 * biggest + clear);
    let puck_keep_out = config.arena.puck.radius_m + config.arena.respawn_puck_clearance_m;
    let mut batch = Vec::with_capacity(config.scenario.creature_count() as usize);
    for group in &config.scenario.creatures {
        let kind = config
            .kind_index(&group.kind)
            .expect("kinds are resolved when the config loads");
        let radius = config.kinds[kind].body.radius_m;
        // As point masses (spawned with their marker, below): each enters its level once all are
        // placed (`lod::select`).
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
                newcomers.take(),
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
    commands.insert_resource(newcomers);
    // With their level's marker, which the level's hook would otherwise add to each one by one.
    commands.spawn_batch(batch.into_iter().map(|creature| (creature, AtPointMass)));
}

pub(super) fn plugin(app: &mut App) {
    app.add_systems(SimStart, spawn_creatures.in_set(StartStage::Creatures));
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
    fn the_placement_grid_finds_the_nearest_rim_within_a_cell_anywhere_in_the_court() {
        let mut rng = WorldRng(rand::rngs::StdRng::seed_from_u64(3));
        // A court not a whole number of cells across, so that its edge cells are partial.
        let (half, cell_m) = (Vec2::new(7.3, 4.1), 1.7);
        let mut grid = Occupancy::over(half, cell_m);
        let mut placed = Vec::new();
        let mut spot = || Vec2::new(rng.0.random_range(-1.0..=1.0), rng.0.random_range(-1.0..=1.0)) * half;
        for i in 0..200 {
            let (p, r) = (spot(), 0.2 + 0.01 * (i % 30) as f32);
            grid.insert(p, r);
            placed.push((p, r));
        }
        for p in (0..500)
            .map(|_| spot())
            .chain([half, -half, Vec2::new(half.x, -half.y)])
        {
            // Every creature whose centre is nearer than a cell lies in the 3 by 3 cells around
            // p, so its rim counts; one further away may count too, never one not placed.
            let rim = |(q, r): &(Vec2, f32)| q.distance(p) - r;
            let nearest = placed.iter().map(rim).fold(cell_m, f32::min);
            let within_a_cell = (placed.iter().filter(|(q, _)| q.distance(p) < cell_m))
                .map(rim)
                .fold(cell_m, f32::min);
            let found = grid.clearance(p);
            assert!(
                found >= nearest && found <= within_a_cell,
                "{p}: {nearest} {found} {within_a_cell}"
            );
        }
    }
}
