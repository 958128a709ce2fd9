//! The displacement part of the inverse of a polyline volume through similar rectangles in
//! parallel planes whose parameters are partly displaced by one sampled map m
//! (`Inverse::Displaced`): the depth-discontinuity occlusion camera (`presets::ddoc`), whose
//! Q_zf and far rectangles are evaluated at q - m(q).
//!
//! Each surface i is the rectangle a_i + lambda_i B x (the same in-plane frame B, scaled by
//! lambda_i >= 0) at x = q, or at x = q - m(q) where it is displaced (delta_i = 1). A point p
//! on the segment from surface a to surface b, at the segment's local t = s (from p's depth,
//! as for undisplaced layers), is then p = lerp(a_a, a_b, s) + ((1 - s) lambda_a + s lambda_b)
//! B w, where w, what the layered inverse of the undisplaced rectangles returns, is
//!
//!   w = q - h m(q),  h = ((1 - s) lambda_a delta_a + s lambda_b delta_b)
//!                        / ((1 - s) lambda_a + s lambda_b),
//!
//! with h in [0, 1]: 0 before the bend (the perspective's own q), 1 beyond it, and in the
//! DDOC's bend h = s z_f / z. The pixel q solves q = w + h m(q). While the map's slope L
//! ([`DdocMap::slope`]) is below 1 that is a contraction with factor k = h L, so q is unique
//! and depends continuously on p; it is found by Newton steps on the bilinear map, each kept
//! only when it shrinks the residual r(q) = q - h m(q) - w at least as much as the
//! fixed-point step q - r(q) would (by the factor k), else that step. The iteration stops
//! when |r| <= [`TOLERANCE`] (1 - k), which bounds the error |q - q*| <= |r| / (1 - k) by
//! [`TOLERANCE`] (image fractions).
//!
//! Degenerate cases: h = 0 (before the bend, a zero map) gives q = w, the layered inverse
//! exactly; a point where the cross-section is a point (the eye of a volume starting there)
//! has no image, as for undisplaced layers; a point beyond the map's image positions sees
//! the border samples (the map is extended by them), so its q lies outside [0, 1]^2 and the
//! bounded inverse drops it; a map of slope [`MAX_SLOPE`] or more is refused (the displaced
//! image may fold there, so a point can have several pixels).

use std::sync::Arc;

use glam::{DMat2, DVec2, DVec3};

use super::control_surface::Surface;
use super::presets::DdocMap;
use crate::error::{Error, Result};

/// The accuracy of the pixel in image fractions (u across the width, v up the height): far
/// below a pixel of any image the map may serve.
pub const TOLERANCE: f64 = 1e-12;

/// The largest map slope the inverse accepts: below 1 the displaced image cannot fold; 0.9
/// bounds the iteration (each step shrinks the residual by at least the slope).
pub const MAX_SLOPE: f64 = 0.9;

/// Steps after which the iteration has converged for any accepted map: the residual starts
/// at most |m| <= 2^(1/2) and shrinks by at least [`MAX_SLOPE`] a step, and
/// 0.9^300 2^(1/2) < 1e-13 = [`TOLERANCE`] (1 - [`MAX_SLOPE`]).
const MAX_STEPS: usize = 300;

/// Relative tolerance for "similar" cross-sections.
const SIMILAR: f64 = 1e-9;

/// The surfaces with every displaced rectangle replaced by the rectangle itself, which of
/// them were displaced, and their one map. Errors: none displaced, or by different maps.
pub(super) fn undisplaced(surfaces: &[Surface]) -> Result<(Vec<Surface>, Vec<bool>, Arc<DdocMap>)> {
    let mut map: Option<&Arc<DdocMap>> = None;
    let mut displaced = Vec::with_capacity(surfaces.len());
    let mut plain = Vec::with_capacity(surfaces.len());
    for s in surfaces {
        match s {
            Surface::Displaced(d) => {
                if map.is_some_and(|m| m != &d.map) {
                    return Err(Error::new(
                        "its control surfaces are displaced by different maps",
                    ));
                }
                map = Some(&d.map);
                displaced.push(true);
                plain.push(Surface::Rectangle {
                    corner: d.corner,
                    u_edge: d.u_edge,
                    v_edge: d.v_edge,
                });
            }
            other => {
                displaced.push(false);
                plain.push(other.clone());
            }
        }
    }
    let map = map.ok_or_else(|| Error::new("none of its control surfaces is displaced"))?;
    Ok((plain, displaced, map.clone()))
}

