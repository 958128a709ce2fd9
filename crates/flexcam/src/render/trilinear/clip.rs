//! Clipping of a shape's outline (Vallance 2005, 4.6 and chapter 5): to the view plane `t >= 0` and
//! to the projection triangle's domain `u >= 0`, `v >= 0`, `u + v <= 1`, by Sutherland-Hodgman
//! against one half-space at a time.
//!
//! The outlines reaching here already hold the exact crossings of their curved edges with
//! `t = 0` and with the three edge surfaces (the anchors of `edge_path`), so each clip line
//! passes through outline points: the interpolated intersection of a chord with the line is
//! then that point itself (up to rounding), and the part of the clipped boundary that runs
//! along the line is straight in `(u, v)` because it is: the plane `t = 0` maps affinely to
//! the base triangle, and the domain lines are the screen triangle's edges. Where an anchor
//! could not be computed (a degenerate depth), the chord is cut by interpolation instead.

use super::edge_path::OutlinePoint;

/// How far, in barycentrics, the domain half-planes reach past the projection triangle's
/// edges. A pixel centre exactly on a shared edge must be covered by one of the two triangles,
/// but their clipped edges are computed through different affine maps and differ by rounding,
/// so a zero margin could leave it to neither (a crack). With the margin both cover a strip
/// about `1e-9` of the triangle wide (micro-pixels), and the z-test picks one; the projectors
/// of the two triangles agree on the shared edge of a continuous mesh.
pub(super) const DOMAIN_MARGIN: f64 = 1e-9;

/// The half-spaces, in order: a point is kept where the function is `>= 0`.
const HALF_SPACES: [fn(&OutlinePoint) -> f64; 4] = [
    |p| p.t,
    |p| p.u + DOMAIN_MARGIN,
    |p| p.v + DOMAIN_MARGIN,
    |p| 1.0 + DOMAIN_MARGIN - p.u - p.v,
];

/// Clips the closed outline `points` (2 or more points; 2 is a line, its two edges the same
/// segment) to the view plane and the domain, in place; `scratch` is reused storage.
/// Consecutive equal points are merged, so the result has 0 points (clipped away), 1 (a
/// single point on a clip line, to be dropped by the caller), 2 (a line) or more.
pub fn clip_outline(points: &mut Vec<OutlinePoint>, scratch: &mut Vec<OutlinePoint>) {
    // Most outlines lie wholly inside: one pass over the points settles that (the loop
    // below would skip every half-space after testing them one by one).
    if points.iter().all(inside_every_half_space) {
        return;
    }
    for inside in HALF_SPACES {
        if points.iter().all(|p| inside(p) >= 0.0) {
            continue;
        }
        clip_half_space(points, scratch, inside);
        std::mem::swap(points, scratch);
        if points.is_empty() {
            return;
        }
    }
}

/// Clips the closed outline `points` to the half-space where `inside` (affine in the
/// outline's coordinates along every chord, as depth `t` and the barycentrics are) is
/// `>= 0`, in place; `scratch` is reused storage. Where the outline's crossings with the
/// clip plane are outline points themselves (anchors), the cut passes through them exactly.
pub fn clip_to(
    points: &mut Vec<OutlinePoint>,
    scratch: &mut Vec<OutlinePoint>,
    inside: impl Fn(&OutlinePoint) -> f64,
) {
    if points.iter().all(|p| inside(p) >= 0.0) {
        return;
    }
    clip_half_space(points, scratch, inside);
    std::mem::swap(points, scratch);
}

/// Whether `p` is in every one of [`HALF_SPACES`]: the same tests, written out so that the
/// common case (an outline wholly inside) needs no call through the table.
fn inside_every_half_space(p: &OutlinePoint) -> bool {
    p.t >= 0.0
        && p.u + DOMAIN_MARGIN >= 0.0
        && p.v + DOMAIN_MARGIN >= 0.0
        && 1.0 + DOMAIN_MARGIN - p.u - p.v >= 0.0
}

/// One Sutherland-Hodgman pass: `out` receives the part of the closed polygon `points` where
/// `inside >= 0`.
fn clip_half_space(
    points: &[OutlinePoint],
    out: &mut Vec<OutlinePoint>,
    inside: impl Fn(&OutlinePoint) -> f64,
) {
    out.clear();
    let Some(&last) = points.last() else {
        return;
    };
    let (mut previous, mut previous_side) = (last, inside(&last));
    for &current in points {
        let side = inside(&current);
        if (side >= 0.0) != (previous_side >= 0.0) {
            let s = previous_side / (previous_side - side);
            push_distinct(out, lerp(&previous, &current, s));
        }
        if side >= 0.0 {
            push_distinct(out, current);
        }
        (previous, previous_side) = (current, side);
    }
    if out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
}

