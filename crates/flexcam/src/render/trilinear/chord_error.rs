//! How far a curved edge piece strays from its chord: a bound over the whole piece from
//! three samples, for the adaptive sampling of outlines (`edge_path::refine`).

use glam::DVec2;

/// A bound on the distance, in pixels, from the chord `p[0] p[2]` of every point of the
/// rational quadratic curve `P(t) = H(t) / Q(t)` between the depths of its three samples
/// `p[0]` (start), `p[1]` (middle depth) and `p[2]` (end), given `q = [Q(t0), Q(tm),
/// Q(t1)]` (any common scale and sign): the error of drawing the piece as its chord.
///
/// With `tau` the depth's fraction of the piece, `Q` in Bernstein form has weights `w0 =
/// q0`, `w1 = 2 qm - (q0 + q2) / 2`, `w2 = q2`, and `Q > 0` on the piece exactly when
/// `w0, w2 > 0` and `D = sqrt(w0 w2) + w1 > 0` (`Q / (tau (1 - tau))` is
/// `w0 / x + 2 w1 + w2 x` with `x = tau / (1 - tau)`, least `2 D`). Then, with `h_m` and
/// `a_m` the middle sample's offsets across and along the chord (of length `L`):
///
/// * across: `h(tau) = 4 qm h_m tau (1 - tau) / Q(tau)`, largest `2 qm |h_m| / D`
///   (`>= |h_m|`, equal when `Q` is the same at both ends);
/// * along, beyond the end: `a(tau) - L = (2 tau (1 - tau) (A - w1 L) - w0 (1 - tau)^2 L) /
///   Q(tau)` with `A = 2 qm a_m - w2 L / 2`, at most `max(0, A - w1 L) / D` (as
///   `tau (1 - tau) / Q <= 1 / (2 D)`); before the start, `-a(tau) <= max(0, -A) / D`.
///
/// The distance to the segment is at most the sum of the two. At the middle the curve is at
/// `p[1]`, so the bound is never below the middle's own distance (the test at the middle
/// alone); near a depth where `Q` vanishes just outside the piece `D` is small and the bound
/// large, where the middle test alone missed the swing.
///
/// Degenerate cases: `Q` zero or changing sign on the piece (the curve through infinity:
/// the degenerate depth or the segment parallel to the plane inside it), ends of different
/// signs, and non-finite inputs certify nothing (`f64::INFINITY`); a chord of zero length
/// (a closed piece) measures both offsets along `x` and `y`.
pub(super) fn chord_error_bound(p: [DVec2; 3], q: [f64; 3]) -> f64 {
    let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
    let [w0, qm, w2] = q.map(|x| sign * x);
    let w1 = 2.0 * qm - 0.5 * (w0 + w2);
    let d = (w0 * w2).sqrt() + w1;
    if !(w0 > 0.0 && w2 > 0.0 && d > 0.0 && qm > 0.0) {
        return f64::INFINITY;
    }
    let chord = p[2] - p[0];
    let length = chord.length();
    let along = if length > 0.0 {
        chord / length
    } else {
        DVec2::X
    };
    let offset = p[1] - p[0];
    let (a_m, h_m) = (offset.dot(along), offset.perp_dot(along));
    let a = 2.0 * qm * a_m - 0.5 * w2 * length;
    let overshoot = (a - w1 * length).max(-a).max(0.0);
    let bound = (2.0 * qm * h_m.abs() + overshoot) / d;
    if bound.is_nan() {
        f64::INFINITY
    } else {
        bound
    }
}

