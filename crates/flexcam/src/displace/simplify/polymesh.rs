//! A polygon mesh of arbitrary n-gons with per-vertex attributes, and its polygon normals.

use glam::{Vec2, Vec3};

use crate::scene::Mesh;

/// A polygon mesh: vertices with a position and optional normal, texture coordinate and colour
/// (each attribute list is empty or as long as `positions`), and faces as lists of at least
/// three vertex indices, counter-clockwise seen from outside.
///
/// Nothing here is checked on construction: [`super::HalfEdgeMesh::build`] checks that the
/// mesh is a manifold the simplifier can work on and names the offending element if not.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PolyMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals, one per position, or empty.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position, or empty.
    pub uvs: Vec<Vec2>,
    /// Vertex colours, one per position, or empty.
    pub colors: Vec<Vec3>,
    /// Each face's vertex indices, counter-clockwise seen from outside.
    pub faces: Vec<Vec<u32>>,
}

impl PolyMesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// Number of triangles a fan triangulation of every face gives.
    pub fn triangle_count(&self) -> usize {
        self.faces.iter().map(|f| f.len().saturating_sub(2)).sum()
    }

    /// The polygon mesh of a triangle mesh: the same vertices and attributes, one face per
    /// triangle.
    pub fn from_triangles(mesh: &Mesh) -> PolyMesh {
        PolyMesh {
            positions: mesh.positions.clone(),
            normals: mesh.normals.clone(),
            uvs: mesh.uvs.clone(),
            colors: mesh.colors.clone(),
            faces: mesh.triangles.iter().map(|t| t.to_vec()).collect(),
        }
    }

    /// The triangle mesh of this mesh, each face split as a fan from its first vertex (exact
    /// for triangles, and for the convex faces edge collapses leave of convex input).
    pub fn to_triangles(&self) -> Mesh {
        let mut triangles = Vec::with_capacity(self.triangle_count());
        for face in &self.faces {
            for i in 1..face.len().saturating_sub(1) {
                triangles.push([face[0], face[i], face[i + 1]]);
            }
        }
        Mesh {
            positions: self.positions.clone(),
            normals: self.normals.clone(),
            uvs: self.uvs.clone(),
            colors: self.colors.clone(),
            triangles,
        }
    }
}

/// A closed torus about the z axis (tube radius `minor` around a circle of radius `major`)
/// of `m` x `n` quads, or twice as many triangles, with outward unit normals. Unlike
/// [`crate::scene::shapes::torus`], whose texture seams are open, it is welded: a surface of
/// genus one without boundary, as simplification tests and benches need.
pub fn closed_torus(major: f32, minor: f32, m: u32, n: u32, triangles: bool) -> PolyMesh {
    let mut mesh = PolyMesh::default();
    for i in 0..m {
        for j in 0..n {
            let (u, v) = (
                i as f32 / m as f32 * std::f32::consts::TAU,
                j as f32 / n as f32 * std::f32::consts::TAU,
            );
            let normal = Vec3::new(u.cos() * v.cos(), u.sin() * v.cos(), v.sin());
            mesh.positions
                .push(Vec3::new(u.cos(), u.sin(), 0.0) * major + normal * minor);
            mesh.normals.push(normal);
        }
    }
    let at = |i: u32, j: u32| (i % m) * n + j % n;
    for i in 0..m {
        for j in 0..n {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            push_cell(&mut mesh.faces, q, triangles);
        }
    }
    mesh
}

/// Adds the grid cell `q` (corners counter-clockwise) as one quad, or as two triangles split
/// along its diagonal from `q[0]`.
pub(super) fn push_cell(faces: &mut Vec<Vec<u32>>, q: [u32; 4], triangles: bool) {
    if triangles {
        faces.push(vec![q[0], q[1], q[2]]);
        faces.push(vec![q[0], q[2], q[3]]);
    } else {
        faces.push(q.to_vec());
    }
}

/// Newell's normal of the polygon with vertices `face` at positions `position(v)`: twice its
/// area times its unit normal for a planar polygon, convex or not; the least-squares plane
/// normal otherwise. For a triangle it is the cross product of two edges, as in the
/// dissertation's polygon normal (Ramsey et al.); unlike the sum of corner cross products it
/// stays right for non-convex n-gons. Corners are taken relative to the first one, so that a
/// polygon far from the origin loses no precision.
pub fn polygon_normal(face: &[u32], position: impl Fn(u32) -> Vec3) -> Vec3 {
    let origin = position(face[0]);
    let mut normal = Vec3::ZERO;
    let mut previous = Vec3::ZERO;
    for &v in &face[1..] {
        let p = position(v) - origin;
        normal += previous.cross(p);
        previous = p;
    }
    normal
}
