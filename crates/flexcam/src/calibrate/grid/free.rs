//! The free fit (`starts = "free"`): every node's start fitted together with its direction,
//! for correspondences from projections whose projectors pass through no common eye
//! (pushbroom, crossed slits, any grid whose starts are off an eye; module section "Starts"
//! of `grid`). Kept starts cannot meet such data, and one common eye cannot either.
//!
//! # Unknowns and gauge
//!
//! Node j has the start S_j = S0_j + L s_j and the direction D_j = l d_j (6 unknowns). Sliding
//! every start along its own projector by one common fraction a of its direction changes no
//! projector of the grid (S(u, v) + a D(u, v), for any weights that sum to 1), and scaling
//! every direction by one factor changes none either. Sliding the starts by different
//! fractions is no such freedom: the blended start then leaves the projector between the
//! nodes (measured: holding each start in the plane across the prior's projector, one
//! fraction per node, left a pushbroom 0.15 to 0.26 degrees off at the points). The common
//! slide is fixed by a penalty on the starts' mean move along the prior's unit directions
//! (weight: the data term's mean diagonal; on a true freedom it biases nothing), the scale by
//! the fit's scale constraint (the prior's directions' component over the constrained nodes,
//! as module `grid`'s). L is the rms distance from the prior's starts to the points (a start's
//! move turns a projector by about its length over that distance) and l the prior's mean
//! projector length, so the unknowns are dimensionless.
//!
//! # Cost
//!
//! sum_k |r_k|^2 + mu sum |second differences|^2 + pull, with r_k = (n_k - m_k) max(|X_k -
//! S(u_k, v_k)| / R_k, 1): n_k the unit blended direction D(u_k, v_k), m_k the unit
//! direction from the blended start S(u_k, v_k) to the point X_k, R_k the distance from the
//! prior's blended start to X_k (fixed). n_k - m_k is the chord 2 sin(angle / 2) of module
//! `angular`, now moving with the starts too. The factor keeps the misses those seen from
//! where the prior looks: the bare chord, an angle at the fit's own start, shrinks when a
//! start moves away from the points with the line no nearer them, which noisy data
//! reward (measured: noisy pushbroom data, 200 points, 41 to 60 % ids with wild nodes);
//! beyond R_k the residual is |X - S| n - (X - S) over R_k, about the point's distance from
//! the projector over R_k, which no slide lowers, and nearer than R_k the chord grows as a
//! start comes closer, so no start gains by moving towards the points either (a residual of
//! the distance over R_k everywhere let starts come up to the points: 91 to 97 % ids for
//! some 50-point noisy pushbroom fits). Exact data are met exactly either way. The residual
//! is continuous at |X - S| = R_k.
//! The smoothness term takes the second differences of the starts (over L) and of the
//! directions (over l) along every row and every column of nodes: zero for node values that
//! are affine along the grid lines, so a bilinear truth (pushbroom, crossed slits, a bilinear
//! grid off any eye, any pinhole) is not biased, while sparse data, which leave many grids
//! exact, get the least bent one. mu is a weight of the ladder `weight::LADDER` (1e-3 to
//! 1e-6) times the data term's mean diagonal, chosen from the data by cross-validation
//! (module `weight`): the largest where the data are sparse or exact, so that sparse fits of
//! bilinear truths come out bilinear; smaller where many points show the grid bent across
//! its nodes, which the largest would bias (by up to 0.17 degrees at the points of a 3 x 3
//! grid, measured).
//! Nodes that no correspondence weighs are pulled to the prior with `PULL` of that diagonal (the
//! smoothness term extrapolates them otherwise); every unknown gets the floor weight of
//! module `grid`, which keeps the matrix positive definite. Levenberg-Marquardt (module
//! `angular`'s) from each given grid's projectors (the kept fit's, the eye fit's, the
//! prior's); the lowest cost wins (for the largest weight; each smaller one starts from the
//! previous weight's fit).
//!
//! # Degenerate cases
//!
//! - All points on one projector (one image position): that projector meets them, the others
//!   are the smoothest continuation of the prior; every constrained node is reported as
//!   undetermined (`sparse_nodes`), and `starts = "auto"` does not take it.
//! - Points only in one cell: that cell's four nodes are fitted, the others unconstrained
//!   (pulled to the prior, smoothed); with fewer than 10 points the cell's 20 unknowns are
//!   undetermined and reported so.
//! - Points all on one plane (whatever the projection): the plane's points at their image
//!   positions are met, but nothing tells how the projectors run off the plane; `auto` keeps
//!   the simpler kept starts, which meet such data as well, and the plane's image is right
//!   either way.
//! - A fitted projector that reaches its point only at t <= 0: the error of module `grid`.

