//! `imitate render`: silhouette frames, the camera and the ground truth,
//! color frames and noise, the same bytes every time, and bad input refused
//! with nothing written.

use crate::common;

use common::{imitate, real_mocap_dir};
use imitate::vision::camera::Camera;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

fn mocap(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap").join(name)
}

fn stderr_of(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn render(args: &[&str], dir: &Path) -> Output {
    imitate().current_dir(dir).arg("render").args(args).arg("-q").output().unwrap()
}

/// The files of a folder, sorted by name.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut names: Vec<PathBuf> = fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    names.sort();
    names
}

/// The frames of a render folder as (width, height, pixels).
fn frames(dir: &Path) -> Vec<(u32, u32, Vec<u8>)> {
    files(&dir.join("frames"))
        .iter()
        .map(|p| {
            let img = image::open(p).unwrap().into_luma8();
            (img.width(), img.height(), img.into_raw())
        })
        .collect()
}

/// An RGB PNG's size and pixels; anything but 8-bit RGB fails.
fn rgb(path: &Path) -> (u32, u32, Vec<u8>) {
    let img = image::open(path).unwrap();
    assert_eq!(img.color(), image::ColorType::Rgb8, "{}", path.display());
    let img = img.into_rgb8();
    (img.width(), img.height(), img.into_raw())
}

/// Intersection over union of two silhouettes (0 off the body, 255 on it).
fn iou(a: &[u8], b: &[u8]) -> f64 {
    let both = a.iter().zip(b).filter(|(x, y)| **x > 0 && **y > 0).count();
    let either = a.iter().zip(b).filter(|(x, y)| **x > 0 || **y > 0).count();
    both as f64 / either as f64
}

#[test]
fn a_take_renders_to_silhouettes_with_a_truth_row_and_label_per_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let take = mocap("wave-h.bvh");
    let labels = mocap("labels.csv");
    let out = render(&[take.to_str().unwrap(), "-o", "run", "--labels", labels.to_str().unwrap()], tmp.path());
    assert!(out.status.success(), "{}", stderr_of(&out));
    let run = tmp.path().join("run");
    // 30 Hz source of N frames: (N − 1)/30 s, sampled at 15 Hz from 0.
    let source_frames: usize = fs::read_to_string(&take)
        .unwrap()
        .lines()
        .find_map(|l| l.strip_prefix("Frames:"))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let expected = (source_frames - 1) / 2 + 1;
    let frames = frames(&run);
    assert_eq!(frames.len(), expected);
    for (i, (w, h, pixels)) in frames.iter().enumerate() {
        assert_eq!((*w, *h), (160, 120));
        assert!(pixels.iter().all(|&p| p == 0 || p == 255), "frame {i} is not binary");
        let on = pixels.iter().filter(|&&p| p == 255).count();
        assert!(on > 300 && on < 4000, "frame {i}: {on} body pixels");
    }
    let truth = fs::read_to_string(run.join("truth.csv")).unwrap();
    let rows: Vec<&str> = truth.lines().skip(1).collect();
    assert_eq!(rows.len(), expected);
    assert!(rows.iter().all(|r| r.split(',').nth(2) == Some("wave-h")));
    assert!(rows[3].starts_with("3,0.2,"), "{}", rows[3]);
    let camera = Camera::read(&run.join("camera.json")).unwrap();
    assert_eq!((camera.width(), camera.height()), (160, 120));
}

#[test]
fn rendering_twice_on_one_or_four_threads_gives_the_same_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let take = mocap("punch.bvh");
    for (threads, name) in [("1", "a"), ("4", "b")] {
        let out = imitate()
            .current_dir(tmp.path())
            .env("RAYON_NUM_THREADS", threads)
            .args(["render", take.to_str().unwrap(), "-o", name, "--camera", "overhead", "--size", "96x72", "-q"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr_of(&out));
    }
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    assert_eq!(frames(&a), frames(&b));
    for file in ["truth.csv", "camera.json"] {
        assert_eq!(fs::read(a.join(file)).unwrap(), fs::read(b.join(file)).unwrap(), "{file}");
    }
    for f in files(&a.join("frames")) {
        let same = fs::read(&f).unwrap() == fs::read(b.join("frames").join(f.file_name().unwrap())).unwrap();
        assert!(same, "{}", f.display());
    }
}

