//! The angular (equidistant) fisheye: the angle off the view axis grows linearly with the
//! distance from the image centre.

use glam::{DVec2, DVec3};

use super::camera_basis::CameraBasis;
use super::chart::{InverseChart, Pole};
use super::image_coords::Resolution;
use super::params::{angle_radians, UpTo};
use super::{
    AnalyticInverse, BranchImage, CameraFrame, ImagePoint, NoInverse, Projection, SingleImage,
    Trilinear,
};
use crate::error::Result;
use crate::geometry::Ray;

/// A pixel at normalised radius r from the image centre (r = 1 on the circle inscribed in the
/// shorter image side) looks r * fov/2 off the view axis, in the direction of its azimuth
/// (right in the image is right in the world, up is up). `fov` may reach 360 degrees. Pixels
/// outside the image circle see nothing. Ray directions are unit length.
#[derive(Debug, Clone, PartialEq)]
pub struct Fisheye {
    basis: CameraBasis,
    half_fov: f64,
    /// Radius of the image circle in pixels.
    circle_radius: f64,
    resolution: Resolution,
}

impl Fisheye {
    /// Errors: a degenerate frame, an empty image, `fov_degrees` not in (0, 360].
    pub fn new(frame: &CameraFrame, fov_degrees: f64, width: u32, height: u32) -> Result<Self> {
        let fov = angle_radians("fisheye", "fov", fov_degrees, UpTo::Including(360.0))?;
        let resolution = Resolution::new(width, height)?;
        Ok(Fisheye {
            basis: CameraBasis::new(frame)?,
            half_fov: 0.5 * fov,
            circle_radius: 0.5 * f64::from(width.min(height)),
            resolution,
        })
    }
}

impl Projection for Fisheye {
    fn kind(&self) -> &'static str {
        "fisheye"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    /// `None` outside the image circle (normalised radius > 1).
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let centred = self.resolution.centred(pixel);
        let radius = centred.length();
        let r = radius / self.circle_radius;
        if r > 1.0 {
            return None;
        }
        let off_axis = r * self.half_fov;
        // At the centre the azimuth is undefined and irrelevant: sin(0) = 0.
        let azimuth = if radius > 0.0 {
            centred / radius
        } else {
            DVec2::ZERO
        };
        let lateral = off_axis.sin() * azimuth;
        let local = DVec3::new(lateral.x, lateral.y, off_axis.cos());
        Some(Ray::new(self.basis.origin, self.basis.to_world(local)))
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// The one image of a point, `t` its distance from the eye; the branch has the radius
/// unlimited (points more than fov/2 off the axis land outside the image circle, on the same
/// radial line, where the projection does not see). Degenerate: the eye and the axis behind
/// it have no image (at fov = 360 the whole image circle sees the point straight behind).
impl SingleImage for Fisheye {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let (image, off_axis) = self.image(point)?;
        Some(BranchImage {
            image,
            seen: off_axis <= self.half_fov,
        })
    }

    /// The axis behind the eye is a pole (it maps to the whole circle of radius
    /// pi / (fov/2) image-circle radii); no clip, no wrap.
    fn chart(&self) -> InverseChart {
        InverseChart {
            poles: vec![Pole {
                origin: self.basis.origin,
                direction: -self.basis.forward,
                clearance: std::f64::consts::PI - self.widest_pixel_angle(),
            }],
            ..InverseChart::default()
        }
    }
}

impl Fisheye {
    /// The image of `point` with the radius unlimited, and its angle off the axis. `None`
    /// for the eye and the axis behind it.
    fn image(&self, point: DVec3) -> Option<(ImagePoint, f64)> {
        let offset = point - self.basis.origin;
        let local = self.basis.to_local(offset);
        let lateral = DVec2::new(local.x, local.y);
        let lateral_length = lateral.length();
        if lateral_length == 0.0 && local.z <= 0.0 {
            return None; // the eye, or on the axis behind it
        }
        let off_axis = lateral_length.atan2(local.z);
        let radius = off_axis / self.half_fov * self.circle_radius;
        let centred = if lateral_length > 0.0 {
            lateral * (radius / lateral_length)
        } else {
            DVec2::ZERO
        };
        let image = ImagePoint {
            pixel: self.resolution.pixel(centred),
            t: offset.length(),
        };
        Some((image, off_axis))
    }

