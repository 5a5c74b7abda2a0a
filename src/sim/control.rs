//! What the humanoid is asked each physics step ([`Controller::step`]):
//! the trajectory's pose turned by the balance and the stepping; and the
//! look-ahead that chooses where each swing foot lands by playing a few
//! placements ahead on copies of the world ([`Controller::plan_swing`]),
//! as sampling-based control of simulated characters does (Liu et al.
//! 2010), here for one choice a step rather than every joint's target.

use super::humanoid::{FEET, Gains, Humanoid};
use super::stepping::Contacts;
use super::targets::{JointTarget, Targets, motorized};
use crate::mocap::body::{Body, JOINTS, Joint};
use crate::mocap::math::angle_between;
use crate::mocap::pose::BodyFrame;
use glam::DVec3;
use rayon::prelude::*;

/// The humanoid has fallen when its pelvis is below this share of its
/// standing height, when its trunk leans further than [`FALLEN_LEAN_RAD`]
/// beyond the trajectory's own lean (a deep bow leans past 60° standing),
/// or when its trunk or head touches the ground.
const FALLEN_PELVIS_SHARE: f64 = 0.5;
const FALLEN_LEAN_RAD: f64 = std::f64::consts::FRAC_PI_4;

/// The look-ahead moves a swing foot's landing up to this far from where
/// the capture point puts it, forward or back and to either side of the
/// take's heading. Over bandai's 44 walks (stayed up, with a horizon of
/// 1 s and 3 × 3 placements): 8 cm 16, 15 cm 20.
const PLACEMENT_REACH_M: f64 = 0.15;
/// Placements tried on either side of none along each axis: a grid of
/// (2n + 1)². Over bandai's 44 walks (1 s, 15 cm): n = 1 kept 20 up,
/// n = 2 27.
const PLACEMENT_STEPS: i32 = 2;
/// A placement that stays up for the whole horizon costs the pelvis's
/// tilt off the trajectory's (rad²) plus this times the centre of mass's
/// horizontal velocity off the trajectory's pelvis's ((m/s)²) at its end.
const VELOCITY_WEIGHT_S2_PER_M2: f64 = 0.05;
/// A placement that falls costs this and more the sooner it falls: more
/// than any that stays up.
const FALLEN_COST: f64 = 10.0;

/// Plays one trajectory on one humanoid, a physics step at a time.
pub(super) struct Controller<'a> {
    /// What the motors follow: the take, set over the feet when balancing.
    pub played: &'a Targets,
    /// The take itself.
    pub take: &'a Targets,
    pub contacts: &'a Contacts,
    pub body: &'a Body,
    pub balance: bool,
    pub assist: bool,
    pub gains: Gains,
    /// The pelvis's height standing, m.
    pub standing_pelvis_m: f64,
    /// Per frame of the take, how far its trunk leans from upright.
    pub leans_rad: Vec<f64>,
}

