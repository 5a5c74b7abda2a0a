//! Standing balance: where the humanoid's weight is against what holds it
//! up (the support polygon, the capture point, the margin between them),
//! and the controller that turns the standing legs to keep the one over
//! the other.

use super::humanoid::{FEET, GRAVITY_M_S2, HIPS, Humanoid, to_f64};
use super::targets::{JointTarget, clamp};
use crate::mocap::body::{JOINTS, Joint};
use glam::{DQuat, DVec2, DVec3};

/// The most the balance may tilt a standing leg about its ankle.
pub(super) const BALANCE_MAX_RAD: f64 = 0.25;
/// How far the balance moves the pelvis for each metre the capture point
/// lies from the middle of the standing soles. The legs' turn moves the
/// centre of mass less than the pelvis (the legs turn with it, partly),
/// and a gain of 1 left a take whose own centre of mass leans off its feet
/// halfway there. Over bandai's 88 standing takes and real/'s 13 (up, RMS
/// joint error where up, worst): 1 kept 80 and 8 (5.3°), 1.5 82 and 9
/// (7.5°), 2 82 and 10 (7.8°), 2.5 81 and 10 (8.4°), 3 80 and 10 (6.5°);
/// from 2 up the pelvis no longer stays level as the legs shift it (a
/// trunk bent 40° sideways tilted it 3.9°, against 1.7° at 1.5).
const CAPTURE_GAIN: f64 = 1.5;
/// The balance also moves the pelvis by the capture point's offset summed
/// over time, this many times per second, up to `GATHERED_MAX_M`. The
/// proportional term alone holds the weight only part of the way back:
/// where the take's own centre of mass lies off its feet on the humanoid's
/// masses (a bow, a weight shift onto one leg), the body settled near the
/// edge of its feet and slowly toppled, its legs at their tilt limit. Over
/// bandai's 88 standing takes and real/'s 13 at 480, 360 and 240 Hz (up),
/// with the dead zone below: none 82, 82, 84 and 12, 12, 12; 1.5/s 86, 84,
/// 84 and 12, 12, 12. Without it, and the shift kept through swings:
/// 0.75/s 85, 84, 85 and 12, 13, 12; 1.5/s 87, 85, 84 and 13, 12, 12; 2.5/s
/// 85, 84, 82 and 12, 13, 12; 4/s 85, 85, 84 and 12, 12, 12.
const GATHER_PER_S: f64 = 1.5;
/// Only the part of the capture point's offset beyond this is gathered, m,
/// so a stance whose weight lies near the middle of its feet keeps the
/// take's pose (without it, a humanoid at rest gathered a 2 cm shift).
/// Over the same takes (1.5/s; up, and the median RMS error where up over
/// bandai's at 480 Hz): none 87, 85, 84 and 13, 12, 13, 1.18°; 1 cm 86,
/// 85, 83 and 12, 12, 12, 1.10°; 2 cm 86, 84, 84 and 12, 12, 12, 1.06°
/// (1.02° gathering nothing).
const GATHER_DEAD_ZONE_M: f64 = 0.02;
/// The most shift the balance gathers, m: the tilt limit's reach at the
/// hips is 0.22 m. Over the same takes (1.5/s, no dead zone, kept through
/// swings): 5 cm 84, 85, 83; 10 cm 87, 85, 84; 20 cm 85, 85, 84.
const GATHERED_MAX_M: f64 = 0.1;
/// How far a standing foot's target is turned from the trajectory's toward
/// lying flat where the foot stands. The trajectory's ankles alone let
/// standing feet roll onto their edges (a retargeted capture's ankles are
/// not a flat foot's; measured on the real captures: soles tipping 5° to
/// 20° while both feet touched); flat alone stays up more but gives up the
/// take's ankle angles. Over bandai's 88 standing takes and real/'s 13:
/// 0 kept 76 and 6 up (RMS error where up 1.2°/4.2° and 2.0°/3.1°, median
/// and worst), ½ 80 and 8 (1.2°/4.5°, 2.0°/2.6°), 0.8 80 and 9 (1.3°/5.5°,
/// 2.5°/9.7°).
const PLANTED_SHARE: f64 = 0.5;
/// A sole corner this close to the ground, on a foot that touches it,
/// bears weight (rapier's soft contacts let a loaded sole sink ~4 mm).
const CONTACT_M: f64 = 0.02;

