//! The asset files: serde types, their loader and their validation.
//!
//! Every number a designer tunes lives in a RON file under `assets/`, with its unit in the
//! field name. One parse-and-validate path serves both Bevy's asset server (the game, with
//! hot reload) and plain file paths (the headless CLI and the tests).

mod arena;
mod creature;
mod game;
mod loader;
mod rules;
mod scenario;
mod validate;

pub use arena::{ArenaConfig, PuckConfig};
pub use creature::{
    BodyConfig, CreatureDef, FallConfig, LegConfig, MAX_LEGS, RaibertConfig, RigidConfig, Stance, SteeringConfig,
};
pub use game::{CameraConfig, CreatureLook, GameConfig, HudConfig, InsetConfig, LightingConfig, SceneColours, Srgb};
pub use loader::{RonAssetLoader, load_file, parse_ron};
pub use rules::{CameraRules, InfluenceRules, LevelRules};
pub use scenario::{CreatureGroup, MAX_CREATURES, MAX_DURATION_S, Scenario};
pub use validate::{ConfigError, Problem, Validate, Validator};

use bevy::prelude::*;

use crate::gait::GaitTable;
use std::path::{Path, PathBuf};

/// Everything one simulation run is built from: the scenario and the files it names.
#[derive(Resource, Clone, Debug)]
pub struct SimConfig {
    pub scenario: Scenario,
    pub arena: ArenaConfig,
    /// Creature definitions, indexed by [`crate::creature::Creature::kind`].
    pub kinds: Vec<CreatureDef>,
    /// Each kind's gait table, if it has one (same index as `kinds`).
    pub gaits: Vec<Option<GaitTable>>,
    pub rules: LevelRules,
}

impl SimConfig {
    /// Loads a scenario file and the arena and creature files it names, resolved against
    /// `assets_root` (`arena` is a path under it; a creature kind `k` is
    /// `creatures/k.ron`). Every problem is reported with the file it is in.
    pub fn load(scenario_path: &Path, assets_root: &Path) -> Result<Self, ConfigError> {
        Self::load_without_table_of(scenario_path, assets_root, None)
    }

    /// As [`SimConfig::load`], but kind `without` (if any) gets no gait table, whatever its
    /// file says: `simlod record-gait` records it anew, even over a broken or outdated one.
    pub fn load_without_table_of(
        scenario_path: &Path,
        assets_root: &Path,
        without: Option<&str>,
    ) -> Result<Self, ConfigError> {
        let scenario: Scenario = load_file(scenario_path)?;
        let arena: ArenaConfig = load_file(&assets_root.join(&scenario.arena))?;
        let rules: LevelRules = load_file(&assets_root.join(&scenario.level_rules))?;
        Self::assemble(
            scenario_path,
            assets_root,
            scenario,
            arena,
            rules,
            |i, kind| {
                let path = creature_file(assets_root, kind);
                if !path.is_file() {
                    return Err(ConfigError::one(
                        scenario_path,
                        format!("creatures[{i}].kind"),
                        format!(
                            "unknown creature kind {kind:?}: there is no {}; known kinds: {}",
                            path.display(),
                            known_kinds(assets_root).join(", ")
                        ),
                    ));
                }
                let mut def: CreatureDef = load_file(&path)?;
                if without == Some(kind) {
                    def.gait_table = None;
                }
                Ok(def)
            },
            |file| load_file(&assets_root.join(file)),
        )
    }

    /// Puts a scenario together with its arena, its level rules, the creature kinds it names
    /// and their gait tables, and checks what spans files. `kind_def(i, k)` gives the definition of kind
    /// `k`, first named by creature group `i`; `gait_table(f)` the table in file `f` (under
    /// the assets folder). Read from disk by [`SimConfig::load`], taken from the asset
    /// server by the game, so both check the same things.
    pub fn assemble(
        scenario_path: &Path,
        assets_root: &Path,
        scenario: Scenario,
        arena: ArenaConfig,
        rules: LevelRules,
        mut kind_def: impl FnMut(usize, &str) -> Result<CreatureDef, ConfigError>,
        mut gait_table: impl FnMut(&str) -> Result<GaitTable, ConfigError>,
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
        };
        config.check_fit(scenario_path)?;
        Ok(config)
    }

    /// Index of a creature kind by name.
    pub fn kind_index(&self, name: &str) -> Option<usize> {
        self.kinds.iter().position(|k| k.name == name)
    }

    /// Checks that span files: every creature fits in the court beside the puck.
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
        Ok(())
    }
}

/// A kind's gait table, checked to be recorded for that kind.
fn gait_of(
    assets_root: &Path,
    kind: &CreatureDef,
    gait_table: &mut impl FnMut(&str) -> Result<GaitTable, ConfigError>,
) -> Result<Option<GaitTable>, ConfigError> {
    let Some(file) = &kind.gait_table else { return Ok(None) };
    let table = gait_table(file)?;
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

/// The file a creature kind is defined in.
pub fn creature_file(assets_root: &Path, kind: &str) -> PathBuf {
    assets_root.join("creatures").join(format!("{kind}.ron"))
}

fn known_kinds(assets_root: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(assets_root.join("creatures"))
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let p = e.path();
            if p.extension()? == "ron" {
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
            .init_asset_loader::<RonAssetLoader<GameConfig>>();
    }
}
