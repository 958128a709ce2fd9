//! The fit of a grid with curved node projectors (quadratic Bezier curves leaving their start
//! along a tangent, module `projector_grid`) by nonlinear least squares.
//!
//! # The problem
//!
//! As in the straight fit, the starts S_j stay (the image plane), and so do the node
//! projectors' lengths L_j = |E_j - S_j|, taken from the prior (as sampled, placed or
//! aimed); the unknowns of every node that some correspondence constrains are the direction
//! D_j of its end, E_j = S_j + L_j D_j, and its unit tangent T_j, which give its control
//! point C_j = S_j + (L_j / 2) T_j. The projector of (u, v) is the
//! quadratic B(t) = (1 - t)^2 S + 2 t (1 - t) C + t^2 E of the blended S, C and E, and
//! correspondence k asks that B_k(t_k) = X_k for some depth t_k, a further unknown. The fit
//! minimises
//!
//! sum_k |B_k(t_k) - X_k|^2 / rho_k^2 + lambda sum_j (|D_j - D0_j|^2 + |T_j - T0_j|^2)
//!
//! with rho_k = |X_k - S_k| (so each term is about the squared angle the point is off its
//! projector, seen from the start, as in the straight fit's report), D0, T0 the straight fit
//! the iteration starts from (its directions, tangents along them), and lambda [`PRIOR_WEIGHT`] of the data term's mean curvature: it only settles what the
//! data leave open (a grid with fewer correspondences than unknowns) and biases what they
//! determine by about lambda (measured below 1e-9 on exact data).
//!
//! Why the lengths are kept: a curved projector's shape depends on its length (C_j moves
//! with L_j), but sliding its end along the curve (the depths rescaled) changes the cost
//! only to fourth order in the angle between tangent and chord, along a curved valley, so
//! the data barely fix the lengths (measured: the iteration wandered to ends that reach
//! the points at t up to 2.9). Kept lengths remove that near-symmetry, as the straight
//! fit's scale constraint removes its exact one; a known grid with the prior's lengths can
//! then be recovered exactly (tests; but see the limits below). Points at a single depth per projector still leave the
//! bend open (any projector reaching them fits); the prior term keeps the straight fit there.
//!
//! # The solver
//!
//! Levenberg-Marquardt on the node unknowns and the depths together, the depths kept in
//! [0, 1] (each step's depths clamped to it): a quadratic continued beyond its ends bends
//! back, and matching a point there (at a negative depth, say) is a wrong local minimum. Each depth t_k enters
//! only residual k, so the depths are eliminated from the damped normal equations by their
//! Schur complement (a 1 x 1 block per correspondence) and the system solved has 5 unknowns
//! per node (the end's direction and the tangent, each as two angles about it). The
//! iteration stops when no step lowers the cost any more (the damping exceeds
//! [`MAX_DAMPING`]: converged to rounding), at a cost of 0, or after [`MAX_ITERATIONS`] steps.
//!
//! Limits: the iteration starts from the straight fit and often ends in a wrong local
//! minimum (a point held at depth 0, then an error): measured, most random bilinear 5 x 5
//! grids bent 0.03 to 0.4 rad failed so; one (the test's) and the 3 x 3 example are
//! recovered. With Bezier interpolation every correspondence weights every node and
//! convergence is slow.
//!
//! Degenerate cases: no correspondences, or none weighting any node (the prior is returned
//! with its tangents); a fitted depth t_k <= 0 or > 1 (the point would be reached behind the
//! start or beyond the end: an error naming the correspondence); a fitted projector of zero
//! length or a tangent pointing back along it (the errors of
//! [`ProjectorGrid::set_projector`]).

use glam::DVec3;
use nalgebra::{DMatrix, DVector};

use super::{Correspondence, FitReport};
use crate::error::{Error, Result};
use crate::projection::flexible::projector_grid::ProjectorGrid;
use crate::projection::projector::{quadratic_point, quadratic_tangent};

/// The prior's weight relative to the data term's mean curvature (see the module docs).
const PRIOR_WEIGHT: f64 = 1e-12;

/// The most Levenberg-Marquardt steps.
const MAX_ITERATIONS: usize = 2000;

/// The damping (relative to the curvature) beyond which no step lowers the cost: converged,
/// to rounding.
const MAX_DAMPING: f64 = 1e20;

/// Unknowns per node: two angles of the end's direction, two of the tangent.
const PER_NODE: usize = 4;

