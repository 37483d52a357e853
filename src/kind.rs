//! Creature kinds: each kind's parameters, worked out once from its creature file and gait
//! table, and the component that says which kind a creature is.

use bevy::prelude::*;
use std::ops::Index;

use crate::config::gait::GaitTable;
use crate::config::{CreatureDef, LegConfig, RigidConfig, SimConfig, SteeringConfig};
use crate::contract::{
    CollisionRecord, DesiredVelocity, GaitPhase, GaitPose, LegPose, Lod, MAX_LEGS, PlanarState, SimEntity,
};

/// A legged creature. Its level of detail is the [`Lod`] component beside it.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
#[require(Lod, PlanarState, GaitPhase, GaitPose, DesiredVelocity, CollisionRecord, SimEntity)]
pub struct Creature {
    /// Index into [`KindTable`] (and [`SimConfig::kinds`]).
    pub kind: usize,
    /// Spawn number, unique over the run: a respawned creature is a new creature.
    pub serial: u32,
}

/// Per-kind constants, derived once from the creature files.
#[derive(Clone, Debug)]
pub struct KindParams {
    /// The footprint's radius: the collision circle below the rigid level.
    pub radius_m: f32,
    /// What the camera rule tests against the view: the height of a sphere's centre and its
    /// radius, holding the body and legs from the ground to a body's radius above the hips.
    pub view_sphere_m: (f32, f32),
    /// The whole creature's mass.
    pub mass_kg: f32,
    /// The point mass's limits: the gait table's measured ones when there is a table.
    pub top_speed_m_per_s: f32,
    /// The point mass's acceleration limit (see `top_speed_m_per_s`).
    pub acceleration_limit_m_per_s2: f32,
    /// How fast the rigid model's command follows the desired velocity.
    pub command_acceleration_m_per_s2: f32,
    /// How fast the body turns to face its course.
    pub turn_rate_rad_per_s: f32,
    /// Standing pose: the point-mass level holds it (the legs straight down).
    pub standing_pose: GaitPose,
    /// Where each leg's hip sits on the body (x forward, y up, z to the right).
    pub hips_m: Vec<Vec3>,
    /// Each leg's parts, spring and foot, in the kind's order.
    pub legs: Vec<LegConfig>,
    /// The legs grouped into virtual legs, in the order they take stance.
    pub virtual_legs: VirtualLegs,
    /// Hop cycles per second.
    pub cycles_per_s: f32,
    /// Part of the cycle before lift-off.
    pub stance_fraction: f32,
    /// Below the rigid level, an impact with a greater normal speed is a fall.
    pub fall_impact_speed_m_per_s: f32,
    /// Share of the approaching speed kept when a point mass bounces off something.
    pub collision_restitution: f32,
    /// How this kind steers: wandering, fleeing the puck, avoiding walls and others.
    pub steering: SteeringConfig,
    /// The rigid model and its controller, if the kind has the rigid level.
    pub rigid: Option<RigidConfig>,
    /// The gait table, if the kind has the hybrid level.
    pub gait: Option<GaitTable>,
    /// The levels this kind has a model for, cheapest first.
    pub levels: Vec<Lod>,
}

impl KindParams {
    /// Steps in a stride: one stance of each virtual leg.
    pub fn steps_per_stride(&self) -> u32 {
        self.virtual_legs.count as u32
    }

    /// The most detailed level this kind has a model for, at or below `wanted`.
    pub fn best_level(&self, wanted: Lod) -> Lod {
        self.levels
            .iter()
            .copied()
            .filter(|&l| l <= wanted)
            .max()
            .unwrap_or(Lod::PointMass)
    }

    /// A kind's constants from its file and its gait table (whose limits the point mass takes).
    pub fn new(d: &CreatureDef, gait: Option<&GaitTable>) -> Self {
        let hips_m: Vec<Vec3> = d.legs.iter().map(|l| Vec3::from(l.hip_m)).collect();
        let standing: Vec<LegPose> = hips_m
            .iter()
            .map(|hip| LegPose::straight(d.body.hip_height_m + hip.y))
            .collect();
        let half_height = (d.body.hip_height_m + d.body.radius_m) / 2.0;
        let top_speed_m_per_s = gait.map_or(d.top_speed_m_per_s, |g| g.top_speed_m_per_s);
        Self {
            radius_m: d.body.radius_m,
            view_sphere_m: (half_height, half_height.hypot(d.body.radius_m)),
            mass_kg: d.body.mass_kg,
            top_speed_m_per_s,
            acceleration_limit_m_per_s2: gait.map_or(d.acceleration_limit_m_per_s2, |g| g.acceleration_limit_m_per_s2),
            command_acceleration_m_per_s2: d.acceleration_limit_m_per_s2,
            turn_rate_rad_per_s: d.turn_rate_deg_per_s.to_radians(),
            standing_pose: GaitPose::new(d.body.hip_height_m, 0.0, 0.0, &standing),
            hips_m,
            legs: d.legs.clone(),
            virtual_legs: VirtualLegs::new(&d.stance.groups(d.legs.len())),
            cycles_per_s: 1.0 / d.hop_period_s,
            stance_fraction: 1.0 - d.flight_fraction,
            fall_impact_speed_m_per_s: d.fall_impact_speed_m_per_s,
            collision_restitution: d.collision_restitution,
            steering: d.steering.clone(),
            rigid: d.rigid.clone(),
            gait: gait.cloned(),
            levels: Lod::ALL
                .into_iter()
                .filter(|l| match l {
                    Lod::PointMass => true,
                    Lod::Hybrid => gait.is_some(),
                    Lod::Rigid => d.rigid.is_some(),
                })
                .collect(),
        }
    }
}