/// Where the body's weight is against what holds it up, at one instant.
/// Points on the ground are (x, z).
#[derive(Clone, Debug, PartialEq)]
pub struct BalanceState {
    pub com: DVec3,
    pub velocity: DVec3,
    /// The capture point: the centre of mass ahead by its velocity over the
    /// inverted pendulum's frequency √(g/h), where the body comes to rest
    /// over if it does not step.
    pub capture: DVec2,
    /// The centre of mass's height over the standing soles (over the
    /// ground while no foot stands), at least 0.1 m: the inverted
    /// pendulum's length.
    pub height_m: f64,
    /// The support polygon: the convex hull of the sole corners on the
    /// ground; empty while no foot stands.
    pub support: Vec<DVec2>,
    /// The middle of the standing soles, in the world; `None` while no
    /// foot stands.
    pub stance_centre: Option<DVec3>,
    /// The middle of each sole (left, right) while it stands.
    pub sole_middles: [Option<DVec3>; 2],
}

impl BalanceState {
    /// How far the capture point lies inside the support polygon, m: its
    /// distance to the nearest edge, negative outside (against a polygon
    /// without area, a foot on an edge, it is never positive). `None`
    /// while no foot stands.
    pub fn margin_m(&self) -> Option<f64> {
        signed_distance(&self.support, self.capture)
    }
}

impl Humanoid {
    /// The corners of foot `k`'s sole (0 left, 1 right) in the world.
    pub(super) fn sole(&self, k: usize) -> [DVec3; 4] {
        let ankle = &self.world.bodies[self.links[FEET[k].index()]];
        let (at, turn) = (ankle.translation().as_dvec3(), to_f64(*ankle.rotation()));
        self.soles[k].map(|c| at + turn * c)
    }

    /// The centre of mass, its velocity, the capture point and the support
    /// polygon now.
    pub fn balance_state(&self) -> BalanceState {
        let (mut mass, mut moment, mut momentum) = (0.0, DVec3::ZERO, DVec3::ZERO);
        for j in Joint::ALL {
            let rigid = &self.world.bodies[self.links[j.index()]];
            let m = self.inertials[j.index()].mass_kg;
            mass += m;
            moment += m * rigid.center_of_mass().as_dvec3();
            momentum += m * rigid.linvel().as_dvec3();
        }
        let (com, velocity) = (moment / mass, momentum / mass);
        let mut corners = Vec::with_capacity(8);
        let mut sole_middles = [None; 2];
        for (k, foot) in FEET.into_iter().enumerate() {
            if !self.stands(foot) {
                continue;
            }
            let sole = self.sole(k);
            sole_middles[k] = Some(sole.iter().sum::<DVec3>() / 4.0);
            corners.extend(sole.iter().filter(|c| c.y < CONTACT_M).map(|c| DVec2::new(c.x, c.z)));
        }
        let (sum, standing) = sole_middles.iter().flatten().fold((DVec3::ZERO, 0), |(sum, n), &m| (sum + m, n + 1));
        let stance_centre = (standing > 0).then(|| sum / f64::from(standing));
        let ground = stance_centre.map_or(0.0, |c| c.y);
        let height_m = (com.y - ground).max(0.1);
        let ahead = com + velocity / (GRAVITY_M_S2 / height_m).sqrt();
        BalanceState {
            com,
            velocity,
            capture: DVec2::new(ahead.x, ahead.z),
            height_m,
            support: convex_hull(corners),
            stance_centre,
            sole_middles,
        }
    }

