//! Q^-1: from a scene point p to (u, v, t) for the analytic class of the thesis (7.3): volumes
//! where t follows directly from p and each surface type has a closed-form inverse.
//!
//! - Parallel planes: both surfaces affine (rectangle, parallelogram bilinear quad, point,
//!   line) and perpendicular to one normal n, at different offsets: t from p.n, then (u, v)
//!   from the interpolated affine surface (a 2 x 2 solve).
//! - Nested spheres: sphere patches sharing centre, frame and angle ranges (or a point at the
//!   other's centre, a sphere of radius 0), different radii: t from |p - c|, (u, v) from the
//!   longitude and latitude.
//! - Coaxial cylinders: cylinder patches sharing the axis line, frame and angle range, with
//!   different radii: t from the distance to the axis, u from the angle, v from the height.
//!
//! - Shape-defined panoramas whose outlines and profiles (and their blends) are star-shaped
//!   around the eye: lookup tables of the curves' angles (module `panorama::lookup`).
//! - Polyline projectors through two or more affine surfaces in parallel planes at
//!   strictly monotonic offsets along the normal (the piecewise depth transitions, the
//!   orthographic-near / perspective-far volume): the depth p.n picks the segment, whose
//!   parallel-planes inverse gives (u, v) and its local t, mapped to the volume's t by the
//!   segment's knots. Neighbouring segments share their surface, so the inverse is
//!   continuous across it.
//! - An affine near surface and a warped rectangle (the long scene's far surface, u
//!   re-parameterised piecewise-linearly) in parallel planes: each piece of the warp is an
//!   affine far surface, so t follows from p.n as for parallel planes, then (u, v) from the
//!   2 x 2 solve of the piece whose u range holds the solution (the pieces meet
//!   continuously at the knots, so a point on a knot gets the same answer from both).
//! - Quadratic Bezier projectors through three affine surfaces in parallel planes, the
//!   middle one strictly between the others (the quadratic depth transitions): the depth
//!   p.n is a quadratic in t, the same for every projector, and the cross-section at that t
//!   an affine surface (module `quadratic_inverse`).
//! - Polyline projectors through similar rectangles in parallel planes whose parameters are
//!   partly displaced by a sampled map (the depth-discontinuity occlusion camera): the
//!   layered inverse, then the displacement undone by a safeguarded Newton iteration
//!   (module `displaced_inverse`).
//!
//! Anything else has no inverse ([`Inverse::classify`] gives `None`, or for a panorama the
//! reason).
//!
//! [`BoundInverse`] is the projection's inverse: the solver with the re-parameterisation and
//! image size that turn (u, v) into pixels.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::control_surface::{CylinderPatch, PolarFrame, SpherePatch, Surface, WarpedRectangle};
use super::displaced_inverse::{undisplaced, Displacement};
use super::panorama::lookup::{self, PanoramaInverse};
use super::quadratic_inverse::QuadraticPlanes;
use super::reparam::Reparam;
use super::section::{affine, in_section, Affine, SAME};
use crate::error::{Error, Result};
use crate::projection::image_coords::Resolution;
use crate::projection::{AnalyticInverse, Charted, ContinuousInverse, ImagePoint};

/// Tolerance on (u, v, t) at the domain boundary, so that edge points are not lost.
const EDGE: f64 = 1e-9;

/// The inverse of one invertible volume.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Inverse {
    Planes {
        near: Affine,
        far: Affine,
        normal: DVec3,
    },
    Spheres {
        near: SpherePatch,
        far: SpherePatch,
    },
    Cylinders {
        near: CylinderPatch,
        far: CylinderPatch,
    },
    /// Shape-defined panoramas by lookup tables (module `panorama::lookup`).
    Panorama(Box<PanoramaInverse>),
    /// Polyline projectors through affine surfaces in parallel planes: one parallel-planes
    /// inverse per segment, in order along the projectors.
    Layers {
        segments: Vec<Layer>,
        normal: DVec3,
    },
    /// An affine near surface and a warped far rectangle: one parallel-planes inverse per
    /// piece of the warp.
    Warped {
        near: Affine,
        pieces: Vec<WarpPiece>,
        normal: DVec3,
    },
    /// Polyline projectors through similar rectangles in parallel planes, some of them
    /// displaced by a sampled map (the depth-discontinuity occlusion camera): the layered
    /// inverse of the rectangles, then the displacement undone by a contraction.
    Displaced {
        segments: Vec<Layer>,
        normal: DVec3,
        displacement: Box<Displacement>,
    },
    /// Quadratic Bezier projectors through three affine surfaces in parallel planes in
    /// order along them (module `quadratic_inverse`).
    Quadratic(QuadraticPlanes),
}

