//! `imitate embed`: spatio-temporal Isomap over segments.

use super::learn::EmbedArgs;
use super::{Global, Outcome, count, note, progress};
use anyhow::Context;
use imitate::vocab::corpus::Corpus;
use imitate::vocab::embed::ValidEmbedParams;
use imitate::vocab::pipeline::embed_segments;
use imitate::vocab::stages::{Embedded, Segments};
use std::path::PathBuf;

/// Embed segments by spatio-temporal Isomap: a neighbourhood graph over
/// the segments' paths with temporally adjacent and common temporal
/// neighbours pulled together, geodesic distances by shortest paths, and
/// classical MDS.
///
/// Reads the motion again from the files the segments table names.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A segments table from `imitate segment`.
    pub segments: PathBuf,
    /// The embedding table to write (`.parquet` or `.csv`).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub embed: EmbedArgs,
}

/// Embeds segments and says how.
pub fn embed(
    corpus: &Corpus,
    mut segments: Segments,
    params: &ValidEmbedParams,
    global: Global,
) -> anyhow::Result<Embedded> {
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
    note(global, &format!("{segments_embedded} embedded in {dims} ({kind}{joined})"));
    segments.lineage.embed = Some(p.clone());
    Ok(Embedded { segments, embedding })
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let params = args.embed.params()?;
    let context = || "`imitate embed` reads a segments table (from `imitate segment`)".to_string();
    let segments = Segments::read(&args.segments).with_context(context)?;
    let bar = progress(global, 1, "read");
    let corpus = segments.load_motion(&args.segments)?;
    bar.finish_and_clear();
    let embedded = embed(&corpus, segments, &params, global).with_context(|| args.segments.display().to_string())?;
    embedded.write(&args.output)?;
    note(global, &format!("wrote {}", args.output.display()));
    Ok(Outcome::Success)
}
