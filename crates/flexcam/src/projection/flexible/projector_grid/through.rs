//! The thesis's projector construction (Brosz 2011, 5.2.1): a node projector given by its start
//! p_n, the scene point p_i it must pass through, an optional tangent v *at p_i* (only its
//! direction counts) and the distance D of its end from p_n, converted to the grid's own node
//! form (start, end, unit tangent at the start) so that rendering, ray casting, fitting and the
//! scene writer apply unchanged.
//!
//! # The construction
//!
//! Without a tangent (or with one along p_i - p_n) the projector is the segment from p_n
//! towards p_i of length D, as in the thesis. With a tangent, a quadratic Bezier S, C, E with
//! S = p_n has to pass through p_i at some parameter t* with B'(t*) along +v and |E - S| = D.
//! A general quadratic has one degree of freedom left after these conditions (seven unknowns:
//! C, E and t*; six equations). The free parameter is fixed by the grid's node form, which
//! puts the control point at half the length along the start tangent, |C - S| = D / 2: the
//! result is then an ordinary node (the fit, the writer of `flexcam fit` and the ray caster
//! take it as it is), and a straight node is the special case C = (S + E) / 2.
//!
//! The curve lies in the plane through S spanned by p_i - S and v. With d = |p_i - S|, unit
//! x along p_i - S, v = (cos phi, sin phi) in that plane, s = 1 / t* and B'(t*) = 2 k' v,
//! position and tangent at t* give (in units of d, k = k' / d, lambda = D / d)
//!
//!   C = (s - k cos phi, -k sin phi),   E = ((2 - s) s + 2 k (s - 1) cos phi, 2 k (s - 1) sin phi)
//!
//! and the two remaining equations are |C| = lambda / 2 and |E| = lambda. For phi = 0 the
//! straight projector solves them (s = lambda, k = lambda / 2; Jacobian determinant
//! 2 lambda^3, never zero). The solution taken is the one reached from it by continuation in
//! phi (Newton in (s, k) at each step): the straight projector bent continuously until its
//! tangent at p_i is v. The system has other roots (curves that loop out and reach p_i late);
//! they are not taken.
//!
//! # Degenerate cases (each an error naming the node, or a straight node)
//!
//! - no tangent, a zero tangent or one along p_i - S (sine of the angle at most
//!   [`ALONG_CHORD`]): the straight node, bit for bit the one `set_projector` gives from
//!   `start + D * (p_i - S) / |p_i - S|`;
//! - p_i at the start, or D not above d (the end must lie beyond the point, the thesis's
//!   "longer than the scene"): error;
//! - a tangent pointing back along the chord, towards the start: error (the curve would fold);
//! - a tangent too far off the chord for a quadratic of this length: the continuation meets a
//!   fold of the branch (Newton fails however small the step) or leaves t* in (0, 1], k > 0:
//!   error naming the largest angle the branch reached. The limit depends on lambda = D / d
//!   (measured with a Python replica of this continuation, 89-degree target): 30 degrees at
//!   lambda = 1.01, 35 at 1.5, 40 at 2, 50 at 3, 60 at 4, 83 at 6, past 89 from 6.5 to 7.5,
//!   then 45 at 8, 11 at 10 and 2.2 at 30. A long projector through a near point hardly
//!   bends: with its control point D / 2 out along its start tangent, the curve near its
//!   start is nearly the straight line along that tangent, so it reaches p_i almost along
//!   the chord. (A node form with a free control-point distance would lift this; the grid's
//!   nodes, the fit and the writer do not have one.)

use glam::DVec3;

use super::ALONG_CHORD;
use crate::error::{Error, Result};

/// A node projector given the thesis's way: through a scene point, optionally with the
/// projector's direction there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Through {
    /// The scene point p_i the projector passes through.
    pub point: DVec3,
    /// The direction of the projector at `point` (only the direction counts; zero: none).
    pub tangent: Option<DVec3>,
    /// The distance D of the projector's end from its start; must exceed |point - start|.
    /// `None`: the node's current length, lengthened to 1.01 times the point's distance when
    /// that is farther (as [`super::ProjectorGrid::aim`] does).
    pub length: Option<f64>,
}

