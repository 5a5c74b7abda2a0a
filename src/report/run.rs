//! One `imitate track` run read back whole, for reports: the trajectory's
//! joint positions, each primitive's probability, progress and likelihood
//! per frame, and the settings from `summary.json`.

use super::metrics::{Primitives, ReportError, Track};
use super::{Curves, Table, read_primitives, read_track};
use crate::track::run::RunSummary;
use std::path::{Path, PathBuf};

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
