//! The rigid-body level (paper section 3.1, figure 2): the one-legged hopper as three rapier
//! bodies on a multibody (reduced-coordinate) joint tree, driven by Raibert's controller.
//!
//! Body on a three-axis hip (spherical joint) to the upper leg; the lower leg telescopes on a
//! springy prismatic joint and ends in a ball foot that meets the ground through rapier
//! contact. The creature entity keeps the state every level shares ([`PlanarState`],
//! [`GaitPhase`]); its bodies are separate entities listed in [`RigidHopper`], removed with it.

mod controller;

pub use controller::{Raibert, Shove, StancePhase};

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;

use crate::arena::{Ground, Puck, Wall};
use crate::config::RigidConfig;
use crate::creature::{Creature, GaitPhase, KindTable, PlanarState};
use crate::gait::GaitPose;
use crate::lod::Lod;
use crate::outcome::{CollisionRecord, FallQueue, Obstacle};
use crate::{SimClock, SimStage};

/// The rapier bodies of a rigid creature.
#[derive(Component, Clone, Copy, Debug)]
pub struct RigidHopper {
    pub body: Entity,
    pub upper_leg: Entity,
    pub lower_leg: Entity,
}

impl RigidHopper {
    pub fn parts(&self) -> [Entity; 3] {
        [self.body, self.upper_leg, self.lower_leg]
    }
}

/// A rapier body that belongs to a creature.
#[derive(Component, Clone, Copy, Debug)]
pub struct RigidPart {
    pub creature: Entity,
}

/// The telescoping leg: a prismatic joint with stops; its spring is a force the controller
/// applies (rapier 0.35.0's force-based motors blow up on multibody links). Rapier builds a
/// multibody from joint coordinates, not from where the bodies stand, so the joint's zero is
/// put at the leg's rest length: coordinate = length - rest length.
fn leg_joint(r: &RigidConfig) -> PrismaticJoint {
    let rest = r.leg_rest_length_m;
    let mut joint = PrismaticJointBuilder::new(Vec3::NEG_Y)
        .local_anchor1(Vec3::ZERO)
        .local_anchor2(Vec3::Y * rest)
        .limits([r.leg_min_length_m - rest, r.controller.thrust_max_m + 0.02])
        .build();
    joint.set_contacts_enabled(false);
    joint
}

/// The physics components every part shares.
fn part(creature: Entity, transform: Transform, velocity: Vec3) -> impl Bundle {
    (
        RigidPart { creature },
        RigidBody::Dynamic,
        transform,
        Velocity::linear(velocity),
        ExternalForce::default(),
        Sleeping::disabled(),
        ActiveEvents::COLLISION_EVENTS,
        CollidingEntities::default(),
    )
}

