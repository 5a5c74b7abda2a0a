//! The tracker: every primitive's filter on each frame, in parallel, then
//! recognition (eq. 7, or eq. 10 with feedback) and arbitration: the
//! winner's pose is the frame's point of the virtual trajectory.

use crate::mocap::body::Body;
use crate::mocap::pose::Pose;
use crate::track::filter::{Estimate, Filter, FilterParams};
use crate::track::root::Root;
use crate::vision::camera::Camera;
use crate::vision::distance::Observation;
use crate::vision::mask::Mask;
use crate::vision::scorer::Scorer;
use crate::vocab::vocabulary::Vocabulary;
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Headings tried when a filter first places its root: silhouettes hardly
/// tell which way a person faces, so every eighth of a turn is scored.
const HEADINGS: usize = 8;

/// Hill-climbing steps of the first placement.
const PLACEMENT_STEPS: usize = 40;

/// How the primitives' estimates become activity probabilities. Both weigh
/// each primitive by its [`Estimate::evidence`] to the filters' sharpness
/// (`R^sharpness`, eq. 8 sharpened, see [`FilterParams::sharpness`]): the
/// estimate's fit together with how well the primitive's dynamics
/// predicted the frame. The estimate's R alone let a primitive win by
/// jumping to whatever pose of its span fits (from the side, hand circles
/// and vertical waving pass through the same silhouettes): the side view
/// recognized 63% with 25 particles, against 95% now.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Recognition {
    /// Eq. 7: the primitives' evidence, normalized over the primitives.
    Likelihood,
    /// Eq. 10: each primitive's evidence times `w_i`, what the history says of
    /// primitive `i` before this frame: last frame's probability, with a
    /// chance of switching to any primitive that makes the history fade
    /// over `memory_s` seconds (the forward pass of a hidden Markov model
    /// over activities).
    Feedback { memory_s: f64 },
}

impl Recognition {
    /// Eq. 10 as `imitate track --feedback` runs it.
    pub const FEEDBACK: Recognition = Recognition::Feedback { memory_s: 0.6 };
}

/// Everything the tracker is set up with.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TrackParams {
    pub filter: FilterParams,
    pub recognition: Recognition,
    pub seed: u64,
}

/// Why a tracker cannot be set up.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TrackError {
    #[error("--particles must be at least 1")]
    NoParticles,
    #[error("--lookahead must be at least 1")]
    NoLookahead,
    #[error("the vocabulary has no primitives")]
    EmptyVocabulary,
}

/// One frame's outcome.
#[derive(Clone, Debug)]
pub struct FrameEstimate {
    /// Each primitive's estimate, in vocabulary order.
    pub estimates: Vec<Estimate>,
    /// Activity probabilities (eq. 7 or 10); `None` when the frame showed
    /// no silhouette and the filters coasted.
    pub probabilities: Option<Vec<f64>>,
    /// The primitive whose pose this frame's trajectory takes: the most
    /// probable, or when coasting the last one that was.
    pub winner: usize,
    /// The winner's pose.
    pub pose: Pose,
}

pub struct Tracker<'v> {
    filters: Vec<Filter<'v>>,
    camera: Camera,
    body: Body,
    params: TrackParams,
    /// `w_i` of eq. 10.
    history: Vec<f64>,
    placed: bool,
    winner: usize,
}

