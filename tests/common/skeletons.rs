//! Source skeletons made here in the naming and topology of common
//! exporters, carrying a canonical motion: the corpus of renamings the
//! mapping is tested on. Each source joint sits on a canonical bone and
//! turns with it, so the canonical motion is the truth its retargeting must
//! give back.

use glam::{DQuat, DVec3};
use imitate::mocap::body::Joint;
use imitate::mocap::bvh::{Bvh, Channel, Joint as BvhJoint, Skeleton};
use imitate::mocap::math::{Axis, EulerOrder};
use imitate::mocap::pose::{Motion, Pose};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// An exporter's names and topology. Names hold a side placeholder:
/// `{L}` (L/R), `{Left}` (Left/Right) or `{l}` (l/r).
#[derive(Clone, Debug)]
pub struct Template {
    pub scheme: &'static str,
    /// A joint above the pelvis at the ground (Bandai's `joint_Root`).
    pub ground_root: Option<&'static str>,
    pub pelvis: &'static str,
    /// One joint bearing both legs below the pelvis (Daz, Reallusion).
    pub leg_root: Option<&'static str>,
    /// Joints between pelvis and chest.
    pub spine: &'static [&'static str],
    pub chest: &'static str,
    /// Joints between chest and head.
    pub neck: &'static [&'static str],
    pub head: &'static str,
    pub head_tip: Option<&'static str>,
    pub clavicle: Option<&'static str>,
    pub upper_arm: &'static str,
    pub forearm: &'static str,
    pub hand: &'static str,
    /// A bone from the pelvis to the hip (CMU's `LHipJoint`).
    pub hip_bone: Option<&'static str>,
    pub thigh: &'static str,
    pub shin: &'static str,
    pub foot: &'static str,
    pub toe: &'static str,
}

const BASE: Template = Template {
    scheme: "",
    ground_root: None,
    pelvis: "Hips",
    leg_root: None,
    spine: &["Spine"],
    chest: "Chest",
    neck: &["Neck"],
    head: "Head",
    head_tip: None,
    clavicle: None,
    upper_arm: "",
    forearm: "",
    hand: "",
    hip_bone: None,
    thigh: "",
    shin: "",
    foot: "",
    toe: "",
};

