//! `imitate track`: the run folder's files and their columns, the same
//! bytes for the same seed on any thread count, coasting over a frame with
//! no silhouette, and bad input refused with nothing written.

use crate::common;

use common::{imitate, real_video_dir};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

fn shipped(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

fn run(dir: &Path, args: &[&str], threads: &str) -> Output {
    imitate().current_dir(dir).env("RAYON_NUM_THREADS", threads).args(args).arg("-q").output().unwrap()
}

fn ok(out: Output) -> Output {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    out
}

/// A rendered video of the shipped horizontal waving in `dir/video`.
fn video(dir: &Path) -> PathBuf {
    let take = shipped("mocap/wave-h.bvh");
    let labels = shipped("mocap/labels.csv");
    ok(run(dir, &["render", take.to_str().unwrap(), "-o", "video", "--labels", labels.to_str().unwrap()], "2"));
    dir.join("video")
}

/// summary.json without its `timing`, the one part that differs run to run.
fn summary_without_timing(run: &Path) -> serde_json::Value {
    let mut summary: serde_json::Value = serde_json::from_slice(&fs::read(run.join("summary.json")).unwrap()).unwrap();
    summary.as_object_mut().unwrap().remove("timing").expect("summary.json reports its timing");
    summary
}

#[test]
fn a_video_tracks_to_a_trajectory_frames_table_and_summary_the_same_on_one_or_four_threads() {
    let tmp = tempfile::tempdir().unwrap();
    let video = video(tmp.path());
    let vocab = shipped("vocab/default.vocab");
    let frames = video.join("frames");
    for (threads, name) in [("1", "a"), ("4", "b")] {
        let args = ["track", frames.to_str().unwrap(), "--vocab", vocab.to_str().unwrap(), "-o", name, "--seed", "3"];
        ok(run(tmp.path(), &args, threads));
    }
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    for file in ["trajectory.bvh", "frames.csv", "likelihoods.csv"] {
        assert_eq!(fs::read(a.join(file)).unwrap(), fs::read(b.join(file)).unwrap(), "{file}");
    }
    assert_eq!(summary_without_timing(&a), summary_without_timing(&b));

    let table = fs::read_to_string(a.join("frames.csv")).unwrap();
    let truth = fs::read_to_string(video.join("truth.csv")).unwrap();
    let header: Vec<&str> = table.lines().next().unwrap().split(',').collect();
    let summary = summary_without_timing(&a);
    let names: Vec<&str> =
        summary["primitives"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
    let mut expected: Vec<String> = ["frame", "time_s", "activity"].map(String::from).to_vec();
    expected.extend(names.iter().map(|n| format!("prob_{n}")));
    expected.extend(names.iter().map(|n| format!("progress_{n}")));
    // Root and joint positions named as in truth.csv.
    let truth_header: Vec<&str> = truth.lines().next().unwrap().split(',').collect();
    expected.extend(truth_header[3..7 + 17 * 3].iter().map(|c| c.to_string()));
    // Then the open set's judgement.
    expected.extend(["unexplained", "fit_silhouette", "fit_keypoints"].map(String::from));
    assert_eq!(header, expected);
    assert_eq!(table.lines().count(), truth.lines().count(), "one row per frame");
    for line in table.lines().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), header.len());
        assert!(names.contains(&fields[2]), "activity {}", fields[2]);
        let probabilities: Vec<f64> = fields[3..3 + names.len()].iter().map(|p| p.parse().unwrap()).collect();
        assert!((probabilities.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        let open_set = fields.len() - 3;
        assert!(fields[3 + names.len()..open_set].iter().all(|v| v.parse::<f64>().unwrap().is_finite()));
        assert!(["0", "1"].contains(&fields[open_set]), "unexplained {}", fields[open_set]);
        let overlap: f64 = fields[open_set + 1].parse().unwrap();
        assert!((0.0..=1.0).contains(&overlap), "fit_silhouette {overlap}");
        assert_eq!(fields[open_set + 2], "", "no keypoints, no fit to them");
    }
    // likelihoods.csv: each primitive's R, then its evidence, one row per
    // frame, all positive.
    let likelihoods = fs::read_to_string(a.join("likelihoods.csv")).unwrap();
    let header: Vec<String> = likelihoods.lines().next().unwrap().split(',').map(String::from).collect();
    let expected: Vec<String> = std::iter::once("frame".to_string())
        .chain(names.iter().map(|n| format!("likelihood_{n}")))
        .chain(names.iter().map(|n| format!("evidence_{n}")))
        .collect();
    assert_eq!(header, expected);
    assert_eq!(likelihoods.lines().count(), truth.lines().count());
    for line in likelihoods.lines().skip(1) {
        let values: Vec<f64> = line.split(',').skip(1).map(|v| v.parse().unwrap()).collect();
        assert_eq!(values.len(), 2 * names.len());
        assert!(values.iter().all(|&v| v > 0.0), "{line}");
    }
    let frames = truth.lines().count() - 1;
    assert_eq!(summary["frames"], frames);
    assert_eq!(summary["seed"], 3);
    assert!(summary["likelihood_evaluations_per_frame"].as_f64().unwrap() > names.len() as f64 * 6.0);
    let bvh = fs::read_to_string(a.join("trajectory.bvh")).unwrap();
    assert!(bvh.contains(&format!("Frames: {frames}\n")) && bvh.contains("ROOT pelvis"));
}

#[test]
fn a_frame_without_a_silhouette_is_coasted_and_left_without_activity() {
    let tmp = tempfile::tempdir().unwrap();
    let video = video(tmp.path());
    let blank = image::GrayImage::new(160, 120);
    blank.save(video.join("frames/000010.png")).unwrap();
    let vocab = shipped("vocab/default.vocab");
    let frames = video.join("frames");
    ok(run(tmp.path(), &["track", frames.to_str().unwrap(), "--vocab", vocab.to_str().unwrap(), "-o", "run"], "2"));
    let table = fs::read_to_string(tmp.path().join("run/frames.csv")).unwrap();
    let row: Vec<&str> = table.lines().nth(11).unwrap().split(',').collect();
    assert_eq!(row[0], "10");
    assert_eq!(row[2], "", "no activity on a frame without a silhouette");
    let primitives = summary_without_timing(&tmp.path().join("run"))["primitives"].as_array().unwrap().len();
    assert!(row[3..3 + primitives].iter().all(|p| p.is_empty()), "no probabilities: {row:?}");
    let open_set = row.len() - 3;
    assert!(row[3 + primitives..open_set].iter().all(|v| v.parse::<f64>().is_ok()), "the pose is still estimated");
    assert!(row[open_set..].iter().all(|v| v.is_empty()), "nothing seen, nothing judged: {row:?}");
    assert_eq!(summary_without_timing(&tmp.path().join("run"))["coasted_frames"], 1);
}

#[test]
fn a_person_built_unlike_the_capsules_is_measured_and_followed_closer_than_by_the_canonical_body() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let take = shipped("mocap/wave-h.bvh");
    let labels = shipped("mocap/labels.csv");
    let render = ["render", take.to_str().unwrap(), "-o", "video", "--labels", labels.to_str().unwrap()];
    ok(run(dir, &[&render[..], &["--body", "slight"]].concat(), "2"));
    let vocab = shipped("vocab/default.vocab");
    let track = ["track", "video/frames", "--vocab", vocab.to_str().unwrap(), "--particles", "12", "--feedback"];
    ok(run(dir, &[&track[..], &["-o", "fitted"]].concat(), "2"));
    ok(run(dir, &[&track[..], &["-o", "canonical", "--no-calibrate"]].concat(), "2"));
    ok(run(dir, &[&track[..], &["-o", "told", "--height", "1.5"]].concat(), "2"));
    let body = |run: &str| summary_without_timing(&dir.join(run))["body"].clone();
    let fitted = body("fitted");
    // The slight build stands 1.50 m; the canonical body 1.75 m.
    assert_eq!(fitted["calibrated"], true, "{fitted}");
    let height = fitted["height_m"].as_f64().unwrap();
    assert!((height - 1.5).abs() < 0.06, "{fitted}");
    assert!(fitted["girth"]["trunk"].as_f64().unwrap() < 1.0, "{fitted}");
    assert!(fitted["evaluations"].as_u64().unwrap() > 0);
    assert_eq!(body("canonical")["calibrated"], false);
    assert!(body("canonical")["note"].as_str().unwrap().contains("calibration off"));
    let told = body("told");
    assert_eq!((told["height_m"].as_f64(), told["height_given"].as_bool()), (Some(1.5), Some(true)), "{told}");
    let root_mm = |run: &str| {
        let estimate = imitate::report::read_track(&dir.join(run).join("frames.csv")).unwrap();
        let truth = imitate::report::read_track(&dir.join("video/truth.csv")).unwrap();
        let primitives = imitate::report::read_primitives(&dir.join(run).join("summary.json")).unwrap();
        imitate::report::metrics::score(&estimate, &truth, &primitives, 0.5).unwrap().root_mm
    };
    // The canonical body stands far back to look as small as the person.
    let (fitted, canonical) = (root_mm("fitted"), root_mm("canonical"));
    assert!(fitted < 0.5 * canonical, "root {fitted:.0} mm calibrated, {canonical:.0} mm canonical");
}

