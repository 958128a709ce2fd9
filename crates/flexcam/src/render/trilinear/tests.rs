//! The trilinear renderer against the reference ray caster on the same scene, projection and
//! resolution, and its degenerate cases.

use std::sync::Arc;

use glam::{DVec2, DVec3, Vec3};

use super::outline::ProjectionTriangle;
use super::*;
use crate::projection::TrilinearMesh;
use crate::render::compare::{compare, Comparison};
use crate::render::{raycast, Counter, Shading};
use crate::scene::{self, Light, Material, Mesh, Object, Scene};

/// The fan screen grid of `cells x cells` cells of the bench and the accuracy tables
/// ([`workloads::fan_grid`]: a bent base patch near (0, 1, 5) whose ray directions fan out
/// over 100 x 70 degrees, lengths growing to the right).
fn fan_mesh(cells: u32) -> TrilinearMesh {
    super::workloads::fan_grid(cells).unwrap()
}

fn flat() -> RenderOptions<'static> {
    RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    }
}

/// Renders `scene` through `mesh` at `size` with both renderers; returns the comparison and
/// the trilinear renderer's stats.
fn against_raycast(
    scene: &Scene,
    mesh: &TrilinearMesh,
    size: (u32, u32),
    curves: CurveOptions,
    options: &RenderOptions,
) -> (Comparison, Stats) {
    let projection = Trilinear::new(mesh, size.0, size.1).unwrap();
    let prepared = PreparedScene::new(scene);
    let (reference, _) = raycast::render(&prepared, &projection, options).unwrap();
    let (frame, stats) = TrilinearRenderer::new(&prepared)
        .render(&projection, options, curves)
        .unwrap();
    (compare(&frame, &reference).unwrap(), stats)
}

fn count(stats: &Stats, name: &str) -> u64 {
    match stats.get(name) {
        Some(Counter::Count(n)) => *n,
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn cube_floor_matches_the_ray_caster_through_2_8_and_18_projections() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    for cells in [1, 2, 3] {
        let (c, stats) = against_raycast(
            &scene,
            &fan_mesh(cells),
            (160, 120),
            CurveOptions::ADAPTIVE,
            &flat(),
        );
        println!(
            "{} projections: ids {:.5}, rgb {:.5}, depth max {:.2e} mean {:.2e}",
            2 * cells * cells,
            c.id_agreement,
            c.relative_rgb_error,
            c.depth_max,
            c.depth_mean
        );
        assert!(c.id_agreement >= 0.995, "{c:?}");
        assert!(c.relative_rgb_error <= 0.02, "{c:?}");
        assert!(c.depth_max < 1e-5, "{c:?}");
        assert_eq!(count(&stats, "unprojectable"), 0);
        assert!(count(&stats, "culled_outside") > 0);
    }
}

#[test]
fn every_curve_mode_renders_the_cube_floor() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    for (mode, steps) in [
        (CurveMode::Tessellate, 4),
        (CurveMode::Slice, 10),
        (CurveMode::Adaptive, 256),
    ] {
        let curves = CurveOptions::new(mode, Some(steps)).unwrap();
        let (c, _) = against_raycast(&scene, &fan_mesh(2), (96, 72), curves, &flat());
        println!(
            "{mode} {steps}: ids {:.5}, rgb {:.5}",
            c.id_agreement, c.relative_rgb_error
        );
        assert!(c.id_agreement >= 0.99, "{mode}: {c:?}");
    }
}

#[test]
fn lit_shading_matches_the_ray_caster() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let options = RenderOptions::default();
    let (c, stats) = against_raycast(
        &scene,
        &fan_mesh(2),
        (96, 72),
        CurveOptions::ADAPTIVE,
        &options,
    );
    assert!(c.id_agreement >= 0.995, "{c:?}");
    assert!(c.relative_rgb_error <= 0.02, "{c:?}");
    assert!(count(&stats, "shading_rays") > 0, "shadow rays are cast");
}

#[test]
fn rendering_is_deterministic() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let projection = Trilinear::new(&fan_mesh(2), 80, 60).unwrap();
    let prepared = PreparedScene::new(&scene);
    let renderer = TrilinearRenderer::new(&prepared);
    let (a, _) = renderer
        .render(&projection, &flat(), CurveOptions::ADAPTIVE)
        .unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let (b, _) = pool.install(|| {
        renderer
            .render(&projection, &flat(), CurveOptions::ADAPTIVE)
            .unwrap()
    });
    assert_eq!(a, b);
}

