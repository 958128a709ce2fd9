//! Photo reprojection (thesis 9.4: "spherical coordinates through Q1, then Q2, resample"):
//! an equirectangular photo of the surroundings seen through any projection.
//!
//! The photo is a panorama of directions: its column x has longitude
//! lambda = (x / W - 1/2) 2 pi and its row y latitude phi = (1/2 - y / H) pi (pixel edges;
//! centres at + 1/2), in the world frame with longitude 0 along -z, longitude 90 degrees
//! along +x and latitude 90 degrees along +y (the orientation of an equirectangular camera
//! at any position looking along -z with up +y, which therefore gets the photo back).
//!
//! Each output pixel takes the direction in which its projector leaves the viewing volume
//! (a straight ray's direction; the last segment of a polyline projector; the end tangent
//! P2 - P1 of a quadratic one): the photo is at infinity, so only that direction matters.
//! It is sampled bilinearly between the four nearest pixel centres, wrapping in longitude
//! and clamping at the poles' rows. With `spp` > 1 the samples of the ray caster's pattern
//! are averaged. Pixels without a projector (outside a fisheye's circle, say) get
//! `background`.

use std::f64::consts::PI;

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

use super::raycast::sampling::SamplePattern;
use super::{Frame, LinearImage};
use crate::error::{Error, Result};
use crate::projection::projector::quadratic_tangent;
use crate::projection::{Projection, Projector};

/// An equirectangular photo in linear RGB.
#[derive(Debug, Clone, PartialEq)]
pub struct EquirectPhoto {
    image: LinearImage,
}

impl EquirectPhoto {
    /// Errors: an image of zero width or height, or pixel data of the wrong length.
    pub fn new(image: LinearImage) -> Result<Self> {
        let n = image.width as usize * image.height as usize;
        if n == 0 || image.pixels.len() != n {
            return Err(Error::new(format!(
                "an equirectangular photo needs a non-empty {} x {} image with one colour per \
                 pixel, got {} colours",
                image.width,
                image.height,
                image.pixels.len()
            )));
        }
        Ok(EquirectPhoto { image })
    }

    /// The continuous photo position (x, y) of world direction `d` (see the module).
    /// Degenerate case: straight up or down the longitude is undefined and taken as 0 (on
    /// the clamped top or bottom row every column is near the pole).
    pub fn position(&self, d: DVec3) -> DVec2 {
        let longitude = if d.x == 0.0 && d.z == 0.0 {
            0.0
        } else {
            d.x.atan2(-d.z)
        };
        let latitude = d.y.atan2(d.x.hypot(d.z));
        let (w, h) = (f64::from(self.image.width), f64::from(self.image.height));
        DVec2::new(
            (longitude / (2.0 * PI) + 0.5) * w,
            (0.5 - latitude / PI) * h,
        )
    }

