//! Raibert's running controller (Legged Robots That Balance, 1986; paper section 3.1), for any
//! number of legs, in three decoupled parts that act through the virtual leg in stance
//! (Raibert's "one-foot" running: a biped's legs take turns, each stance like a hop of the
//! hopper; a quadruped's legs that touch down together act as one virtual leg, Raibert,
//! Chepponis and Brown 1986):
//! - hop height: the stance leg's spring rest length is raised by a thrust during the second
//!   half of stance; the thrust is adjusted once a step toward the configured flight time;
//! - body attitude: in stance, a hip torque between body and stance leg holds the body level,
//!   and a yaw torque turns it toward its heading (through the foot's grip: rapier's point
//!   contact has no torsional friction, so that torque acts on the body alone, capped by the
//!   grip);
//! - speed: in flight the hip swings the leg that lands next so that its foot lands at the
//!   neutral point, half the distance the body travels in stance, plus a correction
//!   proportional to the velocity error. Each foot of a virtual leg lands as far from its own
//!   hip as the virtual foot from the virtual leg's hip.
//!
//! With virtual legs in turn, the idle legs are shortened to clear the ground and swung to
//! mirror the active virtual leg, so that the next one is forward when its turn comes.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use std::f32::consts::PI;

use super::{RigidBodies, RigidPart};
use crate::config::{LegConfig, RigidConfig};
use crate::contract::AtRigid;
use crate::contract::FallQueue;
use crate::contract::GaitPose;
use crate::contract::MAX_LEGS;
use crate::contract::SimClock;
use crate::contract::{DesiredVelocity, GaitPhase, PlanarState};
use crate::kind::{Creature, KindParams, KindTable, VirtualLegs};

/// Foot centre this far above its resting height still counts as on the ground.
pub(super) const FOOT_CONTACT_TOLERANCE_M: f32 = 0.004;
/// With virtual legs in turn, a stance this many times its expected length has stalled.
const STALLED_STANCE_SHARE: f32 = 3.0;
/// Share of a leg's twist about its own axis (relative to the body) removed each tick. The
/// leg is thin, so its twist inertia is tiny: the damping is scaled to it, or it would
/// overshoot and blow up.
const TWIST_DAMPING_PER_TICK: f32 = 0.5;

/// A push on a rigid creature's body: an impulse (N s) applied over the next tick, then gone.
/// Rapier ignores impulses and velocities set on multibody links, so it goes through the
/// body's force.
#[derive(Component, Clone, Copy, Debug)]
pub struct Shove(pub Vec3);

/// Where the creature is in its step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StancePhase {
    /// Every foot off the ground.
    Flight,
    /// Foot down, leg shortening.
    Compression,
    /// Foot down, leg lengthening: the spring's rest length raised by the thrust.
    Thrust,
}

/// What a leg does this tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    /// On the ground: thrust and attitude.
    Stance,
    /// In flight, about to land: foot placement.
    Landing,
    /// Virtual legs in turn, not this leg's turn: shortened, mirroring the active leg.
    Idle,
}

/// The controller's state for one creature.
#[derive(Component, Clone, Debug)]
pub struct Raibert {
    /// Flight, compression or thrust.
    pub phase: StancePhase,
    /// The virtual leg that touched down last: in stance now, or the last one that was.
    pub stance_group: usize,
    /// Current thrust (extra spring extension).
    pub thrust_m: f32,
    /// Estimated stance duration, for the neutral point.
    pub stance_s: f32,
    /// Simulated seconds of the last touchdown.
    pub last_touchdown_s: f32,
    /// Simulated seconds of the last lift-off.
    pub last_liftoff_s: f32,
    /// Touchdown to touchdown, last measured.
    pub hop_period_s: f32,
    /// Integral correction of the commanded velocity, updated once a step, in the frame of
    /// the command (x along it, y to its left): a neutral-point bias turns with the course.
    pub speed_correction: Vec2,
    /// The velocity the controller aims at: the desired one, approached no faster than the
    /// creature's acceleration limit, so a sudden change of mind does not trip it.
    pub command: Vec2,
    /// When the creature entered the rigid level, and each leg's length then: the idle legs'
    /// servo starts from there (see `Raibert::spring_target`).
    pub entry_s: f32,
    /// Each leg's length when the creature entered the rigid level (see `entry_s`).
    pub entry_lengths_m: [f32; MAX_LEGS],
}

