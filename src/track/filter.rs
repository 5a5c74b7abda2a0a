//! One primitive's particle filter in its latent space (eq. 4).

use crate::mocap::body::JointVector;
use crate::mocap::pose::Pose;
use crate::track::calibrate::Physique;
use crate::track::cone::{Cone, ConeScratch};
use crate::track::root::{Root, RootSearch};
use crate::vision::scorer::{Fit, Scorer};
use crate::vision::sighting::Sighting;
use crate::vocab::primitive::Primitive;
use crate::vocab::vocabulary::Vocabulary;
use glam::DVec3;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::sync::Arc;

/// The frame rate [`FilterParams::standard`] was tuned at (the paper's
/// camera's).
const TUNED_FPS: f64 = 15.0;

/// How far (pixels) where the sighting places the person must be from
/// where the root stands for [`Filter::follow`] to consider moving it.
const FOLLOW_MIN_PX: f64 = 3.0;

/// Passes of [`Root::align`] when a filter is placed.
const ALIGN_PASSES: usize = 2;

/// Settings every primitive's filter shares.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FilterParams {
    pub particles: usize,
    pub cone: Cone,
    /// Particle weights are `R^sharpness`: R (eq. 8) varies little between
    /// near poses, and raw R would resample almost uniformly.
    pub sharpness: f64,
    /// The primitive as a prior: a particle `δ` from the nearest training
    /// pose is weighted by `exp(−½ (δ / (manifold · step))²)`, so a filter
    /// explains the silhouette with its own kind of pose rather than any
    /// pose its latent span can reach (which would let every primitive
    /// explain every activity).
    pub manifold: f64,
    /// Chance that a particle is redrawn from the primitive's training
    /// poses instead of moving through the cone. Without it, a filter whose
    /// activity is not being performed collapses onto the one pose of its
    /// manifold that best fits the other activity, and is then too far away
    /// to follow its own activity when that starts.
    pub renewal: f64,
    pub root: RootSearch,
    /// Seconds between frames.
    pub frame_time_s: f64,
}

impl FilterParams {
    /// The settings `imitate track` uses, tuned on the documented
    /// three-activity sequence at 15 frames a second: noise across the cone
    /// half a frame's typical step, R^8, a manifold prior two steps wide, 5%
    /// renewal, and 4 root steps of 3 cm and 0.005 rad a frame.
    ///
    /// At other frame rates they keep what they do in a second: the cone's
    /// step is the primitive's speed times the frame time already; renewal
    /// keeps 0.95 of the particles per fifteenth of a second, and the root's
    /// random walk spreads as far in a second (steps scaled by the square
    /// root of the frame time).
    ///
    /// The turn is small on purpose. A silhouette hardly shows a few
    /// degrees of heading, and a turned torso can make up for a wrong arm
    /// pose, so larger turns let the heading wander: at 0.05 rad it was off
    /// by 6–8° on average and depth errors doubled. Slow turns (a few
    /// degrees a second) are still followed, and placement tries every
    /// heading.
    pub fn standard(particles: usize, lookahead: usize, frame_time_s: f64) -> FilterParams {
        let fifteenths = frame_time_s * TUNED_FPS;
        FilterParams {
            particles,
            cone: Cone { lookahead, spread: 0.5 },
            sharpness: 8.0,
            manifold: 2.0,
            renewal: 1.0 - 0.95f64.powf(fifteenths),
            root: RootSearch { steps: 4, move_m: 0.03 * fifteenths.sqrt(), turn_rad: 0.005 * fifteenths.sqrt() },
            frame_time_s,
        }
    }

    /// The power recognition raises each primitive's evidence to: the
    /// sharpness at the rate it was tuned at, scaled with the frame time,
    /// so that a second of frames weighs as much at any rate (frames closer
    /// together are not independent evidence: at 60 frames a second the
    /// unscaled power made eq. 10 four times as sure a second and
    /// recognition fell from 98% to 87%).
    pub fn evidence_power(&self) -> f64 {
        self.sharpness * self.frame_time_s * TUNED_FPS
    }

    /// Likelihood evaluations a frame costs after the first: every
    /// particle, the weighted mean, and the root's steps.
    pub fn evaluations_per_frame(&self) -> usize {
        self.particles + 1 + self.root.steps
    }
}

