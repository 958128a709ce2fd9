//! The radial laws of `type = "fisheye"`: how a ray's angle theta off the view axis maps to
//! its radius rho in the image plane, and back.
//!
//! The four classic mappings (unit focal length; `lens` scales them in millimetres):
//! equidistant rho = theta, equisolid rho = 2 sin(theta/2), stereographic rho = 2 tan(theta/2),
//! orthographic rho = sin(theta). Their inverses are analytic.
//!
//! Blender Cycles' `fisheye_lens_polynomial` goes the other way: the radius r on the sensor
//! (millimetres) gives the angle, theta(r) = -(k0 + k1 r + k2 r^2 + k3 r^3 + k4 r^4)
//! (Cycles 3.x/4.x, `intern/cycles/kernel/camera/projection.h`,
//! `fisheye_lens_polynomial_to_direction`: `theta = -(coeff0 + dot(coeffs, (r, r^2, r^3,
//! r^4)))`, pixels with |theta| > fov/2 see nothing). Its inverse solves theta(r) = theta for
//! r by Newton's method kept inside a bracket that shrinks every step (bisection where a
//! step would leave it), so it converges on every monotone polynomial (see
//! [`super::monotone_root`]).

use std::f64::consts::{FRAC_PI_2, PI};

use super::monotone_root::solve_increasing;
use super::params::{angle_radians, UpTo};
use crate::error::{Error, Result};

/// A fisheye mapping as a scene file names it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FisheyeMapping {
    /// rho = theta: the angle grows linearly with the radius (the default).
    Equidistant,
    /// rho = 2 sin(theta/2): equal solid angles cover equal image areas.
    Equisolid,
    /// rho = 2 tan(theta/2): conformal (small shapes keep their form).
    Stereographic,
    /// rho = sin(theta): at most a hemisphere.
    Orthographic,
    /// Cycles' `fisheye_lens_polynomial`, [k0, k1, k2, k3, k4]: theta(r) = -(k0 + k1 r + ...
    /// + k4 r^4), r in millimetres on the sensor.
    Polynomial([f64; 5]),
}

/// Mapping names as written in scene files, the polynomial last.
pub const MAPPING_NAMES: [&str; 5] = [
    "equidistant",
    "equisolid",
    "stereographic",
    "orthographic",
    "polynomial",
];

impl FisheyeMapping {
    /// The scene-file name.
    pub fn name(&self) -> &'static str {
        match self {
            FisheyeMapping::Equidistant => "equidistant",
            FisheyeMapping::Equisolid => "equisolid",
            FisheyeMapping::Stereographic => "stereographic",
            FisheyeMapping::Orthographic => "orthographic",
            FisheyeMapping::Polynomial(_) => "polynomial",
        }
    }

    /// Checks `fov_degrees` against this mapping's range and returns half of it in radians:
    /// (0, 360] for the equidistant, equisolid and polynomial mappings, (0, 360) for the
    /// stereographic one (rho is infinite straight behind), (0, 180] for the orthographic one
    /// (sin(theta) turns back at 90 degrees).
    pub fn half_fov(&self, fov_degrees: f64) -> Result<f64> {
        let max = match self {
            FisheyeMapping::Stereographic => UpTo::Below(360.0),
            FisheyeMapping::Orthographic => UpTo::Including(180.0),
            _ => UpTo::Including(360.0),
        };
        let fov = angle_radians("fisheye", "fov", fov_degrees, max).map_err(|e| match self {
            FisheyeMapping::Equidistant => e,
            _ => Error::new(format!("{} (mapping \"{}\")", e.message, self.name())),
        })?;
        Ok(0.5 * fov)
    }
}

/// A classic mapping's rho(theta) for unit focal length, continued monotonically beyond its
/// own range for the rasteriser's branch: the orthographic sin(theta) reflects past 90
/// degrees as 2 - sin(theta).
pub(super) fn classic_radius(mapping: FisheyeMapping, theta: f64) -> f64 {
    match mapping {
        FisheyeMapping::Equisolid => 2.0 * (0.5 * theta).sin(),
        FisheyeMapping::Stereographic => 2.0 * (0.5 * theta).tan(),
        FisheyeMapping::Orthographic if theta > FRAC_PI_2 => 2.0 - theta.sin(),
        FisheyeMapping::Orthographic => theta.sin(),
        FisheyeMapping::Equidistant | FisheyeMapping::Polynomial(_) => theta,
    }
}

/// The inverse of [`classic_radius`] on the mapping's range (rho up to 2 for the equisolid
/// mapping, up to 1 for the orthographic one).
pub(super) fn classic_theta(mapping: FisheyeMapping, rho: f64) -> f64 {
    match mapping {
        FisheyeMapping::Equisolid => 2.0 * (0.5 * rho).min(1.0).asin(),
        FisheyeMapping::Stereographic => 2.0 * (0.5 * rho).atan(),
        FisheyeMapping::Orthographic => rho.min(1.0).asin(),
        FisheyeMapping::Equidistant | FisheyeMapping::Polynomial(_) => rho,
    }
}

/// Samples of the search for the end of a polynomial's valid range.
const POLYNOMIAL_SAMPLES: usize = 4096;

