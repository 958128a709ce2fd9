//! A borrowed view of a triangle mesh's geometry: what projection builders need of a mesh
//! (positions, vertex normals, triangles) without the scene's materials, texture coordinates
//! or colours, so that projections can be built from a scene's meshes without depending on
//! the scene layer.

use glam::Vec3;

/// Positions, optional vertex normals and triangles of a mesh, borrowed.
///
/// Invariants (those of a validated scene mesh): every index of `triangles` is below
/// `positions.len()`; `normals` is empty or as long as `positions`; a zero normal means "no
/// normal here".
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshView<'a> {
    /// Vertex positions.
    pub positions: &'a [Vec3],
    /// Vertex normals, one per position, or empty.
    pub normals: &'a [Vec3],
    /// Vertex indices of each triangle.
    pub triangles: &'a [[u32; 3]],
}
