//! Poses and motions of the canonical body, their forward kinematics, and
//! their BVH form.

use crate::mocap::body::{Body, DOF, JOINTS, Joint, JointVector, Kind};
use crate::mocap::bvh::{Bvh, Channel, Joint as BvhJoint, Skeleton};
use crate::mocap::math::{Axis, heading_of, hinge_angle, swing_twist_exp, swing_twist_log};
use glam::{DQuat, DVec3};

/// One pose of the canonical body: the global root kept apart from the
/// joint-space vector `x`, as in the paper.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Pelvis position in the world, meters.
    pub root: DVec3,
    /// Rotation of the body about +Y, radians; 0 faces +Z.
    pub heading: f64,
    /// Joint space: the pelvis's tilt after the heading, then every other
    /// joint relative to its parent, all relative to the rest pose.
    pub x: JointVector,
}

/// World positions and rotations of every joint of a posed body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyFrame {
    pub positions: [DVec3; JOINTS],
    pub rotations: [DQuat; JOINTS],
}

impl BodyFrame {
    pub fn position(&self, j: Joint) -> DVec3 {
        self.positions[j.index()]
    }

    pub fn rotation(&self, j: Joint) -> DQuat {
        self.rotations[j.index()]
    }

    /// World position of the far end of the bone that leaves `j`.
    pub fn bone_end(&self, body: &Body, j: Joint) -> DVec3 {
        match j.bone_child() {
            Some(c) => self.position(c),
            None => self.position(j) + self.rotation(j) * body.bone(j),
        }
    }
}

impl Pose {
    /// The rest pose standing at the origin.
    pub fn rest(body: &Body) -> Pose {
        Pose { root: DVec3::new(0.0, body.pelvis_height(), 0.0), heading: 0.0, x: [0.0; DOF] }
    }

    /// This joint's numbers in `x`.
    pub fn joint(&self, j: Joint) -> &[f64] {
        let o = j.dof_offset();
        &self.x[o..o + j.dof()]
    }

    /// The pelvis's rotation after the heading: its tilt.
    pub fn tilt(&self) -> DQuat {
        let v = self.joint(Joint::Pelvis);
        swing_twist_exp(DVec3::new(v[0], v[1], v[2]), Joint::Pelvis.rest_bone_axis())
    }

    /// Rotation of `j` relative to its parent (for the pelvis: in the world).
    pub fn local_rotation(&self, j: Joint) -> DQuat {
        let v = self.joint(j);
        let q = match j.kind() {
            Kind::Hinge { axis, .. } => DQuat::from_axis_angle(axis, v[0]),
            Kind::Ball { .. } => swing_twist_exp(DVec3::new(v[0], v[1], v[2]), j.rest_bone_axis()),
        };
        if j == Joint::Pelvis { Axis::Y.rotation(self.heading) * q } else { q }
    }

    /// The pose with these joint rotations: each relative to its parent, the
    /// pelvis's in the world. A hinge takes the component of its rotation
    /// about its axis.
    pub fn from_rotations(root: DVec3, rotations: &[DQuat; JOINTS]) -> Pose {
        let mut x = [0.0; DOF];
        let pelvis = rotations[Joint::Pelvis.index()];
        let heading = heading_of(pelvis);
        for j in Joint::ALL {
            let mut q = rotations[j.index()];
            if j == Joint::Pelvis {
                q = Axis::Y.rotation(-heading) * q;
            }
            let o = j.dof_offset();
            match j.kind() {
                Kind::Hinge { axis, .. } => x[o] = hinge_angle(q, axis),
                Kind::Ball { .. } => x[o..o + 3].copy_from_slice(&swing_twist_log(q, j.rest_bone_axis()).to_array()),
            }
        }
        Pose { root, heading, x }
    }
}

impl Body {
    /// Forward kinematics: where every joint of this body is in `pose`.
    pub fn forward(&self, pose: &Pose) -> BodyFrame {
        let mut positions = [DVec3::ZERO; JOINTS];
        let mut rotations = [DQuat::IDENTITY; JOINTS];
        for j in Joint::ALL {
            let local = pose.local_rotation(j);
            let i = j.index();
            match j.parent() {
                None => {
                    positions[i] = pose.root;
                    rotations[i] = local;
                }
                Some(p) => {
                    let (pp, pr) = (positions[p.index()], rotations[p.index()]);
                    positions[i] = pp + pr * self.offset(j);
                    rotations[i] = pr * local;
                }
            }
        }
        BodyFrame { positions, rotations }
    }
}

