//! The micro-triangles of a displaced mesh written out as an ordinary mesh: what ray tracing
//! the displaced base triangles avoids storing, for comparisons (`flexcam bench displaced`)
//! and for renderers that draw triangles.
//!
//! Each base triangle gives its own `(2^L + 1)(2^L + 2) / 2` micro-vertices and `4^L`
//! micro-triangles ([`MicroGrid`], so the same values bit for bit before the rounding to the
//! mesh's f32), with texture coordinates and no vertex normals (face normals: the
//! micro-vertices' own normals are the undisplaced surface's). Vertices on shared edges are
//! repeated per base triangle, at identical positions.

use glam::DVec3;

use super::micro::{BaseVertex, Displacement, MicroGrid};
use crate::scene::Mesh;

/// The base vertices of triangle `triangle` of `mesh` (which has normals and uvs), in f64; a
/// zero vertex normal (the mesh's "use the face normal") is the face normal.
pub fn base_corners(mesh: &Mesh, triangle: usize) -> [BaseVertex; 3] {
    let indices = mesh.triangles[triangle].map(|i| i as usize);
    let [p0, p1, p2] = indices.map(|i| mesh.positions[i].as_dvec3());
    let face = (p1 - p0).cross(p2 - p0).normalize_or_zero();
    indices.map(|i| {
        let normal = mesh.normals[i].as_dvec3();
        BaseVertex {
            position: mesh.positions[i].as_dvec3(),
            normal: if normal == DVec3::ZERO { face } else { normal },
            uv: mesh.uvs[i].as_dvec2(),
        }
    })
}

/// Every micro-triangle of `mesh` (with normals and uvs) displaced by `displacement`, as a
/// mesh (module docs): `4^L` times the base triangles.
pub fn tessellate(mesh: &Mesh, displacement: &Displacement) -> Mesh {
    let n = 1u32 << displacement.level();
    let per_triangle = ((n + 1) * (n + 2) / 2) as usize;
    let mut out = Mesh::default();
    let count = mesh.triangles.len();
    out.positions.reserve(count * per_triangle);
    out.uvs.reserve(count * per_triangle);
    out.triangles.reserve(count << (2 * displacement.level()));
    for triangle in 0..count {
        let grid = MicroGrid::new(&base_corners(mesh, triangle), displacement);
        let first = out.positions.len() as u32;
        // Grid point (i, j) is vertex `first + offset(n, i) + j`.
        let index = |[i, j]: [u32; 2]| first + offset(n, i) + j;
        for i in 0..=n {
            for j in 0..=n - i {
                out.positions.push(grid.displaced([i, j]).as_vec3());
                out.uvs.push(grid.vertex([i, j]).uv.as_vec2());
            }
        }
        out.triangles
            .extend(grid.triangles().map(|t| t.vertices().map(index)));
    }
    out
}

/// The number of grid points in rows `0..i` of a grid of side `n` (row `k` has `n + 1 - k`).
fn offset(n: u32, i: u32) -> u32 {
    i * (n + 1) - i * i.saturating_sub(1) / 2
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::*;
    use crate::displace::{HeightField, Procedural, Wave};

    #[test]
    fn tessellation_holds_the_micro_grid_of_every_base_triangle() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.2)],
            normals: vec![Vec3::Z; 4],
            uvs: vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE],
            colors: vec![],
            triangles: vec![[0, 1, 2], [1, 3, 2]],
        };
        let wave = Wave {
            amplitude: 1.0,
            frequency: [2, 1],
            phase: 0.3,
        };
        let height = HeightField::Procedural(Procedural::waves(vec![wave]).unwrap());
        for level in 0..4 {
            let d = Displacement::new(height.clone(), 0.1, 1.0, level).unwrap();
            let out = tessellate(&mesh, &d);
            let n = 1usize << level;
            assert_eq!(out.triangles.len(), 2 * n * n);
            assert_eq!(out.positions.len(), 2 * (n + 1) * (n + 2) / 2);
            out.validate().unwrap();
            for (k, t) in out.triangles.iter().enumerate() {
                let base = k / (n * n);
                let grid = MicroGrid::new(&base_corners(&mesh, base), &d);
                let micro = grid.triangles().nth(k % (n * n)).unwrap();
                let want = grid.positions(micro).map(|p| p.as_vec3());
                assert_eq!(t.map(|i| out.positions[i as usize]), want);
            }
        }
    }
}