    /// The largest angle off the axis of a pixel centre inside the image circle (0 when no
    /// centre is inside).
    fn widest_pixel_angle(&self) -> f64 {
        let (w, h) = (self.resolution.width, self.resolution.height);
        let mut widest = 0.0f64;
        for y in 0..h {
            for x in 0..w {
                let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let r = self.resolution.centred(centre).length() / self.circle_radius;
                if r <= 1.0 {
                    widest = widest.max(r);
                }
            }
        }
        widest * self.half_fov
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fisheye(fov: f64) -> Fisheye {
        let frame = CameraFrame {
            position: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        Fisheye::new(&frame, fov, 300, 200).unwrap()
    }

    #[test]
    fn centre_looks_forward() {
        let ray = fisheye(180.0).ray(DVec2::new(150.0, 100.0)).unwrap();
        assert_eq!(ray.direction, DVec3::NEG_Z);
    }

    #[test]
    fn top_of_circle_looks_half_fov_up() {
        for fov in [90.0_f64, 180.0, 250.0] {
            let d = fisheye(fov).ray(DVec2::new(150.0, 0.0)).unwrap().direction;
            let half = 0.5 * fov.to_radians();
            let expected = DVec3::new(0.0, half.sin(), -half.cos());
            assert!((d - expected).length() < 1e-15, "fov {fov}: {d}");
        }
        // Right of centre on the circle: right in the world, azimuth preserved.
        let d = fisheye(180.0)
            .ray(DVec2::new(250.0, 100.0))
            .unwrap()
            .direction;
        assert!((d - DVec3::X).length() < 1e-15);
    }

    #[test]
    fn outside_the_circle_sees_nothing() {
        let f = fisheye(180.0);
        assert!(f.ray(DVec2::new(10.0, 10.0)).is_none());
        assert!(f.ray(DVec2::new(150.0, 0.0)).is_some());
    }

    #[test]
    fn full_sphere_circle_looks_backwards() {
        let d = fisheye(360.0)
            .ray(DVec2::new(250.0, 100.0))
            .unwrap()
            .direction;
        assert!((d - DVec3::Z).length() < 1e-15);
    }

    #[test]
    fn degenerate_points_have_no_image() {
        let mut out = Vec::new();
        let f = fisheye(360.0);
        f.project(DVec3::ZERO, &mut out); // the eye
        f.project(DVec3::new(0.0, 0.0, 2.0), &mut out); // straight behind, 360 ambiguity
        fisheye(180.0).project(DVec3::new(0.0, 1.0, 0.5), &mut out); // outside the fov
        assert!(out.is_empty());
        // Just off the axis behind a 360 fisheye: near the circle, left of centre.
        f.project(DVec3::new(-1e-6, 0.0, 2.0), &mut out);
        assert_eq!(out.len(), 1);
        let r = (out[0].pixel - DVec2::new(150.0, 100.0)).length() / 100.0;
        assert!((1.0 - r).abs() < 1e-6 && out[0].pixel.x < 150.0);
        assert!((out[0].t - 2.0).abs() < 1e-12);
    }

    #[test]
    fn on_axis_point_projects_to_the_centre() {
        let mut out = Vec::new();
        fisheye(200.0).project(DVec3::new(0.0, 0.0, -3.0), &mut out);
        assert_eq!(
            out,
            vec![ImagePoint {
                pixel: DVec2::new(150.0, 100.0),
                t: 3.0
            }]
        );
    }

    #[test]
    fn invalid_fov_is_an_error() {
        let frame = CameraFrame {
            position: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        for fov in [0.0, 360.5, f64::INFINITY] {
            let e = Fisheye::new(&frame, fov, 10, 10).unwrap_err();
            assert!(
                e.message.starts_with("fisheye fov must be in (0, 360]"),
                "{e}"
            );
        }
    }
}
