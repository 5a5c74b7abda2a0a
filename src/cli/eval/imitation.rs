//! `imitate eval`'s imitation table: takes played on the simulated
//! humanoid on a stand, on the ground and on the ground assisted, and the
//! tracked run of trial one imitated by its primitives (eq. 1) beside its
//! trajectory played as it is.

use super::Work;
use anyhow::Context;
use imitate::mocap::retarget::RetargetOptions;
use imitate::params::Params;
use imitate::report::eval::Table;
use imitate::sim::execute::{ExecuteParams, Execution, Summary, ValidExecuteParams, execute, frames_to_skip};
use imitate::sim::humanoid::Base;
use imitate::sim::superpose::imitate_run;
use imitate::vocab::corpus::{Labels, read_labels};
use imitate::vocab::learn::read_take;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// A take to play: its row's name, its activity, its BVH, and where it
/// comes from.
struct Take {
    name: String,
    activity: String,
    bvh: PathBuf,
    source: Source,
}

#[derive(Clone, Copy, PartialEq)]
enum Source {
    Synthetic,
    /// Trial one's run: also imitated by its primitives.
    Tracked,
    Real,
}

/// The three ways every take is played: on a stand, on the ground, and on
/// the ground assisted.
fn settings() -> anyhow::Result<[ValidExecuteParams; 3]> {
    let standing = ExecuteParams::default();
    Ok([
        ExecuteParams { base: Base::Fixed, ..standing }.check()?,
        standing.check()?,
        ExecuteParams { assist: true, ..standing }.check()?,
    ])
}

