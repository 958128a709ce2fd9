//! The depth-discontinuity occlusion camera (Popescu and Aliaga 2006; Brosz 2011, 6.1.2,
//! figure 6.6): a perspective view whose samples beyond a depth z_f are moved in the image
//! by a per-pixel displacement map, so that what a near occluder hides just behind its
//! silhouette comes out beside it.
//!
//! As a flexible volume it has four control surfaces (polyline projectors): the near
//! rectangle at the near clip and Q_zn at depth z_n, both the perspective's, then Q_zf at z_f
//! and the far rectangle at the far clip, both the perspective's rectangles evaluated at the
//! displaced parameters w(q) = q - m(q), where m is the [`DdocMap`] sampled bilinearly at the
//! image position q = (u, v). So each projector is the perspective's up to z_n; beyond z_f it
//! is the perspective ray through image position q - m(q) (a straight line through the eye,
//! since both displaced rectangles are seen from the eye at the same w); between z_n and z_f
//! it bends from one to the other. m(q) is the displacement of the far sample that lands at
//! q: a sample at perspective position p beyond z_f is seen at q with q - m(q) = p.
//!
//! [`DdocMap::from_depth`] makes the map from the depth of the reference perspective: at
//! each depth discontinuity (a pixel at depth <= z_n beside one at depth >= z_f or empty) the
//! far samples are pushed away from the discontinuity, towards the occluded (far) side,
//! by `strength` image widths at the silhouette, falling off as a Gaussian across it, so the
//! band hidden behind the silhouette is seen beside it. The field is the Gaussian-weighted
//! sum of the unit normals of the discontinuity's pixel steps, scaled so that a straight
//! silhouette gets exactly `strength`; with sigma = 2 `strength` its slope across a straight
//! silhouette stays below 0.31, so q - m(q) never folds there.
//!
//! Degenerate cases: no discontinuity gives the zero map (the perspective: every projector
//! passes its four surfaces on one line through the eye); opposite silhouettes closer than
//! a few sigma cancel (a thin occluder moves nothing); map samples beyond the map's pixel
//! centres take the nearest border sample.

use std::path::Path;
use std::sync::Arc;

use glam::{DMat2, DVec2, DVec3};

use super::{Preset, PresetSpec};
use crate::error::{Error, Result};
use crate::file_read::read_regular;

/// The largest map side read or made, pixels: the map is smooth and sampled bilinearly, so
/// a map far smaller than the image serves (a 2048 x 2048 PFM is 48 MiB).
pub const MAX_MAP_SIDE: u32 = 2048;

/// The largest displacement a map may hold, in image fractions: a whole image width or
/// height.
pub const MAX_DISPLACEMENT: f64 = 1.0;

/// The largest `strength` of [`DdocMap::from_depth`], image widths.
pub const MAX_STRENGTH: f64 = 0.1;

/// The Gaussian's sigma over the strength (both in pixels): large enough that the field's
/// slope across a straight silhouette, e^-1/2 / 2, stays well below 1.
const SIGMA_PER_STRENGTH: f64 = 2.0;

/// The Gaussian kernel is cut off this many sigmas out (its weight there is e^-8).
const KERNEL_SIGMAS: f64 = 4.0;

/// A per-pixel displacement map (du, dv) in image fractions (u right, v up), pixel centres
/// at ((x + 1/2) / W, 1 - (y + 1/2) / H), rows from the top.
#[derive(Clone, PartialEq)]
pub struct DdocMap {
    width: u32,
    height: u32,
    samples: Vec<DVec2>,
}

impl std::fmt::Debug for DdocMap {
    /// The size only: the samples are too many for a message.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "DdocMap({} x {})", self.width, self.height)
    }
}

