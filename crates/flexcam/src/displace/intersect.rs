//! Exact ray tracing of a displaced base triangle through a min/max hierarchy over its
//! subdivision, after Smits, Shirley and Stark 2000 ("Direct ray tracing of displacement
//! mapped triangles"), with nothing stored per triangle or with the boxes of the top of the
//! hierarchy kept ([`DisplacedTriangle::kept_boxes`]: exact up to level 6).
//!
//! The hierarchy is the recursion of the 4-to-1 subdivision itself: a node is a sub-triangle
//! at some level, its children the four triangles its edge midpoints cut it into, its leaves
//! (level `L`) the micro-triangles of [`super::micro`]. A node is bounded by a box, in a frame
//! of the base triangle (x along the first edge, z its normal, so thin displacements give thin
//! boxes), that provably contains every displaced micro-vertex below it, hence (by convexity)
//! every micro-triangle below it:
//! * a micro-vertex is `P + N * e`: `P` in the node's flat triangle (midpoints of midpoints);
//!   `N = q / |q|` for some `q` in the convex hull of the node's corner normals (each midpoint
//!   normal is the normalised mean of two such), so each component of `N` lies between the
//!   corners' extreme components times `1 / max |n_i|` and `1 / min_i (n_i . m)` (`m` the
//!   normalised mean corner normal, a lower bound of `|q|`); where the corner normals spread
//!   over a half space or more, `|N_k| <= max(1, max |n_i|)` instead;
//! * `e = S * (h - h_max) * F` with `h` between the height field's bounds over the node's uv
//!   bounding rectangle ([`HeightField::range`]: a min/max pyramid for maps, interval
//!   arithmetic for procedural heights), computed on the fly.
//!
//! Interval arithmetic over these gives the box, widened by a relative allowance (1e-9 of the
//! node's extent plus 1e-14 of its distance from the origin) for the rounding of the frame and
//! the midpoints, and, per ray, by 1e-8 of the ray origin's distance from the base triangle:
//! a reported micro-triangle hit lies within `2e-10` of that distance of its triangle (rays
//! grazing a micro-triangle's plane closer than `micro::GRAZING` do not hit
//! it), so the ray enters every box on the way to it. Traversal is front to back: children are visited in
//! order of their boxes' entry distance, and a child whose entry lies beyond the best hit so
//! far is skipped. A node two levels above the leaves whose children's boxes are not kept
//! displaces its fifteen micro-vertices once and bounds each child by the box of its six
//! (exact, where the box above is conservative).
//!
//! The prepared scene keeps the boxes of the top of the hierarchy per base triangle
//! ([`DisplacedTriangle::kept_boxes`]): up to level 6 the exact boxes of the nodes' displaced
//! micro-vertices, computed once from all of them, down to depth 4 (at level 5 the nodes
//! just above the leaves); a ray tests a node's four kept child boxes at once in f32
//! (`WideRay`, widened so that it enters every child the f64 test would) and computes only
//! what lies below them. A leaf tests its micro-triangle exactly as
//! the brute-force reference
//! ([`MicroGrid::intersect`](super::micro::MicroGrid::intersect)) does, on bit-identical
//! micro-vertices, with the same tie rule ([`MicroHit::before`]), so the two find the same
//! hit: same `t`, micro-triangle and barycentrics.

use glam::{DVec2, DVec3, Vec3, Vec4};

use super::height::HeightField;
use super::micro::{
    hit_micro_triangle, BaseVertex, Displacement, MicroGrid, MicroHit, MicroTriangle,
};
use crate::geometry::Ray;

/// Deepest level of the hierarchy whose exact node boxes [`DisplacedTriangle::kept_boxes`]
/// keeps (`1 + 4 + 16 + 64 + 256` boxes, 8,184 bytes per base triangle in f32).
const EXACT_DEPTH: u32 = 4;
/// Highest subdivision level whose kept boxes are exact: they are computed from every
/// micro-vertex (2,145 per base triangle at level 6, 8,385 at level 7).
const EXACT_LEVEL: u32 = 6;
/// Highest subdivision level whose displaced micro-vertices [`DisplacedTriangle::kept_boxes`]
/// keeps (561 per base triangle at level 5, 13,464 bytes in f64): the levels whose exact
/// kept boxes reach the nodes just above the micro-triangles, so that a ray descends by the
/// kept boxes alone and tests the kept micro-vertices, computing none.
const STORED_LEVEL: u32 = EXACT_DEPTH + 1;
/// Deepest level of the hierarchy whose conservative node boxes (levels above
/// [`EXACT_LEVEL`]) [`DisplacedTriangle::kept_boxes`] keeps (`1 + 4 + 16 + 64` boxes, 2,040
/// bytes per base triangle), each a height range over a uv rectangle.
const CONSERVATIVE_DEPTH: u32 = 3;

/// What the prepared scene keeps of a base triangle ([`DisplacedTriangle::kept_boxes`]).
#[derive(Debug, Clone)]
pub struct KeptBoxes {
    /// Boxes of the hierarchy's top nodes, in level order, in the triangle's frame.
    pub boxes: Vec<CachedBox>,
    /// A world box containing every micro-triangle displaced by any fraction from 0 to the
    /// displacement's (the undisplaced micro-triangles included).
    pub bounds: [DVec3; 2],
    /// Up to level 5 (`STORED_LEVEL`) every displaced micro-vertex in world space, bit for
    /// bit the hierarchy's, grid point `(i, j)` at [`stored_index`]; empty above.
    pub points: Vec<DVec3>,
}

