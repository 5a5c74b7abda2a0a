//! The demonstrator's repertoire: the paper's activities (hand circles,
//! horizontal and vertical waving, punching) plus reaching and "the twist".
//! Each is a [`Drive`] as a function of the phase within one repetition,
//! shaped by that repetition's [`Variation`]. The right arm leads; the
//! other arm, the torso, head and legs move with it.

use super::rig::{Drive, Rig};
use crate::mocap::math::smoothstep5;
use glam::DVec3;
use std::f64::consts::TAU;

/// One of the activities `synth` can perform.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Activity {
    Circles,
    WaveH,
    WaveV,
    Punch,
    Reach,
    Twist,
}

impl Activity {
    pub const ALL: [Activity; 6] =
        [Activity::Circles, Activity::WaveH, Activity::WaveV, Activity::Punch, Activity::Reach, Activity::Twist];

    /// The name used on the command line, in file names and in labels.
    pub fn name(self) -> &'static str {
        match self {
            Activity::Circles => "circles",
            Activity::WaveH => "wave-h",
            Activity::WaveV => "wave-v",
            Activity::Punch => "punch",
            Activity::Reach => "reach",
            Activity::Twist => "twist",
        }
    }

    pub fn from_name(name: &str) -> Option<Activity> {
        Activity::ALL.into_iter().find(|a| a.name() == name)
    }

    /// Seconds per repetition at 1× speed.
    pub fn period_s(self) -> f64 {
        match self {
            Activity::Circles => 1.3,
            Activity::WaveH | Activity::WaveV => 0.9,
            Activity::Punch => 1.2,
            Activity::Reach => 2.2,
            Activity::Twist => 0.8,
        }
    }
}

/// How one repetition differs from the template: all fields are 0 (or 1
/// for the factors) when variation is off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variation {
    /// Factor on the size of the motion.
    pub amplitude: f64,
    /// Factor on the duration of the repetition.
    pub period: f64,
    /// Shift of the hand path, in arm lengths.
    pub offset: DVec3,
    /// Two free shape parameters, about unit size (e.g. where to reach).
    pub shape: [f64; 2],
    /// Shift of the elbow's preferred direction.
    pub pole: f64,
}

/// Number of random numbers behind one [`Variation`].
pub const VARIATION_PARAMS: usize = 8;

impl Variation {
    /// Maps standard normal draws (already scaled by the user's variation)
    /// to a variation.
    pub fn from_params(p: &[f64; VARIATION_PARAMS]) -> Variation {
        Variation {
            amplitude: 1.0 + 0.08 * p[0],
            period: 1.0 + 0.07 * p[1],
            offset: DVec3::new(p[2], p[3], p[4]) * 0.03,
            shape: [p[5], p[6]],
            pole: 0.25 * p[7],
        }
    }
}

/// The arm sides: index into [`Drive`] arrays and the sign of the outward
/// X direction. The right arm (index 1) leads every one-armed activity.
const LEFT: (usize, f64) = (0, 1.0);
const RIGHT: (usize, f64) = (1, -1.0);

/// Standing at ease: arms hanging with soft elbows, knees barely bent.
pub fn rest(rig: &Rig) -> Drive {
    let hang = rig.reach_at(12f64.to_radians());
    let hand = |side: f64| DVec3::new(side * 0.08, -1.0, 0.06).normalize() * hang;
    let pole = |side: f64| DVec3::new(side * 0.25, 0.0, -1.0);
    Drive {
        hands: [hand(1.0), hand(-1.0)],
        poles: [pole(1.0), pole(-1.0)],
        wrists: [DVec3::ZERO; 2],
        torso: DVec3::ZERO,
        hip_turn: 0.0,
        head: DVec3::ZERO,
        crouch: 0.004,
        shift: DVec3::ZERO,
    }
}

