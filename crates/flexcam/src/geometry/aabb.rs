//! Axis-aligned bounding boxes in f32, as the BVH stores them.

use glam::Vec3;

/// The box `[min, max]`. The empty box has `min = +inf`, `max = -inf`, so that growing it by
/// any point or box gives exactly that point or box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// The smallest coordinate of every point in the box, per axis.
    pub min: Vec3,
    /// The largest coordinate of every point in the box, per axis.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (contains nothing; the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    /// The smallest box containing all `points` (empty for no points).
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Aabb {
        points.into_iter().fold(Aabb::EMPTY, Aabb::grow)
    }

    /// This box grown to contain `p`.
    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box containing both boxes.
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Whether the box contains no point.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// The edge lengths (zero for the empty box).
    pub fn extent(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// The centre point (meaningless for the empty box).
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Half the surface area, the quantity the surface area heuristic compares
    /// (zero for the empty box and for flat boxes' missing faces).
    pub fn half_area(&self) -> f32 {
        let e = self.extent();
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_box_is_identity_of_union() {
        let b = Aabb::from_points([Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)]);
        assert_eq!(Aabb::EMPTY.union(b), b);
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.half_area(), 0.0);
        assert_eq!(b.half_area(), 2.0 + 6.0 + 3.0);
    }

    #[test]
    fn point_box_is_flat_not_empty() {
        let b = Aabb::from_points([Vec3::ONE]);
        assert!(!b.is_empty());
        assert_eq!(b.extent(), Vec3::ZERO);
        assert_eq!(b.center(), Vec3::ONE);
    }
}
