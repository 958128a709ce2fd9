//! A UV sphere.

use glam::{Vec2, Vec3};

use super::grid::{push_grid, turn, CollapsedRows, Vertex};
use crate::scene::Mesh;

/// Fewest segments around the sphere.
const MIN_SEGMENTS: u32 = 3;
/// Fewest rings from pole to pole.
const MIN_RINGS: u32 = 2;

/// A UV sphere of `radius` centred on the origin, with `tessellation` segments around the y
/// axis (at least 3) and `tessellation / 2` rings from pole to pole (at least 2).
///
/// The rows at the poles are triangle fans (no zero-area triangles); the seam and the poles
/// have one vertex per segment so that the uvs (u around from +x, v from the south pole up)
/// stay continuous. Triangles: `2 * segments * (rings - 1)`.
///
/// Degenerate input: tessellation below the minimum is raised to it; a negative radius is
/// taken by absolute value; radius 0 gives a point with valid unit normals.
pub fn sphere(radius: f32, tessellation: u32) -> Mesh {
    let radius = radius.abs();
    let (segments, rings) = sphere_grid(tessellation);
    let poles = CollapsedRows {
        first: true,
        last: true,
    };
    let mut mesh = Mesh::default();
    push_grid(&mut mesh, segments, rings, poles, |s, t| {
        let normal = unit_sphere_point(s, t);
        Vertex {
            position: radius * normal,
            normal,
            uv: Vec2::new(s, t),
        }
    });
    mesh
}

/// Segments around and rings from pole to pole for a `tessellation`.
fn sphere_grid(tessellation: u32) -> (u32, u32) {
    let segments = tessellation.max(MIN_SEGMENTS);
    (segments, (segments / 2).max(MIN_RINGS))
}

/// The point at longitude `s` turns and `t` half-turns from the south pole. Longitude runs
/// from +x towards -z, so that d/ds x d/dt points outward.
fn unit_sphere_point(s: f32, t: f32) -> Vec3 {
    let (cos_lon, sin_lon) = turn(s);
    let (cos_pol, sin_pol) = turn(0.5 * t);
    Vec3::new(sin_pol * cos_lon, -cos_pol, -sin_pol * sin_lon)
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::super::test_support::*;
    use super::*;

    #[test]
    fn sphere_counts_and_shape() {
        for n in [3, 4, 9, 16] {
            let mesh = sphere(2.0, n);
            let (segments, rings) = sphere_grid(n);
            assert_eq!(mesh.triangle_count(), (2 * segments * (rings - 1)) as usize);
            assert_well_formed(&mesh);
            assert_winding_matches_normals(&mesh);
            assert_outward(&mesh, |_| Vec3::ZERO);
            assert!(is_closed(&mesh), "tessellation {n}");
            for p in &mesh.positions {
                assert!((p.length() - 2.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn sphere_bounds_and_area_converge() {
        let mesh = sphere(1.5, 256);
        let (lo, hi) = mesh.bounds().unwrap();
        assert!((hi - Vec3::splat(1.5)).abs().max_element() < 1e-4);
        assert!((lo + Vec3::splat(1.5)).abs().max_element() < 1e-4);
        let exact = 4.0 * PI * 1.5 * 1.5;
        assert!((area(&mesh) - exact).abs() / exact < 1e-3);
    }

    #[test]
    fn sphere_degenerate_parameters() {
        assert_eq!(
            sphere(1.0, 0).triangle_count(),
            sphere(1.0, 3).triangle_count()
        );
        // Three segments, two rings: two fans of three triangles.
        assert_eq!(sphere(1.0, 0).triangle_count(), 6);
        let inverted = sphere(-1.0, 8);
        assert_winding_matches_normals(&inverted);
        assert_outward(&inverted, |_| Vec3::ZERO);
        let point = sphere(0.0, 8);
        assert!(point.validate().is_ok());
        assert!(point
            .normals
            .iter()
            .all(|n| (n.length() - 1.0).abs() < 1e-5));
    }
}
