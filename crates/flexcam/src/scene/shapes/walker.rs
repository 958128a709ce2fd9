//! A walking figure: a mannequin mid-stride, built from ellipsoids.

use glam::{Affine3A, Mat3, Vec3};

use super::sphere;
use crate::scene::Mesh;

/// One body part: an ellipsoid, the unit sphere mapped by `axes` (a rotation times a
/// positive scale, so the winding stays outward) and moved to `centre`; figure of height 1.
struct Part {
    centre: Vec3,
    axes: Mat3,
}

impl Part {
    /// An ellipsoid with semi-axes `radii` along x, y and z.
    fn upright(centre: [f32; 3], radii: [f32; 3]) -> Part {
        Part {
            centre: Vec3::from_array(centre),
            axes: Mat3::from_diagonal(Vec3::from_array(radii)),
        }
    }

    /// A limb from joint `from` to joint `to`: an ellipsoid along the segment that reaches
    /// `overlap` beyond each joint (into the neighbouring part), with semi-axes `side`
    /// (across the segment, nearest the x axis) and `depth` (the third axis).
    fn limb(from: [f32; 3], to: [f32; 3], side: f32, depth: f32, overlap: f32) -> Part {
        let (from, to) = (Vec3::from_array(from), Vec3::from_array(to));
        let along = (to - from).normalize();
        let across = (Vec3::X - along * along.x).normalize();
        // (across, along, across x along) is right-handed, so the map keeps the winding.
        let third = across.cross(along);
        let half = 0.5 * from.distance(to) + overlap;
        Part {
            centre: 0.5 * (from + to),
            axes: Mat3::from_cols(side * across, half * along, depth * third),
        }
    }

    /// The part's mesh: a unit [`sphere`] of `tessellation` mapped onto the ellipsoid.
    fn mesh(&self, tessellation: u32) -> Mesh {
        let mut ellipsoid = sphere(1.0, tessellation);
        ellipsoid.transform(&Affine3A::from_mat3_translation(self.axes, self.centre));
        ellipsoid
    }
}

/// The figure's parts: head, torso, pelvis, the arms (upper arm, forearm with the hand) and
/// the legs (thigh, shin, foot). Height 1, feet on y = 0, facing +z; the left leg (+x) and
/// the right arm (-x) swing forward.
#[rustfmt::skip]
fn parts() -> [Part; 13] {
    [
        Part::upright([0.0, 0.915, 0.01], [0.055, 0.075, 0.065]),
        Part::upright([0.0, 0.70, 0.0], [0.135, 0.165, 0.08]),
        Part::upright([0.0, 0.535, 0.0], [0.115, 0.075, 0.078]),
        // Right arm, forward: shoulder to elbow, elbow to hand (from, to, side, depth, overlap).
        Part::limb([-0.135, 0.795, 0.0], [-0.15, 0.63, 0.07], 0.04, 0.04, 0.03),
        Part::limb([-0.15, 0.63, 0.07], [-0.155, 0.49, 0.175], 0.032, 0.032, 0.025),
        // Left arm, back.
        Part::limb([0.135, 0.795, 0.0], [0.15, 0.63, -0.07], 0.04, 0.04, 0.03),
        Part::limb([0.15, 0.63, -0.07], [0.155, 0.46, -0.13], 0.032, 0.032, 0.025),
        // Left leg, forward: hip to knee, knee to ankle, ankle to toe.
        Part::limb([0.07, 0.50, 0.0], [0.075, 0.27, 0.085], 0.062, 0.062, 0.04),
        Part::limb([0.075, 0.27, 0.085], [0.075, 0.045, 0.125], 0.045, 0.045, 0.03),
        Part::limb([0.075, 0.045, 0.125], [0.08, 0.018, 0.255], 0.035, 0.028, 0.03),
        // Right leg, back, its heel raised.
        Part::limb([-0.07, 0.50, 0.0], [-0.075, 0.265, -0.06], 0.062, 0.062, 0.04),
        Part::limb([-0.075, 0.265, -0.06], [-0.075, 0.075, -0.195], 0.045, 0.045, 0.03),
        Part::limb([-0.075, 0.075, -0.195], [-0.08, 0.018, -0.07], 0.035, 0.028, 0.03),
    ]
}

