//! How well a tracking run followed the person: joint position errors,
//! limb direction errors, activity recognition and how quickly a switch of
//! activity is recognized, from the run's frames and the render's truth.

use crate::fsutil::{rounded, rounded_option};
use crate::mocap::body::{JOINTS, Joint};
use crate::mocap::pose::{Motion, Pose};
use crate::vocab::primitive::Primitive;
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// Why a run could not be scored. Every message names the file at fault.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{file}: cannot read: {source}")]
    Read { file: String, source: std::io::Error },
    #[error("{file}: no frames (the table has no rows)")]
    Empty { file: String },
    #[error("{file}: line {line}: a quoted field is never closed")]
    UnclosedQuote { file: String, line: usize },
    #[error("{file}: line {line}: {found} fields where the header has {expected}")]
    FieldCount { file: String, line: usize, found: usize, expected: usize },
    #[error("{file}: missing column `{column}`")]
    MissingColumn { file: String, column: String },
    #[error("{file}: line {line}, column `{column}`: expected {expected}, found {text:?}")]
    BadValue { file: String, line: usize, column: String, expected: &'static str, text: String },
    #[error("{file}: {message}")]
    Summary { file: String, message: String },
    #[error("{file}: primitive `{name}` is listed twice")]
    DuplicatePrimitive { file: String, name: String },
    #[error("{file}: frame {frame}: activity `{name}` is not one of the primitives in {summary}")]
    UnknownPrimitive { file: String, frame: u64, name: String, summary: String },
    #[error("{estimate} has {estimated} frames but {truth} has {truth_frames}: they must describe the same video")]
    FrameCount { estimate: String, estimated: usize, truth: String, truth_frames: usize },
    #[error(
        "row {row} is frame {estimated} in {estimate} but frame {truth_frame} in {truth}: rows must match frame by frame"
    )]
    FrameMismatch { estimate: String, estimated: u64, truth: String, truth_frame: u64, row: usize },
    #[error("{file}: frame {frame}: {from} and {to} are at the same place, so the bone has no direction")]
    DegenerateBone { file: String, frame: u64, from: &'static str, to: &'static str },
    /// It names its file itself.
    #[error(transparent)]
    Bvh(#[from] crate::mocap::bvh::BvhError),
}

/// A body's path through a video, one entry per frame: the columns that
/// `frames.csv` (the tracker's estimate) and `truth.csv` (the render's
/// truth) share.
#[derive(Debug, Clone)]
pub struct Track {
    /// The file it was read from, for messages.
    pub file: String,
    pub frame: Vec<u64>,
    pub time_s: Vec<f64>,
    /// The estimated primitive's name or the true activity; `None` when the
    /// field is empty (a coasting tracker, an unlabelled truth).
    pub activity: Vec<Option<String>>,
    /// `root_x`, `root_y`, `root_z`, meters.
    pub root: Vec<DVec3>,
    /// Every canonical joint's world position, meters, in [`Joint::ALL`] order.
    pub joints: Vec<[DVec3; JOINTS]>,
}

/// The run's primitives (from its `summary.json`): each name and the
/// activity label it stands for, `None` when no label has a majority of it.
#[derive(Debug, Clone)]
pub struct Primitives {
    pub file: String,
    pub labels: BTreeMap<String, Option<String>>,
}

/// The scores of one run. Errors are means over frames (and joints or
/// limbs); recognition counts frames whose true activity some primitive is
/// labelled with. Written to `metrics.json` with six decimals.
#[derive(Debug, Clone, Serialize)]
pub struct Metrics {
    pub frames: usize,
    /// Distance between the estimated and true root, mm.
    #[serde(serialize_with = "rounded")]
    pub root_mm: f64,
    /// Distance between estimated and true world positions, every joint, mm.
    #[serde(serialize_with = "rounded")]
    pub absolute_mm: f64,
    /// Root-relative (each joint minus the pelvis) error, every joint but the pelvis, mm.
    #[serde(serialize_with = "rounded")]
    pub all_joints_mm: f64,
    /// Root-relative error of the spine, chest, neck, head, shoulders, elbows and wrists, mm.
    #[serde(serialize_with = "rounded")]
    pub upper_body_mm: f64,
    /// Root-relative error of the wrists, mm.
    #[serde(serialize_with = "rounded")]
    pub hand_mm: f64,
    /// Angle between estimated and true bone directions, all eight limb bones, degrees.
    #[serde(serialize_with = "rounded")]
    pub limb_direction_deg: f64,
    pub limbs_deg: Limbs,
    #[serde(flatten)]
    pub recognition: Recognition,
}

