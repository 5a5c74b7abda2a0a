//! Stepping: while the take stands on one foot and the humanoid's other
//! foot is off the ground (and on, until that foot lands), the humanoid's
//! swing foot is placed where its balance needs it and its stance hip
//! holds the trunk up (after SIMBICON, Yin et al. 2007, with the take as
//! the reference rather than a hand-made gait, as in data-driven biped
//! control); until that foot is off, the standing hips hold the trunk. The
//! take's swing foot is raised to clear the ground.

use super::humanoid::{FEET, GRAVITY_M_S2, HIPS, Humanoid, toes};
use super::targets::{JointTarget, RootTarget, clamp};
use crate::mocap::body::{Body, JOINTS, Joint};
use crate::mocap::pose::{Motion, Pose};
use glam::{DQuat, DVec3};

/// A foot of the take stands while its ankle is within this of the height
/// it stands at ...
const CONTACT_RISE_M: f64 = 0.04;
/// ... and it moves slower than this.
const CONTACT_SPEED_M_S: f64 = 0.6;
/// The share of the frames whose ankle is at or below the height it is
/// taken to stand at (a take may crouch or jump in places).
const STANDING_QUANTILE: f64 = 0.1;
/// An ankle whose standing height is this far above the other's is held
/// up, not standing.
const LIFTED_M: f64 = 0.15;
/// A sole tilted further than this on a frame the take stands on it is a
/// retargeting failure, not a stance, and does not count.
const LEVEL_MAX_RAD: f64 = std::f64::consts::FRAC_PI_3;
/// A foot turning slower than this stands still (a heel strike rolls the
/// foot down onto its sole at about 3–4 rad/s on bandai's walks).
const LEVEL_STILL_RAD_S: f64 = 0.5;
/// The most the swing leg is turned to place its foot.
const PLACEMENT_MAX_RAD: f64 = 0.5;
/// How far the take's swing foot is raised halfway through its swing
/// (less toward either end, as the sine of the share of the swing gone
/// times π). The canonical foot is longer than a captured ankle-to-ball
/// foot, and a captured swing clears the floor by a few centimetres: played
/// as captured, the humanoid's swing foot caught the ground and its feet
/// fell out of step with the take's. Over bandai's 44 walks, with the
/// stepping legs' gains and the trunk hold (stayed up, feet as the take's,
/// mean time to the fall): none 1, 60%, 1.8 s; 5 cm 5, 66%, 1.9 s; 8 cm 6,
/// 67%, 1.9 s, where 83 of the 88 standing gestures stayed up, not 84.
const SWING_LIFT_M: f64 = 0.05;
/// The take steps within this long of a frame where it stands on one foot.
const STEPPING_WITHIN_S: f64 = 0.3;

/// Which of the take's feet stand, frame by frame, and where its ankles
/// are.
#[derive(Clone, Debug)]
pub struct Contacts {
    frame_time_s: f64,
    standing: Vec<[bool; 2]>,
    ankles: Vec<[DVec3; 2]>,
    /// Per frame, whether the take stands on one foot within
    /// `STEPPING_WITHIN_S` of it.
    stepping: Vec<bool>,
    /// Per frame and foot, the swing it is in: the last frame the foot
    /// stood on before and the first it stands on after.
    swings: Vec<[Option<(usize, usize)>; 2]>,
}

