//! The learning subcommands (`segment`, `embed`, `cluster`, `fit`,
//! `export`, `vocab build`, `vocab info`) as users run them: the stages
//! chain into the same vocabulary `vocab build` writes, outputs do not
//! depend on the number of threads, the shipped vocabulary is reproduced by
//! the README's command, and bad input is refused with one clear message,
//! exit code 1 and nothing written.

use crate::common;

use common::{imitate, real_mocap_dir};
use imitate::vocab::container::Container;
use imitate::vocab::vocabulary::Vocabulary;
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn mocap() -> PathBuf {
    root().join("mocap")
}

fn labels() -> PathBuf {
    root().join("mocap/labels.csv")
}

fn stderr_of(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs `imitate` with `args` (paths as given) and expects success.
fn ok(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Output {
    let out = imitate().args(args.iter().map(|a| a.as_ref())).arg("-q").output().unwrap();
    assert!(
        out.status.success(),
        "imitate {:?}: {}",
        args.iter().map(|a| a.as_ref()).collect::<Vec<_>>(),
        stderr_of(&out)
    );
    out
}

/// Every path under `dir`, relative to it.
fn listing(dir: &Path) -> BTreeSet<PathBuf> {
    let mut found = BTreeSet::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path.clone());
            }
            found.insert(path.strip_prefix(dir).unwrap().to_path_buf());
        }
    }
    found
}

