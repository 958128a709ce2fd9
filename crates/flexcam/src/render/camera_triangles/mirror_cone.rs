//! A cone that holds every ray direction of a per-fragment mirror over a piece of a camera
//! triangle: what the bounds project along in place of the corner directions.
//!
//! The per-fragment ray at barycentrics `b` ([`TriangleMirror`]) has the direction
//! `r(b) = H(n(b)) i(b)`, `H(n) = I - 2 n n^T` the reflection about the plane with normal
//! `n`, `i(b)` the eye's unit ray to the base point `P(b)` and `n(b)` the normalised
//! interpolated normal `N(b)`. It is no convex combination of the corner directions, so the
//! nine-point hull argument needs another cone. With `b0` the piece's centroid, `i0 = i(b0)`,
//! `n0 = n(b0)` and the axis `a = H(n0) i0`:
//!
//! 1. `angle(r(b), a) <= angle(i(b), i0) + 2 angle(n(b), n0)`. `H(n)` is orthogonal, so
//!    `angle(H(n) i, H(n) i0) = angle(i, i0)`; and `H(n0) H(n)` is the rotation by twice the
//!    angle between `n` and `n0` (about `n x n0`), which turns no unit vector by more, so
//!    `angle(H(n) i0, H(n0) i0) <= 2 angle(n, n0)`; the triangle inequality of angles adds
//!    the two.
//! 2. `angle(i(b), i0) <= s_i = max_k angle(P(c_k) - eye, i0)` over the piece's corners
//!    `c_k`, when `s_i < pi / 2`: `P(b) - eye` is a convex combination of the corners'
//!    `P(c_k) - eye`, and the vectors within an angle below `pi / 2` of `i0` form a convex
//!    cone. Likewise `angle(n(b), n0) <= s_n = max_k angle(N(c_k), n0)` (`N` is affine in
//!    `b`), and `s_n < pi / 2` also keeps `N(b)` from vanishing inside the piece.
//! 3. So every `r(b)` lies in the circular cone of axis `a` and half-angle
//!    `h = s_i + 2 s_n`: `r(b) / (r(b) . a) = a + w`, `w` orthogonal to `a` of length
//!    `tan angle(r(b), a) <= tan h`. The disc of radius `tan h` lies in the equilateral
//!    triangle about it (circumradius `2 tan h`), so `r(b)` is a positive combination of
//!    `D_j = a + 2 tan h (cos(2 pi j / 3) e1 + sin(2 pi j / 3) e2)`, `e1, e2` an orthonormal
//!    pair orthogonal to `a`. The bounds then take `D_1, D_2, D_3` as the cone's generators
//!    (on the base plane, where the ray at `b` starts at barycentrics `b`: a point seen at
//!    `b` projects along `r(b)` to `b`, hence into the hull of its projections along the
//!    `D_j`, as [`super::bound`] argues).
//!
//! 4. The ray keeps out of the base triangle's face (`reflect_above`): where `r(b)` has
//!    elevation below `e_max = asin(REFLECTION_LIFT)` over the face (unit normal `g`,
//!    facing the eye), it is replaced by a direction of the same azimuth, higher but at
//!    most at `e_max`: on the vertical great circle through `r(b)`, between `r(b)` and the
//!    point `t` at `e_max`. Along that circle the angle to `a` falls as the elevation rises
//!    up to the point nearest `a`, whose elevation is at least `elev(a)` (`tan e* = tan
//!    elev(a) / cos(azimuth difference)`, or the zenith). So when `elev(a) >= e_max` a
//!    lifted ray is nearer `a` than `r(b)` was and the cone stands. Otherwise (the axis
//!    itself near or under the face) `angle(t, a) <= angle(t, r(b)) + h <= e_max -
//!    elev(r(b)) + h`, with `elev(r(b)) >= elev(a) - h`: the half-angle becomes `max(h, 2 h
//!    + e_max - elev(a))`.
//!
//! The angles are computed with `atan2` (accurate to rounding at every angle) and `h` is
//! enlarged by [`ANGLE_MARGIN`] against rounding. Degenerate cases, each giving `None` (the
//! bounds then take the whole piece, which holds every fragment): the eye at a corner's or
//! the centroid's base point, a zero interpolated normal at a corner or the centroid,
//! `s_i` or `s_n` at least [`MAX_SPREAD`] (normals or eye rays that turn by a right angle
//! over the piece, where the convex-cone step fails), or `h` at least [`MAX_HALF_ANGLE`] (a
//! cone so wide it bounds nothing). Quartering narrows every spread, so pieces of a camera
//! triangle that has no cone usually have one.

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec2, DVec3};

