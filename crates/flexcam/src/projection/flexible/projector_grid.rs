//! The projector-grid interface (Brosz 2011, section 5.2): a viewing volume interpolated from a
//! small grid of explicitly placed projectors, the way the thesis reproduces a painting.
//!
//! Node (c, r) of a `cols x rows` grid sits at (u, v) = (c / (cols - 1), r / (rows - 1)): column
//! 0 is the left edge of the image and row 0 the bottom. Every node holds a projector from a
//! start point S_j to an end point E_j, straight, or curved by an optional tangent (below). The
//! volume blends the nodes' quadratic Bezier control points,
//!
//! S(u, v) = sum_j w_j(u, v) S_j,  C(u, v) = sum_j w_j(u, v) C_j,  E(u, v) = sum_j w_j(u, v) E_j,
//! Q(u, v, t) = (1 - t)^2 S + 2 t (1 - t) C + t^2 E,
//!
//! with the weights w_j of the chosen [`GridInterpolation`]: bilinear within each cell (every
//! node's projector is met exactly; creases along cell edges) or one tensor-product Bezier
//! patch of degree (cols - 1, rows - 1) over all nodes (smooth; only the four corner
//! projectors are met exactly). t in [0, 1] is the near/far clip like in every flexible volume.
//!
//! # Tangents (the thesis's curved projectors, 5.2.1)
//!
//! A straight node has C_j = (S_j + E_j) / 2, which makes its quadratic the segment S_j E_j
//! with t uniform along it. A node with a tangent T_j leaves its start along T_j: C_j = S_j +
//! (|E_j - S_j| / 2) T_j / |T_j|, so the projector still runs from S_j to E_j, its direction at
//! the start is T_j, and only the tangent's direction matters (as in the thesis, which takes
//! the magnitude to be irrelevant). A tangent along the chord E_j - S_j gives C_j = the
//! midpoint, the straight projector itself, so such a node is stored as straight. The thesis attaches the tangent where the projector meets the
//! scene; here it is at the start, so that a node is defined by its start, end and tangent
//! alone, independent of where the scene happens to be; the thesis's form (through a scene
//! point, the tangent there) is converted to this one by
//! [`ProjectorGrid::set_projector_through`] (module `through`). A grid without tangents has
//! straight projectors everywhere and is cast as rays; a grid with any tangent is cast as
//! quadratic Bezier projectors ([`Projector::QuadraticBezier`], the representation of the
//! three-surface Bezier volumes).
//!
//! Degenerate tangents: a zero tangent means "no tangent" (straight), and so does one along
//! the chord (within rounding, `ALONG_CHORD`); a tangent opposite to
//! the chord is an error (the projector would run backwards from its start and fold back over
//! itself along one line, seeing what lies behind the image plane).
//!
//! A grid starts as a sample of any volume with straight projectors (the thesis fills it as a
//! perspective frustum from the perspective preset); [`ProjectorGrid::set_projector`] places
//! one node's projector explicitly, [`ProjectorGrid::aim`] re-aims one through a scene point,
//! and the grid fit of `crate::calibrate` aims all of them at once from point correspondences
//! (module `correspondence`).

use glam::{DVec2, DVec3};

use super::linear_volume::LinearVolume;
use crate::error::{Error, Result};
use crate::geometry::Ray;
use crate::projection::projector::{quadratic_point, quadratic_tangent};
use crate::projection::{BuildReport, Projector};

mod correspondence;
mod through;
pub use correspondence::{Correspondence, GridFitter, Starts};
pub use through::Through;

/// Fewest nodes per side: a grid needs two to span the domain.
pub const MIN_NODES: usize = 2;
/// Most nodes per side. The thesis uses 5 x 5; the limit keeps a Bezier grid's degree, and the
/// dense least-squares system of the fit (3 unknowns per node), small.
pub const MAX_NODES: usize = 9;

