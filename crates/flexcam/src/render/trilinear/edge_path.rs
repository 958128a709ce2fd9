//! The exact image of a scene edge in one projection triangle, followed by depth (Vallance 2005,
//! sections 4.5 and 5).
//!
//! While a shape's polygon edge runs from an image of scene vertex `a` at depth `t_a` to the
//! next image at `t_b`, the plane of the parametric triangle `r1(t), r2(t), r3(t)` cuts the
//! scene segment `ab` in exactly one point for every `t` between them (a segment crosses a
//! plane at most once, and the sweep argument of `shapes` says this edge is crossed there).
//! [`EdgePath::at`] computes that point and its barycentrics in the parametric triangle: the
//! exact image of the edge at depth `t`. A polygon edge is therefore a curve parametrised by
//! `t`, and the renderer samples it:
//!
//! * **anchors**, computed exactly and always inserted: the depth `t = 0` (view-plane
//!   clipping, 4.6: the crossing of the scene edge with the base triangle's plane) and the
//!   depths where the scene edge crosses one of the three edge surfaces of the projection
//!   triangle (scene-space clipping, chapter 5: [`EdgeSurface::crossing_depths`]). Between
//!   two consecutive anchors the curve crosses neither `t = 0` nor any of the three
//!   (extended) domain lines `u = 0`, `v = 0`, `u + v = 1`, so each piece is either wholly
//!   visible or wholly clipped away;
//! * **curve samples** inside visible pieces: fixed slices or adaptive bisection
//!   ([`refine`]).
//!
//! Degenerate cases: where the plane at `t` is parallel to the segment, or the parametric
//! triangle is degenerate at `t` (its plane is undefined), [`EdgePath::at`] gives `None` and
//! the sample is skipped; the chord then spans it. A 2-vertex shape whose two images have the
//! same `t` (a tangency) has no interior depth and stays a straight line.

use glam::{DVec2, DVec3};

use super::screen_map::ScreenMap;
use crate::geometry::{solve_quadratic, Roots};
use crate::projection::ProjectionTriangleCache;

/// A point of a shape's outline: barycentrics in the projection triangle and depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutlinePoint {
    pub u: f64,
    pub v: f64,
    pub t: f64,
}

impl OutlinePoint {
    /// Whether the point is on a ray (`t >= 0`) inside the projection triangle, up to `tol`
    /// in barycentrics.
    pub fn is_visible(&self, tol: f64) -> bool {
        self.t >= 0.0 && self.u >= -tol && self.v >= -tol && self.u + self.v <= 1.0 + tol
    }
}

/// The images of the scene segment from `a` to `b` in the projection triangle of `cache`.
#[derive(Debug, Clone, Copy)]
pub struct EdgePath<'a> {
    pub cache: &'a ProjectionTriangleCache,
    pub a: DVec3,
    pub b: DVec3,
}

impl EdgePath<'_> {
    /// Where the plane of the parametric triangle at depth `t` cuts the line through `a` and
    /// `b`, as the parameter `s` of `a + s (b - a)`; `None` where the line is parallel to that
    /// plane or the plane is undefined (zero normal).
    pub fn segment_parameter(&self, t: f64) -> Option<f64> {
        let (origin, normal) = self.cache.plane_at(t);
        let denominator = normal.dot(self.b - self.a);
        let s = normal.dot(origin - self.a) / denominator;
        (denominator != 0.0 && s.is_finite()).then_some(s)
    }

    /// The image of the segment at depth `t` (module doc), the segment parameter clamped to
    /// `[0, 1]` against rounding; `None` in the degenerate cases of the module doc.
    pub fn at(&self, t: f64) -> Option<OutlinePoint> {
        let s = self.segment_parameter(t)?.clamp(0.0, 1.0);
        let point = self.a + s * (self.b - self.a);
        let (u, v) = self.cache.barycentrics_at(point, t)?;
        Some(OutlinePoint { u, v, t })
    }
}

/// The surface swept by one edge of a projection triangle, `r_i(t) + s (r_j(t) - r_i(t))`
/// (Eq. 5.1 corrected), in coordinates centred on `p_i` (the coplanarity test is invariant
/// under translation; centring avoids cancellation far from the origin). The products of
/// the edge's own vectors that every crossing needs are kept with it.
#[derive(Debug, Clone, Copy)]
pub struct EdgeSurface {
    origin: DVec3,
    /// `p_j - p_i`.
    base: DVec3,
    /// `n_i x n_j`.
    normals_cross: DVec3,
    /// `n_i x base`.
    normal_base_cross: DVec3,
    /// `n_i - n_j`.
    normals_difference: DVec3,
}