/// Cycles' lens polynomial, validated over an image: theta(r) increases strictly on
/// [0, `r_end`] and theta(0) = -k0 >= 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LensPolynomial {
    k: [f64; 5],
    /// The radius (mm) where the valid image ends: where theta reaches fov/2, or the image's
    /// farthest point when theta stays below it there.
    pub r_end: f64,
    /// theta(`r_end`).
    pub theta_end: f64,
}

impl LensPolynomial {
    /// Validates `k` for a fisheye cut at `half_fov` whose image reaches `r_corner` mm from
    /// the centre. Errors (each naming `polynomial`): a non-finite coefficient; k0 > 0 (a
    /// negative angle at the centre, which Cycles would turn into the opposite azimuth);
    /// -k0 >= fov/2 (nothing seen); theta(r) not increasing somewhere on the part of the
    /// image inside the circle (its derivative reaches zero before theta reaches fov/2 and
    /// before the image's farthest point); |theta| back at or below fov/2 between the circle
    /// and the image's farthest point (4096 samples).
    pub fn new(k: [f64; 5], half_fov: f64, r_corner: f64) -> Result<Self> {
        if let Some(bad) = k.iter().find(|c| !c.is_finite()) {
            return Err(Error::new(format!(
                "fisheye polynomial coefficients must be finite, got {bad}"
            )));
        }
        let cut = half_fov.min(PI);
        let mut poly = LensPolynomial {
            k,
            r_end: r_corner,
            theta_end: 0.0,
        };
        let theta0 = poly.theta(0.0);
        if theta0 < 0.0 {
            return Err(Error::new(format!(
                "fisheye polynomial k0 must be <= 0 (theta(0) = -k0 is the angle at the image centre), got {}",
                k[0]
            )));
        }
        if theta0 >= cut {
            return Err(Error::new(format!(
                "fisheye polynomial sees nothing: theta(0) = -k0 = {:.4} degrees is not below fov/2 = {:.4}",
                theta0.to_degrees(),
                cut.to_degrees()
            )));
        }
        let mut inside = 0.0;
        for step in 1..=POLYNOMIAL_SAMPLES {
            let r = r_corner * step as f64 / POLYNOMIAL_SAMPLES as f64;
            if poly.slope(inside) <= 0.0 || poly.slope(r) <= 0.0 {
                let turn = if poly.slope(inside) <= 0.0 {
                    inside
                } else {
                    bisect(inside, r, |x| poly.slope(x) > 0.0)
                };
                if poly.theta(turn) < cut {
                    return Err(Error::new(format!(
                        "fisheye polynomial is not increasing over the image circle: \
                         d theta / dr = 0 at r = {turn:.6} mm (theta = {:.4} degrees, below fov/2 = {:.4})",
                        poly.theta(turn).to_degrees(),
                        cut.to_degrees()
                    )));
                }
            }
            if poly.theta(r) >= cut {
                poly.r_end = bisect(inside, r, |x| poly.theta(x) < cut);
                poly.theta_end = poly.theta(poly.r_end);
                return poly.stays_outside(cut, r_corner).map(|()| poly);
            }
            inside = r;
        }
        poly.theta_end = poly.theta(r_corner);
        Ok(poly)
    }

    /// Checks that beyond `r_end`, up to `r_corner`, |theta| stays above `cut` (sampled as
    /// the search): where a turning polynomial came back inside fov/2, Cycles would show a
    /// second, folded ring of the image there.
    fn stays_outside(&self, cut: f64, r_corner: f64) -> Result<()> {
        for step in 1..=POLYNOMIAL_SAMPLES {
            let r = self.r_end + (r_corner - self.r_end) * step as f64 / POLYNOMIAL_SAMPLES as f64;
            let theta = self.theta(r);
            if theta.abs() <= cut {
                return Err(Error::new(format!(
                    "fisheye polynomial comes back inside fov/2 beyond the image circle: theta = {:.4} degrees at r = {r:.6} mm (the circle ends at {:.6} mm)",
                    theta.to_degrees(),
                    self.r_end
                )));
            }
        }
        Ok(())
    }

    /// theta(r), radians.
    pub fn theta(&self, r: f64) -> f64 {
        let [k0, k1, k2, k3, k4] = self.k;
        -(k0 + r * (k1 + r * (k2 + r * (k3 + r * k4))))
    }

    /// d theta / dr.
    fn slope(&self, r: f64) -> f64 {
        let [_, k1, k2, k3, k4] = self.k;
        -(k1 + r * (2.0 * k2 + r * (3.0 * k3 + r * 4.0 * k4)))
    }

    /// The r in [0, r_end] with theta(r) = `theta`, for theta in [theta(0), theta_end].
    pub fn radius(&self, theta: f64) -> f64 {
        solve_increasing(
            |r| self.theta(r),
            |r| self.slope(r),
            theta,
            (0.0, self.r_end),
            0.5 * self.r_end,
        )
    }
}

