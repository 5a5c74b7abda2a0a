//! `imitate retarget`: any BVH onto the canonical humanoid, written as BVH.

use super::{Global, Outcome, note, progress};
use anyhow::Context;
use imitate::fsutil::write_atomic;
use imitate::mocap::bvh::{read_bvh, write_bvh};
use imitate::mocap::fidelity::{Continuity, DirectionErrors, JUMP_DEG, ThighFacing};
use imitate::mocap::mapping::UserMapping;
use imitate::mocap::retarget::{RetargetOptions, Retargeter, UpAxis};
use imitate::vocab::lineage::RetargetSettings;
use std::path::PathBuf;

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
    #[command(flatten)]
    pub retarget: RetargetArgs,
}

/// How source skeletons are put onto the canonical body: what every
/// command that reads BVH takes.
#[derive(Debug, clap::Args)]
pub struct RetargetArgs {
    /// The source's up axis, when detection from the skeleton gets it wrong.
    #[arg(long, value_enum)]
    pub up: Option<UpArg>,
    /// A mapping file for joints the built-in naming tables do not know
    /// (`canonical = "Source Joint"`, see docs/formats.md).
    #[arg(long = "map", value_name = "MAPPING.toml")]
    pub mapping: Option<PathBuf>,
}

impl RetargetArgs {
    /// The options, the mapping file read.
    pub fn options(&self) -> anyhow::Result<RetargetOptions> {
        let mapping = self.mapping.as_deref().map(UserMapping::load).transpose()?;
        Ok(RetargetOptions { up: self.up.map(Into::into), mapping })
    }

    /// The settings as stage files record them.
    pub fn settings(&self) -> RetargetSettings {
        RetargetSettings::new(self.up.map(Into::into), self.mapping.as_deref())
    }
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

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let options = args.retarget.options()?;
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
    let (facing, continuity) = (ThighFacing::measure(&motion), Continuity::measure(&bvh, &retargeter, &motion));
    note(
        global,
        &format!(
            "{input}: standing thighs face the pelvis's way within 30° in {} of {} leg-frames (worst {:.0}°); \
             {} joint-space jump{} over {JUMP_DEG:.0}° the source's bones do not make (largest jump {:.0}°, {} at frame {}, \
             where the source turned {:.0}°)",
            facing.standing - facing.beyond_30_deg,
            facing.standing,
            facing.worst_deg,
            continuity.unexplained,
            if continuity.unexplained == 1 { "" } else { "s" },
            continuity.worst_jump_deg,
            continuity.worst_joint,
            continuity.worst_frame,
            continuity.worst_source_deg
        ),
    );
    Ok(Outcome::Success)
}
