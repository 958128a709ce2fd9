//! Folds of a projection triangle's rays: where they cross, the Jacobian of
//! `(u, v, t) -> ray(u, v, t)` changes sign and the outlines of projected shapes, made of the
//! images of scene edges, no longer bound what the triangle sees.
//!
//! The Jacobian is `J(u, v, t) = det[E1(t), E2(t), trinorm(u, v)] = N(t) . trinorm(u, v)`
//! with `N(t) = E1(t) x E2(t) = N0 + t N1 + t^2 N2` (see
//! [`ProjectionTriangleCache::sweeps_no_volume`]). Where it vanishes the rays touch a
//! caustic. Where it changes sign a scene plane's image folds over: the region of the
//! screen triangle that sees a scene triangle is then bounded partly by the fold's own
//! curve, which is no image of any scene edge, so shapes traced along scene edges (slicing,
//! adaptive curves) miss or add pieces of it. A renderer has to treat such triangles
//! another way (the trilinear renderer ray casts their pixels).
//!
//! A sign change is what makes a fold. Rays that all meet in one point at the same depth
//! `t0` (a pinhole at `t0 < 0`, or the inward-looking sphere's centre at `t0 > 0`, where
//! `r_i(t) = c + (t - t0) n_i`) give `E1(t) x E2(t) = (t - t0)^2 f1 x f2`: the Jacobian has
//! a double root and keeps its sign; the cones before and beyond the focus are disjoint
//! (the image beyond it is turned by 180 degrees, not mirrored). Behind the base
//! (`t0 <= 0`, a pinhole) that is harmless. In front of it (`0 < t0`) it is not: the scene
//! points of the focus plane (through `c`, parallel to the parametric triangles) other than
//! `c` lie on no ray, so a scene triangle that crosses that plane has an unbounded image,
//! and its outline, traced along the images of its edges, passes through infinity. Audit 4
//! (docs/robustness.md) found `--method trilinear` drawing nothing of a floor seen through
//! two such triangles (1930 px missing); so a focus in front of the base, within the depth
//! range asked about, is reported as a fold too (its pixels are ray cast). When the vertex
//! rays meet the point at different depths (directions of different lengths), the
//! interpolated rays miss it and cross each other near it: a real fold.

use glam::DVec3;

use super::{ProjectionTriangleCache, SLIVER_TOL};

impl ProjectionTriangleCache {
    /// Whether the rays fold over at some depth in `[0, t_max]` (`t_max` may be infinite):
    /// the Jacobian (module doc) takes both signs on the triangle there.
    ///
    /// The Jacobian is linear in `(u, v)`, so over the triangle it lies between its values
    /// along the three vertex directions `n_i`, each a quadratic `N(t) . n_i` in `t` whose
    /// extremes on the range lie at its ends and at its vertex. Each of those values is
    /// compared, as in the degenerate-triangle rule, with the bound `(e + t f)^2 |n_i|` on
    /// its size (`e`, `f`: the largest base edge and direction difference) and counts as a
    /// sign only beyond `sqrt(SLIVER_TOL)` (1e-5) of it: scale-free, and blind to rounding.
    ///
    /// A focus in front of the base (module doc) counts as a fold when its depth `t0`, where
    /// the parametric triangle collapses to a point, lies in `(0, t_max)`: `N(t)` is then
    /// `(t - t0)^2 N2`, so `t0 = -N1.N2 / (2 N2.N2)` and `|N(t0)|` is zero, judged against
    /// the bound `(e + t0 f)^2` as above.
    ///
    /// Degenerate cases (each has a test):
    ///
    /// * rays meeting in one point at one depth (module doc): a double root; a fold only
    ///   when that depth is in front of the base and before `t_max`;
    /// * the same rays with directions of different lengths: a real fold near the point;
    /// * parallel rays (`f = 0`): a constant Jacobian, no fold;
    /// * rays crossing the base triangle itself (both signs at `t = 0`): a fold;
    /// * a sliver base (the Jacobian below the tolerance at `t = 0`): no sign there, so it
    ///   folds only where its rays really cross further on;
    /// * a triangle that sweeps no volume (the Jacobian zero throughout): no fold (the
    ///   renderer ray casts it for that reason already);
    /// * an infinite `t_max`: the far end is judged by the leading coefficient that counts,
    ///   `N2 . n_i` against `f^2 |n_i|`, else `N1 . n_i` against `e f |n_i|` (the Jacobian's
    ///   largest size relative to the bound when `N2 . n_i` vanishes);
    /// * non-finite vertices: comparisons with NaN are false, so no fold is claimed (the
    ///   renderer rejects such meshes elsewhere).
    pub fn folds_before(&self, t_max: f64) -> bool {
        let (e, f) = (self.base_size, self.spread);
        let tol = SLIVER_TOL.sqrt();
        let (mut positive, mut negative) = (false, false);
        for d in self.directions() {
            let size = d.length();
            let [c0, c1, c2] = self.cross.map(|n| n.dot(d));
            let mut judge = |value: f64, bound: f64| {
                positive |= value > tol * bound;
                negative |= value < -tol * bound;
            };
            let at = |t: f64| (c0 + t * (c1 + t * c2), (e + t * f).powi(2) * size);
            let (start, bound) = at(0.0);
            judge(start, bound);
            if t_max.is_finite() {
                let (end, bound) = at(t_max);
                judge(end, bound);
            } else if c2.abs() > tol * f * f * size {
                judge(c2, f * f * size);
            } else {
                judge(c1, e * f * size);
            }
            if c2 != 0.0 {
                let vertex = -c1 / (2.0 * c2);
                if vertex > 0.0 && vertex < t_max {
                    let (extreme, bound) = at(vertex);
                    judge(extreme, bound);
                }
            }
        }
        (positive && negative) || self.focus_before(t_max)
    }

