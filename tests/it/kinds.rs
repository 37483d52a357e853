//! A legged kind is data: kinds that exist only in the tests' own files (a heavier hopper on
//! longer legs, a two-legged kind, a four-legged pacer) are built and stepped at every level, by
//! the same code that runs the shipped kinds.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use std::path::{Path, PathBuf};

use crate::support::*;
use simlod::config::{CreatureDef, SimConfig, Stance, load_file};
use simlod::creature::{Creature, PlanarState};
use simlod::gait::{GaitPose, GaitRow, GaitTable, columns};
use simlod::headless::HeadlessSim;
use simlod::lod::{LevelPolicy, Lod};
use simlod::models::rigid::RigidPart;
use simlod_lab::record::{RecordSettings, record, to_file_text};

/// The tests' own asset folder, copied to a scratch folder of `name` (a test may add to it).
fn fixture_assets(name: &str) -> PathBuf {
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/it/fixtures");
    let to = scratch_dir(name);
    for dir in ["", "creatures", "rules", "scenarios", "gaits"] {
        std::fs::create_dir_all(to.join(dir)).unwrap();
        for entry in std::fs::read_dir(from.join(dir)).into_iter().flatten().flatten() {
            if entry.path().is_file() {
                std::fs::copy(entry.path(), to.join(dir).join(entry.file_name())).unwrap();
            }
        }
    }
    to
}

/// The fixtures' scene with `count` of `kind` only, under `policy`.
fn scene(assets: &Path, kind: &str, count: u32, policy: LevelPolicy) -> SimConfig {
    let text = std::fs::read_to_string(assets.join("scenarios/pinned.ron"))
        .unwrap()
        .replace(
            "(kind: \"pinned\", count: 8)",
            &format!("(kind: \"{kind}\", count: {count})"),
        );
    let file = assets.join(format!("scenarios/scene-{kind}.ron"));
    std::fs::write(&file, text).unwrap();
    let mut config = SimConfig::load(&file, assets).unwrap();
    config.scenario.level_policy = policy;
    config
}

fn levels(sim: &mut HeadlessSim) -> Vec<Lod> {
    let world = sim.app.world_mut();
    world
        .query_filtered::<&Lod, With<Creature>>()
        .iter(world)
        .copied()
        .collect()
}

/// A world of `config` whose every pose is worked out at every tick (frame stepping off), as a
/// reader of poses needs: a hybrid behind its frame is posed only where the simulation reads it.
fn posed_sim(config: SimConfig) -> HeadlessSim {
    let mut sim = HeadlessSim::new(config);
    sim.app
        .insert_resource(simlod::models::point_mass::FrameStepping { enabled: false });
    sim
}

fn poses(sim: &mut HeadlessSim) -> Vec<(PlanarState, GaitPose)> {
    let world = sim.app.world_mut();
    world
        .query::<(&PlanarState, &GaitPose)>()
        .iter(world)
        .map(|(s, p)| (*s, *p))
        .collect()
}

/// The fixtures' scene with the kind of `creatures/<kind>.ron` added, one of it, all rigid.
fn scene_adding(assets: &Path, kind: &str) -> SimConfig {
    let def: CreatureDef = load_file(&assets.join(format!("creatures/{kind}.ron"))).unwrap();
    let mut config = scene(assets, "pinned", 1, LevelPolicy::AllRigid);
    config.kinds.push(def);
    config.gaits.push(None);
    config.scenario.creatures[0].kind = kind.into();
    config
}

/// Records the table of the fixtures' `kind` into its scratch folder, as `simlod record-gait`
/// does, then runs four of it at each level: they move, at the hybrid and rigid levels on legs
/// of lengths within `leg_lengths_m` that all move, and only the rigid level has bodies.
fn records_its_table_and_runs_at_every_level(kind: &str, leg_lengths_m: std::ops::Range<f32>) {
    let assets = fixture_assets(&format!("kind_{kind}"));
    let config = scene_adding(&assets, kind);
    let legs = config.kinds.last().unwrap().legs.len();
    let settings = RecordSettings {
        speeds_m_per_s: vec![0.0, 1.0, 2.0],
        ..RecordSettings::default()
    };
    let table = record(&config, kind, &settings).unwrap_or_else(|e| panic!("{kind}: {e}"));
    assert_eq!(table.columns, columns(legs));
    std::fs::write(assets.join(format!("gaits/{kind}.ron")), to_file_text(&table, "test")).unwrap();

    for (policy, level) in [
        (LevelPolicy::AllPointMass, Lod::PointMass),
        (LevelPolicy::AllHybrid, Lod::Hybrid),
        (LevelPolicy::AllRigid, Lod::Rigid),
    ] {
        let mut sim = posed_sim(scene(&assets, kind, 4, policy));
        let before = poses(&mut sim);
        sim.run_for(4.0);
        assert_eq!(levels(&mut sim), vec![level; 4], "{policy:?}");
        let after = poses(&mut sim);
        let moved = before
            .iter()
            .zip(&after)
            .filter(|(a, b)| a.0.position.distance(b.0.position) > 0.1)
            .count();
        assert!(moved >= 2, "{policy:?}: {moved} of 4 {kind}s moved");
        if level != Lod::PointMass {
            // Its own legs at its own lengths, every one of them moving over a step.
            sim.run_for(0.1);
            let later = poses(&mut sim);
            for leg in 0..legs {
                let lengths: Vec<f32> = after.iter().map(|(_, p)| p.legs()[leg].length_m).collect();
                assert!(
                    lengths.iter().all(|l| leg_lengths_m.contains(l)),
                    "{policy:?}: leg {leg}: {lengths:?}"
                );
                let swung = after
                    .iter()
                    .zip(&later)
                    .any(|(a, b)| a.1.legs()[leg].direction().angle_between(b.1.legs()[leg].direction()) > 0.01);
                assert!(swung, "{policy:?}: leg {leg} of every {kind} still");
            }
        }
        let world = sim.app.world_mut();
        let parts = world.query::<&RigidPart>().iter(world).count();
        assert_eq!(
            parts,
            if level == Lod::Rigid { (1 + 2 * legs) * 4 } else { 0 },
            "{policy:?}"
        );
    }
}

