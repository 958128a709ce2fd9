//! A bounding volume hierarchy over triangles: binned SAH build (parallel over subtrees),
//! 64-byte interior nodes holding both children's boxes for a 4-wide slab test of the pair,
//! and near-first f32 traversal for closest-hit and any-hit queries.

pub(in crate::render) mod curve_triangle;
pub(in crate::render) mod triangle;

use std::mem::MaybeUninit;

use glam::{BVec4A, Vec3, Vec3A, Vec4, Vec4Swizzles};

use self::triangle::{FastHit, FastRay, PackedTriangle};
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

    /// Entry parameters of the ray into the two children's boxes (infinity for a box it
    /// misses within `[t_min, t_max]`), as [`box_entry`] computes them, bit for bit.
    #[inline(always)]
    fn entries(&self, slabs: &Slabs, t_max: f32) -> (f32, f32) {
        let t = |axis: usize| {
            let planes = if slabs.negative[axis] {
                self.planes[axis].zwxy()
            } else {
                self.planes[axis]
            };
            (planes - slabs.origin[axis]) * slabs.inv_direction[axis]
        };
        // A balanced tree of maxima: a shorter dependency chain than a running maximum.
        let interval = Vec4::new(slabs.t_min, slabs.t_min, -t_max, -t_max);
        let acc = t(0).max(t(1)).max(t(2).max(interval));
        let entry = |near: f32, neg_far: f32| {
            let far = -neg_far;
            if near <= far + far.abs() * ROBUST_SLACK {
                near
            } else {
                f32::INFINITY
            }
        };
        (entry(acc.x, acc.z), entry(acc.y, acc.w))
    }
}

/// A ray prepared for [`Node::entries`]: per axis, the origin and reciprocal direction
/// arranged so that `(planes - origin) * inv_direction` is `[near0, near1, -far0, -far1]`
/// (the planes swapped first where the direction is negative).
struct Slabs {
    origin: [Vec4; 3],
    inv_direction: [Vec4; 3],
    negative: [bool; 3],
    t_min: f32,
}

impl Slabs {
    #[inline(always)]
    fn new(ray: &FastRay) -> Slabs {
        let mut slabs = Slabs {
            origin: [Vec4::ZERO; 3],
            inv_direction: [Vec4::ZERO; 3],
            negative: [false; 3],
            t_min: ray.t_min,
        };
        for axis in 0..3 {
            let (o, inv) = (ray.origin[axis], ray.inv_direction[axis]);
            // A positive direction: near = (min - o) * inv, -far = (-max + o) * inv.
            // A negative one: near = (-(-max) - o) * inv = (-max + o) * -inv, and
            // -far = -(min - o) * inv = (min - o) * -inv, with the lanes swapped.
            let negative = inv < 0.0;
            let (o, inv) = if negative { (-o, -inv) } else { (o, inv) };
            slabs.origin[axis] = Vec4::new(o, o, -o, -o);
            slabs.inv_direction[axis] = Vec4::splat(inv);
            slabs.negative[axis] = negative;
        }
        slabs
    }
}

/// Whether the four rays' directions have the same sign on every axis (as their reciprocals,
/// which are never zero, tell).
fn same_signs(rays: [&FastRay; 4]) -> bool {
    let mask = |r: &FastRay| r.inv_direction.cmplt(Vec3A::ZERO).bitmask();
    let m = mask(rays[0]);
    rays[1..].iter().all(|r| mask(r) == m)
}

/// Four rays of one direction-sign class in SoA form for [`Packet::entries`]: lane `r` is
/// ray `r`.
struct Packet {
    origin: [Vec4; 3],
    inv_direction: [Vec4; 3],
    /// Per axis, whether the directions are negative (then a box is entered through its max
    /// plane).
    negative: [bool; 3],
    t_min: Vec4,
    t_max: Vec4,
}

impl Packet {
    #[inline(always)]
    fn new(rays: [&FastRay; 4]) -> Packet {
        let [a, b, c, d] = rays;
        let axis = |o: Vec3A, p: Vec3A, q: Vec3A, r: Vec3A| {
            [
                Vec4::new(o.x, p.x, q.x, r.x),
                Vec4::new(o.y, p.y, q.y, r.y),
                Vec4::new(o.z, p.z, q.z, r.z),
            ]
        };
        Packet {
            origin: axis(a.origin, b.origin, c.origin, d.origin),
            inv_direction: axis(
                a.inv_direction,
                b.inv_direction,
                c.inv_direction,
                d.inv_direction,
            ),
            negative: [
                a.inv_direction.x < 0.0,
                a.inv_direction.y < 0.0,
                a.inv_direction.z < 0.0,
            ],
            t_min: Vec4::new(a.t_min, b.t_min, c.t_min, d.t_min),
            t_max: Vec4::new(a.t_max, b.t_max, c.t_max, d.t_max),
        }
    }

    /// Entry parameters of the four rays into the two children's boxes of `node` (infinity
    /// where a ray misses a box within `[t_min, t_max]`), bit for bit those of [`box_entry`]
    /// (and so of [`Node::entries`]) for each ray: `(plane - origin) * inv_direction` with
    /// the near plane the min plane for a positive direction, the max plane for a negative.
    #[inline(always)]
    fn entries(&self, node: &Node, t_max: Vec4) -> (Vec4, Vec4) {
        let child = |c: usize| {
            let mut near = self.t_min;
            let mut far = t_max;
            for axis in 0..3 {
                let planes = node.planes[axis];
                let (lo, hi) = (planes[c], -planes[c + 2]);
                let (n, f) = if self.negative[axis] {
                    (hi, lo)
                } else {
                    (lo, hi)
                };
                let o = self.origin[axis];
                let inv = self.inv_direction[axis];
                near = near.max((Vec4::splat(n) - o) * inv);
                far = far.min((Vec4::splat(f) - o) * inv);
            }
            let inside = near.cmple(far + far.abs() * ROBUST_SLACK);
            Vec4::select(inside, near, Vec4::INFINITY)
        };
        (child(0), child(1))
    }
}

