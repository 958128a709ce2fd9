use std::path::Path;

use glam::{DVec2, DVec3};

use super::*;
use crate::displace::intersect::kept_point_bytes;
use crate::displace::{MicroGrid, MicroTriangle};
use crate::projection::Projection;
use crate::render::shading::Normals;
use crate::render::{render, Frame, Method, PreparedScene, RenderOptions, Shading};
use crate::scene::file::parse;

/// Two displaced tori (waves and bumps) crossing each other, and an undisplaced box that
/// cuts into one of them.
const SCENE: &str = r#"
[image]
width = 48
height = 40

[projection]
type = "perspective"
position = [0.0, 2.5, 3.0]
look_at = [0.0, 0.0, 0.0]
fov = 60.0

[[object]]
name = "waves"
shape = "torus"
size = [1.0, 0.35]
tessellation = 6
displacement = { procedural = "waves", waves = [[1.0, 5, 0, 0.0], [0.5, 2, 3, 1.0]], scale = 0.2, level = 3 }

[[object]]
name = "bumps"
shape = "torus"
size = [0.8, 0.3]
tessellation = 5
rotate = [90.0, 0.0, 0.0]
translate = [0.7, 0.0, 0.0]
displacement = { procedural = "bumps", cells = [6, 3], radius = 0.45, scale = 0.15, level = 2, fraction = 0.7 }

[[object]]
name = "box"
shape = "box"
size = [0.5, 0.5, 0.5]
translate = [-0.9, 0.2, 0.3]
"#;

fn prepared() -> PreparedScene {
    PreparedScene::new(&parse(SCENE, Path::new("displaced-test.toml")).unwrap())
}

/// Deterministic rays from around the scene through points near it.
fn rays() -> impl Iterator<Item = Ray> {
    let mut x = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..3000).map(move |_| {
        let mut point = || DVec3::new(next(), next(), next()) * 2.0 - 1.0;
        let origin = point() * 4.0;
        let target = point() * 1.3;
        Ray::new(origin, target - origin)
    })
}

/// The nearest hit by testing every micro-triangle of every displaced base triangle, and
/// every triangle of the other objects: (t, object, base triangle, base barycentrics).
fn brute_force(prepared: &PreparedScene, ray: &Ray) -> Option<(f64, usize, usize, DVec2)> {
    let scene = prepared.scene();
    let mut best: Option<(f64, usize, usize, DVec2)> = None;
    let mut offer = |hit: (f64, usize, usize, DVec2)| {
        if best.is_none_or(|b| hit.0 < b.0) {
            best = Some(hit);
        }
    };
    for (o, object) in scene.objects.iter().enumerate() {
        let Some(spec) = &object.displacement else {
            let mesh = &object.mesh;
            for (k, t) in mesh.triangles.iter().enumerate() {
                let v = t.map(|i| mesh.positions[i as usize].as_dvec3());
                if let Some(hit) = crate::geometry::intersect_triangle(ray.origin, ray.direction, v)
                {
                    offer((hit.t, o, k, hit.barycentric));
                }
            }
            continue;
        };
        let d = Displacement::from_spec(spec);
        for k in 0..object.mesh.triangles.len() {
            let grid = MicroGrid::new(&base_corners(&object.mesh, k), &d);
            if let Some(hit) = grid.intersect(ray) {
                let bary = hit.triangle.base_barycentric(d.level(), hit.barycentric);
                offer((hit.t, o, k, bary));
            }
        }
    }
    best
}

/// The flat ray-cast frame of `prepared` through `projection`.
fn flat_frame(prepared: &PreparedScene, projection: &dyn Projection) -> Frame {
    let options = RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    render(prepared, projection, &options).unwrap().frame
}

