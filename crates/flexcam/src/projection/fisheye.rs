//! `type = "fisheye"`: a radial fisheye. The angle off the view axis is a function of the
//! distance from the image centre (the mapping, see [`super::fisheye_mapping`]); the image
//! circle is placed by [`super::fisheye_circle`]. The default, the equidistant mapping with
//! the circle inscribed in the shorter side, is the angular fisheye.

use glam::{DVec2, DVec3};

use super::camera_basis::CameraBasis;
use super::chart::{InverseChart, Pole};
use super::fisheye_circle::{FisheyeFit, Outline};
use super::fisheye_mapping::{classic_radius, classic_theta, FisheyeMapping, LensPolynomial};
use super::image_coords::Resolution;
use super::{
    AnalyticInverse, BranchImage, CameraFrame, ImagePoint, NoInverse, Projection, SingleImage,
    Trilinear,
};
use crate::error::{Error, Result};
use crate::geometry::Ray;

/// A fisheye's mapping and the placement of its image circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FisheyeLens {
    /// How the angle off the axis maps to the distance from the image centre.
    pub mapping: FisheyeMapping,
    /// Where the image circle lies in the image.
    pub fit: FisheyeFit,
}

impl Default for FisheyeLens {
    /// The angular fisheye: equidistant, circle inscribed in the shorter side.
    fn default() -> Self {
        FisheyeLens {
            mapping: FisheyeMapping::Equidistant,
            fit: FisheyeFit::Inscribed,
        }
    }
}

/// The mapping as built: a classic law (unit focal length) or a validated lens polynomial
/// (millimetres).
#[derive(Debug, Clone, Copy, PartialEq)]
enum RadialLaw {
    Classic(FisheyeMapping),
    Polynomial(LensPolynomial),
}

impl RadialLaw {
    /// The angle off the axis at image radius `rho` (inside the valid image).
    fn theta(&self, rho: f64) -> f64 {
        match self {
            RadialLaw::Classic(mapping) => classic_theta(*mapping, rho),
            RadialLaw::Polynomial(p) => p.theta(rho),
        }
    }

    /// The image radius of angle `theta`, continued monotonically beyond the valid image
    /// (the polynomial linearly, r_end (1 + theta - theta_end)) and clamped to 0 below a
    /// polynomial's theta(0).
    fn radius(&self, theta: f64) -> f64 {
        match self {
            RadialLaw::Classic(mapping) => classic_radius(*mapping, theta),
            RadialLaw::Polynomial(p) if theta > p.theta_end => {
                p.r_end * (1.0 + theta - p.theta_end)
            }
            RadialLaw::Polynomial(p) if theta <= p.theta(0.0) => 0.0,
            RadialLaw::Polynomial(p) => p.radius(theta),
        }
    }

    /// The smallest angle with an image: a polynomial's theta(0) = -k0, else 0.
    fn theta_start(&self) -> f64 {
        match self {
            RadialLaw::Classic(_) => 0.0,
            RadialLaw::Polynomial(p) => p.theta(0.0),
        }
    }
}

/// A pixel at normalised radius n from the image centre (n = 1 on the outline: the circle
/// or ellipse where the angle reaches fov/2, or where a lens polynomial's valid image ends)
/// looks theta(n rho_edge) off the view axis, in the direction of its azimuth (right in the
/// image is right in the world, up is up). Pixels outside the outline see nothing. Ray
/// directions are unit length.
#[derive(Debug, Clone, PartialEq)]
pub struct Fisheye {
    kind: &'static str,
    basis: CameraBasis,
    law: RadialLaw,
    /// The angle and the image radius (the mapping's units) at the outline.
    theta_edge: f64,
    rho_edge: f64,
    outline: Outline,
    resolution: Resolution,
}

impl Fisheye {
    /// The angular fisheye. Errors: a degenerate frame, an empty image, `fov_degrees` not
    /// in (0, 360].
    pub fn new(frame: &CameraFrame, fov_degrees: f64, width: u32, height: u32) -> Result<Self> {
        Fisheye::with_lens(
            "fisheye",
            frame,
            fov_degrees,
            &FisheyeLens::default(),
            width,
            height,
        )
    }

