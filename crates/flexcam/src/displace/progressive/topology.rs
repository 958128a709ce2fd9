//! The connectivity of a triangle mesh that chart building and the progressive mesh read:
//! the faces of each edge and of each vertex, face normals and areas, in f64.

use std::collections::HashMap;

use glam::DVec3;

use crate::scene::Mesh;

/// No face (the outside of a boundary edge).
pub const NONE: u32 = u32::MAX;

/// A triangle mesh's connectivity (see the module documentation).
#[derive(Debug, Clone)]
pub struct Topology {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Vertex indices of each face.
    pub triangles: Vec<[u32; 3]>,
    /// The faces of each edge (smaller vertex first): the face where it runs from the
    /// smaller vertex to the larger, and the other ([`NONE`] on the boundary).
    pub edge_faces: HashMap<(u32, u32), [u32; 2]>,
    /// The faces through each vertex.
    pub vertex_faces: Vec<Vec<u32>>,
    /// Unit normal of each face (zero for a degenerate one).
    pub normals: Vec<DVec3>,
    /// Area of each face.
    pub areas: Vec<f64>,
    /// Whether each vertex lies on the mesh's boundary.
    boundary: Vec<bool>,
}

impl Topology {
    /// The connectivity of `mesh` (assumed an oriented manifold: the simplifier checks).
    pub fn new(mesh: &Mesh) -> Topology {
        let positions: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        let mut edge_faces: HashMap<(u32, u32), [u32; 2]> = HashMap::new();
        let mut vertex_faces = vec![Vec::new(); positions.len()];
        let mut normals = Vec::with_capacity(mesh.triangles.len());
        let mut areas = Vec::with_capacity(mesh.triangles.len());
        for (f, t) in mesh.triangles.iter().enumerate() {
            let f = f as u32;
            for k in 0..3 {
                let (v, w) = (t[k], t[(k + 1) % 3]);
                let slot = edge_faces.entry(key(v, w)).or_insert([NONE, NONE]);
                slot[usize::from(v > w)] = f;
                vertex_faces[v as usize].push(f);
            }
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let cross = (b - a).cross(c - a);
            normals.push(cross.normalize_or_zero());
            areas.push(cross.length() * 0.5);
        }
        let mut boundary = vec![false; positions.len()];
        for (&(v, w), faces) in &edge_faces {
            if faces.contains(&NONE) {
                boundary[v as usize] = true;
                boundary[w as usize] = true;
            }
        }
        Topology {
            positions,
            triangles: mesh.triangles.clone(),
            edge_faces,
            vertex_faces,
            normals,
            areas,
            boundary,
        }
    }

    /// The two faces of edge `v`-`w` (either may be [`NONE`]).
    pub fn faces_of(&self, v: u32, w: u32) -> [u32; 2] {
        self.edge_faces
            .get(&key(v, w))
            .copied()
            .unwrap_or([NONE, NONE])
    }

    /// The face across edge `v`-`w` from face `f`.
    pub fn across(&self, f: u32, v: u32, w: u32) -> u32 {
        let [x, y] = self.faces_of(v, w);
        if x == f {
            y
        } else {
            x
        }
    }

    /// The edges of face `f`, as vertex pairs in its winding.
    pub fn edges(&self, f: u32) -> [(u32, u32); 3] {
        let t = self.triangles[f as usize];
        [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
    }

    /// Whether `v` lies on the mesh's boundary.
    pub fn on_boundary(&self, v: u32) -> bool {
        self.boundary[v as usize]
    }

    /// Length of edge `v`-`w`.
    pub fn length(&self, v: u32, w: u32) -> f64 {
        (self.positions[v as usize] - self.positions[w as usize]).length()
    }
}

/// The key of edge `v`-`w`: smaller vertex first.
pub fn key(v: u32, w: u32) -> (u32, u32) {
    (v.min(w), v.max(w))
}
