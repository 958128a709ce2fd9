//! Folds and collapses of a projection triangle's rays, and the one kind of them that the
//! outlines of projected shapes cannot follow.
//!
//! The Jacobian of `(u, v, t) -> ray(u, v, t)` is `J(u, v, t) = det[E1(t), E2(t),
//! trinorm(u, v)] = N(t) . trinorm(u, v)` with `N(t) = E1(t) x E2(t) = N0 + t N1 + t^2 N2`
//! (see [`ProjectionTriangleCache::sweeps_no_volume`]). Where it changes sign the rays cross
//! (a *fold*) and a scene point has three images instead of one. That does not stop the
//! shapes of chapter 4 (Vallance 2005) from being exact: seen from the screen, the pixels of
//! the projection triangle whose rays meet a scene plane `n . x = n . s` at depth `t` lie on
//! the line `n . (tripoint(u, v) + t trinorm(u, v)) = n . s` of the barycentric plane,
//! affine in both `(u, v)` and `t`, so these lines form a pencil through one point and turn
//! monotonically as `t` grows. The sweep of a scene triangle by depth therefore covers each
//! pixel at most once, its shapes are closed by the images of the scene edges alone, and a
//! fold changes only how many shapes there are (appendix C's configurations fold, and their
//! 2 to 9 vertices are this).
//!
//! What the outlines cannot follow is a depth `t0` where the parametric triangle
//! `r1(t), r2(t), r3(t)` *degenerates* (`N(t0) = 0`: it collapses to a segment or a point).
//! Every scene point's cubic has a root there, rejected as spurious (the degenerate-triangle
//! rule of `point_projection`), but the barycentrics of a scene edge's crossing at depths
//! near `t0` grow without bound and change sign: the scene plane through the degenerate
//! triangle is imaged at infinity, and an outline sampled across `t0` closes its curve on
//! the wrong side. This happens where the rays converge through one point (the
//! inward-looking sphere; drawn as a central projection by the renderer) and where they
//! converge onto one line, e.g. base points in one plane with directions of equal component
//! along its normal, whose parametric triangles stay parallel to it and flip over where
//! their area passes zero. [`ProjectionTriangleCache::degenerates_before`] tells a renderer
//! whether such a depth lies in front of the scene's far end.

use glam::DVec3;

use super::ProjectionTriangleCache;
use crate::geometry::solve_quadratic;

/// How small (relative to the bound on its size) the parametric triangle's normal `N(t)`
/// must get for [`ProjectionTriangleCache::degenerates_before`]: far above the rounding of
/// an exact zero and above the degenerate-triangle rule's own threshold (a triangle thinner
/// than `1e-5` of its size), since a renderer only loses speed by treating a near miss as
/// degenerate.
const DEGENERATE_TOL: f64 = 1e-3;

impl ProjectionTriangleCache {
    /// The depths `t > 0` at which the parametric triangle degenerates (`N(t) = 0`, module
    /// doc), up to `DEGENERATE_TOL` (1e-3) of its size: the least and the greatest, `None`
    /// where it never does. (`N` is a quadratic in `t`: it can vanish at two depths.)
    ///
    /// Where `N` vanishes each of its three components does, so the candidates are the real
    /// roots of the components' quadratics (and, for a near miss, their extrema); at each
    /// candidate `|N(t)|` is compared with `(e + t f)^2`, the bound on its size from the
    /// largest base edge `e` and direction difference `f` (as in the degenerate-triangle
    /// rule): scale-free, and blind to rounding.
    ///
    /// Degenerate cases (each has a test):
    ///
    /// * rays through one point at one depth (a collapse to a point) or onto one line at
    ///   one depth (a segment): that depth;
    /// * rays that cross without degenerating (a fold of generic directions): none;
    /// * a pinhole behind the base (`t < 0`) or parallel rays: none;
    /// * a triangle that sweeps no volume (`N` zero at every depth, every component
    ///   identically zero): none reported here ([`Self::sweeps_no_volume`] says it);
    /// * non-finite vertices: comparisons with NaN are false, so none is claimed.
    pub fn degenerate_depths(&self) -> Option<(f64, f64)> {
        let [n0, n1, n2] = self.cross;
        let (e, f) = (self.base_size, self.spread);
        let degenerate_at = |t: &f64| {
            let normal = n0 + *t * (n1 + *t * n2);
            *t > 0.0 && normal.length() <= DEGENERATE_TOL * (e + *t * f).powi(2)
        };
        let mut range: Option<(f64, f64)> = None;
        for k in 0..3 {
            let (c0, c1, c2) = (n0[k], n1[k], n2[k]);
            let extremum = (c2 != 0.0).then(|| -c1 / (2.0 * c2));
            let roots = solve_quadratic(c2, c1, c0);
            for t in roots.iter().chain(extremum).filter(degenerate_at) {
                range = Some(range.map_or((t, t), |(lo, hi)| (lo.min(t), hi.max(t))));
            }
        }
        range
    }

