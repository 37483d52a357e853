//! What a command line or a game changes of a scenario's files for one run, in one place.

use super::{LevelPolicy, SimConfig};

/// Changes to a scenario and its rules for one run (`--seed`, `--policy`, ...); each `None`
/// leaves the file's value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    /// The world's seed.
    pub seed: Option<u64>,
    /// The level policy.
    pub level_policy: Option<LevelPolicy>,
    /// The radius of the puck's area of influence, metres (figure 8).
    pub puck_radius_m: Option<f32>,
    /// The camera's radius of influence, metres (figure 9).
    pub camera_radius_m: Option<f32>,
    /// The budget policy's frame budget, ms of simulation per 1/30 s.
    pub frame_budget_ms: Option<f32>,
    /// Rapier's solver iterations per tick.
    pub solver_iterations: Option<u32>,
}

impl Overrides {
    /// `config` with these changes.
    pub fn apply(&self, config: &mut SimConfig) {
        let (scenario, rules) = (&mut config.scenario, &mut config.rules);
        scenario.seed = self.seed.unwrap_or(scenario.seed);
        scenario.level_policy = self.level_policy.unwrap_or(scenario.level_policy);
        scenario.solver_iterations = self.solver_iterations.unwrap_or(scenario.solver_iterations);
        rules.influence.puck_radius_m = self.puck_radius_m.unwrap_or(rules.influence.puck_radius_m);
        rules.camera.radius_m = self.camera_radius_m.unwrap_or(rules.camera.radius_m);
        rules.budget.frame_budget_ms = self.frame_budget_ms.unwrap_or(rules.budget.frame_budget_ms);
    }
}
