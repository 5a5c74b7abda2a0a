//! `imitate segment`: cut takes into segments.

use super::learn::{SegmentArgs, TakesArgs};
use super::retarget::RetargetArgs;
use super::{Global, Outcome, count, note, progress};
use anyhow::{Context, bail};
use imitate::mocap::pose::Motion;
use imitate::mocap::retarget::RetargetOptions;
use imitate::vocab::corpus::{self, Corpus, read_labels};
use imitate::vocab::lineage::Lineage;
use imitate::vocab::pipeline::segment_corpus;
use imitate::vocab::segment::ValidSegmentParams;
use imitate::vocab::stages::Segments;
use std::path::{Path, PathBuf};

/// Cut BVH takes into segments (one row per segment: file, frames,
/// duration, whether it is a whole cycle, label).
///
/// Writes a `segments` table, Parquet or CSV by the output's extension.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub takes: TakesArgs,
    /// The segments table to write (`.parquet` or `.csv`).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub segment: SegmentArgs,
}

/// Reads and retargets the inputs (BVH files or folders), with their
/// labels, warning of takes the labels leave out.
pub fn load_corpus(
    inputs: &[PathBuf],
    labels: Option<&Path>,
    options: &RetargetOptions,
    global: Global,
) -> anyhow::Result<Corpus> {
    let labels = labels.map(|path| read_labels(path).map(|l| (l, path.display().to_string()))).transpose()?;
    let bar = progress(global, 1, "read");
    let corpus = corpus::load(inputs, options, labels.as_ref().map(|(l, p)| (l, p.as_str())))?;
    bar.finish_and_clear();
    if let Some((_, path)) = &labels {
        let unlabelled: Vec<&str> =
            corpus.takes.iter().filter(|t| t.labels.is_none()).map(|t| t.path.as_str()).collect();
        if !unlabelled.is_empty() {
            note(global, &format!("{path}: warning: no labels for {}", unlabelled.join(", ")));
        }
    }
    Ok(corpus)
}

/// One take (any skeleton: it is retargeted) and, when labelled, each of
/// its frames' activity: what `render` and `execute` read.
pub fn take(
    input: &Path,
    labels: Option<&Path>,
    retarget: &RetargetArgs,
    global: Global,
) -> anyhow::Result<(Motion, Option<Vec<String>>)> {
    if input.is_dir() {
        bail!("{}: is a folder; give one BVH file", input.display());
    }
    let mut corpus = load_corpus(&[input.to_path_buf()], labels, &retarget.options()?, global)?;
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

/// Segments a corpus and says what came of it.
pub fn segment(
    corpus: &Corpus,
    params: &ValidSegmentParams,
    lineage: Lineage,
    global: Global,
) -> anyhow::Result<Segments> {
    let rows = segment_corpus(corpus, params).with_context(|| takes_named(corpus))?;
    // Takes too short for a segment are left out, not fatal to the corpus.
    let mut segmented = vec![false; corpus.takes.len()];
    rows.iter().for_each(|r| segmented[r.take] = true);
    for (take, _) in corpus.takes.iter().zip(&segmented).filter(|(_, s)| !**s) {
        let seconds = take.motion.poses.len() as f64 * take.motion.frame_time_s;
        note(
            global,
            &format!(
                "{}: warning: skipped: no segment of at least {} s in its {seconds:.2} s",
                take.path,
                params.params().min_length_s
            ),
        );
    }
    let segments = Segments::new(lineage, corpus, rows);
    let cycles = segments.rows.iter().filter(|r| r.phase_offset.is_some()).count();
    let seconds: f64 = corpus.takes.iter().map(|t| t.motion.poses.len() as f64 * t.motion.frame_time_s).sum();
    note(
        global,
        &format!(
            "{} ({}, {seconds:.1} s) → {} ({})",
            count(corpus.takes.len(), "take"),
            count(corpus.frames(), "frame"),
            count(segments.rows.len(), "segment"),
            count(cycles, "whole cycle")
        ),
    );
    Ok(segments)
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let params = args.segment.params()?;
    let (takes, settings) = (&args.takes, args.takes.retarget.settings());
    let corpus = load_corpus(&takes.inputs, takes.labels.as_deref(), &takes.retarget.options()?, global)?;
    let segments = segment(&corpus, &params, Lineage::new(settings, params.params().clone()), global)?;
    segments.write(&args.output)?;
    note(global, &format!("wrote {}", args.output.display()));
    Ok(Outcome::Success)
}
