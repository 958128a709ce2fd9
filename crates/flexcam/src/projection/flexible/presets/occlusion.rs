//! The occlusion camera (Mei, Popescu and Sacks 2005; thesis 6.1.2 with the notes' erratum:
//! the third surface is Q_2): polyline projectors through three control surfaces,
//! Q_0 the eye (or the near perspective rectangle), Q_1 the perspective rectangle at the
//! near distortion plane z_1 and Q_2 the perspective far rectangle with its parameters
//! pulled towards the pole.
//!
//! The occlusion camera moves the image of a point beyond z_1 away from the pole (the image
//! of the occluder's centroid) by an amount that grows with depth, so that samples just
//! hidden behind the occluder's silhouette come out from behind it. In (u, v) that is the
//! map q -> q + k (q - q_0) / |q - q_0| at the far plane (the thesis' Q_3 formula, with k
//! the strength). The far surface holds, for each image position q', the far-plane point
//! that the map sends there: its inverse
//!
//! ```text
//! w(q') = q_0 + (q' - q_0) (1 - k / |q' - q_0|)   for |q' - q_0| >= k,
//! w(q') = q_0                                      inside the disc |q' - q_0| < k,
//! ```
//!
//! measured in units of the image width (isotropically, v scaled by H/W). Points on the far
//! plane are seen k image widths further from the pole than in the perspective view, and
//! between z_1 and the far plane the displacement grows linearly with depth:
//! Q(u, v, t) - P(u, v, t) = s (R_f(w(q)) - R_f(q)), s = (t - t_1) / (1 - t_1), where P is the
//! perspective volume and R_f the far rectangle. Projectors therefore bend towards the pole
//! behind z_1 and see round the occluder.
//!
//! Degenerate cases: the image positions inside the disc all end at the far point of the
//! pole (their projectors converge there); strength 0 is the perspective volume.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};

/// A rectangle `corner + x u_edge + y v_edge` evaluated at the pinched parameters
/// (x, y) = w(u, v) (see the module).
#[derive(Debug, Clone, PartialEq)]
pub struct PinchedRectangle {
    /// The rectangle's point at (x, y) = (0, 0).
    pub corner: DVec3,
    /// The step from x = 0 to x = 1.
    pub u_edge: DVec3,
    /// The step from y = 0 to y = 1.
    pub v_edge: DVec3,
    /// q_0 in (u, v).
    pub pole: DVec2,
    /// k, in image widths.
    pub strength: f64,
    /// H / W: the height of the (u, v) square in image widths.
    pub aspect: f64,
}

impl PinchedRectangle {
    /// Errors: a pole outside [0, 1]^2, a negative or non-finite strength, an aspect ratio
    /// that is not positive and finite.
    pub fn new(
        [corner, u_edge, v_edge]: [DVec3; 3],
        pole: DVec2,
        strength: f64,
        aspect: f64,
    ) -> Result<Self> {
        if !(pole.is_finite() && (0.0..=1.0).contains(&pole.x) && (0.0..=1.0).contains(&pole.y)) {
            return Err(Error::new(format!(
                "flexible occlusion pole must lie in the image, [0, 1] x [0, 1], got \
                 [{}, {}]",
                pole.x, pole.y
            )));
        }
        if !(strength.is_finite() && strength >= 0.0) {
            return Err(Error::new(format!(
                "flexible occlusion strength must be finite and at least 0, got {strength}"
            )));
        }
        if !(aspect.is_finite() && aspect > 0.0) {
            return Err(Error::new(format!(
                "flexible occlusion needs a positive image aspect ratio, got {aspect}"
            )));
        }
        Ok(PinchedRectangle {
            corner,
            u_edge,
            v_edge,
            pole,
            strength,
            aspect,
        })
    }

    /// w(u, v): the parameters pulled towards the pole by `strength` image widths.
    pub fn warp(&self, uv: DVec2) -> DVec2 {
        let scale = DVec2::new(1.0, self.aspect);
        let offset = (uv - self.pole) * scale;
        let r = offset.length();
        if r <= self.strength {
            return self.pole;
        }
        self.pole + offset * (1.0 - self.strength / r) / scale
    }

    /// The surface point at (u, v).
    pub fn point(&self, uv: DVec2) -> DVec3 {
        let w = self.warp(uv);
        self.corner + w.x * self.u_edge + w.y * self.v_edge
    }

    /// Whether every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.corner.is_finite() && self.u_edge.is_finite() && self.v_edge.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pinched(strength: f64) -> PinchedRectangle {
        PinchedRectangle::new(
            [DVec3::new(-2.0, -1.0, 5.0), DVec3::X * 4.0, DVec3::Y * 2.0],
            DVec2::new(0.5, 0.5),
            strength,
            0.5,
        )
        .unwrap()
    }

    #[test]
    fn warp_moves_towards_the_pole_by_the_strength() {
        let p = pinched(0.1);
        // 0.3 image widths right of the pole: 0.2 after the pull.
        assert!((p.warp(DVec2::new(0.8, 0.5)) - DVec2::new(0.7, 0.5)).length() < 1e-15);
        // Above the pole: v is in units of H = W / 2, so 0.4 in v is 0.2 widths -> 0.1.
        assert!((p.warp(DVec2::new(0.5, 0.9)) - DVec2::new(0.5, 0.7)).length() < 1e-15);
        // In world units on the far rectangle (4 wide): 0.1 widths = 0.4.
        let unpinched = pinched(0.0);
        let shift = unpinched.point(DVec2::new(0.8, 0.5)) - p.point(DVec2::new(0.8, 0.5));
        assert!((shift - DVec3::X * 0.4).length() < 1e-14);
    }

    #[test]
    fn the_disc_round_the_pole_collapses_and_zero_strength_is_identity() {
        let p = pinched(0.1);
        for uv in [
            DVec2::new(0.55, 0.5),
            DVec2::new(0.5, 0.5),
            DVec2::new(0.45, 0.55),
        ] {
            assert_eq!(p.warp(uv), p.pole);
        }
        let q = pinched(0.0);
        for uv in [DVec2::new(0.2, 0.9), DVec2::new(0.5, 0.5), DVec2::ONE] {
            assert!((q.warp(uv) - uv).length() < 1e-15);
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        let r = [DVec3::ZERO, DVec3::X, DVec3::Y];
        assert!(PinchedRectangle::new(r, DVec2::new(1.5, 0.5), 0.1, 1.0).is_err());
        assert!(PinchedRectangle::new(r, DVec2::splat(0.5), -0.1, 1.0).is_err());
        assert!(PinchedRectangle::new(r, DVec2::splat(0.5), f64::NAN, 1.0).is_err());
        assert!(PinchedRectangle::new(r, DVec2::splat(0.5), 0.1, 0.0).is_err());
    }
}
