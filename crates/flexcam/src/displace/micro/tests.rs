use std::collections::HashMap;

use glam::{DVec2, DVec3};

use super::{BaseVertex, Displacement, MicroGrid, MicroTriangle};
use crate::displace::{HeightField, HeightMap, Procedural, Wave};
use crate::geometry::{intersect_triangle, Ray};

fn vertex(p: [f64; 3], n: [f64; 3], uv: [f64; 2]) -> BaseVertex {
    BaseVertex {
        position: DVec3::from(p),
        normal: DVec3::from(n).normalize(),
        uv: DVec2::from(uv),
    }
}

fn corners() -> [BaseVertex; 3] {
    [
        vertex([0.0, 0.0, 0.0], [0.1, -0.2, 1.0], [0.1, 0.2]),
        vertex([1.0, 0.1, 0.2], [0.3, 0.1, 1.0], [0.9, 0.25]),
        vertex([0.2, 1.0, -0.1], [-0.2, 0.3, 1.0], [0.3, 0.8]),
    ]
}

fn waves(level: u32) -> Displacement {
    let wave = Wave {
        amplitude: 1.0,
        frequency: [3, 2],
        phase: 0.5,
    };
    let height = HeightField::Procedural(Procedural::waves(vec![wave]).unwrap());
    Displacement::new(height, 0.2, 1.0, level).unwrap()
}

/// Algorithm 6.12's recursion, recording every micro-vertex it computes by grid point.
fn recurse(
    v: [BaseVertex; 3],
    g: [[u32; 2]; 3],
    level: u32,
    seen: &mut HashMap<[u32; 2], Vec<BaseVertex>>,
) {
    for k in 0..3 {
        seen.entry(g[k]).or_default().push(v[k]);
    }
    if level == 0 {
        return;
    }
    let [a, b, c] = v;
    let (ab, bc, ac) = (a.midpoint(b), b.midpoint(c), a.midpoint(c));
    let mid = |p: [u32; 2], q: [u32; 2]| [(p[0] + q[0]) / 2, (p[1] + q[1]) / 2];
    let (gab, gbc, gac) = (mid(g[0], g[1]), mid(g[1], g[2]), mid(g[0], g[2]));
    recurse([a, ab, ac], [g[0], gab, gac], level - 1, seen);
    recurse([ab, b, bc], [gab, g[1], gbc], level - 1, seen);
    recurse([ac, bc, c], [gac, gbc, g[2]], level - 1, seen);
    recurse([ac, ab, bc], [gac, gab, gbc], level - 1, seen);
}

#[test]
fn grid_matches_the_recursion_bit_for_bit_at_every_vertex() {
    for level in 0..=5 {
        let d = waves(level);
        let grid = MicroGrid::new(&corners(), &d);
        let n = 1 << level;
        let mut seen = HashMap::new();
        recurse(corners(), [[0, 0], [n, 0], [0, n]], level, &mut seen);
        assert_eq!(seen.len(), ((n + 1) * (n + 2) / 2) as usize);
        for (g, values) in seen {
            for v in values {
                assert_eq!(v, grid.vertex(g), "level {level} at {g:?}");
            }
        }
    }
}

#[test]
fn midpoints_are_the_means_with_normalised_normal() {
    let [a, b, _] = corners();
    let m = a.midpoint(b);
    assert_eq!(m, b.midpoint(a));
    assert_eq!(m.position, (a.position + b.position) / 2.0);
    assert_eq!(m.uv, (a.uv + b.uv) / 2.0);
    assert!((m.normal - (a.normal + b.normal).normalize()).length() < 1e-15);
    let opposite = BaseVertex {
        normal: -a.normal,
        ..a
    };
    assert_eq!(a.midpoint(opposite).normal, DVec3::ZERO);
}

#[test]
fn neighbouring_base_triangles_share_their_edge_micro_vertices_exactly() {
    // (a, b, c) and (b, a, d) share the edge a-b, met in opposite directions.
    let [a, b, c] = corners();
    let d = vertex([0.9, -0.8, 0.3], [0.0, -0.3, 1.0], [0.7, -0.4]);
    let disp = waves(5);
    let first = MicroGrid::new(&[a, b, c], &disp);
    let second = MicroGrid::new(&[b, a, d], &disp);
    // Along a-b: first grid (i, 0) from a; second grid (n - i, 0) from b... the weights of
    // (b, a) are (i/n) for a in the second grid, so its point (i, 0) is first's (n - i, 0).
    let n = 32;
    for i in 0..=n {
        assert_eq!(
            first.displaced([i, 0]),
            second.displaced([n - i, 0]),
            "at {i}"
        );
        assert_eq!(first.vertex([i, 0]), second.vertex([n - i, 0]));
    }
}

#[test]
fn displaced_vertex_formula_and_outer_hull() {
    let map = HeightMap::from_values(2, 1, vec![0.25, 1.0]).unwrap();
    let d = Displacement::new(HeightField::Map(map), 2.0, 0.5, 0).unwrap();
    let v = vertex([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], [0.25, 0.5]);
    // h = 0.25 at the left texel's centre, h_max = 1: P + N * 2 * (0.25 - 1) * 0.5.
    assert_eq!(d.displace(&v), DVec3::new(1.0, 2.0, 3.0 - 0.75));
    let top = BaseVertex {
        uv: DVec2::new(0.75, 0.5),
        ..v
    };
    assert_eq!(d.displace(&top), top.position);
    for &h in &[0.0f64, 0.3, 1.0] {
        let [lo, hi] = d.offset_range([h, h]);
        let exact = 2.0 * (h - 1.0) * 0.5;
        assert!(lo <= exact && exact <= hi && hi <= 1e-11);
    }
}

#[test]
fn triangles_tile_the_base_triangle_and_brute_force_hits_the_flat_case() {
    let flat = Displacement::new(
        HeightField::Map(HeightMap::from_values(1, 1, vec![0.5]).unwrap()),
        1.0,
        1.0,
        3,
    )
    .unwrap();
    let base = corners();
    let grid = MicroGrid::new(&base, &flat);
    let triangles: Vec<MicroTriangle> = grid.triangles().collect();
    assert_eq!(triangles.len(), 64);
    let area = |[a, b, c]: [DVec3; 3]| (b - a).cross(c - a).length() / 2.0;
    let total: f64 = triangles.iter().map(|&t| area(grid.positions(t))).sum();
    let base_area = area(base.map(|v| v.position));
    assert!((total - base_area).abs() < 1e-12 * base_area);
    // Zero displacement (h = h_max): the micro-triangles are the base triangle.
    let ray = Ray::new(DVec3::new(0.4, 0.3, 2.0), DVec3::new(0.05, 0.02, -1.0));
    let want = intersect_triangle(ray.origin, ray.direction, base.map(|v| v.position)).unwrap();
    let hit = grid.intersect(&ray).unwrap();
    assert!((hit.t - want.t).abs() < 1e-12);
    let behind = Ray {
        t_max: want.t * 0.9,
        ..ray
    };
    assert!(grid.intersect(&behind).is_none());
}

#[test]
fn bad_displacement_parameters_are_refused() {
    let h = || HeightField::Procedural(Procedural::bumps([2, 2], 0.3).unwrap());
    assert!(Displacement::new(h(), f64::NAN, 1.0, 2).is_err());
    assert!(Displacement::new(h(), 1.0, f64::INFINITY, 2).is_err());
    assert!(Displacement::new(h(), 1.0, 1.0, 17).is_err());
    assert!(Displacement::new(h(), -1.0, 0.5, 16).is_ok());
}
