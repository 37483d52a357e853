//! The `budget` policy: a frame budget spent where it changes the outcome most (beyond the
//! paper, after its conclusion: "cost/benefit heuristics might be designed to assign a
//! switching priority for each creature. Thus a consistent frame rate could be maintained by
//! using lower levels of detail for the lowest priority creatures").
//!
//! At each decision every creature gets a benefit for each level its kind has, from the
//! paper's two criteria made continuous: how soon a contact with the puck, a wall or another
//! creature could come (a time to contact from positions and velocities, where 3.4 has areas
//! of influence), and how much the viewer sees of it (in view, how near the camera, the
//! followed creature first; 3.4's camera rule). Each level has a predicted cost from the cost
//! model (`assets/costs.ron`), and going rigid costs the building of its bodies once more;
//! what a frame costs whatever its creatures' levels (the court, the puck, this choice) comes
//! off the budget first.
//! The levels are chosen as a multiple-choice knapsack, greedily by benefit per cost
//! (Funkhouser & Sequin, SIGGRAPH '93), so that the predicted cost of the frame stays within
//! the budget. It starts from the last decision: a creature in its dwell keeps at least its
//! level, its last chosen level counts `hysteresis` more, and the switch itself still waits
//! for the flight window (`switch.rs`). No clock is read: the same files give the same run,
//! unless the adaptive mode (`adaptive_frames` above 0) corrects the cost model by measured
//! frame times, which the game and the headless runner write from outside the simulation.
//!
//! Over 600 lines with its unit tests, which sit beside the allocation they check.

use bevy::prelude::*;
use serde::Serialize;
use std::cell::Cell;
use std::collections::{BinaryHeap, VecDeque};

use super::select::{
    Area, DecisionInputs, LevelChoice, SimCamera, ViewReach, areas_now, select_levels, start_at_selected_levels,
};
use super::{LevelPolicy, Lod};
use crate::config::{BudgetRules, LevelCosts, SimConfig};
use crate::contract::GaitPose;
use crate::contract::SimClock;
use crate::contract::{DENSE, chunk_len, run_chunks, threads_for};
use crate::contract::{GaitPhase, PlanarState};
use crate::contract::{SimStage, SimStart, StartStage};
use crate::kind::{Creature, KindTable, starting_gait};
use crate::sense::NeighbourGrid;
use crate::sense::{Court, PuckState};
use bevy::ecs::query::QueryData;

/// One creature as the knapsack sees it.
#[derive(Clone, Debug)]
pub struct Candidate<'a> {
    /// The creature's serial: ties go to the lower.
    pub serial: u32,
    /// The level it is simulated at now.
    pub current: Lod,
    /// The level the last decision chose (it gets the hysteresis).
    pub last: Lod,
    /// The lowest level it may be given (its current one while it dwells).
    pub floor: Lod,
    /// The levels its kind has, cheapest first.
    pub levels: &'a [Lod],
    /// What each of its levels costs, us per 1/30 s.
    pub costs: LevelCosts,
    /// Benefit of each level, indexed by `Lod as usize`. Until `settled`, the rigid level's is
    /// only the most it can be.
    pub benefit: [f32; 3],
    /// Whether `benefit` is exact; if not, [`allocate`] settles it when it must know.
    pub settled: bool,
}

impl Candidate<'_> {
    /// Predicted microseconds of the frame if the creature is given `level`: the level's cost,
    /// and its switch if it goes rigid now (the building of its bodies) or to the other cheap
    /// level.
    fn cost_us(&self, level: Lod) -> f32 {
        self.costs.per_frame_us(level) + self.costs.switch_us(self.current, level)
    }

    /// Predicted microseconds of the frame while the creature moves toward `level`: until its
    /// flight window it still runs at its current level, if that is the dearer.
    fn frame_cost_us(&self, level: Lod) -> f32 {
        self.cost_us(level.max(self.current))
    }

    fn value(&self, level: Lod, hysteresis: f32) -> f32 {
        let b = self.benefit[level as usize];
        if level == self.last { b * (1.0 + hysteresis) } else { b }
    }

    /// Its levels priced for the knapsack, once a listing.
    fn priced(&self, hysteresis: f32) -> Priced {
        Priced {
            cost_us: Lod::ALL.map(|l| self.cost_us(l)),
            value: Lod::ALL.map(|l| self.value(l, hysteresis)),
        }
    }

    /// The next step up its upper hull of cost and benefit from `at`: the most benefit per
    /// microsecond, ties to the lower level; none below `least_per_us`. A loop over its levels,
    /// each priced once in `p`: it is listed for every creature at every decision.
    fn step_from(&self, creature: u32, at: Lod, hull: &Hull, p: &Priced) -> Option<Step> {
        let (cost, value) = (p.cost_us[at as usize], p.value[at as usize]);
        // None found while `best` is `at`. A ratio is positive or infinite, never NaN.
        let (mut best, mut best_ratio) = (at, f32::NEG_INFINITY);
        // After its search, only a step that gains can follow a bound.
        let mut after_search_us = f32::INFINITY;
        for &to in self.levels {
            // Only a level above can be a step up.
            if to <= at {
                continue;
            }
            let (to_cost, to_value) = (p.cost_us[to as usize], p.value[to as usize]);
            let (gains, extra_us) = (to_value > value, to_cost - cost);
            if gains || to == Lod::Rigid {
                after_search_us = after_search_us.min(extra_us);
            }
            if !gains {
                continue;
            }
            let ratio = if extra_us > 0.0 {
                (to_value - value) / extra_us
            } else {
                f32::INFINITY
            };
            if ratio > best_ratio || (ratio == best_ratio && to < best) {
                (best, best_ratio) = (to, ratio);
            }
        }
        if best == at || best_ratio < hull.least_per_us {
            return None;
        }
        let to = best;
        // Only the rigid benefit is ever a bound: a step to another level is exact.
        let bound = !self.settled && to == Lod::Rigid;
        let running = |l: Lod| p.cost_us[l.max(self.current) as usize];
        Some(Step {
            ratio: best_ratio,
            bound,
            serial: self.serial,
            creature,
            from: at,
            to,
            extra_us: if bound {
                after_search_us
            } else {
                p.cost_us[to as usize] - cost
            },
            running_us: running(to) - running(at),
            group: false,
        })
    }

    /// Lists its steps up its upper hull from its floor, in turn (a loop, not an iterator of
    /// them: each step is written once, where the iterator's moves of it stalled the listing).
    fn list_hull(&self, creature: u32, hull: &Hull, p: &Priced, mut listed: impl FnMut(Step)) {
        let top = self.levels.iter().max().copied();
        let mut next = self.step_from(creature, self.floor, hull, p);
        while let Some(step) = next {
            listed(step);
            // Nothing is above its kind's top level.
            next = if Some(step.to) == top {
                None
            } else {
                self.step_from(creature, step.to, hull, p)
            };
        }
    }

    /// The least any step up from its floor or a level above can cost.
    fn cheapest_step_above_floor_us(&self, p: &Priced) -> f32 {
        let mut cheapest = f32::INFINITY;
        for &from in self.levels.iter().filter(|&&l| l >= self.floor) {
            for &to in self.levels.iter().filter(|&&l| l > from) {
                cheapest = cheapest.min(p.cost_us[to as usize] - p.cost_us[from as usize]);
            }
        }
        cheapest
    }
}

/// The creatures the knapsack chooses among, each a [`Candidate`] by its place: a slice of
/// them, or a decision's creatures, each made only when asked for (in a crowd, the few the
/// queue comes back to).
trait Crowd<'a>: Sync {
    /// The `i`-th, its rigid benefit exact once settled.
    fn candidate(&self, i: usize) -> Candidate<'a>;
    /// The `i`-th's exact rigid benefit, settled.
    fn settle(&mut self, i: usize, rigid_benefit: f32);
    /// The steps up the hulls of the quiet creatures of `group` ([`QuietGroups`]) into
    /// `opened`, each creature marked in `settled_now` as it is: none where there are no groups.
    fn open(&self, _group: usize, _hull: &Hull, _settled_now: &mut [bool], _opened: &mut BinaryHeap<Step>) {}
}

impl<'a> Crowd<'a> for [Candidate<'a>] {
    fn candidate(&self, i: usize) -> Candidate<'a> {
        self[i].clone()
    }

    fn settle(&mut self, i: usize, rigid_benefit: f32) {
        let c = &mut self[i];
        c.benefit[Lod::Rigid as usize] = rigid_benefit;
        c.settled = true;
    }
}

/// A candidate's levels priced for the knapsack, by `Lod as usize`: what each costs (as
/// `Candidate::cost_us`) and is worth (as `Candidate::value`).
struct Priced {
    cost_us: [f32; 3],
    value: [f32; 3],
}

/// The levels chosen, and what the frame is predicted to cost.
#[derive(Clone, Debug, PartialEq)]
pub struct Allocation<S = ()> {
    /// One per candidate, in the candidates' order.
    pub levels: Vec<Lod>,
    /// The frame's predicted simulation time at these levels, us per 1/30 s.
    pub predicted_us: f32,
    /// Even the cheapest allowed levels cost more than the budget.
    pub exceeded: bool,
    /// Candidates whose benefit had to be settled (each one's search for contacts), in the
    /// order settled, with what the settling returned beside the benefit.
    pub settled: Vec<(usize, S)>,
    /// Quiet creatures whose benefits were never worked out: their groups not opened (the
    /// incremental choice).
    pub quiet: usize,
}

/// One step up a creature's levels on the knapsack's upper hull; while `bound`, its ratio is
/// only the most any of the creature's steps can have.
#[derive(Clone, Copy, Debug)]
struct Step {
    ratio: f32,
    bound: bool,
    serial: u32,
    creature: u32,
    from: Lod,
    to: Lod,
    /// What the step adds to the predicted frame: the least room in the budget it needs to
    /// change anything. While a bound, the least a step after the search that settles it adds
    /// (the search beside).
    extra_us: f32,
    /// What the step adds to the frame as it will run (a creature going down still costs its
    /// level): kept, so that taking the step does not look at its creature again.
    running_us: f32,
    /// Whether it stands for the steps of a group of quiet creatures (`creature` is the
    /// group: [`QuietGroups`]), above each of them, until it reaches the front.
    group: bool,
}

/// The order steps are taken in, greatest first: the most benefit per microsecond, then the
/// lower serial, then the lower level (a creature's steps up its hull in turn).
impl Ord for Step {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.ratio
            .total_cmp(&other.ratio)
            .then(other.serial.cmp(&self.serial))
            .then(other.to.cmp(&self.to))
    }
}

impl Step {
    /// The ratio as a key, smallest first (the most benefit per microsecond first). A ratio is
    /// never negative (a step gains), so its sign is left out.
    fn descending_ratio(&self) -> u32 {
        debug_assert!(self.ratio.is_sign_positive() && !self.ratio.is_nan(), "{}", self.ratio);
        0x7FFF_FFFF - (self.ratio.to_bits() & 0x7FFF_FFFF)
    }

    /// The same order as a key, smallest first, short of the level: steps sorted by it stably,
    /// in the order of each creature's hull, are in [`Ord`]'s order.
    fn order_key(&self) -> u64 {
        (u64::from(self.descending_ratio()) << u32::BITS) | u64::from(self.serial)
    }

    /// Sorts `steps` into the order they are taken, stably (so each creature's steps stay in
    /// the order of its hull): a radix sort by the ratio alone, then each run of equal ratios
    /// by serial. The radix sort then passes over four bytes of a key, not six or more, and in
    /// a crowd's cheap steps (their ratios from the view) equal ratios are few; where they are
    /// many (a crowd's free steps, to a hybrid that costs what its point mass does), a run is
    /// radix-sorted too.
    fn sort(steps: &mut [Step]) {
        radsort::sort_by_key(steps, Step::descending_ratio);
        for run in steps.chunk_by_mut(|a, b| a.descending_ratio() == b.descending_ratio()) {
            match run.len() {
                0 | 1 => {}
                2..RADIX_SORTED_RUN => run.sort_by_key(|s| s.serial),
                _ => radsort::sort_by_key(run, |s| s.serial),
            }
        }
    }

    /// Lists each sorted by [`Step::sort`], merged into the order one stable sort of them end
    /// to end gives: the earlier list's first among equal keys.
    fn merge(lists: Vec<Vec<Step>>) -> Vec<Step> {
        let key = Step::order_key;
        let mut lists = lists.into_iter();
        let first = lists.next().unwrap_or_default();
        lists.fold(first, |first, second| {
            let mut merged = Vec::with_capacity(first.len() + second.len());
            let (mut i, mut j) = (0, 0);
            while i < first.len() && j < second.len() {
                if key(&second[j]) < key(&first[i]) {
                    merged.push(second[j]);
                    j += 1;
                } else {
                    merged.push(first[i]);
                    i += 1;
                }
            }
            merged.extend_from_slice(&first[i..]);
            merged.extend_from_slice(&second[j..]);
            merged
        })
    }
}

