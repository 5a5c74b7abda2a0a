//! Tracking a whole clip: frames (a folder of images or a video) and a
//! vocabulary in, the run folder out ([`crate::track::run`]). What
//! `imitate track` and Python's `imitate.track` run.

use crate::fsutil::{NotEmpty, refuse_nonempty, write_atomic, write_dir_atomic};
use crate::mocap::body::Body;
use crate::mocap::bvh::write_bvh;
use crate::mocap::pose::{Motion, Pose};
use crate::params::{InvalidField, Params};
use crate::track::auto_camera::{self, AutoCameraError, CameraEstimate, FOV_DEG, Focal, Person, Standing};
use crate::track::baseline::{AnnealParams, FullSpaceFilter, mean_training_pose};
use crate::track::calibrate::{CalibrationParams, CalibrationReport, HEIGHT_M};
use crate::track::filter::FilterParams;
use crate::track::open_set::OpenSet;
use crate::track::root::Root;
use crate::track::run::{
    RunPrimitive, RunSummary, Timing, VocabularyRef, frames_header, frames_row, likelihoods_header, likelihoods_row,
};
use crate::track::tracker::{FrameEstimate, Recognition, TrackError, TrackParams, TrackParamsError, Tracker};
use crate::vision::camera::{Camera, CameraError, Preset};
use crate::vision::frames::{Expect, FrameError, FrameSource, beside_frames};
use crate::vision::keypoints::{Keypoints, KeypointsError, SitePoints};
use crate::vision::mask::Mask;
use crate::vision::resize::{DEFAULT_WORK_WIDTH, shrink_mask, work_size};
use crate::vision::silhouette::{SilhouetteError, Silhouettes};
use crate::vision::truth::{self, TruthError};
use crate::vision::video::{VideoError, VideoProbe, probe_video};
use crate::vocab::vocabulary::{VocabError, Vocabulary};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// The camera a clip is seen through.
#[derive(Clone, Debug)]
pub enum CameraChoice {
    /// The camera.json `render` wrote beside the frames (in the input or
    /// its parent folder), else [`CameraChoice::Auto`].
    Beside,
    /// Estimated from the first seconds of silhouettes and the person's
    /// height.
    Auto,
    /// A preset placement, framed at the frames' size.
    Preset(Preset),
    /// A camera given whole; `from` says where it came from, for messages.
    Given { camera: Box<Camera>, from: String },
}

/// What follows the person instead of the primitives' filters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Baseline {
    /// One annealed particle filter over every joint angle and the root
    /// (Deutscher, Blake & Reid 2000), spending as many likelihood
    /// evaluations per frame as the primitives' filters would.
    FullSpace,
}

/// What the filters score each frame by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Observe {
    Silhouette,
    Keypoints,
    Both,
}

/// How a clip is tracked; [`Default`] is `imitate track`'s defaults.
#[derive(Clone, Debug)]
pub struct ClipOptions {
    pub camera: CameraChoice,
    /// An estimated camera's focal length, when known ([`Focal::Pixels`]
    /// in the frames' own pixels).
    pub focal: Focal,
    pub particles: usize,
    /// K of the bending cone (eq. 6).
    pub lookahead: usize,
    pub seed: u64,
    /// Recognize with eq. 10 instead of eq. 7.
    pub feedback: bool,
    /// Frames per second; `None`: a video's own, a folder's truth.csv's,
    /// else 15.
    pub fps: Option<f64>,
    /// The person's standing height, when known.
    pub height_m: Option<f64>,
    /// Fit the person's build to the first seconds; `false` draws the
    /// canonical body throughout.
    pub calibrate: bool,
    /// The empty scene, for color frames.
    pub background: Option<PathBuf>,
    /// The width frames are reduced to (0: their own size).
    pub work_width: usize,
    pub baseline: Option<Baseline>,
    /// 2-D keypoints of the same frames (docs/formats.md, "Keypoints").
    pub keypoints: Option<PathBuf>,
    /// Default: both with keypoints, else the silhouette.
    pub observe: Option<Observe>,
    /// The open set's threshold ([`OpenSet::min_fit`]).
    pub unexplained_below: f64,
}

