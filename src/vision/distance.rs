//! Exact Euclidean distance transforms and the eq. 8–9 likelihood.
//!
//! The likelihood of a hypothesis silhouette A (the body as drawn) given the
//! observed silhouette B is
//!
//! ```text
//! R(A, B) = 1 / (r(A, B) + r(B, A) + ε),   r(A, B) = Σ_{a ∈ A} min_{b ∈ B} ‖a − b‖²
//! ```
//!
//! over pixel centres, in pixels². The inner minimum is read from a squared
//! Euclidean distance transform, so r(A, B) is one pass over A's pixels once
//! B's transform is known. B's transform is built once per frame
//! ([`Observation`]); A's is rebuilt for every hypothesis into a reused
//! [`DistanceField`], which then allocates nothing.
//!
//! The transform is Felzenszwalb and Huttenlocher's ("Distance Transforms of
//! Sampled Functions", 2012): a vertical pass gives every pixel the distance
//! to the nearest set pixel in its column, then each row takes the lower
//! envelope of the parabolas `g(q)² + (x − q)²` rooted at its pixels. Both
//! passes are exact: integer arithmetic throughout, save one float division
//! per parabola whose rounding an integer check settles.

use super::mask::Mask;

/// ε of eq. 8, in pixels². It only keeps R finite when A = B: every r is a
/// whole number of pixels², so any mismatch costs at least 1 and, with ε = 1,
/// a perfect match scores 1 and a one-pixel miss 1/2 rather than a spike that
/// would swamp every other hypothesis.
pub const EPSILON: f64 = 1.0;

/// In the vertical pass: the column holds no set pixel. Real vertical
/// distances stop at h − 1, and a u32 field bounds h by 65 535 (see
/// `absent_distance`), so they never reach it.
const NO_PIXEL: u16 = u16::MAX;

/// The squared Euclidean distance, in pixels², from every pixel centre of a
/// mask to the nearest set pixel's centre, row-major like the mask.
///
/// Values are `u32`: they are exact integers, at most (w − 1)² + (h − 1)²,
/// and half the width of `f64` halves the memory the likelihood streams
/// through; sums over them are taken in `u64`, still exact.
///
/// * A full mask has every distance 0.
/// * An empty mask has no nearest pixel: its distance is infinite, which the
///   field stands in for by w² + h² at every pixel — strictly more than any
///   distance between two pixels of the image, so no real pixel is ever
///   nearer than "none", yet finite, so r(A, ∅) = |A|·(w² + h²) and
///   R(A, ∅) stay finite and still fall as A grows.
///
/// The field also keeps the buffers the transform works in, so
/// [`compute_into`](Self::compute_into) allocates nothing once it has seen a
/// mask of the same size.
#[derive(Clone, Debug, Default)]
pub struct DistanceField {
    width: usize,
    height: usize,
    values: Vec<u32>,
    /// Every pixel's distance to the nearest set pixel in its column, or
    /// `NO_PIXEL`; `u16` so the vertical pass moves 8 lanes per SSE2 op.
    vertical: Vec<u16>,
    /// The columns holding a set pixel, the only ones that root a parabola.
    occupied: Vec<u32>,
    /// One row's lower envelope, left to right, in its first entries.
    envelope: Vec<Parabola>,
}

/// `g² + (x − apex)²`, stored as `lift = g² + apex²` so that comparing two
/// parabolas at x needs only `lift − 2·x·apex` (the x² is common).
#[derive(Clone, Copy, Debug, Default)]
struct Parabola {
    apex: i64,
    lift: i64,
}

impl DistanceField {
    /// An empty (0 × 0) field, to be filled by [`compute_into`](Self::compute_into).
    pub fn new() -> DistanceField {
        DistanceField::default()
    }

    /// The distance field of `mask`.
    pub fn of(mask: &Mask) -> DistanceField {
        let mut field = DistanceField::new();
        field.compute_into(mask);
        field
    }

