//! `imitate track`: the virtual trajectory, the activity and every
//! primitive's probability and progress, from frames and a vocabulary.

use super::{Global, Outcome, UsageError, note, progress, refuse_nonempty};
use imitate::params::{InvalidField, Params};
use imitate::track::auto_camera::Focal;
use imitate::track::clip::{self, CameraChoice, ClipError, ClipOptions, ClipOptionsError, track_clip};
use imitate::track::open_set::OpenSet;
use imitate::vision::camera::{Camera, Preset};
use imitate::vision::resize::DEFAULT_WORK_WIDTH;
use std::path::{Path, PathBuf};

/// Track a person through one camera with a vocabulary of primitives: one
/// particle filter per primitive in its latent space (bending-cone motion
/// model), activity recognition from the estimates' likelihoods, and the
/// virtual trajectory (the winning primitive's pose each frame).
///
/// Writes DIR/trajectory.bvh, DIR/frames.csv, DIR/likelihoods.csv (not
/// with --baseline), DIR/camera.json (the camera used) and
/// DIR/summary.json (see docs/formats.md).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The frames: a folder of PNG or JPEG images (silhouettes or color),
    /// or a video file (read through ffmpeg).
    pub input: PathBuf,
    /// The vocabulary (`imitate vocab build`).
    #[arg(long, value_name = "FILE.vocab")]
    pub vocab: PathBuf,
    /// The folder to write (refused if it exists and is not empty, unless
    /// --force).
    #[arg(short, long)]
    pub output: PathBuf,
    /// `front`, `side`, `overhead` (framed at the frames' size), a
    /// camera.json file, or `auto`: estimated from the first seconds of
    /// silhouettes and the person's height (--height, else the canonical
    /// body's). Default: the camera.json `render` wrote beside the frames
    /// (in INPUT or its parent folder), else `auto`.
    #[arg(long, value_name = "PRESET|camera.json|auto")]
    pub camera: Option<String>,
    /// The estimated camera's vertical field of view in degrees (10 to
    /// 150), when known. Default: 48 (a phone's or webcam's video).
    #[arg(long, value_name = "DEG", conflicts_with = "focal")]
    pub fov: Option<f64>,
    /// The estimated camera's focal length in pixels of the frames, when
    /// known.
    #[arg(long, value_name = "PX")]
    pub focal: Option<f64>,
    /// Particles per primitive.
    #[arg(long, default_value_t = 6)]
    pub particles: usize,
    /// K of the bending cone: predictions along each primitive's field (1
    /// is the straight-line model).
    #[arg(long, default_value_t = 5)]
    pub lookahead: usize,
    /// Seed of every random draw; the same inputs and seed give the same
    /// files (but summary.json's timing).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Recognize with eq. 10: each primitive's likelihood times its recent
    /// probability, instead of eq. 7's likelihoods alone.
    #[arg(long)]
    pub feedback: bool,
    /// Frames per second of the input. Default: a video's own rate; for
    /// a folder, the rate of the truth.csv `render` wrote beside it, else 15.
    #[arg(long)]
    pub fps: Option<f64>,
    /// The person's standing height in meters (1.0 to 2.3), when known:
    /// calibration then fits only the limbs' shares and the girths.
    #[arg(long, value_name = "M", conflicts_with = "baseline")]
    pub height: Option<f64>,
    /// Draw the canonical body throughout instead of fitting the person's
    /// build (height, limb shares, girths) to the first seconds of
    /// silhouettes.
    #[arg(long, conflicts_with = "height")]
    pub no_calibrate: bool,
    /// The empty scene, for color frames. Default: background.png beside
    /// the frames (as `render --color` writes it), else a background
    /// learned from the frames (what the person does not cover).
    #[arg(long, value_name = "IMAGE")]
    pub background: Option<PathBuf>,
    /// The width in pixels frames are reduced to, keeping their aspect,
    /// for the silhouettes and the likelihood; frames no wider keep their
    /// size, and 0 keeps every frame's own size. Outputs (camera.json,
    /// keypoints) stay in the frames' own pixels.
    #[arg(long, value_name = "PX", default_value_t = DEFAULT_WORK_WIDTH)]
    pub work_size: usize,
    /// Run a baseline instead of the primitives' filters. `full-space`:
    /// one annealed particle filter over every joint angle and the root
    /// (Deutscher, Blake & Reid 2000), spending as many likelihood
    /// evaluations per frame as the primitives' filters would; its rows
    /// name no activity.
    #[arg(long, value_enum)]
    pub baseline: Option<Baseline>,
    /// 2-D keypoints of the same frames from a pose detector: a CSV or
    /// JSON file (MediaPipe's landmarks, as `scripts/keypoints.sh` writes
    /// them, or COCO-17 results) or a folder of OpenPose BODY_25 / COCO
    /// files (see docs/formats.md, "Keypoints").
    #[arg(long, value_name = "FILE", conflicts_with = "baseline")]
    pub keypoints: Option<PathBuf>,
    /// What the filters score each frame by: the silhouette, the
    /// keypoints, or both. Default: both with --keypoints, else the
    /// silhouette.
    #[arg(long, value_enum)]
    pub observe: Option<Observe>,
    /// The open set: a frame is reported unexplained (frames.csv's
    /// `unexplained`) when the primitive with the most evidence accounts
    /// for less than this share of what is seen over half a second: of the
    /// keypoints (weighted by how much they move), those it places within
    /// PCK@0.2; without keypoints, its silhouette's overlap with the
    /// person's.
    #[arg(long, value_name = "FIT", default_value_t = OpenSet::STANDARD.min_fit)]
    pub unexplained_below: f64,
    /// Replace the output folder if it exists.
    #[arg(long)]
    pub force: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, clap::ValueEnum)]
