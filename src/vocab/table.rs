//! Stage tables as Parquet or CSV.
//!
//! Every vocabulary stage (`imitate segment`, `embed`, `cluster`, `fit`)
//! reads the previous stage's table file and writes its own, so a researcher
//! can stop between stages, look at a table, or swap a stage for their own
//! tool. [`Table`] is the small typed layer they share; stage code never
//! touches polars.
//!
//! # File formats
//!
//! The extension chooses the format: `.csv` for small tables, `.parquet` for
//! large ones (any other extension is refused). Both hold the same ordered,
//! named columns, each of one type:
//!
//! | [`ColumnType`] | Parquet type (read also accepts)     | CSV field                                |
//! |----------------|--------------------------------------|------------------------------------------|
//! | `Str`          | string, no nulls                     | the text; empty text is written `""`     |
//! | `OptStr`       | string, nulls allowed                | empty field = absent, `""` = empty text  |
//! | `U32`          | uint32 (any integer width that fits) | decimal integer                          |
//! | `I32`          | int32 (any integer width that fits)  | decimal integer                          |
//! | `F64`          | double (or float)                    | shortest decimal that reads back exactly |
//!
//! CSV is comma-separated UTF-8 with `\n` line ends; a field holding a
//! comma, a quote or a line break is quoted, with quotes doubled. On
//! reading, an empty field in a `Str` column is the empty text (other
//! tools write it unquoted), spaces around numbers are allowed, and a
//! byte-order mark or `\r\n` line ends are accepted.
//!
//! # How a file says what kind of table it is
//!
//! Each table has a kind (`segments`, `embedding`, `clusters`, …), so a stage
//! fed another stage's file stops with a clear message instead of
//! misreading it:
//!
//! - **Parquet:** the file-level key-value metadata `imitate.table = <kind>`.
//!   It is part of the Parquet format, costs nothing per row, survives every
//!   reader, and other tools can write it (Python polars:
//!   `df.write_parquet(path, metadata={"imitate.table": "segments"})`;
//!   pyarrow: `table.replace_schema_metadata({"imitate.table": "segments"})`).
//! - **CSV:** the first line, before the header, is exactly
//!   `# imitate <kind> table`. CSV has no metadata, and a line of its own
//!   keeps the data columns clean; to read the file elsewhere skip the
//!   leading `#` lines (pandas `read_csv(path, skiprows=n)`, polars
//!   `skip_lines=n`), and to write one, print that line before the CSV.
//!
//! A table may also carry notes about how it was made (each stage records
//! its settings as one line of JSON under `build`): Parquet key-value
//! metadata `imitate.<key> = <value>`, or CSV lines `# <key>: <value>`
//! after the first line.
//!
//! [`Table::read`] refuses a file without this declaration, or of another
//! kind, naming the file, the kind found and the kind expected.
//!
//! # Reading
//!
//! [`Table::read`] loads the columns of a schema: a list of names and types.
//! A name ending in `*` stands for a numbered family of columns (`dim_*`:
//! `dim_0`, `dim_1`, … with no gaps, at least one). Columns the schema does
//! not list are ignored, so a user's tool may add its own. Integer columns
//! written with another integer width (pandas writes int64) are accepted
//! when every value fits. Rows are counted from 1, the first row after the
//! header. Values must be present except in `OptStr` columns, and `F64`
//! values must be finite: NaN or an infinity is refused, on writing as well
//! as on reading.
//!
//! # Exactness and determinism
//!
//! Parquet stores values bit for bit. CSV floats are written as the shortest
//! decimal that parses back to the same `f64` (polars formats them with
//! `zmij`, a Schubfach shortest-round-trip algorithm, and they are read back
//! with Rust's correctly rounded parser), so CSV round-trips exactly too,
//! `-0.0` included. Writing the same table twice gives byte-identical files:
//! Parquet has no timestamp (its `created_by` is the constant `Polars`), uses
//! zstd at its default level and row groups of 262 144 rows.
//!
//! Writing goes to a temporary file beside the target, renamed into place
//! when complete, so a failure never leaves a partial file. Reading never
//! panics: a file polars cannot parse is an error quoting polars' message,
//! and polars runs under `catch_unwind` as a last guard.

use std::collections::HashSet;
use std::fmt;
use std::io::{self, Cursor, Write};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use polars::prelude::{
    Column, CsvReadOptions, CsvWriter, DataFrame, DataType, KeyValueMetadata, ParquetCompression, ParquetReader,
    ParquetWriter, PolarsError, QuoteStyle, SerReader, SerWriter, StringChunked,
};

use crate::fsutil;

/// The Parquet key-value metadata key that holds a table's kind.
pub const PARQUET_KIND_KEY: &str = "imitate.table";
/// Parquet key-value metadata keys of table notes start with this.
const PARQUET_PREFIX: &str = "imitate.";
/// The note key reserved for the kind.
const KIND_KEY: &str = "table";

/// The type of a column of a stage table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColumnType {
    /// Text, present in every row.
    Str,
    /// Text that may be absent.
    OptStr,
    U32,
    I32,
    /// Finite 64-bit floats.
    F64,
}

impl ColumnType {
    fn range(self) -> &'static str {
        match self {
            ColumnType::U32 => "0 to 4294967295",
            ColumnType::I32 => "-2147483648 to 2147483647",
            _ => "",
        }
    }
}

impl fmt::Display for ColumnType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ColumnType::Str => "text",
            ColumnType::OptStr => "optional text",
            ColumnType::U32 => "u32",
            ColumnType::I32 => "i32",
            ColumnType::F64 => "f64",
        })
    }
}

/// The values of one column of a stage table.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    Str(Vec<String>),
    OptStr(Vec<Option<String>>),
    U32(Vec<u32>),
    I32(Vec<i32>),
    F64(Vec<f64>),
}

