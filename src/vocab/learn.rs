//! Learning a vocabulary from BVH files, stage by stage: what `imitate
//! segment`, `embed`, `cluster`, `fit` and `vocab build` run, and what
//! Python's `Vocabulary.build` runs. Each stage records its settings in the
//! lineage and tells a [`Listener`] what it found.

use crate::mocap::mapping::{MappingError, UserMapping};
use crate::mocap::pose::Motion;
use crate::mocap::retarget::{RetargetOptions, UpAxis};
use crate::vocab::cluster::{Choice, ClusterError, ValidClusterParams, best};
use crate::vocab::corpus::{self, Corpus, CorpusError, read_labels};
use crate::vocab::embed::ValidEmbedParams;
use crate::vocab::evaluate::{activities_without_primitive, cluster_scores};
use crate::vocab::lineage::{ClusterRecord, Lineage, RetargetSettings};
use crate::vocab::pipeline::{BuildError, BuildParams, embed_segments, fit_primitives, segment_corpus, segment_labels};
use crate::vocab::primitive::ValidFitParams;
use crate::vocab::segment::ValidSegmentParams;
use crate::vocab::stages::{Clustered, Embedded, Segments, build_info};
use crate::vocab::vocabulary::Vocabulary;
use std::path::{Path, PathBuf};

/// Hears how learning goes. Both methods do nothing unless implemented.
pub trait Listener {
    /// A stage begins: `read`, `segment`, `embed`, `cluster` or `fit`.
    fn stage(&mut self, _name: &'static str) {}
    /// What a stage found, or a warning (then starting `PATH: warning:`).
    fn note(&mut self, _text: &str) {}
}

/// Learning in silence.
impl Listener for () {}

/// The takes to learn from, their labels, and how they are put onto the
/// canonical body.
#[derive(Clone, Debug, Default)]
pub struct Takes {
    /// BVH files, or folders whose `.bvh` files are all read.
    pub inputs: Vec<PathBuf>,
    /// Activity labels (docs/formats.md, "Labels").
    pub labels: Option<PathBuf>,
    /// The source's up axis, when detection from the skeleton gets it wrong.
    pub up: Option<UpAxis>,
    /// A mapping file for joints the built-in naming tables do not know.
    pub mapping: Option<PathBuf>,
}

impl Takes {
    /// The retargeting options, the mapping file read.
    pub fn options(&self) -> Result<RetargetOptions, MappingError> {
        let mapping = self.mapping.as_deref().map(UserMapping::load).transpose()?;
        Ok(RetargetOptions { up: self.up, mapping })
    }