    /// Overwrites this field with the distance field of `mask`, reusing its
    /// buffers.
    ///
    /// # Panics
    /// If w² + h² does not fit in a `u32` (masks past ~46 000 pixels a side).
    pub fn compute_into(&mut self, mask: &Mask) {
        let (width, height) = (mask.width(), mask.height());
        let absent = absent_distance(width, height);
        self.width = width;
        self.height = height;
        self.values.resize(width * height, 0);
        if width == 0 || height == 0 {
            return;
        }
        self.vertical.resize(width * height, 0);
        self.envelope.resize(width, Parabola::default());
        vertical_pass(&mut self.vertical, mask.pixels().chunks_exact(width), width);
        // After the vertical pass, a column holds a set pixel iff its top
        // value is finite.
        self.occupied.clear();
        self.occupied.extend((0..width as u32).filter(|&q| self.vertical[q as usize] != NO_PIXEL));
        if self.occupied.is_empty() {
            self.values.fill(absent);
            return;
        }
        for (g, d) in self.vertical.chunks_exact(width).zip(self.values.chunks_exact_mut(width)) {
            horizontal_pass(g, &self.occupied, d, &mut self.envelope);
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The squared distance at pixel (x, y).
    pub fn get(&self, x: usize, y: usize) -> u32 {
        assert!(x < self.width, "x = {x} outside a field {} wide", self.width);
        self.values[y * self.width + x]
    }

    /// Every squared distance, row-major.
    pub fn values(&self) -> &[u32] {
        &self.values
    }
}

/// Leaves in `g` (`width` per row) every pixel's distance (not squared) to
/// the nearest set pixel in its column, or `NO_PIXEL`, for the mask rows
/// `pixels` (each `width` long: a whole mask, or a band of one). Both sweeps
/// run a row at a time and branch-free, so the inner loops are contiguous
/// and vectorise.
fn vertical_pass<'a>(g: &mut [u16], pixels: impl Iterator<Item = &'a [u8]>, width: usize) {
    // 0 for a set pixel, all ones (so `&` keeps the other operand) for a clear one.
    let clear = |p: u8| u16::from(p).wrapping_sub(1);
    let mut rows = g.chunks_exact_mut(width).zip(pixels);
    let Some((first, first_pixels)) = rows.next() else { return };
    for (g, &p) in first.iter_mut().zip(first_pixels) {
        *g = clear(p);
    }
    // Down: the nearest set pixel at or above.
    let mut above: &[u16] = first;
    for (row, row_pixels) in rows {
        for ((g, &up), &p) in row.iter_mut().zip(above).zip(row_pixels) {
            *g = up.saturating_add(1) & clear(p);
        }
        above = row;
    }
    // Up: or below, whichever is nearer.
    let mut rows = g.chunks_exact_mut(width).rev();
    let Some(last) = rows.next() else { return };
    let mut below: &[u16] = last;
    for row in rows {
        for (g, &down) in row.iter_mut().zip(below) {
            *g = (*g).min(down.saturating_add(1));
        }
        below = row;
    }
}

/// One row: `d(x) = min_q g(q)² + (x − q)²` over the `occupied` columns q
/// (there is at least one).
fn horizontal_pass(g: &[u16], occupied: &[u32], d: &mut [u32], envelope: &mut [Parabola]) {
    let width = g.len();
    let mut len = 0;
    // Inside a run of set pixels d = 0, and outside it the nearest of the
    // run is one of its ends, so the run's inner columns are left out of the
    // envelope and their zeros written at the end.
    let mut left_out = false;
    for &q in occupied {
        let q = q as usize;
        if g[q] == 0 && q > 0 && q + 1 < width && g[q - 1] == 0 && g[q + 1] == 0 {
            left_out = true;
            continue;
        }
        len = push(envelope, len, Parabola::new(q as i64, i64::from(g[q])));
    }
    // Each parabola is lowest from where it took over up to where the next
    // one does: a division per parabola, then a tight loop per pixel.
    let envelope = &envelope[..len];
    let mut start = 0;
    for (k, p) in envelope.iter().enumerate() {
        let end = envelope.get(k + 1).map_or(width, |next| takes_over(p, next).clamp(0, width as i64) as usize);
        if end > start {
            let (apex, g2) = (p.apex, p.lift - p.apex * p.apex);
            for (x, d) in (start as i64..).zip(&mut d[start..end]) {
                // Exact and below (w − 1)² + (h − 1)², which fits a u32.
                *d = (g2 + (x - apex) * (x - apex)) as u32;
            }
            start = end;
        }
    }
    if left_out {
        for (d, &g) in d.iter_mut().zip(g) {
            *d &= 0u32.wrapping_sub(u32::from(g != 0));
        }
    }
}

impl Parabola {
    fn new(apex: i64, g: i64) -> Parabola {
        Parabola { apex, lift: g * g + apex * apex }
    }
}

/// Adds `next` (right of every parabola so far) to the lower envelope held
/// in `envelope[..len]`, dropping those it hides; returns the new length.
fn push(envelope: &mut [Parabola], mut len: usize, next: Parabola) -> usize {
    // `last` covers no x once `next` undercuts it no later than `last`
    // undercut `before`. The crossing of parabolas a < b is at
    // x = (b.lift − a.lift) / 2(b.apex − a.apex); cross-multiplying the
    // two crossings keeps the test exact and free of division.
    while let [.., before, last] = envelope[..len] {
        let next_crosses = (next.lift - last.lift) * (last.apex - before.apex);
        let last_crossed = (last.lift - before.lift) * (next.apex - last.apex);
        if next_crosses > last_crossed {
            break;
        }
        len -= 1;
    }
    envelope[len] = next;
    len + 1
}

/// The first x at which `next` is at least as low as `p` (`p.apex <
/// next.apex`): ⌈(next.lift − p.lift) / 2(next.apex − p.apex)⌉.
fn takes_over(p: &Parabola, next: &Parabola) -> i64 {
    let (num, den) = (next.lift - p.lift, 2 * (next.apex - p.apex));
    if den == 2 {
        // Neighbouring apexes, the common case in a silhouette.
        return (num + 1) >> 1;
    }
    // An f64 quotient (an integer division costs several times as much) is
    // exact enough: a non-integer num/den is at least 1/den from the next
    // integer, far beyond the rounding error, so truncation lands on ⌊ ⌋ or
    // ⌈ ⌉ and the integer check settles which.
    let t = (num as f64 / den as f64) as i64;
    t + i64::from(t * den < num)
}

/// The stand-in for "no nearest pixel" in a w × h image: w² + h², beyond
/// every in-image squared distance.
fn absent_distance(width: usize, height: usize) -> u32 {
    width
        .checked_mul(width)
        .zip(height.checked_mul(height))
        .and_then(|(w2, h2)| w2.checked_add(h2))
        .and_then(|d| u32::try_from(d).ok())
        .unwrap_or_else(|| panic!("a {width} × {height} mask is too large for a u32 distance field"))
}

/// r(A, B) of eq. 9: the sum, over A's set pixels, of the squared distance to
/// the nearest pixel of B, read from B's distance field. An empty A costs 0;
/// an empty B costs |A|·(w² + h²) (see [`DistanceField`]).
///
/// # Panics
/// If `a` and `b` differ in size.
pub fn directed_cost(a: &Mask, b: &DistanceField) -> u64 {
    assert_eq!((a.width(), a.height()), (b.width, b.height), "mask and distance field differ in size");
    // Summing in u32 lanes vectorises several times better than widening
    // each term to u64; no value exceeds w² + h², so a chunk this long
    // cannot overflow.
    let chunk = (u32::MAX / absent_distance(b.width, b.height).max(1)) as usize;
    let sum_chunk = |(a, d): (&[u8], &[u32])| {
        // Pixels are 0 or 1: 0 − p is a mask that keeps d or clears it.
        let sum = a.iter().zip(d).map(|(&p, &d)| d & 0u32.wrapping_sub(u32::from(p))).sum::<u32>();
        u64::from(sum)
    };
    a.pixels().chunks(chunk).zip(b.values.chunks(chunk)).map(sum_chunk).sum()
}

/// One frame's observed silhouette B with its distance field, built once and
/// then asked for the likelihood of many hypotheses.
///
/// r(A, B) reads B's field at A's pixels. r(B, A) needs A's distances only
/// at B's pixels, so instead of A's whole field it runs the transform's
/// vertical pass over A's bounding box alone, builds each row's lower
/// envelope only for rows holding B's pixels, and sums each envelope
/// parabola over the stretch of B's runs it covers in closed form: no
/// per-pixel work in the horizontal pass, and the same exact integers.
#[derive(Clone, Debug)]
pub struct Observation {
    mask: Mask,
    field: DistanceField,
    epsilon: f64,
    /// B's set pixels as runs: row y's are `runs[row_starts[y]..row_starts[y + 1]]`.
    runs: Vec<Run>,
    row_starts: Vec<usize>,
    count: u64,
}

/// Columns `start..end` of one row, all set.
#[derive(Clone, Copy, Debug)]
struct Run {
    start: i64,
    end: i64,
}

/// The buffers scoring a hypothesis works in, reused so that scoring
/// allocates nothing once it has seen a frame of the same size.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    /// The vertical pass over the hypothesis's bounding box.
    vertical: Vec<u16>,
    /// The box's columns holding a hypothesis pixel (relative to the box).
    occupied: Vec<u32>,
    envelope: Vec<Parabola>,
    /// Which columns of the image hold a hypothesis pixel.
    columns: Vec<u8>,
    /// One row's inner columns of A's runs, and B's runs less those.
    inside: Vec<Run>,
    outside: Vec<Run>,
}

