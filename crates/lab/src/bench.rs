//! `simlod bench`: the paper's Table 1 unit (cost per creature per 1/30 s of motion) and
//! figure 7's question (how many creatures hold 30 frames a second), headless.
//!
//! A bench world is the scenario scaled to a creature count: the same mix of kinds, the court
//! grown to keep the scenario's density, so the work per creature (neighbours met, walls
//! nearby) stays what the game has. One frame is 1/30 s of motion (one steering decision's
//! ticks). Figures are medians over frames, measured in one process.

pub use crate::scene::scaled;
use serde::Serialize;
use std::time::Instant;

use simlod::config::{CostModel, CrowdShares, KindCosts, LevelCosts, RigidShare, SimConfig};
use simlod::creature::KindTable;
use simlod::headless::HeadlessSim;
use simlod::kind::Creature;
use simlod::lod::{BudgetTally, LevelPolicy, Lod, SwitchTally};

/// Wall-clock budget of one frame at 30 fps.
const FRAME_BUDGET_S: f64 = 1.0 / 30.0;

/// What `simlod bench --json` prints, one object per level.
#[derive(Clone, Debug, Serialize)]
pub struct LevelBench {
    /// The level measured.
    #[serde(serialize_with = "level_name")]
    pub level: Lod,
    /// Median wall time per creature per 1/30 s of motion, at `reference_creatures`.
    pub us_per_creature_per_frame: f64,
    /// The creature count the cost per creature was measured at.
    pub reference_creatures: u32,
    /// Median wall time of a whole frame at `reference_creatures`.
    pub frame_ms_median: f64,
    /// The most creatures whose median frame fits in 1/30 s (within the search's 3 %).
    pub max_creatures_30fps: u32,
    /// Frames measured per run.
    pub frames: usize,
    /// Runs the reference figures are the median of.
    pub runs: usize,
}

fn level_name<S: serde::Serializer>(level: &Lod, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(level.name())
}

/// The middle value (the upper one of an even count); `values` must not be empty.
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// Median frame time in seconds of `config`, after a warm-up.
pub fn median_frame_seconds(config: SimConfig, warmup: usize, frames: usize) -> f64 {
    median_frame_seconds_of(&mut HeadlessSim::new(config), warmup, frames)
}

/// Median frame time in seconds of a world already built, after a warm-up.
pub fn median_frame_seconds_of(sim: &mut HeadlessSim, warmup: usize, frames: usize) -> f64 {
    play_on(sim, warmup);
    median((0..frames).map(|_| timed_frame(sim)).collect())
}

/// `frames` frames of `sim`, untimed.
fn play_on(sim: &mut HeadlessSim, frames: usize) {
    for _ in 0..frames {
        sim.advance_frame();
    }
}

/// One frame of `sim`, in seconds of wall time.
fn timed_frame(sim: &mut HeadlessSim) -> f64 {
    let start = Instant::now();
    sim.advance_frame();
    start.elapsed().as_secs_f64()
}

/// How much longer a frame of `sim` takes than a frame of `beside`, the two worlds stepped a
/// frame each in turn: the median, in seconds. This machine runs fast and slow by spells of a
/// fraction of a second, longer than a frame: a frame and its neighbour share the spell, so it
/// cancels, where two figures taken apart differ by it.
fn median_extra_seconds(sim: &mut HeadlessSim, beside: &mut HeadlessSim, warmup: usize, frames: usize) -> f64 {
    for _ in 0..warmup {
        sim.advance_frame();
        beside.advance_frame();
    }
    median((0..frames).map(|_| timed_frame(sim) - timed_frame(beside)).collect())
}

/// The scenario `sim` plays, as it stands.
fn played(sim: &HeadlessSim) -> &SimConfig {
    sim.app.world().resource::<SimConfig>()
}

/// The scenario `sim` plays, to change as it plays (read at every steering decision).
fn playing(sim: &mut HeadlessSim) -> bevy::prelude::Mut<'_, SimConfig> {
    sim.app.world_mut().resource_mut::<SimConfig>()
}

/// The median over `runs` fresh runs of their median frame times: one run's figure moves
/// with whatever else the machine was doing while it ran.
fn median_of_runs(config: &SimConfig, runs: usize, warmup: usize, frames: usize) -> f64 {
    median(
        (0..runs)
            .map(|_| median_frame_seconds(config.clone(), warmup, frames))
            .collect(),
    )
}

/// What `simlod bench --json` prints for the budget policy's choice, one object per way timed.
#[derive(Clone, Debug, Serialize)]
pub struct ChoiceBench {
    /// The scenario's mix scaled to this many creatures, its court to the same density.
    pub creatures: u32,
    /// The frame budget the choice was made under, ms (`null`: room for every step).
    pub frame_budget_ms: Option<f32>,
    /// Whether creatures were searched for contacts with the others (the rules' weight of
    /// such a contact); without, the choice's work for every creature alone.
    pub searches: bool,
    /// Median wall time of one choice per creature, us: a choice is made each 1/30 s.
    pub us_per_creature_per_frame: f64,
    /// Creatures searched for contacts in a choice.
    pub searched: usize,
    /// Choices timed.
    pub choices: usize,
}

/// The budget policy's choice in the scenario's mix of `creatures`, after `warmup` frames of
/// play under each of `budgets_ms` (the scenario's rules and cost model): timed `choices` times
/// at that moment (`choice_now`, not applied, so each is the same choice) as it plays there, its
/// searches those whose last search no longer stands (at a tight budget, the quiet creatures
/// left to their groups); and after the last, with room for every step and no searches (each
/// creature's bounds, steps and the knapsack over them all: what `--calibrate` times).
fn choice_bench(
    config: &SimConfig,
    creatures: u32,
    budgets_ms: &[f32],
    (warmup, choices): (usize, usize),
) -> Vec<ChoiceBench> {
    let weight = config.rules.budget.creature_weight;
    let mut benches = Vec::new();
    for (i, &budget_ms) in budgets_ms.iter().enumerate() {
        let mut game = scaled(config, creatures, LevelPolicy::Budget);
        (game.rules.budget.frame_budget_ms, game.rules.budget.adaptive_frames) = (budget_ms, 0.0);
        let mut sim = HeadlessSim::new(game);
        play_on(&mut sim, warmup);
        let last = i + 1 == budgets_ms.len();
        let timings = std::iter::once((Some(budget_ms), weight)).chain(last.then_some((None, 0.0)));
        for (frame_budget_ms, creature_weight) in timings {
            let budget_ms = frame_budget_ms.unwrap_or(f32::MAX);
            let (us, searched) = timed_choice(&mut sim, budget_ms, creature_weight, choices);
            benches.push(ChoiceBench {
                creatures,
                frame_budget_ms,
                searches: creature_weight > 0.0,
                us_per_creature_per_frame: us / f64::from(creatures.max(1)),
                searched,
                choices,
            });
        }
    }
    benches
}

/// How hard one level is measured.
struct Effort {
    /// The creature count the cost per creature is measured at.
    reference: u32,
    /// The first count tried when searching for the most at 30 fps.
    search_from: u32,
    warmup: usize,
    frames: usize,
    /// Fresh runs the reference figures are the median of.
    runs: usize,
    search_steps: u32,
}