/// How the node projectors are blended over the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridInterpolation {
    /// Bilinear within each cell: interpolates every node projector, C0 across cell edges.
    Bilinear,
    /// One Bezier patch with the nodes as control points: smooth, interpolates the corners only.
    Bezier,
}

impl GridInterpolation {
    /// The scene-file name.
    pub fn name(self) -> &'static str {
        match self {
            GridInterpolation::Bilinear => "bilinear",
            GridInterpolation::Bezier => "bezier",
        }
    }
}

/// A grid of node projectors and the volume they interpolate.
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectorGrid {
    cols: usize,
    rows: usize,
    /// Row-major, row 0 (bottom) first.
    starts: Vec<DVec3>,
    ends: Vec<DVec3>,
    /// Unit tangents at the starts; `None`: a straight node.
    tangents: Vec<Option<DVec3>>,
    interpolation: GridInterpolation,
}

impl ProjectorGrid {
    /// A grid from explicit node projectors (row-major, bottom row first). Errors: a side
    /// outside [`MIN_NODES`]..=[`MAX_NODES`], point counts that do not match the size, a
    /// non-finite point, or a node whose start and end coincide.
    pub fn new(
        (cols, rows): (usize, usize),
        starts: Vec<DVec3>,
        ends: Vec<DVec3>,
        interpolation: GridInterpolation,
    ) -> Result<Self> {
        for (name, n) in [("columns", cols), ("rows", rows)] {
            if !(MIN_NODES..=MAX_NODES).contains(&n) {
                return Err(Error::new(format!(
                    "projector grid {name} must be from {MIN_NODES} to {MAX_NODES}, not {n}"
                )));
            }
        }
        let count = cols * rows;
        if starts.len() != count || ends.len() != count {
            return Err(Error::new(format!(
                "a {cols} x {rows} projector grid needs {count} start and end points, not {} \
                 and {}",
                starts.len(),
                ends.len()
            )));
        }
        for (j, (s, e)) in starts.iter().zip(&ends).enumerate() {
            node_tangent((j % cols, j / cols), *s, *e, None)?;
        }
        Ok(ProjectorGrid {
            cols,
            rows,
            starts,
            ends,
            tangents: vec![None; count],
            interpolation,
        })
    }

    /// A `cols x rows` grid sampling `volume` at the nodes: with bilinear interpolation it
    /// reproduces any volume whose control surfaces are bilinear in (u, v) (perspective,
    /// orthographic, oblique, ...) exactly; other volumes approximately.
    pub fn sample(
        volume: &LinearVolume,
        size: (usize, usize),
        interpolation: GridInterpolation,
    ) -> Result<Self> {
        let (cols, rows) = size;
        let uvs: Vec<DVec2> = (0..rows.max(1))
            .flat_map(|r| (0..cols.max(1)).map(move |c| node_uv(c, r, cols, rows)))
            .collect();
        let starts = uvs.iter().map(|&uv| volume.point(uv, 0.0)).collect();
        let ends = uvs.iter().map(|&uv| volume.point(uv, 1.0)).collect();
        ProjectorGrid::new(size, starts, ends, interpolation)
    }

    /// Nodes per side: (columns, rows).
    pub fn size(&self) -> (usize, usize) {
        (self.cols, self.rows)
    }

    /// The blending in use.
    pub fn interpolation(&self) -> GridInterpolation {
        self.interpolation
    }

    /// The (u, v) of node (`col`, `row`).
    pub fn node_uv(&self, col: usize, row: usize) -> DVec2 {
        node_uv(col, row, self.cols, self.rows)
    }

    /// Start points of the node projectors, row-major from the bottom row.
    pub fn starts(&self) -> &[DVec3] {
        &self.starts
    }

    /// End points of the node projectors, row-major from the bottom row.
    pub fn ends(&self) -> &[DVec3] {
        &self.ends
    }

    /// Unit tangents at the node projectors' starts (`None`: straight), in the order of
    /// [`ProjectorGrid::starts`].
    pub fn tangents(&self) -> &[Option<DVec3>] {
        &self.tangents
    }

