//! The canonical humanoid every pose downstream is a pose of: 17 joints,
//! Y up, facing +Z, the person's left along +X. Its rest pose is a T-pose
//! (arms along ±X, palms down, legs straight down), so the common arm
//! postures sit far from a half turn.
//!
//! Segment lengths are fractions of standing height after Winter's
//! anthropometric tables (Biomechanics and Motor Control of Human Movement,
//! 4th ed., Fig. 4.1).

use crate::mocap::math::{Axis, EulerOrder};
use glam::DVec3;

/// The joints of the canonical body, parents before children.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Joint {
    Pelvis,
    Spine,
    Chest,
    Neck,
    Head,
    LeftShoulder,
    LeftElbow,
    LeftWrist,
    RightShoulder,
    RightElbow,
    RightWrist,
    LeftHip,
    LeftKnee,
    LeftAnkle,
    RightHip,
    RightKnee,
    RightAnkle,
}

/// Number of canonical joints.
pub const JOINTS: usize = 17;

/// Dimension of joint space: three swing–twist numbers per ball joint
/// (the pelvis's tilt included), one angle per hinge.
pub const DOF: usize = 43;

/// A pose in joint space (the paper's F-vector), ordered as [`Joint::ALL`].
pub type JointVector = [f64; DOF];

/// How a joint moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Three rotational degrees of freedom, stored as swing–twist
    /// coordinates about the rest bone ([`crate::mocap::math::swing_twist_log`]).
    Ball { max_angle_rad: f64 },
    /// One angle about a fixed axis of the parent's frame.
    Hinge { axis: DVec3, min_rad: f64, max_rad: f64 },
}

impl Joint {
    pub const ALL: [Joint; JOINTS] = [
        Joint::Pelvis,
        Joint::Spine,
        Joint::Chest,
        Joint::Neck,
        Joint::Head,
        Joint::LeftShoulder,
        Joint::LeftElbow,
        Joint::LeftWrist,
        Joint::RightShoulder,
        Joint::RightElbow,
        Joint::RightWrist,
        Joint::LeftHip,
        Joint::LeftKnee,
        Joint::LeftAnkle,
        Joint::RightHip,
        Joint::RightKnee,
        Joint::RightAnkle,
    ];

    pub fn index(self) -> usize {
        self as usize
    }

