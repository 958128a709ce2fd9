//! Photo reprojection (thesis 9.4: "spherical coordinates through Q1, then Q2, resample"):
//! a photo of the surroundings, taken by a single-viewpoint camera (equirectangular,
//! cylindrical or fisheye: [`PhotoProjection`]), seen through any projection.
//!
//! The photo is a panorama of directions, laid out by its own camera placed at the origin,
//! looking along `look` with `up` (the equirectangular default: longitude 0 along -z,
//! longitude 90 degrees along +x and latitude 90 degrees along +y, the orientation of an
//! equirectangular camera at any position looking along -z with up +y, which therefore gets
//! the photo back). A world direction d maps to the photo pixel where that camera images
//! the point d, by the camera's own closed-form inverse (the projections' `SingleImage`), so
//! the photo's layout is exactly the one flexcam renders with that camera.
//!
//! Each output pixel takes the direction in which its projector leaves the viewing volume
//! (a straight ray's direction; the last segment of a polyline projector; the end tangent
//! P2 - P1 of a quadratic one): the photo is at infinity, so only that direction matters.
//! It is sampled bilinearly between the four nearest pixel centres, wrapping across the
//! left and right edges of a photo of 360 degrees of longitude and clamping at the other
//! edges (the poles' rows of an equirectangular photo). Directions the photo does not show
//! (outside a fisheye's circle, above or below a cylindrical photo, beyond a partial
//! panorama's sides) and pixels without a projector get `background`. With `spp` > 1 the
//! samples of the ray caster's pattern are averaged.

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

use super::raycast::sampling::SamplePattern;
use super::{Frame, LinearImage};
use crate::error::{Error, Result};
use crate::projection::projector::quadratic_tangent;
use crate::projection::{
    CameraFrame, Cylindrical, Equirectangular, Fisheye, FisheyeFit, FisheyeLens, FisheyeMapping,
    Projection, Projector, SingleImage,
};

/// The single-viewpoint camera a photo was taken with, and its angles in degrees (checked
/// as the scene-file types of the same names check them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PhotoProjection {
    /// Longitude linear across over `h_fov`, latitude linear down over `v_fov`.
    Equirectangular {
        /// Longitude range across the photo, degrees, up to 360.
        h_fov: f64,
        /// Latitude range down the photo, degrees, up to 180.
        v_fov: f64,
    },
    /// Longitude linear across over `h_fov`, tan(latitude) linear down; `v_fov` is the
    /// vertical angle at the photo's centre.
    Cylindrical {
        /// Longitude range across the photo, degrees, up to 360.
        h_fov: f64,
        /// Vertical angle at the centre, degrees, below 180.
        v_fov: f64,
    },
    /// A fisheye of `fov` across the circle inscribed in the photo's shorter side.
    Fisheye {
        /// Angle across the image circle, degrees.
        fov: f64,
        /// How the angle off the axis maps to the radius (a classic law, not a polynomial).
        mapping: FisheyeMapping,
    },
}

/// The names of [`PhotoProjection`]'s kinds, as `--input-projection` takes them.
pub const PHOTO_PROJECTION_NAMES: [&str; 3] = ["equirectangular", "cylindrical", "fisheye"];

impl PhotoProjection {
    /// The whole sphere, longitude 360 degrees across and latitude 180 down.
    pub const WHOLE_SPHERE: PhotoProjection = PhotoProjection::Equirectangular {
        h_fov: 360.0,
        v_fov: 180.0,
    };

    /// The kind's name (one of [`PHOTO_PROJECTION_NAMES`]).
    pub fn name(&self) -> &'static str {
        match self {
            PhotoProjection::Equirectangular { .. } => "equirectangular",
            PhotoProjection::Cylindrical { .. } => "cylindrical",
            PhotoProjection::Fisheye { .. } => "fisheye",
        }
    }
}

/// A photo in linear RGB with the camera that lays its pixels out.
pub struct Photo {
    image: LinearImage,
    /// The photo's camera at the origin, sized to the photo.
    camera: Box<dyn SingleImage>,
    /// Whether the photo spans 360 degrees of longitude, so that its columns wrap round.
    wraps: bool,
}

impl std::fmt::Debug for Photo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Photo")
            .field("width", &self.image.width)
            .field("height", &self.image.height)
            .field("wraps", &self.wraps)
            .finish_non_exhaustive()
    }
}

