//! Construction of a [`Bvh`]: a binned surface area heuristic (SAH) over all three axes,
//! object-median splits where the SAH cannot bin or the tree grows too deep, and large
//! subtrees built in parallel into their own node lists and appended in depth-first order, so
//! that the tree is the same whatever the number of threads.

use std::ops::Range;

use glam::Vec3;

use super::triangle::PackedTriangle;
use super::{Bvh, Child, Node, SAH_DEPTH};
use crate::geometry::Aabb;

/// Relative padding of stored boxes: covers the rounding of the triangles' precomputed edges,
/// so that a hit the triangle test reports never lies outside its leaf's box.
const BOX_PADDING: f32 = 1.0 / (1 << 20) as f32;
/// Largest leaf the SAH may choose.
pub(super) const MAX_LEAF: usize = 4;
/// Bins per axis of the SAH sweep.
const BINS: usize = 16;
/// Ranges of at most this many triangles are binned into [`SMALL_BINS`] bins only.
const SMALL_RANGE: usize = 16;
const SMALL_BINS: usize = 6;
/// Cost of visiting an interior node, relative to one triangle test.
const TRAVERSAL_COST: f32 = 1.0;
/// Subtrees of at least this many triangles build their two halves in parallel (rayon); the
/// tree does not depend on the number of threads.
const PARALLEL_BUILD: usize = 4096;

impl Bvh {
    /// Builds the hierarchy over `triangles`; zero-area triangles are left out (no ray can
    /// hit them face-on). An empty or all-degenerate input gives a BVH that nothing hits.
    #[cfg(test)]
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        Bvh::build_grouped(triangles, |_| 0)
    }

    /// [`Bvh::build`] with the triangles of each group (`group` of a triangle's index in
    /// `triangles`) in a subtree of their own, the groups' subtrees joined by a balanced tree
    /// above them. A [`TriangleMask`](super::TriangleMask) hiding whole groups then prunes at
    /// their roots, so that a query over part of the scene (the scene without a mirror, or
    /// the mirror alone) visits the nodes a tree of that part alone would. With one group the
    /// tree is exactly [`Bvh::build`]'s. The joining levels count towards the depth that
    /// bounds the traversal stack: the groups' subtrees are built as starting that deep.
    pub fn build_grouped(triangles: &[[Vec3; 3]], group: impl Fn(u32) -> u32) -> Bvh {
        let mut prims: Vec<Prim> = triangles
            .iter()
            .enumerate()
            .filter(|(_, &[a, b, c])| PackedTriangle::new(a.into(), b.into(), c.into()).is_some())
            .map(|(id, &[a, b, c])| {
                let bounds = Aabb::from_points([a, b, c]);
                Prim {
                    id: id as u32,
                    bounds,
                    centroid: bounds.center(),
                }
            })
            .collect();
        if prims.is_empty() {
            return Bvh::default();
        }
        // Stable: with one group the order, hence the tree, is that of an ungrouped build.
        prims.sort_by_key(|p| group(p.id));
        let mut groups: Vec<Range<usize>> = Vec::new();
        for (i, p) in prims.iter().enumerate() {
            match groups.last_mut() {
                Some(last) if group(prims[last.start].id) == group(p.id) => last.end = i + 1,
                _ => groups.push(i..i + 1),
            }
        }
        let join_depth = groups.len().next_power_of_two().trailing_zeros() as usize;
        let mut nodes = Vec::with_capacity(prims.len());
        let (root, root_bounds) = build_groups(&mut prims, &groups, join_depth, &mut nodes);
        let triangles = prims
            .iter()
            .map(|p| {
                let [a, b, c] = triangles[p.id as usize];
                PackedTriangle::new(a.into(), b.into(), c.into()).expect("checked above")
            })
            .collect();
        Bvh {
            nodes,
            root,
            root_bounds,
            root_scale: root_bounds
                .min
                .abs()
                .max(root_bounds.max.abs())
                .max_element() as f64,
            triangles,
            ids: prims.iter().map(|p| p.id).collect(),
        }
    }
}

