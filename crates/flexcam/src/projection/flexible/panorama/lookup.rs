//! The inverse of a shape-defined panorama by lookup tables (thesis 9.4.2), for
//! `--method raster`.
//!
//! Every projector of a panorama leaves the eye, so a scene point p is seen along its
//! direction from the eye, given by its spherical angles: the azimuth theta = atan2(x, z)
//! (from the view direction towards the right) and the elevation phi above the horizontal
//! plane. With one outline and one profile (P_p(v)_x > 0), Q_1(u, v) has azimuth
//! atan2(P_o(u)_x, P_o(u)_y), a function of u alone, and elevation atan2(P_p(v)_y,
//! rho P_p(v)_x) with rho = |P_o(u)|, so
//! - u comes from a table of outline azimuths sampled uniformly in arc length;
//! - v from a table of profile elevations psi(v) = atan2(P_p(v)_y, P_p(v)_x), looked up at
//!   the corrected elevation phi' = atan2(y, sqrt(x^2 + z^2) / rho);
//! - t from the distance: |p - eye| = d |Q_1(u, v)| with d = near + t (far - near).
//!
//! Both lookups interpolate linearly between [`TABLE_SAMPLES`] + 1 samples, so (u, v) is
//! exact at the samples and off by O(h^2) between them (h = 1 / TABLE_SAMPLES): the image
//! position of a point is within about 1e-6 of the image size of the exact one (measured by
//! the round-trip tests), far below a pixel at any size this renderer draws.
//!
//! Degenerate cases: points on the up axis through the eye (no azimuth) have no image (the
//! chart's poles); elevations beyond the profile's ends continue the end slopes of the table
//! (v outside [0, 1], clipped by [`super::super::inverse::Inverse::solve`]). Panoramas
//! outside the class have no lookup inverse ([`PanoramaInverse::new`] gives `None`): several
//! outlines or profiles (their azimuth depends on v, their profile on u), an outline whose
//! azimuth does not grow strictly along it (not star-shaped around the eye), and a profile
//! that reaches behind the up axis or whose elevation does not grow strictly along it.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::super::super::camera_basis::CameraBasis;
use super::super::super::chart::{axis_poles, InverseChart};
use super::super::super::image_coords::Resolution;
use super::super::reparam::Reparam;
use super::{ArcCurve, PanoramaShape, PanoramaSurface};

/// Intervals per lookup table (the thesis suggests half the image's larger dimension; this
/// covers any image the renderer draws).
pub const TABLE_SAMPLES: usize = 4096;

/// The lookup's stated accuracy in (u, v) and t. The tables alone are off by O(h) beside a
/// kink of a polyline outline or profile (measured 6e-5 in u, h = 1 / TABLE_SAMPLES), so
/// each lookup is polished on the exact curve ([`POLISH_STEPS`]); what remains is rounding.
/// The inverse's domain test allows this much outside [0, 1], so that points on the
/// volume's boundary (the near surface, t = 0) are kept.
pub const ACCURACY: f64 = 1e-6;

/// False-position (Illinois) steps that polish a table lookup on the exact curve, inside the
/// bracketing table interval: superlinear on smooth pieces, still converging at a kink.
const POLISH_STEPS: usize = 12;

/// A strictly increasing angle sampled at s = k / [`TABLE_SAMPLES`], k = 0..=TABLE_SAMPLES.
#[derive(Debug, Clone, PartialEq)]
struct AngleTable {
    angles: Vec<f64>,
}

impl AngleTable {
    /// The table of `angle` (already unwrapped by the caller), or `None` when it does not
    /// increase strictly or is not finite.
    fn new(mut angle: impl FnMut(f64) -> f64) -> Option<Self> {
        let n = TABLE_SAMPLES as f64;
        let angles: Vec<f64> = (0..=TABLE_SAMPLES).map(|k| angle(k as f64 / n)).collect();
        let increasing = angles.windows(2).all(|w| w[0] < w[1]);
        (increasing && angles.iter().all(|a| a.is_finite())).then_some(AngleTable { angles })
    }

    /// The parameter s at which the curve's angle reaches `angle`: the bracketing table
    /// interval, then false position on `exact` (the angle of the curve at s, unwrapped like
    /// the table) inside it. Beyond the ends the end intervals continue linearly.
    fn lookup(&self, angle: f64, exact: impl Fn(f64) -> f64) -> f64 {
        let a = &self.angles;
        let n = TABLE_SAMPLES as f64;
        let k = a.partition_point(|&x| x <= angle).clamp(1, a.len() - 1) - 1;
        let linear = |k: usize| (k as f64 + (angle - a[k]) / (a[k + 1] - a[k])) / n;
        if angle <= a[0] || angle >= a[TABLE_SAMPLES] {
            return linear(k);
        }
        let (mut lo, mut hi) = (k as f64 / n, (k + 1) as f64 / n);
        let (mut f_lo, mut f_hi) = (a[k] - angle, a[k + 1] - angle);
        for _ in 0..POLISH_STEPS {
            if f_hi - f_lo <= 0.0 {
                break;
            }
            let s = (lo - f_lo * (hi - lo) / (f_hi - f_lo)).clamp(lo, hi);
            let f = exact(s) - angle;
            if f == 0.0 {
                return s;
            }
            if f < 0.0 {
                (lo, f_lo) = (s, f);
                f_hi *= 0.5;
            } else {
                (hi, f_hi) = (s, f);
                f_lo *= 0.5;
            }
        }
        if f_hi - f_lo > 0.0 {
            lo - f_lo * (hi - lo) / (f_hi - f_lo)
        } else {
            linear(k)
        }
    }
}

