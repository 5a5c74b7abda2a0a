//! `imitate track`: the virtual trajectory, the activity and every
//! primitive's probability and progress, from frames and a vocabulary.

use super::{Global, Outcome, UsageError, camera, note, progress, refuse_nonempty};
use anyhow::{Context, bail};
use imitate::fsutil::{write_atomic, write_dir_atomic};
use imitate::mocap::body::Body;
use imitate::mocap::body::Joint;
use imitate::mocap::bvh::write_bvh;
use imitate::mocap::pose::Motion;
use imitate::mocap::pose::Pose;
use imitate::track::auto_camera::{self, CameraEstimate, FOV_DEG, Focal, Person, Standing};
use imitate::track::baseline::{AnnealParams, FullSpaceFilter, mean_training_pose};
use imitate::track::calibrate::{CalibrationParams, CalibrationReport, HEIGHT_M};
use imitate::track::filter::FilterParams;
use imitate::track::open_set::OpenSet;
use imitate::track::root::Root;
use imitate::track::tracker::{FrameEstimate, Recognition, TrackParams, Tracker};
use imitate::vision::camera::Camera;
use imitate::vision::frames::{Expect, FrameSource, beside_frames};
use imitate::vision::keypoints::{Keypoints, SitePoints};
use imitate::vision::mask::Mask;
use imitate::vision::resize::{DEFAULT_WORK_WIDTH, shrink_mask, work_size};
use imitate::vision::silhouette::Silhouettes;
use imitate::vision::truth;
use imitate::vision::video::{VideoProbe, probe_video};
use imitate::vocab::vocabulary::Vocabulary;
use std::fmt::Write as _;
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

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

#[derive(Clone, Copy, Debug, PartialEq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Observe {
    Silhouette,
    Keypoints,
    Both,
}

impl Observe {
    fn silhouette(self) -> bool {
        self != Observe::Keypoints
    }
}

/// What follows the person: the primitives' filters, or the baseline.
enum Follower {
    Primitives(Box<Tracker>),
    FullSpace(Box<FullSpaceFilter>),
}

impl Follower {
    /// The frame's pose, and the primitives' view of it when they track.
    fn step(&mut self, mask: &Mask, keypoints: Option<&SitePoints>) -> (Pose, Option<FrameEstimate>) {
        match self {
            Follower::Primitives(tracker) => {
                let estimate = tracker.step_seen(Some(mask), keypoints);
                (estimate.pose, Some(estimate))
            }
            Follower::FullSpace(filter) => (filter.step(mask), None),
        }
    }

    fn evaluations(&self) -> u64 {
        match self {
            Follower::Primitives(tracker) => tracker.evaluations(),
            Follower::FullSpace(filter) => filter.evaluations(),
        }
    }

    fn body(&self) -> &Body {
        match self {
            Follower::Primitives(tracker) => tracker.body(),
            Follower::FullSpace(filter) => filter.body(),
        }
    }

    /// What calibration found (the baseline draws the canonical body).
    fn calibration(&self) -> Option<&CalibrationReport> {
        match self {
            Follower::Primitives(tracker) => Some(tracker.calibration()),
            Follower::FullSpace(_) => None,
        }
    }
}

