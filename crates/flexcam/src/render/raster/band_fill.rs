//! Steps 4 and 5 of the module documentation fused, band by band: the screen triangles of a
//! band are filled into the band's part of a z-buffer of reconstructed fragments, and the
//! band's visible fragments are shaded straight into the caller's frame while the band is
//! still in cache. Bands are independent, so they run in parallel with no binning pass, no
//! shared batch and no separate full-image clear or copy.
//!
//! Each covered pixel centre is reconstructed once ([`Shader::fragment`]: exact depth, ray
//! parameter and barycentrics, from its triangle's plane set up once per screen triangle,
//! [`TrianglePlane`]); the z-test keeps the nearest, ties going to the smaller
//! primitive key, as the polygon rasteriser's does, so the image does not depend on the
//! order of the triangles, the band size or the thread count.

use glam::Vec3;
use rayon::prelude::*;

use super::coverage::{cover, Bins};
use super::fragment::{Shader, TrianglePlane, Visible};
use crate::error::Result;
use crate::render::scan::RasterStats;
use crate::render::{frame_name, Frame};
use crate::try_alloc;

/// Rows per band: small enough for many parallel tasks on the part of a panorama a model
/// covers, large enough that few screen triangles (mostly one or two pixels) reach two.
pub const BAND_ROWS: u32 = 8;

/// The pixels of a 2x2 quad, as (column, row) offsets from its top left, in the lane order
/// of the quad's shading.
const QUAD: [(usize, usize); 4] = [(0, 0), (1, 0), (0, 1), (1, 1)];

/// What filling and shading did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FillCounts {
    /// Covered pixel centres, each reconstructed and z-tested.
    pub fragments: u64,
    /// Fragments whose projector misses the plane of their triangle within its range.
    pub discarded: u64,
    /// Fragments that won the z-test when tested.
    pub writes: u64,
    /// Pixels holding a visible fragment at the end.
    pub covered: u64,
    /// Rays cast by the shading of the visible fragments.
    pub shading_rays: u64,
}

impl std::ops::Add for FillCounts {
    type Output = FillCounts;

    fn add(self, o: FillCounts) -> FillCounts {
        FillCounts {
            fragments: self.fragments + o.fragments,
            discarded: self.discarded + o.discarded,
            writes: self.writes + o.writes,
            covered: self.covered + o.covered,
            shading_rays: self.shading_rays + o.shading_rays,
        }
    }
}

impl FillCounts {
    /// The rasteriser's counters for these fills of `polygons` screen triangles, `skipped`
    /// more having been left out for invalid coordinates.
    pub fn raster_stats(&self, polygons: u64, skipped: u64) -> RasterStats {
        RasterStats {
            polygons,
            lines: 0,
            skipped,
            fragments: self.fragments,
            writes: self.writes,
            discarded: self.discarded,
            covered: self.covered,
        }
    }
}

/// One bit per pixel of a band: whether its z-buffer slot was written this frame.
struct Written(Vec<u64>);

impl Written {
    /// `pixels` bits, all clear.
    fn new(pixels: usize) -> Self {
        Written(vec![0; pixels.div_ceil(64)])
    }

    fn get(&self, i: usize) -> bool {
        self.0[i / 64] & (1 << (i % 64)) != 0
    }

    fn set(&mut self, i: usize) {
        self.0[i / 64] |= 1 << (i % 64);
    }

    /// Whether none of the `len` bits from `start` on is set (`len` at most 64, the bits
    /// within the band).
    fn none_in(&self, start: usize, len: usize) -> bool {
        let (word, bit) = (start / 64, start % 64);
        let mut bits = self.0[word] >> bit;
        if bit != 0 {
            bits |= self.0.get(word + 1).map_or(0, |w| w << (64 - bit));
        }
        let mask = if len >= 64 { u64::MAX } else { (1 << len) - 1 };
        bits & mask == 0
    }
}