/// The smallest box holding every set pixel of a mask: rows `top..=bottom`,
/// columns `left..=right`.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    top: usize,
    bottom: usize,
    left: usize,
    right: usize,
}

impl Bounds {
    /// `None` for a mask with no pixel set. `columns` is scratch.
    fn of(mask: &Mask, columns: &mut Vec<u8>) -> Option<Bounds> {
        let width = mask.width();
        // An OR fold has no early exit, so it vectorises.
        let any = |row: &[u8]| row.iter().fold(0, |acc, &p| acc | p) != 0;
        let rows = || mask.pixels().chunks_exact(width.max(1));
        let top = rows().position(any)?;
        let bottom = mask.height() - 1 - rows().rev().position(any)?;
        columns.clear();
        columns.resize(width, 0);
        for row in rows().skip(top).take(bottom - top + 1) {
            for (c, &p) in columns.iter_mut().zip(row) {
                *c |= p;
            }
        }
        let left = columns.iter().position(|&c| c != 0)?;
        let right = columns.iter().rposition(|&c| c != 0)?;
        Some(Bounds { top, bottom, left, right })
    }

    fn width(&self) -> usize {
        self.right - self.left + 1
    }
}

impl Observation {
    /// The observation of silhouette `mask`, with ε = [`EPSILON`].
    pub fn new(mask: Mask) -> Observation {
        Observation::with_epsilon(mask, EPSILON)
    }

