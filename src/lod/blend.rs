//! Blended switches (beyond paper 3.4, which suggests "interpolating joint angles between the
//! two levels of detail for a few motion cycles"), done as animation systems do it now:
//! inertialization (Bollo, GDC 2018), not a crossfade. At a switch the offset between where the
//! old model would have drawn the creature and where the new one does is recorded, and decayed
//! to zero over `blend_s` (the level rules) by a quintic that starts at the offset and ends
//! flat. Only the new model is evaluated; the blend changes what is drawn ([`Drawn`]), never
//! the simulation.
//!
//! Every switch is also measured: its pop is the largest jump of what is drawn, in the first
//! three ticks after the switch, away from where the drawn motion of the two ticks before it was
//! heading (body position, feet and leg lengths in metres; body orientation and leg angles in
//! degrees), and the jump in the body's drawn horizontal velocity. Measured both as drawn
//! (blended) and as the models alone give it.

use bevy::prelude::*;
use serde::Serialize;

use super::Lod;
use crate::contract::MAX_LEGS;
use crate::contract::PlanarState;
use crate::contract::{GaitPose, LegPose};
use crate::contract::{SimClock, SimStage, SimStart};
use crate::kind::{Creature, KindTable};

/// Scalars of a drawn pose that a blend offsets: body position (3), body rotation (3, as a
/// scaled axis), then each leg's length and two angles.
const CHANNELS: usize = 6 + 3 * MAX_LEGS;

/// What is drawn of a creature: its body in the world and its legs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Drawn {
    /// The body's centre in the world.
    pub body: Vec3,
    /// The body's orientation in the world.
    pub rotation: Quat,
    /// The body's height and tilt and each leg's length and angles.
    pub pose: GaitPose,
}

impl Drawn {
    /// Where the models put a creature at `state` in `pose`.
    pub fn of(state: &PlanarState, pose: &GaitPose) -> Self {
        Self {
            body: Vec3::new(state.position.x, pose.body_height_m, state.position.y),
            rotation: pose.body_rotation(state.heading),
            pose: *pose,
        }
    }

    /// Each leg's hip and foot in the world, its hips at `hips` on the body.
    pub fn hips_and_feet<'a>(&'a self, hips: &'a [Vec3]) -> impl Iterator<Item = (Vec3, Vec3)> + 'a {
        self.pose.legs().iter().zip(hips).map(|(leg, hip)| {
            let hip = self.body + self.rotation * *hip;
            (hip, hip + self.rotation * leg.direction() * leg.length_m)
        })
    }

    /// `self - other`, channel by channel.
    fn minus(&self, other: &Self) -> [f32; CHANNELS] {
        let mut out = [0.0; CHANNELS];
        out[..3].copy_from_slice(&(self.body - other.body).to_array());
        // The shorter way round: q and -q are the same turn.
        let turn = self.rotation * other.rotation.inverse();
        let turn = if turn.w < 0.0 { -turn } else { turn };
        out[3..6].copy_from_slice(&turn.to_scaled_axis().to_array());
        for (i, (a, b)) in self.pose.legs().iter().zip(other.pose.legs()).enumerate() {
            out[6 + 3 * i..9 + 3 * i].copy_from_slice(&[
                a.length_m - b.length_m,
                a.forward_rad - b.forward_rad,
                a.sideways_rad - b.sideways_rad,
            ]);
        }
        out
    }

    /// `self + offset`, channel by channel.
    fn plus(&self, offset: &[f32; CHANNELS]) -> Self {
        let mut drawn = *self;
        drawn.body += Vec3::from_slice(&offset[..3]);
        drawn.rotation = (Quat::from_scaled_axis(Vec3::from_slice(&offset[3..6])) * self.rotation).normalize();
        for (i, leg) in drawn.pose.legs_mut().iter_mut().enumerate() {
            let o = &offset[6 + 3 * i..9 + 3 * i];
            *leg = LegPose {
                length_m: leg.length_m + o[0],
                forward_rad: leg.forward_rad + o[1],
                sideways_rad: leg.sideways_rad + o[2],
            };
        }
        drawn
    }

