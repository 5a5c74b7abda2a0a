//! Silhouettes from frames: a silhouette frame is thresholded; a color frame
//! is compared with a background image, with shadows suppressed, then
//! cleaned by a median filter, the removal of small blobs and the filling of
//! small holes.
//!
//! Written for speed (a 640×480 frame in well under 2 ms on one core):
//! integer arithmetic, row-contiguous loops, a median filter that counts the
//! set pixels of its window by separable box sums, and connected components
//! found over runs of pixels rather than pixel by pixel. An [`Extractor`]
//! keeps its scratch buffers, so after the first frame it allocates nothing.

use crate::params::{InvalidField, Params};
use crate::vision::background::{LearnedBackground, learn_background};
use crate::vision::frames::{Frame, FrameError, FrameKind, FrameSource, beside_frames, read_image};
use crate::vision::mask::Mask;
use crate::vision::resize::{Shrinker, work_size};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// How many frames, at most, a background is learned from.
pub const BACKGROUND_SAMPLE: usize = 64;

/// The largest median filter radius (a 15×15 window, whose count still fits
/// a byte).
pub const MAX_MEDIAN_RADIUS: usize = 7;

/// Why a silhouette cannot be extracted.
#[derive(Debug, Error)]
pub enum SilhouetteError {
    #[error("{frame}: the frame is {width}×{height}; the background is {background_width}×{background_height}")]
    SizeMismatch { frame: String, width: usize, height: usize, background_width: usize, background_height: usize },
    #[error("{frame}: a color frame, and no background to subtract was given")]
    NoBackground { frame: String },
    #[error("no frames to take a median background from")]
    NoFrames,
    #[error(transparent)]
    Frames(#[from] FrameError),
}

/// A setting of [`ExtractParams`] out of its range.
#[derive(Debug, Error, PartialEq)]
pub enum ExtractParamsError {
    #[error("threshold: the difference threshold must be 1 to 764 (a sum over three channels of 0 to 255), not {0}")]
    Threshold(u16),
    #[error("shadow_low: the shadow brightness ratios must satisfy 0 < low ≤ high < 1, not {low} and {high}")]
    ShadowRatio { low: f32, high: f32 },
    #[error("shadow_chroma: the shadow color tolerance must be at most 765, not {0}")]
    ShadowChroma(u16),
    #[error("median_radius: the median filter radius must be at most {MAX_MEDIAN_RADIUS}, not {0}")]
    MedianRadius(usize),
    #[error("min_blob: the smallest blob must be a fraction of the image in [0, 1), not {0}")]
    MinBlob(f64),
    #[error("max_hole: the largest hole filled must be a fraction of the image in [0, 1), not {0}")]
    MaxHole(f64),
}

impl InvalidField for ExtractParamsError {
    fn field(&self) -> &'static str {
        match self {
            ExtractParamsError::Threshold(_) => "threshold",
            ExtractParamsError::ShadowRatio { .. } => "shadow_low",
            ExtractParamsError::ShadowChroma(_) => "shadow_chroma",
            ExtractParamsError::MedianRadius(_) => "median_radius",
            ExtractParamsError::MinBlob(_) => "min_blob",
            ExtractParamsError::MaxHole(_) => "max_hole",
        }
    }
}

/// Settings of background subtraction and cleaning; each setter takes and
/// returns the settings, and [`Extractor::new`] checks them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractParams {
    threshold: u16,
    shadow_low: f32,
    shadow_high: f32,
    shadow_chroma: u16,
    median_radius: usize,
    min_blob: f64,
    max_hole: f64,
}

impl Default for ExtractParams {
    fn default() -> ExtractParams {
        ExtractParams {
            threshold: 60,
            shadow_low: 0.35,
            shadow_high: 0.95,
            shadow_chroma: 40,
            median_radius: 1,
            min_blob: 0.002,
            max_hole: 0.0005,
        }
    }
}

