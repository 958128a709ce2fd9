//! The projector of every pixel centre, computed lazily and kept for the life of the
//! renderer: each fragment of the rasteriser reconstructs its scene point exactly by
//! intersecting its pixel's projector with the plane of its scene triangle (see the
//! `fragment` module), and looking the projector up is much cheaper than evaluating a
//! nonlinear projection per fragment. Projectors are straight rays, or polylines and
//! quadratic curves for the polyline and quadratic volumes between parallel planes that have
//! an inverse.
//!
//! The image is cut into square tiles of [`TILE`] pixels; a tile's projectors are computed
//! the first time a fragment needs one of them (by whichever thread gets there first), so
//! pixels that no scene triangle covers (the sky of a panorama) never cost a projector, and
//! every later frame of the same projection finds them ready. A renderer of another
//! projection (the next frame of a viewer whose projection is being edited) can take over
//! the tiles' memory ([`PixelRays::take_tiles`], [`PixelRays::reusing`]) and overwrite it,
//! instead of allocating and page-faulting 70 bytes a pixel again.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};

use glam::DVec3;

use crate::projection::{Projection, Projector};

/// Tile edge in pixels: a tile spans two bands of the fill (`band_fill::BAND_ROWS`, 8 rows),
/// so a tile is computed by one thread and read by at most two.
const TILE: u32 = 16;

/// The projectors of one tile, row-major.
pub type Tile = Box<[Option<Projector>]>;

/// The centre projectors of a projection's image, computed tile by tile on first use;
/// `None` where the projection has none (outside a fisheye's circle) or it has zero length.
pub struct PixelRays<'a> {
    projection: &'a dyn Projection,
    size: (u32, u32),
    tiles_x: u32,
    tiles: Vec<OnceLock<Tile>>,
    computed: AtomicU64,
    /// Tiles of an earlier renderer, overwritten before they are read.
    spare: Mutex<Vec<Tile>>,
}

impl<'a> PixelRays<'a> {
    /// The (still empty) projectors of `projection`'s image, computed into the memory of
    /// `spare` tiles (those of another projection, whose projectors are all overwritten)
    /// before new tiles are allocated.
    pub fn reusing(projection: &'a dyn Projection, spare: Vec<Tile>) -> Self {
        let (width, height) = projection.resolution();
        let tiles_x = width.div_ceil(TILE);
        let count = tiles_x as usize * height.div_ceil(TILE) as usize;
        PixelRays {
            projection,
            size: (width, height),
            tiles_x,
            tiles: (0..count).map(|_| OnceLock::new()).collect(),
            computed: AtomicU64::new(0),
            spare: Mutex::new(spare),
        }
    }

    /// The memory of every tile, computed or spare, for [`PixelRays::reusing`]; leaves every
    /// tile to be computed again.
    pub fn take_tiles(&mut self) -> Vec<Tile> {
        let spare = self
            .spare
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let mut tiles = std::mem::take(spare);
        tiles.extend(self.tiles.iter_mut().filter_map(OnceLock::take));
        tiles
    }

    /// The projector through the centre of pixel `(x, y)` (inside the image).
    pub fn get(&self, x: u32, y: u32) -> Option<&Projector> {
        let (tx, ty) = (x / TILE, y / TILE);
        let tile = self.tiles[(ty * self.tiles_x + tx) as usize].get_or_init(|| self.tile(tx, ty));
        tile[((y % TILE) * TILE + x % TILE) as usize].as_ref()
    }

    /// How many tiles have been computed so far (over every frame).
    pub fn computed_tiles(&self) -> u64 {
        self.computed.load(Ordering::Relaxed)
    }

