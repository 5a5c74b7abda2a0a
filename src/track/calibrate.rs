//! The person's build from the silhouettes: standing height, arm and leg
//! shares of it, and the girth of trunk, arms and legs, fitted to the
//! frames of the first seconds in whatever pose the person holds, then
//! refined slowly. Poses stay in the canonical joint space; only the drawn
//! body adapts, so one vocabulary serves every person.
//!
//! The fit holds each sampled frame's tracked joint angles and searches
//! the build that best explains the silhouettes (the sum of log R, eq. 8,
//! over the frames), coordinate by coordinate with shrinking steps. A
//! build changes where the body must stand to cover the same pixels, so
//! each frame's root is moved with it: the body stood with its lowest foot
//! on the floor, its distance along the floor from the camera searched (a
//! taller body stands farther back, which only the feet on the floor tell
//! apart from a nearer, shorter one).

use crate::mocap::body::{Body, Joint};
use crate::mocap::pose::Pose;
use crate::vision::camera::Camera;
use crate::vision::mask::Mask;
use crate::vision::scorer::Scorer;
use crate::vision::shape::Girth;
use crate::vision::sighting::Sighting;
use crate::vision::silhouette::person_region;
use glam::DVec3;
use rayon::prelude::*;

/// Heights a person may have, meters (`--height` is held to them too).
pub const HEIGHT_M: (f64, f64) = (1.0, 2.3);
/// Arm and leg shares of the height, multiples of the canonical body's:
/// the range people's proportions span.
const LIMB_SHARE: (f64, f64) = (0.9, 1.1);
/// Girths searched, multiples of the canonical radii.
const GIRTH: (f64, f64) = (0.6, 2.0);
/// Frames a fit scores (spread evenly over those collected): enough to
/// see several poses, few enough that the fit costs less than the
/// tracking of the seconds it looks at.
const FIT_FRAMES: usize = 6;
/// Rounds of the coordinate search (the steps halve each round): a first
/// fit's, and a refinement's, which starts from steps half as long.
const ROUNDS: usize = 3;
const REFINE_ROUNDS: usize = 2;
/// Golden-section steps of each frame's distance search.
const DEPTH_STEPS: usize = 4;
/// Mean log R per frame a fit must gain over the body it started from to
/// be taken: with six coordinates to turn, a fit always gains a little on
/// the frames it saw; on the tracker's own capsules it gained 0.003–0.012,
/// and taking it drew them worse (upper body 22 mm against 16 mm over 5
/// seeds); the test bodies of other builds gain 0.08–0.4.
const MIN_GAIN: f64 = 0.02;
/// Likelihood evaluations of one frame's placement.
const PLACEMENT_SCORES: u64 = 2 + DEPTH_STEPS as u64;
/// How far the distance search looks either side of where the change of
/// height alone would move the person, meters.
const DEPTH_REACH_M: f64 = 0.45;

/// How the tracker calibrates the body.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CalibrationParams {
    /// Seconds of frames (from the first silhouette) the first fit uses.
    pub window_s: f64,
    /// Frames showing the whole person a fit needs.
    pub min_frames: usize,
    /// Seconds after the first silhouette when a tracker that has not yet
    /// seen enough whole frames gives up and keeps the canonical body.
    pub give_up_s: f64,
    /// Seconds between later refinements, each over the last `window_s`.
    pub refine_every_s: f64,
    /// How far a refinement moves the build towards its own fit.
    pub refine_rate: f64,
    /// The person's standing height (m) when held, and why (told, or the
    /// one an estimated camera scaled the scene to; never
    /// [`HeightFrom::Fit`]): then only the limbs' shares and the girths
    /// are fitted.
    pub held: Option<(f64, HeightFrom)>,
}

/// Where the drawn body's height comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HeightFrom {
    /// Fitted to the silhouettes.
    Fit,
    /// Told (`--height`).
    Option,
    /// Held at the height an estimated camera scaled the scene to: one
    /// camera cannot tell a tall person far away from a short one near.
    Camera,
}

