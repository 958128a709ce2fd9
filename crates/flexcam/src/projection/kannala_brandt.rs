//! `type = "opencv_fisheye"`: the Kannala-Brandt fisheye model (Kannala and Brandt 2006) as
//! OpenCV's `cv::fisheye` module writes it, with the angle measured from the optical axis so
//! that fields wider than 180 degrees work.
//!
//! A point at angle theta from the axis (z), in the azimuth of its (x, y) components, is
//! imaged at normalised radius theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 +
//! k4 theta^8) in that azimuth (OpenCV computes theta as atan(r), which is the same angle in
//! front of the camera and cannot reach 90 degrees). The model is one-to-one while theta_d
//! grows: the *monotone range* is [0, theta_max], theta_max the first zero of
//! d theta_d / d theta in (0, pi] (found by 4096 samples and bisection), or pi. Points beyond
//! theta_max are outside the valid image. The inverse solves the odd polynomial for theta by
//! Newton's method kept inside a bracket that shrinks with every step (bisection where a
//! step would leave it).

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::calibrated::{BoundCamera, CalibratedCamera};
use super::chart::{InverseChart, Pole};
use super::monotone_root::solve_increasing;
use super::{
    AnalyticInverse, BranchImage, ImagePoint, NoInverse, Projection, SingleImage, Trilinear,
};
use crate::error::{Error, Result};
use crate::geometry::Ray;

/// Samples of the search for the end of the monotone range.
const MONOTONE_SAMPLES: usize = 4096;

/// The slope of theta_d continued beyond theta_max (see [`KannalaBrandt::radius_continued`]).
const CONTINUATION_SLOPE: f64 = 1e-3;

/// The Kannala-Brandt fisheye bound to an image. Ray directions are unit length, so `t` is
/// the distance from the eye.
#[derive(Debug, Clone, PartialEq)]
pub struct KannalaBrandt {
    camera: BoundCamera,
    k: [f64; 4],
    /// The end of the monotone range, radians.
    theta_max: f64,
    /// theta_d at `theta_max`: the normalised radius of the valid image's edge.
    radius_max: f64,
}

impl KannalaBrandt {
    /// `k` = [k1, k2, k3, k4]. Errors: those of `BoundCamera::new`, a non-finite
    /// coefficient.
    pub fn new(camera: &CalibratedCamera, k: [f64; 4], width: u32, height: u32) -> Result<Self> {
        if let Some(bad) = k.iter().find(|c| !c.is_finite()) {
            return Err(Error::new(format!(
                "opencv_fisheye k coefficients must be finite, got {bad}"
            )));
        }
        let camera = BoundCamera::new("opencv_fisheye", camera, width, height)?;
        let mut model = KannalaBrandt {
            camera,
            k,
            theta_max: PI,
            radius_max: 0.0,
        };
        model.theta_max = model.monotone_end();
        model.radius_max = model.radius(model.theta_max);
        Ok(model)
    }

    /// The end of the monotone range (radians).
    pub fn theta_max(&self) -> f64 {
        self.theta_max
    }

