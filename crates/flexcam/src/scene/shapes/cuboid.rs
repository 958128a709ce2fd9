//! An axis-aligned box with hard edges.

use glam::{Vec2, Vec3};

use super::grid::{push_grid, CollapsedRows, Vertex};
use crate::scene::Mesh;

/// The six faces as (outward normal, right, up): `right x up = normal`, so each face is
/// counter-clockwise from outside, and its uv runs right and up as seen from outside.
const FACES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Z, Vec3::Y),
    (Vec3::NEG_X, Vec3::Z, Vec3::Y),
    (Vec3::Y, Vec3::X, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::X, Vec3::Z),
    (Vec3::Z, Vec3::X, Vec3::Y),
    (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
];

/// An axis-aligned box with edge lengths `size`, centred on the origin: 12 triangles on 24
/// vertices, so that each face has its own normal (hard edges) and its own `[0,1]^2` uvs.
///
/// Degenerate input: negative sizes are taken by absolute value (the box stays outward
/// facing); a zero size gives zero-area faces.
pub fn cuboid(size: Vec3) -> Mesh {
    let half = 0.5 * size.abs();
    let mut mesh = Mesh::default();
    for (normal, right, up) in FACES {
        push_grid(&mut mesh, 1, 1, CollapsedRows::default(), |s, t| Vertex {
            position: half * (normal + (2.0 * s - 1.0) * right + (2.0 * t - 1.0) * up),
            normal,
            uv: Vec2::new(s, t),
        });
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn cuboid_is_a_closed_box() {
        let size = Vec3::new(1.0, 2.0, 3.0);
        let mesh = cuboid(size);
        assert_eq!(mesh.triangle_count(), 12);
        assert_eq!(mesh.positions.len(), 24);
        assert_well_formed(&mesh);
        assert_winding_matches_normals(&mesh);
        assert_outward(&mesh, |_| Vec3::ZERO);
        assert!(is_closed(&mesh));
        assert!((area(&mesh) - 2.0 * (2.0 + 6.0 + 3.0)).abs() < 1e-5);
        assert_eq!(mesh.bounds(), Some((-0.5 * size, 0.5 * size)));
    }

    #[test]
    fn cuboid_faces_have_hard_normals() {
        let mesh = cuboid(Vec3::ONE);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            // The normal is the axis along which the vertex lies on the face plane.
            assert_eq!(p.dot(*n), 0.5);
        }
    }

    #[test]
    fn cuboid_negative_size_stays_outward() {
        let mesh = cuboid(Vec3::new(-1.0, 1.0, 1.0));
        assert_winding_matches_normals(&mesh);
        assert_outward(&mesh, |_| Vec3::ZERO);
        assert!(cuboid(Vec3::ZERO).validate().is_ok());
    }
}
