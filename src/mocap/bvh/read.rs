//! The tolerant BVH reader. The hierarchy is read line by line; the motion
//! section is streamed in blocks whose lines are parsed in parallel, so a
//! file of any size needs little more memory than its decoded values.

use super::number::{TokenError, TokenProblem, scan_fields, scan_line};
use super::{Bvh, BvhError, BvhErrorKind, Channel, Joint, Skeleton, Warning};
use glam::DVec3;
use rayon::prelude::*;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// Hierarchy lines are short; a longer one means this is not BVH text.
const MAX_HIERARCHY_LINE: usize = 1 << 16;
/// Bytes of motion text read and parsed at a time.
const BLOCK: usize = 8 << 20;
/// Below this many bytes a block is parsed on the calling thread.
const PARALLEL_MIN: usize = 1 << 20;
/// No real number token is longer than this, so a frame line of `c`
/// channels is at most `c × MAX_TOKEN` bytes.
const MAX_TOKEN: usize = 64;

/// Reads a BVH file.
pub fn read_bvh(path: &Path) -> Result<Bvh, BvhError> {
    let name = path.display().to_string();
    let fail = |kind| BvhError { path: name.clone(), line: None, kind: Box::new(kind) };
    let meta = std::fs::metadata(path).map_err(|e| fail(BvhErrorKind::Io(e)))?;
    if meta.is_dir() {
        return Err(fail(BvhErrorKind::IsDirectory));
    }
    let file = File::open(path).map_err(|e| fail(BvhErrorKind::Io(e)))?;
    Reader::new(BufReader::with_capacity(1 << 16, file), meta.len(), name).read()
}

/// Reads BVH text held in memory; `name` stands for the file in messages.
pub fn read_bvh_bytes(bytes: &[u8], name: &str) -> Result<Bvh, BvhError> {
    Reader::new(bytes, bytes.len() as u64, name.to_string()).read()
}

struct Reader<R> {
    input: R,
    size: u64,
    consumed: u64,
    path: String,
    /// Number of the last line read (1-based).
    line: usize,
    /// Whether a line with content has been read: binary data before one
    /// (after blank lines too) means the file is not BVH at all.
    content_seen: bool,
    buf: Vec<u8>,
    warnings: Vec<Warning>,
}

/// What the hierarchy parser has open.
enum Open {
    Joint(usize),
    EndSite { owner: usize, offset: Option<DVec3> },
}

impl<R: BufRead> Reader<R> {
    fn new(input: R, size: u64, path: String) -> Self {
        Reader { input, size, consumed: 0, path, line: 0, content_seen: false, buf: Vec::new(), warnings: Vec::new() }
    }

    fn error(&self, kind: BvhErrorKind) -> BvhError {
        BvhError { path: self.path.clone(), line: Some(self.line), kind: Box::new(kind) }
    }

    /// Unreadable text: before any content the file is simply not BVH.
    fn binary(&self, kind: BvhErrorKind) -> BvhError {
        if !self.content_seen {
            return self.error(BvhErrorKind::NotBvh { found: "binary data".into() });
        }
        self.error(kind)
    }

    fn warn(&mut self, code: &'static str, message: String) {
        self.warnings.push(Warning { code, message });
    }

    /// The next line with content, trimmed; `None` at end of file.
    fn next_line(&mut self) -> Result<Option<String>, BvhError> {
        loop {
            self.buf.clear();
            let read = (&mut self.input)
                .take(MAX_HIERARCHY_LINE as u64 + 1)
                .read_until(b'\n', &mut self.buf)
                .map_err(|e| self.error(BvhErrorKind::Io(e)))?;
            if read == 0 {
                return Ok(None);
            }
            self.consumed += read as u64;
            self.line += 1;
            if self.buf.len() > MAX_HIERARCHY_LINE {
                return Err(self.binary(BvhErrorKind::LineTooLong { limit: MAX_HIERARCHY_LINE }));
            }
            let Ok(text) = std::str::from_utf8(&self.buf) else {
                let found = "bytes that are not UTF-8 text".to_string();
                return Err(self.binary(BvhErrorKind::Expected { expected: "BVH text", found }));
            };
            let trimmed = text.trim_start_matches('\u{feff}').trim();
            if trimmed.contains('\0') {
                let found = "binary data".to_string();
                return Err(self.binary(BvhErrorKind::Expected { expected: "BVH text", found }));
            }
            if !trimmed.is_empty() {
                self.content_seen = true;
                return Ok(Some(trimmed.to_string()));
            }
        }
    }

