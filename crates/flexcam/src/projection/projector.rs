//! The projector of an image position: the curve in the scene that the position sees along.
//!
//! Straight projectors are rays; the flexible projection's volumes blended in t over several
//! control surfaces have curved ones (Brosz 2011, 7.2): polylines (piecewise-linear blending)
//! and quadratic Bezier curves (Bernstein blending of three surfaces). A renderer finds the
//! first scene surface along the projector, in the order of its parameter, and reports the
//! distance along the projector (arc length) as depth.

use glam::DVec3;

use crate::geometry::{solve_cubic, Ray};

/// A projector, from its start (the near end) to its end.
#[derive(Debug, Clone, PartialEq)]
pub enum Projector {
    /// A straight projector: the points of the ray within its interval.
    Straight(Ray),
    /// The segments between successive vertices (at least two), in order; a segment of zero
    /// length sees nothing.
    Polyline(Vec<DVec3>),
    /// The quadratic Bezier curve B(s) = (1-s)^2 P0 + 2 s (1-s) P1 + s^2 P2, s in [0, 1].
    QuadraticBezier([DVec3; 3]),
}

/// The projectors of a rectangle of sample positions, bounded by those of its four corners
/// (see [`crate::projection::Projection::projector_hull`]): a renderer tests a whole tile
/// against the scene with it instead of each of the tile's projectors.
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectorHull {
    /// The projectors of the rectangle's corners, all polylines with the same number of
    /// vertices or all quadratic Bezier curves.
    pub corners: [Projector; 4],
    /// Rounding allowance, absolute, in every coordinate: each control point (polyline
    /// vertex, Bezier control point) of the projector of any sample position in the
    /// rectangle lies within `pad` of the convex hull of the corners' corresponding control
    /// points.
    pub pad: f64,
}

/// The point of quadratic Bezier curve `p` at `s`.
pub fn quadratic_point(p: &[DVec3; 3], s: f64) -> DVec3 {
    let r = 1.0 - s;
    r * r * p[0] + 2.0 * s * r * p[1] + s * s * p[2]
}

/// The depth t in [0, 1] of the point of the quadratic Bezier curve `p` closest to `x`: an
/// end, or a root in (0, 1) of the cubic (B(t) - x) . B'(t) / 2 (its global minimum, so that
/// a point cannot be held at an end while the curve passes nearer further along).
/// Degenerate cases: a curve that does not move (all control points equal: the cubic is
/// identically zero) gives 0; equally near candidates give the smallest t.
pub fn quadratic_closest(p: &[DVec3; 3], x: DVec3) -> f64 {
    // B(t) - x = d + t b + t^2 a.
    let (d, b, a) = (p[0] - x, 2.0 * (p[1] - p[0]), p[2] - 2.0 * p[1] + p[0]);
    let roots = solve_cubic(
        2.0 * a.length_squared(),
        3.0 * a.dot(b),
        b.length_squared() + 2.0 * a.dot(d),
        b.dot(d),
    );
    let inside = roots.iter().filter(|t| *t > 0.0 && *t < 1.0);
    let distance = |t: f64| (quadratic_point(p, t) - x).length_squared();
    let mut best = (0.0, distance(0.0));
    for t in inside.chain([1.0]) {
        let d = distance(t);
        if d < best.1 {
            best = (t, d);
        }
    }
    best.0
}

/// The derivative B'(s) of quadratic Bezier curve `p`: 2 ((1-s)(P1 - P0) + s (P2 - P1)).
pub fn quadratic_tangent(p: &[DVec3; 3], s: f64) -> DVec3 {
    2.0 * ((1.0 - s) * (p[1] - p[0]) + s * (p[2] - p[1]))
}

/// Nodes and weights of 8-point Gauss-Legendre quadrature on [-1, 1] (positive half).
const GAUSS_NODES: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GAUSS_WEIGHTS: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// Equal sub-intervals each smooth piece of the arc-length integral is cut into.
const ARC_PIECES: usize = 4;

/// Largest ratio of the sum of the magnitudes of the two terms that the closed form
/// subtracts ([`arc_length_closed_form`]) to the antiderivative difference: each term carries
/// a few ulps of relative rounding, so the result keeps about 1e-12 relative accuracy up to
/// this ratio.
const CANCELLATION_LIMIT: f64 = 1e3;

