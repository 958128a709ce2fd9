//! Perfect specular reflection and refraction, and the Fresnel reflectance of a dielectric.
//!
//! All directions are unit vectors; `normal` faces the side the ray arrives from
//! (`direction . normal <= 0`).

use glam::DVec3;

/// The mirror image of `direction` about the plane with normal `normal`.
pub(crate) fn reflect(direction: DVec3, normal: DVec3) -> DVec3 {
    direction - 2.0 * direction.dot(normal) * normal
}

/// A refracted direction and the fraction of light reflected instead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Refraction {
    pub direction: DVec3,
    /// Unpolarised Fresnel reflectance, in [0, 1].
    pub reflectance: f64,
}

/// Refraction by Snell's law with relative index `eta` = (index of the side the ray comes
/// from) / (index of the side it enters), or `None` on total internal reflection
/// (`eta * sin(incidence) > 1`). At normal incidence the ray goes straight through; at
/// grazing incidence (`cos = 0`) the reflectance is 1.
pub(crate) fn refract(direction: DVec3, normal: DVec3, eta: f64) -> Option<Refraction> {
    let cos_i = (-direction.dot(normal)).clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let direction = (eta * direction + (eta * cos_i - cos_t) * normal).normalize();
    // Exact Fresnel equations for s and p polarisation, divided through by the entered index.
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let reflectance = if rs.is_finite() && rp.is_finite() {
        (0.5 * (rs * rs + rp * rp)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    Some(Refraction {
        direction,
        reflectance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflection_keeps_tangent_and_flips_normal_component() {
        let d = DVec3::new(1.0, -1.0, 0.0).normalize();
        let r = reflect(d, DVec3::Y);
        assert!((r - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15);
    }

    #[test]
    fn snell_law_and_normal_incidence() {
        let straight = refract(DVec3::NEG_Y, DVec3::Y, 1.0 / 1.5).unwrap();
        assert!((straight.direction - DVec3::NEG_Y).length() < 1e-15);
        assert!(
            (straight.reflectance - 0.04).abs() < 1e-12,
            "((1.5-1)/(1.5+1))^2"
        );
        let d = DVec3::new(1.0, -1.0, 0.0).normalize();
        let r = refract(d, DVec3::Y, 1.0 / 1.5).unwrap();
        let sin_t = r.direction.x;
        assert!((sin_t - (0.5f64).sqrt() / 1.5).abs() < 1e-12);
        assert!(r.direction.y < 0.0);
        assert!(r.reflectance > 0.04 && r.reflectance < 1.0);
    }

    #[test]
    fn total_internal_reflection_beyond_the_critical_angle() {
        // Leaving glass (eta = 1.5): critical angle asin(1/1.5) = 41.8 degrees.
        let steep = DVec3::new(0.5, -1.0, 0.0).normalize(); // 26.6 degrees
        assert!(refract(steep, DVec3::Y, 1.5).is_some());
        let shallow = DVec3::new(1.0, -0.5, 0.0).normalize(); // 63.4 degrees
        assert!(refract(shallow, DVec3::Y, 1.5).is_none());
    }

    #[test]
    fn grazing_incidence_reflects_everything() {
        let r = refract(DVec3::X, DVec3::Y, 1.0 / 1.5).unwrap();
        assert!((r.reflectance - 1.0).abs() < 1e-12);
    }
}
