//! The `play` command: the game in a window.

use crate::Failure;
use clap::Parser;
use std::path::PathBuf;

use crate::scenario::*;
use simlod::config::Overrides;
use simlod::lod::LevelPolicy;

/// `Parser` too, so that `simlod` alone plays with the defaults.
#[cfg(feature = "game")]
#[derive(Parser)]
pub(crate) struct PlayArgs {
    /// The scenario file (default: scenarios/default.ron in the assets folder); it must be
    /// inside the assets folder, which the game watches. A relative path not found as given
    /// is looked up in the assets folder.
    #[arg(long)]
    pub(crate) scenario: Option<PathBuf>,
    /// The assets folder: the scenario's arena and creature kinds, and `game.ron`.
    #[arg(long, default_value = "assets")]
    pub(crate) assets: PathBuf,
    /// Overrides the scenario's level policy (L switches it while playing).
    #[arg(long, value_parser = policy_parser())]
    pub(crate) policy: Option<LevelPolicy>,
    /// Overrides the budget policy's frame budget (ms of simulation per 1/30 s, 0 to 10000; 9
    /// and 0 change it while playing).
    #[arg(long, allow_negative_numbers = true, value_parser = frame_budget_ms)]
    pub(crate) frame_budget: Option<f32>,
    /// Render `--frames` frames, save the window to this PNG file and quit.
    #[arg(long, group = "capture", requires = "frames")]
    pub(crate) screenshot: Option<PathBuf>,
    /// Render `--frames` frames and save them to this file as an animated GIF (every
    /// `recording.every_nth_frame`-th of them, `recording.width_px` wide: `game.ron`), then quit.
    #[arg(long, group = "capture", requires = "frames")]
    pub(crate) record: Option<PathBuf>,
    /// Frames to render (each 1/30 s of the game) for `--screenshot` or `--record`.
    #[arg(long, requires = "capture", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub(crate) frames: Option<u32>,
}

#[cfg(feature = "game")]
impl PlayArgs {
    pub(crate) fn play(self) -> Result<(), Failure> {
        let runtime_dir = private_runtime_dir();
        let played = simlod_game::play(simlod_game::PlayOptions {
            scenario: scenario_file(&self.assets, self.scenario.as_deref()),
            assets: self.assets,
            overrides: Overrides {
                level_policy: self.policy,
                frame_budget_ms: self.frame_budget,
                ..Overrides::default()
            },
            capture: self.frames.and_then(|frames| {
                let (path, kind) = match (self.screenshot, self.record) {
                    (Some(path), _) => (path, simlod_game::Capture::Screenshot),
                    (None, Some(path)) => (path, simlod_game::Capture::Recording),
                    (None, None) => return None,
                };
                Some(simlod_game::CapturePlan { path, frames, kind })
            }),
        });
        if let Some(dir) = runtime_dir {
            let _ = std::fs::remove_dir_all(dir);
        }
        Ok(played?)
    }
}

/// Where `XDG_RUNTIME_DIR` is not set (a virtual X server, a bare session), the Vulkan driver's
/// probe for Wayland prints "error: XDG_RUNTIME_DIR is invalid" although nothing failed. The
/// game runs on X11: a private empty folder answers the probe quietly. Set here, before any
/// thread starts; removed when the game ends.
#[cfg(feature = "game")]
pub(crate) fn private_runtime_dir() -> Option<PathBuf> {
    use std::os::unix::fs::DirBuilderExt;
    if std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return None;
    }
    let dir = std::env::temp_dir().join(format!("simlod-runtime-{}", std::process::id()));
    std::fs::DirBuilder::new().mode(0o700).create(&dir).ok()?;
    // SAFETY: main's thread is the only one yet: nothing reads the environment concurrently.
    unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    Some(dir)
}
