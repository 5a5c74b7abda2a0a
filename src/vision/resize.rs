//! Frames reduced to the working size the silhouettes and the likelihood
//! are computed at (`track --work-size`), whatever the video's size.
//!
//! A pixel of the reduced frame is the area-weighted mean of the source
//! pixels it covers (pixel `i` spans `[i, i + 1)`, so a point at `u` in the
//! source is at `u · width' / width` in the reduced frame), which keeps thin
//! limbs as partial pixels instead of dropping them as point sampling would.

use crate::vision::frames::{Frame, FrameKind};
use crate::vision::mask::Mask;

/// The working width when none is given: a person filling a third of the
/// frame's height is then about 80 pixels tall, their forearms a few
/// pixels wide (at 160 they are one or two, and light noise erodes them).
pub const DEFAULT_WORK_WIDTH: usize = 320;

/// The size a `width × height` frame is reduced to for a working width of
/// `work_width`: the same aspect, the height rounded; a frame no wider than
/// `work_width` keeps its size.
pub fn work_size(width: usize, height: usize, work_width: usize) -> (usize, usize) {
    if width <= work_width || work_width == 0 {
        return (width, height);
    }
    let reduced_height = ((height * work_width) as f64 / width as f64).round().max(1.0) as usize;
    (work_width, reduced_height)
}

/// One axis's resampling: for each output pixel, the source pixels it
/// covers and their weights (in 1/65536ths, summing to 65536).
#[derive(Debug, Clone)]
struct Axis {
    taps: Vec<Vec<(usize, u32)>>,
}

impl Axis {
    fn new(from: usize, to: usize) -> Axis {
        let scale = from as f64 / to as f64;
        let taps = (0..to)
            .map(|i| {
                let (start, end) = (i as f64 * scale, (i + 1) as f64 * scale);
                let covered: Vec<(usize, f64)> = (start.floor() as usize..(end.ceil() as usize).min(from))
                    .map(|s| (s, (end.min(s as f64 + 1.0) - start.max(s as f64)) / scale))
                    .filter(|&(_, w)| w > 0.0)
                    .collect();
                // Integer weights whose sum is exact, the rounding put on the
                // largest so a flat image stays flat.
                let mut weights: Vec<(usize, u32)> =
                    covered.iter().map(|&(s, w)| (s, (w * 65536.0).round() as u32)).collect();
                let total: u32 = weights.iter().map(|w| w.1).sum();
                if let Some(largest) = weights.iter_mut().max_by_key(|w| w.1) {
                    largest.1 = largest.1 + 65536 - total;
                }
                weights
            })
            .collect();
        Axis { taps }
    }
}

/// Reduces frames of one size to another, keeping its weight tables and a
/// scratch buffer between frames.
#[derive(Debug, Clone)]
pub struct Shrinker {
    from: (usize, usize),
    to: (usize, usize),
    columns: Axis,
    rows: Axis,
    /// The frame reduced along rows only, one u32 per channel, in 1/65536ths.
    narrow: Vec<u32>,
}

impl Shrinker {
    /// Reduces `from` (width, height) frames to `to`; neither side may grow.
    pub fn new(from: (usize, usize), to: (usize, usize)) -> Shrinker {
        assert!(to.0 <= from.0 && to.1 <= from.1 && to.0 > 0 && to.1 > 0, "a shrinker only reduces");
        Shrinker { from, to, columns: Axis::new(from.0, to.0), rows: Axis::new(from.1, to.1), narrow: Vec::new() }
    }

    /// The reduced size.
    pub fn size(&self) -> (usize, usize) {
        self.to
    }

    /// `frame` reduced, of its kind: a silhouette frame stays black and
    /// white (a pixel is the person when at least half its area was); a
    /// frame already of the reduced size is returned as it is.
    pub fn shrink(&mut self, frame: Frame) -> Frame {
        if (frame.width(), frame.height()) == self.to {
            return frame;
        }
        assert_eq!((frame.width(), frame.height()), self.from, "frames of one size");
        let ((width, _), (to_width, to_height)) = (self.from, self.to);
        let rgb = frame.rgb();
        // Along each row first (the source row is contiguous), then the rows
        // are combined.
        self.narrow.resize(self.from.1 * to_width * 3, 0);
        for (source, out) in rgb.chunks_exact(3 * width).zip(self.narrow.chunks_exact_mut(3 * to_width)) {
            for (taps, out) in self.columns.taps.iter().zip(out.chunks_exact_mut(3)) {
                let mut sum = [0u32; 3];
                for &(x, w) in taps {
                    for (s, &c) in sum.iter_mut().zip(&source[3 * x..3 * x + 3]) {
                        *s += w * u32::from(c);
                    }
                }
                out.copy_from_slice(&sum);
            }
        }
        let mut reduced = vec![0u8; to_width * to_height * 3];
        for (taps, out) in self.rows.taps.iter().zip(reduced.chunks_exact_mut(3 * to_width)) {
            for (i, o) in out.iter_mut().enumerate() {
                let sum: u64 =
                    taps.iter().map(|&(y, w)| u64::from(w) * u64::from(self.narrow[y * 3 * to_width + i])).sum();
                *o = ((sum + (1 << 31)) >> 32).min(255) as u8;
            }
        }
        if frame.kind() == FrameKind::Silhouette {
            for pixel in reduced.chunks_exact_mut(3) {
                let person = pixel.iter().map(|&c| u16::from(c)).sum::<u16>() >= 3 * 128;
                pixel.fill(if person { 255 } else { 0 });
            }
        }
        Frame::from_rgb(frame.label().to_string(), to_width, to_height, reduced).with_kind(frame.kind())
    }
}

