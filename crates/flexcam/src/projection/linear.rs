//! The linear projections: perspective (pinhole) and orthographic (parallel rays).
//!
//! Both map the image linearly onto a plane perpendicular to the view direction with square
//! pixels; they differ in where the rays start. Rays exist for every pixel position, also
//! outside the image, and the inverses return positions outside the image unclipped.

use glam::{DVec2, DVec3};

use super::camera_basis::CameraBasis;
use super::chart::{HalfSpace, InverseChart, EYE_CLEARANCE};
use super::image_coords::Resolution;
use super::params::{angle_radians, positive_length, UpTo};
use super::{
    AnalyticInverse, BranchImage, CameraFrame, ImagePoint, NoInverse, Projection, SingleImage,
    Trilinear,
};
use crate::error::Result;
use crate::geometry::Ray;

/// A pinhole camera at the frame's position; `fov` is the horizontal angle, the vertical one
/// follows from the aspect ratio. Ray directions are unit length, so `t` is the distance.
#[derive(Debug, Clone, PartialEq)]
pub struct Perspective {
    basis: CameraBasis,
    /// Image-plane extent of one pixel at distance 1 from the eye.
    pixel_size: f64,
    resolution: Resolution,
}

impl Perspective {
    /// Errors: a degenerate frame, an empty image, `fov_degrees` not in (0, 180).
    pub fn new(frame: &CameraFrame, fov_degrees: f64, width: u32, height: u32) -> Result<Self> {
        let fov = angle_radians("perspective", "fov", fov_degrees, UpTo::Below(180.0))?;
        let resolution = Resolution::new(width, height)?;
        Ok(Perspective {
            basis: CameraBasis::new(frame)?,
            pixel_size: 2.0 * (0.5 * fov).tan() / f64::from(width),
            resolution,
        })
    }

    /// The camera basis (eye and orientation).
    pub fn basis(&self) -> &CameraBasis {
        &self.basis
    }
}

impl Projection for Perspective {
    fn kind(&self) -> &'static str {
        "perspective"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let c = self.resolution.centred(pixel) * self.pixel_size;
        let direction = self.basis.to_world(DVec3::new(c.x, c.y, 1.0)).normalize();
        Some(Ray::new(self.basis.origin, direction))
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// The one image of a point, `t` its distance from the eye. Degenerate: a point on or behind
/// the plane through the eye perpendicular to the view direction (the eye itself included)
/// has no image.
impl SingleImage for Perspective {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let offset = point - self.basis.origin;
        let local = self.basis.to_local(offset);
        if local.z <= 0.0 {
            return None;
        }
        let centred = DVec2::new(local.x, local.y) / (local.z * self.pixel_size);
        let image = ImagePoint {
            pixel: self.resolution.pixel(centred),
            t: offset.length(),
        };
        Some(BranchImage { image, seen: true })
    }

    /// Triangles are clipped [`EYE_CLEARANCE`] in front of the eye plane.
    fn chart(&self) -> InverseChart {
        InverseChart {
            clip: vec![in_front(&self.basis, EYE_CLEARANCE)],
            ..InverseChart::default()
        }
    }
}

/// The points at least `distance` in front of the plane through the eye perpendicular to
/// the view direction.
pub(super) fn in_front(basis: &CameraBasis, distance: f64) -> HalfSpace {
    HalfSpace {
        normal: basis.forward,
        offset: basis.forward.dot(basis.origin) + distance,
    }
}

/// Parallel rays along the view direction, starting on the plane through the frame's
/// position perpendicular to it; `width` is the horizontal world extent, the height follows
/// from the aspect ratio. Directions are unit length, so `t` is the distance from that plane.
#[derive(Debug, Clone, PartialEq)]
pub struct Orthographic {
    basis: CameraBasis,
    /// World extent of one pixel.
    pixel_size: f64,
    resolution: Resolution,
}

impl Orthographic {
    /// Errors: a degenerate frame, an empty image, `width` not positive and finite.
    pub fn new(
        frame: &CameraFrame,
        width: f64,
        image_width: u32,
        image_height: u32,
    ) -> Result<Self> {
        let width = positive_length("orthographic", "width", width)?;
        let resolution = Resolution::new(image_width, image_height)?;
        Ok(Orthographic {
            basis: CameraBasis::new(frame)?,
            pixel_size: width / f64::from(image_width),
            resolution,
        })
    }

    /// The camera basis (centre of the view plane and orientation).
    pub fn basis(&self) -> &CameraBasis {
        &self.basis
    }
}

