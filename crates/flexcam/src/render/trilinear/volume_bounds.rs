//! A safe, conservative cull of scene triangles per projection triangle: bounding planes of
//! the volume its rays sweep in front of the view plane.
//!
//! Every point the renderer draws through a projection triangle is on a ray
//! `tripoint(u, v) + t trinorm(u, v)` with barycentrics `w = (1 - u - v, u, v) >= 0` and
//! `t >= 0`, i.e. the point `sum w_k p_k + t sum w_k n_k`. That is a point of the convex set
//! `P = conv(p1, p2, p3) + cone(n1, n2, n3)`: the swept volume (whose sides are the bilinear
//! edge surfaces between vertex rays) lies inside `P`. A plane `m . x = c` bounds `P` when
//! `m . p_k <= c` and `m . n_k <= 0` for all three vertices. A scene triangle whose three
//! vertices are all strictly beyond one such plane lies wholly outside `P` (a half-space is
//! convex), so it has no point in the volume and nothing of it can be drawn: the pair is
//! skipped before any cubic is solved.
//!
//! Candidate normals are those of `P`'s possible facets, both orientations: `n_i x n_j`
//! (two directions), `n_k x (p_j - p_i)` (a direction and a base edge) and the base normal;
//! each is kept only if it bounds `P` (its `m . n_k` are `<= 0`, up to the rounding of the
//! terms that vanish analytically).
//!
//! Degenerate cases: directions that span more than a half-space (diverging over 180
//! degrees), or coplanar directions in opposite senses, leave few or no valid planes: then
//! fewer or no pairs are culled, never a wrong one. Zero or non-finite normals are skipped.
//! A point is only called outside when beyond the plane by more than [`RELATIVE_MARGIN`]
//! times its distance scale (so rounding, and the clip's `1e-9` domain margin, never cull a
//! drawable pair).

use glam::DVec3;

/// How far beyond a plane, relative to the distance from the projection triangle plus the
/// triangle's size, a point must lie to count as outside.
pub const RELATIVE_MARGIN: f64 = 1e-7;

/// Largest number of candidate planes: 3 direction pairs, 9 direction-edge pairs and the
/// base normal, in both orientations.
const MAX_PLANES: usize = 26;

/// Where a box lies against a projection triangle's bounding planes
/// ([`VolumeBounds::box_side`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoxSide {
    /// Wholly beyond one plane: nothing in the box can be drawn.
    Outside,
    /// Not wholly beyond any plane; the planes (bit mask) that still cut the box.
    Within(u32),
}

/// The bounding planes of one projection triangle's ray volume.
#[derive(Debug, Clone, Copy)]
pub struct VolumeBounds {
    /// Unit normals `m` and offsets `c`: the volume is in `m . x <= c`.
    planes: [(DVec3, f64); MAX_PLANES],
    count: usize,
    /// A base point (for the distance scale) and the size of the base triangle.
    origin: DVec3,
    size: f64,
}

impl VolumeBounds {
    /// The bounds of the triangle with base points `p` and directions `n`.
    pub fn new(p: [DVec3; 3], n: [DVec3; 3]) -> VolumeBounds {
        let edges = [p[1] - p[0], p[2] - p[0], p[2] - p[1]];
        // The 13 candidate normals in a fixed order (no allocation: 512 triangles a frame
        // on the detail-in-context surface).
        let mut candidates = [DVec3::ZERO; MAX_PLANES / 2];
        for (slot, (i, j)) in [(0, 1), (0, 2), (1, 2)].into_iter().enumerate() {
            candidates[slot] = n[i].cross(n[j]);
        }
        for (k, direction) in n.iter().enumerate() {
            for (e, edge) in edges.iter().enumerate() {
                candidates[3 + 3 * k + e] = direction.cross(*edge);
            }
        }
        candidates[MAX_PLANES / 2 - 1] = edges[0].cross(edges[1]);
        let direction_scale = n.iter().map(|d| d.length()).fold(0.0, f64::max);
        let mut bounds = VolumeBounds {
            planes: [(DVec3::ZERO, 0.0); MAX_PLANES],
            count: 0,
            origin: p[0],
            size: edges.iter().map(|e| e.length()).fold(0.0, f64::max),
        };
        for m in candidates.into_iter().filter_map(|m| m.try_normalize()) {
            for m in [m, -m] {
                // Terms zero in exact arithmetic come out at rounding level.
                let bounded = n.iter().all(|d| m.dot(*d) <= 1e-12 * direction_scale);
                if bounded && bounds.count < MAX_PLANES {
                    let c = p
                        .iter()
                        .map(|x| m.dot(*x))
                        .fold(f64::NEG_INFINITY, f64::max);
                    bounds.planes[bounds.count] = (m, c);
                    bounds.count += 1;
                }
            }
        }
        bounds
    }