    /// The projectors of tile `(tx, ty)`, row-major; `None` past the image's edge. Written
    /// into a spare tile's memory when there is one (every entry overwritten).
    fn tile(&self, tx: u32, ty: u32) -> Tile {
        self.computed.fetch_add(1, Ordering::Relaxed);
        let spare = self
            .spare
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .pop();
        let mut tile = spare.unwrap_or_else(|| (0..TILE * TILE).map(|_| None).collect());
        let (width, height) = self.size;
        let (x0, y0) = (tx * TILE, ty * TILE);
        let centres =
            |from: u32, to: u32| -> Vec<f64> { (from..to).map(|v| f64::from(v) + 0.5).collect() };
        let columns = centres(x0, (x0 + TILE).min(width));
        let rows = centres(y0, (y0 + TILE).min(height));
        self.projection
            .projector_grid_into(&columns, &rows, TILE as usize, &mut tile);
        for (k, out) in (0..TILE * TILE).zip(tile.iter_mut()) {
            let (x, y) = (x0 + k % TILE, y0 + k / TILE);
            let seen = x < width
                && y < height
                && out.as_ref().is_some_and(|p| match p {
                    Projector::Straight(r) => r.direction != DVec3::ZERO,
                    Projector::Polyline(points) => points.windows(2).any(|w| w[0] != w[1]),
                    Projector::QuadraticBezier(_) => true,
                });
            if !seen {
                *out = None;
            }
        }
        tile
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::{CameraFrame, ProjectionSpec};
    use glam::DVec2;

    #[test]
    fn rays_are_the_projections_and_computed_only_where_asked() {
        let frame = CameraFrame {
            position: DVec3::new(0.5, 0.0, 2.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        };
        // 40 x 20: the last tile column and row are partial (degenerate edge tiles).
        let projection = ProjectionSpec::Fisheye { frame, fov: 180.0 }
            .build(40, 20)
            .unwrap();
        let rays = PixelRays::reusing(projection.as_ref(), Vec::new());
        assert_eq!(rays.computed_tiles(), 0);
        for (x, y) in [(0, 0), (39, 19), (20, 10), (33, 2)] {
            let want = projection.projector(DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5));
            assert_eq!(rays.get(x, y), want.as_ref(), "({x}, {y})");
        }
        // Corners outside the fisheye's circle have no ray.
        assert!(rays.get(0, 0).is_none() && rays.get(20, 10).is_some());
        // Four distinct tiles were asked for; asking again computes nothing.
        assert_eq!(rays.computed_tiles(), 4);
        rays.get(1, 1);
        assert_eq!(rays.computed_tiles(), 4);
    }

    /// Tiles taken over from another projection's projectors (straight rays, then polylines
    /// of a flexible volume, then straight again) are overwritten whole: every projector is
    /// the new projection's, `None` included, as a fresh set of tiles gives.
    #[test]
    fn reused_tiles_hold_the_new_projections_projectors() {
        let frame = CameraFrame {
            position: DVec3::new(0.3, 0.2, 3.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        };
        let flexible = crate::projection::flexible::FlexibleSpec {
            source: crate::projection::flexible::VolumeSource::Preset(
                crate::projection::flexible::PresetSpec {
                    preset: crate::projection::flexible::Preset::CrossedSlits {
                        fov: 70.0,
                        v_fov: None,
                        slit_distance: -2.0,
                    },
                    frame,
                    clip: None,
                },
            ),
            reparam: None,
        };
        let specs = [
            ProjectionSpec::Perspective { frame, fov: 60.0 },
            ProjectionSpec::Flexible(Box::new(flexible)),
            ProjectionSpec::Fisheye { frame, fov: 180.0 },
        ];
        let mut spare = Vec::new();
        for spec in specs {
            let projection = spec.build(40, 20).unwrap();
            let mut rays = PixelRays::reusing(projection.as_ref(), spare);
            for y in 0..20 {
                for x in 0..40 {
                    let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                    let fresh = PixelRays::reusing(projection.as_ref(), Vec::new());
                    assert_eq!(rays.get(x, y), fresh.get(x, y), "{spec:?} ({x}, {y})");
                    let want = projection.projector(centre);
                    assert_eq!(rays.get(x, y).is_some(), want.is_some(), "({x}, {y})");
                }
            }
            spare = rays.take_tiles();
            assert_eq!(spare.len(), 6);
        }
    }
}