impl ExtractParams {
    /// A pixel differs from the background when the sum over R, G and B of
    /// the absolute differences exceeds this (default 60: about 20 a
    /// channel, several times camera noise).
    pub fn threshold(mut self, sum_abs_diff: u16) -> ExtractParams {
        self.threshold = sum_abs_diff;
        self
    }

    /// A pixel whose brightness (R + G + B) is between `low` and `high`
    /// times the background's, and whose color is nearly the background's
    /// scaled by that ratio, is shadow, counted as background (default 0.35
    /// to 0.95).
    pub fn shadow_ratio(mut self, low: f32, high: f32) -> ExtractParams {
        (self.shadow_low, self.shadow_high) = (low, high);
        self
    }

    /// How near "nearly the background's color" is for a shadow: the sum
    /// over channels of `|c − ratio·C|` (frame `c`, background `C`) at most
    /// this (default 40; 0 turns shadow suppression off).
    pub fn shadow_chroma(mut self, sum_abs_diff: u16) -> ExtractParams {
        self.shadow_chroma = sum_abs_diff;
        self
    }

    /// The median filter's window is `2·radius + 1` pixels square (default
    /// 1: 3×3; 0 turns it off).
    pub fn median_radius(mut self, radius: usize) -> ExtractParams {
        self.median_radius = radius;
        self
    }

    /// Connected blobs (8-connected) smaller than this fraction of the
    /// image's area are removed (default 0.002: 38 pixels at 160×120, 614 at
    /// 640×480; 0 keeps every blob).
    pub fn min_blob(mut self, fraction: f64) -> ExtractParams {
        self.min_blob = fraction;
        self
    }

    /// Holes (4-connected background regions not touching the image's edge)
    /// at most this fraction of the image's area are filled (default 0.0005:
    /// 9 pixels at 160×120, 153 at 640×480; 0 fills none).
    pub fn max_hole(mut self, fraction: f64) -> ExtractParams {
        self.max_hole = fraction;
        self
    }
}

impl Params for ExtractParams {
    type Valid = ExtractParams;
    type Error = ExtractParamsError;

    fn check(&self) -> Result<ExtractParams, ExtractParamsError> {
        if !(1..=764).contains(&self.threshold) {
            return Err(ExtractParamsError::Threshold(self.threshold));
        }
        let (low, high) = (self.shadow_low, self.shadow_high);
        if !(low > 0.0 && low <= high && high < 1.0) {
            return Err(ExtractParamsError::ShadowRatio { low, high });
        }
        if self.shadow_chroma > 765 {
            return Err(ExtractParamsError::ShadowChroma(self.shadow_chroma));
        }
        if self.median_radius > MAX_MEDIAN_RADIUS {
            return Err(ExtractParamsError::MedianRadius(self.median_radius));
        }
        if !(0.0..1.0).contains(&self.min_blob) {
            return Err(ExtractParamsError::MinBlob(self.min_blob));
        }
        if !(0.0..1.0).contains(&self.max_hole) {
            return Err(ExtractParamsError::MaxHole(self.max_hole));
        }
        Ok(*self)
    }
}

/// Turns frames into masks. Holds the background and every scratch buffer,
/// so extracting frame after frame of one size allocates nothing after the
/// first.
#[derive(Debug)]
pub struct Extractor {
    params: ExtractParams,
    difference: Difference,
    background: Option<Background>,
    /// The channels' differences of one row.
    diff: Vec<u8>,
    /// The marked pixels before the median filter.
    raw: Vec<u8>,
    median: MedianScratch,
    components: Components,
}

#[derive(Debug)]
struct Background {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Extractor {
    /// An extractor with no background yet: it thresholds silhouette frames
    /// and needs [`Extractor::set_background`] before color frames.
    pub fn new(params: ExtractParams) -> Result<Extractor, ExtractParamsError> {
        params.check()?;
        Ok(Extractor {
            params,
            difference: Difference {
                threshold: u32::from(params.threshold),
                chroma: i32::from(params.shadow_chroma),
                low_256: (params.shadow_low * 256.0).round() as i32,
                high_256: (params.shadow_high * 256.0).round() as i32,
            },
            background: None,
            diff: Vec::new(),
            raw: Vec::new(),
            median: MedianScratch::default(),
            components: Components::default(),
        })
    }