impl Raibert {
    /// A controller taking over a creature moving at `velocity` at `gait`'s point of its step.
    /// Its legs' lengths at entry are, until [`Raibert::entered_in`] says otherwise, where the
    /// controller wants them.
    pub fn resuming(kind: &KindParams, r: &RigidConfig, velocity: Vec2, gait: &GaitPhase, now: f32) -> Self {
        let total = kind
            .legs
            .iter()
            .fold(kind.mass_kg, |m, l| m + l.upper_mass_kg + l.lower_mass_kg);
        let v = &kind.virtual_legs;
        let stiffness = v.legs[0] as f32 * kind.legs[0].spring_n_per_m;
        let mut stance_s = PI * (total / stiffness).sqrt();
        let mut hop_period_s = stance_s + r.controller.flight_time_s;
        // In flight from the hybrid level, as the entry pose is: the table's rhythm, so the
        // legs' servos (idle_leg_swap_s) go on where the table's legs were.
        if kind.gait.is_some() && gait.in_flight && gait.hop_period_s > 0.0 {
            hop_period_s = gait.hop_period_s;
            stance_s = gait.stance_fraction * hop_period_s;
        }
        let last_touchdown_s = now - gait.cycle * hop_period_s;
        let mut controller = Self {
            phase: StancePhase::Flight,
            stance_group: usize::from(gait.step) % v.count,
            thrust_m: r.controller.thrust_initial_m,
            stance_s,
            last_touchdown_s,
            last_liftoff_s: (last_touchdown_s + stance_s).min(now),
            hop_period_s,
            speed_correction: Vec2::ZERO,
            command: velocity,
            entry_s: now,
            entry_lengths_m: [0.0; MAX_LEGS],
        };
        for (i, leg) in kind.legs.iter().enumerate() {
            let role = controller.role(i, v);
            controller.entry_lengths_m[i] = controller.servo_target(leg, r, role, v.together(), now);
        }
        controller
    }

    /// The legs' lengths in the pose the creature entered in.
    pub fn entered_in(&mut self, pose: &GaitPose) {
        for (length, leg) in self.entry_lengths_m.iter_mut().zip(pose.legs()) {
            *length = leg.length_m;
        }
    }

    /// The shared gait phase, as the bodies last touched down and lifted off.
    pub fn gait_phase(&self, now: f32, steps_per_stride: u32) -> GaitPhase {
        let stance = match self.phase {
            StancePhase::Flight => self.last_liftoff_s - self.last_touchdown_s,
            _ => self.stance_s,
        };
        GaitPhase {
            cycle: ((now - self.last_touchdown_s) / self.hop_period_s).clamp(0.0, 0.999),
            in_flight: self.phase == StancePhase::Flight,
            last_touchdown_s: self.last_touchdown_s,
            hop_period_s: self.hop_period_s,
            stance_fraction: (stance / self.hop_period_s).clamp(0.0, 0.999),
            step: if steps_per_stride > 1 {
                self.stance_group as u8
            } else {
                0
            },
        }
    }

    /// The virtual leg that lands next: the one after the last in stance.
    fn landing_group(&self, v: &VirtualLegs) -> usize {
        (self.stance_group + 1) % v.count
    }

    fn role(&self, leg: usize, v: &VirtualLegs) -> Role {
        let group = v.of_leg[leg];
        match self.phase {
            StancePhase::Flight if group == self.landing_group(v) => Role::Landing,
            StancePhase::Compression | StancePhase::Thrust if group == self.stance_group => Role::Stance,
            _ => Role::Idle,
        }
    }
}

/// What the controller senses of one leg this tick.
#[derive(Clone, Copy, Debug, Default)]
struct LegSensed {
    /// The upper leg's spin.
    spin: Vec3,
    /// The hip, from the body's centre, in the world's axes.
    hip: Vec3,
    /// Unit vector from hip to foot.
    axis: Vec3,
    length: f32,
    rate: f32,
    foot_height: f32,
}

