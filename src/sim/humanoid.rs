//! The canonical humanoid as rigid bodies in rapier3d: one link per joint,
//! joined by rapier's impulse joints (hinges for elbows and knees,
//! spherical joints elsewhere) with a motor on every axis.
//!
//! Each link's frame is its joint's frame: at the joint, turned with it, so
//! at rest every frame is the world's and a link's rotation relative to its
//! parent is the joint's rotation.
//!
//! Why impulse joints and not rapier's multibodies (reduced coordinates):
//! a multibody's step costs O(links × dofs²) (its mass matrix is rebuilt
//! whole each step), about 1 ms for these 40 motors, which is 4× real time
//! at 240 Hz; and its three-axis joints integrate angular velocity rather
//! than keep a rotation coordinate, so their motors cannot hold a pose.
//! Impulse joints cost O(joints) a step.

use super::anthropometry::{Inertial, bone_radius_m, foot_breadth_m, inertials, torque_limit_nm};
use super::targets::{JointTarget, RootTarget, motorized};
use crate::mocap::body::{Body, JOINTS, Joint, Kind};
use crate::mocap::math::hinge_angle;
use crate::mocap::pose::{BodyFrame, Pose};
use glam::{DMat3, DQuat, DVec3, Quat, Vec3};
use rapier3d::prelude::*;

/// How the pelvis is held.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Base {
    /// Fixed in place where the trajectory starts, as a humanoid on a
    /// stand; no ground.
    Fixed,
    /// Free, standing on a ground plane (y = 0), where it may fall.
    Free,
}

/// A collision shape in its link's frame.
#[derive(Clone, Copy, Debug)]
enum Shape {
    Capsule {
        a: DVec3,
        b: DVec3,
        radius: f64,
    },
    /// The foot: a box from heel to toe, ankle height tall, whose sole is
    /// the ground plane at rest.
    Box {
        center: DVec3,
        half: DVec3,
    },
}

impl Shape {
    fn collider(&self) -> ColliderBuilder {
        match *self {
            Shape::Capsule { a, b, radius } => {
                ColliderBuilder::capsule_from_endpoints(a.as_vec3(), b.as_vec3(), radius as f32)
            }
            Shape::Box { center, half } => {
                ColliderBuilder::cuboid(half.x as f32, half.y as f32, half.z as f32).translation(center.as_vec3())
            }
        }
    }

    /// The shape's lowest height once its link is at `position`, turned by
    /// `rotation`.
    fn lowest(&self, position: DVec3, rotation: DQuat) -> f64 {
        match *self {
            Shape::Capsule { a, b, radius } => (position + rotation * a).y.min((position + rotation * b).y) - radius,
            Shape::Box { center, half } => (0..8)
                .map(|corner| {
                    let sign = |bit: usize| if corner & (1 << bit) == 0 { -1.0 } else { 1.0 };
                    let offset = DVec3::new(sign(0) * half.x, sign(1) * half.y, sign(2) * half.z);
                    (position + rotation * (center + offset)).y
                })
                .fold(f64::INFINITY, f64::min),
        }
    }
}

/// Each link's collision shape: a capsule along its bone as the camera
/// model draws it (vision::shape), the feet a flat box as broad as a foot
/// (wider than the camera model draws it) to stand on.
fn shapes(body: &Body) -> [Shape; JOINTS] {
    let rest = body.forward(&Pose::rest(body));
    Joint::ALL.map(|j| {
        let radius = bone_radius_m(body, j);
        let end = body.bone(j);
        match j {
            Joint::LeftAnkle | Joint::RightAnkle => {
                // From the heel to the toe tip, the ankle a quarter of the
                // foot's length in front of the heel; from the ground up to
                // the ankle.
                let ankle_height = rest.position(j).y;
                let toe = end.z;
                let heel = -toe / 3.0;
                Shape::Box {
                    center: DVec3::new(0.0, -0.5 * ankle_height, 0.5 * (heel + toe)),
                    half: DVec3::new(0.5 * foot_breadth_m(body), 0.5 * ankle_height, 0.5 * (toe - heel)),
                }
            }
            // The rounded end stops at an end site rather than passing it.
            _ if j.bone_child().is_none() => {
                Shape::Capsule { a: DVec3::ZERO, b: end - end.normalize() * radius.min(end.length()), radius }
            }
            _ => Shape::Capsule { a: DVec3::ZERO, b: end, radius },
        }
    })
}

/// The corners of each foot's sole (left, right) in its ankle's frame.
fn sole_corners(shapes: &[Shape; JOINTS]) -> [[DVec3; 4]; 2] {
    FEET.map(|foot| match shapes[foot.index()] {
        Shape::Box { center, half } => [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, z)| center + DVec3::new(x * half.x, -half.y, z * half.z)),
        Shape::Capsule { .. } => unreachable!("the feet are boxes"),
    })
}

/// The corners of `body`'s soles (left, right), each in its ankle's frame,
/// as its humanoid stands on them.
pub(super) fn soles(body: &Body) -> [[DVec3; 4]; 2] {
    sole_corners(&shapes(body))
}

