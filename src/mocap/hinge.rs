//! The hinge axes of the arms and legs (elbows, knees) over a take.
//!
//! A bent limb's hinge axis is the normal of the plane it bends in, signed
//! so the hinge flexes when it bends deeply (no elbow or knee bends 44°
//! past straight) and, below that, so the limb keeps its twist. A nearly
//! straight limb's plane is noise, so its axis comes from a reference (the
//! source's own limb frame, calibrated on the take's clear bends, or the
//! limb's geometry where the take hardly bends it), kept continuous in
//! sign, and the axis is carried from frame to frame: it may turn about the
//! limb only as fast as a person twists an arm or leg. So no twist flips in
//! one frame where the bones hardly move, whatever the bend plane's noise
//! or the source frame does.

use crate::mocap::math::smoothstep5;
use glam::{DMat3, DQuat, DVec3};

/// Sine of the bend (20°) from which the bend plane says where the hinge
/// axis is; below it the axis follows the reference.
const CLEAR_BEND_SIN: f64 = 0.34;

/// Sine of the bend (10°) from which the bend plane's normal is steady
/// enough (a few degrees of capture noise) to turn the axis faster than a
/// twist; fully so from [`CLEAR_BEND_SIN`].
const STEADY_BEND_SIN: f64 = 0.17;

/// Sine of the bend (44°) from which the axis is the bend plane's normal in
/// every frame, so the far segment's direction is exact.
const EXACT_BEND_SIN: f64 = 0.7;

/// How fast a nearly straight limb's axis may turn about the limb, rad/s
/// (360°/s: a quarter turn in a quarter second; at 30 frames/s, 12° a
/// frame).
const MAX_TWIST_RATE: f64 = 6.3;

/// Sine of the bend (6°) from which a frame's bend plane counts toward a
/// take's hinge axis.
pub const CALIBRATION_BEND_SIN: f64 = 0.1;

/// Bent frames a take needs (of its sampled frames, at most a tenth, at
/// least one) before its bends calibrate a hinge axis.
const MIN_BENT_FRAMES: usize = 12;

/// Share of the bends' weight the calibrated axis must carry.
const MIN_AGREEMENT: f64 = 0.5;

/// One frame's view of a limb: the upper segment's direction, how it
/// bends, and the reference axis for when it is straight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bend {
    /// Unit direction of the upper segment (shoulder to elbow, hip to knee).
    pub upper: DVec3,
    /// Unit normal of the bend plane, signed for flexion (`upper × lower`).
    pub normal: Option<DVec3>,
    /// Sine of the angle between the segments.
    pub sin: f64,
    /// Unit reference axis perpendicular to `upper`, signed for flexion.
    pub reference: Option<DVec3>,
    /// The reference is a source joint's frame, which may flip half a turn
    /// from one frame to the next; one from positions never does.
    pub reference_may_flip: bool,
}

impl Bend {
    /// The bend of segments `upper` then `lower`, with a reference axis.
    pub fn new(upper: DVec3, lower: DVec3, reference: Option<DVec3>, reference_may_flip: bool) -> Option<Bend> {
        let (u, v) = (upper.try_normalize()?, lower.try_normalize()?);
        let cross = u.cross(v);
        let reference = reference.and_then(|r| (r - u * r.dot(u)).try_normalize());
        Some(Bend { upper: u, normal: cross.try_normalize(), sin: cross.length(), reference, reference_may_flip })
    }

    /// The axis this frame says on its own: the bend plane's normal when
    /// clearly bent, else the reference.
    pub fn axis(&self) -> Option<DVec3> {
        match self.normal {
            Some(n) if self.sin >= CLEAR_BEND_SIN => Some(n),
            _ => self.reference.or(self.normal),
        }
    }
}

/// Carries one limb's hinge axis from frame to frame (see the module's
/// documentation), a frame at a time, so a long take can be solved in
/// pieces.
pub struct Tracker {
    straight_step: f64,
    /// The last axis and the upper segment it was perpendicular to.
    carried: Option<(DVec3, DVec3)>,
    reference: Unflipped,
}

impl Tracker {
    pub fn new(frame_time_s: f64) -> Tracker {
        Tracker { straight_step: MAX_TWIST_RATE * frame_time_s, carried: None, reference: Unflipped::default() }
    }

