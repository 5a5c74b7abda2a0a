//! A capture that starts in a bind pose (the T-pose many capture files
//! open with): found, so that `execute` leaves the frame out.

use super::targets::motorized;
use crate::mocap::body::Joint;
use crate::mocap::math::angle_between;
use crate::mocap::pose::{Motion, Pose};

/// The joint that turns most from pose `a` to pose `b`, and by how much,
/// radians.
fn largest_turn(a: &Pose, b: &Pose) -> (Joint, f64) {
    motorized()
        .map(|j| (j, angle_between(a.local_rotation(j), b.local_rotation(j))))
        .fold((Joint::Pelvis, 0.0), |most, turn| if turn.1 > most.1 { turn } else { most })
}

/// A first frame that looks like a bind pose (the T-pose many capture files
/// start with): some joint turns more than 45° from it to the next frame,
/// more than three times the largest turn of nine in ten later frames
/// (measured on the real captures: 77–126° against at most 30°; the
/// largest later turn is no yardstick, as retargeting glitches and fast
/// kicks reach 170°).
pub fn bind_pose_start(motion: &Motion) -> Option<BindPose> {
    let poses = &motion.poses;
    if poses.len() < 3 {
        return None;
    }
    let (joint, first) = largest_turn(&poses[0], &poses[1]);
    let mut later: Vec<f64> = poses[1..].windows(2).map(|w| largest_turn(&w[0], &w[1]).1).collect();
    later.sort_by(f64::total_cmp);
    let typical = later[(later.len() * 9 / 10).min(later.len() - 1)];
    (first > 45f64.to_radians() && first > 3.0 * typical).then_some(BindPose {
        joint,
        turn_rad: first,
        typical_rad: typical,
    })
}

/// A bind pose found at the start of a trajectory ([`bind_pose_start`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BindPose {
    /// The joint that turns most from the first frame to the next,
    pub joint: Joint,
    /// by this much, radians,
    pub turn_rad: f64,
    /// where nine in ten later frames turn no joint more than this.
    pub typical_rad: f64,
}

impl std::fmt::Display for BindPose {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} turns {:.0}° from the first frame to the next, where nine in ten later frames turn no joint more \
             than {:.0}°",
            self.joint.name(),
            self.turn_rad.to_degrees(),
            self.typical_rad.to_degrees()
        )
    }
}

/// How many leading frames of `motion` to leave out: `asked` when given
/// (`None` when it is not less than the frames there are), else one when
/// the first frame is a bind pose, which no body can leave in one frame
/// (most real captures start with one), else none; and that bind pose.
pub fn frames_to_skip(motion: &Motion, asked: Option<usize>) -> Option<(usize, Option<BindPose>)> {
    let frames = motion.poses.len();
    match asked {
        Some(n) if n >= frames && frames > 0 => None,
        Some(n) => Some((n, None)),
        None => {
            let bind = bind_pose_start(motion);
            Some((usize::from(bind.is_some()), bind))
        }
    }
}
