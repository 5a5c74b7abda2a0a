//! A pinhole camera estimated from the silhouettes of a standing person of
//! known (given or assumed) height, for footage that comes with no
//! `camera.json`.
//!
//! The camera is assumed upright (no roll), with square pixels and its
//! principal point at the frame's centre; the focal length comes from the
//! user (`--fov`, `--focal`) or a typical field of view. Each frame that
//! shows the whole person gives the rows of their feet and of the top of
//! their head. For a tilt θ below the horizon and a camera height h, the
//! feet's ray meets the floor at the person's distance, and the head's row
//! there follows from the person's height: the tilt and height that predict
//! every frame's head row best are the camera's. A person seen at several
//! distances fixes both (the horizon is where their feet would vanish); a
//! person standing in one place fixes only a curve of them (a higher camera
//! tilted further down sees the same head and feet rows): a weak prior on
//! the camera's height picks a point of that curve, and other points
//! compete with it, when the person is near, by how well the tracker
//! explains the frames through them (near the person the perspective
//! differs along the curve). The summary says which decided.
//!
//! World frame of the estimate: the floor is y = 0, the camera stands at
//! x = 0 on the +Z side looking towards −Z (a person at heading 0 faces
//! it), and the person's feet on the frames used are on average at z = 0.

use crate::mocap::body::{Body, Joint};
use crate::mocap::pose::Pose;
use crate::track::calibrate::{CalibrationParams, touches_border};
use crate::track::tracker::{TrackParams, Tracker};
use crate::vision::camera::{Camera, CameraSpec};
use crate::vision::mask::Mask;
use crate::vision::silhouette::person_region;
use crate::vocab::vocabulary::Vocabulary;
use glam::DVec3;
use std::sync::Arc;

/// Vertical fields of view `--fov` accepts, degrees.
pub const FOV_DEG: (f64, f64) = (10.0, 150.0);
/// The vertical field of view assumed when none is told: a phone's or a
/// webcam's main camera filming video (about 60° across a 4:3 frame).
pub const DEFAULT_FOV_DEG: f64 = 48.0;
/// The prior on the camera's height above the floor, meters: mean and
/// standard deviation. Hand-held phones, tripods and webcams on desks film
/// people from 0.8 to 2 m; it decides only what the frames cannot.
const CAMERA_HEIGHT_PRIOR_M: (f64, f64) = (1.4, 0.4);
/// A head row's noise as a share of the frame's height: a silhouette's
/// edge, a head bent or turned, a few centimeters of hair.
const ROW_NOISE_SHARE: f64 = 0.01;
/// A frame whose head row misses by more than this many noise units is
/// taken for one where something (a raised hand) stands above the head.
const OUTLIER_UNITS: f64 = 3.0;
/// Within this distance (meters) of a person standing still, the cameras
/// that see their feet and head rows alike are compared by the tracker's
/// likelihood: a camera 0.6 m higher or lower there changes how much nearer
/// the head is than the feet by more than a tenth. Farther, the comparison
/// is noise: on a person 4 m away it chose 1.7 m for a camera 1 m high
/// and doubled the error.
const NEAR_M: f64 = 3.0;
/// The camera heights compared with the prior's choice when the person
/// stands still near the camera, meters: the range people film from.
const PROBE_HEIGHTS_M: [f64; 4] = [0.8, 1.1, 1.7, 2.0];
/// The mean log R per frame another camera of the curve must explain the
/// frames better by than the prior's to be taken: where the perspective
/// hardly differs along the curve, tracking seeds disagree on the best by
/// about this much.
const MIN_PROBE_GAIN: f64 = 0.01;
/// Frames with a silhouette the judge lets the filters lock on in before
/// it counts.
const LOCK_ON_FRAMES: usize = 3;
/// How far apart (as a share of their distance) the person's nearest and
/// farthest tenth of frames must stand for the frames to be fitted one by
/// one: less is sway, and the feet's and head's rows then mostly tell how
/// the person holds themselves.
const MOVED_SHARE: f64 = 0.2;
/// Tilts searched, degrees below the horizon (negative: looking up).
const TILT_DEG: (f64, f64) = (-45.0, 80.0);
/// Camera heights searched, meters.
const HEIGHT_M: (f64, f64) = (0.05, 12.0);
/// Half-width of the column band the head top is looked for in, as a
/// share of the silhouette's height: a head is about a tenth as wide as
/// the person is tall, so a hand raised beside it is not taken for it.
const HEAD_BAND_SHARE: f64 = 0.05;

