//! Noise for robustness tests: what a real segmenter and camera do to a
//! clean render, at four levels.
//!
//! On silhouettes: the edge eroded or dilated in patches, holes in the body,
//! salt and pepper, the shadow at the feet taken for the person, and now and
//! then a box passing in front that hides part of the body. On color frames
//! (see [`crate::vision::color`]): sensor noise, the shadow as a darker
//! floor, the box drawn in front, and at `heavy` a flickering light.
//!
//! Every frame draws its randomness from its own ChaCha stream keyed by the
//! seed and the frame's number, so frames come out the same in any order on
//! any number of threads; when the occlusions happen is drawn once per take.

use crate::mocap::body::Joint;
use crate::mocap::pose::BodyFrame;
use crate::vision::camera::Camera;
use crate::vision::light::light_direction;
use crate::vision::mask::Mask;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// How much noise: `none` gives the clean render, `light` (the default of
/// `render`) a good segmenter, `heavy` a poor one in a busy scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    None,
    Light,
    Medium,
    Heavy,
}

impl Level {
    pub const ALL: [Level; 4] = [Level::None, Level::Light, Level::Medium, Level::Heavy];

    pub fn name(self) -> &'static str {
        match self {
            Level::None => "none",
            Level::Light => "light",
            Level::Medium => "medium",
            Level::Heavy => "heavy",
        }
    }

    /// What the level does (docs/commands.md has the table).
    pub fn params(self) -> Params {
        let occlusion = |every_s, duration_s, size_m| Some(Occlusions { every_s, duration_s, size_m });
        match self {
            Level::None => Params {
                edge_share: 0.0,
                edge_px: 0,
                holes: 0,
                hole_radius_px: (0.0, 0.0),
                salt_pepper: 0.0,
                shadow_m: None,
                occlusions: None,
                sensor_sd: 0.0,
                shadow_darkening: 1.0,
                flicker: 0.0,
            },
            Level::Light => Params {
                edge_share: 0.12,
                edge_px: 1,
                holes: 1,
                hole_radius_px: (1.0, 1.5),
                salt_pepper: 0.0003,
                shadow_m: Some((0.06, 0.15)),
                occlusions: None,
                sensor_sd: 2.0,
                shadow_darkening: 0.8,
                flicker: 0.0,
            },
            Level::Medium => Params {
                edge_share: 0.4,
                edge_px: 1,
                holes: 2,
                hole_radius_px: (1.0, 2.0),
                salt_pepper: 0.002,
                shadow_m: Some((0.08, 0.3)),
                occlusions: occlusion(None, 0.5, (0.3, 0.5)),
                sensor_sd: 3.5,
                shadow_darkening: 0.65,
                flicker: 0.0,
            },
            Level::Heavy => Params {
                edge_share: 0.6,
                edge_px: 2,
                holes: 4,
                hole_radius_px: (1.5, 3.0),
                salt_pepper: 0.005,
                shadow_m: Some((0.1, 0.5)),
                occlusions: occlusion(Some(8.0), 0.8, (0.35, 0.6)),
                sensor_sd: 6.0,
                shadow_darkening: 0.5,
                flicker: 0.02,
            },
        }
    }
}

impl std::str::FromStr for Level {
    type Err = String;

    /// A level's name, or its number from 0 (`none`) to 3 (`heavy`).
    fn from_str(text: &str) -> Result<Level, String> {
        let numbered = |(i, level): (usize, Level)| (text == level.name() || text == i.to_string()).then_some(level);
        Level::ALL
            .into_iter()
            .enumerate()
            .find_map(numbered)
            .ok_or_else(|| "expected none, light, medium or heavy (or 0 to 3)".to_string())
    }
}

