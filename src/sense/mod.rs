//! Sense: the spatial index every neighbour query goes through, so that the cost per
//! creature stays flat as the count grows (no all-pairs loop).

use bevy::prelude::*;

use crate::config::SimConfig;
use crate::contract::PlanarState;
use crate::contract::{DENSE, chunk_len, run_chunks};
use crate::contract::{SimClock, SimStage, SimStart, StartStage};
use crate::kind::{Creature, KindTable};
use bevy::utils::Parallel;

/// The court's inside, on the ground plane.
#[derive(Resource, Clone, Copy, Debug)]
pub struct Court {
    /// Half the inside extents along world x and z.
    pub half_extents: Vec2,
}

/// The puck as every creature sees it this tick.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct PuckState {
    /// Centre on the ground plane (world x, z), metres.
    pub position: Vec2,
    /// Velocity on the ground plane, m/s.
    pub velocity: Vec2,
    /// The puck's own radius.
    pub radius_m: f32,
}

/// What a creature knows of a neighbour: a snapshot taken when the index was built.
#[derive(Clone, Copy, Debug)]
pub struct Neighbour {
    /// Metres, on the ground plane.
    pub position: Vec2,
    /// Metres per second, on the ground plane.
    pub velocity: Vec2,
    /// Its footprint's radius, metres.
    pub radius: f32,
    /// Its mass, kg.
    pub mass: f32,
    /// The neighbour's [`Creature::serial`], so a creature can skip itself.
    pub serial: u32,
}

/// A creature in the index, and its cell (`row * cols + column`) beside it: a query reads
/// both from one line of the cache (32 bytes), the fill and the sort by cell move one thing.
#[derive(Clone, Copy, Debug)]
struct Entry {
    neighbour: Neighbour,
    cell: u32,
}

const _: () = assert!(
    std::mem::size_of::<Entry>() == 32,
    "an entry fills half a line of the cache"
);

/// Cells per block along a row: the index keeps where each block's entries start, not each
/// cell's, so a rebuild clears and sums a thirty-second of the cells (some 27 cells a creature at
/// the shipped density: the cells, not the creatures, were most of a rebuild and of the
/// memory). A block holds about one creature there (72 m²), so each row of a query scans about
/// one entry more than it keeps.
const BLOCK_CELLS: u32 = 32;

/// A uniform grid over the court, rebuilt by counting sort at every steering decision.
#[derive(Resource, Debug, Default)]
pub struct NeighbourGrid {
    min: Vec2,
    inv_cell_m: f32,
    cols: u32,
    rows: u32,
    /// Blocks of [`BLOCK_CELLS`] cells along a row, per row.
    block_cols: u32,
    /// `block_start[b]..block_start[b + 1]` are the entries of block `b` (row by row), in the
    /// order of their cells, and in serial order within a cell.
    block_start: Vec<u32>,
    entries: Vec<Entry>,
    /// Scratch, kept to avoid an allocation per rebuild: each input's block and cell.
    keys: Vec<(u32, u32)>,
    scratch: Vec<Neighbour>,
    /// The fastest entry's planar speed and the widest footprint: how soon anything beyond a
    /// distance can come near (a search stops where nothing further can matter).
    fastest_m_per_s: f32,
    widest_radius_m: f32,
}

impl NeighbourGrid {
    /// A grid covering the court (half extents `half`) with square cells of `cell_m`.
    pub fn new(half: Vec2, cell_m: f32) -> Self {
        let cols = ((2.0 * half.x / cell_m).ceil() as u32).max(1);
        let rows = ((2.0 * half.y / cell_m).ceil() as u32).max(1);
        let block_cols = cols.div_ceil(BLOCK_CELLS);
        Self {
            min: -half,
            inv_cell_m: 1.0 / cell_m,
            cols,
            rows,
            block_cols,
            block_start: vec![0; (block_cols * rows + 1) as usize],
            ..default()
        }
    }

    fn cell_xy(&self, p: Vec2) -> (u32, u32) {
        // No `floor`: clamped at 0 first, the cast's truncation is the floor (and a library call less).
        let c = ((p - self.min) * self.inv_cell_m).max(Vec2::ZERO);
        ((c.x as u32).min(self.cols - 1), (c.y as u32).min(self.rows - 1))
    }

