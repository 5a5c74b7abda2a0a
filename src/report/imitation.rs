//! What an `imitate execute` of a run's virtual trajectory adds to the run's
//! report: how closely the humanoid followed it, joint by joint, how it
//! kept its balance (the margin, what it gave up of the trajectory, the
//! assistance it had) over time, and a filmstrip of the humanoid over the
//! trajectory.

use super::metrics::{ReportError, Track};
use super::plot::{Chart, Figure, Point, Series, Style};
use super::{Curves, Table};
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
    /// Absent in executions written before it was.
    #[serde(default)]
    pub min_balance_margin_m: Option<f64>,
    #[serde(default)]
    pub assist: Option<AssistRow>,
    #[serde(default)]
    pub contact_agreement: Option<f64>,
    pub joints: Vec<JointRow>,
}

#[derive(Debug, Clone, serde::Deserialize)]
pub struct AssistRow {
    pub mean_force_n: f64,
    pub max_force_n: f64,
    pub mean_force_share_of_weight: f64,
    pub mean_torque_nm: f64,
    pub max_torque_nm: f64,
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
    /// From `execution.csv`: each frame's time and its balance columns
    /// (`balance_margin_m`, `departure_deg`, `assist_force_n`,
    /// `assist_torque_nm`), those the file has, and how many of the feet
    /// touched the ground exactly when the take stood on them
    /// (`FEET_AGREEING`, from the feet columns).
    pub time_s: Vec<f64>,
    pub balance: Curves,
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
                 trajectory.bvh whole (--skip 0)",
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
    let table = Table::read(&dir.join("execution.csv"))?;
    let times = table.column("time_s")?.unwrap_or_default();
    if times.len() != summary.frames || times.iter().any(Option::is_none) {
        let message = format!("{} rows with a time, but its summary.json says {} frames", times.len(), summary.frames);
        return Err(ReportError::Summary { file: table.file, message });
    }
    let mut balance = Curves::new();
    for name in BALANCE_COLUMNS {
        if let Some(values) = table.column(name)? {
            balance.push((name.to_string(), values));
        }
    }
    let mut feet = Vec::with_capacity(FEET_COLUMNS.len());
    for name in FEET_COLUMNS {
        feet.extend(table.column(name)?);
    }
    if let [left, right, take_left, take_right] = &feet[..] {
        let agreeing = (0..times.len()).map(|k| {
            let pairs = [(left[k]?, take_left[k]?), (right[k]?, take_right[k]?)];
            Some(pairs.iter().filter(|(down, take)| down == take).count() as f64)
        });
        balance.push((FEET_AGREEING.to_string(), agreeing.collect()));
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
    Ok(Imitation { summary, humanoid, time_s: times.into_iter().flatten().collect(), balance })
}

/// The columns of `execution.csv` the balance figure draws.
const BALANCE_COLUMNS: [&str; 4] = ["balance_margin_m", "departure_deg", "assist_force_n", "assist_torque_nm"];
/// The feet columns of `execution.csv` (absent in executions written
/// before them): the humanoid's left and right, then the take's.
const FEET_COLUMNS: [&str; 4] = ["left_foot_down", "right_foot_down", "take_left_foot_down", "take_right_foot_down"];
/// The balance figure's curve drawn from them.
const FEET_AGREEING: &str = "feet_agreeing";

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
        ) + &match (&s.assist, s.min_balance_margin_m) {
            (Some(a), _) => format!(
                " It was assisted: a push on its pelvis of {:.0} N on average ({:.1}% of its weight), {:.0} N at \
                 most, and a torque turning it of {:.0} N·m on average, {:.0} N·m at most.",
                a.mean_force_n,
                100.0 * a.mean_force_share_of_weight,
                a.max_force_n,
                a.mean_torque_nm,
                a.max_torque_nm
            ),
            (None, Some(m)) if m < 0.0 => {
                format!(" Its capture point left its feet by up to {:.0} mm (a negative balance margin).", -1e3 * m)
            }
            (None, Some(m)) => format!(" Its capture point stayed at least {:.0} mm inside its feet.", 1e3 * m),
            (None, None) => String::new(),
        } + &s.contact_agreement.map_or(String::new(), |a| {
            format!(
                " Its feet touched the ground exactly when the trajectory stood on them {:.0}% of the time{}.",
                100.0 * a,
                if s.fell_at_s.is_some() { " before it fell" } else { "" }
            )
        })
    }

    /// The balance over time, one panel per column the execution has that
    /// says something (a fixed base has no margin; without assistance the
    /// force and torque are zero throughout, and an assisted humanoid whose
    /// capture point never left its feet was never pushed): `None` when
    /// none does.
    pub fn balance_figure(&self, width: u32) -> Option<Figure> {
        let panels: Vec<Chart> = self
            .balance
            .iter()
            .filter(|(_, values)| values.iter().flatten().any(|&v| v != 0.0))
            .map(|(name, values)| {
                let (title, unit) = match name.as_str() {
                    "balance_margin_m" => ("balance margin: the capture point inside the support polygon", "m"),
                    "departure_deg" => ("departure: the most the balance turned a joint from the trajectory", "°"),
                    FEET_AGREEING => {
                        ("feet: how many touch the ground exactly when the trajectory stands on them", "feet")
                    }
                    "assist_force_n" => ("assistance: the push on the pelvis", "N"),
                    _ => ("assistance: the torque turning the pelvis", "N·m"),
                };
                let points = self
                    .time_s
                    .iter()
                    .zip(values)
                    .filter_map(|(&t, v)| v.map(|v| Point { size: 0.0, ..Point::new(t, v) }))
                    .collect();
                let series = vec![Series { name: String::new(), color: 0, style: Style::Line, points }];
                Chart::fitted(title, "time (s)", unit, series)
            })
            .collect();
        (!panels.is_empty()).then(|| Figure::new(width, 180, panels))
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
