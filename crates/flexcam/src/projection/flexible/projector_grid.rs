//! The projector-grid interface (seed 003, section 5.2): a viewing volume interpolated from a
//! small grid of explicitly placed projectors, the way the thesis reproduces a painting.
//!
//! Node (c, r) of a `cols x rows` grid sits at (u, v) = (c / (cols - 1), r / (rows - 1)): column
//! 0 is the left edge of the image and row 0 the bottom. Every node holds a straight projector
//! from a start point to an end point; the volume is
//!
//! Q(u, v, t) = (1 - t) S(u, v) + t E(u, v),  S = sum_j w_j(u, v) S_j,  E = sum_j w_j(u, v) E_j,
//!
//! with the weights w_j of the chosen [`GridInterpolation`]: bilinear within each cell (every
//! node's projector is met exactly; creases along cell edges) or one tensor-product Bezier
//! patch of degree (cols - 1, rows - 1) over all nodes (smooth; only the four corner
//! projectors are met exactly). Because the weights do not depend on t, the projector of every
//! (u, v) is straight, and t in [0, 1] is its near/far clip like in every flexible volume.
//!
//! A grid starts as a sample of any volume with straight projectors (the thesis fills it as a
//! perspective frustum from the perspective preset); [`ProjectorGrid::aim`] then re-aims one
//! projector through a scene point, and `fit` (module `fit`) aims all of them at once from
//! point correspondences.
//!
//! Curved projectors through a hit point with a given tangent (the thesis's quadratic
//! construction, 5.2.1) are not part of this grid yet: every projector here is straight.

use glam::{DVec2, DVec3};

use super::fit::{fit, Correspondence, FitReport};
use super::volume::{LinearVolume, Volume};
use crate::error::{Error, Result};
use crate::geometry::Ray;

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

