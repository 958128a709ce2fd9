//! A user-defined projection: the stereographic "little planet", written against flexcam's
//! public [`Projection`] trait and rendered through flexcam's one render entry point, by ray
//! casting and, since it supplies an inverse, by rasterisation.

use std::f64::consts::PI;
use std::path::Path;

use flexcam::geometry::Ray;
use flexcam::glam::{DVec2, DVec3};
use flexcam::image_io::{write_color_png, ColorEncoding};
use flexcam::projection::{
    AnalyticInverse, BranchImage, CameraBasis, CameraFrame, ImagePoint, InverseChart, NoInverse,
    Pole, Projection, Resolution, SingleImage,
};
use flexcam::render::{self, compare, Comparison, Method, PreparedScene, RenderOptions, Shading};
use flexcam::scene::{self, Overrides};
use flexcam::{Error, Result};

/// The stereographic projection: a pixel at distance r (pixels) from the image centre looks
/// theta = 2 atan(r / 2f) off the view axis, in the direction of its azimuth (right in the
/// image is the basis' right, up is its up). Looking straight down from above the ground, the
/// ground becomes a small planet and the horizon a circle around it.
///
/// `f` is chosen so that the circle inscribed in the shorter image side spans `fov`. Every
/// image position sees something (theta < 180 degrees everywhere), so the whole image is
/// covered.
///
/// Degenerate cases: the eye itself and the points straight behind the camera (theta = 180
/// degrees, which maps to infinity) have no image; `fov` must lie in (0, 360) degrees (360
/// would put infinity on the inscribed circle).
#[derive(Debug, Clone)]
pub struct LittlePlanet {
    basis: CameraBasis,
    resolution: Resolution,
    /// The stereographic focal length in pixels.
    focal: f64,
}

impl LittlePlanet {
    /// The camera of `frame`, `fov_degrees` across the shorter side of a `width` x `height`
    /// image. Errors: a degenerate frame, an empty image, `fov_degrees` not in (0, 360).
    pub fn new(frame: &CameraFrame, fov_degrees: f64, width: u32, height: u32) -> Result<Self> {
        if !(fov_degrees > 0.0 && fov_degrees < 360.0) {
            return Err(Error::new(format!(
                "little planet fov must be in (0, 360) degrees, got {fov_degrees}"
            )));
        }
        let resolution = Resolution::new(width, height)?;
        let half_side = 0.5 * f64::from(width.min(height));
        Ok(LittlePlanet {
            basis: CameraBasis::new(frame)?,
            resolution,
            focal: half_side / (2.0 * (fov_degrees.to_radians() / 4.0).tan()),
        })
    }

    /// The largest angle off the axis of any pixel centre (those of the corner pixels).
    fn widest_pixel_angle(&self) -> f64 {
        let corner = 0.5 * self.resolution.size() - DVec2::splat(0.5);
        2.0 * (corner.length() / (2.0 * self.focal)).atan()
    }
}

impl Projection for LittlePlanet {
    fn kind(&self) -> &'static str {
        "little_planet"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    /// Unit-length directions from the eye; never `None`.
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let centred = self.resolution.centred(pixel);
        let radius = centred.length();
        let off_axis = 2.0 * (radius / (2.0 * self.focal)).atan();
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

    /// The inverse is [`SingleImage`]'s: flexcam derives [`AnalyticInverse`] (and the
    /// continuous map `--method raster` draws triangles by) from it.
    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }
}

impl SingleImage for LittlePlanet {
    /// r = 2 f tan(theta / 2) on the point's azimuth, `t` its distance from the eye (the ray
    /// directions are unit length). `None` for the eye and the axis behind it.
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let offset = point - self.basis.origin;
        let local = self.basis.to_local(offset);
        let lateral = DVec2::new(local.x, local.y);
        let lateral_length = lateral.length();
        if lateral_length == 0.0 && local.z <= 0.0 {
            return None;
        }
        let off_axis = lateral_length.atan2(local.z);
        let radius = 2.0 * self.focal * (0.5 * off_axis).tan();
        let centred = if lateral_length > 0.0 {
            lateral * (radius / lateral_length)
        } else {
            DVec2::ZERO
        };
        Some(BranchImage {
            image: ImagePoint {
                pixel: self.resolution.pixel(centred),
                t: offset.length(),
            },
            seen: true,
        })
    }

    /// The axis behind the eye maps to infinity: a pole, which every pixel centre's ray
    /// misses by at least 180 degrees less the widest pixel angle. No clip planes, no wrap.
    fn chart(&self) -> InverseChart {
        InverseChart {
            poles: vec![Pole {
                origin: self.basis.origin,
                direction: -self.basis.forward,
                clearance: PI - self.widest_pixel_angle(),
            }],
            ..InverseChart::default()
        }
    }
}

/// What [`render_little_planet`] made: how the raster frame agrees with the ray-cast one.
#[derive(Debug, Clone)]
pub struct Report {
    /// `compare(raster, raycast)`.
    pub raster_against_raycast: Comparison,
}

/// Renders scene `source` (a scene file or `builtin:NAME`) through a little planet looking
/// straight down from `eye` (the top of the image towards -z), `width` x `height` pixels, by
/// ray casting into `out` and by rasterisation, and compares the two. The scene's own
/// projection is ignored.
pub fn render_little_planet(
    source: &str,
    eye: DVec3,
    width: u32,
    height: u32,
    out: &Path,
) -> Result<Report> {
    let overrides = Overrides {
        width: Some(width),
        height: Some(height),
        ..Overrides::default()
    };
    let loaded = scene::load_with(source, &overrides)?;
    let frame = CameraFrame {
        position: eye,
        look_at: eye - DVec3::Y,
        up: -DVec3::Z,
    };
    let planet = LittlePlanet::new(&frame, 300.0, loaded.width, loaded.height)?;
    let prepared = PreparedScene::new(&loaded.scene);
    let render = |method| {
        let options = RenderOptions {
            method,
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        render::render(&prepared, &planet, &options).map(|rendered| rendered.frame)
    };
    let raycast = render(Method::Raycast)?;
    let raster = render(Method::Raster)?;
    write_color_png(&raycast, out, ColorEncoding::Linear)?;
    Ok(Report {
        raster_against_raycast: compare(&raster, &raycast)?,
    })
}
