//! The first hit of a quadratic Bezier projector (Brosz 2011, 7.2), found analytically and
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
//! Where no projector hull culled the curve's pieces, the whole curve is first tested the
//! same way against the scene's box alone; each piece is tested against it by the box of the
//! piece's control points before its chord is built; in a leaf, a triangle whose box is
//! apart from that box, whose plane the piece's control points lie strictly on one side of,
//! or one of whose edge planes they, or the part of the piece's chord near the plane, lie
//! outside, is skipped without root finding (the piece cannot meet it; see
//! `curve_triangle`, whose precomputed form of every BVH triangle is built on the first
//! quadratic search). The four projectors of a 2x2 pixel quad share the walks of their
//! pieces.
//!
//! Degenerate cases: see `CurveTriangle::intersect`; a zero-area triangle is never stored
//! in the BVH.

use glam::{DVec3, Vec2};

use super::hull_cull::LiveParts;
use super::pieces::{piece, piece_interval, PIECES};
use crate::render::bvh::curve_triangle::CurveHit;
use crate::render::bvh::{NearSegment, NearSegments4};
use crate::render::prepared::{Hit32, PreparedScene};

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

/// One curve's piece being searched in a packet walk: the curve, the piece's control
/// points, their box and largest coordinate magnitude, the piece's largest distance from its
/// chord (the middle control point's), its padded chord, and where the chord parameter of
/// the piece's points rises with the curve parameter, the middle control point's
/// ([`chord_parameter`]).
struct PieceSearch<'a> {
    curve: &'a [DVec3; 3],
    hull: [DVec3; 3],
    lo: DVec3,
    hi: DVec3,
    scale: f64,
    pad: f64,
    chord: NearSegment,
    along: Option<f64>,
}

/// Slack of the walk's bound ([`PieceSearch::bound`]), in chord parameter units: the f32 slab
/// test that computes a node's entry along the chord rounds it by a few f32 ulps relative
/// (below 1e-6 for entries in [0, 1]), far below this.
const BOUND_SLACK: f64 = 1e-5;

/// Where the chord from `hull[0]` to `hull[2]` is passed by the piece: writing the middle
/// control point as `hull[0] + alpha (hull[2] - hull[0]) + h` with `h` across the chord, the
/// piece's point at local parameter `x` is `hull[0] + tau(x) (hull[2] - hull[0]) + 2 x (1 - x)
/// h` with `tau(x) = x^2 + 2 alpha x (1 - x)`: within `|h| / 2` (less than the piece's pad) of
/// the chord's point at `tau(x)`. Returns `alpha` where `tau` rises with `x` over [0, 1]
/// (`alpha` in [0, 1]). Degenerate cases: a chord of zero length, a non-finite point or an
/// `alpha` outside [0, 1] (the piece turns back along its chord) give `None`.
fn chord_parameter(hull: &[DVec3; 3]) -> Option<f64> {
    let d = hull[2] - hull[0];
    let alpha = (hull[1] - hull[0]).dot(d) / d.length_squared();
    (0.0..=1.0).contains(&alpha).then_some(alpha)
}

impl PieceSearch<'_> {
    /// The bound of the walk ([`super::bvh::Bvh::visit_near_segments4`]) once the piece has a
    /// hit at curve parameter `s` in the piece's interval `(a, b)`: a point of the piece in a
    /// box whose padded box the chord enters beyond it has a larger curve parameter. Such a
    /// point at local parameter `x` is within the pad of the chord's point at `tau(x)`
    /// ([`chord_parameter`]), which is therefore in the padded box: `tau(x)` is at least the
    /// entry, above `tau` at the hit by more than [`BOUND_SLACK`] covers the rounding of
    /// the entry, and `tau` rises with `x`. `f32::MAX` (no bound) where `tau` does not rise.
    fn bound(&self, s: f64, (a, b): (f64, f64)) -> f32 {
        self.along.map_or(f32::MAX, |alpha| {
            let x = (s - a) / (b - a);
            (x * x + 2.0 * alpha * x * (1.0 - x) + BOUND_SLACK) as f32
        })
    }
}

