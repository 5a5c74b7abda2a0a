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
mod tests {
    use super::*;
    use crate::vision::video::probe_video;
    use image::{ImageEncoder, RgbImage};
    use std::process::Command;
    use tempfile::TempDir;

    /// A deterministic color image: a gradient with a pattern, so every
    /// pixel differs from its neighbours and nothing is near black or white.
    fn color_rgb(width: usize, height: usize, seed: usize) -> Vec<u8> {
        let mut rgb = Vec::with_capacity(width * height * 3);
        for y in 0..height {
            for x in 0..width {
                rgb.push((60 + (x * 7 + seed * 13) % 120) as u8);
                rgb.push((60 + (y * 11 + seed * 5) % 120) as u8);
                rgb.push((60 + (x * 3 + y * 5 + seed) % 120) as u8);
            }
        }
        rgb
    }

    /// A silhouette: white inside a rectangle, black elsewhere.
    fn silhouette_rgb(width: usize, height: usize, x0: usize) -> Vec<u8> {
        let mut rgb = vec![0; width * height * 3];
        for y in height / 4..3 * height / 4 {
            for x in x0..(x0 + width / 3).min(width) {
                rgb[3 * (y * width + x)..3 * (y * width + x) + 3].fill(255);
            }
        }
        rgb
    }

    fn write_png(path: &Path, width: usize, height: usize, rgb: &[u8]) {
        RgbImage::from_raw(width as u32, height as u32, rgb.to_vec()).unwrap().save(path).unwrap();
    }

