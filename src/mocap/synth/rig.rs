//! From what the demonstrator is asked to do (a [`Drive`]) to a pose of the
//! canonical body: the torso bends and turns as a chain, the arms reach
//! their hand targets by two-link inverse kinematics, and the legs keep the
//! feet planted under a moving pelvis.

use crate::mocap::body::{Body, JOINTS, Joint, Kind};
use crate::mocap::math::{Axis, exp_map, frame_from_directions};
use crate::mocap::pose::Pose;
use glam::{DQuat, DVec3};

/// One instant of the demonstrator's intent. Arms are indexed
/// `[left, right]`; hand targets and elbow poles are in the chest's frame
/// relative to the shoulder (X the person's left, Y up, Z forward).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    pub hands: [DVec3; 2],
    /// Direction the elbow should point, away from the shoulder–hand line.
    pub poles: [DVec3; 2],
    /// Wrist rotation relative to the forearm (exponential map).
    pub wrists: [DVec3; 2],
    /// Torso lean (about X, forward positive), turn (about Y) and side bend
    /// (about Z), radians, shared over pelvis, spine and chest.
    pub torso: DVec3,
    /// Extra turn of the pelvis alone (hip swivel), radians.
    pub hip_turn: f64,
    /// Head rotation relative to the neck (exponential map).
    pub head: DVec3,
    /// How far the pelvis drops by bending the knees, meters.
    pub crouch: f64,
    /// Pelvis shift (weight transfer), meters.
    pub shift: DVec3,
}

impl Drive {
    /// Blend: `self` at `t = 0`, `other` at `t = 1`. Hands swing about the
    /// shoulder (direction and distance blend separately), as a straight
    /// line between two targets can pass through the shoulder and fold the
    /// elbow shut; everything else blends linearly.
    pub fn lerp(&self, other: &Drive, t: f64) -> Drive {
        let v = |a: DVec3, b: DVec3| a.lerp(b, t);
        let f = |a: f64, b: f64| a + (b - a) * t;
        let swing = |a: DVec3, b: DVec3| slerp(a.normalize(), b.normalize(), t) * f(a.length(), b.length());
        Drive {
            hands: [swing(self.hands[0], other.hands[0]), swing(self.hands[1], other.hands[1])],
            poles: [v(self.poles[0], other.poles[0]), v(self.poles[1], other.poles[1])],
            wrists: [v(self.wrists[0], other.wrists[0]), v(self.wrists[1], other.wrists[1])],
            torso: v(self.torso, other.torso),
            hip_turn: f(self.hip_turn, other.hip_turn),
            head: v(self.head, other.head),
            crouch: f(self.crouch, other.crouch),
            shift: v(self.shift, other.shift),
        }
    }
}

/// Spherical interpolation between unit vectors that are never opposite.
fn slerp(a: DVec3, b: DVec3, t: f64) -> DVec3 {
    let angle = a.angle_between(b);
    if angle < 1e-9 {
        return a.lerp(b, t).normalize();
    }
    (a * ((1.0 - t) * angle).sin() + b * (t * angle).sin()) / angle.sin()
}

/// Shares of the torso rotation taken by pelvis, spine and chest.
const TORSO_SHARES: [f64; 3] = [0.2, 0.4, 0.4];

/// Arm and leg indices into a [`Drive`], and `+1`/`−1` for left/right.
pub const SIDES: [(usize, f64); 2] = [(0, 1.0), (1, -1.0)];

/// A two-link limb: segment lengths and the band of reach its targets are
/// eased into.
#[derive(Clone, Copy, Debug)]
struct Chain {
    a: f64,
    b: f64,
    min_reach: f64,
    /// Width of the band below full reach where targets are eased.
    margin: f64,
}

impl Chain {
    /// Hinge flexion never exceeds 140°, inside the 150° joint limit.
    fn new(a: f64, b: f64, margin_share: f64) -> Chain {
        let min_reach = (a * a + b * b + 2.0 * a * b * 140f64.to_radians().cos()).sqrt();
        Chain { a, b, min_reach, margin: margin_share * (a + b) }
    }