/// Plays `synthetic` (the sequence trial one tracks), the trajectory of
/// trial one's `run` (whose truth is `truth`), also imitated by its
/// primitives, and every take `real`'s labels.csv names (when there is
/// one), each as `imitate execute` does by default.
pub(super) fn table(work: &Work, synthetic: &Path, run: &Path, truth: &Path, real: &Path) -> anyhow::Result<Table> {
    let mut takes = vec![
        Take {
            name: "synthetic sequence".into(),
            activity: "circles, wave-h, wave-v".into(),
            bvh: synthetic.into(),
            source: Source::Synthetic,
        },
        Take {
            name: "its tracked trajectory".into(),
            activity: "(tracked)".into(),
            bvh: run.join("trajectory.bvh"),
            source: Source::Tracked,
        },
    ];
    let labels = real.join("labels.csv");
    if labels.is_file() {
        let Labels::PerFile(files) = read_labels(&labels)? else {
            anyhow::bail!("{}: the real captures are labelled whole (`file,activity`)", labels.display());
        };
        for (file, activity) in files {
            takes.push(Take { bvh: real.join(&file), name: file, activity, source: Source::Real });
        }
    }
    let settings = settings()?;
    let (mut rows, mut metrics) = (Vec::new(), Vec::new());
    let (mut real_up, mut real_assisted_up, mut real_played) = (0, 0, 0);
    for take in &takes {
        work.step(&format!("imitation: {}", take.name));
        let shown = take.bvh.display().to_string();
        let (mut motion, _) = read_take(&take.bvh, None, &RetargetOptions::default(), &mut ())?;
        // A run is imitated frame for frame, as `execute --primitives` plays
        // it: nothing of its trajectory is left out.
        let asked = (take.source == Source::Tracked).then_some(0);
        let (skip, _) = frames_to_skip(&motion, asked).with_context(|| format!("{shown}: no frames"))?;
        motion.poses.drain(..skip);
        let played: Vec<Execution> = settings
            .iter()
            .map(|params| execute(&motion, params, || {}).with_context(|| shown.clone()))
            .collect::<anyhow::Result<_>>()?;
        let [fixed, ground, assisted] = [0, 1, 2].map(|i| &played[i].summary);
        if take.source == Source::Real {
            real_played += 1;
            real_up += usize::from(!ground.fell);
            real_assisted_up += usize::from(!assisted.fell);
        }
        let (push, torque) =
            assisted.assist.as_ref().map_or((f64::NAN, f64::NAN), |a| (a.mean_force_share_of_weight, a.mean_torque_nm));
        let mut row = vec![
            take.name.clone(),
            take.activity.clone(),
            format!("{:.2}", fixed.rms_error_deg),
            ground_cell(ground),
            format!("{}; push {:.1}%, torque {:.0} N·m", ground_cell(assisted), 100.0 * push, torque),
        ];
        let mut figures = json!({
            "take": take.name,
            "activity": take.activity,
            "skipped_frames": skip,
            "fixed_base": figures(fixed),
            "ground": figures(ground),
            "assisted": figures(assisted),
        });
        figures["assisted"]["mean_force_share_of_weight"] = json!(push);
        figures["assisted"]["mean_torque_nm"] = json!(torque);
        // Trial one's run, re-made by its primitives, standing.
        if take.source == Source::Tracked {
            let imitation = imitate_run(run, &motion, Some(truth), &settings[1], || {})
                .with_context(|| format!("{}: imitation by the primitives", run.display()))?;
            let block = imitation.summary.primitives.as_ref().context("an imitation names its primitives")?;
            let (mine, theirs) = (block.upper_body_error_mm, block.trajectory_playback.upper_body_error_mm);
            let (mine_jerk, theirs_jerk) = (imitation.summary.jerk_rms_m_s3, block.trajectory_playback.jerk_rms_m_s3);
            row.push(format!(
                "{:.1} against {:.1} mm; jerk {:.0} against {:.0} m/s³{}",
                mine.unwrap_or(f64::NAN),
                theirs.unwrap_or(f64::NAN),
                mine_jerk,
                theirs_jerk,
                if imitation.summary.fell { "; fell" } else { "" }
            ));
            figures["primitives"] = json!({
                "upper_body_error_mm": mine,
                "trajectory_upper_body_error_mm": theirs,
                "jerk_rms_m_s3": mine_jerk,
                "trajectory_jerk_rms_m_s3": theirs_jerk,
                "fell": imitation.summary.fell,
            });
        } else {
            row.push("—".into());
        }
        rows.push(row);
        metrics.push(figures);
    }
    let real_note = if real_played > 0 {
        format!(
            " Of the {real_played} real takes, {real_up} stay up on the ground and {real_assisted_up} assisted (walks, \
             jumps, kicks and dances included)."
        )
    } else {
        String::new()
    };
    Ok(Table {
        key: "imitation".into(),
        title: "Imitation: the takes played on the simulated humanoid".into(),
        about: format!(
            "Each take played by `imitate execute` with its defaults ({rate} Hz, a first frame that is a bind pose \
             left out, but not from the tracked run, imitated frame for frame): on a stand (fixed base), standing \
             on the ground with balance and stepping, and on the ground with \
             `--assist` (its mean push as a share of body weight and its mean torque); RMS joint error against the take's targets, \
             when it fell, and on the ground how closely the feet followed the take's own contacts (the share of \
             the feet that touched the ground exactly when the take stood on them, before any fall). Trial one's \
             run (6 particles, its first seed) is also imitated by its primitives (`--primitives --truth`, \
             standing): the upper body's root-relative error against the truth and the jerk, \
             against its trajectory played as it is.{real_note}",
            rate = ExecuteParams::DEFAULT_RATE_HZ
        ),
        columns: [
            "take",
            "activity",
            "fixed base: RMS (°)",
            "ground: RMS (°)",
            "ground, assisted: RMS (°)",
            "primitives against the trajectory played",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        metrics: metrics.into(),
    })
}

/// An execution on the ground: its RMS error, whether and when it fell,
/// and how closely its feet followed the take's contacts.
fn ground_cell(summary: &Summary) -> String {
    let feet = summary.contact_agreement.map_or(String::new(), |a| format!("; feet {:.0}%", 100.0 * a));
    match summary.fell_at_s {
        Some(t) => format!("{:.2}, fell at {t:.1} s{feet}", summary.rms_error_deg),
        None => format!("{:.2}, stayed up{feet}", summary.rms_error_deg),
    }
}

fn figures(summary: &Summary) -> Value {
    json!({
        "rms_error_deg": summary.rms_error_deg,
        "max_error_deg": summary.max_error_deg,
        "fell_at_s": summary.fell_at_s,
        "jerk_rms_m_s3": summary.jerk_rms_m_s3,
        "contact_agreement": summary.contact_agreement,
    })
}