/// A grid of straight node projectors and the volume they interpolate.
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectorGrid {
    cols: usize,
    rows: usize,
    /// Row-major, row 0 (bottom) first.
    starts: Vec<DVec3>,
    ends: Vec<DVec3>,
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
            let (c, r) = (j % cols, j / cols);
            if !s.is_finite() || !e.is_finite() {
                return Err(Error::new(format!(
                    "projector grid node ({c}, {r}) has a non-finite point"
                )));
            }
            if s == e {
                return Err(Error::new(format!(
                    "projector grid node ({c}, {r}) has zero length (its start is its end)"
                )));
            }
        }
        Ok(ProjectorGrid {
            cols,
            rows,
            starts,
            ends,
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

    /// Re-aims node (`col`, `row`) through scene point `hit` (the thesis's point-based
    /// placement): the projector keeps its start and its length, unless `hit` lies beyond
    /// that length, in which case it is lengthened to reach 1.01 times as far as `hit`, so the
    /// hit is inside the t range. Errors: a node outside the grid, a non-finite `hit`, or
    /// `hit` at the start point (no direction).
    pub fn aim(&mut self, col: usize, row: usize, hit: DVec3) -> Result<()> {
        if col >= self.cols || row >= self.rows {
            return Err(Error::new(format!(
                "projector ({col}, {row}) is outside the {} x {} grid",
                self.cols, self.rows
            )));
        }
        let j = row * self.cols + col;
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
        self.ends[j] = start + length * direction;
        Ok(())
    }

    /// Replaces every node's end point (same order as [`ProjectorGrid::ends`]), keeping the
    /// starts; validated like [`ProjectorGrid::new`].
    pub fn with_ends(&self, ends: Vec<DVec3>) -> Result<Self> {
        ProjectorGrid::new(self.size(), self.starts.clone(), ends, self.interpolation)
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

    /// Q(u, v, t).
    pub fn point(&self, uv: DVec2, t: f64) -> DVec3 {
        let (start, end) = self.start_end(uv);
        start + t * (end - start)
    }

    /// dQ/dt at (u, v): the same for every t.
    pub fn tangent(&self, uv: DVec2) -> DVec3 {
        let (start, end) = self.start_end(uv);
        end - start
    }

    /// The projector of (u, v) as a ray with t in [0, 1]; `None` where the interpolated
    /// projector has zero length (node projectors pointing at each other can cancel).
    pub fn ray(&self, uv: DVec2) -> Option<Ray> {
        let (origin, end) = self.start_end(uv);
        let direction = end - origin;
        (direction != DVec3::ZERO && direction.is_finite()).then_some(Ray {
            origin,
            direction,
            t_min: 0.0,
            t_max: 1.0,
        })
    }
}

/// One node projector re-aimed through a scene point ([`ProjectorGrid::aim`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aim {
    /// (column, row) of the node, (0, 0) at the bottom left.
    pub node: (usize, usize),
    pub at: DVec3,
}

/// A projector grid as a scene describes it: sampled from the projection's own volume, then
/// re-aimed node by node, then fitted to correspondences (each step optional).
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectorGridSpec {
    /// Nodes per side: (columns, rows).
    pub size: (usize, usize),
    pub interpolation: GridInterpolation,
    pub aims: Vec<Aim>,
    pub correspondences: Vec<Correspondence>,
}

/// A projector grid in use as a viewing volume, with the residual of its fit if it had one.
#[derive(Debug, Clone, PartialEq)]
pub struct GridVolume {
    pub grid: ProjectorGrid,
    pub fit: Option<FitReport>,
}

impl GridVolume {
    /// Samples `base` (which must have straight projectors), applies the aims in order, then
    /// fits the grid to the correspondences when there are any. Errors: a base with curved
    /// projectors, and the errors of [`ProjectorGrid::sample`], [`ProjectorGrid::aim`] and
    /// [`fit`].
    pub fn build(spec: &ProjectorGridSpec, base: &Volume) -> Result<Self> {
        let Volume::Linear(linear) = base else {
            return Err(Error::new(
                "a projector grid starts from a volume with straight projectors (a preset or \
                 near and far surfaces), not from blended surfaces",
            ));
        };
        let mut grid = ProjectorGrid::sample(linear, spec.size, spec.interpolation)?;
        for aim in &spec.aims {
            grid.aim(aim.node.0, aim.node.1, aim.at)?;
        }
        if spec.correspondences.is_empty() {
            return Ok(GridVolume { grid, fit: None });
        }
        let (grid, report) = fit(&grid, &spec.correspondences)?;
        Ok(GridVolume {
            grid,
            fit: Some(report),
        })
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
pub(super) mod tests {
    use super::*;
    use crate::projection::flexible::presets::{Preset, PresetSpec};
    use crate::projection::CameraFrame;

    /// A perspective volume with horizontal field of view `fov` (degrees), aspect 3:4, its
    /// control surfaces at the distances `clip`: the test fixture of grids and fits.
    pub(in crate::projection::flexible) fn perspective_volume(
        fov: f64,
        clip: [f64; 2],
    ) -> LinearVolume {
        let spec = PresetSpec {
            preset: Preset::Perspective { fov },
            frame: CameraFrame {
                position: DVec3::new(0.0, 1.0, 5.0),
                look_at: DVec3::new(0.0, 0.5, 0.0),
                up: DVec3::Y,
            },
            clip: Some(clip),
        };
        let (near, far) = spec.surfaces(0.75).unwrap();
        LinearVolume::new(near, far).unwrap()
    }

    fn uv_samples() -> impl Iterator<Item = DVec2> {
        (0..=12).flat_map(|i| (0..=12).map(move |j| DVec2::new(i as f64, j as f64) / 12.0))
    }

    #[test]
    fn a_bilinear_grid_reproduces_a_perspective_volume_exactly() {
        let volume = perspective_volume(70.0, [1.0, 50.0]);
        let grid = ProjectorGrid::sample(&volume, (5, 5), GridInterpolation::Bilinear).unwrap();
        for uv in uv_samples() {
            for t in [0.0, 0.3, 1.0] {
                let (a, b) = (grid.point(uv, t), volume.point(uv, t));
                assert!((a - b).length() < 1e-12 * b.length().max(1.0), "{uv} {t}");
            }
        }
    }

    #[test]
    fn a_bezier_grid_of_a_bilinear_volume_is_that_volume_too() {
        // Degree elevation: control points sampled from a (bi)linear function on a uniform
        // grid are that function's Bezier control points, so the patch reproduces it.
        let volume = perspective_volume(40.0, [1.0, 50.0]);
        let grid = ProjectorGrid::sample(&volume, (5, 4), GridInterpolation::Bezier).unwrap();
        for uv in uv_samples() {
            let (a, b) = (grid.point(uv, 1.0), volume.point(uv, 1.0));
            assert!((a - b).length() < 1e-9 * b.length(), "{uv}: {a} vs {b}");
        }
    }

    #[test]
    fn weights_are_a_partition_of_unity_and_bilinear_meets_every_node() {
        let volume = perspective_volume(60.0, [1.0, 50.0]);
        for interpolation in [GridInterpolation::Bilinear, GridInterpolation::Bezier] {
            let grid = ProjectorGrid::sample(&volume, (4, 3), interpolation).unwrap();
            for uv in uv_samples().chain([DVec2::new(-0.5, 2.0)]) {
                let mut sum = 0.0;
                grid.for_each_weight(uv, |_, w| sum += w);
                assert!((sum - 1.0).abs() < 1e-12, "{interpolation:?} {uv}");
            }
        }
        let mut grid = ProjectorGrid::sample(&volume, (4, 3), GridInterpolation::Bilinear).unwrap();
        grid.aim(2, 1, DVec3::new(3.0, 2.0, 0.0)).unwrap();
        let uv = grid.node_uv(2, 1);
        let ray = grid.ray(uv).unwrap();
        let to_hit = DVec3::new(3.0, 2.0, 0.0) - ray.origin;
        assert!(ray.direction.normalize().dot(to_hit.normalize()) > 1.0 - 1e-12);
    }

    #[test]
    fn bezier_meets_only_the_corner_projectors() {
        let volume = perspective_volume(60.0, [1.0, 50.0]);
        let mut grid = ProjectorGrid::sample(&volume, (5, 5), GridInterpolation::Bezier).unwrap();
        let before = grid.point(grid.node_uv(2, 2), 1.0);
        grid.aim(2, 2, DVec3::new(4.0, 0.0, 0.0)).unwrap();
        let after = grid.point(grid.node_uv(2, 2), 1.0);
        assert!((after - before).length() > 1e-3, "the centre moved");
        assert_ne!(
            after,
            grid.ends()[12],
            "the centre is approximated, not met"
        );
        for (c, r) in [(0, 0), (4, 0), (0, 4), (4, 4)] {
            let j = r * 5 + c;
            let p = grid.point(grid.node_uv(c, r), 1.0);
            assert!((p - grid.ends()[j]).length() < 1e-12);
        }
    }

    #[test]
    fn aiming_keeps_the_length_unless_the_hit_is_farther() {
        let volume = perspective_volume(60.0, [1.0, 50.0]);
        let mut grid = ProjectorGrid::sample(&volume, (3, 3), GridInterpolation::Bilinear).unwrap();
        let length = (grid.ends()[4] - grid.starts()[4]).length();
        let near_hit = grid.starts()[4] + DVec3::new(1.0, 0.0, 0.0);
        grid.aim(1, 1, near_hit).unwrap();
        assert!(((grid.ends()[4] - grid.starts()[4]).length() - length).abs() < 1e-9);
        let far_hit = grid.starts()[4] + DVec3::new(0.0, 0.0, -10.0 * length);
        grid.aim(1, 1, far_hit).unwrap();
        let new_length = (grid.ends()[4] - grid.starts()[4]).length();
        assert!((new_length - 10.1 * length).abs() < 1e-9 * new_length);
    }

    #[test]
    fn degenerate_grids_and_aims_are_errors() {
        let volume = perspective_volume(60.0, [1.0, 50.0]);
        let bilinear = GridInterpolation::Bilinear;
        for size in [(1, 5), (5, 10), (0, 0)] {
            let e = ProjectorGrid::sample(&volume, size, bilinear).unwrap_err();
            assert!(e.message.contains("must be from 2 to 9"), "{e}");
        }
        let e = ProjectorGrid::new((2, 2), vec![DVec3::ZERO; 4], vec![DVec3::ZERO; 3], bilinear)
            .unwrap_err();
        assert!(e.message.contains("needs 4 start and end points"), "{e}");
        let e = ProjectorGrid::new((2, 2), vec![DVec3::ZERO; 4], vec![DVec3::ZERO; 4], bilinear)
            .unwrap_err();
        assert!(e.message.contains("node (0, 0) has zero length"), "{e}");
        let mut ends = vec![DVec3::ONE; 4];
        ends[3] = DVec3::NAN;
        let e = ProjectorGrid::new((2, 2), vec![DVec3::ZERO; 4], ends, bilinear).unwrap_err();
        assert!(
            e.message.contains("node (1, 1) has a non-finite point"),
            "{e}"
        );
        let mut grid = ProjectorGrid::sample(&volume, (3, 3), bilinear).unwrap();
        assert!(grid.aim(3, 0, DVec3::ZERO).is_err());
        let start = grid.starts()[0];
        let e = grid.aim(0, 0, start).unwrap_err();
        assert!(e.message.contains("cannot be aimed"), "{e}");
    }

    #[test]
    fn opposite_node_projectors_can_cancel_to_no_ray() {
        let bilinear = GridInterpolation::Bilinear;
        let starts = vec![DVec3::ZERO; 4];
        let ends = vec![DVec3::X, DVec3::X, -DVec3::X, -DVec3::X];
        let grid = ProjectorGrid::new((2, 2), starts, ends, bilinear).unwrap();
        assert_eq!(grid.ray(DVec2::new(0.5, 0.5)), None);
        assert!(grid.ray(DVec2::new(0.3, 0.25)).is_some());
    }
}
