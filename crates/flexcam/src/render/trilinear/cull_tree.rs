//! A bounding-box tree over the scene's clusters (`SceneGeometry::clusters`, runs of
//! consecutive triangles of one object) for the hierarchical volume cull: a projection
//! triangle skips every subtree whose box lies beyond one of its bounding planes
//! (`VolumeBounds::box_side`), instead of testing every cluster, so a small projection
//! triangle (a 512-triangle visualisation surface sees a few scene triangles each) touches
//! a few nodes rather than the whole scene.
//!
//! Built once per scene by median splits of the clusters' box centres along the longest
//! axis of their spread: balanced, so at most `log2(clusters) + 2` levels deep. A node's box
//! holds its clusters' boxes, which hold their triangles' vertices, so a box outside a plane
//! has every triangle below it outside (the box test is stricter than the per-vertex test,
//! see `box_side`): the tree culls exactly pairs the triangle-by-triangle test would cull.
//!
//! Degenerate cases: an empty scene has an empty tree (nothing visited, nothing culled); a
//! cluster of zero extent (all vertices at one point, or a flat run) has a box of zero
//! thickness, tested like any other; a cluster with a non-finite vertex has an infinite box
//! (`SceneGeometry`), which no plane can have outside, so it and its ancestors are always
//! visited.

use std::ops::Range;

use glam::DVec3;

use super::volume_bounds::{BoxSide, VolumeBounds};

/// A run of consecutive scene triangles and the eight corners of the axis-aligned box
/// around their vertices. A plane that all eight corners lie beyond has every point of the
/// box, hence every vertex of the run, beyond it (the box is their convex hull). A run with
/// a non-finite vertex gets the infinite box (corners at infinity), never outside a plane.
#[derive(Debug, Clone)]
pub struct Cluster {
    pub triangles: Range<usize>,
    pub box_corners: [DVec3; 8],
}

/// Deeper than any balanced tree over at most 2^32 clusters (`log2 + 2`).
const MAX_DEPTH: usize = 40;

/// A box tree over clusters.
#[derive(Debug, Clone, Default)]
pub struct CullTree {
    /// Depth-first order: a node's first child follows it.
    nodes: Vec<Node>,
}

/// One node: its box (centre and half-extents), how many scene triangles lie below it, and
/// what it holds.
#[derive(Debug, Clone, Copy)]
struct Node {
    centre: DVec3,
    half: DVec3,
    triangles: u64,
    content: Content,
}

#[derive(Debug, Clone, Copy)]
enum Content {
    /// One cluster, by index.
    Leaf(u32),
    /// Two children: the next node and the node at this index.
    Inner(u32),
}

impl CullTree {
    /// The tree over `clusters` (at most 2^32 of them, as the renderer's keys require).
    pub fn new(clusters: &[Cluster]) -> CullTree {
        let mut tree = CullTree {
            nodes: Vec::with_capacity(2 * clusters.len()),
        };
        let mut order: Vec<u32> = (0..clusters.len() as u32).collect();
        if !order.is_empty() {
            tree.build(clusters, &mut order);
        }
        tree
    }

    /// Appends the subtree over the clusters `order` (not empty), its root first.
    fn build(&mut self, clusters: &[Cluster], order: &mut [u32]) {
        let lo_hi = |c: u32| {
            let corners = &clusters[c as usize].box_corners;
            (corners[0], corners[7])
        };
        let (lo, hi) = order
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &c| {
                let (a, b) = lo_hi(c);
                (lo.min(a), hi.max(b))
            });
        let at = self.nodes.len();
        self.nodes.push(Node {
            centre: 0.5 * (lo + hi),
            half: 0.5 * (hi - lo),
            triangles: order
                .iter()
                .map(|&c| clusters[c as usize].triangles.len() as u64)
                .sum(),
            content: Content::Leaf(order[0]),
        });
        if order.len() == 1 {
            return;
        }
        // Twice the centre of a cluster's box: only compared.
        let centre = |c: u32| {
            let (a, b) = lo_hi(c);
            a + b
        };
        let (clo, chi) = order
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &c| {
                (lo.min(centre(c)), hi.max(centre(c)))
            });
        let spread = chi - clo;
        let axis = if spread.x >= spread.y && spread.x >= spread.z {
            0
        } else if spread.y >= spread.z {
            1
        } else {
            2
        };
        let middle = order.len() / 2;
        order.select_nth_unstable_by(middle, |&a, &b| centre(a)[axis].total_cmp(&centre(b)[axis]));
        let (first, second) = order.split_at_mut(middle);
        self.build(clusters, first);
        let second_at = self.nodes.len() as u32;
        self.build(clusters, second);
        self.nodes[at].content = Content::Inner(second_at);
    }

    /// Calls `keep` with every cluster whose box is not wholly beyond one plane of `bounds`
    /// (no two boxes on the path to it were), in tree order, and with the planes that still
    /// cut its box (`BoxSide::Within`: the box lies wholly inside the others); returns the
    /// number of scene triangles in the subtrees skipped.
    pub fn visit(&self, bounds: &VolumeBounds, keep: impl FnMut(u32, u32)) -> u64 {
        self.visit_boxes(
            bounds.all_planes(),
            |centre, half, active| bounds.box_side(centre, half, active),
            keep,
        )
    }

    /// [`Self::visit`] with any box test: `side` tells of a node's box (centre and
    /// half-extents) whether everything in it is culled, given the planes (bit mask) that
    /// still cut its parent's box, `all` at the root. For the central projections' cones
    /// (`BoxTest::side`), which are no volume bounds.
    pub fn visit_boxes(
        &self,
        all: u32,
        mut side: impl FnMut(DVec3, DVec3, u32) -> BoxSide,
        mut keep: impl FnMut(u32, u32),
    ) -> u64 {
        if self.nodes.is_empty() {
            return 0;
        }
        let mut culled = 0;
        // Nodes still to visit, each with the planes that still cut its parent's box.
        let mut stack = [(0u32, 0u32); MAX_DEPTH];
        stack[0] = (0, all);
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let (index, active) = stack[len];
            let node = &self.nodes[index as usize];
            let active = match side(node.centre, node.half, active) {
                BoxSide::Outside => {
                    culled += node.triangles;
                    continue;
                }
                BoxSide::Within(active) => active,
            };
            match node.content {
                Content::Leaf(cluster) => keep(cluster, active),
                Content::Inner(second) => {
                    // The first child is visited first: pushed last.
                    stack[len] = (second, active);
                    stack[len + 1] = (index + 1, active);
                    len += 2;
                }
            }
        }
        culled
    }
}
