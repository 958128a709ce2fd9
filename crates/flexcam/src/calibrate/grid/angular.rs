//! Refinement of a straight fit on the angle each projector misses its point by, for data
//! that no grid with the kept starts meets exactly (section "The straight fit" of module `grid`).
//!
//! The linear data term |P_k D(u_k, v_k)|^2 is |D| sin(angle) squared: it is met by a
//! projector pointing away from its point as well as towards it, and it is made small by
//! making D short. Where the starts leave every grid a residual (a near surface off the
//! camera's eye), the linear optimum shrinks the nodes the residual concentrates on towards
//! zero and past it: measured on 12 points (3 x 3 grid, starts 0.5 off the eye),
//! six of nine nodes came out 1e-8 to 2e-7 of the longest's length and two pointed away
//! (86 and 170 degrees off the prior), which `fit` refused as contradictory data.
//!
//! This module minimises instead sum_k |n_k - a_k|^2 + lambda |y - y0|^2, with n_k =
//! D(u_k, v_k) / |D(u_k, v_k)|: the chord between the fitted projector's unit direction
//! and the point's, 2 sin(angle / 2), which no length changes and which is largest (2) for
//! a projector pointing away. Levenberg-Marquardt (Gauss-Newton with Marquardt's
//! diagonal damping) under the fit's scale constraint, from each given start; the lowest
//! cost wins.
//!
//! Degenerate cases: a blended direction of zero length costs the reversed value 4 and
//! contributes no derivative; a start whose scale-row product is not positive (no common
//! positive scale puts it on the constraint) is skipped; when every start is skipped the
//! first start is returned unchanged (the caller's reach check then names the point).

use glam::DVec3;
use nalgebra::{DMatrix, DVector};

use super::cholesky::{Factor, RankOneUpdated};
use super::{Correspondence, System};

/// Iterations at most per start; each is one Cholesky factorisation of the 3 x nodes system
/// per damping trial (by envelope or by blocks, module `cholesky`).
const MAX_ITERATIONS: usize = 60;

/// Iteration stops when one step lowers the cost by less than this fraction of it.
const RELATIVE_DECREASE: f64 = 1e-10;

/// The refined node directions (unscaled, as `System::solve` returns them) from the best of
/// `starts`, with the prior's weight `weight` (at least the system's floor).
pub(super) fn refine(
    system: &System<'_>,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    starts: &[Vec<DVec3>],
    weight: f64,
) -> Vec<DVec3> {
    let lambda = weight.max(system.floor);
    let problem = Problem {
        system,
        correspondences,
        targets,
        lambda,
    };
    let wanted = system.scale_row.norm_squared();
    let mut best: Option<(f64, DVector<f64>)> = None;
    for start in starts {
        let mut y = DVector::from_iterator(
            3 * start.len(),
            start.iter().flat_map(|d| (*d / system.scale).to_array()),
        );
        if wanted > 0.0 {
            let along = system.scale_row.dot(&y);
            if along <= 0.0 || !along.is_finite() {
                continue;
            }
            y *= wanted / along;
        }
        let (cost, y) = minimise(&problem, y, &system.scale_row);
        if best.as_ref().is_none_or(|(c, _)| cost < *c) {
            best = Some((cost, y));
        }
    }
    match best {
        Some((_, y)) => y
            .as_slice()
            .chunks_exact(3)
            .map(|v| system.scale * DVec3::new(v[0], v[1], v[2]))
            .collect(),
        None => starts.first().cloned().unwrap_or_default(),
    }
}

/// The angular least-squares problem in the system's scaled unknowns y.
struct Problem<'a> {
    system: &'a System<'a>,
    correspondences: &'a [Correspondence],
    targets: &'a [DVec3],
    lambda: f64,
}

/// A least-squares cost that Levenberg-Marquardt can minimise: its value and its
/// Gauss-Newton matrix and gradient at given unknowns (shared with module `free`).
pub(super) trait LeastSquares {
    fn cost(&self, y: &DVector<f64>) -> f64;
    /// The Gauss-Newton matrix less its [`LeastSquares::rank_one`] term, and the gradient
    /// of the whole cost.
    fn linearise(&self, y: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>);
    /// A constant term v v^T of the Gauss-Newton matrix that `linearise` leaves out, so that
    /// its matrix keeps the band of the grid's couplings (module `cholesky`); none by default.
    fn rank_one(&self) -> Option<&DVector<f64>> {
        None
    }
}

impl Problem<'_> {
    /// The blended direction at correspondence `c` for unknowns `y`.
    fn direction(&self, c: &Correspondence, y: &DVector<f64>) -> DVec3 {
        let mut d = DVec3::ZERO;
        self.system.prior.for_each_weight(c.uv, |j, w| {
            d += w * DVec3::new(y[3 * j], y[3 * j + 1], y[3 * j + 2]);
        });
        d
    }
}

