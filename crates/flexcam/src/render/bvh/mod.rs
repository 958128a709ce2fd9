//! A bounding volume hierarchy over triangles: binned SAH build (parallel over subtrees),
//! 64-byte interior nodes holding both children's boxes for a 4-wide slab test of the pair,
//! and near-first f32 traversal for closest-hit and any-hit queries.
//!
//! This module holds the tree's layout (nodes, child references, the depth bound that sizes
//! the traversal stack) and its accessors; `build` constructs it and `traverse` answers the
//! ray, packet and segment queries.

mod build;
pub(in crate::render) mod curve_triangle;
mod light_buffer;
#[cfg(test)]
mod tests;
mod traverse;
pub(in crate::render) mod triangle;

use glam::{Vec3, Vec4};

pub(in crate::render) use self::light_buffer::LightBuffer;
pub(in crate::render) use self::traverse::{NearSegment, NearSegments4};
use self::triangle::{FastHit, PackedTriangle};
use crate::geometry::Aabb;

/// What a node's child slot, or the root, refers to: interior node `index` when `count == 0`,
/// else a leaf of the `count` triangles stored from `index` on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Child {
    index: u32,
    count: u32,
}

/// An interior node: the boxes of its two children, laid out so that one 4-wide slab test per
/// axis tests both, and what the children are. 64 bytes, one cache line.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct Node {
    /// Per axis `[min of child 0, min of child 1, -max of child 0, -max of child 1]`: with the
    /// upper planes negated, the entry and the negated exit distances of both children come
    /// out of one subtract, one multiply and a running maximum.
    planes: [Vec4; 3],
    children: [Child; 2],
}

impl Node {
    fn new(bounds: [Aabb; 2], children: [Child; 2]) -> Node {
        let [a, b] = bounds;
        let axis = |i: usize| Vec4::new(a.min[i], b.min[i], -a.max[i], -b.max[i]);
        Node {
            planes: [axis(0), axis(1), axis(2)],
            children,
        }
    }

    /// The box `(min, max)` of child `k` (0 or 1).
    #[inline(always)]
    fn child_box(&self, k: usize) -> (Vec3, Vec3) {
        let p = &self.planes;
        let min = Vec3::new(p[0][k], p[1][k], p[2][k]);
        let max = -Vec3::new(p[0][k + 2], p[1][k + 2], p[2][k + 2]);
        (min, max)
    }
}

/// Depth after which the build splits at the object median instead of by SAH. Median splits
/// halve the triangle count, so the tree is at most `SAH_DEPTH + 32` deep, which bounds the
/// traversal stack and the build's recursion.
const SAH_DEPTH: usize = 32;
const STACK_SIZE: usize = SAH_DEPTH + 33;

/// A BVH over a set of triangles, each known by its index in the build input.
#[derive(Debug, Clone)]
pub(in crate::render) struct Bvh {
    /// Interior nodes in depth-first order (a node, its left subtree, its right subtree).
    nodes: Vec<Node>,
    root: Child,
    /// The padded box of everything (empty when nothing is stored).
    root_bounds: Aabb,
    /// The largest coordinate magnitude of `root_bounds` (0 when empty), for
    /// [`Bvh::root_overlaps`].
    root_scale: f64,
    triangles: Vec<PackedTriangle>,
    /// Build-input index of each stored triangle.
    ids: Vec<u32>,
}

impl Default for Bvh {
    fn default() -> Bvh {
        Bvh {
            nodes: Vec::new(),
            root: Child { index: 0, count: 0 },
            root_bounds: Aabb::EMPTY,
            root_scale: 0.0,
            triangles: Vec::new(),
            ids: Vec::new(),
        }
    }
}

/// A closest or any hit: the build-input index of the triangle and where it was hit.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct BvhHit {
    pub id: u32,
    pub hit: FastHit,
}