/// The points within `pad` of the segment from `origin` to `origin + direction`, in f32, for
/// [`Bvh::visit_near_segments4`]. A zero direction is allowed (the segment is a point).
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct NearSegment {
    origin: Vec3A,
    inv_direction: Vec3A,
    pad: f32,
}

impl NearSegment {
    /// The segment and its padding (f64, rounded outwards to cover the f32 conversion).
    /// `None` for non-finite input.
    pub fn new(origin: glam::DVec3, direction: glam::DVec3, pad: f64) -> Option<NearSegment> {
        if !(origin.is_finite() && direction.is_finite() && pad.is_finite()) {
            return None;
        }
        // The f32 rounding of the end points, at most one ulp of the largest coordinate.
        let rounding = (origin.abs().max_element() + direction.abs().max_element()) as f32
            * f32::EPSILON
            * 4.0;
        let safe = |c: f32| {
            if c.abs() < 1e-30 {
                1e-30f32.copysign(c)
            } else {
                c
            }
        };
        let d = direction.as_vec3();
        Some(NearSegment {
            origin: Vec3A::from(origin.as_vec3()),
            inv_direction: Vec3A::new(1.0 / safe(d.x), 1.0 / safe(d.y), 1.0 / safe(d.z)),
            pad: pad as f32 * (1.0 + 4.0 * f32::EPSILON) + rounding,
        })
    }

    /// Whether the segment meets the box `[min, max]` enlarged by `pad` (slab test over the
    /// parameter range [0, 1], with the exit enlarged as in [`box_entry`]).
    #[inline(always)]
    fn meets(&self, min: Vec3, max: Vec3) -> bool {
        let t0 = (Vec3A::from(min) - self.pad - self.origin) * self.inv_direction;
        let t1 = (Vec3A::from(max) + self.pad - self.origin) * self.inv_direction;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element().min(1.0);
        near <= far + far.abs() * ROBUST_SLACK
    }
}

/// Up to four [`NearSegment`]s in SoA form, tested against a box at once for
/// [`Bvh::visit_near_segments4`]: lane `i` is segment `i`, each lane's test bit for bit that
/// of [`NearSegment::meets`] (the same operations in the same order, per lane).
pub(in crate::render) struct NearSegments4 {
    origin: [Vec4; 3],
    inv_direction: [Vec4; 3],
    pad: Vec4,
    /// Set in lane `i` when lane `i` holds a segment.
    lanes: BVec4A,
}

impl NearSegments4 {
    /// The segments present (`None`: an empty lane, never reported).
    pub fn new(segments: [Option<&NearSegment>; 4]) -> NearSegments4 {
        let fill = segments.iter().flatten().next().copied();
        let lane = |i: usize| segments[i].or(fill);
        let get = |f: &dyn Fn(&NearSegment) -> f32| {
            Vec4::from_array(std::array::from_fn(|i| lane(i).map_or(0.0, f)))
        };
        let axis = |f: fn(Vec3A) -> f32| {
            [
                get(&|s: &NearSegment| f(s.origin)),
                get(&|s: &NearSegment| f(s.inv_direction)),
            ]
        };
        let [ox, ix] = axis(|v| v.x);
        let [oy, iy] = axis(|v| v.y);
        let [oz, iz] = axis(|v| v.z);
        NearSegments4 {
            origin: [ox, oy, oz],
            inv_direction: [ix, iy, iz],
            pad: get(&|s: &NearSegment| s.pad),
            lanes: BVec4A::from_array(segments.map(|s| s.is_some())),
        }
    }

    /// Per lane, the parameter along the lane's segment (in [0, 1]) at which it enters the
    /// box `[min, max]` enlarged by its pad, or infinity where it misses it or the lane is
    /// empty. A lane's entry is finite exactly when [`NearSegment::meets`] accepts the box
    /// (the same operations in the same order).
    #[inline(always)]
    fn entries(&self, min: Vec3, max: Vec3) -> Vec4 {
        let t = |axis: usize| {
            let o = self.origin[axis];
            let inv = self.inv_direction[axis];
            let t0 = (Vec4::splat(min[axis]) - self.pad - o) * inv;
            let t1 = (Vec4::splat(max[axis]) + self.pad - o) * inv;
            (t0.min(t1), t0.max(t1))
        };
        let ((n0, f0), (n1, f1), (n2, f2)) = (t(0), t(1), t(2));
        let near = n0.max(n1).max(n2).max(Vec4::ZERO);
        let far = f0.min(f1).min(f2).min(Vec4::ONE);
        let inside = near.cmple(far + far.abs() * ROBUST_SLACK) & self.lanes;
        Vec4::select(inside, near, Vec4::INFINITY)
    }

    /// The lanes whose segment meets the box `[min, max]` enlarged by its pad.
    #[cfg(test)]
    fn meets(&self, min: Vec3, max: Vec3) -> u32 {
        self.entries(min, max).cmpne(Vec4::INFINITY).bitmask()
    }
}

/// Entry parameter of `ray` into the box `[min, max]` if it meets it within
/// `[ray.t_min, t_max]`, else infinity. The exit parameter is enlarged by a few ulps (Ize,
/// "Robust BVH ray traversal", 2013) so that rounding never culls a box the ray touches.
#[inline(always)]
fn box_entry(bounds: &Aabb, ray: &FastRay, t_max: f32) -> f32 {
    let t0 = (Vec3A::from(bounds.min) - ray.origin) * ray.inv_direction;
    let t1 = (Vec3A::from(bounds.max) - ray.origin) * ray.inv_direction;
    let near = t0.min(t1).max_element().max(ray.t_min);
    let far = t0.max(t1).min_element().min(t_max);
    if near <= far + far.abs() * ROBUST_SLACK {
        near
    } else {
        f32::INFINITY
    }
}

