//! Fitting a primitive to its segments: PCA latent space (eq. 3) of the
//! pooled poses, latent velocities for the gradient field (eq. 2), speed
//! statistics, and each pose's phase along its segment.

use super::field::Field;
use super::hyperparams::ValidFitParams;
use super::model::{Primitive, Source, SpeedStats};
use crate::mocap::body::{DOF, JointVector};
use crate::mocap::pose::Motion;
use crate::vocab::pca::principal_components;
use crate::vocab::phase::{ArcPath, CycleTemplate};
use crate::vocab::segment::Span;
use rayon::prelude::*;

/// One segment of a primitive's training motion.
#[derive(Clone, Copy, Debug)]
pub struct TrainingSegment<'a> {
    pub motion: &'a Motion,
    pub span: Span,
    /// For a whole cycle, its registered start (see
    /// [`crate::vocab::phase`]); phase is counted from there.
    pub phase_offset: Option<f64>,
    pub file: &'a str,
    pub label: Option<&'a str>,
}

#[derive(Debug, thiserror::Error)]
pub enum FitError {
    #[error("primitive {0} has no segments")]
    NoSegments(String),
    #[error("primitive {0}'s poses do not vary: there is no motion to model")]
    Motionless(String),
    #[error("primitive {name}: {problem}")]
    Numeric { name: String, problem: String },
}

/// The pooled training frames of a primitive.
struct Frames {
    poses: Vec<JointVector>,
    /// Displacement to the next frame, per second.
    velocities: Vec<JointVector>,
    phases: Vec<f64>,
}

fn gather(segments: &[TrainingSegment]) -> Frames {
    let n: usize = segments.iter().map(|s| s.span.frames()).sum();
    // Phase is counted from each cycle's start as registered against the
    // primitive's other cycles; partial swings are placed on the mean
    // cycle. Without cycles, phase runs from 0 to 1 along each segment.
    let cycles: Vec<(&Motion, Span, f64)> =
        segments.iter().filter_map(|s| s.phase_offset.map(|o| (s.motion, s.span, o))).collect();
    let template = CycleTemplate::fit(&cycles);
    let mut aligned = template.as_ref().map(|t| t.offsets.iter().copied());
    let mut frames =
        Frames { poses: Vec::with_capacity(n), velocities: Vec::with_capacity(n), phases: Vec::with_capacity(n) };
    for s in segments {
        let poses = &s.motion.poses;
        let last_frame = poses.len() - 1;
        let path = ArcPath::new(s.motion, s.span);
        // Phase = start + share × fraction along the path.
        let (start, share) = match (&template, s.phase_offset) {
            (Some(_), Some(_)) => (-aligned.as_mut().and_then(Iterator::next).expect("one per cycle"), 1.0),
            (Some(t), None) => t.place(s.motion, s.span),
            (None, _) => (0.0, 1.0),
        };
        for t in s.span.first..=s.span.last {
            // The next frame of the take (the previous one at its very end).
            let (a, b) = if t < last_frame { (t, t + 1) } else { (t - 1, t) };
            let mut v = [0.0; DOF];
            for (k, vk) in v.iter_mut().enumerate() {
                *vk = (poses[b].x[k] - poses[a].x[k]) / s.motion.frame_time_s;
            }
            frames.poses.push(poses[t].x);
            frames.velocities.push(v);
            let along = path.fraction_at_frame(t);
            frames.phases.push((start + share * along).rem_euclid(1.0));
        }
    }
    frames
}

