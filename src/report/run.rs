//! One `imitate track` run read back whole, for reports: the trajectory's
//! joint positions, each primitive's probability, progress and likelihood
//! per frame, and the settings from `summary.json`.

use super::metrics::{Primitives, ReportError, Track};
use super::{Curves, Table, read_primitives, read_track};
use crate::vision::camera::CameraSpec;
use std::path::{Path, PathBuf};

/// What `summary.json` says that reports show.
#[derive(Clone, Debug, serde::Deserialize)]
pub struct RunSummary {
    /// The frames tracked, as given to `track`.
    pub input: String,
    /// The camera, in the frames' own pixels.
    pub camera: CameraSpec,
    /// The size frames were reduced to for tracking; absent in runs
    /// written before `--work-size`, which tracked at the camera's size.
    #[serde(default)]
    pub work_size: Option<[usize; 2]>,
    /// The background color frames were compared with: an image's path,
    /// or what it was learned from.
    #[serde(default)]
    pub background: Option<String>,
    pub fps: f64,
    pub frames: usize,
    pub seed: u64,
    pub likelihood_evaluations_per_frame: f64,
    pub timing: Timing,
    /// The tracker's settings, as written.
    pub settings: serde_json::Value,
    #[serde(default)]
    pub baseline: Option<serde_json::Value>,
}

impl RunSummary {
    /// The background image the run was given, if it was one (and is still
    /// there), to make its silhouettes again.
    pub fn background_plate(&self) -> Option<PathBuf> {
        self.background.as_ref().map(PathBuf::from).filter(|p| p.is_file())
    }
}

#[derive(Clone, Debug, serde::Deserialize)]
pub struct Timing {
    pub seconds: f64,
    pub frames_per_second: f64,
}

pub struct Run {
    pub dir: PathBuf,
    pub track: Track,
    pub primitives: Primitives,
    /// Each primitive's probability (eq. 7 or 10), in `frames.csv` order.
    pub probabilities: Curves,
    pub progress: Curves,
    /// Each primitive's estimate's R (eq. 8), from `likelihoods.csv`;
    /// `None` for a baseline run, which writes none.
    pub likelihoods: Option<Curves>,
    /// The open set: whether each frame was unexplained (frames.csv's 1)
    /// or not (0), `None` where it was not judged, and what share of it
    /// the best primitive accounted for (`fit_` columns, by part);
    /// `unexplained` is `None` for runs written before the open set.
    pub unexplained: Option<Vec<Option<bool>>>,
    pub fits: Curves,
    pub summary: RunSummary,
}

impl Run {
    /// Reads `frames.csv`, `summary.json` and (when the primitives
    /// tracked) `likelihoods.csv` from `dir`. Every error names the file.
    pub fn read(dir: &Path) -> Result<Run, ReportError> {
        let frames = dir.join("frames.csv");
        let track = read_track(&frames)?;
        let table = Table::read(&frames)?;
        let summary_path = dir.join("summary.json");
        let primitives = read_primitives(&summary_path)?;
        let summary: RunSummary = serde_json::from_str(&super::read(&summary_path)?)
            .map_err(|e| ReportError::Summary { file: summary_path.display().to_string(), message: e.to_string() })?;
        let probabilities = table.prefixed("prob_")?;
        let progress = table.prefixed("progress_")?;
        let unexplained = table.column("unexplained")?.map(|c| c.into_iter().map(|v| v.map(|v| v > 0.5)).collect());
        let fits = table.prefixed("fit_")?;
        let likelihoods = match summary.baseline {
            Some(_) => None,
            None => {
                let table = Table::read(&dir.join("likelihoods.csv"))?;
                if table.rows() != track.frame.len() {
                    return Err(ReportError::Summary {
                        file: table.file.clone(),
                        message: format!("{} rows, but frames.csv has {}", table.rows(), track.frame.len()),
                    });
                }
                Some(table.prefixed("likelihood_")?)
            }
        };
        Ok(Run {
            dir: dir.to_path_buf(),
            track,
            primitives,
            probabilities,
            progress,
            likelihoods,
            unexplained,
            fits,
            summary,
        })
    }

    /// Frames the open set judged (observed and tracked by the
    /// primitives), and of them those unexplained.
    pub fn unexplained_frames(&self) -> Option<(usize, usize)> {
        let judged = self.unexplained.as_ref()?.iter().flatten();
        Some(judged.fold((0, 0), |(all, unexplained), &v| (all + 1, unexplained + usize::from(v))))
    }

    /// The primitives' names, in `frames.csv` order.
    pub fn names(&self) -> Vec<&str> {
        self.probabilities.iter().map(|(n, _)| n.as_str()).collect()
    }
}