/// Euclidean distance from `p` to the segment `a b` (to `a` when the segment is a point):
/// what [`chord_error_bound`] bounds, for the tests here and of `edge_path`.
#[cfg(test)]
pub(super) fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let length_squared = d.length_squared();
    let s = if length_squared > 0.0 {
        ((p - a).dot(d) / length_squared).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + s * d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The rational quadratic with control points `c` and Bernstein weights `w` at `tau`,
    /// and its denominator there.
    fn curve(c: [DVec2; 3], w: [f64; 3], tau: f64) -> (DVec2, f64) {
        let b = [
            (1.0 - tau) * (1.0 - tau),
            2.0 * tau * (1.0 - tau),
            tau * tau,
        ];
        let q = b[0] * w[0] + b[1] * w[1] + b[2] * w[2];
        let h = c[0] * (b[0] * w[0]) + c[1] * (b[1] * w[1]) + c[2] * (b[2] * w[2]);
        (h / q, q)
    }

    /// The bound of the curve's three samples, and its largest distance from the chord
    /// over `samples` depths.
    fn bound_and_largest(c: [DVec2; 3], w: [f64; 3], samples: u32) -> (f64, f64) {
        let [s0, sm, s1] = [0.0, 0.5, 1.0].map(|tau| curve(c, w, tau));
        let bound = chord_error_bound([s0.0, sm.0, s1.0], [s0.1, sm.1, s1.1]);
        let largest = (0..=samples)
            .map(|k| f64::from(k) / f64::from(samples))
            .map(|tau| distance_to_segment(curve(c, w, tau).0, s0.0, s1.0))
            .fold(0.0, f64::max);
        (bound, largest)
    }

    proptest! {
        /// On random rational quadratics with a denominator positive on the piece, the bound
        /// holds at densely sampled depths and is never below the middle sample's distance.
        #[test]
        fn the_bound_holds_over_the_piece(
            c in prop::array::uniform3((-50.0..50.0f64, -50.0..50.0f64)),
            w0 in 1e-3..10.0f64,
            w2 in 1e-3..10.0f64,
            excess in 1e-3..10.0f64,
            sign in prop::bool::ANY,
        ) {
            let c = c.map(|(x, y)| DVec2::new(x, y));
            // Positive on the piece: w1 > -sqrt(w0 w2).
            let w1 = -(w0 * w2).sqrt() + excess;
            let w = if sign { [w0, w1, w2] } else { [-w0, -w1, -w2] };
            let (bound, largest) = bound_and_largest(c, w, 400);
            prop_assert!(largest <= bound * (1.0 + 1e-9) + 1e-9, "{largest} > {bound}");
            let middle = curve(c, w, 0.5).0;
            let at_middle = distance_to_segment(middle, curve(c, w, 0.0).0, curve(c, w, 1.0).0);
            prop_assert!(bound >= at_middle * (1.0 - 1e-9));
        }
    }

    /// A denominator the same at both ends (here constant: a parabola, the image under an
    /// orthographic-like triangle) gives exactly the middle's distance when the curve stays
    /// over the chord; the sign of the denominators does not matter.
    #[test]
    fn equal_denominators_give_the_middle_distance() {
        let p = [DVec2::ZERO, DVec2::new(5.0, 1.0), DVec2::new(10.0, 0.0)];
        assert_eq!(chord_error_bound(p, [1.0; 3]), 1.0);
        assert_eq!(chord_error_bound(p, [-2.0; 3]), 1.0);
    }

    /// Near a zero of the denominator just outside the piece the curve swings far out
    /// between the samples while the middle sample is within a tenth of a pixel of the
    /// chord: the bound sees the swing (the test at the middle alone did not).
    #[test]
    fn a_swing_near_a_pole_is_bounded() {
        // Q(tau) = (tau - 0.25)^2 + 1e-4 in Bernstein weights.
        let q = |tau: f64| (tau - 0.25) * (tau - 0.25) + 1e-4;
        let w = [q(0.0), 2.0 * q(0.5) - 0.5 * (q(0.0) + q(1.0)), q(1.0)];
        // The middle control point that puts the curve at (5, 0.05) at tau = 1/2.
        let (end, middle) = (DVec2::new(10.0, 0.0), DVec2::new(5.0, 0.05));
        let c1 = (middle * q(0.5) - end * (0.25 * w[2])) / (0.5 * w[1]);
        let c = [DVec2::ZERO, c1, end];
        assert!(curve(c, w, 0.5).0.distance(middle) < 1e-9);
        let (bound, largest) = bound_and_largest(c, w, 10_000);
        assert!(distance_to_segment(middle, c[0], c[2]) < 0.1, "{middle}");
        assert!(largest > 1.0, "{largest}");
        assert!(bound >= largest, "{bound} < {largest}");
    }

    /// The degenerate cases certify nothing: a denominator zero at an end, ends of
    /// different signs, a zero inside the piece (ends and middle of one sign, or not), and
    /// non-finite input.
    #[test]
    fn a_curve_through_infinity_is_not_certified() {
        let p = [DVec2::ZERO, DVec2::new(5.0, 0.1), DVec2::new(10.0, 0.0)];
        for q in [
            [0.0, 1.0, 1.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.5, -1.0],
            [1.0, -0.5, 1.0],
            // Bernstein weights 4, -0.5, 0.01: positive ends and middle, negative near
            // tau = 0.85.
            [4.0, 0.7525, 0.01],
            [f64::NAN, 1.0, 1.0],
            [1.0, f64::INFINITY, 1.0],
        ] {
            assert_eq!(chord_error_bound(p, q), f64::INFINITY, "{q:?}");
        }
        let far = [DVec2::ZERO, DVec2::new(f64::INFINITY, 0.0), DVec2::X];
        assert_eq!(chord_error_bound(far, [1.0; 3]), f64::INFINITY);
    }

    /// A piece whose ends coincide (a closed loop) is bounded by the middle's offsets from
    /// that point.
    #[test]
    fn a_closed_piece_is_bounded_by_its_middle() {
        let p = [DVec2::ZERO, DVec2::new(3.0, 4.0), DVec2::ZERO];
        let bound = chord_error_bound(p, [1.0; 3]);
        assert!((5.0..=7.0).contains(&bound), "{bound}");
        let w = [1.0, 1.0, 1.0];
        let c = [DVec2::ZERO, DVec2::new(6.0, 8.0), DVec2::ZERO];
        let largest = (0..=100)
            .map(|k| curve(c, w, f64::from(k) / 100.0).0.length())
            .fold(0.0, f64::max);
        assert!(largest <= bound, "{largest} > {bound}");
    }
}
