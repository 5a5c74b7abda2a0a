//! Tracking speed on every core of the machine: one frame of `Tracker::step`
//! (every primitive's filter, recognition, the virtual trajectory's pose)
//! at 160×120, with the paper's four primitives of the shipped vocabulary
//! (circles, wave-h, wave-v, punch) and 6, 50 and 200 particles each. The
//! frames are silhouettes of the shipped circles take drawn from the front
//! camera, cycled; the tracker keeps its state from frame to frame as it
//! does on a video. Frames per second are 1 / the time per frame.
//!
//!     cargo bench --bench track
//!
//! `track_clip/NAME` (run only when `IMITATE_TRACK_FRAMES` is set): the
//! reference for the Python package's `Tracker.step`
//! (`scripts/python-bench.sh`). One iteration is a fresh tracker stepped
//! through every frame of a clip, in order: the silhouettes of the folder
//! `IMITATE_TRACK_FRAMES` (decoded beforehand as `imitate track` decodes
//! them), seen through the camera.json beside it, with the vocabulary
//! `IMITATE_TRACK_VOCAB`, `IMITATE_TRACK_PARTICLES` particles (6) and seed
//! `IMITATE_TRACK_SEED` (0), eq. 10, at 15 frames/s: the settings
//! `imitate.Tracker(vocab, camera, particles=…, feedback=True, seed=…)`
//! takes. Only the steps are timed. `IMITATE_TRACK_WINNERS`, when set,
//! names a file the first pass's winner per frame is written to, so the
//! caller can check that Python tracked the same.
//!
//!     IMITATE_TRACK_FRAMES=run/frames IMITATE_TRACK_VOCAB=v.vocab IMITATE_TRACK_NAME=9x6 \
//!         cargo bench --bench track -- track_clip

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use imitate::track::calibrate::CalibrationParams;
use imitate::track::filter::FilterParams;
use imitate::track::open_set::OpenSet;
use imitate::track::tracker::{Recognition, TrackParams, Tracker};
use imitate::vision::camera::{Camera, Preset};
use imitate::vision::mask::Mask;
use imitate::vision::scorer::Scorer;
use imitate::vocab::corpus;
use imitate::vocab::vocabulary::Vocabulary;
use std::path::Path;
use std::time::{Duration, Instant};

const PAPER: [&str; 4] = ["circles", "wave-h", "wave-v", "punch"];

fn silhouettes(camera: &Camera) -> Vec<Mask> {
    let take = Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap/circles.bvh");
    let corpus = corpus::load(&[take], &Default::default(), None).expect("the shipped take reads");
    let motion = &corpus.takes[0].motion;
    let mut scorer = Scorer::new(camera.clone(), motion.body.clone());
    // Every other frame: the take is at 30 Hz, the tracker's video at 15.
    motion.poses.iter().step_by(2).map(|pose| scorer.draw(pose).clone()).collect()
}

fn track(c: &mut Criterion) {
    let mut vocabulary = Vocabulary::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("vocab/default.vocab"))
        .expect("the shipped vocabulary reads");
    vocabulary.retain(|p| PAPER.contains(&p.name()));
    assert_eq!(vocabulary.primitives().len(), PAPER.len(), "the shipped vocabulary has the paper's primitives");
    let vocabulary = std::sync::Arc::new(vocabulary);
    let camera = Camera::preset(Preset::Front, 160, 120).expect("the front preset frames 160×120");
    let frames = silhouettes(&camera);
    let mut group = c.benchmark_group("track_frame");
    for particles in [6, 50, 200] {
        // The settings `imitate track --feedback` uses, calibration included
        // (its fits, the first after 2 s and one every 6 s, spread over the
        // frames timed).
        let filter = FilterParams::standard(particles, 5, 1.0 / 15.0);
        let calibration = Some(CalibrationParams::standard(None));
        let params = TrackParams {
            filter,
            recognition: Recognition::FEEDBACK,
            calibration,
            open_set: OpenSet::STANDARD,
            seed: 1,
        };
        let mut tracker = Tracker::new(vocabulary.clone(), camera.clone(), params).expect("valid settings");
        let mut k = 0;
        group.bench_function(BenchmarkId::new("4_primitives", particles), |b| {
            b.iter(|| {
                let estimate = tracker.step(&frames[k % frames.len()]);
                k += 1;
                estimate.winner
            })
        });
    }
    group.finish();
}

