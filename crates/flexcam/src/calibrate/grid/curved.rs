//! The fit of a grid with curved node projectors (quadratic Bezier curves leaving their start
//! along a tangent, module `projector_grid`) by nonlinear least squares.
//!
//! # The problem
//!
//! As in the straight fit, the starts S_j stay (the image plane); the unknowns of every node
//! that some correspondence constrains are the direction D_j of its end, its unit tangent T_j
//! and its length L_j = |E_j - S_j| (where the data determine it, below), which give
//! E_j = S_j + L_j D_j and its control point C_j = S_j + (L_j / 2) T_j. The projector of
//! (u, v) is the quadratic B(t) = (1 - t)^2 S + 2 t (1 - t) C + t^2 E of the blended S, C
//! and E, and correspondence k asks that B_k(t_k) = X_k for some depth t_k, a further
//! unknown. The fit minimises
//!
//! sum_k |B_k(t_k) - X_k|^2 / rho_k^2
//!     + lambda sum_j (|D_j - D0_j|^2 + |T_j - T0_j|^2 + ln(L_j / L0_j)^2)
//!
//! with rho_k = |X_k - S_k| (so each term is about the squared angle the point is off its
//! projector, seen from the start, as in the straight fit's report), D0, L0, T0 the straight
//! fit the iteration starts from (its directions and lengths, tangents along them), and
//! lambda [`PRIOR_WEIGHT`] of the data term's mean curvature: it keeps the damped system
//! positive definite. Its pull, about lambda over the data's curvature along an unknown, is
//! large along the length of a weakly bent node (measured: lengths off by 2e-6), so once
//! converged the fit is solved again with the prior centred on its own result, where that
//! pull acts on the small remainder only (as in the straight fit).
//!
//! The lengths: a node's projector is S_j + L_j (t (1 - t) T_j + t^2 D_j), so a change of
//! L_j scales its curve about S_j, which moves the points of a curved projector off it:
//! with points at several depths, a curved node's length is determined. Weakly, for a
//! slight bend: sliding an end along its curve changes the cost only to fourth order in the
//! angle between tangent and chord, so lengths come out less accurately than angles
//! (measured: to 6e-7 on Bezier grids where the angles reach 3e-9). A length the data leave
//! open is held at the prior's ([`Problem::hold_open_lengths`]): a straight node whose points
//! all lie at its own image position (it slides along itself), a node whose points all lie at
//! one depth, or the common scale of all-straight data (it only rescales the depths). While
//! the farthest point sits at a projector's end (t = 1) the bound, not the data, fixes the
//! scale: a fit whose start is too short for its points stretches until they are in view.
//!
//! # The solver
//!
//! Levenberg-Marquardt on the node angles (the end's direction and the tangent, two angles
//! each about their current value), every depth t_k the closest point of its projector to
//! X_k over [0, 1] after each step (the global minimum of a quadratic's squared distance: a
//! cubic's roots and the two ends, [`quadratic_closest`]): a point is never held at an end, such
//! as the start, while the curve passes nearer further along (the trap of the first version,
//! which stepped the depths with the nodes and clamped them). Each depth enters only its own
//! residual and sits where the residual is perpendicular to the projector, so it is
//! eliminated by projecting its three residual rows off B'(t_k) (the Schur complement of a
//! depth strictly inside (0, 1); a depth at 0 or 1 is held). The iteration starts from the
//! straight fit (tangents along its directions), folded nodes are then repaired (below), and
//! each run stops when no step lowers the cost (the
//! damping exceeds [`MAX_DAMPING`]: converged to rounding), at a cost of 0, when it stalls
//! (the cost fell by under [`STALL`] of itself over the last [`STALL_WINDOW`] steps), or
//! after [`MAX_ITERATIONS`] steps. The Gauss-Newton matrix is formed from a dense Jacobian (three
//! rows per correspondence, four columns per node) by one matrix product, so that Bezier
//! grids, where every correspondence weights every node, take about a second, not minutes.
//!
//! Folded minima: from the straight start, the iteration alone ends in a wrong local
//! minimum on most random grids (measured: 9 of 24 bilinear and 0 of 24 Bezier grids
//! recovered), each time with some node folded: its tangent, or its end, more than 90
//! degrees off the other, the curve running backwards from its start and turning round.
//! [`Problem::unfold`] therefore mirrors the folded nodes, the tangent first (an angle a off
//! the end's direction becomes pi - a, same side of the chord), else the end, solves again
//! from there and keeps what lowers the cost (measured, with the lengths kept at the truth's:
//! 24 of 24 bilinear and 8 of 8 Bezier random grids recovered; with each node's length 0.5 to
//! 3 times the prior's and fitted, `recovers_random_bilinear_curved_grids_with_their_own_lengths`
//! and `..._bezier_...`: 23 of 24 bilinear and 14 of 16 Bezier grids). A minimum without a
//! folded node, or one whose mirror does not lower the cost, is left to [`Problem::reseat`]
//! (where the residual is above rounding: restarts with every length scaled by 1.25 and 0.8,
//! and with the three nodes carrying most of the residual put back on the straight fit,
//! kept if the cost drops by over [`RESTART_GAIN`] of itself), which repaired Bezier seed 14
//! (two nodes turned 0.8 and 1.0 rad, not folded); bilinear and Bezier seed 12 (lengths short
//! together, a shallow valley)
//! are not repaired and are left to the report's residual (0.62 and 0.0028 degrees).
//! Tried and not kept: a continuation in the data (from the straight start's own projectors
//! to the points in 8 stages) with steps limited to 0.2 rad (the same 9 grids), and an
//! alternating start (depths fixed, the node control points and ends by linear least squares,
//! put back on the constraint): for fixed depths the free problem is badly conditioned, its
//! control points landing far off the constraint (up to 2,750 times the half length on
//! Bezier grids), and the start was no better.
//!
//! Identifiability: with fewer correspondences than twice the free nodes (each fixes two of a
//! node's four angles) the fit is refused before it starts, naming how many are missing; at
//! the fitted grid, a Gauss-Newton matrix whose smallest eigenvalue is below [`UNDETERMINED`]
//! of its largest means the data leave some combination open: lengths are then held (above);
//! a combination of angles left open (say, one point per node: a curve through it can leave
//! its start in any direction nearby) is refused naming the node that combination moves
//! most, rather than returning the prior term's choice.
//!
//! Degenerate cases: no correspondences, or none weighting any node (the prior is returned
//! with its tangents); a point reached only at depth 0 (it lies behind the projector's
//! start: an error naming the correspondence); a point beyond its projector's end is
//! matched at t = 1 with the miss in the residual; too few or uninformative correspondences
//! (above); a fitted projector of zero length (the errors of
//! [`ProjectorGrid::set_projector`]).

