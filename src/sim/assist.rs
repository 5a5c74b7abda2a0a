//! Assistance (`execute --assist`): a residual force and torque on the
//! pelvis that pull it toward the trajectory's, the "hand of God" of
//! physics-based character control, for motion the humanoid's own joints
//! cannot follow on the ground (walking without stepping, jumps). It is
//! always reported, never hidden: its size at every frame and over the
//! run. It acts as far as it is needed: not while the humanoid stands
//! well over its feet and upright, fully once it is falling.
//!
//! The pull is a six-axis spring joint from a body that carries the
//! trajectory's pelvis (moved to it every step, and colliding with
//! nothing) to the humanoid's pelvis. The solver treats a joint's spring
//! implicitly; the same spring applied as an external force on the pelvis
//! link is explicit, and its damping, scaled for the whole body and
//! acting on the pelvis's small inertia alone, blew the humanoid apart in
//! the first step (measured: 10⁵ N at once).

use super::humanoid::{Humanoid, to_f64};
use super::targets::RootTarget;
use crate::mocap::body::Joint;
use glam::DVec3;
use rapier3d::prelude::*;

/// The pull's natural frequency (rad/s), critically damped: stiff enough to
/// hold a falling body up within a few centimetres, soft beside the
/// joints' 100 rad/s so the joints, not the pull, make the motion.
const ASSIST_RAD_S: f64 = 10.0;
/// The radius of gyration (m) the torque's gains treat the whole body as
/// turning with about its pelvis: about a standing adult's about a
/// horizontal axis through the hips.
const GYRATION_M: f64 = 0.5;
/// How long (s) the pull's far end takes to follow the shift the balance
/// asks of the pelvis (a first-order lag: moved at once, its jumps kicked
/// the body apart). The shift is what the balance asks on top of the
/// trajectory, not where the legs then carry the pelvis, so a pull stays
/// where they do not (the unit test's trunk bent sideways: 250 N → 222 N
/// horizontally). Pulled toward the trajectory's pelvis alone, the pull
/// fought the balance wherever the take's weight is off its feet: over real/'s
/// 13 standing takes the median pull was 45% of body weight and the
/// median RMS joint error 4.4°; following it with a lag of 0.2 s, 24% and
/// 2.0° (bandai's standing gestures 22% → 16%, its walks 83% → 77%; a lag
/// of 0.1 s left the walks at 86%).
const FOLLOW_BALANCE_S: f64 = 0.2;
/// The pull stiffens while the pelvis tilts away from the trajectory's:
/// from this tilt (rad, ~9°) ...
const STIFFEN_FROM_RAD: f64 = 0.15;
/// ... its natural frequency rises linearly to this many times
/// `ASSIST_RAD_S`, reached at twice that tilt. A fall in the making is
/// caught while the pull elsewhere stays as soft as it was: at a constant
/// 10 rad/s 3 of bandai's 44 walks fell; at a constant 16 rad/s all
/// completed but the median pull on real/'s standing takes rose from 24%
/// to 42% of body weight; stiffening from 9° to 3× completes all 46 walks
/// and leaves the medians where they were (from 0.1–0.2 rad up to 2.5–3×
/// completed them all, up to 2× left 1 falling).
const STIFFEN_MAX: f64 = 3.0;
/// The pull acts as far as it is needed: not at all while the capture
/// point lies this far (m) or more inside the support, fully once it
/// reaches the edge (or no foot stands) ...
const NEED_MARGIN_M: f64 = 0.05;
/// ... or once the pelvis tilts this far (rad, ~17°) from the
/// trajectory's, in proportion below. Pulling always, the spring held a
/// humanoid that stood by itself where the trajectory's pelvis was rather
/// than where its balance had put it: the median pull on bandai's standing
/// gestures was 16% of body weight, on real/'s standing takes 26%; as
/// needed, 2% and 16%, every take still completing (bandai's walks 73% →
/// 69%, real/'s 59% → 48%). On the capture point alone (2–5 cm) one of
/// real/'s jumps fell on landing.
const NEED_TILT_RAD: f64 = 0.3;
const LINEAR: [JointAxis; 3] = [JointAxis::LinX, JointAxis::LinY, JointAxis::LinZ];
const ANGULAR: [JointAxis; 3] = [JointAxis::AngX, JointAxis::AngY, JointAxis::AngZ];
const ANCHOR: &str = "the assistance's joint is never removed";

/// A force (N) and a torque (N·m) on the pelvis, world axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wrench {
    pub force: DVec3,
    pub torque: DVec3,
}

