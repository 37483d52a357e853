//! Changing the level policy and the frame budget while the simulation runs.
//!
//! ```sh
//! cargo run --release --example change_policy
//! ```
//!
//! The policy and the rules are read from the [`SimConfig`] resource at every steering
//! decision, so writing them takes effect at once: each creature moves to its new level in
//! its next flight window (paper 3.4). This is what the game's L, 9 and 0 keys do.

use std::path::Path;

use simlod::config::SimConfig;
use simlod::creature::Creature;
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelPolicy, Lod};

fn levels(sim: &mut HeadlessSim) -> [usize; 3] {
    let world = sim.app.world_mut();
    let mut count = [0; 3];
    for level in world.query::<(&Creature, &Lod)>().iter(world).map(|(_, l)| *l) {
        count[level as usize] += 1;
    }
    count
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let config = SimConfig::load(Path::new("assets/scenarios/default.ron"), Path::new("assets"))?;
    let mut sim = HeadlessSim::new(config);
    let phases: [(&str, LevelPolicy, f32); 4] = [
        ("the scenario's own (combined)", LevelPolicy::Combined, 4.0),
        ("all hybrid", LevelPolicy::AllHybrid, 4.0),
        ("budget of 1 ms", LevelPolicy::Budget, 1.0),
        ("budget of 0.3 ms", LevelPolicy::Budget, 0.3),
    ];
    for (name, policy, budget_ms) in phases {
        {
            let mut config = sim.app.world_mut().resource_mut::<SimConfig>();
            config.scenario.level_policy = policy;
            config.rules.budget.frame_budget_ms = budget_ms;
        }
        sim.run_for(3.0);
        let [point_mass, hybrid, rigid] = levels(&mut sim);
        println!(
            "t = {:4.1} s, {name:<30} point mass {point_mass:2}, hybrid {hybrid:2}, rigid {rigid:2}",
            sim.clock().seconds()
        );
    }
    Ok(())
}
