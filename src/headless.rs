//! Running the simulation without a window: for the command line, the tests and the
//! benchmarks. One `App::update` is one frame of `ticks_per_update` fixed ticks.

use bevy::ecs::schedule::SingleThreadedExecutor;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::Instant;

use crate::config::SimConfig;
use crate::contract::SimClock;
use crate::contract::{GaitPhase, PlanarState};
use crate::kind::Creature;
use crate::lod::BudgetTally;
use crate::outcome::{MeasuredFrame, Summary, summarize};
use crate::plugin::SimPlugin;
use crate::sense::PuckState;

/// A headless simulation: `MinimalPlugins` plus the core, driven in fixed ticks.
pub struct HeadlessSim {
    /// The Bevy app: reach its world for anything the run holds.
    pub app: App,
    ticks_per_update: u32,
    /// Each frame's wall time so far, in seconds.
    frames_s: Vec<f64>,
}

impl HeadlessSim {
    /// Builds the world; each [`HeadlessSim::advance_frame`] runs one steering decision's
    /// worth of ticks (1/30 s with the default `decision_hz`).
    pub fn new(config: SimConfig) -> Self {
        let ticks_per_update = config.scenario.ticks_per_decision();
        let mut app = App::new();
        app.add_plugins(MinimalPlugins.set(TaskPoolPlugin {
            task_pool_options: compute_on_every_core(),
        }))
        .add_plugins(SimPlugin::new(config));
        app.finish();
        app.cleanup();
        // Headless, every schedule is small: one thread runs them without wake-ups. Loops over
        // many creatures still spread over the compute pool.
        for (_, schedule) in app.world_mut().resource_mut::<Schedules>().iter_mut() {
            schedule.set_executor(SingleThreadedExecutor::new());
        }
        // The first update runs Startup and sets the clocks going without a fixed tick.
        app.insert_resource(TimeUpdateStrategy::FixedTimesteps(0));
        app.update();
        // The schedules it did not run (the fixed ticks') are built now, not in the first frame:
        // among 100,000 creatures their building made it 12 ms against 4 for the next ones.
        let labels: Vec<_> = app
            .world()
            .resource::<Schedules>()
            .iter()
            .map(|(_, s)| s.label())
            .collect();
        for label in labels {
            app.world_mut().schedule_scope(label, |world, schedule| {
                if let Err(error) = schedule.initialize(world) {
                    panic!("the schedule {label:?} does not build: {error:?}");
                }
            });
        }
        run_ticks_per_update(app.world_mut(), ticks_per_update);
        Self {
            app,
            ticks_per_update,
            frames_s: Vec::new(),
        }
    }

    /// The simulation's clock now.
    pub fn clock(&self) -> SimClock {
        *self.app.world().resource::<SimClock>()
    }

    /// Runs one frame: `ticks_per_decision` fixed ticks. Its wall time is left for the
    /// budget policy's adaptive mode, which alone reads it, and kept for the summary.
    pub fn advance_frame(&mut self) {
        let start = Instant::now();
        self.app.update();
        let seconds = start.elapsed().as_secs_f64();
        self.frames_s.push(seconds);
        self.app.world_mut().resource_mut::<BudgetTally>().measured_us = Some((seconds * 1e6) as f32);
    }

    /// Runs whole frames until at least `seconds` have been simulated.
    pub fn run_for(&mut self, seconds: f64) {
        let frame = f64::from(self.ticks_per_update) * f64::from(self.clock().dt);
        let frames = (seconds / frame - 1e-9).ceil().max(0.0) as u64;
        for _ in 0..frames {
            self.advance_frame();
        }
    }

    /// What the run did so far, as `simlod run` prints it, with each frame's wall time;
    /// `wall_seconds` is the caller's measure.
    pub fn summary(&mut self, wall_seconds: f64) -> Summary {
        Summary {
            measured_frame: MeasuredFrame::of(&self.frames_s),
            ..summarize(self.app.world_mut(), wall_seconds)
        }
    }

    /// A digest of the simulated state, bit for bit: creatures by serial, and the puck.
    pub fn state_digest(&mut self) -> u64 {
        let world = self.app.world_mut();
        let mut rows: Vec<(u32, [u32; 8], bool)> = world
            .query::<(&Creature, &PlanarState, &GaitPhase)>()
            .iter(world)
            .map(|(c, s, g)| {
                let bits = [
                    s.position.x,
                    s.position.y,
                    s.velocity.x,
                    s.velocity.y,
                    s.heading.x,
                    s.heading.y,
                    g.cycle,
                    c.kind as f32,
                ];
                (c.serial, bits.map(f32::to_bits), g.in_flight)
            })
            .collect();
        rows.sort_unstable_by_key(|r| r.0);
        let puck = *world.resource::<PuckState>();
        let mut h = DefaultHasher::new();
        rows.hash(&mut h);
        [puck.position.x, puck.position.y, puck.velocity.x, puck.velocity.y]
            .map(f32::to_bits)
            .hash(&mut h);
        h.finish()
    }
}

/// Makes every `App::update` run exactly `ticks` fixed ticks (of the world's `Time<Fixed>`).
/// Bevy's virtual clock lets at most `max_delta` (250 ms by default) through one update and
/// silently drops the rest, so a frame longer than that (8 ticks at 30 Hz decisions is 33 ms;
/// 2000 ticks at 1 Hz is a whole second) would run fewer ticks than asked: the cap is raised
/// to the frame.
pub fn run_ticks_per_update(world: &mut World, ticks: u32) {
    let frame = world.resource::<Time<Fixed>>().timestep() * ticks;
    let mut clock = world.resource_mut::<Time<Virtual>>();
    if frame > clock.max_delta() {
        clock.set_max_delta(frame);
    }
    world.insert_resource(TimeUpdateStrategy::FixedTimesteps(ticks));
}

/// Bevy's default gives compute a share of the cores, which on two cores is one thread, and
/// loops over creatures then never run in parallel. Headless there is nothing else to run.
fn compute_on_every_core() -> TaskPoolOptions {
    let cores = bevy::tasks::available_parallelism();
    let mut options = TaskPoolOptions::default();
    options.compute.min_threads = cores;
    options
}

/// Runs a scenario for `seconds` as fast as the machine allows and says what happened.
pub fn run(config: SimConfig, seconds: f64) -> Summary {
    let mut sim = HeadlessSim::new(config);
    let start = Instant::now();
    sim.run_for(seconds);
    let wall = start.elapsed().as_secs_f64();
    sim.summary(wall)
}