/// `render_into` a kept frame gives `render`'s new frame, frame after frame, whatever the
/// kept frame held (every pixel is overwritten), with one sample per pixel and with four; a
/// kept frame of another size is replaced by one of the projection's size.
#[test]
fn rendering_into_a_kept_frame_matches_a_new_frame() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let projection = Trilinear::new(&fan_mesh(2), 80, 60).unwrap();
    let prepared = PreparedScene::new(&scene);
    let renderer = TrilinearRenderer::new(&prepared);
    for options in [flat(), RenderOptions { spp: 4, ..flat() }] {
        let (fresh, _) = renderer
            .render(&projection, &options, CurveOptions::ADAPTIVE)
            .unwrap();
        let mut kept = Frame::new(3, 2, Vec3::ONE);
        for _ in 0..2 {
            renderer
                .render_into(&mut kept, &projection, &options, CurveOptions::ADAPTIVE)
                .unwrap();
            assert_eq!(kept, fresh);
            kept.color.fill(Vec3::splat(7.0));
            kept.depth.fill(0.0);
            kept.ids.fill(99);
        }
    }
}

/// A new frame starts as zeroed memory (`Frame::zeroed`), not the background: every pixel
/// must still be written, so wherever nothing is hit the frame holds the background, infinite
/// depth and id 0 (a pixel left unwritten would read black, depth 0), and every other pixel a
/// positive finite depth; flat and lit, one sample per pixel and four (whose pixels on an
/// object's outline average hit and missed samples: their colour is not checked).
#[test]
fn a_new_frame_holds_the_background_wherever_nothing_is_hit() {
    let mut scene = scene::load("builtin:cube-floor").unwrap();
    let background = Vec3::new(0.25, 0.5, 0.75);
    scene.image.background = background;
    let projection = Trilinear::new(&fan_mesh(2), 80, 60).unwrap();
    let prepared = PreparedScene::new(&scene);
    let renderer = TrilinearRenderer::new(&prepared);
    for shading in [Shading::Flat, Shading::Lit] {
        for spp in [1, 4] {
            let options = RenderOptions {
                shading,
                spp,
                ..RenderOptions::default()
            };
            let (frame, _) = renderer
                .render(&projection, &options, CurveOptions::ADAPTIVE)
                .unwrap();
            let empty = frame.ids.iter().filter(|&&id| id == 0).count();
            assert!(empty > 0 && empty < frame.ids.len(), "{empty} empty pixels");
            for ((color, depth), id) in frame.color.iter().zip(&frame.depth).zip(&frame.ids) {
                if *id == 0 {
                    assert_eq!(*depth, f32::INFINITY);
                    assert!(spp > 1 || *color == background, "colour {color}");
                } else {
                    assert!(depth.is_finite() && *depth > 0.0, "depth {depth}");
                }
            }
        }
    }
}

/// One object made of the given triangles, flat colour `color`.
pub(super) fn object(id: u32, triangles: &[[DVec3; 3]], color: Vec3) -> Object {
    let mut mesh = Mesh::default();
    for (k, t) in triangles.iter().enumerate() {
        mesh.positions.extend(t.iter().map(|p| p.as_vec3()));
        let first = 3 * k as u32;
        mesh.triangles.push([first, first + 1, first + 2]);
    }
    Object {
        id,
        name: format!("o{id}"),
        mesh: mesh.into(),
        material: Material {
            color,
            ..Material::default()
        },
        world_to_object: glam::Affine3A::IDENTITY,
        displacement: None,
    }
}

pub(super) fn scene_of(objects: Vec<Object>) -> Scene {
    let mut scene = scene::load("builtin:cube-floor").unwrap();
    scene.objects = objects;
    scene.lights = vec![Light::Directional {
        direction: Vec3::new(-0.3, -1.0, -0.2).normalize(),
        color: Vec3::ONE,
        intensity: 1.0,
    }];
    scene
}

/// A mesh of two projection triangles over the unit square z = 0 looking along +z, with
/// the given normal at each corner (bottom-left, bottom-right, top-left, top-right).
pub(super) fn square(normals: [DVec3; 4]) -> TrilinearMesh {
    TrilinearMesh {
        points: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)],
        normals: normals.to_vec(),
        screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y, DVec2::ONE],
        triangles: vec![[0, 1, 3], [0, 3, 2]],
    }
}

fn diverging() -> TrilinearMesh {
    square([
        DVec3::new(-0.3, -0.3, 1.0),
        DVec3::new(0.3, -0.3, 1.0),
        DVec3::new(-0.3, 0.3, 1.0),
        DVec3::new(0.25, 0.35, 1.1),
    ])
}

