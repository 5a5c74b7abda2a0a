//! Speed of the mocap pipeline against the targets:
//!
//! - `parse/1-core`: BVH text parsed on one core (target ≥ 150 MB/s);
//! - `read+retarget/2-cores`: parse, analyse and retarget on two cores
//!   (target ≥ 200,000 frames/s for the 31-joint, 96-channel CMU skeleton);
//! - `write/canonical`: canonical BVH written to memory (reported only);
//! - `read_folder/positions` (only when `IMITATE_MOCAP_DIR` is set): every
//!   `.bvh` file of that folder read from disk, one after the other, and
//!   put on the canonical body, then every frame's joint positions
//!   (frames × 17 × 3): what the Python package's `read_bvh(path)` and
//!   `positions()` do, the reference of `scripts/python-bench.sh`.
//!
//! The input is a CMU-like take generated here, so the benchmark runs
//! without the real captures (they live outside the repository). Criterion
//! reports the numbers; nothing here asserts a wall-clock time.

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main};
use imitate::mocap::bvh::{Bvh, read_bvh_bytes, write_bvh};
use imitate::mocap::retarget::{RetargetOptions, Retargeter};
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Duration;

/// 20,000 frames of 96 channels is about 14 MB of text: one parse takes
/// tens of milliseconds, long enough to time, short enough for ten samples.
const FRAMES: usize = 20_000;
/// CMU captures are 120 Hz.
const FRAME_TIME: &str = ".0083333";
const NAME: &str = "cmu-like.bvh";

