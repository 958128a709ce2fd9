//! Omni-directional stereo (ODS): a 360 x 180 degree equirectangular panorama per eye, left
//! eye on top and right eye below, whose rays start on the circle of radius ipd/2 around the
//! eye, tangent to it (Peleg, Ben-Ezra and Pritch 2001; Google's "Rendering Omni-directional
//! Stereo Content"), with Blender Cycles' conventions.
//!
//! The ray of longitude `lon` and latitude `lat` (as in [`super::Equirectangular`]: zero at
//! the image centre, longitude growing to the right, latitude up) has the equirectangular
//! direction `D` and starts at `eye + s r(lat) side(lon)`, where `side(lon)` is the
//! horizontal unit vector to the right of `D`, `s` = -1 for the left eye and +1 for the
//! right (each eye sits on its side of every viewing direction), and `r(lat)` is ipd/2,
//! shrunk towards the poles by pole merging as Cycles' `spherical_stereo_transform` does
//! (intern/cycles/kernel/camera/projection.h; `interocular_offset` = -ipd/2 for the left eye,
//! +ipd/2 for the right, intern/cycles/scene/camera.cpp; parallel convergence, so the
//! direction is kept):
//!
//! ```text
//! a = |lat|;  r = ipd/2 if a <= from;  0 if a >= to;
//! otherwise ipd/2 * cos(pi/2 * (a - from) / (to - from))
//! ```
//!
//! The inverse: a point at horizontal distance `d` from the eye's vertical axis, height `h`
//! and longitude `theta` is seen at longitude `theta - s asin(r/d)` (the tangent from the
//! point to the circle of radius r) and at the latitude where `tan(lat) sqrt(d^2 - r(lat)^2)
//! = h`. Without merging r is constant and that is closed; with merging the left side grows
//! strictly with lat wherever d > r(lat), so the root is unique, closed outside the merge
//! band and found by bisection inside it.
//!
//! Degenerate cases: without merging, points within ipd/2 of the vertical axis (the eye
//! included) have no image (no tangent from inside the circle), and the poles are the
//! rows of rays going straight up and down from the circle; with merging, only the points of
//! the disc of radius ipd/2 around the eye at its height have none (they lie on or inside
//! the circle of every ray that reaches them horizontally); a point on the vertical axis
//! has the centre column only (the whole row sees it, as an equirectangular pole); at the
//! very poles (lat = +-90 degrees without merging) `side` is the limit along the column.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

use super::camera_basis::CameraBasis;
use super::chart::{axis_poles, InverseChart};
use super::image_coords::Resolution;
use super::panoramic::horizontal;
use super::params::positive_length;
use super::stereo::{KeepClear, Layout, StereoPair};
use super::{
    AnalyticInverse, BranchImage, CameraFrame, ImagePoint, NoInverse, Projection, SingleImage,
    Trilinear,
};
use crate::error::{Error, Result};
use crate::geometry::Ray;

/// Bisection steps of the latitude inside the merge band: the bracket is at most 90 degrees
/// wide, and 64 halvings bring it below the spacing of doubles there.
const BISECTIONS: u32 = 64;

/// An ODS panorama: both eyes, top-bottom.
pub type Ods = StereoPair<OdsEye>;

/// Pole merging: the eye offset fades from ipd/2 at latitude `from` to 0 at `to` (radians,
/// 0 <= from < to <= pi/2).
#[derive(Debug, Clone, Copy, PartialEq)]
struct PoleMerge {
    from: f64,
    to: f64,
}

/// One eye of an ODS panorama: a 360 x 180 degree equirectangular image of tangent rays.
#[derive(Debug, Clone, PartialEq)]
pub struct OdsEye {
    basis: CameraBasis,
    /// -1 for the left eye, +1 for the right.
    side: f64,
    /// ipd/2.
    radius: f64,
    merge: Option<PoleMerge>,
    radians_per_pixel: DVec2,
    resolution: Resolution,
}