    fn read(mut self) -> Result<Bvh, BvhError> {
        let first = match self.next_line()? {
            Some(l) => l,
            None => {
                return Err(BvhError { path: self.path.clone(), line: None, kind: Box::new(BvhErrorKind::Empty) });
            }
        };
        if !first.eq_ignore_ascii_case("hierarchy") {
            return Err(self.error(BvhErrorKind::NotBvh { found: quote(&first) }));
        }
        let skeleton = self.read_hierarchy()?;
        let (declared_frames, frame_time_s) = self.read_motion_header()?;
        let (data, frames) = self.read_frames(&skeleton, declared_frames)?;
        if frames as u64 != declared_frames {
            self.warn(
                "frame_count_mismatch",
                format!(
                    "the file declares {declared_frames} frames but holds {frames}; using the {frames} frames of data"
                ),
            );
        }
        Ok(Bvh { skeleton, frame_time_s, data, frames, declared_frames, warnings: self.warnings })
    }

    fn read_hierarchy(&mut self) -> Result<Skeleton, BvhError> {
        let mut joints: Vec<Joint> = Vec::new();
        let mut stack: Vec<Open> = Vec::new();
        // A ROOT, JOINT or End Site whose `{` has not been seen yet.
        let mut awaiting_brace: Option<Open> = None;
        let mut offset_seen: Vec<bool> = Vec::new();
        let mut roots = 0usize;
        let mut channel_total = 0usize;
        loop {
            let Some(line) = self.next_line()? else {
                let context = match (awaiting_brace.as_ref(), stack.last()) {
                    (Some(_), _) => "before a `{`".to_string(),
                    (None, Some(Open::Joint(j))) => {
                        format!(
                            "in the hierarchy: joint `{}` (line {}) is not closed",
                            joints[*j].name, joints[*j].line
                        )
                    }
                    (None, Some(Open::EndSite { owner, .. })) => {
                        format!("in the hierarchy: the End Site of `{}` is not closed", joints[*owner].name)
                    }
                    (None, None) => "before MOTION".to_string(),
                };
                return Err(self.error(BvhErrorKind::UnexpectedEof { context }));
            };
            let (keyword, rest) = split_keyword(&line);
            let keyword_lower = keyword.to_ascii_lowercase();

            if let Some(open) = awaiting_brace.take() {
                if !keyword.starts_with('{') {
                    return Err(self.error(BvhErrorKind::Expected { expected: "`{`", found: quote(&line) }));
                }
                stack.push(open);
                let after = line[1..].trim();
                if after.is_empty() {
                    continue;
                }
                // `{ OFFSET ...` on one line: read the remainder as its own line.
                return Err(
                    self.error(BvhErrorKind::Expected { expected: "a line break after `{`", found: quote(after) })
                );
            }

            match keyword_lower.as_str() {
                "root" | "joint" => {
                    let is_root = keyword_lower == "root";
                    let parent = match stack.last() {
                        None if is_root => None,
                        Some(Open::Joint(p)) if !is_root => Some(*p),
                        Some(Open::EndSite { .. }) => {
                            return Err(self.error(BvhErrorKind::Expected {
                                expected: "OFFSET or `}` inside End Site",
                                found: quote(&line),
                            }));
                        }
                        _ => {
                            let expected = if is_root { "JOINT inside a joint" } else { "ROOT at the top level" };
                            return Err(self.error(BvhErrorKind::Expected { expected, found: quote(&line) }));
                        }
                    };
                    let (name, brace) = strip_brace(rest);
                    if name.is_empty() {
                        return Err(
                            self.error(BvhErrorKind::Expected { expected: "a joint name", found: quote(&line) })
                        );
                    }
                    if is_root {
                        roots += 1;
                    }
                    joints.push(Joint {
                        name: name.to_string(),
                        parent,
                        offset: DVec3::ZERO,
                        channels: Vec::new(),
                        first_channel: 0,
                        end_site: None,
                        line: self.line,
                    });
                    offset_seen.push(false);
                    let open = Open::Joint(joints.len() - 1);
                    if brace { stack.push(open) } else { awaiting_brace = Some(open) }
                }
                "end" => {
                    let (site, brace) = strip_brace(rest);
                    let owner = match stack.last() {
                        Some(Open::Joint(j)) if site.eq_ignore_ascii_case("site") => *j,
                        _ => {
                            return Err(self.error(BvhErrorKind::Expected {
                                expected: "`End Site` inside a joint",
                                found: quote(&line),
                            }));
                        }
                    };
                    let open = Open::EndSite { owner, offset: None };
                    if brace { stack.push(open) } else { awaiting_brace = Some(open) }
                }
                "offset" => {
                    let values = scan_fields(rest)
                        .map_err(|e| self.error(BvhErrorKind::BadNumber { what: "OFFSET".into(), token: e.token }))?;
                    let [x, y, z] = <[f64; 3]>::try_from(values).map_err(|v| {
                        self.error(BvhErrorKind::Expected {
                            expected: "three OFFSET values",
                            found: format!("{} values", v.len()),
                        })
                    })?;
                    let offset = DVec3::new(x, y, z);
                    match stack.last_mut() {
                        Some(Open::Joint(j)) => {
                            if offset_seen[*j] {
                                let message = format!(
                                    "joint `{}` has a second OFFSET (line {}); the last one is used",
                                    joints[*j].name, self.line
                                );
                                self.warn("repeated_offset", message);
                            }
                            joints[*j].offset = offset;
                            offset_seen[*j] = true;
                        }
                        Some(Open::EndSite { offset: slot, .. }) => *slot = Some(offset),
                        None => {
                            return Err(self.error(BvhErrorKind::Expected { expected: "ROOT", found: quote(&line) }));
                        }
                    }
                }
                "channels" => {
                    let Some(Open::Joint(j)) = stack.last() else {
                        return Err(self.error(BvhErrorKind::Expected {
                            expected: "CHANNELS only inside a joint",
                            found: quote(&line),
                        }));
                    };
                    let j = *j;
                    let mut tokens = rest.split_whitespace();
                    let count_token = tokens.next().unwrap_or("");
                    let declared: usize = count_token.parse().map_err(|_| {
                        self.error(BvhErrorKind::BadNumber { what: "channel count".into(), token: count_token.into() })
                    })?;
                    let mut channels = Vec::with_capacity(declared.min(6));
                    for token in tokens {
                        let channel = Channel::parse(token)
                            .ok_or_else(|| self.error(BvhErrorKind::UnknownChannel { token: token.into() }))?;
                        if channels.contains(&channel) {
                            return Err(self.error(BvhErrorKind::RepeatedChannel {
                                joint: joints[j].name.clone(),
                                channel: channel.name(),
                            }));
                        }
                        channels.push(channel);
                    }
                    if channels.len() != declared {
                        return Err(self.error(BvhErrorKind::ChannelCount { declared, listed: channels.len() }));
                    }
                    if !joints[j].channels.is_empty() {
                        return Err(self.error(BvhErrorKind::Expected {
                            expected: "one CHANNELS line per joint",
                            found: quote(&line),
                        }));
                    }
                    joints[j].first_channel = channel_total;
                    channel_total += channels.len();
                    joints[j].channels = channels;
                }
                _ if keyword.starts_with('}') => {
                    // Several closing braces may share a line.
                    for token in line.split_whitespace() {
                        for c in token.chars() {
                            if c != '}' {
                                return Err(self.error(BvhErrorKind::Expected { expected: "`}`", found: quote(&line) }));
                            }
                            match stack.pop() {
                                Some(Open::Joint(_)) => {}
                                Some(Open::EndSite { owner, offset }) => {
                                    joints[owner].end_site = Some(offset.unwrap_or(DVec3::ZERO));
                                }
                                None => return Err(self.error(BvhErrorKind::UnbalancedClose)),
                            }
                        }
                    }
                }
                _ if keyword.starts_with('{') => {
                    return Err(self.error(BvhErrorKind::Expected {
                        expected: "ROOT, JOINT, End Site, OFFSET, CHANNELS or `}`",
                        found: quote(&line),
                    }));
                }
                "motion" => {
                    if let Some(open) = stack.last() {
                        let name = match open {
                            Open::Joint(j) | Open::EndSite { owner: j, .. } => &joints[*j].name,
                        };
                        return Err(self.error(BvhErrorKind::Expected {
                            expected: "`}` closing every joint before MOTION",
                            found: format!("MOTION while `{name}` is still open"),
                        }));
                    }
                    break;
                }
                _ => {
                    return Err(self.error(BvhErrorKind::Expected {
                        expected: "ROOT, JOINT, End Site, OFFSET, CHANNELS, `{`, `}` or MOTION",
                        found: quote(&line),
                    }));
                }
            }
        }
        if joints.is_empty() {
            return Err(self.error(BvhErrorKind::NoJoints));
        }
        if channel_total == 0 {
            return Err(self.error(BvhErrorKind::NoChannels));
        }
        for (j, seen) in offset_seen.iter().enumerate() {
            if !seen {
                let message =
                    format!("joint `{}` (line {}) has no OFFSET; 0 0 0 is used", joints[j].name, joints[j].line);
                self.warn("missing_offset", message);
            }
        }
        if roots > 1 {
            let message = format!(
                "the file has {roots} ROOT hierarchies (the first is `{}`); all are read, but a body is one hierarchy, so retargeting refuses the file",
                joints[0].name
            );
            self.warn("multiple_roots", message);
        }
        Ok(Skeleton { joints })
    }

