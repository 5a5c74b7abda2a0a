//! Top eigenpairs of large symmetric matrices.
//!
//! Classical MDS, the last step of ST-Isomap, needs the few eigenpairs with
//! the largest eigenvalues of the double-centred squared geodesic distance
//! matrix: dense, symmetric, n up to several thousand, and (geodesics not
//! being Euclidean) with negative eigenvalues, some of them large.
//!
//! Two methods give the same answer:
//!
//! - [`EigenMethod::Full`]: faer's dense self-adjoint decomposition, O(n³),
//!   then the last `d` pairs of its ascending spectrum;
//! - [`EigenMethod::Subspace`]: a thick-restarted block Krylov (block
//!   Lanczos) method. Each cycle grows an orthonormal basis by multiplying
//!   the newest block by `A`, O(n²·(d + p)) per block, then keeps the
//!   `d + p` Ritz vectors with the largest *algebraic* Ritz values. A Krylov
//!   space finds both ends of the spectrum quickly, so large negative
//!   eigenvalues cost nothing but do not steal the selection, which a power
//!   iteration (converging to the largest |λ|) would let them do.
//!
//! [`EigenMethod::Auto`] picks by size; `benches/eigen.rs` measures the
//! crossover behind [`AUTO_ROWS_PER_COLUMN`].
//!
//! Parallelism: faer's global setting ([`faer::get_global_parallelism`])
//! for the dense decomposition and every product with `A`; the Krylov
//! method's small operations on its thin basis run on one thread.
//!
//! Scratch: `Full` holds the n × n eigenvector matrix; `Subspace` holds two
//! n × 4(d + 10) blocks (the basis and its image under `A`).

use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{ComputeEigenvectors, self_adjoint_evd, self_adjoint_evd_scratch};
use faer::linalg::householder::{
    apply_block_householder_sequence_on_the_left_in_place_scratch,
    apply_block_householder_sequence_on_the_left_in_place_with_conj,
};
use faer::linalg::matmul::matmul;
use faer::linalg::qr::no_pivoting::factor::{qr_in_place, qr_in_place_scratch, recommended_block_size};
use faer::{Accum, ColRef, Conj, Mat, MatRef, Par, Side, get_global_parallelism};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// How [`top_eigenpairs`] computes its answer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EigenMethod {
    /// `Subspace` from n ≥ [`AUTO_ROWS_PER_COLUMN`] · (d + 10) rows, `Full`
    /// below; falls back to `Full` if `Subspace` has not converged after
    /// about the work of a full decomposition.
    #[default]
    Auto,
    /// faer's dense self-adjoint eigendecomposition.
    Full,
    /// Thick-restarted block Krylov iteration with Rayleigh–Ritz.
    Subspace,
}

/// The top eigenpairs of a symmetric matrix, with how they were found.
#[derive(Clone, Debug)]
pub struct TopEigen {
    /// The `d` largest eigenvalues, in descending order.
    pub values: Vec<f64>,
    /// n × d: column `j` is the unit eigenvector of `values[j]`, its
    /// largest-magnitude entry positive.
    pub vectors: Mat<f64>,
    /// The method that produced the result (never `Auto`).
    pub method: EigenMethod,
    /// Restart cycles of `Subspace` (each a Rayleigh–Ritz step); 0 for `Full`.
    pub iterations: usize,
    /// max ‖Av − λv‖₂ over the returned pairs, recomputed from `A`.
    pub max_residual: f64,
}

#[derive(Clone, Debug, thiserror::Error)]
pub enum EigenError {
    #[error("an eigendecomposition needs a square matrix, not {rows} × {cols}")]
    NotSquare { rows: usize, cols: usize },
    #[error("cannot take {d} eigenpairs of a {n} × {n} matrix")]
    TooMany { d: usize, n: usize },
    #[error("matrix entry ({row}, {col}) is {value}, not a finite number")]
    NotFinite { row: usize, col: usize, value: f64 },
    #[error("faer's dense self-adjoint eigendecomposition did not converge")]
    DenseNoConvergence,
    #[error(
        "the subspace eigensolver did not converge in {cycles} cycles: residual {residual:e} > tolerance {tolerance:e}"
    )]
    NoConvergence { cycles: usize, residual: f64, tolerance: f64 },
}