    /// The grid with every node straight (its tangents dropped).
    pub fn straightened(&self) -> Self {
        ProjectorGrid {
            tangents: vec![None; self.tangents.len()],
            ..self.clone()
        }
    }

    /// Whether some node has a tangent, making the volume's projectors quadratic curves.
    pub fn is_curved(&self) -> bool {
        self.tangents.iter().any(Option::is_some)
    }

    /// Places node (`col`, `row`)'s projector explicitly: from `start` to `end`, leaving the
    /// start along `tangent` when one is given (a zero tangent is none; see the module docs).
    /// Errors: a node outside the grid, a non-finite value, `start` equal to `end`, or a
    /// tangent opposite to the chord `end - start`.
    pub fn set_projector(
        &mut self,
        (col, row): (usize, usize),
        start: DVec3,
        end: DVec3,
        tangent: Option<DVec3>,
    ) -> Result<()> {
        let j = self.index(col, row)?;
        self.tangents[j] = node_tangent((col, row), start, end, tangent)?;
        self.starts[j] = start;
        self.ends[j] = end;
        Ok(())
    }

    /// Places node (`col`, `row`)'s projector the thesis's way (5.2.1): from `start` through
    /// the scene point `through.point`, with its direction there along `through.tangent`
    /// when one is given, its end `through.length` from the start (default: the node's length,
    /// lengthened like [`ProjectorGrid::aim`]'s when the point is farther) (see the `through` module's
    /// docs for the construction and its errors). Without a tangent this is the straight node
    /// `set_projector` gives from `start + length * (point - start) / |point - start|`.
    pub fn set_projector_through(
        &mut self,
        (col, row): (usize, usize),
        start: DVec3,
        through: &Through,
    ) -> Result<()> {
        let j = self.index(col, row)?;
        let current = (self.ends[j] - self.starts[j]).length();
        let (end, tangent) = through::node_through((col, row), start, through, current)?;
        self.set_projector((col, row), start, end, tangent)
    }

    /// The index of node (`col`, `row`) in the node lists; an error outside the grid.
    fn index(&self, col: usize, row: usize) -> Result<usize> {
        if col >= self.cols || row >= self.rows {
            return Err(Error::new(format!(
                "projector ({col}, {row}) is outside the {} x {} grid",
                self.cols, self.rows
            )));
        }
        Ok(row * self.cols + col)
    }

    /// Re-aims node (`col`, `row`) through scene point `hit` (the thesis's point-based
    /// placement): the projector keeps its start and its length, unless `hit` lies beyond
    /// that length, in which case it is lengthened to reach 1.01 times as far as `hit`, so the
    /// hit is inside the t range. Errors: a node outside the grid, a non-finite `hit`, or
    /// `hit` at the start point (no direction).
    pub fn aim(&mut self, col: usize, row: usize, hit: DVec3) -> Result<()> {
        let j = self.index(col, row)?;
        let start = self.starts[j];
        let direction = (hit - start).try_normalize().ok_or_else(|| {
            Error::new(format!(
                "projector ({col}, {row}) cannot be aimed at {hit}: it is not a point away \
                 from the projector's start"
            ))
        })?;
        let length = (self.ends[j] - start)
            .length()
            .max(1.01 * (hit - start).length());
        let tangent = self.tangents[j];
        self.set_projector((col, row), start, start + length * direction, tangent)
    }

    /// Replaces every node's end point (same order as [`ProjectorGrid::ends`]), keeping the
    /// starts and tangents; validated like [`ProjectorGrid::set_projector`].
    pub fn with_ends(&self, ends: Vec<DVec3>) -> Result<Self> {
        let mut grid =
            ProjectorGrid::new(self.size(), self.starts.clone(), ends, self.interpolation)?;
        for (j, tangent) in self.tangents.iter().enumerate() {
            let node = (j % self.cols, j / self.cols);
            grid.set_projector(node, grid.starts[j], grid.ends[j], *tangent)?;
        }
        Ok(grid)
    }