    /// Reads `Frames:` and `Frame Time:`, in either order.
    fn read_motion_header(&mut self) -> Result<(u64, f64), BvhError> {
        let mut frames = None;
        let mut frame_time = None;
        while frames.is_none() || frame_time.is_none() {
            let Some(line) = self.next_line()? else {
                let context = if frames.is_none() { "before `Frames:`" } else { "before `Frame Time:`" };
                return Err(self.error(BvhErrorKind::UnexpectedEof { context: context.into() }));
            };
            let lower = line.to_ascii_lowercase();
            if let Some(rest) = lower.strip_prefix("frame time") {
                let text = rest.trim_start().trim_start_matches(':').trim();
                let value = match scan_fields(text).as_deref() {
                    Ok([v]) if *v > 0.0 => *v,
                    _ => return Err(self.error(BvhErrorKind::BadFrameTime { token: text.into() })),
                };
                frame_time = Some(value);
            } else if let Some(rest) = lower.strip_prefix("frames") {
                let text = rest.trim_start().trim_start_matches(':').trim();
                let count: u64 =
                    text.parse().map_err(|_| self.error(BvhErrorKind::BadFrameCount { token: text.into() }))?;
                frames = Some(count);
            } else {
                let expected = if frames.is_none() { "`Frames: N`" } else { "`Frame Time: SECONDS`" };
                return Err(self.error(BvhErrorKind::Expected { expected, found: quote(&line) }));
            }
        }
        Ok((frames.unwrap_or(0), frame_time.unwrap_or(0.0)))
    }

