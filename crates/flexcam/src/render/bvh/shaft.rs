//! Shaft culling (Haines and Wallace, "Shaft culling for efficient ray-cast radiosity",
//! 1991) for coherent shadow rays: the rays of a tile of pixels towards one light start in
//! one box and end at the light (or run along one direction), so they all lie in the convex
//! hull of that box and the light, the shaft. One walk of the tree finds the leaves whose
//! boxes the shaft meets ([`Bvh::shaft_leaves`]); each ray then tests only those leaves
//! ([`Bvh::occluded_among`]), for most of a floor none at all.
//!
//! Exactness: [`Bvh::occluded_among`] answers as the packet walk of [`Bvh::occluded4`] does,
//! ray by ray. That walk lets a ray test a leaf's triangles when the ray's slab test of the
//! leaf's box (made by the leaf's parent node) gives an entry within the ray's interval;
//! the boxes of a node's ancestors contain its box, and the slab test is monotone in the
//! box (rounding is monotone), so the ancestors then accept the ray too. The shaft keeps
//! every leaf whose box, enlarged by a margin far above f32 rounding (as
//! [`Bvh::root_overlaps`]), the hull meets; a ray in the shaft whose slab test accepts a
//! box passes within that margin of it, so its leaf is kept, and the ray then makes the
//! same slab test and the same triangle tests as the walk.

use glam::{DVec2, DVec3, Vec3, Vec4};

use super::traverse::{box_entry, same_signs, Packet, Slabs, ROOT_MARGIN};
use super::triangle::FastRay;
use super::{Bvh, Child, Keep};

/// Where the rays of a shaft end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::render) enum ShaftEnd {
    /// Within the box `[min, max]` (the reach of segments towards a point light).
    Box(DVec3, DVec3),
    /// Nowhere: the rays run on along this direction (towards a directional light).
    Direction(DVec3),
}

/// At most this many leaves are listed for one shaft: past them the rays' own walks are the
/// cheaper query ([`Bvh::shaft_leaves`] gives `None`).
pub(in crate::render) const MAX_SHAFT_LEAVES: usize = 4;

/// The projections on the planes of two axes, each with the third axis.
const AXIS_PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

/// A convex region holding every ray of a tile: the box of the rays' origins joined to
/// where they end, as a box and a set of half-spaces `normal . x <= offset`.
#[derive(Debug, Clone)]
pub(in crate::render) struct Shaft {
    min: DVec3,
    max: DVec3,
    planes: [(DVec3, f64); 12],
    count: usize,
    /// By how much a tested box is enlarged on every side.
    margin: f64,
}

impl Shaft {
    /// The shaft of rays starting in the box `[min, max]` and ending as `end` says, for a
    /// tree whose coordinates reach `scale` in magnitude. `None` when a coordinate is not
    /// finite or the box is empty (`min > max` on some axis).
    pub fn new(min: DVec3, max: DVec3, end: ShaftEnd, scale: f64) -> Option<Shaft> {
        let finite = match end {
            ShaftEnd::Box(lo, hi) => lo.is_finite() && hi.is_finite() && lo.cmple(hi).all(),
            ShaftEnd::Direction(d) => d.is_finite(),
        };
        if !(finite && min.is_finite() && max.is_finite() && min.cmple(max).all()) {
            return None;
        }
        let corners = |lo: DVec3, hi: DVec3, (i, j): (usize, usize)| {
            [
                DVec2::new(lo[i], lo[j]),
                DVec2::new(hi[i], lo[j]),
                DVec2::new(lo[i], hi[j]),
                DVec2::new(hi[i], hi[j]),
            ]
        };
        let mut magnitude = scale.max(min.abs().max(max.abs()).max_element());
        let mut shaft = Shaft {
            min,
            max,
            planes: [(DVec3::ZERO, 0.0); 12],
            count: 0,
            margin: 0.0,
        };
        match end {
            ShaftEnd::Box(lo, hi) => {
                magnitude = magnitude.max(lo.abs().max(hi.abs()).max_element());
                (shaft.min, shaft.max) = (min.min(lo), max.max(hi));
                // Lines through matching corners of the two rectangles that every corner
                // lies on one side of: the projected hull's edges (Haines and Wallace).
                for pair in AXIS_PAIRS {
                    let (from, to) = (corners(min, max, pair), corners(lo, hi, pair));
                    let mut all = [DVec2::ZERO; 8];
                    all[..4].copy_from_slice(&from);
                    all[4..].copy_from_slice(&to);
                    for (a, b) in from.into_iter().zip(to) {
                        shaft.add_support(pair, a, b - a, &all);
                    }
                }
            }
            ShaftEnd::Direction(d) => {
                for axis in 0..3 {
                    if d[axis] > 0.0 {
                        shaft.max[axis] = f64::INFINITY;
                    } else if d[axis] < 0.0 {
                        shaft.min[axis] = f64::NEG_INFINITY;
                    }
                }
                // Lines along the projected direction through the corners of the origins'
                // rectangle: the swept rectangle's edges.
                for pair in AXIS_PAIRS {
                    let from = corners(min, max, pair);
                    let along = DVec2::new(d[pair.0], d[pair.1]);
                    for a in from {
                        shaft.add_support(pair, a, along, &from);
                    }
                }
            }
        }
        shaft.margin = ROOT_MARGIN * magnitude;
        Some(shaft)
    }

