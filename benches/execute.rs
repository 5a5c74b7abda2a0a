//! Simulation speed: the shipped wave-h take (30 Hz, 12.9 s) played on the
//! humanoid at the default rate (480 Hz) and at 240 Hz (the rate issue 20's
//! speed target names), on a fixed base, standing on the ground (with
//! balance) and standing with assistance (`--assist`). Each iteration
//! builds the humanoid and plays the whole take, as `imitate execute` does.
//! Throughput is physics steps a second; the real-time factor is that over
//! the rate.
//!
//!     taskset -c 0 cargo bench --bench execute      (one core)

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imitate::params::Params;
use imitate::sim::execute::{ExecuteParams, execute};
use imitate::sim::humanoid::Base;
use imitate::vocab::corpus;
use std::path::Path;

fn simulate(c: &mut Criterion) {
    let take = Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap/wave-h.bvh");
    let corpus = corpus::load(&[take], &Default::default(), None).expect("the shipped take reads");
    let motion = &corpus.takes[0].motion;
    for rate_hz in [ExecuteParams::DEFAULT_RATE_HZ, 240.0] {
        let mut group = c.benchmark_group(format!("execute_{rate_hz}hz"));
        group.sample_size(10);
        let settings =
            [("fixed_base", Base::Fixed, false), ("free_base", Base::Free, false), ("assisted", Base::Free, true)];
        for (name, base, assist) in settings {
            let params = ExecuteParams { base, assist, rate_hz, ..ExecuteParams::default() }
                .check()
                .expect("the standard settings are valid");
            let steps = execute(motion, &params, || {}).expect("the take plays").summary.steps;
            group.throughput(Throughput::Elements(steps as u64));
            group.bench_function(BenchmarkId::new(name, format!("{:.1}s", motion.duration_s())), |b| {
                b.iter(|| execute(motion, &params, || {}).expect("the take plays").summary.rms_error_deg)
            });
        }
        group.finish();
    }
}

criterion_group!(benches, simulate);
criterion_main!(benches);
