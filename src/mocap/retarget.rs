//! Retargeting by bone direction (docs/method.md, "Retargeting"): forward kinematics on the
//! source skeleton, then for every canonical joint the rotation that points
//! its bone where the source bone points, with the twist about the bone
//! taken from a second direction:
//!
//! - pelvis, spine, chest: the hip and shoulder lines;
//! - upper arms and thighs: the plane the limb bends in (the elbow or knee
//!   is a hinge, so its axis is normal to that plane), which makes the
//!   forearm and shin directions exact as well; a nearly straight limb's
//!   axis is carried over the take ([`crate::mocap::hinge`]);
//! - hands: the thumb; head, hands and feet without a second landmark: the
//!   source joint's own frame, calibrated once per take.

use crate::mocap::body::{Body, JOINTS, Joint, Kind};
use crate::mocap::bvh::{Bvh, Warning};
use crate::mocap::fk::{Kinematics, PositionMode, Transform, sample_frames};
use crate::mocap::hinge::{self, Bend, Tracker};
use crate::mocap::mapping::{Landmark, Mapping, MappingError, SourcePoint, UserMapping, joint_list, map_skeleton};
use crate::mocap::math::{Axis, frame_from_directions};
use crate::mocap::pose::{Motion, Pose};
use glam::{DQuat, DVec3};
use rayon::prelude::*;

/// Plausible standing heights of a captured person, meters.
const HEIGHT_RANGE_M: (f64, f64) = (1.3, 2.2);

/// Which world axis points up in the source.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpAxis {
    Y,
    Z,
}

#[derive(Clone, Debug, Default)]
pub struct RetargetOptions {
    /// Override the detected up axis.
    pub up: Option<UpAxis>,
    /// Landmarks the built-in tables do not find (or find wrongly).
    pub mapping: Option<UserMapping>,
}

/// One canonical landmark, where it was found and by which rule.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MappedLandmark {
    pub canonical: &'static str,
    pub source: Option<String>,
    /// `name`, `structure` or `file`; absent for a landmark not found.
    pub rule: Option<&'static str>,
    /// The naming scheme, how the structure placed it, or the mapping file.
    pub how: Option<String>,
}

/// What retargeting learned about a source skeleton.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Analysis {
    /// The naming scheme whose table matched.
    pub scheme: &'static str,
    pub mapping: Vec<MappedLandmark>,
    /// Canonical joints and landmarks with no source.
    pub missing: Vec<&'static str>,
    /// The source's up axis, e.g. `+Y` or `+Z`.
    pub up_axis: String,
    /// False when `--up` set it.
    pub up_detected: bool,
    /// Standing height estimated from the skeleton's proportions, in file units.
    pub height_units: f64,
    /// `meters`, `centimeters`, `millimeters`, `inches`, or `unknown`.
    pub units: &'static str,
    /// Meters per file unit (for unknown units: what makes a 1.75 m body).
    pub meters_per_unit: f64,
    /// Joints below the root with position channels, and how they read.
    pub position_channels: Vec<(String, PositionMode)>,
    pub warnings: Vec<Warning>,
}

#[derive(Debug, thiserror::Error)]
pub enum RetargetError {
    #[error(transparent)]
    Mapping(#[from] MappingError),
    #[error("{}", unmapped_message(.scheme, .missing, .joints, .structure))]
    Unmapped { scheme: &'static str, missing: Vec<&'static str>, joints: String, structure: Option<String> },
    #[error("the file has no frames of motion to retarget")]
    NoFrames,
    #[error("the file has {} ROOT hierarchies ({}): a capture of one body has one; keep the body's and remove the others", .0.len(), .0.join(", "))]
    MultipleRoots(Vec<String>),
    #[error("the skeleton has no length: its mapped joints all sit at one point")]
    Degenerate,
}

fn unmapped_message(scheme: &str, missing: &[&str], joints: &str, structure: &Option<String>) -> String {
    let example: String = missing.iter().map(|m| format!("    {m} = \"<source joint name>\"\n")).collect();
    let structure = structure.as_ref().map(|why| format!("; its structure gives no body: {why}")).unwrap_or_default();
    format!(
        "cannot map the skeleton onto the canonical body: no source joint for {} (closest built-in naming scheme: {scheme}{structure}).\n\
         Write a mapping file naming the source joint for each (docs/formats.md, \"Mapping files\"), and give it as the mapping:\n\
         \n    # mapping.toml: canonical joint = source joint; {{ end_of = \"J\" }} names J's End Site\n{example}\n\
         The skeleton's joints are: {joints}",
        missing.join(", ")
    )
}

const LANDMARKS: usize = Landmark::COUNT;

/// Landmark positions and their source joints' rotations in one frame,
/// already turned Y-up.
struct SourceFrame {
    p: [Option<DVec3>; LANDMARKS],
    s: [Option<DQuat>; LANDMARKS],
}

impl SourceFrame {
    fn p(&self, l: Landmark) -> Option<DVec3> {
        self.p[l.slot()]
    }
    fn pj(&self, j: Joint) -> Option<DVec3> {
        self.p[j.index()]
    }
    fn sj(&self, j: Joint) -> Option<DQuat> {
        self.s[j.index()]
    }

