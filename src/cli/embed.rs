//! `imitate embed`: spatio-temporal Isomap over segments.

use super::learn::EmbedArgs;
use super::{Global, Notes, Outcome, note, progress};
use anyhow::Context;
use imitate::fsutil::write_atomic;
use imitate::vision::truth::quoted;
use imitate::vocab::corpus::Corpus;
use imitate::vocab::learn::embed;
use imitate::vocab::pipeline::{SegmentRow, segment_vectors};
use imitate::vocab::stages::Segments;
use std::io::Write;
use std::path::{Path, PathBuf};

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
    /// Also write the vectors the segments are compared as (each resampled
    /// along its path and flattened) to this CSV, with each segment's
    /// label: the features to try another learner on.
    #[arg(long, value_name = "FILE.csv")]
    pub vectors: Option<PathBuf>,
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let params = args.embed.params()?;
    let context = || "`imitate embed` reads a segments table (from `imitate segment`)".to_string();
    let segments = Segments::read(&args.segments).with_context(context)?;
    let bar = progress(global, 1, "read");
    let corpus = segments.load_motion(&args.segments)?;
    bar.finish_and_clear();
    let embedded =
        embed(&corpus, segments, &params, &mut Notes(global)).with_context(|| args.segments.display().to_string())?;
    // Both files or neither.
    if let Some(path) = &args.vectors {
        write_vectors(path, &corpus, &embedded.segments.rows, params.params().resample)?;
    }
    if let Err(e) = embedded.write(&args.output) {
        if let Some(path) = &args.vectors {
            let _ = std::fs::remove_file(path);
        }
        return Err(e.into());
    }
    note(global, &format!("wrote {}", args.output.display()));
    Ok(Outcome::Success)
}

/// The segment vectors as CSV: `segment`, `label` (empty when unlabelled),
/// then `v0`, `v1`, … (`resample` poses of every joint-space number, pose
/// by pose, radians).
fn write_vectors(path: &Path, corpus: &Corpus, rows: &[SegmentRow], resample: usize) -> anyhow::Result<()> {
    let (vectors, _) = segment_vectors(corpus, rows, resample);
    let width = vectors.first().map_or(0, Vec::len);
    write_atomic(path, |w| {
        write!(w, "segment,label")?;
        (0..width).try_for_each(|i| write!(w, ",v{i}"))?;
        writeln!(w)?;
        for (i, (row, vector)) in rows.iter().zip(&vectors).enumerate() {
            write!(w, "{i},{}", quoted(row.label.as_deref().unwrap_or("")))?;
            vector.iter().try_for_each(|v| write!(w, ",{v}"))?;
            writeln!(w)?;
        }
        Ok(())
    })
    .with_context(|| format!("{}: cannot write", path.display()))
}
