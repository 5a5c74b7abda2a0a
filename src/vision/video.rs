//! Videos decoded by `ffmpeg` in a child process, one frame at a time, and
//! what their container states of them (`ffprobe`).

use std::ffi::{OsStr, OsString};
use std::fmt;
use std::io::{self, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, Stdio};
use std::thread::JoinHandle;
use thiserror::Error;

/// Why a video cannot be read, each naming the file.
#[derive(Debug, Error)]
pub enum VideoError {
    #[error(
        "{path}: decoding video needs `{program}`, which is not on PATH; install it with \
         `bash scripts/install-tools.sh ffmpeg` (Debian's ffmpeg package)"
    )]
    FfmpegMissing { path: String, program: String },
    #[error("{path}: cannot run ffmpeg: {source}")]
    FfmpegIo { path: String, source: io::Error },
    #[error("{path}: ffmpeg failed after {frames} frames: {message}")]
    Failed { path: String, frames: usize, message: String },
}

/// One decoded frame: its index in the video, size and pixels (RGB,
/// row-major from the top-left).
pub struct Decoded {
    pub index: usize,
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
}

/// The program that decodes videos.
pub const FFMPEG: &str = "ffmpeg";
/// The program that reads what a video's container states: its frame rate
/// and frame count (it comes with ffmpeg).
const FFPROBE: &str = "ffprobe";

/// What a video's container states of its video stream, read by ffprobe
/// before decoding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VideoProbe {
    /// Frames per second: the average rate, else the nominal one; `None`
    /// when it states neither (a rate of 0/0).
    pub rate: Option<f64>,
    /// The number of frames, where the container states it (AVI and MP4
    /// do, and keep stating it when the file is cut short; Matroska does
    /// not).
    pub frames: Option<usize>,
}

/// Reads a video's [`VideoProbe`].
pub fn probe_video(path: &Path) -> Result<VideoProbe, VideoError> {
    let label = path.display().to_string();
    let output = Command::new(FFPROBE)
        .args(["-v", "error", "-select_streams", "v:0", "-show_entries"])
        .arg("stream=avg_frame_rate,r_frame_rate,nb_frames")
        .args(["-of", "default=noprint_wrappers=1"])
        .arg(path)
        .stdin(Stdio::null())
        .output()
        .map_err(|source| match source.kind() {
            io::ErrorKind::NotFound => VideoError::FfmpegMissing { path: label.clone(), program: FFPROBE.into() },
            _ => VideoError::FfmpegIo { path: label.clone(), source },
        })?;
    if !output.status.success() {
        let message = String::from_utf8_lossy(&output.stderr).trim().to_string();
        return Err(VideoError::Failed { path: label, frames: 0, message });
    }
    Ok(parse_probe(&String::from_utf8_lossy(&output.stdout)))
}

/// A [`VideoProbe`] from ffprobe's `key=value` lines: the rate from
/// `avg_frame_rate` when it is a positive finite `num/den`, else
/// `r_frame_rate`; the frames from `nb_frames` when it is a positive count
/// (ffprobe writes `N/A` when the container does not say).
fn parse_probe(text: &str) -> VideoProbe {
    let value = |key: &str| text.lines().find_map(|l| l.trim().strip_prefix(key)?.strip_prefix('='));
    let rate = |key: &str| {
        let value = value(key)?;
        let (num, den) = value.split_once('/').unwrap_or((value, "1"));
        let rate = num.trim().parse::<f64>().ok()? / den.trim().parse::<f64>().ok()?;
        (rate.is_finite() && rate > 0.0).then_some(rate)
    };
    let frames = value("nb_frames").and_then(|v| v.trim().parse::<usize>().ok()).filter(|&n| n > 0);
    VideoProbe { rate: rate("avg_frame_rate").or_else(|| rate("r_frame_rate")), frames }
}

/// ffmpeg's messages without the memory addresses it tags them with
/// (`[h264 @ 0x55d0c2a1b2c0] …` becomes `[h264] …`), so what a run keeps of
/// them is the same from run to run.
fn without_addresses(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(" @ 0x") {
        out.push_str(&rest[..at]);
        let after = &rest[at + " @ 0x".len()..];
        let digits = after.find(|c: char| !c.is_ascii_hexdigit()).unwrap_or(after.len());
        if digits == 0 {
            out.push_str(" @ 0x");
        }
        rest = &after[digits..];
    }
    out.push_str(rest);
    out
}

