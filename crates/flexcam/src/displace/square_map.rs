//! The low-distortion map between the unit square and the upper unit hemisphere of Shirley
//! and Chiu 1997: the concentric map from the square to the disk, then the disk lifted to the
//! hemisphere so that equal areas of the square are equal solid angles. Normal distributions
//! are histograms over this square ([`super::normal_distribution`]): every bin covers the
//! same solid angle, and one axis after the other gives the prefix sums of redistributed
//! bump mapping ([`super::bump`]).
//!
//! With an odd number of bins per side the pole (the unmoved normal) is the centre of the
//! middle bin, so a flat height field's distribution is one bin whose centre is exactly
//! `(0, 0, 1)`.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use glam::{DVec2, DVec3};

/// The unit direction with `z >= 0` at square point `p` in `[0, 1]^2` (the centre is the
/// pole `(0, 0, 1)`, the square's edge the horizon).
pub fn to_hemisphere(p: DVec2) -> DVec3 {
    let disk = to_disk(p);
    let r2 = disk.length_squared().min(1.0);
    let lift = (2.0 - r2).sqrt();
    DVec3::new(disk.x * lift, disk.y * lift, 1.0 - r2)
}

/// The square point of unit direction `n`; a direction below the horizon (`z < 0`) is taken
/// as its mirror image above it, a zero or non-finite one as the pole.
pub fn to_square(n: DVec3) -> DVec2 {
    if !n.is_finite() || n == DVec3::ZERO {
        return DVec2::splat(0.5);
    }
    let n = n.normalize();
    let z = n.z.abs();
    let lift = (1.0 + z).sqrt();
    from_disk(DVec2::new(n.x / lift, n.y / lift))
}

/// The concentric map (Shirley and Chiu 1997): square `[0, 1]^2` to the unit disk.
fn to_disk(p: DVec2) -> DVec2 {
    let s = p * 2.0 - DVec2::ONE;
    if s == DVec2::ZERO {
        return DVec2::ZERO;
    }
    let (r, phi) = if s.x.abs() > s.y.abs() {
        (s.x, FRAC_PI_4 * (s.y / s.x))
    } else {
        (s.y, FRAC_PI_2 - FRAC_PI_4 * (s.x / s.y))
    };
    DVec2::new(r * phi.cos(), r * phi.sin())
}

/// The inverse of [`to_disk`], clamped to the square.
fn from_disk(d: DVec2) -> DVec2 {
    let r = d.length();
    if r == 0.0 {
        return DVec2::splat(0.5);
    }
    let mut phi = d.y.atan2(d.x);
    if phi < -FRAC_PI_4 {
        phi += 2.0 * PI;
    }
    let s = if phi < FRAC_PI_4 {
        DVec2::new(r, phi * r / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        DVec2::new(-(phi - FRAC_PI_2) * r / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        DVec2::new(-r, (phi - PI) * -r / FRAC_PI_4)
    } else {
        DVec2::new(-(phi - 3.0 * FRAC_PI_2) * -r / FRAC_PI_4, -r)
    };
    ((s + DVec2::ONE) * 0.5).clamp(DVec2::ZERO, DVec2::ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pole_and_horizon() {
        assert_eq!(to_hemisphere(DVec2::splat(0.5)), DVec3::Z);
        assert_eq!(to_square(DVec3::Z), DVec2::splat(0.5));
        assert_eq!(to_square(DVec3::ZERO), DVec2::splat(0.5));
        let edge = to_hemisphere(DVec2::new(1.0, 0.5));
        assert!((edge - DVec3::X).length() < 1e-12, "{edge}");
        assert!(to_hemisphere(DVec2::new(0.0, 0.0)).z.abs() < 1e-12);
    }

    #[test]
    fn round_trips_over_the_square() {
        for i in 0..=40 {
            for j in 0..=40 {
                let p = DVec2::new(i as f64 / 40.0, j as f64 / 40.0);
                let n = to_hemisphere(p);
                assert!((n.length() - 1.0).abs() < 1e-12);
                assert!(n.z >= 0.0);
                let back = to_square(n);
                // Corners of the square are one point of the horizon each; elsewhere exact.
                assert!((back - p).length() < 1e-9, "{p} -> {n} -> {back}");
            }
        }
        let below = to_square(DVec3::new(0.3, 0.2, -0.5));
        assert_eq!(below, to_square(DVec3::new(0.3, 0.2, 0.5)));
    }

    /// Equal areas of the square are equal solid angles: the fraction of a uniform grid of
    /// square points above height z is the cap's solid angle fraction, 1 - z.
    #[test]
    fn preserves_area() {
        let n = 400;
        let mut above = 0;
        for i in 0..n {
            for j in 0..n {
                let p = DVec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                if to_hemisphere(p).z > 0.5 {
                    above += 1;
                }
            }
        }
        let fraction = above as f64 / (n * n) as f64;
        assert!((fraction - 0.5).abs() < 0.005, "{fraction}");
    }
}
