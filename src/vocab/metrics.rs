//! Scores for learned vocabularies: how well clusters match labels (purity,
//! adjusted Rand index), how well fields predict motion (cosine), and how
//! monotonically progress rises (Spearman's ρ). Labels are only ever used
//! here, to score, never to learn.

use std::collections::BTreeMap;

/// The share of items whose cluster's majority label is their own label.
/// Items without a label are left out. 1 is perfect.
pub fn purity(clusters: &[usize], labels: &[Option<&str>]) -> f64 {
    let table = contingency(clusters, labels);
    let total: usize = table.values().map(|row| row.values().sum::<usize>()).sum();
    if total == 0 {
        return f64::NAN;
    }
    let majority: usize = table.values().map(|row| row.values().copied().max().unwrap_or(0)).sum();
    majority as f64 / total as f64
}

/// Hubert and Arabie's adjusted Rand index between clusters and labels:
/// 1 for identical partitions, about 0 for chance agreement. Items without
/// a label are left out.
pub fn adjusted_rand_index(clusters: &[usize], labels: &[Option<&str>]) -> f64 {
    let table = contingency(clusters, labels);
    let pairs = |n: usize| (n * n.saturating_sub(1)) as f64 / 2.0;
    let n: usize = table.values().map(|row| row.values().sum::<usize>()).sum();
    let index: f64 = table.values().flat_map(|row| row.values()).map(|&c| pairs(c)).sum();
    let cluster_sums: f64 = table.values().map(|row| pairs(row.values().sum())).sum();
    let mut label_totals: BTreeMap<&str, usize> = BTreeMap::new();
    for row in table.values() {
        for (label, count) in row {
            *label_totals.entry(label).or_insert(0) += count;
        }
    }
    let label_sums: f64 = label_totals.values().map(|&c| pairs(c)).sum();
    let expected = cluster_sums * label_sums / pairs(n);
    let maximum = 0.5 * (cluster_sums + label_sums);
    if (maximum - expected).abs() < f64::EPSILON {
        // One cluster and one label: the partitions agree trivially.
        return 1.0;
    }
    (index - expected) / (maximum - expected)
}

/// Counts of each label in each cluster.
fn contingency<'a>(clusters: &[usize], labels: &[Option<&'a str>]) -> BTreeMap<usize, BTreeMap<&'a str, usize>> {
    let mut table: BTreeMap<usize, BTreeMap<&str, usize>> = BTreeMap::new();
    for (&cluster, label) in clusters.iter().zip(labels) {
        if let Some(label) = label {
            *table.entry(cluster).or_default().entry(label).or_insert(0) += 1;
        }
    }
    table
}

/// The label of each cluster: the one held by more than half of its
/// labelled items; `None` where no label has such a majority (a cluster
/// that mixes activities has no one name) or nothing is labelled.
pub fn majority_labels<'a>(clusters: &[usize], labels: &[Option<&'a str>], k: usize) -> Vec<Option<&'a str>> {
    let table = contingency(clusters, labels);
    (0..k)
        .map(|c| {
            let row = table.get(&c)?;
            let total: usize = row.values().sum();
            row.iter().find(|(_, n)| 2 * **n > total).map(|(label, _)| *label)
        })
        .collect()
}

/// Spearman's rank correlation between two equally long sequences (ties get
/// their mean rank). NaN for fewer than two items or a constant sequence.
pub fn spearman(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "spearman needs paired values");
    pearson(&ranks(a), &ranks(b))
}

fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&i, &j| values[i].total_cmp(&values[j]));
    let mut ranks = vec![0.0; values.len()];
    let mut start = 0;
    while start < order.len() {
        let mut end = start + 1;
        while end < order.len() && values[order[end]] == values[order[start]] {
            end += 1;
        }
        let mean_rank = (start + end - 1) as f64 / 2.0;
        for &i in &order[start..end] {
            ranks[i] = mean_rank;
        }
        start = end;
    }
    ranks
}

fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    if a.len() < 2 {
        return f64::NAN;
    }
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

/// Cosine of the angle between two vectors; NaN when either is zero.
pub fn cosine(a: &[f64], b: &[f64]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let na: f64 = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nb: f64 = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    dot / (na * nb)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels<'a>(v: &[&'a str]) -> Vec<Option<&'a str>> {
        v.iter().map(|s| Some(*s)).collect()
    }

    #[test]
    fn identical_partitions_score_one_whatever_the_cluster_numbering() {
        let l = labels(&["a", "a", "b", "b", "c", "c"]);
        let c = [2, 2, 0, 0, 1, 1];
        assert_eq!(purity(&c, &l), 1.0);
        assert!((adjusted_rand_index(&c, &l) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn adjusted_rand_index_matches_a_hand_computed_example() {
        // Contingency [[2, 1], [0, 3]]: index 1 + 3 = 4, cluster pairs 3 + 3 = 6,
        // label pairs 1 + 6 = 7, 15 pairs in all: expected 2.8, max 6.5.
        let l = labels(&["x", "x", "y", "y", "y", "y"]);
        let c = [0, 0, 0, 1, 1, 1];
        let ari = adjusted_rand_index(&c, &l);
        assert!((ari - (4.0 - 2.8) / (6.5 - 2.8)).abs() < 1e-12, "{ari}");
        assert!((purity(&c, &l) - 5.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn splitting_a_label_over_two_clusters_keeps_purity_but_lowers_the_rand_index() {
        let l = labels(&["a", "a", "a", "a", "b", "b", "b", "b"]);
        let split = [0, 0, 1, 1, 2, 2, 2, 2];
        assert_eq!(purity(&split, &l), 1.0);
        assert!(adjusted_rand_index(&split, &l) < 0.8);
    }

    #[test]
    fn unlabelled_items_are_left_out() {
        let l = vec![Some("a"), None, Some("b")];
        assert_eq!(purity(&[0, 0, 1], &l), 1.0);
        assert!(purity(&[0], &[None]).is_nan());
    }

    #[test]
    fn a_cluster_is_named_only_by_a_label_held_by_more_than_half() {
        let l = labels(&["b", "a", "c", "a", "a", "b", "d"]);
        // Cluster 0: b, a (a tie); 1: empty; 2: c, a, a; 3: b, d.
        assert_eq!(majority_labels(&[0, 0, 2, 2, 2, 3, 3], &l, 4), vec![None, None, Some("a"), None]);
    }

    #[test]
    fn spearman_is_one_for_any_increasing_sequence_and_handles_ties() {
        let t: Vec<f64> = (0..10).map(|i| i as f64).collect();
        let rising: Vec<f64> = t.iter().map(|x| x * x * x + 1.0).collect();
        assert!((spearman(&t, &rising) - 1.0).abs() < 1e-12);
        let falling: Vec<f64> = rising.iter().map(|x| -x).collect();
        assert!((spearman(&t, &falling) + 1.0).abs() < 1e-12);
        let tied = [1.0, 2.0, 2.0, 3.0];
        assert!((spearman(&[1.0, 2.0, 3.0, 4.0], &tied) - 0.9486832980505138).abs() < 1e-12);
    }

    #[test]
    fn cosine_of_parallel_orthogonal_and_opposite_vectors() {
        assert!((cosine(&[1.0, 2.0], &[2.0, 4.0]) - 1.0).abs() < 1e-15);
        assert!(cosine(&[1.0, 0.0], &[0.0, 3.0]).abs() < 1e-15);
        assert!((cosine(&[1.0, 1.0], &[-1.0, -1.0]) + 1.0).abs() < 1e-15);
    }
}
