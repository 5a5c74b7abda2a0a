//! `imitate execute`: trajectories played on the simulated humanoid. The
//! paper's four activities followed on a fixed base, every real capture
//! played, the files agreeing with each other, the same bytes every time,
//! falls reported, joint limits counted, and bad input refused with
//! nothing written.

use crate::common;

use common::{imitate, real_bvh_files};
use glam::DVec3;
use imitate::mocap::body::{Body, Joint};
use imitate::mocap::bvh::{read_bvh, write_bvh};
use imitate::mocap::pose::{Motion, Pose};
use imitate::mocap::retarget::{RetargetOptions, Retargeter};
use imitate::sim::execute::ExecuteParams;
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

fn stderr_of(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn execute(input: &Path, output: &Path, extra: &[&str]) -> Output {
    imitate().arg("execute").arg(input).arg("-o").arg(output).args(extra).output().unwrap()
}

/// Runs `execute` and reads its summary.json.
fn executed(input: &Path, output: &Path, extra: &[&str]) -> Value {
    let out = execute(input, output, extra);
    assert!(out.status.success(), "{}: {}", input.display(), stderr_of(&out));
    serde_json::from_slice(&fs::read(output.join("summary.json")).unwrap()).unwrap()
}

/// `imitate synth` takes of `activities` at `speed`, in `dir`.
fn synth(dir: &Path, activities: &str, speed: &str) -> PathBuf {
    let out = imitate()
        .args(["-q", "synth", "--activities", activities, "--speed", speed, "--seed", "3", "-o"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    dir.to_path_buf()
}

/// execution.csv as its header and rows of numbers.
fn table(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = fs::read_to_string(dir.join("execution.csv")).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    // An empty cell (a margin without a standing foot) reads as NaN.
    let rows = lines
        .map(|l| l.split(',').map(|v| if v.is_empty() { f64::NAN } else { v.parse().unwrap() }).collect())
        .collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header.iter().position(|c| c == name).unwrap_or_else(|| panic!("no column {name}"))
}

fn read_motion(path: &Path) -> Motion {
    let bvh = read_bvh(path).unwrap();
    Retargeter::new(&bvh, &RetargetOptions::default()).unwrap().retarget(&bvh)
}

/// Writes `path`: a canonical take of `frames` frames at 30 Hz, each the
/// rest pose as `shape` (given the frame) sets its joint-space numbers.
fn write_take(path: &Path, frames: usize, shape: impl Fn(usize, &mut [f64])) -> PathBuf {
    write_poses(path, frames, |k, p| shape(k, &mut p.x))
}

/// A take on the standard body of `frames` poses, each the rest pose as
/// `shape` changes it.
fn write_poses(path: &Path, frames: usize, shape: impl Fn(usize, &mut Pose)) -> PathBuf {
    let body = Body::standard();
    let poses: Vec<Pose> = (0..frames)
        .map(|k| {
            let mut p = Pose::rest(&body);
            shape(k, &mut p);
            p
        })
        .collect();
    write_bvh(&Motion { body, frame_time_s: 1.0 / 30.0, poses }.to_bvh(), &mut fs::File::create(path).unwrap())
        .unwrap();
    path.to_path_buf()
}

fn number(summary: &Value, key: &str) -> f64 {
    summary[key].as_f64().unwrap_or_else(|| panic!("{key} in {summary}"))
}

#[test]
fn the_four_paper_activities_are_followed_within_three_degrees_on_a_fixed_base() {
    let dir = tempfile::tempdir().unwrap();
    let activities = ["circles", "wave-h", "wave-v", "punch"];
    for speed in ["1", "4"] {
        let takes = synth(&dir.path().join(format!("takes-{speed}")), &activities.join(","), speed);
        for activity in activities {
            let run = dir.path().join(format!("run-{speed}-{activity}"));
            let s = executed(&takes.join(format!("{activity}.bvh")), &run, &["--fixed-base", "-q"]);
            let rms = number(&s, "rms_error_deg");
            eprintln!("{activity} at {speed}x: {rms:.2}° RMS, {:.2}° at worst", number(&s, "max_error_deg"));
            if speed == "1" {
                assert!(rms <= 3.0, "{activity} at 1x: {rms:.2}° RMS");
            }
            assert_eq!(s["base"], "fixed");
            assert_eq!(s["fell"], false);
            assert_eq!(s["rate_hz"], ExecuteParams::DEFAULT_RATE_HZ);
            // The joints hold together: rapier's joints are kept by its solver.
            assert!(number(&s, "max_joint_gap_mm") < 1.0, "{s}");
        }
    }
}

#[test]
fn the_summary_is_the_table_and_executed_bvh_is_what_the_table_says_the_humanoid_did() {
    let dir = tempfile::tempdir().unwrap();
    let takes = synth(&dir.path().join("takes"), "punch", "2");
    let run = dir.path().join("run");
    let s = executed(&takes.join("punch.bvh"), &run, &["--fixed-base", "-q"]);
    let (header, rows) = table(&run);
    let source = read_motion(&takes.join("punch.bvh"));
    assert_eq!(rows.len(), source.poses.len());
    assert_eq!(number(&s, "frames") as usize, rows.len());
    // On a stand no foot touches any ground: the humanoid's feet columns
    // are empty and their agreement with the take's contacts is not given.
    for foot in ["left_foot_down", "right_foot_down"] {
        assert!(rows.iter().all(|r| r[column(&header, foot)].is_nan()), "{foot}");
    }
    assert!(s["contact_agreement"].is_null(), "{s}");

    // The overall RMS is over every actuated joint's error column, from the
    // second frame (the first is where the humanoid was put).
    let errors: Vec<usize> =
        Joint::ALL.iter().skip(1).map(|j| column(&header, &format!("{}_error_deg", j.name()))).collect();
    let squares: Vec<f64> = rows[1..].iter().flat_map(|r| errors.iter().map(move |&c| r[c] * r[c])).collect();
    let rms = (squares.iter().sum::<f64>() / squares.len() as f64).sqrt();
    assert!((rms - number(&s, "rms_error_deg")).abs() < 1e-3, "{rms} against {}", s["rms_error_deg"]);
    let elbow = s["joints"].as_array().unwrap().iter().find(|j| j["joint"] == "right_elbow").unwrap();
    let torque = column(&header, "right_elbow_torque_nm");
    let peak = rows.iter().map(|r| r[torque].abs()).fold(0.0, f64::max);
    // The summary's peak is over every physics step, the table's over frames.
    assert!(number(elbow, "peak_torque_nm") >= peak - 1e-3 && peak > 0.0, "{elbow} against {peak}");

    // executed.bvh, read back, holds the achieved angles of the table: a
    // ball joint's three numbers are its rotation vector, a hinge's its angle.
    let done = read_motion(&run.join("executed.bvh"));
    assert_eq!(done.poses.len(), rows.len());
    for (k, (pose, row)) in done.poses.iter().zip(&rows).enumerate() {
        for (j, index, name) in [(Joint::RightShoulder, 1, "right_shoulder_y"), (Joint::RightElbow, 0, "right_elbow")] {
            let angle = pose.joint(j)[index].to_degrees();
            let listed = row[column(&header, &format!("{name}_deg"))];
            assert!((angle - listed).abs() < 2e-3, "frame {k} {name}: {angle} in the BVH, {listed} in the table");
        }
        // The targets are the trajectory's angles (inside every limit here).
        let asked = source.poses[k].joint(Joint::RightElbow)[0].to_degrees();
        assert!((asked - row[column(&header, "right_elbow_target_deg")]).abs() < 1e-3, "frame {k}");
    }
}

#[test]
fn the_same_inputs_give_the_same_bytes_on_either_base() {
    let dir = tempfile::tempdir().unwrap();
    let takes = synth(&dir.path().join("takes"), "wave-h", "1");
    for base in [&["--fixed-base"][..], &[][..]] {
        let runs: Vec<PathBuf> = (0..2).map(|k| dir.path().join(format!("run{k}-{}", base.len()))).collect();
        for run in &runs {
            executed(&takes.join("wave-h.bvh"), run, &[base, &["-q"]].concat());
        }
        for file in ["executed.bvh", "execution.csv", "summary.json"] {
            assert!(fs::read(runs[0].join(file)).unwrap() == fs::read(runs[1].join(file)).unwrap(), "{file} differs");
        }
    }
}

#[test]
fn standing_on_the_ground_a_waving_humanoid_stays_up_and_one_leaning_back_falls_and_says_when() {
    let dir = tempfile::tempdir().unwrap();
    let takes = synth(&dir.path().join("takes"), "wave-v", "1");
    let s = executed(&takes.join("wave-v.bvh"), &dir.path().join("up"), &["-q"]);
    assert_eq!((s["base"].as_str(), s["balance"].as_bool()), (Some("free"), Some(true)));
    assert_eq!(s["fell"], false, "{s}");
    assert!(s["fell_at_s"].is_null());
    assert!(number(&s, "rms_error_deg") <= 3.0, "{s}");
    // Every frame says how far the capture point lay inside the feet and
    // how far the balance turned the targets; the summary gathers them.
    let (header, rows) = table(&dir.path().join("up"));
    let (margin, departure) = (column(&header, "balance_margin_m"), column(&header, "departure_deg"));
    let least = rows[1..].iter().map(|r| r[margin]).fold(f64::INFINITY, f64::min);
    assert!(least > 0.0 && (least - number(&s, "min_balance_margin_m")).abs() < 1e-6, "{least} against {s}");
    let most = rows[1..].iter().map(|r| r[departure]).fold(0.0, f64::max);
    assert!(most > 0.0 && (most - number(&s, "departure_max_deg")).abs() < 1e-3, "{most} against {s}");
    // Both feet stand throughout, the humanoid's as the take's (from the
    // second frame: the first is where the humanoid was put, before the
    // physics found its contacts).
    let feet = ["left_foot_down", "right_foot_down", "take_left_foot_down", "take_right_foot_down"];
    assert!(rows[1..].iter().all(|r| feet.iter().all(|f| r[column(&header, f)] == 1.0)));
    assert!(feet[..2].iter().all(|f| rows[0][column(&header, f)].is_nan()));
    assert_eq!(number(&s, "contact_agreement"), 1.0, "{s}");

    // The feet turned 60° toe-down within a second, the legs straight:
    // standing flat, the body leans back with its centre of mass far behind
    // the heels, further than the balance may tilt the legs, then held for
    // two seconds, time to reach the ground. (Bent 80° at the hips instead,
    // the balance holds the body on its feet, the hips pushed back; turned
    // 45°, the balance's gathered shift holds it too.)
    let leaning = write_take(&dir.path().join("lean.bvh"), 90, |k, x| {
        for ankle in [Joint::LeftAnkle, Joint::RightAnkle] {
            x[ankle.dof_offset()] = (k as f64 / 30.0).min(1.0) * 60f64.to_radians();
        }
    });
    let run = dir.path().join("down");
    let s = executed(&leaning, &run, &["-q"]);
    assert_eq!(s["fell"], true, "{s}");
    let at = number(&s, "fell_at_s");
    assert!(at > 0.0 && at < number(&s, "duration_s"), "{s}");
    // By the end the pelvis is far below standing height.
    let (header, rows) = table(&run);
    let last = rows.last().unwrap()[column(&header, "root_y")];
    assert!(last < 0.7 * Body::standard().pelvis_height(), "the pelvis ends at {last} m");
    // The least margin is taken before the fall.
    let (time, margin) = (column(&header, "time_s"), column(&header, "balance_margin_m"));
    let before = rows[1..].iter().filter(|r| r[time] < at).map(|r| r[margin]).fold(f64::INFINITY, f64::min);
    assert!((before - number(&s, "min_balance_margin_m")).abs() < 1e-6, "{before} against {s}");
    // So is the feet's agreement with the take's contacts: the share of
    // the feet that touched the ground exactly when the take stood on them.
    let pairs = [("left_foot_down", "take_left_foot_down"), ("right_foot_down", "take_right_foot_down")];
    let feet: Vec<bool> = rows[1..]
        .iter()
        .filter(|r| r[time] < at)
        .flat_map(|r| pairs.map(|(mine, take)| r[column(&header, mine)] == r[column(&header, take)]))
        .collect();
    let agreeing = feet.iter().filter(|&&a| a).count() as f64 / feet.len() as f64;
    assert!((agreeing - number(&s, "contact_agreement")).abs() < 1e-6, "{agreeing} against {s}");
    assert!(s["assist"].is_null() && rows.iter().all(|r| r[column(&header, "assist_force_n")] == 0.0));

    // Assisted, the same take stays up: the assistance turns the leaning
    // body back (its centre of mass stays over the feet, so there is
    // nothing to push). Its force and torque are in every frame's row and
    // in the summary, the force also as a share of the body's weight.
    let run = dir.path().join("held");
    let s = executed(&leaning, &run, &["-q", "--assist"]);
    assert_eq!(s["fell"], false, "{s}");
    let (header, rows) = table(&run);
    let assist = &s["assist"];
    let most = |name: &str| rows.iter().map(|r| r[column(&header, name)]).fold(0.0, f64::max);
    let torque = most("assist_torque_nm");
    assert!(torque > 0.0 && torque <= number(assist, "max_torque_nm") + 1e-3, "{torque} against {assist}");
    assert!(most("assist_force_n") == 0.0 && number(assist, "max_force_n") == 0.0, "{assist}");
    let weight = number(&s, "mass_kg") * 9.81;
    let share = number(assist, "mean_force_share_of_weight");
    assert!((share * weight - number(assist, "mean_force_n")).abs() < 1e-3, "{assist}");
}

#[test]
fn a_take_that_starts_in_the_air_or_under_the_floor_says_so_and_starts_standing() {
    let dir = tempfile::tempdir().unwrap();
    for (name, by, said) in [("air", 0.5, "above the floor (in the air)"), ("under", -0.3, "below the floor")] {
        let take = write_poses(&dir.path().join(format!("{name}.bvh")), 30, |_, p| p.root.y += by);
        let run = dir.path().join(name);
        let out = execute(&take, &run, &[]);
        assert!(out.status.success(), "{}", stderr_of(&out));
        assert!(stderr_of(&out).contains(said), "{name}: {}", stderr_of(&out));
        let s: Value = serde_json::from_slice(&fs::read(run.join("summary.json")).unwrap()).unwrap();
        assert!((number(&s, "start_raised_m") + by).abs() < 1e-3, "{name}: {s}");
        assert_eq!(s["fell"], false, "{name}: {s}");
    }
    // Standing on the floor, nothing is said.
    let take = write_poses(&dir.path().join("floor.bvh"), 30, |_, _| {});
    let out = execute(&take, &dir.path().join("floor"), &[]);
    assert!(!stderr_of(&out).contains("the floor"), "{}", stderr_of(&out));
}

#[test]
fn on_the_ground_feet_pointing_toe_down_at_the_start_are_laid_flat_and_counted() {
    // Standing still with both ankles turned 20° toe-down: the captured
    // person stood flat; the canonical body would stand on its toes.
    let dir = tempfile::tempdir().unwrap();
    let input = write_take(&dir.path().join("toes.bvh"), 90, |_, x| {
        for ankle in [Joint::LeftAnkle, Joint::RightAnkle] {
            x[ankle.dof_offset()] = 20f64.to_radians();
        }
    });
    let s = executed(&input, &dir.path().join("ground"), &["-q"]);
    let levelled: Vec<f64> = s["feet_levelled_deg"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert!(levelled.iter().all(|d| (d - 20.0).abs() < 1e-6), "{levelled:?}");
    assert_eq!(s["fell"], false, "{s}");
    // The soles stay flat: what the humanoid did, read back.
    let done = read_motion(&dir.path().join("ground/executed.bvh"));
    let last = done.body.forward(done.poses.last().unwrap());
    for ankle in [Joint::LeftAnkle, Joint::RightAnkle] {
        let tilt = (last.rotation(ankle) * DVec3::Y).angle_between(DVec3::Y).to_degrees();
        assert!(tilt < 3.0, "{ankle:?}'s sole tilts {tilt:.1}°");
    }
    // On a stand there is no floor to lay them on.
    let s = executed(&input, &dir.path().join("stand"), &["--fixed-base", "-q"]);
    assert_eq!(s["feet_levelled_deg"], serde_json::json!([0.0, 0.0]));
}

#[test]
fn angles_beyond_a_joint_limit_are_clamped_and_counted_in_the_summary() {
    let dir = tempfile::tempdir().unwrap();
    // The left elbow swings to 170° (its limit is 150°) on frames 10–19.
    let input = write_take(&dir.path().join("over.bvh"), 30, |k, x| {
        x[Joint::LeftElbow.dof_offset()] = if (10..20).contains(&k) { 170f64.to_radians() } else { 1.0 };
    });
    let run = dir.path().join("run");
    let s = executed(&input, &run, &["--fixed-base", "-q"]);
    assert_eq!(s["clamped_frames"], 10, "{s}");
    let elbow = s["joints"].as_array().unwrap().iter().find(|j| j["joint"] == "left_elbow").unwrap();
    assert_eq!(elbow["clamped_frames"], 10);
    assert!((number(elbow, "clamped_by_deg") - 20.0).abs() < 1e-3, "{elbow}");
    let (header, rows) = table(&run);
    let target = column(&header, "left_elbow_target_deg");
    assert!((rows[15][target] - 150.0).abs() < 1e-3 && (rows[5][target] - 1f64.to_degrees()).abs() < 1e-3);
    let reached = column(&header, "left_elbow_deg");
    assert!(rows.iter().all(|r| r[reached] <= 150.1), "the hinge stops at its limit");
}

#[test]
fn every_real_capture_plays_on_a_fixed_base_within_five_degrees_and_bind_poses_are_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let mut errors = Vec::new();
    for path in real_bvh_files() {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let out = dir.path().join(&name);
        let run = execute(&path, &out, &["--fixed-base"]);
        assert!(run.status.success(), "{name}: {}", stderr_of(&run));
        let s: Value = serde_json::from_slice(&fs::read(out.join("summary.json")).unwrap()).unwrap();
        let left_out = stderr_of(&run).contains("the first frame is left out as a bind pose");
        assert_eq!(s["skipped_frames"].as_u64(), Some(u64::from(left_out)), "{name}");
        // boxing starts in a T-pose and turns 110° in its first frame;
        // wave_hello starts in motion.
        match name.as_str() {
            "boxing" => assert!(left_out, "{name}"),
            "wave_hello" => assert!(!left_out, "{name}"),
            _ => {}
        }
        if name == "boxing" {
            // Asked for, the bind pose stays.
            let kept = executed(&path, &dir.path().join(format!("{name}-kept")), &["--fixed-base", "--skip", "0"]);
            assert_eq!(kept["skipped_frames"].as_u64(), Some(0), "{name}");
            assert_eq!(kept["frames"].as_u64(), s["frames"].as_u64().map(|n| n + 1), "{name}");
        }
        let rms = number(&s, "rms_error_deg");
        eprintln!(
            "{name:22} skipped {}: {rms:.2}° RMS, {:.1}° at worst",
            u8::from(left_out),
            number(&s, "max_error_deg")
        );
        assert!(rms <= 5.0, "{name}: {rms:.2}° RMS");
        errors.push(rms);
    }
    if !errors.is_empty() {
        errors.sort_by(f64::total_cmp);
        let median = errors[errors.len() / 2];
        assert!(median <= 1.0, "median {median:.2}° RMS over the real captures");
    }
}

#[test]
fn planning_each_swing_ahead_carries_a_real_walk_through_that_falls_unplanned() {
    let Some(walk) = real_bvh_files().into_iter().find(|p| p.file_stem().is_some_and(|s| s == "walking")) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let unplanned = executed(&walk, &dir.path().join("unplanned"), &["--lookahead", "0"]);
    assert_eq!(unplanned["planned_swings"].as_u64(), Some(0));
    assert_eq!(number(&unplanned, "lookahead_s"), 0.0);
    assert!(unplanned["fell"].as_bool().unwrap(), "unplanned, the walk stayed up");
    let planned = executed(&walk, &dir.path().join("planned"), &[]);
    assert_eq!(number(&planned, "lookahead_s"), ExecuteParams::DEFAULT_LOOKAHEAD_S);
    let swings = planned["planned_swings"].as_u64().unwrap();
    assert!(!planned["fell"].as_bool().unwrap(), "planned, the walk fell at {} s", planned["fell_at_s"]);
    // Every step of a walk of several seconds is planned, none while the
    // take stands.
    assert!(swings >= 6, "{swings} swings planned");
    // Copies of the world played in parallel still give the same bytes.
    let again = dir.path().join("again");
    executed(&walk, &again, &[]);
    for file in ["execution.csv", "summary.json", "executed.bvh"] {
        let [a, b] = [dir.path().join("planned"), again.clone()].map(|d| fs::read(d.join(file)).unwrap());
        assert!(a == b, "{file} differs between two planned runs");
    }
}

#[test]
fn bad_input_is_one_clear_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let takes = synth(&dir.path().join("takes"), "punch", "1");
    let good = takes.join("punch.bvh");
    let text = fs::read_to_string(&good).unwrap();
    let (head, motion) = text.split_once("MOTION\n").unwrap();
    let empty = dir.path().join("empty.bvh");
    fs::write(&empty, format!("{head}MOTION\nFrames: 0\nFrame Time: 0.033333\n")).unwrap();
    let nan = dir.path().join("nan.bvh");
    let mut lines: Vec<String> = motion.lines().map(String::from).collect();
    lines[4] =
        lines[4].split(' ').enumerate().map(|(i, v)| if i == 10 { "nan" } else { v }).collect::<Vec<_>>().join(" ");
    fs::write(&nan, format!("{head}MOTION\n{}\n", lines.join("\n"))).unwrap();
    let missing = dir.path().join("missing.bvh");
    let used = dir.path().join("used");
    fs::create_dir(&used).unwrap();
    fs::write(used.join("keep.txt"), "mine").unwrap();

    let out = dir.path().join("out");
    let cases: [(&Path, &Path, &[&str], i32, &str); 15] = [
        (&good, &out, &["--gains", "0,200"], 2, "--gains 0,200: the stiffness gain must be a positive number"),
        (&good, &out, &["--gains", "-5,200"], 2, "--gains -5,200: the stiffness gain must be a positive number"),
        (&good, &out, &["--gains", "100,0"], 2, "--gains 100,0: the damping gain must be a positive number"),
        (&good, &out, &["--gains", "stiff"], 2, "--gains stiff: expected KP,KD"),
        (&good, &out, &["--rate", "0"], 2, "--rate 0: the physics rate must be"),
        (&good, &out, &["--rate", "-240"], 2, "--rate -240: the physics rate must be"),
        (&good, &out, &["--skip", "100000"], 2, "--skip 100000: "),
        (&good, &out, &["--lookahead", "-1"], 2, "--lookahead -1: how far ahead each swing is planned must be"),
        (&good, &out, &["--lookahead", "6"], 2, "--lookahead 6: how far ahead each swing is planned must be"),
        (&good, &out, &["--lookahead", "NaN"], 2, "--lookahead NaN: how far ahead each swing is planned must be"),
        (&good, &out, &["--assist", "--fixed-base"], 2, "--assist with --fixed-base: assistance holds a humanoid up"),
        (&empty, &out, &[], 1, "empty.bvh: the file has no frames"),
        (&nan, &out, &[], 1, "nan.bvh:"),
        (&missing, &out, &[], 1, "missing.bvh"),
        (&good, &used, &[], 1, "exists and is not empty"),
    ];
    for (input, output, extra, code, expected) in cases {
        let result = execute(input, output, extra);
        let stderr = stderr_of(&result);
        assert_eq!(result.status.code(), Some(code), "{extra:?}: {stderr}");
        assert!(stderr.contains(expected), "{extra:?}: {stderr}");
        assert_eq!(stderr.lines().filter(|l| l.starts_with("imitate: error")).count(), 1, "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    assert!(!out.exists(), "a refused run writes nothing");
    assert_eq!(fs::read_dir(&used).unwrap().count(), 1, "the used folder is left alone");
}
