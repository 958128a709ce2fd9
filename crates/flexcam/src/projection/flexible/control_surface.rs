//! Control surfaces Q_i(u, v) of a flexible viewing volume.
//!
//! Domain convention: every surface is evaluated on the shared domain (u, v) in [0, 1]^2, with
//! u growing to the right of the image and v growing upwards (v = 0 is the bottom row), as the
//! `screen` coordinates of the scene format. Surfaces of one volume must use this domain in
//! the same way (the thesis, 5.1: "the top left corner of the first control surface
//! corresponds to the top left of all the other surfaces").

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

pub use super::nurbs::{NurbsPatch, NurbsSpec};
pub use super::panorama::PanoramaSurface;
pub use super::patch::{BSplinePatch, BezierPatch};
pub use super::presets::{DisplacedRectangle, PathSurface, PinchedRectangle, WarpedRectangle};
use crate::error::{Error, Result};

/// `axis` and `front` count as parallel when the sine of their angle is below this.
const PARALLEL_SINE: f64 = 1e-9;

/// Which parameter varies along a [`Surface::Line`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineParam {
    /// The line runs with u (columns).
    U,
    /// The line runs with v (rows).
    V,
}

/// An orthonormal frame for the polar surfaces: `axis` is latitude +90 degrees (sphere) or the
/// direction of increasing height (cylinder); `front` is longitude (angle) 0; `east` =
/// front x axis is longitude +90 degrees. With axis = +y and front = -z, east is +x: the
/// longitude grows to the right of a viewer looking along -z, as in the panoramas.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarFrame {
    /// Unit direction of latitude +90 degrees, or of increasing cylinder height.
    pub axis: DVec3,
    /// Unit direction of longitude 0, perpendicular to `axis`.
    pub front: DVec3,
    /// front x axis: longitude +90 degrees.
    pub east: DVec3,
}

impl PolarFrame {
    /// Normalises `axis` and makes `front` perpendicular to it (Gram-Schmidt). Errors: a zero
    /// or non-finite vector, or `front` parallel to `axis`.
    pub fn new(axis: DVec3, front: DVec3) -> Result<Self> {
        if !axis.is_finite() || !front.is_finite() {
            return Err(Error::new("surface axis and front must be finite"));
        }
        let axis = axis
            .try_normalize()
            .ok_or_else(|| Error::new("surface axis is zero: it must give a direction"))?;
        let front = front
            .try_normalize()
            .ok_or_else(|| Error::new("surface front is zero: it must give a direction"))?;
        let across = front - front.dot(axis) * axis;
        if across.length() < PARALLEL_SINE {
            return Err(Error::new("surface front is parallel to its axis"));
        }
        let front = across.normalize();
        Ok(PolarFrame {
            axis,
            front,
            east: front.cross(axis),
        })
    }

    /// The unit direction at longitude `lon` and latitude `lat` (radians).
    pub fn direction(&self, lon: f64, lat: f64) -> DVec3 {
        let (sin_lon, cos_lon) = lon.sin_cos();
        let (sin_lat, cos_lat) = lat.sin_cos();
        cos_lat * (cos_lon * self.front + sin_lon * self.east) + sin_lat * self.axis
    }
}

/// A sphere patch in polar form: u maps linearly to longitude from `longitude[0]` to
/// `longitude[1]`, v to latitude from `latitude[0]` to `latitude[1]` (radians; either range
/// may run backwards). Radius 0 is allowed: the patch is then the point `center`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpherePatch {
    /// The sphere's centre.
    pub center: DVec3,
    /// The sphere's radius, at least 0.
    pub radius: f64,
    /// The directions longitude and latitude are measured in.
    pub frame: PolarFrame,
    /// Longitude at u = 0 and at u = 1, radians.
    pub longitude: [f64; 2],
    /// Latitude at v = 0 and at v = 1, radians.
    pub latitude: [f64; 2],
}

/// A cylinder patch: u maps linearly to the angle around `frame.axis` from `angle[0]` to
/// `angle[1]` (radians, 0 at `frame.front`, growing towards `frame.east`), v to the height
/// along the axis from `height[0]` to `height[1]`, measured from `center`. Radius 0 is
/// allowed: the patch is then a segment of the axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderPatch {
    /// A point of the axis, where height 0 is.
    pub center: DVec3,
    /// The cylinder's radius, at least 0.
    pub radius: f64,
    /// The axis and the direction of angle 0.
    pub frame: PolarFrame,
    /// Angle around the axis at u = 0 and at u = 1, radians.
    pub angle: [f64; 2],
    /// Height along the axis at v = 0 and at v = 1.
    pub height: [f64; 2],
}

