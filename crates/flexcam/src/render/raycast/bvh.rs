//! A bounding volume hierarchy over triangles: binned SAH build, flattened 32-byte nodes with
//! sibling pairs stored side by side, and near-first f32 traversal for closest-hit and any-hit
//! queries.

use glam::{Vec3, Vec3A, Vec4};

use super::triangle::{FastHit, FastRay, PackedTriangle};
use crate::geometry::Aabb;

/// A node: its bounds, and in the spare lanes either the index of its first child (children
/// are `first` and `first + 1`, `count == 0`) or the first of its `count` triangles (a leaf).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
struct Node {
    /// `xyz` = lower corner, `w` = bits of `first`.
    min: Vec4,
    /// `xyz` = upper corner, `w` = bits of `count`.
    max: Vec4,
}

impl Node {
    fn new(bounds: Aabb, first: u32, count: u32) -> Node {
        Node {
            min: bounds.min.extend(f32::from_bits(first)),
            max: bounds.max.extend(f32::from_bits(count)),
        }
    }

    #[inline(always)]
    fn first(&self) -> usize {
        self.min.w.to_bits() as usize
    }

    #[inline(always)]
    fn count(&self) -> usize {
        self.max.w.to_bits() as usize
    }

    /// Entry parameter of `ray` into the box if it meets it within `[ray.t_min, t_max]`, else
    /// infinity. The exit parameter is enlarged by a few ulps (Ize, "Robust BVH ray
    /// traversal", 2013) so that rounding never culls a box the ray touches.
    #[inline(always)]
    fn entry(&self, ray: &FastRay, t_max: f32) -> f32 {
        let t0 = (Vec3A::from_vec4(self.min) - ray.origin) * ray.inv_direction;
        let t1 = (Vec3A::from_vec4(self.max) - ray.origin) * ray.inv_direction;
        let near = t0.min(t1).max_element().max(ray.t_min);
        let far = t0.max(t1).min_element().min(t_max);
        if near <= far + far.abs() * ROBUST_SLACK {
            near
        } else {
            f32::INFINITY
        }
    }
}

/// `2 * gamma(3)` for f32 (Pharr et al., pbrt 3rd ed., 3.9.2): the relative error of a slab
/// test, by which the exit distance is enlarged.
const ROBUST_SLACK: f32 = 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);
/// Relative padding of stored boxes: covers the rounding of the triangles' precomputed edges,
/// so that a hit the triangle test reports never lies outside its leaf's box.
const BOX_PADDING: f32 = 1.0 / (1 << 20) as f32;
/// Largest leaf the SAH may choose.
const MAX_LEAF: usize = 4;
/// Bins per axis of the SAH sweep.
const BINS: usize = 16;
/// Cost of visiting an interior node, relative to one triangle test.
const TRAVERSAL_COST: f32 = 1.0;
/// Depth after which the build splits at the object median instead of by SAH. Median splits
/// halve the triangle count, so the tree is at most `SAH_DEPTH + 32` deep, which bounds the
/// traversal stack.
const SAH_DEPTH: usize = 32;
const STACK_SIZE: usize = SAH_DEPTH + 33;

/// A BVH over a set of triangles, each known by its index in the build input.
#[derive(Debug, Clone, Default)]
pub(super) struct Bvh {
    nodes: Vec<Node>,
    triangles: Vec<PackedTriangle>,
    /// Build-input index of each stored triangle.
    ids: Vec<u32>,
}

/// A closest or any hit: the build-input index of the triangle and where it was hit.
#[derive(Debug, Clone, Copy)]
pub(super) struct BvhHit {
    pub id: u32,
    pub hit: FastHit,
}

/// A pending build step: a node and its range of the triangle order.
struct Task {
    node: usize,
    start: usize,
    end: usize,
    depth: usize,
}

