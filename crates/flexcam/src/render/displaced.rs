//! Displaced objects in the prepared scene: every base triangle of a displaced object is a
//! leaf of its own bounding volume hierarchy, bounded by its displacement shell, and traced
//! exactly through the min/max hierarchy of [`crate::displace::DisplacedTriangle`]; no
//! micro-triangle mesh is built (up to level 5 the displaced micro-vertices are kept, not
//! their triangles, normals, texture coordinates or a tree over them).
//!
//! The triangles of displaced objects are left out of the prepared scene's triangle BVH, so
//! that its f32 inner loop stays as it is; queries ([`PreparedScene::intersect`] and the
//! others) search both, the triangle BVH first, then this set up to the hit found there. The
//! set is a binary tree over the shells' boxes (binned surface-area-heuristic splits, leaves
//! of at most [`LEAF`] base triangles), searched in f64 front to back.
//! Memory per base triangle: its object and index, a share of the tree's boxes (about 80
//! bytes in all), its frame (96 bytes) and the kept f32 boxes of the top of its hierarchy
//! ([`DisplacedTriangle::kept_boxes`]: exact up to level 6, at most 341 boxes, 8,184 bytes,
//! from level 5 on), and up to level 5 its displaced micro-vertices in f64 (`(2^L + 1) (2^L +
//! 2) / 2` of 24 bytes: 13,464 bytes at level 5), which the hierarchy reads instead of
//! displacing them per ray, and shading reads (found by its place in scene order, 4
//! bytes), within a cap ([`KEPT_POINTS_BUDGET`]: base triangles past it are traced as above
//! level 5); above level 5 the micro-geometry below the kept boxes is recomputed per ray from
//! the mesh. Its
//! shell box is the exact world box of its micro-vertices, undisplaced and displaced, up to
//! level 6.
//!
//! The prepared scene's queries over this set are in `render::prepared::displaced_hits`.
//! A hit is reported on the base triangle, as any hit is: `triangle` is the base triangle,
//! `barycentric` the base-triangle weights of the hit point's place in the subdivision (the
//! micro-triangle's grid position blended by the micro-hit's barycentrics), so texture
//! coordinates and vertex colours are interpolated there exactly as micro-vertices carry
//! them (midpoint uvs are linear). Normals are the micro-triangle's face normal, used as both
//! geometric and shading normal: micro-vertex normals are those of the undisplaced surface
//! and would hide the displacement from lit shading.

use std::sync::{Arc, OnceLock};
use std::time::Instant;

use glam::DVec3;

use rayon::prelude::*;

use crate::displace::intersect::{enters_root, kept_point_bytes, KeptBoxes, StoredTriangle};
use crate::displace::{base_corners, CachedBox, DisplacedTriangle, Displacement, Frame, MicroHit};
use crate::geometry::Ray;
use crate::scene::{budget, Scene};

/// Most base triangles per leaf.
const LEAF: usize = 2;
/// Traversal stack size: more than the depth of a median-split tree over `u32` items.
const STACK: usize = 40;
/// Most bytes of kept displaced micro-vertices per set (also at most a quarter of the
/// memory budget, [`budget::max_memory`]): 19,937 base triangles at level 5.
pub const KEPT_POINTS_BUDGET: usize = 256 << 20;

mod lods;
mod tables;

pub use lods::LodSelection;
pub(in crate::render) use lods::Lods;
pub(in crate::render) use tables::{ObjectTables, Tables, PARTIAL_STEPS};

/// What the transition system reads of the displaced objects, built once per prepared
/// scene on its first transition render ([`DisplacedSet::transition_data`]): the tables of
/// normal distributions, BRDF and bump redistribution, and the levels of detail.
pub(in crate::render) struct TransitionData {
    pub tables: Tables,
    pub lods: Lods,
    /// Milliseconds it took to build.
    pub build_ms: f64,
}

impl std::fmt::Debug for TransitionData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TransitionData")
            .field("levels", &self.lods.levels.len())
            .field("build_ms", &self.build_ms)
            .finish_non_exhaustive()
    }
}

