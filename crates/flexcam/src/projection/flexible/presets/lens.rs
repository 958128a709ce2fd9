//! The magnifying lens (thesis 4.3 and 6.1.3: lenses as a re-parameterisation): inside a
//! circle of the image the projectors are drawn closer together, so the scene there appears
//! magnified; outside it the map is the identity and the image is exactly the underlying
//! (perspective) one.
//!
//! With c the circle's centre and R its radius in pixels, a pixel p at ρ = |p - c| / R < 1 is
//! moved to p' = c + (p - c) s(ρ) / ρ before the linear map to (u, v), where
//!
//! ```text
//! s(ρ) = a ρ + 2 (1 - a) ρ^2 + (a - 1) ρ^3,   a = 1 / magnification,
//! ```
//!
//! the cubic with s(0) = 0, s'(0) = a, s(1) = 1 and s'(1) = 1: the image is magnified by
//! 1 / s'(0) = `magnification` at the centre and joins the identity with a continuous
//! derivative at the border (the smooth falloff). s'(ρ) = a + (1 - a)(4ρ - 3ρ^2) is positive
//! on [0, 1] exactly when a < 4, so the map is invertible for magnifications above 1/4
//! (below 1 the lens shrinks the centre instead).
//!
//! Degenerate cases: the centre itself (ρ = 0) maps to itself; magnification 1 is the
//! identity; magnifications at or below 1/4, non-finite ones and radii that are not
//! positive are errors.

use glam::DVec2;

use crate::error::{Error, Result};
use crate::projection::image_coords::Resolution;

/// Bisection steps of the inverse radial map: 2^-60 of the radius, below f64 rounding.
const BISECTION_STEPS: u32 = 60;

/// A circular magnifier on the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Magnifier {
    /// The circle's centre in image fractions (u right, v up, as (u, v) of the linear map).
    pub center: DVec2,
    /// The radius as a fraction of the shorter image side.
    pub radius: f64,
    /// The magnification at the centre.
    pub magnification: f64,
}

impl Magnifier {
    /// Errors: see the module's degenerate cases (a non-finite centre too).
    pub fn validate(&self) -> Result<()> {
        if !self.center.is_finite() {
            return Err(Error::new("flexible magnifier center must be finite"));
        }
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(Error::new(format!(
                "flexible magnifier radius must be positive, got {}",
                self.radius
            )));
        }
        if !(self.magnification.is_finite() && self.magnification > 0.25) {
            return Err(Error::new(format!(
                "flexible magnifier magnification must be above 1/4 (the radial map is \
                 not invertible below), got {}",
                self.magnification
            )));
        }
        Ok(())
    }

    /// s(ρ) of the module.
    fn radial(&self, rho: f64) -> f64 {
        let a = 1.0 / self.magnification;
        rho * (a + rho * (2.0 * (1.0 - a) + rho * (a - 1.0)))
    }

    /// ρ with s(ρ) = `s`, for s in [0, 1], by bisection (s is increasing on [0, 1]).
    fn radial_inverse(&self, s: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            if self.radial(mid) < s {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// The circle's centre and radius in pixels.
    fn circle(&self, resolution: &Resolution) -> (DVec2, f64) {
        let size = resolution.size();
        let centre = DVec2::new(self.center.x * size.x, (1.0 - self.center.y) * size.y);
        (centre, self.radius * size.x.min(size.y))
    }

    /// p' of the module: where pixel position `pixel` samples the underlying image.
    pub fn sample_position(&self, resolution: &Resolution, pixel: DVec2) -> DVec2 {
        self.remap_in_circle(resolution, pixel, |rho| self.radial(rho))
    }

    /// The pixel position whose sample position is `sampled` (inverse of
    /// [`Magnifier::sample_position`]).
    pub fn pixel_of(&self, resolution: &Resolution, sampled: DVec2) -> DVec2 {
        self.remap_in_circle(resolution, sampled, |s| self.radial_inverse(s))
    }

    /// `point` moved along its ray from the lens centre to relative radius `radial(rho)`,
    /// where `rho` is its own radius over the lens radius; unchanged at the centre and on or
    /// outside the circle, where the map is the identity.
    fn remap_in_circle(
        &self,
        resolution: &Resolution,
        point: DVec2,
        radial: impl Fn(f64) -> f64,
    ) -> DVec2 {
        let (c, r) = self.circle(resolution);
        let d = point - c;
        let rho = d.length() / r;
        if rho >= 1.0 || rho == 0.0 {
            return point;
        }
        c + d * (radial(rho) / rho)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lens(m: f64) -> Magnifier {
        Magnifier {
            center: DVec2::new(0.25, 0.5),
            radius: 0.25,
            magnification: m,
        }
    }

    fn res() -> Resolution {
        Resolution::new(200, 100).unwrap()
    }

    #[test]
    fn magnification_at_the_centre_is_the_parameter() {
        // Centre pixel (50, 50), radius 25 pixels.
        let l = lens(3.0);
        let c = DVec2::new(50.0, 50.0);
        assert_eq!(l.sample_position(&res(), c), c);
        let h = 1e-6;
        let moved = l.sample_position(&res(), c + DVec2::new(h, 0.0)) - c;
        assert!((h / moved.x - 3.0).abs() < 1e-5, "{}", h / moved.x);
        let moved = l.sample_position(&res(), c + DVec2::new(0.0, -h)) - c;
        assert!((-h / moved.y - 3.0).abs() < 1e-5);
    }

    #[test]
    fn outside_the_circle_is_the_identity_and_the_border_is_smooth() {
        let l = lens(4.0);
        for p in [DVec2::new(75.0, 50.0), DVec2::new(150.0, 10.0), DVec2::ZERO] {
            assert_eq!(l.sample_position(&res(), p), p);
        }
        // Just inside the border the map is within O(h^2) of the identity (s'(1) = 1).
        let inside = DVec2::new(50.0 + 25.0 - 1e-3, 50.0);
        assert!((l.sample_position(&res(), inside) - inside).length() < 1e-5);
    }

    #[test]
    fn inverse_round_trips_and_the_map_is_monotonic() {
        for m in [0.3, 0.8, 2.0, 10.0] {
            let l = lens(m);
            let mut last = 0.0;
            for k in 1..=100 {
                let rho = f64::from(k) / 100.0;
                let s = l.radial(rho);
                assert!(s > last, "{m} {rho}");
                last = s;
            }
            for p in [
                DVec2::new(60.0, 45.0),
                DVec2::new(40.0, 70.0),
                DVec2::new(50.0, 50.0),
            ] {
                let back = l.pixel_of(&res(), l.sample_position(&res(), p));
                assert!((back - p).length() < 1e-9, "{m} {p} {back}");
            }
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(lens(2.0).validate().is_ok());
        for m in [0.25, 0.0, -1.0, f64::INFINITY] {
            assert!(lens(m).validate().is_err(), "{m}");
        }
        let mut l = lens(2.0);
        l.radius = 0.0;
        assert!(l.validate().is_err());
        l.radius = 0.2;
        l.center.x = f64::NAN;
        assert!(l.validate().is_err());
    }
}