/// One control surface over the (u, v) domain [0, 1]^2.
#[derive(Debug, Clone, PartialEq)]
pub enum Surface {
    /// A parallelogram `corner + u * u_edge + v * v_edge` (`corner` at (u, v) = (0, 0), the
    /// bottom-left of the image). Zero edges are allowed (a segment or a point).
    Rectangle {
        /// The point at (u, v) = (0, 0).
        corner: DVec3,
        /// The step from u = 0 to u = 1.
        u_edge: DVec3,
        /// The step from v = 0 to v = 1.
        v_edge: DVec3,
    },
    /// A bilinear patch through four corners, in the order (u, v) = (0, 0), (1, 0), (1, 1),
    /// (0, 1): bottom-left, bottom-right, top-right, top-left.
    Bilinear {
        /// The corners at (0, 0), (1, 0), (1, 1), (0, 1).
        corners: [DVec3; 4],
    },
    /// A sphere or hemisphere patch.
    Sphere(SpherePatch),
    /// A cylinder patch.
    Cylinder(CylinderPatch),
    /// Every (u, v) at one point: a pinhole.
    Point(DVec3),
    /// The segment from `start` to `end`, parameterised by u or by v (the other parameter is
    /// ignored): the slit of a pushbroom or crossed-slits camera.
    Line {
        /// The point at parameter 0.
        start: DVec3,
        /// The point at parameter 1.
        end: DVec3,
        /// Which of u and v runs along the segment.
        along: LineParam,
    },
    /// A bicubic Bezier patch (boxed: 16 control points).
    Bezier(Box<BezierPatch>),
    /// A uniform cubic B-spline patch.
    BSpline(BSplinePatch),
    /// A NURBS patch: any degree up to 7, knots and weights (boxed: a control grid and two
    /// knot vectors).
    Nurbs(Box<NurbsPatch>),
    /// A shape-defined panorama surface: outlines and profiles by arc length (boxed: it
    /// holds a camera basis).
    Panorama(Box<PanoramaSurface>),
    /// A rectangle with its parameters pulled towards a pole: the occlusion camera's far
    /// surface (built by that preset only).
    Pinched(Box<PinchedRectangle>),
    /// The columns of a multiple-centre-of-projection camera path at one distance (built by
    /// the `mcop` preset only).
    Path(Box<PathSurface>),
    /// A rectangle with u re-parameterised piecewise-linearly: the long scene's far surface
    /// (built by that preset only).
    Warped(Box<WarpedRectangle>),
    /// A rectangle at parameters moved by a displacement map: the depth-discontinuity
    /// occlusion camera's far surfaces (built by the `ddoc` preset only).
    Displaced(Box<DisplacedRectangle>),
}

/// Linear interpolation of a parameter range at `s` in [0, 1].
pub(super) fn lerp_range(range: [f64; 2], s: f64) -> f64 {
    range[0] + s * (range[1] - range[0])
}

impl Surface {
    /// A rectangle given by its centre and the half-extent vectors from the centre to the
    /// middle of the u = 1 edge (`u_axis`) and of the v = 1 edge (`v_axis`).
    pub fn rectangle_centred(center: DVec3, u_axis: DVec3, v_axis: DVec3) -> Surface {
        Surface::Rectangle {
            corner: center - u_axis - v_axis,
            u_edge: 2.0 * u_axis,
            v_edge: 2.0 * v_axis,
        }
    }