    /// Whether the parametric triangle degenerates at some depth in `(0, t_max]` (`t_max`
    /// may be infinite; see [`Self::degenerate_depths`]).
    pub fn degenerates_before(&self, t_max: f64) -> bool {
        self.degenerate_depths()
            .is_some_and(|(first, _)| first <= t_max)
    }

    /// The largest depth `t >= 0` at which a ray of the triangle can be inside the sphere
    /// (`center`, `radius`): a renderer need only look for folds before it.
    ///
    /// The ray `tripoint + t trinorm` is in the sphere only where `t |trinorm| <=
    /// |tripoint - center| + radius`. Over the triangle `|tripoint - center|` is at most
    /// its largest value at a vertex (distance is convex), and `|trinorm|` is at least the
    /// smallest component of the three directions along their mean direction (a convex
    /// combination of them). Degenerate cases: infinite where that component is not
    /// positive (directions that vanish, or turn 90 degrees or more away from their mean:
    /// no finite bound is claimed). `center` and `radius` must be finite (`f64::max`
    /// skips a NaN distance).
    pub fn depth_reaching(&self, center: DVec3, radius: f64) -> f64 {
        let base = [self.p1, self.p1 + self.e1, self.p1 + self.e2];
        let reach = base.iter().map(|p| p.distance(center)).fold(0.0, f64::max) + radius;
        let directions = self.directions();
        let mean = (directions[0] + directions[1] + directions[2]).normalize_or_zero();
        let slowest = directions
            .iter()
            .map(|d| d.dot(mean))
            .fold(f64::INFINITY, f64::min);
        if slowest > 0.0 {
            reach / slowest
        } else {
            f64::INFINITY
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::vec3;
    use super::*;
    use proptest::prelude::*;

    const V: fn(f64, f64, f64) -> DVec3 = DVec3::new;

    fn unit_base() -> [DVec3; 3] {
        [V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0), V(0.0, 1.0, 0.0)]
    }

    /// Rays from the base in the plane z = 0 whose z components are all 1: the parametric
    /// triangle stays parallel to the base, and the first two vertex rays cross at
    /// `t = 1 / 0.6` (the first looks right, the second left) while the third is parallel
    /// to the first: the triangle's area is `(1 - 0.6 t) / 2`, zero at `t = 1 / 0.6`.
    fn crossing() -> [DVec3; 3] {
        [V(0.3, 0.0, 1.0), V(-0.3, 0.0, 1.0), V(0.3, 0.0, 1.0)]
    }

    #[test]
    fn rays_flipping_the_triangle_over_degenerate_where_they_cross() {
        let cache = ProjectionTriangleCache::new(unit_base(), crossing());
        assert!(cache.degenerates_before(1.7));
        assert!(cache.degenerates_before(f64::INFINITY));
        assert!(!cache.degenerates_before(1.6), "the scene ends before");
        let (first, last) = cache.degenerate_depths().unwrap();
        assert!(
            (first - 1.0 / 0.6).abs() < 1e-9 && last == first,
            "{first} {last}"
        );
        // The same triangle with the rays turned outwards: they diverge, never cross.
        let unfolded = crossing().map(|n| V(-n.x, n.y, n.z));
        let cache = ProjectionTriangleCache::new(unit_base(), unfolded);
        assert!(!cache.degenerates_before(f64::INFINITY));
    }

    /// A generic fold: the Jacobian takes both signs along the vertex rays from the base
    /// on, but the parametric triangle never degenerates (appendix C's configuration (9),
    /// Vallance 2005).
    #[test]
    fn generic_folds_do_not_degenerate() {
        let p = [
            V(-0.45, 0.44, -0.43),
            V(0.58, -0.75, -0.58),
            V(0.0, 0.81, -0.26),
        ];
        let n = [
            V(0.34, 0.54, -0.77),
            V(-0.74, -0.52, -0.43),
            V(0.37, 0.52, 0.77),
        ];
        let cache = ProjectionTriangleCache::new(p, n);
        assert!(!cache.degenerates_before(f64::INFINITY));
        let signs: Vec<bool> = (0..200)
            .flat_map(|k| n.map(|d| cache.plane_at(f64::from(k) * 0.05).1.dot(d) > 0.0))
            .collect();
        assert!(signs.contains(&true) && signs.contains(&false));
    }

    /// Rays through one point at one depth (a collapse to a point), at any scale; with
    /// directions of unequal lengths the rays miss the point and the triangle stays a
    /// triangle; a pinhole behind the base, parallel rays: none; rays onto a line: there.
    #[test]
    fn rays_meeting_in_front_degenerate_there() {
        let p = unit_base();
        for (s, shift) in [
            (1.0, DVec3::ZERO),
            (1e-3, V(1e4, 0.0, -1e4)),
            (1e3, DVec3::ZERO),
        ] {
            let base = p.map(|x| x * s + shift);
            let centre = V(0.3, 0.2, 4.0) * s + shift;
            let cache = ProjectionTriangleCache::new(base, base.map(|x| centre - x));
            assert!(cache.degenerates_before(1.01), "{s}");
            assert!(
                !cache.degenerates_before(0.99),
                "{s}: the scene ends before"
            );
        }
        let centre = V(0.3, 0.2, 4.0);
        let lengths = [1.0, 2.0, 0.5];
        let unequal =
            ProjectionTriangleCache::new(p, [0, 1, 2].map(|i| (centre - p[i]) * lengths[i]));
        assert!(!unequal.degenerates_before(f64::INFINITY));
        let eye = V(0.2, -0.1, -3.0);
        let pinhole = ProjectionTriangleCache::new(p, p.map(|x| x - eye));
        assert!(!pinhole.degenerates_before(f64::INFINITY));
        let parallel = ProjectionTriangleCache::new(p, [V(0.1, 0.0, 1.0); 3]);
        assert!(!parallel.degenerates_before(f64::INFINITY));
        // Rays from three points of a cylinder to its axis (the z axis), meeting it at depth
        // 1: the parametric triangle becomes a segment of the axis.
        let ring = [V(1.0, 0.0, 0.0), V(0.0, 1.0, 0.5), V(-1.0, 0.0, 1.0)];
        let to_axis = ring.map(|x| V(-x.x, -x.y, 0.0));
        let cylinder = ProjectionTriangleCache::new(ring, to_axis);
        assert!(cylinder.degenerates_before(1.0 + 1e-9));
        assert!(!cylinder.degenerates_before(0.9));
        let (first, last) = cylinder.degenerate_depths().unwrap();
        assert!(
            first <= 1.0 && last >= 1.0 && last - first < 0.1,
            "{first} {last}"
        );
    }

    #[test]
    fn triangles_sweeping_no_volume_are_left_to_their_own_rule() {
        // Collinear base points, rays in their plane: N is zero at every depth.
        let p = [V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0), V(2.0, 0.0, 0.0)];
        let n = [V(0.0, 1.0, 0.0), V(-0.5, 1.0, 0.0), V(1.0, 1.0, 0.0)];
        let cache = ProjectionTriangleCache::new(p, n);
        assert!(cache.sweeps_no_volume());
        assert!(!cache.degenerates_before(f64::INFINITY));
    }

