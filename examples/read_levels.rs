//! A system of your own that reads each creature's level of detail and state every tick.
//!
//! ```sh
//! cargo run --release --example read_levels
//! ```
//!
//! Every level publishes the same components on the creature entity (the level contract):
//! [`Lod`], [`PlanarState`] (position, velocity, heading on the ground), [`GaitPhase`] and
//! `simlod::gait::GaitPose`. A system placed after [`SimStage::Outcome`] and before
//! [`SimStage::Clock`] in `FixedUpdate` sees them as the tick left them, whichever model stepped
//! the creature. It reads every creature every tick, so creatures are stepped a tick at a time
//! (`FrameStepping { enabled: false }`), as for the game's drawing.

use bevy::prelude::*;
use std::path::Path;

use simlod::config::SimConfig;
use simlod::creature::{Creature, GaitPhase, PlanarState};
use simlod::headless::HeadlessSim;
use simlod::lod::Lod;
use simlod::models::point_mass::FrameStepping;
use simlod::{SimClock, SimStage};

/// What our system gathers: time and distance at each level, and the level changes.
#[derive(Resource, Default)]
struct Watch {
    creature_seconds: [f64; 3],
    distance_m: [f64; 3],
    last_level: std::collections::HashMap<u32, Lod>,
    changes: u32,
    airborne_changes: u32,
}

fn watch_levels(
    clock: Res<SimClock>,
    mut watch: ResMut<Watch>,
    creatures: Query<(&Creature, &Lod, &PlanarState, &GaitPhase)>,
) {
    let dt = f64::from(clock.dt);
    for (creature, &level, state, gait) in &creatures {
        watch.creature_seconds[level as usize] += dt;
        watch.distance_m[level as usize] += f64::from(state.velocity.length()) * dt;
        let before = watch.last_level.insert(creature.serial, level);
        if before.is_some_and(|b| b != level) {
            watch.changes += 1;
            // The paper's rule (3.4): a change waits for the flight phase of the hop, unless
            // a collision forces it.
            watch.airborne_changes += u32::from(gait.in_flight);
        }
    }
    if clock.tick.is_multiple_of(u64::from(clock.tick_hz * 5)) {
        let mut at = [0; 3];
        for (_, &level, _, _) in &creatures {
            at[level as usize] += 1;
        }
        println!(
            "t = {:4.1} s: {} point masses, {} hybrids, {} rigid",
            clock.seconds(),
            at[0],
            at[1],
            at[2]
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("The default game for 20 s, read each tick by a system of this example's own:");
    let config = SimConfig::load(Path::new("assets/scenarios/default.ron"), Path::new("assets"))?;
    let mut sim = HeadlessSim::new(config);
    sim.app
        .init_resource::<Watch>()
        .insert_resource(FrameStepping { enabled: false })
        .add_systems(
            FixedUpdate,
            watch_levels.after(SimStage::Outcome).before(SimStage::Clock),
        );
    sim.run_for(20.0);

    let watch = sim.app.world().resource::<Watch>();
    for level in Lod::ALL {
        let (seconds, metres) = (watch.creature_seconds[level as usize], watch.distance_m[level as usize]);
        println!(
            "{:>10}: {seconds:6.1} creature-seconds, {:.2} m/s on average",
            level.name(),
            metres / seconds.max(1e-9)
        );
    }
    println!(
        "{} level changes seen: {} in the flight phase, {} outside it (at once: a collision forces those, paper 3.4)",
        watch.changes,
        watch.airborne_changes,
        watch.changes - watch.airborne_changes
    );
    Ok(())
}