    /// The planes (bit `k` for plane `k`) that `point` lies strictly beyond, by more than the
    /// margin (module doc). A scene triangle whose vertices' masks have a common bit is
    /// outside the volume. The cull itself calls [`VolumeBounds::outside_of`]; this form is
    /// the tests' reference.
    #[cfg(test)]
    pub fn outside(&self, point: DVec3) -> u32 {
        self.outside_of(point, self.all_planes())
    }

    /// The planes among `planes` (bit `k` for plane `k`; the bits of the others are zero)
    /// that `point` lies strictly beyond, by more than the margin (module doc). A scene
    /// triangle whose vertices' masks have a common bit is outside the volume. The cull passes the planes that still cut the box of the point's cluster
    /// ([`VolumeBounds::box_side`]): the box lies wholly inside the others, so the point is
    /// beyond none of them and the mask is the full one, at the cost of a few planes
    /// instead of all.
    pub fn outside_of(&self, point: DVec3, planes: u32) -> u32 {
        let mut mask = 0;
        // The distance scale, computed once and only for a point beyond some plane.
        let mut scale = None;
        let mut remaining = planes & self.all_planes();
        while remaining != 0 {
            let k = remaining.trailing_zeros();
            remaining &= remaining - 1;
            let (m, c) = self.planes[k as usize];
            let beyond = m.dot(point) - c;
            if beyond > 0.0 {
                let scale =
                    *scale.get_or_insert_with(|| (point - self.origin).length() + self.size);
                if beyond > RELATIVE_MARGIN * scale {
                    mask |= 1 << k;
                }
            }
        }
        mask
    }

    /// Every bounding plane (bit `k` for plane `k`): where a box test starts.
    pub fn all_planes(&self) -> u32 {
        // At most MAX_PLANES = 26 planes: the shift never overflows.
        (1 << self.count) - 1
    }

    /// Which side of the planes `active` the axis-aligned box with centre `centre` and
    /// half-extents `half` lies on, for the hierarchical cull (`cull_tree`):
    /// [`BoxSide::Outside`] only when every point `x` of the box is beyond one plane by more
    /// than the margin [`VolumeBounds::outside`] requires of `x` (twice that margin, taken
    /// at the box point farthest from the triangle, so that the rounding of the two tests
    /// cannot disagree), hence every vertex in the box has that plane's bit in its mask and
    /// every triangle in it would be culled one by one too. Otherwise
    /// [`BoxSide::Within`] the planes of `active` that still cut the box: a plane with the
    /// whole box on its inner side is dropped, as no point below can be beyond it.
    ///
    /// Degenerate boxes (zero extent: one point, a flat or thin cluster) are tested like any
    /// other; a box with a non-finite coordinate is never outside (its comparisons fail).
    pub fn box_side(&self, centre: DVec3, half: DVec3, active: u32) -> BoxSide {
        let scale = (centre - self.origin).length() + half.length() + self.size;
        let margin = 2.0 * RELATIVE_MARGIN * scale;
        let mut within = active;
        let mut remaining = active;
        while remaining != 0 {
            let k = remaining.trailing_zeros();
            remaining &= remaining - 1;
            let (m, c) = self.planes[k as usize];
            let middle = m.dot(centre) - c;
            let reach = m.abs().dot(half);
            if middle - reach > margin {
                return BoxSide::Outside;
            }
            if middle + reach <= 0.0 {
                within &= !(1 << k);
            }
        }
        BoxSide::Within(within)
    }