/// The arc length of quadratic Bezier curve `p` from 0 to `s` (s in [0, 1]): in closed form
/// where that is accurate to about 1e-12 relative (`arc_length_closed_form`), else by
/// quadrature (`arc_length_by_quadrature`). The closed form is several times cheaper: the
/// ray caster computes this once per pixel that a quadratic projector hits, for its depth.
/// Degenerate cases: all control points equal gives 0; a straight curve at uniform speed
/// (P1 the midpoint of P0 and P2) gives 2 |P1 - P0| s.
pub fn quadratic_arc_length(p: &[DVec3; 3], s: f64) -> f64 {
    arc_length_closed_form(p, s).unwrap_or_else(|| arc_length_by_quadrature(p, s))
}

/// The arc length of `p` from 0 to `s` by the antiderivative of the speed. With
/// a = P0 - 2 P1 + P2 and b = P1 - P0, B'(x) = 2 (b + x a) and
/// |B'(x)| = 2 |a| sqrt(u^2 + k^2), where u = x + a.b / |a|^2 and
/// k^2 = |a x b|^2 / |a|^4 (Lagrange's identity, free of the cancellation of
/// |a|^2 |b|^2 - (a.b)^2); the integral of sqrt(u^2 + k^2) is G(u) / 2,
/// G(u) = u r(u) + k^2 asinh(u / k), r(u) = sqrt(u^2 + k^2), so the length is
/// |a| (G(u1) - G(u0)) = |a| (u1 r1 - u0 r0 + k^2 D), D = asinh(u1 / k) - asinh(u0 / k)
/// (both non-negative: u1 >= u0). D is one logarithm ([`asinh_difference`]) instead of two
/// asinh calls: this runs once per pixel that a quadratic projector hits, for its depth.
/// `None` where the subtraction u1 r1 - u0 r0 cancels more than [`CANCELLATION_LIMIT`]
/// allows (nearly straight curves with a large shift a.b / |a|^2, and arcs short against
/// it, including s = 0 away from the speed's minimum) or the result is not finite
/// (overflow). Degenerate cases: a = 0 (uniform speed 2 |b|) gives 2 |b| s exactly; k = 0
/// (collinear control points) has no asinh term.
fn arc_length_closed_form(p: &[DVec3; 3], s: f64) -> Option<f64> {
    let a = p[0] - 2.0 * p[1] + p[2];
    let b = p[1] - p[0];
    let a2 = a.length_squared();
    if a2 == 0.0 {
        return Some(2.0 * b.length() * s);
    }
    let k2 = a.cross(b).length_squared() / (a2 * a2);
    let (u0, u1) = (a.dot(b) / a2, a.dot(b) / a2 + s);
    let (r0, r1) = ((u0 * u0 + k2).sqrt(), (u1 * u1 + k2).sqrt());
    let tail = if k2 > 0.0 {
        k2 * asinh_difference(u0, u1, r0, r1, k2.sqrt(), s)
    } else {
        0.0
    };
    let difference = u1 * r1 - u0 * r0 + tail;
    let length = a2.sqrt() * difference;
    (length.is_finite() && u0.abs() * r0 + u1.abs() * r1 <= CANCELLATION_LIMIT * difference)
        .then_some(length)
}

/// asinh(u1 / k) - asinh(u0 / k) for u0 <= u1 = u0 + s, k > 0, given r0 and r1 with
/// ri = sqrt(ui^2 + k^2), as one `ln_1p`. With w(u) = |u| + r(u), asinh(|u| / k) = ln(w / k).
/// Ends on the same side of 0 (the cancellation-prone case: w1 / w0 near 1 for short arcs)
/// give ln(w_far / w_near) = ln_1p(s (1 + |u0 + u1| / (r0 + r1)) / w_near), because
/// |w1 - w0| = s + |r1 - r0| and r1 - r0 = s (u0 + u1) / (r0 + r1): no subtraction. Ends on
/// either side give ln((w0 / k) (w1 / k)) = ln_1p(e0 + e1 + e0 e1) with
/// e = w / k - 1 = |u| (1 + |u| / (r + k)) / k, again without subtraction. Degenerate case:
/// s = 0 gives 0.
fn asinh_difference(u0: f64, u1: f64, r0: f64, r1: f64, k: f64, s: f64) -> f64 {
    if u0 >= 0.0 || u1 <= 0.0 {
        let near = (u0.abs() + r0).min(u1.abs() + r1);
        (s * (1.0 + (u0 + u1).abs() / (r0 + r1)) / near).ln_1p()
    } else {
        let excess = |u: f64, r: f64| u.abs() * (1.0 + u.abs() / (r + k)) / k;
        let (e0, e1) = (excess(u0, r0), excess(u1, r1));
        (e0 + e1 + e0 * e1).ln_1p()
    }
}