    /// Replaces the contents with `items`.
    pub fn rebuild(&mut self, items: impl Iterator<Item = Neighbour>) {
        let items: Vec<Neighbour> = items.collect();
        self.rebuild_parts(&[&items[..]], |part| part.len(), |part, i| part[i]);
    }

    /// Replaces the contents with the items of `parts` in order (say, a query's tables): the
    /// `len_of(part)` items of each, the `i`-th made by `item(part, i)`. Made and keyed across
    /// the cores, in one pass over each part.
    pub fn rebuild_parts<P: Sync>(
        &mut self,
        parts: &[P],
        len_of: impl Fn(&P) -> usize,
        item: impl Fn(&P, usize) -> Neighbour + Sync,
    ) {
        let len = parts.iter().map(&len_of).sum();
        let (mut scratch, mut keys) = (std::mem::take(&mut self.scratch), std::mem::take(&mut self.keys));
        scratch.resize(len, EMPTY);
        keys.resize(len, (0, 0));
        // Each item, its block and cell, and the fastest and widest.
        let n = chunk_len(len as u32, len);
        let mut widest = Parallel::<(f32, f32)>::default();
        let mut jobs = Vec::new();
        let (mut items, mut item_keys) = (&mut scratch[..], &mut keys[..]);
        for part in parts {
            let (here, rest) = std::mem::take(&mut items).split_at_mut(len_of(part));
            let (here_keys, rest_keys) = std::mem::take(&mut item_keys).split_at_mut(here.len());
            (items, item_keys) = (rest, rest_keys);
            let starts = (0..here.len()).step_by(n);
            jobs.extend(
                starts
                    .zip(here.chunks_mut(n).zip(here_keys.chunks_mut(n)))
                    .map(|(start, c)| (part, start, c)),
            );
        }
        let (grid, item, widest_now) = (&*self, &item, &widest);
        run_chunks(jobs.into_iter().map(|(part, start, (items, keys))| {
            move || {
                // The fastest's squared speed: a root a job, not one a creature (the root keeps order).
                let (mut fastest2, mut wide) = (0.0f32, 0.0f32);
                for (i, (n, key)) in items.iter_mut().zip(keys).enumerate() {
                    *n = item(part, start + i);
                    fastest2 = fastest2.max(n.velocity.length_squared());
                    wide = wide.max(n.radius);
                    let (x, y) = grid.cell_xy(n.position);
                    *key = (y * grid.block_cols + x / BLOCK_CELLS, y * grid.cols + x);
                }
                let mut w = widest_now.borrow_local_mut();
                *w = (w.0.max(fastest2.sqrt()), w.1.max(wide));
            }
        }));
        (self.scratch, self.keys) = (scratch, keys);
        (self.fastest_m_per_s, self.widest_radius_m) = widest
            .iter_mut()
            .fold((0.0f32, 0.0f32), |(f, w), fw| (f.max(fw.0), w.max(fw.1)));
        // The blocks in a range a core, which counts, fills in input order and sorts by cell and
        // serial its own: each core reads every key and takes its range's.
        let blocks = self.block_start.len() - 1;
        let ranges = len.div_ceil(n).max(1);
        let edge: Vec<usize> = (0..=ranges).map(|r| r * blocks / ranges).collect();
        // Block b's count goes to b + 2, so that after the sums `block_start[b + 1]` is where b
        // starts; the fill moves it on to where b ends, which is where b + 1 starts (no copy of
        // the starts as the fill's cursors). Range r counts into `edge[r] + 2..edge[r + 1] + 2`
        // (the first from 0; the last block's count is never needed).
        let keys = &self.keys;
        let mut counts = Vec::with_capacity(ranges);
        let (mut rest, mut base) = (&mut self.block_start[..], 0);
        for r in 0..ranges {
            let end = if r + 1 == ranges { blocks + 1 } else { edge[r + 1] + 2 };
            let (mine, more) = std::mem::take(&mut rest).split_at_mut(end - base);
            counts.push((base, mine));
            (rest, base) = (more, end);
        }
        run_chunks(counts.into_iter().map(|(base, counts)| {
            move || {
                counts.fill(0);
                for &(b, _) in keys {
                    if let Some(count) = (b as usize + 2).checked_sub(base).and_then(|i| counts.get_mut(i)) {
                        *count += 1;
                    }
                }
            }
        }));
        // The running sum in a register: each block waits on an add, not on the store before it.
        let mut sum = 0;
        for start in &mut self.block_start {
            sum += *start;
            *start = sum;
        }
        // Range r fills the entries from where its first block starts, its cursors
        // `block_start[edge[r] + 1..edge[r + 1] + 1]`. Every slot is written, so the array is
        // only resized (not cleared and filled first: a pass of its own).
        self.entries.resize(
            len,
            Entry {
                neighbour: EMPTY,
                cell: 0,
            },
        );
        let starts: Vec<usize> = (edge
            .iter()
            .map(|&b| self.block_start.get(b + 1).map_or(len, |&s| s as usize)))
        .collect();
        let (items, keys) = (&self.scratch, &self.keys);
        let mut fills = Vec::with_capacity(ranges);
        let mut entries = &mut self.entries[..];
        let mut cursors = &mut self.block_start[1..];
        for r in 0..ranges {
            let size = starts[r + 1] - starts[r];
            let (mine, more) = std::mem::take(&mut entries).split_at_mut(size);
            let (mine_cursors, more_cursors) = std::mem::take(&mut cursors).split_at_mut(edge[r + 1] - edge[r]);
            fills.push((edge[r], starts[r], mine, mine_cursors));
            (entries, cursors) = (more, more_cursors);
        }
        run_chunks(fills.into_iter().map(|(first, start, entries, cursors)| {
            move || {
                for (&neighbour, &(b, cell)) in items.iter().zip(keys) {
                    if let Some(slot) = (b as usize).checked_sub(first).and_then(|i| cursors.get_mut(i)) {
                        entries[*slot as usize - start] = Entry { neighbour, cell };
                        *slot += 1;
                    }
                }
                // Then by cell within each block, stably (nothing moves across a block's edge).
                sort_by_cell(entries);
            }
        }));
    }