    /// Adds the half-space bounded by the line through `a` along `along` in the plane of the
    /// axes `pair` (extruded along the third) when every point of `points` lies on one side
    /// of it: its offset is the largest of theirs, so it holds them whatever the rounding.
    fn add_support(&mut self, (i, j): (usize, usize), a: DVec2, along: DVec2, points: &[DVec2]) {
        if along == DVec2::ZERO || self.count == self.planes.len() {
            return;
        }
        let normal = along.perp();
        let at_a = normal.dot(a);
        let tolerance = 1e-12 * normal.length() * (a.abs().max_element() + along.length());
        let side = |sign: f64| {
            points
                .iter()
                .all(|p| sign * (normal.dot(*p) - at_a) <= tolerance)
        };
        let sign = if side(1.0) {
            1.0
        } else if side(-1.0) {
            -1.0
        } else {
            return;
        };
        let normal = normal * sign;
        let offset = points
            .iter()
            .map(|p| normal.dot(*p))
            .fold(f64::NEG_INFINITY, f64::max);
        let mut normal3 = DVec3::ZERO;
        (normal3[i], normal3[j]) = (normal.x, normal.y);
        self.planes[self.count] = (normal3, offset);
        self.count += 1;
    }

    /// Whether the box `[min, max]`, enlarged by the margin, lies outside the shaft (wholly
    /// beyond its box or one of its planes). A NaN coordinate rejects nothing.
    pub fn misses(&self, min: Vec3, max: Vec3) -> bool {
        let margin = DVec3::splat(self.margin);
        let (lo, hi) = (min.as_dvec3() - margin, max.as_dvec3() + margin);
        if lo.cmpgt(self.max).any() || hi.cmplt(self.min).any() {
            return true;
        }
        self.planes[..self.count].iter().any(|&(normal, offset)| {
            // The box's corner least far along the normal.
            let nearest = DVec3::select(normal.cmpge(DVec3::ZERO), lo, hi);
            normal.dot(nearest) > offset
        })
    }
}

/// The leaves of a tree a [`Shaft`] meets, each with the parent node whose slab test
/// opens it (none for a tree that is one leaf) and which of its two children it is.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct ShaftLeaves {
    leaves: [(Option<u32>, usize, Child); MAX_SHAFT_LEAVES],
    count: usize,
}

impl ShaftLeaves {
    /// How many leaves are listed.
    pub fn len(&self) -> usize {
        self.count
    }

    fn push(&mut self, leaf: (Option<u32>, usize, Child)) -> Option<()> {
        *self.leaves.get_mut(self.count)? = leaf;
        self.count += 1;
        Some(())
    }
}