#[test]
fn the_frame_rate_is_the_input_s_own_unless_told() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let take = shipped("mocap/wave-h.bvh");
    ok(run(dir, &["render", take.to_str().unwrap(), "-o", "video", "--fps", "30"], "2"));
    let vocab = shipped("vocab/default.vocab");
    let vocab = vocab.to_str().unwrap();
    let rate = |run: &str| {
        let summary = summary_without_timing(&dir.join(run));
        (summary["fps"].as_f64().unwrap(), summary["fps_from"].as_str().unwrap().to_string())
    };
    // A rendered folder: the rate of its truth.csv, and the rows' times are the truth's.
    ok(run(dir, &["track", "video/frames", "--vocab", vocab, "-o", "folder"], "2"));
    assert_eq!(rate("folder"), (30.0, "truth".into()));
    let times = |path: &str| -> Vec<String> {
        let text = fs::read_to_string(dir.join(path)).unwrap();
        text.lines().skip(1).map(|l| l.split(',').nth(1).unwrap().to_string()).collect()
    };
    assert_eq!(times("folder/frames.csv"), times("video/truth.csv"));
    ok(run(dir, &["track", "video/frames", "--vocab", vocab, "-o", "told", "--fps", "12.5"], "2"));
    assert_eq!(rate("told"), (12.5, "option".into()));
    // A video: the rate its container states.
    let ffmpeg = std::process::Command::new("ffmpeg").arg("-version").output().is_ok_and(|o| o.status.success());
    assert!(ffmpeg || std::env::var_os("CI").is_none(), "ffmpeg is not on PATH: under CI it is required");
    if ffmpeg {
        let made = std::process::Command::new("ffmpeg")
            .args(["-v", "error", "-framerate", "25", "-i", "video/frames/%06d.png", "-c:v", "ffv1", "clip.mkv"])
            .current_dir(dir)
            .status()
            .unwrap();
        assert!(made.success());
        let args = ["track", "clip.mkv", "--vocab", vocab, "-o", "clip", "--camera", "video/camera.json"];
        ok(run(dir, &args, "2"));
        assert_eq!(rate("clip"), (25.0, "video".into()));
    }
}

