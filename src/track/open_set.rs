//! The open set: frames whose activity the vocabulary does not hold are
//! reported unexplained, not forced onto the nearest primitive.

use crate::params::{InvalidField, Params};
use crate::vision::keypoints::{Site, SitePoints};
use crate::vision::scorer::{Fit, Share};
use std::collections::VecDeque;

/// When a frame is reported unexplained: the primitive with the most
/// evidence is asked how much of the frame its estimate accounts for
/// ([`Fit`]); over the observed frames of the last `window_s` seconds, the
/// share explained (pixels or points pooled, so a fragment counts for
/// little) is compared with `min_fit`.
///
/// Keypoints decide where the window has them. They count by how much they
/// move: an activity is what moves, and a still torso and legs that any
/// standing pose matches would otherwise outvote the arms of an activity
/// no primitive performs. A silhouette's overlap is mostly torso and legs
/// whatever the arms do (a walk's poses overlapped energetic waving 0.56,
/// waving's own 0.67), so it judges only without keypoints: it tells a
/// person no primitive's poses cover, or a tracker that lost them, not an
/// unfamiliar arm motion.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct OpenSet {
    pub min_fit: f64,
    pub window_s: f64,
}

impl OpenSet {
    /// Half of what is seen: a pose that overlaps the silhouette by less
    /// than half, or puts fewer than half the (moving) keypoints within
    /// PCK@0.2's tolerance, is not the person's; over half a second.
    pub const STANDARD: OpenSet = OpenSet { min_fit: 0.5, window_s: 0.5 };
}

impl Params for OpenSet {
    type Valid = OpenSet;
    type Error = OpenSetError;

    fn check(&self) -> Result<OpenSet, OpenSetError> {
        if !(0.0..=1.0).contains(&self.min_fit) {
            return Err(OpenSetError::MinFit(self.min_fit));
        }
        if !(self.window_s.is_finite() && self.window_s > 0.0) {
            return Err(OpenSetError::Window(self.window_s));
        }
        Ok(*self)
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum OpenSetError {
    #[error("min_fit: the share of a frame its best primitive must explain lies in [0, 1], not {0}")]
    MinFit(f64),
    #[error("window_s: the open set's window is a positive number of seconds, not {0}")]
    Window(f64),
}

impl InvalidField for OpenSetError {
    fn field(&self) -> &'static str {
        match self {
            OpenSetError::MinFit(_) => "min_fit",
            OpenSetError::Window(_) => "window_s",
        }
    }
}

/// A still point's weight against a moving one's 1: enough that a person
/// standing still is judged by all their points alike.
const STILL_WEIGHT: f64 = 0.1;

/// The open set's memory of the last window of observed frames.
pub struct Judge {
    params: OpenSet,
    window: usize,
    /// Keypoints of the window's frames, each relative to its hips' middle
    /// (when seen): what moves in the body, not the body moving.
    points: VecDeque<SitePoints>,
    fits: VecDeque<Fit>,
}

impl Judge {
    pub fn new(params: OpenSet, frame_time_s: f64) -> Judge {
        let window = (params.window_s / frame_time_s).round().max(1.0) as usize;
        Judge { params, window, points: VecDeque::new(), fits: VecDeque::new() }
    }

    /// Adds a frame's keypoints to the window and weighs each site by how
    /// far (RMS about its mean in the window) it moved: in full from
    /// `tolerance_px` on, `STILL_WEIGHT` when still.
    pub fn site_weights(&mut self, points: &SitePoints, tolerance_px: f64) -> [f64; 15] {
        self.points.push_back(about_hips(points));
        if self.points.len() > self.window {
            self.points.pop_front();
        }
        std::array::from_fn(|i| {
            let seen: Vec<(f64, f64)> = self.points.iter().filter_map(|p| p[i].map(|k| (k.x, k.y))).collect();
            if seen.len() < 2 || tolerance_px <= 0.0 {
                return 1.0;
            }
            let n = seen.len() as f64;
            let (mx, my) = seen.iter().fold((0.0, 0.0), |(x, y), p| (x + p.0 / n, y + p.1 / n));
            let spread = (seen.iter().map(|p| (p.0 - mx).powi(2) + (p.1 - my).powi(2)).sum::<f64>() / n).sqrt();
            STILL_WEIGHT + (1.0 - STILL_WEIGHT) * (spread / tolerance_px).min(1.0)
        })
    }