impl LeastSquares for Problem<'_> {
    fn cost(&self, y: &DVector<f64>) -> f64 {
        let data: f64 = self
            .correspondences
            .iter()
            .zip(self.targets)
            .map(|(c, a)| match self.direction(c, y).try_normalize() {
                Some(n) => (n - *a).length_squared(),
                None => 4.0,
            })
            .sum();
        data + self.lambda * (y - &self.system.prior_dirs).norm_squared()
    }

    /// The Gauss-Newton matrix and gradient at `y`.
    fn linearise(&self, y: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
        let n = y.len();
        let mut matrix = DMatrix::<f64>::zeros(n, n);
        let mut gradient = self.lambda * (y - &self.system.prior_dirs);
        let mut weights = Vec::new();
        for (c, a) in self.correspondences.iter().zip(self.targets) {
            let d = self.direction(c, y);
            let length = d.length();
            let Some(unit) = d.try_normalize() else {
                continue;
            };
            // d n / d D = (I - n n^T) / |D|; residual n - a.
            let off = super::projector_off(unit);
            let jr = (unit.dot(*a) * unit - *a) / length;
            let mut jtj = [[0.0; 3]; 3];
            for (r, row) in jtj.iter_mut().enumerate() {
                for (col, value) in row.iter_mut().enumerate() {
                    *value = off[r][col] / (length * length);
                }
            }
            weights.clear();
            self.system
                .prior
                .for_each_weight(c.uv, |j, w| weights.push((j, w)));
            for &(j, wj) in &weights {
                for r in 0..3 {
                    gradient[3 * j + r] += wj * jr[r];
                }
                for &(l, wl) in &weights {
                    super::add_block(&mut matrix, j, l, wj * wl, &jtj);
                }
            }
        }
        for i in 0..n {
            matrix[(i, i)] += self.lambda;
        }
        (matrix, gradient)
    }
}

/// Levenberg-Marquardt (Marquardt's diagonal damping) on `problem` from `y`, keeping the
/// linear constraint `row . y` at its starting value (no constraint when `row` is zero);
/// returns the final cost and unknowns.
///
/// The damping follows Nielsen's rule (Madsen, Nielsen and Tingleff, "Methods for
/// non-linear least squares problems", 3.2): after a step that lowers the cost it is scaled
/// by max(1/3, 1 - (2 rho - 1)^3), rho the actual decrease over the decrease the
/// Gauss-Newton model predicted, so a step that does as predicted leaves it nearly where it
/// was; after a failed step it grows by a factor that doubles with each failure. (Dividing
/// it by ten after every success, as before, made every second factorisation a failed
/// trial on the free fits: measured, 120 factorisations for 60 steps.)
pub(super) fn minimise(
    problem: &impl LeastSquares,
    mut y: DVector<f64>,
    row: &DVector<f64>,
) -> (f64, DVector<f64>) {
    let constrained = row.norm_squared() > 0.0;
    let rank_one = problem.rank_one();
    let mut cost = problem.cost(&y);
    let mut damping = 1e-3;
    for _ in 0..MAX_ITERATIONS {
        let (matrix, gradient) = problem.linearise(&y);
        let mut improved = None;
        let mut growth = 2.0;
        while damping < 1e12 {
            // Marquardt's damping scales the whole matrix's diagonal, the rank-one term's
            // part of it included.
            let mut damped = matrix.clone();
            for i in 0..damped.nrows() {
                let whole = matrix[(i, i)] + rank_one.map_or(0.0, |v| v[i] * v[i]);
                damped[(i, i)] += damping * whole;
            }
            let Some(factor) = Factor::new(damped) else {
                damping *= growth;
                growth *= 2.0;
                continue;
            };
            let solver = RankOneUpdated::new(factor, rank_one);
            let mut step = solver.solve(&(-&gradient));
            if constrained {
                // Keep row . y fixed: remove the step's component along the constraint
                // in the damped metric (Lagrange multiplier).
                let along = solver.solve(row);
                step -= (row.dot(&step) / row.dot(&along)) * along;
            }
            let trial = &y + &step;
            let trial_cost = problem.cost(&trial);
            if trial_cost < cost {
                // The model's decrease: -(2 g . h + h^T A h), A the undamped matrix
                // (the cost is the plain sum of squares, g = J^T r).
                let curvature =
                    step.dot(&(&matrix * &step)) + rank_one.map_or(0.0, |v| v.dot(&step).powi(2));
                let predicted = -(2.0 * gradient.dot(&step) + curvature);
                let rho = (cost - trial_cost) / predicted;
                let scale = if rho.is_finite() && rho > 0.0 {
                    (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0)
                } else {
                    1.0
                };
                damping = (damping * scale).max(1e-12);
                improved = Some((trial_cost, trial));
                break;
            }
            damping *= growth;
            growth *= 2.0;
        }
        let Some((trial_cost, trial)) = improved else {
            break;
        };
        let decrease = cost - trial_cost;
        y = trial;
        cost = trial_cost;
        if decrease <= RELATIVE_DECREASE * cost {
            break;
        }
    }
    (cost, y)
}
