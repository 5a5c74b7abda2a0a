//! The take set over the humanoid's feet before it is played. A
//! retargeted capture keeps the person's joint angles, not their balance:
//! on the canonical body's masses and feet, a take standing still may hold
//! its centre of mass over its heels or the outer edge of a foot (bandai's
//! musical guide: 6 cm behind the ankles, the heel's edge 6.4 cm behind),
//! and the humanoid starts falling on the first frame, faster than
//! the balance's feedback can bring it back (its legs at their tilt limit
//! within 0.1 s, the feet rolled onto their heels). Where the take stands
//! on both feet, its standing legs are tilted ahead of time, as the balance
//! tilts them, so that its centre of mass lies well inside its feet.
//!
//! The played pose departs from the take by this tilt; `execute` scores
//! against the take and counts the tilt in the departure.

use super::anthropometry::{Inertial, inertials};
use super::balance::{BALANCE_MAX_RAD, brought_inside, convex_hull};
use super::humanoid::{FEET, HIPS, soles};
use super::stepping::Contacts;
use crate::mocap::body::{Body, JOINTS, Joint};
use crate::mocap::pose::{BodyFrame, Motion, Pose};
use glam::{DQuat, DVec2, DVec3};

/// How far inside the edge of its feet the take's centre of mass is
/// brought: an upright stance, its centre of mass over the ankles (the
/// heels' edge 6.4 cm behind), is left alone. Over bandai's 88 standing
/// gestures and real/'s 13 (stayed up; RMS joint error against the take
/// where up, worst): none 82 and 9 (4.0°, 2.8°), 3 cm the same, 6 cm 82
/// and 11 (4.0°, 6.9°), 7 cm 81 and 11, 8 cm 82 and 10, 9 cm 82 and 12
/// (8.7°, 6.7°), 10 cm 82 and 12, 12 cm 81 and 12, the middle of the soles
/// 82 and 12 (9.3°, 7.3°). From 9 cm the demo's synthetic demonstrator,
/// standing upright, is tilted too: its trajectory played on the ground
/// strays 50.4 mm from the truth against 30.0 mm up to 6 cm.
const INSET_M: f64 = 0.06;
/// The tilt is averaged over this long either side of each frame, so the
/// legs ease into and out of it as the take puts a foot down or lifts it.
const SMOOTHING_S: f64 = 0.25;

/// `motion` with its standing legs tilted about their ankles wherever it
/// stands on both feet with its centre of mass (on the humanoid's masses)
/// less than `INSET_M` inside the soles `contacts` says stand.
pub fn over_support(motion: &Motion, contacts: &Contacts) -> Motion {
    let body = &motion.body;
    let half = (SMOOTHING_S / motion.frame_time_s).round() as usize;
    let shifts = smoothed(&shifts(motion, contacts), half);
    let poses = motion.poses.iter().zip(&shifts).enumerate();
    let poses = poses.map(|(k, (pose, &shift))| tilted(body, pose, contacts.standing(k), shift)).collect();
    Motion { body: body.clone(), frame_time_s: motion.frame_time_s, poses }
}

/// Per frame, how far (m, on the ground) the centre of mass lies from
/// where it would be `INSET_M` inside the support of both feet; zero on
/// frames the take does not stand on both.
fn shifts(motion: &Motion, contacts: &Contacts) -> Vec<DVec3> {
    let body = &motion.body;
    let links = inertials(body);
    let corners = soles(body);
    let on_ground = |p: DVec3| DVec2::new(p.x, p.z);
    motion
        .poses
        .iter()
        .enumerate()
        .map(|(k, pose)| {
            if contacts.standing(k) != [true; 2] {
                return DVec3::ZERO;
            }
            let frame = body.forward(pose);
            let com = on_ground(centre_of_mass(&links, &frame));
            let soles = FEET.into_iter().zip(&corners).flat_map(|(foot, sole)| {
                let (at, turn) = (frame.position(foot), frame.rotation(foot));
                sole.map(|c| on_ground(at + turn * c))
            });
            let to = brought_inside(&convex_hull(soles.collect()), com, INSET_M) - com;
            DVec3::new(to.x, 0.0, to.y)
        })
        .collect()
}

/// The centre of mass of the body in `frame`, its links weighing as
/// `links` says.
fn centre_of_mass(links: &[Inertial; JOINTS], frame: &BodyFrame) -> DVec3 {
    let weighted = Joint::ALL.iter().map(|&j| {
        let link = &links[j.index()];
        link.mass_kg * (frame.position(j) + frame.rotation(j) * link.com)
    });
    weighted.sum::<DVec3>() / links.iter().map(|l| l.mass_kg).sum::<f64>()
}

