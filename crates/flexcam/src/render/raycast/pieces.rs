//! The parts of a curved projector that the ray caster searches one by one: the segments of
//! a polyline and the pieces a quadratic curve is cut into.

use glam::DVec3;

use crate::geometry::Ray;
use crate::projection::projector::{quadratic_point, quadratic_tangent};

/// Segment `k` of polyline projector `points` as a ray over `t` in `[0, 1]`, from vertex `k`
/// to vertex `k + 1` (a zero direction where the two coincide).
pub(in crate::render) fn polyline_segment(points: &[DVec3], k: usize) -> Ray {
    Ray {
        origin: points[k],
        direction: points[k + 1] - points[k],
        t_min: 0.0,
        t_max: 1.0,
    }
}

/// The length of polyline `points` before its segment `k`: the sum of the lengths of
/// segments 0 to k - 1, in order. Computed only for the segment that hits, not as the search
/// passes each segment (most projectors hit nothing).
pub(in crate::render) fn length_before(points: &[DVec3], k: usize) -> f64 {
    points[..=k]
        .windows(2)
        .fold(0.0, |sum, pair| sum + (pair[1] - pair[0]).length())
}

/// The straight ray a quadratic projector `p` continues as at its hit `s`: origin B(s),
/// direction the tangent B'(s), with the hit at ray parameter 0 (any t is accepted, so that
/// the f64 refinement may move it by rounding). Degenerate case: where B'(s) = 0 (a cusp of a
/// curve doubling back on itself) the chord P2 - P0 stands in for the tangent, and P1 - P0
/// where that is zero too (a closed curve).
pub(in crate::render) fn tangent_ray(p: &[DVec3; 3], s: f64) -> Ray {
    let direction = [quadratic_tangent(p, s), p[2] - p[0], p[1] - p[0]]
        .into_iter()
        .find(|d| *d != DVec3::ZERO)
        .unwrap_or(DVec3::X);
    Ray {
        origin: quadratic_point(p, s),
        direction,
        t_min: f64::NEG_INFINITY,
        t_max: f64::INFINITY,
    }
}

/// Pieces the curve is cut into for the BVH search: more pieces give thinner fattened chords
/// (the padding falls as 1/PIECES^2), boxes that fewer triangles overlap, and fewer triangles
/// tested beyond the first hit, but more traversals and more piece boxes in the tile culls.
/// 24 took the least CPU time on the Table 7.1 bench's smallest models (8, 12, 16, 20, 24,
/// 28, 32, 48 and 64 tried; docs/flexible.md, change 7).
pub(in crate::render) const PIECES: usize = 24;

/// The parameter interval [a, b] of piece `k` of [`PIECES`].
pub(in crate::render) fn piece_interval(k: usize) -> (f64, f64) {
    (k as f64 / PIECES as f64, (k + 1) as f64 / PIECES as f64)
}

/// The control points of the piece of curve `p` over [a, b] (blossoming: the end points and
/// the intersection of the end tangents).
pub(in crate::render) fn piece(p: &[DVec3; 3], a: f64, b: f64) -> [DVec3; 3] {
    let start = quadratic_point(p, a);
    [
        start,
        start + 0.5 * (b - a) * quadratic_tangent(p, a),
        quadratic_point(p, b),
    ]
}