    /// Whether the window's fits, this frame's `fit` among them, fall
    /// short: the keypoints' where it has any, else the silhouettes'.
    pub fn unexplained(&mut self, fit: Fit) -> bool {
        self.fits.push_back(fit);
        if self.fits.len() > self.window {
            self.fits.pop_front();
        }
        let (mut silhouette, mut keypoints) = (Share::default(), Share::default());
        for f in &self.fits {
            f.silhouette.into_iter().for_each(|s| silhouette.add(s));
            f.keypoints.into_iter().for_each(|k| keypoints.add(k));
        }
        let judged = if keypoints.seen > 0.0 { keypoints } else { silhouette };
        judged.value() < self.params.min_fit
    }
}

/// `points` relative to the middle of their hips, when both show.
fn about_hips(points: &SitePoints) -> SitePoints {
    let (Some(l), Some(r)) = (points[Site::LeftHip.index()], points[Site::RightHip.index()]) else {
        return *points;
    };
    let (cx, cy) = ((l.x + r.x) / 2.0, (l.y + r.y) / 2.0);
    points.map(|p| p.map(|k| crate::vision::keypoints::Keypoint { x: k.x - cx, y: k.y - cy, ..k }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vision::keypoints::Keypoint;

    fn points(wrist_x: f64) -> SitePoints {
        let mut p: SitePoints = [None; 15];
        let at = |x, y| Some(Keypoint { x, y, confidence: 1.0 });
        p[Site::LeftHip.index()] = at(90.0, 100.0);
        p[Site::RightHip.index()] = at(110.0, 100.0);
        p[Site::LeftShoulder.index()] = at(90.0, 60.0);
        p[Site::LeftWrist.index()] = at(wrist_x, 80.0);
        p
    }

    #[test]
    fn sites_weigh_by_how_far_they_move_about_the_hips() {
        let mut judge = Judge::new(OpenSet::STANDARD, 0.1);
        // The whole body steps sideways each frame while the wrist swings
        // ±10 px about the hips: only the wrist moves.
        let mut last = [0.0; 15];
        for k in 0..5 {
            let shift = 7.0 * k as f64;
            let mut p = points(70.0 + if k % 2 == 0 { 10.0 } else { -10.0 });
            p.iter_mut().flatten().for_each(|q| q.x += shift);
            last = judge.site_weights(&p, 8.0);
        }
        assert_eq!(last[Site::LeftShoulder.index()], STILL_WEIGHT);
        assert_eq!(last[Site::LeftWrist.index()], 1.0);
        // Unseen sites, and a first frame, weigh in full.
        assert_eq!(last[Site::Nose.index()], 1.0);
        assert_eq!(Judge::new(OpenSet::STANDARD, 0.1).site_weights(&points(70.0), 8.0), [1.0; 15]);
    }

    #[test]
    fn the_window_pools_what_was_explained_of_what_was_seen() {
        let share = |explained, seen| Some(Share { explained, seen });
        let keypoints = |explained, seen| Fit { silhouette: None, keypoints: share(explained, seen) };
        // Half a second at 10 frames a second: five frames.
        let mut judge = Judge::new(OpenSet::STANDARD, 0.1);
        // A frame of few points, all missed, counts for little beside one
        // of many, all explained.
        assert!(judge.unexplained(keypoints(0.0, 0.5)));
        assert!(!judge.unexplained(keypoints(4.0, 4.0)));
        // Missed frames of two points each: the first still pools with
        // the explained one (4 of 6.5), five push it out of the window.
        let missed: Vec<bool> = (0..5).map(|_| judge.unexplained(keypoints(0.0, 2.0))).collect();
        assert_eq!(missed, [false, true, true, true, true]);
        // Keypoints decide where there are any; else the silhouette.
        let mut judge = Judge::new(OpenSet::STANDARD, 0.1);
        assert!(!judge.unexplained(Fit { silhouette: share(1.0, 4.0), keypoints: share(4.0, 4.0) }));
        assert!(!judge.unexplained(Fit { silhouette: share(1.0, 4.0), keypoints: None }));
        let mut judge = Judge::new(OpenSet::STANDARD, 0.1);
        assert!(judge.unexplained(Fit { silhouette: share(1.0, 4.0), keypoints: None }));
        assert!(!judge.unexplained(Fit { silhouette: share(300.0, 400.0), keypoints: None }));
    }

    #[test]
    fn impossible_settings_are_refused() {
        assert_eq!(OpenSet { min_fit: 1.5, ..OpenSet::STANDARD }.check(), Err(OpenSetError::MinFit(1.5)));
        assert_eq!(OpenSet { window_s: 0.0, ..OpenSet::STANDARD }.check(), Err(OpenSetError::Window(0.0)));
        assert!(OpenSet { min_fit: f64::NAN, ..OpenSet::STANDARD }.check().is_err());
        assert_eq!(OpenSet::STANDARD.check(), Ok(OpenSet::STANDARD));
    }
}
