//! `imitate render`: test videos with ground truth, from any BVH.

use super::retarget::RetargetArgs;
use super::segment::take;
use super::{Global, Outcome, UsageError, camera, note, progress, refuse_nonempty};
use anyhow::Context;
use imitate::vision::figure::{Build, BuildError};
use imitate::vision::filming::{Filming, film};
use imitate::vision::noise::Level;
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

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let (width, height) = parse_size(&args.size)?;
    let camera = camera(&args.camera, width, height)?;
    let build = Build::choose(&args.body).map_err(|e| match e {
        BuildError::Unknown(_) => UsageError(format!("--body: {e}")).into(),
        e => anyhow::Error::from(e),
    })?;
    let filming = Filming { camera, fps: args.fps, build, noise: args.noise, color: args.color, seed: args.seed };
    if filming.check().is_err() {
        return Err(UsageError(format!("--fps {}: must be above 0 and at most 1000", args.fps)).into());
    }
    refuse_nonempty(&args.output, args.force)?;
    let started = Instant::now();
    let (motion, labels) = take(&args.input, args.labels.as_deref(), &args.retarget, global)?;
    let bar = progress(global, filming.times(&motion).len() as u64, "render");
    let filmed = film(&motion, labels.as_deref(), &filming, &args.output, &|| bar.inc(1))
        .with_context(|| args.input.display().to_string())?;
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    note(
        global,
        &format!(
            "{}: {filmed} frames at {} Hz, {}×{}, {}, noise {}{} → {} in {seconds:.2} s ({:.0} frames/s)",
            args.input.display(),
            args.fps,
            filming.camera.width(),
            filming.camera.height(),
            filming.build.as_ref().map_or("the tracker's capsules".to_string(), |b| format!("body `{}`", b.name)),
            args.noise.name(),
            if args.color { ", color" } else { "" },
            args.output.display(),
            filmed as f64 / seconds
        ),
    );
    Ok(Outcome::Success)
}
