//! Speed of the top-eigenpair solver that classical MDS needs: faer's full
//! decomposition against the thick-restarted block Krylov method.
//!
//! - `top8/{full,subspace}/n`: the 8 largest eigenpairs at n = 250 … 4000;
//! - `crossover/{full,subspace}-d<d>/n`: d = 2 … 12 around the size where
//!   `Auto` switches, n = r·(d + 10) for r = 10, 16 (`AUTO_ROWS_PER_COLUMN`)
//!   and 22: the full decomposition should win the first, the Krylov method
//!   the last.
//!
//! The matrices are what ST-Isomap feeds MDS: squared shortest-path
//! distances on the 10-nearest-neighbour graph of points on a noisy curved
//! 2-D manifold in 10-D, double-centred. Graph geodesics are not Euclidean,
//! so the spectrum has a tail of both signs rather than the exact rank 10
//! of Euclidean distances in 10-D (which would flatter the Krylov method).
//!
//! A full decomposition slower than `ONE_SHOT` per run is timed once and
//! printed instead of sampled (criterion takes at least ten samples).
//! Criterion reports the numbers; nothing here asserts a wall-clock time.

use criterion::{BenchmarkId, Criterion, SamplingMode, criterion_group, criterion_main};
use faer::Mat;
use imitate::vocab::eigen::{AUTO_ROWS_PER_COLUMN, EigenMethod, TopEigen, top_eigenpairs};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::hint::black_box;
use std::time::{Duration, Instant};

const SIZES: [usize; 5] = [250, 500, 1000, 2000, 4000];
/// Embedding dimensions ST-Isomap typically keeps.
const D: usize = 8;
const NEIGHBOURS: usize = 10;
const ONE_SHOT: Duration = Duration::from_secs(5);

/// A noisy Swiss roll (curved 2-D manifold) turned into 10-D by a random
/// rotation, with a gentle ripple so it is not flat along its width.
fn curved_points(n: usize, rng: &mut ChaCha8Rng) -> Vec<[f64; 10]> {
    let gaussian = Mat::from_fn(10, 10, |_, _| rng.sample::<f64, _>(StandardNormal));
    let rotation = gaussian.qr().compute_Q();
    (0..n)
        .map(|_| {
            let t = std::f64::consts::PI * rng.gen_range(1.5..3.0);
            let h = rng.gen_range(0.0..10.0);
            let flat = [t * t.cos(), h, t * t.sin(), 0.5 * (0.7 * h).sin()];
            std::array::from_fn(|r| {
                (0..4).map(|c| rotation[(r, c)] * flat[c]).sum::<f64>() + 0.05 * rng.sample::<f64, _>(StandardNormal)
            })
        })
        .collect()
}

fn distance(a: &[f64; 10], b: &[f64; 10]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
}

/// Shortest-path lengths from `source` (Dijkstra). Distances are
/// non-negative, so their bit patterns order like the numbers.
fn dijkstra(graph: &[Vec<(usize, f64)>], source: usize) -> Vec<f64> {
    let mut dist = vec![f64::INFINITY; graph.len()];
    dist[source] = 0.0;
    let mut heap = BinaryHeap::from([Reverse((0.0_f64.to_bits(), source))]);
    while let Some(Reverse((bits, node))) = heap.pop() {
        let here = f64::from_bits(bits);
        if here > dist[node] {
            continue;
        }
        for &(next, length) in &graph[node] {
            let through = here + length;
            if through < dist[next] {
                dist[next] = through;
                heap.push(Reverse((through.to_bits(), next)));
            }
        }
    }
    dist
}