impl PartialOrd for Step {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Step {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for Step {}

/// Chooses a level for each candidate: from each one's floor, the steps up with the most
/// benefit per microsecond first, while the budget allows (a multiple-choice knapsack solved
/// greedily on each creature's upper convex hull of cost and benefit); a step that gains less
/// than `least_per_us` per microsecond is never taken, so the budget is a ceiling. Then, since
/// a creature going down keeps costing its old level until its flight window, the last steps
/// taken that add to the frame as it will run are given back until it fits (one that adds
/// nothing, a creature's step to the level it has, is kept). Deterministic: ties go to the
/// lower serial.
///
/// Incremental (after Funkhouser & Sequin): a candidate not yet `settled` waits in the queue
/// at the most its steps could be worth, and is settled by `settle` (its exact rigid benefit,
/// and whatever else the caller keeps of it; charged `settle_us` of the budget) only when it
/// reaches the front with room left for a step of its own. Since a bound is never below what it
/// bounds, the steps are taken in the same order as if every benefit had been exact from the
/// start. The next bounds in the queue are settled ahead across the cores, as many as the
/// budget could pay for: `settle` must depend on the candidate alone, and a search made ahead
/// and never reached is only time lost.
pub fn allocate<S: Send>(
    candidates: &mut [Candidate],
    budget_us: f32,
    hysteresis: f32,
    least_per_us: f32,
    settle_us: f32,
    settle: impl Fn(usize) -> (f32, S) + Sync,
) -> Allocation<S> {
    let hull = Hull {
        hysteresis,
        least_per_us,
        settle_us,
    };
    list_and_allocate(candidates, budget_us, &hull, None, settle)
}

/// [`allocate`], its steps dear beyond `dear_us` if given ([`Floors::dear_us`] if not).
fn list_and_allocate<S: Send>(
    candidates: &mut [Candidate],
    budget_us: f32,
    hull: &Hull,
    dear_us: Option<f32>,
    settle: impl Fn(usize) -> (f32, S) + Sync,
) -> Allocation<S> {
    let mut floors = Floors::with_capacity(candidates.len());
    candidates.iter().for_each(|c| floors.add(c.into()));
    let dear_us = dear_us.unwrap_or_else(|| floors.dear_us(budget_us));
    let listed = hull.list(candidates, dear_us);
    let settled_now = candidates.iter().map(|c| c.settled).collect();
    allocate_listed(
        candidates,
        floors,
        settled_now,
        (listed, QuietGroups::default()),
        budget_us,
        hull,
        settle,
    )
}

/// [`allocate`] from every creature at its floor (`floors`), whether each is `settled_now`, and
/// the steps up their hulls `listed` ([`Hull::list`], its dear steps beyond the room in the
/// budget the floors leave over [`DEAR_STEPS`]) but for the quiet creatures' `groups`, each
/// opened, and charged, only when it reaches the front with room for a step of its own.
fn allocate_listed<'a, S: Send>(
    crowd: &mut (impl Crowd<'a> + ?Sized),
    floors: Floors,
    mut settled_now: Vec<bool>,
    (listed, groups): (Listing, QuietGroups),
    budget_us: f32,
    hull: &Hull,
    settle: impl Fn(usize) -> (f32, S) + Sync,
) -> Allocation<S> {
    // What the floors cost and what the frame as it will run costs (creatures going down still
    // cost their level: a search is paid for at once and never given back, so it must fit
    // beside that too), and the cheapest step of all. Where every level costs no less than the
    // one below, what is spent and the frame as it will run only grow, so a step that cannot
    // fit now never will and may be passed by.
    let (mut levels, mut spent, mut running_us) = (floors.levels, floors.cost_us, floors.frame_us);
    let (cheapest_us, rising, settle_us) = (floors.cheapest_step_us, floors.rising, hull.settle_us);
    // The queue: the lists of steps, merged as it goes, best first.
    let threads = threads_for(levels.len() as u32);
    let mut lists: Vec<Queued<S>> = Vec::new();
    let mut opened_creatures = 0;
    if spent + cheapest_us <= budget_us {
        lists.push(Queued::cheap(listed.cheap, hull, threads));
        lists.extend(
            listed
                .dear
                .into_iter()
                .map(|(_, dear)| Queued::dear(dear, hull, threads)),
        );
        if !groups.steps.is_empty() {
            lists.push(Queued::groups(&groups, threads));
        }
    }
    // The steps of the groups opened, and what opening them cost.
    let (mut opened, mut opened_us) = (BinaryHeap::new(), 0.0);
    // The list last taken from, and the best next step of the others then: it is taken from
    // while its next step is above that.
    let mut run: Option<(usize, Option<Step>)> = None;
    let mut follows = Follows::default();
    // Room for every cheap step to be taken: most are, in a crowd.
    let mut taken = Vec::with_capacity(lists.first().map_or(0, |q| q.steps.len()));
    let mut settled = Vec::new();
    // Whether a search fits beside the frame as it will run.
    let searches_fit = |running_us: f32| settle_us == 0.0 || running_us + settle_us <= budget_us;
    // Whether a list's next step could fit, or any after it (once the budget has less, or no
    // search fits beside the frame as it will run, which only grows, the rest of the list can
    // change nothing and is passed by).
    let live = |q: &Queued<S>, spent: f32, running_us: f32| {
        let (any, exact) = q.needs();
        !rising || spent + if searches_fit(running_us) { any } else { exact } <= budget_us
    };
    'queue: loop {
        // A run on a list: its exact steps in order taken in turn, as the loop below would take
        // them one by one, while each stays ahead of the others' heads and of the steps that
        // follow settled creatures (neither changes meanwhile).
        if let Some((i, others)) = run {
            let q = &mut lists[i];
            let follow = follows.heap.peek().copied();
            while q.next < q.sorted {
                let step = q.steps[q.next];
                if !live(q, spent, running_us)
                    || step.bound
                    || step.group
                    || others.is_some_and(|o| step <= o)
                    || follow.is_some_and(|f| f > step)
                    || opened.peek().is_some_and(|o| *o > step)
                {
                    break;
                }
                q.next += 1;
                if spent + cheapest_us > budget_us {
                    break 'queue;
                }
                let creature = step.creature as usize;
                if levels[creature] == step.from && spent + step.extra_us <= budget_us {
                    levels[creature] = step.to;
                    spent += step.extra_us;
                    running_us += step.running_us;
                    taken.push(step);
                }
            }
        }
        let live = |q: &Queued<S>| live(q, spent, running_us);
        let running_on = run.and_then(|(i, others)| {
            let q = &mut lists[i];
            (live(q) && q.head().is_some_and(|h| others.is_none_or(|o| *h > o))).then_some(i)
        });
        let first = running_on.or_else(|| {
            let (mut best, mut others) = (None::<(usize, Step)>, None);
            for (i, q) in lists.iter_mut().enumerate() {
                if !live(q) {
                    continue;
                }
                let Some(&head) = q.head() else { continue };
                if best.is_none_or(|(_, b)| head > b) {
                    others = others.max(best.map(|(_, b)| b));
                    best = Some((i, head));
                } else {
                    others = others.max(Some(head));
                }
            }
            run = best.map(|(i, _)| (i, others));
            best.map(|(i, _)| i)
        });
        if let Some(q) = first.map(|i| &mut lists[i]) {
            q.sort_to(q.next + 1);
        }
        // The greatest of the lists' next step, the settled creatures' and the opened groups'
        // (the list's among equals). Once no list's step fits, the settled creatures' steps
        // are passed by too.
        let follow = (follows.heap.peek().copied())
            .filter(|_| first.is_some() || !rising || spent + follows.extra_us <= budget_us);
        let listed = first.map(|i| (lists[i].steps[lists[i].next], Source::Listed(i)));
        let best = [
            listed,
            follow.map(|f| (f, Source::Followed)),
            opened.peek().map(|&o| (o, Source::Opened)),
        ]
        .into_iter()
        .flatten()
        .reduce(|a, b| if b.0 > a.0 { b } else { a });
        let Some((step, source)) = best else { break };
        match source {
            Source::Listed(i) => lists[i].next += 1,
            Source::Followed => _ = follows.heap.pop(),
            Source::Opened => _ = opened.pop(),
        }
        if spent + cheapest_us > budget_us {
            break;
        }
        if step.group {
            // Its creatures' steps are all below it, so they are listed from here on as they
            // would have been from the start. Once its room can never be had, they can change
            // nothing (the list's `live` test, for this one).
            let group = step.creature as usize;
            let ((any, exact), open_us) = (groups.needs[group], groups.open_us[group]);
            // Its opening is paid at once and never given back, so it must fit beside the frame
            // as it will run, as a search must.
            let fits = spent + if searches_fit(running_us) { any } else { exact } <= budget_us
                && (open_us == 0.0 || running_us + open_us <= budget_us);
            if !rising || fits {
                crowd.open(group, hull, &mut settled_now, &mut opened);
                opened_creatures += groups.members[group] as usize;
                (spent, running_us, opened_us) = (spent + open_us, running_us + open_us, opened_us + open_us);
            }
            continue;
        }
        let followed = source == Source::Followed;
        debug_assert!(!(followed && step.bound), "a settled creature's steps are exact");
        let creature = step.creature as usize;
        // A step from a level the creature did not reach, or a bound since settled.
        if levels[creature] != step.from || (step.bound && settled_now[creature]) {
            continue;
        }
        if step.bound {
            // Worth settling only with room for the search and a step after it.
            if searches_fit(running_us) && spent + settle_us + step.extra_us <= budget_us {
                // Bounds are listed only (a settled creature's steps are exact).
                let room_us = budget_us - spent.max(running_us);
                let now = if let Source::Listed(i) = source {
                    // Settled with the next bounds of its list, put in order that far.
                    let q = &mut lists[i];
                    let at = q.next - 1;
                    q.sort_to(at + 1 + q.ahead.batch);
                    let sorted = &q.steps[..q.sorted];
                    q.ahead.take(at, sorted, &*crowd, &settled_now, hull, room_us, &settle)
                } else {
                    Settled::of(&step, &*crowd, hull, &settle)
                };
                spent += settle_us;
                running_us += settle_us;
                settled.push((creature, now.kept));
                crowd.settle(creature, now.benefit);
                settled_now[creature] = true;
                follows.push(now.step);
            }
        } else if spent + step.extra_us <= budget_us {
            levels[creature] = step.to;
            spent += step.extra_us;
            running_us += step.running_us;
            taken.push(step);
            // A listed step's successor is listed too.
            if followed {
                let c = crowd.candidate(creature);
                follows.push(c.step_from(step.creature, step.to, hull, &c.priced(hull.hysteresis)));
            }
        }
    }
    let choosing_us = settled.len() as f32 * settle_us + opened_us;
    let frame = |levels: &[Lod]| -> f32 {
        choosing_us
            + (floors.frame_at_us.iter().zip(levels))
                .map(|(at, &l)| at[l as usize])
                .sum::<f32>()
    };
    let mut predicted_us = frame(&levels);
    let mut given_back = false;
    for step in taken.iter().rev() {
        if predicted_us <= budget_us {
            break;
        }
        // A step to a level its creature runs at anyway this frame lowers nothing given back:
        // it would only send the creature down (a crowd's hybrids, all at once).
        if step.running_us == 0.0 {
            continue;
        }
        levels[step.creature as usize] = step.from;
        predicted_us -= step.running_us;
        given_back = true;
    }
    // Summed afresh once, so that the steps' rounding does not add up.
    if given_back {
        predicted_us = frame(&levels);
    }
    Allocation {
        levels,
        predicted_us,
        exceeded: predicted_us > budget_us,
        settled,
        quiet: groups.members.iter().sum::<u32>() as usize - opened_creatures,
    }
}

/// The steps of settled creatures, waiting beside the list, and the least any of them ever
/// needed (what is left needs no less).
struct Follows {
    heap: BinaryHeap<Step>,
    extra_us: f32,
}

impl Default for Follows {
    fn default() -> Self {
        Self {
            heap: Default::default(),
            extra_us: f32::INFINITY,
        }
    }
}

impl Follows {
    fn push(&mut self, step: Option<Step>) {
        if let Some(step) = step {
            self.extra_us = self.extra_us.min(step.extra_us);
            self.heap.push(step);
        }
    }
}

/// What the knapsack's steps are worked out with: a creature's last level counts `hysteresis`
/// more; a step gaining less than `least_per_us` is not listed; settling a bound costs
/// `settle_us`.
#[derive(Clone, Copy, Debug)]
struct Hull {
    hysteresis: f32,
    least_per_us: f32,
    settle_us: f32,
}

impl Hull {
    /// Every step up the hulls of `candidates`, a creature's steps in turn, the cheap ones
    /// sorted ([`Listing`]).
    fn list(&self, candidates: &[Candidate], dear_us: f32) -> Listing {
        let mut listed = Listing::new(dear_us, candidates.len());
        for (i, c) in (0..).zip(candidates) {
            c.list_hull(i, self, &c.priced(self.hysteresis), |step| listed.push(step, self));
        }
        listed.finish();
        listed
    }

    /// The room in the budget a step needs to change anything: a bound's search beside it.
    fn need_us(&self, step: &Step) -> f32 {
        if step.bound {
            self.settle_us + step.extra_us
        } else {
            step.extra_us
        }
    }
}

/// The steps listed, apart by the room each needs. The cheap ones are sorted into the order
/// they are taken. The dear ones, each needing more than `dear_us` (so that only a few of them
/// can ever fit), wait unsorted in a list for each room: the queue puts them in order only
/// as far as it reaches, and passes by the rest of such a list once the budget has no room for
/// its steps (a crowd's bounds to rigid, most of them never reached).
struct Listing {
    dear_us: f32,
    /// How many creatures list their steps here.
    creatures: usize,
    cheap: Vec<Step>,
    /// By whether they are bounds and the bits of what they add; a chunk's apart.
    dear: Vec<((bool, u32), DearSteps)>,
    /// The dear list last pushed to: a crowd's creatures of a kind list into the same rooms.
    last_dear: usize,
}

/// The dear steps that need one room, as listed, and the best of them: the head of their list
/// in the queue before it is put in order (most dear lists are never taken from). The best is
/// found once the listing is done ([`Listing::finish`]).
struct DearSteps {
    steps: Vec<Step>,
    best: Step,
}

impl Listing {
    /// Nothing listed yet, with room for the steps of `creatures`.
    fn new(dear_us: f32, creatures: usize) -> Self {
        Self {
            dear_us,
            creatures,
            cheap: Vec::with_capacity(2 * creatures),
            dear: Vec::new(),
            last_dear: 0,
        }
    }

    fn push(&mut self, step: Step, hull: &Hull) {
        if hull.need_us(&step) <= self.dear_us {
            return self.cheap.push(step);
        }
        let room = (step.bound, step.extra_us.to_bits());
        let last = self.dear.get(self.last_dear).filter(|(r, _)| *r == room);
        match last
            .map(|_| self.last_dear)
            .or_else(|| self.dear.iter().position(|(r, _)| *r == room))
        {
            Some(i) => {
                self.dear[i].1.steps.push(step);
                self.last_dear = i;
            }
            None => {
                // Room for a step of each creature: a creature lists one in a room at most, but
                // in a crowd where two of its levels cost alike.
                let mut steps = Vec::with_capacity(self.creatures);
                steps.push(step);
                self.last_dear = self.dear.len();
                self.dear.push((room, DearSteps { steps, best: step }));
            }
        }
    }

    /// Done listing: the cheap steps sorted, and each dear list's best found. A creature lists
    /// one step in a room, so within a dear list the ratio and the serial order the steps (the
    /// first listed kept among equals, as the hull's lower level would be).
    fn finish(&mut self) {
        Step::sort(&mut self.cheap);
        let key = |s: &Step| (u64::from(0x7FFF_FFFF - s.descending_ratio()) << u32::BITS) | u64::from(!s.serial);
        for (_, dear) in &mut self.dear {
            let mut best = (key(&dear.best), dear.best);
            for step in &dear.steps[1..] {
                let k = key(step);
                if k > best.0 {
                    best = (k, *step);
                }
            }
            dear.best = best.1;
        }
    }

    /// Chunks listed apart, as one: the cheap steps merged ([`Step::merge`]), each chunk's
    /// dear ones kept apart (the queue merges them as it goes).
    fn merge(chunks: Vec<Listing>) -> Listing {
        let (dear_us, creatures) = (
            chunks.first().map_or(f32::INFINITY, |c| c.dear_us),
            chunks.iter().map(|c| c.creatures).sum(),
        );
        let mut cheap = Vec::with_capacity(chunks.len());
        let mut dear = Vec::new();
        for chunk in chunks {
            cheap.push(chunk.cheap);
            dear.extend(chunk.dear);
        }
        Listing {
            dear_us,
            creatures,
            cheap: Step::merge(cheap),
            dear,
            last_dear: 0,
        }
    }
}

/// One list of the queue: its steps in the order they are taken as far as `sorted` (each
/// beyond below every one before), the best of them while none is (a dear list's), the next
/// to take, the room its steps need, and its bounds further on settled ahead.
struct Queued<S> {
    steps: Vec<Step>,
    sorted: usize,
    best: Option<Step>,
    next: usize,
    need: Need,
    ahead: SettledAhead<S>,
}

/// The room in the budget a list's steps need, and its exact ones (infinite for a bound,
/// which needs its search first).
enum Need {
    /// The least any step from each on needs (the cheap steps).
    From(Vec<(f32, f32)>),
    /// What every one of its steps needs (the dear steps of one room).
    Each(f32, f32),
}

/// The fewest steps a dear list is put in order at a time.
const DEAR_SORTED_AT_ONCE: usize = 256;

impl<S: Send> Queued<S> {
    /// The cheap steps, sorted.
    fn cheap(steps: Vec<Step>, hull: &Hull, threads: usize) -> Self {
        // Once the budget has less than the least room any step from here on needs, the
        // rest of the list can change nothing and is passed by.
        let mut need_from = vec![(f32::INFINITY, f32::INFINITY); steps.len() + 1];
        for (i, step) in steps.iter().enumerate().rev() {
            let (any, exact) = need_from[i + 1];
            let need = hull.need_us(step);
            need_from[i] = (any.min(need), if step.bound { exact } else { exact.min(need) });
        }
        Self {
            sorted: steps.len(),
            steps,
            best: None,
            next: 0,
            need: Need::From(need_from),
            ahead: SettledAhead::new(threads),
        }
    }

    /// The dear steps that need one room, unsorted.
    fn dear(dear: DearSteps, hull: &Hull, threads: usize) -> Self {
        let (need, bound) = (hull.need_us(&dear.best), dear.best.bound);
        Self {
            steps: dear.steps,
            sorted: 0,
            best: Some(dear.best),
            next: 0,
            need: Need::Each(need, if bound { f32::INFINITY } else { need }),
            ahead: SettledAhead::new(threads),
        }
    }

    /// The quiet creatures' groups, each a step above all of theirs ([`QuietGroups`]).
    fn groups(groups: &QuietGroups, threads: usize) -> Self {
        let mut need_from = vec![(f32::INFINITY, f32::INFINITY); groups.steps.len() + 1];
        for (i, step) in groups.steps.iter().enumerate().rev() {
            let ((any, exact), need) = (need_from[i + 1], groups.needs[step.creature as usize]);
            need_from[i] = (any.min(need.0), exact.min(need.1));
        }
        Self {
            sorted: groups.steps.len(),
            steps: groups.steps.clone(),
            best: None,
            next: 0,
            need: Need::From(need_from),
            ahead: SettledAhead::new(threads),
        }
    }

    /// The room its next step needs, and an exact one.
    fn needs(&self) -> (f32, f32) {
        match &self.need {
            Need::From(need_from) => need_from[self.next],
            &Need::Each(any, exact) => (any, exact),
        }
    }

    /// Puts its steps in order as far as `end` at least: the greatest of the rest picked out
    /// and sorted, at least as many as are sorted already, so that a list the queue runs
    /// through is sorted in a few passes.
    fn sort_to(&mut self, end: usize) {
        if end <= self.sorted {
            return;
        }
        let end = end.max(2 * self.sorted).max(DEAR_SORTED_AT_ONCE).min(self.steps.len());
        let (rest, count) = (&mut self.steps[self.sorted..], end - self.sorted);
        if count < rest.len() {
            rest.select_nth_unstable_by(count - 1, |a, b| b.cmp(a));
        }
        rest[..count].sort_unstable_by(|a, b| b.cmp(a));
        self.sorted = end;
    }

    /// Its next step: before any is put in order, the best.
    fn head(&mut self) -> Option<&Step> {
        if self.sorted == 0 && self.best.is_some() {
            return self.best.as_ref();
        }
        self.sort_to(self.next + 1);
        self.steps.get(self.next)
    }
}

/// Where the queue's next step comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    /// One of its lists.
    Listed(usize),
    /// The steps of settled creatures ([`Follows`]).
    Followed,
    /// The steps of the groups of quiet creatures opened ([`QuietGroups`]).
    Opened,
}

/// A bound settled: the exact benefit, what the caller keeps of the settling, and the
/// creature's step from there.
struct Settled<S> {
    benefit: f32,
    kept: S,
    step: Option<Step>,
}