/// What a level does to each frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Share of the frame's 8×8-pixel tiles whose edges move each frame,
    /// half of them eroded and half dilated: a segmenter errs in patches.
    pub edge_share: f64,
    /// The most pixels an edge moves; each moved tile picks 1 to this.
    pub edge_px: usize,
    /// Up to this many holes a frame (uniformly 0 to it), discs cleared
    /// around body pixels.
    pub holes: usize,
    /// The holes' radius range, pixels of a frame 120 pixels high (scaled
    /// with the height).
    pub hole_radius_px: (f64, f64),
    /// Share of all pixels flipped (salt and pepper).
    pub salt_pepper: f64,
    /// The shadow on the ground at the feet: its margin around the feet
    /// and how far it reaches away from the light, meters; `None`: no
    /// shadow.
    pub shadow_m: Option<(f64, f64)>,
    /// Boxes passing in front of the person; `None`: never.
    pub occlusions: Option<Occlusions>,
    /// Color frames: standard deviation of the per-pixel sensor noise, in
    /// 8-bit levels.
    pub sensor_sd: f64,
    /// Color frames: the shadowed floor's brightness, as a share of the lit
    /// floor's (same hue).
    pub shadow_darkening: f64,
    /// Color frames: standard deviation of the frame's overall brightness
    /// factor (a flickering light).
    pub flicker: f64,
}

/// When and how boxes pass in front of the person.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Occlusions {
    /// One box in every window of this many seconds; `None`: one per take.
    pub every_s: Option<f64>,
    /// How long a box takes to pass, seconds.
    pub duration_s: f64,
    /// The box's width and height, meters, as it appears at the person's
    /// distance.
    pub size_m: (f64, f64),
}

/// One box passing in front of the person.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Occlusion {
    /// The first frame it covers and how many frames it lasts.
    pub start: usize,
    pub frames: usize,
    /// Moving to the image's right (else left).
    pub rightwards: bool,
    /// How far its centre is above the pelvis, meters.
    pub lift_m: f64,
}

/// Pixels `[x0, x1) × [y0, y1)`, inside the frame and not empty.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

/// A shadow: an ellipse on the ground plane (y = 0) under the feet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shadow {
    pub centre: DVec3,
    /// Unit ground directions of the two axes: away from the light, and
    /// across.
    pub along: DVec3,
    pub across: DVec3,
    /// Semi-axes, meters.
    pub a: f64,
    pub b: f64,
}

impl Shadow {
    /// Whether the ground point `p` is in the shadow.
    pub fn contains(&self, p: DVec3) -> bool {
        let d = p - self.centre;
        let (x, y) = (d.dot(self.along) / self.a, d.dot(self.across) / self.b);
        x * x + y * y <= 1.0
    }

    /// Calls `visit(i, j)` for every pixel whose centre's ray meets the
    /// ground inside the shadow.
    pub fn visit(&self, camera: &Camera, mut visit: impl FnMut(usize, usize)) {
        let (width, height) = (camera.width(), camera.height());
        // The outline's image bounds the pixels to test; all of the frame
        // when part of it is behind the camera.
        let mut bounds = (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        for k in 0..16 {
            let angle = k as f64 * std::f64::consts::TAU / 16.0;
            // 16 points on a circumscribed polygon: √(1 + tan²(π/16)) out.
            let reach = 1.0 / (std::f64::consts::PI / 16.0).cos();
            let p = self.centre + reach * (self.a * angle.cos() * self.along + self.b * angle.sin() * self.across);
            match camera.project(p) {
                Some((u, v, _)) => bounds = (bounds.0.min(u), bounds.1.min(v), bounds.2.max(u), bounds.3.max(v)),
                None => bounds = (0.0, 0.0, width as f64, height as f64),
            }
        }
        let first = |lo: f64| (lo - 0.5).ceil().max(0.0) as usize;
        let end = |hi: f64, count: usize| ((hi - 0.5).floor() + 1.0).clamp(0.0, count as f64) as usize;
        let origin = camera.position();
        for j in first(bounds.1)..end(bounds.3, height) {
            for i in first(bounds.0)..end(bounds.2, width) {
                let ray = camera.ray(i as f64 + 0.5, j as f64 + 0.5);
                let t = -origin.y / ray.y;
                if ray.y < 0.0 && t > 0.0 && self.contains(origin + t * ray) {
                    visit(i, j);
                }
            }
        }
    }
}

/// Which use a frame's random stream is for: the silhouette's and the color
/// frame's are independent, so `--color` leaves the silhouettes as they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stream {
    Silhouette = 0,
    Color = 1,
    /// The take's schedule of occlusions.
    Take = 2,
}

