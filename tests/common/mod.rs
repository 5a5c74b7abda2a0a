//! Helpers shared by the integration tests. Each test crate uses some.
#![allow(dead_code)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// `../shared/mocap/real`, the real captures every stage is tested on.
/// Absent outside CI, the caller skips (and says so); under CI (the `CI`
/// variable set) its absence fails the test.
pub fn real_mocap_dir() -> Option<PathBuf> {
    shared_mocap_dir("real")
}

/// `../shared/mocap/CORPUS` (`real`, `bandai`, `m21`): absent outside CI,
/// the caller skips (and says so); under CI its absence fails the test.
pub fn shared_mocap_dir(corpus: &str) -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/mocap").join(corpus);
    if dir.is_dir() {
        return Some(dir);
    }
    assert!(std::env::var_os("CI").is_none(), "{} is missing: under CI the real captures are required", dir.display());
    eprintln!("skipping: {} is absent (under CI this fails)", dir.display());
    None
}

/// `../shared/video/real`, the real clips: absent outside CI, the caller
/// skips (and says so); under CI its absence fails the test.
pub fn real_video_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/video/real");
    if dir.join("labels.csv").is_file() {
        return Some(dir);
    }
    assert!(std::env::var_os("CI").is_none(), "{} is missing: under CI the real clips are required", dir.display());
    eprintln!("skipping: {} is absent (under CI this fails)", dir.display());
    None
}

/// Every `.bvh` file of the real captures, sorted by name; empty when the
/// folder is absent outside CI.
pub fn real_bvh_files() -> Vec<PathBuf> {
    shared_bvh_files("real")
}

/// How many takes each corpus of `../shared/mocap` holds at least.
fn expected_takes(corpus: &str) -> usize {
    match corpus {
        "real" => 20,
        "bandai" => 300,
        _ => 10,
    }
}

/// Every `.bvh` file of `../shared/mocap/CORPUS`, sorted by name; empty when
/// the folder is absent outside CI.
pub fn shared_bvh_files(corpus: &str) -> Vec<PathBuf> {
    let Some(dir) = shared_mocap_dir(corpus) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("the real captures folder is readable")
        .map(|e| e.expect("directory entries are readable").path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    assert!(files.len() >= expected_takes(corpus), "expected the real captures in {}", dir.display());
    files
}

/// Debian's headless browser, for the report tests. Absent outside CI, the
/// caller skips (and says so); under CI its absence fails the test, since
/// `bash scripts/test.sh` installs it.
pub fn chromium() -> Option<PathBuf> {
    let found = std::env::var_os("PATH")
        .into_iter()
        .flat_map(|paths| std::env::split_paths(&paths).collect::<Vec<_>>())
        .map(|dir| dir.join("chromium"))
        .find(|p| p.is_file());
    if found.is_none() {
        assert!(std::env::var_os("CI").is_none(), "chromium is not on PATH: under CI it is required");
        eprintln!("skipping the browser check: chromium is not on PATH (bash scripts/install-tools.sh chromium)");
    }
    found
}

/// The `imitate` binary built for these tests.
pub fn imitate() -> Command {
    Command::new(env!("CARGO_BIN_EXE_imitate"))
}

/// Hips (3 position channels) and Chest (3 rotation channels). Line 9 is
/// Chest's CHANNELS, line 16 MOTION, 17 `Frames:`, 18 `Frame Time:`, and
/// frame n is line 18 + n.
pub fn hips_chest(chest_offset: &str, chest_channels: &str, motion: &str) -> String {
    format!(
        "HIERARCHY
ROOT Hips
{{
  OFFSET 0 0 0
  CHANNELS 3 Xposition Yposition Zposition
  JOINT Chest
  {{
    OFFSET {chest_offset}
    CHANNELS {chest_channels}
    End Site
    {{
      OFFSET 0 5 0
    }}
  }}
}}
MOTION
{motion}"
    )
}

/// [`hips_chest`] with Chest at `0 10 0` rotating `Zrotation Xrotation Yrotation`.
pub fn hips_chest_text(motion: &str) -> String {
    hips_chest("0 10 0", "3 Zrotation Xrotation Yrotation", motion)
}

/// Opens the page in headless Chromium: every image must load, the console
/// must stay silent, and a screenshot (`screenshot`, in the tests' target
/// folder) is kept to look at.
pub fn browser_check(page: &Path, screenshot: &str) {
    let Some(chromium) = chromium() else { return };
    let url = format!("file://{}", page.display());
    let browser = |extra: &[&str]| {
        let out = Command::new(&chromium)
            .args(["--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--virtual-time-budget=5000"])
            .args(["--enable-logging=stderr", "--v=0"])
            .args(extra)
            .arg(&url)
            .output()
            .unwrap();
        assert!(out.status.success(), "chromium failed: {}", String::from_utf8_lossy(&out.stderr));
        out
    };
    let out = browser(&["--dump-dom"]);
    let dom = String::from_utf8_lossy(&out.stdout);
    assert!(dom.contains("<body data-images-ok=\"true\">"), "not every image loaded: {}", &dom[..dom.len().min(400)]);
    let log = String::from_utf8_lossy(&out.stderr);
    let console: Vec<&str> = log.lines().filter(|l| l.contains("CONSOLE")).collect();
    assert!(console.is_empty(), "the page wrote to the console: {console:?}");

    let shot = Path::new(env!("CARGO_TARGET_TMPDIR")).join(screenshot);
    let _ = fs::remove_file(&shot);
    browser(&[&format!("--screenshot={}", shot.display()), "--window-size=1100,1400"]);
    let image = image::open(&shot).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (1100, 1400));
    // Figure 8 is drawn: its colored markers and shading fill part of the view.
    let colored = image.pixels().filter(|p| p.0.iter().max().unwrap() - p.0.iter().min().unwrap() > 60).count();
    assert!(colored > 5000, "{colored} colored pixels in {}", shot.display());
    eprintln!("screenshot: {}", shot.display());
}