impl PreparedScene {
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
        let [first, ..] = self.intersect_quadratic4([Some(p), None, None, None], live);
        first
    }

    /// [`PreparedScene::intersect_quadratic`] of up to four curves (`None`: no curve, no hit),
    /// with identical results: piece k of the curves still searching is searched by one
    /// shared BVH walk ([`super::bvh::Bvh::visit_near_segments4`], which gives each curve
    /// exactly the triangles of its own walk, in the same order). Pays for the coherent
    /// projectors of a 2x2 pixel quad.
    pub(super) fn intersect_quadratic4(
        &self,
        curves: [Option<&[DVec3; 3]>; 4],
        live: LiveParts,
    ) -> [Option<(f64, Hit32)>; 4] {
        // The whole curve first (within its middle control point's distance of its chord):
        // the projectors of many pixels pass by the scene's box altogether. Not where a
        // hull left only some parts live: the hull has culled the parts that miss the
        // scene for the whole block, and each live piece's own box test below rejects a
        // curve passing by it at less cost than this test made on every curve of the block.
        let whole_curve_test = live == LiveParts::ALL;
        let mut searching = curves.map(|curve| {
            curve.filter(|p| {
                !whole_curve_test
                    || NearSegment::new(p[0], p[2] - p[0], distance_to_segment(p[1], p[0], p[2]))
                        .is_some_and(|whole| self.bvh.near_root(&whole))
            })
        });
        let mut found: [Option<(usize, CurveHit)>; 4] = [None; 4];
        for k in 0..PIECES {
            if searching.iter().all(Option::is_none) {
                break;
            }
            if !live.may_hit(k) {
                continue;
            }
            let (a, b) = piece_interval(k);
            let mut pieces: [Option<PieceSearch>; 4] = [const { None }; 4];
            for (slot, lane) in pieces.iter_mut().zip(searching.iter_mut()) {
                let Some(curve) = *lane else {
                    continue;
                };
                let hull = piece(curve, a, b);
                // The piece lies in the box of its control points: most pieces of a
                // projector that passes the scene are outside its box, and cost only this
                // comparison.
                let (lo, hi) = (
                    hull[0].min(hull[1]).min(hull[2]),
                    hull[0].max(hull[1]).max(hull[2]),
                );
                if !self.bvh.root_overlaps(lo, hi) {
                    continue;
                }
                let pad = distance_to_segment(hull[1], hull[0], hull[2]);
                match NearSegment::new(hull[0], hull[2] - hull[0], pad) {
                    Some(chord) => {
                        *slot = Some(PieceSearch {
                            curve,
                            hull,
                            lo,
                            hi,
                            scale: lo.abs().max(hi.abs()).max_element(),
                            pad,
                            chord,
                            along: chord_parameter(&hull),
                        })
                    }
                    // A control point that is not finite: the curve hits nothing.
                    None => *lane = None,
                }
            }
            if pieces.iter().all(Option::is_none) {
                continue;
            }
            let best = self.search_pieces(&pieces, (a, b));
            for ((lane, best), found) in searching.iter_mut().zip(best).zip(&mut found) {
                if best.is_some() {
                    (*lane, *found) = (None, best);
                }
            }
        }
        found.map(|f| f.map(|(stored, hit)| (hit.s, self.curve_hit32(stored, hit))))
    }

    /// The first hit (stored triangle and hit) of each of `pieces`, all over the curve
    /// parameter interval `(a, b)`: the smallest curve parameter, the first stored triangle
    /// on a tie, whatever order the triangles are visited in. One walk, ordered along the
    /// chords, that ends a lane's search beyond its best hit ([`PieceSearch::bound`]); in a
    /// leaf, a triangle whose box is apart from the piece's, whose plane the piece's control
    /// points lie strictly on one side of, or one of whose edge planes the piece's chord
    /// (near the plane) or its control points lie outside is skipped without root finding
    /// (see `CurveTriangle`), as is one that a view hides ([`PreparedScene::shows`]).
    fn search_pieces(
        &self,
        pieces: &[Option<PieceSearch>; 4],
        (a, b): (f64, f64),
    ) -> [Option<(usize, CurveHit)>; 4] {
        let triangles = self.curve_triangles();
        let chords = NearSegments4::new(pieces.each_ref().map(|p| p.as_ref().map(|p| &p.chord)));
        let mut best: [Option<(usize, CurveHit)>; 4] = [None; 4];
        self.bvh.visit_near_segments4(&chords, |lane, stored| {
            let (Some(piece), best) = (&pieces[lane], &mut best[lane]) else {
                return f32::MAX;
            };
            let bound = |best: &Option<(usize, CurveHit)>| {
                best.map_or(f32::MAX, |(_, h)| piece.bound(h.s, (a, b)))
            };
            if !self.shows(stored) {
                return bound(best);
            }
            let tri = &triangles[stored];
            let margin = tri.margin(piece.scale);
            if tri.boxes_apart(piece.lo, piece.hi, margin)
                || tri.plane_misses(&piece.hull)
                || tri.chord_misses(&piece.hull, piece.pad, margin)
                || tri.edges_miss(&piece.hull, margin)
            {
                return bound(best);
            }
            let hi = best.map_or(b, |(_, h)| h.s);
            if let Some(hit) = tri.intersect(piece.curve, [a, hi]) {
                let first =
                    best.is_none_or(|(was, h)| hit.s < h.s || (hit.s == h.s && stored < was));
                if first {
                    *best = Some((stored, hit));
                }
            }
            bound(best)
        });
        best
    }

    /// The f32 form of curve hit `hit` on stored triangle `stored`.
    fn curve_hit32(&self, stored: usize, hit: CurveHit) -> Hit32 {
        let found = self.hit32(crate::render::bvh::BvhHit {
            id: self.bvh.id(stored),
            hit: crate::render::bvh::triangle::FastHit {
                t: 0.0,
                u: hit.barycentric[0] as f32,
                v: hit.barycentric[1] as f32,
            },
        });
        debug_assert_eq!(
            found.barycentric,
            Vec2::new(hit.barycentric[0] as f32, hit.barycentric[1] as f32)
        );
        found
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::projection::projector::quadratic_point;
    use crate::render::bvh::curve_triangle::CurveTriangle;

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
    fn room() -> &'static PreparedScene {
        static ROOM: std::sync::OnceLock<PreparedScene> = std::sync::OnceLock::new();
        ROOM.get_or_init(|| {
            PreparedScene::new(&crate::scene::builtin::load("teapot-room").expect("built-in scene"))
        })
    }

    /// The first hit of `p` by testing every triangle of `caster`'s BVH over the whole curve
    /// without any cull, with the triangles as the BVH stores them (f32 vertex and edges):
    /// the smallest s, the first stored triangle on a tie (as the search's walk in tree
    /// order finds it).
    fn brute_force_first_hit(caster: &PreparedScene, p: &[DVec3; 3]) -> Option<(f64, Hit32)> {
        let mut best: Option<(usize, CurveHit)> = None;
        for (stored, t) in caster.bvh.all_triangles().iter().enumerate() {
            if let Some(hit) = CurveTriangle::from_packed(t).intersect(p, [0.0, 1.0]) {
                if best.is_none_or(|(_, h)| hit.s < h.s) {
                    best = Some((stored, hit));
                }
            }
        }
        best.map(|(stored, hit)| (hit.s, caster.curve_hit32(stored, hit)))
    }

    fn point() -> impl Strategy<Value = DVec3> {
        (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    #[test]
    fn chords_passed_backwards_or_of_zero_length_give_no_parameter() {
        let x = DVec3::X;
        assert_eq!(chord_parameter(&[DVec3::ZERO, x * 0.5, x]), Some(0.5));
        assert_eq!(chord_parameter(&[DVec3::ZERO, DVec3::Y, DVec3::ZERO]), None);
        assert_eq!(chord_parameter(&[DVec3::ZERO, x * 1.5, x]), None);
        assert_eq!(chord_parameter(&[DVec3::ZERO, -x, x]), None);
        assert_eq!(chord_parameter(&[DVec3::ZERO, DVec3::NAN, x]), None);
        // The ends of the range: the piece's middle point at an end of its chord.
        assert_eq!(chord_parameter(&[DVec3::ZERO, x + DVec3::Y, x]), Some(1.0));
    }

    /// The caster of `flexcam bench flexible`'s Kia row (the teapot of 552 triangles) and
    /// its quadratic volume at 64 x 64 pixels, built once for all cases.
    fn bench_row() -> &'static (PreparedScene, crate::projection::flexible::Flexible) {
        static ROW: std::sync::OnceLock<(PreparedScene, crate::projection::flexible::Flexible)> =
            std::sync::OnceLock::new();
        ROW.get_or_init(|| {
            let (scene, _) = super::super::workloads::teapot_scene(520);
            let volume = super::super::workloads::table_volume(&scene, None, 64)
                .expect("the bench's volume");
            (PreparedScene::new(&scene), volume)
        })
    }

    proptest! {
        /// The BVH search with its culls (whole curve, piece boxes, piece chords, triangle
        /// boxes, hull planes, edge planes) finds exactly the first hit (curve parameter,
        /// object, triangle, barycentrics) that testing every triangle finds, on curves
        /// through and past a room with a teapot (many pieces outside the scene's box).
        #[test]
        fn the_culled_search_finds_the_brute_force_first_hit(
            p0 in point(), p1 in point(), p2 in point(),
        ) {
            let caster = room();
            let p = [p0, p1, p2].map(|q| q * DVec3::new(4.0, 2.0, 4.0) + DVec3::Y * 1.5);
            let searched = caster.intersect_quadratic(&p, LiveParts::ALL);
            prop_assert_eq!(searched, brute_force_first_hit(caster, &p));
        }

        /// A piece whose chord parameter rises ([`chord_parameter`]) lies within half its
        /// pad of the chord's point at `tau(x)`, and `tau` rises with `x`: what the walk's
        /// bound ([`PieceSearch::bound`]) rests on.
        #[test]
        fn a_piece_stays_near_its_chord_point_and_that_point_moves_forward(
            p0 in point(), p1 in point(), p2 in point(), x in 0.0..=1.0f64, step in 0.0..=1.0f64,
        ) {
            let hull = [p0, p1, p2];
            if let Some(alpha) = chord_parameter(&hull) {
                let tau = |x: f64| x * x + 2.0 * alpha * x * (1.0 - x);
                let chord_point = hull[0] + tau(x) * (hull[2] - hull[0]);
                let pad = distance_to_segment(hull[1], hull[0], hull[2]);
                let off = (quadratic_point(&hull, x) - chord_point).length();
                prop_assert!(off <= 0.5 * pad + 1e-12, "{} {}", off, pad);
                let later = x + step * (1.0 - x);
                prop_assert!(tau(later) >= tau(x), "{} {}", tau(later), tau(x));
            }
        }

        /// On the bench's own layout (the Kia row's teapot, quadratic projectors of a random
        /// 2x2 pixel quad), where the ordered walk ends most searches early, the packet
        /// search finds each projector's brute-force first hit: the walk's bound drops
        /// nothing that could win, ties included.
        #[test]
        fn the_ordered_walk_finds_the_brute_force_first_hit_on_the_bench_layout(
            x in 0u32..63, y in 0u32..63, dx in 0.0..1.0f64, dy in 0.0..1.0f64,
        ) {
            use crate::projection::{Projection, Projector};
            let (caster, volume) = bench_row();
            let curves: [Option<[DVec3; 3]>; 4] = std::array::from_fn(|i| {
                let pixel = glam::DVec2::new(
                    f64::from(x + (i as u32 & 1)) + dx,
                    f64::from(y + (i as u32 >> 1)) + dy,
                );
                match volume.projector(pixel) {
                    Some(Projector::QuadraticBezier(p)) => Some(p),
                    _ => None,
                }
            });
            let lanes = curves.each_ref().map(Option::as_ref);
            let searched = caster.intersect_quadratic4(lanes, LiveParts::ALL);
            for (lane, found) in lanes.iter().zip(searched) {
                let want = lane.and_then(|p| brute_force_first_hit(caster, p));
                prop_assert_eq!(found, want);
            }
        }

        /// The packet search finds for each of four curves exactly the first hit that
        /// testing every triangle finds: neighbouring curves (a random curve and three moved
        /// by up to `spread`, sharing most of their walks), some lanes empty.
        #[test]
        fn packets_of_curves_find_each_curve_s_brute_force_first_hit(
            p0 in point(), p1 in point(), p2 in point(),
            moves in [point(), point(), point()],
            spread in 0.0..0.3f64,
            empty in 0..16u32,
        ) {
            let caster = room();
            let base = [p0, p1, p2].map(|q| q * DVec3::new(4.0, 2.0, 4.0) + DVec3::Y * 1.5);
            let curves: [[DVec3; 3]; 4] = std::array::from_fn(|i| match i {
                0 => base,
                _ => base.map(|q| q + moves[i - 1] * spread),
            });
            let lanes: [Option<&[DVec3; 3]>; 4] =
                std::array::from_fn(|i| (empty >> i & 1 == 0).then_some(&curves[i]));
            let searched = caster.intersect_quadratic4(lanes, LiveParts::ALL);
            for (lane, found) in lanes.iter().zip(searched) {
                let want = lane.and_then(|p| brute_force_first_hit(caster, p));
                prop_assert_eq!(found, want);
            }
        }
    }
}