#[test]
fn a_kind_from_files_alone_gets_a_gait_table_and_runs_at_every_level() {
    // The stilt's rest length is 0.85 m (the hopper's 0.75).
    records_its_table_and_runs_at_every_level("stilt", 0.62..0.95);
}

#[test]
fn a_four_legged_kind_a_modder_writes_gets_its_table_and_runs_at_every_level() {
    // Four legs that pace: a grouping of virtual legs no shipped kind uses.
    records_its_table_and_runs_at_every_level("pacer", 0.55..0.95);
}

#[test]
fn a_kind_whose_rigid_model_falls_is_told_what_fell_and_which_numbers_to_look_at() {
    // The pacer made to bound (front legs, then back legs): its pitch is not held at a run.
    let assets = fixture_assets("kind_bounder");
    let mut config = scene_adding(&assets, "pacer");
    config.kinds.last_mut().unwrap().stance = Stance::VirtualLegs(vec![vec![0, 1], vec![2, 3]]);
    let settings = RecordSettings {
        speeds_m_per_s: vec![0.0, 1.0],
        ..RecordSettings::default()
    };
    let err = record(&config, "pacer", &settings)
        .expect_err("the bound falls at 1 m/s")
        .to_string();
    for words in [
        "\"pacer\" fell at",
        "commanded 1 m/s",
        "m high",
        "tilted",
        "virtual leg",
        "look first at",
        "rigid.",
    ] {
        assert!(err.contains(words), "{words:?} not in: {err}");
    }
}

#[test]
fn a_two_legged_kind_is_built_and_stepped_at_every_level() {
    let assets = fixture_assets("kind_strider");
    let mut config = scene(&assets, "strider", 3, LevelPolicy::AllRigid);
    // A table made here, not recorded: one stride of two steps, each leg long in its own
    // stance and short while the other leg's turn.
    let sample = |t: f32| {
        let (a, b) = if t < 0.5 { (0.85, 0.7) } else { (0.7, 0.85) };
        vec![0.9, 0.0, 0.0, a, 0.0, 0.0, b, 0.0, 0.0]
    };
    config.gaits[0] = Some(GaitTable {
        creature: "strider".into(),
        sample_hz: 30.0,
        steps_per_stride: 2,
        columns: columns(2),
        acceleration_limit_m_per_s2: 2.0,
        top_speed_m_per_s: 2.0,
        rows: vec![GaitRow {
            speed_m_per_s: 0.0,
            hop_period_s: 0.4,
            stance_fraction: 0.5,
            samples: (0..24).map(|k| sample(k as f32 / 24.0)).collect(),
        }],
    });

    // Rigid: a body and two legs of two parts each, each leg's parts on two impulse joints.
    let mut sim = HeadlessSim::new(config.clone());
    sim.run_for(0.5);
    let world = sim.app.world_mut();
    assert_eq!(world.query::<&RigidPart>().iter(world).count(), 5 * 3);
    let joints = world.query::<&RapierContextJoints>().single(world).unwrap();
    assert_eq!(joints.impulse_joints.len(), 4 * 3);
    for (_, pose) in poses(&mut sim) {
        assert_eq!(pose.legs().len(), 2);
        assert!(
            pose.legs().iter().all(|l| (0.55..1.1).contains(&l.length_m)),
            "{pose:?}"
        );
    }
    // Stepped for a while without a panic, whatever its balance (its controller is tuned in
    // its own issue); falls are removed and respawned at the same level.
    sim.run_for(3.0);
    assert_eq!(levels(&mut sim), vec![Lod::Rigid; 3]);

    // Hybrid: both legs follow the table, in turn.
    config.scenario.level_policy = LevelPolicy::AllHybrid;
    let mut sim = posed_sim(config.clone());
    let mut seen = [false; 2];
    for _ in 0..30 {
        sim.advance_frame();
        for (_, pose) in poses(&mut sim) {
            let (a, b) = (pose.legs()[0].length_m, pose.legs()[1].length_m);
            assert!((a + b - 1.55).abs() < 0.16, "one leg long, the other short: {a} {b}");
            seen[usize::from(a > b)] = true;
        }
    }
    assert_eq!(seen, [true, true], "each leg takes its turn");
    assert_eq!(levels(&mut sim), vec![Lod::Hybrid; 3]);

    // Point mass: both legs held straight down.
    config.scenario.level_policy = LevelPolicy::AllPointMass;
    let mut sim = HeadlessSim::new(config);
    sim.run_for(1.0);
    for (_, pose) in poses(&mut sim) {
        assert_eq!(pose.legs().len(), 2);
        assert!(
            pose.legs()
                .iter()
                .all(|l| l.forward_rad == 0.0 && l.sideways_rad == 0.0)
        );
    }
}

