//! The Cholesky factorisation of a symmetric positive definite matrix stored by its
//! envelope: each row of the lower triangle from its first nonzero column to the diagonal.
//!
//! The grid fits' Gauss-Newton matrices are banded in the node order (row by row of the
//! grid): a bilinear grid's correspondence weighs the four nodes of its cell, and the free
//! fit's second differences reach two nodes along a row or a column, so a row of unknowns is
//! coupled to at most about two grid rows of nodes on either side. The factor of such a
//! matrix fills in only inside the envelope (George and Liu's profile theorem), so the work
//! is the sum over rows of the squared envelope width instead of a third of the size cubed.
//!
//! Row-oriented (the "bordering" or row Cholesky): entry (i, j) of the factor is
//! (A_ij - <L_i, L_j>) / L_jj over the columns both rows hold, each inner product one
//! contiguous slice against another. The factor is the unique one, up to rounding (a
//! different order of operations than the dense factorisations).
//!
//! Degenerate cases: a matrix that is not positive definite (a pivot zero, negative or not
//! finite) has no factor (`None`); an empty matrix has an empty factor; a zero row off the
//! diagonal has an envelope of the diagonal alone. Only the lower triangle is read.

use nalgebra::{DMatrix, DVector};

/// The lower-triangular factor `L` of `A = L L^T`, row `i` held from column `first[i]`.
pub(super) struct Factor {
    /// The first column of each row's envelope.
    first: Vec<usize>,
    /// Where each row starts in `values` (one more entry: the total length).
    offset: Vec<usize>,
    values: Vec<f64>,
}

/// The first nonzero column of each row of `matrix`'s lower triangle (the diagonal where the
/// row is otherwise zero).
pub(super) fn envelope(matrix: &DMatrix<f64>) -> Vec<usize> {
    (0..matrix.nrows())
        .map(|i| (0..i).find(|&j| matrix[(i, j)] != 0.0).unwrap_or(i))
        .collect()
}

/// The multiply-adds of factorising a matrix of envelope `first`.
pub(super) fn work(first: &[usize]) -> f64 {
    first
        .iter()
        .enumerate()
        .map(|(i, &f)| {
            let w = (i - f) as f64;
            0.5 * w * (w + 1.0)
        })
        .sum()
}

impl Factor {
    /// The factor of the square matrix `matrix` (its lower triangle read) within the
    /// envelope `first` (from [`envelope`]), `None` where it is not positive definite.
    pub(super) fn new(matrix: &DMatrix<f64>, first: Vec<usize>) -> Option<Factor> {
        let n = matrix.nrows();
        debug_assert_eq!(n, matrix.ncols());
        debug_assert_eq!(first.len(), n);
        let mut offset = Vec::with_capacity(n + 1);
        offset.push(0);
        for (i, &f) in first.iter().enumerate() {
            offset.push(offset[i] + i + 1 - f);
        }
        let mut values = vec![0.0; offset[n]];
        for i in 0..n {
            for j in first[i]..=i {
                values[offset[i] + j - first[i]] = matrix[(i, j)];
            }
        }
        for i in 0..n {
            let (done, rest) = values.split_at_mut(offset[i]);
            let row = &mut rest[..i + 1 - first[i]];
            let fi = first[i];
            for j in fi..i {
                let fj = first[j];
                let k0 = fi.max(fj);
                let other = &done[offset[j]..offset[j + 1]];
                let sum = dot(&row[k0 - fi..j - fi], &other[k0 - fj..j - fj]);
                row[j - fi] = (row[j - fi] - sum) / other[j - fj];
            }
            let (off, diagonal) = row.split_at_mut(i - fi);
            let pivot = diagonal[0] - dot(off, off);
            if !(pivot > 0.0 && pivot.is_finite()) {
                return None;
            }
            diagonal[0] = pivot.sqrt();
        }
        values.iter().all(|v| v.is_finite()).then_some(Factor {
            first,
            offset,
            values,
        })
    }

    /// Row `i` of the factor, from column `first[i]` to the diagonal.
    fn row(&self, i: usize) -> &[f64] {
        &self.values[self.offset[i]..self.offset[i + 1]]
    }

