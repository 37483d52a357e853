//! Pictures of the game made by a command, so that they can always be made again:
//! `simlod play --screenshot FILE.png --frames N` renders N frames, saves the window and quits;
//! `simlod play --record FILE.gif --frames N` saves every `recording.every_nth_frame`-th of
//! the N frames as an animated GIF (`recording` in `game.ron`). A blank picture is an error.
//! Each frame advances the game by one steering decision's time (1/30 s by default),
//! whatever the renderer's speed, so the pictures show the same moments on a fast GPU and
//! under a software driver, and the GIF plays at the game's speed.

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use std::path::{Path, PathBuf};

use super::GameSettings;
use simlod::SimClock;

/// What to save, and after how many frames.
#[derive(Clone, Debug)]
pub struct CapturePlan {
    /// The file written: a PNG for a screenshot, a GIF for a recording.
    pub path: PathBuf,
    /// Frames rendered before the game quits (`--frames`), each one steering decision's time.
    pub frames: u32,
    /// A screenshot or a recording.
    pub kind: Capture,
}

/// One picture at the end, or an animated one of the whole run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Capture {
    /// One picture of the last frame (`--screenshot`).
    Screenshot,
    /// An animated GIF of every `recording.every_nth_frame`-th frame (`--record`).
    Recording,
}

/// The plan, the frames rendered so far and, for a recording, the pictures captured (each
/// with the frame it was asked at: captures arrive a frame or more later).
#[derive(Resource, Debug)]
struct Capturing {
    plan: CapturePlan,
    rendered: u32,
    pictures: Vec<(u32, image::RgbImage)>,
}

impl Capturing {
    fn wanted(&self, every_nth_frame: u32) -> u32 {
        match self.plan.kind {
            Capture::Screenshot => 1,
            Capture::Recording => self.plan.frames / every_nth_frame.max(1),
        }
    }
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

/// Counts frames and asks for a picture on the frames the plan wants one.
fn count_frames(mut commands: Commands, mut capturing: ResMut<Capturing>, settings: Res<GameSettings>) {
    capturing.rendered += 1;
    let frame = capturing.rendered;
    let every = settings.recording.every_nth_frame;
    let due = match capturing.plan.kind {
        Capture::Screenshot => frame == capturing.plan.frames,
        Capture::Recording => frame <= capturing.plan.frames && frame.is_multiple_of(every),
    };
    if !due {
        return;
    }
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>,
              mut capturing: ResMut<Capturing>,
              settings: Res<GameSettings>,
              clock: Res<SimClock>,
              mut exit: MessageWriter<AppExit>| {
            let picture = match captured.image.clone().try_into_dynamic() {
                Ok(picture) => picture,
                Err(e) => {
                    error!("cannot read the screenshot: {e}");
                    exit.write(AppExit::error());
                    return;
                }
            };
            match capturing.plan.kind {
                Capture::Screenshot => {
                    exit.write(save_png(&picture.to_rgb8(), &capturing.plan.path));
                }
                Capture::Recording => {
                    let width = settings.recording.width_px.min(picture.width());
                    let height = (picture.height() * width / picture.width().max(1)).max(1);
                    capturing
                        .pictures
                        .push((frame, picture.thumbnail_exact(width, height).to_rgb8()));
                    if capturing.pictures.len() as u32 == capturing.wanted(every) {
                        let frame_s = clock.ticks_per_decision as f32 / clock.tick_hz as f32;
                        let delay_cs = (100.0 * frame_s * every as f32).round() as u16;
                        let mut pictures = std::mem::take(&mut capturing.pictures);
                        pictures.sort_by_key(|(frame, _)| *frame);
                        exit.write(save_gif(&pictures, delay_cs, &capturing.plan.path));
                    }
                }
            }
        },
    );
}

