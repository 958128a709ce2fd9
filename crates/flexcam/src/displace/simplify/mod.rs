//! Simplification of polygon meshes of arbitrary n-gons by edge collapses, with the vertex
//! splits that rebuild the input exactly (Ramsey et al.'s method, as chapter 6 of Ramsey 2005
//! describes it).
//!
//! - [`PolyMesh`]: vertices with optional normals, texture coordinates and colours, faces as
//!   vertex lists of any length.
//! - [`HalfEdgeMesh::build`]: the half-edge structure, and the check that refuses what the
//!   simplifier does not support (non-manifold edges and vertices, inconsistent orientation,
//!   degenerate faces), naming the element ([`Defect`]).
//! - [`simplify`]: random candidate edges, the normal-deviation cost with a threshold, sweeps
//!   of independent collapses, half- or full-edge collapses ([`CollapseKind`]); the result
//!   ([`Simplified`]) holds the coarse mesh and the [`VertexSplit`]s, and
//!   [`Simplified::refine`] replays them.
//! - [`collapse_in_order`]: half-edge collapses cheapest first by a cost the caller gives
//!   ([`HalfEdgeCost`]), from a priority queue: the progressive mesh's order
//!   ([`crate::displace::progressive`]).
//! - [`coarse_triangles`]: a coarse triangle mesh of a scene mesh, for renderers that want
//!   few triangles standing for a detailed surface (a camera mesh over a reflector, say).
//!
//! Full-edge collapses are the default ([`SimplifyOptions::to_faces`], `flexcam simplify`):
//! the dissertation finds they look better, each end moving half as far. Half-edge collapses
//! serve where vertices must stay on the original surface: [`coarse_triangles`].
//!
//! Module layers, bottom up: `polymesh`, `fan`, `halfedge`, `split`, `collapse`, `sweep` and
//! `queue`.

mod collapse;
mod fan;
mod halfedge;
mod obj;
mod polymesh;
mod queue;
mod split;
mod sweep;

pub use collapse::CollapseKind;
pub use halfedge::{Defect, HalfEdge, HalfEdgeMesh, NONE};
pub use obj::{write_obj, ObjPolygons};
pub use polymesh::{closed_torus, polygon_normal, PolyMesh};
pub use queue::{collapse_in_order, HalfEdgeCost, Ordered};
pub use split::{Simplified, SplitVertex, VertexSplit};
pub use sweep::{simplify, SimplifyOptions};

use crate::error::Result;
use crate::scene::Mesh;

/// A coarse version of the triangle mesh `mesh` with at most `triangles` triangles where
/// its topology allows (a closed surface keeps at least a tetrahedron's four, and every
/// boundary loop at least one triangle).
///
/// Half-edge collapses, so every coarse vertex is a vertex of `mesh`, on its surface; no
/// normal-deviation limit other than refusing fold-overs, so the count is reached on curved
/// surfaces too; each collapse is the flattest of 1 % of the edges drawn with `seed`.
/// Attributes (normals, texture coordinates, colours) come along with the vertices. Errors:
/// `mesh` is not an oriented manifold (the message names the triangle, edge or vertex).
pub fn coarse_triangles(mesh: &Mesh, triangles: usize, seed: u64) -> Result<Mesh> {
    let options = SimplifyOptions {
        threshold_degrees: 180.0,
        collapse: CollapseKind::Half,
        seed,
        ..SimplifyOptions::to_faces(triangles)
    };
    Ok(simplify(&PolyMesh::from_triangles(mesh), &options)?
        .coarse
        .to_triangles())
}

#[cfg(test)]
mod tests;