#[test]
fn prepared_scene_hits_exactly_the_micro_triangles_brute_force_finds() {
    let prepared = prepared();
    let set = prepared.displaced.as_ref().unwrap();
    assert_eq!(set.len(), 2 * 36 + 2 * 25);
    let (mut displaced, mut plain) = (0, 0);
    for ray in rays() {
        let want = brute_force(&prepared, &ray);
        let got = prepared.intersect(&ray);
        match (want, got) {
            (None, None) => {}
            (Some((t, object, triangle, bary)), Some(hit)) => {
                assert_eq!((hit.object, hit.triangle), (object, triangle), "{ray:?}");
                if prepared.is_displaced(object) {
                    displaced += 1;
                    // The same f64 micro-triangle test: bit for bit.
                    assert_eq!(hit.t, t, "{ray:?}");
                    assert_eq!(hit.barycentric, bary.as_vec2(), "{ray:?}");
                } else {
                    plain += 1;
                    assert!((hit.t - t).abs() < 1e-5 * t.max(1.0), "{ray:?}");
                }
                // The shadow-ray query agrees with the closest-hit query.
                let segment = Ray {
                    t_max: t * 1.0001,
                    ..ray
                };
                assert!(prepared.occluded(&segment));
                // Nothing lies before the nearest hit: the any-hit search finds nothing there.
                let before = Ray {
                    t_max: t * 0.9999,
                    ..ray
                };
                assert!(!prepared.occluded(&before), "{ray:?}");
            }
            (want, got) => panic!("{ray:?}: brute force {want:?}, prepared {got:?}"),
        }
        if want.is_none() {
            assert!(!prepared.occluded(&ray), "{ray:?}");
        }
    }
    assert!(displaced > 300 && plain > 20, "{displaced} {plain}");
}

#[test]
fn a_point_budget_keeps_micro_vertices_in_scene_order_and_the_same_hits() {
    let scene = parse(SCENE, Path::new("displaced-test.toml")).unwrap();
    let full = DisplacedSet::with_point_budget(&scene, usize::MAX).unwrap();
    // "waves" (72 base triangles at level 3) keeps 40, "bumps" (50 at level 2) none; a
    // budget of 0 keeps none.
    let budget = 40 * kept_point_bytes(3) + kept_point_bytes(2) - 1;
    let capped = DisplacedSet::with_point_budget(&scene, budget).unwrap();
    let none = DisplacedSet::with_point_budget(&scene, 0).unwrap();
    let kept = |set: &DisplacedSet, object: u32| {
        let items = set.items.iter().filter(|item| item.object == object);
        items.filter(|item| !item.points.is_empty()).count()
    };
    assert_eq!([kept(&full, 0), kept(&full, 1)], [72, 50]);
    assert_eq!([kept(&capped, 0), kept(&capped, 1)], [40, 0]);
    assert_eq!([kept(&none, 0), kept(&none, 1)], [0, 0]);
    let key = |hit: Option<DisplacedHit>| hit.map(|h| (h.object, h.triangle, h.micro));
    let mut hits = 0;
    for ray in rays() {
        let want = key(full.closest(&scene, &ray, f64::INFINITY, false));
        for set in [&capped, &none] {
            assert_eq!(
                key(set.closest(&scene, &ray, f64::INFINITY, false)),
                want,
                "{ray:?}"
            );
            let any = set.closest(&scene, &ray, f64::INFINITY, true);
            assert_eq!(any.is_some(), want.is_some(), "{ray:?}");
        }
        hits += usize::from(want.is_some());
    }
    assert!(hits > 300, "{hits}");
}

