use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::collections::VecDeque;

/// A textured background: stripes and blotches in several colors.
fn background_rgb(width: usize, height: usize) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            let blotch = ((x / 9 + y / 7) % 3) as u8 * 25;
            rgb.push(90 + blotch + (x * 7 % 23) as u8);
            rgb.push(110 + (y * 5 % 31) as u8 + blotch / 2);
            rgb.push(70 + ((x + y) * 3 % 29) as u8);
        }
    }
    rgb
}

/// Whether (x, y) is inside an ellipse of centre (cx, cy) and radii (rx, ry).
fn in_ellipse(x: usize, y: usize, (cx, cy): (f64, f64), (rx, ry): (f64, f64)) -> bool {
    let (dx, dy) = ((x as f64 + 0.5 - cx) / rx, (y as f64 + 0.5 - cy) / ry);
    dx * dx + dy * dy <= 1.0
}

/// A person-like shape centred at `cx`: head, body, arms, legs.
fn person(width: usize, height: usize, cx: f64) -> Mask {
    let (w, h) = (width as f64, height as f64);
    Mask::from_fn(width, height, |x, y| {
        let (fx, fy) = (x as f64 + 0.5, y as f64 + 0.5);
        let head = in_ellipse(x, y, (cx, 0.18 * h), (0.04 * w, 0.06 * h));
        let body = (fx - cx).abs() < 0.06 * w && fy > 0.24 * h && fy < 0.58 * h;
        let arms = (fx - cx).abs() < 0.16 * w && fy > 0.27 * h && fy < 0.33 * h;
        let legs = (fx - cx).abs() > 0.01 * w && (fx - cx).abs() < 0.05 * w && fy >= 0.58 * h && fy < 0.86 * h;
        head || body || arms || legs
    })
}

/// A color frame: `person` in a shirt and dark trousers over the
/// background, a shadow on the ground at its feet, Gaussian noise of
/// `sigma` on every channel.
fn scene(background: &[u8], person: &Mask, cx: f64, sigma: f64, rng: &mut ChaCha8Rng) -> Frame {
    let (width, height) = (person.width(), person.height());
    let (w, h) = (width as f64, height as f64);
    let noise = Normal::new(0.0, sigma).unwrap();
    let mut rgb = background.to_vec();
    for y in 0..height {
        for x in 0..width {
            let p = &mut rgb[3 * (y * width + x)..3 * (y * width + x) + 3];
            if person.get(x, y) {
                let shade = ((x + 2 * y) % 11) as u8;
                let color = if (y as f64) < 0.58 * h { [200, 60 + shade, 50] } else { [30, 35, 70 + shade] };
                p.copy_from_slice(&color);
            } else if in_ellipse(x, y, (cx + 0.08 * w, 0.86 * h), (0.16 * w, 0.04 * h)) {
                for c in p.iter_mut() {
                    *c = (f64::from(*c) * 0.6).round() as u8;
                }
            }
            for c in p.iter_mut() {
                *c = (f64::from(*c) + noise.sample(rng)).round().clamp(0.0, 255.0) as u8;
            }
        }
    }
    Frame::from_rgb(format!("scene at {cx}"), width, height, rgb)
}

#[test]
fn a_silhouette_frame_is_thresholded_at_128() {
    let mut out = vec![9; 6];
    threshold_into(&[0, 0, 0, 127, 127, 127, 128, 128, 128, 127, 128, 129, 255, 255, 255, 32, 32, 32], &mut out);
    assert_eq!(out, [0, 0, 1, 1, 1, 0]);

    let rgb = [0, 0, 0, 32, 32, 32, 224, 224, 224, 255, 255, 255, 0, 32, 0, 240, 224, 255];
    let frame = Frame::from_rgb("silhouette", 3, 2, rgb.to_vec());
    assert_eq!(frame.kind(), FrameKind::Silhouette);
    // No background is needed for a silhouette.
    let mask = Extractor::new(ExtractParams::default()).unwrap().extract(&frame).unwrap();
    assert_eq!(mask.pixels(), &[0, 0, 1, 1, 0, 1]);
}