/// The displaced objects' base triangles and the tree over their shells.
#[derive(Debug)]
pub(in crate::render) struct DisplacedSet {
    /// Per object of the scene (by index): its displacement, if it has one.
    displacements: Vec<Option<Displacement>>,
    /// Base triangles in tree order.
    items: Vec<Item>,
    /// The kept node boxes of every item ([`DisplacedTriangle::kept_boxes`]).
    boxes: Vec<CachedBox>,
    /// Per object of the scene: where its base triangles start in `places`.
    first_shell: Vec<usize>,
    /// Per displaced base triangle in scene order (object, then triangle): its item's index.
    places: Vec<u32>,
    /// Depth-first: an interior node's first child follows it, `second` is the other.
    nodes: Vec<Node>,
    /// Per object: the union of its shells' boxes, if it is displaced.
    bounds: Vec<Option<[DVec3; 2]>>,
    /// Built on the first transition render; the views of a scene share it with the set.
    transition: OnceLock<TransitionData>,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: the first item; interior: the second child's node index.
    index: u32,
    /// Leaf: the number of items (at least 1); interior: 0.
    count: u32,
}

/// A displaced base triangle: object index, triangle index, the frame of its node boxes,
/// where its kept boxes are in [`DisplacedSet::boxes`], and its kept displaced micro-vertices
/// (up to level 5; empty above: [`KeptBoxes`]), in an allocation of their own as
/// `kept_boxes` made them, so that building the set never holds two copies.
#[derive(Debug, Clone)]
pub(in crate::render) struct Item {
    pub object: u32,
    pub triangle: u32,
    first_box: u32,
    box_count: u32,
    frame: Frame,
    points: Box<[DVec3]>,
}

/// A hit on a displaced base triangle.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct DisplacedHit {
    pub object: usize,
    pub triangle: usize,
    pub micro: MicroHit,
}

impl DisplacedSet {
    /// The set of `scene`'s displaced objects; `None` when it has none. Displaced
    /// micro-vertices are kept within [`KEPT_POINTS_BUDGET`] or a quarter of the memory
    /// budget, whichever is less ([`DisplacedSet::with_point_budget`]).
    pub fn new(scene: &Scene) -> Option<Arc<DisplacedSet>> {
        let budget = usize::try_from(budget::max_memory() / 4).unwrap_or(usize::MAX);
        DisplacedSet::with_point_budget(scene, KEPT_POINTS_BUDGET.min(budget))
    }

