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
mod tests;
