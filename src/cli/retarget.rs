//! `imitate retarget`: any BVH onto the canonical humanoid, written as BVH.

use super::{Global, Outcome, note, progress};
use anyhow::Context;
use imitate::fsutil::write_atomic;
use imitate::mocap::bvh::{read_bvh, write_bvh};
use imitate::mocap::names::UserMapping;
use imitate::mocap::retarget::{DirectionErrors, RetargetOptions, Retargeter, UpAxis};
use std::path::{Path, PathBuf};

/// Retarget a BVH file onto the canonical 17-joint humanoid.
///
/// Joint rotations are chosen so every canonical bone points where the
/// source bone points; the output is canonical BVH (meters, degrees).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The BVH file to read.
    pub input: PathBuf,
    /// Where to write the canonical BVH.
    #[arg(short, long)]
    pub output: PathBuf,
    /// The source's up axis, when detection from the skeleton gets it wrong.
    #[arg(long, value_enum)]
    pub up: Option<UpArg>,
    /// A mapping file for joints the built-in naming tables do not know
    /// (`canonical = "Source Joint"`, see the README).
    #[arg(long = "map", value_name = "MAPPING.toml")]
    pub mapping: Option<PathBuf>,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum UpArg {
    Y,
    Z,
}

impl From<UpArg> for UpAxis {
    fn from(u: UpArg) -> UpAxis {
        match u {
            UpArg::Y => UpAxis::Y,
            UpArg::Z => UpAxis::Z,
        }
    }
}

/// Reads the options shared with `inspect`.
pub fn options(up: Option<UpArg>, mapping: Option<&Path>) -> anyhow::Result<RetargetOptions> {
    let mapping = mapping.map(UserMapping::load).transpose()?;
    Ok(RetargetOptions { up: up.map(Into::into), mapping })
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let options = options(args.up, args.mapping.as_deref())?;
    let bar = progress(global, 3, "retarget");
    let bvh = read_bvh(&args.input)?;
    bar.inc(1);
    let input = args.input.display();
    let retargeter = Retargeter::new(&bvh, &options).with_context(|| format!("{input}"))?;
    let motion = retargeter.retarget(&bvh);
    bar.inc(1);
    let canonical = motion.to_bvh();
    write_atomic(&args.output, |w| write_bvh(&canonical, w))
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    bar.finish_and_clear();
    for warning in bvh.warnings.iter().chain(&retargeter.analysis().warnings) {
        note(global, &format!("{input}: warning: {warning}"));
    }
    let errors = DirectionErrors::measure(&bvh, &retargeter, &motion);
    note(
        global,
        &format!(
            "{input}: {} frames → {} (canonical, 17 joints); limb directions match the source within {:.2}° on average, {:.2}° at worst",
            motion.poses.len(),
            args.output.display(),
            errors.mean_deg,
            errors.max_deg
        ),
    );
    Ok(Outcome::Success)
}