    /// Turns the standing legs' `targets` so that the body shifts over its
    /// standing feet to bring its centre of mass back over them. The correction
    /// moves the capture point toward the middle of the standing soles (or of
    /// foot `onto`'s, 0 left and 1 right, while it stands: where the take
    /// already stands on that foot alone, the weight moves onto it before the
    /// other foot lifts), `CAPTURE_GAIN` times as far as it is off plus the
    /// shift gathered from how far beyond `GATHER_DEAD_ZONE_M` it has been
    /// off over time (`GATHER_PER_S`), up to `BALANCE_MAX_RAD` of tilt. Each
    /// standing leg tilts about its ankle by the same turn in the world and
    /// its hip turns back by it, so the legs move as a parallelogram: the
    /// pelvis and all above it shift without turning. Tilting the whole body
    /// about the feet instead (the ankle strategy alone) cannot shift it
    /// sideways while both feet stand, as turning about one ankle's forward
    /// axis lifts the other foot (measured: 1 of 23 real captures stayed up
    /// that way, falling sideways with the ankles at their tilt limit).
    /// Nothing changes while no foot stands, and the gathered shift is let
    /// go. `state` is [`Humanoid::balance_state`] now, which the caller
    /// shares with the assistance.
    pub fn balance(&mut self, targets: &mut [JointTarget; JOINTS], onto: Option<usize>, state: &BalanceState) {
        let Some(support) = onto.and_then(|k| state.sole_middles[k]).or(state.stance_centre) else {
            self.gathered_shift = DVec3::ZERO;
            return;
        };
        let off = DVec3::new(support.x - state.capture.x, 0.0, support.z - state.capture.y);
        let dt_s = f64::from(self.world.integration_parameters.dt);
        let beyond = off * ((off.length() - GATHER_DEAD_ZONE_M).max(0.0) / off.length().max(f64::EPSILON));
        self.gathered_shift = (self.gathered_shift + GATHER_PER_S * dt_s * beyond).clamp_length_max(GATHERED_MAX_M);
        let shift = CAPTURE_GAIN * off + self.gathered_shift;
        // Turning a leg by θ about its ankle moves its hip, h above it, by
        // θ × h·Y; θ = Y × shift / h moves the pelvis by `shift`.
        let pelvis = self.rotation(Joint::Pelvis);
        let hip_height =
            (self.world.bodies[self.links[Joint::Pelvis.index()]].translation().as_dvec3().y - support.y).max(0.1);
        let tilt = (DVec3::Y.cross(shift) / hip_height).clamp_length_max(BALANCE_MAX_RAD);
        let turn = DQuat::from_scaled_axis(tilt);
        for k in (0..2).filter(|&k| self.stands(FEET[k])) {
            // The shank turned by `turn` in the world over a foot that
            // stays, and the thigh with it under a pelvis that stays.
            self.plant(targets, k, turn);
            let (hip, thigh) = (HIPS[k], &mut targets[HIPS[k].index()]);
            thigh.rotation = clamp(hip, pelvis.inverse() * turn * pelvis * thigh.rotation).0;
        }
    }

    /// Asks standing foot `k`'s sole to stay halfway between where the
    /// trajectory turns it and flat where it stands (`PLANTED_SHARE`) while
    /// its shank turns by `turn` in the world.
    pub(super) fn plant(&self, targets: &mut [JointTarget; JOINTS], k: usize, turn: DQuat) {
        let foot = FEET[k];
        let shank = self.rotation(foot.parent().expect("only the pelvis has no parent"));
        let sole = self.rotation(foot);
        let flat = DQuat::from_rotation_arc(sole * DVec3::Y, DVec3::Y) * sole;
        let ankle = &mut targets[foot.index()];
        let asked = (shank * ankle.rotation).slerp(flat, PLANTED_SHARE);
        ankle.rotation = clamp(foot, shank.inverse() * turn.inverse() * asked).0;
    }
}

/// The convex hull of `points`, each edge turning left to the next (a
/// positive perp_dot, the orientation [`signed_distance`] expects), without
/// repeated or collinear points (Andrew's monotone chain).
pub(super) fn convex_hull(mut points: Vec<DVec2>) -> Vec<DVec2> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let turns_left = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o) > 0.0;
    let mut hull: Vec<DVec2> = Vec::with_capacity(points.len() + 1);
    for pass in [&points[..], &points.iter().rev().copied().collect::<Vec<_>>()[..]] {
        let floor = hull.len();
        for &p in pass {
            while hull.len() >= floor + 2 && !turns_left(hull[hull.len() - 2], hull[hull.len() - 1], p) {
                hull.pop();
            }
            hull.push(p);
        }
        // Each pass's last point starts the other.
        hull.pop();
    }
    hull
}

