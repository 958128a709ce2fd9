//! Vertex splits, the records that undo edge collapses, and rebuilding finer meshes from a
//! coarse mesh and its splits.
//!
//! The dissertation's split record (Ramsey et al.) holds seven fields: the two ends' positions,
//! the vertex the edge became, the polygons around each end, the vertex completing each
//! removed triangle, and the context of the edge in each polygon that lost a corner. Here the
//! record keeps each changed face's whole vertex list from before the collapse (by face id):
//! the polygons around each end are the listed faces through it, a removed triangle is a
//! listed face absent from the coarser mesh, and the context is the list itself. This gives
//! the exact faces back, corner order and starting corner included.

use glam::{Vec2, Vec3};

use super::PolyMesh;

/// A vertex as a split restores it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitVertex {
    /// The vertex's stable id.
    pub id: u32,
    /// Its position.
    pub position: Vec3,
    /// Zero where the mesh has no such attribute.
    pub normal: Vec3,
    /// Its texture coordinates (zero where the mesh has none).
    pub uv: Vec2,
    /// Its colour (zero where the mesh has none).
    pub color: Vec3,
}

/// The inverse of one edge collapse, in the ids of the simplification (see
/// [`Simplified`]).
#[derive(Debug, Clone, PartialEq)]
pub struct VertexSplit {
    /// The vertex the edge collapsed into: one of the ends (a half-edge collapse) or a
    /// vertex the collapse created (a full-edge one), which the split removes.
    pub into: u32,
    /// The ends of the edge, restored.
    pub ends: [SplitVertex; 2],
    /// Every face the collapse changed or removed: its id and vertex list before it.
    pub faces: Vec<(u32, Vec<u32>)>,
}

/// A simplified mesh and the splits that refine it back to the input.
///
/// Vertices and faces have stable ids through the simplification: the input's vertex and
/// face indices, and after them, the vertices full-edge collapses created. `coarse` is
/// compacted (its vertices are the living ones in id order, its faces the remaining ones in
/// id order); `vertex_ids` and `face_ids` give each one's stable id. `splits` are in the
/// order of the collapses: refining applies them from the last.
#[derive(Debug, Clone, PartialEq)]
pub struct Simplified {
    /// The simplified mesh, compacted.
    pub coarse: PolyMesh,
    /// The splits, in the order of the collapses.
    pub splits: Vec<VertexSplit>,
    /// The stable id of each vertex of `coarse`.
    pub vertex_ids: Vec<u32>,
    /// The stable id of each face of `coarse`.
    pub face_ids: Vec<u32>,
    /// How many stable vertex ids there are (input vertices and created ones).
    pub vertex_id_count: usize,
    /// How many stable face ids there are (the input's faces).
    pub face_id_count: usize,
    /// Sweeps over the mesh the simplification took.
    pub sweeps: usize,
}

impl Simplified {
    /// The mesh after undoing the last `count` collapses (all of them at most): `refine(0)`
    /// is `coarse`, `refine(splits.len())` the input, exactly.
    pub fn refine(&self, count: usize) -> PolyMesh {
        self.refine_with_ids(count).0
    }

    /// [`Simplified::refine`] with the stable ids of its vertices and faces (as
    /// [`Simplified::vertex_ids`] and [`Simplified::face_ids`] give those of `coarse`).
    pub fn refine_with_ids(&self, count: usize) -> (PolyMesh, Vec<u32>, Vec<u32>) {
        let count = count.min(self.splits.len());
        let n = self.vertex_id_count;
        let c = &self.coarse;
        let mut mesh = Stable {
            positions: vec![Vec3::ZERO; n],
            normals: vec![Vec3::ZERO; if c.normals.is_empty() { 0 } else { n }],
            uvs: vec![Vec2::ZERO; if c.uvs.is_empty() { 0 } else { n }],
            colors: vec![Vec3::ZERO; if c.colors.is_empty() { 0 } else { n }],
            alive: vec![false; n],
            faces: vec![Vec::new(); self.face_id_count],
        };
        for (i, &id) in self.vertex_ids.iter().enumerate() {
            mesh.restore(&SplitVertex {
                id,
                position: c.positions[i],
                normal: c.normals.get(i).copied().unwrap_or(Vec3::ZERO),
                uv: c.uvs.get(i).copied().unwrap_or(Vec2::ZERO),
                color: c.colors.get(i).copied().unwrap_or(Vec3::ZERO),
            });
        }
        for (face, &id) in c.faces.iter().zip(&self.face_ids) {
            mesh.faces[id as usize] = face.iter().map(|&v| self.vertex_ids[v as usize]).collect();
        }
        for split in self.splits.iter().rev().take(count) {
            mesh.alive[split.into as usize] = false;
            for end in &split.ends {
                mesh.restore(end);
            }
            for (f, face) in &split.faces {
                mesh.faces[*f as usize] = face.clone();
            }
        }
        mesh.compact_with_ids()
    }
}

/// A mesh in stable ids, with dead vertices and empty (removed) faces.
#[derive(Debug, Clone)]
pub(super) struct Stable {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub colors: Vec<Vec3>,
    pub alive: Vec<bool>,
    pub faces: Vec<Vec<u32>>,
}

impl Stable {
    pub fn restore(&mut self, v: &SplitVertex) {
        let i = v.id as usize;
        self.alive[i] = true;
        self.positions[i] = v.position;
        if !self.normals.is_empty() {
            self.normals[i] = v.normal;
        }
        if !self.uvs.is_empty() {
            self.uvs[i] = v.uv;
        }
        if !self.colors.is_empty() {
            self.colors[i] = v.color;
        }
    }

    /// The living vertices and remaining faces, renumbered in id order, with the stable ids
    /// of each.
    pub fn compact_with_ids(&self) -> (PolyMesh, Vec<u32>, Vec<u32>) {
        let vertex_ids: Vec<u32> = (0..self.alive.len() as u32)
            .filter(|&v| self.alive[v as usize])
            .collect();
        let mut index = vec![u32::MAX; self.alive.len()];
        for (i, &v) in vertex_ids.iter().enumerate() {
            index[v as usize] = i as u32;
        }
        let face_ids: Vec<u32> = (0..self.faces.len() as u32)
            .filter(|&f| !self.faces[f as usize].is_empty())
            .collect();
        let pick3 = |list: &[Vec3]| -> Vec<Vec3> {
            if list.is_empty() {
                Vec::new()
            } else {
                vertex_ids.iter().map(|&v| list[v as usize]).collect()
            }
        };
        let mesh = PolyMesh {
            positions: pick3(&self.positions),
            normals: pick3(&self.normals),
            uvs: if self.uvs.is_empty() {
                Vec::new()
            } else {
                vertex_ids.iter().map(|&v| self.uvs[v as usize]).collect()
            },
            colors: pick3(&self.colors),
            faces: face_ids
                .iter()
                .map(|&f| {
                    self.faces[f as usize]
                        .iter()
                        .map(|&v| index[v as usize])
                        .collect()
                })
                .collect(),
        };
        (mesh, vertex_ids, face_ids)
    }
}