    /// Whether all rays meet in one point at a depth `t0` in `(0, t_max)` (the doc of
    /// [`Self::folds_before`]). `N2 = 0` (parallel direction differences: the triangle
    /// cannot collapse to a point away from a constant `N`) is never a focus.
    fn focus_before(&self, t_max: f64) -> bool {
        let [n0, n1, n2] = self.cross;
        let n2_squared = n2.length_squared();
        if n2_squared == 0.0 {
            return false;
        }
        let t0 = -n1.dot(n2) / (2.0 * n2_squared);
        let (e, f) = (self.base_size, self.spread);
        let residual = (n0 + t0 * (n1 + t0 * n2)).length();
        t0 > 0.0 && t0 < t_max && residual <= SLIVER_TOL.sqrt() * (e + t0 * f).powi(2)
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
    use super::*;
    use proptest::prelude::*;

    const V: fn(f64, f64, f64) -> DVec3 = DVec3::new;

    fn unit_base() -> [DVec3; 3] {
        [V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0), V(0.0, 1.0, 0.0)]
    }

    /// The first two vertex rays cross at `t = 1 / 0.6` (the first looks right, the second
    /// left), the third is parallel to the first: the Jacobian is `1 - 0.6 t` everywhere.
    fn crossing() -> [DVec3; 3] {
        [V(0.3, 0.0, 1.0), V(-0.3, 0.0, 1.0), V(0.3, 0.0, 1.0)]
    }

    #[test]
    fn crossing_rays_fold_where_they_cross() {
        let cache = ProjectionTriangleCache::new(unit_base(), crossing());
        assert!(cache.folds_before(1.7));
        assert!(cache.folds_before(f64::INFINITY));
        assert!(!cache.folds_before(1.6), "the scene ends before the fold");
        // The same triangle with the rays turned outwards: they diverge, never cross.
        let unfolded = crossing().map(|n| V(-n.x, n.y, n.z));
        let cache = ProjectionTriangleCache::new(unit_base(), unfolded);
        assert!(!cache.folds_before(1e6));
        assert!(!cache.folds_before(f64::INFINITY));
    }

    #[test]
    fn rays_crossing_the_base_triangle_fold_at_the_view_plane() {
        let n = [V(1.0, 0.0, 0.1), V(1.0, 0.0, -0.1), V(1.0, 0.0, 0.1)];
        assert!(ProjectionTriangleCache::new(unit_base(), n).folds_before(1e-3));
    }

