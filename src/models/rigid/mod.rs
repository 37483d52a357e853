//! The rigid-body level (paper section 3.1, figure 2): a body box on the kind's legs, as
//! rapier bodies on one multibody (reduced-coordinate) joint tree, driven by Raibert's
//! controller.
//!
//! Each leg: an upper leg on a three-axis hip (spherical joint) where the leg's hip sits on the
//! body, and a lower leg that telescopes on a springy prismatic joint and ends in a ball foot
//! that meets the ground through rapier contact. The creature entity keeps the state every
//! level shares ([`PlanarState`], [`GaitPhase`], [`GaitPose`]); its bodies are separate
//! entities listed in [`RigidBodies`]. The level is entered and left through its marker
//! [`AtRigid`]: adding it builds the bodies and the controller, removing it (a switch down,
//! or the creature's removal) takes them away.

mod controller;

pub use controller::{Raibert, Shove, StancePhase};

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;

use crate::config::{LegConfig, RigidConfig, RigidJoints};
use crate::contract::AtRigid;
use crate::contract::MAX_LEGS;
use crate::contract::{CollisionRecord, FallQueue, Obstacle};
use crate::contract::{GaitPhase, PlanarState};
use crate::contract::{GaitPose, LegPose};
use crate::contract::{Ground, Puck, Wall};
use crate::contract::{SimClock, SimStage};
use crate::kind::{Creature, KindParams, KindTable};

/// The rapier bodies of one leg.
#[derive(Clone, Copy, Debug)]
pub struct LegBodies {
    /// The upper leg, on the three-axis hip.
    pub upper: Entity,
    /// The telescoping lower leg, its ball foot at its end.
    pub lower: Entity,
}

/// The rapier bodies of a rigid creature: its body, then its legs in the kind's order.
#[derive(Component, Clone, Debug)]
pub struct RigidBodies {
    /// The body box.
    pub body: Entity,
    /// Each leg's bodies, in the kind's order.
    pub legs: Vec<LegBodies>,
}

impl RigidBodies {
    /// Every part, the body first.
    pub fn parts(&self) -> impl DoubleEndedIterator<Item = Entity> + '_ {
        std::iter::once(self.body).chain(self.legs.iter().flat_map(|l| [l.upper, l.lower]))
    }
}

/// A rapier body that belongs to a creature.
#[derive(Component, Clone, Copy, Debug)]
pub struct RigidPart {
    /// The creature it belongs to.
    pub creature: Entity,
}

/// The telescoping leg: a prismatic joint with stops; its spring is a force the controller
/// applies (rapier 0.35.0's force-based motors blow up on multibody links). Rapier builds a
/// multibody from joint coordinates, not from where the bodies stand, so the joint's zero is
/// put at the leg's rest length: coordinate = length - rest length.
fn leg_joint(leg: &LegConfig, r: &RigidConfig) -> PrismaticJoint {
    let rest = leg.rest_length_m;
    let mut joint = PrismaticJointBuilder::new(Vec3::NEG_Y)
        .local_anchor1(Vec3::ZERO)
        .local_anchor2(Vec3::Y * rest)
        .limits([leg.min_length_m - rest, leg_length_range_m(leg, r).1 - rest])
        .build();
    joint.set_contacts_enabled(false);
    joint
}

/// A leg's shortest and longest length: its stops, a little past the longest thrust.
fn leg_length_range_m(leg: &LegConfig, r: &RigidConfig) -> (f32, f32) {
    (
        leg.min_length_m,
        leg.rest_length_m + r.controller.thrust_max_m + LEG_STOP_BEYOND_THRUST_M,
    )
}

/// How far past the longest thrust the leg's stop is, so the thrust never rides on it.
const LEG_STOP_BEYOND_THRUST_M: f32 = 0.02;

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

/// How a new multibody starts: the pose to set its joints to and its body's velocity. Rapier
/// builds a multibody at rest with its joints at zero whatever the bodies were spawned with,
/// so both are applied to its coordinates once it exists, then this is removed.
#[derive(Component, Clone, Copy, Debug)]
pub struct RigidStart {
    /// Each leg's rotation from hanging straight down, in the body's frame (scaled axis).
    pub hip_rotations: [Vec3; MAX_LEGS],
    /// Each leg's length past its rest length (its prismatic joint's coordinate).
    pub leg_extensions_m: [f32; MAX_LEGS],
    /// The body's velocity at entry, m/s.
    pub velocity: Vec3,
}

