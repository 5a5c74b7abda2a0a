//! The vocabulary file container: one self-describing JSON header and named
//! arrays of `f64`, in one versioned file guarded by a checksum.
//!
//! The container knows nothing about vocabularies; the vocabulary stores its
//! own fields in the header and its numbers in the arrays.
//!
//! # Layout of a `.vocab` file (format version 1)
//!
//! Every integer is little-endian; every offset counts bytes from the start
//! of the file. `H` is the header length, `P` the padding, `D` the data size.
//!
//! | Offset        | Bytes | Content |
//! |---------------|-------|---------|
//! | 0             | 14    | magic: `imitate-vocab` and a line feed (`69 6d 69 74 61 74 65 2d 76 6f 63 61 62 0a`) |
//! | 14            | 4     | format version, u32: `1` (`01 00 00 00`) |
//! | 18            | 8     | header length `H`, u64 |
//! | 26            | `H`   | header: a JSON object in UTF-8 (below) |
//! | 26+H          | `P`   | padding: `P` = (8 − (26 + `H`) mod 8) mod 8 zero bytes (0 to 7) |
//! | 26+H+P        | `D`   | data: every array's values as IEEE 754 binary64 (`f64`), 8 bytes each, arrays concatenated in the order the header lists them |
//! | 26+H+P+D      | 4     | checksum, u32: CRC-32 of bytes 0 to 26+H+P+D−1, i.e. of everything before it |
//!
//! The file is exactly 26 + `H` + `P` + `D` + 4 bytes long: nothing follows
//! the checksum. The fixed fields alone take 30 bytes; the smallest valid
//! file (header `{"arrays":[],"data_bytes":0}`, no arrays) has 60.
//!
//! **Header.** One JSON object, written compactly (no spaces or line breaks),
//! with the keys of every object in it sorted (by Unicode code point), so the
//! same container always gives the same bytes. Besides the writer's own keys
//! it holds two keys the container adds itself, and which a writer may
//! therefore not use:
//!
//! - `"arrays"`: the arrays in data order, as a list of
//!   `{"len": n, "name": "..."}`, where `n` is the number of values and names
//!   are unique;
//! - `"data_bytes"`: `D`, which is 8 × the sum of every `len` (padding
//!   excluded).
//!
//! For example `{"arrays":[{"len":2,"name":"mean"}],"data_bytes":16,"kind":"demo"}`.
//!
//! **Alignment.** The padding puts the first array at a multiple of 8 bytes
//! from the start of the file. Every array is a whole number of 8-byte values,
//! so every array starts at a multiple of 8: array `i` starts at
//! 26 + `H` + `P` + 8 × (`len` of arrays 0 to `i`−1). Writers write zero
//! bytes as padding; readers do not look at them (the checksum covers them).
//!
//! **Checksum.** CRC-32 as in zlib, gzip and PNG (polynomial `0x04C11DB7`,
//! reflected, initial value and final XOR `0xFFFFFFFF`; the CRC of the
//! ASCII text `123456789` is `0xCBF43926`), computed with `crc32fast`.
//!
//! **Versions.** A reader reads the versions it knows (this one: 1) and
//! refuses a larger number as written by a newer imitate. Version 0 was never
//! written.
//!
//! # Reading
//!
//! A reader checks, in this order, so each refusal says what is wrong: the
//! magic (else "not a vocabulary file"), the version (else "newer" or
//! "unknown" version), that the file holds the whole header `H` says it has
//! (else "truncated"), that the header is a JSON object with consistent
//! `arrays` and `data_bytes` (else "bad header"), that the file holds the
//! whole data and checksum (else "truncated"), the checksum (else
//! "corrupt"), and that nothing follows it (else "trailing bytes").
//! Nothing is allocated from a size in the file before the file is known to
//! hold that many bytes.

use std::collections::HashSet;
use std::convert::Infallible;
use std::fmt;
use std::fs;
use std::io::{self, Write};
use std::path::Path;

use serde_json::{Map, Value};

use crate::fsutil::write_atomic;

/// The first 14 bytes of every vocabulary file.
pub const MAGIC: &[u8; 14] = b"imitate-vocab\n";

/// The format version this code writes, and the newest it reads.
/// 2: poses in swing–twist joint space (1: exponential maps).
pub const FORMAT_VERSION: u32 = 2;

/// The header key holding the list of arrays, added by the container.
pub const ARRAYS_KEY: &str = "arrays";

/// The header key holding the data size in bytes, added by the container.
pub const DATA_BYTES_KEY: &str = "data_bytes";

/// Header keys the container writes itself; a caller's header may not use them.
pub const RESERVED_KEYS: [&str; 2] = [ARRAYS_KEY, DATA_BYTES_KEY];

/// No vocabulary file is shorter: magic, version, header length and checksum.
pub const MIN_FILE_LEN: u64 = (HEADER_AT + CHECKSUM_LEN) as u64;

const VERSION_AT: usize = MAGIC.len();
const HEADER_LEN_AT: usize = VERSION_AT + 4;
const HEADER_AT: usize = HEADER_LEN_AT + 8;
const CHECKSUM_LEN: usize = 4;
const VALUE_LEN: usize = 8;

/// How many values are converted to bytes at a time when writing.
const WRITE_CHUNK: usize = 8192;

/// A JSON header and named arrays of `f64`, in order; see the module
/// documentation for the file layout.
#[derive(Debug, Clone)]
pub struct Container {
    /// The caller's header: a JSON object without the keys in
    /// [`RESERVED_KEYS`] (which [`Container::write`] checks). After reading
    /// it is exactly what the writer put in, without the container's keys.
    pub header: Value,
    arrays: Vec<(String, Vec<f64>)>,
}

impl Container {
    /// A container with `header` and no arrays. `header` must be a JSON
    /// object without the keys in [`RESERVED_KEYS`]; writing refuses it
    /// otherwise.
    pub fn new(header: Value) -> Self {
        Self { header, arrays: Vec::new() }
    }

    /// Appends an array. Names must be unique; writing refuses a container
    /// with two arrays of the same name.
    pub fn push(&mut self, name: impl Into<String>, values: Vec<f64>) {
        self.arrays.push((name.into(), values));
    }

