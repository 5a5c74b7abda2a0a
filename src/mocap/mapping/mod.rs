//! Which source joints play which canonical parts: the naming schemes of
//! common exporters first, then the skeleton's structure for whatever the
//! names leave out, then the user's mapping file over both.

mod schemes;
mod structure;
mod user;

pub use schemes::{NormalName, Side, normalize};
pub use structure::StructureError;
pub use user::UserMapping;

use crate::mocap::body::Joint;
use crate::mocap::bvh::{Bvh, Skeleton};
use crate::mocap::fk::Kinematics;
use schemes::{NormalNames, SCHEMES};
use std::collections::BTreeMap;
use std::fmt;

/// A point of the canonical body that retargeting reads from the source:
/// every canonical joint, plus the tips that orient the head, hands and
/// feet and the thumbs that fix the twist of the hands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Landmark {
    Joint(Joint),
    HeadTop,
    LeftHandTip,
    LeftThumb,
    RightHandTip,
    RightThumb,
    LeftToe,
    RightToe,
}

impl Landmark {
    pub const EXTRAS: [Landmark; 7] = [
        Landmark::HeadTop,
        Landmark::LeftHandTip,
        Landmark::LeftThumb,
        Landmark::RightHandTip,
        Landmark::RightThumb,
        Landmark::LeftToe,
        Landmark::RightToe,
    ];

    /// Number of landmarks: the canonical joints and the extras.
    pub const COUNT: usize = crate::mocap::body::JOINTS + Landmark::EXTRAS.len();

    /// Position in [`Landmark::all`]: a joint's index, then the extras.
    pub fn slot(self) -> usize {
        match self {
            Landmark::Joint(j) => j.index(),
            extra => {
                crate::mocap::body::JOINTS
                    + Landmark::EXTRAS.iter().position(|&e| e == extra).expect("extras are listed")
            }
        }
    }

    /// Every landmark: the canonical joints, then the extras.
    pub fn all() -> impl Iterator<Item = Landmark> {
        Joint::ALL.into_iter().map(Landmark::Joint).chain(Landmark::EXTRAS)
    }

    pub fn name(self) -> &'static str {
        match self {
            Landmark::Joint(j) => j.name(),
            Landmark::HeadTop => "head_top",
            Landmark::LeftHandTip => "left_hand_tip",
            Landmark::LeftThumb => "left_thumb",
            Landmark::RightHandTip => "right_hand_tip",
            Landmark::RightThumb => "right_thumb",
            Landmark::LeftToe => "left_toe",
            Landmark::RightToe => "right_toe",
        }
    }

    pub fn from_name(name: &str) -> Option<Landmark> {
        Landmark::all().find(|l| l.name() == name)
    }

    /// Landmarks without which the arms or spine cannot be retargeted.
    pub fn is_required(self) -> bool {
        matches!(
            self,
            Landmark::Joint(
                Joint::Pelvis
                    | Joint::Spine
                    | Joint::Chest
                    | Joint::Neck
                    | Joint::Head
                    | Joint::LeftShoulder
                    | Joint::LeftElbow
                    | Joint::LeftWrist
                    | Joint::RightShoulder
                    | Joint::RightElbow
                    | Joint::RightWrist
            )
        )
    }
}

impl fmt::Display for Landmark {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A point of the source skeleton: a joint, or the end site below it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SourcePoint {
    pub joint: usize,
    pub end_site: bool,
}

impl SourcePoint {
    /// How the point reads in reports and mapping files.
    pub fn describe(self, skeleton: &Skeleton) -> String {
        let name = &skeleton.joints[self.joint].name;
        if self.end_site { format!("{name} (End Site)") } else { name.clone() }
    }
}

impl Landmark {
    /// The tip that gives a leaf joint's bone direction (the head's top,
    /// a hand's tip, a foot's toe); `None` for the other joints.
    pub fn tip_of(j: Joint) -> Option<Landmark> {
        Some(match j {
            Joint::Head => Landmark::HeadTop,
            Joint::LeftWrist => Landmark::LeftHandTip,
            Joint::RightWrist => Landmark::RightHandTip,
            Joint::LeftAnkle => Landmark::LeftToe,
            Joint::RightAnkle => Landmark::RightToe,
            _ => return None,
        })
    }

    /// The landmark this one hangs below in the canonical body.
    fn above(self) -> Option<Landmark> {
        use Joint::*;
        match self {
            Landmark::Joint(j) => j.parent().map(Landmark::Joint),
            Landmark::HeadTop => Some(Landmark::Joint(Head)),
            Landmark::LeftHandTip | Landmark::LeftThumb => Some(Landmark::Joint(LeftWrist)),
            Landmark::RightHandTip | Landmark::RightThumb => Some(Landmark::Joint(RightWrist)),
            Landmark::LeftToe => Some(Landmark::Joint(LeftAnkle)),
            Landmark::RightToe => Some(Landmark::Joint(RightAnkle)),
        }
    }