#[test]
fn lit_normals_are_the_micro_triangle_faces() {
    let prepared = prepared();
    let mut checked = 0;
    for ray in rays().take(500) {
        let Some(hit) = prepared.intersect(&ray) else {
            continue;
        };
        let Some(face_normal) = prepared.displaced_face_normal(&hit) else {
            continue;
        };
        let normals = Normals::of_face(face_normal, ray.direction.as_vec3());
        let object = &prepared.scene().objects[hit.object];
        let d = Displacement::from_spec(object.displacement.as_deref().unwrap());
        let grid = MicroGrid::new(&base_corners(&object.mesh, hit.triangle), &d);
        let micro = grid.intersect(&ray).unwrap();
        let [a, b, c] = grid.positions(micro.triangle);
        let face = (b - a).cross(c - a).normalize().as_vec3();
        // Away from micro-edges the micro-triangle found from the base barycentrics is the
        // one hit; on an edge it may be the neighbour, so compare where it is the same one.
        if MicroTriangle::containing(d.level(), hit.barycentric.as_dvec2()) == micro.triangle {
            assert!(normals.geometric.dot(face).abs() > 1.0 - 1e-5, "{ray:?}");
            assert!(normals.geometric.dot(ray.direction.as_vec3()) <= 0.0);
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked}");
}

#[test]
fn methods_that_draw_base_triangles_refuse_displaced_objects() {
    let prepared = prepared();
    let projection = prepared.scene().projection.build(16, 16).unwrap();
    for method in [Method::Raster, Method::Trilinear] {
        let options = RenderOptions {
            method,
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        let e = render(&prepared, projection.as_ref(), &options).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "object \"waves\" is displaced, and displaced objects render with --method \
                 raycast only (method {method} would draw the undisplaced triangles)"
            )
        );
    }
    let frame = flat_frame(&prepared, projection.as_ref());
    assert!(frame.ids.contains(&1) && frame.ids.contains(&2) && frame.ids.contains(&3));
}

/// Polyline projectors (with the tile culling that tests whole tiles against the scene)
/// see the displaced micro-geometry: every pixel's id is that of a brute-force search of the
/// pixel's segments in order, every micro-triangle tested.
#[test]
fn polyline_projectors_see_the_micro_geometry() {
    use crate::projection::Projector;
    use crate::render::raycast::pieces::polyline_segment;

    let text = r#"
[image]
width = 48
height = 36

[projection]
type = "flexible"
preset = "ortho_near_persp_far"
position = [0.0, 5.5, 7.0]
look_at = [0.0, 0.4, 0.0]
fov = 50.0
transition = 8.0
clip = [0.0, 30.0]
style = "piecewise"

[[object]]
shape = "torus"
size = [1.5, 0.5]
tessellation = 7
translate = [0.0, 0.5, 0.0]
displacement = { procedural = "waves", waves = [[1.0, 8, 0, 0.0], [1.0, 0, 4, 0.0]], scale = 0.3, level = 2 }
"#;
    let scene = parse(text, Path::new("poly.toml")).unwrap();
    let prepared = PreparedScene::new(&scene);
    let projection = scene.projection.build(48, 36).unwrap();
    let frame = flat_frame(&prepared, projection.as_ref());
    let object = &scene.objects[0];
    let d = Displacement::from_spec(object.displacement.as_deref().unwrap());
    let grids: Vec<MicroGrid> = (0..object.mesh.triangles.len())
        .map(|k| MicroGrid::new(&base_corners(&object.mesh, k), &d))
        .collect();
    let mut hits = 0;
    for y in 0..36u32 {
        for x in 0..48u32 {
            let pixel = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let Some(Projector::Polyline(points)) = projection.projector(pixel) else {
                panic!("not a polyline at {pixel}");
            };
            let hit = (0..points.len() - 1).any(|k| {
                let segment = polyline_segment(&points, k);
                grids.iter().any(|g| g.intersect(&segment).is_some())
            });
            hits += hit as u32;
            assert_eq!(
                frame.ids[(y * 48 + x) as usize],
                hit as u32,
                "pixel ({x}, {y})"
            );
        }
    }
    assert!(hits > 100, "{hits}");
}

