//! A user-defined re-parameterisation (thesis 4.3: "any 2D map"): a grid of (u, v) samples
//! over the image, interpolated bilinearly or bicubically, with its inverse by Newton's
//! method (what the scanline renderer needs).
//!
//! Image coordinates are (s, t) in [0, 1]^2, s = x / W to the right and t = 1 - y / H
//! upwards, so the grid whose samples are their own positions is the linear map. Sample
//! (i, j) sits at (s, t) = (i / (M - 1), j / (N - 1)) for M columns and N rows; row 0 is
//! the bottom of the image.
//!
//! Degenerate cases, each refused by [`UvGrid::new`] with the cell it happens in: a cell
//! whose map folds or collapses (its Jacobian determinant vanishes or changes sign against
//! the grid's orientation; for bilinear cells the determinant is affine in the cell's local
//! coordinates, so its corners decide exactly, for bicubic cells it is checked at
//! [`BICUBIC_CHECKS`]^2 points), and a border that crosses itself (two cells mapped onto
//! each other although neither folds). A map with a positive Jacobian everywhere and a
//! simple border is one-to-one, so the inverse is unique inside the image.
//!
//! Outside [0, 1]^2 the map continues the border cells' polynomials, so the inverse is
//! continuous across the image border (for triangles that cross it); there it is the root
//! Newton's method finds from the nearest sample, `None` where it finds none.

use glam::{DMat2, DVec2};

/// The most samples along either side of a grid.
pub const MAX_GRID_SIDE: usize = 129;

/// Points per side of a bicubic cell at which its Jacobian is checked, beyond the corners.
pub const BICUBIC_CHECKS: usize = 8;

/// Newton iterations before the inverse gives up.
const NEWTON_STEPS: usize = 60;

/// Starting samples tried by the inverse before it gives up.
const STARTS: usize = 9;

/// How a [`UvGrid`] interpolates between its samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleInterpolation {
    /// Bilinear in each cell: continuous, creased along the cell edges.
    Bilinear,
    /// Catmull-Rom in s and in t (the cubic through four neighbouring samples, the missing
    /// neighbours beyond the border extrapolated linearly): continuous first derivatives,
    /// through every sample, exact for affine grids.
    Bicubic,
}

/// The scene-file names of [`SampleInterpolation`].
pub const SAMPLE_INTERPOLATION_NAMES: [&str; 2] = ["bilinear", "bicubic"];

/// Why a grid was refused, with the sample (row-major index) to point at when one is to
/// blame.
#[derive(Debug, Clone, PartialEq)]
pub struct GridProblem {
    /// The first (bottom-left) sample of the offending cell.
    pub sample: Option<usize>,
    /// One line saying what is wrong.
    pub message: String,
}

/// A checked grid of (u, v) samples.
#[derive(Debug, Clone, PartialEq)]
pub struct UvGrid {
    columns: usize,
    rows: usize,
    samples: Vec<DVec2>,
    interpolation: SampleInterpolation,
    buckets: Buckets,
}

impl UvGrid {
    /// A grid of `columns` x `rows` samples, row-major from the bottom row. Errors: a side
    /// outside 2..=[`MAX_GRID_SIDE`], a sample count other than `columns * rows`, a sample
    /// that is not finite, a folding or collapsed cell, a border that crosses itself.
    pub fn new(
        columns: usize,
        rows: usize,
        samples: Vec<DVec2>,
        interpolation: SampleInterpolation,
    ) -> Result<Self, GridProblem> {
        let problem = |sample: Option<usize>, message: String| GridProblem { sample, message };
        for (side, n) in [("columns", columns), ("rows", rows)] {
            if !(2..=MAX_GRID_SIDE).contains(&n) {
                return Err(problem(
                    None,
                    format!("a uv grid needs 2 to {MAX_GRID_SIDE} {side}, got {n}"),
                ));
            }
        }
        if samples.len() != columns * rows {
            return Err(problem(
                None,
                format!(
                    "a uv grid of {columns} x {rows} needs {} samples, got {}",
                    columns * rows,
                    samples.len()
                ),
            ));
        }
        if let Some(i) = samples.iter().position(|p| !p.is_finite()) {
            return Err(problem(
                Some(i),
                format!("uv grid sample {i} is not finite: {}", samples[i]),
            ));
        }
        let buckets = Buckets::new(&samples);
        let grid = UvGrid {
            columns,
            rows,
            samples,
            interpolation,
            buckets,
        };
        grid.check_cells()?;
        grid.check_border()?;
        Ok(grid)
    }

    /// Samples along s.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Samples along t.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The interpolation between samples.
    pub fn interpolation(&self) -> SampleInterpolation {
        self.interpolation
    }