/// The middle of the front edge of `body`'s soles (left, right), each in
/// its ankle's frame: where its toes touch the ground.
pub(super) fn toes(body: &Body) -> [DVec3; 2] {
    // `sole_corners` lists each sole's two heel corners, then its two toe
    // corners.
    soles(body).map(|c| 0.5 * (c[2] + c[3]))
}

/// One joint's motors: one about a hinge's axis, three about a ball
/// joint's (rapier's AngX, AngY, AngZ).
#[derive(Clone, Debug)]
struct Actuator {
    handle: ImpulseJointHandle,
    joint: Joint,
    axes: &'static [JointAxis],
}

const HINGE_AXES: &[JointAxis] = &[JointAxis::AngX];
const BALL_AXES: &[JointAxis] = &[JointAxis::AngX, JointAxis::AngY, JointAxis::AngZ];

/// The simulated humanoid and its world.
pub struct Humanoid {
    pub(super) world: PhysicsWorld,
    pub(super) links: [RigidBodyHandle; JOINTS],
    colliders: [ColliderHandle; JOINTS],
    /// The ground's collider, on a free base.
    ground: Option<ColliderHandle>,
    /// How far the pose was raised (negative: lowered) to stand on the
    /// ground, m; 0 on a fixed base.
    raised_m: f64,
    actuators: Vec<Actuator>,
    /// Per joint, the most torque each of its motors may apply, N·m (0 for
    /// the pelvis, which has none).
    torque_limits: [f64; JOINTS],
    pub(super) inertials: [Inertial; JOINTS],
    /// For each joint, the joints whose links it carries (itself included).
    carried: [Vec<Joint>; JOINTS],
    /// Each joint's place in its parent's frame.
    offsets: [DVec3; JOINTS],
    /// The corners of each foot's sole (left, right) in its ankle's frame.
    pub(super) soles: [[DVec3; 4]; 2],
    /// With assistance, the body that carries the trajectory's pelvis and
    /// the turning spring from it to the pelvis ([`super::assist`]).
    pub(super) anchor: Option<(RigidBodyHandle, ImpulseJointHandle)>,
    /// The assistance's push on the pelvis in the step under way, N.
    pub(super) assist_force: DVec3,
    /// The shift the balance has gathered from the capture point's offset
    /// over time, m ([`Humanoid::balance`]'s integral term).
    pub(super) gathered_shift: DVec3,
}

/// Stiffness and damping of every motor per unit of the inertia it turns.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Gains {
    /// 1/s²: the joint's natural frequency is √kp rad/s.
    pub kp_per_s2: f64,
    /// 1/s: the damping ratio is kd / (2 √kp).
    pub kd_per_s: f64,
}

impl Gains {
    /// A natural frequency of 100 rad/s (16 Hz), critically damped.
    pub const STANDARD: Gains = Gains { kp_per_s2: 10000.0, kd_per_s: 200.0 };

    /// These gains with the natural frequency times `share`, at the same
    /// damping ratio.
    pub fn slowed(self, share: f64) -> Gains {
        Gains { kp_per_s2: self.kp_per_s2 * share * share, kd_per_s: self.kd_per_s * share }
    }
}

/// The share of the natural frequency a leg that holds the body up keeps
/// while the take steps ([`Humanoid::step`]). At the full gains, scaled by
/// the whole body's inertia, a standing leg's motors reach their torque
/// limits for a fraction of a degree's error, and at push-off they threw
/// the body off both feet (measured on bandai's walks). Over bandai's 44
/// walks, with the swing lift and the trunk hold (stayed up, mean time to
/// the fall): the full gains 1, 1.4 s; 0.25 (with a 4 cm lift) 3, 2.0 s;
/// 0.2 5, 1.9 s; the standing takes stay as they were. Softened at all
/// times, not only while the take steps, the legs let standing takes fall
/// (0.2: 11 of real/'s 13).
const STEPPING_LEG_SHARE: f64 = 0.2;

const GROUND: Group = Group::GROUP_2;
const BODY: Group = Group::GROUP_1;
pub(super) const GRAVITY_M_S2: f64 = 9.81;
const RUNAWAY_M_S: f64 = 100.0;
const RUNAWAY_RAD_S: f64 = 1000.0;
/// Every actuator's joint stays in the world it was put in.
const JOINT: &str = "the humanoid's joints are never removed";
pub(super) const FEET: [Joint; 2] = [Joint::LeftAnkle, Joint::RightAnkle];
pub(super) const HIPS: [Joint; 2] = [Joint::LeftHip, Joint::RightHip];