impl CalibrationParams {
    /// What `imitate track` does: fit on the first 2 s, refine every 6 s
    /// by a quarter.
    pub fn standard(height_m: Option<f64>) -> CalibrationParams {
        CalibrationParams {
            window_s: 2.0,
            min_frames: 6,
            give_up_s: 10.0,
            refine_every_s: 6.0,
            refine_rate: 0.25,
            held: height_m.map(|h| (h, HeightFrom::Option)),
        }
    }

    /// These settings with the height held at the `height_m` an estimated
    /// camera scaled the scene to.
    pub fn holding_camera_height(self, height_m: f64) -> CalibrationParams {
        CalibrationParams { held: Some((height_m, HeightFrom::Camera)), ..self }
    }

    /// The held height, meters, if any.
    pub fn held_height(&self) -> Option<f64> {
        self.held.map(|(h, _)| h)
    }

    pub fn height_from(&self) -> HeightFrom {
        self.held.map_or(HeightFrom::Fit, |(_, from)| from)
    }
}

/// The drawn body: its skeleton and how thick its parts are.
#[derive(Clone, Debug, PartialEq)]
pub struct Physique {
    pub body: Body,
    pub girth: Girth,
}

impl Physique {
    pub fn canonical() -> Physique {
        Physique { body: Body::standard(), girth: Girth::CANONICAL }
    }
}

/// The searched coordinates: standing height (m), arm and leg shares,
/// then the girths of trunk, arms and legs. The head's girth is not
/// searched: heads vary little, and a few pixels of head cannot tell it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Coordinates([f64; 6]);

const HEIGHT: usize = 0;

impl Coordinates {
    fn of(p: &Physique) -> Coordinates {
        let (b, g) = (&p.body, &p.girth);
        let (arms, legs) = b.shares();
        Coordinates([b.standing_height(), arms, legs, g.trunk, g.arms, g.legs])
    }

    fn physique(&self) -> Physique {
        let [height, arms, legs, trunk, arm_girth, leg_girth] = self.0;
        Physique {
            body: Body::of_shares(height, arms, legs),
            girth: Girth { head: 1.0, trunk, arms: arm_girth, legs: leg_girth },
        }
    }

    fn bounds(c: usize) -> (f64, f64) {
        match c {
            HEIGHT => HEIGHT_M,
            1 | 2 => LIMB_SHARE,
            _ => GIRTH,
        }
    }

    /// First steps of the search, per coordinate.
    const STEPS: [f64; 6] = [0.12, 0.05, 0.05, 0.2, 0.2, 0.2];
}

/// A build `rate` of the way from `from` to `to`, coordinate by coordinate.
pub fn blend(from: &Physique, to: &Physique, rate: f64) -> Physique {
    let (a, b) = (Coordinates::of(from), Coordinates::of(to));
    Coordinates(std::array::from_fn(|c| a.0[c] + rate * (b.0[c] - a.0[c]))).physique()
}

/// A frame the fit looks at: its silhouette and the pose tracked in it.
#[derive(Clone, Debug)]
pub struct Sample {
    pub sighting: Sighting,
    pub pose: Pose,
}

/// What calibration found, as `summary.json` reports it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CalibrationReport {
    /// Whether a fit was made; when not, `note` says why.
    pub calibrated: bool,
    pub note: Option<String>,
    /// Standing height, meters, and its standard error over the frames
    /// (each frame's own best height, spread over √frames); 0 when given.
    pub height_m: f64,
    pub height_se_m: f64,
    /// Whether `--height` told it; `height_from` says more.
    pub height_given: bool,
    pub height_from: HeightFrom,
    /// Arm and leg length as multiples of the canonical shares of height.
    pub arm_share: f64,
    pub leg_share: f64,
    pub girth: Girth,
    /// Frames the first fit scored, and refinements taken since.
    pub frames: usize,
    pub refinements: usize,
    /// Mean log R gained per frame by the first fit over the body it
    /// started from: how much the build explains.
    pub log_likelihood_gain: f64,
    /// Likelihood evaluations the fits made.
    pub evaluations: u64,
}