    /// Where this motion, at `self` now and `previous` a tick ago, is a tick later.
    fn extrapolated(&self, previous: &Self) -> Self {
        self.plus(&self.minus(previous))
    }
}

/// Inertialization of one channel (Bollo): from offset `x0` moving at `v0`, to zero and flat at
/// `t1`. Where the offset moves toward zero so fast that it would overshoot, the blend is
/// shortened so it does not (Bollo), but to no less than a fifth of `t1`: shorter, the blend
/// would end within a few ticks (a pop), and capping `v0` instead breaks the motion's speed (a
/// pop of up to 2 cm at a swinging foot). Below that a small overshoot is drawn.
fn inertialize(x0: f32, v0: f32, t1: f32, t: f32) -> f32 {
    let t1 = if x0 * v0 < 0.0 {
        (-5.0 * x0 / v0).clamp(t1 / 5.0, t1)
    } else {
        t1
    };
    if t >= t1 || t1 <= 0.0 {
        return 0.0;
    }
    let a0 = (-8.0 * v0 * t1 - 20.0 * x0) / (t1 * t1);
    let a = -(a0 * t1 * t1 + 6.0 * v0 * t1 + 12.0 * x0) / (2.0 * t1.powi(5));
    let b = (3.0 * a0 * t1 * t1 + 16.0 * v0 * t1 + 30.0 * x0) / (2.0 * t1.powi(4));
    let c = -(3.0 * a0 * t1 * t1 + 12.0 * v0 * t1 + 20.0 * x0) / (2.0 * t1.powi(3));
    (((((a * t + b) * t + c) * t + a0 / 2.0) * t + v0) * t) + x0
}

/// A creature's drawing is blended from its old level's motion into its new one's. Stored
/// apart from the creatures' tables (as is [`SwitchProbe`]): a blend comes and goes with each
/// switch, and in a table its coming and going moved the creature's whole row, twice.
#[derive(Component, Clone, Copy, Debug)]
#[component(storage = "SparseSet")]
pub struct SwitchBlend {
    offset: [f32; CHANNELS],
    offset_rate: [f32; CHANNELS],
    start_s: f32,
    duration_s: f32,
}

impl SwitchBlend {
    /// The offset at `now_s`.
    fn offset(&self, now_s: f32) -> [f32; CHANNELS] {
        let t = now_s - self.start_s;
        std::array::from_fn(|i| inertialize(self.offset[i], self.offset_rate[i], self.duration_s, t))
    }

    /// What is drawn of the models' `drawn` at `now_s`.
    pub fn apply(&self, drawn: &Drawn, now_s: f32) -> Drawn {
        drawn.plus(&self.offset(now_s))
    }

    fn done(&self, now_s: f32) -> bool {
        now_s - self.start_s >= self.duration_s
    }
}

/// What is drawn of a creature now: its models' pose, blended if it switched lately.
pub fn drawn(state: &PlanarState, pose: &GaitPose, blend: Option<&SwitchBlend>, now_s: f32) -> Drawn {
    let model = Drawn::of(state, pose);
    blend.map_or(model, |b| b.apply(&model, now_s))
}

/// What was drawn (blended, and by the models alone) of a creature waiting for its flight
/// window, a tick before the current one: with the current drawing, the motion a switch must
/// continue. Kept by the switch for the creatures it waits on only.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct DrawnBefore(pub Option<(Drawn, Drawn)>);

/// A switch being measured over its first `PROBE_TICKS` ticks (stored apart, as a blend is).
#[derive(Component, Clone, Copy, Debug)]
#[component(storage = "SparseSet")]
pub struct SwitchProbe {
    /// The level left.
    pub from: Lod,
    /// The level entered.
    pub to: Lod,
    /// Whether a collision forced the switch, without waiting for the flight window.
    pub forced: bool,
    /// Drawn (and by the models alone) two ticks and one tick before the switch.
    before: [Drawn; 2],
    model_before: [Drawn; 2],
    /// The new model's first pose, and the drawn body in each tick after the switch.
    first_model: Drawn,
    after: [Vec3; PROBE_TICKS],
    pops: Pop,
    model_pops: Pop,
    ticks_seen: usize,
}