impl<'v> Tracker<'v> {
    pub fn new(vocabulary: &'v Vocabulary, camera: Camera, params: TrackParams) -> Result<Tracker<'v>, TrackError> {
        if params.filter.particles == 0 {
            return Err(TrackError::NoParticles);
        }
        if params.filter.cone.lookahead == 0 {
            return Err(TrackError::NoLookahead);
        }
        let primitives = vocabulary.primitives();
        if primitives.is_empty() {
            return Err(TrackError::EmptyVocabulary);
        }
        let body = Body::standard();
        // Until a silhouette places it, the person stands where the camera looks.
        let look_at = DVec3::from_array(camera.spec().look_at);
        let root = Root { position: DVec3::new(look_at.x, body.pelvis_height(), look_at.z), heading: 0.0 };
        let filters = primitives
            .iter()
            .enumerate()
            .map(|(i, p)| {
                // One stream per primitive, so threads cannot change the draws.
                let rng = ChaCha8Rng::seed_from_u64(params.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ i as u64);
                Filter::new(p, params.filter, root, Scorer::new(camera.clone(), body.clone()), rng)
            })
            .collect();
        let n = primitives.len();
        Ok(Tracker { filters, camera, body, params, history: vec![1.0 / n as f64; n], placed: false, winner: 0 })
    }

    pub fn body(&self) -> &Body {
        &self.body
    }

    /// Likelihood evaluations made so far, over every primitive.
    pub fn evaluations(&self) -> u64 {
        self.filters.iter().map(Filter::evaluations).sum()
    }

    /// Tracks one frame's silhouette (the camera's size).
    pub fn step(&mut self, silhouette: &Mask) -> FrameEstimate {
        let observation = (silhouette.count() > 0).then(|| Observation::new(silhouette.clone()));
        if let (false, Some(observation)) = (self.placed, &observation) {
            self.place(silhouette, observation);
        }
        let estimates: Vec<Estimate> = self.filters.par_iter_mut().map(|f| f.step(observation.as_ref())).collect();
        let probabilities = match observation {
            Some(_) => Some(self.recognize(&estimates)),
            None => {
                self.forget();
                None
            }
        };
        if let Some(p) = &probabilities {
            self.winner = (0..p.len()).fold(0, |best, i| if p[i] > p[best] { i } else { best });
            // One person, one root: every filter goes on from the winner's,
            // which its own search then refines. A filter left with its own
            // root while another activity is performed moves that root to
            // fit its wrong pose, and stays lost when its activity starts.
            let root = estimates[self.winner].root;
            self.filters.iter_mut().for_each(|f| f.set_root(root));
        }
        let chosen = &estimates[self.winner];
        let pose = chosen.root.pose(&chosen.x);
        FrameEstimate { estimates, probabilities, winner: self.winner, pose }
    }

    /// Puts every filter's root on the person the first time one shows.
    fn place(&mut self, silhouette: &Mask, observation: &Observation) {
        let Some(root) = Root::from_silhouette(&self.camera, silhouette, self.body.pelvis_height(), 0.0) else {
            return;
        };
        // A silhouette looks the same from the front as from the back, so
        // a prior breaks the tie: people mostly face the camera. Turned
        // away, a heading keeps half its score; at right angles, three
        // quarters (a side view's feet still tell the two apart).
        let towards = self.camera.position() - root.position;
        let facing = towards.x.atan2(towards.z);
        let headings: Vec<(f64, f64)> = (0..HEADINGS)
            .map(|k| k as f64 * std::f64::consts::TAU / HEADINGS as f64)
            .map(|h| (h, 0.75 + 0.25 * (h - facing).cos()))
            .collect();
        self.filters.par_iter_mut().for_each(|f| {
            f.set_root(root);
            f.place(observation, &headings, PLACEMENT_STEPS);
        });
        self.placed = true;
    }

    /// Eq. 7, or eq. 10 with the primitives' history.
    fn recognize(&mut self, estimates: &[Estimate]) -> Vec<f64> {
        let evidence = |e: &Estimate| e.evidence.expect("an observed frame scores every estimate");
        // Relative to the best, so the power cannot underflow all.
        let top = estimates.iter().map(evidence).fold(f64::MIN, f64::max);
        let mut p: Vec<f64> =
            estimates.iter().map(|e| (evidence(e) / top).powf(self.params.filter.sharpness)).collect();
        if let Recognition::Feedback { .. } = self.params.recognition {
            self.forget();
            p.iter_mut().zip(&self.history).for_each(|(p, w)| *p *= w);
        }
        let total: f64 = p.iter().sum();
        p.iter_mut().for_each(|v| *v /= total);
        self.history.copy_from_slice(&p);
        p
    }

    /// Eq. 10's prior for the next frame: any activity may start, so each
    /// keeps `1 − ε` of its probability and shares `ε` evenly; `ε` makes
    /// the history fade over `memory_s`.
    fn forget(&mut self) {
        if let Recognition::Feedback { memory_s } = self.params.recognition {
            let switch = 1.0 - (-self.params.filter.frame_time_s / memory_s).exp();
            let even = switch / self.history.len() as f64;
            self.history.iter_mut().for_each(|w| *w = (1.0 - switch) * *w + even);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::cone::Cone;
    use crate::track::root::RootSearch;
    use crate::vision::camera::Preset;
    use std::path::Path;

    fn vocabulary() -> Vocabulary {
        Vocabulary::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("vocab/default.vocab")).unwrap()
    }

    fn tracker(vocabulary: &Vocabulary, recognition: Recognition) -> Tracker<'_> {
        let filter = FilterParams {
            particles: 2,
            cone: Cone { lookahead: 1, spread: 0.5 },
            sharpness: 4.0,
            manifold: 2.0,
            renewal: 0.0,
            root: RootSearch { steps: 0, move_m: 0.0, turn_rad: 0.0 },
            frame_time_s: 0.1,
        };
        let camera = Camera::preset(Preset::Front, 40, 30).unwrap();
        Tracker::new(vocabulary, camera, TrackParams { filter, recognition, seed: 1 }).unwrap()
    }

    /// Estimates whose likelihoods and evidence are `r` times a common factor.
    fn estimates(tracker: &Tracker, r: &[f64]) -> Vec<Estimate> {
        let n = tracker.filters.len();
        (0..n)
            .map(|i| Estimate {
                latent: Vec::new(),
                root: Root { position: DVec3::ZERO, heading: 0.0 },
                x: [0.0; crate::mocap::body::DOF],
                likelihood: Some(0.01 * r.get(i).copied().unwrap_or(1.0)),
                evidence: Some(0.01 * r.get(i).copied().unwrap_or(1.0)),
                progress: 0.0,
            })
            .collect()
    }

    #[test]
    fn eq7_normalizes_the_sharpened_likelihoods() {
        let vocabulary = vocabulary();
        let mut t = tracker(&vocabulary, Recognition::Likelihood);
        let n = t.filters.len();
        let p = t.recognize(&estimates(&t, &[2.0]));
        // (2^4, 1, 1, …) normalized.
        let total = 16.0 + (n - 1) as f64;
        assert!((p[0] - 16.0 / total).abs() < 1e-12, "{p:?}");
        assert!(p[1..].iter().all(|v| (v - 1.0 / total).abs() < 1e-12), "{p:?}");
    }

    #[test]
    fn eq10_keeps_the_activity_through_one_contrary_frame_that_eq7_follows() {
        let vocabulary = vocabulary();
        let memory = Recognition::Feedback { memory_s: 0.6 };
        let (mut eq7, mut eq10) = (tracker(&vocabulary, Recognition::Likelihood), tracker(&vocabulary, memory));
        for t in [&mut eq7, &mut eq10] {
            for _ in 0..10 {
                let e = estimates(t, &[1.3]);
                t.recognize(&e);
            }
            let e = estimates(t, &[1.0, 1.3]);
            let p = t.recognize(&e);
            let winner = (0..p.len()).fold(0, |b, i| if p[i] > p[b] { i } else { b });
            let expected = if matches!(t.params.recognition, Recognition::Likelihood) { 1 } else { 0 };
            assert_eq!(winner, expected, "{:?}: {p:?}", t.params.recognition);
        }
        // After enough contrary frames, eq. 10 switches too.
        let switched = (0..20).any(|_| {
            let e = estimates(&eq10, &[1.0, 1.3]);
            let p = eq10.recognize(&e);
            p[1] > p[0]
        });
        assert!(switched);
    }

    #[test]
    fn eq10_history_fades_towards_even_over_coasted_frames() {
        let vocabulary = vocabulary();
        let mut t = tracker(&vocabulary, Recognition::Feedback { memory_s: 0.6 });
        let n = t.filters.len() as f64;
        let e = estimates(&t, &[3.0]);
        t.recognize(&e);
        let before = t.history[0];
        t.forget();
        // One frame of 0.1 s keeps exp(−0.1/0.6) of the history and shares the rest evenly.
        let keep = (-0.1f64 / 0.6).exp();
        assert!((t.history[0] - (keep * before + (1.0 - keep) / n)).abs() < 1e-12);
        for _ in 0..200 {
            t.forget();
        }
        assert!(t.history.iter().all(|w| (w - 1.0 / n).abs() < 1e-9), "{:?}", t.history);
    }
}
