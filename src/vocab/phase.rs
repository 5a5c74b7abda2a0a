//! Registering the phase of repetitions. A periodic movement has no
//! natural first frame: the segmenter cuts each repetition wherever the
//! previous one ended, so the same movement starts at different points of
//! its cycle in different takes. Segments that are whole cycles are turned
//! to a common starting point: where the first harmonic of their motion
//! along the corpus's principal axes has phase zero. That is
//! shift-equivariant (turning a cycle turns the harmonic with it) and
//! continuous in the motion, and the axes are fixed for the whole corpus, so
//! the same movement gets the same starting point in every take. Embedding
//! compares registered cycles, and attractor progress counts phase from the
//! registered start.

use crate::mocap::body::{DOF, JointVector};
use crate::mocap::pose::Motion;
use crate::vocab::corpus::Corpus;
use crate::vocab::pca::principal_components;
use crate::vocab::segment::Span;
use std::f64::consts::TAU;

/// Principal axes the phase is read along.
const AXES: usize = 6;
/// Samples around a cycle for its first harmonic.
const SAMPLES: usize = 32;
/// At most this many frames, evenly spread, estimate the axes.
const AXIS_FRAMES: usize = 100_000;

/// A segment's poses measured along the path they trace in joint space:
/// fraction 0 is its first pose, 1 its last, and equal steps of fraction
/// cover equal distances. Pauses take up no room, and speeding up or
/// slowing down inside a movement does not move its poses along, so where
/// a cut falls inside a pause, or how fast a repetition was, does not
/// change how its path compares with others.
pub struct ArcPath<'a> {
    motion: &'a Motion,
    span: Span,
    /// Path length from the first frame to each frame; `None` for a path
    /// of no length, which is measured in frames instead.
    lengths: Option<Vec<f64>>,
}

impl<'a> ArcPath<'a> {
    pub fn new(motion: &'a Motion, span: Span) -> ArcPath<'a> {
        let mut lengths = Vec::with_capacity(span.frames());
        let mut total = 0.0;
        lengths.push(0.0);
        for t in span.first + 1..=span.last {
            let (a, b) = (&motion.poses[t - 1].x, &motion.poses[t].x);
            total += a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
            lengths.push(total);
        }
        let moving = total > 1e-9;
        ArcPath { motion, span, lengths: moving.then_some(lengths) }
    }

    /// How far along the path frame `t` of the span lies, in [0, 1].
    pub fn fraction_at_frame(&self, t: usize) -> f64 {
        let i = t - self.span.first;
        match &self.lengths {
            Some(l) => l[i] / l[l.len() - 1],
            None if self.span.frames() == 1 => 0.0,
            None => i as f64 / (self.span.frames() - 1) as f64,
        }
    }

    /// The pose at fraction `at` ∈ [0, 1] of the path, interpolated
    /// linearly between the frames on either side.
    pub fn pose_at(&self, at: f64) -> JointVector {
        let at = at.clamp(0.0, 1.0);
        let last = self.span.frames() - 1;
        let (i, t) = match &self.lengths {
            None => {
                let position = at * last as f64;
                (position.floor() as usize, position.fract())
            }
            Some(l) => {
                let target = at * l[last];
                // The last frame at or before the target distance.
                let i = l.partition_point(|&d| d <= target).saturating_sub(1).min(last);
                let step = if i < last { l[i + 1] - l[i] } else { 0.0 };
                (i, if step > 0.0 { (target - l[i]) / step } else { 0.0 })
            }
        };
        let a = &self.motion.poses[self.span.first + i].x;
        let b = &self.motion.poses[self.span.first + (i + 1).min(last)].x;
        std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t)
    }
}

/// The corpus's principal axes of pose.
#[derive(Clone, Debug)]
pub struct PhaseAxes {
    mean: JointVector,
    axes: Vec<JointVector>,
}

impl PhaseAxes {
    pub fn of(corpus: &Corpus) -> PhaseAxes {
        let total = corpus.frames();
        let stride = total.div_ceil(AXIS_FRAMES).max(1);
        let poses: Vec<JointVector> =
            corpus.takes.iter().flat_map(|t| t.motion.poses.iter().map(|p| p.x)).step_by(stride).collect();
        let (mean, _, vectors) = principal_components(&poses);
        PhaseAxes { mean, axes: vectors.into_iter().take(AXES).collect() }
    }

