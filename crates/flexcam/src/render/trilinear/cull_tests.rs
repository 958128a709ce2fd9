//! The hierarchical cull of the projection stage (`cull_tree`, `pair_cull`) against the
//! triangle-by-triangle volume test and against no cull at all: the same live pairs and
//! polygons (every vertex, bit for bit) as the former; the same polygons as the latter on
//! the example scenes but the inward sphere, the cube through the fan, randomised scenes and
//! degenerate configurations.

use std::sync::Arc;

use glam::{DVec2, DVec3, Vec3};
use proptest::prelude::*;

use super::central::CentralProjection;
use super::curves::{CurveMode, CurveOptions};
use super::gbuffer::GBuffer;
use super::hit_terms::HitTerms;
use super::hit_terms::TERMS;
use super::occlusion::Occlusion;
use super::outline::ProjectionTriangle;
use super::pair_cull::PairCounts;
use super::pair_cull::{live_pairs, LivePair, LivePairs, VertexCache};
use super::polygons::{draw_all, project_all, projection_triangles, ProjectedScene};
use super::resolve::Resolver;
use super::resolve::PIXEL_TESTED;
use super::scene_geometry::SceneGeometry;
use super::tests::{object, scene_of, square};
use super::workloads;
use crate::projection::{Trilinear, TrilinearMesh};
use crate::render::scan::{PolygonBatch, Scratch};
use crate::scene::{self, Scene};

/// Every pair with a plane, with no volume cull, its cubics solved directly.
fn unculled(triangles: &[ProjectionTriangle], scene: &SceneGeometry) -> Vec<LivePairs> {
    (0..triangles.len() as u32)
        .map(|index| solved_directly(triangles, scene, index, 0..scene.triangles.len()))
        .collect()
}

/// The pairs of projection triangle `index` with the scene triangles `live` (in order)
/// that have a plane, each pair's vertices solved directly and stored on their own (no
/// vertex cache, no sharing).
fn solved_directly(
    triangles: &[ProjectionTriangle],
    scene: &SceneGeometry,
    index: u32,
    live: impl IntoIterator<Item = usize>,
) -> LivePairs {
    let mut group = LivePairs {
        projection: index,
        ..LivePairs::default()
    };
    for k in live {
        if HitTerms::new(scene.corners(k)).is_none() {
            continue;
        }
        let first = group.solutions.len() as u32;
        let triangle = &triangles[index as usize];
        group
            .solutions
            .extend(solve(triangle, scene, scene.triangles[k]));
        group.pairs.push(LivePair {
            triangle: k as u32,
            solved: [first, first + 1, first + 2],
        });
    }
    group
}

fn solve(
    triangle: &ProjectionTriangle,
    scene: &SceneGeometry,
    corners: [u32; 3],
) -> [crate::projection::Solutions; 3] {
    corners.map(|i| {
        triangle
            .map
            .cache()
            .project_point(scene.vertices[i as usize])
    })
}

/// The pairs (projection, scene triangle) that the volume test alone keeps, triangle by
/// triangle with no tree, among those with a plane; for a central projection, those its
/// cones' test alone keeps (`CentralProjection::culled`); none of a ray cast triangle.
fn kept_one_by_one(triangles: &[ProjectionTriangle], scene: &SceneGeometry) -> Vec<(u32, u32)> {
    let mut kept = Vec::new();
    for (index, triangle) in triangles.iter().enumerate() {
        if triangle.ray_cast {
            continue;
        }
        for (k, corners) in scene.triangles.iter().enumerate() {
            let vertices = corners.map(|i| scene.vertices[i as usize]);
            let culled = match &triangle.central {
                Some(central) => {
                    let common = vertices
                        .iter()
                        .fold(u16::MAX, |m, &x| m & central.outside(x));
                    CentralProjection::culled(common)
                }
                None => {
                    let common = vertices
                        .iter()
                        .fold(u32::MAX, |m, &x| m & triangle.bounds().outside(x));
                    common != 0
                }
            };
            if !culled && HitTerms::new(scene.corners(k)).is_some() {
                kept.push((index as u32, k as u32));
            }
        }
    }
    kept
}