#[test]
fn degenerate_configurations_match_the_ray_caster() {
    let red = Vec3::new(0.9, 0.1, 0.1);
    let green = Vec3::new(0.1, 0.8, 0.2);
    let cases: Vec<(&str, TrilinearMesh, Vec<[DVec3; 3]>)> = vec![
        (
            // A scene vertex exactly on the base triangle (t = 0), the others in front.
            "vertex on the view plane",
            diverging(),
            vec![[
                DVec3::new(0.5, 0.5, 0.0),
                DVec3::new(-0.5, 0.2, 2.0),
                DVec3::new(1.2, 1.0, 3.0),
            ]],
        ),
        (
            // Straddling the view plane: the part behind is clipped at t = 0 exactly.
            "straddling the view plane",
            diverging(),
            vec![[
                DVec3::new(0.2, 0.3, -1.0),
                DVec3::new(-0.5, 0.2, 2.0),
                DVec3::new(1.2, 1.0, 3.0),
            ]],
        ),
        (
            // A triangle seen edge-on by the central ray: nearly a line.
            "edge-on",
            diverging(),
            vec![[
                DVec3::new(0.5, 0.5, 1.0),
                DVec3::new(0.5, 0.5, 3.0),
                DVec3::new(0.9, 0.9, 2.0),
            ]],
        ),
        (
            // Its shape touches the shared diagonal of the two screen triangles.
            "touching the screen-triangle edge",
            diverging(),
            vec![[
                DVec3::new(0.5, 0.5, 1.5),
                DVec3::new(1.0, 0.2, 1.5),
                DVec3::new(1.1, 0.6, 2.5),
            ]],
        ),
        (
            // Orthographic-like: every normal the same.
            "parallel normals",
            square([DVec3::new(0.1, 0.05, 1.0); 4]),
            vec![
                [
                    DVec3::new(0.1, 0.1, 1.0),
                    DVec3::new(0.9, 0.2, 2.0),
                    DVec3::new(0.4, 0.9, 3.0),
                ],
                [
                    DVec3::new(-1.0, -1.0, 2.5),
                    DVec3::new(2.0, -1.0, 2.5),
                    DVec3::new(0.5, 2.0, 1.5),
                ],
            ],
        ),
    ];
    for (name, mesh, triangles) in cases {
        let objects = vec![
            object(1, &triangles[..1], red),
            object(2, &triangles[1..], green),
        ];
        let scene = scene_of(objects);
        let (c, stats) = against_raycast(&scene, &mesh, (64, 64), CurveOptions::ADAPTIVE, &flat());
        println!(
            "{name}: ids {:.5} rgb {:.5}",
            c.id_agreement, c.relative_rgb_error
        );
        assert!(c.id_agreement >= 0.995, "{name}: {c:?}");
        // The reference's flat depths come from its f32 search: relative error about 1e-7
        // times |origin| / distance, large right behind the view plane.
        assert!(c.depth_mean < 1e-5 && c.depth_max < 1e-4, "{name}: {c:?}");
        assert_eq!(count(&stats, "fallback_triangles"), 0, "{name}");
    }
}