    pub fn params(&self) -> &ExtractParams {
        &self.params
    }

    /// The image color frames are compared with (such as `background.png`,
    /// or one learned from the frames).
    pub fn set_background(&mut self, background: &Frame) {
        self.background =
            Some(Background { width: background.width(), height: background.height(), rgb: background.rgb().to_vec() });
    }

    /// The person's mask in `frame`, written into `out` (resized to the
    /// frame if it differs). A silhouette frame is thresholded (a pixel
    /// whose mean channel is 128 or more is the person); a color frame goes
    /// through background subtraction, the median filter, blob removal and
    /// hole filling.
    pub fn extract_into(&mut self, frame: &Frame, out: &mut Mask) -> Result<(), SilhouetteError> {
        let (width, height) = (frame.width(), frame.height());
        if frame.kind() == FrameKind::Color {
            let Some(background) = &self.background else {
                return Err(SilhouetteError::NoBackground { frame: frame.label().into() });
            };
            if (background.width, background.height) != (width, height) {
                return Err(SilhouetteError::SizeMismatch {
                    frame: frame.label().into(),
                    width,
                    height,
                    background_width: background.width,
                    background_height: background.height,
                });
            }
        }
        if (out.width(), out.height()) != (width, height) {
            *out = Mask::new(width, height);
        }
        match frame.kind() {
            FrameKind::Silhouette => threshold_into(frame.rgb(), out.pixels_mut()),
            FrameKind::Color => self.subtract_and_clean(frame, out),
        }
        Ok(())
    }

    /// [`Extractor::extract_into`] a new mask.
    pub fn extract(&mut self, frame: &Frame) -> Result<Mask, SilhouetteError> {
        let mut mask = Mask::new(frame.width(), frame.height());
        self.extract_into(frame, &mut mask)?;
        Ok(mask)
    }

