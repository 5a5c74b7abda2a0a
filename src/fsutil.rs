//! Writing output files so that a failure never leaves a partial file: write
//! to a temporary file beside the target, then rename it into place. Also
//! what several writers share: PNG encoding and JSON numbers rounded to six
//! decimals.

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// A folder that holds something where a new one was to be written.
#[derive(Debug, thiserror::Error)]
#[error("{0}: exists and is not empty")]
pub struct NotEmpty(pub String);

/// Refuses to replace the folder `dir` when it holds something, unless
/// `force`.
pub fn refuse_nonempty(dir: &Path, force: bool) -> Result<(), NotEmpty> {
    if !force && dir.read_dir().is_ok_and(|mut d| d.next().is_some()) {
        return Err(NotEmpty(dir.display().to_string()));
    }
    Ok(())
}

/// A file or folder that could not be written, named.
#[derive(Debug, thiserror::Error)]
#[error("{path}: cannot write: {source}")]
pub struct WriteError {
    pub path: String,
    pub source: io::Error,
}

impl WriteError {
    /// Turns an I/O error met writing `path` into one that names it.
    pub fn at(path: &Path) -> impl Fn(io::Error) -> WriteError {
        let path = path.display().to_string();
        move |source| WriteError { path: path.clone(), source }
    }
}

/// Writes the file at `path` through `write`, atomically: readers see the
/// old file or the complete new one, and an error leaves no file behind.
pub fn write_atomic<F>(path: &Path, write: F) -> io::Result<()>
where
    F: FnOnce(&mut BufWriter<fs::File>) -> io::Result<()>,
{
    let tmp = temporary_sibling(path);
    let result = (|| {
        let file = fs::File::create(&tmp)?;
        let mut out = BufWriter::with_capacity(1 << 16, file);
        write(&mut out)?;
        out.flush()?;
        out.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Writes the folder `dir` through `fill`, which writes into the (empty)
/// folder it is given, atomically: the folder is made beside `dir` and
/// put in its place (replacing an existing `dir`) only once `fill` has
/// succeeded; an error from `fill` or from the file system (turned into
/// `E` by `io_error`) leaves nothing behind and `dir` as it was.
pub fn write_dir_atomic<E>(
    dir: &Path,
    fill: impl FnOnce(&Path) -> Result<(), E>,
    io_error: impl Fn(io::Error) -> E,
) -> Result<(), E> {
    let staging = sibling(dir, "tmp");
    let _ = fs::remove_dir_all(&staging);
    let result = fs::create_dir_all(&staging).map_err(&io_error).and_then(|()| fill(&staging)).and_then(|()| {
        if dir.exists() {
            let old = sibling(dir, "old");
            fs::rename(dir, &old).and_then(|()| fs::rename(&staging, dir)).map_err(&io_error)?;
            fs::remove_dir_all(&old).map_err(&io_error)
        } else {
            fs::rename(&staging, dir).map_err(&io_error)
        }
    });
    if result.is_err() {
        let _ = fs::remove_dir_all(&staging);
    }
    result
}

fn temporary_sibling(path: &Path) -> PathBuf {
    sibling(path, "tmp")
}

/// A hidden name beside `path` for work in progress: `.<name>.<what>.<pid>`.
fn sibling(path: &Path, what: &str) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{what}.{}", std::process::id()))
}

/// How hard [`png`] compresses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PngEffort {
    /// Rendered frames, thousands of them: binary masks compress well at
    /// any level, noisy color frames hardly at all.
    Fast,
    /// Report pictures, kept and mailed: the smallest file is worth the time.
    Smallest,
}

/// Pixels (`kind`: gray or RGB, 8 bits) as the bytes of a PNG file.
pub fn png(pixels: &[u8], width: u32, height: u32, kind: image::ExtendedColorType, effort: PngEffort) -> Vec<u8> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let (compression, filter) = match effort {
        PngEffort::Fast => (CompressionType::Fast, FilterType::Sub),
        PngEffort::Smallest => (CompressionType::Best, FilterType::Adaptive),
    };
    let mut out = Vec::with_capacity(pixels.len() / 4);
    PngEncoder::new_with_quality(&mut out, compression, filter)
        .write_image(pixels, width, height, kind)
        .expect("encoding to memory cannot fail");
    out
}

/// Six decimals: micrometres, microdegrees, microseconds, far finer than
/// anything measured here, and the file stays readable.
pub fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

pub fn rounded<S: serde::Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(round6(*v))
}

pub fn rounded_option<S: serde::Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match v {
        Some(v) => s.serialize_some(&round6(*v)),
        None => s.serialize_none(),
    }
}

/// Rounds every fractional number in `value` (and below it) to six
/// decimals, as the JSON files the program writes keep them.
pub fn round6_json(value: &mut serde_json::Value) {
    match value {
        serde_json::Value::Number(n) if n.is_f64() => {
            if let Some(r) = n.as_f64().map(round6).and_then(serde_json::Number::from_f64) {
                *n = r;
            }
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(round6_json),
        serde_json::Value::Object(fields) => fields.values_mut().for_each(round6_json),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_numbers_are_rounded_to_six_decimals_wherever_they_are() {
        let mut v =
            serde_json::json!({"a": 0.1234567891, "b": [1, 2.0000004, {"c": -4.56789012}], "d": "x", "e": null});
        round6_json(&mut v);
        assert_eq!(v, serde_json::json!({"a": 0.123457, "b": [1, 2.0, {"c": -4.56789}], "d": "x", "e": null}));
    }

    #[test]
    fn failed_write_leaves_neither_target_nor_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.bvh");
        let err = write_atomic(&target, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("boom"))
        });
        assert!(err.is_err());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn a_folder_is_written_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out");
        let fill = |ok: bool| {
            move |d: &Path| {
                fs::write(d.join("a.txt"), if ok { "new" } else { "partial" })?;
                if ok { Ok(()) } else { Err(io::Error::other("boom")) }
            }
        };
        assert!(write_dir_atomic(&target, fill(false), |e| e).is_err());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
        fs::create_dir(&target).unwrap();
        fs::write(target.join("old.txt"), "old").unwrap();
        assert!(write_dir_atomic(&target, fill(false), |e| e).is_err());
        assert!(target.join("old.txt").exists() && !target.join("a.txt").exists());
        write_dir_atomic(&target, fill(true), |e| e).unwrap();
        assert_eq!(fs::read_to_string(target.join("a.txt")).unwrap(), "new");
        assert!(!target.join("old.txt").exists());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn successful_write_replaces_the_target_whole() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.txt");
        fs::write(&target, "old").unwrap();
        write_atomic(&target, |w| w.write_all(b"new contents")).unwrap();
        assert_eq!(fs::read_to_string(&target).unwrap(), "new contents");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
