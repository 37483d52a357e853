//! The `experiment` command: the paper's experiments and those beyond it.

use crate::Failure;
use clap::{Args, Subcommand};
use std::path::PathBuf;

use crate::scenario::*;
use simlod_lab::experiments;

#[derive(Args)]
pub(crate) struct ExperimentArgs {
    #[command(subcommand)]
    pub(crate) which: ExperimentKind,
}

#[derive(Subcommand)]
pub(crate) enum ExperimentKind {
    /// Figures 3 and 4: velocity and ground path under step changes in desired velocity.
    StepResponse(ExperimentRun),
    /// Table 1: cost per creature per 1/30 s at each level (the model alone, and in a game).
    Table1(ExperimentRun),
    /// Figure 7: creatures at 30 fps against the percentage of rigid ones.
    Fig7(ExperimentRun),
    /// Figure 8: average and lowest frame rate against the puck's radius of influence.
    Fig8(ExperimentRun),
    /// Figure 9: average and lowest frame rate against the camera's radius of influence.
    Fig9(ExperimentRun),
    /// Figure 10: the change in creatures that hit the puck or a wall, against all rigid.
    Fig10(ExperimentRun),
    /// Beyond the paper: the budget policy against fixed radii on figure 10's axes, and the
    /// frame times of a crowded game.
    Budget(ExperimentRun),
    /// Beyond the paper: figure 7 taken to crowds, every policy's frame time from a hundred
    /// creatures to a million.
    Crowd(ExperimentRun),
    /// Beyond the paper: the budget policy at every crowd size, its measured frame against its
    /// budget, with the cost model alone and corrected by measured frames.
    BudgetScale(ExperimentRun),
    /// Every experiment, into one folder.
    All(ExperimentRun),
    /// Combine fig10 shards (`--shard K/N` runs) into the files of one unsharded run.
    Merge {
        /// The shards' output folders.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Folder the merged files are written to.
        #[arg(long)]
        out: PathBuf,
    },
}

#[derive(Args)]
pub(crate) struct ExperimentRun {
    #[command(flatten)]
    pub(crate) scenario: ScenarioArgs,
    /// The experiment's file (default: experiments/<name>.ron under the assets folder).
    #[arg(long)]
    pub(crate) experiment: Option<PathBuf>,
    /// Folder the CSV, PNG, JSON and report.md files are written to.
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// The experiment file's `quick` settings: small counts, seconds of work.
    #[arg(long)]
    pub(crate) quick: bool,
    /// Overrides the experiment file's trial count.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub(crate) trials: Option<u32>,
    /// Threads for independent trials (default: every core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub(crate) jobs: Option<u32>,
    /// Run only the K-th of N disjoint parts of the trials (fig10), e.g. 2/4.
    #[arg(long)]
    pub(crate) shard: Option<experiments::Shard>,
}

impl ExperimentRun {
    pub(crate) fn run(&self, name: &str) -> Result<(), Failure> {
        self.scenario.refuse_level_flags(
            "experiment",
            "each experiment sets its own level policy, rules and radii from its file (assets/experiments/<name>.ron; --experiment FILE reads another)",
        )?;
        let config = self.scenario.load()?;
        let options = experiments::Options {
            out: self.out.clone(),
            quick: self.quick,
            trials: self.trials,
            jobs: self.jobs.map_or_else(
                || std::thread::available_parallelism().map_or(1, |n| n.get()),
                |j| j as usize,
            ),
            shard: self.shard.unwrap_or(experiments::Shard::WHOLE),
            assets: self.scenario.assets.clone(),
            scenario: self.scenario.scenario_file(),
        };
        let names: Vec<&str> = if name == "all" {
            if self.experiment.is_some() {
                return Err("--experiment names one experiment's file; `all` reads each from the assets folder".into());
            }
            experiments::ALL.to_vec()
        } else {
            vec![name]
        };
        for name in names {
            let file = self
                .experiment
                .clone()
                .unwrap_or_else(|| experiments::default_file(&self.scenario.assets, name));
            print!("{}", experiments::run_named(name, &config, &file, &options)?);
        }
        Ok(())
    }
}
