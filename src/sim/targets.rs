//! What the motors are asked for: every frame's joint rotations, kept inside
//! the joints' limits, and a smooth curve through them at any instant.

use crate::mocap::body::{JOINTS, Joint, Kind};
use crate::mocap::math::{exp_map, exp_map_rate, hinge_angle, log_map};
use crate::mocap::pose::{Motion, Pose};
use glam::{DQuat, DVec3};

/// Every joint but the pelvis (which no motor turns), in canonical order.
pub fn motorized() -> impl Iterator<Item = Joint> {
    Joint::ALL.into_iter().skip(1)
}

/// One joint's target: its rotation relative to its parent and how fast
/// that turns (rad/s, in the parent's frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointTarget {
    pub rotation: DQuat,
    pub spin: DVec3,
}

impl JointTarget {
    pub const REST: JointTarget = JointTarget { rotation: DQuat::IDENTITY, spin: DVec3::ZERO };
}

/// Where the trajectory's pelvis is at an instant ([`Targets::root_at`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootTarget {
    pub position: DVec3,
    pub velocity: DVec3,
    pub rotation: DQuat,
    pub spin: DVec3,
}

/// A trajectory's poses as the motors take them.
#[derive(Clone, Debug)]
pub struct Targets {
    frame_time_s: f64,
    /// Every frame with each joint turned back inside its limits.
    poses: Vec<Pose>,
    /// The same, as each joint's rotation relative to its parent.
    rotations: Vec<[DQuat; JOINTS]>,
    /// Per joint, the frames on which it lay beyond its limits.
    clamped_frames: [usize; JOINTS],
    /// Per joint, the most it lay beyond them, radians.
    clamped_by_rad: [f64; JOINTS],
    /// Frames on which some joint lay beyond its limits.
    frames_clamped: usize,
}

/// A trajectory the humanoid cannot be asked to follow.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TargetsError {
    #[error("the trajectory has no frames")]
    Empty,
    #[error("frame {frame}: {what} is not a finite number")]
    NotFinite { frame: usize, what: String },
    #[error("the frame time must be a positive number of seconds, not {0}")]
    FrameTime(f64),
}

/// `q` (joint `j`'s rotation relative to its parent) turned back inside the
/// joint's limits, and how far beyond them it lay (radians, 0 inside). A
/// hinge stops at its range; a ball joint's rotation angle at its largest.
pub fn clamp(j: Joint, q: DQuat) -> (DQuat, f64) {
    match j.kind() {
        Kind::Hinge { axis, min_rad, max_rad } => {
            let angle = hinge_angle(q, axis);
            let kept = angle.clamp(min_rad, max_rad);
            (DQuat::from_axis_angle(axis, kept), (angle - kept).abs())
        }
        // Half a turn or more bounds nothing (shoulders).
        Kind::Ball { max_angle_rad } if max_angle_rad >= std::f64::consts::PI => (q, 0.0),
        Kind::Ball { max_angle_rad } => {
            let v = log_map(q);
            let angle = v.length();
            if angle <= max_angle_rad {
                (q, 0.0)
            } else {
                (exp_map(v * (max_angle_rad / angle)), angle - max_angle_rad)
            }
        }
    }
}