#[test]
fn projection_triangles_degenerating_inside_the_scene_are_split_there() {
    // One projection triangle above cube-floor's cube whose rays cross: its left vertices
    // look right and its right vertex left. Base points and directions have one z each, so
    // the parametric triangle stays horizontal, and its area, -12 - 0.2 t + 0.24 t^2 (the
    // Jacobian over the whole triangle), passes zero at t = 7.5, inside the cube: there it
    // degenerates to a segment. Followed across that depth, the projected shapes' outlines
    // ran through infinity and drew the cube's hidden faces over its top (relative RGB
    // error 0.064 with adaptive curves, 0.062 with slicing); the pairs reaching across it
    // are split at the band around it (`degenerate_band`), nothing is ray cast. The same
    // with the scene and the mesh scaled by 1e-3 and 1e3 and moved 1e4 away: the rule is
    // relative.
    let v = DVec3::new;
    for (scale, shift) in [
        (1.0, DVec3::ZERO),
        (1e-3, DVec3::ZERO),
        (1e3, DVec3::ZERO),
        (1.0, v(1e4, -1e4, 1e4)),
    ] {
        let mut scene = scene::load("builtin:cube-floor").unwrap();
        scene.objects.retain(|o| o.name == "cube");
        for p in &mut Arc::make_mut(&mut scene.objects[0].mesh).positions {
            *p = (p.as_dvec3() * scale + shift).as_vec3();
        }
        let points = [v(-3.0, 4.0, 7.0), v(3.0, 6.0, 7.0), v(-3.0, 6.0, 7.0)];
        let mesh = TrilinearMesh {
            points: points.iter().map(|p| *p * scale + shift).collect(),
            normals: vec![v(0.5, -0.6, -1.0), v(-0.4, -0.3, -1.0), v(0.4, -0.3, -1.0)],
            screen: vec![DVec2::ZERO, DVec2::ONE, DVec2::Y],
            triangles: vec![[0, 1, 2]],
        };
        for (mode, steps) in [
            (CurveMode::Adaptive, None),
            (CurveMode::Slice, None),
            (CurveMode::Tessellate, Some(6)),
        ] {
            let curves = CurveOptions::new(mode, steps).unwrap();
            let (c, stats) = against_raycast(&scene, &mesh, (96, 72), curves, &flat());
            let case = format!("{scale} {shift} {mode}");
            println!(
                "{case}: ids {:.5} rgb {:.6} split {}",
                c.id_agreement,
                c.relative_rgb_error,
                count(&stats, "split_pairs")
            );
            assert_eq!(count(&stats, "fallback_triangles"), 0, "{case}");
            assert_eq!(count(&stats, "unprojectable"), 0, "{case}");
            assert!(count(&stats, "split_pairs") > 0, "{case}");
            assert!(c.id_agreement >= 0.995, "{case}: {c:?}");
            assert!(c.relative_rgb_error <= 0.005, "{case}: {c:?}");
        }
        // The rays turned outwards (x mirrored) diverge: no fold, no split.
        let unfolded = TrilinearMesh {
            normals: mesh.normals.iter().map(|n| v(-n.x, n.y, n.z)).collect(),
            ..mesh
        };
        let (c, stats) =
            against_raycast(&scene, &unfolded, (96, 72), CurveOptions::ADAPTIVE, &flat());
        assert_eq!(count(&stats, "fallback_triangles"), 0, "{scale} {shift}");
        assert_eq!(count(&stats, "split_pairs"), 0, "{scale} {shift}");
        assert!(c.relative_rgb_error <= 0.02, "{scale} {shift}: {c:?}");
    }
}

/// One projection triangle over the base z = 0 whose directions all have z component 1
/// (its parametric triangle at depth `t` lies in the plane z = t) and are not coplanar,
/// degenerating at one depth `t0 > 0` (returned): by two of its rays crossing at a point
/// there (`point`: `t0 = 1 / 0.6`), or by its three ray points falling onto one line
/// without meeting (area `1 - 0.3 t - 0.15 t^2`).
fn degenerate_triangle(point: bool) -> (TrilinearMesh, f64) {
    let v = DVec3::new;
    let (normals, t0) = if point {
        let n = vec![v(0.3, 0.0, 1.0), v(-0.3, 0.0, 1.0), v(0.1, 0.2, 1.0)];
        (n, 1.0 / 0.6)
    } else {
        let n = vec![v(0.0, 0.0, 1.0), v(0.0, 0.3, 1.0), v(0.5, -0.3, 1.0)];
        (n, (0.69_f64.sqrt() - 0.3) / 0.3)
    };
    let mesh = TrilinearMesh {
        points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        normals,
        screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
        triangles: vec![[0, 1, 2]],
    };
    (mesh, t0)
}

/// Scene triangles against the degenerate depth `t0` of [`degenerate_triangle`] (the plane
/// z = t0): reaching across it, touching it with a vertex, lying in it (seen by every
/// projector through it, at t0), each before a backdrop at z = 3; rays crossing at a point
/// and rays falling onto a line. Each agrees with the ray caster on every pixel away from
/// id edges (the projection triangle's hypotenuse runs through pixel centres, which the
/// two renderers may give to either side), nothing ray cast.
#[test]
fn scene_triangles_at_a_degenerate_depth_match_the_ray_caster() {
    let v = DVec3::new;
    let backdrop = [v(-4.0, -4.0, 3.0), v(5.0, -4.0, 3.0), v(0.5, 5.0, 3.0)];
    for point in [true, false] {
        let (mesh, t0) = degenerate_triangle(point);
        let cases: [(&str, [DVec3; 3]); 3] = [
            (
                "reaching across",
                [v(-1.0, -1.0, 1.0), v(2.5, -0.5, 2.6), v(0.0, 2.5, 2.2)],
            ),
            (
                "touching",
                [v(0.4, 0.3, t0), v(2.0, -1.0, 2.8), v(-1.0, 2.0, 2.6)],
            ),
            (
                "lying in it",
                [v(-0.2, -0.3, t0), v(1.0, 0.1, t0), v(0.3, 0.9, t0)],
            ),
        ];
        for (name, triangle) in cases {
            let scene = scene_of(vec![
                object(1, &[triangle], Vec3::new(0.9, 0.1, 0.1)),
                object(2, &[backdrop], Vec3::new(0.1, 0.8, 0.2)),
            ]);
            let projection = Trilinear::new(&mesh, 64, 64).unwrap();
            let prepared = PreparedScene::new(&scene);
            let (reference, _) = raycast::render(&prepared, &projection, &flat()).unwrap();
            for mode in [CurveMode::Adaptive, CurveMode::Slice, CurveMode::Tessellate] {
                let curves = CurveOptions::new(mode, None).unwrap();
                let (frame, stats) = TrilinearRenderer::new(&prepared)
                    .render(&projection, &flat(), curves)
                    .unwrap();
                let (agreement, interior) =
                    crate::render::interior_id_agreement(64, 64, &frame.ids, &reference.ids)
                        .unwrap();
                let case = format!("{name}, point {point}, {mode}");
                println!(
                    "{case}: ids away from edges {agreement:.5} of {interior}, split {}, \
                     unprojectable {}",
                    count(&stats, "split_pairs"),
                    count(&stats, "unprojectable"),
                );
                assert_eq!(count(&stats, "fallback_triangles"), 0, "{case}");
                assert!(count(&stats, "shapes") > 0, "{case}");
                assert!(interior > 1000, "{case}");
                assert!(agreement >= 0.999, "{case}: {agreement}");
                let c = compare(&frame, &reference).unwrap();
                assert!(c.depth_max < 1e-4, "{case}: {c:?}");
            }
        }
    }
}

