//! Hot reload: the scenario, arena, rules, creature, gait-table and game files load through
//! Bevy's asset server, which watches them. A good edit of a simulation file starts a new
//! round from the edited files; a good edit of the level rules or of `game.ron` applies at
//! once, in the running round. A bad edit is shown on screen and everything runs on with the
//! last good values. The player's live tuning (level policy, radii of influence, frame budget)
//! survives every reload except, for the radii and the budget, an edit of the rules file itself.

use bevy::asset::{AssetLoadError, AssetLoadFailedEvent, AssetPath, UntypedAssetId};
use bevy::prelude::*;
use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;

use super::player::{BaseConfig, NewRound};
use super::{GAME_FILE, GameSettings};
use simlod::config::{
    ArenaConfig, ConfigError, CostModel, CreatureDef, GameConfig, LevelRules, Scenario, SimConfig, creature_file,
    kind_file, load_costs, resolve_reference,
};
use simlod::gait::GaitTable;

/// The files the game watches, and whether one changed since the config was last put
/// together from them.
#[derive(Resource)]
pub struct Watched {
    /// The scenario, as a path under the assets folder.
    scenario_file: String,
    assets_root: PathBuf,
    scenario: Handle<Scenario>,
    arena: Handle<ArenaConfig>,
    rules: Handle<LevelRules>,
    kinds: HashMap<String, Handle<CreatureDef>>,
    /// Gait tables by file.
    gaits: HashMap<String, Handle<GaitTable>>,
    game: Handle<GameConfig>,
    changed: bool,
    /// The level rules as the files last said: the player's radii and frame budget (the keys,
    /// `--frame-budget`) stand until they change.
    file_rules: Option<LevelRules>,
    /// The cost model measured at start-up: it stands for the session, in place of the file's.
    measured_costs: Option<CostModel>,
}

impl Watched {
    /// Watches the scenario at `scenario_file` (under `assets_root`), whose rules file says
    /// `file_rules` now (before the command line's overrides), and plays by `measured_costs`
    /// where the game measured them at start-up (else by the cost model's file).
    pub fn new(
        scenario_file: String,
        assets_root: PathBuf,
        file_rules: LevelRules,
        measured_costs: Option<CostModel>,
    ) -> Self {
        Self {
            scenario_file,
            assets_root,
            scenario: default(),
            arena: default(),
            rules: default(),
            kinds: default(),
            gaits: default(),
            game: default(),
            changed: false,
            file_rules: Some(file_rules),
            measured_costs,
        }
    }

    /// Whether `id` is one of the files watched here. When a reload fails, the asset
    /// server tries again with whichever loader owns the extension; that second attempt's
    /// failure, under another asset type and id, is not ours to show.
    fn watches(&self, id: UntypedAssetId) -> bool {
        id == self.scenario.id().untyped()
            || id == self.arena.id().untyped()
            || id == self.rules.id().untyped()
            || id == self.game.id().untyped()
            || self.kinds.values().any(|h| id == h.id().untyped())
            || self.gaits.values().any(|h| id == h.id().untyped())
    }
}

/// What is wrong with the files now, by file: shown on screen until fixed.
#[derive(Resource, Default, Debug)]
pub struct Problems(pub BTreeMap<String, String>);

/// Key of problems that span files (found when the config is put together).
const ACROSS_FILES: &str = "";

fn watch_files(server: Res<AssetServer>, base: Res<BaseConfig>, mut watched: ResMut<Watched>) {
    watched.scenario = server.load(watched.scenario_file.clone());
    watched.game = server.load(GAME_FILE);
    watched.arena = server.load(base.scenario.arena.clone());
    watched.rules = server.load(base.scenario.level_rules.clone());
    for kind in &base.kinds {
        let handle = server.load(kind_file(&kind.name));
        watched.kinds.insert(kind.name.clone(), handle);
        if let Some(file) = &kind.gait_table {
            let handle = server.load(file.clone());
            watched.gaits.insert(file.clone(), handle);
        }
    }
}