/// A track that must fail: `code`, an error naming the problem, and no
/// output folder.
fn refused(dir: &Path, args: &[&str], code: i32, says: &str) {
    let out = run(dir, args, "2");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    assert!(err.contains(says) && !err.contains("panicked"), "{args:?}: {err}");
    assert!(!dir.join("out").exists(), "{args:?} left output");
}

#[test]
fn bad_input_is_refused_with_nothing_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let video = video(dir);
    let frames = video.join("frames");
    let frames = frames.to_str().unwrap();
    let vocab = shipped("vocab/default.vocab");
    let vocab = vocab.to_str().unwrap();
    refused(dir, &["track", frames, "--vocab", vocab, "-o", "out", "--particles", "0"], 2, "--particles 0");
    refused(dir, &["track", frames, "--vocab", vocab, "-o", "out", "--lookahead", "0"], 2, "--lookahead 0");
    refused(dir, &["track", frames, "--vocab", vocab, "-o", "out", "--work-size", "8"], 2, "--work-size 8");
    refused(dir, &["track", frames, "--vocab", vocab, "-o", "out", "--height", "0.5"], 2, "--height 0.5");
    refused(dir, &["track", frames, "--vocab", vocab, "-o", "out", "--fps", "0"], 2, "--fps 0");
    let share = ["track", frames, "--vocab", vocab, "-o", "out", "--unexplained-below", "1.5"];
    refused(
        dir,
        &share,
        2,
        "--unexplained-below 1.5: the share of a frame its best primitive must explain lies in [0, 1]",
    );
    let both = ["track", frames, "--vocab", vocab, "-o", "out", "--height", "1.7", "--no-calibrate"];
    refused(dir, &both, 2, "cannot be used with");
    refused(dir, &["track", frames, "--vocab", "missing.vocab", "-o", "out"], 1, "missing.vocab");
    refused(dir, &["track", "nowhere", "--vocab", vocab, "-o", "out"], 1, "nowhere");
    // Frames of another size than the camera's.
    let take = shipped("mocap/punch.bvh");
    ok(run(dir, &["render", take.to_str().unwrap(), "-o", "small", "--size", "96x72"], "2"));
    let camera = video.join("camera.json");
    let small = dir.join("small/frames");
    let args = ["track", small.to_str().unwrap(), "--vocab", vocab, "-o", "out", "--camera", camera.to_str().unwrap()];
    refused(dir, &args, 1, "the camera is 160×120");
    // A camera upside down: the person's feet above its horizon.
    let flipped =
        fs::read_to_string(&camera).unwrap().replace("\"up\": [\n    0.0,\n    1.0,", "\"up\": [\n    0.0,\n    -1.0,");
    assert!(flipped.contains("-1.0"), "{flipped}");
    fs::write(dir.join("flipped.json"), flipped).unwrap();
    refused(
        dir,
        &["track", frames, "--vocab", vocab, "-o", "out", "--camera", "flipped.json"],
        1,
        "looks away from the floor",
    );
    // A field of view no camera has, and a focal length for a camera that
    // is given rather than estimated.
    for fov in ["5", "151"] {
        refused(dir, &["track", frames, "--vocab", vocab, "-o", "out", "--fov", fov], 2, &format!("--fov {fov}"));
    }
    refused(dir, &["track", frames, "--vocab", vocab, "-o", "out", "--focal", "0"], 2, "--focal 0");
    let given = ["track", frames, "--vocab", vocab, "-o", "out", "--fov", "40"];
    refused(dir, &given, 2, "this run's camera is given");
    // Frames with no camera beside them, none given, and the person cut
    // off by the frame's top edge in each: no camera can be estimated.
    fs::create_dir(dir.join("loose")).unwrap();
    let cut = image::GrayImage::from_fn(160, 120, |x, y| {
        image::Luma([if (70..90).contains(&x) && y < 80 { 255 } else { 0 }])
    });
    cut.save(dir.join("loose/000000.png")).unwrap();
    refused(dir, &["track", "loose", "--vocab", vocab, "-o", "out"], 2, "no frame showed the whole person");
    // A frame of another kind partway.
    let rgb = image::RgbImage::from_pixel(160, 120, image::Rgb([90, 120, 30]));
    rgb.save(video.join("frames/000005.png")).unwrap();
    refused(dir, &["track", frames, "--vocab", vocab, "-o", "out"], 1, "000005.png");
}