/// One free node: the unit direction of its end and its unit tangent.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    direction: DVec3,
    tangent: DVec3,
}

/// The iterate: the free nodes and the correspondences' depths.
#[derive(Debug, Clone, PartialEq)]
struct State {
    nodes: Vec<Node>,
    depths: Vec<f64>,
}

/// The fixed data of the problem.
struct Problem<'a> {
    grid: &'a ProjectorGrid,
    data: &'a [Correspondence],
    /// Per correspondence: (free node slot, weight) of the nodes weighting its (u, v).
    weights: Vec<Vec<(usize, f64)>>,
    /// Per correspondence: the blended start S_k and 1 / rho_k.
    starts: Vec<(DVec3, f64)>,
    /// Grid index and kept length L_j of each free node.
    free: Vec<(usize, f64)>,
    /// The prior term's centre (the straight fit).
    anchor: Vec<Node>,
}

/// One correspondence linearised: residual, d residual / d t and the columns over the node
/// unknowns (index, column).
struct Linear {
    residual: DVec3,
    along: DVec3,
    columns: Vec<(usize, DVec3)>,
}

/// Fits the end directions and tangents of the nodes of `prior` that `data` constrain, their
/// lengths kept, starting from the directions of `straight`, the straight fit of the same
/// data (module docs). Returns the grid (the prior's
/// starts, interpolation and unconstrained nodes) and its residual.
pub(super) fn fit(
    prior: &ProjectorGrid,
    straight: &ProjectorGrid,
    data: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    let (problem, start) = Problem::new(prior, straight, data);
    let state = problem.solve(start);
    for (k, &t) in state.depths.iter().enumerate() {
        if !(t > 0.0 && t <= 1.0) {
            let c = &data[k];
            return Err(Error::new(format!(
                "correspondence {}: the fitted curved projector of {} reaches {} at t = {t}, \
                 outside its length (0, 1]; give the grid longer projectors or consistent \
                 correspondences",
                k + 1,
                c.uv,
                c.point
            )));
        }
    }
    let mut grid = prior.clone();
    let cols = prior.size().0;
    for (node, &(j, length)) in state.nodes.iter().zip(&problem.free) {
        let start = prior.starts()[j];
        let end = start + length * node.direction;
        grid.set_projector((j % cols, j / cols), start, end, Some(node.tangent))?;
    }
    let report = problem.report(&grid, &state);
    Ok((grid, report))
}

impl<'a> Problem<'a> {
    /// The problem and its starting state: the straight fit's directions, tangents along
    /// them, depths by distance along the straight projectors.
    fn new(
        grid: &'a ProjectorGrid,
        straight: &ProjectorGrid,
        data: &'a [Correspondence],
    ) -> (Self, State) {
        let nodes = grid.starts().len();
        let mut slot = vec![None; nodes];
        let mut free = Vec::new();
        let mut weights = Vec::with_capacity(data.len());
        let mut starts = Vec::with_capacity(data.len());
        let mut depths = Vec::with_capacity(data.len());
        for c in data {
            let mut list = Vec::new();
            grid.for_each_weight(c.uv, |j, w| {
                let s = *slot[j].get_or_insert_with(|| {
                    free.push((j, (grid.ends()[j] - grid.starts()[j]).length()));
                    free.len() - 1
                });
                list.push((s, w));
            });
            weights.push(list);
            let (start, _) = grid.start_end(c.uv);
            starts.push((start, 1.0 / (c.point - start).length()));
            // The distance along the projector as a fraction of its length: positive even
            // where the straight start points a little away from the point.
            let (s, e) = straight.start_end(c.uv);
            let depth = (c.point - s).length() / (e - s).length();
            depths.push(depth.clamp(0.0, 1.0));
        }
        let anchor: Vec<Node> = free
            .iter()
            .map(|&(j, _)| {
                let direction = (straight.ends()[j] - grid.starts()[j]).normalize();
                Node {
                    direction,
                    tangent: direction,
                }
            })
            .collect();
        let state = State {
            nodes: anchor.clone(),
            depths,
        };
        let problem = Problem {
            grid,
            data,
            weights,
            starts,
            free,
            anchor,
        };
        (problem, state)
    }

