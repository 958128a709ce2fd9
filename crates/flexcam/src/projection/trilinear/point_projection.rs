//! Analytic point projection for one trilinear projection triangle (Vallance 2005, chapter 3, with
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
pub(super) mod tests;