/// What the controller senses of its bodies this tick.
struct Sensed {
    body_rotation: Quat,
    body_velocity: Vec3,
    body_spin: Vec3,
    legs: [LegSensed; MAX_LEGS],
}

impl Sensed {
    /// Finite and not absurdly fast: anything else is a blow-up, handled as a fall.
    fn is_sane(&self, legs: usize, blow_up_speed_m_per_s: f32) -> bool {
        let legs_finite = self.legs[..legs]
            .iter()
            .all(|l| l.spin.is_finite() && l.axis.is_finite() && l.rate.is_finite() && l.foot_height.is_finite());
        let finite = self.body_velocity.is_finite()
            && self.body_spin.is_finite()
            && self.body_rotation.is_finite()
            && legs_finite;
        finite && self.body_velocity.length() < blow_up_speed_m_per_s
    }

    fn read(
        bodies: &RigidBodies,
        hips: &[Vec3],
        parts: &Query<(&mut Transform, &mut Velocity, &mut ExternalForce), With<RigidPart>>,
    ) -> Option<Self> {
        let (body, body_v, _) = parts.get(bodies.body).ok()?;
        let mut legs = [LegSensed::default(); MAX_LEGS];
        for ((sensed, leg), hip) in legs.iter_mut().zip(&bodies.legs).zip(hips) {
            let (_, upper_v, _) = parts.get(leg.upper).ok()?;
            let (foot, foot_v, _) = parts.get(leg.lower).ok()?;
            let hip_offset = body.rotation * *hip;
            let to_foot = foot.translation - (body.translation + hip_offset);
            let length = to_foot.length();
            let axis = to_foot / length.max(1e-6);
            let hip_velocity = body_v.linear + body_v.angular.cross(hip_offset);
            *sensed = LegSensed {
                spin: upper_v.angular,
                hip: hip_offset,
                axis,
                length,
                rate: (foot_v.linear - hip_velocity).dot(axis),
                foot_height: foot.translation.y,
            };
        }
        Some(Self {
            body_rotation: body.rotation,
            body_velocity: body_v.linear,
            body_spin: body_v.angular,
            legs,
        })
    }

    fn on_ground(&self, leg: usize, config: &LegConfig) -> bool {
        self.legs[leg].foot_height <= config.foot_radius_m + FOOT_CONTACT_TOLERANCE_M
    }
}

/// Torques for one tick: on the body and on each upper leg.
struct Torques {
    body: Vec3,
    legs: [Vec3; MAX_LEGS],
}

/// A leg spring's push along the leg (foot away from hip), from its rest length `target`.
fn spring_force(s: &LegSensed, leg: &LegConfig, target: f32) -> f32 {
    leg.spring_n_per_m * (target - s.length) - leg.damping_n_s_per_m * s.rate
}

/// Yaw of a rotation about world up: the angle of its forward (+x) axis from +x toward -z.
fn yaw_of(rotation: Quat) -> f32 {
    let f = rotation * Vec3::X;
    (-f.z).atan2(f.x)
}

fn wrap_angle(a: f32) -> f32 {
    (a + PI).rem_euclid(2.0 * PI) - PI
}

