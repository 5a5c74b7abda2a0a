//! Binary images: an observed silhouette, or a body drawn by the renderer.

/// A binary image, row-major from the top-left pixel: which pixels belong to
/// the person (or to the body drawn). Each pixel is one byte, 0 or 1, so
/// rows can be scanned and summed without unpacking bits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mask {
    width: usize,
    height: usize,
    pixels: Vec<u8>,
}

impl Mask {
    /// An empty mask (no pixel set).
    pub fn new(width: usize, height: usize) -> Mask {
        Mask { width, height, pixels: vec![0; width * height] }
    }

    /// A mask whose pixel (x, y) is `inside(x, y)`.
    pub fn from_fn(width: usize, height: usize, inside: impl Fn(usize, usize) -> bool) -> Mask {
        let pixels = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| u8::from(inside(x, y)));
        Mask { width, height, pixels: pixels.collect() }
    }

    /// A mask over `pixels`, row-major from the top-left, each 0 or 1.
    ///
    /// # Panics
    /// If `pixels` does not hold `width × height` bytes, or holds a value
    /// other than 0 or 1: either is a bug in the caller.
    pub fn from_pixels(width: usize, height: usize, pixels: Vec<u8>) -> Mask {
        assert_eq!(pixels.len(), width * height, "a {width}×{height} mask needs {} pixels", width * height);
        assert!(pixels.iter().all(|&p| p <= 1), "mask pixels are 0 or 1");
        Mask { width, height, pixels }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    pub fn get(&self, x: usize, y: usize) -> bool {
        self.pixels[y * self.width + x] != 0
    }

    pub fn set(&mut self, x: usize, y: usize, inside: bool) {
        self.pixels[y * self.width + x] = u8::from(inside);
    }

    /// Every pixel, row-major, 0 or 1.
    pub fn pixels(&self) -> &[u8] {
        &self.pixels
    }

    /// Every pixel, row-major, for writing in place. Writers keep each
    /// value 0 or 1, as every reader of a mask assumes.
    pub fn pixels_mut(&mut self) -> &mut [u8] {
        &mut self.pixels
    }

    /// Sets every pixel of row `y` from `x0` to `x1` (exclusive) inside.
    pub fn fill_span(&mut self, y: usize, x0: usize, x1: usize) {
        let row = y * self.width;
        self.pixels[row + x0..row + x1].fill(1);
    }

    /// Clears every pixel, keeping the size (and the allocation).
    pub fn clear(&mut self) {
        self.pixels.fill(0);
    }

    /// How many pixels are set.
    pub fn count(&self) -> usize {
        self.pixels.iter().map(|&p| p as usize).sum()
    }

    /// How many pixels are set in both masks, and in either (masks of one
    /// size).
    pub fn overlap(&self, other: &Mask) -> (usize, usize) {
        debug_assert_eq!((self.width, self.height), (other.width, other.height), "masks of one size");
        self.pixels
            .iter()
            .zip(&other.pixels)
            .fold((0, 0), |(both, either), (&p, &q)| (both + usize::from(p & q), either + usize::from(p | q)))
    }

    /// Intersection over union with `other` (1 when both are empty).
    pub fn iou(&self, other: &Mask) -> f64 {
        let (both, either) = self.overlap(other);
        if either == 0 { 1.0 } else { both as f64 / either as f64 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_are_row_major_from_the_top_left() {
        let mut m = Mask::from_fn(4, 3, |x, y| x == 3 && y == 0);
        assert_eq!(m.pixels(), &[0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0]);
        m.fill_span(2, 1, 3);
        assert!(m.get(1, 2) && m.get(2, 2) && !m.get(3, 2) && !m.get(0, 2));
        assert_eq!(m.count(), 3);
        m.clear();
        assert_eq!((m.count(), m.width(), m.height()), (0, 4, 3));
    }

    #[test]
    fn iou_counts_shared_over_either() {
        let a = Mask::from_fn(4, 1, |x, _| x < 2);
        let b = Mask::from_fn(4, 1, |x, _| (1..4).contains(&x));
        assert_eq!(a.overlap(&b), (1, 4));
        assert_eq!(a.iou(&b), 0.25);
        assert_eq!(Mask::new(3, 3).iou(&Mask::new(3, 3)), 1.0);
    }
}
