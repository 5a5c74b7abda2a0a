//! Color frames: the body's capsules shaded in color over a lit, textured
//! room, for testing background subtraction.
//!
//! The room is a tiled floor (y = 0) lit in a pool that fades with distance
//! and a back wall 2.5 m behind the point the camera looks at, with a smooth
//! gradient and a texture drawn from the seed; it is the same in every
//! frame, and `background()` is the room empty. One directional light, fixed
//! relative to the camera (above, behind it and to its left), lights the
//! room and the body (Lambert plus ambient) and casts the shadow that
//! [`Noise`] places at the feet.

use crate::mocap::pose::BodyFrame;
use crate::vision::camera::Camera;
use crate::vision::light::light_direction;
use crate::vision::mask::Mask;
use crate::vision::noise::Noise;
use crate::vision::shape::{CAPSULES, Capsule};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Albedos, 8-bit RGB. The body's colors differ from the room's in hue, so
/// a body part in shade is not taken for a shadow on the floor or wall.
pub const SKIN: [f64; 3] = [235.0, 170.0, 135.0];
pub const SHIRT: [f64; 3] = [195.0, 50.0, 55.0];
pub const TROUSERS: [f64; 3] = [45.0, 65.0, 140.0];
pub const SHOES: [f64; 3] = [150.0, 60.0, 40.0];
const FLOOR: [f64; 3] = [115.0, 160.0, 150.0];
const WALL: [f64; 3] = [170.0, 190.0, 215.0];
/// What a ray that meets neither floor nor wall sees (a dim ceiling).
const BEYOND: [f64; 3] = [70.0, 70.0, 78.0];
const OCCLUDER: [f64; 3] = [95.0, 80.0, 125.0];

/// Each capsule's color, in the order of `shape::capsules`: head, neck,
/// the trunk's two sides, upper arms, forearms, hands, thighs, shins, feet,
/// the trunk's middle.
const PART_COLORS: [[f64; 3]; CAPSULES] = [
    SKIN, SKIN, SHIRT, SHIRT, SHIRT, SHIRT, SHIRT, SHIRT, SKIN, SKIN, TROUSERS, TROUSERS, TROUSERS, TROUSERS, SHOES,
    SHOES, SHIRT,
];

/// Light falling on a surface: this much everywhere, plus this much times
/// the cosine to the light.
const AMBIENT: f64 = 0.4;
const DIFFUSE: f64 = 0.6;

/// The back wall's distance behind the point looked at, meters.
const WALL_BEHIND_M: f64 = 2.5;
/// Floor tiles' side, meters.
const TILE_M: f64 = 0.5;

/// Where a ray first meets a surface: the distance along the (unit) ray and
/// the outward unit normal there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f64,
    pub normal: DVec3,
}

/// Where the ray `origin + t·dir` (t > 0, `dir` unit) first enters
/// `capsule`: the nearest entry into its side (the cylinder about the axis,
/// between the ends) or either end sphere.
pub fn intersect(origin: DVec3, dir: DVec3, capsule: &Capsule) -> Option<Hit> {
    let (a, r) = (capsule.a, capsule.radius);
    let mut best: Option<Hit> = None;
    let mut keep = |t: f64, normal: DVec3| {
        if t > 0.0 && best.is_none_or(|b| t < b.t) {
            best = Some(Hit { t, normal });
        }
    };
    // The side: points at distance r from the axis line. With e the axis
    // and w = origin − a, scaled by |e|² to avoid dividing:
    // (ee − de²)·t² + 2(ee·dw − we·de)·t + (ee·ww − we² − r²·ee) = 0.
    let e = capsule.b - a;
    let w = origin - a;
    let (ee, de, we) = (e.dot(e), dir.dot(e), w.dot(e));
    let qa = ee - de * de;
    let qb = ee * dir.dot(w) - we * de;
    let qc = ee * w.dot(w) - we * we - r * r * ee;
    let h = qb * qb - qa * qc;
    // A ray along the axis meets the side nowhere but at the spheres.
    if qa > 1e-12 * ee && h >= 0.0 {
        let t = (-qb - h.sqrt()) / qa;
        let along = we + t * de;
        if along > 0.0 && along < ee {
            keep(t, (origin + t * dir - (a + e * (along / ee))) / r);
        }
    }
    for centre in [a, capsule.b] {
        let oc = origin - centre;
        let b = dir.dot(oc);
        let h = b * b - (oc.dot(oc) - r * r);
        if h >= 0.0 {
            let t = -b - h.sqrt();
            keep(t, (origin + t * dir - centre) / r);
        }
    }
    best
}

