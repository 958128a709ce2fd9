//! The inverse of a shape-defined panorama by lookup tables (thesis 9.4.2), for
//! `--method raster`.
//!
//! Every projector of a panorama leaves the eye, so a scene point p is seen along its
//! direction from the eye, given by its spherical angles: the azimuth theta = atan2(x, z)
//! (from the view direction towards the right) and the elevation phi above the horizontal
//! plane. Q_1(u, v) = (O_x P_x, P_y, O_y P_x), with O the outline blended at row v and P the
//! profile blended at column u (P_x >= 0), has azimuth atan2(O_x, O_y) and elevation
//! atan2(P_y, rho P_x) with rho = |O|, so
//! - u comes from the azimuths of the outline at row v, sampled uniformly in arc length;
//! - v from the elevations psi = atan2(P_y, P_x) of the profile at column u, looked up at
//!   the corrected elevation phi' = atan2(y, sqrt(x^2 + z^2) / rho);
//! - t from the distance: |p - eye| = d |Q_1(u, v)| with d = near + t (far - near).
//!
//! Each curve is sampled at [`TABLE_SAMPLES`] + 1 fractions; a blend of two curves is
//! sampled by blending their samples (the blend is pointwise, so its samples are exact). A
//! lookup is a binary search of the (blended) samples' angles, polished on the exact blended
//! curve inside the bracketing interval (`POLISH_STEPS`).
//!
//! With one outline, u depends on the azimuth alone and the lookup is separable: u, then v.
//! With several outlines the outline depends on v, so u and v are coupled: v is the fixed
//! point of v -> row(column(v)) (column: u at row v; row: v at column u with the rho of
//! (u, v)), found by secant steps on its residual from the uncoupled guess, converged when
//! the residual is below [`COUPLED_TOLERANCE`] within [`COUPLED_STEPS`] steps (and |v|
//! within [`COUPLED_RANGE`]); a point where it does not converge has no image and its triangles are dropped like those
//! touching a pole (`raster_singular_pieces`).
//!
//! The class, checked by [`PanoramaInverse::new`], which says why a shape is outside it:
//! every outline and every blend of two neighbouring outlines must be star-shaped around the
//! eye (its azimuth grows strictly along it, once around), every profile and every blend
//! of two neighbours must stay in front of the up axis (P_x >= 0) with an elevation growing
//! strictly along it. For a blend (1 - w) A + w B the turn between neighbouring samples k,
//! k + 1 is a quadratic in w, (1 - w)^2 a + 2 w (1 - w) b + w^2 c in Bernstein form, checked
//! positive for all w in [0, 1] exactly (a, c > 0 and b > -sqrt(a c)); linear and smooth
//! blends share the range of w, so one check covers both. Two outlines whose points at one
//! u lie 180 degrees or more apart around the eye are refused too (their blend would pass
//! the eye). These checks make u unique at each row and v unique at each column; with
//! several outlines, two different (u, v) of one direction are not excluded by them, and
//! the iteration finds one.
//!
//! Accuracy: the polished lookups are exact but for rounding; the stated [`ACCURACY`] is
//! what the round-trip tests hold to.
//!
//! A shape windowed to the outline fractions [s0, s1] ([`PanoramaShape::windowed`], a
//! panorama of less than a full turn) looks u up the same way, as the outline fraction s,
//! and reports the image column (s - s0) / (s1 - s0) with s taken within half a turn of the
//! window's middle: directions outside the window get u outside [0, 1] (clipped by the
//! inverse's domain test), and u jumps by one turn, 1 / (s1 - s0), only straight opposite
//! the window, which the chart gives the rasteriser as its period.
//!
//! Degenerate cases: points on the up axis through the eye (no azimuth) have no image (the
//! chart's poles); elevations beyond the profile's ends continue the end intervals of the
//! samples linearly (v outside [0, 1], clipped by the inverse's `Inverse::solve`);
//! a coupled iteration that does not converge (above).

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::super::super::camera_basis::CameraBasis;
use super::super::super::chart::{axis_poles, InverseChart};
use super::super::super::image_coords::Resolution;
use super::super::reparam::Reparam;
use super::{ArcCurve, Attached, PanoramaShape, PanoramaSurface};
use crate::error::{Error, Result};

