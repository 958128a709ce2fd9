//! The first hit of a quadratic Bezier projector (seed 003, 7.2), found analytically and
//! accelerated by the BVH.
//!
//! Per triangle, the signed distance of B(s) = (1-s)^2 P0 + 2 s (1-s) P1 + s^2 P2 to the
//! triangle's plane is the quadratic a s^2 + b s + c with x_k = n . (P_k - V0),
//! a = x0 - 2 x1 + x2, b = 2 (x1 - x0), c = x0. Both roots in the accepted range are tested against the
//! triangle, nearest first (the thesis's appendix B keeps only the smaller root: wrong, a
//! curve can cross the plane outside the triangle first and inside it second).
//!
//! Acceleration: the curve is cut into [`PIECES`] pieces by de Casteljau, visited in order of
//! s. A piece lies in the convex hull of its three control points, hence within
//! `pad = dist(middle control point, chord)` of its chord; the BVH visits only leaves whose
//! box, enlarged by `pad`, the chord meets, and the first piece with a hit ends the search.
//! The whole curve is first tested the same way against the scene's box alone, and each
//! piece against it by the box of the piece's control points before its chord is built; in
//! a leaf, a triangle whose box is apart from that box, or whose plane the piece's control
//! points lie strictly on one side of, is skipped without root finding (the piece cannot
//! meet it).
//!
//! Degenerate cases: a curve lying in a triangle's plane (the quadratic is identically zero)
//! does not hit it, as a straight ray parallel to a triangle misses it; a double root (the
//! curve touches the plane) is a hit where the touching point is inside; a point on an edge
//! or vertex is inside (closed triangles); a zero-area triangle is never stored in the BVH.

use glam::{DVec3, Vec2};

use super::bvh::NearSegment;
use super::hull_cull::LiveParts;
use super::triangle::PackedTriangle;
use super::{Hit32, RayCaster};
use crate::geometry::solve_quadratic;
use crate::projection::projector::{quadratic_point, quadratic_tangent};

/// Pieces the curve is cut into for the BVH search: more pieces give thinner fattened chords
/// (the padding falls as 1/PIECES^2) but more traversals.
pub(super) const PIECES: usize = 8;

/// The parameter interval [a, b] of piece `k` of [`PIECES`].
pub(super) fn piece_interval(k: usize) -> (f64, f64) {
    (k as f64 / PIECES as f64, (k + 1) as f64 / PIECES as f64)
}

/// Where a curve hits a triangle: the curve parameter and the barycentric weights of the
/// triangle's second and third vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct CurveHit {
    pub s: f64,
    pub barycentric: [f64; 2],
}

