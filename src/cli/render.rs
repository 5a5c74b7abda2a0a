//! `imitate render`: test videos with ground truth, from any BVH.

use super::retarget::RetargetArgs;
use super::segment::take;
use super::{Global, Outcome, UsageError, camera, note, progress, refuse_nonempty};
use anyhow::Context;
use imitate::fsutil::{write_atomic, write_dir_atomic};
use imitate::vision::color::{Scene, Surface};
use imitate::vision::figure::{Build, BuildError};
use imitate::vision::mask::Mask;
use imitate::vision::noise::{Level, Noise};
use imitate::vision::render::draw;
use imitate::vision::shape::capsules;
use imitate::vision::truth;
use rayon::prelude::*;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

/// Render a BVH take (any skeleton: it is retargeted first) as binary
/// silhouettes of the canonical body drawn as capsules (or of a test body,
/// --body), with the camera and the ground truth of every frame; with
/// --color, also as color frames of the body in a room.
///
/// Writes DIR/frames/000000.png … (0 outside the body, 255 on it; noisy
/// unless --noise none), DIR/camera.json and DIR/truth.csv, with --color
/// DIR/color/000000.png … and DIR/background.png, and with a test body
/// DIR/body.toml (see docs/formats.md).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The BVH file to render.
    pub input: PathBuf,
    /// The folder to write (refused if it exists and is not empty, unless
    /// --force).
    #[arg(short, long)]
    pub output: PathBuf,
    /// `front`, `side`, `overhead`, or a camera.json file.
    #[arg(long, default_value = "front", value_name = "PRESET|camera.json")]
    pub camera: String,
    /// Frame size, WIDTHxHEIGHT, for a preset camera (a camera.json
    /// gives its own).
    #[arg(long, default_value = "160x120", value_name = "WxH")]
    pub size: String,
    /// Frames per second of the video; the take is sampled at these
    /// times, between its own frames where they fall between.
    #[arg(long, default_value_t = 15.0)]
    pub fps: f64,
    /// Activity labels (as for `imitate segment`); truth.csv then names
    /// each frame's activity.
    #[arg(long, value_name = "LABELS.csv")]
    pub labels: Option<PathBuf>,
    /// Also write color frames (color/*.png) of the body shaded over a lit,
    /// textured room, and the empty room (background.png).
    #[arg(long)]
    pub color: bool,
    /// Noise for robustness tests: none, light, medium, heavy (or 0 to
    /// 3). `light` is a good segmenter's output; `none` the clean render.
    #[arg(long, default_value = "light", value_name = "LEVEL")]
    pub noise: Level,
    /// Who performs the take: `capsules` (the tracker's own body), a test
    /// body built differently (`slight`, `lanky`, `average`, `skirt`,
    /// `broad`, `heavy`), or a build file (.toml, see docs/formats.md).
    /// truth.csv then holds that body's own joints.
    #[arg(long, default_value = "capsules", value_name = "NAME|FILE.toml")]
    pub body: String,
    /// Seed of the noise and of the room's textures; the same seed gives
    /// the same files.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    #[command(flatten)]
    pub retarget: RetargetArgs,
    /// Replace the output folder if it exists.
    #[arg(long)]
    pub force: bool,
}

/// `WIDTHxHEIGHT`.
fn parse_size(text: &str) -> Result<(u32, u32), UsageError> {
    let bad = || UsageError(format!("--size {text}: expected WIDTHxHEIGHT, e.g. 160x120"));
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((w.trim().parse().map_err(|_| bad())?, h.trim().parse().map_err(|_| bad())?))
}

/// One frame as an 8-bit grey PNG: 0 outside, 255 on the body.
fn png(mask: &Mask) -> Vec<u8> {
    let grey: Vec<u8> = mask.pixels().iter().map(|&p| p * 255).collect();
    encode(&grey, mask.width(), mask.height(), image::ExtendedColorType::L8)
}