impl Values {
    /// The number of values.
    pub fn len(&self) -> usize {
        match self {
            Values::Str(v) => v.len(),
            Values::OptStr(v) => v.len(),
            Values::U32(v) => v.len(),
            Values::I32(v) => v.len(),
            Values::F64(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn column_type(&self) -> ColumnType {
        match self {
            Values::Str(_) => ColumnType::Str,
            Values::OptStr(_) => ColumnType::OptStr,
            Values::U32(_) => ColumnType::U32,
            Values::I32(_) => ColumnType::I32,
            Values::F64(_) => ColumnType::F64,
        }
    }
}

/// Why a table could not be written or read. Every case names the file.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    #[error("{path}: cannot {action}: {source}")]
    Io { path: String, action: &'static str, source: io::Error },
    #[error("{path}: a table file must end in `.csv` (small tables) or `.parquet` (large ones)")]
    UnsupportedExtension { path: String },
    #[error("{path}: not a readable {format} file: {message}")]
    Unreadable { path: String, format: &'static str, message: String },
    #[error("{path}: does not say what kind of table it is; a `{expected}` table declares itself with {declaration}")]
    Undeclared { path: String, expected: &'static str, declaration: String },
    #[error("{path} holds a table of kind `{found}`, but a table of kind `{expected}` is needed here")]
    WrongKind { path: String, found: String, expected: &'static str },
    #[error("{path}: the `{kind}` table has no column `{column}`; its columns are: {present}")]
    MissingColumn { path: String, kind: &'static str, column: String, present: String },
    #[error("{path}: column `{column}` should hold {expected} values but holds {found}")]
    WrongType { path: String, column: String, expected: ColumnType, found: String },
    #[error("{path}: column `{column}` has no value in row {row}")]
    Null { path: String, column: String, row: usize },
    #[error("{path}: column `{column}` holds {value} in row {row}; tables hold finite numbers only")]
    NonFinite { path: String, column: String, row: usize, value: f64 },
    #[error("{path}: column `{column}` holds {value} in row {row}, outside the {expected} range {}", .expected.range())]
    OutOfRange { path: String, column: String, row: usize, value: String, expected: ColumnType },
}

/// A stage table: a kind and ordered, named columns of equal length.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// What the table holds, e.g. `"segments"`; written into the file.
    pub kind: &'static str,
    columns: Vec<(String, Values)>,
    /// Named one-line texts about the whole table (how it was made).
    meta: Vec<(String, String)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Csv,
    Parquet,
}

impl Format {
    fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?;
        if ext.eq_ignore_ascii_case("csv") {
            Some(Format::Csv)
        } else if ext.eq_ignore_ascii_case("parquet") {
            Some(Format::Parquet)
        } else {
            None
        }
    }

    fn name(self) -> &'static str {
        match self {
            Format::Csv => "CSV",
            Format::Parquet => "Parquet",
        }
    }
}

impl Table {
    /// An empty table of `kind`.
    ///
    /// # Panics
    /// If `kind` is not a non-empty word of ASCII letters, digits, `_` or `-`
    /// (a programming error: kinds are constants).
    pub fn new(kind: &'static str) -> Self {
        assert!(valid_kind(kind), "table kind {kind:?} must be a non-empty word of ASCII letters, digits, `_`, `-`");
        Table { kind, columns: Vec::new(), meta: Vec::new() }
    }

    /// Appends a column.
    ///
    /// # Panics
    /// If `name` is empty or already used, or `values` has a different
    /// length than the columns before it. These are programming errors in
    /// the stage building the table, never caused by an input file.
    pub fn push(&mut self, name: &str, values: Values) -> &mut Self {
        assert!(!name.is_empty(), "a `{}` table column needs a name", self.kind);
        assert!(self.column(name).is_none(), "the `{}` table already has a column `{name}`", self.kind);
        if let Some((first, v)) = self.columns.first() {
            assert_eq!(
                values.len(),
                v.len(),
                "column `{name}` of the `{}` table has {} rows, but `{first}` has {}",
                self.kind,
                values.len(),
                v.len()
            );
        }
        self.columns.push((name.to_owned(), values));
        self
    }

    /// Sets a table-wide note: `key` a word (as kinds are), `value` one
    /// line of text.
    ///
    /// # Panics
    /// If `key` is not a word or `value` holds a line break (programming
    /// errors: keys are constants, values compact JSON).
    pub fn set_meta(&mut self, key: &str, value: String) -> &mut Self {
        assert!(valid_kind(key) && key != KIND_KEY, "table meta key {key:?} must be a word other than `{KIND_KEY}`");
        assert!(!value.contains(['\n', '\r']), "table meta `{key}` must be one line");
        self.meta.retain(|(k, _)| k != key);
        self.meta.push((key.to_owned(), value));
        self
    }

    /// A table-wide note set with [`Table::set_meta`] (or read from the file).
    pub fn meta(&self, key: &str) -> Option<&str> {
        self.meta.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    /// The number of rows (0 for a table without columns).
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |(_, v)| v.len())
    }

    /// The column names, in order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.columns.iter().map(|(n, _)| n.as_str())
    }

    /// The values of the column `name`, if the table has it.
    pub fn column(&self, name: &str) -> Option<&Values> {
        self.columns.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    fn typed(&self, name: &str, want: ColumnType) -> &Values {
        match self.column(name) {
            Some(v) if v.column_type() == want => v,
            Some(v) => panic!("column `{name}` of the `{}` table is {}, not {want}", self.kind, v.column_type()),
            None => panic!("the `{}` table has no column `{name}`", self.kind),
        }
    }

    /// The text column `name`.
    ///
    /// # Panics
    /// If there is no such column of that type: a column [`Table::read`]
    /// checked through its schema is always there.
    pub fn str(&self, name: &str) -> &[String] {
        match self.typed(name, ColumnType::Str) {
            Values::Str(v) => v,
            _ => unreachable!(),
        }
    }

    /// The optional-text column `name`. Panics like [`Table::str`].
    pub fn opt_str(&self, name: &str) -> &[Option<String>] {
        match self.typed(name, ColumnType::OptStr) {
            Values::OptStr(v) => v,
            _ => unreachable!(),
        }
    }

    /// The `u32` column `name`. Panics like [`Table::str`].
    pub fn u32(&self, name: &str) -> &[u32] {
        match self.typed(name, ColumnType::U32) {
            Values::U32(v) => v,
            _ => unreachable!(),
        }
    }

    /// The `i32` column `name`. Panics like [`Table::str`].
    pub fn i32(&self, name: &str) -> &[i32] {
        match self.typed(name, ColumnType::I32) {
            Values::I32(v) => v,
            _ => unreachable!(),
        }
    }

    /// The `f64` column `name`. Panics like [`Table::str`].
    pub fn f64(&self, name: &str) -> &[f64] {
        match self.typed(name, ColumnType::F64) {
            Values::F64(v) => v,
            _ => unreachable!(),
        }
    }

    /// The `f64` columns named `prefix` followed by a number (`dim_0`,
    /// `dim_1`, …), sorted by that number (so `dim_10` follows `dim_9`).
    pub fn f64_columns_with_prefix(&self, prefix: &str) -> Vec<(String, &[f64])> {
        let mut found: Vec<(usize, String, &[f64])> = self
            .columns
            .iter()
            .filter_map(|(name, values)| match values {
                Values::F64(v) => numbered(name, prefix).map(|i| (i, name.clone(), v.as_slice())),
                _ => None,
            })
            .collect();
        found.sort_by_key(|(i, _, _)| *i);
        found.into_iter().map(|(_, name, v)| (name, v)).collect()
    }

    /// Writes the table to `path`: Parquet when it ends in `.parquet`, CSV
    /// when it ends in `.csv`. The write is atomic (a temporary sibling
    /// renamed into place) and deterministic (the same table gives the same
    /// bytes). NaN or infinite values are refused and nothing is written.
    pub fn write(&self, path: &Path) -> Result<(), TableError> {
        let display = path.display().to_string();
        let format = Format::of(path).ok_or_else(|| TableError::UnsupportedExtension { path: display.clone() })?;
        for (name, values) in &self.columns {
            if let Values::F64(v) = values
                && let Some(i) = v.iter().position(|x| !x.is_finite())
            {
                return Err(TableError::NonFinite { path: display, column: name.clone(), row: i + 1, value: v[i] });
            }
        }
        let io_error = |source| TableError::Io { path: display.clone(), action: "write", source };
        let mut df = self.to_dataframe().map_err(|e| io_error(io::Error::other(brief(&e))))?;
        let kind = self.kind;
        fsutil::write_atomic(path, |out| {
            match format {
                Format::Parquet => {
                    let pairs = std::iter::once((PARQUET_KIND_KEY.to_owned(), kind.to_owned()))
                        .chain(self.meta.iter().map(|(k, v)| (format!("{PARQUET_PREFIX}{k}"), v.clone())))
                        .collect();
                    let metadata = KeyValueMetadata::from_static(pairs);
                    ParquetWriter::new(&mut *out)
                        .with_compression(ParquetCompression::Zstd(None))
                        .with_key_value_metadata(Some(metadata))
                        .finish(&mut df)
                        .map_err(|e| io::Error::other(brief(&e)))?;
                }
                Format::Csv => {
                    writeln!(out, "# imitate {kind} table")?;
                    for (key, value) in &self.meta {
                        writeln!(out, "# {key}: {value}")?;
                    }
                    CsvWriter::new(&mut *out)
                        .include_header(true)
                        .include_bom(false)
                        .with_separator(b',')
                        .with_quote_char(b'"')
                        .with_quote_style(QuoteStyle::Necessary)
                        .with_line_terminator("\n".into())
                        .with_float_precision(None)
                        .with_float_scientific(None)
                        .finish(&mut df)
                        .map_err(|e| io::Error::other(brief(&e)))?;
                }
            }
            Ok(())
        })
        .map_err(io_error)
    }

    fn to_dataframe(&self) -> Result<DataFrame, PolarsError> {
        let columns = self
            .columns
            .iter()
            .map(|(name, values)| {
                let name = name.as_str().into();
                match values {
                    Values::Str(v) => Column::new(name, v),
                    Values::OptStr(v) => Column::new(name, v),
                    Values::U32(v) => Column::new(name, v),
                    Values::I32(v) => Column::new(name, v),
                    Values::F64(v) => Column::new(name, v),
                }
            })
            .collect();
        DataFrame::new(self.rows(), columns)
    }

    /// Reads a table of `kind` written by [`Table::write`] (or by another
    /// tool, with the same declaration and columns), in the format its
    /// extension names. Checks the file declares that kind and has every
    /// column of `schema` with values of its type; a schema name ending in
    /// `*` loads a numbered family (`dim_*`: `dim_0`, `dim_1`, …). Returns
    /// the schema's columns, in schema order; other columns are ignored.
    /// Never panics on a bad file.
    pub fn read(path: &Path, kind: &'static str, schema: &[(&str, ColumnType)]) -> Result<Table, TableError> {
        let display = path.display().to_string();
        let format = Format::of(path).ok_or_else(|| TableError::UnsupportedExtension { path: display.clone() })?;
        let ctx = Ctx { path: display, kind };
        let bytes =
            std::fs::read(path).map_err(|source| TableError::Io { path: ctx.path.clone(), action: "read", source })?;
        let read = catch_unwind(AssertUnwindSafe(|| match format {
            Format::Parquet => read_parquet(&ctx, bytes, schema),
            Format::Csv => read_csv(&ctx, &bytes, schema),
        }))
        .unwrap_or_else(|panic| {
            let message = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "the reader failed".to_owned());
            Err(ctx.unreadable(format, format!("polars panicked: {message}")))
        });
        let (columns, meta) = read?;
        Ok(Table { kind, columns, meta })
    }
}

/// The file being read and the kind of table wanted, for error messages.
struct Ctx {
    path: String,
    kind: &'static str,
}

impl Ctx {
    fn unreadable(&self, format: Format, message: String) -> TableError {
        TableError::Unreadable { path: self.path.clone(), format: format.name(), message }
    }

    fn check_kind(&self, found: &str) -> Result<(), TableError> {
        if found == self.kind {
            Ok(())
        } else {
            Err(TableError::WrongKind { path: self.path.clone(), found: shorten(found, 80), expected: self.kind })
        }
    }

    fn wrong_type(&self, column: &str, expected: ColumnType, found: String) -> TableError {
        TableError::WrongType { path: self.path.clone(), column: column.to_owned(), expected, found }
    }

    fn null(&self, column: &str, index: usize) -> TableError {
        TableError::Null { path: self.path.clone(), column: column.to_owned(), row: index + 1 }
    }

    fn non_finite(&self, column: &str, index: usize, value: f64) -> TableError {
        TableError::NonFinite { path: self.path.clone(), column: column.to_owned(), row: index + 1, value }
    }

    fn out_of_range(&self, column: &str, index: usize, value: String, expected: ColumnType) -> TableError {
        TableError::OutOfRange { path: self.path.clone(), column: column.to_owned(), row: index + 1, value, expected }
    }

    /// Matches `schema` against the file's column names: the names to load,
    /// with their types, in schema order (families expanded in number order).
    fn resolve(
        &self,
        present: &[String],
        schema: &[(&str, ColumnType)],
    ) -> Result<Vec<(String, ColumnType)>, TableError> {
        let missing = |column: String| TableError::MissingColumn {
            path: self.path.clone(),
            kind: self.kind,
            column,
            present: if present.is_empty() {
                "(none)".to_owned()
            } else {
                shorten(&present.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", "), 2000)
            },
        };
        let mut wanted = Vec::new();
        for &(name, ty) in schema {
            if let Some(prefix) = name.strip_suffix('*') {
                let numbers: HashSet<usize> = present.iter().filter_map(|n| numbered(n, prefix)).collect();
                if let Some(gap) = (0..=numbers.len()).find(|i| !numbers.contains(i))
                    && (gap < numbers.len() || numbers.is_empty())
                {
                    return Err(missing(format!("{prefix}{gap}")));
                }
                wanted.extend((0..numbers.len()).map(|i| (format!("{prefix}{i}"), ty)));
            } else if present.iter().any(|n| n == name) {
                wanted.push((name.to_owned(), ty));
            } else {
                return Err(missing(name.to_owned()));
            }
        }
        Ok(wanted)
    }
}

/// A table's columns and notes, as read.
type Read = (Vec<(String, Values)>, Vec<(String, String)>);

fn read_parquet(ctx: &Ctx, bytes: Vec<u8>, schema: &[(&str, ColumnType)]) -> Result<Read, TableError> {
    let unreadable = |e: PolarsError| ctx.unreadable(Format::Parquet, brief(&e));
    let mut reader = ParquetReader::new(Cursor::new(bytes));
    let metadata = reader.get_metadata().map_err(unreadable)?;
    let found = metadata
        .key_value_metadata()
        .iter()
        .flatten()
        .find(|kv| kv.key == PARQUET_KIND_KEY)
        .and_then(|kv| kv.value.clone());
    let Some(found) = found else {
        return Err(TableError::Undeclared {
            path: ctx.path.clone(),
            expected: ctx.kind,
            declaration: format!("the Parquet key-value metadata `{PARQUET_KIND_KEY} = {}`", ctx.kind),
        });
    };
    ctx.check_kind(&found)?;
    let meta = metadata
        .key_value_metadata()
        .iter()
        .flatten()
        .filter(|kv| kv.key != PARQUET_KIND_KEY)
        .filter_map(|kv| Some((kv.key.strip_prefix(PARQUET_PREFIX)?.to_owned(), kv.value.clone()?)))
        .collect();
    let present: Vec<String> = reader.schema().map_err(unreadable)?.iter_names().map(|n| n.to_string()).collect();
    let wanted = ctx.resolve(&present, schema)?;
    let df = reader.with_columns(Some(wanted.iter().map(|(n, _)| n.clone()).collect())).finish().map_err(unreadable)?;
    let columns = wanted
        .into_iter()
        .map(|(name, ty)| {
            let column = df.column(&name).map_err(unreadable)?;
            let values = parquet_values(ctx, &name, ty, column)?;
            Ok((name, values))
        })
        .collect::<Result<_, TableError>>()?;
    Ok((columns, meta))
}

fn parquet_values(ctx: &Ctx, name: &str, ty: ColumnType, column: &Column) -> Result<Values, TableError> {
    let dtype = column.dtype().clone();
    let wrong = || ctx.wrong_type(name, ty, format!("{dtype} values"));
    let cast = |to: DataType| column.cast(&to).map_err(|_| wrong());
    match ty {
        ColumnType::Str | ColumnType::OptStr => {
            if ty == ColumnType::OptStr && dtype == DataType::Null {
                return Ok(Values::OptStr(vec![None; column.len()]));
            }
            let strings = column.str().map_err(|_| wrong())?;
            if ty == ColumnType::OptStr {
                Ok(Values::OptStr(strings.iter().map(|s| s.map(str::to_owned)).collect()))
            } else {
                strings
                    .iter()
                    .enumerate()
                    .map(|(i, s)| s.map(str::to_owned).ok_or_else(|| ctx.null(name, i)))
                    .collect::<Result<_, _>>()
                    .map(Values::Str)
            }
        }
        ColumnType::U32 | ColumnType::I32 => {
            let wide: Vec<Option<i128>> = match dtype {
                DataType::UInt8 | DataType::UInt16 | DataType::UInt32 | DataType::UInt64 => {
                    let c = cast(DataType::UInt64)?;
                    c.u64().map_err(|_| wrong())?.iter().map(|v| v.map(i128::from)).collect()
                }
                DataType::Int8 | DataType::Int16 | DataType::Int32 | DataType::Int64 => {
                    let c = cast(DataType::Int64)?;
                    c.i64().map_err(|_| wrong())?.iter().map(|v| v.map(i128::from)).collect()
                }
                _ => return Err(wrong()),
            };
            let value = |i: usize, v: Option<i128>| v.ok_or_else(|| ctx.null(name, i));
            if ty == ColumnType::U32 {
                wide.into_iter()
                    .enumerate()
                    .map(|(i, v)| {
                        let v = value(i, v)?;
                        u32::try_from(v).map_err(|_| ctx.out_of_range(name, i, v.to_string(), ty))
                    })
                    .collect::<Result<_, _>>()
                    .map(Values::U32)
            } else {
                wide.into_iter()
                    .enumerate()
                    .map(|(i, v)| {
                        let v = value(i, v)?;
                        i32::try_from(v).map_err(|_| ctx.out_of_range(name, i, v.to_string(), ty))
                    })
                    .collect::<Result<_, _>>()
                    .map(Values::I32)
            }
        }
        ColumnType::F64 => {
            if !matches!(dtype, DataType::Float32 | DataType::Float64) {
                return Err(wrong());
            }
            let c = cast(DataType::Float64)?;
            c.f64()
                .map_err(|_| wrong())?
                .iter()
                .enumerate()
                .map(|(i, v)| match v {
                    None => Err(ctx.null(name, i)),
                    Some(x) if !x.is_finite() => Err(ctx.non_finite(name, i, x)),
                    Some(x) => Ok(x),
                })
                .collect::<Result<_, _>>()
                .map(Values::F64)
        }
    }
}

fn read_csv(ctx: &Ctx, bytes: &[u8], schema: &[(&str, ColumnType)]) -> Result<Read, TableError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let line_end = bytes.iter().position(|&b| b == b'\n').map_or(bytes.len(), |i| i + 1);
    let first = String::from_utf8_lossy(&bytes[..line_end]);
    let found = first
        .trim_end()
        .strip_prefix("# imitate ")
        .and_then(|rest| rest.strip_suffix(" table"))
        .filter(|k| !k.is_empty() && !k.contains(char::is_whitespace));
    let Some(found) = found else {
        return Err(TableError::Undeclared {
            path: ctx.path.clone(),
            expected: ctx.kind,
            declaration: format!("the first line `# imitate {} table`", ctx.kind),
        });
    };
    ctx.check_kind(found)?;
    // Notes: `# key: value` lines before the header.
    let mut rest = &bytes[line_end..];
    let mut meta = Vec::new();
    while let Some(line) = rest.strip_prefix(b"# ") {
        let end = line.iter().position(|&b| b == b'\n').map_or(line.len(), |i| i + 1);
        let text = String::from_utf8_lossy(&line[..end]);
        if let Some((key, value)) = text.trim_end_matches(['\n', '\r']).split_once(": ") {
            meta.push((key.to_owned(), value.to_owned()));
        }
        rest = &line[end..];
    }
    if rest.iter().all(u8::is_ascii_whitespace) {
        return Err(ctx.unreadable(Format::Csv, "no header line after the first line".to_owned()));
    }
    // Every column is read as text and converted here, so the messages can
    // name the column and row, and floats are parsed by Rust's exact parser.
    let df = CsvReadOptions::default()
        .with_has_header(true)
        .with_infer_schema_length(Some(0))
        .with_raise_if_empty(true)
        .into_reader_with_file_handle(Cursor::new(rest))
        .finish()
        .map_err(|e| ctx.unreadable(Format::Csv, brief(&e)))?;
    let present: Vec<String> = df.get_column_names().iter().map(|n| n.to_string()).collect();
    let wanted = ctx.resolve(&present, schema)?;
    let columns = wanted
        .into_iter()
        .map(|(name, ty)| {
            let text = df.column(&name).and_then(|c| c.str()).map_err(|e| ctx.unreadable(Format::Csv, brief(&e)))?;
            let values = csv_values(ctx, &name, ty, text)?;
            Ok((name, values))
        })
        .collect::<Result<_, TableError>>()?;
    Ok((columns, meta))
}