/// The drive of `activity` at fraction `tau` ∈ [0, 1) of a repetition.
pub fn drive(activity: Activity, tau: f64, v: &Variation, amplitude: f64, rig: &Rig) -> Drive {
    let a = amplitude * v.amplitude;
    let l = rig.arm_length();
    let theta = TAU * tau;
    let (s, c) = theta.sin_cos();
    let mut d = rest(rig);
    let (k, side) = RIGHT;
    // The idle arm swings a little against the leading one.
    d.hands[LEFT.0] += DVec3::new(0.0, 0.0, 0.02 * l * (theta + 0.5).sin());
    match activity {
        Activity::Circles => {
            let center = DVec3::new(side * 0.08, -0.10, 0.68) * l + v.offset * l;
            let r = 0.20 * l * a;
            let squash = 1.0 + 0.1 * v.shape[0];
            d.hands[k] = center + DVec3::new(side * r * c, r * squash * s, 0.05 * l * s);
            d.poles[k] = DVec3::new(side * (0.6 + 0.2 * v.pole), -1.0, -0.1);
            d.wrists[k] = DVec3::new(0.0, 0.0, 0.2 * a * s);
            d.torso = DVec3::new(0.04 + 0.015 * s, side * 0.05 * a * c, 0.03 * a * c);
            d.head = DVec3::new(-0.06 * a * s, side * 0.08 * a * c, 0.0);
            d.crouch += 0.002 * (2.0 * theta).sin();
            d.shift = DVec3::new(side * 0.01 * c, 0.0, 0.0);
        }
        Activity::WaveH => {
            let elbow = DVec3::new(side * 0.9, 0.1 * v.shape[0], 0.45 + 0.1 * v.pole).normalize() * rig.upper_arm();
            let swing = 0.10 + 0.42 * a * s;
            let forearm = DVec3::new(side * swing.sin(), swing.cos(), 0.2).normalize() * (l - rig.upper_arm());
            place_elbow(&mut d, k, elbow, forearm, v.offset * 0.5 * l);
            d.wrists[k] = DVec3::new(0.0, 0.3 * a * (theta - 0.5).sin(), 0.0);
            d.torso = DVec3::new(0.01 * s, 0.05 * s, -side * 0.03 + 0.03 * s);
            d.head = DVec3::new(0.0, side * 0.1, 0.03 * (theta - 0.4).sin());
        }
        Activity::WaveV => {
            let elbow = DVec3::new(side * 0.3, -0.55 + 0.1 * v.shape[0], 0.75).normalize() * rig.upper_arm();
            let lift = 0.5 + 0.45 * a * s;
            let forearm = DVec3::new(side * 0.05, lift.sin(), lift.cos()).normalize() * (l - rig.upper_arm());
            place_elbow(&mut d, k, elbow, forearm, v.offset * 0.5 * l);
            d.wrists[k] = DVec3::new(0.0, 0.0, 0.35 * a * (theta - 0.6).sin());
            d.torso = DVec3::new(0.02 + 0.05 * s, side * 0.04 * s, 0.03 * s);
            d.head = DVec3::new(-0.04 * s, side * 0.05, 0.0);
            d.crouch += 0.002 * s;
        }
        Activity::Punch => {
            let guard = |side: f64| DVec3::new(-side * 0.22, 0.12, 0.40) * l;
            let guard_pole = |side: f64| DVec3::new(side * 0.4, -1.0, -0.2);
            let target =
                DVec3::new(side * (-0.10 + 0.05 * v.shape[0]), 0.03 + 0.06 * v.shape[1], 1.05 * (0.9 + 0.1 * a)) * l;
            let out = pulse(tau, [0.30, 0.46, 0.54, 0.94]);
            // The fist drives out straight but comes back low and wide, the
            // elbow dropping, the forearm turning back and the shoulder
            // leading: a loop, as in captured boxing, not a retrace.
            let back = if tau > 0.54 { 4.0 * out * (1.0 - out) } else { 0.0 };
            d.hands[k] = guard(side).lerp(target, out) + DVec3::new(side * 0.12, -0.18, 0.0) * l * back + v.offset * l;
            d.poles[k] = guard_pole(side).lerp(DVec3::new(side * 0.3, -1.0, 0.0), out)
                + DVec3::new(side * 0.6, -0.6, 0.0) * back;
            let (o, other) = LEFT;
            d.hands[o] = guard(other) + DVec3::new(0.0, 0.01 * l * s, 0.0);
            d.poles[o] = guard_pole(other);
            d.torso = DVec3::new(0.04 + 0.05 * out, -side * (0.22 * a * out - 0.10 * back), 0.0);
            // The fist turns over (pronates) as it lands, and cocks back in guard.
            d.wrists[k] = DVec3::new(side * (0.8 * out - 0.6 * back), 0.0, 0.15 * (1.0 - out));
            d.hip_turn = -side * 0.08 * out;
            d.head = DVec3::new(0.0, side * 0.15 * out, 0.0);
            d.crouch = 0.02;
            d.shift = DVec3::new(0.0, 0.0, 0.02 * out);
        }
        Activity::Reach => {
            let dir = DVec3::new(side * (0.25 + 0.25 * v.shape[0]), 0.05 + 0.35 * v.shape[1], 0.9).normalize();
            // Beyond reach is fine: the arm's inverse kinematics eases it in.
            let target = dir * rig.reach_at(30f64.to_radians()) * a;
            let out = pulse(tau, [0.08, 0.42, 0.58, 0.92]);
            d.hands[k] = d.hands[k].lerp(target + v.offset * l, out);
            d.poles[k] = d.poles[k].lerp(DVec3::new(side * 0.5, -1.0, -0.2), out);
            // The hand turns palm-in and lifts toward what it reaches for.
            d.wrists[k] = DVec3::new(-side * 0.5 * out, 0.0, -0.25 * out);
            d.torso = DVec3::new(0.10 * out * dir.z, side * 0.06 * out, -side * 0.03 * out);
            d.head = DVec3::new(-0.3 * dir.y * out, side * 0.15 * out, 0.0);
            d.crouch += 0.01 * out;
            d.shift = DVec3::new(side * 0.01 * out, 0.0, 0.02 * out);
        }
        Activity::Twist => {
            for (k, side) in [LEFT, RIGHT] {
                d.hands[k] = DVec3::new(side * 0.12, -0.45 + 0.05 * (2.0 * theta).sin(), 0.45 + side * 0.10 * a * s)
                    * l
                    + v.offset * l;
                d.poles[k] = DVec3::new(side * 0.5, -0.6, -0.6);
                d.wrists[k] = DVec3::new(0.0, 0.0, 0.2 * a * (theta + side).sin());
            }
            d.hip_turn = 0.32 * a * s;
            d.torso = DVec3::new(0.06, -0.45 * a * s, 0.03 * (2.0 * theta).sin());
            d.head = DVec3::new(0.03 * (2.0 * theta).sin(), 0.1 * s, 0.0);
            d.crouch = 0.035 + 0.012 * a * (2.0 * theta).sin();
            d.shift = DVec3::new(0.015 * s, 0.0, 0.0);
        }
    }
    d
}

/// Puts arm `k`'s elbow at `elbow` and its wrist a `forearm` further on
/// (both relative to the shoulder), plus `shift`.
fn place_elbow(d: &mut Drive, k: usize, elbow: DVec3, forearm: DVec3, shift: DVec3) {
    let hand = elbow + forearm;
    let axis = hand.normalize();
    d.hands[k] = hand + shift;
    d.poles[k] = elbow - axis * elbow.dot(axis);
}

/// 0 before `t[0]`, rising (minimum-jerk) to 1 at `t[1]`, holding until
/// `t[2]`, falling back to 0 at `t[3]`: a C2 out-and-back movement.
fn pulse(tau: f64, t: [f64; 4]) -> f64 {
    smoothstep5((tau - t[0]) / (t[1] - t[0])) - smoothstep5((tau - t[2]) / (t[3] - t[2]))
}