fn params(args: &Args, fps: f64) -> Result<TrackParams, UsageError> {
    if args.particles == 0 {
        return Err(UsageError("--particles 0: a filter needs at least 1 particle".into()));
    }
    if args.lookahead == 0 {
        return Err(UsageError("--lookahead 0: the bending cone needs at least 1 prediction".into()));
    }
    if (1..MIN_WORK_WIDTH).contains(&args.work_size) {
        return Err(UsageError(format!(
            "--work-size {}: frames reduced below {MIN_WORK_WIDTH} pixels wide show no limbs; give {MIN_WORK_WIDTH} \
             or more, or 0 for the frames' own size",
            args.work_size
        )));
    }
    if let Some(fps) = args.fps
        && !(fps.is_finite() && fps > 0.0 && fps <= 1000.0)
    {
        return Err(UsageError(format!("--fps {fps}: must be above 0 and at most 1000")));
    }
    if let Some(h) = args.height
        && !(h >= HEIGHT_M.0 && h <= HEIGHT_M.1)
    {
        return Err(UsageError(format!("--height {h}: a person's height is {} to {} m", HEIGHT_M.0, HEIGHT_M.1)));
    }
    if let Some(fov) = args.fov
        && !(fov >= FOV_DEG.0 && fov <= FOV_DEG.1)
    {
        return Err(UsageError(format!(
            "--fov {fov}: a vertical field of view is {} to {} degrees",
            FOV_DEG.0, FOV_DEG.1
        )));
    }
    if let Some(focal) = args.focal
        && !(focal.is_finite() && focal > 0.0)
    {
        return Err(UsageError(format!("--focal {focal}: a focal length is a positive number of pixels")));
    }
    if args.keypoints.is_none() && args.observe.is_some_and(|o| o != Observe::Silhouette) {
        return Err(UsageError("--observe keypoints or both: give the keypoints with --keypoints FILE".into()));
    }
    let recognition = if args.feedback { Recognition::FEEDBACK } else { Recognition::Likelihood };
    let filter = FilterParams::standard(args.particles, args.lookahead, 1.0 / fps);
    let calibration = (!args.no_calibrate).then(|| CalibrationParams::standard(args.height));
    let open_set = OpenSet { min_fit: args.unexplained_below, ..OpenSet::STANDARD };
    open_set.check().map_err(|e| UsageError(format!("--unexplained-below {}: {e}", args.unexplained_below)))?;
    Ok(TrackParams { filter, recognition, calibration, open_set, seed: args.seed })
}

/// The camera given (`--camera`, or the camera.json beside the frames) and
/// where it came from, or `None` when it is to be estimated.
fn given_camera(args: &Args, source: &FrameSource) -> anyhow::Result<Option<(Camera, String)>> {
    let given = match (args.camera.as_deref(), beside_frames(&args.input, "camera.json")) {
        (Some("auto"), _) | (None, None) => None,
        (Some(choice), _) => Some((camera(choice, source.width() as u32, source.height() as u32)?, choice.to_string())),
        (None, Some(path)) => Some((Camera::read(&path)?, path.display().to_string())),
    };
    let Some((camera, from)) = given else { return Ok(None) };
    if args.fov.is_some() || args.focal.is_some() {
        return Err(UsageError(format!(
            "--fov and --focal set an estimated camera's focal length, but this run's camera is given ({from}); \
             drop them, or pass --camera auto"
        ))
        .into());
    }
    source.check_size(camera.width(), camera.height())?;
    Ok(Some((camera, from)))
}

/// The narrowest working width: a standing person is then about 10 pixels
/// tall, a limb a fraction of one.
const MIN_WORK_WIDTH: usize = 32;

/// The width silhouettes are reduced to for comparing cameras.
const PROBE_WIDTH: usize = 160;

/// Reads silhouettes into `pending` until the calibration window's
/// seconds of the person, with enough whole frames, are in (or it gives
/// up), and estimates the camera from the whole ones.
fn estimate_camera(
    args: &Args,
    silhouettes: &mut Silhouettes,
    vocabulary: &Arc<Vocabulary>,
    params: TrackParams,
    person: Person,
    pending: &mut Vec<Mask>,
) -> anyhow::Result<(Camera, CameraEstimate)> {
    let fps = 1.0 / params.filter.frame_time_s;
    let window = CalibrationParams::standard(None);
    let (width, height) = silhouettes.size();
    let mut standings = Vec::new();
    let mut first_seen: Option<usize> = None;
    loop {
        let seen_s = first_seen.map_or(0.0, |first| (pending.len() - first) as f64 / fps);
        if (seen_s >= window.window_s && standings.len() >= window.min_frames) || seen_s > window.give_up_s {
            break;
        }
        let mut mask = Mask::new(width, height);
        let Some(read) = silhouettes.next_into(&mut mask) else { break };
        read?;
        if mask.count() > 0 {
            first_seen.get_or_insert(pending.len());
        }
        standings.extend(Standing::measure(&mask));
        pending.push(mask);
    }
    let focal = match (args.fov, args.focal) {
        (Some(deg), _) => Focal::Fov(deg),
        // --focal is in the frames' own pixels.
        (None, Some(px)) => Focal::Pixels(px * width as f64 / silhouettes.source().width() as f64),
        (None, None) => Focal::Assumed,
    };
    // Cameras are compared on the silhouettes reduced to the paper's 160
    // pixels wide: the ranking needs the body's outline, not its fingers,
    // and each camera tracks every frame of the window.
    let probe_size = work_size(width, height, PROBE_WIDTH);
    let probes: Vec<Mask> = pending.iter().map(|m| shrink_mask(m, probe_size)).collect();
    let judge = &mut |camera: &Camera| {
        auto_camera::explained(vocabulary, &camera.resized(probe_size.0, probe_size.1), &probes, params)
    };
    auto_camera::estimate(width, height, &standings, person, focal, judge).map_err(|e| {
        UsageError(format!(
            "{}: {e} (looked at the first {} s of the person); pass --camera (a preset or a camera.json)",
            args.input.display(),
            window.give_up_s
        ))
        .into()
    })
}