#[test]
fn unprojectable_pairs_are_ray_cast_and_counted() {
    // Coplanar, distinct normals (all parallel to the plane y = 0): a = 0 for every scene
    // point, b = K2 - N2.ps with N2 along y, so a scene triangle straddling the plane
    // y = K2 / N2.y is open at infinity: unprojectable.
    let mesh = square([
        DVec3::new(-0.4, 0.0, 1.0),
        DVec3::new(0.4, 0.0, 1.2),
        DVec3::new(-0.3, 0.0, 0.8),
        DVec3::new(0.35, 0.0, 1.1),
    ]);
    let triangle = [
        DVec3::new(-2.0, -3.0, 2.0),
        DVec3::new(3.0, -3.0, 2.5),
        // The plane where b changes sign is y = K2 / N2.y, about 12.6 for the first triangle.
        DVec3::new(0.5, 30.0, 3.0),
    ];
    let scene = scene_of(vec![object(1, &[triangle], Vec3::new(0.9, 0.1, 0.1))]);
    let (c, stats) = against_raycast(&scene, &mesh, (48, 48), CurveOptions::ADAPTIVE, &flat());
    assert!(c.id_agreement >= 0.995, "{c:?}");
    assert!(count(&stats, "unprojectable") > 0, "{stats:?}");
    assert!(count(&stats, "fallback_rays") > 0, "{stats:?}");
}

#[test]
fn no_cracks_between_adjacent_projection_triangles() {
    // A wall far away covers the whole view: every pixel the ray caster covers along the
    // shared edges must be covered, and the crossings of a scene edge with a shared
    // projection edge computed from both triangles must coincide.
    let wall = [
        [
            DVec3::new(-20.0, -20.0, -6.0),
            DVec3::new(20.0, -20.0, -6.0),
            DVec3::new(20.0, 20.0, -2.0),
        ],
        [
            DVec3::new(-20.0, -20.0, -6.0),
            DVec3::new(20.0, 20.0, -2.0),
            DVec3::new(-20.0, 20.0, -2.0),
        ],
    ];
    let scene = scene_of(vec![object(1, &wall, Vec3::new(0.5, 0.5, 0.5))]);
    let mesh = fan_mesh(3);
    let projection = Trilinear::new(&mesh, 90, 90).unwrap();
    let prepared = PreparedScene::new(&scene);
    let (frame, _) = TrilinearRenderer::new(&prepared)
        .render(&projection, &flat(), CurveOptions::ADAPTIVE)
        .unwrap();
    let (reference, _) = raycast::render(&prepared, &projection, &flat()).unwrap();
    let uncovered: Vec<usize> = (0..frame.ids.len())
        .filter(|&i| reference.ids[i] != 0 && frame.ids[i] == 0)
        .collect();
    assert!(uncovered.is_empty(), "cracks at {uncovered:?}");

    // Crossing of a scene segment with the shared edge of triangles 0 and 1 (grid vertices
    // 0 and 4, the first cell's diagonal), computed from both triangles.
    let caches = projection.triangle_caches();
    // Triangle 0 is [a, a+1, a+row+1]: the diagonal is its u = 0 line (vertices 1 and 3);
    // triangle 1 is [a, a+row+1, a+row]: the diagonal is its vertices 1 and 2.
    let on_edge = caches[0].ray_point(0.0, 0.5, 3.0);
    let d = DVec3::new(0.5, -0.3, 0.2);
    let (a, b) = (on_edge + d, on_edge - d);
    let crossings = |t: usize, (i, j): (usize, usize)| {
        let tri = mesh.triangles[t];
        let vertex = |k: usize| (mesh.points[tri[k] as usize], mesh.normals[tri[k] as usize]);
        let surface = edge_path::EdgeSurface::new(vertex(i), vertex(j));
        let path = edge_path::EdgePath {
            cache: &caches[t],
            a,
            b,
        };
        let map = ScreenMap::new(
            tri.map(|k| mesh.screen[k as usize]),
            DVec2::new(90.0, 90.0),
            caches[t],
        );
        surface
            .crossing_depths(a, b)
            .filter(|&t| {
                path.segment_parameter(t)
                    .is_some_and(|s| (0.0..=1.0).contains(&s))
            })
            .filter_map(|t| path.at(t).map(|x| map.pixel(x.u, x.v)))
            .collect::<Vec<_>>()
    };
    let (left, right) = (crossings(0, (0, 2)), crossings(1, (0, 1)));
    assert_eq!(left.len(), 1, "{left:?}");
    assert_eq!(right.len(), 1, "{right:?}");
    assert!(
        (left[0] - right[0]).length() < 1e-9,
        "{left:?} vs {right:?}"
    );
}