/// The message of a failed load: our own [`ConfigError`] when the file was read but is bad.
fn failure_text(error: &AssetLoadError) -> String {
    match error {
        AssetLoadError::AssetLoaderError(e) => e
            .error()
            .downcast_ref::<ConfigError>()
            .map_or_else(|| e.to_string(), ToString::to_string),
        other => other.to_string(),
    }
}

fn note_failures<A: Asset>(
    mut failures: MessageReader<AssetLoadFailedEvent<A>>,
    watched: Res<Watched>,
    mut problems: ResMut<Problems>,
) {
    for failure in failures.read().filter(|f| watched.watches(f.id.untyped())) {
        problems
            .0
            .insert(failure.path.to_string(), failure_text(&failure.error));
    }
}

/// A watched file loaded again: its old problem is gone and the config is put together anew.
fn note_changes<A: Asset>(
    mut events: MessageReader<AssetEvent<A>>,
    server: Res<AssetServer>,
    mut watched: ResMut<Watched>,
    mut problems: ResMut<Problems>,
) {
    for event in events.read() {
        if let AssetEvent::Modified { id } | AssetEvent::LoadedWithDependencies { id } = event {
            let id = id.untyped();
            if !watched.watches(id) {
                continue;
            }
            if let Some(path) = server.get_path(id) {
                problems.0.remove(&path.to_string());
            }
            watched.changed = true;
        }
    }
}

/// Puts the simulation config together from the files as the asset server has them now.
/// `Ok(None)`: a file still loading (asked for here if new). A file that failed keeps its
/// last good value.
fn assemble(
    watched: &mut Watched,
    server: &AssetServer,
    scenarios: &Assets<Scenario>,
    arenas: &Assets<ArenaConfig>,
    rules: &Assets<LevelRules>,
    kinds: &Assets<CreatureDef>,
    gaits: &Assets<GaitTable>,
) -> Result<Option<SimConfig>, ConfigError> {
    let Some(scenario) = scenarios.get(&watched.scenario) else {
        return Ok(None);
    };
    // What the files name must be files inside the assets folder (no symbolic link out of
    // it) before the asset server is asked for them: the same check as `SimConfig::load`.
    let root = watched.assets_root.clone();
    let scenario_path = root.join(&watched.scenario_file);
    resolve_reference(&root, &scenario_path, "arena", &scenario.arena)?;
    resolve_reference(&root, &scenario_path, "level_rules", &scenario.level_rules)?;
    let arena_path = AssetPath::parse(&scenario.arena).clone_owned();
    if watched.arena.path() != Some(&arena_path) {
        watched.arena = server.load(arena_path);
    }
    let rules_path = AssetPath::parse(&scenario.level_rules).clone_owned();
    if watched.rules.path() != Some(&rules_path) {
        watched.rules = server.load(rules_path);
    }
    let mut waiting = false;
    for (i, group) in scenario.creatures.iter().enumerate() {
        let field = format!("creatures[{i}].kind");
        resolve_reference(&root, &scenario_path, &field, &kind_file(&group.kind))?;
        let handle = watched
            .kinds
            .entry(group.kind.clone())
            .or_insert_with(|| server.load(kind_file(&group.kind)));
        let Some(kind) = kinds.get(&*handle) else {
            waiting = true;
            continue;
        };
        if let Some(file) = &kind.gait_table {
            resolve_reference(&root, &creature_file(&root, &group.kind), "gait_table", file)?;
            let gait = watched
                .gaits
                .entry(file.clone())
                .or_insert_with(|| server.load(file.clone()));
            waiting |= gaits.get(&*gait).is_none();
        }
    }
    let (Some(arena), Some(rules)) = (arenas.get(&watched.arena), rules.get(&watched.rules)) else {
        return Ok(None);
    };
    if waiting {
        return Ok(None);
    }
    // The cost model is read from disk whenever the config is put together (not watched),
    // unless measured at start-up.
    let costs = match &watched.measured_costs {
        Some(measured) => measured.clone(),
        None => load_costs(&root, &root.join(&scenario.level_rules), rules)?,
    };
    SimConfig::assemble(
        &scenario_path,
        &root,
        scenario.clone(),
        arena.clone(),
        (rules.clone(), costs),
        |_, kind| Ok(kinds.get(&watched.kinds[kind]).expect("loaded").clone()),
        |_, file| Ok(gaits.get(&watched.gaits[file]).expect("loaded").clone()),
    )
    .map(Some)
}