    /// [`DisplacedSet::new`] keeping the displaced micro-vertices of base triangles (levels
    /// up to 5: [`DisplacedTriangle::kept_boxes`]) in scene order while their total stays
    /// within `budget` bytes; the others are traced by displacing their micro-vertices per
    /// ray, as above level 5: the same hits, slower.
    pub fn with_point_budget(scene: &Scene, budget: usize) -> Option<Arc<DisplacedSet>> {
        let displacements: Vec<Option<Displacement>> = scene
            .objects
            .iter()
            .map(|o| o.displacement.as_deref().map(Displacement::from_spec))
            .collect();
        if displacements.iter().all(Option::is_none) {
            return None;
        }
        // Every displaced base triangle's shell, with its stored boxes, in scene order; the
        // tree is built over (shell index, box) and the shells are then laid out in its order.
        let mut shells = Vec::new();
        let mut boxed = Vec::new();
        let mut bounds = vec![None; scene.objects.len()];
        let mut first_shell = Vec::with_capacity(scene.objects.len());
        let mut budget_left = budget;
        for (index, (object, displacement)) in scene.objects.iter().zip(&displacements).enumerate()
        {
            first_shell.push(shells.len());
            let Some(displacement) = displacement else {
                continue;
            };
            // The first `with_points` base triangles keep their micro-vertices (the budget).
            let count = object.mesh.triangles.len();
            let with_points = match kept_point_bytes(displacement.level()) {
                0 => 0,
                bytes => count.min(budget_left / bytes),
            };
            budget_left -= with_points * kept_point_bytes(displacement.level());
            // Each base triangle's boxes are its own (exact ones displace every micro-vertex
            // once): built in parallel, kept in scene order.
            let kept: Vec<_> = (0..count)
                .into_par_iter()
                .map(|triangle| {
                    let shell =
                        DisplacedTriangle::new(base_corners(&object.mesh, triangle), displacement);
                    let mut kept = shell.kept_boxes();
                    if triangle >= with_points {
                        kept.points = Vec::new();
                    }
                    (triangle, shell.frame(), kept)
                })
                .collect();
            for (
                triangle,
                frame,
                KeptBoxes {
                    boxes,
                    bounds: [lo, hi],
                    points,
                },
            ) in kept
            {
                let bound = bounds[index].get_or_insert([DVec3::INFINITY, DVec3::NEG_INFINITY]);
                *bound = [bound[0].min(lo), bound[1].max(hi)];
                boxed.push(([shells.len() as u32, 0], lo, hi));
                shells.push(([index as u32, triangle as u32], frame, boxes, points));
            }
        }
        let mut nodes = Vec::with_capacity(2 * boxed.len() / LEAF + 1);
        if !boxed.is_empty() {
            build(&mut boxed, 0, 0, &mut nodes);
        }
        let mut items = Vec::with_capacity(boxed.len());
        let mut boxes = Vec::new();
        let mut places = vec![0; shells.len()];
        for ([shell, _], _, _) in boxed {
            places[shell as usize] = items.len() as u32;
            let ([object, triangle], frame, top, micro) = &mut shells[shell as usize];
            items.push(Item {
                object: *object,
                triangle: *triangle,
                first_box: boxes.len() as u32,
                box_count: top.len() as u32,
                frame: *frame,
                points: std::mem::take(micro).into_boxed_slice(),
            });
            boxes.extend_from_slice(top);
        }
        Some(Arc::new(DisplacedSet {
            displacements,
            items,
            boxes,
            first_shell,
            places,
            nodes,
            bounds,
            transition: OnceLock::new(),
        }))
    }

    /// The transition system's tables and levels of detail for `scene` (the scene this set
    /// was built from), built on first use (module [`tables`], [`lods`]).
    pub fn transition_data(&self, scene: &Scene) -> &TransitionData {
        self.transition.get_or_init(|| {
            let start = Instant::now();
            let tables = Tables::new(scene, self);
            let lods = Lods::new(scene, self);
            TransitionData {
                tables,
                lods,
                build_ms: start.elapsed().as_secs_f64() * 1e3,
            }
        })
    }

    /// The union of the shell boxes of object `object`'s base triangles; `None` when it is
    /// not displaced.
    pub fn object_bound(&self, object: usize) -> Option<[DVec3; 2]> {
        self.bounds[object]
    }

    /// Number of displaced base triangles.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// The displacement of object `object`, if it is displaced.
    pub fn displacement(&self, object: usize) -> Option<&Displacement> {
        self.displacements[object].as_ref()
    }