/// One piece of a warped far rectangle: its u range and the affine surface it is there
/// (extended beyond the range).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct WarpPiece {
    pub u: [f64; 2],
    pub far: Affine,
}

/// One segment of a polyline volume between parallel planes: its surfaces and the volume's
/// t at each.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Layer {
    pub near: Affine,
    pub far: Affine,
    pub t: [f64; 2],
}

/// The pieces of `w`: between knots (u_a, x_a) and (u_b, x_b), x(u) = x_a + (u - u_a) s with
/// s = (x_b - x_a) / (u_b - u_a), so the surface is corner + x(u) along + v v_edge.
fn warp_pieces(w: &WarpedRectangle) -> Vec<WarpPiece> {
    w.knots
        .windows(2)
        .map(|k| {
            let slope = (k[1].y - k[0].y) / (k[1].x - k[0].x);
            WarpPiece {
                u: [k[0].x, k[1].x],
                far: Affine {
                    a: w.corner + (k[0].y - k[0].x * slope) * w.along,
                    b: slope * w.along,
                    c: w.v_edge,
                },
            }
        })
        .collect()
}

fn same(a: DVec3, b: DVec3, scale: f64) -> bool {
    (a - b).length() <= SAME * scale.max(1.0)
}

fn same_frame(a: &PolarFrame, b: &PolarFrame) -> bool {
    same(a.axis, b.axis, 1.0) && same(a.front, b.front, 1.0)
}

fn same_range(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).abs() <= SAME && (a[1] - b[1]).abs() <= SAME && (a[1] - a[0]).abs() > SAME
}

/// A point surface at a sphere's centre, as a sphere of radius 0 with that sphere's ranges.
fn as_sphere(s: &Surface, other: &Surface) -> Option<SpherePatch> {
    match (s, other) {
        (Surface::Sphere(p), _) => Some(*p),
        (Surface::Point(c), Surface::Sphere(o)) if same(*c, o.center, o.radius) => {
            Some(SpherePatch { radius: 0.0, ..*o })
        }
        _ => None,
    }
}

impl Inverse {
    /// The inverse of the volume between `near` and `far`, when it is in the analytic class
    /// (`None` outside it). Errors: a panorama outside the lookup's class, with the reason.
    pub fn classify(near: &Surface, far: &Surface) -> Result<Option<Inverse>> {
        if let (Surface::Panorama(n), Surface::Panorama(f)) = (near, far) {
            return PanoramaInverse::new(n, f).map(|p| Some(Inverse::Panorama(Box::new(p))));
        }
        if let Surface::Warped(w) = far {
            return Ok(Inverse::classify_warped(near, w));
        }
        Ok(Inverse::classify_analytic(near, far))
    }

    /// The inverse of the polyline volume through `surfaces` at `knots` when every pair of
    /// neighbours makes parallel planes of one normal (either sign) and the surfaces' offsets
    /// along it are strictly monotonic; `None` otherwise.
    pub fn classify_layers(surfaces: &[Surface], knots: &[f64]) -> Option<Inverse> {
        let mut normal: Option<DVec3> = None;
        let mut segments = Vec::with_capacity(surfaces.len().saturating_sub(1));
        for (pair, t) in surfaces.windows(2).zip(knots.windows(2)) {
            let Some(Inverse::Planes {
                near,
                far,
                normal: n,
            }) = Inverse::classify_analytic(&pair[0], &pair[1])
            else {
                return None;
            };
            let n = match normal {
                None => n,
                Some(m) if same(m, n, 1.0) || same(m, -n, 1.0) => m,
                Some(_) => return None,
            };
            normal = Some(n);
            segments.push(Layer {
                near,
                far,
                t: [t[0], t[1]],
            });
        }
        let normal = normal?;
        let gaps: Vec<f64> = segments
            .iter()
            .map(|l| (l.far.a - l.near.a).dot(normal))
            .collect();
        let monotonic = gaps.iter().all(|g| *g > 0.0) || gaps.iter().all(|g| *g < 0.0);
        monotonic.then_some(Inverse::Layers { segments, normal })
    }