fn bench_level(config: &SimConfig, level: Lod, policy: LevelPolicy, effort: &Effort) -> LevelBench {
    let frame_s = median_of_runs(
        &scaled(config, effort.reference, policy),
        effort.runs,
        effort.warmup,
        effort.frames,
    );
    // Each count tried is the median of fresh runs too: the machine's slow spells last seconds,
    // and one run caught in one would stop the search short.
    let good = most_within_budget(effort.search_from, effort.search_steps, |n| {
        median_of_runs(
            &scaled(config, n, policy),
            effort.runs,
            effort.warmup / 2,
            effort.frames,
        )
    });
    LevelBench {
        level,
        us_per_creature_per_frame: frame_s * 1e6 / f64::from(effort.reference),
        reference_creatures: effort.reference,
        frame_ms_median: frame_s * 1e3,
        max_creatures_30fps: good,
        frames: effort.frames,
        runs: effort.runs,
    }
}

/// The most creatures whose frame, `frame_s(n)` seconds, fits in 1/30 s: doubles from
/// `search_from` until a count misses the budget, then halves the gap (at most `steps` times,
/// to within 3 %).
pub fn most_within_budget(search_from: u32, steps: u32, mut frame_s: impl FnMut(u32) -> f64) -> u32 {
    let mut fits = |n: u32| frame_s(n) <= FRAME_BUDGET_S;
    let (mut good, mut bad) = (0u32, search_from.max(1));
    while bad < simlod::config::MAX_CREATURES && fits(bad) {
        good = bad;
        bad = (bad * 2).min(simlod::config::MAX_CREATURES);
    }
    for _ in 0..steps {
        if bad - good <= good / 32 + 1 {
            break;
        }
        let mid = good + (bad - good) / 2;
        if fits(mid) { good = mid } else { bad = mid }
    }
    good
}

/// The scenario with only the kinds that have a model at `level`.
fn kinds_with(config: &SimConfig, level: Lod) -> SimConfig {
    let kinds = KindTable::of(config);
    let mut c = config.clone();
    c.scenario.creatures.retain(|g| {
        g.count > 0
            && config
                .kind_index(&g.kind)
                .is_some_and(|kind| kinds[kind].levels.contains(&level))
    });
    c
}

/// Runs the benchmark for every level (or `only` one) and prints it.
pub fn run(config: &SimConfig, quick: bool, json: bool, only: Option<Lod>) {
    let scale = |full: u32| if quick { (full / 5).max(1) } else { full };
    let (warmup, frames, runs, search_steps) = if quick { (10, 15, 1, 3) } else { (30, 45, 3, 6) };
    let levels = [
        (Lod::PointMass, LevelPolicy::AllPointMass, scale(10_000), 1000),
        (Lod::Hybrid, LevelPolicy::AllHybrid, scale(10_000), 1000),
        (Lod::Rigid, LevelPolicy::AllRigid, scale(100), 16),
    ];
    if !json {
        println!(
            "simlod bench: frames of 1/30 s, the median over {runs} runs of each run's median of {frames} frames (each count the search for the most at 30 fps tries, too), in one process; court scaled to the scenario's density"
        );
    }
    let mut results = Vec::new();
    for (level, policy, reference, search_from) in levels.into_iter().filter(|l| only.is_none_or(|o| o == l.0)) {
        let effort = Effort {
            reference,
            search_from,
            warmup,
            frames,
            runs,
            search_steps,
        };
        let level_config = kinds_with(config, level);
        if level_config.scenario.creatures.is_empty() {
            if !json {
                println!(
                    "{:<11} skipped: no creature of the scenario has a model at this level",
                    level.name()
                );
            }
            continue;
        }
        let b = bench_level(&level_config, level, policy, &effort);
        if json {
            println!("{}", serde_json::to_string(&b).expect("a bench result serialises"));
        } else {
            println!(
                "{:<11} {:>9.3} us per creature per frame ({:.2} ms a frame at {}); most creatures at 30 fps: {}",
                b.level.name(),
                b.us_per_creature_per_frame,
                b.frame_ms_median,
                b.reference_creatures,
                b.max_creatures_30fps
            );
        }
        results.push(b);
    }
    let cost = |level: Lod| {
        results
            .iter()
            .find(|b| b.level == level)
            .map(|b| b.us_per_creature_per_frame)
    };
    for cheaper in [Lod::Hybrid, Lod::PointMass] {
        if let (Some(rigid), Some(cheap)) = (cost(Lod::Rigid), cost(cheaper)) {
            let cheaper = cheaper.name();
            let ratio = rigid / cheap;
            if json {
                println!(
                    "{}",
                    serde_json::json!({ "ratio": format!("rigid/{cheaper}"), "cost_per_creature": ratio })
                );
            } else {
                println!("a rigid creature costs {ratio:.0} times a {cheaper} one");
            }
        }
    }
    if only.is_none() {
        game_speedup(config, runs, warmup, frames, json);
        run_choice(config, quick, json);
    }
}

/// Times the budget policy's choice among 100,000 creatures (a fifth `quick`) at 10 and 30 ms
/// and prints it (see `choice_bench`).
pub fn run_choice(config: &SimConfig, quick: bool, json: bool) {
    let (creatures, effort) = if quick { (20_000, (10, 15)) } else { (100_000, (30, 45)) };
    for choice in choice_bench(config, creatures, &[10.0, 30.0], effort) {
        if json {
            println!("{}", serde_json::to_string(&choice).expect("a bench result serialises"));
        } else {
            let how = match choice.frame_budget_ms {
                Some(b) => format!("as it plays under a {b} ms budget ({} searched)", choice.searched),
                None => "with room for every step, no searches".to_owned(),
            };
            println!(
                "the budget's choice among {} creatures, {how}: {:.3} us per creature per frame",
                choice.creatures, choice.us_per_creature_per_frame
            );
        }
    }
}

/// The scenario's own game under the influence policy against the identical game all rigid
/// (the saving the paper's figure 8 measures).
fn game_speedup(config: &SimConfig, runs: usize, warmup: usize, frames: usize, json: bool) {
    let frame_ms = |policy: LevelPolicy| {
        let mut c = config.clone();
        c.scenario.level_policy = policy;
        median_of_runs(&c, runs, warmup, frames) * 1e3
    };
    let (influence, rigid) = (frame_ms(LevelPolicy::Influence), frame_ms(LevelPolicy::AllRigid));
    let creatures = config.scenario.creature_count();
    if json {
        for (policy, ms) in [("influence", influence), ("all_rigid", rigid)] {
            println!(
                "{}",
                serde_json::json!({ "game": creatures, "policy": policy, "frame_ms_median": ms })
            );
        }
        println!(
            "{}",
            serde_json::json!({ "game": creatures, "speedup": "all_rigid/influence", "ratio": rigid / influence })
        );
    } else {
        println!(
            "the scenario's game ({creatures} creatures): {influence:.2} ms a frame under the influence policy, {rigid:.2} ms all rigid: {:.1} times faster",
            rigid / influence
        );
    }
}

