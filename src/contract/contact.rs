//! Contacts and falls, as every level reports them, and the markers of what a rigid body can
//! touch.

use bevy::prelude::*;
use std::sync::Mutex;

/// What a creature can collide with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Obstacle {
    /// The giant puck.
    Puck = 0,
    /// A wall of the court.
    Wall = 1,
    /// Another creature.
    Creature = 2,
}

impl Obstacle {
    /// Every obstacle, in the summary's order.
    pub const ALL: [Obstacle; 3] = [Obstacle::Puck, Obstacle::Wall, Obstacle::Creature];

    /// The name in summaries.
    pub fn name(self) -> &'static str {
        match self {
            Obstacle::Puck => "puck",
            Obstacle::Wall => "wall",
            Obstacle::Creature => "creature",
        }
    }
}

/// One creature's collisions. A collision is the start of a contact.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct CollisionRecord {
    /// In contact with each [`Obstacle`] at the last check.
    pub touching: [bool; 3],
    /// Collisions with each [`Obstacle`].
    pub count: [u32; 3],
}

impl CollisionRecord {
    /// The paper's outcome measure: did it collide with the puck or a wall?
    pub fn hit_puck_or_wall(&self) -> bool {
        self.count[Obstacle::Puck as usize] + self.count[Obstacle::Wall as usize] > 0
    }

    /// Notes whether the creature touches `obstacle` now; a new contact is a collision.
    pub(crate) fn note(&mut self, obstacle: Obstacle, touching: bool) {
        let i = obstacle as usize;
        if touching && !self.touching[i] {
            self.count[i] += 1;
        }
        self.touching[i] = touching;
    }
}

/// Creatures that fell this tick; filled in parallel, emptied in serial order.
#[derive(Resource, Default)]
pub struct FallQueue(Mutex<Vec<(u32, Entity)>>);

impl FallQueue {
    /// Marks a creature (by serial and entity) as fallen this tick.
    pub fn push(&self, serial: u32, entity: Entity) {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).push((serial, entity));
    }

    /// The creatures that fell (serial and entity), in the order they were pushed; empties it.
    pub fn take(&self) -> Vec<(u32, Entity)> {
        std::mem::take(&mut *self.0.lock().unwrap_or_else(|p| p.into_inner()))
    }
}

/// The giant puck (a rapier body).
#[derive(Component, Debug)]
pub struct Puck;

/// The ground under the court (a fixed rapier collider).
#[derive(Component, Debug)]
pub struct Ground;

/// A wall of the court (a fixed rapier collider).
#[derive(Component, Debug)]
pub struct Wall;
