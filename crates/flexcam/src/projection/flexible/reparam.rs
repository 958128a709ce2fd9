//! Re-parameterisation (thesis 4.3): the map between image positions and the (u, v) domain
//! [0, 1]^2 of the control surfaces, in both directions (the inverse is what a scanline
//! renderer needs).
//!
//! Centred coordinates: the polar maps use p = (px, py) with the origin at the image centre,
//! y up, scaled so that the circle inscribed in the shorter image side is the unit circle
//! (the notes' correction: the thesis says [0, 1] and atan). Mercator scales x by the width
//! and y by the height, each to [-1, 1].
//!
//! Module `grid`: user-defined maps given by a grid of samples.

pub mod grid;

use std::f64::consts::{FRAC_PI_4, PI};
use std::sync::Arc;

use glam::DVec2;

pub use self::grid::{GridProblem, SampleInterpolation, UvGrid};
use super::super::image_coords::Resolution;
use super::presets::Magnifier;
use crate::error::{Error, Result};

/// A pixel <-> (u, v) map.
#[derive(Debug, Clone, PartialEq)]
pub enum Reparam {
    /// u = x / W, v = 1 - y / H: the image is the domain, v up.
    Linear,
    /// Polar fisheye: u = (atan2(py, px) + pi) / (2 pi), v = |p|; outside the unit circle
    /// there is no (u, v).
    Polar,
    /// Lens-like fisheye (thesis fig. 4.12): as `Polar` but v = r/4 + 3 r^2 / 4 with r = |p|,
    /// which magnifies the centre.
    Lens,
    /// Equisolid-angle (equal-area) fisheye, the model of most real fisheye lenses and of a
    /// photographed mirror ball (`max_angle` = pi): as `Polar`, but the image radius is
    /// proportional to sin(theta / 2) of the angle theta off the axis, r = sin(theta / 2) /
    /// sin(max_angle / 2), for volumes whose v is linear in that angle with v = 1 at
    /// `max_angle` (the fisheye preset, max_angle = fov / 2): v = 2 asin(r sin(max_angle /
    /// 2)) / max_angle. `max_angle` in radians, in (0, pi].
    Equisolid {
        /// Half the angle across the image circle, radians, in (0, pi].
        max_angle: f64,
    },
    /// Equiangular perspective, the map of an equi-angular cubemap face (EAC, as Blender
    /// Cycles' `EQUIANGULAR_CUBEMAP_FACE` and YouTube's cubemaps): for volumes whose (u, v)
    /// is linear on a pinhole's image plane (the perspective preset, horizontal field of
    /// view 2 `half_fov`), the angle off the axis, not its tangent, is linear in each image
    /// coordinate: x = (1/2 + a_x / (2 half_fov)) W with tan a_x = (2u - 1) tan(half_fov),
    /// and likewise in y with the vertical half angle h_y, tan h_y = tan(half_fov) H / W, so
    /// that the image frame sees what the perspective camera's frame sees. `half_fov` in
    /// radians, in (0, pi/2).
    Equiangular {
        /// Half the perspective camera's horizontal angle, radians, in (0, pi/2).
        half_fov: f64,
    },
    /// Mercator map: u = x / W; the image row's Mercator ordinate y_m = py * M(max_latitude),
    /// M(phi) = ln tan(pi/4 + phi/2), gives the latitude phi = atan(sinh(y_m)) and
    /// v = (phi / max_latitude + 1) / 2. So it expects surfaces whose v spans the latitudes
    /// [-max_latitude, max_latitude] linearly (the equirectangular preset with
    /// v_fov = 2 max_latitude). `max_latitude` in radians, in (0, pi/2).
    Mercator {
        /// The latitude at the image's top edge, radians, in (0, pi/2).
        max_latitude: f64,
    },
    /// Lambert cylindrical equal-area map: u = x / W; the image row's ordinate is
    /// proportional to sin(latitude), py = sin(phi) / sin(max_latitude), so equal image areas
    /// cover equal areas of the sphere. Surfaces as for `Mercator`; `max_latitude` in
    /// (0, pi/2] (the poles can be shown: sin stays finite there).
    EqualArea {
        /// The latitude at the image's top edge, radians, in (0, pi/2].
        max_latitude: f64,
    },
    /// The linear map seen through a circular magnifying lens (the `magnifier` preset's
    /// map; [`Magnifier`]): identity outside the circle.
    Magnifier(Magnifier),
    /// A user-defined map: (u, v) interpolated from a grid of samples over the image
    /// positions s = x / W, t = 1 - y / H (module `grid`); pixels whose (u, v) falls outside
    /// [0, 1]^2 see nothing.
    Grid(Arc<UvGrid>),
}