    fn write_jpeg(path: &Path, width: usize, height: usize, rgb: &[u8]) {
        let mut bytes = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 95)
            .write_image(rgb, width as u32, height as u32, image::ExtendedColorType::Rgb8)
            .unwrap();
        fs::write(path, bytes).unwrap();
    }

    fn frames(source: &mut FrameSource) -> Vec<Result<Frame, FrameError>> {
        std::iter::from_fn(|| source.next_frame()).collect()
    }

    #[test]
    fn a_folder_gives_its_images_sorted_by_name_and_ignores_other_files() {
        let dir = TempDir::new().unwrap();
        let (w, h) = (8, 6);
        write_png(&dir.path().join("000002.png"), w, h, &color_rgb(w, h, 2));
        write_png(&dir.path().join("000000.PNG"), w, h, &color_rgb(w, h, 0));
        write_jpeg(&dir.path().join("000001.Jpeg"), w, h, &color_rgb(w, h, 1));
        write_jpeg(&dir.path().join("000003.jpg"), w, h, &color_rgb(w, h, 3));
        fs::write(dir.path().join("notes.txt"), "not a frame").unwrap();
        fs::write(dir.path().join("truth.csv"), "frame\n0\n").unwrap();
        fs::create_dir(dir.path().join("sub.png")).unwrap();
        write_png(&dir.path().join("sub.png/000000.png"), w, h, &color_rgb(w, h, 9));

        let mut source = FrameSource::open(dir.path(), Expect::Color).unwrap();
        assert_eq!((source.width(), source.height(), source.frame_count()), (w, h, Some(4)));
        assert!(!source.is_video());
        let names: Vec<_> =
            (0..4).map(|i| source.frame_path(i).unwrap().file_name().unwrap().to_str().unwrap().to_owned()).collect();
        assert_eq!(names, ["000000.PNG", "000001.Jpeg", "000002.png", "000003.jpg"]);
        let read = frames(&mut source);
        assert_eq!(read.len(), 4);
        let first = read[0].as_ref().unwrap();
        // PNG is lossless: the pixels come back exactly.
        assert_eq!(first.rgb(), color_rgb(w, h, 0));
        assert_eq!(first.label(), dir.path().join("000000.PNG").display().to_string());
        assert!(read.iter().all(|f| f.as_ref().unwrap().kind() == FrameKind::Color));
        // Random access reads the same frame and leaves the order alone.
        assert_eq!(source.frame(2).unwrap().rgb(), read[2].as_ref().unwrap().rgb());
        assert!(matches!(source.frame(4), Err(FrameError::NoSuchFrame { index: 4, count: 4, .. })));
    }

    #[test]
    fn names_sort_byte_by_byte() {
        let dir = TempDir::new().unwrap();
        for name in ["b.png", "10.png", "9.png", "B.png", "a.png"] {
            write_png(&dir.path().join(name), 2, 2, &[0; 12]);
        }
        let source = FrameSource::open(dir.path(), Expect::Auto).unwrap();
        let names: Vec<_> = (0..5).map(|i| source.frame_path(i).unwrap().file_name().unwrap().to_owned()).collect();
        assert_eq!(names, ["10.png", "9.png", "B.png", "a.png", "b.png"]);
    }

    #[test]
    fn a_folder_without_images_is_an_error_naming_it() {
        let dir = TempDir::new().unwrap();
        fs::write(dir.path().join("readme.txt"), "no frames here").unwrap();
        let error = FrameSource::open(dir.path(), Expect::Auto).unwrap_err();
        assert!(matches!(error, FrameError::EmptyFolder { .. }), "{error}");
        let message = error.to_string();
        assert!(message.starts_with(&dir.path().display().to_string()) && message.contains("no PNG or JPEG"));
    }

    #[test]
    fn a_missing_path_is_an_error_naming_it() {
        let dir = TempDir::new().unwrap();
        let missing = dir.path().join("nowhere");
        let error = FrameSource::open(&missing, Expect::Auto).unwrap_err();
        assert_eq!(error.to_string(), format!("{}: no such file or folder", missing.display()));
        let error = read_image(&missing.join("background.png")).unwrap_err();
        assert!(matches!(error, FrameError::Missing { .. }), "{error}");
    }

    #[test]
    fn truncated_and_corrupt_images_are_errors_naming_the_file() {
        let dir = TempDir::new().unwrap();
        let (w, h) = (16, 12);
        write_png(&dir.path().join("000000.png"), w, h, &color_rgb(w, h, 0));
        write_png(&dir.path().join("000001.png"), w, h, &color_rgb(w, h, 1));
        write_jpeg(&dir.path().join("000002.jpg"), w, h, &color_rgb(w, h, 2));
        fs::write(dir.path().join("000003.png"), b"this is no image").unwrap();
        for name in ["000001.png", "000002.jpg"] {
            let path = dir.path().join(name);
            let bytes = fs::read(&path).unwrap();
            fs::write(&path, &bytes[..bytes.len() * 2 / 3]).unwrap();
        }
        let mut source = FrameSource::open(dir.path(), Expect::Color).unwrap();
        let read = frames(&mut source);
        assert_eq!(read.len(), 4, "a folder goes on past a bad frame");
        assert!(read[0].is_ok());
        for (i, name) in [(1, "000001.png"), (2, "000002.jpg"), (3, "000003.png")] {
            let error = read[i].as_ref().unwrap_err();
            assert!(matches!(error, FrameError::Corrupt { .. }), "{error}");
            let message = error.to_string();
            assert!(message.starts_with(&dir.path().join(name).display().to_string()), "{message}");
            assert!(message.contains("not a readable PNG or JPEG image"), "{message}");
        }
    }

    #[test]
    fn an_unreadable_file_is_an_error_naming_it() {
        let dir = TempDir::new().unwrap();
        let path = dir.path().join("000000.png");
        write_png(&path, 4, 4, &[0; 48]);
        // A folder where a file is expected cannot be read as one.
        let error = read_image(dir.path()).unwrap_err();
        assert!(matches!(error, FrameError::Unreadable { .. }), "{error}");
        assert!(error.to_string().starts_with(&format!("{}: cannot read: ", dir.path().display())));
    }

    #[test]
    fn frames_of_another_size_are_errors_naming_both_sizes() {
        let dir = TempDir::new().unwrap();
        write_png(&dir.path().join("000000.png"), 160, 120, &color_rgb(160, 120, 0));
        write_png(&dir.path().join("000012.png"), 160, 121, &color_rgb(160, 121, 1));
        let mut source = FrameSource::open(dir.path(), Expect::Auto).unwrap();
        let read = frames(&mut source);
        let error = read[1].as_ref().unwrap_err();
        assert_eq!(
            error.to_string(),
            format!("{}: the frame is 160×121; earlier frames are 160×120", dir.path().join("000012.png").display())
        );
        assert!(source.check_size(160, 120).is_ok());
        let error = source.check_size(320, 240).unwrap_err();
        assert_eq!(error.to_string(), format!("{}: frames are 160×120; the camera is 320×240", dir.path().display()));
    }

    #[test]
    fn a_color_frame_where_silhouettes_were_expected_is_an_error_naming_the_file_and_pixel() {
        let dir = TempDir::new().unwrap();
        let (w, h) = (6, 4);
        write_png(&dir.path().join("000000.png"), w, h, &silhouette_rgb(w, h, 1));
        let mut color = silhouette_rgb(w, h, 1);
        color[3 * (2 * w + 5)..3 * (2 * w + 5) + 3].copy_from_slice(&[200, 40, 40]);
        write_png(&dir.path().join("000001.png"), w, h, &color);
        let mut source = FrameSource::open(dir.path(), Expect::Silhouettes).unwrap();
        let read = frames(&mut source);
        assert_eq!(read[0].as_ref().unwrap().kind(), FrameKind::Silhouette);
        let error = read[1].as_ref().unwrap_err();
        let message = error.to_string();
        assert!(message.starts_with(&dir.path().join("000001.png").display().to_string()), "{message}");
        assert!(message.contains("a color frame where silhouettes were expected: pixel (5, 2) is (200, 40, 40)"));
    }

    #[test]
    fn auto_is_decided_by_the_first_frame_and_color_accepts_anything() {
        let dir = TempDir::new().unwrap();
        let (w, h) = (6, 4);
        write_png(&dir.path().join("000000.png"), w, h, &silhouette_rgb(w, h, 0));
        write_png(&dir.path().join("000001.png"), w, h, &silhouette_rgb(w, h, 2));
        write_png(&dir.path().join("000002.png"), w, h, &color_rgb(w, h, 0));
        let mut source = FrameSource::open(dir.path(), Expect::Auto).unwrap();
        let read = frames(&mut source);
        assert_eq!(read[1].as_ref().unwrap().kind(), FrameKind::Silhouette);
        let message = read[2].as_ref().unwrap_err().to_string();
        assert!(message.contains("the frame is a color frame, but the first frame"), "{message}");
        assert!(message.contains(&format!("({}) is a silhouette", dir.path().join("000000.png").display())));

        let mut source = FrameSource::open(dir.path(), Expect::Color).unwrap();
        assert!(frames(&mut source).iter().all(|f| f.as_ref().unwrap().kind() == FrameKind::Color));
    }

    #[test]
    fn silhouette_pixels_are_near_black_or_near_white_in_every_channel() {
        let kind = |p: [u8; 3]| Frame::from_rgb("test", 2, 1, [[0, 0, 0], p].concat()).kind();
        for p in [[0, 0, 0], [32, 32, 32], [0, 32, 17], [224, 224, 224], [255, 224, 240], [255, 255, 255]] {
            assert_eq!(kind(p), FrameKind::Silhouette, "{p:?}");
        }
        for p in [[33, 0, 0], [223, 255, 255], [128, 128, 128], [255, 0, 0], [0, 255, 255]] {
            assert_eq!(kind(p), FrameKind::Color, "{p:?}");
        }
        // A color pixel past the first block of pixels is found and located.
        let mut rgb = vec![255; 3 * 300];
        rgb[3 * 250 + 1] = 100;
        assert_eq!(first_color_pixel(&rgb), Some((250, [255, 100, 255])));
    }

    #[test]
    fn a_folder_is_sampled_evenly() {
        let dir = TempDir::new().unwrap();
        for i in 0..10 {
            write_png(&dir.path().join(format!("{i:06}.png")), 4, 3, &color_rgb(4, 3, i));
        }
        let source = FrameSource::open(dir.path(), Expect::Silhouettes).unwrap();
        let labels: Vec<_> = source.sample(4).unwrap().iter().map(|f| f.label().to_owned()).collect();
        let expected: Vec<_> =
            [1, 3, 6, 8].map(|i| dir.path().join(format!("{i:06}.png")).display().to_string()).into();
        assert_eq!(labels, expected);
        assert_eq!(source.sample(64).unwrap().len(), 10);
    }

    #[test]
    fn truncated_jpeg_is_told_by_its_missing_end_marker() {
        assert!(ends_with_jpeg_eoi(&[0xFF, 0xD8, 0xFF, 0xD9]));
        assert!(ends_with_jpeg_eoi(&[0xFF, 0xD8, 0xFF, 0xD9, 0, 0]));
        assert!(!ends_with_jpeg_eoi(&[0xFF, 0xD8, 0x12, 0x34]));
        assert!(!ends_with_jpeg_eoi(&[0xD9]));
    }

    /// Whether ffmpeg runs. Under CI it must: `bash scripts/test.sh`
    /// installs it.
    fn ffmpeg_on_path() -> bool {
        let found = Command::new(FFMPEG).arg("-version").output().is_ok_and(|o| o.status.success());
        assert!(found || std::env::var_os("CI").is_none(), "ffmpeg is not on PATH: under CI it is required");
        found
    }

    #[test]
    fn a_video_states_its_own_frame_rate_and_where_it_can_its_length() {
        if !ffmpeg_on_path() {
            return;
        }
        let dir = TempDir::new().unwrap();
        // Matroska states no frame count; AVI does.
        for (name, states_count) in [("clip.mkv", false), ("clip.avi", true)] {
            let video = dir.path().join(name);
            let made = Command::new(FFMPEG)
                .args(["-v", "error", "-f", "lavfi", "-i", "testsrc=size=32x24:rate=25", "-frames:v", "5"])
                .args(["-r", "29.97"])
                .arg(&video)
                .status()
                .unwrap();
            assert!(made.success());
            let probe = probe_video(&video).unwrap();
            assert!((probe.rate.unwrap() - 29.97).abs() < 0.01, "{name}: {probe:?}");
            let decoded = frames(&mut FrameSource::open(&video, Expect::Color).unwrap()).len();
            assert_eq!(probe.frames, states_count.then_some(decoded), "{name}");
        }
    }

    #[test]
    fn without_ffmpeg_a_video_is_an_error_telling_how_to_install_it() {
        let dir = TempDir::new().unwrap();
        let video = dir.path().join("clip.mkv");
        fs::write(&video, b"not read").unwrap();
        let error = FrameSource::open_with(&video, Expect::Auto, OsStr::new("no-such-ffmpeg-program")).unwrap_err();
        let message = error.to_string();
        assert!(matches!(error, FrameError::Video(VideoError::FfmpegMissing { .. })), "{message}");
        assert!(message.starts_with(&video.display().to_string()), "{message}");
        assert!(message.contains("install it with `bash scripts/install-tools.sh ffmpeg` (Debian's ffmpeg package)"));
        if !ffmpeg_on_path() {
            let error = FrameSource::open(&video, Expect::Auto).unwrap_err();
            assert!(matches!(error, FrameError::Video(VideoError::FfmpegMissing { .. })), "{error}");
        }
    }

    /// Encodes frames losslessly (FFV1 in Matroska) with ffmpeg.
    fn encode_video(dir: &Path, frames: &[Vec<u8>], width: usize, height: usize) -> PathBuf {
        let input = dir.join("in");
        fs::create_dir(&input).unwrap();
        for (i, rgb) in frames.iter().enumerate() {
            write_png(&input.join(format!("{i:06}.png")), width, height, rgb);
        }
        let video = dir.join("clip.mkv");
        let status = Command::new(FFMPEG)
            .args(["-nostdin", "-v", "error", "-framerate", "15", "-i"])
            .arg(input.join("%06d.png"))
            .args(["-c:v", "ffv1"])
            .arg(&video)
            .status()
            .unwrap();
        assert!(status.success());
        video
    }

    #[test]
    fn a_lossless_video_reads_back_exactly_when_ffmpeg_is_installed() {
        if !ffmpeg_on_path() {
            eprintln!("ffmpeg is not on PATH: the video round trip is not run (see the install-error test)");
            return;
        }
        let dir = TempDir::new().unwrap();
        let (w, h) = (24, 18);
        let originals: Vec<_> = (0..7).map(|i| color_rgb(w, h, i)).collect();
        let video = encode_video(dir.path(), &originals, w, h);

        let mut source = FrameSource::open(&video, Expect::Auto).unwrap();
        assert!(source.is_video() && source.frame_count().is_none());
        assert_eq!((source.width(), source.height()), (w, h));
        assert!(matches!(source.frame(0), Err(FrameError::NotSeekable { .. })));
        let read: Vec<_> = frames(&mut source).into_iter().map(Result::unwrap).collect();
        assert_eq!(read.len(), originals.len());
        for (i, (frame, original)) in read.iter().zip(&originals).enumerate() {
            assert_eq!(frame.rgb(), &original[..], "frame {i}");
            assert_eq!(frame.label(), format!("{}, frame {i}", video.display()));
            assert_eq!(frame.kind(), FrameKind::Color);
        }
        assert!(source.next_frame().is_none());
        assert_eq!(source.decoder_messages(), None);

        // Sampling decodes the video again: 7 frames kept at most 3 at a
        // time end as every fourth.
        let sample: Vec<_> = source.sample(3).unwrap().into_iter().map(|f| f.rgb().to_vec()).collect();
        assert_eq!(sample, [originals[0].clone(), originals[4].clone()]);

        // A silhouette video promised and a color one given names the frame.
        let mut source = FrameSource::open(&video, Expect::Silhouettes).unwrap();
        let message = source.next_frame().unwrap().unwrap_err().to_string();
        assert!(message.starts_with(&format!("{}, frame 0: a color frame", video.display())), "{message}");

        // Leaving a video before its end stops ffmpeg (the drop must not hang).
        let mut source = FrameSource::open(&video, Expect::Color).unwrap();
        assert!(source.next_frame().unwrap().is_ok());
        drop(source);
    }

    #[test]
    fn a_truncated_video_gives_its_whole_frames_and_ends() {
        if !ffmpeg_on_path() {
            eprintln!("ffmpeg is not on PATH: the truncated-video test is not run");
            return;
        }
        let dir = TempDir::new().unwrap();
        let (w, h) = (32, 24);
        let originals: Vec<_> = (0..20).map(|i| color_rgb(w, h, i)).collect();
        let video = encode_video(dir.path(), &originals, w, h);
        let bytes = fs::read(&video).unwrap();
        fs::write(&video, &bytes[..bytes.len() / 2]).unwrap();

        let mut source = FrameSource::open(&video, Expect::Color).unwrap();
        let whole: Vec<_> = frames(&mut source).into_iter().map(Result::unwrap).collect();
        assert!(!whole.is_empty() && whole.len() < originals.len(), "{} frames", whole.len());
        for (frame, original) in whole.iter().zip(&originals) {
            assert_eq!(frame.rgb(), &original[..]);
        }
        // The end is clean with ffmpeg's complaint kept, or ffmpeg failed
        // there and the source says why.
        match source.decoding_failed() {
            Some(failure) => assert!(failure.contains("ffmpeg failed after"), "{failure}"),
            None => assert!(source.decoder_messages().is_some_and(|m| !m.is_empty())),
        }
        assert!(source.next_frame().is_none());
    }

    #[test]
    fn a_file_that_is_no_video_is_an_error_with_ffmpegs_message() {
        if !ffmpeg_on_path() {
            eprintln!("ffmpeg is not on PATH: the not-a-video test is not run");
            return;
        }
        let dir = TempDir::new().unwrap();
        let path = dir.path().join("clip.mp4");
        fs::write(&path, b"this is no video at all").unwrap();
        let error = FrameSource::open(&path, Expect::Auto).unwrap_err();
        let message = error.to_string();
        assert!(matches!(error, FrameError::Video(VideoError::Failed { frames: 0, .. })), "{message}");
        assert!(message.starts_with(&format!("{}: ffmpeg failed after 0 frames: ", path.display())), "{message}");
        assert!(message.len() > path.display().to_string().len() + 40, "ffmpeg's own words follow: {message}");
    }
}