impl Controller<'_> {
    /// The foot the humanoid stands on in a swing at `time_s` (see
    /// `swing`).
    pub fn swinging(&self, humanoid: &Humanoid, time_s: f64) -> Option<usize> {
        self.swing(humanoid, time_s).map(|(stance, _)| stance)
    }

    /// The swing under way at `time_s`, its stance foot and where the
    /// take's ankle of that foot is. It starts on the humanoid's own
    /// lift-off where the take stands on one foot alone (as SIMBICON's
    /// state machine switches on contact: steered while still bearing
    /// weight, a foot was torn from under the body), and lasts until the
    /// humanoid's swing foot lands, also where the take, stepping, already
    /// stands on both feet: its double support starts as its heel strikes,
    /// and a humanoid whose foot had not landed yet was left to the
    /// standing balance, its foot coming down where the take's pose put it
    /// rather than where its capture point needed it (over bandai's 44
    /// walks at 480, 360 and 240 Hz, with the stances read from the toes
    /// too: 38, 41 and 41 up, against 36, 35 and 33 without this).
    fn swing(&self, humanoid: &Humanoid, time_s: f64) -> Option<(usize, DVec3)> {
        if !self.balance {
            return None;
        }
        if let Some((stance, ankle)) = self.contacts.single_stance(time_s) {
            return (!humanoid.stands(FEET[1 - stance])).then_some((stance, ankle));
        }
        if !(self.contacts.standing_at(time_s) == [true, true] && self.contacts.stepping(time_s)) {
            return None;
        }
        let stance = match FEET.map(|foot| humanoid.stands(foot)) {
            [true, false] => 0,
            [false, true] => 1,
            _ => return None,
        };
        Some((stance, self.contacts.ankle(time_s, stance)))
    }

    /// Sets `asked` for `time_s` and takes the physics step to it, a swing
    /// foot landing `placement` (m, on the ground) from where the capture
    /// point puts it. Returns the departure: the most any joint's target
    /// was turned from the take's to stay up, radians.
    pub fn step(
        &self,
        humanoid: &mut Humanoid,
        time_s: f64,
        asked: &mut [JointTarget; JOINTS],
        placement: DVec3,
    ) -> f64 {
        self.played.sample(time_s, asked);
        let stepping = self.balance && self.contacts.stepping(time_s);
        let root = self.played.root_at(time_s);
        let mut departure_rad = 0.0;
        // Where the weight is, for the balance and the assistance alike:
        // neither changes it before the step.
        let mut state = None;
        if self.balance {
            let mut wanted = *asked;
            self.take.sample(time_s, &mut wanted);
            self.contacts.lift_swing_feet(self.body, root.rotation, time_s, asked);
            if let Some((foot, ankle)) = self.swing(humanoid, time_s) {
                humanoid.step_over(asked, foot, ankle, &root, placement);
            } else {
                let stance = self.contacts.single_stance(time_s).map(|(foot, _)| foot);
                let state = state.get_or_insert_with(|| humanoid.balance_state());
                humanoid.balance(asked, stance, state);
                if stance.is_some() {
                    humanoid.hold_trunk(asked, root.rotation);
                }
            }
            departure_rad = motorized()
                .map(|j| angle_between(wanted[j.index()].rotation, asked[j.index()].rotation))
                .fold(0.0, f64::max);
        }
        if self.assist {
            let state = state.unwrap_or_else(|| humanoid.balance_state());
            humanoid.assist_toward(&root, &state);
        }
        humanoid.step(asked, self.gains, stepping);
        departure_rad
    }

    /// Whether `humanoid` has fallen while playing toward the take's frame
    /// `k`.
    pub fn fallen(&self, humanoid: &Humanoid, k: usize) -> bool {
        fallen(humanoid, self.standing_pelvis_m, self.leans_rad[k])
    }

    /// Where, from the capture point's placement, the swing starting now
    /// (`from_s`, the humanoid stepped every `dt_s`) best lands: each of a
    /// grid of placements played for `horizon_s` on a copy of the world,
    /// the one that stays up with the least cost, or else falls latest
    /// (the first of equals, so the choice is the same every run).
    pub fn plan_swing(&self, humanoid: &Humanoid, from_s: f64, dt_s: f64, horizon_s: f64) -> DVec3 {
        let root = self.played.root_at(from_s);
        let forward = (root.rotation * DVec3::Z).with_y(0.0).normalize_or(DVec3::Z);
        let side = DVec3::Y.cross(forward);
        let reach = |i: i32| PLACEMENT_REACH_M * f64::from(i) / f64::from(PLACEMENT_STEPS);
        let grid = || -PLACEMENT_STEPS..=PLACEMENT_STEPS;
        let placements: Vec<DVec3> =
            grid().flat_map(|f| grid().map(move |s| reach(f) * forward + reach(s) * side)).collect();
        let costs: Vec<f64> =
            placements.par_iter().map(|&p| self.try_placement(humanoid, from_s, dt_s, horizon_s, p)).collect();
        let best = (0..costs.len()).min_by(|&a, &b| costs[a].total_cmp(&costs[b]).then(a.cmp(&b)));
        best.map_or(DVec3::ZERO, |k| placements[k])
    }

    /// The cost of landing the swing under way at `placement`, played on a
    /// copy of `humanoid` from `from_s` for `horizon_s` (or to the take's
    /// end).
    fn try_placement(&self, humanoid: &Humanoid, from_s: f64, dt_s: f64, horizon_s: f64, placement: DVec3) -> f64 {
        let mut trial = humanoid.fork();
        let mut asked = [JointTarget::REST; JOINTS];
        let frame_time = self.take.frame_time_s();
        let last = self.take.frames() - 1;
        let end_s = (from_s + horizon_s).min(last as f64 * frame_time);
        let steps = ((end_s - from_s) / dt_s).round().max(0.0) as usize;
        for i in 1..=steps {
            let time_s = from_s + i as f64 * dt_s;
            self.step(&mut trial, time_s, &mut asked, placement);
            // The frame this step plays toward, as `execute` counts it.
            let k = ((time_s / frame_time) - 1e-9).ceil().clamp(0.0, last as f64) as usize;
            if trial.runaway().is_some() || self.fallen(&trial, k) {
                return FALLEN_COST + (steps - i) as f64 / steps as f64;
            }
        }
        let root = self.played.root_at(end_s);
        let tilt = (trial.rotation(Joint::Pelvis) * DVec3::Y).angle_between(root.rotation * DVec3::Y);
        let slip = (trial.balance_state().velocity - root.velocity).with_y(0.0);
        tilt * tilt + VELOCITY_WEIGHT_S2_PER_M2 * slip.length_squared()
    }
}

