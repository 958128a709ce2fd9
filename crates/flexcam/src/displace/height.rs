//! Height fields h(u, v) in [0, 1] over texture coordinates, with their largest value h_max
//! and bounds of h over uv rectangles (what the displaced-triangle hierarchy prunes with).
//!
//! A map is an 8- or 16-bit grey PNG: h is the grey value over the largest code value (255 or
//! 65535), linear (no sRGB decoding), sampled exactly as colour textures are
//! ([`crate::scene::texel::TexelGrid::bilinear`]: v = 1 the top row, bilinear between texel
//! centres, wrapping), in f32. h_max is the largest texel value: bilinear blends never exceed
//! it (but for the f32 rounding of the blend, below 1e-7) and the texel's own centre attains
//! it, so it is exact. Bounds over a uv rectangle come from a min/max pyramid of the texels
//! (see [`HeightMap::range`]).

use std::path::Path;

use glam::DVec2;

use super::procedural::Procedural;
use crate::error::Result;
use crate::scene::displacement::{HeightImage, HeightSource};
use crate::scene::texel::TexelGrid;

/// How far an f32 bilinear blend of texels in [0, 1] may stray outside their range (a few
/// units in the last place of 1, with margin).
const BLEND_ROUNDING: f64 = 1e-6;

/// A height field: an image map or a procedural function.
#[derive(Debug, Clone, PartialEq)]
pub enum HeightField {
    /// Heights sampled from a grey image by texture coordinates.
    Map(HeightMap),
    /// Heights from a closed-form function of the texture coordinates.
    Procedural(Procedural),
}

impl HeightField {
    /// The height field a scene describes.
    pub fn new(source: &HeightSource) -> HeightField {
        match source {
            HeightSource::Map(image) => HeightField::Map(HeightMap::new(image)),
            HeightSource::Procedural(spec) => HeightField::Procedural(Procedural::new(spec)),
        }
    }

    /// h at texture coordinates `uv`, in [0, 1].
    #[inline]
    pub fn sample(&self, uv: DVec2) -> f64 {
        match self {
            HeightField::Map(map) => map.sample(uv),
            HeightField::Procedural(p) => p.sample(uv),
        }
    }

    /// h_max: exact for maps, exact or a proven upper bound for procedural heights (see
    /// [`Procedural::max`]). Displacement is `h - h_max <= 0`: the undisplaced surface is an
    /// outer hull.
    pub fn max(&self) -> f64 {
        match self {
            HeightField::Map(map) => map.max(),
            HeightField::Procedural(p) => p.max(),
        }
    }

    /// `[lo, hi]` with `lo <= h(uv) <= hi` for every `uv` in the rectangle `[min, max]` (not
    /// wrapped: any real coordinates).
    #[inline]
    pub fn range(&self, min: DVec2, max: DVec2) -> [f64; 2] {
        match self {
            HeightField::Map(map) => map.range(min, max),
            HeightField::Procedural(p) => p.range(min, max),
        }
    }
}

/// A grey image of heights in [0, 1] with a min/max pyramid over it.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightMap {
    width: u32,
    height: u32,
    /// Row-major, top row first.
    values: Vec<f32>,
    /// `levels[k]` holds `[min, max]` over blocks of `2^k x 2^k` texels (clipped at the right
    /// and bottom edges), row-major; `levels[0]` is the texels themselves. The last level is
    /// one block.
    levels: Vec<Level>,
}

#[derive(Debug, Clone, PartialEq)]
struct Level {
    width: usize,
    height: usize,
    min_max: Vec<[f32; 2]>,
}

impl HeightMap {
    /// Loads an 8- or 16-bit grey PNG ([`HeightImage::load`]). Errors (one line, naming the
    /// file): unreadable, not a PNG, not grey (RGB, with alpha, ...), empty.
    pub fn load(path: &Path) -> Result<HeightMap> {
        HeightImage::load(path).map(|image| HeightMap::new(&image))
    }

    /// A map from `width * height` heights, top row first. Errors: an empty image, a wrong
    /// count, a value outside [0, 1] (NaN included).
    pub fn from_values(width: u32, height: u32, values: Vec<f32>) -> Result<HeightMap> {
        HeightImage::new(width, height, values).map(|image| HeightMap::new(&image))
    }

    /// The map of a (validated) height image, with its pyramid.
    pub fn new(image: &HeightImage) -> HeightMap {
        let (width, height) = (image.width, image.height);
        HeightMap {
            width,
            height,
            values: image.values.clone(),
            levels: pyramid(width as usize, height as usize, &image.values),
        }
    }

    /// h at `uv`: the bilinear texture lookup of the grey values, widened to f64.
    #[inline]
    pub fn sample(&self, uv: DVec2) -> f64 {
        let grid = TexelGrid {
            width: self.width,
            height: self.height,
            texels: &self.values,
        };
        grid.bilinear(uv.as_vec2()) as f64
    }

    /// The largest texel value (exact h_max).
    pub fn max(&self) -> f64 {
        self.levels.last().expect("at least one level").min_max[0][1] as f64
    }