    /// Limb joints lie strictly below the source joint of the landmark
    /// above them; the trunk's joints may share it (a missing spine or neck
    /// taken from the chain), and a tip may be its End Site.
    fn strictly_below(self) -> bool {
        matches!(self, Landmark::Joint(j) if !matches!(j, Joint::Pelvis | Joint::Spine | Joint::Chest | Joint::Neck | Joint::Head))
    }

    /// The part of the body a landmark belongs to: the trunk and head (0),
    /// then the left and right arm and the left and right leg.
    fn part(self) -> u8 {
        use Joint::*;
        match self {
            Landmark::Joint(LeftShoulder | LeftElbow | LeftWrist) | Landmark::LeftHandTip | Landmark::LeftThumb => 1,
            Landmark::Joint(RightShoulder | RightElbow | RightWrist)
            | Landmark::RightHandTip
            | Landmark::RightThumb => 2,
            Landmark::Joint(LeftHip | LeftKnee | LeftAnkle) | Landmark::LeftToe => 3,
            Landmark::Joint(RightHip | RightKnee | RightAnkle) | Landmark::RightToe => 4,
            _ => 0,
        }
    }
}

/// How a landmark's source point was found.
#[derive(Clone, Debug, PartialEq)]
pub enum Rule {
    /// By a built-in naming scheme's table.
    Name(&'static str),
    /// From the skeleton's structure, as the text says.
    Structure(String),
    /// From the user's mapping file.
    File(String),
}

impl Rule {
    /// `name`, `structure` or `file`.
    pub fn kind(&self) -> &'static str {
        match self {
            Rule::Name(_) => "name",
            Rule::Structure(_) => "structure",
            Rule::File(_) => "file",
        }
    }

    /// The scheme, how the structure placed it, or the file.
    pub fn detail(&self) -> &str {
        match self {
            Rule::Name(scheme) => scheme,
            Rule::Structure(how) | Rule::File(how) => how,
        }
    }
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Rule::Name(scheme) => write!(f, "name, {scheme}"),
            Rule::Structure(how) => write!(f, "structure: {how}"),
            Rule::File(path) => write!(f, "mapping file {path}"),
        }
    }
}

/// The source point for every landmark that could be found, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapping {
    /// The built-in scheme the names came from; `structure` when the
    /// structure found more of the required landmarks than the names,
    /// `user` when a mapping file named every point.
    pub scheme: &'static str,
    pub points: BTreeMap<Landmark, SourcePoint>,
    pub rules: BTreeMap<Landmark, Rule>,
    /// Why the structure could not be read, when it was needed and failed.
    pub structure_error: Option<StructureError>,
}

impl Mapping {
    pub fn get(&self, l: Landmark) -> Option<SourcePoint> {
        self.points.get(&l).copied()
    }

    /// Landmarks without a source point.
    pub fn missing(&self) -> Vec<Landmark> {
        Landmark::all().filter(|l| !self.points.contains_key(l)).collect()
    }

    pub fn missing_required(&self) -> Vec<Landmark> {
        self.missing().into_iter().filter(|l| l.is_required()).collect()
    }

    fn insert(&mut self, l: Landmark, point: SourcePoint, rule: Rule) {
        self.points.insert(l, point);
        self.rules.insert(l, rule);
    }

    fn remove(&mut self, l: Landmark) {
        self.points.remove(&l);
        self.rules.remove(&l);
    }
}

#[derive(Debug, thiserror::Error)]
pub enum MappingError {
    #[error("{path}: cannot read: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: not valid TOML: {message}")]
    Toml { path: String, message: String },
    #[error("{path}: `{key}` is not a canonical joint or landmark; use one of: {valid}")]
    UnknownLandmark { path: String, key: String, valid: String },
    #[error("{path}: `{key}` must be a joint name in quotes or {{ end_of = \"JOINT\" }}")]
    BadValue { path: String, key: String },
    #[error("{path}: `{key} = \"{joint}\"`, but the skeleton has no joint `{joint}`; its joints are: {available}")]
    UnknownJoint { path: String, key: String, joint: String, available: String },
    #[error("{path}: `{key}` names the End Site of `{joint}`, which has none")]
    NoEndSite { path: String, key: String, joint: String },
}

