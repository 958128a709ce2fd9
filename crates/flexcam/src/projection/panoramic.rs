//! The panoramas: equirectangular (latitude linear in y) and cylindrical (height on a unit
//! cylinder linear in y). Both have longitude linear in x, zero at the image centre (the
//! look_at direction), increasing to the right. Rays exist for every pixel position, also
//! outside the image; ray directions are unit length, so `t` is the distance from the eye.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::camera_basis::CameraBasis;
use super::chart::{axis_poles, InverseChart};
use super::image_coords::Resolution;
use super::params::{angle_radians, UpTo};
use super::{
    AnalyticInverse, BranchImage, CameraFrame, ImagePoint, NoInverse, Projection, Projector,
    SingleImage, StageKey, StagedInverse, Trilinear,
};
use crate::error::Result;
use crate::geometry::Ray;

/// The longitude of camera-local direction `local` in [-pi, pi): zero straight ahead,
/// positive to the right. The half-open range gives a 360-degree panorama exactly one image
/// column per direction (straight behind is the left edge, x = 0). `None` on the vertical
/// axis, where the longitude is undefined.
fn longitude(local: DVec3) -> Option<f64> {
    if local.x == 0.0 && local.z == 0.0 {
        return None;
    }
    let lon = local.x.atan2(local.z);
    Some(if lon >= PI { -PI } else { lon })
}

/// The camera-local horizontal unit direction at longitude `lon`.
pub(super) fn horizontal(lon: f64) -> DVec2 {
    DVec2::new(lon.sin(), lon.cos())
}

/// The horizontal unit direction of each image column `columns` (continuous x positions)
/// of an image whose longitude is linear in x at `radians_per_pixel`: what a separable
/// panorama's `projector_grid_into` computes once per column.
fn column_directions(
    resolution: &Resolution,
    columns: &[f64],
    radians_per_pixel: f64,
) -> Vec<DVec2> {
    columns
        .iter()
        .map(|&x| horizontal(resolution.centred(DVec2::new(x, 0.0)).x * radians_per_pixel))
        .collect()
}

/// Longitude linear in x over `h_fov`, latitude linear in y over `v_fov` (top row at
/// +v_fov/2). The defaults of the scene format, 360 x 180, image the whole sphere.
#[derive(Debug, Clone, PartialEq)]
pub struct Equirectangular {
    basis: CameraBasis,
    radians_per_pixel: DVec2,
    resolution: Resolution,
}

impl Equirectangular {
    /// Errors: a degenerate frame, an empty image, `h_fov` not in (0, 360], `v_fov` not in
    /// (0, 180].
    pub fn new(
        frame: &CameraFrame,
        h_fov_degrees: f64,
        v_fov_degrees: f64,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let h_fov = angle_radians(
            "equirectangular",
            "h_fov",
            h_fov_degrees,
            UpTo::Including(360.0),
        )?;
        let v_fov = angle_radians(
            "equirectangular",
            "v_fov",
            v_fov_degrees,
            UpTo::Including(180.0),
        )?;
        let resolution = Resolution::new(width, height)?;
        Ok(Equirectangular {
            basis: CameraBasis::new(frame)?,
            radians_per_pixel: DVec2::new(h_fov, v_fov) / resolution.size(),
            resolution,
        })
    }
}

