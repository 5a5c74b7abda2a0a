//! Frame input: the images the tracker looks at, from a folder of PNG or
//! JPEG files or from a video file decoded by `ffmpeg`.
//!
//! Frames are decoded one at a time as they are asked for, so a long video
//! never sits in memory. Each frame is either a *silhouette* (every pixel
//! near black or near white) or a *color* frame; the caller says which it
//! expects ([`Expect`]) and a frame of the other kind is an error that names
//! it.

use crate::vision::video::{Decoded, FFMPEG, Video, VideoError};
use image::{ImageFormat, ImageReader};
use std::ffi::OsStr;
use std::fmt;
use std::fs;
use std::io::{self, Cursor};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A channel at most this is "near black" in a silhouette.
pub const SILHOUETTE_BLACK_MAX: u8 = 32;
/// A channel at least this is "near white" in a silhouette.
pub const SILHOUETTE_WHITE_MIN: u8 = 224;

/// What a source's frames should be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expect {
    /// Every frame is a silhouette; a color frame is an error.
    Silhouettes,
    /// Every frame is a color frame, even one that happens to be black and
    /// white (a dark scene, a fade), so nothing is refused for its kind.
    Color,
    /// The first frame read decides, and every later frame must be of the
    /// same kind.
    Auto,
}

/// What one frame holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameKind {
    /// Every pixel near black (every channel ≤ [`SILHOUETTE_BLACK_MAX`]) or
    /// near white (every channel ≥ [`SILHOUETTE_WHITE_MIN`]): white is the
    /// person.
    Silhouette,
    /// Anything else: a camera image, to be turned into a silhouette by
    /// background subtraction.
    Color,
}

impl fmt::Display for FrameKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FrameKind::Silhouette => "a silhouette",
            FrameKind::Color => "a color frame",
        })
    }
}

/// Why frames cannot be read. Each message names the file (or the video and
/// the frame's number) and the problem.
#[derive(Debug, Error)]
pub enum FrameError {
    #[error("{path}: no such file or folder")]
    Missing { path: String },
    #[error("{path}: cannot read: {source}")]
    Unreadable { path: String, source: io::Error },
    #[error("{path}: not a readable PNG or JPEG image (truncated or corrupt?): {problem}")]
    Corrupt { path: String, problem: String },
    #[error("{path}: no PNG or JPEG images (.png, .jpg, .jpeg) in this folder")]
    EmptyFolder { path: String },
    #[error("{frame}: the frame is {width}×{height}; earlier frames are {expected_width}×{expected_height}")]
    MixedSizes { frame: String, width: usize, height: usize, expected_width: usize, expected_height: usize },
    #[error("{path}: frames are {width}×{height}; the camera is {camera_width}×{camera_height}")]
    WrongSize { path: String, width: usize, height: usize, camera_width: usize, camera_height: usize },
    #[error(
        "{frame}: a color frame where silhouettes were expected: pixel ({x}, {y}) is ({r}, {g}, {b}), but a \
         silhouette pixel has every channel at most {SILHOUETTE_BLACK_MAX} or every channel at least \
         {SILHOUETTE_WHITE_MIN}"
    )]
    NotSilhouette { frame: String, x: usize, y: usize, r: u8, g: u8, b: u8 },
    #[error("{frame}: the frame is {kind}, but the first frame ({first}) is {first_kind}; a source holds one kind")]
    MixedKinds { frame: String, kind: FrameKind, first: String, first_kind: FrameKind },
    #[error(transparent)]
    Video(#[from] VideoError),
    #[error("{path}: a video is read in order; frame {index} cannot be read out of turn")]
    NotSeekable { path: String, index: usize },
    #[error("{path}: no frame {index} (the folder has {count})")]
    NoSuchFrame { path: String, index: usize, count: usize },
}

