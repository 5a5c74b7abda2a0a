//! The `imitate` command: subcommands, help, exit codes, outputs.

use crate::common;

use common::imitate;
use std::fs;
use std::path::Path;

fn stdout_of(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr_of(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn version_and_help_list_the_built_subcommands() {
    let out = imitate().arg("--version").output().unwrap();
    assert!(out.status.success());
    assert_eq!(stdout_of(&out).trim(), format!("imitate {}", env!("CARGO_PKG_VERSION")));
    let help = stdout_of(&imitate().arg("--help").output().unwrap());
    let built = [
        "inspect", "retarget", "synth", "segment", "embed", "cluster", "fit", "export", "vocab", "render", "track",
        "score", "execute", "report", "eval", "demo",
    ];
    for sub in built.iter().chain(&["--quiet"]) {
        assert!(help.contains(sub), "help lacks {sub}:\n{help}");
    }
    for sub in built {
        let out = imitate().args([sub, "--help"]).output().unwrap();
        assert!(out.status.success(), "{sub} --help");
        assert!(stdout_of(&out).contains("Usage: imitate"), "{sub}");
    }
}

#[test]
fn usage_errors_exit_with_code_2_and_say_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let cases: [(&[&str], &str); 8] = [
        (&["juggle"], "unrecognized subcommand"),
        (&["execute", "in.bvh"], "--output"),
        (&["track"], "--vocab"),
        (&["synth", "-o", out_dir.to_str().unwrap(), "--speed", "5"], "5 is outside 0.25 to 4"),
        (&["synth", "-o", out_dir.to_str().unwrap(), "--activities", "juggling"], "unknown activity `juggling`"),
        (&["synth", "-o", out_dir.to_str().unwrap(), "--reps", "0"], "--reps"),
        (
            &["synth", "-o", out_dir.to_str().unwrap(), "--activities", "punch", "--sequence", "reach"],
            "cannot be used with",
        ),
        (&["retarget", "in.bvh"], "--output"),
    ];
    for (args, expected) in cases {
        let out = imitate().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(stderr_of(&out).contains(expected), "{args:?}: {}", stderr_of(&out));
    }
    assert!(!out_dir.exists(), "a usage error writes nothing");
}

#[test]
fn synth_writes_one_take_per_activity_with_labels_and_repeats_itself_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str| {
        let out_dir = dir.path().join(name);
        let out = imitate()
            .args(["-q", "synth", "-o", out_dir.to_str().unwrap(), "--reps", "2", "--seed", "9"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr_of(&out));
        assert!(out.stderr.is_empty(), "--quiet prints nothing: {}", stderr_of(&out));
        out_dir
    };
    let (a, b) = (run("a"), run("b"));
    let mut names: Vec<String> =
        fs::read_dir(&a).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names, ["circles.bvh", "labels.csv", "punch.bvh", "reach.bvh", "twist.bvh", "wave-h.bvh", "wave-v.bvh"]);
    for name in &names {
        assert_eq!(fs::read(a.join(name)).unwrap(), fs::read(b.join(name)).unwrap(), "{name} differs between runs");
    }
    let labels = fs::read_to_string(a.join("labels.csv")).unwrap();
    assert!(labels.starts_with("file,activity\ncircles.bvh,circles\n"), "{labels}");
    let bvh = imitate::mocap::bvh::read_bvh(&a.join("punch.bvh")).unwrap();
    assert_eq!(bvh.skeleton.joints.len(), 17);
    assert!((bvh.frame_rate_hz() - 30.0).abs() < 1e-9);
}

