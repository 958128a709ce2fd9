//! The [`InverseChart`] of an invertible flexible volume: where its extended inverse
//! ([`Inverse::solve_unbounded`] followed by [`Reparam::to_pixel_unbounded`]) is continuous,
//! for rasterisation.
//!
//! - Parallel planes (linear re-parameterisation only): triangles are clipped to t in [0, 1]
//!   (pulled in by [`END_MARGIN`] at an end whose cross-section is a point or a line, where
//!   the image is at infinity). A volume whose cross-section degenerates strictly inside it
//!   (a crossed-slits volume with its slit between the near and far surfaces) has no chart:
//!   the image flips there.
//! - Polyline volumes between parallel planes: the first segment's near clip and the last
//!   one's far clip, when no cross-section degenerates or flips inside (stations included).
//! - Polyline volumes partly displaced by a sampled map (the DDOC): the chart of their
//!   undisplaced rectangles. The displacement moves no point across a clip plane (the
//!   displaced surfaces stay in their planes) and, its slope being below 1, undoing it is a
//!   continuous map of the image plane onto itself.
//! - Quadratic projectors through parallel planes: clipped to the planes of t = 0 and 1,
//!   when no cross-section degenerates or turns over inside (module `quadratic_inverse`).
//! - A warped far rectangle (the long scene): the parallel-planes chart of each piece of
//!   the warp, which must all be the same, with cross-sections of one orientation.
//! - Nested spheres: the image depends only on the direction from the centre; the poles
//!   +-axis are singular, the longitude wraps every 360 degrees (linear and Mercator maps).
//!   With the polar maps the longitude is the azimuth of the image, continuous when the
//!   patch spans 360 degrees and starts (v = 0) at a pole; that pole is the image centre and
//!   only the other one is singular.
//! - Coaxial cylinders (linear map only) whose near surface is a single point on the axis
//!   (the cylindrical preset): the image depends only on the direction from that point, with
//!   poles along +-axis. Other cylinder volumes have no chart (their axis is singular at a
//!   finite image row, which a chart cannot describe).
//! - Shape-defined panoramas (linear map only): like the cylinder, only the direction from
//!   the eye matters; see `panorama::lookup`.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use super::control_surface::{lerp_range, CylinderPatch, SpherePatch};
use super::inverse::{Inverse, Layer, WarpPiece};
use super::quadratic_inverse::QuadraticPlanes;
use super::reparam::Reparam;
use super::section::Affine;
use crate::geometry::{solve_cubic, solve_quadratic};
use crate::projection::chart::{axis_poles, HalfSpace, InverseChart};
use crate::projection::image_coords::Resolution;

/// The fraction of the volume's depth left out at an end where the cross-section
/// degenerates (a pinhole or a slit): the image of that end is at infinity.
pub const END_MARGIN: f64 = 1e-9;

/// Relative rounding allowed when a pole of a sphere volume maps to exactly +-90 degrees
/// of a Mercator or equal-area map.
const MAP_EDGE: f64 = 1e-9;

/// Relative size below which a cross-section counts as degenerate.
const FLAT: f64 = 1e-12;

impl Inverse {
    /// The chart of this volume under `reparam` on an image of `resolution`, or `None` when
    /// the extended inverse is not continuous in a way a chart describes (see the module).
    pub fn chart(&self, reparam: &Reparam, resolution: &Resolution) -> Option<InverseChart> {
        match self {
            Inverse::Planes { near, far, normal } => {
                planar_map(reparam).then_some(())?;
                planes_chart(near, far, *normal)
            }
            Inverse::Spheres { near, .. } => spheres_chart(near, reparam, resolution),
            Inverse::Cylinders { near, far } => {
                (*reparam == Reparam::Linear).then_some(())?;
                cylinders_chart(near, far, resolution)
            }
            Inverse::Panorama(lookup) => lookup.chart(reparam, resolution),
            Inverse::Layers { segments, normal } => {
                planar_map(reparam).then_some(())?;
                layers_chart(segments, *normal)
            }
            Inverse::Warped {
                near,
                pieces,
                normal,
            } => {
                planar_map(reparam).then_some(())?;
                warped_chart(near, pieces, *normal)
            }
            Inverse::Displaced {
                segments, normal, ..
            } => {
                planar_map(reparam).then_some(())?;
                layers_chart(segments, *normal)
            }
            Inverse::Quadratic(q) => {
                planar_map(reparam).then_some(())?;
                quadratic_chart(q)
            }
        }
    }
}

/// Whether `reparam` keeps the extended inverse of a volume between planes continuous: the
/// linear map, and the magnifier (the identity outside its circle), the equiangular map
/// (monotonic in x and in y) and a grid map (one-to-one, continued beyond the image by its
/// border cells), homeomorphisms of the image plane onto their images.
fn planar_map(reparam: &Reparam) -> bool {
    matches!(
        reparam,
        Reparam::Linear | Reparam::Magnifier(_) | Reparam::Equiangular { .. } | Reparam::Grid(_)
    )
}