/// Where grid point `(i, j)` (`i + j <= n`) of a base triangle subdivided into `n` rows is
/// in [`KeptBoxes::points`]: row `i` (of `n + 1 - i` points) after the rows before it.
#[inline]
pub fn stored_index(n: u32, [i, j]: [u32; 2]) -> usize {
    let (n, i, j) = (n as usize, i as usize, j as usize);
    i * (2 * n + 3 - i) / 2 + j
}

/// Bytes of the displaced micro-vertices [`DisplacedTriangle::kept_boxes`] keeps per base
/// triangle at subdivision `level`: 13,464 at level 5, 0 above it (none kept).
pub fn kept_point_bytes(level: u32) -> usize {
    if level <= STORED_LEVEL {
        stored_count(1 << level) * std::mem::size_of::<DVec3>()
    } else {
        0
    }
}

/// How many micro-vertices a base triangle subdivided into `n` rows has.
fn stored_count(n: u32) -> usize {
    let n = n as usize;
    (n + 1) * (n + 2) / 2
}

/// A node box in f32, rounded outward from the f64 box (see [`DisplacedTriangle::kept_boxes`]).
pub type CachedBox = [Vec3; 2];

/// A base triangle (vertices with positions, normals and uv) and its displacement.
#[derive(Debug, Clone, Copy)]
pub struct DisplacedTriangle<'a> {
    corners: [BaseVertex; 3],
    displacement: &'a Displacement,
    frame: Frame,
    /// The boxes of the nodes at depths `0..=k` in level order (the root at 0, the children
    /// of node `i` at `4 i + 1 ..= 4 i + 4`); the boxes of deeper nodes, or all of them when
    /// this is empty, are computed per ray.
    boxes: &'a [CachedBox],
    /// Every displaced micro-vertex ([`KeptBoxes::points`]), where `boxes` holds every
    /// internal node's box; otherwise empty, and the micro-vertices are computed per ray.
    points: &'a [DVec3],
}

/// The orthonormal frame a base triangle's node boxes are expressed in: `origin` and the
/// rows `x, y, z` (x along the first edge, z the face normal).
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    origin: DVec3,
    axes: [DVec3; 3],
}

impl Frame {
    /// The frame of the base triangle with corner positions `[a, b, c]`: the world axes for
    /// a degenerate one (zero area).
    pub fn new([a, b, c]: [DVec3; 3]) -> Frame {
        let x = (b - a).normalize_or_zero();
        let z = (b - a).cross(c - a).normalize_or_zero();
        let axes = if x == DVec3::ZERO || z == DVec3::ZERO {
            [DVec3::X, DVec3::Y, DVec3::Z]
        } else {
            [x, z.cross(x), z]
        };
        Frame { origin: a, axes }
    }

    fn local(&self, p: DVec3) -> DVec3 {
        self.direction(p - self.origin)
    }

    fn direction(&self, d: DVec3) -> DVec3 {
        DVec3::new(
            self.axes[0].dot(d),
            self.axes[1].dot(d),
            self.axes[2].dot(d),
        )
    }

    fn world(&self, p: DVec3) -> DVec3 {
        self.origin + self.axes[0] * p.x + self.axes[1] * p.y + self.axes[2] * p.z
    }
}

/// A node of the hierarchy: three undisplaced micro-vertices and their grid points.
#[derive(Debug, Clone, Copy)]
struct Node {
    v: [BaseVertex; 3],
    g: [[u32; 2]; 3],
}

impl Node {
    /// The four children in the order of the scene contract: `(a, ab, ac)`, `(ab, b, bc)`,
    /// `(ac, bc, c)`, `(ac, ab, bc)`.
    fn children(&self) -> [Node; 4] {
        let midpoints = self.midpoints();
        [0, 1, 2, 3].map(|k| self.child(k, midpoints))
    }

    /// Its edge midpoints `[ab, bc, ca]` (undisplaced), which its children's corners are
    /// made of.
    #[inline]
    fn midpoints(&self) -> [BaseVertex; 3] {
        let [a, b, c] = self.v;
        [a.midpoint(b), b.midpoint(c), c.midpoint(a)]
    }

    /// Child `k` of [`Node::children`], from the node's `midpoints`: built only for the
    /// children a ray descends into.
    #[inline]
    fn child(&self, k: usize, [ab, bc, ca]: [BaseVertex; 3]) -> Node {
        let [a, b, c] = self.v;
        let v = match k {
            0 => [a, ab, ca],
            1 => [ab, b, bc],
            2 => [ca, bc, c],
            _ => [ca, ab, bc],
        };
        Node {
            v,
            g: child_grids(self.g)[k],
        }
    }

    /// Whether the node's grid triangle holds the point `p / 3` (grid units), edges included.
    fn holds(&self, p: [i64; 2]) -> bool {
        let g = self.g.map(|g| [3 * g[0] as i64, 3 * g[1] as i64]);
        let side = |a: [i64; 2], b: [i64; 2]| {
            (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
        };
        let s = [side(g[0], g[1]), side(g[1], g[2]), side(g[2], g[0])];
        s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0)
    }
}

/// The grid corners of the four children of the node with grid corners `[a, b, c]`, in the
/// order of [`Node::children`].
fn child_grids([a, b, c]: [[u32; 2]; 3]) -> [[[u32; 2]; 3]; 4] {
    let mid = |p: [u32; 2], q: [u32; 2]| [(p[0] + q[0]) / 2, (p[1] + q[1]) / 2];
    let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ca, ab, bc]]
}

