//! The simulation's schedule: no two of its systems may touch the same data in an order left to
//! Bevy, in a simulation meant to be bit-identical from run to run.

use bevy::prelude::*;

use crate::support::*;
use simlod::headless::HeadlessSim;

#[test]
fn no_two_simulation_systems_race_for_the_same_data() {
    let mut sim = HeadlessSim::new(default_config());
    // The first frame builds the fixed schedule and its ambiguity analysis.
    sim.advance_frame();
    let world = sim.app.world();
    let schedule = world
        .resource::<Schedules>()
        .get(FixedUpdate)
        .expect("the fixed schedule");
    let graph = schedule.graph();
    let all: Vec<_> = graph
        .conflicting_systems()
        .to_string(graph, world.components())
        .collect();
    // Rapier's own systems are its business; ours (and ours against rapier's) are ours.
    let ours: Vec<String> = all
        .iter()
        .filter(|(a, b, _)| a.starts_with("simlod::") || b.starts_with("simlod::"))
        .map(|(a, b, on)| format!("{a} and {b} on {on:?}"))
        .collect();
    assert!(
        ours.is_empty(),
        "systems whose order is Bevy's choice:\n{}",
        ours.join("\n")
    );
}
