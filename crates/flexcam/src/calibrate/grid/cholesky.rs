//! The Cholesky factorisation the grid fits solve their Gauss-Newton systems with: stored by
//! its envelope (module `envelope_cholesky`) where the matrix is banded enough for that to
//! be less work, densely by blocks (module `blocked_cholesky`) otherwise. Both are exact;
//! the choice weighs their arithmetic, the dense one's counted at a fraction for its faster
//! matrix-product kernels.
//!
//! The fits' matrices are banded in the node order when the grid interpolates bilinearly
//! (a correspondence weighs the four nodes of its cell) and dense when it interpolates as
//! one Bezier patch (every node weighs every point).
//!
//! A matrix that is a banded one plus a rank-one term v v^T (the free fit's common-slide
//! penalty) is solved through the banded one's factor by the Sherman-Morrison formula
//! ([`RankOneUpdated`]).
//!
//! Degenerate cases: a matrix that is not positive definite has no factor (`None`); an
//! empty matrix has an empty factor.

use nalgebra::{DMatrix, DVector};

use super::{blocked_cholesky, envelope_cholesky};

/// How many times faster per multiply-add the dense blocked factorisation runs than the
/// envelope one (its inner loops are `matrixmultiply`'s kernels; the envelope's are inner
/// products of slices), rounded up. Measured with `flexcam fit` on free fits of 1,000 points
/// (docs/log/fitspeed.md): the envelope was faster on 5 x 5, 7 x 7 and 9 x 9 grids.
const DENSE_SPEEDUP: f64 = 1.5;

/// The factor of a symmetric positive definite matrix.
pub(super) enum Factor {
    Dense(blocked_cholesky::Factor),
    Envelope(envelope_cholesky::Factor),
}

impl Factor {
    /// The factor of the square matrix `matrix` (its lower triangle read), `None` where it is
    /// not positive definite.
    pub(super) fn new(matrix: DMatrix<f64>) -> Option<Factor> {
        let first = envelope_cholesky::envelope(&matrix);
        let n = matrix.nrows() as f64;
        if envelope_cholesky::work(&first) * DENSE_SPEEDUP < n * n * n / 6.0 {
            envelope_cholesky::Factor::new(&matrix, first).map(Factor::Envelope)
        } else {
            blocked_cholesky::Factor::new(matrix).map(Factor::Dense)
        }
    }

    /// The solution `x` of `A x = b`.
    pub(super) fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        match self {
            Factor::Dense(factor) => factor.solve(b),
            Factor::Envelope(factor) => factor.solve(b),
        }
    }
}

/// The solver of `(B + v v^T) x = b` from the factor of `B`: x = B^-1 b - B^-1 v (v^T B^-1 b)
/// / (1 + v^T B^-1 v) (Sherman and Morrison). With `B` positive definite, `1 + v^T B^-1 v`
/// is at least 1, so the update never divides by zero.
pub(super) struct RankOneUpdated {
    factor: Factor,
    /// B^-1 v and v (empty for no update).
    solved: DVector<f64>,
    v: DVector<f64>,
    denominator: f64,
}

impl RankOneUpdated {
    /// The solver for `factor`'s matrix plus `v v^T` (`None`: the matrix alone).
    pub(super) fn new(factor: Factor, v: Option<&DVector<f64>>) -> Self {
        match v {
            Some(v) => {
                let solved = factor.solve(v);
                let denominator = 1.0 + v.dot(&solved);
                Self {
                    factor,
                    solved,
                    v: v.clone(),
                    denominator,
                }
            }
            None => Self {
                factor,
                solved: DVector::zeros(0),
                v: DVector::zeros(0),
                denominator: 1.0,
            },
        }
    }

    /// The solution `x` of `(B + v v^T) x = b`.
    pub(super) fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        let mut x = self.factor.solve(b);
        if !self.v.is_empty() {
            x -= (self.v.dot(&x) / self.denominator) * &self.solved;
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn banded_and_dense_matrices_take_their_factorisations() {
        let n = 200;
        let mut banded = DMatrix::identity(n, n) * 4.0;
        for i in 1..n {
            banded[(i, i - 1)] = -1.0;
            banded[(i - 1, i)] = -1.0;
        }
        assert!(matches!(
            Factor::new(banded.clone()),
            Some(Factor::Envelope(_))
        ));
        let dense = DMatrix::from_fn(n, n, |i, j| if i == j { n as f64 } else { 0.5 });
        assert!(matches!(Factor::new(dense), Some(Factor::Dense(_))));
        let b = DVector::from_fn(n, |i, _| i as f64);
        let x = Factor::new(banded.clone()).unwrap().solve(&b);
        assert!((&banded * x - &b).amax() < 1e-10);
    }

    #[test]
    fn the_rank_one_update_solves_the_whole_matrix() {
        let n = 30;
        let mut banded = DMatrix::identity(n, n) * 3.0;
        for i in 1..n {
            banded[(i, i - 1)] = 1.0;
            banded[(i - 1, i)] = 1.0;
        }
        let v = DVector::from_fn(n, |i, _| (i as f64).cos());
        let whole = &banded + &v * v.transpose();
        let b = DVector::from_fn(n, |i, _| (i as f64 * 0.3).sin());
        let solver = RankOneUpdated::new(Factor::new(banded.clone()).unwrap(), Some(&v));
        assert!((&whole * solver.solve(&b) - &b).amax() < 1e-12);
        let plain = RankOneUpdated::new(Factor::new(banded.clone()).unwrap(), None);
        assert!((&banded * plain.solve(&b) - &b).amax() < 1e-12);
    }
}