    /// The observation of silhouette `mask`, with ε = `epsilon` pixels².
    ///
    /// # Panics
    /// Unless `epsilon` is finite and positive (R would be infinite or NaN).
    pub fn with_epsilon(mask: Mask, epsilon: f64) -> Observation {
        assert!(epsilon.is_finite() && epsilon > 0.0, "ε must be finite and positive, not {epsilon}");
        let field = DistanceField::of(&mask);
        let (mut runs, mut row_starts) = (Vec::new(), vec![0]);
        for row in mask.pixels().chunks_exact(mask.width().max(1)).take(mask.height()) {
            let mut x = 0;
            while let Some(start) = row[x..].iter().position(|&p| p != 0).map(|s| x + s) {
                let end = row[start..].iter().position(|&p| p == 0).map_or(row.len(), |e| start + e);
                runs.push(Run { start: start as i64, end: end as i64 });
                x = end;
            }
            row_starts.push(runs.len());
        }
        let count = mask.count() as u64;
        Observation { mask, field, epsilon, runs, row_starts, count }
    }

    pub fn mask(&self) -> &Mask {
        &self.mask
    }

    pub fn field(&self) -> &DistanceField {
        &self.field
    }

    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// (r(A, B), r(B, A)) for hypothesis A.
    ///
    /// # Panics
    /// If `hypothesis` differs in size from the observed mask.
    pub fn costs(&self, hypothesis: &Mask, scratch: &mut Scratch) -> (u64, u64) {
        let (width, height) = (self.mask.width(), self.mask.height());
        assert_eq!((hypothesis.width(), hypothesis.height()), (width, height), "mask and observation differ in size");
        let Some(bounds) = Bounds::of(hypothesis, &mut scratch.columns) else {
            // r(∅, B) = 0; r(B, ∅) as `DistanceField` defines "no pixel".
            return (0, self.count * u64::from(absent_distance(width, height)));
        };
        // r(A, B) over A's box only, as `directed_cost` sums: in u32 lanes
        // per row, which a row's (w² + h²)·w cannot overflow below ~1600 pixels
        // a side; wider frames sum in u64.
        let columns = bounds.left..=bounds.right;
        let forward = (bounds.top..=bounds.bottom)
            .map(|y| {
                let a = &hypothesis.pixels()[y * width..][columns.clone()];
                let d = &self.field.values[y * width..][columns.clone()];
                let terms = a.iter().zip(d).map(|(&p, &d)| d & 0u32.wrapping_sub(u32::from(p)));
                if width <= 1600 { u64::from(terms.sum::<u32>()) } else { terms.map(u64::from).sum() }
            })
            .sum();
        (forward, self.cost_to(hypothesis, bounds, scratch))
    }