/// `Auto` uses `Subspace` from this many rows per column of its block
/// (d + 10). Both methods' costs grow with n, the Krylov one also with the
/// block width, so the crossover moves with d. Measured on geodesic MDS
/// matrices (`benches/eigen.rs`), it lies below n = 120 for d = 2, near 190
/// for d = 4, and between 14 and 18 rows per column for d = 8–12, where it
/// varies with the matrix by a cycle more or less; the losses either side
/// of 16 are a few milliseconds.
pub const AUTO_ROWS_PER_COLUMN: usize = 16;

/// `Subspace` stops when every returned pair has ‖Av − λv‖ at most this
/// times ‖A‖₂ (estimated by the largest |Ritz value| seen).
pub const SUBSPACE_TOLERANCE: f64 = 1e-9;

/// Ritz vectors kept beyond the `d` wanted: the d-th pair then converges at
/// a rate set by the gap to λ_{d+p+1}, not to the (maybe close) λ_{d+1}.
const OVERSAMPLE: usize = 10;
/// The basis grows to this many blocks of `d + OVERSAMPLE` columns between
/// restarts.
const BLOCKS: usize = 4;
/// Spectra met in practice converge in 2–5 cycles; this bounds the rest
/// when `Subspace` is asked for by name.
const MAX_CYCLES: usize = 500;
/// Parallelism of the O(n·m²) work on the thin basis (projections, QR,
/// Rayleigh–Ritz): too little to repay rayon's fork and join, which
/// measured as the larger cost for n in the hundreds.
const THIN: Par = Par::Seq;
/// Fixed, so the same matrix always gives bit-identical output.
const SEED: u64 = 0x1509_e16e;

/// The `d` eigenpairs of the symmetric matrix `a` with the largest
/// eigenvalues, eigenvalues in descending order, eigenvectors as the columns
/// of an n × d matrix (unit length, sign fixed so the largest-magnitude
/// entry of each is positive, so results are reproducible).
///
/// `a` must be symmetric: `Full` reads its lower triangle, `Subspace` all
/// of it.
pub fn top_eigenpairs(a: MatRef<'_, f64>, d: usize, method: EigenMethod) -> Result<TopEigen, EigenError> {
    check(a, d)?;
    let n = a.nrows();
    let (method, fallback) = match method {
        EigenMethod::Auto if n < AUTO_ROWS_PER_COLUMN * (d + OVERSAMPLE) => (EigenMethod::Full, false),
        EigenMethod::Auto => (EigenMethod::Subspace, true),
        other => (other, false),
    };
    if d == 0 {
        return Ok(TopEigen {
            values: Vec::new(),
            vectors: Mat::zeros(n, 0),
            method,
            iterations: 0,
            max_residual: 0.0,
        });
    }
    let par = get_global_parallelism();
    match method {
        // A cycle costs about 6n²(d + 10) flops, the dense route some 5n³:
        // past n / (d + 10) cycles the fallback is the cheaper way on.
        EigenMethod::Subspace if fallback => match subspace(a, d, n / (d + OVERSAMPLE), par) {
            Err(EigenError::NoConvergence { .. }) => full(a, d, par),
            result => result,
        },
        EigenMethod::Subspace => subspace(a, d, MAX_CYCLES, par),
        _ => full(a, d, par),
    }
}

fn check(a: MatRef<'_, f64>, d: usize) -> Result<(), EigenError> {
    let (rows, cols) = a.shape();
    if rows != cols {
        return Err(EigenError::NotSquare { rows, cols });
    }
    if d > rows {
        return Err(EigenError::TooMany { d, n: rows });
    }
    // Column by column: faer stores matrices column-major.
    for col in 0..cols {
        for row in 0..rows {
            let value = a[(row, col)];
            if !value.is_finite() {
                return Err(EigenError::NotFinite { row, col, value });
            }
        }
    }
    Ok(())
}

