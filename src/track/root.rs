//! The global root (pelvis position and heading) each primitive's filter
//! keeps apart from its latent pose, as in the paper: placed from the
//! silhouette, then refined by Gaussian steps kept only when the
//! likelihood rises.

use crate::mocap::body::{Body, Joint, JointVector};
use crate::mocap::pose::Pose;
use crate::vision::camera::Camera;
use crate::vision::keypoints::{Site, SitePoints};
use crate::vision::mask::Mask;
use crate::vision::scorer::Scorer;
use crate::vision::sighting::Sighting;
use crate::vision::silhouette::person_region;
use glam::DVec3;
use rand::Rng;
use rand_distr::StandardNormal;

/// The pelvis's world position (m) and the body's turn about +Y (rad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Root {
    pub position: DVec3,
    pub heading: f64,
}

/// Gaussian step sizes of the root search.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RootSearch {
    /// Hill-climbing steps per frame.
    pub steps: usize,
    /// Standard deviation of a step's move, meters.
    pub move_m: f64,
    /// Standard deviation of a step's turn, radians.
    pub turn_rad: f64,
}

impl Root {
    /// Where a standing person's pelvis is, from their silhouette. Seen
    /// from the side (a camera looking less than 45° down), the ray through
    /// the silhouette's centre column at its lowest row meets the floor
    /// (y = 0) at the feet, and the pelvis stands `pelvis_height` above
    /// them; where that ray misses the floor (a camera looking up), the
    /// person is put at the distance of the camera's `look_at`. Seen from
    /// above, the lowest row is no longer the feet, and the ray through the
    /// silhouette's centre of mass meets the pelvis's height near the
    /// pelvis. Only the person's regions count. `None` for an
    /// empty silhouette.
    pub fn from_silhouette(camera: &Camera, mask: &Mask, pelvis_height: f64, heading: f64) -> Option<Root> {
        let Footprint { u, v, bottom } = Footprint::of(mask)?;
        let origin = camera.position();
        let look_at = DVec3::from_array(camera.spec().look_at);
        let forward = (look_at - origin).normalize();
        let meet = |ray: DVec3, height: f64| (ray.y < -1e-6).then(|| origin + ray * ((height - origin.y) / ray.y));
        let ground = if forward.y < -std::f64::consts::FRAC_1_SQRT_2 {
            meet(camera.ray(u, v), pelvis_height)
        } else {
            meet(camera.ray(u, bottom), 0.0)
        };
        let at = ground.unwrap_or_else(|| origin + camera.ray(u, bottom) * (look_at - origin).length());
        Some(Root { position: DVec3::new(at.x, pelvis_height, at.z), heading })
    }

    /// Where a standing person's pelvis is, from their keypoints: the ray
    /// through the ankles' midpoint meets the height the ankles have at
    /// rest, or without ankles the ray through the hips' midpoint meets
    /// the hips'. `None` without either, or where the ray misses.
    pub fn from_keypoints(camera: &Camera, points: &SitePoints, body: &Body) -> Option<Root> {
        let rest = body.forward(&Pose::rest(body));
        let middle = |a: Site, b: Site| {
            let seen: Vec<_> = [a, b].iter().filter_map(|s| points[s.index()]).collect();
            (!seen.is_empty()).then(|| {
                let n = seen.len() as f64;
                (seen.iter().map(|k| k.x).sum::<f64>() / n, seen.iter().map(|k| k.y).sum::<f64>() / n)
            })
        };
        let ((u, v), height) = match middle(Site::LeftAnkle, Site::RightAnkle) {
            Some(at) => (at, rest.position(Joint::LeftAnkle).y),
            None => (middle(Site::LeftHip, Site::RightHip)?, rest.position(Joint::LeftHip).y),
        };
        let (origin, ray) = (camera.position(), camera.ray(u, v));
        let along = (height - origin.y) / ray.y;
        (along.is_finite() && along > 0.0).then(|| {
            let at = origin + ray * along;
            Root { position: DVec3::new(at.x, body.pelvis_height(), at.z), heading: 0.0 }
        })
    }

    /// Moves the root over the floor by how far the silhouette it draws,
    /// `drawn`, is placed from `placed`, where [`Root::from_silhouette`]
    /// put the observed one: both placements then err alike (the toes
    /// standing in front of the pelvis, the row a pixel rounds to), so the
    /// drawn body stands where the person does. Unmoved for an empty
    /// `drawn`.
    pub fn align(&mut self, camera: &Camera, drawn: &Mask, placed: DVec3) {
        if let Some(at) = Root::from_silhouette(camera, drawn, self.position.y, self.heading) {
            self.position += (placed - at.position).with_y(0.0);
        }
    }

    /// This root moved over the floor to above `point`: its height and
    /// heading kept.
    pub fn over(self, point: DVec3) -> Root {
        Root { position: DVec3::new(point.x, self.position.y, point.z), ..self }
    }