/// The header of `frames.csv`.
fn header(names: &[&str]) -> String {
    let mut columns: Vec<String> = ["frame", "time_s", "activity"].map(String::from).to_vec();
    columns.extend(names.iter().map(|n| format!("prob_{n}")));
    columns.extend(names.iter().map(|n| format!("progress_{n}")));
    columns.extend(["root_x", "root_y", "root_z", "root_heading"].map(String::from));
    columns.extend(truth::position_columns());
    columns.extend(["unexplained", "fit_silhouette", "fit_keypoints"].map(String::from));
    columns.iter().map(|c| truth::quoted(c)).collect::<Vec<_>>().join(",") + "\n"
}

/// The header of `likelihoods.csv`.
fn likelihood_header(names: &[&str]) -> String {
    let columns = std::iter::once("frame".to_string())
        .chain(names.iter().map(|n| format!("likelihood_{n}")))
        .chain(names.iter().map(|n| format!("evidence_{n}")));
    columns.map(|c| truth::quoted(&c)).collect::<Vec<_>>().join(",") + "\n"
}

/// One frame's row of `likelihoods.csv`: each primitive's estimate's R
/// (eq. 8), then each one's evidence, empty on a frame observed by neither
/// silhouette nor keypoints.
fn likelihood_row(frame: usize, estimate: &FrameEstimate) -> String {
    let mut line = frame.to_string();
    let (estimates, evidence) = (estimate.estimates.iter(), estimate.estimates.iter().map(|e| e.evidence));
    for r in estimates.map(|e| e.likelihood).chain(evidence) {
        line.push(',');
        if let Some(r) = r {
            write!(line, "{r}").expect("writing to a string cannot fail");
        }
    }
    line.push('\n');
    line
}

/// One frame's row of `frames.csv`: `pose`, and the primitives' view of
/// it when they tracked (the baseline leaves those columns empty).
fn row(
    frame: usize,
    time_s: f64,
    names: &[&str],
    pose: &Pose,
    estimate: Option<&FrameEstimate>,
    body: &Body,
) -> String {
    let mut line = format!("{frame},{time_s},");
    let probabilities = estimate.and_then(|e| e.probabilities.as_ref());
    if let (Some(e), Some(_)) = (estimate, probabilities) {
        line.push_str(&truth::quoted(names[e.winner]));
    }
    for i in 0..names.len() {
        line.push(',');
        if let Some(p) = probabilities {
            write!(line, "{}", p[i]).expect("writing to a string cannot fail");
        }
    }
    for i in 0..names.len() {
        line.push(',');
        if let Some(e) = estimate {
            write!(line, "{}", e.estimates[i].progress).expect("writing to a string cannot fail");
        }
    }
    let world = body.forward(pose);
    let numbers = [pose.root.x, pose.root.y, pose.root.z, pose.heading]
        .into_iter()
        .chain(Joint::ALL.iter().flat_map(|&j| world.position(j).to_array()));
    for v in numbers {
        write!(line, ",{v}").expect("writing to a string cannot fail");
    }
    line.push(',');
    if let Some(e) = estimate.filter(|e| e.fit.is_some()) {
        line.push_str(if e.unexplained { "1" } else { "0" });
    }
    let fit = estimate.and_then(|e| e.fit);
    for part in [fit.and_then(|f| f.silhouette), fit.and_then(|f| f.keypoints)].map(|s| s.map(|s| s.value())) {
        line.push(',');
        if let Some(v) = part {
            write!(line, "{v}").expect("writing to a string cannot fail");
        }
    }
    line.push('\n');
    line
}