/// One decoded frame: 8-bit RGB, row-major from the top-left pixel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    label: String,
    width: usize,
    height: usize,
    kind: FrameKind,
    rgb: Vec<u8>,
}

impl Frame {
    /// A frame over `rgb` (3 bytes a pixel, row-major), its kind decided by
    /// its pixels. `label` names it in error messages.
    ///
    /// # Panics
    /// If `rgb` does not hold `width × height × 3` bytes: a bug in the caller.
    pub fn from_rgb(label: impl Into<String>, width: usize, height: usize, rgb: Vec<u8>) -> Frame {
        assert_eq!(rgb.len(), width * height * 3, "a {width}×{height} RGB frame needs {} bytes", width * height * 3);
        let kind = if first_color_pixel(&rgb).is_none() { FrameKind::Silhouette } else { FrameKind::Color };
        Frame { label: label.into(), width, height, kind, rgb }
    }

    /// The same pixels taken as `kind` (as a source's rule decides it).
    pub(crate) fn with_kind(mut self, kind: FrameKind) -> Frame {
        self.kind = kind;
        self
    }

    /// The file, or the video and frame number, the frame came from.
    pub fn label(&self) -> &str {
        &self.label
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    pub fn kind(&self) -> FrameKind {
        self.kind
    }

    /// Every pixel, 3 bytes (R, G, B) each, row-major from the top-left.
    pub fn rgb(&self) -> &[u8] {
        &self.rgb
    }
}

/// Reads one PNG or JPEG image, such as a background, its kind decided by
/// its pixels. The format is found from the bytes, not the name.
pub fn read_image(path: &Path) -> Result<Frame, FrameError> {
    let label = path.display().to_string();
    let bytes = fs::read(path).map_err(|source| match source.kind() {
        io::ErrorKind::NotFound => FrameError::Missing { path: label.clone() },
        _ => FrameError::Unreadable { path: label.clone(), source },
    })?;
    let corrupt = |problem: String| FrameError::Corrupt { path: label.clone(), problem };
    let format = image::guess_format(&bytes).map_err(|_| corrupt("neither PNG nor JPEG data".into()))?;
    if !matches!(format, ImageFormat::Png | ImageFormat::Jpeg) {
        return Err(corrupt(format!("{format:?} data; only PNG and JPEG are read")));
    }
    // A JPEG cut short still decodes (the missing blocks come out grey), so
    // the end-of-image marker is what tells a whole file from a truncated one.
    if format == ImageFormat::Jpeg && !ends_with_jpeg_eoi(&bytes) {
        return Err(corrupt("the JPEG data stops before its end-of-image marker".into()));
    }
    let image = image::load_from_memory_with_format(&bytes, format).map_err(|e| corrupt(e.to_string()))?;
    let (width, height) = (image.width() as usize, image.height() as usize);
    Ok(Frame::from_rgb(label, width, height, image.into_rgb8().into_raw()))
}

/// Whether JPEG data ends with its end-of-image marker (FF D9), allowing the
/// zero padding some writers put after it.
fn ends_with_jpeg_eoi(bytes: &[u8]) -> bool {
    let end = bytes.iter().rposition(|&b| b != 0).map_or(0, |i| i + 1);
    end >= 2 && bytes[end - 2..end] == [0xFF, 0xD9]
}

/// The first pixel that is neither near black nor near white, as
/// (pixel index, [r, g, b]).
fn first_color_pixel(rgb: &[u8]) -> Option<(usize, [u8; 3])> {
    let near = |p: &[u8]| {
        let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        hi <= SILHOUETTE_BLACK_MAX || lo >= SILHOUETTE_WHITE_MIN
    };
    // Whole blocks are checked without stopping early, so the test compiles
    // to straight-line code; only a failing block is searched pixel by pixel.
    const BLOCK: usize = 3 * 64;
    for (b, block) in rgb.chunks(BLOCK).enumerate() {
        if !block.chunks_exact(3).fold(true, |all, p| all & near(p)) {
            let i = block.chunks_exact(3).position(|p| !near(p)).expect("the block has a color pixel");
            let p = &block[3 * i..3 * i + 3];
            return Some((b * BLOCK / 3 + i, [p[0], p[1], p[2]]));
        }
    }
    None
}

/// The rule a source applies to each frame's kind.
#[derive(Debug)]
struct KindRule {
    expect: Expect,
    /// Under [`Expect::Auto`], the first frame's kind and label.
    first: Option<(FrameKind, String)>,
}

impl KindRule {
    fn new(expect: Expect) -> KindRule {
        KindRule { expect, first: None }
    }