impl Raibert {
    /// Advances the stance/flight state machine on the legs' contacts.
    fn update_phase(&mut self, s: &Sensed, kind: &KindParams, r: &RigidConfig, desired: Vec2, now: f32) {
        let (legs, v) = (kind.legs.len(), &kind.virtual_legs);
        let on_ground = |i: usize| s.on_ground(i, &kind.legs[i]);
        let first = v.first_leg[self.stance_group];
        let stance_leg = &s.legs[first];
        match self.phase {
            StancePhase::Flight => {
                // The virtual leg due to land first; any other that meets the ground instead
                // takes over. With virtual legs in turn, not the one that just lifted off (it
                // is retracting).
                let landing = self.landing_group(v);
                let Some(touched) = (0..v.count)
                    .map(|k| (landing + k) % v.count)
                    .filter(|&g| v.together() || g != self.stance_group)
                    .find(|&g| (0..legs).any(|i| v.of_leg[i] == g && on_ground(i)))
                else {
                    return;
                };
                let flight = now - self.last_liftoff_s;
                let c = &r.controller;
                self.thrust_m =
                    (self.thrust_m + c.thrust_gain_m_per_s * (c.flight_time_s - flight)).clamp(0.0, c.thrust_max_m);
                self.hop_period_s = (now - self.last_touchdown_s).clamp(0.1, 2.0);
                let along = course(desired, s.body_rotation);
                let error = desired - s.body_velocity.xz();
                let local_error = Vec2::new(error.dot(along), error.dot(along.perp()));
                self.speed_correction = (self.speed_correction + local_error * c.speed_integral_gain)
                    .clamp_length_max(c.max_speed_correction_m_per_s);
                self.last_touchdown_s = now;
                self.stance_group = touched;
                self.phase = StancePhase::Compression;
            }
            StancePhase::Compression
                if stance_leg.rate >= 0.0 && stance_leg.length < kind.legs[first].rest_length_m =>
            {
                self.phase = StancePhase::Thrust;
            }
            StancePhase::Compression | StancePhase::Thrust
                if !(0..legs).any(|i| self.role(i, v) == Role::Stance && on_ground(i))
                    // With virtual legs in turn, a stance that stalled (the leg at its thrust
                    // length without lifting off) ends: the leg retracts and the next one lands.
                    || (!v.together() && now - self.last_touchdown_s > STALLED_STANCE_SHARE * self.stance_s) =>
            {
                self.stance_s = 0.5 * self.stance_s + 0.5 * (now - self.last_touchdown_s).clamp(0.05, 0.5);
                self.last_liftoff_s = now;
                self.phase = StancePhase::Flight;
            }
            _ => {}
        }
    }

    /// The spring rest length a leg in `role` aims at `now`. With legs in turn, from a lift-off
    /// the leg that lifted off shortens, and the one that lands next lengthens, over
    /// `idle_leg_swap_s`: Raibert's leg servo in flight.
    fn servo_target(&self, leg: &LegConfig, r: &RigidConfig, role: Role, together: bool, now: f32) -> f32 {
        let c = &r.controller;
        let swapped = share_of_swap(r, now - self.last_liftoff_s);
        let retracted = |share: f32| (leg.rest_length_m - c.idle_leg_retract_m * share).max(leg.min_length_m);
        match role {
            Role::Stance if self.phase == StancePhase::Thrust => leg.rest_length_m + self.thrust_m,
            Role::Stance => leg.rest_length_m,
            Role::Landing if together => leg.rest_length_m,
            Role::Landing => retracted(1.0 - swapped),
            Role::Idle => retracted(swapped),
        }
    }

    /// The servo's target, eased in from each leg's length at entry over `idle_leg_swap_s`
    /// after entering the rigid level: a leg snapped toward a target far from its entry length
    /// pops what is drawn. Quintic: no jump in the target's speed or acceleration.
    fn spring_target(&self, leg: (usize, &LegConfig), r: &RigidConfig, role: Role, together: bool, now: f32) -> f32 {
        let (i, leg) = leg;
        let servo = self.servo_target(leg, r, role, together, now);
        let eased = share_of_swap(r, now - self.entry_s);
        if eased >= 1.0 || role == Role::Stance {
            return servo;
        }
        let ease = eased * eased * eased * (eased * (6.0 * eased - 15.0) + 10.0);
        self.entry_lengths_m[i] + (servo - self.entry_lengths_m[i]) * ease
    }

