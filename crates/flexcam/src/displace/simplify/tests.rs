//! Simplify, replay the splits, compare with the input; manifold checks; degenerate cases.

use glam::{Vec2, Vec3};
use proptest::prelude::*;

use super::*;

/// A `w` x `h` grid of quads in the z = 0 plane (triangles if `triangles`), its inner
/// vertices moved by up to `jitter` cells in x and y and by `bump` in z by a smooth hill.
fn grid(w: u32, h: u32, triangles: bool, jitter: f32, bump: f32, seed: u64) -> PolyMesh {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let mut rand = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f32 / (1u64 << 53) as f32 - 0.5
    };
    let mut mesh = PolyMesh::default();
    for j in 0..=h {
        for i in 0..=w {
            let inner = i > 0 && j > 0 && i < w && j < h;
            let (dx, dy) = if inner {
                (rand() * jitter, rand() * jitter)
            } else {
                (0.0, 0.0)
            };
            let (x, y) = (i as f32 + dx, j as f32 + dy);
            let z = bump * (x * 0.7).sin() * (y * 0.5).cos();
            mesh.positions.push(Vec3::new(x, y, z));
            mesh.uvs.push(Vec2::new(x / w as f32, y / h as f32));
        }
    }
    let at = |i: u32, j: u32| j * (w + 1) + i;
    for j in 0..h {
        for i in 0..w {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            polymesh::push_cell(&mut mesh.faces, q, triangles);
        }
    }
    mesh
}

/// A closed torus of `m` x `n` quads (radii 2 and 0.7).
fn torus(m: u32, n: u32) -> PolyMesh {
    closed_torus(2.0, 0.7, m, n, false)
}

/// A closed prism over a regular `k`-gon: two k-gon caps and k quads.
fn prism(k: u32) -> PolyMesh {
    let mut mesh = PolyMesh::default();
    for z in [0.0, 1.0] {
        for i in 0..k {
            let a = i as f32 / k as f32 * std::f32::consts::TAU;
            mesh.positions.push(Vec3::new(a.cos(), a.sin(), z));
        }
    }
    mesh.faces.push((0..k).rev().collect());
    mesh.faces.push((k..2 * k).collect());
    for i in 0..k {
        let j = (i + 1) % k;
        mesh.faces.push(vec![i, j, j + k, i + k]);
    }
    mesh
}

/// A tetrahedron, faces outward.
fn tetrahedron() -> PolyMesh {
    PolyMesh {
        positions: vec![
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ],
        faces: vec![vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 1], vec![1, 3, 2]],
        ..PolyMesh::default()
    }
}

/// Simplifies, checks that the coarse mesh and every intermediate are manifolds and that
/// replaying every split gives the input exactly; returns the result.
fn round_trip(mesh: &PolyMesh, options: &SimplifyOptions) -> Simplified {
    let s = simplify(mesh, options).expect("a supported mesh");
    assert_eq!(s.refine(s.splits.len()), *mesh, "replaying every split");
    assert_eq!(s.refine(0), s.coarse);
    let step = (s.splits.len() / 7).max(1);
    for k in (0..s.splits.len()).step_by(step) {
        let m = s.refine(k);
        HalfEdgeMesh::build(&m).unwrap_or_else(|d| panic!("after {k} splits: {d:?}"));
    }
    s
}

fn options(target: usize, kind: CollapseKind, degrees: f32) -> SimplifyOptions {
    SimplifyOptions {
        threshold_degrees: degrees,
        collapse: kind,
        ..SimplifyOptions::to_faces(target)
    }
}