    /// The quadratic Bezier control point of node `j` (see the module docs).
    fn control(&self, j: usize) -> DVec3 {
        let (start, end) = (self.starts[j], self.ends[j]);
        match self.tangents[j] {
            Some(tangent) => start + 0.5 * (end - start).length() * tangent,
            None => 0.5 * (start + end),
        }
    }

    /// Calls `f(node index, weight)` for every node with a non-zero weight at (u, v); the
    /// weights sum to 1. (u, v) outside [0, 1]^2 is clamped to it.
    pub fn for_each_weight(&self, uv: DVec2, mut f: impl FnMut(usize, f64)) {
        let uv = uv.clamp(DVec2::ZERO, DVec2::ONE);
        match self.interpolation {
            GridInterpolation::Bilinear => {
                let (c, s) = cell(uv.x, self.cols);
                let (r, t) = cell(uv.y, self.rows);
                let j = r * self.cols + c;
                for (index, weight) in [
                    (j, (1.0 - s) * (1.0 - t)),
                    (j + 1, s * (1.0 - t)),
                    (j + self.cols, (1.0 - s) * t),
                    (j + self.cols + 1, s * t),
                ] {
                    if weight != 0.0 {
                        f(index, weight);
                    }
                }
            }
            GridInterpolation::Bezier => {
                let bu = bernstein(self.cols - 1, uv.x);
                let bv = bernstein(self.rows - 1, uv.y);
                for (r, wv) in bv.iter().enumerate() {
                    for (c, wu) in bu.iter().enumerate() {
                        let weight = wu * wv;
                        if weight != 0.0 {
                            f(r * self.cols + c, weight);
                        }
                    }
                }
            }
        }
    }

    /// The interpolated start and end of the projector of (u, v).
    pub fn start_end(&self, uv: DVec2) -> (DVec3, DVec3) {
        let (mut start, mut end) = (DVec3::ZERO, DVec3::ZERO);
        self.for_each_weight(uv, |j, w| {
            start += w * self.starts[j];
            end += w * self.ends[j];
        });
        (start, end)
    }

    /// The interpolated quadratic Bezier control points of the projector of (u, v): start,
    /// middle control point, end (the nodes' control points blended with the same weights).
    pub fn control_points(&self, uv: DVec2) -> [DVec3; 3] {
        let mut p = [DVec3::ZERO; 3];
        self.for_each_weight(uv, |j, w| {
            p[0] += w * self.starts[j];
            p[1] += w * self.control(j);
            p[2] += w * self.ends[j];
        });
        p
    }

    /// Q(u, v, t).
    pub fn point(&self, uv: DVec2, t: f64) -> DVec3 {
        if self.is_curved() {
            return quadratic_point(&self.control_points(uv), t);
        }
        let (start, end) = self.start_end(uv);
        start + t * (end - start)
    }

    /// dQ/dt at (u, v, t); for a grid without tangents the same for every t.
    pub fn tangent(&self, uv: DVec2, t: f64) -> DVec3 {
        if self.is_curved() {
            return quadratic_tangent(&self.control_points(uv), t);
        }
        let (start, end) = self.start_end(uv);
        end - start
    }

    /// The projector of (u, v) as a ray with t in [0, 1]; `None` for a curved grid (see
    /// [`ProjectorGrid::projector`]) and where the interpolated projector has zero length
    /// (node projectors pointing at each other can cancel).
    pub fn ray(&self, uv: DVec2) -> Option<Ray> {
        if self.is_curved() {
            return None;
        }
        let (origin, end) = self.start_end(uv);
        let direction = end - origin;
        (direction != DVec3::ZERO && direction.is_finite()).then_some(Ray {
            origin,
            direction,
            t_min: 0.0,
            t_max: 1.0,
        })
    }

