//! ST-Isomap: neighbourhood graph, temporal shrinking, geodesics, MDS.

use super::hyperparams::ValidEmbedParams;
use crate::mocap::pose::Motion;
use crate::vocab::eigen::{EigenError, top_eigenpairs};
use crate::vocab::phase::ArcPath;
use crate::vocab::segment::Span;
use faer::Mat;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// The embedded segments.
#[derive(Clone, Debug, PartialEq)]
pub struct Embedding {
    /// Row-major `segments × dims` coordinates.
    coords: Vec<f64>,
    dims: usize,
    /// MDS eigenvalues, largest first.
    eigenvalues: Vec<f64>,
    /// Graph edges shrunk as adjacent or common temporal neighbours.
    pub atn_edges: usize,
    pub ctn_edges: usize,
    /// Links added to join separate pieces of the neighbourhood graph.
    pub joined_components: usize,
}

impl Embedding {
    /// Coordinates read back (from a table), with the MDS eigenvalues if
    /// known.
    pub fn new(coords: Vec<f64>, dims: usize, eigenvalues: Vec<f64>) -> Embedding {
        assert_eq!(coords.len() % dims.max(1), 0, "coordinates fill whole rows");
        Embedding { coords, dims, eigenvalues, atn_edges: 0, ctn_edges: 0, joined_components: 0 }
    }

    pub fn dims(&self) -> usize {
        self.dims
    }

    pub fn len(&self) -> usize {
        self.coords.len() / self.dims
    }

    pub fn is_empty(&self) -> bool {
        self.coords.is_empty()
    }

    /// Segment `i`'s coordinates.
    pub fn point(&self, i: usize) -> &[f64] {
        &self.coords[i * self.dims..(i + 1) * self.dims]
    }

    pub fn coords(&self) -> &[f64] {
        &self.coords
    }

    pub fn eigenvalues(&self) -> &[f64] {
        &self.eigenvalues
    }
}

