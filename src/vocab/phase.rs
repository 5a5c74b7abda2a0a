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

    /// The path's length in joint space (0 for a still span).
    pub fn length(&self) -> f64 {
        self.lengths.as_ref().map_or(0.0, |l| l[l.len() - 1])
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

/// Rounds of template refinement in [`CycleTemplate::fit`].
const ALIGN_ROUNDS: usize = 3;

/// The mean cycle of one movement, and where each of its cycles starts.
///
/// Within one primitive this registers phase more exactly than the
/// corpus-wide first harmonic, which reads phase along axes shared by every
/// movement and so wavers where a movement's shape varies between
/// repetitions; and it places partial swings (cut where a take starts,
/// ends or changes activity) on the cycle, so their phase agrees with the
/// whole cycles'.
pub struct CycleTemplate {
    /// Poses at phases `origin + k / SAMPLES`, k = 0, 1, ….
    poses: Vec<JointVector>,
    origin: f64,
    /// Mean path length of a cycle (joint space).
    length: f64,
    /// Each cycle's registered start, in the order given.
    pub offsets: Vec<f64>,
}

impl CycleTemplate {
    /// Registers whole cycles against each other: each cycle, sampled along
    /// its path from its current start (`offset`), is turned to the shift
    /// that best matches the template (least squared distance, refined
    /// between samples by a parabola), the template being the mean of the
    /// turned cycles, over a few rounds. Corrections are centred (their
    /// circular mean is zero) so the common start stays where the
    /// corpus-wide registration put it on average. `None` without cycles.
    pub fn fit(cycles: &[(&Motion, Span, f64)]) -> Option<CycleTemplate> {
        let n = SAMPLES;
        let paths: Vec<ArcPath> = cycles.iter().map(|&(motion, span, _)| ArcPath::new(motion, span)).collect();
        let sampled: Vec<Vec<JointVector>> = paths
            .iter()
            .zip(cycles)
            .map(|(path, &(_, _, offset))| {
                (0..n).map(|k| path.pose_at((offset + k as f64 / n as f64).rem_euclid(1.0))).collect()
            })
            .collect();
        let mut poses = sampled.first()?.clone();
        let mut shifts = vec![0.0; cycles.len()];
        for _ in 0..ALIGN_ROUNDS {
            for (shift, cycle) in shifts.iter_mut().zip(&sampled) {
                *shift = best_shift(n, |s| (0..n).map(|k| squared_distance(&cycle[(k + s) % n], &poses[k])).sum());
            }
            poses = (0..n)
                .map(|k| {
                    let mut mean = [0.0; DOF];
                    for (cycle, &shift) in sampled.iter().zip(&shifts) {
                        let at = (k + shift.round() as usize) % n;
                        mean.iter_mut().zip(&cycle[at]).for_each(|(m, x)| *m += x / cycles.len() as f64);
                    }
                    mean
                })
                .collect();
        }
        let (sin, cos) = shifts.iter().fold((0.0, 0.0), |(s, c), &shift| {
            let angle = TAU * shift / n as f64;
            (s + angle.sin(), c + angle.cos())
        });
        let centre = if sin == 0.0 && cos == 0.0 { 0.0 } else { sin.atan2(cos) / TAU };
        let offsets = cycles
            .iter()
            .zip(&shifts)
            .map(|(&(_, _, offset), shift)| (offset + shift / n as f64 - centre).rem_euclid(1.0))
            .collect();
        // Sample k of cycle i lies at phase (k + shift) / n from its first
        // sample, which is at phase shift / n - centre: k / n + centre.
        let length = paths.iter().map(ArcPath::length).sum::<f64>() / paths.len() as f64;
        Some(CycleTemplate { poses, origin: centre, length, offsets })
    }

    /// The template pose at `phase`, interpolated between samples.
    fn pose_at(&self, phase: f64) -> JointVector {
        let n = self.poses.len();
        let q = (phase - self.origin).rem_euclid(1.0) * n as f64;
        let (i, t) = (q.floor() as usize % n, q.fract());
        let (a, b) = (&self.poses[i], &self.poses[(i + 1) % n]);
        std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t)
    }

    /// Where a partial swing lies on the cycle: the phase of its first pose
    /// and the share of a cycle it covers (its path length over a cycle's,
    /// at most 1). Its frames' phases are then `start + share × fraction`.
    pub fn place(&self, motion: &Motion, span: Span) -> (f64, f64) {
        let path = ArcPath::new(motion, span);
        let share = (path.length() / self.length).min(1.0);
        let m = SAMPLES;
        let samples: Vec<JointVector> = (0..m).map(|j| path.pose_at(j as f64 / (m - 1) as f64)).collect();
        let cost = |start: f64| -> f64 {
            samples
                .iter()
                .enumerate()
                .map(|(j, x)| squared_distance(x, &self.pose_at(start + share * j as f64 / (m - 1) as f64)))
                .sum()
        };
        let n = self.poses.len();
        let start = best_shift(n, |s| cost(s as f64 / n as f64)) / n as f64;
        (start.rem_euclid(1.0), share)
    }
}

/// The shift in 0..n with the least `cost`, refined between neighbours by
/// a parabola through the costs on either side (circularly).
fn best_shift(n: usize, cost: impl Fn(usize) -> f64) -> f64 {
    let costs: Vec<f64> = (0..n).map(cost).collect();
    let best = (0..n).min_by(|&a, &b| costs[a].total_cmp(&costs[b])).expect("n > 0");
    let (left, right) = (costs[(best + n - 1) % n], costs[(best + 1) % n]);
    let curvature = left - 2.0 * costs[best] + right;
    let refine = if curvature > 0.0 { 0.5 * (left - right) / curvature } else { 0.0 };
    best as f64 + refine.clamp(-0.5, 0.5)
}

fn squared_distance(a: &JointVector, b: &JointVector) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum()
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
