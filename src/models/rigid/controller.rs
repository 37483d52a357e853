//! Raibert's hopping controller (Legged Robots That Balance, 1986; paper section 3.1), in
//! three decoupled parts:
//! - hop height: the leg spring's rest length is raised by a thrust during the second half of
//!   stance; the thrust is adjusted once a hop toward the configured flight time;
//! - body attitude: in stance, a hip torque between body and leg holds the body level, and a
//!   yaw torque turns it toward its heading (through the foot's grip: rapier's point contact
//!   has no torsional friction, so that torque acts on the body alone, capped by the grip);
//! - speed: in flight the hip swings the leg so that the foot lands at the neutral point, half
//!   the distance the body travels in stance, plus a correction proportional to the velocity
//!   error.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use std::f32::consts::PI;

use super::RigidHopper;
use crate::SimClock;
use crate::config::RigidConfig;
use crate::creature::{Creature, DesiredVelocity, GaitPhase, KindTable, PlanarState};
use crate::outcome::FallQueue;

/// Foot centre this far above its resting height still counts as on the ground.
pub(super) const FOOT_CONTACT_TOLERANCE_M: f32 = 0.004;
/// Share of the leg's twist about its own axis (relative to the body) removed each tick. The
/// leg is thin, so its twist inertia is tiny: the damping is scaled to it, or it would
/// overshoot and blow up.
const TWIST_DAMPING_PER_TICK: f32 = 0.5;

/// A push on a rigid creature's body: an impulse (N s) applied over the next tick, then gone.
/// Rapier ignores impulses and velocities set on multibody links, so it goes through the
/// body's force.
#[derive(Component, Clone, Copy, Debug)]
pub struct Shove(pub Vec3);

/// Where the hopper is in its hop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StancePhase {
    Flight,
    /// Foot down, leg shortening.
    Compression,
    /// Foot down, leg lengthening: the spring's rest length raised by the thrust.
    Thrust,
}

/// The controller's state for one hopper.
#[derive(Component, Clone, Debug)]
pub struct Raibert {
    pub phase: StancePhase,
    /// Current thrust (extra spring extension).
    pub thrust_m: f32,
    /// Estimated stance duration, for the neutral point.
    pub stance_s: f32,
    pub last_touchdown_s: f32,
    pub last_liftoff_s: f32,
    /// Touchdown to touchdown, last measured.
    pub hop_period_s: f32,
    /// Integral correction of the commanded velocity, updated once a hop, in the frame of the
    /// command (x along it, y to its left): a neutral-point bias turns with the course.
    pub speed_correction: Vec2,
    /// The velocity the controller aims at: the desired one, approached no faster than the
    /// creature's acceleration limit, so a sudden change of mind does not trip it.
    pub command: Vec2,
}

impl Raibert {
    pub fn new(r: &RigidConfig, mass_kg: f32, velocity: Vec2, now: f32) -> Self {
        let total = mass_kg + r.upper_leg_mass_kg + r.lower_leg_mass_kg;
        let stance_s = PI * (total / r.leg_spring_n_per_m).sqrt();
        Self {
            phase: StancePhase::Flight,
            thrust_m: r.controller.thrust_initial_m,
            stance_s,
            last_touchdown_s: now,
            last_liftoff_s: now,
            hop_period_s: stance_s + r.controller.flight_time_s,
            speed_correction: Vec2::ZERO,
            command: velocity,
        }
    }

    /// The shared gait phase, as the bodies last touched down and lifted off.
    pub fn gait_phase(&self, now: f32) -> GaitPhase {
        GaitPhase {
            cycle: ((now - self.last_touchdown_s) / self.hop_period_s).clamp(0.0, 0.999),
            in_flight: self.phase == StancePhase::Flight,
            last_touchdown_s: self.last_touchdown_s,
            hop_period_s: self.hop_period_s,
        }
    }
}

/// What the controller senses of its bodies this tick.
struct Sensed {
    body_rotation: Quat,
    body_velocity: Vec3,
    body_spin: Vec3,
    leg_spin: Vec3,
    /// Unit vector from hip to foot.
    leg_axis: Vec3,
    leg_length: f32,
    leg_rate: f32,
    foot_height: f32,
}