mod weight;

use glam::DVec3;
use nalgebra::{DMatrix, DVector, SMatrix};

use super::angular::{minimise, LeastSquares};
use super::{
    constrained_nodes, in_view, prior_directions, targets, undetermined_nodes, Correspondence,
    FitReport, FittedStarts, PRIOR_WEIGHT,
};
use crate::error::{Error, Result};
use crate::projection::flexible::projector_grid::ProjectorGrid;

/// The pull of unconstrained nodes to the prior, relative to the data term's mean diagonal.
const PULL: f64 = 1e-6;

/// Unknowns per node: three for the start, three for the direction.
const PER_NODE: usize = 6;

/// Largest second difference (in the unknowns' units) of a fit taken as bilinear.
const BILINEAR: f64 = 1e-5;

/// What `Starts::Auto` judges a free fit by besides its misses.
#[derive(Debug, Clone, Copy)]
pub(super) struct Shape {
    /// Node values affine along every grid line (all second differences below `BILINEAR`).
    pub(super) bilinear: bool,
    /// The fit's effective number of unknowns: the trace of its hat matrix,
    /// trace((data + smoothness + slide + pull)^-1 data) of the Gauss-Newton matrices at the
    /// fit (the count a penalised least-squares fit spends; at most the 6 unknowns a node
    /// less the gauge, and at most the data's 2 equations a correspondence); infinite where
    /// the matrix does not factor, and where the weight was not cross-validated (fewer than
    /// 20 points or a node without data, module `weight`: the count would then measure the
    /// fixed weight, not what the data support; measured: 16 points of an off-eye 3 x 3 grid
    /// took free starts at 91.5 to 97.2 % ids against 94.2 to 97.1 % kept).
    pub(super) freedom: f64,
}

/// Fits `prior`'s node starts and directions to `correspondences` (module docs), starting
/// from each of `guesses` (grids of the prior's size) and from the prior; returns the grid,
/// its report (`sparse_nodes` counting the constrained nodes that data and smoothness leave
/// undetermined) and its [`Shape`].
pub(super) fn fit(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    guesses: &[&ProjectorGrid],
) -> Result<(ProjectorGrid, FitReport, Shape)> {
    if prior.is_curved() {
        return Err(Error::new(
            "projector grid fit: `starts = \"free\"` fits straight projectors; this grid has \
             tangents",
        ));
    }
    // The correspondences' errors (positions outside the image, a point at its start).
    targets(prior, correspondences)?;
    if correspondences.is_empty() {
        let (grid, report) = super::fit(prior, correspondences)?;
        let shape = Shape {
            bilinear: false,
            freedom: f64::INFINITY,
        };
        return Ok((grid, report, shape));
    }
    let rungs = weight::fit_ladder(prior, correspondences, guesses)?;
    let chosen = weight::choose(prior, correspondences, &rungs);
    let weight::Rung {
        problem,
        y,
        grid,
        sparse_nodes,
    } = &rungs[chosen];
    let dirs: Vec<DVec3> = (0..problem.nodes()).map(|j| problem.dir(j, y)).collect();
    let grid_targets = targets(grid, correspondences)?;
    let (grid, report) = in_view(grid, correspondences, &grid_targets, dirs)?;
    let shape = Shape {
        bilinear: (&problem.rows * y + &problem.constant).amax() <= BILINEAR,
        freedom: if rungs.len() > 1 {
            problem.freedom(y)
        } else {
            f64::INFINITY
        },
    };
    Ok((
        grid,
        FitReport {
            starts: FittedStarts::Free,
            sparse_nodes: *sparse_nodes,
            smoothness: Some(problem.smoothness),
            ..report
        },
        shape,
    ))
}