impl Photo {
    /// `image` taken by `projection` looking along `look` with `up` (only directions
    /// matter). Errors: an image of zero width or height, pixel data of the wrong length, an
    /// angle out of its range, `look` zero or parallel to `up`, a polynomial fisheye
    /// mapping (it needs a sensor).
    pub fn new(
        image: LinearImage,
        projection: PhotoProjection,
        look: DVec3,
        up: DVec3,
    ) -> Result<Self> {
        let n = image.width as usize * image.height as usize;
        if n == 0 || image.pixels.len() != n {
            return Err(Error::new(format!(
                "a photo needs a non-empty {} x {} image with one colour per pixel, got {} \
                 colours",
                image.width,
                image.height,
                image.pixels.len()
            )));
        }
        let frame = CameraFrame {
            position: DVec3::ZERO,
            look_at: look,
            up,
        };
        let (w, h) = (image.width, image.height);
        let (camera, wraps): (Box<dyn SingleImage>, bool) = match projection {
            PhotoProjection::Equirectangular { h_fov, v_fov } => (
                Box::new(Equirectangular::new(&frame, h_fov, v_fov, w, h)?),
                h_fov == 360.0,
            ),
            PhotoProjection::Cylindrical { h_fov, v_fov } => (
                Box::new(Cylindrical::new(&frame, h_fov, v_fov, w, h)?),
                h_fov == 360.0,
            ),
            PhotoProjection::Fisheye { fov, mapping } => {
                if let FisheyeMapping::Polynomial(_) = mapping {
                    return Err(Error::new(
                        "a fisheye photo takes a classic mapping (equidistant, equisolid, \
                         stereographic, orthographic), not a lens polynomial",
                    ));
                }
                let lens = FisheyeLens {
                    mapping,
                    fit: FisheyeFit::Inscribed,
                };
                let camera = Fisheye::with_lens("fisheye", &frame, fov, &lens, w, h)?;
                (Box::new(camera), false)
            }
        };
        Ok(Photo {
            image,
            camera,
            wraps,
        })
    }

    /// An equirectangular photo of the whole sphere in the default orientation (see the
    /// module): what `flexcam reproject` reads without `--input-projection`.
    pub fn equirectangular(image: LinearImage) -> Result<Self> {
        Photo::new(image, PhotoProjection::WHOLE_SPHERE, DVec3::NEG_Z, DVec3::Y)
    }

    /// The continuous photo position (x, y) of world direction `d`, `None` where the photo
    /// does not show it. Degenerate cases: a zero `d` has none; straight up or down an
    /// equirectangular photo's longitude is undefined and taken as 0 (on the clamped top or
    /// bottom row every column is near the pole); a cylindrical photo does not show the
    /// poles (at infinite height); a fisheye of 360 degrees shows straight behind on its
    /// whole circle and gives none.
    pub fn position(&self, d: DVec3) -> Option<DVec2> {
        let branch = self.camera.branch_image(d)?;
        let p = branch.image.pixel;
        let (w, h) = (f64::from(self.image.width), f64::from(self.image.height));
        let across = self.wraps || (0.0..=w).contains(&p.x);
        (branch.seen && across && (0.0..=h).contains(&p.y)).then_some(p)
    }

