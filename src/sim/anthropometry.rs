//! Masses, centres of mass, inertias and strength of the canonical body's
//! parts, scaled to its height.
//!
//! Mass shares, centre-of-mass positions and radii of gyration are Winter's
//! (Biomechanics and Motor Control of Human Movement, 4th ed., Table 4.1,
//! after Dempster), the table the body's proportions already follow. The
//! table gives one radius of gyration per limb (about the centre of mass,
//! across the segment); the inertia along a limb, and every inertia of the
//! trunk parts, neck and head (which the table lumps or leaves out), are
//! those of a solid cylinder of the part's length and breadth.

use crate::mocap::body::{Body, JOINTS, Joint};
use crate::vision::shape::bone_radius_share;
use glam::{DMat3, DVec3};

/// Body mass of the standard 1.75 m body, kg; other heights scale it with
/// the square of height (a constant body-mass index, 22.9 kg/m²).
pub const STANDARD_MASS_KG: f64 = 70.0;

/// Half-width and half-depth of the trunk as shares of height: the chest is
/// about 0.18 H wide and 0.12 H deep.
const TRUNK_HALF_WIDTH: f64 = 0.09;
const TRUNK_HALF_DEPTH: f64 = 0.06;

/// The foot's breadth as a share of height (Winter's segment lengths, Fig.
/// 4.1: 0.055 H, 9.6 cm at 1.75 m).
const FOOT_BREADTH: f64 = 0.055;

/// The head-and-neck segment is one row of the table; it is split between
/// the neck and head links in proportion to the volumes of their capsules.
const HEAD_AND_NECK_SHARE: f64 = 0.081;

/// One link's inertial properties in its own frame (the frame of the joint
/// it hangs from, which at rest is aligned with the world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertial {
    pub mass_kg: f64,
    /// Centre of mass from the joint, meters.
    pub com: DVec3,
    /// Principal moments about the centre of mass along the link's X, Y, Z
    /// axes, kg·m².
    pub inertia: DVec3,
}