    /// r(B, A): Σ over B's pixels of the squared distance to A's nearest,
    /// for A with pixels inside `bounds`.
    fn cost_to(&self, hypothesis: &Mask, bounds: Bounds, scratch: &mut Scratch) -> u64 {
        let (width, box_width) = (self.mask.width(), bounds.width());
        let box_height = bounds.bottom - bounds.top + 1;
        let Scratch { vertical, occupied, envelope, inside, outside, .. } = scratch;
        vertical.resize(box_width * box_height, 0);
        let rows = (bounds.top..=bounds.bottom).map(|y| &hypothesis.pixels()[y * width..][bounds.left..=bounds.right]);
        vertical_pass(vertical, rows, box_width);
        occupied.clear();
        occupied.extend((0..box_width as u32).filter(|&q| vertical[q as usize] != NO_PIXEL));
        envelope.resize(box_width, Parabola::default());
        let (first, last) = (&vertical[..box_width], &vertical[(box_height - 1) * box_width..]);
        let mut total = 0;
        for y in 0..self.mask.height() {
            let runs = &self.runs[self.row_starts[y]..self.row_starts[y + 1]];
            if runs.is_empty() {
                continue;
            }
            // Outside the box, a column's nearest A pixel is its top- (or
            // bottom-) most, the box edge's distance plus the rows between.
            let (g, beyond) = if y < bounds.top {
                (first, bounds.top - y)
            } else if y > bounds.bottom {
                (last, y - bounds.bottom)
            } else {
                (&vertical[(y - bounds.top) * box_width..][..box_width], 0)
            };
            let mut len = 0;
            // As in `horizontal_pass`, the inner columns of a run of A's
            // pixels stay out of the envelope (outside the run its ends are
            // nearer); B's pixels there are at distance 0, so they are cut
            // out of B's runs instead.
            inside.clear();
            for &q in occupied.iter() {
                let q = q as usize;
                let apex = (bounds.left + q) as i64;
                if beyond == 0 && g[q] == 0 && q > 0 && q + 1 < box_width && g[q - 1] == 0 && g[q + 1] == 0 {
                    match inside.last_mut() {
                        Some(run) if run.end == apex => run.end += 1,
                        _ => inside.push(Run { start: apex, end: apex + 1 }),
                    }
                    continue;
                }
                len = push(envelope, len, Parabola::new(apex, i64::from(g[q]) + beyond as i64));
            }
            if inside.is_empty() {
                total += sum_over_runs(&envelope[..len], runs);
            } else {
                subtract(runs, inside, outside);
                total += sum_over_runs(&envelope[..len], outside);
            }
        }
        total
    }