fn assert_same_polygons(a: &ProjectedScene, b: &ProjectedScene, what: &str) {
    assert_eq!(a.polygons.len(), b.polygons.len(), "{what}: polygon count");
    for (i, (p, q)) in a.polygons.iter().zip(b.polygons.iter()).enumerate() {
        assert_eq!(p.primitive, q.primitive, "{what}: polygon {i}");
        assert_eq!(p.vertices, q.vertices, "{what}: polygon {i}");
    }
    assert_eq!(a.fallback, b.fallback, "{what}: fallback triangles");
}

/// `scene` without the pixel-tested bands of pairs outside `kept`: a band is a superset of
/// its pair's pixels, drawn for a pair reaching or meeting a degenerate depth, and that of a
/// pair the cull removes has every fragment discarded (its triangle is outside the volume).
fn without_culled_bands(scene: &ProjectedScene, kept: &[(u32, u32)]) -> ProjectedScene {
    let mut out = ProjectedScene {
        polygons: PolygonBatch::new(),
        counts: scene.counts,
        fallback: scene.fallback.clone(),
    };
    for p in scene.polygons.iter() {
        let key = p.primitive & !PIXEL_TESTED;
        let pair = ((key >> 32) as u32, key as u32);
        if p.primitive & PIXEL_TESTED == 0 || kept.binary_search(&pair).is_ok() {
            out.polygons.push(p.vertices, p.primitive);
        }
    }
    out
}

/// Whether `a`'s polygons appear in `b` in the same order (all of them, bit for bit), every
/// other polygon of `b` keyed to a pair outside `kept`; returns the number of those others,
/// and apart from them that of the pixel-tested bands of `b` not in `a`.
fn polygons_within(
    a: &ProjectedScene,
    b: &ProjectedScene,
    kept: &[(u32, u32)],
    what: &str,
) -> (usize, usize) {
    let key = |p: u64| ((p >> 32) as u32, p as u32);
    let mut mine = a.polygons.iter().peekable();
    let (mut others, mut tested) = (0, 0);
    for q in b.polygons.iter() {
        match mine.peek() {
            Some(p) if p.primitive == q.primitive && p.vertices == q.vertices => {
                mine.next();
            }
            // A pixel-tested band is drawn for each split pair, a superset of its pixels:
            // one of a pair the cull removes has every fragment discarded.
            _ if q.primitive & PIXEL_TESTED != 0 => tested += 1,
            _ => {
                assert!(
                    kept.binary_search(&key(q.primitive)).is_err(),
                    "{what}: polygon of kept pair {:?} missing",
                    key(q.primitive)
                );
                others += 1;
            }
        }
    }
    assert!(
        mine.next().is_none(),
        "{what}: a polygon not drawn without the cull"
    );
    (others, tested)
}

