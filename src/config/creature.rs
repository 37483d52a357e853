//! A creature definition: `assets/creatures/<kind>.ron`.

use super::{Validate, Validator};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// One kind of legged creature (the one-legged hopper, the biped, or a modder's own). Each
/// number's comment gives the range it is checked against when loaded.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreatureDef {
    /// The kind's name; must match the file name (`creatures/<name>.ron`).
    pub name: String,
    pub body: BodyConfig,
    /// Planar speed limit. A kind with a gait table moves its point mass (hybrid and point-mass
    /// levels) at the table's measured limits instead (paper 3.2). 0.01 to 50 m/s.
    pub top_speed_m_per_s: f32,
    /// How fast the creature may change its velocity: the rigid model's command follows the
    /// desired velocity at this rate; the point mass uses it when there is no gait table.
    /// 0.01 to 1000 m/s^2.
    pub acceleration_limit_m_per_s2: f32,
    /// How fast the point mass turns its body to face its direction of travel; 1 to 36,000
    /// degrees/s.
    pub turn_rate_deg_per_s: f32,
    /// Touchdown to touchdown; 0.05 to 10 s.
    pub hop_period_s: f32,
    /// Part of the hop cycle spent in the air, after stance; 0.05 to 0.95.
    pub flight_fraction: f32,
    /// At the point-mass level there is no balance to lose: a creature falls when an impact's
    /// normal speed exceeds this. 0.01 to 1000 m/s.
    pub fall_impact_speed_m_per_s: f32,
    /// Share of the normal impact speed kept after a point-mass collision (0 = dead stop); 0
    /// to 1.
    pub collision_restitution: f32,
    pub steering: SteeringConfig,
    /// The rigid-body model (paper 3.1); a kind without one is never simulated rigid.
    #[serde(default)]
    pub rigid: Option<RigidConfig>,
    /// The gait table file (relative to the assets folder and inside it) the hybrid level plays back
    /// (paper 3.2), written by `simlod record-gait`; a kind without one is never hybrid.
    #[serde(default)]
    pub gait_table: Option<String>,
}

/// The rigid-body hopper of the paper's figure 2: a body, an upper leg on a three-axis hip
/// at the body's centre, and a lower leg with a ball foot on a springy prismatic joint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidConfig {
    /// Half extents of the body box: x forward, y up, z to the side. Its mass is `body.mass_kg`.
    pub body_half_extents_m: (f32, f32, f32),
    pub upper_leg_length_m: f32,
    pub upper_leg_mass_kg: f32,
    pub lower_leg_length_m: f32,
    pub lower_leg_mass_kg: f32,
    pub leg_radius_m: f32,
    pub foot_radius_m: f32,
    pub foot_friction: f32,
    /// Hip to foot centre with the spring at rest.
    pub leg_rest_length_m: f32,
    /// Hip to foot centre at the joint's stop.
    pub leg_min_length_m: f32,
    pub leg_spring_n_per_m: f32,
    pub leg_damping_n_s_per_m: f32,
    pub controller: RaibertConfig,
    pub fall: FallConfig,
}

/// Raibert's three decoupled controllers (Legged Robots That Balance, 1986).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RaibertConfig {
    /// Hop height: the flight time the thrust is adjusted to.
    pub flight_time_s: f32,
    /// Extra spring extension during thrust, at the start.
    pub thrust_initial_m: f32,
    pub thrust_max_m: f32,
    /// Thrust change per second of flight-time error, once a hop.
    pub thrust_gain_m_per_s: f32,
    /// Foot placement: neutral point plus this times the velocity error.
    pub speed_gain_s: f32,
    /// Share of each hop's velocity error added to a running correction of the commanded
    /// velocity (integral action: removes the steady error a biased neutral point leaves).
    pub speed_integral_gain: f32,
    /// Largest foot offset from under the hip, as a fraction of the leg length.
    pub max_foot_offset_fraction: f32,
    /// Flight: hip torque swinging the leg to the foot placement angle.
    pub swing_kp_nm_per_rad: f32,
    pub swing_kd_nm_s_per_rad: f32,
    /// Stance: hip torque holding the body level (pitch and roll).
    pub attitude_kp_nm_per_rad: f32,
    pub attitude_kd_nm_s_per_rad: f32,
    /// Stance: torque turning the body to its heading, through the foot's grip.
    pub yaw_kp_nm_per_rad: f32,
    pub yaw_kd_nm_s_per_rad: f32,
    /// Largest yaw torque the foot's grip on the ground can take.
    pub yaw_max_torque_nm: f32,
    /// Largest yaw error acted on at once, so a reversal turns smoothly, not violently.
    pub max_yaw_error_rad: f32,
    /// Below this desired speed the body keeps its heading.
    pub turn_min_speed_m_per_s: f32,
    /// Bound of the integral correction of the commanded velocity.
    pub max_speed_correction_m_per_s: f32,
}

