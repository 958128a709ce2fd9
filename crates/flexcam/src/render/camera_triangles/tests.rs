//! Camera triangles against the ray caster of the same projection, and the exactness of both
//! bounds.

use glam::DVec2;

use super::*;
use crate::projection::trilinear_builders::SurfaceRays;
use crate::render::compare::{compare, interior_id_agreement, Comparison};
use crate::render::{raycast, Method};
use crate::scene::{self, Scene};

/// The trilinear scenes of `scenes/`.
const TRILINEAR_SCENES: [&str; 5] = [
    "trilinear-detail-in-context",
    "trilinear-fan",
    "trilinear-grid-cylinder",
    "trilinear-inward-sphere",
    "trilinear-two-views",
];

pub(super) fn load(name: &str) -> Scene {
    scene::load(&format!(
        "{}/../../scenes/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

pub(super) fn options(shading: Shading, bound: Bound) -> RenderOptions<'static> {
    RenderOptions {
        method: Method::CameraTriangles,
        shading,
        camera_triangles: Options {
            bound,
            ..Options::default()
        },
        ..RenderOptions::default()
    }
}

pub(super) fn count(stats: &Stats, name: &str) -> u64 {
    match stats.get(name) {
        Some(Counter::Count(n)) => *n,
        other => panic!("{name}: {other:?}"),
    }
}

/// The fraction of pixels away from id edges whose ids agree
/// ([`interior_id_agreement`]); there must be such pixels.
fn id_agreement_inside(frame: &Frame, reference: &Frame) -> f64 {
    let (w, h) = (reference.width, reference.height);
    let (agreement, pixels) = interior_id_agreement(w, h, &frame.ids, &reference.ids).unwrap();
    assert!(pixels > 0, "no pixel away from id edges");
    agreement
}

/// Renders `scene` at `size` by camera triangles and by the ray caster.
fn against_raycast(
    scene: &Scene,
    size: (u32, u32),
    options: &RenderOptions,
) -> (Comparison, f64, Stats) {
    let projection = scene.projection.build(size.0, size.1).unwrap();
    let prepared = PreparedScene::new(scene);
    let (reference, _) = raycast::render(&prepared, projection.as_ref(), options).unwrap();
    let (frame, stats) = render(&prepared, projection.as_ref(), options).unwrap();
    let inside = id_agreement_inside(&frame, &reference);
    (compare(&frame, &reference).unwrap(), inside, stats)
}

#[test]
fn trilinear_scenes_match_the_ray_caster() {
    for name in TRILINEAR_SCENES {
        let scene = load(name);
        for shading in [Shading::Flat, Shading::Lit] {
            let (c, inside, stats) =
                against_raycast(&scene, (160, 120), &options(shading, Bound::Tight));
            println!(
                "{name} {shading:?}: ids {:.5} (inside {inside:.5}), rgb {:.5}, depth max {:.2e}, \
                 overdraw {:?}",
                c.id_agreement, c.relative_rgb_error, c.depth_max, stats["overdraw"]
            );
            assert!(inside >= 0.99, "{name}: {inside} {c:?}");
            assert!(c.id_agreement >= 0.98, "{name}: {c:?}");
            // The mean, not the largest: at two pixels of the inward sphere, rays through the
            // cube's centre, the ray caster misses the cube's top face that we hit.
            assert!(c.depth_mean < 1e-4, "{name}: {c:?}");
            assert!(c.relative_rgb_error < 0.02, "{name}: {c:?}");
            assert!(count(&stats, "rendered_fragments") > 0);
        }
    }
}

/// `scene` at `size` by camera triangles, flat, with the paper's bound and the tight one.
fn both_bounds(scene: &Scene, size: (u32, u32)) -> ((Frame, Stats), (Frame, Stats)) {
    let projection = scene.projection.build(size.0, size.1).unwrap();
    let prepared = PreparedScene::new(scene);
    let run = |bound| {
        render(
            &prepared,
            projection.as_ref(),
            &options(Shading::Flat, bound),
        )
        .unwrap()
    };
    (run(Bound::Paper), run(Bound::Tight))
}

/// The paper's bound and the tight bound give the same rendered fragments (both are exact),
/// hence the same image; the tight one rasterises fewer bounding fragments.
#[test]
fn both_bounds_render_the_same_fragments() {
    for name in TRILINEAR_SCENES {
        let ((paper, paper_stats), (tight, tight_stats)) = both_bounds(&load(name), (160, 120));
        assert_eq!(paper, tight, "{name}");
        assert_eq!(
            count(&paper_stats, "rendered_fragments"),
            count(&tight_stats, "rendered_fragments"),
            "{name}"
        );
        assert!(
            count(&tight_stats, "bounding_fragments") <= count(&paper_stats, "bounding_fragments"),
            "{name}"
        );
    }
}

/// Every pixel of a camera triangle whose ray hits a scene triangle lies in a region of each
/// bound, for every pair of every trilinear scene (brute force over the camera triangle's
/// pixels).
#[test]
fn bounds_hold_every_fragment() {
    for name in TRILINEAR_SCENES {
        let scene = load(name);
        let projection = scene.projection.build(64, 48).unwrap();
        let checked = fragments_in_bounds(name, projection.trilinear().unwrap(), &scene);
        assert!(checked > 100, "{name}: {checked}");
    }
}

/// The same on the reflection surfaces of mirror spheres, whose rays diverge (rays near the
/// silhouette graze the sphere and cross the camera plane from both sides, so the tight
/// bound projects onto planes farther along the rays).
#[test]
fn bounds_hold_every_fragment_of_diverging_rays() {
    for name in ["reflect-sphere-cube", "reflect-funny-mirror"] {
        let (projection, scene) = mirror_surface(name, SurfaceRays::Interpolated);
        let checked = fragments_in_bounds(name, &projection, &scene);
        assert!(checked > 100, "{name}: {checked}");
    }
}

/// The reflection surface of the first trilinear reflector (a mirror, its own mesh) of
/// scene `name` seen at 96 x 72 with rays `rays`, and the scene without the reflector.
pub(super) fn mirror_surface(name: &str, rays: SurfaceRays) -> (Trilinear, Scene) {
    use crate::projection::trilinear_builders::{reflector_surface, Optic};
    let mut scene = load(name);
    let entry = scene.trilinear_reflectors[0];
    let object = scene.objects.iter().find(|o| o.id == entry.id).unwrap();
    let mesh: &crate::scene::Mesh = &object.mesh;
    let crate::projection::ProjectionSpec::Perspective { frame, fov } = &scene.projection else {
        panic!("{name}: not perspective")
    };
    let camera = crate::projection::Perspective::new(frame, *fov, 96, 72).unwrap();
    let surface = reflector_surface(mesh, &camera, Optic::Reflect).unwrap();
    let projection = surface
        .projection(entry.screen_map, rays, 96, 72)
        .unwrap()
        .unwrap();
    scene.objects.retain(|o| o.id != entry.id);
    (projection, scene)
}

/// Checks that every fragment of every (camera, scene triangle) pair of `scene` through
/// `projection` lies in a region of each bound; returns the fragments checked.
pub(super) fn fragments_in_bounds(name: &str, projection: &Trilinear, scene: &Scene) -> usize {
    let (width, height) = projection.resolution();
    let cameras = Camera::all(projection);
    let owners = owners::owners(&cameras, width, height).unwrap();
    let geometry = SceneGeometry::new(scene);
    let mut checked = 0;
    for (c, camera) in cameras.iter().enumerate() {
        for k in 0..geometry.triangles.len() {
            let q = geometry.corners(k);
            for bound in [Bound::Paper, Bound::Tight] {
                let mut regions = Vec::new();
                bound::regions(camera, &q, bound, &mut |r| regions.push(*r));
                for (i, &owner) in owners.iter().enumerate() {
                    if owner != c as u32 {
                        continue;
                    }
                    let (x, y) = (i % width as usize, i / width as usize);
                    let centre = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                    let Some(ray) = camera.pixel_ray(centre) else {
                        continue;
                    };
                    let hit = crate::render::trilinear::plane_hit(&ray, q);
                    let Some((t, u, v)) = hit else { continue };
                    if !(t >= 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0) {
                        continue;
                    }
                    checked += 1;
                    let held = regions.iter().any(|r| contains(r.points(), centre));
                    assert!(
                        held,
                        "{name}: camera {c}, triangle {k}, {bound:?}, {centre}"
                    );
                }
            }
        }
    }
    checked
}

/// Whether the convex polygon `p` (either orientation) holds `x`.
fn contains(p: &[DVec2], x: DVec2) -> bool {
    // Edges between (nearly) coincident vertices have no direction to test.
    let sides: Vec<f64> = (0..p.len())
        .filter(|&i| p[i].distance(p[(i + 1) % p.len()]) > 1e-9)
        .map(|i| convex::cross(p[i], p[(i + 1) % p.len()], x))
        .collect();
    sides.iter().all(|&s| s >= 0.0) || sides.iter().all(|&s| s <= 0.0)
}

/// Culling clusters changes nothing but the work.
#[test]
fn culling_keeps_the_image() {
    let scene = load("trilinear-detail-in-context");
    let projection = scene.projection.build(160, 120).unwrap();
    let prepared = PreparedScene::new(&scene);
    let renderer = CameraTriangleRenderer::new(&prepared);
    let trilinear = projection.trilinear().unwrap();
    let flat = options(Shading::Flat, Bound::Tight);
    let with = |cull| {
        renderer
            .render(
                trilinear,
                &flat,
                Options {
                    cull,
                    ..Options::default()
                },
            )
            .unwrap()
    };
    let ((culled, culled_stats), (all, all_stats)) = (with(true), with(false));
    assert_eq!(culled, all);
    assert!(count(&culled_stats, "culled_pairs") > 0);
    assert_eq!(count(&all_stats, "culled_pairs"), 0);
    assert!(count(&culled_stats, "pairs") < count(&all_stats, "pairs"));
}

/// Culling (cluster groups, clusters per quarter) and the tight bound's quartering (a
/// quarter that its parent's region misses is skipped) drop no fragment: with and without
/// culling every trilinear scene and the mirror spheres' diverging rays render the same
/// frame from the same rendered fragments.
#[test]
fn culling_drops_no_fragment() {
    let mut cases: Vec<(String, Trilinear, Scene)> = TRILINEAR_SCENES
        .iter()
        .map(|name| {
            let scene = load(name);
            let projection = scene.projection.build(96, 72).unwrap();
            (
                name.to_string(),
                projection.trilinear().unwrap().clone(),
                scene,
            )
        })
        .collect();
    for name in ["reflect-sphere-cube", "reflect-funny-mirror"] {
        let (projection, scene) = mirror_surface(name, SurfaceRays::Interpolated);
        cases.push((name.to_string(), projection, scene));
    }
    for (name, projection, scene) in &cases {
        let prepared = PreparedScene::new(scene);
        let renderer = CameraTriangleRenderer::new(&prepared);
        let flat = options(Shading::Flat, Bound::Tight);
        let with = |cull| {
            let method = Options {
                cull,
                ..Options::default()
            };
            renderer.render(projection, &flat, method).unwrap()
        };
        let ((culled, culled_stats), (all, all_stats)) = (with(true), with(false));
        assert_eq!(culled, all, "{name}");
        assert_eq!(
            count(&culled_stats, "rendered_fragments"),
            count(&all_stats, "rendered_fragments"),
            "{name}"
        );
        assert!(count(&culled_stats, "rendered_fragments") > 100, "{name}");
    }
}

/// A cluster group's box holds the box of each of its clusters, and the groups cover the
/// clusters once, in order.
#[test]
fn cluster_groups_hold_their_clusters() {
    let scene = load("trilinear-detail-in-context");
    let geometry = SceneGeometry::new(&scene);
    let groups = quarter_cull::Groups::new(&geometry);
    let mut next = 0;
    for (clusters, corners) in groups.iter() {
        assert_eq!(clusters.start, next);
        next = clusters.end;
        let (lo, hi) = (corners[0], corners[7]);
        for cluster in &geometry.clusters[clusters.clone()] {
            for corner in cluster.box_corners {
                assert!(corner.cmpge(lo).all() && corner.cmple(hi).all());
            }
        }
    }
    assert_eq!(next, geometry.clusters.len());
    assert!(groups.iter().count() > 1);
}

#[test]
fn refuses_what_it_cannot_render() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let projection = scene.projection.build(8, 8).unwrap();
    let prepared = PreparedScene::new(&scene);
    let e = render(
        &prepared,
        projection.as_ref(),
        &options(Shading::Flat, Bound::Tight),
    );
    assert_eq!(
        e.unwrap_err().to_string(),
        format!(
            "the camera-triangles method renders only trilinear projections (and trilinear \
             reflectors in a perspective view), not a {} projection",
            projection.kind()
        )
    );
    let trilinear = load("trilinear-fan");
    let projection = trilinear.projection.build(8, 8).unwrap();
    let four = RenderOptions {
        spp: 4,
        ..options(Shading::Flat, Bound::Tight)
    };
    let e = render(&PreparedScene::new(&trilinear), projection.as_ref(), &four);
    assert_eq!(
        e.unwrap_err().to_string(),
        "method camera-triangles renders one sample per pixel; got --spp 4"
    );
    assert_eq!(
        "loose".parse::<Bound>().unwrap_err().to_string(),
        "unknown bound \"loose\" (available: paper, tight)"
    );
}

/// Reflections and refractions composited into the perspective view: the surfaces rendered
/// by camera triangles give the trilinear method's image (both render the same surfaces
/// exactly), and the stats carry the fragment counts.
#[test]
fn reflectors_composite_as_the_trilinear_method_does() {
    for name in [
        "reflect-sphere-cube",
        "reflect-funny-mirror",
        "refract-lens",
    ] {
        let scene = load(name);
        let main = scene.projection.build(160, 120).unwrap();
        let prepared = PreparedScene::new(&scene);
        for shading in [Shading::Flat, Shading::Lit] {
            let ours =
                crate::render::render(&prepared, main.as_ref(), &options(shading, Bound::Tight))
                    .unwrap();
            let trilinear = crate::render::render(
                &prepared,
                main.as_ref(),
                &RenderOptions {
                    method: Method::Trilinear,
                    shading,
                    ..RenderOptions::default()
                },
            )
            .unwrap();
            let c = compare(&ours.frame, &trilinear.frame).unwrap();
            println!("{name} {shading:?}: {c:?}");
            assert!(c.id_agreement == 1.0, "{name}: {c:?}");
            assert!(c.relative_rgb_error < 0.01, "{name}: {c:?}");
            assert!(count(&ours.counters, "rendered_fragments") > 0, "{name}");
            assert!(count(&ours.counters, "camera_triangles") > 0, "{name}");
        }
    }
}

/// The applications' scenes (convex, concave and mixed reflectors, a single curved
/// refraction) by camera triangles against the ray caster's exact mirror or glass (the same
/// scene without trilinear reflectors): object ids away from id edges, and the relative RGB
/// error, which is that of the reflector surfaces' interpolated rays.
#[test]
fn application_scenes_match_the_exact_ray_caster() {
    for (name, max_rgb) in [
        ("camtri-convex", 0.02),
        ("camtri-concave", 0.02),
        ("camtri-mixed", 0.02),
        ("camtri-refract", 0.02),
    ] {
        let scene = load(name);
        let main = scene.projection.build(160, 120).unwrap();
        let ours = crate::render::render(
            &PreparedScene::new(&scene),
            main.as_ref(),
            &options(Shading::Flat, Bound::Tight),
        )
        .unwrap();
        let reference = crate::render::composite::exact_flat_reference(&scene, main.as_ref());
        let inside = id_agreement_inside(&ours.frame, &reference);
        let c = compare(&ours.frame, &reference).unwrap();
        println!("{name}: ids inside {inside:.5}, {c:?}");
        assert!(inside >= 0.99, "{name}: {inside}");
        assert!(c.relative_rgb_error < max_rgb, "{name}: {c:?}");
        assert!(count(&ours.counters, "rendered_fragments") > 0, "{name}");
    }
}

/// The visualisation around a figure (section 3.4, Figure 12): 400 camera triangles
/// surround the walker, which is seen from the back, both sides and the front in one image,
/// rendered by camera triangles as the ray caster renders the same projection (flat and
/// lit; both bounds give the same image, the tight one with fewer bounding fragments).
#[test]
fn visualisation_around_a_figure_matches_the_ray_caster() {
    let scene = load("camtri-visualisation");
    let (width, height) = (192, 72);
    for shading in [Shading::Flat, Shading::Lit] {
        let (c, inside, stats) =
            against_raycast(&scene, (width, height), &options(shading, Bound::Tight));
        println!(
            "camtri-visualisation {shading:?}: ids {:.5} (inside {inside:.5}), rgb {:.2e}, \
             depth mean {:.2e}, overdraw {:?}",
            c.id_agreement, c.relative_rgb_error, c.depth_mean, stats["overdraw"]
        );
        assert_eq!(count(&stats, "camera_triangles"), 400);
        assert!(inside >= 0.99, "{inside} {c:?}");
        assert!(c.id_agreement >= 0.98, "{c:?}");
        assert!(c.depth_mean < 1e-4, "{c:?}");
        assert!(c.relative_rgb_error < 0.005, "{c:?}");
    }
    let ((paper, paper_stats), (tight, tight_stats)) = both_bounds(&scene, (width, height));
    assert_eq!(paper, tight);
    assert!(count(&tight_stats, "bounding_fragments") < count(&paper_stats, "bounding_fragments"));
    // The walker (object 1) in the middle row of each view: the back at the image's left
    // and right edges, the sides at a quarter and three quarters, the front in the middle.
    let walker = scene
        .objects
        .iter()
        .find(|o| o.name == "walker")
        .unwrap()
        .id;
    let row = (height / 2) as usize * width as usize;
    for column in [0.02, 0.25, 0.5, 0.75, 0.98] {
        let x = (column * f64::from(width)) as usize;
        assert_eq!(tight.ids[row + x], walker, "column {column}");
    }
}
