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
//! A sign change, not a zero, is what matters. Rays that all meet in one point at the
//! same depth `t0` (a pinhole at `t0 < 0`, or the inward-looking sphere's centre at
//! `t0 > 0`, where `r_i(t) = c + (t - t0) n_i`) give `E1(t) x E2(t) = (t - t0)^2 f1 x f2`:
//! the Jacobian has a double root, keeps its sign, and the cones before and beyond the
//! focus are disjoint (the image beyond it is turned by 180 degrees, not mirrored): no fold.
//! But the triangle collapses there, and a scene triangle reaching across the plane of the
//! point has an unbounded image ([`ProjectionTriangleCache::collapses_before`]), which is
//! another reason to treat the triangle another way when `t0 > 0`. When the vertex rays
//! meet the point at different depths (directions of different lengths), the interpolated
//! rays miss it and cross each other near it: a real fold.

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
    /// Degenerate cases (each has a test):
    ///
    /// * rays meeting in one point at one depth (module doc): a double root, no fold;
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
        for q in self.jacobian_along_vertex_rays() {
            let [_, c1, c2] = q.coefficients;
            let mut judge = |value: f64, bound: f64| {
                positive |= value > tol * bound;
                negative |= value < -tol * bound;
            };
            let (start, bound) = q.at(0.0);
            judge(start, bound);
            if t_max.is_finite() {
                let (end, bound) = q.at(t_max);
                judge(end, bound);
            } else if c2.abs() > tol * f * f * q.size {
                judge(c2, f * f * q.size);
            } else {
                judge(c1, e * f * q.size);
            }
            if let Some(vertex) = q.vertex().filter(|&v| v > 0.0 && v < t_max) {
                let (extreme, bound) = q.at(vertex);
                judge(extreme, bound);
            }
        }
        positive && negative
    }

    /// Whether the rays all meet in one point at some depth in `(0, t_max]`: there the
    /// parametric triangle collapses to that point (`N(t) = 0`), and the Jacobian, though it
    /// keeps its sign (a double root, see the module doc), vanishes on the whole triangle.
    ///
    /// The collapse makes the map from scene to screen a central projection from the point:
    /// the depth surfaces are parallel planes, and the one through the point is imaged at
    /// infinity, as a pinhole camera images the plane through its eye. A scene triangle that
    /// reaches across that plane has an unbounded image, two pieces that go off to
    /// infinity in opposite directions, which no outline of scene-edge images can enclose
    /// (measured in audit 4 of docs/robustness.md: a floor seen through rays that converge
    /// in front of it had none of its 1,930 pixels drawn). A renderer has to treat such
    /// triangles another way (the trilinear renderer ray casts their pixels, as for folds).
    /// A pinhole (the point behind the base, `t < 0`) does not collapse in this sense: the
    /// view plane `t = 0` clips its eye plane away.
    ///
    /// Each vertex direction's quadratic `N(t) . n_i` must reach zero, within the tolerance
    /// of [`ProjectionTriangleCache::folds_before`], at its vertex (its extremum), which
    /// lies in `(0, t_max]`. Degenerate cases (each has a test):
    ///
    /// * the point beyond the scene (`t_max` before it) or behind the base: no collapse;
    /// * directions of different lengths (the vertex rays meet the point at different
    ///   depths): no collapse, since `N` does not vanish; that is a fold
    ///   ([`ProjectionTriangleCache::folds_before`]);
    /// * parallel rays and rays meeting only in a line (a cylinder's axis): no collapse
    ///   (the line case has a simple root of the Jacobian: a fold);
    /// * a triangle that sweeps no volume: the quadratics vanish identically, no vertex,
    ///   no collapse (the renderer ray casts it for that reason already).
    pub fn collapses_before(&self, t_max: f64) -> bool {
        let tol = SLIVER_TOL.sqrt();
        self.jacobian_along_vertex_rays().iter().all(|q| {
            q.vertex()
                .filter(|&v| v > 0.0 && v <= t_max)
                .is_some_and(|v| {
                    let (value, bound) = q.at(v);
                    value.abs() <= tol * bound
                })
        })
    }

    /// The Jacobian along each vertex ray, `N(t) . n_i`, with the size bound of the fold
    /// rule ([`ProjectionTriangleCache::folds_before`]).
    fn jacobian_along_vertex_rays(&self) -> [VertexRayJacobian; 3] {
        self.directions().map(|d| VertexRayJacobian {
            coefficients: self.cross.map(|n| n.dot(d)),
            size: d.length(),
            base_size: self.base_size,
            spread: self.spread,
        })
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

/// The quadratic `c0 + c1 t + c2 t^2 = N(t) . n_i` along one vertex ray, and what bounds its
/// size: `(e + t f)^2 |n_i|` (`e`, `f`: the largest base edge and direction difference).
struct VertexRayJacobian {
    coefficients: [f64; 3],
    size: f64,
    base_size: f64,
    spread: f64,
}

impl VertexRayJacobian {
    /// The value at depth `t` and its size bound there.
    fn at(&self, t: f64) -> (f64, f64) {
        let [c0, c1, c2] = self.coefficients;
        let scale = self.base_size + t * self.spread;
        (c0 + t * (c1 + t * c2), scale.powi(2) * self.size)
    }

    /// The depth of the extremum; `None` for a quadratic with no `t^2` term.
    fn vertex(&self) -> Option<f64> {
        let [_, c1, c2] = self.coefficients;
        (c2 != 0.0).then(|| -c1 / (2.0 * c2))
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

    /// Rays through one point at one depth keep the Jacobian's sign (a double root); with
    /// directions of different lengths the vertex rays still meet the point, at depths 1,
    /// 0.5 and 2, but the rays between them miss it and cross: along the first vertex ray
    /// the Jacobian is `4 - 10 t + 4 t^2`, negative from t = 0.5 to 2.
    #[test]
    fn rays_meeting_in_one_point() {
        let centre = V(0.3, 0.2, 4.0);
        let p = unit_base();
        let equal = ProjectionTriangleCache::new(p, p.map(|x| centre - x));
        for t_max in [0.5, 1.0, 1.5, 1e3, f64::INFINITY] {
            assert!(!equal.folds_before(t_max), "{t_max}");
        }
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

    /// Rays through one point at depth 1 (equal depths): a collapse once the scene reaches
    /// that depth, at any scale; with unequal lengths, a pinhole behind the base, parallel
    /// rays, rays through a line, or a triangle sweeping no volume: none.
    #[test]
    fn rays_meeting_in_front_collapse_there() {
        let p = unit_base();
        for (s, shift) in [
            (1.0, DVec3::ZERO),
            (1e-3, V(1e4, 0.0, -1e4)),
            (1e3, DVec3::ZERO),
        ] {
            let base = p.map(|x| x * s + shift);
            let centre = V(0.3, 0.2, 4.0) * s + shift;
            let cache = ProjectionTriangleCache::new(base, base.map(|x| centre - x));
            assert!(cache.collapses_before(1.01), "{s}");
            assert!(cache.collapses_before(f64::INFINITY), "{s}");
            assert!(
                !cache.collapses_before(0.99),
                "{s}: the scene ends before the point"
            );
        }
        let centre = V(0.3, 0.2, 4.0);
        let lengths = [1.0, 2.0, 0.5];
        let unequal =
            ProjectionTriangleCache::new(p, [0, 1, 2].map(|i| (centre - p[i]) * lengths[i]));
        assert!(!unequal.collapses_before(f64::INFINITY));
        assert!(unequal.folds_before(f64::INFINITY), "a fold instead");
        let eye = V(0.2, -0.1, -3.0);
        let pinhole = ProjectionTriangleCache::new(p, p.map(|x| x - eye));
        assert!(!pinhole.collapses_before(f64::INFINITY));
        let parallel = ProjectionTriangleCache::new(p, [V(0.1, 0.0, 1.0); 3]);
        assert!(!parallel.collapses_before(f64::INFINITY));
        // Rays from three points of a cylinder to its axis (the z axis), meeting it at depth
        // 1: the parametric triangle becomes a segment of the axis, not a point.
        let ring = [V(1.0, 0.0, 0.0), V(0.0, 1.0, 0.5), V(-1.0, 0.0, 1.0)];
        let to_axis = ring.map(|x| V(-x.x, -x.y, 0.0));
        let cylinder = ProjectionTriangleCache::new(ring, to_axis);
        assert!(!cylinder.collapses_before(f64::INFINITY));
        assert!(cylinder.folds_before(f64::INFINITY), "a fold instead");
        let flat = [V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0), V(2.0, 0.0, 0.0)];
        let sheet = ProjectionTriangleCache::new(flat, [V(0.0, 1.0, 0.0); 3]);
        assert!(!sheet.collapses_before(f64::INFINITY));
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