/// Where the focal length comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Focal {
    /// A vertical field of view, degrees.
    Fov(f64),
    /// Pixels.
    Pixels(f64),
    /// Nothing told: [`DEFAULT_FOV_DEG`].
    Assumed,
}

impl Focal {
    fn pixels(self, frame_height: usize) -> f64 {
        let from_fov = |deg: f64| frame_height as f64 / 2.0 / (deg.to_radians() / 2.0).tan();
        match self {
            Focal::Fov(deg) => from_fov(deg),
            Focal::Pixels(px) => px,
            Focal::Assumed => from_fov(DEFAULT_FOV_DEG),
        }
    }

    fn source(self) -> &'static str {
        match self {
            Focal::Fov(_) => "fov",
            Focal::Pixels(_) => "focal",
            Focal::Assumed => "assumed",
        }
    }
}

/// One whole silhouette's measurements, pixels from the frame's top left.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Standing {
    /// The bottom edge of the lowest row: where the feet meet the floor.
    pub feet_v: f64,
    /// The top edge of the highest row in the head's column band.
    pub head_v: f64,
    /// The silhouette's middle column (the median of its pixels).
    pub u: f64,
}

impl Standing {
    /// The measurements of `mask`'s largest region (specks and fragments
    /// set aside); `None` when it is empty or touches the frame's edge (a
    /// cut-off person is measured too short).
    pub fn measure(mask: &Mask) -> Option<Standing> {
        let region = person_region(mask);
        if touches_border(&region) {
            return None;
        }
        let w = region.width();
        let rows: Vec<(usize, &[u8])> =
            region.pixels().chunks_exact(w).enumerate().filter(|(_, row)| row.iter().any(|&p| p != 0)).collect();
        let (&(top, _), &(bottom, _)) = (rows.first()?, rows.last()?);
        let mut columns = vec![0usize; w];
        for (_, row) in &rows {
            row.iter().enumerate().filter(|(_, p)| **p != 0).for_each(|(x, _)| columns[x] += 1);
        }
        let half = columns.iter().sum::<usize>().div_ceil(2);
        let mut seen = 0;
        let middle = columns.iter().position(|&c| {
            seen += c;
            seen >= half
        })?;
        let band = (HEAD_BAND_SHARE * (bottom + 1 - top) as f64).ceil().max(1.0) as usize;
        let (from, to) = (middle.saturating_sub(band), (middle + band).min(w - 1));
        let head = rows.iter().find(|(_, row)| row[from..=to].iter().any(|&p| p != 0)).map_or(top, |(y, _)| *y);
        Some(Standing { feet_v: (bottom + 1) as f64, head_v: head as f64, u: middle as f64 + 0.5 })
    }
}

/// What the estimate found, as `summary.json` reports it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CameraEstimate {
    /// Frames showing the whole person the estimate used, and how many of
    /// them it set aside (something above the head).
    pub frames: usize,
    pub outliers: usize,
    /// The person's height the scene is scaled to, meters.
    pub person_height_m: f64,
    /// `option` (`--height`) or `assumed` (the canonical body's).
    pub person_height_from: &'static str,
    /// The vertical field of view, degrees, and where it came from:
    /// `fov`, `focal` or `assumed`.
    pub fov_deg: f64,
    pub focal_from: &'static str,
    /// The camera's height above the floor (m), its tilt below the horizon
    /// (degrees) and its distance along the floor to the person (m).
    pub camera_height_m: f64,
    pub tilt_deg: f64,
    pub distance_m: f64,
    /// How far the person's distance varied over the frames, meters.
    pub depth_range_m: f64,
    /// `frames` when the person's changing distance fixed the height and
    /// tilt. When they stood still within `NEAR_M`, the cameras that see
    /// them alike were compared by how well the tracker explains the
    /// frames through each (`probes`, the prior's first): `likelihood` when
    /// one did clearly better than the prior's choice; else, and farther
    /// off, `prior`.
    pub decided_by: &'static str,
    pub probes: Vec<Probe>,
    /// Likelihood evaluations the comparison made (also counted in the
    /// run's).
    pub evaluations: u64,
    /// Root-mean-square head-row residual over the frames kept, pixels.
    pub rms_residual_px: f64,
}

