//! `imitate export`: a primitives folder as one `.vocab` file.

use super::{Global, Outcome, note};
use anyhow::Context;
use imitate::vocab::stages::read_primitives;
use std::path::PathBuf;

/// Pack a primitives folder (from `imitate fit`) into one versioned,
/// self-describing `.vocab` file guarded by a checksum (format in
/// docs/formats.md).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A primitives folder from `imitate fit`.
    pub primitives: PathBuf,
    /// The vocabulary file to write, e.g. `vocab/NAME.vocab`.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let context = || "`imitate export` reads a primitives folder (from `imitate fit`)".to_string();
    let mut vocabulary = read_primitives(&args.primitives).with_context(context)?;
    vocabulary.save(&args.output)?;
    note(global, &super::vocab::saved(&vocabulary, &args.output));
    Ok(Outcome::Success)
}