    /// Where in `span` (a whole cycle) its registered start lies, as a
    /// fraction of the cycle in [0, 1).
    pub fn offset(&self, motion: &Motion, span: Span) -> f64 {
        let path = ArcPath::new(motion, span);
        let mut harmonics = vec![(0.0, 0.0); self.axes.len()];
        for n in 0..SAMPLES {
            let x = path.pose_at(n as f64 / SAMPLES as f64);
            let (s, c) = (TAU * n as f64 / SAMPLES as f64).sin_cos();
            for (h, axis) in harmonics.iter_mut().zip(&self.axes) {
                let p: f64 = (0..DOF).map(|k| axis[k] * (x[k] - self.mean[k])).sum();
                h.0 += p * c;
                h.1 -= p * s;
            }
        }
        // Each axis's harmonic weighted by its own amplitude: axes the
        // movement barely uses barely count.
        let (re, im) = harmonics.iter().fold((0.0, 0.0), |(re, im), &(a, b)| {
            let amplitude = a.hypot(b);
            (re + amplitude * a, im + amplitude * b)
        });
        (-im.atan2(re) / TAU).rem_euclid(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::synth::{Activity, SynthOptions, activity_take};
    use crate::vocab::corpus::Recording;

    #[test]
    fn the_same_cycle_started_anywhere_registers_to_the_same_pose() {
        let take = activity_take(Activity::Circles, &SynthOptions { variation: 0.0, fps: 120.0, ..Default::default() });
        let period = (Activity::Circles.period_s() * 120.0).round() as usize;
        let corpus = Corpus {
            takes: vec![Recording { path: "c.bvh".into(), motion: take.motion.clone(), labels: None }],
            label_names: vec![],
        };
        let axes = PhaseAxes::of(&corpus);
        // Two cuts of one cycle, starting a third of a cycle apart.
        let middle = take.motion.poses.len() / 2;
        let starts = [middle, middle + period / 3];
        let registered: Vec<JointVector> = starts
            .iter()
            .map(|&s| {
                let span = Span { first: s, last: s + period };
                ArcPath::new(&take.motion, span).pose_at(axes.offset(&take.motion, span))
            })
            .collect();
        let distance: f64 = registered[0].iter().zip(&registered[1]).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
        assert!(distance < 0.02, "registered starts differ by {distance} rad");
    }

    #[test]
    fn the_path_is_measured_by_distance_and_pauses_take_no_room() {
        let take = activity_take(Activity::Circles, &SynthOptions::default());
        let mut motion = take.motion.clone();
        // Four frames mid-take, the second a pause (the first pose again).
        let f = motion.poses.len() / 2;
        motion.poses[f + 1] = motion.poses[f];
        let span = Span { first: f, last: f + 3 };
        let path = ArcPath::new(&motion, span);
        let d = |a: usize, b: usize| -> f64 {
            motion.poses[a].x.iter().zip(&motion.poses[b].x).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
        };
        let (first, second) = (d(f + 1, f + 2), d(f + 2, f + 3));
        assert!(first > 0.0 && second > 0.0);
        assert_eq!(path.fraction_at_frame(f + 1), 0.0);
        assert!((path.fraction_at_frame(f + 2) - first / (first + second)).abs() < 1e-12);
        assert_eq!(path.fraction_at_frame(f + 3), 1.0);
        // Halfway between frames 12 and 13 by distance.
        let at = (first + 0.5 * second) / (first + second);
        let mid = path.pose_at(at);
        let (a, b) = (&motion.poses[f + 2].x, &motion.poses[f + 3].x);
        assert!((0..DOF).all(|k| (mid[k] - 0.5 * (a[k] + b[k])).abs() < 1e-12));
        assert_eq!(path.pose_at(1.0), motion.poses[f + 3].x);
        assert_eq!(path.pose_at(0.0), motion.poses[f].x);
    }

    #[test]
    fn a_still_span_is_measured_in_frames() {
        let take = activity_take(Activity::Punch, &SynthOptions::default());
        let mut motion = take.motion.clone();
        let still = motion.poses[0];
        motion.poses[..5].iter_mut().for_each(|p| *p = still);
        let path = ArcPath::new(&motion, Span { first: 0, last: 4 });
        assert_eq!(path.fraction_at_frame(1), 0.25);
        assert_eq!(path.pose_at(0.6), still.x);
    }
}
