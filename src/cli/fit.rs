//! `imitate fit`: one primitive per cluster.

use super::learn::FitArgs;
use super::{Global, Outcome, note, progress};
use anyhow::Context;
use imitate::vocab::corpus::Corpus;
use imitate::vocab::evaluate::{activities_without_primitive, cluster_scores};
use imitate::vocab::pipeline::fit_primitives;
use imitate::vocab::primitive::ValidFitParams;
use imitate::vocab::stages::{Clustered, build_info, write_primitives};
use imitate::vocab::vocabulary::Vocabulary;
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

/// Fits the primitives and lists them.
pub fn fit(
    corpus: &Corpus,
    clustered: &Clustered,
    params: &ValidFitParams,
    global: Global,
) -> anyhow::Result<Vocabulary> {
    let segments = &clustered.embedded.segments;
    let fitted = fit_primitives(corpus, &segments.rows, &clustered.clustering, params)?;
    for name in &fitted.still {
        note(global, &format!("cluster `{name}` left out: its poses never change, so it has no motion to model"));
    }
    let assignments = fitted.assignments(&clustered.clustering);
    if let Some(scores) = cluster_scores(&segments.rows, &assignments) {
        let missing = activities_without_primitive(&segments.rows, &assignments);
        let missing = if missing.is_empty() {
            String::new()
        } else {
            format!("; no primitive of its own for: {}", missing.join(", "))
        };
        note(
            global,
            &format!(
                "{} primitives against the labels: purity {:.3}, adjusted Rand index {:.3} over all {} segments{missing}",
                fitted.primitives.len(),
                scores.all.purity,
                scores.all.adjusted_rand_index,
                scores.all.segments
            ),
        );
    }
    let info = build_info(&segments.lineage, params.params(), segments, fitted.still);
    let vocabulary = Vocabulary::new(fitted.primitives, info);
    note(global, &summary(&vocabulary));
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

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let params = args.fit.params()?;
    let context = || "`imitate fit` reads a clusters table (from `imitate cluster`)".to_string();
    let clustered = Clustered::read(&args.clusters).with_context(context)?;
    let bar = progress(global, 1, "read");
    let corpus = clustered.embedded.segments.load_motion(&args.clusters)?;
    bar.finish_and_clear();
    let vocabulary = fit(&corpus, &clustered, &params, global).with_context(|| args.clusters.display().to_string())?;
    write_primitives(&vocabulary, &args.output)?;
    note(global, &format!("wrote {}", args.output.display()));
    Ok(Outcome::Success)
}
