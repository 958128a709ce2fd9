//! Perfect specular reflection and refraction, and the Fresnel reflectance of a dielectric.
//!
//! All directions are unit vectors; `normal` faces the side the ray arrives from
//! (`direction . normal <= 0`).

use glam::DVec3;

/// The mirror image of `direction` about the plane with normal `normal`.
pub(crate) fn reflect(direction: DVec3, normal: DVec3) -> DVec3 {
    direction - 2.0 * direction.dot(normal) * normal
}

/// The mirror image of `direction` about the shading normal `shading`, kept on the side of
/// the surface the ray arrives from: `geometric` is the unit face normal facing the incoming
/// ray (`direction . geometric <= 0`).
///
/// Interpolated vertex normals tilt away from a face near a coarse mesh's silhouette, and
/// the mirror image about them can point *into* the surface; a ray tracer that follows it
/// hits the inside of the object and shows whatever bounces around in there (on a mirror
/// sphere of a few rings, floor in the sky's place along its rim). A smooth surface never
/// reflects into itself, so such a direction is lifted, as Cycles' `ensure_valid_reflection`
/// does, to leave the face at a small elevation: wherever the mirror image `r` has `r . g <
/// h`, its direction along the face is kept and its component along `g` set to `h`
/// (`sqrt(1 - h^2) t + h g`, `t` the unit tangential part of `r`), with `h = min(0.9 cos_i,
/// REFLECTION_LIFT)` (`cos_i = -direction . g`: never steeper than the incoming ray leaves).
/// Directions at that elevation or above are returned as `reflect` gives them (the same
/// bits), and the lift is continuous at `r . g = h`.
///
/// Degenerate cases: a mirror image along `-g` (no direction along the face to keep) gives
/// the face's own mirror image `reflect(direction, geometric)`, and as the mirror image
/// passes through `-g` the lifted direction along the face turns over (the one
/// discontinuity); a `geometric` that faces
/// away from the ray counts as `cos_i = 0` (`h = 0`: lifted into the face's plane).
pub fn reflect_above(direction: DVec3, shading: DVec3, geometric: DVec3) -> DVec3 {
    let reflected = reflect(direction, shading);
    let lift = (-0.9 * direction.dot(geometric)).clamp(0.0, REFLECTION_LIFT);
    let height = reflected.dot(geometric);
    if height >= lift {
        return reflected;
    }
    match (reflected - height * geometric).try_normalize() {
        Some(along) => (1.0 - lift * lift).sqrt() * along + lift * geometric,
        None => reflect(direction, geometric),
    }
}

/// The largest elevation (cosine to the face normal) to which [`reflect_above`] lifts a
/// reflection that points into its surface.
pub const REFLECTION_LIFT: f64 = 0.01;

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