/// The closest points of the ray `origin + t·dir` (t ≥ 0, `dir` unit) and
/// the capsule's axis: (on the ray, on the axis).
fn closest(origin: DVec3, dir: DVec3, capsule: &Capsule) -> (DVec3, DVec3) {
    let e = capsule.b - capsule.a;
    let w = origin - capsule.a;
    let (ee, de) = (e.dot(e), dir.dot(e));
    let across = ee - de * de;
    let s = if across > 1e-12 { ((e.dot(w) - de * dir.dot(w)) / across).clamp(0.0, 1.0) } else { 0.0 };
    let on_ray = origin + (capsule.a + s * e - origin).dot(dir).max(0.0) * dir;
    // Clamping either parameter moves the other's best value: project back.
    let s = if ee > 0.0 { ((on_ray - capsule.a).dot(e) / ee).clamp(0.0, 1.0) } else { 0.0 };
    (on_ray, capsule.a + s * e)
}

/// A body as the camera sees it in colour.
pub trait Surface {
    /// The albedo and outward normal where the ray from `origin` along
    /// `dir` (through a pixel the body's mask covers) meets the body.
    fn look(&self, origin: DVec3, dir: DVec3) -> ([f64; 3], DVec3);
}

impl Surface for [Capsule; CAPSULES] {
    fn look(&self, origin: DVec3, dir: DVec3) -> ([f64; 3], DVec3) {
        let (part, normal) = surface(origin, dir, self);
        (PART_COLORS[part], normal)
    }
}

/// The part a body pixel's ray shows and the surface normal there: the
/// first capsule hit, or (at the rim, where the drawn outline covers a pixel
/// whose centre's ray just misses) the capsule passing nearest, its normal
/// pointing at the ray.
fn surface(origin: DVec3, dir: DVec3, capsules: &[Capsule; CAPSULES]) -> (usize, DVec3) {
    let mut best: Option<(usize, Hit)> = None;
    for (k, c) in capsules.iter().enumerate() {
        // A ray that misses the bounding sphere misses the capsule.
        let (centre, bound) = ((c.a + c.b) / 2.0, (c.b - c.a).length() / 2.0 + c.radius);
        let to = centre - origin;
        if (to - to.dot(dir) * dir).length_squared() > bound * bound {
            continue;
        }
        if let Some(hit) = intersect(origin, dir, c)
            && best.is_none_or(|(_, b)| hit.t < b.t)
        {
            best = Some((k, hit));
        }
    }
    if let Some((k, hit)) = best {
        return (k, hit.normal);
    }
    let gap = |c: &Capsule| {
        let (on_ray, on_axis) = closest(origin, dir, c);
        (on_ray - on_axis).length() - c.radius
    };
    let (k, c) = capsules.iter().enumerate().min_by(|x, y| gap(x.1).total_cmp(&gap(y.1))).expect("a body has capsules");
    let (on_ray, on_axis) = closest(origin, dir, c);
    (k, (on_ray - on_axis).try_normalize().unwrap_or(-dir))
}

/// Smooth random values on a square lattice of `SIDE` × `SIDE` (wrapping),
/// interpolated between the points: the room's textures.
struct Lattice {
    values: Vec<f64>,
}

impl Lattice {
    const SIDE: i64 = 64;