/// Spawns a part joined to `parent` as the kind's rigid section says: on one multibody tree,
/// or by an impulse joint. The joint comes in the part's one bundle, as the multibody always
/// did: the multibody's rounding depends on how components arrive (a creature's inserts split
/// in two changed the shipped gait tables).
fn spawn_joined(
    commands: &mut Commands,
    joints: RigidJoints,
    part: impl Bundle,
    parent: Entity,
    joint: TypedJoint,
) -> Entity {
    match joints {
        RigidJoints::Multibody => commands.spawn((part, MultibodyJoint::new(parent, joint))).id(),
        RigidJoints::Impulse => commands.spawn((part, ImpulseJoint::new(parent, joint))).id(),
    }
}

/// Builds the bodies of a creature at the rigid level in `pose`, facing its heading at its
/// planar position, the body's centre at the pose's body height. Free bodies (impulse joints)
/// start at `velocity`; a multibody starts at rest and is set moving by [`RigidStart`].
pub fn spawn_bodies(
    commands: &mut Commands,
    creature: Entity,
    kind: &KindParams,
    r: &RigidConfig,
    state: &PlanarState,
    pose: &GaitPose,
    velocity: Vec3,
) -> RigidBodies {
    let velocity = match r.joints {
        RigidJoints::Multibody => Vec3::ZERO,
        RigidJoints::Impulse => velocity,
    };
    let body_rotation = pose.body_rotation(state.heading);
    let centre = Vec3::new(state.position.x, pose.body_height_m, state.position.y);
    let (hx, hy, hz) = r.body_half_extents_m;
    let body = commands
        .spawn((
            Name::new("creature body"),
            part(
                creature,
                Transform::from_translation(centre).with_rotation(body_rotation),
                velocity,
            ),
            Collider::cuboid(hx, hy, hz),
            ColliderMassProperties::Mass(kind.mass_kg),
        ))
        .id();
    let legs = kind
        .legs
        .iter()
        .zip(&kind.hips_m)
        .zip(pose.legs())
        .map(|((leg, &hip_at), leg_pose)| {
            let leg_rotation = body_rotation * leg_pose.hip_rotation();
            let hip = centre + body_rotation * hip_at;
            let foot = hip + leg_rotation * Vec3::NEG_Y * leg_pose.length_m;
            let mut hip_joint = SphericalJointBuilder::new()
                .local_anchor1(hip_at)
                .local_anchor2(Vec3::ZERO)
                .build();
            hip_joint.set_contacts_enabled(false);
            let upper_len = leg.upper_length_m;
            let upper = spawn_joined(
                commands,
                r.joints,
                (
                    Name::new("creature upper leg"),
                    part(
                        creature,
                        Transform::from_translation(hip).with_rotation(leg_rotation),
                        velocity,
                    ),
                    Collider::compound(vec![(
                        Vec3::new(0.0, -upper_len / 2.0, 0.0),
                        Quat::IDENTITY,
                        Collider::capsule_y(upper_len / 2.0 - leg.radius_m, leg.radius_m),
                    )]),
                    ColliderMassProperties::Mass(leg.upper_mass_kg),
                ),
                body,
                hip_joint.into(),
            );
            let shank = leg.lower_length_m - leg.foot_radius_m;
            let lower = spawn_joined(
                commands,
                r.joints,
                (
                    Name::new("creature lower leg"),
                    part(
                        creature,
                        Transform::from_translation(foot).with_rotation(leg_rotation),
                        velocity,
                    ),
                    Collider::compound(vec![
                        (Vec3::ZERO, Quat::IDENTITY, Collider::ball(leg.foot_radius_m)),
                        (
                            Vec3::new(0.0, leg.foot_radius_m + shank / 2.0, 0.0),
                            Quat::IDENTITY,
                            Collider::capsule_y((shank / 2.0 - leg.radius_m * 0.8).max(0.01), leg.radius_m * 0.8),
                        ),
                    ]),
                    ColliderMassProperties::Mass(leg.lower_mass_kg),
                    Friction {
                        coefficient: leg.foot_friction,
                        combine_rule: CoefficientCombineRule::Max,
                    },
                ),
                upper,
                leg_joint(leg, r).into(),
            );
            LegBodies { upper, lower }
        })
        .collect();
    RigidBodies { body, legs }
}

/// The pose of a rigid creature's bodies, in the frame of its heading.
fn pose_of(
    bodies: &RigidBodies,
    hips: &[Vec3],
    parts: &Query<(&Transform, &Velocity, &CollidingEntities)>,
) -> Option<GaitPose> {
    let (body, _, _) = parts.get(bodies.body).ok()?;
    let mut feet = [Vec3::ZERO; MAX_LEGS];
    for (foot, leg) in feet.iter_mut().zip(&bodies.legs) {
        *foot = parts.get(leg.lower).ok()?.0.translation;
    }
    Some(GaitPose::of_bodies(body, hips, feet))
}