impl<S> Settled<S> {
    /// The bound `step` settled by `settle`, and its creature's next step.
    fn of<'a>(
        step: &Step,
        crowd: &(impl Crowd<'a> + ?Sized),
        hull: &Hull,
        settle: &impl Fn(usize) -> (f32, S),
    ) -> Self {
        let (benefit, kept) = settle(step.creature as usize);
        let mut c = crowd.candidate(step.creature as usize);
        c.benefit[Lod::Rigid as usize] = benefit;
        c.settled = true;
        let step = c.step_from(step.creature, step.from, hull, &c.priced(hull.hysteresis));
        Self { benefit, kept, step }
    }
}

/// The bounds further down the queue, settled ahead across the cores: by their place in the
/// list, in order. Each is settled and its next step worked out beside its creature, so the
/// queue's loop does not wait on a creature it has not looked at for a while.
struct SettledAhead<S> {
    threads: usize,
    /// How many bounds the next batch looks ahead for at most (it doubles with each batch).
    batch: usize,
    settled: std::collections::VecDeque<(usize, Settled<S>)>,
}

impl<S: Send> SettledAhead<S> {
    fn new(threads: usize) -> Self {
        Self {
            threads,
            batch: 4 * threads,
            settled: Default::default(),
        }
    }

    /// The bound listed at `at`, settled: made ahead, or made now together with the next
    /// unsettled bounds in the list, no more than `room_us` could pay for (on one thread, it
    /// alone).
    #[allow(clippy::too_many_arguments)]
    fn take<'a>(
        &mut self,
        at: usize,
        listed: &[Step],
        crowd: &(impl Crowd<'a> + ?Sized),
        settled_now: &[bool],
        hull: &Hull,
        room_us: f32,
        settle: &(impl Fn(usize) -> (f32, S) + Sync),
    ) -> Settled<S> {
        while self.settled.front().is_some_and(|s| s.0 < at) {
            self.settled.pop_front();
        }
        if self.settled.front().is_none_or(|s| s.0 != at) {
            let affordable = if hull.settle_us > 0.0 {
                (room_us / hull.settle_us) as usize
            } else {
                usize::MAX
            };
            let most = if self.threads > 1 {
                self.batch.min(affordable).max(1)
            } else {
                1
            };
            self.batch = (2 * self.batch).min(MAX_SETTLED_AHEAD);
            let places: Vec<usize> = (at..listed.len())
                .filter(|&i| listed[i].bound && !settled_now[listed[i].creature as usize])
                .take(most)
                .collect();
            let mut made: Vec<Option<Settled<S>>> = places.iter().map(|_| None).collect();
            let n = places.len().div_ceil(self.threads);
            run_chunks(places.chunks(n).zip(made.chunks_mut(n)).map(|(places, made)| {
                move || {
                    for (&i, m) in places.iter().zip(made) {
                        *m = Some(Settled::of(&listed[i], crowd, hull, settle));
                    }
                }
            }));
            self.settled = places.into_iter().zip(made.into_iter().flatten()).collect();
        }
        self.settled.pop_front().expect("the bound at the front was settled").1
    }
}

/// A run of steps of one ratio this long or longer is radix-sorted by serial ([`Step::sort`]).
const RADIX_SORTED_RUN: usize = 256;

/// A step needing over this share of the room the floors leave is dear ([`Listing`]): no more
/// than this many such steps fit.
const DEAR_STEPS: f32 = 1024.0;

/// The most bounds settled ahead at once.
const MAX_SETTLED_AHEAD: usize = 4096;

/// Every creature at its floor, gathered one by one before any benefit is worked out: what
/// the floors cost, and whether any creature's cheapest step up fits beside them (if not,
/// [`allocate`] gives every creature its floor, so they are the choice).
struct Floors {
    levels: Vec<Lod>,
    /// Each creature's level where no step fits ([`Floors::holding_cheap_levels`]).
    held: Vec<Lod>,
    /// What each creature adds to the frame as it will run at each level, by `Lod as usize`:
    /// the knapsack's closing sums read these, not the creatures' candidates.
    frame_at_us: Vec<[f32; 3]>,
    /// What the floors cost, us.
    cost_us: f32,
    /// The frame as it will run at the floors (creatures going down still cost their level), us.
    frame_us: f32,
    /// The frame as it will run at the levels held, us.
    held_frame_us: f32,
    /// The cheapest step up from any floor, us.
    cheapest_step_us: f32,
    /// Whether every creature's levels cost no less than the one below.
    rising: bool,
}

/// What one creature at its floor adds to [`Floors`]: the same for every creature of its kind
/// at that floor and level, so worked out once a decision for each.
#[derive(Clone, Copy, Debug)]
struct AtFloor {
    floor: Lod,
    /// Below its kind's dearest level, the level it has; else its floor.
    held: Lod,
    cost_us: f32,
    frame_at_us: [f32; 3],
    cheapest_step_us: f32,
    rising: bool,
}

impl From<&Candidate<'_>> for AtFloor {
    fn from(c: &Candidate) -> Self {
        let dearest = c.levels.iter().copied().max().unwrap_or(c.current);
        Self {
            floor: c.floor,
            held: if c.current < dearest { c.current } else { c.floor },
            cost_us: c.cost_us(c.floor),
            frame_at_us: Lod::ALL.map(|l| c.frame_cost_us(l)),
            cheapest_step_us: c.cheapest_step_above_floor_us(&c.priced(0.0)),
            rising: c.costs.rise_with_level(),
        }
    }
}

impl Floors {
    fn with_capacity(creatures: usize) -> Self {
        Self {
            levels: Vec::with_capacity(creatures),
            held: Vec::with_capacity(creatures),
            frame_at_us: Vec::with_capacity(creatures),
            cost_us: 0.0,
            frame_us: 0.0,
            held_frame_us: 0.0,
            cheapest_step_us: f32::INFINITY,
            rising: true,
        }
    }

    fn add(&mut self, c: AtFloor) {
        self.levels.push(c.floor);
        self.held.push(c.held);
        self.frame_at_us.push(c.frame_at_us);
        self.cost_us += c.cost_us;
        self.frame_us += c.frame_at_us[c.floor as usize];
        self.held_frame_us += c.frame_at_us[c.held as usize];
        self.cheapest_step_us = self.cheapest_step_us.min(c.cheapest_step_us);
        self.rising &= c.rising;
    }

    /// `count` creatures' floors, a part of [`FLOORS_PART`] at a time across `threads` cores,
    /// each part's added by `fill(first, part)` from the creature at `first` on. The parts'
    /// sums are added in their order: the same on any number of cores, and those of a single
    /// part the same as one by one.
    fn gathered(count: usize, threads: usize, fill: impl Fn(usize, &mut Floors) + Sync) -> Self {
        let mut parts: Vec<Option<Floors>> = (0..count.div_ceil(FLOORS_PART)).map(|_| None).collect();
        each_part(&mut parts, threads, |p, slot| {
            let first = p * FLOORS_PART;
            let mut part = Floors::with_capacity(FLOORS_PART.min(count - first));
            fill(first, &mut part);
            *slot = Some(part);
        });
        let mut floors = Floors::with_capacity(count);
        for part in parts.into_iter().flatten() {
            floors.levels.extend(part.levels);
            floors.held.extend(part.held);
            floors.frame_at_us.extend(part.frame_at_us);
            floors.cost_us += part.cost_us;
            floors.frame_us += part.frame_us;
            floors.held_frame_us += part.held_frame_us;
            floors.cheapest_step_us = floors.cheapest_step_us.min(part.cheapest_step_us);
            floors.rising &= part.rising;
        }
        floors
    }

    /// What a step must need to be dear ([`Listing`]): over a [`DEAR_STEPS`]th of the room the
    /// floors leave in `budget_us`. Where a level can cost less than the one below, none is
    /// (what is spent does not only grow, so no list of steps is ever passed by).
    fn dear_us(&self, budget_us: f32) -> f32 {
        if self.rising {
            (budget_us - self.cost_us) / DEAR_STEPS
        } else {
            f32::INFINITY
        }
    }

    fn any_step_fits(&self, budget_us: f32) -> bool {
        self.cost_us + self.cheapest_step_us <= budget_us
    }

    /// Each creature below its kind's dearest level kept at the level it has, not sent to its
    /// floor; the frame as it will run then.
    fn holding_cheap_levels(mut self) -> Self {
        (self.levels, self.frame_us) = (std::mem::take(&mut self.held), self.held_frame_us);
        self
    }

    /// The floors as the allocation, within `budget_us` beside what a frame costs whatever
    /// its creatures' levels (`overhead_us`).
    fn allocation<S>(self, budget_us: f32, overhead_us: f32) -> Allocation<S> {
        Allocation {
            predicted_us: self.frame_us + overhead_us,
            exceeded: self.frame_us + overhead_us > budget_us,
            levels: self.levels,
            settled: Vec::new(),
            quiet: 0,
        }
    }
}

/// The adaptive mode's correction of the cost model after one more measured frame: the
/// measured over the predicted time, smoothed over about `frames` frames. A ratio beyond 10
/// either way (a stalled frame) counts as 10. A frame measured over `emergency_us` (the
/// emergency tier) sets the correction at once to its own ratio, where that is higher.
fn corrected(correction: f32, model_us: f32, measured_us: f32, frames: f32, emergency_us: f32) -> f32 {
    if model_us <= 0.0 || !measured_us.is_finite() {
        return correction;
    }
    let ratio = (measured_us / model_us).clamp(0.1, 10.0);
    let smoothed = correction + (ratio - correction) / frames.max(1.0);
    if measured_us > emergency_us {
        smoothed.max(ratio)
    } else {
        smoothed
    }
}

/// The percentile mode's last frames: what each took beyond its corrected prediction (us),
/// oldest first.
#[derive(Clone, Debug, Default)]
pub struct RecentFrames {
    excess_us: VecDeque<f32>,
    ranked: Vec<f32>,
}

impl RecentFrames {
    /// Adds `excess_us` to the last `frames` and gives their `percentile` by nearest rank
    /// (100: the highest).
    pub fn percentile_with(&mut self, excess_us: f32, frames: usize, percentile: f32) -> f32 {
        self.excess_us.push_back(excess_us);
        while self.excess_us.len() > frames.max(1) {
            self.excess_us.pop_front();
        }
        self.ranked.clear();
        self.ranked.extend(&self.excess_us);
        let at = nearest_rank(self.ranked.len(), percentile);
        *self.ranked.select_nth_unstable_by(at, f32::total_cmp).1
    }
}

/// The percentile mode reads its percentile among the last frames where this many of them lie
/// beyond it, so that a slow frame as rare as the percentile allows is among them, and one stall
/// alone does not set the headroom. Of the last 30 frames, the 99th percentile is their slowest:
/// a machine whose slow frames come a few in a hundred often had none in the window, spent the
/// budget whole and met the next one over it. `simlod experiment budget-scale`'s games keeping
/// the 99th percentile kept the budget in 9 and 9 of the 14 whose cheapest levels fit, and over
/// the last 300 frames in 14 and 14, their mean frame at 0.56 to 0.58 of the budget against 0.62
/// to 0.67 (runs in turn, 2026-12-01).
const FRAMES_BEYOND_THE_PERCENTILE: f32 = 3.0;

/// How many of the last frames the percentile mode takes its `percentile` (50 to 100) of: at
/// least `adaptive_frames`, and enough that three lie beyond it (99: the last 300, 10 s of
/// decisions at 30 a second; 100: the slowest of `adaptive_frames`), at most 10,000.
pub fn percentile_window(adaptive_frames: f32, percentile: f32) -> usize {
    let beyond = if percentile < 100.0 {
        (FRAMES_BEYOND_THE_PERCENTILE * 100.0 / (100.0 - percentile)).ceil()
    } else {
        0.0
    };
    adaptive_frames.max(beyond).clamp(1.0, 10_000.0) as usize
}

/// Where the `percentile` (0 to 100) of `len` values lies among them sorted, by nearest rank:
/// the smallest that as many hundredths of them are at or under (100: the highest).
pub fn nearest_rank(len: usize, percentile: f32) -> usize {
    let rank = (f64::from(percentile) / 100.0 * len as f64).ceil() as usize;
    rank.clamp(1, len.max(1)) - 1
}

/// What the budget policy predicted, decision by decision (the summary and the HUD read it).
#[derive(Resource, Clone, Debug)]
pub struct BudgetTally {
    /// The last decision's predicted simulation time of a frame by the cost model alone.
    pub model_us: f32,
    /// The adaptive mode's measured over predicted time, smoothed; 1 when it is off.
    pub correction: f32,
    /// The percentile mode's headroom: the rules' percentile of what the last frames took
    /// beyond their corrected prediction, us, kept free of the budget (0 in the mean mode).
    pub headroom_us: f32,
    /// The wall time the last frame's simulation took, per 1/30 s of motion (a decision's
    /// ticks), written from outside the simulation by whoever steps it (the game, the headless
    /// runner). Only the adaptive mode reads it. (Here and not a resource of its own: a new
    /// resource is a new entity, which moves the rigid bodies' entity ids and so rapier's
    /// rounding.)
    pub measured_us: Option<f32>,
    /// Decisions taken under the budget policy.
    pub decisions: u64,
    /// Decisions whose predicted frame did not fit the budget even at the cheapest levels
    /// allowed.
    pub over_budget: u64,
    /// The predicted frames' sum, us (for the mean).
    pub predicted_sum_us: f64,
    /// The slowest predicted frame, us.
    pub predicted_max_us: f32,
    /// Creatures searched for contacts with others, over all decisions.
    pub searched: u64,
    /// Creatures left quiet, their benefits not worked out, over all decisions.
    pub quiet: u64,
    /// The percentile mode's last frames.
    pub recent: RecentFrames,
    /// Frames measured so far, each of which corrected the model (the adaptive mode).
    pub frames_measured: u32,
}

/// The budget policy's run, in the summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BudgetSummary {
    /// The frame budget, ms of simulation per 1/30 s.
    pub frame_budget_ms: f32,
    /// The predicted frame on average, ms.
    pub predicted_ms_mean: f64,
    /// The slowest predicted frame, ms.
    pub predicted_ms_max: f32,
    /// Decisions taken under the budget policy.
    pub decisions: u64,
    /// Decisions where even the cheapest levels allowed were predicted over the budget.
    pub decisions_over_budget: u64,
    /// Creatures searched for contacts with other creatures per decision, on average (the
    /// choice searches only those that could still buy a level).
    pub searched_per_decision: f64,
    /// Creatures left quiet per decision, on average: out of view, at their floor, their
    /// benefits never worked out (the incremental choice, where working out every creature
    /// would cost more than the room it leaves).
    pub quiet_per_decision: f64,
    /// Whether the adaptive mode corrected the cost model (the run is then not reproducible),
    /// and its last correction (measured over predicted; 1 when off).
    pub adaptive: bool,
    /// The adaptive mode's last correction, measured over predicted (1 when off).
    pub correction: f32,
    /// What the adaptive mode kept at the budget: 0 the mean frame, else this percentile of
    /// the last frames.
    pub adaptive_percentile: f32,
    /// In the percentile mode, how many times the budget that percentile was kept within (the
    /// mean within the budget itself).
    pub adaptive_percentile_limit: f32,
}

impl Default for BudgetTally {
    fn default() -> Self {
        Self {
            model_us: 0.0,
            correction: 1.0,
            headroom_us: 0.0,
            measured_us: None,
            decisions: 0,
            over_budget: 0,
            predicted_sum_us: 0.0,
            predicted_max_us: 0.0,
            searched: 0,
            quiet: 0,
            recent: RecentFrames::default(),
            frames_measured: 0,
        }
    }
}

impl BudgetTally {
    /// The last decision's predicted simulation time of a frame: the cost model's, times the
    /// adaptive correction, and in the percentile mode with its headroom (the frame at that
    /// percentile).
    pub fn predicted_us(&self) -> f32 {
        self.model_us * self.correction + self.headroom_us
    }

    /// The rules' budget as the cost model is to spend it, over the correction: the mean frame
    /// within the budget, and in the percentile mode the percentile (the mean with its headroom)
    /// within `adaptive_percentile_limit` times it.
    fn model_budget_us(&self, rules: &BudgetRules) -> f32 {
        let budget_us = rules.frame_budget_ms * 1e3;
        let percentile_us = budget_us * rules.adaptive_percentile_limit - self.headroom_us;
        percentile_us.min(budget_us).max(0.0) / self.correction
    }

    /// The adaptive mode after a frame: its measured time (taken, so that each frame counts
    /// once) corrects the cost model toward the mean frame; in the percentile mode, what the
    /// frame took beyond that prediction joins the last frames', whose percentile is kept free
    /// of the budget (of its `adaptive_percentile_limit` times). Frames that vary by a share of
    /// their work or by a stall alike then keep that percentile within the budget, and a crowd
    /// at its floors is not held there by a stall many times its small prediction.
    fn correct(&mut self, rules: &BudgetRules) {
        let Some(measured_us) = self.measured_us.take() else {
            return;
        };
        if self.model_us <= 0.0 || !measured_us.is_finite() {
            return;
        }
        let emergency_us = if rules.emergency_over > 0.0 {
            rules.emergency_over * rules.frame_budget_ms * 1e3
        } else {
            f32::INFINITY
        };
        let predicted_us = self.model_us * self.correction;
        self.correction = corrected(
            self.correction,
            self.model_us,
            measured_us,
            rules.adaptive_frames,
            emergency_us,
        );
        self.frames_measured += 1;
        // The first `adaptive_frames` frames are left out of the percentile: the world's bodies
        // built, every creature's first search, and a correction not yet settled, so what they
        // take beyond the prediction is the model's error being corrected, not the machine's
        // spread. Counted, a round's first second set the headroom for its next ten (the
        // 99th percentile of 300 frames), and held 40 creatures at 1 ms at their floors in a
        // third of the decisions (2026-12-02).
        if rules.adaptive_percentile > 0.0 && self.frames_measured as f32 > rules.adaptive_frames {
            self.headroom_us = self.recent.percentile_with(
                measured_us - predicted_us,
                percentile_window(rules.adaptive_frames, rules.adaptive_percentile),
                rules.adaptive_percentile,
            );
        }
    }