    fn subtract_and_clean(&mut self, frame: &Frame, out: &mut Mask) {
        let (width, height) = (frame.width(), frame.height());
        if width * height == 0 {
            return;
        }
        let background = &self.background.as_ref().expect("checked by extract_into").rgb;
        let radius = self.params.median_radius;
        if radius == 0 {
            self.difference.mark(frame.rgb(), background, width, &mut self.diff, out.pixels_mut());
        } else {
            self.raw.resize(width * height, 0);
            self.difference.mark(frame.rgb(), background, width, &mut self.diff, &mut self.raw);
            self.median.filter(&self.raw, width, height, radius, out.pixels_mut());
        }
        let area = (width * height) as f64;
        let min_blob = (self.params.min_blob * area).ceil() as u32;
        if min_blob > 1 {
            self.components.remove_small(out.pixels_mut(), width, height, 1, min_blob);
        }
        let max_hole = (self.params.max_hole * area).floor() as u32;
        if max_hole > 0 {
            self.components.fill_holes(out.pixels_mut(), width, height, max_hole);
        }
    }
}

/// The background difference test, in integers.
#[derive(Clone, Copy, Debug)]
struct Difference {
    threshold: u32,
    chroma: i32,
    /// The shadow brightness ratios in 1/256ths.
    low_256: i32,
    high_256: i32,
}

impl Difference {
    /// Marks each pixel of a `width`-pixel-wide frame that differs from the
    /// background and is not shadow. `diff` is scratch for one row.
    fn mark(&self, rgb: &[u8], background: &[u8], width: usize, diff: &mut Vec<u8>, raw: &mut [u8]) {
        let Difference { threshold, chroma, low_256: low, high_256: high } = *self;
        // First every pixel's difference: the channels' absolute differences
        // over the whole row at once (vector code, as the bytes are
        // contiguous), then summed per pixel. Then the shadow test, only at
        // the pixels marked (the person and its shadow, a small share).
        diff.resize(3 * width, 0);
        for ((c, b), out) in
            rgb.chunks_exact(3 * width).zip(background.chunks_exact(3 * width)).zip(raw.chunks_exact_mut(width))
        {
            for ((d, &c), &b) in diff.iter_mut().zip(c).zip(b) {
                *d = c.abs_diff(b);
            }
            for (d, o) in diff.chunks_exact(3).zip(out.iter_mut()) {
                *o = u8::from(u32::from(d[0]) + u32::from(d[1]) + u32::from(d[2]) > threshold);
            }
        }
        if chroma == 0 {
            return;
        }
        // Over each run of marked pixels, every pixel tested without a branch.
        let mut start = 0;
        loop {
            start = find(raw, start, 1);
            if start == raw.len() {
                break;
            }
            let end = find(raw, start, 0);
            let (c, b) = (&rgb[3 * start..3 * end], &background[3 * start..3 * end]);
            for ((c, b), out) in c.chunks_exact(3).zip(b.chunks_exact(3)).zip(&mut raw[start..end]) {
                let (r, g, bl) = (c[0] as i32, c[1] as i32, c[2] as i32);
                let (rb, gb, bb) = (b[0] as i32, b[1] as i32, b[2] as i32);
                let (s, sb) = (r + g + bl, rb + gb + bb);
                // Brightness ratio s/sb within [low, high], in 1/256ths.
                let darker = s * 256 >= low * sb && s * 256 <= high * sb;
                // Σ|c·sb − C·s| ≤ chroma·sb is Σ|c − (s/sb)·C| ≤ chroma:
                // the color is the background's, scaled by the ratio.
                let off = (r * sb - rb * s).abs() + (g * sb - gb * s).abs() + (bl * sb - bb * s).abs();
                *out = u8::from(!(darker & (off <= chroma * sb)));
            }
            start = end;
        }
    }
}

/// A silhouette frame's mask: a pixel is the person when the mean of its
/// channels is 128 or more.
fn threshold_into(rgb: &[u8], out: &mut [u8]) {
    for (p, o) in rgb.chunks_exact(3).zip(out.iter_mut()) {
        *o = u8::from(u16::from(p[0]) + u16::from(p[1]) + u16::from(p[2]) >= 3 * 128);
    }
}

/// How many times a learned background's noise (the median difference of a
/// background pixel) a pixel must differ by to be the person: the sum over
/// channels of a background pixel's differences rarely reaches three times
/// its median.
const NOISE_THRESHOLD: f64 = 5.0;
/// The lowest threshold a learned background's noise may set, so a
/// noise-free clip (rendered frames) is not cut at every rounding step.
const MIN_THRESHOLD: u16 = 24;
/// A shadow's color matches the background's, scaled by its darkening,
/// within this many times the learned noise.
const NOISE_SHADOW_CHROMA: f64 = 3.0;
/// The darkest a shadow on a learned background may make the ground; the
/// person's own dark clothes lie below it more often than a shadow does.
const LEARNED_SHADOW_LOW: f32 = 0.5;

/// The extraction settings a learned background calls for: thresholds from
/// its noise, shadow suppression off on greyscale frames (where a darker
/// person and a shadow differ by nothing but texture).
fn learned_params(learned: &LearnedBackground) -> ExtractParams {
    let threshold = ((NOISE_THRESHOLD * learned.noise).round() as u16).clamp(MIN_THRESHOLD, 764);
    let chroma =
        if learned.greyscale { 0 } else { ((NOISE_SHADOW_CHROMA * learned.noise).round() as u16).clamp(1, 765) };
    let defaults = ExtractParams::default();
    defaults.threshold(threshold).shadow_ratio(LEARNED_SHADOW_LOW, defaults.shadow_high).shadow_chroma(chroma)
}

/// The silhouettes of a source's frames, in order, as `track` and `report`
/// see them, at a working size (see [`work_size`]). Color frames are
/// compared with the background chosen when the first one arrives: the one
/// given, else `background.png` beside the frames (as `render --color`
/// writes it), else one learned from the frames themselves
/// ([`learn_background`]), after which only the person's region (its
/// largest coherent region and what lies near it in size) is kept. A color
/// frame whose silhouette covers more than [`MAX_PERSON_SHARE`] of it gives
/// an empty one. A video whose decoding fails after its first frame ends
/// there ([`FrameSource::decoding_failed`] says why): the frames before the
/// damage are still worth tracking.
pub struct Silhouettes {
    source: FrameSource,
    extractor: Extractor,
    shrinker: Shrinker,
    /// Where the frames came from, to find `background.png` beside them.
    input: PathBuf,
    background: Option<PathBuf>,
    background_used: Option<String>,
    learned: bool,
    unusable: usize,
}

impl Silhouettes {
    /// Silhouettes of `source`, opened from `input`, reduced to at most
    /// `work_width` pixels wide (0: the frames' own size), with the default
    /// extraction settings.
    pub fn new(input: &Path, source: FrameSource, background: Option<PathBuf>, work_width: usize) -> Silhouettes {
        let extractor = Extractor::new(ExtractParams::default()).expect("the default settings are valid");
        let size = (source.width(), source.height());
        let shrinker = Shrinker::new(size, work_size(size.0, size.1, work_width));
        Silhouettes {
            source,
            extractor,
            shrinker,
            input: input.to_path_buf(),
            background,
            background_used: None,
            learned: false,
            unusable: 0,
        }
    }