#[test]
fn frames_without_a_camera_are_tracked_through_one_estimated_from_them_nearly_as_well_as_through_the_true_one() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let video = video(dir);
    // The frames alone: no camera.json beside them.
    fs::create_dir(dir.join("loose")).unwrap();
    for entry in fs::read_dir(video.join("frames")).unwrap() {
        let path = entry.unwrap().path();
        fs::copy(&path, dir.join("loose").join(path.file_name().unwrap())).unwrap();
    }
    let vocab = shipped("vocab/default.vocab");
    let track = ["track", "--vocab", vocab.to_str().unwrap(), "--seed", "1", "--particles", "25", "--feedback"];
    ok(run(dir, &[&track[..], &["video/frames", "-o", "told"]].concat(), "2"));
    // The front preset's vertical field of view: 2·atan(60 / 200).
    ok(run(dir, &[&track[..], &["loose", "-o", "estimated", "--fov", "33.4"]].concat(), "2"));
    let summary = summary_without_timing(&dir.join("estimated"));
    let estimate = &summary["camera_estimate"];
    assert_eq!(estimate["focal_from"], "fov", "{estimate}");
    assert!(estimate["frames"].as_u64().unwrap() >= 6, "{estimate}");
    // The camera used is written, and is the summary's.
    let written: serde_json::Value =
        serde_json::from_slice(&fs::read(dir.join("estimated/camera.json")).unwrap()).unwrap();
    assert_eq!(written, summary["camera"]);
    // The person stands still, so the camera's height is the prior's
    // choice; the head and feet still put them about 4 m away.
    let distance = estimate["distance_m"].as_f64().unwrap();
    assert!((distance - 4.0).abs() < 0.3, "{estimate}");
    assert_eq!(summary["body"]["height_from"], "camera");
    let (told, estimated) = (upper_body_mm(dir, "told", "video"), upper_body_mm(dir, "estimated", "video"));
    assert!(estimated < 1.3 * told, "estimated camera {estimated:.1} mm, true camera {told:.1} mm");
}

#[test]
fn a_real_capture_is_tracked_with_the_shipped_vocabulary_within_150_mm_of_its_upper_body() {
    let Some(real) = common::real_mocap_dir() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let take = real.join("two_hand_wave.bvh");
    ok(run(tmp.path(), &["render", take.to_str().unwrap(), "-o", "video"], "2"));
    let vocab = shipped("vocab/default.vocab");
    // One seed's error swings with where the filters first lock on (91 to
    // 157 mm over seeds 0–3), so the mean of three is held to the bound.
    let seeds = ["0", "1", "2"];
    let mut total = 0.0;
    for seed in seeds {
        let out = format!("run{seed}");
        let args = ["track", "video/frames", "--vocab", vocab.to_str().unwrap(), "-o", &out, "--seed", seed];
        ok(run(tmp.path(), &args, "2"));
        total += upper_body_mm(tmp.path(), &out, "video");
    }
    let error = total / seeds.len() as f64;
    // Measured 114 mm: the vocabulary is the synthetic demonstrator's, and
    // waving with both hands is none of its activities.
    assert!(error < 150.0, "upper body {error:.1} mm");
}

