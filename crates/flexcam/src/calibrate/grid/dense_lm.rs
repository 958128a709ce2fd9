//! Levenberg-Marquardt with Marquardt's diagonal damping for the small dense problems of the
//! central fits: the general camera matrix (module `camera_matrix`, 12 unknowns) and the
//! square-pixel pinhole camera (module `pinhole_camera`, 6 or 7). The grids' own fits are
//! large and banded and have their own driver (module `angular`).
//!
//! Each step solves `(J^T J + lambda diag(J^T J)) delta = J^T r` (diagonal entries at least
//! 1e-12) and takes `x - delta`; a step that does not lower the cost is refused and `lambda`
//! grown tenfold, at most [`DAMPING_TRIALS`] times a step; an accepted step shrinks it
//! tenfold (not below 1e-12). The iteration stops when no trial lowers the cost, or when the
//! accepted step gained under 1e-15 of the cost, or after the caller's iteration cap.

use nalgebra::{DMatrix, DVector};

/// Damping values tried per step before the iteration stops.
const DAMPING_TRIALS: usize = 12;

/// Minimises the sum of squared residuals from `start` (module docs): `residuals(x)` is
/// `None` outside the problem's domain (a point behind the camera), which refuses a step
/// there; `jacobian(x)` the residuals' derivative in the unknowns; `step(x, delta)` the point
/// `x - delta` (`None` refuses it: a focal length not positive). The point reached and its
/// cost, or `None` where `start` itself has no residuals.
pub(super) fn minimise<P>(
    start: P,
    max_iterations: usize,
    residuals: impl Fn(&P) -> Option<Vec<f64>>,
    jacobian: impl Fn(&P) -> DMatrix<f64>,
    step: impl Fn(&P, &DVector<f64>) -> Option<P>,
) -> Option<(P, f64)> {
    let cost_of = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut r = residuals(&start)?;
    let (mut x, mut cost) = (start, cost_of(&r));
    let mut damping = 1e-3;
    for _ in 0..max_iterations {
        let j = jacobian(&x);
        let jtj = j.transpose() * &j;
        let jtr = j.transpose() * DVector::from_column_slice(&r);
        let mut improved = false;
        for _ in 0..DAMPING_TRIALS {
            let mut damped = jtj.clone();
            for i in 0..jtj.nrows() {
                damped[(i, i)] += damping * jtj[(i, i)].max(1e-12);
            }
            let Some(delta) = damped.cholesky().map(|ch| ch.solve(&jtr)) else {
                damping *= 10.0;
                continue;
            };
            if let Some((next, r_next)) = step(&x, &delta).and_then(|next| {
                let r_next = residuals(&next)?;
                Some((next, r_next))
            }) {
                let next_cost = cost_of(&r_next);
                if next_cost < cost {
                    improved = cost - next_cost > 1e-15 * cost;
                    (x, r, cost) = (next, r_next, next_cost);
                    damping = (damping * 0.1).max(1e-12);
                    break;
                }
            }
            damping *= 10.0;
        }
        if !improved {
            break;
        }
    }
    Some((x, cost))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line through points with noise: the least-squares line (the normal equations'
    /// solution) to rounding; a start outside the domain gives none; a refused region is
    /// never entered.
    #[test]
    fn fits_a_line_and_keeps_out_of_refused_regions() {
        let points = [(0.0, 1.1), (1.0, 2.9), (2.0, 5.2), (3.0, 6.8)];
        let residuals = |p: &[f64; 2]| {
            Some(
                points
                    .iter()
                    .flat_map(|&(x, y)| [p[0] * x + p[1] - y])
                    .collect(),
            )
        };
        let jacobian = |_: &[f64; 2]| {
            DMatrix::from_fn(
                points.len(),
                2,
                |k, c| if c == 0 { points[k].0 } else { 1.0 },
            )
        };
        let step = |p: &[f64; 2], d: &DVector<f64>| Some([p[0] - d[0], p[1] - d[1]]);
        let (fit, cost) = minimise([0.0, 0.0], 100, residuals, jacobian, step).unwrap();
        // Normal equations: slope 1.94, intercept 1.09.
        assert!(
            (fit[0] - 1.94).abs() < 1e-9 && (fit[1] - 1.09).abs() < 1e-9,
            "{fit:?}"
        );
        assert!((cost - 0.082).abs() < 1e-9, "{cost}");
        // The intercept may not exceed 1: the fit stops at the boundary's side.
        let bounded = |p: &[f64; 2]| (p[1] <= 1.0).then(|| residuals(p)).flatten();
        let (fit, _) = minimise([0.0, 0.0], 100, bounded, jacobian, step).unwrap();
        assert!(fit[1] <= 1.0, "{fit:?}");
        assert!(minimise([0.0, 2.0], 100, bounded, jacobian, step).is_none());
    }
}