fn full(a: MatRef<'_, f64>, d: usize, par: Par) -> Result<TopEigen, EigenError> {
    let n = a.nrows();
    let evd = a.self_adjoint_eigen(Side::Lower).map_err(|_| EigenError::DenseNoConvergence)?;
    // faer sorts ascending: the top pairs are the last columns, reversed.
    let s = evd.S().column_vector();
    let values = (0..d).map(|j| s[n - 1 - j]).collect();
    let vectors = Mat::from_fn(n, d, |i, j| evd.U()[(i, n - 1 - j)]);
    Ok(finish(a, values, vectors, EigenMethod::Full, 0, par))
}

fn subspace(a: MatRef<'_, f64>, d: usize, max_cycles: usize, par: Par) -> Result<TopEigen, EigenError> {
    let n = a.nrows();
    let k = (d + OVERSAMPLE).min(n);
    let m = (BLOCKS * k).min(n);
    // `basis` is orthonormal; `image` = A·basis, kept so that Rayleigh–Ritz
    // and the residuals need no extra products with A.
    let mut basis = Mat::<f64>::zeros(n, m);
    let mut image = Mat::<f64>::zeros(n, m);

    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let start = Mat::from_fn(n, k, |_, _| rng.sample::<f64, _>(StandardNormal));
    basis.subcols_mut(0, k).copy_from(thin_q(start));
    matmul(image.subcols_mut(0, k), Accum::Replace, a, basis.subcols(0, k), 1.0, par);
    let mut filled = k;
    // Start of the newest block: the next block is A times it.
    let mut newest = 0;
    let mut norm = 0.0_f64;
    let mut residual = f64::INFINITY;
    for cycle in 1..=max_cycles {
        while filled < m {
            let width = (filled - newest).min(m - filled);
            let block = orthonormal_complement(basis.subcols(0, filled), image.subcols(newest, width));
            basis.subcols_mut(filled, width).copy_from(&block);
            matmul(image.subcols_mut(filled, width), Accum::Replace, a, block.as_ref(), 1.0, par);
            newest = filled;
            filled += width;
        }

        // Rayleigh–Ritz: the eigenpairs of T = VᵀAV are the best
        // approximations within span(V).
        let v = basis.subcols(0, filled);
        let av = image.subcols(0, filled);
        let mut t = Mat::<f64>::zeros(filled, filled);
        matmul(t.as_mut(), Accum::Replace, v.transpose(), av, 1.0, THIN);
        // Rounding leaves T slightly asymmetric; use its symmetric part.
        let t = Mat::from_fn(filled, filled, |i, j| 0.5 * (t[(i, j)] + t[(j, i)]));
        let (theta, u) = small_eigen(t.as_ref())?;
        norm = norm.max(theta[0].abs()).max(theta[filled - 1].abs());
        // The k largest algebraic Ritz values, descending, and their vectors.
        let values: Vec<f64> = (0..k).map(|j| theta[filled - 1 - j]).collect();
        let top = Mat::from_fn(filled, k, |i, j| u[(i, filled - 1 - j)]);
        let mut x = Mat::<f64>::zeros(n, k);
        let mut ax = Mat::<f64>::zeros(n, k);
        matmul(x.as_mut(), Accum::Replace, v, top.as_ref(), 1.0, THIN);
        matmul(ax.as_mut(), Accum::Replace, av, top.as_ref(), 1.0, THIN);

        residual = (0..d).map(|j| residual_norm(ax.col(j), x.col(j), values[j])).fold(0.0, f64::max);
        // A basis spanning the whole space makes Rayleigh–Ritz exact.
        if residual <= SUBSPACE_TOLERANCE * norm || filled == n {
            let vectors = x.subcols(0, d).to_owned();
            return Ok(finish(a, values[..d].to_vec(), vectors, EigenMethod::Subspace, cycle, par));
        }

        // Thick restart: keep the k best Ritz vectors (and their images);
        // the next block, A·X orthogonalised against X, is their residual.
        basis.subcols_mut(0, k).copy_from(&x);
        image.subcols_mut(0, k).copy_from(&ax);
        filled = k;
        newest = 0;
    }
    Err(EigenError::NoConvergence { cycles: max_cycles, residual, tolerance: SUBSPACE_TOLERANCE * norm })
}

