//! A creature definition: `assets/creatures/<kind>.ron`.

use super::{Validate, Validator, number};
use crate::contract::MAX_LEGS;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// One kind of legged creature (the one-legged hopper, the biped, or a modder's own). Each
/// number's comment gives the range it is checked against when loaded.
#[derive(Asset, TypePath, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreatureDef {
    /// The kind's name; must match the file name (`creatures/<name>.ron`).
    pub name: String,
    /// The body: its footprint, standing height and mass.
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
    /// How it chooses where to go.
    pub steering: SteeringConfig,
    /// The legs (at least one, at most [`MAX_LEGS`]): drawn at every level, simulated at the
    /// rigid one.
    pub legs: Vec<LegConfig>,
    /// How the legs share the ground.
    pub stance: Stance,
    /// The rigid-body model (paper 3.1); a kind without one is never simulated rigid.
    #[serde(default)]
    pub rigid: Option<RigidConfig>,
    /// The gait table file (relative to the assets folder and inside it) the hybrid level plays back
    /// (paper 3.2), written by `simlod record-gait`; a kind without one is never hybrid.
    #[serde(default)]
    pub gait_table: Option<String>,
    /// How the game tells this kind apart from the others (the simulation never reads it).
    #[serde(default)]
    pub look: KindLook,
}

/// A kind's look in the game, within the colouring by level: a crest on the body and its
/// nose in the kind's own colour.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KindLook {
    /// The crest's and the nose's colour, sRGB components from 0 to 1.
    pub marking_srgb: [f32; 3],
}

impl Default for KindLook {
    /// Dark grey, as the legs.
    fn default() -> Self {
        Self {
            marking_srgb: [0.25, 0.25, 0.28],
        }
    }
}

/// One leg, from its hip on the body to its ball foot (paper figure 2): an upper leg on a
/// three-axis hip, and a lower leg that telescopes on a springy prismatic joint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegConfig {
    /// Where the hip sits, from the body's centre: x forward, y up, z to the right; -5 to 5 m.
    pub hip_m: (f32, f32, f32),
    /// Length of the upper leg; 0.02 to 5 m.
    pub upper_length_m: f32,
    /// Mass of the upper leg; 0.01 to 1000 kg.
    pub upper_mass_kg: f32,
    /// Length of the lower leg, foot included; 0.02 to 5 m.
    pub lower_length_m: f32,
    /// Mass of the lower leg; 0.01 to 1000 kg.
    pub lower_mass_kg: f32,
    /// Radius of the leg's parts; 0.002 to 0.5 m.
    pub radius_m: f32,
    /// Radius of the ball foot; 0.005 to 0.5 m.
    pub foot_radius_m: f32,
    /// Friction coefficient of the foot on the ground; 0 to 10.
    pub foot_friction: f32,
    /// Hip to foot centre with the spring at rest; 0.05 to 10 m.
    pub rest_length_m: f32,
    /// Hip to foot centre at the joint's stop; 0.02 to 10 m, below the rest length.
    pub min_length_m: f32,
    /// Stiffness of the leg spring; 1 to 1e6 N/m.
    pub spring_n_per_m: f32,
    /// Damping of the leg spring; 0 to 1e5 N s/m.
    pub damping_n_s_per_m: f32,
}

/// How a kind's legs share the ground: its legs grouped into virtual legs, which take stance in
/// turn (Raibert, Chepponis and Brown, "Running on four legs as though they were one", 1986;
/// Legged Robots That Balance, ch. 6). The legs of a virtual leg touch down and lift off
/// together, and the one-foot controller runs them as one.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Stance {
    /// One virtual leg of every leg: the one-legged hopper, or a kangaroo's two legs hopping.
    #[default]
    Together,
    /// Each leg its own virtual leg, in the file's order: a biped's run ("one-foot" running).
    Alternating,
    /// Virtual legs in the order they take stance, each a list of leg numbers (from 0, in the
    /// file's order); every leg in exactly one. With legs 0-3 front left, front right, back
    /// left, back right: trot `[[0, 3], [1, 2]]`, pace `[[0, 2], [1, 3]]`, bound
    /// `[[0, 1], [2, 3]]`.
    VirtualLegs(Vec<Vec<usize>>),
}