/// Runs `imitate` in `dir` and checks it refused: exit code 1, one line on
/// stderr that names `file` and holds `problem`, no panic, and `dir` left
/// exactly as it was (no output, no temporary file).
fn refused(dir: &Path, args: &[&str], file: &str, problem: &str) {
    let before = listing(dir);
    let out = imitate().current_dir(dir).args(args).output().unwrap();
    let err = stderr_of(&out);
    assert_eq!(out.status.code(), Some(1), "imitate {args:?}: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("imitate: error:")).collect();
    assert_eq!(lines.len(), 1, "imitate {args:?}: one error line expected: {err}");
    assert!(lines[0].contains(file), "imitate {args:?}: the error does not name {file}: {err}");
    assert!(lines[0].contains(problem), "imitate {args:?}: the error does not say `{problem}`: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(listing(dir), before, "imitate {args:?} left files behind");
}

/// `frames` (a range of frame lines) of `source`, as a BVH file at `path`.
fn excerpt(source: &Path, frames: std::ops::Range<usize>, path: &Path, repeat_first: bool) {
    let text = fs::read_to_string(source).unwrap();
    let motion = text.find("MOTION").unwrap();
    let lines: Vec<&str> = text[motion..].lines().collect();
    let frame_time = lines[2];
    let chosen: Vec<&str> = if repeat_first {
        vec![lines[3 + frames.start]; frames.len()]
    } else {
        lines[3 + frames.start..3 + frames.end].to_vec()
    };
    let body = format!("{}MOTION\nFrames: {}\n{frame_time}\n{}\n", &text[..motion], chosen.len(), chosen.join("\n"));
    fs::write(path, body).unwrap();
}

#[test]
fn the_stages_run_one_by_one_write_the_vocabulary_vocab_build_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let t = |name: &str| tmp.path().join(name);
    // A take too short to give a segment is skipped, said so, and still
    // recorded as learned from.
    excerpt(&mocap().join("wave-h.bvh"), 100..104, &t("brief.bvh"), false);
    let built = imitate()
        .args(["vocab", "build"])
        .args([mocap(), t("brief.bvh")])
        .arg("--labels")
        .arg(labels())
        .arg("-o")
        .arg(t("built.vocab"))
        .output()
        .unwrap();
    let said = stderr_of(&built);
    assert!(built.status.success(), "{said}");
    assert!(said.contains("brief.bvh: warning: skipped: no segment of at least 0.2 s in its 0.13 s"), "{said}");
    // Parquet and CSV in turn: the format of a stage file changes nothing.
    ok(&[&"segment", &mocap(), &t("brief.bvh"), &"--labels", &labels(), &"-o", &t("segments.parquet")]);
    ok(&[&"embed", &t("segments.parquet"), &"-o", &t("embedding.csv"), &"--vectors", &t("vectors.csv")]);
    ok(&[&"cluster", &t("embedding.csv"), &"-o", &t("clusters.parquet")]);
    // The vectors the segments were compared as: one row a segment, with
    // its label, 20 poses of every joint-space number.
    let vectors = fs::read_to_string(t("vectors.csv")).unwrap();
    let rows: Vec<&str> = vectors.lines().collect();
    let header: Vec<&str> = rows[0].split(',').collect();
    assert_eq!(header[..3], ["segment", "label", "v0"]);
    assert_eq!(header.len(), 2 + 20 * imitate::mocap::body::DOF);
    let embedded = fs::read_to_string(t("embedding.csv")).unwrap();
    assert_eq!(rows.len() - 1, embedded.lines().filter(|l| !l.starts_with('#')).count() - 1);
    assert!(rows[1..].iter().all(|r| r.split(',').count() == header.len()));
    assert!(rows.iter().any(|r| r.split(',').nth(1) == Some("circles")));
    ok(&[&"fit", &t("clusters.parquet"), &"-o", &t("primitives")]);
    ok(&[&"export", &t("primitives"), &"-o", &t("staged.vocab")]);
    let (built, staged) = (fs::read(t("built.vocab")).unwrap(), fs::read(t("staged.vocab")).unwrap());
    assert!(built == staged, "the stages give a vocabulary other than vocab build's");
    // The primitives folder holds the index and two tables per primitive.
    let vocabulary = Vocabulary::load(&t("built.vocab")).unwrap();
    assert_eq!(vocabulary.build_info().takes.len(), 7);
    let n = vocabulary.primitives().len();
    assert!(n >= 6, "{n} primitives from the six shipped activities");
    assert_eq!(fs::read_dir(t("primitives")).unwrap().count(), 1 + 2 * n);
}

#[test]
fn a_vocabulary_has_the_same_bytes_on_one_and_on_four_threads() {
    let tmp = tempfile::tempdir().unwrap();
    let mut made = Vec::new();
    for threads in ["1", "4"] {
        let path = tmp.path().join(format!("t{threads}.vocab"));
        // The subspace eigen solver, which works in parallel blocks.
        let out = imitate()
            .env("RAYON_NUM_THREADS", threads)
            .args(["vocab", "build", "-q", "--eigen", "subspace", "--seed", "7", "-o"])
            .arg(&path)
            .arg(mocap())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr_of(&out));
        made.push(fs::read(&path).unwrap());
    }
    assert!(made[0] == made[1], "the thread count changed the vocabulary");
}

#[test]
fn the_readme_command_rebuilds_the_shipped_vocabulary_byte_for_byte() {
    let readme = fs::read_to_string(root().join("README.md")).unwrap();
    let line = readme
        .lines()
        .find(|l| l.starts_with("cargo run --release -- vocab build") && l.contains("vocab/default.vocab"))
        .expect("the README gives the command that makes vocab/default.vocab");
    let tmp = tempfile::tempdir().unwrap();
    let made = tmp.path().join("default.vocab");
    let args: Vec<String> = line
        .trim_start_matches("cargo run --release -- ")
        .split_whitespace()
        .map(|a| if a == "vocab/default.vocab" { made.to_str().unwrap().to_string() } else { a.to_string() })
        .collect();
    // Run where the README says to: the repository's root, since the
    // vocabulary records its sources as given.
    let out = imitate().current_dir(root()).args(&args).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let same = fs::read(&made).unwrap() == fs::read(root().join("vocab/default.vocab")).unwrap();
    assert!(same, "vocab/default.vocab differs from what the README's command makes");
}

