//! OpenCV's radial-tangential lens distortion (Brown-Conrady with OpenCV's rational radial
//! factor), its Jacobian, the radius up to which it is invertible, and its inverse by
//! Newton's method.
//!
//! The map takes an undistorted normalised point p = (x, y) (x right, y down, at distance 1
//! along the view) to the distorted point
//!
//! ```text
//! s = x^2 + y^2
//! R = (1 + k1 s + k2 s^2 + k3 s^3) / (1 + k4 s + k5 s^2 + k6 s^3)
//! x' = x R + 2 p1 x y + p2 (s + 2 x^2)
//! y' = y R + p1 (s + 2 y^2) + 2 p2 x y
//! ```
//!
//! which is one-to-one only near the centre: a barrel distortion (k1 < 0) turns back at some
//! radius, and a rational denominator can vanish. Far enough from the centre it is also
//! meaningless: a calibration fits it to the image, and its high powers explode outside.
//! The *valid radius* is where the map first stops being a local diffeomorphism that keeps
//! orientation, or leaves the image by a wide margin: along 128 directions the radius grows
//! (uniformly in the angle atan(r) from the axis, 1024 steps up to [`RADIUS_CAP`]) until the
//! denominator, the radial factor R or the Jacobian determinant is no longer positive (a
//! fold, whose crossing is refined by bisection and kept less 0.1 %, since the crossing
//! varies smoothly with the direction and the margin covers the directions between the
//! samples), or until the distorted radius exceeds twice the image's (the farthest pixel
//! centre's). The valid radius is the smallest over the directions. Points beyond it are
//! outside the camera's valid image: OpenCV's own undistortion is not defined there either.

use glam::{DMat2, DVec2};

/// The largest undistorted radius considered: tan(89.9 degrees). A pinhole's normalised
/// radius is the tangent of the angle off the axis, so this is not a limit in practice.
pub const RADIUS_CAP: f64 = 572.957_213_354_2;

/// Directions and radial steps of the search for the valid radius.
const DIRECTIONS: usize = 128;
const RADIAL_STEPS: usize = 1024;

/// The fraction of the smallest sampled crossing kept as the valid radius.
const VALID_FRACTION: f64 = 0.999;

/// Newton iterations and step halvings of [`RadialTangential::undistort`].
const NEWTON_ITERATIONS: usize = 40;
const HALVINGS: usize = 40;

/// The distorted-point residual (normalised units, relative to max(1, |q|)) below which the
/// inverse is accepted, and the residual or step below which Newton's method stops (a few
/// rounding errors: the iteration goes on past acceptance, which costs one step given its
/// quadratic convergence, so that ill-conditioned points near the valid radius are still
/// found to full precision).
const RESIDUAL: f64 = 1e-12;
const CONVERGED: f64 = 1e-15;

/// The slope of the distortion continued beyond the valid radius (see
/// [`RadialTangential::distort_continued`]).
const CONTINUATION_SLOPE: f64 = 1e-3;

/// The coefficients in OpenCV's order: k1, k2, p1, p2, k3, k4, k5, k6 (the 4- and
/// 5-coefficient forms have the rest zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadialTangential {
    k: [f64; 6],
    p: [f64; 2],
}

/// The distorted point and the Jacobian of the map there, with whether the map is valid
/// there (positive denominator, radial factor and Jacobian determinant).
struct Local {
    distorted: DVec2,
    jacobian: DMat2,
    valid: bool,
}

impl RadialTangential {
    /// From OpenCV's coefficient vector [k1, k2, p1, p2, k3, k4, k5, k6].
    pub fn new(coefficients: [f64; 8]) -> Self {
        let [k1, k2, p1, p2, k3, k4, k5, k6] = coefficients;
        RadialTangential {
            k: [k1, k2, k3, k4, k5, k6],
            p: [p1, p2],
        }
    }

    /// The distorted point of undistorted normalised point `p`.
    pub fn distort(&self, p: DVec2) -> DVec2 {
        self.local(p).distorted
    }