/// When a rigid creature has fallen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FallConfig {
    /// The body's centre below this height.
    pub body_min_height_m: f32,
    /// The body's up axis tilted further than this from vertical.
    pub max_tilt_deg: f32,
    /// Any part faster than this is a numerical blow-up, not motion: handled as a fall.
    pub blow_up_speed_m_per_s: f32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyConfig {
    /// Radius of the creature's footprint on the ground: its collision circle; 0.01 to 10 m.
    pub radius_m: f32,
    /// Height of the hip above the ground while standing; 0.01 to 20 m.
    pub hip_height_m: f32,
    /// 0.01 to 10,000 kg.
    pub mass_kg: f32,
}

/// How the creature picks its desired velocity (paper 3: escape the puck, avoid walls and
/// other creatures). Weights are relative (0 to 1000); the sum is scaled to the top speed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteeringConfig {
    /// Speed of undisturbed wandering; 0 to the top speed.
    pub cruise_speed_m_per_s: f32,
    /// Largest rate at which the wandering heading drifts; 0 to 100 rad/s.
    pub wander_turn_rad_per_s: f32,
    /// The creature flees when this close to the puck's path over the look-ahead; 0 to 10,000 m.
    pub puck_alert_distance_m: f32,
    /// How far ahead the puck's path is predicted; 0 to 60 s.
    pub puck_lookahead_s: f32,
    pub puck_weight: f32,
    /// Walls repel within this distance; 0 to 10,000 m.
    pub wall_avoid_distance_m: f32,
    pub wall_weight: f32,
    /// Other creatures repel within this distance (centre to centre); 0 to 100 m: the
    /// neighbour grid's cells are this big.
    pub separation_distance_m: f32,
    pub separation_weight: f32,
}

impl Validate for CreatureDef {
    fn validate(&self, v: &mut Validator) {
        v.kind_name("name", &self.name);
        v.nested("body", |v| {
            v.range("radius_m", self.body.radius_m, 0.01, 10.0);
            v.range("hip_height_m", self.body.hip_height_m, 0.01, 20.0);
            v.range("mass_kg", self.body.mass_kg, 0.01, 10_000.0);
        });
        v.range("top_speed_m_per_s", self.top_speed_m_per_s, 0.01, 50.0);
        v.range(
            "acceleration_limit_m_per_s2",
            self.acceleration_limit_m_per_s2,
            0.01,
            1000.0,
        );
        v.range("turn_rate_deg_per_s", self.turn_rate_deg_per_s, 1.0, 36_000.0);
        v.range("hop_period_s", self.hop_period_s, 0.05, 10.0);
        v.range("flight_fraction", self.flight_fraction, 0.05, 0.95);
        v.range(
            "fall_impact_speed_m_per_s",
            self.fall_impact_speed_m_per_s,
            0.01,
            1000.0,
        );
        v.range("collision_restitution", self.collision_restitution, 0.0, 1.0);
        if let Some(file) = &self.gait_table {
            v.asset_path("gait_table", file);
        }
        if let Some(r) = &self.rigid {
            v.nested("rigid", |v| r.validate(v));
        }
        let s = &self.steering;
        v.nested("steering", |v| {
            v.range("cruise_speed_m_per_s", s.cruise_speed_m_per_s, 0.0, 50.0);
            v.range("wander_turn_rad_per_s", s.wander_turn_rad_per_s, 0.0, 100.0);
            v.range("puck_alert_distance_m", s.puck_alert_distance_m, 0.0, 10_000.0);
            v.range("puck_lookahead_s", s.puck_lookahead_s, 0.0, 60.0);
            v.range("puck_weight", s.puck_weight, 0.0, 1000.0);
            v.range("wall_avoid_distance_m", s.wall_avoid_distance_m, 0.0, 10_000.0);
            v.range("wall_weight", s.wall_weight, 0.0, 1000.0);
            v.range("separation_distance_m", s.separation_distance_m, 0.0, 100.0);
            v.range("separation_weight", s.separation_weight, 0.0, 1000.0);
            v.require(
                s.cruise_speed_m_per_s.is_nan() || s.cruise_speed_m_per_s <= self.top_speed_m_per_s,
                "cruise_speed_m_per_s",
                format!("must not exceed top_speed_m_per_s ({})", self.top_speed_m_per_s),
            );
        });
    }
}