    /// The inverse of the polyline volume through `surfaces` at `knots`, some of them
    /// displaced rectangles (module `displaced_inverse`). Errors, each a reason the volume
    /// has no inverse: surfaces that are not rectangles in parallel planes in order along
    /// the projectors, rectangles that are not similar (one frame scaled), displaced
    /// surfaces of different maps, a map of slope `MAX_SLOPE` or more.
    pub fn classify_displaced(surfaces: &[Surface], knots: &[f64]) -> Result<Inverse> {
        let (plain, displaced, map) = undisplaced(surfaces)?;
        let Some(Inverse::Layers { segments, normal }) = Inverse::classify_layers(&plain, knots)
        else {
            return Err(Error::new(
                "its displaced control surfaces are not flat, parallel and in order along the \
                 projectors",
            ));
        };
        let frames: Vec<[DVec3; 2]> = std::iter::once(&segments[0].near)
            .chain(segments.iter().map(|l| &l.far))
            .map(|a| [a.b, a.c])
            .collect();
        let displacement = Displacement::new(&frames, &displaced, map)?;
        Ok(Inverse::Displaced {
            segments,
            normal,
            displacement: Box::new(displacement),
        })
    }

    /// An affine `near` and the warped `far` when every piece of the warp makes parallel
    /// planes with `near`, all of one normal.
    fn classify_warped(near: &Surface, far: &WarpedRectangle) -> Option<Inverse> {
        let pieces = warp_pieces(far);
        let mut normal = None;
        for piece in &pieces {
            let f = piece.far;
            let rectangle = Surface::Rectangle {
                corner: f.a,
                u_edge: f.b,
                v_edge: f.c,
            };
            let Some(Inverse::Planes { normal: n, .. }) =
                Inverse::classify_analytic(near, &rectangle)
            else {
                return None;
            };
            if normal.is_some_and(|m: DVec3| !same(m, n, 1.0)) {
                return None;
            }
            normal = Some(n);
        }
        Some(Inverse::Warped {
            near: affine(near)?,
            pieces,
            normal: normal?,
        })
    }

    /// The closed-form cases: nested spheres, coaxial cylinders, parallel planes.
    fn classify_analytic(near: &Surface, far: &Surface) -> Option<Inverse> {
        if let (Some(n), Some(f)) = (as_sphere(near, far), as_sphere(far, near)) {
            let ok = same(n.center, f.center, n.radius.max(f.radius))
                && same_frame(&n.frame, &f.frame)
                && same_range(n.longitude, f.longitude)
                && same_range(n.latitude, f.latitude)
                && n.radius != f.radius;
            return ok.then_some(Inverse::Spheres { near: n, far: f });
        }
        if let (Surface::Cylinder(n), Surface::Cylinder(f)) = (near, far) {
            let offset = f.center - n.center;
            let across = offset - offset.dot(n.frame.axis) * n.frame.axis;
            let ok = same(across, DVec3::ZERO, offset.length())
                && same_frame(&n.frame, &f.frame)
                && same_range(n.angle, f.angle)
                && n.radius != f.radius;
            return ok.then_some(Inverse::Cylinders { near: *n, far: *f });
        }
        let (n, f) = (affine(near)?, affine(far)?);
        let normal = [n.b.cross(n.c), f.b.cross(f.c)]
            .into_iter()
            .find(|m| m.length() > SAME * (1.0 + m.length()))?
            .try_normalize()?;
        let flat = |s: &Affine| {
            let scale = s.b.length() + s.c.length();
            s.b.dot(normal).abs() <= SAME * scale && s.c.dot(normal).abs() <= SAME * scale
        };
        let gap = (f.a - n.a).dot(normal);
        let ok = flat(&n) && flat(&f) && gap.abs() > SAME * (f.a - n.a).length();
        ok.then_some(Inverse::Planes {
            near: n,
            far: f,
            normal,
        })
    }