    /// The name used in every file the project writes.
    pub fn name(self) -> &'static str {
        match self {
            Joint::Pelvis => "pelvis",
            Joint::Spine => "spine",
            Joint::Chest => "chest",
            Joint::Neck => "neck",
            Joint::Head => "head",
            Joint::LeftShoulder => "left_shoulder",
            Joint::LeftElbow => "left_elbow",
            Joint::LeftWrist => "left_wrist",
            Joint::RightShoulder => "right_shoulder",
            Joint::RightElbow => "right_elbow",
            Joint::RightWrist => "right_wrist",
            Joint::LeftHip => "left_hip",
            Joint::LeftKnee => "left_knee",
            Joint::LeftAnkle => "left_ankle",
            Joint::RightHip => "right_hip",
            Joint::RightKnee => "right_knee",
            Joint::RightAnkle => "right_ankle",
        }
    }

    pub fn from_name(name: &str) -> Option<Joint> {
        Joint::ALL.into_iter().find(|j| j.name() == name)
    }

    pub fn parent(self) -> Option<Joint> {
        use Joint::*;
        Some(match self {
            Pelvis => return None,
            Spine | LeftHip | RightHip => Pelvis,
            Chest => Spine,
            Neck | LeftShoulder | RightShoulder => Chest,
            Head => Neck,
            LeftElbow => LeftShoulder,
            LeftWrist => LeftElbow,
            RightElbow => RightShoulder,
            RightWrist => RightElbow,
            LeftKnee => LeftHip,
            LeftAnkle => LeftKnee,
            RightKnee => RightHip,
            RightAnkle => RightKnee,
        })
    }

    /// Unit direction of the bone that leaves this joint in the rest pose
    /// (the same for every body's proportions): the axis of the joint's
    /// twist in joint space.
    pub fn rest_bone_axis(self) -> DVec3 {
        use Joint::*;
        match self {
            Pelvis | Spine | Chest | Neck | Head => DVec3::Y,
            LeftShoulder | LeftElbow | LeftWrist => DVec3::X,
            RightShoulder | RightElbow | RightWrist => DVec3::NEG_X,
            LeftHip | LeftKnee | RightHip | RightKnee => DVec3::NEG_Y,
            LeftAnkle | RightAnkle => DVec3::new(0.0, -FOOT_DROP, FOOT_REACH).normalize(),
        }
    }

    /// The joint the bone from this joint leads to; `None` for the joints
    /// whose bone ends at an end site (head, wrists, ankles).
    pub fn bone_child(self) -> Option<Joint> {
        use Joint::*;
        Some(match self {
            Pelvis => Spine,
            Spine => Chest,
            Chest => Neck,
            Neck => Head,
            LeftShoulder => LeftElbow,
            LeftElbow => LeftWrist,
            RightShoulder => RightElbow,
            RightElbow => RightWrist,
            LeftHip => LeftKnee,
            LeftKnee => LeftAnkle,
            RightHip => RightKnee,
            RightKnee => RightAnkle,
            Head | LeftWrist | RightWrist | LeftAnkle | RightAnkle => return None,
        })
    }

    pub fn kind(self) -> Kind {
        use Joint::*;
        let deg = f64::to_radians;
        let ball = |max: f64| Kind::Ball { max_angle_rad: deg(max) };
        let hinge = |axis, min: f64, max: f64| Kind::Hinge { axis, min_rad: deg(min), max_rad: deg(max) };
        match self {
            // Flexion is positive: the forearm swings forward (+Z) from the
            // T-pose, the shin backward.
            LeftElbow => hinge(DVec3::NEG_Y, 0.0, 150.0),
            RightElbow => hinge(DVec3::Y, 0.0, 150.0),
            LeftKnee | RightKnee => hinge(DVec3::X, 0.0, 150.0),
            Pelvis => ball(90.0),
            Spine | Chest => ball(45.0),
            Neck => ball(60.0),
            Head => ball(70.0),
            LeftShoulder | RightShoulder => ball(180.0),
            LeftWrist | RightWrist => ball(80.0),
            LeftHip | RightHip => ball(130.0),
            LeftAnkle | RightAnkle => ball(50.0),
        }
    }

    pub fn is_knee(self) -> bool {
        matches!(self, Joint::LeftKnee | Joint::RightKnee)
    }

    pub fn is_hinge(self) -> bool {
        matches!(self.kind(), Kind::Hinge { .. })
    }

    /// Number of joint-space numbers this joint owns.
    pub fn dof(self) -> usize {
        if self.is_hinge() { 1 } else { 3 }
    }

    /// Index of this joint's first number in a [`JointVector`].
    pub fn dof_offset(self) -> usize {
        Joint::ALL[..self.index()].iter().map(|j| j.dof()).sum()
    }

    /// Euler order used when writing BVH: the bone's own axis in the middle,
    /// where gimbal lock needs a 90° twist, which joints rarely reach.
    pub fn euler_order(self) -> EulerOrder {
        use Joint::*;
        match self {
            Pelvis => EulerOrder::YXZ,
            LeftShoulder | LeftElbow | LeftWrist | RightShoulder | RightElbow | RightWrist => EulerOrder::ZXY,
            LeftAnkle | RightAnkle => EulerOrder([Axis::X, Axis::Z, Axis::Y]),
            _ => EulerOrder::ZYX,
        }
    }

    /// The mirror image across the body's midline (left ↔ right).
    pub fn mirror(self) -> Joint {
        use Joint::*;
        match self {
            LeftShoulder => RightShoulder,
            LeftElbow => RightElbow,
            LeftWrist => RightWrist,
            RightShoulder => LeftShoulder,
            RightElbow => LeftElbow,
            RightWrist => LeftWrist,
            LeftHip => RightHip,
            LeftKnee => RightKnee,
            LeftAnkle => RightAnkle,
            RightHip => LeftHip,
            RightKnee => LeftKnee,
            RightAnkle => LeftAnkle,
            other => other,
        }
    }
}

/// The toe tip below and ahead of the ankle, as shares of height.
const FOOT_DROP: f64 = 0.030;
const FOOT_REACH: f64 = 0.110;

/// Proportions of a canonical body: its height and the scale of its limbs.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Proportions {
    pub height_m: f64,
    /// Multiplies upper arm, forearm and hand.
    pub arm_scale: f64,
    /// Multiplies thigh and shank.
    pub leg_scale: f64,
}

impl Default for Proportions {
    fn default() -> Self {
        Proportions { height_m: Body::STANDARD_HEIGHT_M, arm_scale: 1.0, leg_scale: 1.0 }
    }
}