impl Sensed {
    /// Finite and not absurdly fast: anything else is a blow-up, handled as a fall.
    fn is_sane(&self, blow_up_speed_m_per_s: f32) -> bool {
        let finite = self.body_velocity.is_finite()
            && self.body_spin.is_finite()
            && self.leg_spin.is_finite()
            && self.leg_axis.is_finite()
            && self.leg_rate.is_finite()
            && self.foot_height.is_finite()
            && self.body_rotation.is_finite();
        finite && self.body_velocity.length() < blow_up_speed_m_per_s
    }

    fn read(hopper: &RigidHopper, parts: &Query<(&mut Transform, &mut Velocity, &mut ExternalForce)>) -> Option<Self> {
        let (body, body_v, _) = parts.get(hopper.body).ok()?;
        let (_, leg_v, _) = parts.get(hopper.upper_leg).ok()?;
        let (foot, foot_v, _) = parts.get(hopper.lower_leg).ok()?;
        let to_foot = foot.translation - body.translation;
        let leg_length = to_foot.length();
        let leg_axis = to_foot / leg_length.max(1e-6);
        Some(Self {
            body_rotation: body.rotation,
            body_velocity: body_v.linear,
            body_spin: body_v.angular,
            leg_spin: leg_v.angular,
            leg_axis,
            leg_length,
            leg_rate: (foot_v.linear - body_v.linear).dot(leg_axis),
            foot_height: foot.translation.y,
        })
    }
}

/// Torques for one tick: on the body and on the upper leg.
struct Torques {
    body: Vec3,
    leg: Vec3,
}

/// The leg spring's push along the leg (foot away from hip), from its rest length `target`.
fn spring_force(s: &Sensed, r: &RigidConfig, target: f32) -> f32 {
    r.leg_spring_n_per_m * (target - s.leg_length) - r.leg_damping_n_s_per_m * s.leg_rate
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
    /// Advances the stance/flight state machine; returns the spring rest length to aim at.
    fn update_phase(&mut self, s: &Sensed, r: &RigidConfig, desired: Vec2, now: f32) -> f32 {
        let on_ground = s.foot_height <= r.foot_radius_m + FOOT_CONTACT_TOLERANCE_M;
        match self.phase {
            StancePhase::Flight if on_ground => {
                let flight = now - self.last_liftoff_s;
                let c = &r.controller;
                self.thrust_m =
                    (self.thrust_m + c.thrust_gain_m_per_s * (c.flight_time_s - flight)).clamp(0.0, c.thrust_max_m);
                self.hop_period_s = (now - self.last_touchdown_s).clamp(0.1, 2.0);
                if let Some(along) = desired.try_normalize() {
                    let error = desired - s.body_velocity.xz();
                    let local_error = Vec2::new(error.dot(along), error.dot(along.perp()));
                    self.speed_correction = (self.speed_correction + local_error * c.speed_integral_gain)
                        .clamp_length_max(c.max_speed_correction_m_per_s);
                }
                self.last_touchdown_s = now;
                self.phase = StancePhase::Compression;
            }
            StancePhase::Compression if s.leg_rate >= 0.0 && s.leg_length < r.leg_rest_length_m => {
                self.phase = StancePhase::Thrust;
            }
            StancePhase::Compression | StancePhase::Thrust if !on_ground => {
                self.stance_s = 0.5 * self.stance_s + 0.5 * (now - self.last_touchdown_s).clamp(0.05, 0.5);
                self.last_liftoff_s = now;
                self.phase = StancePhase::Flight;
            }
            _ => {}
        }
        match self.phase {
            StancePhase::Thrust => r.leg_rest_length_m + self.thrust_m,
            _ => r.leg_rest_length_m,
        }
    }

    fn torques(&self, s: &Sensed, r: &RigidConfig, desired: Vec2, dt: f32) -> Torques {
        let c = &r.controller;
        let relative_spin = s.leg_spin - s.body_spin;
        let twist_inertia = 0.5 * (r.upper_leg_mass_kg + r.lower_leg_mass_kg) * r.leg_radius_m * r.leg_radius_m;
        let twist = s.leg_axis * (relative_spin.dot(s.leg_axis) * twist_inertia * TWIST_DAMPING_PER_TICK / dt);
        match self.phase {
            StancePhase::Flight => {
                // Foot placement: neutral point plus the speed correction.
                let v = s.body_velocity.xz();
                let reach = c.max_foot_offset_fraction * s.leg_length;
                let command = desired.try_normalize().map_or(desired, |along| {
                    desired + along * self.speed_correction.x + along.perp() * self.speed_correction.y
                });
                let offset = (v * (self.stance_s / 2.0) + (v - command) * c.speed_gain_s).clamp_length_max(reach);
                let down = (s.leg_length * s.leg_length - offset.length_squared()).sqrt();
                let aim = Vec3::new(offset.x, -down, offset.y).normalize_or(Vec3::NEG_Y);
                let swing_rate = relative_spin - s.leg_axis * relative_spin.dot(s.leg_axis);
                let tau = s.leg_axis.cross(aim) * c.swing_kp_nm_per_rad - swing_rate * c.swing_kd_nm_s_per_rad - twist;
                Torques { body: -tau, leg: tau }
            }
            StancePhase::Compression | StancePhase::Thrust => {
                let up = s.body_rotation * Vec3::Y;
                let level = up.cross(Vec3::Y) * c.attitude_kp_nm_per_rad
                    - Vec3::new(s.body_spin.x, 0.0, s.body_spin.z) * c.attitude_kd_nm_s_per_rad;
                let yaw = yaw_of(s.body_rotation);
                let wanted = if desired.length() > c.turn_min_speed_m_per_s {
                    (-desired.y).atan2(desired.x)
                } else {
                    yaw
                };
                let yaw_error = wrap_angle(wanted - yaw).clamp(-c.max_yaw_error_rad, c.max_yaw_error_rad);
                let turn = (yaw_error * c.yaw_kp_nm_per_rad - s.body_spin.y * c.yaw_kd_nm_s_per_rad)
                    .clamp(-c.yaw_max_torque_nm, c.yaw_max_torque_nm);
                Torques {
                    body: level + Vec3::Y * turn + twist,
                    leg: -level - twist,
                }
            }
        }
    }
}