    fn torques(&self, s: &Sensed, kind: &KindParams, r: &RigidConfig, desired: Vec2, clock: (f32, f32)) -> Torques {
        let (now, dt) = clock;
        let c = &r.controller;
        let vl = &kind.virtual_legs;
        let mut out = Torques {
            body: Vec3::ZERO,
            legs: [Vec3::ZERO; MAX_LEGS],
        };
        // Foot placement: neutral point plus the speed correction.
        let v = s.body_velocity.xz();
        let along = course(desired, s.body_rotation);
        let command = desired + along * self.speed_correction.x + along.perp() * self.speed_correction.y;
        let placement = v * (self.stance_s / 2.0) + (v - command) * c.speed_gain_s;
        // The virtual leg the idle ones mirror: the one in stance, or the one about to land.
        let active_group = match self.phase {
            StancePhase::Flight => self.landing_group(vl),
            _ => self.stance_group,
        };
        let active = vl.first_leg[active_group];
        let stance_legs = vl.legs[self.stance_group] as f32;
        // The landing virtual leg's hip: the mean of its legs' hips.
        let landing = self.landing_group(vl);
        let (hips, landing_legs) = (0..kind.legs.len())
            .filter(|&i| vl.of_leg[i] == landing)
            .fold((Vec2::ZERO, 0.0), |(sum, n), i| (sum + s.legs[i].hip.xz(), n + 1.0));
        let virtual_hip = hips / landing_legs;
        let heading = course(Vec2::ZERO, s.body_rotation);
        let mut stance_body = Vec3::ZERO;
        for (i, (sensed, leg)) in s.legs.iter().zip(&kind.legs).enumerate() {
            let relative_spin = sensed.spin - s.body_spin;
            let twist_inertia = 0.5 * (leg.upper_mass_kg + leg.lower_mass_kg) * leg.radius_m * leg.radius_m;
            let twist = sensed.axis * (relative_spin.dot(sensed.axis) * twist_inertia * TWIST_DAMPING_PER_TICK / dt);
            let swing_to = |aim: Vec3| {
                let swing_rate = relative_spin - sensed.axis * relative_spin.dot(sensed.axis);
                sensed.axis.cross(aim) * c.swing_kp_nm_per_rad - swing_rate * c.swing_kd_nm_s_per_rad - twist
            };
            let tau = match self.role(i, vl) {
                Role::Landing => {
                    let reach = c.max_foot_offset_fraction * sensed.length;
                    // The virtual foot lands at the placement from the body's centre (a lone
                    // hip off to one side lands its foot under the body), and each foot as far
                    // from its own hip as the virtual foot from the virtual hip.
                    let offset = (placement - virtual_hip).clamp_length_max(reach);
                    let down = (sensed.length * sensed.length - offset.length_squared()).sqrt();
                    swing_to(Vec3::new(offset.x, -down, offset.y).normalize_or(Vec3::NEG_Y))
                }
                Role::Idle => {
                    // Mirrors the active leg fore and aft, straight under its own hip sideways
                    // (clear of the active leg).
                    let a = s.legs[active].axis;
                    let along = a.xz().project_onto(heading);
                    swing_to(Vec3::new(-along.x, a.y, -along.y).normalize_or(Vec3::NEG_Y))
                }
                Role::Stance => {
                    // A hip off the body's centre: the leg's thrust there would roll and pitch
                    // the body each step, so the hip cancels that moment about the centre (not
                    // its yaw: a point foot has no grip to twist on).
                    let thrust = spring_force(
                        sensed,
                        leg,
                        self.spring_target((i, leg), r, Role::Stance, vl.together(), now),
                    );
                    let moment = sensed.hip.cross(sensed.axis * thrust) * Vec3::new(1.0, 0.0, 1.0);
                    stance_body += twist + moment;
                    out.legs[i] = -attitude_level(s, c) / stance_legs - twist - moment;
                    continue;
                }
            };
            out.body -= tau;
            out.legs[i] = tau;
        }
        if self.phase != StancePhase::Flight {
            let yaw = yaw_of(s.body_rotation);
            let wanted = if desired.length() > c.turn_min_speed_m_per_s {
                (-desired.y).atan2(desired.x)
            } else {
                yaw
            };
            let yaw_error = wrap_angle(wanted - yaw).clamp(-c.max_yaw_error_rad, c.max_yaw_error_rad);
            let turn = (yaw_error * c.yaw_kp_nm_per_rad - s.body_spin.y * c.yaw_kd_nm_s_per_rad)
                .clamp(-c.yaw_max_torque_nm, c.yaw_max_torque_nm);
            out.body += attitude_level(s, c) + Vec3::Y * turn + stance_body;
        }
        out
    }
}

/// The frame of the integral speed correction: along the command, or the body's heading when
/// it stands still (running in place drifts too).
fn course(desired: Vec2, body_rotation: Quat) -> Vec2 {
    desired
        .try_normalize()
        .unwrap_or_else(|| (body_rotation * Vec3::X).xz().normalize_or(Vec2::X))
}

