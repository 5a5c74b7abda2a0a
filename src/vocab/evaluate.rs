//! Scoring a learned vocabulary against what learning never saw: activity
//! labels (do clusters match activities?) and held-out repetitions (does
//! each primitive's gradient field predict motion it was not fitted to, do
//! its latent and joint-space fields agree as eq. 5 assumes, and does its
//! attractor progress rise along a repetition?).

use crate::mocap::body::DOF;
use crate::mocap::pose::Motion;
use crate::mocap::synth::{Activity, SynthOptions, sequence_take};
use crate::vocab::corpus::Corpus;
use crate::vocab::metrics::{adjusted_rand_index, cosine, majority_labels, purity, spearman};
use crate::vocab::phase::{ArcPath, PhaseAxes};
use crate::vocab::pipeline::{
    Build, BuildError, BuildParams, SegmentRow, root_classes, segment_corpus_along, segment_vectors, training_segments,
};
use crate::vocab::primitive::{Field, FitError, Primitive, ValidFitParams};
use crate::vocab::segment::Span;
use rayon::prelude::*;
use std::collections::BTreeSet;

/// A segment counts as one activity's when at least this share of its
/// frames carry that activity's label. Segments that straddle a change of
/// activity are transitions: no label is right for them.
pub const WHOLE_ACTIVITY_SHARE: f64 = 0.9;

/// The benchmark stream: circles, horizontal and vertical waving
/// and punching chained, 4 repetitions each, one take per (seed, speed),
/// labelled per frame (for scoring only). Learning uses seeds `10s`,
/// `10s + 1`, `10s + 2` at 0.5×, 1× and 2×; [`held_out_stream`] the same
/// activities from other seeds at other speeds.
pub fn benchmark_stream(seed: u64) -> Corpus {
    stream([10 * seed, 10 * seed + 1, 10 * seed + 2], [0.5, 1.0, 2.0])
}

/// Repetitions learning never saw: seeds `10s + 100` to `10s + 102` at
/// 0.75×, 1× and 1.5×.
pub fn held_out_stream(seed: u64) -> Corpus {
    stream([10 * seed + 100, 10 * seed + 101, 10 * seed + 102], [0.75, 1.0, 1.5])
}

fn stream(seeds: [u64; 3], speeds: [f64; 3]) -> Corpus {
    let activities = [Activity::Circles, Activity::WaveH, Activity::WaveV, Activity::Punch];
    let mut corpus = Corpus::default();
    for (seed, speed) in seeds.into_iter().zip(speeds) {
        let take = sequence_take(&activities, &SynthOptions { speed, repetitions: 4, seed, ..Default::default() });
        corpus.push(format!("stream-{seed}.bvh"), take.motion, Some(&take.labels));
    }
    corpus
}

/// Agreement of a clustering with labels over a set of segments.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Agreement {
    pub segments: usize,
    pub purity: f64,
    pub adjusted_rand_index: f64,
}

/// Agreement over all labelled segments, and over whole-activity segments.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ClusterScores {
    pub all: Agreement,
    pub whole_activity: Agreement,
}

/// How well `assignments` match the segments' labels; `None` when no
/// segment is labelled.
pub fn cluster_scores(rows: &[SegmentRow], assignments: &[usize]) -> Option<ClusterScores> {
    let agreement = |keep: &dyn Fn(&SegmentRow) -> bool| {
        let (clusters, labels): (Vec<usize>, Vec<Option<&str>>) = rows
            .iter()
            .zip(assignments)
            .filter(|(r, _)| r.label.is_some() && keep(r))
            .map(|(r, &a)| (a, r.label.as_deref()))
            .unzip();
        Agreement {
            segments: clusters.len(),
            purity: purity(&clusters, &labels),
            adjusted_rand_index: adjusted_rand_index(&clusters, &labels),
        }
    };
    let all = agreement(&|_| true);
    (all.segments > 0).then(|| ClusterScores {
        all,
        whole_activity: agreement(&|r: &SegmentRow| r.label_share >= WHOLE_ACTIVITY_SHARE),
    })
}