use std::cell::Cell;

use glam::DVec3;
use nalgebra::{DMatrix, DVector};

use super::cholesky::Factor;
use super::{Correspondence, FitReport};
use crate::error::{Error, Result};
use crate::projection::flexible::projector_grid::ProjectorGrid;
use crate::projection::projector::{quadratic_closest, quadratic_point, quadratic_tangent};

/// The prior's weight relative to the data term's mean curvature (see the module docs).
const PRIOR_WEIGHT: f64 = 1e-12;

/// The most restarts with folded nodes mirrored ([`Problem::unfold`]).
const MAX_UNFOLDS: usize = 8;

/// The most rounds of [`Problem::reseat`].
const MAX_RESEATS: usize = 3;

/// Factors every free length is scaled by in the restarts of [`Problem::reseat`].
const RESCALES: [f64; 2] = [1.25, 0.8];

/// How many of the nodes carrying most of the residual [`Problem::reseat`] puts back on
/// the straight fit.
const RESEAT_NODES: usize = 3;

/// The data cost per correspondence (squared angle, rad^2: an rms miss of 1e-8 rad) at or
/// below which a fit counts as exact and [`Problem::reseat`] leaves it.
const ROUNDING: f64 = 1e-16;

/// The most Levenberg-Marquardt steps.
const MAX_ITERATIONS: usize = 2000;

