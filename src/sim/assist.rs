//! Assistance (`execute --assist`): a residual force and torque on the
//! pelvis, the "hand of God" of physics-based character control, for
//! motion the humanoid's own joints cannot follow on the ground (walking
//! without stepping, jumps). It is always reported, never hidden: its size
//! at every frame and over the run. It acts as far as it is needed and no
//! further, in two parts:
//!
//! - a horizontal force that keeps the capture point over the feet, as
//!   much as the inverted pendulum needs (`PUSH_GAIN`). It does not hold
//!   the pelvis where the trajectory has it: the humanoid walks as far as
//!   its own legs carry it. A six-axis spring to the trajectory's pelvis
//!   did, and dragged the humanoid along the take's path: over bandai's 44
//!   walks its mean force was 53% of body weight (median), against 4% for
//!   the push, every walk completing under both.
//! - a torque that turns the pelvis toward the trajectory's, from a
//!   spring joint to a body that carries the trajectory's pelvis (turned
//!   to it every step, colliding with nothing): the solver treats a
//!   joint's spring implicitly, where the same torque applied on the
//!   pelvis link is explicit and its damping, scaled for the whole body
//!   and acting on the pelvis's small inertia alone, blew the humanoid
//!   apart in the first step (measured: 10⁵ N at once). Falls on the
//!   ground are the body toppling, which a force near the centre of mass
//!   cannot stop: with the push alone, 41 of bandai's 44 walks fell.

use super::balance::{BalanceState, brought_inside, convex_hull};
use super::humanoid::{GRAVITY_M_S2, Humanoid, to_f64};
use super::targets::RootTarget;
use crate::mocap::body::Joint;
use glam::{DVec2, DVec3};
use rapier3d::prelude::*;

/// How many times the force that stops the capture point drifting further
/// out (m·g/h per metre it lies beyond the feet: the inverted pendulum's
/// divergence) the push applies: 1 holds it at the feet's edge, 2 brings
/// it back at the pendulum's own rate. Over bandai's 44 walks (turning
/// spring critically damped), 2 and 3 each let one walk fall; 3 raised the
/// median mean force from 5.1% to 6.0% of body weight.
const PUSH_GAIN: f64 = 2.0;
/// The turning spring's natural frequency (rad/s): stiff enough to hold a
/// toppling body up within a few degrees, soft beside the joints' 100
/// rad/s so the joints, not the spring, make the motion.
const ASSIST_RAD_S: f64 = 10.0;
/// The turning spring's damping ratio. Its damping acts on every
/// difference between the pelvis's spin and the trajectory's, which a
/// humanoid stepping out of phase with the take has all the time: over
/// bandai's 44 walks, critically damped (1) one fell and the median mean
/// torque was 149 N·m; at 0.5 none fell (also at 240 and 960 Hz) and it
/// was 121 N·m; at 0.3, 112 N·m.
const DAMPING_RATIO: f64 = 0.5;
/// The radius of gyration (m) the turning spring treats the whole body as
/// turning with about its pelvis: about a standing adult's about a
/// horizontal axis through the hips.
const GYRATION_M: f64 = 0.5;
/// The turning spring stiffens while the pelvis tilts away from the
/// trajectory's: from this tilt (rad, ~9°) ...
const STIFFEN_FROM_RAD: f64 = 0.15;
/// ... its natural frequency rises linearly to this many times
/// `ASSIST_RAD_S`, reached at twice that tilt. A fall in the making is
/// caught while the spring elsewhere stays as soft as it was. (Measured
/// when the assistance was a six-axis spring: at a constant 10 rad/s 3 of
/// bandai's 44 walks fell; at a constant 16 rad/s all completed but the
/// median pull on real/'s standing takes rose from 24% to 42% of body
/// weight; stiffening from 9° to 3× completed all 46 walks and left the
/// medians where they were.)
const STIFFEN_MAX: f64 = 3.0;
/// The turning spring acts as far as it is needed: not at all while the
/// capture point lies this far (m) or more inside the support, fully once
/// it reaches the edge (or no foot stands) ...
const NEED_MARGIN_M: f64 = 0.05;
/// ... or once the pelvis tilts this far (rad, ~17°) from the
/// trajectory's, in proportion below. (Measured with the six-axis spring:
/// pulling always, the median pull on bandai's standing gestures was 16% of
/// body weight, on real/'s standing takes 26%; as needed, 2% and 16%,
/// every take still completing.)
const NEED_TILT_RAD: f64 = 0.3;
const ANGULAR: [JointAxis; 3] = [JointAxis::AngX, JointAxis::AngY, JointAxis::AngZ];
const ANCHOR: &str = "the assistance's joint is never removed";

