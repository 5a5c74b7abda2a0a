//! The tracker: every primitive's filter on each frame, in parallel, then
//! recognition (eq. 7, or eq. 10 with feedback) and arbitration: the
//! winner's pose is the frame's point of the virtual trajectory.

use crate::mocap::body::Body;
use crate::mocap::pose::Pose;
use crate::params::{InvalidField, Params};
use crate::track::calibrate::{self, CalibrationParams, CalibrationReport, HeightFrom, Physique, Sample, blend};
use crate::track::filter::{Estimate, Filter, FilterParams};
use crate::track::open_set::{Judge, OpenSet, OpenSetError};
use crate::track::root::Root;
use crate::vision::camera::Camera;
use crate::vision::keypoints::{SitePoints, torso_px};
use crate::vision::mask::Mask;
use crate::vision::scorer::{Fit, Scorer};
use crate::vision::sighting::{KEYPOINT_SIGMA_TORSO_SHARE, KeypointTarget, PCK_TORSO_SHARE, Sighting};
use crate::vocab::vocabulary::Vocabulary;
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::sync::Arc;

/// Headings tried when a filter first places its root: silhouettes hardly
/// tell which way a person faces, so every eighth of a turn is scored.
const HEADINGS: usize = 8;

/// Hill-climbing steps of the first placement.
const PLACEMENT_STEPS: usize = 40;

/// How the primitives' estimates become activity probabilities. Both weigh
/// each primitive by its [`Estimate::evidence`] to the filters' sharpness
/// (`R^sharpness`, eq. 8 sharpened, see [`FilterParams::sharpness`], per
/// fifteenth of a second: [`FilterParams::evidence_power`]): the
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
    /// How the drawn body is fitted to the person; `None` keeps the
    /// canonical body throughout.
    pub calibration: Option<CalibrationParams>,
    pub open_set: OpenSet,
    pub seed: u64,
}

impl Params for TrackParams {
    type Valid = TrackParams;
    type Error = TrackParamsError;