/// How far from zero, relative to the size of its terms (`|c2| t^2 + |c1| |t| + |c0|`),
/// the crossing quadratic must stay over a depth range for
/// [`CrossingQuadratic::clear_between`] to let a caller skip its roots. The root finder's estimates
/// have residuals of a few `f64::EPSILON` of that size (its tangency window accepts
/// `64 EPSILON` of the discriminant's), six orders of magnitude below this bound, so a
/// range the bound clears holds no root the solver could return.
const CLEAR_OF_ROOTS: f64 = 1e-9;

impl EdgeSurface {
    /// The surface of the edge from vertex `(p_i, n_i)` to `(p_j, n_j)`.
    pub fn new((p_i, n_i): (DVec3, DVec3), (p_j, n_j): (DVec3, DVec3)) -> EdgeSurface {
        let base = p_j - p_i;
        EdgeSurface {
            origin: p_i,
            base,
            normals_cross: n_i.cross(n_j),
            normal_base_cross: n_i.cross(base),
            normals_difference: n_i - n_j,
        }
    }

    /// The depths at which the line through `s1` and `s2` is coplanar with the projection
    /// edge, i.e. crosses its (extended) surface: the roots of `c2 t^2 + c1 t + c0` of the
    /// notes, with `p_i = 0`, `p_j = base`:
    /// `c2 = (s1 - s2).(n_i x n_j)`,
    /// `c1 = (s1 - s2).(n_i x base) + s1.(s2 x (n_i - n_j))`,
    /// `c0 = -s1.(s2 x base)`.
    /// Degenerate cases: a line coplanar with the edge at every depth (all coefficients zero)
    /// or never (a nonzero constant) gives no depth; a degree drop gives the remaining root.
    pub fn crossing_depths(&self, s1: DVec3, s2: DVec3) -> impl Iterator<Item = f64> {
        self.crossing_quadratic(s1, s2).roots().into_iter()
    }

    /// The crossing quadratic of [`EdgeSurface::crossing_depths`] for the line through `s1`,
    /// `s2`, kept so that a caller testing it over several depth ranges (the polygon edges
    /// imaging one scene edge) computes its coefficients once.
    pub fn crossing_quadratic(&self, s1: DVec3, s2: DVec3) -> CrossingQuadratic {
        let (s1, s2) = (s1 - self.origin, s2 - self.origin);
        let d = s1 - s2;
        let c2 = d.dot(self.normals_cross);
        let c1 = d.dot(self.normal_base_cross) + s1.dot(s2.cross(self.normals_difference));
        let c0 = -s1.dot(s2.cross(self.base));
        CrossingQuadratic([c2, c1, c0])
    }
}

/// `[c2, c1, c0]` of [`EdgeSurface::crossing_depths`] for one line and one edge surface.
#[derive(Debug, Clone, Copy)]
pub struct CrossingQuadratic([f64; 3]);

impl CrossingQuadratic {
    /// Whether none of [`CrossingQuadratic::roots`] can lie strictly between `lo` and `hi`,
    /// so that a caller may skip the root finding: the range has nothing strictly inside
    /// (`lo >= hi`, or a bound NaN), or the quadratic provably has no root in `[lo, hi]`: its
    /// value at `lo`, at `hi` and at its extremum (where that is inside) has one sign and is
    /// larger than [`CLEAR_OF_ROOTS`] times the size of its terms at either end (that size
    /// is convex in `t`, so the quadratic clears the bound over the whole range). A range
    /// found clear is clear for every range inside it. Most polygon edges of a small
    /// projection triangle cross no edge surface; this skips their root finding.
    ///
    /// Degenerate cases: non-finite coefficients or bounds, a quadratic vanishing
    /// identically or nearly touching zero in the range fail the test (`false`), and the
    /// caller goes to the root finder.
    pub fn clear_between(&self, lo: f64, hi: f64) -> bool {
        let has_inside = lo < hi;
        !has_inside || clear_of_roots(self.0, lo, hi)
    }

    /// All its roots, as [`EdgeSurface::crossing_depths`] gives them.
    pub fn roots(&self) -> Roots {
        let [c2, c1, c0] = self.0;
        solve_quadratic(c2, c1, c0)
    }
}

