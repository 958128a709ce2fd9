//! Exact (f64) ray-triangle intersection, the reference the f32 fast paths refine against.

use glam::{DVec2, DVec3};

/// Where a ray meets a triangle: the ray parameter and the barycentric weights `(u, v)` of the
/// second and third vertices (the first has `1 - u - v`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleHit {
    /// The line parameter of the hit, any sign.
    pub t: f64,
    /// The weights (u, v) of the second and third vertices.
    pub barycentric: DVec2,
}

/// Moller-Trumbore intersection of the line `origin + t * direction` with triangle
/// `(a, b, c)`, from either side, for any `t` (the caller checks its interval).
///
/// Degenerate cases, all `None`: a zero-area triangle (its determinant is zero for every
/// direction), a direction parallel to the triangle's plane (zero determinant), a zero
/// direction, and non-finite input (every comparison with NaN fails). Points on an edge count
/// as inside.
pub fn intersect_triangle(
    origin: DVec3,
    direction: DVec3,
    [a, b, c]: [DVec3; 3],
) -> Option<TriangleHit> {
    let e1 = b - a;
    let e2 = c - a;
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = origin - a;
    let u = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = direction.dot(q) * inv_det;
    if !(0.0..=1.0 - u).contains(&v) {
        return None;
    }
    let t = e2.dot(q) * inv_det;
    t.is_finite().then_some(TriangleHit {
        t,
        barycentric: DVec2::new(u, v),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRI: [DVec3; 3] = [DVec3::ZERO, DVec3::X, DVec3::Y];

    #[test]
    fn hits_from_both_sides_with_unnormalised_direction() {
        let o = DVec3::new(0.25, 0.25, 2.0);
        let h = intersect_triangle(o, DVec3::new(0.0, 0.0, -4.0), TRI).unwrap();
        assert!((h.t - 0.5).abs() < 1e-15);
        assert!((h.barycentric - DVec2::new(0.25, 0.25)).length() < 1e-15);
        let h = intersect_triangle(-o, DVec3::new(0.5, 0.5, 4.0), TRI).unwrap();
        assert!((h.t - 0.5).abs() < 1e-15);
    }

    #[test]
    fn misses_outside_and_behind_gives_negative_t() {
        let d = DVec3::NEG_Z;
        assert!(intersect_triangle(DVec3::new(0.6, 0.6, 1.0), d, TRI).is_none());
        assert!(intersect_triangle(DVec3::new(-0.1, 0.2, 1.0), d, TRI).is_none());
        let h = intersect_triangle(DVec3::new(0.1, 0.1, -1.0), d, TRI).unwrap();
        assert!(h.t < 0.0);
    }

    #[test]
    fn degenerate_cases_never_hit() {
        let o = DVec3::new(0.25, 0.25, 1.0);
        // Parallel to the plane, in it and above it.
        assert!(intersect_triangle(DVec3::new(-1.0, 0.2, 0.0), DVec3::X, TRI).is_none());
        assert!(intersect_triangle(o, DVec3::X, TRI).is_none());
        // Zero direction, zero-area triangles, NaN.
        assert!(intersect_triangle(o, DVec3::ZERO, TRI).is_none());
        let line = [DVec3::ZERO, DVec3::ONE, DVec3::splat(2.0)];
        assert!(intersect_triangle(DVec3::new(1.0, 1.0, 5.0), DVec3::NEG_Z, line).is_none());
        let point = [DVec3::ONE; 3];
        assert!(intersect_triangle(DVec3::new(1.0, 1.0, 5.0), DVec3::NEG_Z, point).is_none());
        assert!(intersect_triangle(DVec3::NAN, DVec3::NEG_Z, TRI).is_none());
    }
}