    pub fn source(&self) -> &FrameSource {
        &self.source
    }

    /// The working size (width, height) the silhouettes have.
    pub fn size(&self) -> (usize, usize) {
        self.shrinker.size()
    }

    /// The background color frames were compared with, once one was.
    pub fn background_used(&self) -> Option<&str> {
        self.background_used.as_deref()
    }

    /// The next frame's silhouette, written into `mask`; `None` after the
    /// last frame.
    pub fn next_into(&mut self, mask: &mut Mask) -> Option<Result<(), SilhouetteError>> {
        self.next_seen(mask).map(|seen| seen.map(drop))
    }

    /// [`Silhouettes::next_into`], giving the frame (at the working size)
    /// the silhouette came from.
    pub fn next_seen(&mut self, mask: &mut Mask) -> Option<Result<Frame, SilhouetteError>> {
        let frame = match self.source.next_frame()? {
            Ok(frame) => self.shrinker.shrink(frame),
            Err(e) => return Some(Err(e.into())),
        };
        Some(self.extract(&frame, mask).map(|()| frame))
    }

    fn extract(&mut self, frame: &Frame, mask: &mut Mask) -> Result<(), SilhouetteError> {
        if frame.kind() == FrameKind::Color && self.background_used.is_none() {
            let from = match self.background.clone().or_else(|| beside_frames(&self.input, "background.png")) {
                Some(path) => {
                    let plate = read_image(&path)?;
                    let source = (self.source.width(), self.source.height());
                    if (plate.width(), plate.height()) != source {
                        return Err(SilhouetteError::SizeMismatch {
                            frame: format!("{} against {}", self.source.path(), path.display()),
                            width: source.0,
                            height: source.1,
                            background_width: plate.width(),
                            background_height: plate.height(),
                        });
                    }
                    self.extractor.set_background(&self.shrinker.shrink(plate));
                    path.display().to_string()
                }
                None => {
                    let sample: Vec<Frame> =
                        self.source.sample(BACKGROUND_SAMPLE)?.into_iter().map(|f| self.shrinker.shrink(f)).collect();
                    if sample.is_empty() {
                        return Err(SilhouetteError::NoFrames);
                    }
                    let learned = learn_background(&sample);
                    self.extractor = Extractor::new(learned_params(&learned)).expect("learned settings are in range");
                    self.extractor.set_background(&learned.frame);
                    self.learned = true;
                    learned.frame.label().to_string()
                }
            };
            self.background_used = Some(from);
        }
        self.extractor.extract_into(frame, mask)?;
        if self.learned {
            *mask = person_region(mask);
        }
        // Most of the frame changed: a cut to another scene, a camera that
        // moved or the light switched, not a person.
        if frame.kind() == FrameKind::Color
            && mask.count() as f64 > MAX_PERSON_SHARE * (mask.width() * mask.height()) as f64
        {
            mask.clear();
            self.unusable += 1;
        }
        Ok(())
    }

