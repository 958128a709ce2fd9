use glam::{DVec2, DVec3};
use nalgebra::{DMatrix, DVector};

use super::cholesky::Factor;
use super::{Correspondence, FitReport, PRIOR_SPREAD, PRIOR_WEIGHT};
use crate::error::{Error, Result};
use crate::projection::flexible::ProjectorGrid;

/// The direction of correspondence `c`'s projector in `prior`'s grid with node directions
/// `dirs`: the nodes' directions blended with the grid's weights at its image position.
pub(super) fn blended(prior: &ProjectorGrid, c: &Correspondence, dirs: &[DVec3]) -> DVec3 {
    let mut d = DVec3::ZERO;
    prior.for_each_weight(c.uv, |j, w| d += w * dirs[j]);
    d
}

/// Whether every correspondence's blended direction in `dirs` points towards its target
/// (positive dot product: its point is reached at t > 0).
pub(super) fn all_in_front(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    dirs: &[DVec3],
) -> bool {
    correspondences
        .iter()
        .zip(targets)
        .all(|(c, a)| blended(prior, c, dirs).dot(*a) > 0.0)
}

/// Largest mean squared chord (2 sin(angle / 2)) per correspondence, in rad^2, at which the
/// linear fit is taken as meeting the data (rms miss 1e-6 rad): below it the linear optimum
/// cannot have shrunk or reversed a node (module docs of `grid`, "Inexact data").
pub(super) const EXACT_CHORD: f64 = 1e-12;

/// Whether the floor-weighted linear directions `dirs` meet every correspondence to within
/// `EXACT_CHORD` on average (each in front of its start).
pub(super) fn nearly_exact(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    dirs: &[DVec3],
) -> bool {
    let sum: f64 = correspondences
        .iter()
        .zip(targets)
        .map(|(c, a)| {
            let d = blended(prior, c, dirs);
            d.try_normalize().map_or(4.0, |n| (n - *a).length_squared())
        })
        .sum();
    sum <= EXACT_CHORD * correspondences.len() as f64
}

/// The straight fit's first solve, its node directions before any lengthening.
pub(super) enum FirstSolve {
    /// Noisy data: the one solve with the noise's prior weight ([`noise_weight`]).
    Noisy(Vec<DVec3>),
    /// Exact data: the floor-weighted solve, the first of two (see [`fit`]).
    Exact(Vec<DVec3>),
}

/// The first solve of the straight fit of `prior` to `correspondences` (`targets`: their
/// unit directions from their projectors' starts): the floor-weighted solve both measures
/// the noise and, for exact data, is the first of the two solves.
pub(super) fn first_solve(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
) -> Result<FirstSolve> {
    let system = System::new(prior, correspondences, targets);
    let floor_dirs = system.solve(0.0)?;
    Ok(
        match noise_weight(&system, correspondences, targets, &floor_dirs) {
            Some(weight) => FirstSolve::Noisy(system.solve(weight)?),
            None => FirstSolve::Exact(floor_dirs),
        },
    )
}

/// The prior's weight for noisy correspondences, or `None` when the data show no noise above
/// what the floor weight `PRIOR_WEIGHT` handles (see the module docs of `grid`, "Noisy data").
///
/// The solve at the floor weight, `floor_dirs`, measures the data term's residual sum of squares; divided by
/// the degrees of freedom (two equations per correspondence less the unknowns of the
/// constrained nodes, plus one for the scale constraint) it estimates the noise variance
/// sigma^2 per equation, in the unknowns' scaled units (about radians squared). The weight is
/// then sigma^2 / `PRIOR_SPREAD`^2: the maximum a posteriori weight for a prior whose node
/// directions may be off by about `PRIOR_SPREAD` of their length.
///
/// Degenerate cases: exact data (the estimate is at rounding level, below the floor: `None`,
/// so that exact data are fitted as before); no more equations than unknowns (say one
/// correspondence, or 30 points for a Bezier grid's 75 unknowns: the data can be met exactly,
/// noise cannot be told from signal: `None`).
pub(super) fn noise_weight(
    system: &System<'_>,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    floor_dirs: &[DVec3],
) -> Option<f64> {
    let prior = system.prior;
    let constrained = constrained_nodes(prior, correspondences);
    let unknowns = 3 * constrained.iter().filter(|c| **c).count();
    let equations = 2 * correspondences.len() + 1;
    if equations <= unknowns {
        return None;
    }
    let sum_of_squares: f64 = correspondences
        .iter()
        .zip(targets)
        .map(|(c, a)| {
            let d = blended(prior, c, floor_dirs) / system.scale;
            (d - d.dot(*a) * *a).length_squared()
        })
        .sum();
    let variance = sum_of_squares / (equations - unknowns) as f64;
    let weight = variance / (PRIOR_SPREAD * PRIOR_SPREAD);
    (weight > system.floor).then_some(weight)
}