impl Projection for Equirectangular {
    fn kind(&self) -> &'static str {
        "equirectangular"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let angles = self.resolution.centred(pixel) * self.radians_per_pixel;
        let (lon, lat) = (angles.x, angles.y);
        let h = lat.cos() * horizontal(lon);
        let direction = self.basis.to_world(DVec3::new(h.x, lat.sin(), h.y));
        Some(Ray::new(self.basis.origin, direction))
    }

    /// Longitude depends on the column alone and latitude on the row alone: their sines and
    /// cosines are taken once per column and per row, then combined exactly as
    /// [`Equirectangular::ray`] combines them (the same bits).
    fn projector_grid_into(
        &self,
        columns: &[f64],
        rows: &[f64],
        stride: usize,
        out: &mut [Option<Projector>],
    ) {
        let longitudes = column_directions(&self.resolution, columns, self.radians_per_pixel.x);
        for (j, &y) in rows.iter().enumerate() {
            let lat = self.resolution.centred(DVec2::new(0.0, y)).y * self.radians_per_pixel.y;
            let (sin, cos) = (lat.sin(), lat.cos());
            for (i, h) in longitudes.iter().enumerate() {
                let h = cos * *h;
                let direction = self.basis.to_world(DVec3::new(h.x, sin, h.y));
                out[j * stride + i] =
                    Some(Projector::Straight(Ray::new(self.basis.origin, direction)));
            }
        }
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// The one image of a point with its longitude taken in [-pi, pi): for h_fov = 360 that lies
/// in the image, otherwise it may lie left or right of it. Degenerate: the eye has no image;
/// a point straight above or below the eye (a pole, seen by a whole row) has the centre
/// column only.
impl SingleImage for Equirectangular {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let offset = point - self.basis.origin;
        let angles = Equirectangular::angles(self.basis.to_local(offset))?;
        let image = ImagePoint {
            pixel: StagedInverse::pixel(self, angles),
            t: offset.length(),
        };
        Some(BranchImage { image, seen: true })
    }

    /// Longitude wraps every 360 degrees; the poles straight up and down are singular.
    fn chart(&self) -> InverseChart {
        let top = (0.5 * f64::from(self.resolution.height) - 0.5) * self.radians_per_pixel.y;
        InverseChart {
            clip: Vec::new(),
            period: Some(2.0 * PI / self.radians_per_pixel.x),
            poles: axis_poles(self.basis.origin, self.basis.up, -top, top),
        }
    }

    fn staged(&self) -> Option<&dyn StagedInverse> {
        Some(self)
    }
}

impl Equirectangular {
    /// The longitude and latitude of camera-local offset `local`; `None` at the eye.
    fn angles(local: DVec3) -> Option<DVec2> {
        if local == DVec3::ZERO {
            return None;
        }
        let lon = longitude(local).unwrap_or(0.0);
        let lat = local.y.atan2(DVec2::new(local.x, local.z).length());
        Some(DVec2::new(lon, lat))
    }
}

/// Longitude and latitude (two `atan2` and a square root) depend on the eye and its frame
/// alone; the pixel divides them by the angle per pixel.
impl StagedInverse for Equirectangular {
    fn key(&self) -> StageKey {
        StageKey::new("equirectangular", &self.basis)
    }

    fn coordinates(&self, point: DVec3) -> Option<DVec2> {
        Equirectangular::angles(self.basis.to_local(point - self.basis.origin))
    }

    fn pixel(&self, angles: DVec2) -> DVec2 {
        self.resolution.pixel(angles / self.radians_per_pixel)
    }
}

/// Longitude linear in x over `h_fov`; y maps linearly to the height on a unit cylinder
/// around the vertical axis, height = (0.5 - y/H) * 2 tan(v_fov/2), so tan(latitude) is linear
/// in y and `v_fov` is the vertical angle at the image centre.
#[derive(Debug, Clone, PartialEq)]
pub struct Cylindrical {
    basis: CameraBasis,
    radians_per_pixel: f64,
    height_per_pixel: f64,
    resolution: Resolution,
}

impl Cylindrical {
    /// Errors: a degenerate frame, an empty image, `h_fov` not in (0, 360], `v_fov` not in
    /// (0, 180).
    pub fn new(
        frame: &CameraFrame,
        h_fov_degrees: f64,
        v_fov_degrees: f64,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let h_fov = angle_radians(
            "cylindrical",
            "h_fov",
            h_fov_degrees,
            UpTo::Including(360.0),
        )?;
        let v_fov = angle_radians("cylindrical", "v_fov", v_fov_degrees, UpTo::Below(180.0))?;
        let resolution = Resolution::new(width, height)?;
        Ok(Cylindrical {
            basis: CameraBasis::new(frame)?,
            radians_per_pixel: h_fov / f64::from(width),
            height_per_pixel: 2.0 * (0.5 * v_fov).tan() / f64::from(height),
            resolution,
        })
    }
}