/// Iterations over which a run's progress is measured for [`STALL`].
const STALL_WINDOW: usize = 100;

/// A run stops when its cost fell by less than this fraction of itself over the last
/// [`STALL_WINDOW`] iterations: at that rate the rest of [`MAX_ITERATIONS`] would lower it by
/// at most 2e-5 of itself (measured: on data that leave a node nearly open, the iteration
/// creeps along the flat valley, each run taking all its steps).
const STALL: f64 = 1e-6;

/// The fraction of the cost by which a restart of [`Problem::unfold`] or [`Problem::reseat`]
/// must lower it to be kept: runs ended by [`STALL`] in one flat valley differ by less, and
/// keeping such a restart would only start another round.
const RESTART_GAIN: f64 = 1e-3;

/// The damping (relative to the curvature) beyond which no step lowers the cost: converged,
/// to rounding.
const MAX_DAMPING: f64 = 1e20;

/// The smallest eigenvalue of the fitted Gauss-Newton matrix, relative to its largest, at
/// which the data still determine every node angle (see [`Problem::check_determined`]).
const UNDETERMINED: f64 = 1e-10;

/// Unknowns per node: two angles of the end's direction, two of the tangent, and the
/// logarithm of the projector's length.
const PER_NODE: usize = 5;

/// The column of a node's log-length among its [`PER_NODE`] unknowns.
const LENGTH: usize = 4;

/// One free node: the unit direction of its end, its unit tangent and its length L_j
/// (E_j = S_j + L_j D_j, C_j = S_j + (L_j / 2) T_j).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    direction: DVec3,
    tangent: DVec3,
    length: f64,
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
    /// Grid index and prior length L_j of each free node.
    free: Vec<(usize, f64)>,
    /// Per free node: whether its length is held at the prior's (the data leave it open).
    held: Vec<bool>,
    /// The prior term's centre and the iteration's start (the straight fit).
    anchor: Vec<Node>,
    /// Levenberg-Marquardt iterations so far, over every run (for the report).
    iterations: Cell<usize>,
}

/// Fits the end directions, tangents and lengths (those the data determine; the others keep
/// the prior's) of the nodes of `prior` that `data` constrain, starting from `straight`, the
/// straight fit of the same data (module docs). Returns the grid (the prior's starts, interpolation and unconstrained
/// nodes) and its residual.
pub(super) fn fit(
    prior: &ProjectorGrid,
    straight: &ProjectorGrid,
    data: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    let mut problem = Problem::new(prior, straight, data);
    problem.check_count()?;
    let mut state = problem.unfold(problem.solve(problem.anchor.clone()));
    if problem.hold_open_lengths(&mut state) {
        state = problem.unfold(problem.solve(state.nodes));
    }
    state = problem.reseat(state);
    // The prior term pulls each unknown towards its centre by about PRIOR_WEIGHT over the
    // data's curvature along it, which is small along a weakly bent node's length (measured:
    // lengths off by 2e-6); centred again on the fit, the pull acts on that residual only.
    problem.anchor = state.nodes.clone();
    state = problem.solve(state.nodes);
    if let Some(k) = state.depths.iter().position(|t| *t <= 0.0) {
        let c = &data[k];
        return Err(Error::new(format!(
            "correspondence {}: the fitted curved projector of {} comes nearest to {} at its \
             start (t = 0): the point lies behind the image plane, or the correspondences \
             contradict each other",
            k + 1,
            c.uv,
            c.point
        )));
    }
    problem.check_determined(&state, true)?;
    let mut grid = prior.clone();
    let cols = prior.size().0;
    for (node, &(j, _)) in state.nodes.iter().zip(&problem.free) {
        let start = prior.starts()[j];
        let end = start + node.length * node.direction;
        grid.set_projector((j % cols, j / cols), start, end, Some(node.tangent))?;
    }
    let report = problem.report(&grid, &state);
    Ok((grid, report))
}

