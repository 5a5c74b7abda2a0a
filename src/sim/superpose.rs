//! Imitation by the primitives themselves (`execute --primitives`): the
//! humanoid's target at each frame is the superposition of the primitives'
//! predictions (eq. 1), each primitive's gradient field carrying the pose
//! one frame on (eq. 2), weighted by how strongly the run recognized it
//! (the "mirror neurons' firing", eq. 7 or 10), rather than the pose the
//! tracker arbitrated.
//!
//! Each frame, the imitation's own pose of the frame before is projected
//! into every primitive's latent space (eq. 3) and carried one frame along
//! its field, at the latent pace the person was seen moving at over the
//! frame before (its median training pace at the start); the superposed
//! pose moves by the weighted sum of those moves, then `SEEN_SHARE` of the
//! way to the run's estimate of the frame before, so it neither drifts
//! off what was seen nor copies the estimate's frame-to-frame noise.
//! Nothing comes from the frame being predicted. Measured on the demo's
//! run (`execute --primitives --truth`): the jerk 0.52× the trajectory
//! played's standing, the upper body's root-relative error against the
//! truth 23.1 mm (the trajectory played: 30.0 mm), on a fixed base 15.6 mm
//! (14.0 mm).
//! Moving by the primitives from the estimate with no pull toward it (an
//! earlier version, which also measured the pace between the imitation and
//! the estimate) left the jerk 1.3× the trajectory's.

use super::execute::{ExecuteError, Execution, Playback, PrimitivesImitation, ValidExecuteParams, execute};
use crate::mocap::body::JointVector;
use crate::mocap::pose::{Motion, Pose};
use crate::report::metrics::{ReportError, motion_error_mm};
use crate::report::read_track;
use crate::report::run::Run;
use crate::vocab::vocabulary::{VocabError, Vocabulary};
use std::path::{Path, PathBuf};

/// How far each frame's superposed pose is drawn toward the run's estimate.
const SEEN_SHARE: f64 = 0.5;

/// A trajectory re-made by the primitives.
#[derive(Clone, Debug)]
pub struct Superposed {
    pub motion: Motion,
    /// Frames whose pose the primitives made; the others (the first, and
    /// frames after one without recognition) keep the trajectory's pose.
    pub superposed_frames: usize,
    pub kept_frames: usize,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SuperposeError {
    #[error("the run's primitives are {run:?}, the vocabulary's {vocabulary:?}: a run of another vocabulary")]
    Primitives { run: Vec<String>, vocabulary: Vec<String> },
    #[error("the run has {run} frames of probabilities, the trajectory {trajectory} frames")]
    Frames { run: usize, trajectory: usize },
}

/// `trajectory` (the run's estimate) with every frame after the first made
/// by `vocabulary`'s primitives weighted by `probabilities` (per
/// primitive, named by `names` in the vocabulary's order, one value per
/// frame, `None` where the run recognized nothing; a frame after one
/// without recognition keeps the estimate).
pub fn superpose(
    trajectory: &Motion,
    vocabulary: &Vocabulary,
    names: &[&str],
    probabilities: &[Vec<Option<f64>>],
) -> Result<Superposed, SuperposeError> {
    let primitives = vocabulary.primitives();
    if names.len() != primitives.len() || names.iter().zip(primitives).any(|(n, p)| *n != p.name()) {
        return Err(SuperposeError::Primitives {
            run: names.iter().map(|n| n.to_string()).collect(),
            vocabulary: primitives.iter().map(|p| p.name().to_string()).collect(),
        });
    }
    let frames = trajectory.poses.len();
    if let Some(wrong) = probabilities.iter().find(|p| p.len() != frames) {
        return Err(SuperposeError::Frames { run: wrong.len(), trajectory: frames });
    }
    let dt = trajectory.frame_time_s;
    let mut poses = trajectory.poses.clone();
    let mut superposed_frames = 0;
    for k in 1..frames {
        let weights: Vec<f64> = probabilities.iter().map(|p| p[k - 1].unwrap_or(0.0).max(0.0)).collect();
        let total: f64 = weights.iter().sum();
        if total <= 0.0 {
            continue;
        }
        let mut x: JointVector = poses[k - 1].x;
        for (primitive, &w) in primitives.iter().zip(&weights).filter(|(_, w)| **w > 0.0) {
            let at = primitive.project(&poses[k - 1].x);
            // The pace the person was seen moving at, in this primitive's
            // latent space.
            let pace = (k >= 2).then(|| {
                let [seen, before] = [k - 1, k - 2].map(|f| primitive.project(&trajectory.poses[f].x));
                seen.iter().zip(&before).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt() / dt
            });
            let Some(next) = primitive.predict(&at, 1, dt, pace).pop() else { continue };
            let (from, to) = (primitive.reconstruct(&at), primitive.reconstruct(&next));
            for ((sum, a), b) in x.iter_mut().zip(from).zip(to) {
                *sum += w / total * (b - a);
            }
        }
        for (z, seen) in x.iter_mut().zip(&trajectory.poses[k - 1].x) {
            *z += SEEN_SHARE * (seen - *z);
        }
        let asked = &trajectory.poses[k];
        poses[k] = Pose { root: asked.root, heading: asked.heading, x };
        superposed_frames += 1;
    }
    Ok(Superposed {
        motion: Motion { body: trajectory.body.clone(), frame_time_s: dt, poses },
        superposed_frames,
        kept_frames: frames - superposed_frames,
    })
}

/// Why a run could not be imitated by its primitives.
#[derive(Debug, thiserror::Error)]
pub enum ImitateError {
    #[error(transparent)]
    Report(#[from] ReportError),
    #[error("{summary}: a --baseline run recognizes no primitives, so none can imitate it")]
    Baseline { summary: String },
    #[error("{summary} names the vocabulary {vocabulary}, which cannot be read: {source}")]
    Vocabulary { summary: String, vocabulary: String, source: VocabError },
    #[error(
        "{summary}: the run was tracked with a vocabulary of checksum {tracked}, but {vocabulary} is {found} now: \
         a run of another vocabulary"
    )]
    Checksum { summary: String, vocabulary: String, tracked: String, found: String },
    #[error("{run} against {vocabulary}: {source}")]
    Superpose { run: String, vocabulary: String, source: SuperposeError },
    #[error("{truth}: {frames} frames, but the run has {run}")]
    Truth { truth: String, frames: usize, run: usize },
    #[error("{input}: {source}")]
    Execute { input: String, source: ExecuteError },
}