    fn local(&self, p: DVec2) -> Local {
        let [k1, k2, k3, k4, k5, k6] = self.k;
        let [p1, p2] = self.p;
        let (x, y) = (p.x, p.y);
        let s = x * x + y * y;
        let numerator = 1.0 + s * (k1 + s * (k2 + s * k3));
        let denominator = 1.0 + s * (k4 + s * (k5 + s * k6));
        let d_numerator = k1 + s * (2.0 * k2 + s * 3.0 * k3);
        let d_denominator = k4 + s * (2.0 * k5 + s * 3.0 * k6);
        let radial = numerator / denominator;
        // dR/ds
        let d_radial =
            (d_numerator * denominator - numerator * d_denominator) / (denominator * denominator);
        let distorted = DVec2::new(
            x * radial + 2.0 * p1 * x * y + p2 * (s + 2.0 * x * x),
            y * radial + p1 * (s + 2.0 * y * y) + 2.0 * p2 * x * y,
        );
        let cross = 2.0 * x * y * d_radial + 2.0 * p1 * x + 2.0 * p2 * y;
        let jacobian = DMat2::from_cols(
            DVec2::new(
                radial + 2.0 * x * x * d_radial + 2.0 * p1 * y + 6.0 * p2 * x,
                cross,
            ),
            DVec2::new(
                cross,
                radial + 2.0 * y * y * d_radial + 6.0 * p1 * y + 2.0 * p2 * x,
            ),
        );
        let valid = denominator > 0.0 && radial > 0.0 && jacobian.determinant() > 0.0;
        Local {
            distorted,
            jacobian,
            valid: valid && distorted.is_finite(),
        }
    }

    /// The valid radius (see the module documentation) for an image whose farthest pixel
    /// centre has distorted normalised radius `image_radius`: [`RADIUS_CAP`] where the map
    /// stays valid and inside twice that radius that far in every direction.
    pub fn valid_radius(&self, image_radius: f64) -> f64 {
        let exit = 2.0 * image_radius;
        let cap_angle = RADIUS_CAP.atan();
        let mut smallest = RADIUS_CAP;
        for d in 0..DIRECTIONS {
            let azimuth = std::f64::consts::TAU * d as f64 / DIRECTIONS as f64;
            let direction = DVec2::from_angle(azimuth);
            let valid = |r: f64| self.local(direction * r).valid;
            let mut inside = 0.0;
            for step in 1..=RADIAL_STEPS {
                let r = (cap_angle * step as f64 / RADIAL_STEPS as f64).tan();
                if r >= smallest {
                    break;
                }
                let local = self.local(direction * r);
                if local.valid && local.distorted.length() > exit {
                    smallest = r;
                    break;
                }
                if !local.valid {
                    let mut outside = r;
                    for _ in 0..60 {
                        let middle = 0.5 * (inside + outside);
                        if valid(middle) {
                            inside = middle;
                        } else {
                            outside = middle;
                        }
                    }
                    smallest = smallest.min(VALID_FRACTION * inside);
                    break;
                }
                inside = r;
            }
        }
        smallest
    }

    /// The largest distorted radius of a point on the circle of radius `valid_radius`,
    /// sampled as [`RadialTangential::valid_radius`] samples directions, with 1 % to spare: no
    /// valid point's distorted radius exceeds it.
    pub fn distorted_bound(&self, valid_radius: f64) -> f64 {
        (0..DIRECTIONS)
            .map(|d| {
                let azimuth = std::f64::consts::TAU * d as f64 / DIRECTIONS as f64;
                self.distort(DVec2::from_angle(azimuth) * valid_radius)
                    .length()
            })
            .fold(0.0, f64::max)
            * 1.01
    }

    /// The distortion continued beyond `valid_radius` so that it stays continuous and
    /// one-to-one: a point at radius r > valid_radius maps to the distorted point of its
    /// direction at the valid radius, moved out along that direction by
    /// [`CONTINUATION_SLOPE`] (r - valid_radius). The rasteriser projects triangle corners
    /// beyond the valid image with it, so a triangle reaching out of the valid image is cut
    /// by it instead of folding back into the image.
    pub fn distort_continued(&self, p: DVec2, valid_radius: f64) -> DVec2 {
        let r = p.length();
        if r <= valid_radius {
            return self.distort(p);
        }
        let direction = p / r;
        self.distort(direction * valid_radius)
            + direction * (CONTINUATION_SLOPE * (r - valid_radius))
    }