/// The micro-triangle of the leaf with grid corners `g`, and its vertices' displaced
/// positions `displaced` (in the order of `g`) put in that triangle's order. Spelled out
/// (no iterators): it runs for every micro-triangle a ray tests.
#[inline]
fn micro_triangle(g: [[u32; 2]; 3], displaced: [DVec3; 3]) -> (MicroTriangle, [DVec3; 3]) {
    let i = g[0][0].min(g[1][0]).min(g[2][0]);
    let j = g[0][1].min(g[1][1]).min(g[2][1]);
    let up = g[0] == [i, j] || g[1] == [i, j] || g[2] == [i, j];
    let triangle = MicroTriangle { i, j, up };
    // The position of the first corner of `g` at `v` (the first corner's if none is).
    let at = |v: [u32; 2]| {
        if g[0] == v {
            displaced[0]
        } else if g[1] == v {
            displaced[1]
        } else if g[2] == v {
            displaced[2]
        } else {
            displaced[0]
        }
    };
    let [p, q, r] = triangle.vertices();
    (triangle, [at(p), at(q), at(r)])
}

/// Keeps `found` in `best` if it comes first ([`MicroHit::before`]).
#[inline]
fn keep(best: &mut Option<MicroHit>, found: Option<MicroHit>) {
    if let Some(hit) = found {
        if best.is_none_or(|b| hit.before(&b)) {
            *best = Some(hit);
        }
    }
}

/// Tests the four leaves below a node with grid corners `g` whose six micro-vertices,
/// displaced, are `[a, b, c, ab, bc, ca]` (corners, then edge midpoints), without boxes (a
/// box costs about what its triangle test does). The best hit does not depend on the order
/// of the tests ([`MicroHit::before`]).
fn test_leaves(
    ray: &Ray,
    g: [[u32; 2]; 3],
    [a, b, c, ab, bc, ca]: [DVec3; 6],
    best: &mut Option<MicroHit>,
) {
    let corners = [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ca, ab, bc]];
    for (grid, displaced) in child_grids(g).into_iter().zip(corners) {
        let (triangle, positions) = micro_triangle(grid, displaced);
        keep(best, hit_micro_triangle(ray, triangle, positions));
    }
}

/// The world box of a node just above the leaves from its six displaced micro-vertices: the
/// exact box of its four micro-triangles (their convex hull's), widened by 1e-8 of the
/// largest distance along an axis from `origin`, the ray's origin, to its faces. A reported
/// hit lies within `2e-10` times its distance from the origin of its micro-triangle (module
/// docs), and that distance is at most `sqrt(3)` times the widening's base (plus the
/// error), so the ray enters the widened box on the way to every hit in it; the allowance
/// also covers the rounding of the slab distances.
fn leaf_parent_box(points: &[DVec3; 6], origin: DVec3) -> [DVec3; 2] {
    let lo = points.iter().fold(DVec3::INFINITY, |m, &p| m.min(p));
    let hi = points.iter().fold(DVec3::NEG_INFINITY, |m, &p| m.max(p));
    let slack = DVec3::splat(1e-8 * (origin - lo).abs().max((origin - hi).abs()).max_element());
    [lo - slack, hi + slack]
}

/// The box of the micro-vertices `local` (in the frame, grid point `(i, j)` at `i * side +
/// j`) of the node with grid corners `g` at subdivision `depth` of `level`: its
/// micro-triangles' (so their convex hulls'). Records it, and those of its descendants, at
/// their places in the level order (`index` its own) where `out` holds them.
fn exact_box(
    local: &[DVec3],
    side: usize,
    g: [[u32; 2]; 3],
    depth: u32,
    level: u32,
    index: usize,
    out: &mut [[DVec3; 2]],
) -> [DVec3; 2] {
    let found = if depth == level {
        let p = g.map(|[i, j]| local[i as usize * side + j as usize]);
        [p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2])]
    } else {
        let mut found = [DVec3::INFINITY, DVec3::NEG_INFINITY];
        for (k, child) in child_grids(g).into_iter().enumerate() {
            let [lo, hi] = exact_box(local, side, child, depth + 1, level, 4 * index + 1 + k, out);
            found = [found[0].min(lo), found[1].max(hi)];
        }
        found
    };
    // Deeper nodes' level-order places lie beyond the kept ones.
    if let Some(slot) = out.get_mut(index) {
        *slot = found;
    }
    found
}

/// A ray in the base triangle's frame, for slab tests.
#[derive(Clone)]
struct LocalRay {
    origin: DVec3,
    direction: DVec3,
    /// The direction's reciprocal (infinite where a component is zero: not used there).
    inv: DVec3,
    t_min: f64,
    t_max: f64,
    /// How much every box is widened for this ray (module docs).
    slack: f64,
    /// The ray in f32 for the kept boxes, where the triangle has them and f32 holds it.
    wide: Option<WideRay>,
    /// Whether the search stops at the first hit found (any hit: a shadow ray's question)
    /// instead of looking on for the nearest.
    first: bool,
}

impl LocalRay {
    fn new(frame: &Frame, ray: &Ray) -> LocalRay {
        let origin = frame.local(ray.origin);
        let slack = 1e-8 * origin.abs().max_element();
        LocalRay::with(origin, frame.direction(ray.direction), ray, slack)
    }

    /// The ray from `origin` along `direction` over `ray`'s interval, boxes widened by
    /// `slack`.
    fn with(origin: DVec3, direction: DVec3, ray: &Ray, slack: f64) -> LocalRay {
        LocalRay {
            origin,
            direction,
            inv: direction.recip(),
            t_min: ray.t_min,
            t_max: ray.t_max,
            slack,
            wide: None,
            first: false,
        }
    }

    /// The same ray with its f32 form ([`WideRay`]) for a triangle whose kept root box is
    /// `root`, if it has kept boxes.
    fn with_root(self, root: Option<&CachedBox>) -> LocalRay {
        let wide = root.and_then(|root| WideRay::new(&self, root));
        LocalRay { wide, ..self }
    }
}