/// The point at `s` from `a` to `b`; exactly `a` or `b` at the ends (an anchor on the clip
/// line is kept as it is).
fn lerp(a: &OutlinePoint, b: &OutlinePoint, s: f64) -> OutlinePoint {
    if s <= 0.0 {
        return *a;
    }
    if s >= 1.0 {
        return *b;
    }
    OutlinePoint {
        u: a.u + s * (b.u - a.u),
        v: a.v + s * (b.v - a.v),
        t: a.t + s * (b.t - a.t),
    }
}

fn push_distinct(out: &mut Vec<OutlinePoint>, p: OutlinePoint) {
    if out.last() != Some(&p) {
        out.push(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(u: f64, v: f64, t: f64) -> OutlinePoint {
        OutlinePoint { u, v, t }
    }

    fn clipped(points: &[OutlinePoint]) -> Vec<OutlinePoint> {
        let (mut points, mut scratch) = (points.to_vec(), Vec::new());
        clip_outline(&mut points, &mut scratch);
        points
    }

    /// The written-out test agrees with the table of half-spaces, on points inside, outside
    /// and exactly on (or a rounding step off) each clip line, margin included.
    #[test]
    fn the_inside_shortcut_is_the_table() {
        let m = DOMAIN_MARGIN;
        let values = [
            -1.0,
            -m - 1e-17,
            -m,
            -m + 1e-17,
            -f64::MIN_POSITIVE,
            0.0,
            1e-300,
            0.25,
            0.5,
            1.0 - 1e-17,
            1.0,
            1.0 + m,
            1.0 + m + 1e-16,
            2.0,
            f64::NAN,
        ];
        for &u in &values {
            for &v in &values {
                for &t in &values {
                    let q = p(u, v, t);
                    let table = HALF_SPACES.iter().all(|inside| inside(&q) >= 0.0);
                    assert_eq!(inside_every_half_space(&q), table, "{q:?}");
                }
            }
        }
    }

    #[test]
    fn inside_outline_is_unchanged_and_outside_vanishes() {
        let inside = [p(0.1, 0.1, 1.0), p(0.5, 0.1, 2.0), p(0.2, 0.6, 1.5)];
        assert_eq!(clipped(&inside), inside);
        let behind = [p(0.1, 0.1, -1.0), p(0.5, 0.1, -2.0), p(0.2, 0.6, -0.5)];
        assert!(clipped(&behind).is_empty());
        let outside = [p(-0.1, 0.1, 1.0), p(-0.5, 0.1, 2.0), p(-0.2, 0.6, 1.5)];
        assert!(clipped(&outside).is_empty());
    }

    #[test]
    fn view_plane_cut_passes_through_the_exact_crossings() {
        // The t = 0 crossings are outline points (anchors): the cut keeps them and joins
        // them straight.
        let outline = [
            p(0.1, 0.1, 1.0),
            p(0.3, 0.1, 0.0),
            p(0.5, 0.1, -1.0),
            p(0.3, 0.4, 0.0),
        ];
        assert_eq!(
            clipped(&outline),
            [p(0.1, 0.1, 1.0), p(0.3, 0.1, 0.0), p(0.3, 0.4, 0.0)]
        );
    }

    #[test]
    fn domain_cut_interpolates_between_chord_ends() {
        // A square straddling u = 0 and u + v = 1.
        let outline = [
            p(-0.2, 0.2, 1.0),
            p(0.6, 0.2, 1.0),
            p(0.6, 0.6, 1.0),
            p(-0.2, 0.6, 1.0),
        ];
        let out = clipped(&outline);
        let slack = DOMAIN_MARGIN + 1e-15;
        assert!(out
            .iter()
            .all(|q| q.u >= -slack && q.u + q.v <= 1.0 + slack));
        // Pentagon: (0,.2) (.6,.2) (.6,.4) (.4,.6) (0,.6).
        assert_eq!(out.len(), 5, "{out:?}");
    }

    #[test]
    fn a_line_stays_a_line() {
        // Cut at u = -DOMAIN_MARGIN; the two passes over the segment compute that end by
        // interpolation from opposite sides, equal up to rounding.
        let out = clipped(&[p(-0.5, 0.25, 1.0), p(0.5, 0.25, 1.0)]);
        assert!((2..=3).contains(&out.len()), "{out:?}");
        assert!(out.contains(&p(0.5, 0.25, 1.0)), "{out:?}");
        assert!(out
            .iter()
            .all(|q| q.v == 0.25 && (q.u == 0.5 || (q.u + DOMAIN_MARGIN).abs() < 1e-15)));
    }
}
