use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::{enters_root, stored_index, DisplacedTriangle, KeptBoxes, Node};
use crate::displace::{
    BaseVertex, Displacement, HeightField, HeightMap, MicroGrid, Procedural, Wave,
};
use crate::geometry::Ray;

/// A test case: base triangle, displacement, and the parameters of the rays aimed at it.
#[derive(Debug, Clone)]
struct Case {
    corners: [BaseVertex; 3],
    displacement: Displacement,
}

fn unit() -> impl Strategy<Value = f64> {
    -1.0..1.0f64
}

fn vec3() -> impl Strategy<Value = DVec3> {
    (unit(), unit(), unit()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

fn height_field() -> impl Strategy<Value = HeightField> {
    let map = (
        1u32..12,
        1u32..12,
        proptest::collection::vec(0.0..=1.0f32, 144),
    )
        .prop_map(|(w, h, values)| {
            let values = values[..(w * h) as usize].to_vec();
            HeightField::Map(HeightMap::from_values(w, h, values).unwrap())
        });
    let waves = (1i32..5, -4i32..4, 0.0..6.0f64).prop_map(|(m, n, phase)| {
        let waves = vec![
            Wave {
                amplitude: 1.0,
                frequency: [m, n],
                phase,
            },
            Wave {
                amplitude: 0.3,
                frequency: [n, -m],
                phase: 0.0,
            },
        ];
        HeightField::Procedural(Procedural::waves(waves).unwrap())
    });
    let bumps = (1u32..6, 1u32..6, 0.1..0.5f64)
        .prop_map(|(nu, nv, r)| HeightField::Procedural(Procedural::bumps([nu, nv], r).unwrap()));
    prop_oneof![2 => map, 1 => waves, 1 => bumps]
}

fn case() -> impl Strategy<Value = Case> {
    case_in(0..=5)
}

/// A case at a subdivision level in `levels`.
fn case_in(levels: std::ops::RangeInclusive<u32>) -> impl Strategy<Value = Case> {
    (
        [vec3(), vec3(), vec3()],
        [vec3(), vec3(), vec3()],
        [(unit(), unit()), (unit(), unit()), (unit(), unit())],
        height_field(),
        -0.6..0.6f64,
        levels,
    )
        .prop_filter_map(
            "degenerate base triangle",
            |(p, bend, uv, height, scale, level)| {
                let face = (p[1] - p[0]).cross(p[2] - p[0]);
                (face.length() > 0.05).then(|| {
                    let n = face.normalize();
                    let corners = [0, 1, 2].map(|k| BaseVertex {
                        position: p[k],
                        normal: (n + 0.6 * bend[k]).normalize_or(n),
                        uv: DVec2::new(uv[k].0, uv[k].1) * 1.5,
                    });
                    Case {
                        corners,
                        displacement: Displacement::new(height, scale, 1.0, level).unwrap(),
                    }
                })
            },
        )
}

/// The same hit, bit for bit, from the hierarchy (computing every node box per ray, with
/// the top levels' boxes stored as the prepared scene stores them, and with the displaced
/// micro-vertices stored too up to level 5) and from testing every micro-triangle.
fn check(case: &Case, grid: &MicroGrid, ray: &Ray) -> Result<(), TestCaseError> {
    let computed = DisplacedTriangle::new(case.corners, &case.displacement);
    let KeptBoxes {
        boxes: exact,
        points,
        ..
    } = computed.exact_boxes();
    let conservative = computed.conservative_boxes();
    let brute = grid.intersect(ray);
    prop_assert_eq!(computed.intersect(ray), brute, "ray {:?}", ray);
    let variants: [(&[_], &[_], &str); 3] = [
        (&exact, &[], "exact"),
        (&exact, &points, "exact with micro-vertices"),
        (&conservative, &[], "conservative"),
    ];
    for (boxes, points, kind) in variants {
        let stored = DisplacedTriangle::with_boxes(
            case.corners,
            &case.displacement,
            computed.frame(),
            boxes,
            points,
        );
        if kind == "exact with micro-vertices" {
            // Kept up to level 5, and then used.
            let level = case.displacement.level();
            prop_assert_eq!(stored.points.is_empty(), level > 5, "level {}", level);
        }
        prop_assert_eq!(
            stored.intersect(ray),
            brute,
            "{} boxes, ray {:?}",
            kind,
            ray
        );
        // The any-hit search (shadow rays) finds a hit exactly when there is one, and no
        // nearer one than the nearest.
        let any = enters_root(&computed.frame(), &boxes[0], ray)
            .and_then(|entry| stored.intersect_entered(ray, &entry, true));
        prop_assert_eq!(
            any.is_some(),
            brute.is_some(),
            "{} any, ray {:?}",
            kind,
            ray
        );
        if let (Some(any), Some(brute)) = (any, brute) {
            prop_assert!(
                any.t >= brute.t && any.t <= ray.t_max,
                "{} any, ray {:?}",
                kind,
                ray
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// Rays aimed at random points of the displaced surface's shell, rays through
    /// micro-vertices, grazing rays and rays along micro-edges, from random origins.
    #[test]
    fn same_hits_as_brute_force(
        case in case(),
        origins in proptest::collection::vec(vec3(), 8),
        weights in proptest::collection::vec((0.0..1.0f64, 0.0..1.0f64, -1.2..0.2f64), 8),
        picks in proptest::collection::vec((0u32..1024, 0u32..1024), 4),
    ) {
        let grid = MicroGrid::new(&case.corners, &case.displacement);
        let triangles: Vec<_> = grid.triangles().collect();
        let [a, b, c] = case.corners.map(|v| v.position);
        let normal = (b - a).cross(c - a).normalize();
        let scale = case.displacement_scale();
        for (origin, &(s, t, depth)) in origins.iter().zip(&weights) {
            // A point of the base triangle, pushed into the displacement shell.
            let (s, t) = if s + t > 1.0 { (1.0 - s, 1.0 - t) } else { (s, t) };
            let target = a + s * (b - a) + t * (c - a) + normal * depth * scale;
            let from = target + *origin * 3.0;
            check(&case, &grid, &Ray::new(from, target - from))?;
            // Grazing: nearly in the base plane.
            let along = (b - a).normalize();
            let grazing = along + normal * 1e-3 * origin.x;
            check(&case, &grid, &Ray::new(target - grazing * 2.0, grazing))?;
            // With a clipped interval.
            let clipped = Ray { t_min: 0.9, t_max: 1.05, ..Ray::new(from, target - from) };
            check(&case, &grid, &clipped)?;
        }
        for &(k, e) in &picks {
            let tri = triangles[k as usize % triangles.len()];
            let p = grid.positions(tri);
            let (p0, p1) = (p[e as usize % 3], p[(e as usize + 1) % 3]);
            // Through a micro-vertex, and exactly along a micro-edge (shared by two
            // micro-triangles, or a base edge), from outside and from on it.
            let from = p0 + origins[0] * 2.0;
            check(&case, &grid, &Ray::new(from, p0 - from))?;
            check(&case, &grid, &Ray::new(p0 - (p1 - p0), p1 - p0))?;
            check(&case, &grid, &Ray::new((p0 + p1) * 0.5, p1 - p0))?;
            // Through an edge's midpoint, crossing it.
            let mid = (p0 + p1) * 0.5;
            check(&case, &grid, &Ray::new(mid + normal + origins[1] * 0.5, -(normal + origins[1] * 0.5)))?;
        }
    }

    /// Every kept exact box holds the micro-triangles of its node (in the triangle's frame)
    /// and is their box up to the f32 rounding: so the test fails for a box that is only
    /// conservative. The world bounds hold every micro-vertex undisplaced, displaced and
    /// half displaced. The kept micro-vertices (up to level 5) are the displaced ones, bit
    /// for bit, each once at its place.
    #[test]
    fn exact_boxes_hold_their_micro_triangles_and_no_more(case in case_in(0..=6)) {
        let grid = MicroGrid::new(&case.corners, &case.displacement);
        let triangle = DisplacedTriangle::new(case.corners, &case.displacement);
        let KeptBoxes { boxes, bounds: [w_lo, w_hi], points } = triangle.exact_boxes();
        let depth = case.displacement.level().saturating_sub(1).min(4);
        prop_assert_eq!(boxes.len(), ((1usize << (2 * (depth + 1))) - 1) / 3);
        // The nodes in level order, down to the deepest kept depth.
        let mut nodes = vec![triangle.root()];
        let mut start = 0;
        while nodes.len() < boxes.len() {
            let next: Vec<Node> = nodes[start..].iter().flat_map(Node::children).collect();
            start = nodes.len();
            nodes.extend(next);
        }
        for (node, &[lo, hi]) in nodes.iter().zip(&boxes) {
            let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
            let mut found = [DVec3::INFINITY, DVec3::NEG_INFINITY];
            for micro in grid.triangles() {
                let centroid = [0, 1].map(|k| micro.vertices().iter().map(|g| g[k] as i64).sum::<i64>());
                if !node.holds(centroid) {
                    continue;
                }
                for p in grid.positions(micro).map(|p| triangle.frame.local(p)) {
                    prop_assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "{} outside [{}, {}]", p, lo, hi);
                    found = [found[0].min(p), found[1].max(p)];
                }
            }
            let tolerance = 1e-6 * (1.0 + found[0].abs().max(found[1].abs()).max_element());
            prop_assert!(
                (found[0] - lo).max_element() <= tolerance && (hi - found[1]).max_element() <= tolerance,
                "[{}, {}] wider than its micro-triangles' [{}, {}]", lo, hi, found[0], found[1]
            );
        }
        let half = case.displacement.with_fraction(0.5);
        let n = 1u32 << case.displacement.level();
        let kept = case.displacement.level() <= 5;
        prop_assert_eq!(points.len(), if kept { ((n + 1) * (n + 2) / 2) as usize } else { 0 });
        for i in 0..=n {
            for j in 0..=n - i {
                let vertex = grid.vertex([i, j]);
                for p in [vertex.position, grid.displaced([i, j]), half.displace(&vertex)] {
                    prop_assert!(p.cmpge(w_lo).all() && p.cmple(w_hi).all(), "{} outside [{}, {}]", p, w_lo, w_hi);
                }
                if kept {
                    prop_assert_eq!(points[stored_index(n, [i, j])], grid.displaced([i, j]));
                }
            }
        }
        // Micro-triangle positions read from the kept micro-vertices, and descended to
        // without them, are the brute force's.
        let stored = DisplacedTriangle::with_boxes(case.corners, &case.displacement, triangle.frame(), &boxes, &points);
        for micro in grid.triangles() {
            prop_assert_eq!(stored.positions(micro), grid.positions(micro));
            prop_assert_eq!(triangle.positions(micro), grid.positions(micro));
        }
    }

    /// Every micro-vertex, undisplaced, displaced and half displaced, lies inside the
    /// triangle's conservative world bounds (the shell box above the exact levels), also
    /// where the triangle's heights stay below the map's maximum.
    #[test]
    fn bounds_contain_every_micro_vertex(case in case()) {
        let grid = MicroGrid::new(&case.corners, &case.displacement);
        let [lo, hi] = DisplacedTriangle::new(case.corners, &case.displacement).bounds();
        let half = case.displacement.with_fraction(0.5);
        let n = 1u32 << case.displacement.level();
        for i in 0..=n {
            for j in 0..=n - i {
                let vertex = grid.vertex([i, j]);
                for p in [vertex.position, grid.displaced([i, j]), half.displace(&vertex)] {
                    prop_assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "{} outside [{}, {}]", p, lo, hi);
                }
            }
        }
    }
}

impl Case {
    /// The largest displacement magnitude (|S| with h - h_max in [-1, 0]).
    fn displacement_scale(&self) -> f64 {
        let [lo, _] = self.displacement.offset_range([0.0, 0.0]);
        lo.abs().max(1e-3)
    }
}

#[test]
fn misses_and_bad_rays() {
    let height = HeightField::Procedural(Procedural::bumps([3, 3], 0.4).unwrap());
    let d = Displacement::new(height, 0.1, 1.0, 4).unwrap();
    let v = |p: [f64; 3], uv: [f64; 2]| BaseVertex {
        position: DVec3::from(p),
        normal: DVec3::Z,
        uv: DVec2::from(uv),
    };
    let tri = DisplacedTriangle::new(
        [
            v([0.0; 3], [0.0, 0.0]),
            v([1.0, 0.0, 0.0], [1.0, 0.0]),
            v([0.0, 1.0, 0.0], [0.0, 1.0]),
        ],
        &d,
    );
    let down = DVec3::NEG_Z;
    assert!(tri
        .intersect(&Ray::new(DVec3::new(2.0, 2.0, 1.0), down))
        .is_none());
    assert!(tri
        .intersect(&Ray::new(DVec3::new(0.2, 0.2, 1.0), DVec3::ZERO))
        .is_none());
    assert!(tri
        .intersect(&Ray::new(DVec3::new(f64::NAN, 0.2, 1.0), down))
        .is_none());
    // Over a bump's centre (h = h_max: not displaced) and between bumps (h = 0: 0.1 down).
    let centre = tri
        .intersect(&Ray::new(DVec3::new(1.0 / 6.0, 1.0 / 6.0, 1.0), down))
        .unwrap();
    assert!((centre.t - 1.0).abs() < 0.05, "{centre:?}");
    let low = tri
        .intersect(&Ray::new(DVec3::new(1.0 / 3.0, 1.0 / 3.0, 1.0), down))
        .unwrap();
    assert!((low.t - 1.1).abs() < 1e-3, "{low:?}");
    // A degenerate base triangle still traces (world axes), like the brute force.
    let flat = [
        v([0.0; 3], [0.0, 0.0]),
        v([1.0, 0.0, 0.0], [1.0, 0.0]),
        v([2.0, 0.0, 0.0], [0.0, 1.0]),
    ];
    let ray = Ray::new(DVec3::new(0.5, 1.0, 1.0), DVec3::new(0.0, -1.0, -1.0));
    assert_eq!(
        DisplacedTriangle::new(flat, &d).intersect(&ray),
        MicroGrid::new(&flat, &d).intersect(&ray)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Level 6 (4,096 micro-triangles): the kept exact boxes reach depth 4, and the nodes
    /// below them are bounded from their displaced micro-vertices per ray
    /// (`visit_leaf_parents`); same hits as brute force.
    #[test]
    fn same_hits_as_brute_force_at_level_6(
        case in case_in(6..=6),
        origins in proptest::collection::vec(vec3(), 12),
        weights in proptest::collection::vec((0.0..1.0f64, 0.0..1.0f64, -1.2..0.2f64), 12),
    ) {
        let grid = MicroGrid::new(&case.corners, &case.displacement);
        let [a, b, c] = case.corners.map(|v| v.position);
        let normal = (b - a).cross(c - a).normalize();
        let scale = case.displacement_scale();
        for (origin, &(s, t, depth)) in origins.iter().zip(&weights) {
            let (s, t) = if s + t > 1.0 { (1.0 - s, 1.0 - t) } else { (s, t) };
            let target = a + s * (b - a) + t * (c - a) + normal * depth * scale;
            let from = target + *origin * 3.0;
            check(&case, &grid, &Ray::new(from, target - from))?;
        }
    }
}

/// Rays along the frame's axes (zero direction components: the kept boxes' f64 test, the
/// f32 one cannot hold them) and oblique ones (the f32 test) through a triangle whose frame
/// is the world's: the same hits as brute force, with exact and conservative kept boxes.
#[test]
fn axis_parallel_rays_through_kept_boxes() {
    let waves = vec![
        Wave {
            amplitude: 1.0,
            frequency: [3, 1],
            phase: 0.5,
        },
        Wave {
            amplitude: 0.4,
            frequency: [-2, 5],
            phase: 0.0,
        },
    ];
    let height = HeightField::Procedural(Procedural::waves(waves).unwrap());
    let v = |p: [f64; 3], n: [f64; 3], uv: [f64; 2]| BaseVertex {
        position: DVec3::from(p),
        normal: DVec3::from(n).normalize(),
        uv: DVec2::from(uv),
    };
    let corners = [
        v([0.0; 3], [0.1, 0.0, 1.0], [0.0, 0.0]),
        v([1.0, 0.0, 0.0], [0.0, 0.1, 1.0], [1.0, 0.0]),
        v([0.0, 1.0, 0.0], [-0.1, 0.0, 1.0], [0.0, 1.0]),
    ];
    for level in [3, 5] {
        let case = Case {
            corners,
            displacement: Displacement::new(height.clone(), 0.1, 1.0, level).unwrap(),
        };
        let grid = MicroGrid::new(&case.corners, &case.displacement);
        for i in 0..24 {
            for j in 0..24 - i {
                let (x, y) = ((i as f64 + 0.3) / 24.0, (j as f64 + 0.6) / 24.0);
                let from = DVec3::new(x, y, 1.0);
                for direction in [DVec3::NEG_Z, DVec3::new(0.05, -0.02, -1.0)] {
                    check(&case, &grid, &Ray::new(from, direction)).unwrap();
                }
                let side = DVec3::new(-1.0, y, -0.05 * x);
                check(&case, &grid, &Ray::new(side, DVec3::X)).unwrap();
            }
        }
    }
}

/// A base triangle whose heights all stay below the map's maximum (the bright texel lies
/// elsewhere): its conservative box sits below the base plane, yet [`DisplacedTriangle::
/// bounds`] must still hold the undisplaced triangle, which the transition system traces.
#[test]
fn bounds_hold_the_undisplaced_triangle_below_the_maps_maximum() {
    // 16 x 16 texels, the bright one in row 2, column 10; the triangle's uvs reach columns
    // 1 to 5 and rows 10 to 14 (v = 1 the top row), apart at every level of the pyramid.
    let mut values = vec![0.0f32; 256];
    values[2 * 16 + 10] = 1.0;
    let map = HeightField::Map(HeightMap::from_values(16, 16, values).unwrap());
    let d = Displacement::new(map, 0.5, 1.0, 7).unwrap();
    let v = |p: [f64; 3], uv: [f64; 2]| BaseVertex {
        position: DVec3::from(p),
        normal: DVec3::Z,
        uv: DVec2::from(uv),
    };
    let corners = [
        v([0.0; 3], [0.1, 0.1]),
        v([1.0, 0.0, 0.0], [0.3, 0.1]),
        v([0.0, 1.0, 0.0], [0.1, 0.3]),
    ];
    let triangle = DisplacedTriangle::new(corners, &d);
    let [lo, hi] = triangle.bounds();
    let root = triangle.node_box(&triangle.root());
    assert!(
        root[1].z < 0.0,
        "the root's conservative box is below the base: {root:?}"
    );
    for c in &corners {
        let p = c.position;
        assert!(
            p.cmpge(lo).all() && p.cmple(hi).all(),
            "{p} outside [{lo}, {hi}]"
        );
    }
}