    /// The control points of correspondence `k`'s projector in `state`.
    fn controls(&self, k: usize, state: &State) -> [DVec3; 3] {
        let mut p = [self.starts[k].0, DVec3::ZERO, DVec3::ZERO];
        for &(s, w) in &self.weights[k] {
            let ((j, length), node) = (self.free[s], state.nodes[s]);
            let start = self.grid.starts()[j];
            p[1] += w * (start + 0.5 * length * node.tangent);
            p[2] += w * (start + length * node.direction);
        }
        p
    }

    /// The weighted residual of correspondence `k`.
    fn residual(&self, k: usize, state: &State) -> DVec3 {
        let point = quadratic_point(&self.controls(k, state), state.depths[k]);
        (point - self.data[k].point) * self.starts[k].1
    }

    /// The cost: squared residuals plus the prior term.
    fn cost(&self, state: &State, lambda: f64) -> f64 {
        let data: f64 = (0..self.data.len())
            .map(|k| self.residual(k, state).length_squared())
            .sum();
        let prior: f64 = state
            .nodes
            .iter()
            .zip(&self.anchor)
            .map(|(n, a)| {
                (n.direction - a.direction).length_squared()
                    + (n.tangent - a.tangent).length_squared()
            })
            .sum();
        data + lambda * prior
    }

    /// Correspondence `k` linearised at `state` (columns of the end's three coordinates and
    /// the tangent's two angles, about the planes of [`tangent_frame`]).
    fn linearise(&self, k: usize, state: &State) -> Linear {
        let p = self.controls(k, state);
        let t = state.depths[k];
        let scale = self.starts[k].1;
        let mut columns = Vec::with_capacity(PER_NODE * self.weights[k].len());
        for &(s, w) in &self.weights[k] {
            let ((_, length), node) = (self.free[s], state.nodes[s]);
            // dE/d angle = L e (the end turns), dC/d angle = (L / 2) e (the tangent turns).
            let frames = [
                (tangent_frame(node.direction), t * t * length),
                (tangent_frame(node.tangent), t * (1.0 - t) * length),
            ];
            for (m, ((e1, e2), factor)) in frames.into_iter().enumerate() {
                for (i, e) in [e1, e2].into_iter().enumerate() {
                    columns.push((PER_NODE * s + 2 * m + i, w * scale * factor * e));
                }
            }
        }
        Linear {
            residual: (quadratic_point(&p, t) - self.data[k].point) * scale,
            along: quadratic_tangent(&p, t) * scale,
            columns,
        }
    }

    /// Levenberg-Marquardt from `state` (module docs).
    fn solve(&self, mut state: State) -> State {
        let n = PER_NODE * self.free.len();
        if n == 0 {
            return state;
        }
        let mut lambda = None;
        let mut damping = 0.1;
        let mut cost = f64::INFINITY;
        for _ in 0..MAX_ITERATIONS {
            let lines: Vec<Linear> = (0..self.data.len())
                .map(|k| self.linearise(k, &state))
                .collect();
            let mut normal = DMatrix::<f64>::zeros(n, n);
            let mut gradient = DVector::<f64>::zeros(n);
            for line in &lines {
                for &(i, a) in &line.columns {
                    gradient[i] += a.dot(line.residual);
                    for &(j, b) in &line.columns {
                        normal[(i, j)] += a.dot(b);
                    }
                }
            }
            let lambda = *lambda.get_or_insert_with(|| {
                let mean = normal.trace() / n as f64;
                PRIOR_WEIGHT * if mean > 0.0 { mean } else { 1.0 }
            });
            if cost.is_infinite() {
                cost = self.cost(&state, lambda);
            }
            self.add_prior(&state, lambda, &mut normal, &mut gradient);
            loop {
                let Some(candidate) = self.step(&state, &lines, &normal, &gradient, damping) else {
                    damping *= 10.0;
                    if damping > MAX_DAMPING {
                        return state;
                    }
                    continue;
                };
                let next = self.cost(&candidate, lambda);
                if next < cost {
                    state = candidate;
                    cost = next;
                    damping = (damping / 10.0).max(1e-15);
                    if cost == 0.0 {
                        return state;
                    }
                    break;
                }
                damping *= 10.0;
                if damping > MAX_DAMPING {
                    return state;
                }
            }
        }
        state
    }