    /// The values of the array called `name`.
    pub fn array(&self, name: &str) -> Option<&[f64]> {
        self.arrays.iter().find(|(n, _)| n == name).map(|(_, values)| values.as_slice())
    }

    /// Moves the array called `name` out of the container (it is no longer
    /// in it afterwards).
    pub fn take(&mut self, name: &str) -> Option<Vec<f64>> {
        let index = self.arrays.iter().position(|(n, _)| n == name)?;
        Some(self.arrays.remove(index).1)
    }

    /// The arrays' names, in order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.arrays.iter().map(|(name, _)| name.as_str())
    }

    /// The arrays as (name, values), in order.
    pub fn arrays(&self) -> impl Iterator<Item = (&str, &[f64])> {
        self.arrays.iter().map(|(name, values)| (name.as_str(), values.as_slice()))
    }

    /// Writes the container to `path` atomically: on any error no file (and
    /// no temporary file) is left, and an existing file at `path` is kept.
    pub fn write(&self, path: &Path) -> Result<(), ContainerError> {
        let plan = self.plan().map_err(|e| ContainerError::new(path, ContainerErrorKind::Invalid(e)))?;
        write_atomic(path, |out| self.emit(&plan, &mut |bytes: &[u8]| out.write_all(bytes)))
            .map_err(|e| ContainerError::new(path, ContainerErrorKind::Write(e)))
    }

    /// The bytes [`Container::write`] writes. The same container always gives
    /// the same bytes.
    pub fn to_bytes(&self) -> Result<Vec<u8>, InvalidContainer> {
        let plan = self.plan()?;
        let mut out = Vec::with_capacity(usize::try_from(plan.file_len()).unwrap_or(0));
        let Ok(()) = self.emit::<Infallible>(&plan, &mut |bytes: &[u8]| {
            out.extend_from_slice(bytes);
            Ok(())
        });
        Ok(out)
    }

    /// Reads the vocabulary file at `path`.
    pub fn read(path: &Path) -> Result<Container, ContainerError> {
        let bytes = fs::read(path).map_err(|e| ContainerError::new(path, ContainerErrorKind::Read(e)))?;
        Self::from_bytes(&bytes, &path.display().to_string())
    }

    /// Reads a container from the bytes of a file; `name` stands for the
    /// file in error messages.
    pub fn from_bytes(bytes: &[u8], name: &str) -> Result<Container, ContainerError> {
        decode(bytes).map_err(|kind| ContainerError { path: name.to_string(), kind: Box::new(kind) })
    }

    /// Checks the container and builds its header.
    fn plan(&self) -> Result<Plan, InvalidContainer> {
        let Value::Object(caller) = &self.header else {
            return Err(InvalidContainer::HeaderNotObject { found: json_kind(&self.header) });
        };
        if let Some(key) = RESERVED_KEYS.into_iter().find(|key| caller.contains_key(*key)) {
            return Err(InvalidContainer::ReservedKey { key });
        }
        let mut seen = HashSet::new();
        if let Some((name, _)) = self.arrays.iter().find(|(name, _)| !seen.insert(name.as_str())) {
            return Err(InvalidContainer::DuplicateArray { name: name.clone() });
        }
        let data_bytes: u64 = self.arrays.iter().map(|(_, values)| (values.len() * VALUE_LEN) as u64).sum();
        let list = self
            .arrays
            .iter()
            .map(|(name, values)| {
                let mut entry = Map::new();
                entry.insert("len".into(), Value::from(values.len() as u64));
                entry.insert("name".into(), Value::from(name.as_str()));
                Value::Object(entry)
            })
            .collect();
        let mut header = caller.clone();
        header.insert(ARRAYS_KEY.into(), Value::Array(list));
        header.insert(DATA_BYTES_KEY.into(), Value::from(data_bytes));
        let header = serde_json::to_vec(&sorted_keys(&Value::Object(header)))
            .map_err(|e| InvalidContainer::Serialize { reason: e.to_string() })?;
        let padding = padding_after(header.len() as u64);
        Ok(Plan { header, padding, data_bytes })
    }

    /// Passes the file's bytes, in order, to `sink`.
    fn emit<E>(&self, plan: &Plan, sink: &mut impl FnMut(&[u8]) -> Result<(), E>) -> Result<(), E> {
        let mut crc = crc32fast::Hasher::new();
        let mut put = |bytes: &[u8]| {
            crc.update(bytes);
            sink(bytes)
        };
        put(MAGIC)?;
        put(&FORMAT_VERSION.to_le_bytes())?;
        put(&(plan.header.len() as u64).to_le_bytes())?;
        put(&plan.header)?;
        put(&[0; VALUE_LEN][..plan.padding])?;
        let mut buffer = Vec::with_capacity(WRITE_CHUNK * VALUE_LEN);
        for (_, values) in &self.arrays {
            for chunk in values.chunks(WRITE_CHUNK) {
                buffer.clear();
                for value in chunk {
                    buffer.extend_from_slice(&value.to_le_bytes());
                }
                put(&buffer)?;
            }
        }
        sink(&crc.finalize().to_le_bytes())
    }
}

/// The container's header, serialized, and the sizes that follow from it.
struct Plan {
    header: Vec<u8>,
    padding: usize,
    data_bytes: u64,
}

impl Plan {
    fn file_len(&self) -> u64 {
        (HEADER_AT + self.header.len() + self.padding + CHECKSUM_LEN) as u64 + self.data_bytes
    }
}

/// Zero bytes between a header of `header_len` bytes and the data, so the
/// data starts at a multiple of 8. `header_len` must be at most the file
/// size (so the sum cannot overflow).
fn padding_after(header_len: u64) -> usize {
    let end = HEADER_AT as u64 + header_len;
    ((VALUE_LEN as u64 - end % VALUE_LEN as u64) % VALUE_LEN as u64) as usize
}

/// `value` with the keys of every object in it in sorted order, whether or
/// not serde_json keeps insertion order (its `preserve_order` feature).
fn sorted_keys(value: &Value) -> Value {
    match value {
        Value::Object(map) => {
            let mut keys: Vec<&String> = map.keys().collect();
            keys.sort();
            Value::Object(keys.into_iter().map(|key| (key.clone(), sorted_keys(&map[key.as_str()]))).collect())
        }
        Value::Array(items) => Value::Array(items.iter().map(sorted_keys).collect()),
        other => other.clone(),
    }
}

