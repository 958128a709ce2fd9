//! Interpolation and extrapolation between two viewing volumes (thesis 6.3, eq. 6.1):
//! Q(u, v, t) = a Q1(u, v, t) + (1 - a) Q2(u, v, t) on the shared (u, v) domain, for any real
//! a (a in [0, 1] interpolates, outside it extrapolates).
//!
//! Where the blend is again a volume of the same simple kind it is built as such, so that it
//! keeps an analytic inverse: straight projectors between surfaces of matching type blend
//! surface by surface (rectangles to a rectangle, points to a point, other affine or bilinear
//! pairs to a bilinear patch through the blended corners; spheres and cylinders sharing centre
//! axis, frame and angle ranges to one with the blended radius). Every other pair becomes a
//! [`InterpolatedVolume`] that evaluates both volumes and mixes the points.

use glam::{DVec2, DVec3};

use super::surface::{lerp_range, CylinderPatch, SpherePatch, Surface};
use super::volume::{LinearVolume, Volume};
use crate::error::{Error, Result};
use crate::geometry::Ray;
use crate::projection::Projector;

/// a Q1 + (1 - a) Q2, evaluated point by point.
#[derive(Debug, Clone, PartialEq)]
pub struct InterpolatedVolume {
    pub weight: f64,
    pub first: Volume,
    pub second: Volume,
}

impl InterpolatedVolume {
    /// a Q1(u, v, t) + (1 - a) Q2(u, v, t).
    pub fn point(&self, uv: DVec2, t: f64) -> DVec3 {
        mix(
            self.weight,
            self.first.point(uv, t),
            self.second.point(uv, t),
        )
    }

    /// a dQ1/dt + (1 - a) dQ2/dt.
    pub fn tangent(&self, uv: DVec2, t: f64) -> DVec3 {
        mix(
            self.weight,
            self.first.tangent(uv, t),
            self.second.tangent(uv, t),
        )
    }

    /// When both projectors of (u, v) are straight, so is the blend: origin and direction
    /// mix the same way (t in [0, 1] for both). `None` when either has no ray or the blend has
    /// zero length.
    pub fn ray(&self, uv: DVec2) -> Option<Ray> {
        let (a, b) = (self.first.ray(uv)?, self.second.ray(uv)?);
        let direction = mix(self.weight, a.direction, b.direction);
        if direction == DVec3::ZERO || !direction.is_finite() {
            return None;
        }
        Some(Ray {
            origin: mix(self.weight, a.origin, b.origin),
            direction,
            t_min: 0.0,
            t_max: 1.0,
        })
    }
}

impl InterpolatedVolume {
    /// The projector of (u, v): straight when both are; a quadratic Bezier when each is
    /// straight or quadratic (a straight projector is the quadratic with its middle control
    /// point halfway, so the mix of control points is exact); otherwise a polyline through
    /// [`MIXED_SEGMENTS`] + 1 mixed points at equal steps of t (exact where both volumes'
    /// knots fall on those steps, an approximation elsewhere). `None` where either volume has
    /// no projector.
    pub fn projector(&self, uv: DVec2) -> Option<Projector> {
        let (a, b) = (self.first.projector(uv)?, self.second.projector(uv)?);
        if let (Projector::Straight(_), Projector::Straight(_)) = (&a, &b) {
            return self.ray(uv).map(Projector::Straight);
        }
        if let (Some(qa), Some(qb)) = (as_quadratic(&a), as_quadratic(&b)) {
            return Some(Projector::QuadraticBezier(
                [0, 1, 2].map(|i| mix(self.weight, qa[i], qb[i])),
            ));
        }
        Some(Projector::Polyline(
            (0..=MIXED_SEGMENTS)
                .map(|k| self.point(uv, f64::from(k) / f64::from(MIXED_SEGMENTS)))
                .collect(),
        ))
    }
}

/// Steps in t of the polyline that stands for a mix of projectors of different kinds.
pub const MIXED_SEGMENTS: u32 = 32;

/// A straight projector over t in [0, 1] or a quadratic one as quadratic control points.
fn as_quadratic(p: &Projector) -> Option<[DVec3; 3]> {
    match p {
        Projector::Straight(r) => {
            let (start, end) = (r.at(0.0), r.at(1.0));
            Some([start, start.lerp(end, 0.5), end])
        }
        Projector::QuadraticBezier(q) => Some(*q),
        Projector::Polyline(_) => None,
    }
}