/// Whether `c2 t^2 + c1 t + c0` keeps one sign over `[lo, hi]`, away from zero by more than
/// [`CLEAR_OF_ROOTS`] times the size of its terms there (see
/// [`CrossingQuadratic::clear_between`]); `false` for any non-finite input.
fn clear_of_roots([c2, c1, c0]: [f64; 3], lo: f64, hi: f64) -> bool {
    let value = |t: f64| (c2 * t + c1) * t + c0;
    let size = |t: f64| (c2.abs() * t.abs() + c1.abs()) * t.abs() + c0.abs();
    let bound = CLEAR_OF_ROOTS * size(lo).max(size(hi));
    let (at_lo, at_hi) = (value(lo), value(hi));
    // `c2 != 0` with the extremum strictly inside: its value must clear the bound too.
    let extremum = -c1 / (2.0 * c2);
    let at_extremum = if lo < extremum && extremum < hi {
        value(extremum)
    } else {
        at_lo
    };
    let clear = |x: f64| x.abs() > bound && x.signum() == at_lo.signum();
    bound.is_finite() && clear(at_lo) && clear(at_hi) && clear(at_extremum)
}

/// Appends to `out` the interior samples of the edge piece from `a` to `b` (both images on
/// `path`, excluded), bisecting in depth while the exact image at the middle depth is more
/// than `tolerance` pixels from the chord `a b` on screen, at most `levels` times (so at most
/// `2^levels` segments). The test at the middle depth alone can miss a curve that crosses its
/// chord there (an S shape); the images of straight edges under a trilinear projection are
/// rational curves of low degree in `t`, and the first split already removes such a crossing
/// unless it sits exactly at the middle. The first `forced.levels` levels bisect without
/// the test where the piece is near a degenerate depth ([`Forced`]).
pub fn refine(
    path: &EdgePath,
    map: &ScreenMap,
    (a, b): (OutlinePoint, OutlinePoint),
    tolerance: f64,
    (levels, forced): (u32, Forced),
    out: &mut Vec<OutlinePoint>,
) {
    let t = 0.5 * (a.t + b.t);
    if levels == 0 || t == a.t || t == b.t {
        return;
    }
    if let Some(middle) = path.at(t) {
        refine_around(path, map, (a, middle, b), tolerance, (levels, forced), out);
    }
}

/// [`refine`] of the piece from `a` to `b` whose image at the middle depth,
/// `path.at(0.5 (a.t + b.t))`, is `middle`, already computed by the caller (the outline
/// tracer computes it to decide whether the piece is visible at all).
pub fn refine_around(
    path: &EdgePath,
    map: &ScreenMap,
    (a, middle, b): (OutlinePoint, OutlinePoint, OutlinePoint),
    tolerance: f64,
    (levels, forced): (u32, Forced),
    out: &mut Vec<OutlinePoint>,
) {
    if levels == 0 || middle.t == a.t || middle.t == b.t {
        return;
    }
    let (pa, pb, pm) = (
        map.pixel(a.u, a.v),
        map.pixel(b.u, b.v),
        map.pixel(middle.u, middle.v),
    );
    if !forced.applies(a.t, b.t) && distance_to_segment(pm, pa, pb) <= tolerance {
        return;
    }
    let next = (levels - 1, forced.next());
    refine(path, map, (a, middle), tolerance, next, out);
    out.push(middle);
    refine(path, map, (middle, b), tolerance, next, out);
}

/// Bisection levels of [`refine`] taken whatever the tolerance, near the depths at which the
/// projection triangle's parametric triangle degenerates: there an edge's image swings far
/// out and back within a piece, and the test at the middle alone can miss it
/// (`degenerate_band`). Its coordinates are ratios whose denominator, the parametric
/// triangle's area, vanishes at those depths; a piece beyond them, at a distance of at least
/// [`NEAR_DEGENERATE`] times its own depth extent, is bisected by the tolerance alone. Each
/// bisection halves the extent, so the forced levels run out first on the pieces far beyond
/// the degenerate depths; a piece reaching them, or before them, takes them all (before
/// them the test at the middle still misses detail: on the inverse-perspective example,
/// converging rays whose focus lies beyond the scene, freeing those pieces too raised the
/// relative RGB error against the ray caster from 0.00001 to 0.00007 at 800 x 800).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forced {
    pub levels: u32,
    /// The degenerate depths, first and last.
    pub around: (f64, f64),
}

/// How far beyond the last degenerate depth, in multiples of a piece's depth extent, a piece
/// must lie for [`Forced`] levels not to apply to it.
pub const NEAR_DEGENERATE: f64 = 4.0;

