//! `imitate cluster`: group embedded segments into primitives.

use super::learn::ClusterArgs;
use super::{Global, Notes, Outcome, note};
use anyhow::Context;
use imitate::vocab::learn::cluster;
use imitate::vocab::stages::Embedded;
use std::path::PathBuf;

/// Group embedded segments into primitives by k-means (linfa). Without
/// `--k`, k is the largest whose mean silhouette lies within `--tolerance`
/// standard errors of the best, among clusterings whose every cluster holds
/// `--min-size` segments, and the command says so.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// An embedding table from `imitate embed`.
    pub embedding: PathBuf,
    /// The clusters table to write (`.parquet` or `.csv`).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub cluster: ClusterArgs,
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let params = args.cluster.params()?;
    let context = || "`imitate cluster` reads an embedding table (from `imitate embed`)".to_string();
    let embedded = Embedded::read(&args.embedding).with_context(context)?;
    let clustered =
        cluster(embedded, &params, &mut Notes(global)).with_context(|| args.embedding.display().to_string())?;
    clustered.write(&args.output)?;
    note(global, &format!("wrote {}", args.output.display()));
    Ok(Outcome::Success)
}