    /// Whether the ray through the bottom of the person's regions in
    /// `mask` points below the horizon, as it must for a person standing on
    /// the floor before a camera above it; `true` for an empty mask.
    pub fn feet_below_horizon(camera: &Camera, mask: &Mask) -> bool {
        Footprint::of(mask).is_none_or(|f| camera.ray(f.u, f.bottom).y < 0.0)
    }

    /// The pose with this root and joint-space vector `x`.
    pub fn pose(&self, x: &JointVector) -> Pose {
        Pose { root: self.position, heading: self.heading, x: *x }
    }
}

/// Where the person's regions in a silhouette lie, in pixels.
struct Footprint {
    /// Their centre of mass.
    u: f64,
    v: f64,
    /// The lower edge of their lowest row.
    bottom: f64,
}

impl Footprint {
    /// `None` for an empty silhouette. Only the person's regions count: a
    /// speck below them would put their feet nearer the camera.
    fn of(mask: &Mask) -> Option<Footprint> {
        let mask = &person_region(mask);
        let (mut count, mut sum_x, mut sum_y, mut bottom) = (0usize, 0usize, 0usize, 0usize);
        for (y, row) in mask.pixels().chunks_exact(mask.width()).enumerate() {
            let n = row.iter().filter(|&&p| p != 0).count();
            if n > 0 {
                count += n;
                sum_x += row.iter().enumerate().filter(|(_, p)| **p != 0).map(|(x, _)| x).sum::<usize>();
                sum_y += n * y;
                bottom = y;
            }
        }
        (count > 0).then(|| Footprint {
            u: sum_x as f64 / count as f64 + 0.5,
            v: sum_y as f64 / count as f64 + 0.5,
            bottom: bottom as f64 + 1.0,
        })
    }
}

impl RootSearch {
    /// Hill-climbs `root` for the joint-space pose `x`, which scores
    /// `score` there: `steps` Gaussian moves (one likelihood evaluation
    /// each), each kept when it scores higher. Returns the final score.
    pub fn refine(
        &self,
        root: &mut Root,
        x: &JointVector,
        mut score: f64,
        sighting: &Sighting,
        scorer: &mut Scorer,
        rng: &mut impl Rng,
    ) -> f64 {
        for _ in 0..self.steps {
            let mut gauss = || rng.sample::<f64, _>(StandardNormal);
            let candidate = Root {
                position: root.position + DVec3::new(gauss(), gauss(), gauss()) * self.move_m,
                heading: root.heading + gauss() * self.turn_rad,
            };
            let s = scorer.score(sighting, &candidate.pose(x));
            if s > score {
                (*root, score) = (candidate, s);
            }
        }
        score
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Body;
    use crate::vision::camera::Preset;

    #[test]
    fn the_root_is_placed_under_the_person_from_the_front_side_and_overhead_and_by_the_ankles() {
        let body = Body::standard();
        let mut pose = Pose::rest(&body);
        pose.root = DVec3::new(0.2, body.pelvis_height(), -0.3);
        for preset in [Preset::Front, Preset::Side, Preset::Overhead] {
            let camera = Camera::preset(preset, 160, 120).unwrap();
            let mut scorer = Scorer::new(camera.clone(), body.clone());
            let mask = scorer.draw(&pose).clone();
            let root = Root::from_silhouette(&camera, &mask, body.pelvis_height(), 0.0).unwrap();
            let off = (root.position - pose.root).with_y(0.0).length();
            eprintln!("{preset:?}: placed {off:.3} m from the pelvis");
            // Level cameras see the nearest toe in the lowest row, and at 4 m a
            // row is 8 cm of floor; the hill climb refines it.
            assert!(off < 0.25, "{preset:?}: placed {off:.2} m away");
            assert_eq!(root.position.y, body.pelvis_height());
        }
        // From keypoints: the ankles where the camera sees them.
        let camera = Camera::preset(Preset::Front, 160, 120).unwrap();
        let world = body.forward(&pose);
        let mut points = [None; 15];
        for (site, joint) in [(Site::LeftAnkle, Joint::LeftAnkle), (Site::RightAnkle, Joint::RightAnkle)] {
            let (x, y, _) = camera.project(world.position(joint)).unwrap();
            points[site.index()] = Some(crate::vision::keypoints::Keypoint { x, y, confidence: 1.0 });
        }
        let root = Root::from_keypoints(&camera, &points, &body).unwrap();
        let off = (root.position - pose.root).with_y(0.0).length();
        assert!(off < 0.02, "placed {off:.3} m from the pelvis by its ankles");
        assert!(Root::from_keypoints(&camera, &[None; 15], &body).is_none());
        let empty = Mask::new(160, 120);
        assert!(Root::from_silhouette(&Camera::preset(Preset::Front, 160, 120).unwrap(), &empty, 1.0, 0.0).is_none());
    }
}