    /// Creatures in the index.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the index holds no creature.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Calls `f` for every entry whose centre lies within `radius` of `p`.
    pub fn for_each_within(&self, p: Vec2, radius: f32, mut f: impl FnMut(&Neighbour)) {
        let (x0, y0) = self.cell_xy(p - Vec2::splat(radius));
        let (x1, y1) = self.cell_xy(p + Vec2::splat(radius));
        let r2 = radius * radius;
        for y in y0..=y1 {
            let blocks = y * self.block_cols;
            let (a, b) = (
                self.block_start[(blocks + x0 / BLOCK_CELLS) as usize] as usize,
                self.block_start[(blocks + x1 / BLOCK_CELLS + 1) as usize] as usize,
            );
            // The blocks' entries in cells x0..=x1 of this row (they are in the order of their cells).
            let (first, last) = (y * self.cols + x0, y * self.cols + x1);
            for e in &self.entries[a..b] {
                if e.cell > last {
                    break;
                }
                if e.cell >= first && e.neighbour.position.distance_squared(p) <= r2 {
                    f(&e.neighbour);
                }
            }
        }
    }

    /// The fastest entry's planar speed, m/s, and the widest entry's footprint radius, m.
    pub fn fastest_and_widest(&self) -> (f32, f32) {
        (self.fastest_m_per_s, self.widest_radius_m)
    }

    /// Calls `f` for every entry within `radius` of `p` in rings of doubling radius from
    /// `first`, and stops after a ring when `done(ring)` says nothing beyond `ring` can matter.
    /// An entry is visited once.
    pub fn for_each_nearest_first(
        &self,
        p: Vec2,
        first: f32,
        radius: f32,
        mut f: impl FnMut(&Neighbour),
        mut done: impl FnMut(f32) -> bool,
    ) {
        let (mut inner2, mut ring) = (-1.0f32, first.min(radius));
        loop {
            self.for_each_within(p, ring, |n| {
                if n.position.distance_squared(p) > inner2 {
                    f(n);
                }
            });
            if ring >= radius || done(ring) {
                return;
            }
            inner2 = ring * ring;
            ring = (2.0 * ring).min(radius);
        }
    }