/// A kind's legs grouped into virtual legs (its file's `stance`), kept in fixed arrays: the
/// controller looks them up each tick without allocating.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VirtualLegs {
    /// How many virtual legs: the steps in a stride.
    pub count: usize,
    /// Each leg's virtual leg.
    pub of_leg: [usize; MAX_LEGS],
    /// Each virtual leg's first leg: its compression ends the virtual leg's, and the legs that
    /// swing mirror it.
    pub first_leg: [usize; MAX_LEGS],
    /// How many legs each virtual leg has.
    pub legs: [usize; MAX_LEGS],
}

impl VirtualLegs {
    /// From a validated grouping: every leg in exactly one group.
    pub fn new(groups: &[Vec<usize>]) -> Self {
        let mut v = Self {
            count: groups.len(),
            of_leg: [0; MAX_LEGS],
            first_leg: [0; MAX_LEGS],
            legs: [0; MAX_LEGS],
        };
        for (g, group) in groups.iter().enumerate().take(MAX_LEGS) {
            v.first_leg[g] = group.first().copied().unwrap_or(0);
            v.legs[g] = group.len();
            for &leg in group.iter().filter(|&&l| l < MAX_LEGS) {
                v.of_leg[leg] = g;
            }
        }
        v
    }

    /// One virtual leg of every leg: they all hop together.
    pub fn together(&self) -> bool {
        self.count == 1
    }
}

/// The creature kinds of this run, indexed by [`Creature::kind`].
#[derive(Resource, Clone, Debug)]
pub struct KindTable(pub Vec<KindParams>);

impl KindTable {
    /// The kinds of a run's config.
    pub fn of(config: &SimConfig) -> Self {
        Self(
            config
                .kinds
                .iter()
                .zip(&config.gaits)
                .map(|(d, g)| KindParams::new(d, g.as_ref()))
                .collect(),
        )
    }
}

impl Index<usize> for KindTable {
    type Output = KindParams;
    fn index(&self, kind: usize) -> &KindParams {
        &self.0[kind]
    }
}

/// The rhythm and pose a standing creature starts in at `level`, `cycle` into its hop: what
/// its level shows from the first frame (a hybrid's are its table's).
pub fn starting_gait(level: Lod, params: &KindParams, cycle: f32, now_s: f32) -> (GaitPhase, GaitPose) {
    let (hop_period_s, stance_fraction, pose) = match (level, &params.gait) {
        (Lod::Hybrid, Some(table)) => {
            let (period, stance) = table.rhythm(0.0);
            (
                period,
                stance,
                table.pose(0.0, cycle / params.steps_per_stride() as f32),
            )
        }
        _ => (1.0 / params.cycles_per_s, params.stance_fraction, params.standing_pose),
    };
    (GaitPhase::at(cycle, hop_period_s, stance_fraction, now_s), pose)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hop_run_and_trot_are_groupings_of_legs_into_virtual_legs() {
        use crate::config::Stance;
        let hop = VirtualLegs::new(&Stance::Together.groups(2));
        assert!(hop.together());
        assert_eq!((hop.of_leg, hop.legs[0]), ([0; MAX_LEGS], 2));
        let run = VirtualLegs::new(&Stance::Alternating.groups(2));
        assert_eq!((run.count, run.of_leg[1], run.first_leg[1]), (2, 1, 1));
        let trot = VirtualLegs::new(&Stance::VirtualLegs(vec![vec![0, 3], vec![1, 2]]).groups(4));
        assert_eq!((trot.count, trot.of_leg, trot.first_leg[1]), (2, [0, 1, 1, 0], 1));
        assert_eq!(trot.legs[..2], [2, 2]);
    }
}
