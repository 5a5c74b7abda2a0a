//! `imitate score`: runs built from a render's own truth score exactly what
//! was done to them (perfect, joints shifted, wrong or missing activities,
//! late switches), the same bytes every time, and bad input is refused
//! naming the file with nothing written.

use crate::common;

use common::{imitate, real_mocap_dir};
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

fn mocap(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap").join(name)
}

fn stderr_of(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A CSV file split at commas: the tables here hold no quoted fields.
#[derive(Clone)]
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    fn read(path: &Path) -> Table {
        let text = fs::read_to_string(path).unwrap();
        let mut lines = text.lines().map(|l| l.split(',').map(String::from).collect::<Vec<_>>());
        Table { header: lines.next().unwrap(), rows: lines.collect() }
    }

    fn write(&self, path: &Path) {
        let lines: Vec<String> = std::iter::once(&self.header).chain(&self.rows).map(|r| r.join(",")).collect();
        fs::write(path, lines.join("\n") + "\n").unwrap();
    }

    fn col(&self, name: &str) -> usize {
        self.header.iter().position(|c| c == name).unwrap_or_else(|| panic!("no column {name}"))
    }

    /// Sets the column `name` of rows `rows` to `value`.
    fn set(&mut self, name: &str, rows: std::ops::Range<usize>, value: &str) {
        let c = self.col(name);
        for row in &mut self.rows[rows] {
            row[c] = value.to_string();
        }
    }
}

/// Renders `take` (clean, labelled by `labels`) into `dir/render`; its truth.
fn render(dir: &Path, take: &Path, labels: &Path) -> Table {
    let out = imitate()
        .current_dir(dir)
        .args(["render", take.to_str().unwrap(), "-o", "render", "--noise", "none", "-q", "--labels"])
        .arg(labels)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    Table::read(&dir.join("render/truth.csv"))
}

/// The `frames.csv` of a tracker that got `truth` exactly right: each
/// frame's activity is the primitive of the same name, probability 1.
fn perfect(truth: &Table, primitives: &[&str]) -> Table {
    let columns: Vec<String> = ["frame", "time_s", "activity"]
        .into_iter()
        .map(String::from)
        .chain(primitives.iter().map(|p| format!("prob_{p}")))
        .chain(primitives.iter().map(|p| format!("progress_{p}")))
        .chain(["root_x", "root_y", "root_z", "root_heading"].map(String::from))
        .chain(imitate::vision::truth::position_columns())
        .collect();
    let rows = truth
        .rows
        .iter()
        .map(|row| {
            columns
                .iter()
                .map(|c| match (c.strip_prefix("prob_"), c.strip_prefix("progress_")) {
                    (Some(p), _) => if row[truth.col("activity")] == p { "1" } else { "0" }.to_string(),
                    (_, Some(_)) => "0.5".to_string(),
                    _ => row[truth.col(c)].clone(),
                })
                .collect()
        })
        .collect();
    Table { header: columns, rows }
}

/// `dir/run` holding `frames` and a summary.json of `primitives` (name,
/// label) among the other fields `track` writes.
fn run_dir(dir: &Path, frames: &Table, primitives: &[(&str, Option<&str>)]) -> PathBuf {
    let run = dir.join("run");
    fs::create_dir_all(&run).unwrap();
    frames.write(&run.join("frames.csv"));
    let list: Vec<Value> =
        primitives.iter().map(|(n, l)| serde_json::json!({"name": n, "label": l, "dims": 3})).collect();
    let summary =
        serde_json::json!({"input": "render/frames", "primitives": list, "fps": 15.0, "frames": frames.rows.len()});
    fs::write(run.join("summary.json"), serde_json::to_string_pretty(&summary).unwrap()).unwrap();
    run
}

fn score(dir: &Path, extra: &[&str]) -> Output {
    imitate().current_dir(dir).args(["score", "run", "--truth", "render/truth.csv"]).args(extra).output().unwrap()
}

/// Scores `dir/run` against `dir/render/truth.csv`; metrics.json.
fn metrics(dir: &Path, extra: &[&str]) -> Value {
    let out = score(dir, extra);
    assert!(out.status.success(), "{}", stderr_of(&out));
    serde_json::from_str(&fs::read_to_string(dir.join("run/metrics.json")).unwrap()).unwrap()
}

fn close(value: &Value, expected: f64) -> bool {
    (value.as_f64().unwrap() - expected).abs() < 1e-6
}

