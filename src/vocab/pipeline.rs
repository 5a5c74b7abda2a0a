//! The stages chained in memory: what `imitate vocab build` runs, and what
//! each stage's subcommand runs one step of.

use crate::mocap::body::DOF;
use crate::params::Params;
use crate::vocab::cluster::{ClusterError, Clustering, ValidClusterParams};
use crate::vocab::corpus::{Corpus, Recording};
use crate::vocab::embed::{EmbedError, Embedding, ValidEmbedParams, resample};
use crate::vocab::metrics::majority_labels;
use crate::vocab::phase::PhaseAxes;
use crate::vocab::primitive::{FitError, Primitive, TrainingSegment, ValidFitParams};
use crate::vocab::root_motion::{RootClass, RootMotion, root_groups};
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
    #[error("{path}: every frame is the same pose: there is no motion to learn from (leave the take out)")]
    Motionless { path: String },
    #[error("every primitive's segments hold one pose each: there is no motion to learn from")]
    StillPrimitives,
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
    // A still take is no short one: the file is wrong (a rest pose
    // exported as a take), and a user who gave it should hear so.
    let still = |t: &&Recording| t.motion.poses.len() > 1 && t.motion.poses.windows(2).all(|w| w[0] == w[1]);
    if let Some(take) = corpus.takes.iter().find(still) {
        return Err(BuildError::Motionless { path: take.path.clone() });
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

/// A group's name: the label held by more than half of its labelled
/// segments, else `p<cluster>`; not yet unique.
fn group_name(rows: &[SegmentRow], cluster: usize, members: &[usize]) -> String {
    let labels: Vec<Option<&str>> = members.iter().map(|&i| rows[i].label.as_deref()).collect();
    let majority = majority_labels(&vec![0; members.len()], &labels, 1)[0];
    majority.map_or_else(|| format!("p{cluster}"), str::to_string)
}

/// Names made unique: a repeated name gets `-2`, `-3`, ….
fn unique_names(names: impl Iterator<Item = String>) -> Vec<String> {
    let mut used = std::collections::BTreeMap::<String, usize>::new();
    names
        .map(|base| {
            let count = used.entry(base.clone()).or_insert(0);
            *count += 1;
            if *count == 1 { base } else { format!("{base}-{count}") }
        })
        .collect()
}

/// Segments `members` (indices into `rows`), as training motion.
pub fn training_segments<'a>(
    corpus: &'a Corpus,
    rows: &'a [SegmentRow],
    members: &[usize],
) -> Vec<TrainingSegment<'a>> {
    members
        .iter()
        .map(|&i| {
            let r = &rows[i];
            TrainingSegment {
                motion: &corpus.takes[r.take].motion,
                span: r.span,
                phase_offset: r.phase_offset,
                file: &corpus.takes[r.take].path,
                label: r.label.as_deref(),
            }
        })
        .collect()
}

/// Poses along each swing for [`direction_groups`].
const DIRECTION_SAMPLES: usize = 16;
/// Rounds of [`direction_groups`]' orientation.
const DIRECTION_ROUNDS: usize = 5;
/// A swing counts as going the other way when its path reversed is closer
/// to the common path than this share of its path as it is.
const REVERSED_SHARE: f64 = 0.5;

