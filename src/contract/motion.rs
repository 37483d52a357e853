//! What every level publishes of a creature's motion: its body on the plane and its gait's
//! phase, and the velocity steering asks of it.

use bevy::prelude::*;

/// The body's state on the ground plane, shared by every level (plane x, y = world x, z).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct PlanarState {
    /// Metres, on the ground plane.
    pub position: Vec2,
    /// Metres per second, on the ground plane.
    pub velocity: Vec2,
    /// Direction the body faces: a unit vector (an angle would cost an `atan2` per tick).
    pub heading: Vec2,
}

impl Default for PlanarState {
    fn default() -> Self {
        Self {
            position: Vec2::ZERO,
            velocity: Vec2::ZERO,
            heading: Vec2::X,
        }
    }
}

impl PlanarState {
    /// The heading as an angle, radians from +x towards +y (world +z).
    pub fn heading_angle(&self) -> f32 {
        self.heading.to_angle()
    }
}

/// Where the creature is in its gait, kept at every level so that a level switch can wait for
/// the flight window (paper 3.4): read from the controller at the rigid level, advanced by
/// time at the others. A step runs from one touchdown to the next (a hop of the hopper); a
/// stride is one step of each virtual leg in turn (one step when the legs share the ground together).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct GaitPhase {
    /// Fraction of the step since the last touchdown, in `[0, 1)`.
    pub cycle: f32,
    /// Whether every foot is off the ground (the flight phase: where a switch may happen).
    pub in_flight: bool,
    /// Simulated time of the last touchdown, s.
    pub last_touchdown_s: f32,
    /// Touchdown to touchdown, s.
    pub hop_period_s: f32,
    /// Part of the step on the ground, from touchdown.
    pub stance_fraction: f32,
    /// Which step of the stride this is: the virtual leg that touched down last.
    pub step: u8,
}

impl GaitPhase {
    /// At `cycle` of the first step of a stride, steps of `hop_period_s`, at time `now_s`.
    pub fn at(cycle: f32, hop_period_s: f32, stance_fraction: f32, now_s: f32) -> Self {
        Self {
            cycle,
            in_flight: cycle >= stance_fraction,
            last_touchdown_s: now_s - cycle * hop_period_s,
            hop_period_s,
            stance_fraction,
            step: 0,
        }
    }

    /// The gait `cycles` cycles on at the given rhythm, `end_s` the simulated time it is then:
    /// stance first, then flight; each touchdown starts the next of `steps_per_stride` steps.
    pub fn advanced(
        &self,
        cycles: f32,
        hop_period_s: f32,
        stance_fraction: f32,
        steps_per_stride: u32,
        end_s: f32,
    ) -> Self {
        let cycle = self.cycle + cycles;
        if cycle >= 1.0 {
            let touchdowns = cycle.floor();
            Self {
                step: ((u32::from(self.step) + touchdowns as u32) % steps_per_stride.max(1)) as u8,
                ..Self::at(cycle - touchdowns, hop_period_s, stance_fraction, end_s)
            }
        } else {
            Self {
                cycle,
                in_flight: cycle >= stance_fraction,
                hop_period_s,
                stance_fraction,
                ..*self
            }
        }
    }

    /// How far through the stride (0..1 from the first leg's touchdown): the gait table's phase.
    pub fn stride(&self, steps_per_stride: u32) -> f32 {
        (f32::from(self.step) + self.cycle) / steps_per_stride.max(1) as f32
    }

    /// How far through its flight the creature is (0 lift-off, 1 touchdown), if in flight.
    pub fn flight_progress(&self) -> Option<f32> {
        self.in_flight
            .then(|| ((self.cycle - self.stance_fraction) / (1.0 - self.stance_fraction).max(1e-3)).clamp(0.0, 1.0))
    }
}

/// A creature whose desired velocity comes from outside (the player's keyboard, a test, an
/// experiment): steering leaves it alone.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct PlayerControlled;

/// The planar velocity steering asks for.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct DesiredVelocity(pub Vec2);
