//! What an `imitate execute` of a run's virtual trajectory adds to the run's
//! report: how closely the humanoid followed it, joint by joint, and a
//! filmstrip of the humanoid over the trajectory.

use super::metrics::{ReportError, Track};
use crate::mocap::bvh::read_bvh;
use crate::mocap::retarget::{RetargetOptions, Retargeter};
use std::path::Path;

/// The part of an execution's `summary.json` the report shows.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct ExecutionSummary {
    pub frames: usize,
    pub skipped_frames: usize,
    pub base: String,
    pub rate_hz: f64,
    pub rms_error_deg: f64,
    pub max_error_deg: f64,
    pub fell_at_s: Option<f64>,
    pub joints: Vec<JointRow>,
}

#[derive(Debug, Clone, serde::Deserialize)]
pub struct JointRow {
    pub joint: String,
    pub rms_error_deg: f64,
    pub max_error_deg: f64,
    pub peak_torque_nm: f64,
    pub torque_limit_nm: f64,
    pub torque_limited_share: f64,
}

/// An execution of a run's trajectory: its numbers, and where the
/// humanoid's joints were at each of the run's frames.
#[derive(Debug, Clone)]
pub struct Imitation {
    pub summary: ExecutionSummary,
    pub humanoid: Track,
}

/// Reads the `execute` folder `dir` (its `summary.json` and
/// `executed.bvh`), which must have played every frame of `run`.
pub fn read_imitation(dir: &Path, run: &Track) -> Result<Imitation, ReportError> {
    let path = dir.join("summary.json");
    let file = path.display().to_string();
    let text = super::read(&path)?;
    let summary: ExecutionSummary = serde_json::from_str(&text)
        .map_err(|e| ReportError::Summary { file: file.clone(), message: format!("not an execution summary: {e}") })?;
    if summary.skipped_frames != 0 || summary.frames != run.frame.len() {
        return Err(ReportError::Summary {
            file,
            message: format!(
                "the humanoid played {} frames (after skipping {}), but {} has {}: execute the run's \
                 trajectory.bvh whole",
                summary.frames,
                summary.skipped_frames,
                run.file,
                run.frame.len()
            ),
        });
    }
    let path = dir.join("executed.bvh");
    let file = path.display().to_string();
    let bvh = read_bvh(&path)?;
    let motion = Retargeter::new(&bvh, &RetargetOptions::default())
        .map_err(|e| ReportError::Summary { file: file.clone(), message: e.to_string() })?
        .retarget(&bvh);
    if motion.poses.len() != run.frame.len() {
        let message = format!("{} frames, but its summary.json says {}", motion.poses.len(), summary.frames);
        return Err(ReportError::Summary { file, message });
    }
    let frames: Vec<_> = motion.poses.iter().map(|p| motion.body.forward(p)).collect();
    let humanoid = Track {
        file,
        frame: run.frame.clone(),
        time_s: run.time_s.clone(),
        activity: vec![None; run.frame.len()],
        root: motion.poses.iter().map(|p| p.root).collect(),
        joints: frames.iter().map(|f| f.positions).collect(),
    };
    Ok(Imitation { summary, humanoid })
}

impl Imitation {
    /// One sentence: how the humanoid was held and how it followed.
    pub fn sentence(&self) -> String {
        let s = &self.summary;
        let ending = match (s.base.as_str(), s.fell_at_s) {
            ("fixed", _) => "on a stand (fixed base)".to_string(),
            (_, Some(t)) => format!("standing on the ground; it fell {t:.2} s in"),
            (_, None) => "standing on the ground; it stayed up".to_string(),
        };
        format!(
            "The virtual trajectory played on the simulated humanoid at {:.0} Hz (imitate execute): its joints followed \
             within {:.2}° RMS, {:.1}° at worst, {ending}.",
            s.rate_hz, s.rms_error_deg, s.max_error_deg
        )
    }

    /// Per joint: name, RMS and worst error (°), peak torque and its cap
    /// (N·m), the share of steps at the cap.
    pub fn rows(&self) -> Vec<Vec<String>> {
        self.summary
            .joints
            .iter()
            .map(|j| {
                vec![
                    j.joint.clone(),
                    format!("{:.2}", j.rms_error_deg),
                    format!("{:.1}", j.max_error_deg),
                    format!("{:.1}", j.peak_torque_nm),
                    format!("{:.0}", j.torque_limit_nm),
                    format!("{:.1}%", 100.0 * j.torque_limited_share),
                ]
            })
            .collect()
    }
}