    /// The (u, v) and t of scene point `p`, or `None` when p is outside the volume (t or
    /// (u, v) outside [0, 1], within a 1e-9 tolerance, then clamped) or on a degenerate
    /// spot (a point where the projectors meet, a polar axis outside the longitude range).
    pub fn solve(&self, p: DVec3) -> Option<(DVec2, f64)> {
        let (uv, t) = self.solve_unbounded(p)?;
        let edge = match self {
            Inverse::Panorama(_) => lookup::ACCURACY,
            _ => EDGE,
        };
        let inside = |x: f64| (-edge..=1.0 + edge).contains(&x);
        (inside(uv.x) && inside(uv.y) && inside(t))
            .then(|| (uv.clamp(DVec2::ZERO, DVec2::ONE), t.clamp(0.0, 1.0)))
    }

    /// (u, v) and t of `p` extended beyond the volume: the same formulas with no domain test
    /// (longitudes outside the range continue past its ends). `None` only on the degenerate
    /// spots of [`Inverse::solve`].
    pub fn solve_unbounded(&self, p: DVec3) -> Option<(DVec2, f64)> {
        match self {
            Inverse::Planes { near, far, normal } => planes(near, far, *normal, p),
            Inverse::Spheres { near, far } => spheres(near, far, p),
            Inverse::Cylinders { near, far } => cylinders(near, far, p),
            Inverse::Panorama(lookup) => lookup.solve(p),
            Inverse::Warped {
                near,
                pieces,
                normal,
            } => warped(near, pieces, *normal, p),
            Inverse::Layers { segments, normal } => layers(segments, *normal, p),
            Inverse::Quadratic(q) => q.solve(p),
            Inverse::Displaced {
                segments,
                normal,
                displacement,
            } => {
                let (k, w, local) = layer_solution(segments, *normal, p)?;
                let q = displacement.undo(k, local, w)?;
                let t = segments[k].t;
                Some((q, t[0] + local * (t[1] - t[0])))
            }
        }
    }
}

/// The parallel-planes solution of the first segment that reaches p's depth (the last one
/// beyond them all, the first one before them, so that the solution extends beyond the
/// volume), its local t mapped to the volume's.
fn layers(segments: &[Layer], n: DVec3, p: DVec3) -> Option<(DVec2, f64)> {
    let (k, uv, s) = layer_solution(segments, n, p)?;
    let t = segments[k].t;
    Some((uv, t[0] + s * (t[1] - t[0])))
}

/// The segment [`layers`] picks for `p`, its (u, v) and its local t (0 on the segment's near
/// surface, 1 on its far one).
fn layer_solution(segments: &[Layer], n: DVec3, p: DVec3) -> Option<(usize, DVec2, f64)> {
    let last = segments.len() - 1;
    let k = segments
        .iter()
        .position(|l| (p - l.near.a).dot(n) / (l.far.a - l.near.a).dot(n) <= 1.0 + EDGE)
        .unwrap_or(last);
    let layer = &segments[k];
    let (uv, s) = planes(&layer.near, &layer.far, n, p)?;
    Some((k, uv, s))
}

/// The parallel-planes solution of the piece whose u range holds it (the first piece open
/// below, the last above, so that the solution extends beyond the volume).
fn warped(near: &Affine, pieces: &[WarpPiece], n: DVec3, p: DVec3) -> Option<(DVec2, f64)> {
    let last = pieces.len() - 1;
    pieces.iter().enumerate().find_map(|(k, piece)| {
        let (uv, t) = planes(near, &piece.far, n, p)?;
        let above = k == 0 || uv.x >= piece.u[0] - EDGE;
        let below = k == last || uv.x <= piece.u[1] + EDGE;
        (above && below).then_some((uv, t))
    })
}

fn planes(near: &Affine, far: &Affine, n: DVec3, p: DVec3) -> Option<(DVec2, f64)> {
    let t = (p - near.a).dot(n) / (far.a - near.a).dot(n);
    let section = Affine {
        a: near.a.lerp(far.a, t),
        b: near.b.lerp(far.b, t),
        c: near.c.lerp(far.c, t),
    };
    Some((in_section(&section, p)?, t))
}

