//! Clipping a scene triangle to the half-spaces of an [`InverseChart`] in 3D, before
//! projection (Sutherland-Hodgman), so that no piece reaches the place where the inverse
//! jumps (the plane through a perspective eye, the ends of a flexible volume).
//!
//! Where an edge crosses a plane, the crossing is computed from the edge's end points in a
//! canonical order (see [`canonical`]), so the two triangles sharing the edge get the same
//! point bit for bit and their clipped outlines still meet without a crack.
//!
//! [`InverseChart`]: crate::projection::InverseChart

use glam::DVec3;

use crate::projection::HalfSpace;

/// The most vertices a triangle clipped by [`MAX_PLANES`] planes can have.
const MAX_VERTICES: usize = 3 + MAX_PLANES;

/// The most half-spaces a chart may have (a flexible volume between planes has two).
pub const MAX_PLANES: usize = 4;

/// A convex polygon of at most [`MAX_VERTICES`] vertices, without allocation.
#[derive(Debug, Clone, Copy)]
pub struct Clipped {
    vertices: [DVec3; MAX_VERTICES],
    len: usize,
}

impl Clipped {
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices[..self.len]
    }

    /// The polygon as a fan of triangles around its first vertex.
    pub fn fan(&self) -> impl Iterator<Item = [DVec3; 3]> + '_ {
        let v = self.vertices();
        (1..v.len().saturating_sub(1)).map(move |i| [v[0], v[i], v[i + 1]])
    }
}

/// Whether `a` comes before `b` in the lexicographic order of their coordinates.
pub fn canonical(a: DVec3, b: DVec3) -> bool {
    (a.x, a.y, a.z) <= (b.x, b.y, b.z)
}

/// The point where segment `a b` crosses the plane of `plane`, from its ends in canonical
/// order; `da`, `db` are their signed distances, of opposite signs.
fn crossing(a: DVec3, da: f64, b: DVec3, db: f64) -> DVec3 {
    let ((p, dp), (q, dq)) = if canonical(a, b) {
        ((a, da), (b, db))
    } else {
        ((b, db), (a, da))
    };
    p + (q - p) * (dp / (dp - dq))
}

/// `triangle` clipped to the intersection of `planes` (at most [`MAX_PLANES`]; points on a
/// plane count as inside, and an edge is cut only where its ends lie strictly on opposite
/// sides). The result has fewer than three vertices when nothing of the
/// triangle, or only an edge or a point of it, is inside.
pub fn clip(triangle: [DVec3; 3], planes: &[HalfSpace]) -> Clipped {
    debug_assert!(planes.len() <= MAX_PLANES);
    let mut polygon = Clipped {
        vertices: [DVec3::ZERO; MAX_VERTICES],
        len: 3,
    };
    polygon.vertices[..3].copy_from_slice(&triangle);
    for plane in planes {
        let input = polygon;
        polygon.len = 0;
        let v = input.vertices();
        for (i, &a) in v.iter().enumerate() {
            let b = v[(i + 1) % v.len()];
            let (da, db) = (plane.signed_distance(a), plane.signed_distance(b));
            if da >= 0.0 {
                polygon.vertices[polygon.len] = a;
                polygon.len += 1;
            }
            if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
                polygon.vertices[polygon.len] = crossing(a, da, b, db);
                polygon.len += 1;
            }
        }
        if polygon.len < 3 {
            polygon.len = 0;
            break;
        }
    }
    polygon
}

#[cfg(test)]
mod tests {
    use super::*;

    fn z_at_least(z: f64) -> HalfSpace {
        HalfSpace {
            normal: DVec3::Z,
            offset: z,
        }
    }

    #[test]
    fn inside_outside_and_crossing() {
        let t = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
        ];
        assert_eq!(clip(t, &[z_at_least(-1.0)]).vertices(), &t);
        assert!(clip(t, &[z_at_least(3.0)]).vertices().is_empty());
        let cut = clip(t, &[z_at_least(1.0)]);
        assert_eq!(cut.vertices().len(), 4);
        assert!(cut.vertices().iter().all(|v| v.z >= 1.0));
        assert_eq!(cut.fan().count(), 2);
        // Two planes leave a band.
        let band = clip(
            t,
            &[
                z_at_least(0.5),
                HalfSpace {
                    normal: DVec3::NEG_Z,
                    offset: -1.5,
                },
            ],
        );
        assert_eq!(band.vertices().len(), 4);
    }

    /// Degenerate: a triangle touching the plane in one vertex or an edge keeps nothing.
    #[test]
    fn touching_only_is_empty() {
        let t = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, 1.0, -1.0),
        ];
        assert!(clip(t, &[z_at_least(0.0)]).vertices().len() < 3);
    }

    #[test]
    fn shared_edges_cross_at_the_same_point() {
        let (a, b) = (DVec3::new(0.1, 0.3, -0.7), DVec3::new(0.9, -0.2, 1.3));
        let plane = [z_at_least(0.123)];
        let one = clip([a, b, DVec3::new(-1.0, 0.0, 2.0)], &plane);
        let two = clip([b, a, DVec3::new(2.0, 1.0, 2.0)], &plane);
        let on_ab: Vec<DVec3> = one
            .vertices()
            .iter()
            .copied()
            .filter(|v| v.z < 0.2 && v.x > 0.0)
            .collect();
        assert_eq!(on_ab.len(), 1);
        assert!(two.vertices().contains(&on_ab[0]));
    }
}