    /// Streams the motion lines. Returns the values and the frame count.
    fn read_frames(&mut self, skeleton: &Skeleton, declared: u64) -> Result<(Vec<f64>, usize), BvhError> {
        let channels = skeleton.channel_count();
        // Trust the declared count only as far as the remaining bytes could
        // hold it (two bytes a value at the least), so a wrong count never
        // causes a huge allocation.
        let remaining = self.size.saturating_sub(self.consumed);
        let reserve = (declared.saturating_mul(channels as u64)).min(remaining / 2) as usize;
        let mut data: Vec<f64> = Vec::with_capacity(reserve);
        let max_line = channels.saturating_mul(MAX_TOKEN).saturating_add(1024);
        let block = BLOCK.max(max_line);
        let mut buf: Vec<u8> = Vec::with_capacity(block.min(remaining as usize + 1));
        let mut frames = 0usize;
        let mut eof = false;
        while !eof {
            let want = block - buf.len();
            let got = (&mut self.input)
                .take(want as u64)
                .read_to_end(&mut buf)
                .map_err(|e| self.error(BvhErrorKind::Io(e)))?;
            // A block that exactly fills may still be the last one: peek,
            // so a short final line reads as truncated wherever blocks end.
            eof = got < want
                || match self.input.fill_buf() {
                    Ok(rest) => rest.is_empty(),
                    Err(e) => return Err(self.error(BvhErrorKind::Io(e))),
                };
            let complete = if eof {
                buf.len()
            } else {
                match buf.iter().rposition(|&b| b == b'\n') {
                    Some(p) => p + 1,
                    None => {
                        self.line += 1;
                        return Err(self.error(BvhErrorKind::LineTooLong { limit: max_line }));
                    }
                }
            };
            let region = &buf[..complete];
            let result = parse_region(region, channels, &mut data);
            let done_lines = match result {
                Ok(p) => p,
                Err((p, err)) => {
                    self.line += p.lines + 1;
                    let frame = frames + p.frames + 1;
                    let rest_is_blank = region[err.line_end..].iter().all(|b| b.is_ascii_whitespace());
                    return Err(self.error(frame_error(skeleton, frame, channels, eof && rest_is_blank, err.kind)));
                }
            };
            frames += done_lines.frames;
            self.line += done_lines.lines;
            buf.drain(..complete);
        }
        Ok((data, frames))
    }
}

