//! Which source joints play which canonical parts: built-in tables for the
//! naming schemes of common exporters, and user mapping files.

use crate::mocap::body::Joint;
use crate::mocap::bvh::Skeleton;
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

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

/// A built-in naming scheme: for each landmark, the source names to try in
/// order. `end:NAME` means the End Site of joint NAME.
struct Scheme {
    name: &'static str,
    entries: &'static [(&'static str, &'static [&'static str])],
}

/// The arm and leg entries of a scheme whose left and right names differ
/// only by a `Left`/`Right` prefix are written once, with `*` for the side.
const SCHEMES: &[Scheme] = &[
    Scheme {
        name: "cmu",
        entries: &[
            ("pelvis", &["Hips"]),
            ("spine", &["Chest", "LowerBack"]),
            ("chest", &["Chest2", "Spine1", "Spine"]),
            ("neck", &["Neck"]),
            ("head", &["Head"]),
            ("head_top", &["end:Head"]),
            ("*_shoulder", &["*Shoulder"]),
            ("*_elbow", &["*Elbow"]),
            ("*_wrist", &["*Wrist"]),
            ("left_hand_tip", &["LFingers", "end:LFingers"]),
            ("right_hand_tip", &["RFingers", "end:RFingers"]),
            ("left_thumb", &["end:LThumb", "LThumb"]),
            ("right_thumb", &["end:RThumb", "RThumb"]),
            ("*_hip", &["*Hip"]),
            ("*_knee", &["*Knee"]),
            ("*_ankle", &["*Ankle"]),
            ("*_toe", &["*Toe"]),
        ],
    },
    Scheme {
        name: "74-joint",
        entries: &[
            ("pelvis", &["Hips"]),
            ("spine", &["Spine2"]),
            ("chest", &["Spine4"]),
            ("neck", &["Neck"]),
            ("head", &["Head"]),
            ("head_top", &["HeadTip", "end:HeadTip"]),
            ("*_shoulder", &["*Arm"]),
            ("*_elbow", &["*ForeArm"]),
            ("*_wrist", &["*Hand"]),
            ("*_hand_tip", &["*Finger3Proximal", "*Finger3Metacarpal"]),
            ("*_thumb", &["*Finger1Metacarpal"]),
            ("*_hip", &["*Thigh"]),
            ("*_knee", &["*Shin"]),
            ("*_ankle", &["*Foot"]),
            ("*_toe", &["*Toe"]),
        ],
    },
    Scheme {
        name: "27-joint",
        entries: &[
            ("pelvis", &["Hips"]),
            ("spine", &["Spine1"]),
            ("chest", &["Spine3"]),
            ("neck", &["Neck"]),
            ("head", &["Head"]),
            ("head_top", &["end:Head"]),
            ("*_shoulder", &["*Arm"]),
            ("*_elbow", &["*ForeArm"]),
            ("*_wrist", &["*Hand"]),
            ("*_hand_tip", &["*HandEnd"]),
            ("*_thumb", &["*HandThumb1"]),
            ("*_hip", &["*UpLeg"]),
            ("*_knee", &["*Leg"]),
            ("*_ankle", &["*Foot"]),
            ("*_toe", &["*ToeBase"]),
        ],
    },
    // Mixamo's `mixamorig:` names, which the 60-joint dance file shares.
    Scheme {
        name: "mixamo",
        entries: &[
            ("pelvis", &["Hips"]),
            ("spine", &["Spine"]),
            ("chest", &["Spine2", "Spine1"]),
            ("neck", &["Neck"]),
            ("head", &["Head"]),
            ("head_top", &["HeadTop_End", "end:HeadTop_End", "end:Head"]),
            ("*_shoulder", &["*Arm"]),
            ("*_elbow", &["*ForeArm"]),
            ("*_wrist", &["*Hand"]),
            ("*_hand_tip", &["*HandMiddle1", "*HandIndex1", "*InHandMiddle"]),
            ("*_thumb", &["*HandThumb1"]),
            ("*_hip", &["*UpLeg"]),
            ("*_knee", &["*Leg"]),
            ("*_ankle", &["*Foot"]),
            ("*_toe", &["*ToeBase", "*Toe"]),
        ],
    },
    // 3ds Max Biped (`Bip01 L UpperArm`).
    Scheme {
        name: "biped",
        entries: &[
            ("pelvis", &["Bip01 Pelvis", "Bip01"]),
            ("spine", &["Bip01 Spine", "Bip01 Spine1"]),
            ("chest", &["Bip01 Spine2", "Bip01 Spine1"]),
            ("neck", &["Bip01 Neck"]),
            ("head", &["Bip01 Head"]),
            ("head_top", &["Bip01 HeadNub", "end:Bip01 Head"]),
            ("left_shoulder", &["Bip01 L UpperArm"]),
            ("left_elbow", &["Bip01 L Forearm"]),
            ("left_wrist", &["Bip01 L Hand"]),
            ("left_hand_tip", &["Bip01 L Finger2", "Bip01 L Finger1"]),
            ("left_thumb", &["Bip01 L Finger0"]),
            ("right_shoulder", &["Bip01 R UpperArm"]),
            ("right_elbow", &["Bip01 R Forearm"]),
            ("right_wrist", &["Bip01 R Hand"]),
            ("right_hand_tip", &["Bip01 R Finger2", "Bip01 R Finger1"]),
            ("right_thumb", &["Bip01 R Finger0"]),
            ("left_hip", &["Bip01 L Thigh"]),
            ("left_knee", &["Bip01 L Calf"]),
            ("left_ankle", &["Bip01 L Foot"]),
            ("left_toe", &["Bip01 L Toe0"]),
            ("right_hip", &["Bip01 R Thigh"]),
            ("right_knee", &["Bip01 R Calf"]),
            ("right_ankle", &["Bip01 R Foot"]),
            ("right_toe", &["Bip01 R Toe0"]),
        ],
    },
    // What this project writes.
    Scheme {
        name: "canonical",
        entries: &[
            ("pelvis", &["pelvis"]),
            ("spine", &["spine"]),
            ("chest", &["chest"]),
            ("neck", &["neck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("left_shoulder", &["left_shoulder"]),
            ("left_elbow", &["left_elbow"]),
            ("left_wrist", &["left_wrist"]),
            ("left_hand_tip", &["end:left_wrist"]),
            ("right_shoulder", &["right_shoulder"]),
            ("right_elbow", &["right_elbow"]),
            ("right_wrist", &["right_wrist"]),
            ("right_hand_tip", &["end:right_wrist"]),
            ("left_hip", &["left_hip"]),
            ("left_knee", &["left_knee"]),
            ("left_ankle", &["left_ankle"]),
            ("left_toe", &["end:left_ankle"]),
            ("right_hip", &["right_hip"]),
            ("right_knee", &["right_knee"]),
            ("right_ankle", &["right_ankle"]),
            ("right_toe", &["end:right_ankle"]),
        ],
    },
];

/// The source point for every landmark that could be found.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapping {
    /// The built-in scheme the names came from (`user` where a mapping file
    /// gave them all).
    pub scheme: &'static str,
    pub points: BTreeMap<Landmark, SourcePoint>,
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
}

/// A mapping file: landmark name → source joint name, or `{ end_of = "J" }`
/// for the End Site of joint J.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UserMapping {
    pub path: String,
    entries: Vec<(Landmark, String, bool)>,
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

impl UserMapping {
    pub fn load(path: &Path) -> Result<UserMapping, MappingError> {
        let display = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|source| MappingError::Io { path: display.clone(), source })?;
        UserMapping::parse(&text, &display)
    }

    pub fn parse(text: &str, path: &str) -> Result<UserMapping, MappingError> {
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| MappingError::Toml { path: path.into(), message: e.to_string() })?;
        let mut entries = Vec::new();
        for (key, value) in table {
            let landmark = Landmark::from_name(&key).ok_or_else(|| MappingError::UnknownLandmark {
                path: path.into(),
                key: key.clone(),
                valid: Landmark::all().map(Landmark::name).collect::<Vec<_>>().join(", "),
            })?;
            let (joint, end_site) = match &value {
                toml::Value::String(s) => (s.clone(), false),
                toml::Value::Table(t) if t.len() == 1 => match t.get("end_of") {
                    Some(toml::Value::String(s)) => (s.clone(), true),
                    _ => {
                        return Err(MappingError::BadValue { path: path.into(), key });
                    }
                },
                _ => {
                    return Err(MappingError::BadValue { path: path.into(), key });
                }
            };
            entries.push((landmark, joint, end_site));
        }
        Ok(UserMapping { path: path.into(), entries })
    }
}