    /// (u, v) at image position `st` (continued beyond [0, 1]^2 by the border cells).
    pub fn uv(&self, st: DVec2) -> DVec2 {
        let (cell, local) = self.locate(st);
        self.cell_value(cell, local)
    }

    /// The image position (s, t) whose (u, v) is `uv`, by Newton's method from the nearest
    /// samples; `None` when it does not converge. Unique inside [0, 1]^2 (the grid does not
    /// fold), and a root there is preferred: the border cells' continued polynomials may
    /// take `uv` again outside, and Newton's method from a near sample may end there.
    /// Otherwise the root found from the nearest sample that gives one.
    pub fn st(&self, uv: DVec2) -> Option<DVec2> {
        let mut outside = None;
        for k in self.buckets.nearest(&self.samples, uv, STARTS) {
            match self.newton(uv, self.sample_st(k)) {
                Some(st) if Self::in_image(st) => return Some(st),
                Some(st) => outside = outside.or(Some(st)),
                None => {}
            }
        }
        outside
    }

    /// Whether `st` lies in the image [0, 1]^2, up to what Newton's tolerance moves a root
    /// on the border.
    fn in_image(st: DVec2) -> bool {
        const SLACK: f64 = 1e-9;
        st.cmpge(DVec2::splat(-SLACK)).all() && st.cmple(DVec2::splat(1.0 + SLACK)).all()
    }

    /// The (s, t) of sample `k`.
    fn sample_st(&self, k: usize) -> DVec2 {
        let (i, j) = (k % self.columns, k / self.columns);
        DVec2::new(
            i as f64 / (self.columns - 1) as f64,
            j as f64 / (self.rows - 1) as f64,
        )
    }

    /// Newton's method with step halving on |uv(st) - uv| from `start`.
    fn newton(&self, uv: DVec2, start: DVec2) -> Option<DVec2> {
        let tolerance = 1e-12 * self.buckets.scale;
        let mut st = start;
        let mut residual = self.uv(st) - uv;
        for _ in 0..NEWTON_STEPS {
            if residual.length() <= tolerance {
                return Some(st);
            }
            let jacobian = self.jacobian(st);
            let det = jacobian.determinant();
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            let step = jacobian.inverse() * residual;
            let mut lambda = 1.0;
            loop {
                let candidate = st - lambda * step;
                let r = self.uv(candidate) - uv;
                if r.length() < residual.length() {
                    st = candidate;
                    residual = r;
                    break;
                }
                lambda *= 0.5;
                if lambda < 1e-6 {
                    // No decrease: converged to rounding, or stuck.
                    return (residual.length() <= 1e3 * tolerance).then_some(st);
                }
            }
        }
        (residual.length() <= 1e3 * tolerance).then_some(st)
    }

    /// d(u, v)/d(s, t) at `st` (the columns are d/ds and d/dt).
    pub fn jacobian(&self, st: DVec2) -> DMat2 {
        let (cell, local) = self.locate(st);
        self.cell_jacobian(cell, local)
    }

    /// The cell (i, j) of `st` (border cells beyond the image) and the local coordinates
    /// in it (in [0, 1]^2 inside the image).
    fn locate(&self, st: DVec2) -> ((usize, usize), DVec2) {
        let x = st.x * (self.columns - 1) as f64;
        let y = st.y * (self.rows - 1) as f64;
        let cell = |x: f64, n: usize| (x.floor().max(0.0) as usize).min(n - 2);
        let (i, j) = (cell(x, self.columns), cell(y, self.rows));
        ((i, j), DVec2::new(x - i as f64, y - j as f64))
    }

    /// Sample (i, j) with indices one beyond the border extrapolated linearly.
    fn sample(&self, i: isize, j: isize) -> DVec2 {
        let (m, n) = (self.columns as isize, self.rows as isize);
        let at = |i: isize, j: isize| self.samples[(j * m + i) as usize];
        let column = |j: isize| {
            if i < 0 {
                2.0 * at(0, j) - at(1, j)
            } else if i >= m {
                2.0 * at(m - 1, j) - at(m - 2, j)
            } else {
                at(i, j)
            }
        };
        if j < 0 {
            2.0 * column(0) - column(1)
        } else if j >= n {
            2.0 * column(n - 1) - column(n - 2)
        } else {
            column(j)
        }
    }