const ERRORS: [&str; 10] = [
    "root_mm",
    "absolute_mm",
    "all_joints_mm",
    "upper_body_mm",
    "hand_mm",
    "limb_direction_deg",
    "/limbs_deg/upper_arm",
    "/limbs_deg/forearm",
    "/limbs_deg/thigh",
    "/limbs_deg/shin",
];

fn field<'a>(m: &'a Value, name: &str) -> &'a Value {
    if name.starts_with('/') { m.pointer(name).unwrap() } else { &m[name] }
}

#[test]
fn a_perfect_run_scores_no_error_and_full_accuracy_the_same_bytes_every_time() {
    let tmp = tempfile::tempdir().unwrap();
    let truth = render(tmp.path(), &mocap("wave-h.bvh"), &mocap("labels.csv"));
    let n = truth.rows.len();
    run_dir(tmp.path(), &perfect(&truth, &["wave-h"]), &[("wave-h", Some("wave-h"))]);
    let out = score(tmp.path(), &[]);
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains(&format!("{n} frames: upper body 0.0 mm")), "{}", stderr_of(&out));
    let written = fs::read(tmp.path().join("run/metrics.json")).unwrap();
    let m: Value = serde_json::from_slice(&written).unwrap();
    // The top-level keys in the order written (serde_json's Value sorts them).
    let text = String::from_utf8(written.clone()).unwrap();
    let keys: Vec<&str> =
        text.lines().filter_map(|l| l.strip_prefix("  \"")?.split_once('"').map(|(key, _)| key)).collect();
    assert_eq!(
        keys,
        [
            "frames",
            "root_mm",
            "absolute_mm",
            "all_joints_mm",
            "upper_body_mm",
            "hand_mm",
            "limb_direction_deg",
            "limbs_deg",
            "recognition_accuracy",
            "recognition_accuracy_settled",
            "settle_s",
            "frames_scored",
            "frames_settled",
            "frames_unlabelled",
            "frames_coasting",
            "switches",
            "switches_recognized",
            "switch_latency_s",
            "confusion"
        ]
    );
    assert_eq!(m["frames"], n);
    for name in ERRORS {
        assert_eq!(field(&m, name).as_f64(), Some(0.0), "{name}");
    }
    assert_eq!(
        (m["recognition_accuracy"].as_f64(), m["recognition_accuracy_settled"].as_f64()),
        (Some(1.0), Some(1.0))
    );
    assert_eq!((&m["frames_scored"], &m["frames_settled"], &m["frames_unlabelled"]), (&n.into(), &n.into(), &0.into()));
    assert_eq!((&m["switches"], &m["switch_latency_s"]), (&0.into(), &Value::Null));
    assert_eq!(m["confusion"], serde_json::json!({"wave-h": {"wave-h": n}}));
    // Again, elsewhere, quietly: the same bytes.
    let out = score(tmp.path(), &["-o", "again.json", "-q"]);
    assert!(out.status.success() && out.stderr.is_empty(), "{}", stderr_of(&out));
    assert_eq!(fs::read(tmp.path().join("again.json")).unwrap(), written);
}

#[test]
fn every_joint_but_the_pelvis_10_mm_off_is_10_mm_root_relative_with_no_limb_error() {
    let tmp = tempfile::tempdir().unwrap();
    let truth = render(tmp.path(), &mocap("wave-h.bvh"), &mocap("labels.csv"));
    let mut frames = perfect(&truth, &["wave-h"]);
    let joints: Vec<String> = imitate::vision::truth::position_columns().into_iter().step_by(3).skip(1).collect();
    for name in &joints {
        let c = frames.col(name);
        for row in &mut frames.rows {
            row[c] = (row[c].parse::<f64>().unwrap() + 0.01).to_string();
        }
    }
    run_dir(tmp.path(), &frames, &[("wave-h", Some("wave-h"))]);
    let m = metrics(tmp.path(), &[]);
    for name in ["all_joints_mm", "upper_body_mm", "hand_mm"] {
        assert!(close(&m[name], 10.0), "{name}: {}", m[name]);
    }
    // The pelvis is right: 16 of 17 joints 10 mm off.
    assert!(close(&m["absolute_mm"], 160.0 / 17.0), "{}", m["absolute_mm"]);
    assert_eq!(m["root_mm"].as_f64(), Some(0.0));
    for name in &ERRORS[5..] {
        assert!(close(field(&m, name), 0.0), "{name}: {}", field(&m, name));
    }
}