    /// The retargeting settings as stage files record them.
    pub fn settings(&self) -> RetargetSettings {
        RetargetSettings::new(self.up, self.mapping.as_deref())
    }
}

/// Why a vocabulary could not be learned.
#[derive(Debug, thiserror::Error)]
pub enum LearnError {
    #[error(transparent)]
    Mapping(#[from] MappingError),
    #[error(transparent)]
    Corpus(#[from] CorpusError),
    #[error("{0}: is a folder; give one BVH file")]
    Folder(String),
    /// A stage failed on the takes named.
    #[error("{takes}: {source}")]
    Stage { takes: String, source: BuildError },
}

/// What [`build`] learned.
pub struct Built {
    pub vocabulary: Vocabulary,
    /// Frames read, over all takes.
    pub frames: usize,
}

/// Reads the takes and runs every stage: the vocabulary `vocab build`
/// writes, before it is saved.
pub fn build(takes: &Takes, params: &BuildParams, listener: &mut dyn Listener) -> Result<Built, LearnError> {
    listener.stage("read");
    let corpus = read_corpus(&takes.inputs, takes.labels.as_deref(), &takes.options()?, listener)?;
    let on_takes = |source: BuildError| LearnError::Stage { takes: takes_named(&corpus), source };
    listener.stage("segment");
    let lineage = Lineage::new(takes.settings(), params.segment.params().clone());
    let segments = segment(&corpus, &params.segment, lineage, listener).map_err(on_takes)?;
    listener.stage("embed");
    let embedded = embed(&corpus, segments, &params.embed, listener).map_err(on_takes)?;
    listener.stage("cluster");
    let clustered = cluster(embedded, &params.cluster, listener).map_err(|e| on_takes(e.into()))?;
    listener.stage("fit");
    let vocabulary = fit(&corpus, &clustered, &params.fit, listener).map_err(on_takes)?;
    Ok(Built { vocabulary, frames: corpus.frames() })
}

/// Reads and retargets the inputs (BVH files or folders) with their
/// labels, warning of takes the labels leave out.
pub fn read_corpus(
    inputs: &[PathBuf],
    labels: Option<&Path>,
    options: &RetargetOptions,
    listener: &mut dyn Listener,
) -> Result<Corpus, CorpusError> {
    let labels = labels.map(|path| read_labels(path).map(|l| (l, path.display().to_string()))).transpose()?;
    let corpus = corpus::load(inputs, options, labels.as_ref().map(|(l, p)| (l, p.as_str())))?;
    if let Some((_, path)) = &labels {
        let unlabelled: Vec<&str> =
            corpus.takes.iter().filter(|t| t.labels.is_none()).map(|t| t.path.as_str()).collect();
        if !unlabelled.is_empty() {
            listener.note(&format!("{path}: warning: no labels for {}", unlabelled.join(", ")));
        }
    }
    Ok(corpus)
}

/// One take read and retargeted, with each frame's activity when `labels`
/// are given.
pub fn read_take(
    input: &Path,
    labels: Option<&Path>,
    options: &RetargetOptions,
    listener: &mut dyn Listener,
) -> Result<(Motion, Option<Vec<String>>), LearnError> {
    if input.is_dir() {
        return Err(LearnError::Folder(input.display().to_string()));
    }
    let mut corpus = read_corpus(&[input.to_path_buf()], labels, options, listener)?;
    let recording = corpus.takes.pop().expect("one input gives one take");
    let names = recording.labels.map(|ids| ids.iter().map(|&id| corpus.label(id).to_string()).collect());
    Ok((recording.motion, names))
}

/// The takes a corpus was read from, for error messages: up to three
/// files, then how many more.
pub fn takes_named(corpus: &Corpus) -> String {
    let paths: Vec<&str> = corpus.takes.iter().map(|t| t.path.as_str()).collect();
    match paths.len() {
        0..=3 => paths.join(", "),
        n => format!("{} and {} more", paths[..3].join(", "), n - 3),
    }
}

/// `1 take`, `3 takes`.
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 { format!("1 {noun}") } else { format!("{n} {noun}s") }
}

/// Segments a corpus and says what came of it.
pub fn segment(
    corpus: &Corpus,
    params: &ValidSegmentParams,
    lineage: Lineage,
    listener: &mut dyn Listener,
) -> Result<Segments, BuildError> {
    let rows = segment_corpus(corpus, params)?;
    // Takes too short for a segment are left out, not fatal to the corpus.
    let mut segmented = vec![false; corpus.takes.len()];
    rows.iter().for_each(|r| segmented[r.take] = true);
    for (take, _) in corpus.takes.iter().zip(&segmented).filter(|(_, s)| !**s) {
        let seconds = take.motion.poses.len() as f64 * take.motion.frame_time_s;
        listener.note(&format!(
            "{}: warning: skipped: no segment of at least {} s in its {seconds:.2} s",
            take.path,
            params.params().min_length_s
        ));
    }
    let segments = Segments::new(lineage, corpus, rows);
    let cycles = segments.rows.iter().filter(|r| r.phase_offset.is_some()).count();
    let seconds: f64 = corpus.takes.iter().map(|t| t.motion.poses.len() as f64 * t.motion.frame_time_s).sum();
    listener.note(&format!(
        "{} ({}, {seconds:.1} s) → {} ({})",
        count(corpus.takes.len(), "take"),
        count(corpus.frames(), "frame"),
        count(segments.rows.len(), "segment"),
        count(cycles, "whole cycle")
    ));
    Ok(segments)
}

/// Embeds segments and says how.
pub fn embed(
    corpus: &Corpus,
    mut segments: Segments,
    params: &ValidEmbedParams,
    listener: &mut dyn Listener,
) -> Result<Embedded, BuildError> {
    let embedding = embed_segments(corpus, &segments.rows, params)?;
    let p = params.params();
    let kind = if p.temporal {
        format!(
            "ST-Isomap, {} neighbours; {} adjacent and {} common temporal neighbour links shrunk",
            p.neighbors, embedding.atn_edges, embedding.ctn_edges
        )
    } else {
        format!("plain Isomap, {} neighbours", p.neighbors)
    };
    let joined = match embedding.joined_components {
        0 => String::new(),
        n => format!("; {n} separate pieces of the graph joined at their closest segments"),
    };
    let (segments_embedded, dims) = (count(embedding.len(), "segment"), count(embedding.dims(), "dimension"));
    listener.note(&format!("{segments_embedded} embedded in {dims} ({kind}{joined})"));
    segments.lineage.embed = Some(p.clone());
    Ok(Embedded { segments, embedding })
}

/// Clusters embedded segments and says how k was chosen and, where the
/// segments are labelled, how well clusters match the labels.
pub fn cluster(
    mut embedded: Embedded,
    params: &ValidClusterParams,
    listener: &mut dyn Listener,
) -> Result<Clustered, ClusterError> {
    let clustering = params.cluster(&embedded.embedding, &segment_labels(&embedded.segments.rows))?;
    let score = clustering.score().unwrap_or(f64::NAN);
    let how = match clustering.choice() {
        Choice::Given => format!("k = {} as given (mean silhouette {score:.3})", clustering.k()),
        Choice::ByLabel => {
            format!("k = {}: one cluster per activity label (mean silhouette {score:.3})", clustering.k())
        }
        Choice::Silhouette => {
            let tried = clustering.scores();
            let (low, high) = (tried.first().map_or(0, |t| t.k), tried.last().map_or(0, |t| t.k));
            let p = params.params();
            let why = match best(tried, p.min_size) {
                Some(b) if b.k != clustering.k() => format!(
                    "within {} standard error{} of the best ({:.3} ± {:.3} at k = {}), the largest k",
                    p.tolerance,
                    if p.tolerance == 1.0 { "" } else { "s" },
                    b.silhouette,
                    b.standard_error,
                    b.k
                ),
                _ => "the best".to_string(),
            };
            let sized = if p.min_size > 1 {
                format!(" with clusters of {} or more segments", p.min_size)
            } else {
                String::new()
            };
            format!("k = {} chosen by mean silhouette {score:.3}, {why} of k = {low} to {high}{sized}", clustering.k())
        }
    };
    listener.note(&format!("{} segments → {how}", embedded.embedding.len()));
    let rows = &embedded.segments.rows;
    if let Some(scores) = cluster_scores(rows, clustering.assignments()) {
        let (all, whole) = (scores.all, scores.whole_activity);
        listener.note(&format!(
            "against the labels: purity {:.3}, adjusted Rand index {:.3} over the {} segments of one activity; \
             {:.3} and {:.3} over all {}",
            whole.purity, whole.adjusted_rand_index, whole.segments, all.purity, all.adjusted_rand_index, all.segments
        ));
        let missing = activities_without_primitive(rows, clustering.assignments());
        if !missing.is_empty() {
            listener.note(&format!("no cluster of its own for: {}", missing.join(", ")));
        }
    }
    embedded.segments.lineage.cluster = Some(ClusterRecord::new(params.params().clone(), &clustering));
    Ok(Clustered { embedded, clustering })
}

/// Fits the primitives and lists them.
pub fn fit(
    corpus: &Corpus,
    clustered: &Clustered,
    params: &ValidFitParams,
    listener: &mut dyn Listener,
) -> Result<Vocabulary, BuildError> {
    let segments = &clustered.embedded.segments;
    let fitted = fit_primitives(corpus, &segments.rows, &clustered.clustering, params)?;
    for name in &fitted.still {
        listener.note(&format!("cluster `{name}` left out: its poses never change, so it has no motion to model"));
    }
    let assignments = fitted.assignments(&clustered.clustering);
    if let Some(scores) = cluster_scores(&segments.rows, &assignments) {
        let missing = activities_without_primitive(&segments.rows, &assignments);
        let missing = if missing.is_empty() {
            String::new()
        } else {
            format!("; no primitive of its own for: {}", missing.join(", "))
        };
        listener.note(&format!(
            "{} primitives against the labels: purity {:.3}, adjusted Rand index {:.3} over all {} segments{missing}",
            fitted.primitives.len(),
            scores.all.purity,
            scores.all.adjusted_rand_index,
            scores.all.segments
        ));
    }
    let info = build_info(&segments.lineage, params.params(), segments, fitted.still);
    let vocabulary = Vocabulary::new(fitted.primitives, info);
    listener.note(&summary(&vocabulary));
    Ok(vocabulary)
}

/// One line per primitive.
pub fn summary(vocabulary: &Vocabulary) -> String {
    let width = vocabulary.primitives().iter().map(|p| p.name().chars().count()).max().unwrap_or(0).max(16);
    let mut lines = vec![format!(
        "{:<width$} {:>4} {:>9} {:>7} {:>9} {:>12}",
        "primitive", "dims", "variance", "frames", "segments", "speed (1/s)"
    )];
    for p in vocabulary.primitives() {
        lines.push(format!(
            "{:<width$} {:>4} {:>8.1}% {:>7} {:>9} {:>12.2}",
            p.name(),
            p.dims(),
            100.0 * p.variance_kept(),
            p.training_frames(),
            p.sources().len(),
            p.speed().median
        ));
    }
    lines.join("\n")
}
