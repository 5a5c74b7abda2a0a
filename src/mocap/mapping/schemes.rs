//! The naming schemes of common exporters, matched through one normal form
//! of a joint's name, so that `UpperArm_L`, `LeftUpperArm`, `upper_arm.L`,
//! `L_UpperArm`, `upperarm_l` and `mixamorig:LeftUpperArm` are one name.

use super::{Landmark, SourcePoint};
use crate::mocap::bvh::Skeleton;
use std::collections::BTreeMap;

/// The person's side a name says a joint is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Side {
    Left,
    Right,
}

/// A joint name reduced to what it says: the side (if any) and the rest,
/// lower case, without separators, namespaces or exporter prefixes, every
/// number without leading zeros (`spine.001`, `Spine01` and `spine_1` are
/// all `spine1`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NormalName {
    pub side: Option<Side>,
    pub key: String,
}

/// Leading words exporters put before every joint's own name.
const PREFIXES: &[&[&str]] = &[&["mixamorig"], &["def"], &["org"], &["cc", "base"], &["armature"]];

/// Leading words followed by a number (`Bip01`, `Character1`).
const NUMBERED_PREFIXES: &[&str] = &["bip", "character"];

/// The normal form of a joint name.
pub fn normalize(name: &str) -> NormalName {
    let base = name.rsplit([':', '|']).next().unwrap_or(name);
    let mut words = split_words(base);
    strip_prefixes(&mut words);
    let side_of = |w: &str| match w {
        "l" | "left" => Some(Side::Left),
        "r" | "right" => Some(Side::Right),
        _ => None,
    };
    let mut side = None;
    if words.len() > 1 {
        let n = words.len();
        // The side is the first or last word, or the one before a trailing
        // number (`DEF-upper_arm.L.001`).
        let at = if side_of(&words[0]).is_some() {
            Some(0)
        } else if side_of(&words[n - 1]).is_some() {
            Some(n - 1)
        } else if n > 2 && is_number(&words[n - 1]) && side_of(&words[n - 2]).is_some() {
            Some(n - 2)
        } else {
            None
        };
        if let Some(at) = at {
            side = side_of(&words[at]);
            words.remove(at);
        }
    }
    NormalName { side, key: words.concat() }
}

/// Words of a name: split at separators, at lower-to-upper case changes
/// (`LeftUpLeg`), before the last capital of a run of capitals followed by a
/// lower-case letter (`LHipJoint` is `L Hip Joint`), and between letters and
/// digits. Lower case; numbers lose their leading zeros.
fn split_words(name: &str) -> Vec<String> {
    let chars: Vec<char> = name.chars().collect();
    let mut words = Vec::new();
    let mut word = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if !c.is_alphanumeric() {
            push_word(&mut words, &mut word);
            continue;
        }
        if let Some(&prev) = i.checked_sub(1).and_then(|p| chars.get(p)) {
            let next_lower = chars.get(i + 1).is_some_and(|n| n.is_lowercase());
            let boundary = (prev.is_lowercase() && c.is_uppercase())
                || (prev.is_uppercase() && c.is_uppercase() && next_lower)
                || (prev.is_alphabetic() && c.is_ascii_digit())
                || (prev.is_ascii_digit() && c.is_alphabetic());
            if boundary && prev.is_alphanumeric() {
                push_word(&mut words, &mut word);
            }
        }
        word.extend(c.to_lowercase());
    }
    push_word(&mut words, &mut word);
    words
}

fn push_word(words: &mut Vec<String>, word: &mut String) {
    if word.is_empty() {
        return;
    }
    let w = std::mem::take(word);
    if is_number(&w) {
        let trimmed = w.trim_start_matches('0');
        words.push(if trimmed.is_empty() { "0".into() } else { trimmed.into() });
    } else {
        words.push(w);
    }
}

fn is_number(w: &str) -> bool {
    !w.is_empty() && w.bytes().all(|b| b.is_ascii_digit())
}

/// Removes exporter prefixes, keeping at least one word.
fn strip_prefixes(words: &mut Vec<String>) {
    loop {
        let fixed = PREFIXES.iter().find(|p| words.len() > p.len() && words.iter().zip(p.iter()).all(|(w, p)| w == p));
        if let Some(p) = fixed {
            words.drain(..p.len());
            continue;
        }
        let numbered = words.len() > 2 && NUMBERED_PREFIXES.contains(&words[0].as_str()) && is_number(&words[1]);
        if numbered {
            words.drain(..2);
            continue;
        }
        break;
    }
}