/// How hard [`calibrate`] measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Calibration {
    /// `simlod bench --calibrate`: every figure the median of three passes over all of them
    /// (about 10 s here).
    Full,
    /// The game's start-up (`frame_budget.calibrate_at_start` in `game.ron`): three shorter
    /// passes, then the shares in the crowd that plays, `creatures` of the scenario's mix (see
    /// `in_the_crowd_that_plays`): about 1.3 s here for the default game, 2 s for 3,000
    /// creatures. Each figure from 8 frames after 8 of warm-up, not 20 after 20: in the same
    /// hour (three runs of each, 2026-11-29), games played by either kept as near their
    /// prediction (the default game at 4 ms, 1.05 and 1.05 times it; 3,000 creatures at 10
    /// ms, 0.93 and 0.85), and the calibration took 1.3 s against 2.9, 2.2 against 4.2.
    AtStartUp {
        /// The creatures the game plays, the scenario's mix scaled as [`scaled`] does.
        creatures: u32,
    },
    /// One short pass (`--quick`): a rough figure in half a second.
    Quick,
}

/// `simlod bench --calibrate`: the budget policy's cost model from measured medians. First the
/// fixed cost of a frame: the scenario's court and puck without creatures. Then for each kind
/// of the scenario alone, in a court scaled to its density: what each level's frame takes over
/// a court without creatures stepped beside it (see `median_extra_seconds`), divided
/// by the creatures (fewer than [`simlod::PARALLEL_MIN_CREATURES`], so one thread, as in a
/// game), and the switch into the rigid level (see `switch_cost_us`). A kind without an entry
/// is predicted at the dearest calibrated kind's costs. Then the budget policy's own choice
/// (see `choice_cost_us`, `choice_in_play_us`); last, the rigid level in play as shares of its
/// figures by the count of rigid creatures (see `rigid_in_play`), and the cheap levels' cost
/// per creature in a crowd stepped across the cores, as shares of their cost on one thread
/// (both, at start-up, in the crowd that plays: see `in_the_crowd_that_plays`).
pub fn calibrate(config: &SimConfig, how: Calibration) -> CostModel {
    match how {
        Calibration::AtStartUp { creatures } => in_the_crowd_that_plays(config, passes(config, how), creatures).0,
        Calibration::Full | Calibration::Quick => passes(config, how),
    }
}

/// Whole passes over every figure, each figure the median of the passes': a pass takes a few
/// seconds, and this machine has slow spells as long (rigid creatures and the fixed cost
/// measured a third dearer throughout one calibration, and not in the next).
fn passes(config: &SimConfig, how: Calibration) -> CostModel {
    let passes = match how {
        Calibration::Full | Calibration::AtStartUp { .. } => 3,
        Calibration::Quick => 1,
    };
    median_model(&(0..passes).map(|_| calibrate_pass(config, how)).collect::<Vec<_>>())
}

/// The cost model measured as the game measures it at start-up, in the crowd of `config`'s
/// scenario, and what it says: how long it took, its lines and what of it is the file's, for a
/// log or a terminal.
pub fn calibrate_at_start_up(config: &SimConfig) -> (CostModel, String) {
    let start = Instant::now();
    let creatures = config.scenario.creature_count();
    let how = Calibration::AtStartUp { creatures };
    let (model, kept) = in_the_crowd_that_plays(config, passes(config, how), creatures);
    let mut said = format!(
        "measured in {:.1} s (us per creature per 1/30 s):",
        start.elapsed().as_secs_f32()
    );
    for line in cost_model_lines(&model).iter().chain(&kept) {
        said += &format!("\n  {line}");
    }
    (model, said)
}

/// The creatures of the scenario's mix a level's cost on one thread is measured among, below a
/// crowd (see [`simlod::PARALLEL_MIN_CREATURES`]).
const BELOW_A_CROWD: u32 = 2000;

/// The counts of rigid creatures the rigid level's shares in play are measured at.
const RIGID_COUNTS: [u32; 5] = [10, 40, 160, 400, 800];

/// Microseconds a frame of `count` creatures of `config` all under `policy` takes over a court
/// without creatures stepped beside it, per creature.
fn per_creature_us(config: &SimConfig, count: u32, policy: LevelPolicy, effort: (usize, usize)) -> f64 {
    let mut world = HeadlessSim::new(scaled(config, count, policy));
    extra_us_per_creature(&mut world, &mut HeadlessSim::new(scaled(config, 0, policy)), effort)
}

/// Microseconds a frame of `sim` takes over a frame of `beside` (see
/// [`median_extra_seconds`]), per creature of `sim`.
fn extra_us_per_creature(sim: &mut HeadlessSim, beside: &mut HeadlessSim, (warmup, frames): (usize, usize)) -> f64 {
    let count = played(sim).scenario.creature_count();
    (median_extra_seconds(sim, beside, warmup, frames) * 1e6).max(0.0) / f64::from(count.max(1))
}

/// The game's start-up: `model`'s shares in the crowd that plays, `creatures` of the scenario's
/// mix. Where it is a crowd, the cheap levels' and the choice's (see [`crowd_shares`]); else the
/// file's, for a crowd a new round may bring. Then the rigid level's in play in that crowd (see
/// [`rigid_in_play`]) at each count of [`RIGID_COUNTS`] up to the first the rules' budget
/// holds, from the first whose rigid creatures are a fair part of the frame; none, the file's
/// kept, where the crowd's floors are over that budget. Kept from a file
/// measured on another machine, these shares priced 100,000 point masses at three quarters of
/// what they ran, and 350 rigid creatures among 4,000 at 0.57 (2026-11-29).
fn in_the_crowd_that_plays(config: &SimConfig, mut model: CostModel, creatures: u32) -> (CostModel, Option<String>) {
    let effort = (12, 8);
    let mut crowd = under_the_budget(config, creatures, &model);
    let budget_ms = config.rules.budget.frame_budget_ms;
    let in_a_crowd = creatures >= simlod::PARALLEL_MIN_CREATURES;
    let beyond_the_floors = if in_a_crowd {
        let (shares, beyond) = crowd_shares(config, &model, &mut crowd, Some(budget_ms), effort);
        (model.crowd_shares, model.larger_crowd_shares) = (Some(shares), Vec::new());
        beyond
    } else {
        (model.crowd_shares, model.larger_crowd_shares) =
            (config.costs.crowd_shares, config.costs.larger_crowd_shares.clone());
        affords_more_than_the_floors(&mut crowd, &model, budget_ms)
    };
    if !beyond_the_floors {
        // No creature of such a crowd is rigid at that budget: the file's rigid shares stand.
        model.rigid_shares = config.costs.rigid_shares.clone();
        let what = if in_a_crowd {
            "the hybrid's and the choice's crowd shares and the rigid level's shares"
        } else {
            "the crowd shares and the rigid level's shares"
        };
        let kept = format!(
            "its floors over the {budget_ms} ms budget, where it plays: {what} from the file (1 and none without one), not measured"
        );
        return (model, Some(kept));
    }
    model.rigid_shares = Vec::new();
    let [point_mass, hybrid, rigid_us] = mix_us(played(&crowd), &model, 0);
    let rest_us = f64::from(model.overhead_us(creatures as usize)) + f64::from(creatures) * point_mass.max(hybrid);
    let holds = (f64::from(config.rules.budget.frame_budget_ms) * 1e3 - rest_us) / rigid_us.max(1e-9);
    let mut counts: Vec<u32> = RIGID_COUNTS
        .iter()
        .map(|&r| r.min(creatures))
        .filter(|&r| r > 0)
        .collect();
    counts.dedup();
    // A count whose rigid creatures are under half the rest of the frame measures the rest's
    // spread more than them (among 100,000 creatures, 16 rigid ones came out at 0.01 of their
    // figure, and 11 at 5.8, 2026-11-29): the counts start at the first over it.
    let last = counts.len().saturating_sub(1);
    let first = (counts.iter().position(|&r| f64::from(r) * rigid_us >= rest_us / 2.0)).map_or(last, |i| i.min(last));
    let needed = counts
        .iter()
        .position(|&r| f64::from(r) >= holds)
        .map_or(counts.len(), |i| i + 1);
    let counts = &counts[first..needed.max(first + 1).min(counts.len())];
    model.rigid_shares = rigid_shares(config, &model, counts, Some(&mut crowd), effort);
    let kept = (!in_a_crowd)
        .then(|| "no crowd: the crowd shares, for a crowd a new round may bring, from the file, not measured".into());
    (model, kept)
}

