//! The per-fragment stage (Hou et al. 2006, 2.2) and the band-local z-buffer it writes.
//!
//! Each pixel of a bounding region is a fragment of one (camera triangle, scene triangle)
//! pair, keyed `camera << 32 | scene triangle`. Its ray is the camera triangle's ray at the
//! pixel centre ([`Camera::pixel_ray`]: origin and direction interpolated barycentrically,
//! or for a per-fragment mirror the eye's ray reflected about the interpolated normal); it
//! is intersected with
//! the scene triangle's plane, and the fragment is killed when the pixel belongs to another
//! camera triangle ([`super::owners`]), when the hit lies outside the scene triangle or
//! behind the ray's origin. A surviving fragment is *rendered*: its depth is the exact ray
//! parameter of the hit, computed per fragment (so no early z applies), and it wins the
//! pixel when `(depth, key)` is lexicographically smallest, whatever the drawing order.

use glam::DVec2;

use super::camera::Camera;
use crate::error::Result;
use crate::render::scan::{spans, FillRule, Polygon, Scratch, NO_PRIMITIVE};
use crate::render::trilinear::{band_name, plane_hit, GBuffer, SceneGeometry};
use crate::try_alloc;

/// The fragments of some shapes: how many the bounds produced and how many were rendered.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FragmentCounts {
    pub bounding: u64,
    pub rendered: u64,
}

impl std::ops::Add for FragmentCounts {
    type Output = FragmentCounts;

    fn add(self, o: FragmentCounts) -> FragmentCounts {
        FragmentCounts {
            bounding: self.bounding + o.bounding,
            rendered: self.rendered + o.rendered,
        }
    }
}

/// The winners of one band of rows (the trilinear method's [`GBuffer`]: depth as the exact
/// ray parameter, key, scene barycentrics) and what the stage needs besides.
#[derive(Debug, Clone)]
pub struct BandBuffer {
    pub hits: GBuffer,
    /// The key of the last fragment at each pixel: a pair's regions (the tight bound's
    /// pieces) are drawn one after the other and may share boundary pixels, which are one
    /// fragment of the pair, counted once.
    last: Vec<u64>,
    pub scratch: Scratch<0>,
}

impl BandBuffer {
    /// A buffer for bands of up to `rows` rows of an image `width` pixels wide. Fails when
    /// its memory cannot be had.
    pub fn new(width: u32, rows: u32) -> Result<BandBuffer> {
        let n = width as usize * rows as usize;
        Ok(BandBuffer {
            hits: GBuffer::new(width, rows)?,
            last: try_alloc::filled(n, NO_PRIMITIVE, || band_name(width, rows))?,
            scratch: Scratch::default(),
        })
    }

    /// Empties the buffer for rows `rows`.
    pub fn start_band(&mut self, rows: (u32, u32)) {
        let n = (rows.1 - rows.0) as usize * self.hits.width() as usize;
        self.hits.start_band(rows);
        self.last[..n].fill(NO_PRIMITIVE);
    }
}

/// What the stage reads.
pub struct Stage<'a> {
    pub cameras: &'a [Camera],
    /// The camera triangle of each pixel of the image ([`super::owners`]).
    pub owners: &'a [u32],
    pub scene: &'a SceneGeometry,
    pub width: u32,
}

impl Stage<'_> {
    /// Draws the bounding region `polygon` (keyed as the module doc says) into `buffer`.
    pub fn draw(&self, buffer: &mut BandBuffer, polygon: &Polygon<'_, 0>) -> FragmentCounts {
        let key = polygon.primitive;
        let camera_index = (key >> 32) as u32;
        let camera = &self.cameras[camera_index as usize];
        let corners = self.scene.corners((key & u64::from(u32::MAX)) as usize);
        let (rows, width) = (buffer.hits.rows(), buffer.hits.width());
        let mut counts = FragmentCounts::default();
        let mut scratch = std::mem::take(&mut buffer.scratch);
        spans(
            polygon,
            FillRule::NonZero,
            rows,
            width,
            &mut scratch,
            |span| {
                let image_row = span.y as usize * self.width as usize;
                let band_row = (span.y - rows.0) as usize * width as usize;
                for x in span.x0..span.x1 {
                    let i = band_row + x as usize;
                    if buffer.last[i] == key {
                        continue;
                    }
                    buffer.last[i] = key;
                    counts.bounding += 1;
                    if self.owners[image_row + x as usize] != camera_index {
                        continue;
                    }
                    let centre = DVec2::new(f64::from(x) + 0.5, f64::from(span.y) + 0.5);
                    let Some(ray) = camera.pixel_ray(centre) else {
                        continue;
                    };
                    let Some((t, u, v)) = plane_hit(&ray, corners) else {
                        continue;
                    };
                    if !(t >= 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0) {
                        continue;
                    }
                    counts.rendered += 1;
                    let hits = &mut buffer.hits;
                    if t < hits.depth[i] || (t == hits.depth[i] && key < hits.keys[i]) {
                        hits.depth[i] = t;
                        hits.keys[i] = key;
                        hits.barycentrics[i] = [u as f32, v as f32];
                    }
                }
            },
        );
        buffer.scratch = scratch;
        counts
    }
}
