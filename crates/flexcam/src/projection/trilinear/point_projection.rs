//! Analytic point projection for one trilinear projection triangle (seed 000, chapter 3, with
//! the corrected formulas of notes/trilinear.md).
//!
//! A projection triangle has base points `p1, p2, p3` and (unnormalised) directions
//! `n1, n2, n3`; its rays are `ray(u, v, t) = tripoint(u, v) + t * trinorm(u, v)`. A scene
//! point `ps` is imaged at every `(u, v, t)` with `ray(u, v, t) == ps`. The parametric triangle
//! `r_i(t) = p_i + t n_i` contains `ps` in its plane exactly where
//! `f(t) = det[r1 - ps; r2 - ps; r3 - ps] = a t^3 + b t^2 + c t + d = 0`, and at each real root
//! the barycentrics of `ps` in the triangle `r1(t), r2(t), r3(t)` give `(u, v)`.
//!
//! # The cached N/K form
//!
//! [`ProjectionTriangleCache`] stores, per triangle, with `e1 = p2 - p1`, `e2 = p3 - p1`,
//! `f1 = n2 - n1`, `f2 = n3 - n1`:
//!
//! ```text
//! N0 = e1 x e2,  N1 = e1 x f2 + f1 x e2,  N2 = f1 x f2
//! K3 = [n1,n2,n3], K2 = [p1,n2,n3] + [n1,p2,n3] + [n1,n2,p3],
//! K1 = [n1,p2,p3] + [p1,n2,p3] + [p1,p2,n3], K0 = [p1,p2,p3]
//! a = K3, b = K2 - N2.ps, c = K1 - N1.ps, d = K0 - N0.ps
//! ```
//!
//! The determinant is invariant under translating the `p_i` and `ps` together, so the cache
//! evaluates these formulas in coordinates centred on `p1` (where `K0 = 0`,
//! `K1 = n1.N0`, `K2 = n1.N1`, `K3 = n1.N2`, and `ps` becomes `ps - p1`). The cubic is the
//! same; only the cancellation of large triple products against `N.ps` for meshes far from
//! the origin is avoided. A scene point then costs one subtraction and three dot products
//! before the solve ([`ProjectionTriangleCache::coefficients`]).
//!
//! # Barycentrics
//!
//! At a root `t`: `E1 = r2 - r1`, `E2 = r3 - r1`, `E3 = ps - r1`, `d11 = E1.E1`,
//! `d22 = E2.E2`, `d12 = E1.E2`, `a1 = E3.E1`, `a2 = E3.E2`, `D = d11 d22 - d12^2` (det A),
//! `u = (a1 d22 - a2 d12) / D`, `v = (a2 d11 - a1 d12) / D`. These are evaluated through the
//! Binet-Cauchy identities `D = |E1 x E2|^2`, `a1 d22 - a2 d12 = (E3 x E2).(E1 x E2)` and
//! `a2 d11 - a1 d12 = (E1 x E3).(E1 x E2)`: the same numbers without the cancellation of
//! `d11 d22 - d12^2` (the error of `u` grows as `1/sin` of the triangle's angle instead of
//! `1/sin^2`).
//!
//! # Degenerate-triangle rule
//!
//! Wherever the parametric triangle degenerates (collapses to a segment or a point) at some
//! `t`, `E1 x E2 = 0` there, so `f(t) = (r1 - ps).(E1 x E2) = 0` for *every* `ps`: such a root
//! says nothing about `ps` and is rejected as spurious. The test is relative, never an
//! absolute constant. With `s(t) = max(|e1|, |e2|, |e2 - e1|) + |t| max(|f1|, |f2|, |f2 - f1|)`
//! (the scale of the terms that cancel when the edges `E1`, `E2`, `E2 - E1` are formed, hence
//! of their rounding errors), a root is rejected when
//!
//! * `d11 <= COLLAPSE_TOL * s(t)^2` or `d22 <= COLLAPSE_TOL * s(t)^2` (an edge from `r1` has
//!   collapsed: the triangle is a segment through `r1` or a point), or
//! * `D <= SLIVER_TOL * d11 * d22`, i.e. `sin^2` of the angle between `E1` and `E2` is below
//!   `SLIVER_TOL` (the triangle is a segment).
//!
//! Both tolerances are `1e-10`: a spurious root computed with relative error up to about
//! `1e-5` (far more than the `~1e-8` of a double root, see `geometry::roots`) is rejected,
//! and a genuine triangle is only rejected when it is thinner than `1e-5` of its own size,
//! where `(u, v)` would have lost most of their digits anyway. Rejected roots are counted
//! (with multiplicity) by [`Solutions::rejected`].
//!
//! Degenerate cases (each has a test):
//!
//! * **All normals parallel** (orthographic; lengths may differ): `N2 = 0` and `n1.N1 = 0`,
//!   so `a` and `b` vanish (exactly or to rounding); the cubic is linear with one root and
//!   [`Solutions::lost_to_infinity`] is 2.
//! * **Coplanar, non-parallel normals** (`[n1, n2, n3] = 0`): `a = 0`, the cubic is a
//!   quadratic with 0 or 2 real roots, and one root went to infinity (`lost_to_infinity`
//!   is 1): the odd-count assumption of the shape algorithm does not hold for such triangles.
//! * **Perspective** (`n_i = p_i - e`): `r_i(-1) = e` for all `i`, `E1 x E2 = (1 + t)^2 N0` and
//!   `f(t) = (t + 1)^2 * linear`. The double root `t = -1` (the triangle collapsed to the
//!   eye) fails the `d11` test and is rejected; the linear factor's root is the image. The eye
//!   itself gives `f = (t + 1)^3 [n1, n2, n3]`: no image at all.
//! * **Point on the base triangle**: a root at `t = 0` (exactly 0 when `f(0) = d` is exactly
//!   zero, e.g. `ps = p1`), with the base barycentrics.
//! * **Point on a vertex ray** `ps = p_k + s n_k`: `t = s` is a root with `(u, v)` the vertex's
//!   barycentrics (inside, on the boundary). For `k = 1`, `f(t) = (t - s) n1.(E1 x E2)`: the
//!   other roots do not depend on `s` (they are where `n1` lies in the triangle's plane).
//! * **Every `t` a root** (`f` identically zero, e.g. a base triangle that is a segment with
//!   all normals parallel): nothing can be said; no solution, and
//!   [`Solutions::is_every_t`] is `true`.