/// The names used in scene files, in order.
pub const REPARAM_NAMES: [&str; 8] = [
    "linear",
    "polar",
    "lens",
    "mercator",
    "equal_area",
    "equisolid",
    "equiangular",
    "grid",
];

/// The default top latitude of the Mercator map, degrees.
pub const DEFAULT_MERCATOR_LATITUDE: f64 = 85.0;

impl Reparam {
    /// The scene-file name.
    pub fn name(&self) -> &'static str {
        match self {
            Reparam::Linear => "linear",
            Reparam::Polar => "polar",
            Reparam::Lens => "lens",
            Reparam::Equisolid { .. } => "equisolid",
            Reparam::Equiangular { .. } => "equiangular",
            Reparam::Mercator { .. } => "mercator",
            Reparam::EqualArea { .. } => "equal_area",
            Reparam::Magnifier(_) => "magnifier",
            Reparam::Grid(_) => "grid",
        }
    }

    /// Errors: a Mercator latitude outside (0, 90) degrees (the Mercator ordinate is
    /// infinite at the pole), an equal-area one outside (0, 90], an equisolid angle outside
    /// (0, 180] (beyond 180 degrees off the axis sin(theta / 2) falls again: the map folds),
    /// an equiangular field of view outside (0, 180) degrees (a pinhole's image plane ends
    /// at 180).
    pub fn validate(&self) -> Result<()> {
        if let Reparam::Equiangular { half_fov } = *self {
            if !(half_fov > 0.0 && half_fov < 0.5 * PI) {
                return Err(Error::new(format!(
                    "flexible equiangular perspective fov must be in (0, 180) degrees, got {}",
                    2.0 * half_fov.to_degrees()
                )));
            }
            return Ok(());
        }
        if let Reparam::Equisolid { max_angle } = *self {
            if !(max_angle > 0.0 && max_angle <= PI) {
                return Err(Error::new(format!(
                    "flexible equisolid fisheye fov must be in (0, 360] degrees, got {}",
                    2.0 * max_angle.to_degrees()
                )));
            }
            return Ok(());
        }
        let (latitude, pole_allowed) = match *self {
            Reparam::Mercator { max_latitude } => (max_latitude, false),
            Reparam::EqualArea { max_latitude } => (max_latitude, true),
            Reparam::Magnifier(m) => return m.validate(),
            _ => return Ok(()),
        };
        let below_pole = latitude < 0.5 * PI || (pole_allowed && latitude == 0.5 * PI);
        if !(latitude > 0.0 && below_pole) {
            let bracket = if pole_allowed { ']' } else { ')' };
            return Err(Error::new(format!(
                "flexible {} max_latitude must be in (0, 90{bracket} degrees, got {}",
                self.name(),
                latitude.to_degrees()
            )));
        }
        Ok(())
    }

    /// The (u, v) of continuous pixel position `pixel`, or `None` outside the map's domain
    /// (outside the image for linear and Mercator, outside the unit circle for the polar
    /// maps, outside [0, 1]^2 for every map's (u, v)).
    pub fn to_uv(&self, resolution: &Resolution, pixel: DVec2) -> Option<DVec2> {
        let inside = match self {
            Reparam::Polar | Reparam::Lens | Reparam::Equisolid { .. } => {
                resolution.centred(pixel).length() <= circle_radius(resolution)
            }
            Reparam::Grid(_) => in_domain(image_position(resolution, pixel)),
            _ => true,
        };
        let uv = self.to_uv_continued(resolution, pixel);
        (inside && in_domain(uv)).then_some(uv)
    }

    /// [`Reparam::to_uv`] without its domain: the polar maps continue beyond the circle
    /// (v = |p| above 1; the equisolid map holds v at its value for 180 degrees off the
    /// axis, where its formula ends), a grid map beyond the image by its border cells, and
    /// (u, v) may leave [0, 1]^2. So two volumes on different maps can be blended over the
    /// whole image (see `volume::remapped`).
    pub fn to_uv_continued(&self, resolution: &Resolution, pixel: DVec2) -> DVec2 {
        let size = resolution.size();
        match self {
            Reparam::Linear => image_position(resolution, pixel),
            Reparam::Magnifier(m) => {
                image_position(resolution, m.sample_position(resolution, pixel))
            }
            Reparam::Grid(grid) => grid.uv(image_position(resolution, pixel)),
            Reparam::Polar | Reparam::Lens | Reparam::Equisolid { .. } => {
                let p = resolution.centred(pixel) / circle_radius(resolution);
                let r = p.length();
                let v = match *self {
                    Reparam::Lens => 0.25 * r + 0.75 * r * r,
                    Reparam::Equisolid { max_angle } => {
                        let s = (r * (0.5 * max_angle).sin()).min(1.0);
                        2.0 * s.asin() / max_angle
                    }
                    _ => r,
                };
                DVec2::new((p.y.atan2(p.x) + PI) / (2.0 * PI), v)
            }
            Reparam::Equiangular { half_fov } => {
                // Centred coordinates in [-1, 1] across the image, y up.
                let p = resolution.centred(pixel) / (0.5 * size);
                let half = half_angles(*half_fov, resolution);
                let tan_ratio = |p: f64, half: f64| (p * half).tan() / half.tan();
                DVec2::new(
                    0.5 + 0.5 * tan_ratio(p.x, half.x),
                    0.5 + 0.5 * tan_ratio(p.y, half.y),
                )
            }
            Reparam::Mercator { max_latitude } => {
                let py = resolution.centred(pixel).y / (0.5 * size.y);
                let latitude = (py * mercator(*max_latitude)).sinh().atan();
                DVec2::new(pixel.x / size.x, 0.5 * (latitude / max_latitude + 1.0))
            }
            Reparam::EqualArea { max_latitude } => {
                let py = resolution.centred(pixel).y / (0.5 * size.y);
                let latitude = (py * max_latitude.sin()).clamp(-1.0, 1.0).asin();
                DVec2::new(pixel.x / size.x, 0.5 * (latitude / max_latitude + 1.0))
            }
        }
    }

    /// The continuous pixel position of `uv` (inverse of [`Reparam::to_uv`]); `None` outside
    /// [0, 1]^2.
    pub fn to_pixel(&self, resolution: &Resolution, uv: DVec2) -> Option<DVec2> {
        if !in_domain(uv) {
            return None;
        }
        self.to_pixel_unbounded(resolution, uv)
    }

    /// [`Reparam::to_pixel`] extended beyond [0, 1]^2 by the same formulas. `None` where
    /// they are undefined: a lens-like v below -1/48 (no real radius), an equisolid angle
    /// |v| max_angle beyond 180 degrees (where the map folds back), a Mercator latitude
    /// (2v - 1) max_latitude of 90 degrees or more, a (u, v) whose grid inverse does not
    /// converge (see [`UvGrid::st`]).
    pub fn to_pixel_unbounded(&self, resolution: &Resolution, uv: DVec2) -> Option<DVec2> {
        let size = resolution.size();
        let pixel = match self {
            Reparam::Linear => DVec2::new(uv.x * size.x, (1.0 - uv.y) * size.y),
            Reparam::Magnifier(m) => {
                m.pixel_of(resolution, DVec2::new(uv.x * size.x, (1.0 - uv.y) * size.y))
            }
            Reparam::Grid(grid) => {
                let st = grid.st(uv)?;
                DVec2::new(st.x * size.x, (1.0 - st.y) * size.y)
            }
            Reparam::Polar | Reparam::Lens | Reparam::Equisolid { .. } => {
                let r = match *self {
                    // v = r/4 + 3 r^2/4  <=>  3 r^2 + r - 4 v = 0, the root in [0, 1].
                    Reparam::Lens => (-1.0 + (1.0 + 48.0 * uv.y).sqrt()) / 6.0,
                    Reparam::Equisolid { max_angle } => {
                        let theta = uv.y * max_angle;
                        if theta.abs() > PI {
                            return None;
                        }
                        (0.5 * theta).sin() / (0.5 * max_angle).sin()
                    }
                    _ => uv.y,
                };
                let azimuth = 2.0 * PI * uv.x - PI;
                let p = r * DVec2::new(azimuth.cos(), azimuth.sin());
                resolution.pixel(p * circle_radius(resolution))
            }
            Reparam::Equiangular { half_fov } => {
                let half = half_angles(*half_fov, resolution);
                let angle_ratio = |u: f64, half: f64| ((2.0 * u - 1.0) * half.tan()).atan() / half;
                let p = DVec2::new(angle_ratio(uv.x, half.x), angle_ratio(uv.y, half.y));
                resolution.pixel(p * 0.5 * size)
            }
            Reparam::Mercator { max_latitude } => {
                let latitude = (2.0 * uv.y - 1.0) * max_latitude;
                if latitude.abs() >= 0.5 * PI {
                    return None;
                }
                let py = mercator(latitude) / mercator(*max_latitude);
                let y = resolution.pixel(DVec2::new(0.0, py * 0.5 * size.y)).y;
                DVec2::new(uv.x * size.x, y)
            }
            Reparam::EqualArea { max_latitude } => {
                let latitude = (2.0 * uv.y - 1.0) * max_latitude;
                let py = latitude.sin() / max_latitude.sin();
                let y = resolution.pixel(DVec2::new(0.0, py * 0.5 * size.y)).y;
                DVec2::new(uv.x * size.x, y)
            }
        };
        pixel.is_finite().then_some(pixel)
    }

    /// The smallest and largest v over the pixel centres inside the map's domain, `None` when
    /// no pixel centre is inside it. The linear and Mercator maps take v from the row alone.
    pub fn v_range(&self, resolution: &Resolution) -> Option<(f64, f64)> {
        let columns = match self {
            Reparam::Linear
            | Reparam::Mercator { .. }
            | Reparam::EqualArea { .. }
            | Reparam::Equiangular { .. } => 1,
            Reparam::Polar
            | Reparam::Lens
            | Reparam::Equisolid { .. }
            | Reparam::Magnifier(_)
            | Reparam::Grid(_) => resolution.width,
        };
        let mut range: Option<(f64, f64)> = None;
        for y in 0..resolution.height {
            for x in 0..columns {
                let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                if let Some(uv) = self.to_uv(resolution, centre) {
                    let (lo, hi) = range.unwrap_or((uv.y, uv.y));
                    range = Some((lo.min(uv.y), hi.max(uv.y)));
                }
            }
        }
        range
    }
}

