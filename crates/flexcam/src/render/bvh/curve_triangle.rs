//! A BVH triangle as the quadratic projector's search reads it: the f64 form of the stored
//! f32 triangle with what its tests need precomputed once per scene (normal, squared area,
//! box, inward edge normals), so that the tests of a curve piece against a triangle are a
//! few dot products. Every value is computed by the same expressions the tests computed
//! per call before, so the hits found are bit for bit the same.
//!
//! The tests, cheapest first; each says "no hit on this piece" only where the analytic search
//! ([`CurveTriangle::intersect`]) could not report one:
//! - [`CurveTriangle::boxes_apart`]: the piece's control-point box and the triangle's box are
//!   apart (a hit lies in both);
//! - [`CurveTriangle::plane_misses`]: the piece's control points lie strictly on one side of
//!   the triangle's plane (the piece lies in their convex hull);
//! - [`CurveTriangle::edges_miss`]: the control points lie outside one edge's plane (the
//!   plane through the edge along the normal): the piece crosses the triangle's plane, but
//!   beside the triangle. The barycentric weights the search tests are linear functions of
//!   the point, so a hit on the piece, a convex combination of its control points, would
//!   have the weight negative too;
//! - [`CurveTriangle::chord_misses`]: the same edge test made on the part of the piece's
//!   chord that comes within the piece's pad of the triangle's plane, allowing the pad: the
//!   piece lies within its pad of its chord, so a hit lies within the pad of a chord point
//!   that is itself within the pad of the plane and of the inside of every edge. A short
//!   piece is nearly straight (its pad falls as the square of its length), so this narrows
//!   where the piece can cross the plane to nearly a point, where the control points span
//!   the whole piece: it leaves the root finding to little more than the triangles hit.
//!
//! These leave most triangles near a piece without root finding: the piece's padded chord
//! meets their leaf's box, but the piece passes beside them.

use glam::DVec3;

use super::triangle::PackedTriangle;
use crate::geometry::solve_quadratic;
use crate::projection::projector::quadratic_point;

/// Margin of the box and edge tests, relative to the largest coordinate magnitude of the
/// piece's control points and the triangle. The hit the root finding would report is
/// rounded off the exact piece and off the triangle by a few ulps of that magnitude (the
/// piece's control points by de Casteljau, the hit point and its barycentric test): far
/// below this margin, so that the tests drop no hit that the root finding would accept. It
/// stays far below any triangle of a model too, so the tests keep nearly all of their effect.
pub(in crate::render) const MARGIN: f64 = 1e-6;

/// Where a curve hits a triangle: the curve parameter and the barycentric weights of the
/// triangle's second and third vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::render) struct CurveHit {
    pub s: f64,
    pub barycentric: [f64; 2],
}

/// A triangle (first vertex, then the two edges from it) with its precomputed tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::render) struct CurveTriangle {
    v0: DVec3,
    e1: DVec3,
    e2: DVec3,
    /// e1 x e2 and its squared length (twice the area, squared); zero for a zero-area
    /// triangle, which is never hit.
    normal: DVec3,
    area2: f64,
    /// |e1 x e2|: distances along `normal` divided by it are distances to the plane.
    normal_length: f64,
    /// The triangle's box (its three corners) and its largest coordinate magnitude.
    lo: DVec3,
    hi: DVec3,
    scale: f64,
    /// Unit normals of the planes through the edges from v0 along e2 and along e1, pointing
    /// into the triangle: the signed distances of a point to them are its barycentric weights
    /// u and v times fixed positive factors. Zero for a zero-area triangle.
    inward_u: DVec3,
    inward_v: DVec3,
    /// The same for the edge from v0 + e1 to v0 + e2, as a unit normal pointing away from
    /// the triangle and the plane's distance from v0 along it: `(p - v0) . outward_w -
    /// offset_w` is the signed distance of p outside that edge (1 - u - v times a positive
    /// factor, negated).
    outward_w: DVec3,
    offset_w: f64,
}