/// Mean direction error of each kind of limb bone, left and right together, degrees.
#[derive(Debug, Clone, Serialize)]
pub struct Limbs {
    #[serde(serialize_with = "rounded")]
    pub upper_arm: f64,
    #[serde(serialize_with = "rounded")]
    pub forearm: f64,
    #[serde(serialize_with = "rounded")]
    pub thigh: f64,
    #[serde(serialize_with = "rounded")]
    pub shin: f64,
}

/// Which activity the tracker named, frame by frame, against the truth.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Recognition {
    /// Share of scored frames whose primitive's label is the true activity;
    /// `None` when no frame is scored.
    #[serde(serialize_with = "rounded_option")]
    pub recognition_accuracy: Option<f64>,
    /// The same, leaving out the frames within `settle_s` of a switch.
    #[serde(serialize_with = "rounded_option")]
    pub recognition_accuracy_settled: Option<f64>,
    #[serde(serialize_with = "rounded")]
    pub settle_s: f64,
    /// Frames whose true activity is the label of some primitive.
    pub frames_scored: usize,
    /// Scored frames outside the settling windows.
    pub frames_settled: usize,
    /// Frames not scored: no true activity, or one no primitive stands for.
    pub frames_unlabelled: usize,
    /// Frames where the tracker saw no silhouette and named no activity.
    pub frames_coasting: usize,
    /// Changes of the true activity into one some primitive stands for.
    pub switches: usize,
    /// Those switches the tracker followed before the next one.
    pub switches_recognized: usize,
    /// Mean delay from a recognized switch to the first frame naming it, s.
    #[serde(serialize_with = "rounded_option")]
    pub switch_latency_s: Option<f64>,
    /// True activity → what the tracker named (a primitive's label, its
    /// name when unlabelled, `(none)` when coasting) → frames, over every
    /// frame with a true activity.
    pub confusion: BTreeMap<String, BTreeMap<String, usize>>,
}

/// What the tracker named on one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Guess<'a> {
    Coasting,
    Primitive { name: &'a str, label: Option<&'a str> },
}

impl<'a> Guess<'a> {
    fn label(self) -> Option<&'a str> {
        match self {
            Guess::Coasting => None,
            Guess::Primitive { label, .. } => label,
        }
    }

    /// Its entry in the confusion table.
    fn shown(self) -> &'a str {
        match self {
            Guess::Coasting => "(none)",
            Guess::Primitive { name, label } => label.unwrap_or(name),
        }
    }
}

/// The joints of the upper-body error.
pub const UPPER_BODY: [Joint; 10] = [
    Joint::Spine,
    Joint::Chest,
    Joint::Neck,
    Joint::Head,
    Joint::LeftShoulder,
    Joint::LeftElbow,
    Joint::LeftWrist,
    Joint::RightShoulder,
    Joint::RightElbow,
    Joint::RightWrist,
];

const HANDS: [Joint; 2] = [Joint::LeftWrist, Joint::RightWrist];

/// Each kind of limb's bones, left then right, as (from, to) joints.
const LIMBS: [[(Joint, Joint); 2]; 4] = [
    [(Joint::LeftShoulder, Joint::LeftElbow), (Joint::RightShoulder, Joint::RightElbow)],
    [(Joint::LeftElbow, Joint::LeftWrist), (Joint::RightElbow, Joint::RightWrist)],
    [(Joint::LeftHip, Joint::LeftKnee), (Joint::RightHip, Joint::RightKnee)],
    [(Joint::LeftKnee, Joint::LeftAnkle), (Joint::RightKnee, Joint::RightAnkle)],
];

