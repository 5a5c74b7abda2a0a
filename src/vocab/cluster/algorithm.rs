//! k-means over the embedding, and the choice of k.

use super::hyperparams::ValidClusterParams;
use crate::vocab::embed::Embedding;
use linfa::DatasetBase;
use linfa::prelude::{Fit, Predict};
use linfa_clustering::KMeans;
use ndarray::{Array1, Array2};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// How the number of primitives was settled.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Choice {
    /// Given with `--k`.
    Given,
    /// Chosen by mean silhouette (see [`best`] and `ClusterParams::tolerance`).
    Silhouette,
    /// One cluster per activity label (`ClusterParams::by_label`).
    ByLabel,
}

/// Segments grouped into primitives.
#[derive(Clone, Debug, PartialEq)]
pub struct Clustering {
    /// Each segment's primitive, numbered by first appearance.
    assignments: Vec<usize>,
    k: usize,
    choice: Choice,
    /// Every k tried (for `--k`, only that one).
    scores: Vec<Tried>,
}

/// One k tried, and how it scored.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tried {
    pub k: usize,
    /// Mean silhouette.
    pub silhouette: f64,
    /// Its standard error (the spread of the points' silhouettes over the
    /// square root of their number).
    #[serde(default)]
    pub standard_error: f64,
    /// Segments in its smallest cluster.
    pub smallest: usize,
}

impl Clustering {
    /// A clustering read back from a table, with how its k was chosen.
    pub fn recorded(assignments: Vec<usize>, choice: Choice, scores: Vec<Tried>) -> Clustering {
        let k = assignments.iter().max().map_or(0, |m| m + 1);
        Clustering { assignments, k, choice, scores }
    }

    pub fn assignments(&self) -> &[usize] {
        &self.assignments
    }

    pub fn k(&self) -> usize {
        self.k
    }

    pub fn choice(&self) -> &Choice {
        &self.choice
    }

    pub fn scores(&self) -> &[Tried] {
        &self.scores
    }