    /// The kind of a frame, or why the frame breaks the rule.
    fn check(&mut self, label: &str, width: usize, rgb: &[u8]) -> Result<FrameKind, FrameError> {
        match self.expect {
            Expect::Color => Ok(FrameKind::Color),
            Expect::Silhouettes => match first_color_pixel(rgb) {
                None => Ok(FrameKind::Silhouette),
                Some((i, [r, g, b])) => {
                    Err(FrameError::NotSilhouette { frame: label.into(), x: i % width, y: i / width, r, g, b })
                }
            },
            Expect::Auto => {
                let kind = if first_color_pixel(rgb).is_none() { FrameKind::Silhouette } else { FrameKind::Color };
                match &self.first {
                    None => {
                        self.first = Some((kind, label.into()));
                        Ok(kind)
                    }
                    Some((first_kind, _)) if *first_kind == kind => Ok(kind),
                    Some((first_kind, first)) => Err(FrameError::MixedKinds {
                        frame: label.into(),
                        kind,
                        first: first.clone(),
                        first_kind: *first_kind,
                    }),
                }
            }
        }
    }
}

/// Whether a file name is a PNG or JPEG image by its extension, in any case.
fn is_image_name(path: &Path) -> bool {
    path.extension()
        .and_then(OsStr::to_str)
        .is_some_and(|e| ["png", "jpg", "jpeg"].iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// A file `render` writes beside its frames (`camera.json`,
/// `background.png`): in `input` when it is a folder, else next to it.
pub fn beside_frames(input: &Path, name: &str) -> Option<PathBuf> {
    let parent = input.parent().map(|p| p.join(name));
    [input.is_dir().then(|| input.join(name)), parent].into_iter().flatten().find(|p| p.is_file())
}

/// A sequence of frames: the images of a folder, or a video's frames.
///
/// - **Folder**: every `.png`, `.jpg` and `.jpeg` file in it (extension in
///   any case; not in subfolders), sorted by file name compared byte by
///   byte, so `000010.png` follows `000009.png` when numbers are
///   zero-padded, but `10.png` comes before `9.png`. Other files are
///   ignored. Frames can also be read by index ([`FrameSource::frame`]).
/// - **Video**: any other file, decoded by `ffmpeg` in a child process, in
///   order only.
///
/// The frame size is known once the source is open (from the first image's
/// header, or the video's first frame) and every frame must have it.
#[derive(Debug)]
pub struct FrameSource {
    path: String,
    input: Input,
    rule: KindRule,
    width: usize,
    height: usize,
    /// The index of the next frame [`FrameSource::next_frame`] gives.
    next: usize,
}

#[derive(Debug)]
enum Input {
    Folder(Vec<PathBuf>),
    Video(Box<Video>),
}

impl FrameSource {
    /// Opens a folder of images or a video file.
    pub fn open(path: impl AsRef<Path>, expect: Expect) -> Result<FrameSource, FrameError> {
        FrameSource::open_with(path.as_ref(), expect, OsStr::new(FFMPEG))
    }

    /// [`FrameSource::open`] with the decoder program named, so tests can
    /// name one that does not exist.
    fn open_with(path: &Path, expect: Expect, ffmpeg: &OsStr) -> Result<FrameSource, FrameError> {
        let label = path.display().to_string();
        let meta = fs::metadata(path).map_err(|source| match source.kind() {
            io::ErrorKind::NotFound => FrameError::Missing { path: label.clone() },
            _ => FrameError::Unreadable { path: label.clone(), source },
        })?;
        let (input, width, height) = if meta.is_dir() {
            let files = list_images(path)?;
            let (width, height) = image_size(&files[0])?;
            (Input::Folder(files), width, height)
        } else {
            let video = Video::spawn(ffmpeg, path)?;
            let (width, height) = video.size();
            (Input::Video(Box::new(video)), width, height)
        };
        Ok(FrameSource { path: label, input, rule: KindRule::new(expect), width, height, next: 0 })
    }

    /// The folder or video, as given.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Frame width, pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Frame height, pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Whether the frames come from a video (read in order only).
    pub fn is_video(&self) -> bool {
        matches!(self.input, Input::Video(_))
    }

    /// How many frames a folder holds; `None` for a video, whose length is
    /// known only once it has been read.
    pub fn frame_count(&self) -> Option<usize> {
        match &self.input {
            Input::Folder(files) => Some(files.len()),
            Input::Video(_) => None,
        }
    }

    /// The image file of a folder's frame `index`.
    pub fn frame_path(&self, index: usize) -> Option<&Path> {
        match &self.input {
            Input::Folder(files) => files.get(index).map(PathBuf::as_path),
            Input::Video(_) => None,
        }
    }

    /// An error unless the frames are `width × height`, the camera's size.
    pub fn check_size(&self, width: usize, height: usize) -> Result<(), FrameError> {
        if (self.width, self.height) == (width, height) {
            return Ok(());
        }
        Err(FrameError::WrongSize {
            path: self.path.clone(),
            width: self.width,
            height: self.height,
            camera_width: width,
            camera_height: height,
        })
    }

    /// A folder's frame `index`, read out of turn (the order
    /// [`FrameSource::next_frame`] follows is unchanged). Videos refuse.
    pub fn frame(&mut self, index: usize) -> Result<Frame, FrameError> {
        let Input::Folder(files) = &self.input else {
            return Err(FrameError::NotSeekable { path: self.path.clone(), index });
        };
        let file = files.get(index).ok_or_else(|| FrameError::NoSuchFrame {
            path: self.path.clone(),
            index,
            count: files.len(),
        })?;
        let frame = read_image(file)?;
        self.accept(frame)
    }

    /// The next frame in order, `None` after the last. A folder goes on past
    /// a bad frame (its error is given in its place); a video ends at its
    /// first error.
    pub fn next_frame(&mut self) -> Option<Result<Frame, FrameError>> {
        let frame = match &mut self.input {
            Input::Folder(files) => read_image(files.get(self.next)?),
            Input::Video(video) => video.next_frame()?.map(|d| self.decoded(d)).map_err(FrameError::from),
        };
        self.next += 1;
        Some(frame.and_then(|frame| self.accept(frame)))
    }

    /// What ffmpeg said while decoding a video that still ended cleanly
    /// (such as a damaged stretch it skipped, or a last frame cut short), once
    /// the video has been read to its end.
    pub fn decoder_messages(&self) -> Option<&str> {
        match &self.input {
            Input::Video(video) => video.messages(),
            Input::Folder(_) => None,
        }
    }

    /// Why a video's decoder failed after its first frame, ending it early
    /// (the frames before were given), once it has.
    pub fn decoding_failed(&self) -> Option<&str> {
        match &self.input {
            Input::Video(video) => video.failed(),
            Input::Folder(_) => None,
        }
    }

    /// A video's decoded frame, labelled by the video and its number.
    fn decoded(&self, d: Decoded) -> Frame {
        Frame::from_rgb(format!("{}, frame {}", self.path, d.index), d.width, d.height, d.rgb)
    }

    /// At most `max` frames spread evenly over the source, for a background
    /// estimate, read as color whatever the source expects. A folder gives
    /// `min(max, frame count)` frames, the `i`-th of `k` from the middle of
    /// the `i`-th of `k` equal stretches. A video is decoded once more from
    /// its start by a second ffmpeg (the source's own place is kept), keeping
    /// every `s`-th frame and doubling `s` whenever more than `max` are kept,
    /// so a long video gives between `max / 2` and `max` evenly spaced
    /// frames and never holds more than `max + 1` at once; one that fails
    /// partway gives those of the frames it decoded.
    pub fn sample(&self, max: usize) -> Result<Vec<Frame>, FrameError> {
        let mut frames = Vec::new();
        if max == 0 {
            return Ok(frames);
        }
        match &self.input {
            Input::Folder(files) => {
                let k = max.min(files.len());
                for i in 0..k {
                    let frame = read_image(&files[(2 * i + 1) * files.len() / (2 * k)])?;
                    frames.push(self.sized(frame)?);
                }
            }
            Input::Video(video) => {
                let mut again = video.again()?;
                let (mut stride, mut index) = (1, 0);
                while let Some(decoded) = again.next_frame() {
                    let frame = self.sized(self.decoded(decoded?))?;
                    if index % stride == 0 {
                        frames.push(frame);
                        if frames.len() > max {
                            stride *= 2;
                            let mut i = 0;
                            frames.retain(|_| {
                                i += 1;
                                (i - 1) % 2 == 0
                            });
                        }
                    }
                    index += 1;
                }
            }
        }
        for frame in &mut frames {
            frame.kind = FrameKind::Color;
        }
        Ok(frames)
    }

    /// A frame checked against the source's size.
    fn sized(&self, frame: Frame) -> Result<Frame, FrameError> {
        if (frame.width, frame.height) == (self.width, self.height) {
            return Ok(frame);
        }
        Err(FrameError::MixedSizes {
            frame: frame.label,
            width: frame.width,
            height: frame.height,
            expected_width: self.width,
            expected_height: self.height,
        })
    }

    /// A frame checked against the source's size and kind rule.
    fn accept(&mut self, frame: Frame) -> Result<Frame, FrameError> {
        let mut frame = self.sized(frame)?;
        frame.kind = self.rule.check(&frame.label, frame.width, &frame.rgb)?;
        Ok(frame)
    }
}

impl Iterator for FrameSource {
    type Item = Result<Frame, FrameError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.next_frame()
    }
}

/// The images of a folder, sorted by name; an error if there are none.
fn list_images(dir: &Path) -> Result<Vec<PathBuf>, FrameError> {
    let label = || dir.display().to_string();
    let unreadable = |source| FrameError::Unreadable { path: label(), source };
    let mut files = Vec::new();
    for entry in fs::read_dir(dir).map_err(unreadable)? {
        let entry = entry.map_err(unreadable)?;
        let path = entry.path();
        // A folder named like an image is not one; a link to an image is.
        if is_image_name(&path) && !path.is_dir() {
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err(FrameError::EmptyFolder { path: label() });
    }
    files.sort_by(|a, b| a.file_name().map(OsStr::as_encoded_bytes).cmp(&b.file_name().map(OsStr::as_encoded_bytes)));
    Ok(files)
}

/// An image's size from its header, without decoding it.
fn image_size(path: &Path) -> Result<(usize, usize), FrameError> {
    let label = || path.display().to_string();
    let bytes = fs::read(path).map_err(|source| FrameError::Unreadable { path: label(), source })?;
    let reader = ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|source| FrameError::Unreadable { path: label(), source })?;
    let (w, h) = reader.into_dimensions().map_err(|e| FrameError::Corrupt { path: label(), problem: e.to_string() })?;
    Ok((w as usize, h as usize))
}

#[cfg(test)]
mod tests;