impl ValidFitParams {
    /// Fits primitive `name` to its segments.
    pub fn fit(&self, name: &str, segments: &[TrainingSegment]) -> Result<Primitive, FitError> {
        let p = self.params();
        if segments.is_empty() {
            return Err(FitError::NoSegments(name.to_string()));
        }
        let frames = gather(segments);
        let (mean, eigenvalues, eigenvectors) = principal_components(&frames.poses);
        let total: f64 = eigenvalues.iter().sum();
        if total <= 1e-18 {
            return Err(FitError::Motionless(name.to_string()));
        }
        // The smallest dimension keeping the asked share of variance.
        let mut kept = 0.0;
        let mut dims = DOF;
        for (i, &value) in eigenvalues.iter().enumerate() {
            kept += value;
            if kept >= p.variance * total {
                dims = i + 1;
                break;
            }
        }
        let dims = dims.clamp(p.min_dims, p.max_dims);
        let basis: Vec<JointVector> = eigenvectors[..dims].to_vec();
        let variances = eigenvalues[..dims].to_vec();
        let variance_kept = variances.iter().sum::<f64>() / total;

        let project = |x: &JointVector, centre: bool| -> Vec<f64> {
            basis
                .iter()
                .map(|row| (0..DOF).map(|k| row[k] * (x[k] - if centre { mean[k] } else { 0.0 })).sum())
                .collect()
        };
        let points: Vec<f64> = frames.poses.par_iter().flat_map_iter(|x| project(x, true)).collect();
        let velocities: Vec<f64> = frames.velocities.par_iter().flat_map_iter(|v| project(v, false)).collect();
        let speeds: Vec<f64> =
            velocities.chunks_exact(dims).map(|v| v.iter().map(|c| c * c).sum::<f64>().sqrt()).collect();
        let speed = SpeedStats::of(&speeds);
        let field = Field::new(dims, points, velocities, frames.phases, p.neighbors).ok_or_else(|| {
            FitError::Numeric { name: name.to_string(), problem: "training poses are not finite".into() }
        })?;
        let sources = segments
            .iter()
            .map(|s| Source {
                file: s.file.to_string(),
                first_frame: s.span.first,
                last_frame: s.span.last,
                label: s.label.map(str::to_string),
            })
            .collect();
        Ok(Primitive { name: name.to_string(), mean, basis, variances, variance_kept, field, speed, sources })
    }

    /// The gradient field of the segments in joint space, for checking that
    /// latent directions agree with joint-space ones (eq. 5).
    pub fn joint_field(&self, name: &str, segments: &[TrainingSegment]) -> Result<Field, FitError> {
        let frames = gather(segments);
        let flat = |rows: &[JointVector]| rows.iter().flatten().copied().collect::<Vec<f64>>();
        Field::new(DOF, flat(&frames.poses), flat(&frames.velocities), frames.phases, self.params().neighbors)
            .ok_or_else(|| FitError::Numeric { name: name.to_string(), problem: "no finite training poses".into() })
    }
}

#[cfg(test)]
mod tests {
    use super::super::hyperparams::FitParams;
    use super::*;
    use crate::mocap::synth::{Activity, SynthOptions, activity_take};
    use crate::params::Params;

    fn segments_of(motion: &Motion) -> Vec<TrainingSegment<'_>> {
        // Whole repetitions are not needed here: fixed windows will do.
        (0..motion.poses.len() / 30)
            .map(|i| TrainingSegment {
                motion,
                span: Span { first: 30 * i, last: 30 * i + 29 },
                phase_offset: None,
                file: "take.bvh",
                label: None,
            })
            .collect()
    }

    #[test]
    fn pca_keeps_the_asked_variance_in_the_fewest_dimensions() {
        let take = activity_take(Activity::Circles, &SynthOptions::default());
        let segments = segments_of(&take.motion);
        let params = FitParams::new().variance(0.95).min_dims(1).max_dims(12).check().unwrap();
        let fitted = params.fit("circles", &segments).unwrap();
        assert!(fitted.variance_kept() >= 0.95, "{}", fitted.variance_kept());
        let one_fewer: f64 = fitted.variances()[..fitted.dims() - 1].iter().sum::<f64>()
            / fitted.variances().iter().sum::<f64>()
            * fitted.variance_kept();
        assert!(one_fewer < 0.95, "{} dimensions where fewer keep {one_fewer}", fitted.dims());
        // The floor holds even where fewer dimensions keep enough.
        let floored = FitParams::new().variance(0.5).min_dims(5).check().unwrap().fit("circles", &segments).unwrap();
        assert_eq!(floored.dims(), 5);
        // The basis is orthonormal.
        for (i, a) in fitted.basis().iter().enumerate() {
            for (j, b) in fitted.basis().iter().enumerate() {
                let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
                assert!((dot - if i == j { 1.0 } else { 0.0 }).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn projecting_and_reconstructing_a_training_pose_loses_only_the_discarded_variance() {
        let take = activity_take(Activity::WaveH, &SynthOptions::default());
        let segments = segments_of(&take.motion);
        let full = FitParams::new().variance(1.0).max_dims(12).check().unwrap().fit("w", &segments).unwrap();
        let x = take.motion.poses[60].x;
        let back = full.reconstruct(&full.project(&x));
        let error: f64 = x.iter().zip(&back).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
        assert!(error < 0.02, "reconstruction error {error}");
    }

    #[test]
    fn motionless_segments_are_an_error() {
        let mut take = activity_take(Activity::WaveH, &SynthOptions::default()).motion;
        let still = take.poses[0];
        take.poses.iter_mut().for_each(|p| *p = still);
        let err = FitParams::new().check().unwrap().fit("still", &segments_of(&take)).unwrap_err();
        assert_eq!(err.to_string(), "primitive still's poses do not vary: there is no motion to model");
    }
}