/// `frames.csv`-style keypoints of `video`'s true joints as its camera
/// sees them, every other frame's wrists left out, in `dir/NAME`.
fn true_keypoints(dir: &Path, video: &Path, name: &str) -> PathBuf {
    use imitate::mocap::body::Joint;
    let camera = imitate::vision::camera::Camera::read(&video.join("camera.json")).unwrap();
    let truth = imitate::report::read_track(&video.join("truth.csv")).unwrap();
    let sites = [
        (Joint::LeftShoulder, "left_shoulder"),
        (Joint::RightShoulder, "right_shoulder"),
        (Joint::LeftElbow, "left_elbow"),
        (Joint::RightElbow, "right_elbow"),
        (Joint::LeftWrist, "left_wrist"),
        (Joint::RightWrist, "right_wrist"),
        (Joint::LeftHip, "left_hip"),
        (Joint::RightHip, "right_hip"),
        (Joint::LeftAnkle, "left_ankle"),
        (Joint::RightAnkle, "right_ankle"),
    ];
    let mut csv = String::from("frame,joint,x,y,confidence\n");
    for (k, joints) in truth.joints.iter().enumerate() {
        for (joint, name) in sites {
            let (u, v, _) = camera.project(joints[joint.index()]).unwrap();
            let found = k % 2 == 0 || !name.ends_with("wrist");
            csv += &if found { format!("{k},{name},{u:.2},{v:.2},0.9\n") } else { format!("{k},{name},,,0\n") };
        }
    }
    fs::write(dir.join(name), csv).unwrap();
    dir.join(name)
}

#[test]
fn keypoints_alone_or_beside_the_silhouette_follow_the_person_closer_than_the_silhouette_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let video = video(dir);
    let keypoints = true_keypoints(dir, &video, "keypoints.csv");
    let vocab = shipped("vocab/default.vocab");
    let mut errors = Vec::new();
    for observe in ["silhouette", "keypoints", "both"] {
        let out = format!("run-{observe}");
        let args = [
            "track",
            "video/frames",
            "--vocab",
            vocab.to_str().unwrap(),
            "-o",
            &out,
            "--keypoints",
            keypoints.to_str().unwrap(),
            "--observe",
            observe,
            "--seed",
            "1",
        ];
        ok(run(dir, &args, "2"));
        let summary = summary_without_timing(&dir.join(&out));
        assert_eq!(summary["observe"], observe);
        assert_eq!(summary["keypoints"]["frames"], summary["frames"]);
        errors.push(upper_body_mm(dir, &out, "video"));
        // The projected joints agree with the keypoints they were tracked by.
        ok(run(dir, &["score", &out, "--keypoints", keypoints.to_str().unwrap()], "2"));
        let agreement: serde_json::Value =
            serde_json::from_slice(&fs::read(dir.join(&out).join("agreement.json")).unwrap()).unwrap();
        let pck = agreement["pck_mirror"].as_f64().unwrap();
        eprintln!("{observe}: PCK@0.2 {pck:.3}");
        assert!(pck >= 0.9, "{observe}: PCK@0.2 {pck}");
    }
    eprintln!("upper body: silhouette {:.1} mm, keypoints {:.1} mm, both {:.1} mm", errors[0], errors[1], errors[2]);
    assert!(errors[1] < errors[0] && errors[2] < errors[0], "{errors:?}");
    let both = ["score", "run-both", "--truth", "video/truth.csv", "--keypoints", keypoints.to_str().unwrap()];
    assert_eq!(run(dir, &both, "2").status.code(), Some(2));
    assert_eq!(run(dir, &["score", "run-both"], "2").status.code(), Some(2));
}

#[test]
fn keypoints_that_cannot_be_used_are_refused_with_nothing_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    video(dir);
    let vocab = shipped("vocab/default.vocab");
    let vocab = vocab.to_str().unwrap();
    let track = ["track", "video/frames", "--vocab", vocab, "-o", "out"];
    let with = |extra: &[&'static str]| [&track[..], extra].concat();
    refused(dir, &with(&["--observe", "keypoints"]), 2, "--keypoints FILE");
    refused(dir, &with(&["--keypoints", "k.csv", "--baseline", "full-space"]), 2, "cannot be used with");
    refused(dir, &with(&["--keypoints", "missing.csv"]), 1, "missing.csv");
    fs::write(dir.join("broken.csv"), "frame,joint,x\n").unwrap();
    refused(dir, &with(&["--keypoints", "broken.csv"]), 1, "no `y` column");
    // Keypoints of a longer video.
    let mut longer = fs::read_to_string(true_keypoints(dir, &dir.join("video"), "k.csv")).unwrap();
    longer += "999,left_wrist,10,10,1\n";
    fs::write(dir.join("longer.csv"), longer).unwrap();
    refused(dir, &with(&["--keypoints", "longer.csv"]), 1, "keypoints of another video");
}