    /// The weights of samples i - 1 .. i + 2 at local coordinate `f` and their derivatives.
    fn weights(&self, f: f64) -> ([f64; 4], [f64; 4]) {
        match self.interpolation {
            SampleInterpolation::Bilinear => ([0.0, 1.0 - f, f, 0.0], [0.0, -1.0, 1.0, 0.0]),
            SampleInterpolation::Bicubic => {
                let (f2, f3) = (f * f, f * f * f);
                (
                    [
                        0.5 * (-f + 2.0 * f2 - f3),
                        0.5 * (2.0 - 5.0 * f2 + 3.0 * f3),
                        0.5 * (f + 4.0 * f2 - 3.0 * f3),
                        0.5 * (-f2 + f3),
                    ],
                    [
                        0.5 * (-1.0 + 4.0 * f - 3.0 * f2),
                        0.5 * (-10.0 * f + 9.0 * f2),
                        0.5 * (1.0 + 8.0 * f - 9.0 * f2),
                        0.5 * (-2.0 * f + 3.0 * f2),
                    ],
                )
            }
        }
    }

    /// Σ wx[a] wy[b] p(i - 1 + a, j - 1 + b).
    fn combine(&self, (i, j): (usize, usize), wx: &[f64; 4], wy: &[f64; 4]) -> DVec2 {
        let mut sum = DVec2::ZERO;
        for (b, wy) in wy.iter().enumerate() {
            for (a, wx) in wx.iter().enumerate() {
                let w = wx * wy;
                if w != 0.0 {
                    sum +=
                        w * self.sample(i as isize - 1 + a as isize, j as isize - 1 + b as isize);
                }
            }
        }
        sum
    }

    fn cell_value(&self, cell: (usize, usize), local: DVec2) -> DVec2 {
        let (wx, _) = self.weights(local.x);
        let (wy, _) = self.weights(local.y);
        self.combine(cell, &wx, &wy)
    }

    fn cell_jacobian(&self, cell: (usize, usize), local: DVec2) -> DMat2 {
        let (wx, dx) = self.weights(local.x);
        let (wy, dy) = self.weights(local.y);
        DMat2::from_cols(
            (self.columns - 1) as f64 * self.combine(cell, &dx, &wy),
            (self.rows - 1) as f64 * self.combine(cell, &wx, &dy),
        )
    }

    /// The points per side at which a cell's Jacobian is checked.
    fn checks(&self) -> usize {
        match self.interpolation {
            SampleInterpolation::Bilinear => 1,
            SampleInterpolation::Bicubic => BICUBIC_CHECKS,
        }
    }

    /// The sign of the grid's orientation: of the signed area its border encloses.
    fn orientation(&self) -> f64 {
        let border = self.border();
        let area: f64 = border
            .iter()
            .zip(border.iter().cycle().skip(1))
            .map(|((a, _), (b, _))| a.perp_dot(*b))
            .sum();
        area.signum()
    }

