//! One tracking run as a report folder: what `imitate report` writes and
//! `demo` ends with (docs/formats.md, "Reports").

use crate::fsutil::{WriteError, write_dir_atomic};
use crate::report::filmstrip::{MAX_FRAMES, Observed, pick_frames};
use crate::report::imitation::read_imitation;
use crate::report::metrics::{Metrics, ReportError, score};
use crate::report::page::{Truth, run_report};
use crate::report::read_track;
use crate::report::run::Run;
use crate::vision::camera::{Camera, CameraError};
use crate::vision::frames::{Expect, FrameError, FrameKind, FrameSource};
use crate::vision::mask::Mask;
use crate::vision::silhouette::{SilhouetteError, Silhouettes};
use std::path::{Path, PathBuf};

/// What a report shows beside the run.
#[derive(Clone, Debug, Default)]
pub struct ReportInputs {
    /// The video's truth.csv: scores, and the truth drawn beside the estimate.
    pub truth: Option<PathBuf>,
    /// The frames that were tracked, when not where summary.json says.
    pub frames: Option<PathBuf>,
    /// An execution folder of the run's trajectory.
    pub execution: Option<PathBuf>,
    /// Seconds after each switch of the true activity that the settled
    /// accuracy leaves out.
    pub settle_s: f64,
}

/// Why a report could not be made.
#[derive(Debug, thiserror::Error)]
pub enum WriteReportError {
    #[error("settle_s: must be a number of seconds, 0 or more, not {0}")]
    Settle(f64),
    #[error(transparent)]
    Report(#[from] ReportError),
    #[error("{file}: the camera: {source}")]
    Camera { file: String, source: CameraError },
    #[error("{0}")]
    Frames(#[from] FrameError),
    #[error("{0}")]
    Silhouette(#[from] SilhouetteError),
    /// The frames hold another number of frames than the run tracked.
    #[error("{input}: {found} frames, but the run tracked {tracked}; give the frames it tracked")]
    OtherFrames { input: String, found: usize, tracked: usize },
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// Writes the report of the run in `run_dir` into `output` (replacing it
/// once whole) and returns the run's scores against the truth, when given.
pub fn write_report(run_dir: &Path, inputs: &ReportInputs, output: &Path) -> Result<Option<Metrics>, WriteReportError> {
    if !(inputs.settle_s.is_finite() && inputs.settle_s >= 0.0) {
        return Err(WriteReportError::Settle(inputs.settle_s));
    }
    let run = Run::read(run_dir)?;
    let camera = tracked_camera(&run)?;
    let truth = inputs.truth.as_deref().map(read_track).transpose()?;
    let metrics = truth.as_ref().map(|t| score(&run.track, t, &run.primitives, inputs.settle_s)).transpose()?;
    let input = inputs.frames.clone().unwrap_or_else(|| PathBuf::from(&run.summary.input));
    let picks = pick_frames(run.track.frame.len(), MAX_FRAMES);
    let background = run.summary.background_plate();
    let observed = silhouettes(&input, run.track.frame.len(), &picks, camera.width(), background)?;
    let truth_view = truth.as_ref().zip(metrics.as_ref()).map(|(track, metrics)| Truth { track, metrics });
    let imitation = inputs.execution.as_deref().map(|dir| read_imitation(dir, &run.track)).transpose()?;
    let mut files = run_report(&run, truth_view, imitation.as_ref(), &camera, &picks, &observed);
    if let Some(m) = &metrics {
        let json = serde_json::to_string_pretty(m).expect("metrics are plain numbers and maps") + "\n";
        files.push(("metrics.json".into(), json.into_bytes()));
    }
    let at = WriteError::at(output);
    let io = |e: std::io::Error| WriteReportError::Write(at(e));
    write_dir_atomic(
        output,
        |dir| files.iter().try_for_each(|(name, bytes)| std::fs::write(dir.join(name), bytes)).map_err(io),
        io,
    )?;
    Ok(metrics)
}

/// What the tracker saw of frames `picks` of `input` (which must hold
/// `frames` frames), at most `work_width` pixels wide (as `track
/// --work-size`), color frames against `background` when the run was given
/// one: the silhouettes, and the images of color frames.
pub fn silhouettes(
    input: &Path,
    frames: usize,
    picks: &[usize],
    work_width: usize,
    background: Option<PathBuf>,
) -> Result<Vec<Observed>, WriteReportError> {
    let source = FrameSource::open(input, Expect::Auto)?;
    let other = |found| WriteReportError::OtherFrames { input: input.display().to_string(), found, tracked: frames };
    if let Some(n) = source.frame_count().filter(|&n| n != frames) {
        return Err(other(n));
    }
    let mut silhouettes = Silhouettes::new(input, source, background, work_width);
    let (mut mask, mut out, mut k) = (Mask::new(1, 1), Vec::new(), 0);
    while out.len() < picks.len() {
        let frame = match silhouettes.next_seen(&mut mask) {
            Some(r) => r?,
            None => return Err(other(k)),
        };
        if picks[out.len()] == k {
            let image = (frame.kind() == FrameKind::Color).then_some(frame);
            out.push(Observed { mask: mask.clone(), image });
        }
        k += 1;
    }
    Ok(out)
}

/// The camera a run tracked through, at the size it worked at.
pub fn tracked_camera(run: &Run) -> Result<Camera, WriteReportError> {
    let file = run.dir.join("summary.json").display().to_string();
    let camera = Camera::new(run.summary.camera.clone(), &file)
        .map_err(|source| WriteReportError::Camera { file: file.clone(), source })?;
    Ok(match run.summary.work_size {
        Some([width, height]) => camera.resized(width, height),
        None => camera,
    })
}