impl Humanoid {
    /// The humanoid of `body` in `pose`, every joint turning as `start`
    /// asks, stepped every `dt_s`. On a free base the pose is lowered or
    /// raised until the lowest point of the feet that are down
    /// (`feet_down`: left, right) touches the ground, or its lowest point
    /// where neither is. A take that starts mid-stride, put on its lowest
    /// point, stood on the foot it swings (the canonical foot, longer than
    /// a captured one, reaches below the standing sole) and fell within a
    /// second (2 of bandai's 44 walks); a swing foot below the ground is
    /// pushed out by the contacts.
    pub fn new(
        body: &Body,
        base: Base,
        pose: &Pose,
        start: &[JointTarget; JOINTS],
        dt_s: f64,
        feet_down: [bool; 2],
    ) -> Humanoid {
        let mut world = PhysicsWorld::new();
        world.integration_parameters.dt = dt_s as f32;
        world.gravity = -Vec3::Y * GRAVITY_M_S2 as f32;
        // A chain of joints holds a heavy body up only once the solver has
        // carried the load down the chain; rapier's one inner iteration a
        // pass leaves a standing humanoid sagging until it falls (measured:
        // 2 inner iterations fall within 6 s of standing waving, 4 do not).
        world.integration_parameters.num_internal_pgs_iterations = 4;
        // rapier leaves friction out of the pass that pushes contacts apart
        // by default; a standing foot, pressed into the ground and pushed
        // sideways by that pass, then creeps (measured: both feet of a
        // quiet, symmetric stance slid 2 cm sideways in 3 s, and the
        // body with them; with friction in that pass, about 3 mm).
        world.integration_parameters.friction_in_bias_pass = true;
        let shapes = shapes(body);
        let inertials = inertials(body);
        let mut frame = body.forward(pose);
        let (mut ground, mut raised_m) = (None, 0.0);
        if base == Base::Free {
            let standing: Vec<Joint> =
                FEET.into_iter().zip(feet_down).filter_map(|(f, down)| down.then_some(f)).collect();
            let on = if standing.is_empty() { &Joint::ALL[..] } else { &standing[..] };
            let lowest = on
                .iter()
                .map(|&j| shapes[j.index()].lowest(frame.position(j), frame.rotation(j)))
                .fold(f64::INFINITY, f64::min);
            raised_m = -lowest;
            let lift = DVec3::Y * raised_m;
            frame.positions.iter_mut().for_each(|p| *p += lift);
            // The ground: a slab whose top is y = 0, far wider than any walk.
            let slab = ColliderBuilder::cuboid(1000.0, 1.0, 1000.0).collision_groups(groups(GROUND)).friction(1.0);
            ground = Some(world.insert(RigidBodyBuilder::fixed().translation(-Vec3::Y), slab).1);
        }
        let placed = Joint::ALL.map(|j| {
            let kind = match (j, base) {
                (Joint::Pelvis, Base::Fixed) => RigidBodyBuilder::fixed(),
                _ => RigidBodyBuilder::dynamic(),
            };
            let inertial = inertials[j.index()];
            let properties =
                MassProperties::new(inertial.com.as_vec3(), inertial.mass_kg as f32, inertial.inertia.as_vec3());
            // Asleep, a body would not wake for a motor's new target.
            let rigid = kind.pose(placement(&frame, j)).additional_mass_properties(properties).can_sleep(false);
            // Mass comes from the tables above, not from the shapes.
            let collider = shapes[j.index()].collider().density(0.0).friction(1.0).collision_groups(groups(BODY));
            world.insert(rigid, collider)
        });
        let colliders = placed.map(|(_, collider)| collider);
        let links = placed.map(|(link, _)| link);

        let mut torque_limits = [0.0; JOINTS];
        let actuators = motorized()
            .map(|j| {
                let parent = j.parent().expect("only the pelvis has no parent");
                let limit = torque_limit_nm(body, j).expect("every joint but the pelvis has a motor");
                torque_limits[j.index()] = limit;
                let (joint, axes) = motorized_joint(j, body.offset(j), limit);
                let handle = world.insert_impulse_joint(links[parent.index()], links[j.index()], joint);
                Actuator { handle, joint: j, axes }
            })
            .collect();
        let carried = Joint::ALL.map(|j| Joint::ALL.into_iter().filter(|&c| carries(j, c)).collect());
        let offsets = Joint::ALL.map(|j| body.offset(j));
        let soles = sole_corners(&shapes);
        let mut humanoid = Humanoid {
            world,
            links,
            colliders,
            ground,
            raised_m,
            actuators,
            torque_limits,
            inertials,
            carried,
            offsets,
            soles,
            anchor: None,
            assist_force: DVec3::ZERO,
            gathered_shift: DVec3::ZERO,
        };
        humanoid.set_velocities(start);
        humanoid
    }

    /// Sets every link moving as the joints' spins in `start` move it (the
    /// pelvis still), so a trajectory starts in motion.
    fn set_velocities(&mut self, start: &[JointTarget; JOINTS]) {
        let frame = self.frame();
        let mut spin = [DVec3::ZERO; JOINTS];
        let mut linear = [DVec3::ZERO; JOINTS];
        for j in motorized() {
            let p = j.parent().expect("only the pelvis has no parent");
            spin[j.index()] = spin[p.index()] + frame.rotation(p) * start[j.index()].spin;
            linear[j.index()] = linear[p.index()] + spin[p.index()].cross(frame.position(j) - frame.position(p));
        }
        for j in Joint::ALL {
            let rigid = &mut self.world.bodies[self.links[j.index()]];
            if rigid.is_dynamic() {
                // rapier's linear velocity is its centre of mass's.
                let com = rigid.center_of_mass().as_dvec3() - frame.position(j);
                let at_com = linear[j.index()] + spin[j.index()].cross(com);
                rigid.set_linvel(at_com.as_vec3(), true);
                rigid.set_angvel(spin[j.index()].as_vec3(), true);
            }
        }
    }

