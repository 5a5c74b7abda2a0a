//! Synthesized takes as files: what `imitate synth` writes, and what
//! `eval` and `demo` make their test motion with (docs/formats.md,
//! "Labels").

use super::{Activity, SynthOptions, Take, activity_take, sequence_take};
use crate::fsutil::write_atomic;
use crate::mocap::bvh::write_bvh;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The chained take's file in its folder.
pub const SEQUENCE_FILE: &str = "sequence.bvh";
/// The labels' file in a folder of synthesized takes.
pub const LABELS_FILE: &str = "labels.csv";

/// A file or folder that could not be made.
#[derive(Debug, thiserror::Error)]
#[error("cannot {what} {path}: {source}")]
pub struct WriteError {
    what: &'static str,
    path: String,
    source: std::io::Error,
}

impl WriteError {
    fn at(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> WriteError {
        let path = path.display().to_string();
        move |source| WriteError { what, path, source }
    }
}

/// Writes `activities` chained with smooth transitions as `dir/sequence.bvh`
/// and each frame's activity as `dir/labels.csv` (`frame,activity`).
pub fn write_sequence(dir: &Path, activities: &[Activity], options: &SynthOptions) -> Result<Take, WriteError> {
    std::fs::create_dir_all(dir).map_err(WriteError::at("create", dir))?;
    let take = sequence_take(activities, options);
    write_take(&dir.join(SEQUENCE_FILE), &take)?;
    let labels = dir.join(LABELS_FILE);
    write_atomic(&labels, |w| {
        writeln!(w, "frame,activity")?;
        take.labels.iter().enumerate().try_for_each(|(frame, label)| writeln!(w, "{frame},{label}"))
    })
    .map_err(WriteError::at("write", &labels))?;
    Ok(take)
}

/// Writes one take of each of `activities` as `dir/<activity>.bvh` and
/// which is which as `dir/labels.csv` (`file,activity`); `written` hears of
/// each take once its file is written.
pub fn write_activities(
    dir: &Path,
    activities: &[Activity],
    options: &SynthOptions,
    written: &mut dyn FnMut(&Path, &Take),
) -> Result<(), WriteError> {
    std::fs::create_dir_all(dir).map_err(WriteError::at("create", dir))?;
    for &activity in activities {
        let take = activity_take(activity, options);
        let path: PathBuf = dir.join(format!("{}.bvh", activity.name()));
        write_take(&path, &take)?;
        written(&path, &take);
    }
    let labels = dir.join(LABELS_FILE);
    write_atomic(&labels, |w| {
        writeln!(w, "file,activity")?;
        activities.iter().try_for_each(|a| writeln!(w, "{}.bvh,{}", a.name(), a.name()))
    })
    .map_err(WriteError::at("write", &labels))
}

/// A take as canonical BVH.
fn write_take(path: &Path, take: &Take) -> Result<(), WriteError> {
    let bvh = take.motion.to_bvh();
    write_atomic(path, |w| write_bvh(&bvh, w)).map_err(WriteError::at("write", path))
}
