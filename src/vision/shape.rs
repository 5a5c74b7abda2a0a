//! The body as the camera sees it: one capsule (a cylinder with rounded
//! ends) per bone, sized from the body's height.

use crate::mocap::body::{Body, Joint};
use crate::mocap::pose::BodyFrame;
use glam::DVec3;

/// A segment from `a` to `b` swept by a sphere of `radius`, world meters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    pub a: DVec3,
    pub b: DVec3,
    pub radius: f64,
}

/// Where a capsule runs: from a joint to another joint, or to the end of
/// the bone leaving a joint (head top, hand tip, toe).
#[derive(Clone, Copy, Debug)]
enum Span {
    Joints(Joint, Joint),
    Bone(Joint),
}

/// Every capsule and its radius as a share of standing height. Radii are
/// half the typical breadth of each part for an adult (anthropometric
/// tables give head breadth ≈ 0.087 H, thigh ≈ 0.09 H, upper arm
/// ≈ 0.055 H, …). The trunk is three capsules: hip to shoulder on each
/// side, so it is broad seen from the front and shallow from the side, and
/// (last) pelvis to neck, which fills the chest between them and gives the
/// trunk its depth (chest depth ≈ 0.12 H).
const PARTS: [(Span, f64); 17] = {
    use Joint::*;
    [
        (Span::Bone(Head), 0.050),
        (Span::Joints(Neck, Head), 0.030),
        (Span::Joints(LeftHip, LeftShoulder), 0.055),
        (Span::Joints(RightHip, RightShoulder), 0.055),
        (Span::Joints(LeftShoulder, LeftElbow), 0.027),
        (Span::Joints(RightShoulder, RightElbow), 0.027),
        (Span::Joints(LeftElbow, LeftWrist), 0.021),
        (Span::Joints(RightElbow, RightWrist), 0.021),
        (Span::Bone(LeftWrist), 0.017),
        (Span::Bone(RightWrist), 0.017),
        (Span::Joints(LeftHip, LeftKnee), 0.042),
        (Span::Joints(RightHip, RightKnee), 0.042),
        (Span::Joints(LeftKnee, LeftAnkle), 0.029),
        (Span::Joints(RightKnee, RightAnkle), 0.029),
        (Span::Bone(LeftAnkle), 0.020),
        (Span::Bone(RightAnkle), 0.020),
        (Span::Joints(Pelvis, Neck), 0.060),
    ]
};

/// How many capsules a body is drawn with.
pub const CAPSULES: usize = PARTS.len();

/// Radius of the capsule along the bone that leaves `j`, as a share of
/// standing height; the trunk's joints (pelvis, spine, chest) share the
/// trunk's middle capsule.
pub fn bone_radius_share(j: Joint) -> f64 {
    let along = |span: &Span| match *span {
        Span::Joints(from, to) => from == j && j.bone_child() == Some(to),
        Span::Bone(from) => from == j,
    };
    let trunk = PARTS[CAPSULES - 1].1;
    PARTS.iter().find(|(span, _)| along(span)).map_or(trunk, |part| part.1)
}

/// How thick the drawn body's parts are: multiples of the canonical radii
/// for each group of capsules. A person's build is estimated as this and
/// the skeleton's proportions; poses stay in the canonical joint space.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Girth {
    /// Head and neck.
    pub head: f64,
    /// The trunk's three capsules.
    pub trunk: f64,
    /// Upper arms, forearms and hands.
    pub arms: f64,
    /// Thighs, shins and feet.
    pub legs: f64,
}

impl Girth {
    pub const CANONICAL: Girth = Girth { head: 1.0, trunk: 1.0, arms: 1.0, legs: 1.0 };

    /// The multiple for capsule `k` of [`PARTS`]' order.
    fn of(&self, k: usize) -> f64 {
        match k {
            0 | 1 => self.head,
            4..=9 => self.arms,
            10..=15 => self.legs,
            _ => self.trunk,
        }
    }
}

/// The body's capsules in a posed frame, at the canonical girth.
pub fn capsules(body: &Body, frame: &BodyFrame) -> [Capsule; CAPSULES] {
    shaped_capsules(body, &Girth::CANONICAL, frame)
}

/// The body's capsules in a posed frame, each group as thick as `girth`
/// says.
pub fn shaped_capsules(body: &Body, girth: &Girth, frame: &BodyFrame) -> [Capsule; CAPSULES] {
    let height = body.proportions.height_m;
    let mut k = 0;
    PARTS.map(|(span, share)| {
        let radius = share * height * girth.of(k);
        k += 1;
        let (a, b) = match span {
            Span::Joints(from, to) => (frame.position(from), frame.position(to)),
            // The rounded end reaches the end site (head top, finger or
            // toe tip) rather than passing it by a radius.
            Span::Bone(j) => {
                let (a, end) = (frame.position(j), frame.bone_end(body, j));
                (a, end - (end - a).normalize_or_zero() * radius.min((end - a).length()))
            }
        };
        Capsule { a, b, radius }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::pose::Pose;

    #[test]
    fn a_t_pose_body_is_as_tall_and_as_wide_as_the_skeleton_and_its_limbs_thinner_than_its_trunk() {
        for height in [1.5, 1.75, 2.0] {
            let body = Body::new(crate::mocap::body::Proportions { height_m: height, ..Default::default() });
            let parts = capsules(&body, &body.forward(&Pose::rest(&body)));
            let reach = |f: &dyn Fn(DVec3) -> f64| {
                parts.iter().flat_map(|c| [f(c.a) + c.radius, f(c.b) + c.radius]).fold(f64::MIN, f64::max)
            };
            let top = reach(&|p| p.y);
            let bottom = -reach(&|p| -p.y);
            let span = reach(&|p| p.x) + reach(&|p| -p.x);
            let frame = body.forward(&Pose::rest(&body));
            let head_top = frame.bone_end(&body, Joint::Head).y;
            let tips = frame.bone_end(&body, Joint::LeftWrist).x - frame.bone_end(&body, Joint::RightWrist).x;
            assert!((top - head_top).abs() < 1e-9, "{height}: top {top}, head top {head_top}");
            assert!(bottom > -0.03 * height && bottom < 0.0, "{height}: the feet reach {bottom}");
            assert!((span - tips).abs() < 0.04 * height, "{height}: span {span}, finger tips {tips}");
        }
        let radius = |from: Joint| PARTS.iter().find(|p| matches!(p.0, Span::Joints(f, _) if f == from)).unwrap().1;
        let (side, middle) = (radius(Joint::LeftHip), radius(Joint::Pelvis));
        assert!(middle >= side);
        assert!(PARTS.iter().filter(|p| p.1 != middle).all(|p| p.1 <= side));
    }
}
