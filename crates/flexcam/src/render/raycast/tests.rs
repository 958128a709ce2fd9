//! Ray caster tests on hand-made scenes, with a tiny parallel projection.

use glam::{Affine3A, DVec2, DVec3, Vec3};

use super::*;
use crate::geometry::intersect_triangle;
use crate::projection::{AnalyticInverse, CameraFrame, NoInverse, ProjectionSpec, Trilinear};
use crate::render::{raycast, Counter, Shading};
use crate::scene::{Finish, ImageSettings, Light, Material, Mesh, Object, Pattern, Scene};

/// Parallel rays along `direction` from a grid of origins: pixel (x, y) starts at
/// `corner + x * right - y * up` (continuous pixel coordinates). Columns left of `blind`
/// see nothing.
struct Parallel {
    size: (u32, u32),
    corner: DVec3,
    right: DVec3,
    up: DVec3,
    direction: DVec3,
    blind: f64,
}

impl Parallel {
    /// A `w x h` image, one world unit per pixel, looking along `direction` from z = 10
    /// with pixel (0, 0)'s corner at `(x, y)`.
    fn new(w: u32, h: u32, (x, y): (f64, f64), direction: DVec3) -> Parallel {
        Parallel {
            size: (w, h),
            corner: DVec3::new(x, y, 10.0),
            right: DVec3::X,
            up: DVec3::Y,
            direction,
            blind: 0.0,
        }
    }
}

impl Projection for Parallel {
    fn kind(&self) -> &'static str {
        "test-parallel"
    }
    fn resolution(&self) -> (u32, u32) {
        self.size
    }
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        (pixel.x >= self.blind).then(|| {
            Ray::new(
                self.corner + pixel.x * self.right - pixel.y * self.up,
                self.direction,
            )
        })
    }
    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Err(NoInverse { reason: None })
    }
    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }
}

/// A quad centred at `c` spanned by `u` and `v` (face normal `u x v`), as two triangles.
fn quad(c: Vec3, u: Vec3, v: Vec3) -> Mesh {
    Mesh {
        positions: vec![c - u - v, c + u - v, c + u + v, c - u + v],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        ..Default::default()
    }
}

fn object(id: u32, mesh: Mesh, color: Vec3, finish: Finish) -> Object {
    Object {
        id,
        name: format!("o{id}"),
        mesh: mesh.into(),
        material: Material {
            color,
            pattern: Pattern::Solid,
            finish,
        },
        world_to_object: Affine3A::IDENTITY,
        displacement: None,
    }
}

fn scene(objects: Vec<Object>, lights: Vec<Light>) -> Scene {
    Scene {
        objects,
        lights,
        image: ImageSettings {
            width: 1,
            height: 1,
            background: Vec3::new(0.0, 0.0, 0.25),
            spp: 1,
        },
        projection: ProjectionSpec::Perspective {
            frame: CameraFrame {
                position: DVec3::Z,
                look_at: DVec3::ZERO,
                up: DVec3::Y,
            },
            fov: 60.0,
        },
        base_dir: None,
        trilinear_reflectors: Vec::new(),
        caustics: Vec::new(),
        motions: Vec::new(),
        inputs: Vec::new(),
    }
}

const RED: Vec3 = Vec3::new(1.0, 0.0, 0.0);
const GREEN: Vec3 = Vec3::new(0.0, 1.0, 0.0);
const BLUE: Vec3 = Vec3::new(0.0, 0.0, 1.0);

fn flat(max_bounces: u32) -> RenderOptions<'static> {
    RenderOptions {
        shading: Shading::Flat,
        spp: 1,
        max_bounces,
        ..RenderOptions::default()
    }
}