    /// The run so far under `rules`, as the summary reports it.
    pub fn summary(&self, rules: &BudgetRules) -> BudgetSummary {
        BudgetSummary {
            frame_budget_ms: rules.frame_budget_ms,
            predicted_ms_mean: self.predicted_sum_us / self.decisions.max(1) as f64 / 1e3,
            predicted_ms_max: self.predicted_max_us / 1e3,
            decisions: self.decisions,
            decisions_over_budget: self.over_budget,
            searched_per_decision: self.searched as f64 / self.decisions.max(1) as f64,
            quiet_per_decision: self.quiet as f64 / self.decisions.max(1) as f64,
            adaptive: rules.adaptive_frames > 0.0,
            correction: self.correction,
            adaptive_percentile: rules.adaptive_percentile,
            adaptive_percentile_limit: rules.adaptive_percentile_limit,
        }
    }

    fn record<S>(&mut self, a: &Allocation<S>) {
        self.model_us = a.predicted_us;
        self.decisions += 1;
        self.over_budget += u64::from(a.exceeded);
        self.searched += a.settled.len() as u64;
        self.quiet += a.quiet as u64;
        self.predicted_sum_us += f64::from(self.predicted_us());
        self.predicted_max_us = self.predicted_max_us.max(self.predicted_us());
    }
}

/// Seconds until two discs, `d` apart (one's centre minus the other's) with relative velocity
/// `w`, come within `reach` of each other on their present courses: 0 if they are, infinite if
/// they never do.
pub fn time_to_contact(d: Vec2, w: Vec2, reach: f32) -> f32 {
    let c = d.length_squared() - reach * reach;
    if c <= 0.0 {
        return 0.0;
    }
    let (a, b) = (w.length_squared(), 2.0 * d.dot(w));
    let disc = b * b - 4.0 * a * c;
    if a <= 1e-12 || b >= 0.0 || disc < 0.0 {
        return f32::INFINITY;
    }
    (-b - disc.sqrt()) / (2.0 * a)
}

/// `e^x`, without the library's slow path for a result that underflows to 0 (most creatures
/// of a crowd are that far from any contact): below -104 it is 0 (under half the least
/// subnormal), as the library would round it.
fn decay(x: f32) -> f32 {
    if x < -104.0 { 0.0 } else { x.exp() }
}

/// The first ring of the search for the soonest contact with another creature, m.
const NEAREST_RING_M: f32 = 4.0;

/// A circle a creature may meet, and how fast a creature can close on it at most.
struct Circle {
    area: Area,
    closing_m_per_s: f32,
}

impl Circle {
    /// The puck and the host's `areas` of influence (weighed as the puck is), for creatures
    /// of at most `top_speed`: each one's closing speed worked out once a decision.
    fn of(puck: &PuckState, areas: Vec<Area>, top_speed: f32) -> Vec<Circle> {
        let puck = Area {
            position: puck.position,
            velocity: puck.velocity,
            radius_m: puck.radius_m,
        };
        (std::iter::once(puck).chain(areas))
            .map(|area| Circle {
                closing_m_per_s: (top_speed + area.velocity.length()).max(1e-3),
                area,
            })
            .collect()
    }
}

/// What the benefits are computed from at one decision.
struct Scene<'a> {
    rules: &'a BudgetRules,
    /// The puck, then the host's areas of influence.
    circles: Vec<Circle>,
    court: &'a Court,
    grid: &'a NeighbourGrid,
    camera: &'a SimCamera,
    /// Each kind's reach against the view, by kind.
    view_reach: Vec<ViewReach>,
    /// The fastest kind's top speed, for the earliest possible contacts.
    top_speed: f32,
    /// The widest kind's footprint radius, m.
    widest_m: f32,
    /// How far away another creature can still matter.
    reach_m: f32,
    /// The latest times at which the puck or an area, and a wall, can be worth as much as a
    /// contact with another creature ([`outweigh_times_s`]).
    outweigh_creature_s: ([f32; 2], [f32; 2]),
}

impl Scene<'_> {
    /// How much a contact on the present course `t_course` seconds away, and at the
    /// earliest `t_worst` away, is worth.
    fn urgency(&self, t_course: f32, t_worst: f32) -> f32 {
        let h = self.rules.contact_horizon_s;
        decay(-t_course / h).max(self.rules.worst_case_share * decay(-t_worst / h))
    }

    /// When a contact could come with `circle`.
    fn circle(&self, s: &PlanarState, radius: f32, circle: &Circle) -> ContactTimes {
        let c = &circle.area;
        let d = s.position - c.position;
        let reach = radius + c.radius_m + self.rules.contact_margin_m;
        let gap = (d.length() - reach).max(0.0);
        ContactTimes {
            course_s: time_to_contact(d, s.velocity - c.velocity, reach),
            worst_s: gap / circle.closing_m_per_s,
        }
    }

    /// How urgent the contacts with the puck, the host's areas and the walls are, weighed (the
    /// rigid level's benefit from contacts, before other creatures are searched).
    fn near_benefit(&self, near: &Near) -> f32 {
        let r = self.rules;
        let weighed = |weight: f32, t: ContactTimes| weight * self.urgency(t.course_s, t.worst_s);
        weighed(r.puck_weight, near.puck).max(weighed(r.wall_weight, near.wall))
    }

    /// Whether the puck, the areas or the walls could be worth as much as a contact with
    /// another creature now: tested on the times, against [`Scene::outweigh_creature_s`], with
    /// no exponential worked out (most of a crowd is too far).
    fn may_outweigh_a_creature(&self, near: &Near) -> bool {
        let ([puck_course, puck_worst], [wall_course, wall_worst]) = self.outweigh_creature_s;
        near.puck.course_s <= puck_course
            || near.puck.worst_s <= puck_worst
            || near.wall.course_s <= wall_course
            || near.wall.worst_s <= wall_worst
    }

    /// How soon a contact could come with the puck, the host's areas or a wall.
    fn near(&self, s: &PlanarState, radius: f32) -> Near {
        let margin = self.rules.contact_margin_m;
        // The puck, and the host's areas of influence.
        let (puck, areas) = self.circles.split_first().expect("the puck is a circle");
        let mut soonest = self.circle(s, radius, puck);
        for a in areas {
            soonest = soonest.sooner(self.circle(s, radius, a));
        }
        // The walls: the nearest on each axis.
        let room = self.court.half_extents - Vec2::splat(radius + margin) - s.position.abs();
        let along = s.velocity * s.position.signum();
        let course = |room: f32, v: f32| {
            if room <= 0.0 {
                0.0
            } else if v > 0.0 {
                room / v
            } else {
                f32::INFINITY
            }
        };
        let gap = room.min_element().max(0.0);
        Near {
            puck: soonest,
            wall: ContactTimes {
                course_s: course(room.x, along.x).min(course(room.y, along.y)),
                worst_s: gap / self.top_speed.max(1e-3),
            },
        }
    }

    /// How urgent the soonest contact with another creature is (0 to 1).
    fn crowding(&self, c: &Creature, s: &PlanarState, radius: f32) -> f32 {
        let margin = self.rules.contact_margin_m;
        // Other creatures: urgency falls with time, so only the soonest contacts count (one
        // urgency per creature, not one per neighbour).
        // Nearest first: beyond a ring, a creature is at least `gap` away and closes at most at
        // the fastest speeds, so once that bound is worth no more than the soonest contact
        // found, the rest cannot change it (the same value as a search of the whole reach).
        let (t_course, t_worst) = (Cell::new(f32::INFINITY), Cell::new(f32::INFINITY));
        let closing = (2.0 * self.top_speed).max(1e-3);
        let (fastest, widest) = self.grid.fastest_and_widest();
        let closing_on_course = (s.velocity.length() + fastest).max(1e-3);
        self.grid.for_each_nearest_first(
            s.position,
            NEAREST_RING_M,
            self.reach_m,
            |n| {
                if n.serial == c.serial {
                    return;
                }
                let d = s.position - n.position;
                let reach = radius + n.radius + margin;
                t_worst.set(t_worst.get().min((d.length() - reach).max(0.0) / closing));
                t_course.set(t_course.get().min(time_to_contact(d, s.velocity - n.velocity, reach)));
            },
            |ring| {
                let gap = (ring - (radius + widest + margin)).max(0.0);
                self.urgency(gap / closing_on_course, gap / closing) <= self.urgency(t_course.get(), t_worst.get())
            },
        );
        self.urgency(t_course.get(), t_worst.get())
    }

    /// How much the viewer sees of a creature: 0 out of view, 1 at the camera, halving at
    /// `view_half_distance_m`.
    fn view(&self, reach: &ViewReach, s: &PlanarState) -> f32 {
        let distance = self.camera.ground_distance(s.position);
        if self.camera.sees_within(reach, s.position, distance) {
            1.0 / (1.0 + distance / self.rules.view_half_distance_m)
        } else {
            0.0
        }
    }

    /// What one creature's levels are worth before its search for contacts with other
    /// creatures: exact for the point mass and the hybrid, the most it can be for the rigid
    /// level, unless the puck, an area or a wall already outweighs any other creature.
    fn bounds(&self, entity: Entity, s: &PlanarState, kind: usize, radius_m: f32) -> Bounds {
        let r = self.rules;
        let view = self.view(&self.view_reach[kind], s);
        let hybrid = r.view_hybrid_weight * view;
        let followed = if self.camera.following == Some(entity) {
            r.player_rigid_weight
        } else {
            0.0
        };
        Bounds {
            hybrid,
            seen: hybrid + r.view_rigid_weight * view + followed,
            near: self.near(s, radius_m),
        }
    }
}

impl Scene<'_> {
    /// The court in tiles of about [`CREATURES_PER_TILE`] creatures of `creatures`, each tested
    /// once against the view and the nearest contacts ([`Tiles`]).
    fn tiles(&self, creatures: usize) -> Tiles {
        let half = self.court.half_extents;
        let tiles = (creatures / CREATURES_PER_TILE).max(1) as f32;
        let tile_m = (4.0 * half.x * half.y / tiles).sqrt().max(SMALLEST_TILE_M);
        let (cols, rows) = (
            (2.0 * half.x / tile_m).ceil().max(1.0) as u32,
            (2.0 * half.y / tile_m).ceil().max(1.0) as u32,
        );
        // A centimetre more on each side, for the rounding of a creature's place into its tile.
        let slack = Vec2::splat(0.01);
        // A creature may run a little over its kind's top speed (pushed, or rounding).
        let fastest = self.top_speed.max(self.grid.fastest_and_widest().0);
        let near = (0..rows)
            .flat_map(|y| (0..cols).map(move |x| -half + tile_m * Vec2::new(x as f32, y as f32)))
            .map(|lo| {
                let (lo, hi) = (lo - slack, lo + Vec2::splat(tile_m) + slack);
                let out_of_view = self
                    .view_reach
                    .iter()
                    .all(|reach| self.camera.sees_none_within(reach, lo, hi));
                if out_of_view {
                    self.near_at_most(lo, hi, fastest)
                } else {
                    -1.0
                }
            })
            .collect();
        Tiles {
            min: -half,
            inv_tile_m: 1.0 / tile_m,
            cols,
            rows,
            fastest_m_per_s: fastest,
            near,
        }
    }

    /// The most [`Scene::near_benefit`] can be for a creature no faster than `fastest_m_per_s`
    /// on the ground in `lo..hi`: its contacts no sooner than the box's gaps allow, on its
    /// course at that speed and at the earliest at its kind's.
    fn near_at_most(&self, lo: Vec2, hi: Vec2, fastest_m_per_s: f32) -> f32 {
        let margin = self.rules.contact_margin_m;
        let mut puck = ContactTimes {
            course_s: f32::INFINITY,
            worst_s: f32::INFINITY,
        };
        for circle in &self.circles {
            let a = &circle.area;
            let gap = (a.position.distance(a.position.clamp(lo, hi)) - (self.widest_m + a.radius_m + margin)).max(0.0);
            puck = puck.sooner(ContactTimes {
                course_s: gap / (fastest_m_per_s + a.velocity.length()).max(1e-3),
                worst_s: gap / circle.closing_m_per_s,
            });
        }
        let room = self.court.half_extents - Vec2::splat(self.widest_m + margin) - lo.abs().max(hi.abs());
        let gap = room.min_element().max(0.0);
        let wall = ContactTimes {
            course_s: gap / fastest_m_per_s.max(1e-3),
            worst_s: gap / self.top_speed.max(1e-3),
        };
        self.near_benefit(&Near { puck, wall })
    }
}

/// Creatures a tile of [`Tiles`] holds on average, in a crowd at the default game's density.
const CREATURES_PER_TILE: usize = 32;

/// The smallest tile, m.
const SMALLEST_TILE_M: f32 = 4.0;

/// The court in square tiles, each with whether any creature in it may be in view and the most
/// its contacts with the puck, the host's areas and the walls can be worth: what a quiet
/// creature's group is bounded by ([`QuietGroups`]).
struct Tiles {
    min: Vec2,
    inv_tile_m: f32,
    cols: u32,
    rows: u32,
    /// The fastest speed the tiles' bounds hold for: a faster creature is never quiet.
    fastest_m_per_s: f32,
    /// By tile, row by row: [`Scene::near_at_most`], negative where a creature may be in view.
    near: Vec<f32>,
}

impl Tiles {
    /// The most a creature at `s` out of view can gain from the puck, the areas and the walls;
    /// none if it may be in view (or is faster than any kind, or off the court).
    fn quiet_near(&self, s: &PlanarState) -> Option<f32> {
        if s.velocity.length_squared() > self.fastest_m_per_s * self.fastest_m_per_s {
            return None;
        }
        let at = (s.position - self.min) * self.inv_tile_m;
        if !(at.x >= 0.0 && at.y >= 0.0) {
            return None;
        }
        let (x, y) = (at.x as u32, at.y as u32);
        if x >= self.cols || y >= self.rows {
            return None;
        }
        Some(self.near[(y * self.cols + x) as usize]).filter(|&near| near >= 0.0)
    }
}

/// Rows of a decision in a group of quiet creatures ([`QuietGroups`]): a bit of a `u64` each.
const GROUP_ROWS: usize = 64;

/// What a group's quiet creatures' steps can be, gathered row by row: their one step each (out
/// of view, at their floor, a quiet creature can only go rigid, for contacts). A group's rows
/// are in two: those whose step is a bound to be settled by a search (group `2 g`), and those
/// whose step may be exact (`2 g + 1`: a search standing, or the puck or a wall outweighing any
/// other creature), so that where no search fits, only the second is opened.
#[derive(Clone, Copy, Debug)]
struct QuietGroup {
    /// Its creatures with a step, a bit a row.
    members: u64,
    /// The most benefit per microsecond any of their steps can have, and the lowest serial.
    ratio: f32,
    serial: u32,
    /// The least room any of their steps needs.
    need_us: f32,
}

impl Default for QuietGroup {
    fn default() -> Self {
        Self {
            members: 0,
            ratio: 0.0,
            serial: u32::MAX,
            need_us: f32::INFINITY,
        }
    }
}

impl QuietGroup {
    fn add(&mut self, row: usize, ratio: f32, serial: u32, need_us: f32) {
        self.members |= 1 << (row % GROUP_ROWS);
        self.ratio = self.ratio.max(ratio);
        self.serial = self.serial.min(serial);
        self.need_us = self.need_us.min(need_us);
    }

    /// A quiet creature's one step, to rigid, into its group's two (`pair`): worth at most
    /// `rigid_at_most`, adding `extra_us`, and a bound to be settled unless `may_be_exact`.
    fn gather(
        pair: &mut [QuietGroup],
        (row, serial): (usize, u32),
        rigid_at_most: f32,
        extra_us: f32,
        may_be_exact: bool,
        hull: &Hull,
    ) {
        if rigid_at_most <= 0.0 {
            return;
        }
        let ratio = if extra_us > 0.0 {
            rigid_at_most / extra_us
        } else {
            f32::INFINITY
        };
        if ratio >= hull.least_per_us {
            let need_us = if may_be_exact {
                extra_us
            } else {
                hull.settle_us + extra_us
            };
            pair[usize::from(may_be_exact)].add(row, ratio, serial, need_us);
        }
    }