/// The rigid level's shares in play (see [`rigid_in_play`]) with room for each of `counts`
/// rigid creatures, among the `crowd` given, else in a world of their own of four times as
/// many creatures of the scenario's mix; by how many were rigid. One that came out under half
/// its room is left out: a crowd climbs from its floors a few tens of creatures a frame, and
/// among 2,548 creatures with room for ten rigid ones, one was rigid and its share came out
/// at 10, the most a share may be (2026-12-01); the model's figure is nearer. The file
/// requires the counts rising: one that came out no more than the one before is left out too.
fn rigid_shares(
    config: &SimConfig,
    model: &CostModel,
    counts: &[u32],
    mut crowd: Option<&mut HeadlessSim>,
    effort: (usize, usize),
) -> Vec<RigidShare> {
    let mut shares: Vec<RigidShare> = Vec::new();
    for &count in counts {
        let (rigid, share) = match crowd.as_deref_mut() {
            Some(crowd) => rigid_in_play(crowd, model, count, effort),
            None => {
                let mut own = under_the_budget(config, 4 * count, model);
                rigid_in_play(&mut own, model, count, effort)
            }
        };
        if 2 * rigid >= count && shares.last().is_none_or(|fewer| rigid > fewer.rigid) {
            shares.push(RigidShare { rigid, share });
        }
    }
    shares
}

/// The cheap levels' and the choice's shares in `crowd` (see [`under_the_budget`], not yet
/// played), stepped across the cores, of `model`'s figures (measured among [`BELOW_A_CROWD`],
/// on one thread). Two worlds of the crowd play on through every figure, where one
/// for each once did (building 100,000 creatures takes 0.15 s, and a world's first frames are
/// its slowest): one at each cheap level in turn, going up (a crowd's hybrids sent down at
/// once make its slowest frames), then `crowd` under the budget, from its floors up (where no
/// step fits, the budget keeps cheap levels as they are). Each level's crowd figure is taken
/// right after the one-thread figure it is a share of: taken apart, a slow spell of the
/// machine under one of them moved the share by a third. That one-thread figure is the
/// noisier (0.050 to 0.077 us a point mass in four start-ups of 40,000 within minutes, where
/// the crowd's ran 0.055 to 0.066), yet shares of the model's own figures in its place priced
/// crowds at their floors 1.18 to 1.38 times under what they ran in 7 of 11 games, where these
/// were within 10 % in 8 of 10 the same hour (2026-12-01). The choice's is of the choice in
/// play at that size (see [`choice_in_play_us`]): what it does
/// beside the choice itself (writing the levels, the switch stage's passes) is a smaller part
/// of it there. Taken by the choice alone's share, the model charged 40,000 creatures at 30 ms
/// about 13 ms too much a frame (2026-11-28). Where only the floors fit, the crowd's frames
/// beyond what the model says of the rest of them, as the choice in play: timed against the
/// same crowd under a fixed policy stepped beside it, the frames of 40,000 creatures at their
/// floors ran 1.1 to 1.5 times their prediction in six runs of an hour (2026-11-29). The rigid
/// level's share is left at 1. The floors are measured first: where they are over `budget_ms`
/// (the budget the crowd plays at, see [`affords_more_than_the_floors`]; false beside the
/// shares), the hybrid's and the choice's shares are the file's.
fn crowd_shares(
    config: &SimConfig,
    model: &CostModel,
    crowd: &mut HeadlessSim,
    budget_ms: Option<f32>,
    (warmup, frames): (usize, usize),
) -> (CrowdShares, bool) {
    let count = played(crowd).scenario.creature_count();
    let share = |crowd: f64, alone: f64| (crowd / alone.max(1e-9)).clamp(0.01, 10.0) as f32;
    let (mut levels, mut court) = (
        HeadlessSim::new(scaled(config, count, LevelPolicy::AllPointMass)),
        HeadlessSim::new(scaled(config, 0, LevelPolicy::AllPointMass)),
    );
    let mut level_share = |levels: &mut HeadlessSim, policy| {
        let alone = per_creature_us(config, BELOW_A_CROWD, policy, (warmup, frames));
        share(extra_us_per_creature(levels, &mut court, (warmup, frames)), alone)
    };
    let point_mass = level_share(&mut levels, LevelPolicy::AllPointMass);
    // The choice alone, among point masses: with room for every step, its work is the same
    // whatever the model's figures.
    let alone = choice_cost_us(&mut levels, model, frames.div_ceil(3), false);
    // Until measured, the file's (1 where it has none).
    let file = config.costs.shares_in_crowd(count);
    let mut shares = CrowdShares {
        creatures: count,
        point_mass,
        hybrid: file.map_or(1.0, |s| s.hybrid),
        choice: file.map_or(1.0, |s| s.choice),
        floors_only: 1.0,
        rigid: 1.0,
    };
    // The choice's figures in the crowd beside its levels at their shares there.
    let mut at_count = CostModel {
        crowd_shares: Some(shares),
        larger_crowd_shares: Vec::new(),
        ..model.clone()
    };
    let floors_us = in_play(crowd, &at_count, 0.0, (warmup, frames)).beyond_the_cheap_us_per_creature(count);
    shares.floors_only = share(floors_us, f64::from(model.floors_only_us_per_creature));
    at_count.crowd_shares = Some(shares);
    // A crowd whose floors are over the rules' budget plays at its floors: the rest of its
    // figures would price levels it never reaches (at the shipped 4 ms, from about 40,000
    // creatures; 100,000 took 7 s to measure them all, 2026-12-02).
    if budget_ms.is_some_and(|budget_ms| !affords_more_than_the_floors(crowd, &at_count, budget_ms)) {
        return (shares, false);
    }
    // The warm-up is the crowd's switch: those out of view at once, the rest in their next
    // flight window.
    playing(&mut levels).scenario.level_policy = LevelPolicy::AllHybrid;
    shares.hybrid = level_share(&mut levels, LevelPolicy::AllHybrid);
    drop(levels);
    at_count.crowd_shares = Some(shares);
    // Long enough for half the crowd to climb to the hybrid level (the switches are priced,
    // so they come a few hundred a frame).
    let in_play = choice_in_play_us(crowd, &at_count, alone.per_creature_us, (warmup.max(30), frames));
    shares.choice = share(in_play, f64::from(model.decision_us_per_creature));
    (shares, true)
}