    /// The projector of (u, v): a ray for a grid without tangents, else the quadratic Bezier
    /// curve of [`ProjectorGrid::control_points`]; `None` where it has zero length.
    pub fn projector(&self, uv: DVec2) -> Option<Projector> {
        if !self.is_curved() {
            return self.ray(uv).map(Projector::Straight);
        }
        let p = self.control_points(uv);
        let moves = p[1] != p[0] || p[2] != p[0];
        (moves && p.iter().all(|q| q.is_finite())).then_some(Projector::QuadraticBezier(p))
    }
}

/// The sine of the angle below which a tangent counts as along the chord (or opposite to it):
/// its control point is then off the chord by at most 1e-12 of the projector's length, which
/// is rounding noise.
const ALONG_CHORD: f64 = 1e-12;

/// Validates node `node`'s projector from `start` to `end` and returns its unit tangent
/// (`None` for no tangent, a zero one, or one along the chord: a straight node). Errors: a non-finite value, `start` equal to
/// `end`, or a tangent opposite to the chord (see the module docs).
fn node_tangent(
    (c, r): (usize, usize),
    start: DVec3,
    end: DVec3,
    tangent: Option<DVec3>,
) -> Result<Option<DVec3>> {
    let tangent = tangent.unwrap_or(DVec3::ZERO);
    if !start.is_finite() || !end.is_finite() || !tangent.is_finite() {
        return Err(Error::new(format!(
            "projector grid node ({c}, {r}) has a non-finite point or tangent"
        )));
    }
    if start == end {
        return Err(Error::new(format!(
            "projector grid node ({c}, {r}) has zero length (its start is its end)"
        )));
    }
    let Some(unit) = stable_unit(tangent) else {
        return Ok(None);
    };
    let chord = (end - start).normalize();
    if unit.cross(chord).length() > ALONG_CHORD {
        return Ok(Some(unit));
    }
    if unit.dot(chord) > 0.0 {
        // Along the chord: the quadratic is the straight projector itself.
        return Ok(None);
    }
    Err(Error::new(format!(
        "projector grid node ({c}, {r}): the tangent {tangent} points back along the \
         projector (from its end to its start), which would fold it over itself"
    )))
}

/// `v` normalised, or `v` itself when it is a unit vector to rounding (its squared length
/// within 4 ulp of 1), so that a stored tangent given again is stored bit for bit the same:
/// a tangent written out in shortest round-trip form (`flexcam fit`) loads back to the same
/// grid (normalising a unit vector again can move it by an ulp, back and forth). `None` for
/// a zero vector.
fn stable_unit(v: DVec3) -> Option<DVec3> {
    if (v.length_squared() - 1.0).abs() <= 4.0 * f64::EPSILON {
        return Some(v);
    }
    v.try_normalize()
}

/// One node projector re-aimed through a scene point ([`ProjectorGrid::aim`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aim {
    /// (column, row) of the node, (0, 0) at the bottom left.
    pub node: (usize, usize),
    /// The scene point the node's projector is re-aimed through.
    pub at: DVec3,
}

/// One node projector placed explicitly ([`ProjectorGrid::set_projector`]); the start and
/// end default to the sampled node's. With `through`, the projector is placed through a scene
/// point instead ([`ProjectorGrid::set_projector_through`]); `end` and `tangent` are then
/// unused (the tangent at the point is `through`'s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeProjector {
    /// (column, row) of the node, (0, 0) at the bottom left.
    pub node: (usize, usize),
    /// Where the projector starts; `None`: the sampled node's start.
    pub start: Option<DVec3>,
    /// Where the projector ends; `None`: the sampled node's end.
    pub end: Option<DVec3>,
    /// The direction the projector leaves its start in; `None`: straight.
    pub tangent: Option<DVec3>,
    /// The thesis's form: through a scene point, the tangent there.
    pub through: Option<Through>,
}

