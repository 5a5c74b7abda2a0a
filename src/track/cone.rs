//! The bending cone (eq. 6, Figure 4): the motion model of a primitive's
//! particle filter.
//!
//! From a particle `y`, the primitive's gradient field is followed `K`
//! steps of one frame's typical displacement, giving a curved axis
//! `ŷ[0] = y, ŷ[1], …, ŷ[K]`. A sample picks a step `k` in `0..K` at random,
//! a point uniformly between `ŷ[k]` and `ŷ[k+1]`, and adds Gaussian noise
//! across that piece of the axis whose spread grows linearly with `k`. So a
//! particle may keep pace with the typical speed or run up to `K` times
//! ahead, along the manifold rather than off its tangent: fast motion, or
//! frames missed, stay on the primitive. `K = 1` is the straight-line
//! model (one step along the local flow).

use crate::vocab::primitive::Primitive;
use rand::Rng;
use rand_distr::StandardNormal;

/// Settings of the bending cone.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Cone {
    /// `K`: predictions along the field, each one frame's typical step.
    pub lookahead: usize,
    /// Noise across the axis at step `k`: `spread × step × (k + 1)`,
    /// `step` being one frame's typical latent displacement.
    pub spread: f64,
}

/// Scratch space for sampling, reused across particles.
#[derive(Clone, Debug, Default)]
pub struct ConeScratch {
    axis: Vec<f64>,
    direction: Vec<f64>,
}

impl Cone {
    /// Moves `y` (in place) to a sample of the cone from it. `step` is one
    /// frame's typical latent displacement of the primitive.
    pub fn sample(
        &self,
        primitive: &Primitive,
        step: f64,
        y: &mut [f64],
        rng: &mut impl Rng,
        scratch: &mut ConeScratch,
    ) {
        let d = y.len();
        let ConeScratch { axis, direction } = scratch;
        axis.clear();
        axis.extend_from_slice(y);
        direction.resize(d, 0.0);
        // The curved axis, cut short where the field vanishes.
        for k in 0..self.lookahead {
            if !primitive.field().direction(&axis[k * d..(k + 1) * d], direction) {
                break;
            }
            for i in 0..d {
                axis.push(axis[k * d + i] + step * direction[i]);
            }
        }
        let pieces = axis.len() / d - 1;
        if pieces == 0 {
            // No flow here: the particle stays, with noise in every direction.
            for v in y.iter_mut() {
                *v += self.spread * step * rng.sample::<f64, _>(StandardNormal);
            }
            return;
        }
        let k = rng.gen_range(0..pieces);
        let along: f64 = rng.gen_range(0.0..1.0);
        let (a, b) = (&axis[k * d..(k + 1) * d], &axis[(k + 1) * d..(k + 2) * d]);
        let sigma = self.spread * step * (k + 1) as f64;
        let length = a.iter().zip(b).map(|(p, q)| (q - p) * (q - p)).sum::<f64>().sqrt();
        for v in direction.iter_mut() {
            *v = rng.sample::<f64, _>(StandardNormal) * sigma;
        }
        if length > 0.0 {
            // Keep the noise across the axis: the position along it is
            // already drawn.
            let along_noise: f64 = (0..d).map(|i| direction[i] * (b[i] - a[i])).sum::<f64>() / length;
            for i in 0..d {
                direction[i] -= along_noise * (b[i] - a[i]) / length;
            }
        }
        for i in 0..d {
            y[i] = a[i] + along * (b[i] - a[i]) + direction[i];
        }
    }
}