/// `2 * gamma(3)` for f32 (Pharr et al., pbrt 3rd ed., 3.9.2): the relative error of a slab
/// test, by which the exit distance is enlarged.
const ROBUST_SLACK: f32 = 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);
/// Relative padding of stored boxes: covers the rounding of the triangles' precomputed edges,
/// so that a hit the triangle test reports never lies outside its leaf's box.
const BOX_PADDING: f32 = 1.0 / (1 << 20) as f32;
/// Relative margin of [`Bvh::root_overlaps`]: 100 times the f32 rounding of a coordinate.
const ROOT_MARGIN: f64 = 1e-5;
/// Largest leaf the SAH may choose.
const MAX_LEAF: usize = 4;
/// Bins per axis of the SAH sweep.
const BINS: usize = 16;
/// Ranges of at most this many triangles are binned into [`SMALL_BINS`] bins only.
const SMALL_RANGE: usize = 16;
const SMALL_BINS: usize = 6;
/// Cost of visiting an interior node, relative to one triangle test.
const TRAVERSAL_COST: f32 = 1.0;
/// Depth after which the build splits at the object median instead of by SAH. Median splits
/// halve the triangle count, so the tree is at most `SAH_DEPTH + 32` deep, which bounds the
/// traversal stack and the build's recursion.
const SAH_DEPTH: usize = 32;
const STACK_SIZE: usize = SAH_DEPTH + 33;
/// Subtrees of at least this many triangles build their two halves in parallel (rayon); the
/// tree does not depend on the number of threads.
const PARALLEL_BUILD: usize = 4096;

/// The pending far children of a front-to-back walk, each with the entry distance (one ray's
/// `f32`, or four lanes' `Vec4`) it was pushed with, so that a pop can skip nodes that
/// closer hits found since have put out of reach. One stack shared by every ordered walk of
/// [`Bvh`]; it holds at most one node per level of the tree, fewer than `STACK_SIZE`.
struct Pending<E: Copy> {
    /// Left uninitialised: filling 65 entries per ray would cost as much as a few node
    /// tests. Entries below `depth` are always initialised (each push writes one).
    stack: [MaybeUninit<(Child, E)>; STACK_SIZE],
    depth: usize,
}

impl<E: Copy> Pending<E> {
    #[inline(always)]
    fn new() -> Pending<E> {
        Pending {
            stack: [const { MaybeUninit::uninit() }; STACK_SIZE],
            depth: 0,
        }
    }

    #[inline(always)]
    fn push(&mut self, child: Child, entry: E) {
        self.stack[self.depth].write((child, entry));
        self.depth += 1;
    }

    /// Pops nodes, most recently pushed first, until one whose entry `open` accepts; `None`
    /// once the stack is empty.
    #[inline(always)]
    fn pop(&mut self, mut open: impl FnMut(E) -> bool) -> Option<(Child, E)> {
        while self.depth > 0 {
            self.depth -= 1;
            // SAFETY: `stack[depth]` was written by the push that made `depth` this large
            // (pushes write `stack[depth]` and then increment it; pops decrement it).
            let (child, entry) = unsafe { self.stack[self.depth].assume_init() };
            if open(entry) {
                return Some((child, entry));
            }
        }
        None
    }
}

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

impl Bvh {
    /// Builds the hierarchy over `triangles`; zero-area triangles are left out (no ray can
    /// hit them face-on). An empty or all-degenerate input gives a BVH that nothing hits.
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
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
        let mut nodes = Vec::with_capacity(prims.len());
        let (root, root_bounds) = build_subtree(&mut prims, 0, 0, &mut nodes);
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

    /// Number of nodes of the binary tree (interior nodes and leaves).
    pub fn node_count(&self) -> usize {
        if self.triangles.is_empty() {
            0
        } else {
            2 * self.nodes.len() + 1
        }
    }

    /// The hit with the smallest `t` in the ray's interval, if any.
    pub fn closest(&self, ray: &FastRay) -> Option<BvhHit> {
        self.traverse::<false>(ray)
    }

    /// Whether anything is hit in the ray's interval (stops at the first hit found).
    pub fn occluded(&self, ray: &FastRay) -> bool {
        self.traverse::<true>(ray).is_some()
    }

    /// Near-first traversal: at an interior node both children's boxes are tested at once,
    /// the nearer is visited and the farther pushed with its entry distance, and popped nodes
    /// entered beyond the closest hit so far are skipped. With `ANY`, returns at the first hit.
    #[inline(always)]
    fn traverse<const ANY: bool>(&self, ray: &FastRay) -> Option<BvhHit> {
        if self.triangles.is_empty() || box_entry(&self.root_bounds, ray, ray.t_max).is_infinite() {
            return None;
        }
        let slabs = Slabs::new(ray);
        let mut t_max = ray.t_max;
        let mut best: Option<(usize, FastHit)> = None;
        // Stored index of `best` (past the end while there is none): on equal `t` the lower
        // index wins, so the result does not depend on the order leaves are visited in, and
        // packet traversal ([`Bvh::closest4`]) finds exactly the same hits.
        let mut best_index = usize::MAX;
        let mut pending = Pending::<f32>::new();
        let mut current = self.root;
        loop {
            if current.count > 0 {
                let first = current.index as usize;
                let count = current.count as usize;
                for (i, tri) in self.triangles[first..first + count].iter().enumerate() {
                    if let Some(hit) = tri.intersect(ray, t_max) {
                        if hit.t < t_max || first + i < best_index {
                            t_max = hit.t;
                            best = Some((first + i, hit));
                            best_index = first + i;
                        }
                        if ANY {
                            return self.finish(best);
                        }
                    }
                }
            } else {
                let node = &self.nodes[current.index as usize];
                let (t0, t1) = node.entries(&slabs, t_max);
                let [c0, c1] = node.children;
                let (near, far, t_near, t_far) = if t1 < t0 {
                    (c1, c0, t1, t0)
                } else {
                    (c0, c1, t0, t1)
                };
                if t_near != f32::INFINITY {
                    if t_far != f32::INFINITY {
                        pending.push(far, t_far);
                    }
                    current = near;
                    continue;
                }
            }
            // The nearest pending node still in front of the closest hit.
            match pending.pop(|t_entry| t_entry <= t_max) {
                Some((child, _)) => current = child,
                None => return self.finish(best),
            }
        }
    }