#[derive(Debug, thiserror::Error)]
pub enum EmbedError {
    #[error("only {0} segments: an embedding needs at least 3")]
    TooFewSegments(usize),
    #[error("{segments} segments can be embedded in at most {} dimensions, not the {dims} asked (dims)", .segments - 1)]
    TooManyDims { dims: usize, segments: usize },
    #[error("every segment is the same motion: there is nothing to tell apart")]
    AllIdentical,
    #[error("segment vectors must all have {expected} values; one has {found}")]
    Ragged { expected: usize, found: usize },
    #[error("a segment holds a value that is not finite")]
    NotFinite,
    #[error("the MDS eigen solve failed: {0}")]
    Eigen(#[from] EigenError),
}

/// The joint-space path of `span` resampled to `n` poses evenly spaced
/// along it ([`ArcPath`]) and flattened (`n × DOF` values), so segments of
/// any duration compare point by point. A whole cycle with a registered
/// start (`offset`, a fraction of the cycle) is sampled around the loop
/// from there; anything else from its first frame to its last.
pub fn resample(motion: &Motion, span: Span, n: usize, offset: Option<f64>) -> Vec<f64> {
    let path = ArcPath::new(motion, span);
    (0..n)
        .flat_map(|k| {
            let at = match offset {
                Some(o) => (o + k as f64 / n as f64).rem_euclid(1.0),
                None if n == 1 => 0.0,
                None => k as f64 / (n - 1) as f64,
            };
            path.pose_at(at)
        })
        .collect()
}

impl ValidEmbedParams {
    /// Embeds segment vectors (all of one length). `next[i]` is the segment
    /// that follows `i` directly in its take, if any.
    pub fn embed(&self, vectors: &[Vec<f64>], next: &[Option<usize>]) -> Result<Embedding, EmbedError> {
        let p = self.params();
        let s = vectors.len();
        if s < 3 {
            return Err(EmbedError::TooFewSegments(s));
        }
        if p.dims >= s {
            return Err(EmbedError::TooManyDims { dims: p.dims, segments: s });
        }
        let width = vectors[0].len();
        if let Some(v) = vectors.iter().find(|v| v.len() != width) {
            return Err(EmbedError::Ragged { expected: width, found: v.len() });
        }
        if vectors.iter().flatten().any(|v| !v.is_finite()) {
            return Err(EmbedError::NotFinite);
        }
        let squared = squared_distances(vectors);
        if squared.iter().all(|&d| d <= 1e-18) {
            return Err(EmbedError::AllIdentical);
        }
        let k = p.neighbors.min(s - 1);
        let knn: Vec<Vec<usize>> =
            (0..s).into_par_iter().map(|i| nearest(&squared[i * s..(i + 1) * s], i, k)).collect();
        let mut graph = Graph::new(s);
        let mut atn_edges = 0;
        let mut ctn_edges = 0;
        let previous = invert(next);
        for i in 0..s {
            for &j in &knn[i] {
                let common = p.temporal && common_temporal(i, j, next, &previous, &knn);
                ctn_edges += usize::from(common);
                let factor = if common { p.c_ctn } else { 1.0 };
                graph.link(i, j, squared[i * s + j].sqrt() / factor);
            }
        }
        if p.temporal {
            for (i, n) in next.iter().enumerate() {
                if let Some(j) = *n {
                    atn_edges += 1;
                    graph.link(i, j, squared[i * s + j].sqrt() / p.c_atn);
                }
            }
        }
        let joined_components = graph.join_components(&squared);
        drop(squared);
        // The n × n matrix is freed as soon as its eigenpairs are out.
        let top = {
            let b = geodesic_gram(&graph);
            top_eigenpairs(b.as_ref(), p.dims, p.eigen)?
        };
        let mut coords = Vec::with_capacity(s * p.dims);
        for i in 0..s {
            for (c, &value) in top.values.iter().enumerate() {
                coords.push(top.vectors[(i, c)] * value.max(0.0).sqrt());
            }
        }
        Ok(Embedding { coords, dims: p.dims, eigenvalues: top.values, atn_edges, ctn_edges, joined_components })
    }
}

/// `previous[j] = i` where `next[i] = j`.
fn invert(next: &[Option<usize>]) -> Vec<Option<usize>> {
    let mut previous = vec![None; next.len()];
    for (i, n) in next.iter().enumerate() {
        if let Some(j) = *n {
            previous[j] = Some(i);
        }
    }
    previous
}

/// Neighbours `i` and `j` correspond in time when what follows them (or
/// what precedes them) are neighbours too: the same movement in the same
/// context, not merely a similar pose sequence.
fn common_temporal(i: usize, j: usize, next: &[Option<usize>], previous: &[Option<usize>], knn: &[Vec<usize>]) -> bool {
    let linked = |a: Option<usize>, b: Option<usize>| match (a, b) {
        (Some(a), Some(b)) => a == b || knn[a].contains(&b) || knn[b].contains(&a),
        _ => false,
    };
    linked(next[i], next[j]) || linked(previous[i], previous[j])
}

/// All squared Euclidean distances, row-major `s × s`, from one Gram
/// matrix product of the centred vectors (faer's parallel matmul).
fn squared_distances(vectors: &[Vec<f64>]) -> Vec<f64> {
    let (s, width) = (vectors.len(), vectors[0].len());
    let mean: Vec<f64> = (0..width).map(|c| vectors.iter().map(|v| v[c]).sum::<f64>() / s as f64).collect();
    let x = Mat::<f64>::from_fn(s, width, |i, c| vectors[i][c] - mean[c]);
    let gram = &x * x.transpose();
    let norms: Vec<f64> = (0..s).map(|i| gram[(i, i)]).collect();
    let mut out = vec![0.0; s * s];
    out.par_chunks_mut(s).enumerate().for_each(|(i, row)| {
        for (j, d) in row.iter_mut().enumerate() {
            *d = if i == j { 0.0 } else { (norms[i] + norms[j] - 2.0 * gram[(i, j)]).max(0.0) };
        }
    });
    out
}

/// The `k` nearest others of point `i` given its row of squared
/// distances; ties go to the lower index, so the graph is reproducible.
fn nearest(row: &[f64], i: usize, k: usize) -> Vec<usize> {
    let mut others: Vec<usize> = (0..row.len()).filter(|&j| j != i).collect();
    let order = |a: &usize, b: &usize| row[*a].total_cmp(&row[*b]).then(a.cmp(b));
    if k < others.len() {
        others.select_nth_unstable_by(k - 1, order);
        others.truncate(k);
    }
    others.sort_by(order);
    others
}

/// An undirected weighted graph with sorted adjacency lists.
struct Graph {
    adjacency: Vec<Vec<(usize, f64)>>,
}

impl Graph {
    fn new(n: usize) -> Graph {
        Graph { adjacency: vec![Vec::new(); n] }
    }

