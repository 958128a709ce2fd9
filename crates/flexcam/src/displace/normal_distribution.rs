//! Normal distributions of a displaced surface seen from each view angle (Becker and Max
//! 1993; Ramsey 2005, section 5.2): rays are fired at the height field as a grid of bilinear
//! patches from many view directions, the normals they hit are histogrammed, and each view's
//! histogram is normalised to sum to 1. These visible-normal distributions are what the
//! diffuse BRDF ([`super::brdf_table`]) and redistributed bump mapping ([`super::bump`]) are
//! built from, so that all three rendering methods of the transition system agree in
//! intensity.
//!
//! The surface is a [`Chart`]: the height field over one period of uv laid flat at the world
//! size of that period (`size`, the mean lengths of `dP/du` and `dP/dv` over an object), its
//! heights `z = S * F * (h - h_max)` on a grid of `cells x cells` nodes, bilinear between
//! them. The chart is periodic, so rays leaving one side come back on the other.
//!
//! Histograms are over the Shirley-Chiu square ([`super::square_map`]), [`BINS`] x [`BINS`]
//! bins of equal solid angle, in the frame of the view: the surface normal is `+z` and the
//! viewer's azimuth is `+x`. The distributions are isotropic, as the dissertation's are:
//! each view angle averages [`AZIMUTHS`] view azimuths, each hit normal rotated into its
//! view's frame. View angles are [`VIEWS`] nodes from 0 to [`MAX_VIEW`]; steeper views use
//! the last node.
//!
//! Degenerate cases: a flat height field or a zero scale puts every normal in the middle bin,
//! whose centre is the unmoved normal `(0, 0, 1)`, at every view angle.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::height::HeightField;
use super::square_map::to_square;
use crate::error::{Error, Result};
use crate::geometry::{BilinearPatch, Ray};

/// Histogram bins per side of the square (odd: the pole is the middle bin's centre).
pub const BINS: usize = 31;
/// View-angle nodes of a distribution.
pub const VIEWS: usize = 31;
/// The largest view angle tabulated (radians; 86 degrees).
pub const MAX_VIEW: f64 = 86.0 * PI / 180.0;
/// View azimuths averaged per view angle.
pub const AZIMUTHS: usize = 8;

/// A periodic height field over one period of uv, laid flat at world size (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    cells: usize,
    size: DVec2,
    /// `z` at node `(i, j)` (i along u) at index `j * cells + i`.
    heights: Vec<f64>,
    lo: f64,
    hi: f64,
}

impl Chart {
    /// The chart of `height` at world size `size` (of one uv period), heights scaled by
    /// `scale` (`S * F`) below `h_max`, on `cells x cells` nodes. Errors: fewer than 2 cells,
    /// a size that is not positive and finite, a scale that is not finite.
    pub fn new(height: &HeightField, scale: f64, size: DVec2, cells: usize) -> Result<Chart> {
        if cells < 2 {
            return Err(Error::new(format!(
                "a chart needs 2 cells or more, not {cells}"
            )));
        }
        if !(size.is_finite() && size.min_element() > 0.0) {
            return Err(Error::new(format!(
                "a chart's size must be positive and finite, not {size}"
            )));
        }
        if !scale.is_finite() {
            return Err(Error::new(format!("chart scale {scale} is not finite")));
        }
        let h_max = height.max();
        let heights: Vec<f64> = (0..cells * cells)
            .map(|k| {
                let uv = DVec2::new((k % cells) as f64, (k / cells) as f64) / cells as f64;
                scale * (height.sample(uv) - h_max)
            })
            .collect();
        let lo = heights.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Ok(Chart {
            cells,
            size,
            heights,
            lo,
            hi,
        })
    }

    /// The world size of one uv period.
    pub fn size(&self) -> DVec2 {
        self.size
    }

    /// Highest minus lowest node height (world units).
    pub fn relief(&self) -> f64 {
        self.hi - self.lo
    }

    /// The height field's mean wavelength (world units): `2 pi sigma_z / sigma_g`, the root
    /// mean square of the heights about their mean over that of the slopes (the cells' edge
    /// slopes, the gradients bump mapping shades with), which is the exact wavelength of a
    /// single wave in any direction and, for a mixture, a wavelength weighted towards the
    /// components that tilt the normals most. It is how far apart the bumps are, which
    /// decides whether a footprint resolves them (the transition function's frequency term,
    /// [`crate::displace::transition`]). A flat chart has no bumps: 0.
    pub fn wavelength(&self) -> f64 {
        let n = self.cells as i64;
        let count = (n * n) as f64;
        let mean = self.heights.iter().sum::<f64>() / count;
        let height_square = self
            .heights
            .iter()
            .map(|z| (z - mean) * (z - mean))
            .sum::<f64>()
            / count;
        let cell = self.cell();
        let mut slope_square = 0.0;
        for j in 0..n {
            for i in 0..n {
                let z = self.z(i, j);
                let along_u = (self.z(i + 1, j) - z) / cell.x;
                let along_v = (self.z(i, j + 1) - z) / cell.y;
                slope_square += along_u * along_u + along_v * along_v;
            }
        }
        let slope_square = slope_square / count;
        if slope_square > 0.0 {
            2.0 * PI * (height_square / slope_square).sqrt()
        } else {
            0.0
        }
    }

