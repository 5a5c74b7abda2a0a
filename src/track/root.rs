//! The global root (pelvis position and heading) each primitive's filter
//! keeps apart from its latent pose, as in the paper: placed from the
//! silhouette, then refined by Gaussian steps kept only when the
//! likelihood rises.

use crate::mocap::body::JointVector;
use crate::mocap::pose::Pose;
use crate::vision::camera::Camera;
use crate::vision::distance::Observation;
use crate::vision::mask::Mask;
use crate::vision::scorer::Scorer;
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
    /// pelvis. Only the silhouette's largest region counts. `None` for an
    /// empty silhouette.
    pub fn from_silhouette(camera: &Camera, mask: &Mask, pelvis_height: f64, heading: f64) -> Option<Root> {
        // The person's own region: a speck below them would put their
        // feet nearer the camera.
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
        if count == 0 {
            return None;
        }
        let (u, v) = (sum_x as f64 / count as f64 + 0.5, sum_y as f64 / count as f64 + 0.5);
        let origin = camera.position();
        let look_at = DVec3::from_array(camera.spec().look_at);
        let forward = (look_at - origin).normalize();
        let meet = |ray: DVec3, height: f64| (ray.y < -1e-6).then(|| origin + ray * ((height - origin.y) / ray.y));
        let ground = if forward.y < -std::f64::consts::FRAC_1_SQRT_2 {
            meet(camera.ray(u, v), pelvis_height)
        } else {
            meet(camera.ray(u, bottom as f64 + 1.0), 0.0)
        };
        let at = ground.unwrap_or_else(|| origin + camera.ray(u, bottom as f64 + 1.0) * (look_at - origin).length());
        Some(Root { position: DVec3::new(at.x, pelvis_height, at.z), heading })
    }

    /// Whether the ray through the bottom of the person's regions in
    /// `mask` points below the horizon, as it must for a person standing on
    /// the floor before a camera above it; `true` for an empty mask.
    pub fn feet_below_horizon(camera: &Camera, mask: &Mask) -> bool {
        let person = person_region(mask);
        let w = person.width();
        let Some((bottom, row)) = person.pixels().chunks_exact(w).enumerate().rfind(|(_, r)| r.contains(&1)) else {
            return true;
        };
        let columns: Vec<usize> = row.iter().enumerate().filter(|(_, p)| **p != 0).map(|(x, _)| x).collect();
        let middle = columns[columns.len() / 2] as f64 + 0.5;
        camera.ray(middle, bottom as f64 + 1.0).y < 0.0
    }

    /// The pose with this root and joint-space vector `x`.
    pub fn pose(&self, x: &JointVector) -> Pose {
        Pose { root: self.position, heading: self.heading, x: *x }
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
        observation: &Observation,
        scorer: &mut Scorer,
        rng: &mut impl Rng,
    ) -> f64 {
        for _ in 0..self.steps {
            let mut gauss = || rng.sample::<f64, _>(StandardNormal);
            let candidate = Root {
                position: root.position + DVec3::new(gauss(), gauss(), gauss()) * self.move_m,
                heading: root.heading + gauss() * self.turn_rad,
            };
            let s = scorer.score(observation, &candidate.pose(x));
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
    fn the_root_is_placed_under_the_person_from_the_front_side_and_overhead() {
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
        let empty = Mask::new(160, 120);
        assert!(Root::from_silhouette(&Camera::preset(Preset::Front, 160, 120).unwrap(), &empty, 1.0, 0.0).is_none());
    }
}