fn json_kind(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "a list",
        Value::Object(_) => "an object",
    }
}

/// Reads a container from a file's bytes; see the module documentation for
/// the order of the checks.
fn decode(bytes: &[u8]) -> Result<Container, ContainerErrorKind> {
    let file_len = bytes.len() as u64;
    let too_short = || ContainerErrorKind::Truncated { len: file_len, needed: Needed::Minimum(MIN_FILE_LEN) };

    // Magic: a file that is a prefix of the magic is a cut vocabulary file.
    let start = &bytes[..bytes.len().min(MAGIC.len())];
    if bytes.is_empty() || start != &MAGIC[..start.len()] {
        return Err(ContainerErrorKind::NotVocab { found: describe_start(bytes) });
    }

    // Version.
    let Some(version) = bytes.get(VERSION_AT..HEADER_LEN_AT) else {
        return Err(too_short());
    };
    let version = u32::from_le_bytes(version.try_into().expect("4 bytes"));
    if version > FORMAT_VERSION {
        return Err(ContainerErrorKind::NewerVersion { version });
    }
    if version == 1 {
        return Err(ContainerErrorKind::OlderJointSpace { version });
    }
    if version != FORMAT_VERSION {
        return Err(ContainerErrorKind::UnknownVersion { version });
    }

    // Header length: the header and the checksum must fit in the file.
    let Some(header_len) = bytes.get(HEADER_LEN_AT..HEADER_AT) else {
        return Err(too_short());
    };
    let header_len = u64::from_le_bytes(header_len.try_into().expect("8 bytes"));
    let header_needs = (HEADER_AT + CHECKSUM_LEN) as u128 + u128::from(header_len);
    if header_needs > u128::from(file_len) {
        return Err(ContainerErrorKind::Truncated { len: file_len, needed: Needed::HeaderAtLeast(header_needs) });
    }
    // Now header_len < file_len, so it fits in usize and nothing overflows.
    let header_end = HEADER_AT + header_len as usize;

    // Header.
    let (header, arrays, data_bytes) =
        parse_header(&bytes[HEADER_AT..header_end]).map_err(|reason| ContainerErrorKind::BadHeader { reason })?;

    // Declared size against the actual one.
    let data_at = header_end + padding_after(header_len);
    let needed = data_at as u128 + u128::from(data_bytes) + CHECKSUM_LEN as u128;
    if needed > u128::from(file_len) {
        return Err(ContainerErrorKind::Truncated { len: file_len, needed: Needed::Exactly(needed) });
    }
    // Now every size is at most the file size.
    let checksum_at = needed as usize - CHECKSUM_LEN;

    // Checksum.
    let stored = u32::from_le_bytes(bytes[checksum_at..checksum_at + CHECKSUM_LEN].try_into().expect("4 bytes"));
    let computed = crc32fast::hash(&bytes[..checksum_at]);
    if stored != computed {
        return Err(ContainerErrorKind::Corrupt { stored, computed });
    }
    if needed < u128::from(file_len) {
        return Err(ContainerErrorKind::TrailingBytes { extra: file_len - needed as u64, end: needed as u64 });
    }

    let mut at = data_at;
    let arrays = arrays
        .into_iter()
        .map(|(name, len)| {
            let end = at + len as usize * VALUE_LEN;
            let values = bytes[at..end]
                .chunks_exact(VALUE_LEN)
                .map(|value| f64::from_le_bytes(value.try_into().expect("8 bytes")))
                .collect();
            at = end;
            (name, values)
        })
        .collect();
    Ok(Container { header: Value::Object(header), arrays })
}

/// Arrays as (name, number of values).
type ArrayList = Vec<(String, u64)>;

/// Parses the JSON header into the caller's part, the list of arrays and the
/// data size, checking that they agree. Errors say what is wrong.
fn parse_header(json: &[u8]) -> Result<(Map<String, Value>, ArrayList, u64), String> {
    let text = std::str::from_utf8(json)
        .map_err(|e| format!("the JSON header is not UTF-8 (invalid byte at header offset {})", e.valid_up_to()))?;
    let header: Value = serde_json::from_str(text).map_err(|e| format!("the JSON header is not valid JSON ({e})"))?;
    let Value::Object(mut header) = header else {
        return Err(format!("the JSON header is {}, not an object", json_kind(&header)));
    };

    let list = match header.remove(ARRAYS_KEY) {
        Some(Value::Array(list)) => list,
        Some(other) => return Err(format!("`{ARRAYS_KEY}` is {}, not a list", json_kind(&other))),
        None => return Err(format!("the JSON header has no `{ARRAYS_KEY}` list")),
    };
    let mut arrays = Vec::with_capacity(list.len());
    let mut names = HashSet::new();
    let mut sum: u64 = 0;
    for (i, entry) in list.into_iter().enumerate() {
        let Value::Object(entry) = entry else {
            return Err(format!("`{ARRAYS_KEY}` entry {i} is {}, not an object", json_kind(&entry)));
        };
        if let Some(key) = entry.keys().find(|key| *key != "name" && *key != "len") {
            return Err(format!("`{ARRAYS_KEY}` entry {i} has the unknown key `{key}`"));
        }
        let Some(name) = entry.get("name").and_then(Value::as_str) else {
            return Err(format!("`{ARRAYS_KEY}` entry {i} has no `name` string"));
        };
        let Some(len) = entry.get("len").and_then(Value::as_u64) else {
            return Err(format!("`{ARRAYS_KEY}` entry {i} (`{name}`) has no `len` that is a whole number"));
        };
        if !names.insert(name.to_string()) {
            return Err(format!("`{ARRAYS_KEY}` lists the name `{name}` twice"));
        }
        sum = len.checked_mul(VALUE_LEN as u64).and_then(|bytes| sum.checked_add(bytes)).ok_or_else(|| {
            format!("array `{name}` has {len} values, which makes the data larger than any file can be")
        })?;
        arrays.push((name.to_string(), len));
    }

    let data_bytes = match header.remove(DATA_BYTES_KEY) {
        Some(value) => value.as_u64().ok_or_else(|| format!("`{DATA_BYTES_KEY}` is not a whole number: {value}"))?,
        None => return Err(format!("the JSON header has no `{DATA_BYTES_KEY}`")),
    };
    if data_bytes != sum {
        return Err(format!(
            "`{DATA_BYTES_KEY}` is {data_bytes}, but the arrays' lengths add up to {sum} bytes (8 per value)"
        ));
    }
    Ok((header, arrays, data_bytes))
}