/// Lines and frames parsed from a run of complete lines.
#[derive(Clone, Copy, Default)]
struct Progress {
    lines: usize,
    frames: usize,
}

enum LineProblem {
    Token(TokenError),
    Count(usize),
}

/// The outcome of parsing a run of lines: progress, or progress up to the
/// bad line and what was wrong with it.
type Parsed = Result<Progress, (Progress, LineError)>;

struct LineError {
    kind: LineProblem,
    /// Index just past the bad line within its region.
    line_end: usize,
}

/// Parses complete lines, splitting large regions into parts parsed in
/// parallel. On error returns the progress before the bad line.
fn parse_region(region: &[u8], channels: usize, data: &mut Vec<f64>) -> Parsed {
    let threads = rayon::current_num_threads();
    if region.len() < PARALLEL_MIN || threads == 1 {
        return parse_lines(region, channels, data);
    }
    let parts = split_at_lines(region, threads * 4);
    let results: Vec<(Vec<f64>, Parsed)> = parts
        .par_iter()
        .map(|&(start, end)| {
            let mut values = Vec::with_capacity((end - start) / 6);
            let r = parse_lines(&region[start..end], channels, &mut values);
            (values, r)
        })
        .collect();
    let mut total = Progress::default();
    for ((values, result), &(start, _)) in results.into_iter().zip(&parts) {
        match result {
            Ok(p) => {
                data.extend_from_slice(&values);
                total.lines += p.lines;
                total.frames += p.frames;
            }
            Err((p, mut err)) => {
                err.line_end += start;
                total.lines += p.lines;
                total.frames += p.frames;
                return Err((total, err));
            }
        }
    }
    Ok(total)
}