/// a x + (1 - a) y.
fn mix(a: f64, x: DVec3, y: DVec3) -> DVec3 {
    a * x + (1.0 - a) * y
}

/// The volume a Q1 + (1 - a) Q2. Weights 1 and 0 give `first` and `second` themselves
/// (exactly, with no rounding). Errors: a non-finite weight; a blend whose projectors all
/// have zero length (for example a = 1/2 between a volume and its mirror image through the
/// near surface).
pub fn interpolate(weight: f64, first: Volume, second: Volume) -> Result<Volume> {
    if !weight.is_finite() {
        return Err(Error::new(format!(
            "flexible interpolation weight must be finite, got {weight}"
        )));
    }
    if weight == 1.0 {
        return Ok(first);
    }
    if weight == 0.0 {
        return Ok(second);
    }
    if let (Volume::Linear(a), Volume::Linear(b)) = (&first, &second) {
        let surfaces = (
            blend_surface(weight, &a.near, &b.near),
            blend_surface(weight, &a.far, &b.far),
        );
        if let (Some(near), Some(far)) = surfaces {
            return LinearVolume::new(near, far)
                .map(|v| Volume::Linear(Box::new(v)))
                .map_err(|e| Error::new(format!("flexible interpolation: {}", e.message)));
        }
    }
    let volume = Volume::Interpolated(Box::new(InterpolatedVolume {
        weight,
        first,
        second,
    }));
    volume
        .check_projectors()
        .map_err(|e| Error::new(format!("flexible interpolation: {}", e.message)))?;
    Ok(volume)
}

/// The corners (u, v) = (0, 0), (1, 0), (1, 1), (0, 1) of a surface that is bilinear in
/// (u, v) (rectangles, bilinear patches, points, lines), `None` for curved surfaces.
fn bilinear_corners(s: &Surface) -> Option<[DVec3; 4]> {
    match s {
        Surface::Rectangle { .. } | Surface::Point(_) | Surface::Line { .. } => {
            Some([DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y].map(|uv| s.point(uv)))
        }
        Surface::Bilinear { corners } => Some(*corners),
        _ => None,
    }
}

/// a S1 + (1 - a) S2 as one surface, when the pair allows it exactly; `None` otherwise
/// (including sphere or cylinder blends whose radius would be negative).
fn blend_surface(a: f64, s1: &Surface, s2: &Surface) -> Option<Surface> {
    let blended = match (s1, s2) {
        (Surface::Point(p), Surface::Point(q)) => Surface::Point(mix(a, *p, *q)),
        (
            Surface::Rectangle {
                corner,
                u_edge,
                v_edge,
            },
            Surface::Rectangle {
                corner: c2,
                u_edge: u2,
                v_edge: v2,
            },
        ) => Surface::Rectangle {
            corner: mix(a, *corner, *c2),
            u_edge: mix(a, *u_edge, *u2),
            v_edge: mix(a, *v_edge, *v2),
        },
        (Surface::Sphere(p), Surface::Sphere(q))
            if p.center == q.center
                && p.frame == q.frame
                && p.longitude == q.longitude
                && p.latitude == q.latitude =>
        {
            Surface::Sphere(SpherePatch {
                radius: a * p.radius + (1.0 - a) * q.radius,
                ..*p
            })
        }
        (Surface::Cylinder(p), Surface::Cylinder(q))
            if p.frame == q.frame && p.angle == q.angle =>
        {
            let height = |s: f64| a * lerp_range(p.height, s) + (1.0 - a) * lerp_range(q.height, s);
            Surface::Cylinder(CylinderPatch {
                center: mix(a, p.center, q.center),
                radius: a * p.radius + (1.0 - a) * q.radius,
                height: [height(0.0), height(1.0)],
                ..*p
            })
        }
        _ => {
            let (c1, c2) = (bilinear_corners(s1)?, bilinear_corners(s2)?);
            Surface::Bilinear {
                corners: [0, 1, 2, 3].map(|k| mix(a, c1[k], c2[k])),
            }
        }
    };
    blended.validate().is_ok().then_some(blended)
}