/// Pixels as a PNG, compressed fast: frames are many.
fn encode(pixels: &[u8], width: usize, height: usize, kind: image::ExtendedColorType) -> Vec<u8> {
    imitate::fsutil::png(pixels, width as u32, height as u32, kind, imitate::fsutil::PngEffort::Fast)
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    if !(args.fps.is_finite() && args.fps > 0.0 && args.fps <= 1000.0) {
        return Err(UsageError(format!("--fps {}: must be above 0 and at most 1000", args.fps)).into());
    }
    let (width, height) = parse_size(&args.size)?;
    let camera = camera(&args.camera, width, height)?;
    let build = Build::choose(&args.body).map_err(|e| match e {
        BuildError::Unknown(_) => UsageError(format!("--body: {e}")).into(),
        e => anyhow::Error::from(e),
    })?;
    refuse_nonempty(&args.output, args.force)?;
    let started = Instant::now();
    let (motion, labels) = take(&args.input, args.labels.as_deref(), &args.retarget, global)?;
    let motion = match &build {
        Some(build) => motion.on_body(&build.body()),
        None => motion,
    };
    let times: Vec<f64> = (0..).map(|k| k as f64 / args.fps).take_while(|&t| t <= motion.duration_s() + 1e-9).collect();
    let bar = progress(global, times.len() as u64, "render");
    let noise = Noise::new(args.noise, args.seed, &camera, times.len(), args.fps);
    let scene = args.color.then(|| Scene::new(&camera, args.seed));
    let output = args.output.display().to_string();
    let io = |e: std::io::Error| anyhow::anyhow!("{output}: cannot write: {e}");
    let (width, height) = (camera.width(), camera.height());
    write_dir_atomic(
        &args.output,
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
                        let surface: Box<dyn Surface> = match &build {
                            Some(build) => {
                                let figure = build.figure(&motion.body, &world);
                                figure.draw(&camera, mask);
                                Box::new(figure)
                            }
                            None => {
                                let parts = capsules(&motion.body, &world);
                                draw(&camera, &parts, mask);
                                Box::new(parts)
                            }
                        };
                        if let Some(scene) = &scene {
                            let rgb = scene.shade(k, &world, surface.as_ref(), mask, &noise);
                            let encoded = encode(&rgb, width, height, image::ExtendedColorType::Rgb8);
                            std::fs::write(color.join(format!("{k:06}.png")), encoded)?;
                        }
                        noise.apply(k, &world, mask);
                        std::fs::write(frames.join(format!("{k:06}.png")), png(mask))?;
                        bar.inc(1);
                        let source = ((t / motion.frame_time_s).round() as usize).min(motion.poses.len() - 1);
                        let activity = labels.as_ref().map(|l| l[source].as_str());
                        Ok(truth::row(k, t, activity, &pose, &world))
                    },
                )
                .collect::<std::io::Result<_>>()
                .map_err(io)?;
            std::fs::write(dir.join("camera.json"), camera.to_json()).map_err(io)?;
            if let Some(build) = &build {
                std::fs::write(dir.join("body.toml"), build.to_toml()).map_err(io)?;
            }
            write_atomic(&dir.join("truth.csv"), |w| {
                w.write_all(truth::header().as_bytes())?;
                rows.iter().try_for_each(|r| w.write_all(r.as_bytes()))
            })
            .map_err(io)
        },
        io,
    )
    .with_context(|| args.input.display().to_string())?;
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    note(
        global,
        &format!(
            "{}: {} frames at {} Hz, {width}×{height}, {}, noise {}{} → {output} in {seconds:.2} s ({:.0} frames/s)",
            args.input.display(),
            times.len(),
            args.fps,
            build.as_ref().map_or("the tracker's capsules".to_string(), |b| format!("body `{}`", b.name)),
            args.noise.name(),
            if args.color { ", color" } else { "" },
            times.len() as f64 / seconds
        ),
    );
    Ok(Outcome::Success)
}
