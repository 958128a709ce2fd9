//! Per-fragment mirror rays (Hou, Wei, Shum and Guo 2006, section 3.1, the reflection
//! variant of camera triangles): instead of interpolating the vertex rays, a mirror's
//! projection triangle interpolates its *vertex normals* and reflects the eye's ray about
//! the interpolated normal at every screen point.
//!
//! The screen point at barycentrics `b` of a projection triangle with base points `p_k` and
//! unit vertex normals `n_k` emits the ray from `P(b) = sum b_k p_k` along
//! `reflect(i(b), n(b))`, where `i(b) = (P(b) - eye) / |P(b) - eye|` is the eye's unit ray to
//! that point and `n(b) = N(b) / |N(b)|`, `N(b) = sum b_k n_k`, kept out of the base
//! triangle's face as the ray caster keeps its mirror rays ([`reflect_above`]: where the
//! interpolated normal leans so far that the mirror image points into the face, near a
//! coarse mirror's rim, it leaves at a small elevation instead). At a vertex this is the
//! vertex ray of the interpolated surface (`vertex_ray` with [`Optic::Reflect`]); in between
//! it is the exact mirror reflection of the eye's ray at `P(b)` for the mirror whose normals
//! are interpolated as the ray caster interpolates them, where the interpolated vertex rays
//! only approximate it. Reflection about `n` and about `-n` is the same, so the side the
//! normals face does not matter.
//!
//! Degenerate cases (each tested):
//! - `N(b) = 0` (vertex normals that cancel inside the triangle): no normal, the ray goes on
//!   along `i(b)` (as `reflect` about a zero normal gives), not lifted;
//! - a degenerate base triangle (no face normal): not lifted;
//! - the eye on the base triangle at `P(b)`: no incident direction, no ray (`None`, as a zero
//!   interpolated direction gives none).
//!
//! [`Optic::Reflect`]: super::mesh_builders::Optic::Reflect

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::geometry::optics::{reflect, reflect_above};
use crate::geometry::Ray;

/// The per-fragment mirror of a trilinear projection: the eye whose rays it reflects and the
/// unit shading normal of each mesh vertex (same order as the mesh's points).
#[derive(Debug, Clone, PartialEq)]
pub struct FragmentMirror {
    /// The eye of the reflected rays (the main camera's centre).
    pub eye: DVec3,
    /// The unit shading normal of each mesh vertex.
    pub normals: Vec<DVec3>,
}

impl FragmentMirror {
    /// Checks the mirror against a mesh of `vertices` vertices. Errors: another count of
    /// normals; a normal or eye that is not finite; a normal that is not of unit length
    /// (within 1e-6).
    pub(super) fn validate(&self, vertices: usize) -> Result<()> {
        if self.normals.len() != vertices {
            return Err(Error::new(format!(
                "per-fragment mirror: {} normals for {vertices} vertices",
                self.normals.len()
            )));
        }
        if !self.eye.is_finite() {
            return Err(Error::new("per-fragment mirror: the eye is not finite"));
        }
        if let Some(k) = self
            .normals
            .iter()
            .position(|n| !n.is_finite() || (n.length() - 1.0).abs() > 1e-6)
        {
            return Err(Error::new(format!(
                "per-fragment mirror: normal {k} is not a finite unit vector"
            )));
        }
        Ok(())
    }

    /// The mirror of the projection triangle with base points `points` and mesh vertices
    /// `vertices`.
    pub fn triangle(&self, points: [DVec3; 3], vertices: [usize; 3]) -> TriangleMirror {
        TriangleMirror {
            eye: self.eye,
            points,
            normals: vertices.map(|k| self.normals[k]),
        }
    }
}

/// One projection triangle's per-fragment mirror (module doc): its base points, its unit
/// vertex normals and the eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleMirror {
    /// The eye of the reflected rays.
    pub eye: DVec3,
    /// The base points `p_k` (barycentrics `(u, v)` weigh `p_1` and `p_2`).
    pub points: [DVec3; 3],
    /// The unit vertex normals `n_k`.
    pub normals: [DVec3; 3],
}

impl TriangleMirror {
    /// `P(b)`: the base point at barycentrics `b = (u, v)`.
    #[inline]
    pub fn point(&self, b: DVec2) -> DVec3 {
        interpolate(&self.points, b)
    }

    /// `N(b)`: the vertex normals interpolated at `b`, not normalised.
    #[inline]
    pub fn normal(&self, b: DVec2) -> DVec3 {
        interpolate(&self.normals, b)
    }

    /// The ray at barycentrics `b` (module doc), its direction a unit vector; `None` where
    /// the eye is at `P(b)`.
    #[inline]
    pub fn ray(&self, b: DVec2) -> Option<Ray> {
        let point = self.point(b);
        let incident = (point - self.eye).try_normalize()?;
        let normal = self.normal(b).normalize_or_zero();
        if normal == DVec3::ZERO {
            return Some(Ray::new(point, reflect(incident, normal)));
        }
        Some(Ray::new(
            point,
            reflect_above(incident, normal, self.face_towards(incident)),
        ))
    }