/// A canonical body: rest offsets of every joint from its parent and the
/// end sites of the head, hands and feet, in meters.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub proportions: Proportions,
    offsets: [DVec3; JOINTS],
    ends: [Option<DVec3>; JOINTS],
}

impl Default for Body {
    fn default() -> Self {
        Body::standard()
    }
}

impl Body {
    pub const STANDARD_HEIGHT_M: f64 = 1.75;

    /// The canonical body all retargeted and learned poses use.
    pub fn standard() -> Body {
        Body::new(Proportions::default())
    }

    pub fn new(p: Proportions) -> Body {
        use Joint::*;
        let h = p.height_m;
        let (arm, leg) = (p.arm_scale, p.leg_scale);
        let thigh = 0.245 * h * leg;
        let shank = 0.246 * h * leg;
        let ankle_height = 0.039 * h;
        let hip_drop = 0.029 * h;
        let mut offsets = [DVec3::ZERO; JOINTS];
        let mut set = |j: Joint, x: f64, y: f64, z: f64| offsets[j.index()] = DVec3::new(x, y, z);
        // The pelvis offset is its rest height: where the feet touch y = 0.
        set(Pelvis, 0.0, ankle_height + shank + thigh + hip_drop, 0.0);
        set(Spine, 0.0, 0.057 * h, 0.0);
        set(Chest, 0.0, 0.114 * h, 0.0);
        set(Neck, 0.0, 0.097 * h, 0.0);
        set(Head, 0.0, 0.057 * h, 0.0);
        for (side, shoulder, elbow, wrist, hip, knee, ankle) in [
            (1.0, LeftShoulder, LeftElbow, LeftWrist, LeftHip, LeftKnee, LeftAnkle),
            (-1.0, RightShoulder, RightElbow, RightWrist, RightHip, RightKnee, RightAnkle),
        ] {
            set(shoulder, side * 0.109 * h, 0.086 * h, 0.0);
            set(elbow, side * 0.186 * h * arm, 0.0, 0.0);
            set(wrist, side * 0.146 * h * arm, 0.0, 0.0);
            set(hip, side * 0.051 * h, -hip_drop, 0.0);
            set(knee, 0.0, -thigh, 0.0);
            set(ankle, 0.0, -shank, 0.0);
        }
        let mut ends = [None; JOINTS];
        // Head top, hand tip (fingers), toe tip.
        ends[Head.index()] = Some(DVec3::new(0.0, 0.114 * h, 0.0));
        ends[LeftWrist.index()] = Some(DVec3::new(0.108 * h * arm, 0.0, 0.0));
        ends[RightWrist.index()] = Some(DVec3::new(-0.108 * h * arm, 0.0, 0.0));
        for ankle in [LeftAnkle, RightAnkle] {
            ends[ankle.index()] = Some(DVec3::new(0.0, -FOOT_DROP * h, FOOT_REACH * h));
        }
        Body { proportions: p, offsets, ends }
    }

    /// The body that stands `standing_m` tall with arms and legs
    /// `arm_share` and `leg_share` times the canonical body's shares of
    /// its height (the trunk takes up the difference). Standing height is
    /// linear in the legs' scale, s(L) = s₀ + b·L, and proportional to the
    /// height scale, so both scales are solved directly.
    pub fn of_shares(standing_m: f64, arm_share: f64, leg_share: f64) -> Body {
        let unit = |leg_scale: f64| Body::new(Proportions { height_m: 1.0, arm_scale: 1.0, leg_scale });
        let (s0, s1) = (unit(0.0).standing_height(), unit(1.0).standing_height());
        // The leg scale L whose share L / s(L) is leg_share / s(1).
        let share = leg_share / s1;
        let leg_scale = share * s0 / (1.0 - share * (s1 - s0));
        let stands = s0 + (s1 - s0) * leg_scale;
        Body::new(Proportions { height_m: standing_m / stands, arm_scale: arm_share * stands / s1, leg_scale })
    }

    /// The arm and leg shares [`Body::of_shares`] built this body from.
    pub fn shares(&self) -> (f64, f64) {
        let canonical = Body::standard();
        let share = |b: &Body, j: Joint| b.offset(j).length() / b.standing_height();
        (
            share(self, Joint::LeftWrist) / share(&canonical, Joint::LeftWrist),
            share(self, Joint::LeftKnee) / share(&canonical, Joint::LeftKnee),
        )
    }