/// Ticks after a switch in which its pop is measured: the blend takes over in the first two,
/// and shows its own curvature in the third.
const PROBE_TICKS: usize = 3;

impl SwitchProbe {
    /// A switch from `from` to `to`; what was drawn two ticks and one tick before it.
    pub fn new(from: Lod, to: Lod, forced: bool, before: [Drawn; 2], model_before: [Drawn; 2]) -> Self {
        Self {
            from,
            to,
            forced,
            before,
            model_before,
            first_model: Drawn::default(),
            after: [Vec3::ZERO; PROBE_TICKS],
            pops: Pop::default(),
            model_pops: Pop::default(),
            ticks_seen: 0,
        }
    }
}

/// The size of one switch's pop.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pop {
    /// The largest jump of the body, a foot or a leg's length.
    pub metres: f32,
    /// The largest turn of the body or a leg.
    pub degrees: f32,
    /// The jump in the body's drawn horizontal velocity.
    pub velocity_m_per_s: f32,
}

/// How far `seen` is from `expected`.
fn jump(seen: &Drawn, expected: &Drawn, hips: &[Vec3]) -> Pop {
    let mut metres = seen.body.distance(expected.body);
    for ((_, a), (_, b)) in seen.hips_and_feet(hips).zip(expected.hips_and_feet(hips)) {
        metres = metres.max(a.distance(b));
    }
    let mut degrees = seen.rotation.angle_between(expected.rotation).to_degrees();
    for (a, b) in seen.pose.legs().iter().zip(expected.pose.legs()) {
        metres = metres.max((a.length_m - b.length_m).abs());
        degrees = degrees
            .max((a.forward_rad - b.forward_rad).abs().to_degrees())
            .max((a.sideways_rad - b.sideways_rad).abs().to_degrees());
    }
    Pop {
        metres,
        degrees,
        velocity_m_per_s: 0.0,
    }
}

impl Pop {
    fn max(self, other: Pop) -> Pop {
        Pop {
            metres: self.metres.max(other.metres),
            degrees: self.degrees.max(other.degrees),
            velocity_m_per_s: self.velocity_m_per_s.max(other.velocity_m_per_s),
        }
    }
}

/// One kind of switch: from, to, and whether a collision forced it.
pub type SwitchKind = (Lod, Lod, bool);

/// Every switch's pop over the run, by kind of switch.
#[derive(Resource, Clone, Debug, Default)]
pub struct PopTally {
    /// Each switch's kind, its pop as drawn and its pop by the models alone.
    pub pops: Vec<(SwitchKind, Pop, Pop)>,
    /// The latest switches (for the game's debug display), newest last.
    pub recent: Vec<(SwitchKind, Pop)>,
}

/// How many recent pops are kept for display.
const RECENT_POPS: usize = 6;

/// The largest and the 95th percentile of one measure.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Spread {
    /// The largest.
    pub max: f32,
    /// The 95th percentile.
    pub p95: f32,
}

impl Spread {
    fn of(mut values: Vec<f32>) -> Self {
        values.sort_by(f32::total_cmp);
        let at = |q: f32| {
            values
                .get(((values.len() as f32 - 1.0) * q).round() as usize)
                .copied()
                .unwrap_or(0.0)
        };
        Self {
            max: at(1.0),
            p95: at(0.95),
        }
    }
}

/// The pops of one kind of switch, as the summary prints them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PopSummary {
    /// The level left, by name.
    pub from: &'static str,
    /// The level entered, by name.
    pub to: &'static str,
    /// Whether collisions forced these switches, without waiting for the flight window.
    pub forced: bool,
    /// How many switches of this kind.
    pub count: usize,
    /// As drawn, blended.
    pub metres: Spread,
    /// As drawn: the largest turn of the body or a leg, degrees.
    pub degrees: Spread,
    /// As drawn: the jump in the body's horizontal velocity.
    pub velocity_m_per_s: Spread,
    /// As the models alone give it, unblended.
    pub model_metres: Spread,
    /// As the models alone give it: the largest turn, degrees.
    pub model_degrees: Spread,
}

