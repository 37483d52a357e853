//! Steering: creatures escape the puck and keep off the walls and each other.

use crate::support::*;
use bevy::prelude::*;
use simlod::config::SimConfig;
use simlod::contract::{DesiredVelocity, PlanarState};
use simlod::creature::Clearance;
use simlod::headless;
use simlod::outcome::Obstacle;

const SEEDS: std::ops::Range<u64> = 1..11;

/// Collisions with the puck and walls, and creatures that had one, summed over seeds.
fn hits(config: &SimConfig, seconds: f64) -> (u64, u64, u64) {
    let mut totals = (0, 0, 0);
    for seed in SEEDS {
        let mut c = config.clone();
        c.scenario.seed = seed;
        let s = headless::run(c, seconds);
        totals.0 += s.collisions[Obstacle::Puck];
        totals.1 += s.collisions[Obstacle::Wall];
        totals.2 += s.creatures_collided;
    }
    totals
}

/// The same creatures with every steering urge but wandering switched off.
fn without_steering(mut config: SimConfig) -> SimConfig {
    for k in &mut config.kinds {
        k.steering.puck_weight = 0.0;
        k.steering.wall_weight = 0.0;
        k.steering.wall_avoid_distance_m = 0.0;
        k.steering.separation_weight = 0.0;
    }
    config
}

#[test]
fn creatures_do_not_run_into_walls_on_their_own() {
    // A puck too small and slow to chase anyone: only wandering and wall avoidance remain.
    let mut config = default_config();
    config.arena.puck.radius_m = 0.05;
    config.arena.puck.speed_m_per_s = 0.01;
    let (_, wall, _) = hits(&config, 60.0);
    let (_, wall_unsteered, _) = hits(&without_steering(config), 60.0);
    eprintln!("wall collisions over 10 x 60 s of wandering: {wall} steered, {wall_unsteered} unsteered");
    // Steered, a wall is touched at most a few times in 400 creature-minutes (a rigid foot
    // swinging out near it); without steering, over ten times as often.
    assert!(
        wall_unsteered > 10 && wall * 10 < wall_unsteered,
        "wall collisions: {wall} steered, {wall_unsteered} without steering"
    );
}

#[test]
fn steering_keeps_collisions_with_the_puck_and_walls_low_in_the_default_scenario() {
    let config = default_config();
    let creatures = u64::from(config.scenario.creature_count());
    let (puck, wall, collided) = hits(&config, 20.0);
    let (puck_unsteered, wall_unsteered, collided_unsteered) = hits(&without_steering(config), 20.0);
    eprintln!(
        "steered: puck {puck} wall {wall} creatures {collided}; unsteered: puck {puck_unsteered} wall {wall_unsteered} creatures {collided_unsteered}"
    );
    // "Creatures mostly survive": over ten 20 s trials, fewer than one creature in ten
    // collides with the puck or a wall in a trial ...
    assert!(
        collided * 10 < creatures * SEEDS.count() as u64,
        "{collided} of {creatures} x 10 collided"
    );
    // ... and steering, not luck, is why: without it at least three times as many do.
    assert!(
        collided_unsteered >= 3 * collided.max(1),
        "unsteered {collided_unsteered} vs steered {collided}"
    );
}

/// What a watch over every decision's clearances saw.
#[derive(Resource, Default)]
struct ClearanceWatch {
    /// Creature-decisions checked, and of them those between two looks around.
    checked: u64,
    waiting: u64,
    /// Clearances wider than the distance to the nearest other creature.
    too_wide: Vec<String>,
}

/// After steering at each decision: each creature's clearance against the nearest other centre,
/// found by brute force (the positions the index was built from).
fn watch_clearances(
    clock: Res<simlod::contract::SimClock>,
    mut watch: ResMut<ClearanceWatch>,
    creatures: Query<(&simlod::kind::Creature, &PlanarState, &Clearance), Without<simlod::contract::PlayerControlled>>,
    everyone: Query<(&simlod::kind::Creature, &PlanarState)>,
) {
    if !clock.is_decision_tick() {
        return;
    }
    let decision = clock.decision() as u32;
    for (c, s, clear) in &creatures {
        let nearest = (everyone.iter())
            .filter(|(o, _)| o.serial != c.serial)
            .map(|(_, o)| o.position.distance(s.position))
            .fold(f32::INFINITY, f32::min);
        watch.checked += 1;
        watch.waiting += u64::from(clear.look_again > decision + 1);
        if clear.clear_m > nearest + 1e-4 {
            watch.too_wide.push(format!(
                "decision {decision}: creature {} clear {} m, nearest {nearest} m",
                c.serial, clear.clear_m
            ));
        }
    }
}

/// Watches every decision's clearances in `sim`, right after steering.
fn watch(sim: &mut simlod::headless::HeadlessSim) {
    sim.app.init_resource::<ClearanceWatch>().add_systems(
        FixedUpdate,
        watch_clearances
            .after(simlod::contract::SimStage::Steer)
            .before(simlod::contract::SimStage::SelectLod),
    );
}

/// The clearances watched over `seconds` of `config`, and the creatures that fell.
fn clearances_over(config: SimConfig, seconds: f64) -> (ClearanceWatch, u64) {
    let mut sim = simlod::headless::HeadlessSim::new(config);
    watch(&mut sim);
    sim.run_for(seconds);
    let falls = sim.summary(0.0).falls;
    let watch = sim.app.world_mut().remove_resource::<ClearanceWatch>().unwrap();
    (watch, falls)
}