    /// How many color frames so far changed over more than
    /// [`MAX_PERSON_SHARE`] of their area and were given as empty.
    pub fn unusable(&self) -> usize {
        self.unusable
    }
}

/// The largest share of a color frame a silhouette may cover; beyond it the
/// frame is taken to show no person (an empty silhouette, which the tracker
/// coasts through).
pub const MAX_PERSON_SHARE: f64 = 0.5;

/// Scratch rows of the binary median filter.
#[derive(Debug, Default)]
struct MedianScratch {
    /// Column counts of one output row, padded by `radius` on each side.
    columns: Vec<u8>,
}

impl MedianScratch {
    /// The median of a binary image over a `(2r+1)²` window: a pixel is set
    /// when more than half the window is. Outside the image the nearest edge
    /// pixel repeats. Counts are separable box sums, each a few whole-row
    /// additions of bytes that compile to vector code.
    fn filter(&mut self, input: &[u8], width: usize, height: usize, radius: usize, out: &mut [u8]) {
        let padded = width + 2 * radius;
        self.columns.resize(padded, 0);
        let half = ((2 * radius + 1) * (2 * radius + 1) / 2) as u8;
        for y in 0..height {
            let columns = &mut self.columns[radius..radius + width];
            columns.fill(0);
            for dy in 0..=2 * radius {
                let source = (y + dy).saturating_sub(radius).min(height - 1);
                for (c, &p) in columns.iter_mut().zip(&input[source * width..(source + 1) * width]) {
                    *c += p;
                }
            }
            let (first, last) = (self.columns[radius], self.columns[radius + width - 1]);
            self.columns[..radius].fill(first);
            self.columns[radius + width..].fill(last);
            let row = &mut out[y * width..(y + 1) * width];
            row.copy_from_slice(&self.columns[..width]);
            for dx in 1..=2 * radius {
                for (o, &c) in row.iter_mut().zip(&self.columns[dx..dx + width]) {
                    *o += c;
                }
            }
            for o in row.iter_mut() {
                *o = u8::from(*o > half);
            }
        }
    }
}

/// A horizontal run of equal pixels, `x0..x1` on row `y`.
#[derive(Clone, Copy, Debug)]
struct Run {
    y: u32,
    x0: u32,
    x1: u32,
}

/// Connected components over runs: union-find on the runs of one value,
/// each run joined with the runs it touches on the row above.
#[derive(Debug, Default)]
struct Components {
    runs: Vec<Run>,
    /// Union-find parent of each run; a root's parent is itself, and a
    /// parent's index is never above its child's.
    parent: Vec<u32>,
    /// Pixel count of each root's component.
    area: Vec<u32>,
    /// Whether each root's component touches the image's edge.
    edge: Vec<bool>,
}

impl Components {
    /// Clears the `value` components (8-connected) smaller than `min_area`.
    fn remove_small(&mut self, pixels: &mut [u8], width: usize, height: usize, value: u8, min_area: u32) {
        self.label(pixels, width, height, value, true);
        for (run, &root) in self.runs.iter().zip(&self.parent) {
            if self.area[root as usize] < min_area {
                let row = run.y as usize * width;
                pixels[row + run.x0 as usize..row + run.x1 as usize].fill(1 - value);
            }
        }
    }

    /// Sets the holes (4-connected unset components not touching the edge)
    /// of at most `max_area` pixels.
    fn fill_holes(&mut self, pixels: &mut [u8], width: usize, height: usize, max_area: u32) {
        self.label(pixels, width, height, 0, false);
        for (run, &root) in self.runs.iter().zip(&self.parent) {
            if self.area[root as usize] <= max_area && !self.edge[root as usize] {
                let row = run.y as usize * width;
                pixels[row + run.x0 as usize..row + run.x1 as usize].fill(1);
            }
        }
    }