/// Builds the subtree over `prims` (stored from triangle `offset` on), appending its interior
/// nodes to `nodes` in depth-first order; returns what the subtree is and its padded box.
/// Large subtrees build their halves in parallel into separate lists, appended in order, so
/// the layout is that of a serial build.
/// The subtree over the groups `groups` (ranges of `prims`, which holds all triangles): a
/// group alone is [`build_subtree`] of its range, started at depth `depth`; more are split in
/// two halves under a new node, laid out depth-first like the rest of the tree.
fn build_groups(
    prims: &mut [Prim],
    groups: &[Range<usize>],
    depth: usize,
    nodes: &mut Vec<Node>,
) -> (Child, Aabb) {
    if let [range] = groups {
        return build_subtree(&mut prims[range.clone()], range.start, depth, nodes);
    }
    let slot = nodes.len();
    nodes.push(Node::new(
        [Aabb::EMPTY; 2],
        [Child { index: 0, count: 0 }; 2],
    ));
    let (left, right) = groups.split_at(groups.len() / 2);
    let (c0, b0) = build_groups(prims, left, depth, nodes);
    let (c1, b1) = build_groups(prims, right, depth, nodes);
    nodes[slot] = Node::new([b0, b1], [c0, c1]);
    let index = slot as u32;
    (Child { index, count: 0 }, b0.union(b1))
}

fn build_subtree(
    prims: &mut [Prim],
    offset: usize,
    depth: usize,
    nodes: &mut Vec<Node>,
) -> (Child, Aabb) {
    let bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds));
    let padded = Aabb {
        min: bounds.min - bounds.min.abs() * BOX_PADDING,
        max: bounds.max + bounds.max.abs() * BOX_PADDING,
    };
    let Some(mid) = split(prims, bounds, depth) else {
        let leaf = Child {
            index: offset as u32,
            count: prims.len() as u32,
        };
        return (leaf, padded);
    };
    let slot = nodes.len();
    nodes.push(Node::new(
        [Aabb::EMPTY; 2],
        [Child { index: 0, count: 0 }; 2],
    ));
    let parallel = prims.len() >= PARALLEL_BUILD;
    let (left, right) = prims.split_at_mut(mid);
    let ((c0, b0), (c1, b1)) = if parallel {
        // A subtree over n triangles has fewer than n interior nodes.
        let mut left_nodes = Vec::with_capacity(left.len());
        let mut right_nodes = Vec::with_capacity(right.len());
        let (l, r) = rayon::join(
            || build_subtree(left, offset, depth + 1, &mut left_nodes),
            || build_subtree(right, offset + mid, depth + 1, &mut right_nodes),
        );
        let l = (append(nodes, left_nodes, l.0), l.1);
        let r = (append(nodes, right_nodes, r.0), r.1);
        (l, r)
    } else {
        let l = build_subtree(left, offset, depth + 1, nodes);
        let r = build_subtree(right, offset + mid, depth + 1, nodes);
        (l, r)
    };
    nodes[slot] = Node::new([b0, b1], [c0, c1]);
    (
        Child {
            index: slot as u32,
            count: 0,
        },
        padded,
    )
}

/// Appends the nodes of a subtree built into its own list (`root` refers into it) to `nodes`,
/// renumbering its interior references; returns `root` renumbered.
fn append(nodes: &mut Vec<Node>, sub: Vec<Node>, root: Child) -> Child {
    let base = nodes.len() as u32;
    let shift = |c: Child| {
        if c.count == 0 {
            Child {
                index: c.index + base,
                count: 0,
            }
        } else {
            c
        }
    };
    nodes.extend(sub.into_iter().map(|mut n| {
        n.children = n.children.map(shift);
        n
    }));
    shift(root)
}

/// A triangle during the build.
#[derive(Debug, Clone, Copy)]
struct Prim {
    bounds: Aabb,
    centroid: Vec3,
    id: u32,
}