/// After a change: a new round when the simulation files now say something else; new level
/// rules apply to the running round (they decide levels from now on, paper 3.4). Any other
/// change (`game.ron`, say) keeps the rules the player tuned with the keys.
fn apply_changes(
    server: Res<AssetServer>,
    scenarios: Res<Assets<Scenario>>,
    arenas: Res<Assets<ArenaConfig>>,
    rules: Res<Assets<LevelRules>>,
    kinds: Res<Assets<CreatureDef>>,
    gaits: Res<Assets<GaitTable>>,
    mut watched: ResMut<Watched>,
    mut problems: ResMut<Problems>,
    mut base: ResMut<BaseConfig>,
    mut live: ResMut<SimConfig>,
    mut rounds: MessageWriter<NewRound>,
    settings: Option<Res<GameSettings>>,
) {
    if !watched.changed {
        return;
    }
    match assemble(&mut watched, &server, &scenarios, &arenas, &rules, &kinds, &gaits) {
        Ok(None) => return,
        Ok(Some(mut config)) => {
            problems.0.remove(ACROSS_FILES);
            // The level policy is the player's (`--policy`, the L key), not the file's.
            config.scenario.level_policy = base.scenario.level_policy;
            let rules_edited = watched.file_rules.as_ref() != Some(&config.rules);
            if rules_edited {
                watched.file_rules = Some(config.rules.clone());
                if let Some(settings) = &settings {
                    settings.0.frame_budget.apply(&mut config.rules);
                }
                live.rules = config.rules.clone();
            } else {
                config.rules = base.rules.clone();
            }
            let same = config.scenario == base.scenario
                && config.arena == base.arena
                && config.kinds == base.kinds
                && config.gaits == base.gaits;
            base.0 = config;
            if !same {
                rounds.write(NewRound);
            }
        }
        Err(e) => {
            problems.0.insert(ACROSS_FILES.to_owned(), e.to_string());
        }
    }
    watched.changed = false;
}

/// A good edit of `game.ron` applies at once: the looks, and the game's adaptive mode of the
/// budget where the rules leave it off.
fn apply_looks(
    watched: Res<Watched>,
    looks: Res<Assets<GameConfig>>,
    mut settings: ResMut<GameSettings>,
    mut base: ResMut<BaseConfig>,
    mut live: ResMut<SimConfig>,
) {
    let Some(new) = looks.get(&watched.game).filter(|new| **new != settings.0) else {
        return;
    };
    if new.frame_budget != settings.0.frame_budget
        && let Some(files) = &watched.file_rules
    {
        let mut rules = files.clone();
        new.frame_budget.apply(&mut rules);
        for budget in [&mut base.rules.budget, &mut live.rules.budget] {
            budget.adaptive_frames = rules.budget.adaptive_frames;
            budget.adaptive_percentile = rules.budget.adaptive_percentile;
            budget.adaptive_percentile_limit = rules.budget.adaptive_percentile_limit;
        }
    }
    settings.0 = new.clone();
}

/// Hot reload: watches the asset files from startup, notes each file's problems for the HUD,
/// and applies good edits (a new round, or new rules or looks in place).
pub fn plugin(app: &mut App) {
    app.init_resource::<Problems>()
        .add_systems(Startup, watch_files)
        .add_systems(
            Update,
            (
                (
                    note_failures::<Scenario>,
                    note_failures::<ArenaConfig>,
                    note_failures::<LevelRules>,
                    note_failures::<CreatureDef>,
                    note_failures::<GaitTable>,
                    note_failures::<GameConfig>,
                    note_changes::<Scenario>,
                    note_changes::<ArenaConfig>,
                    note_changes::<LevelRules>,
                    note_changes::<CreatureDef>,
                    note_changes::<GaitTable>,
                    note_changes::<GameConfig>,
                ),
                apply_changes,
                apply_looks.run_if(resource_exists::<GameSettings>),
            )
                .chain(),
        );
}