/// One camera of the curve compared, and its score.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Probe {
    pub camera_height_m: f64,
    pub tilt_deg: f64,
    /// The judge's score: the mean log R of the tracker's estimates.
    pub score: f64,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AutoCameraError {
    #[error("no frame showed the whole person standing: a camera cannot be estimated")]
    NoStandingFrame,
    #[error("the silhouettes fit no upright camera (the feet would stand above the horizon)")]
    NoCamera,
}

/// The person the scene is scaled to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Person {
    /// Standing height, meters.
    pub height_m: f64,
    /// How far the toe tips reach in front of the head, meters.
    pub toes_m: f64,
    /// Whether the height was told (`--height`) rather than assumed.
    pub given: bool,
}

impl Person {
    /// The person `body` draws, standing.
    pub fn of(body: &Body, given: bool) -> Person {
        let frame = body.forward(&Pose::rest(body));
        let toes = frame.bone_end(body, Joint::LeftAnkle).z.max(frame.bone_end(body, Joint::RightAnkle).z);
        Person { height_m: body.standing_height(), toes_m: toes - frame.position(Joint::Head).z, given }
    }
}

/// What a camera of one tilt and height is judged with.
struct Geometry<'a> {
    frames: &'a [Standing],
    person: Person,
    /// Focal length and principal row, pixels.
    f: f64,
    cy: f64,
    /// A head row's noise, pixels.
    noise: f64,
}