/// Builds the bodies of a creature at the rigid level: the hip at `hip_height_m` above its
/// planar position, the leg hanging straight down at rest length, facing its heading.
pub fn spawn_hopper(
    commands: &mut Commands,
    creature: Entity,
    r: &RigidConfig,
    mass_kg: f32,
    state: &PlanarState,
    hip_height_m: f32,
) -> RigidHopper {
    let yaw = Quat::from_rotation_y(-state.heading.y.atan2(state.heading.x));
    let hip = Vec3::new(state.position.x, hip_height_m, state.position.y);
    let velocity = Vec3::new(state.velocity.x, 0.0, state.velocity.y);
    let (hx, hy, hz) = r.body_half_extents_m;
    let body = commands
        .spawn((
            Name::new("hopper body"),
            part(creature, Transform::from_translation(hip).with_rotation(yaw), velocity),
            Collider::cuboid(hx, hy, hz),
            ColliderMassProperties::Mass(mass_kg),
        ))
        .id();
    let upper_len = r.upper_leg_length_m;
    let mut hip_joint = SphericalJointBuilder::new()
        .local_anchor1(Vec3::ZERO)
        .local_anchor2(Vec3::ZERO)
        .build();
    hip_joint.set_contacts_enabled(false);
    let upper_leg = commands
        .spawn((
            Name::new("hopper upper leg"),
            part(creature, Transform::from_translation(hip).with_rotation(yaw), velocity),
            Collider::compound(vec![(
                Vec3::new(0.0, -upper_len / 2.0, 0.0),
                Quat::IDENTITY,
                Collider::capsule_y(upper_len / 2.0 - r.leg_radius_m, r.leg_radius_m),
            )]),
            ColliderMassProperties::Mass(r.upper_leg_mass_kg),
            MultibodyJoint::new(body, hip_joint.into()),
        ))
        .id();
    let shank = r.lower_leg_length_m - r.foot_radius_m;
    let lower_leg = commands
        .spawn((
            Name::new("hopper lower leg"),
            part(
                creature,
                Transform::from_translation(hip - Vec3::Y * r.leg_rest_length_m).with_rotation(yaw),
                velocity,
            ),
            Collider::compound(vec![
                (Vec3::ZERO, Quat::IDENTITY, Collider::ball(r.foot_radius_m)),
                (
                    Vec3::new(0.0, r.foot_radius_m + shank / 2.0, 0.0),
                    Quat::IDENTITY,
                    Collider::capsule_y((shank / 2.0 - r.leg_radius_m * 0.8).max(0.01), r.leg_radius_m * 0.8),
                ),
            ]),
            ColliderMassProperties::Mass(r.lower_leg_mass_kg),
            Friction {
                coefficient: r.foot_friction,
                combine_rule: CoefficientCombineRule::Max,
            },
            MultibodyJoint::new(upper_leg, leg_joint(r).into()),
        ))
        .id();
    RigidHopper {
        body,
        upper_leg,
        lower_leg,
    }
}

/// The body and leg pose of a rigid hopper, in the frame of its heading.
pub fn rigid_pose(body: &Transform, foot: &Transform) -> GaitPose {
    let (_, pitch, roll) = body.rotation.to_euler(EulerRot::YZX);
    let to_foot = foot.translation - body.translation;
    let leg = body.rotation.inverse() * to_foot;
    GaitPose {
        body_height_m: body.translation.y,
        roll_rad: roll,
        pitch_rad: pitch,
        leg_length_m: to_foot.length(),
        leg_forward_rad: leg.x.atan2(-leg.y),
        leg_sideways_rad: (-leg.z).atan2(-leg.y),
    }
}

/// Gives every rigid creature without bodies its bodies and a fresh controller.
fn build_bodies(
    mut commands: Commands,
    kinds: Res<KindTable>,
    clock: Res<SimClock>,
    creatures: Query<
        (Entity, &Creature, &Lod, &PlanarState, &GaitPhase, &GaitPose),
        (Without<RigidHopper>, Changed<Lod>),
    >,
) {
    let now = clock.seconds() as f32;
    for (entity, creature, lod, state, gait, pose) in &creatures {
        let kind = &kinds[creature.kind];
        let (Lod::Rigid, Some(r)) = (lod, &kind.rigid) else {
            continue;
        };
        // The body at the height the lower level had it, the leg hanging at rest length
        // clear of the ground; the hop resumes where it was.
        let hip = pose.body_height_m.max(r.leg_rest_length_m + r.foot_radius_m + 0.005);
        let hopper = spawn_hopper(&mut commands, entity, r, kind.mass_kg, state, hip);
        let mut raibert = Raibert::new(r, kind.mass_kg, state.velocity, now);
        raibert.last_touchdown_s = now - gait.cycle * raibert.hop_period_s;
        raibert.last_liftoff_s = (raibert.last_touchdown_s + raibert.stance_s).min(now);
        commands.entity(entity).insert((hopper, raibert));
    }
}

