//! Free-form control surfaces: bicubic Bezier patches and uniform cubic B-spline patches.
//!
//! Both are given by a grid of control points `control[row][column]`, rows along v (row 0 at
//! v = 0, the bottom of the image), columns along u (column 0 at u = 0). A Bezier patch
//! interpolates its four corner control points; a B-spline patch interpolates none of them in
//! general but is C2 everywhere, and a grid larger than 4 x 4 gives more control without
//! raising the degree (the thesis's "B-spline / NURBS patches", 5.1, in their uniform form).

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};

/// The cubic Bernstein weights at `s`.
fn bernstein3(s: f64) -> [f64; 4] {
    let r = 1.0 - s;
    [r * r * r, 3.0 * s * r * r, 3.0 * s * s * r, s * s * s]
}

/// The uniform cubic B-spline weights at local parameter `s` in [0, 1] of one span.
fn bspline3(s: f64) -> [f64; 4] {
    let r = 1.0 - s;
    let (s2, s3) = (s * s, s * s * s);
    [
        r * r * r / 6.0,
        (3.0 * s3 - 6.0 * s2 + 4.0) / 6.0,
        (-3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0) / 6.0,
        s3 / 6.0,
    ]
}

/// The tensor product of 4 x 4 control points `at(row, column)` with weights `wu`, `wv`.
fn tensor(at: impl Fn(usize, usize) -> DVec3, wu: [f64; 4], wv: [f64; 4]) -> DVec3 {
    let mut p = DVec3::ZERO;
    for (row, wr) in wv.iter().enumerate() {
        for (column, wc) in wu.iter().enumerate() {
            p += (wr * wc) * at(row, column);
        }
    }
    p
}

/// A bicubic Bezier patch: `control[row][column]`, 4 x 4 points.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierPatch {
    /// The 16 control points, `control[row][column]`.
    pub control: [[DVec3; 4]; 4],
}

impl BezierPatch {
    /// The patch point at (u, v); outside [0, 1]^2 the polynomial extrapolates.
    pub fn point(&self, uv: DVec2) -> DVec3 {
        tensor(
            |r, c| self.control[r][c],
            bernstein3(uv.x),
            bernstein3(uv.y),
        )
    }
}

/// A uniform cubic B-spline patch over a grid of `rows x columns >= 4 x 4` control points
/// (`control` row-major). u in [0, 1] spans the `columns - 3` polynomial pieces along a row
/// uniformly, v the `rows - 3` pieces along a column.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplinePatch {
    rows: usize,
    columns: usize,
    control: Vec<DVec3>,
}

impl BSplinePatch {
    /// A patch from `control[row][column]`. Errors: fewer than 4 rows or columns, or rows of
    /// different lengths.
    pub fn new(control: Vec<Vec<DVec3>>) -> Result<BSplinePatch> {
        let rows = control.len();
        let columns = control.first().map_or(0, Vec::len);
        if rows < 4 || columns < 4 {
            return Err(Error::new(format!(
                "bspline surface needs at least 4 x 4 control points, got {rows} x {columns}"
            )));
        }
        if let Some(bad) = control.iter().position(|row| row.len() != columns) {
            return Err(Error::new(format!(
                "bspline surface rows must have equal lengths: row {} has {} points, row 1 has \
                 {columns}",
                bad + 1,
                control[bad].len()
            )));
        }
        Ok(BSplinePatch {
            rows,
            columns,
            control: control.into_iter().flatten().collect(),
        })
    }

    /// Rows and columns of the control grid.
    pub fn size(&self) -> (usize, usize) {
        (self.rows, self.columns)
    }

    /// The control points, row-major.
    pub fn control(&self) -> &[DVec3] {
        &self.control
    }

    /// The patch point at (u, v). Outside [0, 1]^2 the end spans extrapolate.
    pub fn point(&self, uv: DVec2) -> DVec3 {
        let (first_column, su) = span(uv.x, self.columns - 3);
        let (first_row, sv) = span(uv.y, self.rows - 3);
        tensor(
            |r, c| self.control[(first_row + r) * self.columns + first_column + c],
            bspline3(su),
            bspline3(sv),
        )
    }
}

/// The span of `pieces` uniform spans that parameter `x` in [0, 1] falls in, and the local
/// parameter within it (x = 1 belongs to the last span, at local 1; values outside [0, 1]
/// extrapolate the end spans).
fn span(x: f64, pieces: usize) -> (usize, f64) {
    let scaled = x * pieces as f64;
    let index = (scaled.floor().max(0.0) as usize).min(pieces - 1);
    (index, scaled - index as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 4 x 4 grid of the plane z = 0 over [0, 3]^2: x = column, y = row.
    fn grid(rows: usize, columns: usize) -> Vec<Vec<DVec3>> {
        (0..rows)
            .map(|r| {
                (0..columns)
                    .map(|c| DVec3::new(c as f64, r as f64, 0.0))
                    .collect()
            })
            .collect()
    }

    #[test]
    fn bezier_interpolates_corners_and_reproduces_a_plane() {
        let g = grid(4, 4);
        let control = std::array::from_fn(|r| std::array::from_fn(|c| g[r][c]));
        let b = BezierPatch { control };
        assert_eq!(b.point(DVec2::ZERO), DVec3::ZERO);
        assert_eq!(b.point(DVec2::ONE), DVec3::new(3.0, 3.0, 0.0));
        // Equally spaced control points give the linear parameterisation.
        let p = b.point(DVec2::new(0.25, 0.5));
        assert!((p - DVec3::new(0.75, 1.5, 0.0)).length() < 1e-12, "{p}");
    }

    #[test]
    fn bspline_of_a_uniform_grid_is_linear_in_its_inner_range() {
        // A uniform cubic B-spline reproduces linear functions: the patch of an equally spaced
        // grid covers the inner range [1, columns - 2] x [1, rows - 2] linearly.
        let s = BSplinePatch::new(grid(5, 6)).unwrap();
        for (uv, want) in [
            (DVec2::ZERO, DVec3::new(1.0, 1.0, 0.0)),
            (DVec2::ONE, DVec3::new(4.0, 3.0, 0.0)),
            (DVec2::new(0.5, 0.25), DVec3::new(2.5, 1.5, 0.0)),
        ] {
            assert!(
                (s.point(uv) - want).length() < 1e-12,
                "{uv}: {}",
                s.point(uv)
            );
        }
    }

    #[test]
    fn bspline_spans_join_continuously() {
        let mut g = grid(4, 5);
        g[2][2].z = 3.0; // a bump shared by both spans along u
        let s = BSplinePatch::new(g).unwrap();
        let eps = 1e-9;
        let left = s.point(DVec2::new(0.5 - eps, 0.4));
        let right = s.point(DVec2::new(0.5 + eps, 0.4));
        assert!((left - right).length() < 1e-8);
        assert!(s.point(DVec2::new(0.5, 0.5)).z > 0.0);
    }

    #[test]
    fn bspline_grids_too_small_or_ragged_are_errors() {
        assert!(BSplinePatch::new(grid(3, 4))
            .unwrap_err()
            .message
            .contains("4 x 4"));
        assert!(BSplinePatch::new(Vec::new()).is_err());
        let mut g = grid(4, 4);
        g[2].pop();
        let e = BSplinePatch::new(g).unwrap_err();
        assert!(e.message.contains("row 3 has 3"), "{e}");
    }
}
