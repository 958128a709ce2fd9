//! Stereo pairs: two single-eye projections tiled in one image, left eye first (on top for
//! the top-bottom layout of omni-directional stereo, on the left for VR180's side by side).
//!
//! A pair is one [`Projection`] whose rays are its eyes' rays, each in its own tile, and whose
//! inverse images a point once per eye that sees it. That inverse has two branches, so it has
//! no chart; renderers that fill triangles by one continuous inverse draw the eyes one at a
//! time through [`Projection::views`], each eye a [`View`] with its own chart.

use glam::{DVec2, DVec3};

use super::image_coords::Resolution;
use super::{AnalyticInverse, Charted, ImagePoint, NoInverse, Projection, SingleImage, Trilinear};
use crate::error::{Error, Result};
use crate::geometry::Ray;

/// One tile of a projection's image drawn by a projection of its own (an eye of a stereo
/// pair): what [`Projection::views`] lists.
#[derive(Clone, Copy)]
pub struct View<'a> {
    /// The tile's projection; the tile is `projection.resolution()` pixels.
    pub projection: &'a dyn Projection,
    /// The tile's top-left corner in the whole image, in pixels.
    pub offset: [u32; 2],
    /// Where this view's inverse jumps or has no image although rays pass close by: a
    /// rasteriser cannot draw scene triangles that touch it and must refuse them.
    pub keep_clear: Option<KeepClear>,
}

/// A region around an omni-directional stereo eye circle that a scene triangle must not touch
/// for its image to be drawn by the continuous inverse (see `ods`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KeepClear {
    /// The closed disc of `radius` around `centre` perpendicular to the unit `axis`.
    Disc {
        /// The eye circle's centre.
        centre: DVec3,
        /// Unit axis (the projection's up).
        axis: DVec3,
        /// Half the interpupillary distance.
        radius: f64,
    },
    /// The closed solid cylinder of `radius` around the infinite line through `centre` along
    /// the unit `axis`.
    Cylinder {
        /// The eye circle's centre.
        centre: DVec3,
        /// Unit axis (the projection's up).
        axis: DVec3,
        /// Half the interpupillary distance.
        radius: f64,
    },
}

impl KeepClear {
    /// What the region is, for refusals.
    pub fn describe(&self) -> &'static str {
        match self {
            KeepClear::Disc { .. } => "the disc of radius ipd/2 around the eye at its height",
            KeepClear::Cylinder { .. } => {
                "the vertical cylinder of radius ipd/2 around the eye (no pole merging)"
            }
        }
    }

    /// Whether the closed triangle `corners` touches the region, decided in the plane
    /// perpendicular to the axis: a disc is touched where the triangle's cut by the disc's
    /// plane (a segment, a point or the whole triangle lying in it) comes within the radius
    /// of the centre; the cylinder where the triangle's shadow along the axis does. A
    /// degenerate (collinear) triangle whose line passes the centre counts as touching:
    /// the answer errs towards refusing. A relative margin of 1e-9 on the radius absorbs
    /// rounding.
    pub fn touches(&self, corners: [DVec3; 3]) -> bool {
        let (centre, axis, radius) = match *self {
            KeepClear::Disc {
                centre,
                axis,
                radius,
            }
            | KeepClear::Cylinder {
                centre,
                axis,
                radius,
            } => (centre, axis, radius),
        };
        let heights = corners.map(|p| axis.dot(p - centre));
        let flat = corners.map(|p| {
            let q = p - centre;
            q - axis * axis.dot(q)
        });
        let shadow: Vec<DVec3> = match self {
            KeepClear::Cylinder { .. } => flat.to_vec(),
            KeepClear::Disc { .. } if heights.iter().all(|&h| h == 0.0) => flat.to_vec(),
            KeepClear::Disc { .. } => {
                let mut cut = Vec::with_capacity(3);
                for i in 0..3 {
                    let j = (i + 1) % 3;
                    let (hi, hj) = (heights[i], heights[j]);
                    if hi == 0.0 {
                        cut.push(flat[i]);
                    } else if (hi < 0.0) != (hj < 0.0) && hj != 0.0 {
                        cut.push(flat[i].lerp(flat[j], hi / (hi - hj)));
                    }
                }
                cut
            }
        };
        distance_to_origin(&shadow, axis) <= radius * (1.0 + 1e-9)
    }
}

