//! Pairs split at a depth where the projection triangle's parametric triangle degenerates.
//!
//! Where the parametric triangle `r1(t), r2(t), r3(t)` collapses to a segment at a depth
//! `t0` (rays converging onto a line, or crossing at a focus: a glass ball, the base plane of
//! detail in context inside the scene), the barycentrics of the scene points imaged near
//! `t0` grow without bound (`projection::trilinear::point_projection::fold`): a shape whose
//! depths reach across `t0` has an outline through infinity, which no polygon of sampled
//! points follows. Seen from the screen nothing is singular there: each pixel's projector
//! meets the scene triangle's plane once, at the depth `t = N / D` with `N` and `D` affine in
//! the barycentrics `(u, v)` (`hit_terms`), so the pixels that see the plane at depth `t` lie
//! on a line of the projection triangle, and those that see it at depths in `[lo, hi]` form
//! a region bounded by straight lines: where `s D > 0`, `s (N - lo D) >= 0` and
//! `s (hi D - N) >= 0`, for one sign `s` (at most two convex polygons).
//!
//! So such a pair is drawn in three depth ranges, split at the ends of the band
//! `[lo, hi] = [first (1 - BAND_MARGIN), last (1 + BAND_MARGIN)]` around the degenerate
//! depths `first..last` ([`DegenerateBand`]):
//!
//! - before and beyond the band, by its shapes: each shape reaching across the degenerate
//!   depths is traced with exact anchors at `lo` and `hi` on every edge (`outline`), and its
//!   outline is cut at `t <= lo` and at `t >= hi` (`clip::clip_to`). The cut passes through
//!   the anchors, and the part of each cut boundary that runs along `t = lo` is straight in
//!   `(u, v)` because the plane's image at one depth is a line: closed along that line in
//!   any order, the outline fills the same pixels by the non-zero rule. The outline between
//!   the anchors, through infinity, is cut away whatever it is.
//! - inside the band, by the region above ([`DegenerateBand::outlines`]), keyed pixel tested
//!   (`resolve::PIXEL_TESTED`): a superset of the pixels that see the scene triangle there,
//!   each fragment's exact hit deciding, and every fragment outside the triangle discarded.
//!
//! Every pixel drawn is thus an exact hit of its own projector with the scene triangle, as
//! the ray caster finds it. Degenerate cases (each has a test): a band polygon that is
//! empty, a line or a point is not drawn; a plane parallel to the projector at a corner
//! (`D = 0`) bounds the region by `s D >= 0` and gives no vertex an infinite depth (every
//! vertex gets the band's `lo`: only the terms decide a fragment's depth); a scene triangle
//! lying in a plane of depth `t0`, or reaching across it, is cut the same way (its band
//! polygon holds the pixels seeing it there). A scene vertex at `t0` itself has its genuine
//! root there, rejected with the spurious one, so its image count disagrees in parity with
//! the others' and no shapes are formed (`Unprojectable::OpenShape`): such a pair is drawn
//! pixel tested at every depth ([`DegenerateBand::everywhere`]).

use glam::DVec3;

use super::clip::{clip_outline, clip_to};
use super::edge_path::OutlinePoint;
use crate::projection::{ProjectionTriangleCache, Shape, TriangleShapes};

/// How far the band reaches past the degenerate depths, relative to them. Outline points
/// at the band's ends lie at barycentrics of the order of `1 / BAND_MARGIN` times the
/// scene's distance from the degenerate segment (far outside the triangle, cut by the
/// domain clip, and sampled to the curve tolerance as everywhere); a wider band only draws
/// more pixels by their per-pixel test.
pub const BAND_MARGIN: f64 = 0.05;

/// How near (relative to the scene triangle's distance from the degenerate segment) a
/// vertex must be to the plane through the segment to count as lying in it
/// ([`DegenerateBand::is_touched_by`]): far above rounding, far below a scene's detail.
const TOUCH_TOL: f64 = 1e-6;

/// The depths `[lo, hi]` drawn pixel tested around a projection triangle's degenerate
/// depths (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DegenerateBand {
    /// The degenerate depths, first and last (`ProjectionTriangleCache::degenerate_depths`).
    pub degenerate: (f64, f64),
    pub lo: f64,
    pub hi: f64,
}

/// A triangle containing the projection triangle's domain (with the clip's margin), cut
/// down to the band's region.
const START: [(f64, f64); 3] = [(-1.0, -1.0), (3.0, -1.0), (-1.0, 3.0)];

impl DegenerateBand {
    /// The band around the degenerate depths `(first, last)`, `0 < first <= last`.
    pub fn around((first, last): (f64, f64)) -> DegenerateBand {
        DegenerateBand {
            degenerate: (first, last),
            lo: first * (1.0 - BAND_MARGIN),
            hi: last * (1.0 + BAND_MARGIN),
        }
    }

    /// Every depth `t >= 0`: a pair of a degenerating projection triangle that has no shapes
    /// drawn pixel tested wherever its plane is seen (module doc).
    pub fn everywhere() -> DegenerateBand {
        DegenerateBand {
            degenerate: (0.0, f64::INFINITY),
            lo: 0.0,
            hi: f64::INFINITY,
        }
    }