    /// The surface point Q(u, v). Outside [0, 1]^2 the formulas extrapolate.
    pub fn point(&self, uv: DVec2) -> DVec3 {
        let (u, v) = (uv.x, uv.y);
        match self {
            Surface::Rectangle {
                corner,
                u_edge,
                v_edge,
            } => *corner + u * *u_edge + v * *v_edge,
            Surface::Bilinear {
                corners: [a, b, c, d],
            } => {
                let bottom = a.lerp(*b, u);
                let top = d.lerp(*c, u);
                bottom.lerp(top, v)
            }
            Surface::Sphere(s) => {
                let lon = lerp_range(s.longitude, u);
                let lat = lerp_range(s.latitude, v);
                s.center + s.radius * s.frame.direction(lon, lat)
            }
            Surface::Cylinder(c) => {
                let angle = lerp_range(c.angle, u);
                let height = lerp_range(c.height, v);
                c.center + height * c.frame.axis + c.radius * c.frame.direction(angle, 0.0)
            }
            Surface::Point(p) => *p,
            Surface::Line { start, end, along } => {
                let s = match along {
                    LineParam::U => u,
                    LineParam::V => v,
                };
                start.lerp(*end, s)
            }
            Surface::Bezier(b) => b.point(uv),
            Surface::BSpline(b) => b.point(uv),
            Surface::Nurbs(n) => n.point(uv),
            Surface::Panorama(p) => p.point(uv),
            Surface::Pinched(p) => p.point(uv),
            Surface::Path(p) => p.point(uv),
            Surface::Warped(w) => w.point(uv),
            Surface::Displaced(d) => d.point(uv),
        }
    }

    /// The scene-file name of the surface type.
    pub fn kind(&self) -> &'static str {
        match self {
            Surface::Rectangle { .. } => "rectangle",
            Surface::Bilinear { .. } => "bilinear",
            Surface::Sphere(_) => "sphere",
            Surface::Cylinder(_) => "cylinder",
            Surface::Point(_) => "point",
            Surface::Line { .. } => "line",
            Surface::Bezier(_) => "bezier",
            Surface::BSpline(_) => "bspline",
            Surface::Nurbs(_) => "nurbs",
            Surface::Panorama(_) => "panorama",
            Surface::Pinched(_) => "pinched",
            Surface::Path(_) => "path",
            Surface::Warped(_) => "warped",
            Surface::Displaced(_) => "displaced",
        }
    }

    /// For a surface bilinear in (u, v) (rectangle, bilinear patch, point, line): a bound on
    /// the magnitude of every coordinate of its coefficients and of the intermediates of
    /// [`Surface::point`] over u, v in [0, 1], so that its rounding there is a few ulps of
    /// this bound. Over any rectangle of (u, v) such a surface's points are convex
    /// combinations of the rectangle's corner points (the bilinear weights). `None` for the
    /// curved surfaces, which have no such property.
    pub fn bilinear_scale(&self) -> Option<f64> {
        let max = |points: &[DVec3]| {
            points
                .iter()
                .fold(0.0f64, |m, p| m.max(p.abs().max_element()))
        };
        match self {
            Surface::Rectangle {
                corner,
                u_edge,
                v_edge,
            } => Some((corner.abs() + u_edge.abs() + v_edge.abs()).max_element()),
            // Each lerp a + (b - a) s has intermediates of up to twice its ends.
            Surface::Bilinear { corners } => Some(2.0 * max(corners)),
            Surface::Point(p) => Some(max(&[*p])),
            Surface::Line { start, end, .. } => Some(2.0 * max(&[*start, *end])),
            Surface::Sphere(_)
            | Surface::Cylinder(_)
            | Surface::Bezier(_)
            | Surface::BSpline(_)
            | Surface::Nurbs(_)
            | Surface::Panorama(_)
            | Surface::Pinched(_)
            | Surface::Path(_)
            | Surface::Warped(_)
            | Surface::Displaced(_) => None,
        }
    }

    /// Checks the numbers: every coordinate finite, radii at least 0, latitudes within
    /// [-90, 90] degrees and longitude / angle spans at most 360 degrees.
    pub fn validate(&self) -> Result<()> {
        let finite = |points: &[DVec3]| points.iter().all(|p| p.is_finite());
        let ok = match self {
            Surface::Rectangle {
                corner,
                u_edge,
                v_edge,
            } => finite(&[*corner, *u_edge, *v_edge]),
            Surface::Bilinear { corners } => finite(corners),
            Surface::Point(p) => finite(&[*p]),
            Surface::Line { start, end, .. } => finite(&[*start, *end]),
            Surface::Bezier(b) => finite(b.control.as_flattened()),
            Surface::BSpline(b) => finite(b.control()),
            Surface::Nurbs(n) => n.is_finite(),
            Surface::Panorama(p) => {
                p.validate()?;
                true
            }
            Surface::Pinched(p) => p.is_finite(),
            Surface::Path(p) => p.is_finite(),
            Surface::Warped(w) => w.is_finite(),
            Surface::Displaced(d) => d.is_finite(),
            Surface::Sphere(s) => {
                check_radius(s.radius)?;
                check_span("longitude", s.longitude)?;
                if s.latitude
                    .iter()
                    .any(|l| l.abs() > 0.5 * PI * (1.0 + 1e-12))
                {
                    return Err(Error::new(format!(
                        "sphere latitude must lie within [-90, 90] degrees, got [{}, {}]",
                        s.latitude[0].to_degrees(),
                        s.latitude[1].to_degrees()
                    )));
                }
                finite(&[s.center])
            }
            Surface::Cylinder(c) => {
                check_radius(c.radius)?;
                check_span("angle", c.angle)?;
                finite(&[c.center]) && c.height.iter().all(|h| h.is_finite())
            }
        };
        if ok {
            Ok(())
        } else {
            Err(Error::new(format!(
                "{} surface has a non-finite coordinate",
                self.kind()
            )))
        }
    }
}

