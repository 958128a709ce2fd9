//! A rectangle in the xz plane.

use glam::{Vec2, Vec3};

use super::grid::{push_grid, CollapsedRows, Vertex};
use crate::scene::Mesh;

/// A `width` x `depth` rectangle in the xz plane at y = 0, centred on the origin, normal +y,
/// split into `tessellation` x `tessellation` quads.
///
/// Degenerate input: `tessellation` 0 gives one quad; negative sizes are taken by absolute
/// value (the plane keeps facing +y); a zero size gives zero-area triangles.
/// Texture coordinates cover `[0,1]^2`, with (0,0) at (-x, +z): seen from above with -z up,
/// the bottom-left corner.
pub fn plane(width: f32, depth: f32, tessellation: u32) -> Mesh {
    let (width, depth) = (width.abs(), depth.abs());
    let mut mesh = Mesh::default();
    // s runs along +x and t along -z, so that d/ds x d/dt = +y.
    push_grid(
        &mut mesh,
        tessellation,
        tessellation,
        CollapsedRows::default(),
        |s, t| Vertex {
            position: Vec3::new((s - 0.5) * width, 0.0, (0.5 - t) * depth),
            normal: Vec3::Y,
            uv: Vec2::new(s, t),
        },
    );
    mesh
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn plane_counts_bounds_and_area() {
        for n in [1, 2, 7] {
            let mesh = plane(4.0, 2.0, n);
            assert_eq!(mesh.triangle_count(), 2 * (n * n) as usize);
            assert_eq!(mesh.positions.len(), ((n + 1) * (n + 1)) as usize);
            assert_well_formed(&mesh);
            assert_winding_matches_normals(&mesh);
            assert!((area(&mesh) - 8.0).abs() < 1e-4);
            assert_eq!(
                mesh.bounds(),
                Some((Vec3::new(-2.0, 0.0, -1.0), Vec3::new(2.0, 0.0, 1.0)))
            );
            assert!(!is_closed(&mesh));
        }
    }

    #[test]
    fn plane_uv_corners() {
        let mesh = plane(2.0, 2.0, 1);
        let at = |p: Vec3| {
            mesh.positions
                .iter()
                .position(|&q| q == p)
                .map(|k| mesh.uvs[k])
        };
        assert_eq!(at(Vec3::new(-1.0, 0.0, 1.0)), Some(Vec2::ZERO));
        assert_eq!(at(Vec3::new(1.0, 0.0, -1.0)), Some(Vec2::ONE));
    }

    #[test]
    fn plane_degenerate_parameters() {
        assert_eq!(plane(1.0, 1.0, 0).triangle_count(), 2);
        let mesh = plane(-3.0, 1.0, 2);
        assert_winding_matches_normals(&mesh);
        assert!((area(&mesh) - 3.0).abs() < 1e-5);
        let flat = plane(0.0, 0.0, 2);
        assert!(flat.validate().is_ok());
        assert!(flat.normals.iter().all(|n| *n == Vec3::Y));
    }
}