/// How far joint `j` is from the truth once each body's own pelvis is
/// subtracted (m): the root-relative error of one joint on one frame.
pub fn root_relative_m(estimate: &[DVec3; JOINTS], truth: &[DVec3; JOINTS], j: usize) -> f64 {
    let pelvis = Joint::Pelvis.index();
    (estimate[j] - estimate[pelvis]).distance(truth[j] - truth[pelvis])
}

/// The mean over frames (from `from`) of the upper body's root-relative
/// error (mm, as [`score`] measures it) of `motion`'s poses against
/// `truth`'s, frame by frame; `None` when `truth` has another number of
/// frames.
pub fn motion_error_mm(motion: &Motion, truth: &Track, from: usize) -> Option<f64> {
    if truth.joints.len() != motion.poses.len() {
        return None;
    }
    let errors: Vec<f64> = motion.poses[from.min(motion.poses.len())..]
        .iter()
        .zip(&truth.joints[from.min(truth.joints.len())..])
        .map(|(pose, t)| {
            let positions = motion.body.forward(pose).positions;
            UPPER_BODY.iter().map(|j| root_relative_m(&positions, t, j.index())).sum::<f64>() / UPPER_BODY.len() as f64
        })
        .collect();
    Some(1000.0 * errors.iter().sum::<f64>() / errors.len().max(1) as f64)
}