/// ST-Isomap's B = −½ J G² J for the graph geodesics G of `n` curved points.
fn geodesic_mds(n: usize) -> Mat<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
    let points = curved_points(n, &mut rng);
    let nearest: Vec<Vec<usize>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut order: Vec<usize> = (0..n).collect();
            order.select_nth_unstable_by(NEIGHBOURS, |&a, &b| {
                distance(&points[i], &points[a]).total_cmp(&distance(&points[i], &points[b]))
            });
            order.truncate(NEIGHBOURS + 1);
            order
        })
        .collect();
    // Symmetric: an edge if either end is among the other's neighbours.
    let mut graph = vec![Vec::new(); n];
    for (i, near) in nearest.iter().enumerate() {
        for &j in near.iter().filter(|&&j| j != i) {
            let length = distance(&points[i], &points[j]);
            graph[i].push((j, length));
            graph[j].push((i, length));
        }
    }
    let geodesics: Vec<Vec<f64>> = (0..n).into_par_iter().map(|s| dijkstra(&graph, s)).collect();
    assert!(geodesics.iter().flatten().all(|g| g.is_finite()), "the neighbour graph of {n} points is not connected");
    let squared = |i: usize, j: usize| geodesics[i][j].powi(2);
    let mean: Vec<f64> = (0..n).map(|i| (0..n).map(|j| squared(i, j)).sum::<f64>() / n as f64).collect();
    let grand = mean.iter().sum::<f64>() / n as f64;
    Mat::from_fn(n, n, |i, j| -0.5 * (squared(i, j) - mean[i] - mean[j] + grand))
}

fn solve(b: &Mat<f64>, d: usize, method: EigenMethod) -> TopEigen {
    top_eigenpairs(black_box(b.as_ref()), d, method).expect("the eigensolver failed on a benchmark matrix")
}

fn eigen(c: &mut Criterion) {
    let mut group = c.benchmark_group("top8");
    group.sample_size(10).sampling_mode(SamplingMode::Flat).warm_up_time(Duration::from_secs(1));
    for n in SIZES {
        let b = geodesic_mds(n);
        // One untimed-by-criterion run of each: the two must agree, and
        // their residuals and the Krylov cycles go on record.
        let clock = Instant::now();
        let full = solve(&b, D, EigenMethod::Full);
        let full_once = clock.elapsed();
        let subspace = solve(&b, D, EigenMethod::Subspace);
        let spread = full.values.iter().zip(&subspace.values).map(|(f, s)| (f - s).abs() / f.abs()).fold(0.0, f64::max);
        assert!(spread < 1e-9, "n = {n}: the methods disagree by {spread:e} (relative)");
        eprintln!(
            "n = {n}: λ = {:.4e} … {:.4e}; full residual {:.2e}; subspace residual {:.2e} after {} cycles",
            full.values[0],
            full.values[D - 1],
            full.max_residual,
            subspace.max_residual,
            subspace.iterations
        );

        // Enough for ten samples of the slower method in one go.
        group.measurement_time(Duration::from_secs_f64((12.0 * full_once.as_secs_f64()).clamp(3.0, 60.0)));
        if full_once <= ONE_SHOT {
            group.bench_with_input(BenchmarkId::new("full", n), &b, |bench, b| {
                bench.iter(|| solve(b, D, EigenMethod::Full))
            });
        } else {
            eprintln!("n = {n}: full timed once: {:.2} s", full_once.as_secs_f64());
        }
        group.bench_with_input(BenchmarkId::new("subspace", n), &b, |bench, b| {
            bench.iter(|| solve(b, D, EigenMethod::Subspace))
        });
    }
    group.finish();

    let mut group = c.benchmark_group("crossover");
    // Milliseconds each: short runs keep the 24 benchmarks to a minute.
    group.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(1));
    for d in [2, 4, 8, 12] {
        // `Auto`'s block is d + 10 columns wide.
        for rows_per_column in [10, AUTO_ROWS_PER_COLUMN, 22] {
            let n = rows_per_column * (d + 10);
            let b = geodesic_mds(n);
            for (name, method) in [("full", EigenMethod::Full), ("subspace", EigenMethod::Subspace)] {
                group.bench_with_input(BenchmarkId::new(format!("{name}-d{d}"), n), &b, |bench, b| {
                    bench.iter(|| solve(b, d, method))
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, eigen);
criterion_main!(benches);