    /// The closest hits of four rays, exactly as [`Bvh::closest`] finds them one by one, by
    /// one traversal shared by the four: a node is entered when any of the rays meets its box,
    /// and every ray keeps its own closest hit. Pays for coherent rays (neighbouring pixels'
    /// primary rays); the rays' direction signs must agree on every axis, else (or when a
    /// ray is `None`) each ray is traced alone.
    pub fn closest4(&self, rays: [Option<&FastRay>; 4]) -> [Option<BvhHit>; 4] {
        match rays {
            [Some(a), Some(b), Some(c), Some(d)] if same_signs([a, b, c, d]) => {
                self.traverse4([a, b, c, d])
            }
            [a, b, c, d] => {
                let single = |r: Option<&FastRay>| r.and_then(|r| self.closest(r));
                [single(a), single(b), single(c), single(d)]
            }
        }
    }

    /// The packet traversal of [`Bvh::closest4`]. The result per ray is the minimum of
    /// `(t, stored index)` over the triangles it hits, as for [`Bvh::traverse`]: a ray's
    /// winning leaf is always visited (its boxes pass the same slab test, at a `t_max` no
    /// smaller than the winning `t`), and which other leaves are visited, or in what order,
    /// does not change that minimum.
    #[inline(always)]
    fn traverse4(&self, rays: [&FastRay; 4]) -> [Option<BvhHit>; 4] {
        if self.triangles.is_empty() {
            return [None; 4];
        }
        let root_entry = Vec4::from_array(rays.map(|r| box_entry(&self.root_bounds, r, r.t_max)));
        if root_entry.cmpne(Vec4::INFINITY).bitmask() == 0 {
            return [None; 4];
        }
        let packet = Packet::new(rays);
        let mut t_max = packet.t_max;
        let mut best: [Option<(usize, FastHit)>; 4] = [None; 4];
        let mut best_index = [usize::MAX; 4];
        let mut pending = Pending::<Vec4>::new();
        let (mut current, mut entry) = (self.root, root_entry);
        loop {
            if current.count > 0 {
                let first = current.index as usize;
                let count = current.count as usize;
                // Only the rays that reach this leaf in front of their closest hit.
                let mut active = entry.cmple(t_max).bitmask();
                let mut t_max_lanes = t_max.to_array();
                while active != 0 {
                    let r = active.trailing_zeros() as usize;
                    active &= active - 1;
                    let ray = rays[r];
                    for (i, tri) in self.triangles[first..first + count].iter().enumerate() {
                        if let Some(hit) = tri.intersect(ray, t_max_lanes[r]) {
                            if hit.t < t_max_lanes[r] || first + i < best_index[r] {
                                t_max_lanes[r] = hit.t;
                                best[r] = Some((first + i, hit));
                                best_index[r] = first + i;
                            }
                        }
                    }
                }
                t_max = Vec4::from_array(t_max_lanes);
            } else {
                let node = &self.nodes[current.index as usize];
                let (t0, t1) = packet.entries(node, t_max);
                let (hit0, hit1) = (
                    t0.cmpne(Vec4::INFINITY).bitmask() != 0,
                    t1.cmpne(Vec4::INFINITY).bitmask() != 0,
                );
                let [c0, c1] = node.children;
                if hit0 || hit1 {
                    let (near, far, e_near, e_far, both) = if !hit0 {
                        (c1, c0, t1, t0, false)
                    } else if !hit1 {
                        (c0, c1, t0, t1, false)
                    } else if t1.min_element() < t0.min_element() {
                        (c1, c0, t1, t0, true)
                    } else {
                        (c0, c1, t0, t1, true)
                    };
                    if both {
                        pending.push(far, e_far);
                    }
                    (current, entry) = (near, e_near);
                    continue;
                }
            }
            // The next pending node some ray still enters in front of its closest hit.
            match pending.pop(|e| e.cmple(t_max).bitmask() != 0) {
                Some(next) => (current, entry) = next,
                None => return best.map(|b| self.finish(b)),
            }
        }
    }

    /// Whether `segment` meets the box of the whole tree enlarged by its pad (never for an
    /// empty tree): a cheap first test for a query that would otherwise traverse.
    pub fn near_root(&self, segment: &NearSegment) -> bool {
        !self.triangles.is_empty() && segment.meets(self.root_bounds.min, self.root_bounds.max)
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

    /// Whether the box `[min, max]` overlaps the box of the whole tree enlarged by
    /// [`ROOT_MARGIN`] of the largest coordinate magnitude of either box (never for an empty
    /// tree, always for non-finite input): a test without divisions for anything known to
    /// lie inside `[min, max]`, such as a curve piece inside the box of its control points
    /// or a ray's segment inside the box of its two ends. The margin, far above f32
    /// rounding, keeps the test conservative for the f32 searches that follow it: what it
    /// rejects, they could not hit.
    #[inline]
    pub fn root_overlaps(&self, min: glam::DVec3, max: glam::DVec3) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let (lo, hi) = (
            self.root_bounds.min.as_dvec3(),
            self.root_bounds.max.as_dvec3(),
        );
        let scale = self.root_scale.max(min.abs().max(max.abs()).max_element());
        let margin = glam::DVec3::splat(ROOT_MARGIN * scale);
        // Written so that NaN anywhere fails a rejection and counts as an overlap.
        let apart = (min - margin).cmpgt(hi).any() || (max + margin).cmplt(lo).any();
        !apart
    }

