use super::*;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The squared distance from (x, y) to the nearest set pixel, by trying
/// them all; `None` for an empty mask.
fn nearest_by_brute_force(mask: &Mask, x: usize, y: usize) -> Option<u32> {
    let (w, h) = (mask.width(), mask.height());
    (0..h)
        .flat_map(|by| (0..w).map(move |bx| (bx, by)))
        .filter(|&(bx, by)| mask.get(bx, by))
        .map(|(bx, by)| (bx.abs_diff(x).pow(2) + by.abs_diff(y).pow(2)) as u32)
        .min()
}

fn field_by_brute_force(mask: &Mask) -> Vec<u32> {
    let absent = (mask.width().pow(2) + mask.height().pow(2)) as u32;
    (0..mask.height())
        .flat_map(|y| (0..mask.width()).map(move |x| (x, y)))
        .map(|(x, y)| nearest_by_brute_force(mask, x, y).unwrap_or(absent))
        .collect()
}

fn cost_by_brute_force(a: &Mask, b: &Mask) -> u64 {
    let b_field = field_by_brute_force(b);
    (0..a.height())
        .flat_map(|y| (0..a.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| a.get(x, y))
        .map(|(x, y)| u64::from(b_field[y * a.width() + x]))
        .sum()
}

/// A w × h mask with each pixel set with probability `density`.
fn random_mask(rng: &mut ChaCha8Rng, width: usize, height: usize, density: f64) -> Mask {
    let mut mask = Mask::new(width, height);
    for y in 0..height {
        for x in 0..width {
            mask.set(x, y, rng.gen_bool(density));
        }
    }
    mask
}

/// Masks up to 24 × 24 (1 × 1, 1 × n and n × 1 included), anywhere from
/// empty through a lone pixel to full.
fn masks() -> impl Strategy<Value = Mask> {
    let density = prop_oneof![Just(0u32), Just(100), 0u32..=5, 0u32..=100];
    (1usize..=24, 1usize..=24, density).prop_flat_map(|(w, h, density)| {
        proptest::collection::vec(0u32..100, w * h).prop_map(move |draws| {
            let mut mask = Mask::new(w, h);
            for (i, draw) in draws.into_iter().enumerate() {
                mask.set(i % w, i / w, draw < density);
            }
            mask
        })
    })
}

/// Runs `test` on cases from `strategy` with a fixed seed, so a failure
/// reproduces.
fn check<S: Strategy>(strategy: S, test: impl Fn(S::Value) -> Result<(), TestCaseError>) {
    let config = Config { cases: 512, failure_persistence: None, ..Config::default() };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[7; 32]);
    if let Err(e) = TestRunner::new_with_rng(config, rng).run(&strategy, test) {
        panic!("{e}");
    }
}

#[test]
fn transform_matches_brute_force_on_every_mask_of_at_most_16_pixels() {
    let mut field = DistanceField::new();
    for (w, h) in (1..=16).flat_map(|w| (1..=16 / w).map(move |h| (w, h))) {
        for bits in 0u32..1 << (w * h) {
            let mask = Mask::from_fn(w, h, |x, y| bits >> (y * w + x) & 1 != 0);
            field.compute_into(&mask);
            assert_eq!(field.values(), field_by_brute_force(&mask), "{w} × {h}, bits {bits:b}");
        }
    }
}

#[test]
fn transform_matches_brute_force_on_random_masks() {
    check(masks(), |mask| {
        let field = DistanceField::of(&mask);
        prop_assert_eq!((field.width(), field.height()), (mask.width(), mask.height()));
        prop_assert_eq!(field.values(), field_by_brute_force(&mask));
        Ok(())
    });
}

#[test]
fn transform_matches_brute_force_on_sparse_masks_up_to_80_by_60() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut field = DistanceField::new();
    for _ in 0..40 {
        let (w, h) = (rng.gen_range(1..=80), rng.gen_range(1..=60));
        let pixels = rng.gen_range(1..=4);
        let mut mask = Mask::new(w, h);
        for _ in 0..pixels {
            mask.set(rng.gen_range(0..w), rng.gen_range(0..h), true);
        }
        field.compute_into(&mask);
        assert_eq!(field.values(), field_by_brute_force(&mask), "{w} × {h}");
    }
}

#[test]
fn reused_field_matches_a_fresh_one_across_sizes() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut reused = DistanceField::new();
    for &(w, h) in &[(30, 20), (1, 1), (50, 3), (0, 4), (3, 50), (30, 20)] {
        let mask = random_mask(&mut rng, w, h, 0.1);
        reused.compute_into(&mask);
        let fresh = DistanceField::of(&mask);
        assert_eq!((reused.width(), reused.height()), (w, h));
        assert_eq!(reused.values(), fresh.values());
    }
}