impl CurveTriangle {
    /// The f64 form of `[v0, e1, e2]` with its tests precomputed.
    pub fn new([v0, e1, e2]: [DVec3; 3]) -> CurveTriangle {
        let normal = e1.cross(e2);
        let area2 = normal.length_squared();
        let (a, b) = (v0 + e1, v0 + e2);
        let (lo, hi) = (v0.min(a).min(b), v0.max(a).max(b));
        // u = (p - v0) . (e2 x n) / |n|^2, v = (p - v0) . (n x e1) / |n|^2, and
        // u + v = (p - v0) . ((e2 - e1) x n) / |n|^2.
        let w = (e2 - e1).cross(normal);
        let w_length = w.length();
        CurveTriangle {
            v0,
            e1,
            e2,
            normal,
            area2,
            normal_length: area2.sqrt(),
            lo,
            hi,
            scale: lo.abs().max(hi.abs()).max_element(),
            inward_u: e2.cross(normal).normalize_or_zero(),
            inward_v: normal.cross(e1).normalize_or_zero(),
            outward_w: w.normalize_or_zero(),
            offset_w: if w_length > 0.0 {
                area2 / w_length
            } else {
                0.0
            },
        }
    }

    /// The f64 form of a triangle as the BVH stores it (f32 vertex and edges).
    pub fn from_packed(t: &PackedTriangle) -> CurveTriangle {
        CurveTriangle::new([t.v0, t.e1, t.e2].map(|v| glam::Vec3::from(v).as_dvec3()))
    }

    /// [`MARGIN`] of the larger of `piece_scale` (the largest coordinate magnitude of a
    /// piece's control points) and the triangle's own: the absolute margin of
    /// [`CurveTriangle::boxes_apart`] and [`CurveTriangle::edges_miss`] for that piece.
    #[inline]
    pub fn margin(&self, piece_scale: f64) -> f64 {
        MARGIN * piece_scale.max(self.scale)
    }