impl CalibrationReport {
    /// Nothing fitted yet: the canonical body is drawn (`height_from`
    /// says what will set the height once a fit is made).
    pub fn canonical(height_from: HeightFrom) -> CalibrationReport {
        let p = Physique::canonical();
        CalibrationReport {
            calibrated: false,
            note: None,
            height_m: p.body.standing_height(),
            height_se_m: 0.0,
            height_given: height_from == HeightFrom::Option,
            height_from,
            arm_share: 1.0,
            leg_share: 1.0,
            girth: p.girth,
            frames: 0,
            refinements: 0,
            log_likelihood_gain: 0.0,
            evaluations: 0,
        }
    }
}

/// A fitted build and where it puts the last sample's root.
#[derive(Clone, Debug)]
pub struct Fit {
    /// Whether the build explains the frames better than the one it
    /// started from by `MIN_GAIN`.
    pub accepted: bool,
    pub physique: Physique,
    /// The last sample's pose re-rooted for the fitted build.
    pub last_pose: Pose,
    pub height_se_m: f64,
    pub frames: usize,
    pub log_likelihood_gain: f64,
    /// Likelihood evaluations the fit made.
    pub evaluations: u64,
}

/// Whether a silhouette shows the whole person: its person's regions
/// (specks aside) are not empty and does not touch the frame's border (a cut-off
/// body would be fitted too small).
pub fn whole(mask: &Mask) -> bool {
    let person = person_region(mask);
    person.count() > 0 && !touches_border(&person)
}

/// Whether any pixel of `mask` lies on the frame's border.
pub fn touches_border(mask: &Mask) -> bool {
    let (w, h) = (mask.width(), mask.height());
    (0..w).any(|i| mask.get(i, 0) || mask.get(i, h - 1)) || (0..h).any(|j| mask.get(0, j) || mask.get(w - 1, j))
}

/// Fits the build to `samples` (poses tracked with `start`), starting
/// from `start`; a refinement searches nearer and shorter. `height_m`
/// fixes the height. `None` without samples.
pub fn fit(camera: &Camera, samples: &[Sample], start: &Physique, height_m: Option<f64>, refine: bool) -> Option<Fit> {
    let last = samples.last()?;
    let chosen: Vec<&Sample> = spread(samples, FIT_FRAMES);
    let scorers = || Scorer::new(camera.clone(), start.body.clone());
    let placements = std::cell::Cell::new(0u64);
    let score = |build: &Coordinates| -> f64 {
        placements.set(placements.get() + chosen.len() as u64);
        let physique = build.physique();
        let scores: Vec<f64> = chosen
            .par_iter()
            .map_init(scorers, |scorer, s| placed(scorer, camera, s, start, &physique).0.ln())
            .collect();
        scores.iter().sum()
    };
    let mut build = Coordinates::of(start);
    if let Some(h) = height_m {
        build.0[HEIGHT] = h;
    }
    let initial = score(&Coordinates::of(start));
    let mut best = score(&build);
    let (mut steps, rounds) =
        if refine { (Coordinates::STEPS.map(|s| s / 2.0), REFINE_ROUNDS) } else { (Coordinates::STEPS, ROUNDS) };
    for _ in 0..rounds {
        for (c, &step) in steps.iter().enumerate() {
            if c == HEIGHT && height_m.is_some() {
                continue;
            }
            let (low, high) = Coordinates::bounds(c);
            // The height steps as a share of itself.
            let step = if c == HEIGHT { step * build.0[c] } else { step };
            for sign in [1.0, -1.0] {
                let mut candidate = build;
                candidate.0[c] = (build.0[c] + sign * step).clamp(low, high);
                if candidate == build {
                    continue;
                }
                let s = score(&candidate);
                if s > best {
                    (build, best) = (candidate, s);
                    break;
                }
            }
        }
        steps.iter_mut().for_each(|s| *s /= 2.0);
    }
    let physique = build.physique();
    let height_se_m = if height_m.is_some() {
        0.0
    } else {
        placements.set(placements.get() + 3 * chosen.len() as u64);
        height_spread(camera, &chosen, start, &build)
    };
    let mut scorer = scorers();
    let (_, last_pose) = placed(&mut scorer, camera, last, start, &physique);
    let log_likelihood_gain = (best - initial) / chosen.len() as f64;
    Some(Fit {
        accepted: log_likelihood_gain >= MIN_GAIN,
        physique,
        last_pose,
        height_se_m,
        frames: chosen.len(),
        log_likelihood_gain,
        evaluations: (placements.get() + 1) * PLACEMENT_SCORES,
    })
}