/// Splits a cluster's segments (`members`) by the way they travel: swings
/// (segments that are not whole cycles) that follow the cluster's common
/// path backwards, like the way back of a reach clustered with the way
/// out, form a second group. A pose-only gradient field cannot hold both
/// directions of one path (they cancel), so each group becomes a primitive
/// of its own. Each swing's path is oriented to agree with the mean of the
/// oriented paths, over a few rounds; a second group needs two swings.
fn direction_groups(corpus: &Corpus, rows: &[SegmentRow], members: &[usize]) -> Vec<Vec<usize>> {
    let swings: Vec<usize> = members.iter().copied().filter(|&i| rows[i].phase_offset.is_none()).collect();
    let paths: Vec<Vec<f64>> = swings
        .iter()
        .map(|&i| resample(&corpus.takes[rows[i].take].motion, rows[i].span, DIRECTION_SAMPLES, None))
        .collect();
    let reversed = |path: &[f64]| -> Vec<f64> { path.chunks_exact(DOF).rev().flatten().copied().collect() };
    let distance = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    let mut backwards = vec![false; paths.len()];
    // Start from the first swing's path: the mean of a path and its
    // reverse runs both ways at once and would orient nothing.
    let Some(mut mean) = paths.first().cloned() else { return vec![members.to_vec()] };
    for _ in 0..DIRECTION_ROUNDS {
        for (path, back) in paths.iter().zip(backwards.iter_mut()) {
            *back = distance(&reversed(path), &mean) < REVERSED_SHARE * distance(path, &mean);
        }
        mean.fill(0.0);
        for (path, &back) in paths.iter().zip(&backwards) {
            let oriented = if back { reversed(path) } else { path.clone() };
            mean.iter_mut().zip(&oriented).for_each(|(m, x)| *m += x / paths.len() as f64);
        }
    }
    let back: Vec<usize> = swings.iter().zip(&backwards).filter(|(_, b)| **b).map(|(i, _)| *i).collect();
    let forward: Vec<usize> = members.iter().copied().filter(|i| !back.contains(i)).collect();
    let forward_swings = forward.iter().filter(|&&i| rows[i].phase_offset.is_none()).count();
    if back.len() >= 2 && forward_swings >= 2 { vec![forward, back] } else { vec![members.to_vec()] }
}

/// A root group needs this many segments; rarer root motions join their
/// cluster's most common one (see [`root_groups`]).
const MIN_ROOT_GROUP: usize = 2;

/// The primitives fitted to a clustering.
pub struct Fitted {
    /// In cluster order, without the clusters of still segments.
    pub primitives: Vec<Primitive>,
    /// The segments (indices into the rows) each primitive was fitted to.
    pub members: Vec<Vec<usize>>,
    /// How the root moved around each primitive's segments.
    pub root: Vec<RootClass>,
    /// Names of clusters left out because their poses never change: with
    /// no motion there is no gradient field to learn.
    pub still: Vec<String>,
}

impl Fitted {
    /// Each segment's primitive; a segment of a still cluster (left out)
    /// gets `primitives + cluster`, so the segments of one such cluster
    /// stay together when a partition is scored.
    pub fn assignments(&self, clustering: &Clustering) -> Vec<usize> {
        let mut of: Vec<usize> = clustering.assignments().iter().map(|c| self.primitives.len() + c).collect();
        for (p, members) in self.members.iter().enumerate() {
            members.iter().for_each(|&i| of[i] = p);
        }
        of
    }
}

/// Each segment's root class ([`RootMotion::around`]).
pub fn root_classes(corpus: &Corpus, rows: &[SegmentRow]) -> Vec<RootClass> {
    rows.par_iter().map(|r| RootMotion::around(&corpus.takes[r.take].motion, r.span).class()).collect()
}