    /// The solution `x` of `A x = b`.
    pub(super) fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        let n = self.first.len();
        let mut x = b.clone();
        // L z = b, row by row.
        for i in 0..n {
            let (fi, row) = (self.first[i], self.row(i));
            let sum = dot(&row[..i - fi], &x.as_slice()[fi..i]);
            x[i] = (x[i] - sum) / row[i - fi];
        }
        // L^T x = z, column by column of L^T (row by row of L, last first).
        for i in (0..n).rev() {
            let (fi, row) = (self.first[i], self.row(i));
            x[i] /= row[i - fi];
            let xi = x[i];
            for (value, l) in x.as_mut_slice()[fi..i].iter_mut().zip(row) {
                *value -= l * xi;
            }
        }
        x
    }
}

/// The inner product of two slices of equal length, with four partial sums so that the
/// loop vectorises (floating-point addition is not reordered otherwise).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    let mut sums = [0.0; 4];
    let (a4, a_rest) = a.split_at(a.len() / 4 * 4);
    let (b4, b_rest) = b.split_at(a4.len());
    for (x, y) in a4.chunks_exact(4).zip(b4.chunks_exact(4)) {
        for k in 0..4 {
            sums[k] += x[k] * y[k];
        }
    }
    let tail: f64 = a_rest.iter().zip(b_rest).map(|(x, y)| x * y).sum();
    (sums[0] + sums[1]) + (sums[2] + sums[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A symmetric positive definite matrix of size `n` and half-bandwidth `band` (with
    /// rows of varying width below it) from a seed.
    fn banded_spd(n: usize, band: usize, seed: u64) -> DMatrix<f64> {
        let mut draw = crate::calibrate::grid::tests::lcg_uniform(seed);
        let mut next = || draw() - 0.5;
        let mut a = DMatrix::zeros(n, n);
        for i in 0..n {
            // Every third row narrower: envelopes are not a plain band.
            let width = if i % 3 == 0 { band / 2 } else { band };
            for j in i.saturating_sub(width)..i {
                let v = next();
                a[(i, j)] = v;
                a[(j, i)] = v;
            }
        }
        for i in 0..n {
            let row: f64 = (0..n).map(|j| a[(i, j)].abs()).sum();
            a[(i, i)] = row + 1.0;
        }
        a
    }

    proptest! {
        #[test]
        fn solves_like_the_dense_factor(n in 0usize..60, band in 0usize..20, seed in any::<u64>()) {
            let a = banded_spd(n, band, seed);
            let first = envelope(&a);
            let factor = Factor::new(&a, first).unwrap();
            let b = DVector::from_fn(n, |i, _| (i as f64 * 0.7).sin());
            let ours = factor.solve(&b);
            let theirs = a.clone().cholesky().unwrap().solve(&b);
            prop_assert!((&ours - &theirs).amax() <= 1e-12 * (1.0 + theirs.amax()));
            prop_assert!((&a * &ours - &b).amax() <= 1e-11);
        }
    }

    #[test]
    fn the_envelope_is_the_first_nonzero_column() {
        let mut a = DMatrix::identity(4, 4);
        a[(2, 0)] = 1.0;
        a[(0, 2)] = 1.0;
        a[(3, 2)] = -1.0;
        a[(2, 3)] = -1.0;
        assert_eq!(envelope(&a), vec![0, 1, 0, 2]);
        assert_eq!(work(&[0, 1, 0, 2]), 0.0 + 0.0 + 3.0 + 1.0);
    }

    #[test]
    fn refuses_what_is_not_positive_definite() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let mut a = banded_spd(12, 3, 9);
            a[(7, 7)] = bad;
            assert!(Factor::new(&a, envelope(&a)).is_none(), "{bad}");
        }
        // Positive diagonal, indefinite: [[1, 2], [2, 1]].
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(Factor::new(&a, envelope(&a)).is_none());
        let empty = Factor::new(&DMatrix::zeros(0, 0), Vec::new()).unwrap();
        assert_eq!(empty.solve(&DVector::zeros(0)).len(), 0);
    }
}