    /// The rotation of the first link (rest direction `rest_bone`, hinge
    /// axis `rest_axis` at rest) and the hinge flexion that bring the end
    /// to `target`, bending toward `pole`. Targets beyond reach, or too
    /// close, are eased smoothly inside it, so a smooth target path gives a
    /// smooth pose.
    fn solve(&self, target: DVec3, pole: DVec3, rest_bone: DVec3, rest_axis: DVec3) -> (DQuat, f64) {
        let (a, b) = (self.a, self.b);
        let axis = target.normalize();
        let d = soft_clamp(target.length(), self.min_reach, a + b, self.margin);
        let flexion = ((d * d - a * a - b * b) / (2.0 * a * b)).clamp(-1.0, 1.0).acos();
        let cos_root = ((a * a + d * d - b * b) / (2.0 * a * d)).clamp(-1.0, 1.0);
        let across = (pole - axis * pole.dot(axis)).normalize();
        let first = axis * cos_root + across * (1.0 - cos_root * cos_root).sqrt();
        // The hinge axis that bends the chain toward the pole with positive
        // flexion is pole × reach axis.
        let rotation = frame_from_directions(rest_bone, rest_axis, first, across.cross(axis))
            .expect("the pole is never along the reach axis");
        (rotation, flexion)
    }
}

/// `x` eased into `(lo, hi)`: unchanged more than `margin` inside, and
/// approaching the bounds smoothly (C2, by tanh) without reaching them.
fn soft_clamp(x: f64, lo: f64, hi: f64, margin: f64) -> f64 {
    let ease = |excess: f64| margin * (excess / margin).tanh();
    if x > hi - margin {
        hi - margin + ease(x - (hi - margin))
    } else if x < lo + margin {
        lo + margin - ease(lo + margin - x)
    } else {
        x
    }
}

/// The canonical body with the limb chains inverse kinematics needs.
pub struct Rig {
    pub body: Body,
    arm: Chain,
    leg: Chain,
}

impl Rig {
    pub fn new(body: Body) -> Rig {
        let length = |j: Joint| body.offset(j).length();
        Rig {
            // Arms ease over the last 4% of reach, so a punch can aim past
            // full extension; legs only over 0.3%, so planted feet stay put.
            arm: Chain::new(length(Joint::LeftElbow), length(Joint::LeftWrist), 0.04),
            leg: Chain::new(length(Joint::LeftKnee), length(Joint::LeftAnkle), 0.003),
            body,
        }
    }

    /// Shoulder to wrist with the arm fully straight.
    pub fn arm_length(&self) -> f64 {
        self.arm.a + self.arm.b
    }

    /// Shoulder-to-wrist distance at elbow flexion `flexion` (radians).
    pub fn reach_at(&self, flexion: f64) -> f64 {
        let (a, b) = (self.arm.a, self.arm.b);
        (a * a + b * b + 2.0 * a * b * flexion.cos()).sqrt()
    }

    pub fn upper_arm(&self) -> f64 {
        self.arm.a
    }

    /// The pose that carries out `drive`, standing at the origin facing +Z.
    pub fn pose(&self, drive: &Drive) -> Pose {
        use Joint::*;
        let body = &self.body;
        let mut local = [DQuat::IDENTITY; JOINTS];
        let share = |k: usize| exp_map(drive.torso * TORSO_SHARES[k]);
        local[Pelvis.index()] = Axis::Y.rotation(drive.hip_turn) * share(0);
        local[Spine.index()] = share(1);
        local[Chest.index()] = share(2);
        // The neck takes a third of the head's motion, as real necks do.
        local[Neck.index()] = exp_map(drive.head / 3.0);
        local[Head.index()] = exp_map(drive.head * (2.0 / 3.0));

        for (k, side) in SIDES {
            let [shoulder, elbow, wrist] =
                if side > 0.0 { [LeftShoulder, LeftElbow, LeftWrist] } else { [RightShoulder, RightElbow, RightWrist] };
            let (rotation, flexion) =
                self.arm.solve(drive.hands[k], drive.poles[k], body.bone(shoulder), hinge_axis(elbow));
            local[shoulder.index()] = rotation;
            local[elbow.index()] = DQuat::from_axis_angle(hinge_axis(elbow), flexion);
            local[wrist.index()] = exp_map(drive.wrists[k]);
        }

        let pelvis_rotation = local[Pelvis.index()];
        let root = DVec3::new(0.0, body.pelvis_height() - drive.crouch, 0.0) + drive.shift;
        for (_, side) in SIDES {
            let [hip, knee, ankle] =
                if side > 0.0 { [LeftHip, LeftKnee, LeftAnkle] } else { [RightHip, RightKnee, RightAnkle] };
            let hip_at = root + pelvis_rotation * body.offset(hip);
            // Feet stay flat where they stand in the rest pose.
            let rest_hip = DVec3::new(0.0, body.pelvis_height(), 0.0) + body.offset(hip);
            let foot_at = rest_hip - DVec3::Y * (self.leg.a + self.leg.b);
            let (thigh, flexion) = self.leg.solve(foot_at - hip_at, DVec3::Z, body.bone(hip), hinge_axis(knee));
            local[hip.index()] = pelvis_rotation.inverse() * thigh;
            local[knee.index()] = DQuat::from_axis_angle(hinge_axis(knee), flexion);
            local[ankle.index()] = (thigh * local[knee.index()]).inverse();
        }
        Pose::from_rotations(root, &local)
    }
}