/// A take of the canonical body.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    pub body: Body,
    pub frame_time_s: f64,
    pub poses: Vec<Pose>,
}

impl Pose {
    /// The pose a fraction `t` of the way from `self` to `next`: the root
    /// moved in a straight line, every joint turned the short way round
    /// (spherical interpolation of its rotation).
    pub fn interpolate(&self, next: &Pose, t: f64) -> Pose {
        let rotations = Joint::ALL.map(|j| self.local_rotation(j).slerp(next.local_rotation(j), t));
        Pose::from_rotations(self.root.lerp(next.root, t), &rotations)
    }
}

impl Motion {
    /// Duration, seconds: from the first frame to the last.
    pub fn duration_s(&self) -> f64 {
        self.poses.len().saturating_sub(1) as f64 * self.frame_time_s
    }

    /// The pose at `time_s` seconds after the first frame, between the
    /// frames around it; held at the first and last frame outside them.
    /// The motion must have a frame.
    pub fn pose_at(&self, time_s: f64) -> Pose {
        let last = self.poses.len() - 1;
        let at = (time_s / self.frame_time_s).clamp(0.0, last as f64);
        let i = (at.floor() as usize).min(last);
        if i == last { self.poses[last] } else { self.poses[i].interpolate(&self.poses[i + 1], at - i as f64) }
    }

    /// The same motion performed by `body`: every joint angle kept, the
    /// root's path scaled by the ratio of pelvis heights, so the feet stay
    /// on the ground and strides lengthen with the legs.
    pub fn on_body(&self, body: &Body) -> Motion {
        let scale = body.pelvis_height() / self.body.pelvis_height();
        let poses = self.poses.iter().map(|p| Pose { root: p.root * scale, ..*p }).collect();
        Motion { body: body.clone(), frame_time_s: self.frame_time_s, poses }
    }

    /// The BVH skeleton of `body`: 6 channels on the pelvis, three rotation
    /// channels on every other joint (hinges too, for importers that expect
    /// three), end sites on the head, hands and feet.
    pub fn skeleton(body: &Body) -> Skeleton {
        let mut joints = Vec::with_capacity(JOINTS);
        let mut next_channel = 0;
        for j in Joint::ALL {
            let rotations = j.euler_order().0.map(Channel::Rotation);
            let channels: Vec<Channel> = if j == Joint::Pelvis {
                [Axis::X, Axis::Y, Axis::Z].map(Channel::Position).into_iter().chain(rotations).collect()
            } else {
                rotations.to_vec()
            };
            let offset = if j == Joint::Pelvis { DVec3::ZERO } else { body.offset(j) };
            joints.push(BvhJoint {
                name: j.name().to_string(),
                parent: j.parent().map(Joint::index),
                offset,
                first_channel: next_channel,
                end_site: body.end_site(j),
                channels,
                line: 0,
            });
            next_channel += joints.last().map_or(0, |b: &BvhJoint| b.channels.len());
        }
        Skeleton { joints }
    }