    fn new(rng: &mut ChaCha8Rng) -> Lattice {
        Lattice { values: (0..Self::SIDE * Self::SIDE).map(|_| rng.gen_range(0.0..1.0)).collect() }
    }

    fn at(&self, x: i64, y: i64) -> f64 {
        self.values[(y.rem_euclid(Self::SIDE) * Self::SIDE + x.rem_euclid(Self::SIDE)) as usize]
    }

    /// In [0, 1), smooth between lattice points.
    fn smooth(&self, x: f64, y: f64) -> f64 {
        let (x0, y0) = (x.floor(), y.floor());
        let ease = |f: f64| f * f * (3.0 - 2.0 * f);
        let (fx, fy) = (ease(x - x0), ease(y - y0));
        let (i, j) = (x0 as i64, y0 as i64);
        let top = self.at(i, j) * (1.0 - fx) + self.at(i + 1, j) * fx;
        let bottom = self.at(i, j + 1) * (1.0 - fx) + self.at(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// The room: floor, back wall, their textures and the light.
struct Room {
    origin: DVec3,
    light: DVec3,
    /// The camera's horizontal view direction and the wall's distance
    /// along it; no wall for a camera looking straight down.
    wall: Option<(DVec3, f64)>,
    /// The ground point under the point looked at: the floor's pool of
    /// light is centred there.
    centre: DVec3,
    tiles: Lattice,
    floor_grain: Lattice,
    wall_grain: Lattice,
}

impl Room {
    fn new(camera: &Camera, seed: u64) -> Room {
        let origin = camera.position();
        let look_at = DVec3::from(camera.spec().look_at);
        let view = look_at - origin;
        let wall = DVec3::new(view.x, 0.0, view.z).try_normalize().map(|ahead| {
            let distance = DVec3::new(view.x, 0.0, view.z).length() + WALL_BEHIND_M;
            (ahead, distance)
        });
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        Room {
            origin,
            light: light_direction(camera),
            wall,
            centre: DVec3::new(look_at.x, 0.0, look_at.z),
            tiles: Lattice::new(&mut rng),
            floor_grain: Lattice::new(&mut rng),
            wall_grain: Lattice::new(&mut rng),
        }
    }

    /// The color the ray `dir` from the camera sees.
    fn color(&self, dir: DVec3) -> [f64; 3] {
        let floor = (dir.y < 0.0 && self.origin.y > 0.0).then(|| -self.origin.y / dir.y);
        let wall = self.wall.and_then(|(ahead, distance)| {
            let closing = dir.dot(ahead);
            (closing > 0.0).then(|| distance / closing)
        });
        match (floor, wall) {
            (Some(t), w) if w.is_none_or(|w| t < w) => self.floor(self.origin + t * dir),
            (_, Some(t)) => self.wall(self.origin + t * dir),
            _ => BEYOND,
        }
    }

    fn floor(&self, p: DVec3) -> [f64; 3] {
        let (x, z) = (p.x / TILE_M, p.z / TILE_M);
        let (i, k) = (x.floor(), z.floor());
        // Grout lines 1.5 cm wide, a checker of two tones, each tile's own
        // shade and a fine mottle.
        let grout = if x - i < 0.03 || z - k < 0.03 { 0.75 } else { 1.0 };
        let checker = if (i as i64 + k as i64).rem_euclid(2) == 0 { 1.0 } else { 0.92 };
        let tone = 0.94 + 0.12 * self.tiles.at(i as i64, k as i64);
        let mottle = 0.95 + 0.1 * self.floor_grain.smooth(p.x / 0.12, p.z / 0.12);
        let d = (p - self.centre).length();
        let pool = 1.0 / (1.0 + (d / 4.0) * (d / 4.0));
        let lit = AMBIENT + DIFFUSE * self.light.y.max(0.0) * pool;
        FLOOR.map(|c| c * grout * checker * tone * mottle * lit)
    }

    fn wall(&self, p: DVec3) -> [f64; 3] {
        let (ahead, _) = self.wall.expect("a wall point comes from the wall");
        let across = DVec3::Y.cross(ahead).dot(p);
        let texture = 0.95 + 0.07 * self.wall_grain.smooth(across / 0.4, p.y / 0.4)
            - 0.03 * self.wall_grain.smooth(across / 0.08 + 17.0, p.y / 0.08);
        // Brighter towards the top: a smooth gradient over 3 m.
        let rise = (p.y / 3.0).clamp(0.0, 1.0);
        let gradient = 0.8 + 0.2 * rise * rise * (3.0 - 2.0 * rise);
        let lit = AMBIENT + DIFFUSE * (-ahead).dot(self.light).max(0.0) * gradient;
        WALL.map(|c| c * texture * lit)
    }
}

fn byte(value: f64) -> u8 {
    value.round().clamp(0.0, 255.0) as u8
}

/// A camera's view of the room, where the body is shaded frame by frame.
#[derive(Clone, Debug)]
pub struct Scene {
    camera: Camera,
    light: DVec3,
    /// The empty room, 8-bit RGB, row-major from the top-left pixel.
    background: Vec<u8>,
}

impl Scene {
    /// The room seen by `camera`, its textures drawn from `seed`.
    pub fn new(camera: &Camera, seed: u64) -> Scene {
        let room = Room::new(camera, seed);
        let (width, height) = (camera.width(), camera.height());
        let mut background = Vec::with_capacity(width * height * 3);
        for j in 0..height {
            for i in 0..width {
                // 3 × 3 rays a pixel, so tile edges and grout do not alias.
                let mut sum = [0.0; 3];
                for (di, dj) in (0..9).map(|k| (k % 3, k / 3)) {
                    let (u, v) = (i as f64 + (di as f64 + 0.5) / 3.0, j as f64 + (dj as f64 + 0.5) / 3.0);
                    let c = room.color(camera.ray(u, v));
                    sum = [sum[0] + c[0], sum[1] + c[1], sum[2] + c[2]];
                }
                background.extend(sum.map(|s| byte(s / 9.0)));
            }
        }
        Scene { camera: camera.clone(), light: room.light, background }
    }

    /// The empty room, 8-bit RGB, row-major from the top-left pixel.
    pub fn background(&self) -> &[u8] {
        &self.background
    }

    /// Frame `frame` in 8-bit RGB: the room, the shadow at the feet of
    /// `world` darkening the floor, the body's `surface` shaded over the
    /// pixels of its clean silhouette `body`, the box passing in front, and
    /// the sensor's noise, as `noise` has them.
    ///
    /// # Panics
    /// If `body` is not the camera's frame size.
    pub fn shade(&self, frame: usize, world: &BodyFrame, surface: &dyn Surface, body: &Mask, noise: &Noise) -> Vec<u8> {
        let width = self.camera.width();
        assert_eq!((body.width(), body.height()), (width, self.camera.height()), "a mask the camera's size");
        let mut rgb = self.background.clone();
        if let Some(shadow) = noise.shadow(world) {
            let dark = noise.params().shadow_darkening;
            shadow.visit(&self.camera, |i, j| {
                let at = 3 * (j * width + i);
                for c in &mut rgb[at..at + 3] {
                    *c = byte(f64::from(*c) * dark);
                }
            });
        }
        let origin = self.camera.position();
        for (k, _) in body.pixels().iter().enumerate().filter(|(_, p)| **p != 0) {
            let (i, j) = (k % width, k / width);
            let (albedo, normal) = surface.look(origin, self.camera.ray(i as f64 + 0.5, j as f64 + 0.5));
            let lit = AMBIENT + DIFFUSE * normal.dot(self.light).max(0.0);
            rgb[3 * k..3 * k + 3].copy_from_slice(&albedo.map(|c| byte(c * lit)));
        }
        if let Some(r) = noise.occluder(frame, world) {
            // A box lit from above: lighter at the top, a darker outline.
            for j in r.y0..r.y1 {
                let lit = 1.05 - 0.25 * (j - r.y0) as f64 / (r.y1 - r.y0) as f64;
                for i in r.x0..r.x1 {
                    let edge = if i == r.x0 || i + 1 == r.x1 || j == r.y0 || j + 1 == r.y1 { 0.7 } else { 1.0 };
                    let at = 3 * (j * width + i);
                    rgb[at..at + 3].copy_from_slice(&OCCLUDER.map(|c| byte(c * lit * edge)));
                }
            }
        }
        noise.sensor(frame, &mut rgb);
        rgb
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::{Body, Joint};
    use crate::mocap::pose::Pose;
    use crate::vision::camera::Preset;
    use crate::vision::noise::Level;
    use crate::vision::render::draw;
    use crate::vision::shape::capsules;

    /// Distance from `p` to the segment `a`–`b`.
    fn to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
        let e = b - a;
        (p - (a + e * ((p - a).dot(e) / e.dot(e)).clamp(0.0, 1.0))).length()
    }

    #[test]
    fn rays_meet_capsules_where_a_fine_march_along_them_first_enters() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut hits = 0;
        for _ in 0..300 {
            let mut point = || DVec3::new(rng.gen_range(-0.5..0.5), rng.gen_range(0.5..1.5), rng.gen_range(-0.5..0.5));
            let (a, b) = (point(), point());
            let capsule = Capsule { a, b, radius: rng.gen_range(0.02..0.15) };
            let origin = DVec3::new(rng.gen_range(-3.0..3.0), rng.gen_range(0.0..3.0), rng.gen_range(2.0..4.0));
            // Aimed near the capsule: about half the rays hit it.
            let target = a.lerp(b, rng.gen_range(-0.3..1.3))
                + 0.15 * DVec3::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), 0.0);
            let dir = (target - origin).normalize();
            let step = 1e-4;
            let marched =
                (0..80_000).map(|k| k as f64 * step).find(|&t| to_segment(origin + t * dir, a, b) <= capsule.radius);
            match (intersect(origin, dir, &capsule), marched) {
                (Some(hit), Some(t)) => {
                    hits += 1;
                    assert!(hit.t <= t + 1e-9 && hit.t > t - step - 1e-9, "{capsule:?}: {} vs {t}", hit.t);
                    let p = origin + hit.t * dir;
                    assert!((to_segment(p, a, b) - capsule.radius).abs() < 1e-9);
                    // The normal points from the nearest axis point out through p.
                    let outward = (p - a.lerp(b, ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0)))
                        / capsule.radius;
                    assert!((hit.normal - outward).length() < 1e-6 && hit.normal.dot(dir) < 0.0);
                }
                (None, None) => {}
                // A graze the march's step can miss or the formula round away.
                (found, marched) => {
                    let (on_ray, on_axis) = closest(origin, dir, &capsule);
                    let gap = (on_ray - on_axis).length() - capsule.radius;
                    assert!(gap.abs() < 1e-6, "{capsule:?} {origin} {dir}: {found:?} vs {marched:?}, gap {gap}");
                }
            }
        }
        assert!(hits > 60, "{hits} hits");
    }

    #[test]
    fn part_colors_follow_the_order_of_the_capsules() {
        let body = Body::standard();
        let world = body.forward(&Pose::rest(&body));
        let parts = capsules(&body, &world);
        for (k, joint, color) in [
            (0, Joint::Head, SKIN),
            (2, Joint::LeftHip, SHIRT),
            (4, Joint::LeftShoulder, SHIRT),
            (8, Joint::LeftWrist, SKIN),
            (10, Joint::LeftHip, TROUSERS),
            (13, Joint::RightKnee, TROUSERS),
            (15, Joint::RightAnkle, SHOES),
            (16, Joint::Pelvis, SHIRT),
        ] {
            assert_eq!(parts[k].a, world.position(joint), "capsule {k}");
            assert_eq!(PART_COLORS[k], color, "capsule {k}");
        }
    }

    #[test]
    fn the_room_is_the_seed_s_and_the_body_stands_out_from_it_everywhere() {
        let body = Body::standard();
        let mut pose = Pose::rest(&body);
        pose.root.x += 0.3;
        let world = body.forward(&pose);
        let parts = capsules(&body, &world);
        for preset in Preset::ALL {
            let camera = Camera::preset(preset, 160, 120).unwrap();
            let scene = Scene::new(&camera, 1);
            assert_eq!(scene.background().len(), 160 * 120 * 3);
            assert_eq!(Scene::new(&camera, 1).background(), scene.background());
            assert_ne!(Scene::new(&camera, 2).background(), scene.background());
            let mut mask = Mask::new(160, 120);
            draw(&camera, &parts, &mut mask);
            let rgb = scene.shade(0, &world, &parts, &mask, &Noise::new(Level::None, 1, &camera, 1, 15.0));
            let bg = scene.background();
            let mut weak = 0;
            for (k, &inside) in mask.pixels().iter().enumerate() {
                let differ: u32 = (0..3).map(|c| u32::from(rgb[3 * k + c].abs_diff(bg[3 * k + c]))).sum();
                if inside == 0 {
                    assert_eq!(differ, 0, "{}: pixel {k} off the body changed", preset.name());
                } else if differ <= 60 {
                    weak += 1;
                }
            }
            // Every body pixel by more than 20 levels a channel on average.
            assert_eq!(weak, 0, "{}: {weak} of {} body pixels near the background", preset.name(), mask.count());
        }
    }

    #[test]
    fn the_body_is_lit_from_the_light_s_side() {
        let body = Body::standard();
        let world = body.forward(&Pose::rest(&body));
        let parts = capsules(&body, &world);
        let camera = Camera::preset(Preset::Front, 320, 240).unwrap();
        let scene = Scene::new(&camera, 0);
        let mut mask = Mask::new(320, 240);
        draw(&camera, &parts, &mut mask);
        let rgb = scene.shade(0, &world, &parts, &mask, &Noise::new(Level::None, 0, &camera, 1, 15.0));
        // The light is to the camera's left, the image's left: the head's
        // left edge is brighter than its right.
        let (u, v, _) = camera.project(world.position(Joint::Head) + DVec3::Y * 0.1).unwrap();
        let row = v as usize;
        let on: Vec<usize> = (0..320).filter(|&i| mask.get(i, row)).filter(|&i| (i as f64 - u).abs() < 12.0).collect();
        let brightness = |i: usize| (0..3).map(|c| u32::from(rgb[3 * (row * 320 + i) + c])).sum::<u32>();
        let (left, right) = (brightness(on[1]), brightness(on[on.len() - 2]));
        assert!(left > right + 60, "left {left}, right {right}");
    }

    #[test]
    fn the_shadow_darkens_the_floor_by_the_level_s_share_and_keeps_its_hue() {
        let body = Body::standard();
        let world = body.forward(&Pose::rest(&body));
        let parts = capsules(&body, &world);
        let camera = Camera::preset(Preset::Overhead, 160, 120).unwrap();
        let scene = Scene::new(&camera, 0);
        let mut mask = Mask::new(160, 120);
        draw(&camera, &parts, &mut mask);
        let noise = Noise::new(Level::Light, 0, &camera, 1, 15.0);
        let rgb = scene.shade(0, &world, &parts, &mask, &noise);
        let bg = scene.background();
        let mut ratios = Vec::new();
        noise.shadow(&world).unwrap().visit(&camera, |i, j| {
            if !mask.get(i, j) {
                let k = 3 * (j * 160 + i);
                let sum = |p: &[u8]| p.iter().map(|&c| f64::from(c)).sum::<f64>();
                ratios.push(sum(&rgb[k..k + 3]) / sum(&bg[k..k + 3]));
            }
        });
        assert!(ratios.len() > 20);
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        assert!((mean - noise.params().shadow_darkening).abs() < 0.02, "{mean}");
    }
}