    /// Sets the whole body moving as the trajectory's pelvis moves at its
    /// start (`root`: its velocity and spin), on top of how its joints move
    /// it: a walk started from rest would have to be begun by legs that are
    /// already mid-stride. The pelvis's spin carries the links too (against
    /// every link moved by the pelvis's velocity alone, as many of bandai's
    /// and real/'s standing takes stayed up and their 46 walks fell 0.14 s
    /// later on average).
    pub fn launch(&mut self, root: &RootTarget) {
        let pelvis = self.world.bodies[self.links[Joint::Pelvis.index()]].translation().as_dvec3();
        for &link in &self.links {
            let rigid = &mut self.world.bodies[link];
            if rigid.is_dynamic() {
                let arm = rigid.center_of_mass().as_dvec3() - pelvis;
                let moving = rigid.linvel().as_dvec3() + root.velocity + root.spin.cross(arm);
                rigid.set_linvel(moving.as_vec3(), true);
                rigid.set_angvel((rigid.angvel().as_dvec3() + root.spin).as_vec3(), true);
            }
        }
    }

    /// A copy of the humanoid in its world as it is now, to try a control
    /// on ahead of time.
    pub(super) fn fork(&self) -> Humanoid {
        let w = &self.world;
        let world = PhysicsWorld {
            gravity: w.gravity,
            integration_parameters: w.integration_parameters,
            physics_pipeline: PhysicsPipeline::new(),
            collision_pipeline: CollisionPipeline::new(),
            islands: w.islands.clone(),
            broad_phase: w.broad_phase.clone(),
            narrow_phase: w.narrow_phase.clone(),
            bodies: w.bodies.clone(),
            colliders: w.colliders.clone(),
            impulse_joints: w.impulse_joints.clone(),
            multibody_joints: w.multibody_joints.clone(),
            soft_bodies: w.soft_bodies.clone(),
            ccd_solver: w.ccd_solver.clone(),
        };
        Humanoid {
            world,
            links: self.links,
            colliders: self.colliders,
            ground: self.ground,
            raised_m: self.raised_m,
            actuators: self.actuators.clone(),
            torque_limits: self.torque_limits,
            inertials: self.inertials,
            carried: self.carried.clone(),
            offsets: self.offsets,
            soles: self.soles,
            anchor: self.anchor,
            assist_force: self.assist_force,
            gathered_shift: self.gathered_shift,
        }
    }

    /// The whole body's mass, kg.
    pub(super) fn mass_kg(&self) -> f64 {
        self.inertials.iter().map(|i| i.mass_kg).sum()
    }

    pub(super) fn rotation(&self, j: Joint) -> DQuat {
        to_f64(*self.world.bodies[self.links[j.index()]].rotation())
    }

    /// The length of rapier's substeps: it splits each step into as many as
    /// it runs solver iterations, and motor impulses are per substep.
    pub(super) fn substep_s(&self) -> f64 {
        let p = &self.world.integration_parameters;
        f64::from(p.dt) / p.num_solver_iterations as f64
    }

    /// Asks every motor for `targets` by the end of the next step, with
    /// stiffness and damping of `gains` times the inertia its axis turns in
    /// the present pose (everything the joint carries, held rigid, or what
    /// a standing leg holds up), then takes the step.
    ///
    /// A ball joint's three motors act on its rotation away from the target
    /// (rapier's joint frame on the parent side is turned to the target),
    /// not on the rotation from rest: the coordinates rapier's motors use
    /// (2·asin of the quaternion's components) turn at the angular velocity
    /// only near zero; far from it the three springs push partly sideways
    /// and, stiff, set an arm hanging at its side (100° from the T-pose)
    /// into flutter (measured: 80–100° RMS errors on real captures).
    ///
    /// While `stepping` (the take steps), a leg whose foot stands turns
    /// with `STEPPING_LEG_SHARE` of the natural frequency.
    pub fn step(&mut self, targets: &[JointTarget; JOINTS], gains: Gains, stepping: bool) {
        let dt = f64::from(self.world.integration_parameters.dt);
        let standing = FEET.map(|foot| self.stands(foot));
        let turned = self.turned_inertia(standing);
        for actuator in &self.actuators {
            let j = actuator.joint;
            let holds_up = leg_of(j).is_some_and(|leg| standing[leg]);
            let gains = if stepping && holds_up { gains.slowed(STEPPING_LEG_SHARE) } else { gains };
            let parent = self.rotation(j.parent().expect("only the pelvis has no parent"));
            let target = targets[j.index()];
            let data = &mut self.world.impulse_joints.get_mut(actuator.handle, false).expect(JOINT).data;
            // Where each motor's zero lies.
            let zero = match j.kind() {
                Kind::Hinge { axis, .. } => hinge_angle(target.rotation, axis),
                Kind::Ball { .. } => {
                    data.local_frame1.rotation = target.rotation.as_quat();
                    0.0
                }
            };
            for (&motor, along) in actuator.axes.iter().zip(motor_axes(j, target.rotation)) {
                let world_axis = parent * along;
                let inertia = world_axis.dot(turned[j.index()] * world_axis);
                let rate = target.spin.dot(along);
                // rapier's motors are implicit springs on the joint's state
                // at the step's start: aiming a step's travel short of the
                // target reaches it at the step's end.
                data.set_motor(
                    motor,
                    (zero - dt * rate) as f32,
                    rate as f32,
                    (gains.kp_per_s2 * inertia) as f32,
                    (gains.kd_per_s * inertia) as f32,
                );
            }
        }
        self.world.step();
    }