impl Default for ClipOptions {
    fn default() -> ClipOptions {
        ClipOptions {
            camera: CameraChoice::Beside,
            focal: Focal::Assumed,
            particles: 6,
            lookahead: 5,
            seed: 0,
            feedback: false,
            fps: None,
            height_m: None,
            calibrate: true,
            background: None,
            work_width: DEFAULT_WORK_WIDTH,
            baseline: None,
            keypoints: None,
            observe: None,
            unexplained_below: OpenSet::STANDARD.min_fit,
        }
    }
}

/// The narrowest working width: a standing person is then about 10 pixels
/// tall, a limb a fraction of one.
pub const MIN_WORK_WIDTH: usize = 32;

/// The width silhouettes are reduced to for comparing cameras.
const PROBE_WIDTH: usize = 160;

/// A folder's frame rate when nothing says otherwise: the paper's camera's.
pub const DEFAULT_FPS: f64 = 15.0;

/// A clip option out of range or at odds with another.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ClipOptionsError {
    #[error(
        "work_width: frames reduced below {MIN_WORK_WIDTH} pixels wide show no limbs; give {MIN_WORK_WIDTH} or more, \
         or 0 for the frames' own size, not {0}"
    )]
    WorkWidth(usize),
    #[error("fps: must be above 0 and at most 1000, not {0}")]
    Fps(f64),
    #[error("height_m: a person's height is {low} to {high} m, not {0}", low = HEIGHT_M.0, high = HEIGHT_M.1)]
    Height(f64),
    #[error("focal: a vertical field of view is {low} to {high} degrees, not {0}", low = FOV_DEG.0, high = FOV_DEG.1)]
    Fov(f64),
    #[error("focal: a focal length is a positive number of pixels, not {0}")]
    FocalPixels(f64),
    #[error("observe: keypoints are observed only when they are given")]
    ObserveWithoutKeypoints,
    #[error("height_m: the height is what calibration holds, and calibration is off")]
    HeightWithoutCalibration,
    #[error("keypoints: the baseline observes the silhouette only")]
    KeypointsWithBaseline,
    #[error("height_m: the baseline draws the canonical body")]
    HeightWithBaseline,
    #[error("{}", .0.naming(tracker_field(.0)))]
    Tracker(TrackParamsError),
}

/// The clip option a tracker setting comes from.
fn tracker_field(e: &TrackParamsError) -> &'static str {
    match e.field() {
        "min_fit" => "unexplained_below",
        "frame_time_s" => "fps",
        field => field,
    }
}

impl InvalidField for ClipOptionsError {
    fn field(&self) -> &'static str {
        match self {
            ClipOptionsError::WorkWidth(_) => "work_width",
            ClipOptionsError::Fps(_) => "fps",
            ClipOptionsError::Height(_)
            | ClipOptionsError::HeightWithoutCalibration
            | ClipOptionsError::HeightWithBaseline => "height_m",
            ClipOptionsError::Fov(_) | ClipOptionsError::FocalPixels(_) => "focal",
            ClipOptionsError::ObserveWithoutKeypoints => "observe",
            ClipOptionsError::KeypointsWithBaseline => "keypoints",
            ClipOptionsError::Tracker(e) => tracker_field(e),
        }
    }
}

impl Params for ClipOptions {
    type Valid = TrackParams;
    type Error = ClipOptionsError;

    /// The tracker's settings at the options' frame rate (else
    /// [`DEFAULT_FPS`]: the rate is checked again once the frames say it).
    fn check(&self) -> Result<TrackParams, ClipOptionsError> {
        self.track_params(self.fps.unwrap_or(DEFAULT_FPS))
    }
}