pub(super) fn control_hoppers(
    clock: Res<SimClock>,
    kinds: Res<KindTable>,
    falls: Res<FallQueue>,
    mut commands: Commands,
    mut hoppers: Query<(
        Entity,
        &Creature,
        &RigidHopper,
        &PlanarState,
        &DesiredVelocity,
        &mut Raibert,
        Option<&Shove>,
    )>,
    mut parts: Query<(&mut Transform, &mut Velocity, &mut ExternalForce)>,
) {
    let now = clock.seconds() as f32;
    for (entity, creature, hopper, state, desired, mut raibert, shove) in &mut hoppers {
        let Some(r) = &kinds[creature.kind].rigid else { continue };
        let Some(sensed) = Sensed::read(hopper, &parts) else {
            continue;
        };
        if !sensed.is_sane(r.fall.blow_up_speed_m_per_s) {
            // Calm the bodies so the physics step survives until the fall removes them.
            falls.push(creature.serial, entity);
            for part in hopper.parts() {
                if let Ok((mut transform, mut velocity, mut force)) = parts.get_mut(part) {
                    if !transform.is_finite() {
                        *transform = Transform::from_xyz(state.position.x, r.leg_rest_length_m, state.position.y);
                    }
                    *velocity = Velocity::zero();
                    *force = ExternalForce::default();
                }
            }
            continue;
        }
        let kind = &kinds[creature.kind];
        let step = (desired.0 - raibert.command).clamp_length_max(kind.command_acceleration_m_per_s2 * clock.dt);
        raibert.command += step;
        let command = raibert.command;
        let target = raibert.update_phase(&sensed, r, command, now);
        let push = sensed.leg_axis * spring_force(&sensed, r, target);
        let torques = raibert.torques(&sensed, r, command, clock.dt);
        let shove_force = shove.map_or(Vec3::ZERO, |s| {
            commands.entity(entity).remove::<Shove>();
            s.0 / clock.dt
        });
        let actuation = [
            (hopper.body, shove_force, torques.body),
            (hopper.upper_leg, -push, torques.leg),
            (hopper.lower_leg, push, Vec3::ZERO),
        ];
        for (part, force, torque) in actuation {
            if let Ok((_, _, mut f)) = parts.get_mut(part) {
                *f = ExternalForce { force, torque };
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