/// How far the idle legs' servo has gone, `elapsed_s` after it started.
fn share_of_swap(r: &RigidConfig, elapsed_s: f32) -> f32 {
    let swap_s = r.controller.idle_leg_swap_s;
    if swap_s > 0.0 {
        (elapsed_s / swap_s).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// The stance hip torque that holds the body level (pitch and roll).
fn attitude_level(s: &Sensed, c: &crate::config::RaibertConfig) -> Vec3 {
    let up = s.body_rotation * Vec3::Y;
    up.cross(Vec3::Y) * c.attitude_kp_nm_per_rad
        - Vec3::new(s.body_spin.x, 0.0, s.body_spin.z) * c.attitude_kd_nm_s_per_rad
}

pub(super) fn control_legs(
    clock: Res<SimClock>,
    kinds: Res<KindTable>,
    falls: Res<FallQueue>,
    mut commands: Commands,
    mut creatures: Query<
        (
            Entity,
            &Creature,
            &RigidBodies,
            &PlanarState,
            &DesiredVelocity,
            &mut Raibert,
            Option<&Shove>,
        ),
        With<AtRigid>,
    >,
    mut parts: Query<(&mut Transform, &mut Velocity, &mut ExternalForce), With<RigidPart>>,
) {
    let now = clock.seconds() as f32;
    for (entity, creature, bodies, state, desired, mut raibert, shove) in &mut creatures {
        let kind = &kinds[creature.kind];
        let Some(r) = &kind.rigid else { continue };
        let Some(sensed) = Sensed::read(bodies, &kind.hips_m, &parts) else {
            continue;
        };
        if !sensed.is_sane(kind.legs.len(), r.fall.blow_up_speed_m_per_s) {
            // Calm the bodies so the physics step survives until the fall removes them.
            falls.push(creature.serial, entity);
            for part in bodies.parts() {
                if let Ok((mut transform, mut velocity, mut force)) = parts.get_mut(part) {
                    if !transform.is_finite() {
                        *transform =
                            Transform::from_xyz(state.position.x, kind.standing_pose.body_height_m, state.position.y);
                    }
                    *velocity = Velocity::zero();
                    *force = ExternalForce::default();
                }
            }
            continue;
        }
        let step = (desired.0 - raibert.command).clamp_length_max(kind.command_acceleration_m_per_s2 * clock.dt);
        raibert.command += step;
        let command = raibert.command;
        raibert.update_phase(&sensed, kind, r, command, now);
        let torques = raibert.torques(&sensed, kind, r, command, (now, clock.dt));
        let shove_force = shove.map_or(Vec3::ZERO, |s| {
            commands.entity(entity).remove::<Shove>();
            s.0 / clock.dt
        });
        if let Ok((_, _, mut f)) = parts.get_mut(bodies.body) {
            *f = ExternalForce {
                force: shove_force,
                torque: torques.body,
            };
        }
        let v = &kind.virtual_legs;
        for (i, (leg_bodies, leg)) in bodies.legs.iter().zip(&kind.legs).enumerate() {
            let role = raibert.role(i, v);
            let sensed_leg = &sensed.legs[i];
            let target = raibert.spring_target((i, leg), r, role, v.together(), now);
            let push = sensed_leg.axis * spring_force(sensed_leg, leg, target);
            for (part, force, torque) in [
                (leg_bodies.upper, -push, torques.legs[i]),
                (leg_bodies.lower, push, Vec3::ZERO),
            ] {
                if let Ok((_, _, mut f)) = parts.get_mut(part) {
                    *f = ExternalForce { force, torque };
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_follows_the_heading_convention_of_the_plane() {
        // Heading (x, y) on the plane is world (x, z); a yaw of +90 degrees faces world -z.
        assert!((yaw_of(Quat::from_rotation_y(0.5)) - 0.5).abs() < 1e-6);
        let facing_minus_z = Quat::from_rotation_y(PI / 2.0) * Vec3::X;
        assert!((facing_minus_z - Vec3::NEG_Z).length() < 1e-6);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-5);
    }
}