    /// Adds the prior term's curvature and gradient.
    fn add_prior(
        &self,
        state: &State,
        lambda: f64,
        normal: &mut DMatrix<f64>,
        gradient: &mut DVector<f64>,
    ) {
        for (s, (node, anchor)) in state.nodes.iter().zip(&self.anchor).enumerate() {
            let pairs = [
                (node.direction, anchor.direction),
                (node.tangent, anchor.tangent),
            ];
            for (m, (value, centre)) in pairs.into_iter().enumerate() {
                let (e1, e2) = tangent_frame(value);
                for (i, e) in [e1, e2].into_iter().enumerate() {
                    let i = PER_NODE * s + 2 * m + i;
                    normal[(i, i)] += lambda;
                    gradient[i] += lambda * e.dot(value - centre);
                }
            }
        }
    }

    /// The damped step from `state` (the depths eliminated by their Schur complement), or
    /// `None` where the damped system is not positive definite.
    fn step(
        &self,
        state: &State,
        lines: &[Linear],
        normal: &DMatrix<f64>,
        gradient: &DVector<f64>,
        damping: f64,
    ) -> Option<State> {
        let n = normal.nrows();
        let mut system = normal.clone();
        for i in 0..n {
            system[(i, i)] += damping * normal[(i, i)].max(f64::MIN_POSITIVE);
        }
        let mut rhs = -gradient.clone();
        let eliminated: Vec<Depth> = lines.iter().map(|line| Depth::new(line, damping)).collect();
        for Depth { u, h, g } in &eliminated {
            for &(i, ui) in u {
                rhs[i] += ui * g / h;
                for &(j, uj) in u {
                    system[(i, j)] -= ui * uj / h;
                }
            }
        }
        let delta = system.cholesky()?.solve(&rhs);
        let nodes = state
            .nodes
            .iter()
            .enumerate()
            .map(|(s, node)| {
                let turn = |v: DVec3, m: usize| {
                    let (e1, e2) = tangent_frame(v);
                    let d = |i: usize| delta[PER_NODE * s + 2 * m + i];
                    (v + d(0) * e1 + d(1) * e2).normalize()
                };
                Node {
                    direction: turn(node.direction, 0),
                    tangent: turn(node.tangent, 1),
                }
            })
            .collect();
        let depths = state
            .depths
            .iter()
            .zip(&eliminated)
            .map(|(t, Depth { u, h, g })| {
                let coupled: f64 = u.iter().map(|&(i, ui)| ui * delta[i]).sum();
                (t - (g + coupled) / h).clamp(0.0, 1.0)
            })
            .collect();
        let next = State { nodes, depths };
        let finite = next.depths.iter().all(|t| t.is_finite())
            && next
                .nodes
                .iter()
                .all(|n| n.direction.is_finite() && n.tangent.is_finite());
        finite.then_some(next)
    }

    /// The residual of the fitted `grid`: the angle, seen from the projector's start, between
    /// each point and the nearest point of its projector (for a straight projector, the
    /// angle between the projector and the point: the straight fit's measure).
    fn report(&self, grid: &ProjectorGrid, state: &State) -> FitReport {
        let angles: Vec<f64> = self
            .data
            .iter()
            .zip(&state.depths)
            .map(|(c, &t)| {
                let p = grid.control_points(c.uv);
                let on = quadratic_point(&p, t);
                let off = (c.point - on).length();
                off.atan2((on - p[0]).length()).to_degrees()
            })
            .collect();
        let count = angles.len();
        FitReport {
            correspondences: count,
            unconstrained_nodes: grid.starts().len() - self.free.len(),
            max_angle_deg: angles.iter().copied().fold(0.0, f64::max),
            rms_angle_deg: if count == 0 {
                0.0
            } else {
                (angles.iter().map(|a| a * a).sum::<f64>() / count as f64).sqrt()
            },
        }
    }
}

/// One depth's row of the damped normal equations, eliminated: u = A^T b over the line's
/// columns, h = |b|^2 (1 + damping) and g = b . r (b: d residual / d t).
struct Depth {
    u: Vec<(usize, f64)>,
    h: f64,
    g: f64,
}

impl Depth {
    fn new(line: &Linear, damping: f64) -> Self {
        let u = line
            .columns
            .iter()
            .map(|&(i, a)| (i, a.dot(line.along)))
            .collect();
        let h = line.along.length_squared() * (1.0 + damping);
        Depth {
            u,
            h: h.max(f64::MIN_POSITIVE),
            g: line.along.dot(line.residual),
        }
    }
}

/// Two unit vectors perpendicular to the unit vector `v` and to each other: the directions
/// its two angles turn it in.
fn tangent_frame(v: DVec3) -> (DVec3, DVec3) {
    v.any_orthonormal_pair()
}
