//! Principal components of joint-space poses, summed deterministically.

use crate::mocap::body::{DOF, JointVector};
use faer::{Mat, Side};
use rayon::prelude::*;

/// Frames per parallel chunk of the covariance sum; chunk sums are added
/// in order, so the result does not depend on scheduling.
const CHUNK: usize = 4096;

/// Mean, eigenvalues (descending) and unit eigenvectors of the poses'
/// covariance. Each eigenvector's largest component is made positive, so
/// the basis is reproducible.
pub fn principal_components(poses: &[JointVector]) -> (JointVector, Vec<f64>, Vec<JointVector>) {
    let n = poses.len() as f64;
    let sums: Vec<JointVector> = poses
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut s = [0.0; DOF];
            for x in chunk {
                for k in 0..DOF {
                    s[k] += x[k];
                }
            }
            s
        })
        .collect();
    let mut mean = [0.0; DOF];
    for s in &sums {
        for k in 0..DOF {
            mean[k] += s[k];
        }
    }
    mean.iter_mut().for_each(|m| *m /= n);
    let partial: Vec<Vec<f64>> = poses
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut c = vec![0.0; DOF * DOF];
            for x in chunk {
                let d: Vec<f64> = (0..DOF).map(|k| x[k] - mean[k]).collect();
                for a in 0..DOF {
                    for b in a..DOF {
                        c[a * DOF + b] += d[a] * d[b];
                    }
                }
            }
            c
        })
        .collect();
    let mut covariance = Mat::<f64>::zeros(DOF, DOF);
    for c in &partial {
        for a in 0..DOF {
            for b in a..DOF {
                covariance[(a, b)] += c[a * DOF + b] / n;
            }
        }
    }
    for a in 0..DOF {
        for b in 0..a {
            covariance[(a, b)] = covariance[(b, a)];
        }
    }
    let eigen = covariance.self_adjoint_eigen(Side::Lower).expect("a 43 × 43 covariance decomposes");
    let (values, vectors) = (eigen.S(), eigen.U());
    let mut order: Vec<usize> = (0..DOF).collect();
    order.reverse();
    let eigenvalues = order.iter().map(|&i| values[i].max(0.0)).collect();
    let eigenvectors = order
        .iter()
        .map(|&i| {
            let mut v = [0.0; DOF];
            for (k, vk) in v.iter_mut().enumerate() {
                *vk = vectors[(k, i)];
            }
            let largest = v.iter().copied().max_by(|a, b| a.abs().total_cmp(&b.abs())).unwrap_or(1.0);
            if largest < 0.0 {
                v.iter_mut().for_each(|c| *c = -*c);
            }
            v
        })
        .collect();
    (mean, eigenvalues, eigenvectors)
}