/// The image position (s, t) = (x / W, 1 - y / H) of pixel position `pixel`: the linear
/// map's (u, v), a grid map's argument.
fn image_position(resolution: &Resolution, pixel: DVec2) -> DVec2 {
    let size = resolution.size();
    DVec2::new(pixel.x / size.x, 1.0 - pixel.y / size.y)
}

/// Whether `uv` lies in the closed domain [0, 1]^2.
fn in_domain(uv: DVec2) -> bool {
    (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y)
}

/// The radius in pixels of the circle inscribed in the shorter image side (as `Fisheye`).
fn circle_radius(resolution: &Resolution) -> f64 {
    0.5 * f64::from(resolution.width.min(resolution.height))
}

/// The horizontal and vertical half angles of an equiangular map of horizontal half angle
/// `half_fov` on an image of `resolution`: the vertical one is the perspective camera's,
/// tan h_y = tan(half_fov) H / W.
fn half_angles(half_fov: f64, resolution: &Resolution) -> DVec2 {
    let size = resolution.size();
    DVec2::new(half_fov, (half_fov.tan() * size.y / size.x).atan())
}

/// The Mercator ordinate of latitude `phi`.
fn mercator(phi: f64) -> f64 {
    (FRAC_PI_4 + 0.5 * phi).tan().ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn res() -> Resolution {
        Resolution::new(200, 100).unwrap()
    }

    /// A grid map that squeezes the image towards its centre column and bends the rows.
    fn bent_grid(interpolation: SampleInterpolation) -> Reparam {
        let samples = (0..5)
            .flat_map(|j| (0..6).map(move |i| (i, j)))
            .map(|(i, j)| {
                let (s, t) = (f64::from(i) / 5.0, f64::from(j) / 4.0);
                DVec2::new(0.5 + 0.4 * (PI * (s - 0.5)).sin(), t * (0.9 + 0.1 * s))
            })
            .collect();
        Reparam::Grid(Arc::new(UvGrid::new(6, 5, samples, interpolation).unwrap()))
    }

    #[test]
    fn a_grid_of_the_image_positions_is_the_linear_map() {
        let samples = (0..3)
            .flat_map(|j| (0..3).map(move |i| DVec2::new(f64::from(i), f64::from(j)) / 2.0))
            .collect();
        let grid = UvGrid::new(3, 3, samples, SampleInterpolation::Bicubic).unwrap();
        let map = Reparam::Grid(Arc::new(grid));
        assert_eq!(map.name(), "grid");
        for pixel in [
            DVec2::new(0.0, 100.0),
            DVec2::new(73.25, 31.5),
            DVec2::new(200.0, 0.0),
        ] {
            let (a, b) = (
                map.to_uv(&res(), pixel).unwrap(),
                Reparam::Linear.to_uv(&res(), pixel).unwrap(),
            );
            assert!((a - b).length() < 1e-15, "{pixel}");
        }
        assert_eq!(map.to_uv(&res(), DVec2::new(-0.5, 50.0)), None);
        // Beyond the image the inverse continues the map.
        let outside = map
            .to_pixel_unbounded(&res(), DVec2::new(-0.25, 1.5))
            .unwrap();
        assert!(
            (outside - DVec2::new(-50.0, -50.0)).length() < 1e-9,
            "{outside}"
        );
    }

    #[test]
    fn a_grid_map_sees_nothing_where_its_uv_leaves_the_domain() {
        // u runs from -0.5 to 1.5 across the image: the outer quarters see nothing.
        let samples = vec![
            DVec2::new(-0.5, 0.0),
            DVec2::new(1.5, 0.0),
            DVec2::new(-0.5, 1.0),
            DVec2::new(1.5, 1.0),
        ];
        let grid = UvGrid::new(2, 2, samples, SampleInterpolation::Bilinear).unwrap();
        let map = Reparam::Grid(Arc::new(grid));
        assert_eq!(map.to_uv(&res(), DVec2::new(20.0, 50.0)), None);
        let uv = map.to_uv(&res(), DVec2::new(100.0, 50.0)).unwrap();
        assert!((uv - DVec2::splat(0.5)).length() < 1e-15);
        let (lo, hi) = map.v_range(&res()).unwrap();
        assert!(
            (lo - 0.005).abs() < 1e-15 && (hi - 0.995).abs() < 1e-15,
            "{lo} {hi}"
        );
    }

    #[test]
    fn linear_has_v_up_and_rejects_outside() {
        let r = Reparam::Linear;
        assert_eq!(r.to_uv(&res(), DVec2::new(0.0, 100.0)), Some(DVec2::ZERO));
        assert_eq!(r.to_uv(&res(), DVec2::new(200.0, 0.0)), Some(DVec2::ONE));
        assert_eq!(r.to_uv(&res(), DVec2::new(-0.1, 50.0)), None);
        assert_eq!(r.to_uv(&res(), DVec2::new(50.0, 100.5)), None);
    }

    #[test]
    fn polar_uses_centred_coordinates() {
        let r = Reparam::Polar;
        // Centre: radius 0. Right of centre on the circle: azimuth 0 -> u = 1/2.
        assert_eq!(r.to_uv(&res(), DVec2::new(100.0, 50.0)).unwrap().y, 0.0);
        let right = r.to_uv(&res(), DVec2::new(150.0, 50.0)).unwrap();
        assert!((right - DVec2::new(0.5, 1.0)).length() < 1e-15);
        // Above the centre: azimuth pi/2 -> u = 3/4, half way out -> v = 1/2.
        let up = r.to_uv(&res(), DVec2::new(100.0, 25.0)).unwrap();
        assert!((up - DVec2::new(0.75, 0.5)).length() < 1e-15);
        // Outside the inscribed circle: nothing.
        assert_eq!(r.to_uv(&res(), DVec2::new(10.0, 10.0)), None);
    }

    #[test]
    fn lens_follows_the_thesis_weights() {
        let p = Reparam::Lens
            .to_uv(&res(), DVec2::new(125.0, 50.0))
            .unwrap();
        assert!((p.y - (0.25 * 0.5 + 0.75 * 0.25)).abs() < 1e-15);
        assert_eq!(
            Reparam::Lens
                .to_uv(&res(), DVec2::new(150.0, 50.0))
                .unwrap()
                .y,
            1.0
        );
    }

    #[test]
    fn equisolid_radius_is_the_sine_of_half_the_angle() {
        // The mirror ball (max angle 180 degrees): r = sin(theta / 2), so half way out
        // (r = 1/2) is 60 degrees off the axis and r = sin(45) is 90 degrees.
        let ball = Reparam::Equisolid { max_angle: PI };
        assert!(ball.validate().is_ok());
        for (x, degrees) in [(125.0, 60.0), (100.0 + 50.0 * FRAC_PI_4.sin(), 90.0)] {
            let v = ball.to_uv(&res(), DVec2::new(x, 50.0)).unwrap().y;
            assert!((v * 180.0 - degrees).abs() < 1e-9, "{x}: {v}");
        }
        // A 150-degree lens (max angle 75): the rim is 75 degrees, the centre 0.
        let lens = Reparam::Equisolid {
            max_angle: 75f64.to_radians(),
        };
        assert_eq!(lens.to_uv(&res(), DVec2::new(150.0, 50.0)).unwrap().y, 1.0);
        assert_eq!(lens.to_uv(&res(), DVec2::new(100.0, 50.0)).unwrap().y, 0.0);
        // Unlike the equidistant map, the centre is magnified: v(1/2) < 1/2.
        assert!(lens.to_uv(&res(), DVec2::new(125.0, 50.0)).unwrap().y < 0.5);
        // Beyond 180 degrees the map folds: refused, and no pixel for such angles.
        for bad in [0.0, -1.0, PI + 1e-9, f64::NAN] {
            assert!(Reparam::Equisolid { max_angle: bad }.validate().is_err());
        }
        assert_eq!(ball.to_pixel_unbounded(&res(), DVec2::new(0.5, 1.01)), None);
    }

    #[test]
    fn equiangular_angles_are_linear_in_the_image() {
        // An equi-angular cubemap face: 90 degrees on a square image. A quarter of the width
        // right of the centre is 22.5 degrees off the axis, so u = (1 + tan 22.5) / 2 on the
        // image plane; the frame's edges stay the perspective camera's.
        let square = Resolution::new(100, 100).unwrap();
        let face = Reparam::Equiangular {
            half_fov: FRAC_PI_4,
        };
        assert!(face.validate().is_ok());
        let uv = face.to_uv(&square, DVec2::new(75.0, 25.0)).unwrap();
        let want = 0.5 + 0.5 * (0.5 * FRAC_PI_4).tan();
        assert!((uv - DVec2::splat(want)).length() < 1e-15, "{uv}");
        assert_eq!(
            face.to_uv(&square, DVec2::new(50.0, 50.0)),
            Some(DVec2::splat(0.5))
        );
        let corner = face.to_uv(&square, DVec2::new(100.0, 0.0)).unwrap();
        assert!((corner - DVec2::new(1.0, 1.0)).length() < 1e-15, "{corner}");
        // On a 2:1 image the vertical half angle is the pinhole's: tan = tan(45) / 2, and the
        // row a quarter of the height from the top is half that angle up.
        let wide = Reparam::Equiangular {
            half_fov: FRAC_PI_4,
        };
        let v = wide.to_uv(&res(), DVec2::new(100.0, 25.0)).unwrap().y;
        let half_y = 0.5f64.atan();
        assert!((v - (0.5 + 0.5 * (0.5 * half_y).tan() / half_y.tan())).abs() < 1e-15);
        for bad in [0.0, -0.1, 0.5 * PI, f64::NAN] {
            assert!(Reparam::Equiangular { half_fov: bad }.validate().is_err());
        }
    }

    #[test]
    fn mercator_centre_row_is_the_equator_and_edges_are_max_latitude() {
        let r = Reparam::Mercator {
            max_latitude: 80f64.to_radians(),
        };
        assert!(r.validate().is_ok());
        let centre = r.to_uv(&res(), DVec2::new(100.0, 50.0)).unwrap();
        assert!((centre - DVec2::new(0.5, 0.5)).length() < 1e-15);
        let top = r.to_uv(&res(), DVec2::new(0.0, 0.0)).unwrap();
        assert!((top - DVec2::new(0.0, 1.0)).length() < 1e-12);
        // Mercator stretches high latitudes: a quarter of the way down is above 40 degrees.
        let q = r.to_uv(&res(), DVec2::new(0.0, 25.0)).unwrap();
        assert!(q.y > 0.75);
        for bad in [0.0, 90f64.to_radians(), f64::NAN] {
            assert!(Reparam::Mercator { max_latitude: bad }.validate().is_err());
        }
    }

    #[test]
    fn equal_area_ordinate_is_proportional_to_the_sine_of_the_latitude() {
        // Lambert's cylindrical equal-area map: y = R sin(phi). With the top row at 90
        // degrees, the row a quarter of the height below the top (py = 1/2) is at 30 degrees.
        let r = Reparam::EqualArea {
            max_latitude: 0.5 * PI,
        };
        assert!(r.validate().is_ok());
        for (row, degrees) in [(25.0, 30.0), (50.0, 0.0), (0.0, 90.0), (100.0, -90.0)] {
            let uv = r.to_uv(&res(), DVec2::new(10.0, row)).unwrap();
            let latitude = (2.0 * uv.y - 1.0) * 0.5 * PI;
            assert!((latitude.to_degrees() - degrees).abs() < 1e-9, "{row}");
        }
        // A 60-degree map: the top row is 60 degrees, row 25 has sin(phi) = sin(60)/2.
        let r = Reparam::EqualArea {
            max_latitude: 60f64.to_radians(),
        };
        let uv = r.to_uv(&res(), DVec2::new(0.0, 25.0)).unwrap();
        let latitude = (2.0 * uv.y - 1.0) * 60f64.to_radians();
        assert!((latitude.sin() - 0.5 * 60f64.to_radians().sin()).abs() < 1e-12);
        for bad in [0.0, 91f64.to_radians(), f64::NAN] {
            assert!(Reparam::EqualArea { max_latitude: bad }.validate().is_err());
        }
    }

    #[test]
    fn every_map_round_trips() {
        let maps = [
            Reparam::Linear,
            Reparam::Polar,
            Reparam::Lens,
            Reparam::Equisolid { max_angle: PI },
            Reparam::Equisolid { max_angle: 0.7 },
            Reparam::Equiangular {
                half_fov: 0.25 * PI,
            },
            Reparam::Equiangular { half_fov: 1.5 },
            Reparam::Mercator { max_latitude: 1.2 },
            Reparam::EqualArea { max_latitude: 1.2 },
            Reparam::EqualArea {
                max_latitude: 0.5 * PI,
            },
            bent_grid(SampleInterpolation::Bilinear),
            bent_grid(SampleInterpolation::Bicubic),
        ];
        for map in maps {
            for pixel in [
                DVec2::new(100.0, 50.0),
                DVec2::new(73.25, 31.5),
                DVec2::new(120.0, 80.0),
            ] {
                let uv = map.to_uv(&res(), pixel).unwrap();
                let back = map.to_pixel(&res(), uv).unwrap();
                assert!((back - pixel).length() < 1e-9, "{map:?}: {pixel} -> {back}");
            }
            assert_eq!(map.to_pixel(&res(), DVec2::new(1.5, 0.5)), None);
        }
    }
}
