//! The one tessellator behind every analytic shape: a rectangular grid of samples of a
//! parametric surface, split into counter-clockwise triangles.
//!
//! The grid has `columns + 1` x `rows + 1` vertices at parameters `(s, t)` in `[0,1]^2`
//! (`s` along a row, `t` across rows). Triangles are counter-clockwise seen from the side
//! `dP/ds x dP/dt` points to, so each shape picks its parametrisation to make that outward.
//!
//! A row may collapse to a single point (a sphere pole, the lid top of the teapot). Each quad
//! touching such a row would have one zero-area triangle; it is left out, so the row becomes
//! a triangle fan. Vertices on a collapsed row are still emitted per
//! column, so that each fan triangle keeps its own uv and its own limit normal.

use glam::{Vec2, Vec3};

use crate::scene::Mesh;

/// One sample of a parametric surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Vertex {
    pub position: Vec3,
    pub normal: Vec3,
    pub uv: Vec2,
}

/// Which of the outer rows of a grid collapse to a single point.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(super) struct CollapsedRows {
    /// The row at `t = 0`.
    pub first: bool,
    /// The row at `t = 1`.
    pub last: bool,
}

/// Number of triangles [`push_grid`] emits for a grid of this size (for tests of shapes
/// built from several grids).
#[cfg(test)]
pub(super) fn grid_triangle_count(columns: u32, rows: u32, collapsed: CollapsedRows) -> usize {
    let (columns, rows) = (columns.max(1) as usize, rows.max(1) as usize);
    2 * columns * rows - columns * (usize::from(collapsed.first) + usize::from(collapsed.last))
}

/// Appends a `columns` x `rows` quad grid sampled by `vertex(s, t)` to `mesh`.
///
/// `columns` and `rows` are raised to at least 1. `s = i / columns` and `t = j / rows` are
/// exactly 0 and 1 on the borders, so periodic shapes can make their seams coincide exactly.
/// When both outer rows are collapsed and `rows` is 1, every triangle would be degenerate:
/// nothing is emitted for that grid but its vertices.
pub(super) fn push_grid(
    mesh: &mut Mesh,
    columns: u32,
    rows: u32,
    collapsed: CollapsedRows,
    vertex: impl Fn(f32, f32) -> Vertex,
) {
    let (columns, rows) = (columns.max(1), rows.max(1));
    let base = mesh.positions.len() as u32;
    for j in 0..=rows {
        let t = j as f32 / rows as f32;
        for i in 0..=columns {
            let v = vertex(i as f32 / columns as f32, t);
            mesh.positions.push(v.position);
            mesh.normals.push(v.normal);
            mesh.uvs.push(v.uv);
        }
    }
    let index = |i: u32, j: u32| base + j * (columns + 1) + i;
    for j in 0..rows {
        for i in 0..columns {
            let (a, b) = (index(i, j), index(i + 1, j));
            let (c, d) = (index(i + 1, j + 1), index(i, j + 1));
            // On a collapsed first row a and b coincide; on a collapsed last row c and d do.
            if !(j == 0 && collapsed.first) {
                mesh.triangles.push([a, b, c]);
            }
            if !(j + 1 == rows && collapsed.last) {
                mesh.triangles.push([a, c, d]);
            }
        }
    }
}

/// `(cos, sin)` of the angle `fraction` of a full turn, computed in f64 so that closing
/// seams and poles land within f32 rounding of the exact values.
pub(super) fn turn(fraction: f32) -> (f32, f32) {
    let (sin, cos) = (std::f64::consts::TAU * fraction as f64).sin_cos();
    (cos as f32, sin as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(s: f32, t: f32) -> Vertex {
        Vertex {
            position: Vec3::new(s, t, 0.0),
            normal: Vec3::Z,
            uv: Vec2::new(s, t),
        }
    }

    #[test]
    fn grid_counts_and_winding() {
        let mut mesh = Mesh::default();
        push_grid(&mut mesh, 3, 2, CollapsedRows::default(), flat);
        assert_eq!(mesh.positions.len(), 12);
        assert_eq!(
            mesh.triangle_count(),
            grid_triangle_count(3, 2, CollapsedRows::default())
        );
        assert_eq!(mesh.triangle_count(), 12);
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "counter-clockwise about +z");
        }
        assert!(mesh.validate().is_ok());
    }

    #[test]
    fn collapsed_rows_drop_one_triangle_per_quad() {
        let both = CollapsedRows {
            first: true,
            last: true,
        };
        let mut mesh = Mesh::default();
        push_grid(&mut mesh, 4, 3, both, flat);
        assert_eq!(mesh.triangle_count(), 2 * 4 * 3 - 2 * 4);
        assert_eq!(mesh.triangle_count(), grid_triangle_count(4, 3, both));
        // A single row collapsed at both ends has no triangle left.
        let mut mesh = Mesh::default();
        push_grid(&mut mesh, 4, 1, both, flat);
        assert_eq!(mesh.triangle_count(), 0);
        assert_eq!(grid_triangle_count(4, 1, both), 0);
    }

    #[test]
    fn zero_sizes_are_raised_to_one() {
        let mut mesh = Mesh::default();
        push_grid(&mut mesh, 0, 0, CollapsedRows::default(), flat);
        assert_eq!(mesh.triangle_count(), 2);
        assert_eq!(grid_triangle_count(0, 0, CollapsedRows::default()), 2);
    }

    #[test]
    fn turn_is_exact_enough_at_quarters() {
        let (c, s) = turn(1.0);
        assert_eq!(c, 1.0);
        assert!(s.abs() < 1e-15);
        let (c, s) = turn(0.5);
        assert_eq!(c, -1.0);
        assert!(s.abs() < 1e-15);
    }
}
