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
//! With a projective screen map (`Trilinear::with_screen_weights`), `(u, v)` is not affine in
//! pixel position, but the homogeneous weight `W` is, and so is every term times `W`
//! ([`crate::projection::ProjectiveMap`]). The terms are then carried multiplied by `W`, with
//! `W` itself as a seventh term: `t = (W N) / (W D)` is unchanged and
//! `b1 = (W a1 + t W c1) / W`. For the affine map `W` is exactly 1 at every vertex, hence
//! at every pixel (the interpolation of a constant is exact), and the division by it changes
//! nothing.
//!
//! Degenerate cases: a scene triangle of zero area has no plane ([`HitTerms::new`] gives
//! `None`); a projector parallel to the plane has `D = 0` and a non-finite `t`, and
//! [`Terms::hit`] gives `None` for it as for any non-finite value.

use glam::DVec3;

use super::screen_map::ScreenMap;

/// How many terms a vertex carries (the rasteriser's attribute count).
pub const TERMS: usize = 7;

/// The terms at one point, in the order `[a1, a2, c1, c2, N, D, W]` (module doc).
pub type Terms = [f64; TERMS];

/// Where the pieces of the hit are, as a fragment's attributes.
const A1: usize = 0;
const A2: usize = 1;
const C1: usize = 2;
const C2: usize = 3;
const NUMERATOR: usize = 4;
const DENOMINATOR: usize = 5;
const WEIGHT: usize = 6;

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

    /// The terms at barycentrics `(u, v)` of the projection triangle of `map`, multiplied
    /// by its homogeneous weight there (module doc; 1 for the affine map).
    pub fn at(&self, map: &ScreenMap, u: f64, v: f64) -> Terms {
        let cache = map.cache();
        let offset = cache.tripoint(u, v) - self.corner;
        let direction = cache.trinorm(u, v);
        let mut terms = [0.0; TERMS];
        terms[A1] = self.dual[0].dot(offset);
        terms[A2] = self.dual[1].dot(offset);
        terms[C1] = self.dual[0].dot(direction);
        terms[C2] = self.dual[1].dot(direction);
        terms[NUMERATOR] = -self.normal.dot(offset);
        terms[DENOMINATOR] = self.normal.dot(direction);
        terms[WEIGHT] = 1.0;
        if let Some(weight) = map.homogeneous_weight(u, v) {
            terms.iter_mut().for_each(|term| *term *= weight);
        }
        terms
    }
}

/// The hit the terms describe: `(t, b1, b2)`, the ray parameter and the barycentrics of
/// the triangle's second and third corners (unbounded: outside the triangle too); `None`
/// where the projector is parallel to the plane or a value is not finite (also a zero
/// weight, which no pixel of a valid projective map has).
/// (The stage itself runs [`solve`] and tests in its own order; the tests check against this.)
#[cfg(test)]
pub fn hit(terms: &Terms) -> Option<(f64, f64, f64)> {
    finite(solve(terms))
}

/// `hit` before its test for finite values: `(t, b1, b2)`, any of them possibly
/// infinite or NaN.
#[inline]
pub fn solve(terms: &Terms) -> (f64, f64, f64) {
    let (t, b1, b2) = weighted(terms);
    (t, b1 / terms[WEIGHT], b2 / terms[WEIGHT])
}

/// [`solve`] for terms whose weight is exactly 1 (every pixel of the affine map, the
/// default): the same bits, without dividing by the weight, since IEEE 754 division by 1
/// returns its operand unchanged (infinities and NaN included). A fragment's hit then waits
/// on one division instead of two in a row, the span loop's longest dependency chain. Use
/// it only where [`unit_weight_along`] holds; for another weight it is wrong.
#[inline]
pub fn solve_unit_weight(terms: &Terms) -> (f64, f64, f64) {
    debug_assert_eq!(terms[WEIGHT], 1.0);
    weighted(terms)
}

/// Whether every terms stepped from `start` by `step` (each the last plus `step`, as a span
/// walks its pixels) have a weight of exactly 1, so that [`solve_unit_weight`] solves
/// them: a start of 1 and a step of zero (`1 + 0` is exactly 1). A non-finite step is not
/// zero, so a one-pixel span's huge step takes [`solve`].
pub fn unit_weight_along(start: &Terms, step: &Terms) -> bool {
    start[WEIGHT] == 1.0 && step[WEIGHT] == 0.0
}

/// The ray parameter and the barycentrics times the weight.
#[inline(always)]
fn weighted(terms: &Terms) -> (f64, f64, f64) {
    let t = terms[NUMERATOR] / terms[DENOMINATOR];
    (t, terms[A1] + t * terms[C1], terms[A2] + t * terms[C2])
}

/// `Some(hit)` where all three of its values are finite.
#[inline]
pub fn finite((t, b1, b2): (f64, f64, f64)) -> Option<(f64, f64, f64)> {
    (t.is_finite() && b1.is_finite() && b2.is_finite()).then_some((t, b1, b2))
}

#[cfg(test)]
mod tests {
    use glam::DVec2;

    use super::*;
    use crate::projection::{ProjectionTriangleCache, ProjectiveMap};

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

    /// The affine map of [`cache`]'s triangle, and the projective one of weights 1, 0.5, 2.
    fn maps() -> [ScreenMap; 2] {
        let screen = [
            DVec2::new(0.1, 0.2),
            DVec2::new(0.9, 0.3),
            DVec2::new(0.4, 0.95),
        ];
        let affine = ScreenMap::new(screen, DVec2::new(200.0, 100.0), cache());
        [
            affine,
            affine.with_projective(ProjectiveMap::new([1.0, 0.5, 2.0])),
        ]
    }