/// Says what the start of a file that is not a vocabulary file looks like.
fn describe_start(bytes: &[u8]) -> String {
    const SHOW_BYTES: usize = 8;
    const SHOW_CHARS: usize = 40;
    if bytes.is_empty() {
        return "the file is empty".into();
    }
    let name = &MAGIC[..MAGIC.len() - 1];
    if let Some(&next) = bytes.strip_prefix(name).and_then(|rest| rest.first()) {
        return format!(
            "it starts with `imitate-vocab` but then byte {next:#04x} instead of a line feed \
             (was it copied as text, changing its line endings?)"
        );
    }
    let head = &bytes[..bytes.len().min(4 * SHOW_CHARS)];
    let (text, complete) = match std::str::from_utf8(head) {
        Ok(text) => (text, true),
        // A cut inside a multi-byte character at the end of `head` is fine.
        Err(e) => (std::str::from_utf8(&head[..e.valid_up_to()]).unwrap_or_default(), e.error_len().is_none()),
    };
    let text = text.trim_start();
    let line_ends = text.contains(['\n', '\r']);
    let line = text.lines().next().unwrap_or_default().trim_end();
    let printable = !line.is_empty() && line.chars().all(|c| c == '\t' || !c.is_control());
    if printable && (complete || line_ends) {
        let shown: String = line.chars().take(SHOW_CHARS).collect();
        let more = if shown.len() < line.len() { "…" } else { "" };
        return format!("it starts with `{shown}{more}`");
    }
    let hex: Vec<String> = bytes.iter().take(SHOW_BYTES).map(|b| format!("{b:02x}")).collect();
    let more = if bytes.len() > SHOW_BYTES { " …" } else { "" };
    format!("it starts with binary data ({}{more})", hex.join(" "))
}

/// Why a vocabulary file could not be read or written, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {kind}")]
pub struct ContainerError {
    pub path: String,
    /// Boxed: errors are rare and `Result<Container, ContainerError>` stays small.
    pub kind: Box<ContainerErrorKind>,
}

impl ContainerError {
    fn new(path: &Path, kind: ContainerErrorKind) -> Self {
        Self { path: path.display().to_string(), kind: Box::new(kind) }
    }
}

/// What is wrong with a vocabulary file, one variant per kind of problem.
#[derive(Debug, thiserror::Error)]
pub enum ContainerErrorKind {
    #[error("cannot read: {0}")]
    Read(io::Error),
    #[error("cannot write: {0}")]
    Write(io::Error),
    #[error("cannot write: {0}")]
    Invalid(InvalidContainer),
    #[error("not a vocabulary file: {found}")]
    NotVocab { found: String },
    #[error(
        "written by a newer imitate (format version {version}; this version reads {FORMAT_VERSION}): update imitate"
    )]
    NewerVersion { version: u32 },
    #[error(
        "format version {version}, whose poses are in an earlier joint space (exponential maps; this version reads \
         format {FORMAT_VERSION}, swing–twist): build the vocabulary again with `imitate vocab build`"
    )]
    OlderJointSpace { version: u32 },
    #[error(
        "unknown format version {version} (this version reads {FORMAT_VERSION}, and no imitate wrote \
         {version}): the file is damaged"
    )]
    UnknownVersion { version: u32 },
    #[error("truncated: {len} bytes, {needed}")]
    Truncated { len: u64, needed: Needed },
    #[error(
        "corrupt: checksum {stored:#010x} stored in the file does not match {computed:#010x} computed from its contents"
    )]
    Corrupt { stored: u32, computed: u32 },
    #[error("bad header: {reason}")]
    BadHeader { reason: String },
    #[error("{extra} trailing bytes after the checksum, which should end the file at byte {end}")]
    TrailingBytes { extra: u64, end: u64 },
}

/// How long a truncated file should have been, as far as could be told.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Needed {
    /// The file ends before its header length: any vocabulary file has at
    /// least this many bytes.
    Minimum(u64),
    /// The header length says the file has at least this many bytes
    /// (before the header is read, the data size is unknown).
    HeaderAtLeast(u128),
    /// The header describes a file of exactly this many bytes.
    Exactly(u128),
}

impl fmt::Display for Needed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Needed::Minimum(n) => write!(f, "a vocabulary file has at least {n}"),
            Needed::HeaderAtLeast(n) => write!(f, "the header length says at least {n}"),
            Needed::Exactly(n) => write!(f, "the header describes {n}"),
        }
    }
}

