//! `imitate eval --quick` and `imitate demo`: the report's files, its
//! numbers equal to metrics.json's, the same numbers for the same seed, the
//! page loading whole in headless Chromium, and bad input refused.

use crate::common;

use common::{browser_check, imitate, real_mocap_dir};
use std::fs;
use std::path::Path;
use std::process::Output;

fn run(dir: &Path, args: &[&str]) -> Output {
    imitate().current_dir(dir).args(args).arg("-q").output().unwrap()
}

fn ok(out: Output) -> Output {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    out
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&fs::read(path).unwrap()).unwrap()
}

/// `mean (min–max)` as the page writes a spread, scaled.
fn cell(spread: &serde_json::Value, scale: f64) -> String {
    let v = |k: &str| scale * spread[k].as_f64().unwrap();
    format!("{:.1} ({:.1}–{:.1})", v("mean"), v("min"), v("max"))
}

#[test]
fn a_quick_evaluation_reports_every_trial_with_the_numbers_of_its_metrics_json() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let real = real_mocap_dir().map_or("absent".to_string(), |d| d.display().to_string());
    let mocap = real_mocap_dir().map_or("absent".to_string(), |d| d.parent().unwrap().display().to_string());
    // One work folder for both runs: the vocabulary built there records its
    // sources' paths.
    let eval =
        |out: &str| ok(run(dir, &["eval", "--quick", "-o", out, "--work", "work", "--real", &real, "--mocap", &mocap]));
    eval("a");
    let report = dir.join("a");
    let metrics = json(&report.join("metrics.json"));
    assert_eq!(metrics["schema"], "imitate-eval/1");
    let mut trials = vec!["particles", "recognition", "speed", "viewpoint", "baseline", "person"];
    if real != "absent" {
        trials.extend(["real", "mocap_styles"]);
    }
    let keys: Vec<&str> = metrics["trials"].as_object().unwrap().keys().map(String::as_str).collect();
    let mut expected = trials.clone();
    expected.sort();
    assert_eq!(keys, expected);
    for file in [
        "index.html",
        "timing.json",
        "figure8.png",
        "figure8.svg",
        "filmstrip-front.png",
        "filmstrip-fast.png",
        "filmstrip-punch.png",
        "filmstrip-overhead.png",
        "filmstrip-person.png",
    ] {
        assert!(report.join(file).is_file(), "{file} missing");
    }
    let html = fs::read_to_string(report.join("index.html")).unwrap();
    for trial in &trials {
        for ext in ["csv", "png", "svg"] {
            assert!(report.join(format!("{trial}.{ext}")).is_file(), "{trial}.{ext} missing");
        }
        // Every setting's cells on the page are metrics.json's numbers.
        let settings = metrics["trials"][trial].as_array().unwrap();
        assert!(!settings.is_empty(), "{trial}");
        let csv = fs::read_to_string(report.join(format!("{trial}.csv"))).unwrap();
        assert_eq!(csv.lines().count(), settings.len() + 1, "{trial}.csv: a row per setting");
        for s in settings {
            assert_eq!(s["seeds"], 2, "--quick runs 2 seeds");
            assert!(html.contains(&cell(&s["upper_body_mm"], 1.0)), "{trial} {}: upper body", s["x"]);
            assert!(html.contains(&cell(&s["hand_mm"], 1.0)), "{trial} {}: hands", s["x"]);
            if !s["recognition_settled"].is_null() {
                assert!(html.contains(&cell(&s["recognition_settled"], 100.0)), "{trial} {}: recognition", s["x"]);
            }
        }
    }
    // The tables: their CSV a row per metrics.json row.
    let tables = metrics["tables"].as_object().unwrap();
    for (key, rows) in tables {
        let csv = fs::read_to_string(report.join(format!("{key}.csv"))).unwrap();
        assert_eq!(csv.lines().count(), rows.as_array().unwrap().len() + 1, "{key}.csv: a row per row");
    }
    // Imitation: the synthetic take followed closely on a stand and kept up
    // on the ground; the tracked run imitated by its primitives within 1.2×
    // of its trajectory played, and smoother (issue 20).
    let imitation = tables["imitation"].as_array().unwrap();
    let (synthetic, tracked) = (&imitation[0], &imitation[1]);
    let number = |v: &serde_json::Value| v.as_f64().unwrap();
    assert!(number(&synthetic["fixed_base"]["rms_error_deg"]) < 1.0, "{synthetic}");
    assert!(synthetic["ground"]["fell_at_s"].is_null(), "{synthetic}");
    assert!(html.contains(&format!("{:.2}", number(&synthetic["fixed_base"]["rms_error_deg"]))));
    let primitives = &tracked["primitives"];
    let (mine, theirs) =
        (number(&primitives["upper_body_error_mm"]), number(&primitives["trajectory_upper_body_error_mm"]));
    assert!(mine <= 1.2 * theirs, "{primitives}");
    assert!(number(&primitives["jerk_rms_m_s3"]) < number(&primitives["trajectory_jerk_rms_m_s3"]), "{primitives}");
    let labelled =
        real_mocap_dir().map_or(0, |d| fs::read_to_string(d.join("labels.csv")).unwrap().lines().count() - 1);
    assert_eq!(imitation.len(), 2 + labelled, "every real take is played");
    // The real motion capture's tables: their cells on the page.
    if mocap != "absent" {
        let keys: Vec<&str> = tables.keys().map(String::as_str).collect();
        assert_eq!(keys, ["imitation", "mocap_corpora", "mocap_held_out", "mocap_projection", "mocap_vocabularies"]);
        let corpora = tables["mocap_corpora"].as_array().unwrap();
        let all = corpora.last().unwrap();
        assert_eq!(all["corpus"], "all");
        assert_eq!(all["mapped"], all["takes"], "every real take maps with no mapping file");
        assert!(html.contains(&format!("{} of {}", all["mapped"], all["takes"])));
        for row in tables["mocap_vocabularies"].as_array().unwrap() {
            let purity = row["purity"].as_f64().unwrap();
            assert!(html.contains(&format!("{purity:.3}")), "{}: purity", row["corpus"]);
        }
        let held_out = tables["mocap_held_out"].as_array().unwrap();
        assert!(held_out.iter().any(|r| r["corpus"] == "bandai dataset 2" && r["group"] == "normal"));
        for row in held_out {
            let cosine = row["latent_cosine"].as_f64().unwrap();
            assert!(html.contains(&format!("{cosine:.3}")), "{} {}: field cosine", row["corpus"], row["group"]);
        }
    }
    // The headline numbers point into metrics.json.
    let mut headline = 0;
    for part in html.split("data-metric=\"").skip(1) {
        let (pointer, rest) = part.split_once('"').unwrap();
        let shown = rest[1..].split_once('<').unwrap().0;
        let value =
            metrics.pointer(pointer).unwrap_or_else(|| panic!("{pointer} not in metrics.json")).as_f64().unwrap();
        let expected = if shown.ends_with('%') { format!("{:.1}%", 100.0 * value) } else { format!("{value:.1} mm") };
        assert_eq!(shown, expected, "{pointer}");
        headline += 1;
    }
    assert_eq!(headline, 3);
    // The baseline names no activity; the primitives recognize.
    let baseline = metrics["trials"]["baseline"].as_array().unwrap();
    assert!(baseline.iter().any(|s| s["follower"] == "full_space" && s["recognition_settled"].is_null()));
    // Trial two measures the hand's speed.
    let speeds: Vec<f64> =
        metrics["trials"]["speed"].as_array().unwrap().iter().map(|s| s["hand_m_per_s"].as_f64().unwrap()).collect();
    assert!(
        speeds.windows(2).take(4).all(|w| w[0] <= w[1] + 1e-9),
        "hand speed rises with the playback speed: {speeds:?}"
    );
    let timing = json(&report.join("timing.json"));
    assert!(timing["machine"].as_str().unwrap().contains("logical cores"));

    // The same seed gives the same numbers and tables (only timing differs).
    eval("b");
    for file in ["metrics.json", "particles.csv", "speed.csv", "imitation.csv", "figure8.svg", "filmstrip-front.png"] {
        let same = fs::read(report.join(file)).unwrap() == fs::read(dir.join("b").join(file)).unwrap();
        assert!(same, "{file} differs between two runs of the same seed");
    }
    browser_check(&report.join("index.html"), "eval-screenshot.png");
}