impl PopTally {
    /// By kind of switch, in a fixed order.
    pub fn summary(&self) -> Vec<PopSummary> {
        let mut kinds: Vec<SwitchKind> = self.pops.iter().map(|p| p.0).collect();
        kinds.sort();
        kinds.dedup();
        kinds
            .into_iter()
            .map(|kind| {
                let of = |f: &dyn Fn(&(SwitchKind, Pop, Pop)) -> f32| {
                    Spread::of(self.pops.iter().filter(|p| p.0 == kind).map(f).collect())
                };
                PopSummary {
                    from: kind.0.name(),
                    to: kind.1.name(),
                    forced: kind.2,
                    count: self.pops.iter().filter(|p| p.0 == kind).count(),
                    metres: of(&|p| p.1.metres),
                    degrees: of(&|p| p.1.degrees),
                    velocity_m_per_s: of(&|p| p.1.velocity_m_per_s),
                    model_metres: of(&|p| p.2.metres),
                    model_degrees: of(&|p| p.2.degrees),
                }
            })
            .collect()
    }
}

/// Channel by channel, `a - b` per second of `dt`.
fn rate(a: &[f32; CHANNELS], b: &[f32; CHANNELS], dt: f32) -> [f32; CHANNELS] {
    std::array::from_fn(|i| (a[i] - b[i]) / dt)
}

/// The blend of a switch, and its pop. In the switch's first tick the drawing continues the old
/// motion; in its second, when the new model's own rate is known, the offset from the old
/// motion and the offset's rate are decayed from there (inertialization). Each tick of
/// [`PROBE_TICKS`] the drawing is compared with where the old drawn motion was heading.
fn blend_and_measure(
    mut commands: Commands,
    clock: Res<SimClock>,
    config: Res<crate::config::SimConfig>,
    kinds: Res<KindTable>,
    mut tally: ResMut<PopTally>,
    // Only creatures in a switch's probe or blend: the rest are not visited at all.
    mut creatures: Query<
        (
            Entity,
            &Creature,
            &PlanarState,
            &GaitPose,
            Option<&mut SwitchProbe>,
            Option<&SwitchBlend>,
        ),
        Or<(With<SwitchProbe>, With<SwitchBlend>)>,
    >,
) {
    // The time of the state this tick leaves (what is drawn until the next).
    let now = (clock.tick + 1) as f32 * clock.dt;
    let dt = clock.dt;
    let blend_s = config.rules.blend_s;
    for (entity, creature, state, pose, probe, blend) in &mut creatures {
        let Some(mut probe) = probe else {
            if blend.is_some_and(|b| b.done(now)) {
                commands.entity(entity).remove::<SwitchBlend>();
            }
            continue;
        };
        let hips = &kinds[creature.kind].hips_m;
        let model = Drawn::of(state, pose);
        let step = probe.ticks_seen;
        // Where the drawn motion (and the models') was heading, `step + 1` ticks on.
        let heading_to = |[prev, last]: [Drawn; 2]| {
            let (mut a, mut b) = (prev, last);
            for _ in 0..=step {
                (a, b) = (b, b.extrapolated(&a));
            }
            b
        };
        let expected = heading_to(probe.before);
        let seen = if blend_s > 0.0 && step < 2 {
            let [prev, last] = probe.before;
            let offset_rate = if step == 0 {
                [0.0; CHANNELS]
            } else {
                let old = rate(&last.minus(&prev), &[0.0; CHANNELS], dt);
                let new = rate(&model.minus(&probe.first_model), &[0.0; CHANNELS], dt);
                rate(&old, &new, 1.0)
            };
            commands.entity(entity).insert(SwitchBlend {
                offset: expected.minus(&model),
                offset_rate,
                start_s: now,
                duration_s: blend_s,
            });
            expected
        } else {
            drawn(state, pose, blend, now)
        };
        if step == 0 {
            probe.first_model = model;
        }
        probe.after[step] = seen.body;
        probe.pops = probe.pops.max(jump(&seen, &expected, hips));
        probe.model_pops = probe
            .model_pops
            .max(jump(&model, &heading_to(probe.model_before), hips));
        probe.ticks_seen += 1;
        if probe.ticks_seen == PROBE_TICKS {
            let [prev, last] = probe.before;
            let before = (last.body - prev.body).xz() / dt;
            let after = (probe.after[PROBE_TICKS - 1] - probe.after[PROBE_TICKS - 2]).xz() / dt;
            probe.pops.velocity_m_per_s = after.distance(before);
            let kind = (probe.from, probe.to, probe.forced);
            tally.pops.push((kind, probe.pops, probe.model_pops));
            tally.recent.push((kind, probe.pops));
            if tally.recent.len() > RECENT_POPS {
                tally.recent.remove(0);
            }
            commands.entity(entity).remove::<SwitchProbe>();
        }
    }
}