/// The point nearest `p` on the straight way from it to the middle of the
/// convex polygon `hull` (the mean of its corners) that lies at least
/// `inset` inside it: `p` itself if it does, the middle if no point does.
pub(super) fn brought_inside(hull: &[DVec2], p: DVec2, inset: f64) -> DVec2 {
    let inside = |q: DVec2| signed_distance(hull, q).is_some_and(|d| d >= inset);
    if hull.is_empty() || inside(p) {
        return p;
    }
    let middle = hull.iter().sum::<DVec2>() / hull.len() as f64;
    if !inside(middle) {
        return middle;
    }
    // The distance inside grows along the way (the polygon is convex):
    // halve the share of the way that is known to reach the inset.
    let (mut short, mut far) = (0.0, 1.0);
    for _ in 0..40 {
        let half = 0.5 * (short + far);
        if inside(p.lerp(middle, half)) {
            far = half;
        } else {
            short = half;
        }
    }
    p.lerp(middle, far)
}

/// The distance from `p` to the nearest edge of the convex polygon `hull`
/// (as [`convex_hull`] orders it), positive inside, negative outside;
/// `None` for no polygon.
fn signed_distance(hull: &[DVec2], p: DVec2) -> Option<f64> {
    let to_segment = |a: DVec2, b: DVec2| {
        let along = b - a;
        let t = if along.length_squared() > 0.0 {
            ((p - a).dot(along) / along.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + t * along).distance(p)
    };
    match hull.len() {
        0 => None,
        1 => Some(-hull[0].distance(p)),
        2 => Some(-to_segment(hull[0], hull[1])),
        n => {
            let edges = (0..n).map(|i| (hull[i], hull[(i + 1) % n]));
            let inside = edges.clone().all(|(a, b)| (b - a).perp_dot(p - a) >= 0.0);
            let nearest = edges.map(|(a, b)| to_segment(a, b)).fold(f64::INFINITY, f64::min);
            Some(if inside { nearest } else { -nearest })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_margin_is_the_distance_to_the_nearest_edge_inside_and_negative_outside() {
        // Two feet side by side, corners in any order, one repeated, one
        // on an edge.
        let corners = [(0.0, 0.0), (0.1, 0.0), (0.1, 0.2), (0.0, 0.2), (0.3, 0.0), (0.4, 0.0), (0.4, 0.2), (0.3, 0.2)]
            .map(|(x, z)| DVec2::new(x, z));
        let mut points = corners.to_vec();
        points.extend([corners[2], DVec2::new(0.2, 0.0)]);
        points.reverse();
        let hull = convex_hull(points);
        assert_eq!(hull.len(), 4, "{hull:?}");
        let close = |got: Option<f64>, want: f64| (got.unwrap() - want).abs() < 1e-12;
        assert!(close(signed_distance(&hull, DVec2::new(0.2, 0.1)), 0.1));
        assert!(close(signed_distance(&hull, DVec2::new(0.2, 0.05)), 0.05));
        assert!(close(signed_distance(&hull, DVec2::new(0.2, 0.5)), -0.3));
        assert!(close(signed_distance(&hull, DVec2::new(0.7, 0.6)), -0.5));
        // One foot on its edge: a segment, never positive.
        let edge = convex_hull(vec![DVec2::ZERO, DVec2::new(0.0, 0.2)]);
        assert!(close(signed_distance(&edge, DVec2::new(0.0, 0.1)), 0.0));
        assert!(close(signed_distance(&edge, DVec2::new(0.1, 0.1)), -0.1));
        assert_eq!(signed_distance(&[], DVec2::ZERO), None);
    }

    #[test]
    fn a_point_is_brought_the_inset_inside_on_its_way_to_the_middle() {
        let square =
            convex_hull([(0.0, 0.0), (0.4, 0.0), (0.4, 0.4), (0.0, 0.4)].map(|(x, z)| DVec2::new(x, z)).to_vec());
        let close = |a: DVec2, b: DVec2| a.distance(b) < 1e-9;
        // Behind the square's middle: straight in to 0.1 inside.
        assert!(close(brought_inside(&square, DVec2::new(0.2, -0.3), 0.1), DVec2::new(0.2, 0.1)));
        // Already that far inside: left alone.
        assert!(close(brought_inside(&square, DVec2::new(0.15, 0.3), 0.1), DVec2::new(0.15, 0.3)));
        // An inset no point reaches: the middle.
        assert!(close(brought_inside(&square, DVec2::new(0.9, 0.9), 0.3), DVec2::new(0.2, 0.2)));
        assert!(close(brought_inside(&[], DVec2::ONE, 0.1), DVec2::ONE));
    }
}