/// The boundary between `inside` (where `keep` holds) and `outside` (where it does not),
/// bisected to rounding; returns the last point where `keep` holds.
fn bisect(mut inside: f64, mut outside: f64, keep: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..100 {
        let middle = 0.5 * (inside + outside);
        if middle == inside || middle == outside {
            break;
        }
        if keep(middle) {
            inside = middle;
        } else {
            outside = middle;
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classic_laws_invert() {
        for mapping in [
            FisheyeMapping::Equidistant,
            FisheyeMapping::Equisolid,
            FisheyeMapping::Stereographic,
            FisheyeMapping::Orthographic,
        ] {
            for theta in [0.0, 0.1, 0.7, 1.5] {
                let rho = classic_radius(mapping, theta);
                let back = classic_theta(mapping, rho);
                assert!((back - theta).abs() < 1e-14, "{mapping:?} {theta}");
            }
        }
        // Orthographic past 90 degrees continues upwards.
        let o = FisheyeMapping::Orthographic;
        assert!(classic_radius(o, 2.0) > classic_radius(o, FRAC_PI_2));
    }

    #[test]
    fn fov_ranges_per_mapping() {
        assert!(FisheyeMapping::Orthographic.half_fov(180.0).is_ok());
        let e = FisheyeMapping::Orthographic.half_fov(200.0).unwrap_err();
        assert_eq!(
            e.message,
            "fisheye fov must be in (0, 180] degrees, got 200 (mapping \"orthographic\")"
        );
        assert!(FisheyeMapping::Stereographic.half_fov(360.0).is_err());
        assert!(FisheyeMapping::Equisolid.half_fov(360.0).is_ok());
        let e = FisheyeMapping::Equidistant.half_fov(400.0).unwrap_err();
        assert_eq!(
            e.message,
            "fisheye fov must be in (0, 360] degrees, got 400"
        );
    }

    /// Cycles' default polynomial (fitted to its 50 mm perspective on a 36 mm sensor).
    const CYCLES_DEFAULT: [f64; 5] = [
        -1.1735143712967577e-05,
        -0.019988736953434998,
        -3.3525322965709175e-06,
        3.099275275886036e-06,
        -2.6064646454854524e-08,
    ];

    #[test]
    fn polynomial_inverse_and_end() {
        let p = LensPolynomial::new(CYCLES_DEFAULT, PI / 2.0, 21.6).unwrap();
        // theta stays below 90 degrees on the 36 x 24 sensor: the valid image is all of it.
        assert_eq!(p.r_end, 21.6);
        for r in [0.0, 0.3, 5.0, 17.9, 21.6] {
            let back = p.radius(p.theta(r));
            assert!((back - r).abs() <= 1e-12 * (1.0 + r), "{r}: {back}");
        }
        // A cut at 20 degrees ends the image where theta = 20 degrees.
        let p = LensPolynomial::new(CYCLES_DEFAULT, 20f64.to_radians(), 21.6).unwrap();
        assert!((p.theta(p.r_end) - 20f64.to_radians()).abs() < 1e-14);
    }

    #[test]
    fn bad_polynomials_are_refused() {
        // theta = 0.1 r - 0.01 r^2 turns at r = 5 (theta = 0.25 rad, 14.3 degrees).
        let e = LensPolynomial::new([0.0, -0.1, 0.01, 0.0, 0.0], PI / 2.0, 20.0).unwrap_err();
        assert!(e.message.starts_with("fisheye polynomial is not increasing over the image circle: d theta / dr = 0 at r = 5.000000 mm"), "{e}");
        // The same polynomial cut at 0.1 rad on an 8 mm image never reaches the turn (on a
        // 20 mm one it would come back below 0.1 rad beyond r = 8.87).
        assert!(LensPolynomial::new([0.0, -0.1, 0.01, 0.0, 0.0], 0.1, 8.0).is_ok());
        let e = LensPolynomial::new([0.01, -0.1, 0.0, 0.0, 0.0], 1.0, 20.0).unwrap_err();
        assert!(e.message.starts_with("fisheye polynomial k0 must be <= 0"));
        let e = LensPolynomial::new([0.0, 0.1, 0.0, 0.0, 0.0], 1.0, 20.0).unwrap_err();
        assert!(e.message.contains("not increasing"), "{e}");
        let e = LensPolynomial::new([-2.0, -0.1, 0.0, 0.0, 0.0], 1.0, 20.0).unwrap_err();
        assert!(e.message.starts_with("fisheye polynomial sees nothing"));
        // theta = 0.1 r - 0.005 r^2 passes 0.4 rad near r = 5.5, turns at 10 and is back
        // below 0.4 by r = 14.5: a second ring inside a 20 mm image.
        let e = LensPolynomial::new([0.0, -0.1, 0.005, 0.0, 0.0], 0.4, 20.0).unwrap_err();
        assert!(
            e.message
                .starts_with("fisheye polynomial comes back inside fov/2"),
            "{e}"
        );
        assert!(LensPolynomial::new([0.0, -0.1, 0.005, 0.0, 0.0], 0.4, 14.0).is_ok());
        let e = LensPolynomial::new([0.0, f64::NAN, 0.0, 0.0, 0.0], 1.0, 20.0).unwrap_err();
        assert!(e.message.contains("finite"));
    }
}