impl<'a> Problem<'a> {
    /// The problem, its prior centred on the straight fit's directions and lengths, with
    /// tangents along them; no length held yet.
    fn new(grid: &'a ProjectorGrid, straight: &ProjectorGrid, data: &'a [Correspondence]) -> Self {
        let nodes = grid.starts().len();
        let mut slot = vec![None; nodes];
        let mut free = Vec::new();
        let mut weights = Vec::with_capacity(data.len());
        let mut starts = Vec::with_capacity(data.len());
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
        }
        let anchor = free
            .iter()
            .map(|&(j, _)| {
                let chord = straight.ends()[j] - grid.starts()[j];
                let direction = chord.normalize();
                Node {
                    direction,
                    tangent: direction,
                    length: chord.length(),
                }
            })
            .collect();
        Problem {
            grid,
            data,
            weights,
            starts,
            held: vec![false; free.len()],
            free,
            anchor,
            iterations: Cell::new(0),
        }
    }

    /// The control points of correspondence `k`'s projector with node unknowns `nodes`.
    fn controls(&self, k: usize, nodes: &[Node]) -> [DVec3; 3] {
        let mut p = [self.starts[k].0, DVec3::ZERO, DVec3::ZERO];
        for &(s, w) in &self.weights[k] {
            let (node, start) = (nodes[s], self.grid.starts()[self.free[s].0]);
            p[1] += w * (start + 0.5 * node.length * node.tangent);
            p[2] += w * (start + node.length * node.direction);
        }
        p
    }

    /// The state of node unknowns `nodes`: each depth at the point of its projector closest
    /// to its scene point.
    fn with_closest_depths(&self, nodes: Vec<Node>) -> State {
        let depths = (0..self.data.len())
            .map(|k| quadratic_closest(&self.controls(k, &nodes), self.data[k].point))
            .collect();
        State { nodes, depths }
    }

    /// The cost: squared weighted residuals plus the prior term.
    fn cost(&self, state: &State, lambda: f64) -> f64 {
        let data: f64 = (0..self.data.len())
            .map(|k| {
                let point = quadratic_point(&self.controls(k, &state.nodes), state.depths[k]);
                ((point - self.data[k].point) * self.starts[k].1).length_squared()
            })
            .sum();
        let prior: f64 = state
            .nodes
            .iter()
            .zip(&self.anchor)
            .map(|(n, a)| {
                (n.direction - a.direction).length_squared()
                    + (n.tangent - a.tangent).length_squared()
                    + (n.length / a.length).ln().powi(2)
            })
            .sum();
        data + lambda * prior
    }

    /// The weighted residuals (three rows per correspondence) and their Jacobian over the
    /// node angles (about the planes of [`tangent_frame`]) and log-lengths at `state` (a held
    /// length's column zero), each depth strictly
    /// inside (0, 1) eliminated: its rows are projected off the projector's tangent B'(t_k)
    /// (the depth sits at the closest point, where the residual is perpendicular to the
    /// projector, and follows the nodes to first order: the Schur complement of the depth);
    /// a depth at 0 or 1 is held there.
    fn linearise(&self, state: &State) -> (DMatrix<f64>, DVector<f64>) {
        let rows = 3 * self.data.len();
        let mut jacobian = DMatrix::<f64>::zeros(rows, PER_NODE * self.free.len());
        let mut residuals = DVector::<f64>::zeros(rows);
        for k in 0..self.data.len() {
            let p = self.controls(k, &state.nodes);
            let t = state.depths[k];
            let scale = self.starts[k].1;
            let along = quadratic_tangent(&p, t);
            let interior = t > 0.0 && t < 1.0 && along != DVec3::ZERO;
            // The part of a residual row-triple that the depth cannot absorb.
            let kept = |v: DVec3| {
                if interior {
                    v - along * (v.dot(along) / along.length_squared())
                } else {
                    v
                }
            };
            let r = kept((quadratic_point(&p, t) - self.data[k].point) * scale);
            for axis in 0..3 {
                residuals[3 * k + axis] = r[axis];
            }
            for &(s, w) in &self.weights[k] {
                let node = state.nodes[s];
                let length = node.length;
                // dE/d angle = L e (the end turns), dC/d angle = (L / 2) e (the tangent).
                let (d1, d2) = tangent_frame(node.direction);
                let (t1, t2) = tangent_frame(node.tangent);
                let (end, control) = (t * t * length, t * (1.0 - t) * length);
                // d/d ln L: the end and the control point move out along D and T / 2.
                let stretch = if self.held[s] {
                    DVec3::ZERO
                } else {
                    end * node.direction + control * node.tangent
                };
                let columns = [end * d1, end * d2, control * t1, control * t2, stretch];
                for (m, column) in columns.into_iter().enumerate() {
                    let column = kept(w * scale * column);
                    for axis in 0..3 {
                        jacobian[(3 * k + axis, PER_NODE * s + m)] = column[axis];
                    }
                }
            }
        }
        (jacobian, residuals)
    }

    /// Repairs the folded local minima of [`Problem::solve`] (module docs): while the fitted
    /// `state` has nodes whose tangent is more than 90 degrees off their end's direction, it
    /// mirrors, in each such node, first the tangent across the plane perpendicular to the
    /// end's direction (an angle a off it becomes pi - a, on the same side: the tangent was
    /// folded), and if that does not lower the cost, the end's direction across the plane
    /// perpendicular to the tangent instead (the end was folded), solves again from there and
    /// keeps the result when it [`improves`] the cost; at most [`MAX_UNFOLDS`] rounds.
    fn unfold(&self, mut state: State) -> State {
        let mut cost = self.cost(&state, 0.0);
        for _ in 0..MAX_UNFOLDS {
            let folded: Vec<usize> = (state.nodes.iter().enumerate())
                .filter(|(_, n)| n.tangent.dot(n.direction) < 0.0)
                .map(|(s, _)| s)
                .collect();
            if folded.is_empty() {
                break;
            }
            let mirrored = |tangent: bool| {
                let mut nodes = state.nodes.clone();
                for &s in &folded {
                    let n = &mut nodes[s];
                    let (moved, fixed) = if tangent {
                        (&mut n.tangent, n.direction)
                    } else {
                        (&mut n.direction, n.tangent)
                    };
                    *moved = (*moved - 2.0 * moved.dot(fixed) * fixed).normalize();
                }
                self.solve(nodes)
            };
            let better = [true, false].into_iter().find_map(|tangent| {
                let candidate = mirrored(tangent);
                let candidate_cost = self.cost(&candidate, 0.0);
                improves(candidate_cost, cost).then_some((candidate, candidate_cost))
            });
            let Some(better) = better else {
                break;
            };
            (state, cost) = better;
        }
        state
    }

    /// Repairs a wrong minimum that [`Problem::unfold`] leaves (module docs), only where the
    /// data residual is above rounding: restarts from `state` with, in turn, every length
    /// scaled by each of [`RESCALES`] (a minimum with the lengths off together: bilinear and
    /// Bezier seed 12), and the [`RESEAT_NODES`] nodes that carry most of the residual put
    /// back on the straight fit (a few nodes turned wrong: Bezier seed 14), each solved and
    /// unfolded; keeps the lowest cost where it [`improves`] on the last, repeats while it
    /// does (at most [`MAX_RESEATS`] rounds).
    fn reseat(&self, mut state: State) -> State {
        let mut cost = self.cost(&state, 0.0);
        for _ in 0..MAX_RESEATS {
            if cost <= ROUNDING * self.data.len() as f64 {
                break;
            }
            let mut candidates: Vec<Vec<Node>> = RESCALES
                .iter()
                .map(|f| {
                    let mut nodes = state.nodes.clone();
                    for (s, n) in nodes.iter_mut().enumerate() {
                        if !self.held[s] {
                            n.length *= f;
                        }
                    }
                    nodes
                })
                .collect();
            let mut nodes = state.nodes.clone();
            for s in self.worst_nodes(&state) {
                nodes[s] = Node {
                    length: if self.held[s] {
                        nodes[s].length
                    } else {
                        self.anchor[s].length
                    },
                    ..self.anchor[s]
                };
            }
            candidates.push(nodes);
            let best = candidates
                .into_iter()
                .map(|nodes| {
                    let candidate = self.unfold(self.solve(nodes));
                    let c = self.cost(&candidate, 0.0);
                    (candidate, c)
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match best {
                Some((candidate, c)) if improves(c, cost) => (state, cost) = (candidate, c),
                _ => break,
            }
        }
        state
    }

    /// The (at most [`RESEAT_NODES`]) free nodes carrying most of the data residual at
    /// `state`: each correspondence's squared residual shared among its nodes by weight.
    fn worst_nodes(&self, state: &State) -> Vec<usize> {
        let mut share = vec![0.0; self.free.len()];
        for k in 0..self.data.len() {
            let p = self.controls(k, &state.nodes);
            let miss = ((quadratic_point(&p, state.depths[k]) - self.data[k].point)
                * self.starts[k].1)
                .length_squared();
            for &(s, w) in &self.weights[k] {
                share[s] += w * miss;
            }
        }
        let mut order: Vec<usize> = (0..share.len()).collect();
        order.sort_by(|a, b| share[*b].total_cmp(&share[*a]));
        order.truncate(RESEAT_NODES);
        order
    }

    /// Levenberg-Marquardt on the node unknowns from `nodes` (module docs).
    fn solve(&self, nodes: Vec<Node>) -> State {
        let mut state = self.with_closest_depths(nodes);
        let n = PER_NODE * self.free.len();
        if n == 0 {
            return state;
        }
        let mut lambda = None;
        let mut damping = 0.1;
        let mut cost = f64::INFINITY;
        let mut costs = Vec::with_capacity(MAX_ITERATIONS);
        'run: for iteration in 0..MAX_ITERATIONS {
            if iteration > STALL_WINDOW
                && costs[iteration - 1 - STALL_WINDOW] - cost <= STALL * cost
            {
                break;
            }
            self.iterations.set(self.iterations.get() + 1);
            let (jacobian, residuals) = self.linearise(&state);
            let mut normal = gram(&jacobian);
            let mut gradient = jacobian.tr_mul(&residuals);
            let lambda = *lambda.get_or_insert_with(|| {
                let mean = normal.trace() / n as f64;
                PRIOR_WEIGHT * if mean > 0.0 { mean } else { 1.0 }
            });
            if cost.is_infinite() {
                cost = self.cost(&state, lambda);
            }
            self.add_prior(&state, lambda, &mut normal, &mut gradient);
            loop {
                let next = self.step(&state, &normal, &gradient, damping);
                if let Some(next) = next {
                    let next_cost = self.cost(&next, lambda);
                    if next_cost < cost {
                        state = next;
                        cost = next_cost;
                        damping = (damping / 10.0).max(1e-15);
                        break;
                    }
                }
                damping *= 10.0;
                if damping > MAX_DAMPING {
                    break 'run;
                }
            }
            if cost == 0.0 {
                break;
            }
            costs.push(cost);
        }
        state
    }

    /// Errors when the correspondences are fewer than the node angles: each fixes two (three
    /// coordinates less its depth), each free node has four (its length, which the data may
    /// leave open, is not counted: see [`Problem::hold_open_lengths`]).
    fn check_count(&self) -> Result<()> {
        let needed = 2 * self.free.len();
        if self.data.len() >= needed {
            return Ok(());
        }
        Err(Error::new(format!(
            "curved projector grid fit: the correspondences weight {} node projectors, which \
             need at least {needed} correspondences (each fixes 2 of a node's 4 angles: end \
             direction and tangent); got {}, add {} more",
            self.free.len(),
            self.data.len(),
            needed - self.data.len()
        )))
    }

    /// Holds at the prior's length the node lengths that the data leave open at the fitted
    /// `state` (setting them there; returns whether any was held, so that the caller solves
    /// again). A length is open when the Gauss-Newton matrix over the node unknowns, depths
    /// eliminated, is singular to [`UNDETERMINED`] along a combination that moves it: a
    /// straight node whose points all lie at its own image position (it can slide along
    /// itself), a node whose points all lie at one depth along it, or the common scale of a
    /// grid whose projectors are all straight (scaling every length scales the projectors
    /// about their starts, which only rescales the depths). As many lengths are held as the
    /// matrix has open combinations, chosen by column pivoting on the combinations' length
    /// components (the lengths that each combination moves most, in turn), so that the held
    /// ones fix every open combination. Holds nothing when the node angles are open even with
    /// every length fixed: the fit's final [`Problem::check_determined`] refuses that.
    fn hold_open_lengths(&mut self, state: &mut State) -> bool {
        let columns = self.columns(true);
        let open = self.open_combinations(state, &columns);
        if open.is_empty() || self.check_determined(state, false).is_err() {
            return false;
        }
        // Per free length: its components in the open combinations (the pivoting's columns).
        let mut lengths: Vec<(usize, Vec<f64>)> = (columns.iter().enumerate())
            .filter(|(_, c)| *c % PER_NODE == LENGTH)
            .map(|(i, c)| (c / PER_NODE, open.iter().map(|v| v[i]).collect()))
            .collect();
        for _ in 0..open.len() {
            let norm = |v: &Vec<f64>| v.iter().map(|x| x * x).sum::<f64>();
            let Some(pivot) = (0..lengths.len())
                .max_by(|a, b| norm(&lengths[*a].1).total_cmp(&norm(&lengths[*b].1)))
            else {
                break;
            };
            let (slot, q) = lengths.swap_remove(pivot);
            let q_norm = norm(&q);
            if q_norm == 0.0 {
                break;
            }
            for (_, v) in &mut lengths {
                let along = v.iter().zip(&q).map(|(x, y)| x * y).sum::<f64>() / q_norm;
                v.iter_mut().zip(&q).for_each(|(x, y)| *x -= along * y);
            }
            self.held[slot] = true;
            state.nodes[slot].length = self.free[slot].1;
        }
        true
    }

    /// The indices of the node unknowns in use: every node's four angles, and with `lengths`
    /// the log-length of every node whose length is not held.
    fn columns(&self, lengths: bool) -> Vec<usize> {
        (0..self.free.len())
            .flat_map(|s| {
                let length = lengths && !self.held[s];
                (0..PER_NODE)
                    .filter(move |m| *m != LENGTH || length)
                    .map(move |m| PER_NODE * s + m)
            })
            .collect()
    }

    /// The combinations of the unknowns `columns` (unit vectors over them, weakest first)
    /// that the data leave open at `state`: the eigenvectors of the Gauss-Newton matrix,
    /// depths eliminated and without the prior term, whose eigenvalues are below
    /// [`UNDETERMINED`] of its largest.
    fn open_combinations(&self, state: &State, columns: &[usize]) -> Vec<DVector<f64>> {
        if columns.is_empty() {
            return Vec::new();
        }
        let (jacobian, _) = self.linearise(state);
        let normal = gram(&jacobian);
        let normal = normal.select_rows(columns).select_columns(columns);
        let eigen = normal.symmetric_eigen();
        let largest = eigen.eigenvalues.max();
        let mut open: Vec<(f64, DVector<f64>)> = (eigen.eigenvalues.iter().enumerate())
            .filter(|(_, value)| **value <= UNDETERMINED * largest)
            .map(|(i, value)| (*value, eigen.eigenvectors.column(i).into_owned()))
            .collect();
        open.sort_by(|a, b| a.0.total_cmp(&b.0));
        open.into_iter().map(|(_, v)| v).collect()
    }

    /// Errors when the data leave some combination of the node unknowns open at the fitted
    /// `state` (the angles, and with `lengths` the lengths not held: see
    /// [`Problem::open_combinations`]), naming the node the weakest combination moves most:
    /// the prior term would then choose its end and tangent, not the data.
    fn check_determined(&self, state: &State, lengths: bool) -> Result<()> {
        let columns = self.columns(lengths);
        let Some(weakest) = self.open_combinations(state, &columns).into_iter().next() else {
            return Ok(());
        };
        let mut moved = vec![0.0; self.free.len()];
        for (i, c) in columns.iter().enumerate() {
            moved[c / PER_NODE] += weakest[i] * weakest[i];
        }
        let slot = (0..self.free.len())
            .max_by(|a, b| moved[*a].total_cmp(&moved[*b]))
            .unwrap_or(0);
        let cols = self.grid.size().0;
        let (col, row) = (self.free[slot].0 % cols, self.free[slot].0 / cols);
        Err(Error::new(format!(
            "curved projector grid fit: the correspondences do not determine the end and \
             tangent of node ({col}, {row}) (too few points near image position {}, or all at \
             one depth along their projectors); add correspondences at several depths there",
            self.grid.node_uv(col, row)
        )))
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
            let i = PER_NODE * s + LENGTH;
            normal[(i, i)] += lambda;
            gradient[i] += lambda * (node.length / anchor.length).ln();
        }
    }

    /// The damped step from `state` on the node unknowns, its depths the closest points
    /// again. `None` (a failed step: more damping) where the damped system is not positive
    /// definite or a value would not be finite.
    fn step(
        &self,
        state: &State,
        normal: &DMatrix<f64>,
        gradient: &DVector<f64>,
        damping: f64,
    ) -> Option<State> {
        let mut system = normal.clone();
        for i in 0..system.nrows() {
            system[(i, i)] += damping * normal[(i, i)].max(f64::MIN_POSITIVE);
        }
        let delta = Factor::new(system)?.solve(&-gradient);
        let nodes: Vec<Node> = state
            .nodes
            .iter()
            .enumerate()
            .map(|(s, node)| {
                let turn = |v: DVec3, m: usize| {
                    let (e1, e2) = tangent_frame(v);
                    let d = |i: usize| delta[PER_NODE * s + 2 * m + i];
                    (v + d(0) * e1 + d(1) * e2).normalize()
                };
                let stretch = if self.held[s] {
                    1.0
                } else {
                    delta[PER_NODE * s + LENGTH].exp()
                };
                Node {
                    direction: turn(node.direction, 0),
                    tangent: turn(node.tangent, 1),
                    length: node.length * stretch,
                }
            })
            .collect();
        let finite = nodes
            .iter()
            .all(|n| n.direction.is_finite() && n.tangent.is_finite() && n.length.is_normal());
        finite.then(|| self.with_closest_depths(nodes))
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
        FitReport {
            curved_iterations: Some(self.iterations.get()),
            ..FitReport::from_angles(&angles, grid.starts().len() - self.free.len())
        }
    }
}

/// Whether a restart's cost `candidate` lowers `cost` by over [`RESTART_GAIN`] of it, so
/// that [`Problem::unfold`] and [`Problem::reseat`] keep it.
fn improves(candidate: f64, cost: f64) -> bool {
    candidate < (1.0 - RESTART_GAIN) * cost
}

/// J^T J, by a blocked matrix product (nalgebra's `tr_mul` forms it entry by entry, column
/// dot column: measured 75 % of a Bezier grid's fit time, several times the product's).
fn gram(jacobian: &DMatrix<f64>) -> DMatrix<f64> {
    jacobian.transpose() * jacobian
}

/// Two unit vectors perpendicular to the unit vector `v` and to each other: the directions
/// its two angles turn it in.
fn tangent_frame(v: DVec3) -> (DVec3, DVec3) {
    v.any_orthonormal_pair()
}