#[test]
fn lone_pixel_field_is_squared_distance_from_it() {
    let field = DistanceField::of(&Mask::from_fn(5, 1, |x, _| x == 0));
    assert_eq!(field.values(), &[0, 1, 4, 9, 16]);
    let field = DistanceField::of(&Mask::from_fn(3, 3, |x, y| (x, y) == (1, 1)));
    assert_eq!(field.values(), &[2, 1, 2, 1, 0, 1, 2, 1, 2]);
    assert_eq!(DistanceField::of(&Mask::from_fn(7, 9, |x, y| (x, y) == (6, 8))).get(0, 0), 36 + 64);
}

#[test]
fn full_mask_field_is_zero_everywhere() {
    for (w, h) in [(1, 1), (1, 9), (9, 1), (16, 12)] {
        assert!(DistanceField::of(&Mask::from_fn(w, h, |_, _| true)).values().iter().all(|&d| d == 0));
    }
}

#[test]
fn empty_mask_field_is_squared_image_diagonal_beyond_every_real_distance() {
    for (w, h) in [(1, 1), (1, 9), (9, 1), (16, 12)] {
        let field = DistanceField::of(&Mask::new(w, h));
        let absent = (w * w + h * h) as u32;
        assert!(field.values().iter().all(|&d| d == absent));
        let farthest = ((w - 1).pow(2) + (h - 1).pow(2)) as u32;
        assert!(absent > farthest);
    }
}

#[test]
fn zero_sized_mask_has_an_empty_field_and_zero_cost() {
    for (w, h) in [(0, 0), (0, 5), (5, 0)] {
        let mask = Mask::new(w, h);
        let field = DistanceField::of(&mask);
        assert!(field.values().is_empty());
        assert_eq!(directed_cost(&mask, &field), 0);
        assert_eq!(Observation::new(mask.clone()).likelihood(&mask, &mut Scratch::default()), 1.0 / EPSILON);
    }
}

#[test]
fn directed_cost_matches_brute_force_on_random_pairs() {
    check(mask_pairs(), |(a, b)| {
        prop_assert_eq!(directed_cost(&a, &DistanceField::of(&b)), cost_by_brute_force(&a, &b));
        prop_assert_eq!(directed_cost(&b, &DistanceField::of(&a)), cost_by_brute_force(&b, &a));
        Ok(())
    });
}

/// Pairs of masks of one size, B drawn independently of A.
fn mask_pairs() -> impl Strategy<Value = (Mask, Mask)> {
    masks().prop_flat_map(|a| {
        let (w, h) = (a.width(), a.height());
        (Just(a), proptest::collection::vec(0u32..100, w * h), prop_oneof![Just(0u32), 0u32..=5, 0u32..=100]).prop_map(
            move |(a, draws, density)| {
                let b = Mask::from_fn(w, h, |x, y| draws[y * w + x] < density);
                (a, b)
            },
        )
    })
}

#[test]
fn observation_costs_match_brute_force_on_random_pairs() {
    check(mask_pairs(), |(a, b)| {
        let costs = Observation::new(b.clone()).costs(&a, &mut Scratch::default());
        prop_assert_eq!(costs, (cost_by_brute_force(&a, &b), cost_by_brute_force(&b, &a)));
        Ok(())
    });
}

/// The hypothesis side works inside A's bounding box: B's pixels above,
/// below and beside it, and boxes touching every edge, at frame sizes.
#[test]
fn observation_costs_match_brute_force_for_blobs_anywhere_in_a_frame() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let mut scratch = Scratch::default();
    let blob = |rng: &mut ChaCha8Rng, w: usize, h: usize| {
        let (cx, cy) = (rng.gen_range(-5.0..w as f64 + 5.0), rng.gen_range(-5.0..h as f64 + 5.0));
        let (rx, ry) = (rng.gen_range(0.5..w as f64 / 3.0), rng.gen_range(0.5..h as f64 / 3.0));
        Mask::from_fn(w, h, move |x, y| ((x as f64 - cx) / rx).powi(2) + ((y as f64 - cy) / ry).powi(2) <= 1.0)
    };
    for _ in 0..60 {
        let (w, h) = (rng.gen_range(1..=96), rng.gen_range(1..=72));
        let (a, b) = (blob(&mut rng, w, h), blob(&mut rng, w, h));
        let costs = Observation::new(b.clone()).costs(&a, &mut scratch);
        assert_eq!(costs, (cost_by_brute_force(&a, &b), cost_by_brute_force(&b, &a)), "{w} × {h}");
    }
}

#[test]
fn squares_between_sums_squares_of_either_sign() {
    for lo in -6..=6 {
        for hi in lo..=6 {
            assert_eq!(squares_between(lo, hi), (lo..=hi).map(|t| t * t).sum::<i64>(), "{lo}..={hi}");
        }
    }
}

