//! The local perspective edit of a shape-defined panorama (thesis 9.5): inside a chosen
//! rectangle [u0, u1] x [v0, v1] of the image the panorama becomes a perspective image.
//!
//! The image direction of (u, v) is that of Q_1(u, v) = (O_x P_x, P_y, O_y P_x), that is of
//! (O_x(u), P_y(v) / P_x(v), O_y(u)) when P_x > 0. It is a perspective (planar) image exactly
//! when this direction is an affine function of (u, v): the image is then a linear map of a
//! plane not through the eye, seen from the eye, so straight scene lines stay straight. The
//! edit makes it so:
//! - every outline over [u0, u1] becomes the chord from O(u0) to O(u1), parameterised
//!   linearly (O affine in u);
//! - every profile over [v0, v1] becomes the chord from P(v0) to P(v1), parameterised
//!   centrally ([`Piece::Central`]: the slope P_y / P_x linear in v). A vertical chord is
//!   then also linear; a slanted one is not, as its arc length would make the slope a
//!   Moebius function of v and bend the image's lines.
//!
//! Exact: with one outline and one profile (the presets and most custom panoramas) the
//! rectangle is an exact perspective image of the vertical plane through the outline's chord
//! (up to floating point). Approximate: with several outlines or profiles each is flattened
//! and the blend of their chords varies across the rectangle, so it is perspective only where
//! the blend weight is constant.
//!
//! Outside the rectangle: the fractions outside [u0, u1] of every outline and outside
//! [v0, v1] of every profile keep their points, so Q (and each ray) is unchanged wherever
//! u lies outside [u0, u1] and v outside [v0, v1]. The column band u in [u0, u1] changes over
//! the whole height (the outline there is the chord, which also changes its distance |O| and
//! so the elevation of every row), and the row band v in [v0, v1] changes over the whole
//! width (the elevations between the rectangle's top and bottom rows follow the chord). The
//! surface stays continuous across the rectangle's borders, since the chords join the curves
//! at their end points.
//!
//! Across the seam: u0 > u1 names the rectangle [u0, 1] + [0, u1] (the image's right and
//! left edges joined). The outlines' chords are parameterised over the unwrapped range
//! [u0, u1 + 1] and split at the seam ([`ArcCurve::replace`]), so the outline's start (the
//! seam column) moves onto the chord, off the ray straight behind the eye; the image stays
//! continuous across the seam as before.
//!
//! The presets that are shape-defined panoramas take the edit as those panoramas
//! ([`edit_source`]): `cubic` and `rounded_cubic`, and the `cylindrical` (circle and
//! vertical segment) and `equirectangular` (circle and arc) presets, whose rays the
//! panoramas repeat outside the edited bands (`PresetSpec::panorama`). The edited volume is
//! a panorama, so `--method raster` draws it through the panorama's lookup inverse instead
//! of the presets' own cylinder and sphere inverses.
//!
//! Less than a full turn: a cylindrical or equirectangular preset of `h_fov` < 360 is the
//! circle windowed to its azimuths ([`PanoramaShape::windowed`]): the image's u maps onto the
//! outline fractions [s0, s1], so the rectangle's columns [u0, u1] are the outline's
//! fractions s0 + u (s1 - s0), which the chord replaces; the window is kept. Degenerate
//! cases: a rectangle reaching the image's edge (u0 = 0 or u1 = 1) flattens the outline up
//! to the window's end, and the edge column moves onto the chord like any other; a tiny
//! `h_fov` gives a rectangle turning a tiny angle, whose chord is nearly the arc (the window
//! itself is refused below [`super::MIN_WINDOW`] of a turn).
//!
//! Errors: a non-finite rectangle, one outside [0, 1]^2, u0 = u1 (or u0 = 1, u1 = 0: no
//! width) or v0 >= v1; a rectangle across the seam (u0 > u1) of a windowed panorama, which
//! has image edges instead of a seam; an outline range turning through 180 degrees or more
//! around the eye (its chord would pass through or behind the eye); a profile end on or
//! behind the up axis (P_x <= 0: the chord would meet the axis through the eye).

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec2;

use super::super::VolumeSource;
use super::curve::{ArcCurve, Piece};
use super::{Attached, PanoramaShape, PanoramaSpec};
use crate::error::{Error, Result};

/// Samples per outline range when measuring how far it turns around the eye.
const TURN_SAMPLES: usize = 1024;