/// The node's end and unit start tangent (`None`: straight) for a projector from `start`
/// given by `through` (see the module docs); `current` is the node's length before, the
/// default length. Errors name node (`c`, `r`).
pub(super) fn node_through(
    (c, r): (usize, usize),
    start: DVec3,
    through: &Through,
    current: f64,
) -> Result<(DVec3, Option<DVec3>)> {
    let fail = |what: String| Error::new(format!("projector grid node ({c}, {r}): {what}"));
    let Through {
        point,
        tangent,
        length,
    } = *through;
    let length = length.unwrap_or(current.max(1.01 * (point - start).length()));
    let tangent = tangent.unwrap_or(DVec3::ZERO);
    if !start.is_finite() || !point.is_finite() || !tangent.is_finite() || !length.is_finite() {
        return Err(fail("a non-finite start, point, tangent or length".into()));
    }
    let chord = point - start;
    let d = chord.length();
    if d == 0.0 {
        return Err(fail(format!("the point {point} is its start")));
    }
    if length <= d {
        return Err(fail(format!(
            "the length {length} does not reach past the point {point}, which is {d} from the \
             start; the end must lie beyond it"
        )));
    }
    let x = chord.normalize();
    let straight = || Ok((start + length * x, None));
    let Some(v) = tangent.try_normalize() else {
        return straight();
    };
    let across = v - v.dot(x) * x;
    let sin = across.length();
    if sin <= ALONG_CHORD {
        if v.dot(x) > 0.0 {
            return straight();
        }
        return Err(fail(format!(
            "the tangent {tangent} at the point points back towards the start"
        )));
    }
    let y = across / sin;
    let phi = sin.atan2(v.dot(x));
    let (s, k) = continue_to(phi, length / d).map_err(|reached| {
        fail(format!(
            "no quadratic projector of length {length} passes through {point} with the \
             tangent {tangent} there: it is {:.1} degrees off the line from the start, and \
             this length bends at most about {:.1} degrees",
            phi.to_degrees(),
            reached.to_degrees()
        ))
    })?;
    let (control, end) = control_end(s, k, phi);
    let to_3d = |p: [f64; 2]| p[0] * x + p[1] * y;
    let start_tangent = to_3d(control).normalize();
    let end = start + length * to_3d(end).normalize();
    Ok((end, Some(start_tangent)))
}

/// C and E in the plane's units (module docs) for s = 1 / t*, k and the angle `phi`.
fn control_end(s: f64, k: f64, phi: f64) -> ([f64; 2], [f64; 2]) {
    let (sin, cos) = phi.sin_cos();
    (
        [s - k * cos, -k * sin],
        [
            (2.0 - s) * s + 2.0 * k * (s - 1.0) * cos,
            2.0 * k * (s - 1.0) * sin,
        ],
    )
}

/// Steps in phi per radian of bend: 1 degree each, the Newton start then lies well inside
/// the basin of the next solution.
const STEPS_PER_RADIAN: f64 = 180.0 / std::f64::consts::PI;
/// Halvings of a failed step before the branch counts as ended (a fold).
const MAX_HALVINGS: u32 = 20;

/// (s, k) at angle `phi` by continuation from the straight projector at phi = 0; `Err` with
/// the largest angle reached when the branch folds or leaves t* in (0, 1], k > 0.
fn continue_to(phi: f64, lambda: f64) -> std::result::Result<(f64, f64), f64> {
    let (mut s, mut k) = (lambda, 0.5 * lambda);
    let mut at = 0.0;
    let mut step = phi / (phi * STEPS_PER_RADIAN).ceil().max(1.0);
    let mut halvings = 0;
    while at < phi {
        let next = (at + step).min(phi);
        match newton(s, k, next, lambda) {
            Some((s1, k1)) if s1 >= 1.0 && k1 > 0.0 => {
                (s, k, at) = (s1, k1, next);
            }
            _ => {
                halvings += 1;
                if halvings > MAX_HALVINGS {
                    return Err(at);
                }
                step *= 0.5;
            }
        }
    }
    Ok((s, k))
}

