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
    /// The k with the highest mean silhouette.
    Silhouette,
}

/// Segments grouped into primitives.
#[derive(Clone, Debug, PartialEq)]
pub struct Clustering {
    /// Each segment's primitive, numbered by first appearance.
    assignments: Vec<usize>,
    k: usize,
    choice: Choice,
    /// Mean silhouette for every k tried (for `--k`, only that one).
    scores: Vec<(usize, f64)>,
}

impl Clustering {
    /// A clustering read back from a table, with how its k was chosen.
    pub fn recorded(assignments: Vec<usize>, choice: Choice, scores: Vec<(usize, f64)>) -> Clustering {
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

    pub fn scores(&self) -> &[(usize, f64)] {
        &self.scores
    }

    /// The mean silhouette of the chosen k.
    pub fn score(&self) -> Option<f64> {
        self.scores.iter().find(|(k, _)| *k == self.k).map(|(_, s)| *s)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ClusterError {
    #[error("--k {k} asks for more primitives than the {segments} segments there are")]
    TooManyClusters { k: usize, segments: usize },
    #[error("only {0} segments: choosing the number of primitives needs at least 3")]
    TooFewSegments(usize),
    #[error("k-means failed: {0}")]
    KMeans(String),
}

impl ValidClusterParams {
    /// Clusters the embedded segments.
    pub fn cluster(&self, embedding: &Embedding) -> Result<Clustering, ClusterError> {
        let p = self.params();
        let n = embedding.len();
        let records = Array2::from_shape_vec((n, embedding.dims()), embedding.coords().to_vec())
            .map_err(|e| ClusterError::KMeans(e.to_string()))?;
        let (assignments, choice, scores) = match p.k {
            Some(k) => {
                if k > n {
                    return Err(ClusterError::TooManyClusters { k, segments: n });
                }
                let a = self.kmeans(&records, k)?;
                let score = silhouette(&records, &a);
                (a, Choice::Given, vec![(k, score)])
            }
            None => {
                if n < 3 {
                    return Err(ClusterError::TooFewSegments(n));
                }
                // The best of all, and the best with clusters of min_size.
                let mut best: [Option<(f64, Vec<usize>)>; 2] = [None, None];
                let mut scores = Vec::new();
                for k in 2..=p.max_k.min(n - 1) {
                    let a = self.kmeans(&records, k)?;
                    let score = silhouette(&records, &a);
                    scores.push((k, score));
                    let mut sizes = vec![0; k];
                    a.iter().for_each(|&c| sizes[c] += 1);
                    let sized = sizes.iter().all(|&s| s >= p.min_size);
                    for (slot, eligible) in best.iter_mut().zip([true, sized]) {
                        // Strictly better only: ties keep the fewer primitives.
                        if eligible && slot.as_ref().is_none_or(|(s, _)| score > *s) {
                            *slot = Some((score, a.clone()));
                        }
                    }
                }
                let [any, sized] = best;
                let (_, a) = sized.or(any).expect("k = 2 is always tried");
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

/// Points beyond which the silhouette is estimated on an evenly spread
/// sample of this many (it costs a pass over all pairs).
const SILHOUETTE_SAMPLE: usize = 2000;

/// Mean silhouette (Rousseeuw 1987) of a labelling: for each point, how
/// much nearer it is on average to its own cluster (`a`) than to the
/// nearest other (`b`), `(b − a) / max(a, b)`. A point alone in its cluster
/// scores 0, as Rousseeuw defines it. (linfa scores it 1, which rewards
/// splitting points off into clusters of their own: we choose k with this
/// one.)
fn silhouette(records: &Array2<f64>, assignments: &[usize]) -> f64 {
    let n = assignments.len();
    let k = assignments.iter().max().map_or(0, |m| m + 1);
    if k < 2 {
        return 0.0;
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
    scores.iter().sum::<f64>() / scores.len() as f64
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
        let c = ClusterParams::new().check().unwrap().cluster(&blobs()).unwrap();
        assert_eq!(c.k(), 3);
        assert_eq!(c.choice(), &Choice::Silhouette);
        let best = c.score().unwrap();
        assert!(best > 0.9 && c.scores().iter().all(|(_, s)| *s <= best), "{:?}", c.scores());
        // Numbered by first appearance: segment 0 is in primitive 0.
        assert_eq!(&c.assignments()[..3], &[0, 1, 2]);
    }

    #[test]
    fn a_given_k_is_used_and_too_large_a_k_is_an_error() {
        let params = ClusterParams::new().k(Some(2)).check().unwrap();
        let c = params.cluster(&blobs()).unwrap();
        assert_eq!((c.k(), c.choice()), (2, &Choice::Given));
        let err = ClusterParams::new().k(Some(61)).check().unwrap().cluster(&blobs()).unwrap_err();
        assert_eq!(err.to_string(), "--k 61 asks for more primitives than the 60 segments there are");
    }

    #[test]
    fn the_same_seed_gives_the_same_clusters() {
        let params = ClusterParams::new().seed(5).check().unwrap();
        assert_eq!(params.cluster(&blobs()).unwrap(), params.cluster(&blobs()).unwrap());
    }
}
