//! Test bodies: people built differently from the tracker's capsules, to
//! draw test videos the tracker's own body model cannot match exactly.
//!
//! A [`Build`] says who: standing height, girth (a multiple of every
//! part's breadth), arm and leg length as multiples of their canonical
//! share of the height, hair and clothing. Its figure is ellipsoids (head,
//! hair, the trunk's three parts, shoulders, hands, feet) and tapered
//! cones cut square at both ends (neck, limbs, a skirt), with balls at the
//! elbows and knees: elliptic cross-sections, flat ends, limbs thicker at
//! the root, none of which the capsules have. Figures are ray cast, pixel
//! by pixel, so they are exact and slow beside the tracker's renderer;
//! they only draw test videos.

use crate::mocap::body::{Body, Joint};
use crate::mocap::pose::BodyFrame;
use crate::vision::camera::Camera;
use crate::vision::color::{SHIRT, SHOES, SKIN, Surface, TROUSERS};
use crate::vision::mask::Mask;
use crate::vision::render::NEAR;
use glam::{DMat3, DVec3};
use std::path::Path;

/// Hair over the head.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Hair {
    None,
    /// A cap a little larger than the head.
    Short,
    /// The cap, and hair down the back to the shoulder blades.
    Long,
}

impl Hair {
    pub fn name(self) -> &'static str {
        match self {
            Hair::None => "none",
            Hair::Short => "short",
            Hair::Long => "long",
        }
    }
}

/// What the figure wears over a fitted base of shirt and trousers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Clothing {
    Fitted,
    /// A shirt standing off the trunk and upper arms.
    LooseShirt,
    /// A skirt flaring from the waist to above the knees.
    Skirt,
}

impl Clothing {
    pub fn name(self) -> &'static str {
        match self {
            Clothing::Fitted => "fitted",
            Clothing::LooseShirt => "loose-shirt",
            Clothing::Skirt => "skirt",
        }
    }
}

/// Who a test body is (`render --body`; docs/formats.md, "Test bodies").
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Build {
    pub name: String,
    /// Standing height, head top to soles, meters.
    pub height_m: f64,
    /// Multiplies every part's breadth and depth (not the head's length).
    pub girth: f64,
    /// Arm length as a multiple of the canonical body's share of height.
    pub arm_share: f64,
    /// Leg length likewise; the trunk takes up the difference.
    pub leg_share: f64,
    pub hair: Hair,
    pub clothing: Clothing,
}

/// Ranges a build file is held to: people, not caricatures.
pub const HEIGHT_M: (f64, f64) = (1.0, 2.3);
pub const GIRTH: (f64, f64) = (0.5, 2.0);
pub const LIMB_SHARE: (f64, f64) = (0.8, 1.2);

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error(
        "no body named `{0}`: give `capsules` (the tracker's own), one of {presets}, or a build file (.toml)",
        presets = PRESETS.iter().map(|b| b.0).collect::<Vec<_>>().join(", ")
    )]
    Unknown(String),
    #[error("{path}: cannot read: {source}")]
    Read { path: String, source: std::io::Error },
    #[error("{path}: {reason}")]
    Parse { path: String, reason: String },
    #[error("{path}: `{field}` is {value}; it must be {low} to {high}")]
    Range { path: String, field: &'static str, value: f64, low: f64, high: f64 },
}

/// The test bodies that ship: from the thinnest to the thickest, 1.5 m to
/// 1.95 m, limbs short and long, every hair and clothing.
/// (name, height, girth, arms, legs, hair, clothing).
const PRESETS: [(&str, f64, f64, f64, f64, Hair, Clothing); 6] = [
    ("slight", 1.50, 0.80, 0.92, 0.95, Hair::Long, Clothing::Fitted),
    ("lanky", 1.95, 0.85, 1.10, 1.10, Hair::Short, Clothing::Fitted),
    ("average", 1.75, 1.00, 1.00, 1.00, Hair::Short, Clothing::Fitted),
    ("skirt", 1.65, 1.10, 0.95, 1.05, Hair::Long, Clothing::Skirt),
    ("broad", 1.85, 1.30, 1.05, 0.95, Hair::Short, Clothing::LooseShirt),
    ("heavy", 1.60, 1.50, 0.90, 0.90, Hair::None, Clothing::LooseShirt),
];