impl Contacts {
    /// The contacts of `motion`'s feet: a foot stands where its ankle or
    /// its toe (the middle of the front of the humanoid's sole, the foot
    /// turned as the take turns it) lies low and moves slowly. The ankle
    /// alone missed the stance at each change of feet, the heel raised as
    /// the toe pushes off: on four of bandai's fast walks, 29% to 49% of
    /// the frames read as both feet in the air, where in the capture a
    /// foot's ankle or toe joint lay within 3 cm of the floor on all but 7
    /// of those 205 frames.
    pub fn of(motion: &Motion) -> Contacts {
        let toes = toes(&motion.body);
        // Per frame, foot and point (ankle, toe): where it is.
        let points: Vec<[[DVec3; 2]; 2]> = motion
            .poses
            .iter()
            .map(|pose| {
                let frame = motion.body.forward(pose);
                [0, 1].map(|f| {
                    let ankle = frame.position(FEET[f]);
                    [ankle, ankle + frame.rotation(FEET[f]) * toes[f]]
                })
            })
            .collect();
        // Each foot's own: a retargeted take may hold one ankle a few
        // centimetres higher than the other throughout (measured on bandai:
        // standing gestures read as standing on one foot against the lower
        // ankle's height).
        let [ankle_y, toe_y] = [0, 1].map(|p| {
            [0, 1].map(|f| {
                let mut heights: Vec<f64> = points.iter().map(|at| at[f][p].y).collect();
                heights.sort_by(f64::total_cmp);
                heights.get((STANDING_QUANTILE * heights.len() as f64) as usize).copied().unwrap_or(0.0)
            })
        });
        // A foot held up the whole take does not stand at its lowest: its
        // ankle and its toe stand as low as the other's ankle allows.
        let held_up = [0, 1].map(|f| (ankle_y[f] - ankle_y[1 - f] - LIFTED_M).max(0.0));
        let standing_y = [ankle_y, toe_y].map(|y| [0, 1].map(|f| y[f] - held_up[f]));
        let dt = motion.frame_time_s;
        let low_and_slow = |k: usize, f: usize, p: usize| {
            let speed = per_second(k, points.len(), dt, |before, after| {
                (points[after][f][p] - points[before][f][p]).with_y(0.0).length()
            });
            points[k][f][p].y < standing_y[p][f] + CONTACT_RISE_M && speed < CONTACT_SPEED_M_S
        };
        let standing: Vec<[bool; 2]> =
            (0..points.len()).map(|k| [0, 1].map(|f| (0..2).any(|p| low_and_slow(k, f, p)))).collect();
        let reach = (STEPPING_WITHIN_S / dt).round() as usize;
        let stepping = within_reach(&standing.iter().map(|s| s[0] != s[1]).collect::<Vec<_>>(), reach);
        let swings = swings(&standing);
        let ankles = points.iter().map(|at| at.map(|[ankle, _]| ankle)).collect();
        Contacts { frame_time_s: dt, standing, ankles, stepping, swings }
    }

    /// The frame nearest `time_s`.
    fn frame_at(&self, time_s: f64) -> usize {
        ((time_s / self.frame_time_s).max(0.0).round() as usize).min(self.standing.len() - 1)
    }

    /// Which of the take's feet (left, right) stand on frame `k`.
    pub fn standing(&self, k: usize) -> [bool; 2] {
        self.standing[k]
    }

    /// The one foot the take stands on at `time_s` (0 left, 1 right) and
    /// where its ankle is; `None` while it stands on both or neither.
    pub fn single_stance(&self, time_s: f64) -> Option<(usize, DVec3)> {
        let foot = match self.standing_at(time_s) {
            [true, false] => 0,
            [false, true] => 1,
            _ => return None,
        };
        Some((foot, self.ankle(time_s, foot)))
    }

    /// Which of the take's feet (left, right) stand at `time_s`.
    pub fn standing_at(&self, time_s: f64) -> [bool; 2] {
        self.standing[self.frame_at(time_s)]
    }

    /// Where the take's ankle of foot `f` (0 left, 1 right) is at
    /// `time_s`, between its frames.
    pub fn ankle(&self, time_s: f64, f: usize) -> DVec3 {
        let at = (time_s / self.frame_time_s).max(0.0);
        let last = self.standing.len() - 1;
        let (a, b) = ((at.floor() as usize).min(last), (at.floor() as usize + 1).min(last));
        self.ankles[a][f].lerp(self.ankles[b][f], at - at.floor())
    }

    /// Whether the take stands on one foot within `STEPPING_WITHIN_S` of
    /// `time_s`.
    pub fn stepping(&self, time_s: f64) -> bool {
        self.stepping[self.frame_at(time_s)]
    }

