//! A clip's background learned from what is not the person, for clips that
//! have no empty frame (the person never leaves, so a per-pixel median of the
//! frames holds them wherever they stand for more than half the clip).
//!
//! 1. Each sampled frame is compared with its own local background: the
//!    median color of a window a fifth of the frame wide, taken on a frame
//!    reduced fourfold. A person a few pixels across is an outlier in it; the
//!    pixels far from it (by the frame's own robust spread), widened by a
//!    margin, are the frame's first guess at the person.
//! 2. Each pixel's background is the median over the frames where it was not
//!    guessed to be the person; a pixel the person covers in (nearly) every
//!    frame takes the median of its local backgrounds instead.
//! 3. The typical difference of a background pixel from the learned
//!    background (compression noise, texture, slow light changes) sets the
//!    thresholds of the difference and shadow tests.

use crate::vision::frames::Frame;
use crate::vision::resize::Shrinker;

/// A background learned from a clip's frames, with its noise.
#[derive(Debug, Clone)]
pub struct LearnedBackground {
    pub frame: Frame,
    /// The median over background pixels of the sum over R, G and B of the
    /// absolute differences from `frame`.
    pub noise: f64,
    /// Whether every sampled pixel is grey (R = G = B): shadows cannot be
    /// told from a darker person by color.
    pub greyscale: bool,
    /// The share of pixels the person covered in every sampled frame.
    pub never_seen: f64,
}

/// How many times the frame's robust spread a pixel must differ from its
/// local background to be the first guess at the person.
const OUTLIER_SPREADS: f64 = 4.0;
/// A pixel needs to be seen free of the person in this many frames for its
/// median over them to be its background.
const MIN_FREE: usize = 3;
/// The local background's window is this fraction of the frame's width.
const LOCAL_WINDOW_SHARE: f64 = 0.2;
/// The reduction the local background is taken at.
const LOCAL_REDUCTION: usize = 4;

/// Learns the background of frames of one size (as
/// [`crate::vision::frames::FrameSource::sample`] gives them). Panics on no
/// frames.
pub fn learn_background(frames: &[Frame]) -> LearnedBackground {
    let (width, height) = (frames[0].width(), frames[0].height());
    let pixels = width * height;
    let small = (width.div_ceil(LOCAL_REDUCTION), height.div_ceil(LOCAL_REDUCTION));
    let mut shrinker = Shrinker::new((width, height), small);
    let locals: Vec<Vec<u8>> = frames.iter().map(|frame| local_background(frame, &mut shrinker)).collect();
    // The first guesses, widened by a margin of about 1% of the width.
    let margin = (width / 100).max(1);
    let guesses: Vec<Vec<bool>> = frames
        .iter()
        .zip(&locals)
        .map(|(frame, local)| {
            let differences: Vec<u32> =
                frame.rgb().chunks_exact(3).zip(local.chunks_exact(3)).map(|(c, b)| sum_abs(c, b)).collect();
            let spread = 1.4826 * f64::from(median_u32(&mut differences.clone())).max(1.0);
            let outliers: Vec<bool> = differences.iter().map(|&d| f64::from(d) > OUTLIER_SPREADS * spread).collect();
            dilate(&outliers, width, height, margin)
        })
        .collect();
    let mut background = vec![0u8; pixels * 3];
    let (mut values, mut never_seen) = (Vec::with_capacity(frames.len()), 0usize);
    let mut sources: Vec<&[u8]> = Vec::with_capacity(frames.len());
    for p in 0..pixels {
        sources.clear();
        sources.extend(frames.iter().zip(&guesses).filter(|(_, guess)| !guess[p]).map(|(f, _)| f.rgb()));
        if sources.len() < MIN_FREE {
            never_seen += usize::from(sources.is_empty());
            sources.clear();
            sources.extend(locals.iter().map(Vec::as_slice));
        }
        for c in 0..3 {
            values.clear();
            values.extend(sources.iter().map(|rgb| rgb[3 * p + c]));
            let middle = values.len() / 2;
            background[3 * p + c] = *values.select_nth_unstable(middle).1;
        }
    }
    let mut noise: Vec<u32> = Vec::new();
    for (frame, guess) in frames.iter().zip(&guesses) {
        let pairs = frame.rgb().chunks_exact(3).zip(background.chunks_exact(3)).zip(guess);
        noise.extend(pairs.filter(|(_, person)| !**person).map(|((c, b), _)| sum_abs(c, b)));
    }
    let noise = if noise.is_empty() { 0.0 } else { f64::from(median_u32(&mut noise)) };
    let greyscale = frames.iter().all(|f| f.rgb().chunks_exact(3).all(|c| c[0] == c[1] && c[1] == c[2]));
    LearnedBackground {
        frame: Frame::from_rgb(
            format!("the background learned from {} frames", frames.len()),
            width,
            height,
            background,
        ),
        noise,
        greyscale,
        never_seen: never_seen as f64 / pixels as f64,
    }
}

fn sum_abs(c: &[u8], b: &[u8]) -> u32 {
    c.iter().zip(b).map(|(&c, &b)| u32::from(c.abs_diff(b))).sum()
}

fn median_u32(values: &mut [u32]) -> u32 {
    let middle = values.len() / 2;
    *values.select_nth_unstable(middle).1
}