/// `mask` reduced to `to` (width, height): a reduced pixel is set when at
/// least half the area it covers is.
pub fn shrink_mask(mask: &Mask, to: (usize, usize)) -> Mask {
    let (width, height) = (mask.width(), mask.height());
    if (width, height) == to {
        return mask.clone();
    }
    let grey = mask.pixels().iter().flat_map(|&p| [p * 255; 3]).collect();
    let reduced = Shrinker::new((width, height), to).shrink(Frame::from_rgb("a mask", width, height, grey));
    Mask::from_pixels(to.0, to.1, reduced.rgb().chunks_exact(3).map(|c| u8::from(c[0] >= 128)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_working_size_keeps_the_aspect_and_never_enlarges() {
        assert_eq!(work_size(640, 480, 160), (160, 120));
        assert_eq!(work_size(1920, 1080, 320), (320, 180));
        assert_eq!(work_size(160, 120, 320), (160, 120));
        assert_eq!(work_size(641, 480, 320), (320, 240));
    }

    #[test]
    fn a_reduced_mask_keeps_the_pixels_at_least_half_covered() {
        let mask = Mask::from_fn(4, 4, |x, y| x < 2 && y < 3);
        let reduced = shrink_mask(&mask, (2, 2));
        assert_eq!(reduced.pixels(), &[1, 0, 1, 0]);
    }

    #[test]
    fn a_reduced_frame_keeps_its_kind() {
        // A silhouette's edge falls between pixels: it stays black and white.
        let edge: Vec<u8> = (0..6 * 2).flat_map(|i| [if i % 6 < 3 { 255 } else { 0 }; 3]).collect();
        let silhouette = Frame::from_rgb("s", 6, 2, edge);
        let reduced = Shrinker::new((6, 2), (4, 1)).shrink(silhouette);
        assert_eq!(reduced.kind(), FrameKind::Silhouette);
        assert_eq!(reduced.rgb(), &[255, 255, 255, 255, 255, 255, 0, 0, 0, 0, 0, 0]);
        // A color frame that reduces to black and white is still color.
        let color = Frame::from_rgb("c", 2, 1, vec![0, 0, 0, 255, 255, 255]).with_kind(FrameKind::Color);
        assert_eq!(Shrinker::new((2, 1), (1, 1)).shrink(color).kind(), FrameKind::Color);
    }

    #[test]
    fn halving_averages_each_two_by_two_block() {
        let rgb: Vec<u8> = (0..4 * 2).flat_map(|i| [i as u8 * 10, 200, 7]).collect();
        let mut shrinker = Shrinker::new((4, 2), (2, 1));
        let reduced = shrinker.shrink(Frame::from_rgb("t", 4, 2, rgb));
        // Pixels 0, 1, 4, 5 → red (0 + 10 + 40 + 50) / 4 = 25.
        assert_eq!(reduced.rgb(), &[25, 200, 7, 45, 200, 7]);
    }

    #[test]
    fn a_fractional_reduction_keeps_a_flat_frame_flat_and_weighs_by_area() {
        let mut shrinker = Shrinker::new((5, 3), (2, 2));
        let flat = shrinker.shrink(Frame::from_rgb("t", 5, 3, vec![77; 45]));
        assert!(flat.rgb().iter().all(|&c| c == 77));
        // A bright first column covers 1 of the 2.5 source pixels of the
        // first reduced column: 255 · 0.4 = 102.
        let mut rgb = vec![0u8; 45];
        for y in 0..3 {
            rgb[y * 15..y * 15 + 3].copy_from_slice(&[255, 255, 255]);
        }
        let edge = shrinker.shrink(Frame::from_rgb("t", 5, 3, rgb).with_kind(FrameKind::Color));
        assert_eq!(edge.rgb()[0], 102);
        assert_eq!(edge.rgb()[3], 0);
    }
}