    /// The frame turned by `up`, keeping only the landmarks still mapped.
    fn turned(&self, up: DQuat, points: &[Option<SourcePoint>; LANDMARKS]) -> SourceFrame {
        let keep = |k: usize| points[k].is_some();
        SourceFrame {
            p: std::array::from_fn(|k| self.p[k].filter(|_| keep(k)).map(|v| up * v)),
            s: std::array::from_fn(|k| self.s[k].filter(|_| keep(k)).map(|q| up * q)),
        }
    }
}

/// The arms and legs: a ball joint, a hinge, and the joint at the far end.
#[derive(Clone, Copy)]
struct Limb {
    parent: Joint,
    root: Joint,
    hinge: Joint,
    end: Joint,
}

const LIMBS: [Limb; 4] = [
    Limb { parent: Joint::Chest, root: Joint::LeftShoulder, hinge: Joint::LeftElbow, end: Joint::LeftWrist },
    Limb { parent: Joint::Chest, root: Joint::RightShoulder, hinge: Joint::RightElbow, end: Joint::RightWrist },
    Limb { parent: Joint::Pelvis, root: Joint::LeftHip, hinge: Joint::LeftKnee, end: Joint::LeftAnkle },
    Limb { parent: Joint::Pelvis, root: Joint::RightHip, hinge: Joint::RightKnee, end: Joint::RightAnkle },
];

/// Hinge axes of the four limbs, then the twists of the two hands: what
/// is carried from frame to frame.
const TRACKED: usize = LIMBS.len() + 2;

/// Frames [`Retargeter::retarget`] solves at a time: enough to keep both
/// cores busy, few enough that a piece's source frames (about 1.6 kB each)
/// stay in cache.
const PIECE_FRAMES: usize = 1024;

/// The direction of limb `k`'s end (hand or foot): to its tip, else along
/// the source end joint's own frame, calibrated.
fn end_direction(f: &SourceFrame, cal: &Calibration, k: usize) -> Option<DVec3> {
    let end = LIMBS[k].end;
    let from_tip =
        Landmark::tip_of(end).and_then(|tip| f.p(tip)).zip(f.pj(end)).map(|(t, c)| t - c).filter(|d| d.length() > 0.0);
    from_tip.or_else(|| Some(f.sj(end)? * cal.end_bone[k]?))
}

/// The twist of hand `k` (0 left, 1 right): toward the thumb, else the
/// source hand's own frame, calibrated; and whether it is a frame (which
/// may flip half a turn between frames).
fn end_twist(f: &SourceFrame, cal: &Calibration, k: usize) -> Option<(DVec3, bool)> {
    let end = LIMBS[k].end;
    let (thumb, _) = twist_landmarks(end);
    match thumb.and_then(|t| Some(f.p(t)? - f.pj(end)?)) {
        Some(t) => Some((t, false)),
        None => Some((f.sj(end)? * cal.end_twist[k]?, true)),
    }
}

/// For the limb ends: the landmark that gives their twist, and the
/// rest-pose axis that twist lies along.
fn twist_landmarks(end: Joint) -> (Option<Landmark>, DVec3) {
    match end {
        Joint::LeftWrist => (Some(Landmark::LeftThumb), DVec3::Z),
        Joint::RightWrist => (Some(Landmark::RightThumb), DVec3::Z),
        Joint::LeftAnkle | Joint::RightAnkle => (None, DVec3::X),
        _ => unreachable!("limb ends are wrists and ankles"),
    }
}

/// Directions fixed in a source joint's own frame that stand in for
/// missing landmarks. Found once per take by averaging, over sampled
/// frames, where the canonical solution puts them in that frame.
#[derive(Clone, Copy, Debug, Default)]
struct Calibration {
    /// Per limb: the hinge axis in the source limb-root joint's frame.
    hinge: [Option<DVec3>; 4],
    /// Per limb end (indexed like `LIMBS`) and the head (index 4): bone and
    /// twist axes in the source joint's frame.
    end_bone: [Option<DVec3>; 5],
    end_twist: [Option<DVec3>; 5],
}

/// Turns frames of one source skeleton into canonical poses.
pub struct Retargeter {
    kin: Kinematics,
    needed: Vec<bool>,
    points: [Option<SourcePoint>; LANDMARKS],
    end_offsets: Vec<DVec3>,
    up: DQuat,
    /// Canonical meters per source unit.
    scale: f64,
    cal: Calibration,
    body: Body,
    /// Canonical joint → source joint, when the source is a canonical
    /// skeleton whose rotations carry over exactly.
    direct: Option<[usize; JOINTS]>,
    analysis: Analysis,
}

impl Retargeter {
    /// Analyses `bvh` (mapping, up axis, units, position conventions) and
    /// calibrates the twist fallbacks.
    pub fn new(bvh: &Bvh, options: &RetargetOptions) -> Result<Retargeter, RetargetError> {
        let skeleton = &bvh.skeleton;
        let roots: Vec<String> = skeleton.roots().map(|r| skeleton.joints[r].name.clone()).collect();
        if roots.len() > 1 {
            return Err(RetargetError::MultipleRoots(roots));
        }
        let kin = Kinematics::new(bvh);
        let mapping = map_skeleton(bvh, &kin, options.mapping.as_ref())?;
        let missing_required = mapping.missing_required();
        if !missing_required.is_empty() {
            return Err(RetargetError::Unmapped {
                scheme: mapping.scheme,
                missing: missing_required.iter().map(|l| l.name()).collect(),
                joints: joint_list(skeleton),
                structure: mapping.structure_error.as_ref().map(|e| e.to_string()),
            });
        }
        if bvh.frames == 0 {
            return Err(RetargetError::NoFrames);
        }
        let mut points = [None; LANDMARKS];
        for (l, p) in &mapping.points {
            points[l.slot()] = Some(*p);
        }
        let needed = kin.with_ancestors(points.iter().flatten().map(|p| p.joint));
        let end_offsets = skeleton.joints.iter().map(|j| j.end_site.unwrap_or(DVec3::ZERO)).collect();
        let body = Body::standard();
        let mut r = Retargeter {
            kin,
            needed,
            points,
            end_offsets,
            up: DQuat::IDENTITY,
            scale: 1.0,
            cal: Calibration::default(),
            body,
            direct: None,
            analysis: Analysis {
                scheme: mapping.scheme,
                mapping: Vec::new(),
                missing: Vec::new(),
                up_axis: String::new(),
                up_detected: options.up.is_none(),
                height_units: 0.0,
                units: "unknown",
                meters_per_unit: 1.0,
                position_channels: Vec::new(),
                warnings: Vec::new(),
            },
        };
        // Up to SAMPLE_FRAMES frames, in the file's own axes, serve the
        // analysis and (turned upright) the calibration.
        let mut scratch = vec![Transform::default(); skeleton.joints.len()];
        let frames: Vec<SourceFrame> =
            sample_frames(bvh.frames).into_iter().map(|f| r.source_frame(bvh.frame(f), &mut scratch)).collect();
        r.analyse(bvh, &mapping, options, &frames)?;
        if r.direct.is_none() {
            let upright: Vec<SourceFrame> = frames.iter().map(|f| f.turned(r.up, &r.points)).collect();
            r.cal = r.calibrate(&upright);
        }
        Ok(r)
    }