/// A force (N) and a torque (N·m) on the pelvis, world axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wrench {
    pub force: DVec3,
    pub torque: DVec3,
}

impl Humanoid {
    /// Attaches the assistance's turning spring where the pelvis is now.
    pub fn attach_assist(&mut self) {
        let pelvis = self.links[Joint::Pelvis.index()];
        let at = *self.world.bodies[pelvis].position();
        let anchor = self.world.bodies.insert(RigidBodyBuilder::kinematic_position_based().pose(at));
        let mut joint = GenericJointBuilder::new(JointAxesMask::empty()).build();
        for axis in ANGULAR {
            joint.set_motor_model(axis, MotorModel::ForceBased);
        }
        set_turning(&mut joint, self.mass_kg(), ASSIST_RAD_S);
        let handle = self.world.impulse_joints.insert(anchor, pelvis, joint, true);
        self.anchor = Some((anchor, handle));
    }

    /// Sets the assistance for the next step: the push that keeps the
    /// capture point over the feet (`PUSH_GAIN`), and the turning spring
    /// toward `target`'s pelvis, stiffened as the pelvis tilts away from it
    /// (`STIFFEN_FROM_RAD`, `STIFFEN_MAX`) and acting only as far as the
    /// humanoid needs it (`NEED_MARGIN_M`, `NEED_TILT_RAD`); `state` is
    /// [`Humanoid::balance_state`] now.
    pub fn assist_toward(&mut self, target: &RootTarget, state: &BalanceState) {
        let (anchor, handle) = self.anchor.expect("attach_assist comes first");
        let mass = self.mass_kg();
        // Both feet, standing or not: a swinging foot lands where it is
        // headed. Over the standing feet alone, the push held the capture
        // point back against every step (bandai's walks: median mean force
        // 12% of body weight against 4%; real/'s zombie walk fell).
        let feet = convex_hull((0..2).flat_map(|k| self.sole(k)).map(|c| DVec2::new(c.x, c.z)).collect());
        let push = push_n(&feet, state.capture, mass, state.height_m);
        self.assist_force = DVec3::new(push.x, 0.0, push.y);

        let tilt = (self.rotation(Joint::Pelvis) * DVec3::Y).angle_between(target.rotation * DVec3::Y);
        let stiffen = ((tilt - STIFFEN_FROM_RAD) / STIFFEN_FROM_RAD).clamp(0.0, 1.0);
        let share = need(state.margin_m(), tilt);
        let joint = &mut self.world.impulse_joints.get_mut(handle, false).expect(ANCHOR).data;
        set_turning(joint, share * mass, ASSIST_RAD_S * (1.0 + stiffen * (STIFFEN_MAX - 1.0)));
        let pelvis = &mut self.world.bodies[self.links[Joint::Pelvis.index()]];
        // Forces added to a body stay until reset.
        pelvis.reset_forces(false);
        pelvis.add_force(self.assist_force.as_vec3(), true);
        let pose = rapier3d::math::Pose::from_parts(pelvis.translation(), target.rotation.as_quat());
        self.world.bodies[anchor].set_next_kinematic_position(pose);
    }

    /// The force and torque the assistance applied to the pelvis in the
    /// last substep of the last step; zero without assistance.
    pub fn assist_wrench(&self) -> Wrench {
        let Some((anchor, handle)) = self.anchor else { return Wrench::default() };
        let data = &self.world.impulse_joints.get(handle).expect(ANCHOR).data;
        let frame = to_f64(*self.world.bodies[anchor].rotation()) * to_f64(data.local_frame1.rotation);
        let impulse = ANGULAR.map(|a| data.motor(a).map_or(0.0, |m| f64::from(m.impulse)));
        Wrench { force: self.assist_force, torque: frame * DVec3::from_array(impulse) / self.substep_s() }
    }
}