    /// Base triangle `triangle` of object `object` (displaced) with its displacement (the
    /// object's, [`DisplacedSet::displacement`]), with the frame, boxes and micro-vertices
    /// the set keeps of it, as its queries trace it (the same hits and positions as without
    /// them, read rather than computed).
    pub fn triangle<'a>(
        &'a self,
        scene: &Scene,
        object: usize,
        triangle: usize,
        displacement: &'a Displacement,
    ) -> DisplacedTriangle<'a> {
        let corners = base_corners(&scene.objects[object].mesh, triangle);
        let item = self
            .first_shell
            .get(object)
            .and_then(|first| self.places.get(first + triangle))
            .and_then(|&place| self.items.get(place as usize))
            .filter(|item| (item.object, item.triangle) == (object as u32, triangle as u32));
        match item {
            Some(item) => DisplacedTriangle::with_boxes(
                corners,
                displacement,
                item.frame,
                self.item_boxes(item),
                &item.points,
            ),
            None => DisplacedTriangle::new(corners, displacement),
        }
    }

    /// The kept node boxes of `item`.
    fn item_boxes(&self, item: &Item) -> &[CachedBox] {
        &self.boxes[item.first_box as usize..(item.first_box + item.box_count) as usize]
    }

    /// The nearest micro-triangle hit of `ray` with `t` in `[ray.t_min, min(ray.t_max,
    /// limit)]`; on equal `t`, the lower object, then the lower base triangle. With `any`,
    /// the first hit found.
    pub fn closest(&self, scene: &Scene, ray: &Ray, limit: f64, any: bool) -> Option<DisplacedHit> {
        self.closest_by(ray, limit, any, |item, displacement, bounded| {
            let boxes = self.item_boxes(item);
            let entry = enters_root(&item.frame, &boxes[0], bounded)?;
            // Kept micro-vertices need neither the corners nor the displacement.
            let micro = match StoredTriangle::new(displacement.level(), boxes, &item.points) {
                Some(stored) => stored.intersect_entered(bounded, &entry, any),
                None => DisplacedTriangle::with_boxes(
                    base_corners(
                        &scene.objects[item.object as usize].mesh,
                        item.triangle as usize,
                    ),
                    displacement,
                    item.frame,
                    boxes,
                    &item.points,
                )
                .intersect_entered(bounded, &entry, any),
            }?;
            Some((micro.t, micro))
        })
        .map(|(object, triangle, micro)| DisplacedHit {
            object,
            triangle,
            micro,
        })
    }

    /// The nearest hit of `ray` with `t` in `[ray.t_min, min(ray.t_max, limit)]` that `test`
    /// finds on the base triangles whose shell boxes the ray enters: `test(item, its
    /// object's displacement, the ray bounded by the best hit so far)` gives `(t, what)`.
    /// On equal `t`, the lower object, then the lower base triangle; with `any`, the first
    /// hit found. Every shell box bounds its base triangle displaced by any fraction from 0
    /// to the object's (the offsets `S * (h - h_max) * F * s` lie between 0 and the full
    /// ones), so `test` may trace the undisplaced or a partly displaced surface.
    pub fn closest_by<H: Copy>(
        &self,
        ray: &Ray,
        limit: f64,
        any: bool,
        test: impl Fn(&Item, &Displacement, &Ray) -> Option<(f64, H)>,
    ) -> Option<(usize, usize, H)> {
        let slabs = Slabs::new(ray)?;
        let mut t_max = ray.t_max.min(limit);
        let mut best: Option<(f64, usize, usize, H)> = None;
        // At most one pending node per level; median splits keep the tree under 40 deep.
        let mut stack = [(0u32, 0.0f64); STACK];
        let mut depth = 0;
        let root = self.nodes.first()?;
        slabs.entry(root, ray.t_min, t_max)?;
        let mut current = 0u32;
        loop {
            let node = self.nodes[current as usize];
            if node.count > 0 {
                for item in &self.items[node.index as usize..(node.index + node.count) as usize] {
                    let (object, triangle) = (item.object as usize, item.triangle as usize);
                    let Some(displacement) = self.displacement(object) else {
                        continue;
                    };
                    let bounded = Ray { t_max, ..*ray };
                    if let Some((t, found)) = test(item, displacement, &bounded) {
                        let better = best.is_none_or(|(b, bo, bt, _)| {
                            t < b || (t == b && (object, triangle) < (bo, bt))
                        });
                        if better {
                            t_max = t;
                            best = Some((t, object, triangle, found));
                            if any {
                                return best.map(|(_, o, tr, f)| (o, tr, f));
                            }
                        }
                    }
                }
            } else {
                let (a, b) = (current + 1, node.index);
                let ea = slabs.entry(&self.nodes[a as usize], ray.t_min, t_max);
                let eb = slabs.entry(&self.nodes[b as usize], ray.t_min, t_max);
                // The nearer child next, the other pending with its entry distance.
                let next = match (ea, eb) {
                    (Some(x), Some(y)) => {
                        let (near, far, far_entry) = if y < x { (b, a, x) } else { (a, b, y) };
                        stack[depth] = (far, far_entry);
                        depth += 1;
                        Some(near)
                    }
                    (Some(_), None) => Some(a),
                    (None, Some(_)) => Some(b),
                    (None, None) => None,
                };
                if let Some(next) = next {
                    current = next;
                    continue;
                }
            }
            // Ties with the best hit stay: an equal t may win on the triangle order.
            loop {
                if depth == 0 {
                    return best.map(|(_, o, tr, f)| (o, tr, f));
                }
                depth -= 1;
                let (node, entry) = stack[depth];
                if entry <= t_max {
                    current = node;
                    break;
                }
            }
        }
    }

    /// Whether any shell box overlaps the box `[lo, hi]`.
    pub fn overlaps(&self, lo: DVec3, hi: DVec3) -> bool {
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let Some(node) = self.nodes.get(i as usize) else {
                return false;
            };
            if node.lo.cmpgt(hi).any() || node.hi.cmplt(lo).any() {
                continue;
            }
            if node.count > 0 {
                return true;
            }
            stack.extend([i + 1, node.index]);
        }
        false
    }
}