/// Labels that are not the majority label of any group of `assignments`
/// (clusters or primitives): activities the vocabulary has no primitive of
/// its own for.
pub fn activities_without_primitive(rows: &[SegmentRow], assignments: &[usize]) -> Vec<String> {
    let labels: Vec<Option<&str>> = rows.iter().map(|r| r.label.as_deref()).collect();
    let groups = assignments.iter().max().map_or(0, |m| m + 1);
    let named: BTreeSet<&str> = majority_labels(assignments, &labels, groups).into_iter().flatten().collect();
    let all: BTreeSet<&str> = labels.iter().flatten().copied().collect();
    all.difference(&named).map(|s| s.to_string()).collect()
}

/// One primitive on one held-out stretch of motion.
///
/// Direction figures are averaged over frames weighted by how far the body
/// moves at each (the joint-space length of the frame's true displacement):
/// a held pose has no direction to predict, and its frame-to-frame jitter
/// should count for as little as it moves. Equivalently, of all the
/// distance travelled, the share that went the predicted way.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RepetitionCheck {
    pub primitive: String,
    pub activity: String,
    /// Where the stretch is: file, first and last frame.
    pub file: String,
    pub first_frame: usize,
    pub last_frame: usize,
    pub frames: usize,
    /// Whether the stretch is a whole cycle (a repetition that returns to
    /// where it began), as the segmenter found.
    pub cyclic: bool,
    /// Joint-space distance travelled (the weight of this check).
    pub travel: f64,
    /// Mean cosine between the latent field's direction at each frame and
    /// the frame's true displacement to the next, both in latent space.
    pub latent_cosine: f64,
    /// Mean cosine, at each frame's reconstruction `g⁻¹(g(x))`, between the
    /// latent direction mapped to joint space and the joint-space field's
    /// direction (eq. 5).
    pub joint_agreement: f64,
    /// Spearman's ρ between position along the stretch's path and
    /// attractor progress: poses sampled evenly along the path the motion
    /// traces (as segments are compared and phase is counted, see
    /// [`ArcPath`]), so a pause, where progress can only stand still, counts
    /// once rather than once per frame.
    pub progress_rho: f64,
    /// The same ρ over every frame in time order, pauses included.
    pub progress_rho_frames: f64,
    /// How far progress advances over the stretch, in cycles: about 1 for
    /// a whole repetition.
    pub progress_advance: f64,
}