/// Checks the culled stage on `scene` through `projection`: its live pairs are exactly
/// those of the one-by-one test, with the directly solved cubics, and its polygons exactly
/// those of drawing them; its counts add up; drawing every pair (no cull) gives its
/// polygons plus, possibly, polygons of pairs the volume test culls (returned: how many).
fn check(
    scene: &Scene,
    projection: &Trilinear,
    curves: CurveOptions,
    what: &str,
) -> (PairCounts, usize) {
    let geometry = SceneGeometry::new(scene);
    let triangles = projection_triangles(projection);
    // One cache for all projection triangles, as one worker uses it.
    let mut cache = VertexCache::new(geometry.vertices.len());
    let live: Vec<LivePairs> = triangles
        .iter()
        .enumerate()
        .map(|(index, triangle)| live_pairs(triangle, index as u32, &geometry, &mut cache).0)
        .collect();
    let pairs: Vec<(u32, u32)> = live
        .iter()
        .flat_map(|g| g.pairs.iter().map(move |p| (g.projection, p.triangle)))
        .collect();
    let kept = kept_one_by_one(&triangles, &geometry);
    assert_eq!(pairs, kept, "{what}: live pairs");
    let mut direct = Vec::new();
    for group in &live {
        let triangles_of = group.pairs.iter().map(|p| p.triangle as usize);
        let d = solved_directly(&triangles, &geometry, group.projection, triangles_of);
        for (p, q) in group.pairs.iter().zip(&d.pairs) {
            assert_eq!(group.solved(p), d.solved(q), "{what}: solutions");
        }
        // Each live vertex is solved and stored once per projection triangle.
        let mut vertices: Vec<u32> = group
            .pairs
            .iter()
            .flat_map(|p| geometry.triangles[p.triangle as usize])
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        assert_eq!(
            group.solutions.len(),
            vertices.len(),
            "{what}: solution pool"
        );
        direct.push(d);
    }
    let culled = project_all(&triangles, &geometry, curves);
    let one_by_one = draw_all(
        &triangles,
        &geometry,
        &direct,
        curves,
        PairCounts::default(),
    );
    assert_same_polygons(&culled, &one_by_one, what);
    let all = unculled(&triangles, &geometry);
    let reference = draw_all(&triangles, &geometry, &all, curves, PairCounts::default());
    let reference = without_culled_bands(&reference, &kept);
    let (others, tested) = polygons_within(&culled, &reference, &kept, what);
    assert_eq!(tested, 0, "{what}");
    if others == 0 {
        // A culled pair drawn anyway through a triangle whose parametric triangle
        // degenerates (the inward sphere's, drawn here without their central projections)
        // can reach across that depth and make the triangle fall back: only the others'
        // fallbacks must agree.
        let ordinary = |f: &[bool]| -> Vec<bool> {
            f.iter()
                .zip(&triangles)
                .map(|(&f, t)| f && t.degenerate.is_none())
                .collect()
        };
        let mut reference = reference;
        reference.fallback = ordinary(&reference.fallback);
        let mut culled = culled.clone();
        culled.fallback = ordinary(&culled.fallback);
        // Culling never adds a fallback. It may remove one: a pair outside the volume whose
        // shapes the unculled drawing cannot project (`unprojectable`) makes its triangle
        // fall back there; each such triangle must fall back on its culled pairs alone.
        for (index, (&c, r)) in culled
            .fallback
            .iter()
            .zip(&mut reference.fallback)
            .enumerate()
        {
            if c || !*r {
                continue;
            }
            let outside = (0..geometry.triangles.len())
                .filter(|&k| kept.binary_search(&(index as u32, k as u32)).is_err());
            let alone = [solved_directly(
                &triangles,
                &geometry,
                index as u32,
                outside,
            )];
            let drawn = draw_all(&triangles, &geometry, &alone, curves, PairCounts::default());
            assert!(
                drawn.fallback[index],
                "{what}: culling removed triangle {index}'s fallback, not caused by a culled pair"
            );
            *r = false;
        }
        assert_same_polygons(&culled, &reference, what);
    }
    let c = culled.counts;
    assert_eq!(c.pairs, (triangles.len() * geometry.triangles.len()) as u64);
    assert!(c.culled_tree <= c.culled_volume, "{what}: {c:?}");
    assert_eq!(
        c.pairs - c.culled_volume - c.culled_zero_area,
        pairs.len() as u64,
        "{what}: {c:?}"
    );
    (c, others)
}

fn trilinear(mesh: &TrilinearMesh, width: u32, height: u32) -> Trilinear {
    Trilinear::new(mesh, width, height).unwrap()
}