impl Build {
    /// Every shipped test body, thinnest first.
    pub fn presets() -> Vec<Build> {
        PRESETS.iter().map(|p| Build::preset(p.0).expect("a listed preset")).collect()
    }

    /// A shipped test body by name.
    pub fn preset(name: &str) -> Option<Build> {
        PRESETS.iter().find(|p| p.0 == name).map(|&(name, height_m, girth, arm_share, leg_share, hair, clothing)| {
            Build { name: name.to_string(), height_m, girth, arm_share, leg_share, hair, clothing }
        })
    }

    /// `capsules` (`None`: the tracker's own body), a preset's name, or a
    /// build file (TOML, the fields of [`Build`]).
    pub fn choose(choice: &str) -> Result<Option<Build>, BuildError> {
        if choice == "capsules" {
            return Ok(None);
        }
        if let Some(build) = Build::preset(choice) {
            return Ok(Some(build));
        }
        let path = Path::new(choice);
        if path.extension().is_some_and(|e| e == "toml") || path.exists() {
            return Build::load(path).map(Some);
        }
        Err(BuildError::Unknown(choice.to_string()))
    }

    /// Reads and checks a build file.
    pub fn load(path: &Path) -> Result<Build, BuildError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| BuildError::Read { path: name.clone(), source })?;
        let build: Build =
            toml::from_str(&text).map_err(|e| BuildError::Parse { path: name.clone(), reason: e.to_string() })?;
        build.check(&name)?;
        Ok(build)
    }

    /// The build as a file [`Build::load`] reads back (written by hand:
    /// the `toml` crate is built for reading only).
    pub fn to_toml(&self) -> String {
        format!(
            "name = {:?}\nheight_m = {:?}\ngirth = {:?}\narm_share = {:?}\nleg_share = {:?}\nhair = \"{}\"\nclothing = \"{}\"\n",
            self.name,
            self.height_m,
            self.girth,
            self.arm_share,
            self.leg_share,
            self.hair.name(),
            self.clothing.name()
        )
    }

    fn check(&self, path: &str) -> Result<(), BuildError> {
        for (field, value, (low, high)) in [
            ("height_m", self.height_m, HEIGHT_M),
            ("girth", self.girth, GIRTH),
            ("arm_share", self.arm_share, LIMB_SHARE),
            ("leg_share", self.leg_share, LIMB_SHARE),
        ] {
            if !(value >= low && value <= high) {
                return Err(BuildError::Range { path: path.to_string(), field, value, low, high });
            }
        }
        Ok(())
    }

    /// The build's skeleton: the canonical body's joints, standing
    /// `height_m` tall, its arms and legs the given multiples of the
    /// canonical body's shares of the height.
    pub fn body(&self) -> Body {
        Body::of_shares(self.height_m, self.arm_share, self.leg_share)
    }

    /// The figure in a posed frame of [`Build::body`].
    pub fn figure(&self, body: &Body, frame: &BodyFrame) -> Figure {
        Figure { parts: parts(self, body, frame) }
    }
}

/// A solid of a figure, in world meters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solid {
    /// Semi-axes `radii` along the unit columns of `axes`.
    Ellipsoid { centre: DVec3, axes: DMat3, radii: DVec3 },
    /// A cone from `a` (radius `ra`) to `b` (radius `rb`), cut square at
    /// both ends.
    Frustum { a: DVec3, b: DVec3, ra: f64, rb: f64 },
}

impl Solid {
    /// A sphere holding the solid: centre and radius.
    fn bound(&self) -> (DVec3, f64) {
        match *self {
            Solid::Ellipsoid { centre, radii, .. } => (centre, radii.max_element()),
            Solid::Frustum { a, b, ra, rb } => ((a + b) / 2.0, (b - a).length() / 2.0 + ra.max(rb)),
        }
    }