impl Projection for Orthographic {
    fn kind(&self) -> &'static str {
        "orthographic"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let c = self.resolution.centred(pixel) * self.pixel_size;
        let origin = self.basis.origin + self.basis.to_world(DVec3::new(c.x, c.y, 0.0));
        Some(Ray::new(origin, self.basis.forward))
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// The one image of a point, `t` its distance from the view plane; the branch extends behind
/// the plane (negative `t`), where the projection does not see (rays start at `t = 0`). A
/// point on the plane has `t = 0`.
impl SingleImage for Orthographic {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let local = self.basis.to_local(point - self.basis.origin);
        let centred = DVec2::new(local.x, local.y) / self.pixel_size;
        let image = ImagePoint {
            pixel: self.resolution.pixel(centred),
            t: local.z,
        };
        Some(BranchImage {
            image,
            seen: image.t >= 0.0,
        })
    }

    /// The map is linear everywhere: no clip, no wrap, no pole.
    fn chart(&self) -> InverseChart {
        InverseChart::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> CameraFrame {
        CameraFrame {
            position: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
        }
    }

    #[test]
    fn perspective_centre_looks_forward_and_edges_at_half_fov() {
        let p = Perspective::new(&frame(), 90.0, 200, 100).unwrap();
        let centre = p.ray(DVec2::new(100.0, 50.0)).unwrap();
        assert_eq!(centre.origin, DVec3::new(0.0, 1.0, 5.0));
        assert!((centre.direction - DVec3::NEG_Z).length() < 1e-15);
        // Right edge, centre row: 45 degrees to the right (+x).
        let right = p.ray(DVec2::new(200.0, 50.0)).unwrap().direction;
        assert!((right - DVec3::new(1.0, 0.0, -1.0).normalize()).length() < 1e-15);
        // Top edge, centre column: square pixels, so tan(vertical half angle) = 0.5.
        let top = p.ray(DVec2::new(100.0, 0.0)).unwrap().direction;
        assert!((top - DVec3::new(0.0, 0.5, -1.0).normalize()).length() < 1e-15);
    }

    #[test]
    fn perspective_points_on_or_behind_the_eye_plane_have_no_image() {
        let p = Perspective::new(&frame(), 60.0, 64, 48).unwrap();
        let mut out = Vec::new();
        p.project(DVec3::new(0.0, 1.0, 5.0), &mut out); // the eye
        p.project(DVec3::new(3.0, 2.0, 5.0), &mut out); // on the eye plane
        p.project(DVec3::new(0.0, 1.0, 6.0), &mut out); // behind
        assert!(out.is_empty());
        p.project(DVec3::new(0.0, 1.0, 2.0), &mut out);
        assert_eq!(
            out,
            vec![ImagePoint {
                pixel: DVec2::new(32.0, 24.0),
                t: 3.0
            }]
        );
    }

    #[test]
    fn perspective_projects_outside_the_image_unclipped() {
        let p = Perspective::new(&frame(), 90.0, 100, 100).unwrap();
        let mut out = Vec::new();
        p.project(DVec3::new(10.0, 1.0, 4.0), &mut out); // far right, 84 degrees off
        assert_eq!(out.len(), 1);
        assert!(out[0].pixel.x > 100.0);
    }

    #[test]
    fn orthographic_rays_are_parallel_on_the_view_plane() {
        let o = Orthographic::new(&frame(), 4.0, 200, 100).unwrap();
        let corner = o.ray(DVec2::ZERO).unwrap();
        assert_eq!(corner.direction, DVec3::NEG_Z);
        assert!((corner.origin - DVec3::new(-2.0, 2.0, 5.0)).length() < 1e-15);
        let mut out = Vec::new();
        o.project(DVec3::new(-2.0, 2.0, 1.0), &mut out);
        assert_eq!(
            out,
            vec![ImagePoint {
                pixel: DVec2::ZERO,
                t: 4.0
            }]
        );
    }

    #[test]
    fn orthographic_points_behind_the_view_plane_have_no_image() {
        let o = Orthographic::new(&frame(), 4.0, 20, 10).unwrap();
        let mut out = Vec::new();
        o.project(DVec3::new(0.0, 1.0, 5.5), &mut out);
        assert!(out.is_empty());
        o.project(DVec3::new(0.5, 1.0, 5.0), &mut out); // on the plane: t = 0
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].t, 0.0);
    }

    #[test]
    fn invalid_parameters_are_errors() {
        for fov in [0.0, 180.0, -10.0, f64::NAN] {
            let e = Perspective::new(&frame(), fov, 10, 10).unwrap_err();
            assert!(
                e.message.starts_with("perspective fov must be in (0, 180)"),
                "{e}"
            );
        }
        for width in [0.0, -1.0, f64::INFINITY] {
            let e = Orthographic::new(&frame(), width, 10, 10).unwrap_err();
            assert!(e.message.starts_with("orthographic width"), "{e}");
        }
        assert!(Perspective::new(&frame(), 60.0, 0, 10).is_err());
        assert!(Orthographic::new(&frame(), 1.0, 10, 0).is_err());
    }
}
