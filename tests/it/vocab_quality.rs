//! What a learned vocabulary is worth, measured as docs/numbers.md reports it:
//! clusters against activity labels (never seen by learning), and each
//! primitive's gradient field and progress on held-out repetitions.

use crate::common;

use imitate::vocab::corpus::{Corpus, load, read_labels};
use imitate::vocab::evaluate::{
    activities_without_primitive, benchmark_stream, check_held_out, cluster_scores, held_out_stream,
};
use imitate::vocab::pipeline::{Build, BuildParams, build};

fn learn(corpus: &Corpus) -> Build {
    build(corpus, &BuildParams::standard(), |_| {}).unwrap()
}

#[test]
fn the_synthetic_stream_clusters_by_activity_and_every_activity_gets_a_primitive() {
    for s in 1..=3 {
        let corpus = benchmark_stream(s);
        let b = learn(&corpus);
        let scores = cluster_scores(&b.segments, b.clustering.assignments()).unwrap();
        let whole = scores.whole_activity;
        assert!(whole.segments >= 36, "seed {s}: only {} whole-activity segments", whole.segments);
        assert!(whole.purity >= 0.95, "seed {s}: purity {:.3}", whole.purity);
        assert!(whole.adjusted_rand_index >= 0.90, "seed {s}: ARI {:.3}", whole.adjusted_rand_index);
        let missing = activities_without_primitive(&b.segments, b.clustering.assignments());
        assert!(missing.iter().all(|m| m == "rest"), "seed {s}: no primitive for {missing:?}");
        let names: Vec<&str> = b.fitted.primitives.iter().map(|p| p.name()).collect();
        for activity in ["circles", "wave-h", "wave-v", "punch"] {
            assert!(names.contains(&activity), "seed {s}: no primitive named {activity} in {names:?}");
        }
    }
}

#[test]
fn fields_and_progress_hold_on_held_out_repetitions() {
    for s in 1..=3 {
        let training = benchmark_stream(s);
        // Other repetitions at other speeds.
        let held_out = held_out_stream(s);
        let b = learn(&training);
        let report = check_held_out(&b, &training, &held_out, &BuildParams::standard()).unwrap();
        assert!(report.unmatched.iter().all(|m| m == "rest"), "seed {s}: {:?}", report.unmatched);
        let moving = report.repetitions.iter().filter(|r| r.travel > 0.0 && r.activity != "rest");
        let activities: std::collections::BTreeSet<&str> = moving.clone().map(|r| r.activity.as_str()).collect();
        assert_eq!(activities.len(), 4, "seed {s}: {activities:?}");
        // The primitive nearest to each held-out repetition is its own
        // activity's (`wave-h` or `wave-h-2` for horizontal waving).
        for r in report.repetitions.iter().filter(|r| r.activity != "rest") {
            let own = r.primitive == r.activity || r.primitive.starts_with(&format!("{}-", r.activity));
            assert!(
                own,
                "seed {s}: {} {}-{} ({}) is nearest to {}",
                r.file, r.first_frame, r.last_frame, r.activity, r.primitive
            );
        }
        let latent = report.mean_direction(|r| r.latent_cosine);
        let joint = report.mean_direction(|r| r.joint_agreement);
        assert!(latent >= 0.90, "seed {s}: latent field cosine {latent:.3}");
        assert!(joint >= 0.90, "seed {s}: latent vs joint-space direction (eq. 5) {joint:.3}");
        let cycles: Vec<_> = moving.filter(|r| r.cyclic).collect();
        assert!(cycles.len() >= 24, "seed {s}: {} held-out cycles", cycles.len());
        for r in cycles {
            assert!(
                r.progress_rho >= 0.90,
                "seed {s}: progress rho {:.3} along {} {}-{} ({})",
                r.progress_rho,
                r.file,
                r.first_frame,
                r.last_frame,
                r.primitive
            );
            // Rising is not enough: progress must also move on through
            // the cycle, not hover.
            assert!(r.progress_advance >= 0.5, "seed {s}: progress advanced only {:.2}", r.progress_advance);
        }
    }
}

#[test]
fn real_captures_cluster_with_purity_of_at_least_0_8() {
    let Some(dir) = common::real_mocap_dir() else { return };
    let labels_path = dir.join("labels.csv");
    let labels = read_labels(&labels_path).unwrap();
    let corpus = load(&[dir], &Default::default(), Some((&labels, "labels.csv"))).unwrap();
    assert_eq!(corpus.takes.len(), 23);
    let b = learn(&corpus);
    let scores = cluster_scores(&b.segments, b.clustering.assignments()).unwrap();
    assert!(scores.all.segments >= 150, "{} segments", scores.all.segments);
    assert!(scores.all.purity >= 0.80, "purity {:.3}", scores.all.purity);
    // Every primitive can be used: finite projections and a field.
    for p in &b.fitted.primitives {
        let y = p.project(p.mean());
        assert!(y.iter().all(|v| v.abs() < 1e-9), "{}: the mean projects to the origin", p.name());
        assert!(p.progress(&y).is_finite());
    }
}

#[test]
fn bandai_dataset_2_gives_each_of_its_ten_activities_primitives_of_its_own() {
    let files: Vec<_> = common::shared_bvh_files("bandai")
        .into_iter()
        .filter(|f| f.file_name().is_some_and(|n| n.to_string_lossy().starts_with("dataset-2_")))
        .collect();
    let Some(dir) = files.first().and_then(|f| f.parent()) else { return };
    let labels = read_labels(&dir.join("labels.csv")).unwrap();
    let corpus = load(&files, &Default::default(), Some((&labels, "labels.csv"))).unwrap();
    assert_eq!(corpus.takes.len(), 240);
    let b = learn(&corpus);
    // The vocabulary's partition is its primitives: the clusters split by
    // how the root moves (walks that turn left, go straight, turn right).
    let primitives = b.fitted.assignments(&b.clustering);
    let scores = cluster_scores(&b.segments, &primitives).unwrap().all;
    assert!(scores.purity >= 0.90, "purity {:.3}", scores.purity);
    let missing = activities_without_primitive(&b.segments, &primitives);
    assert!(missing.is_empty(), "no primitive of its own for {missing:?}");
    let names: Vec<&str> = b.fitted.primitives.iter().map(|p| p.name()).collect();
    for turn in ["walk-turn-left", "walk-turn-right"] {
        assert!(names.contains(&turn), "no primitive named {turn} in {names:?}");
    }
}