    /// Scaling the base by `s` and the directions by `k` and translating both leaves the
    /// answer where it was, at depths scaled by `s / k`; so does the depth bound.
    #[test]
    fn the_rule_is_scale_free() {
        for (s, k, shift) in [
            (1e-3, 1.0, DVec3::ZERO),
            (1e3, 1.0, DVec3::ZERO),
            (1.0, 1e-3, DVec3::ZERO),
            (1.0, 1e3, DVec3::ZERO),
            (1.0, 1.0, V(1e4, -1e4, 1e4)),
            (1e-3, 1e3, V(1e4, 1e4, 0.0)),
        ] {
            let p = unit_base().map(|x| x * s + shift);
            let cache = ProjectionTriangleCache::new(p, crossing().map(|n| n * k));
            let depth = s / k;
            assert!(cache.degenerates_before(1.7 * depth), "{s} {k} {shift}");
            assert!(!cache.degenerates_before(1.6 * depth), "{s} {k} {shift}");
            let reach = cache.depth_reaching(V(0.0, 0.0, 10.0) * s + shift, s);
            // |base - centre| <= sqrt(101); the mean direction is (0.1, 0, 1) / sqrt(1.01),
            // along which the slowest direction, (-0.3, 0, 1), moves 0.97 / sqrt(1.01).
            let expected = (101.0_f64.sqrt() + 1.0) * 1.01_f64.sqrt() / 0.97 * depth;
            assert!(
                (reach / expected - 1.0).abs() < 1e-6,
                "{reach} vs {expected}"
            );
        }
    }

