//! The integration tests: one crate, a headless `App` with `MinimalPlugins` driven in fixed
//! steps.

mod assets;
mod budget;
mod cli;
mod court;
mod determinism;
mod docs;
mod experiments;
mod fuzz;
mod gait;
mod game;
mod host;
mod kinds;
mod layers;
mod outcome;
mod player;
mod pops;
mod restart;
mod rigid;
mod schedule;
mod steering;
mod support;
mod switching;
mod ticks;