/// What a filter makes of one frame.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// The latent pose estimate `ȳ_i[t]` and its joint-space pose.
    pub latent: Vec<f64>,
    pub root: Root,
    pub x: JointVector,
    /// R of the estimate (eq. 8), or `None` on a frame with no silhouette.
    pub likelihood: Option<f64>,
    /// What recognition weighs this primitive by, on R's scale: the
    /// geometric mean of the estimate's R and the particles' prediction of
    /// the frame (the power mean of their R, to the sharpness, before they
    /// are weighted: the filter's estimate of `p(z[t] | z[1:t−1], primitive)`).
    /// A primitive that fits the frame only with a pose its dynamics did
    /// not predict scores lower than one that saw it coming. `None` on a
    /// frame with no silhouette.
    pub evidence: Option<f64>,
    /// Attractor progress of the estimate, in [0, 1).
    pub progress: f64,
}

/// The particles of one primitive and its global root.
pub struct Filter {
    /// The vocabulary, shared, and which of its primitives this is.
    vocabulary: Arc<Vocabulary>,
    index: usize,
    params: FilterParams,
    /// Row-major, `particles × dims`.
    particles: Vec<f64>,
    weights: Vec<f64>,
    root: Root,
    rng: ChaCha8Rng,
    scorer: Scorer,
    cone: ConeScratch,
    /// Likelihood evaluations made so far.
    evaluations: u64,
}

impl Filter {
    /// A filter of the vocabulary's primitive `index` whose particles
    /// start at random training poses of it (its manifold is the prior),
    /// with root `root`.
    pub fn new(
        vocabulary: Arc<Vocabulary>,
        index: usize,
        params: FilterParams,
        root: Root,
        scorer: Scorer,
        mut rng: ChaCha8Rng,
    ) -> Self {
        let primitive = &vocabulary.primitives()[index];
        let (d, field) = (primitive.dims(), primitive.field());
        let mut particles = Vec::with_capacity(params.particles * d);
        for _ in 0..params.particles {
            let i = rng.gen_range(0..field.len());
            particles.extend_from_slice(&field.points()[i * d..(i + 1) * d]);
        }
        let weights = vec![1.0 / params.particles as f64; params.particles];
        Filter {
            vocabulary,
            index,
            params,
            particles,
            weights,
            root,
            rng,
            scorer,
            cone: ConeScratch::default(),
            evaluations: 0,
        }
    }

    pub fn primitive(&self) -> &Primitive {
        &self.vocabulary.primitives()[self.index]
    }

    pub fn set_root(&mut self, root: Root) {
        self.root = root;
    }

    /// Draws hypotheses with this body from now on.
    pub fn set_shape(&mut self, physique: &Physique) {
        self.scorer.set_shape(physique.body.clone(), physique.girth);
    }

    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// One latent step of the primitive at the typical speed over a frame.
    fn step_length(&self) -> f64 {
        self.primitive().speed().median * self.params.frame_time_s
    }

    /// The joint-space pose of particle `j`.
    fn particle_pose(&self, j: usize) -> JointVector {
        let d = self.primitive().dims();
        self.primitive().reconstruct(&self.particles[j * d..(j + 1) * d])
    }

    /// What share of the frame `pose` accounts for (see [`Scorer::fit`]).
    pub fn fit(&mut self, sighting: &Sighting, pose: &Pose, tolerance_px: f64, weights: Option<&[f64; 15]>) -> Fit {
        self.scorer.fit(sighting, pose, tolerance_px, weights)
    }

    fn score(&mut self, sighting: &Sighting, x: &JointVector, root: &Root) -> f64 {
        self.evaluations += 1;
        self.scorer.score(sighting, &root.pose(x))
    }