impl DdocMap {
    /// A map of `width` x `height` samples, row by row from the top. Errors: a side of 0 or
    /// above [`MAX_MAP_SIDE`], a sample count that is not the size's, a sample not finite or
    /// beyond [`MAX_DISPLACEMENT`] (the first one named by its pixel).
    pub fn new(width: u32, height: u32, samples: Vec<DVec2>) -> Result<DdocMap> {
        if !(1..=MAX_MAP_SIDE).contains(&width) || !(1..=MAX_MAP_SIDE).contains(&height) {
            return Err(Error::new(format!(
                "a ddoc map is 1 to {MAX_MAP_SIDE} pixels a side, got {width} x {height}"
            )));
        }
        if samples.len() != width as usize * height as usize {
            return Err(Error::new(format!(
                "a {width} x {height} ddoc map needs {} samples, got {}",
                width as usize * height as usize,
                samples.len()
            )));
        }
        let bad = samples
            .iter()
            .position(|s| !(s.is_finite() && s.abs().max_element() <= MAX_DISPLACEMENT));
        if let Some(k) = bad {
            let (x, y) = (k % width as usize, k / width as usize);
            return Err(Error::new(format!(
                "ddoc map sample at pixel ({x}, {y}) (from the top left) must be finite and \
                 at most {MAX_DISPLACEMENT} in size, got ({}, {})",
                samples[k].x, samples[k].y
            )));
        }
        Ok(DdocMap {
            width,
            height,
            samples,
        })
    }

    /// The map's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The samples, row by row from the top.
    pub fn samples(&self) -> &[DVec2] {
        &self.samples
    }

    /// m(q): the map at image position `uv`, bilinear between pixel centres, the border
    /// samples beyond them.
    pub fn sample(&self, uv: DVec2) -> DVec2 {
        let cell = self.cell(uv);
        cell.top().lerp(cell.bottom(), cell.fraction.y)
    }

    /// m(q) and its derivative at `uv`: columns dm/du and dm/dv of the bilinear patch there
    /// (zero across a border, beyond which the map is its border samples; on a line between
    /// cells, the next cell's in map pixels).
    pub fn sample_with_slope(&self, uv: DVec2) -> (DVec2, DMat2) {
        let cell = self.cell(uv);
        let [c00, c10, c01, c11] = cell.corners;
        let (top, bottom) = (cell.top(), cell.bottom());
        // d/du = W d/dx and d/dv = -H d/dy inside the map; nothing moves beyond it.
        let du = if cell.inside[0] {
            self.width as f64
        } else {
            0.0
        };
        let dv = if cell.inside[1] {
            -(self.height as f64)
        } else {
            0.0
        };
        let along_x = (c10 - c00).lerp(c11 - c01, cell.fraction.y);
        let slope = DMat2::from_cols(du * along_x, dv * (bottom - top));
        (top.lerp(bottom, cell.fraction.y), slope)
    }

    /// The map cell around `uv`; a position that is not finite gets a cell of zeros (no
    /// displacement, no slope).
    fn cell(&self, uv: DVec2) -> Cell {
        let (w, h) = (self.width as usize, self.height as usize);
        let (x, y) = (uv.x * w as f64 - 0.5, (1.0 - uv.y) * h as f64 - 0.5);
        if !(x.is_finite() && y.is_finite()) {
            return Cell {
                corners: [DVec2::ZERO; 4],
                fraction: DVec2::ZERO,
                inside: [false; 2],
            };
        }
        let (cx, cy) = (x.clamp(0.0, (w - 1) as f64), y.clamp(0.0, (h - 1) as f64));
        let (x0, y0) = (cx.floor() as usize, cy.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
        let at = |x: usize, y: usize| self.samples[y * w + x];
        Cell {
            corners: [at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1)],
            fraction: DVec2::new(cx - x0 as f64, cy - y0 as f64),
            inside: [cx == x, cy == y],
        }
    }