/// Up to `count` samples spread evenly over `samples`, the last included.
fn spread<T>(samples: &[T], count: usize) -> Vec<&T> {
    let n = samples.len();
    if n <= count {
        return samples.iter().collect();
    }
    (0..count).map(|k| &samples[(n - 1) - (count - 1 - k) * (n - 1) / (count - 1)]).collect()
}

/// The lowest of the feet's joints and toe tips above the floor.
fn lowest_foot(body: &Body, pose: &Pose) -> f64 {
    let frame = body.forward(pose);
    [Joint::LeftAnkle, Joint::RightAnkle]
        .into_iter()
        .flat_map(|j| [frame.position(j).y, frame.bone_end(body, j).y])
        .fold(f64::INFINITY, f64::min)
}

/// The sample's pose for `physique` (tracked with `start`): standing on
/// the floor (its lowest foot as high as at rest: the tracked root's
/// height is not trusted, since a body of the wrong size is moved up or
/// down to fit), its distance from the camera along the floor searched.
/// Returns R there and the pose.
fn placed(scorer: &mut Scorer, camera: &Camera, sample: &Sample, start: &Physique, physique: &Physique) -> (f64, Pose) {
    scorer.set_shape(physique.body.clone(), physique.girth);
    let body = &physique.body;
    let ratio = body.pelvis_height() / start.body.pelvis_height();
    let mut root = sample.pose.root;
    root.y -= lowest_foot(body, &sample.pose) - lowest_foot(body, &Pose::rest(body));
    let eye = camera.position();
    let along = (root - eye).with_y(0.0);
    let distance = along.length();
    let away = along.try_normalize().unwrap_or(DVec3::Z);
    // A body `ratio` times the size covers the same pixels `ratio` times
    // as far away; the feet on the floor decide from there.
    let guess = distance * (ratio - 1.0);
    let mut at = |offset: f64| {
        let mut pose = sample.pose;
        pose.root = root + away * offset;
        (scorer.score(&sample.sighting, &pose), pose)
    };
    // Golden-section search for the best offset.
    let phi = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = ((guess - DEPTH_REACH_M).max(-distance * 0.5), guess + DEPTH_REACH_M);
    let (mut c, mut d) = (b - phi * (b - a), a + phi * (b - a));
    let (mut fc, mut fd) = (at(c), at(d));
    for _ in 0..DEPTH_STEPS {
        if fc.0 >= fd.0 {
            (b, d, fd) = (d, c, fc);
            c = b - phi * (b - a);
            fc = at(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + phi * (b - a);
            fd = at(d);
        }
    }
    if fc.0 >= fd.0 { fc } else { fd }
}

/// The standard error of the fitted height: each frame's own best height
/// (a parabola through its scores at the fit and 4% either side), their
/// spread over √frames.
fn height_spread(camera: &Camera, chosen: &[&Sample], start: &Physique, build: &Coordinates) -> f64 {
    const STEP: f64 = 0.04;
    let at = |scale: f64| {
        let mut b = *build;
        b.0[HEIGHT] = (b.0[HEIGHT] * scale).clamp(HEIGHT_M.0, HEIGHT_M.1);
        b.physique()
    };
    let [low, mid, high] = [at(1.0 - STEP), at(1.0), at(1.0 + STEP)];
    let bests: Vec<f64> = chosen
        .par_iter()
        .map_init(
            || Scorer::new(camera.clone(), start.body.clone()),
            |scorer, s| {
                let [l, m, h] = [&low, &mid, &high].map(|p| placed(scorer, camera, s, start, p).0.ln());
                let curvature = l - 2.0 * m + h;
                // A frame whose scores do not bend down says nothing of the
                // height: it counts at the edge of the step.
                let vertex =
                    if curvature < 0.0 { (0.5 * (l - h) / curvature).clamp(-1.0, 1.0) } else { (h - l).signum() };
                build.0[HEIGHT] * (1.0 + STEP * vertex)
            },
        )
        .collect();
    let n = bests.len() as f64;
    let mean = bests.iter().sum::<f64>() / n;
    let variance = bests.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (variance / n).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::synth::{Activity, SynthOptions, activity_take};
    use crate::vision::camera::Preset;
    use crate::vision::figure::Build as TestBuild;

    /// Silhouettes of a test body (built unlike the tracker's capsules)
    /// waving, with the true poses as the tracked ones.
    fn samples(build: &TestBuild, camera: &Camera) -> Vec<Sample> {
        let take = activity_take(Activity::WaveH, &SynthOptions { repetitions: 2, seed: 3, ..Default::default() });
        let motion = take.motion.on_body(&build.body());
        (0..motion.poses.len())
            .step_by(motion.poses.len() / 12)
            .map(|t| {
                let pose = motion.poses[t];
                let mut mask = Mask::new(camera.width(), camera.height());
                build.figure(&motion.body, &motion.body.forward(&pose)).draw(camera, &mut mask);
                // The tracker's poses are the canonical body's: its root at
                // the canonical pelvis height.
                let mut canonical = pose;
                canonical.root.y *= Body::standard().pelvis_height() / motion.body.pelvis_height();
                Sample { sighting: Sighting::silhouette(mask), pose: canonical }
            })
            .collect()
    }

    /// Within 4% of the height: a figure and the capsules differ in shape,
    /// so the best-fitting capsules need not be the figure's skeleton (the
    /// lanky build's fit stands 2.015 m for 1.95, its legs a shorter share
    /// and its trunk a longer one; the others come within 1.2 cm).
    #[test]
    fn the_fit_finds_a_test_body_s_height_within_four_percent_and_its_girth_in_order() {
        let camera = Camera::preset(Preset::Front, 160, 120).unwrap();
        let mut trunks = Vec::new();
        for name in ["slight", "average", "heavy", "lanky"] {
            let build = TestBuild::preset(name).unwrap();
            let fit = fit(&camera, &samples(&build, &camera), &Physique::canonical(), None, false).unwrap();
            let found = fit.physique.body.standing_height();
            eprintln!("{name}: {found:.3} m (± {:.3}), girth {:?}", fit.height_se_m, fit.physique.girth);
            assert!((found / build.height_m - 1.0).abs() < 0.04, "{name}: {found:.3} m, built {}", build.height_m);
            assert!(fit.height_se_m > 0.0 && fit.height_se_m < 0.05, "{name}: ± {}", fit.height_se_m);
            assert!(fit.log_likelihood_gain >= 0.0);
            trunks.push(fit.physique.girth.trunk);
        }
        assert!(trunks[0] < trunks[1] && trunks[1] < trunks[2], "trunk girths {trunks:?}");
    }

    #[test]
    fn a_given_height_is_kept() {
        let camera = Camera::preset(Preset::Front, 160, 120).unwrap();
        let build = TestBuild::preset("broad").unwrap();
        let fit = fit(&camera, &samples(&build, &camera), &Physique::canonical(), Some(1.85), false).unwrap();
        assert!((fit.physique.body.standing_height() - 1.85).abs() < 1e-9);
        assert_eq!(fit.height_se_m, 0.0);
    }

    #[test]
    fn only_whole_silhouettes_count() {
        let mut mask = Mask::new(10, 8);
        assert!(!whole(&mask));
        mask.set(4, 4, true);
        assert!(whole(&mask));
        mask.set(0, 5, true);
        assert!(!whole(&mask));
    }

    #[test]
    fn spreading_keeps_the_ends() {
        let items: Vec<usize> = (0..25).collect();
        let picked: Vec<usize> = spread(&items, 5).into_iter().copied().collect();
        assert_eq!(picked, [0, 6, 12, 18, 24]);
        assert_eq!(spread(&items[..3], 5).len(), 3);
    }
}