    /// Chooses the heading (of `candidates`, each with its prior) and the
    /// particle that best explain the first frame, moves the root so that
    /// the body drawn in that pose stands where the person does, then
    /// hill-climbs the root with that pose for `climb` steps.
    pub fn place(&mut self, sighting: &Sighting, candidates: &[(f64, f64)], climb: usize) {
        let mut best = (f64::MIN, self.root, 0);
        for &(heading, prior) in candidates {
            let root = Root { heading, ..self.root };
            for j in 0..self.params.particles {
                let x = self.particle_pose(j);
                let s = self.score(sighting, &x, &root);
                if s * prior > best.0 {
                    best = (s * prior, root, j);
                }
            }
        }
        let (_, mut root, j) = best;
        let x = self.particle_pose(j);
        // A second pass settles the pixel the silhouette's footprint
        // rounds to.
        let placed = self.root.position;
        for _ in 0..ALIGN_PASSES {
            root = self.moved_to(root, &x, sighting, placed);
        }
        let score = self.score(sighting, &x, &root);
        let search = RootSearch { steps: climb, ..self.params.root };
        search.refine(&mut root, &x, score, sighting, &mut self.scorer, &mut self.rng);
        self.evaluations += climb as u64;
        self.root = root;
    }

    /// `root` moved over the floor to where `sighting` places the person
    /// (`anchor`, where [`Root::from_silhouette`] or
    /// [`Root::from_keypoints`] put them) with the body in pose `x`: from a
    /// silhouette, until the body drawn has its footprint there too (the
    /// lowest row is the nearest toe, not the point under the pelvis).
    fn moved_to(&mut self, mut root: Root, x: &JointVector, sighting: &Sighting, anchor: DVec3) -> Root {
        if sighting.mask().is_some() {
            let camera = self.scorer.camera().clone();
            root.align(&camera, self.scorer.draw(&root.pose(x)), anchor);
            self.evaluations += 1;
            root
        } else {
            root.over(anchor)
        }
    }

    /// The root as it was, or moved over the floor to `anchor` (where the
    /// sighting's keypoints place the pelvis), whichever explains the
    /// frame better with the particles' mean pose. A walking or running
    /// person goes farther between frames than the root's hill climb
    /// reaches.
    pub fn follow(&mut self, sighting: &Sighting, anchor: DVec3) -> Root {
        let stay = self.root;
        let moved = stay.over(anchor);
        // Within a few pixels the move is the detector's jitter, not the
        // person: the hill climb refines from where the root is.
        let camera = self.scorer.camera();
        let seen = |r: &Root| camera.project(r.position.with_y(0.0)).map(|(u, v, _)| glam::DVec2::new(u, v));
        if let (Some(a), Some(b)) = (seen(&moved), seen(&stay))
            && a.distance(b) < FOLLOW_MIN_PX
        {
            return stay;
        }
        let x = self.primitive().reconstruct(&self.mean());
        if self.score(sighting, &x, &moved) > self.score(sighting, &x, &stay) { moved } else { stay }
    }

    /// One frame: every particle moves through the bending cone (or a few
    /// are renewed from the training poses); with a sighting it is
    /// weighted by its likelihood, the estimate is the better of the
    /// weighted mean and the best particle, the root is refined for it,
    /// and the particles are resampled. Without one (an empty silhouette)
    /// the filter coasts: the particles move and the estimate is their
    /// mean.
    pub fn step(&mut self, sighting: Option<&Sighting>) -> Estimate {
        // Its own handle on the vocabulary, so the primitive is borrowed
        // while the particles change.
        let vocabulary = Arc::clone(&self.vocabulary);
        let primitive = &vocabulary.primitives()[self.index];
        let (d, n) = (primitive.dims(), self.params.particles);
        let step = self.step_length();
        let field = primitive.field();
        for j in 0..n {
            let y = &mut self.particles[j * d..(j + 1) * d];
            if self.rng.gen_bool(self.params.renewal) {
                let i = self.rng.gen_range(0..field.len());
                y.copy_from_slice(&field.points()[i * d..(i + 1) * d]);
            } else {
                self.params.cone.sample(primitive, step, y, &mut self.rng, &mut self.cone);
            }
        }
        let Some(sighting) = sighting else {
            self.weights.fill(1.0 / n as f64);
            let latent = self.mean();
            let x = primitive.reconstruct(&latent);
            return self.estimate(latent, x, None, None);
        };
        let root = self.root;
        let mut scores = vec![0.0; n];
        for (j, s) in scores.iter_mut().enumerate() {
            let x = self.particle_pose(j);
            *s = self.score(sighting, &x, &root);
        }
        // Weights relative to the best score, so the power cannot underflow all.
        let top = scores.iter().copied().fold(f64::MIN, f64::max);
        let k = self.params.sharpness;
        let predicted = top * (scores.iter().map(|s| (s / top).powf(k)).sum::<f64>() / n as f64).powf(1.0 / k);
        let width = self.params.manifold * step;
        let mut nearest = Vec::with_capacity(1);
        for (j, (w, s)) in self.weights.iter_mut().zip(&scores).enumerate() {
            let off = primitive.field().distance_to_data(&self.particles[j * d..(j + 1) * d], &mut nearest);
            *w = (s / top).powf(k) * (-0.5 * (off / width).powi(2)).exp();
        }
        let total: f64 = self.weights.iter().sum();
        self.weights.iter_mut().for_each(|w| *w /= total);
        let best = (0..n).fold(0, |b, j| if self.weights[j] > self.weights[b] { j } else { b });
        let mean = self.mean();
        let mean_x = primitive.reconstruct(&mean);
        let mean_score = self.score(sighting, &mean_x, &root);
        let (latent, x, score) = if mean_score >= scores[best] {
            (mean, mean_x, mean_score)
        } else {
            (self.particles[best * d..(best + 1) * d].to_vec(), self.particle_pose(best), scores[best])
        };
        let mut root = root;
        let score = self.params.root.refine(&mut root, &x, score, sighting, &mut self.scorer, &mut self.rng);
        self.evaluations += self.params.root.steps as u64;
        self.root = root;
        self.resample();
        self.estimate(latent, x, Some(score), Some((score * predicted).sqrt()))
    }

