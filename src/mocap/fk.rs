//! Forward kinematics of a source BVH skeleton: each joint's world position
//! and rotation in each frame, in file units.
//!
//! Position channels below the root come in two conventions: deltas added
//! to the joint's OFFSET, or absolute local positions that already include
//! it (Blender-style exporters). Reading one as the other doubles a bone,
//! so each joint's convention is detected from its data.

use crate::mocap::bvh::{Bvh, Channel};
use crate::mocap::math::Axis;
use glam::{DQuat, DVec3};

/// How a joint's position channels relate to its OFFSET.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionMode {
    /// Local position = OFFSET + channels.
    Delta,
    /// Local position = channels (axes without a channel keep the OFFSET).
    Absolute,
}

/// Frames examined when detecting a convention or sampling a take.
pub const SAMPLE_FRAMES: usize = 256;

#[derive(Clone, Debug)]
struct JointPlan {
    parent: Option<usize>,
    offset: DVec3,
    rotations: Vec<(usize, Axis)>,
    positions: [Option<usize>; 3],
    mode: PositionMode,
}

/// Precomputed channel decoding for one skeleton.
#[derive(Clone, Debug)]
pub struct Kinematics {
    joints: Vec<JointPlan>,
}

/// A joint's world transform in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub position: DVec3,
    pub rotation: DQuat,
}

impl Default for Transform {
    fn default() -> Self {
        Transform { position: DVec3::ZERO, rotation: DQuat::IDENTITY }
    }
}

impl Kinematics {
    /// Plans the decoding of `bvh`'s channels, detecting each joint's
    /// position convention from (up to [`SAMPLE_FRAMES`] of) its frames.
    pub fn new(bvh: &Bvh) -> Kinematics {
        let samples = sample_frames(bvh.frames);
        let joints = bvh
            .skeleton
            .joints
            .iter()
            .map(|joint| -> (JointPlan, bool) {
                let mut rotations = Vec::new();
                let mut positions = [None; 3];
                for (k, channel) in joint.channels.iter().enumerate() {
                    let index = joint.first_channel + k;
                    match channel {
                        Channel::Rotation(axis) => rotations.push((index, *axis)),
                        Channel::Position(axis) => positions[axis.index()] = Some(index),
                    }
                }
                let (mode, settled) = detect_mode(bvh, &samples, joint.offset, &positions);
                (JointPlan { parent: joint.parent, offset: joint.offset, rotations, positions, mode }, settled)
            })
            .collect();
        Kinematics { joints: one_convention(joints) }
    }

    /// The position convention of joint `j`, when it has position channels.
    pub fn position_mode(&self, j: usize) -> Option<PositionMode> {
        self.joints[j].positions.iter().any(Option::is_some).then_some(self.joints[j].mode)
    }

    /// Local translation and rotation of joint `j` in `frame`.
    #[inline]
    pub fn local(&self, j: usize, frame: &[f64]) -> (DVec3, DQuat) {
        let plan = &self.joints[j];
        let mut rotation = DQuat::IDENTITY;
        for &(index, axis) in &plan.rotations {
            rotation *= axis.rotation(frame[index].to_radians());
        }
        let mut translation = plan.offset;
        for (axis, channel) in plan.positions.iter().enumerate() {
            if let Some(index) = channel {
                match plan.mode {
                    PositionMode::Delta => translation[axis] += frame[*index],
                    PositionMode::Absolute => translation[axis] = frame[*index],
                }
            }
        }
        (translation, rotation)
    }

    /// World transforms of the joints marked in `needed` (which must include
    /// every ancestor of a marked joint); others are left untouched.
    pub fn world(&self, frame: &[f64], needed: &[bool], out: &mut [Transform]) {
        for (j, plan) in self.joints.iter().enumerate() {
            if !needed[j] {
                continue;
            }
            let (t, r) = self.local(j, frame);
            out[j] = match plan.parent {
                None => Transform { position: t, rotation: r },
                Some(p) => {
                    let parent = out[p];
                    Transform { position: parent.position + parent.rotation * t, rotation: parent.rotation * r }
                }
            };
        }
    }

