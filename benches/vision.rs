//! Speed of what the tracker calls for every hypothesis, on one core:
//!
//! - `draw/<size>`: the body's capsules drawn into a mask;
//! - `distance_field/<size>`: the exact squared EDT of a silhouette;
//! - `score/<size>`: eq. 8–9 for a hypothesis already drawn;
//! - `likelihood/<size>`: one evaluation as the tracker makes it
//!   (`Scorer::score`): forward kinematics, drawing the hypothesis and
//!   scoring it against an observation (eq. 8–9) whose distance field was
//!   computed once.
//!
//! The poses are frames of the shipped horizontal-waving take: the
//! observation one frame, the hypothesis the next. Criterion reports the
//! numbers; nothing here asserts a wall-clock time.
//!
//!     cargo bench --bench vision

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use imitate::mocap::body::Body;
use imitate::mocap::pose::Pose;
use imitate::vision::camera::{Camera, Preset};
use imitate::vision::distance::{DistanceField, Observation, Scratch};
use imitate::vision::mask::Mask;
use imitate::vision::render::draw;
use imitate::vision::scorer::Scorer;
use imitate::vision::shape::capsules;
use imitate::vision::sighting::Sighting;
use imitate::vocab::corpus;
use std::hint::black_box;
use std::path::PathBuf;

const SIZES: [(u32, u32); 3] = [(160, 120), (320, 240), (640, 480)];

fn poses() -> (Body, Pose, Pose) {
    let take = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("mocap/wave-h.bvh");
    let corpus = corpus::load(&[take], &Default::default(), None).expect("the shipped take reads");
    let motion = &corpus.takes[0].motion;
    (motion.body.clone(), motion.poses[120], motion.poses[121])
}

fn silhouette(camera: &Camera, body: &Body, pose: &Pose) -> Mask {
    let mut mask = Mask::new(camera.width(), camera.height());
    draw(camera, &capsules(body, &body.forward(pose)), &mut mask);
    mask
}

fn vision(c: &mut Criterion) {
    let (body, observed, hypothesis) = poses();
    for (w, h) in SIZES {
        let size = format!("{w}x{h}");
        let camera = Camera::preset(Preset::Front, w, h).unwrap();
        let parts = capsules(&body, &body.forward(&hypothesis));
        let mut mask = Mask::new(camera.width(), camera.height());
        c.bench_with_input(BenchmarkId::new("draw", &size), &parts, |b, parts| {
            b.iter(|| {
                mask.clear();
                draw(&camera, black_box(parts), &mut mask);
            })
        });
        let observation = Observation::new(silhouette(&camera, &body, &observed));
        let mut field = DistanceField::new();
        c.bench_function(&format!("distance_field/{size}"), |b| {
            b.iter(|| field.compute_into(black_box(observation.mask())))
        });
        let mut scratch = Scratch::default();
        let drawn = silhouette(&camera, &body, &hypothesis);
        c.bench_function(&format!("score/{size}"), |b| {
            b.iter(|| observation.likelihood(black_box(&drawn), &mut scratch))
        });
        let mut scorer = Scorer::new(camera.clone(), body.clone());
        let sighting = Sighting::silhouette(observation.mask().clone());
        c.bench_function(&format!("likelihood/{size}"), |b| b.iter(|| scorer.score(&sighting, black_box(&hypothesis))));
    }
}

criterion_group!(benches, vision);
criterion_main!(benches);