#[test]
fn vocab_info_lists_primitives_dimensions_variance_frames_and_sources() {
    let path = root().join("vocab/default.vocab");
    let vocabulary = Vocabulary::load(&path).unwrap();
    let text = String::from_utf8(ok(&[&"vocab", &"info", &path]).stdout).unwrap();
    assert!(text.contains("imitate vocabulary, format 2"), "{text}");
    for p in vocabulary.primitives() {
        let row = text.lines().find(|l| l.split_whitespace().next() == Some(p.name())).unwrap_or_else(|| {
            panic!("no row for {} in:\n{text}", p.name());
        });
        let cells: Vec<&str> = row.split_whitespace().collect();
        assert_eq!(cells[1], p.dims().to_string(), "{row}");
        assert_eq!(cells[2], format!("{:.1}%", 100.0 * p.variance_kept()), "{row}");
        assert_eq!(cells[3], p.training_frames().to_string(), "{row}");
        let sources = text.lines().find(|l| l.starts_with(&format!("{}: ", p.name()))).unwrap();
        assert!(sources.contains("mocap/"), "{sources}");
    }

    let json = ok(&[&"vocab", &"info", &"--json", &path]).stdout;
    let value: serde_json::Value = serde_json::from_slice(&json).unwrap();
    assert_eq!(value["format_version"], 2);
    assert_eq!(value["checksum"], format!("{:#010x}", vocabulary.checksum().unwrap()));
    let listed = value["primitives"].as_array().unwrap();
    assert_eq!(listed.len(), vocabulary.primitives().len());
    for (entry, p) in listed.iter().zip(vocabulary.primitives()) {
        assert_eq!(entry["name"], p.name());
        assert_eq!(entry["dims"], p.dims());
    }
    assert_eq!(value["build"]["frames"], 2997, "{}", value["build"]);
}

#[test]
fn inputs_without_motion_to_learn_from_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fs::create_dir(dir.join("empty")).unwrap();
    refused(dir, &["vocab", "build", "empty", "-o", "v.vocab"], "empty", "no .bvh files");
    refused(dir, &["segment", "empty", "-o", "s.csv"], "empty", "no .bvh files");
    let circles = mocap().join("circles.bvh");
    excerpt(&circles, 200..204, &dir.join("short.bvh"), false);
    refused(dir, &["segment", "short.bvh", "-o", "s.csv"], "short.bvh", "shorter than the minimum segment length");
    excerpt(&circles, 200..500, &dir.join("still.bvh"), true);
    refused(dir, &["vocab", "build", "still.bvh", "-o", "v.vocab"], "still.bvh", "every frame is the same pose");
    // Also among takes that move: the file is wrong, not short.
    refused(
        dir,
        &["vocab", "build", &mocap().to_string_lossy(), "still.bvh", "-o", "v.vocab"],
        "still.bvh",
        "every frame is the same pose",
    );
    // Real motion, but too little of it for an embedding.
    excerpt(&circles, 100..260, &dir.join("brief.bvh"), false);
    refused(dir, &["vocab", "build", "brief.bvh", "-o", "v.vocab"], "brief.bvh", "segments");
    refused(dir, &["vocab", "build", &mocap().to_string_lossy(), "--k", "500", "-o", "v.vocab"], "mocap", "--k 500");
    // A labels file naming a take that is neither given nor beside it.
    fs::write(dir.join("labels.csv"), "file,activity\ncircles.bvh,circles\ncircels.bvh,circles\n").unwrap();
    let (circles, labels) = (circles.to_string_lossy(), "labels.csv");
    for command in [&["vocab", "build"][..], &["segment"]] {
        let args = [command, &[&circles, "--labels", labels, "-o", "out"]].concat();
        refused(dir, &args, "labels.csv", "names 1 file neither among the inputs nor beside them: circels.bvh");
    }
}