    /// The height at node `(i, j)`, wrapping.
    fn z(&self, i: i64, j: i64) -> f64 {
        let n = self.cells as i64;
        self.heights[(j.rem_euclid(n) * n + i.rem_euclid(n)) as usize]
    }

    /// World size of a cell.
    fn cell(&self) -> DVec2 {
        self.size / self.cells as f64
    }

    /// The unit normal (`z > 0`, `x` along u) of the bilinear surface at texture coordinates
    /// `uv` (wrapping): what bump mapping shades with.
    pub fn normal(&self, uv: DVec2) -> DVec3 {
        let g = uv * self.cells as f64;
        let (i, j) = (g.x.floor(), g.y.floor());
        let f = g - DVec2::new(i, j);
        let (i, j) = (i as i64, j as i64);
        let [z00, z10, z01, z11] = [
            self.z(i, j),
            self.z(i + 1, j),
            self.z(i, j + 1),
            self.z(i + 1, j + 1),
        ];
        let twist = z11 - z10 - z01 + z00;
        let cell = self.cell();
        let dzdx = (z10 - z00 + f.y * twist) / cell.x;
        let dzdy = (z01 - z00 + f.x * twist) / cell.y;
        DVec3::new(-dzdx, -dzdy, 1.0).normalize()
    }

    /// The unit normal (`z > 0`) where the ray entering the chart's top plane at world point
    /// `entry` with direction `direction` (`z < 0`) first meets the surface: a 2D grid walk
    /// over the cells under the ray, each cell's bilinear patch tested where the ray's
    /// height range meets the cell's. `None` for a direction that does not descend.
    pub fn trace(&self, entry: DVec2, direction: DVec3) -> Option<DVec3> {
        if direction.z.is_nan() || direction.z >= 0.0 {
            return None;
        }
        let cell = self.cell();
        let origin = DVec3::new(entry.x, entry.y, self.hi);
        let g = entry / cell;
        let (mut i, mut j) = (g.x.floor() as i64, g.y.floor() as i64);
        let step = |d: f64| if d > 0.0 { 1 } else { -1 };
        let (si, sj) = (step(direction.x), step(direction.y));
        let next = |k: i64, s: i64, o: f64, d: f64, w: f64| {
            if d == 0.0 {
                f64::INFINITY
            } else {
                ((k + i64::from(s > 0)) as f64 * w - o) / d
            }
        };
        let mut tx = next(i, si, entry.x, direction.x, cell.x);
        let mut ty = next(j, sj, entry.y, direction.y, cell.y);
        let (dtx, dty) = (cell.x / direction.x.abs(), cell.y / direction.y.abs());
        let t_bottom = (self.lo - self.hi) / direction.z;
        let mut t_enter = 0.0;
        let slack = 1e-9 * (cell.x + cell.y + self.relief());
        loop {
            let t_exit = tx.min(ty).min(t_bottom);
            let corners = [
                self.z(i, j),
                self.z(i + 1, j),
                self.z(i, j + 1),
                self.z(i + 1, j + 1),
            ];
            let top = corners.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if origin.z + direction.z * t_exit <= top + slack {
                let at = |di: i64, dj: i64, z: f64| {
                    DVec3::new((i + di) as f64 * cell.x, (j + dj) as f64 * cell.y, z)
                };
                let patch = BilinearPatch {
                    p00: at(0, 0, corners[0]),
                    p10: at(1, 0, corners[1]),
                    p01: at(0, 1, corners[2]),
                    p11: at(1, 1, corners[3]),
                };
                let ray = Ray {
                    origin,
                    direction,
                    t_min: t_enter - slack,
                    t_max: t_exit + slack,
                };
                if let Some(hit) = patch.intersect(&ray) {
                    let f = hit.uv;
                    let twist = corners[3] - corners[1] - corners[2] + corners[0];
                    let dzdx = (corners[1] - corners[0] + f.y * twist) / cell.x;
                    let dzdy = (corners[2] - corners[0] + f.x * twist) / cell.y;
                    return Some(DVec3::new(-dzdx, -dzdy, 1.0).normalize());
                }
            }
            if t_exit >= t_bottom {
                // Below the lowest node: a surface point at the bottom (a flat chart) or a
                // ray lost to rounding: the cell's own normal there.
                return Some(self.normal((origin + direction * t_bottom).truncate() / self.size));
            }
            t_enter = t_exit;
            if tx < ty {
                i += si;
                tx += dtx;
            } else {
                j += sj;
                ty += dty;
            }
        }
    }
}