    /// Finds the runs of `value` and their components; afterwards every
    /// run's parent is its root, and roots hold areas and edge flags.
    fn label(&mut self, pixels: &[u8], width: usize, height: usize, value: u8, eight: bool) {
        self.runs.clear();
        self.parent.clear();
        // Runs on the row above touch when their spans overlap, or for
        // 8-connectivity also meet at a corner.
        let reach = u32::from(eight);
        let mut above = 0..0;
        for y in 0..height {
            let row = &pixels[y * width..(y + 1) * width];
            let start = self.runs.len();
            let mut x = 0;
            loop {
                x = find(row, x, value);
                if x == width {
                    break;
                }
                let end = find(row, x, 1 - value);
                self.parent.push(self.runs.len() as u32);
                self.runs.push(Run { y: y as u32, x0: x as u32, x1: end as u32 });
                x = end;
            }
            let mut j = above.start;
            for i in start..self.runs.len() {
                let Run { x0, x1, .. } = self.runs[i];
                while j < above.end && self.runs[j].x1 + reach <= x0 {
                    j += 1;
                }
                let mut k = j;
                while k < above.end && self.runs[k].x0 < x1 + reach {
                    self.union(i, k);
                    k += 1;
                }
            }
            above = start..self.runs.len();
        }
        self.area.clear();
        self.area.resize(self.runs.len(), 0);
        self.edge.clear();
        self.edge.resize(self.runs.len(), false);
        let (last_row, width) = (height as u32 - 1, width as u32);
        for i in 0..self.runs.len() {
            // Parents come before children, so one pass in order flattens.
            let root = self.parent[self.parent[i] as usize];
            self.parent[i] = root;
            let Run { y, x0, x1 } = self.runs[i];
            self.area[root as usize] += x1 - x0;
            self.edge[root as usize] |= y == 0 || y == last_row || x0 == 0 || x1 == width;
        }
    }

    fn root(&mut self, mut i: usize) -> usize {
        while self.parent[i] as usize != i {
            let grand = self.parent[self.parent[i] as usize];
            self.parent[i] = grand;
            i = grand as usize;
        }
        i
    }

    /// Joins two components, the later root under the earlier.
    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        let (low, high) = (a.min(b), a.max(b));
        self.parent[high] = low as u32;
    }
}

/// The person in `mask`: its 8-connected regions of at least
/// `PERSON_SHARE` of the largest one's area (specks set aside, a limb cut
/// off by a thin gap kept); empty for an empty mask.
pub fn person_region(mask: &Mask) -> Mask {
    let (width, height) = (mask.width(), mask.height());
    let mut components = Components::default();
    components.label(mask.pixels(), width, height, 1, true);
    let largest = components.area.iter().copied().max().unwrap_or(0);
    let mut region = Mask::new(width, height);
    for (run, &root) in components.runs.iter().zip(&components.parent) {
        if f64::from(components.area[root as usize]) >= PERSON_SHARE * f64::from(largest) {
            region.fill_span(run.y as usize, run.x0 as usize, run.x1 as usize);
        }
    }
    region
}

/// The share of the largest region's area a region needs to count as part
/// of the person: a hand is about 2% of a silhouette, a speck far less.
const PERSON_SHARE: f64 = 0.01;

/// The first index at or after `from` where `row` holds `value` (0 or 1),
/// or `row.len()`. Skips eight pixels at a time where none can match.
fn find(row: &[u8], from: usize, value: u8) -> usize {
    // Pixels are 0 or 1: a word of eight that all miss equals `other`.
    let other = u64::from_ne_bytes([1 - value; 8]);
    let mut x = from;
    while x + 8 <= row.len() {
        let word = u64::from_ne_bytes(row[x..x + 8].try_into().expect("eight bytes"));
        if word != other {
            break;
        }
        x += 8;
    }
    row[x..].iter().position(|&p| p == value).map_or(row.len(), |i| x + i)
}

#[cfg(test)]
mod tests;