/// The number of body parts of [`walker`].
pub const WALKER_PARTS: u32 = 13;

/// A walking figure about `height` tall (the top of the head at 0.99 `height`), standing on
/// y = 0 around the y axis and facing +z, mid-stride: the left leg (+x) forward, the right
/// one behind with its heel raised, the arms swinging against the legs. Each of its 13 parts
/// (head, torso, pelvis, two upper arms, two forearms with the hands, two thighs, two shins,
/// two feet) is an ellipsoid tessellated as [`sphere`] is at `tessellation` (segments
/// around, at least 3), the parts overlapping at the joints: `13 * 2 * s * (s / 2 - 1)`
/// triangles for `s` segments, 6,864 at 24 (the paper's walker has 6,841). Each part is
/// closed; uvs are each part's own sphere uvs. The pose is fixed: the same mesh for the
/// same arguments.
///
/// Degenerate input: tessellation below 3 is raised to it; a negative height is taken by
/// absolute value; height 0 gives a point with valid unit normals.
pub fn walker(height: f32, tessellation: u32) -> Mesh {
    let mut mesh = Mesh::default();
    for part in parts() {
        mesh.append(&part.mesh(tessellation));
    }
    // A uniform scale leaves the normals as they are (and keeps them at height 0).
    let height = height.abs();
    for p in &mut mesh.positions {
        *p *= height;
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn walker_counts_and_shape() {
        for n in [3, 8, 24] {
            let mesh = walker(1.8, n);
            let per_part = sphere(1.0, n).triangle_count();
            assert_eq!(mesh.triangle_count(), WALKER_PARTS as usize * per_part);
            assert_well_formed(&mesh);
            assert_winding_matches_normals(&mesh);
        }
        assert_eq!(walker(1.8, 24).triangle_count(), 6864);
        // Each part is a closed ellipsoid whose normals point away from its centre.
        for part in parts() {
            let mesh = part.mesh(16);
            assert!(is_closed(&mesh));
            assert_outward(&mesh, |_| part.centre);
        }
    }

    /// About `height` tall, on the floor, around the y axis, wider across (x) than deep.
    #[test]
    fn walker_stands_on_the_floor() {
        let mesh = walker(1.8, 48);
        let (lo, hi) = mesh.bounds().unwrap();
        assert!(lo.y.abs() < 0.01, "{lo}");
        assert!((hi.y - 0.99 * 1.8).abs() < 1e-3, "{hi}");
        assert!(
            (hi.x + lo.x).abs() < 0.02 && hi.x - lo.x < 0.45 * 1.8,
            "{lo} {hi}"
        );
        // Mid-stride: a foot well in front and one well behind.
        assert!(hi.z > 0.25 * 1.8 && lo.z < -0.2 * 1.8, "{lo} {hi}");
    }

    /// The same arguments give the same mesh; the height scales it uniformly.
    #[test]
    fn walker_is_deterministic_and_scales() {
        assert_eq!(walker(1.8, 24), walker(1.8, 24));
        let (unit, tall) = (walker(1.0, 12), walker(2.5, 12));
        for (a, b) in unit.positions.iter().zip(&tall.positions) {
            assert!((*a * 2.5 - *b).length() < 1e-5);
        }
        assert_eq!(unit.normals, tall.normals);
    }

    #[test]
    fn walker_degenerate_parameters() {
        assert_eq!(walker(1.0, 0), walker(1.0, 3));
        assert_eq!(walker(-1.5, 8).positions, walker(1.5, 8).positions);
        let point = walker(0.0, 8);
        assert!(point.validate().is_ok());
        assert!(point.positions.iter().all(|p| *p == Vec3::ZERO));
        assert!(point
            .normals
            .iter()
            .all(|n| (n.length() - 1.0).abs() < 1e-5));
    }
}