impl Targets {
    /// The motors' targets for every frame of `motion`; a joint beyond its
    /// limits is turned back to them and counted.
    pub fn new(motion: &Motion) -> Result<Targets, TargetsError> {
        if motion.poses.is_empty() {
            return Err(TargetsError::Empty);
        }
        if !(motion.frame_time_s.is_finite() && motion.frame_time_s > 0.0) {
            return Err(TargetsError::FrameTime(motion.frame_time_s));
        }
        let mut poses = Vec::with_capacity(motion.poses.len());
        let mut rotations = Vec::with_capacity(motion.poses.len());
        let mut clamped_frames = [0; JOINTS];
        let mut clamped_by_rad = [0.0f64; JOINTS];
        let mut frames_clamped = 0;
        for (frame, pose) in motion.poses.iter().enumerate() {
            if !(pose.root.is_finite() && pose.heading.is_finite()) {
                return Err(TargetsError::NotFinite { frame, what: "the root".into() });
            }
            if let Some(j) = Joint::ALL.into_iter().find(|&j| pose.joint(j).iter().any(|v| !v.is_finite())) {
                return Err(TargetsError::NotFinite { frame, what: format!("joint {}", j.name()) });
            }
            let mut local = Joint::ALL.map(|j| pose.local_rotation(j));
            let mut any_clamped = false;
            for j in motorized() {
                let (kept, beyond) = clamp(j, local[j.index()]);
                local[j.index()] = kept;
                if beyond > 0.0 {
                    any_clamped = true;
                    clamped_frames[j.index()] += 1;
                    clamped_by_rad[j.index()] = clamped_by_rad[j.index()].max(beyond);
                }
            }
            frames_clamped += usize::from(any_clamped);
            poses.push(Pose::from_rotations(pose.root, &local));
            rotations.push(local);
        }
        Ok(Targets {
            frame_time_s: motion.frame_time_s,
            poses,
            rotations,
            clamped_frames,
            clamped_by_rad,
            frames_clamped,
        })
    }

    pub fn frames(&self) -> usize {
        self.poses.len()
    }

    pub fn frame_time_s(&self) -> f64 {
        self.frame_time_s
    }

    /// Frame `k` as the motors are asked for it: the trajectory's root, its
    /// joints inside their limits.
    pub fn pose(&self, k: usize) -> &Pose {
        &self.poses[k]
    }

    pub fn clamped_frames(&self, j: Joint) -> usize {
        self.clamped_frames[j.index()]
    }

    pub fn clamped_by_rad(&self, j: Joint) -> f64 {
        self.clamped_by_rad[j.index()]
    }

    /// Frames on which some joint lay beyond its limits.
    pub fn frames_clamped(&self) -> usize {
        self.frames_clamped
    }

    /// The trajectory's pelvis at `time_s`, between frames on the straight
    /// line and the shortest turn: where it is, how fast it goes (m/s),
    /// how it is turned in the world and how fast that turns (rad/s, world
    /// axes). Beyond the last frame it holds still.
    pub fn root_at(&self, time_s: f64) -> RootTarget {
        let last = self.frames() - 1;
        let at = (time_s / self.frame_time_s).max(0.0);
        let turn = |k: usize| self.poses[k].local_rotation(Joint::Pelvis);
        if at >= last as f64 {
            let held = &self.poses[last];
            return RootTarget { position: held.root, velocity: DVec3::ZERO, rotation: turn(last), spin: DVec3::ZERO };
        }
        let k = at.floor() as usize;
        let u = at - k as f64;
        let (a, b) = (&self.poses[k], &self.poses[k + 1]);
        let (from, to) = (turn(k), turn(k + 1));
        let step = log_map(to * from.inverse());
        RootTarget {
            position: a.root.lerp(b.root, u),
            velocity: (b.root - a.root) / self.frame_time_s,
            rotation: exp_map(u * step) * from,
            spin: step / self.frame_time_s,
        }
    }

