//! What the calibrated lens models (`opencv`, `opencv_fisheye`) share: OpenCV's camera frame
//! and pixel conventions, the intrinsic matrix, and its scaling from the calibration's image
//! size to the rendered one.
//!
//! OpenCV's camera frame has x right, y down and z along the view direction; flexcam's
//! [`CameraBasis`] has y up, so the two differ by the sign of y. OpenCV puts pixel centres at
//! integer coordinates ((0, 0) is the centre of the top-left pixel), flexcam at +0.5, so an
//! OpenCV coordinate u is the flexcam position u + 0.5. A calibration made at W0 x H0 pixels
//! and used at W x H scales the pixel edges (not the centres) by W / W0 and H / H0:
//! fx' = fx W / W0 and cx' + 0.5 = (cx + 0.5) W / W0, and likewise in y.

use glam::{DVec2, DVec3};

use super::camera_basis::CameraBasis;
use super::image_coords::Resolution;
use super::CameraFrame;
use crate::error::{Error, Result};

/// The intrinsic parameters of a calibration, in the calibration's pixels and OpenCV's pixel
/// convention: a normalised image point (x, y) (x right, y down, at distance 1 along the
/// view) is at pixel (fx x + cx, fy y + cy).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    /// Focal length in x, calibration pixels.
    pub fx: f64,
    /// Focal length in y, calibration pixels.
    pub fy: f64,
    /// Principal point x, calibration pixels, OpenCV's convention (0 = the centre of the left
    /// column).
    pub cx: f64,
    /// Principal point y, calibration pixels, OpenCV's convention (0 = the centre of the top row).
    pub cy: f64,
}

/// The image size a calibration was made for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CalibrationSize {
    /// Given by `calibration_size = [w, h]`: the intrinsics scale to any rendered size.
    Given([u32; 2]),
    /// Not given: the calibration is for the scene's own image size, and rendering at
    /// another size is refused (a calibration does not say how it would scale).
    SceneImage([u32; 2]),
}

/// A calibrated camera: placement, intrinsics and the calibration's image size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CalibratedCamera {
    /// Eye, view direction (OpenCV's z) and up (OpenCV's -y).
    pub frame: CameraFrame,
    /// Focal lengths and principal point, in the calibration's pixels.
    pub intrinsics: Intrinsics,
    /// The image size the intrinsics are for, and whether they may scale.
    pub size: CalibrationSize,
}

/// A calibrated camera bound to an image: the basis, and the intrinsics scaled to the image
/// in flexcam's pixel convention (pixel centres at +0.5).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BoundCamera {
    pub basis: CameraBasis,
    pub resolution: Resolution,
    /// Focal lengths in the rendered image's pixels.
    focal: DVec2,
    /// The principal point in flexcam pixel positions (OpenCV's cx + 0.5, scaled).
    centre: DVec2,
}

impl BoundCamera {
    /// Binds `camera` to a `width` x `height` image. Errors (naming projection `kind`): an
    /// empty image, a degenerate frame, a non-finite intrinsic, a focal length that is not
    /// positive, an empty calibration size, and a rendered size that differs from the scene's
    /// own when no `calibration_size` is given.
    pub fn new(kind: &str, camera: &CalibratedCamera, width: u32, height: u32) -> Result<Self> {
        let resolution = Resolution::new(width, height)?;
        let Intrinsics { fx, fy, cx, cy } = camera.intrinsics;
        for (name, value) in [("fx", fx), ("fy", fy), ("cx", cx), ("cy", cy)] {
            if !value.is_finite() {
                return Err(Error::new(format!(
                    "{kind} {name} must be finite, got {value}"
                )));
            }
        }
        for (name, value) in [("fx", fx), ("fy", fy)] {
            if value <= 0.0 {
                return Err(Error::new(format!(
                    "{kind} {name} must be a positive focal length in pixels, got {value}"
                )));
            }
        }
        let scale = match camera.size {
            CalibrationSize::Given([w, h]) => {
                if w == 0 || h == 0 {
                    return Err(Error::new(format!(
                        "{kind} calibration_size [{w}, {h}] is empty: both sides must be at least 1"
                    )));
                }
                resolution.size() / DVec2::new(f64::from(w), f64::from(h))
            }
            CalibrationSize::SceneImage([w, h]) => {
                if [w, h] != [width, height] {
                    return Err(Error::new(format!(
                        "{kind} fx, fy, cx, cy are for the scene's {w}x{h} image, not {width}x{height}: \
                         give `calibration_size = [{w}, {h}]` to scale them"
                    )));
                }
                DVec2::ONE
            }
        };
        Ok(BoundCamera {
            basis: CameraBasis::new(&camera.frame)?,
            resolution,
            focal: DVec2::new(fx, fy) * scale,
            centre: (DVec2::new(cx, cy) + 0.5) * scale,
        })
    }

