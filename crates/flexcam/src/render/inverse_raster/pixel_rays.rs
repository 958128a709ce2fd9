//! The projector of every pixel centre, computed once per projection: each fragment of the
//! rasteriser reconstructs its scene point exactly by intersecting its pixel's projector with
//! the plane of its scene triangle (see the `fragment` module), and looking the projector up
//! is much cheaper than evaluating a nonlinear projection per fragment.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::geometry::Ray;
use crate::projection::Projection;

/// The centre rays of a `width` x `height` image, row-major; `None` where the projection has
/// no ray (outside a fisheye's circle).
pub struct PixelRays {
    width: u32,
    rays: Vec<Option<Ray>>,
}

impl PixelRays {
    /// Evaluates `projection.ray` at every pixel centre, in parallel over rows.
    pub fn new(projection: &dyn Projection) -> Self {
        let (width, height) = projection.resolution();
        let rays = (0..height)
            .into_par_iter()
            .flat_map_iter(|y| {
                (0..width).map(move |x| {
                    let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                    projection
                        .ray(centre)
                        .filter(|r| r.direction != DVec3::ZERO)
                })
            })
            .collect();
        PixelRays { width, rays }
    }

    /// The ray through the centre of pixel `(x, y)` (inside the image).
    pub fn get(&self, x: u32, y: u32) -> Option<&Ray> {
        self.rays[y as usize * self.width as usize + x as usize].as_ref()
    }
}