/// What went wrong decoding a video that was still tracked: it ended more
/// than a frame short of the count its container states (one frame of slack:
/// containers round, and `running.avi` states 227 for its 226), its decoder
/// failed after the first frame, or the decoder reported damage it skipped.
#[derive(Debug, serde::Serialize)]
struct Decoding {
    frames_read: usize,
    frames_stated: Option<usize>,
    ended_early: bool,
    /// The decoder's own words: its error, or what it said of the damage.
    messages: Option<String>,
}

impl Decoding {
    /// `None` when the video was decoded whole without complaint.
    fn of(probe: &VideoProbe, frames_read: usize, silhouettes: &Silhouettes) -> Option<Decoding> {
        let failed = silhouettes.source().decoding_failed();
        let ended_early = failed.is_some() || probe.frames.is_some_and(|stated| frames_read + 1 < stated);
        let messages = failed.or(silhouettes.source().decoder_messages()).map(str::to_string);
        (ended_early || messages.is_some()).then_some(Decoding {
            frames_read,
            frames_stated: probe.frames,
            ended_early,
            messages,
        })
    }
}

impl std::fmt::Display for Decoding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.ended_early, self.frames_stated) {
            (true, Some(stated)) => {
                write!(f, "the file ended early: {} of the {stated} frames it states were read", self.frames_read)?
            }
            (true, None) => write!(f, "the file ended early: {} frames were read", self.frames_read)?,
            (false, _) => write!(f, "the decoder reported damage it skipped")?,
        }
        match self.messages.as_deref().and_then(|m| m.lines().next()) {
            Some(first) => write!(f, " ({first})"),
            None => Ok(()),
        }
    }
}

/// Where the frame rate came from.
#[derive(Clone, Copy, Debug, serde::Serialize)]
#[serde(rename_all = "snake_case")]
enum RateFrom {
    Option,
    Video,
    Truth,
    Default,
}

/// The frames' rate: `--fps`, else a video's own, else (a folder) the
/// rate of the truth.csv `render` wrote beside it, else 15 (the paper's
/// camera).
fn frame_rate(args: &Args, probe: Option<&VideoProbe>) -> anyhow::Result<(f64, RateFrom)> {
    if let Some(fps) = args.fps {
        return Ok((fps, RateFrom::Option));
    }
    if let Some(probe) = probe {
        return match probe.rate {
            Some(fps) if fps <= 1000.0 => Ok((fps, RateFrom::Video)),
            Some(fps) => Err(UsageError(format!(
                "{}: the video states {fps} frames a second, more than 1000; pass --fps",
                args.input.display()
            ))
            .into()),
            None => {
                Err(UsageError(format!("{}: the video states no frame rate; pass --fps", args.input.display())).into())
            }
        };
    }
    if let Some(truth) = beside_frames(&args.input, "truth.csv")
        && let Some(fps) = truth::frame_rate(&truth)?
    {
        return Ok((fps, RateFrom::Truth));
    }
    Ok((DEFAULT_FPS, RateFrom::Default))
}