use crate::geometry::optics::{reflect, REFLECTION_LIFT};
use crate::projection::TriangleMirror;

/// The largest spread (radians) of the eye rays or the normals over a piece that still gives
/// a cone: below a right angle, with room for rounding.
pub const MAX_SPREAD: f64 = 1.5;

/// The widest half-angle (radians) of a cone worth bounding with.
pub const MAX_HALF_ANGLE: f64 = 1.4;

/// Relative enlargement of the half-angle against rounding (and an absolute 1e-12 radians).
const ANGLE_MARGIN: f64 = 1e-9;

/// The generators `D_1, D_2, D_3` of a cone holding every ray direction of `mirror` over the
/// piece `sub` of its triangle (barycentric corners), or `None` in the degenerate cases of
/// the module doc.
pub fn cone(mirror: &TriangleMirror, sub: [DVec2; 3]) -> Option<[DVec3; 3]> {
    let (axis, half) = axis_and_half_angle(mirror, sub)?;
    let (e1, e2) = axis.any_orthonormal_pair();
    let radius = 2.0 * half.tan();
    Some([0.0, 1.0, 2.0].map(|j: f64| {
        let angle = TAU * j / 3.0;
        axis + radius * (angle.cos() * e1 + angle.sin() * e2)
    }))
}

/// The cone's unit axis `a` and half-angle `h` (module doc).
pub fn axis_and_half_angle(mirror: &TriangleMirror, sub: [DVec2; 3]) -> Option<(DVec3, f64)> {
    let centre = (sub[0] + sub[1] + sub[2]) / 3.0;
    let i0 = (mirror.point(centre) - mirror.eye).try_normalize()?;
    let n0 = mirror.normal(centre).try_normalize()?;
    let (mut spread_i, mut spread_n) = (0.0_f64, 0.0_f64);
    for c in sub {
        spread_i = spread_i.max(angle(mirror.point(c) - mirror.eye, i0)?);
        spread_n = spread_n.max(angle(mirror.normal(c), n0)?);
    }
    if spread_i >= MAX_SPREAD || spread_n >= MAX_SPREAD {
        return None;
    }
    let half = spread_i + 2.0 * spread_n;
    let axis = reflect(i0, n0);
    // Step 4: the lift out of the face (a degenerate face lifts nothing).
    let face = mirror.face_towards(i0);
    let elevation = FRAC_PI_2 - angle(face, axis).unwrap_or(FRAC_PI_2);
    let lift = REFLECTION_LIFT.asin();
    let half = if face != DVec3::ZERO && elevation < lift {
        half.max(2.0 * half + lift - elevation)
    } else {
        half
    };
    let half = half * (1.0 + ANGLE_MARGIN) + 1e-12;
    (half < MAX_HALF_ANGLE).then_some((axis, half))
}