/// The pose a creature enters the rigid level in (paper 3.4: the motion continues): in
/// flight, the gait table's for its speed and stride phase where its kind has one; else (no
/// table, or on the ground: a new creature, or a switch forced by a collision) upright at the
/// height its level last had, each leg straight down at the length the controller wants it
/// (`lengths_m`: with legs in turn, the idle one already shortened); the body raised if need be
/// so every foot starts clear of the ground. Also the body's vertical velocity, from the table's change
/// of height over the stride.
fn entry_pose(
    kind: &KindParams,
    r: &RigidConfig,
    state: &PlanarState,
    gait: &GaitPhase,
    last: &GaitPose,
    lengths_m: &[f32; MAX_LEGS],
) -> (GaitPose, RigidStart) {
    let speed = state.velocity.length();
    let (mut pose, climb) = match &kind.gait {
        // In flight, as a switch in the flight window is; the controller starts in flight.
        Some(table) if gait.in_flight => {
            let (period, _) = table.rhythm(speed);
            let steps = kind.steps_per_stride() as f32;
            let stride = gait.stride(kind.steps_per_stride());
            let sample = 1.0 / (table.sample_hz * period * steps);
            let (now, next) = (table.pose(speed, stride), table.pose(speed, stride + sample));
            (now, (next.body_height_m - now.body_height_m) * table.sample_hz)
        }
        // Else the body where the lower level had it, the legs hanging straight.
        _ => {
            let legs: Vec<LegPose> = lengths_m[..kind.legs.len()]
                .iter()
                .map(|l| LegPose::straight(*l))
                .collect();
            (GaitPose::new(last.body_height_m, 0.0, 0.0, &legs), 0.0)
        }
    };
    let rotation = pose.body_rotation(state.heading);
    let mut lowest_foot: f32 = 0.0;
    for ((leg_pose, leg), hip) in pose.legs_mut().iter_mut().zip(&kind.legs).zip(&kind.hips_m) {
        let (shortest, longest) = leg_length_range_m(leg, r);
        leg_pose.length_m = leg_pose.length_m.clamp(shortest, longest);
        let foot_drop = -(rotation * (*hip + leg_pose.direction() * leg_pose.length_m)).y;
        lowest_foot = lowest_foot.max(foot_drop + leg.foot_radius_m + FOOT_START_CLEARANCE_M);
    }
    pose.body_height_m = pose.body_height_m.max(lowest_foot);
    let mut start = RigidStart {
        hip_rotations: [Vec3::ZERO; MAX_LEGS],
        leg_extensions_m: [0.0; MAX_LEGS],
        velocity: Vec3::new(state.velocity.x, climb, state.velocity.y),
    };
    for (i, (leg_pose, leg)) in pose.legs().iter().zip(&kind.legs).enumerate() {
        start.hip_rotations[i] = leg_pose.hip_rotation().to_scaled_axis();
        start.leg_extensions_m[i] = leg_pose.length_m - leg.rest_length_m;
    }
    (pose, start)
}

/// Gap left under a foot of a creature that starts with its foot below the ground.
const FOOT_START_CLEARANCE_M: f32 = 0.005;

/// Entering the rigid level: the bodies, in the entry pose, and a controller that resumes the
/// gait where it was.
fn enter_rigid(
    add: On<Add, AtRigid>,
    mut commands: Commands,
    kinds: Res<KindTable>,
    clock: Res<SimClock>,
    creatures: Query<(&Creature, &PlanarState, &GaitPhase, &GaitPose)>,
) {
    let entity = add.entity;
    let Ok((creature, state, gait, last)) = creatures.get(entity) else {
        return;
    };
    let kind = &kinds[creature.kind];
    let Some(r) = &kind.rigid else { return };
    let mut controller = Raibert::resuming(kind, r, state.velocity, gait, clock.seconds() as f32);
    let (pose, start) = entry_pose(kind, r, state, gait, last, &controller.entry_lengths_m);
    controller.entered_in(&pose);
    let bodies = spawn_bodies(&mut commands, entity, kind, r, state, &pose, start.velocity);
    // Free bodies start moving as spawned; a multibody is set moving by `start_multibodies`.
    let mut creature = commands.entity(entity);
    match r.joints {
        RigidJoints::Multibody => creature.insert((bodies, controller, start, pose)),
        RigidJoints::Impulse => creature.insert((bodies, controller, pose)),
    };
}