/// Intervals per sampled curve (the thesis suggests half the image's larger dimension; this
/// covers any image the renderer draws).
pub const TABLE_SAMPLES: usize = 4096;

/// The lookup's stated accuracy in (u, v) and t. The samples alone are off by O(h) beside a
/// kink of a polyline outline or profile (measured 6e-5 in u, h = 1 / TABLE_SAMPLES), so
/// each lookup is polished on the exact curve (`POLISH_STEPS`); what remains is rounding.
/// The inverse's domain test allows this much outside [0, 1], so that points on the
/// volume's boundary (the near surface, t = 0) are kept.
pub const ACCURACY: f64 = 1e-6;

/// False-position (Illinois) steps that polish a lookup on the exact curve, inside the
/// bracketing sample interval: superlinear on smooth pieces, still converging at a kink.
const POLISH_STEPS: usize = 12;

/// Several outlines: the largest residual |row(column(v)) - v| accepted as converged.
pub const COUPLED_TOLERANCE: f64 = 1e-11;

/// Several outlines: the most secant steps of the coupled iteration.
pub const COUPLED_STEPS: usize = 40;

/// Several outlines: the coupled iteration fails once |v| exceeds this (a map without a
/// fixed point drives the secant steps away; far out, the residual would round to 0).
pub const COUPLED_RANGE: f64 = 1e3;

/// A curve sampled at s = k / [`TABLE_SAMPLES`], k = 0..=TABLE_SAMPLES, with the angle of
/// each sample seen from the eye (unwrapped: continuous along the curve).
#[derive(Debug, Clone, PartialEq)]
struct Samples {
    points: Vec<DVec2>,
    angles: Vec<f64>,
}

impl Samples {
    /// The samples of `curve` and their angles by `angle`, unwrapped from near `start`.
    fn new(curve: &ArcCurve, angle: impl Fn(DVec2) -> f64, start: f64) -> Self {
        let n = TABLE_SAMPLES as f64;
        let points: Vec<DVec2> = (0..=TABLE_SAMPLES)
            .map(|k| curve.at(k as f64 / n))
            .collect();
        let mut previous = start;
        let angles = points
            .iter()
            .map(|&p| {
                previous = unwrap_near(angle(p), previous);
                previous
            })
            .collect();
        Samples { points, angles }
    }

    /// Whether the angles are finite and increase strictly.
    fn increasing(&self) -> bool {
        self.angles.iter().all(|a| a.is_finite()) && self.angles.windows(2).all(|w| w[0] < w[1])
    }
}

/// The sample angles of the blend of two sampled curves with weight `w` of the second, by
/// `angle` of the blended point, unwrapped near the blend of the two angles (the curves'
/// points at one sample lie less than 180 degrees apart: checked by the callers).
#[derive(Clone, Copy)]
struct Blend<'a> {
    first: &'a Samples,
    second: &'a Samples,
    w: f64,
}

impl Blend<'_> {
    fn angle(&self, k: usize, angle: impl Fn(DVec2) -> f64) -> f64 {
        let a = self.first.angles[k];
        if self.w == 0.0 {
            return a;
        }
        let p = self.first.points[k].lerp(self.second.points[k], self.w);
        unwrap_near(angle(p), a + self.w * (self.second.angles[k] - a))
    }
}