    /// How far through its swing the take's foot `f` (0 left, 1 right) is
    /// at `time_s`: 0 as it lifts, 1 as it lands; `None` while it stands,
    /// before its first and after its last stance, and while both feet are
    /// up without the other standing in between (a jump, or a take's feet
    /// read as lifted for a frame or two while it stands: the demo's
    /// tracked trajectory, lifted there, bent both knees 6° off).
    fn swing_share(&self, time_s: f64, f: usize) -> Option<f64> {
        let (lifted, lands) = self.swings[self.frame_at(time_s)][f]?;
        let at = (time_s / self.frame_time_s).max(0.0);
        Some(((at - lifted as f64) / (lands - lifted) as f64).clamp(0.0, 1.0))
    }

    /// Raises each of the take's swing feet in `targets` (the take's pose
    /// of `body` at `time_s`, its pelvis turned by `pelvis`) by
    /// `SWING_LIFT_M` times the sine of its swing's share gone times π.
    pub fn lift_swing_feet(&self, body: &Body, pelvis: DQuat, time_s: f64, targets: &mut [JointTarget; JOINTS]) {
        for f in 0..2 {
            if let Some(share) = self.swing_share(time_s, f) {
                lift_foot(body, pelvis, targets, f, SWING_LIFT_M * (std::f64::consts::PI * share).sin());
            }
        }
    }

    /// `motion` with each foot turned, for the whole take, by the constant
    /// rotation (in the foot's own frame) that lays its sole flat on the
    /// first frame the take stands still on it, and by how much each was
    /// turned (left, right; radians). A captured foot runs from the ankle
    /// to the ball of the foot, steeper than the canonical foot's ankle to
    /// toe tip, so a retargeted person standing flat stands on the
    /// canonical body's toes (15–30° on the real captures), and a walk
    /// lands on them. Still, because a walk's first stance frame is often
    /// its heel strike, the foot rolling down onto its sole (on bandai's
    /// feminine walks, one foot of a take was turned 5° and the other
    /// 24°); a foot never still where the take stands on it is laid flat
    /// on the first such frame. A foot the take never stands on is left
    /// alone.
    pub fn level_feet(&self, motion: &Motion) -> (Motion, [f64; 2]) {
        let mut out = motion.clone();
        let mut turned = [0.0; 2];
        let feet: Vec<[DQuat; 2]> = motion
            .poses
            .iter()
            .map(|pose| {
                let frame = motion.body.forward(pose);
                FEET.map(|foot| frame.rotation(foot))
            })
            .collect();
        for (k, foot) in FEET.into_iter().enumerate() {
            let world = |i: usize| feet[i][k];
            let still = |i: usize| {
                let spin = per_second(i, feet.len(), motion.frame_time_s, |before, after| {
                    world(after).angle_between(world(before))
                });
                spin < LEVEL_STILL_RAD_S
            };
            let stances = || {
                (0..feet.len())
                    .filter(|&i| self.standing[i][k] && (world(i) * DVec3::Y).angle_between(DVec3::Y) <= LEVEL_MAX_RAD)
            };
            let flat = stances().find(|&i| still(i)).or_else(|| stances().next()).map(|i| {
                let sole = world(i) * DVec3::Y;
                world(i).inverse() * DQuat::from_rotation_arc(sole, DVec3::Y) * world(i)
            });
            let Some(correction) = flat else { continue };
            for pose in &mut out.poses {
                let mut local = Joint::ALL.map(|j| pose.local_rotation(j));
                local[foot.index()] *= correction;
                *pose = Pose::from_rotations(pose.root, &local);
            }
            turned[k] = correction.angle_between(DQuat::IDENTITY);
        }
        (out, turned)
    }
}