fn hinge_axis(j: Joint) -> DVec3 {
    match j.kind() {
        Kind::Hinge { axis, .. } => axis,
        Kind::Ball { .. } => unreachable!("elbows and knees are hinges"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn neutral(rig: &Rig) -> Drive {
        let hang = rig.reach_at(0.3);
        Drive {
            hands: [DVec3::new(0.05, -hang, 0.05), DVec3::new(-0.05, -hang, 0.05)],
            poles: [DVec3::new(0.2, 0.0, -1.0), DVec3::new(-0.2, 0.0, -1.0)],
            wrists: [DVec3::ZERO; 2],
            torso: DVec3::ZERO,
            hip_turn: 0.0,
            head: DVec3::ZERO,
            crouch: 0.004,
            shift: DVec3::ZERO,
        }
    }

    #[test]
    fn arms_reach_their_hand_targets_with_elbows_toward_the_pole() {
        let rig = Rig::new(Body::standard());
        let mut drive = neutral(&rig);
        drive.hands[1] = DVec3::new(-0.1, 0.1, 0.4);
        drive.poles[1] = DVec3::new(-0.5, -1.0, 0.0);
        let pose = rig.pose(&drive);
        let frame = rig.body.forward(&pose);
        let chest = frame.rotation(Joint::Chest);
        let wrist = chest.inverse() * (frame.position(Joint::RightWrist) - frame.position(Joint::RightShoulder));
        assert!((wrist - drive.hands[1]).length() < 1e-9, "{wrist:?}");
        let elbow = chest.inverse() * (frame.position(Joint::RightElbow) - frame.position(Joint::RightShoulder));
        assert!(elbow.y < 0.0 && elbow.x < 0.0, "elbow down and out: {elbow:?}");
        let flexion = pose.joint(Joint::RightElbow)[0];
        assert!(flexion > 0.5 && flexion < 150f64.to_radians());
    }

    #[test]
    fn feet_stay_planted_while_the_pelvis_drops_turns_and_shifts() {
        let rig = Rig::new(Body::standard());
        let mut drive = neutral(&rig);
        let rest = rig.body.forward(&rig.pose(&drive));
        drive.crouch = 0.05;
        drive.hip_turn = 0.3;
        drive.shift = DVec3::new(0.03, 0.0, 0.0);
        let moved = rig.body.forward(&rig.pose(&drive));
        for ankle in [Joint::LeftAnkle, Joint::RightAnkle] {
            assert!((moved.position(ankle) - rest.position(ankle)).length() < 1e-9);
            // Flat foot: the ankle's world rotation stays the identity.
            assert!(moved.rotation(ankle).abs_diff_eq(DQuat::IDENTITY, 1e-9));
        }
        assert!(moved.position(Joint::Pelvis).y < rest.position(Joint::Pelvis).y - 0.045);
    }

    #[test]
    fn out_of_reach_targets_ease_inside_without_straightening_fully() {
        let rig = Rig::new(Body::standard());
        let mut drive = neutral(&rig);
        drive.hands[0] = DVec3::new(2.0, 0.0, 0.0);
        let pose = rig.pose(&drive);
        let flexion = pose.joint(Joint::LeftElbow)[0];
        assert!(flexion > 0.0 && flexion < 0.1, "{flexion}");
    }
}
