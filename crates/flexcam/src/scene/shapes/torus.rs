//! A torus.

use glam::{Vec2, Vec3};

use super::grid::{push_grid, turn, CollapsedRows, Vertex};
use crate::scene::Mesh;

/// Fewest segments around either circle.
const MIN_SEGMENTS: u32 = 3;

/// A torus about the y axis: a tube of radius `minor` swept along a circle of radius `major`
/// in the xz plane, with `tessellation` segments around each circle (at least 3):
/// `2 * tessellation^2` triangles. u runs around the ring from +x, v around the tube from
/// its outer equator, upward first.
///
/// Degenerate input: tessellation below 3 is raised to it; negative radii are taken by
/// absolute value. `minor > major` gives a self-intersecting spindle torus and zero radii
/// give zero-area triangles, both with valid unit normals.
pub fn torus(major: f32, minor: f32, tessellation: u32) -> Mesh {
    let (major, minor) = (major.abs(), minor.abs());
    let segments = tessellation.max(MIN_SEGMENTS);
    let mut mesh = Mesh::default();
    push_grid(
        &mut mesh,
        segments,
        segments,
        CollapsedRows::default(),
        |s, t| {
            let ring = ring_direction(s);
            let (cos_tube, sin_tube) = turn(t);
            let normal = cos_tube * ring + sin_tube * Vec3::Y;
            Vertex {
                position: major * ring + minor * normal,
                normal,
                uv: Vec2::new(s, t),
            }
        },
    );
    mesh
}

/// The unit direction in the xz plane `s` turns from +x towards -z (so that, with the tube
/// angle as t, d/ds x d/dt points out of the tube).
fn ring_direction(s: f32) -> Vec3 {
    let (c, s_) = turn(s);
    Vec3::new(c, 0.0, -s_)
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::super::test_support::*;
    use super::*;

    /// The point of the core circle nearest to `p`.
    fn core_point(p: Vec3) -> Vec3 {
        2.0 * Vec3::new(p.x, 0.0, p.z).normalize()
    }

    #[test]
    fn torus_counts_and_shape() {
        for n in [3, 8, 24] {
            let mesh = torus(2.0, 0.5, n);
            assert_eq!(mesh.triangle_count(), 2 * (n * n) as usize);
            assert_well_formed(&mesh);
            assert_winding_matches_normals(&mesh);
            assert_outward(&mesh, core_point);
            assert!(is_closed(&mesh), "tessellation {n}");
            for p in &mesh.positions {
                assert!(((*p - core_point(*p)).length() - 0.5).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn torus_bounds_and_area_converge() {
        let mesh = torus(2.0, 0.5, 400);
        let (lo, hi) = mesh.bounds().unwrap();
        assert!((hi - Vec3::new(2.5, 0.5, 2.5)).abs().max_element() < 1e-4);
        assert!((lo + Vec3::new(2.5, 0.5, 2.5)).abs().max_element() < 1e-4);
        let exact = 4.0 * PI * PI * 2.0 * 0.5;
        assert!((area(&mesh) - exact).abs() / exact < 1e-3);
    }

    #[test]
    fn torus_degenerate_parameters() {
        assert_eq!(torus(1.0, 0.2, 1).triangle_count(), 18);
        // Where the spindle's tube crosses the axis the winding turns over; only validity
        // and finite unit normals are promised there.
        let spindle = torus(0.5, 1.0, 12);
        assert!(spindle.validate().is_ok());
        assert!(spindle
            .normals
            .iter()
            .all(|n| (n.length() - 1.0).abs() < 1e-5));
        let point = torus(0.0, 0.0, 6);
        assert!(point.validate().is_ok());
        assert!(point
            .normals
            .iter()
            .all(|n| (n.length() - 1.0).abs() < 1e-5));
    }
}