/// Builds the subtree over `items` (stored from item `offset` on, at tree depth `depth`),
/// appending its nodes: binned surface-area-heuristic splits ([`sah_split`]), or the median
/// of the box centres along their widest axis where the heuristic finds none or the tree is
/// [`SAH_DEPTH`] deep (median splits halve the count, so the tree stays under [`STACK`]
/// deep).
fn build(
    items: &mut [([u32; 2], DVec3, DVec3)],
    offset: usize,
    depth: usize,
    nodes: &mut Vec<Node>,
) {
    let (lo, hi) = items.iter().fold(
        (DVec3::INFINITY, DVec3::NEG_INFINITY),
        |(lo, hi), &(_, a, b)| (lo.min(a), hi.max(b)),
    );
    let slot = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        index: offset as u32,
        count: items.len() as u32,
    });
    if items.len() <= LEAF {
        return;
    }
    let (c_lo, c_hi) = items.iter().fold(
        (DVec3::INFINITY, DVec3::NEG_INFINITY),
        |(lo, hi), &(_, a, b)| {
            let c = (a + b) * 0.5;
            (lo.min(c), hi.max(c))
        },
    );
    let mid = match (depth < SAH_DEPTH)
        .then(|| sah_split(items, c_lo, c_hi))
        .flatten()
    {
        Some(mid) => mid,
        None => {
            let extent = c_hi - c_lo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = items.len() / 2;
            items.select_nth_unstable_by(mid, |p, q| {
                let (cp, cq) = (p.1[axis] + p.2[axis], q.1[axis] + q.2[axis]);
                cp.total_cmp(&cq).then(p.0.cmp(&q.0))
            });
            mid
        }
    };
    let (left, right) = items.split_at_mut(mid);
    build(left, offset, depth + 1, nodes);
    let second = nodes.len() as u32;
    build(right, offset + mid, depth + 1, nodes);
    nodes[slot].index = second;
    nodes[slot].count = 0;
}

/// Depth below which [`build`] splits by the surface area heuristic.
const SAH_DEPTH: usize = 20;
/// Bins per axis of [`sah_split`].
const BINS: usize = 16;

