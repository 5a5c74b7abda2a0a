//! `imitate cluster`: group embedded segments into primitives.

use super::learn::ClusterArgs;
use super::{Global, Outcome, note};
use anyhow::Context;
use imitate::vocab::cluster::{Choice, ValidClusterParams, best};
use imitate::vocab::evaluate::{activities_without_primitive, cluster_scores};
use imitate::vocab::lineage::ClusterRecord;
use imitate::vocab::pipeline::segment_labels;
use imitate::vocab::stages::{Clustered, Embedded};
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

/// Clusters embedded segments and says how k was chosen and, where the
/// segments are labelled, how well clusters match the labels.
pub fn cluster(mut embedded: Embedded, params: &ValidClusterParams, global: Global) -> anyhow::Result<Clustered> {
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
    note(global, &format!("{} segments → {how}", embedded.embedding.len()));
    let rows = &embedded.segments.rows;
    if let Some(scores) = cluster_scores(rows, clustering.assignments()) {
        let (all, whole) = (scores.all, scores.whole_activity);
        note(
            global,
            &format!(
                "against the labels: purity {:.3}, adjusted Rand index {:.3} over the {} segments of one activity; \
                 {:.3} and {:.3} over all {}",
                whole.purity,
                whole.adjusted_rand_index,
                whole.segments,
                all.purity,
                all.adjusted_rand_index,
                all.segments
            ),
        );
        let missing = activities_without_primitive(rows, clustering.assignments());
        if !missing.is_empty() {
            note(global, &format!("no cluster of its own for: {}", missing.join(", ")));
        }
    }
    embedded.segments.lineage.cluster = Some(ClusterRecord::new(params.params().clone(), &clustering));
    Ok(Clustered { embedded, clustering })
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let params = args.cluster.params()?;
    let context = || "`imitate cluster` reads an embedding table (from `imitate embed`)".to_string();
    let embedded = Embedded::read(&args.embedding).with_context(context)?;
    let clustered = cluster(embedded, &params, global).with_context(|| args.embedding.display().to_string())?;
    clustered.write(&args.output)?;
    note(global, &format!("wrote {}", args.output.display()));
    Ok(Outcome::Success)
}