#[test]
fn the_pinned_scene_gives_the_same_digest_as_when_it_was_pinned() {
    let assets = fixture_assets("pinned");
    let mut sim = HeadlessSim::new(scene(&assets, "pinned", 8, LevelPolicy::Influence));
    sim.run_for(5.0);
    let summary = sim.summary(0.0);
    assert!(summary.switches.total() > 0 && summary.levels_mean[Lod::Rigid] > 0.0);
    // Any change to what the simulation computes moves this; a deliberate one re-pins it.
    assert_eq!(sim.state_digest(), PINNED_DIGEST, "{summary:?}");
}

const PINNED_DIGEST: u64 = 14568542103330336229;

/// The shipped scenario with the third kind, made of asset files alone.
fn three_kinds(policy: LevelPolicy) -> SimConfig {
    let root = assets_root();
    let mut config = SimConfig::load(&root.join("scenarios/three-kinds.ron"), &root).expect("the shipped assets load");
    config.scenario.level_policy = policy;
    config
}

#[test]
fn the_shipped_stilt_is_asset_files_alone_and_its_table_is_the_commands() {
    // Its table is what the command writes from its file, byte for byte.
    let mut config = three_kinds(LevelPolicy::AllRigid);
    let stilt = config.kind_index("stilt").unwrap();
    config.gaits[stilt] = None; // as record-gait does: never from an earlier table
    let table = record(&config, "stilt", &RecordSettings::default()).unwrap();
    let command = "simlod record-gait --creature assets/creatures/stilt.ron --speeds 0,1,2,3";
    let shipped = std::fs::read_to_string(assets_root().join("gaits/stilt.ron")).unwrap();
    assert_eq!(to_file_text(&table, command), shipped);

    // Every policy moves its stilts at that level.
    every_fixed_policy_moves(three_kinds, "stilt", 10);
}

#[test]
fn every_fixed_policy_moves_hoppers_and_bipeds_at_its_level() {
    // The default game's two kinds, in a scene of their own.
    let make = |policy| crate::support::scene(&[("hopper", 30), ("biped", 10)], policy);
    every_fixed_policy_moves(make, "hopper", 30);
    every_fixed_policy_moves(make, "biped", 10);
}

/// Under each fixed policy, the `count` creatures of `kind` in the world `make` builds are
/// all at that policy's level after 3 s, and at least half of them moved.
fn every_fixed_policy_moves(make: impl Fn(LevelPolicy) -> SimConfig, kind: &str, count: usize) {
    for (policy, level) in [
        (LevelPolicy::AllPointMass, Lod::PointMass),
        (LevelPolicy::AllHybrid, Lod::Hybrid),
        (LevelPolicy::AllRigid, Lod::Rigid),
    ] {
        let config = make(policy);
        let index = config.kind_index(kind).unwrap();
        let mut sim = HeadlessSim::new(config);
        let of_kind = |sim: &mut HeadlessSim| -> Vec<(Lod, Vec2)> {
            let world = sim.app.world_mut();
            world
                .query::<(&Creature, &Lod, &PlanarState)>()
                .iter(world)
                .filter(|(c, _, _)| c.kind == index)
                .map(|(_, l, s)| (*l, s.position))
                .collect()
        };
        let before = of_kind(&mut sim);
        sim.run_for(3.0);
        let after = of_kind(&mut sim);
        assert_eq!(after.len(), count, "{kind}, {policy:?}");
        assert!(after.iter().all(|(l, _)| *l == level), "{kind}, {policy:?}: {after:?}");
        let moved = before
            .iter()
            .zip(&after)
            .filter(|(a, b)| a.1.distance(b.1) > 0.1)
            .count();
        assert!(moved >= count / 2, "{kind}, {policy:?}: {moved} of {count} moved");
    }
}
