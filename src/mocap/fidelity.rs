//! How faithfully a retargeted motion follows its source: limb
//! directions, the thighs' twist, and jumps in joint space the source's
//! bones do not make.

use crate::mocap::body::Joint;
use crate::mocap::bvh::Bvh;
use crate::mocap::fk::Transform;
use crate::mocap::mapping::Landmark;
use crate::mocap::pose::Motion;
use crate::mocap::retarget::Retargeter;
use glam::DVec3;

/// How closely a retargeted motion follows its source: the angle between
/// each canonical limb bone and the source bone, per frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DirectionErrors {
    /// Mean over frames for the upper arms, forearms, thighs and shins, in
    /// the order of [`DirectionErrors::BONES`], degrees.
    pub per_bone_deg: Vec<(&'static str, f64)>,
    /// Mean over frames and bones, degrees.
    pub mean_deg: f64,
    /// Largest single-frame error, degrees.
    pub max_deg: f64,
}

impl DirectionErrors {
    pub const BONES: [(&'static str, Joint, Joint); 8] = [
        ("left upper arm", Joint::LeftShoulder, Joint::LeftElbow),
        ("left forearm", Joint::LeftElbow, Joint::LeftWrist),
        ("right upper arm", Joint::RightShoulder, Joint::RightElbow),
        ("right forearm", Joint::RightElbow, Joint::RightWrist),
        ("left thigh", Joint::LeftHip, Joint::LeftKnee),
        ("left shin", Joint::LeftKnee, Joint::LeftAnkle),
        ("right thigh", Joint::RightHip, Joint::RightKnee),
        ("right shin", Joint::RightKnee, Joint::RightAnkle),
    ];

    /// Compares `motion` (retargeted from `bvh` by `retargeter`) with the
    /// source bones, over the bones both have.
    pub fn measure(bvh: &Bvh, retargeter: &Retargeter, motion: &Motion) -> DirectionErrors {
        let mut scratch = vec![Transform::default(); bvh.skeleton.joints.len()];
        let mut sums = [0.0; 8];
        let mut counts = [0usize; 8];
        let mut max_deg: f64 = 0.0;
        for (f, pose) in motion.poses.iter().enumerate() {
            let source = retargeter.source_landmarks(bvh.frame(f), &mut scratch);
            let canon = motion.body.forward(pose);
            for (b, (_, from, to)) in DirectionErrors::BONES.iter().enumerate() {
                let (Some(sa), Some(sb)) = (source[from.index()], source[to.index()]) else {
                    continue;
                };
                let d_source = (sb - sa).normalize_or_zero();
                let d_canon = (canon.position(*to) - canon.position(*from)).normalize_or_zero();
                let deg = d_source.dot(d_canon).clamp(-1.0, 1.0).acos().to_degrees();
                sums[b] += deg;
                counts[b] += 1;
                max_deg = max_deg.max(deg);
            }
        }
        let per_bone_deg: Vec<(&'static str, f64)> = DirectionErrors::BONES
            .iter()
            .enumerate()
            .filter(|(b, _)| counts[*b] > 0)
            .map(|(b, (name, _, _))| (*name, sums[b] / counts[b] as f64))
            .collect();
        let mean_deg = per_bone_deg.iter().map(|(_, d)| d).sum::<f64>() / per_bone_deg.len().max(1) as f64;
        DirectionErrors { per_bone_deg, mean_deg, max_deg }
    }
}

/// Thighs held at 30° of plumb or closer, with the knee bent less than
/// 30°, count as standing for [`ThighFacing`].
const STANDING_DEG: f64 = 30.0;

/// Where the canonical thighs face in standing frames: the angle about the
/// thigh between the way the knee faces (the hip frame's +Z) and the way
/// the pelvis faces. A knee axis guessed from noise shows as 90°; feet
/// turned out, as in some dance styles, show as they are.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ThighFacing {
    /// Leg-frames that stand (two a frame when both legs do).
    pub standing: usize,
    /// Of those, how many face more than 30° from the pelvis.
    pub beyond_30_deg: usize,
    /// The largest angle, degrees (0 with no standing frame).
    pub worst_deg: f64,
}

impl ThighFacing {
    pub fn measure(motion: &Motion) -> ThighFacing {
        let mut facing = ThighFacing { standing: 0, beyond_30_deg: 0, worst_deg: 0.0 };
        for pose in &motion.poses {
            let frame = motion.body.forward(pose);
            for (hip, knee) in [(Joint::LeftHip, Joint::LeftKnee), (Joint::RightHip, Joint::RightKnee)] {
                let thigh = (frame.position(knee) - frame.position(hip)).normalize_or_zero();
                let bent = pose.joint(knee)[0].abs().to_degrees();
                if thigh.angle_between(DVec3::NEG_Y).to_degrees() > STANDING_DEG || bent > STANDING_DEG {
                    continue;
                }
                let across = |v: DVec3| (v - thigh * v.dot(thigh)).normalize_or_zero();
                let knee_faces = across(frame.rotation(hip) * DVec3::Z);
                let pelvis_faces = across(frame.rotation(Joint::Pelvis) * DVec3::Z);
                let deg = knee_faces.angle_between(pelvis_faces).to_degrees();
                facing.standing += 1;
                facing.beyond_30_deg += usize::from(deg > STANDING_DEG);
                facing.worst_deg = facing.worst_deg.max(deg);
            }
        }
        facing
    }
}

/// A joint-space jump larger than this between two frames, degrees, must
/// be explained by the source's bones turning as much.
pub const JUMP_DEG: f64 = 60.0;

/// Jumps between frames in joint space against the source's own motion.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Continuity {
    /// The largest change of one joint's joint-space numbers between two
    /// frames, degrees; its joint and the frame it ends at.
    pub worst_jump_deg: f64,
    pub worst_joint: &'static str,
    pub worst_frame: usize,
    /// How far the source bones at that joint turned over that frame (or
    /// the angle between the joint's bone and its parent's changed).
    pub worst_source_deg: f64,
    /// Jumps over 60° where the source's bones at the joint turned less.
    pub unexplained: usize,
}