/// The naming schemes of the exporters users bring.
pub fn templates() -> Vec<Template> {
    vec![
        Template {
            scheme: "unity (Bandai)",
            ground_root: Some("joint_Root"),
            clavicle: Some("Shoulder_{L}"),
            upper_arm: "UpperArm_{L}",
            forearm: "LowerArm_{L}",
            hand: "Hand_{L}",
            thigh: "UpperLeg_{L}",
            shin: "LowerLeg_{L}",
            foot: "Foot_{L}",
            toe: "Toes_{L}",
            ..BASE
        },
        Template {
            scheme: "unity",
            spine: &["Spine", "Chest"],
            chest: "UpperChest",
            clavicle: Some("{Left}Shoulder"),
            upper_arm: "{Left}UpperArm",
            forearm: "{Left}LowerArm",
            hand: "{Left}Hand",
            thigh: "{Left}UpperLeg",
            shin: "{Left}LowerLeg",
            foot: "{Left}Foot",
            toe: "{Left}Toes",
            ..BASE
        },
        Template {
            scheme: "mixamo",
            pelvis: "mixamorig:Hips",
            spine: &["mixamorig:Spine", "mixamorig:Spine1"],
            chest: "mixamorig:Spine2",
            neck: &["mixamorig:Neck"],
            head: "mixamorig:Head",
            head_tip: Some("mixamorig:HeadTop_End"),
            clavicle: Some("mixamorig:{Left}Shoulder"),
            upper_arm: "mixamorig:{Left}Arm",
            forearm: "mixamorig:{Left}ForeArm",
            hand: "mixamorig:{Left}Hand",
            thigh: "mixamorig:{Left}UpLeg",
            shin: "mixamorig:{Left}Leg",
            foot: "mixamorig:{Left}Foot",
            toe: "mixamorig:{Left}ToeBase",
            ..BASE
        },
        Template {
            scheme: "mixamo, no prefix",
            spine: &["Spine", "Spine1"],
            chest: "Spine2",
            head_tip: Some("HeadTop_End"),
            clavicle: Some("{Left}Shoulder"),
            upper_arm: "{Left}Arm",
            forearm: "{Left}ForeArm",
            hand: "{Left}Hand",
            thigh: "{Left}UpLeg",
            shin: "{Left}Leg",
            foot: "{Left}Foot",
            toe: "{Left}ToeBase",
            ..BASE
        },
        Template {
            scheme: "CMU BVH",
            spine: &["LowerBack", "Spine"],
            chest: "Spine1",
            neck: &["Neck", "Neck1"],
            clavicle: Some("{Left}Shoulder"),
            upper_arm: "{Left}Arm",
            forearm: "{Left}ForeArm",
            hand: "{Left}Hand",
            hip_bone: Some("{L}HipJoint"),
            thigh: "{Left}UpLeg",
            shin: "{Left}Leg",
            foot: "{Left}Foot",
            toe: "{Left}ToeBase",
            ..BASE
        },
        Template {
            scheme: "motionbuilder",
            spine: &["Ab"],
            clavicle: Some("{Left}Collar"),
            upper_arm: "{Left}Shoulder",
            forearm: "{Left}Elbow",
            hand: "{Left}Wrist",
            thigh: "{Left}Hip",
            shin: "{Left}Knee",
            foot: "{Left}Ankle",
            toe: "{Left}Toe",
            ..BASE
        },
        Template {
            scheme: "cmu-asf",
            pelvis: "root",
            spine: &["lowerback", "upperback"],
            chest: "thorax",
            neck: &["lowerneck", "upperneck"],
            head: "head",
            clavicle: Some("{l}clavicle"),
            upper_arm: "{l}humerus",
            forearm: "{l}radius",
            hand: "{l}wrist",
            hip_bone: Some("{l}hipjoint"),
            thigh: "{l}femur",
            shin: "{l}tibia",
            foot: "{l}foot",
            toe: "{l}toes",
            ..BASE
        },
        Template {
            scheme: "blender metarig",
            pelvis: "spine",
            spine: &["spine.001", "spine.002"],
            chest: "spine.003",
            neck: &["spine.004", "spine.005"],
            head: "spine.006",
            clavicle: Some("shoulder.{L}"),
            upper_arm: "upper_arm.{L}",
            forearm: "forearm.{L}",
            hand: "hand.{L}",
            thigh: "thigh.{L}",
            shin: "shin.{L}",
            foot: "foot.{L}",
            toe: "toe.{L}",
            ..BASE
        },
        Template {
            scheme: "rigify",
            pelvis: "DEF-spine",
            spine: &["DEF-spine.001", "DEF-spine.002"],
            chest: "DEF-spine.003",
            neck: &["DEF-spine.004", "DEF-spine.005"],
            head: "DEF-spine.006",
            clavicle: Some("DEF-shoulder.{L}"),
            upper_arm: "DEF-upper_arm.{L}",
            forearm: "DEF-forearm.{L}",
            hand: "DEF-hand.{L}",
            thigh: "DEF-thigh.{L}",
            shin: "DEF-shin.{L}",
            foot: "DEF-foot.{L}",
            toe: "DEF-toe.{L}",
            ..BASE
        },
        Template {
            scheme: "daz",
            pelvis: "hip",
            leg_root: Some("pelvis"),
            spine: &["abdomenLower", "abdomenUpper", "chestLower"],
            chest: "chestUpper",
            neck: &["neckLower", "neckUpper"],
            head: "head",
            clavicle: Some("{l}Collar"),
            upper_arm: "{l}ShldrBend",
            forearm: "{l}ForearmBend",
            hand: "{l}Hand",
            thigh: "{l}ThighBend",
            shin: "{l}Shin",
            foot: "{l}Foot",
            toe: "{l}Toe",
            ..BASE
        },
        Template {
            scheme: "reallusion",
            pelvis: "CC_Base_Hip",
            leg_root: Some("CC_Base_Pelvis"),
            spine: &["CC_Base_Waist", "CC_Base_Spine01"],
            chest: "CC_Base_Spine02",
            neck: &["CC_Base_NeckTwist01", "CC_Base_NeckTwist02"],
            head: "CC_Base_Head",
            clavicle: Some("CC_Base_{L}_Clavicle"),
            upper_arm: "CC_Base_{L}_Upperarm",
            forearm: "CC_Base_{L}_Forearm",
            hand: "CC_Base_{L}_Hand",
            thigh: "CC_Base_{L}_Thigh",
            shin: "CC_Base_{L}_Calf",
            foot: "CC_Base_{L}_Foot",
            toe: "CC_Base_{L}_ToeBase",
            ..BASE
        },
        Template {
            scheme: "unreal",
            pelvis: "pelvis",
            spine: &["spine_01", "spine_02"],
            chest: "spine_03",
            neck: &["neck_01"],
            head: "head",
            clavicle: Some("clavicle_{l}"),
            upper_arm: "upperarm_{l}",
            forearm: "lowerarm_{l}",
            hand: "hand_{l}",
            thigh: "thigh_{l}",
            shin: "calf_{l}",
            foot: "foot_{l}",
            toe: "ball_{l}",
            ..BASE
        },
        Template {
            scheme: "biped",
            pelvis: "Bip01 Pelvis",
            spine: &["Bip01 Spine", "Bip01 Spine1"],
            chest: "Bip01 Spine2",
            neck: &["Bip01 Neck"],
            head: "Bip01 Head",
            head_tip: Some("Bip01 HeadNub"),
            clavicle: Some("Bip01 {L} Clavicle"),
            upper_arm: "Bip01 {L} UpperArm",
            forearm: "Bip01 {L} Forearm",
            hand: "Bip01 {L} Hand",
            thigh: "Bip01 {L} Thigh",
            shin: "Bip01 {L} Calf",
            foot: "Bip01 {L} Foot",
            toe: "Bip01 {L} Toe0",
            ..BASE
        },
        // No name says anything: joints are numbered.
        Template {
            scheme: "anonymous",
            pelvis: "j",
            spine: &["j", "j"],
            chest: "j",
            neck: &["j"],
            head: "j",
            clavicle: Some("j"),
            upper_arm: "j",
            forearm: "j",
            hand: "j",
            thigh: "j",
            shin: "j",
            foot: "j",
            toe: "j",
            ..BASE
        },
    ]
}