    /// The inertia tensor (world axes, about the joint) of what each
    /// joint's motors turn: the links it carries, or, on a leg whose foot
    /// stands on the ground, the rest of the body, which that leg holds up.
    /// `standing` says which feet (left, right) stand.
    fn turned_inertia(&self, standing: [bool; 2]) -> [DMat3; JOINTS] {
        let placed = Joint::ALL.map(|j| {
            let rigid = &self.world.bodies[self.links[j.index()]];
            let rotation = to_f64(*rigid.rotation());
            let position = rigid.translation().as_dvec3();
            (position, DMat3::from_quat(rotation), position + rotation * self.inertials[j.index()].com)
        });
        let about = |at: DVec3, links: &mut dyn Iterator<Item = Joint>| {
            links.fold(DMat3::ZERO, |sum, c| {
                let (_, rotation, com) = placed[c.index()];
                sum + self.inertials[c.index()].tensor_about(rotation, com - at)
            })
        };
        Joint::ALL.map(|j| {
            let at = placed[j.index()].0;
            let carried = about(at, &mut self.carried[j.index()].iter().copied());
            let holds_up = leg_of(j).is_some_and(|leg| standing[leg]);
            if holds_up { about(at, &mut Joint::ALL.into_iter()) - carried } else { carried }
        })
    }

    /// Whether `foot`'s link touches the ground.
    pub(super) fn stands(&self, foot: Joint) -> bool {
        self.touches_ground(foot)
    }

    /// Whether joint `j`'s link touches the ground.
    pub fn touches_ground(&self, j: Joint) -> bool {
        self.ground.is_some_and(|ground| {
            let pair = self.world.narrow_phase.contact_pair(self.colliders[j.index()], ground);
            pair.is_some_and(|p| p.has_any_active_contact())
        })
    }

    /// The torque each joint's motors applied in the last substep of the
    /// last step (N·m, in the parent's frame; the pelvis's is zero), and
    /// whether one of its motors was at its limit.
    pub fn torques(&self, torque: &mut [DVec3; JOINTS], at_limit: &mut [bool; JOINTS]) {
        let substep = self.substep_s();
        for actuator in &self.actuators {
            let j = actuator.joint;
            let data = &self.world.impulse_joints.get(actuator.handle).expect(JOINT).data;
            let most = self.torque_limits[j.index()] * substep;
            let impulses = actuator.axes.iter().map(|&axis| data.motor(axis).map_or(0.0, |m| f64::from(m.impulse)));
            let (mut sum, mut limited) = (DVec3::ZERO, false);
            for (impulse, along) in impulses.zip(motor_axes(j, to_f64(data.local_frame1.rotation))) {
                sum += along * impulse;
                // rapier caps each impulse at the limit times the substep,
                // in f32.
                limited |= impulse.abs() >= most * (1.0 - 1e-5);
            }
            torque[j.index()] = sum / substep;
            at_limit[j.index()] = limited;
        }
    }

    /// How far apart the two sides of the most stretched joint are, meters:
    /// impulse joints are held together by the solver, not by construction.
    pub fn largest_joint_gap_m(&self) -> f64 {
        let frame = self.frame();
        Joint::ALL
            .into_iter()
            .filter_map(|j| {
                let p = j.parent()?;
                let expected = frame.position(p) + frame.rotation(p) * self.offsets[j.index()];
                Some((frame.position(j) - expected).length())
            })
            .fold(0.0, f64::max)
    }

    /// How far the pose it was made in was raised (negative: lowered) to
    /// stand on the ground, m.
    pub fn raised_m(&self) -> f64 {
        self.raised_m
    }

    /// A link moving faster than any part of a body does (or not finitely):
    /// the joint, its speed (m/s) and its spin (rad/s). A person's fastest
    /// limb, a pitching hand, reaches ~40 m/s and ~100 rad/s; beyond
    /// `RUNAWAY_M_S` or `RUNAWAY_RAD_S` the simulation has come apart.
    pub fn runaway(&self) -> Option<(Joint, f64, f64)> {
        Joint::ALL.into_iter().find_map(|j| {
            let rigid = &self.world.bodies[self.links[j.index()]];
            let (speed, spin) = (f64::from(rigid.linvel().length()), f64::from(rigid.angvel().length()));
            let sane = speed <= RUNAWAY_M_S && spin <= RUNAWAY_RAD_S;
            (!sane).then_some((j, speed, spin))
        })
    }

    /// The most torque each of joint `j`'s motors may apply, N·m.
    pub fn torque_limit_nm(&self, j: Joint) -> f64 {
        self.torque_limits[j.index()]
    }

