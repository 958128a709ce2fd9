//! `type = "opencv"`: a pinhole camera with OpenCV's radial-tangential distortion, as
//! `cv::projectPoints` images points and `cv::undistortPoints` inverts it (see
//! [`RadialTangential`] for the map and the valid radius).

use glam::{DVec2, DVec3};

use super::calibrated::{BoundCamera, CalibratedCamera};
use super::chart::{InverseChart, EYE_CLEARANCE};
use super::linear::in_front;
use super::radial_tangential::RadialTangential;
use super::{
    AnalyticInverse, BranchImage, ImagePoint, NoInverse, Projection, SingleImage, Trilinear,
};
use crate::error::{Error, Result};
use crate::geometry::Ray;

/// A point with OpenCV camera coordinates (X, Y, Z), Z > 0, is imaged at the pixel of the
/// distorted normalised point of (X / Z, Y / Z). Pixels whose undistorted point would lie
/// beyond the valid radius see nothing. Ray directions are unit length, so `t` is the
/// distance from the eye.
#[derive(Debug, Clone, PartialEq)]
pub struct Opencv {
    camera: BoundCamera,
    distortion: RadialTangential,
    /// The undistorted normalised radius up to which the distortion is invertible.
    valid_radius: f64,
    /// No point within the valid radius has a larger distorted normalised radius.
    distorted_bound: f64,
}

impl Opencv {
    /// `distortion` in OpenCV's order [k1, k2, p1, p2, k3, k4, k5, k6]. Errors: those of
    /// `BoundCamera::new`, a non-finite coefficient.
    pub fn new(
        camera: &CalibratedCamera,
        distortion: [f64; 8],
        width: u32,
        height: u32,
    ) -> Result<Self> {
        if let Some(bad) = distortion.iter().find(|c| !c.is_finite()) {
            return Err(Error::new(format!(
                "opencv distortion coefficients must be finite, got {bad}"
            )));
        }
        let camera = BoundCamera::new("opencv", camera, width, height)?;
        let distortion = RadialTangential::new(distortion);
        let valid_radius = distortion.valid_radius(camera.widest_normalised_radius());
        Ok(Opencv {
            camera,
            distortion,
            valid_radius,
            distorted_bound: distortion.distorted_bound(valid_radius),
        })
    }

    /// The undistorted normalised radius beyond which the camera sees nothing (see
    /// `RadialTangential`).
    pub fn valid_radius(&self) -> f64 {
        self.valid_radius
    }
}

impl Projection for Opencv {
    fn kind(&self) -> &'static str {
        "opencv"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.camera.resolution.width, self.camera.resolution.height)
    }

    /// `None` where undistortion finds no point within the valid radius.
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let q = self.camera.normalised(pixel);
        if q.length() > self.distorted_bound {
            return None;
        }
        let p = self.distortion.undistort(q, self.valid_radius)?;
        let direction = self.camera.to_world(DVec3::new(p.x, p.y, 1.0)).normalize();
        Some(Ray::new(self.camera.basis.origin, direction))
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// The one image of a point, `t` its distance from the eye; beyond the valid radius the
/// branch continues by `RadialTangential::distort_continued`, where the camera does not
/// see. Degenerate: a point on or behind the plane through the eye has no image.
impl SingleImage for Opencv {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let offset = point - self.camera.basis.origin;
        let local = self.camera.to_opencv(offset);
        if local.z <= 0.0 {
            return None;
        }
        let p = DVec2::new(local.x, local.y) / local.z;
        let q = self.distortion.distort_continued(p, self.valid_radius);
        Some(BranchImage {
            image: ImagePoint {
                pixel: self.camera.pixel(q),
                t: offset.length(),
            },
            seen: p.length() < self.valid_radius,
        })
    }

    /// Triangles are clipped [`EYE_CLEARANCE`] in front of the eye plane, as for a pinhole.
    fn chart(&self) -> InverseChart {
        InverseChart {
            clip: vec![in_front(&self.camera.basis, EYE_CLEARANCE)],
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
                position: DVec3::new(0.0, 1.0, 0.0),
                look_at: DVec3::new(0.0, 1.0, -1.0),
                up: DVec3::Y,
            },
            intrinsics: Intrinsics {
                fx: 300.0,
                fy: 310.0,
                cx: 159.5,
                cy: 119.5,
            },
            size: CalibrationSize::SceneImage([320, 240]),
        }
    }

    #[test]
    fn undistorted_centre_looks_forward_and_y_is_down() {
        let cam = Opencv::new(&camera(), [0.0; 8], 320, 240).unwrap();
        let centre = cam.ray(DVec2::new(160.0, 120.0)).unwrap();
        assert_eq!(centre.direction, DVec3::NEG_Z);
        // One focal length below the centre (OpenCV y down): 45 degrees down.
        let below = cam.ray(DVec2::new(160.0, 120.0 + 310.0)).unwrap();
        let expected = DVec3::new(0.0, -1.0, -1.0).normalize();
        assert!((below.direction - expected).length() < 1e-15);
    }

    #[test]
    fn strong_barrel_corners_see_nothing() {
        // k1 = -0.5: r (1 - 0.5 r^2) turns back at r = sqrt(2/3), distorted radius 0.544;
        // the image corners are at normalised radius ~0.66.
        let cam = Opencv::new(
            &camera(),
            [-0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            320,
            240,
        )
        .unwrap();
        assert!((cam.valid_radius() - 0.999 * (2.0f64 / 3.0).sqrt()).abs() < 1e-9);
        assert!(cam.ray(DVec2::new(0.5, 0.5)).is_none());
        assert!(cam.ray(DVec2::new(160.0, 120.0)).is_some());
        // A point far off the axis is on the continued branch but not seen.
        let mut out = Vec::new();
        cam.project(DVec3::new(3.0, 1.0, -1.0), &mut out);
        assert!(out.is_empty());
        assert!(cam
            .branch_image(DVec3::new(3.0, 1.0, -1.0))
            .is_some_and(|b| !b.seen));
    }

    #[test]
    fn non_finite_coefficients_are_errors() {
        let e = Opencv::new(
            &camera(),
            [0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            320,
            240,
        )
        .unwrap_err();
        assert_eq!(
            e.message,
            "opencv distortion coefficients must be finite, got NaN"
        );
    }
}