fn upper_body_mm(dir: &Path, run: &str, video: &str) -> f64 {
    let estimate = imitate::report::read_track(&dir.join(run).join("frames.csv")).unwrap();
    let truth = imitate::report::read_track(&dir.join(video).join("truth.csv")).unwrap();
    let primitives = imitate::report::read_primitives(&dir.join(run).join("summary.json")).unwrap();
    imitate::report::metrics::score(&estimate, &truth, &primitives, 0.5).unwrap().upper_body_mm
}

#[test]
fn the_primitives_filters_halve_the_error_of_the_full_space_baseline_at_the_same_likelihood_budget() {
    let tmp = tempfile::tempdir().unwrap();
    let video = video(tmp.path());
    let vocab = shipped("vocab/default.vocab");
    let frames = video.join("frames");
    // Neither draws anything but the canonical body: the budgets compared
    // are the filters' alone.
    let track = ["track", frames.to_str().unwrap(), "--vocab", vocab.to_str().unwrap(), "--seed", "2"];
    ok(run(tmp.path(), &[&track[..], &["-o", "primitives", "--no-calibrate"]].concat(), "2"));
    ok(run(tmp.path(), &[&track[..], &["-o", "baseline", "--baseline", "full-space"]].concat(), "2"));

    let per_frame =
        |run: &str| summary_without_timing(&tmp.path().join(run))["likelihood_evaluations_per_frame"].as_f64();
    let (primitives, baseline) = (per_frame("primitives").unwrap(), per_frame("baseline").unwrap());
    // The same budget per frame; the primitives also spend once on placing their roots.
    assert!(baseline <= primitives && baseline > 0.9 * primitives, "{baseline} vs {primitives}");
    let table = fs::read_to_string(tmp.path().join("baseline/frames.csv")).unwrap();
    assert!(table.lines().skip(1).all(|l| l.split(',').nth(2) == Some("")), "the baseline names no activity");

    let (ours, theirs) =
        (upper_body_mm(tmp.path(), "primitives", "video"), upper_body_mm(tmp.path(), "baseline", "video"));
    assert!(2.0 * ours < theirs, "primitives {ours:.1} mm, baseline {theirs:.1} mm");
}

#[test]
fn color_frames_are_tracked_at_the_working_size_and_their_silhouettes_scored_against_masks() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let take = shipped("mocap/wave-h.bvh");
    let take = take.to_str().unwrap();
    let vocab = shipped("vocab/default.vocab");
    let vocab = vocab.to_str().unwrap();
    // The same take in color at 320×240 (`color/color`, with the empty
    // scene beside it) and as clean silhouettes, the reference masks.
    ok(run(dir, &["render", take, "-o", "color", "--color", "--size", "320x240"], "2"));
    ok(run(dir, &["render", take, "-o", "clean", "--size", "320x240"], "2"));
    let args = ["track", "color/color", "--vocab", vocab, "-o", "run", "--work-size", "160"];
    ok(run(dir, &args, "2"));
    let summary = summary_without_timing(&dir.join("run"));
    assert_eq!(summary["work_size"], serde_json::json!([160, 120]));
    // The camera stays in the frames' own pixels: the one they were rendered by.
    let camera =
        |path: &str| -> serde_json::Value { serde_json::from_slice(&fs::read(dir.join(path)).unwrap()).unwrap() };
    assert_eq!(camera("run/camera.json"), camera("color/camera.json"));
    ok(run(dir, &["score", "run", "--masks", "clean/frames"], "2"));
    let agreement = camera("run/silhouettes.json");
    assert_eq!(agreement["work_size"], serde_json::json!([160, 120]));
    let iou = agreement["mean_iou"].as_f64().unwrap();
    // 0.94 measured: the person's edge pixels, averaged with the floor by
    // the reduction, fall under the difference threshold about half the time.
    assert!(iou > 0.9, "IoU {iou} against the clean silhouettes");
    // A reference with a mask more than the frames describes another video.
    let longer = dir.join("longer");
    fs::create_dir(&longer).unwrap();
    let mut masks: Vec<PathBuf> = fs::read_dir(dir.join("clean/frames")).unwrap().map(|e| e.unwrap().path()).collect();
    masks.sort();
    for (i, mask) in masks.iter().enumerate() {
        fs::copy(mask, longer.join(format!("{i:06}.png"))).unwrap();
    }
    fs::copy(&masks[0], longer.join(format!("{:06}.png", masks.len()))).unwrap();
    let frames = masks.len();
    let says = format!("{} masks, but color/color has only {frames} frames", frames + 1);
    refused(dir, &["score", "run", "--masks", "longer", "-o", "out"], 1, &says);
    // Masks of another size than the frames.
    ok(run(dir, &["render", take, "-o", "small"], "2"));
    let says = "the masks are 160×120, but the frames of color/color are 320×240";
    refused(dir, &["score", "run", "--masks", "small/frames", "-o", "out"], 1, says);
}