    fn estimate(&self, latent: Vec<f64>, x: JointVector, likelihood: Option<f64>, evidence: Option<f64>) -> Estimate {
        let progress = self.primitive().progress(&latent);
        Estimate { latent, root: self.root, x, likelihood, evidence, progress }
    }

    /// The weighted mean of the particles.
    fn mean(&self) -> Vec<f64> {
        let d = self.primitive().dims();
        let mut mean = vec![0.0; d];
        for (y, w) in self.particles.chunks_exact(d).zip(&self.weights) {
            mean.iter_mut().zip(y).for_each(|(m, v)| *m += w * v);
        }
        mean
    }

    fn resample(&mut self) {
        let d = self.primitive().dims();
        let mut next = Vec::with_capacity(self.particles.len());
        for j in systematic(&self.weights, &mut self.rng) {
            next.extend_from_slice(&self.particles[j * d..(j + 1) * d]);
        }
        self.particles = next;
        self.weights.fill(1.0 / self.params.particles as f64);
    }
}

/// Systematic resampling: the indices `n` evenly spaced pointers, after one
/// uniform draw, pick from the running sum of `weights` (normalized, `n`
/// of them); low variance, and `O(n)`.
pub fn systematic<'w>(weights: &'w [f64], rng: &mut impl Rng) -> impl Iterator<Item = usize> + 'w {
    let n = weights.len();
    let start: f64 = rng.gen_range(0.0..1.0 / n as f64);
    let (mut j, mut cumulative) = (0, weights[0]);
    (0..n).map(move |k| {
        let pointer = start + k as f64 / n as f64;
        while pointer > cumulative && j + 1 < n {
            j += 1;
            cumulative += weights[j];
        }
        j
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_of_frames_renews_moves_and_weighs_alike_at_any_rate() {
        let at = |fps: f64| FilterParams::standard(25, 5, 1.0 / fps);
        let tuned = at(TUNED_FPS);
        assert_eq!((tuned.renewal, tuned.root.move_m, tuned.evidence_power()), (1.0 - 0.95, 0.03, 8.0));
        for fps in [25.0, 29.97, 60.0] {
            let p = at(fps);
            // Particles kept unrenewed over a second, the root walk's spread
            // over a second, and the evidence's power summed over a second.
            let kept = (1.0 - p.renewal).powf(fps);
            assert!((kept - 0.95f64.powf(TUNED_FPS)).abs() < 1e-12, "{fps}");
            let spread = p.root.move_m * fps.sqrt();
            assert!((spread - 0.03 * TUNED_FPS.sqrt()).abs() < 1e-12, "{fps}");
            assert!((p.evidence_power() * fps - 8.0 * TUNED_FPS).abs() < 1e-9, "{fps}");
        }
    }
}