/// The flat colour, depth and id seen along one ray (a 1x1 image).
fn trace(
    scene: &Scene,
    origin: DVec3,
    direction: DVec3,
    options: &RenderOptions,
) -> (Vec3, f32, u32) {
    let mut camera = Parallel::new(1, 1, (0.0, 0.0), direction);
    camera.corner = origin - DVec3::new(0.5, -0.5, 0.0);
    let (frame, _) = raycast::render(&PreparedScene::new(scene), &camera, options).unwrap();
    (frame.color[0], frame.depth[0], frame.ids[0])
}

#[test]
fn intersect_maps_hits_to_objects_and_agrees_with_f64_brute_force() {
    let mut objects = Vec::new();
    for k in 0..6u32 {
        let c = Vec3::new(k as f32 * 0.7 - 2.0, (k % 3) as f32 * 0.5, -(k as f32));
        let u = Vec3::new(1.0, 0.2 * k as f32, 0.1);
        objects.push(object(
            k + 1,
            quad(c, u, Vec3::new(0.0, 1.0, 0.3)),
            RED,
            Finish::Diffuse,
        ));
    }
    let scene = scene(objects, vec![]);
    let caster = PreparedScene::new(&scene);
    let mut hits = 0;
    for i in 0..40 {
        for j in 0..40 {
            let origin = DVec3::new(0.0, 0.5, 8.0);
            let target = DVec3::new(i as f64 * 0.15 - 3.0, j as f64 * 0.1 - 1.0, -3.0);
            let ray = Ray::new(origin, (target - origin) * 0.37);
            let mut expected: Option<(usize, usize, f64)> = None;
            for (o, obj) in scene.objects.iter().enumerate() {
                for (t, tri) in obj.mesh.triangles.iter().enumerate() {
                    let v = tri.map(|i| obj.mesh.positions[i as usize].as_dvec3());
                    if let Some(h) = intersect_triangle(ray.origin, ray.direction, v) {
                        if h.t >= 0.0 && expected.is_none_or(|e| h.t < e.2) {
                            expected = Some((o, t, h.t));
                        }
                    }
                }
            }
            let got = caster.intersect(&ray).map(|h| (h.object, h.triangle, h.t));
            match (got, expected) {
                (Some(g), Some(e)) => {
                    assert_eq!((g.0, g.1), (e.0, e.1));
                    assert!((g.2 - e.2).abs() < 1e-9 * e.2);
                    hits += 1;
                }
                (g, e) => assert_eq!(g.is_some(), e.is_some(), "ray {i},{j}"),
            }
        }
    }
    assert!(hits > 300);
}

/// A red diffuse 18 x 18 quad centred on the origin in the plane z = 0 (facing +z), object
/// id `id`, and no lights.
fn red_wall(id: u32) -> Scene {
    let wall = quad(Vec3::ZERO, Vec3::X * 9.0, Vec3::Y * 9.0);
    scene(vec![object(id, wall, RED, Finish::Diffuse)], vec![])
}

#[test]
fn pixels_without_a_projector_get_the_background() {
    let scene = red_wall(1);
    let mut camera = Parallel::new(3, 1, (0.0, 0.0), DVec3::NEG_Z);
    camera.blind = 1.0;
    let (frame, stats) = raycast::render(&PreparedScene::new(&scene), &camera, &flat(8)).unwrap();
    assert_eq!(frame.color, vec![scene.image.background, RED, RED]);
    assert_eq!(frame.depth[0], f32::INFINITY);
    assert_eq!(frame.ids, vec![0, 1, 1]);
    assert_eq!(stats["primary_rays"], Counter::Count(2));
}

#[test]
fn depth_is_euclidean_distance_along_an_unnormalised_projector() {
    let scene = red_wall(3);
    let (color, depth, id) = trace(
        &scene,
        DVec3::new(0.0, 0.0, 4.0),
        DVec3::new(0.0, 3.0, -4.0) * 0.1,
        &flat(8),
    );
    assert_eq!((color, id), (RED, 3));
    assert!((depth - 5.0).abs() < 1e-5);
}