/// How far `motion` lies from a vocabulary's primitives: the upper-body
/// error (root-relative, mm, as [`score`] measures it) of each frame's pose
/// projected into a primitive's latent space (eq. 3, there and back),
/// through whichever primitive's projection comes nearest that frame,
/// averaged over the frames. Large where the motion's poses are ones no
/// primitive learned; a tracker held to the primitives' spaces rarely does
/// much better. `None` without primitives or frames.
pub fn latent_projection_mm(primitives: &[Primitive], motion: &Motion) -> Option<f64> {
    if primitives.is_empty() || motion.poses.is_empty() {
        return None;
    }
    let positions = |pose: &Pose| -> [DVec3; JOINTS] {
        let frame = motion.body.forward(pose);
        std::array::from_fn(|j| frame.position(Joint::ALL[j]))
    };
    // Collected before summing: a parallel sum's order, and so its last
    // bits, would vary from run to run.
    let per_frame: Vec<f64> = motion
        .poses
        .par_iter()
        .map(|pose| {
            let truth = positions(pose);
            primitives
                .iter()
                .map(|p| {
                    let held = Pose { x: p.reconstruct(&p.project(&pose.x)), ..*pose };
                    let near = positions(&held);
                    UPPER_BODY.iter().map(|j| root_relative_m(&near, &truth, j.index())).sum::<f64>()
                        / UPPER_BODY.len() as f64
                })
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    Some(1000.0 * per_frame.iter().sum::<f64>() / per_frame.len() as f64)
}

/// Seconds after a switch of activity that settled recognition leaves out
/// while the tracker catches up: `score`'s default and `eval`'s.
pub const SETTLE_S: f64 = 0.5;

/// Scores `estimate` (a run's `frames.csv`) against `truth` (the render's
/// `truth.csv`), row by row; the rows must be the same frames. A frame
/// counts as a switch of activity, and starts a settling window of
/// `settle_s` seconds, where its true activity differs from the previous
/// frame's (empty and unscored activities included).
pub fn score(estimate: &Track, truth: &Track, primitives: &Primitives, settle_s: f64) -> Result<Metrics, ReportError> {
    match_frames(estimate, truth)?;
    let frames = truth.frame.len();
    let mut root = 0.0;
    let mut absolute = 0.0;
    let mut relative = [0.0; JOINTS];
    for ((est, tru), (est_root, tru_root)) in
        estimate.joints.iter().zip(&truth.joints).zip(estimate.root.iter().zip(&truth.root))
    {
        root += est_root.distance(*tru_root);
        for j in 0..JOINTS {
            absolute += est[j].distance(tru[j]);
            relative[j] += root_relative_m(est, tru, j);
        }
    }
    // Per-joint sums over frames, so a joint set's mean is its sums' mean.
    let mean_mm =
        |set: &[Joint]| 1000.0 * set.iter().map(|j| relative[j.index()]).sum::<f64>() / (set.len() * frames) as f64;
    let limbs = limb_errors(estimate, truth)?;
    Ok(Metrics {
        frames,
        root_mm: 1000.0 * root / frames as f64,
        absolute_mm: 1000.0 * absolute / (JOINTS * frames) as f64,
        all_joints_mm: mean_mm(&Joint::ALL[1..]),
        upper_body_mm: mean_mm(&UPPER_BODY),
        hand_mm: mean_mm(&HANDS),
        limb_direction_deg: limbs.iter().sum::<f64>() / limbs.len() as f64,
        limbs_deg: Limbs { upper_arm: limbs[0], forearm: limbs[1], thigh: limbs[2], shin: limbs[3] },
        recognition: recognition(estimate, truth, primitives, settle_s)?,
    })
}

fn match_frames(estimate: &Track, truth: &Track) -> Result<(), ReportError> {
    if estimate.frame.len() != truth.frame.len() {
        return Err(ReportError::FrameCount {
            estimate: estimate.file.clone(),
            estimated: estimate.frame.len(),
            truth: truth.file.clone(),
            truth_frames: truth.frame.len(),
        });
    }
    match estimate.frame.iter().zip(&truth.frame).position(|(a, b)| a != b) {
        Some(row) => Err(ReportError::FrameMismatch {
            estimate: estimate.file.clone(),
            estimated: estimate.frame[row],
            truth: truth.file.clone(),
            truth_frame: truth.frame[row],
            row: row + 1,
        }),
        None => Ok(()),
    }
}

/// Mean direction error of each kind of limb in [`LIMBS`], degrees.
fn limb_errors(estimate: &Track, truth: &Track) -> Result<[f64; 4], ReportError> {
    let direction = |track: &Track, row: usize, (from, to): (Joint, Joint)| {
        let bone = track.joints[row][to.index()] - track.joints[row][from.index()];
        // A body whose joints coincide was not drawn from any pose: its
        // angle would silently read 0°.
        if bone.length() < 1e-9 {
            return Err(ReportError::DegenerateBone {
                file: track.file.clone(),
                frame: track.frame[row],
                from: from.name(),
                to: to.name(),
            });
        }
        Ok(bone)
    };
    let mut sums = [0.0; 4];
    for row in 0..truth.frame.len() {
        for (sum, bones) in sums.iter_mut().zip(&LIMBS) {
            for &bone in bones {
                *sum += angle_deg(direction(estimate, row, bone)?, direction(truth, row, bone)?);
            }
        }
    }
    Ok(sums.map(|s| s / (2 * truth.frame.len()) as f64))
}

/// The angle between two vectors, degrees. `atan2` stays exact near 0° and
/// 180°, where `acos` of the cosine loses half its digits.
fn angle_deg(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

fn recognition(
    estimate: &Track,
    truth: &Track,
    primitives: &Primitives,
    settle_s: f64,
) -> Result<Recognition, ReportError> {
    let guesses = estimate
        .activity
        .iter()
        .zip(&estimate.frame)
        .map(|(activity, &frame)| match activity {
            None => Ok(Guess::Coasting),
            Some(name) => match primitives.labels.get_key_value(name) {
                Some((name, label)) => Ok(Guess::Primitive { name, label: label.as_deref() }),
                None => Err(ReportError::UnknownPrimitive {
                    file: estimate.file.clone(),
                    frame,
                    name: name.clone(),
                    summary: primitives.file.clone(),
                }),
            },
        })
        .collect::<Result<Vec<_>, _>>()?;
    let activities: Vec<Option<&str>> = truth.activity.iter().map(Option::as_deref).collect();
    let labels: BTreeSet<&str> = primitives.labels.values().flatten().map(String::as_str).collect();
    Ok(recognize(&activities, &guesses, &truth.time_s, &labels, settle_s))
}

/// Recognition scores of `guesses` against the true `activities`, frames at
/// `time_s`; only activities in `labels` are scored.
fn recognize(
    activities: &[Option<&str>],
    guesses: &[Guess],
    time_s: &[f64],
    labels: &BTreeSet<&str>,
    settle_s: f64,
) -> Recognition {
    // Frame times are decimals read back; a frame exactly `settle_s` after
    // a switch must not fall in or out of the window by rounding.
    const SLACK_S: f64 = 1e-9;
    let switch = |i: usize| i > 0 && activities[i] != activities[i - 1];
    let mut confusion: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    let (mut scored, mut correct, mut settled, mut settled_correct) = (0, 0, 0, 0);
    let (mut unlabelled, mut coasting) = (0, 0);
    let mut last_switch_s = None;
    for (i, (&activity, &guess)) in activities.iter().zip(guesses).enumerate() {
        if switch(i) {
            last_switch_s = Some(time_s[i]);
        }
        if guess == Guess::Coasting {
            coasting += 1;
        }
        if let Some(activity) = activity {
            *confusion.entry(activity.to_string()).or_default().entry(guess.shown().to_string()).or_default() += 1;
        }
        let Some(activity) = activity.filter(|a| labels.contains(a)) else {
            unlabelled += 1;
            continue;
        };
        let right = usize::from(guess.label() == Some(activity));
        scored += 1;
        correct += right;
        if last_switch_s.is_none_or(|s| time_s[i] - s >= settle_s - SLACK_S) {
            settled += 1;
            settled_correct += right;
        }
    }
    let mut latencies = Vec::new();
    let starts: Vec<usize> = (0..activities.len()).filter(|&i| switch(i)).collect();
    for (k, &start) in starts.iter().enumerate() {
        let Some(activity) = activities[start].filter(|a| labels.contains(a)) else {
            continue;
        };
        let end = starts.get(k + 1).copied().unwrap_or(activities.len());
        if let Some(hit) = (start..end).find(|&i| guesses[i].label() == Some(activity)) {
            latencies.push(time_s[hit] - time_s[start]);
        }
    }
    let share = |part: usize, whole: usize| (whole > 0).then(|| part as f64 / whole as f64);
    Recognition {
        recognition_accuracy: share(correct, scored),
        recognition_accuracy_settled: share(settled_correct, settled),
        settle_s,
        frames_scored: scored,
        frames_settled: settled,
        frames_unlabelled: unlabelled,
        frames_coasting: coasting,
        switches: starts.iter().filter(|&&i| activities[i].is_some_and(|a| labels.contains(a))).count(),
        switches_recognized: latencies.len(),
        switch_latency_s: (!latencies.is_empty()).then(|| latencies.iter().sum::<f64>() / latencies.len() as f64),
        confusion,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motion_a_vocabulary_learned_projects_near_it_and_motion_it_never_saw_far_from_it() {
        use crate::mocap::synth::{Activity, SynthOptions, activity_take};
        use crate::vocab::evaluate::benchmark_stream;
        use crate::vocab::pipeline::{BuildParams, build};
        // Circles, waving both ways and punching, learned.
        let built = build(&benchmark_stream(1), &BuildParams::standard(), |_| {}).unwrap();
        let primitives = &built.fitted.primitives;
        let options = SynthOptions { repetitions: 4, seed: 77, ..Default::default() };
        let seen = latent_projection_mm(primitives, &activity_take(Activity::WaveH, &options).motion).unwrap();
        let unseen = latent_projection_mm(primitives, &activity_take(Activity::Twist, &options).motion).unwrap();
        assert!(seen < 15.0, "waving, learned: {seen:.1} mm");
        assert!(unseen > 3.0 * seen, "twisting, never learned: {unseen:.1} mm against {seen:.1} mm");
        assert_eq!(latent_projection_mm(&[], &activity_take(Activity::WaveH, &options).motion), None);
    }

    #[test]
    fn limb_angles_are_exact_at_0_and_180_degrees_and_ignore_length() {
        let a = DVec3::new(0.3, -0.2, 0.1);
        assert_eq!(angle_deg(a, a), 0.0);
        assert_eq!(angle_deg(a, 4.0 * a), 0.0);
        assert!(angle_deg(a, 5.0 * a) < 1e-12);
        assert_eq!(angle_deg(a, -a), 180.0);
        assert!((angle_deg(DVec3::X, DVec3::new(0.0, 2.0, 0.0)) - 90.0).abs() < 1e-12);
        assert!((angle_deg(DVec3::X, DVec3::new(1.0, 1.0, 0.0)) - 45.0).abs() < 1e-12);
        // 1e-6 rad apart: acos(cos) would give about 0.8e-6 or 1.2e-6.
        let tiny = angle_deg(DVec3::X, DVec3::new(1e-6f64.cos(), 1e-6f64.sin(), 0.0));
        assert!((tiny - 1e-6f64.to_degrees()).abs() < 1e-15, "{tiny}");
    }

    fn track(joints: Vec<[DVec3; JOINTS]>) -> Track {
        let n = joints.len();
        Track {
            file: "t.csv".into(),
            frame: (0..n as u64).collect(),
            time_s: (0..n).map(|i| i as f64 / 10.0).collect(),
            activity: vec![None; n],
            root: joints.iter().map(|j| j[0]).collect(),
            joints,
        }
    }

    /// A T-pose: arms along ±X, legs down.
    fn t_pose() -> [DVec3; JOINTS] {
        let mut j = [DVec3::ZERO; JOINTS];
        for (joint, p) in [
            (Joint::Pelvis, [0.0, 1.0, 0.0]),
            (Joint::Spine, [0.0, 1.1, 0.0]),
            (Joint::Chest, [0.0, 1.3, 0.0]),
            (Joint::Neck, [0.0, 1.5, 0.0]),
            (Joint::Head, [0.0, 1.6, 0.0]),
            (Joint::LeftShoulder, [0.2, 1.45, 0.0]),
            (Joint::LeftElbow, [0.5, 1.45, 0.0]),
            (Joint::LeftWrist, [0.75, 1.45, 0.0]),
            (Joint::RightShoulder, [-0.2, 1.45, 0.0]),
            (Joint::RightElbow, [-0.5, 1.45, 0.0]),
            (Joint::RightWrist, [-0.75, 1.45, 0.0]),
            (Joint::LeftHip, [0.1, 0.95, 0.0]),
            (Joint::LeftKnee, [0.1, 0.5, 0.0]),
            (Joint::LeftAnkle, [0.1, 0.1, 0.0]),
            (Joint::RightHip, [-0.1, 0.95, 0.0]),
            (Joint::RightKnee, [-0.1, 0.5, 0.0]),
            (Joint::RightAnkle, [-0.1, 0.1, 0.0]),
        ] {
            j[joint.index()] = DVec3::from_array(p);
        }
        j
    }

    #[test]
    fn a_forearm_raised_straight_up_is_90_degrees_on_one_of_two_forearms() {
        let truth = track(vec![t_pose(); 2]);
        let mut raised = t_pose();
        raised[Joint::LeftWrist.index()] = DVec3::new(0.5, 1.7, 0.0);
        let estimate = track(vec![t_pose(), raised]);
        let limbs = limb_errors(&estimate, &truth).unwrap();
        // One bone of four (two forearms, two frames) is 90° off.
        assert!((limbs[1] - 22.5).abs() < 1e-12, "{limbs:?}");
        assert_eq!([limbs[0], limbs[2], limbs[3]], [0.0; 3]);
        let mut collapsed = t_pose();
        collapsed[Joint::RightKnee.index()] = collapsed[Joint::RightHip.index()];
        let err = limb_errors(&track(vec![t_pose(), collapsed]), &truth).unwrap_err().to_string();
        assert_eq!(err, "t.csv: frame 1: right_hip and right_knee are at the same place, so the bone has no direction");
    }

    fn guesses<'a>(names: &[Option<&'a str>]) -> Vec<Guess<'a>> {
        names.iter().map(|n| n.map_or(Guess::Coasting, |n| Guess::Primitive { name: n, label: Some(n) })).collect()
    }

    #[test]
    fn latency_runs_from_the_switch_to_the_first_frame_naming_the_new_activity() {
        let (a, b) = (Some("a"), Some("b"));
        let truth = [a, a, a, b, b, b, b, a, a, a];
        let guess = guesses(&[a, a, a, a, None, b, a, b, b, a]);
        let time: Vec<f64> = (0..10).map(|i| i as f64 * 0.1).collect();
        let labels = BTreeSet::from(["a", "b"]);
        let r = recognize(&truth, &guess, &time, &labels, 0.15);
        assert_eq!((r.switches, r.switches_recognized), (2, 2));
        // b at 0.3 named at 0.5; a at 0.7 named at 0.9.
        assert!((r.switch_latency_s.unwrap() - 0.2).abs() < 1e-12);
        assert_eq!((r.frames_scored, r.frames_coasting), (10, 1));
        assert_eq!(r.recognition_accuracy, Some(0.5));
        // Frames 3, 4, 7 and 8 are within 0.15 s of a switch; of the 6
        // others only 6 is wrong.
        assert_eq!(r.frames_settled, 6);
        assert_eq!(r.recognition_accuracy_settled, Some(5.0 / 6.0));
        assert_eq!(r.confusion["b"], BTreeMap::from([("a".into(), 2), ("(none)".into(), 1), ("b".into(), 1)]));
    }

    #[test]
    fn a_switch_not_followed_before_the_next_one_is_unrecognized_and_unscored_labels_only_switch() {
        let (a, b, rest) = (Some("a"), Some("b"), Some("rest"));
        let truth = [a, a, b, b, rest, rest, a, a];
        // b is named only after the truth moved on to rest: too late.
        let guess = guesses(&[a, a, a, a, b, b, a, a]);
        let time: Vec<f64> = (0..8).map(f64::from).collect();
        let labels = BTreeSet::from(["a", "b"]);
        let r = recognize(&truth, &guess, &time, &labels, 0.0);
        assert_eq!((r.switches, r.switches_recognized), (2, 1));
        assert_eq!(r.switch_latency_s, Some(0.0));
        assert_eq!((r.frames_scored, r.frames_unlabelled), (6, 2));
        assert_eq!(r.recognition_accuracy, Some(4.0 / 6.0));
        assert_eq!(r.recognition_accuracy_settled, r.recognition_accuracy);
        assert_eq!(r.confusion["rest"], BTreeMap::from([("b".into(), 2)]));
    }

    #[test]
    fn unlabelled_primitives_show_their_name_and_never_count_as_right() {
        let truth = [Some("a"); 3];
        let guess = [
            Guess::Primitive { name: "p1", label: None },
            Guess::Primitive { name: "a", label: Some("a") },
            Guess::Primitive { name: "p1", label: None },
        ];
        let r = recognize(&truth, &guess, &[0.0, 0.1, 0.2], &BTreeSet::from(["a"]), 0.5);
        assert_eq!(r.recognition_accuracy, Some(1.0 / 3.0));
        assert_eq!((r.switches, r.switch_latency_s), (0, None));
        assert_eq!(r.confusion["a"], BTreeMap::from([("a".into(), 1), ("p1".into(), 2)]));
    }
}
