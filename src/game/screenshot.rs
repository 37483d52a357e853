//! `simlod play --screenshot FILE --frames N`: renders N frames, saves the window as a PNG
//! and quits; a blank picture is an error. Each frame advances the game by one steering
//! decision's time (1/30 s by default), whatever the renderer's speed, so the picture
//! shows the same moment on a fast GPU and under a software driver.

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use std::path::{Path, PathBuf};

use crate::SimClock;

/// Where the picture goes, and after how many frames.
#[derive(Resource, Debug)]
struct ScreenshotPlan {
    path: PathBuf,
    frames: u32,
    rendered: u32,
}

/// A picture is blank when every pixel has nearly the same colour.
fn is_blank(rgb: &[u8]) -> bool {
    let (mut lo, mut hi) = ([u8::MAX; 3], [0u8; 3]);
    for pixel in rgb.chunks_exact(3) {
        for c in 0..3 {
            lo[c] = lo[c].min(pixel[c]);
            hi[c] = hi[c].max(pixel[c]);
        }
    }
    (0..3).all(|c| hi[c].saturating_sub(lo[c]) < 8)
}

fn count_frames(mut commands: Commands, mut plan: ResMut<ScreenshotPlan>) {
    plan.rendered += 1;
    if plan.rendered != plan.frames {
        return;
    }
    let path = plan.path.clone();
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
            exit.write(save(&captured.image, &path));
        },
    );
}

/// Saves the picture unless it is blank; the exit status says which.
fn save(image: &Image, path: &Path) -> AppExit {
    let rgb = match image.clone().try_into_dynamic() {
        Ok(picture) => picture.to_rgb8(),
        Err(e) => {
            error!("cannot read the screenshot: {e}");
            return AppExit::error();
        }
    };
    if is_blank(rgb.as_raw()) {
        error!("the screenshot is blank: nothing was drawn");
        return AppExit::error();
    }
    match rgb.save(path) {
        Ok(()) => {
            info!("screenshot saved to {}", path.display());
            AppExit::Success
        }
        Err(e) => {
            error!("cannot save the screenshot to {}: {e}", path.display());
            AppExit::error()
        }
    }
}

pub(super) fn plugin(app: &mut App, path: PathBuf, frames: u32) {
    // A frame is one steering decision's ticks, every one of them run (at 1 Hz decisions a
    // frame is a second of simulation, more than Bevy lets through an update by default).
    let ticks = app.world().resource::<SimClock>().ticks_per_decision;
    crate::headless::run_ticks_per_update(app.world_mut(), ticks);
    app.insert_resource(ScreenshotPlan {
        path,
        frames: frames.max(1),
        rendered: 0,
    })
    .add_systems(Last, count_frames);
}

#[cfg(test)]
mod tests {
    use super::is_blank;

    #[test]
    fn a_uniform_picture_is_blank_and_one_with_something_drawn_is_not() {
        let sky = [140u8, 180, 215].repeat(1000);
        assert!(is_blank(&sky));
        let mut drawn = sky.clone();
        drawn[1500..1503].copy_from_slice(&[20, 20, 20]);
        assert!(!is_blank(&drawn));
    }
}
