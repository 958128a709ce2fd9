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

use super::blocked_cholesky::Factor;
use super::{Correspondence, System};

/// Iterations at most per start; each is one Cholesky factorisation of the 3 x nodes system
/// per damping trial (by blocks, module `blocked_cholesky`).
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
    fn linearise(&self, y: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>);
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
pub(super) fn minimise(
    problem: &impl LeastSquares,
    mut y: DVector<f64>,
    row: &DVector<f64>,
) -> (f64, DVector<f64>) {
    let constrained = row.norm_squared() > 0.0;
    let mut cost = problem.cost(&y);
    let mut damping = 1e-3;
    for _ in 0..MAX_ITERATIONS {
        let (matrix, gradient) = problem.linearise(&y);
        let mut improved = None;
        while damping < 1e12 {
            let mut damped = matrix.clone();
            for i in 0..damped.nrows() {
                damped[(i, i)] *= 1.0 + damping;
            }
            let Some(factor) = Factor::new(damped) else {
                damping *= 10.0;
                continue;
            };
            let mut step = factor.solve(&(-&gradient));
            if constrained {
                // Keep row . y fixed: remove the step's component along the constraint
                // in the damped metric (Lagrange multiplier).
                let along = factor.solve(row);
                step -= (row.dot(&step) / row.dot(&along)) * along;
            }
            let trial = &y + &step;
            let trial_cost = problem.cost(&trial);
            if trial_cost < cost {
                improved = Some((trial_cost, trial));
                damping = (damping * 0.1).max(1e-12);
                break;
            }
            damping *= 10.0;
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