use glam::DVec3;

use crate::geometry::solve_cubic;

mod fold;

/// Rejection threshold for `d11 / s(t)^2` and `d22 / s(t)^2` (module doc).
const COLLAPSE_TOL: f64 = 1e-10;

/// Rejection threshold for `D / (d11 d22) = sin^2` of the angle between `E1` and `E2`.
const SLIVER_TOL: f64 = 1e-10;

/// One solution of `ray(u, v, t) == ps` for one projection triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleSolution {
    /// The depth: the ray parameter along the unnormalised `trinorm(u, v)`. `t < 0` is behind
    /// the view plane (not on a ray, which starts at `t = 0`).
    pub t: f64,
    /// Barycentric weight of the second vertex.
    pub u: f64,
    /// Barycentric weight of the third vertex.
    pub v: f64,
    /// `0 <= u, v, u + v <= 1` up to [`ProjectionTriangleCache::INSIDE_TOL`].
    pub inside: bool,
    /// Multiplicity of the root `t` of the cubic (2: a tangency, which toggles edge parity
    /// twice; 3: a triple root).
    pub multiplicity: u8,
}

/// All solutions of one projection triangle for one scene point, sorted by ascending `t`:
/// at most three, fixed capacity (no allocation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solutions {
    items: [TriangleSolution; 3],
    len: u8,
    rejected: u8,
    lost_to_infinity: u8,
    every_t: bool,
}

impl Solutions {
    const EMPTY: Solutions = Solutions {
        items: [TriangleSolution {
            t: 0.0,
            u: 0.0,
            v: 0.0,
            inside: false,
            multiplicity: 0,
        }; 3],
        len: 0,
        rejected: 0,
        lost_to_infinity: 0,
        every_t: false,
    };

    /// The solutions (inside the triangle or not, any sign of `t`), ascending in `t`.
    pub fn as_slice(&self) -> &[TriangleSolution] {
        &self.items[..self.len as usize]
    }

    /// Iterates over [`as_slice`](Self::as_slice) by value.
    pub fn iter(&self) -> std::iter::Copied<std::slice::Iter<'_, TriangleSolution>> {
        self.as_slice().iter().copied()
    }

    /// Number of solutions.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// `true` when there is no solution.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Roots of the cubic rejected as spurious by the degenerate-triangle rule, counted with
    /// multiplicity.
    pub fn rejected(&self) -> usize {
        self.rejected as usize
    }

    /// Roots of the cubic that went to infinity (degree drop), as reported by `solve_cubic`.
    pub fn lost_to_infinity(&self) -> usize {
        self.lost_to_infinity as usize
    }

    /// `true` when the cubic vanishes identically (every `t` is a root; no solution listed).
    pub fn is_every_t(&self) -> bool {
        self.every_t
    }

    /// Number of solutions counted with multiplicity, plus rejected and lost roots: 3 for any
    /// point whose cubic is not identically zero (complex pairs aside), which parity-based
    /// callers can check.
    pub fn total_multiplicity(&self) -> usize {
        self.iter().map(|s| s.multiplicity as usize).sum()
    }
}

/// The per-triangle cache of the N/K form (module doc), in coordinates centred on `p1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionTriangleCache {
    p1: DVec3,
    n1: DVec3,
    e1: DVec3,
    e2: DVec3,
    f1: DVec3,
    f2: DVec3,
    /// `N0, N1, N2`.
    cross: [DVec3; 3],
    /// `K3, K2, K1` relative to `p1` (`K0 = 0` there).
    k3: f64,
    k2: f64,
    k1: f64,
    /// `max(|e1|, |e2|, |e2 - e1|)`.
    base_size: f64,
    /// `max(|f1|, |f2|, |f2 - f1|)`.
    spread: f64,
}

impl ProjectionTriangleCache {
    /// Absolute tolerance on `u`, `v` and `1 - u - v` of the inside test:
    /// `-INSIDE_TOL <= u, v` and `u + v <= 1 + INSIDE_TOL`. It covers the rounding of
    /// `(u, v)` (at most ~1e-10 in random well-conditioned draws, see the `accuracy_report`
    /// test) so that a point on a shared edge of two projection triangles is inside both
    /// rather than neither.
    pub const INSIDE_TOL: f64 = 1e-9;