impl Forced {
    /// No forced level.
    pub const NONE: Forced = Forced {
        levels: 0,
        around: (0.0, 0.0),
    };

    /// Whether the piece from depth `a` to `b` is bisected whatever the tolerance. A NaN
    /// depth or bound gives `true` (bisected, as every piece of such a triangle was before
    /// the distance test).
    pub fn applies(&self, a: f64, b: f64) -> bool {
        // Not `f64::min`, which passes over a NaN.
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        let beyond = lo - self.around.1;
        self.levels > 0 && !(beyond > 0.0 && beyond >= NEAR_DEGENERATE * (hi - lo))
    }

    /// The levels left for the halves of a piece.
    fn next(self) -> Forced {
        Forced {
            levels: self.levels.saturating_sub(1),
            ..self
        }
    }
}

/// Euclidean distance from `p` to the segment `a b` (to `a` when the segment is a point).
fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let length_squared = d.length_squared();
    let s = if length_squared > 0.0 {
        ((p - a).dot(d) / length_squared).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + s * d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn triangle() -> ([DVec3; 3], [DVec3; 3]) {
        (
            [
                DVec3::new(-1.0, -1.0, 0.0),
                DVec3::new(1.0, -1.0, 0.1),
                DVec3::new(0.0, 1.0, -0.1),
            ],
            [
                DVec3::new(-0.4, -0.3, 1.0),
                DVec3::new(0.5, -0.2, 1.2),
                DVec3::new(0.1, 0.6, 0.9),
            ],
        )
    }

    proptest! {
        /// Every sample lies on the ray of its own (u, v) at its own t: the exact image.
        #[test]
        fn samples_are_exact_images(
            a in (-3.0..3.0f64, -3.0..3.0f64, 0.5..6.0f64),
            b in (-3.0..3.0f64, -3.0..3.0f64, 0.5..6.0f64),
            t in 0.0..8.0f64,
        ) {
            let (p, n) = triangle();
            let cache = ProjectionTriangleCache::new(p, n);
            let (a, b) = (DVec3::new(a.0, a.1, a.2), DVec3::new(b.0, b.1, b.2));
            let path = EdgePath { cache: &cache, a, b };
            if let Some(s) = path.segment_parameter(t) {
                if (0.0..=1.0).contains(&s) {
                    if let Some(x) = path.at(t) {
                        let point = a + s * (b - a);
                        let back = cache.ray_point(x.u, x.v, x.t);
                        prop_assert!((back - point).length() < 1e-8 * (1.0 + point.length()));
                    }
                }
            }
        }

        /// At every crossing depth the line's point is on the extended projection edge: the
        /// barycentric of the opposite vertex is zero (scene-space clipping).
        #[test]
        fn crossing_depths_land_on_the_edge_line(
            a in (-3.0..3.0f64, -3.0..3.0f64, 0.5..6.0f64),
            b in (-3.0..3.0f64, -3.0..3.0f64, 0.5..6.0f64),
        ) {
            let (p, n) = triangle();
            let cache = ProjectionTriangleCache::new(p, n);
            let (a, b) = (DVec3::new(a.0, a.1, a.2), DVec3::new(b.0, b.1, b.2));
            let path = EdgePath { cache: &cache, a, b };
            // u = 0 is the edge from vertex 1 to vertex 3.
            let surface = EdgeSurface::new((p[0], n[0]), (p[2], n[2]));
            for t in surface.crossing_depths(a, b) {
                let Some(s) = path.segment_parameter(t) else { continue };
                let point = a + s * (b - a);
                if let Some((u, _)) = cache.barycentrics_at(point, t) {
                    prop_assert!(u.abs() < 1e-7, "t {t} u {u}");
                }
            }
        }
    }

    /// Forced levels apply to a piece reaching the degenerate depths or before them, and
    /// to one beyond them by less than `NEAR_DEGENERATE` times its extent; not without
    /// levels, nor to a piece far beyond; a NaN depth keeps them (the old rule).
    #[test]
    fn forced_levels_apply_near_and_before_the_degenerate_depths() {
        let forced = Forced {
            levels: 5,
            around: (1.0, 2.0),
        };
        assert!(!Forced::NONE.applies(0.0, 1.0));
        assert!(forced.applies(0.5, 1.5), "reaching");
        assert!(forced.applies(1.2, 1.8), "between");
        assert!(forced.applies(0.1, 0.2), "before");
        assert!(forced.applies(3.0, 2.5), "beyond by less than 4 extents");
        assert!(!forced.applies(4.0, 4.5), "beyond by 4 extents");
        assert!(!forced.applies(100.0, 110.0), "far beyond");
        assert!(forced.applies(f64::NAN, 110.0));
        assert!(forced.applies(100.0, f64::NAN));
        assert!(!Forced {
            levels: 0,
            ..forced
        }
        .applies(0.5, 1.5));
        assert_eq!(forced.next().levels, 4);
        assert_eq!(Forced::NONE.next(), Forced::NONE);
    }

    /// The roots strictly inside `(lo, hi)`, in the solver's order.
    fn inside(depths: impl IntoIterator<Item = f64>, (lo, hi): (f64, f64)) -> Vec<f64> {
        depths.into_iter().filter(|&t| lo < t && t < hi).collect()
    }

    proptest! {
        /// The filtered crossings are exactly the unfiltered ones inside the range, for
        /// random ranges and for ranges ending at, just short of and just past each root.
        #[test]
        fn crossings_between_are_the_crossings_inside_the_range(
            a in (-3.0..3.0f64, -3.0..3.0f64, 0.5..6.0f64),
            b in (-3.0..3.0f64, -3.0..3.0f64, 0.5..6.0f64),
            lo in -4.0..8.0f64,
            length in 0.0..8.0f64,
            edge in 0usize..3,
        ) {
            let (p, n) = triangle();
            let [i, j] = [[0, 2], [0, 1], [1, 2]][edge];
            let surface = EdgeSurface::new((p[i], n[i]), (p[j], n[j]));
            let (a, b) = (DVec3::new(a.0, a.1, a.2), DVec3::new(b.0, b.1, b.2));
            let mut ranges = vec![(lo, lo + length)];
            for r in surface.crossing_depths(a, b) {
                let tiny = 1e-12 * (1.0 + r.abs());
                ranges.extend([
                    (r - length, r),
                    (r, r + length),
                    (r - tiny, r + tiny),
                    (r - length, r - tiny),
                    (r + tiny, r + length),
                    (r, r),
                ]);
            }
            let quadratic = surface.crossing_quadratic(a, b);
            for (lo, hi) in ranges {
                if quadratic.clear_between(lo, hi) {
                    prop_assert_eq!(
                        inside(surface.crossing_depths(a, b), (lo, hi)),
                        Vec::<f64>::new(),
                        "range {:?}", (lo, hi)
                    );
                }
            }
        }
    }

    /// The cases of `clear_of_roots`: a root or tangency in the range, a near-tangency (no
    /// real root, but within rounding of one), a degree drop, an identically zero or
    /// non-finite quadratic, and an empty range.
    #[test]
    fn clear_of_roots_only_where_no_root_can_be() {
        // (t - 1)^2: clear of [0, 0.5] and [1.5, 3], not of ranges reaching 1.
        assert!(clear_of_roots([1.0, -2.0, 1.0], 0.0, 0.5));
        assert!(clear_of_roots([1.0, -2.0, 1.0], 1.5, 3.0));
        assert!(!clear_of_roots([1.0, -2.0, 1.0], 0.0, 2.0));
        assert!(!clear_of_roots([1.0, -2.0, 1.0], 0.5, 1.0));
        // Complex roots 1e-7 off the axis: the solver's tangency window may still report
        // a double root at 1, so the range around it is not clear; far from it, it is.
        assert!(!clear_of_roots([1.0, -2.0, 1.0 + 1e-14], 0.0, 2.0));
        assert!(clear_of_roots([1.0, -2.0, 1.0 + 1e-14], 2.0, 3.0));
        // Two simple roots, 1 and 3, the extremum (2) between them: clear between the
        // roots, not across either.
        assert!(clear_of_roots([1.0, -4.0, 3.0], 1.5, 2.5));
        assert!(!clear_of_roots([1.0, -4.0, 3.0], 0.5, 1.5));
        assert!(!clear_of_roots([1.0, -4.0, 3.0], 2.5, 3.5));
        assert!(!clear_of_roots([1.0, -4.0, 3.0], 0.0, 4.0));
        // Linear (c2 = 0): root at 1.
        assert!(clear_of_roots([0.0, 1.0, -1.0], 0.0, 0.5));
        assert!(!clear_of_roots([0.0, 1.0, -1.0], 0.0, 2.0));
        // A nonzero constant never crosses; zero everywhere, non-finite input: not clear.
        assert!(clear_of_roots([0.0, 0.0, 2.0], -5.0, 5.0));
        assert!(!clear_of_roots([0.0; 3], 0.0, 1.0));
        assert!(!clear_of_roots([f64::NAN, 1.0, 1.0], 0.0, 1.0));
        assert!(!clear_of_roots([1.0, 0.0, 1.0], 0.0, f64::INFINITY));
        // The segment of `crossing_of_a_known_point`, crossing the edge surface at t = 2:
        // found in a range around 2; an empty or reversed range gives no crossing at all.
        let (p, n) = triangle();
        let cache = ProjectionTriangleCache::new(p, n);
        let surface = EdgeSurface::new((p[0], n[0]), (p[2], n[2]));
        let on_edge = cache.ray_point(0.0, 0.4, 2.0);
        let offset = DVec3::new(0.7, 0.2, -0.3);
        let (a, b) = (on_edge + offset, on_edge - offset * 1.5);
        let quadratic = surface.crossing_quadratic(a, b);
        assert!(!quadratic.clear_between(1.0, 3.0));
        let found = inside(quadratic.roots().as_slice().iter().copied(), (1.0, 3.0));
        assert!(found.iter().any(|t| (t - 2.0).abs() < 1e-10), "{found:?}");
        for (lo, hi) in [(2.0, 2.0), (3.0, 1.0), (f64::NAN, 3.0)] {
            assert!(quadratic.clear_between(lo, hi));
        }
    }

    #[test]
    fn crossing_of_a_known_point() {
        // A segment through the point at (u, v, t) = (0, 0.4, 2) of the edge u = 0.
        let (p, n) = triangle();
        let cache = ProjectionTriangleCache::new(p, n);
        let on_edge = cache.ray_point(0.0, 0.4, 2.0);
        let (a, b) = (
            on_edge + DVec3::new(0.7, 0.2, -0.3),
            on_edge - DVec3::new(0.7, 0.2, -0.3) * 1.5,
        );
        let surface = EdgeSurface::new((p[0], n[0]), (p[2], n[2]));
        let depths: Vec<f64> = surface.crossing_depths(a, b).collect();
        assert!(depths.iter().any(|t| (t - 2.0).abs() < 1e-10), "{depths:?}");
        let x = EdgePath {
            cache: &cache,
            a,
            b,
        }
        .at(2.0)
        .unwrap();
        assert!(x.u.abs() < 1e-10 && (x.v - 0.4).abs() < 1e-10, "{x:?}");
    }

    #[test]
    fn parallel_segment_has_no_image() {
        // Orthographic along z: the plane at depth t is z = t, and a segment in the plane
        // z = 2 is parallel to every one of them (no single crossing point, even at t = 2).
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let cache = ProjectionTriangleCache::new(p, [DVec3::Z; 3]);
        let path = EdgePath {
            cache: &cache,
            a: DVec3::new(0.1, 0.1, 2.0),
            b: DVec3::new(0.5, 0.2, 2.0),
        };
        assert!(path.at(1.0).is_none());
        assert_eq!(path.segment_parameter(2.0), None);
    }

    #[test]
    fn refinement_follows_a_curve_to_the_tolerance() {
        let (p, n) = triangle();
        let cache = ProjectionTriangleCache::new(p, n);
        let screen = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let map = ScreenMap::new(screen, DVec2::splat(400.0), cache);
        let path = EdgePath {
            cache: &cache,
            a: cache.ray_point(0.1, 0.1, 0.5),
            b: cache.ray_point(0.7, 0.2, 6.0),
        };
        let (a, b) = (path.at(0.5).unwrap(), path.at(6.0).unwrap());
        let mut out = Vec::new();
        refine(&path, &map, (a, b), 0.25, (10, Forced::NONE), &mut out);
        assert!(!out.is_empty(), "the image of this edge is curved");
        // Every chord is within the tolerance at densely sampled depths.
        let mut points = vec![a];
        points.extend(&out);
        points.push(b);
        for w in points.windows(2) {
            for k in 1..8 {
                let t = w[0].t + (w[1].t - w[0].t) * f64::from(k) / 8.0;
                let x = path.at(t).unwrap();
                let d = distance_to_segment(
                    map.pixel(x.u, x.v),
                    map.pixel(w[0].u, w[0].v),
                    map.pixel(w[1].u, w[1].v),
                );
                assert!(d < 0.5, "chord off by {d} px");
            }
        }
        // With no levels nothing is added; a straight image (orthographic) needs no sample.
        out.clear();
        refine(&path, &map, (a, b), 0.25, (0, Forced::NONE), &mut out);
        assert!(out.is_empty());
    }
}