/// Builds the top-bottom pair for a `width` x `height` image. `pole_merge` = [from, to] in
/// degrees. Errors: a degenerate frame, an empty image or an odd height, `ipd` not a
/// positive length, merge latitudes not 0 <= from < to <= 90.
pub fn ods(
    frame: &CameraFrame,
    ipd: f64,
    pole_merge: Option<[f64; 2]>,
    width: u32,
    height: u32,
) -> Result<Ods> {
    let radius = 0.5 * positive_length("ods", "ipd", ipd)?;
    let merge = pole_merge.map(merge_radians).transpose()?;
    let (w, h) = Layout::TopBottom.eye_size("ods", width, height)?;
    let basis = CameraBasis::new(frame)?;
    let resolution = Resolution::new(w, h)?;
    let eye = |side| OdsEye {
        basis,
        side,
        radius,
        merge,
        radians_per_pixel: DVec2::new(2.0 * PI, PI) / resolution.size(),
        resolution,
    };
    let keep_clear = if merge.is_some() {
        KeepClear::Disc {
            centre: basis.origin,
            axis: basis.up,
            radius,
        }
    } else {
        KeepClear::Cylinder {
            centre: basis.origin,
            axis: basis.up,
            radius,
        }
    };
    Ok(StereoPair::new(
        "ods",
        [eye(-1.0), eye(1.0)],
        Layout::TopBottom,
        Some(keep_clear),
    ))
}

fn merge_radians([from, to]: [f64; 2]) -> Result<PoleMerge> {
    if !(from.is_finite() && to.is_finite() && 0.0 <= from && from < to && to <= 90.0) {
        return Err(Error::new(format!(
            "ods pole merging needs 0 <= pole_merge_from < pole_merge_to <= 90 degrees, got \
             from {from} to {to}"
        )));
    }
    Ok(PoleMerge {
        from: from.to_radians(),
        to: to.to_radians(),
    })
}

/// The horizontal unit vector to the right of longitude `lon`.
fn right_of(lon: f64) -> DVec2 {
    DVec2::new(lon.cos(), -lon.sin())
}

impl OdsEye {
    /// The eye offset at latitude `lat` (see the module doc): ipd/2 faded by pole merging.
    fn offset(&self, lat: f64) -> f64 {
        let Some(PoleMerge { from, to }) = self.merge else {
            return self.radius;
        };
        let a = lat.abs();
        if a <= from {
            self.radius
        } else if a >= to {
            0.0
        } else {
            self.radius * (FRAC_PI_2 * (a - from) / (to - from)).cos()
        }
    }

    /// The horizontal distance from the ray's origin to the point, along the ray's
    /// horizontal direction, at latitude `lat`: sqrt(d^2 - r(lat)^2), zero where the point
    /// lies inside the circle.
    fn reach(&self, d: f64, lat: f64) -> f64 {
        let r = self.offset(lat);
        ((d - r) * (d + r)).max(0.0).sqrt()
    }

    /// The latitude of the ray through a point at horizontal distance `d > 0` and height
    /// `h != 0`: the root of tan(lat) reach(lat) = h (unique, see the module doc).
    fn latitude(&self, d: f64, h: f64) -> f64 {
        let closed = |r: f64| h.atan2(((d - r) * (d + r)).max(0.0).sqrt());
        let Some(PoleMerge { from, to }) = self.merge else {
            return closed(self.radius);
        };
        let inner = closed(self.radius);
        if d > self.radius && inner.abs() <= from {
            return inner;
        }
        let outer = closed(0.0);
        if outer.abs() >= to {
            return outer;
        }
        // The root lies in the band: bisect sin(lat) reach(lat) - h cos(lat), whose sign is
        // that of tan(lat) reach(lat) - h, over [from, to] on h's side.
        let (mut lo, mut hi) = (from, to);
        let residual = |a: f64| {
            let lat = a.copysign(h);
            lat.sin() * self.reach(d, lat) - h * lat.cos()
        };
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if (residual(mid) < 0.0) == (h > 0.0) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (0.5 * (lo + hi)).copysign(h)
    }
}