/// Finds the source point for every landmark: the user's mapping where it
/// gives one, else the built-in scheme that maps the most required
/// landmarks (then the most landmarks). Only the first root's hierarchy is
/// searched.
pub fn map_skeleton(skeleton: &Skeleton, user: Option<&UserMapping>) -> Result<Mapping, MappingError> {
    let first_root = skeleton.roots().next().unwrap_or(0);
    let in_body = |j: usize| skeleton.is_ancestor_or_self(first_root, j);
    let mut best: Option<Mapping> = None;
    let score = |m: &Mapping| {
        let required = m.points.keys().filter(|l| l.is_required()).count();
        (required, m.points.len())
    };
    for scheme in SCHEMES {
        let mut points = BTreeMap::new();
        for (landmark, candidates) in expand(scheme) {
            if let Some(point) = candidates.iter().find_map(|c| resolve(skeleton, c, &in_body)) {
                points.insert(landmark, point);
            }
        }
        let mapping = Mapping { scheme: scheme.name, points };
        if best.as_ref().is_none_or(|b| score(&mapping) > score(b)) {
            best = Some(mapping);
        }
    }
    let mut mapping = best.unwrap_or(Mapping { scheme: "none", points: BTreeMap::new() });
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
            mapping.points.insert(*landmark, SourcePoint { joint: index, end_site: *end_site });
        }
        // Every mapped point came from the user's file.
        if mapping.points.len() == user.entries.len() {
            mapping.scheme = "user";
        }
    }
    Ok(mapping)
}