/// The shape made perspective inside `rect` = [u0, v0, u1, v1] (module doc; u0 > u1: across
/// the seam).
pub fn make_perspective(shape: &PanoramaShape, rect: [f64; 4]) -> Result<PanoramaShape> {
    let [u0, v0, u1, v1] = rect;
    if let (Some([s0, s1]), true) = (shape.window(), u0 > u1) {
        return Err(Error::new(format!(
            "a perspective rectangle across the seam (u0 > u1, got [{u0}, {v0}, {u1}, {v1}]) \
             needs a panorama of the whole outline; this one spans {:.1} degrees of it and \
             has image edges instead",
            (s1 - s0) * 360.0
        )));
    }
    let unit = |x: f64| (0.0..=1.0).contains(&x);
    let width = if u0 < u1 { u1 - u0 } else { 1.0 - u0 + u1 };
    let across = u0 != u1 && width > 0.0;
    if !(unit(u0) && unit(u1) && across && unit(v0) && unit(v1) && v0 < v1) {
        return Err(Error::new(format!(
            "perspective rectangle [u0, v0, u1, v1] needs u0, u1, v0, v1 in [0, 1], u0 != u1 \
             (u0 > u1: across the seam) and v0 < v1, got [{u0}, {v0}, {u1}, {v1}]"
        )));
    }
    let range = [shape.fraction(u0), shape.fraction(u1)];
    let outlines = flatten(shape.outlines(), |c| outline_chord(c, range))?;
    let profiles = flatten(shape.profiles(), |c| profile_chord(c, [v0, v1]))?;
    let edited = PanoramaShape::new(outlines, profiles, shape.blend())?;
    match shape.window() {
        Some(window) => edited.windowed(window),
        None => Ok(edited),
    }
}

/// `source` with the perspective edit over `rect`: the shape of a shape-defined panorama, or
/// of the panorama that a `cubic`, `rounded_cubic`, `cylindrical` or `equirectangular`
/// preset is (windowed for less than 360 degrees). Errors: any other volume, and those of
/// [`make_perspective`].
pub fn edit_source(source: &VolumeSource, rect: [f64; 4]) -> Result<VolumeSource> {
    let spec = match source {
        VolumeSource::Panorama(spec) => spec.clone(),
        VolumeSource::Preset(preset) => match preset.panorama() {
            Some(spec) => spec?,
            None => {
                return Err(Error::new(format!(
                    "a perspective rectangle needs a shape-defined panorama (outlines and \
                     profiles, or the cubic, rounded_cubic, cylindrical and equirectangular \
                     presets), not the {} preset",
                    preset.preset.name()
                )))
            }
        },
        _ => {
            return Err(Error::new(
                "a perspective rectangle needs a shape-defined panorama (outlines and \
                 profiles, or the cubic, rounded_cubic, cylindrical and equirectangular \
                 presets)",
            ))
        }
    };
    Ok(VolumeSource::Panorama(PanoramaSpec {
        shape: Arc::new(make_perspective(&spec.shape, rect)?),
        ..spec
    }))
}

/// Each attached curve with `edit` applied.
fn flatten(
    list: &[Attached],
    edit: impl Fn(&ArcCurve) -> Result<ArcCurve>,
) -> Result<Vec<Attached>> {
    list.iter()
        .map(|a| {
            Ok(Attached {
                at: a.at,
                curve: edit(&a.curve)?,
            })
        })
        .collect()
}

/// The outline with its fractions [u0, u1] (across the seam when u0 > u1) replaced by its
/// linearly parameterised chord.
fn outline_chord(curve: &ArcCurve, [u0, u1]: [f64; 2]) -> Result<ArcCurve> {
    let unwrapped = if u1 < u0 { u1 + 1.0 } else { u1 };
    let turn = turning(curve, [u0, unwrapped]);
    if turn.abs() >= PI * (1.0 - 1e-9) {
        return Err(Error::new(format!(
            "perspective rectangle: the outline over its fractions [{u0}, {u1}] turns {:.1} \
             degrees around the eye; a chord (a plane) needs less than 180",
            turn.abs().to_degrees()
        )));
    }
    let chord = Piece::Line {
        from: curve.at(u0),
        to: curve.at(u1),
    };
    curve.replace([u0, u1], chord)
}

/// The signed angle the curve turns around the origin between fractions `range` (a closed
/// curve wraps past 1), summed over [`TURN_SAMPLES`] steps (outlines never pass through the
/// eye).
fn turning(curve: &ArcCurve, [a, b]: [f64; 2]) -> f64 {
    let point = |k: usize| curve.at(a + (b - a) * k as f64 / TURN_SAMPLES as f64);
    (0..TURN_SAMPLES)
        .map(|k| {
            let (p, q) = (point(k), point(k + 1));
            p.perp_dot(q).atan2(p.dot(q))
        })
        .sum()
}

/// The profile with [v0, v1] replaced by its centrally parameterised chord.
fn profile_chord(curve: &ArcCurve, [v0, v1]: [f64; 2]) -> Result<ArcCurve> {
    let (from, to): (DVec2, DVec2) = (curve.at(v0), curve.at(v1));
    // Ends within 1e-9 (relative) of the axis count as on it: the slope there is unbounded.
    let ahead = |p: DVec2| p.x > 1e-9 * p.length();
    if !(ahead(from) && ahead(to)) {
        return Err(Error::new(format!(
            "perspective rectangle: the profile at v = {v0} or {v1} lies on or behind the up \
             axis through the eye (distance {} and {}); the chord must stay in front of it",
            from.x, to.x
        )));
    }
    curve.replace([v0, v1], Piece::Central { from, to })
}

#[cfg(test)]
mod tests;