/// A video decoded by ffmpeg into a stream of binary PPM images, one per
/// frame. Each image carries its own size, so a video whose frames ffmpeg
/// turns (rotation metadata) or resizes mid-stream is read as it comes out
/// rather than cut at a size guessed beforehand.
pub struct Video {
    program: OsString,
    file: PathBuf,
    /// The file as error messages name it.
    label: String,
    child: Child,
    stdout: Option<BufReader<ChildStdout>>,
    /// Collects ffmpeg's messages while frames are read, so a full stderr
    /// pipe never stalls it.
    stderr: Option<JoinHandle<String>>,
    width: usize,
    height: usize,
    /// The first frame's header, read at the start to learn the size.
    pending: Option<(usize, usize)>,
    frames: usize,
    messages: Option<String>,
    /// Why decoding stopped after the first frame, when it failed there.
    failed: Option<String>,
}

impl fmt::Debug for Video {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Video").field("file", &self.file).field("frames", &self.frames).finish_non_exhaustive()
    }
}

/// How a PPM header read ended.
enum Header {
    Size(usize, usize),
    /// The stream ended at a frame boundary.
    End,
    /// The stream ended, or held something else, inside a header.
    Broken,
}

impl Video {
    /// Starts `program` (ffmpeg) on `file` and reads the first frame's
    /// header.
    pub fn spawn(program: &OsStr, file: &Path) -> Result<Video, VideoError> {
        let label = file.display().to_string();
        let mut child = Command::new(program)
            .args(["-nostdin", "-v", "error", "-i"])
            .arg(file)
            .args(["-f", "image2pipe", "-c:v", "ppm", "-pix_fmt", "rgb24", "-"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| match source.kind() {
                io::ErrorKind::NotFound => {
                    VideoError::FfmpegMissing { path: label.clone(), program: program.to_string_lossy().into() }
                }
                _ => VideoError::FfmpegIo { path: label.clone(), source },
            })?;
        let stdout = child.stdout.take().map(BufReader::new);
        let stderr = child.stderr.take().map(|mut pipe| {
            std::thread::spawn(move || {
                let mut text = Vec::new();
                // A read error only shortens the message; the exit status still tells failure.
                let _ = pipe.read_to_end(&mut text);
                without_addresses(String::from_utf8_lossy(&text).trim())
            })
        });
        let mut video = Video {
            program: program.to_owned(),
            file: file.to_owned(),
            label: label.clone(),
            child,
            stdout,
            stderr,
            width: 0,
            height: 0,
            pending: None,
            frames: 0,
            messages: None,
            failed: None,
        };
        match video.read_header() {
            Ok(Header::Size(w, h)) => {
                (video.width, video.height) = (w, h);
                video.pending = Some((w, h));
                Ok(video)
            }
            Ok(Header::End | Header::Broken) => {
                video.finish()?;
                let message = video.messages.take().unwrap_or_else(|| "the video has no frames".into());
                Err(VideoError::Failed { path: label, frames: 0, message })
            }
            Err(source) => Err(VideoError::FfmpegIo { path: label, source }),
        }
    }

    /// Another decoder of the same file, from its start.
    pub fn again(&self) -> Result<Video, VideoError> {
        Video::spawn(&self.program, &self.file)
    }

    /// Frame width and height, pixels, as the first frame gave them.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The next frame: its index, size and pixels (RGB, row-major); `None`
    /// at the end. A decoder that fails after the first frame ends the
    /// video there, the frames before it kept ([`Video::failed`] says
    /// why): a file cut short or damaged partway is still read up to the
    /// damage.
    pub fn next_frame(&mut self) -> Option<Result<Decoded, VideoError>> {
        match self.decode()? {
            Err(error) if self.frames > 0 => {
                self.failed = Some(error.to_string());
                None
            }
            decoded => Some(decoded),
        }
    }

    /// Why decoding stopped after the first frame, once it has.
    pub fn failed(&self) -> Option<&str> {
        self.failed.as_deref()
    }

    /// What ffmpeg said while decoding a video that still ended cleanly.
    pub fn messages(&self) -> Option<&str> {
        self.messages.as_deref()
    }

    fn decode(&mut self) -> Option<Result<Decoded, VideoError>> {
        self.stdout.as_ref()?;
        let header = match self.pending.take() {
            Some((w, h)) => Ok(Header::Size(w, h)),
            None => self.read_header(),
        };
        let (width, height) = match header {
            Ok(Header::Size(w, h)) => (w, h),
            Ok(Header::End) => return self.finish().err().map(Err),
            Ok(Header::Broken) => {
                self.note("the stream ended inside a frame header");
                return self.finish().err().map(Err);
            }
            Err(source) => return self.fail(VideoError::FfmpegIo { path: self.label.clone(), source }),
        };
        let mut rgb = vec![0; width * height * 3];
        let stdout = self.stdout.as_mut().expect("checked above");
        match read_full(stdout, &mut rgb) {
            Ok(n) if n == rgb.len() => {}
            Ok(n) => {
                self.note(&format!("the stream ended {n} bytes into frame {}", self.frames));
                return self.finish().err().map(Err);
            }
            Err(source) => return self.fail(VideoError::FfmpegIo { path: self.label.clone(), source }),
        }
        let index = self.frames;
        self.frames += 1;
        Some(Ok(Decoded { index, width, height, rgb }))
    }

    /// Reads a binary PPM header (`P6`, width, height, 255, each after
    /// whitespace, and one whitespace byte before the pixels), as ffmpeg's
    /// PPM encoder writes it.
    fn read_header(&mut self) -> io::Result<Header> {
        let stdout = self.stdout.as_mut().expect("read only while the stream is open");
        let mut magic = [0u8; 2];
        match read_full(stdout, &mut magic)? {
            0 => return Ok(Header::End),
            2 if magic == *b"P6" => {}
            _ => return Ok(Header::Broken),
        }
        let mut fields = [0usize; 3];
        for field in &mut fields {
            let mut byte = [0u8; 1];
            let mut digits = 0;
            loop {
                if read_full(stdout, &mut byte)? == 0 {
                    return Ok(Header::Broken);
                }
                match byte[0] {
                    b'0'..=b'9' if digits < 9 => {
                        *field = *field * 10 + usize::from(byte[0] - b'0');
                        digits += 1;
                    }
                    b' ' | b'\t' | b'\n' | b'\r' if digits == 0 => {}
                    b' ' | b'\t' | b'\n' | b'\r' => break,
                    _ => return Ok(Header::Broken),
                }
            }
        }
        Ok(match fields {
            [w, h, 255] if w > 0 && h > 0 => Header::Size(w, h),
            _ => Header::Broken,
        })
    }

    /// Adds a line to what is reported when the video ends cleanly.
    fn note(&mut self, line: &str) {
        let messages = self.messages.get_or_insert_with(String::new);
        if !messages.is_empty() {
            messages.push('\n');
        }
        messages.push_str(line);
    }

    /// Closes the stream after an error: the video ends with it.
    fn fail(&mut self, error: VideoError) -> Option<Result<Decoded, VideoError>> {
        self.stdout = None;
        let _ = self.child.kill();
        let _ = self.child.wait();
        Some(Err(error))
    }

    /// Ends the stream and waits for ffmpeg: an error if it failed, with what
    /// it printed; otherwise its messages are kept for [`Video::messages`].
    fn finish(&mut self) -> Result<(), VideoError> {
        let path = self.label.as_str();
        self.stdout = None;
        let status = self.child.wait();
        let stderr = self.stderr.take().and_then(|t| t.join().ok()).unwrap_or_default();
        let failed = match status {
            Ok(status) if status.success() => None,
            Ok(status) => Some(if stderr.is_empty() { format!("ffmpeg exited with {status}") } else { stderr.clone() }),
            Err(source) => return Err(VideoError::FfmpegIo { path: path.into(), source }),
        };
        if let Some(message) = failed {
            return Err(VideoError::Failed { path: path.into(), frames: self.frames, message });
        }
        if !stderr.is_empty() {
            self.note(&stderr);
        }
        Ok(())
    }
}

impl Drop for Video {
    /// A video left before its end stops its ffmpeg rather than leaving it
    /// blocked on a full pipe.
    fn drop(&mut self) {
        if self.stdout.take().is_some() {
            let _ = self.child.kill();
        }
        let _ = self.child.wait();
        if let Some(thread) = self.stderr.take() {
            let _ = thread.join();
        }
    }
}

/// Reads until `buf` is full or the stream ends; how many bytes were read.
fn read_full(reader: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match reader.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_probe_reads_the_average_else_the_nominal_rate_and_a_stated_frame_count() {
        let rate = |text: &str| parse_probe(text).rate;
        assert_eq!(rate("r_frame_rate=30000/1001\navg_frame_rate=355/12\n"), Some(355.0 / 12.0));
        assert_eq!(rate("r_frame_rate=25/1\navg_frame_rate=0/0\n"), Some(25.0));
        assert_eq!(rate("r_frame_rate=0/0\navg_frame_rate=0/0\n"), None);
        assert_eq!(rate("avg_frame_rate=15\n"), Some(15.0));
        assert_eq!(rate(""), None);
        let frames = |text: &str| parse_probe(text).frames;
        assert_eq!(frames("avg_frame_rate=25/1\nnb_frames=243\n"), Some(243));
        assert_eq!(frames("nb_frames=N/A\n"), None);
        assert_eq!(frames("nb_frames=0\n"), None);
    }

    #[test]
    fn ffmpeg_s_memory_addresses_are_left_out_of_its_messages() {
        let said = "[mpeg4 @ 0x56388d941140] ac-tex damaged at 1 1\n[mpeg4 @ 0x56388d941140] Error at MB: 12";
        assert_eq!(without_addresses(said), "[mpeg4] ac-tex damaged at 1 1\n[mpeg4] Error at MB: 12");
        assert_eq!(without_addresses("a @ 0xz and @ 0x"), "a @ 0xz and @ 0x");
    }
}