/// The free fit's least-squares problem in its scaled unknowns (module docs).
struct Problem<'a> {
    prior: &'a ProjectorGrid,
    correspondences: &'a [Correspondence],
    /// The prior's starts S0_j.
    origins: Vec<DVec3>,
    /// The common slide's penalty row: the prior's unit directions on the start unknowns,
    /// over the square root of the node count (unit length); and its weight.
    slide: DVector<f64>,
    slide_weight: f64,
    /// The slide penalty's matrix is `slide_root slide_root^T`: `slide` times the square
    /// root of its weight.
    slide_root: DVector<f64>,
    /// L: the rms distance from the prior's starts to the points.
    length: f64,
    /// l: the prior's mean projector length.
    scale: f64,
    /// The smoothness term's matrix mu L^T L and gradient constant mu L^T c (below).
    smooth: DMatrix<f64>,
    smooth_c: DVector<f64>,
    /// The second differences themselves (rows of L, constant c).
    rows: DMatrix<f64>,
    constant: DVector<f64>,
    mu: f64,
    /// mu relative to the data term's mean diagonal (the ladder's rung, module `weight`).
    smoothness: f64,
    /// The weight of each unknown's pull to `prior_y` (floor, or `PULL` on unconstrained
    /// nodes).
    pull: DVector<f64>,
    prior_y: DVector<f64>,
    /// The scale constraint's row: the prior's directions over the constrained nodes.
    scale_row: DVector<f64>,
}

impl<'a> Problem<'a> {
    /// The problem of fitting `prior` to `correspondences` with the smoothness weight
    /// `smoothness` (relative to the data term's mean diagonal).
    fn new(
        prior: &'a ProjectorGrid,
        correspondences: &'a [Correspondence],
        smoothness: f64,
    ) -> Self {
        let dirs = prior_directions(prior);
        let nodes = dirs.len();
        let scale = dirs.iter().map(|d| d.length()).sum::<f64>() / nodes as f64;
        let distance: f64 = correspondences
            .iter()
            .map(|c| (c.point - prior.start_end(c.uv).0).length_squared())
            .sum();
        let length = (distance / correspondences.len() as f64).sqrt();
        let constrained = constrained_nodes(prior, correspondences);
        let n = PER_NODE * nodes;
        let mut prior_y = DVector::zeros(n);
        let mut scale_row = DVector::zeros(n);
        let mut slide = DVector::zeros(n);
        for (j, d) in dirs.iter().enumerate() {
            let along = d.normalize_or_zero() / (nodes as f64).sqrt();
            for r in 0..3 {
                prior_y[PER_NODE * j + 3 + r] = d[r] / scale;
                slide[PER_NODE * j + r] = along[r];
                if constrained[j] {
                    scale_row[PER_NODE * j + 3 + r] = d[r] / scale;
                }
            }
        }
        let mut problem = Self {
            prior,
            correspondences,
            origins: prior.starts().to_vec(),
            slide,
            slide_weight: 0.0,
            slide_root: DVector::zeros(n),
            length,
            scale,
            smooth: DMatrix::zeros(n, n),
            smooth_c: DVector::zeros(n),
            rows: DMatrix::zeros(0, n),
            constant: DVector::zeros(0),
            mu: 0.0,
            smoothness,
            pull: DVector::zeros(n),
            prior_y,
            scale_row,
        };
        // The weights follow the data term's mean diagonal at the prior (the chords'
        // derivatives hardly depend on where they are taken).
        let (data, _) = problem.data_term(&problem.prior_y);
        let mean = (data.trace() / n as f64).max(f64::MIN_POSITIVE);
        problem.mu = smoothness * mean;
        problem.slide_weight = mean;
        problem.slide_root = mean.sqrt() * &problem.slide;
        (problem.rows, problem.constant) = problem.second_differences();
        let (rows, constant, mu) = (&problem.rows, &problem.constant, problem.mu);
        problem.smooth = mu * rows.transpose() * rows;
        problem.smooth_c = mu * rows.transpose() * constant;
        for (j, constrained) in constrained.iter().enumerate() {
            let weight = if *constrained { PRIOR_WEIGHT } else { PULL };
            for i in 0..PER_NODE {
                problem.pull[PER_NODE * j + i] = weight * mean;
            }
        }
        problem
    }

    /// Levenberg-Marquardt (module `angular`'s) from each of `starts` (grids of the prior's
    /// size, their directions scaled onto the scale constraint; one whose directions have no
    /// positive component along it is skipped): the unknowns of the lowest cost, `None` when
    /// every start was skipped.
    fn solve(&self, starts: &[&ProjectorGrid]) -> Option<DVector<f64>> {
        let wanted = self.scale_row.norm_squared();
        let mut best: Option<(f64, DVector<f64>)> = None;
        for start in starts {
            let mut y = self.unknowns_of(start);
            let along = self.scale_row.dot(&y);
            if !(along > 0.0 && along.is_finite()) {
                continue;
            }
            self.rescale(&mut y, wanted / along);
            let (cost, y) = minimise(self, y, &self.scale_row);
            if best.as_ref().is_none_or(|(c, _)| cost < *c) {
                best = Some((cost, y));
            }
        }
        best.map(|(_, y)| y)
    }