/// The value of environment variable `name`, parsed, or `default`.
fn setting<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().map_or(default, |v| v.parse().unwrap_or_else(|_| panic!("{name}: cannot parse `{v}`")))
}

fn track_clip(c: &mut Criterion) {
    use imitate::params::Params;
    use imitate::track::clip::ClipOptions;
    use imitate::vision::frames::{Expect, FrameSource};
    use imitate::vision::resize::DEFAULT_WORK_WIDTH;
    use imitate::vision::silhouette::Silhouettes;

    let Ok(input) = std::env::var("IMITATE_TRACK_FRAMES") else { return };
    let input = Path::new(&input);
    let vocab = std::env::var("IMITATE_TRACK_VOCAB").expect("IMITATE_TRACK_VOCAB: the vocabulary to track with");
    let particles: usize = setting("IMITATE_TRACK_PARTICLES", 6);
    let seed: u64 = setting("IMITATE_TRACK_SEED", 0);
    let name = std::env::var("IMITATE_TRACK_NAME").unwrap_or_else(|_| format!("{particles}_particles"));

    let vocabulary = std::sync::Arc::new(Vocabulary::load(Path::new(&vocab)).expect("the vocabulary reads"));
    let beside = input.parent().unwrap_or(input).join("camera.json");
    let camera = Camera::read(&beside).expect("a camera.json beside the frames");
    // The silhouettes `imitate track` and `imitate.Silhouettes` make of the
    // folder, all decoded before anything is timed.
    let source = FrameSource::open(input, Expect::Auto).expect("the frames open");
    let mut silhouettes = Silhouettes::new(input, source, None, DEFAULT_WORK_WIDTH);
    let (width, height) = silhouettes.size();
    assert_eq!((width, height), (camera.width(), camera.height()), "frames of the camera's size");
    let mut frames = Vec::new();
    let mut mask = Mask::new(width, height);
    while let Some(next) = silhouettes.next_into(&mut mask) {
        next.expect("every frame gives a silhouette");
        frames.push(mask.clone());
    }
    assert!(!frames.is_empty(), "{}: no frames", input.display());
    // What `imitate.Tracker(..., particles, feedback=True, seed, fps=15)` checks its options into.
    let options = ClipOptions { particles, seed, feedback: true, fps: Some(15.0), ..ClipOptions::default() };
    let params = options.check().expect("valid settings");
    let fresh = || Tracker::new(vocabulary.clone(), camera.clone(), params).expect("a tracker for the vocabulary");

    if let Ok(path) = std::env::var("IMITATE_TRACK_WINNERS") {
        let mut tracker = fresh();
        let names: Vec<&str> = vocabulary.primitives().iter().map(|p| p.name()).collect();
        let lines: String = frames.iter().map(|f| format!("{}\n", names[tracker.step(f).winner])).collect();
        std::fs::write(&path, lines).expect("the winners file is written");
    }

    let mut group = c.benchmark_group("track_clip");
    // One iteration is the whole clip; ten of them, each timed alone.
    group.sampling_mode(criterion::SamplingMode::Flat).sample_size(10).warm_up_time(Duration::from_millis(500));
    group.throughput(criterion::Throughput::Elements(frames.len() as u64));
    group.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let mut timed = Duration::ZERO;
            for _ in 0..iters {
                let mut tracker = fresh();
                let started = Instant::now();
                for frame in &frames {
                    std::hint::black_box(tracker.step(frame).winner);
                }
                timed += started.elapsed();
            }
            timed
        })
    });
    group.finish();
}

criterion_group!(benches, track, track_clip);
criterion_main!(benches);