/// How a generated skeleton departs from its template's plain form.
#[derive(Clone, Copy, Debug, Default)]
pub struct Variation {
    /// Children listed in a random order.
    pub shuffled: bool,
    /// Twist bones half way along the upper arms, forearms and thighs.
    pub twist: bool,
    /// Three fingers of three joints and a thumb on each hand.
    pub fingers: bool,
    /// No joint between chest and head.
    pub no_neck: bool,
    /// Each joint's frame turned by its own constant rotation (the bind
    /// orientations exporters leave on joints), random Euler orders.
    pub bind_frames: bool,
    /// Z up and centimeters.
    pub z_up_cm: bool,
    pub seed: u64,
}

/// Which canonical joint a source joint sits at, for checking a mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct Truth {
    pub joint: Joint,
    pub name: String,
}

/// A skeleton made from a template: the file and, per canonical joint it
/// plays, the source joint's name (for the spine, every joint that may).
pub struct Generated {
    pub bvh: Bvh,
    pub truth: Vec<Truth>,
}

struct Part {
    name: String,
    parent: Option<usize>,
    /// Rest position, world, meters.
    rest: DVec3,
    /// The canonical joint whose frame the part turns with; none for a
    /// ground root, which stays put.
    follows: Option<Joint>,
}

fn sided(name: &str, left: bool) -> String {
    let pick = |l: &str, r: &str| if left { l.to_string() } else { r.to_string() };
    name.replace("{Left}", &pick("Left", "Right")).replace("{L}", &pick("L", "R")).replace("{l}", &pick("l", "r"))
}