/// The angle between the trunk (pelvis to neck) and the vertical.
pub(super) fn lean(frame: &BodyFrame) -> f64 {
    (frame.position(Joint::Neck) - frame.position(Joint::Pelvis)).angle_between(DVec3::Y)
}

/// Whether the humanoid has fallen where the trajectory leans its trunk by
/// `asked_lean_rad`.
fn fallen(humanoid: &Humanoid, standing_pelvis_m: f64, asked_lean_rad: f64) -> bool {
    let frame = humanoid.frame();
    frame.position(Joint::Pelvis).y < FALLEN_PELVIS_SHARE * standing_pelvis_m
        || lean(&frame) > asked_lean_rad + FALLEN_LEAN_RAD
        || [Joint::Pelvis, Joint::Spine, Joint::Chest, Joint::Neck, Joint::Head]
            .into_iter()
            .any(|j| humanoid.touches_ground(j))
}

#[cfg(test)]
mod tests {
    use super::super::humanoid::Base;
    use super::*;
    use crate::mocap::pose::{Motion, Pose};
    use glam::DQuat;
    use std::f64::consts::FRAC_PI_3;

    /// The standard body bowing: spine and chest each bent forward by
    /// `each_deg`.
    fn bow(body: &Body, each_deg: f64) -> Pose {
        let mut local = [DQuat::IDENTITY; JOINTS];
        for j in [Joint::Spine, Joint::Chest] {
            local[j.index()] = DQuat::from_rotation_x(each_deg.to_radians());
        }
        Pose::from_rotations(Pose::rest(body).root, &local)
    }

    #[test]
    fn a_deep_bow_is_a_fall_only_when_the_trajectory_does_not_bow() {
        let body = Body::standard();
        let pose = bow(&body, 60.0);
        let asked = lean(&body.forward(&pose));
        assert!(asked > FRAC_PI_3, "the bow leans {:.0}°", asked.to_degrees());
        let humanoid = Humanoid::new(&body, Base::Free, &pose, &[JointTarget::REST; JOINTS], 1.0 / 240.0, [false; 2]);
        let standing = body.pelvis_height();
        assert!(!fallen(&humanoid, standing, asked), "bowing as asked");
        assert!(fallen(&humanoid, standing, 0.0), "bowing where the trajectory stands upright");
    }

    #[test]
    fn a_swing_goes_on_through_the_takes_double_support_until_the_swing_foot_lands() {
        let body = Body::standard();
        let flat = Pose::rest(&body);
        let mut local = [DQuat::IDENTITY; JOINTS];
        local[Joint::RightHip.index()] = DQuat::from_rotation_x(-0.8);
        local[Joint::RightKnee.index()] = DQuat::from_rotation_x(1.5);
        let lifted = Pose::from_rotations(flat.root, &local);
        // The humanoid on its left foot, its right held up, once the
        // physics has found its contacts.
        let mut held = [JointTarget::REST; JOINTS];
        for j in Joint::ALL {
            held[j.index()].rotation = lifted.local_rotation(j);
        }
        let mut humanoid = Humanoid::new(&body, Base::Free, &lifted, &held, 1.0 / 240.0, [true, false]);
        for _ in 0..3 {
            humanoid.step(&held, Gains::STANDARD, false);
        }
        assert!(humanoid.stands(Joint::LeftAnkle) && !humanoid.stands(Joint::RightAnkle));
        let swinging = |poses: Vec<Pose>, frame: f64| {
            let take = Motion { body: body.clone(), frame_time_s: 1.0 / 30.0, poses };
            let targets = Targets::new(&take).unwrap();
            let contacts = Contacts::of(&take);
            let control = Controller {
                played: &targets,
                take: &targets,
                contacts: &contacts,
                body: &body,
                balance: true,
                assist: false,
                gains: Gains::STANDARD,
                standing_pelvis_m: body.pelvis_height(),
                leans_rad: vec![0.0; take.poses.len()],
            };
            control.swinging(&humanoid, frame * take.frame_time_s)
        };
        // The take on both feet, on its left alone, on both, 10 frames each.
        let step = || [flat; 10].into_iter().chain([lifted; 10]).chain([flat; 10]).collect::<Vec<_>>();
        assert_eq!(swinging(step(), 15.0), Some(0), "the take on its left foot alone");
        assert_eq!(swinging(step(), 23.0), Some(0), "the take's right foot down, the humanoid's not yet");
        // A take that stands on both feet throughout has no swing.
        assert_eq!(swinging(vec![flat; 30], 15.0), None);
    }
}