    /// The grid of the node projectors `y` (ends one direction from the starts).
    fn grid_of(&self, y: &DVector<f64>) -> Result<ProjectorGrid> {
        let starts: Vec<DVec3> = (0..self.nodes()).map(|j| self.start(j, y)).collect();
        let ends = starts
            .iter()
            .enumerate()
            .map(|(j, s)| *s + self.dir(j, y))
            .collect();
        ProjectorGrid::new(self.prior.size(), starts, ends, self.prior.interpolation())
    }

    /// The constrained nodes that the model (data, smoothness, slide penalty; no pull)
    /// leaves undetermined at `y`, whose grid is `grid` (`undetermined_nodes` of module `checks`).
    fn undetermined(&self, y: &DVector<f64>, grid: &ProjectorGrid) -> usize {
        let (matrix, _) = self.linearise_model(y);
        let constrained = constrained_nodes(self.prior, self.correspondences);
        undetermined_nodes(
            grid,
            &matrix,
            PER_NODE,
            &self.scale_row,
            &constrained,
            self.scale,
        )
    }

    /// [`Shape::freedom`] at `y`.
    fn freedom(&self, y: &DVector<f64>) -> f64 {
        let (data, _) = self.data_term(y);
        let (model, _) = self.linearise(y);
        self.with_slide(model)
            .cholesky()
            .map_or(f64::INFINITY, |factor| factor.solve(&data).trace())
    }

    fn nodes(&self) -> usize {
        self.origins.len()
    }

    /// S_j for unknowns `y`.
    fn start(&self, j: usize, y: &DVector<f64>) -> DVec3 {
        let k = PER_NODE * j;
        self.origins[j] + self.length * DVec3::new(y[k], y[k + 1], y[k + 2])
    }

    /// D_j for unknowns `y`.
    fn dir(&self, j: usize, y: &DVector<f64>) -> DVec3 {
        let k = PER_NODE * j + 3;
        self.scale * DVec3::new(y[k], y[k + 1], y[k + 2])
    }

    /// Scales the directions in `y` by `factor`.
    fn rescale(&self, y: &mut DVector<f64>, factor: f64) {
        for j in 0..self.nodes() {
            for r in 0..3 {
                y[PER_NODE * j + 3 + r] *= factor;
            }
        }
    }

    /// The unknowns of `grid`'s node projectors.
    fn unknowns_of(&self, grid: &ProjectorGrid) -> DVector<f64> {
        let mut y = DVector::zeros(PER_NODE * self.nodes());
        for (j, (s, e)) in grid.starts().iter().zip(grid.ends()).enumerate() {
            let (offset, d) = ((*s - self.origins[j]) / self.length, *e - *s);
            for r in 0..3 {
                y[PER_NODE * j + r] = offset[r];
                y[PER_NODE * j + 3 + r] = d[r] / self.scale;
            }
        }
        y
    }

    /// The second differences of the starts (over L) and directions (over l) along every
    /// row and column of nodes, as rows of L y + c.
    fn second_differences(&self) -> (DMatrix<f64>, DVector<f64>) {
        let (cols, rows) = self.prior.size();
        let mut triples = Vec::new();
        for r in 0..rows {
            for c in 1..cols.saturating_sub(1) {
                triples.push([r * cols + c - 1, r * cols + c, r * cols + c + 1]);
            }
        }
        for c in 0..cols {
            for r in 1..rows.saturating_sub(1) {
                triples.push([(r - 1) * cols + c, r * cols + c, (r + 1) * cols + c]);
            }
        }
        let n = PER_NODE * self.nodes();
        let mut matrix = DMatrix::zeros(6 * triples.len(), n);
        let mut constant = DVector::zeros(6 * triples.len());
        for (t, triple) in triples.iter().enumerate() {
            for (&j, weight) in triple.iter().zip([1.0, -2.0, 1.0]) {
                for r in 0..3 {
                    constant[6 * t + r] += weight * self.origins[j][r] / self.length;
                }
                for r in 0..PER_NODE {
                    matrix[(6 * t + r, PER_NODE * j + r)] += weight;
                }
            }
        }
        (matrix, constant)
    }

