//! Whole tiles culled at once: when a projection bounds the projectors of a tile by those of
//! its corners ([`ProjectorHull`]), every part of the per-projector searches (a polyline's
//! segment, a quadratic's piece of [`PIECES`]) is bounded for all of the tile's projectors
//! by one box, built from the corners' corresponding parts. A part whose box overlaps no
//! leaf box of the BVH (enlarged as the scene-box tests are, [`super::bvh::Bvh::leaves_overlap`])
//! holds no hit for any projector of the tile: a hit lies on the part, inside its box, and
//! in its leaf's box. The searches skip such parts, and where every part is skipped the tile
//! is background without generating a single projector: exactly what each projector's own
//! search would have found.

use glam::DVec3;

use super::pieces::{piece, piece_interval, PIECES};
use crate::projection::{Projector, ProjectorHull};
use crate::render::prepared::PreparedScene;

/// Rounding allowance of the caster's own arithmetic on control points (a segment's end
/// `origin + (end - origin)`, a piece's control points by de Casteljau), relative to the
/// largest control-point coordinate: that arithmetic is rounded by a few ulps of it, below
/// 1e-14; the allowance is generous by two orders of magnitude.
const CASTER_ROUNDING: f64 = 1e-12;

/// Which parts (polyline segments, quadratic pieces, in order) of the projectors a hull
/// bounds may hold a hit: bit k for part k, the last bit for part 63 and all
/// after it together.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct LiveParts(u64);

impl LiveParts {
    /// Every part may meet the scene (no hull, or one that bounds nothing).
    pub const ALL: LiveParts = LiveParts(u64::MAX);

    /// Whether part `k` may meet the scene.
    #[inline]
    pub fn may_hit(self, k: usize) -> bool {
        self.0 >> k.min(63) & 1 == 1
    }

    /// Whether no part may: every projector misses everything.
    pub fn none(self) -> bool {
        self.0 == 0
    }

    /// The parts `live(k)` says of `count` parts.
    fn of(count: usize, live: impl Fn(usize) -> bool) -> LiveParts {
        LiveParts(
            (0..count)
                .filter(|&k| live(k))
                .fold(0, |bits, k| bits | 1 << k.min(63)),
        )
    }
}

impl PreparedScene {
    /// Which parts of the projectors bounded by `hull` may hold a hit: those whose box over
    /// the hull overlaps a leaf of the BVH (each projector's own search tests the scene's box
    /// alone: [`PreparedScene::misses_scene_box`] for segments, the control-point box for a
    /// quadratic's pieces). Only the parts `within` leaves live are tested: the others stay
    /// dead, as for a rectangle inside one whose parts `within` are (its projectors are among
    /// that rectangle's, so a part that holds no hit for those holds none for these; the
    /// tiles pass the tile's parts for its blocks, each of which would otherwise test every
    /// part of every corner again). `within` itself when the corners are of mixed kinds,
    /// polylines of different lengths, or straight.
    pub(super) fn live_parts(&self, hull: &ProjectorHull, within: LiveParts) -> LiveParts {
        match &hull.corners {
            [Projector::Polyline(a), Projector::Polyline(b), Projector::Polyline(c), Projector::Polyline(d)]
                if [b, c, d].iter().all(|p| p.len() == a.len()) =>
            {
                let corners = [a, b, c, d];
                let pad = self.hull_pad(hull.pad, corners.iter().flat_map(|p| p.iter()));
                LiveParts::of(a.len().saturating_sub(1), |k| {
                    if !within.may_hit(k) {
                        return false;
                    }
                    let ends = corners.map(|p| [p[k], p[k + 1]]);
                    !self.box_misses_scene(ends.as_flattened(), pad)
                })
            }
            [Projector::QuadraticBezier(a), Projector::QuadraticBezier(b), Projector::QuadraticBezier(c), Projector::QuadraticBezier(d)] =>
            {
                let corners = [a, b, c, d];
                let pad = self.hull_pad(hull.pad, corners.iter().flat_map(|p| p.iter()));
                LiveParts::of(PIECES, |k| {
                    if !within.may_hit(k) {
                        return false;
                    }
                    let (s0, s1) = piece_interval(k);
                    let points = corners.map(|p| piece(p, s0, s1));
                    !self.box_misses_scene(points.as_flattened(), pad)
                })
            }
            _ => within,
        }
    }