impl Geometry<'_> {
    /// How many pixels the head row predicted for frame `s` lies below the
    /// measured one, and the person's distance along the floor; `None`
    /// when the feet's ray does not meet the floor.
    fn predict(&self, s: &Standing, tilt: f64, h: f64) -> Option<(f64, f64)> {
        let feet = tilt + ((s.feet_v - self.cy) / self.f).atan();
        if feet <= 1e-3 || feet >= std::f64::consts::FRAC_PI_2 {
            return None;
        }
        // The lowest row is the toes, a little nearer than the head above
        // the ankles (people mostly face the camera).
        let distance = h / feet.tan() + self.person.toes_m;
        let head = ((h - self.person.height_m) / distance).atan();
        let head_v = self.cy + self.f * (head - tilt).tan();
        Some((head_v - s.head_v, distance))
    }

    /// The frames' head-row misfits in noise units, each capped at
    /// [`OUTLIER_UNITS`]; `None` when a frame's feet are at or above the
    /// horizon.
    fn misfit(&self, tilt: f64, h: f64) -> Option<f64> {
        self.frames.iter().try_fold(0.0, |total, s| {
            let (r, _) = self.predict(s, tilt, h)?;
            Some(total + (r / self.noise).powi(2).min(OUTLIER_UNITS.powi(2)))
        })
    }

    /// The misfit and the prior on the camera's height.
    fn cost(&self, tilt: f64, h: f64) -> Option<f64> {
        let prior = ((h - CAMERA_HEIGHT_PRIOR_M.0) / CAMERA_HEIGHT_PRIOR_M.1).powi(2);
        self.misfit(tilt, h).map(|m| m + prior)
    }

    /// The tilt (degrees) at which a camera `h` m high fits the frames
    /// best; `None` when at no tilt do their feet show below the horizon.
    fn tilt_at(&self, h: f64) -> Option<f64> {
        let misfit = |tilt_deg: f64| self.misfit(f64::to_radians(tilt_deg), h);
        let steps = 1250;
        let mut best = (0..=steps)
            .map(|i| TILT_DEG.0 + (TILT_DEG.1 - TILT_DEG.0) * f64::from(i) / f64::from(steps))
            .filter_map(|t| misfit(t).map(|m| (t, m)))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        let mut step = 0.05;
        while step > 1e-4 {
            match [best.0 - step, best.0 + step]
                .into_iter()
                .filter_map(|t| misfit(t).map(|m| (t, m)))
                .find(|c| c.1 < best.1)
            {
                Some(better) => best = better,
                None => step /= 2.0,
            }
        }
        Some(best.0)
    }

    /// The camera tilted `tilt` degrees at `h` m, and its report.
    #[allow(clippy::too_many_arguments)]
    fn camera(
        &self,
        width: usize,
        height: usize,
        tilt: f64,
        h: f64,
        focal: Focal,
        decided_by: &'static str,
        probes: Vec<Probe>,
    ) -> Result<(Camera, CameraEstimate), AutoCameraError> {
        let t = tilt.to_radians();
        let kept: Vec<(f64, f64)> = self
            .frames
            .iter()
            .filter_map(|s| self.predict(s, t, h))
            .filter(|(r, _)| r.abs() <= OUTLIER_UNITS * self.noise)
            .collect();
        let distances: Vec<f64> = kept.iter().map(|(_, d)| *d).collect();
        let distance = median(&distances).ok_or(AutoCameraError::NoCamera)?;
        let nearest = distances.iter().copied().fold(f64::MAX, f64::min);
        let farthest = distances.iter().copied().fold(f64::MIN, f64::max);
        let rms = (kept.iter().map(|(r, _)| r * r).sum::<f64>() / kept.len() as f64).sqrt();
        let position = DVec3::new(0.0, h, distance);
        let look_at = position + DVec3::new(0.0, -t.sin(), -t.cos()) * distance.max(1.0);
        let spec = CameraSpec {
            width: width as u32,
            height: height as u32,
            fx: self.f,
            fy: self.f,
            cx: width as f64 / 2.0,
            cy: self.cy,
            position: position.to_array(),
            look_at: look_at.to_array(),
            up: [0.0, 1.0, 0.0],
        };
        let camera = Camera::new(spec, "the estimated camera").map_err(|_| AutoCameraError::NoCamera)?;
        let report = CameraEstimate {
            frames: self.frames.len(),
            outliers: self.frames.len() - kept.len(),
            person_height_m: self.person.height_m,
            person_height_from: if self.person.given { "option" } else { "assumed" },
            fov_deg: 2.0 * (self.cy / self.f).atan().to_degrees(),
            focal_from: focal.source(),
            camera_height_m: h,
            tilt_deg: tilt,
            distance_m: distance,
            depth_range_m: farthest - nearest,
            decided_by,
            probes,
            evaluations: 0,
            rms_residual_px: rms,
        };
        Ok((camera, report))
    }

    /// The tilt (degrees) and height (m) of least cost: a coarse grid
    /// over tilt and log height, then a pattern search from the best cell
    /// (the capped misfits make the surface bumpy, so no gradient method is
    /// trusted from afar).
    fn search(&self) -> Option<(f64, f64)> {
        let cost = |tilt_deg: f64, h: f64| self.cost(tilt_deg.to_radians(), h);
        let mut best: Option<(f64, f64, f64)> = None;
        let (tilts, heights) = (250usize, 120usize);
        for i in 0..=tilts {
            let tilt = TILT_DEG.0 + (TILT_DEG.1 - TILT_DEG.0) * i as f64 / tilts as f64;
            for k in 0..=heights {
                let h = HEIGHT_M.0 * (HEIGHT_M.1 / HEIGHT_M.0).powf(k as f64 / heights as f64);
                if let Some(c) = cost(tilt, h)
                    && best.is_none_or(|b| c < b.2)
                {
                    best = Some((tilt, h, c));
                }
            }
        }
        let (mut tilt, mut h, mut best_cost) = best?;
        let (mut step_tilt, mut step_h) = (0.5, 0.05);
        while step_tilt > 1e-4 {
            let mut moved = false;
            for (dt, dh) in [(step_tilt, 0.0), (-step_tilt, 0.0), (0.0, step_h), (0.0, -step_h)] {
                let (t, hh) = (tilt + dt, (h + dh).clamp(HEIGHT_M.0, HEIGHT_M.1));
                if let Some(c) = cost(t, hh)
                    && c < best_cost
                {
                    (tilt, h, best_cost, moved) = (t, hh, c, true);
                }
            }
            if !moved {
                step_tilt /= 2.0;
                step_h /= 2.0;
            }
        }
        Some((tilt, h))
    }
}

