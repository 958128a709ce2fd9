//! Where a fisheye's image circle lies in the image: fitted to the image by its field of
//! view, or set by a focal length on a sensor in millimetres as Blender Cycles does. The
//! circle becomes an ellipse where the fit stretches it (`fit = "fill"` on a non-square
//! image, a sensor with non-square pixels).

use glam::DVec2;

use super::params::positive_length;
use crate::error::{Error, Result};

/// How the fisheye's circle (the angle fov/2) is placed in the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FisheyeFit {
    /// A circle inscribed in the shorter image side (the default).
    Inscribed,
    /// An ellipse touching all four sides (Cycles' equidistant fisheye on any frame).
    Fill,
    /// A circle through the four corners: every pixel sees (a "full-frame" fisheye).
    Diagonal,
    /// A sensor in millimetres: the mapping's radius is in millimetres on it.
    Sensor(Sensor),
}

/// Which sensor side Cycles fits to the image (`sensor_fit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensorFit {
    /// `sensor_width` spans the longer image side.
    Auto,
    /// `sensor_width` spans the image width.
    Horizontal,
    /// `sensor_height` spans the image height.
    Vertical,
}

/// Sensor fit names as written in scene files.
pub const SENSOR_FIT_NAMES: [&str; 3] = ["auto", "horizontal", "vertical"];

impl SensorFit {
    /// The fit named `name` in a scene file.
    pub fn parse(name: &str) -> Option<SensorFit> {
        match name {
            "auto" => Some(SensorFit::Auto),
            "horizontal" => Some(SensorFit::Horizontal),
            "vertical" => Some(SensorFit::Vertical),
            _ => None,
        }
    }
}

/// A camera sensor as Blender describes it (Cycles' `blender_camera_sync`): with the fit
/// horizontal (`auto` on a landscape image) the sensor is `width` mm wide and as tall as
/// the image's aspect makes it; with the fit vertical it is `height` mm tall. Pixels are
/// `pixel_aspect[0]` wide for `pixel_aspect[1]` tall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensor {
    /// Sensor width, mm (`sensor_width`).
    pub width: f64,
    /// Sensor height, mm (`sensor_height`).
    pub height: f64,
    /// Which sensor side spans the image (`sensor_fit`).
    pub fit: SensorFit,
    /// Pixel width and height ratio (`pixel_aspect`).
    pub pixel_aspect: [f64; 2],
    /// The focal length in mm of a classic mapping (rho = lens g(theta)); `None` for the
    /// lens polynomial, whose radius is already in mm.
    pub lens: Option<f64>,
}

impl Sensor {
    /// Millimetres per pixel in x and in y for a `size` image. Errors: a sensor side, a
    /// pixel aspect or the focal length not positive and finite.
    pub fn millimetres_per_pixel(&self, size: DVec2) -> Result<DVec2> {
        positive_length("fisheye", "sensor_width", self.width)?;
        positive_length("fisheye", "sensor_height", self.height)?;
        if let Some(lens) = self.lens {
            positive_length("fisheye", "lens", lens)?;
        }
        let [ax, ay] = self.pixel_aspect;
        if !(ax.is_finite() && ay.is_finite() && ax > 0.0 && ay > 0.0) {
            return Err(Error::new(format!(
                "fisheye pixel_aspect must be two positive numbers, got [{ax}, {ay}]"
            )));
        }
        let ratio = DVec2::new(size.x * ax, size.y * ay);
        let horizontal = match self.fit {
            SensorFit::Auto => ratio.x > ratio.y,
            SensorFit::Horizontal => true,
            SensorFit::Vertical => false,
        };
        // Millimetres per unit of the aspect-weighted size along the fitted side.
        let unit = if horizontal {
            self.width / ratio.x
        } else if self.fit == SensorFit::Auto {
            self.width / ratio.y
        } else {
            self.height / ratio.y
        };
        Ok(DVec2::new(unit * ax, unit * ay))
    }
}