    const TRIANGLE: [DVec3; 3] = [
        DVec3::new(-1.0, -1.0, 3.0),
        DVec3::new(2.0, -0.5, 4.0),
        DVec3::new(0.0, 2.0, 2.5),
    ];

    #[test]
    fn terms_give_the_exact_hit() {
        let terms = HitTerms::new(TRIANGLE).unwrap();
        for map in maps() {
            for (u, v) in [(0.2, 0.3), (0.0, 0.0), (0.9, 0.05), (0.1, 0.85)] {
                let (t, b1, b2) = hit(&terms.at(&map, u, v)).unwrap();
                let on_ray = map.cache().ray_point(u, v, t);
                let [a, b, c] = TRIANGLE;
                let on_plane = a + b1 * (b - a) + b2 * (c - a);
                assert!((on_ray - on_plane).length() < 1e-12, "{u} {v}");
            }
        }
    }

    #[test]
    fn affine_terms_carry_a_weight_of_exactly_one() {
        let terms = HitTerms::new(TRIANGLE).unwrap();
        assert_eq!(terms.at(&maps()[0], 0.3, 0.4)[WEIGHT], 1.0);
    }

    #[test]
    fn interpolated_terms_are_the_terms_of_the_middle_pixel() {
        // Affine in pixel position (for the projective map, the weighted terms): the mean
        // of the terms at two points is the terms at the pixel halfway between them.
        let terms = HitTerms::new(TRIANGLE).unwrap();
        for map in maps() {
            let (p, q) = (terms.at(&map, 0.1, 0.7), terms.at(&map, 0.6, 0.1));
            let middle_pixel = 0.5 * (map.pixel(0.1, 0.7) + map.pixel(0.6, 0.1));
            let uv = map.barycentrics(middle_pixel);
            let middle = terms.at(&map, uv.x, uv.y);
            for i in 0..TERMS {
                assert!((0.5 * (p[i] + q[i]) - middle[i]).abs() < 1e-12, "term {i}");
            }
        }
    }

    /// The same bits from [`solve_unit_weight`] as from [`solve`].
    fn same_hit(terms: &Terms) -> bool {
        let bits = |(t, b1, b2): (f64, f64, f64)| [t, b1, b2].map(f64::to_bits);
        bits(solve_unit_weight(terms)) == bits(solve(terms))
    }

    /// Values that stress the division: zeros of both signs, infinities, NaN, tiny and huge.
    const SPECIAL: [f64; 10] = [
        0.0,
        -0.0,
        1.0,
        -3.5,
        f64::MIN_POSITIVE,
        5e-324,
        f64::MAX,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];

    #[test]
    fn unit_weight_hit_changes_no_bit_on_special_values() {
        // Every pair of terms takes every pair of special values, the others ordinary;
        // weight 1.
        let base: Terms = [0.25, -0.5, 0.125, 2.0, 3.0, 1.5, 1.0];
        for i in 0..TERMS - 1 {
            for j in 0..TERMS - 1 {
                for x in SPECIAL {
                    for y in SPECIAL {
                        let mut terms = base;
                        (terms[i], terms[j]) = (x, y);
                        assert!(same_hit(&terms), "{terms:?}");
                    }
                }
            }
        }
    }

    proptest::proptest! {
        #[test]
        fn unit_weight_hit_changes_no_bit(
            bits in proptest::array::uniform6(proptest::num::u64::ANY),
        ) {
            // Arbitrary bit patterns (NaN and infinities included) for the six terms.
            let mut terms = [1.0; TERMS];
            for (term, b) in terms.iter_mut().zip(bits) {
                *term = f64::from_bits(b);
            }
            proptest::prop_assert!(same_hit(&terms), "{:?}", terms);
        }
    }

    #[test]
    fn unit_weight_along_a_span_needs_a_start_of_one_and_a_zero_step() {
        let with_weight = |w: f64| {
            let mut terms = [0.5; TERMS];
            terms[WEIGHT] = w;
            terms
        };
        let one = with_weight(1.0);
        assert!(unit_weight_along(&one, &with_weight(0.0)));
        assert!(unit_weight_along(&one, &with_weight(-0.0)));
        for step in [1e-300, -1e-300, f64::INFINITY, f64::NAN] {
            assert!(!unit_weight_along(&one, &with_weight(step)), "{step}");
        }
        for start in [1.0 + f64::EPSILON, 1.0 - f64::EPSILON / 2.0, -1.0, f64::NAN] {
            assert!(
                !unit_weight_along(&with_weight(start), &with_weight(0.0)),
                "{start}"
            );
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
    fn projector_parallel_to_the_plane_or_zero_weight_has_no_hit() {
        // The plane x = 5 and the projector at (u, v) = (0, 1), direction (0, 0.25, 0.9).
        let plane = [
            DVec3::new(5.0, 0.0, 0.0),
            DVec3::new(5.0, 1.0, 0.0),
            DVec3::new(5.0, 0.0, 1.0),
        ];
        let terms = HitTerms::new(plane).unwrap().at(&maps()[0], 0.0, 1.0);
        assert_eq!(terms[DENOMINATOR], 0.0);
        assert!(hit(&terms).is_none());
        let mut weightless = HitTerms::new(TRIANGLE).unwrap().at(&maps()[1], 0.2, 0.2);
        weightless[WEIGHT] = 0.0;
        assert!(hit(&weightless).is_none());
    }
}
