//! Discontinuous (piecewise) flexible projections (Brosz 2011, 6.1.1 and 6.2.2, figures 6.2,
//! 6.3 and 6.12): several flexible projections side by side in one image, each owning a
//! rectangle of it. A piece's volume is re-parameterised into its rectangle: the piece is
//! built as a projection of its own at the rectangle's size in pixels, so its presets take
//! the rectangle's aspect ratio and its `reparam` maps the rectangle's pixels to its (u, v).
//! Pixels outside every rectangle see nothing (the background).
//!
//! This one construct gives the thesis's discontinuous volumes (the near and far surfaces
//! split into parts), collages of multi-camera projections, single-centre projections
//! (pieces whose projectors all start at one point) and mosaics of general linear cameras
//! (Yu and McMillan 2004: `glc` pieces whose rays agree along shared edges).
//!
//! Rectangles are given as image fractions and snapped to whole pixels (each edge to the
//! nearest pixel boundary), so that every pixel belongs to at most one piece and `--method
//! raster` can draw the pieces one by one as the views of the projection
//! ([`Projection::views`]); snapping is monotonic, so rectangles that do not overlap as
//! fractions do not overlap as pixels.

use glam::DVec2;

use super::{Flexible, FlexibleSpec, GridFitter};
use crate::error::{Error, Result};
use crate::geometry::Ray;
use crate::projection::image_coords::Resolution;
use crate::projection::{
    AnalyticInverse, BuildReport, Charted, ImagePoint, NoInverse, Projection, Projector,
    ProjectorHull, View,
};

/// The most pieces a projection may have: a collage or mosaic of a few dozen parts, each
/// searched per ray.
pub const MAX_PIECES: usize = 64;

/// One piece: a flexible projection and the image rectangle it owns.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// `[u0, v0, u1, v1]`: the rectangle's lower-left and upper-right corners as image
    /// fractions (u to the right, v up, both in [0, 1]).
    pub rect: [f64; 4],
    /// The piece's projection, re-parameterised into the rectangle.
    pub spec: FlexibleSpec,
}

/// Checks one rectangle: finite, inside [0, 1]^2, with u0 < u1 and v0 < v1.
pub fn check_rect(rect: [f64; 4]) -> Result<()> {
    let [u0, v0, u1, v1] = rect;
    let inside = |a: f64, b: f64| (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) && a < b;
    if rect.iter().all(|x| x.is_finite()) && inside(u0, u1) && inside(v0, v1) {
        return Ok(());
    }
    Err(Error::new(format!(
        "a piece's `rect` must be [u0, v0, u1, v1] with 0 <= u0 < u1 <= 1 and \
         0 <= v0 < v1 <= 1, got {rect:?}"
    )))
}

/// The first two rectangles (indices) that overlap in an area (sharing an edge or a corner
/// is not overlapping), `None` when none do.
pub fn overlapping(rects: &[[f64; 4]]) -> Option<(usize, usize)> {
    for (i, a) in rects.iter().enumerate() {
        for (j, b) in rects.iter().enumerate().skip(i + 1) {
            let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
            if !apart {
                return Some((i, j));
            }
        }
    }
    None
}

/// Checks a list of pieces: 1 to [`MAX_PIECES`] of them, every rectangle valid, no two
/// overlapping. The messages number pieces from 1, as a reader counts them in the file.
pub fn check_pieces(pieces: &[Piece]) -> Result<()> {
    if pieces.is_empty() || pieces.len() > MAX_PIECES {
        return Err(Error::new(format!(
            "`pieces` must hold 1 to {MAX_PIECES} pieces, got {}",
            pieces.len()
        )));
    }
    for (i, piece) in pieces.iter().enumerate() {
        check_rect(piece.rect)
            .map_err(|e| Error::new(format!("piece {}: {}", i + 1, e.message)))?;
    }
    let rects: Vec<[f64; 4]> = pieces.iter().map(|p| p.rect).collect();
    match overlapping(&rects) {
        Some((i, j)) => Err(Error::new(format!(
            "pieces {} and {} overlap: rect {:?} and rect {:?} share an area (rectangles may \
             only touch)",
            i + 1,
            j + 1,
            rects[i],
            rects[j]
        ))),
        None => Ok(()),
    }
}

/// A piece bound to its tile of the image.
#[derive(Debug, Clone, PartialEq)]
struct Tile {
    /// The piece's projection at the tile's size.
    projection: Flexible,
    /// The tile's top-left pixel in the whole image.
    offset: [u32; 2],
    /// The tile's width and height in pixels.
    size: [u32; 2],
}

impl Tile {
    /// The tile-local position of image position `pixel` when the tile owns it (x in
    /// [x0, x1), y in [y0, y1)).
    fn local(&self, pixel: DVec2) -> Option<DVec2> {
        let lo = DVec2::new(f64::from(self.offset[0]), f64::from(self.offset[1]));
        let local = pixel - lo;
        let inside = |x: f64, side: u32| (0.0..f64::from(side)).contains(&x);
        (inside(local.x, self.size[0]) && inside(local.y, self.size[1])).then_some(local)
    }

    fn origin(&self) -> DVec2 {
        DVec2::new(f64::from(self.offset[0]), f64::from(self.offset[1]))
    }
}

