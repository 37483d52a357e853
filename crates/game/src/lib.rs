//! The game: the escape-the-puck world in a window (paper figures 1, 5 and 6). The player
//! steers one creature; the camera follows it with the puck in view; an overhead inset
//! shows the whole court; the HUD shows the frame rate, the simulation's cost and the
//! levels of detail. Everything here only reads the simulation, except the player's
//! desired velocity and starting the world over.

mod camera;
mod capture;
mod controls;
mod creatures;
mod hud;
pub mod player;
pub mod reload;
mod scene;
pub mod view;

use bevy::asset::AssetMetaCheck;
use bevy::log::{BoxedFmtLayer, LogPlugin};
use bevy::prelude::*;
use bevy::window::WindowResolution;
use std::path::{Path, PathBuf};

pub use capture::{Capture, CapturePlan};
use simlod::SimPlugin;
use simlod::config::{ConfigError, CostModel, GameConfig, Overrides, SimConfig, load_file};

/// What `simlod play` was asked for.
pub struct PlayOptions {
    /// The scenario file to play (`--scenario`); it must lie inside the assets folder.
    pub scenario: PathBuf,
    /// The assets folder (`--assets`), watched for edits.
    pub assets: PathBuf,
    /// What the command line changes of the scenario's files (the rules' until they are edited).
    pub overrides: Overrides,
    /// Render some frames, save a screenshot or a recording of them, and quit.
    pub capture: Option<CapturePlan>,
}

/// The look of the game: the last good `assets/game.ron`.
#[derive(Resource, Clone, Debug, Deref)]
pub struct GameSettings(pub GameConfig);

/// The file the game's looks are read from, under the assets folder.
pub const GAME_FILE: &str = "game.ron";

/// Said instead of a panic when there is no display to open a window on.
pub const NO_DISPLAY: &str = "simlod cannot open the game window: no display is available (DISPLAY is not set or the X server cannot be reached); `simlod run` simulates without a window.";

/// Why the game could not be played.
#[derive(Debug, thiserror::Error)]
pub enum GameError {
    /// An asset file that did not load or did not pass its checks: it names the file and field.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// No display to open the window on.
    #[error("{NO_DISPLAY}")]
    NoDisplay,
    /// What the game was asked does not fit its files: the message says how.
    #[error("{0}")]
    Invalid(String),
    /// The game stopped with an error, which it logged.
    #[error("the game stopped with an error (see above)")]
    Stopped,
}

/// Opens the game window and plays until it closes.
pub fn play(options: PlayOptions) -> Result<(), GameError> {
    let mut config = SimConfig::load(&options.scenario, &options.assets)?;
    let file_rules = config.rules.clone();
    options.overrides.apply(&mut config);
    let looks: GameConfig = load_file(&options.assets.join(GAME_FILE))?;
    looks.frame_budget.apply(&mut config.rules);
    if let Some(plan) = &options.capture
        && plan.kind == Capture::Recording
        && plan.frames < looks.recording.every_nth_frame
    {
        return Err(GameError::Invalid(format!(
            "--frames {} records no picture: {GAME_FILE}'s recording.every_nth_frame is {}",
            plan.frames, looks.recording.every_nth_frame
        )));
    }
    let scenario_asset = asset_path(&options.assets, &options.scenario)?;
    let mut app = App::new();
    add_window_plugins(&mut app, &options)?;
    // After the window's plugins: the display is there, and the task pools are the game's, so
    // the costs are measured as the game will run.
    let measured_costs = looks.frame_budget.calibrate_at_start.then(|| measure_costs(&config));
    if let Some(model) = &measured_costs {
        config.costs = model.clone();
    }
    app.add_plugins(SimPlugin::new(config))
        .insert_resource(GameSettings(looks))
        .insert_resource(reload::Watched::new(
            scenario_asset,
            options.assets.clone(),
            file_rules,
            measured_costs,
        ));
    plugin(&mut app);
    if let Some(plan) = options.capture {
        capture::plugin(&mut app, plan);
    }
    match app.run() {
        AppExit::Success => Ok(()),
        AppExit::Error(_) => Err(GameError::Stopped),
    }
}

/// The budget policy's cost model measured on this machine, said on the terminal: a model
/// measured on another machine, or on another day, is off by as much as the machines differ.
fn measure_costs(config: &SimConfig) -> CostModel {
    info!("measuring the budget policy's costs on this machine (frame_budget.calibrate_at_start in {GAME_FILE})");
    let (model, said) = simlod_lab::bench::calibrate_at_start_up(config);
    info!("{said}");
    model
}

/// The scenario's path inside the assets folder, which is what the asset server watches.
fn asset_path(assets: &Path, scenario: &Path) -> Result<String, GameError> {
    let (Ok(root), Ok(file)) = (assets.canonicalize(), scenario.canonicalize()) else {
        return Err(GameError::Invalid(format!(
            "cannot find {} or {}",
            scenario.display(),
            assets.display()
        )));
    };
    let inside = file.strip_prefix(&root).map_err(|_| {
        GameError::Invalid(format!(
            "the scenario {} must be inside the assets folder {} (or give --assets)",
            scenario.display(),
            assets.display()
        ))
    })?;
    Ok(inside.to_string_lossy().replace('\\', "/"))
}

/// The log's format: colour codes only where stderr is a terminal (and `NO_COLOR` is not set),
/// so a log file or a pipe gets plain text.
fn plain_when_piped(_: &mut App) -> Option<BoxedFmtLayer> {
    use std::io::IsTerminal;
    let colour = std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none();
    Some(Box::new(
        bevy::log::tracing_subscriber::fmt::Layer::default()
            .with_ansi(colour)
            .with_writer(std::io::stderr),
    ))
}

/// Bevy's plugins for a window. Building the window's event loop panics when there is no
/// display; that panic is caught and told in one sentence.
fn add_window_plugins(app: &mut App, options: &PlayOptions) -> Result<(), GameError> {
    let plugins = DefaultPlugins
        .set(WindowPlugin {
            primary_window: Some(Window {
                title: "simlod: escape the puck".to_owned(),
                resolution: WindowResolution::new(1280, 720),
                ..default()
            }),
            ..default()
        })
        .set(LogPlugin {
            fmt_layer: plain_when_piped,
            // winit's complaints about a virtual X server (no XSETTINGS, a 0 mm screen) are
            // not the player's problem.
            filter: format!("{},winit=error", bevy::log::DEFAULT_FILTER),
            ..default()
        })
        .set(AssetPlugin {
            // Bevy resolves a relative path against the executable's folder, not ours.
            file_path: std::path::absolute(&options.assets)
                .unwrap_or_else(|_| options.assets.clone())
                .to_string_lossy()
                .into_owned(),
            watch_for_changes_override: Some(true),
            meta_check: AssetMetaCheck::Never,
            ..default()
        });
    let quiet = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let built = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        app.add_plugins(plugins);
    }));
    std::panic::set_hook(quiet);
    built.map_err(|_| GameError::NoDisplay)
}

fn plugin(app: &mut App) {
    player::plugin(app);
    reload::plugin(app);
    scene::plugin(app);
    creatures::plugin(app);
    view::plugin(app);
    camera::plugin(app);
    controls::plugin(app);
    hud::plugin(app);
}