#[test]
fn background_subtraction_recovers_a_person_through_noise_and_shadow() {
    let (width, height) = (160, 120);
    let background = background_rgb(width, height);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let truth = person(width, height, 70.0);
    let frame = scene(&background, &truth, 70.0, 6.0, &mut rng);
    let mut extractor = Extractor::new(ExtractParams::default()).unwrap();
    extractor.set_background(&Frame::from_rgb("background", width, height, background.clone()));
    let mask = extractor.extract(&frame).unwrap();
    let score = mask.iou(&truth);
    assert!(score > 0.97, "IoU {score}");

    // Without shadow suppression the shadow joins the silhouette.
    let mut plain = Extractor::new(ExtractParams::default().shadow_chroma(0)).unwrap();
    plain.set_background(&Frame::from_rgb("background", width, height, background));
    let score = plain.extract(&frame).unwrap().iou(&truth);
    assert!(score < 0.9, "IoU without shadow suppression {score}");
}

#[test]
fn a_background_learned_from_the_frames_hides_a_moving_person() {
    let (width, height) = (160, 120);
    let background = background_rgb(width, height);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let frames: Vec<_> = (0..9)
        .map(|i| {
            let cx = 20.0 + 15.0 * i as f64;
            scene(&background, &person(width, height, cx), cx, 4.0, &mut rng)
        })
        .collect();
    let learned = learn_background(&frames);
    let off = learned.frame.rgb().iter().zip(&background).filter(|&(&m, &b)| m.abs_diff(b) > 12).count();
    assert!(off < width * height * 3 / 200, "{off} channels far from the background");

    let mut extractor = Extractor::new(learned_params(&learned)).unwrap();
    extractor.set_background(&learned.frame);
    for (i, frame) in frames.iter().enumerate() {
        let truth = person(width, height, 20.0 + 15.0 * i as f64);
        let score = extractor.extract(frame).unwrap().iou(&truth);
        assert!(score > 0.95, "frame {i}: IoU {score}");
    }
}

#[test]
fn a_frame_of_another_size_than_the_background_is_an_error() {
    let mut extractor = Extractor::new(ExtractParams::default()).unwrap();
    let frame = Frame::from_rgb("frame 7", 8, 6, background_rgb(8, 6));
    let message = extractor.extract(&frame).unwrap_err().to_string();
    assert_eq!(message, "frame 7: a color frame, and no background to subtract was given");
    extractor.set_background(&Frame::from_rgb("background", 8, 5, background_rgb(8, 5)));
    let message = extractor.extract(&frame).unwrap_err().to_string();
    assert_eq!(message, "frame 7: the frame is 8×6; the background is 8×5");
}

#[test]
fn settings_out_of_range_are_refused() {
    let new = |p: ExtractParams| Extractor::new(p).map(|_| ()).unwrap_err();
    let p = ExtractParams::default();
    assert_eq!(new(p.threshold(0)), ExtractParamsError::Threshold(0));
    assert_eq!(new(p.threshold(765)), ExtractParamsError::Threshold(765));
    assert_eq!(new(p.shadow_ratio(0.0, 0.9)), ExtractParamsError::ShadowRatio { low: 0.0, high: 0.9 });
    assert_eq!(new(p.shadow_ratio(0.8, 0.7)), ExtractParamsError::ShadowRatio { low: 0.8, high: 0.7 });
    assert_eq!(new(p.shadow_ratio(0.5, 1.0)), ExtractParamsError::ShadowRatio { low: 0.5, high: 1.0 });
    assert_eq!(new(p.shadow_chroma(766)), ExtractParamsError::ShadowChroma(766));
    assert_eq!(new(p.median_radius(8)), ExtractParamsError::MedianRadius(8));
    assert_eq!(new(p.min_blob(1.0)), ExtractParamsError::MinBlob(1.0));
    assert!(matches!(new(p.max_hole(f64::NAN)), ExtractParamsError::MaxHole(_)));
    assert!(Extractor::new(p.median_radius(7).min_blob(0.0).max_hole(0.0).shadow_chroma(0)).is_ok());
}