/// The horizontal force (N, on the ground's x and z) that brings the
/// capture point `capture` back over the convex polygon `feet`, for a body
/// of `mass_kg` whose centre of mass stands `height_m` over them: none
/// while it lies over them; beyond, `PUSH_GAIN` × m·g/h per metre it lies
/// out.
fn push_n(feet: &[DVec2], capture: DVec2, mass_kg: f64, height_m: f64) -> DVec2 {
    let back = brought_inside(feet, capture, 0.0) - capture;
    PUSH_GAIN * mass_kg * GRAVITY_M_S2 / height_m * back
}

/// How much of the turning spring acts (0 to 1), with the capture point
/// `margin_m` inside the support (`None`: no foot stands) and the pelvis
/// tilted `tilt_rad` from the trajectory's: `NEED_MARGIN_M`,
/// `NEED_TILT_RAD`.
fn need(margin_m: Option<f64>, tilt_rad: f64) -> f64 {
    let falling = margin_m.map_or(1.0, |m| ((NEED_MARGIN_M - m) / NEED_MARGIN_M).clamp(0.0, 1.0));
    falling.max((tilt_rad / NEED_TILT_RAD).min(1.0))
}

/// Sets the turning spring to natural frequency `rad_s` and
/// `DAMPING_RATIO`, for a body of `mass_kg` turning about its pelvis with
/// `GYRATION_M`.
fn set_turning(joint: &mut GenericJoint, mass_kg: f64, rad_s: f64) {
    let inertia = mass_kg * GYRATION_M * GYRATION_M;
    let (stiffness, damping) = (inertia * rad_s * rad_s, inertia * 2.0 * DAMPING_RATIO * rad_s);
    for axis in ANGULAR {
        joint.set_motor(axis, 0.0, 0.0, stiffness as f32, damping as f32);
        // rapier takes a motor's compliance as the inverse of its stiffness
        // and damping, and that of zero as zero: without this, a spring
        // with nothing to do would lock the pelvis rigidly.
        joint.set_motor_max_force(axis, if stiffness > 0.0 { f32::MAX } else { 0.0 });
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
    /// A shove that topples the unassisted humanoid holding the rest
    /// pose (measured: 0.3 m/s does not, 0.5 m/s does).
    const SHOVE_M_S: f64 = 0.8;

    /// The standard humanoid standing at rest, assisted when `assisted`,
    /// and a trajectory's pelvis where its pelvis is, turned `tilt_deg`
    /// forward.
    fn at_rest(tilt_deg: f64, assisted: bool) -> (Humanoid, RootTarget) {
        let body = Body::standard();
        let mut humanoid =
            Humanoid::new(&body, Base::Free, &Pose::rest(&body), &[JointTarget::REST; JOINTS], DT, [false; 2]);
        if assisted {
            humanoid.attach_assist();
        }
        let root = RootTarget {
            position: humanoid.frame().position(Joint::Pelvis),
            velocity: DVec3::ZERO,
            rotation: DQuat::from_rotation_x(tilt_deg.to_radians()) * humanoid.rotation(Joint::Pelvis),
            spin: DVec3::ZERO,
        };
        (humanoid, root)
    }

    /// The stiffness (N·m/rad) of the turning spring on a humanoid
    /// standing at rest, turned toward a trajectory whose pelvis is turned
    /// `tilt_deg` forward.
    fn turning_stiffness(tilt_deg: f64) -> f64 {
        let (mut humanoid, root) = at_rest(tilt_deg, true);
        // A step to find the feet on the ground.
        humanoid.step(&[JointTarget::REST; JOINTS], Gains::STANDARD, false);
        humanoid.assist_toward(&root, &humanoid.balance_state());
        let (_, handle) = humanoid.anchor.unwrap();
        let joint = &humanoid.world.impulse_joints.get(handle).unwrap().data;
        f64::from(joint.motor(JointAxis::AngX).unwrap().stiffness)
    }

    #[test]
    fn the_spring_stiffens_once_the_pelvis_tilts_well_away_from_the_trajectorys() {
        let full = crate::sim::anthropometry::body_mass_kg(&Body::standard()) * (GYRATION_M * ASSIST_RAD_S).powi(2);
        // Standing at rest, the capture point well inside the feet, only
        // the tilt calls for the spring; halfway up the stiffening ramp the
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
    fn a_spring_with_nothing_to_do_turns_nothing() {
        // The trajectory's pelvis spins about the vertical at 1 rad/s; a
        // spring set to nothing must not drag the humanoid's along (a
        // rapier motor without stiffness or damping is a rigid lock).
        let (mut humanoid, _) = at_rest(0.0, true);
        let (anchor, handle) = humanoid.anchor.unwrap();
        let start = humanoid.rotation(Joint::Pelvis);
        for k in 1..=24 {
            set_turning(&mut humanoid.world.impulse_joints.get_mut(handle, false).unwrap().data, 0.0, ASSIST_RAD_S);
            let turned = DQuat::from_rotation_y(k as f64 * DT) * start;
            let at = humanoid.world.bodies[anchor].translation();
            humanoid.world.bodies[anchor]
                .set_next_kinematic_position(rapier3d::math::Pose::from_parts(at, turned.as_quat()));
            humanoid.step(&[JointTarget::REST; JOINTS], Gains::STANDARD, false);
            assert_eq!(humanoid.assist_wrench().torque, DVec3::ZERO, "step {k}");
        }
        let turned_deg = humanoid.rotation(Joint::Pelvis).angle_between(start).to_degrees();
        assert!(turned_deg < 0.5, "the pelvis turned {turned_deg:.2}° with the spring");
    }

    #[test]
    fn the_push_is_the_pendulums_divergence_times_the_gain_beyond_the_feet_and_none_over_them() {
        // Two feet side by side: 0.2 m across, 0.25 m long.
        let feet = convex_hull(vec![
            DVec2::new(-0.1, -0.05),
            DVec2::new(0.1, -0.05),
            DVec2::new(0.1, 0.2),
            DVec2::new(-0.1, 0.2),
        ]);
        let (mass, height) = (70.0, 0.9);
        for capture in [DVec2::ZERO, DVec2::new(0.1, 0.2), DVec2::new(-0.05, 0.1)] {
            assert_eq!(push_n(&feet, capture, mass, height), DVec2::ZERO, "{capture}");
        }
        // 0.1 m ahead of the toes, on the way to the middle: pushed back.
        let push = push_n(&feet, DVec2::new(0.0, 0.3), mass, height);
        let want = PUSH_GAIN * mass * GRAVITY_M_S2 / height * 0.1;
        assert!(push.x.abs() < 1e-6 && (push.y + want).abs() < 1e-6, "{push} against {want:.1} N back");
    }

    #[test]
    fn the_spring_acts_as_far_as_the_capture_point_nears_the_edge_or_the_pelvis_tilts() {
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

    /// The pelvis's lowest height (m) and the assistance's mean force (N)
    /// over three seconds after the humanoid standing at rest is shoved
    /// forward at `speed_m_s`, its joints holding the rest pose.
    fn after_a_shove(speed_m_s: f64, assisted: bool) -> (f64, f64) {
        let (mut humanoid, mut root) = at_rest(0.0, assisted);
        humanoid.launch(&RootTarget { velocity: DVec3::new(0.0, 0.0, speed_m_s), ..root });
        root.velocity = DVec3::ZERO;
        let (mut lowest, mut force) = (f64::INFINITY, 0.0);
        let steps = (3.0 / DT) as usize;
        for _ in 0..steps {
            if assisted {
                humanoid.assist_toward(&root, &humanoid.balance_state());
            }
            humanoid.step(&[JointTarget::REST; JOINTS], Gains::STANDARD, false);
            lowest = lowest.min(humanoid.frame().position(Joint::Pelvis).y);
            force += humanoid.assist_wrench().force.length() / steps as f64;
        }
        (lowest, force)
    }

    #[test]
    fn a_shove_that_topples_the_humanoid_is_caught_with_a_mean_force_well_under_its_weight() {
        let standing = at_rest(0.0, false).0.frame().position(Joint::Pelvis).y;
        let weight = crate::sim::anthropometry::body_mass_kg(&Body::standard()) * GRAVITY_M_S2;
        let (unassisted, _) = after_a_shove(SHOVE_M_S, false);
        assert!(unassisted < 0.5 * standing, "unassisted, the pelvis only sank to {unassisted:.2} m");
        let (assisted, force) = after_a_shove(SHOVE_M_S, true);
        assert!(assisted > 0.9 * standing, "assisted, the pelvis sank to {assisted:.2} m of {standing:.2}");
        assert!(force < 0.1 * weight, "a mean push of {force:.0} N against a weight of {weight:.0} N");
    }
}