    /// Distance from `p` to the nearest entry's rim, looking no further than `radius`.
    pub fn clearance(&self, p: Vec2, radius: f32) -> f32 {
        let mut best = radius;
        self.for_each_within(p, radius, |n| best = best.min(n.position.distance(p) - n.radius));
        best
    }
}

/// Sorts `entries` by their cells, and within a cell by serial: by insertion, since an entry out
/// of order is rare and near its place (a block holds a creature or two). By serial, not in the
/// query's order, so that a query visits a cell's creatures in the same order however the
/// tables hold them (a switch's blend moves a creature to another table): sums over neighbours
/// are then the same bit for bit.
fn sort_by_cell(entries: &mut [Entry]) {
    let key = |e: &Entry| (e.cell, e.neighbour.serial);
    for i in 1..entries.len() {
        let e = entries[i];
        if key(&entries[i - 1]) <= key(&e) {
            continue;
        }
        let mut j = i;
        while j > 0 && key(&entries[j - 1]) > key(&e) {
            entries[j] = entries[j - 1];
            j -= 1;
        }
        entries[j] = e;
    }
}

const EMPTY: Neighbour = Neighbour {
    position: Vec2::ZERO,
    velocity: Vec2::ZERO,
    radius: 0.0,
    mass: 0.0,
    serial: 0,
};

/// Rebuilds the index at each steering decision.
pub(crate) fn index_creatures(
    clock: Res<SimClock>,
    kinds: Res<KindTable>,
    mut grid: ResMut<NeighbourGrid>,
    creatures: Query<(&Creature, &PlanarState)>,
) {
    if !clock.is_decision_tick() {
        return;
    }
    // Table by table, in the query's order.
    let tables: Vec<(&[Creature], &[PlanarState])> = creatures.contiguous_iter().expect(DENSE).collect();
    grid.rebuild_parts(
        &tables,
        |(c, _)| c.len(),
        |(c, s), i| {
            let (c, s, k) = (&c[i], &s[i], &kinds[c[i].kind]);
            Neighbour {
                position: s.position,
                velocity: s.velocity,
                radius: k.radius_m,
                mass: k.mass_kg,
                serial: c.serial,
            }
        },
    );
}