/// Random binary masks of many shapes and densities.
fn random_masks(seed: u64) -> Vec<(usize, usize, Vec<u8>)> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..300)
        .map(|_| {
            let (width, height) = (rng.gen_range(1..40), rng.gen_range(1..30));
            let density = rng.gen_range(0.05..0.95);
            (width, height, (0..width * height).map(|_| u8::from(rng.gen_bool(density))).collect())
        })
        .collect()
}

fn median_reference(input: &[u8], width: usize, height: usize, radius: usize) -> Vec<u8> {
    let r = radius as isize;
    let clamp = |v: isize, n: usize| v.clamp(0, n as isize - 1) as usize;
    let mut out = vec![0; width * height];
    for y in 0..height {
        for x in 0..width {
            let mut count = 0;
            for dy in -r..=r {
                for dx in -r..=r {
                    count += usize::from(input[clamp(y as isize + dy, height) * width + clamp(x as isize + dx, width)]);
                }
            }
            out[y * width + x] = u8::from(2 * count > (2 * radius + 1).pow(2));
        }
    }
    out
}

#[test]
fn the_median_filter_matches_a_brute_force_count() {
    let mut scratch = MedianScratch::default();
    for (i, (width, height, input)) in random_masks(1).into_iter().enumerate() {
        let radius = i % (MAX_MEDIAN_RADIUS + 1);
        let mut out = vec![7; width * height];
        scratch.filter(&input, width, height, radius, &mut out);
        assert_eq!(out, median_reference(&input, width, height, radius), "{width}×{height}, radius {radius}");
    }
    // A lone pixel goes, a lone gap is filled, a straight edge stays.
    let input = Mask::from_fn(7, 5, |x, y| (x >= 3 && !(x == 5 && y == 2)) || (x == 1 && y == 2));
    let mut out = vec![0; 35];
    scratch.filter(input.pixels(), 7, 5, 1, &mut out);
    assert_eq!(out, Mask::from_fn(7, 5, |x, _| x >= 3).pixels());
}

/// The components of `value` by flood fill: (pixel indices, touches the edge).
fn components_reference(pixels: &[u8], width: usize, height: usize, value: u8, eight: bool) -> Vec<(Vec<usize>, bool)> {
    let mut seen = vec![false; pixels.len()];
    let mut components = Vec::new();
    for start in 0..pixels.len() {
        if seen[start] || pixels[start] != value {
            continue;
        }
        seen[start] = true;
        let (mut members, mut edge, mut queue) = (Vec::new(), false, VecDeque::from([start]));
        while let Some(i) = queue.pop_front() {
            members.push(i);
            let (x, y) = ((i % width) as isize, (i / width) as isize);
            edge |= x == 0 || y == 0 || x == width as isize - 1 || y == height as isize - 1;
            for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                let (nx, ny) = (x + dx, y + dy);
                let diagonal = dx != 0 && dy != 0;
                if (diagonal && !eight) || nx < 0 || ny < 0 || nx >= width as isize || ny >= height as isize {
                    continue;
                }
                let j = ny as usize * width + nx as usize;
                if !seen[j] && pixels[j] == value {
                    seen[j] = true;
                    queue.push_back(j);
                }
            }
        }
        components.push((members, edge));
    }
    components
}