/// Leaving the rigid level, or the world: the bodies and the controller go.
fn leave_rigid(remove: On<Remove, AtRigid>, creatures: Query<&RigidBodies>, mut commands: Commands) {
    let Ok(bodies) = creatures.get(remove.entity) else {
        return;
    };
    for part in bodies.parts().rev() {
        if let Ok(mut e) = commands.get_entity(part) {
            e.despawn();
        }
    }
    commands
        .entity(remove.entity)
        .try_remove::<(RigidBodies, Raibert, RigidStart)>();
}

/// Puts a new multibody in its entry pose and sets it moving: each hip and leg joint to the
/// pose's angles and length, the free root's velocity (which carries the whole tree) to the
/// body's.
fn start_multibodies(
    mut commands: Commands,
    mut context: Query<(&mut RapierContextJoints, &mut RapierRigidBodySet)>,
    new: Query<(Entity, &RigidStart, &RigidBodies)>,
    handles: Query<&RapierMultibodyJointHandle>,
) {
    let Ok((mut joints, mut bodies)) = context.single_mut() else {
        return;
    };
    for (creature, start, parts) in &new {
        commands.entity(creature).remove::<RigidStart>();
        let mut displace = |part: Entity, displacement: &[f32]| {
            if let Ok(handle) = handles.get(part)
                && let Some((multibody, link)) = joints.multibody_joints.get_mut(handle.0)
                && let Some(link) = multibody.link_mut(link)
            {
                link.joint.apply_displacement(displacement);
            }
        };
        for (i, leg) in parts.legs.iter().enumerate() {
            displace(leg.upper, &start.hip_rotations[i].to_array());
            displace(leg.lower, &[start.leg_extensions_m[i]]);
        }
        let Some((multibody, _)) = parts
            .legs
            .first()
            .and_then(|leg| handles.get(leg.upper).ok())
            .and_then(|handle| joints.multibody_joints.get_mut(handle.0))
        else {
            continue;
        };
        // The root's pose is read from its body, where it was spawned.
        multibody.forward_kinematics(&bodies.bodies, true);
        multibody.update_rigid_bodies(&mut bodies.bodies, true);
        let mut velocity = multibody.generalized_velocity_mut();
        for (i, v) in start.velocity.to_array().into_iter().enumerate() {
            velocity[i] = v;
        }
    }
}

/// Reads the shared state back from the bodies, notes collisions and detects falls.
fn observe_rigid(
    clock: Res<SimClock>,
    kinds: Res<KindTable>,
    falls: Res<FallQueue>,
    mut creatures: Query<
        (
            Entity,
            &Creature,
            &RigidBodies,
            &Raibert,
            &mut PlanarState,
            &mut GaitPhase,
            &mut GaitPose,
            &mut CollisionRecord,
        ),
        With<AtRigid>,
    >,
    parts: Query<(&Transform, &Velocity, &CollidingEntities)>,
    obstacles: Query<(Has<Puck>, Has<Wall>, Has<Ground>, Option<&RigidPart>)>,
) {
    let now = clock.seconds() as f32;
    for (entity, creature, bodies, raibert, mut state, mut gait, mut pose, mut record) in &mut creatures {
        let kind = &kinds[creature.kind];
        let Some(r) = &kind.rigid else { continue };
        let Ok((body, body_velocity, _)) = parts.get(bodies.body) else {
            continue;
        };
        let forward = body.rotation * Vec3::X;
        state.position = body.translation.xz();
        state.velocity = body_velocity.linear.xz();
        state.heading = forward.xz().try_normalize().unwrap_or(state.heading);
        *gait = raibert.gait_phase(now, kind.steps_per_stride());
        if let Some(bodies_pose) = pose_of(bodies, &kind.hips_m, &parts) {
            *pose = bodies_pose;
        }
        // The controller sees a touchdown next tick; the bodies show it now.
        for (leg, config) in bodies.legs.iter().zip(&kind.legs) {
            if let Ok((foot, _, _)) = parts.get(leg.lower) {
                gait.in_flight &= foot.translation.y > config.foot_radius_m + controller::FOOT_CONTACT_TOLERANCE_M;
            }
        }

        let mut touching = [false; 3];
        let mut body_on_ground = false;
        for (i, part) in bodies.parts().enumerate() {
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
    let schedule = SimClock::schedule_of(app);
    app.add_observer(enter_rigid)
        .add_observer(leave_rigid)
        .add_systems(schedule, controller::control_legs.in_set(SimStage::Step))
        .add_systems(
            schedule,
            start_multibodies
                .after(PhysicsSet::SyncBackend)
                .before(PhysicsSet::StepSimulation),
        )
        .add_systems(schedule, observe_rigid.in_set(SimStage::Observe));
}