/// Half the surface area of the box `[lo, hi]` (0 for an empty one).
fn half_area(lo: DVec3, hi: DVec3) -> f64 {
    let d = (hi - lo).max(DVec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// The binned surface-area-heuristic split of `items` (box centres within `[c_lo, c_hi]`):
/// over [`BINS`] bins of the centres along each axis, the boundary that minimises the sum
/// over both sides of box area times count. Partitions `items` (stably ordered by their
/// index within each side) and returns the size of the first side; `None` when every centre
/// falls in one bin on every axis.
fn sah_split(items: &mut [([u32; 2], DVec3, DVec3)], c_lo: DVec3, c_hi: DVec3) -> Option<usize> {
    let extent = c_hi - c_lo;
    let bin = |item: &([u32; 2], DVec3, DVec3), axis: usize| -> usize {
        let c = (item.1[axis] + item.2[axis]) * 0.5;
        let x = (c - c_lo[axis]) / extent[axis] * BINS as f64;
        (x as usize).min(BINS - 1)
    };
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        if extent[axis].is_nan() || extent[axis] <= 0.0 {
            continue;
        }
        let mut counts = [0usize; BINS];
        let mut boxes = [(DVec3::INFINITY, DVec3::NEG_INFINITY); BINS];
        for item in items.iter() {
            let b = bin(item, axis);
            counts[b] += 1;
            boxes[b] = (boxes[b].0.min(item.1), boxes[b].1.max(item.2));
        }
        // Cost of the left side of each boundary, accumulated from the left.
        let mut left = [0.0f64; BINS];
        let (mut lo, mut hi, mut n) = (DVec3::INFINITY, DVec3::NEG_INFINITY, 0);
        for ((cost, &(b_lo, b_hi)), &count) in left.iter_mut().zip(&boxes).zip(&counts) {
            (lo, hi, n) = (lo.min(b_lo), hi.max(b_hi), n + count);
            *cost = half_area(lo, hi) * n as f64;
        }
        let (mut lo, mut hi, mut n) = (DVec3::INFINITY, DVec3::NEG_INFINITY, 0);
        for k in (1..BINS).rev() {
            (lo, hi, n) = (lo.min(boxes[k].0), hi.max(boxes[k].1), n + counts[k]);
            let cost = left[k - 1] + half_area(lo, hi) * n as f64;
            if n > 0 && n < items.len() && best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, k));
            }
        }
    }
    let (_, axis, boundary) = best?;
    items.sort_by_key(|item| (bin(item, axis) >= boundary, item.0));
    Some(items.partition_point(|item| bin(item, axis) < boundary))
}

/// A ray's slab-test constants in f64.
struct Slabs {
    origin: DVec3,
    inv: DVec3,
    /// Whether a direction component is zero (its reciprocal infinite).
    axis_parallel: bool,
}

impl Slabs {
    fn new(ray: &Ray) -> Option<Slabs> {
        let valid = ray.origin.is_finite()
            && ray.direction.is_finite()
            && ray.direction != DVec3::ZERO
            && ray.t_min <= ray.t_max;
        let inv = ray.direction.recip();
        valid.then(|| Slabs {
            origin: ray.origin,
            inv,
            axis_parallel: !inv.is_finite(),
        })
    }

    /// Where the ray enters the node's box within `[t_min, t_max]`, if it does. The boxes
    /// already hold their shells' rounding allowance; a zero direction component gives an
    /// infinite reciprocal, and the origin test by the sign of the NaN-free products.
    #[inline]
    fn entry(&self, node: &Node, t_min: f64, t_max: f64) -> Option<f64> {
        if self.axis_parallel {
            return self.entry_axis_parallel(node, t_min, t_max);
        }
        // No zero direction component: every product is finite, and the maxima and minima
        // over the axes are those of the per-axis loop below, bit for bit.
        let t0 = (node.lo - self.origin) * self.inv;
        let t1 = (node.hi - self.origin) * self.inv;
        let near = t0.min(t1).max_element().max(t_min);
        let far = t0.max(t1).min_element().min(t_max);
        let slack = 1e-12 * far.abs().max(near.abs());
        (near <= far + slack).then_some(near)
    }

    /// [`Slabs::entry`] for a ray with a zero direction component.
    fn entry_axis_parallel(&self, node: &Node, t_min: f64, t_max: f64) -> Option<f64> {
        let mut near = t_min;
        let mut far = t_max;
        for k in 0..3 {
            let (o, inv) = (self.origin[k], self.inv[k]);
            if inv.is_infinite() {
                if o < node.lo[k] || o > node.hi[k] {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((node.lo[k] - o) * inv, (node.hi[k] - o) * inv);
            near = near.max(t0.min(t1));
            far = far.min(t0.max(t1));
        }
        let slack = 1e-12 * far.abs().max(near.abs());
        (near <= far + slack).then_some(near)
    }
}

#[cfg(test)]
mod tests;