fn csv_values(ctx: &Ctx, name: &str, ty: ColumnType, text: &StringChunked) -> Result<Values, TableError> {
    let cells = text.iter();
    fn number<'a>(ctx: &Ctx, name: &str, i: usize, s: Option<&'a str>) -> Result<&'a str, TableError> {
        match s.map(str::trim) {
            None | Some("") => Err(ctx.null(name, i)),
            Some(s) => Ok(s),
        }
    }
    let not_a = |i: usize, s: &str| ctx.wrong_type(name, ty, format!("`{}` in row {}", shorten(s, 40), i + 1));
    // A row's integer, with its row.
    let integer = |(i, s): (usize, Option<&str>)| -> Result<(usize, i128), TableError> {
        let s = number(ctx, name, i, s)?;
        s.parse::<i128>().map(|v| (i, v)).map_err(|_| not_a(i, s))
    };
    let out_of_range = |i: usize, v: i128| ctx.out_of_range(name, i, v.to_string(), ty);
    /// Each row's integer as a `T`, if it fits.
    fn narrowed<T: TryFrom<i128>>(
        rows: impl Iterator<Item = Result<(usize, i128), TableError>>,
        out_of_range: impl Fn(usize, i128) -> TableError,
    ) -> Result<Vec<T>, TableError> {
        rows.map(|row| {
            let (i, v) = row?;
            T::try_from(v).map_err(|_| out_of_range(i, v))
        })
        .collect()
    }
    Ok(match ty {
        // An empty field is the empty text in a text column (other tools
        // write "" unquoted) and an absent value in an optional one.
        ColumnType::Str => Values::Str(cells.map(|s| s.unwrap_or("").to_owned()).collect()),
        ColumnType::OptStr => Values::OptStr(cells.map(|s| s.map(str::to_owned)).collect()),
        ColumnType::U32 => Values::U32(narrowed(cells.enumerate().map(integer), out_of_range)?),
        ColumnType::I32 => Values::I32(narrowed(cells.enumerate().map(integer), out_of_range)?),
        ColumnType::F64 => Values::F64(
            cells
                .enumerate()
                .map(|(i, s)| {
                    let s = number(ctx, name, i, s)?;
                    match s.parse::<f64>() {
                        Ok(x) if x.is_finite() => Ok(x),
                        Ok(x) => Err(ctx.non_finite(name, i, x)),
                        Err(_) => Err(not_a(i, s)),
                    }
                })
                .collect::<Result<_, _>>()?,
        ),
    })
}

