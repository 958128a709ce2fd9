//! Ray / bilinear-patch intersection in f64 (Ramsey, Potter and Hansen 2004).
//!
//! A bilinear patch through four corners is `p(u, v) = uv a + u b + v c + d` for `(u, v)` in
//! `[0, 1]^2`, with `a = p11 - p10 - p01 + p00`, `b = p10 - p00`, `c = p01 - p00`, `d = p00`.
//! Setting it equal to the ray `r + t q` and eliminating `t` with the ray component `k` of
//! largest magnitude (never a zero or tiny divisor, whatever the direction) gives two bilinear
//! equations `uv A_i + u B_i + v C_i + D_i = 0`, one for each other axis `i`, and from them a
//! quadratic in `v`:
//!
//! ```text
//! v^2 (A2 C1 - A1 C2) + v (A2 D1 - A1 D2 + B2 C1 - B1 C2) + (B2 D1 - B1 D2) = 0.
//! ```
//!
//! For each root `v` in `[0, 1]`, `u` comes from whichever of the two expressions
//! `-(v C2 + D2) / (v A2 + B2)` and `(v (C1 - C2) + D1 - D2) / (v (A2 - A1) + B2 - B1)` has the
//! larger denominator (either can vanish at a valid hit; both vanish together only on a ruling,
//! below), and `t = (p_k(u, v) - r_k) / q_k` from the point on the patch.
//!
//! The quadratic is solved by [`quadratic_roots`] with the cancellation-free formula, which
//! also takes the linear case (a parallelogram, or any ray for which the `v^2` term vanishes:
//! one root) and a tiny leading term (its large root falls outside `[0, 1]`). Not
//! [`solve_quadratic`](super::solve_quadratic): its degree-drop rule discards a root more than
//! `1/EPSILON` times larger than the other, but here a root at (nearly) 0 beside one at 0.6 is
//! an ordinary ray crossing the patch twice.

use glam::{DVec2, DVec3};

use super::Ray;

/// A bilinear patch given by its four corners: `p00` at `(u, v) = (0, 0)`, `p10` at `(1, 0)`,
/// `p01` at `(0, 1)`, `p11` at `(1, 1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BilinearPatch {
    /// The corner at (u, v) = (0, 0).
    pub p00: DVec3,
    /// The corner at (u, v) = (1, 0).
    pub p10: DVec3,
    /// The corner at (u, v) = (0, 1).
    pub p01: DVec3,
    /// The corner at (u, v) = (1, 1).
    pub p11: DVec3,
}

/// Where a ray meets a bilinear patch: the ray parameter and the patch parameters `(u, v)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchHit {
    /// The ray parameter of the hit (`ray.at(t)` is the point).
    pub t: f64,
    /// The patch parameters of the hit, each in [0, 1].
    pub uv: DVec2,
}

impl BilinearPatch {
    /// The point at patch parameters `(u, v)`, in the `uv a + u b + v c + d` form the
    /// intersection solves (so that `t` is computed from the same expression).
    pub fn point(&self, u: f64, v: f64) -> DVec3 {
        let [a, b, c, d] = self.coefficients();
        u * v * a + u * b + v * c + d
    }

    /// `[a, b, c, d]` of `p(u, v) = uv a + u b + v c + d`.
    fn coefficients(&self) -> [DVec3; 4] {
        [
            self.p11 - self.p10 - self.p01 + self.p00,
            self.p10 - self.p00,
            self.p01 - self.p00,
            self.p00,
        ]
    }