    /// The next frame's axis; `None` where the frame has no limb, which
    /// also ends what is carried.
    pub fn next(&mut self, bend: Option<&Bend>) -> Option<DVec3> {
        let Some(bend) = bend else {
            self.carried = None;
            self.reference = Unflipped::default();
            return None;
        };
        let unflipped =
            bend.reference.map(|r| if bend.reference_may_flip { self.reference.next(r, bend.upper) } else { r });
        let Some((axis, upper)) = self.carried else {
            let axis = bend.axis();
            self.carried = axis.map(|a| (a, bend.upper));
            return axis;
        };
        let u = bend.upper;
        // Carry the axis along as the upper segment swings.
        let moved = DQuat::from_rotation_arc(upper, u) * axis;
        let moved = (moved - u * moved.dot(u)).try_normalize().unwrap_or(axis);
        // The bend plane counts the more the limb bends (fully from 44°,
        // where the far segment's direction is exact), the reference the
        // rest. Which way the limb bends: a slight bend keeps the carried
        // twist (hyperextended a little, or capture noise); a clear one
        // (20°) goes the reference's way; a deep one is a flexion, and a
        // twist that said otherwise was wrong.
        let side = if bend.sin < CLEAR_BEND_SIN { moved } else { unflipped.unwrap_or(moved) };
        let weight = smoothstep5(bend.sin / EXACT_BEND_SIN);
        let target = match bend.normal {
            Some(n) => {
                let n = if n.dot(side) < 0.0 && bend.sin < EXACT_BEND_SIN { -n } else { n };
                (n * weight + unflipped.unwrap_or(n) * (1.0 - weight)).try_normalize().or(Some(n))
            }
            None => unflipped,
        };
        let next = match target {
            Some(target) => {
                // Only a steady bend plane turns the axis faster than a
                // twist.
                let clear = smoothstep5((bend.sin - STEADY_BEND_SIN) / (CLEAR_BEND_SIN - STEADY_BEND_SIN));
                let step = self.straight_step + clear * (std::f64::consts::PI - self.straight_step);
                turn_toward(moved, target, u, step)
            }
            None => moved,
        };
        self.carried = Some((next, u));
        Some(next)
    }
}

/// A reference that turns more than this (cosine of 135°, negated) in one
/// frame has flipped, not turned.
const FLIP_COS: f64 = 0.7;

/// A reference axis kept continuous in sign: where it all but reverses
/// from one frame to the next (a source frame that flips half a turn,
/// which no limb does), it is reversed back, for the rest of the take.
#[derive(Default)]
struct Unflipped {
    last: Option<(DVec3, DVec3)>,
    reversed: bool,
}

impl Unflipped {
    fn next(&mut self, reference: DVec3, upper: DVec3) -> DVec3 {
        let mut r = if self.reversed { -reference } else { reference };
        if let Some((last, last_upper)) = self.last
            && (DQuat::from_rotation_arc(last_upper, upper) * last).dot(r) < -FLIP_COS
        {
            self.reversed = !self.reversed;
            r = -r;
        }
        self.last = Some((r, upper));
        r
    }
}

/// `from` turned about `about` toward `to` by at most `step` radians (both
/// perpendicular to `about`).
fn turn_toward(from: DVec3, to: DVec3, about: DVec3, step: f64) -> DVec3 {
    let angle = from.cross(to).dot(about).atan2(from.dot(to));
    DQuat::from_axis_angle(about, angle.clamp(-step, step)) * from
}

/// A hinge axis in the limb root's own frame for a take: the dominant
/// axis of the bend normals of its bent frames (`bent`, in that frame,
/// each as long as the sine of its bend) when there are enough of `frames`
/// sampled frames and they agree on it; else the sum of the geometric
/// references in that frame (`geometric`). A knee's is signed by the
/// geometry: knees bend backward.
pub fn calibrate(bent: &[DVec3], geometric: DVec3, frames: usize, knee: bool) -> Option<DVec3> {
    let enough = bent.len() >= MIN_BENT_FRAMES.min(frames.div_ceil(10)).max(1);
    let geometric = geometric.try_normalize();
    // Bends that scatter every way are noise, not a hinge.
    let agreeing = |axis: &DVec3| {
        let along: f64 = bent.iter().map(|v| v.dot(*axis)).sum();
        along >= MIN_AGREEMENT * bent.iter().map(|v| v.length()).sum::<f64>()
    };
    match (enough.then(|| dominant_axis(bent)).flatten().filter(agreeing), geometric) {
        (Some(axis), Some(g)) if knee && axis.dot(g) < 0.0 => Some(-axis),
        (Some(axis), _) => Some(axis),
        (None, g) => g,
    }
}

