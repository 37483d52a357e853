use bevy::prelude::*;
use simlod::config::SimConfig;
use simlod::creature::{DesiredVelocity, PlanarState, PlayerControlled};
use simlod::headless::HeadlessSim;
use simlod::lod::LevelPolicy;
use simlod::models::rigid::{Raibert, RigidHopper};
use std::path::Path;

fn main() {
    let args: Vec<f32> = std::env::args().skip(1).map(|a| a.parse().unwrap()).collect();
    let (vx, secs) = (
        args.first().copied().unwrap_or(0.0),
        args.get(1).copied().unwrap_or(5.0) as f64,
    );
    let root = Path::new("assets");
    let mut config = SimConfig::load(&root.join("scenarios/default.ron"), root).unwrap();
    config.scenario.creatures.retain(|g| g.kind == "hopper");
    config.scenario.creatures[0].count = 1;
    config.scenario.level_policy = LevelPolicy::AllRigid;
    config.arena.puck.speed_m_per_s = 0.001;
    config.arena.court_length_m = 420.0;
    config.arena.court_width_m = 420.0;
    if std::env::var("TICK").is_ok() {
        config.scenario.decision_hz = config.scenario.tick_hz;
    }
    let mut sim = HeadlessSim::new(config);
    {
        let w = sim.app.world_mut();
        let e = w
            .query_filtered::<Entity, With<simlod::creature::Creature>>()
            .single(w)
            .unwrap();
        w.entity_mut(e)
            .insert((PlayerControlled, DesiredVelocity(Vec2::new(vx, 0.0))));
        let mut q = w.query::<&mut PlanarState>();
        let mut s = q.single_mut(w).unwrap();
        s.position = Vec2::new(50.0, -80.0);
        s.heading = Vec2::X;
    }
    let mut t = 0.0f64;
    while t < secs {
        sim.advance_frame();
        t = sim.clock().seconds();
        let w = sim.app.world_mut();
        let Some((h, r, s)) = w
            .query::<(&RigidHopper, &Raibert, &PlanarState)>()
            .iter(w)
            .next()
            .map(|(h, r, s)| (*h, r.clone(), *s))
        else {
            println!("{t:.2} gone");
            break;
        };
        let body = *w.get::<Transform>(h.body).unwrap();
        let foot = *w.get::<Transform>(h.lower_leg).unwrap();
        let upper = *w.get::<Transform>(h.upper_leg).unwrap();
        if std::env::var("TICK").is_ok() {
            println!(
                "body {} {:?} upper {} {:?} lower {} {:?}",
                body.translation, body.rotation, upper.translation, upper.rotation, foot.translation, foot.rotation
            );
        }
        let up = body.rotation * Vec3::Y;
        println!(
            "{t:5.2} x {:6.2} z {:6.2} vx {:5.2} vz {:5.2} y {:.3} tilt {:5.1} leg {:.3} foot {:.3} {:?} thrust {:.3} Ts {:.3} T {:.3}",
            s.position.x,
            s.position.y,
            s.velocity.x,
            s.velocity.y,
            body.translation.y,
            up.angle_between(Vec3::Y).to_degrees(),
            (foot.translation - body.translation).length(),
            foot.translation.y,
            r.phase,
            r.thrust_m,
            r.stance_s,
            r.hop_period_s
        );
    }
}