/// Builds the source skeleton of `template` with `variation` and the BVH
/// of `motion` on it.
pub fn generate(template: &Template, variation: Variation, motion: &Motion) -> Generated {
    let body = &motion.body;
    let rest = body.forward(&Pose::rest(body));
    let at = |j: Joint| rest.position(j);
    let mut parts: Vec<Part> = Vec::new();
    let mut truth = Vec::new();
    let mut counter = 0usize;
    let mut add = |parts: &mut Vec<Part>, name: &str, parent: Option<usize>, rest: DVec3, follows: Option<Joint>| {
        let name = if template.scheme == "anonymous" {
            counter += 1;
            format!("j{counter}")
        } else {
            name.to_string()
        };
        parts.push(Part { name, parent, rest, follows });
        parts.len() - 1
    };
    let ground = template.ground_root.map(|n| add(&mut parts, n, None, DVec3::ZERO, None));
    let pelvis = add(&mut parts, template.pelvis, ground, at(Joint::Pelvis), Some(Joint::Pelvis));
    truth.push(Truth { joint: Joint::Pelvis, name: parts[pelvis].name.clone() });
    // Spine joints: one at the canonical spine joint, the others half way
    // to it or spread beyond it, so each sits on one canonical bone.
    let (p, s, c) = (at(Joint::Pelvis), at(Joint::Spine), at(Joint::Chest));
    let k = template.spine.len();
    let spots: Vec<(DVec3, Joint)> = match k {
        0 => vec![],
        1 => vec![(s, Joint::Spine)],
        _ => {
            let below = usize::from(k >= 3);
            let above = k - 1 - below;
            let mut v = Vec::new();
            if below == 1 {
                v.push((p.lerp(s, 0.5), Joint::Pelvis));
            }
            v.push((s, Joint::Spine));
            for i in 1..=above {
                v.push((s.lerp(c, i as f64 / (above + 1) as f64), Joint::Spine));
            }
            v
        }
    };
    let mut top = pelvis;
    for (name, (spot, follows)) in template.spine.iter().zip(spots) {
        top = add(&mut parts, name, Some(top), spot, Some(follows));
        truth.push(Truth { joint: Joint::Spine, name: parts[top].name.clone() });
    }
    if k == 0 {
        truth.push(Truth { joint: Joint::Spine, name: parts[pelvis].name.clone() });
    }
    let chest = add(&mut parts, template.chest, Some(top), c, Some(Joint::Chest));
    truth.push(Truth { joint: Joint::Chest, name: parts[chest].name.clone() });
    let (n, h) = (at(Joint::Neck), at(Joint::Head));
    let necks: &[&str] = if variation.no_neck { &[] } else { template.neck };
    let mut top = chest;
    for (i, name) in necks.iter().enumerate() {
        let spot = if i == 0 { n } else { n.lerp(h, i as f64 / necks.len() as f64) };
        top = add(&mut parts, name, Some(top), spot, Some(if i == 0 { Joint::Chest } else { Joint::Neck }));
        if i == 0 {
            truth.push(Truth { joint: Joint::Neck, name: parts[top].name.clone() });
        }
    }
    let head = add(&mut parts, template.head, Some(top), h, Some(Joint::Head));
    truth.push(Truth { joint: Joint::Head, name: parts[head].name.clone() });
    if necks.is_empty() {
        truth.push(Truth { joint: Joint::Neck, name: parts[head].name.clone() });
    }
    if let Some(tip) = template.head_tip {
        add(&mut parts, tip, Some(head), h + body.end_site(Joint::Head).unwrap(), Some(Joint::Head));
    }
    for left in [true, false] {
        use Joint::*;
        let (shoulder, elbow, wrist) =
            if left { (LeftShoulder, LeftElbow, LeftWrist) } else { (RightShoulder, RightElbow, RightWrist) };
        let mut top = chest;
        if let Some(clavicle) = template.clavicle {
            top = add(&mut parts, &sided(clavicle, left), Some(top), c.lerp(at(shoulder), 0.25), Some(Chest));
        }
        let upper = add(&mut parts, &sided(template.upper_arm, left), Some(top), at(shoulder), Some(shoulder));
        let mut top = upper;
        if variation.twist {
            let twist = sided("{Left}UpperArmTwist", left);
            top = add(&mut parts, &twist, Some(top), at(shoulder).lerp(at(elbow), 0.5), Some(shoulder));
        }
        let fore = add(&mut parts, &sided(template.forearm, left), Some(top), at(elbow), Some(elbow));
        let mut top = fore;
        if variation.twist {
            let twist = sided("{Left}ForeArmTwist", left);
            top = add(&mut parts, &twist, Some(top), at(elbow).lerp(at(wrist), 0.5), Some(elbow));
        }
        let hand = add(&mut parts, &sided(template.hand, left), Some(top), at(wrist), Some(wrist));
        if variation.fingers {
            let tip = body.end_site(wrist).unwrap();
            for (finger, sideways) in [("Index", 0.012), ("Middle", 0.0), ("Ring", -0.012)] {
                let mut top = hand;
                for joint in 1..=3 {
                    let along = at(wrist) + tip * (0.45 + 0.18 * joint as f64) + DVec3::Z * sideways;
                    let name = sided(&format!("{{Left}}Hand{finger}{joint}"), left);
                    top = add(&mut parts, &name, Some(top), along, Some(wrist));
                }
            }
            let thumb = sided("{Left}HandThumb1", left);
            add(&mut parts, &thumb, Some(hand), at(wrist) + tip * 0.3 + DVec3::Z * 0.03, Some(wrist));
        }
        truth.extend(
            [(shoulder, upper), (elbow, fore), (wrist, hand)]
                .map(|(joint, part)| Truth { joint, name: parts[part].name.clone() }),
        );
    }
    let legs_from =
        template.leg_root.map(|n| add(&mut parts, n, Some(pelvis), p, Some(Joint::Pelvis))).unwrap_or(pelvis);
    for left in [true, false] {
        use Joint::*;
        let (hip, knee, ankle) = if left { (LeftHip, LeftKnee, LeftAnkle) } else { (RightHip, RightKnee, RightAnkle) };
        let mut top = legs_from;
        if let Some(bone) = template.hip_bone {
            top = add(&mut parts, &sided(bone, left), Some(top), p, Some(Pelvis));
        }
        let thigh = add(&mut parts, &sided(template.thigh, left), Some(top), at(hip), Some(hip));
        let mut top = thigh;
        if variation.twist {
            let twist = sided("{Left}UpLegTwist", left);
            top = add(&mut parts, &twist, Some(top), at(hip).lerp(at(knee), 0.5), Some(hip));
        }
        let shin = add(&mut parts, &sided(template.shin, left), Some(top), at(knee), Some(knee));
        let foot = add(&mut parts, &sided(template.foot, left), Some(shin), at(ankle), Some(ankle));
        add(
            &mut parts,
            &sided(template.toe, left),
            Some(foot),
            at(ankle) + body.end_site(ankle).unwrap() * 0.7,
            Some(ankle),
        );
        truth.extend(
            [(hip, thigh), (knee, shin), (ankle, foot)]
                .map(|(joint, part)| Truth { joint, name: parts[part].name.clone() }),
        );
    }
    Generated { bvh: to_bvh(&parts, variation, motion), truth }
}