impl Bvh {
    /// Builds the hierarchy over `triangles`; zero-area triangles are left out (no ray can
    /// hit them face-on). An empty or all-degenerate input gives a BVH that nothing hits.
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        let mut prims = Vec::with_capacity(triangles.len());
        for (id, &[a, b, c]) in triangles.iter().enumerate() {
            if let Some(triangle) = PackedTriangle::new(a.into(), b.into(), c.into()) {
                let bounds = Aabb::from_points([a, b, c]);
                prims.push(Prim {
                    id: id as u32,
                    triangle,
                    bounds,
                    centroid: bounds.center(),
                });
            }
        }
        if prims.is_empty() {
            return Bvh::default();
        }
        let mut nodes = vec![Node::new(Aabb::EMPTY, 0, 0)];
        let mut tasks = vec![Task {
            node: 0,
            start: 0,
            end: prims.len(),
            depth: 0,
        }];
        while let Some(task) = tasks.pop() {
            let range = &mut prims[task.start..task.end];
            let bounds = range.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds));
            let padded = Aabb {
                min: bounds.min - bounds.min.abs() * BOX_PADDING,
                max: bounds.max + bounds.max.abs() * BOX_PADDING,
            };
            let Some(mid) = split(range, bounds, task.depth) else {
                nodes[task.node] = Node::new(padded, task.start as u32, range.len() as u32);
                continue;
            };
            let left = nodes.len();
            nodes[task.node] = Node::new(padded, left as u32, 0);
            nodes.push(Node::new(Aabb::EMPTY, 0, 0));
            nodes.push(Node::new(Aabb::EMPTY, 0, 0));
            let depth = task.depth + 1;
            let mid = task.start + mid;
            tasks.push(Task {
                node: left + 1,
                start: mid,
                end: task.end,
                depth,
            });
            tasks.push(Task {
                node: left,
                start: task.start,
                end: mid,
                depth,
            });
        }
        Bvh {
            nodes,
            triangles: prims.iter().map(|p| p.triangle).collect(),
            ids: prims.iter().map(|p| p.id).collect(),
        }
    }

    /// Number of nodes (interior and leaves).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The hit with the smallest `t` in the ray's interval, if any.
    pub fn closest(&self, ray: &FastRay) -> Option<BvhHit> {
        self.traverse::<false>(ray)
    }

    /// Whether anything is hit in the ray's interval (stops at the first hit found).
    pub fn occluded(&self, ray: &FastRay) -> bool {
        self.traverse::<true>(ray).is_some()
    }

    /// Near-first traversal: at an interior node both children's boxes are tested, the nearer
    /// is visited and the farther pushed with its entry distance, and popped nodes entered
    /// beyond the closest hit so far are skipped. With `ANY`, returns at the first hit.
    #[inline(always)]
    fn traverse<const ANY: bool>(&self, ray: &FastRay) -> Option<BvhHit> {
        let root = self.nodes.first()?;
        let mut t_max = ray.t_max;
        if root.entry(ray, t_max) == f32::INFINITY {
            return None;
        }
        let mut best: Option<(usize, FastHit)> = None;
        let mut stack = [(0u32, 0f32); STACK_SIZE];
        let mut depth = 0;
        let mut node = root;
        loop {
            let count = node.count();
            if count > 0 {
                let first = node.first();
                for (i, tri) in self.triangles[first..first + count].iter().enumerate() {
                    if let Some(hit) = tri.intersect(ray, t_max) {
                        t_max = hit.t;
                        best = Some((first + i, hit));
                        if ANY {
                            return self.finish(best);
                        }
                    }
                }
            } else {
                let first = node.first();
                let (mut near, mut far) = (first, first + 1);
                let mut t_near = self.nodes[near].entry(ray, t_max);
                let mut t_far = self.nodes[far].entry(ray, t_max);
                if t_far < t_near {
                    std::mem::swap(&mut near, &mut far);
                    std::mem::swap(&mut t_near, &mut t_far);
                }
                if t_near != f32::INFINITY {
                    if t_far != f32::INFINITY {
                        stack[depth] = (far as u32, t_far);
                        depth += 1;
                    }
                    node = &self.nodes[near];
                    continue;
                }
            }
            // Pop the nearest pending node still in front of the closest hit.
            loop {
                if depth == 0 {
                    return self.finish(best);
                }
                depth -= 1;
                let (index, t_entry) = stack[depth];
                if t_entry <= t_max {
                    node = &self.nodes[index as usize];
                    break;
                }
            }
        }
    }

    /// The hit at stored triangle `i`, known by its build-input index.
    fn finish(&self, best: Option<(usize, FastHit)>) -> Option<BvhHit> {
        best.map(|(i, hit)| BvhHit {
            id: self.ids[i],
            hit,
        })
    }
}

/// A triangle during the build.
#[derive(Debug, Clone, Copy)]
struct Prim {
    id: u32,
    triangle: PackedTriangle,
    bounds: Aabb,
    centroid: Vec3,
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
    let binning = Binning::new(centroids);
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
        for s in (1..BINS).rev() {
            acc = acc.merge(axis_bins[s]);
            right_cost[s] = acc.bounds.half_area() * acc.count as f32;
        }
        let mut left = Bin::EMPTY;
        for s in 1..BINS {
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

/// Maps centroids to SAH bins: the centroid bounds cut into [`BINS`] equal slices per axis.
struct Binning {
    min: Vec3,
    scale: Vec3,
}

impl Binning {
    fn new(centroids: Aabb) -> Binning {
        Binning {
            min: centroids.min,
            scale: BINS as f32 / centroids.extent(),
        }
    }

    /// The bin of `c` along `axis` (an axis of positive extent).
    fn bin(&self, c: Vec3, axis: usize) -> usize {
        (((c[axis] - self.min[axis]) * self.scale[axis]) as usize).min(BINS - 1)
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
        for n in [1, 2, 5, 40, 700] {
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
        assert!(bvh.nodes.iter().all(|n| n.count() <= MAX_LEAF));
    }

    #[test]
    fn nodes_are_32_bytes() {
        assert_eq!(std::mem::size_of::<Node>(), 32);
    }
}