#[test]
fn frames_cut_to_another_scene_are_coasted_and_counted_not_tracked_as_a_person() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let take = shipped("mocap/wave-h.bvh");
    let vocab = shipped("vocab/default.vocab");
    ok(run(dir, &["render", take.to_str().unwrap(), "-o", "color", "--color"], "2"));
    // Frames 20 to 24 cut to another scene: a flat field of another color.
    let cut = image::RgbImage::from_pixel(160, 120, image::Rgb([40, 140, 60]));
    for k in 20..25 {
        cut.save(dir.join(format!("color/color/{k:06}.png"))).unwrap();
    }
    ok(run(dir, &["track", "color/color", "--vocab", vocab.to_str().unwrap(), "-o", "run"], "2"));
    let summary = summary_without_timing(&dir.join("run"));
    assert_eq!(summary["unusable_silhouettes"], 5);
    let frames = fs::read_to_string(dir.join("run/frames.csv")).unwrap();
    let activity = |k: usize| frames.lines().nth(k + 1).unwrap().split(',').nth(2).unwrap().to_string();
    assert!((20..25).all(|k| activity(k).is_empty()), "the cut frames are coasted");
    assert!(!activity(19).is_empty() && !activity(30).is_empty(), "the frames around the cut are tracked");
}

#[test]
fn a_real_clip_cut_short_is_tracked_to_where_it_ends_and_the_run_says_so() {
    let Some(clips) = real_video_dir() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let vocab = shipped("vocab/default.vocab");
    let bytes = fs::read(clips.join("kth_boxing.avi")).unwrap();
    fs::write(dir.join("cut.avi"), &bytes[..bytes.len() / 2]).unwrap();
    let out = imitate()
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .args(["track", "cut.avi", "--vocab", vocab.to_str().unwrap(), "-o", "run"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&ok(out).stderr).to_string();
    let summary = summary_without_timing(&dir.join("run"));
    let decoding = &summary["decoding"];
    let read = decoding["frames_read"].as_u64().unwrap();
    assert_eq!(summary["frames"], read);
    assert_eq!((decoding["ended_early"].as_bool(), decoding["frames_stated"].as_u64()), (Some(true), Some(448)));
    assert!((150..300).contains(&read), "half the file holds about half the frames: {read}");
    let warned = format!("cut.avi: warning: the file ended early: {read} of the 448 frames it states were read");
    assert!(stderr.contains(&warned), "{stderr}");
    let rows = fs::read_to_string(dir.join("run/frames.csv")).unwrap().lines().count() - 1;
    assert_eq!(rows as u64, read);
    // Keypoints of the whole clip, or of the copy, go with it; those of
    // a longer video do not.
    let vocab = vocab.to_str().unwrap();
    for (name, last, used) in [("whole.csv", 447, true), ("copy.csv", read - 1, true), ("other.csv", 459, false)] {
        fs::write(
            dir.join(name),
            format!("frame,joint,x,y,confidence\n0,left_hip,80,60,0.9\n{last},left_hip,80,60,0.9\n"),
        )
        .unwrap();
        let args = ["track", "cut.avi", "--vocab", vocab, "-o", "out", "--keypoints", name];
        if used {
            ok(run(dir, &args, "2"));
            fs::remove_dir_all(dir.join("out")).unwrap();
        } else {
            refused(dir, &args, 1, "other.csv: keypoints of 460 frames, and the video has 448");
        }
    }
    // The whole clip is decoded without complaint.
    fs::write(dir.join("whole.avi"), &bytes).unwrap();
    ok(run(dir, &["track", "whole.avi", "--vocab", vocab, "-o", "whole"], "2"));
    let summary = summary_without_timing(&dir.join("whole"));
    assert_eq!((summary["frames"].as_u64(), &summary["decoding"]), (Some(448), &serde_json::Value::Null));
}

#[test]
fn a_real_runner_who_leaves_and_comes_back_is_coasted_while_gone_and_followed_again() {
    let Some(clips) = real_video_dir() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let clip = clips.join("kth_running.avi");
    let vocab = shipped("vocab/default.vocab");
    ok(run(dir, &["track", clip.to_str().unwrap(), "--vocab", vocab.to_str().unwrap(), "-o", "run"], "2"));
    // The runner crosses the frame again and again, the empty scene between.
    let frames = fs::read_to_string(dir.join("run/frames.csv")).unwrap();
    let named: Vec<bool> = frames.lines().skip(1).map(|l| !l.split(',').nth(2).unwrap().is_empty()).collect();
    let stretches: Vec<usize> = named.split(|&n| !n).map(<[bool]>::len).filter(|&len| len > 0).collect();
    assert!(stretches.len() >= 3 && stretches.iter().all(|&len| len >= 10), "named stretches {stretches:?}");
    let summary = summary_without_timing(&dir.join("run"));
    assert_eq!(summary["frames"], 335);
    assert_eq!(summary["coasted_frames"], named.iter().filter(|&&n| !n).count());
    assert!(summary["coasted_frames"].as_u64().unwrap() > 150, "the scene is empty most of the clip");
    // A coasted frame has no likelihoods.
    let likelihoods = fs::read_to_string(dir.join("run/likelihoods.csv")).unwrap();
    for (line, seen) in likelihoods.lines().skip(1).zip(&named) {
        assert_eq!(line.split(',').nth(1).unwrap().is_empty(), !seen, "{line}");
    }
}

#[test]
fn a_real_scene_without_a_person_is_refused_with_nothing_written() {
    let Some(clips) = real_video_dir() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // kth_running.avi's frames 35–95, between the runner's first two
    // crossings: the field with nobody in it.
    let made = std::process::Command::new("ffmpeg")
        .args(["-v", "error", "-i"])
        .arg(clips.join("kth_running.avi"))
        .args(["-vf", "select='between(n,35,95)'", "-fps_mode", "passthrough", "-c:v", "mpeg4", "-q:v", "2"])
        .arg(dir.join("empty.avi"))
        .status()
        .expect("ffmpeg runs (bash scripts/install-tools.sh ffmpeg)");
    assert!(made.success());
    let vocab = shipped("vocab/default.vocab");
    refused(dir, &["track", "empty.avi", "--vocab", vocab.to_str().unwrap(), "-o", "out"], 2, "pass --camera");
}

/// The share of a run's judged frames its frames.csv calls unexplained.
fn unexplained_share(run: &Path) -> f64 {
    let table = imitate::report::Table::read(&run.join("frames.csv")).unwrap();
    let judged: Vec<f64> =
        table.column("unexplained").unwrap().expect("an unexplained column").into_iter().flatten().collect();
    let summary = summary_without_timing(run);
    let unexplained = judged.iter().filter(|&&v| v == 1.0).count();
    assert_eq!(summary["unexplained_frames"], unexplained);
    unexplained as f64 / judged.len() as f64
}

#[test]
fn an_activity_the_vocabulary_lacks_is_reported_unexplained_and_one_it_holds_is_not() {
    let Some(bandai) = common::shared_mocap_dir("bandai") else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let take = |name: &str| bandai.join(format!("dataset-2_{name}.bvh"));
    // Waving with both hands, energetically, seen as keypoints.
    ok(run(dir, &["render", take("wave-both-hands_active_001").to_str().unwrap(), "-o", "video"], "2"));
    let keypoints = true_keypoints(dir, &dir.join("video"), "keypoints.csv");
    // Vocabularies of walks and runs, and of those and calm waving.
    let gaits = [take("walk_normal_001"), take("run_normal_001")];
    let waves = [take("wave-both-hands_normal_001"), take("wave-both-hands_normal_002")];
    let labels = bandai.join("labels.csv");
    let mut shares = Vec::new();
    for (name, files) in [("gaits", gaits.to_vec()), ("waves", [&gaits[..], &waves[..]].concat())] {
        let vocab = format!("{name}.vocab");
        let mut build: Vec<&str> = vec!["vocab", "build"];
        build.extend(files.iter().map(|f| f.to_str().unwrap()));
        build.extend(["--labels", labels.to_str().unwrap(), "--by-label", "-o", &vocab]);
        ok(run(dir, &build, "2"));
        let args = ["track", "video/frames", "--vocab", &vocab, "-o", name, "--keypoints", keypoints.to_str().unwrap()];
        ok(run(dir, &[&args[..], &["--observe", "keypoints", "--seed", "1"]].concat(), "2"));
        shares.push(unexplained_share(&dir.join(name)));
    }
    eprintln!("unexplained: {:.2} with walks and runs, {:.2} with waves too", shares[0], shares[1]);
    // Measured 0.93 and 0.02 (0.11 to 0.13 with seeds 0, 2 and 3).
    assert!(shares[0] >= 0.7 && shares[1] <= 0.2, "{shares:?}");
    // The report says so.
    ok(run(dir, &["report", "gaits", "-o", "report"], "2"));
    let page = fs::read_to_string(dir.join("report/index.html")).unwrap();
    assert!(page.contains("Open set") && page.contains("were unexplained"), "the report names the open set");
}