/// The fraction s at which an increasing sampled angle reaches `target`: the bracketing
/// sample interval by binary search over `sample(k)`, then false position on `exact` (the
/// angle of the exact curve at s, unwrapped like the samples) inside it. Beyond the ends the
/// end intervals continue linearly.
fn invert(sample: impl Fn(usize) -> f64, exact: impl Fn(f64) -> f64, target: f64) -> f64 {
    let n = TABLE_SAMPLES;
    let (first, last) = (sample(0), sample(n));
    let k = if target <= first {
        0
    } else if target >= last {
        n - 1
    } else {
        let (mut lo, mut hi) = (0, n);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if sample(mid) <= target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    let (a, b) = (sample(k), sample(k + 1));
    let linear = (k as f64 + (target - a) / (b - a)) / n as f64;
    if target <= first || target >= last {
        return linear;
    }
    let (mut lo, mut hi) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
    let (mut f_lo, mut f_hi) = (a - target, b - target);
    for _ in 0..POLISH_STEPS {
        if f_hi - f_lo <= 0.0 {
            break;
        }
        let s = (lo - f_lo * (hi - lo) / (f_hi - f_lo)).clamp(lo, hi);
        let f = exact(s) - target;
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
        linear
    }
}

/// The lookup inverse of the volume between two panorama surfaces of one shape.
#[derive(Debug, Clone, PartialEq)]
pub struct PanoramaInverse {
    basis: CameraBasis,
    near: f64,
    far: f64,
    shape: Arc<PanoramaShape>,
    outlines: Vec<Samples>,
    profiles: Vec<Samples>,
}

/// The representative of angle `a` within pi of `reference`.
fn unwrap_near(a: f64, reference: f64) -> f64 {
    a + TAU * ((reference - a) / TAU).round()
}

/// The azimuth of a horizontal (right, forward) direction, from forward towards the right.
fn azimuth(d: DVec2) -> f64 {
    d.x.atan2(d.y)
}

/// The elevation of a profile point (distance from the up axis, height) seen from the eye.
fn elevation(p: DVec2) -> f64 {
    p.y.atan2(p.x)
}

impl PanoramaInverse {
    /// The inverse of the volume from `near` to `far`. Errors (the reason, for the refusal
    /// of `--method raster`): surfaces of different eyes, frames or shapes or of one scale,
    /// and shapes outside the class of the module.
    pub fn new(near: &PanoramaSurface, far: &PanoramaSurface) -> Result<Self> {
        let same = near.basis == far.basis
            && (Arc::ptr_eq(&near.shape, &far.shape) || near.shape == far.shape)
            && near.scale != far.scale;
        if !same {
            return Err(Error::new(
                "its near and far panorama surfaces differ in eye, frame or shape, or coincide",
            ));
        }
        let shape = &near.shape;
        Ok(PanoramaInverse {
            basis: near.basis,
            near: near.scale,
            far: far.scale,
            shape: Arc::clone(shape),
            outlines: outline_samples(shape.outlines())?,
            profiles: profile_samples(shape.profiles())?,
        })
    }

    /// The outline fraction at row `v` for the (unwrapped) azimuth `theta`, in [0, 1].
    fn fraction(&self, theta: f64, v: f64) -> f64 {
        let (i, j, w) = self.shape.outline_blend(v);
        let blend = Blend {
            first: &self.outlines[i],
            second: &self.outlines[j],
            w,
        };
        let sample = |k| blend.angle(k, azimuth);
        // The blended outline turns once around from its seam sample: theta within one turn
        // above it.
        let start = sample(0);
        let target = start + (theta - start).rem_euclid(TAU);
        let exact = |s| unwrap_near(azimuth(self.shape.outline_at(s, v)), target);
        invert(sample, exact, target).clamp(0.0, 1.0)
    }

    /// v at column `u` for the elevation `phi'` corrected for the outline's distance.
    fn row(&self, corrected: f64, u: f64) -> f64 {
        let (i, j, w) = self.shape.profile_blend(u);
        let blend = Blend {
            first: &self.profiles[i],
            second: &self.profiles[j],
            w,
        };
        let exact = |s| elevation(self.shape.profile(DVec2::new(u, s)));
        invert(|k| blend.angle(k, elevation), exact, corrected)
    }

    /// (u, v) and t of scene point `p`, extended beyond the volume (v and t outside [0, 1]
    /// continue; u wraps into [0, 1], or with a window, [`PanoramaShape::windowed`],
    /// continues to within half a turn of the window's middle). `None` on the up axis
    /// through the eye, and where the coupled iteration of several outlines does not
    /// converge.
    pub fn solve(&self, p: DVec3) -> Option<(DVec2, f64)> {
        let local = self.basis.to_local(p - self.basis.origin);
        let horizontal = DVec2::new(local.x, local.z);
        let h = horizontal.length();
        if h == 0.0 || !h.is_finite() {
            return None;
        }
        let theta = azimuth(horizontal);
        // (u, v) from the column at row v and the row at that column.
        let step = |v: f64| {
            let s = self.fraction(theta, v);
            let u = self.shape.column(s);
            let rho = self.shape.outline_at(s, v).length();
            DVec2::new(u, self.row(local.y.atan2(h / rho), u))
        };
        let uv = if self.outlines.len() == 1 {
            step(0.0)
        } else {
            coupled(step)?
        };
        let reach = self.shape.local(uv).length();
        if reach == 0.0 {
            return None;
        }
        let d = local.length() / reach;
        Some((uv, (d - self.near) / (self.far - self.near)))
    }

    /// The chart under `reparam` (linear only: u wraps once across the image width, or
    /// once every 1 / (s1 - s0) widths for a window [s0, s1] of the outline): the seam
    /// period and the poles up and down the axis through the eye, with the clearance left
    /// by the highest and lowest pixel-centre rows.
    pub fn chart(&self, reparam: &Reparam, resolution: &Resolution) -> Option<InverseChart> {
        (*reparam == Reparam::Linear).then_some(())?;
        let (v_lo, v_hi) = reparam.v_range(resolution)?;
        let (rho_lo, rho_hi) = self.distance_bounds();
        // The elevation of row v over all u is atan2(P_y, rho P_x) for a blend P of the
        // profiles' points at v (within their angles, P_x >= 0) and rho within the bounds:
        // extreme at a profile's point and a bound.
        let elevations = |v: f64| {
            let all = self.shape.profiles().iter().flat_map(|a| {
                let p = a.curve.at(v);
                [p.y.atan2(rho_lo * p.x), p.y.atan2(rho_hi * p.x)]
            });
            all.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), e| {
                (lo.min(e), hi.max(e))
            })
        };
        let lowest = elevations(v_lo).0;
        let highest = elevations(v_hi).1;
        Some(InverseChart {
            clip: Vec::new(),
            period: Some(
                f64::from(resolution.width) / self.shape.window().map_or(1.0, |[a, b]| b - a),
            ),
            poles: axis_poles(self.basis.origin, self.basis.up, lowest, highest),
        })
    }

    /// Bounds on the distance |O| of every blended outline point from the eye: exact for
    /// one outline; for several, the farthest point of any outline (a blend is no farther)
    /// and the nearest point of the segments joining neighbouring outlines' samples, less
    /// twice the longest sample step (a point between samples is no nearer).
    fn distance_bounds(&self) -> (f64, f64) {
        let list = self.shape.outlines();
        let ranges = list.iter().map(|a| a.curve.distance_range());
        let hi = ranges.clone().map(|r| r.1).fold(0.0, f64::max);
        if list.len() == 1 {
            return (ranges.map(|r| r.0).fold(f64::INFINITY, f64::min), hi);
        }
        let step = self
            .outlines
            .iter()
            .flat_map(|s| s.points.windows(2).map(|w| (w[1] - w[0]).length()))
            .fold(0.0, f64::max);
        let nearest = self
            .outlines
            .windows(2)
            .flat_map(|pair| pair[0].points.iter().zip(&pair[1].points))
            .map(|(&a, &b)| segment_distance(a, b))
            .fold(f64::INFINITY, f64::min);
        ((nearest - 2.0 * step).max(0.0), hi)
    }
}