/// Saves the picture unless it is blank; the exit status says which.
fn save_png(rgb: &image::RgbImage, path: &Path) -> AppExit {
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

/// Writes the pictures as a looping GIF, each shown `delay_cs` hundredths of a second; a
/// recording whose every picture is blank is not written.
fn save_gif(pictures: &[(u32, image::RgbImage)], delay_cs: u16, path: &Path) -> AppExit {
    if pictures.iter().all(|(_, rgb)| is_blank(rgb.as_raw())) {
        error!("the recording is blank: nothing was drawn");
        return AppExit::error();
    }
    match write_gif(pictures, delay_cs, path) {
        Ok(()) => {
            info!("recording of {} pictures saved to {}", pictures.len(), path.display());
            AppExit::Success
        }
        Err(e) => {
            error!("cannot save the recording to {}: {e}", path.display());
            AppExit::error()
        }
    }
}

fn write_gif(pictures: &[(u32, image::RgbImage)], delay_cs: u16, path: &Path) -> Result<(), String> {
    let Some((_, first)) = pictures.first() else {
        return Err("no pictures".to_owned());
    };
    let (width, height) = (first.width() as u16, first.height() as u16);
    let file = std::fs::File::create(path).map_err(|e| e.to_string())?;
    let mut encoder =
        gif::Encoder::new(std::io::BufWriter::new(file), width, height, &[]).map_err(|e| e.to_string())?;
    encoder.set_repeat(gif::Repeat::Infinite).map_err(|e| e.to_string())?;
    for (_, rgb) in pictures {
        // NeuQuant's palette per picture, at its faster end (10 of 1 to 30).
        let mut frame = gif::Frame::from_rgb_speed(width, height, rgb.as_raw(), 10);
        frame.delay = delay_cs;
        encoder.write_frame(&frame).map_err(|e| e.to_string())?;
    }
    Ok(())
}

pub(super) fn plugin(app: &mut App, plan: CapturePlan) {
    // A frame is one steering decision's ticks, every one of them run (at 1 Hz decisions a
    // frame is a second of simulation, more than Bevy lets through an update by default).
    let ticks = app.world().resource::<SimClock>().ticks_per_decision;
    simlod::headless::run_ticks_per_update(app.world_mut(), ticks);
    app.insert_resource(Capturing {
        plan: CapturePlan {
            frames: plan.frames.max(1),
            ..plan
        },
        rendered: 0,
        pictures: Vec::new(),
    })
    .add_systems(Last, count_frames);
}

#[cfg(test)]
mod tests {
    use super::{is_blank, write_gif};

    #[test]
    fn a_uniform_picture_is_blank_and_one_with_something_drawn_is_not() {
        let sky = [140u8, 180, 215].repeat(1000);
        assert!(is_blank(&sky));
        let mut drawn = sky.clone();
        drawn[1500..1503].copy_from_slice(&[20, 20, 20]);
        assert!(!is_blank(&drawn));
    }

    #[test]
    fn a_recording_is_written_as_a_looping_gif_of_every_picture_in_order() {
        let picture = |shade: u8| image::RgbImage::from_fn(8, 6, |x, _| image::Rgb([shade, x as u8 * 30, 0]));
        let pictures = vec![(2, picture(10)), (4, picture(200)), (6, picture(90))];
        let path = std::env::temp_dir().join(format!("simlod-capture-{}.gif", std::process::id()));
        write_gif(&pictures, 7, &path).unwrap();
        let mut decoder = gif::DecodeOptions::new();
        decoder.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = decoder.read_info(std::fs::File::open(&path).unwrap()).unwrap();
        assert_eq!((decoder.width(), decoder.height()), (8, 6));
        let mut reds = Vec::new();
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            assert_eq!(frame.delay, 7);
            reds.push(frame.buffer[0]);
        }
        std::fs::remove_file(&path).unwrap();
        assert_eq!(reds.len(), 3);
        assert!(
            reds[0] < reds[2] && reds[2] < reds[1],
            "the pictures in order: {reds:?}"
        );
    }
}