impl Humanoid {
    /// Attaches the assistance's spring where the pelvis is now, scaled by
    /// the whole body's mass and its inertia about the pelvis so it moves
    /// the body, not only the pelvis.
    pub fn attach_assist(&mut self) {
        let pelvis = self.links[Joint::Pelvis.index()];
        let at = *self.world.bodies[pelvis].position();
        let anchor = self.world.bodies.insert(RigidBodyBuilder::kinematic_position_based().pose(at));
        let mut joint = GenericJointBuilder::new(JointAxesMask::empty()).build();
        for axis in LINEAR.into_iter().chain(ANGULAR) {
            joint.set_motor_model(axis, MotorModel::ForceBased);
        }
        set_pull(&mut joint, self.mass_kg(), ASSIST_RAD_S);
        let handle = self.world.impulse_joints.insert(anchor, pelvis, joint, true);
        self.anchor = Some((anchor, handle));
    }

    /// Moves the spring's far end to `target` (the trajectory's pelvis,
    /// shifted by `offset` to where the humanoid was put, and by where the
    /// balance now moves the pelvis, `balance_shift`, followed with a lag
    /// of `FOLLOW_BALANCE_S`) by the end of the next step, so the pull does
    /// not drag the pelvis back against the balance's corrections; the
    /// pull stiffens as the pelvis tilts away from `target`'s
    /// (`STIFFEN_FROM_RAD`, `STIFFEN_MAX`), and acts only as far as the
    /// humanoid needs it (`NEED_MARGIN_M`, `NEED_TILT_RAD`).
    pub fn assist_toward(&mut self, target: &RootTarget, offset: DVec3, balance_shift: DVec3) {
        let dt = f64::from(self.world.integration_parameters.dt);
        self.assist_shift += (balance_shift - self.assist_shift) * (dt / FOLLOW_BALANCE_S).min(1.0);
        let (anchor, handle) = self.anchor.expect("attach_assist comes first");
        let tilt = (self.rotation(Joint::Pelvis) * DVec3::Y).angle_between(target.rotation * DVec3::Y);
        let stiffen = ((tilt - STIFFEN_FROM_RAD) / STIFFEN_FROM_RAD).clamp(0.0, 1.0);
        let share = need(self.balance_state().margin_m(), tilt);
        let mass = self.mass_kg();
        let joint = &mut self.world.impulse_joints.get_mut(handle, false).expect(ANCHOR).data;
        set_pull(joint, share * mass, ASSIST_RAD_S * (1.0 + stiffen * (STIFFEN_MAX - 1.0)));
        let at = target.position + offset + self.assist_shift;
        let pose = rapier3d::math::Pose::from_parts(at.as_vec3(), target.rotation.as_quat());
        self.world.bodies[anchor].set_next_kinematic_position(pose);
    }

    /// The force and torque the spring applied to the pelvis in the last
    /// substep of the last step; zero without assistance.
    pub fn assist_wrench(&self) -> Wrench {
        let Some((anchor, handle)) = self.anchor else { return Wrench::default() };
        let data = &self.world.impulse_joints.get(handle).expect(ANCHOR).data;
        let frame = to_f64(*self.world.bodies[anchor].rotation()) * to_f64(data.local_frame1.rotation);
        let substep = self.substep_s();
        let along = |axes: [JointAxis; 3]| {
            let impulse = axes.map(|a| data.motor(a).map_or(0.0, |m| f64::from(m.impulse)));
            frame * DVec3::from_array(impulse) / substep
        };
        Wrench { force: along(LINEAR), torque: along(ANGULAR) }
    }
}

/// How much of the pull acts (0 to 1), with the capture point `margin_m`
/// inside the support (`None`: no foot stands) and the pelvis tilted
/// `tilt_rad` from the trajectory's: `NEED_MARGIN_M`, `NEED_TILT_RAD`.
fn need(margin_m: Option<f64>, tilt_rad: f64) -> f64 {
    let falling = margin_m.map_or(1.0, |m| ((NEED_MARGIN_M - m) / NEED_MARGIN_M).clamp(0.0, 1.0));
    falling.max((tilt_rad / NEED_TILT_RAD).min(1.0))
}