/// `execute --primitives`: the run in `run_dir` (its `trajectory` already
/// read) re-made by its vocabulary's primitives and played with `params`,
/// its summary's `primitives` block setting it beside the trajectory
/// played as it is, both scored against `truth` (a truth.csv) when given.
/// `progress` hears of every frame of both.
pub fn imitate_run(
    run_dir: &Path,
    trajectory: &Motion,
    truth: Option<&Path>,
    params: &ValidExecuteParams,
    mut progress: impl FnMut(),
) -> Result<Execution, ImitateError> {
    let run = Run::read(run_dir)?;
    let summary = run_dir.join("summary.json").display().to_string();
    if run.summary.baseline.is_some() {
        return Err(ImitateError::Baseline { summary });
    }
    let vocab_path = PathBuf::from(&run.summary.vocabulary.path);
    let vocab_name = vocab_path.display().to_string();
    let vocabulary = Vocabulary::load(&vocab_path).map_err(|source| ImitateError::Vocabulary {
        summary: summary.clone(),
        vocabulary: vocab_name.clone(),
        source,
    })?;
    if let (Some(tracked), Some(found)) = (&run.summary.vocabulary.checksum, vocabulary.checksum())
        && *tracked != format!("{found:08x}")
    {
        let (tracked, found) = (tracked.clone(), format!("{found:08x}"));
        return Err(ImitateError::Checksum { summary, vocabulary: vocab_name, tracked, found });
    }
    let truth_track = truth.map(read_track).transpose()?;
    let probabilities: Vec<Vec<Option<f64>>> = run.probabilities.iter().map(|(_, p)| p.clone()).collect();
    let superposed = superpose(trajectory, &vocabulary, &run.names(), &probabilities).map_err(|source| {
        ImitateError::Superpose { run: run_dir.display().to_string(), vocabulary: vocab_name.clone(), source }
    })?;
    let input = run_dir.join("trajectory.bvh").display().to_string();
    let failed = |source| ImitateError::Execute { input: input.clone(), source };
    let played = execute(trajectory, params, &mut progress).map_err(failed)?;
    let mut imitated = execute(&superposed.motion, params, &mut progress).map_err(failed)?;
    let error_mm = |execution: &Execution| {
        let Some(truth) = &truth_track else { return Ok(None) };
        let done = execution.motion();
        let frames = (truth.joints.len(), done.poses.len());
        let mm = motion_error_mm(&done, truth, 1);
        mm.map(Some).ok_or(ImitateError::Truth { truth: truth.file.clone(), frames: frames.0, run: frames.1 })
    };
    imitated.summary.primitives = Some(PrimitivesImitation {
        run: run_dir.display().to_string(),
        vocabulary: vocab_name,
        superposed_frames: superposed.superposed_frames,
        kept_frames: superposed.kept_frames,
        rms_error_from_trajectory_deg: imitated.rms_error_against_deg(trajectory),
        truth: truth.map(|p| p.display().to_string()),
        upper_body_error_mm: error_mm(&imitated)?,
        trajectory_playback: Playback {
            rms_error_deg: played.summary.rms_error_deg,
            jerk_rms_m_s3: played.summary.jerk_rms_m_s3,
            upper_body_error_mm: error_mm(&played)?,
            fell_at_s: played.summary.fell_at_s,
        },
    });
    Ok(imitated)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Body;
    use std::path::Path;

    fn shipped() -> Vocabulary {
        Vocabulary::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("vocab/default.vocab")).unwrap()
    }

    fn still(frames: usize) -> Motion {
        let body = Body::standard();
        Motion { poses: vec![Pose::rest(&body); frames], body, frame_time_s: 1.0 / 30.0 }
    }

    #[test]
    fn another_vocabulary_or_another_length_is_refused_and_no_recognition_keeps_the_trajectory() {
        let vocabulary = shipped();
        let names: Vec<&str> = vocabulary.primitives().iter().map(|p| p.name()).collect();
        let motion = still(5);
        let wrong = superpose(&motion, &vocabulary, &names[1..], &vec![vec![None; 5]; names.len() - 1]);
        assert!(matches!(wrong, Err(SuperposeError::Primitives { .. })), "{wrong:?}");
        let short = superpose(&motion, &vocabulary, &names, &vec![vec![None; 4]; names.len()]);
        assert_eq!(short.unwrap_err(), SuperposeError::Frames { run: 4, trajectory: 5 });
        let none = superpose(&motion, &vocabulary, &names, &vec![vec![None; 5]; names.len()]).unwrap();
        assert_eq!((none.superposed_frames, none.kept_frames), (0, 5));
        assert_eq!(none.motion.poses, motion.poses);
        // Recognized throughout, every frame but the first is the primitives'.
        let all = superpose(&motion, &vocabulary, &names, &vec![vec![Some(1.0); 5]; names.len()]).unwrap();
        assert_eq!((all.superposed_frames, all.kept_frames), (4, 1));
        assert!(all.motion.poses.iter().flat_map(|p| p.x).all(f64::is_finite));
    }
}