/// Every example scene of a trilinear projection (the visualisation surfaces of chapter 6,
/// the fan, the cylinder grid), at its own size; the detail-in-context surface culls most of
/// its pairs by whole subtrees.
#[test]
fn the_tree_changes_no_polygon_of_the_example_scenes() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with("trilinear-") && n.ends_with(".toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 5, "{names:?}");
    for name in names {
        let scene = scene::load(dir.join(&name).to_str().unwrap()).unwrap();
        let (width, height) = (scene.image.width, scene.image.height);
        let projection = scene.projection.build(width, height).unwrap();
        let projection = projection.trilinear().unwrap();
        let (c, others) = check(&scene, projection, CurveOptions::ADAPTIVE, &name);
        println!(
            "{name}: {} pairs, {} culled by the tree, {} one by one, {} live, {} shapes; \
             {others} more polygons without the volume cull",
            c.pairs,
            c.culled_tree,
            c.culled_volume - c.culled_tree,
            c.pairs - c.culled_volume - c.culled_zero_area,
            c.shapes
        );
        // The inward sphere's rays leave the volume test's culled pairs with chord
        // polygons when drawn anyway (see docs/trilinear.md); every other scene draws
        // nothing more without the cull.
        if name != "trilinear-inward-sphere.toml" {
            assert_eq!(others, 0, "{name}");
        }
        if name == "trilinear-detail-in-context.toml" {
            assert!(c.culled_tree > c.pairs / 2, "{name}: {c:?}");
        }
    }
}

/// The bench's cube: cube-floor through the fan at 800 x 800 (18 projections), every curve
/// mode, with and without scene-space clipping (tessellation through 8 projections at a
/// smaller size, as it projects every grid point of every unculled pair).
#[test]
fn the_tree_changes_no_polygon_of_the_cube() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let fan = workloads::fan_grid(3).unwrap();
    let unclipped = CurveOptions {
        scene_clipping: false,
        ..CurveOptions::ADAPTIVE
    };
    let slice = CurveOptions {
        mode: CurveMode::Slice,
        steps: 10,
        scene_clipping: true,
    };
    for (curves, what) in [
        (CurveOptions::ADAPTIVE, "adaptive"),
        (unclipped, "adaptive, no scene-space clipping"),
        (slice, "slice"),
    ] {
        let (c, others) = check(&scene, &trilinear(&fan, 800, 800), curves, what);
        assert!(c.culled_volume > 0 && c.shapes > 0, "{what}: {c:?}");
        assert_eq!(others, 0, "{what}");
    }
    let tessellate = CurveOptions {
        mode: CurveMode::Tessellate,
        steps: 4,
        scene_clipping: true,
    };
    let fan = workloads::fan_grid(2).unwrap();
    let (_, others) = check(&scene, &trilinear(&fan, 160, 120), tessellate, "tessellate");
    assert_eq!(others, 0, "tessellate");
}

/// The cull of projection triangles drawn as central projections, set as the renderer sets
/// them (`render_into`: central where the rays meet in one point, ray cast where they sweep
/// no volume): through the tree, exactly the pairs the cones' test keeps one by one; drawing
/// every pair instead (no cull) gives the same polygons and fallback triangles, so the
/// culled pairs had no image. Returns the counts.
fn check_central(scene: &Scene, projection: &Trilinear, what: &str) -> PairCounts {
    let geometry = SceneGeometry::new(scene);
    let triangles = central_triangles(projection, what);
    let mut cache = VertexCache::new(geometry.vertices.len());
    let mut counts = PairCounts::default();
    let live: Vec<LivePairs> = triangles
        .iter()
        .enumerate()
        .map(|(index, triangle)| {
            let (live, c) = live_pairs(triangle, index as u32, &geometry, &mut cache);
            counts.add(&c);
            live
        })
        .collect();
    let pairs: Vec<(u32, u32)> = live
        .iter()
        .flat_map(|l| l.pairs.iter().map(move |p| (l.projection, p.triangle)))
        .collect();
    let kept = kept_one_by_one(&triangles, &geometry);
    assert_eq!(pairs, kept, "{what}: live pairs");
    // The volume cull alone: `project_all` also drops the pairs hidden behind covers
    // (`occlusion`), which change no pixel but do change the polygons (tested there).
    let culled = draw_all(&triangles, &geometry, &live, CurveOptions::ADAPTIVE, counts);
    let all = unculled(&triangles, &geometry);
    let reference = draw_all(
        &triangles,
        &geometry,
        &all,
        CurveOptions::ADAPTIVE,
        PairCounts::default(),
    );
    let reference = without_culled_bands(&reference, &kept);
    let others = polygons_within(&culled, &reference, &kept, what);
    assert_eq!(others, (0, 0), "{what}");
    assert_same_polygons(&culled, &reference, what);
    culled.counts
}