    /// The map's Lipschitz constant in image fractions, and the map pixel (from the top
    /// left) of the cell that reaches it: the largest spectral norm of dm/d(u, v) over the
    /// map. Inside a cell the derivative is affine in the cell's coordinates, so the norm,
    /// a convex function of it, is largest at a corner; every cell's four corner derivatives
    /// are checked. While it is below 1, q - h m(q) is one-to-one for every h in [0, 1].
    pub fn slope(&self) -> (f64, (u32, u32)) {
        let (w, h) = (self.width as usize, self.height as usize);
        let at = |x: usize, y: usize| self.samples[y * w + x];
        let (su, sv) = (w as f64, -(h as f64));
        let mut worst = (0.0, (0, 0));
        for y0 in 0..h.saturating_sub(1).max(1) {
            for x0 in 0..w.saturating_sub(1).max(1) {
                let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
                let su = if x1 > x0 { su } else { 0.0 };
                let sv = if y1 > y0 { sv } else { 0.0 };
                let (top, bottom) = (at(x1, y0) - at(x0, y0), at(x1, y1) - at(x0, y1));
                let (left, right) = (at(x0, y1) - at(x0, y0), at(x1, y1) - at(x1, y0));
                for (along_x, along_y) in
                    [(top, left), (top, right), (bottom, left), (bottom, right)]
                {
                    let norm = spectral_norm(DMat2::from_cols(su * along_x, sv * along_y));
                    if norm > worst.0 {
                        worst = (norm, (x0 as u32, y0 as u32));
                    }
                }
            }
        }
        worst
    }

    /// The map in the PFM file `path` (see [`DdocMap::from_pfm`]). Errors name the file.
    pub fn read(path: &Path) -> Result<DdocMap> {
        let limit = 64 + 12 * u64::from(MAX_MAP_SIDE) * u64::from(MAX_MAP_SIDE);
        let bytes = read_regular(path, "ddoc map", limit)?;
        DdocMap::from_pfm(&bytes).map_err(|e| Error::in_file(path, e.message))
    }

    /// A map from the bytes of a colour PFM (`PF`, width, height, scale: negative for
    /// little-endian, positive for big-endian; rows bottom to top): red is du, green dv, blue
    /// is ignored. Errors: a grayscale or unknown magic, a bad size or scale, data of another
    /// length than the size needs, and the sample checks of [`DdocMap::new`].
    pub fn from_pfm(bytes: &[u8]) -> Result<DdocMap> {
        let (header, data) = pfm_header(bytes)?;
        let [magic, width, height, scale] = header;
        if magic != "PF" {
            return Err(Error::new(format!(
                "a ddoc map is a colour PFM (magic PF: du, dv and an unused channel), got \
                 magic {magic:?}"
            )));
        }
        let side = |text: &str, what: &str| -> Result<u32> {
            text.parse::<u32>()
                .ok()
                .filter(|n| (1..=MAX_MAP_SIDE).contains(n))
                .ok_or_else(|| {
                    Error::new(format!(
                        "ddoc map {what} must be 1 to {MAX_MAP_SIDE} pixels, got {text:?}"
                    ))
                })
        };
        let (w, h) = (side(width, "width")?, side(height, "height")?);
        let scale: f64 = scale
            .parse()
            .ok()
            .filter(|s: &f64| s.is_finite() && *s != 0.0)
            .ok_or_else(|| {
                Error::new(format!(
                    "ddoc map PFM scale must be a non-zero number (negative: little-endian), \
                     got {scale:?}"
                ))
            })?;
        let need = w as usize * h as usize * 12;
        if data.len() != need {
            return Err(Error::new(format!(
                "a {w} x {h} colour PFM holds {need} bytes of samples, the file has {}",
                data.len()
            )));
        }
        let value = |k: usize| {
            let b = [data[k], data[k + 1], data[k + 2], data[k + 3]];
            f64::from(if scale < 0.0 {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            })
        };
        // PFM rows run from the bottom; the map's from the top.
        let (w, h) = (w as usize, h as usize);
        let samples = (0..w * h)
            .map(|k| {
                let (x, y) = (k % w, k / w);
                let at = ((h - 1 - y) * w + x) * 12;
                DVec2::new(value(at), value(at + 4))
            })
            .collect();
        DdocMap::new(w as u32, h as u32, samples)
    }

