//! Loading a scenario from your own assets folder.
//!
//! ```sh
//! cargo run --release --example own_assets                 # a copy of assets/ made here
//! cargo run --release --example own_assets -- my-assets    # or your own folder
//! ```
//!
//! A scenario names its arena, level rules and creature kinds by paths relative to the assets
//! folder; creature files name their gait tables the same way. So a folder of your own, laid
//! out as `assets/` is, is a complete game. Here a copy of the shipped folder gets a scenario
//! of its own: a crowd of stilts and hoppers under the areas of influence.

use std::path::{Path, PathBuf};

use simlod::config::SimConfig;
use simlod::headless;

fn copy_dir(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let target = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            copy_dir(&entry.path(), &target)?;
        } else {
            std::fs::copy(entry.path(), &target)?;
        }
    }
    Ok(())
}

const SCENARIO: &str = r#"// Written by examples/own_assets.rs.
(
    seed: 42,
    duration_s: 10.0,
    tick_hz: 240,
    decision_hz: 30,
    arena: "arena.ron",
    creatures: [
        (kind: "stilt", count: 12),
        (kind: "hopper", count: 12),
    ],
    level_policy: Influence,
    level_rules: "rules/levels.ron",
)
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let assets = match std::env::args().nth(1) {
        Some(dir) => PathBuf::from(dir),
        None => {
            let copy = std::env::temp_dir().join("simlod-own-assets");
            copy_dir(Path::new("assets"), &copy)?;
            copy
        }
    };
    let scenario = assets.join("scenarios/stilts-and-hoppers.ron");
    std::fs::write(&scenario, SCENARIO)?;

    // A broken file is an error that names the file and the field, never a panic.
    let config = SimConfig::load(&scenario, &assets)?;
    let seconds = f64::from(config.scenario.duration_s);
    let summary = headless::run(config, seconds);
    println!("{} from {}", scenario.display(), assets.display());
    println!(
        "{} creatures for {:.0} s: {} collided with the puck or a wall, {} fell, {} level switches",
        summary.creatures,
        summary.sim_seconds,
        summary.creatures_collided,
        summary.falls,
        summary.switches.total()
    );
    Ok(())
}