    #[test]
    fn depth_reaching_a_sphere() {
        let cache = ProjectionTriangleCache::new(unit_base(), crossing());
        let reach = cache.depth_reaching(V(0.0, 0.0, 10.0), 1.0);
        // No ray point beyond it is in the sphere; the central ray gets there near 10.
        assert!((11.0..12.0).contains(&reach), "{reach}");
        // Directions 90 degrees or more from their mean: no finite bound.
        let away = [V(1.0, 0.0, 0.0), V(-1.0, 0.0, 0.0), V(0.0, 0.0, 1e-3)];
        let cache = ProjectionTriangleCache::new(unit_base(), away);
        assert_eq!(cache.depth_reaching(DVec3::ZERO, 1.0), f64::INFINITY);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// Random triangles: the predicate agrees with the smallest relative size of `N(t)`
        /// sampled on a grid of 4000 depths in `(0, t_max]`: below 1e-6 it degenerates,
        /// above 1e-2 it does not. Random directions almost never degenerate, so a third of
        /// the cases aim the three rays at one point, reached at `at * t_max`: degenerate
        /// exactly when `at < 1`.
        #[test]
        fn agrees_with_the_sampled_normal(
            p in [vec3(2.0), vec3(2.0), vec3(2.0)],
            n in [vec3(1.5), vec3(1.5), vec3(1.5)],
            offset in vec3(100.0),
            t_max in 0.1..10.0f64,
            meet in prop_oneof![Just(None), Just(None), (0.01..2.0f64).prop_map(Some)],
        ) {
            let p = p.map(|x| x + offset);
            let n = match meet {
                Some(at) => p.map(|x| (offset + n[0] - x) / (at * t_max)),
                None => n,
            };
            let cache = ProjectionTriangleCache::new(p, n);
            let (e, f) = (cache.base_size, cache.spread);
            let mut smallest = f64::INFINITY;
            for k in 1..=4000 {
                let t = t_max * f64::from(k) / 4000.0;
                let (_, normal) = cache.plane_at(t);
                smallest = smallest.min(normal.length() / (e + t * f).powi(2));
            }
            let degenerates = cache.degenerates_before(t_max);
            match meet {
                Some(at) if (at - 1.0).abs() > 1e-6 => {
                    prop_assert_eq!(degenerates, at < 1.0, "meeting at {} t_max", at);
                }
                Some(_) => {}
                None if smallest < 1e-6 => prop_assert!(degenerates, "smallest {smallest}"),
                None if smallest > 1e-2 => prop_assert!(!degenerates, "smallest {smallest}"),
                None => {}
            }
        }
    }
}