    /// Where the ray `origin + t·dir` (t > 0) first meets the solid, and the
    /// outward normal there.
    pub fn hit(&self, origin: DVec3, dir: DVec3) -> Option<(f64, DVec3)> {
        match *self {
            Solid::Ellipsoid { centre, axes, radii } => {
                let to_local = axes.transpose();
                let p = to_local * (origin - centre) / radii;
                let q = to_local * dir / radii;
                let t = entry(q.length_squared(), 2.0 * p.dot(q), p.length_squared() - 1.0)
                    .into_iter()
                    .flatten()
                    .find(|&t| t > 0.0)?;
                Some((t, (axes * ((p + t * q) / radii)).normalize()))
            }
            Solid::Frustum { a, b, ra, rb } => frustum_hit(a, b, ra, rb, origin, dir),
        }
    }
}

/// The roots of `a·t² + b·t + c`, smaller first (the one root of a linear
/// equation when `a` vanishes).
fn entry(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    if a.abs() < 1e-12 {
        return [(b.abs() > 1e-12).then(|| -c / b), None];
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return [None, None];
    }
    let root = disc.sqrt();
    let (t0, t1) = ((-b - root) / (2.0 * a), (-b + root) / (2.0 * a));
    [Some(t0.min(t1)), Some(t0.max(t1))]
}

fn frustum_hit(a: DVec3, b: DVec3, ra: f64, rb: f64, origin: DVec3, dir: DVec3) -> Option<(f64, DVec3)> {
    let axis = b - a;
    let length = axis.length();
    let w = axis / length;
    let (u, v) = w.any_orthonormal_pair();
    let rel = origin - a;
    let (o, d) = (DVec3::new(u.dot(rel), v.dot(rel), w.dot(rel)), DVec3::new(u.dot(dir), v.dot(dir), w.dot(dir)));
    // Radius r(z) = ra + k·z along the axis; the side is x² + y² = r(z)².
    let k = (rb - ra) / length;
    let r0 = ra + k * o.z;
    let side = entry(
        d.x * d.x + d.y * d.y - k * k * d.z * d.z,
        2.0 * (o.x * d.x + o.y * d.y - k * d.z * r0),
        o.x * o.x + o.y * o.y - r0 * r0,
    )
    .into_iter()
    .flatten()
    .filter(|&t| t > 0.0 && (0.0..=length).contains(&(o.z + t * d.z)))
    .map(|t| {
        let p = o + t * d;
        (t, (p.x * u + p.y * v - k * (ra + k * p.z) * w).normalize())
    });
    let caps = [(0.0, ra, -w), (length, rb, w)].into_iter().filter_map(|(z, r, normal)| {
        let t = (z - o.z) / d.z;
        let p = o + t * d;
        (d.z != 0.0 && t > 0.0 && p.x * p.x + p.y * p.y <= r * r).then_some((t, normal))
    });
    side.chain(caps).min_by(|x, y| x.0.total_cmp(&y.0))
}

/// Albedos, 8-bit RGB, beside the capsule body's skin, shirt, trousers and
/// shoes.
const HAIR: [f64; 3] = [70.0, 45.0, 30.0];
const SKIRT: [f64; 3] = [205.0, 150.0, 45.0];

/// One solid and its colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Part {
    pub solid: Solid,
    pub albedo: [f64; 3],
}

/// A test body posed in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    pub parts: Vec<Part>,
}

impl Figure {
    /// Draws the figure through `camera` into `mask` (adding to what it
    /// holds): a pixel is inside when the ray through its centre meets a
    /// solid.
    pub fn draw(&self, camera: &Camera, mask: &mut Mask) {
        let origin = camera.position();
        for part in &self.parts {
            let Some((i0, i1, j0, j1)) = pixel_box(camera, part.solid.bound()) else { continue };
            for j in j0..=j1 {
                for i in i0..=i1 {
                    if !mask.get(i, j) && part.solid.hit(origin, camera.ray(i as f64 + 0.5, j as f64 + 0.5)).is_some() {
                        mask.set(i, j, true);
                    }
                }
            }
        }
    }

    /// The colour and outward normal where a ray first meets the figure;
    /// `None` when it misses.
    pub fn look(&self, origin: DVec3, dir: DVec3) -> Option<([f64; 3], DVec3)> {
        self.parts
            .iter()
            .filter_map(|p| p.solid.hit(origin, dir).map(|(t, normal)| (t, p.albedo, normal)))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, albedo, normal)| (albedo, normal))
    }
}