/// The distance of the segment from `a` to `b` from the origin.
fn segment_distance(a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let s = if d == DVec2::ZERO {
        0.0
    } else {
        (-a.dot(d) / d.length_squared()).clamp(0.0, 1.0)
    };
    (a + s * d).length()
}

/// Several outlines: the (u, v) whose v is a fixed point of `step` (v -> (u at row v, v at
/// column u)), by secant steps on the residual from the uncoupled guess (row 1/2). `None`
/// when the residual does not fall below [`COUPLED_TOLERANCE`] within [`COUPLED_STEPS`], or
/// an iterate leaves [-[`COUPLED_RANGE`], [`COUPLED_RANGE`]].
fn coupled(step: impl Fn(f64) -> DVec2) -> Option<DVec2> {
    let mut x0 = 0.5;
    let mut r0 = step(x0).y - x0;
    let mut x1 = x0 + r0;
    for _ in 0..COUPLED_STEPS {
        let uv = step(x1);
        let r1 = uv.y - x1;
        if r1.abs() <= COUPLED_TOLERANCE {
            return Some(uv);
        }
        // A secant step, or a plain fixed-point step where the residual did not change.
        let next = if r1 != r0 {
            x1 - r1 * (x1 - x0) / (r1 - r0)
        } else {
            uv.y
        };
        if next.is_nan() || next.abs() > COUPLED_RANGE {
            return None;
        }
        (x0, r0, x1) = (x1, r1, next);
    }
    None
}

