//! A gradient field over training points (paper eq. 2): at any point, the
//! normalized, distance-weighted sum of the displacements of its nearest
//! training points; and, with the same weights, their phase.

use crate::vocab::knn::KnnIndex;
use std::f64::consts::TAU;

/// Training points with their velocities and phases, indexed for search.
#[derive(Debug)]
pub struct Field {
    dims: usize,
    points: Vec<f64>,
    velocities: Vec<f64>,
    phases: Vec<f64>,
    neighbors: usize,
    index: KnnIndex,
}

impl Field {
    /// Row-major points and velocities (`n × dims`), one phase each.
    /// `None` when they are empty, of mismatched sizes, not finite, or of a
    /// dimension the index does not support.
    pub fn new(
        dims: usize,
        points: Vec<f64>,
        velocities: Vec<f64>,
        phases: Vec<f64>,
        neighbors: usize,
    ) -> Option<Field> {
        if points.len() != velocities.len() || points.len() != phases.len() * dims || neighbors == 0 {
            return None;
        }
        if velocities.iter().chain(&phases).any(|v| !v.is_finite()) {
            return None;
        }
        let index = KnnIndex::new(&points, dims)?;
        Some(Field { dims, points, velocities, phases, neighbors, index })
    }

    pub fn dims(&self) -> usize {
        self.dims
    }

    pub fn len(&self) -> usize {
        self.phases.len()
    }

    pub fn is_empty(&self) -> bool {
        self.phases.is_empty()
    }

    pub fn neighbors(&self) -> usize {
        self.neighbors
    }

    pub fn points(&self) -> &[f64] {
        &self.points
    }

    pub fn velocities(&self) -> &[f64] {
        &self.velocities
    }

    pub fn phases(&self) -> &[f64] {
        &self.phases
    }

    /// The nearest training points and their weights: a Gaussian of the
    /// distance with the k-th neighbour's distance as bandwidth, so the
    /// kernel adapts to how densely the data cover this region.
    fn weighted_neighbours(&self, query: &[f64], found: &mut Vec<(usize, f64)>) {
        self.index.nearest(query, self.neighbors, found);
        let bandwidth = found.last().map_or(1.0, |f| f.1).max(1e-12);
        for f in found.iter_mut() {
            f.1 = (-(f.1 / bandwidth).powi(2)).exp();
        }
    }

    /// The distance from `query` to the nearest training point: how far
    /// off the primitive's manifold it lies.
    pub fn distance_to_data(&self, query: &[f64], scratch: &mut Vec<(usize, f64)>) -> f64 {
        self.index.nearest(query, 1, scratch);
        scratch.first().map_or(f64::INFINITY, |f| f.1)
    }

    /// The field's unit direction at `query` (eq. 2), written into `out`;
    /// false where the neighbours' displacements cancel out.
    pub fn direction(&self, query: &[f64], out: &mut [f64]) -> bool {
        let mut found = Vec::with_capacity(self.neighbors);
        self.weighted_neighbours(query, &mut found);
        out.fill(0.0);
        for &(i, w) in &found {
            for (o, v) in out.iter_mut().zip(self.velocity(i)) {
                *o += w * v;
            }
        }
        let norm = out.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm < 1e-300 {
            return false;
        }
        out.iter_mut().for_each(|o| *o /= norm);
        true
    }

    /// Attractor progress at `query`: the weighted mean of the neighbours'
    /// phases in [0, 1), taken on the circle, because a segment ends close
    /// to where the next one starts, and 0.98 and 0.02 should average to 0,
    /// not 0.5. Each neighbour's weight is scaled by how well its motion
    /// agrees with the field's direction here, so where two parts of a
    /// cycle pass close to each other in opposite directions (the way up
    /// and the way down of a wave), the part moving the way the field
    /// moves decides.
    pub fn phase(&self, query: &[f64]) -> f64 {
        let mut found = Vec::with_capacity(self.neighbors);
        self.weighted_neighbours(query, &mut found);
        let mut flow = vec![0.0; self.dims];
        for &(i, w) in &found {
            flow.iter_mut().zip(self.velocity(i)).for_each(|(f, v)| *f += w * v);
        }
        let agreement = |i: usize| -> f64 {
            let v = self.velocity(i);
            let dot: f64 = v.iter().zip(&flow).map(|(a, b)| a * b).sum();
            let norms = v.iter().map(|a| a * a).sum::<f64>().sqrt() * flow.iter().map(|a| a * a).sum::<f64>().sqrt();
            if norms > 0.0 { (dot / norms).max(0.0) } else { 0.0 }
        };
        let circular_mean = |weight: &dyn Fn(usize, f64) -> f64| {
            let (mut s, mut c) = (0.0, 0.0);
            for &(i, w) in &found {
                let (sin, cos) = (TAU * self.phases[i]).sin_cos();
                s += weight(i, w) * sin;
                c += weight(i, w) * cos;
            }
            (s, c)
        };
        let (mut s, mut c) = circular_mean(&|i, w| w * agreement(i));
        if s == 0.0 && c == 0.0 {
            // No neighbour moves (or the field vanishes): plain weights.
            (s, c) = circular_mean(&|_, w| w);
        }
        (s.atan2(c) / TAU).rem_euclid(1.0)
    }

    fn velocity(&self, i: usize) -> &[f64] {
        &self.velocities[i * self.dims..(i + 1) * self.dims]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points around the unit circle moving counter-clockwise.
    fn circle() -> Field {
        let n = 200;
        let (mut points, mut velocities, mut phases) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..n {
            let a = TAU * i as f64 / n as f64;
            points.extend([a.cos(), a.sin()]);
            velocities.extend([-a.sin(), a.cos()]);
            phases.push(i as f64 / n as f64);
        }
        Field::new(2, points, velocities, phases, 6).unwrap()
    }

    #[test]
    fn the_direction_follows_the_flow_of_the_training_data() {
        let field = circle();
        let mut d = [0.0; 2];
        for a in [0.1f64, 1.0, 2.5, 4.0] {
            assert!(field.direction(&[1.1 * a.cos(), 1.1 * a.sin()], &mut d));
            let tangent = [-a.sin(), a.cos()];
            assert!(d[0] * tangent[0] + d[1] * tangent[1] > 0.99, "{a}: {d:?}");
        }
    }

    #[test]
    fn progress_rises_around_the_circle_and_wraps_cleanly() {
        let field = circle();
        for (a, expected) in [(0.5f64, 0.5 / TAU), (3.0, 3.0 / TAU)] {
            assert!((field.phase(&[a.cos(), a.sin()]) - expected).abs() < 0.01);
        }
        // At the seam, neighbours at 0.99 and 0.01 average to 0 (mod 1).
        let seam = field.phase(&[1.0, 0.0]);
        assert!(!(0.01..=0.99).contains(&seam), "{seam}");
    }

    #[test]
    fn mismatched_or_non_finite_training_data_is_refused() {
        assert!(Field::new(2, vec![0.0; 4], vec![0.0; 2], vec![0.0; 2], 3).is_none());
        assert!(Field::new(1, vec![0.0], vec![f64::NAN], vec![0.0], 3).is_none());
        assert!(Field::new(1, vec![0.0], vec![1.0], vec![0.0], 0).is_none());
    }
}