/// A built-in naming scheme: for each landmark, the normal keys to try in
/// order. A `*` landmark stands for both sides, and its keys match joints
/// whose name says that side. `end:KEY` is the End Site of joint KEY.
pub struct Scheme {
    pub name: &'static str,
    entries: &'static [(&'static str, &'static [&'static str])],
}

/// Tried in order; the first of equally good schemes wins.
pub const SCHEMES: &[Scheme] = &[
    // MotionBuilder's actor names and the CMU captures converted with them
    // (`LeftCollar`, `LeftShoulder`, `LeftElbow`, `LeftWrist`).
    Scheme {
        name: "cmu",
        entries: &[
            ("pelvis", &["hips"]),
            ("spine", &["chest", "lowerback"]),
            ("chest", &["chest2", "spine1", "spine"]),
            ("neck", &["neck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("*_shoulder", &["shoulder"]),
            ("*_elbow", &["elbow"]),
            ("*_wrist", &["wrist"]),
            ("*_hand_tip", &["fingers", "end:fingers"]),
            ("*_thumb", &["end:thumb", "thumb"]),
            ("*_hip", &["hip"]),
            ("*_knee", &["knee"]),
            ("*_ankle", &["ankle"]),
            ("*_toe", &["toe"]),
        ],
    },
    Scheme {
        name: "74-joint",
        entries: &[
            ("pelvis", &["hips"]),
            ("spine", &["spine2"]),
            ("chest", &["spine4"]),
            ("neck", &["neck"]),
            ("head", &["head"]),
            ("head_top", &["headtip", "end:headtip"]),
            ("*_shoulder", &["arm"]),
            ("*_elbow", &["forearm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["finger3proximal", "finger3metacarpal"]),
            ("*_thumb", &["finger1metacarpal"]),
            ("*_hip", &["thigh"]),
            ("*_knee", &["shin"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toe"]),
        ],
    },
    Scheme {
        name: "27-joint",
        entries: &[
            ("pelvis", &["hips"]),
            ("spine", &["spine1"]),
            ("chest", &["spine3"]),
            ("neck", &["neck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("*_shoulder", &["arm"]),
            ("*_elbow", &["forearm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["handend"]),
            ("*_thumb", &["handthumb1"]),
            ("*_hip", &["upleg"]),
            ("*_knee", &["leg"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toebase"]),
        ],
    },
    // Mixamo (`mixamorig:` or not), MotionBuilder's HumanIK and the CMU BVH
    // conversions (`LeftUpLeg`, `LeftArm`, `LeftForeArm`).
    Scheme {
        name: "mixamo",
        entries: &[
            ("pelvis", &["hips"]),
            ("spine", &["spine"]),
            ("chest", &["spine2", "spine1"]),
            ("neck", &["neck"]),
            ("head", &["head"]),
            ("head_top", &["headtopend", "end:headtopend", "end:head"]),
            ("*_shoulder", &["arm"]),
            ("*_elbow", &["forearm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["handmiddle1", "handindex1", "inhandmiddle"]),
            ("*_thumb", &["handthumb1"]),
            ("*_hip", &["upleg"]),
            ("*_knee", &["leg"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toebase", "toe"]),
        ],
    },
    // Unity's humanoid (`LeftUpperArm`, and `UpperArm_L` as the Bandai Namco
    // captures write it).
    Scheme {
        name: "unity",
        entries: &[
            ("pelvis", &["hips"]),
            ("spine", &["spine"]),
            ("chest", &["upperchest", "chest"]),
            ("neck", &["neck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("*_shoulder", &["upperarm"]),
            ("*_elbow", &["lowerarm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["middleproximal", "indexproximal"]),
            ("*_thumb", &["thumbproximal"]),
            ("*_hip", &["upperleg"]),
            ("*_knee", &["lowerleg"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toes", "toe"]),
        ],
    },
    // MotionBuilder's older names with an abdomen (`Ab`, `LeftCollar`).
    Scheme {
        name: "motionbuilder",
        entries: &[
            ("pelvis", &["hips"]),
            ("spine", &["ab", "abdomen", "lowerback", "spine"]),
            ("chest", &["chest2", "chest"]),
            ("neck", &["neck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("*_shoulder", &["shoulder"]),
            ("*_elbow", &["elbow"]),
            ("*_wrist", &["wrist", "hand"]),
            ("*_hand_tip", &["fingers", "end:hand", "end:wrist"]),
            ("*_hip", &["hip", "upleg"]),
            ("*_knee", &["knee"]),
            ("*_ankle", &["ankle"]),
            ("*_toe", &["toe"]),
        ],
    },
    // The CMU database's own ASF names (`lhumerus`, `lfemur`, `thorax`).
    Scheme {
        name: "cmu-asf",
        entries: &[
            ("pelvis", &["root", "hips"]),
            ("spine", &["lowerback"]),
            ("chest", &["thorax", "upperback"]),
            ("neck", &["lowerneck", "upperneck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("*_shoulder", &["humerus"]),
            ("*_elbow", &["radius"]),
            ("*_wrist", &["wrist"]),
            ("*_hand_tip", &["hand", "fingers"]),
            ("*_thumb", &["thumb"]),
            ("*_hip", &["femur"]),
            ("*_knee", &["tibia"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toes"]),
        ],
    },
    // Blender's human metarig and Rigify's deform bones (`upper_arm.L`,
    // `DEF-forearm.L`, `spine.003`).
    Scheme {
        name: "blender",
        entries: &[
            ("pelvis", &["spine", "hips"]),
            ("spine", &["spine1"]),
            ("chest", &["spine3", "spine2"]),
            ("neck", &["spine4", "neck"]),
            ("head", &["spine6", "spine5", "head"]),
            ("head_top", &["end:spine6", "end:head"]),
            ("*_shoulder", &["upperarm"]),
            ("*_elbow", &["forearm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["fmiddle1", "fmiddle01"]),
            ("*_thumb", &["thumb1"]),
            ("*_hip", &["thigh"]),
            ("*_knee", &["shin"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toe"]),
        ],
    },
    // Daz Genesis (`lShldrBend`, `abdomenLower`, `hip`).
    Scheme {
        name: "daz",
        entries: &[
            ("pelvis", &["hip"]),
            ("spine", &["abdomenlower", "abdomen"]),
            ("chest", &["chestupper", "chest"]),
            ("neck", &["necklower", "neck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("*_shoulder", &["shldrbend", "shldr"]),
            ("*_elbow", &["forearmbend", "forearm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["mid1"]),
            ("*_thumb", &["thumb1"]),
            ("*_hip", &["thighbend", "thigh"]),
            ("*_knee", &["shin"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toe", "metatarsals"]),
        ],
    },
    // Reallusion Character Creator (`CC_Base_L_Upperarm`, `CC_Base_Waist`).
    Scheme {
        name: "reallusion",
        entries: &[
            ("pelvis", &["hip"]),
            ("spine", &["waist", "spine1"]),
            ("chest", &["spine2"]),
            ("neck", &["necktwist1", "neck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("*_shoulder", &["upperarm"]),
            ("*_elbow", &["forearm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["mid1"]),
            ("*_thumb", &["thumb1"]),
            ("*_hip", &["thigh"]),
            ("*_knee", &["calf"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toebase"]),
        ],
    },
    // Unreal's mannequin (`upperarm_l`, `spine_03`, `calf_l`).
    Scheme {
        name: "unreal",
        entries: &[
            ("pelvis", &["pelvis"]),
            ("spine", &["spine1"]),
            ("chest", &["spine5", "spine3"]),
            ("neck", &["neck1", "neck"]),
            ("head", &["head"]),
            ("head_top", &["end:head"]),
            ("*_shoulder", &["upperarm"]),
            ("*_elbow", &["lowerarm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["middle1"]),
            ("*_thumb", &["thumb1"]),
            ("*_hip", &["thigh"]),
            ("*_knee", &["calf"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["ball"]),
        ],
    },
    // 3ds Max Biped (`Bip01 L UpperArm`).
    Scheme {
        name: "biped",
        entries: &[
            ("pelvis", &["pelvis", "bip1"]),
            ("spine", &["spine", "spine1"]),
            ("chest", &["spine2", "spine1"]),
            ("neck", &["neck"]),
            ("head", &["head"]),
            ("head_top", &["headnub", "end:head"]),
            ("*_shoulder", &["upperarm"]),
            ("*_elbow", &["forearm"]),
            ("*_wrist", &["hand"]),
            ("*_hand_tip", &["finger2", "finger1"]),
            ("*_thumb", &["finger0"]),
            ("*_hip", &["thigh"]),
            ("*_knee", &["calf"]),
            ("*_ankle", &["foot"]),
            ("*_toe", &["toe0"]),
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
            ("*_shoulder", &["shoulder"]),
            ("*_elbow", &["elbow"]),
            ("*_wrist", &["wrist"]),
            ("*_hand_tip", &["end:wrist"]),
            ("*_hip", &["hip"]),
            ("*_knee", &["knee"]),
            ("*_ankle", &["ankle"]),
            ("*_toe", &["end:ankle"]),
        ],
    },
];

/// Joint names in normal form, over the joints of one body.
pub struct NormalNames<'a> {
    skeleton: &'a Skeleton,
    names: Vec<Option<NormalName>>,
}

impl<'a> NormalNames<'a> {
    /// The normal names of the joints `in_body` keeps.
    pub fn new(skeleton: &'a Skeleton, in_body: impl Fn(usize) -> bool) -> NormalNames<'a> {
        let names =
            skeleton.joints.iter().enumerate().map(|(j, joint)| in_body(j).then(|| normalize(&joint.name))).collect();
        NormalNames { skeleton, names }
    }

    /// The normal name of joint `j`, if it is in the body.
    pub fn get(&self, j: usize) -> Option<&NormalName> {
        self.names[j].as_ref()
    }

    /// The first joint (in the file's order) whose name is `key` on `side`.
    /// A sided key also matches a name that glues the side's letter or word
    /// to it (`lfemur`, `rhand`).
    fn find(&self, key: &str, side: Option<Side>) -> Option<usize> {
        let glued = |n: &NormalName| match side {
            Some(Side::Left) => n.side.is_none() && ["l", "left"].iter().any(|s| n.key.strip_prefix(s) == Some(key)),
            Some(Side::Right) => n.side.is_none() && ["r", "right"].iter().any(|s| n.key.strip_prefix(s) == Some(key)),
            None => false,
        };
        self.names.iter().position(|n| n.as_ref().is_some_and(|n| (n.side == side && n.key == key) || glued(n)))
    }

    /// A scheme's candidate: a joint, or `end:KEY` for its End Site (which
    /// must have a length: a zero End Site says nothing about a direction).
    fn resolve(&self, candidate: &str, side: Option<Side>) -> Option<SourcePoint> {
        let (key, end_site) = match candidate.strip_prefix("end:") {
            Some(k) => (k, true),
            None => (candidate, false),
        };
        let joint = self.find(key, side)?;
        if end_site && self.skeleton.joints[joint].end_site.is_none_or(|e| e.length() <= 1e-9) {
            return None;
        }
        Some(SourcePoint { joint, end_site })
    }
}

/// The points a scheme's table finds in a skeleton.
pub fn apply(scheme: &Scheme, names: &NormalNames) -> BTreeMap<Landmark, SourcePoint> {
    let mut points = BTreeMap::new();
    for (key, candidates) in scheme.entries {
        let sides: &[(Option<Side>, &str)] = if key.starts_with('*') {
            &[(Some(Side::Left), "left"), (Some(Side::Right), "right")]
        } else {
            &[(None, "")]
        };
        for &(side, word) in sides {
            let name = key.replacen('*', word, 1);
            let landmark = Landmark::from_name(&name).expect("scheme keys are landmarks");
            if let Some(point) = candidates.iter().find_map(|c| names.resolve(c, side)) {
                points.insert(landmark, point);
            }
        }
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    fn n(name: &str) -> (Option<Side>, String) {
        let n = normalize(name);
        (n.side, n.key)
    }

    #[test]
    fn one_name_written_many_ways_has_one_normal_form() {
        let left_upper_arm = (Some(Side::Left), "upperarm".to_string());
        for name in [
            "UpperArm_L",
            "LeftUpperArm",
            "upper_arm.L",
            "L_UpperArm",
            "upperarm_l",
            "mixamorig:LeftUpperArm",
            "mixamorig_LeftUpperArm",
            "CC_Base_L_Upperarm",
            "DEF-upper_arm.L",
            "Bip01 L UpperArm",
            "Character1_LeftUpperArm",
            "Armature|upper_arm.L",
        ] {
            assert_eq!(n(name), left_upper_arm, "{name}");
        }
        assert_eq!(n("DEF-upper_arm.L.001"), (Some(Side::Left), "upperarm1".into()));
        assert_eq!(n("lShldrBend"), (Some(Side::Left), "shldrbend".into()));
        assert_eq!(n("LHipJoint"), (Some(Side::Left), "hipjoint".into()));
        assert_eq!(n("RThumb"), (Some(Side::Right), "thumb".into()));
        assert_eq!(n("spine.001"), (None, "spine1".into()));
        assert_eq!(n("Spine01"), (None, "spine1".into()));
        assert_eq!(n("spine_05"), (None, "spine5".into()));
        assert_eq!(n("LowerBack"), (None, "lowerback".into()));
        assert_eq!(n("Leg"), (None, "leg".into()));
        assert_eq!(n("Bip01"), (None, "bip1".into()));
        assert_eq!(n("HeadTop_End"), (None, "headtopend".into()));
        assert_eq!(n("lfemur"), (None, "lfemur".into()));
    }
}
