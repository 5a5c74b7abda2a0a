//! `imitate segment`: cut takes into segments.

use super::learn::{SegmentArgs, TakesArgs};
use super::retarget::RetargetArgs;
use super::{Global, Notes, Outcome, note, progress};
use anyhow::Context;
use imitate::mocap::pose::Motion;
use imitate::mocap::retarget::RetargetOptions;
use imitate::vocab::corpus::Corpus;
use imitate::vocab::learn::{read_corpus, read_take, segment, takes_named};
use imitate::vocab::lineage::Lineage;
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

/// One take (any skeleton: it is retargeted) and, when labelled, each of
/// its frames' activity: what `render` and `execute` read.
pub fn take(
    input: &Path,
    labels: Option<&Path>,
    retarget: &RetargetArgs,
    global: Global,
) -> anyhow::Result<(Motion, Option<Vec<String>>)> {
    let bar = progress(global, 1, "read");
    let read = read_take(input, labels, &retarget.options()?, &mut Notes(global))?;
    bar.finish_and_clear();
    Ok(read)
}

/// Reads the takes under a progress bar, notes on stderr.
fn load_corpus(
    inputs: &[PathBuf],
    labels: Option<&Path>,
    options: &RetargetOptions,
    global: Global,
) -> anyhow::Result<Corpus> {
    let bar = progress(global, 1, "read");
    let corpus = read_corpus(inputs, labels, options, &mut Notes(global))?;
    bar.finish_and_clear();
    Ok(corpus)
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let params = args.segment.params()?;
    let (takes, settings) = (&args.takes, args.takes.retarget.settings());
    let corpus = load_corpus(&takes.inputs, takes.labels.as_deref(), &takes.retarget.options()?, global)?;
    let lineage = Lineage::new(settings, params.params().clone());
    let segments = segment(&corpus, &params, lineage, &mut Notes(global)).with_context(|| takes_named(&corpus))?;
    segments.write(&args.output)?;
    note(global, &format!("wrote {}", args.output.display()));
    Ok(Outcome::Success)
}