/// Checks `primitive` along `span` of `motion`; `joint` is the primitive's
/// joint-space field (see [`ValidFitParams::joint_field`]).
pub fn check_repetition(primitive: &Primitive, joint: &Field, motion: &Motion, span: Span) -> RepetitionCheck {
    let d = primitive.dims();
    let (mut latent_sum, mut joint_sum, mut travel) = (0.0, 0.0, 0.0);
    let mut progress = Vec::with_capacity(span.frames());
    let (mut y, mut next, mut latent_dir, mut joint_dir) = (vec![0.0; d], vec![0.0; d], vec![0.0; d], vec![0.0; DOF]);
    for t in span.first..=span.last {
        let x = &motion.poses[t].x;
        primitive.project_into(x, &mut y);
        progress.push(primitive.progress(&y));
        let Some(following) = motion.poses.get(t + 1) else { continue };
        let weight: f64 = x.iter().zip(&following.x).map(|(a, b)| (b - a).powi(2)).sum::<f64>().sqrt();
        primitive.project_into(&following.x, &mut next);
        let truth: Vec<f64> = next.iter().zip(&y).map(|(b, a)| b - a).collect();
        if weight == 0.0 || truth.iter().all(|v| *v == 0.0) {
            continue; // no motion (in this latent space): no direction to compare with
        }
        travel += weight;
        if !primitive.field().direction(&y, &mut latent_dir) {
            continue; // a vanished field scores 0
        }
        latent_sum += weight * cosine(&latent_dir, &truth);
        let mapped = primitive.reconstruct(&latent_dir);
        let mapped: Vec<f64> = mapped.iter().zip(primitive.mean()).map(|(x, m)| x - m).collect();
        if joint.direction(&primitive.reconstruct(&y), &mut joint_dir) {
            joint_sum += weight * cosine(&mapped, &joint_dir);
        }
    }
    let path = ArcPath::new(motion, span);
    let last = (span.frames() - 1).max(1) as f64;
    let along: Vec<f64> = (0..span.frames())
        .map(|i| {
            primitive.project_into(&path.pose_at(i as f64 / last), &mut y);
            primitive.progress(&y)
        })
        .collect();
    let rising = |phases: &[f64]| {
        let order: Vec<f64> = (0..phases.len()).map(|i| i as f64).collect();
        spearman(&order, &unwrap_cycles(phases))
    };
    let unwrapped = unwrap_cycles(&progress);
    RepetitionCheck {
        primitive: primitive.name().to_string(),
        activity: String::new(),
        file: String::new(),
        first_frame: span.first,
        last_frame: span.last,
        frames: span.frames(),
        cyclic: false,
        travel,
        latent_cosine: latent_sum / travel,
        joint_agreement: joint_sum / travel,
        progress_rho: rising(&along),
        progress_rho_frames: rising(&progress),
        progress_advance: unwrapped.last().copied().unwrap_or(0.0) - unwrapped.first().copied().unwrap_or(0.0),
    }
}

/// Phases in [0, 1) made continuous: each step is taken the short way
/// round the circle, so crossing from 0.98 to 0.02 is a step of +0.04.
fn unwrap_cycles(phases: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(phases.len());
    let mut total = phases.first().copied().unwrap_or(0.0);
    for (i, &p) in phases.iter().enumerate() {
        if i > 0 {
            total += (p - phases[i - 1] + 0.5).rem_euclid(1.0) - 0.5;
        }
        out.push(total);
    }
    out
}

/// Held-out checks of a whole vocabulary.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct HeldOutReport {
    pub repetitions: Vec<RepetitionCheck>,
    /// Held-out activities no primitive is named after (checked all the
    /// same, with the primitive nearest to each segment).
    pub unmatched: Vec<String>,
}

impl HeldOutReport {
    /// The mean of a direction figure over all repetitions, weighted by
    /// distance travelled (see [`RepetitionCheck`]).
    pub fn mean_direction(&self, figure: impl Fn(&RepetitionCheck) -> f64) -> f64 {
        let moving = || self.repetitions.iter().filter(|r| r.travel > 0.0);
        moving().map(|r| figure(r) * r.travel).sum::<f64>() / moving().map(|r| r.travel).sum::<f64>()
    }

    /// The mean of a figure over the repetitions that moved.
    pub fn mean(&self, figure: impl Fn(&RepetitionCheck) -> f64) -> f64 {
        let moving: Vec<f64> = self.repetitions.iter().filter(|r| r.travel > 0.0).map(figure).collect();
        moving.iter().sum::<f64>() / moving.len() as f64
    }

    /// The smallest value of a figure over the repetitions that moved.
    pub fn min(&self, figure: impl Fn(&RepetitionCheck) -> f64) -> f64 {
        self.repetitions.iter().filter(|r| r.travel > 0.0).map(figure).fold(f64::INFINITY, f64::min)
    }
}