/// Why a container cannot be written.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InvalidContainer {
    #[error("the header must be a JSON object, not {found}")]
    HeaderNotObject { found: &'static str },
    #[error("the header has the key `{key}`, which the container writes itself")]
    ReservedKey { key: &'static str },
    #[error("two arrays are named `{name}`")]
    DuplicateArray { name: String },
    #[error("the header cannot be serialized: {reason}")]
    Serialize { reason: String },
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use serde_json::json;

    const NAME: &str = "model.vocab";

    /// A NaN with a payload and the sign bit set, to check bits survive.
    fn odd_nan() -> f64 {
        f64::from_bits(0xfff8_0000_dead_beef)
    }

    fn sample() -> Container {
        let mut c = Container::new(json!({"kind": "test", "primitives": 3, "nested": {"b": [1, 2], "a": null}}));
        c.push("mean", vec![1.0, -2.5, 3.25]);
        c.push("empty", vec![]);
        c.push("special", vec![f64::NAN, odd_nan(), f64::INFINITY, f64::NEG_INFINITY, -0.0, 0.0, f64::MIN_POSITIVE]);
        c.push("ramp", (0..100).map(|i| i as f64 * 0.1).collect());
        c
    }

    fn bits(values: &[f64]) -> Vec<u64> {
        values.iter().map(|v| v.to_bits()).collect()
    }

    fn header_len(bytes: &[u8]) -> usize {
        u64::from_le_bytes(bytes[HEADER_LEN_AT..HEADER_AT].try_into().unwrap()) as usize
    }

    /// Recomputes the trailing checksum of a (patched) file.
    fn reseal(bytes: &mut [u8]) {
        let at = bytes.len() - CHECKSUM_LEN;
        let crc = crc32fast::hash(&bytes[..at]);
        bytes[at..].copy_from_slice(&crc.to_le_bytes());
    }

    /// A file with the given version, raw header bytes and data, correctly
    /// padded and with a valid checksum.
    fn assemble(version: u32, header: &[u8], data: &[f64]) -> Vec<u8> {
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&version.to_le_bytes());
        bytes.extend_from_slice(&(header.len() as u64).to_le_bytes());
        bytes.extend_from_slice(header);
        bytes.resize(bytes.len() + padding_after(header.len() as u64), 0);
        for v in data {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&[0; 4]);
        reseal(&mut bytes);
        bytes
    }

    fn error_of(result: Result<Container, ContainerError>) -> ContainerError {
        match result {
            Ok(_) => panic!("expected an error, read a container"),
            Err(e) => e,
        }
    }

    /// Reads `bytes` expecting an error whose message names the file and
    /// contains `expected`; returns the error's kind.
    fn refused(bytes: &[u8], expected: &str) -> ContainerErrorKind {
        let err = error_of(Container::from_bytes(bytes, NAME));
        let message = err.to_string();
        assert!(message.starts_with(&format!("{NAME}: ")), "message does not name the file: {message}");
        assert!(message.contains(expected), "message `{message}` does not contain `{expected}`");
        *err.kind
    }

    #[test]
    fn round_trip_keeps_header_names_order_and_every_bit() {
        let original = sample();
        let bytes = original.to_bytes().unwrap();
        let read = Container::from_bytes(&bytes, NAME).unwrap();
        assert_eq!(read.header, original.header, "the header comes back without the container's keys");
        assert_eq!(read.names().collect::<Vec<_>>(), ["mean", "empty", "special", "ramp"]);
        for (name, values) in original.arrays() {
            assert_eq!(bits(read.array(name).unwrap()), bits(values), "array `{name}`");
        }
        assert_eq!(read.array("empty").unwrap().len(), 0);
        let special = read.array("special").unwrap();
        assert_eq!(special[1].to_bits(), 0xfff8_0000_dead_beef, "NaN payload and sign kept");
        assert!(special[4].is_sign_negative() && special[4] == 0.0, "-0.0 kept");
        assert_eq!(read.array("missing"), None);
    }

    #[test]
    fn container_without_arrays_round_trips() {
        let c = Container::new(json!({}));
        let bytes = c.to_bytes().unwrap();
        assert_eq!(bytes.len(), 60, "the smallest valid file, as documented");
        let read = Container::from_bytes(&bytes, NAME).unwrap();
        assert_eq!(read.header, json!({}));
        assert_eq!(read.names().count(), 0);
    }

    #[test]
    fn bytes_match_the_documented_layout_exactly() {
        let mut c = Container::new(json!({"kind": "demo"}));
        c.push("mean", vec![1.0, -2.0]);
        let bytes = c.to_bytes().unwrap();
        let header = br#"{"arrays":[{"len":2,"name":"mean"}],"data_bytes":16,"kind":"demo"}"#;
        let mut expected = b"imitate-vocab\n".to_vec();
        expected.extend_from_slice(&[2, 0, 0, 0]);
        expected.extend_from_slice(&(header.len() as u64).to_le_bytes());
        expected.extend_from_slice(header);
        // 26 + 66 = 92 bytes so far: 4 zero bytes pad the data to offset 96.
        assert_eq!(header.len(), 66);
        expected.extend_from_slice(&[0, 0, 0, 0]);
        expected.extend_from_slice(&1.0f64.to_le_bytes());
        expected.extend_from_slice(&(-2.0f64).to_le_bytes());
        let crc = crc32fast::hash(&expected);
        expected.extend_from_slice(&crc.to_le_bytes());
        assert_eq!(bytes, expected);
        assert_eq!(bytes.len(), 26 + 66 + 4 + 16 + 4);
    }

    #[test]
    fn checksum_is_the_standard_crc32() {
        assert_eq!(crc32fast::hash(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn same_container_gives_same_bytes_whatever_the_key_order() {
        let a = sample().to_bytes().unwrap();
        assert_eq!(a, sample().to_bytes().unwrap());
        // The same header built with keys inserted in another order.
        let mut header = Map::new();
        header.insert("primitives".into(), json!(3));
        header.insert("nested".into(), json!({"a": null, "b": [1, 2]}));
        header.insert("kind".into(), json!("test"));
        let mut other = Container::new(Value::Object(header));
        for (name, values) in sample().arrays() {
            other.push(name, values.to_vec());
        }
        assert_eq!(a, other.to_bytes().unwrap());
        // Reading and writing again changes nothing.
        let again = Container::from_bytes(&a, NAME).unwrap().to_bytes().unwrap();
        assert_eq!(a, again);
    }

    #[test]
    fn every_array_starts_8_byte_aligned_for_every_padding() {
        let mut paddings = HashSet::new();
        for extra in 0..16 {
            let mut c = Container::new(json!({"text": "x".repeat(extra)}));
            c.push("one", vec![1.5]);
            c.push("none", vec![]);
            c.push("three", vec![2.5, 3.5, 4.5]);
            c.push("last", vec![5.5]);
            let bytes = c.to_bytes().unwrap();
            let h = header_len(&bytes);
            let padding = padding_after(h as u64);
            paddings.insert(padding);
            assert!(bytes[HEADER_AT + h..HEADER_AT + h + padding].iter().all(|&b| b == 0), "padding is zeros");
            let mut at = HEADER_AT + h + padding;
            for (name, values) in c.arrays() {
                assert_eq!(at % 8, 0, "array `{name}` starts at {at}");
                for (i, v) in values.iter().enumerate() {
                    let stored = f64::from_le_bytes(bytes[at + 8 * i..at + 8 * i + 8].try_into().unwrap());
                    assert_eq!(stored, *v, "array `{name}` value {i} at its offset");
                }
                at += 8 * values.len();
            }
            assert_eq!(at + CHECKSUM_LEN, bytes.len(), "the checksum ends the file");
        }
        assert_eq!(paddings.len(), 8, "every padding 0..=7 was exercised: {paddings:?}");
    }

    #[test]
    fn large_arrays_round_trip_across_write_chunks() {
        let n = 3 * WRITE_CHUNK + 5;
        let mut c = Container::new(json!({"large": true}));
        c.push("a", (0..n).map(|i| (i as f64).sin()).collect());
        c.push("b", (0..1_000_003).map(|i| i as f64 * 1e-3).collect());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("large.vocab");
        c.write(&path).unwrap();
        assert_eq!(fs::metadata(&path).unwrap().len(), c.to_bytes().unwrap().len() as u64);
        let read = Container::read(&path).unwrap();
        assert_eq!(bits(read.array("a").unwrap()), bits(c.array("a").unwrap()));
        assert_eq!(read.array("b").unwrap().len(), 1_000_003);
        assert_eq!(read.array("b").unwrap()[1_000_002], 1_000_002.0 * 1e-3);
    }

    #[test]
    fn take_moves_an_array_out_and_array_finds_by_name() {
        let mut c = sample();
        assert_eq!(c.array("mean"), Some(&[1.0, -2.5, 3.25][..]));
        assert_eq!(c.take("mean"), Some(vec![1.0, -2.5, 3.25]));
        assert_eq!(c.array("mean"), None);
        assert_eq!(c.take("mean"), None);
        assert_eq!(c.names().collect::<Vec<_>>(), ["empty", "special", "ramp"]);
    }

    #[test]
    fn write_then_read_gives_the_same_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.vocab");
        let c = sample();
        c.write(&path).unwrap();
        assert_eq!(fs::read(&path).unwrap(), c.to_bytes().unwrap());
        let read = Container::read(&path).unwrap();
        assert_eq!(read.header, c.header);
        assert_eq!(bits(read.array("special").unwrap()), bits(c.array("special").unwrap()));
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn failed_write_into_missing_directory_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no-such-dir").join("v.vocab");
        let err = sample().write(&path).unwrap_err();
        assert!(matches!(*err.kind, ContainerErrorKind::Write(_)), "{err}");
        assert!(err.to_string().starts_with(&format!("{}: cannot write: ", path.display())), "{err}");
        assert!(!path.exists());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn header_with_reserved_key_is_refused_and_keeps_the_existing_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.vocab");
        fs::write(&path, b"old").unwrap();
        for key in RESERVED_KEYS {
            let mut header = Map::new();
            header.insert(key.to_string(), json!(1));
            let c = Container::new(Value::Object(header));
            assert_eq!(c.to_bytes().unwrap_err(), InvalidContainer::ReservedKey { key });
            let err = c.write(&path).unwrap_err();
            assert!(matches!(*err.kind, ContainerErrorKind::Invalid(InvalidContainer::ReservedKey { .. })));
            assert_eq!(
                err.to_string(),
                format!(
                    "{}: cannot write: the header has the key `{key}`, which the container writes itself",
                    path.display()
                )
            );
        }
        assert_eq!(fs::read(&path).unwrap(), b"old");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn header_that_is_not_an_object_and_duplicate_names_are_refused() {
        assert_eq!(
            Container::new(json!([1, 2])).to_bytes().unwrap_err(),
            InvalidContainer::HeaderNotObject { found: "a list" }
        );
        let mut c = Container::new(json!({}));
        c.push("x", vec![1.0]);
        c.push("x", vec![2.0]);
        assert_eq!(c.to_bytes().unwrap_err(), InvalidContainer::DuplicateArray { name: "x".into() });
    }

    #[test]
    fn missing_file_is_a_read_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("absent.vocab");
        let err = error_of(Container::read(&path));
        assert!(matches!(*err.kind, ContainerErrorKind::Read(_)));
        assert!(err.to_string().starts_with(&format!("{}: cannot read: ", path.display())), "{err}");
    }

    #[test]
    fn other_files_are_not_vocabulary_files_and_the_message_shows_their_start() {
        let cases: [(&[u8], &str); 6] = [
            (b"HIERARCHY\nROOT Hips\n", "not a vocabulary file: it starts with `HIERARCHY`"),
            (b"", "not a vocabulary file: the file is empty"),
            (
                b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR",
                "not a vocabulary file: it starts with binary data (89 50 4e 47 0d 0a 1a 0a …)",
            ),
            (b"  {\"arrays\": []}", "it starts with `{\"arrays\": []}`"),
            (b"imitate-vocab\r\n\x01\0\0\0", "but then byte 0x0d instead of a line feed"),
            (b"imitate-vocaX\n", "it starts with `imitate-vocaX`"),
        ];
        for (bytes, expected) in cases {
            let kind = refused(bytes, expected);
            assert!(matches!(kind, ContainerErrorKind::NotVocab { .. }), "{kind}");
        }
        let long = "x".repeat(100);
        refused(long.as_bytes(), &format!("it starts with `{}…`", "x".repeat(40)));
    }

    #[test]
    fn newer_version_asks_to_update_and_version_zero_is_unknown() {
        let mut bytes = sample().to_bytes().unwrap();
        bytes[VERSION_AT..HEADER_LEN_AT].copy_from_slice(&3u32.to_le_bytes());
        reseal(&mut bytes);
        let kind =
            refused(&bytes, "written by a newer imitate (format version 3; this version reads 2): update imitate");
        assert!(matches!(kind, ContainerErrorKind::NewerVersion { version: 3 }));

        bytes[VERSION_AT..HEADER_LEN_AT].copy_from_slice(&0u32.to_le_bytes());
        reseal(&mut bytes);
        let kind = refused(&bytes, "unknown format version 0 (this version reads 2");
        assert!(matches!(kind, ContainerErrorKind::UnknownVersion { version: 0 }));
    }

    #[test]
    fn a_vocabulary_of_the_earlier_joint_space_asks_to_be_built_again() {
        let mut bytes = sample().to_bytes().unwrap();
        bytes[VERSION_AT..HEADER_LEN_AT].copy_from_slice(&1u32.to_le_bytes());
        reseal(&mut bytes);
        let kind = refused(&bytes, "format version 1, whose poses are in an earlier joint space");
        assert!(matches!(kind, ContainerErrorKind::OlderJointSpace { version: 1 }), "{kind}");
        assert!(kind.to_string().contains("imitate vocab build"), "{kind}");
    }

    #[test]
    fn newer_version_is_reported_even_if_the_rest_is_unreadable() {
        // A newer format may change everything after the version.
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&3u32.to_le_bytes());
        bytes.extend_from_slice(b"whatever version 3 holds");
        assert!(matches!(refused(&bytes, "newer imitate"), ContainerErrorKind::NewerVersion { version: 3 }));
    }

    #[test]
    fn every_cut_of_a_valid_file_is_refused_as_truncated() {
        let bytes = sample().to_bytes().unwrap();
        let h = header_len(&bytes);
        assert_eq!(refused(&bytes[..0], "the file is empty").to_string(), "not a vocabulary file: the file is empty");
        for cut in 1..bytes.len() {
            let kind = refused(&bytes[..cut], &format!("truncated: {cut} bytes, "));
            let ContainerErrorKind::Truncated { len, needed } = kind else { panic!("cut at {cut}: {kind}") };
            assert_eq!(len, cut as u64);
            let expected = if cut < HEADER_AT {
                Needed::Minimum(MIN_FILE_LEN)
            } else if cut < HEADER_AT + h + CHECKSUM_LEN {
                Needed::HeaderAtLeast((HEADER_AT + h + CHECKSUM_LEN) as u128)
            } else {
                Needed::Exactly(bytes.len() as u128)
            };
            assert_eq!(needed, expected, "cut at {cut}");
        }
        let message = error_of(Container::from_bytes(&bytes[..bytes.len() - 1], NAME)).to_string();
        assert_eq!(
            message,
            format!("{NAME}: truncated: {} bytes, the header describes {}", bytes.len() - 1, bytes.len())
        );
    }

    #[test]
    fn every_single_byte_change_is_refused_for_the_right_reason() {
        let bytes = sample().to_bytes().unwrap();
        let header_end = HEADER_AT + header_len(&bytes);
        for at in 0..bytes.len() {
            for flip in [0x01u8, 0x02, 0x10, 0x80, 0xff, 0x5a] {
                let mut changed = bytes.clone();
                changed[at] ^= flip;
                let err = error_of(Container::from_bytes(&changed, NAME));
                assert!(err.to_string().starts_with(NAME));
                let kind = *err.kind;
                let right = match at {
                    _ if at < VERSION_AT => matches!(kind, ContainerErrorKind::NotVocab { .. }),
                    _ if at < HEADER_LEN_AT => {
                        match u32::from_le_bytes(changed[VERSION_AT..HEADER_LEN_AT].try_into().unwrap()) {
                            0 => matches!(kind, ContainerErrorKind::UnknownVersion { version: 0 }),
                            1 => matches!(kind, ContainerErrorKind::OlderJointSpace { version: 1 }),
                            v => matches!(kind, ContainerErrorKind::NewerVersion { version } if version == v),
                        }
                    }
                    // A header running past the file is a cut file; within the file,
                    // a shorter header cuts the JSON and a longer one takes in the
                    // padding's zero bytes after it.
                    _ if at < HEADER_AT => {
                        if (HEADER_AT + CHECKSUM_LEN) as u128 + header_len(&changed) as u128 > changed.len() as u128 {
                            matches!(kind, ContainerErrorKind::Truncated { needed: Needed::HeaderAtLeast(_), .. })
                        } else {
                            matches!(kind, ContainerErrorKind::BadHeader { .. })
                        }
                    }
                    _ if at < header_end => {
                        matches!(kind, ContainerErrorKind::BadHeader { .. } | ContainerErrorKind::Corrupt { .. })
                    }
                    _ => matches!(kind, ContainerErrorKind::Corrupt { .. }),
                };
                assert!(right, "byte {at} ^ {flip:#04x}: {kind}");
            }
        }
    }

    #[test]
    fn corrupt_data_is_reported_with_both_checksums() {
        let mut bytes = sample().to_bytes().unwrap();
        let stored = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().unwrap());
        let last_value = bytes.len() - 5;
        bytes[last_value] ^= 0x40;
        let computed = crc32fast::hash(&bytes[..bytes.len() - 4]);
        let kind = refused(
            &bytes,
            &format!("corrupt: checksum {stored:#010x} stored in the file does not match {computed:#010x} computed"),
        );
        assert!(matches!(kind, ContainerErrorKind::Corrupt { .. }));
    }

    #[test]
    fn bytes_after_the_checksum_are_refused_as_trailing() {
        let mut bytes = sample().to_bytes().unwrap();
        let end = bytes.len();
        bytes.extend_from_slice(b"junk");
        let kind =
            refused(&bytes, &format!("4 trailing bytes after the checksum, which should end the file at byte {end}"));
        assert!(matches!(kind, ContainerErrorKind::TrailingBytes { extra: 4, .. }));
        // Two files glued together: the second is trailing bytes of the first.
        let mut twice = sample().to_bytes().unwrap();
        twice.extend_from_slice(&sample().to_bytes().unwrap());
        assert!(matches!(refused(&twice, "trailing bytes"), ContainerErrorKind::TrailingBytes { .. }));
    }

    #[test]
    fn huge_header_lengths_are_truncation_not_allocation() {
        let valid = sample().to_bytes().unwrap();
        for huge in [1_000_000_000_000_000_000u64, u64::MAX, u64::MAX - 25, (1 << 63) + 1] {
            let mut bytes = valid.clone();
            bytes[HEADER_LEN_AT..HEADER_AT].copy_from_slice(&huge.to_le_bytes());
            let expected = huge as u128 + 30;
            let kind = refused(&bytes, &format!("the header length says at least {expected}"));
            assert!(
                matches!(kind, ContainerErrorKind::Truncated { needed: Needed::HeaderAtLeast(n), .. } if n == expected)
            );
        }
    }

    #[test]
    fn malformed_headers_are_refused_each_with_its_reason() {
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (
                b"{\"arrays\":[],\"data_bytes\":0,\"k\":\"\xff\"}".to_vec(),
                "not UTF-8 (invalid byte at header offset 33)",
            ),
            (b"{\"arrays\":[],".to_vec(), "not valid JSON (EOF while parsing"),
            (b"[1,2]".to_vec(), "the JSON header is a list, not an object"),
            (b"{\"data_bytes\":0}".to_vec(), "has no `arrays` list"),
            (b"{\"arrays\":{},\"data_bytes\":0}".to_vec(), "`arrays` is an object, not a list"),
            (b"{\"arrays\":[]}".to_vec(), "has no `data_bytes`"),
            (b"{\"arrays\":[],\"data_bytes\":-1}".to_vec(), "`data_bytes` is not a whole number: -1"),
            (b"{\"arrays\":[3],\"data_bytes\":0}".to_vec(), "`arrays` entry 0 is a number, not an object"),
            (b"{\"arrays\":[{\"len\":0}],\"data_bytes\":0}".to_vec(), "entry 0 has no `name` string"),
            (
                b"{\"arrays\":[{\"name\":\"a\"}],\"data_bytes\":0}".to_vec(),
                "entry 0 (`a`) has no `len` that is a whole number",
            ),
            (
                b"{\"arrays\":[{\"name\":\"a\",\"len\":1.5}],\"data_bytes\":12}".to_vec(),
                "has no `len` that is a whole number",
            ),
            (b"{\"arrays\":[{\"name\":\"a\",\"len\":0,\"x\":1}],\"data_bytes\":0}".to_vec(), "has the unknown key `x`"),
            (
                b"{\"arrays\":[{\"name\":\"a\",\"len\":0},{\"name\":\"a\",\"len\":0}],\"data_bytes\":0}".to_vec(),
                "lists the name `a` twice",
            ),
            (
                b"{\"arrays\":[{\"name\":\"a\",\"len\":1}],\"data_bytes\":16}".to_vec(),
                "`data_bytes` is 16, but the arrays' lengths add up to 8 bytes",
            ),
            (
                b"{\"arrays\":[{\"name\":\"a\",\"len\":2305843009213693952}],\"data_bytes\":0}".to_vec(),
                "array `a` has 2305843009213693952 values, which makes the data larger than any file can be",
            ),
            (
                format!(
                    "{{\"arrays\":[{{\"name\":\"a\",\"len\":{n}}},{{\"name\":\"b\",\"len\":{n}}}],\"data_bytes\":0}}",
                    n = 1u64 << 60
                )
                .into_bytes(),
                "array `b` has 1152921504606846976 values, which makes the data larger",
            ),
        ];
        for (header, expected) in cases {
            let bytes = assemble(FORMAT_VERSION, &header, &[1.0]);
            refused(&bytes, "bad header: ");
            let kind = refused(&bytes, expected);
            assert!(matches!(kind, ContainerErrorKind::BadHeader { .. }), "{expected}: {kind}");
        }
    }

    #[test]
    fn huge_declared_data_is_truncation_not_allocation() {
        let n = 1u64 << 60;
        let header = format!("{{\"arrays\":[{{\"name\":\"a\",\"len\":{n}}}],\"data_bytes\":{}}}", n * 8);
        let bytes = assemble(FORMAT_VERSION, header.as_bytes(), &[1.0, 2.0]);
        let kind = refused(&bytes, &format!("truncated: {} bytes, the header describes", bytes.len()));
        let expected = bytes.len() as u128 - 16 + u128::from(n * 8);
        assert!(matches!(kind, ContainerErrorKind::Truncated { needed: Needed::Exactly(e), .. } if e == expected));
    }

    #[test]
    fn random_mutations_never_panic_and_never_read_as_valid() {
        let valid = sample().to_bytes().unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(0x0c0a_b001);
        let mut refused_as = std::collections::BTreeMap::<&str, usize>::new();
        for _ in 0..2000 {
            let mut bytes = valid.clone();
            for _ in 0..rng.gen_range(1..=4) {
                let len = bytes.len();
                match rng.gen_range(0..7) {
                    0 if len > 0 => {
                        let at = rng.gen_range(0..len);
                        bytes[at] ^= 1 << rng.gen_range(0..8);
                    }
                    1 if len > 0 => {
                        let at = rng.gen_range(0..len);
                        bytes[at] = rng.r#gen();
                    }
                    2 => {
                        let at = rng.gen_range(0..=len);
                        bytes.insert(at, rng.r#gen());
                    }
                    3 if len > 0 => {
                        bytes.remove(rng.gen_range(0..len));
                    }
                    4 => bytes.truncate(rng.gen_range(0..=len)),
                    5 if len >= HEADER_AT => {
                        let field = rng.gen_range(VERSION_AT..HEADER_AT - 1);
                        bytes[field] = rng.r#gen();
                    }
                    _ => bytes.extend((0..rng.gen_range(1..9)).map(|_| rng.r#gen::<u8>())),
                }
            }
            if bytes == valid {
                continue;
            }
            let err = error_of(Container::from_bytes(&bytes, NAME));
            assert!(err.to_string().starts_with(NAME));
            let kind = match *err.kind {
                ContainerErrorKind::NotVocab { .. } => "not a vocabulary file",
                ContainerErrorKind::NewerVersion { .. } => "newer",
                ContainerErrorKind::UnknownVersion { .. } => "unknown version",
                ContainerErrorKind::OlderJointSpace { .. } => "older joint space",
                ContainerErrorKind::Truncated { .. } => "truncated",
                ContainerErrorKind::Corrupt { .. } => "corrupt",
                ContainerErrorKind::BadHeader { .. } => "bad header",
                ContainerErrorKind::TrailingBytes { .. } => "trailing",
                ContainerErrorKind::Read(_) | ContainerErrorKind::Write(_) | ContainerErrorKind::Invalid(_) => {
                    panic!("reading bytes cannot fail with {err}")
                }
            };
            *refused_as.entry(kind).or_default() += 1;
        }
        // The mutations reach every check, not just the first.
        for kind in ["not a vocabulary file", "newer", "truncated", "corrupt", "bad header"] {
            assert!(
                refused_as.get(kind).copied().unwrap_or(0) > 0,
                "no mutation was refused as {kind}: {refused_as:?}"
            );
        }
    }
}