/// The source joints' names, for messages.
pub fn joint_list(skeleton: &Skeleton) -> String {
    skeleton.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(", ")
}

/// A scheme's entries with `*` expanded to both sides.
fn expand(scheme: &Scheme) -> Vec<(Landmark, Vec<String>)> {
    let mut out = Vec::new();
    for (key, names) in scheme.entries {
        if let Some(rest) = key.strip_prefix('*') {
            for (side, prefix) in [("left", "Left"), ("right", "Right")] {
                let landmark = Landmark::from_name(&format!("{side}{rest}")).expect("scheme keys are landmarks");
                out.push((landmark, names.iter().map(|n| n.replace('*', prefix)).collect()));
            }
        } else {
            let landmark = Landmark::from_name(key).expect("scheme keys are landmarks");
            out.push((landmark, names.iter().map(|n| n.to_string()).collect()));
        }
    }
    out
}

/// Finds a candidate name: exactly, or ignoring case and any namespace
/// prefix (`mixamorig:Hips`, `Armature|Hips`).
fn resolve(skeleton: &Skeleton, candidate: &str, in_body: &impl Fn(usize) -> bool) -> Option<SourcePoint> {
    let (name, end_site) = match candidate.strip_prefix("end:") {
        Some(n) => (n, true),
        None => (candidate, false),
    };
    let joints = &skeleton.joints;
    let found = (0..joints.len())
        .find(|&j| in_body(j) && joints[j].name == name)
        .or_else(|| (0..joints.len()).find(|&j| in_body(j) && base_name(&joints[j].name).eq_ignore_ascii_case(name)))?;
    if end_site && joints[found].end_site.is_none() {
        return None;
    }
    Some(SourcePoint { joint: found, end_site })
}

fn base_name(name: &str) -> &str {
    name.rsplit([':', '|']).next().unwrap_or(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::bvh::{Joint as BvhJoint, Skeleton};
    use glam::DVec3;

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
        let m = map_skeleton(&skeleton(MIXAMO), None).unwrap();
        assert_eq!(m.scheme, "mixamo");
        assert!(m.missing_required().is_empty());
        assert_eq!(m.get(Landmark::Joint(Joint::Chest)).unwrap().joint, 3);
        assert_eq!(m.get(Landmark::HeadTop), Some(SourcePoint { joint: 11, end_site: true }));
    }

    #[test]
    fn missing_required_landmarks_are_listed() {
        let m = map_skeleton(&skeleton(&["Hips", "Spine", "Neck", "Head"]), None).unwrap();
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
        let m = map_skeleton(&skeleton(&names), Some(&user)).unwrap();
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
        let err = map_skeleton(&skeleton(&["Hips"]), Some(&user)).unwrap_err().to_string();
        assert!(err.contains("no joint `Nope`") && err.contains("Hips"), "{err}");
        let err = UserMapping::parse("chest = [", "m.toml").unwrap_err().to_string();
        assert!(err.starts_with("m.toml: not valid TOML"), "{err}");
    }
}
