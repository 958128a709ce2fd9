//! The scene's triangles in one flat f64 list, numbered like the ray caster's BVH (objects in
//! order, each object's triangles in order), with the owner of each.

use std::collections::HashMap;

use glam::DVec3;

use crate::scene::Scene;

/// Which object triangle a scene triangle is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Owner {
    /// Index in `scene.objects`.
    pub object: u32,
    /// The object's id (what the id buffer holds).
    pub id: u32,
    /// Index of the triangle in the object's mesh.
    pub triangle: u32,
}

/// Every scene vertex (f64, world space) and triangle.
#[derive(Debug, Clone, Default)]
pub struct SceneGeometry {
    pub vertices: Vec<DVec3>,
    /// Indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// `owners[k]` is where `triangles[k]` comes from.
    pub owners: Vec<Owner>,
    /// The id of each object, by index in `scene.objects`.
    pub object_ids: Vec<u32>,
    /// Per triangle, the edges `<V1V2, V1V3, V2V3>` (bits 0, 1, 2) that another triangle
    /// shares (same end positions, any object): the surface continues across them.
    pub shared_edges: Vec<u8>,
    /// Per triangle and edge `<V1V2, V1V3, V2V3>`, a triangle across it ([`NO_NEIGHBOUR`]
    /// where none shares the edge; where several do, the first in triangle order).
    pub neighbours: Vec<[u32; 3]>,
}

/// The entry of [`SceneGeometry::neighbours`] for an edge no other triangle shares.
pub const NO_NEIGHBOUR: u32 = u32::MAX;

/// The edges `<V1V2, V1V3, V2V3>` as vertex pairs.
const EDGES: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

/// An edge by its end positions, order-independent.
fn edge_key(a: DVec3, b: DVec3) -> [u64; 6] {
    let bits = |p: DVec3| p.to_array().map(f64::to_bits);
    let (a, b) = (bits(a), bits(b));
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}

impl SceneGeometry {
    pub fn new(scene: &Scene) -> SceneGeometry {
        let mut out = SceneGeometry::default();
        for (index, object) in scene.objects.iter().enumerate() {
            out.object_ids.push(object.id);
            let first = out.vertices.len() as u32;
            out.vertices
                .extend(object.mesh.positions.iter().map(|p| p.as_dvec3()));
            for (k, triangle) in object.mesh.triangles.iter().enumerate() {
                out.triangles.push(triangle.map(|i| first + i));
                out.owners.push(Owner {
                    object: index as u32,
                    id: object.id,
                    triangle: k as u32,
                });
            }
        }
        // The first two triangles using each edge.
        let mut users: HashMap<[u64; 6], [u32; 2]> = HashMap::new();
        for k in 0..out.triangles.len() {
            let c = out.corners(k);
            for (i, j) in EDGES {
                let entry = users
                    .entry(edge_key(c[i], c[j]))
                    .or_insert([NO_NEIGHBOUR; 2]);
                if entry[0] == NO_NEIGHBOUR {
                    entry[0] = k as u32;
                } else if entry[1] == NO_NEIGHBOUR {
                    entry[1] = k as u32;
                }
            }
        }
        out.neighbours = (0..out.triangles.len())
            .map(|k| {
                let c = out.corners(k);
                EDGES.map(|(i, j)| {
                    let [a, b] = users[&edge_key(c[i], c[j])];
                    if a == k as u32 {
                        b
                    } else {
                        a
                    }
                })
            })
            .collect();
        out.shared_edges = out
            .neighbours
            .iter()
            .map(|across| {
                (0..3).fold(0, |mask, bit| {
                    mask | (u8::from(across[bit] != NO_NEIGHBOUR) << bit)
                })
            })
            .collect();
        out
    }

    /// The vertices of triangle `k`.
    pub fn corners(&self, k: usize) -> [DVec3; 3] {
        self.triangles[k].map(|i| self.vertices[i as usize])
    }
}
