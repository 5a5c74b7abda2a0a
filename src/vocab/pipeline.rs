//! The stages chained in memory: what `imitate vocab build` runs, and what
//! each stage's subcommand runs one step of.

use crate::vocab::cluster::{ClusterError, Clustering, ValidClusterParams};
use crate::vocab::corpus::Corpus;
use crate::vocab::embed::{EmbedError, Embedding, ValidEmbedParams, resample};
use crate::vocab::metrics::majority_labels;
use crate::vocab::phase::PhaseAxes;
use crate::vocab::primitive::{FitError, Primitive, TrainingSegment, ValidFitParams};
use crate::vocab::segment::{Cut, Span, ValidSegmentParams, segment_motion};
use rayon::prelude::*;

/// One segment of a corpus.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentRow {
    /// Index of its take in the corpus.
    pub take: usize,
    pub span: Span,
    /// For a whole cycle, where its registered start lies (a fraction of
    /// the cycle; see [`crate::vocab::phase`]).
    pub phase_offset: Option<f64>,
    /// The majority label of its frames, if the take is labelled.
    pub label: Option<String>,
    /// The share of its frames with that label: below 1 for a segment that
    /// straddles a change of activity.
    pub label_share: f64,
}

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error("no segments: every take is shorter than the minimum segment length ({min_s} s)")]
    NoSegments { min_s: f64 },
    #[error("every pose of every take is the same: there is no motion to learn from")]
    Motionless,
    #[error(transparent)]
    Embed(#[from] EmbedError),
    #[error(transparent)]
    Cluster(#[from] ClusterError),
    #[error(transparent)]
    Fit(#[from] FitError),
}

/// Segments every take (in parallel), in take order, registering the
/// phase of whole cycles.
pub fn segment_corpus(corpus: &Corpus, params: &ValidSegmentParams) -> Result<Vec<SegmentRow>, BuildError> {
    segment_corpus_along(corpus, params, &PhaseAxes::of(corpus))
}

/// [`segment_corpus`], registering phase along given axes (those of
/// another corpus, to compare with its segments).
pub fn segment_corpus_along(
    corpus: &Corpus,
    params: &ValidSegmentParams,
    axes: &PhaseAxes,
) -> Result<Vec<SegmentRow>, BuildError> {
    let moving = corpus.takes.iter().any(|t| t.motion.poses.windows(2).any(|w| w[0].x != w[1].x));
    if !moving {
        return Err(BuildError::Motionless);
    }
    let per_take: Vec<Vec<Cut>> = corpus.takes.par_iter().map(|t| segment_motion(params, &t.motion)).collect();
    let mut rows = Vec::new();
    for (take, cuts) in per_take.into_iter().enumerate() {
        let (motion, labels) = (&corpus.takes[take].motion, corpus.takes[take].labels.as_deref());
        for Cut { span, cyclic } in cuts {
            let frames = labels.map(|l| &l[span.first..=span.last]);
            let (label, label_share) = match frames.and_then(majority) {
                Some((id, count)) => (Some(corpus.label(id).to_string()), count as f64 / span.frames() as f64),
                None => (None, 1.0),
            };
            let phase_offset = cyclic.then(|| axes.offset(motion, span));
            rows.push(SegmentRow { take, span, phase_offset, label, label_share });
        }
    }
    if rows.is_empty() {
        return Err(BuildError::NoSegments { min_s: params.params().min_length_s });
    }
    Ok(rows)
}

/// The most frequent label id (the lowest on ties) and its count.
fn majority(labels: &[u32]) -> Option<(u32, usize)> {
    let mut counts = std::collections::BTreeMap::new();
    for &l in labels {
        *counts.entry(l).or_insert(0usize) += 1;
    }
    let best = counts.values().copied().max()?;
    counts.into_iter().find(|(_, c)| *c == best)
}

/// Each segment resampled and flattened, and which segment follows which
/// directly in its take.
pub fn segment_vectors(corpus: &Corpus, rows: &[SegmentRow], frames: usize) -> (Vec<Vec<f64>>, Vec<Option<usize>>) {
    let vectors =
        rows.par_iter().map(|r| resample(&corpus.takes[r.take].motion, r.span, frames, r.phase_offset)).collect();
    let next = (0..rows.len())
        .map(|i| {
            let (a, b) = (&rows[i], rows.get(i + 1)?);
            (a.take == b.take && b.span.first == a.span.last + 1).then_some(i + 1)
        })
        .collect();
    (vectors, next)
}

/// Embeds the segments.
pub fn embed_segments(
    corpus: &Corpus,
    rows: &[SegmentRow],
    params: &ValidEmbedParams,
) -> Result<Embedding, BuildError> {
    let (vectors, next) = segment_vectors(corpus, rows, params.params().resample);
    Ok(params.embed(&vectors, &next)?)
}

/// Primitive names: each cluster's majority label (held by more than half
/// its labelled segments; a repeated label gets `-2`, `-3`, …), else
/// `p<i>` for cluster `i`.
pub fn primitive_names(rows: &[SegmentRow], clustering: &Clustering) -> Vec<String> {
    let labels: Vec<Option<&str>> = rows.iter().map(|r| r.label.as_deref()).collect();
    let majorities = majority_labels(clustering.assignments(), &labels, clustering.k());
    let mut used = std::collections::BTreeMap::<String, usize>::new();
    majorities
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let base = m.map_or_else(|| format!("p{i}"), str::to_string);
            let count = used.entry(base.clone()).or_insert(0);
            *count += 1;
            if *count == 1 { base } else { format!("{base}-{count}") }
        })
        .collect()
}