/// A mirror at z = 0 facing +z, a red quad up and to the right where a 45-degree ray lands.
fn mirror_scene(scale: f32) -> Scene {
    let s = |v: Vec3| v * scale;
    scene(
        vec![
            object(
                1,
                quad(Vec3::ZERO, s(Vec3::X * 2.0), s(Vec3::Y * 2.0)),
                GREEN,
                Finish::Mirror,
            ),
            object(
                2,
                quad(s(Vec3::new(2.0, 0.0, 2.0)), s(Vec3::Y), s(Vec3::Z * 0.5)),
                RED,
                Finish::Diffuse,
            ),
        ],
        vec![],
    )
}

#[test]
fn flat_mirror_shows_the_reflected_object_at_any_scene_scale() {
    for scale in [1e-3f32, 1.0, 1e4] {
        let scene = mirror_scene(scale);
        let origin = DVec3::new(-2.0, 0.0, 2.0) * scale as f64;
        let (color, depth, id) = trace(&scene, origin, DVec3::new(1.0, 0.0, -1.0), &flat(8));
        assert_eq!(color, RED, "scale {scale}");
        // Depth and id are the mirror's.
        assert_eq!(id, 1);
        assert!((depth as f64 - 8f64.sqrt() * scale as f64).abs() < 1e-5 * scale as f64);
    }
    // No bounce allowed: the mirror shows the background.
    let scene = mirror_scene(1.0);
    let (color, _, id) = trace(
        &scene,
        DVec3::new(-2.0, 0.0, 2.0),
        DVec3::new(1.0, 0.0, -1.0),
        &flat(0),
    );
    assert_eq!((color, id), (scene.image.background, 1));
}

#[test]
fn facing_mirrors_run_out_of_bounces() {
    let m = |z: f32| {
        object(
            1,
            quad(Vec3::Z * z, Vec3::X * 100.0, Vec3::Y * 100.0),
            GREEN,
            Finish::Mirror,
        )
    };
    let scene = scene(vec![m(0.0), m(1.0)], vec![]);
    let options = flat(8);
    let (color, _, _) = trace(
        &scene,
        DVec3::new(0.0, 0.0, 0.5),
        DVec3::new(0.1, 0.0, -1.0),
        &options,
    );
    assert_eq!(color, scene.image.background);
    let mut camera = Parallel::new(1, 1, (0.0, 0.0), DVec3::new(0.1, 0.0, -1.0));
    camera.corner.z = 0.5;
    let (frame, stats) = raycast::render(&PreparedScene::new(&scene), &camera, &options).unwrap();
    assert_eq!(frame.color[0], scene.image.background);
    assert_eq!(stats["secondary_rays"], Counter::Count(8));
}

/// A glass interface at z = 0 (face normal +z), with coloured targets where rays land.
fn glass_scene(targets: Vec<Object>) -> Scene {
    let mut objects = vec![object(
        1,
        quad(Vec3::ZERO, Vec3::X * 50.0, Vec3::Y * 50.0),
        Vec3::ONE,
        Finish::Glass { ior: 1.5 },
    )];
    objects.extend(targets);
    scene(objects, vec![])
}

#[test]
fn flat_glass_refracts_entering_and_leaving() {
    // Entering at 45 degrees: sin(t) = sin(45)/1.5, so one unit down x grows by 0.5345, not 1.
    let target = |id, x: f32, color| {
        object(
            id,
            quad(Vec3::new(x, 0.0, -1.0), Vec3::X * 0.2, Vec3::Y),
            color,
            Finish::Diffuse,
        )
    };
    let scene = glass_scene(vec![target(2, 1.53, RED), target(3, 2.0, BLUE)]);
    let (color, _, id) = trace(
        &scene,
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, -1.0),
        &flat(8),
    );
    assert_eq!((color, id), (RED, 1));
    // Leaving at 30 degrees from inside: sin(t) = 1.5 * 0.5, one unit up x grows by 1.134.
    let up = |id, x: f32, color| {
        object(
            id,
            quad(Vec3::new(x, 0.0, 1.0), Vec3::Y, Vec3::X * 0.2),
            color,
            Finish::Diffuse,
        )
    };
    let scene = glass_scene(vec![up(2, 0.577 + 1.134, RED), up(3, 1.155, BLUE)]);
    let d = DVec3::new(30f64.to_radians().tan(), 0.0, 1.0);
    let (color, _, _) = trace(&scene, DVec3::new(0.0, 0.0, -1.0), d, &flat(8));
    assert_eq!(color, RED);
}

