//! The run folder a tracked clip is written to, and read back from:
//! `frames.csv`, `likelihoods.csv`, `trajectory.bvh`, `camera.json` and
//! `summary.json` (docs/formats.md). [`RunSummary`] is the one type that
//! writes `summary.json` and reads it back.

use crate::mocap::body::{Body, Joint};
use crate::mocap::pose::Pose;
use crate::track::tracker::FrameEstimate;
use crate::vision::camera::CameraSpec;
use crate::vision::truth;
use std::fmt::Write as _;
use std::path::PathBuf;

/// `summary.json`: what was tracked, how, and what came of it. The
/// sections reports do not read (the camera's estimate, the body's
/// calibration, the settings) are kept as the JSON they were written as.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RunSummary {
    /// The frames tracked, as given.
    pub input: String,
    pub vocabulary: VocabularyRef,
    pub primitives: Vec<RunPrimitive>,
    /// The camera, in the frames' own pixels.
    pub camera: CameraSpec,
    /// The size frames were reduced to for tracking; absent in runs
    /// written before `--work-size`, which tracked at the camera's size.
    #[serde(default)]
    pub work_size: Option<[usize; 2]>,
    /// How the camera was estimated; `None` when it was given.
    #[serde(default)]
    pub camera_estimate: Option<serde_json::Value>,
    /// What calibration found; `None` for the baseline.
    #[serde(default)]
    pub body: Option<serde_json::Value>,
    /// The background color frames were compared with: an image's path,
    /// or what it was learned from.
    #[serde(default)]
    pub background: Option<String>,
    /// The tracker's settings, as written.
    pub settings: serde_json::Value,
    #[serde(default)]
    pub observe: Option<serde_json::Value>,
    #[serde(default)]
    pub keypoints: Option<serde_json::Value>,
    #[serde(default)]
    pub baseline: Option<serde_json::Value>,
    pub seed: u64,
    pub fps: f64,
    #[serde(default)]
    pub fps_from: Option<serde_json::Value>,
    pub frames: usize,
    #[serde(default)]
    pub decoding: Option<serde_json::Value>,
    #[serde(default)]
    pub coasted_frames: usize,
    /// Frames the open set reported unexplained; `None` for the baseline
    /// and runs written before the open set.
    #[serde(default)]
    pub unexplained_frames: Option<usize>,
    #[serde(default)]
    pub unusable_silhouettes: usize,
    #[serde(default)]
    pub likelihood_evaluations: u64,
    pub likelihood_evaluations_per_frame: f64,
    pub timing: Timing,
}

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct VocabularyRef {
    pub path: String,
    /// The file's checksum, hexadecimal.
    pub checksum: Option<String>,
}

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RunPrimitive {
    pub name: String,
    #[serde(default)]
    pub label: Option<String>,
    #[serde(default)]
    pub dims: usize,
}

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Timing {
    pub seconds: f64,
    pub frames_per_second: f64,
}

impl RunSummary {
    /// The background image the run was given, if it was one (and is still
    /// there), to make its silhouettes again.
    pub fn background_plate(&self) -> Option<PathBuf> {
        self.background.as_ref().map(PathBuf::from).filter(|p| p.is_file())
    }

    /// `summary.json`'s text: keys sorted at every level, as every JSON
    /// summary of the project is.
    pub fn to_json(&self) -> String {
        let value = serde_json::to_value(self).expect("the summary serializes");
        serde_json::to_string_pretty(&value).expect("the summary serializes") + "\n"
    }
}

/// The header of `frames.csv`.
pub fn frames_header(names: &[&str]) -> String {
    let mut columns: Vec<String> = ["frame", "time_s", "activity"].map(String::from).to_vec();
    columns.extend(names.iter().map(|n| format!("prob_{n}")));
    columns.extend(names.iter().map(|n| format!("progress_{n}")));
    columns.extend(["root_x", "root_y", "root_z", "root_heading"].map(String::from));
    columns.extend(truth::position_columns());
    columns.extend(["unexplained", "fit_silhouette", "fit_keypoints"].map(String::from));
    columns.iter().map(|c| truth::quoted(c)).collect::<Vec<_>>().join(",") + "\n"
}

/// The header of `likelihoods.csv`.
pub fn likelihoods_header(names: &[&str]) -> String {
    let columns = std::iter::once("frame".to_string())
        .chain(names.iter().map(|n| format!("likelihood_{n}")))
        .chain(names.iter().map(|n| format!("evidence_{n}")));
    columns.map(|c| truth::quoted(&c)).collect::<Vec<_>>().join(",") + "\n"
}

/// One frame's row of `likelihoods.csv`: each primitive's estimate's R
/// (eq. 8), then each one's evidence, empty on a frame observed by neither
/// silhouette nor keypoints.
pub fn likelihoods_row(frame: usize, estimate: &FrameEstimate) -> String {
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
pub fn frames_row(
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