    /// Rays through one point at one depth keep the Jacobian's sign (a double root), a fold
    /// only for the focus in front of the base (module doc); with directions of different
    /// lengths the vertex rays still meet the point, at depths 1,
    /// 0.5 and 2, but the rays between them miss it and cross: along the first vertex ray
    /// the Jacobian is `4 - 10 t + 4 t^2`, negative from t = 0.5 to 2.
    #[test]
    fn rays_meeting_in_one_point() {
        let centre = V(0.3, 0.2, 4.0);
        let p = unit_base();
        let equal = ProjectionTriangleCache::new(p, p.map(|x| centre - x));
        // The focus at t = 1, in front of the base: a fold once the scene reaches it.
        for t_max in [0.5, 0.99] {
            assert!(!equal.folds_before(t_max), "{t_max}");
        }
        for t_max in [1.01, 1.5, 1e3, f64::INFINITY] {
            assert!(equal.folds_before(t_max), "{t_max}");
        }
        // Scale-free: the same triangle scaled and moved far from the origin.
        let far = ProjectionTriangleCache::new(
            p.map(|x| x * 1e3 + V(1e5, -1e5, 1e5)),
            p.map(|x| (centre - x) * 1e3),
        );
        assert!(!far.folds_before(0.99) && far.folds_before(1.01));
        let lengths = [1.0, 2.0, 0.5];
        let unequal =
            ProjectionTriangleCache::new(p, [0, 1, 2].map(|i| (centre - p[i]) * lengths[i]));
        assert!(!unequal.folds_before(0.45));
        assert!(unequal.folds_before(0.55));
        assert!(unequal.folds_before(f64::INFINITY));
        // A pinhole behind the base (perspective) and a base that is a point: no fold.
        let eye = V(0.2, -0.1, -3.0);
        let perspective = ProjectionTriangleCache::new(p, p.map(|x| x - eye));
        assert!(!perspective.folds_before(f64::INFINITY));
        let spread = [V(0.0, 0.0, 1.0), V(0.1, 0.0, 1.0), V(0.0, 0.1, 1.0)];
        let pinhole = ProjectionTriangleCache::new([DVec3::ZERO; 3], spread);
        assert!(!pinhole.folds_before(f64::INFINITY));
        // Parallel rays: a constant Jacobian.
        let parallel = ProjectionTriangleCache::new(p, [V(0.1, 0.0, 1.0); 3]);
        assert!(!parallel.folds_before(f64::INFINITY));
    }

    #[test]
    fn slivers_fold_only_where_their_rays_cross() {
        // Thinner than 1e-5 of its size: the Jacobian at t = 0 is below the tolerance.
        let p = [V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0), V(0.5, 1e-7, 0.0)];
        let diverging = [V(-0.3, -0.3, 1.0), V(0.3, -0.3, 1.0), V(0.0, 0.3, 1.0)];
        assert!(!ProjectionTriangleCache::new(p, diverging).folds_before(f64::INFINITY));
        // Rows crossing at t = 1 / 0.6 with the third ray between: a fold there.
        let n = [V(0.3, -0.3, 1.0), V(-0.3, -0.3, 1.0), V(0.0, 0.3, 1.0)];
        let cache = ProjectionTriangleCache::new(p, n);
        assert!(!cache.folds_before(1.6));
        assert!(cache.folds_before(1.7));
    }

    #[test]
    fn triangles_sweeping_no_volume_do_not_fold() {
        // Collinear base points, rays in their plane: the Jacobian is zero throughout.
        let p = [V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0), V(2.0, 0.0, 0.0)];
        let n = [V(0.0, 1.0, 0.0), V(-0.5, 1.0, 0.0), V(1.0, 1.0, 0.0)];
        let cache = ProjectionTriangleCache::new(p, n);
        assert!(cache.sweeps_no_volume());
        assert!(!cache.folds_before(f64::INFINITY));
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
            assert!(cache.folds_before(1.7 * depth), "{s} {k} {shift}");
            assert!(!cache.folds_before(1.6 * depth), "{s} {k} {shift}");
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

    fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
        (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// Random triangles: the predicate agrees with the sign of the Jacobian sampled at
        /// the vertices on a grid of 4001 depths in `[0, t_max]`, outside a band: where the
        /// samples reach beyond 1e-3 of the bound on both sides it folds; where they stay
        /// beyond it on one side it does not (a quadratic that dips across zero between
        /// two samples needs a curvature the ranges here do not allow).
        #[test]
        fn agrees_with_the_sampled_jacobian(
            p in [vec3(2.0), vec3(2.0), vec3(2.0)],
            n in [vec3(1.5), vec3(1.5), vec3(1.5)],
            offset in vec3(100.0),
            t_max in 0.1..10.0f64,
        ) {
            let p = p.map(|x| x + offset);
            let cache = ProjectionTriangleCache::new(p, n);
            let (e, f) = (cache.base_size, cache.spread);
            let band = 1e-3;
            let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
            for k in 0..=4000 {
                let t = t_max * k as f64 / 4000.0;
                let (_, normal) = cache.plane_at(t);
                for d in n {
                    let bound = (e + t * f).powi(2) * d.length();
                    let relative = normal.dot(d) / bound;
                    low = low.min(relative);
                    high = high.max(relative);
                }
            }
            let folds = cache.folds_before(t_max);
            if low < -band && high > band {
                prop_assert!(folds, "samples {low} to {high}");
            }
            if low > band || high < -band {
                prop_assert!(!folds, "samples {low} to {high}");
            }
        }
    }
}