    /// The normalised (distorted) image point of flexcam pixel position `pixel`.
    pub fn normalised(&self, pixel: DVec2) -> DVec2 {
        (pixel - self.centre) / self.focal
    }

    /// The flexcam pixel position of normalised (distorted) image point `normalised`.
    pub fn pixel(&self, normalised: DVec2) -> DVec2 {
        normalised * self.focal + self.centre
    }

    /// The world direction of OpenCV camera-frame vector `opencv` (x right, y down, z
    /// forward).
    pub fn to_world(&self, opencv: DVec3) -> DVec3 {
        self.basis
            .to_world(DVec3::new(opencv.x, -opencv.y, opencv.z))
    }

    /// The OpenCV camera-frame components of the world vector `world`.
    pub fn to_opencv(&self, world: DVec3) -> DVec3 {
        let local = self.basis.to_local(world);
        DVec3::new(local.x, -local.y, local.z)
    }

    /// The largest normalised radius of a pixel centre: the radius of the image corner
    /// centre farthest from the principal point.
    pub fn widest_normalised_radius(&self) -> f64 {
        let last = self.resolution.size() - 0.5;
        [
            DVec2::splat(0.5),
            DVec2::new(last.x, 0.5),
            DVec2::new(0.5, last.y),
            last,
        ]
        .into_iter()
        .map(|corner| self.normalised(corner).length())
        .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(size: CalibrationSize) -> CalibratedCamera {
        CalibratedCamera {
            frame: CameraFrame {
                position: DVec3::ZERO,
                look_at: DVec3::NEG_Z,
                up: DVec3::Y,
            },
            intrinsics: Intrinsics {
                fx: 500.0,
                fy: 400.0,
                cx: 319.5,
                cy: 239.5,
            },
            size,
        }
    }

    #[test]
    fn opencv_pixel_centres_are_at_integers() {
        let bound = BoundCamera::new(
            "opencv",
            &camera(CalibrationSize::SceneImage([640, 480])),
            640,
            480,
        )
        .unwrap();
        // OpenCV pixel (cx, cy) = (319.5, 239.5) is flexcam position (320, 240), the centre.
        assert_eq!(bound.normalised(DVec2::new(320.0, 240.0)), DVec2::ZERO);
        // OpenCV pixel (0, 0), the top-left centre, is flexcam (0.5, 0.5).
        let n = bound.normalised(DVec2::splat(0.5));
        assert_eq!(n, DVec2::new(-319.5 / 500.0, -239.5 / 400.0));
        assert_eq!(bound.pixel(n), DVec2::splat(0.5));
        // y down in OpenCV is down in the world image: -up.
        assert_eq!(bound.to_world(DVec3::Y), DVec3::NEG_Y);
        assert_eq!(bound.to_opencv(DVec3::NEG_Y), DVec3::Y);
    }

    #[test]
    fn scaling_keeps_the_pixel_edges() {
        let half = BoundCamera::new(
            "opencv",
            &camera(CalibrationSize::Given([640, 480])),
            320,
            240,
        )
        .unwrap();
        // The image centre stays the image centre; focal lengths halve.
        assert_eq!(half.normalised(DVec2::new(160.0, 120.0)), DVec2::ZERO);
        assert_eq!(half.focal, DVec2::new(250.0, 200.0));
    }

    #[test]
    fn another_size_needs_calibration_size() {
        let e = BoundCamera::new(
            "opencv",
            &camera(CalibrationSize::SceneImage([640, 480])),
            320,
            240,
        )
        .unwrap_err();
        assert_eq!(
            e.message,
            "opencv fx, fy, cx, cy are for the scene's 640x480 image, not 320x240: give \
             `calibration_size = [640, 480]` to scale them"
        );
        let mut bad = camera(CalibrationSize::Given([640, 480]));
        bad.intrinsics.fy = 0.0;
        let e = BoundCamera::new("opencv", &bad, 640, 480).unwrap_err();
        assert!(
            e.message
                .starts_with("opencv fy must be a positive focal length"),
            "{e}"
        );
        let e = BoundCamera::new(
            "opencv",
            &camera(CalibrationSize::Given([0, 480])),
            640,
            480,
        )
        .unwrap_err();
        assert!(
            e.message.contains("calibration_size [0, 480] is empty"),
            "{e}"
        );
    }
}