/// A [`LocalRay`] in f32, each component splatted over four lanes, to test the four kept
/// boxes of a node's children at once ([`wide_entries`]).
///
/// Conservative: with `u = 2^-24`, each slab distance `(lo - s - o) / d` computed in f32
/// (the box plane moved out by `s`, the origin rounded, the reciprocal rounded twice, the
/// difference and the product rounded) is off by at most `4.1 u (M + |o| + s) / |d|`, `M` the
/// largest coordinate of the triangle's root box (every kept box lies in it) and `|o|` the
/// origin's; so with `s = 2^-20 (M + |o|)` plus the [`LocalRay`]'s own slack, the computed
/// entry is at most, and the exit at least, those of the box widened by that slack alone,
/// and a child the f64 test would enter is entered, at no later distance.
#[derive(Debug, Clone, Copy)]
struct WideRay {
    origin: [Vec4; 3],
    inv: [Vec4; 3],
    /// `t_min` rounded down.
    t_min: f32,
    t_max: f64,
    /// How much every box is widened for this ray (above).
    slack: Vec4,
}

impl WideRay {
    /// `local` in f32, for the triangle with kept root box `root`; `None` where f32 would
    /// not hold the test (a zero or tiny direction component, huge coordinates or slab
    /// distances), which then takes the f64 test.
    fn new(local: &LocalRay, root: &CachedBox) -> Option<WideRay> {
        let reach = root[0].abs().max(root[1].abs()).max_element() as f64
            + local.origin.abs().max_element();
        let inv = local.inv.abs().max_element();
        if !(inv.is_finite() && reach * inv.max(1.0) < 1e30) {
            return None;
        }
        let splat = |v: DVec3| [v.x, v.y, v.z].map(|x| Vec4::splat(x as f32));
        Some(WideRay {
            origin: splat(local.origin),
            inv: splat(local.inv),
            t_min: f32_below(local.t_min),
            t_max: local.t_max,
            slack: Vec4::splat(f32_above(reach * (1.0 / 1048576.0) + local.slack)),
        })
    }
}

