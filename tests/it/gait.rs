//! The gait table and the hybrid level (paper 3.2).

use bevy::prelude::*;

use crate::support::*;
use simlod::config::{ConfigError, SimConfig, load_file};
use simlod::creature::{DesiredVelocity, GaitPhase, PlanarState};
use simlod::gait::{GaitPose, GaitTable, columns};
use simlod::lod::{LevelPolicy, Lod};
use simlod_lab::experiments::{lone_creature, stand};
use simlod_lab::record::{RecordSettings, record, to_file_text};

const SHIPPED: &str = "gaits/hopper.ron";

/// Records `kind`'s table as `simlod record-gait` does by default and compares it with the
/// shipped one, byte for byte.
fn recording_again_reproduces(kind: &str, command: &str) {
    let mut config = config_having(kind);
    let index = config.kind_index(kind).unwrap();
    config.gaits[index] = None; // as record-gait does: never from an earlier table
    let settings = RecordSettings::up_to(config.kinds[index].top_speed_m_per_s);
    let table = record(&config, kind, &settings).unwrap();
    let shipped = std::fs::read_to_string(assets_root().join(format!("gaits/{kind}.ron"))).unwrap();
    assert!(
        shipped.contains(command),
        "the shipped table's header names the command that made it"
    );
    assert_eq!(to_file_text(&table, command), shipped);
}

#[test]
fn recording_again_reproduces_the_shipped_table() {
    recording_again_reproduces(
        "hopper",
        "simlod record-gait --creature assets/creatures/hopper.ron --speeds 0,1,2,3",
    );
}

#[test]
fn recording_the_biped_again_reproduces_its_shipped_table_with_both_legs() {
    recording_again_reproduces(
        "biped",
        "simlod record-gait --creature assets/creatures/biped.ron --speeds 0,1,2,2.5",
    );
    let config = default_config();
    let table = config.gaits[config.kind_index("biped").unwrap()].as_ref().unwrap();
    assert_eq!(table.columns, columns(2));
    assert_eq!(table.steps_per_stride, 2, "a stride is a step of each leg");
}

#[test]
fn recording_the_kinds_on_virtual_legs_again_reproduces_their_shipped_tables() {
    for kind in ["kangaroo", "quadruped"] {
        let command = format!("simlod record-gait --creature assets/creatures/{kind}.ron --speeds 0,1,2");
        recording_again_reproduces(kind, &command);
    }
}

#[test]
fn the_table_matches_the_rigid_models_measured_limits() {
    let table = &default_config().gaits[0].clone().unwrap();
    assert_eq!(table.rows.len(), 4);
    // The rigid hopper really runs near 3 m/s and its hop rhythm barely changes with speed
    // (the paper's reason why interpolating the table works).
    assert!(
        table.top_speed_m_per_s > 2.5 && table.top_speed_m_per_s < 3.2,
        "{}",
        table.top_speed_m_per_s
    );
    let periods: Vec<f32> = table.rows.iter().map(|r| r.hop_period_s).collect();
    let (lo, hi) = (
        periods.iter().cloned().fold(f32::MAX, f32::min),
        periods.iter().cloned().fold(0.0, f32::max),
    );
    assert!(hi / lo < 1.15, "hop periods {periods:?}");
    assert!(table.acceleration_limit_m_per_s2 > 0.3 && table.acceleration_limit_m_per_s2 < 3.0);
}

fn broken(test: &str, edit: impl Fn(&str) -> String) -> ConfigError {
    let dir = scratch_dir(test);
    let file = dir.join("gait.ron");
    let text = std::fs::read_to_string(assets_root().join(SHIPPED)).unwrap();
    std::fs::write(&file, edit(&text)).unwrap();
    load_file::<GaitTable>(&file).unwrap_err()
}

/// The shipped table with its first sample's values passed through `edit`.
fn first_sample_edited(text: &str, edit: impl Fn(Vec<&str>) -> Vec<String>) -> String {
    let start = text.find("samples: [").unwrap() + "samples: [".len();
    let open = start + text[start..].find('[').unwrap() + 1;
    let close = open + text[open..].find(']').unwrap();
    let values: Vec<&str> = text[open..close].split(", ").collect();
    format!("{}{}{}", &text[..open], edit(values).join(", "), &text[close..])
}

#[test]
fn a_sample_row_of_another_length_is_named() {
    let err = broken("gait_row_length", |t| {
        first_sample_edited(t, |v| v[..5].iter().map(|s| s.to_string()).collect())
    });
    let text = err.to_string();
    assert!(
        text.contains("gait.ron") && text.contains("`rows[0].samples[0]`") && text.contains("has 5 values"),
        "{text}"
    );
}

#[test]
fn speeds_out_of_order_are_refused() {
    let err = broken("gait_order", |t| {
        t.replacen("speed_m_per_s: 1.", "speed_m_per_s: 9.", 1)
    });
    assert!(err.to_string().contains("increasing order"), "{err}");
}

#[test]
fn a_nan_in_the_table_is_named() {
    let err = broken("gait_nan", |t| {
        first_sample_edited(t, |v| {
            std::iter::once("NaN".to_owned())
                .chain(v[1..].iter().map(|s| s.to_string()))
                .collect()
        })
    });
    let text = err.to_string();
    assert!(
        text.contains("`rows[0].samples[0]`") && text.contains("body_height_m is NaN"),
        "{text}"
    );
}