    /// Every cell's Jacobian has the grid's orientation (see the module).
    fn check_cells(&self) -> Result<(), GridProblem> {
        let orientation = self.orientation();
        let k = self.checks();
        for j in 0..self.rows - 1 {
            for i in 0..self.columns - 1 {
                for b in 0..=k {
                    for a in 0..=k {
                        let local = DVec2::new(a as f64, b as f64) / k as f64;
                        let det = self.cell_jacobian((i, j), local).determinant();
                        // NaN (a non-finite Jacobian) counts as folding too.
                        let one_to_one = det * orientation > 0.0;
                        if !one_to_one {
                            return Err(GridProblem {
                                sample: Some(j * self.columns + i),
                                message: format!(
                                    "uv grid cell ({i}, {j}) (column, row from the bottom \
                                     left) folds: its map is not one-to-one there"
                                ),
                            });
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The border as a closed polygon (counter-clockwise in (s, t)), each point with its
    /// cell: the samples for bilinear grids, [`BICUBIC_CHECKS`] points per cell edge for
    /// bicubic ones.
    fn border(&self) -> Vec<(DVec2, (usize, usize))> {
        let k = self.checks();
        let (m, n) = (self.columns - 1, self.rows - 1);
        let mut points = Vec::with_capacity(2 * (m + n) * k);
        let mut edge = |cells: Vec<(usize, usize)>, local: &dyn Fn(f64) -> DVec2| {
            for cell in cells {
                for a in 0..k {
                    let f = a as f64 / k as f64;
                    points.push((self.cell_value(cell, local(f)), cell));
                }
            }
        };
        edge((0..m).map(|i| (i, 0)).collect(), &|f| DVec2::new(f, 0.0));
        edge((0..n).map(|j| (m - 1, j)).collect(), &|f| {
            DVec2::new(1.0, f)
        });
        edge((0..m).rev().map(|i| (i, n - 1)).collect(), &|f| {
            DVec2::new(1.0 - f, 1.0)
        });
        edge((0..n).rev().map(|j| (0, j)).collect(), &|f| {
            DVec2::new(0.0, 1.0 - f)
        });
        points
    }

    /// The border does not cross itself (no two non-neighbouring edges meet).
    fn check_border(&self) -> Result<(), GridProblem> {
        let border = self.border();
        let count = border.len();
        let segment = |k: usize| (border[k].0, border[(k + 1) % count].0);
        for a in 0..count {
            for b in a + 2..count {
                if a == 0 && b == count - 1 {
                    continue;
                }
                if segments_meet(segment(a), segment(b)) {
                    let ((i, j), (k, l)) = (border[a].1, border[b].1);
                    return Err(GridProblem {
                        sample: Some(j * self.columns + i),
                        message: format!(
                            "uv grid folds: its border at cell ({i}, {j}) crosses the border \
                             at cell ({k}, {l}), so two parts of the image would see the same \
                             (u, v)"
                        ),
                    });
                }
            }
        }
        Ok(())
    }
}

/// Whether the closed segments `p` and `q` share a point.
fn segments_meet(p: (DVec2, DVec2), q: (DVec2, DVec2)) -> bool {
    let (lo_p, hi_p) = (p.0.min(p.1), p.0.max(p.1));
    let (lo_q, hi_q) = (q.0.min(q.1), q.0.max(q.1));
    if hi_p.x < lo_q.x || hi_q.x < lo_p.x || hi_p.y < lo_q.y || hi_q.y < lo_p.y {
        return false;
    }
    let side = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let (d1, d2) = (side(q.0, q.1, p.0), side(q.0, q.1, p.1));
    let (d3, d4) = (side(p.0, p.1, q.0), side(p.0, p.1, q.1));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return true;
    }
    // Touching or collinear: an end on the other segment (the bounding boxes overlap).
    let on = |d: f64, a: DVec2, b: DVec2, c: DVec2| {
        d == 0.0 && a.min(b).cmple(c).all() && c.cmple(a.max(b)).all()
    };
    on(d1, q.0, q.1, p.0) || on(d2, q.0, q.1, p.1) || on(d3, p.0, p.1, q.0) || on(d4, p.0, p.1, q.1)
}

/// The samples bucketed on a square grid over their bounding box, for the nearest ones.
#[derive(Debug, Clone, PartialEq)]
struct Buckets {
    lo: DVec2,
    cell: DVec2,
    side: usize,
    /// Sample indices by bucket, row-major.
    members: Vec<Vec<usize>>,
    /// The bounding box's diagonal, at least 1: the inverse's length scale.
    scale: f64,
}

impl Buckets {
    fn new(samples: &[DVec2]) -> Self {
        let lo = samples.iter().fold(DVec2::INFINITY, |a, p| a.min(*p));
        let hi = samples.iter().fold(DVec2::NEG_INFINITY, |a, p| a.max(*p));
        let side = ((samples.len() as f64).sqrt().ceil() as usize).clamp(1, MAX_GRID_SIDE);
        let cell = ((hi - lo) / side as f64).max(DVec2::splat(f64::MIN_POSITIVE));
        let mut buckets = Buckets {
            lo,
            cell,
            side,
            members: vec![Vec::new(); side * side],
            scale: (hi - lo).length().max(1.0),
        };
        for (k, p) in samples.iter().enumerate() {
            let (x, y) = buckets.bucket(*p);
            buckets.members[y * side + x].push(k);
        }
        buckets
    }

    /// The bucket of `p`, clamped to the grid.
    fn bucket(&self, p: DVec2) -> (usize, usize) {
        let q = ((p - self.lo) / self.cell).floor();
        let clamp = |x: f64| (x.max(0.0) as usize).min(self.side - 1);
        (clamp(q.x), clamp(q.y))
    }

    /// Up to `count` samples nearest `p`, nearest first: those of the first ring of
    /// buckets round p's bucket that holds any, and of the next ring.
    fn nearest(&self, samples: &[DVec2], p: DVec2, count: usize) -> Vec<usize> {
        let (bx, by) = self.bucket(p);
        let mut found = Vec::new();
        let mut rings_after_hit = None;
        for ring in 0..self.side {
            let (lo_x, hi_x) = (bx.saturating_sub(ring), (bx + ring).min(self.side - 1));
            let (lo_y, hi_y) = (by.saturating_sub(ring), (by + ring).min(self.side - 1));
            for y in lo_y..=hi_y {
                for x in lo_x..=hi_x {
                    let on_ring = x.abs_diff(bx) == ring || y.abs_diff(by) == ring;
                    if on_ring {
                        found.extend_from_slice(&self.members[y * self.side + x]);
                    }
                }
            }
            if !found.is_empty() {
                match rings_after_hit {
                    None => rings_after_hit = Some(1),
                    Some(_) => break,
                }
            }
        }
        found.sort_by(|a, b| {
            let (da, db) = (samples[*a].distance(p), samples[*b].distance(p));
            da.total_cmp(&db)
        });
        found.truncate(count);
        found
    }
}

#[cfg(test)]
mod tests;
