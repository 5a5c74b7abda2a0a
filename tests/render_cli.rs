//! `imitate render`: silhouette frames, the camera and the ground truth,
//! the same bytes every time, and bad input refused with nothing written.

mod common;

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

/// The frames of a render folder as (width, height, pixels).
fn frames(dir: &Path) -> Vec<(u32, u32, Vec<u8>)> {
    let mut names: Vec<PathBuf> = fs::read_dir(dir.join("frames")).unwrap().map(|e| e.unwrap().path()).collect();
    names.sort();
    names
        .iter()
        .map(|p| {
            let img = image::open(p).unwrap().into_luma8();
            (img.width(), img.height(), img.into_raw())
        })
        .collect()
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
    let files: Vec<_> = fs::read_dir(a.join("frames")).unwrap().map(|e| e.unwrap().path()).collect();
    for f in files {
        let same = fs::read(&f).unwrap() == fs::read(b.join("frames").join(f.file_name().unwrap())).unwrap();
        assert!(same, "{}", f.display());
    }
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
