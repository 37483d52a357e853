//! The `bench` command: the cost of each level, and calibration of the budget's cost model.

use crate::Failure;
use clap::Args;
use std::path::PathBuf;

use crate::scenario::*;
use simlod::config::{MeasuredAnew, SimConfig};
use simlod::lod::Lod;
use simlod_lab::bench::Calibration;

#[derive(Args)]
pub(crate) struct BenchArgs {
    #[command(flatten)]
    pub(crate) scenario: ScenarioArgs,
    /// Print one JSON object per level, one per line.
    #[arg(long)]
    pub(crate) json: bool,
    /// Fewer, shorter repetitions: a rough figure in seconds.
    #[arg(long)]
    pub(crate) quick: bool,
    /// Only this level (no cost ratios, no game).
    #[arg(long, value_parser = level_parser(), conflicts_with = "calibrate")]
    pub(crate) level: Option<Lod>,
    /// Only the scenario's creatures of this kind (for example `biped`): its cost at each level.
    #[arg(long, conflicts_with = "calibrate")]
    pub(crate) kind: Option<String>,
    /// Only the budget policy's choice among 100,000 creatures (20,000 with `--quick`): as it
    /// plays under a 30 ms budget, and with room for every step and no searches.
    #[arg(long, conflicts_with_all = ["calibrate", "level"])]
    pub(crate) choice: bool,
    /// Measure the budget policy's cost model (each kind's levels and its switches)
    /// and write it to the file the level rules name (`budget.cost_model`), or to `--out`.
    #[arg(long)]
    pub(crate) calibrate: bool,
    /// Where `--calibrate` writes the cost model.
    #[arg(long, requires = "calibrate")]
    pub(crate) out: Option<PathBuf>,
}

impl BenchArgs {
    pub(crate) fn run(&self) -> Result<(), Failure> {
        let mut config = self.scenario.load_measuring(MeasuredAnew {
            cost_model: self.calibrate,
            ..MeasuredAnew::default()
        })?;
        if let Some(kind) = &self.kind {
            let all: Vec<String> = config.scenario.creatures.iter().map(|g| g.kind.clone()).collect();
            config.scenario.creatures.retain(|g| &g.kind == kind);
            if config.scenario.creatures.is_empty() {
                return Err(Failure::from(format!(
                    "--kind {kind}: the scenario has no creatures of that kind (it has {})",
                    all.join(", ")
                )));
            }
        }
        if self.calibrate {
            return self.calibrate(&config);
        }
        if self.choice {
            simlod_lab::bench::run_choice(&config, self.quick, self.json);
        } else {
            simlod_lab::bench::run(&config, self.quick, self.json, self.level);
        }
        Ok(())
    }

    pub(crate) fn calibrate(&self, config: &SimConfig) -> Result<(), Failure> {
        let out = self
            .out
            .clone()
            .unwrap_or_else(|| self.scenario.assets.join(&config.rules.budget.cost_model));
        let how = if self.quick {
            Calibration::Quick
        } else {
            Calibration::Full
        };
        let model = simlod_lab::bench::calibrate(config, how);
        let rules = self
            .scenario
            .rules
            .as_ref()
            .map(|r| format!(" --rules {}", r.display()));
        let command = format!(
            "simlod bench --calibrate {}{}{}",
            self.scenario.file_flags(),
            rules.unwrap_or_default(),
            if self.quick { " --quick" } else { "" }
        );
        if let Some(dir) = out.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        }
        std::fs::write(&out, simlod_lab::bench::costs_file_text(&model, &command))
            .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
        if self.json {
            println!("{}", serde_json::to_string(&model).expect("a cost model serialises"));
        } else {
            println!(
                "wrote the cost model to {} (us per creature per 1/30 s; us per switch):",
                out.display()
            );
            for line in simlod_lab::bench::cost_model_lines(&model) {
                println!("  {line}");
            }
        }
        Ok(())
    }
}