#[test]
fn wrong_unlabelled_and_coasting_frames_count_as_misses_and_show_in_the_confusion_table() {
    let tmp = tempfile::tempdir().unwrap();
    let truth = render(tmp.path(), &mocap("wave-h.bvh"), &mocap("labels.csv"));
    let n = truth.rows.len();
    let mut frames = perfect(&truth, &["wave-h", "wave-v", "p1"]);
    frames.set("activity", 10..12, "wave-v");
    frames.set("activity", 20..23, "p1");
    // Coasting: no activity, no probabilities.
    for name in ["activity", "prob_wave-h", "prob_wave-v", "prob_p1"] {
        frames.set(name, 30..34, "");
    }
    run_dir(tmp.path(), &frames, &[("wave-h", Some("wave-h")), ("wave-v", Some("wave-v")), ("p1", None)]);
    let m = metrics(tmp.path(), &[]);
    assert!(close(&m["recognition_accuracy"], (n - 9) as f64 / n as f64), "{}", m["recognition_accuracy"]);
    // No switch in the truth, so nothing is left out to settle.
    assert_eq!(m["recognition_accuracy_settled"], m["recognition_accuracy"]);
    assert_eq!((&m["frames_scored"], &m["frames_coasting"]), (&n.into(), &4.into()));
    assert_eq!(m["confusion"], serde_json::json!({"wave-h": {"wave-h": n - 9, "wave-v": 2, "p1": 3, "(none)": 4}}));
    assert_eq!(m["upper_body_mm"].as_f64(), Some(0.0));
}

#[test]
fn a_late_switch_costs_its_frames_and_latency_which_the_settle_window_forgives() {
    let tmp = tempfile::tempdir().unwrap();
    let mut truth = render(tmp.path(), &mocap("wave-h.bvh"), &mocap("labels.csv"));
    let n = truth.rows.len();
    // The truth: rest (which no primitive stands for), wave-h from frame 5,
    // wave-v from frame 60; the tracker names wave-h throughout the rest
    // and wave-v 3 frames (0.2 s at 15 Hz) late.
    truth.set("activity", 60..n, "wave-v");
    let mut frames = perfect(&truth, &["wave-h", "wave-v"]);
    truth.set("activity", 0..5, "rest");
    truth.write(&tmp.path().join("render/truth.csv"));
    frames.set("activity", 60..63, "wave-h");
    run_dir(tmp.path(), &frames, &[("wave-h", Some("wave-h")), ("wave-v", Some("wave-v"))]);
    let m = metrics(tmp.path(), &[]);
    assert_eq!((&m["switches"], &m["switches_recognized"]), (&2.into(), &2.into()));
    // 0 s into wave-h at frame 5, 0.2 s into wave-v.
    assert!(close(&m["switch_latency_s"], 0.1), "{}", m["switch_latency_s"]);
    assert_eq!((&m["frames_scored"], &m["frames_unlabelled"]), (&(n - 5).into(), &5.into()));
    assert!(close(&m["recognition_accuracy"], (n - 8) as f64 / (n - 5) as f64));
    // 0.5 s after each switch: frames 5–12 and 60–67 (7/15 s < 0.5 s ≤ 8/15 s).
    assert_eq!(m["frames_settled"], n - 5 - 16);
    assert_eq!((m["settle_s"].as_f64(), m["recognition_accuracy_settled"].as_f64()), (Some(0.5), Some(1.0)));
    assert_eq!(m["confusion"]["rest"], serde_json::json!({"wave-h": 5}));
    // A window of 0.1 s leaves out frames 5, 6, 60 and 61: one late frame stays.
    let m = metrics(tmp.path(), &["--settle", "0.1"]);
    assert_eq!(m["frames_settled"], n - 5 - 4);
    assert!(close(&m["recognition_accuracy_settled"], (n - 10) as f64 / (n - 9) as f64));
    // Recognized only after the next switch: not recognized at all.
    frames.set("activity", 60..n, "wave-h");
    run_dir(tmp.path(), &frames, &[("wave-h", Some("wave-h")), ("wave-v", Some("wave-v"))]);
    let m = metrics(tmp.path(), &[]);
    assert_eq!((&m["switches"], &m["switches_recognized"]), (&2.into(), &1.into()));
    assert_eq!(m["switch_latency_s"].as_f64(), Some(0.0));
}

#[test]
fn a_perfect_run_on_a_real_capture_scores_no_error_and_full_accuracy() {
    let Some(real) = real_mocap_dir() else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let truth = render(tmp.path(), &real.join("two_hand_wave.bvh"), &real.join("labels.csv"));
    assert!(truth.rows.iter().all(|r| r[truth.col("activity")] == "wave_both"));
    run_dir(tmp.path(), &perfect(&truth, &["wave_both", "p1"]), &[("wave_both", Some("wave_both")), ("p1", None)]);
    let m = metrics(tmp.path(), &[]);
    for name in ERRORS {
        assert_eq!(field(&m, name).as_f64(), Some(0.0), "{name}");
    }
    assert_eq!((m["frames"].as_u64(), m["recognition_accuracy"].as_f64()), (Some(truth.rows.len() as u64), Some(1.0)));
}

