//! The parametric viewing volume Q(u, v, t) with straight projectors.
//!
//! Two control surfaces give Q(u, v, t) = (1 - t) Q_near(u, v) + t Q_far(u, v), t in [0, 1]:
//! the projector of (u, v) is the segment from Q_near to Q_far, and t outside [0, 1] is clipped
//! (the framework's per-projector near and far clip). Volumes with curved projectors (polyline,
//! Bezier in t over more control surfaces) are the other [`Volume`] variants, in
//! [`super::blend`]; everything that only needs Q and dQ/dt works with all of them.

use glam::{DVec2, DVec3};

use super::control_surface::Surface;
use crate::error::{Error, Result};
use crate::geometry::Ray;

/// Samples per side of the grid on which [`Volume::check_projectors`] looks for a projector
/// of non-zero length.
const CHECK_SAMPLES: u32 = 17;

/// A volume with straight projectors between a near and a far control surface.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearVolume {
    /// Where the projectors start (t = 0).
    pub near: Surface,
    /// Where the projectors end (t = 1).
    pub far: Surface,
}

impl LinearVolume {
    /// Validates both surfaces. Errors: an invalid surface, or near and far surfaces that
    /// coincide on a 17 x 17 grid of (u, v) (every projector would have zero length: nothing
    /// can be seen). Where they coincide only at some (u, v), those projectors have no ray
    /// ([`LinearVolume::ray`] gives `None`) and the build succeeds.
    pub fn new(near: Surface, far: Surface) -> Result<Self> {
        near.validate()
            .map_err(|e| Error::new(format!("flexible near {}", e.message)))?;
        far.validate()
            .map_err(|e| Error::new(format!("flexible far {}", e.message)))?;
        let volume = LinearVolume { near, far };
        check_projectors(|uv, _| volume.tangent(uv))?;
        Ok(volume)
    }

    /// Q(u, v, t).
    pub fn point(&self, uv: DVec2, t: f64) -> DVec3 {
        let near = self.near.point(uv);
        near + t * (self.far.point(uv) - near)
    }

    /// dQ/dt at (u, v): Q_far - Q_near, the same for every t.
    pub fn tangent(&self, uv: DVec2) -> DVec3 {
        self.far.point(uv) - self.near.point(uv)
    }

    /// The projector of (u, v) as a ray: origin Q_near, direction Q_far - Q_near
    /// (unnormalised, so the ray parameter is t), t in [0, 1]. `None` for a zero-length
    /// projector (near and far surfaces meet at (u, v)).
    pub fn ray(&self, uv: DVec2) -> Option<Ray> {
        let origin = self.near.point(uv);
        let direction = self.far.point(uv) - origin;
        if direction == DVec3::ZERO || !direction.is_finite() {
            return None;
        }
        Some(Ray {
            origin,
            direction,
            t_min: 0.0,
            t_max: 1.0,
        })
    }
}

/// See [`Volume::check_projectors`]; `tangent` is dQ/dt at (u, v, t).
pub(super) fn check_projectors(tangent: impl Fn(DVec2, f64) -> DVec3) -> Result<()> {
    let n = f64::from(CHECK_SAMPLES - 1);
    let any_length = (0..CHECK_SAMPLES).any(|i| {
        (0..CHECK_SAMPLES).any(|j| {
            let uv = DVec2::new(f64::from(i) / n, f64::from(j) / n);
            tangent(uv, 0.0) != DVec3::ZERO || tangent(uv, 1.0) != DVec3::ZERO
        })
    });
    if any_length {
        Ok(())
    } else {
        Err(Error::new(
            "flexible near and far surfaces coincide: every projector has zero length",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f64, half: f64) -> Surface {
        Surface::rectangle_centred(DVec3::new(0.0, 0.0, z), DVec3::X * half, DVec3::Y * half)
    }

    #[test]
    fn point_and_tangent_interpolate_linearly() {
        let v = LinearVolume::new(square(1.0, 1.0), square(2.0, 2.0)).unwrap();
        let uv = DVec2::new(0.75, 0.25); // thesis (u, v) = (0.5, -0.5)
        assert_eq!(v.point(uv, 0.0), DVec3::new(0.5, -0.5, 1.0));
        assert_eq!(v.point(uv, 1.0), DVec3::new(1.0, -1.0, 2.0));
        assert_eq!(v.point(uv, 0.5), DVec3::new(0.75, -0.75, 1.5));
        assert_eq!(v.tangent(uv), DVec3::new(0.5, -0.5, 1.0));
        let ray = v.ray(uv).unwrap();
        assert_eq!((ray.t_min, ray.t_max), (0.0, 1.0));
        assert_eq!(ray.at(1.0), v.point(uv, 1.0));
    }

    #[test]
    fn a_projector_of_zero_length_has_no_ray() {
        // Two squares crossing at the centre: the projector of (1/2, 1/2) is a point.
        let far = Surface::rectangle_centred(DVec3::ZERO, DVec3::X, DVec3::Z);
        let near = Surface::rectangle_centred(DVec3::ZERO, DVec3::X, DVec3::Y);
        let v = LinearVolume::new(near, far).unwrap();
        assert_eq!(v.ray(DVec2::splat(0.5)), None);
        assert!(v.ray(DVec2::new(0.5, 0.75)).is_some());
    }

    #[test]
    fn coincident_surfaces_are_an_error() {
        let e = LinearVolume::new(square(1.0, 1.0), square(1.0, 1.0)).unwrap_err();
        assert!(e.message.contains("coincide"), "{e}");
        let p = Surface::Point(DVec3::ONE);
        assert!(LinearVolume::new(p.clone(), p.clone()).is_err());
        // A point near surface and a zero-size far rectangle at the same place: also empty.
        let r = Surface::rectangle_centred(DVec3::ONE, DVec3::ZERO, DVec3::ZERO);
        assert!(LinearVolume::new(p, r).is_err());
    }

    #[test]
    fn invalid_surfaces_are_named() {
        let bad = Surface::Point(DVec3::new(f64::NAN, 0.0, 0.0));
        let e = LinearVolume::new(square(1.0, 1.0), bad).unwrap_err();
        assert!(e.message.starts_with("flexible far point surface"), "{e}");
    }
}