impl Projection for Cylindrical {
    fn kind(&self) -> &'static str {
        "cylindrical"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let centred = self.resolution.centred(pixel);
        let h = horizontal(centred.x * self.radians_per_pixel);
        let height = centred.y * self.height_per_pixel;
        let direction = self
            .basis
            .to_world(DVec3::new(h.x, height, h.y))
            .normalize();
        Some(Ray::new(self.basis.origin, direction))
    }

    /// Longitude depends on the column alone: its sine and cosine are taken once per column
    /// and combined with each row's height exactly as [`Cylindrical::ray`] does (the same
    /// bits).
    fn projector_grid_into(
        &self,
        columns: &[f64],
        rows: &[f64],
        stride: usize,
        out: &mut [Option<Projector>],
    ) {
        let longitudes = column_directions(&self.resolution, columns, self.radians_per_pixel);
        for (j, &y) in rows.iter().enumerate() {
            let height = self.resolution.centred(DVec2::new(0.0, y)).y * self.height_per_pixel;
            for (i, h) in longitudes.iter().enumerate() {
                let direction = self
                    .basis
                    .to_world(DVec3::new(h.x, height, h.y))
                    .normalize();
                out[j * stride + i] =
                    Some(Projector::Straight(Ray::new(self.basis.origin, direction)));
            }
        }
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// The one image of a point with its longitude taken in [-pi, pi) (see [`Equirectangular`]'s
/// branch); the row may lie above or below the image. Degenerate: points on the cylinder's
/// axis (the eye and the poles straight above or below it, at infinite height) have no
/// image.
impl SingleImage for Cylindrical {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let offset = point - self.basis.origin;
        let coordinates = Cylindrical::coordinates_of(self.basis.to_local(offset))?;
        let image = ImagePoint {
            pixel: StagedInverse::pixel(self, coordinates),
            t: offset.length(),
        };
        Some(BranchImage { image, seen: true })
    }

    /// Longitude wraps every 360 degrees; the poles (at infinite height) are singular.
    fn chart(&self) -> InverseChart {
        let top = ((0.5 * f64::from(self.resolution.height) - 0.5) * self.height_per_pixel).atan();
        InverseChart {
            clip: Vec::new(),
            period: Some(2.0 * PI / self.radians_per_pixel),
            poles: axis_poles(self.basis.origin, self.basis.up, -top, top),
        }
    }

    fn staged(&self) -> Option<&dyn StagedInverse> {
        Some(self)
    }
}

impl Cylindrical {
    /// The longitude and height on the unit cylinder of camera-local offset `local`;
    /// `None` on the cylinder's axis.
    fn coordinates_of(local: DVec3) -> Option<DVec2> {
        let lon = longitude(local)?;
        let height = local.y / DVec2::new(local.x, local.z).length();
        Some(DVec2::new(lon, height))
    }
}

/// Longitude and height (an `atan2` and a square root) depend on the eye and its frame
/// alone; the pixel divides them by the angle and the height per pixel.
impl StagedInverse for Cylindrical {
    fn key(&self) -> StageKey {
        StageKey::new("cylindrical", &self.basis)
    }

    fn coordinates(&self, point: DVec3) -> Option<DVec2> {
        Cylindrical::coordinates_of(self.basis.to_local(point - self.basis.origin))
    }