/// The projection triangles of `projection`, central where their rays meet in one point and
/// ray cast where they sweep no volume, as the renderer sets them; most of them central.
fn central_triangles(projection: &Trilinear, what: &str) -> Vec<ProjectionTriangle> {
    let mut triangles = projection_triangles(projection);
    for triangle in &mut triangles {
        let cache = *triangle.map.cache();
        triangle.ray_cast = cache.sweeps_no_volume();
        triangle.central = (!triangle.ray_cast)
            .then(|| CentralProjection::of(&cache))
            .flatten();
    }
    let central = triangles.iter().filter(|t| t.central.is_some()).count();
    assert!(central > triangles.len() / 2, "{what}: {central} central");
    triangles
}

/// The winners (depth and key per pixel) of `polygons` drawn into one band of the whole
/// `width` x `height` frame, each fragment resolved to its exact hit (pixel centres).
fn winners(
    polygons: &PolygonBatch<TERMS>,
    triangles: &[ProjectionTriangle],
    geometry: &SceneGeometry,
    (width, height): (u32, u32),
) -> (Vec<f64>, Vec<u64>) {
    let resolver = Resolver {
        triangles,
        scene: geometry,
        sample: DVec2::splat(0.5),
    };
    let mut buffer = GBuffer::new(width, height).unwrap();
    buffer.start_band((0, height));
    let mut scratch = Scratch::default();
    for k in 0..polygons.len() {
        buffer.draw(&polygons.get(k), &resolver, &mut scratch);
    }
    (buffer.depth, buffer.keys)
}

/// The occlusion cull changes no pixel: the inward-looking sphere, with its own scene and
/// with random triangles added around its centre (some through the focus), drawn from the live pairs with and without the
/// pairs hidden behind covers, has the same winner (depth and key) at every pixel and the
/// same ray-cast triangles, with fewer polygons where its own cube hides the rest.
#[test]
fn pairs_hidden_behind_covers_change_no_pixel() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/trilinear-inward-sphere.toml"
    );
    let mut scene = scene::load(path).unwrap();
    let size = (160, 120);
    let built = scene.projection.build(size.0, size.1).unwrap();
    let projection = built.trilinear().unwrap();
    let triangles = central_triangles(projection, "inward sphere");
    for random in [None, Some((200, 7))] {
        if let Some((count, seed)) = random {
            let mut objects = random_scene(count, seed).objects;
            for object in &mut objects {
                object.id += 10;
                for p in &mut Arc::make_mut(&mut object.mesh).positions {
                    *p += Vec3::new(0.0, 1.5, 1.0);
                }
            }
            scene.objects.extend(objects);
        }
        let geometry = SceneGeometry::new(&scene);
        let mut cache = VertexCache::new(geometry.vertices.len());
        let mut occlusion = Occlusion::new(geometry.vertices.len());
        let (mut all, mut hidden, mut dropped) = (Vec::new(), Vec::new(), 0);
        for (index, triangle) in triangles.iter().enumerate() {
            let (live, _) = live_pairs(triangle, index as u32, &geometry, &mut cache);
            let mut fewer = live.clone();
            if let Some(central) = &triangle.central {
                dropped += occlusion.cull_hidden(central, &geometry, &mut fewer);
            }
            all.push(live);
            hidden.push(fewer);
        }
        let curves = CurveOptions::ADAPTIVE;
        let counts = PairCounts::default();
        let all = draw_all(&triangles, &geometry, &all, curves, counts);
        let fewer = draw_all(&triangles, &geometry, &hidden, curves, counts);
        let what = format!("{random:?}: {dropped} hidden");
        assert!(dropped > 0, "{what}");
        assert!(fewer.polygons.len() < all.polygons.len(), "{what}");
        assert_eq!(fewer.fallback, all.fallback, "{what}");
        let (depth, keys) = winners(&all.polygons, &triangles, &geometry, size);
        let (fewer_depth, fewer_keys) = winners(&fewer.polygons, &triangles, &geometry, size);
        assert_eq!(fewer_keys, keys, "{what}");
        let same = |a: &f64, b: &f64| a.to_bits() == b.to_bits();
        assert!(
            depth.iter().zip(&fewer_depth).all(|(a, b)| same(a, b)),
            "{what}"
        );
    }
}