#[test]
fn flat_glass_total_internal_reflection_reflects() {
    // Leaving at 45 degrees (beyond the 41.8-degree critical angle) reflects back down.
    let below = object(
        2,
        quad(Vec3::new(3.0, 0.0, -2.0), Vec3::X * 0.3, Vec3::Y),
        GREEN,
        Finish::Diffuse,
    );
    let above = object(
        3,
        quad(Vec3::new(2.0, 0.0, 1.0), Vec3::X * 3.0, Vec3::Y),
        RED,
        Finish::Diffuse,
    );
    let scene = glass_scene(vec![below, above]);
    let (color, _, _) = trace(
        &scene,
        DVec3::new(0.0, 0.0, -1.0),
        DVec3::new(1.0, 0.0, 1.0),
        &flat(8),
    );
    assert_eq!(color, GREEN);
}

/// A floor, a box-like occluder, a mirror and a glass pane: enough for every lit path.
fn busy_scene(lights: Vec<Light>) -> Scene {
    scene(
        vec![
            object(
                1,
                quad(Vec3::new(0.0, 0.0, -2.0), Vec3::X * 8.0, Vec3::Y * 8.0),
                Vec3::splat(0.8),
                Finish::Diffuse,
            ),
            object(
                2,
                quad(Vec3::new(-1.0, 0.0, 0.0), Vec3::X, Vec3::Y),
                RED,
                Finish::Diffuse,
            ),
            object(
                3,
                quad(Vec3::new(1.5, 1.5, -1.0), Vec3::new(1.0, 0.0, 0.5), Vec3::Y),
                Vec3::splat(0.9),
                Finish::Mirror,
            ),
            object(
                4,
                quad(
                    Vec3::new(1.0, -2.0, 1.0),
                    Vec3::new(1.0, 0.0, -0.3),
                    Vec3::Y,
                ),
                Vec3::new(0.9, 1.0, 0.9),
                Finish::Glass { ior: 1.5 },
            ),
            object(
                5,
                quad(Vec3::new(-3.0, -3.0, 0.5), Vec3::X * 0.5, Vec3::Y * 0.5),
                GREEN,
                Finish::Emissive,
            ),
        ],
        lights,
    )
}

#[test]
fn lit_shadows_cost_shadow_rays_and_darken() {
    let light = Light::Point {
        position: Vec3::new(-1.0, 0.0, 5.0),
        color: Vec3::ONE,
        intensity: 1.0,
    };
    let scene = busy_scene(vec![light]);
    let lit = RenderOptions {
        shading: Shading::Lit,
        ..flat(8)
    };
    // The floor straight below the occluder is in its shadow: ambient only.
    let (shadowed, _, id) = trace(&scene, DVec3::new(-1.0, 0.0, -1.5), DVec3::NEG_Z, &lit);
    assert_eq!(id, 1);
    assert!((shadowed - Vec3::splat(0.08)).length() < 1e-6, "{shadowed}");
    let (sunny, _, _) = trace(&scene, DVec3::new(-5.0, 5.0, -1.5), DVec3::NEG_Z, &lit);
    assert!(sunny.x > 0.5, "{sunny}");
    // Emissive shows its colour.
    let (glow, _, _) = trace(&scene, DVec3::new(-3.0, -3.0, 3.0), DVec3::NEG_Z, &lit);
    assert_eq!(glow, GREEN);
    // Without lights a headlight lights what the ray sees.
    let dark = busy_scene(vec![]);
    let (head, _, _) = trace(&dark, DVec3::new(-5.0, 5.0, -1.5), DVec3::NEG_Z, &lit);
    assert!(head.x > 0.5, "{head}");
    let (_, stats) = raycast::render(
        &PreparedScene::new(&scene),
        &Parallel::new(8, 8, (-4.0, 4.0), DVec3::NEG_Z),
        &lit,
    )
    .unwrap();
    let Counter::Count(shadow) = stats["shadow_rays"] else {
        panic!()
    };
    assert!(shadow > 0);
}