/// The frame's local background at full size: each channel's median over a
/// window [`LOCAL_WINDOW_SHARE`] of the width, on the frame reduced by
/// `shrinker` ([`LOCAL_REDUCTION`]-fold), each reduced pixel covering its
/// block.
fn local_background(frame: &Frame, shrinker: &mut Shrinker) -> Vec<u8> {
    let (width, height) = (frame.width(), frame.height());
    let (small_width, small_height) = shrinker.size();
    let small = shrinker.shrink(frame.clone());
    let radius = ((LOCAL_WINDOW_SHARE * small_width as f64) / 2.0).round().max(1.0) as usize;
    let median = median_filter(small.rgb(), small_width, small_height, radius);
    let mut local = vec![0u8; width * height * 3];
    for y in 0..height {
        let sy = (y * small_height / height).min(small_height - 1);
        for x in 0..width {
            let sx = (x * small_width / width).min(small_width - 1);
            local[3 * (y * width + x)..][..3].copy_from_slice(&median[3 * (sy * small_width + sx)..][..3]);
        }
    }
    local
}

/// Each channel's median over a `(2·radius + 1)²` window clipped to the
/// image, by a 256-bin histogram slid along each row.
fn median_filter(rgb: &[u8], width: usize, height: usize, radius: usize) -> Vec<u8> {
    let mut out = vec![0u8; rgb.len()];
    for c in 0..3 {
        for y in 0..height {
            let rows = y.saturating_sub(radius)..(y + radius + 1).min(height);
            let mut histogram = [0u32; 256];
            let mut count = 0u32;
            let column = |x: usize, add: bool, histogram: &mut [u32; 256], count: &mut u32| {
                for yy in rows.clone() {
                    let bin = &mut histogram[usize::from(rgb[3 * (yy * width + x) + c])];
                    if add {
                        *bin += 1;
                        *count += 1;
                    } else {
                        *bin -= 1;
                        *count -= 1;
                    }
                }
            };
            for x in 0..radius.min(width) {
                column(x, true, &mut histogram, &mut count);
            }
            for x in 0..width {
                if x + radius < width {
                    column(x + radius, true, &mut histogram, &mut count);
                }
                if x > radius {
                    column(x - radius - 1, false, &mut histogram, &mut count);
                }
                let (mut seen, half) = (0u32, count / 2);
                let bin = histogram.iter().position(|&n| {
                    seen += n;
                    seen > half
                });
                out[3 * (y * width + x) + c] = bin.unwrap_or(0) as u8;
            }
        }
    }
    out
}

/// `mask` widened by `radius` pixels (a square neighbourhood), by separable
/// running maxima.
fn dilate(mask: &[bool], width: usize, height: usize, radius: usize) -> Vec<bool> {
    let mut rows = vec![false; mask.len()];
    for y in 0..height {
        for x in 0..width {
            let (lo, hi) = (x.saturating_sub(radius), (x + radius + 1).min(width));
            rows[y * width + x] = mask[y * width + lo..y * width + hi].iter().any(|&m| m);
        }
    }
    let mut out = vec![false; mask.len()];
    for y in 0..height {
        let (lo, hi) = (y.saturating_sub(radius), (y + radius + 1).min(height));
        for x in 0..width {
            out[y * width + x] = (lo..hi).any(|yy| rows[yy * width + x]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A textured ground with a dark figure standing at `x0` in every frame
    /// (its torso never leaves) and an arm that moves.
    fn clip(frames: usize) -> (Vec<Frame>, Vec<u8>) {
        let (width, height) = (80, 60);
        let ground: Vec<u8> = (0..width * height)
            .flat_map(|p| {
                let (x, y) = (p % width, p / width);
                let t = ((x * 7 + y * 13) % 11) as u8;
                [150 + t, 130 + t, 110 + t]
            })
            .collect();
        let clip = (0..frames)
            .map(|k| {
                let mut rgb = ground.clone();
                let arm = 15 + k % 20;
                for y in 10..50 {
                    for x in 36..44 {
                        rgb[3 * (y * width + x)..][..3].copy_from_slice(&[30, 30, 60]);
                    }
                }
                for x in 44..56 {
                    rgb[3 * (arm * width + x)..][..3].copy_from_slice(&[30, 30, 60]);
                }
                Frame::from_rgb(format!("frame {k}"), width, height, rgb)
            })
            .collect();
        (clip, ground)
    }

    #[test]
    fn the_background_under_a_person_who_never_leaves_is_the_ground_around_them() {
        let (frames, ground) = clip(30);
        let learned = learn_background(&frames);
        let off = |p: usize| sum_abs(&learned.frame.rgb()[3 * p..3 * p + 3], &ground[3 * p..3 * p + 3]);
        // Under the torso (never seen) the ground's texture cannot be known,
        // only its level: within the texture's range of 10 per channel.
        let under_torso = 30 * 80 + 40;
        assert!(off(under_torso) <= 30, "{}", off(under_torso));
        // Where the arm passes now and then, the ground itself.
        assert_eq!(off(20 * 80 + 50), 0);
        // The plain per-pixel median would hold the figure there.
        assert!(learned.never_seen > 0.02 && learned.never_seen < 0.2, "{}", learned.never_seen);
        assert!(!learned.greyscale);
        assert!(learned.noise < 3.0);
    }

    #[test]
    fn the_sliding_median_matches_a_sorted_window() {
        let (width, height) = (9, 7);
        let rgb: Vec<u8> = (0..width * height * 3).map(|i| ((i * 37 + i / 5) % 251) as u8).collect();
        let filtered = median_filter(&rgb, width, height, 2);
        for (y, x, c) in [(0usize, 0usize, 0usize), (3, 4, 1), (6, 8, 2), (2, 7, 0)] {
            let mut window: Vec<u8> = (y.saturating_sub(2)..(y + 3).min(height))
                .flat_map(|yy| (x.saturating_sub(2)..(x + 3).min(width)).map(move |xx| (yy, xx)))
                .map(|(yy, xx)| rgb[3 * (yy * width + xx) + c])
                .collect();
            window.sort_unstable();
            // The upper middle for an even count.
            assert_eq!(filtered[3 * (y * width + x) + c], window[window.len() / 2], "({y}, {x}, {c})");
        }
    }
}