    /// Whether the box `[min, max]`, enlarged as in [`Bvh::root_overlaps`], overlaps the box
    /// of some leaf: the same test made tighter, since the leaves' boxes hug the triangles
    /// where the root's box has empty corners. As conservative for the searches that follow:
    /// a hit they report lies in its leaf's (padded) box, and on a path that the margin keeps
    /// inside the enlarged box. Non-finite input counts as an overlap.
    pub fn leaves_overlap(&self, min: glam::DVec3, max: glam::DVec3) -> bool {
        if !self.root_overlaps(min, max) {
            return false;
        }
        let scale = self.root_scale.max(min.abs().max(max.abs()).max_element());
        let margin = glam::DVec3::splat(ROOT_MARGIN * scale);
        let (lo, hi) = (min - margin, max + margin);
        if !(lo.is_finite() && hi.is_finite()) {
            return true;
        }
        self.walk_leaves(
            |child_min, child_max| {
                let (child_min, child_max) = (child_min.as_dvec3(), child_max.as_dvec3());
                !(lo.cmpgt(child_max).any() || hi.cmplt(child_min).any())
            },
            |_| true,
        )
    }

    /// Calls `visit` with the lane and the stored index (see [`Bvh::all_triangles`],
    /// [`Bvh::id`]) of the triangles in the leaves whose box, enlarged by the lane's pad on
    /// every side, the lane's segment meets: a conservative cull for anything that lies within
    /// `pad` of the segment (a curve inside the convex hull of its control points, see
    /// [`NearSegment`]). `visit` returns the lane's bound: from then on the lane skips every
    /// node and triangle whose box its segment enters beyond that parameter (`f32::MAX`:
    /// none), so a caller that knows nothing beyond some point of the segment can improve
    /// its result ends the lane's walk there. The walk is ordered along the segments: at a
    /// node, the child that some lane enters first is visited first, so that the bounds fall
    /// early. A lane enters a node only when its own segment meets every box on the way
    /// within its bound, so each lane sees a subset of the triangles a walk of its segment
    /// alone would, whatever the other lanes hold, and every triangle of a box it enters
    /// within its bound; the node visits are shared, and one 4-wide test serves the four
    /// lanes.
    pub fn visit_near_segments4(
        &self,
        segments: &NearSegments4,
        mut visit: impl FnMut(usize, usize) -> f32,
    ) {
        if self.triangles.is_empty() {
            return;
        }
        let mut bounds = Vec4::MAX;
        let mut pending = Pending::<Vec4>::new();
        let mut current = self.root;
        let mut entry = segments.entries(self.root_bounds.min, self.root_bounds.max);
        loop {
            // The lanes that enter `current` within their bounds.
            let active = entry.cmple(bounds);
            if current.count > 0 {
                let first = current.index as usize;
                for stored in first..first + current.count as usize {
                    let mut left = entry.cmple(bounds).bitmask();
                    while left != 0 {
                        let lane = left.trailing_zeros() as usize;
                        bounds[lane] = visit(lane, stored);
                        left &= left - 1;
                    }
                }
            } else if active.any() {
                let node = &self.nodes[current.index as usize];
                let enter = |k: usize| {
                    let (min, max) = node.child_box(k);
                    let e = segments.entries(min, max);
                    Vec4::select(active & e.cmple(bounds), e, Vec4::INFINITY)
                };
                let (e0, e1) = (enter(0), enter(1));
                let (first0, first1) = (e0.min_element(), e1.min_element());
                let [c0, c1] = node.children;
                let (near, far, e_near, e_far, f_far) = if first1 < first0 {
                    (c1, c0, e1, e0, first0)
                } else {
                    (c0, c1, e0, e1, first1)
                };
                if e_near.min_element() != f32::INFINITY {
                    if f_far != f32::INFINITY {
                        pending.push(far, e_far);
                    }
                    (current, entry) = (near, e_near);
                    continue;
                }
            }
            // The next pending node some lane enters within its bound.
            match pending.pop(|e| e.cmple(bounds).any()) {
                Some(next) => (current, entry) = next,
                None => return,
            }
        }
    }

    /// Walks the tree depth first, in tree order, into every child whose box (`min`, `max`)
    /// `enter` accepts, calling `leaf` on each leaf reached (the root too, when it is one);
    /// `leaf` returning true ends the walk. Returns whether a leaf ended it. A fixed stack,
    /// no allocation per call: it holds at most one pending sibling per level of the tree,
    /// fewer than STACK_SIZE.
    fn walk_leaves(
        &self,
        mut enter: impl FnMut(Vec3, Vec3) -> bool,
        mut leaf: impl FnMut(Child) -> bool,
    ) -> bool {
        let mut stack = [self.root; STACK_SIZE];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let current = stack[depth];
            if current.count > 0 {
                if leaf(current) {
                    return true;
                }
                continue;
            }
            let node = &self.nodes[current.index as usize];
            // Push the second child first, so that the first is visited first (tree order).
            for k in [1, 0] {
                let (min, max) = node.child_box(k);
                if enter(min, max) {
                    stack[depth] = node.children[k];
                    depth += 1;
                }
            }
        }
        false
    }

    /// The hit at stored triangle `i`, known by its build-input index.
    fn finish(&self, best: Option<(usize, FastHit)>) -> Option<BvhHit> {
        best.map(|(i, hit)| BvhHit {
            id: self.ids[i],
            hit,
        })
    }
}