fn reset_pop_tally(mut tally: ResMut<PopTally>) {
    *tally = PopTally::default();
}

pub(super) fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    app.init_resource::<PopTally>()
        .add_systems(SimStart, reset_pop_tally)
        .add_systems(schedule, blend_and_measure.in_set(SimStage::Outcome));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_inertialized_offset_starts_where_it_was_and_ends_flat_at_zero() {
        let (x0, v0, t1) = (0.2, 0.5, 0.25);
        assert!((inertialize(x0, v0, t1, 0.0) - x0).abs() < 1e-6);
        let h = 1e-4;
        let rate = (inertialize(x0, v0, t1, h) - x0) / h;
        assert!((rate - v0).abs() < 0.01, "starts at the offset's rate: {rate}");
        assert!(inertialize(x0, v0, t1, t1 - 1e-3).abs() < 1e-4);
        assert_eq!(inertialize(x0, v0, t1, t1 + 1e-3), 0.0);
        // Moving toward zero fast, it stops at zero rather than overshooting, and it does not
        // drop there at once either.
        let samples: Vec<f32> = (0..50).map(|i| inertialize(0.1, -2.0, t1, i as f32 * 0.005)).collect();
        assert!(samples.iter().all(|x| *x >= -1e-4), "{samples:?}");
        assert!(samples.windows(2).all(|w| (w[0] - w[1]).abs() < 0.02), "{samples:?}");
        // Faster still, it keeps its speed (no pop) and overshoots a little instead, gone by
        // t1 / 5: from zero the quintic peaks at 0.082 v0 t, so under a tenth of v0 t1 / 5.
        let (x0, v0) = (0.01, -4.0);
        // (A finer step: the shortened blend curves a hundred times faster.)
        let h = 1e-5;
        let rate = (inertialize(x0, v0, t1, h) - x0) / h;
        assert!((rate - v0).abs() < 0.01, "keeps the offset's rate: {rate}");
        let samples: Vec<f32> = (0..50).map(|i| inertialize(x0, v0, t1, i as f32 * 0.001)).collect();
        let overshoot = -samples.iter().copied().fold(0.0, f32::min);
        assert!(overshoot < 0.1 * -v0 * t1 / 5.0, "{samples:?}");
        assert_eq!(inertialize(x0, v0, t1, t1 / 5.0 + 1e-3), 0.0);
    }

    #[test]
    fn a_drawn_pose_plus_its_difference_from_another_is_the_other() {
        let legs = [LegPose {
            length_m: 0.7,
            forward_rad: 0.2,
            sideways_rad: -0.1,
        }];
        let a = Drawn::of(
            &PlanarState {
                position: Vec2::new(1.0, 2.0),
                velocity: Vec2::ZERO,
                heading: Vec2::from_angle(0.3),
            },
            &GaitPose::new(0.8, 0.05, -0.02, &legs),
        );
        let mut b = a;
        b.body += Vec3::new(0.1, -0.05, 0.02);
        b.rotation = -(Quat::from_rotation_y(0.2) * b.rotation);
        b.pose.legs_mut()[0].forward_rad = -0.3;
        let back = b.plus(&a.minus(&b));
        assert!(back.body.distance(a.body) < 1e-5);
        assert!(back.rotation.angle_between(a.rotation) < 1e-4);
        // Either sign of a quaternion is the same turn: the difference is the short one.
        assert!(Vec3::from_slice(&a.minus(&b)[3..6]).length() < 0.21);
        assert!((back.pose.legs()[0].forward_rad - 0.2).abs() < 1e-6);
    }
}