/// Whether (1 - w)^2 a + 2 w (1 - w) b + w^2 c > 0 for every w in [0, 1].
fn positive_on_unit_interval(a: f64, b: f64, c: f64) -> bool {
    a > 0.0 && c > 0.0 && (b > 0.0 || b * b < a * c)
}

/// Whether the blend of two sampled curves with any weight in [0, 1] turns strictly in the
/// sense of `turn` (bilinear: the turn from a sample to the next) at every sample step.
fn blend_turns(first: &Samples, second: &Samples, turn: impl Fn(DVec2, DVec2) -> f64) -> bool {
    let (a, b) = (&first.points, &second.points);
    (0..TABLE_SAMPLES).all(|k| {
        let mixed = 0.5 * (turn(a[k], b[k + 1]) + turn(b[k], a[k + 1]));
        positive_on_unit_interval(turn(a[k], a[k + 1]), mixed, turn(b[k], b[k + 1]))
    })
}

/// Outline samples with azimuths unwrapped from near -pi (the seam behind the eye). Errors:
/// an outline or a blend of neighbours not star-shaped around the eye, neighbours 180
/// degrees or more apart.
fn outline_samples(list: &[Attached]) -> Result<Vec<Samples>> {
    let samples: Vec<Samples> = list
        .iter()
        .map(|a| Samples::new(&a.curve, azimuth, -PI))
        .collect();
    for (a, s) in list.iter().zip(&samples) {
        let turned = s.angles[TABLE_SAMPLES] - s.angles[0];
        if !(s.increasing() && (turned - TAU).abs() < 1e-9) {
            return Err(Error::new(format!(
                "the panorama's outline{} is not star-shaped around the eye (its azimuth does                  not grow strictly along it)",
                attached_at(list, a, "v")
            )));
        }
    }
    // Clockwise seen from above: the azimuth grows.
    let clockwise = |p: DVec2, q: DVec2| q.perp_dot(p);
    for (pair, curves) in samples.windows(2).zip(list.windows(2)) {
        let (a, b) = (&pair[0], &pair[1]);
        let rows = format!("at v = {} and {}", curves[0].at, curves[1].at);
        if let Some(k) = (0..=TABLE_SAMPLES).find(|&k| (a.angles[k] - b.angles[k]).abs() >= PI) {
            return Err(Error::new(format!(
                "the panorama's outlines {rows} point 180 degrees or more apart around the eye                  at u = {}: their blend would pass the eye",
                k as f64 / TABLE_SAMPLES as f64
            )));
        }
        if !blend_turns(a, b, clockwise) {
            return Err(Error::new(format!(
                "the blend of the panorama's outlines {rows} is not star-shaped around the eye                  (its azimuth turns back between those rows)"
            )));
        }
    }
    Ok(samples)
}