pub enum Baseline {
    FullSpace,
}

#[derive(Clone, Copy, Debug, PartialEq, clap::ValueEnum)]
pub enum Observe {
    Silhouette,
    Keypoints,
    Both,
}

/// The library's options for the flags; a camera file is read here, so
/// its errors name it.
fn options(args: &Args) -> anyhow::Result<ClipOptions> {
    let camera = match args.camera.as_deref() {
        None => CameraChoice::Beside,
        Some("auto") => CameraChoice::Auto,
        Some(choice) => match Preset::from_name(choice) {
            Some(preset) => CameraChoice::Preset(preset),
            None if Path::new(choice).is_file() => {
                CameraChoice::Given { camera: Box::new(Camera::read(Path::new(choice))?), from: choice.to_string() }
            }
            None => {
                return Err(UsageError(format!(
                    "--camera {choice}: neither a preset (front, side, overhead) nor a camera.json file"
                ))
                .into());
            }
        },
    };
    let focal = match (args.fov, args.focal) {
        (Some(deg), _) => Focal::Fov(deg),
        (None, Some(px)) => Focal::Pixels(px),
        (None, None) => Focal::Assumed,
    };
    Ok(ClipOptions {
        camera,
        focal,
        particles: args.particles,
        lookahead: args.lookahead,
        seed: args.seed,
        feedback: args.feedback,
        fps: args.fps,
        height_m: args.height,
        calibrate: !args.no_calibrate,
        background: args.background.clone(),
        work_width: args.work_size,
        baseline: args.baseline.map(|Baseline::FullSpace| clip::Baseline::FullSpace),
        keypoints: args.keypoints.clone(),
        observe: args.observe.map(|o| match o {
            Observe::Silhouette => clip::Observe::Silhouette,
            Observe::Keypoints => clip::Observe::Keypoints,
            Observe::Both => clip::Observe::Both,
        }),
        unexplained_below: args.unexplained_below,
    })
}

/// The flag, with the value given, that sets a clip option.
fn flag(args: &Args, option: &str) -> String {
    let shown = |value: Option<String>| value.map_or(String::new(), |v| format!(" {v}"));
    match option {
        "work_width" => format!("--work-size {}", args.work_size),
        "fps" => format!("--fps{}", shown(args.fps.map(|v| v.to_string()))),
        "height_m" => format!("--height{}", shown(args.height.map(|v| v.to_string()))),
        "focal" => match (args.fov, args.focal) {
            (Some(deg), _) => format!("--fov {deg}"),
            (None, Some(px)) => format!("--focal {px}"),
            (None, None) => "--fov or --focal".to_string(),
        },
        "particles" => format!("--particles {}", args.particles),
        "lookahead" => format!("--lookahead {}", args.lookahead),
        "unexplained_below" => format!("--unexplained-below {}", args.unexplained_below),
        other => format!("--{}", other.replace('_', "-")),
    }
}

/// A usage error (exit 2) where an option is at fault or would settle it,
/// naming its flag; any other error as it is.
fn cli_error(args: &Args, e: ClipError) -> anyhow::Error {
    match (&e, e.option()) {
        (ClipError::Options(o @ ClipOptionsError::ObserveWithoutKeypoints), _) => {
            UsageError(format!("{} (give them with --keypoints FILE)", o.naming(&flag(args, o.field())))).into()
        }
        (ClipError::Options(o), _) => UsageError(o.naming(&flag(args, o.field()))).into(),
        (ClipError::FocalWithCamera { .. }, _) => {
            UsageError(format!("{e} (drop --fov and --focal, or pass --camera auto)")).into()
        }
        (_, Some(option)) => UsageError(format!("{e} (pass --{option})")).into(),
        _ => e.into(),
    }
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let options = options(&args)?;
    options.check().map_err(|e| cli_error(&args, e.into()))?;
    refuse_nonempty(&args.output, args.force)?;
    let mut bar = None;
    let tracked = track_clip(&args.input, &args.vocab, &options, &mut |p| {
        bar.get_or_insert_with(|| progress(global, p.total.unwrap_or(0) as u64, "track")).inc(1)
    });
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let tracked = tracked.map_err(|e| cli_error(&args, e))?;
    let summary = &tracked.summary;
    let k = summary.frames;
    if let Some(decoding) = &tracked.decoding {
        note(global, &format!("{}: warning: {decoding}; the {k} frames read were tracked", args.input.display()));
    }
    tracked.write(&args.output, args.force)?;
    let who = match tracked.baseline_size {
        None => format!("{} primitives × {} particles", summary.primitives.len(), args.particles),
        Some((layers, particles)) => format!("full-space annealed filter, {layers} layers × {particles} particles"),
    };
    note(
        global,
        &format!(
            "{}: {k} frames ({} without a silhouette or keypoints), {who} → {} in {:.2} s ({:.1} frames/s, {:.0} likelihoods/frame)",
            args.input.display(),
            summary.coasted_frames,
            args.output.display(),
            summary.timing.seconds,
            summary.timing.frames_per_second,
            summary.likelihood_evaluations_per_frame
        ),
    );
    Ok(Outcome::Success)
}