    pub fn analysis(&self) -> &Analysis {
        &self.analysis
    }

    /// The canonical body poses are retargeted onto.
    pub fn body(&self) -> &Body {
        &self.body
    }

    /// Retargets every frame: in parallel, but for the hinge axes, which
    /// are carried from frame to frame ([`crate::mocap::hinge`]). A take
    /// is solved in pieces of `PIECE_FRAMES`, so the source frames each
    /// piece's passes share stay in cache and their buffers are reused.
    pub fn retarget(&self, bvh: &Bvh) -> Motion {
        let channels = bvh.channel_count();
        let joints = bvh.skeleton.joints.len();
        let poses = if let Some(direct) = self.direct {
            bvh.data.par_chunks(channels).map(|frame| self.direct_pose(frame, &direct)).collect()
        } else {
            let mut trackers: [Tracker; TRACKED] = std::array::from_fn(|_| Tracker::new(bvh.frame_time_s));
            let (mut sources, mut bends) = (Vec::new(), Vec::new());
            let mut poses = Vec::with_capacity(bvh.frames);
            for piece in bvh.data.chunks(channels * PIECE_FRAMES) {
                piece
                    .par_chunks(channels)
                    .map_init(|| vec![Transform::default(); joints], |scratch, frame| self.source_frame(frame, scratch))
                    .collect_into_vec(&mut sources);
                sources.par_iter().map(|f| self.bends(f, &self.cal)).collect_into_vec(&mut bends);
                // Each limb's axes run in frame order; the limbs are apart.
                let axes: Vec<Vec<Option<DVec3>>> = trackers
                    .par_iter_mut()
                    .enumerate()
                    .map(|(k, tracker)| bends.iter().map(|b| tracker.next(b[k].as_ref())).collect())
                    .collect();
                poses.par_extend(sources.par_iter().enumerate().map(|(t, source)| {
                    let world = self.solve(source, &self.cal, std::array::from_fn(|k| axes[k][t]));
                    let local = local_rotations(&world.rotations, &world.hinge_angles);
                    let root = source.pj(Joint::Pelvis).unwrap_or(DVec3::ZERO) * self.scale;
                    Pose::from_rotations(root, &local)
                }));
            }
            poses
        };
        Motion { body: self.body.clone(), frame_time_s: bvh.frame_time_s, poses }
    }