/// Decides how to split the triangles `range` with union bounds `bounds`: `None` makes a
/// leaf; `Some(k)` means `range` has been reordered so that the left child gets `range[..k]`
/// (`0 < k < range.len()`).
///
/// Binned SAH over all three axes; a leaf when it is no costlier and small enough. Degenerate
/// cases: coincident centroids (no axis to bin on) and depth beyond [`SAH_DEPTH`] split at the
/// object median, or make a leaf when at most [`MAX_LEAF`] triangles remain.
fn split(range: &mut [Prim], bounds: Aabb, depth: usize) -> Option<usize> {
    let n = range.len();
    if n <= 1 {
        return None;
    }
    let centroids = Aabb::from_points(range.iter().map(|p| p.centroid));
    let extent = centroids.extent();
    if depth >= SAH_DEPTH || extent == Vec3::ZERO {
        return (n > MAX_LEAF).then(|| median_split(range, extent));
    }
    // Small ranges bin more coarsely: the per-call cost of clearing and sweeping 3 x 16 bins
    // dominates the build near the leaves, where a few bins separate a few triangles as well.
    let count = if n <= SMALL_RANGE { SMALL_BINS } else { BINS };
    let binning = Binning::new(centroids, count);
    let mut bins = [[Bin::EMPTY; BINS]; 3];
    for p in range.iter() {
        for (axis, axis_bins) in bins.iter_mut().enumerate() {
            if extent[axis] > 0.0 {
                let bin = &mut axis_bins[binning.bin(p.centroid, axis)];
                bin.bounds = bin.bounds.union(p.bounds);
                bin.count += 1;
            }
        }
    }
    let inv_area = 1.0 / bounds.half_area().max(f32::MIN_POSITIVE);
    let mut best: Option<(f32, usize, usize)> = None;
    for (axis, axis_bins) in bins.iter().enumerate() {
        if extent[axis] <= 0.0 {
            continue;
        }
        // Right-hand sums of area x count for each split position, then a left sweep.
        let mut right_cost = [0.0f32; BINS];
        let mut acc = Bin::EMPTY;
        for s in (1..count).rev() {
            acc = acc.merge(axis_bins[s]);
            right_cost[s] = acc.bounds.half_area() * acc.count as f32;
        }
        let mut left = Bin::EMPTY;
        for s in 1..count {
            left = left.merge(axis_bins[s - 1]);
            if left.count == 0 || left.count == n {
                continue;
            }
            let cost = TRAVERSAL_COST
                + (left.bounds.half_area() * left.count as f32 + right_cost[s]) * inv_area;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, s));
            }
        }
    }
    let (cost, axis, s) = best?;
    if n <= MAX_LEAF && n as f32 <= cost {
        return None;
    }
    let mut k = 0;
    for i in 0..n {
        if binning.bin(range[i].centroid, axis) < s {
            range.swap(i, k);
            k += 1;
        }
    }
    Some(k)
}

/// Splits at the object median along the axis of largest centroid extent (any axis when the
/// centroids coincide): both halves are non-empty for two or more triangles.
fn median_split(range: &mut [Prim], extent: Vec3) -> usize {
    let axis = extent.max_position();
    let mid = range.len() / 2;
    range.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    mid
}

/// Maps centroids to SAH bins: the centroid bounds cut into `count` (at most [`BINS`]) equal
/// slices per axis.
struct Binning {
    min: Vec3,
    scale: Vec3,
    last: usize,
}

impl Binning {
    fn new(centroids: Aabb, count: usize) -> Binning {
        Binning {
            min: centroids.min,
            scale: count as f32 / centroids.extent(),
            last: count - 1,
        }
    }

    /// The bin of `c` along `axis` (an axis of positive extent).
    fn bin(&self, c: Vec3, axis: usize) -> usize {
        (((c[axis] - self.min[axis]) * self.scale[axis]) as usize).min(self.last)
    }
}

/// Triangles falling in one SAH bin.
#[derive(Debug, Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: usize,
}

impl Bin {
    const EMPTY: Bin = Bin {
        bounds: Aabb::EMPTY,
        count: 0,
    };

    fn merge(self, other: Bin) -> Bin {
        Bin {
            bounds: self.bounds.union(other.bounds),
            count: self.count + other.count,
        }
    }
}
