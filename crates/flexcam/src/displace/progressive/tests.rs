//! The progressive mesh: charts are discs, the parameterisation is one to one, deviation
//! falls as levels grow, `M100` is the input.

use glam::{DVec2, Vec2, Vec3};

use super::charts::is_disc;
use super::*;
use crate::scene::shapes::torus;

/// A bumpy `n` x `n` grid of triangles over the unit square with uvs and normals.
fn bumpy_grid(n: u32) -> Mesh {
    let mut mesh = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            let z = 0.08 * (x * 9.0).sin() * (y * 7.0).cos();
            mesh.positions.push(Vec3::new(x, y, z));
            mesh.uvs.push(Vec2::new(x, y));
            mesh.normals.push(Vec3::Z);
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            mesh.triangles
                .push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            mesh.triangles
                .push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    mesh
}

fn meshes() -> Vec<(&'static str, Mesh)> {
    vec![("grid", bumpy_grid(40)), ("torus", torus(1.0, 0.35, 40))]
}

#[test]
fn charts_are_discs_and_cover_the_mesh() {
    for (name, mesh) in meshes() {
        let pm = ProgressiveMesh::new(&mesh).unwrap();
        let count = pm.chart_uvs.len();
        assert!(count > 1, "{name}: one chart");
        assert_eq!(pm.charts.len(), mesh.triangles.len());
        for c in 0..count as u32 {
            let faces: Vec<u32> = (0..pm.charts.len() as u32)
                .filter(|&f| pm.charts[f as usize] == c)
                .collect();
            let inside = |g: u32| g != topology::NONE && pm.charts[g as usize] == c;
            assert!(
                is_disc(&pm.topology, faces.iter().copied(), inside),
                "{name}: chart {c}"
            );
        }
    }
}

#[test]
fn parameterisation_is_one_to_one_per_chart() {
    for (name, mesh) in meshes() {
        let pm = ProgressiveMesh::new(&mesh).unwrap();
        for lod in &pm.lods {
            for (t, &f) in lod.mesh.triangles.iter().zip(&lod.faces) {
                let uvs = &pm.chart_uvs[pm.charts[f as usize] as usize];
                let [a, b, c] = t.map(|v| uvs[&lod.vertices[v as usize]]);
                let area = (b - a).perp_dot(c - a);
                assert!(
                    area > 0.0,
                    "{name} M{}: triangle {t:?} flips ({area})",
                    lod.percent
                );
            }
        }
        // Inside the unit circle, boundary on it.
        for uvs in &pm.chart_uvs {
            assert!(uvs.values().all(|p| p.length() <= 1.0 + 1e-12));
            assert!(
                uvs.values()
                    .filter(|p| (p.length() - 1.0).abs() < 1e-12)
                    .count()
                    >= 3
            );
        }
    }
}

/// A bijection of each chart: the chart's triangles tile its disc exactly once, so their
/// uv areas add up to the area of the boundary polygon.
#[test]
fn chart_triangles_tile_their_polygon() {
    let mesh = bumpy_grid(30);
    let pm = ProgressiveMesh::new(&mesh).unwrap();
    for (c, uvs) in pm.chart_uvs.iter().enumerate() {
        let mut area = 0.0;
        for (f, t) in mesh.triangles.iter().enumerate() {
            if pm.charts[f] == c as u32 {
                let [a, b, d] = t.map(|v| uvs[&v]);
                area += 0.5 * (b - a).perp_dot(d - a);
            }
        }
        // The boundary points in angle order form the polygon.
        let mut rim: Vec<DVec2> = uvs
            .values()
            .copied()
            .filter(|p| (p.length() - 1.0).abs() < 1e-12)
            .collect();
        rim.sort_by(|p, q| p.y.atan2(p.x).total_cmp(&q.y.atan2(q.x)));
        let polygon: f64 = (0..rim.len())
            .map(|i| 0.5 * rim[i].perp_dot(rim[(i + 1) % rim.len()]))
            .sum();
        assert!(
            (area - polygon).abs() < 1e-9,
            "chart {c}: {area} vs {polygon}"
        );
    }
}

#[test]
fn deviation_grows_as_levels_shrink_and_m100_is_the_input() {
    for (name, mesh) in meshes() {
        let pm = ProgressiveMesh::new(&mesh).unwrap();
        assert_eq!(pm.lods.len(), LOD_PERCENTS.len());
        let full = &pm.lods[0];
        assert_eq!(full.mesh, mesh, "{name}: M100 differs from the input");
        assert!(
            full.deviation < 1e-12,
            "{name}: M100 deviates by {}",
            full.deviation
        );
        for pair in pm.lods.windows(2) {
            let (finer, coarser) = (&pair[0], &pair[1]);
            assert!(
                coarser.mesh.triangles.len() < finer.mesh.triangles.len(),
                "{name}: M{} has no fewer faces than M{}",
                coarser.percent,
                finer.percent
            );
            assert!(
                coarser.deviation >= finer.deviation && coarser.deviation > 0.0,
                "{name}: deviation M{} {} < M{} {}",
                coarser.percent,
                coarser.deviation,
                finer.percent,
                finer.deviation
            );
        }
        let last = pm.lods.last().unwrap();
        assert!(
            last.mesh.triangles.len() <= mesh.triangles.len() * 21 / 100,
            "{name}: M20 has {} of {} faces",
            last.mesh.triangles.len(),
            mesh.triangles.len()
        );
    }
}

/// Every level keeps input vertices with their own attributes, and the boundary (the
/// torus's open texture seams) in place.
#[test]
fn levels_keep_input_vertices_and_boundary() {
    let mesh = torus(1.0, 0.35, 30);
    let pm = ProgressiveMesh::new(&mesh).unwrap();
    for lod in &pm.lods {
        for (i, &v) in lod.vertices.iter().enumerate() {
            assert_eq!(lod.mesh.positions[i], mesh.positions[v as usize]);
            assert_eq!(lod.mesh.uvs[i], mesh.uvs[v as usize]);
            assert_eq!(lod.mesh.normals[i], mesh.normals[v as usize]);
        }
        for v in 0..mesh.positions.len() as u32 {
            if pm.topology.on_boundary(v) {
                assert!(
                    lod.vertices.contains(&v),
                    "M{}: boundary vertex {v} gone",
                    lod.percent
                );
            }
        }
    }
}

#[test]
fn refuses_non_manifold_meshes() {
    let mut mesh = bumpy_grid(2);
    let extra = mesh.positions.len() as u32;
    mesh.positions.push(Vec3::new(0.5, 0.5, 1.0));
    mesh.uvs.push(Vec2::ZERO);
    mesh.normals.push(Vec3::Z);
    let [a, b, _] = mesh.triangles[0];
    mesh.triangles.push([a, b, extra]);
    // The edge from vertex 0 to vertex 1 now has a third face.
    let message = ProgressiveMesh::new(&mesh).unwrap_err().to_string();
    assert!(
        message.contains("from vertex 0 to vertex 1") && message.contains("face 8"),
        "{message}"
    );
}
