//! A run's 2-D agreement with reference keypoints (a detector's, say
//! MediaPipe Pose's on a real clip, which is a reference and not ground
//! truth): the run's joints projected through its camera, and the share
//! within a fraction of the torso of the reference's points (PCK).

use crate::mocap::body::Joint;
use crate::report::metrics::Track;
use crate::vision::camera::Camera;
use crate::vision::keypoints::{Keypoints, Site, torso_px};
use std::collections::BTreeMap;

/// The share of the reference's torso within which a point agrees, as the
/// literature's PCK@0.2 counts it.
pub const PCK_THRESHOLD: f64 = crate::vision::sighting::PCK_TORSO_SHARE;

/// The points PCK is counted over: shoulders, elbows, wrists and hips,
/// each with its mirror.
const SCORED: [(Site, Joint, Site); 8] = [
    (Site::LeftShoulder, Joint::LeftShoulder, Site::RightShoulder),
    (Site::RightShoulder, Joint::RightShoulder, Site::LeftShoulder),
    (Site::LeftElbow, Joint::LeftElbow, Site::RightElbow),
    (Site::RightElbow, Joint::RightElbow, Site::LeftElbow),
    (Site::LeftWrist, Joint::LeftWrist, Site::RightWrist),
    (Site::RightWrist, Joint::RightWrist, Site::LeftWrist),
    (Site::LeftHip, Joint::LeftHip, Site::RightHip),
    (Site::RightHip, Joint::RightHip, Site::LeftHip),
];

/// What `imitate score --keypoints` writes.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Agreement {
    /// The reference's file.
    pub reference: String,
    /// A point counts within this share of the reference's torso
    /// (mid-shoulder to mid-hip) of its reference point.
    pub threshold_torso: f64,
    /// Frames whose reference shows the torso (both shoulders and hips),
    /// and the reference points in them.
    pub frames: usize,
    pub points: usize,
    /// The share of points within the threshold, the run's left and right
    /// taken as they are.
    pub pck: f64,
    /// The same, each frame with left and right swapped where that agrees
    /// better: a silhouette cannot tell a person's left from right.
    pub pck_mirror: f64,
    /// `pck_mirror` by point (`left_wrist`…).
    pub pck_mirror_by_point: BTreeMap<String, f64>,
}

/// Why a run and its reference cannot be compared.
#[derive(Debug, thiserror::Error)]
pub enum AgreementError {
    #[error(
        "{estimate} has {estimated} frames but the keypoints {reference} have {listed}: they must describe the same video"
    )]
    FrameCount { estimate: String, estimated: usize, reference: String, listed: usize },
    #[error("{reference}: no frame shows both shoulders and both hips, so no torso to measure against")]
    NoTorso { reference: String },
}

/// PCK@`threshold` of `run` (its joints seen through `camera`) against
/// `reference`, frame by frame.
pub fn agreement(
    run: &Track,
    camera: &Camera,
    reference: &Keypoints,
    threshold: f64,
) -> Result<Agreement, AgreementError> {
    let reference_name = reference.path.display().to_string();
    if reference.frames.len() > run.joints.len() {
        return Err(AgreementError::FrameCount {
            estimate: run.file.clone(),
            estimated: run.joints.len(),
            reference: reference_name,
            listed: reference.frames.len(),
        });
    }
    let (mut frames, mut points, mut hits, mut mirror_hits) = (0, 0, 0, 0);
    let mut by_point = [(0usize, 0usize); SCORED.len()];
    for (joints, seen) in run.joints.iter().zip(&reference.frames) {
        let at = |s: Site| seen[s.index()].map(|k| glam::DVec2::new(k.x, k.y));
        // PCK measures against the torso only where all four corners show it.
        let corners = [Site::LeftShoulder, Site::RightShoulder, Site::LeftHip, Site::RightHip];
        if corners.iter().any(|&s| at(s).is_none()) {
            continue;
        }
        let Some(torso) = torso_px(seen) else { continue };
        frames += 1;
        let projected = |j: Joint| camera.project(joints[j.index()]).map(|(u, v, _)| glam::DVec2::new(u, v));
        let within = |estimate: Option<glam::DVec2>, target: glam::DVec2| {
            estimate.is_some_and(|e| e.distance(target) <= threshold * torso)
        };
        let (mut straight, mut mirrored) = (Vec::new(), Vec::new());
        for (site, joint, mirror) in SCORED {
            let Some(target) = at(site) else { continue };
            let mirror_joint = SCORED.iter().find(|s| s.0 == mirror).expect("every point has a mirror").1;
            straight.push(within(projected(joint), target));
            mirrored.push(within(projected(mirror_joint), target));
        }
        let count = |v: &[bool]| v.iter().filter(|&&b| b).count();
        let swap = count(&mirrored) > count(&straight);
        points += straight.len();
        hits += count(&straight);
        mirror_hits += count(if swap { &mirrored } else { &straight });
        let mut taken = if swap { mirrored } else { straight }.into_iter();
        for (i, (site, ..)) in SCORED.iter().enumerate() {
            if at(*site).is_some() {
                by_point[i].0 += 1;
                by_point[i].1 += usize::from(taken.next().expect("one verdict per reference point"));
            }
        }
    }
    if frames == 0 {
        return Err(AgreementError::NoTorso { reference: reference_name });
    }
    let share = |hit: usize, of: usize| if of == 0 { 0.0 } else { hit as f64 / of as f64 };
    let pck_mirror_by_point = SCORED
        .iter()
        .zip(&by_point)
        .map(|((_, joint, _), &(of, hit))| (joint.name().to_string(), share(hit, of)))
        .collect();
    Ok(Agreement {
        reference: reference_name,
        threshold_torso: threshold,
        frames,
        points,
        pck: share(hits, points),
        pck_mirror: share(mirror_hits, points),
        pck_mirror_by_point,
    })
}
