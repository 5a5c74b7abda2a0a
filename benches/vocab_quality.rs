//! The vocabulary figures docs/numbers.md reports, as Markdown tables:
//!
//! 1. the synthetic stream (circles, horizontal and vertical
//!    waving, punching; 4 repetitions each at 0.5×, 1× and 2×), five seeds:
//!    clusters against the activity labels, and on held-out repetitions
//!    (new seeds at 0.75×, 1× and 1.5×) the latent field's direction
//!    against the true displacement, latent against joint-space direction
//!    (eq. 5) and attractor progress;
//! 2. every file of `../shared/mocap/real/`: clusters against `labels.csv`,
//!    and the same held-out figures with the last third of each take held
//!    out;
//! 3. the ablation: plain Isomap against ST-Isomap, kinematic centroids
//!    against zero-velocity crossings, on both.
//!
//!     cargo bench --bench vocab_quality
//!
//! Labels only ever score; learning never sees them.

use imitate::params::Params;
use imitate::vocab::cluster::ClusterParams;
use imitate::vocab::corpus::{Corpus, load, read_labels};
use imitate::vocab::embed::EmbedParams;
use imitate::vocab::evaluate::{
    ClusterScores, HeldOutReport, benchmark_stream, check_held_out, cluster_scores, held_out_stream,
};
use imitate::vocab::pipeline::{BuildParams, build};
use imitate::vocab::primitive::FitParams;
use imitate::vocab::segment::{Method, SegmentParams};
use std::path::PathBuf;

const SEEDS: [u64; 5] = [1, 2, 3, 4, 5];

fn params(method: Method, temporal: bool) -> BuildParams {
    BuildParams {
        segment: SegmentParams::new().method(method).check().unwrap(),
        embed: EmbedParams::new().temporal(temporal).check().unwrap(),
        cluster: ClusterParams::new().check().unwrap(),
        fit: FitParams::new().check().unwrap(),
    }
}

fn real() -> Option<Corpus> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/mocap/real");
    let labels = read_labels(&dir.join("labels.csv")).ok()?;
    load(&[dir], &Default::default(), Some((&labels, "labels.csv"))).ok()
}

/// The first two thirds of every take, and the last third.
fn split_thirds(corpus: &Corpus) -> (Corpus, Corpus) {
    let (mut first, mut last) = (Corpus::default(), Corpus::default());
    for take in &corpus.takes {
        let cut = take.motion.poses.len() * 2 / 3;
        for (part, range) in [(&mut first, 0..cut), (&mut last, cut..take.motion.poses.len())] {
            let mut motion = take.motion.clone();
            motion.poses = take.motion.poses[range.clone()].to_vec();
            let labels: Option<Vec<&str>> =
                take.labels.as_ref().map(|l| l[range.clone()].iter().map(|&id| corpus.label(id)).collect());
            part.push(take.path.clone(), motion, labels.as_deref());
        }
    }
    (first, last)
}

struct Row {
    k: usize,
    segments: usize,
    scores: ClusterScores,
    held_out: Option<HeldOutReport>,
}

fn run(training: &Corpus, held_out: Option<&Corpus>, p: &BuildParams) -> Row {
    let b = build(training, p, |_| {}).expect("the corpus builds");
    let scores = cluster_scores(&b.segments, b.clustering.assignments()).expect("labelled");
    let held_out = held_out.map(|h| check_held_out(&b, training, h, p).expect("held-out checks run"));
    Row { k: b.clustering.k(), segments: b.segments.len(), scores, held_out }
}

fn held_out_cells(report: &HeldOutReport) -> String {
    let cycles: Vec<f64> =
        report.repetitions.iter().filter(|r| r.cyclic && r.travel > 0.0).map(|r| r.progress_rho).collect();
    let min_rho = cycles.iter().copied().fold(f64::INFINITY, f64::min);
    let mean_rho = cycles.iter().sum::<f64>() / cycles.len().max(1) as f64;
    format!(
        "{:.3} | {:.3} | {:.3} | {:.3} | {}",
        report.mean_direction(|r| r.latent_cosine),
        report.mean_direction(|r| r.joint_agreement),
        mean_rho,
        min_rho,
        cycles.len()
    )
}

fn main() {
    println!("## Synthetic stream (default settings)\n");
    println!(
        "| seed | segments | k | purity | ARI | purity (all) | ARI (all) | field cos | eq. 5 cos | progress ρ mean | \
         progress ρ min | held-out cycles |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let defaults = params(Method::Kcs, true);
    for seed in SEEDS {
        let r = run(&benchmark_stream(seed), Some(&held_out_stream(seed)), &defaults);
        let (w, a) = (r.scores.whole_activity, r.scores.all);
        println!(
            "| {seed} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {} |",
            r.segments,
            r.k,
            w.purity,
            w.adjusted_rand_index,
            a.purity,
            a.adjusted_rand_index,
            held_out_cells(r.held_out.as_ref().unwrap())
        );
    }
    let real = real();
    match &real {
        None => println!("\n(../shared/mocap/real is absent: real-capture figures skipped)"),
        Some(corpus) => {
            println!("\n## Real captures (all files; last third of each take held out for the field figures)\n");
            let all = run(corpus, None, &defaults);
            let (first, last) = split_thirds(corpus);
            let split = run(&first, Some(&last), &defaults);
            println!(
                "| learned from | segments | k | purity | ARI | field cos | eq. 5 cos | progress ρ mean | progress ρ min | held-out cycles |"
            );
            println!("|---|---|---|---|---|---|---|---|---|---|");
            let a = all.scores.all;
            println!(
                "| every frame | {} | {} | {:.3} | {:.3} | – | – | – | – | – |",
                all.segments, all.k, a.purity, a.adjusted_rand_index
            );
            let s = split.scores.all;
            println!(
                "| first two thirds | {} | {} | {:.3} | {:.3} | {} |",
                split.segments,
                split.k,
                s.purity,
                s.adjusted_rand_index,
                held_out_cells(split.held_out.as_ref().unwrap())
            );
        }
    }
    println!("\n## Ablation\n");
    println!("Stream: mean over seeds 1–5 (purity and ARI over whole-activity segments). Real: all files.\n");
    println!(
        "| embedding | segmentation | stream purity | stream ARI | stream k | stream field cos | real purity | real ARI | real k |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for temporal in [true, false] {
        for method in [Method::Kcs, Method::Zvc] {
            let p = params(method, temporal);
            let rows: Vec<Row> =
                SEEDS.iter().map(|&s| run(&benchmark_stream(s), Some(&held_out_stream(s)), &p)).collect();
            let mean = |f: &dyn Fn(&Row) -> f64| rows.iter().map(f).sum::<f64>() / rows.len() as f64;
            let real_cells = real.as_ref().map_or("– | – | –".to_string(), |c| {
                let r = run(c, None, &p);
                format!("{:.3} | {:.3} | {}", r.scores.all.purity, r.scores.all.adjusted_rand_index, r.k)
            });
            println!(
                "| {} | {} | {:.3} | {:.3} | {:.1} | {:.3} | {real_cells} |",
                if temporal { "ST-Isomap" } else { "plain Isomap" },
                match method {
                    Method::Kcs => "KCS",
                    Method::Zvc => "ZVC",
                },
                mean(&|r| r.scores.whole_activity.purity),
                mean(&|r| r.scores.whole_activity.adjusted_rand_index),
                mean(&|r| r.k as f64),
                mean(&|r| r.held_out.as_ref().unwrap().mean_direction(|c| c.latent_cosine)),
            );
        }
    }
}