    /// The data term's Gauss-Newton matrix and gradient at `y`.
    fn data_term(&self, y: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
        let n = y.len();
        let mut matrix = DMatrix::<f64>::zeros(n, n);
        let mut gradient = DVector::<f64>::zeros(n);
        let mut weights = Vec::new();
        for c in self.correspondences {
            weights.clear();
            self.prior
                .for_each_weight(c.uv, |j, w| weights.push((j, w)));
            let Some(b) = self.blend(c, &weights, y) else {
                continue;
            };
            let residual = b.residual();
            let off_n = glam::DMat3::IDENTITY - outer(b.n, b.n);
            // Nearer than R: r = n - m, d r / d s_j = w_j L (I - m m^T) / |w|, w = X - S.
            // Farther: r = (|w| n - w) / R, d r / d s_j = w_j L (I - n m^T) / R. Either way
            // d r / d d_j = w_j l (I - n n^T) / |D| times the factor max(|w| / R, 1).
            let (across, factor) = if b.m_len < b.reach {
                (glam::DMat3::IDENTITY - outer(b.m, b.m), 1.0 / b.m_len)
            } else {
                (glam::DMat3::IDENTITY - outer(b.n, b.m), 1.0 / b.reach)
            };
            let blocks: Vec<(usize, SMatrix<f64, 3, 6>)> = weights
                .iter()
                .map(|&(j, w)| {
                    let js = across * (w * self.length * factor);
                    let jd = off_n * (w * self.scale * b.far() / b.n_len);
                    let block = SMatrix::<f64, 3, 6>::from_fn(|r, col| {
                        if col < 3 {
                            js.col(col)[r]
                        } else {
                            jd.col(col - 3)[r]
                        }
                    });
                    (j, block)
                })
                .collect();
            let r = nalgebra::Vector3::new(residual.x, residual.y, residual.z);
            for (j, bj) in &blocks {
                let mut g = gradient.fixed_rows_mut::<6>(PER_NODE * j);
                g += bj.transpose() * r;
                for (l, bl) in &blocks {
                    let mut m = matrix.fixed_view_mut::<6, 6>(PER_NODE * j, PER_NODE * l);
                    m += bj.transpose() * bl;
                }
            }
        }
        (matrix, gradient)
    }

    /// The blended projector at correspondence `c` (its grid `weights`) against its point
    /// ([`Blend`]); `None` where the projector or the way to the point has no direction, or
    /// the point lies at the prior's start.
    fn blend(
        &self,
        c: &Correspondence,
        weights: &[(usize, f64)],
        y: &DVector<f64>,
    ) -> Option<Blend> {
        let (mut s, mut d, mut s0) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        for &(j, w) in weights {
            s += w * self.start(j, y);
            d += w * self.dir(j, y);
            s0 += w * self.origins[j];
        }
        let to = c.point - s;
        let reach = (c.point - s0).length();
        (reach > 0.0).then_some(())?;
        Some(Blend {
            n: d.try_normalize()?,
            n_len: d.length(),
            m: to.try_normalize()?,
            m_len: to.length(),
            reach,
        })
    }

    /// The squared miss of correspondence `c` (its grid `weights`) at `y`: `Blend::residual`
    /// squared, `REVERSED` where it has none.
    fn miss_squared(&self, c: &Correspondence, weights: &[(usize, f64)], y: &DVector<f64>) -> f64 {
        self.blend(c, weights, y)
            .map_or(REVERSED, |b| b.residual().length_squared())
    }

    /// The model's Gauss-Newton matrix and gradient at `y`: data, smoothness and the common
    /// slide's penalty, no pull (what the nodes are determined by).
    fn linearise_model(&self, y: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
        let (matrix, gradient) = self.banded_model(y);
        (self.with_slide(matrix), gradient)
    }

    /// [`Problem::linearise_model`] less the slide penalty's matrix (a rank-one term over
    /// every start, outside the grid's band: [`Problem::slide_root`]).
    fn banded_model(&self, y: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
        let (matrix, gradient) = self.data_term(y);
        let slide = self.slide_weight * &self.slide;
        (
            matrix + &self.smooth,
            gradient + &self.smooth * y + &self.smooth_c + slide * self.slide.dot(y),
        )
    }

    /// `matrix` plus the slide penalty's matrix.
    fn with_slide(&self, matrix: DMatrix<f64>) -> DMatrix<f64> {
        matrix + &self.slide_root * self.slide_root.transpose()
    }
}