#[test]
fn blob_removal_and_hole_filling_match_a_flood_fill() {
    let mut components = Components::default();
    for (i, (width, height, input)) in random_masks(2).into_iter().enumerate() {
        let min_area = 1 + (i % 9) as u32;
        let mut expected = input.clone();
        for (members, _) in components_reference(&input, width, height, 1, true) {
            if members.len() < min_area as usize {
                members.iter().for_each(|&j| expected[j] = 0);
            }
        }
        let mut out = input.clone();
        components.remove_small(&mut out, width, height, 1, min_area);
        assert_eq!(out, expected, "{width}×{height}, blobs under {min_area} removed");

        let max_hole = (i % 7) as u32;
        for (members, edge) in components_reference(&out, width, height, 0, false) {
            if !edge && members.len() <= max_hole as usize {
                members.iter().for_each(|&j| expected[j] = 1);
            }
        }
        components.fill_holes(&mut out, width, height, max_hole);
        assert_eq!(out, expected, "{width}×{height}, holes up to {max_hole} filled");
    }
}

#[test]
fn blobs_touching_at_a_corner_are_one_and_holes_open_at_a_corner_are_not() {
    // Two 2×2 squares meeting at a corner make one blob of 8 pixels.
    let squares = Mask::from_fn(6, 6, |x, y| {
        (1..3).contains(&x) && (1..3).contains(&y) || (3..5).contains(&x) && (3..5).contains(&y)
    });
    let mut pixels = squares.pixels().to_vec();
    Components::default().remove_small(&mut pixels, 6, 6, 1, 8);
    assert_eq!(pixels, squares.pixels());
    Components::default().remove_small(&mut pixels, 6, 6, 1, 9);
    assert!(pixels.iter().all(|&p| p == 0));
    // A ring with a one-pixel hole is closed; a ring broken at the edge is not.
    let ring = Mask::from_fn(5, 5, |x, y| (1..4).contains(&x) && (1..4).contains(&y) && (x, y) != (2, 2));
    let mut pixels = ring.pixels().to_vec();
    Components::default().fill_holes(&mut pixels, 5, 5, 1);
    assert_eq!(pixels, Mask::from_fn(5, 5, |x, y| (1..4).contains(&x) && (1..4).contains(&y)).pixels());
    let open = Mask::from_fn(3, 3, |x, y| (x, y) != (1, 1) && (x, y) != (1, 0));
    let mut pixels = open.pixels().to_vec();
    Components::default().fill_holes(&mut pixels, 3, 3, 5);
    assert_eq!(pixels, open.pixels());
}

#[test]
fn extracting_again_reuses_the_buffers() {
    let (width, height) = (64, 48);
    let background = background_rgb(width, height);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut extractor = Extractor::new(ExtractParams::default()).unwrap();
    extractor.set_background(&Frame::from_rgb("background", width, height, background.clone()));
    let mut out = Mask::new(width, height);
    let frames: Vec<_> = [20.0, 30.0, 40.0]
        .iter()
        .map(|&cx| scene(&background, &person(width, height, cx), cx, 3.0, &mut rng))
        .collect();
    extractor.extract_into(&frames[0], &mut out).unwrap();
    let buffers = |e: &Extractor, out: &Mask| {
        (e.raw.as_ptr(), e.median.columns.as_ptr(), e.components.runs.as_ptr(), out.pixels().as_ptr())
    };
    let before = buffers(&extractor, &out);
    for frame in &frames {
        extractor.extract_into(frame, &mut out).unwrap();
        assert_eq!(buffers(&extractor, &out), before);
        assert_eq!(out, extractor.extract(frame).unwrap());
    }
}

#[test]
fn find_locates_the_next_pixel_of_a_value() {
    let row: Vec<u8> = (0..37).map(|i| u8::from(i == 0 || i == 20 || i == 36)).collect();
    assert_eq!((find(&row, 0, 1), find(&row, 1, 1), find(&row, 21, 1), find(&row, 37, 1)), (0, 20, 36, 37));
    assert_eq!((find(&row, 0, 0), find(&row, 20, 0)), (1, 21));
    assert_eq!(find(&[1; 17], 0, 0), 17);
}
