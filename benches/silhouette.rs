//! Speed of silhouette extraction from a color frame, on one core: background
//! subtraction with shadow suppression, the 3×3 median filter, the removal of
//! small blobs and the filling of small holes, as `Extractor::extract_into`
//! runs them on every frame (`extract/<size>`); and the threshold of a
//! silhouette frame (`threshold/<size>`).
//!
//! The frame is synthetic and deterministic: a person-like shape in a shirt
//! and dark trousers over a textured background, a shadow at its feet, and
//! noise on every channel. Criterion reports the numbers; nothing here
//! asserts a wall-clock time.
//!
//!     cargo bench --bench silhouette

use criterion::{Criterion, criterion_group, criterion_main};
use imitate::vision::frames::Frame;
use imitate::vision::mask::Mask;
use imitate::vision::silhouette::{ExtractParams, Extractor};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

const SIZES: [(usize, usize); 3] = [(160, 120), (320, 240), (640, 480)];

/// The background and a frame of the scene at `width × height`.
fn scene(width: usize, height: usize) -> (Frame, Frame) {
    let mut background = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            let blotch = ((x * 160 / width / 9 + y * 120 / height / 7) % 3) as u8 * 25;
            background.extend([
                90 + blotch + (x * 7 % 23) as u8,
                110 + (y * 5 % 31) as u8,
                70 + ((x + y) * 3 % 29) as u8,
            ]);
        }
    }
    let (w, h) = (width as f64, height as f64);
    let inside = |x: f64, y: f64, (cx, cy): (f64, f64), (rx, ry): (f64, f64)| {
        ((x - cx) / rx).powi(2) + ((y - cy) / ry).powi(2) <= 1.0
    };
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut rgb = background.clone();
    for y in 0..height {
        for x in 0..width {
            let (fx, fy) = ((x as f64 + 0.5) / w, (y as f64 + 0.5) / h);
            let dx = (fx - 0.45).abs();
            let head = inside(fx, fy, (0.45, 0.18), (0.04, 0.06));
            let body = dx < 0.06 && (0.24..0.58).contains(&fy);
            let arms = dx < 0.16 && (0.27..0.33).contains(&fy);
            let legs = (0.01..0.05).contains(&dx) && (0.58..0.86).contains(&fy);
            let p = &mut rgb[3 * (y * width + x)..3 * (y * width + x) + 3];
            if head || body || arms {
                p.copy_from_slice(&[200, 60 + (x % 11) as u8, 50]);
            } else if legs {
                p.copy_from_slice(&[30, 35, 70 + (y % 11) as u8]);
            } else if inside(fx, fy, (0.53, 0.86), (0.16, 0.04)) {
                p.iter_mut().for_each(|c| *c = (u16::from(*c) * 3 / 5) as u8);
            }
            for c in p.iter_mut() {
                *c = (i16::from(*c) + rng.gen_range(-8..=8)).clamp(0, 255) as u8;
            }
        }
    }
    (Frame::from_rgb("background", width, height, background), Frame::from_rgb("frame", width, height, rgb))
}

fn silhouette(c: &mut Criterion) {
    for (width, height) in SIZES {
        let size = format!("{width}x{height}");
        let (background, frame) = scene(width, height);
        let mut extractor = Extractor::new(ExtractParams::default()).expect("the defaults are valid");
        extractor.set_background(&background);
        let mut mask = Mask::new(width, height);
        c.bench_function(&format!("extract/{size}"), |b| {
            b.iter(|| extractor.extract_into(black_box(&frame), &mut mask).expect("sizes match"))
        });
        let silhouette =
            Frame::from_rgb("silhouette", width, height, mask.pixels().iter().flat_map(|&p| [p * 255; 3]).collect());
        c.bench_function(&format!("threshold/{size}"), |b| {
            b.iter(|| extractor.extract_into(black_box(&silhouette), &mut mask).expect("sizes match"))
        });
    }
}

criterion_group!(benches, silhouette);
criterion_main!(benches);