#[test]
fn flat_quad_grid_collapses_far_and_rebuilds_exactly() {
    let mesh = grid(12, 9, false, 0.0, 0.0, 1);
    for kind in [CollapseKind::Full, CollapseKind::Half] {
        let s = round_trip(&mesh, &options(1, kind, 1.0));
        // A flat grid may go down to very few faces: the outline's four corners stay.
        assert!(
            s.coarse.face_count() <= 4,
            "{kind:?}: {}",
            s.coarse.face_count()
        );
        assert_eq!(s.coarse.face_count(), mesh.face_count() - count_removed(&s));
        for face in &s.coarse.faces {
            let n = polygon_normal(face, |v| s.coarse.positions[v as usize]);
            assert!(n.z > 0.0, "{kind:?}: a coarse face turned over");
        }
    }
}

/// Faces removed over all collapses.
fn count_removed(s: &Simplified) -> usize {
    let mut alive = vec![false; s.face_id_count];
    for &f in &s.face_ids {
        alive[f as usize] = true;
    }
    alive.iter().filter(|a| !**a).count()
}

#[test]
fn curved_grid_stops_at_the_threshold() {
    let mesh = grid(16, 16, true, 0.2, 1.0, 3);
    let tight = round_trip(&mesh, &options(1, CollapseKind::Full, 2.0));
    let loose = round_trip(&mesh, &options(1, CollapseKind::Full, 30.0));
    assert!(tight.coarse.face_count() > loose.coarse.face_count());
    assert!(tight.coarse.face_count() > 8);
}

#[test]
fn closed_torus_rebuilds_exactly_with_both_collapses() {
    let mesh = torus(24, 12);
    for kind in [CollapseKind::Full, CollapseKind::Half] {
        let s = round_trip(&mesh, &options(60, kind, 40.0));
        assert!(
            s.coarse.face_count() <= 60,
            "{kind:?}: {}",
            s.coarse.face_count()
        );
        // Still a closed surface of genus one: V - E + F = 0.
        let he = HalfEdgeMesh::build(&s.coarse).unwrap();
        let (v, e, f) = (
            s.coarse.vertex_count(),
            he.edges().count(),
            s.coarse.face_count(),
        );
        assert_eq!(v + f, e, "{kind:?}: Euler characteristic");
        assert!((0..v as u32).all(|v| !he.is_boundary_vertex(v)));
    }
}

#[test]
fn n_gons_lose_corners_and_come_back() {
    // A hexagonal prism: hexagon caps lose corners before they disappear.
    let mesh = prism(6);
    let s = round_trip(&mesh, &options(1, CollapseKind::Half, 60.0));
    assert!(s.coarse.vertex_count() < mesh.vertex_count());
    let corners = |m: &PolyMesh| m.faces.iter().map(Vec::len).sum::<usize>();
    assert!(corners(&s.coarse) < corners(&mesh));
    // Quads with a pentagon and heptagon in one mesh: a grid with two cells merged twice.
    let mut mixed = grid(6, 5, false, 0.1, 0.3, 5);
    let (q0, q1) = (mixed.faces.remove(1), mixed.faces.remove(0));
    // q1 = [0,1,8,7], q0 = [1,2,9,8]: merged into the hexagon [0,1,2,9,8,7].
    assert_eq!((q1[1], q1[2]), (q0[0], q0[3]));
    mixed
        .faces
        .push(vec![q1[0], q0[0], q0[1], q0[2], q0[3], q1[3]]);
    for kind in [CollapseKind::Full, CollapseKind::Half] {
        let s = round_trip(&mixed, &options(3, kind, 45.0));
        assert!(s.coarse.face_count() < mixed.face_count());
    }
}

#[test]
fn tetrahedron_cannot_collapse() {
    // Collapsing any edge would leave two triangles on the same three vertices.
    let mesh = tetrahedron();
    for kind in [CollapseKind::Full, CollapseKind::Half] {
        let s = round_trip(&mesh, &options(1, kind, 180.0));
        assert!(s.splits.is_empty());
        assert_eq!(s.coarse, mesh);
    }
    // A closed mesh simplifies down to a tetrahedron at the least.
    let s = round_trip(&torus(6, 4), &options(1, CollapseKind::Half, 180.0));
    assert!(s.coarse.face_count() >= 4);
}

