//! The projector of an image position: the curve in the scene that the position sees along.
//!
//! Straight projectors are rays; the flexible projection's volumes blended in t over several
//! control surfaces have curved ones (seed 003, 7.2): polylines (piecewise-linear blending)
//! and quadratic Bezier curves (Bernstein blending of three surfaces). A renderer finds the
//! first scene surface along the projector, in the order of its parameter, and reports the
//! distance along the projector (arc length) as depth.

use glam::DVec3;

use crate::geometry::Ray;

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

/// The arc length of quadratic Bezier curve `p` from 0 to `s` (s in [0, 1]), by 8-point
/// Gauss-Legendre quadrature of the speed |B'| on 4 equal pieces of each side of the speed's
/// minimum. |B'|^2 is a quadratic in s, so the speed is smooth except where B' = 0, which can
/// only happen at that minimum: splitting there makes each piece smooth. Accuracy: exact to
/// rounding for collinear control points (the speed is then linear on each side, a cusp when
/// P1 lies beyond an end: the curve doubles back); about 1e-12 relative for curves whose
/// control polygon turns by up to about 90 degrees; it degrades only for nearly-cusped
/// curves (speed nearly zero inside [0, s]), where the error stays below about 1e-6 of the
/// length. Degenerate case: all control points equal gives 0.
pub fn quadratic_arc_length(p: &[DVec3; 3], s: f64) -> f64 {
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
            let step = (w[1] - w[0]) / ARC_PIECES as f64;
            (0..ARC_PIECES).map(move |k| (w[0] + k as f64 * step, step))
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
}
