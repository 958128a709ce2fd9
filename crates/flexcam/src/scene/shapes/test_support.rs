//! Checks shared by the shape tests: normals, winding, closedness and area.

use std::collections::HashMap;

use glam::Vec3;

use crate::scene::Mesh;

/// The three corner positions of triangle `t`.
pub fn corners(mesh: &Mesh, t: [u32; 3]) -> [Vec3; 3] {
    t.map(|k| mesh.positions[k as usize])
}

/// Total triangle area.
pub fn area(mesh: &Mesh) -> f32 {
    mesh.triangles
        .iter()
        .map(|&t| {
            let [a, b, c] = corners(mesh, t);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// Asserts the mesh is valid, has one unit normal and one uv in `[0,1]^2` per vertex, no
/// NaN, and no triangle with (near) zero area.
pub fn assert_well_formed(mesh: &Mesh) {
    mesh.validate().expect("valid mesh");
    assert_eq!(mesh.normals.len(), mesh.positions.len());
    assert_eq!(mesh.uvs.len(), mesh.positions.len());
    for (i, n) in mesh.normals.iter().enumerate() {
        assert!(
            (n.length() - 1.0).abs() < 1e-4,
            "normal {i} = {n} is not unit"
        );
    }
    for uv in &mesh.uvs {
        assert!(
            uv.is_finite() && uv.min_element() >= 0.0 && uv.max_element() <= 1.0,
            "{uv}"
        );
    }
    let (lo, hi) = mesh.bounds().expect("non-empty");
    let scale = (hi - lo).length();
    for &t in &mesh.triangles {
        let [a, b, c] = corners(mesh, t);
        let double_area = (b - a).cross(c - a).length();
        assert!(
            double_area > 1e-9 * scale * scale,
            "zero-area triangle {t:?}"
        );
    }
}

/// Asserts that each triangle's winding (counter-clockwise = front) agrees with the vertex
/// normals at its corners.
pub fn assert_winding_matches_normals(mesh: &Mesh) {
    for &t in &mesh.triangles {
        let [a, b, c] = corners(mesh, t);
        let face = (b - a).cross(c - a);
        for k in t {
            let n = mesh.normals[k as usize];
            assert!(face.dot(n) > 0.0, "triangle {t:?} winds against normal {n}");
        }
    }
}

/// Asserts every vertex normal points away from `centre(position)`.
pub fn assert_outward(mesh: &Mesh, centre: impl Fn(Vec3) -> Vec3) {
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        assert!(
            n.dot(*p - centre(*p)) > 0.0,
            "normal {n} at {p} points inward"
        );
    }
}

/// Whether the mesh is closed and consistently oriented once coincident positions are
/// welded: every directed edge occurs exactly once and its reverse exactly once.
pub fn is_closed(mesh: &Mesh) -> bool {
    let mut ids: HashMap<[i64; 3], usize> = HashMap::new();
    let weld: Vec<usize> = mesh
        .positions
        .iter()
        .map(|p| {
            let key = (*p * 1e4).round().to_array().map(|x| x as i64);
            let next = ids.len();
            *ids.entry(key).or_insert(next)
        })
        .collect();
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for t in &mesh.triangles {
        let v = t.map(|k| weld[k as usize]);
        for e in 0..3 {
            *directed.entry((v[e], v[(e + 1) % 3])).or_default() += 1;
        }
    }
    directed
        .iter()
        .all(|(&(a, b), &count)| count == 1 && directed.get(&(b, a)) == Some(&1))
}