/// `--spp 4`: the ray caster's sample pattern, colours averaged, depth and id of the sample
/// nearest the centre. The supersampled trilinear image agrees with the supersampled ray
/// caster within the accuracy target, and the edges are anti-aliased: pixels appear whose
/// colour is none of the scene's flat colours (a mix of two or more).
#[test]
fn supersampling_matches_the_ray_caster_and_antialiases_edges() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let options = RenderOptions { spp: 4, ..flat() };
    let mesh = fan_mesh(2);
    let (c, stats) = against_raycast(&scene, &mesh, (160, 120), CurveOptions::ADAPTIVE, &options);
    println!(
        "spp 4: ids {:.5}, rgb {:.5}, depth max {:.2e}",
        c.id_agreement, c.relative_rgb_error, c.depth_max
    );
    assert!(c.id_agreement >= 0.995, "{c:?}");
    assert!(c.relative_rgb_error <= 0.02, "{c:?}");
    assert!(c.depth_max < 1e-5, "{c:?}");

    let projection = Trilinear::new(&mesh, 160, 120).unwrap();
    let prepared = PreparedScene::new(&scene);
    let renderer = TrilinearRenderer::new(&prepared);
    let (one, _) = renderer
        .render(&projection, &flat(), CurveOptions::ADAPTIVE)
        .unwrap();
    let (four, _) = renderer
        .render(&projection, &options, CurveOptions::ADAPTIVE)
        .unwrap();
    // One sample per pixel shows only flat colours (and the background).
    let palette: Vec<Vec3> = one.color.iter().fold(Vec::new(), |mut seen, c| {
        if !seen.contains(c) {
            seen.push(*c);
        }
        seen
    });
    let mixed = four.color.iter().filter(|c| !palette.contains(c)).count();
    println!(
        "{} flat colours, {mixed} anti-aliased pixels",
        palette.len()
    );
    assert!(mixed > 500, "{mixed} anti-aliased pixels");
    // Every sample pass rasterised the same polygons.
    assert_eq!(count(&stats, "raster_polygons") % 4, 0);
}

/// A square at z = 2 cut along its diagonal (shared): its lower (x > y) and upper triangles.
fn diagonal_square() -> [[DVec3; 3]; 2] {
    let (lo, hi) = (DVec3::new(0.25, 0.25, 2.0), DVec3::new(0.75, 0.75, 2.0));
    [
        [lo, DVec3::new(0.75, 0.25, 2.0), hi],
        [lo, hi, DVec3::new(0.25, 0.75, 2.0)],
    ]
}

/// The scene geometry of `triangles` (one red object, id 1) and the projection triangles of
/// an 8 x 8 pixel view of it through parallel rays along +z over the unit square.
fn parallel_rays_onto(triangles: &[[DVec3; 3]]) -> (SceneGeometry, Vec<ProjectionTriangle>) {
    let scene = scene_of(vec![object(1, triangles, Vec3::new(0.9, 0.1, 0.1))]);
    let projection = Trilinear::new(&square([DVec3::Z; 4]), 8, 8).unwrap();
    (
        SceneGeometry::new(&scene),
        projection_triangles(&projection),
    )
}