/// The lookup inverse of the volume between two panorama surfaces of one shape.
#[derive(Debug, Clone, PartialEq)]
pub struct PanoramaInverse {
    basis: CameraBasis,
    near: f64,
    far: f64,
    shape: Arc<PanoramaShape>,
    outline: AngleTable,
    profile: AngleTable,
}

/// The representative of angle `a` within pi of `reference`.
fn unwrap_near(a: f64, reference: f64) -> f64 {
    let turn = 2.0 * PI;
    a + turn * ((reference - a) / turn).round()
}

/// The azimuth of a horizontal (right, forward) direction, from forward towards the right.
fn azimuth(d: DVec2) -> f64 {
    d.x.atan2(d.y)
}

impl PanoramaInverse {
    /// The inverse of the volume from `near` to `far`, when both share eye, frame and shape,
    /// have different scales and the shape is in the class of the module.
    pub fn new(near: &PanoramaSurface, far: &PanoramaSurface) -> Option<Self> {
        let same = near.basis == far.basis
            && (Arc::ptr_eq(&near.shape, &far.shape) || near.shape == far.shape)
            && near.scale != far.scale;
        let shape = &near.shape;
        if !same || shape.outlines().len() != 1 || shape.profiles().len() != 1 {
            return None;
        }
        let outline = &shape.outlines()[0].curve;
        let profile = &shape.profiles()[0].curve;
        Some(PanoramaInverse {
            basis: near.basis,
            near: near.scale,
            far: far.scale,
            shape: Arc::clone(shape),
            outline: outline_table(outline)?,
            profile: profile_table(profile)?,
        })
    }

    /// (u, v) and t of scene point `p`, extended beyond the volume (v and t outside [0, 1]
    /// continue; u wraps into [0, 1]). `None` on the up axis through the eye.
    pub fn solve(&self, p: DVec3) -> Option<(DVec2, f64)> {
        let local = self.basis.to_local(p - self.basis.origin);
        let horizontal = DVec2::new(local.x, local.z);
        let h = horizontal.length();
        if h == 0.0 || !h.is_finite() {
            return None;
        }
        let target = azimuth(horizontal);
        let outline = &self.shape.outlines()[0].curve;
        let u = self
            .outline
            .lookup(target, |s| unwrap_near(azimuth(outline.at(s)), target))
            .clamp(0.0, 1.0);
        let rho = outline.at(u).length();
        let profile = &self.shape.profiles()[0].curve;
        let v = self.profile.lookup(local.y.atan2(h / rho), |s| {
            let p = profile.at(s);
            p.y.atan2(p.x)
        });
        let uv = DVec2::new(u, v);
        let reach = self.shape.local(uv).length();
        if reach == 0.0 {
            return None;
        }
        let d = local.length() / reach;
        Some((uv, (d - self.near) / (self.far - self.near)))
    }

    /// The chart under `reparam` (linear only: u wraps once across the image width): the
    /// seam period and the poles up and down the axis through the eye, with the clearance
    /// left by the highest and lowest pixel-centre rows.
    pub fn chart(&self, reparam: Reparam, resolution: &Resolution) -> Option<InverseChart> {
        (reparam == Reparam::Linear).then_some(())?;
        let (v_lo, v_hi) = reparam.v_range(resolution)?;
        let (rho_lo, rho_hi) = self.shape.outlines()[0].curve.distance_range();
        let profile = &self.shape.profiles()[0].curve;
        // The elevation of row v over all u: atan2(y, rho x), extreme at the nearest or the
        // farthest outline point.
        let elevations = |v: f64| {
            let p = profile.at(v);
            let a = p.y.atan2(rho_lo * p.x);
            let b = p.y.atan2(rho_hi * p.x);
            (a.min(b), a.max(b))
        };
        let lowest = elevations(v_lo).0;
        let highest = elevations(v_hi).1;
        Some(InverseChart {
            clip: Vec::new(),
            period: Some(f64::from(resolution.width)),
            poles: axis_poles(self.basis.origin, self.basis.up, lowest, highest),
        })
    }
}

/// Outline azimuths from -pi at the seam (behind the eye) up to pi, unwrapped.
fn outline_table(outline: &ArcCurve) -> Option<AngleTable> {
    let mut previous = -PI;
    let table = AngleTable::new(|s| {
        previous = unwrap_near(azimuth(outline.at(s)), previous);
        previous
    })?;
    let ends = (table.angles[0], table.angles[TABLE_SAMPLES]);
    ((ends.0 + PI).abs() < 1e-9 && (ends.1 - PI).abs() < 1e-9).then_some(table)
}

/// Profile elevations psi(v) = atan2(y, x), none when a point lies behind the axis.
fn profile_table(profile: &ArcCurve) -> Option<AngleTable> {
    let n = TABLE_SAMPLES as f64;
    let in_front = (0..=TABLE_SAMPLES).all(|k| profile.at(k as f64 / n).x >= 0.0);
    in_front.then_some(())?;
    AngleTable::new(|s| {
        let p = profile.at(s);
        p.y.atan2(p.x)
    })
}