#[test]
fn eval_refuses_a_used_output_folder_and_a_vocabulary_of_one_primitive() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fs::create_dir(dir.join("taken")).unwrap();
    fs::write(dir.join("taken/keep.txt"), "mine").unwrap();
    let out = run(dir, &["eval", "--quick", "-o", "taken"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("taken: exists and is not empty"));
    assert_eq!(fs::read_to_string(dir.join("taken/keep.txt")).unwrap(), "mine");

    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("vocab/default.vocab");
    let mut vocab = imitate::vocab::vocabulary::Vocabulary::load(&shipped).unwrap();
    let first = vocab.primitives()[0].name().to_string();
    vocab.retain(|p| p.name() == first);
    vocab.save(&dir.join("one.vocab")).unwrap();
    let out = run(dir, &["eval", "--quick", "-o", "r", "--vocab", "one.vocab"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--vocab one.vocab: 1 primitive; recognition needs at least 2"), "{stderr}");
    assert!(!dir.join("r").exists());
}

#[test]
fn the_demo_tracks_the_shipped_vocabulary_and_prints_its_report_and_headline_numbers() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let demo = || imitate().current_dir(dir).arg("demo").output().unwrap();
    let out = ok(demo());
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(said.contains("report: demo/report/index.html"), "{said}");
    let metrics = json(&dir.join("demo/report/metrics.json"));
    let ub = metrics["upper_body_mm"].as_f64().unwrap();
    assert!(said.contains(&format!("upper-body error {ub:.1} mm")), "{said}");
    // The shipped vocabulary follows its own activities well.
    assert!(ub < 40.0, "upper body {ub} mm");
    assert!(metrics["recognition_accuracy_settled"].as_f64().unwrap() > 0.8);
    // The humanoid plays the virtual trajectory standing, and says how well.
    let execution = json(&dir.join("demo/humanoid/summary.json"));
    assert_eq!(execution["input"], "demo/run/trajectory.bvh");
    let rms = execution["rms_error_deg"].as_f64().unwrap();
    assert!(said.contains(&format!("joints within {rms:.2}° RMS")), "{said}");
    assert!(rms <= 3.0, "the humanoid follows within {rms}° RMS");
    assert!(dir.join("demo/humanoid/executed.bvh").is_file());
    // A second demo replaces the first; another folder is never replaced.
    ok(demo());
    fs::create_dir(dir.join("mine")).unwrap();
    fs::write(dir.join("mine/notes.txt"), "keep").unwrap();
    let out = imitate().current_dir(dir).args(["demo", "-o", "mine"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("is not a demo's folder"));
    assert!(dir.join("mine/notes.txt").is_file());
}