/// Length of the table of sensor noise values: a frame reads it from a
/// random place, which is much cheaper than a normal draw per channel.
const GRAIN: usize = 1 << 18;

/// Edge tiles are this many pixels square.
const TILE: usize = 8;

/// The noise of one take at one level.
#[derive(Clone, Debug)]
pub struct Noise {
    level: Level,
    params: Params,
    seed: u64,
    camera: Camera,
    occlusions: Vec<Occlusion>,
    /// Sensor noise values, 8-bit levels; empty without sensor noise.
    grain: Vec<i8>,
}

impl Noise {
    /// The noise of a take of `frames` frames at `fps` seen by `camera`.
    pub fn new(level: Level, seed: u64, camera: &Camera, frames: usize, fps: f64) -> Noise {
        let params = level.params();
        let occlusions = params.occlusions.map_or_else(Vec::new, |o| schedule(&o, seed, frames, fps));
        let grain = if params.sensor_sd > 0.0 {
            let mut rng = stream(seed, u64::MAX, Stream::Color);
            let normal = Normal::new(0.0, params.sensor_sd).expect("a positive deviation");
            (0..GRAIN).map(|_| normal.sample(&mut rng).round().clamp(-127.0, 127.0) as i8).collect()
        } else {
            Vec::new()
        };
        Noise { level, params, seed, camera: camera.clone(), occlusions, grain }
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The boxes passing in front, in order of time.
    pub fn occlusions(&self) -> &[Occlusion] {
        &self.occlusions
    }

    /// Frame `frame`'s random numbers for one use.
    fn rng(&self, frame: usize, purpose: Stream) -> ChaCha8Rng {
        stream(self.seed, frame as u64, purpose)
    }

    /// The shadow under the feet of `world`, if the level has one.
    pub fn shadow(&self, world: &BodyFrame) -> Option<Shadow> {
        let (margin, reach) = self.params.shadow_m?;
        let ground = |p: DVec3| DVec3::new(p.x, 0.0, p.z);
        let (left, right) = (world.position(Joint::LeftAnkle), world.position(Joint::RightAnkle));
        let light = light_direction(&self.camera);
        // Straight down from a light overhead: any ground direction will do.
        let along = ground(-light).try_normalize().unwrap_or(DVec3::X);
        let across = DVec3::Y.cross(along);
        let apart = ground(left - right);
        Some(Shadow {
            centre: ground((left + right) / 2.0) + along * reach / 2.0,
            along,
            across,
            a: reach / 2.0 + margin + apart.dot(along).abs() / 2.0,
            b: margin + apart.dot(across).abs() / 2.0,
        })
    }

    /// The box in front of the person at frame `frame`, if one is passing
    /// and shows in the frame.
    pub fn occluder(&self, frame: usize, world: &BodyFrame) -> Option<Rect> {
        let size = self.params.occlusions?.size_m;
        let event = self.occlusions.iter().find(|o| (o.start..o.start + o.frames).contains(&frame))?;
        let pelvis = self.camera.to_camera(world.position(Joint::Pelvis));
        if pelvis.z < crate::vision::render::NEAR {
            return None;
        }
        let (u, v) = self.camera.pixel_of(pelvis);
        let spec = self.camera.spec();
        let (across, up) = (spec.fx / pelvis.z, spec.fy / pelvis.z);
        // From 0.8 m on one side of the pelvis to 0.8 m on the other.
        let progress = (frame - event.start) as f64 / event.frames as f64 + 0.5 / event.frames as f64;
        let sweep = if event.rightwards { progress - 0.5 } else { 0.5 - progress } * 1.6;
        let (x, y) = (u + sweep * across, v - event.lift_m * up);
        let (w, h) = (size.0 * across / 2.0, size.1 * up / 2.0);
        let first = |lo: f64, count: usize| (lo - 0.5).ceil().clamp(0.0, count as f64) as usize;
        let (width, height) = (self.camera.width(), self.camera.height());
        let rect = Rect {
            x0: first(x - w, width),
            y0: first(y - h, height),
            x1: first(x + w, width),
            y1: first(y + h, height),
        };
        (rect.x0 < rect.x1 && rect.y0 < rect.y1).then_some(rect)
    }

    /// Spoils the clean silhouette `mask` of `world` as frame `frame`: the
    /// shadow added, edges moved in patches, holes, the passing box, then
    /// salt and pepper.
    ///
    /// # Panics
    /// If `mask` is not the camera's frame size.
    pub fn apply(&self, frame: usize, world: &BodyFrame, mask: &mut Mask) {
        let (width, height) = (mask.width(), mask.height());
        assert_eq!((width, height), (self.camera.width(), self.camera.height()), "a mask the camera's size");
        if self.level == Level::None {
            return;
        }
        let mut rng = self.rng(frame, Stream::Silhouette);
        let pixels = mask.pixels_mut();
        if let Some(shadow) = self.shadow(world) {
            shadow.visit(&self.camera, |i, j| pixels[j * width + i] = 1);
        }
        if self.params.edge_px > 0 {
            let moved = self.edges(&mut rng, pixels, width);
            pixels.copy_from_slice(&moved);
        }
        self.holes(&mut rng, pixels, width);
        if let Some(r) = self.occluder(frame, world) {
            for row in pixels.chunks_exact_mut(width).take(r.y1).skip(r.y0) {
                row[r.x0..r.x1].fill(0);
            }
        }
        let flips = (self.params.salt_pepper * (width * height) as f64).round() as usize;
        for _ in 0..flips {
            pixels[rng.gen_range(0..width * height)] ^= 1;
        }
    }

    /// `pixels` with each tile's edge kept, eroded or dilated.
    fn edges(&self, rng: &mut ChaCha8Rng, pixels: &[u8], width: usize) -> Vec<u8> {
        let most = self.params.edge_px;
        // variants[r] = grown by r + 1, variants[most + r] = shrunk by r + 1.
        let mut variants: Vec<Vec<u8>> = Vec::with_capacity(2 * most);
        for (first, grow) in [(0, true), (most, false)] {
            for r in 0..most {
                let src = if r == 0 { pixels } else { &variants[first + r - 1] };
                let mut dst = vec![0; pixels.len()];
                if grow {
                    step(src, &mut dst, width, |a, b| a | b)
                } else {
                    step(src, &mut dst, width, |a, b| a & b)
                }
                variants.push(dst);
            }
        }
        let mut out = pixels.to_vec();
        let height = pixels.len() / width;
        for ty in (0..height).step_by(TILE) {
            for tx in (0..width).step_by(TILE) {
                let pick = rng.gen_range(0.0..1.0);
                if pick >= self.params.edge_share {
                    continue;
                }
                let by = if most == 1 { 0 } else { rng.gen_range(0..most) };
                let source = &variants[if pick < self.params.edge_share / 2.0 { by } else { most + by }];
                let x1 = (tx + TILE).min(width);
                for y in ty..(ty + TILE).min(height) {
                    out[y * width + tx..y * width + x1].copy_from_slice(&source[y * width + tx..y * width + x1]);
                }
            }
        }
        out
    }

    /// Clears up to `holes` discs centred on body pixels.
    fn holes(&self, rng: &mut ChaCha8Rng, pixels: &mut [u8], width: usize) {
        if self.params.holes == 0 {
            return;
        }
        let height = pixels.len() / width;
        let rows: Vec<usize> = (0..height).filter(|&y| pixels[y * width..(y + 1) * width].contains(&1)).collect();
        let (Some(&top), Some(&bottom)) = (rows.first(), rows.last()) else { return };
        let scale = height as f64 / 120.0;
        let (small, large) = self.params.hole_radius_px;
        for _ in 0..rng.gen_range(0..=self.params.holes) {
            let radius = rng.gen_range(small..=large) * scale;
            // A few tries at a body pixel within the body's rows.
            let centre = (0..16)
                .map(|_| (rng.gen_range(0..width), rng.gen_range(top..=bottom)))
                .find(|&(x, y)| pixels[y * width + x] != 0);
            let Some((cx, cy)) = centre else { continue };
            let reach = radius.floor() as usize;
            for y in cy.saturating_sub(reach)..=(cy + reach).min(height - 1) {
                for x in cx.saturating_sub(reach)..=(cx + reach).min(width - 1) {
                    let (dx, dy) = (x.abs_diff(cx) as f64, y.abs_diff(cy) as f64);
                    if dx * dx + dy * dy <= radius * radius {
                        pixels[y * width + x] = 0;
                    }
                }
            }
        }
    }

    /// Sensor noise and flicker on frame `frame`'s RGB pixels.
    pub fn sensor(&self, frame: usize, rgb: &mut [u8]) {
        let mut rng = self.rng(frame, Stream::Color);
        if self.params.flicker > 0.0 {
            let sd = self.params.flicker;
            let gain =
                1.0 + Normal::new(0.0, sd).expect("a positive deviation").sample(&mut rng).clamp(-3.0 * sd, 3.0 * sd);
            for c in rgb.iter_mut() {
                *c = (f64::from(*c) * gain).round().min(255.0) as u8;
            }
        }
        if self.grain.is_empty() {
            return;
        }
        // The table read on from a random place, wrapping round.
        let mut at = rng.gen_range(0..GRAIN);
        let mut rest = rgb;
        while !rest.is_empty() {
            let n = rest.len().min(GRAIN - at);
            let (now, later) = std::mem::take(&mut rest).split_at_mut(n);
            for (c, &g) in now.iter_mut().zip(&self.grain[at..at + n]) {
                *c = (i16::from(*c) + i16::from(g)).clamp(0, 255) as u8;
            }
            rest = later;
            at = 0;
        }
    }
}

/// The random stream of `seed`, frame `frame` and one use: ChaCha keyed by
/// the seed and the frame, one stream per use.
fn stream(seed: u64, frame: u64, purpose: Stream) -> ChaCha8Rng {
    let mut key = [0u8; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    key[8..16].copy_from_slice(&frame.to_le_bytes());
    let mut rng = ChaCha8Rng::from_seed(key);
    rng.set_stream(purpose as u64);
    rng
}

/// When boxes pass: one in each window (the take, or `every_s`), at a
/// random time within it that keeps a box's length of quiet after it.
fn schedule(o: &Occlusions, seed: u64, frames: usize, fps: f64) -> Vec<Occlusion> {
    let mut rng = stream(seed, u64::MAX, Stream::Take);
    let length = ((o.duration_s * fps).round() as usize).max(1);
    let window = o.every_s.map_or(frames, |every| ((every * fps).round() as usize).max(2 * length)).max(1);
    (0..frames)
        .step_by(window)
        .map(|from| {
            let room = (window.min(frames - from)).saturating_sub(2 * length);
            let start = from + rng.gen_range(0..=room);
            Occlusion {
                start,
                frames: length.min(frames - start),
                rightwards: rng.gen_bool(0.5),
                lift_m: rng.gen_range(-0.4..=0.4),
            }
        })
        .collect()
}

/// One step of 4-neighbour dilation (`op` = or) or erosion (`op` = and) of
/// `src` into `dst`. The frame's border repeats its pixels, so a body cut
/// by the edge of the frame neither grows nor shrinks from there.
fn step(src: &[u8], dst: &mut [u8], width: usize, op: impl Fn(u8, u8) -> u8 + Copy) {
    let height = src.len() / width;
    for y in 0..height {
        let row = &src[y * width..][..width];
        let above = &src[y.saturating_sub(1) * width..][..width];
        let below = &src[(y + 1).min(height - 1) * width..][..width];
        let out = &mut dst[y * width..][..width];
        for (o, ((&r, &a), &b)) in out.iter_mut().zip(row.iter().zip(above).zip(below)) {
            *o = op(op(r, a), b);
        }
        for (o, &l) in out[1..].iter_mut().zip(&row[..width - 1]) {
            *o = op(*o, l);
        }
        for (o, &r) in out[..width - 1].iter_mut().zip(&row[1..]) {
            *o = op(*o, r);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Body;
    use crate::mocap::pose::Pose;
    use crate::vision::camera::Preset;
    use crate::vision::render::draw;
    use crate::vision::shape::capsules;

    fn standing(body: &Body, at: DVec3) -> BodyFrame {
        let mut pose = Pose::rest(body);
        pose.root += at;
        body.forward(&pose)
    }

    fn clean(camera: &Camera, body: &Body, world: &BodyFrame) -> Mask {
        let mut mask = Mask::new(camera.width(), camera.height());
        draw(camera, &capsules(body, world), &mut mask);
        mask
    }

    #[test]
    fn levels_are_named_or_numbered_and_anything_else_is_refused() {
        for (i, level) in Level::ALL.into_iter().enumerate() {
            assert_eq!(level.name().parse::<Level>(), Ok(level));
            assert_eq!(i.to_string().parse::<Level>(), Ok(level));
        }
        for bad in ["4", "Light", "", "extreme"] {
            assert!(bad.parse::<Level>().unwrap_err().contains("none, light, medium or heavy"), "{bad}");
        }
    }

    #[test]
    fn none_keeps_the_silhouette_and_each_level_spoils_it_more() {
        let body = Body::standard();
        let camera = Camera::preset(Preset::Front, 160, 120).unwrap();
        let world = standing(&body, DVec3::ZERO);
        let truth = clean(&camera, &body, &world);
        let mut previous = 1.0;
        for level in Level::ALL {
            // Every frame of a take one box passes through (medium), as
            // long as a heavy window, so both show their boxes.
            let noise = Noise::new(level, 7, &camera, 120, 15.0);
            let scores: Vec<f64> = (0..120)
                .map(|k| {
                    let mut mask = truth.clone();
                    noise.apply(k, &world, &mut mask);
                    assert!(mask.pixels().iter().all(|&p| p <= 1));
                    mask.iou(&truth)
                })
                .collect();
            let mean = scores.iter().sum::<f64>() / scores.len() as f64;
            let worst = scores.iter().copied().fold(1.0, f64::min);
            let (low, high) = match level {
                Level::None => (1.0, 1.0),
                Level::Light => (0.9, 0.99),
                Level::Medium => (0.8, 0.95),
                Level::Heavy => (0.6, 0.85),
            };
            let less = level == Level::None || mean < previous;
            assert!(mean >= low && mean <= high && less, "{}: mean IoU {mean}", level.name());
            assert!(worst >= low - 0.15, "{}: worst IoU {worst}", level.name());
            previous = mean;
        }
    }

    #[test]
    fn a_frame_is_the_same_for_its_seed_and_number_alone() {
        let body = Body::standard();
        let camera = Camera::preset(Preset::Side, 160, 120).unwrap();
        let world = standing(&body, DVec3::ZERO);
        let truth = clean(&camera, &body, &world);
        let spoil = |seed: u64, frame: usize| {
            let mut mask = truth.clone();
            Noise::new(Level::Medium, seed, &camera, 300, 15.0).apply(frame, &world, &mut mask);
            mask
        };
        assert_eq!(spoil(1, 40), spoil(1, 40));
        assert_ne!(spoil(1, 40), spoil(1, 41));
        assert_ne!(spoil(1, 40), spoil(2, 40));
    }

    #[test]
    fn the_shadow_lies_on_the_ground_around_the_feet_and_falls_away_from_the_light() {
        let body = Body::standard();
        for preset in Preset::ALL {
            let camera = Camera::preset(preset, 160, 120).unwrap();
            let noise = Noise::new(Level::Heavy, 0, &camera, 10, 15.0);
            let away = -light_direction(&camera);
            for at in [DVec3::ZERO, DVec3::new(0.8, 0.0, -0.5)] {
                let world = standing(&body, at);
                let shadow = noise.shadow(&world).unwrap();
                assert_eq!(shadow.centre.y, 0.0);
                for ankle in [Joint::LeftAnkle, Joint::RightAnkle] {
                    let p = world.position(ankle);
                    assert!(shadow.contains(DVec3::new(p.x, 0.0, p.z)), "{}: {ankle:?}", preset.name());
                }
                let feet = (world.position(Joint::LeftAnkle) + world.position(Joint::RightAnkle)) / 2.0;
                let lean = (shadow.centre - DVec3::new(feet.x, 0.0, feet.z)).normalize();
                assert!(lean.dot(DVec3::new(away.x, 0.0, away.z).normalize()) > 0.99, "{}", preset.name());
                // Its pixels see the ground inside it, round where the feet are.
                let (fu, fv, _) = camera.project(DVec3::new(feet.x, 0.0, feet.z)).unwrap();
                let mut count = 0;
                shadow.visit(&camera, |i, j| {
                    let ray = camera.ray(i as f64 + 0.5, j as f64 + 0.5);
                    let ground = camera.position() - camera.position().y / ray.y * ray;
                    assert!(shadow.contains(ground));
                    assert!((i as f64 - fu).abs() < 40.0 && (j as f64 - fv).abs() < 40.0, "{}", preset.name());
                    count += 1;
                });
                assert!(count > 20, "{}: {count} pixels", preset.name());
            }
        }
    }

    #[test]
    fn boxes_pass_briefly_once_a_window_at_times_drawn_from_the_seed() {
        let camera = Camera::preset(Preset::Front, 160, 120).unwrap();
        // 60 s at 15 Hz: heavy has one box in each 8 s window, 0.8 s long.
        let heavy = Noise::new(Level::Heavy, 3, &camera, 900, 15.0);
        let boxes = heavy.occlusions();
        assert_eq!(boxes.len(), 8);
        for (w, o) in boxes.iter().enumerate() {
            assert_eq!(o.frames, 12);
            assert!(o.start >= w * 120 && o.start + 2 * o.frames <= ((w + 1) * 120).min(900), "{o:?}");
        }
        assert_eq!(Noise::new(Level::Heavy, 3, &camera, 900, 15.0).occlusions(), boxes);
        assert_ne!(Noise::new(Level::Heavy, 4, &camera, 900, 15.0).occlusions(), boxes);
        // Medium: one box a take, half a second; light: none.
        let medium = Noise::new(Level::Medium, 3, &camera, 900, 15.0);
        assert!(matches!(medium.occlusions(), [o] if o.frames == 8));
        assert!(Noise::new(Level::Light, 3, &camera, 900, 15.0).occlusions().is_empty());
        // A take shorter than a box: the box lasts the take.
        assert!(
            matches!(Noise::new(Level::Heavy, 3, &camera, 5, 15.0).occlusions(), [o] if o.start == 0 && o.frames == 5)
        );
    }

    #[test]
    fn the_box_shows_while_it_passes_crosses_the_body_and_hides_what_it_covers() {
        let body = Body::standard();
        let camera = Camera::preset(Preset::Front, 160, 120).unwrap();
        let world = standing(&body, DVec3::ZERO);
        let truth = clean(&camera, &body, &world);
        let noise = Noise::new(Level::Heavy, 5, &camera, 900, 15.0);
        let o = noise.occlusions()[2];
        let (pu, _) = camera.pixel_of(camera.to_camera(world.position(Joint::Pelvis)));
        let mut centres = Vec::new();
        for k in o.start - 3..o.start + o.frames + 3 {
            let shown = noise.occluder(k, &world);
            assert_eq!(shown.is_some(), (o.start..o.start + o.frames).contains(&k), "frame {k}");
            let Some(r) = shown else { continue };
            centres.push((r.x0 + r.x1) as f64 / 2.0);
            // Salt and pepper aside, nothing is left under the box.
            let mut mask = truth.clone();
            noise.apply(k, &world, &mut mask);
            let under = (r.y0..r.y1).flat_map(|y| (r.x0..r.x1).map(move |x| (x, y)));
            let (area, left) = under.fold((0, 0), |(a, l), (x, y)| (a + 1, l + usize::from(mask.get(x, y))));
            assert!(left as f64 <= 0.05 * area as f64 + 3.0, "frame {k}: {left} of {area}");
        }
        // It sweeps steadily from one side of the pelvis to the other.
        let sign = if o.rightwards { 1.0 } else { -1.0 };
        assert!(centres.windows(2).all(|w| sign * (w[1] - w[0]) > 0.0), "{centres:?}");
        assert!(sign * (centres[0] - pu) < 0.0 && sign * (centres[centres.len() - 1] - pu) > 0.0, "{centres:?}");
    }

    #[test]
    fn sensor_noise_has_the_level_s_spread_and_none_leaves_the_pixels() {
        let camera = Camera::preset(Preset::Front, 160, 120).unwrap();
        let noise = Noise::new(Level::Medium, 9, &camera, 10, 15.0);
        let mut rgb = vec![128u8; 160 * 120 * 3];
        noise.sensor(4, &mut rgb);
        let n = rgb.len() as f64;
        let mean = rgb.iter().map(|&c| f64::from(c)).sum::<f64>() / n;
        let sd = (rgb.iter().map(|&c| (f64::from(c) - mean).powi(2)).sum::<f64>() / n).sqrt();
        assert!((mean - 128.0).abs() < 0.2 && (sd - 3.5).abs() < 0.2, "mean {mean}, sd {sd}");
        let mut again = vec![128u8; 160 * 120 * 3];
        noise.sensor(5, &mut again);
        assert_ne!(rgb, again);
        let mut clean = vec![128u8; 30];
        Noise::new(Level::None, 9, &camera, 10, 15.0).sensor(4, &mut clean);
        assert!(clean.iter().all(|&c| c == 128));
    }

    #[test]
    fn edges_grow_and_shrink_by_a_pixel_a_step_but_not_from_the_frame_s_border() {
        // A 3 × 3 square in a 7 × 7 frame, and a bar along the top border.
        let square = Mask::from_fn(7, 7, |x, y| (2..5).contains(&x) && (2..5).contains(&y));
        let mut grown = vec![0; 49];
        step(square.pixels(), &mut grown, 7, |a, b| a | b);
        assert_eq!(grown.iter().filter(|&&p| p == 1).count(), 9 + 4 * 3);
        let mut shrunk = vec![0; 49];
        step(square.pixels(), &mut shrunk, 7, |a, b| a & b);
        assert_eq!(shrunk.iter().filter(|&&p| p == 1).count(), 1);
        let bar = Mask::from_fn(7, 7, |_, y| y < 2);
        step(bar.pixels(), &mut shrunk, 7, |a, b| a & b);
        assert_eq!(&shrunk[..7], &[1; 7]);
        assert!(shrunk[7..].iter().all(|&p| p == 0));
    }
}