/// Newton's method on |C|^2 = lambda^2 / 4, |E|^2 = lambda^2 from (s, k); `None` when it does
/// not converge to rounding within the iteration limit or meets a singular Jacobian.
fn newton(mut s: f64, mut k: f64, phi: f64, lambda: f64) -> Option<(f64, f64)> {
    let (sin, cos) = phi.sin_cos();
    let scale = lambda * lambda;
    for _ in 0..50 {
        let (c, e) = control_end(s, k, phi);
        let f1 = c[0] * c[0] + c[1] * c[1] - 0.25 * scale;
        let f2 = e[0] * e[0] + e[1] * e[1] - scale;
        if f1.abs() <= 1e-14 * scale && f2.abs() <= 1e-14 * scale {
            return Some((s, k));
        }
        // Derivatives of C and E in s and k (module docs).
        let (cs, ck) = ([1.0, 0.0], [-cos, -sin]);
        let es = [2.0 - 2.0 * s + 2.0 * k * cos, 2.0 * k * sin];
        let ek = [2.0 * (s - 1.0) * cos, 2.0 * (s - 1.0) * sin];
        let dot = |a: [f64; 2], b: [f64; 2]| 2.0 * (a[0] * b[0] + a[1] * b[1]);
        let (a, b, p, q) = (dot(c, cs), dot(c, ck), dot(e, es), dot(e, ek));
        let det = a * q - b * p;
        if det.abs() <= 1e-300 || !det.is_finite() {
            return None;
        }
        s -= (q * f1 - b * f2) / det;
        k -= (a * f2 - p * f1) / det;
        if !s.is_finite() || !k.is_finite() {
            return None;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::projector::{quadratic_point, quadratic_tangent};
    use proptest::prelude::*;

    const NODE: (usize, usize) = (2, 3);

    /// The quadratic of the node the construction returns (the grid's control point rule).
    fn curve(start: DVec3, end: DVec3, tangent: Option<DVec3>) -> [DVec3; 3] {
        let control = match tangent {
            Some(t) => start + 0.5 * (end - start).length() * t,
            None => 0.5 * (start + end),
        };
        [start, control, end]
    }

    /// Checks the 5.2.1 conditions: through `point` at some t in (0, 1] with the tangent
    /// there along `v`, end at distance `length`; returns that t.
    fn check(start: DVec3, through: &Through) -> f64 {
        let (end, tangent) = node_through(NODE, start, through, 1.0).unwrap();
        let p = curve(start, end, tangent);
        let scale = through.length.unwrap();
        assert!(((end - start).length() - scale).abs() <= 1e-12 * scale);
        // The closest parameter to the point, by dense sampling then Newton on the distance.
        let mut t = (0..=2000)
            .map(|i| i as f64 / 2000.0)
            .min_by(|a, b| {
                let da = (quadratic_point(&p, *a) - through.point).length();
                let db = (quadratic_point(&p, *b) - through.point).length();
                da.total_cmp(&db)
            })
            .unwrap();
        for _ in 0..50 {
            let r = quadratic_point(&p, t) - through.point;
            let d1 = quadratic_tangent(&p, t);
            let d2 = 2.0 * (p[0] - 2.0 * p[1] + p[2]);
            t -= r.dot(d1) / (d1.dot(d1) + r.dot(d2));
        }
        let miss = (quadratic_point(&p, t) - through.point).length();
        assert!(miss <= 1e-9 * scale, "misses the point by {miss}");
        let v = through.tangent.unwrap().normalize();
        let along = quadratic_tangent(&p, t).normalize();
        assert!(
            along.cross(v).length() <= 1e-9,
            "tangent {along} not along {v}"
        );
        assert!(along.dot(v) > 0.0, "tangent {along} opposite to {v}");
        t
    }

    #[test]
    fn a_tangent_at_the_point_bends_the_projector_through_it() {
        let start = DVec3::new(0.2, -0.1, 1.0);
        let point = DVec3::new(0.5, 0.3, -2.0);
        for (tangent, length) in [
            (DVec3::new(0.3, 0.0, -1.0), 8.0),
            (DVec3::new(-0.4, 0.5, -1.0), 6.0),
            (DVec3::new(0.0, 1.0, -1.0), 8.0),
        ] {
            let through = Through {
                point,
                tangent: Some(tangent),
                length: Some(length),
            };
            let t = check(start, &through);
            assert!(t > 0.0 && t < 1.0, "t* = {t}");
        }
    }

    #[test]
    fn no_tangent_or_one_along_the_chord_gives_the_straight_node_bit_for_bit() {
        let start = DVec3::new(0.2, -0.1, 1.0);
        let point = DVec3::new(0.5, 0.3, -2.0);
        let straight = start + 7.0 * (point - start).normalize();
        for tangent in [None, Some(DVec3::ZERO), Some(3.0 * (point - start))] {
            let through = Through {
                point,
                tangent,
                length: Some(7.0),
            };
            assert_eq!(
                node_through(NODE, start, &through, 1.0).unwrap(),
                (straight, None)
            );
        }
    }

    #[test]
    fn impossible_projectors_are_errors_naming_the_node() {
        let start = DVec3::ZERO;
        let point = DVec3::new(0.0, 0.0, -2.0);
        let cases = [
            (
                point,
                Some(DVec3::new(0.0, 0.0, 1.0)),
                6.0,
                "back towards the start",
            ),
            (
                point,
                Some(DVec3::new(0.0, 1.0, -0.2)),
                6.0,
                "bends at most",
            ),
            (
                point,
                Some(DVec3::new(0.3, 0.0, -1.0)),
                2.0,
                "does not reach past",
            ),
            (start, None, 6.0, "is its start"),
            (point, None, f64::NAN, "non-finite"),
        ];
        for (point, tangent, length, expected) in cases {
            let through = Through {
                point,
                tangent,
                length: Some(length),
            };
            let message = node_through(NODE, start, &through, 1.0)
                .unwrap_err()
                .to_string();
            assert!(message.contains("node (2, 3)"), "{message}");
            assert!(message.contains(expected), "{message}");
        }
    }

    /// The largest bend reported by the error is one the construction does meet just below.
    #[test]
    fn the_reported_bend_limit_is_reachable() {
        let point = DVec3::new(0.0, 0.0, -1.0);
        let through = |deg: f64| Through {
            point,
            tangent: Some(DVec3::new(
                deg.to_radians().sin(),
                0.0,
                -deg.to_radians().cos(),
            )),
            length: Some(3.0),
        };
        let message = node_through(NODE, DVec3::ZERO, &through(80.0), 1.0)
            .unwrap_err()
            .to_string();
        let limit: f64 = message
            .split("at most about ")
            .nth(1)
            .and_then(|rest| rest.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap();
        assert!(limit > 30.0 && limit < 80.0, "{message}");
        check(DVec3::ZERO, &through(limit - 0.5));
    }

    proptest! {
        /// Random starts, points, lengths and tangents up to 25 degrees off the chord with D
        /// from 1.5 to 4 times the distance (inside the measured limits): every construction
        /// meets the 5.2.1 conditions.
        #[test]
        fn through_point_round_trip(
            start in prop::array::uniform3(-2.0..2.0f64),
            dir in prop::array::uniform3(-1.0..1.0f64),
            dist in 0.5..5.0f64,
            ratio in 1.5..4.0f64,
            bend in 0.001..0.44f64,
            roll in 0.0..std::f64::consts::TAU,
        ) {
            let start = DVec3::from(start);
            let Some(x) = DVec3::from(dir).try_normalize() else { return Ok(()) };
            let point = start + dist * x;
            let y = x.any_orthonormal_vector();
            let z = x.cross(y);
            let side = roll.cos() * y + roll.sin() * z;
            let tangent = bend.cos() * x + bend.sin() * side;
            check(start, &Through { point, tangent: Some(tangent), length: Some(ratio * dist) });
        }
    }
}