/// The smallest s in `[lo, hi]` at which curve `p` meets the closed triangle `tri` (first
/// vertex, then the two edges from it), see the module documentation for the degenerate
/// cases.
pub(super) fn intersect_quadratic_triangle(
    p: &[DVec3; 3],
    [v0, e1, e2]: [DVec3; 3],
    [lo, hi]: [f64; 2],
) -> Option<CurveHit> {
    let normal = e1.cross(e2);
    let area2 = normal.length_squared();
    if area2 == 0.0 {
        return None;
    }
    let [x0, x1, x2] = p.map(|q| normal.dot(q - v0));
    let roots = solve_quadratic(x0 - 2.0 * x1 + x2, 2.0 * (x1 - x0), x0);
    roots
        .iter()
        .filter(|s| (lo..=hi).contains(s))
        .find_map(|s| {
            let w = quadratic_point(p, s) - v0;
            let u = w.cross(e2).dot(normal) / area2;
            let v = e1.cross(w).dot(normal) / area2;
            (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then_some(CurveHit {
                s,
                barycentric: [u, v],
            })
        })
}

/// Whether the curve piece with control points `hull` lies strictly on one side of the plane
/// of triangle `[v0, e1, e2]`: then the piece (inside the convex hull of its control points)
/// cannot meet the triangle, and the root finding is skipped. A cheap first test: most
/// triangles near a piece's chord are not crossed by it. Degenerate cases: a control point
/// on the plane, or a zero-area triangle (every distance 0), is not strictly on one side and
/// gives `false`, leaving the decision to [`intersect_quadratic_triangle`].
fn hull_misses_plane(hull: &[DVec3; 3], [v0, e1, e2]: [DVec3; 3]) -> bool {
    let normal = e1.cross(e2);
    let [x0, x1, x2] = hull.map(|q| normal.dot(q - v0));
    (x0 > 0.0 && x1 > 0.0 && x2 > 0.0) || (x0 < 0.0 && x1 < 0.0 && x2 < 0.0)
}

/// Margin of [`boxes_apart`], relative to the largest coordinate magnitude of either box.
/// The hit the root finding would report is rounded off the exact piece and off the
/// triangle by a few ulps of that magnitude (the piece's control points by de Casteljau, the
/// hit point and its barycentric test): far below this margin, so that the test drops no hit
/// that the root finding would accept. It stays far below any triangle of a model too, so
/// the test keeps nearly all of its effect.
const BOX_MARGIN: f64 = 1e-6;

/// Whether the box `[lo, hi]` (of a curve piece's control points) and the box of triangle
/// `[v0, e1, e2]` (its corners v0, v0 + e1, v0 + e2) are apart by more than [`BOX_MARGIN`]:
/// a hit of the piece lies in both (on the piece, inside the hull of its control points,
/// and on the triangle), so the root finding is skipped. Cheaper than
/// [`hull_misses_plane`] (no cross product) and complementary to it: most triangles a piece's
/// padded chord comes near lie beside the piece, their planes crossed by it. Degenerate
/// cases: a triangle thinner than about 1e-9 radians, whose barycentric test rounds by more
/// than the margin, may lose a hit that only that rounding gave; a NaN coordinate fails
/// every comparison and never makes the boxes apart.
fn boxes_apart(lo: DVec3, hi: DVec3, [v0, e1, e2]: [DVec3; 3]) -> bool {
    let (a, b) = (v0 + e1, v0 + e2);
    let (t_lo, t_hi) = (v0.min(a).min(b), v0.max(a).max(b));
    let scale = lo
        .abs()
        .max(hi.abs())
        .max(t_lo.abs())
        .max(t_hi.abs())
        .max_element();
    let margin = DVec3::splat(BOX_MARGIN * scale);
    (lo - margin).cmpgt(t_hi).any() || (hi + margin).cmplt(t_lo).any()
}

/// The control points of the piece of curve `p` over [a, b] (blossoming: the end points and
/// the intersection of the end tangents).
pub(super) fn piece(p: &[DVec3; 3], a: f64, b: f64) -> [DVec3; 3] {
    let start = quadratic_point(p, a);
    [
        start,
        start + 0.5 * (b - a) * quadratic_tangent(p, a),
        quadratic_point(p, b),
    ]
}

/// The distance from `q` to the segment from `a` to `b`.
fn distance_to_segment(q: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let len2 = d.length_squared();
    let s = if len2 > 0.0 {
        ((q - a).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (q - (a + s * d)).length()
}

impl RayCaster {
    /// The first hit (smallest s in [0, 1]) of quadratic Bezier curve `p`, as the curve
    /// parameter and the hit in the f32 form of the straight search (`t` = 0: the shading
    /// ray starts at the hit). `None` when nothing is hit or a control point is not finite.
    /// Pieces that `live` rules out (see `hull_cull`) are skipped: their control-point box
    /// is known to miss the scene's box.
    pub(super) fn intersect_quadratic(
        &self,
        p: &[DVec3; 3],
        live: LiveParts,
    ) -> Option<(f64, Hit32)> {
        // The whole curve first (within its middle control point's distance of its chord):
        // the projectors of many pixels pass by the scene's box altogether.
        let whole = NearSegment::new(p[0], p[2] - p[0], distance_to_segment(p[1], p[0], p[2]))?;
        if !self.bvh.near_root(&whole) {
            return None;
        }
        for k in 0..PIECES {
            if !live.may_hit(k) {
                continue;
            }
            let (a, b) = piece_interval(k);
            let q = piece(p, a, b);
            // The piece lies in the box of its control points: most pieces of a projector
            // that passes the scene are outside its box, and cost only this comparison.
            let (lo, hi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
            if !self.bvh.root_overlaps(lo, hi) {
                continue;
            }
            let pad = distance_to_segment(q[1], q[0], q[2]);
            let segment = NearSegment::new(q[0], q[2] - q[0], pad)?;
            let mut best: Option<(u32, CurveHit)> = None;
            self.bvh
                .visit_near_segment(&segment, |id, tri: &PackedTriangle| {
                    let tri = [tri.v0, tri.e1, tri.e2].map(|v| glam::Vec3::from(v).as_dvec3());
                    if boxes_apart(lo, hi, tri) || hull_misses_plane(&q, tri) {
                        return;
                    }
                    let hi = best.map_or(b, |(_, h)| h.s);
                    if let Some(hit) = intersect_quadratic_triangle(p, tri, [a, hi]) {
                        if best.is_none_or(|(_, h)| hit.s < h.s) {
                            best = Some((id, hit));
                        }
                    }
                });
            if let Some((id, hit)) = best {
                let found = self.hit32(super::bvh::BvhHit {
                    id,
                    hit: super::triangle::FastHit {
                        t: 0.0,
                        u: hit.barycentric[0] as f32,
                        v: hit.barycentric[1] as f32,
                    },
                });
                debug_assert_eq!(
                    found.barycentric,
                    Vec2::new(hit.barycentric[0] as f32, hit.barycentric[1] as f32)
                );
                return Some((hit.s, found));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    fn tri(a: DVec3, b: DVec3, c: DVec3) -> [DVec3; 3] {
        [a, b - a, c - a]
    }

    /// The triangle z = 0 with corners (0,0), (1,0), (0,1).
    fn unit() -> [DVec3; 3] {
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
        let hit = intersect_quadratic_triangle(&p, unit(), FULL).unwrap();
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
        let hit = intersect_quadratic_triangle(
            &p,
            tri(
                DVec3::ZERO,
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
            ),
            FULL,
        )
        .unwrap();
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
        let hit = intersect_quadratic_triangle(&p, unit(), FULL).unwrap();
        assert!((hit.s - 0.5).abs() < 1e-7, "{hit:?}");
        // Lifted slightly, it misses; touching outside misses too.
        let lifted = p.map(|q| q + DVec3::Z * 1e-6);
        assert_eq!(intersect_quadratic_triangle(&lifted, unit(), FULL), None);
        let outside = p.map(|q| q + DVec3::X * 2.0);
        assert_eq!(intersect_quadratic_triangle(&outside, unit(), FULL), None);
    }

    #[test]
    fn a_curve_in_the_plane_or_parallel_to_it_misses() {
        let in_plane = [
            DVec3::ZERO,
            DVec3::new(0.3, 0.1, 0.0),
            DVec3::new(0.2, 0.5, 0.0),
        ];
        assert_eq!(intersect_quadratic_triangle(&in_plane, unit(), FULL), None);
        // Tangent parallel to the plane everywhere, above it.
        let parallel = in_plane.map(|q| q + DVec3::Z);
        assert_eq!(intersect_quadratic_triangle(&parallel, unit(), FULL), None);
    }

    #[test]
    fn a_curve_through_an_edge_or_vertex_hits() {
        // Crosses z = 0 at s = 1/2 exactly on the hypotenuse x + y = 1 at (0.5, 0.5).
        let p = [
            DVec3::new(0.5, 0.5, -1.0),
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(0.5, 0.5, 1.0),
        ];
        let hit = intersect_quadratic_triangle(&p, unit(), FULL).unwrap();
        assert!((hit.barycentric[0] + hit.barycentric[1] - 1.0).abs() < 1e-15);
        let vertex = p.map(|q| q - DVec3::new(0.5, 0.5, 0.0));
        assert!(intersect_quadratic_triangle(&vertex, unit(), FULL).is_some());
    }

    #[test]
    fn zero_area_triangles_and_out_of_range_roots_miss() {
        let p = [
            DVec3::new(0.2, 0.2, -1.0),
            DVec3::new(0.2, 0.2, 0.0),
            DVec3::new(0.2, 0.2, 1.0),
        ];
        let flat = tri(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert_eq!(intersect_quadratic_triangle(&p, flat, FULL), None);
        assert_eq!(intersect_quadratic_triangle(&p, unit(), [0.0, 0.49]), None);
        assert!(intersect_quadratic_triangle(&p, unit(), [0.5, 0.5]).is_some());
    }

    #[test]
    fn pieces_reproduce_the_curve() {
        let p = [
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(3.0, 0.0, 1.0),
        ];
        let q = piece(&p, 0.25, 0.75);
        for s in [0.0, 0.3, 1.0] {
            let want = quadratic_point(&p, 0.25 + 0.5 * s);
            assert!((quadratic_point(&q, s) - want).length() < 1e-14);
        }
    }

    /// The caster of the built-in teapot room, built once for all cases.
    fn room() -> &'static RayCaster {
        static ROOM: std::sync::OnceLock<RayCaster> = std::sync::OnceLock::new();
        ROOM.get_or_init(|| {
            RayCaster::new(&crate::scene::builtin::load("teapot-room").expect("built-in scene"))
        })
    }

    #[test]
    fn boxes_apart_only_beyond_the_margin() {
        let t = unit();
        // Just beyond x = 1 by more than the margin: apart; within it: not.
        let x = |d: f64| DVec3::new(1.0 + d, 0.0, 0.0);
        assert!(boxes_apart(x(1e-3), x(2.0), t));
        assert!(!boxes_apart(x(1e-7), x(2.0), t));
        // Below z = 0 or overlapping: apart only when separated.
        assert!(boxes_apart(
            DVec3::new(0.1, 0.1, -2.0),
            DVec3::new(0.2, 0.2, -1.0),
            t
        ));
        assert!(!boxes_apart(
            DVec3::new(0.1, 0.1, -2.0),
            DVec3::new(0.2, 0.2, 1.0),
            t
        ));
        // Degenerate case: a coordinate that is not finite is never apart.
        let nan = DVec3::new(f64::NAN, 0.1, 0.0);
        assert!(!boxes_apart(nan, nan, t));
    }

    #[test]
    fn a_hull_on_one_side_of_the_plane_misses_and_a_crossing_one_does_not() {
        let above = [
            DVec3::new(0.2, 0.2, 0.1),
            DVec3::new(0.3, 0.2, 0.5),
            DVec3::Z,
        ];
        assert!(hull_misses_plane(&above, unit()));
        assert!(hull_misses_plane(&above.map(|q| -q), unit()));
        let crossing = [above[0], above[1], -DVec3::Z];
        assert!(!hull_misses_plane(&crossing, unit()));
        // Degenerate cases: a control point on the plane, a zero-area triangle.
        let touching = [above[0], DVec3::new(0.3, 0.2, 0.0), above[2]];
        assert!(!hull_misses_plane(&touching, unit()));
        let flat = tri(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert!(!hull_misses_plane(&above, flat));
    }

    /// The first hit of `p` by testing every triangle of `caster`'s BVH over the whole curve,
    /// with the triangles as the BVH stores them (f32 vertex and edges).
    fn brute_force_first_hit(caster: &RayCaster, p: &[DVec3; 3]) -> Option<f64> {
        caster
            .bvh
            .all_triangles()
            .iter()
            .filter_map(|t| {
                let tri = [t.v0, t.e1, t.e2].map(|v| glam::Vec3::from(v).as_dvec3());
                intersect_quadratic_triangle(p, tri, FULL).map(|h| h.s)
            })
            .min_by(f64::total_cmp)
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
    fn dense_first_hit(p: &[DVec3; 3], t: [DVec3; 3], n: usize) -> Option<f64> {
        let normal = t[1].cross(t[2]);
        let side = |s: f64| normal.dot(quadratic_point(p, s) - t[0]);
        (0..n).find_map(|k| {
            let (a, b) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
            if (side(a) > 0.0) == (side(b) > 0.0) {
                return None;
            }
            let s = a + (b - a) * side(a) / (side(a) - side(b));
            let w = quadratic_point(p, s) - t[0];
            let area2 = normal.length_squared();
            let u = w.cross(t[2]).dot(normal) / area2;
            let v = t[1].cross(w).dot(normal) / area2;
            (u > 1e-6 && v > 1e-6 && u + v < 1.0 - 1e-6).then_some(s)
        })
    }

    proptest! {
        /// The hull test never rejects a piece that hits: wherever it says a piece misses
        /// the triangle's plane, the analytic search over that piece finds nothing.
        #[test]
        fn a_rejected_piece_has_no_hit((p, [a, b, c], [lo, hi]) in curve_triangle_range()) {
            let t = tri(a, b, c);
            if hull_misses_plane(&piece(&p, lo, hi), t) {
                prop_assert_eq!(intersect_quadratic_triangle(&p, t, [lo, hi]), None);
            }
        }

        /// A piece whose control points' box is apart from a triangle's box has no hit on
        /// it; boxes that overlap or touch are never apart.
        #[test]
        fn a_piece_boxed_apart_has_no_hit((p, [a, b, c], [lo, hi]) in curve_triangle_range()) {
            let t = tri(a, b, c);
            let q = piece(&p, lo, hi);
            let (q_lo, q_hi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
            if boxes_apart(q_lo, q_hi, t) {
                prop_assert_eq!(intersect_quadratic_triangle(&p, t, [lo, hi]), None);
            }
            // The triangle's own box is never apart from itself, nor from a box inside it.
            let t_lo = a.min(b).min(c);
            let t_hi = a.max(b).max(c);
            prop_assert!(!boxes_apart(t_lo, t_hi, t));
            prop_assert!(!boxes_apart(a, a, t));
        }

        /// The BVH search with its culls (whole curve, piece boxes, piece chords, triangle
        /// boxes, hull planes) finds the first hit that testing every triangle finds, on curves through
        /// and past a room with a teapot (many pieces outside the scene's box).
        #[test]
        fn the_culled_search_finds_the_brute_force_first_hit(
            p0 in point(), p1 in point(), p2 in point(),
        ) {
            let caster = room();
            let p = [p0, p1, p2].map(|q| q * DVec3::new(4.0, 2.0, 4.0) + DVec3::Y * 1.5);
            let searched = caster.intersect_quadratic(&p, LiveParts::ALL).map(|(s, _)| s);
            prop_assert_eq!(searched, brute_force_first_hit(caster, &p));
        }

        /// The analytic first hit agrees with dense sampling of the curve wherever the
        /// sampled crossing is clearly inside the triangle.
        #[test]
        fn analytic_hit_matches_dense_sampling(
            p0 in point(), p1 in point(), p2 in point(),
            a in point(), b in point(), c in point(),
        ) {
            let p = [p0, p1, p2];
            let t = tri(a, b, c);
            prop_assume!(t[1].cross(t[2]).length() > 1e-3);
            let dense = dense_first_hit(&p, t, 4096);
            let analytic = intersect_quadratic_triangle(&p, t, FULL);
            if let Some(s) = dense {
                let hit = analytic.expect("dense sampling found a hit");
                // The analytic hit is at the sampled one, or at an earlier tangential touch
                // (which sampling by sign changes cannot see).
                prop_assert!(hit.s <= s + 1e-3, "analytic {} dense {}", hit.s, s);
                let q = quadratic_point(&p, hit.s);
                let normal = t[1].cross(t[2]).normalize();
                prop_assert!(normal.dot(q - t[0]).abs() < 1e-9);
            }
        }
    }
}