/// Which stored triangles a query considers. Queries are monomorphised over it: with
/// [`AllTriangles`] the test folds away and the traversal is the unmasked one.
pub(in crate::render) trait Keep {
    /// Whether stored triangle `stored` (see [`Bvh::all_triangles`]) takes part.
    fn keeps(&self, stored: usize) -> bool;

    /// Which children of interior node `node` hold a triangle that takes part: bit 0 for
    /// child 0, bit 1 for child 1. A traversal skips a child whose bit is clear, so a
    /// query over part of the scene does not descend into the subtrees of what it hides.
    fn kept_children(&self, node: usize) -> u8;
}

/// Every triangle of the tree.
pub(in crate::render) struct AllTriangles;

impl Keep for AllTriangles {
    #[inline(always)]
    fn keeps(&self, _: usize) -> bool {
        true
    }

    #[inline(always)]
    fn kept_children(&self, _: usize) -> u8 {
        0b11
    }
}

/// The stored triangles of a chosen subset (one bit each, by stored index): a query over part
/// of the scene (the scene without one object, or that object alone) answered by the whole
/// scene's tree, exactly as a tree of that part alone would answer it up to the order of
/// hits at equal `t`. It also records, per interior node, which children hold a kept
/// triangle ([`Keep::kept_children`]), so that the hidden part's subtrees are not entered:
/// where the hidden object is compact (a mirror sphere), the masked query visits about the
/// nodes a tree of the shown part would.
#[derive(Debug, Clone)]
pub(in crate::render) struct TriangleMask {
    bits: Vec<u64>,
    children: Vec<u8>,
}

impl TriangleMask {
    /// The mask keeping the stored triangles whose build-input index `keeps` accepts.
    pub fn by_id(bvh: &Bvh, keeps: impl Fn(u32) -> bool) -> TriangleMask {
        let mut bits = vec![0u64; bvh.ids.len().div_ceil(64)];
        for (stored, &id) in bvh.ids.iter().enumerate() {
            if keeps(id) {
                bits[stored / 64] |= 1 << (stored % 64);
            }
        }
        let mut mask = TriangleMask {
            bits,
            children: vec![0; bvh.nodes.len()],
        };
        if !bvh.triangles.is_empty() {
            mask.mark_children(bvh, bvh.root);
        }
        mask
    }

    /// Whether subtree `child` holds a kept triangle, recording the answer for every interior
    /// node below it. Recursion depth is the tree's depth, bounded by the traversal stack's
    /// size.
    fn mark_children(&mut self, bvh: &Bvh, child: Child) -> bool {
        if child.count > 0 {
            let first = child.index as usize;
            return (first..first + child.count as usize).any(|stored| self.keeps(stored));
        }
        let node = child.index as usize;
        let [c0, c1] = bvh.nodes[node].children;
        let kept = [self.mark_children(bvh, c0), self.mark_children(bvh, c1)];
        self.children[node] = u8::from(kept[0]) | u8::from(kept[1]) << 1;
        kept[0] || kept[1]
    }
}

impl Keep for TriangleMask {
    #[inline(always)]
    fn keeps(&self, stored: usize) -> bool {
        self.bits[stored / 64] & (1 << (stored % 64)) != 0
    }

    #[inline(always)]
    fn kept_children(&self, node: usize) -> u8 {
        self.children[node]
    }
}

impl Bvh {
    /// Number of nodes of the binary tree (interior nodes and leaves).
    pub fn node_count(&self) -> usize {
        if self.triangles.is_empty() {
            0
        } else {
            2 * self.nodes.len() + 1
        }
    }

    /// Every stored triangle, in stored order (the indices [`Bvh::visit_near_segments4`]
    /// reports).
    pub fn all_triangles(&self) -> &[PackedTriangle] {
        &self.triangles
    }

    /// The build-input index of stored triangle `stored`.
    pub fn id(&self, stored: usize) -> u32 {
        self.ids[stored]
    }
}