/// The unit axis along which `vectors` spread most (the top eigenvector of
/// Σ v vᵀ, by power iteration), signed to agree with most of them
/// (weighted by length). `None` when they are all zero.
fn dominant_axis(vectors: &[DVec3]) -> Option<DVec3> {
    let scatter = vectors.iter().fold(DMat3::ZERO, |m, v| m + DMat3::from_cols(*v * v.x, *v * v.y, *v * v.z));
    // Start from the column with the most weight: never orthogonal to the
    // top eigenvector unless the scatter is zero.
    let mut axis = [scatter.x_axis, scatter.y_axis, scatter.z_axis]
        .into_iter()
        .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))?
        .try_normalize()?;
    for _ in 0..100 {
        let next = (scatter * axis).try_normalize()?;
        let converged = next.dot(axis) > 1.0 - 1e-15;
        axis = next;
        if converged {
            break;
        }
    }
    let agreement: f64 = vectors.iter().map(|v| v.dot(axis)).sum();
    Some(if agreement < 0.0 { -axis } else { axis })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(bends: &[Option<Bend>], frame_time_s: f64) -> Vec<Option<DVec3>> {
        let mut tracker = Tracker::new(frame_time_s);
        bends.iter().map(|b| tracker.next(b.as_ref())).collect()
    }

    fn bend(upper: DVec3, lower: DVec3, reference: DVec3) -> Option<Bend> {
        Bend::new(upper, lower, Some(reference), true)
    }

    #[test]
    fn a_bent_limb_follows_its_bend_plane_signed_for_flexion() {
        // Upper arm along +X, forearm swung toward +Z: flexion about −Y.
        let b = bend(DVec3::X, DVec3::new(0.5, 0.0, 0.8), DVec3::Y).unwrap();
        let axes = track(&[Some(b)], 1.0 / 30.0);
        assert!(axes[0].unwrap().abs_diff_eq(DVec3::NEG_Y, 1e-12));
    }

    #[test]
    fn a_straight_limb_ignores_a_reference_that_flips_and_turns_only_so_fast() {
        let straight = DVec3::X;
        let mut bends = vec![bend(DVec3::X, straight, DVec3::Y); 5];
        // The source frame flips half a turn, then turns a quarter: the
        // flip is undone, so the quarter turn ends at −Z.
        bends.extend(vec![bend(DVec3::X, straight, DVec3::NEG_Y); 5]);
        bends.extend(vec![bend(DVec3::X, straight, DVec3::Z); 10]);
        let axes = track(&bends, 1.0 / 30.0);
        for a in &axes[..10] {
            assert!(a.unwrap().abs_diff_eq(DVec3::Y, 1e-12), "{a:?}");
        }
        let turns: Vec<f64> = axes.windows(2).map(|w| w[0].unwrap().angle_between(w[1].unwrap())).collect();
        assert!(turns.iter().all(|&t| t <= MAX_TWIST_RATE / 30.0 + 1e-9), "{turns:?}");
        assert!(axes[19].unwrap().abs_diff_eq(DVec3::NEG_Z, 1e-9), "{:?}", axes[19]);
    }

    #[test]
    fn the_axis_is_carried_along_as_the_limb_swings() {
        // A straight arm swings from +X to +Z with no reference at all.
        let mut bends = vec![Bend::new(DVec3::X, DVec3::new(0.5, 0.0, 0.8), None, false)];
        for i in 1..=10 {
            let t = i as f64 / 10.0 * std::f64::consts::FRAC_PI_2;
            let u = DVec3::new(t.cos(), 0.0, t.sin());
            bends.push(Bend::new(u, u, None, false));
        }
        let axes = track(&bends, 1.0 / 30.0);
        assert!(axes[10].unwrap().abs_diff_eq(DVec3::NEG_Y, 1e-9), "{:?}", axes[10]);
    }

    #[test]
    fn a_knee_calibrated_on_noise_takes_the_geometrys_axis_and_sign() {
        let few = [DVec3::new(0.0, 0.0, 0.3)];
        assert_eq!(calibrate(&few, DVec3::X * 5.0, 64, true), Some(DVec3::X));
        let many = vec![DVec3::NEG_X * 0.5; 20];
        assert_eq!(calibrate(&many, DVec3::X, 64, true), Some(DVec3::X));
        assert_eq!(calibrate(&many, DVec3::X, 64, false), Some(DVec3::NEG_X));
    }
}