/// A grid sized for the court and the largest creature's reach.
pub(crate) fn size_grid(mut commands: Commands, config: Res<SimConfig>) {
    let cell_m = config
        .kinds
        .iter()
        .map(|k| k.steering.separation_distance_m.max(4.0 * k.body.radius_m))
        .fold(0.5, f32::max);
    commands.insert_resource(NeighbourGrid::new(config.arena.half_extents(), cell_m));
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    // The index of the creatures as placed, for the rules that give each its first level.
    app.add_systems(SimStart, (size_grid, index_creatures).chain().in_set(StartStage::Index))
        .add_systems(schedule, index_creatures.in_set(SimStage::Sense));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f32, y: f32, serial: u32) -> Neighbour {
        Neighbour {
            position: Vec2::new(x, y),
            serial,
            radius: 0.5,
            ..EMPTY
        }
    }

    #[test]
    fn an_index_built_in_ranges_across_the_cores_visits_cell_by_cell_in_serial_order_whatever_the_input_order() {
        bevy::tasks::ComputeTaskPool::get_or_init(bevy::tasks::TaskPool::default);
        let mut grid = NeighbourGrid::new(Vec2::new(60.0, 40.0), 1.5);
        // A crowd above the parallel size, scattered by a fixed hash, some sharing cells.
        let items: Vec<_> = (0..6000u32)
            .map(|i| {
                let h = i.wrapping_mul(2_654_435_761);
                at(
                    (h % 1200) as f32 / 10.0 - 60.0,
                    (h / 1200 % 800) as f32 / 10.0 - 40.0,
                    i,
                )
            })
            .collect();
        // Given out of serial order, as the tables may hold them.
        let mut shuffled = items.clone();
        shuffled.sort_by_key(|n| n.serial.wrapping_mul(40_503) % 6007);
        grid.rebuild(shuffled.into_iter());
        for (k, p) in [
            (0, Vec2::ZERO),
            (1, Vec2::new(-59.0, 39.0)),
            (2, Vec2::new(30.3, -12.7)),
        ] {
            let mut found = Vec::new();
            grid.for_each_within(p, 4.0, |n| found.push(n.serial));
            // Row by row, cell by cell, and in serial order within a cell.
            let cell = |n: &Neighbour| {
                let (x, y) = grid.cell_xy(n.position);
                (y, x)
            };
            let mut want: Vec<&Neighbour> = items.iter().filter(|n| n.position.distance(p) <= 4.0).collect();
            want.sort_by_key(|n| (cell(n), n.serial));
            let want: Vec<u32> = want.iter().map(|n| n.serial).collect();
            assert!(!want.is_empty(), "query {k}");
            assert_eq!(found, want, "query {k}");
        }
    }

    #[test]
    fn nearest_first_visits_each_entry_once_ring_by_ring_until_told_to_stop() {
        let mut grid = NeighbourGrid::new(Vec2::new(10.0, 10.0), 1.5);
        let items: Vec<_> = (0..400)
            .map(|i| at((i % 20) as f32 - 9.5, (i / 20) as f32 - 9.5, i))
            .collect();
        grid.rebuild(items.iter().copied());
        let within = |r: f32| -> Vec<u32> {
            let mut want: Vec<u32> = items
                .iter()
                .filter(|n| n.position.length() <= r)
                .map(|n| n.serial)
                .collect();
            want.sort();
            want
        };
        let search = |stop_at: f32| {
            let (mut found, mut rings) = (Vec::new(), Vec::new());
            grid.for_each_nearest_first(
                Vec2::ZERO,
                1.0,
                9.0,
                |n| found.push(n.serial),
                |ring| {
                    rings.push(ring);
                    ring >= stop_at
                },
            );
            found.sort();
            (found, rings)
        };
        // Never told to stop: everything within the radius, once; rings 1, 2, 4, 8 (then 9).
        let (found, rings) = search(f32::INFINITY);
        assert_eq!(found, within(9.0));
        assert_eq!(rings, [1.0, 2.0, 4.0, 8.0]);
        // Told to stop after the ring of 4 m: exactly what lies within it.
        assert_eq!(search(4.0).0, within(4.0));
        assert_eq!(grid.fastest_and_widest(), (0.0, 0.5));
    }

    #[test]
    fn query_finds_exactly_the_entries_within_the_radius() {
        let mut grid = NeighbourGrid::new(Vec2::new(10.0, 10.0), 1.5);
        let items: Vec<_> = (0..400)
            .map(|i| at((i % 20) as f32 - 9.5, (i / 20) as f32 - 9.5, i))
            .collect();
        grid.rebuild(items.iter().copied());
        for p in [Vec2::ZERO, Vec2::new(9.9, -9.9), Vec2::new(-3.2, 4.7)] {
            for r in [0.3, 1.0, 2.5, 6.0] {
                let mut found: Vec<u32> = Vec::new();
                grid.for_each_within(p, r, |n| found.push(n.serial));
                found.sort();
                let want: Vec<u32> = items
                    .iter()
                    .filter(|n| n.position.distance(p) <= r)
                    .map(|n| n.serial)
                    .collect();
                assert_eq!(found, want, "p {p} r {r}");
            }
        }
    }

    #[test]
    fn points_outside_the_court_fall_into_edge_cells() {
        let mut grid = NeighbourGrid::new(Vec2::new(2.0, 2.0), 1.0);
        grid.rebuild([at(5.0, 5.0, 1)].into_iter());
        let mut n = 0;
        grid.for_each_within(Vec2::new(4.5, 4.5), 1.0, |_| n += 1);
        assert_eq!(n, 1);
        assert!((grid.clearance(Vec2::new(5.0, 3.0), 10.0) - 1.5).abs() < 1e-6);
    }
}