#[test]
fn levels_of_detail_coarsen_within_one_shared_bound() {
    // The test scene with its first torus fine enough to simplify.
    let text = SCENE.replacen("tessellation = 6", "tessellation = 32", 1);
    let prepared = PreparedScene::new(&parse(&text, Path::new("lod-test.toml")).unwrap());
    let set = prepared.displaced.as_ref().unwrap();
    let data = set.transition_data(&prepared.scene);
    // Built once: a second call finds the same data.
    assert!(std::ptr::eq(data, set.transition_data(&prepared.scene)));
    let lods = &data.lods;
    assert!(lods.failures.is_empty(), "{:?}", lods.failures);
    let sizes: Vec<usize> = lods
        .levels
        .iter()
        .map(|l| l.scene.objects[0].mesh.triangles.len())
        .collect();
    assert_eq!(sizes[0], prepared.scene.objects[0].mesh.triangles.len());
    assert!(sizes.windows(2).all(|w| w[1] < w[0]), "{sizes:?}");
    assert!(sizes[4] * 100 <= sizes[0] * 21, "{sizes:?}");
    let deviations = lods.deviations(0);
    assert!(deviations[0] < 1e-12);
    assert!(
        deviations.windows(2).all(|w| w[1] >= w[0]),
        "{deviations:?}"
    );
    assert!(deviations[4] > 0.0);
    // Every level's shells, and the detailed mesh undisplaced and displaced, are inside the
    // shared bound.
    let [lo, hi] = lods.bound(0).unwrap();
    let inside = |p: DVec3| p.cmpge(lo).all() && p.cmple(hi).all();
    for level in &lods.levels {
        let [a, b] = level.set.object_bound(0).unwrap();
        assert!(inside(a) && inside(b));
    }
    let mesh = &prepared.scene.objects[0].mesh;
    let displacement = set.displacement(0).unwrap();
    for triangle in 0..mesh.triangles.len() {
        for v in crate::displace::base_corners(mesh, triangle) {
            assert!(inside(v.position) && inside(displacement.displace(&v)));
        }
    }
    // Selection.
    let near = DVec3::new(0.0, 2.5, 3.0);
    assert_eq!(lods.select(LodSelection::Finest, 0, near, 1e9), 0);
    assert_eq!(lods.select(LodSelection::Footprint, 0, near, 0.0), 0);
    assert_eq!(lods.select(LodSelection::Footprint, 0, near, 1e9), 4);
    let between = lods.select(LodSelection::Footprint, 0, near, 2.0 * deviations[2]);
    assert!(between >= 2 && deviations[between] <= deviations[2]);
    assert!(between == 4 || deviations[between + 1] > deviations[2]);
    assert_eq!(lods.select(LodSelection::Distance, 0, near * 1e3, 0.0), 4);
    assert_eq!(lods.select(LodSelection::Distance, 0, near, 0.0), 0);
    assert_eq!(lods.select(LodSelection::Distance, 0, DVec3::ZERO, 0.0), 4);
}

/// Coincident shells (every centre in one bin on every axis) have no heuristic split: the
/// build falls back to median splits, which keep the tree shallower than the traversal
/// stack and every shell in exactly one leaf.
#[test]
fn coincident_shells_split_at_the_median() {
    let count = 1000u32;
    let mut items: Vec<([u32; 2], DVec3, DVec3)> = (0..count)
        .map(|i| ([i, 0], DVec3::ZERO, DVec3::ONE))
        .collect();
    assert!(sah_split(&mut items, DVec3::splat(0.5), DVec3::splat(0.5)).is_none());
    let mut nodes = Vec::new();
    build(&mut items, 0, 0, &mut nodes);
    let mut seen = vec![0; count as usize];
    let mut deepest = 0;
    let mut stack = vec![(0u32, 1usize)];
    while let Some((i, depth)) = stack.pop() {
        let node = nodes[i as usize];
        deepest = deepest.max(depth);
        if node.count > 0 {
            assert!(node.count as usize <= LEAF);
            for item in &items[node.index as usize..(node.index + node.count) as usize] {
                seen[item.0[0] as usize] += 1;
            }
        } else {
            stack.extend([(i + 1, depth + 1), (node.index, depth + 1)]);
        }
    }
    assert!(seen.iter().all(|&n| n == 1));
    assert!(deepest < STACK, "depth {deepest}");
}