/// A projector grid as a scene describes it: sampled from the projection's own volume, then
/// nodes placed explicitly, then re-aimed node by node, then fitted to correspondences (each
/// step optional).
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectorGridSpec {
    /// Nodes per side: (columns, rows).
    pub size: (usize, usize),
    /// How projectors between the nodes are interpolated.
    pub interpolation: GridInterpolation,
    /// Node projectors placed explicitly.
    pub projectors: Vec<NodeProjector>,
    /// Node projectors re-aimed through scene points.
    pub aims: Vec<Aim>,
    /// Scene points the fitted grid must show at given image positions.
    pub correspondences: Vec<Correspondence>,
    /// Where the fitted projectors start (scene key `starts`; unused without correspondences).
    pub starts: Starts,
}

/// A projector grid in use as a viewing volume.
#[derive(Debug, Clone, PartialEq)]
pub struct GridVolume {
    /// The nodes' projectors and their interpolation.
    pub grid: ProjectorGrid,
}

impl GridVolume {
    /// Samples `base`, places the explicit node
    /// projectors, applies the aims in order, then, when there are correspondences, has
    /// `fitter` fit the grid to them and adds what it reports to `report`. Errors: correspondences without a fitter; the errors of
    /// [`ProjectorGrid::sample`], [`ProjectorGrid::set_projector`], [`ProjectorGrid::aim`] and
    /// of the fitter.
    pub fn build(
        spec: &ProjectorGridSpec,
        base: &LinearVolume,
        fitter: Option<&dyn GridFitter>,
        report: &mut BuildReport,
    ) -> Result<Self> {
        let mut grid = ProjectorGrid::sample(base, spec.size, spec.interpolation)?;
        for node in &spec.projectors {
            let (col, row) = node.node;
            let j = grid.index(col, row)?;
            let start = node.start.unwrap_or(grid.starts[j]);
            if let Some(through) = &node.through {
                grid.set_projector_through(node.node, start, through)?;
                continue;
            }
            let end = node.end.unwrap_or(grid.ends[j]);
            grid.set_projector(node.node, start, end, node.tangent)?;
        }
        for aim in &spec.aims {
            grid.aim(aim.node.0, aim.node.1, aim.at)?;
        }
        if spec.correspondences.is_empty() {
            return Ok(GridVolume { grid });
        }
        let fitter = fitter.ok_or_else(|| {
            Error::new(
                "a projector grid with `fit` correspondences is built with the grid fit \
                 (flexcam::calibrate::build)",
            )
        })?;
        let (grid, fitted) = fitter.fit(&grid, &spec.correspondences, spec.starts)?;
        report.extend(fitted);
        Ok(GridVolume { grid })
    }
}

/// The (u, v) of node (`col`, `row`) in a `cols x rows` grid.
fn node_uv(col: usize, row: usize, cols: usize, rows: usize) -> DVec2 {
    let along = |i: usize, n: usize| i as f64 / (n.max(2) - 1) as f64;
    DVec2::new(along(col, cols), along(row, rows))
}

/// The cell index along one axis of `n` nodes and the local coordinate in it, for x in
/// [0, 1]; x = 1 falls in the last cell at local coordinate 1.
fn cell(x: f64, n: usize) -> (usize, f64) {
    let cells = n - 1;
    let scaled = x * cells as f64;
    let index = (scaled.floor() as usize).min(cells - 1);
    (index, scaled - index as f64)
}

/// The Bernstein polynomials of degree `degree` at x.
fn bernstein(degree: usize, x: f64) -> Vec<f64> {
    // Built up degree by degree (de Casteljau's recurrence): exact partition of unity.
    let mut b = vec![1.0];
    for _ in 0..degree {
        let mut next = vec![0.0; b.len() + 1];
        for (i, &value) in b.iter().enumerate() {
            next[i] += (1.0 - x) * value;
            next[i + 1] += x * value;
        }
        b = next;
    }
    b
}

#[cfg(test)]
pub(crate) mod tests;
