//! The asset files: serde types, their loader and their validation.
//!
//! Every number a designer tunes lives in a RON file under `assets/`, with its unit in the
//! field name. One parse-and-validate path serves both Bevy's asset server (the game, with
//! hot reload) and plain file paths (the headless CLI and the tests).

mod arena;
mod costs;
mod creature;
pub mod gait;
mod game;
mod loader;
mod overrides;
mod rules;
mod scenario;
mod validate;

pub use crate::contract::MAX_LEGS;
pub use arena::{ArenaConfig, PuckConfig};
pub use costs::{CostModel, CrowdShares, KindCosts, LevelCosts, RigidShare};
pub use creature::{
    BodyConfig, CreatureDef, FallConfig, KindLook, LegConfig, RaibertConfig, RigidConfig, RigidJoints, Stance,
    SteeringConfig,
};
pub use game::{
    CameraConfig, CreatureLook, FrameBudgetInGame, GameConfig, HudConfig, InsetConfig, LightingConfig, RecordingConfig,
    SceneColours, Srgb,
};
pub use loader::{RonAssetLoader, load_file, parse_ron};
pub use overrides::Overrides;
pub use rules::{
    BudgetRules, CameraRules, InfluenceRules, LevelRules, validate_adaptive_percentile,
    validate_adaptive_percentile_limit,
};
pub use scenario::{CreatureGroup, LevelPolicy, MAX_CREATURES, MAX_DURATION_S, Scenario};
pub use validate::{ConfigError, Problem, Validate, Validator, number};

use bevy::prelude::*;

use crate::config::gait::GaitTable;
use std::path::{Path, PathBuf};

/// Everything one simulation run is built from: the scenario and the files it names.
#[derive(Resource, Clone, Debug)]
pub struct SimConfig {
    /// The scenario file.
    pub scenario: Scenario,
    /// The court and puck it names.
    pub arena: ArenaConfig,
    /// Creature definitions, indexed by [`crate::creature::Creature::kind`].
    pub kinds: Vec<CreatureDef>,
    /// Each kind's gait table, if it has one (same index as `kinds`).
    pub gaits: Vec<Option<GaitTable>>,
    /// The level rules it names.
    pub rules: LevelRules,
    /// The budget policy's cost model (the file the rules' `budget.cost_model` names).
    pub costs: CostModel,
}

/// What a command measures anew, and so need not load: `simlod record-gait` a kind's gait
/// table, `simlod bench --calibrate` the cost model (which starts empty).
#[derive(Clone, Copy, Debug, Default)]
pub struct MeasuredAnew<'a> {
    /// The kind whose gait table is about to be recorded.
    pub gait_table_of: Option<&'a str>,
    /// Whether the cost model is about to be calibrated.
    pub cost_model: bool,
}

impl SimConfig {
    /// What each of its kinds costs (in the kinds' order) in a world of its scenario's size,
    /// `rigid` of its creatures rigid.
    pub fn costs_by_kind(&self, rigid: u32) -> Vec<LevelCosts> {
        let population = self.scenario.creature_count();
        self.kinds
            .iter()
            .map(|k| self.costs.in_crowd(&k.name, population, rigid))
            .collect()
    }

    /// Loads a scenario file and the arena and creature files it names, resolved against
    /// `assets_root` (`arena` is a path under it; a creature kind `k` is
    /// `creatures/k.ron`). Every problem is reported with the file it is in; a file that
    /// cannot be read, with the file and field that named it.
    pub fn load(scenario_path: &Path, assets_root: &Path) -> Result<Self, ConfigError> {
        Self::load_measuring(scenario_path, assets_root, MeasuredAnew::default())
    }

    /// As [`SimConfig::load`], but what is about to be measured anew is not loaded, whatever
    /// its file says (even a broken, outdated or missing one): see [`MeasuredAnew`].
    pub fn load_measuring(scenario_path: &Path, assets_root: &Path, anew: MeasuredAnew) -> Result<Self, ConfigError> {
        let scenario: Scenario = load_file(scenario_path)?;
        let arena = load_reference(assets_root, scenario_path, "arena", &scenario.arena)?;
        let rules: LevelRules = load_reference(assets_root, scenario_path, "level_rules", &scenario.level_rules)?;
        let costs = if anew.cost_model {
            CostModel::default()
        } else {
            load_costs(assets_root, &assets_root.join(&scenario.level_rules), &rules)?
        };
        Self::assemble(
            scenario_path,
            assets_root,
            scenario,
            arena,
            (rules, costs),
            |i, kind| {
                let field = format!("creatures[{i}].kind");
                let path = creature_file(assets_root, kind);
                if !path.exists() {
                    return Err(ConfigError::one(
                        scenario_path,
                        field,
                        format!(
                            "unknown creature kind {kind:?}: there is no {}; known kinds: {}",
                            path.display(),
                            known_kinds(assets_root).join(", ")
                        ),
                    ));
                }
                let mut def: CreatureDef = load_reference(assets_root, scenario_path, &field, &kind_file(kind))?;
                if anew.gait_table_of == Some(kind) {
                    def.gait_table = None;
                }
                Ok(def)
            },
            |creature, file| load_reference(assets_root, creature, "gait_table", file),
        )
    }