impl Surface for Figure {
    /// At a pixel the figure's mask covers, the ray meets it; should one
    /// miss, the nearest part's colour facing the camera stands in.
    fn look(&self, origin: DVec3, dir: DVec3) -> ([f64; 3], DVec3) {
        Figure::look(self, origin, dir).unwrap_or_else(|| {
            let gap = |p: &Part| {
                let (centre, radius) = p.solid.bound();
                (centre - origin).cross(dir).length() - radius
            };
            let nearest = self.parts.iter().min_by(|a, b| gap(a).total_cmp(&gap(b))).expect("a figure has parts");
            (nearest.albedo, -dir)
        })
    }
}

/// The pixels whose centres may see a sphere (centre, radius): the image
/// box of the cube around it, or the whole frame when the cube reaches the
/// near plane; `None` when it lies outside the frame or behind the camera.
fn pixel_box(camera: &Camera, (centre, radius): (DVec3, f64)) -> Option<(usize, usize, usize, usize)> {
    let c = camera.to_camera(centre);
    if c.z + radius < NEAR {
        return None;
    }
    let (w, h) = (camera.width(), camera.height());
    if c.z - radius < NEAR {
        return Some((0, w - 1, 0, h - 1));
    }
    let (mut lo, mut hi) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for k in 0..8 {
        let corner = c + radius * DVec3::new(sign(k & 1), sign(k & 2), sign(k & 4));
        let (u, v) = camera.pixel_of(corner);
        lo = (lo.0.min(u), lo.1.min(v));
        hi = (hi.0.max(u), hi.1.max(v));
    }
    // Pixel i's centre is i + ½.
    let first = |x: f64| (x - 0.5).ceil().max(0.0) as usize;
    let last = |x: f64, n: usize| ((x - 0.5).floor().min(n as f64 - 1.0)) as i64;
    let (i1, j1) = (last(hi.0, w), last(hi.1, h));
    let (i0, j0) = (first(lo.0), first(lo.1));
    (i1 >= i0 as i64 && j1 >= j0 as i64).then_some((i0, i1 as usize, j0, j1 as usize))
}

fn sign(bit: usize) -> f64 {
    if bit == 0 { -1.0 } else { 1.0 }
}

/// An orthonormal frame whose first column is `along` and whose second
/// lies as near `toward` as it can.
fn frame_along(along: DVec3, toward: DVec3) -> DMat3 {
    let x = along.normalize();
    let y = (toward - toward.dot(x) * x).try_normalize().unwrap_or_else(|| x.any_orthonormal_vector());
    DMat3::from_cols(x, y, x.cross(y))
}