    /// Adds edge `i`–`j`, keeping the shorter weight if it exists.
    fn link(&mut self, i: usize, j: usize, weight: f64) {
        for (a, b) in [(i, j), (j, i)] {
            let list = &mut self.adjacency[a];
            match list.binary_search_by(|(n, _)| n.cmp(&b)) {
                Ok(at) => list[at].1 = list[at].1.min(weight),
                Err(at) => list.insert(at, (b, weight)),
            }
        }
    }

    /// Joins separate pieces by their closest pair of points, one link at
    /// a time, until the graph is connected. Returns the links added.
    fn join_components(&mut self, squared: &[f64]) -> usize {
        let n = self.adjacency.len();
        let mut added = 0;
        loop {
            let component = self.components();
            if component.iter().all(|&c| c == 0) {
                return added;
            }
            let mut best = (f64::INFINITY, 0, 0);
            for i in 0..n {
                for j in 0..n {
                    if component[i] == 0 && component[j] != 0 && squared[i * n + j] < best.0 {
                        best = (squared[i * n + j], i, j);
                    }
                }
            }
            self.link(best.1, best.2, best.0.sqrt());
            added += 1;
        }
    }

    /// The component of each node, numbered in order of first appearance.
    fn components(&self) -> Vec<usize> {
        let n = self.adjacency.len();
        let mut component = vec![usize::MAX; n];
        let mut next_id = 0;
        for start in 0..n {
            if component[start] != usize::MAX {
                continue;
            }
            let mut stack = vec![start];
            component[start] = next_id;
            while let Some(a) = stack.pop() {
                for &(b, _) in &self.adjacency[a] {
                    if component[b] == usize::MAX {
                        component[b] = next_id;
                        stack.push(b);
                    }
                }
            }
            next_id += 1;
        }
        component
    }

    /// Shortest path lengths from `source` to every node (Dijkstra).
    fn shortest_paths(&self, source: usize, out: &mut [f64]) {
        out.fill(f64::INFINITY);
        out[source] = 0.0;
        let mut heap = BinaryHeap::new();
        heap.push(Visit { distance: 0.0, node: source });
        while let Some(Visit { distance, node }) = heap.pop() {
            if distance > out[node] {
                continue;
            }
            for &(next, weight) in &self.adjacency[node] {
                let through = distance + weight;
                if through < out[next] {
                    out[next] = through;
                    heap.push(Visit { distance: through, node: next });
                }
            }
        }
    }
}

/// A heap entry ordered so the nearest pops first.
#[derive(PartialEq)]
struct Visit {
    distance: f64,
    node: usize,
}

impl Eq for Visit {}

impl Ord for Visit {
    fn cmp(&self, other: &Self) -> Ordering {
        other.distance.total_cmp(&self.distance).then(other.node.cmp(&self.node))
    }
}

impl PartialOrd for Visit {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Classical MDS's matrix `B = −½ J G² J` for the geodesic distances `G`
/// (all-pairs Dijkstra, one source per task, in parallel).
fn geodesic_gram(graph: &Graph) -> Mat<f64> {
    let n = graph.adjacency.len();
    let mut squared = vec![0.0; n * n];
    squared.par_chunks_mut(n).enumerate().for_each(|(source, row)| {
        graph.shortest_paths(source, row);
        for d in row.iter_mut() {
            *d *= *d;
        }
    });
    let row_means: Vec<f64> = squared.par_chunks(n).map(|row| row.iter().sum::<f64>() / n as f64).collect();
    let grand = row_means.iter().sum::<f64>() / n as f64;
    // Geodesics on an undirected graph are symmetric, so column means are
    // the row means.
    Mat::from_fn(n, n, |i, j| -0.5 * (squared[i * n + j] - row_means[i] - row_means[j] + grand))
}

#[cfg(test)]
mod tests {
    use super::super::hyperparams::EmbedParams;
    use super::*;
    use crate::params::Params;

