//! The primitive the tracker consumes: project poses into its latent space
//! and back, follow its gradient field, predict ahead, read progress.

use super::field::Field;
use crate::mocap::body::{DOF, JointVector};

/// Where a primitive's training motion came from.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Source {
    pub file: String,
    pub first_frame: usize,
    pub last_frame: usize,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

/// Distribution of latent speed (latent units per second) over the
/// training frames.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpeedStats {
    pub mean: f64,
    pub median: f64,
    pub p10: f64,
    pub p90: f64,
}

impl SpeedStats {
    /// Statistics of `speeds` (not empty).
    pub fn of(speeds: &[f64]) -> SpeedStats {
        let mut sorted = speeds.to_vec();
        sorted.sort_by(f64::total_cmp);
        let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        SpeedStats {
            mean: sorted.iter().sum::<f64>() / sorted.len() as f64,
            median: at(0.5),
            p10: at(0.1),
            p90: at(0.9),
        }
    }
}

/// One learned primitive.
#[derive(Debug)]
pub struct Primitive {
    pub(crate) name: String,
    pub(crate) mean: JointVector,
    /// Orthonormal rows spanning the latent space (`A` of eq. 3).
    pub(crate) basis: Vec<JointVector>,
    /// Pose variance along each basis row.
    pub(crate) variances: Vec<f64>,
    /// Share of the pose variance the basis keeps.
    pub(crate) variance_kept: f64,
    pub(crate) field: Field,
    pub(crate) speed: SpeedStats,
    pub(crate) sources: Vec<Source>,
}

impl Primitive {
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The latent dimension `d`.
    pub fn dims(&self) -> usize {
        self.basis.len()
    }

    pub fn mean(&self) -> &JointVector {
        &self.mean
    }

    pub fn basis(&self) -> &[JointVector] {
        &self.basis
    }

    pub fn variances(&self) -> &[f64] {
        &self.variances
    }

    pub fn variance_kept(&self) -> f64 {
        self.variance_kept
    }

    pub fn speed(&self) -> &SpeedStats {
        &self.speed
    }

    pub fn sources(&self) -> &[Source] {
        &self.sources
    }

    /// The activity label most of its training segments carry (ties to the
    /// first in name order), or `None` when none is labelled: what a
    /// recognition of this primitive is scored as.
    pub fn majority_label(&self) -> Option<&str> {
        let mut counts = std::collections::BTreeMap::<&str, usize>::new();
        for label in self.sources.iter().filter_map(|s| s.label.as_deref()) {
            *counts.entry(label).or_default() += 1;
        }
        counts
            .into_iter()
            .fold(None, |best: Option<(&str, usize)>, (l, n)| match best {
                Some((_, m)) if m >= n => best,
                _ => Some((l, n)),
            })
            .map(|(l, _)| l)
    }

    /// The training poses in latent space, their latent velocities (per
    /// second) and phases.
    pub fn field(&self) -> &Field {
        &self.field
    }

    pub fn training_frames(&self) -> usize {
        self.field.len()
    }

    /// `y = A (x − μ)` (eq. 3), written into `out` (length `dims`).
    pub fn project_into(&self, x: &JointVector, out: &mut [f64]) {
        for (o, row) in out.iter_mut().zip(&self.basis) {
            *o = (0..DOF).map(|k| row[k] * (x[k] - self.mean[k])).sum();
        }
    }

    pub fn project(&self, x: &JointVector) -> Vec<f64> {
        let mut y = vec![0.0; self.dims()];
        self.project_into(x, &mut y);
        y
    }

    /// `x = μ + Aᵀ y`: the joint-space pose of latent point `y`.
    pub fn reconstruct(&self, y: &[f64]) -> JointVector {
        let mut x = self.mean;
        for (c, row) in y.iter().zip(&self.basis) {
            for k in 0..DOF {
                x[k] += c * row[k];
            }
        }
        x
    }

    /// The gradient field's unit direction at latent point `y` (eq. 2);
    /// `None` where the nearby training motion cancels out.
    pub fn direction(&self, y: &[f64]) -> Option<Vec<f64>> {
        let mut d = vec![0.0; self.dims()];
        self.field.direction(y, &mut d).then_some(d)
    }

    /// `steps` predictions from `y`, each `speed × dt` along the field from
    /// the last (eq. 2 iterated: the curved axis of the bending cone).
    /// `speed` defaults to the primitive's median speed. Stops early where
    /// the field vanishes.
    pub fn predict(&self, y: &[f64], steps: usize, dt: f64, speed: Option<f64>) -> Vec<Vec<f64>> {
        let step = speed.unwrap_or(self.speed.median) * dt;
        let mut out = Vec::with_capacity(steps);
        let mut at = y.to_vec();
        let mut d = vec![0.0; self.dims()];
        for _ in 0..steps {
            if !self.field.direction(&at, &mut d) {
                break;
            }
            for (a, v) in at.iter_mut().zip(&d) {
                *a += step * v;
            }
            out.push(at.clone());
        }
        out
    }

    /// Attractor progress of latent point `y`, in [0, 1).
    pub fn progress(&self, y: &[f64]) -> f64 {
        self.field.phase(y)
    }
}
