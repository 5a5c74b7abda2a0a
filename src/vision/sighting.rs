//! What one frame shows of the person, the tracker's observation: the
//! silhouette (scored by eq. 8's R), 2-D keypoints from a detector (scored
//! by a Gaussian on the confidence-weighted reprojection error), or both,
//! their scores multiplied.

use crate::mocap::body::{Body, Joint};
use crate::mocap::pose::BodyFrame;
use crate::vision::camera::Camera;
use crate::vision::distance::Observation;
use crate::vision::keypoints::{Site, SitePoints};
use crate::vision::mask::Mask;
use glam::DVec3;

/// A detector's typical error, as a share of the person's torso (the
/// mid-shoulder to mid-hip length): PCK@0.2, the usual bar of a good 2-D
/// pose estimate, is two of these.
pub const KEYPOINT_SIGMA_TORSO_SHARE: f64 = 0.1;

/// PCK@0.2's tolerance, as a share of the torso: a point this near its
/// joint counts as placed.
pub const PCK_TORSO_SHARE: f64 = 2.0 * KEYPOINT_SIGMA_TORSO_SHARE;

/// The largest keypoint energy scored: beyond it every pose explains the
/// points equally badly, and the score stays a positive number.
const MAX_ENERGY: f64 = 600.0;

/// One frame's observation; at least one of the two parts.
#[derive(Clone, Debug)]
pub struct Sighting {
    silhouette: Option<Observation>,
    keypoints: Option<KeypointTarget>,
}

impl Sighting {
    /// The frame's silhouette alone.
    pub fn silhouette(mask: Mask) -> Sighting {
        Sighting { silhouette: Some(Observation::new(mask)), keypoints: None }
    }

    /// A silhouette (`None`, or empty, when the frame shows none) and
    /// keypoints; `None` when neither shows the person.
    pub fn of(silhouette: Option<&Mask>, keypoints: Option<KeypointTarget>) -> Option<Sighting> {
        let silhouette = silhouette.filter(|m| m.count() > 0).map(|m| Observation::new(m.clone()));
        (silhouette.is_some() || keypoints.is_some()).then_some(Sighting { silhouette, keypoints })
    }

    /// The silhouette, when the frame has one.
    pub fn mask(&self) -> Option<&Mask> {
        self.silhouette.as_ref().map(Observation::mask)
    }

    pub fn observation(&self) -> Option<&Observation> {
        self.silhouette.as_ref()
    }

    pub fn keypoints(&self) -> Option<&KeypointTarget> {
        self.keypoints.as_ref()
    }
}

/// A frame's keypoints, in pixels of the frames the camera sees, with the
/// spread their score allows.
#[derive(Clone, Debug, PartialEq)]
pub struct KeypointTarget {
    points: SitePoints,
    /// The Gaussian's standard deviation, pixels.
    sigma_px: f64,
}

impl KeypointTarget {
    /// `points` scored with a standard deviation of `sigma_px`; `None`
    /// without a point, or for a spread that is not a positive number.
    pub fn new(points: SitePoints, sigma_px: f64) -> Option<KeypointTarget> {
        (points.iter().any(Option::is_some) && sigma_px.is_finite() && sigma_px > 0.0)
            .then_some(KeypointTarget { points, sigma_px })
    }

    pub fn points(&self) -> &SitePoints {
        &self.points
    }

    /// Σ c·d² / 2σ² over the points, d each point's distance (pixels) from
    /// where `camera` sees its site on `world`.
    pub fn energy(&self, camera: &Camera, body: &Body, world: &BodyFrame) -> f64 {
        let energy: f64 = self.squared_misses(camera, body, world).map(|(_, (c, d2))| c * d2).sum();
        (energy / (2.0 * self.sigma_px * self.sigma_px)).min(MAX_ENERGY)
    }

    /// How many of the points, weighted by confidence times `weights` (by
    /// site; all 1 when `None`), lie within `tolerance_px` of where
    /// `camera` sees their sites on `world`, and of how many in all.
    pub fn share_within(
        &self,
        camera: &Camera,
        body: &Body,
        world: &BodyFrame,
        tolerance_px: f64,
        weights: Option<&[f64; 15]>,
    ) -> (f64, f64) {
        let (mut within, mut all) = (0.0, 0.0);
        for (i, (c, d2)) in self.squared_misses(camera, body, world) {
            let w = c * weights.map_or(1.0, |w| w[i]);
            all += w;
            if d2 <= tolerance_px * tolerance_px {
                within += w;
            }
        }
        (within, all)
    }

    /// Each point's site index, confidence and squared distance (pixels)
    /// from where `camera` sees its site on `world`.
    fn squared_misses<'a>(
        &'a self,
        camera: &'a Camera,
        body: &'a Body,
        world: &'a BodyFrame,
    ) -> impl Iterator<Item = (usize, (f64, f64))> + 'a {
        Site::ALL.iter().zip(&self.points).enumerate().filter_map(move |(i, (site, point))| {
            let point = point.as_ref()?;
            // A site behind the camera is as far off as a point can count.
            let d2 = camera
                .project(site_position(*site, body, world))
                .map_or(f64::INFINITY, |(u, v, _)| (u - point.x).powi(2) + (v - point.y).powi(2));
            Some((i, (point.confidence, d2)))
        })
    }
}

/// Where the skeleton has `site`. The nose, which the skeleton lacks,
/// stands in front of the head's base, 45% of the head's length up and
/// forward.
pub fn site_position(site: Site, body: &Body, world: &BodyFrame) -> DVec3 {
    let joint = |j: Joint| world.position(j);
    match site {
        Site::Nose => {
            let length = body.bone(Joint::Head).length();
            joint(Joint::Head) + world.rotation(Joint::Head) * (DVec3::new(0.0, 0.45, 0.45) * length)
        }
        Site::Neck => joint(Joint::Neck),
        Site::LeftShoulder => joint(Joint::LeftShoulder),
        Site::RightShoulder => joint(Joint::RightShoulder),
        Site::LeftElbow => joint(Joint::LeftElbow),
        Site::RightElbow => joint(Joint::RightElbow),
        Site::LeftWrist => joint(Joint::LeftWrist),
        Site::RightWrist => joint(Joint::RightWrist),
        Site::MidHip => (joint(Joint::LeftHip) + joint(Joint::RightHip)) / 2.0,
        Site::LeftHip => joint(Joint::LeftHip),
        Site::RightHip => joint(Joint::RightHip),
        Site::LeftKnee => joint(Joint::LeftKnee),
        Site::RightKnee => joint(Joint::RightKnee),
        Site::LeftAnkle => joint(Joint::LeftAnkle),
        Site::RightAnkle => joint(Joint::RightAnkle),
    }
}