/// Visible-normal histograms of a chart per view angle (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct NormalDistribution {
    /// Per view node, `BINS * BINS` bin masses summing to 1, bin `(a, b)` at `b * BINS + a`.
    views: Vec<Vec<f64>>,
}

impl NormalDistribution {
    /// The distribution of `chart` from `rays x rays` stratified rays per view azimuth and
    /// view angle (in parallel over view angles).
    pub fn new(chart: &Chart, rays: usize) -> NormalDistribution {
        let views = (0..VIEWS)
            .into_par_iter()
            .map(|k| visible_normals(chart, view_angle(k), rays, k as u64))
            .collect();
        NormalDistribution { views }
    }

    /// The normalised histogram of view node `k`.
    pub fn view(&self, k: usize) -> &[f64] {
        &self.views[k]
    }
}

/// The normalised histogram of the normals of `chart` visible from view angle `theta`
/// ([`visible_normal_samples`]).
pub fn visible_normals(chart: &Chart, theta: f64, rays: usize, seed: u64) -> Vec<f64> {
    histogram(&visible_normal_samples(chart, theta, rays, seed))
}

/// The normals of `chart` visible from view angle `theta`, each in its view's frame (viewer
/// at `+x`): for each of [`AZIMUTHS`] strata of the view azimuth, `rays x rays` rays at
/// stratified points of the chart, each from its own azimuth within the stratum (a fixed
/// set of azimuths would leave the histogram with their symmetry instead of an isotropic
/// one), jittered by `seed`.
pub fn visible_normal_samples(chart: &Chart, theta: f64, rays: usize, seed: u64) -> Vec<DVec3> {
    let rays = rays.max(1);
    let mut normals = Vec::with_capacity(AZIMUTHS * rays * rays);
    for m in 0..AZIMUTHS {
        for s in 0..rays * rays {
            let index = ((seed * AZIMUTHS as u64 + m as u64) * (rays * rays) as u64) + s as u64;
            let phi = 2.0 * PI * (m as f64 + unit(3 * index + 2)) / AZIMUTHS as f64;
            let view = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let cell = DVec2::new((s % rays) as f64, (s / rays) as f64);
            let jitter = DVec2::new(unit(3 * index), unit(3 * index + 1));
            let entry = (cell + jitter) / rays as f64 * chart.size();
            if let Some(n) = chart.trace(entry, -view) {
                normals.push(rotate(n, -phi));
            }
        }
    }
    normals
}

/// The view angle of node `k`.
pub fn view_angle(k: usize) -> f64 {
    k as f64 * MAX_VIEW / (VIEWS - 1) as f64
}

/// The node below view angle `theta` and the weight of the node above it (clamped to the
/// tabulated range).
pub fn view_node(theta: f64) -> (usize, f64) {
    let x = (theta / MAX_VIEW * (VIEWS - 1) as f64).clamp(0.0, (VIEWS - 1) as f64);
    let k = (x.floor() as usize).min(VIEWS - 2);
    (k, x - k as f64)
}

/// `n` rotated by `angle` about `z`.
pub fn rotate(n: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    DVec3::new(c * n.x - s * n.y, s * n.x + c * n.y, n.z)
}

/// The bin of square point `p`.
pub fn bin(p: DVec2) -> usize {
    let index = |x: f64| ((x * BINS as f64) as usize).min(BINS - 1);
    index(p.y) * BINS + index(p.x)
}

/// The normalised histogram of unit normals `normals` (all zero when there are none).
pub fn histogram(normals: &[DVec3]) -> Vec<f64> {
    let mut bins = vec![0.0; BINS * BINS];
    for n in normals {
        bins[bin(to_square(*n))] += 1.0;
    }
    let total: f64 = bins.iter().sum();
    if total > 0.0 {
        bins.iter_mut().for_each(|b| *b /= total);
    }
    bins
}

/// The total variation distance between two normalised histograms: half the sum of the
/// absolute differences, 0 for equal ones, 1 for disjoint ones.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    0.5 * a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>()
}

/// A deterministic number in `[0, 1)` from `seed` (SplitMix64).
pub fn unit(seed: u64) -> f64 {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

#[cfg(test)]
pub(crate) mod tests;