#[test]
fn help_names_the_inputs_the_output_and_the_settle_window() {
    let out = imitate().args(["score", "--help"]).output().unwrap();
    assert!(out.status.success());
    let help = String::from_utf8(out.stdout).unwrap();
    let words = [
        "RUN_DIR",
        "--truth <truth.csv>",
        "--keypoints <FILE>",
        "--output <FILE.json>",
        "--settle <S>",
        "[default: 0.5]",
    ];
    for word in words {
        assert!(help.contains(word), "{word} missing from:\n{help}");
    }
}

/// Something done to a test folder holding `run/` and `render/truth.csv`.
type Spoil = Box<dyn Fn(&Path)>;

#[test]
fn bad_input_is_refused_naming_the_file_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let truth = render(tmp.path(), &mocap("wave-h.bvh"), &mocap("labels.csv"));
    let n = truth.rows.len();
    let good = perfect(&truth, &["wave-h"]);
    let primitives = [("wave-h", Some("wave-h"))];
    let edited = |edit: &dyn Fn(&mut Table)| {
        let mut frames = good.clone();
        edit(&mut frames);
        frames
    };
    let missing_column = edited(&|t| {
        let c = t.col("left_wrist_y");
        t.header.remove(c);
        t.rows.iter_mut().for_each(|r| drop(r.remove(c)));
    });
    let not_a_number = edited(&|t| t.set("head_z", 3..4, "abc"));
    let nan = edited(&|t| t.set("root_x", 7..8, "NaN"));
    let short = edited(&|t| drop(t.rows.pop()));
    let renumbered = edited(&|t| t.set("frame", 2..3, "99"));
    let header_only = edited(&|t| t.rows.clear());
    let unknown = edited(&|t| t.set("activity", 4..5, "jump"));
    let frames = |table: Table| -> Spoil { Box::new(move |dir| table.write(&dir.join("run/frames.csv"))) };
    let write = |name: &'static str, text: &'static str| -> Spoil {
        Box::new(move |dir| fs::write(dir.join(name), text).unwrap())
    };
    let remove = |name: &'static str| -> Spoil { Box::new(move |dir| fs::remove_file(dir.join(name)).unwrap()) };
    let f = "run/frames.csv";
    let cases: Vec<(Spoil, String)> = vec![
        (remove("run/frames.csv"), format!("{f}: cannot read")),
        (remove("run/summary.json"), "run/summary.json: cannot read".into()),
        (remove("render/truth.csv"), "render/truth.csv: cannot read".into()),
        (frames(missing_column), format!("{f}: missing column `left_wrist_y`")),
        (frames(not_a_number), format!("{f}: line 5, column `head_z`: expected a number, found \"abc\"")),
        (frames(nan), format!("{f}: line 9, column `root_x`: expected a number, found \"NaN\"")),
        (frames(short), format!("{f} has {} frames but render/truth.csv has {n}", n - 1)),
        (frames(renumbered), format!("row 3 is frame 99 in {f} but frame 2 in render/truth.csv")),
        (frames(header_only), format!("{f}: no frames")),
        (write("run/frames.csv", ""), format!("{f}: no frames")),
        (frames(unknown), format!("{f}: frame 4: activity `jump` is not one of the primitives in run/summary.json")),
        (write("run/summary.json", "{\"fps\": 15}"), "run/summary.json: missing field `primitives`".into()),
        (write("run/summary.json", "primitives: []"), "run/summary.json: expected value".into()),
    ];
    for (spoil, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        fs::create_dir(dir.path().join("render")).unwrap();
        fs::copy(tmp.path().join("render/truth.csv"), dir.path().join("render/truth.csv")).unwrap();
        let run = run_dir(dir.path(), &good, &primitives);
        spoil(dir.path());
        let out = score(dir.path(), &[]);
        let stderr = stderr_of(&out);
        assert_eq!(out.status.code(), Some(1), "{expected}: {stderr}");
        assert!(stderr.starts_with(&format!("imitate: error: {expected}")), "{expected}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!run.join("metrics.json").exists(), "{expected}");
    }
    let dir = tmp.path();
    run_dir(dir, &good, &primitives);
    let out = score(dir, &["--settle=-1"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("--settle -1"), "{}", stderr_of(&out));
    assert!(!dir.join("run/metrics.json").exists());
}
