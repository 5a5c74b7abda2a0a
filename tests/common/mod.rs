//! Helpers shared by the integration tests. Each test crate uses some.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

/// `../shared/mocap/real`, the real captures every stage is tested on.
/// Absent outside CI, the caller skips (and says so); under CI (the `CI`
/// variable set) its absence fails the test.
pub fn real_mocap_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/mocap/real");
    if dir.is_dir() {
        return Some(dir);
    }
    assert!(std::env::var_os("CI").is_none(), "{} is missing: under CI the real captures are required", dir.display());
    eprintln!("skipping: {} is absent (under CI this fails)", dir.display());
    None
}

/// Every `.bvh` file of the real captures, sorted by name; empty when the
/// folder is absent outside CI.
pub fn real_bvh_files() -> Vec<PathBuf> {
    let Some(dir) = real_mocap_dir() else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("the real captures folder is readable")
        .map(|e| e.expect("directory entries are readable").path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    assert!(files.len() >= 20, "expected the real captures in {}", dir.display());
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