    /// The undistorted point within `valid_radius` whose distorted point is `q`, by Newton's
    /// method on the map with its Jacobian from `q` itself, each step halved until it stays
    /// inside the valid radius and reduces the residual. `None` where that fails: `q` is
    /// outside the image of the valid disc.
    pub fn undistort(&self, q: DVec2, valid_radius: f64) -> Option<DVec2> {
        let scale = q.length().max(1.0);
        let mut p = if q.length() < valid_radius {
            q
        } else {
            DVec2::ZERO
        };
        let mut local = self.local(p);
        let mut residual = local.distorted - q;
        for _ in 0..NEWTON_ITERATIONS {
            if residual.length() <= CONVERGED * scale || !local.valid {
                break;
            }
            let mut step = local.jacobian.inverse() * residual;
            if step.length() <= CONVERGED * scale {
                break;
            }
            let mut accepted = false;
            for _ in 0..HALVINGS {
                let candidate = p - step;
                if candidate.length() < valid_radius {
                    let next = self.local(candidate);
                    let next_residual = next.distorted - q;
                    if next_residual.length() < residual.length() {
                        p = candidate;
                        local = next;
                        residual = next_residual;
                        accepted = true;
                        break;
                    }
                }
                step *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        (residual.length() <= RESIDUAL * scale).then_some(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn barrel() -> RadialTangential {
        RadialTangential::new([-0.3, 0.08, 0.001, -0.0005, 0.0, 0.0, 0.0, 0.0])
    }

    #[test]
    fn zero_coefficients_are_the_identity() {
        let none = RadialTangential::new([0.0; 8]);
        let p = DVec2::new(0.3, -1.7);
        assert_eq!(none.distort(p), p);
        // It leaves twice the image radius (1 here) just beyond radius 2.
        let valid = none.valid_radius(1.0);
        assert!(valid > 2.0 && valid < 2.01, "{valid}");
        assert_eq!(none.undistort(p, valid), Some(p));
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let rational = RadialTangential::new([0.2, -0.05, 0.003, -0.002, 0.01, 0.1, -0.02, 0.005]);
        for model in [barrel(), rational] {
            for p in [DVec2::new(0.3, -0.2), DVec2::new(-0.6, 0.5)] {
                let h = 1e-6;
                let j = model.local(p).jacobian;
                let dx =
                    (model.distort(p + DVec2::X * h) - model.distort(p - DVec2::X * h)) / (2.0 * h);
                let dy =
                    (model.distort(p + DVec2::Y * h) - model.distort(p - DVec2::Y * h)) / (2.0 * h);
                assert!((j.x_axis - dx).length() < 1e-8, "{j} {dx}");
                assert!((j.y_axis - dy).length() < 1e-8, "{j} {dy}");
            }
        }
    }

    #[test]
    fn barrel_distortion_turns_back_at_the_valid_radius() {
        // Radially: d/dr (r (1 + k1 r^2 + k2 r^4)) = 1 + 3 k1 r^2 + 5 k2 r^4 = 0 at
        // r^2 = (1.5 - sqrt(2.25 - 1)) / 0.5 for k1 = -0.5, k2 = 0.05.
        let radial = RadialTangential::new([-0.5, 0.05, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let turn = ((1.5 - 1.25f64.sqrt()) / 0.5).sqrt();
        let valid = radial.valid_radius(1.0);
        assert!(
            (valid - VALID_FRACTION * turn).abs() < 1e-9,
            "{valid} vs {turn}"
        );
        // Inside, undistortion inverts; outside, the image of the valid disc is left.
        let p = DVec2::new(0.7, -0.5) * (0.9 * valid / DVec2::new(0.7, -0.5).length());
        let q = radial.distort(p);
        assert!((radial.undistort(q, valid).unwrap() - p).length() < 1e-13);
        let beyond = radial.distort(DVec2::new(turn, 0.0)) * 1.001;
        assert_eq!(radial.undistort(beyond, valid), None);
    }

    #[test]
    fn continuation_is_continuous_and_moves_out() {
        let model = barrel();
        let valid = model.valid_radius(1.0);
        let direction = DVec2::new(0.6, 0.8);
        let at = model.distort_continued(direction * valid, valid);
        let just = model.distort_continued(direction * (valid + 1e-9), valid);
        assert!((at - just).length() < 1e-9);
        let far = model.distort_continued(direction * (valid + 10.0), valid);
        assert!((far - at).dot(direction) > 0.0);
    }
}