    /// The unit normal of the base triangle turned against `incident` (to the side a ray
    /// along it arrives from); zero for a degenerate triangle.
    #[inline]
    pub fn face_towards(&self, incident: DVec3) -> DVec3 {
        let [p0, p1, p2] = self.points;
        let face = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        if face.dot(incident) > 0.0 {
            -face
        } else {
            face
        }
    }
}

/// `w a_0 + u a_1 + v a_2` with `w = 1 - u - v`.
#[inline]
fn interpolate(a: &[DVec3; 3], b: DVec2) -> DVec3 {
    (1.0 - b.x - b.y) * a[0] + b.x * a[1] + b.y * a[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat() -> TriangleMirror {
        TriangleMirror {
            eye: DVec3::new(0.2, 0.3, 2.0),
            points: [DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: [DVec3::Z; 3],
        }
    }

    /// A flat mirror reflects every eye ray exactly: the ray continues the eye's mirror image.
    #[test]
    fn a_flat_mirror_reflects_the_eye() {
        let m = flat();
        let mirrored_eye = DVec3::new(m.eye.x, m.eye.y, -m.eye.z);
        for b in [DVec2::new(0.1, 0.2), DVec2::new(0.7, 0.1), DVec2::ZERO] {
            let ray = m.ray(b).unwrap();
            let from_image = (ray.origin - mirrored_eye).normalize();
            assert!((ray.direction - from_image).length() < 1e-12, "{b}");
            assert!((ray.direction.length() - 1.0).abs() < 1e-12);
        }
    }

    /// At a vertex the ray is the vertex's reflected eye ray, whichever way the normal faces.
    #[test]
    fn vertex_rays_and_flipped_normals() {
        let mut m = flat();
        m.normals = [
            DVec3::new(0.3, 0.0, 1.0).normalize(),
            DVec3::new(0.0, 0.4, 1.0).normalize(),
            DVec3::new(-0.2, 0.1, -1.0).normalize(),
        ];
        let at = m.ray(DVec2::Y).unwrap();
        let i = (m.points[2] - m.eye).normalize();
        assert!((at.direction - reflect(i, m.normals[2])).length() < 1e-12);
        let mut flipped = m;
        flipped.normals = m.normals.map(|n| -n);
        let b = DVec2::new(0.3, 0.3);
        let (a, c) = (m.ray(b).unwrap(), flipped.ray(b).unwrap());
        assert!((a.direction - c.direction).length() < 1e-12);
    }

    /// Degenerate cases: cancelling normals pass the eye's ray on; the eye on the triangle
    /// gives no ray.
    #[test]
    fn degenerate_normals_and_eye() {
        let mut m = flat();
        m.normals = [DVec3::Z, -DVec3::Z, DVec3::Z];
        let b = DVec2::new(0.5, 0.0);
        assert_eq!(m.normal(b), DVec3::ZERO);
        let ray = m.ray(b).unwrap();
        assert!((ray.direction - (m.point(b) - m.eye).normalize()).length() < 1e-12);
        let mut on = flat();
        on.eye = on.point(DVec2::new(0.25, 0.25));
        assert!(on.ray(DVec2::new(0.25, 0.25)).is_none());
    }

    /// Near a rim, normals leaning far from the face would mirror the eye's ray into it:
    /// the ray leaves the face instead, at the ray caster's elevation; a ray mirrored well
    /// above the face is the plain mirror image.
    #[test]
    fn rays_are_kept_out_of_the_face() {
        let mut m = flat();
        // The eye looks down at about 45 degrees; normals leaning 70 degrees towards it.
        m.eye = DVec3::new(-2.0, 0.2, 2.0);
        let lean = DVec3::new(-0.94, 0.0, 0.34).normalize();
        m.normals = [lean; 3];
        let b = DVec2::new(0.3, 0.3);
        let i = (m.point(b) - m.eye).normalize();
        assert!(reflect(i, lean).z < 0.0);
        let ray = m.ray(b).unwrap();
        assert!((ray.direction.z - crate::geometry::REFLECTION_LIFT).abs() < 1e-12);
        assert!((ray.direction.length() - 1.0).abs() < 1e-12);
        // The base triangle wound the other way gives the same ray.
        let mut turned = m;
        turned.points.swap(1, 2);
        turned.normals.swap(1, 2);
        let turned_ray = turned.ray(DVec2::new(0.3, 0.3)).unwrap();
        assert!((turned_ray.direction - ray.direction).length() < 1e-12);
        // Degenerate base triangle: no face, the plain mirror image.
        let mut line = m;
        line.points = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        let r = line.ray(b).unwrap();
        let i = (line.point(b) - line.eye).normalize();
        assert!((r.direction - reflect(i, lean)).length() < 1e-12);
    }

    #[test]
    fn validation() {
        let ok = FragmentMirror {
            eye: DVec3::ZERO,
            normals: vec![DVec3::Z; 3],
        };
        assert!(ok.validate(3).is_ok());
        assert_eq!(
            ok.validate(4).unwrap_err().to_string(),
            "per-fragment mirror: 3 normals for 4 vertices"
        );
        let bad = FragmentMirror {
            normals: vec![DVec3::Z, DVec3::ZERO, DVec3::Z],
            ..ok.clone()
        };
        assert_eq!(
            bad.validate(3).unwrap_err().to_string(),
            "per-fragment mirror: normal 1 is not a finite unit vector"
        );
    }
}