/// An orthonormal basis of the part of span(`block`) orthogonal to the
/// orthonormal `basis`. Two rounds of projection and QR: one round leaves
/// errors in proportion to how much of `block` lay in `basis`, which is
/// nearly all of it once the Krylov space stops growing (low-rank `A`).
fn orthonormal_complement(basis: MatRef<'_, f64>, block: MatRef<'_, f64>) -> Mat<f64> {
    let mut q = block.to_owned();
    let mut overlap = Mat::<f64>::zeros(basis.ncols(), block.ncols());
    for _ in 0..2 {
        matmul(overlap.as_mut(), Accum::Replace, basis.transpose(), q.as_ref(), 1.0, THIN);
        matmul(q.as_mut(), Accum::Add, basis, overlap.as_ref(), -1.0, THIN);
        q = thin_q(q);
    }
    q
}

/// The orthonormal factor of the thin Householder QR of `a` (rows ≥ cols).
fn thin_q(mut a: Mat<f64>) -> Mat<f64> {
    let (rows, cols) = a.shape();
    let block_size = recommended_block_size::<f64>(rows, cols);
    let mut coeff = Mat::<f64>::zeros(block_size, cols);
    let scratch = qr_in_place_scratch::<f64>(rows, cols, block_size, THIN, Default::default())
        .or(apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(rows, block_size, cols));
    let mut buffer = MemBuffer::new(scratch);
    qr_in_place(a.as_mut(), coeff.as_mut(), THIN, MemStack::new(&mut buffer), Default::default());
    let mut q = Mat::<f64>::identity(rows, cols);
    apply_block_householder_sequence_on_the_left_in_place_with_conj(
        a.as_ref(),
        coeff.as_ref(),
        Conj::No,
        q.as_mut(),
        THIN,
        MemStack::new(&mut buffer),
    );
    q
}

/// Eigenvalues (ascending) and eigenvectors of the small symmetric `t`.
fn small_eigen(t: MatRef<'_, f64>) -> Result<(Diag<f64>, Mat<f64>), EigenError> {
    let n = t.nrows();
    let mut s = Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    let scratch = self_adjoint_evd_scratch::<f64>(n, ComputeEigenvectors::Yes, THIN, Default::default());
    self_adjoint_evd(
        t,
        s.as_mut(),
        Some(u.as_mut()),
        THIN,
        MemStack::new(&mut MemBuffer::new(scratch)),
        Default::default(),
    )
    .map_err(|_| EigenError::DenseNoConvergence)?;
    Ok((s, u))
}

fn residual_norm(av: ColRef<'_, f64>, v: ColRef<'_, f64>, lambda: f64) -> f64 {
    av.iter().zip(v.iter()).map(|(av, v)| (av - lambda * v).powi(2)).sum::<f64>().sqrt()
}