    /// Puts a scenario together with its arena, its level rules, the creature kinds it names
    /// and their gait tables, and checks what spans files. `kind_def(i, k)` gives the definition of kind
    /// `k`, first named by creature group `i`; `gait_table(c, f)` the table in file `f` (under
    /// the assets folder) named by the creature file `c`. Read from disk by [`SimConfig::load`], taken from the asset
    /// server by the game, so both check the same things.
    pub fn assemble(
        scenario_path: &Path,
        assets_root: &Path,
        scenario: Scenario,
        arena: ArenaConfig,
        (rules, costs): (LevelRules, CostModel),
        mut kind_def: impl FnMut(usize, &str) -> Result<CreatureDef, ConfigError>,
        mut gait_table: impl FnMut(&Path, &str) -> Result<GaitTable, ConfigError>,
    ) -> Result<Self, ConfigError> {
        let mut kinds = Vec::with_capacity(scenario.creatures.len());
        for (i, group) in scenario.creatures.iter().enumerate() {
            if kinds.iter().any(|k: &CreatureDef| k.name == group.kind) {
                continue;
            }
            let def = kind_def(i, &group.kind)?;
            if def.name != group.kind {
                return Err(ConfigError::one(
                    &creature_file(assets_root, &group.kind),
                    "name",
                    format!("is {:?} but the file is named for kind {:?}", def.name, group.kind),
                ));
            }
            kinds.push(def);
        }
        let gaits = kinds
            .iter()
            .map(|k| gait_of(assets_root, k, &mut gait_table))
            .collect::<Result<_, _>>()?;
        let config = Self {
            scenario,
            arena,
            kinds,
            gaits,
            rules,
            costs,
        };
        config.check_fit(scenario_path)?;
        Ok(config)
    }

    /// Index of a creature kind by name.
    pub fn kind_index(&self, name: &str) -> Option<usize> {
        self.kinds.iter().position(|k| k.name == name)
    }

    /// Checks that span files: every creature fits in the court beside the puck, and all of
    /// them fit at once with their clearance (see [`SimConfig::fit`]).
    fn check_fit(&self, scenario_path: &Path) -> Result<(), ConfigError> {
        let biggest = self.kinds.iter().map(|k| k.body.radius_m).fold(0.0, f32::max);
        let half = self.arena.half_extents();
        if half.min_element() <= self.arena.puck.radius_m + 2.0 * biggest {
            return Err(ConfigError::one(
                scenario_path,
                "arena",
                format!(
                    "the court ({} x {} m) leaves no room beside the puck (radius {} m) for a creature (radius {} m)",
                    self.arena.court_length_m, self.arena.court_width_m, self.arena.puck.radius_m, biggest
                ),
            ));
        }
        let fit = self.fit();
        if fit.needed_m2 > fit.room_m2 {
            return Err(ConfigError::one(
                scenario_path,
                "creatures",
                format!(
                    "{} creatures do not fit in the court: with their respawn_creature_clearance_m of {} m they need {:.0} m^2, packed as tightly as circles can be, and the court ({} x {} m) leaves {:.0} m^2 beside the puck: at most about {} of them fit",
                    self.scenario.creature_count(),
                    self.arena.respawn_creature_clearance_m,
                    fit.needed_m2,
                    self.arena.court_length_m,
                    self.arena.court_width_m,
                    fit.room_m2,
                    fit.most
                ),
            ));
        }
        Ok(())
    }

    /// How much of the court the creatures need. Each takes a disk of its radius plus half
    /// the clearance (`respawn_creature_clearance_m`) kept between two creatures; the disks'
    /// centres keep that far from the walls, so all disks lie in the court less half the
    /// clearance at each wall, beside the puck. No arrangement of equal disks covers more
    /// than pi / sqrt(12) (0.907) of a plane, so more than that cannot be placed without
    /// overlaps: placement would fall back to overlapping spots ever more crowded.
    pub fn fit(&self) -> Fit {
        const DENSEST_PACKING: f32 = 0.9069;
        let clear = self.arena.respawn_creature_clearance_m;
        let disk = |kind: &str| {
            let r = self
                .kinds
                .iter()
                .find(|k| k.name == kind)
                .map_or(0.0, |k| k.body.radius_m)
                + 0.5 * clear;
            std::f32::consts::PI * r * r
        };
        let needed_m2: f32 = self
            .scenario
            .creatures
            .iter()
            .map(|g| g.count as f32 * disk(&g.kind))
            .sum();
        let court = (self.arena.court_length_m - clear).max(0.0) * (self.arena.court_width_m - clear).max(0.0);
        let puck = std::f32::consts::PI * self.arena.puck.radius_m.powi(2);
        let room_m2 = ((court - puck) * DENSEST_PACKING).max(0.0);
        let count = self.scenario.creature_count().max(1) as f32;
        Fit {
            needed_m2,
            room_m2,
            most: (room_m2 / (needed_m2 / count)).floor() as u64,
        }
    }
}