impl Stance {
    /// The virtual legs of a kind with `legs` legs, in the order they take stance.
    pub fn groups(&self, legs: usize) -> Vec<Vec<usize>> {
        match self {
            Stance::Together => vec![(0..legs).collect()],
            Stance::Alternating => (0..legs).map(|i| vec![i]).collect(),
            Stance::VirtualLegs(groups) => groups.clone(),
        }
    }

    /// Steps in one stride: one stance of each virtual leg. The gait table records a whole
    /// stride.
    pub fn steps_per_stride(&self, legs: usize) -> u32 {
        self.groups(legs).len().max(1) as u32
    }

    /// Whether every one of `legs` legs is in exactly one virtual leg.
    fn check(&self, legs: usize, v: &mut Validator) {
        let groups = self.groups(legs);
        let mut seen = vec![0; legs];
        for group in &groups {
            for &leg in group {
                if let Some(n) = seen.get_mut(leg) {
                    *n += 1;
                }
            }
        }
        let out_of_range: Vec<usize> = groups.iter().flatten().copied().filter(|&l| l >= legs).collect();
        v.require(
            out_of_range.is_empty(),
            "stance",
            format!(
                "the legs are numbered 0 to {}, not {out_of_range:?}",
                legs.saturating_sub(1)
            ),
        );
        let missing: Vec<usize> = (0..legs).filter(|&l| seen[l] == 0).collect();
        let twice: Vec<usize> = (0..legs).filter(|&l| seen[l] > 1).collect();
        let wrong: Vec<String> = [(missing, "in none"), (twice, "in more than one")]
            .into_iter()
            .filter(|(legs, _)| !legs.is_empty())
            .map(|(legs, how)| format!("legs {legs:?} {how}"))
            .collect();
        v.require(
            wrong.is_empty(),
            "stance",
            format!("each leg goes in exactly one virtual leg: {}", wrong.join(", ")),
        );
        v.require(
            groups.iter().all(|g| !g.is_empty()),
            "stance",
            "a virtual leg has at least one leg",
        );
    }
}

/// The rigid-body model (paper 3.1): the body box on the kind's legs, its controller and
/// when it has fallen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidConfig {
    /// Half extents of the body box: x forward, y up, z to the side; each 0.01 to 5 m. Its mass
    /// is `body.mass_kg`.
    pub body_half_extents_m: (f32, f32, f32),
    /// Gains and limits: times 0.01 to 5 s, thrusts 0 to 1 m, gains `*_kp_*` 0 to 1e5 and
    /// `*_kd_*` 0 to 1e4, torques 0 to 1e4 N m, speeds 0 to 50 m/s, as each field says.
    pub controller: RaibertConfig,
    /// When it has fallen.
    pub fall: FallConfig,
    /// How rapier joins the bodies: `Impulse` (the default) or `Multibody`.
    #[serde(default)]
    pub joints: RigidJoints,
}

/// How the rigid model's bodies are joined in rapier.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum RigidJoints {
    /// One multibody (reduced-coordinate) joint tree per creature: the joints hold exactly,
    /// but rapier rebuilds the tree's mass matrix at each solver iteration.
    Multibody,
    /// Free bodies held together by impulse joints, solved with the contacts: a fraction of
    /// the multibody's cost; the joints give a little under load, so they want more solver
    /// iterations (the scenario's `solver_iterations`).
    #[default]
    Impulse,
}