    /// Marks `joints` and all their ancestors.
    pub fn with_ancestors(&self, joints: impl IntoIterator<Item = usize>) -> Vec<bool> {
        let mut needed = vec![false; self.joints.len()];
        for j in joints {
            let mut at = Some(j);
            while let Some(k) = at {
                if needed[k] {
                    break;
                }
                needed[k] = true;
                at = self.joints[k].parent;
            }
        }
        needed
    }
}

/// Up to [`SAMPLE_FRAMES`] frame indices spread evenly over the take.
pub fn sample_frames(frames: usize) -> Vec<usize> {
    spread_frames(frames, SAMPLE_FRAMES)
}

/// Up to `count` frame indices spread evenly over the take, first and last
/// included.
pub fn spread_frames(frames: usize, count: usize) -> Vec<usize> {
    let n = frames.min(count);
    (0..n).map(|i| if n == 1 { 0 } else { i * (frames - 1) / (n - 1) }).collect()
}

/// A joint's channels are settled when they keep within this share of
/// the offset's length of their median: the joint holds its place on its
/// parent, as a bone does, so whether they sit at the offset or at zero
/// shows the convention plainly.
const SETTLED_SHARE: f64 = 0.1;

/// Absolute when the channels' typical values sit nearer the OFFSET than
/// zero: deltas hover around zero, absolute positions around the offset.
/// Also says whether the joint is settled (see [`SETTLED_SHARE`]); a joint
/// that travels (the hips carrying the body across the room) has no
/// typical value to go by.
fn detect_mode(bvh: &Bvh, samples: &[usize], offset: DVec3, positions: &[Option<usize>; 3]) -> (PositionMode, bool) {
    if offset.length() < 1e-9 || positions.iter().all(Option::is_none) || samples.is_empty() {
        return (PositionMode::Delta, false);
    }
    let mut typical = DVec3::ZERO;
    let mut offset_on_channels = DVec3::ZERO;
    let mut spread = DVec3::ZERO;
    for (axis, channel) in positions.iter().enumerate() {
        if let Some(index) = channel {
            let mut values: Vec<f64> = samples.iter().map(|&f| bvh.frame(f)[*index]).collect();
            values.sort_by(f64::total_cmp);
            typical[axis] = values[values.len() / 2];
            spread[axis] = values.iter().map(|v| (v - typical[axis]).abs()).fold(0.0, f64::max);
            offset_on_channels[axis] = offset[axis];
        }
    }
    let mode = if (typical - offset_on_channels).length() < typical.length() {
        PositionMode::Absolute
    } else {
        PositionMode::Delta
    };
    (mode, spread.length() <= SETTLED_SHARE * offset.length())
}