/// Fills the screen triangles of `bins` (those of every piece-building job, each sorted into
/// bands of [`BAND_ROWS`]) into `zbuffer` (resized to the image; its slots are written
/// where fragments land and read only where written this frame, so it needs no clearing)
/// and writes the image of `size` pixels into `frame`
/// (resized): visible pixels shaded by `shader`, others `background` at infinite depth with
/// id 0. Fails when the memory for a larger frame or z-buffer cannot be had (module
/// `try_alloc`); `frame` is then left empty (0 x 0).
pub fn fill_and_shade(
    shader: &Shader<'_>,
    bins: &[Bins],
    zbuffer: &mut Vec<Visible>,
    frame: &mut Frame,
    size: (u32, u32),
    background: Vec3,
) -> Result<FillCounts> {
    let (width, height) = size;
    let n = width as usize * height as usize;
    if let Err(e) = resize(frame, zbuffer, size, background) {
        *frame = Frame::new(0, 0, background);
        return Err(e);
    }
    if n == 0 {
        return Ok(FillCounts::default());
    }
    let row = width as usize;
    let chunk = BAND_ROWS as usize * row;
    Ok(frame
        .color
        .par_chunks_mut(chunk)
        .zip(frame.depth.par_chunks_mut(chunk))
        .zip(frame.ids.par_chunks_mut(chunk))
        .zip(zbuffer.par_chunks_mut(chunk))
        .enumerate()
        .map(|(band, (((colors, depths), ids), visible))| {
            let first = band as u32 * BAND_ROWS;
            let rows = (first, first + (visible.len() / row) as u32);
            let mut counts = FillCounts::default();
            if bins.iter().all(|job| job.band(band).is_empty()) {
                // Nothing reaches the band (the sky of a panorama): background only, and
                // the z-buffer's rows are left as they are (not read).
                colors.fill(background);
                depths.fill(f32::INFINITY);
                ids.fill(0);
                return counts;
            }
            // Which slots hold a fragment of this frame: the others read as Visible::NONE
            // without clearing the band's z-buffer rows (32 bytes a pixel) or reading them
            // back where nothing was written (most of a band's width).
            let mut written = Written::new(visible.len());
            for triangle in bins.iter().flat_map(|job| job.band(band)) {
                let mut plane = TrianglePlane::new(shader.corners(triangle.key));
                cover(triangle, rows, width, |x, y| {
                    counts.fragments += 1;
                    let Some(fragment) = shader.fragment(x, y, triangle.key, &mut plane) else {
                        counts.discarded += 1;
                        return;
                    };
                    let i = (y - first) as usize * row + x as usize;
                    let current = if written.get(i) {
                        &visible[i]
                    } else {
                        &Visible::NONE
                    };
                    if fragment.beats(current) {
                        visible[i] = fragment;
                        written.set(i);
                        counts.writes += 1;
                    }
                });
            }
            // Shaded in 2x2 quads (the last row of an odd band alone), so that the shadow
            // rays of neighbouring pixels are traced together.
            let band_rows = visible.len() / row;
            for top in (0..band_rows).step_by(2) {
                let quad_rows = top..(top + 2).min(band_rows);
                let mut left = 0;
                while left < row {
                    // A run of up to 64 columns with nothing drawn in the quad's rows (the
                    // sky beside a model): background at once, no per-quad test.
                    let span = (row - left).min(64);
                    if quad_rows
                        .clone()
                        .all(|y| written.none_in(y * row + left, span))
                    {
                        for y in quad_rows.clone() {
                            let run = y * row + left..y * row + left + span;
                            colors[run.clone()].fill(background);
                            depths[run.clone()].fill(f32::INFINITY);
                            ids[run].fill(0);
                        }
                        left += span;
                        continue;
                    }
                    // The quad's pixel indices in the band, where inside it; loops rather
                    // than `array::map`, which is not inlined here.
                    let mut quad = [None; 4];
                    let mut pixels = [None; 4];
                    for (lane, (dx, dy)) in QUAD.into_iter().enumerate() {
                        let (x, y) = (left + dx, top + dy);
                        if x < row && y < band_rows {
                            let i = y * row + x;
                            quad[lane] = Some(i);
                            if written.get(i) {
                                pixels[lane] = Some((x as u32, first + y as u32, &visible[i]));
                            }
                        }
                    }
                    if pixels.iter().all(Option::is_none) {
                        // Nothing drawn here (the sky beside a model): no shading call.
                        for i in quad.into_iter().flatten() {
                            (colors[i], depths[i], ids[i]) = (background, f32::INFINITY, 0);
                        }
                        left += 2;
                        continue;
                    }
                    let (shaded, rays) = shader.shade4(pixels);
                    counts.shading_rays += rays;
                    for lane in 0..4 {
                        let Some(i) = quad[lane] else {
                            continue;
                        };
                        if pixels[lane].is_some() {
                            let slot = &visible[i];
                            (colors[i], depths[i], ids[i]) =
                                (shaded[lane], slot.depth as f32, shader.id(slot.key));
                            counts.covered += 1;
                        } else {
                            (colors[i], depths[i], ids[i]) = (background, f32::INFINITY, 0);
                        }
                    }
                    left += 2;
                }
            }
            counts
        })
        .reduce(FillCounts::default, |a, b| a + b))
}

/// `frame` and `zbuffer` resized to `size` pixels (the new pixels of `frame` are
/// `background`, infinite depth, id 0; those of `zbuffer` [`Visible::NONE`]).
fn resize(
    frame: &mut Frame,
    zbuffer: &mut Vec<Visible>,
    (width, height): (u32, u32),
    background: Vec3,
) -> Result<()> {
    let n = width as usize * height as usize;
    let what = || frame_name(width, height);
    try_alloc::resize(&mut frame.color, n, background, what)?;
    try_alloc::resize(&mut frame.depth, n, f32::INFINITY, what)?;
    try_alloc::resize(&mut frame.ids, n, 0, what)?;
    try_alloc::resize(zbuffer, n, Visible::NONE, || {
        format!("the z-buffer of {}", frame_name(width, height))
    })?;
    (frame.width, frame.height) = (width, height);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `none_in` is "no `get` in the range" for every start and length up to 64 within
    /// three words holding a few set bits, at word boundaries and inside words.
    #[test]
    fn none_in_is_no_bit_set_in_the_range() {
        let pixels = 150;
        for set in [
            vec![],
            vec![0],
            vec![63],
            vec![64],
            vec![70, 149],
            vec![127, 128],
        ] {
            let mut written = Written::new(pixels);
            for &i in &set {
                written.set(i);
            }
            for start in 0..pixels {
                for len in 1..=64.min(pixels - start) {
                    let expected = (start..start + len).all(|i| !written.get(i));
                    assert_eq!(
                        written.none_in(start, len),
                        expected,
                        "{set:?} {start} {len}"
                    );
                }
            }
        }
    }
}
