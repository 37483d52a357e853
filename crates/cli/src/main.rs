//! The `simlod` command line: the game (the default), the headless simulation and its
//! measurements.

mod bench;
mod experiment;
#[cfg(feature = "game")]
mod play;
mod record_gait;
mod run;
mod scenario;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

use crate::bench::BenchArgs;
use crate::experiment::{ExperimentArgs, ExperimentKind};
#[cfg(feature = "game")]
use crate::play::PlayArgs;
use crate::record_gait::RecordGaitArgs;
use crate::run::RunArgs;
use simlod_lab::experiments;

/// The budget's choice of a crowd allocates and frees some 20 MB a decision at 100,000
/// creatures: an allocator that keeps freed memory, not the system's, which gives it back and
/// takes it again a page fault at a time.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Why a command failed: its message is printed after `error:`.
type Failure = Box<dyn std::error::Error>;

#[derive(Parser)]
#[command(
    name = "simlod",
    version,
    about = "Simulation levels of detail for real-time animation (Carlson & Hodgins, GI '97)"
)]
struct Cli {
    /// Without a command: `play` (in a build with the `game` feature).
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Play the game in a window (the default).
    #[cfg(feature = "game")]
    Play(PlayArgs),
    /// Simulate a scenario without a window, as fast as the machine allows, and summarise it.
    Run(RunArgs),
    /// Measure the cost per creature per 1/30 s of motion and the most creatures at 30 fps.
    Bench(BenchArgs),
    /// Run one of the paper's experiments and write its data as CSV.
    Experiment(ExperimentArgs),
    /// Record a creature's gait table from its rigid model (paper 3.2).
    RecordGait(RecordGaitArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        #[cfg(feature = "game")]
        None => PlayArgs::parse_from(["play"]).play(),
        #[cfg(not(feature = "game"))]
        None => Err(Failure::from(
            "this build has no game window (built without the `game` feature); `simlod run` simulates without one",
        )),
        #[cfg(feature = "game")]
        Some(Command::Play(args)) => args.play(),
        Some(Command::Run(args)) => args.run(),
        Some(Command::RecordGait(args)) => args.run(),
        Some(Command::Bench(args)) => args.run(),
        Some(Command::Experiment(ExperimentArgs { which })) => match which {
            ExperimentKind::StepResponse(run) => run.run("step-response"),
            ExperimentKind::Table1(run) => run.run("table1"),
            ExperimentKind::Fig7(run) => run.run("fig7"),
            ExperimentKind::Fig8(run) => run.run("fig8"),
            ExperimentKind::Fig9(run) => run.run("fig9"),
            ExperimentKind::Fig10(run) => run.run("fig10"),
            ExperimentKind::Budget(run) => run.run("budget"),
            ExperimentKind::Crowd(run) => run.run("crowd"),
            ExperimentKind::BudgetScale(run) => run.run("budget-scale"),
            ExperimentKind::All(run) => run.run("all"),
            ExperimentKind::Merge { dirs, out } => {
                (experiments::fig10::merge(&dirs, &out).map(|summary| print!("{summary}"))).map_err(Failure::from)
            }
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}