#[test]
fn color_frames_show_the_body_over_the_empty_room_of_background_png() {
    let tmp = tempfile::tempdir().unwrap();
    let take = mocap("wave-h.bvh");
    let take = take.to_str().unwrap();
    for (name, extra) in [("color", &["--color"][..]), ("plain", &[]), ("clean", &["--noise", "none"])] {
        let out = render(&[&[take, "-o", name, "--size", "96x72"], extra].concat(), tmp.path());
        assert!(out.status.success(), "{}", stderr_of(&out));
    }
    let (run, clean) = (tmp.path().join("color"), frames(&tmp.path().join("clean")));
    // The silhouettes are the same with or without --color.
    assert_eq!(frames(&run), frames(&tmp.path().join("plain")));
    assert!(!tmp.path().join("plain/color").exists() && !tmp.path().join("plain/background.png").exists());
    let (w, h, background) = rgb(&run.join("background.png"));
    assert_eq!((w, h), (96, 72));
    let colors = files(&run.join("color"));
    assert_eq!(colors.len(), clean.len());
    for (k, (path, (_, _, body))) in colors.iter().zip(&clean).enumerate() {
        assert_eq!(path.file_name().unwrap().to_str().unwrap(), format!("{k:06}.png"));
        let (w, h, pixels) = rgb(path);
        assert_eq!((w, h), (96, 72));
        // Summed over R, G and B, body pixels differ from the room by far
        // more than the sensor's noise, and the rest (the shadow at the
        // feet aside) hardly at all.
        let differ =
            |p: usize| (0..3).map(|c| u32::from(pixels[3 * p + c].abs_diff(background[3 * p + c]))).sum::<u32>();
        let on: Vec<u32> = (0..body.len()).filter(|&p| body[p] > 0).map(differ).collect();
        let off: Vec<u32> = (0..body.len()).filter(|&p| body[p] == 0).map(differ).collect();
        let clear = on.iter().filter(|&&d| d > 60).count();
        assert!(clear as f64 >= 0.98 * on.len() as f64, "frame {k}: {clear} of {} body pixels stand out", on.len());
        let close = off.iter().filter(|&&d| d <= 20).count();
        assert!(close as f64 >= 0.97 * off.len() as f64, "frame {k}: {close} of {} others near the room", off.len());
    }
}

#[test]
fn each_noise_level_spoils_the_silhouette_by_a_bounded_amount() {
    let tmp = tempfile::tempdir().unwrap();
    let take = mocap("punch.bvh");
    // Levels by name or number; heavy also has boxes passing in front.
    for level in ["none", "light", "2", "heavy"] {
        let out = render(&[take.to_str().unwrap(), "-o", level, "--noise", level], tmp.path());
        assert!(out.status.success(), "{}", stderr_of(&out));
    }
    let clean = frames(&tmp.path().join("none"));
    let mut previous = 1.0;
    for (level, low, high) in [("light", 0.9, 0.99), ("2", 0.78, 0.95), ("heavy", 0.6, 0.85)] {
        let spoilt = frames(&tmp.path().join(level));
        assert_eq!(spoilt.len(), clean.len());
        let scores: Vec<f64> = clean.iter().zip(&spoilt).map(|(a, b)| iou(&a.2, &b.2)).collect();
        assert!(spoilt.iter().all(|f| f.2.iter().all(|&p| p == 0 || p == 255)), "{level}: not binary");
        let mean = scores.iter().sum::<f64>() / scores.len() as f64;
        let worst = scores.iter().copied().fold(1.0, f64::min);
        assert!(mean >= low && mean <= high && mean < previous, "{level}: mean IoU {mean}");
        assert!(worst >= low - 0.2, "{level}: worst IoU {worst}");
        previous = mean;
    }
}