/// The chart of a polyline volume between parallel planes: every segment's
/// parallel-planes chart must exist (no cross-section degenerates inside a segment), every
/// inner surface's cross-section must have area, and all of one orientation (the image does
/// not flip at a station); triangles are clipped to the first segment's near end and the last
/// one's far end.
fn layers_chart(segments: &[Layer], n: DVec3) -> Option<InverseChart> {
    let charts = segments
        .iter()
        .map(|l| planes_chart(&l.near, &l.far, n))
        .collect::<Option<Vec<_>>>()?;
    let area = |s: &Affine| s.b.cross(s.c).dot(n);
    let inner: Vec<f64> = segments[1..].iter().map(|l| area(&l.near)).collect();
    let scale = segments
        .iter()
        .flat_map(|l| [area(&l.near).abs(), area(&l.far).abs()])
        .fold(0.0, f64::max);
    let ends = [
        area(&segments[0].near),
        area(&segments[segments.len() - 1].far),
    ];
    let positive = inner.first().map_or(ends[0] + ends[1] > 0.0, |a| *a > 0.0);
    let oriented = |a: f64| if positive { a > 0.0 } else { a < 0.0 };
    let ok = inner.iter().all(|a| a.abs() > FLAT * scale && oriented(*a))
        && ends.iter().all(|a| a.abs() <= FLAT * scale || oriented(*a));
    ok.then_some(())?;
    let lower = charts.first()?.clip.first()?.to_owned();
    let upper = charts.last()?.clip.last()?.to_owned();
    Some(InverseChart {
        clip: vec![lower, upper],
        ..InverseChart::default()
    })
}

/// The chart of a warped volume: every piece's parallel-planes chart, all the same (t
/// depends on p . n alone, so their clip planes are), and every piece's cross-section of one
/// orientation, so that the pieces join into one continuous, unfolded image.
fn warped_chart(near: &Affine, pieces: &[WarpPiece], n: DVec3) -> Option<InverseChart> {
    let charts = pieces
        .iter()
        .map(|piece| planes_chart(near, &piece.far, n))
        .collect::<Option<Vec<_>>>()?;
    let orientation = |far: &Affine| {
        let (b, c) = (near.b.lerp(far.b, 0.5), near.c.lerp(far.c, 0.5));
        b.cross(c).dot(n) > 0.0
    };
    let first = orientation(&pieces.first()?.far);
    let same = charts.windows(2).all(|w| w[0] == w[1])
        && pieces.iter().all(|p| orientation(&p.far) == first);
    if same {
        charts.into_iter().next()
    } else {
        None
    }
}

/// The chart of quadratic projectors through parallel planes: triangles clipped to the
/// planes of t = 0 and t = 1 (pulled in by [`END_MARGIN`] at an end whose cross-section is a
/// point or a segment, imaged at infinity). `None` where the cross-section degenerates or turns over strictly inside
/// the volume: its signed area (b(t) x c(t)) . n, a quartic in t, must keep one sign
/// between the ends, which is checked at its critical points (the roots of its
/// derivative, a cubic) and at the ends.
fn quadratic_chart(q: &QuadraticPlanes) -> Option<InverseChart> {
    let n = q.normal;
    let [s0, s1, s2] = &q.surfaces;
    // b(t) = b0 + t beta1 + t^2 beta2, likewise c(t).
    let b = [s0.b, 2.0 * (s1.b - s0.b), s0.b - 2.0 * s1.b + s2.b];
    let c = [s0.c, 2.0 * (s1.c - s0.c), s0.c - 2.0 * s1.c + s2.c];
    let mut e = [0.0; 5];
    for (i, bi) in b.iter().enumerate() {
        for (j, cj) in c.iter().enumerate() {
            e[i + j] += bi.cross(*cj).dot(n);
        }
    }
    let area = |t: f64| e.iter().rev().fold(0.0, |sum, k| sum * t + k);
    let critical: Vec<f64> = solve_cubic(4.0 * e[4], 3.0 * e[3], 2.0 * e[2], e[1])
        .iter()
        .collect();
    let scale = [0.0, 0.5, 1.0]
        .iter()
        .chain(critical.iter().filter(|t| (0.0..=1.0).contains(*t)))
        .map(|t| area(*t).abs())
        .fold(0.0, f64::max);
    let flat = |t: f64| area(t).abs() <= FLAT * scale;
    let lo = if flat(0.0) { END_MARGIN } else { 0.0 };
    let hi = if flat(1.0) { 1.0 - END_MARGIN } else { 1.0 };
    let mut inner = critical
        .into_iter()
        .filter(|t| lo < *t && *t < hi)
        .chain([0.0, 1.0].into_iter().filter(|t| !flat(*t)));
    let first = area(inner.next()?);
    let kept = inner.all(|t| !flat(t) && (area(t) > 0.0) == (first > 0.0));
    (kept && first.abs() > FLAT * scale).then_some(())?;
    // Inside: depth(lo) <= p . n <= depth(hi) along the direction the depth rises.
    let up = (q.offsets[2] - q.offsets[0]).signum() * n;
    let side = |t: f64| (q.offsets[2] - q.offsets[0]).signum() * q.depth(t);
    Some(InverseChart {
        clip: vec![
            HalfSpace {
                normal: up,
                offset: side(lo),
            },
            HalfSpace {
                normal: -up,
                offset: -side(hi),
            },
        ],
        ..InverseChart::default()
    })
}