impl LeastSquares for Problem<'_> {
    fn cost(&self, y: &DVector<f64>) -> f64 {
        let mut weights = Vec::new();
        let data: f64 = self
            .correspondences
            .iter()
            .map(|c| {
                weights.clear();
                self.prior
                    .for_each_weight(c.uv, |j, w| weights.push((j, w)));
                self.miss_squared(c, &weights, y)
            })
            .sum();
        let smooth = self.mu * (&self.rows * y + &self.constant).norm_squared();
        let pull: f64 = (y - &self.prior_y)
            .iter()
            .zip(self.pull.iter())
            .map(|(d, w)| w * d * d)
            .sum();
        data + smooth + pull + self.slide_weight * self.slide.dot(y).powi(2)
    }

    fn linearise(&self, y: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
        let (mut matrix, mut gradient) = self.banded_model(y);
        for i in 0..y.len() {
            matrix[(i, i)] += self.pull[i];
            gradient[i] += self.pull[i] * (y[i] - self.prior_y[i]);
        }
        (matrix, gradient)
    }

    fn rank_one(&self) -> Option<&DVector<f64>> {
        Some(&self.slide_root)
    }
}

/// The squared miss counted where a projector or the way to its point has no direction (a
/// reversed projector's chord, 2, squared).
const REVERSED: f64 = 4.0;

/// A blended projector against its correspondence's point X.
struct Blend {
    /// The unit blended direction D(u, v) and its length.
    n: DVec3,
    n_len: f64,
    /// The unit direction from the blended start S(u, v) to X and the distance.
    m: DVec3,
    m_len: f64,
    /// R: the distance from the prior's blended start to X (fixed while the fit moves).
    reach: f64,
}

impl Blend {
    /// max(|X - S| / R, 1).
    fn far(&self) -> f64 {
        (self.m_len / self.reach).max(1.0)
    }

    /// The chord n - m (2 sin(angle / 2) at the fit's own start) times max(|X - S| / R, 1)
    /// (module section "Cost"): where the start is farther from X than the prior's, about
    /// the point's distance from the projector over R, the angle seen from where the prior
    /// looks.
    fn residual(&self) -> DVec3 {
        (self.n - self.m) * self.far()
    }
}