/// Where several triangles meet at the edge a fragment crossed (non-manifold), each is
/// tried: a fin along the square's diagonal, listed first, is not hit at pixel (3, 3), so
/// the lower triangle's fragment there resolves to the upper triangle behind it in the list.
#[test]
fn fragments_across_a_non_manifold_edge_try_every_triangle_there() {
    let [lower, upper] = diagonal_square();
    let fin = [lower[0], lower[2], DVec3::new(0.75, 0.25, 3.0)];
    let (geometry, triangles) = parallel_rays_onto(&[lower, fin, upper]);
    let resolver = Resolver {
        triangles: &triangles,
        scene: &geometry,
        sample: DVec2::splat(0.5),
    };
    let key = |scene_triangle: u64| (1u64 << 32) | scene_triangle;
    let redirected = resolver.hit(key(0), resolver.position(3, 3)).unwrap();
    assert!(redirected.exact);
    assert_eq!((redirected.key, redirected.t), (key(2), 2.0));
}

/// A fragment keyed to one scene triangle at a pixel just across an edge it shares, inside
/// the neighbour, resolves to an exact hit of the neighbour: the pixel that the neighbour's
/// own polygon left uncovered where its chord cuts inside its curved edge. Before, it became
/// a crack filler pushed behind every exact fragment, so a farther surface of the same
/// object won the pixel (the 4 pixels of `fan_scene_shows_the_nearest_surface_everywhere`).
#[test]
fn fragments_across_a_shared_edge_resolve_to_the_neighbour() {
    let [lower, upper] = diagonal_square();
    let (geometry, triangles) = parallel_rays_onto(&[lower, upper]);
    let resolver = Resolver {
        triangles: &triangles,
        scene: &geometry,
        sample: DVec2::splat(0.5),
    };
    // Pixel (3, 3): screen (0.4375, 0.5625), above the diagonal: the upper triangle's.
    let key = |scene_triangle: u64| (1u64 << 32) | scene_triangle;
    let at = resolver.position(3, 3);
    let own = resolver.hit(key(1), at).unwrap();
    let redirected = resolver.hit(key(0), at).unwrap();
    assert!(own.exact && redirected.exact);
    assert_eq!((redirected.key, redirected.t), (key(1), 2.0));
    assert_eq!(redirected.barycentric, own.barycentric);
    // The stage rewrites the fragment to the neighbour, at its exact depth, with the
    // neighbour's barycentrics, from the hit terms of the fragment's own triangle.
    let uv = triangles[1].map.barycentrics(at);
    let terms = hit_terms::HitTerms::new(geometry.corners(0)).unwrap();
    let (staged_key, depth, stored) = resolver
        .staged(
            key(0),
            hit_terms::solve(&terms.at(&triangles[1].map, uv.x, uv.y)),
            3,
            3,
        )
        .unwrap();
    assert_eq!((staged_key, depth), (key(1), 2.0));
    assert_eq!(stored, own.barycentric);
    // Beyond an edge nobody shares (left of the square): discarded.
    assert!(resolver.hit(key(1), resolver.position(1, 3)).is_none());
}

/// The example scene at its own size: wherever both renderers see the same object, the
/// depth is the same, so trilinear never shows a farther surface of it (before the
/// neighbour resolution, 4 pixels showed the cube's far side, relative depth error 0.54).
#[test]
fn fan_scene_shows_the_nearest_surface_everywhere() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/trilinear-fan.toml");
    let scene = scene::load(path.to_str().unwrap()).unwrap();
    let (width, height) = (scene.image.width, scene.image.height);
    let projection = scene.projection.build(width, height).unwrap();
    let mesh = projection.trilinear().unwrap().mesh().clone();
    let (c, _) = against_raycast(
        &scene,
        &mesh,
        (width, height),
        CurveOptions::ADAPTIVE,
        &flat(),
    );
    println!(
        "fan scene {width}x{height}: ids {:.5}, depth max {:.2e}",
        c.id_agreement, c.depth_max
    );
    assert!(c.depth_max < 1e-5, "{c:?}");
    assert!(c.id_agreement >= 0.9999, "{c:?}");
}

