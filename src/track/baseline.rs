//! The baseline the paper argues against: one annealed particle filter over
//! the full joint space and the root (Deutscher, Blake & Reid 2000), with
//! no vocabulary. Each frame diffuses the particles, then runs `layers`
//! rounds of weighting by a softened likelihood, resampling and shrinking
//! diffusion, each round's softening chosen so that about half the
//! particles survive (the paper's particle survival rate).

use crate::mocap::body::{Body, DOF, JointVector};
use crate::mocap::pose::Pose;
use crate::track::filter::systematic;
use crate::track::root::Root;
use crate::vision::camera::Camera;
use crate::vision::mask::Mask;
use crate::vision::scorer::Scorer;
use crate::vision::sighting::Sighting;
use crate::vocab::vocabulary::Vocabulary;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;

/// Settings of the annealed filter.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct AnnealParams {
    /// Particles in every layer.
    pub particles: usize,
    /// Annealing layers per frame.
    pub layers: usize,
    /// Diffusion per frame before the first layer: radians per joint
    /// angle, meters of root position, radians of heading.
    pub angle_rad: f64,
    pub move_m: f64,
    pub turn_rad: f64,
    /// Each layer's diffusion is this share of the last one's.
    pub shrink: f64,
    /// Share of particles each layer should keep (Deutscher's α = 0.5).
    pub survival: f64,
}

impl AnnealParams {
    /// Settings that spend `budget` likelihood evaluations per frame. The
    /// diffusion is the best of a grid (0.03, 0.07, 0.15 rad × 0.01, 0.03
    /// m) on the documented three-activity sequence: wider steps lose the
    /// arms in 43 dimensions.
    pub fn with_budget(budget: usize) -> AnnealParams {
        const LAYERS: usize = 5;
        AnnealParams {
            particles: (budget / LAYERS).max(1),
            layers: LAYERS,
            angle_rad: 0.03,
            move_m: 0.01,
            turn_rad: 0.05,
            shrink: 0.6,
            survival: 0.5,
        }
    }

    pub fn evaluations_per_frame(&self) -> usize {
        self.particles * self.layers
    }
}

/// The mean of every training pose of `vocabulary`: where the baseline
/// starts. The canonical rest pose holds the arms out (a T-pose), which no
/// tracked person stands in; this gives the baseline the same knowledge of
/// ordinary poses the primitives have, and nothing of their dynamics.
pub fn mean_training_pose(vocabulary: &Vocabulary) -> JointVector {
    let mut mean = [0.0; DOF];
    let mut count = 0usize;
    for primitive in vocabulary.primitives() {
        for y in primitive.field().points().chunks_exact(primitive.dims()) {
            mean.iter_mut().zip(primitive.reconstruct(y)).for_each(|(m, v)| *m += v);
            count += 1;
        }
    }
    mean.iter_mut().for_each(|m| *m /= count.max(1) as f64);
    mean
}

/// One annealed filter over `(x, y, z, θ, joint angles)`.
pub struct FullSpaceFilter {
    params: AnnealParams,
    camera: Camera,
    body: Body,
    particles: Vec<Pose>,
    /// One per worker thread.
    scorers: Vec<Scorer>,
    estimate: Pose,
    rng: ChaCha8Rng,
    /// Likelihood evaluations made so far.
    evaluations: u64,
}

impl FullSpaceFilter {
    /// A filter whose particles start at the joint angles `start`.
    pub fn new(camera: Camera, params: AnnealParams, start: JointVector, seed: u64) -> FullSpaceFilter {
        let body = Body::standard();
        let look_at = DVec3::from_array(camera.spec().look_at);
        let estimate = Pose { root: DVec3::new(look_at.x, body.pelvis_height(), look_at.z), heading: 0.0, x: start };
        let scorers = (0..rayon::current_num_threads()).map(|_| Scorer::new(camera.clone(), body.clone())).collect();
        FullSpaceFilter {
            params,
            camera,
            body,
            particles: Vec::new(),
            scorers,
            estimate,
            rng: ChaCha8Rng::seed_from_u64(seed),
            evaluations: 0,
        }
    }

    pub fn body(&self) -> &Body {
        &self.body
    }

    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// One frame: the estimated pose. Until the person first shows, and on
    /// frames without a silhouette, the estimate stays where it was.
    pub fn step(&mut self, silhouette: &Mask) -> Pose {
        if silhouette.count() == 0 {
            return self.estimate;
        }
        if self.particles.is_empty() {
            self.place(silhouette);
        }
        let sighting = Sighting::silhouette(silhouette.clone());
        let mut scale = 1.0;
        for _ in 0..self.params.layers {
            self.diffuse(scale);
            let scores = self.score(&sighting);
            let weights = self.anneal(&scores);
            self.estimate = self.mean(&weights);
            self.particles = systematic(&weights, &mut self.rng).map(|j| self.particles[j]).collect();
            scale *= self.params.shrink;
        }
        self.estimate
    }