/// The BVH of `motion` on `parts`, with each leaf's End Site along its
/// parent bone.
fn to_bvh(parts: &[Part], variation: Variation, motion: &Motion) -> Bvh {
    let mut rng = ChaCha8Rng::seed_from_u64(variation.seed);
    let orders = [EulerOrder::XYZ, EulerOrder::ZXY, EulerOrder::ZYX, EulerOrder::YXZ];
    let n = parts.len();
    let bind: Vec<DQuat> = (0..n)
        .map(|_| {
            if variation.bind_frames {
                let axis = DVec3::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
                DQuat::from_axis_angle(axis.normalize_or(DVec3::X), rng.gen_range(0.0..std::f64::consts::PI))
            } else {
                DQuat::IDENTITY
            }
        })
        .collect();
    let order: Vec<EulerOrder> = (0..n)
        .map(|_| if variation.bind_frames { *orders.choose(&mut rng).unwrap() } else { EulerOrder::ZXY })
        .collect();
    let (up, scale) = if variation.z_up_cm {
        (DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2), 100.0)
    } else {
        (DQuat::IDENTITY, 1.0)
    };
    // Declaration order: parents first, children in a (maybe shuffled) order.
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, part) in parts.iter().enumerate() {
        if let Some(p) = part.parent {
            children[p].push(i);
        }
    }
    if variation.shuffled {
        for c in &mut children {
            c.shuffle(&mut rng);
        }
    }
    let mut declared = Vec::with_capacity(n);
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        declared.push(i);
        stack.extend(children[i].iter().rev());
    }
    let index_of: Vec<usize> = {
        let mut v = vec![0; n];
        for (k, &i) in declared.iter().enumerate() {
            v[i] = k;
        }
        v
    };
    let mut joints = Vec::with_capacity(n);
    let mut next_channel = 0;
    for &i in &declared {
        let part = &parts[i];
        let rotations = order[i].0.map(Channel::Rotation);
        let channels: Vec<Channel> = if joints_translate(parts, i) {
            [Axis::X, Axis::Y, Axis::Z].map(Channel::Position).into_iter().chain(rotations).collect()
        } else {
            rotations.to_vec()
        };
        let offset = match part.parent {
            Some(p) => bind[p].inverse() * (part.rest - parts[p].rest) * scale,
            None => DVec3::ZERO,
        };
        let end_site = children[i].is_empty().then(|| {
            let along = part.parent.map_or(DVec3::Y, |p| (part.rest - parts[p].rest).normalize_or(DVec3::Y));
            bind[i].inverse() * along * 0.05 * scale
        });
        joints.push(BvhJoint {
            name: part.name.clone(),
            parent: part.parent.map(|p| index_of[p]),
            offset,
            first_channel: next_channel,
            end_site,
            channels,
            line: 0,
        });
        next_channel += joints.last().map_or(0, |j: &BvhJoint| j.channels.len());
    }
    let skeleton = Skeleton { joints };
    let rest = motion.body.forward(&Pose::rest(&motion.body));
    let mut data = Vec::with_capacity(motion.poses.len() * next_channel);
    for pose in &motion.poses {
        let frame = motion.body.forward(pose);
        let world: Vec<DQuat> =
            (0..n).map(|i| up * parts[i].follows.map_or(DQuat::IDENTITY, |f| frame.rotation(f)) * bind[i]).collect();
        for &i in &declared {
            let part = &parts[i];
            let parent_world = part.parent.map_or(DQuat::IDENTITY, |p| world[p]);
            if joints_translate(parts, i) {
                // Where the part is, in its parent's frame (the world for a
                // root), less the offset it already has.
                let position = match part.follows {
                    Some(f) => frame.position(f) + frame.rotation(f) * (part.rest - rest.position(f)),
                    None => part.rest,
                };
                let offset = if part.parent.is_some() { part.rest } else { DVec3::ZERO };
                data.extend((parent_world.inverse() * (up * position - up * offset) * scale).to_array());
            }
            let local = parent_world.inverse() * world[i];
            data.extend(order[i].from_quat(local).map(f64::to_degrees));
        }
    }
    Bvh {
        skeleton,
        frame_time_s: motion.frame_time_s,
        frames: motion.poses.len(),
        declared_frames: motion.poses.len() as u64,
        data,
        warnings: Vec::new(),
    }
}

/// The root, and the pelvis below a ground root, carry position channels.
fn joints_translate(parts: &[Part], i: usize) -> bool {
    parts[i].parent.is_none_or(|p| parts[p].follows.is_none())
}

/// The canonical motion every generated skeleton carries: the
/// demonstrator's hand circles, punches and dance, with bent knees.
pub fn motion() -> Motion {
    use imitate::mocap::synth::{Activity, SynthOptions, sequence_take};
    let options = SynthOptions { repetitions: 2, ..Default::default() };
    sequence_take(&[Activity::Circles, Activity::Punch, Activity::Twist], &options).motion
}