    /// Points along a spiral arm in 3-D, lifted into 6-D.
    fn spiral(n: usize) -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| {
                let t = 1.0 + 3.0 * i as f64 / n as f64;
                let (x, y) = (t * (2.0 * t).cos(), t * (2.0 * t).sin());
                vec![x, y, 0.3 * t, 0.5 * x - 0.2 * y, 0.1 * t * t, 0.0]
            })
            .collect()
    }

    #[test]
    fn isomap_unrolls_a_spiral_into_its_arc_length_order() {
        let points = spiral(150);
        let params = EmbedParams::new().neighbors(6).dims(1).temporal(false).check().unwrap();
        let e = params.embed(&points, &vec![None; 150]).unwrap();
        let first: Vec<f64> = (0..150).map(|i| e.point(i)[0]).collect();
        let rho = crate::vocab::metrics::spearman(&first, &(0..150).map(|i| i as f64).collect::<Vec<_>>());
        assert!(rho.abs() > 0.999, "ρ = {rho}");
    }

    #[test]
    fn geodesic_distances_follow_the_graph_not_straight_lines() {
        // A path 0–1–2 with unit edges and a far point 3 joined to 2.
        let mut g = Graph::new(4);
        g.link(0, 1, 1.0);
        g.link(1, 2, 1.0);
        g.link(2, 3, 5.0);
        let mut out = vec![0.0; 4];
        g.shortest_paths(0, &mut out);
        assert_eq!(out, vec![0.0, 1.0, 2.0, 7.0]);
        assert_eq!(g.components(), vec![0, 0, 0, 0]);
    }

    #[test]
    fn separate_pieces_are_joined_by_their_closest_pair() {
        let points = vec![vec![0.0], vec![1.0], vec![10.0], vec![11.0]];
        let squared = squared_distances(&points);
        let mut g = Graph::new(4);
        g.link(0, 1, 1.0);
        g.link(2, 3, 1.0);
        assert_eq!(g.join_components(&squared), 1);
        assert!(g.adjacency[1].contains(&(2, 9.0)));
    }

    #[test]
    fn temporal_neighbours_are_pulled_together() {
        // Two interleaved activities: A B A B ...; spatially A and B are
        // far apart but every A is followed by a B.
        let mut points = Vec::new();
        for i in 0..40 {
            let wobble = 0.01 * (i as f64).sin();
            points.push(if i % 2 == 0 { vec![0.0 + wobble, 0.0] } else { vec![10.0 + wobble, 1.0] });
        }
        let next: Vec<Option<usize>> = (0..40).map(|i| (i + 1 < 40).then_some(i + 1)).collect();
        let gap = |temporal: bool| {
            let params = EmbedParams::new().neighbors(4).dims(1).temporal(temporal).c_atn(5.0).check().unwrap();
            let e = params.embed(&points, &next).unwrap();
            (e.point(0)[0] - e.point(1)[0]).abs()
        };
        assert!(gap(true) < 0.5 * gap(false), "{} vs {}", gap(true), gap(false));
    }

    #[test]
    fn bad_inputs_are_errors() {
        let params = EmbedParams::new().dims(2).check().unwrap();
        assert!(matches!(params.embed(&[vec![0.0], vec![1.0]], &[None, None]), Err(EmbedError::TooFewSegments(2))));
        let same = vec![vec![1.0, 2.0]; 5];
        assert!(matches!(params.embed(&same, &[None; 5]), Err(EmbedError::AllIdentical)));
        let ragged = vec![vec![1.0, 2.0], vec![1.0], vec![0.0, 0.0]];
        assert!(matches!(params.embed(&ragged, &[None; 3]), Err(EmbedError::Ragged { .. })));
        let nan = vec![vec![1.0], vec![f64::NAN], vec![0.0]];
        assert!(matches!(params.embed(&nan, &[None; 3]), Err(EmbedError::NotFinite)));
        let few = vec![vec![0.0], vec![1.0], vec![2.0]];
        let too_many = EmbedParams::new().dims(3).check().unwrap();
        assert!(matches!(too_many.embed(&few, &[None; 3]), Err(EmbedError::TooManyDims { .. })));
    }
}