    /// A fisheye with `lens`, reporting `kind` as its type name. Errors: those of
    /// [`Fisheye::new`], a fov outside the mapping's range
    /// ([`FisheyeMapping::half_fov`]), a bad sensor, a bad polynomial
    /// (`LensPolynomial::new`), a polynomial without a sensor or with a focal length, a
    /// classic mapping on a sensor without one.
    pub fn with_lens(
        kind: &'static str,
        frame: &CameraFrame,
        fov_degrees: f64,
        lens: &FisheyeLens,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let half_fov = lens.mapping.half_fov(fov_degrees)?;
        let resolution = Resolution::new(width, height)?;
        let size = resolution.size();
        let (law, theta_edge, rho_edge, radii) = match (lens.mapping, lens.fit) {
            (FisheyeMapping::Polynomial(k), FisheyeFit::Sensor(sensor)) => {
                if sensor.lens.is_some() {
                    return Err(Error::new(
                        "fisheye lens (focal length) belongs to the classic mappings: the polynomial maps millimetres to angles itself",
                    ));
                }
                let mm = sensor.millimetres_per_pixel(size)?;
                let r_corner = (0.5 * size * mm).length();
                let p = LensPolynomial::new(k, half_fov, r_corner)?;
                (
                    RadialLaw::Polynomial(p),
                    p.theta_end,
                    p.r_end,
                    DVec2::splat(p.r_end) / mm,
                )
            }
            (FisheyeMapping::Polynomial(_), _) => {
                return Err(Error::new(
                    "fisheye mapping \"polynomial\" works in millimetres on a sensor: give sensor_width (and sensor_fit), not fit",
                ))
            }
            (mapping, fit) => {
                let rho_edge = classic_radius(mapping, half_fov);
                let radii = match fit {
                    FisheyeFit::Inscribed => DVec2::splat(0.5 * size.min_element()),
                    FisheyeFit::Fill => 0.5 * size,
                    FisheyeFit::Diagonal => DVec2::splat(0.5 * size.length()),
                    FisheyeFit::Sensor(sensor) => {
                        let focal = sensor.lens.ok_or_else(|| {
                            Error::new(format!(
                                "fisheye sensor_width and sensor_height need lens (the focal length in mm) for mapping \"{}\"",
                                mapping.name()
                            ))
                        })?;
                        DVec2::splat(focal * rho_edge) / sensor.millimetres_per_pixel(size)?
                    }
                };
                (RadialLaw::Classic(mapping), half_fov, rho_edge, radii)
            }
        };
        Ok(Fisheye {
            kind,
            basis: CameraBasis::new(frame)?,
            law,
            theta_edge,
            rho_edge,
            outline: Outline::new(radii),
            resolution,
        })
    }
}

impl Projection for Fisheye {
    fn kind(&self) -> &'static str {
        self.kind
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    /// `None` outside the outline (normalised radius > 1).
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let (n, azimuth) = self.outline.polar(self.resolution.centred(pixel));
        if n > 1.0 {
            return None;
        }
        let off_axis = self.law.theta(n * self.rho_edge);
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

/// The one image of a point, `t` its distance from the eye; the branch continues the
/// mapping monotonically beyond the outline (points more than fov/2 off the axis land
/// outside it, on the same radial line, where the projection does not see). Degenerate: the
/// eye and the axis behind it have no image (at fov = 360 the whole outline sees the point
/// straight behind); a lens polynomial with k0 < 0 sees nothing within -k0 of the axis
/// (those points sit at the centre, unseen).
impl SingleImage for Fisheye {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let (image, off_axis) = self.image(point)?;
        Some(BranchImage {
            image,
            seen: off_axis <= self.theta_edge && off_axis >= self.law.theta_start(),
        })
    }

    /// The axis behind the eye is a pole (it maps to the whole outline scaled by the
    /// continued radius of pi); no clip, no wrap.
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
        let n = self.law.radius(off_axis) / self.rho_edge;
        let centred = if lateral_length > 0.0 {
            self.outline.position(n, lateral, lateral_length)
        } else {
            DVec2::ZERO
        };
        let image = ImagePoint {
            pixel: self.resolution.pixel(centred),
            t: offset.length(),
        };
        Some((image, off_axis))
    }

    /// The largest angle off the axis of a pixel centre inside the outline (theta(0) when no
    /// centre is inside).
    fn widest_pixel_angle(&self) -> f64 {
        let (w, h) = (self.resolution.width, self.resolution.height);
        let mut widest = 0.0f64;
        for y in 0..h {
            for x in 0..w {
                let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let (n, _) = self.outline.polar(self.resolution.centred(centre));
                if n <= 1.0 {
                    widest = widest.max(n);
                }
            }
        }
        self.law.theta(widest * self.rho_edge)
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
