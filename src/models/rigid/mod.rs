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
use crate::creature::{Creature, GaitPhase, KindParams, KindTable, PlanarState};
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
        .limits([r.leg_min_length_m - rest, leg_length_range_m(r).1 - rest])
        .build();
    joint.set_contacts_enabled(false);
    joint
}

/// The leg's shortest and longest length: its stops, a little past the longest thrust.
fn leg_length_range_m(r: &RigidConfig) -> (f32, f32) {
    (
        r.leg_min_length_m,
        r.leg_rest_length_m + r.controller.thrust_max_m + LEG_STOP_BEYOND_THRUST_M,
    )
}

/// How far past the longest thrust the leg's stop is, so the thrust never rides on it.
const LEG_STOP_BEYOND_THRUST_M: f32 = 0.02;

/// The physics components every part shares.
fn part(creature: Entity, transform: Transform) -> impl Bundle {
    (
        RigidPart { creature },
        RigidBody::Dynamic,
        transform,
        Velocity::zero(),
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
    /// The leg's rotation from hanging straight down, in the body's frame (scaled axis).
    pub hip_rotation: Vec3,
    /// The leg's length past its rest length (the prismatic joint's coordinate).
    pub leg_extension_m: f32,
    pub velocity: Vec3,
}

/// Builds the bodies of a creature at the rigid level in `pose`, facing its heading at its
/// planar position, the hip at the pose's body height.
pub fn spawn_hopper(
    commands: &mut Commands,
    creature: Entity,
    r: &RigidConfig,
    mass_kg: f32,
    state: &PlanarState,
    pose: &GaitPose,
) -> RigidHopper {
    let body_rotation = pose.body_rotation(state.heading);
    let leg_rotation = body_rotation * pose.hip_rotation();
    let hip = Vec3::new(state.position.x, pose.body_height_m, state.position.y);
    let foot = hip + leg_rotation * Vec3::NEG_Y * pose.leg_length_m;
    let (hx, hy, hz) = r.body_half_extents_m;
    let body = commands
        .spawn((
            Name::new("hopper body"),
            part(creature, Transform::from_translation(hip).with_rotation(body_rotation)),
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
            part(creature, Transform::from_translation(hip).with_rotation(leg_rotation)),
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
            part(creature, Transform::from_translation(foot).with_rotation(leg_rotation)),
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

/// The pose a creature enters the rigid level in (paper 3.4: the motion continues): in
/// flight, the gait table's for its speed and hop phase where its kind has one; else (no
/// table, or on the ground: a new creature, or a switch forced by a collision) upright at the
/// height its level last had; the hip raised if need be so the foot starts clear of the
/// ground. Also the body's vertical velocity, from the table's change of height over the hop.
fn entry_pose(
    kind: &KindParams,
    r: &RigidConfig,
    state: &PlanarState,
    gait: &GaitPhase,
    last: &GaitPose,
) -> (GaitPose, RigidStart) {
    let speed = state.velocity.length();
    let (mut pose, climb) = match &kind.gait {
        // In flight, as a switch in the flight window is; the controller starts in flight.
        Some(table) if gait.in_flight => {
            let (period, _) = table.rhythm(speed);
            let step = 1.0 / (table.sample_hz * period);
            let (now, next) = (table.pose(speed, gait.cycle), table.pose(speed, gait.cycle + step));
            (now, (next.body_height_m - now.body_height_m) * table.sample_hz)
        }
        // Else the body where the lower level had it, the leg hanging at rest.
        _ => (
            GaitPose {
                body_height_m: last.body_height_m,
                leg_length_m: r.leg_rest_length_m,
                ..default()
            },
            0.0,
        ),
    };
    let (shortest, longest) = leg_length_range_m(r);
    pose.leg_length_m = pose.leg_length_m.clamp(shortest, longest);
    let foot_drop = -(pose.body_rotation(state.heading) * pose.leg_direction()).y * pose.leg_length_m;
    pose.body_height_m = pose
        .body_height_m
        .max(foot_drop + r.foot_radius_m + FOOT_START_CLEARANCE_M);
    let start = RigidStart {
        hip_rotation: pose.hip_rotation().to_scaled_axis(),
        leg_extension_m: pose.leg_length_m - r.leg_rest_length_m,
        velocity: Vec3::new(state.velocity.x, climb, state.velocity.y),
    };
    (pose, start)
}

/// Gap left under the foot of a hopper that starts with its foot below the ground.
const FOOT_START_CLEARANCE_M: f32 = 0.005;

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
        let (pose, start) = entry_pose(kind, r, state, gait, pose);
        let hopper = spawn_hopper(&mut commands, entity, r, kind.mass_kg, state, &pose);
        // The hop resumes where it was.
        let mut raibert = Raibert::new(r, kind.mass_kg, state.velocity, now);
        raibert.last_touchdown_s = now - gait.cycle * raibert.hop_period_s;
        raibert.last_liftoff_s = (raibert.last_touchdown_s + raibert.stance_s).min(now);
        commands.entity(entity).insert((hopper, raibert, start));
    }
}

/// Puts a new multibody in its entry pose and sets it moving: the hip and leg joints to the
/// pose's angles and length, the free root's velocity (which carries the whole tree) to the
/// body's.
fn start_multibodies(
    mut commands: Commands,
    mut context: Query<(&mut RapierContextJoints, &mut RapierRigidBodySet)>,
    new: Query<(Entity, &RigidStart, &RigidHopper)>,
    handles: Query<&RapierMultibodyJointHandle>,
) {
    let Ok((mut joints, mut bodies)) = context.single_mut() else {
        return;
    };
    for (creature, start, hopper) in &new {
        commands.entity(creature).remove::<RigidStart>();
        let Ok(handle) = handles.get(hopper.upper_leg) else {
            continue;
        };
        let Some((multibody, _)) = joints.multibody_joints.get_mut(handle.0) else {
            continue;
        };
        for link in multibody.links_mut() {
            match link.joint.ndofs() {
                3 => link.joint.apply_displacement(&start.hip_rotation.to_array()),
                1 => link.joint.apply_displacement(&[start.leg_extension_m]),
                _ => {}
            }
        }
        // The root's pose is read from its body, where it was spawned.
        multibody.forward_kinematics(&bodies.bodies, true);
        multibody.update_rigid_bodies(&mut bodies.bodies, true);
        let mut velocity = multibody.generalized_velocity_mut();
        for (i, v) in start.velocity.to_array().into_iter().enumerate() {
            velocity[i] = v;
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
            // The controller sees a touchdown next tick; the bodies show it now.
            gait.in_flight &= foot.translation.y > r.foot_radius_m + controller::FOOT_CONTACT_TOLERANCE_M;
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
            start_multibodies
                .after(PhysicsSet::SyncBackend)
                .before(PhysicsSet::StepSimulation),
        )
        .add_systems(FixedUpdate, observe_hoppers.in_set(SimStage::Observe));
}