    fn pixel(&self, coordinates: DVec2) -> DVec2 {
        let (lon, height) = (coordinates.x, coordinates.y);
        let centred = DVec2::new(lon / self.radians_per_pixel, height / self.height_per_pixel);
        self.resolution.pixel(centred)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The projectors of a grid of positions, as `projector_grid_into` writes them into a
    /// buffer of `stride` columns, against one `projector` call per position: equal bit
    /// for bit, and the entries past each row's columns untouched.
    fn grid_is_per_pixel(projection: &dyn Projection, columns: &[f64], rows: &[f64]) {
        let stride = columns.len() + 2;
        let marker = Some(Projector::Straight(Ray::new(DVec3::ONE, DVec3::ONE)));
        let mut out = vec![marker.clone(); rows.len() * stride];
        projection.projector_grid_into(columns, rows, stride, &mut out);
        for (j, &y) in rows.iter().enumerate() {
            for (i, &x) in columns.iter().enumerate() {
                let want = projection.projector(DVec2::new(x, y));
                assert_eq!(out[j * stride + i], want, "({x}, {y})");
            }
            for i in columns.len()..stride {
                assert_eq!(out[j * stride + i], marker);
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        /// Per-column and per-row trigonometry gives the per-pixel projectors exactly, at
        /// any field of view, frame and image size, including positions outside the image.
        #[test]
        fn grid_projectors_are_the_per_pixel_ones(
            h_fov in 1.0f64..=360.0,
            v_fov in 1.0f64..179.0,
            (width, height) in (1u32..400, 1u32..300),
            look in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            x0 in -20.0f64..420.0,
            y0 in -20.0f64..320.0,
        ) {
            let look_at = DVec3::new(look.0, look.1, look.2);
            prop_assume!(look_at.length() > 0.1 && look_at.cross(DVec3::Y).length() > 0.05);
            let frame = CameraFrame { position: DVec3::ZERO, look_at, up: DVec3::Y };
            let columns: Vec<f64> = (0..7).map(|i| x0 + 1.37 * f64::from(i)).collect();
            let rows: Vec<f64> = (0..5).map(|j| y0 + 0.91 * f64::from(j)).collect();
            let e = Equirectangular::new(&frame, h_fov, v_fov, width, height).unwrap();
            grid_is_per_pixel(&e, &columns, &rows);
            let c = Cylindrical::new(&frame, h_fov, v_fov, width, height).unwrap();
            grid_is_per_pixel(&c, &columns, &rows);
        }
    }

    /// Degenerate grids: no columns or no rows write nothing.
    #[test]
    fn empty_grids_write_nothing() {
        let e = Equirectangular::new(&frame(), 360.0, 180.0, 36, 18).unwrap();
        let mut out = vec![None; 4];
        e.projector_grid_into(&[], &[1.5, 2.5], 2, &mut out);
        e.projector_grid_into(&[1.5, 2.5], &[], 2, &mut out);
        assert!(out.iter().all(Option::is_none));
    }

    fn frame() -> CameraFrame {
        CameraFrame {
            position: DVec3::new(1.0, 2.0, 3.0),
            look_at: DVec3::new(1.0, 2.0, 2.0),
            up: DVec3::Y,
        }
    }

    fn near(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-14
    }

    #[test]
    fn equirectangular_closed_forms() {
        let e = Equirectangular::new(&frame(), 360.0, 180.0, 360, 180).unwrap();
        assert!(near(
            e.ray(DVec2::new(180.0, 90.0)).unwrap().direction,
            DVec3::NEG_Z
        ));
        // x = 0 looks straight backwards for h_fov = 360.
        assert!(near(
            e.ray(DVec2::new(0.0, 90.0)).unwrap().direction,
            DVec3::Z
        ));
        // Longitude increases to the right: a quarter turn right is +x.
        assert!(near(
            e.ray(DVec2::new(270.0, 90.0)).unwrap().direction,
            DVec3::X
        ));
        // The top row is +v_fov/2 = straight up.
        assert!(near(
            e.ray(DVec2::new(35.0, 0.0)).unwrap().direction,
            DVec3::Y
        ));
        let narrow = Equirectangular::new(&frame(), 90.0, 60.0, 90, 60).unwrap();
        let top = narrow.ray(DVec2::new(45.0, 0.0)).unwrap().direction;
        let lat = 30f64.to_radians();
        assert!(near(top, DVec3::new(0.0, lat.sin(), -lat.cos())));
    }

    #[test]
    fn equirectangular_behind_maps_to_the_left_edge_once() {
        let e = Equirectangular::new(&frame(), 360.0, 180.0, 360, 180).unwrap();
        let mut out = Vec::new();
        e.project(DVec3::new(1.0, 2.0, 7.0), &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].pixel - DVec2::new(0.0, 90.0)).length() < 1e-12);
        assert!((out[0].t - 4.0).abs() < 1e-15);
    }

    #[test]
    fn equirectangular_degenerate_points() {
        let e = Equirectangular::new(&frame(), 360.0, 180.0, 360, 180).unwrap();
        let mut out = Vec::new();
        e.project(DVec3::new(1.0, 2.0, 3.0), &mut out); // the eye
        assert!(out.is_empty());
        e.project(DVec3::new(1.0, 5.0, 3.0), &mut out); // north pole: centre column, top row
        assert_eq!(
            out,
            vec![ImagePoint {
                pixel: DVec2::new(180.0, 0.0),
                t: 3.0
            }]
        );
        let ray = e.ray(out[0].pixel).unwrap();
        assert!(near(ray.at(out[0].t), DVec3::new(1.0, 5.0, 3.0)));
    }

    #[test]
    fn cylindrical_closed_forms() {
        let c = Cylindrical::new(&frame(), 180.0, 90.0, 200, 100).unwrap();
        assert!(near(
            c.ray(DVec2::new(100.0, 50.0)).unwrap().direction,
            DVec3::NEG_Z
        ));
        // Top row at height tan(v_fov/2) = 1 on the unit cylinder: 45 degrees up.
        let top = c.ray(DVec2::new(100.0, 0.0)).unwrap().direction;
        assert!(near(top, DVec3::new(0.0, 1.0, -1.0).normalize()));
        // Height is linear in y: a quarter of the way down is height 0.5.
        let quarter = c.ray(DVec2::new(100.0, 25.0)).unwrap().direction;
        assert!(near(quarter, DVec3::new(0.0, 0.5, -1.0).normalize()));
        // The right edge is 90 degrees to the right.
        assert!(near(
            c.ray(DVec2::new(200.0, 50.0)).unwrap().direction,
            DVec3::X
        ));
    }

    #[test]
    fn cylindrical_axis_points_have_no_image() {
        let c = Cylindrical::new(&frame(), 360.0, 120.0, 64, 32).unwrap();
        let mut out = Vec::new();
        c.project(DVec3::new(1.0, 2.0, 3.0), &mut out); // the eye
        c.project(DVec3::new(1.0, 9.0, 3.0), &mut out); // north pole
        c.project(DVec3::new(1.0, -9.0, 3.0), &mut out); // south pole
        assert!(out.is_empty());
        c.project(DVec3::new(1.0, 9.0, 2.0), &mut out); // steep but off the axis
        assert_eq!(out.len(), 1);
        assert!(out[0].pixel.y < 0.0, "above the image, unclipped");
    }

    #[test]
    fn invalid_fields_of_view_are_errors() {
        let f = frame();
        let cases = [
            Equirectangular::new(&f, 361.0, 90.0, 8, 8).err(),
            Equirectangular::new(&f, 90.0, 181.0, 8, 8).err(),
            Equirectangular::new(&f, 0.0, 90.0, 8, 8).err(),
            Cylindrical::new(&f, 360.5, 90.0, 8, 8).err(),
            Cylindrical::new(&f, 90.0, 180.0, 8, 8).err(),
            Cylindrical::new(&f, 90.0, f64::NAN, 8, 8).err(),
        ];
        let messages: Vec<String> = cases.into_iter().map(|e| e.unwrap().message).collect();
        assert!(messages[0].starts_with("equirectangular h_fov must be in (0, 360]"));
        assert!(messages[1].starts_with("equirectangular v_fov must be in (0, 180]"));
        assert!(messages[2].starts_with("equirectangular h_fov"));
        assert!(messages[3].starts_with("cylindrical h_fov must be in (0, 360]"));
        assert!(messages[4].starts_with("cylindrical v_fov must be in (0, 180)"));
        assert!(messages[5].starts_with("cylindrical v_fov"));
        assert!(Equirectangular::new(&f, 360.0, 180.0, 8, 8).is_ok());
    }
}
