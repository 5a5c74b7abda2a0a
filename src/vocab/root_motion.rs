//! How the root moved around a segment. Primitives model joint space only
//! (the paper keeps the global root apart from `x`), so a walk that turns
//! left, one that goes straight and one that turns right are one cluster of
//! joint-space paths, and so are a walk forward and a walk sideways when
//! the legs move alike. What tells such activities apart is the root: its
//! turning and its travel in the body's own frame, over the stretch of the
//! take around the segment (an activity holds for seconds; a straight step
//! in the middle of a turn belongs to the turn).

use crate::mocap::pose::Motion;
use crate::vocab::segment::Span;
use std::f64::consts::{PI, TAU};

/// Seconds of the take on each side of a segment's middle over which the
/// root's motion is averaged (never less than the segment itself).
pub const CONTEXT_S: f64 = 2.0;

/// Turning slower than this (rad/s, about 14°/s) counts as not turning: a
/// quarter turn spread over the context's four seconds still counts, while
/// the sway of a person standing or gesturing does not.
pub const TURN_RAD_S: f64 = 0.25;

/// Travel slower than this (m/s) counts as in place: the slowest real walks
/// seen cover 0.6 m/s, a standing body's sway a few cm/s.
pub const TRAVEL_M_S: f64 = 0.3;

/// The root's mean motion around a segment, in the body's own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootMotion {
    /// Heading change per second; positive turns to the person's left.
    pub turn_rad_s: f64,
    /// Horizontal velocity along the way the body faces, and to its left.
    pub forward_m_s: f64,
    pub left_m_s: f64,
}

/// Which way the root turned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Turn {
    Left,
    Straight,
    Right,
}

/// Where the root travelled, relative to the way the body faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Travel {
    InPlace,
    Forward,
    Back,
    Left,
    Right,
}

/// The root's motion as a kind: segments of one kind can share a primitive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct RootClass {
    pub turn: Turn,
    pub travel: Travel,
}

impl RootMotion {
    /// The mean over the frames within [`CONTEXT_S`] of `span`'s middle,
    /// and at least over `span`, kept within the take.
    pub fn around(motion: &Motion, span: Span) -> RootMotion {
        let poses = &motion.poses;
        let reach = (CONTEXT_S / motion.frame_time_s).round() as usize;
        let middle = (span.first + span.last) / 2;
        let first = span.first.min(middle.saturating_sub(reach));
        let last = span.last.max(middle + reach).min(poses.len() - 1);
        if last == first {
            return RootMotion { turn_rad_s: 0.0, forward_m_s: 0.0, left_m_s: 0.0 };
        }
        let (mut turn, mut forward, mut left) = (0.0, 0.0, 0.0);
        for w in poses[first..=last].windows(2) {
            turn += (w[1].heading - w[0].heading + PI).rem_euclid(TAU) - PI;
            let step = w[1].root - w[0].root;
            let (sin, cos) = w[0].heading.sin_cos();
            forward += step.x * sin + step.z * cos;
            left += step.x * cos - step.z * sin;
        }
        let seconds = (last - first) as f64 * motion.frame_time_s;
        RootMotion { turn_rad_s: turn / seconds, forward_m_s: forward / seconds, left_m_s: left / seconds }
    }

    pub fn class(&self) -> RootClass {
        let turn = if self.turn_rad_s > TURN_RAD_S {
            Turn::Left
        } else if self.turn_rad_s < -TURN_RAD_S {
            Turn::Right
        } else {
            Turn::Straight
        };
        // Four quarters around the body, each 90° wide.
        let travel = if self.forward_m_s.hypot(self.left_m_s) < TRAVEL_M_S {
            Travel::InPlace
        } else if self.forward_m_s.abs() >= self.left_m_s.abs() {
            if self.forward_m_s > 0.0 { Travel::Forward } else { Travel::Back }
        } else if self.left_m_s > 0.0 {
            Travel::Left
        } else {
            Travel::Right
        };
        RootClass { turn, travel }
    }
}