/// `Some(n)` when `name` is `prefix` followed by the decimal number `n`
/// written without leading zeros.
fn numbered(name: &str, prefix: &str) -> Option<usize> {
    let digits = name.strip_prefix(prefix)?;
    let canonical =
        !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) && (digits == "0" || !digits.starts_with('0'));
    if canonical { digits.parse().ok() } else { None }
}

fn valid_kind(kind: &str) -> bool {
    !kind.is_empty() && kind.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

/// The first line of a polars error, shortened.
fn brief(e: &PolarsError) -> String {
    let text = e.to_string();
    shorten(text.lines().find(|l| !l.trim().is_empty()).unwrap_or("unknown error").trim(), 300)
}

fn shorten(s: &str, max_chars: usize) -> String {
    match s.char_indices().nth(max_chars) {
        Some((end, _)) => format!("{}…", &s[..end]),
        None => s.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use std::fs;
    use std::path::PathBuf;

    use super::*;

    const SEGMENTS: &[(&str, ColumnType)] = &[
        ("take", ColumnType::Str),
        ("label", ColumnType::OptStr),
        ("start", ColumnType::U32),
        ("offset", ColumnType::I32),
        ("cost", ColumnType::F64),
    ];

    fn tricky_strings() -> Vec<String> {
        ["", "walk", "naïve 歩く 🚶", "a,b", "say \"hi\"", "two\nlines", "cr\r\nlf", " padded ", "#hash", "\"", ","]
            .map(String::from)
            .to_vec()
    }

    fn tricky_floats() -> Vec<f64> {
        vec![
            0.0,
            -0.0,
            0.1,
            1.0 / 3.0,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
            -1.5e-300,
            1e21,
            123_456_789.123_456_78,
        ]
    }

    /// A `segments` table holding every column type with awkward values.
    fn tricky() -> Table {
        let mut t = Table::new("segments");
        t.push("take", Values::Str(tricky_strings()))
            .push(
                "label",
                Values::OptStr(vec![
                    None,
                    Some(String::new()),
                    Some("wave".into()),
                    None,
                    Some("a,\"b\"\nc".into()),
                    Some("ü".into()),
                    None,
                    Some(" ".into()),
                    Some("NA".into()),
                    Some("null".into()),
                    None,
                ]),
            )
            .push("start", Values::U32(vec![0, 1, u32::MAX, 7, 42, 100, 3, 9, 11, 12, u32::MAX - 1]))
            .push("offset", Values::I32(vec![i32::MIN, -1, 0, 1, i32::MAX, -7, 5, -100, 3, 2, -2]))
            .push("cost", Values::F64(tricky_floats()));
        t
    }

    fn assert_same(a: &Table, b: &Table) {
        assert_eq!(a, b);
        for name in a.names() {
            if let (Some(Values::F64(x)), Some(Values::F64(y))) = (a.column(name), b.column(name)) {
                let bits = |v: &[f64]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(x), bits(y), "column {name} differs in its bits");
            }
        }
    }

    fn err_text(r: Result<Table, TableError>) -> String {
        r.expect_err("the read should fail").to_string()
    }

    /// Writes `df` as Parquet the way another tool would, with `kind` as its
    /// declaration when given.
    fn write_foreign_parquet(path: &Path, mut df: DataFrame, kind: Option<&str>) {
        let metadata = kind.map(|k| KeyValueMetadata::from_static(vec![(PARQUET_KIND_KEY.into(), k.into())]));
        let file = fs::File::create(path).unwrap();
        ParquetWriter::new(file).with_key_value_metadata(metadata).finish(&mut df).unwrap();
    }

    fn files_in(dir: &Path) -> Vec<PathBuf> {
        let mut v: Vec<_> = fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
        v.sort();
        v
    }

    #[test]
    fn parquet_and_csv_round_trips_keep_every_type_and_awkward_value_exactly() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["segments.parquet", "segments.csv"] {
            let path = dir.path().join(name);
            let table = tricky();
            table.write(&path).unwrap();
            assert_same(&Table::read(&path, "segments", SEGMENTS).unwrap(), &table);
        }
    }

    #[test]
    fn notes_round_trip_in_both_formats_and_the_data_stays_readable() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["notes.parquet", "notes.csv"] {
            let path = dir.path().join(name);
            let mut table = tricky();
            table.set_meta("build", r#"{"segment":{"method":"kcs"},"note":"a: b # c"}"#.into());
            table.set_meta("made_by", "imitate 0.1.0".into());
            table.write(&path).unwrap();
            let back = Table::read(&path, "segments", SEGMENTS).unwrap();
            assert_same(&back, &table);
            assert_eq!(back.meta("build"), table.meta("build"), "{name}");
            assert_eq!(back.meta("made_by"), Some("imitate 0.1.0"), "{name}");
            assert_eq!(back.meta("absent"), None);
        }
        let csv = fs::read_to_string(dir.path().join("notes.csv")).unwrap();
        assert!(csv.starts_with("# imitate segments table\n# build: {"), "{csv}");
    }

    #[test]
    fn csv_floats_read_back_bit_for_bit() {
        // 20 000 finite doubles spread over every exponent and mantissa.
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut values = Vec::new();
        while values.len() < 20_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = f64::from_bits(state);
            if x.is_finite() {
                values.push(x);
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("floats.csv");
        let mut table = Table::new("floats");
        table.push("x", Values::F64(values));
        table.write(&path).unwrap();
        assert_same(&Table::read(&path, "floats", &[("x", ColumnType::F64)]).unwrap(), &table);
    }

    #[test]
    fn csv_text_is_the_documented_declaration_header_and_shortest_numbers() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        let mut table = Table::new("clusters");
        table
            .push("name", Values::Str(vec!["".into(), "a,b".into()]))
            .push("note", Values::OptStr(vec![None, Some("".into())]))
            .push("n", Values::U32(vec![u32::MAX, 0]))
            .push("x", Values::F64(vec![-0.0, 0.1]));
        table.write(&path).unwrap();
        let text = fs::read_to_string(&path).unwrap();
        assert_eq!(text, "# imitate clusters table\nname,note,n,x\n\"\",,4294967295,-0.0\n\"a,b\",\"\",0,0.1\n");
    }

    #[test]
    fn parquet_with_100k_rows_round_trips() {
        let n = 100_000;
        let mut table = Table::new("embedding");
        table
            .push("segment", Values::U32((0..n as u32).collect()))
            .push("take", Values::Str((0..n).map(|i| format!("take_{}", i % 97)).collect()))
            .push("dim_0", Values::F64((0..n).map(|i| (i as f64).sin()).collect()))
            .push("dim_1", Values::F64((0..n).map(|i| (i as f64 * 0.5).cos() * 1e-7).collect()));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("embedding.parquet");
        table.write(&path).unwrap();
        let schema = [("segment", ColumnType::U32), ("take", ColumnType::Str), ("dim_*", ColumnType::F64)];
        let back = Table::read(&path, "embedding", &schema).unwrap();
        assert_eq!(back.rows(), n);
        assert_same(&back, &table);
    }

    #[test]
    fn writing_the_same_table_twice_gives_identical_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let mut big = Table::new("embedding");
        big.push("segment", Values::U32((0..30_000).collect()))
            .push("dim_0", Values::F64((0..30_000).map(|i| f64::from(i).sqrt()).collect()));
        for (table, ext) in [(&tricky(), "csv"), (&tricky(), "parquet"), (&big, "parquet")] {
            let a = dir.path().join(format!("a.{ext}"));
            let b = dir.path().join(format!("b.{ext}"));
            table.write(&a).unwrap();
            table.write(&b).unwrap();
            assert_eq!(fs::read(&a).unwrap(), fs::read(&b).unwrap(), "{ext} bytes differ");
            // Reading and writing again reproduces the file too.
            let schema: Vec<(&str, ColumnType)> =
                table.columns.iter().map(|(n, v)| (n.as_str(), v.column_type())).collect();
            Table::read(&a, table.kind, &schema).unwrap().write(&b).unwrap();
            assert_eq!(fs::read(&a).unwrap(), fs::read(&b).unwrap(), "{ext} bytes differ after a round trip");
        }
    }

    #[test]
    fn a_table_of_another_kind_is_refused_naming_the_file_and_both_kinds() {
        let dir = tempfile::tempdir().unwrap();
        for ext in ["csv", "parquet"] {
            let path = dir.path().join(format!("clusters.{ext}"));
            let mut table = Table::new("embedding");
            table.push("dim_0", Values::F64(vec![1.0]));
            table.write(&path).unwrap();
            let message = err_text(Table::read(&path, "clusters", &[("cluster", ColumnType::U32)]));
            assert_eq!(
                message,
                format!(
                    "{} holds a table of kind `embedding`, but a table of kind `clusters` is needed here",
                    path.display()
                )
            );
        }
    }

    #[test]
    fn a_file_that_does_not_declare_its_kind_is_refused_with_how_to_declare_it() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("plain.csv");
        fs::write(&csv, "take,start\nwalk,3\n").unwrap();
        let message = err_text(Table::read(&csv, "segments", &[("take", ColumnType::Str)]));
        assert_eq!(
            message,
            format!(
                "{}: does not say what kind of table it is; a `segments` table declares itself with the first line \
                 `# imitate segments table`",
                csv.display()
            )
        );

        let parquet = dir.path().join("plain.parquet");
        let df = DataFrame::new_infer_height(vec![Column::new("take".into(), ["walk"])]).unwrap();
        write_foreign_parquet(&parquet, df, None);
        let message = err_text(Table::read(&parquet, "segments", &[("take", ColumnType::Str)]));
        assert!(message.contains("Parquet key-value metadata `imitate.table = segments`"), "{message}");
    }

    #[test]
    fn a_foreign_file_with_the_declaration_and_columns_is_read() {
        let dir = tempfile::tempdir().unwrap();
        // pandas-style CSV: int64-looking numbers, unquoted empty text, an
        // extra column, Windows line ends, a byte-order mark.
        let csv = dir.path().join("mine.csv");
        fs::write(&csv, "\u{feff}# imitate segments table\r\nextra,take,start\r\nz,,3\r\ny,run, 4 \r\n").unwrap();
        let t = Table::read(&csv, "segments", &[("take", ColumnType::Str), ("start", ColumnType::U32)]).unwrap();
        assert_eq!(t.str("take"), ["", "run"]);
        assert_eq!(t.u32("start"), [3, 4]);
        assert_eq!(t.names().collect::<Vec<_>>(), ["take", "start"]);

        // Parquet with int64 counts (pandas' default) and float32 values.
        let parquet = dir.path().join("mine.parquet");
        let df = DataFrame::new_infer_height(vec![
            Column::new("start".into(), [0_i64, 4_294_967_295]),
            Column::new("offset".into(), [-5_i64, 5]),
            Column::new("cost".into(), [0.5_f32, -2.25]),
        ])
        .unwrap();
        write_foreign_parquet(&parquet, df, Some("segments"));
        let schema = [("start", ColumnType::U32), ("offset", ColumnType::I32), ("cost", ColumnType::F64)];
        let t = Table::read(&parquet, "segments", &schema).unwrap();
        assert_eq!(t.u32("start"), [0, u32::MAX]);
        assert_eq!(t.i32("offset"), [-5, 5]);
        assert_eq!(t.f64("cost"), [0.5, -2.25]);
    }

    #[test]
    fn a_missing_column_is_named_with_the_columns_present() {
        let dir = tempfile::tempdir().unwrap();
        for ext in ["csv", "parquet"] {
            let path = dir.path().join(format!("segments.{ext}"));
            let mut table = Table::new("segments");
            table.push("take", Values::Str(vec!["walk".into()])).push("start", Values::U32(vec![3]));
            table.write(&path).unwrap();
            let message =
                err_text(Table::read(&path, "segments", &[("take", ColumnType::Str), ("end", ColumnType::U32)]));
            assert_eq!(
                message,
                format!(
                    "{}: the `segments` table has no column `end`; its columns are: `take`, `start`",
                    path.display()
                )
            );
        }
    }

    #[test]
    fn a_column_of_the_wrong_type_is_refused_naming_column_expected_and_found() {
        let dir = tempfile::tempdir().unwrap();
        let parquet = dir.path().join("t.parquet");
        let mut table = Table::new("segments");
        table.push("start", Values::F64(vec![1.5])).push("take", Values::U32(vec![1]));
        table.write(&parquet).unwrap();
        let message = err_text(Table::read(&parquet, "segments", &[("start", ColumnType::U32)]));
        assert_eq!(
            message,
            format!("{}: column `start` should hold u32 values but holds f64 values", parquet.display())
        );
        let message = err_text(Table::read(&parquet, "segments", &[("take", ColumnType::Str)]));
        assert_eq!(
            message,
            format!("{}: column `take` should hold text values but holds u32 values", parquet.display())
        );

        let csv = dir.path().join("t.csv");
        fs::write(&csv, "# imitate segments table\nstart,cost\n3,0.5\nthree,x\n").unwrap();
        let message = err_text(Table::read(&csv, "segments", &[("start", ColumnType::U32)]));
        assert_eq!(
            message,
            format!("{}: column `start` should hold u32 values but holds `three` in row 2", csv.display())
        );
        let message = err_text(Table::read(&csv, "segments", &[("cost", ColumnType::F64)]));
        assert_eq!(message, format!("{}: column `cost` should hold f64 values but holds `x` in row 2", csv.display()));
    }

    #[test]
    fn integers_that_do_not_fit_are_refused_naming_value_and_row() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("t.csv");
        fs::write(&csv, "# imitate segments table\nstart,offset\n1,1\n-1,2147483648\n").unwrap();
        let message = err_text(Table::read(&csv, "segments", &[("start", ColumnType::U32)]));
        assert_eq!(
            message,
            format!("{}: column `start` holds -1 in row 2, outside the u32 range 0 to 4294967295", csv.display())
        );
        let message = err_text(Table::read(&csv, "segments", &[("offset", ColumnType::I32)]));
        assert!(message.contains("`offset` holds 2147483648 in row 2, outside the i32 range"), "{message}");

        let parquet = dir.path().join("t.parquet");
        let df = DataFrame::new_infer_height(vec![Column::new("start".into(), [5_i64, 4_294_967_296])]).unwrap();
        write_foreign_parquet(&parquet, df, Some("segments"));
        let message = err_text(Table::read(&parquet, "segments", &[("start", ColumnType::U32)]));
        assert!(message.contains("`start` holds 4294967296 in row 2, outside the u32 range"), "{message}");
    }

    #[test]
    fn nan_or_infinity_is_refused_naming_column_and_row() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("t.csv");
        fs::write(&csv, "# imitate embedding table\ndim_0,dim_1\n1.0,2.0\n3.0,NaN\n").unwrap();
        let message = err_text(Table::read(&csv, "embedding", &[("dim_*", ColumnType::F64)]));
        assert_eq!(
            message,
            format!("{}: column `dim_1` holds NaN in row 2; tables hold finite numbers only", csv.display())
        );
        fs::write(&csv, "# imitate embedding table\ndim_0\n-inf\n").unwrap();
        let message = err_text(Table::read(&csv, "embedding", &[("dim_*", ColumnType::F64)]));
        assert!(message.contains("`dim_0` holds -inf in row 1"), "{message}");

        let parquet = dir.path().join("t.parquet");
        let df = DataFrame::new_infer_height(vec![Column::new("x".into(), [0.0, 1.0, f64::INFINITY])]).unwrap();
        write_foreign_parquet(&parquet, df, Some("embedding"));
        let message = err_text(Table::read(&parquet, "embedding", &[("x", ColumnType::F64)]));
        assert!(message.contains("`x` holds inf in row 3"), "{message}");

        // Writing refuses NaN too, and writes nothing.
        let mut table = Table::new("embedding");
        table.push("x", Values::F64(vec![1.0, f64::NAN]));
        let out = dir.path().join("nan.parquet");
        let message = table.write(&out).unwrap_err().to_string();
        assert_eq!(
            message,
            format!("{}: column `x` holds NaN in row 2; tables hold finite numbers only", out.display())
        );
        assert!(!out.exists());
    }

    #[test]
    fn a_missing_value_in_a_required_column_is_refused_with_its_row() {
        let dir = tempfile::tempdir().unwrap();
        let parquet = dir.path().join("t.parquet");
        let mut table = Table::new("segments");
        table.push("label", Values::OptStr(vec![Some("a".into()), None]));
        table.write(&parquet).unwrap();
        let message = err_text(Table::read(&parquet, "segments", &[("label", ColumnType::Str)]));
        assert_eq!(message, format!("{}: column `label` has no value in row 2", parquet.display()));

        let csv = dir.path().join("t.csv");
        fs::write(&csv, "# imitate segments table\ntake,start\nwalk,\n").unwrap();
        let message = err_text(Table::read(&csv, "segments", &[("start", ColumnType::U32)]));
        assert_eq!(message, format!("{}: column `start` has no value in row 1", csv.display()));
    }

    #[test]
    fn numbered_columns_are_read_as_a_family_in_numeric_order() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("e.parquet");
        let mut table = Table::new("embedding");
        table.push("segment", Values::U32(vec![0, 1]));
        for i in [3, 0, 10, 1, 2, 4, 5, 6, 7, 8, 9, 11] {
            table.push(&format!("dim_{i}"), Values::F64(vec![i as f64, -(i as f64)]));
        }
        table.push("dim_x", Values::F64(vec![0.0, 0.0])).push("dim_01", Values::F64(vec![0.0, 0.0]));
        let dims = table.f64_columns_with_prefix("dim_");
        let names: Vec<&str> = dims.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, (0..12).map(|i| format!("dim_{i}")).collect::<Vec<_>>());
        assert_eq!(dims[10].1, [10.0, -10.0]);
        table.write(&path).unwrap();
        let back =
            Table::read(&path, "embedding", &[("segment", ColumnType::U32), ("dim_*", ColumnType::F64)]).unwrap();
        let back_names: Vec<&str> = back.names().collect();
        assert_eq!(back_names.len(), 13);
        assert_eq!(back_names[0], "segment");
        assert_eq!(back.f64_columns_with_prefix("dim_"), dims);

        let mut gap = Table::new("embedding");
        gap.push("dim_0", Values::F64(vec![1.0])).push("dim_2", Values::F64(vec![1.0]));
        gap.write(&path).unwrap();
        let message = err_text(Table::read(&path, "embedding", &[("dim_*", ColumnType::F64)]));
        assert!(message.contains("no column `dim_1`; its columns are: `dim_0`, `dim_2`"), "{message}");
        let message = err_text(Table::read(&path, "embedding", &[("pc_*", ColumnType::F64)]));
        assert!(message.contains("no column `pc_0`"), "{message}");
    }

    #[test]
    fn truncated_or_garbage_parquet_is_refused_without_panicking() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("good.parquet");
        tricky().write(&good).unwrap();
        let bytes = fs::read(&good).unwrap();
        let bad = dir.path().join("bad.parquet");
        let mut cases: Vec<Vec<u8>> = vec![Vec::new(), b"PAR1".to_vec(), b"not a parquet file at all\n".repeat(40)];
        cases.extend((1..16).map(|k| bytes[..bytes.len() * k / 16].to_vec()));
        cases.push(bytes[..bytes.len() - 1].to_vec());
        for case in cases {
            fs::write(&bad, &case).unwrap();
            match Table::read(&bad, "segments", SEGMENTS) {
                Err(TableError::Unreadable { path, format: "Parquet", .. }) => {
                    assert_eq!(path, bad.display().to_string())
                }
                other => panic!("{} bytes: expected an unreadable-file error, got {other:?}", case.len()),
            }
        }
        // Damage inside the data may or may not be detected, but never panics.
        for at in (4..bytes.len().saturating_sub(8)).step_by(97) {
            let mut damaged = bytes.clone();
            damaged[at] ^= 0xA5;
            fs::write(&bad, &damaged).unwrap();
            let _ = Table::read(&bad, "segments", SEGMENTS);
        }
    }

    #[test]
    fn malformed_csv_is_refused_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("t.csv");
        let cases: [&[u8]; 3] = [
            b"# imitate segments table\n",
            b"# imitate segments table\ntake\n\"unclosed\n",
            b"# imitate segments table\ntake\n\xff\xfe\n",
        ];
        for text in cases {
            fs::write(&csv, text).unwrap();
            let message = err_text(Table::read(&csv, "segments", &[("take", ColumnType::Str)]));
            assert!(message.starts_with(&format!("{}: not a readable CSV file: ", csv.display())), "{message}");
        }
    }

    #[test]
    fn an_unsupported_extension_is_refused_on_write_and_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("segments.tsv");
        let expected =
            format!("{}: a table file must end in `.csv` (small tables) or `.parquet` (large ones)", path.display());
        assert_eq!(tricky().write(&path).unwrap_err().to_string(), expected);
        fs::write(&path, "x").unwrap();
        assert_eq!(err_text(Table::read(&path, "segments", SEGMENTS)), expected);
    }

    #[test]
    fn a_missing_file_is_an_io_error_naming_it() {
        let path = Path::new("/nonexistent/segments.csv");
        let message = err_text(Table::read(path, "segments", SEGMENTS));
        assert!(message.starts_with("/nonexistent/segments.csv: cannot read: "), "{message}");
    }

    #[test]
    fn a_failed_write_leaves_no_file_behind() {
        let dir = tempfile::tempdir().unwrap();
        // The rename onto a directory fails after the whole file was written.
        for ext in ["csv", "parquet"] {
            let target = dir.path().join(format!("busy.{ext}"));
            fs::create_dir(&target).unwrap();
            fs::write(target.join("inside"), "x").unwrap();
            let message = tricky().write(&target).unwrap_err().to_string();
            assert!(message.starts_with(&format!("{}: cannot write: ", target.display())), "{message}");
            assert_eq!(files_in(dir.path()), std::slice::from_ref(&target));
            fs::remove_dir_all(&target).unwrap();
        }
        // A refused table leaves the previous file as it was.
        let target = dir.path().join("kept.csv");
        tricky().write(&target).unwrap();
        let before = fs::read(&target).unwrap();
        let mut nan = Table::new("segments");
        nan.push("cost", Values::F64(vec![f64::NAN]));
        assert!(nan.write(&target).is_err());
        assert_eq!(fs::read(&target).unwrap(), before);
        assert_eq!(files_in(dir.path()), [target]);
    }

    #[test]
    fn a_lone_optional_text_column_keeps_its_absent_rows_in_csv() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("labels.csv");
        let mut table = Table::new("labels");
        table.push("label", Values::OptStr(vec![None, Some("a".into()), None, None, Some(String::new()), None]));
        table.write(&path).unwrap();
        assert_same(&Table::read(&path, "labels", &[("label", ColumnType::OptStr)]).unwrap(), &table);
    }

    #[test]
    fn an_empty_table_round_trips_and_reports_zero_rows() {
        let dir = tempfile::tempdir().unwrap();
        let mut table = Table::new("segments");
        table
            .push("take", Values::Str(vec![]))
            .push("label", Values::OptStr(vec![]))
            .push("start", Values::U32(vec![]))
            .push("offset", Values::I32(vec![]))
            .push("cost", Values::F64(vec![]));
        for ext in ["csv", "parquet"] {
            let path = dir.path().join(format!("empty.{ext}"));
            table.write(&path).unwrap();
            let back = Table::read(&path, "segments", SEGMENTS).unwrap();
            assert_eq!(back.rows(), 0);
            assert_eq!(back, table);
        }
    }

    #[test]
    #[should_panic(expected = "column `b` of the `segments` table has 1 rows, but `a` has 2")]
    fn pushing_a_column_of_another_length_is_a_programming_error() {
        let mut table = Table::new("segments");
        table.push("a", Values::U32(vec![1, 2])).push("b", Values::U32(vec![1]));
    }
}