impl Bvh {
    /// The leaves whose boxes the shaft of rays starting in `[min, max]` and ending as `end`
    /// says meets ([`Shaft::new`]), in tree order; `None` when there are more than
    /// [`MAX_SHAFT_LEAVES`] or the shaft has no finite bounds.
    pub fn shaft_leaves(&self, min: DVec3, max: DVec3, end: ShaftEnd) -> Option<ShaftLeaves> {
        let shaft = Shaft::new(min, max, end, self.root_scale)?;
        let mut out = ShaftLeaves {
            leaves: [(None, 0, self.root); MAX_SHAFT_LEAVES],
            count: 0,
        };
        if self.triangles.is_empty() || shaft.misses(self.root_bounds.min, self.root_bounds.max) {
            return Some(out);
        }
        if self.root.count > 0 {
            out.push((None, 0, self.root))?;
            return Some(out);
        }
        let mut stack = [0u32; super::STACK_SIZE];
        stack[0] = self.root.index;
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let parent = stack[depth];
            let node = &self.nodes[parent as usize];
            for k in 0..2 {
                let (min, max) = node.child_box(k);
                if shaft.misses(min, max) {
                    continue;
                }
                let child = node.children[k];
                if child.count > 0 {
                    out.push((Some(parent), k, child))?;
                } else {
                    stack[depth] = child.index;
                    depth += 1;
                }
            }
        }
        Some(out)
    }

    /// Whether `ray`, which lies in the shaft that gave `leaves`, hits a triangle `keep`
    /// keeps in its interval: [`Bvh::occluded4`]'s answer for the ray (see the module
    /// documentation), from the listed leaves alone.
    pub fn occluded_among<K: Keep>(&self, ray: &FastRay, leaves: &ShaftLeaves, keep: &K) -> bool {
        if leaves.count == 0 {
            return false;
        }
        let root = box_entry(&self.root_bounds, ray, ray.t_max);
        if root > ray.t_max {
            return false;
        }
        let slabs = Slabs::new(ray);
        leaves.leaves[..leaves.count]
            .iter()
            .any(|&(parent, k, leaf)| {
                let entry = match parent {
                    None => root,
                    Some(node) => {
                        let (t0, t1) = self.nodes[node as usize].entries(&slabs, ray.t_max);
                        if k == 0 {
                            t0
                        } else {
                            t1
                        }
                    }
                };
                entry <= ray.t_max && self.leaf_blocks(leaf, ray, keep)
            })
    }

    /// [`Bvh::occluded_among`] of four rays (`None`: no ray, `false`), with the same
    /// answers: when the four are present and agree in their direction signs, each leaf's
    /// slab test is made for the four at once, as in the packet walk.
    pub fn occluded4_among<K: Keep>(
        &self,
        rays: [Option<&FastRay>; 4],
        leaves: &ShaftLeaves,
        keep: &K,
    ) -> [bool; 4] {
        let [Some(a), Some(b), Some(c), Some(d)] = rays else {
            let single =
                |r: Option<&FastRay>| r.is_some_and(|r| self.occluded_among(r, leaves, keep));
            return [
                single(rays[0]),
                single(rays[1]),
                single(rays[2]),
                single(rays[3]),
            ];
        };
        let lanes = [a, b, c, d];
        if !same_signs(lanes) {
            return lanes.map(|r| self.occluded_among(r, leaves, keep));
        }
        if leaves.count == 0 {
            return [false; 4];
        }
        let packet = Packet::new(lanes);
        let t_max = packet.t_max;
        let mut blocked = 0u32;
        for &(parent, k, leaf) in &leaves.leaves[..leaves.count] {
            let entry = match parent {
                None => Vec4::from_array(lanes.map(|r| box_entry(&self.root_bounds, r, r.t_max))),
                Some(node) => {
                    let (t0, t1) = packet.entries(&self.nodes[node as usize], t_max);
                    if k == 0 {
                        t0
                    } else {
                        t1
                    }
                }
            };
            let mut active = entry.cmple(t_max).bitmask() & !blocked;
            while active != 0 {
                let r = active.trailing_zeros() as usize;
                active &= active - 1;
                if self.leaf_blocks(leaf, lanes[r], keep) {
                    blocked |= 1 << r;
                }
            }
            if blocked == 0b1111 {
                break;
            }
        }
        [0, 1, 2, 3].map(|r| blocked & (1 << r) != 0)
    }

    /// Whether a triangle of leaf `leaf` that `keep` keeps is hit in `ray`'s interval, each
    /// tested as the walks test it.
    fn leaf_blocks<K: Keep>(&self, leaf: Child, ray: &FastRay, keep: &K) -> bool {
        let first = leaf.index as usize;
        self.triangles[first..first + leaf.count as usize]
            .iter()
            .enumerate()
            .any(|(i, tri)| tri.intersect(ray, ray.t_max).is_some() && keep.keeps(first + i))
    }
}
