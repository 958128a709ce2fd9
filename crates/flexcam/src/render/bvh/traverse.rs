//! Queries on a built [`Bvh`]: near-first closest-hit and any-hit traversal of one ray, a
//! packet traversal of four coherent rays that finds exactly the single-ray hits, and ordered
//! walks of four padded segments for the curve tracer. Every box test is a slab test whose
//! exit distance is enlarged by the f32 rounding bound, so that no box a ray touches is culled.

use std::mem::MaybeUninit;

use glam::{BVec4A, Vec3, Vec3A, Vec4, Vec4Swizzles};

use super::triangle::{FastHit, FastRay};
use super::{Bvh, BvhHit, Child, Keep, Node, STACK_SIZE};
use crate::geometry::Aabb;

impl Node {
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
pub(super) fn same_signs(rays: [&FastRay; 4]) -> bool {
    let mask = |r: &FastRay| r.inv_direction.cmplt(Vec3A::ZERO).bitmask();
    let m = mask(rays[0]);
    rays[1..].iter().all(|r| mask(r) == m)
}

/// Four rays of one direction-sign class in SoA form for [`Packet::entries`]: lane `r` is
/// ray `r`.
pub(super) struct Packet {
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
    pub(super) fn new(rays: [&FastRay; 4]) -> Packet {
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

    /// Entry parameters of the four rays into the box `[min, max]` (infinity where a ray
    /// misses it within `[t_min, t_max]`), bit for bit [`box_entry`] of each ray, by the
    /// arithmetic of [`Packet::entries`].
    #[inline(always)]
    pub(super) fn box_entries(&self, min: Vec3, max: Vec3, t_max: Vec4) -> Vec4 {
        let mut near = self.t_min;
        let mut far = t_max;
        for axis in 0..3 {
            let (n, f) = if self.negative[axis] {
                (max[axis], min[axis])
            } else {
                (min[axis], max[axis])
            };
            let o = self.origin[axis];
            let inv = self.inv_direction[axis];
            near = near.max((Vec4::splat(n) - o) * inv);
            far = far.min((Vec4::splat(f) - o) * inv);
        }
        let inside = near.cmple(far + far.abs() * ROBUST_SLACK);
        Vec4::select(inside, near, Vec4::INFINITY)
    }

    /// Entry parameters of the four rays into the two children's boxes of `node` (infinity
    /// where a ray misses a box within `[t_min, t_max]`), bit for bit those of [`box_entry`]
    /// (and so of [`Node::entries`]) for each ray: `(plane - origin) * inv_direction` with
    /// the near plane the min plane for a positive direction, the max plane for a negative.
    #[inline(always)]
    fn entries(&self, node: &Node, t_max: Vec4) -> (Vec4, Vec4) {
        let child = |c: usize| {
            let [x, y, z] = node.planes;
            let min = Vec3::new(x[c], y[c], z[c]);
            let max = Vec3::new(-x[c + 2], -y[c + 2], -z[c + 2]);
            self.box_entries(min, max, t_max)
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
    pub(super) fn meets(&self, min: Vec3, max: Vec3) -> bool {
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
    pub(super) fn entries(&self, min: Vec3, max: Vec3) -> Vec4 {
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
    pub(super) fn meets(&self, min: Vec3, max: Vec3) -> u32 {
        self.entries(min, max).cmpne(Vec4::INFINITY).bitmask()
    }
}

/// The children's entry distances `t0`, `t1` (one ray's or a packet's) with a child that
/// holds no kept triangle ([`Keep::kept_children`] bits `kept`) given the distance `missed`
/// (infinity), as if its box were missed.
#[inline(always)]
fn skip_hidden<E: Copy>(kept: u8, (t0, t1): (E, E), missed: E) -> (E, E) {
    (
        if kept & 1 != 0 { t0 } else { missed },
        if kept & 2 != 0 { t1 } else { missed },
    )
}

/// Entry parameter of `ray` into the box `[min, max]` if it meets it within
/// `[ray.t_min, t_max]`, else infinity. The exit parameter is enlarged by a few ulps (Ize,
/// "Robust BVH ray traversal", 2013) so that rounding never culls a box the ray touches.
#[inline(always)]
pub(super) fn box_entry(bounds: &Aabb, ray: &FastRay, t_max: f32) -> f32 {
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
/// Relative margin of [`Bvh::root_overlaps`]: 100 times the f32 rounding of a coordinate.
const ROOT_MARGIN: f64 = 1e-5;

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

impl Bvh {
    /// The hit with the smallest `t` in the ray's interval among the triangles `keep` keeps,
    /// if any.
    pub fn closest<K: Keep>(&self, ray: &FastRay, keep: &K) -> Option<BvhHit> {
        self.traverse::<false, K>(ray, keep)
    }

    /// Whether a triangle `keep` keeps is hit in the ray's interval (stops at the first hit
    /// found).
    pub fn occluded<K: Keep>(&self, ray: &FastRay, keep: &K) -> bool {
        self.traverse::<true, K>(ray, keep).is_some()
    }

    /// Near-first traversal: at an interior node both children's boxes are tested at once,
    /// the nearer is visited and the farther pushed with its entry distance, and popped nodes
    /// entered beyond the closest hit so far are skipped. With `ANY`, returns at the first hit.
    /// A hit on a triangle `keep` leaves out is ignored (tested after the intersection, which
    /// rarely succeeds, so the unmasked [`AllTriangles`](super::AllTriangles) costs nothing).
    #[inline(always)]
    fn traverse<const ANY: bool, K: Keep>(&self, ray: &FastRay, keep: &K) -> Option<BvhHit> {
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
                        if !keep.keeps(first + i) {
                            continue;
                        }
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
                let kept = keep.kept_children(current.index as usize);
                let (t0, t1) = skip_hidden(kept, node.entries(&slabs, t_max), f32::INFINITY);
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
    pub fn closest4<K: Keep>(&self, rays: [Option<&FastRay>; 4], keep: &K) -> [Option<BvhHit>; 4] {
        self.packet::<false, K>(rays, keep)
    }

    /// Whether each of four rays hits a triangle `keep` keeps in its interval, exactly as
    /// [`Bvh::occluded`] answers ray by ray, by one traversal shared by the four (a ray
    /// drops out at its first hit): four coherent shadow rays (a 2x2 quad's, towards one
    /// light). Traced one by one as for [`Bvh::closest4`].
    pub fn occluded4<K: Keep>(&self, rays: [Option<&FastRay>; 4], keep: &K) -> [bool; 4] {
        let hits = self.packet::<true, K>(rays, keep);
        // Spelled out: `array::map` is not inlined here.
        [
            hits[0].is_some(),
            hits[1].is_some(),
            hits[2].is_some(),
            hits[3].is_some(),
        ]
    }

    /// [`Bvh::closest4`] or, with `ANY`, [`Bvh::occluded4`]'s hits: one packet traversal
    /// when the four rays are present and agree in their direction signs, else ray by ray.
    #[inline(always)]
    fn packet<const ANY: bool, K: Keep>(
        &self,
        rays: [Option<&FastRay>; 4],
        keep: &K,
    ) -> [Option<BvhHit>; 4] {
        match rays {
            [Some(a), Some(b), Some(c), Some(d)] if same_signs([a, b, c, d]) => {
                self.traverse4::<ANY, K>([a, b, c, d], keep)
            }
            [a, b, c, d] => {
                let single = |r: Option<&FastRay>| r.and_then(|r| self.traverse::<ANY, K>(r, keep));
                [single(a), single(b), single(c), single(d)]
            }
        }
    }

    /// The packet traversal of [`Bvh::closest4`]. The result per ray is the minimum of
    /// `(t, stored index)` over the triangles it hits, as for [`Bvh::traverse`]: a ray's
    /// winning leaf is always visited (its boxes pass the same slab test, at a `t_max` no
    /// smaller than the winning `t`), and which other leaves are visited, or in what order,
    /// does not change that minimum.
    ///
    /// With `ANY` a ray stops at its first hit, and the traversal when all four have one:
    /// whether a ray hits anything does not depend on which leaves the others open, since
    /// every leaf holding a triangle it hits is one it enters. A finished lane's `t_max`
    /// becomes minus infinity, so it enters no box and no leaf after (its far bound is
    /// minus infinity, or NaN once the slack is added, and no entry compares below either).
    #[inline(always)]
    fn traverse4<const ANY: bool, K: Keep>(
        &self,
        rays: [&FastRay; 4],
        keep: &K,
    ) -> [Option<BvhHit>; 4] {
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
                            if !keep.keeps(first + i) {
                                continue;
                            }
                            if hit.t < t_max_lanes[r] || first + i < best_index[r] {
                                t_max_lanes[r] = hit.t;
                                best[r] = Some((first + i, hit));
                                best_index[r] = first + i;
                            }
                            if ANY {
                                t_max_lanes[r] = f32::NEG_INFINITY;
                                break;
                            }
                        }
                    }
                }
                t_max = Vec4::from_array(t_max_lanes);
                if ANY && best.iter().all(Option::is_some) {
                    return best.map(|b| self.finish(b));
                }
            } else {
                let node = &self.nodes[current.index as usize];
                let kept = keep.kept_children(current.index as usize);
                let (t0, t1) = skip_hidden(kept, packet.entries(node, t_max), Vec4::INFINITY);
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
    pub(super) fn walk_leaves(
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