    /// The bilinear sample at continuous photo position `p` (pixel centres at + 1/2):
    /// columns wrap round, rows clamp to the first and last.
    pub fn sample(&self, p: DVec2) -> Vec3 {
        let (w, h) = (self.image.width as i64, self.image.height as i64);
        let (fx, fy) = (p.x - 0.5, p.y - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (ax, ay) = ((fx - x0) as f32, (fy - y0) as f32);
        let texel = |x: i64, y: i64| {
            let x = x.rem_euclid(w);
            let y = y.clamp(0, h - 1);
            self.image.pixels[(y * w + x) as usize]
        };
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = texel(x0, y0).lerp(texel(x0 + 1, y0), ax);
        let bottom = texel(x0, y0 + 1).lerp(texel(x0 + 1, y0 + 1), ax);
        top.lerp(bottom, ay)
    }

    /// The photo's colour in world direction `d`.
    pub fn look(&self, d: DVec3) -> Vec3 {
        self.sample(self.position(d))
    }
}

/// The direction in which `projector` leaves the volume; `None` when it is a point.
pub fn exit_direction(projector: &Projector) -> Option<DVec3> {
    let d = match projector {
        Projector::Straight(ray) => ray.direction,
        Projector::Polyline(points) => points
            .windows(2)
            .rev()
            .map(|w| w[1] - w[0])
            .find(|d| *d != DVec3::ZERO)?,
        Projector::QuadraticBezier(p) => {
            let end = quadratic_tangent(p, 1.0);
            // P2 = P1: the end tangent vanishes; the curve leaves along P2 - P0.
            if end == DVec3::ZERO {
                p[2] - p[0]
            } else {
                end
            }
        }
    };
    (d != DVec3::ZERO && d.is_finite()).then_some(d)
}

/// The photo seen through `projection`, `spp` samples per pixel (at least 1), pixels without
/// a projector set to `background`. Only the colour of the frame is meaningful (depth is
/// infinite and ids 0: the photo is at infinity). Fails only when the frame's memory cannot
/// be had (module `try_alloc`).
pub fn reproject(
    photo: &EquirectPhoto,
    projection: &dyn Projection,
    spp: u32,
    background: Vec3,
) -> Result<Frame> {
    let (width, height) = projection.resolution();
    let pattern = SamplePattern::new(spp);
    let mut frame = Frame::try_new(width, height, background)?;
    frame
        .color
        .par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, colour) in row.iter_mut().enumerate() {
                let corner = DVec2::new(x as f64, y as f64);
                let seen: Vec<Vec3> = pattern
                    .offsets
                    .iter()
                    .filter_map(|o| projection.projector(corner + *o))
                    .filter_map(|p| exit_direction(&p))
                    .map(|d| photo.look(d))
                    .collect();
                if !seen.is_empty() {
                    // Samples without a projector count as background.
                    let missing = (pattern.offsets.len() - seen.len()) as f32;
                    let sum: Vec3 = seen.iter().sum::<Vec3>() + missing * background;
                    *colour = sum / pattern.offsets.len() as f32;
                }
            }
        });
    Ok(frame)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::{CameraFrame, ProjectionSpec};

    fn frame(look: DVec3) -> CameraFrame {
        CameraFrame {
            position: DVec3::new(3.0, -1.0, 2.0),
            look_at: DVec3::new(3.0, -1.0, 2.0) + look,
            up: DVec3::Y,
        }
    }

    /// A `w` x `h` perspective camera of [`frame`]`(look)` with horizontal angle `fov`.
    fn perspective(look: DVec3, fov: f64, (w, h): (u32, u32)) -> Box<dyn Projection> {
        let frame = frame(look);
        ProjectionSpec::Perspective { frame, fov }
            .build(w, h)
            .unwrap()
    }

    /// A `w` x `h` equirectangular camera of [`frame`]`(look)` seeing the whole sphere.
    fn whole_sphere(look: DVec3, (w, h): (u32, u32)) -> Box<dyn Projection> {
        let frame = frame(look);
        ProjectionSpec::Equirectangular {
            frame,
            h_fov: 360.0,
            v_fov: 180.0,
        }
        .build(w, h)
        .unwrap()
    }

    /// A `w` x `h` photo of `pixels` (row by row from the top).
    fn photo(w: u32, h: u32, pixels: Vec<Vec3>) -> EquirectPhoto {
        EquirectPhoto::new(LinearImage {
            width: w,
            height: h,
            pixels,
        })
        .unwrap()
    }

    /// A photo whose colour is (longitude / 2 pi + 1/2, latitude / pi + 1/2, 0.5) at every
    /// pixel centre.
    fn direction_photo(w: u32, h: u32) -> EquirectPhoto {
        let pixels = (0..h)
            .flat_map(|y| {
                (0..w).map(move |x| {
                    let u = (f64::from(x) + 0.5) / f64::from(w);
                    let v = 1.0 - (f64::from(y) + 0.5) / f64::from(h);
                    Vec3::new(u as f32, v as f32, 0.5)
                })
            })
            .collect();
        photo(w, h, pixels)
    }

    /// A photo of pseudo-random colours.
    fn noise_photo(w: u32, h: u32) -> EquirectPhoto {
        let pixels = (0..w * h)
            .map(|i| {
                let k = i.wrapping_mul(2_654_435_761);
                Vec3::new(
                    (k % 251) as f32 / 250.0,
                    (k / 251 % 241) as f32 / 240.0,
                    (k / 60_000 % 239) as f32 / 238.0,
                )
            })
            .collect();
        photo(w, h, pixels)
    }

    #[test]
    fn an_equirectangular_camera_of_the_same_frame_returns_the_photo() {
        let (w, h) = (64, 32);
        let photo = noise_photo(w, h);
        let camera = whole_sphere(DVec3::NEG_Z, (w, h));
        let out = reproject(&photo, camera.as_ref(), 1, Vec3::ZERO).unwrap();
        let worst = out
            .color
            .iter()
            .zip(&photo.image.pixels)
            .map(|(a, b)| (*a - *b).abs().max_element())
            .fold(0.0, f32::max);
        assert!(worst < 1e-4, "{worst}");
        // Turned by 90 degrees to +x: column x shows the photo's column x + W/4.
        let turned = whole_sphere(DVec3::X, (w, h));
        let out = reproject(&photo, turned.as_ref(), 1, Vec3::ZERO).unwrap();
        for (y, x) in [(3usize, 5usize), (20, 60)] {
            let want = photo.image.pixels[y * w as usize + (x + w as usize / 4) % w as usize];
            let got = out.color[y * w as usize + x];
            assert!((got - want).abs().max_element() < 1e-4, "{x} {y}");
        }
    }

    #[test]
    fn a_perspective_camera_sees_the_directions_it_looks_in() {
        // Longitude 90 (+x), 90-degree perspective, square image: the centre looks along +x,
        // the top-left corner along (x, y, z) = (1, 1, -1) (left of +x is -z).
        let photo = direction_photo(720, 360);
        let camera = perspective(DVec3::X, 90.0, (20, 20));
        let out = reproject(&photo, camera.as_ref(), 1, Vec3::ZERO).unwrap();
        let colour = |lon: f64, lat: f64| {
            Vec3::new((lon / 360.0 + 0.5) as f32, (lat / 180.0 + 0.5) as f32, 0.5)
        };
        // The four centre pixels straddle the axis: their mean is the axis direction.
        let centre = (out.color[9 * 20 + 9]
            + out.color[9 * 20 + 10]
            + out.color[10 * 20 + 9]
            + out.color[10 * 20 + 10])
            / 4.0;
        assert!((centre - colour(90.0, 0.0)).abs().max_element() < 1e-3);
        // Corner pixel centres at (+-0.95, +-0.95) of the half-extent.
        let elevation = 0.95f64.atan2(1.0f64.hypot(0.95)).to_degrees();
        let side = 0.95f64.atan().to_degrees();
        for (index, lon, lat) in [
            (0, 90.0 - side, elevation),
            (19, 90.0 + side, elevation),
            (19 * 20, 90.0 - side, -elevation),
            (399, 90.0 + side, -elevation),
        ] {
            let got = out.color[index];
            assert!(
                (got - colour(lon, lat)).abs().max_element() < 1e-3,
                "{index}: {got} vs {}",
                colour(lon, lat)
            );
        }
    }

    #[test]
    fn sampling_wraps_in_longitude_and_clamps_at_the_poles() {
        let photo = noise_photo(8, 4);
        let px = |x: usize, y: usize| photo.image.pixels[y * 8 + x];
        // Half way between the last and the first column.
        let wrap = photo.sample(DVec2::new(8.0, 1.5));
        assert!((wrap - (px(7, 1) + px(0, 1)) / 2.0).abs().max_element() < 1e-6);
        // Above the top row's centre: the top row.
        let top = photo.sample(DVec2::new(2.5, 0.1));
        assert!((top - px(2, 0)).abs().max_element() < 1e-6);
        assert_eq!(photo.look(DVec3::Y), photo.sample(DVec2::new(4.0, 0.0)));
        assert!(EquirectPhoto::new(LinearImage {
            width: 0,
            height: 4,
            pixels: vec![],
        })
        .is_err());
    }

    #[test]
    fn curved_projectors_leave_along_their_last_direction() {
        let poly = Projector::Polyline(vec![DVec3::ZERO, DVec3::Z, DVec3::Z, DVec3::Z]);
        assert_eq!(exit_direction(&poly), Some(DVec3::Z));
        let q = Projector::QuadraticBezier([DVec3::ZERO, DVec3::Z, DVec3::new(1.0, 0.0, 1.0)]);
        assert_eq!(exit_direction(&q), Some(DVec3::new(2.0, 0.0, 0.0)));
        let flat = Projector::QuadraticBezier([DVec3::ZERO, DVec3::X, DVec3::X]);
        assert_eq!(exit_direction(&flat), Some(DVec3::X));
        assert_eq!(
            exit_direction(&Projector::Polyline(vec![DVec3::X; 3])),
            None
        );
    }

    #[test]
    fn supersampling_averages_the_pattern() {
        let photo = noise_photo(32, 16);
        let camera = perspective(DVec3::NEG_Z, 60.0, (6, 4));
        let one = reproject(&photo, camera.as_ref(), 1, Vec3::ZERO).unwrap();
        let many = reproject(&photo, camera.as_ref(), 16, Vec3::ZERO).unwrap();
        let pattern = SamplePattern::new(16);
        let corner = DVec2::new(2.0, 1.0);
        let want = pattern
            .offsets
            .iter()
            .map(|o| {
                let d = exit_direction(&camera.projector(corner + *o).unwrap()).unwrap();
                photo.look(d)
            })
            .sum::<Vec3>()
            / 16.0;
        assert!((many.color[6 + 2] - want).abs().max_element() < 1e-6);
        assert_ne!(one.color[6 + 2], many.color[6 + 2]);
    }
}