/// Whether `sim`'s crowd as it stands, priced by `model`, costs less at its floors than
/// `budget_ms` (the budget policy's choice, not applied): if not, it plays at its floors.
fn affords_more_than_the_floors(sim: &mut HeadlessSim, model: &CostModel, budget_ms: f32) -> bool {
    let mut game = playing(sim);
    (game.costs, game.rules.budget.frame_budget_ms) = (model.clone(), budget_ms);
    simlod::lod::choice_now(sim.app.world_mut()).is_some_and(|a| !a.exceeded)
}

/// One pass of [`calibrate`]: every figure measured once.
fn calibrate_pass(config: &SimConfig, how: Calibration) -> CostModel {
    let (warmup, frames, cheap_count, rigid_count) = match how {
        Calibration::Full => (30, 45, BELOW_A_CROWD, 30),
        Calibration::AtStartUp { .. } => (8, 8, BELOW_A_CROWD, 8),
        Calibration::Quick => (10, 15, 400, 10),
    };
    let kinds = KindTable::of(config);
    // Cheap to measure: many frames, several runs.
    let fixed_us = median_of_runs(&scaled(config, 0, LevelPolicy::AllPointMass), 3, warmup, 5 * frames) * 1e6;
    let mut entries = Vec::new();
    for def in &config.kinds {
        let alone = crate::scene::only_kind(config, &def.name);
        let levels = &kinds[config.kind_index(&def.name).expect("a kind of the config")].levels;
        let mut us = [0.0f64; 3];
        for &level in levels {
            let (policy, count) = match level {
                Lod::PointMass => (LevelPolicy::AllPointMass, cheap_count),
                Lod::Hybrid => (LevelPolicy::AllHybrid, cheap_count),
                Lod::Rigid => (LevelPolicy::AllRigid, rigid_count),
            };
            us[level as usize] = per_creature_us(&alone, count, policy, (warmup, frames));
        }
        // A kind without a level is predicted at the next cheaper level it has.
        for l in 1..3 {
            if !levels.contains(&Lod::ALL[l]) {
                us[l] = us[l - 1];
            }
        }
        let switch_us = if levels.contains(&Lod::Rigid) {
            switch_cost_us(&alone, 4 * rigid_count, levels[levels.len() - 2])
        } else {
            0.0
        };
        let cheap_switch_us = if levels.contains(&Lod::PointMass) && levels.contains(&Lod::Hybrid) {
            cheap_switch_us(
                &alone,
                cheap_count,
                warmup,
                if how == Calibration::Full { 3 } else { 1 },
            )
        } else {
            0.0
        };
        entries.push(KindCosts {
            kind: def.name.clone(),
            costs: LevelCosts {
                point_mass_us_per_frame: us[0] as f32,
                hybrid_us_per_frame: us[1] as f32,
                rigid_us_per_frame: us[2] as f32,
                switch_to_rigid_us: switch_us as f32,
                cheap_switch_us: cheap_switch_us as f32,
            },
        });
    }
    let mut model = CostModel {
        other_kinds: dearest(&entries),
        kinds: entries,
        fixed_us_per_frame: fixed_us as f32,
        decision_us_per_creature: 0.0,
        floors_only_us_per_creature: 0.0,
        contact_search_us: 0.0,
        crowd_shares: None,
        larger_crowd_shares: Vec::new(),
        rigid_shares: Vec::new(),
    };
    // The choice timed among point masses, then in play in the same world.
    let mut choosing = HeadlessSim::new(scaled(config, cheap_count, LevelPolicy::AllPointMass));
    play_on(&mut choosing, warmup);
    let choice = choice_cost_us(&mut choosing, &model, frames, true);
    model.floors_only_us_per_creature = floors_only_us(config, &model, cheap_count, (warmup, frames)) as f32;
    model.contact_search_us = choice.search_us as f32;
    model.decision_us_per_creature =
        choice_in_play_us(&mut choosing, &model, choice.per_creature_us, (warmup.max(30), frames)) as f32;
    if let Calibration::AtStartUp { .. } = how {
        return model;
    }
    // The rigid level in play, among ten rigid creatures and among hundreds, in crowds of four
    // times as many; the warm-up long enough for the budget's creatures to reach their levels.
    let rigid_counts: &[u32] = match how {
        Calibration::Quick => &[10, 100],
        _ => &RIGID_COUNTS,
    };
    model.rigid_shares = rigid_shares(config, &model, rigid_counts, None, (warmup.max(30), frames));
    // The cheap levels and the choice in crowds stepped across the cores (a creature costs less
    // the larger the crowd: at 4,096 a point mass about its cost on one thread, at 65,536 two
    // thirds of it, 2026-11-27).
    let crowds: &[u32] = match how {
        Calibration::Quick => &[8 * simlod::PARALLEL_MIN_CREATURES],
        _ => &[2, 8, 32].map(|k| k * simlod::PARALLEL_MIN_CREATURES),
    };
    let rigid_among = match how {
        Calibration::Quick => 100,
        _ => 400,
    };
    // Only beyond twice the largest crowd the rigid shares were measured in: nearer, they hold
    // (the smallest crowd's share measured 0.84 to 1.33 in seven calibrations in an hour,
    // 2026-11-28, where they say 1).
    let largest = 4 * rigid_counts.last().copied().unwrap_or(0);
    let with_shares = |model: &mut CostModel, measured: &[CrowdShares]| {
        model.crowd_shares = measured.first().copied();
        model.larger_crowd_shares = measured[1..].to_vec();
    };
    let mut measured: Vec<CrowdShares> = Vec::new();
    for &count in crowds {
        let mut crowd = under_the_budget(config, count, &model);
        measured.push(crowd_shares(config, &model, &mut crowd, None, (warmup, frames)).0);
        with_shares(&mut model, &measured);
        // Then the rigid level in the same crowd, at its share among as many rigid creatures:
        // among tens of thousands it cost more than among four times the rigid ones (100,000
        // creatures at 30 ms ran 1.21 times the budget without it, 2026-11-27). The cheap
        // levels and the choice at their shares just measured.
        if count > 2 * largest {
            let (_, rigid) = rigid_in_play(&mut crowd, &model, rigid_among, (warmup.max(30), frames));
            measured.last_mut().expect("just measured").rigid = rigid;
            with_shares(&mut model, &measured);
        }
    }
    model
}

