//! The flags every simulating command shares: the scenario, its assets and what overrides them.

use crate::Failure;
use clap::Args;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use std::path::{Path, PathBuf};

use crate::run::*;
use simlod::config::{MeasuredAnew, Overrides, SimConfig, load_costs, load_file};
use simlod::lod::{LevelPolicy, Lod};

#[derive(Args)]
pub(crate) struct ScenarioArgs {
    /// The scenario file (default: scenarios/default.ron in the assets folder); a relative
    /// path not found as given is looked up in the assets folder.
    #[arg(long)]
    pub(crate) scenario: Option<PathBuf>,
    /// The assets folder: the default scenario, and the files every scenario names (arena,
    /// rules, cost model, creature kinds, gait tables).
    #[arg(long, default_value = "assets")]
    pub(crate) assets: PathBuf,
    /// Overrides the scenario's seed.
    #[arg(long)]
    pub(crate) seed: Option<u64>,
    /// Overrides the scenario's level policy.
    #[arg(long, value_parser = policy_parser())]
    pub(crate) policy: Option<LevelPolicy>,
    /// Overrides the radius of the puck's area of influence (metres).
    #[arg(long, allow_negative_numbers = true, value_parser = non_negative_metres)]
    pub(crate) puck_radius: Option<f32>,
    /// Overrides the camera's radius of influence (metres).
    #[arg(long, allow_negative_numbers = true, value_parser = non_negative_metres)]
    pub(crate) camera_radius: Option<f32>,
    /// Overrides the budget policy's frame budget (ms of simulation per 1/30 s, 0 to 10000).
    #[arg(long, allow_negative_numbers = true, value_parser = frame_budget_ms)]
    pub(crate) frame_budget: Option<f32>,
    /// Overrides the scenario's level rules file.
    #[arg(long)]
    pub(crate) rules: Option<PathBuf>,
    /// Overrides the scenario's rapier solver iterations per tick (1 to 16).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub(crate) solver_iterations: Option<u32>,
}

/// A number from 0 to 10000 `unit`.
pub(crate) fn up_to_ten_thousand(s: &str, unit: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("not a number: {s:?}"))?;
    if v.is_finite() && (0.0..=1e4).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be between 0 and 10000 {unit}, got {v}"))
    }
}

pub(crate) fn non_negative_metres(s: &str) -> Result<f32, String> {
    up_to_ten_thousand(s, "metres")
}

pub(crate) fn frame_budget_ms(s: &str) -> Result<f32, String> {
    up_to_ten_thousand(s, "ms")
}

/// The scenario file a command reads: `scenario` as given, or, if a relative path is not found
/// there, the same path in the assets folder; without one, the assets folder's default.
pub(crate) fn scenario_file(assets: &Path, scenario: Option<&Path>) -> PathBuf {
    match scenario {
        None => assets.join(DEFAULT_SCENARIO),
        Some(path) if path.is_relative() && !path.exists() && assets.join(path).exists() => assets.join(path),
        Some(path) => path.to_path_buf(),
    }
}

/// The scenario every command runs without `--scenario`, in the assets folder.
const DEFAULT_SCENARIO: &str = "scenarios/default.ron";

impl ScenarioArgs {
    /// Refuses the level flags (policy, rules, radii, budget) for a command that never reads
    /// them, saying `why`, rather than let them be ignored without a word.
    pub(crate) fn refuse_level_flags(&self, command: &str, why: &str) -> Result<(), Failure> {
        let given = [
            ("--policy", self.policy.is_some()),
            ("--puck-radius", self.puck_radius.is_some()),
            ("--camera-radius", self.camera_radius.is_some()),
            ("--frame-budget", self.frame_budget.is_some()),
            ("--rules", self.rules.is_some()),
        ];
        match given.iter().find(|(_, given)| *given) {
            Some((flag, _)) => Err(Failure::from(format!(
                "{flag} does not apply to `simlod {command}`: {why}"
            ))),
            None => Ok(()),
        }
    }

    pub(crate) fn scenario_file(&self) -> PathBuf {
        scenario_file(&self.assets, self.scenario.as_deref())
    }

    /// The flags that find these files again from anywhere: `--assets`, and `--scenario`
    /// where it is not the default.
    pub(crate) fn file_flags(&self) -> String {
        let mut flags = format!("--assets {}", self.assets.display());
        if let Some(scenario) = &self.scenario {
            flags += &format!(" --scenario {}", scenario.display());
        }
        flags
    }

    pub(crate) fn what_ran(&self, config: &SimConfig) -> WhatRan {
        WhatRan {
            policy: config.scenario.level_policy.name().to_owned(),
            rules: self
                .rules
                .clone()
                .unwrap_or_else(|| self.assets.join(&config.scenario.level_rules)),
            cost_model: self.assets.join(&config.rules.budget.cost_model).display().to_string(),
        }
    }

    pub(crate) fn load(&self) -> Result<SimConfig, Failure> {
        self.load_measuring(MeasuredAnew::default())
    }

    /// The scenario with its overrides, without what is about to be measured anew (see
    /// [`SimConfig::load_measuring`]).
    pub(crate) fn load_measuring(&self, anew: MeasuredAnew) -> Result<SimConfig, Failure> {
        let mut config = SimConfig::load_measuring(&self.scenario_file(), &self.assets, anew)?;
        if let Some(rules) = &self.rules {
            config.rules = load_file(rules)?;
            if !anew.cost_model {
                config.costs = load_costs(&self.assets, rules, &config.rules)?;
            }
        }
        Overrides {
            seed: self.seed,
            level_policy: self.policy,
            puck_radius_m: self.puck_radius,
            camera_radius_m: self.camera_radius,
            frame_budget_ms: self.frame_budget,
            solver_iterations: self.solver_iterations,
        }
        .apply(&mut config);
        Ok(config)
    }
}

/// `--policy`: a policy by its name, each listed with its line of help.
pub(crate) fn policy_parser() -> impl TypedValueParser<Value = LevelPolicy> {
    PossibleValuesParser::new(LevelPolicy::ALL.map(|p| PossibleValue::new(p.name()).help(p.describe()))).map(|name| {
        *LevelPolicy::ALL
            .iter()
            .find(|p| p.name() == name)
            .expect("a listed name")
    })
}

/// `--level`: a level by its name (`point-mass`), each listed with its line of help.
pub(crate) fn level_parser() -> impl TypedValueParser<Value = Lod> {
    let flag = |l: Lod| l.name().replace('_', "-");
    PossibleValuesParser::new(Lod::ALL.map(|l| PossibleValue::new(flag(l)).help(l.describe())))
        .map(move |name| *Lod::ALL.iter().find(|&&l| flag(l) == name).expect("a listed name"))
}