    /// Where every joint is and how it is turned, in the world.
    pub fn frame(&self) -> BodyFrame {
        let mut positions = [DVec3::ZERO; JOINTS];
        let mut rotations = [DQuat::IDENTITY; JOINTS];
        for j in Joint::ALL {
            let rigid = &self.world.bodies[self.links[j.index()]];
            positions[j.index()] = rigid.translation().as_dvec3();
            rotations[j.index()] = to_f64(*rigid.rotation());
        }
        BodyFrame { positions, rotations }
    }

    /// The pose the humanoid is in: every joint's rotation relative to its
    /// parent, the pelvis's place and turn in the world.
    pub fn pose(&self) -> Pose {
        let frame = self.frame();
        let local = Joint::ALL.map(|j| match j.parent() {
            None => frame.rotation(j),
            Some(p) => (frame.rotation(p).inverse() * frame.rotation(j)).normalize(),
        });
        Pose::from_rotations(frame.position(Joint::Pelvis), &local)
    }
}

/// Joint `j` at `anchor` in its parent's frame, a motor on each of its axes
/// capped at `torque_limit_nm`. A hinge stops at its limits; a ball joint's
/// motors move their zero every step ([`Humanoid::step`]), so its limit is
/// kept on the targets instead ([`super::targets::clamp`]).
fn motorized_joint(j: Joint, anchor: DVec3, torque_limit_nm: f64) -> (GenericJoint, &'static [JointAxis]) {
    let (mut joint, axes): (GenericJoint, _) = match j.kind() {
        Kind::Hinge { axis, min_rad, max_rad } => (
            RevoluteJointBuilder::new(axis.as_vec3()).limits([min_rad as f32, max_rad as f32]).build().into(),
            HINGE_AXES,
        ),
        Kind::Ball { .. } => (SphericalJointBuilder::new().build().into(), BALL_AXES),
    };
    joint.set_local_anchor1(anchor.as_vec3()).set_local_anchor2(Vec3::ZERO);
    for &axis in axes {
        joint.set_motor_model(axis, MotorModel::ForceBased).set_motor_max_force(axis, torque_limit_nm as f32);
    }
    (joint, axes)
}

/// The axes joint `j`'s motors turn about, in its parent's frame: a hinge's
/// axis, or the axes of a ball joint's target frame `target` (unused
/// entries zero).
fn motor_axes(j: Joint, target: DQuat) -> [DVec3; 3] {
    match j.kind() {
        Kind::Hinge { axis, .. } => [axis, DVec3::ZERO, DVec3::ZERO],
        Kind::Ball { .. } => DVec3::AXES.map(|a| target * a),
    }
}

/// The leg `j` belongs to (0 left, 1 right, as `FEET`), if it is a leg
/// joint.
fn leg_of(j: Joint) -> Option<usize> {
    use Joint::*;
    match j {
        LeftHip | LeftKnee | LeftAnkle => Some(0),
        RightHip | RightKnee | RightAnkle => Some(1),
        _ => None,
    }
}

/// Whether `ancestor`'s motors turn `joint`'s link.
fn carries(ancestor: Joint, joint: Joint) -> bool {
    std::iter::successors(Some(joint), |j| j.parent()).any(|j| j == ancestor)
}

fn placement(frame: &BodyFrame, j: Joint) -> rapier3d::math::Pose {
    rapier3d::math::Pose::from_parts(frame.position(j).as_vec3(), frame.rotation(j).as_quat())
}

fn groups(member: Group) -> InteractionGroups {
    let other = if member == GROUND { BODY } else { GROUND };
    InteractionGroups::new(member, other, InteractionTestMode::And)
}