/// Sets the pull's springs to natural frequency `rad_s`, critically
/// damped, scaled by the body's `mass_kg` and its inertia about the pelvis
/// so they move the body, not only the pelvis.
fn set_pull(joint: &mut GenericJoint, mass_kg: f64, rad_s: f64) {
    let inertia = mass_kg * GYRATION_M * GYRATION_M;
    let (kp, kd) = (rad_s * rad_s, 2.0 * rad_s);
    for (axes, scale) in [(LINEAR, mass_kg), (ANGULAR, inertia)] {
        for axis in axes {
            joint.set_motor(axis, 0.0, 0.0, (kp * scale) as f32, (kd * scale) as f32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::{Body, JOINTS};
    use crate::mocap::pose::Pose;
    use crate::sim::humanoid::{Base, Gains};
    use crate::sim::targets::JointTarget;
    use glam::DQuat;

    const DT: f64 = 1.0 / 240.0;

    /// The standard humanoid standing at rest, assisted, and a trajectory's
    /// pelvis where its pelvis is, turned `tilt_deg` forward.
    fn assisted_at_rest(tilt_deg: f64) -> (Humanoid, RootTarget) {
        let body = Body::standard();
        let mut humanoid = Humanoid::new(&body, Base::Free, &Pose::rest(&body), &[JointTarget::REST; JOINTS], DT);
        humanoid.attach_assist();
        let root = RootTarget {
            position: humanoid.frame().position(Joint::Pelvis),
            velocity: DVec3::ZERO,
            rotation: DQuat::from_rotation_x(tilt_deg.to_radians()) * humanoid.rotation(Joint::Pelvis),
            spin: DVec3::ZERO,
        };
        (humanoid, root)
    }

    /// The mean horizontal pull (N) over the last of five seconds standing with the
    /// trunk bent 40° sideways (the weight well off the middle of the
    /// feet, which the balance shifts the pelvis against), assisted toward
    /// the standing pelvis; `follow`: whether the pull's far end follows
    /// the balance's shift.
    fn mean_pull_n(follow: bool) -> f64 {
        let (mut humanoid, root) = assisted_at_rest(0.0);
        let mut targets = [JointTarget::REST; JOINTS];
        for j in [Joint::Spine, Joint::Chest] {
            targets[j.index()].rotation = DQuat::from_rotation_z(20f64.to_radians());
        }
        let (steps, last) = ((5.0 / DT) as usize, (1.0 / DT) as usize);
        let mut sum = 0.0;
        for k in 0..steps {
            let mut asked = targets;
            let shift = humanoid.balance(&mut asked, None);
            humanoid.assist_toward(&root, DVec3::ZERO, if follow { shift } else { DVec3::ZERO });
            humanoid.step(&asked, Gains::STANDARD, false);
            if k >= steps - last {
                let force = humanoid.assist_wrench().force;
                sum += DVec3::new(force.x, 0.0, force.z).length();
            }
        }
        sum / last as f64
    }

    /// The stiffness (N·m/rad) of the pull's turning springs on a humanoid
    /// standing at rest, pulled toward a trajectory whose pelvis is turned
    /// `tilt_deg` forward.
    fn turning_stiffness(tilt_deg: f64) -> f64 {
        let (mut humanoid, root) = assisted_at_rest(tilt_deg);
        // A step to find the feet on the ground.
        humanoid.step(&[JointTarget::REST; JOINTS], Gains::STANDARD, false);
        humanoid.assist_toward(&root, DVec3::ZERO, DVec3::ZERO);
        let (_, handle) = humanoid.anchor.unwrap();
        let joint = &humanoid.world.impulse_joints.get(handle).unwrap().data;
        f64::from(joint.motor(JointAxis::AngX).unwrap().stiffness)
    }

    #[test]
    fn the_pull_stiffens_once_the_pelvis_tilts_well_away_from_the_trajectorys() {
        let full = crate::sim::anthropometry::body_mass_kg(&Body::standard()) * (GYRATION_M * ASSIST_RAD_S).powi(2);
        // Standing at rest, the capture point well inside the feet, only
        // the tilt calls for the pull; halfway up the stiffening ramp the
        // frequency is 2×, the stiffness 4×.
        let halfway = (1.5 * STIFFEN_FROM_RAD).to_degrees();
        for (tilt_deg, times) in [(0.0, 0.0), (8.0, 1.0), (halfway, 4.0), (30.0, 9.0)] {
            let needed = (f64::to_radians(tilt_deg) / NEED_TILT_RAD).min(1.0);
            let got = turning_stiffness(tilt_deg);
            let want = needed * times * full;
            assert!((got - want).abs() < 0.01 * full, "{got:.1} N·m/rad at {tilt_deg}°, {want:.1} expected");
        }
    }

    #[test]
    fn the_pull_acts_as_far_as_the_capture_point_nears_the_edge_or_the_pelvis_tilts() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        // Well inside the feet and upright: none.
        assert!(close(need(Some(2.0 * NEED_MARGIN_M), 0.0), 0.0));
        assert!(close(need(Some(NEED_MARGIN_M), 0.0), 0.0));
        assert!(close(need(Some(0.5 * NEED_MARGIN_M), 0.0), 0.5));
        // At the edge, beyond it, or in the air: all of it.
        for margin in [Some(0.0), Some(-0.3), None] {
            assert!(close(need(margin, 0.0), 1.0), "{margin:?}");
        }
        // The larger of the two calls.
        assert!(close(need(Some(0.8 * NEED_MARGIN_M), 0.5 * NEED_TILT_RAD), 0.5));
        assert!(close(need(Some(NEED_MARGIN_M), 2.0 * NEED_TILT_RAD), 1.0));
    }

    #[test]
    fn following_the_balance_the_pull_is_smaller_than_holding_the_pelvis_where_the_trajectory_has_it() {
        // Measured: 222 N against 250 N. The balance's shift is what it
        // asks on top of the trajectory, not where the legs carry the
        // pelvis, so some pull stays.
        let (held, following) = (mean_pull_n(false), mean_pull_n(true));
        assert!(following < 0.95 * held, "{following:.1} N following the balance against {held:.1} N held");
    }
}