    /// Every particle starts at the starting pose, standing on the
    /// silhouette's feet and facing the camera.
    fn place(&mut self, silhouette: &Mask) {
        let facing = |root: DVec3| {
            let towards = self.camera.position() - root;
            towards.x.atan2(towards.z)
        };
        if let Some(root) = Root::from_silhouette(&self.camera, silhouette, self.body.pelvis_height(), 0.0) {
            self.estimate.root = root.position;
            self.estimate.heading = facing(root.position);
        }
        self.particles = vec![self.estimate; self.params.particles];
    }

    fn diffuse(&mut self, scale: f64) {
        let p = self.params;
        for pose in &mut self.particles {
            let mut gauss = || self.rng.sample::<f64, _>(StandardNormal) * scale;
            pose.root += DVec3::new(gauss(), gauss(), gauss()) * p.move_m;
            pose.heading += gauss() * p.turn_rad;
            pose.x.iter_mut().for_each(|a| *a += gauss() * p.angle_rad);
        }
    }

    /// The particles' likelihoods, scored in parallel: one contiguous share
    /// of the particles per kept scorer, since a scorer's drawing buffers
    /// cost more to build than a score. The draws stay serial, so threads
    /// cannot change results.
    fn score(&mut self, sighting: &Sighting) -> Vec<f64> {
        self.evaluations += self.particles.len() as u64;
        let share = self.particles.len().div_ceil(self.scorers.len());
        let mut scores = vec![0.0; self.particles.len()];
        scores.par_chunks_mut(share).zip(self.particles.par_chunks(share)).zip(self.scorers.par_iter_mut()).for_each(
            |((out, poses), scorer)| {
                out.iter_mut().zip(poses).for_each(|(s, pose)| *s = scorer.score(sighting, pose));
            },
        );
        scores
    }

    /// Normalized weights `(R/top)^β`, with `β` found by bisection so that
    /// the effective number of particles is the survival share.
    fn anneal(&self, scores: &[f64]) -> Vec<f64> {
        let top = scores.iter().copied().fold(f64::MIN, f64::max);
        let relative: Vec<f64> = scores.iter().map(|s| s / top).collect();
        let weights = |beta: f64| {
            let w: Vec<f64> = relative.iter().map(|r| r.powf(beta)).collect();
            let total: f64 = w.iter().sum();
            w.into_iter().map(|v| v / total).collect::<Vec<_>>()
        };
        let survival = |w: &[f64]| 1.0 / (w.iter().map(|v| v * v).sum::<f64>() * w.len() as f64);
        let (mut low, mut high) = (0.0, 1.0);
        while survival(&weights(high)) > self.params.survival && high < 1e6 {
            high *= 2.0;
        }
        for _ in 0..40 {
            let mid = 0.5 * (low + high);
            if survival(&weights(mid)) > self.params.survival { low = mid } else { high = mid }
        }
        weights(high)
    }

    fn mean(&self, weights: &[f64]) -> Pose {
        let mut mean = Pose { root: DVec3::ZERO, heading: 0.0, x: [0.0; DOF] };
        for (pose, &w) in self.particles.iter().zip(weights) {
            mean.root += pose.root * w;
            mean.heading += pose.heading * w;
            mean.x.iter_mut().zip(&pose.x).for_each(|(m, v)| *m += w * v);
        }
        mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vision::camera::Preset;

    fn filter(budget: usize) -> FullSpaceFilter {
        let camera = Camera::preset(Preset::Front, 80, 60).unwrap();
        FullSpaceFilter::new(camera, AnnealParams::with_budget(budget), [0.0; DOF], 3)
    }

    #[test]
    fn each_layer_softens_the_likelihood_until_about_half_the_particles_survive() {
        let f = filter(500);
        let scores: Vec<f64> = (0..100).map(|i| 0.01 + 0.0001 * ((i * 37) % 100) as f64).collect();
        let w = f.anneal(&scores);
        let survival = 1.0 / (w.iter().map(|v| v * v).sum::<f64>() * w.len() as f64);
        assert!((survival - 0.5).abs() < 1e-3, "{survival}");
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // Higher scores weigh more.
        let best = (0..100).max_by(|&a, &b| scores[a].total_cmp(&scores[b])).unwrap();
        assert!(w.iter().all(|&v| v <= w[best]));
    }

    #[test]
    fn a_frame_spends_the_budget_and_an_empty_frame_spends_nothing_and_keeps_the_pose() {
        let mut f = filter(60);
        let camera = f.camera.clone();
        let mut scorer = Scorer::new(camera, f.body.clone());
        let mut standing = Pose::rest(&f.body);
        standing.root = DVec3::new(0.0, f.body.pelvis_height(), 0.0);
        let seen = scorer.draw(&standing).clone();
        let first = f.step(&seen);
        assert_eq!(f.evaluations(), 60);
        let empty = Mask::new(80, 60);
        assert_eq!(f.step(&empty), first);
        assert_eq!(f.evaluations(), 60);
        f.step(&seen);
        assert_eq!(f.evaluations(), 120);
    }
}
