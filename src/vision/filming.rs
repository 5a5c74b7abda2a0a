//! A take filmed as a test video with its ground truth: what `imitate
//! render` writes, and what `eval` and `demo` make their videos with
//! (docs/formats.md, "Frame input" and "Truth").

use crate::fsutil::{PngEffort, WriteError, png, write_atomic, write_dir_atomic};
use crate::mocap::pose::Motion;
use crate::vision::camera::Camera;
use crate::vision::color::{Scene, Surface};
use crate::vision::figure::Build;
use crate::vision::mask::Mask;
use crate::vision::noise::{Level, Noise};
use crate::vision::render::draw;
use crate::vision::shape::capsules;
use crate::vision::truth;
use rayon::prelude::*;
use std::borrow::Cow;
use std::io::Write;
use std::path::Path;

/// `render`'s frame size by default: the paper's camera's.
pub const DEFAULT_SIZE: (u32, u32) = (160, 120);
/// `render`'s frame rate by default: the paper's camera's.
pub const DEFAULT_FPS: f64 = 15.0;

/// How a take is filmed.
#[derive(Clone, Debug)]
pub struct Filming {
    pub camera: Camera,
    pub fps: f64,
    /// Who performs: `None` is the tracker's own capsules.
    pub build: Option<Build>,
    pub noise: Level,
    /// Color frames of a room (color/ and background.png) beside the
    /// silhouettes.
    pub color: bool,
    /// Seed of the noise and the room's textures.
    pub seed: u64,
}

impl Filming {
    /// Through `camera`, as `render` films by default: the capsules at
    /// [`DEFAULT_FPS`], light noise, silhouettes only, seed 0.
    pub fn new(camera: Camera) -> Filming {
        Filming { camera, fps: DEFAULT_FPS, build: None, noise: Level::Light, color: false, seed: 0 }
    }

    /// The times of the frames filmed of `motion`, seconds.
    pub fn times(&self, motion: &Motion) -> Vec<f64> {
        (0..).map(|k| k as f64 / self.fps).take_while(|&t| t <= motion.duration_s() + 1e-9).collect()
    }

    /// Refuses a frame rate no camera films at.
    pub fn check(&self) -> Result<(), FilmingError> {
        match self.fps.is_finite() && self.fps > 0.0 && self.fps <= 1000.0 {
            true => Ok(()),
            false => Err(FilmingError::Fps(self.fps)),
        }
    }
}

/// Why a take could not be filmed.
#[derive(Debug, thiserror::Error)]
pub enum FilmingError {
    #[error("fps: must be above 0 and at most 1000, not {0}")]
    Fps(f64),
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// Films `motion` (with each source frame's activity in `labels`) into
/// the folder `out`, replacing it whole once every file is written;
/// `progress` hears of each frame. Returns how many frames were filmed.
pub fn film(
    motion: &Motion,
    labels: Option<&[String]>,
    filming: &Filming,
    out: &Path,
    progress: &(dyn Fn() + Sync),
) -> Result<usize, FilmingError> {
    filming.check()?;
    let fps = filming.fps;
    let motion = match &filming.build {
        Some(build) => Cow::Owned(motion.on_body(&build.body())),
        None => Cow::Borrowed(motion),
    };
    let camera = &filming.camera;
    let times = filming.times(&motion);
    let noise = Noise::new(filming.noise, filming.seed, camera, times.len(), fps);
    let scene = filming.color.then(|| Scene::new(camera, filming.seed));
    let at = WriteError::at(out);
    let io = |e: std::io::Error| FilmingError::Write(at(e));
    let (width, height) = (camera.width(), camera.height());
    write_dir_atomic(
        out,
        |dir| {
            let frames = dir.join("frames");
            std::fs::create_dir(&frames).map_err(io)?;
            let color = dir.join("color");
            if let Some(scene) = &scene {
                std::fs::create_dir(&color).map_err(io)?;
                let room = encode(scene.background(), width, height, image::ExtendedColorType::Rgb8);
                std::fs::write(dir.join("background.png"), room).map_err(io)?;
            }
            let rows: Vec<String> = times
                .par_iter()
                .enumerate()
                .map_init(
                    || Mask::new(width, height),
                    |mask, (k, &t)| {
                        let pose = motion.pose_at(t);
                        let world = motion.body.forward(&pose);
                        mask.clear();
                        let surface: Box<dyn Surface> = match &filming.build {
                            Some(build) => {
                                let figure = build.figure(&motion.body, &world);
                                figure.draw(camera, mask);
                                Box::new(figure)
                            }
                            None => {
                                let parts = capsules(&motion.body, &world);
                                draw(camera, &parts, mask);
                                Box::new(parts)
                            }
                        };
                        if let Some(scene) = &scene {
                            let rgb = scene.shade(k, &world, surface.as_ref(), mask, &noise);
                            let encoded = encode(&rgb, width, height, image::ExtendedColorType::Rgb8);
                            std::fs::write(color.join(format!("{k:06}.png")), encoded)?;
                        }
                        noise.apply(k, &world, mask);
                        std::fs::write(frames.join(format!("{k:06}.png")), grey_png(mask))?;
                        progress();
                        let source = ((t / motion.frame_time_s).round() as usize).min(motion.poses.len() - 1);
                        let activity = labels.map(|l| l[source].as_str());
                        Ok(truth::row(k, t, activity, &pose, &world))
                    },
                )
                .collect::<std::io::Result<_>>()
                .map_err(io)?;
            std::fs::write(dir.join("camera.json"), camera.to_json()).map_err(io)?;
            if let Some(build) = &filming.build {
                std::fs::write(dir.join("body.toml"), build.to_toml()).map_err(io)?;
            }
            write_atomic(&dir.join("truth.csv"), |w| {
                w.write_all(truth::header().as_bytes())?;
                rows.iter().try_for_each(|r| w.write_all(r.as_bytes()))
            })
            .map_err(io)
        },
        io,
    )?;
    Ok(times.len())
}

/// One frame as an 8-bit grey PNG: 0 outside, 255 on the body.
fn grey_png(mask: &Mask) -> Vec<u8> {
    let grey: Vec<u8> = mask.pixels().iter().map(|&p| p * 255).collect();
    encode(&grey, mask.width(), mask.height(), image::ExtendedColorType::L8)
}

/// Pixels as a PNG, compressed fast: frames are many.
fn encode(pixels: &[u8], width: usize, height: usize, kind: image::ExtendedColorType) -> Vec<u8> {
    png(pixels, width as u32, height as u32, kind, PngEffort::Fast)
}