#[test]
fn synth_sequence_writes_per_frame_labels_matching_the_take() {
    let dir = tempfile::tempdir().unwrap();
    let out = imitate()
        .args([
            "synth",
            "-o",
            dir.path().to_str().unwrap(),
            "--sequence",
            "circles,wave-h,wave-v",
            "--reps",
            "2",
            "--fps",
            "15",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("sequence.bvh"));
    let bvh = imitate::mocap::bvh::read_bvh(&dir.path().join("sequence.bvh")).unwrap();
    let labels = fs::read_to_string(dir.path().join("labels.csv")).unwrap();
    let rows: Vec<&str> = labels.lines().collect();
    assert_eq!(rows[0], "frame,activity");
    assert_eq!(rows.len() - 1, bvh.frames);
    assert_eq!(rows[1], "0,rest");
    assert!(rows.iter().any(|r| r.ends_with(",wave-h")));
    assert_eq!(rows.last().unwrap(), &format!("{},rest", bvh.frames - 1));
}

#[test]
fn retarget_writes_canonical_bvh_and_reports_how_closely_it_follows_the_source() {
    let Some(dir) = common::real_mocap_dir() else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let output = tmp.path().join("dab_canonical.bvh");
    let out = imitate()
        .args(["retarget", dir.join("dab.bvh").to_str().unwrap(), "-o", output.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let err = stderr_of(&out);
    assert!(err.contains("339 frames") && err.contains("limb directions match the source within"), "{err}");
    // And how the twists hold: what the fidelity tests check in
    // tests/retarget.rs, reported for the user's own take.
    assert!(err.contains("standing thighs face the pelvis's way within 30° in "), "{err}");
    assert!(err.contains("over 60° the source's bones do not make (largest jump"), "{err}");
    assert!(err.contains("warning: the capture stands along +Z"), "{err}");
    let bvh = imitate::mocap::bvh::read_bvh(&output).unwrap();
    let names: Vec<&str> = bvh.skeleton.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names[..5], ["pelvis", "spine", "chest", "neck", "head"]);
    assert_eq!(bvh.frames, 339);
    // Quiet: no summary, no warnings.
    let out = imitate()
        .args(["-q", "retarget", dir.join("dab.bvh").to_str().unwrap(), "-o", output.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success() && out.stderr.is_empty());
}

#[test]
fn retarget_maps_unknown_names_from_the_structure_and_uses_a_mapping_file_when_given() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("robot.bvh");
    // A canonical take with every joint renamed to something no scheme knows.
    let take = imitate::mocap::synth::activity_take(imitate::mocap::synth::Activity::WaveV, &Default::default());
    let mut bvh = take.motion.to_bvh();
    for joint in &mut bvh.skeleton.joints {
        joint.name = format!("Link_{}", joint.name.replace('_', ""));
    }
    let mut text = Vec::new();
    imitate::mocap::bvh::write_bvh(&bvh, &mut text).unwrap();
    fs::write(&input, text).unwrap();
    let output = tmp.path().join("out.bvh");
    let out = imitate().args(["retarget", input.to_str().unwrap(), "-o", output.to_str().unwrap()]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("within 0.00°"), "{}", stderr_of(&out));
    let inspect = imitate().args(["inspect", input.to_str().unwrap()]).output().unwrap();
    let report = String::from_utf8_lossy(&inspect.stdout).to_string();
    assert!(report.contains("naming      structure"), "{report}");
    assert!(report.contains("left_elbow ← Link_leftelbow (the limb's hinge; side from the pose)"), "{report}");

    let mapping = tmp.path().join("mapping.toml");
    let entries: String = imitate::mocap::body::Joint::ALL
        .iter()
        .map(|j| format!("{} = \"Link_{}\"\n", j.name(), j.name().replace('_', "")))
        .collect();
    fs::write(&mapping, entries).unwrap();
    let out = imitate()
        .args(["retarget", input.to_str().unwrap(), "-o", output.to_str().unwrap(), "--map", mapping.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("within 0.00°"), "{}", stderr_of(&out));
}

#[test]
fn a_skeleton_without_arms_is_an_error_that_shows_the_mapping_file_to_write() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("trunk.bvh");
    let text = "HIERARCHY\nROOT Base\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\
        JOINT Mid\n{\nOFFSET 0 30 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        JOINT Top\n{\nOFFSET 0 30 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{\nOFFSET 0 20 0\n}\n}\n}\n}\n\
        MOTION\nFrames: 2\nFrame Time: 0.1\n0 90 0 0 0 0 0 0 0 0 0 0\n0 90 0 0 0 0 5 0 0 0 0 0\n";
    fs::write(&input, text).unwrap();
    let output = tmp.path().join("out.bvh");
    let out = imitate().args(["retarget", input.to_str().unwrap(), "-o", output.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = stderr_of(&out);
    assert!(err.starts_with(&format!("imitate: error: {}: cannot map the skeleton", input.display())), "{err}");
    assert!(err.contains("its structure gives no body: it has 0 limbs"), "{err}");
    assert!(err.contains("left_elbow = \"<source joint name>\"") && err.contains("Base, Mid, Top"), "{err}");
    // The library says what to write; the command says which flag takes it.
    assert!(err.trim_end().ends_with("(pass the mapping file with --map FILE)"), "{err}");
    assert!(!output.exists());
}

#[test]
fn a_bad_mapping_file_is_an_error_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    let mapping = tmp.path().join("m.toml");
    fs::write(&mapping, "elbow = \"X\"\n").unwrap();
    let out = imitate().args(["inspect", "--map", mapping.to_str().unwrap(), "missing.bvh"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = stderr_of(&out);
    assert!(err.contains(&format!("{}: `elbow` is not a canonical joint", mapping.display())), "{err}");
}

fn inspect_json(files: &[&Path]) -> (Option<i32>, serde_json::Value) {
    let out = imitate().arg("inspect").arg("--json").args(files).output().unwrap();
    (out.status.code(), serde_json::from_slice(&out.stdout).expect("inspect --json prints JSON"))
}

#[test]
fn inspect_reports_frames_units_channels_mapping_and_warnings() {
    let Some(dir) = common::real_mocap_dir() else {
        return;
    };
    let (code, json) = inspect_json(&[&dir.join("boxing.bvh"), &dir.join("jumping_jacks.bvh"), &dir.join("dab.bvh")]);
    assert_eq!(code, Some(0));
    let boxing = &json[0];
    assert_eq!(boxing["ok"], true);
    assert_eq!(boxing["joints"], 74);
    assert_eq!(boxing["frames"], 60);
    assert!((boxing["frame_rate_hz"].as_f64().unwrap() - 30.0).abs() < 0.01);
    assert!((boxing["duration_s"].as_f64().unwrap() - 2.0).abs() < 0.01);
    assert_eq!(boxing["rotation_orders"]["YXZ"], 74);
    assert_eq!(boxing["analysis"]["units"], "centimeters");
    assert_eq!(boxing["analysis"]["scheme"], "74-joint");
    assert_eq!(boxing["analysis"]["up_axis"], "+Y");
    let mapping = boxing["analysis"]["mapping"].as_array().unwrap();
    let left_elbow = mapping.iter().find(|m| m["canonical"] == "left_elbow").unwrap();
    assert_eq!(left_elbow["source"], "LeftForeArm");
    let cmu = &json[1];
    assert_eq!(cmu["rotation_orders"]["ZXY"], 12);
    assert_eq!(cmu["rotation_orders"]["ZYX"], 19);
    let dab = &json[2];
    assert_eq!(dab["analysis"]["up_axis"], "+Z");
    let codes: Vec<&str> = dab["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert_eq!(codes, ["up_axis", "units_unknown"]);

    let text = stdout_of(&imitate().args(["inspect", dir.join("boxing.bvh").to_str().unwrap()]).output().unwrap());
    for field in [
        "joints      74 (root: Hips)",
        "60 at 30.000 Hz",
        "units       centimeters",
        "up axis     +Y (detected)",
        "left_elbow ← LeftForeArm",
        "missing",
        "warnings    none",
    ] {
        assert!(text.contains(field), "lacks `{field}`:\n{text}");
    }
}

#[test]
fn inspect_batch_reports_every_file_and_fails_when_one_fails() {
    let Some(dir) = common::real_mocap_dir() else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let bad = tmp.path().join("broken.bvh");
    fs::write(&bad, "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n").unwrap();
    let (code, json) = inspect_json(&[&dir.join("wave_hello.bvh"), &bad, &dir.join("zombie.bvh")]);
    assert_eq!(code, Some(1));
    let ok: Vec<bool> = json.as_array().unwrap().iter().map(|r| r["ok"].as_bool().unwrap()).collect();
    assert_eq!(ok, [true, false, true]);
    assert!(json[1]["error"].as_str().unwrap().contains(&format!("{}:4:", bad.display())));
}

#[test]
fn a_reader_that_closes_the_pipe_early_ends_inspect_quietly() {
    use std::io::Read;
    use std::process::Stdio;
    let Some(dir) = common::real_mocap_dir() else { return };
    // Far more JSON than a pipe buffer holds.
    let file = dir.join("boxing.bvh");
    let mut child = imitate()
        .args(["inspect", "--json"])
        .args(std::iter::repeat_n(&file, 60))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 16];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr_of(&out));
    assert!(!stderr_of(&out).contains("panicked"), "{}", stderr_of(&out));
    assert!(first.starts_with(b"[\n  {"));
}

#[test]
fn the_shipped_mocap_takes_are_reproduced_byte_for_byte_by_the_readme_command() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = fs::read_to_string(root.join("README.md")).unwrap();
    let line = readme
        .lines()
        .find(|l| l.starts_with("cargo run --release -- synth -o mocap"))
        .expect("the README gives the command that makes mocap/");
    let tmp = tempfile::tempdir().unwrap();
    let args: Vec<String> = line
        .trim_start_matches("cargo run --release -- ")
        .split_whitespace()
        .map(|a| if a == "mocap" { tmp.path().to_str().unwrap().to_string() } else { a.to_string() })
        .collect();
    let out = imitate().args(&args).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let mut shipped: Vec<_> = fs::read_dir(root.join("mocap")).unwrap().map(|e| e.unwrap().file_name()).collect();
    shipped.sort();
    let mut made: Vec<_> = fs::read_dir(tmp.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    made.sort();
    assert_eq!(shipped, made);
    for name in shipped {
        let same = fs::read(root.join("mocap").join(&name)).unwrap() == fs::read(tmp.path().join(&name)).unwrap();
        assert!(same, "mocap/{} differs from what the README's command makes", name.to_string_lossy());
    }
}