#[test]
fn rendering_is_deterministic_across_thread_counts_and_reports_progress() {
    let lights = vec![
        Light::Point {
            position: Vec3::new(-1.0, 2.0, 5.0),
            color: Vec3::ONE,
            intensity: 0.7,
        },
        Light::Directional {
            direction: Vec3::new(0.3, -0.2, -1.0),
            color: Vec3::ONE,
            intensity: 0.5,
        },
    ];
    let scene = busy_scene(lights);
    let camera = Parallel {
        direction: DVec3::new(0.1, -0.05, -1.0),
        ..Parallel::new(37, 29, (-4.0, 4.0), DVec3::NEG_Z)
    };
    let caster = PreparedScene::new(&scene);
    let calls = std::sync::Mutex::new(Vec::new());
    let progress = |done: u64, total: u64| calls.lock().unwrap().push((done, total));
    let options = RenderOptions {
        shading: Shading::Lit,
        spp: 4,
        max_bounces: 8,
        progress: Some(&progress),
        ..RenderOptions::default()
    };
    let render_with = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| raycast::render(&caster, &camera, &options).unwrap())
    };
    let (one, stats_one) = render_with(1);
    let (many, stats_many) = render_with(4);
    assert_eq!(one, many);
    assert_eq!(stats_one["rays_cast"], stats_many["rays_cast"]);
    // 37 x 29 pixels in 16 x 16 tiles: 3 x 2 tiles, twice.
    let mut calls = calls.into_inner().unwrap();
    assert_eq!(calls.len(), 12);
    calls.sort();
    assert_eq!(calls.last(), Some(&(6, 6)));
    assert!(one.ids.contains(&3) && one.ids.contains(&4));
}

/// `render_into` a kept frame gives `render`'s new frame, frame after frame, whatever the
/// kept frame held (every pixel is overwritten, edge tiles included: 37 x 29 pixels are
/// not whole 16 x 16 tiles nor 2 x 2 quads), lit with one sample per pixel and with four; a
/// kept frame of another size is replaced by one of the projection's size.
#[test]
fn rendering_into_a_kept_frame_matches_a_new_frame() {
    let light = Light::Point {
        position: Vec3::new(-1.0, 2.0, 5.0),
        color: Vec3::ONE,
        intensity: 0.7,
    };
    let scene = busy_scene(vec![light]);
    let mut camera = Parallel {
        direction: DVec3::new(0.1, -0.05, -1.0),
        ..Parallel::new(37, 29, (-4.0, 4.0), DVec3::NEG_Z)
    };
    camera.blind = 3.0;
    let caster = PreparedScene::new(&scene);
    for spp in [1, 4] {
        let options = RenderOptions {
            shading: Shading::Lit,
            spp,
            ..flat(8)
        };
        let (fresh, fresh_stats) = raycast::render(&caster, &camera, &options).unwrap();
        assert!(fresh.ids.contains(&0) && fresh.ids.contains(&3));
        let mut kept = Frame::new(3, 2, Vec3::ONE);
        for _ in 0..2 {
            let stats = raycast::render_into(&caster, &mut kept, &camera, &options).unwrap();
            assert_eq!(kept, fresh);
            assert_eq!(stats["rays_cast"], fresh_stats["rays_cast"]);
            kept.color.fill(Vec3::splat(7.0));
            kept.depth.fill(0.0);
            kept.ids.fill(99);
        }
    }
}