/// Each figure of `models` (the same kinds and crowds, in the same order) the median of theirs.
fn median_model(models: &[CostModel]) -> CostModel {
    let median_of =
        |figure: &dyn Fn(&CostModel) -> f32| median(models.iter().map(|m| f64::from(figure(m))).collect()) as f32;
    let costs_of = |costs: &dyn Fn(&CostModel) -> &LevelCosts| LevelCosts {
        point_mass_us_per_frame: median_of(&|m| costs(m).point_mass_us_per_frame),
        hybrid_us_per_frame: median_of(&|m| costs(m).hybrid_us_per_frame),
        rigid_us_per_frame: median_of(&|m| costs(m).rigid_us_per_frame),
        switch_to_rigid_us: median_of(&|m| costs(m).switch_to_rigid_us),
        cheap_switch_us: median_of(&|m| costs(m).cheap_switch_us),
    };
    let shares_of = |shares: &dyn Fn(&CostModel) -> &CrowdShares| CrowdShares {
        creatures: shares(&models[0]).creatures,
        point_mass: median_of(&|m| shares(m).point_mass),
        hybrid: median_of(&|m| shares(m).hybrid),
        choice: median_of(&|m| shares(m).choice),
        floors_only: median_of(&|m| shares(m).floors_only),
        rigid: median_of(&|m| shares(m).rigid),
    };
    let first = &models[0];
    let mut model = CostModel {
        kinds: (first.kinds.iter().enumerate())
            .map(|(i, k)| KindCosts {
                kind: k.kind.clone(),
                costs: costs_of(&|m| &m.kinds[i].costs),
            })
            .collect(),
        other_kinds: LevelCosts::default(),
        fixed_us_per_frame: median_of(&|m| m.fixed_us_per_frame),
        decision_us_per_creature: median_of(&|m| m.decision_us_per_creature),
        floors_only_us_per_creature: median_of(&|m| m.floors_only_us_per_creature),
        contact_search_us: median_of(&|m| m.contact_search_us),
        crowd_shares: first
            .crowd_shares
            .map(|_| shares_of(&|m| m.crowd_shares.as_ref().expect("every pass measures the same crowds"))),
        larger_crowd_shares: (0..first.larger_crowd_shares.len())
            .map(|i| shares_of(&|m| &m.larger_crowd_shares[i]))
            .collect(),
        rigid_shares: (0..first.rigid_shares.len())
            .map(|i| RigidShare {
                rigid: median_of(&|m| m.rigid_shares[i].rigid as f32) as u32,
                share: median_of(&|m| m.rigid_shares[i].share),
            })
            .collect(),
    };
    model.other_kinds = dearest(&model.kinds);
    model
}

/// What a kind without an entry is predicted at: the dearest calibrated kind's each cost.
fn dearest(kinds: &[KindCosts]) -> LevelCosts {
    let dearest = |f: fn(&LevelCosts) -> f32| kinds.iter().map(|k| f(&k.costs)).fold(0.0, f32::max);
    LevelCosts {
        point_mass_us_per_frame: dearest(|c| c.point_mass_us_per_frame),
        hybrid_us_per_frame: dearest(|c| c.hybrid_us_per_frame),
        rigid_us_per_frame: dearest(|c| c.rigid_us_per_frame),
        switch_to_rigid_us: dearest(|c| c.switch_to_rigid_us),
        cheap_switch_us: dearest(|c| c.cheap_switch_us),
    }
}

/// The budget policy's choice for the world as it stands under `budget_ms`, a contact with
/// another creature weighed `creature_weight`, timed `calls` times (not applied, so each is
/// the same choice): the median, us, and the creatures it searched.
fn timed_choice(sim: &mut HeadlessSim, budget_ms: f32, creature_weight: f32, calls: usize) -> (f64, usize) {
    let world = sim.app.world_mut();
    let mut config = world.resource_mut::<SimConfig>();
    (config.rules.budget.frame_budget_ms, config.rules.budget.creature_weight) = (budget_ms, creature_weight);
    let mut searched = 0;
    let us = median(
        (0..calls)
            .map(|_| {
                let start = Instant::now();
                searched = simlod::lod::choice_now(world).map_or(0, |a| a.settled.len());
                start.elapsed().as_secs_f64() * 1e6
            })
            .collect(),
    );
    (us, searched)
}

/// What the budget policy's own choice costs, microseconds: per creature without the search
/// for contacts between creatures, and per creature searched.
struct ChoiceCost {
    per_creature_us: f64,
    search_us: f64,
}

/// The budget policy's own choice, timed in `sim` as it stands: with room for every
/// creature's every step (so nothing is left out), without the search for contacts between
/// creatures (the creatures' weight at 0, so none needs it); and, `with_searches`, per creature
/// searched (else 0). The world's rules are left as they were, to play on.
fn choice_cost_us(sim: &mut HeadlessSim, model: &CostModel, calls: usize, with_searches: bool) -> ChoiceCost {
    let (count, rules) = (played(sim).scenario.creature_count(), played(sim).rules.budget.clone());
    // Every creature worked out: what the incremental choice saves on one it leaves quiet.
    (playing(sim).costs, playing(sim).rules.budget.incremental_choice) = (model.clone(), false);
    let mut time_choice = |creature_weight, budget_ms| timed_choice(sim, budget_ms, creature_weight, calls);
    let (unsearched_us, _) = time_choice(0.0, f32::MAX);
    let search_us = if with_searches {
        let (searched_us, searched) = time_choice(rules.creature_weight, f32::MAX);
        (searched_us - unsearched_us).max(0.0) / searched.max(1) as f64
    } else {
        0.0
    };
    playing(sim).rules.budget = rules;
    ChoiceCost {
        per_creature_us: unsearched_us / f64::from(count.max(1)),
        search_us,
    }
}

/// What a game under the budget policy took, frame by frame, against what the cost model
/// says of its parts.
struct InPlay {
    /// The frames' median, us.
    median_us: f64,
    /// The model's fixed cost, the searches for contacts and the levels below rigid, on
    /// average, us.
    cheap_us: f64,
    /// What the model says of the rigid creatures (at its share for as many) on average, us,
    /// and how many there were.
    rigid_us: f64,
    rigid: f64,
}

impl InPlay {
    /// What the frames took (their median) beyond the model's figures for the fixed cost, the
    /// searches and the cheap levels, per creature of `count`: the choice's part of a game
    /// without rigid creatures, so that the model's parts add up to the frame measured.
    fn beyond_the_cheap_us_per_creature(&self, count: u32) -> f64 {
        ((self.median_us - self.cheap_us) / f64::from(count.max(1))).max(0.0)
    }
}

/// The scenario's mix of `count` creatures under the budget policy, priced by `model`, with no
/// room yet: built so, for its first update already chooses (priced by a model still to be
/// measured, every figure 0, it made 40,000 creatures rigid, and their frames took seconds).
fn under_the_budget(config: &SimConfig, count: u32, model: &CostModel) -> HeadlessSim {
    let mut game = scaled(config, count, LevelPolicy::Budget);
    game.costs = model.clone();
    let budget = &mut game.rules.budget;
    (budget.frame_budget_ms, budget.adaptive_frames) = (0.0, 0.0);
    HeadlessSim::new(game)
}