#[test]
fn likelihood_of_small_cases_matches_hand_computation() {
    let pixel = |w, h, px, py| Mask::from_fn(w, h, move |x, y| (x, y) == (px, py));
    let mut scratch = Scratch::default();
    let likelihood = |a: &Mask, b: &Mask, scratch: &mut Scratch| Observation::new(b.clone()).likelihood(a, scratch);
    // Same lone pixel: both sums are empty of cost.
    assert_eq!(likelihood(&pixel(5, 5, 2, 2), &pixel(5, 5, 2, 2), &mut scratch), 1.0);
    // Pixels 3-4-5 apart: 25 each way.
    assert_eq!(likelihood(&pixel(5, 5, 0, 0), &pixel(5, 5, 3, 4), &mut scratch), 1.0 / 51.0);
    // A = {(0,0), (1,0)}, B = {(0,0)}: r(A, B) = 0 + 1, r(B, A) = 0.
    let pair = Mask::from_fn(5, 5, |x, y| y == 0 && x < 2);
    assert_eq!(likelihood(&pair, &pixel(5, 5, 0, 0), &mut scratch), 1.0 / 2.0);
    // A = row 0 of 3 × 2, B = {(2, 1)}: r(A, B) = 5 + 2 + 1, r(B, A) = 1.
    let row = Mask::from_fn(3, 2, |_, y| y == 0);
    assert_eq!(Observation::new(pixel(3, 2, 2, 1)).costs(&row, &mut scratch), (8, 1));
    assert_eq!(likelihood(&row, &pixel(3, 2, 2, 1), &mut scratch), 1.0 / 10.0);
    // Empty A against B = {(0,0)} in 3 × 2: r(A, B) = 0, r(B, ∅) = 3² + 2².
    assert_eq!(likelihood(&Mask::new(3, 2), &pixel(3, 2, 0, 0), &mut scratch), 1.0 / 14.0);
    // Both empty: A = B.
    assert_eq!(likelihood(&Mask::new(3, 2), &Mask::new(3, 2), &mut scratch), 1.0);
    // A chosen ε takes the place of 1.
    let observation = Observation::with_epsilon(pixel(5, 5, 3, 4), 0.5);
    assert_eq!(observation.likelihood(&pixel(5, 5, 0, 0), &mut scratch), 1.0 / 50.5);
}

#[test]
fn likelihood_is_symmetric_and_finite() {
    check(mask_pairs(), |(a, b)| {
        let mut scratch = Scratch::default();
        let ab = Observation::new(b.clone()).likelihood(&a, &mut scratch);
        let ba = Observation::new(a.clone()).likelihood(&b, &mut scratch);
        prop_assert_eq!(ab, ba);
        prop_assert!(ab.is_finite() && ab > 0.0 && ab <= 1.0 / EPSILON);
        Ok(())
    });
}

#[test]
fn likelihood_is_highest_when_hypothesis_equals_observation() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut scratch = Scratch::default();
    for _ in 0..200 {
        let (w, h) = (rng.gen_range(1..=40), rng.gen_range(1..=30));
        let density = [0.0, 0.02, 0.3, 0.9, 1.0][rng.gen_range(0..5)];
        let observed = random_mask(&mut rng, w, h, density);
        let observation = Observation::new(observed.clone());
        let best = observation.likelihood(&observed, &mut scratch);
        assert_eq!(best, 1.0 / EPSILON);
        for _ in 0..10 {
            // Flip a few pixels, or shift the whole silhouette by one.
            let mut perturbed = observed.clone();
            if rng.gen_bool(0.5) {
                for _ in 0..rng.gen_range(1..=3) {
                    let (x, y) = (rng.gen_range(0..w), rng.gen_range(0..h));
                    perturbed.set(x, y, !perturbed.get(x, y));
                }
            } else {
                let (dx, dy) = [(1, 0), (0, 1), (-1, 0), (0, -1)][rng.gen_range(0..4)];
                perturbed = Mask::from_fn(w, h, |x, y| {
                    let (sx, sy) = (x as isize - dx, y as isize - dy);
                    sx >= 0
                        && sy >= 0
                        && (sx as usize) < w
                        && (sy as usize) < h
                        && observed.get(sx as usize, sy as usize)
                });
            }
            let score = observation.likelihood(&perturbed, &mut scratch);
            if perturbed == observed {
                assert_eq!(score, best);
            } else {
                assert!(score < best, "{w} × {h}: perturbed scores {score}, exact match {best}");
            }
        }
    }
}

#[test]
#[should_panic(expected = "differ in size")]
fn likelihood_rejects_a_hypothesis_of_another_size() {
    Observation::new(Mask::new(4, 3)).likelihood(&Mask::new(3, 4), &mut Scratch::default());
}

#[test]
#[should_panic(expected = "finite and positive")]
fn observation_rejects_zero_epsilon() {
    Observation::with_epsilon(Mask::new(4, 3), 0.0);
}
