//! Reading a 200 MB BVH file needs at most twice the memory of its decoded
//! values. Measured in a separate `imitate inspect --timing` process, whose
//! peak resident memory no other test shares.

use crate::common;

use imitate::mocap::bvh::write_bvh;
use imitate::mocap::synth::{Activity, SynthOptions, activity_take};
use std::io::{BufWriter, Write};

#[cfg(target_os = "linux")]
#[test]
fn reading_200_megabytes_peaks_below_twice_the_decoded_values() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.bvh");
    // A canonical take's frames repeated to 200 MB, with a truthful count.
    let take = activity_take(Activity::Twist, &SynthOptions { fps: 120.0, ..Default::default() });
    let mut text = Vec::new();
    write_bvh(&take.motion.to_bvh(), &mut text).unwrap();
    let text = String::from_utf8(text).unwrap();
    let motion_at = text.find("MOTION\n").unwrap();
    let frames: String = text[motion_at..].lines().skip(3).map(|l| format!("{l}\n")).collect();
    let per_copy = take.motion.poses.len();
    let copies = 200_000_000 / frames.len() + 1;
    let mut out = BufWriter::with_capacity(1 << 20, std::fs::File::create(&path).unwrap());
    write!(out, "{}MOTION\nFrames: {}\nFrame Time: {}\n", &text[..motion_at], per_copy * copies, 1.0 / 120.0).unwrap();
    for _ in 0..copies {
        out.write_all(frames.as_bytes()).unwrap();
    }
    out.flush().unwrap();
    drop(out);
    assert!(std::fs::metadata(&path).unwrap().len() >= 200_000_000);

    let run = common::imitate().args(["inspect", "--timing", "--json", path.to_str().unwrap()]).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let report: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert_eq!(report[0]["frames"].as_u64().unwrap() as usize, per_copy * copies);
    let decoded_mb = report[0]["timing"]["decoded_mb"].as_f64().unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    let peak_mb: f64 = stderr
        .split("peak resident memory ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no peak memory in: {stderr}"));
    eprintln!("peak {peak_mb:.1} MB for {decoded_mb:.1} MB of decoded values");
    assert!(peak_mb <= 2.0 * decoded_mb, "peak {peak_mb:.1} MB for {decoded_mb:.1} MB decoded");
}