/// Finds the source point for every landmark of the body under the first
/// root: the built-in scheme whose table maps the most required landmarks
/// (then the most landmarks) while keeping the canonical hierarchy; then,
/// for what it leaves out, the skeleton's structure where it agrees with
/// the names; then the user's mapping file over both.
pub fn map_skeleton(bvh: &Bvh, kin: &Kinematics, user: Option<&UserMapping>) -> Result<Mapping, MappingError> {
    let skeleton = &bvh.skeleton;
    let first_root = skeleton.roots().next().unwrap_or(0);
    let in_body = |j: usize| skeleton.is_ancestor_or_self(first_root, j);
    let names = NormalNames::new(skeleton, in_body);
    let score =
        |points: &BTreeMap<Landmark, SourcePoint>| (points.keys().filter(|l| l.is_required()).count(), points.len());
    let mut best: Option<(&'static str, BTreeMap<Landmark, SourcePoint>)> = None;
    for scheme in SCHEMES {
        let points = hierarchical(skeleton, schemes::apply(scheme, &names));
        if best.as_ref().is_none_or(|(_, b)| score(&points) > score(b)) {
            best = Some((scheme.name, points));
        }
    }
    let (scheme, table) = best.expect("there are schemes");
    let named_required = score(&table).0;
    let mut mapping = Mapping { scheme, points: BTreeMap::new(), rules: BTreeMap::new(), structure_error: None };
    for (l, p) in table {
        mapping.insert(l, p, Rule::Name(scheme));
    }
    let wanted = |l: &Landmark| !matches!(l, Landmark::LeftThumb | Landmark::RightThumb);
    if Landmark::all().filter(wanted).any(|l| !mapping.points.contains_key(&l)) {
        match structure::find(bvh, kin, &in_body, &names) {
            Ok(found) => fill_from_structure(skeleton, &mut mapping, found),
            Err(e) => mapping.structure_error = Some(e),
        }
    }
    let by_structure = mapping.rules.iter().filter(|(l, r)| l.is_required() && matches!(r, Rule::Structure(_))).count();
    if by_structure > named_required {
        mapping.scheme = "structure";
    }
    if let Some(user) = user {
        for (landmark, joint, end_site) in &user.entries {
            let index = skeleton.find(joint).ok_or_else(|| MappingError::UnknownJoint {
                path: user.path.clone(),
                key: landmark.name().into(),
                joint: joint.clone(),
                available: joint_list(skeleton),
            })?;
            if *end_site && skeleton.joints[index].end_site.is_none() {
                return Err(MappingError::NoEndSite {
                    path: user.path.clone(),
                    key: landmark.name().into(),
                    joint: joint.clone(),
                });
            }
            mapping.insert(*landmark, SourcePoint { joint: index, end_site: *end_site }, Rule::File(user.path.clone()));
        }
        if mapping.rules.values().all(|r| matches!(r, Rule::File(_))) {
            mapping.scheme = "user";
        }
    }
    Ok(mapping)
}

/// Whether `p` lies where the canonical hierarchy puts `l` relative to `q`,
/// the point of the nearest landmark above it.
fn lies_below(skeleton: &Skeleton, l: Landmark, p: SourcePoint, q: SourcePoint) -> bool {
    if p.joint == q.joint {
        return match l {
            Landmark::Joint(_) => !l.strictly_below() && !p.end_site && !q.end_site,
            _ => p.end_site && !q.end_site,
        };
    }
    !q.end_site && skeleton.is_ancestor_or_self(q.joint, p.joint)
}

/// The point of the nearest landmark above `l` that `points` has.
fn nearest_above(l: Landmark, points: &BTreeMap<Landmark, SourcePoint>) -> Option<SourcePoint> {
    let mut at = l.above();
    while let Some(a) = at {
        if let Some(p) = points.get(&a) {
            return Some(*p);
        }
        at = a.above();
    }
    None
}

/// A scheme's points, keeping (parents first) only those that lie below
/// the points kept above them: a table that names the chest above the
/// spine has the wrong scheme for that skeleton.
fn hierarchical(skeleton: &Skeleton, points: BTreeMap<Landmark, SourcePoint>) -> BTreeMap<Landmark, SourcePoint> {
    let mut kept = BTreeMap::new();
    for l in Landmark::all() {
        let Some(&p) = points.get(&l) else {
            continue;
        };
        if nearest_above(l, &kept).is_none_or(|q| lies_below(skeleton, l, p, q)) {
            kept.insert(l, p);
        }
    }
    kept
}

/// Adds the structure's points for the landmarks the names left out: a
/// limb's only where the structure's limb has the joints the names gave it,
/// and each only while the whole mapping keeps the canonical hierarchy.
fn fill_from_structure(skeleton: &Skeleton, mapping: &mut Mapping, found: structure::Found) {
    let agrees = |part: u8, mapping: &Mapping| {
        found
            .points
            .iter()
            .filter(|(l, _)| l.part() == part && matches!(l, Landmark::Joint(_)))
            .all(|(l, (p, _))| mapping.get(*l).is_none_or(|q| q == *p))
    };
    for (l, (p, how)) in &found.points {
        if mapping.points.contains_key(l) || (l.part() != 0 && !agrees(l.part(), mapping)) {
            continue;
        }
        mapping.insert(*l, *p, Rule::Structure(how.clone()));
        let consistent = Landmark::all().all(|k| {
            mapping
                .get(k)
                .is_none_or(|pk| nearest_above(k, &mapping.points).is_none_or(|q| lies_below(skeleton, k, pk, q)))
        });
        if !consistent {
            mapping.remove(*l);
        }
    }
}

/// The source joints' names, for messages.
pub fn joint_list(skeleton: &Skeleton) -> String {
    skeleton.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::bvh::{Joint as BvhJoint, Skeleton};
    use glam::DVec3;

    /// `skeleton` as a file of one frame (it has no channels).
    fn map(skeleton: Skeleton, user: Option<&UserMapping>) -> Result<Mapping, MappingError> {
        let bvh = Bvh {
            skeleton,
            frame_time_s: 1.0 / 30.0,
            data: Vec::new(),
            frames: 1,
            declared_frames: 1,
            warnings: Vec::new(),
        };
        map_skeleton(&bvh, &Kinematics::new(&bvh), user)
    }

    fn skeleton(names: &[&str]) -> Skeleton {
        // A chain is enough for name lookup.
        let joints = names
            .iter()
            .enumerate()
            .map(|(i, n)| BvhJoint {
                name: n.to_string(),
                parent: i.checked_sub(1),
                offset: DVec3::Y,
                channels: vec![],
                first_channel: 0,
                end_site: (i + 1 == names.len()).then_some(DVec3::Y),
                line: 0,
            })
            .collect();
        Skeleton { joints }
    }

    const MIXAMO: &[&str] = &[
        "mixamorig:Hips",
        "mixamorig:Spine",
        "mixamorig:Spine1",
        "mixamorig:Spine2",
        "mixamorig:Neck",
        "mixamorig:LeftArm",
        "mixamorig:LeftForeArm",
        "mixamorig:LeftHand",
        "mixamorig:RightArm",
        "mixamorig:RightForeArm",
        "mixamorig:RightHand",
        "mixamorig:Head",
    ];

    #[test]
    fn mixamo_names_map_through_their_namespace_prefix() {
        let m = map(skeleton(MIXAMO), None).unwrap();
        assert_eq!(m.scheme, "mixamo");
        assert!(m.missing_required().is_empty());
        assert_eq!(m.get(Landmark::Joint(Joint::Chest)).unwrap().joint, 3);
        assert_eq!(m.get(Landmark::HeadTop), Some(SourcePoint { joint: 11, end_site: true }));
    }

    #[test]
    fn missing_required_landmarks_are_listed() {
        let m = map(skeleton(&["Hips", "Spine", "Neck", "Head"]), None).unwrap();
        let missing: Vec<&str> = m.missing_required().iter().map(|l| l.name()).collect();
        // `Spine` can serve as the chest (CMU table); nothing serves as the
        // spine below it, and there are no arms at all.
        assert_eq!(
            missing,
            ["spine", "left_shoulder", "left_elbow", "left_wrist", "right_shoulder", "right_elbow", "right_wrist"]
        );
    }

    #[test]
    fn a_user_mapping_overrides_and_completes_the_built_in_scheme() {
        let names = ["Bip01 Pelvis", "Bip01 Spine", "Waist", "Bip01 Neck", "Bip01 Head"];
        let user = UserMapping::parse("chest = \"Waist\"\nhead_top = { end_of = \"Bip01 Head\" }\n", "m.toml").unwrap();
        let m = map(skeleton(&names), Some(&user)).unwrap();
        assert_eq!(m.get(Landmark::Joint(Joint::Chest)).unwrap().joint, 2);
        assert_eq!(m.get(Landmark::HeadTop), Some(SourcePoint { joint: 4, end_site: true }));
    }

    #[test]
    fn user_mapping_errors_name_the_file_and_the_problem() {
        let err = UserMapping::parse("elbow = \"X\"", "m.toml").unwrap_err().to_string();
        assert!(err.starts_with("m.toml: `elbow` is not a canonical joint"), "{err}");
        let err = UserMapping::parse("chest = 3", "m.toml").unwrap_err().to_string();
        assert!(err.contains("must be a joint name"), "{err}");
        let user = UserMapping::parse("chest = \"Nope\"", "m.toml").unwrap();
        let err = map(skeleton(&["Hips"]), Some(&user)).unwrap_err().to_string();
        assert!(err.contains("no joint `Nope`") && err.contains("Hips"), "{err}");
        let err = UserMapping::parse("chest = [", "m.toml").unwrap_err().to_string();
        assert!(err.starts_with("m.toml: not valid TOML"), "{err}");
    }
}