impl Humanoid {
    /// Turns `targets` so that, while the take stands on foot `stance`
    /// (whose ankle is at `take_ankle`, the take's pelvis as `root` says),
    /// the humanoid's swing foot lands where its capture point needs it:
    /// the take's own placement moved by as far as the humanoid's capture
    /// point, taken from the stance ankle, is off the take's (a gain of 1:
    /// 0 to 1.5 on either of its terms kept the walks up alike), its sole
    /// held flat in the world. A standing stance foot's hip
    /// turns the pelvis to the take's rotation in the world, whatever the
    /// leg beneath does, and its sole is laid halfway to flat as
    /// [`Humanoid::balance`] does. `placement` (m, on the ground) moves the
    /// landing further, as a plan chose it. The balance's gathered shift
    /// is let go: it was gathered over feet that no longer stand as they
    /// did (without the dead zone and kept through the swings, bandai's
    /// walks at 480 Hz kept 38 of 44 up; let go, 41).
    pub fn step_over(
        &mut self,
        targets: &mut [JointTarget; JOINTS],
        stance: usize,
        take_ankle: DVec3,
        root: &RootTarget,
        placement: DVec3,
    ) {
        self.gathered_shift = DVec3::ZERO;
        let swing = 1 - stance;
        let frame = self.frame();
        let pelvis = frame.rotation(Joint::Pelvis);
        let height = (frame.position(Joint::Pelvis).y - frame.position(FEET[stance]).y).max(0.1);
        let omega = (GRAVITY_M_S2 / height).sqrt();
        let flat = |v: DVec3| DVec3::new(v.x, 0.0, v.z);
        let velocity = self.world.bodies[self.links[Joint::Pelvis.index()]].linvel().as_dvec3();
        let off = flat(frame.position(Joint::Pelvis) - frame.position(FEET[stance]) - (root.position - take_ankle))
            + flat(velocity - root.velocity) / omega
            + placement;
        let (hip, knee, ankle) = (HIPS[swing], FEET[swing].parent().expect("a foot has a shank"), FEET[swing]);
        let leg = (frame.position(hip) - frame.position(ankle)).length().max(0.1);
        // Turning the leg by θ about its hip moves its foot, `leg` below,
        // by θ × (−Y·leg); θ = off × Y / leg moves it by `off`.
        let turn = DQuat::from_scaled_axis((off.cross(DVec3::Y) / leg).clamp_length_max(PLACEMENT_MAX_RAD));
        let thigh = root.rotation * targets[hip.index()].rotation;
        let shank = thigh * targets[knee.index()].rotation;
        let sole = shank * targets[ankle.index()].rotation;
        // Flat, so that its toe does not catch the ground: the canonical
        // foot is longer than a captured ankle-to-ball foot.
        let sole = DQuat::from_rotation_arc(sole * DVec3::Y, DVec3::Y) * sole;
        targets[hip.index()].rotation = clamp(hip, pelvis.inverse() * turn * thigh).0;
        targets[ankle.index()].rotation = clamp(ankle, (turn * shank).inverse() * sole).0;
        if self.stands(FEET[stance]) {
            let thigh = frame.rotation(HIPS[stance]);
            targets[HIPS[stance].index()].rotation = clamp(HIPS[stance], root.rotation.inverse() * thigh).0;
            self.plant(targets, stance, DQuat::IDENTITY);
        }
    }

    /// Turns the standing legs' hips in `targets` so that the pelvis tilts
    /// back to the tilt of `pelvis` (the take's) with the thighs where they
    /// are: while the take stands on one foot and the humanoid still on
    /// both (or on the other), no stance hip holds the trunk as
    /// [`Humanoid::step_over`]'s does, and it tipped over the legs (the
    /// walks' falls: the trunk leaning 45° past the take's while both feet
    /// stood).
    pub fn hold_trunk(&self, targets: &mut [JointTarget; JOINTS], pelvis: DQuat) {
        let now = self.rotation(Joint::Pelvis);
        // The tilt from the take's to the humanoid's, undone at the hips.
        let tilt = DQuat::from_rotation_arc(pelvis * DVec3::Y, now * DVec3::Y);
        for k in (0..2).filter(|&k| self.stands(FEET[k])) {
            let hip = &mut targets[HIPS[k].index()];
            hip.rotation = clamp(HIPS[k], now.inverse() * tilt * now * hip.rotation).0;
        }
    }
}

/// Per entry of `marks`, whether any entry within `reach` of it is set.
fn within_reach(marks: &[bool], reach: usize) -> Vec<bool> {
    // How many are set before each entry.
    let before: Vec<usize> = std::iter::once(0)
        .chain(marks.iter().scan(0, |sum, &m| {
            *sum += usize::from(m);
            Some(*sum)
        }))
        .collect();
    let last = marks.len().saturating_sub(1);
    (0..marks.len()).map(|k| before[(k + reach).min(last) + 1] > before[k.saturating_sub(reach)]).collect()
}