/// Raibert's three decoupled controllers (Legged Robots That Balance, 1986).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RaibertConfig {
    /// Hop height: the flight time the thrust is adjusted to.
    pub flight_time_s: f32,
    /// Extra spring extension during thrust, at the start.
    pub thrust_initial_m: f32,
    /// Largest extra spring extension during thrust.
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
    /// Flight: damping of the leg's swing.
    pub swing_kd_nm_s_per_rad: f32,
    /// Stance: hip torque holding the body level (pitch and roll).
    pub attitude_kp_nm_per_rad: f32,
    /// Stance: damping of the body's pitch and roll.
    pub attitude_kd_nm_s_per_rad: f32,
    /// Stance: torque turning the body to its heading, through the foot's grip.
    pub yaw_kp_nm_per_rad: f32,
    /// Stance: damping of the body's turn.
    pub yaw_kd_nm_s_per_rad: f32,
    /// Largest yaw torque the foot's grip on the ground can take.
    pub yaw_max_torque_nm: f32,
    /// Legs in turn: how much an idle leg is shortened below its rest length to clear the
    /// ground while it swings to its next touchdown.
    pub idle_leg_retract_m: f32,
    /// Legs in turn: from a lift-off, the time over which the leg that lifted off shortens by
    /// `idle_leg_retract_m` and the leg that lands next lengthens back to rest (a leg servo,
    /// not a jump: a gait table sampled at 30 Hz can follow it). 0: at once.
    pub idle_leg_swap_s: f32,
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
    /// The body's centre below this height; 0.01 to 10 m.
    pub body_min_height_m: f32,
    /// The body's up axis tilted further than this from vertical.
    pub max_tilt_deg: f32,
    /// Any part faster than this is a numerical blow-up, not motion: handled as a fall; 1 to
    /// 1000 m/s.
    pub blow_up_speed_m_per_s: f32,
}

/// The body every level shares (paper 3.3: the point mass is this body alone).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyConfig {
    /// Radius of the creature's footprint on the ground: its collision circle; 0.01 to 10 m.
    pub radius_m: f32,
    /// Height of the hip above the ground while standing; 0.01 to 20 m.
    pub hip_height_m: f32,
    /// Mass of the body, legs not included; 0.01 to 10,000 kg.
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
    /// Weight of fleeing the puck's path.
    pub puck_weight: f32,
    /// Walls repel within this distance; 0 to 10,000 m.
    pub wall_avoid_distance_m: f32,
    /// Weight of turning away from a wall.
    pub wall_weight: f32,
    /// Other creatures repel within this distance (centre to centre); 0 to 100 m: the
    /// neighbour grid's cells are this big.
    pub separation_distance_m: f32,
    /// Weight of keeping apart from other creatures.
    pub separation_weight: f32,
    /// Steering's level of detail: a creature with nothing within these reaches (the puck's
    /// path, the walls, another creature) looks around once in this many decisions and keeps
    /// its desired velocity between; 1 to 64 (1: at every decision; left out, 1).
    #[serde(default = "every_decision")]
    pub look_every_decisions_when_clear: u32,
}

fn every_decision() -> u32 {
    1
}

impl Validate for CreatureDef {
    fn validate(&self, v: &mut Validator) {
        v.kind_name("name", &self.name);
        v.nested("look", |v| {
            v.nested("marking_srgb", |v| {
                for (i, x) in self.look.marking_srgb.into_iter().enumerate() {
                    v.within(&i.to_string(), x, 0.0, 1.0);
                }
            });
        });
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
        v.require(
            (1..=MAX_LEGS).contains(&self.legs.len()),
            "legs",
            format!("a creature has 1 to {MAX_LEGS} legs, got {}", self.legs.len()),
        );
        for (i, leg) in self.legs.iter().enumerate() {
            v.nested(&format!("legs[{i}]"), |v| leg.validate(v));
        }
        self.validate_relations(v);
        if let Some(r) = &self.rigid {
            v.nested("rigid", |v| r.validate_on(&self.legs, v));
            v.require(
                r.fall.body_min_height_m < self.body.hip_height_m
                    || not_finite(&[r.fall.body_min_height_m, self.body.hip_height_m]),
                "rigid.fall.body_min_height_m",
                format!(
                    "must be below body.hip_height_m ({} m): a creature standing lower than its fall height has fallen",
                    number(self.body.hip_height_m)
                ),
            );
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
                (1..=64).contains(&s.look_every_decisions_when_clear),
                "look_every_decisions_when_clear",
                format!("must be 1 to 64, not {}", s.look_every_decisions_when_clear),
            );
            v.require(
                s.cruise_speed_m_per_s.is_nan() || s.cruise_speed_m_per_s <= self.top_speed_m_per_s,
                "cruise_speed_m_per_s",
                format!("must not exceed top_speed_m_per_s ({})", self.top_speed_m_per_s),
            );
        });
    }
}