/// u for angle `angle` in the range `range` (radians, span at most 2 pi): of the angles
/// 2 pi apart, the one inside the range (or the first above its low end).
fn unwrap(range: [f64; 2], angle: f64) -> f64 {
    let (lo, hi) = (range[0].min(range[1]), range[0].max(range[1]));
    let turn = 2.0 * PI;
    let above = angle + turn * ((lo - angle) / turn).ceil();
    let a = [above - turn, above]
        .into_iter()
        .find(|a| (lo - EDGE..=hi + EDGE).contains(a))
        .unwrap_or(above);
    (a - range[0]) / (range[1] - range[0])
}

/// Longitude of a unit-frame direction, with a fallback on the polar axis where it is
/// undefined: any longitude of the range gives the same point, so take the range's middle.
fn longitude(frame: &PolarFrame, d: DVec3, range: [f64; 2]) -> (f64, f64) {
    let (x, y) = (d.dot(frame.front), d.dot(frame.east));
    if x == 0.0 && y == 0.0 {
        return (0.5, DVec2::new(x, y).length());
    }
    (unwrap(range, y.atan2(x)), DVec2::new(x, y).length())
}

fn spheres(near: &SpherePatch, far: &SpherePatch, p: DVec3) -> Option<(DVec2, f64)> {
    let q = p - near.center;
    let rho = q.length();
    if rho == 0.0 {
        return None;
    }
    let t = (rho - near.radius) / (far.radius - near.radius);
    let d = q / rho;
    let (u, horizontal) = longitude(&near.frame, d, near.longitude);
    let lat = d.dot(near.frame.axis).atan2(horizontal);
    let v = (lat - near.latitude[0]) / (near.latitude[1] - near.latitude[0]);
    Some((DVec2::new(u, v), t))
}

fn cylinders(near: &CylinderPatch, far: &CylinderPatch, p: DVec3) -> Option<(DVec2, f64)> {
    let axis = near.frame.axis;
    let q = p - near.center;
    let h = q.dot(axis);
    let across = q - h * axis;
    let rho = across.length();
    let t = (rho - near.radius) / (far.radius - near.radius);
    let u = if rho == 0.0 {
        0.5
    } else {
        longitude(&near.frame, across / rho, near.angle).0
    };
    // Height along the projector: (1 - t) h_near(v) + t h_far(v), far heights from near's
    // centre.
    let shift = (far.center - near.center).dot(axis);
    let far_height = [far.height[0] + shift, far.height[1] + shift];
    let start = (1.0 - t) * near.height[0] + t * far_height[0];
    let span = (1.0 - t) * (near.height[1] - near.height[0]) + t * (far_height[1] - far_height[0]);
    if span == 0.0 {
        return None;
    }
    let v = (h - start) / span;
    Some((DVec2::new(u, v), t))
}

/// The inverse of a flexible projection: an [`Inverse`] with the re-parameterisation and image
/// size that turn its (u, v) into pixels.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct BoundInverse {
    pub solver: Inverse,
    pub reparam: Reparam,
    pub resolution: Resolution,
}

impl AnalyticInverse for BoundInverse {
    /// Appends the one image of `point` when it lies inside the viewing volume (t and
    /// (u, v) in [0, 1]); points outside it, and degenerate spots where a whole set of
    /// projectors meets (the eye of a perspective volume), append nothing.
    fn project(&self, point: DVec3, out: &mut Vec<ImagePoint>) {
        let Some((uv, t)) = self.solver.solve(point) else {
            return;
        };
        if let Some(pixel) = self.reparam.to_pixel(&self.resolution, uv) {
            out.push(ImagePoint { pixel, t });
        }
    }

    /// The analytic class under the maps that keep the extended inverse continuous (see
    /// the `chart` module); `None` otherwise.
    fn charted(&self) -> Option<Charted<'_>> {
        let chart = self.solver.chart(&self.reparam, &self.resolution)?;
        Some(Charted { chart, map: self })
    }
}

impl ContinuousInverse for BoundInverse {
    /// (u, v, t) by the inverse's formulas without the domain test, then the pixel by the
    /// extended re-parameterisation.
    fn project_continuous(&self, point: DVec3) -> Option<ImagePoint> {
        let (uv, t) = self.solver.solve_unbounded(point)?;
        let pixel = self.reparam.to_pixel_unbounded(&self.resolution, uv)?;
        Some(ImagePoint { pixel, t })
    }
}