/// Every solid of `build` in `frame`. Sizes are shares of the standing
/// height from anthropometric tables (head breadth ≈ 0.087 H, length
/// ≈ 0.13 H, shoulder breadth ≈ 0.23 H, hip breadth ≈ 0.19 H, chest
/// depth ≈ 0.12 H, thigh ≈ 0.10 H across at the top, calf ≈ 0.065 H, …);
/// girth scales breadths and depths, the skeleton fixes lengths.
fn parts(build: &Build, body: &Body, frame: &BodyFrame) -> Vec<Part> {
    use Joint::*;
    let h = build.height_m;
    let g = build.girth;
    let loose = if build.clothing == Clothing::LooseShirt { 0.018 * h } else { 0.0 };
    let at = |j: Joint| frame.position(j);
    let turn = |j: Joint| DMat3::from_quat(frame.rotation(j));
    let ellipsoid = |centre: DVec3, axes: DMat3, radii: DVec3, albedo| Part {
        solid: Solid::Ellipsoid { centre, axes, radii },
        albedo,
    };
    let cone = |a: DVec3, b: DVec3, ra: f64, rb: f64, albedo| Part { solid: Solid::Frustum { a, b, ra, rb }, albedo };
    let mut parts = Vec::with_capacity(32);

    // The trunk: hips, abdomen and chest, each in its own joint's frame;
    // widths are the skeleton's (hip and shoulder joints) plus soft tissue.
    let hip_half = body.offset(LeftHip).x.abs();
    let shoulder_half = body.offset(LeftShoulder).x.abs();
    let pelvis = turn(Pelvis);
    parts.push(ellipsoid(
        at(Pelvis) + pelvis * DVec3::new(0.0, -0.012 * h, -0.004 * h),
        pelvis,
        DVec3::new(hip_half + 0.046 * h * g + loose, 0.07 * h, 0.062 * h * g + loose),
        TROUSERS,
    ));
    let spine = turn(Spine);
    parts.push(ellipsoid(
        at(Spine) + spine * DVec3::new(0.0, 0.045 * h, 0.0),
        spine,
        DVec3::new(0.082 * h * g + loose, 0.085 * h, 0.058 * h * g + loose),
        SHIRT,
    ));
    let chest = turn(Chest);
    parts.push(ellipsoid(
        at(Chest) + chest * DVec3::new(0.0, 0.05 * h, 0.004 * h),
        chest,
        DVec3::new(0.6 * shoulder_half + 0.045 * h * g + loose, 0.085 * h, 0.062 * h * g + loose),
        SHIRT,
    ));
    parts.push(cone(
        at(Neck) - (at(Head) - at(Neck)) * 0.3,
        at(Head),
        0.032 * h * g.sqrt(),
        0.028 * h * g.sqrt(),
        SKIN,
    ));

    // The head and its hair: a head varies little with build.
    let head = turn(Head);
    let head_len = body.bone(Head).length();
    // From the chin, a little below the head joint, to the head top.
    let skull = at(Head) + head * DVec3::new(0.0, 0.45 * head_len, 0.006 * h);
    let skull_radii = DVec3::new(0.044 * h * g.powf(0.2), 0.55 * head_len, 0.054 * h * g.powf(0.2));
    parts.push(ellipsoid(skull, head, skull_radii, SKIN));
    if build.hair != Hair::None {
        // A cap over the top and back, a centimetre or so thick.
        let cap = 0.007 * h;
        parts.push(ellipsoid(
            skull + head * DVec3::new(0.0, 0.15 * head_len, -0.01 * h),
            head,
            DVec3::new(skull_radii.x + cap, 0.4 * head_len + cap, skull_radii.z + cap),
            HAIR,
        ));
    }
    if build.hair == Hair::Long {
        parts.push(ellipsoid(
            at(Head) + head * DVec3::new(0.0, -0.03 * h, -0.05 * h),
            head,
            DVec3::new(0.05 * h, 0.1 * h, 0.022 * h),
            HAIR,
        ));
    }

    // Arms: a rounded shoulder, limbs tapering away from the trunk, a ball
    // at the elbow, a flat hand.
    for (shoulder, elbow, wrist) in [(LeftShoulder, LeftElbow, LeftWrist), (RightShoulder, RightElbow, RightWrist)] {
        let sleeve = 0.6 * loose;
        parts.push(ellipsoid(at(shoulder), turn(shoulder), DVec3::splat(0.036 * h * g + sleeve), SHIRT));
        parts.push(cone(at(shoulder), at(elbow), 0.032 * h * g + sleeve, 0.022 * h * g + sleeve, SHIRT));
        parts.push(ellipsoid(at(elbow), turn(elbow), DVec3::splat(0.021 * h * g), SKIN));
        parts.push(cone(at(elbow), at(wrist), 0.023 * h * g, 0.015 * h * g, SKIN));
        let tip = frame.bone_end(body, wrist);
        let axes = frame_along(tip - at(wrist), turn(wrist) * DVec3::Z);
        let half = 0.5 * (tip - at(wrist)).length();
        parts.push(ellipsoid(
            at(wrist) + axes.x_axis * half,
            axes,
            DVec3::new(1.05 * half, 0.024 * h * g.sqrt(), 0.009 * h * g.sqrt()),
            SKIN,
        ));
    }

    // Legs: thighs broad at the hip, a ball at the knee, calves, and feet
    // from the heel to the toe tip.
    for (hip, knee, ankle) in [(LeftHip, LeftKnee, LeftAnkle), (RightHip, RightKnee, RightAnkle)] {
        parts.push(cone(at(hip), at(knee), 0.05 * h * g, 0.032 * h * g, TROUSERS));
        parts.push(ellipsoid(at(knee), turn(knee), DVec3::splat(0.031 * h * g), TROUSERS));
        parts.push(cone(at(knee), at(ankle), 0.034 * h * g, 0.021 * h * g, TROUSERS));
        let toe = frame.bone_end(body, ankle);
        let heel = at(ankle) - (toe - at(ankle)) * 0.25;
        let axes = frame_along(toe - heel, turn(ankle) * DVec3::X);
        let half = 0.5 * (toe - heel).length();
        let foot = DVec3::new(half, 0.028 * h * g.powf(0.3), 0.022 * h * g.powf(0.3));
        parts.push(ellipsoid(heel + axes.x_axis * half, axes, foot, SHOES));
    }

    if build.clothing == Clothing::Skirt {
        let waist = at(Pelvis) + pelvis * DVec3::new(0.0, 0.03 * h, 0.0);
        let hem = at(Pelvis) + pelvis * DVec3::new(0.0, -0.2 * h, 0.0);
        parts.push(cone(waist, hem, hip_half + 0.05 * h * g, hip_half + 0.11 * h * g, SKIRT));
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::pose::Pose;
    use crate::vision::camera::Preset;
    use crate::vision::render::draw;
    use crate::vision::shape::capsules;

    /// Distance from `p` to the segment `a`–`b`.
    fn to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
        let e = b - a;
        (p - (a + e * ((p - a).dot(e) / e.length_squared()).clamp(0.0, 1.0))).length()
    }

    /// Whether `p` lies inside the solid, straight from its definition.
    fn inside(solid: &Solid, p: DVec3) -> bool {
        match *solid {
            Solid::Ellipsoid { centre, axes, radii } => ((axes.transpose() * (p - centre)) / radii).length() <= 1.0,
            Solid::Frustum { a, b, ra, rb } => {
                let e = b - a;
                let z = (p - a).dot(e) / e.length_squared();
                (0.0..=1.0).contains(&z) && to_segment(p, a, b) <= ra + (rb - ra) * z + 1e-12
            }
        }
    }

    #[test]
    fn rays_meet_solids_where_a_fine_march_along_them_first_enters() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut hits = 0;
        for n in 0..600 {
            let centre = DVec3::new(rng.gen_range(-0.3..0.3), rng.gen_range(0.5..1.5), rng.gen_range(-0.3..0.3));
            let solid = if n % 2 == 0 {
                let q = glam::DQuat::from_euler(glam::EulerRot::XYZ, rng.r#gen(), rng.r#gen(), rng.r#gen());
                let radii = DVec3::new(rng.gen_range(0.02..0.2), rng.gen_range(0.02..0.2), rng.gen_range(0.02..0.2));
                Solid::Ellipsoid { centre, axes: DMat3::from_quat(q), radii }
            } else {
                let b =
                    centre + DVec3::new(rng.gen_range(-0.4..0.4), rng.gen_range(-0.4..0.4), rng.gen_range(-0.4..0.4));
                Solid::Frustum { a: centre, b, ra: rng.gen_range(0.02..0.15), rb: rng.gen_range(0.02..0.15) }
            };
            let origin = DVec3::new(rng.gen_range(-1.0..1.0), rng.gen_range(0.0..2.0), 4.0);
            let aim = solid.bound().0 + DVec3::new(rng.gen_range(-0.2..0.2), rng.gen_range(-0.2..0.2), 0.0);
            let dir = (aim - origin).normalize();
            let step = 1e-4;
            let marched = (0..80_000).map(|k| k as f64 * step).find(|&t| inside(&solid, origin + t * dir));
            match (solid.hit(origin, dir), marched) {
                (Some((t, normal)), Some(m)) => {
                    hits += 1;
                    assert!(t <= m + 1e-9 && t > m - step - 1e-9, "{solid:?}: {t} vs {m}");
                    assert!((normal.length() - 1.0).abs() < 1e-9);
                    // Outward: just along the normal is outside, just inside is in.
                    let p = origin + t * dir;
                    assert!(!inside(&solid, p + 1e-6 * normal) && inside(&solid, p - 1e-6 * normal), "{solid:?}");
                }
                (None, None) => {}
                (found, m) => panic!("{solid:?} from {origin} along {dir}: hit {found:?}, march {m:?}"),
            }
        }
        assert!(hits > 150 && hits < 550, "{hits} of 600 rays hit");
    }

    #[test]
    fn each_build_stands_its_height_with_its_limb_shares() {
        for build in Build::presets() {
            let body = build.body();
            assert!((body.standing_height() - build.height_m).abs() < 1e-9, "{}", build.name);
            let (arms, legs) = body.shares();
            assert!((arms - build.arm_share).abs() < 1e-9 && (legs - build.leg_share).abs() < 1e-9, "{}", build.name);
        }
    }

    /// Extent and area of a figure's mask.
    fn measure(mask: &Mask) -> (usize, usize, usize) {
        let rows: Vec<usize> = (0..mask.height()).filter(|&j| (0..mask.width()).any(|i| mask.get(i, j))).collect();
        let cols: Vec<usize> = (0..mask.width()).filter(|&i| (0..mask.height()).any(|j| mask.get(i, j))).collect();
        (rows.last().unwrap() - rows[0] + 1, cols.last().unwrap() - cols[0] + 1, mask.count())
    }

    #[test]
    fn the_average_build_looks_like_the_capsules_and_the_others_as_tall_and_as_broad_as_they_are_built() {
        let camera = Camera::preset(Preset::Front, 320, 240).unwrap();
        let draw_figure = |build: &Build| {
            let body = build.body();
            let mut mask = Mask::new(320, 240);
            build.figure(&body, &body.forward(&Pose::rest(&body))).draw(&camera, &mut mask);
            mask
        };
        let standard = Body::standard();
        let mut capsule_mask = Mask::new(320, 240);
        draw(&camera, &capsules(&standard, &standard.forward(&Pose::rest(&standard))), &mut capsule_mask);
        let (capsule_tall, capsule_wide, capsule_area) = measure(&capsule_mask);
        let (tall, wide, area) = measure(&draw_figure(&Build::preset("average").unwrap()));
        // Same skeleton: same height and span, within two pixels; a person
        // rather than the capsules' cartoon: area within a fifth.
        assert!(
            tall.abs_diff(capsule_tall) <= 2 && wide.abs_diff(capsule_wide) <= 3,
            "{tall}×{wide} against {capsule_tall}×{capsule_wide}"
        );
        assert!((area as f64 / capsule_area as f64 - 1.0).abs() < 0.2, "{area} vs {capsule_area}");
        let (mut last_area_per_height, mut builds) = (0.0, Build::presets());
        builds.sort_by(|a, b| a.girth.total_cmp(&b.girth));
        for build in builds {
            let (tall, _, area) = measure(&draw_figure(&build));
            let expected = capsule_tall as f64 * build.height_m / 1.75;
            assert!((tall as f64 - expected).abs() <= 3.0, "{}: {tall} px tall, expected {expected}", build.name);
            // Thicker builds cover more of their height.
            let per_height = area as f64 / (tall * tall) as f64;
            assert!(per_height > last_area_per_height * 0.97, "{}: {per_height}", build.name);
            last_area_per_height = per_height;
        }
    }

    #[test]
    fn builds_read_back_from_their_files_and_bad_ones_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("me.toml");
        let mut build = Build::preset("skirt").unwrap();
        build.name = "me".into();
        std::fs::write(&path, build.to_toml()).unwrap();
        assert_eq!(Build::choose(path.to_str().unwrap()).unwrap(), Some(build.clone()));
        assert_eq!(Build::choose("capsules").unwrap(), None);
        assert_eq!(Build::choose("heavy").unwrap().unwrap().girth, 1.5);
        let message = Build::choose("giant").unwrap_err().to_string();
        assert!(message.contains("giant") && message.contains("slight, lanky"), "{message}");
        std::fs::write(&path, build.to_toml().replace("height_m = 1.65", "height_m = 2.6")).unwrap();
        let message = Build::load(&path).unwrap_err().to_string();
        assert!(message.contains("me.toml") && message.contains("`height_m` is 2.6"), "{message}");
        std::fs::write(&path, "name = \"x\"\nheight_m = 1.7\n").unwrap();
        let message = Build::load(&path).unwrap_err().to_string();
        assert!(message.contains("me.toml") && message.contains("girth"), "{message}");
    }
}