/// The distance from the origin to the convex hull of at most three points lying in the
/// plane through the origin perpendicular to `axis`; infinite for no points.
fn distance_to_origin(points: &[DVec3], axis: DVec3) -> f64 {
    let segment = |a: DVec3, b: DVec3| {
        let ab = b - a;
        let s = if ab.length_squared() > 0.0 {
            (-a.dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + s * ab).length()
    };
    match *points {
        [] => f64::INFINITY,
        [a] => a.length(),
        [a, b] => segment(a, b),
        [a, b, c, ..] => {
            let side = |p: DVec3, q: DVec3| axis.dot((q - p).cross(-p));
            let sides = [side(a, b), side(b, c), side(c, a)];
            if sides.iter().all(|&s| s >= 0.0) || sides.iter().all(|&s| s <= 0.0) {
                0.0
            } else {
                segment(a, b).min(segment(b, c)).min(segment(c, a))
            }
        }
    }
}

/// How the two eyes are tiled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// Left eye on top, right eye below (omni-directional stereo).
    TopBottom,
    /// Left eye on the left, right eye on the right (VR180).
    SideBySide,
}

impl Layout {
    /// The size of one eye's tile in a `width` x `height` image. Errors: an empty image, or
    /// an odd side along the split (the eyes would differ in size).
    pub fn eye_size(self, kind: &str, width: u32, height: u32) -> Result<(u32, u32)> {
        Resolution::new(width, height)?;
        let (side, name) = match self {
            Layout::TopBottom => (height, "height"),
            Layout::SideBySide => (width, "width"),
        };
        if side % 2 != 0 {
            return Err(Error::new(format!(
                "{kind} needs an even image {name} (one half per eye), got {width}x{height}"
            )));
        }
        Ok(match self {
            Layout::TopBottom => (width, height / 2),
            Layout::SideBySide => (width / 2, height),
        })
    }

    /// The offset of eye `index` (0 left, 1 right) for tiles of `eye` size.
    fn offset(self, index: usize, eye: (u32, u32)) -> [u32; 2] {
        let k = index as u32;
        match self {
            Layout::TopBottom => [0, k * eye.1],
            Layout::SideBySide => [k * eye.0, 0],
        }
    }

    /// The coordinate along the split and the tile's extent there.
    fn along(self, pixel: DVec2, eye: (u32, u32)) -> (f64, f64) {
        match self {
            Layout::TopBottom => (pixel.y, f64::from(eye.1)),
            Layout::SideBySide => (pixel.x, f64::from(eye.0)),
        }
    }
}

/// Two eyes tiled as `layout` says: eye 0 the left, eye 1 the right.
#[derive(Debug, Clone, PartialEq)]
pub struct StereoPair<E> {
    kind: &'static str,
    eyes: [E; 2],
    layout: Layout,
    eye_size: (u32, u32),
    keep_clear: Option<KeepClear>,
}

impl<E: Projection + SingleImage> StereoPair<E> {
    /// A pair of `eyes` (left, right) of equal resolution, named `kind`, whose views keep
    /// `keep_clear` (see [`View::keep_clear`]).
    pub fn new(
        kind: &'static str,
        eyes: [E; 2],
        layout: Layout,
        keep_clear: Option<KeepClear>,
    ) -> Self {
        let eye_size = eyes[0].resolution();
        StereoPair {
            kind,
            eyes,
            layout,
            eye_size,
            keep_clear,
        }
    }

    /// The eye whose tile holds `pixel` (positions before the split belong to the left eye,
    /// the others to the right, also outside the image) and the position in its tile.
    fn eye_at(&self, pixel: DVec2) -> (&E, DVec2) {
        let (along, extent) = self.layout.along(pixel, self.eye_size);
        let index = usize::from(along >= extent);
        let [x, y] = self.layout.offset(index, self.eye_size);
        (
            &self.eyes[index],
            pixel - DVec2::new(f64::from(x), f64::from(y)),
        )
    }
}

impl<E: Projection + SingleImage> Projection for StereoPair<E> {
    fn kind(&self) -> &'static str {
        self.kind
    }

    fn resolution(&self) -> (u32, u32) {
        let (w, h) = self.eye_size;
        match self.layout {
            Layout::TopBottom => (w, 2 * h),
            Layout::SideBySide => (2 * w, h),
        }
    }

    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let (eye, local) = self.eye_at(pixel);
        eye.ray(local)
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Ok(self)
    }

    fn views(&self) -> Vec<View<'_>> {
        (0..2)
            .map(|index| View {
                projection: &self.eyes[index] as &dyn Projection,
                offset: self.layout.offset(index, self.eye_size),
                keep_clear: self.keep_clear,
            })
            .collect()
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// Every eye's image of the point where that eye sees it and the image lies in the eye's
/// own tile along the split (half-open: a VR180 eye's image exactly 90 degrees to its right
/// belongs to the other tile and is dropped); the other coordinate is left unclipped, as for
/// the single-eye panoramas. No chart: the two images are two branches.
impl<E: Projection + SingleImage> AnalyticInverse for StereoPair<E> {
    fn project(&self, point: DVec3, out: &mut Vec<ImagePoint>) {
        for (index, eye) in self.eyes.iter().enumerate() {
            let Some(branch) = eye.branch_image(point).filter(|b| b.seen) else {
                continue;
            };
            let (along, extent) = self.layout.along(branch.image.pixel, self.eye_size);
            if !(0.0..extent).contains(&along) {
                continue;
            }
            let [x, y] = self.layout.offset(index, self.eye_size);
            out.push(ImagePoint {
                pixel: branch.image.pixel + DVec2::new(f64::from(x), f64::from(y)),
                t: branch.image.t,
            });
        }
    }