impl Validate for RigidConfig {
    fn validate(&self, v: &mut Validator) {
        let (x, y, z) = self.body_half_extents_m;
        for (i, e) in [x, y, z].into_iter().enumerate() {
            v.positive(&format!("body_half_extents_m.{i}"), e);
        }
        v.positive("upper_leg_length_m", self.upper_leg_length_m);
        v.positive("upper_leg_mass_kg", self.upper_leg_mass_kg);
        v.positive("lower_leg_length_m", self.lower_leg_length_m);
        v.positive("lower_leg_mass_kg", self.lower_leg_mass_kg);
        v.positive("leg_radius_m", self.leg_radius_m);
        v.positive("foot_radius_m", self.foot_radius_m);
        v.non_negative("foot_friction", self.foot_friction);
        v.positive("leg_rest_length_m", self.leg_rest_length_m);
        v.positive("leg_min_length_m", self.leg_min_length_m);
        v.positive("leg_spring_n_per_m", self.leg_spring_n_per_m);
        v.non_negative("leg_damping_n_s_per_m", self.leg_damping_n_s_per_m);
        v.require(
            self.leg_min_length_m < self.leg_rest_length_m,
            "leg_min_length_m",
            format!("must be below leg_rest_length_m ({})", self.leg_rest_length_m),
        );
        v.require(
            self.upper_leg_length_m > 2.0 * self.leg_radius_m && self.lower_leg_length_m > self.foot_radius_m,
            "upper_leg_length_m",
            "each leg part must be longer than it is thick: upper_leg_length_m above twice leg_radius_m, lower_leg_length_m above foot_radius_m",
        );
        v.require(
            self.lower_leg_length_m + y < self.leg_min_length_m,
            "lower_leg_length_m",
            "the lower leg would reach into the body at the shortest leg: keep lower_leg_length_m + body half height below leg_min_length_m",
        );
        let c = &self.controller;
        v.nested("controller", |v| {
            v.positive("flight_time_s", c.flight_time_s);
            v.non_negative("thrust_initial_m", c.thrust_initial_m);
            v.non_negative("thrust_max_m", c.thrust_max_m);
            v.non_negative("thrust_gain_m_per_s", c.thrust_gain_m_per_s);
            v.non_negative("speed_gain_s", c.speed_gain_s);
            v.within("speed_integral_gain", c.speed_integral_gain, 0.0, 1.0);
            v.within("max_foot_offset_fraction", c.max_foot_offset_fraction, 0.0, 0.9);
            for (name, value) in [
                ("swing_kp_nm_per_rad", c.swing_kp_nm_per_rad),
                ("swing_kd_nm_s_per_rad", c.swing_kd_nm_s_per_rad),
                ("attitude_kp_nm_per_rad", c.attitude_kp_nm_per_rad),
                ("attitude_kd_nm_s_per_rad", c.attitude_kd_nm_s_per_rad),
                ("yaw_kp_nm_per_rad", c.yaw_kp_nm_per_rad),
                ("yaw_kd_nm_s_per_rad", c.yaw_kd_nm_s_per_rad),
                ("yaw_max_torque_nm", c.yaw_max_torque_nm),
                ("turn_min_speed_m_per_s", c.turn_min_speed_m_per_s),
                ("max_speed_correction_m_per_s", c.max_speed_correction_m_per_s),
            ] {
                v.non_negative(name, value);
            }
            v.within("max_yaw_error_rad", c.max_yaw_error_rad, 0.01, std::f32::consts::PI);
            v.require(
                c.thrust_initial_m <= c.thrust_max_m,
                "thrust_initial_m",
                "must not exceed thrust_max_m",
            );
        });
        v.nested("fall", |v| {
            v.positive("body_min_height_m", self.fall.body_min_height_m);
            v.within("max_tilt_deg", self.fall.max_tilt_deg, 1.0, 180.0);
            v.positive("blow_up_speed_m_per_s", self.fall.blow_up_speed_m_per_s);
        });
    }
}