#[test]
fn supersampling_averages_colour_and_keeps_the_centre_sample_aov() {
    // Pixel 0 spans x in [0, 1]; red left of x = 0.49, blue behind and right of it.
    let left = object(
        1,
        quad(Vec3::new(-4.51, 0.0, 0.0), Vec3::X * 5.0, Vec3::Y * 5.0),
        RED,
        Finish::Diffuse,
    );
    let right = object(
        2,
        quad(Vec3::new(5.5, 0.0, -1.0), Vec3::X * 5.0, Vec3::Y * 5.0),
        BLUE,
        Finish::Diffuse,
    );
    let scene = scene(vec![left, right], vec![]);
    let caster = PreparedScene::new(&scene);
    let camera = Parallel::new(1, 1, (0.0, 0.0), DVec3::NEG_Z);
    let (one, _) = raycast::render(&caster, &camera, &flat(8)).unwrap();
    assert_eq!(
        one.color[0], BLUE,
        "spp 1 samples exactly the centre x = 0.5"
    );
    let (four, stats) =
        raycast::render(&caster, &camera, &RenderOptions { spp: 4, ..flat(8) }).unwrap();
    assert!((four.color[0] - Vec3::new(0.5, 0.0, 0.5)).length() < 1e-6);
    // The two samples nearest the centre tie; the lower index (x = 0.375) is red.
    assert_eq!((four.ids[0], four.depth[0]), (1, 10.0));
    assert_eq!(stats["primary_rays"], Counter::Count(4));
}

#[test]
fn empty_scene_renders_background_and_reports_build_stats() {
    let scene = scene(vec![], vec![]);
    let (frame, stats) = raycast::render(
        &PreparedScene::new(&scene),
        &Parallel::new(2, 2, (0.0, 0.0), DVec3::NEG_Z),
        &flat(8),
    )
    .unwrap();
    assert!(frame.color.iter().all(|&c| c == scene.image.background));
    assert_eq!(stats["bvh_nodes"], Counter::Count(0));
    assert_eq!(stats["triangles"], Counter::Count(0));
    assert!(matches!(stats["bvh_build_ms"], Counter::Value(ms) if ms >= 0.0));
}

/// The image rendered pixel by pixel with single rays, as before packets.
fn render_single_rays(
    caster: &PreparedScene,
    camera: &dyn Projection,
    options: &RenderOptions,
) -> Frame {
    let (w, h) = camera.resolution();
    let mut frame = Frame::new(w, h, caster.scene.image.background);
    let mut tracer = shade::Tracer::new(caster, options);
    for y in 0..h {
        for x in 0..w {
            let ray = camera.ray(DVec2::new(x as f64 + 0.5, y as f64 + 0.5));
            let s = tracer.sample(ray.as_ref());
            let i = (y * w + x) as usize;
            (frame.color[i], frame.depth[i], frame.ids[i]) = (s.color, s.depth, s.id);
        }
    }
    frame
}