    /// This motion as BVH: positions in meters, rotations in degrees.
    pub fn to_bvh(&self) -> Bvh {
        let skeleton = Motion::skeleton(&self.body);
        let channels = skeleton.channel_count();
        let mut data = Vec::with_capacity(self.poses.len() * channels);
        for pose in &self.poses {
            data.extend_from_slice(&pose.root.to_array());
            for j in Joint::ALL {
                let angles = j.euler_order().from_quat(pose.local_rotation(j));
                data.extend(angles.iter().map(|a| a.to_degrees()));
            }
        }
        Bvh {
            skeleton,
            frame_time_s: self.frame_time_s,
            frames: self.poses.len(),
            declared_frames: self.poses.len() as u64,
            data,
            warnings: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_pose() -> Pose {
        let mut pose = Pose::rest(&Body::standard());
        for (i, v) in pose.x.iter_mut().enumerate() {
            *v = 0.4 * ((i as f64) * 1.7).sin();
        }
        pose.heading = 2.0;
        pose.root = DVec3::new(0.3, 0.9, -1.0);
        pose
    }

    #[test]
    fn rotations_survive_conversion_to_joint_space_and_back() {
        let pose = sample_pose();
        let rotations = Joint::ALL.map(|j| pose.local_rotation(j));
        let back = Pose::from_rotations(pose.root, &rotations);
        for j in Joint::ALL {
            let (a, b) = (pose.local_rotation(j), back.local_rotation(j));
            assert!(crate::mocap::math::log_map(a.inverse() * b).length() < 1e-12, "{j:?}");
        }
        // The pelvis's tilt is measured after the heading, so converting
        // the canonical form again changes nothing.
        let again = Pose::from_rotations(back.root, &Joint::ALL.map(|j| back.local_rotation(j)));
        assert!((again.heading - back.heading).abs() < 1e-12);
        for (a, b) in again.x.iter().zip(back.x.iter()) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    #[test]
    fn rest_pose_places_the_arms_along_x_and_legs_down() {
        let body = Body::standard();
        let frame = body.forward(&Pose::rest(&body));
        let arm = frame.position(Joint::LeftWrist) - frame.position(Joint::LeftShoulder);
        assert!(arm.x > 0.5 && arm.y.abs() < 1e-12 && arm.z.abs() < 1e-12);
        let leg = frame.position(Joint::RightAnkle) - frame.position(Joint::RightHip);
        assert!(leg.y < -0.8 && leg.x.abs() < 1e-12);
    }

    #[test]
    fn positive_elbow_flexion_swings_the_forearm_forward_and_knee_flexion_the_shin_back() {
        let body = Body::standard();
        let mut pose = Pose::rest(&body);
        for j in [Joint::LeftElbow, Joint::RightElbow, Joint::LeftKnee] {
            pose.x[j.dof_offset()] = 0.5;
        }
        let frame = body.forward(&pose);
        for (elbow, wrist) in [(Joint::LeftElbow, Joint::LeftWrist), (Joint::RightElbow, Joint::RightWrist)] {
            assert!((frame.position(wrist) - frame.position(elbow)).z > 0.1);
        }
        assert!((frame.position(Joint::LeftAnkle) - frame.position(Joint::LeftKnee)).z < -0.1);
    }

    fn motion(poses: Vec<Pose>) -> Motion {
        Motion { body: Body::standard(), frame_time_s: 0.1, poses }
    }

    #[test]
    fn a_motion_between_frames_turns_each_joint_part_way_and_holds_its_ends() {
        let body = Body::standard();
        let mut a = Pose::rest(&body);
        let mut b = a;
        a.heading = 0.2;
        b.heading = 0.6;
        b.root.x += 1.0;
        let elbow = Joint::LeftElbow.dof_offset();
        b.x[elbow] = 1.0;
        let shoulder = Joint::LeftShoulder.dof_offset();
        b.x[shoulder + 2] = 0.8;
        let m = motion(vec![a, b]);
        let mid = m.pose_at(0.025);
        assert!((mid.heading - 0.3).abs() < 1e-9, "{}", mid.heading);
        assert!((mid.root.x - a.root.x - 0.25).abs() < 1e-12);
        assert!((mid.x[elbow] - 0.25).abs() < 1e-9);
        assert!((mid.x[shoulder + 2] - 0.2).abs() < 1e-9 && mid.x[shoulder].abs() < 1e-12);
        assert_eq!(m.pose_at(-1.0), a);
        assert_eq!(m.pose_at(5.0), b);
        assert!((m.duration_s() - 0.1).abs() < 1e-15);
        // At a frame's own time: that frame (up to conversion round-off).
        let at = m.pose_at(0.1);
        assert!(at.x.iter().zip(&b.x).all(|(p, q)| (p - q).abs() < 1e-12) && at.root == b.root);
    }

    #[test]
    fn another_body_keeps_every_angle_and_stands_on_the_ground() {
        use crate::mocap::body::Proportions;
        let standard = Body::standard();
        let mut step = Pose::rest(&standard);
        step.root += DVec3::new(0.4, -0.05, 1.0);
        step.x[Joint::LeftKnee.dof_offset()] = 0.7;
        let short = Body::new(Proportions { height_m: 1.5, arm_scale: 1.0, leg_scale: 0.9 });
        let moved = motion(vec![Pose::rest(&standard), step]).on_body(&short);
        assert_eq!(moved.body, short);
        assert_eq!(moved.poses[1].x, step.x);
        // Standing at rest, the short body stands as it does at rest.
        assert!((moved.poses[0].root - Pose::rest(&short).root).length() < 1e-12);
        let scale = short.pelvis_height() / standard.pelvis_height();
        assert!((moved.poses[1].root.z - scale).abs() < 1e-12);
    }
}
