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

/// How the primitives' estimates become activity probabilities.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Recognition {
    /// Eq. 7: the estimates' likelihoods, normalized over the primitives.
    Likelihood,
    /// Eq. 10: each likelihood times the primitive's recent probability
    /// `w_i` (an exponential average over `memory_s` seconds), normalized.
    Feedback { memory_s: f64 },
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
        let probabilities = observation.is_some().then(|| self.recognize(&estimates));
        if let Some(p) = &probabilities {
            self.winner = (0..p.len()).fold(0, |best, i| if p[i] > p[best] { i } else { best });
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

    /// Eq. 7, or eq. 10 with the primitives' recent probabilities.
    fn recognize(&mut self, estimates: &[Estimate]) -> Vec<f64> {
        let likelihood = |e: &Estimate| e.likelihood.expect("an observed frame scores every estimate");
        let mut p: Vec<f64> = match self.params.recognition {
            Recognition::Likelihood => estimates.iter().map(likelihood).collect(),
            Recognition::Feedback { .. } => {
                estimates.iter().zip(&self.history).map(|(e, w)| likelihood(e) * w).collect()
            }
        };
        let total: f64 = p.iter().sum();
        p.iter_mut().for_each(|v| *v /= total);
        if let Recognition::Feedback { memory_s } = self.params.recognition {
            let keep = (-self.params.filter.frame_time_s / memory_s).exp();
            for (w, &now) in self.history.iter_mut().zip(&p) {
                *w = keep * *w + (1.0 - keep) * now;
            }
        }
        p
    }
}