#[test]
fn packet_rendering_equals_single_ray_rendering() {
    let light = Light::Point {
        position: Vec3::new(-1.0, 2.0, 5.0),
        color: Vec3::ONE,
        intensity: 0.7,
    };
    let scene = busy_scene(vec![light]);
    let caster = PreparedScene::new(&scene);
    let frame = |position: DVec3, look_at: DVec3| CameraFrame {
        position,
        look_at,
        up: DVec3::Y,
    };
    let cameras: Vec<Box<dyn Projection>> = vec![
        Box::new(Parallel {
            blind: 7.0,
            direction: DVec3::new(0.1, -0.05, -1.0),
            ..Parallel::new(37, 29, (-4.0, 4.0), DVec3::NEG_Z)
        }),
        ProjectionSpec::Perspective {
            frame: frame(DVec3::new(0.5, 0.3, 6.0), DVec3::ZERO),
            fov: 70.0,
        }
        .build(41, 33)
        .unwrap(),
        ProjectionSpec::Fisheye {
            frame: frame(DVec3::new(-0.5, 1.0, 3.0), DVec3::new(0.0, 0.0, -2.0)),
            fov: 180.0,
        }
        .build(35, 35)
        .unwrap(),
    ];
    for camera in &cameras {
        for shading in [Shading::Flat, Shading::Lit] {
            let options = RenderOptions { shading, ..flat(8) };
            let (packets, _) = raycast::render(&caster, camera.as_ref(), &options).unwrap();
            let single = render_single_rays(&caster, camera.as_ref(), &options);
            assert_eq!(packets.ids, single.ids, "{}", camera.kind());
            let bits = |f: &Frame| {
                let c: Vec<[u32; 3]> = f
                    .color
                    .iter()
                    .map(|c| c.to_array().map(f32::to_bits))
                    .collect();
                let d: Vec<u32> = f.depth.iter().map(|d| d.to_bits()).collect();
                (c, d)
            };
            assert_eq!(bits(&packets), bits(&single), "{}", camera.kind());
        }
    }
}

/// The first hit of polyline `points` by searching its segments one by one, each with an
/// unculled BVH search (no scene-box or hull cull): the first segment with a hit wins.
fn segment_by_segment(caster: &PreparedScene, points: &[DVec3]) -> Option<(usize, Hit32)> {
    (0..points.len().saturating_sub(1)).find_map(|k| {
        crate::render::bvh::triangle::FastRay::new(&polyline_segment(points, k))
            .and_then(|fast| caster.bvh.closest(&fast, &crate::render::bvh::AllTriangles))
            .map(|found| (k, caster.hit32(found)))
    })
}

/// Four polylines searched together, each against [`segment_by_segment`].
fn assert_polylines_match(caster: &PreparedScene, polylines: [Option<&[DVec3]>; 4]) {
    let together = caster.intersect4_polylines(polylines, hull_cull::LiveParts::ALL);
    let alone = polylines.map(|p| p.and_then(|p| segment_by_segment(caster, p)));
    assert_eq!(together, alone, "{polylines:?}");
}

/// Degenerate case: a joint exactly on a triangle (the wall z = 0) is hit at the end of the
/// earlier segment (t = 1, its interval is closed), which wins over the later segment's hit
/// at its start, as searching segment by segment finds it; so is a polyline whose later
/// segment runs along the wall's plane.
#[test]
fn a_joint_on_a_triangle_is_hit_by_the_earlier_segment() {
    let caster = PreparedScene::new(&red_wall(1));
    let lane = |x: f64, bend: DVec3| {
        vec![
            DVec3::new(x, 0.25, 2.0),
            DVec3::new(x, 0.25, 0.0),
            DVec3::new(x, 0.25, 0.0) + bend,
        ]
    };
    let polylines = [
        lane(0.25, DVec3::new(0.0, 0.0, -2.0)),
        lane(0.5, DVec3::new(1.0, 0.0, -2.0)),
        lane(-0.25, DVec3::new(1.0, 0.0, 0.0)),
        lane(0.75, DVec3::new(0.0, 0.0, -2.0)),
    ];
    let found = caster.intersect4_polylines(
        polylines.each_ref().map(|p| Some(p.as_slice())),
        hull_cull::LiveParts::ALL,
    );
    for (p, hit) in polylines.iter().zip(found) {
        let (k, hit) = hit.expect("the joint lies on the wall");
        assert_eq!((k, hit.t), (0, 1.0), "{p:?}");
    }
    assert_polylines_match(&caster, polylines.each_ref().map(|p| Some(p.as_slice())));
}