fn check_radius(radius: f64) -> Result<()> {
    if radius.is_finite() && radius >= 0.0 {
        Ok(())
    } else {
        Err(Error::new(format!(
            "surface radius must be finite and at least 0, got {radius}"
        )))
    }
}

fn check_span(name: &str, range: [f64; 2]) -> Result<()> {
    if range.iter().all(|a| a.is_finite())
        && (range[1] - range[0]).abs() <= 2.0 * PI * (1.0 + 1e-12)
    {
        Ok(())
    } else {
        Err(Error::new(format!(
            "surface {name} range must span at most 360 degrees, got [{}, {}]",
            range[0].to_degrees(),
            range[1].to_degrees()
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    fn frame() -> PolarFrame {
        PolarFrame::new(DVec3::Y, DVec3::NEG_Z).unwrap()
    }

    #[test]
    fn polar_frame_east_is_right_of_a_viewer_along_minus_z() {
        let f = frame();
        assert!(close(f.east, DVec3::X));
        assert!(close(f.direction(0.5 * PI, 0.0), DVec3::X));
        assert!(close(f.direction(0.3, 0.5 * PI), DVec3::Y));
        // A front that is not perpendicular to the axis is straightened.
        let g = PolarFrame::new(DVec3::Y * 3.0, DVec3::new(0.0, 1.0, -1.0)).unwrap();
        assert!(close(g.front, DVec3::NEG_Z));
    }

    #[test]
    fn degenerate_frames_are_errors() {
        assert!(PolarFrame::new(DVec3::ZERO, DVec3::X).is_err());
        assert!(PolarFrame::new(DVec3::Y, DVec3::ZERO).is_err());
        assert!(PolarFrame::new(DVec3::Y, DVec3::NEG_Y * 2.0).is_err());
        assert!(PolarFrame::new(DVec3::Y, DVec3::new(f64::NAN, 0.0, 0.0)).is_err());
    }

    #[test]
    fn rectangle_corner_and_centred_forms_agree() {
        let r = Surface::rectangle_centred(DVec3::new(0.0, 0.0, 1.0), DVec3::X, DVec3::Y * 2.0);
        assert!(close(r.point(DVec2::ZERO), DVec3::new(-1.0, -2.0, 1.0)));
        assert!(close(r.point(DVec2::ONE), DVec3::new(1.0, 2.0, 1.0)));
        assert!(close(r.point(DVec2::splat(0.5)), DVec3::new(0.0, 0.0, 1.0)));
        assert!(close(
            r.point(DVec2::new(1.0, 0.25)),
            DVec3::new(1.0, -1.0, 1.0)
        ));
    }

    #[test]
    fn zero_size_rectangle_is_a_point() {
        let r = Surface::rectangle_centred(DVec3::ONE, DVec3::ZERO, DVec3::ZERO);
        for uv in [DVec2::ZERO, DVec2::new(0.3, 0.9), DVec2::ONE] {
            assert_eq!(r.point(uv), DVec3::ONE);
        }
        assert!(r.validate().is_ok());
    }

    #[test]
    fn bilinear_interpolates_its_corners() {
        let corners = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 1.0), DVec3::Y];
        let b = Surface::Bilinear { corners };
        assert_eq!(b.point(DVec2::ZERO), corners[0]);
        assert_eq!(b.point(DVec2::X), corners[1]);
        assert_eq!(b.point(DVec2::ONE), corners[2]);
        assert_eq!(b.point(DVec2::Y), corners[3]);
        // The twist: the centre is the mean of the corners.
        assert!(close(
            b.point(DVec2::splat(0.5)),
            DVec3::new(0.5, 0.5, 0.25)
        ));
    }

    #[test]
    fn sphere_maps_u_to_longitude_and_v_to_latitude() {
        let s = Surface::Sphere(SpherePatch {
            center: DVec3::new(1.0, 0.0, 0.0),
            radius: 2.0,
            frame: frame(),
            longitude: [-0.5 * PI, 0.5 * PI],
            latitude: [-0.25 * PI, 0.25 * PI],
        });
        assert!(close(
            s.point(DVec2::splat(0.5)),
            DVec3::new(1.0, 0.0, -2.0)
        ));
        assert!(close(
            s.point(DVec2::new(1.0, 0.5)),
            DVec3::new(3.0, 0.0, 0.0)
        ));
        let top = s.point(DVec2::new(0.5, 1.0));
        let h = 2.0 * (0.25 * PI).cos();
        assert!(close(top, DVec3::new(1.0, h, -h)));
        assert!(s.validate().is_ok());
    }

    #[test]
    fn radius_zero_sphere_and_cylinder_collapse() {
        let s = Surface::Sphere(SpherePatch {
            center: DVec3::ONE,
            radius: 0.0,
            frame: frame(),
            longitude: [-PI, PI],
            latitude: [-0.5 * PI, 0.5 * PI],
        });
        assert_eq!(s.point(DVec2::new(0.2, 0.7)), DVec3::ONE);
        let c = Surface::Cylinder(CylinderPatch {
            center: DVec3::ZERO,
            radius: 0.0,
            frame: frame(),
            angle: [-PI, PI],
            height: [-1.0, 1.0],
        });
        assert!(close(
            c.point(DVec2::new(0.9, 0.75)),
            DVec3::new(0.0, 0.5, 0.0)
        ));
        assert!(s.validate().is_ok() && c.validate().is_ok());
    }

    #[test]
    fn cylinder_maps_u_to_angle_and_v_to_height() {
        let c = Surface::Cylinder(CylinderPatch {
            center: DVec3::new(0.0, 1.0, 0.0),
            radius: 3.0,
            frame: frame(),
            angle: [-0.5 * PI, 0.5 * PI],
            height: [-1.0, 2.0],
        });
        assert!(close(
            c.point(DVec2::new(0.5, 0.0)),
            DVec3::new(0.0, 0.0, -3.0)
        ));
        assert!(close(
            c.point(DVec2::new(0.0, 1.0)),
            DVec3::new(-3.0, 3.0, 0.0)
        ));
    }

    #[test]
    fn point_and_line_surfaces() {
        let p = Surface::Point(DVec3::X);
        assert_eq!(p.point(DVec2::new(0.4, 0.6)), DVec3::X);
        let l = Surface::Line {
            start: DVec3::ZERO,
            end: DVec3::new(4.0, 0.0, 0.0),
            along: LineParam::U,
        };
        assert_eq!(l.point(DVec2::new(0.25, 0.9)), DVec3::X);
        let l = Surface::Line {
            start: DVec3::ZERO,
            end: DVec3::new(4.0, 0.0, 0.0),
            along: LineParam::V,
        };
        assert_eq!(l.point(DVec2::new(0.9, 0.25)), DVec3::X);
    }

    #[test]
    fn invalid_numbers_are_errors() {
        let mut s = SpherePatch {
            center: DVec3::ZERO,
            radius: -1.0,
            frame: frame(),
            longitude: [-PI, PI],
            latitude: [0.0, 0.5 * PI],
        };
        assert!(Surface::Sphere(s).validate().is_err());
        s.radius = 1.0;
        s.latitude = [0.0, PI];
        assert!(Surface::Sphere(s).validate().is_err());
        s.latitude = [0.0, 0.5 * PI];
        s.longitude = [-PI, 1.5 * PI];
        assert!(Surface::Sphere(s).validate().is_err());
        let r = Surface::Point(DVec3::new(0.0, f64::INFINITY, 0.0));
        assert!(r.validate().unwrap_err().message.contains("non-finite"));
    }
}