    /// Group `group`'s creatures' steps up their hulls into `opened`, each marked in
    /// `settled_now` as it is.
    fn open<'a>(
        group: usize,
        members: u64,
        crowd: &(impl Crowd<'a> + ?Sized),
        hull: &Hull,
        settled_now: &mut [bool],
        opened: &mut BinaryHeap<Step>,
    ) {
        let mut members = members;
        while members != 0 {
            let i = group / 2 * GROUP_ROWS + members.trailing_zeros() as usize;
            members &= members - 1;
            let c = crowd.candidate(i);
            settled_now[i] = c.settled;
            c.list_hull(i as u32, hull, &c.priced(hull.hysteresis), |step| opened.push(step));
        }
    }
}

/// The quiet creatures of a decision (out of view in a tile the view cone misses, at the level
/// last chosen and their floor, not followed) by groups of [`GROUP_ROWS`] rows, each group one
/// step above all of theirs: their benefits are worked out only for a group that reaches the
/// front of the queue with room for a step of its own, and that costs the budget what it saves
/// (Funkhouser & Sequin's incremental choice, taken to crowds).
#[derive(Default)]
struct QuietGroups {
    /// A step for each group with members, sorted.
    steps: Vec<Step>,
    /// By group: the room its steps need, any and an exact one, its opening beside.
    needs: Vec<(f32, f32)>,
    /// By group: what working out its creatures costs, and how many there are.
    open_us: Vec<f32>,
    members: Vec<u32>,
}

impl QuietGroups {
    /// The groups gathered, a creature's working out at `evaluate_us`.
    fn of(groups: &[QuietGroup], evaluate_us: f32) -> Self {
        let mut all = Self::default();
        for (g, q) in (0..).zip(groups) {
            let open = evaluate_us * q.members.count_ones() as f32;
            let exact_us = if g % 2 == 1 { q.need_us } else { f32::INFINITY };
            all.needs.push((open + q.need_us, open + exact_us));
            all.open_us.push(open);
            all.members.push(q.members.count_ones());
            if q.members != 0 {
                all.steps.push(Step {
                    ratio: q.ratio,
                    bound: false,
                    serial: q.serial,
                    creature: g,
                    // Below any creature's step up, so above it among equals.
                    from: Lod::PointMass,
                    to: Lod::PointMass,
                    extra_us: open + q.need_us,
                    running_us: 0.0,
                    group: true,
                });
            }
        }
        Step::sort(&mut all.steps);
        all
    }
}

/// How soon a contact could come: on the present courses, and at the earliest, s.
#[derive(Clone, Copy, Debug, Default)]
struct ContactTimes {
    course_s: f32,
    worst_s: f32,
}

impl ContactTimes {
    fn sooner(self, other: Self) -> Self {
        Self {
            course_s: self.course_s.min(other.course_s),
            worst_s: self.worst_s.min(other.worst_s),
        }
    }
}

/// How soon a creature could meet the puck or one of the host's areas (weighed alike), and a
/// wall. Urgency falls with time, so the soonest of each weight is all that counts.
#[derive(Clone, Copy, Debug, Default)]
struct Near {
    puck: ContactTimes,
    wall: ContactTimes,
}

/// The latest times, on the course and at the earliest, at which a contact weighed `weight`
/// can still be worth `creature_weight` (urgency `e^(-t/horizon)`, the worst case at its
/// share), widened a little so that rounding never leaves out one that is: the test only
/// spares the exponentials, and what passes it is weighed exactly.
fn outweigh_times_s(rules: &BudgetRules, weight: f32) -> [f32; 2] {
    let latest = |worth: f32| {
        if rules.creature_weight <= 0.0 {
            f32::INFINITY
        } else if worth <= 0.0 {
            f32::NEG_INFINITY
        } else {
            let t = rules.contact_horizon_s * (worth / rules.creature_weight).ln();
            t + t.abs() * 1e-3 + 1e-3
        }
    };
    [latest(weight), latest(weight * rules.worst_case_share)]
}

/// One creature's benefits before its search for contacts with other creatures.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    hybrid: f32,
    /// The rigid level's benefit from the view and the player.
    seen: f32,
    /// How soon the puck, an area or a wall could be met.
    near: Near,
}

impl Bounds {
    /// The rigid level's benefit with contacts with other creatures at `crowding`. The puck,
    /// the areas and the walls are weighed only where they could outweigh those contacts.
    fn rigid(&self, scene: &Scene, crowding: f32) -> f32 {
        let creatures = scene.rules.creature_weight * crowding;
        let near = if crowding >= 1.0 && !scene.may_outweigh_a_creature(&self.near) {
            0.0
        } else {
            scene.near_benefit(&self.near)
        };
        self.seen + near.max(creatures)
    }

    /// Whether no other creature can change the rigid level's benefit.
    fn settled(&self, scene: &Scene) -> bool {
        scene.may_outweigh_a_creature(&self.near) && scene.near_benefit(&self.near) >= scene.rules.creature_weight
    }
}

type CreatureRow = (
    Entity,
    &'static Creature,
    &'static Lod,
    &'static PlanarState,
    &'static mut LevelChoice,
);

type Creatures<'w, 's> = Query<'w, 's, CreatureRow>;

/// One decision of the budget policy, in the query's order: settled are the creatures searched
/// for contacts with others (by their place in the query, in order), and how urgent their
/// soonest contact is.
impl Allocation<f32> {
    /// Keeps a creature's search for `contact_recheck_s`: its choice's new level, and its
    /// search if it had one.
    fn write(
        &self,
        searched: &mut std::iter::Peekable<std::slice::Iter<(usize, f32)>>,
        row: usize,
        now_s: f32,
        choice: &mut LevelChoice,
    ) {
        let level = self.levels[row];
        if choice.wanted != level {
            choice.wanted = level;
        }
        if let Some(&(_, urgency)) = searched.next_if(|s| s.0 == row) {
            choice.crowding = Some((urgency, now_s));
        }
    }
}

/// Creatures dealt to a core at a time by the budget's choice.
const DEALT_BLOCK: usize = 1024;

/// Creatures whose floors are summed together before the parts' sums are ([`Floors::gathered`]).
const FLOORS_PART: usize = 4096;

/// Runs `work` on each of `parts` with its place, a run of them on each of `threads` cores.
fn each_part<T: Send>(parts: &mut [T], threads: usize, work: impl Fn(usize, &mut T) + Sync) {
    let per_thread = parts.len().div_ceil(threads.max(1)).max(1);
    run_chunks(parts.chunks_mut(per_thread).enumerate().map(|(t, run)| {
        let work = &work;
        move || {
            for (k, part) in run.iter_mut().enumerate() {
                work(t * per_thread + k, part);
            }
        }
    }));
}

/// The allocation for every creature now, in the query's order; `starting`, for a new world's
/// creatures, built at the levels it gives them.
fn decide(
    now_s: f32,
    config: &SimConfig,
    kinds: &KindTable,
    scene: &Scene,
    creatures: &Creatures,
    budget_us: f32,
    starting: bool,
) -> Allocation<f32> {
    let readonly = creatures.as_readonly();
    let tables = Tables::of(&readonly);
    // The rigid level at its cost among the rigid creatures there are now.
    let rigid = tables
        .tables
        .iter()
        .map(|t| t.2.iter().filter(|&&l| l == Lod::Rigid).count())
        .sum::<usize>();
    let mut costs = config.costs_by_kind(rigid as u32);
    // A creature built at the hybrid level switches to it in no frame. Priced as in play, a
    // crowd of 3,000 came up to it a few hundred a frame, with no room for a rigid creature
    // meanwhile. (The rigid level's building stays priced at the start, as it always was: a
    // few creatures' worth, it keeps the runs of the budget experiment as they were.)
    if starting {
        costs.iter_mut().for_each(|c| c.cheap_switch_us = 0.0);
    }
    // Whether a kind keeps each level as its floor, worked out once.
    let held: Vec<[bool; 3]> = (kinds.0.iter().zip(&costs))
        .map(|(kind, costs)| Lod::ALL.map(|l| costs.holds(l, kind.levels[0])))
        .collect();
    let floor = |c: &Creature, lod: Lod, choice: &LevelChoice| {
        let dwelling = choice.switched && now_s - choice.last_switch_s < config.rules.min_dwell_s;
        if dwelling || held[c.kind][lod as usize] {
            lod
        } else {
            kinds[c.kind].levels[0]
        }
    };
    // Each kind at each floor and level, once.
    let at_floor: Vec<[[AtFloor; 3]; 3]> = (kinds.0.iter().zip(&costs))
        .map(|(kind, &costs)| {
            Lod::ALL.map(|floor| {
                Lod::ALL.map(|current| {
                    let c = Candidate {
                        serial: 0,
                        current,
                        last: current,
                        floor,
                        levels: &kind.levels,
                        costs,
                        benefit: [0.0; 3],
                        settled: true,
                    };
                    (&c).into()
                })
            })
        })
        .collect();
    let count = tables.len();
    // A table's slices at a time: a row apiece through `Tables::rows` (its flattening's checks
    // at every row) made this pass about twice as slow among 100,000 creatures.
    let cores = threads_for(config.scenario.creature_count());
    let floors = Floors::gathered(count, cores, |first, part| {
        for (_, c, lod, _, choice) in tables.parts(first, first + FLOORS_PART) {
            for ((c, &lod), choice) in c.iter().zip(lod).zip(choice) {
                part.add(at_floor[c.kind][floor(c, lod, choice) as usize][lod as usize]);
            }
        }
    });
    // The frame's fixed cost (court, puck, schedule) and this choice's come off the budget
    // first. Quiet creatures are left to their groups, their working out paid for only if
    // their group is opened, where working out every creature would leave no room for a step
    // (a crowd whose choice would otherwise buy nothing beyond its floors) and the pass over
    // them would: where the budget affords every creature, all listed at once cost less than
    // their groups opened one by one (at 100,000 creatures with room for every step, 6 ms
    // against 40, and at 30 ms frames of 40 ms and more).
    let (evaluate_us, overhead_us) = (config.costs.evaluation_us(count), config.costs.overhead_us(count));
    let incremental = config.rules.budget.incremental_choice
        && !floors.any_step_fits(budget_us - overhead_us)
        && floors.any_step_fits(budget_us - config.costs.floors_only_overhead_us(count));
    // Where a creature is quiet, the most its contacts with the puck, the areas and the walls
    // can be worth (negative where it is not).
    let (mut quiet_near, mut quiet) = (Vec::new(), 0);
    if incremental {
        let (tiles, following) = (scene.tiles(count), scene.camera.following);
        quiet_near = vec![-1.0; count];
        // A part at a time across the cores, as the floors' pass.
        let mut parts: Vec<_> = quiet_near.chunks_mut(FLOORS_PART).map(|near| (near, 0)).collect();
        each_part(&mut parts, cores, |p, (near, quiet)| {
            let first = p * FLOORS_PART;
            let mut i = first;
            for (entity, _, lod, s, choice) in tables.parts(first, first + near.len()) {
                for (((&entity, &lod), s), choice) in entity.iter().zip(lod).zip(s).zip(choice) {
                    let floor = floors.levels[i];
                    if lod == floor
                        && choice.wanted == floor
                        && following != Some(entity)
                        && let Some(at_most) = tiles.quiet_near(s)
                    {
                        (near[i - first], *quiet) = (at_most, *quiet + 1);
                    }
                    i += 1;
                }
            }
        });
        quiet = parts.iter().map(|p| p.1).sum();
    }
    let room_us = budget_us - overhead_us + quiet as f32 * evaluate_us;
    // Nor where the room it leaves for steps is less than working out the others costs: at
    // the margin the choice spent on itself what bought no level (40,000 creatures at 4 ms,
    // their mean frame up from 0.8 of the budget to 1.0 at the same levels, 2026-12-04).
    let wasted = incremental && room_us - floors.cost_us < (count - quiet) as f32 * evaluate_us;
    // Where not one step up fits, the benefits are not worked out, nor the creatures listed,
    // and the choice costs the pass over them above (a crowd far over its budget), charged as
    // such. A creature at its kind's dearest level goes to its floor; the others keep their
    // levels: a cheap level sent to its floor saves a creature hundredths of a microsecond a
    // frame, and its switch costs it about four (`cheap_switch_us`). A crowd's hybrids sent to
    // their floors at once (40,000 creatures at 10 ms in the adaptive mode, 2026-11-27) made
    // frames of 181, 51 and 37 ms, and the correction that followed held the crowd at its
    // floors.
    if wasted || !floors.any_step_fits(room_us) {
        let overhead_us = config.costs.floors_only_overhead_us(count);
        return floors.holding_cheap_levels().allocation(budget_us, overhead_us);
    }
    let rules = &config.rules.budget;
    let hull = Hull {
        hysteresis: rules.hysteresis,
        least_per_us: rules.least_benefit_per_ms / 1e3,
        settle_us: config.costs.contact_search_us,
    };
    // A creature's benefits before its search, worked out again for the few the queue comes
    // back to (the same bits: they depend on the creature and the scene alone) rather than kept
    // for every creature.
    let bounds_of = |(entity, c, _, s, _): Row| scene.bounds(entity, s, c.kind, kinds[c.kind].radius_m);
    // A creature as the knapsack sees it: made where its bounds are worked out, and again only
    // for the few the queue comes back to.
    // In the incremental choice, ties go to the creature first in the query (its place is its
    // serial here): a group of quiet creatures is a run of places, so that among a crowd's equal
    // bounds the queue reaches a group's creatures together, not one from each group in turn.
    // Working out every creature, they go to the lower serial, as they always did.
    let made = |row: Row, floor: Lod, place: usize| {
        let ((_, c, &lod, _, choice), bound) = (row, bounds_of(row));
        // A search within `contact_recheck_s` stands; without one, any contact with another
        // creature could be now.
        let standing = choice.crowding.filter(|&(_, at)| now_s - at < rules.contact_recheck_s);
        Candidate {
            serial: if incremental { place as u32 } else { c.serial },
            current: lod,
            last: choice.wanted,
            floor,
            levels: &kinds[c.kind].levels,
            costs: costs[c.kind],
            benefit: [0.0, bound.hybrid, bound.rigid(scene, standing.map_or(1.0, |s| s.0))],
            settled: standing.is_some() || bound.settled(scene),
        }
    };
    // Each creature's bounds and steps are its own, worked out and listed across the cores,
    // each core's steps sorted while they are at hand, then merged. The creatures are dealt to
    // the cores a block at a time in turn: what one costs here depends on where it is (in view
    // or not), and the query keeps neighbours together, so that halves of it would not balance.
    // What a quiet creature's step to rigid adds (at its floor, it switches from there): none
    // where its kind has no rigid level above the floor.
    let rigid_extra_us = |kind: usize, floor: Lod| {
        let at = at_floor[kind][floor as usize][floor as usize].frame_at_us;
        (floor < Lod::Rigid && kinds[kind].levels.contains(&Lod::Rigid))
            .then(|| at[Lod::Rigid as usize] - at[floor as usize])
    };
    // A quiet creature's one step, gathered into its group: at most the tile's contacts with the
    // puck, the areas and the walls, or the contacts with other creatures its search stands at
    // (or could be, without one), over what it adds.
    let quiet_step = |(_, c, _, _, choice): Row, floor: Lod, near: f32, row: usize, group: &mut [QuietGroup]| {
        let standing = choice.crowding.filter(|&(_, at)| now_s - at < rules.contact_recheck_s);
        let rigid_at_most = near.max(rules.creature_weight * standing.map_or(1.0, |s| s.0));
        if let Some(extra_us) = rigid_extra_us(c.kind, floor) {
            let may_be_exact = standing.is_some() || near >= rules.creature_weight;
            QuietGroup::gather(group, (row, row as u32), rigid_at_most, extra_us, may_be_exact, &hull);
        }
    };
    let quiet_near = |i: usize| quiet_near.get(i).copied().filter(|&near| near >= 0.0);
    let mut settled_now = vec![false; count];
    let mut groups = vec![QuietGroup::default(); 2 * count.div_ceil(GROUP_ROWS)];
    let threads = count.div_ceil(chunk_len(config.scenario.creature_count(), count));
    let dear_us = floors.dear_us(room_us);
    let mut dealt: Vec<Vec<_>> = (0..threads).map(|_| Vec::new()).collect();
    let blocks = (floors.levels.chunks(DEALT_BLOCK)).zip(
        settled_now
            .chunks_mut(DEALT_BLOCK)
            .zip(groups.chunks_mut(2 * DEALT_BLOCK / GROUP_ROWS)),
    );
    for (b, block) in blocks.enumerate() {
        dealt[b % threads].push(((b * DEALT_BLOCK) as u32, block));
    }
    let mut chunks: Vec<Option<Listing>> = (0..threads).map(|_| None).collect();
    run_chunks(dealt.into_iter().zip(chunks.iter_mut()).map(|(blocks, listed)| {
        let (hull, made, quiet_near, quiet_step, tables) = (&hull, &made, &quiet_near, &quiet_step, &tables);
        move || {
            let mut listing = Listing::new(dear_us, blocks.iter().map(|(_, (floors, _))| floors.len()).sum());
            for (first, (mut floors, (mut settled_now, groups))) in blocks {
                let mut i = first;
                // A table's part at a time: its slices side by side with the block's.
                for (entity, c, lod, s, choice) in tables.parts(first as usize, first as usize + floors.len()) {
                    let n = entity.len();
                    let (floors_here, settled_here);
                    ((floors_here, floors), (settled_here, settled_now)) =
                        (floors.split_at(n), std::mem::take(&mut settled_now).split_at_mut(n));
                    let rows = (entity.iter().zip(c).zip(lod)).zip(s.iter().zip(choice));
                    for ((((&entity, c), lod), (s, choice)), (&floor, settled)) in
                        rows.zip(floors_here.iter().zip(settled_here))
                    {
                        let (row, at) = ((entity, c, lod, s, choice), (i - first) as usize);
                        if let Some(near) = quiet_near(i as usize) {
                            let group = 2 * (at / GROUP_ROWS);
                            quiet_step(row, floor, near, i as usize, &mut groups[group..group + 2]);
                        } else {
                            let candidate = made(row, floor, i as usize);
                            *settled = candidate.settled;
                            let p = candidate.priced(hull.hysteresis);
                            candidate.list_hull(i, hull, &p, |step| listing.push(step, hull));
                        }
                        i += 1;
                    }
                }
            }
            listing.finish();
            *listed = Some(listing);
        }
    }));
    let listed = Listing::merge(chunks.into_iter().flatten().collect());
    let floor_levels = floors.levels.clone();
    let mut crowd = Gathered {
        made: |i: usize| made(tables.row(i), floor_levels[i], i),
        settled: Default::default(),
        members: groups.iter().map(|g| g.members).collect(),
    };
    let groups = QuietGroups::of(&groups, evaluate_us);
    // Quiet creatures with no step up are in no group.
    let stepless = quiet - groups.members.iter().sum::<u32>() as usize;
    // Only a creature that could still buy a level is searched for contacts with the others.
    let mut allocation = allocate_listed(&mut crowd, floors, settled_now, (listed, groups), room_us, &hull, |i| {
        let row @ (_, c, _, s, _) = tables.row(i);
        let urgency = scene.crowding(c, s, kinds[c.kind].radius_m);
        (bounds_of(row).rigid(scene, urgency), urgency)
    });
    allocation.settled.sort_unstable_by_key(|s| s.0);
    allocation.predicted_us += overhead_us - quiet as f32 * evaluate_us;
    allocation.quiet += stepless;
    allocation
}