    /// The bilinear sample at continuous photo position `p` (pixel centres at + 1/2):
    /// columns wrap round in a 360-degree photo and clamp to the first and last otherwise,
    /// rows clamp to the first and last.
    pub fn sample(&self, p: DVec2) -> Vec3 {
        let (w, h) = (self.image.width as i64, self.image.height as i64);
        let (fx, fy) = (p.x - 0.5, p.y - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (ax, ay) = ((fx - x0) as f32, (fy - y0) as f32);
        let texel = |x: i64, y: i64| {
            let x = if self.wraps {
                x.rem_euclid(w)
            } else {
                x.clamp(0, w - 1)
            };
            let y = y.clamp(0, h - 1);
            self.image.pixels[(y * w + x) as usize]
        };
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = texel(x0, y0).lerp(texel(x0 + 1, y0), ax);
        let bottom = texel(x0, y0 + 1).lerp(texel(x0 + 1, y0 + 1), ax);
        top.lerp(bottom, ay)
    }

    /// The photo's colour in world direction `d`, `None` where the photo does not show it.
    pub fn look(&self, d: DVec3) -> Option<Vec3> {
        self.position(d).map(|p| self.sample(p))
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

/// The photo seen through `projection`, `spp` samples per pixel (at least 1), samples
/// without a projector or outside the photo counted as `background`. Only the colour of the
/// frame is meaningful (depth is infinite and ids 0: the photo is at infinity). Fails only
/// when the frame's memory cannot be had (module `try_alloc`).
pub fn reproject(
    photo: &Photo,
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
                    .filter_map(|d| photo.look(d))
                    .collect();
                if !seen.is_empty() {
                    // Samples without a projector or a photo colour count as background.
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
    use crate::projection::ProjectionSpec;

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
    fn photo(w: u32, h: u32, pixels: Vec<Vec3>) -> Photo {
        Photo::equirectangular(LinearImage {
            width: w,
            height: h,
            pixels,
        })
        .unwrap()
    }

    /// A photo whose colour is (longitude / 2 pi + 1/2, latitude / pi + 1/2, 0.5) at every
    /// pixel centre.
    fn direction_photo(w: u32, h: u32) -> Photo {
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
    fn noise_photo(w: u32, h: u32) -> Photo {
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
        assert_eq!(
            photo.look(DVec3::Y),
            Some(photo.sample(DVec2::new(4.0, 0.0)))
        );
        assert!(Photo::equirectangular(LinearImage {
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
                photo.look(d).unwrap()
            })
            .sum::<Vec3>()
            / 16.0;
        assert!((many.color[6 + 2] - want).abs().max_element() < 1e-6);
        assert_ne!(one.color[6 + 2], many.color[6 + 2]);
    }

    /// The colour a smooth test world shows in direction `d`: linear in the unit direction,
    /// so that bilinear sampling of a photo of it is exact up to the curvature of the
    /// photo's mapping.
    fn world(d: DVec3) -> Vec3 {
        (0.5 + 0.5 * d.normalize()).as_vec3()
    }

    /// A `w` x `h` photo of [`world`] taken by `spec` (its pixel centres' ray directions),
    /// black where it has no ray.
    fn photo_of_world(spec: &ProjectionSpec, (w, h): (u32, u32)) -> LinearImage {
        let camera = spec.build(w, h).unwrap();
        let pixels = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                camera
                    .ray(centre)
                    .map_or(Vec3::ZERO, |r| world(r.direction))
            })
            .collect();
        LinearImage {
            width: w,
            height: h,
            pixels,
        }
    }

    /// Cylindrical, fisheye (every classic mapping) and partial equirectangular photos taken
    /// by a tilted camera, read back by [`Photo`] with the same kind, angles and frame and
    /// seen through a perspective camera looking elsewhere: every covered pixel shows the
    /// world's colour in its own direction (to the photo's resampling error), so the photo's
    /// layout is the inverse of the camera that took it.
    #[test]
    fn photos_of_each_kind_read_back_the_world() {
        let (look, up) = (DVec3::new(0.3, -0.2, -1.0), DVec3::new(0.1, 1.0, 0.0));
        let frame = CameraFrame {
            position: DVec3::ZERO,
            look_at: look,
            up,
        };
        let mappings = [
            FisheyeMapping::Equidistant,
            FisheyeMapping::Equisolid,
            FisheyeMapping::Stereographic,
            FisheyeMapping::Orthographic,
        ];
        let mut cases: Vec<(ProjectionSpec, PhotoProjection, (u32, u32))> = vec![
            (
                ProjectionSpec::Cylindrical {
                    frame,
                    h_fov: 360.0,
                    v_fov: 120.0,
                },
                PhotoProjection::Cylindrical {
                    h_fov: 360.0,
                    v_fov: 120.0,
                },
                (720, 400),
            ),
            (
                ProjectionSpec::Equirectangular {
                    frame,
                    h_fov: 200.0,
                    v_fov: 120.0,
                },
                PhotoProjection::Equirectangular {
                    h_fov: 200.0,
                    v_fov: 120.0,
                },
                (400, 240),
            ),
        ];
        for mapping in mappings {
            cases.push((
                ProjectionSpec::MappedFisheye {
                    frame,
                    fov: 180.0,
                    lens: FisheyeLens {
                        mapping,
                        fit: FisheyeFit::Inscribed,
                    },
                },
                PhotoProjection::Fisheye {
                    fov: 180.0,
                    mapping,
                },
                (500, 400),
            ));
        }
        let view = ProjectionSpec::Perspective {
            frame: CameraFrame {
                position: DVec3::new(5.0, 1.0, -2.0),
                look_at: DVec3::new(5.4, 0.9, -3.0),
                up: DVec3::Y,
            },
            fov: 70.0,
        }
        .build(40, 30)
        .unwrap();
        for (spec, kind, size) in cases {
            let photo = Photo::new(photo_of_world(&spec, size), kind, look, up).unwrap();
            let out = reproject(&photo, view.as_ref(), 1, Vec3::splat(-1.0)).unwrap();
            let mut worst = 0.0f32;
            for (i, got) in out.color.iter().enumerate() {
                let pixel = DVec2::new((i % 40) as f64 + 0.5, (i / 40) as f64 + 0.5);
                let d = view.ray(pixel).unwrap().direction;
                assert_ne!(*got, Vec3::splat(-1.0), "{kind:?}: {pixel} is shown");
                worst = worst.max((*got - world(d)).abs().max_element());
            }
            assert!(worst < 1e-3, "{kind:?}: worst {worst}");
        }
    }

    /// Directions a photo does not show: behind a 180-degree fisheye, above a cylindrical
    /// photo's top row and at its pole, beyond a partial panorama's sides; a 360-degree
    /// fisheye's point straight behind (its whole circle) and the zero direction. Bad angles
    /// and frames are refused.
    #[test]
    fn directions_outside_the_photo_have_no_colour() {
        let image = |w: u32, h: u32| LinearImage {
            width: w,
            height: h,
            pixels: vec![Vec3::ONE; (w * h) as usize],
        };
        let (look, up) = (DVec3::NEG_Z, DVec3::Y);
        let fisheye = |fov| PhotoProjection::Fisheye {
            fov,
            mapping: FisheyeMapping::Equidistant,
        };
        let f180 = Photo::new(image(64, 64), fisheye(180.0), look, up).unwrap();
        assert!(f180.look(DVec3::NEG_Z).is_some());
        assert!(f180.look(DVec3::new(1.0, 0.0, -0.01)).is_some());
        assert!(f180.look(DVec3::new(1.0, 0.0, 0.01)).is_none());
        assert!(f180.look(DVec3::Z).is_none());
        assert!(f180.look(DVec3::ZERO).is_none());
        let f360 = Photo::new(image(64, 64), fisheye(360.0), look, up).unwrap();
        assert!(f360.look(DVec3::new(0.01, 0.0, 1.0)).is_some());
        assert!(f360.look(DVec3::Z).is_none());
        let cylinder = PhotoProjection::Cylindrical {
            h_fov: 360.0,
            v_fov: 90.0,
        };
        let c = Photo::new(image(64, 32), cylinder, look, up).unwrap();
        assert!(c.look(DVec3::new(0.0, 0.99, -1.0)).is_some());
        assert!(c.look(DVec3::new(0.0, 1.01, -1.0)).is_none());
        assert!(c.look(DVec3::Y).is_none());
        // Straight behind is the seam of a 360-degree photo: shown, wrapping.
        assert!(c.look(DVec3::Z).is_some());
        let partial = PhotoProjection::Equirectangular {
            h_fov: 90.0,
            v_fov: 90.0,
        };
        let e = Photo::new(image(32, 32), partial, look, up).unwrap();
        assert!(e.look(DVec3::new(0.99, 0.0, -1.0)).is_some());
        assert!(e.look(DVec3::new(1.01, 0.0, -1.0)).is_none());
        for (kind, look) in [
            (fisheye(0.0), look),
            (
                PhotoProjection::Equirectangular {
                    h_fov: 360.0,
                    v_fov: 200.0,
                },
                look,
            ),
            (
                PhotoProjection::Cylindrical {
                    h_fov: 360.0,
                    v_fov: 180.0,
                },
                look,
            ),
            (PhotoProjection::WHOLE_SPHERE, DVec3::ZERO),
            (PhotoProjection::WHOLE_SPHERE, DVec3::Y),
            (
                PhotoProjection::Fisheye {
                    fov: 180.0,
                    mapping: FisheyeMapping::Polynomial([0.0, -0.1, 0.0, 0.0, 0.0]),
                },
                look,
            ),
        ] {
            assert!(Photo::new(image(8, 8), kind, look, up).is_err(), "{kind:?}");
        }
    }
}
