//! The exact hit of a pixel's projector with a scene triangle's plane, as terms that are
//! affine in pixel position, so that the rasteriser's linear interpolation carries them
//! exactly (up to rounding) and each fragment's hit costs a division and two multiply-adds
//! instead of building its projector and intersecting it.
//!
//! Inside a projection triangle the projector at barycentrics `(u, v)` is
//! `tripoint(u, v) + t trinorm(u, v)`, both affine in `(u, v)`, and `(u, v)` is affine in
//! pixel position ([`super::screen_map`]). With the scene triangle `A, B, C`, its normal
//! `n = (B - A) x (C - A)` and its dual vectors `g1 = ((C - A) x n) / |n|^2`,
//! `g2 = (n x (B - A)) / |n|^2` (so that a point `P` of the plane has barycentrics
//! `g1 . (P - A)` of `B` and `g2 . (P - A)` of `C`):
//!
//! ```text
//! t  = N / D,           N = n . (A - tripoint),   D = n . trinorm
//! b1 = a1 + t c1,       a1 = g1 . (tripoint - A), c1 = g1 . trinorm
//! b2 = a2 + t c2,       a2 = g2 . (tripoint - A), c2 = g2 . trinorm
//! ```
//!
//! `N, D, a1, c1, a2, c2` are affine in `(u, v)`: their values at a polygon's vertices,
//! interpolated linearly over the polygon, are their values at every pixel. The hit is the
//! one `Resolver::hit`'s Moller-Trumbore gives, rounded differently.
//!
//! Degenerate cases: a scene triangle of zero area has no plane ([`HitTerms::new`] gives
//! `None`); a projector parallel to the plane has `D = 0` and a non-finite `t`, and
//! [`Terms::hit`] gives `None` for it as for any non-finite value.

use glam::DVec3;

use crate::projection::ProjectionTriangleCache;

/// How many terms a vertex carries (the rasteriser's attribute count).
pub const TERMS: usize = 6;

/// The terms at one point, in the order `[a1, a2, c1, c2, N, D]`.
pub type Terms = [f64; TERMS];

/// Where the pieces of the hit are, as a fragment's attributes.
const A1: usize = 0;
const A2: usize = 1;
const C1: usize = 2;
const C2: usize = 3;
const NUMERATOR: usize = 4;
const DENOMINATOR: usize = 5;

/// One scene triangle's plane, ready to give the terms at any projector.
#[derive(Debug, Clone, Copy)]
pub struct HitTerms {
    corner: DVec3,
    normal: DVec3,
    dual: [DVec3; 2],
}

impl HitTerms {
    /// The terms of triangle `[a, b, c]`; `None` when it has no plane (zero area, or
    /// non-finite corners).
    pub fn new([a, b, c]: [DVec3; 3]) -> Option<HitTerms> {
        let (e1, e2) = (b - a, c - a);
        let normal = e1.cross(e2);
        let area2 = normal.length_squared();
        let dual = [e2.cross(normal) / area2, normal.cross(e1) / area2];
        (area2 > 0.0 && dual.iter().all(|g| g.is_finite())).then_some(HitTerms {
            corner: a,
            normal,
            dual,
        })
    }

    /// The terms at barycentrics `(u, v)` of the projection triangle of `cache`.
    pub fn at(&self, cache: &ProjectionTriangleCache, u: f64, v: f64) -> Terms {
        let offset = cache.tripoint(u, v) - self.corner;
        let direction = cache.trinorm(u, v);
        let mut terms = [0.0; TERMS];
        terms[A1] = self.dual[0].dot(offset);
        terms[A2] = self.dual[1].dot(offset);
        terms[C1] = self.dual[0].dot(direction);
        terms[C2] = self.dual[1].dot(direction);
        terms[NUMERATOR] = -self.normal.dot(offset);
        terms[DENOMINATOR] = self.normal.dot(direction);
        terms
    }
}

/// The hit the terms describe: `(t, b1, b2)`, the ray parameter and the barycentrics of
/// the triangle's second and third corners (unbounded: outside the triangle too); `None`
/// where the projector is parallel to the plane or a value is not finite.
#[inline]
pub fn hit(terms: &Terms) -> Option<(f64, f64, f64)> {
    let t = terms[NUMERATOR] / terms[DENOMINATOR];
    let b1 = terms[A1] + t * terms[C1];
    let b2 = terms[A2] + t * terms[C2];
    (t.is_finite() && b1.is_finite() && b2.is_finite()).then_some((t, b1, b2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::ProjectionTriangleCache;

    fn cache() -> ProjectionTriangleCache {
        ProjectionTriangleCache::new(
            [DVec3::ZERO, DVec3::X, DVec3::Y],
            [
                DVec3::new(-0.2, -0.1, 1.0),
                DVec3::new(0.3, 0.0, 1.2),
                DVec3::new(0.0, 0.25, 0.9),
            ],
        )
    }

    const TRIANGLE: [DVec3; 3] = [
        DVec3::new(-1.0, -1.0, 3.0),
        DVec3::new(2.0, -0.5, 4.0),
        DVec3::new(0.0, 2.0, 2.5),
    ];

    #[test]
    fn terms_give_the_exact_hit() {
        let cache = cache();
        let terms = HitTerms::new(TRIANGLE).unwrap();
        for (u, v) in [(0.2, 0.3), (0.0, 0.0), (0.9, 0.05), (-0.3, 1.2)] {
            let (t, b1, b2) = hit(&terms.at(&cache, u, v)).unwrap();
            let on_ray = cache.ray_point(u, v, t);
            let [a, b, c] = TRIANGLE;
            let on_plane = a + b1 * (b - a) + b2 * (c - a);
            assert!((on_ray - on_plane).length() < 1e-12, "{u} {v}");
        }
    }

    #[test]
    fn interpolated_terms_are_the_terms_of_the_midpoint() {
        // Affine in (u, v): the mean of the terms at two points is the terms at their middle.
        let cache = cache();
        let terms = HitTerms::new(TRIANGLE).unwrap();
        let (p, q) = (terms.at(&cache, 0.1, 0.7), terms.at(&cache, 0.6, 0.1));
        let middle = terms.at(&cache, 0.35, 0.4);
        for i in 0..TERMS {
            assert!((0.5 * (p[i] + q[i]) - middle[i]).abs() < 1e-12, "term {i}");
        }
    }

    #[test]
    fn zero_area_triangle_has_no_terms() {
        let line = [DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)];
        assert!(HitTerms::new(line).is_none());
        assert!(HitTerms::new([DVec3::ZERO; 3]).is_none());
        assert!(HitTerms::new([DVec3::ZERO, DVec3::X, DVec3::NAN]).is_none());
    }

    #[test]
    fn projector_parallel_to_the_plane_has_no_hit() {
        // The plane x = 5 and the projector at (u, v) = (0, 1), direction (0, 0.25, 0.9).
        let plane = [
            DVec3::new(5.0, 0.0, 0.0),
            DVec3::new(5.0, 1.0, 0.0),
            DVec3::new(5.0, 0.0, 1.0),
        ];
        let terms = HitTerms::new(plane).unwrap().at(&cache(), 0.0, 1.0);
        assert_eq!(terms[DENOMINATOR], 0.0);
        assert!(hit(&terms).is_none());
    }
}