/// The start of the curved fit: the straight fit of `prior` without its tangents (the
/// noise's prior weight where the straight residual exceeds rounding, else the two solves of
/// exact data), without the check that every point is reached (a straight projector may
/// point away from a point that the curved one reaches).
pub(super) fn straight_start(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<ProjectorGrid> {
    let straight = prior.straightened();
    let targets = targets(&straight, correspondences)?;
    match first_solve(&straight, correspondences, &targets)? {
        FirstSolve::Noisy(dirs) => with_directions(&straight, &dirs),
        FirstSolve::Exact(dirs) => {
            let first = with_directions(&straight, &dirs)?;
            with_directions(&first, &solve_directions(&first, correspondences)?)
        }
    }
}

/// One least-squares solve around `prior` at the floor weight (see [`fit`]), its projectors
/// lengthened so that every point is in view.
pub(super) fn fit_once(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    let targets = targets(prior, correspondences)?;
    let dirs = solve_directions(prior, correspondences)?;
    in_view(prior, correspondences, &targets, dirs)
}

/// The grid of `prior` with the solved node directions `dirs`, all lengthened by one common
/// factor where some point would lie beyond its projector's end (module docs), and its
/// residual; `targets` are the correspondences' unit directions from their projectors' starts.
pub(super) fn in_view(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    mut dirs: Vec<DVec3>,
) -> Result<(ProjectorGrid, FitReport)> {
    let fitted = with_directions(prior, &dirs)?;
    let reach = farthest_reach(&fitted, correspondences)?;
    if reach > 1.0 {
        for d in &mut dirs {
            *d *= 1.01 * reach;
        }
    }
    let fitted = with_directions(prior, &dirs)?;
    let constrained = constrained_nodes(prior, correspondences);
    let report = residual(&fitted, correspondences, targets, &constrained);
    Ok((fitted, report))
}

/// Whether some correspondence weights each node of `grid`.
pub(super) fn constrained_nodes(
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Vec<bool> {
    let mut constrained = vec![false; grid.starts().len()];
    for c in correspondences {
        grid.for_each_weight(c.uv, |j, _| constrained[j] = true);
    }
    constrained
}

/// The node directions of one least-squares solve around `prior` at the floor weight.
pub(super) fn solve_directions(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<Vec<DVec3>> {
    let targets = targets(prior, correspondences)?;
    System::new(prior, correspondences, &targets).solve(0.0)
}

/// The least-squares system of one fit: the data term's normal matrix and the prior, in
/// unknowns scaled by the prior's mean projector length.
pub(super) struct System<'a> {
    pub(super) prior: &'a ProjectorGrid,
    /// The data term's normal matrix (3 rows per node).
    pub(super) normal: DMatrix<f64>,
    /// The prior's node directions over `scale`.
    pub(super) prior_dirs: DVector<f64>,
    /// The scale constraint's row: the prior over the constrained nodes, zero elsewhere.
    pub(super) scale_row: DVector<f64>,
    /// The prior's mean projector length.
    pub(super) scale: f64,
    /// The least prior weight: `PRIOR_WEIGHT` of the normal matrix's mean diagonal.
    pub(super) floor: f64,
}

impl<'a> System<'a> {
    pub(super) fn new(
        prior: &'a ProjectorGrid,
        correspondences: &[Correspondence],
        targets: &[DVec3],
    ) -> Self {
        let nodes = prior.starts().len();
        let dirs: Vec<DVec3> = prior
            .starts()
            .iter()
            .zip(prior.ends())
            .map(|(s, e)| *e - *s)
            .collect();
        let scale = dirs.iter().map(|d| d.length()).sum::<f64>() / nodes as f64;
        let n = 3 * nodes;
        let mut normal = DMatrix::<f64>::zeros(n, n);
        let mut weights = Vec::new();
        for (c, a) in correspondences.iter().zip(targets) {
            weights.clear();
            prior.for_each_weight(c.uv, |j, w| weights.push((j, w)));
            let p = projector_off(*a);
            for &(j, wj) in &weights {
                for &(l, wl) in &weights {
                    add_block(&mut normal, j, l, wj * wl, &p);
                }
            }
        }
        let constrained = constrained_nodes(prior, correspondences);
        let prior_dirs =
            DVector::from_iterator(n, dirs.iter().flat_map(|d| (*d / scale).to_array()));
        let scale_row = DVector::from_iterator(
            n,
            (0..n).map(|i| {
                if constrained[i / 3] {
                    prior_dirs[i]
                } else {
                    0.0
                }
            }),
        );
        let mean_diagonal = normal.trace() / n as f64;
        let floor = PRIOR_WEIGHT
            * if mean_diagonal > 0.0 {
                mean_diagonal
            } else {
                1.0
            };
        Self {
            prior,
            normal,
            prior_dirs,
            scale_row,
            scale,
            floor,
        }
    }

    /// The node directions minimising the data term plus `weight` (at least the floor) times
    /// the squared distance to the prior, under the scale constraint.
    pub(super) fn solve(&self, weight: f64) -> Result<Vec<DVec3>> {
        let lambda = weight.max(self.floor);
        let mut matrix = self.normal.clone();
        for i in 0..matrix.nrows() {
            matrix[(i, i)] += lambda;
        }
        let factor = Factor::new(matrix).ok_or_else(|| {
            Error::new("projector grid fit: the least-squares system is singular")
        })?;
        // The scale constraint g^T y = |g|^2 (g: the prior over the constrained nodes) through
        // a Lagrange multiplier: y = y_a + mu y_b with (A + lambda I) y_a = lambda y0 and
        // (A + lambda I) y_b = g.
        let mut solution = factor.solve(&(lambda * &self.prior_dirs));
        let wanted = self.scale_row.norm_squared();
        if wanted > 0.0 {
            let along = factor.solve(&self.scale_row);
            let mu = (wanted - self.scale_row.dot(&solution)) / self.scale_row.dot(&along);
            solution += mu * along;
        }
        let dirs: Vec<DVec3> = solution
            .as_slice()
            .chunks_exact(3)
            .map(|y| self.scale * DVec3::new(y[0], y[1], y[2]))
            .collect();
        if let Some(j) = dirs.iter().position(|d| d.length() <= 1e-12 * self.scale) {
            return Err(Error::new(format!(
                "projector grid fit: node ({}, {}) got a zero-length projector",
                j % self.prior.size().0,
                j / self.prior.size().0
            )));
        }
        Ok(dirs)
    }
}

/// The unit direction a_k from the start of each correspondence's projector to its point.
pub(super) fn targets(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<Vec<DVec3>> {
    correspondences
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let inside = c.uv.cmpge(DVec2::ZERO).all() && c.uv.cmple(DVec2::ONE).all();
            if !inside || !c.point.is_finite() {
                return Err(Error::new(format!(
                    "correspondence {}: the image position must be in [0, 1] x [0, 1] and the \
                     point finite (got uv {} and point {})",
                    k + 1,
                    c.uv,
                    c.point
                )));
            }
            let (start, _) = prior.start_end(c.uv);
            (c.point - start).try_normalize().ok_or_else(|| {
                Error::new(format!(
                    "correspondence {}: the point {} is the start of its own projector",
                    k + 1,
                    c.point
                ))
            })
        })
        .collect()
}

/// I - a a^T for unit a, row-major.
pub(super) fn projector_off(a: DVec3) -> [[f64; 3]; 3] {
    let mut p = [[0.0; 3]; 3];
    for (r, row) in p.iter_mut().enumerate() {
        for (c, value) in row.iter_mut().enumerate() {
            *value = f64::from(u8::from(r == c)) - a[r] * a[c];
        }
    }
    p
}

/// normal[block (j, l)] += w * p.
pub(super) fn add_block(normal: &mut DMatrix<f64>, j: usize, l: usize, w: f64, p: &[[f64; 3]; 3]) {
    for (r, row) in p.iter().enumerate() {
        for (c, value) in row.iter().enumerate() {
            normal[(3 * j + r, 3 * l + c)] += w * value;
        }
    }
}

pub(super) fn with_directions(prior: &ProjectorGrid, dirs: &[DVec3]) -> Result<ProjectorGrid> {
    let ends = prior
        .starts()
        .iter()
        .zip(dirs)
        .map(|(s, d)| *s + *d)
        .collect();
    prior.with_ends(ends)
}

/// The largest projector parameter t at which a correspondence's point is reached (its
/// projection onto the fitted projector). Errors when a point is reached only at t <= 0.
pub(super) fn farthest_reach(
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<f64> {
    let mut reach = 0.0f64;
    for (k, c) in correspondences.iter().enumerate() {
        let (start, end) = grid.start_end(c.uv);
        let d = end - start;
        let t = (c.point - start).dot(d) / d.length_squared();
        if t.is_nan() || t <= 0.0 {
            return Err(Error::new(format!(
                "correspondence {}: no projector of the grid can reach {} at {} (the fitted \
                 projector points away from it; the correspondences contradict each other)",
                k + 1,
                c.point,
                c.uv
            )));
        }
        reach = reach.max(t);
    }
    Ok(reach)
}

pub(super) fn residual(
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    constrained: &[bool],
) -> FitReport {
    let angles: Vec<f64> = correspondences
        .iter()
        .zip(targets)
        .map(|(c, a)| {
            let d = grid.tangent(c.uv, 0.0).normalize();
            // atan2 of |cross| and dot: accurate for tiny angles, unlike acos.
            d.cross(*a).length().atan2(d.dot(*a)).to_degrees()
        })
        .collect();
    FitReport::from_angles(&angles, constrained.iter().filter(|c| !**c).count())
}