/// Estimates the camera of `width` × `height` frames from `frames` (whole
/// silhouettes) of `person`. When the person stood still, the cameras of
/// the curve that sees them alike are compared by `judge` (how well the
/// tracker explains the frames through each, higher better, and the
/// likelihood evaluations that cost), the prior's choice among them first.
pub fn estimate(
    width: usize,
    height: usize,
    frames: &[Standing],
    person: Person,
    focal: Focal,
    judge: &mut dyn FnMut(&Camera) -> (f64, u64),
) -> Result<(Camera, CameraEstimate), AutoCameraError> {
    if frames.is_empty() {
        return Err(AutoCameraError::NoStandingFrame);
    }
    let f = focal.pixels(height);
    let noise = (ROW_NOISE_SHARE * height as f64).max(1.0);
    let cy = height as f64 / 2.0;
    // First the camera of the typical frame (each row's median): with
    // one frame the head and feet rows fit exactly along a curve of
    // cameras, and the prior on the height chooses among them.
    let column = |row: fn(&Standing) -> f64| median(&frames.iter().map(row).collect::<Vec<_>>());
    let typical = Standing {
        feet_v: column(|s| s.feet_v).ok_or(AutoCameraError::NoStandingFrame)?,
        head_v: column(|s| s.head_v).ok_or(AutoCameraError::NoStandingFrame)?,
        u: column(|s| s.u).ok_or(AutoCameraError::NoStandingFrame)?,
    };
    let still = Geometry { frames: std::slice::from_ref(&typical), person, f, cy, noise };
    let (tilt, h) = still.search().ok_or(AutoCameraError::NoCamera)?;
    // A person who came nearer or went farther tells the horizon: then
    // every frame is fitted.
    let geometry = Geometry { frames, person, f, cy, noise };
    let distances: Vec<f64> =
        frames.iter().filter_map(|s| geometry.predict(s, tilt.to_radians(), h)).map(|(_, d)| d).collect();
    let (near, far) = (quantile(&distances, 0.1), quantile(&distances, 0.9));
    if far - near > MOVED_SHARE * (near + far) / 2.0
        && let Some((tilt, h)) = geometry.search()
    {
        return geometry.camera(width, height, tilt, h, focal, "frames", Vec::new());
    }
    // Standing still: far off, the curve's cameras see the person alike
    // and the tracker cannot tell them apart; near, they are judged.
    let (camera, report) = geometry.camera(width, height, tilt, h, focal, "prior", Vec::new())?;
    if report.distance_m >= NEAR_M {
        return Ok((camera, report));
    }
    let mut probes = vec![(h, tilt)];
    probes.extend(PROBE_HEIGHTS_M.iter().filter_map(|&hh| still.tilt_at(hh).map(|t| (hh, t))));
    let (mut judged, mut evaluations) = (Vec::new(), 0);
    for (hh, t) in probes {
        // A camera of the curve that keeps no frame is not one to judge.
        if let Ok((camera, _)) = geometry.camera(width, height, t, hh, focal, "", Vec::new()) {
            let (score, spent) = judge(&camera);
            evaluations += spent;
            judged.push(Probe { camera_height_m: hh, tilt_deg: t, score });
        }
    }
    // The prior's camera unless another explains the frames clearly better.
    let prior = *judged.first().ok_or(AutoCameraError::NoCamera)?;
    let best = judged.iter().copied().fold(prior, |b, p| if p.score > b.score { p } else { b });
    let (chosen, decided_by) =
        if best.score > prior.score + MIN_PROBE_GAIN { (best, "likelihood") } else { (prior, "prior") };
    let (camera, report) =
        geometry.camera(width, height, chosen.tilt_deg, chosen.camera_height_m, focal, decided_by, judged)?;
    Ok((camera, CameraEstimate { evaluations, ..report }))
}

/// The `q` quantile of `values` (nearest rank); 0 when empty.
fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(((v.len().max(1) - 1) as f64 * q).round() as usize).copied().unwrap_or(0.0)
}

/// How well the tracker explains `masks` through `camera`: the mean log R
/// (eq. 8) of the frames' arbitrated estimates, once the filters have had
/// `LOCK_ON_FRAMES` frames to lock on. The body is the one `params`
/// start from; it is not fitted here.
/// Also the likelihood evaluations it made.
pub fn explained(vocabulary: &Arc<Vocabulary>, camera: &Camera, masks: &[Mask], params: TrackParams) -> (f64, u64) {
    let held = params.calibration.map(|c| CalibrationParams { window_s: f64::MAX, give_up_s: f64::MAX, ..c });
    let params = TrackParams { calibration: held, ..params };
    let Ok(mut tracker) = Tracker::new(Arc::clone(vocabulary), camera.clone(), params) else {
        return (f64::MIN, 0);
    };
    let (mut total, mut counted, mut seen) = (0.0, 0usize, 0usize);
    for mask in masks {
        let estimate = tracker.step(mask);
        if let Some(r) = estimate.estimates[estimate.winner].likelihood {
            seen += 1;
            if seen > LOCK_ON_FRAMES {
                total += r.max(f64::MIN_POSITIVE).ln();
                counted += 1;
            }
        }
    }
    let score = if counted == 0 { f64::MIN } else { total / counted as f64 };
    (score, tracker.evaluations())
}