    /// R(A, B) of eq. 8 for hypothesis A, in (0, 1/ε]: 1/ε exactly when A = B
    /// (including both empty), finite always.
    ///
    /// # Panics
    /// If `hypothesis` differs in size from the observed mask.
    pub fn likelihood(&self, hypothesis: &Mask, scratch: &mut Scratch) -> f64 {
        let (forward, backward) = self.costs(hypothesis, scratch);
        // Summed as integers first, so R(A, B) and R(B, A) are the same f64;
        // exact in f64 for any image below ~10⁵ pixels a side.
        1.0 / ((forward + backward) as f64 + self.epsilon)
    }
}

/// Σ over the columns of `runs` of the lower `envelope` there: each
/// parabola summed in closed form over the part of each run it covers.
fn sum_over_runs(envelope: &[Parabola], runs: &[Run]) -> u64 {
    let end_of = |k: usize| envelope.get(k + 1).map_or(i64::MAX, |next| takes_over(&envelope[k], next));
    let (mut k, mut end) = (0, end_of(0));
    let mut total = 0;
    for run in runs {
        let mut x = run.start;
        while x < run.end {
            while end <= x {
                k += 1;
                end = end_of(k);
            }
            let stop = end.min(run.end);
            let p = &envelope[k];
            let g2 = p.lift - p.apex * p.apex;
            total += (stop - x) * g2 + squares_between(x - p.apex, stop - 1 - p.apex);
            x = stop;
        }
    }
    total as u64
}

/// Leaves in `out` the columns of `runs` not in `cut` (both sorted and
/// disjoint), as runs.
fn subtract(runs: &[Run], cut: &[Run], out: &mut Vec<Run>) {
    out.clear();
    let mut cut = cut.iter().peekable();
    for run in runs {
        let mut start = run.start;
        while start < run.end {
            // Cuts wholly left of what remains of this run cut nothing more.
            while cut.next_if(|c| c.end <= start).is_some() {}
            match cut.peek() {
                Some(c) if c.start < run.end => {
                    if c.start > start {
                        out.push(Run { start, end: c.start });
                    }
                    start = c.end;
                }
                _ => {
                    out.push(Run { start, end: run.end });
                    break;
                }
            }
        }
    }
}

/// Σ t² for t from `lo` to `hi` (lo ≤ hi), either sign.
fn squares_between(lo: i64, hi: i64) -> i64 {
    // Σ_{t=1}^{n} t², which is 0 at n = 0 and at n = −1.
    let upto = |n: i64| n * (n + 1) * (2 * n + 1) / 6;
    if lo >= 0 {
        upto(hi) - upto(lo - 1)
    } else if hi <= 0 {
        upto(-lo) - upto(-hi - 1)
    } else {
        upto(-lo) + upto(hi)
    }
}

#[cfg(test)]
mod tests;