fn planes_chart(near: &Affine, far: &Affine, n: DVec3) -> Option<InverseChart> {
    // The signed cross-section area (b(t) x c(t)) . n is a quadratic in t.
    let (db, dc) = (far.b - near.b, far.c - near.c);
    let f0 = near.b.cross(near.c).dot(n);
    let f1 = (near.b.cross(dc) + db.cross(near.c)).dot(n);
    let f2 = db.cross(dc).dot(n);
    let area = |t: f64| f0 + t * (f1 + t * f2);
    let scale = [0.0, 0.5, 1.0]
        .map(|t| area(t).abs())
        .into_iter()
        .fold(0.0, f64::max);
    let flat = |t: f64| area(t).abs() <= FLAT * scale;
    let lo = if flat(0.0) { END_MARGIN } else { 0.0 };
    let hi = if flat(1.0) { 1.0 - END_MARGIN } else { 1.0 };
    let roots = solve_quadratic(f2, f1, f0);
    if roots.is_identically_zero() || roots.into_iter().any(|t| lo < t && t < hi) {
        return None;
    }
    // t(p) = s . (p - near.a).
    let s = n / (far.a - near.a).dot(n);
    let base = s.dot(near.a);
    Some(InverseChart {
        clip: vec![
            HalfSpace {
                normal: s,
                offset: lo + base,
            },
            HalfSpace {
                normal: -s,
                offset: -hi - base,
            },
        ],
        ..InverseChart::default()
    })
}

/// The horizontal period in pixels of a map linear in u, for an angle range `range`.
fn period(range: [f64; 2], resolution: &Resolution) -> f64 {
    f64::from(resolution.width) * 2.0 * PI / (range[1] - range[0]).abs()
}

fn spheres_chart(
    near: &SpherePatch,
    reparam: &Reparam,
    resolution: &Resolution,
) -> Option<InverseChart> {
    let (v_lo, v_hi) = reparam.v_range(resolution)?;
    let (a, b) = (
        lerp_range(near.latitude, v_lo),
        lerp_range(near.latitude, v_hi),
    );
    let mut poles = axis_poles(near.center, near.frame.axis, a.min(b), a.max(b));
    let period = match reparam {
        Reparam::Linear => Some(period(near.longitude, resolution)),
        Reparam::Mercator { max_latitude } | Reparam::EqualArea { max_latitude } => {
            // Every latitude strictly between the poles must stay on the finite (Mercator)
            // and monotonic (equal area: sin) part of the map, i.e. the poles may map at
            // most to +-90 degrees: the poles themselves are singular anyway (their pieces
            // are dropped), so the natural case, the map's own latitudes those of the
            // patch (Mercator at `max_latitude` = `v_fov` / 2, equal area over the full
            // sphere), is accepted (within rounding, `MAP_EDGE`).
            let finite = [-FRAC_PI_2, FRAC_PI_2].into_iter().all(|lat| {
                let v = (lat - near.latitude[0]) / (near.latitude[1] - near.latitude[0]);
                ((2.0 * v - 1.0) * max_latitude).abs() <= FRAC_PI_2 * (1.0 + MAP_EDGE)
            });
            finite.then_some(())?;
            Some(period(near.longitude, resolution))
        }
        Reparam::Magnifier(_) | Reparam::Equiangular { .. } | Reparam::Grid(_) => return None,
        Reparam::Polar | Reparam::Lens | Reparam::Equisolid { .. } => {
            let full = ((near.longitude[1] - near.longitude[0]).abs() - 2.0 * PI).abs() <= FLAT;
            let start = near.latitude[0];
            let at_pole = (start.abs() - FRAC_PI_2).abs() <= FLAT;
            (full && at_pole).then_some(())?;
            // The pole at v = 0 is the image centre: not singular.
            poles.remove(if start > 0.0 { 0 } else { 1 });
            None
        }
    };
    Some(InverseChart {
        clip: Vec::new(),
        period,
        poles,
    })
}

fn cylinders_chart(
    near: &CylinderPatch,
    far: &CylinderPatch,
    resolution: &Resolution,
) -> Option<InverseChart> {
    let point = near.radius == 0.0 && near.height[0] == near.height[1];
    point.then_some(())?;
    let axis = near.frame.axis;
    let eye = near.center + near.height[0] * axis;
    // The elevation from the eye of v: tan = (far height(v) - eye height) / far radius.
    let shift = (far.center - near.center).dot(axis) - near.height[0];
    let elevation = |v: f64| ((lerp_range(far.height, v) + shift) / far.radius).atan();
    let (v_lo, v_hi) = Reparam::Linear.v_range(resolution)?;
    let (a, b) = (elevation(v_lo), elevation(v_hi));
    Some(InverseChart {
        clip: Vec::new(),
        period: Some(period(near.angle, resolution)),
        poles: axis_poles(eye, axis, a.min(b), a.max(b)),
    })
}