/// The inward-looking sphere (its central projections), with its own scene and with random
/// triangles (in front of it, behind it, collapsed) around its centre: the tree culls most
/// pairs by whole subtrees, and changes no pair and no polygon.
#[test]
fn the_tree_changes_no_polygon_of_central_projections() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/trilinear-inward-sphere.toml"
    );
    let mut scene = scene::load(path).unwrap();
    let built = scene.projection.build(64, 32).unwrap();
    let projection = built.trilinear().unwrap();
    let c = check_central(&scene, projection, "inward sphere");
    assert!(c.culled_tree > c.pairs / 2 && c.shapes > 0, "{c:?}");
    for (count, seed) in [(40, 1), (200, 7)] {
        let random = random_scene(count, seed);
        scene.objects = random.objects;
        for object in &mut scene.objects {
            for p in &mut Arc::make_mut(&mut object.mesh).positions {
                *p += Vec3::new(0.0, 1.5, 4.0);
            }
        }
        let what = format!("inward sphere, {count} random triangles");
        let c = check_central(&scene, projection, &what);
        assert!(c.culled_tree > 0 && c.shapes > 0, "{what}: {c:?}");
    }
}

/// `count` random triangles of the bench's random data (`seed`), plus the same triangles
/// mirrored behind the view plane (`z > 0`, the grids look along -z from `z = 0`), and the
/// same triangles collapsed to their first vertex (zero area; clusters of zero extent).
fn random_scene(count: u32, seed: u64) -> Scene {
    let mut scene = workloads::random_triangles(count, seed);
    let mut behind = scene.objects[0].clone();
    behind.id = 2;
    for p in &mut Arc::make_mut(&mut behind.mesh).positions {
        p.z = -p.z;
    }
    let mut collapsed = scene.objects[0].clone();
    collapsed.id = 3;
    let mesh = Arc::make_mut(&mut collapsed.mesh);
    for triangle in &mesh.triangles {
        let first = mesh.positions[triangle[0] as usize];
        for &i in &triangle[1..] {
            mesh.positions[i as usize] = first;
        }
    }
    scene.objects.extend([behind, collapsed]);
    scene
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Random triangles (in front, behind, collapsed) through random screen meshes of 2 to
    /// 32 projection triangles.
    #[test]
    fn the_tree_changes_no_polygon_of_random_scenes(
        count in 1u32..48,
        cells in 1u32..5,
        seed in any::<u64>(),
    ) {
        let scene = random_scene(count, seed);
        let mesh = workloads::random_grid(cells, seed ^ 0x5eed).unwrap();
        let projection = trilinear(&mesh, 64, 64);
        let (_, others) = check(&scene, &projection, CurveOptions::ADAPTIVE, "random");
        prop_assert_eq!(others, 0);
    }
}

/// A random case of the property above in which a pair outside projection triangle 7's
/// volume cannot be projected: unculled, the triangle falls back; culled, it does not.
#[test]
fn the_tree_changes_no_polygon_of_random_scene_17096366145756637255() {
    let seed = 17096366145756637255;
    let scene = random_scene(1, seed);
    let mesh = workloads::random_grid(3, seed ^ 0x5eed).unwrap();
    let projection = trilinear(&mesh, 64, 64);
    let (_, others) = check(&scene, &projection, CurveOptions::ADAPTIVE, "random");
    assert_eq!(others, 0);
}