/// The inverse of [`refract`]: the unit normal `n` (facing the side `incident` arrives from)
/// about which `incident` refracts into `refracted` with relative index `eta`. Snell's law
/// in vector form, `refracted - eta incident = (eta cos_i - cos_t) n`, gives `n` up to sign
/// from the two directions alone (the tangential parts cancel), and of the two roots of
/// `|refracted| = 1` the transmitted one has `refracted . n = -cos_t < 0`. `None` when no
/// normal refracts `incident` into `refracted`: `refracted` leaves on `incident`'s side (a
/// reflection), or `eta = 1` (an index-matched interface bends nothing, so every normal or
/// none fits).
pub(crate) fn refraction_normal(incident: DVec3, refracted: DVec3, eta: f64) -> Option<DVec3> {
    if eta == 1.0 {
        return None;
    }
    let n = (refracted - eta * incident).try_normalize()?;
    let n = if n.dot(incident) > 0.0 { -n } else { n };
    (refracted.dot(n) < 0.0).then_some(n)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    proptest! {
        /// The normal recovered from a refraction is the normal refracted about, and
        /// refracting about it again gives the same direction and reflectance.
        #[test]
        fn refraction_normal_inverts_refract(
            (ix, iy, iz) in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            (nx, ny, nz) in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            eta in prop_oneof![0.3f64..0.99, 1.01f64..3.0],
        ) {
            let (Some(i), Some(n)) = (
                DVec3::new(ix, iy, iz).try_normalize(),
                DVec3::new(nx, ny, nz).try_normalize(),
            ) else {
                return Ok(());
            };
            let n = if n.dot(i) > 0.0 { -n } else { n };
            // Away from grazing incidence, where the refracted direction is the tangent and
            // the normal is lost in rounding.
            prop_assume!(-i.dot(n) > 1e-3);
            let Some(r) = refract(i, n, eta) else {
                return Ok(());
            };
            // Away from the critical angle (cos_t = 0), where the same happens leaving.
            prop_assume!(-r.direction.dot(n) > 1e-3);
            let back = refraction_normal(i, r.direction, eta).unwrap();
            prop_assert!((back - n).length() < 1e-9, "{back} against {n}");
            let again = refract(i, back, eta).unwrap();
            prop_assert!((again.direction - r.direction).length() < 1e-9);
            prop_assert!((again.reflectance - r.reflectance).abs() < 1e-9);
            // A refraction turns a ray by less than 90 degrees (`refracted . incident =
            // eta sin^2 + cos_i cos_t >= 0`), so a reflection turned by more is none.
            let mirrored = reflect(i, n);
            if mirrored.dot(i) < 0.0 {
                prop_assert_eq!(refraction_normal(i, mirrored, eta), None);
            }
        }
    }

    #[test]
    fn refraction_normal_degenerate_cases() {
        let d = DVec3::new(1.0, -1.0, 0.0).normalize();
        // Index-matched: nothing to recover.
        assert_eq!(refraction_normal(d, d, 1.0), None);
        // Normal incidence: the direction itself, against it.
        let n = refraction_normal(DVec3::NEG_Y, DVec3::NEG_Y, 1.0 / 1.5).unwrap();
        assert!((n - DVec3::Y).length() < 1e-15, "{n}");
    }

    proptest! {
        /// A lifted reflection is a unit vector on the incoming side of the face, the plain
        /// mirror image wherever that is high enough, and continuous at the threshold.
        #[test]
        fn reflect_above_stays_on_the_incoming_side(
            (dx, dy, dz) in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            (nx, ny, nz) in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        ) {
            let (Some(d), Some(n)) = (
                DVec3::new(dx, dy, dz).try_normalize(),
                DVec3::new(nx, ny, nz).try_normalize(),
            ) else {
                return Ok(());
            };
            // The face is the plane y = 0, seen from above.
            prop_assume!(d.y < 0.0);
            let g = DVec3::Y;
            let r = reflect_above(d, n, g);
            prop_assert!((r.length() - 1.0).abs() < 1e-12);
            let plain = reflect(d, n);
            let lift = (-0.9 * d.y).min(REFLECTION_LIFT);
            if plain.y >= lift {
                prop_assert_eq!(r, plain);
            } else {
                prop_assert!(r.y > 0.0 || lift == 0.0, "{r} under the face");
                prop_assert!((r.y - lift).abs() < 1e-12, "{r} not at elevation {lift}");
                // The direction along the face is kept.
                let (t, u) = (DVec3::new(plain.x, 0.0, plain.z), DVec3::new(r.x, 0.0, r.z));
                prop_assert!(t.cross(u).length() <= 1e-9 * t.length() && t.dot(u) >= 0.0);
            }
        }
    }

    #[test]
    fn reflect_above_degenerate_and_threshold_cases() {
        let g = DVec3::Y;
        // A reflection well above the face is the mirror image itself.
        let d = DVec3::new(1.0, -1.0, 0.0).normalize();
        assert_eq!(reflect_above(d, g, g), reflect(d, g));
        // A shading normal tilted so far that the mirror image points into the face: it
        // leaves at the elevation REFLECTION_LIFT, in the same direction along the face.
        let tilted = DVec3::new(1.0, 0.3, 0.0).normalize();
        assert!(reflect(d, tilted).y < 0.0 && reflect(d, tilted).x < 0.0);
        let r = reflect_above(d, tilted, g);
        assert!(
            (r.y - REFLECTION_LIFT).abs() < 1e-15 && r.x < 0.0 && r.z == 0.0,
            "{r}"
        );
        // Continuity: tilting the shading normal in small steps through the threshold moves
        // the ray in small steps (up to 63 degrees; at 67.5 the mirror image is -g, where
        // the direction along the face flips: the degenerate case).
        let near = |tilt: f64| reflect_above(d, DVec3::new(tilt, 1.0, 0.0).normalize(), g);
        let mut last = near(0.0);
        for k in 1..=2000 {
            let next = near(f64::from(k) * 1e-3);
            assert!(
                (next - last).length() < 3e-3,
                "jump at tilt {k}e-3: {last} -> {next}"
            );
            last = next;
        }
        assert!(
            last.y == REFLECTION_LIFT,
            "the last tilts are lifted: {last}"
        );
        // A shading normal halfway between the ray and -g mirrors it straight into the
        // face: no direction along the face is left but rounding's, and the ray leaves
        // upwards either way (exactly -g: the face's own mirror image).
        let down = DVec3::new(0.0, -1.0, 1.0).normalize();
        let halfway = (down + g).normalize();
        assert!((reflect(down, halfway) + g).length() < 1e-12);
        assert!(reflect_above(down, halfway, g).y > 0.0);
        assert_eq!(reflect(down, g), DVec3::new(0.0, 1.0, 1.0).normalize());
        // A face normal facing away from the ray counts as grazing: lifted into the plane.
        let slant = DVec3::new(1.0, 1.0, 0.0).normalize();
        let r = reflect_above(slant, g, g);
        assert!(r.y.abs() < 1e-15 && (r.x - 1.0).abs() < 1e-15, "{r}");
    }

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