#[test]
fn a_stage_file_fed_to_the_wrong_stage_or_holding_nan_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let m = mocap();
    let mocap = m.to_str().unwrap();
    let run = |args: &[&str]| {
        let out = imitate().current_dir(dir).args(args).arg("-q").output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
    };
    run(&["segment", mocap, "-o", "segments.csv"]);
    run(&["embed", "segments.csv", "-o", "embedding.csv"]);
    run(&["cluster", "embedding.csv", "-o", "clusters.csv"]);
    run(&["fit", "clusters.csv", "-o", "primitives"]);
    run(&["export", "primitives", "-o", "made.vocab"]);

    let kind = |k: &str| format!("holds a table of kind `{k}`");
    refused(dir, &["embed", "embedding.csv", "-o", "e.csv"], "embedding.csv", &kind("embedding"));
    refused(dir, &["cluster", "segments.csv", "-o", "c.csv"], "segments.csv", &kind("segments"));
    refused(dir, &["cluster", "clusters.csv", "-o", "c.csv"], "clusters.csv", &kind("clusters"));
    refused(dir, &["fit", "embedding.csv", "-o", "p"], "embedding.csv", &kind("embedding"));
    refused(dir, &["fit", "made.vocab", "-o", "p"], "made.vocab", "must end in `.csv`");
    refused(dir, &["export", "clusters.csv", "-o", "v.vocab"], "clusters.csv", "not a primitives folder");
    refused(dir, &["vocab", "info", "clusters.csv"], "clusters.csv", "not a vocabulary file");
    refused(dir, &["vocab", "info", "primitives/index.json"], "primitives/index.json", "not a vocabulary file");

    // A NaN where a number belongs.
    let table = fs::read_to_string(dir.join("embedding.csv")).unwrap();
    let header = table.lines().find(|l| l.starts_with("file,")).unwrap();
    let column = header.split(',').position(|c| c == "dim_0").unwrap();
    let mut lines: Vec<String> = table.lines().map(str::to_string).collect();
    let first_row = lines.iter().position(|l| l.starts_with("file,")).unwrap() + 1;
    let mut cells: Vec<&str> = lines[first_row].split(',').collect();
    cells[column] = "NaN";
    lines[first_row] = cells.join(",");
    fs::write(dir.join("nan.csv"), lines.join("\n") + "\n").unwrap();
    refused(dir, &["cluster", "nan.csv", "-o", "c.csv"], "nan.csv", "column `dim_0` holds NaN in row 1");
}

/// Reads `source`, lets `edit` change its header, and writes it (with a
/// fresh checksum) to `path`.
fn edited(source: &Path, path: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let mut container = Container::read(source).unwrap();
    edit(&mut container.header);
    container.write(path).unwrap();
}

#[test]
fn damaged_newer_and_other_body_vocabularies_are_refused_saying_which() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let shipped = root().join("vocab/default.vocab");
    let bytes = fs::read(&shipped).unwrap();

    fs::write(dir.join("truncated.vocab"), &bytes[..bytes.len() / 2]).unwrap();
    refused(dir, &["vocab", "info", "truncated.vocab"], "truncated.vocab", "truncated");
    let mut flipped = bytes.clone();
    flipped[bytes.len() - 100] ^= 0x10;
    fs::write(dir.join("corrupt.vocab"), &flipped).unwrap();
    refused(dir, &["vocab", "info", "corrupt.vocab"], "corrupt.vocab", "corrupt");
    let mut newer = bytes.clone();
    newer[14] = 9;
    fs::write(dir.join("newer.vocab"), &newer).unwrap();
    refused(dir, &["vocab", "info", "newer.vocab"], "newer.vocab", "newer");

    edited(&shipped, &dir.join("renamed.vocab"), |h| h["body"]["joints"][3]["name"] = "tail".into());
    refused(dir, &["vocab", "info", "renamed.vocab"], "renamed.vocab", "different canonical body");
    edited(&shipped, &dir.join("taller.vocab"), |h| {
        let height = h["body"]["proportions"]["height_m"].as_f64().unwrap();
        h["body"]["proportions"]["height_m"] = (height + 0.2).into();
    });
    refused(dir, &["vocab", "info", "taller.vocab"], "taller.vocab", "different canonical body");
}

