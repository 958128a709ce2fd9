//! A ray (a straight projector) with its valid parameter interval.

use glam::DVec3;

/// The points `origin + t * direction` for `t` in `[t_min, t_max]`.
///
/// `direction` is not necessarily unit length: projections whose depth is a ray parameter
/// (trilinear, flexible volumes) keep it unnormalised so that `t` means their depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// The point at t = 0.
    pub origin: DVec3,
    /// The step per unit of t (not necessarily unit length).
    pub direction: DVec3,
    /// The smallest parameter the ray covers (hits before it are ignored).
    pub t_min: f64,
    /// The largest parameter the ray covers (may be infinite).
    pub t_max: f64,
}

impl Ray {
    /// A ray over `t` in `[0, +inf)`.
    pub fn new(origin: DVec3, direction: DVec3) -> Self {
        Ray {
            origin,
            direction,
            t_min: 0.0,
            t_max: f64::INFINITY,
        }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.direction
    }
}