    /// Bounds of h over the uv rectangle `[min, max]`.
    ///
    /// A bilinear sample at texel coordinates `(x, y)` (`x = u * width`, `y = (1 - v) *
    /// height`) blends texels `floor(x - 1/2)` and the next one in each axis, so h over the
    /// rectangle lies between the smallest and the largest texel of the integer rectangle of
    /// those footprints, widened by a texel on each side for the f32 rounding of `uv` (and by
    /// more for coordinates so large that f32 spacing exceeds a texel) and wrapped. The texel
    /// rectangle is split at the wrap into at most four, and each is bounded by the at most
    /// 2 x 2 pyramid blocks of the finest level at which it spans no more than two blocks per
    /// axis: conservative, O(1), and tight to within a block of that size. The bounds are
    /// widened by `BLEND_ROUNDING` for the f32 rounding of the blend itself.
    pub fn range(&self, min: DVec2, max: DVec2) -> [f64; 2] {
        let (w, h) = (self.width as f64, self.height as f64);
        let slack = |a: f64, b: f64, n: f64| 1.0 + a.abs().max(b.abs()) * n * 1e-6;
        let xs = footprint(min.x * w, max.x * w, slack(min.x, max.x, w));
        let ys = footprint((1.0 - max.y) * h, (1.0 - min.y) * h, slack(min.y, max.y, h));
        let mut out = [f32::INFINITY, f32::NEG_INFINITY];
        for x in wrap(xs, self.width as i64).into_iter().flatten() {
            for y in wrap(ys, self.height as i64).into_iter().flatten() {
                let [lo, hi] = self.block_range(x, y);
                out = [out[0].min(lo), out[1].max(hi)];
            }
        }
        [
            out[0] as f64 - BLEND_ROUNDING,
            out[1] as f64 + BLEND_ROUNDING,
        ]
    }

    /// Bounds over texels `x[0]..=x[1]`, `y[0]..=y[1]` (in range).
    fn block_range(&self, x: [usize; 2], y: [usize; 2]) -> [f32; 2] {
        let mut k = 0;
        while (x[1] >> k) - (x[0] >> k) > 1 || (y[1] >> k) - (y[0] >> k) > 1 {
            k += 1;
        }
        let k = k.min(self.levels.len() - 1);
        let level = &self.levels[k];
        let mut out = [f32::INFINITY, f32::NEG_INFINITY];
        for by in (y[0] >> k)..=(y[1] >> k).min(level.height - 1) {
            for bx in (x[0] >> k)..=(x[1] >> k).min(level.width - 1) {
                let [lo, hi] = level.min_max[by * level.width + bx];
                out = [out[0].min(lo), out[1].max(hi)];
            }
        }
        out
    }
}

/// The integer texel range (unwrapped) whose bilinear footprints cover continuous texel
/// coordinates `[lo, hi]`, widened by `slack` texels; `None` when it is unbounded (non-finite
/// or huge input): the whole axis.
fn footprint(lo: f64, hi: f64, slack: f64) -> Option<[i64; 2]> {
    let first = (lo - 0.5 - slack).floor();
    let last = (hi - 0.5 + slack).floor() + 1.0;
    let limit = (1u64 << 52) as f64;
    (first.abs() < limit && last.abs() < limit).then_some([first as i64, last as i64])
}

/// The unwrapped range `r` as at most two in-range ranges of an axis of `n` texels.
fn wrap(r: Option<[i64; 2]>, n: i64) -> [Option<[usize; 2]>; 2] {
    let whole = [Some([0, n as usize - 1]), None];
    let Some([first, last]) = r else {
        return whole;
    };
    if last - first + 1 >= n {
        return whole;
    }
    let start = first.rem_euclid(n);
    let end = start + (last - first);
    if end < n {
        [Some([start as usize, end as usize]), None]
    } else {
        [
            Some([start as usize, n as usize - 1]),
            Some([0, (end - n) as usize]),
        ]
    }
}

/// The min/max pyramid of `values` (`width x height`, row-major).
fn pyramid(width: usize, height: usize, values: &[f32]) -> Vec<Level> {
    let mut levels = vec![Level {
        width,
        height,
        min_max: values.iter().map(|&h| [h, h]).collect(),
    }];
    while let Some(fine) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
        let (w, h) = (fine.width.div_ceil(2), fine.height.div_ceil(2));
        let mut min_max = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let mut out = [f32::INFINITY, f32::NEG_INFINITY];
                for fy in (2 * y)..(2 * y + 2).min(fine.height) {
                    for fx in (2 * x)..(2 * x + 2).min(fine.width) {
                        let [lo, hi] = fine.min_max[fy * fine.width + fx];
                        out = [out[0].min(lo), out[1].max(hi)];
                    }
                }
                min_max.push(out);
            }
        }
        levels.push(Level {
            width: w,
            height: h,
            min_max,
        });
    }
    levels
}

#[cfg(test)]
mod tests;