/// `sim` played on under the budget policy at `room_us` a frame, priced by `model`, every
/// frame timed after a warm-up (long enough for its creatures to reach their levels), each
/// beside what `model` says of the levels its creatures ran at (read after the frame) and of
/// its searches.
fn in_play(sim: &mut HeadlessSim, model: &CostModel, room_us: f64, (warmup, frames): (usize, usize)) -> InPlay {
    let mut game = playing(sim);
    (game.scenario.level_policy, game.costs) = (LevelPolicy::Budget, model.clone());
    let budget = &mut game.rules.budget;
    (budget.frame_budget_ms, budget.adaptive_frames) = ((room_us / 1e3) as f32, 0.0);
    play_on(sim, warmup);
    let (mut measured, mut cheap_us, mut rigid_us, mut rigid) = (Vec::with_capacity(frames), 0.0, 0.0, 0u64);
    for _ in 0..frames {
        let searched_before = sim.app.world().resource::<BudgetTally>().searched;
        measured.push(timed_frame(sim) * 1e6);
        let world = sim.app.world_mut();
        let searched = world.resource::<BudgetTally>().searched - searched_before;
        cheap_us += f64::from(model.fixed_us_per_frame) + searched as f64 * f64::from(model.contact_search_us);
        let mut levels = world.query::<(&Creature, &Lod)>();
        let rigid_now = levels.iter(world).filter(|(_, lod)| **lod == Lod::Rigid).count();
        let costs = world.resource::<SimConfig>().costs_by_kind(rigid_now as u32);
        for (c, &lod) in levels.iter(world) {
            let us = f64::from(costs[c.kind].per_frame_us(lod));
            if lod == Lod::Rigid {
                (rigid_us, rigid) = (rigid_us + us, rigid + 1);
            } else {
                cheap_us += us;
            }
        }
    }
    let n = frames.max(1) as f64;
    InPlay {
        median_us: median(measured),
        cheap_us: cheap_us / n,
        rigid_us: rigid_us / n,
        rigid: rigid as f64 / n,
    }
}

/// What `model` says a creature of `game`'s mix costs at each level, `rigid` of them rigid.
fn mix_us(game: &SimConfig, model: &CostModel, rigid: u32) -> [f64; 3] {
    let game = SimConfig {
        costs: model.clone(),
        ..game.clone()
    };
    let costs = game.costs_by_kind(rigid);
    let count = game.scenario.creature_count();
    Lod::ALL.map(|level| {
        (game.scenario.creatures.iter().zip(&costs))
            .map(|(g, c)| f64::from(g.count) * f64::from(c.per_frame_us(level)))
            .sum::<f64>()
            / f64::from(count.max(1))
    })
}

/// The choice's cost per creature in play: `sim`'s crowd played on under the budget with room
/// for about half of it at the hybrid level and none rigid (the rigid level priced out of
/// reach, the choice charged at `alone_us`, the choice alone timed in that crowd), what
/// its frames take (their median) beyond what `model` says of the rest of them: the fixed
/// cost, the searches and the cheap levels at their shares in the crowd. Besides the choice
/// itself (`choice_now`), this is the writing of every creature's level, the switch stage's
/// passes, the switches between the cheap levels and a world of a table for each level: timed
/// as the choice alone, the cheap levels in a world of mixed levels ran about twice their
/// prediction at 4,000 creatures. Taken beyond the same crowd all point masses and all hybrid
/// stepped beside it, in place of the model's figures, it came out at a tenth of the choice
/// alone in crowds of tens of thousands, and the model priced 40,000 creatures' cheap frame at
/// 6.8 ms where it ran 12 (2026-11-29): three worlds of a crowd stepped in turn crowd each
/// other out of the caches, so the two beside were dearer than the model's figures for them.
/// Never less than `alone_us`.
fn choice_in_play_us(sim: &mut HeadlessSim, model: &CostModel, alone_us: f64, effort: (usize, usize)) -> f64 {
    let mut priced = model.clone();
    for k in &mut priced.kinds {
        k.costs.rigid_us_per_frame = 1e6;
    }
    priced.other_kinds.rigid_us_per_frame = 1e6;
    priced.decision_us_per_creature = alone_us as f32;
    for shares in priced.crowd_shares.iter_mut().chain(&mut priced.larger_crowd_shares) {
        shares.choice = 1.0;
    }
    let count = played(sim).scenario.creature_count();
    let [pm, hybrid, _] = mix_us(played(sim), &priced, 0);
    let room_us = f64::from(priced.overhead_us(count as usize)) + f64::from(count) * (pm + hybrid) / 2.0;
    // Every creature worked out, as in `choice_cost_us`.
    let incremental = std::mem::replace(&mut playing(sim).rules.budget.incremental_choice, false);
    let us = in_play(sim, &priced, room_us, effort).beyond_the_cheap_us_per_creature(count);
    playing(sim).rules.budget.incremental_choice = incremental;
    // The frames hold the choice itself, so what they take beyond the rest is never less than
    // the choice timed alone in the same crowd: a difference of two medians, it came out below
    // it in most calibrations, and at 0 to 0.08 of it in some, which priced a crowd's choice
    // as good as free (40,000 creatures at 4 ms ran 1.55 times the prediction, 2026-12-04).
    us.max(alone_us)
}

/// The rigid level's cost in play as a share of what `model` says of it (among four times as
/// many creatures as rigid ones, before any rigid share: its kinds' figures, which are measured
/// in open court, among a few tens of one kind): `sim`'s crowd played on under the budget
/// policy with room for about `rigid` rigid ones, those it picks (about to touch
/// something, or in view). The share is what its frames take (their median) beyond the rest of
/// what the model predicts of them (the fixed cost, the choice and its searches, the cheaper
/// levels), over what it predicts of the rigid creatures; with how many there were. Rapier
/// works through its contacts across the cores once it has more than 64 to update, so that a
/// rigid creature among a hundred or two costs about two thirds of one among tens; among more,
/// rapier's own work per body grows again (4,000 all rigid: 72 us a hopper or biped in its
/// stage against 47 among 443); and one about to touch something costs the solver more than
/// one in open court.
fn rigid_in_play(sim: &mut HeadlessSim, model: &CostModel, rigid: u32, effort: (usize, usize)) -> (u32, f32) {
    let count = played(sim).scenario.creature_count();
    let [pm, hybrid, rigid_us] = mix_us(played(sim), model, rigid);
    let room_us =
        f64::from(model.overhead_us(count as usize)) + f64::from(count) * hybrid.max(pm) + f64::from(rigid) * rigid_us;
    let game = in_play(sim, model, room_us, effort);
    let choice_us = f64::from(model.overhead_us(count as usize) - model.fixed_us_per_frame);
    (
        game.rigid.round().max(1.0) as u32,
        ((game.median_us - game.cheap_us - choice_us) / game.rigid_us.max(1e-9)).clamp(0.01, 10.0) as f32,
    )
}