/// A discontinuous flexible projection bound to an image size: its pieces, each in its tile.
#[derive(Debug, Clone, PartialEq)]
pub struct FlexiblePieces {
    tiles: Vec<Tile>,
    resolution: Resolution,
    /// Why the projection has no analytic inverse: the first piece without one, named.
    no_inverse: Option<String>,
}

/// The pixel span `[round(a n), round(b n))` of the fractions `[a, b]` of a side of `n`
/// pixels.
fn span(a: f64, b: f64, n: u32) -> (u32, u32) {
    let snap = |x: f64| (x * f64::from(n)).round() as u32;
    (snap(a), snap(b))
}

impl FlexiblePieces {
    /// Builds every piece at the size of its tile (see the module doc). Errors: those of
    /// [`check_pieces`]; a rectangle that covers no whole pixel at this size (named, with the
    /// size); any piece's own build error, prefixed with its number.
    pub fn build(
        pieces: &[Piece],
        width: u32,
        height: u32,
        fitter: Option<&dyn GridFitter>,
        report: &mut BuildReport,
    ) -> Result<Self> {
        let resolution = Resolution::new(width, height)?;
        check_pieces(pieces)?;
        let mut tiles = Vec::with_capacity(pieces.len());
        let mut no_inverse = None;
        for (i, piece) in pieces.iter().enumerate() {
            let [u0, v0, u1, v1] = piece.rect;
            let (x0, x1) = span(u0, u1, width);
            // v grows upwards, rows downwards.
            let (y0, y1) = span(1.0 - v1, 1.0 - v0, height);
            if x1 <= x0 || y1 <= y0 {
                return Err(Error::new(format!(
                    "piece {}: rect {:?} covers no whole pixel of a {width}x{height} image \
                     (its edges snap to the same pixel boundary)",
                    i + 1,
                    piece.rect
                )));
            }
            let projection = Flexible::build(&piece.spec, x1 - x0, y1 - y0, fitter, report)
                .map_err(|e| Error::new(format!("piece {}: {}", i + 1, e.message)))?;
            if no_inverse.is_none() {
                if let Err(none) = projection.inverse() {
                    let why = none
                        .reason
                        .map_or_else(String::new, |reason| format!(": {reason}"));
                    no_inverse = Some(format!(
                        "piece {} (rect {:?}) has no analytic inverse{why}",
                        i + 1,
                        piece.rect
                    ));
                }
            }
            tiles.push(Tile {
                projection,
                offset: [x0, y0],
                size: [x1 - x0, y1 - y0],
            });
        }
        Ok(FlexiblePieces {
            tiles,
            resolution,
            no_inverse,
        })
    }

    /// The tile owning `pixel` and the pixel's position in it.
    fn owner(&self, pixel: DVec2) -> Option<(&Tile, DVec2)> {
        self.tiles
            .iter()
            .find_map(|tile| tile.local(pixel).map(|local| (tile, local)))
    }
}

impl Projection for FlexiblePieces {
    fn kind(&self) -> &'static str {
        "flexible"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    /// The owning piece's ray; `None` outside every piece.
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let (tile, local) = self.owner(pixel)?;
        tile.projection.ray(local)
    }

    fn projector(&self, pixel: DVec2) -> Option<Projector> {
        let (tile, local) = self.owner(pixel)?;
        tile.projection.projector(local)
    }

    fn projector_into(&self, pixel: DVec2, out: &mut Option<Projector>) {
        match self.owner(pixel) {
            Some((tile, local)) => tile.projection.projector_into(local, out),
            None => *out = None,
        }
    }

    /// The owning piece's hull when one tile owns the whole rectangle (its closed corners
    /// both strictly inside the tile's half-open span); `None` across tiles.
    fn projector_hull(&self, lo: DVec2, hi: DVec2) -> Option<ProjectorHull> {
        let (tile, local_lo) = self.owner(lo)?;
        let local_hi = tile.local(hi)?;
        tile.projection.projector_hull(local_lo, local_hi)
    }

    /// Every piece's images of a point that fall inside its own tile, when every piece has
    /// an inverse; otherwise the first piece without one, named. There is no chart (the
    /// pieces are separate branches): `--method raster` draws them one by one as views.
    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        match &self.no_inverse {
            None => Ok(self),
            Some(reason) => Err(NoInverse {
                reason: Some(reason.clone()),
            }),
        }
    }

    fn views(&self) -> Vec<View<'_>> {
        self.tiles
            .iter()
            .map(|tile| View {
                projection: &tile.projection,
                offset: tile.offset,
                keep_clear: None,
            })
            .collect()
    }
}

impl AnalyticInverse for FlexiblePieces {
    fn project(&self, point: glam::DVec3, out: &mut Vec<ImagePoint>) {
        let mut images = Vec::new();
        for tile in &self.tiles {
            let Ok(inverse) = tile.projection.inverse() else {
                continue;
            };
            images.clear();
            inverse.project(point, &mut images);
            let origin = tile.origin();
            out.extend(
                images
                    .iter()
                    .map(|image| ImagePoint {
                        pixel: image.pixel + origin,
                        t: image.t,
                    })
                    .filter(|image| tile.local(image.pixel).is_some()),
            );
        }
    }

    fn charted(&self) -> Option<Charted<'_>> {
        None
    }
}

#[cfg(test)]
mod tests;
