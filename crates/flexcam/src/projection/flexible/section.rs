//! Flat control surfaces as the analytic inverses read them: an affine surface
//! a + u b + v c, and the (u, v) of a point on one (a volume's cross-section through it).

use glam::{DMat2, DVec2, DVec3};

use super::control_surface::{LineParam, Surface};

/// Relative tolerance for "the same" centre, frame or range, and for the domain edges.
pub(super) const SAME: f64 = 1e-12;

/// An affine surface a + u b + v c.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Affine {
    pub a: DVec3,
    pub b: DVec3,
    pub c: DVec3,
}

/// `s` as an affine surface, `None` where it is not one (a twisted bilinear quad, a curved
/// surface).
pub(super) fn affine(s: &Surface) -> Option<Affine> {
    match *s {
        Surface::Rectangle {
            corner,
            u_edge,
            v_edge,
        } => Some(Affine {
            a: corner,
            b: u_edge,
            c: v_edge,
        }),
        Surface::Point(p) => Some(Affine {
            a: p,
            b: DVec3::ZERO,
            c: DVec3::ZERO,
        }),
        Surface::Line { start, end, along } => Some(match along {
            LineParam::U => Affine {
                a: start,
                b: end - start,
                c: DVec3::ZERO,
            },
            LineParam::V => Affine {
                a: start,
                b: DVec3::ZERO,
                c: end - start,
            },
        }),
        Surface::Bilinear {
            corners: [p00, p10, p11, p01],
        } => {
            let twist = p11 - p10 - p01 + p00;
            let scale = (p10 - p00).length() + (p01 - p00).length();
            (twist.length() <= SAME * scale).then_some(Affine {
                a: p00,
                b: p10 - p00,
                c: p01 - p00,
            })
        }
        Surface::Sphere(_)
        | Surface::Cylinder(_)
        | Surface::Bezier(_)
        | Surface::BSpline(_)
        | Surface::Nurbs(_)
        | Surface::Panorama(_)
        | Surface::Pinched(_)
        | Surface::Path(_)
        | Surface::Warped(_)
        | Surface::Displaced(_) => None,
    }
}

/// The (u, v) of `p` on the cross-section `s` of a volume, the affine surface through p's
/// plane: the 2 x 2 least-squares solve of a + u b + v c = p. `None` where the
/// cross-section is a point or a segment (b and c parallel or zero): no single (u, v).
pub(super) fn in_section(s: &Affine, p: DVec3) -> Option<DVec2> {
    let (a, b, c) = (s.a, s.b, s.c);
    // Least squares in the plane: [b.b b.c; b.c c.c] (u, v) = (b.q, c.q).
    let q = p - a;
    let m = DMat2::from_cols(
        DVec2::new(b.dot(b), b.dot(c)),
        DVec2::new(b.dot(c), c.dot(c)),
    );
    let det = m.determinant();
    if det.abs() <= SAME * SAME * (b.length_squared() * c.length_squared()) || det == 0.0 {
        return None; // the cross-section is a point or a segment: no single (u, v)
    }
    Some(m.inverse() * DVec2::new(b.dot(q), c.dot(q)))
}