/// Degenerate case: a zero-length segment (a repeated vertex) sees nothing, even with its
/// point on the wall, and the search goes on to the next segment (which finds the wall at
/// its start when it starts there); a polyline of one point has no segment and finds
/// nothing.
#[test]
fn a_zero_length_segment_sees_nothing_and_the_next_segment_is_searched() {
    let caster = PreparedScene::new(&red_wall(1));
    let front = DVec3::new(0.5, 0.5, 1.0);
    let on_wall = DVec3::new(0.5, 0.5, 0.0);
    let behind = DVec3::new(0.5, 0.5, -1.0);
    let repeated_in_front = [front + DVec3::Z, front, front, behind];
    let repeated_on_wall = [on_wall, on_wall, front, behind];
    let single = [front];
    let found = caster.intersect4_polylines(
        [
            Some(&repeated_in_front[..]),
            Some(&repeated_on_wall[..]),
            Some(&single[..]),
            None,
        ],
        hull_cull::LiveParts::ALL,
    );
    assert_eq!(found[0].map(|(k, hit)| (k, hit.t)), Some((2, 0.5)));
    // The segment after the zero-length one starts on the wall: a hit at its start.
    assert_eq!(found[1].map(|(k, hit)| (k, hit.t)), Some((1, 0.0)));
    assert_eq!((found[2], found[3]), (None, None));
    assert_polylines_match(
        &caster,
        [
            Some(&repeated_in_front[..]),
            Some(&repeated_on_wall[..]),
            Some(&single[..]),
            None,
        ],
    );
}

mod polyline_properties {
    use proptest::prelude::*;

    use super::*;

    /// The caster of the built-in teapot room, built once for all cases.
    fn room() -> &'static PreparedScene {
        static ROOM: std::sync::OnceLock<PreparedScene> = std::sync::OnceLock::new();
        ROOM.get_or_init(|| {
            PreparedScene::new(&crate::scene::builtin::load("teapot-room").expect("built-in scene"))
        })
    }

    /// A point of the room (x and z in [-4, 4], y in [-0.5, 3.5]) and around it.
    fn point() -> impl Strategy<Value = DVec3> {
        (-1.2..1.2f64, -1.2..1.2f64, -1.2..1.2f64)
            .prop_map(|(x, y, z)| DVec3::new(x * 4.0, y * 2.0 + 1.5, z * 4.0))
    }

    proptest! {
        /// Four neighbouring polylines of 2 to 6 segments with joints inside the room (a
        /// random polyline and three with every vertex moved by up to `spread`; large
        /// spreads give lanes of disagreeing signs, which the packet search traces one by
        /// one), some lanes empty, some with a repeated vertex (a zero-length segment): the
        /// packet search with its scene-box cull finds for each exactly the first hit (segment, t, object, triangle, barycentrics) of searching its
        /// segments one by one without any cull.
        #[test]
        fn polyline_packets_find_the_unculled_segment_by_segment_first_hit(
            base in proptest::collection::vec(point(), 3..=7),
            moves in proptest::collection::vec(point(), 21),
            spread in prop_oneof![0.0..0.05f64, 0.0..2.0f64],
            empty in 0..16u32,
            repeat in 0..8usize,
        ) {
            let caster = room();
            let polylines: Vec<Vec<DVec3>> = (0..4)
                .map(|i| {
                    let mut points: Vec<DVec3> = base
                        .iter()
                        .enumerate()
                        .map(|(j, &q)| match i {
                            0 => q,
                            _ => q + moves[(i - 1) * 7 + j] * spread,
                        })
                        .collect();
                    if repeat < points.len() && i == repeat % 4 {
                        points.insert(repeat, points[repeat]);
                    }
                    points
                })
                .collect();
            let lanes: [Option<&[DVec3]>; 4] = std::array::from_fn(|i| {
                (empty >> i & 1 == 0).then_some(polylines[i].as_slice())
            });
            let together = caster.intersect4_polylines(lanes, hull_cull::LiveParts::ALL);
            let alone = lanes.map(|p| p.and_then(|p| segment_by_segment(caster, p)));
            prop_assert_eq!(together, alone);
        }
    }
}