    /// The cache of the triangle with base points `p` and directions `n` (vertex order
    /// defines `u` and `v`: `u` weighs vertex 2, `v` vertex 3).
    pub fn new(p: [DVec3; 3], n: [DVec3; 3]) -> Self {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (f1, f2) = (n[1] - n[0], n[2] - n[0]);
        let cross = [e1.cross(e2), e1.cross(f2) + f1.cross(e2), f1.cross(f2)];
        let n1 = n[0];
        ProjectionTriangleCache {
            p1: p[0],
            n1,
            e1,
            e2,
            f1,
            f2,
            cross,
            k3: n1.dot(cross[2]),
            k2: n1.dot(cross[1]),
            k1: n1.dot(cross[0]),
            base_size: e1.length().max(e2.length()).max((e2 - e1).length()),
            spread: f1.length().max(f2.length()).max((f2 - f1).length()),
        }
    }

    /// `tripoint(u, v)`.
    pub fn tripoint(&self, u: f64, v: f64) -> DVec3 {
        self.p1 + u * self.e1 + v * self.e2
    }

    /// `trinorm(u, v)` (not normalised).
    pub fn trinorm(&self, u: f64, v: f64) -> DVec3 {
        self.n1 + u * self.f1 + v * self.f2
    }

    /// `ray(u, v, t) = tripoint(u, v) + t * trinorm(u, v)`.
    pub fn ray_point(&self, u: f64, v: f64, t: f64) -> DVec3 {
        self.tripoint(u, v) + t * self.trinorm(u, v)
    }

    /// The cubic's coefficients `[a, b, c, d]` for scene point `ps`.
    pub fn coefficients(&self, ps: DVec3) -> [f64; 4] {
        let q = self.p1 - ps;
        [
            self.k3,
            self.k2 + self.cross[2].dot(q),
            self.k1 + self.cross[1].dot(q),
            self.cross[0].dot(q),
        ]
    }

    /// Every solution of `ray(u, v, t) == ps` (up to three), inside the triangle or not, any
    /// sign of `t`, spurious roots of degenerate parametric triangles removed (module doc).
    pub fn project_point(&self, ps: DVec3) -> Solutions {
        let [a, b, c, d] = self.coefficients(ps);
        let roots = solve_cubic(a, b, c, d);
        let mut out = Solutions::EMPTY;
        out.lost_to_infinity = roots.lost_to_infinity() as u8;
        out.every_t = roots.is_identically_zero();
        let w = ps - self.p1;
        for (&t, &multiplicity) in roots.as_slice().iter().zip(roots.multiplicities()) {
            match self.barycentrics(w, t) {
                Some((u, v)) => {
                    let tol = Self::INSIDE_TOL;
                    let inside = u >= -tol && v >= -tol && u + v <= 1.0 + tol;
                    out.items[out.len as usize] = TriangleSolution {
                        t,
                        u,
                        v,
                        inside,
                        multiplicity,
                    };
                    out.len += 1;
                }
                None => out.rejected += multiplicity,
            }
        }
        out
    }

    /// The plane of the parametric triangle at depth `t`: a point on it (`r1(t)`) and its
    /// (unnormalised) normal `E1(t) x E2(t) = N0 + t N1 + t^2 N2`, zero where the triangle is
    /// degenerate at `t`.
    pub fn plane_at(&self, t: f64) -> (DVec3, DVec3) {
        let [n0, n1, n2] = self.cross;
        (self.p1 + t * self.n1, n0 + t * (n1 + t * n2))
    }

    /// `(u, v)` of the scene point `ps` in the parametric triangle at depth `t` (meaningful
    /// when `ps` lies in its plane), or `None` where that triangle is degenerate (the rule of
    /// the module doc).
    pub fn barycentrics_at(&self, ps: DVec3, t: f64) -> Option<(f64, f64)> {
        self.barycentrics(ps - self.p1, t)
    }

    /// Whether the triangle sweeps no volume: the Jacobian of `(u, v, t) -> ray(u, v, t)`,
    /// `det[E1(t), E2(t), trinorm(u, v)] = N(t) . trinorm(u, v)` with
    /// `N(t) = E1(t) x E2(t) = N0 + t N1 + t^2 N2`, vanishes identically, i.e. every
    /// `N_k . n_i` is zero. Then the rays sweep a surface: either the parametric triangle
    /// is degenerate at every `t` (`N = 0`: every `t` is a root for every scene point, e.g.
    /// the pole rows of a grid over a sphere, where two vertices share base point and ray),
    /// or every ray lies in one plane (a grid cell spanning longitudes 0 to 180 of a sphere
    /// whose rays meet at its centre: points off that plane have no root). Either way no
    /// scene point can be projected through it, yet a ray caster sees what crosses the
    /// surface.
    ///
    /// The test is relative, as the degenerate-triangle rule: `|N_k . n_i|` is compared
    /// with `|n_i|` times the bound on `|N_k|` from the lengths it is formed from (`|e|^2`,
    /// `|e| |f|`, `|f|^2`, with `e` and `f` the largest base edge and direction difference)
    /// and counts as zero below `sqrt(SLIVER_TOL)` of it (a volume thinner than `1e-5` of
    /// its extent). Degenerate cases: a non-finite cache (a NaN or infinite vertex) is
    /// never called degenerate here (the renderer rejects those elsewhere); an orthographic
    /// triangle (`f = 0`) is degenerate only when its base is.
    pub fn sweeps_no_volume(&self) -> bool {
        let (e, f) = (self.base_size, self.spread);
        let scales = [e * e, e * f, f * f];
        let directions = self.directions();
        self.cross.iter().zip(scales).all(|(n, scale)| {
            directions.iter().all(|d| {
                let bound = scale * d.length();
                let jacobian = n.dot(*d);
                jacobian * jacobian <= SLIVER_TOL * bound * bound
            })
        })
    }