impl Projection for OdsEye {
    fn kind(&self) -> &'static str {
        "ods"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let angles = self.resolution.centred(pixel) * self.radians_per_pixel;
        let (lon, lat) = (angles.x, angles.y);
        let h = lat.cos() * horizontal(lon);
        let o = self.side * self.offset(lat) * right_of(lon);
        let origin = self.basis.origin + self.basis.to_world(DVec3::new(o.x, 0.0, o.y));
        let direction = self.basis.to_world(DVec3::new(h.x, lat.sin(), h.y));
        Some(Ray::new(origin, direction))
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// The one image of a point with its longitude taken in [-pi, pi); `None` on the singular
/// set of the module doc.
impl SingleImage for OdsEye {
    fn branch_image(&self, point: DVec3) -> Option<BranchImage> {
        let local = self.basis.to_local(point - self.basis.origin);
        let (d, h) = (DVec2::new(local.x, local.z).length(), local.y);
        let (lon, lat, reach) = if d == 0.0 {
            // On the axis: seen only where the offset has faded to zero, straight up or down.
            let lat = FRAC_PI_2.copysign(h);
            if h == 0.0 || self.offset(lat) != 0.0 {
                return None;
            }
            (0.0, lat, 0.0)
        } else {
            let lat = if h == 0.0 { 0.0 } else { self.latitude(d, h) };
            let r = self.offset(lat);
            if d <= r && (self.merge.is_none() || h == 0.0) {
                return None;
            }
            let theta = local.x.atan2(local.z);
            let lon = theta - self.side * (r / d).min(1.0).asin();
            (lon, lat, self.reach(d, lat))
        };
        let lon = (lon + PI).rem_euclid(2.0 * PI) - PI;
        let centred = DVec2::new(lon, lat) / self.radians_per_pixel;
        let image = ImagePoint {
            pixel: self.resolution.pixel(centred),
            t: reach.hypot(h),
        };
        Some(BranchImage { image, seen: true })
    }