    /// How each limb bends in one source frame, with the reference axis for
    /// when it is straight: the source's own upper-arm or thigh frame,
    /// calibrated, else the limb's geometry.
    ///
    /// After the four limbs, the two hands: their direction, and the twist
    /// about it (the thumb, else the source hand's own frame, which may
    /// flip), carried like a straight limb's hinge axis.
    fn bends(&self, f: &SourceFrame, cal: &Calibration) -> [Option<Bend>; TRACKED] {
        std::array::from_fn(|k| {
            if k >= LIMBS.len() {
                let k = k - LIMBS.len();
                let dir = end_direction(f, cal, k)?;
                let (twist, may_flip) = end_twist(f, cal, k)?;
                return Bend::new(dir, dir, Some(twist), may_flip);
            }
            let limb = &LIMBS[k];
            let (a, b, c) = (f.pj(limb.root)?, f.pj(limb.hinge)?, f.pj(limb.end)?);
            let calibrated = f.sj(limb.root).zip(cal.hinge[k]).map(|(s, h)| s * h);
            let from_frame = calibrated.is_some();
            Bend::new(b - a, c - b, calibrated.or_else(|| hinge_reference(f, limb, b - a)), from_frame)
        })
    }

    /// Source landmark positions for one frame in the canonical world
    /// (Y up, meters), for checking a retargeted pose against its source.
    pub fn source_landmarks(&self, frame: &[f64], scratch: &mut [Transform]) -> [Option<DVec3>; Landmark::COUNT] {
        let source = self.source_frame(frame, scratch);
        source.p.map(|p| p.map(|v| v * self.scale))
    }

    fn source_frame(&self, frame: &[f64], scratch: &mut [Transform]) -> SourceFrame {
        self.kin.world(frame, &self.needed, scratch);
        let mut p = [None; LANDMARKS];
        let mut s = [None; LANDMARKS];
        for (k, point) in self.points.iter().enumerate() {
            if let Some(point) = point {
                let t = scratch[point.joint];
                let local = if point.end_site { t.rotation * self.end_offsets[point.joint] } else { DVec3::ZERO };
                p[k] = Some(self.up * (t.position + local));
                s[k] = Some(self.up * t.rotation);
            }
        }
        SourceFrame { p, s }
    }

    fn direct_pose(&self, frame: &[f64], direct: &[usize; JOINTS]) -> Pose {
        // The file's rest frames are the canonical ones turned by the
        // inverse of `up`, so every rotation carries over conjugated.
        let mut local = [DQuat::IDENTITY; JOINTS];
        let mut root = DVec3::ZERO;
        let down = self.up.inverse();
        for j in Joint::ALL {
            let (t, r) = self.kin.local(direct[j.index()], frame);
            if j == Joint::Pelvis {
                root = self.up * t * self.scale;
            }
            local[j.index()] = self.up * r * down;
        }
        Pose::from_rotations(root, &local)
    }

    /// World rotations of the canonical joints for one source frame, with
    /// each limb's hinge axis and each hand's twist (as [`Self::bends`]).
    fn solve(&self, f: &SourceFrame, cal: &Calibration, axes: [Option<DVec3>; TRACKED]) -> Solved {
        use Joint::*;
        let mut w = [DQuat::IDENTITY; JOINTS];
        let mut hinge_angles = [0.0; JOINTS];
        let up_from = |a: Joint, b: Joint| Some(f.pj(b)? - f.pj(a)?);
        let hip_line = up_from(RightHip, LeftHip);
        let shoulder_line = up_from(RightShoulder, LeftShoulder);
        let lateral_torso = hip_line.or(shoulder_line).unwrap_or(DVec3::X);
        let lateral_chest = shoulder_line.unwrap_or(lateral_torso);
        let mixed = lateral_torso.normalize_or_zero() + lateral_chest.normalize_or_zero();

        let pelvis_up = up_from(Pelvis, Spine).filter(|v| v.length() > 0.0).or(up_from(Pelvis, Chest));
        w[Pelvis.index()] = orient(DVec3::Y, DVec3::X, pelvis_up, lateral_torso, DQuat::IDENTITY);
        w[Spine.index()] = orient(DVec3::Y, DVec3::X, up_from(Spine, Chest), mixed, w[Pelvis.index()]);
        w[Chest.index()] = orient(DVec3::Y, DVec3::X, up_from(Chest, Neck), lateral_chest, w[Spine.index()]);
        let neck_lateral = w[Chest.index()] * DVec3::X;
        w[Neck.index()] = orient(DVec3::Y, DVec3::X, up_from(Neck, Head), neck_lateral, w[Chest.index()]);

        // Head: its top gives the direction; its own frame the twist.
        let head_bone = self.body.bone(Head);
        let head_dir = f
            .p(Landmark::HeadTop)
            .zip(f.pj(Head))
            .map(|(top, head)| top - head)
            .or_else(|| Some(f.sj(Head)? * cal.end_bone[4]?));
        let head_twist = f.sj(Head).zip(cal.end_twist[4]).map(|(s, v)| s * v).unwrap_or(neck_lateral);
        w[Head.index()] = orient(head_bone, DVec3::X, head_dir, head_twist, w[Neck.index()]);

        for (k, limb) in LIMBS.iter().enumerate() {
            let parent = w[limb.parent.index()];
            let Kind::Hinge { axis: rest_axis, .. } = limb.hinge.kind() else {
                unreachable!("limb middles are hinges")
            };
            let bone = self.body.bone(limb.root);
            let (Some(a), Some(b), Some(c)) = (f.pj(limb.root), f.pj(limb.hinge), f.pj(limb.end)) else {
                // Unmapped leg: held at rest under its parent.
                for j in [limb.root, limb.hinge, limb.end] {
                    w[j.index()] = parent;
                }
                continue;
            };
            let (u, v) = (b - a, c - b);
            let axis = axes[k].unwrap_or(parent * rest_axis);
            let root = orient(bone, rest_axis, Some(u), axis, parent);
            let angle = signed_angle(u, v, root * rest_axis);
            w[limb.root.index()] = root;
            hinge_angles[limb.hinge.index()] = angle;
            let hinge = root * DQuat::from_axis_angle(rest_axis, angle);
            w[limb.hinge.index()] = hinge;

            let (_, rest_twist) = twist_landmarks(limb.end);
            // A hand's twist is tracked (after the limbs' hinge axes, the
            // arms first); a foot turns about the shin by little, and
            // source foot frames flip, so its twist is the shin's.
            let hand = matches!(limb.end, Joint::LeftWrist | Joint::RightWrist);
            let tracked = if hand { axes[LIMBS.len() + k] } else { None };
            let twist = tracked.unwrap_or(hinge * rest_twist);
            w[limb.end.index()] = orient(self.body.bone(limb.end), rest_twist, end_direction(f, cal, k), twist, hinge);
        }
        Solved { rotations: w, hinge_angles }
    }