/// A folder's frame rate when nothing says otherwise: the paper's camera's.
const DEFAULT_FPS: f64 = 15.0;

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    // The options are checked before any file is read; the settings are
    // made once the frames' rate is known.
    params(&args, DEFAULT_FPS)?;
    refuse_nonempty(&args.output, args.force)?;
    let vocabulary = Arc::new(Vocabulary::load(&args.vocab)?);
    let source = FrameSource::open(&args.input, Expect::Auto)?;
    let probe = if source.is_video() { Some(probe_video(&args.input)?) } else { None };
    let (fps, rate_from) = frame_rate(&args, probe.as_ref())?;
    let mut params = params(&args, fps)?;
    let mut given = given_camera(&args, &source)?;
    let frame_size = (source.width(), source.height());
    let work = work_size(frame_size.0, frame_size.1, args.work_size);
    // A given camera is written back as it was given, byte for byte.
    let given_as_is = given.as_ref().map(|(camera, _)| camera.clone());
    if let Some((camera, _)) = &mut given {
        *camera = camera.resized(work.0, work.1);
    }
    let observe = args.observe.unwrap_or(if args.keypoints.is_some() { Observe::Both } else { Observe::Silhouette });
    let (keypoints, keypoints_report) = match &args.keypoints {
        Some(path) => {
            let mut keypoints = Keypoints::read(path)?;
            let outside = keypoints.fit_to(source.width(), source.height())?;
            let report = serde_json::json!({
                "path": path.display().to_string(),
                "layout": keypoints.layout.map(|l| l.name()),
                "frames": keypoints.frames.len(),
                "points_dropped": keypoints.dropped,
                "points_outside_frames": outside,
            });
            keypoints.rescale(frame_size, work);
            (Some(keypoints), Some(report))
        }
        None => (None, None),
    };
    let keypoints_of = |k: usize| {
        keypoints.as_ref().and_then(|kp| kp.frames.get(k)).filter(|points| points.iter().any(Option::is_some))
    };
    // The timing includes estimating the camera.
    let started = Instant::now();
    let mut silhouettes = Silhouettes::new(&args.input, source, args.background.clone(), args.work_size);
    let mut pending = Vec::new();
    let (camera, camera_estimate) = match &given {
        Some((camera, _)) => (camera.clone(), None),
        None => {
            let height = args.height.unwrap_or_else(|| Body::standard().standing_height());
            let person = Person::of(&Body::of_shares(height, 1.0, 1.0), args.height.is_some());
            // One camera cannot tell a tall person far away from a short
            // one near: the height the scene was scaled to is held.
            if args.height.is_none() {
                params.calibration = params.calibration.map(|c| c.holding_camera_height(height));
            }
            let (camera, estimate) =
                estimate_camera(&args, &mut silhouettes, &vocabulary, params, person, &mut pending)?;
            (camera, Some(estimate))
        }
    };
    let tracker = Tracker::new(Arc::clone(&vocabulary), camera.clone(), params)
        .with_context(|| args.vocab.display().to_string())?;
    let anneal = AnnealParams::with_budget(vocabulary.primitives().len() * params.filter.evaluations_per_frame());
    let mut follower = match args.baseline {
        None => Follower::Primitives(Box::new(tracker)),
        Some(Baseline::FullSpace) => {
            let start = mean_training_pose(&vocabulary);
            Follower::FullSpace(Box::new(FullSpaceFilter::new(camera.clone(), anneal, start, args.seed)))
        }
    };
    let names: Vec<&str> = vocabulary.primitives().iter().map(|p| p.name()).collect();
    let bar = progress(global, silhouettes.source().frame_count().unwrap_or(0) as u64, "track");
    let mut mask = Mask::new(camera.width(), camera.height());
    let (mut rows, mut likelihood_rows, mut poses, mut coasted) = (Vec::new(), Vec::new(), Vec::new(), 0usize);
    let mut unexplained = 0usize;
    let mut k = 0;
    // The frames the camera was estimated from first, then the rest.
    let mut pending = pending.into_iter();
    loop {
        let read = match pending.next() {
            Some(frame) => {
                mask = frame;
                Some(Ok(()))
            }
            None => silhouettes.next_into(&mut mask),
        };
        let Some(read) = read else { break };
        read?;
        // A given camera must see the person's feet below its horizon on
        // the first frame that shows them.
        if let Some((_, from)) = given.take_if(|_| mask.count() > 0)
            && !Root::feet_below_horizon(&camera, &mask)
        {
            bail!(
                "{from}: the camera sees the person's feet above its horizon in {}: it looks away from the floor \
                 they stand on (check its `look_at` and `up`)",
                args.input.display()
            );
        }
        if !observe.silhouette() {
            mask.clear();
        }
        let seen = if observe == Observe::Silhouette { None } else { keypoints_of(k) };
        let (pose, estimate) = follower.step(&mask, seen);
        coasted += usize::from(mask.count() == 0 && seen.is_none());
        rows.push(row(k, k as f64 / fps, &names, &pose, estimate.as_ref(), follower.body()));
        if let Some(e) = &estimate {
            likelihood_rows.push(likelihood_row(k, e));
            unexplained += usize::from(e.unexplained);
        }
        poses.push(pose);
        bar.inc(1);
        k += 1;
    }
    bar.finish_and_clear();
    if k == 0 {
        bail!("{}: no frames", args.input.display());
    }
    let decoding = probe.and_then(|probe| Decoding::of(&probe, k, &silhouettes));
    if let Some(decoding) = &decoding {
        note(global, &format!("{}: warning: {decoding}; the {k} frames read were tracked", args.input.display()));
    }
    if let Some(keypoints) = &keypoints {
        // Keypoints of the damaged copy end where it does; those of the
        // whole video run on to the count it states.
        let stated = decoding.as_ref().filter(|d| d.ended_early).and_then(|d| d.frames_stated);
        keypoints.check_frames(k).or_else(|e| stated.map_or(Err(e), |n| keypoints.check_frames(n)))?;
    }
    let seconds = started.elapsed().as_secs_f64();
    let evaluations = follower.evaluations() + camera_estimate.as_ref().map_or(0, |e| e.evaluations);
    // The camera in the frames' own pixels, as the user's files are.
    let seen_camera = given_as_is.unwrap_or_else(|| camera.resized(frame_size.0, frame_size.1));
    let motion = Motion { body: follower.body().clone(), frame_time_s: 1.0 / fps, poses };
    let summary = serde_json::json!({
        "input": args.input.display().to_string(),
        "vocabulary": {
            "path": args.vocab.display().to_string(),
            "checksum": vocabulary.checksum().map(|c| format!("{c:08x}")),
        },
        "primitives": vocabulary.primitives().iter().map(|p| serde_json::json!({
            "name": p.name(), "label": p.majority_label(), "dims": p.dims(),
        })).collect::<Vec<_>>(),
        "camera": seen_camera.spec(),
        "work_size": [work.0, work.1],
        "camera_estimate": camera_estimate,
        "body": follower.calibration(),
        "background": silhouettes.background_used(),
        "settings": params,
        "observe": observe,
        "keypoints": keypoints_report,
        "baseline": args.baseline.map(|_| serde_json::json!({ "kind": "full_space", "settings": anneal })),
        "seed": args.seed,
        "fps": fps,
        "fps_from": rate_from,
        "frames": k,
        "decoding": decoding,
        "coasted_frames": coasted,
        "unexplained_frames": args.baseline.is_none().then_some(unexplained),
        "unusable_silhouettes": silhouettes.unusable(),
        "likelihood_evaluations": evaluations,
        "likelihood_evaluations_per_frame": evaluations as f64 / k as f64,
        "timing": { "seconds": seconds, "frames_per_second": k as f64 / seconds },
    });
    let output = args.output.display().to_string();
    let io = |e: std::io::Error| anyhow::anyhow!("{output}: cannot write: {e}");
    write_dir_atomic(
        &args.output,
        |dir| {
            std::fs::write(dir.join("camera.json"), seen_camera.to_json()).map_err(io)?;
            write_atomic(&dir.join("trajectory.bvh"), |w| write_bvh(&motion.to_bvh(), w)).map_err(io)?;
            write_atomic(&dir.join("frames.csv"), |w| {
                w.write_all(header(&names).as_bytes())?;
                rows.iter().try_for_each(|r| w.write_all(r.as_bytes()))
            })
            .map_err(io)?;
            if !likelihood_rows.is_empty() {
                write_atomic(&dir.join("likelihoods.csv"), |w| {
                    w.write_all(likelihood_header(&names).as_bytes())?;
                    likelihood_rows.iter().try_for_each(|r| w.write_all(r.as_bytes()))
                })
                .map_err(io)?;
            }
            let json = serde_json::to_string_pretty(&summary).expect("the summary serializes") + "\n";
            std::fs::write(dir.join("summary.json"), json).map_err(io)
        },
        io,
    )?;
    let who = match args.baseline {
        None => format!("{} primitives × {} particles", names.len(), args.particles),
        Some(Baseline::FullSpace) => {
            format!("full-space annealed filter, {} layers × {} particles", anneal.layers, anneal.particles)
        }
    };
    note(
        global,
        &format!(
            "{}: {k} frames ({coasted} without a silhouette or keypoints), {who} → {output} in {seconds:.2} s ({:.1} frames/s, {:.0} likelihoods/frame)",
            args.input.display(),
            k as f64 / seconds,
            evaluations as f64 / k as f64
        ),
    );
    Ok(Outcome::Success)
}