    /// The map as a little-endian colour PFM (du, dv, 0), rows bottom to top.
    pub fn to_pfm(&self) -> Vec<u8> {
        let mut out = format!("PF\n{} {}\n-1.0\n", self.width, self.height).into_bytes();
        for row in self.samples.chunks(self.width as usize).rev() {
            for s in row {
                for v in [s.x as f32, s.y as f32, 0.0] {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        out
    }

    /// The map of a reference perspective whose depth along the view axis at each pixel is
    /// `depth` (`width` x `height`, rows from the top; infinite where nothing is seen): see
    /// the module. `strength` is the displacement at a straight silhouette in image widths.
    /// Errors: a bad size or depth count, a strength outside (0, [`MAX_STRENGTH`]], z_n and
    /// z_f not 0 < z_n < z_f.
    pub fn from_depth(
        (width, height): (u32, u32),
        depth: &[f64],
        [z_near, z_far]: [f64; 2],
        strength: f64,
    ) -> Result<DdocMap> {
        if !(1..=MAX_MAP_SIDE).contains(&width) || !(1..=MAX_MAP_SIDE).contains(&height) {
            return Err(Error::new(format!(
                "a ddoc map is 1 to {MAX_MAP_SIDE} pixels a side, got {width} x {height}"
            )));
        }
        let (w, h) = (width as usize, height as usize);
        if depth.len() != w * h {
            return Err(Error::new(format!(
                "{} depth samples for a {width} x {height} map",
                depth.len()
            )));
        }
        if !(strength.is_finite() && 0.0 < strength && strength <= MAX_STRENGTH) {
            return Err(Error::new(format!(
                "ddoc map strength must be in (0, {MAX_STRENGTH}] image widths, got {strength}"
            )));
        }
        check_depths(z_near, z_far)?;
        // The unit normals of the silhouette's pixel steps, from the near pixel towards the
        // far one, half on each pixel of the pair.
        let mut normals = vec![DVec2::ZERO; w * h];
        let near = |d: f64| d <= z_near;
        let far = |d: f64| d >= z_far || d.is_nan();
        let mut step = |a: usize, b: usize, n: DVec2| {
            let (da, db) = (depth[a], depth[b]);
            let n = if near(da) && far(db) {
                n
            } else if near(db) && far(da) {
                -n
            } else {
                return;
            };
            normals[a] += 0.5 * n;
            normals[b] += 0.5 * n;
        };
        for y in 0..h {
            for x in 0..w {
                let k = y * w + x;
                if x + 1 < w {
                    step(k, k + 1, DVec2::X);
                }
                if y + 1 < h {
                    step(k, k + w, DVec2::Y);
                }
            }
        }
        let strength_px = strength * w as f64;
        let sigma = SIGMA_PER_STRENGTH * strength_px;
        let field = gaussian_blur(&normals, w, h, sigma);
        // A straight silhouette has one step per pixel of its length: its blurred normals
        // sum to sqrt(2 pi) sigma across it.
        let scale = strength_px / ((2.0 * std::f64::consts::PI).sqrt() * sigma);
        let samples = field
            .into_iter()
            .map(|m| {
                let px = m * scale; // pixels, x right, y down
                DVec2::new(px.x / w as f64, -px.y / h as f64)
            })
            .collect();
        DdocMap::new(width, height, samples)
    }
}

/// The map samples around a position: the corners (x0, y0), (x1, y0), (x0, y1), (x1, y1)
/// (rows from the top), the position's fraction across the cell, and whether it lies inside
/// the map's pixel centres along x and along y (not clamped onto the border).
struct Cell {
    corners: [DVec2; 4],
    fraction: DVec2,
    inside: [bool; 2],
}

impl Cell {
    /// The value along the cell's top row at the position's x.
    fn top(&self) -> DVec2 {
        self.corners[0].lerp(self.corners[1], self.fraction.x)
    }

    /// The value along the cell's bottom row at the position's x.
    fn bottom(&self) -> DVec2 {
        self.corners[2].lerp(self.corners[3], self.fraction.x)
    }
}

/// The four header tokens of a PFM and the bytes after the single whitespace byte that ends
/// the header. Errors: a header that ends early or is not ASCII.
fn pfm_header(bytes: &[u8]) -> Result<([&str; 4], &[u8])> {
    let mut tokens = [""; 4];
    let mut at = 0;
    for token in &mut tokens {
        while at < bytes.len() && bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while at < bytes.len() && at - start < 32 && !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        if at >= bytes.len() || at == start {
            return Err(Error::new(
                "not a PFM: the header (magic, width, height, scale) ends early",
            ));
        }
        *token = std::str::from_utf8(&bytes[start..at])
            .map_err(|_| Error::new("not a PFM: the header is not text"))?;
    }
    Ok((tokens, &bytes[at + 1..]))
}

/// The reference perspective of a `ddoc` preset (its frame, `fov` and clip), whose depth
/// [`DdocMap::from_depth`] reads, and its [z_near, z_far]; `None` for other presets.
pub fn reference(spec: &PresetSpec) -> Option<(PresetSpec, [f64; 2])> {
    let Preset::Ddoc {
        fov, z_near, z_far, ..
    } = spec.preset
    else {
        return None;
    };
    let perspective = PresetSpec {
        preset: Preset::Perspective { fov },
        ..spec.clone()
    };
    Some((perspective, [z_near, z_far]))
}

/// Checks 0 < z_near < z_far, both finite.
pub fn check_depths(z_near: f64, z_far: f64) -> Result<()> {
    if z_near.is_finite() && z_far.is_finite() && 0.0 < z_near && z_near < z_far {
        Ok(())
    } else {
        Err(Error::new(format!(
            "flexible ddoc needs 0 < z_near < z_far, got z_near {z_near}, z_far {z_far}"
        )))
    }
}

/// The largest singular value of `m`.
fn spectral_norm(m: DMat2) -> f64 {
    let [a, b] = [m.x_axis, m.y_axis];
    let frobenius = a.length_squared() + b.length_squared();
    let det = m.determinant();
    let gap = (frobenius * frobenius - 4.0 * det * det).max(0.0).sqrt();
    (0.5 * (frobenius + gap)).sqrt()
}

/// `field` blurred by the unnormalised Gaussian exp(-r^2 / (2 sigma^2)), separably, cut
/// off at [`KERNEL_SIGMAS`] sigmas; beyond the border the field is 0.
fn gaussian_blur(field: &[DVec2], w: usize, h: usize, sigma: f64) -> Vec<DVec2> {
    let reach = (KERNEL_SIGMAS * sigma).ceil() as usize;
    let kernel: Vec<f64> = (0..=reach)
        .map(|d| (-(d as f64).powi(2) / (2.0 * sigma * sigma)).exp())
        .collect();
    let pass = |input: &[DVec2], len: usize, count: usize, at: &dyn Fn(usize, usize) -> usize| {
        let mut out = vec![DVec2::ZERO; input.len()];
        for line in 0..count {
            for i in 0..len {
                let (lo, hi) = (i.saturating_sub(reach), (i + reach).min(len - 1));
                out[at(line, i)] = (lo..=hi)
                    .map(|j| kernel[i.abs_diff(j)] * input[at(line, j)])
                    .sum();
            }
        }
        out
    };
    let rows = pass(field, w, h, &|y, x| y * w + x);
    pass(&rows, h, w, &|x, y| y * w + x)
}

/// A rectangle `corner + x u_edge + y v_edge` evaluated at the displaced parameters
/// (x, y) = q - m(q): the DDOC's Q_zf and far surfaces (see the module).
#[derive(Debug, Clone, PartialEq)]
pub struct DisplacedRectangle {
    /// The rectangle's point at (x, y) = (0, 0).
    pub corner: DVec3,
    /// The step from x = 0 to x = 1.
    pub u_edge: DVec3,
    /// The step from y = 0 to y = 1.
    pub v_edge: DVec3,
    /// m, in image fractions.
    pub map: Arc<DdocMap>,
}

impl DisplacedRectangle {
    /// The surface point at (u, v).
    pub fn point(&self, uv: DVec2) -> DVec3 {
        let w = uv - self.map.sample(uv);
        self.corner + w.x * self.u_edge + w.y * self.v_edge
    }

    /// Whether every coordinate is finite (the map's samples are checked when it is made).
    pub fn is_finite(&self) -> bool {
        self.corner.is_finite() && self.u_edge.is_finite() && self.v_edge.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(w: u32, h: u32, f: impl Fn(usize, usize) -> DVec2) -> DdocMap {
        let samples = (0..(w * h) as usize)
            .map(|k| f(k % w as usize, k / w as usize))
            .collect();
        DdocMap::new(w, h, samples).unwrap()
    }

    #[test]
    fn pfm_round_trips_and_samples_bilinearly() {
        let m = map(3, 2, |x, y| DVec2::new(0.01 * x as f64, -0.02 * y as f64));
        let back = DdocMap::from_pfm(&m.to_pfm()).unwrap();
        assert_eq!(back.size(), (3, 2));
        for (a, b) in m.samples().iter().zip(back.samples()) {
            assert!((*a - *b).length() < 1e-7);
        }
        // Pixel centre (1, 0) from the top left is at u = 1.5 / 3, v = 1 - 0.5 / 2.
        let s = m.sample(DVec2::new(0.5, 0.75));
        assert!((s - DVec2::new(0.01, 0.0)).length() < 1e-12, "{s}");
        // Halfway between the rows, and beyond the border.
        let s = m.sample(DVec2::new(0.5, 0.5));
        assert!((s - DVec2::new(0.01, -0.01)).length() < 1e-12, "{s}");
        let s = m.sample(DVec2::new(-3.0, -3.0));
        assert!((s - DVec2::new(0.0, -0.02)).length() < 1e-12, "{s}");
    }

    #[test]
    fn bad_pfms_are_refused() {
        let good = map(2, 2, |_, _| DVec2::ZERO).to_pfm();
        let header = "PF\n2 2\n-1.0\n".len();
        let mut nan = good.clone();
        nan[header..header + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        let mut huge = good.clone();
        huge[header + 4..header + 8].copy_from_slice(&2.5f32.to_le_bytes());
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (
                good[..good.len() - 1].to_vec(),
                "holds 48 bytes of samples, the file has 47",
            ),
            ([good.as_slice(), &[0]].concat(), "the file has 49"),
            (b"Pf\n2 2\n-1.0\n".to_vec(), "magic \"Pf\""),
            (b"PF\n0 2\n-1.0\n".to_vec(), "width must be 1 to 2048"),
            (b"PF\n2 99999\n-1.0\n".to_vec(), "height must be 1 to 2048"),
            (
                b"PF\n2 2\nzero\n".to_vec(),
                "scale must be a non-zero number",
            ),
            (b"PF\n2".to_vec(), "ends early"),
            (nan, "pixel (0, 1) (from the top left) must be finite"),
            (
                huge,
                "pixel (0, 1) (from the top left) must be finite and at most 1",
            ),
        ];
        for (bytes, expected) in cases {
            let e = DdocMap::from_pfm(&bytes).unwrap_err().message;
            assert!(e.contains(expected), "{e} (expected {expected})");
        }
    }

    /// A near square (depth 2) in front of a far wall (depth 10): the samples around each
    /// silhouette are pushed away from it, outwards (towards the far side), by the strength
    /// at a straight silhouette, falling off away from it.
    #[test]
    fn the_map_pushes_away_from_each_discontinuity() {
        let (w, h) = (120usize, 100usize);
        let inside = |x: usize, y: usize| (40..80).contains(&x) && (30..70).contains(&y);
        let depth: Vec<f64> = (0..w * h)
            .map(|k| if inside(k % w, k / w) { 2.0 } else { 10.0 })
            .collect();
        let strength = 0.02; // 2.4 px
        let m = DdocMap::from_depth((w as u32, h as u32), &depth, [3.0, 8.0], strength).unwrap();
        let at = |x: usize, y: usize| m.samples()[y * w + x];
        // Right of the square's right edge (x = 80): du > 0, about the strength, dv ~ 0.
        let right = at(80, 50);
        assert!(
            right.x > 0.0 && (right.x - strength).abs() < 0.05 * strength,
            "{right}"
        );
        assert!(right.y.abs() < 1e-3 * strength, "{right}");
        // Left of its left edge: du < 0; above its top (y = 29, v up): dv > 0; below: dv < 0.
        assert!(at(39, 50).x < -0.9 * strength);
        assert!(at(60, 29).y > 0.0 && at(60, 70).y < 0.0);
        // Falling off away from the edge, to nothing far from it.
        assert!(at(86, 50).x < right.x && at(86, 50).x > 0.0);
        assert!(at(110, 50).length() < 1e-6 && at(5, 5).length() < 1e-6);
        // No discontinuity, no displacement; depths between z_n and z_f make none either.
        let flat = DdocMap::from_depth((8, 8), &[10.0; 64], [3.0, 8.0], 0.05).unwrap();
        assert!(flat.samples().iter().all(|s| *s == DVec2::ZERO));
        let mid: Vec<f64> = (0..64).map(|k| if k % 8 < 4 { 2.0 } else { 5.0 }).collect();
        let none = DdocMap::from_depth((8, 8), &mid, [3.0, 8.0], 0.05).unwrap();
        assert!(none.samples().iter().all(|s| *s == DVec2::ZERO));
    }

    /// q - m(q) is monotonic across a straight silhouette: the far image does not fold.
    #[test]
    fn the_displaced_positions_do_not_fold_across_a_silhouette() {
        let (w, h) = (200usize, 4usize);
        let depth: Vec<f64> = (0..w * h)
            .map(|k| if k % w < 100 { 1.0 } else { f64::INFINITY })
            .collect();
        let m =
            DdocMap::from_depth((w as u32, h as u32), &depth, [2.0, 4.0], MAX_STRENGTH).unwrap();
        let pos: Vec<f64> = (0..w)
            .map(|x| (x as f64 + 0.5) / w as f64 - m.samples()[w + x].x)
            .collect();
        assert!(pos.windows(2).all(|p| p[1] > p[0]));
    }

    #[test]
    fn bad_parameters_are_refused() {
        let d = [1.0; 4];
        let cases = [
            (
                DdocMap::from_depth((2, 2), &d, [1.0, 2.0], 0.0),
                "strength must be in (0, 0.1]",
            ),
            (
                DdocMap::from_depth((2, 2), &d, [1.0, 2.0], 0.5),
                "strength must be in",
            ),
            (
                DdocMap::from_depth((2, 2), &d, [2.0, 2.0], 0.05),
                "0 < z_near < z_far",
            ),
            (
                DdocMap::from_depth((2, 2), &d[..3], [1.0, 2.0], 0.05),
                "3 depth samples",
            ),
            (
                DdocMap::from_depth((0, 2), &d, [1.0, 2.0], 0.05),
                "1 to 2048 pixels",
            ),
        ];
        for (result, expected) in cases {
            let e = result.unwrap_err().message;
            assert!(e.contains(expected), "{e} (expected {expected})");
        }
    }
}