#[test]
fn fold_over_is_refused_whatever_the_threshold() {
    // A fan of five triangles around vertex 4 whose collapse into vertex 0 would turn the
    // triangle (4, 1, 2) over: vertex 0 lies beyond the line through 1 and 2.
    let mesh = PolyMesh {
        positions: vec![
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.3, 0.3, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.3, -0.3, 0.0),
        ],
        faces: vec![
            vec![4, 0, 1],
            vec![4, 1, 2],
            vec![4, 2, 3],
            vec![4, 3, 5],
            vec![4, 5, 0],
        ],
        ..PolyMesh::default()
    };
    HalfEdgeMesh::build(&mesh).unwrap();
    let work = collapse::Work::new(&mesh);
    let plan = work.plan(4, 0, CollapseKind::Half).unwrap();
    assert!(
        work.cost(&plan).unwrap() < 0.0,
        "the collapse turns a face over"
    );
    let s = round_trip(&mesh, &options(1, CollapseKind::Half, 180.0));
    for face in &s.coarse.faces {
        let n = polygon_normal(face, |v| s.coarse.positions[v as usize]);
        assert!(n.z > 0.0);
    }
    // Random flat meshes: no face of any coarse mesh points down.
    for seed in 0..6 {
        let mesh = grid(10, 10, seed % 2 == 0, 0.8, 0.0, seed);
        let s = round_trip(&mesh, &options(1, CollapseKind::Full, 180.0));
        for face in &s.coarse.faces {
            let n = polygon_normal(face, |v| s.coarse.positions[v as usize]);
            assert!(n.z > 0.0, "seed {seed}");
        }
    }
}

#[test]
fn defects_are_refused_naming_the_element() {
    let base = grid(2, 2, false, 0.0, 0.0, 0);
    let mut flipped = base.clone();
    flipped.faces[3].reverse();
    let mut short = base.clone();
    short.faces[1] = vec![0, 1];
    let mut repeated = base.clone();
    repeated.faces[2] = vec![3, 4, 4, 7];
    let mut out_of_range = base.clone();
    out_of_range.faces[0][2] = 99;
    let mut fin = base.clone();
    fin.positions[4].x = f32::NAN;
    // A fin: a third quad on the grid edge 4-5 between faces 1 and 3.
    let mut fin_edge = base.clone();
    fin_edge.positions.push(Vec3::new(1.5, 1.0, 1.0));
    fin_edge.positions.push(Vec3::new(1.0, 1.0, 1.0));
    fin_edge.uvs.extend([Vec2::ZERO; 2]);
    fin_edge.faces.push(vec![4, 5, 9, 10]);
    // Two squares touching at one corner: a bow tie.
    let bow_tie = PolyMesh {
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
        ],
        faces: vec![vec![0, 1, 2, 3], vec![2, 4, 5, 6]],
        ..PolyMesh::default()
    };
    let mut short_normals = base.clone();
    short_normals.normals = vec![Vec3::Z; 3];
    let cases: Vec<(PolyMesh, &str)> = vec![
        (
            flipped,
            "face 1 and face 3 both run from vertex 5 to vertex 4: inconsistent orientation",
        ),
        (short, "face 1 has fewer than three vertices"),
        (repeated, "face 2 uses vertex 4 twice (degenerate face)"),
        (
            out_of_range,
            "face 0 refers to vertex 99, which does not exist",
        ),
        (fin, "vertex 4 has a non-finite position"),
        (
            fin_edge,
            "the edge from vertex 4 to vertex 5 is shared by 3 faces (face 1, face 3, face 4)",
        ),
        (
            bow_tie,
            "the faces around vertex 2 do not form one fan: non-manifold vertex",
        ),
        (
            short_normals,
            "the mesh has 3 normals, neither none nor one per vertex",
        ),
    ];
    for (mesh, expected) in cases {
        let err = crate::error::Error::from(
            simplify(&mesh, &options(1, CollapseKind::Full, 10.0)).unwrap_err(),
        );
        assert!(
            err.to_string().starts_with(expected),
            "{err} does not start with {expected}"
        );
    }
}