/// Where the ray enters each of the four boxes `boxes` (a node's kept children) within its
/// interval and before `limit`, at or before the f64 test's entry ([`WideRay`]); infinite
/// for a box it misses.
#[inline]
fn wide_entries(ray: &WideRay, boxes: &[CachedBox], limit: f64) -> [f32; 4] {
    let lane = |side: usize, axis: usize| {
        Vec4::new(
            boxes[0][side][axis],
            boxes[1][side][axis],
            boxes[2][side][axis],
            boxes[3][side][axis],
        )
    };
    let mut near = Vec4::splat(ray.t_min);
    let mut far = Vec4::splat(f32_above(ray.t_max.min(limit)));
    for axis in 0..3 {
        let t0 = (lane(0, axis) - ray.slack - ray.origin[axis]) * ray.inv[axis];
        let t1 = (lane(1, axis) + ray.slack - ray.origin[axis]) * ray.inv[axis];
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    Vec4::select(near.cmple(far), near, Vec4::INFINITY).to_array()
}

/// A ray that enters a triangle's kept root box, in that triangle's frame: what
/// [`enters_root`] found, for [`DisplacedTriangle::intersect_entered`].
pub struct RootEntry(LocalRay);

/// Whether `ray` enters a triangle's kept root box `root` (the first of its
/// [`DisplacedTriangle::kept_boxes`], in its `frame`): the test
/// [`DisplacedTriangle::intersect`] starts with, without the triangle's corners, so that a
/// caller can skip fetching them for the many triangles a ray reaches only in their world
/// box. `None` means no hit.
pub fn enters_root(frame: &Frame, root: &CachedBox, ray: &Ray) -> Option<RootEntry> {
    let [lo, hi] = *root;
    let local = LocalRay::new(frame, ray);
    slab_entry(&local, [lo.as_dvec3(), hi.as_dvec3()], f64::INFINITY)?;
    Some(RootEntry(local.with_root(Some(root))))
}

impl<'a> DisplacedTriangle<'a> {
    /// The base triangle `corners` (in order `a, b, c`) displaced by `displacement`. Vertex
    /// normals are used as given (the mesh's; unit length expected). A degenerate base
    /// triangle (zero area) is traced in the world axes.
    pub fn new(corners: [BaseVertex; 3], displacement: &'a Displacement) -> Self {
        DisplacedTriangle {
            corners,
            displacement,
            frame: Frame::new(corners.map(|v| v.position)),
            boxes: &[],
            points: &[],
        }
    }

    /// The same triangle with its frame, top node boxes and displaced micro-vertices kept
    /// from [`DisplacedTriangle::frame`] and [`DisplacedTriangle::kept_boxes`] of it, so
    /// that a ray pays one slab test per kept box instead of computing it, and reads the
    /// micro-vertices instead of displacing them: same hits. `points` are used only where
    /// there are as many as the triangle has micro-vertices and `boxes` holds the box of
    /// every node above the micro-triangles (as `kept_boxes` keeps them); `&[]` computes
    /// them per ray.
    pub fn with_boxes(
        corners: [BaseVertex; 3],
        displacement: &'a Displacement,
        frame: Frame,
        boxes: &'a [CachedBox],
        points: &'a [DVec3],
    ) -> Self {
        let usable = StoredTriangle::new(displacement.level(), boxes, points).is_some();
        DisplacedTriangle {
            corners,
            displacement,
            frame,
            boxes,
            points: if usable { points } else { &[] },
        }
    }

    /// The frame its node boxes are expressed in.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// What the prepared scene keeps: the boxes of its internal nodes down to depth `min(L -
    /// 1, 4)` (a leaf-parent's children are tested directly, without boxes), in level order,
    /// each rounded outward to f32 (so it still contains its node's micro-geometry): `1`,
    /// `5`, `21`, `85` or `341` boxes, at most 8,184 bytes; and up to level 5
    /// (`STORED_LEVEL`) its displaced micro-vertices (at most 561, 13,464 bytes), which
    /// every ray would otherwise recompute from the corners (midpoints with their
    /// normalisations, height samples). Up to level 6 (`EXACT_LEVEL`) the boxes
    /// are exact: the boxes of the node's displaced micro-vertices, computed once here from
    /// all of them (`exact_boxes`), so a ray enters far fewer nodes than through the
    /// conservative boxes (positions, normal cone, height range over the node's uv
    /// rectangle) the hierarchy computes per ray. Above it they are those conservative boxes,
    /// down to depth 3 (`conservative_boxes`).
    pub fn kept_boxes(&self) -> KeptBoxes {
        if self.displacement.level() <= EXACT_LEVEL {
            self.exact_boxes()
        } else {
            KeptBoxes {
                boxes: self.conservative_boxes(),
                bounds: self.bounds(),
                points: Vec::new(),
            }
        }
    }

    /// The conservative boxes of its internal nodes down to depth `min(L - 1, 3)`, in level
    /// order, as [`Self::node_box`] computes them per ray, rounded outward to f32.
    fn conservative_boxes(&self) -> Vec<CachedBox> {
        let depth = self
            .displacement
            .level()
            .saturating_sub(1)
            .min(CONSERVATIVE_DEPTH);
        let mut level = vec![self.root()];
        let mut out = Vec::new();
        for d in 0..=depth {
            out.extend(level.iter().map(|node| outward(self.node_box(node))));
            if d < depth {
                level = level.iter().flat_map(Node::children).collect();
            }
        }
        out
    }

    /// The exact boxes of its internal nodes down to depth `min(L - 1, 4)`, in level order,
    /// and its world bounds ([`KeptBoxes`]), from every micro-vertex ([`MicroGrid`]: the
    /// micro-vertices the hierarchy tests, bit for bit). A node's box is that of the
    /// displaced micro-vertices of its micro-triangles in the frame (their convex hull's, so
    /// every micro-triangle's), widened as [`Self::node_box`] is for the rounding of the
    /// frame transform (1e-9 of the node's extent plus 1e-14 of the frame origin's distance
    /// from the world origin), then rounded outward to f32.
    fn exact_boxes(&self) -> KeptBoxes {
        let level = self.displacement.level();
        let depth = level.saturating_sub(1).min(EXACT_DEPTH);
        let grid = MicroGrid::new(&self.corners, self.displacement);
        let n = 1u32 << level;
        let side = n as usize + 1;
        let mut local = vec![DVec3::ZERO; side * side];
        let mut world = [DVec3::INFINITY, DVec3::NEG_INFINITY];
        let mut points = Vec::with_capacity(if level <= STORED_LEVEL {
            side * (side + 1) / 2
        } else {
            0
        });
        for i in 0..=n {
            for j in 0..=n - i {
                let (vertex, displaced) = (grid.vertex([i, j]), grid.displaced([i, j]));
                if level <= STORED_LEVEL {
                    points.push(displaced);
                }
                local[i as usize * side + j as usize] = self.frame.local(displaced);
                world = [
                    world[0].min(displaced).min(vertex.position),
                    world[1].max(displaced).max(vertex.position),
                ];
            }
        }
        let far = self.frame.origin.abs().max_element();
        let widen = |[lo, hi]: [DVec3; 2]| {
            let reach = lo.abs().max(hi.abs()).max_element();
            let slack = DVec3::splat(1e-9 * reach + 1e-14 * far);
            [lo - slack, hi + slack]
        };
        let mut exact = vec![[DVec3::ZERO; 2]; ((1usize << (2 * (depth + 1))) - 1) / 3];
        let root = self.root();
        exact_box(&local, side, root.g, 0, level, 0, &mut exact);
        let boxes = exact.into_iter().map(|b| outward(widen(b))).collect();
        // The world box of the undisplaced and displaced micro-vertices holds every partly
        // displaced one (on the segment between the two, up to rounding).
        let reach = world[0].abs().max(world[1].abs()).max_element();
        let slack = DVec3::splat(1e-9 * (world[1] - world[0]).max_element() + 1e-14 * reach);
        KeptBoxes {
            boxes,
            bounds: [world[0] - slack, world[1] + slack],
            points,
        }
    }

    /// A world-space box `[min, max]` containing every micro-triangle, undisplaced, displaced
    /// or displaced by any fraction in between: the root's conservative box joined with the
    /// base triangle (the undisplaced micro-vertices lie on it, and the root's height range
    /// need not reach `h_max`, where the offset is 0), so it holds the segments between the
    /// two too.
    pub fn bounds(&self) -> [DVec3; 2] {
        let [lo, hi] = self.node_box(&self.root());
        let base = self.corners.map(|v| v.position);
        let mut out = [
            base[0].min(base[1]).min(base[2]),
            base[0].max(base[1]).max(base[2]),
        ];
        for k in 0..8 {
            let corner = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let p = self.frame.world(corner);
            out = [out[0].min(p), out[1].max(p)];
        }
        let slack = DVec3::splat(1e-14) * out[0].abs().max(out[1].abs());
        [out[0] - slack, out[1] + slack]
    }

    /// The first micro-triangle hit with `t` in `[ray.t_min, ray.t_max]`, from either side;
    /// the same hit as [`MicroGrid::intersect`](super::micro::MicroGrid::intersect).
    pub fn intersect(&self, ray: &Ray) -> Option<MicroHit> {
        if !valid(ray) {
            return None;
        }
        let local = LocalRay::new(&self.frame, ray);
        let root = match self.boxes.first() {
            Some(&[lo, hi]) => [lo.as_dvec3(), hi.as_dvec3()],
            None => self.node_box(&self.root()),
        };
        slab_entry(&local, root, f64::INFINITY)?;
        self.intersect_entered(ray, &RootEntry(local.with_root(self.boxes.first())), false)
    }

    /// [`DisplacedTriangle::intersect`] for a ray [`enters_root`] let through with this
    /// triangle's frame and root box (those it was made [`with_boxes`](Self::with_boxes)
    /// of): the same hit, without testing the root box again. With `any`, the first hit
    /// found instead (there is one exactly when there is a nearest one).
    pub fn intersect_entered(&self, ray: &Ray, entry: &RootEntry, any: bool) -> Option<MicroHit> {
        if let Some(stored) = self.stored() {
            return stored.intersect_entered(ray, entry, any);
        }
        if !valid(ray) {
            return None;
        }
        let local = LocalRay {
            first: any,
            ..entry.0.clone()
        };
        let mut best = None;
        self.visit(ray, &local, &self.root(), 0, 0, &mut best);
        best
    }

    /// Its kept boxes and micro-vertices, where it has both for every node.
    fn stored(&self) -> Option<StoredTriangle<'a>> {
        StoredTriangle::new(self.displacement.level(), self.boxes, self.points)
    }

    /// The displaced vertices of micro-triangle `triangle` (in [`MicroTriangle::vertices`]
    /// order), bit for bit those the intersection tests: found by descending the subdivision
    /// into the child that holds it, `L` steps, or read from the kept micro-vertices.
    pub fn positions(&self, triangle: MicroTriangle) -> [DVec3; 3] {
        let target = triangle.vertices();
        let n = 1u32 << self.displacement.level();
        let on_grid = |&[i, j]: &[u32; 2]| i.checked_add(j).is_some_and(|s| s <= n);
        if !self.points.is_empty() && target.iter().all(on_grid) {
            return target.map(|g| self.points[stored_index(n, g)]);
        }
        // Three times the target's centroid, in grid units: integer and strictly inside.
        let centroid = [0, 1].map(|k| target.iter().map(|g| g[k] as i64).sum::<i64>());
        let mut node = self.root();
        for _ in 0..self.displacement.level() {
            node = node
                .children()
                .into_iter()
                .find(|child| child.holds(centroid))
                .unwrap_or(node);
        }
        target.map(|g| {
            let k = node.g.iter().position(|&x| x == g).unwrap_or(0);
            self.displacement.displace(&node.v[k])
        })
    }

    fn root(&self) -> Node {
        let n = 1u32 << self.displacement.level();
        Node {
            v: self.corners,
            g: [[0, 0], [n, 0], [0, n]],
        }
    }

    /// Descends into `node` (at subdivision `depth`, with index `index` in the level order
    /// of [`DisplacedTriangle::boxes`], its box already entered).
    fn visit(
        &self,
        ray: &Ray,
        local: &LocalRay,
        node: &Node,
        depth: u32,
        index: usize,
        best: &mut Option<MicroHit>,
    ) {
        let level = self.displacement.level();
        let displace = |v: &BaseVertex| self.displacement.displace(v);
        if depth == level {
            let (triangle, positions) = micro_triangle(node.g, node.v.map(|v| displace(&v)));
            keep(best, hit_micro_triangle(ray, triangle, positions));
            return;
        }
        if local.first && best.is_some() {
            return;
        }
        let midpoints = node.midpoints();
        if depth + 1 == level {
            // The four leaves share six micro-vertices: displace each once.
            let [a, b, c] = node.v.map(|v| displace(&v));
            let [ab, bc, ca] = midpoints.map(|v| displace(&v));
            test_leaves(ray, node.g, [a, b, c, ab, bc, ca], best);
            return;
        }
        // Index of the first child in the level order of the next depth.
        let first = 4 * index + 1;
        if depth + 2 == level && self.boxes.len() <= first {
            self.visit_leaf_parents(ray, local, node, midpoints, best);
            return;
        }
        let limit = best.map_or(f64::INFINITY, |b| b.t);
        let (order, count) = match self.boxes.get(first..first + 4) {
            Some(kept) => kept_order(local, kept, limit),
            None => front_to_back(|k| {
                slab_entry(local, self.node_box(&node.child(k, midpoints)), limit)
            }),
        };
        for &(entry, k) in &order[..count] {
            // Ties with the best hit stay: a hit at equal t may win on the triangle order.
            if best.is_some_and(|b| entry > b.t) {
                break;
            }
            if local.first && best.is_some() {
                return;
            }
            let child = node.child(k, midpoints);
            self.visit(ray, local, &child, depth + 1, first + k, best);
        }
    }

    /// Descends into `node`, two levels above the leaves, whose children's boxes are not
    /// kept: its fifteen micro-vertices are displaced once each (a midpoint is symmetric bit
    /// for bit, so the children sharing an inner edge share its midpoint), and each child's
    /// exact box of its six ([`leaf_parent_box`]) takes the place of [`Self::node_box`],
    /// which costs about as much as displacing them (a height range over the node's uv
    /// rectangle) and bounds them more loosely. Children are visited front to back, pruned
    /// beyond the best hit, as in [`Self::visit`].
    fn visit_leaf_parents(
        &self,
        ray: &Ray,
        local: &LocalRay,
        node: &Node,
        [ab, bc, ca]: [BaseVertex; 3],
        best: &mut Option<MicroHit>,
    ) {
        let [a, b, c] = node.v;
        let d = |v: BaseVertex| self.displacement.displace(&v);
        let (da, db, dc, dab, dbc, dca) = (d(a), d(b), d(c), d(ab), d(bc), d(ca));
        // The inner edges (of the middle child), each shared with one corner child.
        let (ab_ca, ab_bc, bc_ca) = (d(ab.midpoint(ca)), d(ab.midpoint(bc)), d(bc.midpoint(ca)));
        let six: [[DVec3; 6]; 4] = [
            [da, dab, dca, d(a.midpoint(ab)), ab_ca, d(ca.midpoint(a))],
            [dab, db, dbc, d(ab.midpoint(b)), d(b.midpoint(bc)), ab_bc],
            [dca, dbc, dc, bc_ca, d(bc.midpoint(c)), d(c.midpoint(ca))],
            [dca, dab, dbc, ab_ca, ab_bc, bc_ca],
        ];
        let world = LocalRay::with(ray.origin, ray.direction, ray, 0.0);
        let limit = best.map_or(f64::INFINITY, |b| b.t);
        let (order, count) =
            front_to_back(|k| slab_entry(&world, leaf_parent_box(&six[k], ray.origin), limit));
        let grids = child_grids(node.g);
        for &(entry, k) in &order[..count] {
            if best.is_some_and(|b| entry > b.t || local.first) {
                break;
            }
            test_leaves(ray, grids[k], six[k], best);
        }
    }

    /// The node's box `[lo, hi]` in the base triangle's frame (module docs).
    fn node_box(&self, node: &Node) -> [DVec3; 2] {
        let p = node.v.map(|v| self.frame.local(v.position));
        let n = node.v.map(|v| self.frame.direction(v.normal));
        let [p_lo, p_hi] = [p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2])];
        let [n_lo, n_hi] = normal_range(n);
        let [e_lo, e_hi] = self
            .displacement
            .offset_range(uv_height_range(self.displacement.height(), &node.v));
        // Component-wise product of the intervals [n_lo, n_hi] and [e_lo, e_hi].
        let products = [n_lo * e_lo, n_lo * e_hi, n_hi * e_lo, n_hi * e_hi];
        let d_lo = products[0]
            .min(products[1])
            .min(products[2])
            .min(products[3]);
        let d_hi = products[0]
            .max(products[1])
            .max(products[2])
            .max(products[3]);
        let reach = p_lo.abs().max(p_hi.abs()).max_element() + e_lo.abs().max(e_hi.abs());
        let far = self.frame.origin.abs().max_element();
        let slack = DVec3::splat(1e-9 * reach + 1e-14 * far);
        [p_lo + d_lo - slack, p_hi + d_hi + slack]
    }
}