    /// Every motorized joint's target at `time_s` (the pelvis's entry is
    /// left as it is): a Catmull–Rom spline through the frames, in each
    /// joint's rotations, so the curve passes through every frame, its
    /// rate is continuous, and it never wraps the long way round. Beyond
    /// the last frame the pose holds.
    pub fn sample(&self, time_s: f64, out: &mut [JointTarget; JOINTS]) {
        let last = self.frames() - 1;
        let at = (time_s / self.frame_time_s).max(0.0);
        if at >= last as f64 {
            for j in motorized() {
                out[j.index()] = JointTarget { rotation: self.rotations[last][j.index()], spin: DVec3::ZERO };
            }
            return;
        }
        let k = at.floor() as usize;
        let u = at - k as f64;
        let (u2, u3) = (u * u, u * u * u);
        // Hermite basis for the tangent at k, the next frame and the tangent
        // there (the curve is zero at frame k), and their rates.
        let (h10, h01, h11) = (u3 - 2.0 * u2 + u, -2.0 * u3 + 3.0 * u2, u3 - u2);
        let (d10, d01, d11) = (3.0 * u2 - 4.0 * u + 1.0, -6.0 * u2 + 6.0 * u, 3.0 * u2 - 2.0 * u);
        for j in motorized() {
            let at_k = self.rotations[k][j.index()];
            let from_k = at_k.inverse();
            // The frames around, as rotations away from frame k: small,
            // whatever the joint's own angle.
            let away = |f: usize| log_map(from_k * self.rotations[f][j.index()]);
            let next = away(k + 1);
            // Beyond either end the curve is carried on in a straight line.
            let before = if k > 0 { away(k - 1) } else { -next };
            let after = if k + 2 <= last { away(k + 2) } else { 2.0 * next };
            let (m1, m2) = (0.5 * (next - before), 0.5 * after);
            let v = h10 * m1 + h01 * next + h11 * m2;
            let v_dot = (d10 * m1 + d01 * next + d11 * m2) / self.frame_time_s;
            let rotation = at_k * exp_map(v);
            // Between two frames at a limit the curve may overshoot it.
            let (kept, beyond) = clamp(j, rotation);
            let spin = if beyond > 0.0 { DVec3::ZERO } else { at_k * exp_map_rate(v, v_dot) };
            out[j.index()] = JointTarget { rotation: kept, spin };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Body;
    use crate::mocap::math::angle_between;

    fn motion_of(frames: &[(f64, DVec3)]) -> Motion {
        let body = Body::standard();
        let poses = frames
            .iter()
            .map(|&(elbow, shoulder)| {
                let mut p = Pose::rest(&body);
                p.x[Joint::LeftElbow.dof_offset()] = elbow;
                let o = Joint::LeftShoulder.dof_offset();
                p.x[o..o + 3].copy_from_slice(&shoulder.to_array());
                p
            })
            .collect();
        Motion { body, frame_time_s: 0.1, poses }
    }

    fn sample(t: &Targets, time_s: f64) -> [JointTarget; JOINTS] {
        let mut out = [JointTarget::REST; JOINTS];
        t.sample(time_s, &mut out);
        out
    }

    #[test]
    fn the_curve_passes_through_every_frame_and_its_rate_is_the_slope_between() {
        let ramp: Vec<(f64, DVec3)> = (0..5).map(|k| (0.2 + 0.2 * k as f64, DVec3::ZERO)).collect();
        let t = Targets::new(&motion_of(&ramp)).unwrap();
        let e = Joint::LeftElbow;
        let axis = DVec3::NEG_Y;
        for k in 0..4 {
            let s = sample(&t, k as f64 * 0.1)[e.index()];
            assert!((hinge_angle(s.rotation, axis) - (0.2 + 0.2 * k as f64)).abs() < 1e-12, "frame {k}");
            // A straight ramp: 0.2 rad every 0.1 s, everywhere.
            assert!((s.spin - axis * 2.0).length() < 1e-9, "frame {k}: {}", s.spin);
        }
        assert!((hinge_angle(sample(&t, 0.25)[e.index()].rotation, axis) - 0.7).abs() < 1e-12);
        let held = sample(&t, 9.0)[e.index()];
        assert!((hinge_angle(held.rotation, axis) - 1.0).abs() < 1e-12 && held.spin == DVec3::ZERO);
    }

    #[test]
    fn a_ball_joint_turning_through_half_a_turn_is_followed_the_short_way_with_its_rate() {
        // About one axis from 150° to 210° (written −150°: its rotation
        // vector flips there), 20° a frame: the curve must pass 180°, not
        // swing back through 0.
        let axis = DVec3::new(0.0, 0.6, 0.8);
        let frames: Vec<(f64, DVec3)> = (0..5)
            .map(|k| {
                let angle = (150.0 + 20.0 * k as f64).to_radians();
                (0.0, log_map(DQuat::from_axis_angle(axis, angle)))
            })
            .collect();
        let t = Targets::new(&motion_of(&frames)).unwrap();
        let s = Joint::LeftShoulder.index();
        for step in 0..40 {
            let time = step as f64 * 0.01;
            let expected = DQuat::from_axis_angle(axis, (150.0 + 200.0 * time).to_radians());
            let got = sample(&t, time)[s];
            assert!(
                angle_between(got.rotation, expected) < 1e-9,
                "t {time}: {:.3}°",
                angle_between(got.rotation, expected).to_degrees()
            );
            assert!((got.spin - axis * 200f64.to_radians()).length() < 1e-9, "t {time}: {}", got.spin);
        }
    }

    #[test]
    fn the_rate_is_the_rate_of_turn_of_the_curve() {
        let frames = [
            (0.3, DVec3::new(0.4, -0.9, 1.3)),
            (0.9, DVec3::new(0.1, -0.5, 1.6)),
            (1.4, DVec3::new(-0.2, 0.1, 1.2)),
            (0.6, DVec3::new(0.0, 0.3, 0.4)),
        ];
        let t = Targets::new(&motion_of(&frames)).unwrap();
        let h = 1e-6;
        for time in [0.03, 0.12, 0.18, 0.27] {
            let (now, later) = (sample(&t, time), sample(&t, time + h));
            for j in [Joint::LeftShoulder, Joint::LeftElbow] {
                let numeric = log_map(later[j.index()].rotation * now[j.index()].rotation.inverse()) / h;
                let analytic = now[j.index()].spin;
                assert!((numeric - analytic).length() < 1e-4, "{j:?} at {time}: {numeric} vs {analytic}");
            }
        }
    }

    #[test]
    fn joints_beyond_their_limits_are_turned_back_and_counted() {
        let shoulder = DVec3::ZERO;
        let t =
            Targets::new(&motion_of(&[(0.5, shoulder), (2.8, shoulder), (-0.3, shoulder), (0.5, shoulder)])).unwrap();
        let e = Joint::LeftElbow;
        let elbow = |k: usize| t.pose(k).joint(e)[0];
        assert!((elbow(1) - 150f64.to_radians()).abs() < 1e-12);
        assert!(elbow(2).abs() < 1e-12);
        assert_eq!(t.clamped_frames(e), 2);
        assert!((t.clamped_by_rad(e) - 0.3).abs() < 1e-9);
        assert_eq!(t.clamped_frames(Joint::RightElbow), 0);
        assert_eq!(t.frames_clamped(), 2);
        for k in 0..=30 {
            let angle = hinge_angle(sample(&t, k as f64 * 0.01)[e.index()].rotation, DVec3::NEG_Y);
            assert!((-1e-12..=150f64.to_radians() + 1e-12).contains(&angle), "{angle}");
        }
        // A wrist turned 100° about a slanted axis stops at 80° about it.
        let (kept, beyond) =
            clamp(Joint::LeftWrist, DQuat::from_axis_angle(DVec3::new(0.6, 0.0, 0.8), 100f64.to_radians()));
        assert!((beyond - 20f64.to_radians()).abs() < 1e-12);
        assert!(angle_between(kept, DQuat::from_axis_angle(DVec3::new(0.6, 0.0, 0.8), 80f64.to_radians())) < 1e-12);
    }

    #[test]
    fn an_empty_or_broken_trajectory_is_refused_with_the_frame_and_joint() {
        assert_eq!(Targets::new(&motion_of(&[])).unwrap_err(), TargetsError::Empty);
        let err = Targets::new(&motion_of(&[(0.1, DVec3::ZERO), (f64::NAN, DVec3::ZERO)])).unwrap_err();
        assert_eq!(err, TargetsError::NotFinite { frame: 1, what: "joint left_elbow".into() });
        assert_eq!(err.to_string(), "frame 1: joint left_elbow is not a finite number");
        let mut still = motion_of(&[(0.1, DVec3::ZERO)]);
        still.frame_time_s = 0.0;
        assert_eq!(Targets::new(&still).unwrap_err(), TargetsError::FrameTime(0.0));
    }
}