/// The arc length of quadratic Bezier curve `p` from 0 to `s` (s in [0, 1]), by 8-point
/// Gauss-Legendre quadrature of the speed |B'| on 4 equal pieces of each side of the speed's
/// minimum. |B'|^2 is a quadratic in s, so the speed is smooth except where B' = 0, which can
/// only happen at that minimum: splitting there makes each piece smooth. Accuracy: exact to
/// rounding for collinear control points (the speed is then linear on each side, a cusp when
/// P1 lies beyond an end: the curve doubles back); about 1e-12 relative for curves whose
/// control polygon turns by up to about 90 degrees; it degrades only for nearly-cusped
/// curves (speed nearly zero inside [0, s]), where the error stays below about 1e-6 of the
/// length. Degenerate case: all control points equal gives 0.
fn arc_length_by_quadrature(p: &[DVec3; 3], s: f64) -> f64 {
    gauss_arc_length(p, s, ARC_PIECES)
}

/// [`arc_length_by_quadrature`] with `pieces` equal sub-intervals on each side of the
/// speed's minimum.
fn gauss_arc_length(p: &[DVec3; 3], s: f64, pieces: usize) -> f64 {
    let a = p[0] - 2.0 * p[1] + p[2];
    let b = p[1] - p[0];
    // B'(x) = 2 (b + x a): the speed is smallest at x = -a.b / a.a.
    let a2 = a.length_squared();
    let minimum = if a2 > 0.0 { -a.dot(b) / a2 } else { 0.0 };
    // The break points on the stack: this runs once per shaded pixel of a quadratic volume.
    let (split, plain) = ([0.0, minimum, s], [0.0, s]);
    let breaks: &[f64] = if minimum > 0.0 && minimum < s {
        &split
    } else {
        &plain
    };
    breaks
        .windows(2)
        .flat_map(|w| {
            let step = (w[1] - w[0]) / pieces as f64;
            (0..pieces).map(move |k| (w[0] + k as f64 * step, step))
        })
        .map(|(start, step)| {
            let half = 0.5 * step;
            let mid = start + half;
            let sum: f64 = GAUSS_NODES
                .iter()
                .zip(GAUSS_WEIGHTS)
                .map(|(x, w)| {
                    w * (quadratic_tangent(p, mid - half * x).length()
                        + quadratic_tangent(p, mid + half * x).length())
                })
                .sum();
            half * sum
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The length of the curve's n-chord polyline: the reference for the closed form.
    fn dense_length(p: &[DVec3; 3], n: usize) -> f64 {
        (0..n)
            .map(|k| {
                let (a, b) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
                (quadratic_point(p, b) - quadratic_point(p, a)).length()
            })
            .sum()
    }

    #[test]
    fn arc_length_of_a_straight_curve_is_exact() {
        let p = [
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 2.0),
            DVec3::new(2.0, 4.0, 4.0),
        ];
        assert!((quadratic_arc_length(&p, 1.0) - 6.0).abs() < 1e-14);
        assert!((quadratic_arc_length(&p, 0.25) - 1.5).abs() < 1e-14);
        assert_eq!(quadratic_arc_length(&p, 0.0), 0.0);
    }

    #[test]
    fn arc_length_matches_a_dense_polyline() {
        let p = [
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, 0.0, 0.5),
        ];
        let dense = dense_length(&p, 200_000);
        let exact = quadratic_arc_length(&p, 1.0);
        assert!((exact - dense).abs() < 1e-10 * exact, "{exact} {dense}");
    }

    #[test]
    fn arc_length_through_a_cusp_is_exact() {
        // P1 beyond P2 on one line: the curve goes out to x = 4/3 and comes back to x = 1.
        let p = [DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::X];
        let exact = 4.0 / 3.0 + 1.0 / 3.0;
        let got = quadratic_arc_length(&p, 1.0);
        assert!((got - exact).abs() < 1e-14, "{got} {exact}");
        // Nearly cusped: P1 slightly off the line.
        let near = [DVec3::ZERO, DVec3::new(2.0, 1e-4, 0.0), DVec3::X];
        let dense = dense_length(&near, 400_000);
        let got = quadratic_arc_length(&near, 1.0);
        assert!((got - dense).abs() < 1e-6 * dense, "{got} {dense}");
        assert_eq!(quadratic_arc_length(&[DVec3::ONE; 3], 1.0), 0.0);
    }

    #[test]
    fn nearly_straight_curves_fall_back_to_the_quadrature() {
        // P1 a millionth off the midpoint along the chord: the speed's minimum lies 2.5e5
        // curve lengths away and the antiderivative values cancel to 1 part in 2.5e5.
        let p = [DVec3::ZERO, DVec3::new(0.5 + 1e-6, 0.0, 0.0), DVec3::X];
        assert_eq!(arc_length_closed_form(&p, 1.0), None);
        assert!((quadratic_arc_length(&p, 1.0) - 1.0).abs() < 1e-14);
        // Nothing to integrate: the two values are equal.
        let bent = [
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, 0.0, 0.5),
        ];
        assert_eq!(arc_length_closed_form(&bent, 0.0), None);
        assert_eq!(quadratic_arc_length(&bent, 0.0), 0.0);
        // A bent curve takes the closed form, as does a point moving at uniform speed.
        assert!(arc_length_closed_form(&bent, 1.0).is_some());
        let uniform = [
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 2.0),
            DVec3::new(2.0, 4.0, 4.0),
        ];
        assert_eq!(arc_length_closed_form(&uniform, 0.5), Some(3.0));
        // Overflowing coordinates are not finite in closed form: the quadrature decides.
        let huge = bent.map(|q| q * 1e300);
        assert_eq!(arc_length_closed_form(&huge, 1.0), None);
    }

    #[test]
    fn a_short_arc_on_one_side_of_the_slowest_point_keeps_its_precision() {
        // a = (1, 0, 0), b = (-2e-8, 1, 0): u runs from -2e-8 to -1e-8 and k = 1, so the
        // two asinh values differ by about 1e-8 and the ratio w0 / w1 of their logarithms
        // is 1 + 1e-8: taking ln of that ratio would lose about 8 digits of the tail.
        let b = DVec3::new(-2e-8, 1.0, 0.0);
        let p = [DVec3::ZERO, b, DVec3::X + 2.0 * b];
        let s = 1e-8;
        let closed = arc_length_closed_form(&p, s).expect("no cancellation in u r here");
        let fine = gauss_arc_length(&p, s, 256);
        assert!((closed - fine).abs() <= 1e-13 * fine, "{closed} {fine}");
        // Mirrored: both ends on the positive side.
        let b = DVec3::new(1e-8, 1.0, 0.0);
        let p = [DVec3::ZERO, b, DVec3::X + 2.0 * b];
        let closed = arc_length_closed_form(&p, s).expect("no cancellation in u r here");
        let fine = gauss_arc_length(&p, s, 256);
        assert!((closed - fine).abs() <= 1e-13 * fine, "{closed} {fine}");
    }

    #[test]
    fn asinh_difference_matches_the_asinh_calls() {
        let k: f64 = 0.7;
        for (u0, s) in [
            (-3.0, 1.0),
            (-0.5, 1.0),
            (0.25, 0.5),
            (-1.0, 0.0),
            (0.0, 2.0),
        ] {
            let u1 = u0 + s;
            let (r0, r1) = ((u0 * u0 + k * k).sqrt(), (u1 * u1 + k * k).sqrt());
            let got = asinh_difference(u0, u1, r0, r1, k, s);
            let want = (u1 / k).asinh() - (u0 / k).asinh();
            assert!(
                (got - want).abs() <= 1e-15 * (1.0 + want),
                "{u0} {s}: {got} {want}"
            );
        }
    }

    fn point() -> impl proptest::strategy::Strategy<Value = DVec3> {
        use proptest::prelude::*;
        (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    proptest::proptest! {
        /// Where the closed form is taken it agrees to 1e-11 relative with the quadrature
        /// refined to 256 pieces on each side of the speed's minimum (accurate to rounding
        /// on these curves), on random curves whose speed stays above 1 % of its largest
        /// value over [0, s]; otherwise the quadrature is taken.
        #[test]
        fn the_closed_form_matches_the_quadrature(
            p in [point(), point(), point()],
            s in 0.0..1.0f64,
        ) {
            let (a, b) = (p[0] - 2.0 * p[1] + p[2], p[1] - p[0]);
            let slowest = if a.length_squared() > 0.0 {
                (-a.dot(b) / a.length_squared()).clamp(0.0, s)
            } else {
                0.0
            };
            let speed = |x: f64| quadratic_tangent(&p, x).length();
            proptest::prop_assume!(speed(slowest) > 0.01 * speed(0.0).max(speed(s)));
            let fine = gauss_arc_length(&p, s, 256);
            if let Some(closed) = arc_length_closed_form(&p, s) {
                proptest::prop_assert!(
                    (closed - fine).abs() <= 1e-11 * fine,
                    "closed form {closed}, quadrature {fine}"
                );
            }
            let quadrature = arc_length_by_quadrature(&p, s);
            proptest::prop_assert_eq!(
                quadratic_arc_length(&p, s),
                arc_length_closed_form(&p, s).unwrap_or(quadrature)
            );
        }
    }
}