/// Cuts `region` into about `parts` pieces that each end at a line break.
fn split_at_lines(region: &[u8], parts: usize) -> Vec<(usize, usize)> {
    let step = region.len().div_ceil(parts);
    let mut cuts = Vec::with_capacity(parts);
    let mut start = 0;
    while start < region.len() {
        let nominal = (start + step).min(region.len());
        let end = region[nominal..].iter().position(|&b| b == b'\n').map_or(region.len(), |p| nominal + p + 1);
        cuts.push((start, end));
        start = end;
    }
    cuts
}

fn parse_lines(region: &[u8], channels: usize, data: &mut Vec<f64>) -> Parsed {
    let mut progress = Progress::default();
    let mut pos = 0;
    while pos < region.len() {
        let before = data.len();
        match scan_line(region, pos, data) {
            Ok((0, next)) => pos = next,
            Ok((count, next)) if count == channels => {
                progress.frames += 1;
                pos = next;
            }
            Ok((count, next)) => {
                data.truncate(before);
                return Err((progress, LineError { kind: LineProblem::Count(count), line_end: next }));
            }
            Err(token) => {
                data.truncate(before);
                let line_end = region[pos..].iter().position(|&b| b == b'\n').map_or(region.len(), |p| pos + p + 1);
                return Err((progress, LineError { kind: LineProblem::Token(token), line_end }));
            }
        }
        progress.lines += 1;
    }
    Ok(progress)
}

/// The error for a bad motion line: which frame, and which joint's channel
/// when one value is at fault.
fn frame_error(skeleton: &Skeleton, frame: usize, expected: usize, at_end: bool, problem: LineProblem) -> BvhErrorKind {
    match problem {
        LineProblem::Count(found) if at_end && found < expected => {
            BvhErrorKind::TruncatedFrame { frame, found, expected }
        }
        LineProblem::Count(found) => BvhErrorKind::WrongValueCount { frame, found, expected },
        LineProblem::Token(TokenError { index, problem, token }) => {
            let (joint, channel_name) = channel_owner(skeleton, index);
            let channel = index + 1;
            match problem {
                TokenProblem::NonFinite => BvhErrorKind::NonFinite { frame, channel, joint, channel_name, token },
                TokenProblem::NonNumeric => BvhErrorKind::NonNumeric { frame, channel, joint, channel_name, token },
            }
        }
    }
}

fn channel_owner(skeleton: &Skeleton, index: usize) -> (String, &'static str) {
    skeleton
        .joints
        .iter()
        .find(|j| index >= j.first_channel && index < j.first_channel + j.channels.len())
        .map(|j| (j.name.clone(), j.channels[index - j.first_channel].name()))
        .unwrap_or_else(|| ("beyond the last joint".into(), "extra value"))
}

/// Splits a hierarchy line into its keyword and the rest.
fn split_keyword(line: &str) -> (&str, &str) {
    if line.starts_with(['{', '}']) {
        return (&line[..1], line[1..].trim());
    }
    match line.find(char::is_whitespace) {
        Some(i) => (&line[..i], line[i..].trim()),
        None => (line, ""),
    }
}

/// Removes a trailing `{` from a declaration, reporting whether it was there.
fn strip_brace(rest: &str) -> (&str, bool) {
    match rest.strip_suffix('{') {
        Some(name) => (name.trim(), true),
        None => (rest, false),
    }
}

/// A line as it appears in a message: quoted and cut to a readable length.
fn quote(text: &str) -> String {
    let cut: String = text.chars().take(48).collect();
    let more = if cut.len() < text.len() { "…" } else { "" };
    format!("`{cut}{more}`")
}