    /// The projection's pad plus [`CASTER_ROUNDING`] of the largest coordinate of `points`.
    fn hull_pad<'a>(&self, pad: f64, points: impl Iterator<Item = &'a DVec3>) -> f64 {
        let largest = points.fold(0.0f64, |m, p| m.max(p.abs().max_element()));
        pad + CASTER_ROUNDING * largest
    }

    /// Whether the box of `points` enlarged by `pad` misses every leaf box of the BVH; a
    /// point or pad that is not finite counts as an overlap. (A slice rather than an
    /// iterator: flattening the corners' arrays lazily cost more than the test itself.)
    fn box_misses_scene(&self, points: &[DVec3], pad: f64) -> bool {
        let (mut lo, mut hi, mut finite) = (DVec3::INFINITY, DVec3::NEG_INFINITY, pad.is_finite());
        for &p in points {
            finite &= p.is_finite();
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        let (lo, hi) = (lo - DVec3::splat(pad), hi + DVec3::splat(pad));
        finite
            && !self.bvh.leaves_overlap(lo, hi)
            && !self.displaced.as_ref().is_some_and(|d| d.overlaps(lo, hi))
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec2;

    use super::{LiveParts, PreparedScene};
    use crate::geometry::Ray;
    use crate::projection::flexible::Flexible;
    use crate::projection::{AnalyticInverse, NoInverse, Projection, Projector, Trilinear};
    use crate::render::raycast::workloads::{table_volume, teapot_scene};
    use crate::render::{raycast, Counter, Frame, RenderOptions, Shading, Stats};

    /// `Flexible` without its hull: every tile is searched projector by projector.
    struct NoHull<'a>(&'a Flexible);

    impl Projection for NoHull<'_> {
        fn kind(&self) -> &'static str {
            self.0.kind()
        }
        fn resolution(&self) -> (u32, u32) {
            self.0.resolution()
        }
        fn ray(&self, pixel: DVec2) -> Option<Ray> {
            self.0.ray(pixel)
        }
        fn projector(&self, pixel: DVec2) -> Option<Projector> {
            self.0.projector(pixel)
        }
        fn inverse(&self) -> Result<&dyn AnalyticInverse, NoInverse> {
            self.0.inverse()
        }
        fn trilinear(&self) -> Option<&Trilinear> {
            None
        }
    }

    /// The teapot of 56 triangles and the volume of `flexcam bench flexible` around it.
    fn teapot_and_volume() -> (PreparedScene, impl Fn(Option<u32>, u32) -> Flexible) {
        let (scene, _) = teapot_scene(56);
        let caster = PreparedScene::new(&scene);
        (caster, move |segments, size| {
            table_volume(&scene, segments, size).unwrap()
        })
    }

    fn count(stats: &Stats, key: &str) -> u64 {
        match stats[key] {
            Counter::Count(n) => n,
            Counter::Value(v) => panic!("{key} is a value: {v}"),
        }
    }

    fn assert_frames_equal(a: &Frame, b: &Frame, what: &str) {
        assert_eq!(a.color, b.color, "{what}: colours");
        assert_eq!(a.depth, b.depth, "{what}: depths");
        assert_eq!(a.ids, b.ids, "{what}: ids");
    }

    #[test]
    fn culled_tiles_render_exactly_like_the_per_projector_searches() {
        let (caster, bench_volume) = teapot_and_volume();
        // 104 = 6.5 tiles of 16: edge tiles of 8 pixels too.
        let size = 104;
        for segments in [None, Some(2), Some(5)] {
            let projection = bench_volume(segments, size);
            for spp in [1, 4] {
                let options = RenderOptions {
                    shading: Shading::Lit,
                    spp,
                    ..RenderOptions::default()
                };
                let (culled, stats) = raycast::render(&caster, &projection, &options).unwrap();
                let (plain, plain_stats) =
                    raycast::render(&caster, &NoHull(&projection), &options).unwrap();
                let what = format!("segments {segments:?}, spp {spp}");
                assert_frames_equal(&culled, &plain, &what);
                for key in ["primary_rays", "secondary_rays", "shadow_rays"] {
                    assert_eq!(
                        count(&stats, key),
                        count(&plain_stats, key),
                        "{what}: {key}"
                    );
                }
                // Some of the 13 x 13 blocks are culled, and some are not: the teapot is in
                // view.
                let blocks = count(&stats, "blocks_culled");
                assert!(blocks > 0 && blocks < 169, "{what}: {blocks} blocks culled");
                assert_eq!(count(&plain_stats, "blocks_culled"), 0);
                assert!(culled.ids.iter().any(|&id| id != 0), "{what}");
            }
        }
    }

    #[test]
    fn a_hull_over_the_model_is_live_and_mixed_corners_are_never_culled() {
        let (caster, bench_volume) = teapot_and_volume();
        let projection = bench_volume(None, 64);
        // The whole image in one rectangle: it sees the teapot.
        let whole = projection
            .projector_hull(DVec2::splat(0.5), DVec2::splat(63.5))
            .unwrap();
        let live = caster.live_parts(&whole, LiveParts::ALL);
        assert!(!live.none() && live != LiveParts::ALL, "{live:?}");
        // Parts ruled out beforehand stay dead; the others are tested as before.
        let first_live = (0..64).find(|&k| live.may_hit(k)).unwrap();
        let all_but_first = LiveParts(!(1 << first_live));
        let masked = caster.live_parts(&whole, all_but_first);
        assert_eq!(masked, LiveParts(live.0 & all_but_first.0));
        // A corner of the image far from the teapot is culled.
        let corner = projection
            .projector_hull(DVec2::splat(0.5), DVec2::splat(1.5))
            .unwrap();
        assert!(caster.live_parts(&corner, LiveParts::ALL).none());
        // Polylines of different lengths, or kinds mixed, are not bounded: never culled.
        let mut mixed = corner.clone();
        let Projector::QuadraticBezier(p) = &corner.corners[0] else {
            panic!("{:?}", corner.corners[0]);
        };
        mixed.corners[0] = Projector::Polyline(p.to_vec());
        assert_eq!(caster.live_parts(&mixed, LiveParts::ALL), LiveParts::ALL);
        assert_eq!(caster.live_parts(&mixed, LiveParts(0b10)), LiveParts(0b10));
        let polylines = bench_volume(Some(3), 64)
            .projector_hull(DVec2::splat(0.5), DVec2::splat(1.5))
            .unwrap();
        assert!(caster.live_parts(&polylines, LiveParts::ALL).none());
        let mut uneven = polylines.clone();
        uneven.corners[1] = Projector::Polyline(p.to_vec());
        assert_eq!(caster.live_parts(&uneven, LiveParts::ALL), LiveParts::ALL);
        // A pad that is not finite never culls.
        let mut unbounded = polylines;
        unbounded.pad = f64::INFINITY;
        assert_eq!(
            caster.live_parts(&unbounded, LiveParts::ALL),
            LiveParts(0b111)
        );
    }

    #[test]
    fn live_parts_beyond_63_share_the_last_bit() {
        let parts = LiveParts::of(70, |k| k == 2 || k == 65);
        assert!(parts.may_hit(2) && !parts.may_hit(3) && !parts.may_hit(62));
        assert!(parts.may_hit(63) && parts.may_hit(65) && parts.may_hit(69));
        assert!(!parts.none());
        assert!(LiveParts::of(70, |_| false).none());
        assert!(LiveParts::of(0, |_| true).none());
        assert!((0..100).all(|k| LiveParts::ALL.may_hit(k)));
    }
}