/// The f32 box containing the f64 box `[lo, hi]`.
fn outward([lo, hi]: [DVec3; 2]) -> CachedBox {
    [
        Vec3::new(f32_below(lo.x), f32_below(lo.y), f32_below(lo.z)),
        Vec3::new(f32_above(hi.x), f32_above(hi.y), f32_above(hi.z)),
    ]
}

/// One unit in the last place of `x` or more: rounding to nearest may land inside.
fn f32_step(x: f32) -> f32 {
    x.abs() * f32::EPSILON + f32::MIN_POSITIVE
}

/// An f32 at or below `x`.
fn f32_below(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        f - f32_step(f)
    } else {
        f
    }
}

/// An f32 at or above `x`.
fn f32_above(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f + f32_step(f)
    } else {
        f
    }
}

/// Component bounds of every normal below a node with corner normals `n` (module docs).
fn normal_range(n: [DVec3; 3]) -> [DVec3; 2] {
    let q_lo = n[0].min(n[1]).min(n[2]);
    let q_hi = n[0].max(n[1]).max(n[2]);
    let longest = n[0].length().max(n[1].length()).max(n[2].length());
    let m = (n[0] + n[1] + n[2]).normalize_or_zero();
    let nearest = n[0].dot(m).min(n[1].dot(m)).min(n[2].dot(m));
    if nearest.is_nan() || nearest <= 0.0 || longest == 0.0 {
        let r = DVec3::splat(longest.max(1.0) * (1.0 + 1e-12));
        return [-r, r];
    }
    // Allow for the rounding of the normalisations.
    let (s_lo, s_hi) = ((1.0 - 1e-12) / longest, (1.0 + 1e-12) / nearest);
    let candidates = [
        q_lo,
        q_hi,
        q_lo * s_lo,
        q_lo * s_hi,
        q_hi * s_lo,
        q_hi * s_hi,
    ];
    let lo = candidates.iter().fold(DVec3::INFINITY, |a, &c| a.min(c));
    let hi = candidates
        .iter()
        .fold(DVec3::NEG_INFINITY, |a, &c| a.max(c));
    [lo, hi]
}