/// a b^T.
fn outer(a: DVec3, b: DVec3) -> glam::DMat3 {
    glam::DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

#[cfg(test)]
mod tests {
    use glam::DVec2;

    use super::super::{fit_with, Starts};
    use super::*;
    pub(super) use crate::calibrate::grid::tests::lcg_uniform as uniform;
    use crate::projection::flexible::presets::Preset;
    use crate::projection::flexible::projector_grid::tests::{
        perspective_volume as perspective, preset_volume,
    };
    use crate::projection::flexible::projector_grid::GridInterpolation;
    use crate::projection::flexible::LinearVolume;

    /// A known projection the tests take points from: (u, v) and t to a point.
    pub(super) trait Truth {
        fn point(&self, uv: DVec2, t: f64) -> DVec3;
    }

    impl Truth for LinearVolume {
        fn point(&self, uv: DVec2, t: f64) -> DVec3 {
            LinearVolume::point(self, uv, t)
        }
    }

    impl Truth for ProjectorGrid {
        fn point(&self, uv: DVec2, t: f64) -> DVec3 {
            ProjectorGrid::point(self, uv, t)
        }
    }

    /// `count` points of `truth` at seeded image positions in `[lo, hi]^2` and depths t in
    /// (0.1, 0.6).
    pub(super) fn seen_by(
        truth: &impl Truth,
        count: usize,
        seed: u64,
        lo: f64,
        hi: f64,
    ) -> Vec<Correspondence> {
        let mut next = uniform(seed);
        (0..count)
            .map(|_| {
                let uv = DVec2::new(lo + (hi - lo) * next(), lo + (hi - lo) * next());
                Correspondence {
                    uv,
                    point: truth.point(uv, 0.1 + 0.5 * next()),
                }
            })
            .collect()
    }

    /// The pushbroom and crossed-slits truths (bilinear in (u, v), no common eye).
    pub(super) fn truths() -> [LinearVolume; 2] {
        [
            preset_volume(
                Preset::Pushbroom {
                    width: 6.0,
                    v_fov: 50.0,
                },
                [1.0, 30.0],
            ),
            preset_volume(
                Preset::CrossedSlits {
                    fov: 60.0,
                    v_fov: None,
                    slit_distance: -2.0,
                },
                [1.0, 30.0],
            ),
        ]
    }

    /// A 3 x 3 perspective prior with the fixture's eye.
    pub(super) fn prior() -> ProjectorGrid {
        ProjectorGrid::sample(
            &perspective(60.0, [1.0, 40.0]),
            (3, 3),
            GridInterpolation::Bilinear,
        )
        .unwrap()
    }

    /// The largest distance, over a 9 x 9 grid of (u, v), from the truth's points at
    /// t = 0.1 and 0.6 to the fitted projector's line.
    pub(super) fn farthest_miss(
        fitted: &ProjectorGrid,
        truth: &impl Truth,
        lo: f64,
        hi: f64,
    ) -> f64 {
        let mut worst = 0.0f64;
        for i in 0..=8 {
            for j in 0..=8 {
                let uv = DVec2::new(
                    lo + (hi - lo) * f64::from(i) / 8.0,
                    lo + (hi - lo) * f64::from(j) / 8.0,
                );
                let (s, e) = fitted.start_end(uv);
                let d = (e - s).normalize();
                for t in [0.1, 0.6] {
                    worst = worst.max((truth.point(uv, t) - s).cross(d).length());
                }
            }
        }
        worst
    }

    #[test]
    fn recovers_pushbroom_and_crossed_slits_from_a_perspective_prior() {
        for truth in truths() {
            for count in [12, 50] {
                let data = seen_by(&truth, count, 3, 0.0, 1.0);
                let (fitted, report) = fit_with(&prior(), &data, Starts::Free).unwrap();
                assert!(
                    farthest_miss(&fitted, &truth, 0.0, 1.0) < 1e-5,
                    "{count} {report:?}"
                );
                assert!(report.max_angle_deg < 1e-6, "{report:?}");
                assert_eq!(report.starts, FittedStarts::Free);
                assert_eq!(report.sparse_nodes, 0, "{report:?}");
                // `auto` takes it: kept starts and one eye miss these data.
                let (auto, auto_report) = fit_with(&prior(), &data, Starts::Auto).unwrap();
                assert_eq!(auto_report.starts, FittedStarts::Free);
                assert_eq!(auto, fitted);
            }
        }
    }

    /// 200 correspondences of `truth` (drawn with `seed`) whose image positions carry noise
    /// of up to 1.5e-3 in u and v (about half a pixel of a 320-pixel image), kept in the
    /// image.
    fn noisy(truth: &impl Truth, seed: u64) -> Vec<Correspondence> {
        let mut next = uniform(100 + seed);
        seen_by(truth, 200, seed, 0.0, 1.0)
            .into_iter()
            .map(|c| Correspondence {
                uv: (c.uv + 3e-3 * DVec2::new(next() - 0.5, next() - 0.5))
                    .clamp(DVec2::ZERO, DVec2::ONE),
                ..c
            })
            .collect()
    }

    #[test]
    fn noisy_pushbroom_data_take_free_starts_near_the_truth() {
        // Before the residual was scaled by max(|X - S| / R, 1) and `auto`
        // compared misses seen from the prior's starts (module section "Cost",
        // `fit::misses_seen_from`), noisy pushbroom data in the CLI table (docs/flexible.md,
        // "Noisy non-central data") gave free fits with receding starts and `auto` an eye
        // far behind the points.
        let [pushbroom, _] = truths();
        for seed in [1, 2] {
            let data = noisy(&pushbroom, seed);
            let (fitted, report) = fit_with(&prior(), &data, Starts::Auto).unwrap();
            let miss = farthest_miss(&fitted, &pushbroom, 0.0, 1.0);
            assert_eq!(report.starts, FittedStarts::Free, "{report:?}");
            // Measured 0.060 and 0.052 (points up to 18 from the starts: about 3e-3 rad,
            // the noise's size).
            assert!(miss < 0.15, "seed {seed}: {miss}");
        }
    }

    #[test]
    fn a_pushbroom_length_pattern_is_no_wild_node_but_a_stretched_or_turned_node_is() {
        // Noisy pushbroom data (`noisy`, seed 1) fitted with free starts, then the node
        // lengths set affine in u from 0.02 to 2.02 times the fit's: a pushbroom's nodes along
        // a row share one direction, so no blended line moves (the lengths noisy fits drift
        // to; docs/flexible.md, "Wild nodes"), though the u = 0 column is 50 times shorter
        // than the median node and the length bar alone (4 times) counts it wild.
        let [pushbroom, _] = truths();
        let data = noisy(&pushbroom, 1);
        let (fitted, report) = fit_with(&prior(), &data, Starts::Free).unwrap();
        assert_eq!(report.wild_nodes, 0, "{report:?}");
        let starts = fitted.starts();
        let scaled = |factor: &dyn Fn(usize) -> f64| {
            let ends = (0..9)
                .map(|j| starts[j] + (fitted.ends()[j] - starts[j]) * factor(j))
                .collect();
            fitted.with_ends(ends).unwrap()
        };
        let affine = |j: usize| 0.02 + (j % 3) as f64;
        let gauge = scaled(&affine);
        assert!(farthest_miss(&gauge, &pushbroom, 0.0, 1.0) < 0.15);
        assert_eq!(super::super::wild_nodes(&prior(), &gauge, &data), 0);
        // The same fit with every node as long as the centre one, then the centre node 10
        // times as long: the lines around it move, wild. Or a node turned by 90 degrees.
        let length = |j: usize| (fitted.ends()[j] - starts[j]).length();
        let even = |j: usize| length(4) / length(j);
        assert_eq!(super::super::wild_nodes(&prior(), &scaled(&even), &data), 0);
        let stretched = scaled(&|j| even(j) * if j == 4 { 10.0 } else { 1.0 });
        assert_eq!(super::super::wild_nodes(&prior(), &stretched, &data), 1);
        let mut ends = scaled(&even).ends().to_vec();
        let d = ends[8] - starts[8];
        ends[8] = starts[8] + d.cross(DVec3::X).normalize() * d.length();
        let turned = fitted.with_ends(ends).unwrap();
        assert_eq!(super::super::wild_nodes(&prior(), &turned, &data), 1);
    }

    #[test]
    fn points_on_one_projector_are_met_and_reported_undetermined() {
        let [pushbroom, _] = truths();
        let uv = DVec2::new(0.3, 0.6);
        let line: Vec<_> = (0..8)
            .map(|k| Correspondence {
                uv,
                point: pushbroom.point(uv, 0.1 + 0.07 * f64::from(k)),
            })
            .collect();
        let (fitted, report) = fit_with(&prior(), &line, Starts::Free).unwrap();
        // That projector meets them, but nothing says how the others run.
        let (s, e) = fitted.start_end(uv);
        for c in &line {
            assert!((c.point - s).cross((e - s).normalize()).length() < 1e-6);
        }
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        assert_eq!(report.sparse_nodes, 4, "{report:?}");
        assert!(report.warning().unwrap().contains("not determined"));
        // `auto` has no evidence for free starts (16 equations).
        let (_, auto) = fit_with(&prior(), &line, Starts::Auto).unwrap();
        assert_ne!(auto.starts, FittedStarts::Free, "{auto:?}");
    }

    #[test]
    fn points_in_one_cell_fit_that_cell_and_the_smoothness_carries_a_bilinear_truth() {
        for truth in truths() {
            let data = seen_by(&truth, 40, 7, 0.0, 0.5);
            let (fitted, report) = fit_with(&prior(), &data, Starts::Free).unwrap();
            assert_eq!(report.unconstrained_nodes, 5, "{report:?}");
            assert_eq!(report.sparse_nodes, 0, "{report:?}");
            // Measured 4e-4 in the cell (points up to 18 away: 2e-5 rad) and 0.035 over
            // the image: the unconstrained nodes continue the cell's affine fields, pulled
            // weakly (not at all would leave them free) to the prior.
            assert!(farthest_miss(&fitted, &truth, 0.0, 0.5) < 1e-3);
            assert!(farthest_miss(&fitted, &truth, 0.0, 1.0) < 0.05);
            // Too few points in the cell for its four nodes' 24 unknowns: reported.
            let (_, few) = fit_with(&prior(), &data[..3], Starts::Free).unwrap();
            assert!(few.sparse_nodes > 0, "{few:?}");
        }
    }

    #[test]
    fn coplanar_points_of_a_pushbroom_keep_the_simpler_model_and_the_planes_image() {
        let [pushbroom, _] = truths();
        // 40 points where the pushbroom's projectors meet the plane z = -4 (across the view).
        let mut next = uniform(11);
        let on_plane = |uv: DVec2| {
            let (s, e) = (pushbroom.point(uv, 0.0), pushbroom.point(uv, 1.0));
            s + (e - s) * ((-4.0 - s.z) / (e.z - s.z))
        };
        let data: Vec<_> = (0..40)
            .map(|_| {
                let uv = DVec2::new(next(), next());
                Correspondence {
                    uv,
                    point: on_plane(uv),
                }
            })
            .collect();
        let (fitted, report) = fit_with(&prior(), &data, Starts::Auto).unwrap();
        assert_ne!(report.starts, FittedStarts::Free, "{report:?}");
        // The plane's image is right everywhere: every projector meets its plane point.
        for i in 0..=8 {
            for j in 0..=8 {
                let uv = DVec2::new(f64::from(i), f64::from(j)) / 8.0;
                let (s, e) = fitted.start_end(uv);
                let miss = (on_plane(uv) - s).cross((e - s).normalize()).length();
                assert!(miss < 1e-3, "{uv}: {miss}");
            }
        }
    }
}