impl CreatureDef {
    /// Numbers that are each in range but together describe a creature that cannot exist:
    /// each rule names both fields. A NaN or infinity was reported by its range check.
    fn validate_relations(&self, v: &mut Validator) {
        v.require(
            self.stance != Stance::Alternating || self.legs.len() >= 2,
            "stance",
            format!(
                "Alternating takes turns between legs: it needs at least 2, and legs has {}",
                self.legs.len()
            ),
        );
        self.stance.check(self.legs.len(), v);
        let body = &self.body;
        for (i, leg) in self.legs.iter().enumerate() {
            let reach = leg.upper_length_m + leg.lower_length_m;
            v.require(
                leg.rest_length_m <= reach || not_finite(&[leg.rest_length_m, reach]),
                &format!("legs[{i}].rest_length_m"),
                format!(
                    "{} m is beyond what the leg's parts reach end to end: upper_length_m + lower_length_m = {} m",
                    number(leg.rest_length_m),
                    number(reach)
                ),
            );
            let (x, y, z) = leg.hip_m;
            let hip_height = body.hip_height_m + y;
            v.require(
                (leg.min_length_m..=reach).contains(&hip_height) || not_finite(&[hip_height, reach, leg.min_length_m]),
                "body.hip_height_m",
                format!(
                    "standing at {} m puts leg {i}'s hip {} m above the ground (with legs[{i}].hip_m.1), where the leg cannot stand: it is between legs[{i}].min_length_m ({} m) and its parts end to end ({} m)",
                    number(body.hip_height_m),
                    number(hip_height),
                    number(leg.min_length_m),
                    number(reach)
                ),
            );
            let out = x.hypot(z);
            v.require(
                out <= body.radius_m || not_finite(&[out, body.radius_m]),
                &format!("legs[{i}].hip_m"),
                format!(
                    "the hip is {} m from the body's centre across the ground, outside body.radius_m ({} m)",
                    number(out),
                    number(body.radius_m)
                ),
            );
        }
    }
}

/// A relation between numbers is not checked where one of them is not a number: its own range
/// check has reported it.
fn not_finite(values: &[f32]) -> bool {
    values.iter().any(|x| !x.is_finite())
}

impl Validate for LegConfig {
    fn validate(&self, v: &mut Validator) {
        let (x, y, z) = self.hip_m;
        for (i, e) in [x, y, z].into_iter().enumerate() {
            v.range(&format!("hip_m.{i}"), e, -5.0, 5.0);
        }
        v.range("upper_length_m", self.upper_length_m, 0.02, 5.0);
        v.range("upper_mass_kg", self.upper_mass_kg, 0.01, 1000.0);
        v.range("lower_length_m", self.lower_length_m, 0.02, 5.0);
        v.range("lower_mass_kg", self.lower_mass_kg, 0.01, 1000.0);
        v.range("radius_m", self.radius_m, 0.002, 0.5);
        v.range("foot_radius_m", self.foot_radius_m, 0.005, 0.5);
        v.range("foot_friction", self.foot_friction, 0.0, 10.0);
        v.range("rest_length_m", self.rest_length_m, 0.05, 10.0);
        v.range("min_length_m", self.min_length_m, 0.02, 10.0);
        v.range("spring_n_per_m", self.spring_n_per_m, 1.0, 1e6);
        v.range("damping_n_s_per_m", self.damping_n_s_per_m, 0.0, 1e5);
        v.require(
            self.min_length_m < self.rest_length_m,
            "min_length_m",
            format!("must be below rest_length_m ({})", self.rest_length_m),
        );
        v.require(
            self.upper_length_m > 2.0 * self.radius_m && self.lower_length_m > self.foot_radius_m,
            "upper_length_m",
            "each leg part must be longer than it is thick: upper_length_m above twice radius_m, lower_length_m above foot_radius_m",
        );
    }
}