#[test]
fn impossible_options_are_usage_errors_with_exit_code_2() {
    let tmp = tempfile::tempdir().unwrap();
    let m = mocap();
    let mocap = m.to_str().unwrap();
    let cases: [(&[&str], &str); 7] = [
        (&["--k", "0"], "--k"),
        (&["--by-label", "--k", "3"], "by label"),
        (&["--variance", "1.5"], "variance"),
        (&["--min-dims", "6", "--max-dims", "3"], "dims"),
        (&["--method", "guess"], "guess"),
        (&["--neighbors", "0"], "neighbo"),
        (&["--min-length", "2", "--max-length", "1"], "length"),
    ];
    for (extra, says) in cases {
        let out = imitate()
            .current_dir(tmp.path())
            .args(["vocab", "build", mocap, "-o", "v.vocab"])
            .args(extra)
            .output()
            .unwrap();
        let err = stderr_of(&out);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(says), "{extra:?}: {err}");
        assert!(!tmp.path().join("v.vocab").exists());
    }
}

#[test]
fn real_captures_segment_and_build_from_the_command_line() {
    let Some(real) = real_mocap_dir() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let segments = tmp.path().join("segments.csv");
    ok(&[&"segment", &real, &"--labels", &real.join("labels.csv"), &"-o", &segments]);
    let table = fs::read_to_string(&segments).unwrap();
    let header: Vec<&str> = table.lines().find(|l| l.starts_with("file,")).unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let rows: Vec<Vec<&str>> =
        table.lines().skip_while(|l| !l.starts_with("file,")).skip(1).map(|l| l.split(',').collect()).collect();
    assert!(rows.len() >= 150, "{} segments", rows.len());
    let files: BTreeSet<&str> = rows.iter().map(|r| r[col("file")]).collect();
    assert_eq!(files.len(), 23, "every real take gives segments");
    for r in &rows {
        let (first, last): (usize, usize) =
            (r[col("first_frame")].parse().unwrap(), r[col("last_frame")].parse().unwrap());
        let take: usize = r[col("take_frames")].parse().unwrap();
        assert!(first < last && last < take, "{r:?}");
        assert_eq!(r[col("frames")].parse::<usize>().unwrap(), last - first + 1);
        assert!(!r[col("label")].is_empty(), "labels.csv labels every real take: {r:?}");
    }

    let built = tmp.path().join("real.vocab");
    ok(&[&"vocab", &"build", &real, &"--labels", &real.join("labels.csv"), &"-o", &built]);
    let vocabulary = Vocabulary::load(&built).unwrap();
    assert!(vocabulary.primitives().len() >= 8, "{} primitives", vocabulary.primitives().len());
    assert_eq!(vocabulary.build_info().takes.len(), 23);
}

#[test]
fn by_label_every_activity_of_the_real_captures_gets_a_primitive_of_its_own() {
    let Some(real) = real_mocap_dir() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let labels_path = real.join("labels.csv");
    let built = tmp.path().join("real.vocab");
    ok(&[&"vocab", &"build", &real, &"--labels", &labels_path, &"--by-label", &"-o", &built]);
    let labels: BTreeSet<String> = fs::read_to_string(&labels_path)
        .unwrap()
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(1).map(|a| a.trim().to_string()))
        .collect();
    let vocabulary = Vocabulary::load(&built).unwrap();
    let named: BTreeSet<String> =
        vocabulary.primitives().iter().map(|p| p.majority_label().unwrap().to_string()).collect();
    assert_eq!(named, labels, "one activity per primitive, every activity named");
    // Unlabelled, there is nothing to cluster by.
    let out = imitate()
        .current_dir(tmp.path())
        .args(["vocab", "build"])
        .arg(&real)
        .args(["--by-label", "-o", "x.vocab"])
        .output()
        .unwrap();
    assert_ne!(out.status.code(), Some(0));
    assert!(stderr_of(&out).contains("clustering by label needs labelled segments"), "{}", stderr_of(&out));
    assert!(!tmp.path().join("x.vocab").exists());
}