    /// The mean silhouette of the chosen k.
    pub fn score(&self) -> Option<f64> {
        self.scores.iter().find(|t| t.k == self.k).map(|t| t.silhouette)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ClusterError {
    #[error("k = {k} asks for more primitives than the {segments} segments there are")]
    TooManyClusters { k: usize, segments: usize },
    #[error("only {0} segments: choosing the number of primitives needs at least 3")]
    TooFewSegments(usize),
    #[error("k-means failed: {0}")]
    KMeans(String),
    #[error("clustering by label needs labelled segments, and none of the {0} is")]
    NoLabels(usize),
}

impl ValidClusterParams {
    /// Clusters the embedded segments; `labels` are their activities (in
    /// segment order), which only clustering by label reads.
    pub fn cluster(&self, embedding: &Embedding, labels: &[Option<String>]) -> Result<Clustering, ClusterError> {
        let n = embedding.len();
        let records = Array2::from_shape_vec((n, embedding.dims()), embedding.coords().to_vec())
            .map_err(|e| ClusterError::KMeans(e.to_string()))?;
        if self.params().by_label {
            return self.by_label(&records, labels);
        }
        self.cluster_records(&records)
    }

    /// One cluster per label; the unlabelled segments clustered among
    /// themselves as [`Self::cluster_records`] does (one cluster when they
    /// are too few to choose k).
    fn by_label(&self, records: &Array2<f64>, labels: &[Option<String>]) -> Result<Clustering, ClusterError> {
        let n = records.nrows();
        assert_eq!(labels.len(), n, "one label per segment");
        let mut ids: std::collections::BTreeMap<&str, usize> = std::collections::BTreeMap::new();
        let mut assignments: Vec<Option<usize>> = labels
            .iter()
            .map(|l| {
                l.as_deref().map(|l| {
                    let next = ids.len();
                    *ids.entry(l).or_insert(next)
                })
            })
            .collect();
        if ids.is_empty() {
            return Err(ClusterError::NoLabels(n));
        }
        let unlabelled: Vec<usize> = (0..n).filter(|&i| assignments[i].is_none()).collect();
        if !unlabelled.is_empty() {
            let first = ids.len();
            let own = if unlabelled.len() < 3 {
                vec![0; unlabelled.len()]
            } else {
                self.cluster_records(&records.select(ndarray::Axis(0), &unlabelled))?.assignments
            };
            unlabelled.iter().zip(own).for_each(|(&i, c)| assignments[i] = Some(first + c));
        }
        let assignments =
            by_first_appearance(&assignments.into_iter().map(|a| a.expect("all assigned")).collect::<Vec<_>>());
        let k = assignments.iter().max().map_or(0, |m| m + 1);
        let tried = score(records, &assignments, k);
        Ok(Clustering { assignments, k, choice: Choice::ByLabel, scores: vec![tried] })
    }

    fn cluster_records(&self, records: &Array2<f64>) -> Result<Clustering, ClusterError> {
        let p = self.params();
        let n = records.nrows();
        let (assignments, choice, scores) = match p.k {
            Some(k) => {
                if k > n {
                    return Err(ClusterError::TooManyClusters { k, segments: n });
                }
                let a = self.kmeans(records, k)?;
                let tried = score(records, &a, k);
                (a, Choice::Given, vec![tried])
            }
            None => {
                if n < 3 {
                    return Err(ClusterError::TooFewSegments(n));
                }
                let tried = (2..=p.max_k.min(n - 1))
                    .into_par_iter()
                    .map(|k| {
                        let a = self.kmeans(records, k)?;
                        Ok((score(records, &a, k), a))
                    })
                    .collect::<Result<Vec<_>, ClusterError>>()?;
                let scores: Vec<Tried> = tried.iter().map(|t| t.0).collect();
                let chosen = choose_k(&scores, p.min_size, p.tolerance);
                let a = tried.into_iter().find(|t| t.0.k == chosen).expect("chosen among the tried").1;
                (a, Choice::Silhouette, scores)
            }
        };
        let assignments = by_first_appearance(&assignments);
        let k = assignments.iter().max().map_or(0, |m| m + 1);
        Ok(Clustering { assignments, k, choice, scores })
    }

    fn kmeans(&self, records: &Array2<f64>, k: usize) -> Result<Vec<usize>, ClusterError> {
        let p = self.params();
        let dataset = DatasetBase::from(records.clone());
        let model = KMeans::params_with_rng(k, ChaCha8Rng::seed_from_u64(p.seed))
            .n_runs(p.runs)
            .tolerance(1e-9)
            .max_n_iterations(500)
            .fit(&dataset)
            .map_err(|e| ClusterError::KMeans(e.to_string()))?;
        let labels: Array1<usize> = model.predict(records);
        Ok(labels.to_vec())
    }
}

/// How the `k` clusters of `assignments` score.
fn score(records: &Array2<f64>, assignments: &[usize], k: usize) -> Tried {
    let mut sizes = vec![0; k];
    assignments.iter().for_each(|&c| sizes[c] += 1);
    let (silhouette, standard_error) = silhouette(records, assignments);
    Tried { k, silhouette, standard_error, smallest: sizes.into_iter().min().unwrap_or(0) }
}

/// The clusterings that compete when k is chosen: those whose clusters all
/// hold at least `min_size` segments, or all of them if none do.
pub fn eligible(tried: &[Tried], min_size: usize) -> impl Iterator<Item = &Tried> {
    let any_sized = tried.iter().any(|t| t.smallest >= min_size);
    tried.iter().filter(move |t| t.smallest >= min_size || !any_sized)
}

/// The eligible clustering with the best mean silhouette.
pub fn best(tried: &[Tried], min_size: usize) -> Option<&Tried> {
    eligible(tried, min_size).fold(None, |best: Option<&Tried>, t| match best {
        Some(b) if b.silhouette >= t.silhouette => Some(b),
        _ => Some(t),
    })
}

/// Among the eligible clusterings, the largest k whose mean silhouette is
/// within `tolerance` standard errors of the best (statistically as good).
fn choose_k(tried: &[Tried], min_size: usize, tolerance: f64) -> usize {
    let best = best(tried, min_size).expect("k = 2 is tried");
    let floor = best.silhouette - tolerance * best.standard_error;
    eligible(tried, min_size).filter(|t| t.silhouette >= floor).map(|t| t.k).max().unwrap_or(best.k)
}

/// Points beyond which the silhouette is estimated on an evenly spread
/// sample of this many (it costs a pass over all pairs).
const SILHOUETTE_SAMPLE: usize = 2000;

/// Mean silhouette (Rousseeuw 1987) of a labelling: for each point, how
/// much nearer it is on average to its own cluster (`a`) than to the
/// nearest other (`b`), `(b − a) / max(a, b)`. A point alone in its cluster
/// scores 0, as Rousseeuw defines it. (linfa scores it 1, which rewards
/// splitting points off into clusters of their own: we choose k with this
/// one.)
/// Returns the mean and its standard error.
fn silhouette(records: &Array2<f64>, assignments: &[usize]) -> (f64, f64) {
    let n = assignments.len();
    let k = assignments.iter().max().map_or(0, |m| m + 1);
    if k < 2 {
        return (0.0, 0.0);
    }
    let mut sizes = vec![0usize; k];
    for &a in assignments {
        sizes[a] += 1;
    }
    let stride = n.div_ceil(SILHOUETTE_SAMPLE).max(1);
    let sample: Vec<usize> = (0..n).step_by(stride).collect();
    let rows: Vec<ndarray::ArrayView1<f64>> = (0..n).map(|i| records.row(i)).collect();
    let scores: Vec<f64> = sample
        .par_iter()
        .map(|&i| {
            if sizes[assignments[i]] == 1 {
                return 0.0;
            }
            let mut sums = vec![0.0; k];
            for j in 0..n {
                let d: f64 = rows[i].iter().zip(rows[j].iter()).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
                sums[assignments[j]] += d;
            }
            let own = assignments[i];
            let a = sums[own] / (sizes[own] - 1) as f64;
            let b = (0..k)
                .filter(|&c| c != own && sizes[c] > 0)
                .map(|c| sums[c] / sizes[c] as f64)
                .fold(f64::INFINITY, f64::min);
            if a.max(b) > 0.0 { (b - a) / a.max(b) } else { 0.0 }
        })
        .collect();
    let m = scores.len() as f64;
    let mean = scores.iter().sum::<f64>() / m;
    let variance = scores.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (m - 1.0).max(1.0);
    (mean, (variance / m).sqrt())
}

/// Renumbers clusters in order of their first member, so numbering (and
/// the default names p0, p1, …) follows the data, not k-means' seeds.
fn by_first_appearance(assignments: &[usize]) -> Vec<usize> {
    let mut map = std::collections::BTreeMap::new();
    assignments
        .iter()
        .map(|&a| {
            let next = map.len();
            *map.entry(a).or_insert(next)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::hyperparams::ClusterParams;
    use super::*;
    use crate::params::Params;

    /// Three tight blobs in 2-D, interleaved in segment order.
    fn blobs() -> Embedding {
        let centres = [[0.0, 0.0], [5.0, 0.0], [0.0, 5.0]];
        let mut coords = Vec::new();
        for i in 0..60 {
            let c = centres[(i * 7) % 3];
            coords.extend([c[0] + 0.1 * (i as f64).sin(), c[1] + 0.1 * (i as f64).cos()]);
        }
        Embedding::new(coords, 2, Vec::new())
    }

    #[test]
    fn the_number_of_primitives_is_chosen_by_silhouette() {
        let c = ClusterParams::new().check().unwrap().cluster(&blobs(), &[]).unwrap();
        assert_eq!(c.k(), 3);
        assert_eq!(c.choice(), &Choice::Silhouette);
        let best = c.score().unwrap();
        assert!(best > 0.9 && c.scores().iter().all(|t| t.silhouette <= best), "{:?}", c.scores());
        // Numbered by first appearance: segment 0 is in primitive 0.
        assert_eq!(&c.assignments()[..3], &[0, 1, 2]);
    }

    #[test]
    fn a_given_k_is_used_and_too_large_a_k_is_an_error() {
        let params = ClusterParams::new().k(Some(2)).check().unwrap();
        let c = params.cluster(&blobs(), &[]).unwrap();
        assert_eq!((c.k(), c.choice()), (2, &Choice::Given));
        let err = ClusterParams::new().k(Some(61)).check().unwrap().cluster(&blobs(), &[]).unwrap_err();
        assert_eq!(err.to_string(), "k = 61 asks for more primitives than the 60 segments there are");
    }

    #[test]
    fn by_label_each_activity_is_one_cluster_and_the_unlabelled_are_clustered() {
        // Labels that cut across the blobs: the first 30 segments `a`, the
        // next 15 `b`; the last 15 unlabelled, clustered by where they lie.
        let labels: Vec<Option<String>> =
            (0..60).map(|i| [Some("a"), Some("b"), None][i / 30 + i / 45].map(String::from)).collect();
        let c = ClusterParams::new().by_label(true).check().unwrap().cluster(&blobs(), &labels).unwrap();
        assert_eq!(c.choice(), &Choice::ByLabel);
        let a = c.assignments();
        assert!(a[..30].iter().all(|&x| x == 0) && a[30..45].iter().all(|&x| x == 1), "{a:?}");
        // The unlabelled fall in the three blobs, each its own cluster.
        let blob = |i: usize| (i * 7) % 3;
        for i in 45..60 {
            for j in 45..60 {
                assert_eq!(a[i] == a[j], blob(i) == blob(j), "{i} {j}: {a:?}");
            }
        }
        assert_eq!(c.k(), 5);
        let none: Vec<Option<String>> = vec![None; 60];
        let err = ClusterParams::new().by_label(true).check().unwrap().cluster(&blobs(), &none).unwrap_err();
        assert_eq!(err.to_string(), "clustering by label needs labelled segments, and none of the 60 is");
    }

    #[test]
    fn the_same_seed_gives_the_same_clusters() {
        let params = ClusterParams::new().seed(5).check().unwrap();
        assert_eq!(params.cluster(&blobs(), &[]).unwrap(), params.cluster(&blobs(), &[]).unwrap());
    }
}