/// A creature as a decision reads it.
type Row<'w> = (Entity, &'w Creature, &'w Lod, &'w PlanarState, &'w LevelChoice);

/// Rows of one table, a slice of each component.
type TableRows<'w> = (
    &'w [Entity],
    &'w [Creature],
    &'w [Lod],
    &'w [PlanarState],
    &'w [LevelChoice],
);

/// A decision's creatures, read table by table where the query holds them: each core reads
/// its own, where a row apiece gathered on one core first cost a pass over the crowd.
struct Tables<'w> {
    tables: Vec<TableRows<'w>>,
    /// Where each table's rows start, then how many there are in all.
    starts: Vec<usize>,
}

impl<'w> Tables<'w> {
    fn of(creatures: &'w Query<'_, '_, <CreatureRow as QueryData>::ReadOnly>) -> Self {
        let tables: Vec<_> = creatures.contiguous_iter().expect(DENSE).collect();
        let starts = std::iter::once(0)
            .chain(tables.iter().scan(0, |sum, t| {
                *sum += t.0.len();
                Some(*sum)
            }))
            .collect();
        Self { tables, starts }
    }

    fn len(&self) -> usize {
        self.starts.last().copied().unwrap_or(0)
    }

    /// The rows `from..to`, in the query's order, as the parts of the tables they lie in.
    fn parts(&self, from: usize, to: usize) -> impl Iterator<Item = TableRows<'w>> + '_ {
        // The last table starting at or before `from` holds it (an empty one never does).
        let first = self.starts.partition_point(|&s| s <= from).saturating_sub(1);
        (self.tables[first.min(self.tables.len())..]
            .iter()
            .zip(&self.starts[first..]))
        .take_while(move |(_, start)| **start < to)
        .map(move |(&(entity, c, lod, s, choice), &start)| {
            let (a, b) = (from.max(start) - start, to.min(start + entity.len()).max(start) - start);
            let r = a..b.max(a);
            (
                &entity[r.clone()],
                &c[r.clone()],
                &lod[r.clone()],
                &s[r.clone()],
                &choice[r],
            )
        })
    }

    /// The rows `from..to`, in the query's order.
    fn rows(&self, from: usize, to: usize) -> impl Iterator<Item = Row<'w>> + '_ {
        self.parts(from, to).flat_map(|(entity, c, lod, s, choice)| {
            (entity.iter().zip(c).zip(lod))
                .zip(s.iter().zip(choice))
                .map(|(((&e, c), l), (s, ch))| (e, c, l, s, ch))
        })
    }

    fn row(&self, i: usize) -> Row<'w> {
        self.rows(i, i + 1).next().expect("a row of the decision")
    }
}

/// A decision's creatures as the knapsack sees them ([`Crowd`]): each `made` from what the
/// decision gathered of it when asked for, its rigid benefit once `settled`.
struct Gathered<F> {
    made: F,
    settled: std::collections::HashMap<usize, f32>,
    /// By group of quiet creatures, its members ([`QuietGroup::members`]).
    members: Vec<u64>,
}

impl<'a, F: Fn(usize) -> Candidate<'a> + Sync> Crowd<'a> for Gathered<F> {
    fn candidate(&self, i: usize) -> Candidate<'a> {
        let mut c = (self.made)(i);
        if let Some(&rigid_benefit) = self.settled.get(&i) {
            c.benefit[Lod::Rigid as usize] = rigid_benefit;
            c.settled = true;
        }
        c
    }

    fn settle(&mut self, i: usize, rigid_benefit: f32) {
        self.settled.insert(i, rigid_benefit);
    }

    fn open(&self, group: usize, hull: &Hull, settled_now: &mut [bool], opened: &mut BinaryHeap<Step>) {
        QuietGroup::open(group, self.members[group], self, hull, settled_now, opened);
    }
}

fn scene<'a>(
    config: &'a SimConfig,
    kinds: &KindTable,
    puck: &'a PuckState,
    areas: Vec<Area>,
    court: &'a Court,
    grid: &'a NeighbourGrid,
    camera: &'a SimCamera,
) -> Scene<'a> {
    let rules = &config.rules.budget;
    let top_speed = kinds.0.iter().map(|k| k.top_speed_m_per_s).fold(0.0, f32::max);
    let biggest = kinds.0.iter().map(|k| k.radius_m).fold(0.0, f32::max);
    Scene {
        rules,
        circles: Circle::of(puck, areas, top_speed),
        court,
        grid,
        camera,
        view_reach: kinds.0.iter().map(|k| camera.view_reach(k, 0.0)).collect(),
        top_speed,
        widest_m: biggest,
        // Beyond three horizons at both creatures' top speeds, a contact is worth under 5 %.
        reach_m: 2.0 * biggest + rules.contact_margin_m + 2.0 * top_speed * 3.0 * rules.contact_horizon_s,
        outweigh_creature_s: (
            outweigh_times_s(rules, rules.puck_weight),
            outweigh_times_s(rules, rules.wall_weight),
        ),
    }
}

impl DecisionInputs<'_, '_> {
    /// The allocation for every creature now, in the query's order: within `budget_us` as the
    /// cost model predicts it.
    fn decide(&self, creatures: &Creatures, budget_us: f32, starting: bool) -> Allocation<f32> {
        let scene = scene(
            &self.config,
            &self.kinds,
            &self.puck,
            areas_now(&self.areas),
            &self.court,
            &self.grid,
            &self.camera,
        );
        decide(
            self.clock.seconds() as f32,
            &self.config,
            &self.kinds,
            &scene,
            creatures,
            budget_us,
            starting,
        )
    }
}

/// At each decision, under the budget policy: every creature's wanted level.
fn choose_by_budget(inputs: DecisionInputs, mut tally: ResMut<BudgetTally>, mut creatures: Creatures) {
    if !inputs.clock.is_decision_tick() {
        return;
    }
    let rules = &inputs.config.rules.budget;
    if rules.adaptive_frames > 0.0 {
        tally.correct(rules);
    }
    let decision = inputs.decide(&creatures, tally.model_budget_us(rules), false);
    tally.record(&decision);
    // In the query's order, as decided.
    let now_s = inputs.clock.seconds() as f32;
    let mut searched = decision.settled.iter().peekable();
    let mut row = 0;
    // A table's column at a time, its change ticks left as they were: nothing reads them, and
    // a row apiece through the query cost a quarter of a millisecond among 100,000 creatures.
    for (.., mut choices) in creatures.contiguous_iter_mut().expect(DENSE) {
        for choice in choices.bypass_change_detection() {
            decision.write(&mut searched, row, now_s, choice);
            row += 1;
        }
    }
}

/// The budget policy's choice for the world as it stands, at its rules' budget, without
/// applying it: what `simlod bench --calibrate` times to measure the choice. None in a world
/// without the simulation's resources.
pub fn choice_now(world: &mut World) -> Option<Allocation<f32>> {
    let mut state = bevy::ecs::system::SystemState::<(DecisionInputs, Creatures)>::new(world);
    let (inputs, creatures) = state.get_mut(world).ok()?;
    Some(inputs.decide(&creatures, inputs.config.rules.budget.frame_budget_ms * 1e3, false))
}