/// Height bounds over the uv bounding rectangle of a node's corners, widened for the rounding
/// of the uv midpoints below it.
fn uv_height_range(height: &HeightField, v: &[BaseVertex; 3]) -> [f64; 2] {
    let lo = v[0].uv.min(v[1].uv).min(v[2].uv);
    let hi = v[0].uv.max(v[1].uv).max(v[2].uv);
    let slack = DVec2::splat(1e-12) * (DVec2::ONE + lo.abs().max(hi.abs()));
    height.range(lo - slack, hi + slack)
}

/// The children whose kept boxes `kept` the ray enters within its interval and before
/// `limit`, nearest first ([`front_to_back`]): all four at once in f32 where the ray has its
/// f32 form ([`WideRay`]), each in f64 otherwise.
#[inline]
fn kept_order(local: &LocalRay, kept: &[CachedBox], limit: f64) -> ([(f64, usize); 4], usize) {
    match &local.wide {
        Some(wide) => {
            let entries = wide_entries(wide, kept, limit);
            front_to_back(|k| (entries[k] < f32::INFINITY).then_some(entries[k] as f64))
        }
        None => front_to_back(|k| slab_entry(local, kept[k].map(|v| v.as_dvec3()), limit)),
    }
}

/// The children `k` (0 to 3) whose boxes the ray enters, `entry(k)` giving where, as
/// `(entry, k)` nearest first, and how many there are.
#[inline]
fn front_to_back(entry: impl Fn(usize) -> Option<f64>) -> ([(f64, usize); 4], usize) {
    let mut order: [(f64, usize); 4] = [(f64::INFINITY, 4); 4];
    let mut count = 0;
    for k in 0..4 {
        if let Some(t) = entry(k) {
            let mut at = count;
            while at > 0 && order[at - 1].0 > t {
                order[at] = order[at - 1];
                at -= 1;
            }
            order[at] = (t, k);
            count += 1;
        }
    }
    (order, count)
}

