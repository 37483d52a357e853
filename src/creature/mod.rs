//! Creatures: the components every level of detail shares, spawning and respawning.

pub mod steering;
pub use steering::Clearance;

pub use crate::contract::{DesiredVelocity, GaitPhase, PlanarState, PlayerControlled};
pub use crate::kind::{Creature, KindParams, KindTable, VirtualLegs, starting_gait};

use bevy::prelude::*;
use rand::RngExt;

use crate::config::SimConfig;

use crate::contract::GaitPose;
use crate::contract::Lod;
use crate::contract::{SimStart, StartStage, WorldRng};
use std::collections::HashMap;

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
    let mut newcomers = Newcomers::default();
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
    commands.spawn_batch(batch);
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
}