    /// Longitude wraps every 360 degrees. The poles are those of the eye's equirectangular
    /// grid, seen from the eye: a point within angle `c` of the vertical axis from the eye
    /// is imaged within `c` of the pole (tan(lat) = h / reach >= h / d), so the clearance is
    /// conservative. The singular disc or cylinder is left to [`KeepClear`].
    fn chart(&self) -> InverseChart {
        let top = (0.5 * f64::from(self.resolution.height) - 0.5) * self.radians_per_pixel.y;
        InverseChart {
            clip: Vec::new(),
            period: Some(2.0 * PI / self.radians_per_pixel.x),
            poles: axis_poles(self.basis.origin, self.basis.up, -top, top),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::stereo::tests::{frame, near, EYE};

    /// The ray through `pixel`, by hand: the left eye is the top 360 x 180 half, the right
    /// the bottom; (lon, lat) from the tile position; origin ipd/2 to the eye's side of the
    /// direction.
    #[test]
    fn rays_of_given_pixels_are_the_tangent_rays() {
        let o = ods(&frame(), 0.064, None, 360, 360).unwrap();
        assert_eq!(o.resolution(), (360, 360));
        // Left eye, image centre: straight ahead (-z), from 0.032 to the left (-x).
        let r = o.ray(DVec2::new(180.0, 90.0)).unwrap();
        assert!(near(r.direction, DVec3::NEG_Z));
        assert!(near(r.origin, EYE + DVec3::new(-0.032, 0.0, 0.0)));
        // Right eye, centre of the bottom half: from 0.032 to the right.
        let r = o.ray(DVec2::new(180.0, 270.0)).unwrap();
        assert!(near(r.direction, DVec3::NEG_Z));
        assert!(near(r.origin, EYE + DVec3::new(0.032, 0.0, 0.0)));
        // Left eye looking a quarter turn right (+x): its left is the old forward, -z.
        let r = o.ray(DVec2::new(270.0, 90.0)).unwrap();
        assert!(near(r.direction, DVec3::X));
        assert!(near(r.origin, EYE + DVec3::new(0.0, 0.0, -0.032)));
        // Left eye looking back (+z, the left edge): its left is +x.
        let r = o.ray(DVec2::new(0.0, 90.0)).unwrap();
        assert!(near(r.direction, DVec3::Z));
        assert!(near(r.origin, EYE + DVec3::new(0.032, 0.0, 0.0)));
        // 45 degrees up, straight ahead, left eye: the offset is horizontal.
        let r = o.ray(DVec2::new(180.0, 45.0)).unwrap();
        let s = 0.5f64.sqrt();
        assert!(near(r.direction, DVec3::new(0.0, s, -s)));
        assert!(near(r.origin, EYE + DVec3::new(-0.032, 0.0, 0.0)));
    }

    /// Cycles' pole merging: the full offset up to `from`, cos(pi/2 fac) between, none
    /// beyond `to`.
    #[test]
    fn pole_merging_fades_the_offset() {
        let o = ods(&frame(), 0.064, Some([60.0, 75.0]), 360, 360).unwrap();
        let origin_at = |lat: f64| o.ray(DVec2::new(180.0, 90.0 - lat)).unwrap().origin;
        assert!(near(origin_at(50.0), EYE + DVec3::new(-0.032, 0.0, 0.0)));
        assert!(near(origin_at(-60.0), EYE + DVec3::new(-0.032, 0.0, 0.0)));
        let mid = 0.032 * std::f64::consts::FRAC_PI_4.cos();
        assert!(near(origin_at(67.5), EYE + DVec3::new(-mid, 0.0, 0.0)));
        assert!(near(origin_at(-67.5), EYE + DVec3::new(-mid, 0.0, 0.0)));
        assert!(near(origin_at(80.0), EYE));
    }

    /// A point straight ahead at distance 2: each eye turns by asin(r / d) towards it.
    #[test]
    fn a_point_ahead_is_seen_by_both_eyes_on_their_tangents() {
        let o = ods(&frame(), 0.064, None, 360, 360).unwrap();
        let mut out = Vec::new();
        o.project(EYE + DVec3::new(0.0, 0.0, -2.0), &mut out);
        let turn = (0.032f64 / 2.0).asin().to_degrees();
        assert_eq!(out.len(), 2);
        assert!((out[0].pixel - DVec2::new(180.0 + turn, 90.0)).length() < 1e-11);
        assert!((out[1].pixel - DVec2::new(180.0 - turn, 270.0)).length() < 1e-11);
        let reach = (4.0f64 - 0.032 * 0.032).sqrt();
        assert!((out[0].t - reach).abs() < 1e-14 && (out[1].t - reach).abs() < 1e-14);
    }

    #[test]
    fn degenerate_points() {
        let plain = ods(&frame(), 0.064, None, 64, 64).unwrap();
        let merged = ods(&frame(), 0.064, Some([60.0, 75.0]), 64, 64).unwrap();
        let images = |o: &Ods, p: DVec3| {
            let mut out = Vec::new();
            o.project(p, &mut out);
            out
        };
        // The eye, and a point inside the circle at its height: no image either way.
        for o in [&plain, &merged] {
            assert!(images(o, EYE).is_empty());
            assert!(images(o, EYE + DVec3::new(0.01, 0.0, 0.02)).is_empty());
        }
        // Above the eye within the circle: none without merging; with merging it is seen
        // near the pole, on the rays whose offset has faded below its distance.
        let above = EYE + DVec3::new(0.01, 1.0, 0.0);
        assert!(images(&plain, above).is_empty());
        assert_eq!(images(&merged, above).len(), 2);
        // On the axis: the centre column of the top row with merging, nothing without.
        let pole = EYE + DVec3::new(0.0, 3.0, 0.0);
        assert!(images(&plain, pole).is_empty());
        let seen = images(&merged, pole);
        assert_eq!(seen.len(), 2);
        assert_eq!(seen[0].pixel, DVec2::new(32.0, 0.0));
        assert!((seen[0].t - 3.0).abs() < 1e-15);
    }

    #[test]
    fn invalid_parameters_are_errors() {
        let f = frame();
        let message = |r: Result<Ods>| r.err().unwrap().message;
        assert!(message(ods(&f, 0.0, None, 8, 8)).starts_with("ods ipd must be a positive"));
        assert!(message(ods(&f, f64::NAN, None, 8, 8)).starts_with("ods ipd"));
        assert!(message(ods(&f, 0.064, None, 8, 7)).contains("even image height"));
        for merge in [[75.0, 60.0], [60.0, 60.0], [-1.0, 60.0], [60.0, 91.0]] {
            assert!(message(ods(&f, 0.064, Some(merge), 8, 8))
                .starts_with("ods pole merging needs 0 <= pole_merge_from"));
        }
        assert!(ods(&f, 0.064, Some([0.0, 90.0]), 8, 8).is_ok());
    }
}