    /// Mapping report, implausible tips, up axis, height and units, from
    /// sampled `frames` in the file's own axes.
    fn analyse(
        &mut self,
        bvh: &Bvh,
        mapping: &Mapping,
        options: &RetargetOptions,
        frames: &[SourceFrame],
    ) -> Result<(), RetargetError> {
        let skeleton = &bvh.skeleton;
        for (tip, deviation) in implausible_tips(frames, &self.body) {
            let source = mapping.get(tip).map(|p| p.describe(skeleton)).unwrap_or_default();
            self.points[tip.slot()] = None;
            let message = format!(
                "`{tip}` ({source}) lies {deviation:.0}° from where a {tip} would be relative to its bone on average; \
                 it is ignored and that part is oriented from its source joint's frame"
            );
            self.analysis.warnings.push(Warning { code: "landmark_ignored", message });
        }
        let a = &mut self.analysis;
        a.mapping = Landmark::all()
            .map(|l| {
                let source = self.points[l.slot()];
                let rule = source.and(mapping.rules.get(&l));
                MappedLandmark {
                    canonical: l.name(),
                    source: source.map(|p| p.describe(skeleton)),
                    rule: rule.map(|r| r.kind()),
                    how: rule.map(|r| r.detail().to_string()),
                }
            })
            .collect();
        let missing: Vec<Landmark> = Landmark::all().filter(|l| self.points[l.slot()].is_none()).collect();
        a.missing = missing.iter().map(|l| l.name()).collect();
        for (j, joint) in skeleton.joints.iter().enumerate() {
            if joint.parent.is_some()
                && let Some(mode) = self.kin.position_mode(j)
            {
                a.position_channels.push((joint.name.clone(), mode));
            }
        }

        let (up_vec, up_name) = match options.up {
            Some(UpAxis::Y) => (DVec3::Y, "+Y".to_string()),
            Some(UpAxis::Z) => (DVec3::Z, "+Z".to_string()),
            None => detect_up(frames),
        };
        self.up = DQuat::from_rotation_arc(up_vec, DVec3::Y);
        let height = estimate_height(frames, &self.body).ok_or(RetargetError::Degenerate)?;
        self.scale = self.body.proportions.height_m / height;
        let a = &mut self.analysis;
        a.up_axis = up_name;
        a.height_units = height;
        let (units, meters_per_unit) = detect_units(height);
        a.units = units;
        a.meters_per_unit = meters_per_unit;

        if a.up_axis != "+Y" {
            let how = if a.up_detected { "detected from the skeleton" } else { "as given" };
            let message = format!("the capture stands along {} ({how}); it is turned to stand along +Y", a.up_axis);
            a.warnings.push(Warning { code: "up_axis", message });
        }
        if units == "unknown" {
            let message = format!(
                "units are not stated and no common unit gives a plausible height ({height:.3} units tall); \
                 the body is scaled to {:.2} m",
                Body::STANDARD_HEIGHT_M
            );
            a.warnings.push(Warning { code: "units_unknown", message });
        }
        let legs: Vec<&str> = missing
            .iter()
            .filter(|l| matches!(l, Landmark::Joint(j) if Joint::LeftHip <= *j))
            .map(|l| l.name())
            .collect();
        if !legs.is_empty() {
            let message = format!("no source joints for {}: those legs stay in the rest pose", legs.join(", "));
            a.warnings.push(Warning { code: "legs_unmapped", message });
        }
        let extras: Vec<&str> = missing
            .iter()
            .filter(|l| !matches!(l, Landmark::Joint(_)) && mapping.get(**l).is_none())
            .map(|l| l.name())
            .collect();
        if !extras.is_empty() && mapping.scheme != "canonical" {
            let message = format!(
                "no source points for {}: the head, hands and feet take that direction from their source joint's own frame",
                extras.join(", ")
            );
            a.warnings.push(Warning { code: "landmarks_unmapped", message });
        }
        let absolute: Vec<&str> =
            a.position_channels.iter().filter(|(_, m)| *m == PositionMode::Absolute).map(|(n, _)| n.as_str()).collect();
        if !absolute.is_empty() {
            let message = format!(
                "position channels below the root hold whole local positions (equal to the OFFSET, as Blender \
                 writes them) on {}; read as absolute",
                absolute.join(", ")
            );
            a.warnings.push(Warning { code: "absolute_position_channels", message });
        }
        if mapping.scheme == "canonical" {
            self.direct = canonical_joints(bvh, &self.body, self.up);
            if let Some(direct) = self.direct {
                // Canonical files carry the rotations themselves; only the root scales.
                let file_height = [Joint::LeftKnee, Joint::LeftAnkle]
                    .iter()
                    .map(|j| skeleton.joints[direct[j.index()]].offset.length())
                    .sum::<f64>();
                self.scale = self.body.leg_length() / file_height.max(f64::MIN_POSITIVE);
            }
        }
        Ok(())
    }