/// Fixes the signs and measures the residuals of the pairs one method found.
fn finish(
    a: MatRef<'_, f64>,
    values: Vec<f64>,
    mut vectors: Mat<f64>,
    method: EigenMethod,
    iterations: usize,
    par: Par,
) -> TopEigen {
    for col in vectors.col_iter_mut() {
        let peak = (0..col.nrows()).fold(0, |best, i| if col[i].abs() > col[best].abs() { i } else { best });
        if col[peak] < 0.0 {
            for x in col.iter_mut() {
                *x = -*x;
            }
        }
    }
    let mut av = Mat::<f64>::zeros(a.nrows(), values.len());
    matmul(av.as_mut(), Accum::Replace, a, vectors.as_ref(), 1.0, par);
    let max_residual = values
        .iter()
        .enumerate()
        .map(|(j, &value)| residual_norm(av.col(j), vectors.col(j), value))
        .fold(0.0, f64::max);
    TopEigen { values, vectors, method, iterations, max_residual }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gaussian(rows: usize, cols: usize, rng: &mut ChaCha8Rng) -> Mat<f64> {
        Mat::from_fn(rows, cols, |_, _| rng.sample::<f64, _>(StandardNormal))
    }

    /// Q diag(λ) Qᵀ for an orthogonal Q, made exactly symmetric.
    fn with_spectrum(lambda: &[f64], q: MatRef<'_, f64>) -> Mat<f64> {
        let n = lambda.len();
        let scaled = Mat::from_fn(n, n, |i, j| q[(i, j)] * lambda[j]);
        let a = &scaled * q.transpose();
        Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
    }

    /// Classical MDS's B = −½ J D² J, J the centring projector.
    fn double_centre(d2: &Mat<f64>) -> Mat<f64> {
        let n = d2.nrows();
        let mean: Vec<f64> = (0..n).map(|i| (0..n).map(|j| d2[(i, j)]).sum::<f64>() / n as f64).collect();
        let grand = mean.iter().sum::<f64>() / n as f64;
        Mat::from_fn(n, n, |i, j| -0.5 * (d2[(i, j)] - mean[i] - mean[j] + grand))
    }

    /// A noisy Swiss roll (a curved 2-D manifold) turned into 10-D by a
    /// random rotation.
    fn curved_points(n: usize, rng: &mut ChaCha8Rng) -> Vec<[f64; 10]> {
        let rotation = gaussian(10, 10, rng).qr().compute_Q();
        (0..n)
            .map(|_| {
                let t = std::f64::consts::PI * rng.gen_range(1.5..3.0);
                let h = rng.gen_range(0.0..10.0);
                let mut flat = [0.0; 10];
                flat[..4].copy_from_slice(&[t * t.cos(), h, t * t.sin(), 0.5 * (0.7 * h).sin()]);
                let mut p = [0.0; 10];
                for (r, x) in p.iter_mut().enumerate() {
                    *x = (0..10).map(|c| rotation[(r, c)] * flat[c]).sum::<f64>()
                        + 0.05 * rng.sample::<f64, _>(StandardNormal);
                }
                p
            })
            .collect()
    }

    fn squared_distances(points: &[[f64; 10]]) -> Mat<f64> {
        let n = points.len();
        Mat::from_fn(n, n, |i, j| points[i].iter().zip(&points[j]).map(|(a, b)| (a - b).powi(2)).sum())
    }

    /// ST-Isomap's B: squared shortest-path distances on the symmetric
    /// `neighbours`-nearest-neighbour graph of curved points, double-centred.
    fn geodesic_mds(n: usize, neighbours: usize, seed: u64) -> Mat<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let euclid = squared_distances(&curved_points(n, &mut rng));
        let mut geo = Mat::from_fn(n, n, |_, _| f64::INFINITY);
        for i in 0..n {
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| euclid[(i, a)].total_cmp(&euclid[(i, b)]));
            for &j in &order[..=neighbours] {
                let d = euclid[(i, j)].sqrt();
                geo[(i, j)] = d;
                geo[(j, i)] = d;
            }
        }
        // Floyd–Warshall.
        for k in 0..n {
            for j in 0..n {
                let kj = geo[(k, j)];
                for i in 0..n {
                    let through = geo[(i, k)] + kj;
                    if through < geo[(i, j)] {
                        geo[(i, j)] = through;
                    }
                }
            }
        }
        assert!(geo.is_all_finite(), "the neighbour graph is not connected");
        double_centre(&Mat::from_fn(n, n, |i, j| geo[(i, j)].powi(2)))
    }

    fn abs_cos(a: ColRef<'_, f64>, b: ColRef<'_, f64>) -> f64 {
        (a.transpose() * b).abs() / (a.norm_l2() * b.norm_l2())
    }

    /// Values within 1e-9 relative, vectors within |cos| ≥ 1 − 1e-9, unit
    /// length, values descending, residuals within the tolerance.
    fn assert_matches(found: &TopEigen, values: &[f64], vectors: MatRef<'_, f64>, norm: f64) {
        let d = values.len();
        assert_eq!(found.values.len(), d);
        assert_eq!(found.vectors.shape(), (vectors.nrows(), d));
        assert!(found.values.windows(2).all(|w| w[0] >= w[1]), "not descending: {:?}", found.values);
        for (j, (&got, &want)) in found.values.iter().zip(values).enumerate() {
            assert!((got - want).abs() <= 1e-9 * want.abs(), "value {j}: {got} vs {want}");
            let cos = abs_cos(found.vectors.col(j), vectors.col(j));
            assert!(cos >= 1.0 - 1e-9, "vector {j}: |cos| = {cos}");
            assert!((found.vectors.col(j).norm_l2() - 1.0).abs() < 1e-12);
        }
        assert!(found.max_residual <= 1e-9 * norm, "residual {} for ‖A‖ = {norm}", found.max_residual);
    }

    #[test]
    fn both_methods_find_the_largest_algebraic_eigenpairs_despite_larger_negative_ones() {
        let n = 300;
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let q = gaussian(n, n, &mut rng).qr().compute_Q();
        // Six known tops, a gap, a bulk down to −120 and two negative
        // eigenvalues larger in magnitude than any positive one: a power
        // iteration would converge to those.
        let top = [100.0, 80.0, 64.0, 51.2, 41.0, 32.8];
        let mut lambda = top.to_vec();
        lambda.extend((0..n - 8).map(|i| 30.0 - 150.0 * i as f64 / (n - 9) as f64));
        lambda.extend([-250.0, -300.0]);
        let a = with_spectrum(&lambda, q.as_ref());
        for d in [1, 6] {
            for method in [EigenMethod::Full, EigenMethod::Subspace] {
                let found = top_eigenpairs(a.as_ref(), d, method).unwrap();
                assert_eq!(found.method, method);
                assert_matches(&found, &top[..d], q.subcols(0, d), 300.0);
            }
        }
    }

    #[test]
    fn subspace_agrees_with_full_on_a_geodesic_mds_matrix() {
        let b = geodesic_mds(400, 8, 2);
        let spectrum = b.self_adjoint_eigenvalues(Side::Lower).unwrap();
        let norm = spectrum[0].abs().max(spectrum[spectrum.len() - 1].abs());
        // Graph geodesics are not Euclidean: B has clearly negative eigenvalues.
        assert!(spectrum[0] < -1e-3 * norm, "smallest eigenvalue {}", spectrum[0]);
        let full = top_eigenpairs(b.as_ref(), 8, EigenMethod::Full).unwrap();
        let subspace = top_eigenpairs(b.as_ref(), 8, EigenMethod::Subspace).unwrap();
        assert_matches(&full, &full.values, full.vectors.as_ref(), norm);
        assert_matches(&subspace, &full.values, full.vectors.as_ref(), norm);
        // Same sign convention, so the vectors agree entry by entry.
        let entries = (0..400).flat_map(|i| (0..8).map(move |j| (i, j)));
        let diff = entries.map(|(i, j)| (subspace.vectors[(i, j)] - full.vectors[(i, j)]).abs()).fold(0.0, f64::max);
        assert!(diff < 1e-6, "largest entry difference {diff}");
    }

    #[test]
    fn same_input_gives_bit_identical_output() {
        let b = geodesic_mds(250, 8, 3);
        for method in [EigenMethod::Full, EigenMethod::Subspace] {
            let first = top_eigenpairs(b.as_ref(), 5, method).unwrap();
            let second = top_eigenpairs(b.as_ref(), 5, method).unwrap();
            let bits = |t: &TopEigen| {
                let mut bits: Vec<u64> = t.values.iter().map(|v| v.to_bits()).collect();
                bits.extend(t.vectors.col_iter().flat_map(|c| c.iter().map(|v| v.to_bits()).collect::<Vec<_>>()));
                bits
            };
            assert_eq!(bits(&first), bits(&second), "{method:?}");
            assert_eq!(first.iterations, second.iterations);
        }
    }

    #[test]
    fn subspace_handles_low_rank_zero_tiny_and_empty_requests() {
        // Euclidean MDS of 3-D points has rank 3: asking for 5 pairs gives
        // three real ones and two orthonormal vectors of eigenvalue 0.
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let points: Vec<[f64; 10]> = (0..300)
            .map(|_| {
                let mut p = [0.0; 10];
                p[..3].iter_mut().for_each(|x| *x = rng.sample(StandardNormal));
                p
            })
            .collect();
        let b = double_centre(&squared_distances(&points));
        let full = top_eigenpairs(b.as_ref(), 3, EigenMethod::Full).unwrap();
        let norm = full.values[0];
        let found = top_eigenpairs(b.as_ref(), 5, EigenMethod::Subspace).unwrap();
        let top = TopEigen {
            values: found.values[..3].to_vec(),
            vectors: found.vectors.subcols(0, 3).to_owned(),
            ..found.clone()
        };
        assert_matches(&top, &full.values, full.vectors.as_ref(), norm);
        assert!(found.values[3..].iter().all(|v| v.abs() <= 1e-9 * norm), "{:?}", found.values);
        let gram = found.vectors.transpose() * &found.vectors;
        assert!((&gram - Mat::<f64>::identity(5, 5)).norm_max() < 1e-12);
        assert!(found.max_residual <= 1e-9 * norm);

        let zero = Mat::<f64>::zeros(50, 50);
        let found = top_eigenpairs(zero.as_ref(), 3, EigenMethod::Subspace).unwrap();
        assert_eq!(found.values, [0.0; 3]);
        let gram = found.vectors.transpose() * &found.vectors;
        assert!((&gram - Mat::<f64>::identity(3, 3)).norm_max() < 1e-12);

        // Fewer rows than the oversampled block: one exact Rayleigh–Ritz step.
        let a = with_spectrum(&[3.0, -7.0, 2.0, 1.0, 0.5], gaussian(5, 5, &mut rng).qr().compute_Q().as_ref());
        let full = top_eigenpairs(a.as_ref(), 2, EigenMethod::Full).unwrap();
        let found = top_eigenpairs(a.as_ref(), 2, EigenMethod::Subspace).unwrap();
        assert_eq!(found.iterations, 1);
        assert_matches(&found, &[3.0, 2.0], full.vectors.as_ref(), 7.0);

        let none = top_eigenpairs(a.as_ref(), 0, EigenMethod::Subspace).unwrap();
        assert!(none.values.is_empty());
        assert_eq!(none.vectors.shape(), (5, 0));
    }

    #[test]
    fn auto_uses_full_for_small_matrices_and_subspace_for_large_ones() {
        // d = 8: the block has 18 columns.
        let small = geodesic_mds(18 * AUTO_ROWS_PER_COLUMN - 1, 8, 5);
        assert_eq!(top_eigenpairs(small.as_ref(), 8, EigenMethod::Auto).unwrap().method, EigenMethod::Full);
        let large = geodesic_mds(18 * AUTO_ROWS_PER_COLUMN, 8, 5);
        assert_eq!(top_eigenpairs(large.as_ref(), 8, EigenMethod::Auto).unwrap().method, EigenMethod::Subspace);
        // A wider block for more pairs moves the crossover past this n.
        assert_eq!(top_eigenpairs(large.as_ref(), 60, EigenMethod::Auto).unwrap().method, EigenMethod::Full);
    }

    #[test]
    fn bad_input_gives_a_clear_error() {
        let a = Mat::<f64>::identity(4, 4);
        let err = top_eigenpairs(a.as_ref(), 5, EigenMethod::Auto).unwrap_err();
        assert!(matches!(err, EigenError::TooMany { d: 5, n: 4 }));
        assert_eq!(err.to_string(), "cannot take 5 eigenpairs of a 4 × 4 matrix");

        let wide = Mat::<f64>::zeros(3, 4);
        let err = top_eigenpairs(wide.as_ref(), 1, EigenMethod::Subspace).unwrap_err();
        assert!(matches!(err, EigenError::NotSquare { rows: 3, cols: 4 }));
        assert_eq!(err.to_string(), "an eigendecomposition needs a square matrix, not 3 × 4");

        let mut nan = Mat::<f64>::identity(4, 4);
        nan[(2, 1)] = f64::NAN;
        let err = top_eigenpairs(nan.as_ref(), 1, EigenMethod::Full).unwrap_err();
        assert!(matches!(err, EigenError::NotFinite { row: 2, col: 1, .. }));
        assert_eq!(err.to_string(), "matrix entry (2, 1) is NaN, not a finite number");
    }
}