impl Continuity {
    /// Compares `motion` (retargeted from `bvh` by `retargeter`) frame to
    /// frame with the source's bones: a joint's own bone, its parent's and
    /// its child's, and the angle between its bone and its parent's.
    pub fn measure(bvh: &Bvh, retargeter: &Retargeter, motion: &Motion) -> Continuity {
        let mut scratch = vec![Transform::default(); bvh.skeleton.joints.len()];
        let bone = |points: &[Option<DVec3>; Landmark::COUNT], j: Joint| -> Option<DVec3> {
            let far = match j.bone_child() {
                Some(c) => points[c.index()]?,
                None => points[Landmark::tip_of(j)?.slot()]?,
            };
            (far - points[j.index()]?).try_normalize()
        };
        let mut result = Continuity {
            worst_jump_deg: 0.0,
            worst_joint: Joint::Pelvis.name(),
            worst_frame: 0,
            worst_source_deg: 0.0,
            unexplained: 0,
        };
        let mut previous = retargeter.source_landmarks(bvh.frame(0), &mut scratch);
        for t in 1..motion.poses.len() {
            let points = retargeter.source_landmarks(bvh.frame(t), &mut scratch);
            let turned = |j: Joint| -> f64 {
                let neighbours = [Some(j), j.parent(), j.bone_child()];
                let own = neighbours
                    .into_iter()
                    .flatten()
                    .filter_map(|k| Some(bone(&previous, k)?.angle_between(bone(&points, k)?)))
                    .fold(0.0, f64::max);
                // A joint that bends (a punch straightening the elbow) turns
                // by as much as the angle between its bone and its parent's
                // changes, which can exceed either bone's own turn.
                let bend =
                    |at: &[Option<DVec3>; Landmark::COUNT]| Some(bone(at, j)?.angle_between(bone(at, j.parent()?)?));
                let bent = bend(&previous).zip(bend(&points)).map_or(0.0, |(a, b)| (b - a).abs());
                own.max(bent).to_degrees()
            };
            for j in Joint::ALL.into_iter().filter(|&j| j != Joint::Pelvis) {
                let (a, b) = (motion.poses[t - 1].joint(j), motion.poses[t].joint(j));
                let jump = a.iter().zip(b).map(|(p, q)| (q - p).powi(2)).sum::<f64>().sqrt().to_degrees();
                if jump <= JUMP_DEG && jump <= result.worst_jump_deg {
                    continue;
                }
                let source = turned(j);
                if jump > JUMP_DEG && source < jump.min(JUMP_DEG) {
                    result.unexplained += 1;
                }
                if jump > result.worst_jump_deg {
                    result = Continuity {
                        worst_jump_deg: jump,
                        worst_joint: j.name(),
                        worst_frame: t,
                        worst_source_deg: source,
                        ..result
                    };
                }
            }
            previous = points;
        }
        result
    }
}