impl ClipOptions {
    fn track_params(&self, fps: f64) -> Result<TrackParams, ClipOptionsError> {
        if (1..MIN_WORK_WIDTH).contains(&self.work_width) {
            return Err(ClipOptionsError::WorkWidth(self.work_width));
        }
        if let Some(fps) = self.fps
            && !(fps.is_finite() && fps > 0.0 && fps <= 1000.0)
        {
            return Err(ClipOptionsError::Fps(fps));
        }
        if let Some(h) = self.height_m {
            if !(h >= HEIGHT_M.0 && h <= HEIGHT_M.1) {
                return Err(ClipOptionsError::Height(h));
            }
            if self.baseline.is_some() {
                return Err(ClipOptionsError::HeightWithBaseline);
            }
            if !self.calibrate {
                return Err(ClipOptionsError::HeightWithoutCalibration);
            }
        }
        match self.focal {
            Focal::Fov(deg) if !(deg >= FOV_DEG.0 && deg <= FOV_DEG.1) => return Err(ClipOptionsError::Fov(deg)),
            Focal::Pixels(px) if !(px.is_finite() && px > 0.0) => return Err(ClipOptionsError::FocalPixels(px)),
            _ => {}
        }
        if self.keypoints.is_some() && self.baseline.is_some() {
            return Err(ClipOptionsError::KeypointsWithBaseline);
        }
        if self.keypoints.is_none() && self.observe.is_some_and(|o| o != Observe::Silhouette) {
            return Err(ClipOptionsError::ObserveWithoutKeypoints);
        }
        let recognition = if self.feedback { Recognition::FEEDBACK } else { Recognition::Likelihood };
        let filter = FilterParams::standard(self.particles, self.lookahead, 1.0 / fps);
        let calibration = self.calibrate.then(|| CalibrationParams::standard(self.height_m));
        let open_set = OpenSet { min_fit: self.unexplained_below, ..OpenSet::STANDARD };
        TrackParams { filter, recognition, calibration, open_set, seed: self.seed }
            .check()
            .map_err(ClipOptionsError::Tracker)
    }

    fn observe(&self) -> Observe {
        self.observe.unwrap_or(if self.keypoints.is_some() { Observe::Both } else { Observe::Silhouette })
    }
}