/// Splits `members` (segments, by index into `classes`) by their root's
/// class: each class held by at least `min_size` segments forms a group,
/// and the segments of rarer classes join the most common class (a
/// stumble is not an activity). Groups come in order of their first
/// member, each with its class; one group when the segments all move
/// alike, none when there are no members.
pub fn root_groups(members: &[usize], classes: &[RootClass], min_size: usize) -> Vec<(RootClass, Vec<usize>)> {
    // Each class with its count, in order of first appearance.
    let mut tally: Vec<(RootClass, usize)> = Vec::new();
    for &i in members {
        match tally.iter_mut().find(|(c, _)| *c == classes[i]) {
            Some((_, n)) => *n += 1,
            None => tally.push((classes[i], 1)),
        }
    }
    // The most common class, the first to appear among equals.
    let Some(common) = tally.iter().fold(None, |best: Option<&(RootClass, usize)>, t| match best {
        Some(b) if b.1 >= t.1 => Some(b),
        _ => Some(t),
    }) else {
        return Vec::new();
    };
    let mut groups: Vec<(RootClass, Vec<usize>)> = Vec::new();
    for &i in members {
        let own = tally.iter().find(|(c, _)| *c == classes[i]).expect("tallied above");
        let class = if own.1 >= min_size { own.0 } else { common.0 };
        match groups.iter_mut().find(|(c, _)| *c == class) {
            Some((_, group)) => group.push(i),
            None => groups.push((class, vec![i])),
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Body;
    use crate::mocap::pose::Pose;
    use glam::DVec3;

    /// A take at 30 fps whose root turns at `turn` rad/s and moves at
    /// `forward` and `left` m/s in the body's frame.
    fn take(frames: usize, turn: f64, forward: f64, left: f64) -> Motion {
        let body = Body::standard();
        let dt = 1.0 / 30.0;
        let mut pose = Pose::rest(&body);
        pose.heading = 3.0; // near half a turn, so the heading wraps as it turns
        let mut poses = Vec::new();
        for _ in 0..frames {
            poses.push(pose);
            let (sin, cos) = pose.heading.sin_cos();
            let facing = DVec3::new(sin, 0.0, cos);
            let to_left = DVec3::new(cos, 0.0, -sin);
            pose.root += (facing * forward + to_left * left) * dt;
            pose.heading = (pose.heading + turn * dt + PI).rem_euclid(TAU) - PI;
        }
        Motion { body, frame_time_s: dt, poses }
    }

    #[test]
    fn turning_and_travel_are_read_in_the_body_frame_across_the_heading_wrap() {
        let m = RootMotion::around(&take(300, 0.5, 1.2, -0.4), Span { first: 100, last: 130 });
        assert!((m.turn_rad_s - 0.5).abs() < 1e-9, "{m:?}");
        // Velocity read at each frame's start heading lags the turn by half a
        // frame: within a percent.
        assert!((m.forward_m_s - 1.2).abs() < 0.012 && (m.left_m_s + 0.4).abs() < 0.012, "{m:?}");
        assert_eq!(m.class(), RootClass { turn: Turn::Left, travel: Travel::Forward });
        let backwards = RootMotion::around(&take(300, -0.4, -0.8, 0.1), Span { first: 0, last: 20 }).class();
        assert_eq!(backwards, RootClass { turn: Turn::Right, travel: Travel::Back });
        let sideways = RootMotion::around(&take(300, 0.0, 0.2, 0.9), Span { first: 0, last: 20 }).class();
        assert_eq!(sideways, RootClass { turn: Turn::Straight, travel: Travel::Left });
    }

    #[test]
    fn the_context_reaches_two_seconds_each_side_of_the_middle_within_the_take() {
        // Still for 8 s, then turning: a segment at 7.3 s sees the first
        // 1.3 s of the turn, a third of its four-second context.
        let mut m = take(240, 0.0, 0.0, 0.0);
        // Both start facing the same way, so the turn continues the stillness.
        m.poses.extend(take(240, 1.0, 0.0, 0.0).poses);
        let at = |first, last| RootMotion::around(&m, Span { first, last });
        assert!(at(90, 91).turn_rad_s.abs() < 1e-9, "{:?}", at(90, 91));
        let reaching = at(220, 221).turn_rad_s;
        assert!((reaching - 1.0 / 3.0).abs() < 1e-9, "{reaching}");
        // The take's ends clip the window; a one-frame take does not move.
        assert!((at(470, 479).turn_rad_s - 1.0).abs() < 1e-9);
        assert_eq!(
            RootMotion::around(&take(1, 1.0, 1.0, 0.0), Span { first: 0, last: 0 }).class().travel,
            Travel::InPlace
        );
    }

    #[test]
    fn sway_is_in_place_and_straight() {
        let class = RootMotion::around(&take(120, 0.1, 0.05, 0.05), Span { first: 0, last: 119 }).class();
        assert_eq!(class, RootClass { turn: Turn::Straight, travel: Travel::InPlace });
    }

    #[test]
    fn rare_root_motions_join_the_most_common_and_groups_keep_first_appearance_order() {
        let (s, l, r) = (
            RootClass { turn: Turn::Straight, travel: Travel::Forward },
            RootClass { turn: Turn::Left, travel: Travel::Forward },
            RootClass { turn: Turn::Right, travel: Travel::Forward },
        );
        let classes = [l, s, s, r, l, s, s];
        let groups = root_groups(&[0, 1, 2, 3, 4, 5, 6], &classes, 2);
        // One right turn alone joins the straight walk, the commonest.
        assert_eq!(groups, vec![(l, vec![0, 4]), (s, vec![1, 2, 3, 5, 6])]);
        // Between classes as common, the first to appear takes the rare.
        assert_eq!(root_groups(&[0, 1, 2, 3, 4], &classes, 2), vec![(l, vec![0, 3, 4]), (s, vec![1, 2])]);
        assert_eq!(root_groups(&[1, 2, 5], &classes, 2), vec![(s, vec![1, 2, 5])]);
        assert!(root_groups(&[], &classes, 2).is_empty());
    }
}