    /// The ray directions at the three vertices.
    fn directions(&self) -> [DVec3; 3] {
        [self.n1, self.n1 + self.f1, self.n1 + self.f2]
    }

    /// `(u, v)` of `ps = p1 + w` in the parametric triangle at `t`, or `None` where that
    /// triangle is degenerate (module doc).
    fn barycentrics(&self, w: DVec3, t: f64) -> Option<(f64, f64)> {
        let edge1 = self.e1 + t * self.f1;
        let edge2 = self.e2 + t * self.f2;
        let edge3 = w - t * self.n1;
        let d11 = edge1.length_squared();
        let d22 = edge2.length_squared();
        let scale = self.base_size + t.abs() * self.spread;
        let reference = COLLAPSE_TOL * scale * scale;
        let normal = edge1.cross(edge2);
        let det = normal.length_squared();
        // Written so that NaN (overflowing t) is rejected too.
        if !(d11 > reference && d22 > reference && det > SLIVER_TOL * d11 * d22) {
            return None;
        }
        let u = edge3.cross(edge2).dot(normal) / det;
        let v = edge1.cross(edge3).dot(normal) / det;
        Some((u, v))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use proptest::prelude::*;

    fn triple(a: DVec3, b: DVec3, c: DVec3) -> f64 {
        a.dot(b.cross(c))
    }

    /// The notes' formulas literally, in global coordinates.
    fn notes_coefficients(p: [DVec3; 3], n: [DVec3; 3], ps: DVec3) -> [f64; 4] {
        let (e1, e2, f1, f2) = (p[1] - p[0], p[2] - p[0], n[1] - n[0], n[2] - n[0]);
        let n0 = e1.cross(e2);
        let n1 = e1.cross(f2) + f1.cross(e2);
        let n2 = f1.cross(f2);
        let k3 = triple(n[0], n[1], n[2]);
        let k2 = triple(p[0], n[1], n[2]) + triple(n[0], p[1], n[2]) + triple(n[0], n[1], p[2]);
        let k1 = triple(n[0], p[1], p[2]) + triple(p[0], n[1], p[2]) + triple(p[0], p[1], n[2]);
        let k0 = triple(p[0], p[1], p[2]);
        [k3, k2 - n2.dot(ps), k1 - n1.dot(ps), k0 - n0.dot(ps)]
    }

    /// The notes' barycentric formulas literally (Gram form).
    fn notes_barycentrics(p: [DVec3; 3], n: [DVec3; 3], ps: DVec3, t: f64) -> (f64, f64) {
        let r = [0, 1, 2].map(|i| p[i] + t * n[i]);
        let (e1, e2, e3) = (r[1] - r[0], r[2] - r[0], ps - r[0]);
        let (d11, d22, d12) = (e1.dot(e1), e2.dot(e2), e1.dot(e2));
        let (a1, a2) = (e3.dot(e1), e3.dot(e2));
        let det = d11 * d22 - d12 * d12;
        ((a1 * d22 - a2 * d12) / det, (a2 * d11 - a1 * d12) / det)
    }

    fn sample() -> ([DVec3; 3], [DVec3; 3]) {
        (
            [
                DVec3::new(0.1, -0.2, 0.05),
                DVec3::new(1.2, 0.1, -0.1),
                DVec3::new(-0.1, 0.9, 0.2),
            ],
            [
                DVec3::new(-0.2, -0.1, 1.0),
                DVec3::new(0.4, 0.0, 1.1),
                DVec3::new(0.0, 0.5, 0.8),
            ],
        )
    }

    fn find(s: &Solutions, t: f64) -> TriangleSolution {
        *s.as_slice()
            .iter()
            .find(|x| (x.t - t).abs() <= 1e-9 * t.abs().max(1.0))
            .unwrap_or_else(|| panic!("no solution at t = {t}: {s:?}"))
    }

    #[test]
    fn cached_coefficients_and_barycentrics_match_the_notes() {
        let (p, n) = sample();
        let cache = ProjectionTriangleCache::new(p, n);
        let ps = cache.ray_point(0.3, 0.25, 2.5);
        let ours = cache.coefficients(ps);
        let notes = notes_coefficients(p, n, ps);
        let scale = notes.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        for (x, y) in ours.iter().zip(notes) {
            assert!((x - y).abs() <= 1e-13 * scale, "{ours:?} vs {notes:?}");
        }
        let s = cache.project_point(ps);
        let hit = find(&s, 2.5);
        assert!((hit.u - 0.3).abs() < 1e-12 && (hit.v - 0.25).abs() < 1e-12);
        assert!(hit.inside && hit.multiplicity == 1);
        for x in s.iter() {
            let (u, v) = notes_barycentrics(p, n, ps, x.t);
            assert!(
                (x.u - u).abs() < 1e-9 && (x.v - v).abs() < 1e-9,
                "{x:?} vs {u} {v}"
            );
            assert!((cache.ray_point(x.u, x.v, x.t) - ps).length() < 1e-12);
        }
    }

    #[test]
    fn every_real_root_is_returned_inside_or_not() {
        let (p, n) = sample();
        let cache = ProjectionTriangleCache::new(p, n);
        for ps in [
            cache.ray_point(0.3, 0.25, 2.5),
            cache.ray_point(-1.5, 2.0, -3.0),
            DVec3::new(5.0, -3.0, 0.7),
        ] {
            let s = cache.project_point(ps);
            let [a, b, c, d] = cache.coefficients(ps);
            let roots = solve_cubic(a, b, c, d);
            assert_eq!(s.len() + s.rejected(), roots.len());
            assert_eq!(s.rejected(), 0);
            for x in s.iter() {
                let expected = x.u >= 0.0 && x.v >= 0.0 && x.u + x.v <= 1.0;
                assert_eq!(x.inside, expected);
                assert!((cache.ray_point(x.u, x.v, x.t) - ps).length() < 1e-10 * (1.0 + x.t.abs()));
            }
        }
        // Outside solutions are still reported.
        let s = cache.project_point(cache.ray_point(-1.5, 2.0, -3.0));
        let hit = find(&s, -3.0);
        assert!(!hit.inside && (hit.u + 1.5).abs() < 1e-10 && (hit.v - 2.0).abs() < 1e-10);
    }

    #[test]
    fn parallel_normals_give_one_root() {
        let (p, _) = sample();
        let dir = DVec3::new(0.1, -0.2, 1.0);
        // Equal normals: exact degree drop.
        let cache = ProjectionTriangleCache::new(p, [dir; 3]);
        let ps = cache.ray_point(0.2, 0.5, 3.0);
        let s = cache.project_point(ps);
        assert_eq!(s.len(), 1);
        assert_eq!(s.lost_to_infinity(), 2);
        let hit = find(&s, 3.0);
        assert!(hit.inside && (hit.u - 0.2).abs() < 1e-12 && (hit.v - 0.5).abs() < 1e-12);
        // Parallel normals of different lengths (t is then not a common distance).
        let cache = ProjectionTriangleCache::new(p, [dir, 2.0 * dir, 0.5 * dir]);
        let ps = cache.ray_point(0.6, 0.1, 4.0);
        let s = cache.project_point(ps);
        assert_eq!(s.len(), 1, "{s:?}");
        assert_eq!(s.lost_to_infinity() + s.rejected(), 2);
        let hit = find(&s, 4.0);
        assert!((hit.u - 0.6).abs() < 1e-12 && (hit.v - 0.1).abs() < 1e-12);
    }

    #[test]
    fn coplanar_normals_give_a_quadratic() {
        // n3 = n1 + n2 (exact in binary): [n1, n2, n3] = 0, the normals are not parallel.
        let (p, _) = sample();
        let n = [
            DVec3::new(-0.5, 0.25, 1.0),
            DVec3::new(0.5, 0.5, 1.0),
            DVec3::new(0.0, 0.75, 2.0),
        ];
        let cache = ProjectionTriangleCache::new(p, n);
        assert_eq!(cache.coefficients(DVec3::ONE)[0], 0.0);
        let ps = cache.ray_point(0.25, 0.5, 2.0);
        let s = cache.project_point(ps);
        assert_eq!(s.lost_to_infinity(), 1);
        assert_eq!(s.len(), 2, "{s:?}");
        let hit = find(&s, 2.0);
        assert!((hit.u - 0.25).abs() < 1e-12 && (hit.v - 0.5).abs() < 1e-12 && hit.inside);
        // A point with no real root: the quadratic's discriminant is negative. Search a few.
        let none = (0..200)
            .map(|k| DVec3::new(0.3, -3.0 + 0.03 * f64::from(k), -0.5))
            .find(|&q| {
                let [_, b, c, d] = cache.coefficients(q);
                c * c - 4.0 * b * d < -1e-6 * (c * c + (4.0 * b * d).abs())
            });
        let q = none.expect("a point with two complex roots");
        let s = cache.project_point(q);
        assert!(s.is_empty() && s.lost_to_infinity() == 1, "{s:?}");
    }

    fn perspective_triangle(eye: DVec3) -> ([DVec3; 3], [DVec3; 3]) {
        let p = [
            eye + DVec3::new(-0.4, -0.3, -1.0),
            eye + DVec3::new(0.5, -0.2, -1.0),
            eye + DVec3::new(0.0, 0.45, -1.0),
        ];
        (p, p.map(|x| x - eye))
    }

    #[test]
    fn perspective_double_root_at_minus_one_is_rejected() {
        let eye = DVec3::new(0.3, -0.7, 2.0);
        let (p, n) = perspective_triangle(eye);
        let cache = ProjectionTriangleCache::new(p, n);
        for (u, v, t) in [
            (0.2, 0.3, 1.5),
            (0.7, 0.1, 0.0),
            (-0.5, 0.9, 7.0),
            (0.3, 0.3, -0.5),
        ] {
            let ps = cache.ray_point(u, v, t);
            let s = cache.project_point(ps);
            assert_eq!(s.len(), 1, "only the genuine root survives: {s:?}");
            assert_eq!(s.rejected(), 2, "{s:?}");
            let hit = s.as_slice()[0];
            assert!((hit.t - t).abs() < 1e-12 * (1.0 + t.abs()));
            assert!((hit.u - u).abs() < 1e-12 && (hit.v - v).abs() < 1e-12);
            // The rejected root is at -1, whatever ps: f(-1) = 0.
            let [a, b, c, d] = cache.coefficients(ps);
            let scale = a.abs() + b.abs() + c.abs() + d.abs();
            assert!((-a + b - c + d).abs() < 1e-14 * scale);
        }
        // The eye itself: a triple root at -1, no image.
        let s = cache.project_point(eye);
        assert!(s.is_empty() && s.rejected() == 3, "{s:?}");
        // Same rule at a very different scale (the test is relative).
        let big = 1e6;
        let (p, n) = perspective_triangle(eye);
        let cache = ProjectionTriangleCache::new(p.map(|x| x * big), n.map(|x| x * big));
        let ps = cache.ray_point(0.2, 0.3, 1.5);
        let s = cache.project_point(ps);
        assert_eq!((s.len(), s.rejected()), (1, 2), "{s:?}");
        let small = 1e-6;
        let cache = ProjectionTriangleCache::new(p.map(|x| x * small), n.map(|x| x * small));
        let s = cache.project_point(cache.ray_point(0.2, 0.3, 1.5));
        assert_eq!((s.len(), s.rejected()), (1, 2), "{s:?}");
    }

    #[test]
    fn converging_rays_collapse_in_front_and_image_beyond_the_crossing() {
        // Rays through one point F (n_i = F - p_i): the perspective case with t negated. The
        // parametric triangle collapses to F at t = +1, in front of the base (a rejected
        // double root), and is point-reflected beyond it; every scene point, before or
        // beyond F, keeps exactly one image, on its own ray. (Audit 4: POV-Ray and the ray
        // caster agree on such projections; this pins the point projection's part.)
        let p = [
            DVec3::new(-1.45764322, 0.477759585, 5.5424479),
            DVec3::new(1.54085543, 0.51293406, 6.46326127),
            DVec3::new(-1.51028013, 2.4670385, 5.55334929),
        ];
        let f = DVec3::new(0.0, 1.8, 3.8);
        let cache = ProjectionTriangleCache::new(p, p.map(|q| f - q));
        for (u, v, t) in [
            (0.2, 0.3, 0.5),
            (0.2, 0.3, 3.5),
            (-0.4, 1.2, 2.0),
            (0.9, 0.05, 40.0),
        ] {
            let ps = cache.ray_point(u, v, t);
            let s = cache.project_point(ps);
            assert_eq!((s.len(), s.rejected()), (1, 2), "{s:?}");
            let hit = s.as_slice()[0];
            assert!((hit.t - t).abs() < 1e-12 * (1.0 + t.abs()), "{hit:?}");
            assert!(
                (hit.u - u).abs() < 1e-11 && (hit.v - v).abs() < 1e-11,
                "{hit:?}"
            );
        }
        // F itself: a triple root at 1, no image.
        let s = cache.project_point(f);
        assert!(s.is_empty() && s.rejected() == 3, "{s:?}");
    }

    #[test]
    fn collapse_to_a_segment_is_rejected() {
        // r2(t) and r3(t) meet at t = 1: the triangle is a segment there, f(1) = 0 for all ps.
        let p = [DVec3::ZERO, DVec3::X, DVec3::new(0.0, 1.0, 0.0)];
        let n = [
            DVec3::Z,
            DVec3::new(-0.5, 0.5, 1.0),
            DVec3::new(0.5, -0.5, 1.0),
        ];
        let cache = ProjectionTriangleCache::new(p, n);
        for ps in [DVec3::new(0.3, 0.3, 2.0), DVec3::new(-2.0, 1.0, 0.5)] {
            let s = cache.project_point(ps);
            assert!(s.iter().all(|x| (x.t - 1.0).abs() > 1e-6), "{s:?}");
            assert!(s.rejected() >= 1, "{s:?}");
            let [a, b, c, d] = cache.coefficients(ps);
            assert!((a + b + c + d).abs() < 1e-14);
        }
    }

    #[test]
    fn point_on_the_base_triangle_has_t_zero() {
        let (p, n) = sample();
        let cache = ProjectionTriangleCache::new(p, n);
        // Exactly a vertex: d is exactly 0, so t is exactly 0.
        let s = cache.project_point(p[0]);
        let hit = find(&s, 0.0);
        assert_eq!((hit.t, hit.u, hit.v), (0.0, 0.0, 0.0));
        assert!(hit.inside);
        let ps = cache.tripoint(0.4, 0.35);
        let s = cache.project_point(ps);
        let hit = find(&s, 0.0);
        assert!(hit.t.abs() < 1e-14 && hit.inside);
        assert!((hit.u - 0.4).abs() < 1e-14 && (hit.v - 0.35).abs() < 1e-14);
    }

    #[test]
    fn point_on_a_vertex_ray() {
        let (p, n) = sample();
        let cache = ProjectionTriangleCache::new(p, n);
        let bary = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
        for k in 0..3 {
            for s_param in [0.0, 0.7, 3.0] {
                let ps = p[k] + s_param * n[k];
                let s = cache.project_point(ps);
                let hit = find(&s, s_param);
                assert!(hit.inside, "vertex {k} at {s_param}: {hit:?}");
                assert!((hit.u - bary[k].0).abs() < 1e-12 && (hit.v - bary[k].1).abs() < 1e-12);
            }
        }
        // For vertex 1 the other roots do not depend on the position along the ray.
        let others = |s_param: f64| {
            let s = cache.project_point(p[0] + s_param * n[0]);
            s.iter()
                .map(|x| x.t)
                .filter(|t| (t - s_param).abs() > 1e-6)
                .collect::<Vec<_>>()
        };
        let (x, y) = (others(0.7), others(3.0));
        assert_eq!(x.len(), y.len());
        for (a, b) in x.iter().zip(&y) {
            assert!((a - b).abs() < 1e-9 * (1.0 + a.abs()));
        }
    }

    #[test]
    fn folded_triangle_images_a_point_several_times() {
        // Along u the rays x = u + t (1 - 3u), z = t (1 + 2u) cross (a fold): the point
        // (0.3, y, 1) is seen from u = (2.6 +- sqrt(1.16)) / 4 (at v ~ y). n3 tilts in y so
        // that the cubic keeps its degree.
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let n = [
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(-2.0, 0.0, 3.0),
            DVec3::new(1.0, 0.05, 1.0),
        ];
        let cache = ProjectionTriangleCache::new(p, n);
        let ps = DVec3::new(0.3, 0.02, 1.0);
        let s = cache.project_point(ps);
        let visible: Vec<_> = s.iter().filter(|x| x.inside && x.t >= 0.0).collect();
        assert_eq!(visible.len(), 2, "{s:?}");
        for x in s.iter() {
            assert!(
                (cache.ray_point(x.u, x.v, x.t) - ps).length() < 1e-12,
                "{x:?}"
            );
        }
        // Without the tilt: exactly the two predicted images (and a quadratic).
        let cache = ProjectionTriangleCache::new(p, [n[0], n[1], n[0]]);
        let s = cache.project_point(ps);
        assert_eq!(s.lost_to_infinity(), 1);
        let mut us: Vec<f64> = s.iter().filter(|x| x.inside).map(|x| x.u).collect();
        us.sort_by(f64::total_cmp);
        let root = 1.16_f64.sqrt();
        assert_eq!(us.len(), 2, "{s:?}");
        assert!((us[0] - (2.6 - root) / 4.0).abs() < 1e-12);
        assert!((us[1] - (2.6 + root) / 4.0).abs() < 1e-12);
        assert!(s.iter().all(|x| (x.v - 0.02).abs() < 1e-12));
    }

    #[test]
    fn sweeping_no_volume() {
        let v = DVec3::new;
        // Two vertices sharing base point and ray (a sphere grid's pole row): a surface.
        let p = [v(0.0, 6.0, 0.0), v(0.0, 6.0, 0.0), v(0.8, 5.9, 0.1)];
        let n = [v(0.0, -1.0, 0.0), v(0.0, -1.0, 0.0), v(-0.8, -0.9, -0.1)];
        assert!(ProjectionTriangleCache::new(p, n).sweeps_no_volume());
        // The same within rounding (longitude -180 and 180 on a sphere of radius 6).
        let q = v(6.0 * std::f64::consts::PI.sin(), 0.0, -6.0);
        let r = v(6.0 * (-std::f64::consts::PI).sin(), 0.0, -6.0);
        assert_ne!(q, r);
        let far = v(0.0, 1.0, 0.0);
        let cache = ProjectionTriangleCache::new(
            [q, r, v(0.0, 3.0, -5.0)],
            [far - q, far - r, far - v(0.0, 3.0, -5.0)],
        );
        assert!(cache.sweeps_no_volume());
        // Collinear base points with coplanar rays in one plane: a planar sweep.
        let p = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0)];
        let n = [v(0.0, 1.0, 0.0), v(0.5, 1.0, 0.0), v(1.0, 1.0, 0.0)];
        assert!(ProjectionTriangleCache::new(p, n).sweeps_no_volume());
        // Base points and rays in one plane (x = 0), the parametric triangle never
        // degenerate: rays from a sphere's longitudes 0 and 180 to its centre.
        let centre = v(0.0, 1.0, 0.0);
        let p = [v(0.0, -4.2, 3.0), v(0.0, -4.2, -3.0), v(0.0, 2.0, -5.9)];
        let cache = ProjectionTriangleCache::new(p, p.map(|x| centre - x));
        assert!(cache.plane_at(0.5).1.length() > 1.0);
        assert!(cache.sweeps_no_volume());
        // Not degenerate: a perspective triangle, an orthographic one, a base that is a
        // point (a pinhole), two vertices sharing a base point only, and a thin but real one.
        let (p, n) = perspective_triangle(v(0.0, 0.0, 5.0));
        assert!(!ProjectionTriangleCache::new(p, n).sweeps_no_volume());
        let p = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
        assert!(!ProjectionTriangleCache::new(p, [v(0.0, 0.0, -1.0); 3]).sweeps_no_volume());
        let n = [v(0.0, 0.0, -1.0), v(0.1, 0.0, -1.0), v(0.0, 0.1, -1.0)];
        assert!(!ProjectionTriangleCache::new([DVec3::ZERO; 3], n).sweeps_no_volume());
        let p = [v(0.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
        assert!(!ProjectionTriangleCache::new(p, n).sweeps_no_volume());
        let p = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.5, 1e-3, 0.0)];
        assert!(!ProjectionTriangleCache::new(p, [v(0.0, 0.0, -1.0); 3]).sweeps_no_volume());
        // A NaN vertex is left to the renderer's own checks.
        let p = [v(f64::NAN, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.5, 1.0, 0.0)];
        assert!(!ProjectionTriangleCache::new(p, [v(0.0, 0.0, -1.0); 3]).sweeps_no_volume());
    }

    #[test]
    fn identically_zero_cubic() {
        // A base triangle that is a segment and equal normals: the parametric triangle is a
        // segment at every t, so f vanishes identically for every point.
        let p = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        let cache = ProjectionTriangleCache::new(p, [DVec3::Z; 3]);
        for ps in [DVec3::new(0.5, 0.0, 3.0), DVec3::new(0.5, 1.0, 3.0)] {
            let s = cache.project_point(ps);
            assert!(s.is_every_t() && s.is_empty(), "{s:?}");
        }
    }

    /// Points with each coordinate in `(-range, range)`: the strategy of the projection
    /// tests' random triangles.
    pub(in crate::projection::trilinear) fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
        (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    /// Uniform barycentrics inside the triangle (the square folded along its diagonal).
    fn inside_uv() -> impl Strategy<Value = (f64, f64)> {
        (0.0..=1.0f64, 0.0..=1.0f64).prop_map(|(a, b)| {
            if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            }
        })
    }

    /// Sine of the angle of the system's Jacobian [E1, E2, trinorm] at (u, v, t): the volume
    /// it spans over the product of the lengths. Zero where two solutions merge (a fold) or
    /// the parametric triangle degenerates.
    fn conditioning(cache: &ProjectionTriangleCache, u: f64, v: f64, t: f64) -> f64 {
        let e1 = cache.e1 + t * cache.f1;
        let e2 = cache.e2 + t * cache.f2;
        let n = cache.trinorm(u, v);
        triple(e1, e2, n).abs() / (e1.length() * e2.length() * n.length())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// Random triangles and rays: ps = ray(u, v, t) is found again. Skipped draws: the
        /// Jacobian sine `conditioning` below 1e-3 (near a fold or a degenerate triangle,
        /// where (u, v, t) is ill-conditioned), or a base triangle thinner than sine 1e-3.
        #[test]
        fn random_rays_round_trip(
            p in [vec3(2.0), vec3(2.0), vec3(2.0)],
            n in [vec3(1.5), vec3(1.5), vec3(1.5)],
            offset in vec3(100.0),
            (u, v) in inside_uv(),
            t in 0.0..10.0f64,
        ) {
            let p = p.map(|x| x + offset);
            let cache = ProjectionTriangleCache::new(p, n);
            let base = cache.e1.cross(cache.e2).length()
                / (cache.e1.length() * cache.e2.length());
            prop_assume!(base > 1e-3);
            prop_assume!(conditioning(&cache, u, v, t) > 1e-3);
            let ps = cache.ray_point(u, v, t);
            let s = cache.project_point(ps);
            let hit = s.iter().min_by(|a, b| {
                let da = (a.t - t).abs() + (a.u - u).abs() + (a.v - v).abs();
                let db = (b.t - t).abs() + (b.u - u).abs() + (b.v - v).abs();
                da.total_cmp(&db)
            });
            let hit = hit.ok_or_else(|| TestCaseError::fail(format!("no solution {s:?}")))?;
            prop_assert!((hit.t - t).abs() <= 1e-9 * t.max(1.0), "t {} vs {t}: {s:?}", hit.t);
            let uv_error = (hit.u - u).abs().max((hit.v - v).abs());
            prop_assert!(uv_error <= 1e-9, "{hit:?} vs {u} {v}");
            prop_assert!(hit.inside);
            // Every reported solution is a genuine image.
            let scale = ps.length() + cache.base_size + cache.trinorm(u, v).length() * t;
            for x in s.iter() {
                let err = (cache.ray_point(x.u, x.v, x.t) - ps).length();
                let bound = 1e-9 * (scale + x.t.abs() * cache.trinorm(x.u, x.v).length());
                prop_assert!(err <= bound, "{x:?} err {err}");
            }
        }
    }

    /// Accuracy report (run with `--ignored --nocapture`): the round trip of
    /// `random_rays_round_trip` over many draws, worst errors of t (relative to max(1, t))
    /// and of (u, v), and how many draws the conditioning filter skipped.
    #[test]
    #[ignore]
    fn accuracy_report() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut vec = |r: f64| DVec3::new(next(), next(), next()) * 2.0 * r - DVec3::splat(r);
        for threshold in [1e-3, 1e-5, 0.0] {
            let (mut worst_t, mut worst_uv, mut skipped, mut missed) = (0.0_f64, 0.0_f64, 0, 0);
            let draws = 200_000;
            for _ in 0..draws {
                let offset = vec(100.0);
                let p = [vec(2.0) + offset, vec(2.0) + offset, vec(2.0) + offset];
                let n = [vec(1.5), vec(1.5), vec(1.5)];
                let w = vec(0.5) + DVec3::splat(0.5);
                let (mut u, mut v) = (w.x, w.y);
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let t = 10.0 * w.z;
                let cache = ProjectionTriangleCache::new(p, n);
                let base =
                    cache.e1.cross(cache.e2).length() / (cache.e1.length() * cache.e2.length());
                if base <= threshold || conditioning(&cache, u, v, t) <= threshold {
                    skipped += 1;
                    continue;
                }
                let s = cache.project_point(cache.ray_point(u, v, t));
                let best = s.iter().map(|x| {
                    (
                        (x.t - t).abs() / t.max(1.0),
                        (x.u - u).abs().max((x.v - v).abs()),
                    )
                });
                match best.min_by(|a, b| (a.0 + a.1).total_cmp(&(b.0 + b.1))) {
                    Some((et, euv)) => {
                        worst_t = worst_t.max(et);
                        worst_uv = worst_uv.max(euv);
                    }
                    None => missed += 1,
                }
            }
            println!(
                "threshold {threshold:e}: {draws} draws, {skipped} skipped, {missed} missed: \
             worst t error {worst_t:.3e}, worst (u, v) error {worst_uv:.3e}"
            );
        }
        // Rough throughput (optimised test profile; not a benchmark).
        let (p, n) = sample();
        let cache = ProjectionTriangleCache::new(p, n);
        let points: Vec<DVec3> = (0..1000).map(|_| vec(3.0)).collect();
        let start = std::time::Instant::now();
        let mut count = 0;
        for _ in 0..1000 {
            for &ps in &points {
                count += std::hint::black_box(cache.project_point(ps)).len();
            }
        }
        let elapsed = start.elapsed().as_secs_f64();
        println!(
            "project_point: {:.1} ns per call ({count} solutions)",
            elapsed * 1e9 / 1e6
        );
    }
}