#[test]
fn a_creature_that_looks_around_rarely_never_claims_more_clearance_than_it_has() {
    // The contact check passes by a creature whose clearance keeps it clear: between its looks
    // around, the clearance must shrink at least as fast as the others can close in, and a
    // creature respawned beside it must wake it. The default game (every level, the puck
    // knocking creatures over) and a crowd of point masses at ten times the density.
    let mut crowd = scene(
        &[("hopper", 300), ("biped", 100)],
        simlod::lod::LevelPolicy::AllPointMass,
    );
    crowd.arena.puck.speed_m_per_s = 6.0;
    for (config, seconds) in [(default_config(), 20.0), (crowd, 10.0)] {
        let (watch, falls) = clearances_over(config, seconds);
        eprintln!(
            "{} creature-decisions, {} between looks around, {falls} falls",
            watch.checked, watch.waiting
        );
        assert!(
            watch.too_wide.is_empty(),
            "{:#?}",
            &watch.too_wide[..watch.too_wide.len().min(10)]
        );
        assert!(watch.waiting * 10 > watch.checked, "the rare looks were exercised");
        assert!(falls > 0, "respawns were exercised");
    }
}

/// `hoppers` hoppers looking around once in `every` decisions when clear, in a court of 400 by
/// 400 m with a puck too small and slow to alarm anyone; the first at (100, 100), far from the
/// puck at the centre and from the walls.
fn open_court(hoppers: u32, every: u32) -> simlod::headless::HeadlessSim {
    let mut config = scene(&[("hopper", hoppers)], simlod::lod::LevelPolicy::AllPointMass);
    config.arena.court_length_m = 400.0;
    config.arena.court_width_m = 400.0;
    config.arena.puck.radius_m = 0.05;
    config.arena.puck.speed_m_per_s = 0.01;
    for k in &mut config.kinds {
        k.steering.look_every_decisions_when_clear = every;
    }
    let mut sim = simlod::headless::HeadlessSim::new(config);
    let world = sim.app.world_mut();
    let mut states = world.query::<(&simlod::kind::Creature, &mut PlanarState)>();
    for (c, mut s) in states.iter_mut(world) {
        if c.serial == 0 {
            s.position = Vec2::new(100.0, 100.0);
        }
    }
    sim
}

/// How many of `decisions` changed the desired velocity of a lone hopper in open court, looking
/// around once in `every` decisions when clear (it wanders 4 m in the 4 s).
fn looks_of_a_lone_hopper(every: u32, decisions: u32) -> u32 {
    let mut sim = open_court(1, every);
    let desired = |sim: &mut simlod::headless::HeadlessSim| {
        let world = sim.app.world_mut();
        world.query::<&DesiredVelocity>().single(world).unwrap().0
    };
    let mut last = desired(&mut sim);
    let mut changes = 0;
    for _ in 0..decisions {
        sim.advance_frame();
        let now = desired(&mut sim);
        changes += u32::from(now != last);
        last = now;
    }
    changes
}

#[test]
fn a_creature_with_nothing_within_reach_looks_around_once_in_its_number_of_decisions() {
    // Its wandering turns it a little at every look: each look changes its desired velocity.
    assert_eq!(looks_of_a_lone_hopper(1, 120), 120);
    assert_eq!(looks_of_a_lone_hopper(2, 120), 60);
    assert_eq!(looks_of_a_lone_hopper(4, 120), 30);
    // Its clearance reaches as far as it looked (its separation distance, 1.5 m) and shrinks by
    // 0.21 m a decision: after three waits it must look again to stay clear for the contacts.
    let every_seven = looks_of_a_lone_hopper(7, 119);
    assert!((30..=40).contains(&every_seven), "{every_seven} looks");
}

#[test]
fn a_creature_respawned_beside_one_between_its_looks_wakes_it() {
    // Hopper 0 looks around at decision 0 (its turn) and would wait until decision 4. Then the
    // other hopper falls and is respawned, as `outcome` does it, 0.8 m from it: at decision 1
    // its clearance (1.5 m less a decision's closing in) would claim more than it has.
    let mut sim = open_court(2, 4);
    watch(&mut sim);
    sim.advance_frame();
    let world = sim.app.world_mut();
    let mut creatures = world.query::<(Entity, &simlod::kind::Creature, &PlanarState, &Clearance)>();
    let rows: Vec<_> = creatures.iter(world).map(|(e, c, s, cl)| (e, *c, *s, *cl)).collect();
    let (_, first, state, clearance) = rows.iter().find(|r| r.1.serial == 0).unwrap();
    assert!(clearance.look_again == 4 && clearance.clear_m > 1.0, "{clearance:?}");
    let (other, ..) = rows.iter().find(|r| r.1.serial == 1).unwrap();
    let spot = state.position + Vec2::new(0.8, 0.0);
    let now = sim.clock().seconds() as f32;
    let world = sim.app.world_mut();
    world.despawn(*other);
    let kinds = world.resource::<simlod::kind::KindTable>().clone();
    let bundle = world.resource_scope(|_, mut rng: Mut<simlod::contract::WorldRng>| {
        simlod::creature::creature_bundle(
            first.kind,
            &kinds[first.kind],
            2,
            simlod::lod::Lod::PointMass,
            spot,
            now,
            &mut rng,
        )
    });
    world.spawn(bundle);
    world.resource_mut::<simlod::creature::Newcomers>().placed_at.push(spot);
    sim.advance_frame();
    let watch = sim.app.world_mut().remove_resource::<ClearanceWatch>().unwrap();
    assert_eq!(watch.checked, 4, "two decisions of two creatures");
    assert!(watch.too_wide.is_empty(), "{:#?}", watch.too_wide);
}