impl Inertial {
    /// The inertia tensor about `point` (link frame) once the link is turned
    /// by `rotation`, with `point` and the result in world axes relative to
    /// the link's origin.
    pub fn tensor_about(&self, rotation: DMat3, com_from_point: DVec3) -> DMat3 {
        let own = rotation * DMat3::from_diagonal(self.inertia) * rotation.transpose();
        let d = com_from_point;
        own + self.mass_kg * (DMat3::from_diagonal(DVec3::splat(d.length_squared())) - outer(d, d))
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Where a part's table row measures from and to, in the link's frame.
struct Segment {
    proximal: DVec3,
    distal: DVec3,
}

impl Segment {
    fn length(&self) -> f64 {
        (self.distal - self.proximal).length()
    }

    fn at(&self, share: f64) -> DVec3 {
        self.proximal + (self.distal - self.proximal) * share
    }
}

/// Winter's row for a limb: mass share, centre of mass from the proximal
/// end, radius of gyration about the centre of mass (shares of length).
struct Limb {
    mass_share: f64,
    com_share: f64,
    gyration_share: f64,
}

fn limb(j: Joint) -> Option<Limb> {
    use Joint::*;
    let row = |mass_share, com_share, gyration_share| Some(Limb { mass_share, com_share, gyration_share });
    match j {
        LeftShoulder | RightShoulder => row(0.028, 0.436, 0.322),
        LeftElbow | RightElbow => row(0.016, 0.430, 0.303),
        LeftWrist | RightWrist => row(0.006, 0.506, 0.297),
        LeftHip | RightHip => row(0.100, 0.433, 0.323),
        LeftKnee | RightKnee => row(0.0465, 0.433, 0.302),
        LeftAnkle | RightAnkle => row(0.0145, 0.50, 0.475),
        _ => None,
    }
}

/// The body's mass, kg.
pub fn body_mass_kg(body: &Body) -> f64 {
    STANDARD_MASS_KG * (body.proportions.height_m / Body::STANDARD_HEIGHT_M).powi(2)
}

/// The foot's breadth, meters: the width of the sole it stands on.
pub fn foot_breadth_m(body: &Body) -> f64 {
    FOOT_BREADTH * body.proportions.height_m
}

/// The bone a link runs along, from its joint, in its own frame.
fn bone(body: &Body, j: Joint) -> Segment {
    Segment { proximal: DVec3::ZERO, distal: body.bone(j) }
}

/// The radius of the capsule drawn along `j`'s bone, meters.
pub fn bone_radius_m(body: &Body, j: Joint) -> f64 {
    bone_radius_share(j) * body.proportions.height_m
}

/// Volume of the capsule along `j`'s bone (the rounded end stops at the end
/// site, as `vision::shape` draws it).
fn capsule_volume(body: &Body, j: Joint) -> f64 {
    let r = bone_radius_m(body, j);
    let length = match j.bone_child() {
        Some(_) => body.bone(j).length(),
        None => (body.bone(j).length() - r).max(0.0),
    };
    std::f64::consts::PI * r * r * (length + 4.0 / 3.0 * r)
}

/// Principal moments (about X, Y, Z) of a solid cylinder of `mass` and
/// `length` lying along the coordinate axis nearest `along`, with an
/// elliptic cross-section of half-axes `a` (along X, or Y for a cylinder
/// along X) and `b` (along Z, or Y for a cylinder along Z).
fn cylinder(mass: f64, length: f64, along: DVec3, a: f64, b: f64) -> DVec3 {
    let across = |half: f64| mass * (half * half / 4.0 + length * length / 12.0);
    let long = mass * (a * a + b * b) / 4.0;
    match long_axis(along) {
        0 => DVec3::new(long, across(b), across(a)),
        1 => DVec3::new(across(b), long, across(a)),
        _ => DVec3::new(across(b), across(a), long),
    }
}

/// Index of the coordinate axis a segment mostly runs along.
fn long_axis(along: DVec3) -> usize {
    let a = along.abs();
    if a.y >= a.x && a.y >= a.z {
        1
    } else if a.x >= a.z {
        0
    } else {
        2
    }
}

/// Every link's inertial properties, indexed by joint.
pub fn inertials(body: &Body) -> [Inertial; JOINTS] {
    use Joint::*;
    let h = body.proportions.height_m;
    let mass = body_mass_kg(body);
    let (half_width, half_depth) = (TRUNK_HALF_WIDTH * h, TRUNK_HALF_DEPTH * h);
    let head_volume = capsule_volume(body, Head);
    let neck_volume = capsule_volume(body, Neck);
    let hips = 0.5 * (body.offset(LeftHip) + body.offset(RightHip));
    Joint::ALL.map(|j| {
        if let Some(row) = limb(j) {
            let segment = bone(body, j);
            let (m, length) = (row.mass_share * mass, segment.length());
            let r = bone_radius_m(body, j);
            let along = segment.distal - segment.proximal;
            // The table's radius of gyration across the limb; along it,
            // the cylinder's moment.
            let mut inertia = DVec3::splat(m * (row.gyration_share * length).powi(2));
            let long = long_axis(along);
            inertia[long] = cylinder(m, length, along, r, r)[long];
            return Inertial { mass_kg: m, com: segment.at(row.com_share), inertia };
        }
        // Trunk rows run from the upper landmark down; the share places the
        // centre of mass from that upper end.
        let (share, com_share, segment, (a, b)) = match j {
            Pelvis => (0.142, 0.105, Segment { proximal: body.offset(Spine), distal: hips }, (half_width, half_depth)),
            Spine => {
                (0.139, 0.44, Segment { proximal: body.offset(Chest), distal: DVec3::ZERO }, (half_width, half_depth))
            }
            Chest => {
                (0.216, 0.82, Segment { proximal: body.offset(Neck), distal: DVec3::ZERO }, (half_width, half_depth))
            }
            Neck | Head => {
                let volume = if j == Neck { neck_volume } else { head_volume };
                let share = HEAD_AND_NECK_SHARE * volume / (neck_volume + head_volume);
                let r = bone_radius_m(body, j);
                (share, 0.5, bone(body, j), (r, r))
            }
            _ => unreachable!("every limb has a table row"),
        };
        let m = share * mass;
        let along = segment.distal - segment.proximal;
        Inertial { mass_kg: m, com: segment.at(com_share), inertia: cylinder(m, segment.length(), along, a, b) }
    })
}

/// The most torque each of a joint's motors may apply, N·m: rounded peak
/// joint torques of an adult, for the standard 70 kg body, scaled with body
/// mass. `None` for the pelvis, which has no motor.
pub fn torque_limit_nm(body: &Body, j: Joint) -> Option<f64> {
    use Joint::*;
    let standard = match j {
        Pelvis => return None,
        Spine | Chest => 300.0,
        Neck => 50.0,
        Head => 30.0,
        LeftShoulder | RightShoulder => 120.0,
        LeftElbow | RightElbow => 80.0,
        LeftWrist | RightWrist => 20.0,
        LeftHip | RightHip | LeftKnee | RightKnee => 250.0,
        LeftAnkle | RightAnkle => 150.0,
    };
    Some(standard * body_mass_kg(body) / STANDARD_MASS_KG)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Proportions;

    #[test]
    fn the_parts_weigh_the_whole_body_and_scale_with_its_height() {
        for height_m in [1.2, 1.75, 2.2] {
            let body = Body::new(Proportions { height_m, ..Default::default() });
            let parts: f64 = inertials(&body).iter().map(|i| i.mass_kg).sum();
            let whole = body_mass_kg(&body);
            assert!((parts - whole).abs() < 1e-9 * whole, "{height_m} m: {parts} of {whole} kg");
            assert!((whole - 70.0 * (height_m / 1.75f64).powi(2)).abs() < 1e-9);
        }
        let limit =
            |h: f64| torque_limit_nm(&Body::new(Proportions { height_m: h, ..Default::default() }), Joint::LeftElbow);
        assert_eq!(limit(1.75), Some(80.0));
        assert!((limit(2.1).unwrap() - 80.0 * 1.44).abs() < 1e-9);
        assert_eq!(torque_limit_nm(&Body::standard(), Joint::Pelvis), None);
    }

    #[test]
    fn each_limbs_centre_of_mass_lies_on_its_bone_and_its_inertia_is_smallest_along_it() {
        let body = Body::new(Proportions { height_m: 1.75, arm_scale: 1.2, leg_scale: 0.9 });
        let parts = inertials(&body);
        for j in [Joint::LeftShoulder, Joint::RightElbow, Joint::LeftHip, Joint::RightKnee] {
            let (bone, part) = (body.bone(j), parts[j.index()]);
            let share = part.com.dot(bone) / bone.length_squared();
            assert!((0.4..0.45).contains(&share) && part.com.cross(bone).length() < 1e-12, "{j:?}: {share}");
            // A limb turns most easily about its own length.
            let along = if bone.x.abs() > bone.y.abs() { part.inertia.x } else { part.inertia.y };
            assert!(part.inertia.to_array().iter().all(|&i| i >= along && i > 0.0), "{j:?}: {}", part.inertia);
        }
    }
}
