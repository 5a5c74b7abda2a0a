//! `imitate fit`: one primitive per cluster.

use super::learn::FitArgs;
use super::{Global, Notes, Outcome, note, progress};
use anyhow::Context;
use imitate::vocab::learn::fit;
use imitate::vocab::stages::{Clustered, write_primitives};
use std::path::PathBuf;

/// Fit primitives to each cluster (more than one where its segments' root
/// moves in different ways, as a walk turning left and one going straight,
/// or its swings travel one path both ways): a PCA latent space (as many
/// dimensions as keep `--variance` of the pose variance, within
/// `--min-dims` and `--max-dims`), a gradient field over the training poses'
/// k nearest neighbours, speed statistics, and attractor progress (phase
/// along each training segment).
///
/// Writes a folder: `index.json` and, per primitive, its latent space and
/// field as Parquet tables (see docs/formats.md). Reads the motion again from
/// the files the table names.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A clusters table from `imitate cluster`.
    pub clusters: PathBuf,
    /// The primitives folder to write (replaced whole if it exists).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub fit: FitArgs,
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let params = args.fit.params()?;
    let context = || "`imitate fit` reads a clusters table (from `imitate cluster`)".to_string();
    let clustered = Clustered::read(&args.clusters).with_context(context)?;
    let bar = progress(global, 1, "read");
    let corpus = clustered.embedded.segments.load_motion(&args.clusters)?;
    bar.finish_and_clear();
    let vocabulary =
        fit(&corpus, &clustered, &params, &mut Notes(global)).with_context(|| args.clusters.display().to_string())?;
    write_primitives(&vocabulary, &args.output)?;
    note(global, &format!("wrote {}", args.output.display()));
    Ok(Outcome::Success)
}