/// The image outline of the fisheye's valid region, centred on the image centre: a circle
/// or an axis-aligned ellipse, radii in pixels. A centred position c maps to the normalised
/// radius n (1 on the outline) and an azimuth: for a circle n = |c| / R and the azimuth is
/// c / |c|; for an ellipse both come from s = (c.x / Rx, c.y / Ry).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Outline {
    Circle(f64),
    Ellipse(DVec2),
}

impl Outline {
    /// The outline with radii `radii` (a circle where they are equal).
    pub fn new(radii: DVec2) -> Outline {
        if radii.x == radii.y {
            Outline::Circle(radii.x)
        } else {
            Outline::Ellipse(radii)
        }
    }

    /// Normalised radius and unit azimuth of centred position `c`. Degenerate: at the centre
    /// the azimuth is undefined; it is then up, (0, 1), as in Cycles (whose angle at the
    /// centre need not be zero).
    pub fn polar(&self, c: DVec2) -> (f64, DVec2) {
        let (scaled, radius) = match *self {
            Outline::Circle(r) => {
                let radius = c.length();
                return (radius / r, if radius > 0.0 { c / radius } else { DVec2::Y });
            }
            Outline::Ellipse(radii) => {
                let s = c / radii;
                (s, s.length())
            }
        };
        let azimuth = if radius > 0.0 {
            scaled / radius
        } else {
            DVec2::Y
        };
        (radius, azimuth)
    }

    /// The centred position at normalised radius `n` in the direction of `lateral` (any
    /// length > 0; the azimuth is `lateral`'s direction in the scaled frame).
    pub fn position(&self, n: f64, lateral: DVec2, lateral_length: f64) -> DVec2 {
        match *self {
            Outline::Circle(r) => lateral * (n * r / lateral_length),
            Outline::Ellipse(radii) => lateral * (n / lateral_length) * radii,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sensor(fit: SensorFit, pixel_aspect: [f64; 2]) -> Sensor {
        Sensor {
            width: 36.0,
            height: 24.0,
            fit,
            pixel_aspect,
            lens: Some(10.5),
        }
    }

    #[test]
    fn sensor_fits_as_blender() {
        let landscape = DVec2::new(360.0, 200.0);
        let mm = sensor(SensorFit::Auto, [1.0, 1.0])
            .millimetres_per_pixel(landscape)
            .unwrap();
        assert_eq!(mm, DVec2::splat(0.1));
        // Portrait: `auto` puts the sensor width along the height.
        let portrait = DVec2::new(200.0, 360.0);
        let mm = sensor(SensorFit::Auto, [1.0, 1.0])
            .millimetres_per_pixel(portrait)
            .unwrap();
        assert_eq!(mm, DVec2::splat(0.1));
        let mm = sensor(SensorFit::Vertical, [1.0, 1.0])
            .millimetres_per_pixel(landscape)
            .unwrap();
        assert_eq!(mm, DVec2::splat(0.12));
        // Pixels twice as tall as wide: the same mm across the width, twice per pixel in y.
        let mm = sensor(SensorFit::Horizontal, [1.0, 2.0])
            .millimetres_per_pixel(landscape)
            .unwrap();
        assert_eq!(mm, DVec2::new(0.1, 0.2));
        let e = sensor(SensorFit::Auto, [0.0, 1.0])
            .millimetres_per_pixel(landscape)
            .unwrap_err();
        assert!(e.message.starts_with("fisheye pixel_aspect must be"));
    }

    #[test]
    fn outline_polar_and_back() {
        for outline in [
            Outline::new(DVec2::splat(50.0)),
            Outline::new(DVec2::new(80.0, 40.0)),
        ] {
            let c = DVec2::new(12.0, -7.0);
            let (n, azimuth) = outline.polar(c);
            let back = outline.position(n, azimuth, 1.0);
            assert!((back - c).length() < 1e-12, "{outline:?}: {back}");
        }
        let e = Outline::new(DVec2::new(80.0, 40.0));
        assert_eq!(e.polar(DVec2::new(0.0, 40.0)).0, 1.0);
        assert_eq!(e.polar(DVec2::new(80.0, 0.0)).0, 1.0);
        assert_eq!(e.polar(DVec2::ZERO), (0.0, DVec2::Y));
    }
}