#[test]
fn one_seed_gives_the_same_bytes_on_one_or_four_threads_and_another_seed_other_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let take = mocap("twist.bvh");
    for (threads, name, seed) in [("1", "a", "5"), ("4", "b", "5"), ("4", "c", "6")] {
        let out = imitate()
            .current_dir(tmp.path())
            .env("RAYON_NUM_THREADS", threads)
            .args(["render", take.to_str().unwrap(), "-o", name, "--size", "96x72", "--color", "--noise", "heavy"])
            .args(["--seed", seed, "-q"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr_of(&out));
    }
    let (a, b, c) = (tmp.path().join("a"), tmp.path().join("b"), tmp.path().join("c"));
    let every = |dir: &Path| {
        let mut all = files(dir);
        all.extend(files(&dir.join("frames")));
        all.extend(files(&dir.join("color")));
        all.retain(|p| p.is_file());
        all
    };
    let (ours, theirs) = (every(&a), every(&b));
    assert_eq!(ours.len(), theirs.len());
    assert!(ours.len() > 2 * 170, "{} files", ours.len());
    for (x, y) in ours.iter().zip(&theirs) {
        assert_eq!(x.strip_prefix(&a).unwrap(), y.strip_prefix(&b).unwrap());
        assert!(fs::read(x).unwrap() == fs::read(y).unwrap(), "{}", x.display());
    }
    // Another seed: another room and other noise in every frame.
    assert_ne!(fs::read(a.join("background.png")).unwrap(), fs::read(c.join("background.png")).unwrap());
    let (first, second) = (frames(&a), frames(&c));
    assert!(first.iter().zip(&second).all(|(x, y)| x != y));
}

#[test]
fn a_camera_json_is_used_as_written() {
    let tmp = tempfile::tempdir().unwrap();
    let take = mocap("circles.bvh");
    let first = render(&[take.to_str().unwrap(), "-o", "side", "--camera", "side", "--size", "64x48"], tmp.path());
    assert!(first.status.success(), "{}", stderr_of(&first));
    let again = tmp.path().join("side/camera.json");
    let second = render(&[take.to_str().unwrap(), "-o", "again", "--camera", again.to_str().unwrap()], tmp.path());
    assert!(second.status.success(), "{}", stderr_of(&second));
    assert_eq!(frames(&tmp.path().join("side")), frames(&tmp.path().join("again")));
}

#[test]
fn real_captures_render_from_every_preset() {
    let Some(real) = real_mocap_dir() else { return };
    let tmp = tempfile::tempdir().unwrap();
    for (file, camera) in [("walking.bvh", "side"), ("jumping_jacks.bvh", "front"), ("wave_hello.bvh", "overhead")] {
        let take = real.join(file);
        let out = render(&[take.to_str().unwrap(), "-o", camera, "--camera", camera], tmp.path());
        assert!(out.status.success(), "{file}: {}", stderr_of(&out));
        for (i, (_, _, pixels)) in frames(&tmp.path().join(camera)).iter().enumerate() {
            assert!(pixels.iter().filter(|&&p| p == 255).count() > 100, "{file} frame {i} shows no body");
        }
    }
}

/// A truth.csv's column by name, one value per frame.
fn column(truth: &str, name: &str) -> Vec<f64> {
    let mut lines = truth.lines();
    let at = lines.next().unwrap().split(',').position(|c| c == name).unwrap();
    lines.map(|l| l.split(',').nth(at).unwrap().parse().unwrap()).collect()
}

#[test]
fn a_test_body_performs_the_take_on_its_own_skeleton_and_says_who_it_is() {
    let tmp = tempfile::tempdir().unwrap();
    let take = mocap("wave-h.bvh");
    let take = take.to_str().unwrap();
    for (name, body) in [("capsules", "capsules"), ("heavy", "heavy"), ("lanky", "lanky")] {
        let out = render(&[take, "-o", name, "--body", body, "--noise", "none", "--color"], tmp.path());
        assert!(out.status.success(), "{body}: {}", stderr_of(&out));
    }
    let dir = |name: &str| tmp.path().join(name);
    assert!(!dir("capsules").join("body.toml").exists());
    let heavy = imitate::vision::figure::Build::load(&dir("heavy").join("body.toml")).unwrap();
    assert_eq!(heavy, imitate::vision::figure::Build::preset("heavy").unwrap());
    let truth = |name: &str| fs::read_to_string(dir(name).join("truth.csv")).unwrap();
    // Every angle kept, the skeleton the build's: the head sits as high as
    // the build is tall, and the waving hand's path shrinks or grows with it.
    let head = |name: &str| column(&truth(name), "head_y")[0];
    assert!(head("heavy") < head("capsules") && head("capsules") < head("lanky"));
    assert!((head("heavy") / head("lanky") - 1.60 / 1.95).abs() < 0.02, "{} {}", head("heavy"), head("lanky"));
    assert_eq!(column(&truth("heavy"), "left_elbow_angle"), column(&truth("capsules"), "left_elbow_angle"));
    // The heavy build covers more of the frame for its height than the
    // capsules, the lanky less.
    let cover = |name: &str| {
        let area: usize = frames(&dir(name)).iter().map(|f| f.2.iter().filter(|&&p| p == 255).count()).sum();
        area as f64 / head(name).powi(2)
    };
    let (c, h, l) = (cover("capsules"), cover("heavy"), cover("lanky"));
    assert!(h > 1.15 * c && l < c, "cover: capsules {c}, heavy {h}, lanky {l}");
    assert_eq!(files(&dir("heavy").join("color")).len(), frames(&dir("heavy")).len());
}