/// A new world under the budget policy: its creatures, placed at the cheapest level, start at
/// the levels the budget gives them (in that level's rhythm and pose).
fn start_by_budget(
    mut commands: Commands,
    inputs: DecisionInputs,
    mut tally: ResMut<BudgetTally>,
    mut creatures: Creatures,
    mut gaits: Query<(&mut GaitPhase, &mut GaitPose)>,
) {
    *tally = BudgetTally::default();
    if inputs.config.scenario.level_policy != LevelPolicy::Budget {
        return;
    }
    let now = inputs.clock.seconds() as f32;
    let budget_us = tally.model_budget_us(&inputs.config.rules.budget);
    let decision = inputs.decide(&creatures, budget_us, true);
    let mut searched = decision.settled.iter().peekable();
    for (row, ((entity, c, &lod, _, mut choice), &level)) in creatures.iter_mut().zip(&decision.levels).enumerate() {
        if level != lod
            && let Ok((mut gait, mut pose)) = gaits.get_mut(entity)
        {
            (*gait, *pose) = starting_gait(level, &inputs.kinds[c.kind], gait.cycle, now);
            commands.entity(entity).insert(level);
        }
        decision.write(&mut searched, row, now, &mut choice);
    }
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.init_resource::<BudgetTally>()
        .add_systems(
            SimStart,
            start_by_budget
                .after(start_at_selected_levels)
                .in_set(StartStage::Levels),
        )
        .add_systems(
            schedule,
            choose_by_budget
                .in_set(SimStage::SelectLod)
                .after(select_levels)
                .run_if(|config: Res<SimConfig>| config.scenario.level_policy == LevelPolicy::Budget),
        );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::LevelRules;

    const COSTS: LevelCosts = LevelCosts {
        point_mass_us_per_frame: 1.0,
        hybrid_us_per_frame: 2.0,
        rigid_us_per_frame: 100.0,
        switch_to_rigid_us: 50.0,
        cheap_switch_us: 0.0,
    };

    /// Numbers in [0, 1) from `seed`, the same every run (a linear congruential generator).
    fn uniform(seed: u64) -> impl FnMut() -> f32 {
        let mut seed = seed;
        move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    fn candidate(serial: u32, current: Lod, rigid_benefit: f32) -> Candidate<'static> {
        Candidate {
            serial,
            current,
            last: current,
            floor: Lod::PointMass,
            levels: &Lod::ALL,
            costs: COSTS,
            benefit: [0.0, 0.5, rigid_benefit],
            settled: true,
        }
    }

    #[test]
    fn a_decisions_rows_are_read_across_its_tables_in_order_from_anywhere() {
        // Tables of 3, none, 2 and 4 creatures, each told apart by its serial.
        let lens = [3usize, 0, 2, 4];
        let creatures: Vec<Vec<Creature>> = (lens.iter().scan(0, |n, &len| {
            *n += len;
            Some(*n - len)
        }))
        .zip(lens)
        .map(|(first, len)| {
            (first..first + len)
                .map(|i| Creature {
                    kind: 0,
                    serial: i as u32,
                })
                .collect()
        })
        .collect();
        let (entities, lods, states, choices) = (
            [Entity::PLACEHOLDER; 4],
            [Lod::PointMass; 4],
            [PlanarState::default(); 4],
            [LevelChoice::default(); 4],
        );
        let tables: Vec<_> = (creatures.iter().zip(lens))
            .map(|(c, len)| (&entities[..len], &c[..], &lods[..len], &states[..len], &choices[..len]))
            .collect();
        let tables = Tables {
            starts: vec![0, 3, 3, 5, 9],
            tables,
        };
        assert_eq!(tables.len(), 9);
        for from in 0..=9 {
            for to in from..=9 {
                let serials: Vec<u32> = tables.rows(from, to).map(|r| r.1.serial).collect();
                assert_eq!(serials, (from as u32..to as u32).collect::<Vec<_>>(), "{from}..{to}");
            }
        }
        assert_eq!(tables.row(5).1.serial, 5);
    }

    fn floors_of(crowd: &[Candidate]) -> Floors {
        let mut floors = Floors::with_capacity(crowd.len());
        crowd.iter().for_each(|c| floors.add(c.into()));
        floors
    }

    #[test]
    fn a_crowds_floors_sum_the_same_on_any_number_of_cores_and_one_parts_as_one_by_one() {
        bevy::tasks::ComputeTaskPool::get_or_init(bevy::tasks::TaskPool::default);
        let mut r = uniform(11);
        let levels = [Lod::PointMass, Lod::Hybrid, Lod::Rigid];
        let crowd: Vec<Candidate> = (0..3 * FLOORS_PART as u32 + 17)
            .map(|i| {
                let costs = LevelCosts {
                    point_mass_us_per_frame: 0.1 + r(),
                    hybrid_us_per_frame: 1.0 + r(),
                    rigid_us_per_frame: 50.0 + 100.0 * r(),
                    ..COSTS
                };
                Candidate {
                    costs,
                    floor: levels[(3.0 * r()) as usize % 2],
                    ..candidate(i, levels[(3.0 * r()) as usize % 3], 1.0)
                }
            })
            .collect();
        let gathered = |crowd: &[Candidate], threads: usize| {
            Floors::gathered(crowd.len(), threads, |first, part| {
                let to = (first + FLOORS_PART).min(crowd.len());
                crowd[first..to].iter().for_each(|c| part.add(c.into()));
            })
        };
        let sums = |f: &Floors| {
            (
                f.levels.clone(),
                f.held.clone(),
                [f.cost_us, f.frame_us, f.held_frame_us, f.cheapest_step_us].map(f32::to_bits),
            )
        };
        let one = sums(&gathered(&crowd, 1));
        for threads in [2, 3, 8] {
            assert_eq!(sums(&gathered(&crowd, threads)), one, "{threads} threads");
        }
        // The parts' sums in their order: within rounding of one by one, and a crowd of one part
        // bit for bit.
        let (by_one, part) = (floors_of(&crowd), &crowd[..FLOORS_PART]);
        assert_eq!(
            (one.0.clone(), one.1.clone()),
            (by_one.levels.clone(), by_one.held.clone())
        );
        assert!((f32::from_bits(one.2[0]) - by_one.cost_us).abs() <= 1e-5 * by_one.cost_us);
        assert_eq!(sums(&gathered(part, 2)), sums(&floors_of(part)));
        // Held where no step fits: below the dearest level, the level it has; else its floor.
        let held = floors_of(&crowd).holding_cheap_levels();
        for (c, &level) in crowd.iter().zip(&held.levels) {
            assert_eq!(level, if c.current < Lod::Rigid { c.current } else { c.floor });
        }
    }

    #[test]
    fn where_no_step_up_fits_beside_the_floors_every_creature_keeps_its_floor() {
        // Three at the point mass (1 us each); the cheapest step is to the hybrid (1 us more).
        let crowd: Vec<Candidate> = (0..3).map(|i| candidate(i, Lod::PointMass, 9.0)).collect();
        let floors = vec![Lod::PointMass; 3];
        for budget_us in [0.0, 2.0, 3.9] {
            assert!(!floors_of(&crowd).any_step_fits(budget_us));
            let allocation = allocate(&mut crowd.clone(), budget_us, 0.0, 0.0, 0.0, |_| (0.0, ()));
            assert_eq!(allocation.levels, floors, "{budget_us} us");
            // The floors gathered alone are that allocation, a frame's fixed cost beside them.
            let fixed_us = 0.5;
            let by_floors: Allocation = floors_of(&crowd).allocation(budget_us + fixed_us, fixed_us);
            assert_eq!(by_floors.levels, allocation.levels);
            assert_eq!(by_floors.exceeded, allocation.exceeded, "{budget_us} us");
            assert!((by_floors.predicted_us - (allocation.predicted_us + fixed_us)).abs() < 1e-6);
        }
        assert!(floors_of(&crowd).any_step_fits(4.0));
        assert_ne!(
            allocate(&mut crowd.clone(), 4.0, 0.0, 0.0, 0.0, |_| (0.0, ())).levels,
            floors
        );
        // A rigid creature dwelling at its level: its floor is rigid, its own cost counts.
        let dwelling = Candidate {
            floor: Lod::Rigid,
            ..candidate(3, Lod::Rigid, 9.0)
        };
        let crowd = [crowd, vec![dwelling]].concat();
        assert!(!floors_of(&crowd).any_step_fits(103.9));
        assert!(floors_of(&crowd).any_step_fits(104.0));
    }

    /// A crowd of `n` with mixed levels and dwells, and each one's exact rigid benefit; half of
    /// them are in view (a hybrid benefit), a few dearer (another kind).
    fn mixed_crowd(n: u32) -> (Vec<Candidate<'static>>, Vec<f32>) {
        let mut next = uniform(99);
        let mut exact = Vec::new();
        let crowd = (0..n)
            .map(|i| {
                let current = Lod::ALL[(next() * 3.0) as usize];
                let hybrid = if next() < 0.5 { next() } else { 0.0 };
                exact.push(hybrid + 2.0 * next());
                Candidate {
                    last: Lod::ALL[(next() * 3.0) as usize],
                    floor: if next() < 0.2 { current } else { Lod::PointMass },
                    costs: if i % 7 == 0 {
                        LevelCosts {
                            rigid_us_per_frame: 180.0,
                            ..COSTS
                        }
                    } else {
                        COSTS
                    },
                    // Unsettled: the most the rigid level could be worth.
                    benefit: [0.0, hybrid, hybrid + 2.0],
                    settled: false,
                    ..candidate(n - i, current, 0.0)
                }
            })
            .collect();
        (crowd, exact)
    }

    /// The crowd with every rigid benefit exact from the start.
    fn settled_first(crowd: &[Candidate<'static>], exact: &[f32]) -> Vec<Candidate<'static>> {
        crowd
            .iter()
            .zip(exact)
            .map(|(c, &rigid)| Candidate {
                benefit: [0.0, c.benefit[1], rigid],
                settled: true,
                ..c.clone()
            })
            .collect()
    }

    /// Checks that each creature was settled once, with what its own settling gave (its
    /// index), and returns how many were.
    fn settled_once_each(a: &Allocation<usize>) -> usize {
        let mut once: Vec<usize> = a
            .settled
            .iter()
            .map(|&(i, kept)| {
                assert_eq!(i, kept);
                i
            })
            .collect();
        once.sort_unstable();
        once.dedup();
        assert_eq!(once.len(), a.settled.len());
        once.len()
    }

    #[test]
    fn settling_only_the_creatures_that_reach_the_front_chooses_as_settling_them_all() {
        let (crowd, exact) = mixed_crowd(300);
        let settled_first = settled_first(&crowd, &exact);
        for (budget_us, hysteresis, least_per_us) in [(800.0, 0.0, 0.0), (3000.0, 0.2, 0.0), (20_000.0, 0.2, 0.005)] {
            let whole = allocate(
                &mut settled_first.clone(),
                budget_us,
                hysteresis,
                least_per_us,
                0.0,
                |_| -> (f32, ()) { unreachable!("every benefit is exact") },
            );
            let lazy = allocate(&mut crowd.clone(), budget_us, hysteresis, least_per_us, 0.0, |i| {
                (exact[i], i)
            });
            assert_eq!(lazy.levels, whole.levels, "{budget_us} us");
            assert_eq!(lazy.predicted_us, whole.predicted_us);
            // Each settled once, and under a small budget only a few.
            let settled = settled_once_each(&lazy);
            if budget_us < 1000.0 {
                assert!(settled < 30, "{settled} settled");
            }
        }
    }

    /// A crowd whose quiet creatures wait in groups, as a decision's do: how many were opened.
    struct Grouped<'a> {
        crowd: Vec<Candidate<'a>>,
        members: Vec<u64>,
        opened: std::sync::atomic::AtomicUsize,
    }

    impl<'a> Crowd<'a> for Grouped<'a> {
        fn candidate(&self, i: usize) -> Candidate<'a> {
            self.crowd[i].clone()
        }

        fn settle(&mut self, i: usize, rigid_benefit: f32) {
            self.crowd[..].settle(i, rigid_benefit);
        }

        fn open(&self, group: usize, hull: &Hull, settled_now: &mut [bool], opened: &mut BinaryHeap<Step>) {
            let members = self.members[group].count_ones() as usize;
            self.opened.fetch_add(members, std::sync::atomic::Ordering::Relaxed);
            QuietGroup::open(group, self.members[group], self, hull, settled_now, opened);
        }
    }

    #[test]
    fn quiet_creatures_left_to_their_groups_are_chosen_as_if_every_one_were_listed() {
        let (mut crowd, mut exact) = mixed_crowd(3000);
        // Two in three quiet: out of view (no hybrid benefit), at their floor and last level;
        // one in five of those with a search standing (exact).
        let quiet: Vec<bool> = (0..crowd.len()).map(|i| i % 3 != 0).collect();
        // Each creature's serial its place, as in a decision's incremental choice.
        crowd.iter_mut().enumerate().for_each(|(i, c)| c.serial = i as u32);
        for (i, c) in crowd.iter_mut().enumerate().filter(|(i, _)| quiet[*i]) {
            exact[i] -= c.benefit[1];
            (c.current, c.last, c.floor, c.benefit) = (Lod::PointMass, Lod::PointMass, Lod::PointMass, [0.0, 0.0, 2.0]);
            if i % 5 == 0 {
                (c.benefit[2], c.settled) = (exact[i], true);
            }
        }
        for (room_us, settle_us, least_per_us) in [
            (300.0, 0.0, 0.0),
            (300.0, 3.0, 0.0),
            (3000.0, 3.0, 0.0),
            (1e6, 3.0, 0.002),
        ] {
            let hull = Hull {
                hysteresis: 0.2,
                least_per_us,
                settle_us,
            };
            let mut floors = Floors::with_capacity(crowd.len());
            crowd.iter().for_each(|c| floors.add(c.into()));
            let budget_us = floors.cost_us + room_us;
            let whole = list_and_allocate(&mut crowd.clone(), budget_us, &hull, None, |i| (exact[i], i));
            // The others listed; the quiet ones gathered into their groups.
            let mut listing = Listing::new(floors.dear_us(budget_us), crowd.len());
            let mut groups = vec![QuietGroup::default(); 2 * crowd.len().div_ceil(GROUP_ROWS)];
            for (i, c) in crowd.iter().enumerate() {
                let p = c.priced(hull.hysteresis);
                if quiet[i] {
                    let extra_us = p.cost_us[Lod::Rigid as usize] - p.cost_us[Lod::PointMass as usize];
                    let pair = &mut groups[2 * (i / GROUP_ROWS)..][..2];
                    QuietGroup::gather(pair, (i, c.serial), c.benefit[2], extra_us, c.settled, &hull);
                } else {
                    c.list_hull(i as u32, &hull, &p, |step| listing.push(step, &hull));
                }
            }
            listing.finish();
            let members: usize = groups.iter().map(|g| g.members.count_ones() as usize).sum();
            let mut grouped = Grouped {
                members: groups.iter().map(|g| g.members).collect(),
                crowd: crowd.clone(),
                opened: Default::default(),
            };
            let settled_now = crowd.iter().zip(&quiet).map(|(c, &q)| c.settled && !q).collect();
            let groups = QuietGroups::of(&groups, 0.0);
            let lazy = allocate_listed(
                &mut grouped,
                floors,
                settled_now,
                (listing, groups),
                budget_us,
                &hull,
                |i| (exact[i], i),
            );
            assert_eq!(
                Allocation {
                    quiet: 0,
                    ..lazy.clone()
                },
                whole,
                "{room_us} us, searches {settle_us} us"
            );
            let opened = grouped.opened.into_inner();
            assert_eq!(lazy.quiet, members - opened);
            // With room for a few steps, few of the quiet creatures are worked out.
            if room_us < 1000.0 {
                assert!(opened < 500, "{opened} opened of 2,000");
            }
        }
    }

    #[test]
    fn settling_ahead_across_the_cores_chooses_as_settling_one_at_a_time() {
        bevy::tasks::ComputeTaskPool::get_or_init(bevy::tasks::TaskPool::default);
        // A crowd big enough to be settled ahead in batches.
        let (crowd, exact) = mixed_crowd(4 * crate::contract::PARALLEL_MIN_CREATURES);
        let settled_first = settled_first(&crowd, &exact);
        for budget_us in [320_000.0, 450_000.0, 1_500_000.0] {
            let whole = allocate(&mut settled_first.clone(), budget_us, 0.2, 0.0, 0.0, |_| (0.0, ()));
            let ahead = allocate(&mut crowd.clone(), budget_us, 0.2, 0.0, 0.0, |i| (exact[i], i));
            assert_eq!(ahead.levels, whole.levels, "{budget_us} us");
            assert_eq!(ahead.predicted_us, whole.predicted_us);
            settled_once_each(&ahead);
            // Charged for its searches, what it settles and chooses stays within the budget.
            let charged = allocate(&mut crowd.clone(), budget_us, 0.2, 0.0, 3.0, |i| (exact[i], ()));
            assert!(!charged.settled.is_empty());
            assert!(
                charged.predicted_us <= budget_us,
                "{budget_us} us: {}",
                charged.predicted_us
            );
        }
    }

    #[test]
    fn a_dear_lists_head_is_its_best_step_whatever_the_order_listed() {
        // Hybrids stepping to rigid (98 us, dear beside a room of 1 ms): few rigid benefits, so
        // many equal ratios, the lower serial first among them; serials listed out of order.
        let mut next = uniform(7);
        let crowd: Vec<Candidate> = (0..2000)
            .map(|i| candidate((i * 7919) % 2000, Lod::Hybrid, 1.0 + (next() * 4.0).floor()))
            .collect();
        let hull = Hull {
            hysteresis: 0.0,
            least_per_us: 0.0,
            settle_us: 0.0,
        };
        let listing = hull.list(&crowd, 1.0);
        assert_eq!(listing.dear.len(), 1);
        let (_, dear) = &listing.dear[0];
        assert_eq!(dear.steps.len(), crowd.len());
        let best = dear.steps.iter().max().unwrap();
        assert_eq!((dear.best.serial, dear.best.ratio), (best.serial, best.ratio));
        let most = dear.steps.iter().map(|s| s.ratio).fold(0.0, f32::max);
        let first = dear.steps.iter().filter(|s| s.ratio == most).map(|s| s.serial).min();
        assert_eq!(
            Some(dear.best.serial),
            first,
            "the lowest serial among the greatest ratio"
        );
        assert!(dear.steps.iter().filter(|s| s.ratio == most).count() > 100);
    }

    #[test]
    fn dear_steps_put_in_order_only_as_far_as_the_queue_reaches_are_taken_as_if_all_were_sorted() {
        let (crowd, exact) = mixed_crowd(3000);
        // Bounds to settle, and exact steps.
        for (crowd, settle_us) in [(&crowd, 0.0), (&crowd, 3.0), (&settled_first(&crowd, &exact), 0.0)] {
            let hull = Hull {
                hysteresis: 0.2,
                least_per_us: 0.0,
                settle_us,
            };
            let mut floors = Floors::with_capacity(crowd.len());
            crowd.iter().for_each(|c| floors.add(c.into()));
            // Room for a few steps to rigid (and with the least, for a few hybrid ones), to many.
            for room_us in [50.0, 500.0, 5000.0, 50_000.0] {
                let budget_us = floors.cost_us + room_us;
                let listing = hull.list(crowd, floors.dear_us(budget_us));
                assert!(listing.dear.iter().any(|(_, dear)| dear.steps.len() > 300));
                let lazy = list_and_allocate(&mut crowd.clone(), budget_us, &hull, None, |i| (exact[i], i));
                let sorted = list_and_allocate(&mut crowd.clone(), budget_us, &hull, Some(f32::INFINITY), |i| {
                    (exact[i], i)
                });
                assert_eq!(lazy, sorted, "{budget_us} us, searches of {settle_us} us");
            }
        }
    }

    #[test]
    fn where_a_level_costs_less_than_the_one_below_no_step_is_passed_by() {
        // Rigid dearer than a point mass, cheaper than a hybrid. The second creature's search
        // does not fit beside the frame as it will run at its turn; the first, a hybrid bought
        // rigid after its own search, then makes that frame cheaper. A step passed by at its
        // turn is not looked at again, so the second is not searched.
        let costs = LevelCosts {
            point_mass_us_per_frame: 1.0,
            hybrid_us_per_frame: 50.0,
            rigid_us_per_frame: 10.0,
            switch_to_rigid_us: 0.0,
            cheap_switch_us: 0.0,
        };
        assert!(!costs.rise_with_level() && COSTS.rise_with_level());
        let unsettled = |serial, current, rigid| Candidate {
            costs,
            benefit: [0.0, 0.0, rigid],
            settled: false,
            ..candidate(serial, current, rigid)
        };
        let mut crowd = [unsettled(0, Lod::Hybrid, 3.0), unsettled(1, Lod::PointMass, 2.0)];
        let a = allocate(&mut crowd, 65.0, 0.0, 0.0, 10.0, |_| (1.0, ()));
        assert_eq!(a.levels, [Lod::Rigid, Lod::PointMass]);
        assert_eq!(a.settled.len(), 1);
        assert_eq!(a.predicted_us, 21.0);
    }

    #[test]
    fn each_search_comes_off_the_budget_and_into_the_prediction() {
        // All point masses now, so that the budget has room.
        let (mut crowd, exact) = mixed_crowd(300);
        for c in &mut crowd {
            (c.current, c.floor) = (Lod::PointMass, Lod::PointMass);
        }
        let free = allocate(&mut crowd.clone(), 3000.0, 0.2, 0.0, 0.0, |i| (exact[i], ()));
        let charged = allocate(&mut crowd.clone(), 3000.0, 0.2, 0.0, 5.0, |i| (exact[i], ()));
        assert!(!charged.settled.is_empty());
        let at_levels: f32 = crowd
            .iter()
            .zip(&charged.levels)
            .map(|(c, &l)| c.frame_cost_us(l))
            .sum();
        let searched = charged.settled.len() as f32 * 5.0;
        assert!(
            (charged.predicted_us - (at_levels + searched)).abs() < 0.01,
            "{charged:?}"
        );
        assert!(charged.predicted_us <= 3000.0);
        // What the searches cost is not spent on levels.
        let levels_us = |a: &Allocation| {
            crowd
                .iter()
                .zip(&a.levels)
                .map(|(c, &l)| c.frame_cost_us(l))
                .sum::<f32>()
        };
        assert!(
            levels_us(&charged) < levels_us(&free),
            "{} {}",
            levels_us(&charged),
            levels_us(&free)
        );
    }

    #[test]
    fn a_creature_is_searched_only_with_room_for_the_search_and_a_step_that_can_follow_it() {
        // Out of view: nothing gained at the hybrid level, so after its search only the rigid
        // step could follow (149 us from its point mass, the building of its bodies with it).
        // A creature in view beside it takes its hybrid step (1 us) first.
        let unseen = Candidate {
            benefit: [0.0, 0.0, 2.0],
            settled: false,
            ..candidate(0, Lod::PointMass, 2.0)
        };
        let seen = candidate(1, Lod::PointMass, 0.0);
        let crowd = [unseen, seen];
        // The point masses cost 2 us, the hybrid step 1, the search 1.
        for (budget_us, searched) in [(60.0, false), (152.0, false), (153.0, true), (400.0, true)] {
            let a = allocate(&mut crowd.clone(), budget_us, 0.0, 0.0, 1.0, |_| (1.5, ()));
            assert_eq!(!a.settled.is_empty(), searched, "{budget_us} us: {a:?}");
            assert_eq!(a.levels[1], Lod::Hybrid, "{budget_us} us");
            let rigid = if budget_us >= 153.0 { Lod::Rigid } else { Lod::PointMass };
            assert_eq!(a.levels[0], rigid, "{budget_us} us");
        }
    }

    /// A scene with no host areas, creatures at most 3 m/s.
    fn test_scene<'a>(
        b: &'a BudgetRules,
        puck: &'a PuckState,
        court: &'a Court,
        grid: &'a NeighbourGrid,
        camera: &'a SimCamera,
        reach_m: f32,
    ) -> Scene<'a> {
        Scene {
            rules: b,
            circles: Circle::of(puck, Vec::new(), 3.0),
            court,
            grid,
            camera,
            view_reach: Vec::new(),
            top_speed: 3.0,
            widest_m: 0.6,
            reach_m,
            outweigh_creature_s: (outweigh_times_s(b, b.puck_weight), outweigh_times_s(b, b.wall_weight)),
        }
    }

    #[test]
    fn a_tiles_bound_on_the_puck_and_the_walls_is_never_below_a_creatures_benefit_in_it() {
        let rules: LevelRules = ron::from_str(include_str!("../../assets/rules/levels.ron")).unwrap();
        let b = &rules.budget;
        let puck = PuckState {
            position: Vec2::new(10.0, -5.0),
            velocity: Vec2::new(-4.0, 3.0),
            radius_m: 2.0,
        };
        let court = Court {
            half_extents: Vec2::new(60.0, 40.0),
        };
        let (grid, camera) = (NeighbourGrid::default(), SimCamera::default());
        let scene = test_scene(b, &puck, &court, &grid, &camera, 30.0);
        let mut next = uniform(77);
        let (tile, mut least, mut largest) = (8.0, f32::INFINITY, 0.0f32);
        for y in -5..5 {
            for x in -7..7 {
                let lo = Vec2::new(x as f32, y as f32) * tile;
                let hi = lo + Vec2::splat(tile);
                let most = scene.near_at_most(lo, hi, 3.0);
                for _ in 0..200 {
                    let s = PlanarState {
                        position: lo + Vec2::new(next(), next()) * tile,
                        velocity: Vec2::from_angle(next() * 6.3) * 3.0 * next(),
                        heading: Vec2::X,
                    };
                    let benefit = scene.near_benefit(&scene.near(&s, 0.2 + 0.4 * next()));
                    assert!(benefit <= most, "{benefit} over {most} in the tile at {lo}");
                }
                (least, largest) = (least.min(most), largest.max(most));
            }
        }
        // At the puck the bound is a contact now; in the middle of the court, far less.
        assert!(largest == 1.0 && least < 0.25, "{least} to {largest}");
    }

    #[test]
    fn the_nearest_first_search_finds_the_same_soonest_contact_as_the_whole_reach() {
        let mut rules: LevelRules = ron::from_str(include_str!("../../assets/rules/levels.ron")).unwrap();
        // The creatures' term alone.
        (rules.budget.puck_weight, rules.budget.wall_weight) = (0.0, 0.0);
        let b = &rules.budget;
        let half = Vec2::splat(60.0);
        // A crowd at the game's density and some strays far apart, moving up to 3 m/s.
        let mut next = uniform(12345);
        let creatures: Vec<(Creature, PlanarState)> = (0..3000)
            .map(|i| {
                let spread = if i < 2800 { 0.4 } else { 1.0 };
                let position = (Vec2::new(next(), next()) * 2.0 - Vec2::ONE) * half * spread;
                let velocity = Vec2::from_angle(next() * std::f32::consts::TAU) * 3.0 * next();
                (
                    Creature { kind: 0, serial: i },
                    PlanarState {
                        position,
                        velocity,
                        ..default()
                    },
                )
            })
            .collect();
        let mut grid = NeighbourGrid::new(half, 1.6);
        grid.rebuild(creatures.iter().map(|(c, s)| crate::sense::Neighbour {
            position: s.position,
            velocity: s.velocity,
            radius: 0.35,
            mass: 10.0,
            serial: c.serial,
        }));
        let (puck, court, camera) = (
            PuckState {
                position: Vec2::splat(1e4),
                velocity: Vec2::ZERO,
                radius_m: 1.0,
            },
            Court { half_extents: half },
            SimCamera::default(),
        );
        let top_speed = 3.0;
        let reach_m = 0.7 + b.contact_margin_m + 2.0 * top_speed * 3.0 * b.contact_horizon_s;
        let scene = test_scene(b, &puck, &court, &grid, &camera, reach_m);
        let mut with_neighbours = 0;
        for (c, s) in &creatures {
            let (mut t_course, mut t_worst, mut seen) = (f32::INFINITY, f32::INFINITY, 0);
            grid.for_each_within(s.position, scene.reach_m, |n| {
                if n.serial != c.serial {
                    let d = s.position - n.position;
                    let reach = 0.7 + b.contact_margin_m;
                    t_worst = t_worst.min((d.length() - reach).max(0.0) / (2.0 * top_speed));
                    t_course = t_course.min(time_to_contact(d, s.velocity - n.velocity, reach));
                    seen += 1;
                }
            });
            let whole = b.creature_weight * scene.urgency(t_course, t_worst);
            assert_eq!(
                b.creature_weight * scene.crowding(c, s, 0.35),
                whole,
                "creature {}",
                c.serial
            );
            with_neighbours += usize::from(seen > 0);
        }
        assert!(with_neighbours > 2800);
    }

    #[test]
    fn the_puck_and_the_walls_weighed_only_where_they_could_outweigh_a_creature_give_the_same_benefits() {
        let rules: LevelRules = ron::from_str(include_str!("../../assets/rules/levels.ron")).unwrap();
        let b = &rules.budget;
        let half = Vec2::new(80.0, 50.0);
        let puck = PuckState {
            position: Vec2::new(10.0, -5.0),
            velocity: Vec2::new(4.0, 3.0),
            radius_m: 2.0,
        };
        let (court, camera, grid) = (
            Court { half_extents: half },
            SimCamera::default(),
            NeighbourGrid::new(half, 1.6),
        );
        let scene = test_scene(b, &puck, &court, &grid, &camera, 30.0);
        let mut next = uniform(7);
        let (mut spared, mut weighed) = (0, 0);
        for _ in 0..20_000 {
            let s = PlanarState {
                position: (Vec2::new(next(), next()) * 2.0 - Vec2::ONE) * half,
                velocity: Vec2::from_angle(next() * std::f32::consts::TAU) * 3.0 * next(),
                ..default()
            };
            let bounds = Bounds {
                hybrid: 0.0,
                seen: next(),
                near: scene.near(&s, 0.35),
            };
            let near = scene.near_benefit(&bounds.near);
            for crowding in [1.0, 0.6, 0.0] {
                let exact = bounds.seen + near.max(b.creature_weight * crowding);
                assert_eq!(bounds.rigid(&scene, crowding), exact, "{s:?} at {crowding}");
            }
            assert_eq!(bounds.settled(&scene), near >= b.creature_weight, "{s:?}");
            if scene.may_outweigh_a_creature(&bounds.near) {
                weighed += 1;
            } else {
                spared += 1;
            }
        }
        // Both sides of the test are exercised: most creatures are spared the weighing.
        assert!(spared > weighed && weighed > 100, "{spared} spared, {weighed} weighed");
    }

    #[test]
    fn steps_sorted_by_their_key_are_in_the_order_they_are_taken() {
        let mut next = uniform(3);
        let ratios = [0.0, 1e-30, 0.006, 0.5, 7.0, f32::INFINITY];
        // In one piece, and in chunks sorted apart and merged.
        for (most_serial, count) in [(5u32, 4000), (1000, 4000), (100_000, 40_000), (u32::MAX, 40_001)] {
            let mut steps: Vec<Step> = (0..count)
                .map(|i| {
                    // Many equal ratios, as a crowd's unsearched bounds have.
                    let ratio = if next() < 0.5 {
                        ratios[(next() * 6.0) as usize]
                    } else {
                        next() * 10.0
                    };
                    Step {
                        ratio,
                        bound: false,
                        serial: (next() * most_serial as f32) as u32,
                        // Where it was listed: among equal steps, that order is kept.
                        creature: i,
                        from: Lod::PointMass,
                        to: Lod::Rigid,
                        extra_us: 1.0,
                        running_us: 1.0,
                        group: false,
                    }
                })
                .collect();
            let chunks = steps
                .chunks(count as usize / 3 + 1)
                .map(|chunk| {
                    let mut chunk = chunk.to_vec();
                    Step::sort(&mut chunk);
                    chunk
                })
                .collect();
            let merged = Step::merge(chunks);
            Step::sort(&mut steps);
            for steps in [steps, merged] {
                assert!(
                    steps
                        .windows(2)
                        .all(|w| w[0] > w[1] || (w[0] == w[1] && w[0].creature < w[1].creature)),
                    "up to serial {most_serial}"
                );
            }
        }
    }

    #[test]
    fn decay_is_the_exponential_down_to_where_it_rounds_to_zero() {
        for x in [
            0.0f32,
            -1.0,
            -50.0,
            -87.0,
            -100.0,
            -103.9,
            -104.0,
            -104.1,
            -200.0,
            f32::NEG_INFINITY,
        ] {
            assert_eq!(decay(x).to_bits(), x.exp().to_bits(), "{x}");
        }
        // Every float from -104 to -128 (a negative float's bits grow as it falls).
        for bits in (-104.0f32).to_bits()..=(-128.0f32).to_bits() {
            assert_eq!(f32::from_bits(bits).exp(), 0.0);
        }
    }

    #[test]
    fn a_contact_ahead_comes_at_the_closing_time_and_a_passing_body_never() {
        // 10 m apart, closing at 2 m/s, touching at 1 m: 4.5 s.
        let t = time_to_contact(Vec2::new(10.0, 0.0), Vec2::new(-2.0, 0.0), 1.0);
        assert!((t - 4.5).abs() < 1e-5, "{t}");
        assert_eq!(
            time_to_contact(Vec2::new(10.0, 0.0), Vec2::new(2.0, 0.0), 1.0),
            f32::INFINITY
        );
        assert_eq!(
            time_to_contact(Vec2::new(10.0, 5.0), Vec2::new(-2.0, 0.0), 1.0),
            f32::INFINITY
        );
        assert_eq!(time_to_contact(Vec2::new(0.5, 0.0), Vec2::ZERO, 1.0), 0.0);
    }

    #[test]
    fn the_budget_goes_to_the_most_benefit_per_cost_and_is_never_exceeded() {
        let cs: Vec<_> = (0..5).map(|i| candidate(i, Lod::PointMass, i as f32)).collect();
        // Room for two going rigid and three hybrids (2 x (100 + 50) + 3 x 2 = 306).
        let a = allocate(&mut cs.clone(), 310.0, 0.0, 0.0, 0.0, |_| (0.0, ()));
        assert_eq!(
            a.levels,
            [Lod::Hybrid, Lod::Hybrid, Lod::Hybrid, Lod::Rigid, Lod::Rigid]
        );
        assert!(a.predicted_us <= 310.0 && !a.exceeded, "{a:?}");
    }

    #[test]
    fn a_level_that_gains_less_than_the_least_benefit_per_cost_is_not_bought_however_large_the_budget() {
        let cs: Vec<_> = (0..5).map(|i| candidate(i, Lod::PointMass, i as f32)).collect();
        // Going rigid from hybrid gains i - 0.5 for 148 us; at 0.02 per us only i = 4 pays.
        let a = allocate(&mut cs.clone(), 10_000.0, 0.0, 0.02, 0.0, |_| (0.0, ()));
        assert_eq!(
            a.levels,
            [Lod::Hybrid, Lod::Hybrid, Lod::Hybrid, Lod::Hybrid, Lod::Rigid]
        );
        assert!(
            (a.predicted_us - (4.0 * 2.0 + 150.0)).abs() < 1e-3 && !a.exceeded,
            "{a:?}"
        );
    }

    #[test]
    fn a_creature_going_down_still_counts_until_it_switches() {
        // One rigid now, with no benefit left; one hybrid with a contact ahead. Going down in
        // the flight window, the first still costs its rigid level this frame: no room yet.
        let cs = [candidate(0, Lod::Rigid, 0.0), candidate(1, Lod::Hybrid, 5.0)];
        let a = allocate(&mut cs.clone(), 160.0, 0.0, 0.0, 0.0, |_| (0.0, ()));
        assert_eq!(a.levels, [Lod::Hybrid, Lod::Hybrid]);
        assert!(a.predicted_us <= 160.0, "{a:?}");
    }

    #[test]
    fn a_frame_over_by_creatures_still_going_down_keeps_the_levels_the_others_run_at() {
        // One rigid now with no benefit left, going down: it costs its rigid level this frame
        // whatever is chosen, so the frame is over the budget. Four hybrids in view keep their
        // level: giving their steps back would lower nothing this frame, only switch them.
        let mut cs = vec![candidate(0, Lod::Rigid, 0.0)];
        cs.extend((1..5).map(|i| candidate(i, Lod::Hybrid, 0.0)));
        let a = allocate(&mut cs, 20.0, 0.0, 0.0, 0.0, |_| (0.0, ()));
        assert_eq!(a.levels, [Lod::Hybrid; 5]);
        assert!(a.exceeded && a.predicted_us == 108.0, "{a:?}");
        // A step that adds to the frame as it will run is still given back: a point mass's.
        cs.push(candidate(5, Lod::PointMass, 0.0));
        let a = allocate(&mut cs, 20.0, 0.0, 0.0, 0.0, |_| (0.0, ()));
        assert_eq!(a.levels[5], Lod::PointMass, "{a:?}");
        assert_eq!(a.levels[..5], [Lod::Hybrid; 5]);
    }

    #[test]
    fn the_adaptive_correction_moves_toward_measured_over_predicted_and_ignores_a_stall() {
        // Frames measured at twice the prediction: over about 10 frames the correction nears 2.
        let none = f32::INFINITY;
        let mut c = 1.0;
        for _ in 0..50 {
            c = corrected(c, 1000.0, 2000.0, 10.0, none);
        }
        assert!((c - 2.0).abs() < 0.01, "{c}");
        // One frame stalled a thousand times over counts as ten times, a tenth of it.
        let stalled = corrected(2.0, 1000.0, 1e9, 10.0, none);
        assert!((stalled - 2.8).abs() < 1e-5, "{stalled}");
        // Nothing predicted yet: nothing to correct.
        assert_eq!(corrected(1.5, 0.0, 2000.0, 10.0, none), 1.5);
    }

    #[test]
    fn a_frame_over_the_emergency_line_corrects_at_once_and_one_under_it_is_smoothed() {
        // Predicted 1 ms, measured 3 ms, with the emergency line at 1.5 ms: at once.
        assert_eq!(corrected(1.0, 1000.0, 3000.0, 30.0, 1500.0), 3.0);
        // Measured 1.4 ms, under the line: a thirtieth of the way.
        let smoothed = corrected(1.0, 1000.0, 1400.0, 30.0, 1500.0);
        assert!((smoothed - (1.0 + 0.4 / 30.0)).abs() < 1e-6, "{smoothed}");
        // An emergency never lowers a correction already above its frame's ratio.
        assert_eq!(corrected(4.0, 1000.0, 3000.0, 30.0, 1500.0), 4.0 - 1.0 / 30.0);
    }

    #[test]
    fn the_percentile_mode_keeps_that_rank_among_the_last_frames_only() {
        let mut recent = RecentFrames::default();
        // Excesses 1, 2, ..., 100 us: the 99th percentile of the 100 is 99, the 50th 50.
        let mut last = 0.0;
        for r in 1..=100 {
            last = recent.percentile_with(r as f32, 100, 99.0);
        }
        assert_eq!(last, 99.0);
        assert_eq!(
            recent.clone().percentile_with(100.0, 100, 50.0),
            51.0,
            "1 left the window"
        );
        // 100 frames of 1 push the old ones out: one slow frame in a hundred is the 100th
        // percentile, not the 99th.
        for _ in 0..99 {
            recent.percentile_with(1.0, 100, 99.0);
        }
        assert_eq!(recent.percentile_with(5.0, 100, 99.0), 1.0);
        assert_eq!(recent.clone().percentile_with(1.0, 100, 100.0), 5.0);
        // A shorter window keeps only the newest.
        assert_eq!(recent.percentile_with(1.0, 1, 100.0), 1.0);
    }

    #[test]
    fn the_percentile_mode_keeps_the_mean_within_the_budget_and_the_percentile_within_its_limit() {
        let rules = |limit| BudgetRules {
            frame_budget_ms: 10.0,
            adaptive_percentile_limit: limit,
            ..ron::from_str::<LevelRules>(include_str!("../../assets/rules/levels.ron"))
                .unwrap()
                .budget
        };
        let tally = |headroom_us| BudgetTally {
            correction: 2.0,
            headroom_us,
            ..BudgetTally::default()
        };
        // Within the budget: 10 ms less 1 ms of slow frames, over a model that runs twice slow.
        assert_eq!(tally(1000.0).model_budget_us(&rules(1.0)), 4500.0);
        // Within 1.2 times it, 12 ms less 1 ms: but the mean is held at the budget, 10 ms.
        assert_eq!(tally(1000.0).model_budget_us(&rules(1.2)), 5000.0);
        // Frames slower than the room between: the percentile's limit holds the mean under.
        assert_eq!(tally(3000.0).model_budget_us(&rules(1.2)), 4500.0);
        // Slow frames beyond the limit itself leave nothing to spend.
        assert_eq!(tally(20_000.0).model_budget_us(&rules(1.2)), 0.0);
    }

    #[test]
    fn the_percentile_is_taken_among_enough_frames_that_three_lie_beyond_it() {
        assert_eq!(percentile_window(30.0, 99.0), 300);
        assert_eq!(percentile_window(30.0, 95.0), 60);
        // Where the smoothing's frames already hold three beyond, and at the slowest frame.
        assert_eq!(percentile_window(30.0, 90.0), 30);
        assert_eq!(percentile_window(30.0, 100.0), 30);
        assert_eq!(percentile_window(30.0, 99.99), 10_000);
    }

    #[test]
    fn too_small_a_budget_gives_the_cheapest_levels_and_says_so() {
        let cs: Vec<_> = (0..3).map(|i| candidate(i, Lod::PointMass, 9.0)).collect();
        let a = allocate(&mut cs.clone(), 1.0, 0.0, 0.0, 0.0, |_| (0.0, ()));
        assert_eq!(a.levels, [Lod::PointMass; 3]);
        assert!(a.exceeded);
    }
}