/// Microseconds a creature that the budget policy adds to a frame where not one step up fits:
/// its scenario's crowd of `count` under the budget policy with no room, each creature at its
/// floor, against the same crowd at the cheapest level under a fixed policy, the two stepped a
/// frame each in turn. Besides the choice's pass over the crowd, the policy writes every
/// creature's level and its switch stage passes over them, where a fixed policy rests: timed
/// as the choice alone, the charge at 100,000 creatures was 0.7 ms a frame, timed so 1.2, and
/// the frames of such a crowd ran 1.2 times their prediction, 1.1 times now. Below a crowd its
/// charge is a tenth of a millisecond, within the spread of what the model says of the rest of
/// the frame: taken beyond that, it came out at nothing (2026-11-29).
fn floors_only_us(config: &SimConfig, model: &CostModel, count: u32, effort: (usize, usize)) -> f64 {
    let mut fixed = HeadlessSim::new(scaled(config, count, LevelPolicy::AllPointMass));
    extra_us_per_creature(&mut under_the_budget(config, count, model), &mut fixed, effort)
}

/// Microseconds per switch into the rigid level (building a creature's bodies): a world of
/// `count` creatures built all rigid, less the same world built at `below`, per creature.
/// Building the rest of the world costs both the same; the rigid one enters every creature's
/// level the way a switch does (the level's observers). Rapier's taking the bodies into its
/// world in the next step is not in it: a first step of standing creatures costs less than a
/// steady one, which hides it in the noise of a shared machine. The median of
/// [`SWITCH_PAIRS`] pairs built in turn, after one of each unmeasured: the first world a
/// process builds pays for its warm-up, which once made the cheaper world the dearer to build
/// and the switch free.
fn switch_cost_us(config: &SimConfig, count: u32, below: Lod) -> f64 {
    let build_s = |policy: LevelPolicy| {
        let start = Instant::now();
        drop(HeadlessSim::new(scaled(config, count, policy)));
        start.elapsed().as_secs_f64()
    };
    let cheap = match below {
        Lod::Hybrid => LevelPolicy::AllHybrid,
        _ => LevelPolicy::AllPointMass,
    };
    build_s(cheap);
    build_s(LevelPolicy::AllRigid);
    let pairs = (0..SWITCH_PAIRS)
        .map(|_| {
            let (cheap_s, rigid_s) = (build_s(cheap), build_s(LevelPolicy::AllRigid));
            (rigid_s - cheap_s) * 1e6 / f64::from(count)
        })
        .collect();
    median(pairs).max(0.0)
}

/// Worlds built at each level to measure a switch into rigid, in turn.
const SWITCH_PAIRS: usize = 5;

/// What a switch between the cheap levels costs, us: `count` point masses of `config`'s mix
/// sent to the hybrid level at once (those out of view need not wait for their flight window),
/// the frame they switch in over the median of the three before, shared among its switches. The
/// median of `bursts`, each after the first a hop's frames at the point mass (those still
/// hybrid then do not switch in the next burst, nor count). Each of a calibration's passes
/// times its own: at start-up one burst, about 15 ms a kind.
fn cheap_switch_us(config: &SimConfig, count: u32, warmup: usize, bursts: usize) -> f64 {
    let mut sim = HeadlessSim::new(scaled(config, count, LevelPolicy::AllPointMass));
    let policy = |sim: &mut HeadlessSim, policy| playing(sim).scenario.level_policy = policy;
    let switches = |sim: &HeadlessSim| sim.app.world().resource::<SwitchTally>().switches.total();
    play_on(&mut sim, warmup);
    let mut per_switch = Vec::new();
    for burst in 0..bursts {
        // Hybrids wait for their window to go down.
        if burst > 0 {
            policy(&mut sim, LevelPolicy::AllPointMass);
            play_on(&mut sim, BACK_DOWN_FRAMES);
        }
        let before_s = median((0..3).map(|_| timed_frame(&mut sim)).collect());
        let (switched, start) = (switches(&sim), Instant::now());
        policy(&mut sim, LevelPolicy::AllHybrid);
        sim.advance_frame();
        let burst_s = start.elapsed().as_secs_f64();
        let n = switches(&sim) - switched;
        if n > 0 {
            per_switch.push((burst_s - before_s) * 1e6 / n as f64);
        }
    }
    if per_switch.is_empty() {
        0.0
    } else {
        median(per_switch).max(0.0)
    }
}

/// Frames after a burst for its hybrids to go back down: half a second, about a hop.
const BACK_DOWN_FRAMES: usize = 15;

/// What a cost model says, a line each: every kind's levels, the frame's fixed cost and the
/// choice's, the crowd's shares, and the rigid level's in play among more rigid creatures.
pub fn cost_model_lines(model: &CostModel) -> Vec<String> {
    let mut lines: Vec<String> = (model.kinds.iter())
        .map(|k| {
            let c = &k.costs;
            format!(
                "{:<8} point mass {:.3}, hybrid {:.3}, rigid {:.1}; switch to rigid {:.1}, between the cheap levels {:.2}",
                k.kind,
                c.point_mass_us_per_frame,
                c.hybrid_us_per_frame,
                c.rigid_us_per_frame,
                c.switch_to_rigid_us,
                c.cheap_switch_us
            )
        })
        .collect();
    lines.push(format!(
        "a frame whatever its creatures (court, puck, schedule): {:.1}; the budget policy's choice per creature: {:.3}, where only the floors fit: {:.3}, and per creature it searches for contacts: {:.2}",
        model.fixed_us_per_frame,
        model.decision_us_per_creature,
        model.floors_only_us_per_creature,
        model.contact_search_us
    ));
    for shares in model.crowd_shares.iter().chain(&model.larger_crowd_shares) {
        lines.push(format!(
            "in a crowd of {} (across the cores): point mass x {:.2}, hybrid x {:.2}, the choice x {:.2}, where only the floors fit x {:.2}, rigid x {:.2}",
            shares.creatures, shares.point_mass, shares.hybrid, shares.choice, shares.floors_only, shares.rigid
        ));
    }
    if !model.rigid_shares.is_empty() {
        let shares: Vec<String> = (model.rigid_shares.iter())
            .map(|r| format!("{} x {:.2}", r.rigid, r.share))
            .collect();
        lines.push(format!(
            "the rigid level in play among this many rigid creatures: {}",
            shares.join(", ")
        ));
    }
    lines
}

/// The cost model as its file says it, with the command that measured it.
pub fn costs_file_text(model: &CostModel, command: &str) -> String {
    let pretty = ron::ser::PrettyConfig::new().depth_limit(3).struct_names(false);
    let body = ron::ser::to_string_pretty(model, pretty).expect("a cost model serialises");
    format!(
        "// The budget policy's cost model: wall time per creature per 1/30 s of motion at each\n// level, of a switch into the rigid level and of one between the point mass and the hybrid,\n// of a frame whatever its creatures (the court, the puck, the schedule) and of the budget\n// policy's choice per creature (and where only the floors fit) and per creature it searches\n// for contacts, in microseconds (medians), and the shares of those costs in crowds and among\n// many rigid creatures, measured by:\n//     {command}\n// Run it again on the machine that plays; `other_kinds` is what a kind not listed costs.\n{body}\n"
    )
}