pub(super) fn to_f64(q: Quat) -> DQuat {
    q.as_dquat().normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::math::log_map;

    const DT: f64 = 1.0 / 240.0;

    fn rest_humanoid(base: Base) -> (Body, Humanoid) {
        let body = Body::standard();
        let humanoid = Humanoid::new(&body, base, &Pose::rest(&body), &[JointTarget::REST; JOINTS], DT, [false; 2]);
        (body, humanoid)
    }

    /// Weight times horizontal lever of everything `j` carries, in the
    /// rest pose, N·m.
    fn static_load_nm(body: &Body, j: Joint) -> f64 {
        let frame = body.forward(&Pose::rest(body));
        let at = frame.position(j);
        let inertials = inertials(body);
        Joint::ALL
            .into_iter()
            .filter(|&c| carries(j, c))
            .map(|c| {
                let i = inertials[c.index()];
                let lever = frame.position(c) + i.com - at;
                i.mass_kg * GRAVITY_M_S2 * DVec3::new(lever.x, 0.0, lever.z).length()
            })
            .sum()
    }

    #[test]
    fn the_start_stands_on_the_feet_that_are_down_or_else_on_its_lowest_point() {
        // The whole body rolled 5° onto its left side: the left foot lowest.
        let body = Body::standard();
        let rest = Pose::rest(&body);
        let mut local = Joint::ALL.map(|j| rest.local_rotation(j));
        local[Joint::Pelvis.index()] = DQuat::from_rotation_z(-5f64.to_radians()) * local[Joint::Pelvis.index()];
        let pose = Pose::from_rotations(rest.root, &local);
        let lowest = |humanoid: &Humanoid, joints: &[Joint]| {
            let (shapes, frame) = (shapes(&body), humanoid.frame());
            joints
                .iter()
                .map(|&j| shapes[j.index()].lowest(frame.position(j), frame.rotation(j)))
                .fold(f64::INFINITY, f64::min)
        };
        let start = |feet_down| Humanoid::new(&body, Base::Free, &pose, &[JointTarget::REST; JOINTS], DT, feet_down);
        let [left, right] = FEET;
        for feet_down in [[false, false], [true, false], [true, true]] {
            let humanoid = start(feet_down);
            assert!(lowest(&humanoid, &Joint::ALL).abs() < 1e-6, "{feet_down:?}");
            assert!(lowest(&humanoid, &[left]).abs() < 1e-6, "{feet_down:?}");
        }
        // Standing on the right foot, the lifted left reaches into the floor.
        let humanoid = start([false, true]);
        assert!(lowest(&humanoid, &[right]).abs() < 1e-6);
        assert!(lowest(&humanoid, &[left]) < -0.005, "{}", lowest(&humanoid, &[left]));
    }

    #[test]
    fn holding_the_arms_out_takes_the_torque_of_their_weight_about_each_joint() {
        let (body, mut humanoid) = rest_humanoid(Base::Fixed);
        let (mut torque, mut limited) = ([DVec3::ZERO; JOINTS], [false; JOINTS]);
        for _ in 0..240 {
            humanoid.step(&[JointTarget::REST; JOINTS], Gains::STANDARD, false);
        }
        humanoid.torques(&mut torque, &mut limited);
        // The T-pose's elbow hinges turn about the vertical: their joints, not
        // their motors, hold the forearms up.
        assert!(torque[Joint::LeftElbow.index()].length() < 0.01, "{}", torque[Joint::LeftElbow.index()]);
        for j in [Joint::LeftShoulder, Joint::RightShoulder, Joint::LeftWrist] {
            let expected = static_load_nm(&body, j);
            let got = torque[j.index()];
            assert!((got.length() - expected).abs() < 0.03 * expected, "{j:?}: {got} against {expected:.3} N·m");
            // Holding up an arm along ±X is a torque about Z.
            assert!(got.normalize().z.abs() > 0.99, "{j:?}: {got}");
            assert!(!limited[j.index()]);
        }
        // Without a feedforward term a motor holds its load by sagging until
        // its spring pushes back, by about the load over kp times the inertia
        // it turns: 0.1–0.5° here.
        let pose = humanoid.pose();
        let worst = motorized().map(|j| log_map(pose.local_rotation(j)).length()).fold(0.0, f64::max);
        assert!(worst < 1f64.to_radians(), "the rest pose held within {:.3}°", worst.to_degrees());
    }

    #[test]
    fn a_humanoid_standing_at_rest_on_the_ground_stays_up() {
        let (body, mut humanoid) = rest_humanoid(Base::Free);
        let start = humanoid.frame().position(Joint::Pelvis);
        // Lowered onto the ground: the soles at y = 0.
        assert!((start.y - body.pelvis_height()).abs() < 1e-6, "{start}");
        let feet = FEET.map(|f| humanoid.frame().position(f));
        for _ in 0..(5.0 / DT) as usize {
            let mut targets = [JointTarget::REST; JOINTS];
            humanoid.balance(&mut targets, None, &humanoid.balance_state());
            humanoid.step(&targets, Gains::STANDARD, false);
        }
        let frame = humanoid.frame();
        let end = frame.position(Joint::Pelvis);
        // The feet press 4 mm into the ground (rapier's contacts are soft).
        assert!((end.y - start.y).abs() < 0.01, "the pelvis went from {start} to {end} in 5 s");
        let lean = (frame.position(Joint::Neck) - end).angle_between(DVec3::Y);
        // Upright: it falls at 60°.
        assert!(lean < 5f64.to_radians(), "the trunk leans {:.1}°", lean.to_degrees());
        assert!(FEET.iter().all(|&f| humanoid.stands(f)), "both feet on the ground");
        // Standing still, the feet stay where they stood.
        for (k, foot) in FEET.into_iter().enumerate() {
            let slid = (frame.position(foot) - feet[k]).with_y(0.0).length();
            assert!(slid < 0.005, "{foot:?} slid {:.1} mm", slid * 1e3);
        }
        assert!(humanoid.largest_joint_gap_m() < 1e-3);
    }

    #[test]
    fn leaning_the_trunk_sideways_the_legs_shift_the_pelvis_back_over_the_feet() {
        let (_, mut humanoid) = rest_humanoid(Base::Free);
        let start = humanoid.frame().position(Joint::Pelvis);
        // Spine and chest bent 20° each to the left: the trunk's weight
        // swings well off the middle of the feet.
        let mut targets = [JointTarget::REST; JOINTS];
        for j in [Joint::Spine, Joint::Chest] {
            targets[j.index()].rotation = DQuat::from_rotation_z(20f64.to_radians());
        }
        for _ in 0..(5.0 / DT) as usize {
            let mut asked = targets;
            humanoid.balance(&mut asked, None, &humanoid.balance_state());
            humanoid.step(&asked, Gains::STANDARD, false);
        }
        let frame = humanoid.frame();
        let pelvis = frame.position(Joint::Pelvis);
        assert!(FEET.iter().all(|&f| humanoid.stands(f)), "both feet on the ground");
        // Bending left (+Z turns +Y toward −X) moves the trunk to −X; the
        // pelvis goes the other way, level.
        assert!(pelvis.x - start.x > 0.02, "the pelvis went from {start} to {pelvis}");
        let tilt = (frame.rotation(Joint::Pelvis) * DVec3::Y).angle_between(DVec3::Y);
        assert!(tilt < 3f64.to_radians(), "the pelvis tilts {:.1}°", tilt.to_degrees());
        assert!((pelvis.y - start.y).abs() < 0.03, "the pelvis went from {start} to {pelvis}");
        // Held still, the weight comes back to the gathering's dead zone
        // (2 cm) about the middle of the feet: the balance's proportional
        // term alone left it 3.9 cm off.
        let state = humanoid.balance_state();
        let middle = state.stance_centre.expect("both feet on the ground");
        let off = (state.com - middle).with_y(0.0).length();
        assert!(off < 0.025, "the centre of mass stays {:.1} cm off the middle of the feet", off * 100.0);
    }

    #[test]
    fn the_standing_hips_tilt_the_pelvis_to_the_takes_with_both_feet_down() {
        let (_, mut humanoid) = rest_humanoid(Base::Free);
        // The take's pelvis pitched 8.6° forward over legs at rest.
        let take = DQuat::from_rotation_x(0.15);
        for _ in 0..(1.0 / DT) as usize {
            let mut targets = [JointTarget::REST; JOINTS];
            humanoid.balance(&mut targets, None, &humanoid.balance_state());
            humanoid.hold_trunk(&mut targets, take);
            humanoid.step(&targets, Gains::STANDARD, false);
        }
        let pelvis = humanoid.frame().rotation(Joint::Pelvis);
        let off = (pelvis * DVec3::Y).angle_between(take * DVec3::Y);
        // More than halfway: the planted legs give way partly (3.3° left).
        assert!(off < 0.075, "the pelvis tilts {:.1}° from the take's", off.to_degrees());
        assert!(FEET.iter().all(|&f| humanoid.stands(f)), "both feet on the ground");
    }

    #[test]
    fn a_fork_plays_on_exactly_as_the_humanoid_does_and_leaves_it_alone() {
        let (_, mut humanoid) = rest_humanoid(Base::Free);
        let mut targets = [JointTarget::REST; JOINTS];
        targets[Joint::LeftShoulder.index()].rotation = DQuat::from_rotation_z(0.8);
        targets[Joint::Spine.index()].rotation = DQuat::from_rotation_x(0.3);
        // Moving and in contact with the ground when forked.
        for _ in 0..24 {
            humanoid.step(&targets, Gains::STANDARD, false);
        }
        let at_fork = humanoid.frame();
        let mut fork = humanoid.fork();
        for _ in 0..120 {
            fork.step(&targets, Gains::STANDARD, false);
        }
        assert_eq!(humanoid.frame().positions, at_fork.positions, "the humanoid moved with its fork");
        for _ in 0..120 {
            humanoid.step(&targets, Gains::STANDARD, false);
        }
        let (played, forked) = (humanoid.frame(), fork.frame());
        assert_ne!(played.positions, at_fork.positions, "the humanoid stood still");
        assert_eq!(played.positions, forked.positions);
        assert_eq!(played.rotations, forked.rotations);
    }

    #[test]
    fn softened_gains_keep_their_damping_ratio() {
        let soft = Gains::STANDARD.slowed(0.2);
        let ratio = |g: Gains| g.kd_per_s / (2.0 * g.kp_per_s2.sqrt());
        assert!((soft.kp_per_s2.sqrt() - 20.0).abs() < 1e-9, "{soft:?}");
        assert!((ratio(soft) - ratio(Gains::STANDARD)).abs() < 1e-12, "{soft:?}");
    }

    #[test]
    fn asked_onto_one_foot_the_balance_carries_the_weight_over_it_with_both_feet_down() {
        let (_, mut humanoid) = rest_humanoid(Base::Free);
        for _ in 0..(3.0 / DT) as usize {
            let mut targets = [JointTarget::REST; JOINTS];
            humanoid.balance(&mut targets, Some(1), &humanoid.balance_state());
            humanoid.step(&targets, Gains::STANDARD, false);
        }
        let state = humanoid.balance_state();
        let [left, right] = state.sole_middles.map(|s| s.expect("both feet on the ground"));
        let over = |sole: DVec3| glam::DVec2::new(sole.x - state.com.x, sole.z - state.com.z).length();
        // The rest pose's centre of mass lies halfway between the feet,
        // ~10 cm from each.
        assert!(over(right) < 0.03, "{:.3} m from the right sole, {:.3} m from the left", over(right), over(left));
        assert!(state.margin_m().is_some_and(|m| m > 0.0), "{state:?}");
    }
}