/// The segments of cluster `c`, as training motion.
pub fn training_segments<'a>(
    corpus: &'a Corpus,
    rows: &'a [SegmentRow],
    assignments: &[usize],
    c: usize,
) -> Vec<TrainingSegment<'a>> {
    rows.iter()
        .zip(assignments)
        .filter(|(_, a)| **a == c)
        .map(|(r, _)| TrainingSegment {
            motion: &corpus.takes[r.take].motion,
            span: r.span,
            phase_offset: r.phase_offset,
            file: &corpus.takes[r.take].path,
            label: r.label.as_deref(),
        })
        .collect()
}

/// The primitives fitted to a clustering.
pub struct Fitted {
    /// In cluster order, without the clusters of still segments.
    pub primitives: Vec<Primitive>,
    /// The cluster each primitive was fitted to.
    pub clusters: Vec<usize>,
    /// Names of clusters left out because their poses never change: with
    /// no motion there is no gradient field to learn.
    pub still: Vec<String>,
}

/// Fits one primitive per cluster (in parallel), in cluster order.
pub fn fit_primitives(
    corpus: &Corpus,
    rows: &[SegmentRow],
    clustering: &Clustering,
    params: &ValidFitParams,
) -> Result<Fitted, BuildError> {
    let names = primitive_names(rows, clustering);
    let results: Vec<Result<Primitive, FitError>> = (0..clustering.k())
        .into_par_iter()
        .map(|c| params.fit(&names[c], &training_segments(corpus, rows, clustering.assignments(), c)))
        .collect();
    let mut fitted = Fitted { primitives: Vec::new(), clusters: Vec::new(), still: Vec::new() };
    for (c, result) in results.into_iter().enumerate() {
        match result {
            Ok(primitive) => {
                fitted.primitives.push(primitive);
                fitted.clusters.push(c);
            }
            Err(FitError::Motionless(name)) => fitted.still.push(name),
            Err(other) => return Err(other.into()),
        }
    }
    if fitted.primitives.is_empty() {
        return Err(BuildError::Motionless);
    }
    Ok(fitted)
}

/// Everything one build produced.
pub struct Build {
    pub segments: Vec<SegmentRow>,
    pub embedding: Embedding,
    pub clustering: Clustering,
    pub fitted: Fitted,
}

/// The settings of every stage.
#[derive(Clone, Debug)]
pub struct BuildParams {
    pub segment: ValidSegmentParams,
    pub embed: ValidEmbedParams,
    pub cluster: ValidClusterParams,
    pub fit: ValidFitParams,
}

/// Runs all stages; `stage` is told as each one starts (for progress).
pub fn build(corpus: &Corpus, params: &BuildParams, mut stage: impl FnMut(&str)) -> Result<Build, BuildError> {
    stage("segment");
    let segments = segment_corpus(corpus, &params.segment)?;
    stage("embed");
    let embedding = embed_segments(corpus, &segments, &params.embed)?;
    stage("cluster");
    let clustering = params.cluster.cluster(&embedding)?;
    stage("fit");
    let fitted = fit_primitives(corpus, &segments, &clustering, &params.fit)?;
    Ok(Build { segments, embedding, clustering, fitted })
}