    /// The nearest point of the patch on `ray` with `t` in `[ray.t_min, ray.t_max]`, from
    /// either side.
    ///
    /// Degenerate cases (each has a test):
    /// * zero or non-finite direction, non-finite origin or corners: `None`;
    /// * a planar patch (`a` in the plane of `b` and `c`, a parallelogram when `a = 0`): the
    ///   quadratic is linear or has its roots where the plane is crossed; a ray parallel to the
    ///   plane has no root; a ray lying in the plane of a planar patch makes both the `v` and
    ///   the `u` equations vanish identically and is `None` (as for a triangle seen edge-on);
    /// * a patch with two coinciding corners (a triangle) or collapsed edges: `u` is taken from
    ///   the larger denominator, so the collapsed corner is hit like any other point; a patch
    ///   collapsed to a segment or a point has no area and is never hit (`None`);
    /// * a ray along a ruling of the patch (a line `v = const` or `u = const`, the edges among
    ///   them): the hits form a segment; the nearest point of it in the interval is returned
    ///   (the ray origin's parameter `t_min` when the origin lies on the segment). Along
    ///   `v = const` both `u` denominators vanish at that root; along `u = const` the `v`
    ///   equation vanishes identically and the `u` equation (the same elimination with `u` and
    ///   `v` swapped) gives the line. These cases are recognised on exact zeros only;
    /// * a twisted patch crossed twice: the smaller `t` in the interval;
    /// * a tangent ray (double root): one hit.
    ///
    /// Hits on the patch boundary (`u` or `v` exactly 0 or 1) count.
    pub fn intersect(&self, ray: &Ray) -> Option<PatchHit> {
        let (r, q) = (ray.origin, ray.direction);
        let corners_finite = [self.p00, self.p10, self.p01, self.p11]
            .iter()
            .all(|p| p.is_finite());
        if !(corners_finite && r.is_finite() && q.is_finite()) || q == DVec3::ZERO {
            return None;
        }
        let [a, b, c, d] = self.coefficients();
        let k = q.abs().max_position();
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let dr = d - r;
        // Ray axis `i` against axis `k`: (p_i - r_i) q_k - (p_k - r_k) q_i = 0.
        let row = |i: usize| {
            let cross = |x: DVec3| x[i] * q[k] - x[k] * q[i];
            [cross(a), cross(b), cross(c), cross(dr)]
        };
        let [a1, b1, c1, d1] = row(i);
        let [a2, b2, c2, d2] = row(j);
        let ctx = Solver {
            patch: self,
            ray,
            k,
        };

        let Some(roots_v) = quadratic_roots(
            a2 * c1 - a1 * c2,
            a2 * d1 - a1 * d2 + b2 * c1 - b1 * c2,
            b2 * d1 - b1 * d2,
        ) else {
            // Every v solves: the ray runs along a line u = const (or lies in a planar patch).
            let roots_u = quadratic_roots(
                a2 * b1 - a1 * b2,
                a2 * d1 - a1 * d2 + c2 * b1 - c1 * b2,
                c2 * d1 - c1 * d2,
            )?;
            return roots_u
                .into_iter()
                .flatten()
                .filter(|u| (0.0..=1.0).contains(u))
                .filter_map(|u| ctx.segment(DVec2::new(u, 0.0), DVec2::new(u, 1.0)))
                .min_by(|x, y| x.t.total_cmp(&y.t));
        };
        roots_v
            .into_iter()
            .flatten()
            .filter(|v| (0.0..=1.0).contains(v))
            .filter_map(|v| {
                let den_a = v * a2 + b2;
                let den_b = v * (a2 - a1) + b2 - b1;
                if den_a == 0.0 && den_b == 0.0 {
                    // Both u coefficients vanish: the ray runs along the line v = const.
                    return ctx.segment(DVec2::new(0.0, v), DVec2::new(1.0, v));
                }
                let u = if den_b.abs() > den_a.abs() {
                    (v * (c1 - c2) + d1 - d2) / den_b
                } else {
                    -(v * c2 + d2) / den_a
                };
                ctx.at(u, v)
            })
            .min_by(|x, y| x.t.total_cmp(&y.t))
    }
}

/// The real roots of `a x^2 + b x + c` (at most two; `None` in a slot for a missing root), or
/// `None` when all coefficients are zero (every `x` is a root).
///
/// `a = 0` is the linear case (no root when `b = 0` too). Otherwise the discriminant is
/// computed with a fused multiply-add; a negative one within rounding of zero (relative to
/// `b^2 + |4ac|`) is a tangency, one double root; the roots are `q / a` and `c / q` with
/// `q = -(b + sign(b) sqrt(disc)) / 2`, free of cancellation whatever the ratio of the roots.
fn quadratic_roots(a: f64, b: f64, c: f64) -> Option<[Option<f64>; 2]> {
    if a == 0.0 {
        if b == 0.0 {
            return (c != 0.0).then_some([None, None]);
        }
        return Some([Some(-c / b), None]);
    }
    let disc = b.mul_add(b, -4.0 * a * c);
    let scale = b * b + (4.0 * a * c).abs();
    if disc < -4.0 * f64::EPSILON * scale {
        return Some([None, None]);
    }
    let q = -0.5 * (b + b.signum() * disc.max(0.0).sqrt());
    if q == 0.0 {
        // b = 0 and a double root at 0 (c = 0 too).
        return Some([Some(0.0), None]);
    }
    Some([Some(q / a), Some(c / q)])
}

/// What computing `t` from a patch point needs: the patch, the ray and its largest axis.
struct Solver<'a> {
    patch: &'a BilinearPatch,
    ray: &'a Ray,
    k: usize,
}

impl Solver<'_> {
    /// The ray parameter of the patch point `(u, v)` along the largest ray axis.
    fn t(&self, uv: DVec2) -> f64 {
        let p = self.patch.point(uv.x, uv.y);
        (p[self.k] - self.ray.origin[self.k]) / self.ray.direction[self.k]
    }

    /// The hit at `(u, v)`, if both are in `[0, 1]` and `t` is in the ray's interval.
    fn at(&self, u: f64, v: f64) -> Option<PatchHit> {
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let uv = DVec2::new(u, v);
        let t = self.t(uv);
        (t >= self.ray.t_min && t <= self.ray.t_max).then_some(PatchHit { t, uv })
    }

    /// The nearest point in the ray's interval of the patch segment from `uv0` to `uv1`, which
    /// lies on the ray's line.
    fn segment(&self, uv0: DVec2, uv1: DVec2) -> Option<PatchHit> {
        let (t0, t1) = (self.t(uv0), self.t(uv1));
        let t = t0.min(t1).max(self.ray.t_min);
        if t > t0.max(t1) || t > self.ray.t_max {
            return None;
        }
        let s = if t1 == t0 { 0.0 } else { (t - t0) / (t1 - t0) };
        Some(PatchHit {
            t,
            uv: uv0.lerp(uv1, s.clamp(0.0, 1.0)),
        })
    }
}

#[cfg(test)]
mod tests;
