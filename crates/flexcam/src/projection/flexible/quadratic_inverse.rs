//! Q^-1 for quadratic Bezier projectors through three flat control surfaces in parallel
//! planes, the scanline class of curved projectors (Brosz 2011, 7.3): the quadratic depth
//! transitions (`depth_transition` and `ortho_near_persp_far` with `style = "quadratic"`) and
//! `blend = "bezier"` volumes of three such surfaces.
//!
//! The volume is Q(u, v, t) = sum_k B_k(t) S_k(u, v) with the Bernstein polynomials
//! B_0 = (1 - t)^2, B_1 = 2 t (1 - t), B_2 = t^2 and affine surfaces S_k = a_k + u b_k + v c_k,
//! each perpendicular to one normal n at the offset d_k = a_k . n.
//!
//! - t: the depth p . n = sum_k B_k(t) d_k is the same quadratic for every projector,
//!   A t^2 + B t + C = 0 with A = d_0 - 2 d_1 + d_2, B = 2 (d_1 - d_0), C = d_0 - p . n.
//!   The middle plane lies strictly between the others, so the depth rises (or falls)
//!   strictly over t in [0, 1] (its extremum, at -B / 2A, lies outside), and the root on that
//!   branch is t = -2 C / (B + sign(B) sqrt(B^2 - 4 A C)), free of cancellation.
//! - (u, v): the cross-section at t is the affine surface sum_k B_k(t) S_k, through p's plane:
//!   a 2 x 2 solve (`inverse::in_section`).
//!
//! Degenerate cases:
//! - equally spaced planes (A = 0): the depth is linear in t and the formula gives -C / B
//!   exactly;
//! - a point beyond the depth's extremum (B^2 - 4 A C < 0, only possible outside the volume):
//!   no t on the branch, `None`;
//! - a cross-section that is a point or a segment (a pinhole or slit at an end): no (u, v),
//!   `None` for points in its plane; where one lies strictly inside the volume the image
//!   turns over there and there is no chart (module `chart`);
//! - outside the class, each refused with its reason ([`QuadraticPlanes::classify`]): a
//!   surface that is not flat (a twisted bilinear quad, a curved surface), surfaces that are
//!   not parallel planes of one normal, none spanning a plane (points and lines only), and a
//!   middle plane on or beyond the near or far one (the depth would not be monotonic in t).

use glam::{DVec2, DVec3};

use super::control_surface::Surface;
use super::section::{affine, in_section, Affine, SAME};
use crate::error::{Error, Result};

/// The inverse of a quadratic volume between parallel planes.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct QuadraticPlanes {
    /// The control surfaces, near (t = 0), middle (the control net), far (t = 1).
    pub surfaces: [Affine; 3],
    /// The planes' shared unit normal.
    pub normal: DVec3,
    /// Each surface's offset along `normal`.
    pub offsets: [f64; 3],
}

/// The Bernstein weights of degree 2 at t.
fn bernstein(t: f64) -> [f64; 3] {
    let r = 1.0 - t;
    [r * r, 2.0 * t * r, t * t]
}

/// The reason, ending the refusal's sentence, why quadratic projectors through these
/// surfaces are outside the class.
fn outside(why: &str) -> Error {
    Error::new(format!(
        "its quadratic (Bezier) projectors run through control surfaces {why}, outside the \
         scanline class of curved projectors (three flat surfaces in parallel planes, the \
         middle one strictly between the others)"
    ))
}

impl QuadraticPlanes {
    /// The inverse of the quadratic volume through `surfaces` (near, middle, far). Errors,
    /// each a reason the volume has no inverse: other than three surfaces, a surface that is
    /// not flat, none spanning a plane, surfaces not in parallel planes of one normal, a
    /// middle plane not strictly between the others.
    pub fn classify(surfaces: &[Surface]) -> Result<QuadraticPlanes> {
        if surfaces.len() != 3 {
            return Err(outside(&format!("{} of them, not 3", surfaces.len())));
        }
        let flat = |k: usize| {
            affine(&surfaces[k]).ok_or_else(|| {
                outside(&format!(
                    "of which surface {} is not flat (a rectangle, an untwisted bilinear \
                     quad, a point or a line)",
                    k + 1
                ))
            })
        };
        let surfaces = [flat(0)?, flat(1)?, flat(2)?];
        let normal = surfaces
            .iter()
            .map(|s| s.b.cross(s.c))
            .find(|m| m.length() > SAME * (1.0 + m.length()))
            .and_then(DVec3::try_normalize)
            .ok_or_else(|| outside("of which none spans a plane (points and lines only)"))?;
        let in_plane = |s: &Affine| {
            let scale = s.b.length() + s.c.length();
            s.b.dot(normal).abs() <= SAME * scale && s.c.dot(normal).abs() <= SAME * scale
        };
        if !surfaces.iter().all(in_plane) {
            return Err(outside("that are not parallel planes sharing one normal"));
        }
        let offsets = surfaces.map(|s| s.a.dot(normal));
        let span = (surfaces[2].a - surfaces[0].a).length();
        let (first, second) = (offsets[1] - offsets[0], offsets[2] - offsets[1]);
        let strictly = |g: f64| g.abs() > SAME * span;
        if !(strictly(first) && strictly(second) && (first > 0.0) == (second > 0.0)) {
            return Err(outside(
                "whose middle plane does not lie strictly between the near and far planes",
            ));
        }
        Ok(QuadraticPlanes {
            surfaces,
            normal,
            offsets,
        })
    }

    /// The offset along the normal of the volume's cross-section at t.
    pub fn depth(&self, t: f64) -> f64 {
        let w = bernstein(t);
        (0..3).map(|k| w[k] * self.offsets[k]).sum()
    }

    /// The t whose cross-section holds `p`, on the branch of the depth through [0, 1];
    /// `None` beyond the depth's extremum.
    fn t(&self, p: DVec3) -> Option<f64> {
        let [d0, d1, d2] = self.offsets;
        let (a, b, c) = (d0 - 2.0 * d1 + d2, 2.0 * (d1 - d0), d0 - p.dot(self.normal));
        let discriminant = b * b - 4.0 * a * c;
        if discriminant < 0.0 {
            return None;
        }
        Some(-2.0 * c / (b + b.signum() * discriminant.sqrt()))
    }

    /// The volume's cross-section at t, an affine surface.
    fn section(&self, t: f64) -> Affine {
        let w = bernstein(t);
        let s = &self.surfaces;
        let sum = |f: fn(&Affine) -> DVec3| (0..3).map(|k| w[k] * f(&s[k])).sum::<DVec3>();
        Affine {
            a: sum(|s| s.a),
            b: sum(|s| s.b),
            c: sum(|s| s.c),
        }
    }

    /// (u, v) and t of `p`, the formulas extended beyond the volume (see the module).
    pub fn solve(&self, p: DVec3) -> Option<(DVec2, f64)> {
        let t = self.t(p)?;
        Some((in_section(&self.section(t), p)?, t))
    }
}

#[cfg(test)]
#[path = "quadratic_inverse_tests.rs"]
mod tests;
