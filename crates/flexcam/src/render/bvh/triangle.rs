//! Triangles precomputed for the f32 inner loop (Moller-Trumbore on a first vertex and two
//! edges), and the f32 form of a ray.

use glam::{DVec3, Vec3A};

use crate::geometry::Ray;

/// A triangle as the inner loop reads it: one vertex and the two edges from it.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct PackedTriangle {
    pub v0: Vec3A,
    pub e1: Vec3A,
    pub e2: Vec3A,
}

/// Smallest direction component magnitude used for the reciprocal direction. Replacing smaller
/// components (zero included) by it keeps `1 / d` finite, so slab tests never compute
/// `0 * inf = NaN`; the box test is then that of a direction tilted by less than 1e-30 radians.
const MIN_COMPONENT: f32 = 1e-30;

/// A ray in f32 with what every box and triangle test needs precomputed.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct FastRay {
    pub origin: Vec3A,
    pub direction: Vec3A,
    pub inv_direction: Vec3A,
    pub t_min: f32,
    pub t_max: f32,
}

impl FastRay {
    /// The f32 form of `ray`, or `None` when the ray cannot hit anything: non-finite origin or
    /// direction, a zero direction, or an empty interval. `t_min`/`t_max` are rounded to f32,
    /// so the interval is honoured to f32 precision.
    pub fn new(ray: &Ray) -> Option<FastRay> {
        let finite = ray.origin.is_finite() && ray.direction.is_finite();
        // False for an empty interval and for a NaN bound.
        let interval = ray.t_min <= ray.t_max;
        if !finite || ray.direction == DVec3::ZERO || !interval {
            return None;
        }
        let origin = Vec3A::from(ray.origin.as_vec3());
        let direction = Vec3A::from(ray.direction.as_vec3());
        let safe = |c: f32| {
            if c.abs() < MIN_COMPONENT {
                MIN_COMPONENT.copysign(c)
            } else {
                c
            }
        };
        let inv_direction = Vec3A::new(
            1.0 / safe(direction.x),
            1.0 / safe(direction.y),
            1.0 / safe(direction.z),
        );
        Some(FastRay {
            origin,
            direction,
            inv_direction,
            t_min: ray.t_min as f32,
            t_max: ray.t_max as f32,
        })
    }
}

/// A hit found by the f32 inner loop: ray parameter and barycentrics of vertices 1 and 2.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct FastHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

impl PackedTriangle {
    /// Precomputes the triangle `(a, b, c)`; `None` for a zero-area triangle (its edge cross
    /// product is exactly zero: it could only ever be hit edge-on, and is never stored).
    pub fn new(a: Vec3A, b: Vec3A, c: Vec3A) -> Option<PackedTriangle> {
        let (e1, e2) = (b - a, c - a);
        (e1.cross(e2) != Vec3A::ZERO).then_some(PackedTriangle { v0: a, e1, e2 })
    }

    /// Moller-Trumbore from either side, accepting `t` in `[ray.t_min, t_max]`. The
    /// barycentric tests are made on the undivided numerators against the determinant (signs
    /// folded so that it is positive), so the division is only paid where the line meets the
    /// triangle. A direction parallel to the plane gives a zero determinant, rejected
    /// outright; NaN anywhere fails the range tests (false for NaN).
    #[inline(always)]
    pub fn intersect(&self, ray: &FastRay, t_max: f32) -> Option<FastHit> {
        let p = ray.direction.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 {
            return None;
        }
        let sign = 1.0f32.copysign(det);
        let abs_det = det.abs();
        let s = ray.origin - self.v0;
        let u = s.dot(p) * sign;
        if !(0.0..=abs_det).contains(&u) {
            return None;
        }
        let q = s.cross(self.e1);
        let v = ray.direction.dot(q) * sign;
        if !(v >= 0.0 && u + v <= abs_det) {
            return None;
        }
        let inv_det = 1.0 / abs_det;
        let t = self.e2.dot(q) * sign * inv_det;
        // An infinite reciprocal (subnormal determinant) would give infinite or NaN values.
        (t >= ray.t_min && t <= t_max && inv_det < f32::INFINITY).then_some(FastHit {
            t,
            u: u * inv_det,
            v: v * inv_det,
        })
    }
}
