//! The player: one creature steered from the keyboard, rounds, game over and restart.
//!
//! The player's creature is an ordinary creature marked [`PlayerControlled`]: steering
//! leaves it alone and the game writes its desired velocity in the Steer stage. When it
//! falls, the core removes it (and respawns an ordinary creature): the round is over.

use bevy::prelude::*;

use simlod::config::SimConfig;
use simlod::creature::{Creature, DesiredVelocity, KindTable, PlayerControlled};
use simlod::outcome::CollisionRecord;
use simlod::{SimClock, SimStage, start_over};

/// The config each new round starts from: the files' last good values, with the player's
/// live tuning (the level policy, the radii of influence).
#[derive(Resource, Clone, Debug, Deref, DerefMut)]
pub struct BaseConfig(pub SimConfig);

/// Ask for a new round: the world starts over from [`BaseConfig`].
#[derive(Message, Clone, Copy, Debug)]
pub struct NewRound;

/// How the player did in a round.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Score {
    /// Simulated seconds the player's creature has stayed up this round.
    pub survived_s: f64,
    /// The player's creature's collisions with the puck, walls and creatures.
    pub collisions: u32,
}

/// The round being played.
#[derive(Resource, Debug, Default)]
pub struct Round {
    /// Rounds started so far; round `n` is played with the scenario's seed plus `n`.
    pub number: u64,
    /// The player's creature, once chosen (the first creature of the first kind).
    pub player: Option<Entity>,
    /// The player's score so far, or its final score once the round is over.
    pub score: Option<Score>,
    /// Whether the round is over: the player's creature fell.
    pub over: bool,
    /// The longest time survived in any round of this session (a new round keeps it).
    pub best_survived_s: f64,
}

/// The planar direction the player asks for (length 0 to 1), in world coordinates.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq)]
pub struct PlayerIntent(pub Vec2);

/// Takes the first creature of the scenario's first kind once a round's world is built.
fn choose_player(mut commands: Commands, mut round: ResMut<Round>, creatures: Query<(Entity, &Creature)>) {
    if round.player.is_some() || round.over {
        return;
    }
    let Some((entity, _)) = creatures.iter().min_by_key(|(_, c)| (c.kind, c.serial)) else {
        return;
    };
    commands.entity(entity).insert(PlayerControlled);
    round.player = Some(entity);
}

/// The player's creature goes where the player asks, at its top speed.
fn steer_player(
    intent: Res<PlayerIntent>,
    kinds: Res<KindTable>,
    mut players: Query<(&Creature, &mut DesiredVelocity), With<PlayerControlled>>,
) {
    for (creature, mut desired) in &mut players {
        desired.0 = intent.0.clamp_length_max(1.0) * kinds[creature.kind].top_speed_m_per_s;
    }
}

/// Keeps the score each tick, after collisions are noted and before the fallen are
/// removed: the collision that knocks the player down counts.
fn keep_score(
    clock: Res<SimClock>,
    mut round: ResMut<Round>,
    players: Query<&CollisionRecord, With<PlayerControlled>>,
) {
    if round.over {
        return;
    }
    if let Some(record) = round.player.and_then(|p| players.get(p).ok()) {
        round.score = Some(Score {
            survived_s: clock.seconds(),
            collisions: record.count.iter().sum(),
        });
        round.best_survived_s = round.best_survived_s.max(clock.seconds());
    }
}

/// The round is over when the player's creature is gone: it fell and the core removed it.
fn notice_fall(mut round: ResMut<Round>, players: Query<(), With<PlayerControlled>>) {
    if let Some(player) = round.player
        && !round.over
        && players.get(player).is_err()
    {
        round.over = true;
    }
}

/// Starts the world over for each [`NewRound`].
fn start_rounds(
    mut commands: Commands,
    mut asked: MessageReader<NewRound>,
    base: Res<BaseConfig>,
    mut round: ResMut<Round>,
) {
    if asked.read().count() == 0 {
        return;
    }
    round.number += 1;
    round.player = None;
    round.score = None;
    round.over = false;
    let mut config = base.0.clone();
    config.scenario.seed = config.scenario.seed.wrapping_add(round.number);
    commands.queue(move |world: &mut World| start_over(world, config));
}

/// The player's creature and its rounds: everything of the game that needs no window.
/// Add after [`simlod::SimPlugin`]: the first round is the world it built.
pub fn plugin(app: &mut App) {
    let schedule = SimClock::schedule_of(app);
    let base = BaseConfig(app.world().resource::<SimConfig>().clone());
    app.insert_resource(base)
        .add_message::<NewRound>()
        .init_resource::<Round>()
        .init_resource::<PlayerIntent>()
        .add_systems(schedule, steer_player.in_set(SimStage::Steer))
        .add_systems(schedule, keep_score.after(SimStage::Observe).before(SimStage::Outcome))
        .add_systems(Update, (start_rounds, choose_player, notice_fall).chain());
}