/// Degenerate scenes and meshes: a triangle wholly behind the view plane, one straddling
/// it, a triangle with an edge in the edge surface of a projection edge (the diagonal's
/// plane `x = y` under parallel normals) and a vertex on it, a zero-area sliver, an object
/// of zero extent (every vertex at one point), an object with a non-finite vertex (its
/// cluster's box is infinite and never culled), and directions spanning more than a
/// half-space (no bounding plane at all: nothing culled).
#[test]
fn the_tree_changes_no_polygon_in_degenerate_cases() {
    let v = DVec3::new;
    let scene = scene_of(vec![
        object(
            1,
            &[
                [v(0.2, 0.2, -3.0), v(0.8, 0.3, -2.0), v(0.4, 0.9, -1.0)],
                [v(0.2, 0.3, -1.0), v(-0.5, 0.2, 2.0), v(1.2, 1.0, 3.0)],
                [v(0.5, 0.5, 2.0), v(0.7, 0.7, 3.0), v(0.9, 0.2, 2.5)],
                [v(0.1, 0.1, 2.0), v(0.5, 0.5, 2.0), v(0.9, 0.9, 2.0)],
            ],
            Vec3::new(0.9, 0.1, 0.1),
        ),
        object(2, &[[v(0.3, 0.6, 2.0); 3]; 4], Vec3::ONE),
        object(
            3,
            &[
                [v(f64::NAN, 0.5, 2.0), v(0.5, 0.5, 2.0), v(0.4, 0.6, 2.0)],
                [v(0.3, 0.3, 4.0), v(0.6, 0.3, 4.0), v(0.3, 0.6, 4.0)],
            ],
            Vec3::ONE,
        ),
        // Far outside every volume below: culled wherever there are planes.
        object(
            4,
            &[[v(50.0, 50.0, 2.0), v(51.0, 50.0, 2.0), v(50.0, 51.0, 2.0)]; 3],
            Vec3::ONE,
        ),
    ]);
    let meshes = [
        ("parallel normals", square([v(0.0, 0.0, 1.0); 4])),
        (
            "diverging",
            square([
                v(-0.3, -0.3, 1.0),
                v(0.3, -0.3, 1.0),
                v(-0.3, 0.3, 1.0),
                v(0.25, 0.35, 1.1),
            ]),
        ),
        (
            "beyond a half-space",
            square([
                v(1.0, 0.0, 0.1),
                v(0.0, 1.0, 0.1),
                v(-1.0, -1.0, 0.1),
                v(0.3, 0.3, 1.0),
            ]),
        ),
    ];
    for (what, mesh) in meshes {
        let projection = trilinear(&mesh, 48, 48);
        let (c, others) = check(&scene, &projection, CurveOptions::ADAPTIVE, what);
        println!("{what}: {c:?}");
        assert_eq!(others, 0, "{what}");
        assert!(c.culled_zero_area > 0, "{what}: {c:?}");
        if what == "parallel normals" {
            assert!(c.culled_tree > 0 && c.shapes > 0, "{what}: {c:?}");
        }
    }
}

/// The stage's result does not depend on the number of threads (its work items are
/// concatenated in order).
#[test]
fn the_projection_stage_is_the_same_on_one_thread() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let geometry = SceneGeometry::new(&scene);
    let projection = trilinear(&workloads::fan_grid(3).unwrap(), 400, 400);
    let triangles = projection_triangles(&projection);
    let many = project_all(&triangles, &geometry, CurveOptions::ADAPTIVE);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one = pool.install(|| project_all(&triangles, &geometry, CurveOptions::ADAPTIVE));
    assert_same_polygons(&many, &one, "one thread");
    assert_eq!(many.counts, one.counts);
}