#[test]
fn attributes_follow_and_same_seed_same_result() {
    let mesh = torus(16, 8);
    let a = round_trip(&mesh, &options(40, CollapseKind::Full, 45.0));
    let b = simplify(&mesh, &options(40, CollapseKind::Full, 45.0)).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.coarse.normals.len(), a.coarse.vertex_count());
    assert!(a
        .coarse
        .normals
        .iter()
        .all(|n| (n.length() - 1.0).abs() < 1e-5));
    let c = simplify(
        &mesh,
        &SimplifyOptions {
            seed: 2,
            ..options(40, CollapseKind::Full, 45.0)
        },
    )
    .unwrap();
    assert_ne!(a.splits, c.splits);
}

#[test]
fn coarse_triangles_reach_the_count() {
    let mesh = grid(20, 20, true, 0.3, 2.0, 9).to_triangles();
    let coarse = coarse_triangles(&mesh, 100, 4).unwrap();
    coarse.validate().unwrap();
    assert!(
        coarse.triangle_count() <= 100,
        "{}",
        coarse.triangle_count()
    );
    assert!(coarse.triangle_count() >= 50);
    // Half-edge collapses: every coarse vertex is an input vertex.
    assert!(coarse.positions.iter().all(|p| mesh.positions.contains(p)));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn random_grids_rebuild_exactly(
        w in 1u32..9, h in 1u32..9, triangles: bool, jitter in 0.0f32..0.9,
        bump in 0.0f32..1.5, seed: u64, half: bool, degrees in 1.0f32..120.0,
        fraction in 0.01f32..1.0, target in 0usize..40,
    ) {
        let mesh = grid(w, h, triangles, jitter, bump, seed);
        let kind = if half { CollapseKind::Half } else { CollapseKind::Full };
        let o = SimplifyOptions {
            candidate_fraction: fraction,
            seed,
            ..options(target, kind, degrees)
        };
        let s = round_trip(&mesh, &o);
        prop_assert!(s.coarse.face_count() <= mesh.face_count());
        HalfEdgeMesh::build(&s.coarse).unwrap();
    }
}

/// Every built-in shape is a mesh the simplifier accepts, at coarse and fine tessellations,
/// so that a reflector's camera mesh (`camera_triangles = N`) or an LOD chain can be made of
/// any of them: the cylinder's caps once were rings of triangles touching at their rim
/// vertices (one centre vertex per segment), refused as non-manifold. Not a sphere (or the
/// walker's ellipsoids) of tessellation below 6: its two rings make the pole fans (one pole vertex per segment, for
/// the uvs) meet at each equator vertex in two fans, which the simplifier refuses by name.
#[test]
fn built_in_shapes_simplify() {
    use crate::scene::shapes;
    let sphere = shapes::sphere(1.0, 5);
    let refused = coarse_triangles(&sphere, sphere.triangles.len() / 2, 1).unwrap_err();
    assert!(
        refused.to_string().contains("non-manifold vertex"),
        "{refused}"
    );
    for n in [3, 4, 6, 11, 24] {
        let meshes = [
            ("sphere", shapes::sphere(1.0, n.max(6))),
            ("cylinder", shapes::cylinder(0.7, 1.5, n)),
            ("torus", shapes::torus(1.0, 0.35, n)),
            ("box", shapes::cuboid(Vec3::ONE)),
            ("plane", shapes::plane(1.0, 1.0, n)),
            ("walker", shapes::walker(1.8, n.max(6))),
            ("teapot", shapes::teapot(1.0, n)),
        ];
        for (name, mesh) in meshes {
            let faces = mesh.triangles.len();
            let coarse = coarse_triangles(&mesh, faces / 2, 1)
                .unwrap_or_else(|e| panic!("{name}, tessellation {n}: {e}"));
            assert!(coarse.triangles.len() < faces, "{name}, tessellation {n}");
        }
    }
}
