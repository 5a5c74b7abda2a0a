//! Background subtraction recovers the true silhouette from `render --color`
//! output: the frames' silhouettes, extracted against `background.png`,
//! match the clean render (`--noise none`) with mean IoU ≥ 0.95 at the
//! default noise and ≥ 0.85 at the heaviest, on a synthetic take and on
//! real captures, from every preset camera. On real clips where the person
//! never leaves the frame, a background learned from the frames finds them
//! in every frame.

use crate::common;

use common::{imitate, real_mocap_dir, real_video_dir};
use imitate::vision::frames::{Expect, FrameSource, read_image};
use imitate::vision::mask::Mask;
use imitate::vision::silhouette::{ExtractParams, Extractor, Silhouettes};
use std::path::{Path, PathBuf};

fn render(take: &Path, dir: &Path, camera: &str, extra: &[&str]) {
    let out = imitate()
        .arg("render")
        .arg(take)
        .arg("-o")
        .arg(dir)
        .args(["--camera", camera, "-q"])
        .args(extra)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}: {}", take.display(), String::from_utf8_lossy(&out.stderr));
}

/// The masks of a folder of frames, in order.
fn masks(folder: &Path, expect: Expect, extractor: &mut Extractor) -> Vec<Mask> {
    let source = FrameSource::open(folder, expect).unwrap();
    source.map(|frame| extractor.extract(&frame.unwrap()).unwrap()).collect()
}

/// (mean, worst) IoU over the frames of `take` rendered in color at `noise`
/// and extracted against the rendered background.
fn recovery(take: &Path, camera: &str, noise: &str, work: &Path) -> (f64, f64) {
    let name = format!("{}-{camera}", take.file_stem().unwrap().to_string_lossy());
    let (clean, noisy) = (work.join(format!("{name}-clean")), work.join(format!("{name}-{noise}")));
    if !clean.exists() {
        render(take, &clean, camera, &["--noise", "none"]);
    }
    render(take, &noisy, camera, &["--color", "--noise", noise, "--seed", "3"]);
    let mut extractor = Extractor::new(ExtractParams::default()).unwrap();
    let truth = masks(&clean.join("frames"), Expect::Silhouettes, &mut extractor);
    extractor.set_background(&read_image(&noisy.join("background.png")).unwrap());
    let found = masks(&noisy.join("color"), Expect::Color, &mut extractor);
    assert_eq!(truth.len(), found.len());
    let scores: Vec<f64> = truth.iter().zip(&found).map(|(t, f)| t.iou(f)).collect();
    let mean = scores.iter().sum::<f64>() / scores.len() as f64;
    let worst = scores.iter().copied().fold(1.0, f64::min);
    eprintln!("{name} at {noise}: mean IoU {mean:.3}, worst frame {worst:.3}, {} frames", scores.len());
    (mean, worst)
}

fn check(takes: &[PathBuf]) {
    let work = tempfile::tempdir().unwrap();
    for take in takes {
        for camera in ["front", "side", "overhead"] {
            let (light, _) = recovery(take, camera, "light", work.path());
            assert!(light >= 0.95, "{} from {camera}, light noise: mean IoU {light:.3}", take.display());
            let (heavy, _) = recovery(take, camera, "heavy", work.path());
            assert!(heavy >= 0.85, "{} from {camera}, heavy noise: mean IoU {heavy:.3}", take.display());
        }
    }
}

#[test]
fn silhouettes_of_synthetic_color_renders_are_recovered_at_every_noise_level() {
    let shipped = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("mocap");
    check(&[shipped.join("wave-h.bvh"), shipped.join("punch.bvh")]);
}

#[test]
fn silhouettes_of_real_captures_rendered_in_color_are_recovered_at_every_noise_level() {
    let Some(real) = real_mocap_dir() else { return };
    check(&[real.join("boxing.bvh"), real.join("two_hand_wave.bvh"), real.join("jumping_jacks.bvh")]);
}

/// The rows from the person's top to their feet, in every frame of `clip`'s
/// silhouettes at a working width of 320.
fn heights(clip: &Path) -> Vec<usize> {
    let source = FrameSource::open(clip, Expect::Auto).unwrap();
    let mut silhouettes = Silhouettes::new(clip, source, None, 320);
    let mut mask = Mask::new(1, 1);
    let mut heights = Vec::new();
    while let Some(read) = silhouettes.next_into(&mut mask) {
        read.unwrap();
        let rows: Vec<usize> = (0..mask.height()).filter(|&y| (0..mask.width()).any(|x| mask.get(x, y))).collect();
        heights.push(rows.last().map_or(0, |last| last + 1 - rows[0]));
    }
    heights
}

#[test]
fn a_person_who_never_leaves_a_real_clip_is_found_whole_in_every_frame() {
    let Some(dir) = real_video_dir() else { return };
    // A phone clip outdoors with a hard shadow, and a greyscale KTH clip;
    // neither has an empty frame, so a per-pixel median holds the person.
    for (clip, tallest) in [("waving.avi", 240), ("kth_boxing.avi", 120)] {
        let mut heights = heights(&dir.join(clip));
        heights.sort_unstable();
        let (low, median) = (heights[0], heights[heights.len() / 2]);
        let tall = heights.iter().filter(|&&h| h * 10 > median * 13).count();
        // Standing in place: found in every frame, a third or more of the
        // frame tall and never under two thirds of their usual height; at
        // most a tenth of the frames taller by over 30% (arms overhead add
        // about a fifth) with a stray region kept.
        assert!(low * 3 >= tallest, "{clip}: the person is {low} rows tall in some frame");
        assert!(low * 3 >= median * 2, "{clip}: {low} rows in some frame, {median} in most");
        assert!(tall * 10 <= heights.len(), "{clip}: {tall} of {} frames over 1.3 × {median} rows", heights.len());
    }
}