    /// Whether `shape`'s vertex depths reach from before to beyond the degenerate depths
    /// (touching them counts): its outline is cut at the band. Shapes ending before or
    /// starting beyond them are bounded and drawn whole.
    pub fn is_reached_by(&self, shape: &Shape) -> bool {
        let (first, last) = self.degenerate;
        let depths = shape.vertices.iter().map(|x| x.t);
        let lo = depths.clone().fold(f64::INFINITY, f64::min);
        let hi = depths.fold(f64::NEG_INFINITY, f64::max);
        lo <= last && hi >= first
    }

    /// Whether the scene triangle `scene` meets, or lies in, the plane at a degenerate depth
    /// `t0` of `cache` (the limit of the parametric triangle's planes there: through `r1(t0)`
    /// with normal `N'(t0)`, `N` being quadratic, its central difference is exact up to
    /// rounding), a vertex within [`TOUCH_TOL`] of it counting as in it. Its points in that
    /// plane are seen at `t0`, but their genuine roots there are rejected with the spurious
    /// one, so its shapes need not reach `t0`: the band is drawn for it too.
    pub fn is_touched_by(&self, cache: &ProjectionTriangleCache, scene: [DVec3; 3]) -> bool {
        let (first, last) = self.degenerate;
        [first, last].into_iter().any(|t0| {
            let h = 0.5 * t0.abs().max(1.0);
            let (origin, _) = cache.plane_at(t0);
            let normal = (cache.plane_at(t0 + h).1 - cache.plane_at(t0 - h).1) / (2.0 * h);
            let sides = scene.map(|x| (x - origin).dot(normal));
            let reach = scene.iter().map(|x| x.distance(origin)).fold(0.0, f64::max);
            let tol = TOUCH_TOL * normal.length() * reach;
            let lies = sides.iter().any(|s| s.abs() <= tol);
            lies || (sides.iter().any(|&s| s > 0.0) && sides.iter().any(|&s| s < 0.0))
        })
    }

    /// Whether a shape of `shapes` reaches the degenerate depths ([`Self::is_reached_by`]).
    pub fn is_reached_by_any(&self, shapes: &TriangleShapes) -> bool {
        shapes.iter().any(|shape| self.is_reached_by(&shape))
    }

    /// Cuts the traced outline `traced` of a shape reaching the band into its parts before
    /// and beyond it, each clipped to the view plane and the domain, and calls `each` with
    /// every part left (two points or more); `outline` and `scratch` are reused storage.
    pub fn cut(
        &self,
        traced: &[OutlinePoint],
        (outline, scratch): (&mut Vec<OutlinePoint>, &mut Vec<OutlinePoint>),
        mut each: impl FnMut(&[OutlinePoint]),
    ) {
        let (lo, hi) = (self.lo, self.hi);
        let sides: [&dyn Fn(&OutlinePoint) -> f64; 2] = [&|p| lo - p.t, &|p| p.t - hi];
        for inside in sides {
            outline.clear();
            outline.extend_from_slice(traced);
            clip_to(outline, scratch, inside);
            clip_outline(outline, scratch);
            if outline.len() >= 2 {
                each(outline);
            }
        }
    }

    /// Calls `each` with the outline (barycentrics, each point at depth `lo`) of every
    /// non-empty region of the projection triangle of `cache` whose projectors meet the plane
    /// of the scene triangle `scene` at a depth in the band (module doc), clipped to the
    /// view plane and the domain; `outline` and `scratch` are reused storage. Nothing for a
    /// scene triangle without a plane.
    pub fn outlines(
        &self,
        cache: &ProjectionTriangleCache,
        [a, b, c]: [DVec3; 3],
        (outline, scratch): (&mut Vec<OutlinePoint>, &mut Vec<OutlinePoint>),
        mut each: impl FnMut(&[OutlinePoint]),
    ) {
        let normal = (b - a).cross(c - a);
        if normal == DVec3::ZERO || !normal.is_finite() {
            return;
        }
        // `N` and `D` of the hit `t = N / D` at barycentrics `(u, v)`: affine in them.
        let terms = |p: &OutlinePoint| {
            (
                normal.dot(a - cache.tripoint(p.u, p.v)),
                normal.dot(cache.trinorm(p.u, p.v)),
            )
        };
        let (lo, hi) = (self.lo, self.hi);
        for s in [1.0, -1.0] {
            outline.clear();
            outline.extend(START.map(|(u, v)| OutlinePoint { u, v, t: lo }));
            clip_to(outline, scratch, |p| s * terms(p).1);
            clip_to(outline, scratch, |p| {
                let (n, d) = terms(p);
                s * (n - lo * d)
            });
            if hi.is_finite() {
                clip_to(outline, scratch, |p| {
                    let (n, d) = terms(p);
                    s * (hi * d - n)
                });
            }
            for p in outline.iter_mut() {
                p.t = lo;
            }
            clip_outline(outline, scratch);
            if outline.len() >= 3 {
                each(outline);
            }
        }
    }
}

#[cfg(test)]
mod tests;