/// Where the ray enters `[lo, hi]` within its interval and before `limit`, if it does.
/// A zero direction component tests the origin against that slab instead of dividing.
#[inline]
fn slab_entry(ray: &LocalRay, [lo, hi]: [DVec3; 2], limit: f64) -> Option<f64> {
    let mut near = ray.t_min;
    let mut far = ray.t_max.min(limit);
    let (lo, hi) = (lo - ray.slack, hi + ray.slack);
    for k in 0..3 {
        let (o, d) = (ray.origin[k], ray.direction[k]);
        if d == 0.0 {
            if o < lo[k] || o > hi[k] {
                return None;
            }
            continue;
        }
        let (t0, t1) = ((lo[k] - o) * ray.inv[k], (hi[k] - o) * ray.inv[k]);
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    // Rounding of the slab distances (a few units in the last place of each, relative: the
    // reciprocal and the product) is covered by the boxes' slack.
    (near <= far).then_some(near)
}

/// A base triangle's kept boxes and displaced micro-vertices where they reach every node
/// above the micro-triangles (up to level 5, [`DisplacedTriangle::kept_boxes`]): all a ray
/// needs to trace it exactly, by grid corners alone, with neither its corners nor its
/// displacement (no midpoint, no height is computed).
#[derive(Debug, Clone, Copy)]
pub struct StoredTriangle<'a> {
    level: u32,
    boxes: &'a [CachedBox],
    points: &'a [DVec3],
}

impl<'a> StoredTriangle<'a> {
    /// The triangle at subdivision `level` with kept `boxes` and micro-vertices `points` (as
    /// [`DisplacedTriangle::kept_boxes`] keeps them); `None` unless there are as many points
    /// as it has micro-vertices and a box for every node above the micro-triangles.
    pub fn new(level: u32, boxes: &'a [CachedBox], points: &'a [DVec3]) -> Option<Self> {
        let internal = ((1usize << (2 * level)) - 1) / 3;
        let usable = points.len() == stored_count(1 << level) && boxes.len() >= internal;
        usable.then_some(StoredTriangle {
            level,
            boxes,
            points,
        })
    }

    /// [`DisplacedTriangle::intersect_entered`] of the triangle these were kept from: the
    /// same hit, bit for bit (with `any`, a hit exactly when there is one).
    pub fn intersect_entered(&self, ray: &Ray, entry: &RootEntry, any: bool) -> Option<MicroHit> {
        if !valid(ray) {
            return None;
        }
        let mut best = None;
        let n = 1u32 << self.level;
        self.visit(
            ray,
            &entry.0,
            any,
            [[0, 0], [n, 0], [0, n]],
            (0, 0),
            &mut best,
        );
        best
    }

    /// Descends into the node with grid corners `g` at `depth` (level-order index `index`)
    /// by its kept children's boxes, front to back, as [`DisplacedTriangle::visit`] does,
    /// and tests the micro-triangles on the kept micro-vertices, the same as `visit`
    /// computes, bit for bit; with `first`, stops at the first hit.
    fn visit(
        &self,
        ray: &Ray,
        local: &LocalRay,
        first: bool,
        g: [[u32; 2]; 3],
        (depth, index): (u32, usize),
        best: &mut Option<MicroHit>,
    ) {
        let n = 1u32 << self.level;
        let at = |p: [u32; 2]| self.points[stored_index(n, p)];
        if depth == self.level {
            let (triangle, positions) = micro_triangle(g, [at(g[0]), at(g[1]), at(g[2])]);
            keep(best, hit_micro_triangle(ray, triangle, positions));
            return;
        }
        let grids = child_grids(g);
        if depth + 1 == self.level {
            // The middle child is (ca, ab, bc).
            let [ca, ab, bc] = grids[3];
            let [a, b, c] = g;
            let six = [at(a), at(b), at(c), at(ab), at(bc), at(ca)];
            test_leaves(ray, g, six, best);
            return;
        }
        let next = 4 * index + 1;
        let limit = best.map_or(f64::INFINITY, |b| b.t);
        // `new` keeps points only where every internal node's box is kept.
        let (order, count) = kept_order(local, &self.boxes[next..next + 4], limit);
        for &(entry, k) in &order[..count] {
            if best.is_some_and(|b| entry > b.t || first) {
                break;
            }
            self.visit(ray, local, first, grids[k], (depth + 1, next + k), best);
        }
    }
}

/// Whether `ray` can hit anything: a finite origin and a finite, non-zero direction.
#[inline]
fn valid(ray: &Ray) -> bool {
    ray.origin.is_finite() && ray.direction.is_finite() && ray.direction != DVec3::ZERO
}

#[cfg(test)]
mod tests;