/// Rapier builds a new multibody at rest whatever velocities its bodies were given: set the
/// free root's velocity, which carries the whole tree, from the planar state.
fn carry_velocity_into_bodies(
    mut context: Query<&mut RapierContextJoints>,
    new: Query<(&PlanarState, &RigidHopper), Added<RigidHopper>>,
    handles: Query<&RapierMultibodyJointHandle>,
) {
    let Ok(mut joints) = context.single_mut() else { return };
    for (state, hopper) in &new {
        let Ok(handle) = handles.get(hopper.upper_leg) else {
            continue;
        };
        if let Some((multibody, _)) = joints.multibody_joints.get_mut(handle.0) {
            let mut velocity = multibody.generalized_velocity_mut();
            velocity[0] = state.velocity.x;
            velocity[2] = state.velocity.y;
        }
    }
}

/// Removes a creature's bodies with it, whether it is despawned or changes level.
fn remove_bodies(remove: On<Remove, RigidHopper>, hoppers: Query<&RigidHopper>, mut commands: Commands) {
    if let Ok(hopper) = hoppers.get(remove.entity) {
        for part in hopper.parts().into_iter().rev() {
            if let Ok(mut e) = commands.get_entity(part) {
                e.despawn();
            }
        }
    }
}

/// Reads the shared state back from the bodies, notes collisions and detects falls.
fn observe_hoppers(
    clock: Res<SimClock>,
    kinds: Res<KindTable>,
    falls: Res<FallQueue>,
    mut creatures: Query<(
        Entity,
        &Creature,
        &RigidHopper,
        &Raibert,
        &mut PlanarState,
        &mut GaitPhase,
        &mut GaitPose,
        &mut CollisionRecord,
    )>,
    parts: Query<(&Transform, &Velocity, &CollidingEntities)>,
    obstacles: Query<(Has<Puck>, Has<Wall>, Has<Ground>, Option<&RigidPart>)>,
) {
    let now = clock.seconds() as f32;
    for (entity, creature, hopper, raibert, mut state, mut gait, mut pose, mut record) in &mut creatures {
        let Some(r) = &kinds[creature.kind].rigid else { continue };
        let Ok((body, body_velocity, _)) = parts.get(hopper.body) else {
            continue;
        };
        let forward = body.rotation * Vec3::X;
        state.position = body.translation.xz();
        state.velocity = body_velocity.linear.xz();
        state.heading = forward.xz().try_normalize().unwrap_or(state.heading);
        *gait = raibert.gait_phase(now);
        if let Ok((foot, _, _)) = parts.get(hopper.lower_leg) {
            *pose = rigid_pose(body, foot);
        }

        let mut touching = [false; 3];
        let mut body_on_ground = false;
        for (i, part) in hopper.parts().into_iter().enumerate() {
            let Ok((_, _, colliding)) = parts.get(part) else {
                continue;
            };
            for other in colliding.iter() {
                let Ok((puck, wall, ground, other_part)) = obstacles.get(other) else {
                    continue;
                };
                touching[Obstacle::Puck as usize] |= puck;
                touching[Obstacle::Wall as usize] |= wall;
                touching[Obstacle::Creature as usize] |= other_part.is_some_and(|p| p.creature != entity);
                body_on_ground |= ground && i == 0;
            }
        }
        for o in Obstacle::ALL {
            record.note(o, touching[o as usize]);
        }
        let up = body.rotation * Vec3::Y;
        let tilted = up.y < r.fall.max_tilt_deg.to_radians().cos();
        let low = body.translation.y < r.fall.body_min_height_m;
        let broken = !(body.translation.is_finite() && body_velocity.linear.is_finite());
        if tilted || low || body_on_ground || broken {
            falls.push(creature.serial, entity);
        }
    }
}

pub(super) fn plugin(app: &mut App) {
    app.add_observer(remove_bodies)
        .add_systems(
            FixedUpdate,
            (build_bodies, controller::control_hoppers)
                .chain()
                .in_set(SimStage::Step),
        )
        .add_systems(
            FixedUpdate,
            carry_velocity_into_bodies
                .after(PhysicsSet::SyncBackend)
                .before(PhysicsSet::StepSimulation),
        )
        .add_systems(FixedUpdate, observe_hoppers.in_set(SimStage::Observe));
}
