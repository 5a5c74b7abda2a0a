//! Tracking speed on every core of the machine: one frame of `Tracker::step`
//! (every primitive's filter, recognition, the virtual trajectory's pose)
//! at 160×120, with the paper's four primitives of the shipped vocabulary
//! (circles, wave-h, wave-v, punch) and 6, 50 and 200 particles each. The
//! frames are silhouettes of the shipped circles take drawn from the front
//! camera, cycled; the tracker keeps its state from frame to frame as it
//! does on a video. Frames per second are 1 / the time per frame.
//!
//!     cargo bench --bench track

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

criterion_group!(benches, track);
criterion_main!(benches);