/// How a polyline volume's surfaces are displaced (see the module): per segment the weights
/// that give h, the map and its slope.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Displacement {
    /// Per segment, its two ends' (lambda, lambda delta): the cross-section's scale, and
    /// that scale where the surface is displaced (0 where not).
    weights: Vec<[(f64, f64); 2]>,
    map: Arc<DdocMap>,
    /// The map's slope, below [`MAX_SLOPE`].
    slope: f64,
}

impl Displacement {
    /// The displacement of the surfaces whose in-plane edges are `frames` (u edge, v edge,
    /// in order along the projectors), `displaced` where flagged, by `map`. Errors, each a
    /// reason the volume has no inverse: frames that are not one frame scaled by
    /// lambda >= 0 (to 1e-9), a map of slope [`MAX_SLOPE`] or more.
    pub fn new(frames: &[[DVec3; 2]], displaced: &[bool], map: Arc<DdocMap>) -> Result<Self> {
        let scales = similar_scales(frames).ok_or_else(|| {
            Error::new(
                "its control surfaces are not similar rectangles (one frame scaled), so the \
                 displacement does not separate from the depth",
            )
        })?;
        let (slope, (x, y)) = map.slope();
        if slope >= MAX_SLOPE {
            return Err(Error::new(format!(
                "its displacement map's slope reaches {slope:.3} (at map pixel ({x}, {y}) from \
                 the top left), so the displaced image may fold; the raster inverts maps of \
                 slope below {MAX_SLOPE}"
            )));
        }
        let weight = |i: usize| (scales[i], if displaced[i] { scales[i] } else { 0.0 });
        let weights = (1..frames.len())
            .map(|k| [weight(k - 1), weight(k)])
            .collect();
        Ok(Displacement {
            weights,
            map,
            slope,
        })
    }

    /// The pixel position q of a point on segment `k` at its local t `local` (continued
    /// beyond [0, 1] with the h of the nearest end) whose undisplaced position is `w`.
    /// `None` only if the iteration fails to converge (see [`undisplace`]).
    pub fn undo(&self, k: usize, local: f64, w: DVec2) -> Option<DVec2> {
        let [(la, da), (lb, db)] = self.weights[k];
        let s = local.clamp(0.0, 1.0);
        let scale = (1.0 - s) * la + s * lb;
        // On an end whose cross-section is a point (lambda = 0), the limit from inside.
        let h = if scale > 0.0 {
            ((1.0 - s) * da + s * db) / scale
        } else if s < 0.5 {
            db / lb
        } else {
            da / la
        };
        undisplace(&self.map, w, h, self.slope)
    }
}

/// Each frame's scale lambda_i against the largest, when every frame is that one scaled by
/// lambda_i >= 0 (to [`SIMILAR`]); `None` otherwise.
fn similar_scales(frames: &[[DVec3; 2]]) -> Option<Vec<f64>> {
    let size = |f: &[DVec3; 2]| f[0].length() + f[1].length();
    let [b, c] = *frames.iter().max_by(|a, b| size(a).total_cmp(&size(b)))?;
    let scale = b.length() + c.length();
    frames
        .iter()
        .map(|[fb, fc]| {
            let lambda = (fb.dot(b) + fc.dot(c)) / (b.length_squared() + c.length_squared());
            let off = (*fb - lambda * b).length() + (*fc - lambda * c).length();
            (lambda >= 0.0 && off <= SIMILAR * scale).then_some(lambda)
        })
        .collect()
}

/// The q with q - h m(q) = `w` to [`TOLERANCE`], for `h` in [0, 1] and a map of slope
/// `slope` < 1 (see the module); `None` if the iteration has not converged in
/// [`MAX_STEPS`] steps (it always has for a slope below [`MAX_SLOPE`]).
pub(super) fn undisplace(map: &DdocMap, w: DVec2, h: f64, slope: f64) -> Option<DVec2> {
    if h == 0.0 {
        return Some(w);
    }
    let k = h * slope;
    let at = |q: DVec2| {
        let (m, dm) = map.sample_with_slope(q);
        (q, q - h * m - w, dm)
    };
    let (mut q, mut r, mut dm) = at(w);
    for _ in 0..MAX_STEPS {
        if r.length() <= TOLERANCE * (1.0 - k) {
            return Some(q);
        }
        // I - h dm is invertible: |h dm| <= k < 1.
        let newton = at(q - (DMat2::IDENTITY - h * dm).inverse() * r);
        (q, r, dm) = if newton.1.length() <= k * r.length() {
            newton
        } else {
            at(q - r)
        };
    }
    None
}