/// Builds the subtree over `prims` (stored from triangle `offset` on), appending its interior
/// nodes to `nodes` in depth-first order; returns what the subtree is and its padded box.
/// Large subtrees build their halves in parallel into separate lists, appended in order, so
/// the layout is that of a serial build.
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

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::geometry::Ray;

    /// A deterministic generator for test inputs (SplitMix64).
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }

        fn vec(&mut self, scale: f32) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next()) * 2.0 * scale - scale
        }
    }

    fn soup(rng: &mut Rng, n: usize) -> Vec<[Vec3; 3]> {
        (0..n)
            .map(|_| {
                let c = rng.vec(10.0);
                [c + rng.vec(1.5), c + rng.vec(1.5), c + rng.vec(1.5)]
            })
            .collect()
    }

    /// The closest hit by testing every triangle with the same f32 routine.
    fn brute_force(triangles: &[[Vec3; 3]], ray: &FastRay) -> Option<(u32, f32)> {
        let mut best: Option<(u32, f32)> = None;
        for (i, &[a, b, c]) in triangles.iter().enumerate() {
            let Some(tri) = PackedTriangle::new(a.into(), b.into(), c.into()) else {
                continue;
            };
            let t_max = best.map_or(ray.t_max, |b| b.1);
            if let Some(h) = tri.intersect(ray, t_max) {
                best = Some((i as u32, h.t));
            }
        }
        best
    }

    #[test]
    fn closest_hit_equals_brute_force_on_random_soups() {
        let mut rng = Rng(7);
        let mut hits = 0;
        for n in [1, 2, 5, 40, 700, 9000] {
            let triangles = soup(&mut rng, n);
            let bvh = Bvh::build(&triangles);
            for k in 0..400 {
                // Unnormalised directions; every fourth ray has a finite interval.
                let origin = rng.vec(15.0).as_dvec3();
                let target = rng.vec(8.0).as_dvec3();
                let scale = 0.1 + 3.0 * rng.next() as f64;
                let mut ray = Ray::new(origin, (target - origin) * scale);
                if k % 4 == 0 {
                    ray.t_min = 0.3 / scale;
                    ray.t_max = 0.9 / scale;
                }
                let fast = FastRay::new(&ray).unwrap();
                let expected = brute_force(&triangles, &fast);
                let got = bvh.closest(&fast).map(|h| (h.id, h.hit.t));
                assert_eq!(got, expected, "soup of {n}, ray {k}");
                assert_eq!(bvh.occluded(&fast), expected.is_some());
                if let Some((_, t)) = got {
                    assert!(t as f64 >= ray.t_min as f32 as f64 && t as f64 <= ray.t_max);
                    hits += 1;
                }
            }
        }
        assert!(hits > 200, "too few hits ({hits}) to test anything");
    }

    #[test]
    fn degenerate_triangles_are_never_hit() {
        let line = [Vec3::ZERO, Vec3::ONE, Vec3::splat(2.0)];
        let point = [Vec3::ONE; 3];
        let bvh = Bvh::build(&[line, point]);
        assert_eq!(bvh.node_count(), 0);
        for d in [DVec3::X, DVec3::ONE, DVec3::new(-1.0, 1.0, 0.0)] {
            let ray = Ray::new(DVec3::ONE - d, d);
            assert!(bvh.closest(&FastRay::new(&ray).unwrap()).is_none());
        }
        // Mixed with a proper triangle, only that one is found.
        let good = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(3.0, -1.0, 1.0),
            Vec3::new(-1.0, 3.0, 1.0),
        ];
        let bvh = Bvh::build(&[line, good, point]);
        let ray = Ray::new(DVec3::new(1.0, 1.0, 5.0), DVec3::NEG_Z);
        assert_eq!(bvh.closest(&FastRay::new(&ray).unwrap()).unwrap().id, 1);
    }

    #[test]
    fn rays_parallel_to_a_triangle_miss_it() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let bvh = Bvh::build(&[tri]);
        for origin in [DVec3::new(-1.0, 0.25, 0.0), DVec3::new(-1.0, 0.25, 1e-3)] {
            let ray = Ray::new(origin, DVec3::X);
            assert!(bvh.closest(&FastRay::new(&ray).unwrap()).is_none());
        }
    }

    #[test]
    fn interval_limits_are_honoured() {
        let tri = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(2.0, -1.0, 0.0),
            Vec3::new(-1.0, 2.0, 0.0),
        ];
        let bvh = Bvh::build(&[tri]);
        let mut ray = Ray::new(DVec3::new(0.0, 0.0, 4.0), DVec3::new(0.0, 0.0, -2.0));
        let t = bvh.closest(&FastRay::new(&ray).unwrap()).unwrap().hit.t;
        assert_eq!(t, 2.0);
        ray.t_max = 1.99;
        assert!(bvh.closest(&FastRay::new(&ray).unwrap()).is_none());
        ray.t_max = 3.0;
        ray.t_min = 2.01;
        assert!(bvh.closest(&FastRay::new(&ray).unwrap()).is_none());
        ray.t_min = 3.5;
        assert!(FastRay::new(&ray).is_none(), "empty interval");
        ray.t_min = f64::NAN;
        assert!(FastRay::new(&ray).is_none(), "NaN bound");
    }

    #[test]
    fn coincident_triangles_build_a_bounded_tree() {
        // Many copies of one triangle: no axis to bin on, so median splits.
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let bvh = Bvh::build(&vec![tri; 1000]);
        let ray = Ray::new(DVec3::new(0.2, 0.2, 1.0), DVec3::NEG_Z);
        let hit = bvh.closest(&FastRay::new(&ray).unwrap()).unwrap();
        assert_eq!(hit.hit.t, 1.0);
        assert!(bvh
            .nodes
            .iter()
            .flat_map(|n| n.children)
            .all(|c| c.count as usize <= MAX_LEAF));
    }

    /// `closest4` must give bit for bit what `closest` gives ray by ray.
    fn assert_packet_matches(bvh: &Bvh, rays: [Option<FastRay>; 4], what: &str) -> usize {
        let key = |h: Option<BvhHit>| {
            h.map(|h| {
                (
                    h.id,
                    h.hit.t.to_bits(),
                    h.hit.u.to_bits(),
                    h.hit.v.to_bits(),
                )
            })
        };
        let got = bvh.closest4([0, 1, 2, 3].map(|i| rays[i].as_ref()));
        let mut hits = 0;
        for (r, got) in rays.iter().zip(got) {
            let expected = r.as_ref().and_then(|r| bvh.closest(r));
            assert_eq!(key(got), key(expected), "{what}");
            hits += usize::from(expected.is_some());
        }
        hits
    }

    #[test]
    fn packets_find_exactly_the_single_ray_hits() {
        let mut rng = Rng(11);
        let mut hits = 0;
        for n in [1, 3, 60, 2000, 20000] {
            let triangles = soup(&mut rng, n);
            let bvh = Bvh::build(&triangles);
            for k in 0..300 {
                // A pinhole quad: one origin, four directions a small angle apart (an
                // occasional ray of the quad set far off, or missing, or with an interval).
                let origin = rng.vec(15.0).as_dvec3();
                let target = rng.vec(8.0).as_dvec3();
                let spread = [1e-4, 1e-2, 0.3][k % 3];
                let mut rays = [0; 4].map(|_| {
                    let d = (target - origin).normalize() + rng.vec(spread).as_dvec3();
                    let mut ray = Ray::new(origin, d * (0.5 + rng.next() as f64));
                    if k % 7 == 0 {
                        ray.t_min = 5.0;
                        ray.t_max = 20.0;
                    }
                    FastRay::new(&ray)
                });
                match k % 10 {
                    1 => rays[2] = None,
                    2 => rays[1] = FastRay::new(&Ray::new(origin, -(target - origin))),
                    3 => {
                        rays[3] = FastRay::new(&Ray::new(
                            rng.vec(15.0).as_dvec3(),
                            rng.vec(1.0).as_dvec3(),
                        ))
                    }
                    _ => {}
                }
                hits += assert_packet_matches(&bvh, rays, &format!("soup of {n}, quad {k}"));
            }
        }
        assert!(hits > 1000, "too few hits ({hits}) to test anything");
    }

    #[test]
    fn packets_and_single_rays_break_ties_alike() {
        // Stacked copies of a triangle and a grid of triangles sharing edges: every ray
        // meets several triangles at exactly the same `t`; the lowest stored index wins.
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let mut triangles = vec![tri; 300];
        for i in 0..20 {
            for j in 0..20 {
                let c = Vec3::new(i as f32, j as f32, -1.0);
                triangles.push([c, c + Vec3::X, c + Vec3::Y]);
                triangles.push([c + Vec3::X, c + Vec3::ONE - Vec3::Z, c + Vec3::Y]);
            }
        }
        let bvh = Bvh::build(&triangles);
        let mut rng = Rng(5);
        let mut hits = 0;
        for k in 0..400 {
            let origin = DVec3::new(0.3, 0.3, 4.0) + rng.vec(0.5).as_dvec3() * 4.0;
            let target = DVec3::new(rng.next() as f64 * 20.0, rng.next() as f64 * 20.0, -1.0);
            // Pixel-like steps, some of them through shared edges and vertices.
            let step = [0.0, 0.5, 1.0][k % 3];
            let rays = [(0.0, 0.0), (step, 0.0), (0.0, step), (step, step)].map(|(x, y)| {
                FastRay::new(&Ray::new(origin, target + DVec3::new(x, y, 0.0) - origin))
            });
            hits += assert_packet_matches(&bvh, rays, &format!("ray {k}"));
        }
        assert!(hits > 1000);
        // The stacked copies: the same one of the 300 wins (the first stored), whatever the
        // ray, the order of traversal depending on the ray's direction.
        let ids: Vec<u32> = [
            DVec3::NEG_Z,
            DVec3::new(0.3, 0.2, -1.0),
            DVec3::new(-0.2, -0.1, -1.0),
        ]
        .map(|d| {
            let ray = FastRay::new(&Ray::new(DVec3::new(0.2, 0.2, 0.0) - d, d)).unwrap();
            bvh.closest(&ray).unwrap().id
        })
        .to_vec();
        assert!(
            ids[0] < 300 && ids.iter().all(|&id| id == ids[0]),
            "{ids:?}"
        );
    }

    #[test]
    fn boxes_apart_from_every_leaf_are_apart_from_every_triangle() {
        let mut rng = Rng(7);
        let triangles = soup(&mut rng, 300);
        let bvh = Bvh::build(&triangles);
        let (mut apart, mut root_only) = (0, 0);
        for _ in 0..4000 {
            let (c, half) = (rng.vec(12.0).as_dvec3(), rng.vec(1.0).abs().as_dvec3());
            let (min, max) = (c - half, c + half);
            let touched = triangles.iter().any(|t| {
                let lo = t[0].min(t[1]).min(t[2]).as_dvec3();
                let hi = t[0].max(t[1]).max(t[2]).as_dvec3();
                lo.cmple(max).all() && hi.cmpge(min).all()
            });
            if !bvh.leaves_overlap(min, max) {
                assert!(!touched, "box [{min}, {max}] touches a triangle");
                apart += 1;
                root_only += usize::from(bvh.root_overlaps(min, max));
            } else {
                assert!(bvh.root_overlaps(min, max));
            }
        }
        // Both outcomes occur, and the leaves reject boxes inside the root's box.
        assert!(apart > 100 && root_only > 10, "{apart} {root_only}");
        assert!(bvh.leaves_overlap(DVec3::splat(f64::NAN), DVec3::ZERO));
        assert!(!Bvh::build(&[]).leaves_overlap(DVec3::ZERO, DVec3::ONE));
    }

    #[test]
    fn four_segments_meet_a_box_exactly_when_each_does_alone() {
        let mut rng = Rng(11);
        let segment = |rng: &mut Rng| {
            let origin = rng.vec(6.0).as_dvec3();
            // Some directions with a zero component, some segments of zero length.
            let mut direction = rng.vec(4.0).as_dvec3();
            match (rng.next() * 4.0) as u32 {
                0 => direction.y = 0.0,
                1 => direction = DVec3::ZERO,
                _ => {}
            }
            NearSegment::new(origin, direction, f64::from(rng.next()) * 0.5).unwrap()
        };
        let (mut met, mut missed) = (0, 0);
        for _ in 0..2000 {
            let lanes: [NearSegment; 4] = std::array::from_fn(|_| segment(&mut rng));
            let present = (rng.next() * 16.0) as u32;
            let four = NearSegments4::new(std::array::from_fn(|i| {
                (present >> i & 1 == 1).then_some(&lanes[i])
            }));
            let (c, half) = (rng.vec(3.0), rng.vec(3.0).abs());
            let mask = four.meets(c - half, c + half);
            for (i, lane) in lanes.iter().enumerate() {
                let alone = present >> i & 1 == 1 && lane.meets(c - half, c + half);
                assert_eq!(mask >> i & 1 == 1, alone, "lane {i}");
                if alone {
                    met += 1;
                } else {
                    missed += 1;
                }
            }
        }
        // Both outcomes occur often (about 5 % of the present lanes meet their box).
        assert!(met > 100 && missed > 1000, "{met} {missed}");
    }

    /// Without a bound, the ordered walk of four segments visits each lane's triangles
    /// exactly once each, and exactly those of the leaves a tree-order walk of the lane's
    /// segment alone meets (empty lanes: none); with a bound, a lane visits no triangle
    /// beyond it: after `visit` returns a bound of 0 for a lane, the lane sees only
    /// triangles of leaves its segment enters at its start.
    #[test]
    fn ordered_walks_visit_each_lane_s_leaves_and_stop_at_the_bound() {
        let mut rng = Rng(13);
        let (mut visits, mut bounded) = (0, 0);
        for n in [1, 40, 700] {
            let triangles = soup(&mut rng, n);
            let bvh = Bvh::build(&triangles);
            // The box of each stored triangle's leaf.
            let mut leaf_boxes =
                vec![(bvh.root_bounds.min, bvh.root_bounds.max); bvh.triangles.len()];
            for node in &bvh.nodes {
                for (k, child) in node.children.iter().enumerate() {
                    let first = child.index as usize;
                    leaf_boxes[first..first + child.count as usize].fill(node.child_box(k));
                }
            }
            for _ in 0..200 {
                let base = rng.vec(12.0).as_dvec3();
                let lanes: [NearSegment; 4] = std::array::from_fn(|_| {
                    let origin = base + rng.vec(1.0).as_dvec3();
                    NearSegment::new(origin, rng.vec(8.0).as_dvec3(), f64::from(rng.next()))
                        .unwrap()
                });
                let present = (rng.next() * 16.0) as u32;
                let four = NearSegments4::new(std::array::from_fn(|i| {
                    (present >> i & 1 == 1).then_some(&lanes[i])
                }));
                let mut seen: Vec<(usize, usize)> = Vec::new();
                bvh.visit_near_segments4(&four, |lane, stored| {
                    seen.push((lane, stored));
                    f32::MAX
                });
                seen.sort_unstable();
                let mut alone: Vec<(usize, usize)> = Vec::new();
                for (i, lane) in lanes
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| present >> i & 1 == 1)
                {
                    bvh.walk_leaves(
                        |min, max| lane.meets(min, max),
                        |leaf| {
                            let first = leaf.index as usize;
                            alone.extend((first..first + leaf.count as usize).map(|t| (i, t)));
                            false
                        },
                    );
                }
                // The root leaf of a one-triangle tree is entered by `walk_leaves` unasked.
                if bvh.root.count > 0 {
                    let root = bvh.root_bounds;
                    alone.retain(|&(i, _)| lanes[i].meets(root.min, root.max));
                }
                alone.sort_unstable();
                assert_eq!(seen, alone);
                visits += seen.len();
                // A bound of 0 after the first visit of each lane: what the lane sees
                // afterwards lies in leaves whose padded box its segment enters at its start.
                let mut stopped = [false; 4];
                bvh.visit_near_segments4(&four, |lane, stored| {
                    if stopped[lane] {
                        let (min, max) = leaf_boxes[stored];
                        let alone = NearSegments4::new([Some(&lanes[lane]), None, None, None]);
                        assert_eq!(alone.entries(min, max)[0], 0.0);
                        bounded += 1;
                    }
                    stopped[lane] = true;
                    0.0
                });
            }
        }
        assert!(visits > 1000 && bounded > 10, "{visits} {bounded}");
    }

    #[test]
    fn nodes_are_one_cache_line() {
        assert_eq!(std::mem::size_of::<Node>(), 64);
    }
}
