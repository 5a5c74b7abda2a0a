//! k-nearest-neighbour search over training poses, by kiddo's k-d trees.
//! kiddo fixes the dimension at compile time; latent spaces choose theirs
//! from the data, so one tree type per dimension is instantiated and the
//! right one picked at run time.

use crate::mocap::body::DOF;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZeroUsize;

/// The largest latent dimension a primitive may have.
pub const MAX_LATENT_DIMS: usize = 12;

/// Nearest-neighbour search over a fixed set of points.
pub struct KnnIndex {
    search: Box<dyn Search>,
    dims: usize,
    len: usize,
}

impl std::fmt::Debug for KnnIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "KnnIndex {{ dims: {}, len: {} }}", self.dims, self.len)
    }
}

trait Search: Send + Sync {
    /// The `k` nearest points to `query` as (index, distance), nearest first.
    fn nearest(&self, query: &[f64], k: NonZeroUsize, out: &mut Vec<(usize, f64)>);
}

struct Tree<const K: usize>(ImmutableKdTree<f64, K>);

impl<const K: usize> Search for Tree<K> {
    fn nearest(&self, query: &[f64], k: NonZeroUsize, out: &mut Vec<(usize, f64)>) {
        let point: [f64; K] = query.try_into().expect("the query has the index's dimension");
        let found = self.0.query(&point).nearest_n::<SquaredEuclidean<f64>>(k).execute();
        out.extend(found.iter().map(|r| (r.item as usize, r.distance.sqrt())));
    }
}

fn tree<const K: usize>(points: &[f64]) -> Box<dyn Search> {
    let rows: Vec<[f64; K]> =
        points.chunks_exact(K).map(|c| c.try_into().expect("chunks_exact gives K values")).collect();
    Box::new(Tree(ImmutableKdTree::new_from_slice(&rows).expect("a non-empty set of finite points builds a tree")))
}

impl KnnIndex {
    /// Indexes row-major points of dimension `dims` (1 to
    /// [`MAX_LATENT_DIMS`], or the joint-space dimension). `None` for an
    /// unsupported dimension, no points, or non-finite coordinates.
    pub fn new(points: &[f64], dims: usize) -> Option<KnnIndex> {
        if dims == 0 || points.is_empty() || !points.len().is_multiple_of(dims) || points.iter().any(|v| !v.is_finite())
        {
            return None;
        }
        let search = match dims {
            1 => tree::<1>(points),
            2 => tree::<2>(points),
            3 => tree::<3>(points),
            4 => tree::<4>(points),
            5 => tree::<5>(points),
            6 => tree::<6>(points),
            7 => tree::<7>(points),
            8 => tree::<8>(points),
            9 => tree::<9>(points),
            10 => tree::<10>(points),
            11 => tree::<11>(points),
            12 => tree::<12>(points),
            DOF => tree::<DOF>(points),
            _ => return None,
        };
        Some(KnnIndex { search, dims, len: points.len() / dims })
    }

    pub fn dims(&self) -> usize {
        self.dims
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The `k` nearest points (at most all of them) as (index, Euclidean
    /// distance), nearest first, written into `out` (cleared first).
    pub fn nearest(&self, query: &[f64], k: usize, out: &mut Vec<(usize, f64)>) {
        out.clear();
        if let Some(k) = NonZeroUsize::new(k.min(self.len)) {
            self.search.nearest(query, k, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_same_neighbours_as_brute_force_in_every_supported_dimension() {
        for dims in (1..=MAX_LATENT_DIMS).chain([DOF]) {
            let points: Vec<f64> = (0..300 * dims).map(|i| ((i * 7919) % 1000) as f64 / 1000.0).collect();
            let index = KnnIndex::new(&points, dims).unwrap();
            let query: Vec<f64> = (0..dims).map(|c| 0.37 + 0.01 * c as f64).collect();
            let mut found = Vec::new();
            index.nearest(&query, 5, &mut found);
            let mut brute: Vec<(usize, f64)> = points
                .chunks_exact(dims)
                .enumerate()
                .map(|(i, p)| (i, p.iter().zip(&query).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt()))
                .collect();
            brute.sort_by(|a, b| a.1.total_cmp(&b.1));
            for (f, b) in found.iter().zip(&brute) {
                assert!((f.1 - b.1).abs() < 1e-12, "dims {dims}: {found:?} vs {:?}", &brute[..5]);
            }
        }
    }

    #[test]
    fn unsupported_dimensions_and_bad_points_are_refused() {
        assert!(KnnIndex::new(&[0.0; 13], 13).is_none());
        assert!(KnnIndex::new(&[], 2).is_none());
        assert!(KnnIndex::new(&[0.0, f64::NAN], 2).is_none());
    }

    #[test]
    fn asking_for_more_neighbours_than_points_gives_them_all() {
        let index = KnnIndex::new(&[0.0, 1.0, 2.0], 1).unwrap();
        let mut out = Vec::new();
        index.nearest(&[0.9], 10, &mut out);
        assert_eq!(out.iter().map(|o| o.0).collect::<Vec<_>>(), vec![1, 0, 2]);
    }
}