    /// Rest offset of `j` from its parent (for the pelvis: its rest
    /// position above the ground).
    pub fn offset(&self, j: Joint) -> DVec3 {
        self.offsets[j.index()]
    }

    /// End site offset below `j`, for the head, wrists and ankles.
    pub fn end_site(&self, j: Joint) -> Option<DVec3> {
        self.ends[j.index()]
    }

    /// The rest-pose vector along the bone that leaves `j`.
    pub fn bone(&self, j: Joint) -> DVec3 {
        match j.bone_child() {
            Some(c) => self.offset(c),
            None => self.end_site(j).expect("leaf joints have end sites"),
        }
    }

    /// Pelvis height in the rest pose.
    pub fn pelvis_height(&self) -> f64 {
        self.offsets[Joint::Pelvis.index()].y
    }

    /// Length of hip to knee to ankle, averaged over both legs.
    pub fn leg_length(&self) -> f64 {
        self.offset(Joint::LeftKnee).length() + self.offset(Joint::LeftAnkle).length()
    }

    /// Head top above the soles in the rest pose.
    pub fn standing_height(&self) -> f64 {
        self.pelvis_height() + self.trunk_length()
    }

    /// Length of the path pelvis → spine → chest → neck → head → head top.
    pub fn trunk_length(&self) -> f64 {
        [Joint::Spine, Joint::Chest, Joint::Neck, Joint::Head].iter().map(|&j| self.offset(j).length()).sum::<f64>()
            + self.bone(Joint::Head).length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joints_are_ordered_parents_first_and_named_uniquely() {
        for j in Joint::ALL {
            if let Some(p) = j.parent() {
                assert!(p.index() < j.index(), "{j:?}");
            }
            assert_eq!(Joint::from_name(j.name()), Some(j));
        }
    }

    #[test]
    fn joint_space_has_three_numbers_per_ball_and_one_per_hinge() {
        let total: usize = Joint::ALL.iter().map(|j| j.dof()).sum();
        assert_eq!(total, DOF);
        assert_eq!(Joint::RightAnkle.dof_offset() + 3, DOF);
        assert_eq!(Joint::ALL.iter().filter(|j| j.is_hinge()).count(), 4);
    }

    #[test]
    fn standard_body_stands_on_the_ground_at_its_height() {
        let body = Body::standard();
        let head_top =
            [Joint::Spine, Joint::Chest, Joint::Neck, Joint::Head].iter().map(|&j| body.offset(j).y).sum::<f64>()
                + body.pelvis_height()
                + body.end_site(Joint::Head).unwrap().y;
        assert!((head_top - 1.75).abs() < 0.01, "head top at {head_top}");
        let ankle = body.pelvis_height() + body.offset(Joint::LeftHip).y - body.leg_length();
        assert!((ankle - 0.039 * 1.75).abs() < 1e-12);
    }

    #[test]
    fn proportions_scale_limbs_and_keep_feet_on_the_ground() {
        let tall_legs = Body::new(Proportions { height_m: 1.6, arm_scale: 1.1, leg_scale: 1.2 });
        let base = Body::new(Proportions { height_m: 1.6, ..Default::default() });
        assert!((tall_legs.leg_length() - 1.2 * base.leg_length()).abs() < 1e-12);
        let arm = |b: &Body| b.offset(Joint::LeftElbow).length();
        assert!((arm(&tall_legs) - 1.1 * arm(&base)).abs() < 1e-12);
        let ankle = |b: &Body| b.pelvis_height() + b.offset(Joint::LeftHip).y - b.leg_length();
        assert!((ankle(&tall_legs) - ankle(&base)).abs() < 1e-12);
    }

    #[test]
    fn each_joints_twist_axis_is_its_rest_bone() {
        let body = Body::new(Proportions { height_m: 1.6, arm_scale: 1.2, leg_scale: 0.9 });
        for j in Joint::ALL {
            assert!(body.bone(j).normalize().abs_diff_eq(j.rest_bone_axis(), 1e-12), "{j:?}");
        }
    }

    #[test]
    fn left_and_right_mirror_across_x() {
        let body = Body::standard();
        for j in Joint::ALL {
            let (a, b) = (body.offset(j), body.offset(j.mirror()));
            assert!((a - DVec3::new(-b.x, b.y, b.z)).length() < 1e-12 || j == Joint::Pelvis);
        }
    }
}