fn median(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    (!v.is_empty()).then(|| {
        let n = v.len();
        if n % 2 == 1 { v[n / 2] } else { (v[n / 2 - 1] + v[n / 2]) / 2.0 }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vision::render::draw;
    use crate::vision::shape::capsules;

    fn render_silhouette(cam: &Camera, body: &Body, pose: &Pose) -> Mask {
        let mut mask = Mask::new(cam.width(), cam.height());
        draw(cam, &capsules(body, &body.forward(pose)), &mut mask);
        mask
    }

    /// A camera `h` m up, `tilt` degrees down, `d` m from the origin, with
    /// a vertical field of view `fov` degrees, at 320 × 240.
    fn camera(h: f64, tilt: f64, d: f64, fov: f64) -> Camera {
        let t = f64::to_radians(tilt);
        let f = 120.0 / (fov.to_radians() / 2.0).tan();
        let spec = CameraSpec {
            width: 320,
            height: 240,
            fx: f,
            fy: f,
            cx: 160.0,
            cy: 120.0,
            position: [0.0, h, d],
            look_at: [0.0, h - t.sin(), d - t.cos()],
            up: [0.0, 1.0, 0.0],
        };
        Camera::new(spec, "test").unwrap()
    }

    /// The canonical body standing at each of `places` (x, z), seen by `cam`.
    fn standings(cam: &Camera, places: &[(f64, f64)]) -> Vec<Standing> {
        let body = Body::standard();
        places
            .iter()
            .map(|&(x, z)| {
                let mut pose = Pose::rest(&body);
                pose.root.x = x;
                pose.root.z = z;
                Standing::measure(&render_silhouette(cam, &body, &pose)).unwrap()
            })
            .collect()
    }

    #[test]
    fn a_person_walking_towards_the_camera_fixes_its_height_and_tilt() {
        let person = Person::of(&Body::standard(), false);
        for (h, tilt, d) in [(0.9, 5.0, 4.0), (2.0, 25.0, 4.0), (1.6, 12.0, 5.0)] {
            let cam = camera(h, tilt, d, 50.0);
            let places: Vec<(f64, f64)> = (0..8).map(|k| (0.0, 1.5 - 0.4 * f64::from(k))).collect();
            let (found, report) =
                estimate(320, 240, &standings(&cam, &places), person, Focal::Fov(50.0), &mut |_| (0.0, 0)).unwrap();
            assert_eq!(report.decided_by, "frames", "{report:?}");
            assert!((report.camera_height_m - h).abs() < 0.1, "{h} m: found {report:?}");
            assert!((report.tilt_deg - tilt).abs() < 3.0, "{tilt}°: found {report:?}");
            assert_eq!(found.width(), 320);
        }
    }

    #[test]
    fn a_person_standing_still_is_put_where_their_feet_and_head_are_seen() {
        let body = Body::standard();
        let cam = camera(1.0, 10.0, 4.0, 45.0);
        let frames = standings(&cam, &[(0.3, 0.0)]);
        let (found, report) =
            estimate(320, 240, &frames, Person::of(&body, false), Focal::Fov(45.0), &mut |_| (0.0, 0)).unwrap();
        // 4 m away: the prior decides, and nothing is compared.
        assert_eq!(report.decided_by, "prior");
        assert!(report.probes.is_empty(), "{report:?}");
        let again = Standing::measure(&render_silhouette(&found, &body, &{
            let mut pose = Pose::rest(&body);
            pose.root.x = 0.3;
            pose
        }))
        .unwrap();
        assert!(
            (again.feet_v - frames[0].feet_v).abs() <= 1.0 && (again.head_v - frames[0].head_v).abs() <= 1.0,
            "{again:?} against {:?}; {report:?}",
            frames[0]
        );
        assert!((again.u - frames[0].u).abs() <= 1.0, "{again:?} against {:?}", frames[0]);
    }

    #[test]
    fn an_empty_clip_has_no_camera() {
        assert_eq!(
            estimate(320, 240, &[], Person::of(&Body::standard(), false), Focal::Assumed, &mut |_| (0.0, 0))
                .unwrap_err(),
            AutoCameraError::NoStandingFrame
        );
    }
}
