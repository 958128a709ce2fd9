//! Indexed triangle meshes with optional per-vertex attributes.

use glam::{Affine3A, Vec2, Vec3};

use crate::error::{Error, Result};
use crate::geometry::MeshView;

/// An indexed triangle mesh.
///
/// `positions` is always present; `normals`, `uvs` and `colors` are either empty or have one
/// entry per position. Colours are linear RGB.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals (shading), one per position, or empty for flat shading.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position, or empty.
    pub uvs: Vec<Vec2>,
    /// Vertex colours (linear RGB), one per position, or empty (white).
    pub colors: Vec<Vec3>,
    /// Vertex indices of each triangle, each below `positions.len()`.
    pub triangles: Vec<[u32; 3]>,
}

impl<'a> From<&'a Mesh> for MeshView<'a> {
    fn from(mesh: &'a Mesh) -> Self {
        MeshView {
            positions: &mesh.positions,
            normals: &mesh.normals,
            triangles: &mesh.triangles,
        }
    }
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Checks the invariants: attribute lengths, indices in range, finite positions.
    /// Loaders call this so that renderers may index without checks.
    pub fn validate(&self) -> Result<()> {
        let n = self.positions.len();
        for (name, len) in [
            ("normals", self.normals.len()),
            ("texture coordinates", self.uvs.len()),
            ("colours", self.colors.len()),
        ] {
            if len != 0 && len != n {
                return Err(Error::new(format!(
                    "mesh has {len} {name} for {n} vertices"
                )));
            }
        }
        if let Some(bad) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::new(format!(
                "vertex {bad} has a non-finite position"
            )));
        }
        if let Some((i, t)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&k| k as usize >= n))
        {
            return Err(Error::new(format!(
                "triangle {i} refers to vertex {:?}, but the mesh has {n} vertices",
                t
            )));
        }
        Ok(())
    }

    /// Applies an affine transform to positions, and its inverse transpose to normals.
    pub fn transform(&mut self, m: &Affine3A) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        let normal_matrix = m.matrix3.inverse().transpose();
        for n in &mut self.normals {
            *n = (normal_matrix * *n).normalize_or_zero();
        }
    }

    /// Appends `other`, re-indexing its triangles. Attributes present in only one of the two
    /// meshes are filled with defaults for the other (normal zero = use the face normal,
    /// uv zero, colour white).
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        let (n_self, n_other) = (self.positions.len(), other.positions.len());
        fn merge<T: Copy>(a: &mut Vec<T>, b: &[T], n_a: usize, n_b: usize, fill: T) {
            if a.is_empty() && b.is_empty() {
                return;
            }
            if a.is_empty() {
                a.resize(n_a, fill);
            }
            if b.is_empty() {
                a.extend(std::iter::repeat_n(fill, n_b));
            } else {
                a.extend_from_slice(b);
            }
        }
        merge(
            &mut self.normals,
            &other.normals,
            n_self,
            n_other,
            Vec3::ZERO,
        );
        merge(&mut self.uvs, &other.uvs, n_self, n_other, Vec2::ZERO);
        merge(&mut self.colors, &other.colors, n_self, n_other, Vec3::ONE);
        self.positions.extend_from_slice(&other.positions);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }

    /// Axis-aligned bounds of the positions, or `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Mesh {
        Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            triangles: vec![[0, 1, 2]],
            ..Default::default()
        }
    }

    #[test]
    fn validate_rejects_bad_index_and_lengths() {
        let mut m = tri();
        assert!(m.validate().is_ok());
        m.triangles.push([0, 1, 3]);
        assert!(m.validate().is_err());
        let mut m = tri();
        m.normals = vec![Vec3::Z];
        assert!(m.validate().is_err());
        let mut m = tri();
        m.positions[1] = Vec3::NAN;
        assert!(m.validate().is_err());
    }

    #[test]
    fn append_fills_missing_attributes() {
        let mut a = tri();
        let mut b = tri();
        b.colors = vec![Vec3::X; 3];
        a.append(&b);
        assert_eq!(a.positions.len(), 6);
        assert_eq!(a.colors.len(), 6);
        assert_eq!(a.colors[0], Vec3::ONE);
        assert_eq!(a.triangles[1], [3, 4, 5]);
        assert!(a.validate().is_ok());
    }

    #[test]
    fn transform_keeps_normals_perpendicular_under_nonuniform_scale() {
        let mut m = tri();
        m.normals = vec![Vec3::Z; 3];
        m.transform(&Affine3A::from_scale(Vec3::new(2.0, 1.0, 3.0)));
        assert!((m.normals[0] - Vec3::Z).length() < 1e-6);
        assert_eq!(m.positions[1], Vec3::new(2.0, 0.0, 0.0));
    }
}