/// The cluster cull is sound: where a cluster's box corners are all beyond one bounding plane
/// of a projection triangle's volume, so is every vertex of its triangles (each of them
/// would be culled on its own). On cube-floor through the 18 fan triangles some clusters are
/// culled and some are not.
#[test]
fn culled_clusters_hold_only_triangles_beyond_the_same_plane() {
    use super::volume_bounds::VolumeBounds;
    let geometry = SceneGeometry::new(&scene::load("builtin:cube-floor").unwrap());
    let mesh = workloads::fan_grid(3).unwrap();
    let (mut culled, mut kept) = (0, 0);
    for t in &mesh.triangles {
        let pick = |values: &[DVec3]| t.map(|i| values[i as usize]);
        let bounds = VolumeBounds::new(pick(&mesh.points), pick(&mesh.normals));
        for cluster in &geometry.clusters {
            let common = cluster
                .box_corners
                .iter()
                .fold(u32::MAX, |m, &c| m & bounds.outside(c));
            if common == 0 {
                kept += 1;
                continue;
            }
            culled += 1;
            for k in cluster.triangles.clone() {
                for v in geometry.corners(k) {
                    assert_ne!(bounds.outside(v) & common, 0, "vertex {v} of triangle {k}");
                }
            }
        }
    }
    assert!(culled > 0 && kept > 0, "{culled} culled, {kept} kept");
}

/// The bench's workloads: the cube-floor fan of 2 to 50 projection triangles diverges; the
/// random grids (nominal rays jittered by up to 0.15 per component) fold in places (one of
/// the 50 triangles of the bench's seed), and are drawn by their shapes there too: nothing
/// is ray cast, within the targets.
#[test]
fn bench_workloads_draw_their_folds_by_their_shapes() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    for cells in 1..=5 {
        let (_, stats) = against_raycast(
            &scene,
            &fan_mesh(cells),
            (40, 30),
            CurveOptions::ADAPTIVE,
            &flat(),
        );
        assert_eq!(count(&stats, "fallback_triangles"), 0, "{cells}");
    }
    let seed = 2005;
    let scene = super::workloads::random_triangles(640, seed + 640);
    for cells in [1, 3, 5] {
        let mesh = super::workloads::random_grid(cells, seed + u64::from(cells)).unwrap();
        let (c, stats) = against_raycast(&scene, &mesh, (64, 64), CurveOptions::ADAPTIVE, &flat());
        assert_eq!(count(&stats, "fallback_triangles"), 0, "{cells}");
        assert!(
            c.id_agreement >= 0.995 && c.relative_rgb_error <= 0.02,
            "{cells}: {c:?}"
        );
    }
}

#[test]
fn pinholes_clip_scene_triangles_running_behind_the_eye() {
    // Every base point at the eye: the view plane t = 0 is undefined, and large scene
    // triangles running from in front of the eye to behind it (one floor quad under and
    // behind the camera; a box the eye is inside) were drawn with wrong outlines: ids
    // 58.7 % and 63.8 %, relative RGB error 0.44 and 0.66. The base is now moved along
    // the rays (`view_plane`), which changes no ray.
    let objects = r#"
[[object]]
name = "floor"
shape = "plane"
size = [12.0, 12.0]
tessellation = 1
color = [0.9, 0.9, 0.9]
checker = { color = [0.1, 0.1, 0.1], size = 1.0 }
[[object]]
name = "box"
shape = "box"
size = [1.0, 1.0, 1.0]
tessellation = 1
face_colors = [[0.9, 0.15, 0.1], [0.1, 0.75, 0.8], [0.2, 0.8, 0.2], [0.8, 0.2, 0.8], [0.15, 0.3, 0.9], [0.95, 0.8, 0.1]]
translate = [0.0, 0.8, 0.0]
[[light]]
type = "directional"
direction = [-0.3, -1.0, -0.5]
"#;
    let v = DVec3::new;
    let normals = vec![
        v(-0.968735180, -0.717256095, -0.260632266),
        v(-0.081669655, -0.717256095, -0.999853537),
        v(-0.250686341, 0.107545334, -1.202673560),
        v(-1.137751867, 0.107545334, -0.463452289),
    ];
    // Inside the box, and above the floor outside it.
    for eye in [v(0.0, 1.0, 0.2), v(0.0, 1.5, 3.0)] {
        let text = format!("[projection]\ntype = \"perspective\"\nposition = [0, 1, 5]\nlook_at = [0, 0, 0]\nfov = 60\n{objects}");
        let scene = scene::file::parse(&text, std::path::Path::new("pinhole.toml")).unwrap();
        let mesh = TrilinearMesh {
            points: vec![eye; 4],
            normals: normals.clone(),
            screen: vec![DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        for mode in [CurveMode::Adaptive, CurveMode::Slice, CurveMode::Tessellate] {
            let curves = CurveOptions::new(mode, None).unwrap();
            let (c, _) = against_raycast(&scene, &mesh, (100, 75), curves, &flat());
            assert!(c.id_agreement >= 0.9999, "{eye} {mode}: {c:?}");
            assert!(c.relative_rgb_error <= 1e-3, "{eye} {mode}: {c:?}");
        }
    }
}