/// Segments `held_out` (labelled) as the build was segmented, and checks
/// each whole-activity segment with the primitive whose training segments
/// hold the one nearest to it, compared as the embedding compares segments.
/// The primitive is chosen from the motion alone, as tracking chooses it,
/// not by label: a coarse label (`gesture` for eight unrelated motions,
/// `walk` for a walk and a zombie shuffle) can name a primitive learned
/// from a different movement, whose field says nothing about this one.
/// Joint-space fields are fitted to each primitive's training segments.
pub fn check_held_out(
    build: &Build,
    training: &Corpus,
    held_out: &Corpus,
    params: &BuildParams,
) -> Result<HeldOutReport, BuildError> {
    let joint_fields = joint_fields(build, training, &params.fit)?;
    let rows = segment_corpus_along(held_out, &params.segment, &PhaseAxes::of(training))?;
    let frames = params.embed.params().resample;
    let (known, _) = segment_vectors(training, &build.segments, frames);
    let (fresh, _) = segment_vectors(held_out, &rows, frames);
    let fitted = &build.fitted;
    // The primitive each training segment was fitted to, if any (not a
    // still cluster's).
    let primitive_of: Vec<Option<usize>> =
        fitted.assignments(&build.clustering).into_iter().map(|p| (p < fitted.primitives.len()).then_some(p)).collect();
    let classes = root_classes(held_out, &rows);
    let activities: BTreeSet<&str> = fitted.primitives.iter().map(|p| activity_of(p.name())).collect();
    let repetitions: Vec<RepetitionCheck> = rows
        .par_iter()
        .zip(&fresh)
        .zip(&classes)
        .filter(|((r, _), _)| r.label.is_some() && r.label_share >= WHOLE_ACTIVITY_SHARE)
        .filter_map(|((r, vector), class)| {
            // Among the primitives whose root moved as this segment's did,
            // when there are any (root_groups keeps them apart).
            let alike = fitted.root.contains(class);
            let (_, p) = (0..known.len())
                .filter_map(|i| primitive_of[i].map(|p| (i, p)))
                .filter(|&(_, p)| !alike || fitted.root[p] == *class)
                .min_by(|a, b| {
                    squared_distance(vector, &known[a.0]).total_cmp(&squared_distance(vector, &known[b.0]))
                })?;
            let motion = &held_out.takes[r.take].motion;
            let mut check = check_repetition(&fitted.primitives[p], &joint_fields[p], motion, r.span);
            check.activity = r.label.clone().expect("filtered to labelled segments");
            check.file = held_out.takes[r.take].path.clone();
            check.cyclic = r.phase_offset.is_some();
            Some(check)
        })
        .collect();
    let mut unmatched: Vec<String> = Vec::new();
    for r in &repetitions {
        if !activities.contains(r.activity.as_str()) && !unmatched.contains(&r.activity) {
            unmatched.push(r.activity.clone());
        }
    }
    Ok(HeldOutReport { repetitions, unmatched })
}

/// The activity a primitive stands for: its name without a repeat's
/// number (`circles`, `circles-2`, … all stand for `circles`).
pub fn activity_of(primitive: &str) -> &str {
    primitive.rsplit_once('-').filter(|(_, n)| n.parse::<u32>().is_ok()).map_or(primitive, |(a, _)| a)
}

fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum()
}

/// Each primitive's gradient field in joint space, from its training
/// segments.
fn joint_fields(build: &Build, corpus: &Corpus, fit: &ValidFitParams) -> Result<Vec<Field>, FitError> {
    let fitted = &build.fitted;
    fitted
        .primitives
        .par_iter()
        .zip(&fitted.members)
        .map(|(primitive, members)| {
            let segments = training_segments(corpus, &build.segments, members);
            fit.joint_field(primitive.name(), &segments)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_repeat_number_is_not_part_of_the_activity() {
        assert_eq!(activity_of("circles-2"), "circles");
        assert_eq!(activity_of("wave-left-hand"), "wave-left-hand");
        assert_eq!(activity_of("wave-left-hand-12"), "wave-left-hand");
        assert_eq!(activity_of("p3"), "p3");
    }

    #[test]
    fn unwrapping_takes_each_step_the_short_way_round() {
        let unwrapped = unwrap_cycles(&[0.9, 0.95, 0.02, 0.1, 0.08]);
        let expected = [0.9, 0.95, 1.02, 1.1, 1.08];
        assert!(unwrapped.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-12), "{unwrapped:?}");
    }
}