/// Each entry averaged with its neighbours up to `half` away.
fn smoothed(values: &[DVec3], half: usize) -> Vec<DVec3> {
    let last = values.len().saturating_sub(1);
    (0..values.len())
        .map(|k| {
            let (from, to) = (k.saturating_sub(half), (k + half).min(last));
            values[from..=to].iter().sum::<DVec3>() / (to - from + 1) as f64
        })
        .collect()
}

/// `pose` with its `standing` legs turned about their ankles by the tilt
/// that moves their hips by `shift` (at most `BALANCE_MAX_RAD`), each foot
/// staying as it is in the world and the pelvis keeping its rotation: the
/// balance's parallelogram, and the pelvis moved with the hips.
fn tilted(body: &Body, pose: &Pose, standing: [bool; 2], shift: DVec3) -> Pose {
    let legs: Vec<usize> = (0..2).filter(|&k| standing[k]).collect();
    if shift == DVec3::ZERO || legs.is_empty() {
        return *pose;
    }
    let frame = body.forward(pose);
    let leg = |k: usize| frame.position(HIPS[k]) - frame.position(FEET[k]);
    let height = legs.iter().map(|&k| leg(k).y).sum::<f64>() / legs.len() as f64;
    // Turning a leg by θ about its ankle moves its hip, h above it, by
    // θ × h·Y; θ = Y × shift / h moves it by `shift`.
    let turn = DQuat::from_scaled_axis((DVec3::Y.cross(shift) / height.max(0.1)).clamp_length_max(BALANCE_MAX_RAD));
    let pelvis = frame.rotation(Joint::Pelvis);
    let mut local = Joint::ALL.map(|j| pose.local_rotation(j));
    let mut moved = DVec3::ZERO;
    for &k in &legs {
        let (hip, foot) = (HIPS[k], FEET[k]);
        let knee = foot.parent().expect("a foot has a shank");
        local[hip.index()] = pelvis.inverse() * turn * frame.rotation(hip);
        local[foot.index()] = (turn * frame.rotation(knee)).inverse() * frame.rotation(foot);
        moved += turn * leg(k) - leg(k);
    }
    Pose::from_rotations(pose.root + moved / legs.len() as f64, &local)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The standard body standing with its feet 35 cm apart, its trunk
    /// bent back by `lean` (radians) at the spine and at the chest.
    fn standing(lean: f64, frames: usize) -> Motion {
        let body = Body::standard();
        let mut local = [DQuat::IDENTITY; JOINTS];
        for j in [Joint::Spine, Joint::Chest] {
            local[j.index()] = DQuat::from_rotation_x(-lean);
        }
        for (k, hip) in HIPS.into_iter().enumerate() {
            let out = if k == 0 { 0.1 } else { -0.1 };
            local[hip.index()] = DQuat::from_rotation_z(out);
            local[FEET[k].index()] = DQuat::from_rotation_z(-out);
        }
        let pose = Pose::from_rotations(Pose::rest(&body).root, &local);
        Motion { body, frame_time_s: 1.0 / 30.0, poses: vec![pose; frames] }
    }

    fn com(motion: &Motion, k: usize) -> DVec3 {
        centre_of_mass(&inertials(&motion.body), &motion.body.forward(&motion.poses[k]))
    }

    #[test]
    fn a_take_leaning_back_over_its_heels_is_tilted_forward_with_its_feet_where_they_were() {
        let take = standing(0.6, 20);
        let contacts = Contacts::of(&take);
        let over = over_support(&take, &contacts);
        let ankle_z = take.body.forward(&take.poses[10]).position(FEET[0]).z;
        // 10 cm behind the ankles, 3 cm beyond the heels' edge; after,
        // within 2 cm of the inset (0.4 cm behind the ankles): the legs
        // turn with the pelvis, so the centre of mass moves less than it.
        assert!(com(&take, 10).z < ankle_z - 0.09, "{:?}", com(&take, 10));
        assert!(com(&over, 10).z > ankle_z - 0.024, "{:?} → {:?}", com(&take, 10), com(&over, 10));
        let (before, after) = (take.body.forward(&take.poses[10]), over.body.forward(&over.poses[10]));
        for foot in FEET {
            assert!(before.position(foot).distance(after.position(foot)) < 1e-6, "{foot:?}");
            assert!(before.rotation(foot).angle_between(after.rotation(foot)) < 1e-6, "{foot:?}");
        }
        for j in [Joint::Pelvis, Joint::Head] {
            assert!(before.rotation(j).angle_between(after.rotation(j)) < 1e-6, "{j:?}");
        }
    }

    #[test]
    fn a_take_standing_well_over_its_feet_is_left_as_it_is() {
        // Bent 17° forward: its centre of mass 6 cm ahead of the ankles,
        // 12 cm from the heels' edge and 13 cm from the toes'.
        let take = standing(-0.3, 20);
        let over = over_support(&take, &Contacts::of(&take));
        assert_eq!(over.poses, take.poses);
    }
}
