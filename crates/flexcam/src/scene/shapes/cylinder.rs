//! A capped cylinder.

use glam::{Vec2, Vec3};

use super::grid::{push_grid, turn, CollapsedRows, Vertex};
use crate::scene::Mesh;

/// Fewest segments around the cylinder.
const MIN_SEGMENTS: u32 = 3;

/// A capped cylinder about the y axis, from y = -height/2 to y = height/2, with
/// `tessellation` segments around (at least 3): one row of side quads and a triangle fan
/// per cap, `4 * segments` triangles.
///
/// Sides and caps have separate vertices (a hard edge). The side's uv runs around from +x
/// (u) and up (v); each cap's uv is its planar projection onto `[0,1]^2`, as seen from
/// outside with -z (top) or +z (bottom) up.
///
/// Degenerate input: tessellation below 3 is raised to it; negative sizes are taken by
/// absolute value; zero sizes give zero-area triangles with valid unit normals.
pub fn cylinder(radius: f32, height: f32, tessellation: u32) -> Mesh {
    let (radius, half) = (radius.abs(), 0.5 * height.abs());
    let segments = tessellation.max(MIN_SEGMENTS);
    let mut mesh = Mesh::default();
    // Longitude runs from +x towards -z, so that d/ds x d/dt is outward on the side.
    push_grid(&mut mesh, segments, 1, CollapsedRows::default(), |s, t| {
        let (c, s_) = turn(s);
        let normal = Vec3::new(c, 0.0, -s_);
        Vertex {
            position: radius * normal + Vec3::new(0.0, (2.0 * t - 1.0) * half, 0.0),
            normal,
            uv: Vec2::new(s, t),
        }
    });
    // Top cap, seen from +y: rim from +x towards -z, then the centre.
    push_cap(&mut mesh, segments, false, |s, r| {
        let (c, s_) = turn(s);
        Vertex {
            position: Vec3::new(radius * r * c, half, -radius * r * s_),
            normal: Vec3::Y,
            uv: Vec2::new(0.5 + 0.5 * r * c, 0.5 + 0.5 * r * s_),
        }
    });
    // Bottom cap, seen from -y: the centre, then the rim.
    push_cap(&mut mesh, segments, true, |s, r| {
        let (c, s_) = turn(s);
        Vertex {
            position: Vec3::new(radius * r * c, -half, -radius * r * s_),
            normal: Vec3::NEG_Y,
            uv: Vec2::new(0.5 + 0.5 * r * c, 0.5 - 0.5 * r * s_),
        }
    });
    mesh
}

/// Appends a cap: `segments + 1` rim vertices `vertex(s, 1)` (`s = i / segments`, the first
/// and last coinciding) and one centre vertex `vertex(0, 0)`, joined by a fan of `segments`
/// triangles around the centre. `centre_first`: the centre is emitted before the rim and the
/// fan turns the other way (the bottom cap, whose outside is the other side).
///
/// One shared centre, not one per segment as [`push_grid`]'s collapsed rows keep for their
/// uvs (every centre sample here has the same position, normal and uv): with one per segment,
/// neighbouring fan triangles would share only a rim vertex, the cap would be a ring of
/// triangles touching at points, and mesh simplification (a reflector's camera mesh, LOD)
/// would refuse it as non-manifold.
fn push_cap(
    mesh: &mut Mesh,
    segments: u32,
    centre_first: bool,
    vertex: impl Fn(f32, f32) -> Vertex,
) {
    let mut push = |v: Vertex| {
        mesh.positions.push(v.position);
        mesh.normals.push(v.normal);
        mesh.uvs.push(v.uv);
        mesh.positions.len() as u32 - 1
    };
    let centre = centre_first.then(|| push(vertex(0.0, 0.0)));
    let rim: Vec<u32> = (0..=segments)
        .map(|i| push(vertex(i as f32 / segments as f32, 1.0)))
        .collect();
    let centre = centre.unwrap_or_else(|| push(vertex(0.0, 0.0)));
    for pair in rim.windows(2) {
        mesh.triangles.push(if centre_first {
            [centre, pair[1], pair[0]]
        } else {
            [pair[0], pair[1], centre]
        });
    }
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::super::test_support::*;
    use super::*;

    #[test]
    fn cylinder_counts_and_shape() {
        for n in [3, 5, 32] {
            let mesh = cylinder(0.5, 2.0, n);
            assert_eq!(mesh.triangle_count(), 4 * n as usize);
            assert_well_formed(&mesh);
            assert_winding_matches_normals(&mesh);
            assert_outward(&mesh, |_| Vec3::ZERO);
            assert!(is_closed(&mesh), "tessellation {n}");
            let (lo, hi) = mesh.bounds().unwrap();
            assert!((lo.y + 1.0).abs() < 1e-6 && (hi.y - 1.0).abs() < 1e-6);
            assert!((hi.x - 0.5).abs() < 1e-6);
        }
    }

    #[test]
    fn cylinder_area_converges() {
        let mesh = cylinder(0.5, 2.0, 512);
        let exact = 2.0 * PI * 0.5 * 2.0 + 2.0 * PI * 0.25;
        assert!((area(&mesh) - exact).abs() / exact < 1e-4);
    }

    #[test]
    fn cylinder_has_hard_edges() {
        let mesh = cylinder(1.0, 1.0, 8);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            let on_cap = n.y != 0.0;
            assert!(on_cap == (n.x == 0.0 && n.z == 0.0));
            if on_cap {
                assert_eq!(p.y, 0.5 * n.y);
            }
        }
    }

    #[test]
    fn cylinder_degenerate_parameters() {
        assert_eq!(cylinder(1.0, 1.0, 0).triangle_count(), 12);
        let mesh = cylinder(-1.0, -2.0, 6);
        assert_winding_matches_normals(&mesh);
        assert_outward(&mesh, |_| Vec3::ZERO);
        let flat = cylinder(0.0, 0.0, 6);
        assert!(flat.validate().is_ok());
        assert!(flat.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-6));
    }
}