    fn charted(&self) -> Option<Charted<'_>> {
        None
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::projection::CameraFrame;

    /// The eye of the ods and vr180 tests.
    pub(in crate::projection) const EYE: DVec3 = DVec3::new(1.0, 2.0, 3.0);

    /// [`EYE`] looking down -z with y up: camera right is +x.
    pub(in crate::projection) fn frame() -> CameraFrame {
        CameraFrame {
            position: EYE,
            look_at: EYE + DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }

    pub(in crate::projection) fn near(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-13
    }

    fn disc() -> KeepClear {
        KeepClear::Disc {
            centre: DVec3::new(1.0, 2.0, 3.0),
            axis: DVec3::Y,
            radius: 0.5,
        }
    }

    fn shifted(corners: [[f64; 3]; 3]) -> [DVec3; 3] {
        corners.map(|c| DVec3::from_array(c) + DVec3::new(1.0, 2.0, 3.0))
    }

    #[test]
    fn disc_is_touched_only_where_the_triangle_cuts_it() {
        let d = disc();
        // A vertical triangle crossing the plane 0.4 from the centre: touches.
        assert!(d.touches(shifted([
            [0.4, -1.0, -1.0],
            [0.4, -1.0, 1.0],
            [0.4, 1.0, 0.0]
        ])));
        // The same 0.6 away: misses.
        assert!(!d.touches(shifted([
            [0.6, -1.0, -1.0],
            [0.6, -1.0, 1.0],
            [0.6, 1.0, 0.0]
        ])));
        // Entirely above the plane, over the centre: misses (a disc, not a cylinder).
        assert!(!d.touches(shifted([
            [-1.0, 0.1, -1.0],
            [1.0, 0.1, -1.0],
            [0.0, 0.1, 1.0]
        ])));
        // Lying in the plane around the centre: touches.
        assert!(d.touches(shifted([
            [-9.0, 0.0, -9.0],
            [9.0, 0.0, -9.0],
            [0.0, 0.0, 9.0]
        ])));
        // Lying in the plane, its nearest edge 1 away: misses.
        assert!(!d.touches(shifted([
            [-9.0, 0.0, 1.0],
            [9.0, 0.0, 1.0],
            [0.0, 0.0, 9.0]
        ])));
        // Touching the plane at one corner inside the disc.
        assert!(d.touches(shifted([[0.1, 0.0, 0.1], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]])));
    }

    #[test]
    fn cylinder_is_touched_by_anything_over_or_under_the_eye() {
        let c = KeepClear::Cylinder {
            centre: DVec3::ZERO,
            axis: DVec3::Y,
            radius: 0.5,
        };
        // A floor far below the eye, around the axis.
        assert!(c.touches([
            DVec3::new(-9.0, -5.0, -9.0),
            DVec3::new(9.0, -5.0, -9.0),
            DVec3::new(0.0, -5.0, 9.0)
        ]));
        // A wall 0.6 from the axis.
        assert!(!c.touches([
            DVec3::new(0.6, -5.0, -9.0),
            DVec3::new(0.6, -5.0, 9.0),
            DVec3::new(0.6, 5.0, 0.0)
        ]));
    }

    #[test]
    fn odd_sides_along_the_split_are_errors() {
        assert_eq!(Layout::TopBottom.eye_size("ods", 7, 8).unwrap(), (7, 4));
        assert_eq!(Layout::SideBySide.eye_size("vr180", 8, 7).unwrap(), (4, 7));
        let e = Layout::TopBottom.eye_size("ods", 8, 7).unwrap_err();
        assert_eq!(
            e.message,
            "ods needs an even image height (one half per eye), got 8x7"
        );
        assert!(Layout::SideBySide.eye_size("vr180", 7, 8).is_err());
        assert!(Layout::SideBySide.eye_size("vr180", 0, 8).is_err());
    }
}