#[test]
fn an_empty_table_is_refused() {
    let err = broken("gait_empty", |t| {
        let start = t.find("rows: [").unwrap();
        format!("{}rows: [],\n)", &t[..start])
    });
    assert!(err.to_string().contains("the table is empty"), "{err}");
}

/// Runs a rigid and a hybrid creature of `kind` side by side at `speed` and compares their
/// poses at the same phase of the stride, once settled: the largest gap in each of the table's
/// columns.
fn pose_gap(kind: &str, speed: f32) -> Vec<f32> {
    let config: SimConfig = config_having(kind);
    let start = Vec2::new(-180.0, 0.0);
    let mut runners: Vec<_> = [LevelPolicy::AllRigid, LevelPolicy::AllHybrid]
        .into_iter()
        .map(|policy| {
            let (mut sim, e) = lone_creature(&config, kind, policy, start, 420.0);
            let world = sim.app.world_mut();
            world.entity_mut(e).insert(DesiredVelocity(Vec2::new(speed, 0.0)));
            // Facing its course: the gap of a steady run, not of a turn.
            stand(world, e, start, Some(Vec2::X));
            sim.run_for(12.0);
            (sim, e)
        })
        .collect();
    let table = config.gaits[config.kind_index(kind).unwrap()].clone().unwrap();
    let mut gap = vec![0.0f32; table.columns.len()];
    for _ in 0..90 {
        for (sim, _) in &mut runners {
            sim.advance_frame();
        }
        // The rigid creature's phase, measured; the table's pose at that phase and speed.
        let (sim, e) = &runners[0];
        let world = sim.app.world();
        assert_eq!(world.get::<Lod>(*e), Some(&Lod::Rigid), "the rigid {kind} is standing");
        let rigid = *world.get::<GaitPose>(*e).unwrap();
        let phase = world.get::<GaitPhase>(*e).unwrap().stride(table.steps_per_stride);
        let speed_now = world.get::<PlanarState>(*e).unwrap().velocity.length();
        let played = table.pose(speed_now, phase);
        for ((g, r), p) in gap.iter_mut().zip(rigid.to_row()).zip(played.to_row()) {
            *g = g.max((r - p).abs());
        }
        // And the hybrid creature itself plays the same table.
        let (sim, e) = &runners[1];
        let world = sim.app.world();
        let (g, p) = (world.get::<GaitPhase>(*e).unwrap(), world.get::<GaitPose>(*e).unwrap());
        let s = world.get::<PlanarState>(*e).unwrap();
        assert_eq!(*p, table.pose(s.velocity.length(), g.stride(table.steps_per_stride)));
    }
    gap
}

/// The table of `kind` played at its rigid model's own phase and speed stays within the
/// limits at each of `speeds`.
fn hybrid_pose_follows_the_rigid_model(kind: &str, speeds: &[f32]) {
    // What a viewer sees of a creature 0.8-0.9 m tall: a few centimetres of height and a few
    // degrees of body or leg angle are invisible at game distances; the hop itself is 25 cm
    // and the leg swings 25 degrees.
    // Limits by column: body height, roll, pitch, then each leg's length, forward and
    // sideways angles (lengths in metres, angles in degrees).
    let (body, leg) = ([0.05, 5.0, 5.0], [0.05, 8.0, 8.0]);
    for &speed in speeds {
        let gap = pose_gap(kind, speed);
        let limits = body.iter().chain(leg.iter().cycle()).copied();
        for (i, (column, limit)) in columns((gap.len() - 3) / 3).iter().zip(limits).enumerate() {
            let g = if column.ends_with("_rad") {
                gap[i].to_degrees()
            } else {
                gap[i]
            };
            eprintln!("{kind} at {speed} m/s: largest gap in {column}: {g:.4}");
            assert!(g < limit, "{kind} at {speed} m/s: {column} off by {g} (limit {limit})");
        }
    }
}

#[test]
fn at_steady_speeds_the_hybrid_pose_follows_the_rigid_model() {
    hybrid_pose_follows_the_rigid_model("hopper", &[0.0, 1.5, 2.0, 2.8]);
}

#[test]
fn at_steady_speeds_the_hybrid_biped_follows_the_rigid_biped() {
    // Both legs' columns, at the table's rows and between them, up to near its top speed.
    hybrid_pose_follows_the_rigid_model("biped", &[0.0, 1.5, 2.0, 2.4]);
}

#[test]
fn at_steady_speeds_the_hybrid_kinds_on_virtual_legs_follow_their_rigid_models() {
    // Every leg's columns, at the table's rows and between them, up to near the top speed.
    hybrid_pose_follows_the_rigid_model("kangaroo", &[0.0, 1.0, 1.5, 1.9]);
    hybrid_pose_follows_the_rigid_model("quadruped", &[0.0, 1.0, 1.5, 1.75]);
}

#[test]
fn hoppers_and_bipeds_run_all_hybrid() {
    let config = scene(&[("hopper", 30), ("biped", 10)], LevelPolicy::AllHybrid);
    let summary = simlod::headless::run(config, 10.0);
    assert_eq!(summary.levels[Lod::Hybrid], 40, "hoppers and bipeds have a gait table");
}
