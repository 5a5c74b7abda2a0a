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
mod tests;
