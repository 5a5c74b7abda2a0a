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
        let message = err_text(Table::read(&path, "segments", &[("take", ColumnType::Str), ("end", ColumnType::U32)]));
        assert_eq!(
            message,
            format!("{}: the `segments` table has no column `end`; its columns are: `take`, `start`", path.display())
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
    assert_eq!(message, format!("{}: column `start` should hold u32 values but holds f64 values", parquet.display()));
    let message = err_text(Table::read(&parquet, "segments", &[("take", ColumnType::Str)]));
    assert_eq!(message, format!("{}: column `take` should hold text values but holds u32 values", parquet.display()));

    let csv = dir.path().join("t.csv");
    fs::write(&csv, "# imitate segments table\nstart,cost\n3,0.5\nthree,x\n").unwrap();
    let message = err_text(Table::read(&csv, "segments", &[("start", ColumnType::U32)]));
    assert_eq!(message, format!("{}: column `start` should hold u32 values but holds `three` in row 2", csv.display()));
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
    assert_eq!(message, format!("{}: column `x` holds NaN in row 2; tables hold finite numbers only", out.display()));
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
    let back = Table::read(&path, "embedding", &[("segment", ColumnType::U32), ("dim_*", ColumnType::F64)]).unwrap();
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
