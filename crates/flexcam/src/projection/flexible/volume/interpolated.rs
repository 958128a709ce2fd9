//! [`InterpolatedVolume`]: a Q1 + (1 - a) Q2 of two volumes that do not blend into a simpler
//! one, evaluated by evaluating both and mixing the points (built by module `interpolate`).

use glam::{DVec2, DVec3};

use super::Volume;
use crate::geometry::Ray;
use crate::projection::Projector;

/// a Q1 + (1 - a) Q2, evaluated point by point.
#[derive(Debug, Clone, PartialEq)]
pub struct InterpolatedVolume {
    /// a: the share of `first`; outside [0, 1] the mix extrapolates.
    pub weight: f64,
    /// Q1.
    pub first: Volume,
    /// Q2.
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
    /// zero length. A volume that does not see (u, v) itself (a remapped fisheye outside its
    /// circle) takes part with its continuation; the caller decides whether the mix sees it
    /// ([`Volume::sees`]).
    pub fn ray(&self, uv: DVec2) -> Option<Ray> {
        let (a, b) = (
            self.first.ray_continued(uv)?,
            self.second.ray_continued(uv)?,
        );
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
        let (a, b) = (
            self.first.projector_continued(uv)?,
            self.second.projector_continued(uv)?,
        );
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
pub(in crate::projection::flexible) fn mix(a: f64, x: DVec3, y: DVec3) -> DVec3 {
    a * x + (1.0 - a) * y
}
