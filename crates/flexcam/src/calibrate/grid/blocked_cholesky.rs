//! The Cholesky factorisation of the fits' Gauss-Newton matrices by blocks of columns, so
//! that nearly all of its arithmetic is one matrix product per block (nalgebra's `gemm`,
//! which runs large products through `matrixmultiply`'s vectorised kernels) instead of
//! nalgebra's column-by-column `cholesky`, whose inner loops run at a tenth of that speed.
//! A free fit of a 9 x 9 grid has 486 unknowns and factorises its matrix once per
//! Levenberg-Marquardt trial: the factorisation was 80 % of the time of `flexcam fit` with
//! 1,000 correspondences (docs/log/frame28.md).
//!
//! Right-looking: each block of [`BLOCK`] columns is factorised by nalgebra's `cholesky`
//! (its diagonal block), its rows below are multiplied by the inverse of that block's factor
//! (transposed), and their outer product is subtracted from the rest of the matrix. The factor is the unique one
//! (up to rounding, in a different order of operations than the unblocked algorithm).
//!
//! Degenerate cases: a matrix that is not positive definite (a pivot zero, negative or not
//! finite) has no factor (`None`), as with nalgebra's `cholesky`; an empty matrix has an
//! empty factor. Only the lower triangle of the matrix is read.

use nalgebra::{DMatrix, DVector};

/// Columns per block: small enough that the diagonal blocks' unblocked factorisation is a
/// small part of the work, large enough for the products to run at full speed.
const BLOCK: usize = 48;

/// The lower-triangular factor `L` of a symmetric positive definite matrix `A = L L^T`.
pub(super) struct Factor {
    lower: DMatrix<f64>,
}

impl Factor {
    /// The factor of the square matrix `matrix` (its lower triangle read), `None` where it is
    /// not positive definite.
    pub(super) fn new(mut matrix: DMatrix<f64>) -> Option<Factor> {
        let n = matrix.nrows();
        debug_assert_eq!(n, matrix.ncols());
        for k in (0..n).step_by(BLOCK) {
            let width = BLOCK.min(n - k);
            let diagonal = matrix.view((k, k), (width, width)).clone_owned();
            let lower = diagonal.cholesky()?.unpack();
            matrix.view_mut((k, k), (width, width)).copy_from(&lower);
            let below = n - k - width;
            if below == 0 {
                continue;
            }
            // L21 = A21 L11^-T, as a product with the inverse of the small diagonal factor
            // (column by column triangular solves of the whole panel run far slower).
            let inverse = lower.solve_lower_triangular(&DMatrix::identity(width, width))?;
            let solved = matrix.view((k + width, k), (below, width)) * inverse.transpose();
            matrix
                .view_mut((k + width, k), (below, width))
                .copy_from(&solved);
            // A22 -= L21 L21^T (the whole block: the product is the fast path).
            matrix
                .view_mut((k + width, k + width), (below, below))
                .gemm(-1.0, &solved, &solved.transpose(), 1.0);
        }
        matrix.fill_upper_triangle(0.0, 1);
        matrix
            .iter()
            .all(|v| v.is_finite())
            .then_some(Factor { lower: matrix })
    }

    /// The solution `x` of `A x = b`.
    pub(super) fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        let mut x = b.clone();
        self.lower.solve_lower_triangular_mut(&mut x);
        self.lower.tr_solve_lower_triangular_mut(&mut x);
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric positive definite matrix of size `n` from a seed: `M M^T + n I`.
    fn spd(n: usize, seed: u64) -> DMatrix<f64> {
        let mut draw = crate::calibrate::grid::tests::lcg_uniform(seed);
        let mut next = || draw() - 0.5;
        let m = DMatrix::from_fn(n, n, |_, _| next());
        &m * m.transpose() + DMatrix::identity(n, n) * n as f64
    }

    /// The factor and the solutions are nalgebra's, to rounding, at sizes below, at and
    /// across the block size, and the factor is lower triangular.
    #[test]
    fn agrees_with_the_unblocked_factorisation() {
        for (n, seed) in [
            (1, 1),
            (5, 2),
            (47, 3),
            (48, 4),
            (49, 5),
            (130, 6),
            (486, 7),
        ] {
            let a = spd(n, seed);
            let b = DVector::from_fn(n, |i, _| (i as f64 * 0.37).sin());
            let ours = Factor::new(a.clone()).unwrap();
            let theirs = a.clone().cholesky().unwrap();
            let scale = theirs.l().abs().max();
            assert!(
                (&ours.lower - theirs.l()).abs().max() <= 1e-12 * scale,
                "{n}"
            );
            for column in 0..n {
                assert!(
                    (0..column).all(|row| ours.lower[(row, column)] == 0.0),
                    "{n}"
                );
            }
            let x = ours.solve(&b);
            assert!((&a * &x - &b).abs().max() <= 1e-10 * b.abs().max(), "{n}");
        }
    }

    /// Matrices that are not positive definite have no factor, whichever block the failing
    /// pivot lies in; the empty matrix has an empty one.
    #[test]
    fn indefinite_matrices_have_no_factor() {
        for (n, bad) in [(3, 1), (100, 20), (100, 70)] {
            let mut a = spd(n, 9);
            a[(bad, bad)] = -1e6;
            assert!(Factor::new(a).is_none(), "{n} {bad}");
        }
        let mut nan = spd(60, 10);
        nan[(55, 3)] = f64::NAN;
        assert!(Factor::new(nan).is_none());
        let empty = Factor::new(DMatrix::zeros(0, 0)).unwrap();
        assert_eq!(empty.solve(&DVector::zeros(0)).len(), 0);
    }
}