/// The angle between `v` and the unit vector `unit`; `None` for a zero or non-finite `v`.
fn angle(v: DVec3, unit: DVec3) -> Option<f64> {
    let length = v.length();
    (length > 0.0 && length.is_finite()).then(|| v.cross(unit).length().atan2(v.dot(unit)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A patch of a unit sphere around the +z pole, seen from the eye above it.
    fn sphere_patch(size: f64, eye: DVec3) -> TriangleMirror {
        let on_sphere = |x: f64, y: f64| DVec3::new(x, y, 1.0).normalize();
        let normals = [
            on_sphere(-size, -size),
            on_sphere(size, -size),
            on_sphere(0.0, size),
        ];
        TriangleMirror {
            eye,
            points: normals,
            normals,
        }
    }

    /// Every direction on a dense grid of the piece lies in the cone of the generators (a
    /// non-negative combination), on pieces of several sizes and eyes.
    #[test]
    fn the_cone_holds_every_reflected_direction() {
        for (size, eye) in [
            (0.05, DVec3::new(0.0, 0.0, 3.0)),
            (0.3, DVec3::new(0.4, -0.2, 2.0)),
            (0.4, DVec3::new(2.0, 0.5, 1.5)),
        ] {
            let mirror = sphere_patch(size, eye);
            for sub in [
                [DVec2::ZERO, DVec2::X, DVec2::Y],
                [
                    DVec2::new(0.5, 0.0),
                    DVec2::new(0.5, 0.5),
                    DVec2::new(0.0, 0.5),
                ],
            ] {
                let d = cone(&mirror, sub).unwrap();
                let m = glam::DMat3::from_cols(d[0], d[1], d[2]).inverse();
                let n = 40;
                for a in 0..=n {
                    for b in 0..=n - a {
                        let (s, t) = (a as f64 / n as f64, b as f64 / n as f64);
                        let p = sub[0] + s * (sub[1] - sub[0]) + t * (sub[2] - sub[0]);
                        let r = mirror.ray(p).unwrap().direction;
                        let weights = m * r;
                        assert!(weights.min_element() >= -1e-12, "{size} {p} {weights}");
                    }
                }
            }
        }
    }

    /// A patch near a mirror's rim, where the normals lean so far from the face that some
    /// mirror images point into it: the lifted rays lie in the cone too.
    #[test]
    fn the_cone_holds_lifted_rays() {
        let lean = |x: f64, y: f64| DVec3::new(-0.94 + x, y, 0.34).normalize();
        let mirror = TriangleMirror {
            eye: DVec3::new(-2.0, 0.2, 2.0),
            points: [DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: [lean(0.0, 0.0), lean(0.3, 0.0), lean(0.0, 0.3)],
        };
        let sub = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let d = cone(&mirror, sub).unwrap();
        let m = glam::DMat3::from_cols(d[0], d[1], d[2]).inverse();
        let (mut lifted, n) = (0, 40);
        for a in 0..=n {
            for b in 0..=n - a {
                let p = DVec2::new(a as f64, b as f64) / n as f64;
                let r = mirror.ray(p).unwrap().direction;
                lifted += usize::from(r.z == REFLECTION_LIFT);
                assert!((m * r).min_element() >= -1e-12, "{p}");
            }
        }
        assert!(lifted > 0);
    }

    /// The half-angle shrinks with the piece: a quarter's cone is narrower.
    #[test]
    fn quarters_narrow_the_cone() {
        let mirror = sphere_patch(0.3, DVec3::new(0.4, -0.2, 2.0));
        let whole = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let quarter = [DVec2::ZERO, DVec2::new(0.5, 0.0), DVec2::new(0.0, 0.5)];
        let (_, h) = axis_and_half_angle(&mirror, whole).unwrap();
        let (_, hq) = axis_and_half_angle(&mirror, quarter).unwrap();
        assert!(hq < 0.6 * h, "{hq} {h}");
    }

    /// Degenerate cases give no cone: the eye at a corner, a zero normal at a corner,
    /// normals that turn by a right angle, a cone too wide.
    #[test]
    fn degenerate_pieces_have_no_cone() {
        let whole = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let mut at_eye = sphere_patch(0.1, DVec3::new(0.0, 0.0, 3.0));
        at_eye.eye = at_eye.points[1];
        assert!(cone(&at_eye, whole).is_none());
        let mut zero = sphere_patch(0.1, DVec3::new(0.0, 0.0, 3.0));
        zero.normals[2] = DVec3::ZERO;
        assert!(cone(&zero, whole).is_none());
        let mut turned = sphere_patch(0.1, DVec3::new(0.0, 0.0, 3.0));
        turned.normals = [DVec3::X, DVec3::Y, -DVec3::X];
        assert!(cone(&turned, whole).is_none());
        // Normals 0.5 radians apart: 2 s_n alone exceeds MAX_HALF_ANGLE.
        let wide = sphere_patch(0.9, DVec3::new(0.0, 0.0, 3.0));
        let (_, s) =
            axis_and_half_angle(&sphere_patch(0.3, DVec3::new(0.0, 0.0, 3.0)), whole).unwrap();
        assert!(s < MAX_HALF_ANGLE);
        assert!(cone(&wide, whole).is_none());
    }
}