    /// The number of bounding planes found (the tests' count of them).
    #[cfg(test)]
    fn len(&self) -> usize {
        self.count
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::ProjectionTriangleCache;
    use proptest::prelude::*;

    /// A perspective-like projection triangle looking down -z from the unit triangle at the
    /// origin, its directions spread by 0.1.
    fn narrow_frustum() -> VolumeBounds {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let n = [
            DVec3::new(-0.1, -0.1, -1.0),
            DVec3::new(0.1, -0.1, -1.0),
            DVec3::new(-0.1, 0.1, -1.0),
        ];
        VolumeBounds::new(p, n)
    }

    fn vec3() -> impl Strategy<Value = DVec3> {
        (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    /// A projection triangle: base points near the origin, directions around -z spread by
    /// `spread` (up to folding and diverging beyond a half-space when large).
    fn triangle(spread: f64) -> impl Strategy<Value = ([DVec3; 3], [DVec3; 3])> {
        (
            [vec3(), vec3(), vec3()],
            [vec3(), vec3(), vec3()],
            [0.3..2.0f64, 0.3..2.0f64, 0.3..2.0f64],
        )
            .prop_map(move |(p, d, len)| {
                let p = p.map(|x| 0.3 * x);
                let n = [0, 1, 2].map(|k| (-DVec3::Z + spread * 0.3 * d[k]) * len[k]);
                (p, n)
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// Every point of the swept volume is inside every bounding plane.
        #[test]
        fn volume_points_are_never_outside(
            (p, n) in triangle(1.0),
            u in 0.0..1.0f64, v in 0.0..1.0f64, t in 0.0..20.0f64,
        ) {
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let cache = ProjectionTriangleCache::new(p, n);
            let bounds = VolumeBounds::new(p, n);
            prop_assert_eq!(bounds.outside(cache.ray_point(u, v, t)), 0);
        }

        /// The cull against full projection: whenever the three vertices of a random scene
        /// triangle share an outside plane, no point of the triangle has an image inside the
        /// projection triangle at `t >= 0` (projected by the cubic on a dense grid of the
        /// scene triangle, its vertices included).
        #[test]
        fn culled_triangles_have_no_visible_image(
            (p, n) in triangle(2.5),
            scene in [vec3(), vec3(), vec3()],
            shift in vec3(),
        ) {
            let scene = scene.map(|x| x + 2.0 * shift - 4.0 * DVec3::Z);
            let bounds = VolumeBounds::new(p, n);
            let common = scene.iter().fold(u32::MAX, |m, &x| m & bounds.outside(x));
            if common != 0 {
                let cache = ProjectionTriangleCache::new(p, n);
                let steps = 12;
                for i in 0..=steps {
                    for j in 0..=steps - i {
                        let (a, b) = (f64::from(i) / 12.0, f64::from(j) / 12.0);
                        let x = scene[0] + a * (scene[1] - scene[0]) + b * (scene[2] - scene[0]);
                        for s in cache.project_point(x).iter() {
                            let inside = s.t >= 0.0
                                && s.u >= -1e-9 && s.v >= -1e-9 && s.u + s.v <= 1.0 + 1e-9;
                            prop_assert!(!inside, "culled point {x} images at {s:?}");
                        }
                    }
                }
            }
        }
    }

    /// A random box: centre and half-extents (some of them zero: flat, thin and point boxes).
    fn axis_box() -> impl Strategy<Value = (DVec3, DVec3)> {
        (vec3(), vec3(), 0..8u32).prop_map(|(c, h, flat)| {
            let h = DVec3::select(
                glam::BVec3::new(flat & 1 != 0, flat & 2 != 0, flat & 4 != 0),
                DVec3::ZERO,
                h.abs(),
            );
            (c + DVec3::new(0.0, 0.0, -4.0), h)
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// The box test agrees with the point test at every point of the box (its corners
        /// and random points inside): a box outside has all of them beyond one common
        /// plane; a plane dropped from the active set has none of them beyond it.
        #[test]
        fn the_box_test_is_implied_by_every_point_of_the_box(
            (p, n) in triangle(2.5),
            (centre, half) in axis_box(),
            inner in prop::collection::vec((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), 8),
        ) {
            let bounds = VolumeBounds::new(p, n);
            let corners = (0..8).map(|c| {
                DVec3::new(
                    if c & 1 == 0 { -1.0 } else { 1.0 },
                    if c & 2 == 0 { -1.0 } else { 1.0 },
                    if c & 4 == 0 { -1.0 } else { 1.0 },
                )
            });
            let inner = inner.into_iter().map(|(x, y, z)| DVec3::new(x, y, z));
            let points: Vec<DVec3> = corners.chain(inner).map(|s| centre + s * half).collect();
            let masks: Vec<u32> = points.iter().map(|&x| bounds.outside(x)).collect();
            match bounds.box_side(centre, half, bounds.all_planes()) {
                BoxSide::Outside => {
                    let common = masks.iter().fold(u32::MAX, |m, &x| m & x);
                    prop_assert_ne!(common, 0);
                }
                BoxSide::Within(active) => {
                    let dropped = bounds.all_planes() & !active;
                    for (&point, m) in points.iter().zip(masks) {
                        prop_assert_eq!(m & dropped, 0);
                        // So the test among the planes still cutting the box is complete.
                        prop_assert_eq!(bounds.outside_of(point, active), m);
                    }
                }
            }
        }

        /// The test among some planes is the full test restricted to them.
        #[test]
        fn the_test_among_some_planes_is_the_full_test_restricted(
            (p, n) in triangle(2.5),
            point in vec3(),
            planes in any::<u32>(),
        ) {
            let bounds = VolumeBounds::new(p, n);
            let point = 2.0 * point;
            prop_assert_eq!(bounds.outside_of(point, planes), bounds.outside(point) & planes);
        }
    }

    #[test]
    fn boxes_beyond_a_side_are_outside_and_boxes_in_front_are_not() {
        let bounds = narrow_frustum();
        let all = bounds.all_planes();
        assert_eq!(all.count_ones() as usize, bounds.len());
        // A flat box far to the side, and one point (zero extent) behind the base.
        for (centre, half) in [
            (DVec3::new(6.0, 0.2, -3.0), DVec3::new(0.5, 0.5, 0.0)),
            (DVec3::new(0.2, 0.2, 3.0), DVec3::ZERO),
        ] {
            assert_eq!(bounds.box_side(centre, half, all), BoxSide::Outside);
        }
        // A box in front: inside several planes entirely (dropped), cut by none or some.
        match bounds.box_side(DVec3::new(0.3, 0.3, -3.0), DVec3::splat(0.05), all) {
            BoxSide::Within(active) => assert_ne!(active, all),
            BoxSide::Outside => panic!("a box inside the volume is outside"),
        }
        // A box with a non-finite corner (an infinite box) is never outside, nor is one
        // tested against no plane.
        let infinite = (DVec3::splat(f64::NAN), DVec3::splat(f64::INFINITY));
        assert_eq!(
            bounds.box_side(infinite.0, infinite.1, all),
            BoxSide::Within(all)
        );
        assert_eq!(
            bounds.box_side(DVec3::new(6.0, 0.2, -3.0), DVec3::ZERO, 0),
            BoxSide::Within(0)
        );
    }

    #[test]
    fn a_narrow_frustum_is_bounded_on_every_side() {
        // A perspective-like triangle looking down -z from the origin: points far off to
        // either side, behind the base or beyond a side are outside; points in front are not.
        let bounds = narrow_frustum();
        assert!(bounds.len() >= 4, "{bounds:?}");
        assert_eq!(bounds.outside(DVec3::new(0.2, 0.2, -3.0)), 0);
        for far in [
            DVec3::new(5.0, 0.2, -3.0),
            DVec3::new(-5.0, 0.2, -3.0),
            DVec3::new(0.2, 5.0, -3.0),
            DVec3::new(0.2, 0.2, 3.0),
        ] {
            assert_ne!(bounds.outside(far), 0, "{far}");
        }
    }

    #[test]
    fn directions_spanning_more_than_a_half_space_cull_nothing() {
        // Normals along +x, +y and -x-y-ish (diverging over 180 degrees) with z mixed in:
        // only planes containing all three directions' half-spaces survive, if any.
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let n = [
            DVec3::new(1.0, 0.0, 0.1),
            DVec3::new(0.0, 1.0, 0.1),
            DVec3::new(-1.0, -1.0, 0.1),
        ];
        let bounds = VolumeBounds::new(p, n);
        let cache = ProjectionTriangleCache::new(p, n);
        for (u, v, t) in [(0.1, 0.1, 50.0), (0.8, 0.1, 30.0), (0.1, 0.8, 70.0)] {
            assert_eq!(bounds.outside(cache.ray_point(u, v, t)), 0);
        }
        // A zero direction gives no plane from it, never a wrong one.
        let bounds = VolumeBounds::new(p, [DVec3::ZERO, -DVec3::Z, -DVec3::Z]);
        assert_eq!(bounds.outside(DVec3::new(0.5, 0.2, -2.0)), 0);
    }
}