    /// The source-frame directions that stand in for missing landmarks and
    /// for the bend plane of straight limbs, from upright sampled frames.
    fn calibrate(&self, frames: &[SourceFrame]) -> Calibration {
        // Hinge axes, seen from the limb root's frame: the line the
        // bend-plane normals of clearly bent frames cluster on (their
        // dominant axis, pointed the way most of them bend), when the take
        // bends the limb often enough; else, and for the sign of a knee
        // always, the limb's own geometry (`hinge_reference`). Slight bends
        // are noise: a take that hardly bends its knees once turned a
        // thigh by 90° on them.
        let mut cal = Calibration::default();
        for (k, limb) in LIMBS.iter().enumerate() {
            let mut bent = Vec::new();
            let mut reference = DVec3::ZERO;
            for f in frames {
                let (Some(a), Some(b), Some(c), Some(s)) =
                    (f.pj(limb.root), f.pj(limb.hinge), f.pj(limb.end), f.sj(limb.root))
                else {
                    continue;
                };
                let normal = (b - a).normalize_or_zero().cross((c - b).normalize_or_zero());
                if normal.length() >= hinge::CALIBRATION_BEND_SIN {
                    bent.push(s.inverse() * normal);
                }
                if let Some(r) = hinge_reference(f, limb, b - a) {
                    reference += s.inverse() * r;
                }
            }
            cal.hinge[k] = hinge::calibrate(&bent, reference, frames.len(), limb.hinge.is_knee());
        }

        // Ends: where the solved parent frame puts the rest bone and twist
        // axes, seen from the source joint (assumes the end is, on average
        // over the take, near its rest pose relative to its parent).
        let mut bone_sum = [DVec3::ZERO; 5];
        let mut twist_sum = [DVec3::ZERO; 5];
        for f in frames {
            let axes = self.bends(f, &cal).map(|b| b.and_then(|b| b.axis()));
            let solved = self.solve(f, &cal, axes);
            let ends = [
                (Joint::LeftWrist, Joint::LeftElbow, DVec3::Z),
                (Joint::RightWrist, Joint::RightElbow, DVec3::Z),
                (Joint::LeftAnkle, Joint::LeftKnee, DVec3::X),
                (Joint::RightAnkle, Joint::RightKnee, DVec3::X),
                (Joint::Head, Joint::Neck, DVec3::X),
            ];
            for (e, (end, parent, rest_twist)) in ends.into_iter().enumerate() {
                if let Some(s) = f.sj(end) {
                    let parent_rotation = solved.rotations[parent.index()];
                    let inv = s.inverse();
                    bone_sum[e] += inv * (parent_rotation * self.body.bone(end).normalize());
                    twist_sum[e] += inv * (parent_rotation * rest_twist);
                }
            }
        }
        for e in 0..5 {
            cal.end_bone[e] = bone_sum[e].try_normalize();
            cal.end_twist[e] = twist_sum[e].try_normalize();
        }
        cal
    }
}

/// The hinge axis a limb's own geometry gives in one frame, perpendicular
/// to the upper segment `upper`: for a knee, the hip line (to the person's
/// left, as the canonical knee's +X), turned toward the line across the
/// foot where the foot points away from the thigh; for an elbow, the axis
/// about which the forearm swings forward (toward where the chest faces),
/// or up where the arm points forward. `None` where the landmarks are
/// missing or the directions degenerate.
fn hinge_reference(f: &SourceFrame, limb: &Limb, upper: DVec3) -> Option<DVec3> {
    use Joint::*;
    let u = upper.try_normalize()?;
    let across = |v: DVec3| (v - u * v.dot(u)).try_normalize();
    let lateral = |left: Joint, right: Joint| Some(f.pj(left)? - f.pj(right)?);
    if limb.hinge.is_knee() {
        let hips = across(lateral(LeftHip, RightHip)?)?;
        let toe = if limb.end == LeftAnkle { Landmark::LeftToe } else { Landmark::RightToe };
        // The foot counts as much as it points away from the thigh.
        let foot = f.p(toe).zip(f.pj(limb.end)).map(|(t, a)| (t - a).normalize_or_zero().cross(u)).unwrap_or(hips);
        return across(hips + foot);
    }
    let left = lateral(LeftShoulder, RightShoulder)?;
    let up = f.pj(Neck)? - f.pj(Chest)?;
    let forward = left.cross(up);
    let swing = across(forward).filter(|_| forward.normalize_or_zero().dot(u).abs() < 0.9).or_else(|| across(up))?;
    u.cross(swing).try_normalize()
}

struct Solved {
    rotations: [DQuat; JOINTS],
    hinge_angles: [f64; JOINTS],
}

/// The rotation taking the rest pair (`rest_primary`, `rest_secondary`) to
/// the observed (`primary`, `secondary`); where either is missing or
/// degenerate, the parent's rotation (rest relative to the parent).
fn orient(
    rest_primary: DVec3,
    rest_secondary: DVec3,
    primary: Option<DVec3>,
    secondary: DVec3,
    parent: DQuat,
) -> DQuat {
    primary
        .and_then(|p| frame_from_directions(rest_primary, rest_secondary, p, secondary))
        .or_else(|| {
            // Secondary parallel to the primary: keep the parent's twist.
            let p = primary?;
            frame_from_directions(rest_primary, rest_secondary, p, parent * rest_secondary)
        })
        .unwrap_or(parent)
}

/// Angle from `u` to `v` about `axis` (right-handed), in (−π, π].
fn signed_angle(u: DVec3, v: DVec3, axis: DVec3) -> f64 {
    u.cross(v).dot(axis).atan2(u.dot(v))
}

/// Each joint's rotation relative to its parent; hinges get exactly their
/// angle about their axis.
fn local_rotations(world: &[DQuat; JOINTS], hinge_angles: &[f64; JOINTS]) -> [DQuat; JOINTS] {
    let mut local = [DQuat::IDENTITY; JOINTS];
    for j in Joint::ALL {
        local[j.index()] = match (j.parent(), j.kind()) {
            (None, _) => world[j.index()],
            (Some(_), Kind::Hinge { axis, .. }) => DQuat::from_axis_angle(axis, hinge_angles[j.index()]),
            (Some(p), Kind::Ball { .. }) => (world[p.index()].inverse() * world[j.index()]).normalize(),
        };
    }
    local
}

/// The signed world axis along which the body stands: the mean direction
/// from the feet (or pelvis) to the head, snapped to its largest component.
fn detect_up(frames: &[SourceFrame]) -> (DVec3, String) {
    let mut sum = DVec3::ZERO;
    for f in frames {
        let Some(head) = f.pj(Joint::Head) else {
            continue;
        };
        let feet = f.pj(Joint::LeftAnkle).zip(f.pj(Joint::RightAnkle)).map(|(l, r)| 0.5 * (l + r));
        if let Some(base) = feet.or(f.pj(Joint::Pelvis)) {
            sum += (head - base).normalize_or_zero();
        }
    }
    let axis =
        Axis::ALL.into_iter().max_by(|a, b| sum[a.index()].abs().total_cmp(&sum[b.index()].abs())).unwrap_or(Axis::Y);
    let sign = if sum[axis.index()] < 0.0 { -1.0 } else { 1.0 };
    let name = format!("{}{}", if sign < 0.0 { '-' } else { '+' }, axis.letter());
    (axis.unit() * sign, name)
}

/// Standing height in file units: the canonical height scaled by the
/// ratio of the median leg length (hip to knee to ankle) to the canonical
/// one, or of the trunk (pelvis to head top) for captures without legs.
fn estimate_height(frames: &[SourceFrame], body: &Body) -> Option<f64> {
    use Joint::*;
    let median_of = |f: &dyn Fn(&SourceFrame) -> Option<f64>| -> Option<f64> {
        let mut v: Vec<f64> = frames.iter().filter_map(f).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        Some(v[v.len() / 2])
    };
    let dist = |f: &SourceFrame, a: Landmark, b: Landmark| Some((f.p(a)? - f.p(b)?).length());
    let j = Landmark::Joint;
    let chain = |f: &SourceFrame, joints: &[Joint]| -> Option<f64> {
        joints.windows(2).map(|w| dist(f, j(w[0]), j(w[1]))).sum()
    };
    let leg = |f: &SourceFrame| {
        let l = chain(f, &[LeftHip, LeftKnee, LeftAnkle]);
        let r = chain(f, &[RightHip, RightKnee, RightAnkle]);
        match (l, r) {
            (Some(l), Some(r)) => Some(0.5 * (l + r)),
            (l, r) => l.or(r),
        }
    };
    let trunk_to_head = |f: &SourceFrame| chain(f, &[Pelvis, Spine, Chest, Neck, Head]);
    let head_top = |f: &SourceFrame| dist(f, Landmark::HeadTop, j(Head));

    // The legs set the pelvis height and the stride, so they set the scale
    // of root motion; trunks vary more between skeletons (CMU's is short).
    let height = match median_of(&leg) {
        Some(leg) => leg / body.leg_length(),
        None => {
            let body_trunk_to_head = body.trunk_length() - body.bone(Head).length();
            let trunk = median_of(&trunk_to_head)?;
            match median_of(&head_top) {
                Some(top) => (trunk + top) / body.trunk_length(),
                None => trunk / body_trunk_to_head,
            }
        }
    } * body.proportions.height_m;
    (height > 0.0 && height.is_finite()).then_some(height)
}

/// Tips whose direction from their joint, averaged over the take, sits
/// more than 45° from the canonical rest angle to the bone before it (an
/// End Site that points sideways says nothing about the head), and thumbs
/// that lie along the hand. Returns each with its deviation in degrees.
fn implausible_tips(frames: &[SourceFrame], body: &Body) -> Vec<(Landmark, f64)> {
    use Joint::*;
    let checks = [
        (Landmark::HeadTop, Head, Neck),
        (Landmark::LeftHandTip, LeftWrist, LeftElbow),
        (Landmark::RightHandTip, RightWrist, RightElbow),
        (Landmark::LeftToe, LeftAnkle, LeftKnee),
        (Landmark::RightToe, RightAnkle, RightKnee),
        (Landmark::LeftThumb, LeftWrist, LeftElbow),
        (Landmark::RightThumb, RightWrist, RightElbow),
    ];
    let mut rejected = Vec::new();
    for (tip, end, before) in checks {
        let angles: Vec<f64> = frames
            .iter()
            .filter_map(|f| {
                let (t, e, b) = (f.p(tip)?, f.pj(end)?, f.pj(before)?);
                let (d, bone) = ((t - e).try_normalize()?, (e - b).try_normalize()?);
                Some(d.dot(bone).clamp(-1.0, 1.0).acos().to_degrees())
            })
            .collect();
        if angles.is_empty() {
            continue;
        }
        let mean = angles.iter().sum::<f64>() / angles.len() as f64;
        let is_thumb = matches!(tip, Landmark::LeftThumb | Landmark::RightThumb);
        let deviation = if is_thumb {
            // Only its part across the hand is used: it must not lie along it.
            (20.0 - mean).max(mean - 160.0)
        } else {
            (mean - body.bone(end).angle_between(body.bone(before)).to_degrees()).abs() - 45.0
        };
        if deviation > 0.0 {
            rejected.push((tip, deviation + if is_thumb { 0.0 } else { 45.0 }));
        }
    }
    rejected
}

/// The common unit under which `height` (file units) is a plausible human
/// stature, and meters per unit; else `unknown`, scaled to a standard body.
fn detect_units(height: f64) -> (&'static str, f64) {
    let (lo, hi) = HEIGHT_RANGE_M;
    for (name, meters) in [("meters", 1.0), ("centimeters", 0.01), ("millimeters", 0.001), ("inches", 0.0254)] {
        let h = height * meters;
        if (lo..=hi).contains(&h) {
            return (name, meters);
        }
    }
    ("unknown", Body::STANDARD_HEIGHT_M / height)
}

/// For a skeleton that is the canonical one (same names and hierarchy, rest
/// directions the same once turned upright by `up`), canonical joint →
/// source joint.
fn canonical_joints(bvh: &Bvh, body: &Body, up: DQuat) -> Option<[usize; JOINTS]> {
    let skeleton = &bvh.skeleton;
    let mut map = [0usize; JOINTS];
    for j in Joint::ALL {
        let s = skeleton.find(j.name())?;
        map[j.index()] = s;
        let joint = &skeleton.joints[s];
        if joint.parent != j.parent().map(|p| map[p.index()]) {
            return None;
        }
        if j != Joint::Pelvis && (up * joint.offset).normalize_or_zero().dot(body.offset(j).normalize()) < 0.9995 {
            return None;
        }
        let rotations = joint.channels.iter().filter(|c| matches!(c, crate::mocap::bvh::Channel::Rotation(_))).count();
        if rotations != 3 || joint.euler_order().is_none() {
            return None;
        }
    }
    Some(map)
}