/// Profile samples with their elevations. Errors: a profile reaching behind the up axis or
/// whose elevation does not grow strictly, a blend of neighbours (across the seam too)
/// whose elevation does not.
fn profile_samples(list: &[Attached]) -> Result<Vec<Samples>> {
    let samples: Vec<Samples> = list
        .iter()
        .map(|a| Samples::new(&a.curve, elevation, 0.0))
        .collect();
    for (a, s) in list.iter().zip(&samples) {
        let at = attached_at(list, a, "u");
        if s.points.iter().any(|p| p.x < 0.0) {
            return Err(Error::new(format!(
                "the panorama's profile{at} reaches behind the up axis (the image folds)"
            )));
        }
        if !s.increasing() {
            return Err(Error::new(format!(
                "the panorama's profile{at} does not rise strictly as seen from the eye (its                  elevation must grow along it)"
            )));
        }
    }
    let counter_clockwise = |p: DVec2, q: DVec2| p.perp_dot(q);
    for i in 0..list.len() {
        let j = (i + 1) % list.len();
        if i != j && !blend_turns(&samples[i], &samples[j], counter_clockwise) {
            return Err(Error::new(format!(
                "the blend of the panorama's profiles at u = {} and {} does not rise strictly                  as seen from the eye between those columns",
                list[i].at, list[j].at
            )));
        }
    }
    Ok(samples)
}

/// " at v = X" (or u) for a curve of a list of several, "" for a single one.
fn attached_at(list: &[Attached], curve: &Attached, parameter: &str) -> String {
    if list.len() == 1 {
        String::new()
    } else {
        format!(" at {parameter} = {}", curve.at)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bernstein_positivity_is_exact() {
        // a = c = 1: positive iff b > -1.
        assert!(positive_on_unit_interval(1.0, -0.99, 1.0));
        assert!(!positive_on_unit_interval(1.0, -1.0, 1.0));
        assert!(positive_on_unit_interval(1.0, 5.0, 1e-9));
        // The ends themselves.
        assert!(!positive_on_unit_interval(0.0, 1.0, 1.0));
        assert!(!positive_on_unit_interval(1.0, 1.0, -1e-12));
        // a = 4, c = 1: the minimum (ac - b^2) / (a - 2b + c) is 0 at b = -2.
        assert!(positive_on_unit_interval(4.0, -1.999, 1.0));
        assert!(!positive_on_unit_interval(4.0, -2.0, 1.0));
    }

    #[test]
    fn coupled_iteration_converges_or_fails() {
        // A contraction with fixed point v = 0.3 (u follows v).
        let contraction = |v: f64| DVec2::new(2.0 * v, 0.3 + 0.8 * (v - 0.3));
        let uv = coupled(contraction).unwrap();
        assert!(
            (uv.y - 0.3).abs() < 1e-10 && (uv.x - 0.6).abs() < 1e-10,
            "{uv}"
        );
        // An expanding map still has its fixed point found by the secant steps.
        let expanding = |v: f64| DVec2::new(0.0, 0.3 + 3.0 * (v - 0.3));
        assert!((coupled(expanding).unwrap().y - 0.3).abs() < 1e-10);
        // No fixed point: refused.
        assert!(coupled(|v: f64| DVec2::new(0.0, v + 0.1 + 0.05 * v.sin())).is_none());
        assert!(coupled(|_| DVec2::new(0.0, f64::NAN)).is_none());
    }
}