    fn check(&self) -> Result<TrackParams, TrackParamsError> {
        if self.filter.particles == 0 {
            return Err(TrackParamsError::Particles);
        }
        if self.filter.cone.lookahead == 0 {
            return Err(TrackParamsError::Lookahead);
        }
        let frame_time_s = self.filter.frame_time_s;
        if !(frame_time_s.is_finite() && frame_time_s > 0.0) {
            return Err(TrackParamsError::FrameTime(frame_time_s));
        }
        self.open_set.check()?;
        Ok(*self)
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TrackParamsError {
    #[error("particles: a filter needs at least 1 particle")]
    Particles,
    #[error("lookahead: the bending cone needs at least 1 prediction")]
    Lookahead,
    #[error("frame_time_s: a frame lasts a positive number of seconds, not {0}")]
    FrameTime(f64),
    #[error(transparent)]
    OpenSet(#[from] OpenSetError),
}

impl InvalidField for TrackParamsError {
    fn field(&self) -> &'static str {
        match self {
            TrackParamsError::Particles => "particles",
            TrackParamsError::Lookahead => "lookahead",
            TrackParamsError::FrameTime(_) => "frame_time_s",
            TrackParamsError::OpenSet(e) => e.field(),
        }
    }
}

/// Why a tracker cannot be set up.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TrackError {
    #[error(transparent)]
    Params(#[from] TrackParamsError),
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
    /// What share of the frame the primitive with the most evidence
    /// accounts for; `None` when the filters coasted.
    pub fit: Option<Fit>,
    /// No primitive explains the person (see [`OpenSet`]); false when
    /// the filters coasted.
    pub unexplained: bool,
}

pub struct Tracker {
    vocabulary: Arc<Vocabulary>,
    filters: Vec<Filter>,
    camera: Camera,
    physique: Physique,
    params: TrackParams,
    calibration: Calibrating,
    /// `w_i` of eq. 10.
    history: Vec<f64>,
    placed: bool,
    winner: usize,
    /// The person's torso in the last keypoints that showed it, pixels.
    torso_px: Option<f64>,
    open_set: Judge,
}

impl Tracker {
    /// A tracker of `vocabulary`'s primitives (shared: a caller may hold
    /// it too) through `camera`.
    pub fn new(vocabulary: Arc<Vocabulary>, camera: Camera, params: TrackParams) -> Result<Tracker, TrackError> {
        params.check()?;
        let primitives = vocabulary.primitives();
        if primitives.is_empty() {
            return Err(TrackError::EmptyVocabulary);
        }
        // A held height is drawn from the first frame; a fitted one from
        // the first fit.
        let physique = match params.calibration.and_then(|c| c.held_height()) {
            Some(h) => Physique { body: Body::of_shares(h, 1.0, 1.0), ..Physique::canonical() },
            None => Physique::canonical(),
        };
        let body = &physique.body;
        // Until a silhouette places it, the person stands where the camera looks.
        let look_at = DVec3::from_array(camera.spec().look_at);
        let root = Root { position: DVec3::new(look_at.x, body.pelvis_height(), look_at.z), heading: 0.0 };
        let n = primitives.len();
        let filters = (0..n)
            .map(|i| {
                // One stream per primitive, so threads cannot change the draws.
                let rng = ChaCha8Rng::seed_from_u64(params.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ i as u64);
                let scorer = Scorer::new(camera.clone(), body.clone());
                Filter::new(Arc::clone(&vocabulary), i, params.filter, root, scorer, rng)
            })
            .collect();
        let calibration = Calibrating::new(params.calibration, body.standing_height());
        Ok(Tracker {
            vocabulary,
            filters,
            camera,
            physique,
            params,
            calibration,
            history: vec![1.0 / n as f64; n],
            placed: false,
            winner: 0,
            torso_px: None,
            open_set: Judge::new(params.open_set, params.filter.frame_time_s),
        })
    }

    /// The vocabulary whose primitives are tracked.
    pub fn vocabulary(&self) -> &Arc<Vocabulary> {
        &self.vocabulary
    }

    /// The skeleton drawn now (calibration changes it).
    pub fn body(&self) -> &Body {
        &self.physique.body
    }

    /// What calibration has found so far.
    pub fn calibration(&self) -> &CalibrationReport {
        &self.calibration.report
    }

    /// Likelihood evaluations made so far, over every primitive and
    /// calibration.
    pub fn evaluations(&self) -> u64 {
        self.filters.iter().map(Filter::evaluations).sum::<u64>() + self.calibration.report.evaluations
    }

    /// Tracks one frame's silhouette (the camera's size).
    pub fn step(&mut self, silhouette: &Mask) -> FrameEstimate {
        self.step_seen(Some(silhouette), None)
    }

    /// Tracks one frame from what it shows: its silhouette (the camera's
    /// size; `None` where not observed) and a detector's keypoints (pixels
    /// of the camera's frames). With neither, the filters coast.
    pub fn step_seen(&mut self, silhouette: Option<&Mask>, keypoints: Option<&SitePoints>) -> FrameEstimate {
        let target = keypoints.and_then(|k| self.keypoint_target(k));
        let sighting = Sighting::of(silhouette, target);
        match (self.placed, &sighting) {
            (false, Some(sighting)) => self.place(sighting),
            (true, Some(sighting)) => self.follow(sighting),
            _ => {}
        }
        let estimates: Vec<Estimate> = self.filters.par_iter_mut().map(|f| f.step(sighting.as_ref())).collect();
        let probabilities = match sighting {
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
        let fit = sighting.as_ref().map(|s| self.fit(s, &estimates));
        let unexplained = fit.is_some_and(|f| self.open_set.unexplained(f));
        if let Some(sighting) = sighting
            && self.placed
        {
            self.calibrate(sighting, pose);
        }
        FrameEstimate { estimates, probabilities, winner: self.winner, pose, fit, unexplained }
    }

    /// What share of the frame the estimate of the primitive with the most
    /// evidence accounts for; keypoints count within PCK's tolerance of
    /// the torso seen, weighted by how much they move (see [`OpenSet`]).
    fn fit(&mut self, sighting: &Sighting, estimates: &[Estimate]) -> Fit {
        let evidence = |i: usize| estimates[i].evidence.unwrap_or(0.0);
        let best = (0..estimates.len()).fold(0, |best, i| if evidence(i) > evidence(best) { i } else { best });
        let pose = estimates[best].root.pose(&estimates[best].x);
        let tolerance_px = PCK_TORSO_SHARE * self.torso_px.unwrap_or(0.0);
        let weights = sighting.keypoints().map(|k| self.open_set.site_weights(k.points(), tolerance_px));
        self.filters[best].fit(sighting, &pose, tolerance_px, weights.as_ref())
    }

    /// The keypoints as the filters score them: a detector's error is a
    /// share of the person's torso (this frame's, else the last one seen),
    /// widened by the square root of the filters' sharpness, which their
    /// weights raise each score to. `None` before any torso was seen.
    fn keypoint_target(&mut self, points: &SitePoints) -> Option<KeypointTarget> {
        if let Some(torso) = torso_px(points) {
            self.torso_px = Some(torso);
        }
        let sigma = KEYPOINT_SIGMA_TORSO_SHARE * self.torso_px? * self.params.filter.sharpness.sqrt();
        KeypointTarget::new(*points, sigma)
    }

    /// Collects the frame for calibration and fits the body when a window
    /// is full: the first fit from the canonical body, later ones a step
    /// of the way from the current build towards their own.
    fn calibrate(&mut self, sighting: Sighting, pose: Pose) {
        let Some(params) = self.params.calibration else { return };
        let dt = self.params.filter.frame_time_s;
        let state = &mut self.calibration;
        state.seen_s += dt;
        let window = (params.window_s / dt).round().max(1.0) as usize;
        if sighting.mask().is_some_and(calibrate::whole) {
            state.samples.push(Sample { sighting, pose });
            if state.samples.len() > window {
                state.samples.remove(0);
            }
        }
        let first = !state.report.calibrated;
        if first && state.report.note.is_some() {
            return; // given up
        }
        let due = if first { params.window_s } else { params.refine_every_s };
        if state.seen_s + 1e-9 < state.next_s + due {
            return;
        }
        // The window is over: fit if it had enough whole frames, else
        // wait for more (the first fit, until it gives up) or for the next
        // window.
        if state.samples.len() < params.min_frames {
            if !first {
                state.next_s = state.seen_s;
            } else if state.seen_s > params.give_up_s {
                state.report.note = Some(format!(
                    "no standing frame to calibrate from: fewer than {} frames showed the whole person in the \
                     first {} s; the canonical body was drawn throughout",
                    params.min_frames, params.give_up_s
                ));
                state.samples.clear();
            }
            return;
        }
        let start = self.physique.clone();
        let samples = std::mem::take(&mut state.samples);
        state.next_s = state.seen_s;
        let Some(fit) = calibrate::fit(&self.camera, &samples, &start, params.held_height(), !first) else { return };
        let report = &mut state.report;
        report.evaluations += fit.evaluations;
        if first {
            report.calibrated = true;
            report.frames = fit.frames;
            report.height_se_m = fit.height_se_m;
            report.log_likelihood_gain = fit.log_likelihood_gain;
            if !fit.accepted {
                report.note = Some(format!(
                    "the body drawn explains the person as well as any build fitted (mean log R gained {:.3} per \
                     frame): kept",
                    fit.log_likelihood_gain
                ));
            }
        } else if fit.accepted {
            report.refinements += 1;
        }
        if !fit.accepted {
            return;
        }
        report.note = None;
        let physique = if first { fit.physique.clone() } else { blend(&start, &fit.physique, params.refine_rate) };
        report.height_m = physique.body.standing_height();
        (report.arm_share, report.leg_share) = physique.body.shares();
        report.girth = physique.girth;
        // Every filter goes on from the winner's root moved for the new
        // build, as the fit placed it.
        let scale = physique.body.pelvis_height() / fit.physique.body.pelvis_height();
        let root = Root {
            position: glam::DVec3::new(fit.last_pose.root.x, fit.last_pose.root.y * scale, fit.last_pose.root.z),
            heading: fit.last_pose.heading,
        };
        for f in &mut self.filters {
            f.set_shape(&physique);
            f.set_root(root);
        }
        self.physique = physique;
    }

    /// Where the sighting places the person: under their silhouette, or
    /// else their keypoints.
    fn anchor(&self, sighting: &Sighting) -> Option<Root> {
        let body = &self.physique.body;
        match sighting.mask() {
            Some(mask) => Root::from_silhouette(&self.camera, mask, body.pelvis_height(), 0.0),
            None => sighting.keypoints().and_then(|k| Root::from_keypoints(&self.camera, k.points(), body)),
        }
    }

    /// Moves the person's root to where their keypoints' ankles (or hips)
    /// place them when the last winner's filter, in its particles' mean
    /// pose, explains the frame better there: one person, one root, as
    /// after recognition. Silhouettes alone do not move it so: their
    /// footprint is the feet's row, a pixel of it tens of centimetres of
    /// floor through a wide lens, and shadows widen it; following it cost
    /// recognition through 70° lenses at 160×120 (46 → 30% at 1.4 m high,
    /// 4 m away).
    fn follow(&mut self, sighting: &Sighting) {
        let body = &self.physique.body;
        let anchor = sighting.keypoints().and_then(|k| Root::from_keypoints(&self.camera, k.points(), body));
        let Some(anchor) = anchor else { return };
        let root = self.filters[self.winner].follow(sighting, anchor.position);
        self.filters.iter_mut().for_each(|f| f.set_root(root));
    }

    /// Puts every filter's root on the person the first time one shows.
    fn place(&mut self, sighting: &Sighting) {
        let Some(root) = self.anchor(sighting) else { return };
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
            f.place(sighting, &headings, PLACEMENT_STEPS);
        });
        self.placed = true;
    }

    /// Eq. 7, or eq. 10 with the primitives' history.
    fn recognize(&mut self, estimates: &[Estimate]) -> Vec<f64> {
        let evidence = |e: &Estimate| e.evidence.expect("an observed frame scores every estimate");
        // Relative to the best, so the power cannot underflow all.
        let top = estimates.iter().map(evidence).fold(f64::MIN, f64::max);
        let mut p: Vec<f64> =
            estimates.iter().map(|e| (evidence(e) / top).powf(self.params.filter.evidence_power())).collect();
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

/// Calibration's state: frames collected and what was found.
struct Calibrating {
    samples: Vec<Sample>,
    /// Seconds of observed frames since the person was placed, and when
    /// the current window began.
    seen_s: f64,
    next_s: f64,
    report: CalibrationReport,
}

impl Calibrating {
    fn new(params: Option<CalibrationParams>, height_m: f64) -> Calibrating {
        let mut report = CalibrationReport::canonical(params.map_or(HeightFrom::Fit, |p| p.height_from()));
        report.height_m = height_m;
        if params.is_none() {
            report.note = Some("calibration off: the canonical body was drawn throughout".into());
        }
        Calibrating { samples: Vec::new(), seen_s: 0.0, next_s: 0.0, report }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::cone::Cone;
    use crate::track::root::RootSearch;
    use crate::vision::camera::Preset;
    use std::path::Path;

    fn vocabulary() -> Arc<Vocabulary> {
        Arc::new(Vocabulary::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("vocab/default.vocab")).unwrap())
    }

    fn tracker(vocabulary: &Arc<Vocabulary>, recognition: Recognition) -> Tracker {
        let filter = FilterParams {
            particles: 2,
            cone: Cone { lookahead: 1, spread: 0.5 },
            sharpness: 4.0,
            manifold: 2.0,
            renewal: 0.0,
            root: RootSearch { steps: 0, move_m: 0.0, turn_rad: 0.0 },
            // The rate the sharpness is tuned at: the evidence's power is 4.
            frame_time_s: 1.0 / 15.0,
        };
        let camera = Camera::preset(Preset::Front, 40, 30).unwrap();
        let params = TrackParams { filter, recognition, calibration: None, open_set: OpenSet::STANDARD, seed: 1 };
        Tracker::new(Arc::clone(vocabulary), camera, params).unwrap()
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
    fn a_person_never_seen_whole_is_drawn_canonical_and_the_summary_says_why() {
        let vocabulary = vocabulary();
        let mut t = tracker(&vocabulary, Recognition::Likelihood);
        let params = CalibrationParams { give_up_s: 1.0, ..CalibrationParams::standard(None) };
        t.params.calibration = Some(params);
        t.calibration = Calibrating::new(Some(params), t.body().standing_height());
        // Cut off by the frame's bottom edge in every frame, for the 2 s
        // window and past the 1 s given.
        let cut = Mask::from_fn(40, 30, |i, j| (15..25).contains(&i) && j >= 10);
        for _ in 0..40 {
            t.step(&cut);
        }
        let report = t.calibration();
        assert!(!report.calibrated, "{report:?}");
        assert!(report.note.as_deref().is_some_and(|n| n.starts_with("no standing frame")), "{report:?}");
        assert_eq!(t.body(), &Body::standard());
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
        // One frame of 1/15 s keeps exp(−(1/15)/0.6) of the history and shares the rest evenly.
        let keep = (-(1.0f64 / 15.0) / 0.6).exp();
        assert!((t.history[0] - (keep * before + (1.0 - keep) / n)).abs() < 1e-12);
        for _ in 0..200 {
            t.forget();
        }
        assert!(t.history.iter().all(|w| (w - 1.0 / n).abs() < 1e-9), "{:?}", t.history);
    }
}