/// Why a clip could not be tracked. [`ClipError::option`] names the
/// option that is at fault or would settle it.
#[derive(Debug, thiserror::Error)]
pub enum ClipError {
    #[error(transparent)]
    Options(#[from] ClipOptionsError),
    #[error(transparent)]
    Vocabulary(#[from] VocabError),
    #[error(transparent)]
    Frames(#[from] FrameError),
    #[error(transparent)]
    Video(#[from] VideoError),
    #[error(transparent)]
    Silhouettes(#[from] SilhouetteError),
    #[error(transparent)]
    Keypoints(#[from] KeypointsError),
    #[error(transparent)]
    Camera(#[from] CameraError),
    #[error(transparent)]
    Truth(#[from] TruthError),
    #[error("{input}: the video states {fps} frames a second, more than 1000; give the frame rate")]
    RateTooHigh { input: String, fps: f64 },
    #[error("{input}: the video states no frame rate; give the frame rate")]
    NoRate { input: String },
    #[error(
        "a focal length or field of view is for a camera to be estimated, but this run's camera is given ({from}); \
         drop it, or ask for the camera to be estimated"
    )]
    FocalWithCamera { from: String },
    #[error("{input}: {source} (looked at the first {seconds} s of the person); give the camera")]
    NoCamera { input: String, source: AutoCameraError, seconds: f64 },
    #[error(
        "{from}: the camera sees the person's feet above its horizon in {input}: it looks away from the floor they \
         stand on (check its `look_at` and `up`)"
    )]
    LooksAway { from: String, input: String },
    #[error("{0}: no frames")]
    NoFrames(String),
    #[error("{vocab}: {source}")]
    Tracker { vocab: String, source: TrackError },
    #[error(transparent)]
    NotEmpty(#[from] NotEmpty),
    #[error("{dir}: cannot write: {source}")]
    Write { dir: String, source: std::io::Error },
}

impl ClipError {
    /// The option at fault, or the one that would settle it: a front-end
    /// names its own for it.
    pub fn option(&self) -> Option<&'static str> {
        match self {
            ClipError::Options(e) => Some(e.field()),
            ClipError::RateTooHigh { .. } | ClipError::NoRate { .. } => Some("fps"),
            ClipError::FocalWithCamera { .. } => Some("focal"),
            ClipError::NoCamera { .. } => Some("camera"),
            _ => None,
        }
    }
}

/// How far tracking has come: frames done, of how many when known.
#[derive(Clone, Copy, Debug)]
pub struct ClipProgress {
    pub done: usize,
    pub total: Option<usize>,
}

/// What went wrong decoding a video that was still tracked: it ended more
/// than a frame short of the count its container states (one frame of slack:
/// containers round, and `running.avi` states 227 for its 226), its decoder
/// failed after the first frame, or the decoder reported damage it skipped.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Decoding {
    pub frames_read: usize,
    pub frames_stated: Option<usize>,
    pub ended_early: bool,
    /// The decoder's own words: its error, or what it said of the damage.
    pub messages: Option<String>,
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

/// A tracked clip, ready to be written as a run folder.
pub struct TrackedClip {
    pub summary: RunSummary,
    /// The camera in the frames' own pixels (a given one as given).
    pub camera: Camera,
    /// The virtual trajectory.
    pub motion: Motion,
    /// Set when the video was damaged; its frames read were tracked.
    pub decoding: Option<Decoding>,
    /// What followed the person, for messages: the primitives' filters
    /// (`None`), or the baseline's layers × particles.
    pub baseline_size: Option<(usize, usize)>,
    frames_rows: Vec<String>,
    likelihood_rows: Vec<String>,
}

impl TrackedClip {
    /// The primitives' names, in the tables' order.
    pub fn names(&self) -> Vec<&str> {
        self.summary.primitives.iter().map(|p| p.name.as_str()).collect()
    }

    /// `frames.csv`'s text.
    pub fn frames_csv(&self) -> String {
        frames_header(&self.names()) + &self.frames_rows.concat()
    }

    /// Writes the run folder, replacing `dir` whole when `force`; a folder
    /// that holds something is refused otherwise. Nothing is left half
    /// written.
    pub fn write(&self, dir: &Path, force: bool) -> Result<(), ClipError> {
        refuse_nonempty(dir, force)?;
        let label = dir.display().to_string();
        let io = |source: std::io::Error| ClipError::Write { dir: label.clone(), source };
        let names = self.names();
        write_dir_atomic(
            dir,
            |dir| {
                std::fs::write(dir.join("camera.json"), self.camera.to_json()).map_err(io)?;
                write_atomic(&dir.join("trajectory.bvh"), |w| write_bvh(&self.motion.to_bvh(), w)).map_err(io)?;
                write_atomic(&dir.join("frames.csv"), |w| {
                    w.write_all(frames_header(&names).as_bytes())?;
                    self.frames_rows.iter().try_for_each(|r| w.write_all(r.as_bytes()))
                })
                .map_err(io)?;
                if !self.likelihood_rows.is_empty() {
                    write_atomic(&dir.join("likelihoods.csv"), |w| {
                        w.write_all(likelihoods_header(&names).as_bytes())?;
                        self.likelihood_rows.iter().try_for_each(|r| w.write_all(r.as_bytes()))
                    })
                    .map_err(io)?;
                }
                std::fs::write(dir.join("summary.json"), self.summary.to_json()).map_err(io)
            },
            io,
        )
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

/// The frames' rate: the option, else a video's own, else (a folder) the
/// rate of the truth.csv `render` wrote beside it, else [`DEFAULT_FPS`];
/// and where it came from.
fn frame_rate(
    input: &Path,
    options: &ClipOptions,
    probe: Option<&VideoProbe>,
) -> Result<(f64, &'static str), ClipError> {
    if let Some(fps) = options.fps {
        return Ok((fps, "option"));
    }
    let label = || input.display().to_string();
    if let Some(probe) = probe {
        return match probe.rate {
            Some(fps) if fps <= 1000.0 => Ok((fps, "video")),
            Some(fps) => Err(ClipError::RateTooHigh { input: label(), fps }),
            None => Err(ClipError::NoRate { input: label() }),
        };
    }
    if let Some(truth) = beside_frames(input, "truth.csv")
        && let Some(fps) = truth::frame_rate(&truth)?
    {
        return Ok((fps, "truth"));
    }
    Ok((DEFAULT_FPS, "default"))
}

/// The camera given (by the options, or the camera.json beside the
/// frames) and where it came from, or `None` when it is to be estimated.
fn given_camera(
    input: &Path,
    options: &ClipOptions,
    source: &FrameSource,
) -> Result<Option<(Camera, String)>, ClipError> {
    let given = match &options.camera {
        CameraChoice::Auto => None,
        CameraChoice::Beside => match beside_frames(input, "camera.json") {
            Some(path) => Some((Camera::read(&path)?, path.display().to_string())),
            None => None,
        },
        CameraChoice::Preset(preset) => {
            let camera = Camera::preset(*preset, source.width() as u32, source.height() as u32)?;
            Some((camera, preset.name().to_string()))
        }
        CameraChoice::Given { camera, from } => Some((camera.as_ref().clone(), from.clone())),
    };
    let Some((camera, from)) = given else { return Ok(None) };
    if options.focal != Focal::Assumed {
        return Err(ClipError::FocalWithCamera { from });
    }
    source.check_size(camera.width(), camera.height())?;
    Ok(Some((camera, from)))
}

/// Reads silhouettes into `pending` until the calibration window's
/// seconds of the person, with enough whole frames, are in (or it gives
/// up), and estimates the camera from the whole ones.
fn estimate_camera(
    input: &Path,
    options: &ClipOptions,
    silhouettes: &mut Silhouettes,
    vocabulary: &Arc<Vocabulary>,
    params: TrackParams,
    person: Person,
    pending: &mut Vec<Mask>,
) -> Result<(Camera, CameraEstimate), ClipError> {
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
    let focal = match options.focal {
        // A focal length is given in the frames' own pixels.
        Focal::Pixels(px) => Focal::Pixels(px * width as f64 / silhouettes.source().width() as f64),
        other => other,
    };
    // Cameras are compared on the silhouettes reduced to the paper's 160
    // pixels wide: the ranking needs the body's outline, not its fingers,
    // and each camera tracks every frame of the window.
    let probe_size = work_size(width, height, PROBE_WIDTH);
    let probes: Vec<Mask> = pending.iter().map(|m| shrink_mask(m, probe_size)).collect();
    let judge = &mut |camera: &Camera| {
        auto_camera::explained(vocabulary, &camera.resized(probe_size.0, probe_size.1), &probes, params)
    };
    auto_camera::estimate(width, height, &standings, person, focal, judge).map_err(|source| ClipError::NoCamera {
        input: input.display().to_string(),
        source,
        seconds: window.give_up_s,
    })
}

/// A section of `summary.json`.
fn json(section: &impl serde::Serialize) -> serde_json::Value {
    serde_json::to_value(section).expect("the summary serializes")
}

/// Tracks the clip at `input` (a folder of images or a video) with the
/// vocabulary read from `vocab_path`. `progress` hears of every frame.
pub fn track_clip(
    input: &Path,
    vocab_path: &Path,
    options: &ClipOptions,
    progress: &mut dyn FnMut(ClipProgress),
) -> Result<TrackedClip, ClipError> {
    // The options are checked before any file is read; the settings are
    // made once the frames' rate is known.
    options.check()?;
    let vocabulary = Vocabulary::load(vocab_path)?;
    track_clip_with(input, vocab_path, Arc::new(vocabulary), options, progress)
}

/// [`track_clip`] with a vocabulary already read from `vocab_path`.
pub fn track_clip_with(
    input: &Path,
    vocab_path: &Path,
    vocabulary: Arc<Vocabulary>,
    options: &ClipOptions,
    progress: &mut dyn FnMut(ClipProgress),
) -> Result<TrackedClip, ClipError> {
    options.check()?;
    let label = input.display().to_string();
    let source = FrameSource::open(input, Expect::Auto)?;
    let probe = if source.is_video() { Some(probe_video(input)?) } else { None };
    let (fps, rate_from) = frame_rate(input, options, probe.as_ref())?;
    let mut params = options.track_params(fps)?;
    let mut given = given_camera(input, options, &source)?;
    let frame_size = (source.width(), source.height());
    let work = work_size(frame_size.0, frame_size.1, options.work_width);
    // A given camera is written back as it was given, byte for byte.
    let given_as_is = given.as_ref().map(|(camera, _)| camera.clone());
    if let Some((camera, _)) = &mut given {
        *camera = camera.resized(work.0, work.1);
    }
    let observe = options.observe();
    let (keypoints, keypoints_report) = match &options.keypoints {
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
    let mut silhouettes = Silhouettes::new(input, source, options.background.clone(), options.work_width);
    let mut pending = Vec::new();
    let (camera, camera_estimate) = match &given {
        Some((camera, _)) => (camera.clone(), None),
        None => {
            let height = options.height_m.unwrap_or_else(|| Body::standard().standing_height());
            let person = Person::of(&Body::of_shares(height, 1.0, 1.0), options.height_m.is_some());
            // One camera cannot tell a tall person far away from a short
            // one near: the height the scene was scaled to is held.
            if options.height_m.is_none() {
                params.calibration = params.calibration.map(|c| c.holding_camera_height(height));
            }
            let (camera, estimate) =
                estimate_camera(input, options, &mut silhouettes, &vocabulary, params, person, &mut pending)?;
            (camera, Some(estimate))
        }
    };
    let vocab_label = vocab_path.display().to_string();
    let tracker = Tracker::new(Arc::clone(&vocabulary), camera.clone(), params)
        .map_err(|source| ClipError::Tracker { vocab: vocab_label.clone(), source })?;
    let anneal = AnnealParams::with_budget(vocabulary.primitives().len() * params.filter.evaluations_per_frame());
    let mut follower = match options.baseline {
        None => Follower::Primitives(Box::new(tracker)),
        Some(Baseline::FullSpace) => {
            let start = mean_training_pose(&vocabulary);
            Follower::FullSpace(Box::new(FullSpaceFilter::new(camera.clone(), anneal, start, options.seed)))
        }
    };
    let names: Vec<&str> = vocabulary.primitives().iter().map(|p| p.name()).collect();
    let total = silhouettes.source().frame_count();
    let mut mask = Mask::new(camera.width(), camera.height());
    let (mut frames_rows, mut likelihood_rows, mut poses, mut coasted) = (Vec::new(), Vec::new(), Vec::new(), 0usize);
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
            return Err(ClipError::LooksAway { from, input: label });
        }
        if observe == Observe::Keypoints {
            mask.clear();
        }
        let seen = if observe == Observe::Silhouette { None } else { keypoints_of(k) };
        let (pose, estimate) = follower.step(&mask, seen);
        coasted += usize::from(mask.count() == 0 && seen.is_none());
        frames_rows.push(frames_row(k, k as f64 / fps, &names, &pose, estimate.as_ref(), follower.body()));
        if let Some(e) = &estimate {
            likelihood_rows.push(likelihoods_row(k, e));
            unexplained += usize::from(e.unexplained);
        }
        poses.push(pose);
        k += 1;
        progress(ClipProgress { done: k, total });
    }
    if k == 0 {
        return Err(ClipError::NoFrames(label));
    }
    let decoding = probe.and_then(|probe| Decoding::of(&probe, k, &silhouettes));
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
    let summary = RunSummary {
        input: label,
        vocabulary: VocabularyRef { path: vocab_label, checksum: vocabulary.checksum().map(|c| format!("{c:08x}")) },
        primitives: vocabulary
            .primitives()
            .iter()
            .map(|p| RunPrimitive {
                name: p.name().to_string(),
                label: p.majority_label().map(str::to_string),
                dims: p.dims(),
            })
            .collect(),
        camera: seen_camera.spec().clone(),
        work_size: Some([work.0, work.1]),
        camera_estimate: camera_estimate.as_ref().map(json),
        body: follower.calibration().map(json),
        background: silhouettes.background_used().map(str::to_string),
        settings: json(&params),
        observe: Some(json(&observe)),
        keypoints: keypoints_report,
        baseline: options.baseline.map(|_| serde_json::json!({ "kind": "full_space", "settings": json(&anneal) })),
        seed: options.seed,
        fps,
        fps_from: Some(serde_json::Value::from(rate_from)),
        frames: k,
        decoding: decoding.as_ref().map(json),
        coasted_frames: coasted,
        unexplained_frames: options.baseline.is_none().then_some(unexplained),
        unusable_silhouettes: silhouettes.unusable(),
        likelihood_evaluations: evaluations,
        likelihood_evaluations_per_frame: evaluations as f64 / k as f64,
        timing: Timing { seconds, frames_per_second: k as f64 / seconds },
    };
    Ok(TrackedClip {
        summary,
        camera: seen_camera,
        motion,
        decoding,
        baseline_size: options.baseline.map(|_| (anneal.layers, anneal.particles)),
        frames_rows,
        likelihood_rows,
    })
}