/// One joint of the generated skeleton in declaration order: nesting depth
/// (the root is 0), name, offset from the parent, and its `End Site`.
type JointSpec = (usize, &'static str, [f64; 3], Option<[f64; 3]>);

/// A 31-joint CMU-style skeleton in inch-like units, T-pose, Y up, facing
/// +Z: legs hang down −Y, the spine rises +Y, the arms reach along ±X.
/// Collars and hip joints keep CMU's zero-length links.
const SKELETON: &[JointSpec] = &[
    (0, "Hips", [0.0, 0.0, 0.0], None),
    (1, "LHipJoint", [0.0, 0.0, 0.0], None),
    (2, "LeftHip", [1.6183, -1.8047, 0.6941], None),
    (3, "LeftKnee", [0.0, -7.4821, 0.0], None),
    (4, "LeftAnkle", [0.0, -7.3519, -0.1127], None),
    (5, "LeftToe", [0.0, -0.6603, 2.1286], Some([0.0, 0.0, 1.1052])),
    (1, "RHipJoint", [0.0, 0.0, 0.0], None),
    (2, "RightHip", [-1.5942, -1.8047, 0.6941], None),
    (3, "RightKnee", [0.0, -7.5138, 0.0], None),
    (4, "RightAnkle", [0.0, -7.3306, -0.1127], None),
    (5, "RightToe", [0.0, -0.6489, 2.1173], Some([0.0, 0.0, 1.1109])),
    (1, "lowerback", [0.0, 0.0, 0.0], None),
    (2, "Chest", [-0.0211, 2.0757, -0.1698], None),
    (3, "Chest2", [0.0507, 2.0844, -0.0314], None),
    (4, "lowerneck", [0.0, 0.0, 0.0], None),
    (5, "Neck", [-0.1073, 1.6041, 0.3137], None),
    (6, "Head", [0.0841, 1.6568, -0.3082], Some([0.0391, 1.6915, -0.1415])),
    (5, "LeftCollar", [0.0, 0.0, 0.0], None),
    (6, "LeftShoulder", [3.5232, 0.7322, -0.5469], None),
    (7, "LeftElbow", [5.3246, 0.0, 0.0], None),
    (8, "LeftWrist", [3.4840, 0.0, 0.0], None),
    (9, "lhand", [0.0, 0.0, 0.0], None),
    (10, "LFingers", [0.5725, 0.0, 0.0], Some([0.4615, 0.0, 0.0])),
    (9, "LThumb", [0.0, 0.0, 0.0], Some([0.3314, 0.0, 0.4686])),
    (5, "RightCollar", [0.0, 0.0, 0.0], None),
    (6, "RightShoulder", [-3.4177, 0.9359, -0.1002], None),
    (7, "RightElbow", [-5.3359, 0.0, 0.0], None),
    (8, "RightWrist", [-3.6413, 0.0, 0.0], None),
    (9, "rhand", [0.0, 0.0, 0.0], None),
    (10, "RFingers", [-0.7348, 0.0, 0.0], Some([-0.5924, 0.0, 0.0])),
    (9, "RThumb", [0.0, 0.0, 0.0], Some([-0.4253, 0.0, 0.6015])),
];

/// The `HIERARCHY` section for `SKELETON`, tab-indented like CMU exports.
fn hierarchy() -> String {
    let mut text = String::from("HIERARCHY\n");
    // Joints whose `{` block is still open; a shallower joint closes them.
    let mut open = 0;
    for &(depth, name, [x, y, z], end_site) in SKELETON {
        while open > depth {
            open -= 1;
            writeln!(text, "{}}}", "\t".repeat(open)).unwrap();
        }
        let pad = "\t".repeat(depth);
        let (keyword, channels) = if depth == 0 {
            ("ROOT", "6 Xposition Yposition Zposition Zrotation Yrotation Xrotation")
        } else {
            ("JOINT", "3 Zrotation Xrotation Yrotation")
        };
        writeln!(text, "{pad}{keyword} {name}\n{pad}{{").unwrap();
        writeln!(text, "{pad}\tOFFSET {x:.5} {y:.5} {z:.5}").unwrap();
        writeln!(text, "{pad}\tCHANNELS {channels}").unwrap();
        if let Some([ex, ey, ez]) = end_site {
            writeln!(text, "{pad}\tEnd Site\n{pad}\t{{\n{pad}\t\tOFFSET {ex:.5} {ey:.5} {ez:.5}\n{pad}\t}}").unwrap();
        }
        open = depth + 1;
    }
    while open > 0 {
        open -= 1;
        writeln!(text, "{}}}", "\t".repeat(open)).unwrap();
    }
    text
}

/// The value of channel `c` in frame `f`: a walk-like drift for the root
/// position, and for rotations three sines per channel whose frequencies
/// and phases differ by channel, so no two columns or frames repeat and the
/// digits vary the way captured angles do (up to about ±30°).
fn channel_value(c: usize, f: usize) -> f64 {
    let t = f as f64 / 120.0;
    let k = c as f64;
    match c {
        0 => 6.0 * (0.05 * t).sin() + 0.8 * (1.9 * t).sin(),
        1 => 17.7 + 0.4 * (2.0 * std::f64::consts::PI * 1.1 * t).sin(),
        2 => 0.02 * t + 0.8 * (1.7 * t + 0.4).cos(),
        _ => {
            // Golden-ratio phases keep the channels out of step.
            let phase = k * 1.618_034;
            let bias = 8.0 * (k * 0.7).sin();
            bias + 16.0 * (t * (1.3 + 0.011 * k) + phase).sin()
                + 7.0 * (t * (3.1 + 0.023 * k) + 2.0 * phase).sin()
                + 1.5 * (t * (9.7 + 0.05 * k) + 3.0 * phase).sin()
        }
    }
}

/// A complete CMU-like BVH file: `SKELETON` and `FRAMES` frames written
/// with four decimals, space separated, as common exporters write them.
fn cmu_like_bvh() -> Vec<u8> {
    let channels = 6 + 3 * (SKELETON.len() - 1);
    let mut text = hierarchy();
    writeln!(text, "MOTION\nFrames: {FRAMES}\nFrame Time: {FRAME_TIME}").unwrap();
    text.reserve(FRAMES * channels * 9);
    for f in 0..FRAMES {
        for c in 0..channels {
            let sep = if c == 0 { "" } else { " " };
            write!(text, "{sep}{:.4}", channel_value(c, f)).unwrap();
        }
        text.push('\n');
    }
    text.into_bytes()
}

fn pool(threads: usize) -> ThreadPool {
    ThreadPoolBuilder::new().num_threads(threads).build().expect("cannot start a rayon thread pool")
}

/// Parses the generated file and checks it is what the targets are about:
/// 31 joints, 96 channels, every frame, no warnings, mapped by the CMU table.
fn checked_input(text: &[u8]) -> (Bvh, Retargeter) {
    let bvh = read_bvh_bytes(text, NAME).expect("the generated BVH does not parse");
    assert_eq!(bvh.skeleton.joints.len(), 31);
    assert_eq!(bvh.channel_count(), 96);
    assert_eq!(bvh.frames, FRAMES);
    assert!(bvh.warnings.is_empty(), "warnings: {:?}", bvh.warnings);
    let retargeter =
        Retargeter::new(&bvh, &RetargetOptions::default()).expect("the generated CMU-like skeleton does not retarget");
    assert_eq!(retargeter.analysis().scheme, "cmu");
    (bvh, retargeter)
}

/// Each iteration is 50–150 ms, so ten samples over a few seconds give a
/// stable median while the whole run stays well under two minutes.
fn settle(group: &mut BenchmarkGroup<'_, WallTime>) {
    group.sample_size(10).warm_up_time(Duration::from_secs(2)).measurement_time(Duration::from_secs(6));
}

fn mocap(c: &mut Criterion) {
    let text = cmu_like_bvh();
    let (bvh, retargeter) = checked_input(&text);
    let one = pool(1);
    let two = pool(2);
    let frames = Throughput::Elements(FRAMES as u64);

    let mut group = c.benchmark_group("parse");
    settle(&mut group);
    // Decimal bytes, so criterion prints MB/s, the unit the target is in.
    group.throughput(Throughput::BytesDecimal(text.len() as u64));
    // `install` per iteration costs microseconds against a ~100 ms parse,
    // and keeps the timing on the caller's thread.
    group.bench_function("1-core", |b| b.iter(|| one.install(|| read_bvh_bytes(black_box(&text), NAME).unwrap())));
    group.bench_function("2-cores", |b| b.iter(|| two.install(|| read_bvh_bytes(black_box(&text), NAME).unwrap())));
    group.finish();

    let mut group = c.benchmark_group("read+retarget");
    settle(&mut group);
    group.throughput(frames.clone());
    // Everything a user waits for between a file and canonical poses:
    // parse, mapping and calibration, then every frame.
    group.bench_function("2-cores", |b| {
        b.iter(|| {
            two.install(|| {
                let bvh = read_bvh_bytes(black_box(&text), NAME).unwrap();
                let r = Retargeter::new(&bvh, &RetargetOptions::default()).unwrap();
                r.retarget(&bvh)
            })
        })
    });
    group.finish();

    let mut group = c.benchmark_group("retarget");
    settle(&mut group);
    group.throughput(frames);
    // The per-frame solve alone; the difference from `read+retarget` is
    // parsing plus `Retargeter::new`.
    group.bench_function("2-cores", |b| b.iter(|| two.install(|| retargeter.retarget(black_box(&bvh)))));
    group.finish();

    // The canonical file the pipeline hands on; its size (six decimals, the
    // canonical joint set) differs from the input's, so measure its bytes.
    let canonical = two.install(|| retargeter.retarget(&bvh)).to_bvh();
    let mut out = Vec::new();
    write_bvh(&canonical, &mut out).unwrap();
    let written = out.len();
    // The sizes behind the throughputs, for the record.
    eprintln!(
        "input: {} bytes, {FRAMES} frames x {} channels; canonical output: {written} bytes",
        text.len(),
        bvh.channel_count()
    );

    let mut group = c.benchmark_group("write");
    settle(&mut group);
    group.throughput(Throughput::BytesDecimal(written as u64));
    group.bench_function("canonical", |b| {
        // Reuse the buffer so the timing is formatting, not reallocation.
        b.iter(|| {
            out.clear();
            write_bvh(black_box(&canonical), &mut out).unwrap();
            black_box(out.len())
        })
    });
    group.finish();
}

/// `read_folder/positions`: the files of `IMITATE_MOCAP_DIR`, read and
/// retargeted as `imitate retarget` reads them, and forward kinematics for
/// every frame, the joint positions flattened into one array per file as
/// `Motion.positions()` gives them.
fn read_folder(c: &mut Criterion) {
    use imitate::mocap::bvh::read_bvh;
    let Ok(dir) = std::env::var("IMITATE_MOCAP_DIR") else { return };
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|entry| entry.expect("a folder entry").path())
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")))
        .collect();
    files.sort();
    let read = |path: &std::path::Path| {
        let bvh = read_bvh(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let retargeter =
            Retargeter::new(&bvh, &RetargetOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let motion = retargeter.retarget(&bvh);
        let positions: Vec<f64> = motion
            .poses
            .iter()
            .flat_map(|p| motion.body.forward(p).positions.into_iter().flat_map(|v| v.to_array()))
            .collect();
        positions
    };
    let frames: usize = files.iter().map(|f| read(f).len() / (imitate::mocap::body::JOINTS * 3)).sum();
    eprintln!("{dir}: {} files, {frames} frames", files.len());
    let mut group = c.benchmark_group("read_folder");
    group.sampling_mode(criterion::SamplingMode::Flat).sample_size(10).warm_up_time(Duration::from_secs(1));
    group.throughput(Throughput::Elements(frames as u64));
    group.bench_function("positions", |b| b.iter(|| files.iter().map(|f| black_box(read(f)).len()).sum::<usize>()));
    group.finish();
}

criterion_group!(benches, mocap, read_folder);
criterion_main!(benches);