/// One file, one convention: exporters do not mix them. Every joint below
/// the root takes the convention the settled joints show, when they agree
/// by a clear majority: the joint that disagrees is the one carrying the
/// body about the room (its OFFSET is where the take's rest pose stood,
/// its channels where the body is now), whose own reading cannot be
/// trusted. A file with no clear majority keeps each joint's own reading.
fn one_convention(joints: Vec<(JointPlan, bool)>) -> Vec<JointPlan> {
    let settled = |mode| joints.iter().filter(|(p, s)| *s && p.parent.is_some() && p.mode == mode).count();
    let (absolute, delta) = (settled(PositionMode::Absolute), settled(PositionMode::Delta));
    let file_mode = match (absolute, delta) {
        (a, d) if a > 2 * d => Some(PositionMode::Absolute),
        (a, d) if d > 2 * a => Some(PositionMode::Delta),
        _ => None,
    };
    joints
        .into_iter()
        .map(|(mut plan, _)| {
            if let (Some(mode), Some(_)) = (file_mode, plan.parent) {
                plan.mode = mode;
            }
            plan
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::bvh::read_bvh_bytes;

    fn two_bone(channels_line: &str, frame: &str) -> Bvh {
        let text = format!(
            "HIERARCHY\nROOT a\n{{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\nJOINT b\n{{\nOFFSET 0 10 0\n{channels_line}\nEnd Site\n{{\nOFFSET 0 5 0\n}}\n}}\n}}\nMOTION\nFrames: 2\nFrame Time: 0.1\n{frame}\n{frame}\n"
        );
        read_bvh_bytes(text.as_bytes(), "test.bvh").unwrap()
    }

    fn joint_b_height(bvh: &Bvh) -> f64 {
        let kin = Kinematics::new(bvh);
        let mut out = vec![Transform::default(); 2];
        kin.world(bvh.frame(0), &[true, true], &mut out);
        out[1].position.y
    }

    #[test]
    fn absolute_position_channels_equal_to_the_offset_do_not_double_the_bone() {
        let bvh =
            two_bone("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation", "0 0 0 0 10 0 0 0 0");
        assert_eq!(Kinematics::new(&bvh).position_mode(1), Some(PositionMode::Absolute));
        assert!((joint_b_height(&bvh) - 10.0).abs() < 1e-12);
    }

    #[test]
    fn delta_position_channels_add_to_the_offset() {
        let bvh =
            two_bone("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation", "0 0 0 0 0.5 0 0 0 0");
        assert_eq!(Kinematics::new(&bvh).position_mode(1), Some(PositionMode::Delta));
        assert!((joint_b_height(&bvh) - 10.5).abs() < 1e-12);
    }

    #[test]
    fn a_travelling_joint_takes_the_convention_its_settled_bones_show() {
        // As Bandai's exports: the hips carry the body across the room on
        // absolute channels, far from both their OFFSET and zero, while the
        // spine's channels repeat its OFFSET.
        // Whether the take walks through the room or stands in one spot
        // away from where its rest pose stood, the hips read the same way.
        let six = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation";
        let bones = "0 15 0 0 0 0 0 12 0 0 0 0 0 10 0 0 0 0";
        for depths in [[-500.0, -250.0, 0.0, 250.0, 500.0], [-5.0, -4.0, -5.0, -6.0, -5.0]] {
            let mut frames = String::new();
            for z in depths {
                frames += &format!("0 0 0 0 0 0 1 90 {z} 0 0 0 {bones}\n");
            }
            let text = format!(
                "HIERARCHY\nROOT root\n{{\nOFFSET 0 0 0\n{six}\nJOINT hips\n{{\nOFFSET 4 91 -427\n{six}\nJOINT spine\n{{\nOFFSET 0 15 0\n{six}\nJOINT chest\n{{\nOFFSET 0 12 0\n{six}\nJOINT neck\n{{\nOFFSET 0 10 0\n{six}\nEnd Site\n{{\nOFFSET 0 5 0\n}}\n}}\n}}\n}}\n}}\n}}\nMOTION\nFrames: 5\nFrame Time: 0.1\n{frames}"
            );
            let bvh = read_bvh_bytes(text.as_bytes(), "test.bvh").unwrap();
            let kin = Kinematics::new(&bvh);
            assert_eq!(kin.position_mode(2), Some(PositionMode::Absolute));
            assert_eq!(kin.position_mode(1), Some(PositionMode::Absolute));
            let mut out = vec![Transform::default(); 5];
            kin.world(bvh.frame(2), &[true; 5], &mut out);
            let expected = DVec3::new(1.0, 90.0, depths[2]);
            assert!((out[1].position - expected).length() < 1e-12, "{:?}", out[1].position);
        }
    }

    #[test]
    fn position_channels_listed_after_rotations_still_translate_before_rotating() {
        let bvh =
            two_bone("CHANNELS 6 Zrotation Xrotation Yrotation Xposition Yposition Zposition", "0 0 0 90 0 0 0 10 0");
        // The rotation turns b's own frame; b itself stays at its offset.
        assert!((joint_b_height(&bvh) - 10.0).abs() < 1e-12);
    }

    #[test]
    fn rotations_compose_in_channel_order() {
        let bvh = two_bone("CHANNELS 3 Zrotation Xrotation Yrotation", "0 0 0 30 40 50");
        let kin = Kinematics::new(&bvh);
        let (_, r) = kin.local(1, bvh.frame(0));
        let expected = DQuat::from_rotation_z(30f64.to_radians())
            * DQuat::from_rotation_x(40f64.to_radians())
            * DQuat::from_rotation_y(50f64.to_radians());
        assert!(r.abs_diff_eq(expected, 1e-14));
    }

    #[test]
    fn samples_cover_first_and_last_frame() {
        assert_eq!(sample_frames(0), Vec::<usize>::new());
        assert_eq!(sample_frames(1), vec![0]);
        let s = sample_frames(10_000);
        assert_eq!((s.len(), s[0], *s.last().unwrap()), (SAMPLE_FRAMES, 0, 9_999));
    }
}