    /// theta_d of `theta`.
    fn radius(&self, theta: f64) -> f64 {
        let [k1, k2, k3, k4] = self.k;
        let t2 = theta * theta;
        theta * (1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
    }

    /// d theta_d / d theta.
    fn slope(&self, theta: f64) -> f64 {
        let [k1, k2, k3, k4] = self.k;
        let t2 = theta * theta;
        1.0 + t2 * (3.0 * k1 + t2 * (5.0 * k2 + t2 * (7.0 * k3 + t2 * 9.0 * k4)))
    }

    /// The first theta in (0, pi] where the slope is no longer positive, or pi.
    fn monotone_end(&self) -> f64 {
        let mut inside = 0.0;
        for step in 1..=MONOTONE_SAMPLES {
            let theta = PI * step as f64 / MONOTONE_SAMPLES as f64;
            if self.slope(theta) <= 0.0 {
                let mut outside = theta;
                for _ in 0..60 {
                    let middle = 0.5 * (inside + outside);
                    if self.slope(middle) > 0.0 {
                        inside = middle;
                    } else {
                        outside = middle;
                    }
                }
                return inside;
            }
            inside = theta;
        }
        PI
    }

    /// theta_d continued beyond theta_max with a small positive slope, so that the branch
    /// stays continuous and one-to-one for the rasteriser.
    fn radius_continued(&self, theta: f64) -> f64 {
        if theta <= self.theta_max {
            self.radius(theta)
        } else {
            self.radius_max + CONTINUATION_SLOPE * (theta - self.theta_max)
        }
    }

    /// The theta in [0, theta_max] with theta_d = `radius`, `None` beyond `radius_max`.
    fn theta(&self, radius: f64) -> Option<f64> {
        if radius > self.radius_max {
            return None;
        }
        Some(solve_increasing(
            |theta| self.radius(theta),
            |theta| self.slope(theta),
            radius,
            (0.0, self.theta_max),
            radius.min(self.theta_max),
        ))
    }
}

impl Projection for KannalaBrandt {
    fn kind(&self) -> &'static str {
        "opencv_fisheye"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.camera.resolution.width, self.camera.resolution.height)
    }

    /// `None` beyond the valid image's edge (normalised radius above theta_d(theta_max)).
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let q = self.camera.normalised(pixel);
        let radius = q.length();
        let theta = self.theta(radius)?;
        let lateral = if radius > 0.0 {
            q * (theta.sin() / radius)
        } else {
            DVec2::ZERO
        };
        let direction = self
            .camera
            .to_world(DVec3::new(lateral.x, lateral.y, theta.cos()));
        Some(Ray::new(self.camera.basis.origin, direction))
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// The one image of a point, `t` its distance from the eye. Degenerate: the eye and the axis
/// behind it have no image.
impl SingleImage for KannalaBrandt {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let offset = point - self.camera.basis.origin;
        let local = self.camera.to_opencv(offset);
        let lateral = DVec2::new(local.x, local.y);
        let lateral_length = lateral.length();
        if lateral_length == 0.0 && local.z <= 0.0 {
            return None;
        }
        let theta = lateral_length.atan2(local.z);
        let q = if lateral_length > 0.0 {
            lateral * (self.radius_continued(theta) / lateral_length)
        } else {
            DVec2::ZERO
        };
        Some(BranchImage {
            image: ImagePoint {
                pixel: self.camera.pixel(q),
                t: offset.length(),
            },
            seen: theta <= self.theta_max,
        })
    }

    /// The axis behind the eye is a pole; its clearance is pi less the widest pixel centre's
    /// angle (the centre farthest from the principal point, within the valid image).
    fn chart(&self) -> InverseChart {
        let widest = self.camera.widest_normalised_radius().min(self.radius_max);
        let widest_angle = self.theta(widest).unwrap_or(self.theta_max);
        InverseChart {
            poles: vec![Pole {
                origin: self.camera.basis.origin,
                direction: -self.camera.basis.forward,
                clearance: PI - widest_angle,
            }],
            ..InverseChart::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::{CalibrationSize, CameraFrame, Intrinsics};

    fn camera() -> CalibratedCamera {
        CalibratedCamera {
            frame: CameraFrame {
                position: DVec3::ZERO,
                look_at: DVec3::NEG_Z,
                up: DVec3::Y,
            },
            intrinsics: Intrinsics {
                fx: 100.0,
                fy: 100.0,
                cx: 199.5,
                cy: 199.5,
            },
            size: CalibrationSize::SceneImage([400, 400]),
        }
    }

    #[test]
    fn equidistant_without_coefficients_sees_behind() {
        let cam = KannalaBrandt::new(&camera(), [0.0; 4], 400, 400).unwrap();
        assert_eq!(cam.theta_max(), PI);
        // 100 px right of the centre: theta = 1 radian, to the right.
        let d = cam.ray(DVec2::new(300.0, 200.0)).unwrap().direction;
        assert!((d - DVec3::new(1f64.sin(), 0.0, -1f64.cos())).length() < 1e-15);
        // pi * 100 px below: straight behind; beyond it nothing.
        let d = cam
            .ray(DVec2::new(200.0, 200.0 + 0.99 * PI * 100.0))
            .unwrap()
            .direction;
        assert!(d.z > 0.99 && d.y < 0.0, "{d}");
        assert!(cam
            .ray(DVec2::new(200.0, 200.0 + 1.01 * PI * 100.0))
            .is_none());
    }

    #[test]
    fn turning_polynomial_limits_the_range() {
        // theta (1 - 0.1 theta^2): slope 1 - 0.3 theta^2 vanishes at theta = sqrt(1/0.3).
        let cam = KannalaBrandt::new(&camera(), [-0.1, 0.0, 0.0, 0.0], 400, 400).unwrap();
        let end = (1.0f64 / 0.3).sqrt();
        assert!((cam.theta_max() - end).abs() < 1e-12);
        let radius = cam.radius(end);
        assert!(cam.theta(radius * 1.0001).is_none());
        let theta = cam.theta(0.5 * radius).unwrap();
        assert!((cam.radius(theta) - 0.5 * radius).abs() < 1e-15);
        // A point beyond the range is on the continued branch, not seen.
        let b = cam.branch_image(DVec3::new(0.0, 1.0, 1.0)).unwrap();
        assert!(!b.seen);
    }

    #[test]
    fn non_finite_coefficients_are_errors() {
        let e =
            KannalaBrandt::new(&camera(), [0.0, f64::INFINITY, 0.0, 0.0], 400, 400).unwrap_err();
        assert_eq!(
            e.message,
            "opencv_fisheye k coefficients must be finite, got inf"
        );
    }
}