    /// The smallest s in `[lo, hi]` at which curve `p` meets the closed triangle.
    /// Degenerate cases: a curve lying in the triangle's plane (the quadratic is identically
    /// zero) does not hit it, as a straight ray parallel to a triangle misses it; a double
    /// root (the curve touches the plane) is a hit where the touching point is inside; a
    /// point on an edge or vertex is inside (closed triangles); a zero-area triangle is
    /// never hit.
    pub fn intersect(&self, p: &[DVec3; 3], [lo, hi]: [f64; 2]) -> Option<CurveHit> {
        let (normal, area2) = (self.normal, self.area2);
        if area2 == 0.0 {
            return None;
        }
        let [x0, x1, x2] = p.map(|q| normal.dot(q - self.v0));
        let roots = solve_quadratic(x0 - 2.0 * x1 + x2, 2.0 * (x1 - x0), x0);
        roots
            .iter()
            .filter(|s| (lo..=hi).contains(s))
            .find_map(|s| {
                let w = quadratic_point(p, s) - self.v0;
                let u = w.cross(self.e2).dot(normal) / area2;
                let v = self.e1.cross(w).dot(normal) / area2;
                (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then_some(CurveHit {
                    s,
                    barycentric: [u, v],
                })
            })
    }

    /// Whether the box `[lo, hi]` (of a curve piece's control points) and the triangle's box
    /// are apart by more than `margin` ([`CurveTriangle::margin`]): a hit of the piece lies in
    /// both (on the piece, inside the hull of its control points, and on the triangle).
    /// Cheaper than the plane and edge tests and complementary to them. Degenerate cases: a
    /// triangle thinner than about 1e-9 radians, whose barycentric test rounds by more than
    /// the margin, may lose a hit that only that rounding gave; a NaN coordinate fails every
    /// comparison and never makes the boxes apart.
    #[inline]
    pub fn boxes_apart(&self, lo: DVec3, hi: DVec3, margin: f64) -> bool {
        let margin = DVec3::splat(margin);
        (lo - margin).cmpgt(self.hi).any() || (hi + margin).cmplt(self.lo).any()
    }

    /// Whether the control points `hull` of a curve piece lie strictly on one side of the
    /// triangle's plane: then the piece (inside their convex hull) cannot meet the triangle.
    /// Degenerate cases: a control point on the plane, or a zero-area triangle (every
    /// distance 0), is not strictly on one side and gives `false`.
    #[inline]
    pub fn plane_misses(&self, hull: &[DVec3; 3]) -> bool {
        let [x0, x1, x2] = hull.map(|q| self.normal.dot(q - self.v0));
        (x0 > 0.0 && x1 > 0.0 && x2 > 0.0) || (x0 < 0.0 && x1 < 0.0 && x2 < 0.0)
    }

    /// Whether the control points `hull` of a curve piece all lie more than `margin`
    /// ([`CurveTriangle::margin`]) outside the plane of one edge (through the edge, along the
    /// normal): then every point of the piece lies outside it too, its barycentric weight
    /// for that edge is negative, and the search cannot accept it. The margin covers the
    /// rounding of the search's own barycentric test (a few ulps of the coordinates, in
    /// distance). Degenerate cases: a zero-area triangle has zero edge normals and gives
    /// `false`; a NaN coordinate fails every comparison and gives `false`.
    #[inline]
    pub fn edges_miss(&self, hull: &[DVec3; 3], margin: f64) -> bool {
        let w = hull.map(|q| q - self.v0);
        let outside = |distance: &dyn Fn(DVec3) -> f64| w.iter().all(|&w| distance(w) > margin);
        outside(&|w| -w.dot(self.inward_u))
            || outside(&|w| -w.dot(self.inward_v))
            || outside(&|w| w.dot(self.outward_w) - self.offset_w)
    }

    /// Whether a curve piece with control points `hull` misses the triangle by its chord
    /// (from `hull[0]` to `hull[2]`): every point of the piece lies within `pad` (the middle
    /// control point's distance from the chord) of a chord point, so a hit X, on the plane
    /// and inside every edge plane, has a chord point C within `pad` of it, itself within
    /// `pad` of the plane and at most `pad` outside each edge plane (the distances are
    /// 1-Lipschitz). The chord points within `pad + margin` of the plane form one interval
    /// of the chord; the distance outside an edge plane is linear along it, so if both ends
    /// of that interval lie more than `pad + margin` outside one edge plane, no such C
    /// exists and the piece has no hit. `margin` ([`CurveTriangle::margin`]) covers the
    /// rounding of the control points, of this test and of the search's own hit point and
    /// barycentric test, as in [`CurveTriangle::edges_miss`]. Degenerate cases: a chord of
    /// zero length is a point (the whole chord is tested); a chord parallel to the plane
    /// within `pad + margin` of it is tested whole; a zero-area triangle has zero normals
    /// and gives `false`; a NaN coordinate or pad fails every rejection and gives `false`.
    #[inline]
    pub fn chord_misses(&self, hull: &[DVec3; 3], pad: f64, margin: f64) -> bool {
        let slack = pad + margin;
        let (w0, w2) = (hull[0] - self.v0, hull[2] - self.v0);
        // Distances to the plane times |normal|, as in `plane_misses`.
        let (d0, d2) = (self.normal.dot(w0), self.normal.dot(w2));
        let reach = slack * self.normal_length;
        if (d0 > reach && d2 > reach) || (d0 < -reach && d2 < -reach) {
            return true;
        }
        // The chord parameters [lo, hi] where the chord is within `reach` of the plane: one
        // end is inside the band or the chord crosses it (the case above is excluded). A
        // NaN bound makes `min`/`max` keep the other operand, so [0, 1] at worst.
        let step = d2 - d0;
        let (lo, hi) = if step == 0.0 {
            (0.0, 1.0)
        } else {
            let (ta, tb) = ((-reach - d0) / step, (reach - d0) / step);
            (ta.min(tb).max(0.0), ta.max(tb).min(1.0))
        };
        // Whether the chord over [lo, hi] lies more than `slack` outside an edge plane, from
        // the signed distances `e0`, `e2` of its ends inside it.
        let outside = |e0: f64, e2: f64| {
            let at = |t: f64| e0 + t * (e2 - e0);
            at(lo) < -slack && at(hi) < -slack
        };
        outside(w0.dot(self.inward_u), w2.dot(self.inward_u))
            || outside(w0.dot(self.inward_v), w2.dot(self.inward_v))
            || outside(
                self.offset_w - w0.dot(self.outward_w),
                self.offset_w - w2.dot(self.outward_w),
            )
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::render::raycast::pieces::piece;

    fn tri(a: DVec3, b: DVec3, c: DVec3) -> CurveTriangle {
        CurveTriangle::new([a, b - a, c - a])
    }

    /// The triangle z = 0 with corners (0,0), (1,0), (0,1).
    fn unit() -> CurveTriangle {
        tri(DVec3::ZERO, DVec3::X, DVec3::Y)
    }

    const FULL: [f64; 2] = [0.0, 1.0];

    #[test]
    fn a_straight_curve_hits_where_the_ray_does() {
        let p = [
            DVec3::new(0.2, 0.2, -1.0),
            DVec3::new(0.2, 0.2, 0.0),
            DVec3::new(0.2, 0.2, 1.0),
        ];
        let hit = unit().intersect(&p, FULL).unwrap();
        assert!((hit.s - 0.5).abs() < 1e-15);
        assert!((hit.barycentric[0] - 0.2).abs() < 1e-15);
    }

    #[test]
    fn the_second_root_counts_when_the_first_misses() {
        // The curve dips through z = 0 outside the triangle (x < 0), comes back up, and
        // crosses again at x = 0.5 inside it.
        let p = [
            DVec3::new(-1.5, 0.1, 1.0),
            DVec3::new(0.0, 0.1, -2.0),
            DVec3::new(1.5, 0.1, 1.0),
        ];
        let big = tri(
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        );
        let hit = big.intersect(&p, FULL).unwrap();
        assert!(hit.s > 0.5, "{hit:?}");
        let at = quadratic_point(&p, hit.s);
        assert!(at.z.abs() < 1e-12 && at.x > 0.0);
    }

    #[test]
    fn a_tangent_curve_touching_inside_is_a_double_root_hit() {
        // z(s) = 0.5 (1 - 2 s)^2 touches z = 0 at s = 1/2, at (0.25, 0.25).
        let p = [
            DVec3::new(0.0, 0.25, 0.5),
            DVec3::new(0.25, 0.25, -0.5),
            DVec3::new(0.5, 0.25, 0.5),
        ];
        let hit = unit().intersect(&p, FULL).unwrap();
        assert!((hit.s - 0.5).abs() < 1e-7, "{hit:?}");
        // Lifted slightly, it misses; touching outside misses too.
        let lifted = p.map(|q| q + DVec3::Z * 1e-6);
        assert_eq!(unit().intersect(&lifted, FULL), None);
        let outside = p.map(|q| q + DVec3::X * 2.0);
        assert_eq!(unit().intersect(&outside, FULL), None);
    }

    #[test]
    fn a_curve_in_the_plane_or_parallel_to_it_misses() {
        let in_plane = [
            DVec3::ZERO,
            DVec3::new(0.3, 0.1, 0.0),
            DVec3::new(0.2, 0.5, 0.0),
        ];
        assert_eq!(unit().intersect(&in_plane, FULL), None);
        // Tangent parallel to the plane everywhere, above it.
        let parallel = in_plane.map(|q| q + DVec3::Z);
        assert_eq!(unit().intersect(&parallel, FULL), None);
    }

    #[test]
    fn a_curve_through_an_edge_or_vertex_hits_and_is_not_rejected() {
        // Crosses z = 0 at s = 1/2 exactly on the hypotenuse x + y = 1 at (0.5, 0.5).
        let p = [
            DVec3::new(0.5, 0.5, -1.0),
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(0.5, 0.5, 1.0),
        ];
        let hit = unit().intersect(&p, FULL).unwrap();
        assert!((hit.barycentric[0] + hit.barycentric[1] - 1.0).abs() < 1e-15);
        let margin = unit().margin(1.0);
        assert!(!unit().edges_miss(&p, margin));
        // Through the vertex at the origin, and along the edges u = 0 and v = 0.
        let vertex = p.map(|q| q - DVec3::new(0.5, 0.5, 0.0));
        assert!(unit().intersect(&vertex, FULL).is_some());
        assert!(!unit().edges_miss(&vertex, margin));
        for edge in [DVec3::new(0.0, 0.3, 0.0), DVec3::new(0.3, 0.0, 0.0)] {
            let on_edge = vertex.map(|q| q + edge);
            assert!(unit().intersect(&on_edge, FULL).is_some());
            assert!(!unit().edges_miss(&on_edge, margin));
        }
    }

    #[test]
    fn zero_area_triangles_and_out_of_range_roots_miss() {
        let p = [
            DVec3::new(0.2, 0.2, -1.0),
            DVec3::new(0.2, 0.2, 0.0),
            DVec3::new(0.2, 0.2, 1.0),
        ];
        let flat = tri(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert_eq!(flat.intersect(&p, FULL), None);
        assert_eq!(unit().intersect(&p, [0.0, 0.49]), None);
        assert!(unit().intersect(&p, [0.5, 0.5]).is_some());
    }

    #[test]
    fn boxes_apart_only_beyond_the_margin() {
        let t = unit();
        // Just beyond x = 1 by more than the margin: apart; within it: not.
        let x = |d: f64| DVec3::new(1.0 + d, 0.0, 0.0);
        let margin = t.margin(2.0);
        assert!(t.boxes_apart(x(1e-3), x(2.0), margin));
        assert!(!t.boxes_apart(x(1e-7), x(2.0), margin));
        // Below z = 0 or overlapping: apart only when separated.
        let m = t.margin(2.0);
        assert!(t.boxes_apart(DVec3::new(0.1, 0.1, -2.0), DVec3::new(0.2, 0.2, -1.0), m));
        assert!(!t.boxes_apart(DVec3::new(0.1, 0.1, -2.0), DVec3::new(0.2, 0.2, 1.0), m));
        // Degenerate case: a coordinate that is not finite is never apart.
        let nan = DVec3::new(f64::NAN, 0.1, 0.0);
        assert!(!t.boxes_apart(nan, nan, t.margin(f64::NAN)));
    }

    #[test]
    fn a_hull_on_one_side_of_the_plane_misses_and_a_crossing_one_does_not() {
        let above = [
            DVec3::new(0.2, 0.2, 0.1),
            DVec3::new(0.3, 0.2, 0.5),
            DVec3::Z,
        ];
        assert!(unit().plane_misses(&above));
        assert!(unit().plane_misses(&above.map(|q| -q)));
        let crossing = [above[0], above[1], -DVec3::Z];
        assert!(!unit().plane_misses(&crossing));
        // Degenerate cases: a control point on the plane, a zero-area triangle.
        let touching = [above[0], DVec3::new(0.3, 0.2, 0.0), above[2]];
        assert!(!unit().plane_misses(&touching));
        let flat = tri(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert!(!flat.plane_misses(&above));
    }

    #[test]
    fn a_hull_beside_each_edge_misses_and_one_over_the_triangle_does_not() {
        let t = unit();
        let margin = t.margin(2.0);
        // A piece crossing z = 0 at x = -0.1 (beside the edge u = 0... the y axis), at
        // y = -0.1 (beside v = 0), and at x = y = 0.6 (beyond the hypotenuse).
        let crossing_at = |x: f64, y: f64| {
            [
                DVec3::new(x, y, -1.0),
                DVec3::new(x, y, 0.0),
                DVec3::new(x, y, 1.0),
            ]
        };
        for (x, y) in [(-0.1, 0.3), (0.3, -0.1), (0.6, 0.6)] {
            let p = crossing_at(x, y);
            assert!(t.edges_miss(&p, margin), "({x}, {y})");
            assert!(!t.plane_misses(&p));
            assert_eq!(t.intersect(&p, FULL), None);
        }
        // Inside, and just outside by less than the margin: kept.
        assert!(!t.edges_miss(&crossing_at(0.3, 0.3), margin));
        assert!(!t.edges_miss(&crossing_at(-1e-7, 0.3), margin));
        assert!(!t.edges_miss(&crossing_at(0.5 + 1e-7, 0.5), margin));
        // A piece whose control points straddle an edge plane is kept even though the
        // points are each outside some edge.
        let straddle = [
            DVec3::new(-0.5, 0.2, -1.0),
            DVec3::new(0.2, -0.5, 0.0),
            DVec3::new(0.9, 0.9, 1.0),
        ];
        assert!(!t.edges_miss(&straddle, margin));
        // Degenerate cases: a zero-area triangle, a NaN control point.
        let flat = tri(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert!(!flat.edges_miss(&crossing_at(5.0, 5.0), margin));
        let nan = crossing_at(f64::NAN, 5.0);
        assert!(!t.edges_miss(&nan, margin));
    }

    /// The piece's pad as the search computes it: the middle control point's distance from
    /// the chord.
    fn pad(q: &[DVec3; 3]) -> f64 {
        let d = q[2] - q[0];
        let s = if d.length_squared() > 0.0 {
            ((q[1] - q[0]).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (q[1] - (q[0] + s * d)).length()
    }

    #[test]
    fn a_chord_crossing_beside_the_triangle_misses_where_the_control_points_do_not() {
        let t = unit();
        let margin = t.margin(4.0);
        // A straight oblique piece crossing z = 0 at (x, y): its control points straddle the
        // edge planes x = 0 and x + y = 1, so only the chord test can reject it.
        let oblique = |x: f64, y: f64| {
            [
                DVec3::new(x - 2.6, y, -1.0),
                DVec3::new(x, y, 0.0),
                DVec3::new(x + 2.6, y, 1.0),
            ]
        };
        let beyond = oblique(0.6, 0.6);
        assert!(!t.plane_misses(&beyond) && !t.edges_miss(&beyond, margin));
        assert!(t.chord_misses(&beyond, pad(&beyond), margin));
        assert_eq!(t.intersect(&beyond, FULL), None);
        // Inside, and outside by less than the margin: kept (and the first hits).
        let inside = oblique(0.3, 0.3);
        assert!(!t.chord_misses(&inside, pad(&inside), margin));
        assert!(t.intersect(&inside, FULL).is_some());
        let grazing = oblique(0.5 + 1e-7, 0.5);
        assert!(!t.chord_misses(&grazing, pad(&grazing), margin));
        // The same chord with the middle control point pulled towards the triangle: the curve
        // crosses at (0.4, 0.4), inside, and the pad keeps it.
        let bent = [beyond[0], DVec3::new(0.2, 0.2, 0.0), beyond[2]];
        assert!(t.intersect(&bent, FULL).is_some());
        assert!(!t.chord_misses(&bent, pad(&bent), margin));
    }

    #[test]
    fn degenerate_chords_and_triangles_in_the_chord_test() {
        let t = unit();
        let margin = t.margin(4.0);
        // A chord of zero length (a closed curve crossing z = 0 twice at one point): tested
        // as its point with the pad (2): kept over the triangle, missed far beside it.
        let closed = |x: f64, y: f64| {
            [
                DVec3::new(x, y, -1.0),
                DVec3::new(x, y, 1.0),
                DVec3::new(x, y, -1.0),
            ]
        };
        assert!(!t.chord_misses(&closed(0.3, 0.3), 2.0, margin));
        assert!(t.intersect(&closed(0.3, 0.3), FULL).is_some());
        assert!(t.chord_misses(&closed(5.0, 5.0), 2.0, margin));
        assert_eq!(t.intersect(&closed(5.0, 5.0), FULL), None);
        // A chord parallel to the plane within the pad of it: tested whole (missed only if
        // all of it lies beside one edge).
        let parallel = |y: f64| {
            [
                DVec3::new(-1.0, y, 1e-4),
                DVec3::new(0.5, y, -1e-4),
                DVec3::new(2.0, y, 1e-4),
            ]
        };
        assert!(!t.chord_misses(&parallel(0.3), 2e-4, margin));
        assert!(t.chord_misses(&parallel(-0.5), 2e-4, margin));
        // A zero-area triangle, a NaN control point, a NaN pad.
        let flat = tri(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert!(!flat.chord_misses(&closed(5.0, 5.0), 0.0, margin));
        let mut nan = closed(5.0, 5.0);
        nan[0].x = f64::NAN;
        assert!(!t.chord_misses(&nan, 2.0, margin));
        assert!(!t.chord_misses(&closed(5.0, 5.0), f64::NAN, margin));
    }

    fn point() -> impl Strategy<Value = DVec3> {
        (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    /// A random curve's control points, a random triangle's corners, and a random piece
    /// `[lo, hi]` of the curve's range (possibly empty at 1).
    fn curve_triangle_range() -> impl Strategy<Value = ([DVec3; 3], [DVec3; 3], [f64; 2])> {
        (
            [point(), point(), point()],
            [point(), point(), point()],
            0.0..1.0f64,
            0.0..1.0f64,
        )
            .prop_map(|(p, corners, lo, width)| (p, corners, [lo, (lo + width).min(1.0)]))
    }

    /// The first s of a dense sampling of the curve at which it is on the other side of the
    /// plane from its start and the crossing lies inside the triangle, located to `1 / n`.
    fn dense_first_hit(p: &[DVec3; 3], [v0, e1, e2]: [DVec3; 3], n: usize) -> Option<f64> {
        let normal = e1.cross(e2);
        let side = |s: f64| normal.dot(quadratic_point(p, s) - v0);
        (0..n).find_map(|k| {
            let (a, b) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
            if (side(a) > 0.0) == (side(b) > 0.0) {
                return None;
            }
            let s = a + (b - a) * side(a) / (side(a) - side(b));
            let w = quadratic_point(p, s) - v0;
            let area2 = normal.length_squared();
            let u = w.cross(e2).dot(normal) / area2;
            let v = e1.cross(w).dot(normal) / area2;
            (u > 1e-6 && v > 1e-6 && u + v < 1.0 - 1e-6).then_some(s)
        })
    }

    proptest! {
        /// The plane test never rejects a piece that hits: wherever it says a piece misses
        /// the triangle's plane, the analytic search over that piece finds nothing.
        #[test]
        fn a_rejected_piece_has_no_hit((p, [a, b, c], [lo, hi]) in curve_triangle_range()) {
            let t = tri(a, b, c);
            if t.plane_misses(&piece(&p, lo, hi)) {
                prop_assert_eq!(t.intersect(&p, [lo, hi]), None);
            }
        }

        /// Nor does the edge test: on random pieces, and on pieces moved so that half of
        /// them lie just outside an edge plane (2e-5, beyond the margin of these
        /// coordinates, which stay below 20, and far above rounding), where the test must
        /// reject them.
        #[test]
        fn a_piece_beside_an_edge_has_no_hit(
            (p, [a, b, c], [lo, hi]) in curve_triangle_range(),
            edge in 0..3usize,
            grazing in any::<bool>(),
        ) {
            let t = tri(a, b, c);
            let q = piece(&p, lo, hi);
            let (normal, offset) = match edge {
                0 => (-t.inward_u, 0.0),
                1 => (-t.inward_v, 0.0),
                _ => (t.outward_w, t.offset_w),
            };
            let shifted = grazing && normal != DVec3::ZERO;
            let p = if shifted {
                // Move the curve along the edge plane's normal until the piece's control
                // point nearest the plane lies 2e-5 outside it.
                let nearest = q
                    .iter()
                    .map(|w| (*w - t.v0).dot(normal) - offset)
                    .fold(f64::INFINITY, f64::min);
                p.map(|x| x + normal * (2e-5 - nearest))
            } else {
                p
            };
            let q = piece(&p, lo, hi);
            let scale = q.iter().fold(0.0f64, |m, x| m.max(x.abs().max_element()));
            let rejected = t.edges_miss(&q, t.margin(scale));
            prop_assert!(rejected || !shifted, "a piece outside an edge plane is kept");
            if rejected {
                prop_assert_eq!(t.intersect(&p, [lo, hi]), None);
            }
        }

        /// The chord test never rejects a piece that hits: on random pieces, and on
        /// triangles placed so that the piece crosses their plane at a random point of the
        /// piece, at barycentric weights (u, v) around the triangle (inside, on, or just
        /// outside an edge), where a piece crossing inside must be kept.
        #[test]
        fn a_piece_missed_by_its_chord_has_no_hit(
            (p, [a, b, c], [lo, hi]) in curve_triangle_range(),
            at in 0.0..1.0f64,
            (u, v) in (-0.3..1.3f64, -0.3..1.3f64),
            placed in any::<bool>(),
        ) {
            let q = piece(&p, lo, hi);
            let (a, b, c) = if placed {
                // Move the triangle so that its point at (u, v) is the curve's at `at`.
                let crossing = quadratic_point(&p, lo + at * (hi - lo));
                let shift = crossing - (a + u * (b - a) + v * (c - a));
                (a + shift, b + shift, c + shift)
            } else {
                (a, b, c)
            };
            let t = tri(a, b, c);
            let scale = q.iter().fold(0.0f64, |m, x| m.max(x.abs().max_element()));
            if t.chord_misses(&q, pad(&q), t.margin(scale)) {
                prop_assert_eq!(t.intersect(&p, [lo, hi]), None);
                let inside = u > 1e-3 && v > 1e-3 && u + v < 1.0 - 1e-3;
                prop_assert!(!(placed && inside), "a crossing inside is kept");
            }
        }

        /// A piece whose control points' box is apart from a triangle's box has no hit on
        /// it; boxes that overlap or touch are never apart.
        #[test]
        fn a_piece_boxed_apart_has_no_hit((p, [a, b, c], [lo, hi]) in curve_triangle_range()) {
            let t = tri(a, b, c);
            let q = piece(&p, lo, hi);
            let (q_lo, q_hi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
            let margin = t.margin(q_lo.abs().max(q_hi.abs()).max_element());
            if t.boxes_apart(q_lo, q_hi, margin) {
                prop_assert_eq!(t.intersect(&p, [lo, hi]), None);
            }
            // The triangle's own box is never apart from itself, nor from a box inside it.
            let t_lo = a.min(b).min(c);
            let t_hi = a.max(b).max(c);
            prop_assert!(!t.boxes_apart(t_lo, t_hi, t.margin(0.0)));
            prop_assert!(!t.boxes_apart(a, a, t.margin(0.0)));
        }

        /// The analytic first hit agrees with dense sampling of the curve wherever the
        /// sampled crossing is clearly inside the triangle.
        #[test]
        fn analytic_hit_matches_dense_sampling(
            p0 in point(), p1 in point(), p2 in point(),
            a in point(), b in point(), c in point(),
        ) {
            let p = [p0, p1, p2];
            let corners = [a, b - a, c - a];
            prop_assume!(corners[1].cross(corners[2]).length() > 1e-3);
            let dense = dense_first_hit(&p, corners, 4096);
            let analytic = CurveTriangle::new(corners).intersect(&p, FULL);
            if let Some(s) = dense {
                let hit = analytic.expect("dense sampling found a hit");
                // The analytic hit is at the sampled one, or at an earlier tangential touch
                // (which sampling by sign changes cannot see).
                prop_assert!(hit.s <= s + 1e-3, "analytic {} dense {}", hit.s, s);
                let q = quadratic_point(&p, hit.s);
                let normal = corners[1].cross(corners[2]).normalize();
                prop_assert!(normal.dot(q - a).abs() < 1e-9);
            }
        }
    }
}