/// Fits primitives to each cluster (in parallel), in cluster order. A
/// cluster is first split by how the root moved around its segments
/// ([`root_groups`]: joint space alone cannot tell a walk that turns from
/// one that goes straight), then each part by the way its swings travel
/// (`direction_groups`); each group is a primitive, named by its own
/// segments' majority label (a repeated name numbered).
pub fn fit_primitives(
    corpus: &Corpus,
    rows: &[SegmentRow],
    clustering: &Clustering,
    params: &ValidFitParams,
) -> Result<Fitted, BuildError> {
    let classes = root_classes(corpus, rows);
    let groups: Vec<(usize, RootClass, Vec<usize>)> = (0..clustering.k())
        .into_par_iter()
        .flat_map_iter(|c| {
            let members: Vec<usize> = (0..rows.len()).filter(|&i| clustering.assignments()[i] == c).collect();
            root_groups(&members, &classes, MIN_ROOT_GROUP).into_iter().flat_map(move |(class, part)| {
                direction_groups(corpus, rows, &part).into_iter().map(move |g| (c, class, g))
            })
        })
        .collect();
    let names = unique_names(groups.iter().map(|(c, _, members)| group_name(rows, *c, members)));
    let results: Vec<Result<Primitive, FitError>> = groups
        .par_iter()
        .zip(&names)
        .map(|((_, _, members), name)| params.fit(name, &training_segments(corpus, rows, members)))
        .collect();
    let mut fitted = Fitted { primitives: Vec::new(), members: Vec::new(), root: Vec::new(), still: Vec::new() };
    for ((_, class, members), result) in groups.into_iter().zip(results) {
        match result {
            Ok(primitive) => {
                fitted.primitives.push(primitive);
                fitted.members.push(members);
                fitted.root.push(class);
            }
            Err(FitError::Motionless(name)) => fitted.still.push(name),
            Err(other) => return Err(other.into()),
        }
    }
    if fitted.primitives.is_empty() {
        return Err(BuildError::StillPrimitives);
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

impl BuildParams {
    /// Every stage's defaults, as `vocab build` takes them.
    pub fn standard() -> BuildParams {
        BuildParams {
            segment: crate::vocab::segment::SegmentParams::new().check().expect("the defaults are valid"),
            embed: crate::vocab::embed::EmbedParams::new().check().expect("the defaults are valid"),
            cluster: crate::vocab::cluster::ClusterParams::new().check().expect("the defaults are valid"),
            fit: crate::vocab::primitive::FitParams::new().check().expect("the defaults are valid"),
        }
    }
}

/// Each segment's activity, in order, as clustering by label reads them.
pub fn segment_labels(rows: &[SegmentRow]) -> Vec<Option<String>> {
    rows.iter().map(|r| r.label.clone()).collect()
}

/// Runs all stages; `stage` is told as each one starts (for progress).
pub fn build(corpus: &Corpus, params: &BuildParams, mut stage: impl FnMut(&str)) -> Result<Build, BuildError> {
    stage("segment");
    let segments = segment_corpus(corpus, &params.segment)?;
    stage("embed");
    let embedding = embed_segments(corpus, &segments, &params.embed)?;
    stage("cluster");
    let clustering = params.cluster.cluster(&embedding, &segment_labels(&segments))?;
    stage("fit");
    let fitted = fit_primitives(corpus, &segments, &clustering, &params.fit)?;
    Ok(Build { segments, embedding, clustering, fitted })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::{Body, Joint};
    use crate::mocap::pose::{Motion, Pose};
    use crate::vocab::cluster::Choice;
    use crate::vocab::root_motion::{Travel, Turn};

    /// One take of `swings` 20-frame swings along one curved path in joint
    /// space, alternately out (rest to raised) and back when `both_ways`,
    /// else always out, each a little larger than the last; one row each.
    fn swings(swings: usize, both_ways: bool) -> (Corpus, Vec<SegmentRow>) {
        let body = Body::standard();
        let mut poses = Vec::new();
        let mut rows = Vec::new();
        for s in 0..swings {
            let size = 1.0 + 0.03 * s as f64;
            let back = both_ways && s % 2 == 1;
            let first = poses.len();
            for f in 0..20 {
                let t = f as f64 / 19.0;
                let along = if back { 1.0 - t } else { t };
                let mut pose = Pose::rest(&body);
                pose.x[10] = size * along;
                pose.x[11] = size * along * along;
                pose.x[12] = 0.3 * (3.0 * along).sin();
                poses.push(pose);
            }
            let span = Span { first, last: poses.len() - 1 };
            rows.push(SegmentRow { take: 0, span, phase_offset: None, label: None, label_share: 0.0 });
        }
        let mut corpus = Corpus::default();
        corpus.push("swings.bvh".into(), Motion { body, frame_time_s: 1.0 / 30.0, poses }, None);
        (corpus, rows)
    }

    /// A labelled take of `cycles` 30-frame leg swings (out and back along
    /// one path, as cycles) while the root walks forward at 1.2 m/s and
    /// turns at `turn` rad/s.
    fn walk(corpus: &mut Corpus, rows: &mut Vec<SegmentRow>, file: &str, label: &str, cycles: usize, turn: f64) {
        let body = Body::standard();
        let dt = 1.0 / 30.0;
        let mut pose = Pose::rest(&body);
        let mut poses = Vec::new();
        let take = corpus.takes.len();
        for c in 0..cycles {
            let first = poses.len();
            for f in 0..30 {
                let swing = (std::f64::consts::TAU * f as f64 / 30.0).sin() * (1.0 + 0.02 * c as f64);
                pose.x[Joint::LeftHip.dof_offset()] = 0.5 * swing;
                pose.x[Joint::RightHip.dof_offset()] = -0.5 * swing;
                poses.push(pose);
                let (sin, cos) = pose.heading.sin_cos();
                pose.root += glam::DVec3::new(sin, 0.0, cos) * 1.2 * dt;
                pose.heading += turn * dt;
            }
            let span = Span { first, last: poses.len() - 1 };
            rows.push(SegmentRow { take, span, phase_offset: Some(0.0), label: Some(label.into()), label_share: 1.0 });
        }
        let labels = vec![label; poses.len()];
        corpus.push(file.into(), Motion { body, frame_time_s: dt, poses }, Some(&labels));
    }

    #[test]
    fn a_cluster_of_steps_is_split_by_how_the_root_turns_and_each_part_named_by_its_own_labels() {
        let (mut corpus, mut rows) = (Corpus::default(), Vec::new());
        walk(&mut corpus, &mut rows, "a.bvh", "walk", 4, 0.0);
        walk(&mut corpus, &mut rows, "b.bvh", "walk-turn-left", 4, 0.6);
        walk(&mut corpus, &mut rows, "c.bvh", "walk", 4, 0.0);
        // One cluster: the legs move alike in all three takes.
        let clustering = Clustering::recorded(vec![0; rows.len()], Choice::Given, Vec::new());
        let params = crate::vocab::primitive::FitParams::new().check().unwrap();
        let fitted = fit_primitives(&corpus, &rows, &clustering, &params).unwrap();
        let names: Vec<&str> = fitted.primitives.iter().map(|p| p.name()).collect();
        assert_eq!(names, ["walk", "walk-turn-left"]);
        assert_eq!(fitted.members, [vec![0, 1, 2, 3, 8, 9, 10, 11], vec![4, 5, 6, 7]]);
        let forward = |turn| RootClass { turn, travel: Travel::Forward };
        assert_eq!(fitted.root, [forward(Turn::Straight), forward(Turn::Left)]);
        assert_eq!(fitted.assignments(&clustering), [0, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 0]);
    }

    #[test]
    fn swings_along_one_path_both_ways_split_into_one_group_per_direction() {
        let (corpus, rows) = swings(8, true);
        let members: Vec<usize> = (0..rows.len()).collect();
        let groups = direction_groups(&corpus, &rows, &members);
        assert_eq!(groups, vec![vec![0, 2, 4, 6], vec![1, 3, 5, 7]]);
    }

    #[test]
    fn swings_all_one_way_or_whole_cycles_stay_one_group() {
        let (corpus, rows) = swings(8, false);
        let members: Vec<usize> = (0..rows.len()).collect();
        assert_eq!(direction_groups(&corpus, &rows, &members), vec![members.clone()]);
        // Cycles travel their loop one way by construction: never split.
        let (corpus, mut rows) = swings(8, true);
        rows.iter_mut().for_each(|r| r.phase_offset = Some(0.0));
        assert_eq!(direction_groups(&corpus, &rows, &members), vec![members]);
        // One swing back is not a group of its own.
        let (corpus, rows) = swings(3, true);
        let members: Vec<usize> = (0..rows.len()).collect();
        assert_eq!(direction_groups(&corpus, &rows, &members), vec![members]);
    }
}
