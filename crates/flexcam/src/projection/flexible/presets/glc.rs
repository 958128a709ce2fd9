//! General linear cameras (Yu and McMillan 2004; thesis 6.1.2): the rays that are affine
//! combinations of three generator rays, each given by where it crosses the planes z = 0
//! (the image plane) and z = 1 in camera-local coordinates. Extending every ray to the
//! clip distances gives the two planar control surfaces of the flexible volume (fig. 6.4).

use glam::{DMat2, DVec2, DVec3};

use crate::error::{Error, Result};

/// The generators' image-plane triangle counts as degenerate when its doubled area is below
/// this fraction of the squared longest side.
const COLLINEAR: f64 = 1e-12;

/// The affine map from a ray's crossing (x0, y0) of z = 0 to its crossing (x1, y1) of z = 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct GeneralLinearCamera {
    /// Crossing of z = 1 of the ray through the image-plane origin.
    offset: DVec2,
    /// d(x1, y1) / d(x0, y0).
    linear: DMat2,
}

impl GeneralLinearCamera {
    /// From generators [x0, y0, x1, y1]. Errors: a non-finite number, or image-plane
    /// crossings (x0, y0) on one line (or coincident): the barycentric coordinates that
    /// define the affine combinations do not exist.
    pub fn new(generators: [[f64; 4]; 3]) -> Result<Self> {
        if generators.iter().flatten().any(|x| !x.is_finite()) {
            return Err(Error::new("flexible glc generators must be finite"));
        }
        let start = generators.map(|g| DVec2::new(g[0], g[1]));
        let end = generators.map(|g| DVec2::new(g[2], g[3]));
        let from = DMat2::from_cols(start[0] - start[2], start[1] - start[2]);
        let longest = [
            start[0] - start[1],
            start[1] - start[2],
            start[2] - start[0],
        ]
        .iter()
        .map(|e| e.length_squared())
        .fold(0.0, f64::max);
        if from.determinant().abs() <= COLLINEAR * longest || longest == 0.0 {
            return Err(Error::new(
                "flexible glc generators must cross the image plane (z = 0) at three points \
                 not on one line",
            ));
        }
        let to = DMat2::from_cols(end[0] - end[2], end[1] - end[2]);
        let linear = to * from.inverse();
        Ok(GeneralLinearCamera {
            offset: end[2] - linear * start[2],
            linear,
        })
    }

    /// The camera-local point at depth z of the ray that crosses the image plane at `image`.
    pub fn point(&self, image: DVec2, z: f64) -> DVec3 {
        let end = self.offset + self.linear * image;
        image.lerp(end, z).extend(z)
    }
}