/// What [`SimConfig::fit`] found.
#[derive(Clone, Copy, Debug)]
pub struct Fit {
    /// The area the creatures need with their clearance.
    pub needed_m2: f32,
    /// The most of the court that disks can cover, beside the puck.
    pub room_m2: f32,
    /// About how many creatures of this mix fit.
    pub most: u64,
}

/// A kind's gait table, checked to be recorded for that kind.
fn gait_of(
    assets_root: &Path,
    kind: &CreatureDef,
    gait_table: &mut impl FnMut(&Path, &str) -> Result<GaitTable, ConfigError>,
) -> Result<Option<GaitTable>, ConfigError> {
    let Some(file) = &kind.gait_table else { return Ok(None) };
    let table = gait_table(&creature_file(assets_root, &kind.name), file)?;
    if table.creature != kind.name {
        return Err(ConfigError::one(
            &assets_root.join(file),
            "creature",
            format!("the table was recorded for {:?}, not {:?}", table.creature, kind.name),
        ));
    }
    let steps = kind.stance.steps_per_stride(kind.legs.len());
    if table.leg_count() != kind.legs.len() || table.steps_per_stride != steps {
        return Err(ConfigError::one(
            &assets_root.join(file),
            "columns",
            format!(
                "the table poses {} legs in strides of {} steps; {:?} has {} legs in strides of {steps}: record it again",
                table.leg_count(),
                table.steps_per_stride,
                kind.name,
                kind.legs.len()
            ),
        ));
    }
    Ok(Some(table))
}

/// The cost model the level rules (read from `rules_file`) name.
pub fn load_costs(assets_root: &Path, rules_file: &Path, rules: &LevelRules) -> Result<CostModel, ConfigError> {
    load_reference(assets_root, rules_file, "budget.cost_model", &rules.budget.cost_model)
}

/// The file a creature kind is defined in.
pub fn creature_file(assets_root: &Path, kind: &str) -> PathBuf {
    assets_root.join(kind_file(kind))
}

/// The file of a creature kind, as a path under the assets folder.
pub fn kind_file(kind: &str) -> String {
    format!("creatures/{kind}.ron")
}

/// The file `reference` (under `assets_root`) that field `field` of file `referrer` names,
/// once it is known to be a file inside the assets folder: not outside it by `..`, an
/// absolute path or a symbolic link, not a folder, not missing. Errors name the referrer and
/// its field, and the path.
pub fn resolve_reference(
    assets_root: &Path,
    referrer: &Path,
    field: &str,
    reference: &str,
) -> Result<PathBuf, ConfigError> {
    let refuse = |why: String| Err(ConfigError::one(referrer, field, why));
    if let Err(why) = validate::inside_assets(reference) {
        return refuse(format!("{why}, got {reference:?}"));
    }
    let path = assets_root.join(reference);
    let real = match path.canonicalize() {
        Ok(real) => real,
        Err(e) => return refuse(format!("cannot read {}: {e}", path.display())),
    };
    match assets_root.canonicalize() {
        Ok(root) if real.starts_with(&root) => {}
        _ => {
            return refuse(format!(
                "{} leads outside the assets folder {} (through a symbolic link)",
                path.display(),
                assets_root.display()
            ));
        }
    }
    if real.is_dir() {
        return refuse(format!("{} is a folder, not a file", path.display()));
    }
    Ok(path)
}

/// Reads and parses the file a field of another names (see [`resolve_reference`]).
fn load_reference<T: serde::de::DeserializeOwned + Validate>(
    assets_root: &Path,
    referrer: &Path,
    field: &str,
    reference: &str,
) -> Result<T, ConfigError> {
    let path = resolve_reference(assets_root, referrer, field, reference)?;
    let bytes = std::fs::read(&path)
        .map_err(|e| ConfigError::one(referrer, field, format!("cannot read {}: {e}", path.display())))?;
    parse_ron(&bytes, &path)
}

fn known_kinds(assets_root: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(assets_root.join("creatures"))
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let p = e.path();
            if p.extension()? == "ron" && p.is_file() {
                Some(p.file_stem()?.to_string_lossy().into_owned())
            } else {
                None
            }
        })
        .collect();
    names.sort();
    names
}

/// Registers the asset types and their loader with Bevy's asset server, when it is present.
pub fn plugin(app: &mut App) {
    if app.is_plugin_added::<bevy::asset::AssetPlugin>() {
        // All share the `.ron` extension: the asset server picks the loader by the
        // asset type asked for.
        app.init_asset::<Scenario>()
            .init_asset::<ArenaConfig>()
            .init_asset::<CreatureDef>()
            .init_asset::<LevelRules>()
            .init_asset_loader::<RonAssetLoader<LevelRules>>()
            .init_asset::<GameConfig>()
            .init_asset_loader::<RonAssetLoader<Scenario>>()
            .init_asset_loader::<RonAssetLoader<ArenaConfig>>()
            .init_asset_loader::<RonAssetLoader<CreatureDef>>()
            .init_asset_loader::<RonAssetLoader<GameConfig>>()
            .init_asset::<GaitTable>()
            .init_asset_loader::<RonAssetLoader<GaitTable>>();
    }
}