/// How fast something changes at frame `k` of `frames` taken every
/// `dt_s`: `change` between the frames either side of it (the one side at
/// either end), per second.
fn per_second(k: usize, frames: usize, dt_s: f64, change: impl Fn(usize, usize) -> f64) -> f64 {
    let (before, after) = (k.saturating_sub(1), (k + 1).min(frames.saturating_sub(1)));
    change(before, after) / (dt_s * (after - before).max(1) as f64)
}

/// Per frame and foot, the swing it is in (see [`Contacts`]'s `swings`):
/// only between two frames the foot stands on, with the other foot
/// standing on one in between ([`Contacts::swing_share`] says why).
fn swings(standing: &[[bool; 2]]) -> Vec<[Option<(usize, usize)>; 2]> {
    let mut swings = vec![[None; 2]; standing.len()];
    for f in 0..2 {
        let mut stood = None;
        for (k, s) in standing.iter().enumerate() {
            if !s[f] {
                continue;
            }
            if let Some(lifted) = stood.filter(|&l| (l + 1..k).any(|j| standing[j][1 - f])) {
                for swing in &mut swings[lifted + 1..k] {
                    swing[f] = Some((lifted, k));
                }
            }
            stood = Some(k);
        }
    }
    swings
}

/// Raises foot `f`'s ankle (0 left, 1 right) in `targets` by `lift_m`
/// straight up in the world, its pelvis turned by `pelvis`: the hip and the
/// knee turn in the leg's plane (the knee's hinge stays its axis) and the
/// foot keeps its turn in the world. An ankle out of the leg's reach goes
/// as far as it reaches; a straight leg, whose plane is undefined, is left
/// alone.
fn lift_foot(body: &Body, pelvis: DQuat, targets: &mut [JointTarget; JOINTS], f: usize, lift_m: f64) {
    let mut local = Joint::ALL.map(|j| targets[j.index()].rotation);
    local[Joint::Pelvis.index()] = pelvis;
    let frame = body.forward(&Pose::from_rotations(DVec3::ZERO, &local));
    let (hip, ankle) = (HIPS[f], FEET[f]);
    let knee = ankle.parent().expect("a foot has a shank");
    let (h, k, a) = (frame.position(hip), frame.position(knee), frame.position(ankle));
    let (thigh_m, shank_m) = ((k - h).length(), (a - k).length());
    let normal = (k - h).cross(a - k);
    if normal.length() < 1e-9 {
        return;
    }
    let goal = a + lift_m * DVec3::Y;
    let toward = (goal - h).normalize();
    let reach = (goal - h).length().clamp((thigh_m - shank_m).abs() + 1e-6, thigh_m + shank_m - 1e-6);
    // The thigh leaves the hip-to-ankle line at the angle the law of
    // cosines gives, on the side the knee bends to.
    let thigh_off =
        ((thigh_m * thigh_m + reach * reach - shank_m * shank_m) / (2.0 * thigh_m * reach)).clamp(-1.0, 1.0);
    let side = normal.normalize() * (k - h).cross(toward).dot(normal).signum();
    let new_knee = h + DQuat::from_axis_angle(side, -thigh_off.acos()) * toward * thigh_m;
    let new_ankle = h + toward * reach;
    let thigh = DQuat::from_rotation_arc((k - h).normalize(), (new_knee - h).normalize()) * frame.rotation(hip);
    let shank =
        DQuat::from_rotation_arc((a - k).normalize(), (new_ankle - new_knee).normalize()) * frame.rotation(knee);
    targets[hip.index()].rotation = clamp(hip, pelvis.inverse() * thigh).0;
    targets[knee.index()].rotation = clamp(knee, thigh.inverse() * shank).0;
    targets[ankle.index()].rotation = clamp(ankle, shank.inverse() * frame.rotation(ankle)).0;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The standard body standing, with the feet `lifted` (left, right)
    /// off the ground by a bent hip and knee and every sole turned 20°
    /// toe-down.
    fn stance(body: &Body, lifted: [bool; 2]) -> Pose {
        let mut local = [DQuat::IDENTITY; JOINTS];
        for (k, foot) in FEET.into_iter().enumerate() {
            local[foot.index()] = DQuat::from_rotation_x(20f64.to_radians());
            if lifted[k] {
                local[HIPS[k].index()] = DQuat::from_rotation_x(-0.8);
                local[foot.parent().unwrap().index()] = DQuat::from_rotation_x(1.5);
            }
        }
        Pose::from_rotations(Pose::rest(body).root, &local)
    }

    fn motion(phases: &[[bool; 2]]) -> Motion {
        let body = Body::standard();
        let poses = phases.iter().flat_map(|&lifted| std::iter::repeat_n(stance(&body, lifted), 10)).collect();
        Motion { body, frame_time_s: 1.0 / 30.0, poses }
    }

    #[test]
    fn the_take_stands_on_the_foot_that_is_down_and_a_foot_held_up_throughout_never_stands() {
        let take = motion(&[[false, false], [true, false], [false, false], [false, true]]);
        let contacts = Contacts::of(&take);
        let at = |k: usize| contacts.single_stance(k as f64 * take.frame_time_s).map(|(foot, _)| foot);
        assert_eq!([at(5), at(15), at(25), at(35)], [None, Some(1), None, Some(0)]);
        let (_, ankle) = contacts.single_stance(15.0 * take.frame_time_s).unwrap();
        assert!(ankle.distance(take.body.forward(&take.poses[15]).position(Joint::RightAnkle)) < 1e-12);
        // Standing on the right leg the whole take.
        let take = motion(&[[true, false]; 3]);
        let contacts = Contacts::of(&take);
        assert!((0..30).all(|k| contacts.single_stance(k as f64 / 30.0).is_some_and(|(foot, _)| foot == 1)));
    }

    #[test]
    fn the_swing_foot_is_lifted_most_halfway_through_its_swing_and_the_take_steps_around_it() {
        // Both feet down, the right lifted for 10 frames, both down.
        let take = motion(&[[false, false], [false, true], [false, false], [false, false]]);
        let contacts = Contacts::of(&take);
        let ft = take.frame_time_s;
        let lifted = |time_s: f64| {
            let mut targets = [JointTarget::REST; JOINTS];
            for j in Joint::ALL {
                targets[j.index()].rotation = take.poses[(time_s / ft).round() as usize].local_rotation(j);
            }
            let pelvis = targets[Joint::Pelvis.index()].rotation;
            let before = take.body.forward(&Pose::from_rotations(DVec3::ZERO, &targets.map(|t| t.rotation)));
            contacts.lift_swing_feet(&take.body, pelvis, time_s, &mut targets);
            let after = take.body.forward(&Pose::from_rotations(DVec3::ZERO, &targets.map(|t| t.rotation)));
            (before, after)
        };
        let (before, after) = lifted(14.5 * ft);
        let rise = after.position(Joint::RightAnkle) - before.position(Joint::RightAnkle);
        // Its swing runs from frame 9, the last it stood on, to 20.
        let expected = SWING_LIFT_M * (std::f64::consts::PI * 5.5 / 11.0).sin();
        assert!((rise.y - expected).abs() < 1e-6 && rise.with_y(0.0).length() < 1e-6, "{rise}");
        let turned = after.rotation(Joint::RightAnkle).angle_between(before.rotation(Joint::RightAnkle));
        assert!(turned < 1e-6, "the foot turned {turned}");
        // The standing foot and the frames where both stand are left alone.
        assert!(after.position(Joint::LeftAnkle).distance(before.position(Joint::LeftAnkle)) < 1e-12);
        let (before, after) = lifted(25.0 * ft);
        assert!(after.position(Joint::RightAnkle).distance(before.position(Joint::RightAnkle)) < 1e-12);
        // Both feet up at once (a jump) is no swing.
        let jump = motion(&[[false, false], [true, true], [false, false]]);
        assert_eq!(Contacts::of(&jump).swing_share(15.0 * ft, 1), None);
        // Stepping from 0.3 s before the first frame on one foot (10) to 0.3 s
        // after the last (19).
        let stepping = |k: usize| contacts.stepping(k as f64 * ft);
        assert_eq!([stepping(0), stepping(1), stepping(28), stepping(29)], [false, true, true, false]);
    }

    #[test]
    fn each_foot_is_laid_flat_as_it_first_stands_still_even_if_it_starts_in_the_air() {
        let take = motion(&[[true, false], [false, false]]);
        let (levelled, turned) = Contacts::of(&take).level_feet(&take);
        for (k, foot) in FEET.into_iter().enumerate() {
            assert!((turned[k].to_degrees() - 20.0).abs() < 1e-6, "{turned:?}");
            let sole = levelled.body.forward(&levelled.poses[15]).rotation(foot) * DVec3::Y;
            assert!(sole.angle_between(DVec3::Y) < 1e-9, "{foot:?}");
        }
    }

    #[test]
    fn a_foot_rolling_onto_its_sole_is_laid_flat_where_it_comes_to_rest_not_where_it_strikes() {
        // Both feet stand throughout; the left rolls from heel strike (flat in
        // the canonical body, 0°) down to the captured 20° at 4° a frame
        // (2.1 rad/s), then rests there.
        let body = Body::standard();
        let mut take = motion(&[[false, false]; 3]);
        for (k, pose) in take.poses.iter_mut().enumerate().take(5) {
            let mut local = Joint::ALL.map(|j| pose.local_rotation(j));
            local[Joint::LeftAnkle.index()] = DQuat::from_rotation_x((4.0 * k as f64).to_radians());
            *pose = Pose::from_rotations(Pose::rest(&body).root, &local);
        }
        let contacts = Contacts::of(&take);
        assert!((0..5).all(|k| contacts.standing(k)[0]), "the rolling foot stands");
        let (_, turned) = contacts.level_feet(&take);
        assert!((turned[0].to_degrees() - 20.0).abs() < 1e-6, "{turned:?}");
        // A foot never still where it stands is laid flat where it first stands.
        for (k, pose) in take.poses.iter_mut().enumerate() {
            let mut local = Joint::ALL.map(|j| pose.local_rotation(j));
            local[Joint::LeftAnkle.index()] = DQuat::from_rotation_x((20.0 + 2.0 * k as f64).to_radians());
            *pose = Pose::from_rotations(Pose::rest(&body).root, &local);
        }
        let (_, turned) = Contacts::of(&take).level_feet(&take);
        assert!((turned[0].to_degrees() - 20.0).abs() < 1e-6, "{turned:?}");
    }

    #[test]
    fn a_foot_on_its_toe_stands_but_not_while_it_slides() {
        // Both feet flat for 10 frames, 10 on tiptoe (each foot turned 30°
        // further toe-down, the body raised until the toes are back where
        // they stood), 10 flat.
        let body = Body::standard();
        let mut take = motion(&[[false, false]; 3]);
        let flat = take.poses[0];
        let mut local = Joint::ALL.map(|j| flat.local_rotation(j));
        for foot in FEET {
            local[foot.index()] *= DQuat::from_rotation_x(30f64.to_radians());
        }
        let toe = |pose: &Pose| {
            let frame = body.forward(pose);
            (frame.position(Joint::LeftAnkle) + frame.rotation(Joint::LeftAnkle) * toes(&body)[0]).y
        };
        let turned = Pose::from_rotations(flat.root, &local);
        let raised_m = toe(&flat) - toe(&turned);
        assert!(raised_m > CONTACT_RISE_M, "the ankles rise {raised_m} m: the ankles alone would not stand");
        let tiptoe = Pose::from_rotations(flat.root + DVec3::Y * raised_m, &local);
        take.poses[10..20].fill(tiptoe);
        assert_eq!(Contacts::of(&take).standing(15), [true, true]);
        // Gliding forward at 1 m/s on tiptoe, no foot stands.
        for (k, pose) in take.poses.iter_mut().enumerate() {
            *pose = Pose::from_rotations(tiptoe.root + DVec3::Z * k as f64 * take.frame_time_s, &local);
        }
        let gliding = Contacts::of(&take);
        assert!((0..30).all(|k| gliding.standing(k) == [false, false]));
    }
}