impl RigidConfig {
    fn validate_on(&self, legs: &[LegConfig], v: &mut Validator) {
        let (x, y, z) = self.body_half_extents_m;
        for (i, e) in [x, y, z].into_iter().enumerate() {
            v.range(&format!("body_half_extents_m.{i}"), e, 0.01, 5.0);
        }
        for (i, leg) in legs.iter().enumerate() {
            let (hx, hy, hz) = leg.hip_m;
            v.require(
                (hx.abs() <= x && hy.abs() <= y && hz.abs() <= z) || not_finite(&[hx, hy, hz, x, y, z]),
                "body_half_extents_m",
                format!(
                    "leg {i}'s hip (legs[{i}].hip_m: {}, {}, {}) is outside the body box it hangs from",
                    number(hx),
                    number(hy),
                    number(hz)
                ),
            );
            v.require(
                leg.lower_length_m + y < leg.min_length_m,
                "body_half_extents_m.1",
                format!(
                    "leg {i}'s lower leg would reach into the body at its shortest: keep its lower_length_m + the body's half height below its min_length_m ({})",
                    leg.min_length_m
                ),
            );
        }
        let c = &self.controller;
        v.nested("controller", |v| {
            v.range("flight_time_s", c.flight_time_s, 0.01, 5.0);
            v.range("thrust_initial_m", c.thrust_initial_m, 0.0, 1.0);
            v.range("thrust_max_m", c.thrust_max_m, 0.0, 1.0);
            v.range("thrust_gain_m_per_s", c.thrust_gain_m_per_s, 0.0, 10.0);
            v.range("speed_gain_s", c.speed_gain_s, 0.0, 1.0);
            v.within("speed_integral_gain", c.speed_integral_gain, 0.0, 1.0);
            v.within("max_foot_offset_fraction", c.max_foot_offset_fraction, 0.0, 0.9);
            for (name, value, most) in [
                ("swing_kp_nm_per_rad", c.swing_kp_nm_per_rad, 1e5),
                ("swing_kd_nm_s_per_rad", c.swing_kd_nm_s_per_rad, 1e4),
                ("attitude_kp_nm_per_rad", c.attitude_kp_nm_per_rad, 1e5),
                ("attitude_kd_nm_s_per_rad", c.attitude_kd_nm_s_per_rad, 1e4),
                ("yaw_kp_nm_per_rad", c.yaw_kp_nm_per_rad, 1e5),
                ("yaw_kd_nm_s_per_rad", c.yaw_kd_nm_s_per_rad, 1e4),
                ("yaw_max_torque_nm", c.yaw_max_torque_nm, 1e4),
                ("turn_min_speed_m_per_s", c.turn_min_speed_m_per_s, 50.0),
                ("max_speed_correction_m_per_s", c.max_speed_correction_m_per_s, 50.0),
                ("idle_leg_retract_m", c.idle_leg_retract_m, 5.0),
                ("idle_leg_swap_s", c.idle_leg_swap_s, 5.0),
            ] {
                v.range(name, value, 0.0, most);
            }
            v.within("max_yaw_error_rad", c.max_yaw_error_rad, 0.01, std::f32::consts::PI);
            v.require(
                c.thrust_initial_m <= c.thrust_max_m,
                "thrust_initial_m",
                "must not exceed thrust_max_m",
            );
        });
        v.nested("fall", |v| {
            v.range("body_min_height_m", self.fall.body_min_height_m, 0.01, 10.0);
            v.within("max_tilt_deg", self.fall.max_tilt_deg, 1.0, 180.0);
            v.range("blow_up_speed_m_per_s", self.fall.blow_up_speed_m_per_s, 1.0, 1000.0);
        });
    }
}
