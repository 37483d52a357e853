//! The headless core in your own app: `MinimalPlugins` plus [`SimPlugin`], driven one frame
//! (one steering decision, 1/30 s) at a time, then the run's summary.
//!
//! ```sh
//! cargo run --release --example headless_core
//! ```
//!
//! `simlod::headless::HeadlessSim` wraps exactly these steps; this shows them in the open, for
//! a game or a tool that builds its own `App`.

use bevy::prelude::*;
use std::path::Path;

use simlod::SimPlugin;
use simlod::config::SimConfig;
use simlod::headless::run_ticks_per_update;
use simlod::lod::Lod;
use simlod::outcome::summarize;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The shipped default game: 30 hoppers and 10 bipeds escaping the puck.
    let config = SimConfig::load(Path::new("assets/scenarios/default.ron"), Path::new("assets"))?;
    let ticks_per_frame = config.scenario.ticks_per_decision();

    let mut app = App::new();
    app.add_plugins(MinimalPlugins).add_plugins(SimPlugin::new(config));
    app.finish();
    app.cleanup();
    // The first update builds the world (`Startup`); every later one runs one frame's fixed
    // ticks exactly, whatever the wall clock says: the run is deterministic.
    app.update();
    run_ticks_per_update(app.world_mut(), ticks_per_frame);
    let frames = 10 * 30; // ten simulated seconds
    for _ in 0..frames {
        app.update();
    }

    let summary = summarize(app.world_mut(), 0.0);
    println!(
        "{} creatures, {:.1} s simulated: {} collided with the puck or a wall, {} fell",
        summary.creatures, summary.sim_seconds, summary.creatures_collided, summary.falls
    );
    for level in Lod::ALL {
        println!(
            "  {:>10}: {:5.1} creatures on average",
            level.name(),
            summary.levels_mean[level]
        );
    }
    Ok(())
}