/// Runs a render that must fail: `code`, one error line holding `says`,
/// and no file left in the working folder beyond what was there.
fn refused(dir: &Path, args: &[&str], code: i32, says: &str) {
    let before: Vec<_> = fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    let out = render(args, dir);
    let err = stderr_of(&out);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    assert!(err.contains(says) && !err.contains("panicked"), "{args:?}: {err}");
    let after: Vec<_> = fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(before.len(), after.len(), "{args:?} left files: {after:?}");
}

#[test]
fn bad_input_is_refused_with_nothing_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let take = mocap("twist.bvh");
    let take = take.to_str().unwrap();
    refused(dir, &["missing.bvh", "-o", "out"], 1, "missing.bvh");
    fs::write(dir.join("broken.bvh"), "HIERARCHY\nROOT Hips\n{\n").unwrap();
    refused(dir, &["broken.bvh", "-o", "out"], 1, "broken.bvh");
    refused(dir, &[mocap("").to_str().unwrap(), "-o", "out"], 1, "is a folder");
    refused(dir, &[take, "-o", "out", "--size", "160by120"], 2, "WIDTHxHEIGHT");
    refused(dir, &[take, "-o", "out", "--size", "0x120"], 2, "`width` is 0");
    refused(dir, &[take, "-o", "out", "--fps", "0"], 2, "--fps 0");
    refused(dir, &[take, "-o", "out", "--camera", "fisheye"], 2, "neither a preset");
    refused(dir, &[take, "-o", "out", "--noise", "loud"], 2, "--noise");
    refused(dir, &[take, "-o", "out", "--noise", "4"], 2, "expected none, light, medium or heavy");
    refused(dir, &[take, "-o", "out", "--body", "giant"], 2, "no body named `giant`");
    refused(dir, &[take, "-o", "out", "--body", "nobody.toml"], 1, "nobody.toml: cannot read");
    fs::write(dir.join("tall.toml"), "name = \"tall\"\nheight_m = 2.6\ngirth = 1\narm_share = 1\nleg_share = 1\nhair = \"none\"\nclothing = \"fitted\"\n").unwrap();
    refused(dir, &[take, "-o", "out", "--body", "tall.toml"], 1, "tall.toml: `height_m` is 2.6; it must be 1 to 2.3");
    let mut spec = Camera::preset(imitate::vision::camera::Preset::Front, 160, 120).unwrap().spec().clone();
    spec.up = [0.0, 0.0, 1.0];
    fs::write(dir.join("along.json"), serde_json::to_string(&spec).unwrap()).unwrap();
    refused(dir, &[take, "-o", "out", "--camera", "along.json"], 1, "along.json: the camera looks straight along `up`");
    fs::write(dir.join("partial.json"), r#"{"width": 160, "height": 120}"#).unwrap();
    refused(dir, &[take, "-o", "out", "--camera", "partial.json"], 1, "missing field `fx`");
    fs::create_dir(dir.join("taken")).unwrap();
    fs::write(dir.join("taken/keep.txt"), "mine").unwrap();
    refused(dir, &[take, "-o", "taken"], 1, "exists and is not empty");
    assert_eq!(fs::read_to_string(dir.join("taken/keep.txt")).unwrap(), "mine");
}
