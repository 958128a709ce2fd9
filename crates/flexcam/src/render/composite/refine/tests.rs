use glam::{DVec2, DVec3, Vec3};

use super::*;
use crate::projection::trilinear_builders::{reflector_surface, ReflectorSurface};
use crate::scene::reflector_fixtures::{
    camera, lens_plane, sphere_and_cube, ReflectorFixture, BALL,
};

const SIZE: (u32, u32) = (160, 120);

/// The fixture sphere's world-space mesh (`segments` tessellation) and the main camera.
fn sphere(segments: u32) -> (Mesh, Perspective) {
    let scene = sphere_and_cube(segments);
    let ball = scene.objects.iter().find(|o| o.id == BALL).unwrap();
    (Mesh::clone(&ball.mesh), camera(&scene, SIZE))
}

/// The T-junctions of `mesh`: (vertex, triangle edge) pairs where the vertex lies strictly
/// inside the edge (a crack in the surface image: the triangles on the two sides of the edge
/// do not share that vertex). Zero-length edges (a sphere's poles) are skipped.
fn t_junctions(mesh: &Mesh) -> usize {
    let mut points: Vec<Vec3> = mesh.positions.clone();
    points.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
    points.dedup();
    let mut found = 0;
    for &[a, b, c] in &mesh.triangles {
        for (p, q) in [(a, b), (b, c), (c, a)] {
            let (p, q) = (mesh.positions[p as usize], mesh.positions[q as usize]);
            let along = q - p;
            let length_sq = along.length_squared();
            if length_sq == 0.0 {
                continue;
            }
            found += points
                .iter()
                .filter(|&&v| {
                    let t = (v - p).dot(along) / length_sq;
                    let off = (v - p - t * along).length();
                    t > 1e-4 && t < 1.0 - 1e-4 && off < 1e-5 * length_sq.sqrt()
                })
                .count();
        }
    }
    found
}

/// The camera of the lens fixture (composite tests): above the plate, seeing it at 15 to
/// 56 degrees of incidence.
fn lens_camera() -> Perspective {
    let scene = ReflectorFixture {
        eye: [0.0, 3.0, 1.5],
        look_at: [0.0, 0.0, 0.0],
        reflector: "shape = \"sphere\"\nmaterial = \"glass\"",
        cube: "size = [0.8, 0.8, 0.8]",
        cell: 0.25,
    }
    .scene("lens.toml");
    camera(&scene, SIZE)
}

/// `mesh` refined as a mirror seen by `camera` with the affine screen map (the default) to
/// `tolerance_px`.
fn mirror(mesh: &Mesh, camera: &Perspective, tolerance_px: f64) -> Refinement {
    refine(
        mesh,
        camera,
        Optic::Reflect,
        SurfaceScreenMap::Affine,
        tolerance_px,
    )
}

/// One triangle centred on `x` whose normals splay apart by about 90 degrees: its mirror
/// rays diverge so fast that no depth of refinement meets a fine tolerance (the depth-cap
/// and off-image tests).
fn splayed_triangle(x: f32) -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(x - 1.0, 0.8, 0.0),
            Vec3::new(x + 1.0, 0.8, 0.0),
            Vec3::new(x, 2.0, 0.0),
        ],
        normals: vec![
            Vec3::new(-1.0, 0.0, 0.1),
            Vec3::new(1.0, 0.0, 0.1),
            Vec3::new(0.0, 1.0, 0.1),
        ],
        triangles: vec![[0, 1, 2]],
        ..Mesh::default()
    }
}

/// Whether every vertex ray and screen position of `surface` is finite.
fn finite(surface: &ReflectorSurface) -> bool {
    let mesh = &surface.mesh;
    mesh.normals.iter().all(|r| r.is_finite()) && mesh.screen.iter().all(|s| s.is_finite())
}

/// `refined` without the triangles refinement leaves whole as facing away
/// (`Refiner::back_facing`): the surface drops them, so a T-junction or an edge over the
/// tolerance on them does not show.
fn front(refined: &Mesh, camera: &Perspective) -> Mesh {
    let refiner = Refiner::new(
        refined,
        camera,
        Optic::Reflect,
        SurfaceScreenMap::Affine,
        1.0,
    );
    let triangles = refined
        .triangles
        .iter()
        .copied()
        .filter(|&t| !refiner.back_facing(t))
        .collect();
    Mesh {
        triangles,
        ..refined.clone()
    }
}

/// Leaving back-facing triangles whole changes no surface: the close 24-segment sphere
/// (its far hemisphere faces away) as a mirror at two tolerances gives the same surface
/// mesh and weights as refining every triangle, from fewer triangles; as glass (whose
/// vertex rays depend on the triangles around them) every triangle is refined, as before.
#[test]
fn back_facing_triangles_left_whole_change_no_surface() {
    let (mesh, camera) = sphere(24);
    let glass = Optic::Refract { ior: 1.5 };
    for (optic, tolerance) in [(Optic::Reflect, 0.5), (Optic::Reflect, 0.1), (glass, 0.5)] {
        let map = SurfaceScreenMap::Affine;
        let whole = refine(&mesh, &camera, optic, map, tolerance);
        let refiner = Refiner::new(&mesh, &camera, optic, map, tolerance);
        let all = refine_where(&mesh, refiner, |_, _| false);
        let surface = |r: &Refinement| reflector_surface(&r.mesh, &camera, optic).unwrap();
        let (a, b) = (surface(&whole), surface(&all));
        println!(
            "{optic:?} {tolerance} px: {} triangles refined instead of {}, {} kept",
            whole.mesh.triangles.len(),
            all.mesh.triangles.len(),
            a.mesh.triangles.len()
        );
        if optic == Optic::Reflect {
            assert!(whole.mesh.triangles.len() < all.mesh.triangles.len());
        } else {
            assert_eq!(whole.mesh, all.mesh);
        }
        assert!(!a.mesh.triangles.is_empty());
        assert_eq!((a.mesh, a.weights), (b.mesh, b.weights));
        assert_eq!(whole.unsplit, all.unsplit);
    }
}

#[test]
fn refinement_is_crack_free() {
    let (mesh, camera) = sphere(24);
    let refined = mirror(&mesh, &camera, 0.5);
    assert!(
        refined.mesh.triangles.len() > mesh.triangles.len(),
        "the close sphere is refined: {} triangles",
        refined.mesh.triangles.len()
    );
    refined.mesh.validate().unwrap();
    // No vertex lies inside another triangle's edge (across the sphere's seam too, whose
    // vertices the input mesh duplicates), among the triangles the surface can keep.
    assert_eq!(t_junctions(&mesh), 0);
    assert_eq!(t_junctions(&front(&refined.mesh, &camera)), 0);
    // The refined surface covers exactly the screen area of the unrefined one: the sum of
    // its kept triangles' screen areas is the same (no gaps, no overlaps added).
    let area = |s: &ReflectorSurface| -> f64 {
        s.mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|k| s.mesh.screen[k as usize]);
                0.5 * (b - a).perp_dot(c - a).abs()
            })
            .sum()
    };
    let before = reflector_surface(&mesh, &camera, Optic::Reflect).unwrap();
    let after = reflector_surface(&refined.mesh, &camera, Optic::Reflect).unwrap();
    let (a0, a1) = (area(&before), area(&after));
    println!("screen area {a0:.6} -> {a1:.6}");
    assert!((a1 - a0).abs() < 1e-3 * a0, "{a0} vs {a1}");
}

#[test]
fn new_vertices_carry_the_ray_casters_interpolated_normals() {
    let (mesh, camera) = sphere(16);
    let refined = mirror(&mesh, &camera, 0.5);
    let n = mesh.positions.len();
    assert!(refined.mesh.positions.len() > n);
    // The input vertices are unchanged.
    assert_eq!(&refined.mesh.positions[..n], &mesh.positions[..]);
    assert_eq!(&refined.mesh.normals[..n], &mesh.normals[..]);
    // Every new vertex lies on a reflector triangle, at barycentrics whose interpolation of
    // the raw vertex normals (the ray caster's shading normal before normalising) is its
    // normal.
    for k in n..refined.mesh.positions.len() {
        let p = refined.mesh.positions[k];
        let found = mesh.triangles.iter().any(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let (e1, e2, d) = (b - a, c - a, p - a);
            let normal = e1.cross(e2);
            if normal.length() < 1e-9 || d.dot(normal).abs() > 1e-5 * normal.length() {
                return false;
            }
            let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
            let det = d11 * d22 - d12 * d12;
            let u = (d22 * d.dot(e1) - d12 * d.dot(e2)) / det;
            let v = (d11 * d.dot(e2) - d12 * d.dot(e1)) / det;
            let w = 1.0 - u - v;
            if u < -1e-5 || v < -1e-5 || w < -1e-5 {
                return false;
            }
            let [na, nb, nc] = t.map(|i| mesh.normals[i as usize]);
            let expected = na * w + nb * u + nc * v;
            (expected - refined.mesh.normals[k]).length() < 1e-4
        });
        assert!(found, "new vertex {k} at {p} is not on the reflector");
    }
}

#[test]
fn refinement_stops_within_the_tolerance() {
    let (mesh, camera) = sphere(24);
    let mut counts = Vec::new();
    for tolerance in [0.0, 2.0, 0.5, 0.1] {
        let refined = mirror(&mesh, &camera, tolerance);
        counts.push(refined.mesh.triangles.len());
        assert_eq!(refined.unsplit, 0, "tolerance {tolerance}");
        // Every remaining edge is within the bound (decided again from scratch).
        let mut check = Refiner::new(
            &refined.mesh,
            &camera,
            Optic::Reflect,
            SurfaceScreenMap::Affine,
            tolerance.max(1e-9),
        );
        if tolerance > 0.0 {
            let vertices = check.positions.len();
            for &[a, b, c] in &front(&refined.mesh, &camera).triangles {
                for (p, q) in [(a, b), (b, c), (c, a)] {
                    check.midpoint(p, q);
                }
            }
            assert_eq!(check.positions.len(), vertices, "tolerance {tolerance}");
        }
    }
    println!("triangles at tolerance 0 / 2 / 0.5 / 0.1 px: {counts:?}");
    assert!(counts[0] < counts[1] && counts[1] < counts[2] && counts[2] < counts[3]);
    assert_eq!(counts[0], mesh.triangles.len());
}

#[test]
fn zero_tolerance_is_the_mesh_unchanged() {
    let (mesh, camera) = sphere(8);
    let refined = mirror(&mesh, &camera, 0.0);
    assert_eq!(refined.mesh, mesh);
}

/// Where the surface's interpolation is exact (the projective map with straight rays at
/// ior 1, or a flat mirror), nothing is split however small the tolerance.
#[test]
fn exact_interpolation_needs_no_split() {
    let mut plate = lens_plane(1.2, 2.2);
    plate.normals.fill(Vec3::Y);
    let scene = sphere_and_cube(8);
    let camera = camera(&scene, SIZE);
    for optic in [Optic::Refract { ior: 1.0 }, Optic::Reflect] {
        let refined = refine(&plate, &camera, optic, SurfaceScreenMap::Projective, 1e-3);
        assert_eq!(
            refined.mesh.triangles.len(),
            plate.triangles.len(),
            "{optic:?}"
        );
        assert_eq!(refined.unsplit, 0);
    }
}

/// Parallel end rays (zero spread) fall back on the pixel angle: an exact midpoint ray is no
/// error, a turned one a finite number of pixels.
#[test]
fn parallel_vertex_rays_have_a_finite_error() {
    let (mesh, camera) = sphere(8);
    let refiner = Refiner::new(
        &mesh,
        &camera,
        Optic::Reflect,
        SurfaceScreenMap::Affine,
        0.5,
    );
    let sample = |unit: DVec3, x: f64| Sample {
        point: DVec3::new(0.0, 1.0, 0.0),
        unit,
        interpolated: unit,
        pixel: DVec2::new(x, 60.0),
        entering: true,
    };
    let d = DVec3::new(0.0, 0.6, 0.8);
    let (p, q) = (sample(d, 70.0), sample(d, 90.0));
    assert_eq!(refiner.error_px(&p, &q, &sample(d, 80.0)), 0.0);
    let turned = DVec3::new(0.01, 0.6, 0.8).normalize();
    let error = refiner.error_px(&p, &q, &sample(turned, 80.0));
    let pixel = refiner.pixel_angle(DVec2::new(80.0, 60.0));
    assert!(error.is_finite() && error > 0.0);
    assert!((error - angle(d, turned) / pixel).abs() < 1e-9 * error);
    // Coincident ends on screen (zero length): the spread is not finite, the floor is used.
    assert!(refiner.error_px(&p, &p, &sample(turned, 70.0)).is_finite());
}

/// A pathological reflector (normals turning by 180 degrees across one triangle) at a
/// tolerance far below a pixel stops at the depth cap: at most `4^MAX_LEVEL` triangles, the
/// edges still over the tolerance counted, every vertex ray finite.
#[test]
fn the_depth_cap_bounds_a_pathological_mesh() {
    let scene = sphere_and_cube(8);
    let camera = camera(&scene, (1600, 1200));
    let mesh = splayed_triangle(0.0);
    let refined = mirror(&mesh, &camera, 1e-6);
    let count = refined.mesh.triangles.len();
    println!("{count} triangles, {} edges left over", refined.unsplit);
    assert!(count <= 4usize.pow(MAX_LEVEL), "{count}");
    assert!(count >= 4usize.pow(MAX_LEVEL - 1), "{count}");
    assert!(refined.unsplit > 0);
    refined.mesh.validate().unwrap();
    let surface = reflector_surface(&refined.mesh, &camera, Optic::Reflect).unwrap();
    assert!(finite(&surface));
}

/// A glass plate of ior 0.5 (entering it is like leaving glass of index 2): vertices seen
/// beyond the critical angle (30 degrees) totally reflect, the others refract. The ray
/// jumps across that line, so the triangles across it are refined down to the pixel limit
/// (the jump cannot be interpolated away) and the rest are not; every new vertex's ray is
/// the exact one, the mirror ray where it totally reflects.
#[test]
fn total_internal_reflection_at_new_vertices() {
    let mut plate = lens_plane(1.2, 2.2);
    plate.normals.fill(Vec3::Y);
    let camera = lens_camera();
    let optic = Optic::Refract { ior: 0.5 };
    let refined = refine(&plate, &camera, optic, SurfaceScreenMap::Projective, 0.5);
    let n = plate.positions.len();
    println!(
        "{} -> {} triangles, {} edges left at the pixel limit",
        plate.triangles.len(),
        refined.mesh.triangles.len(),
        refined.unsplit
    );
    assert!(refined.mesh.triangles.len() > plate.triangles.len());
    let eye = camera.basis().origin;
    let (mut reflected, mut refracted) = (0, 0);
    for k in n..refined.mesh.positions.len() {
        let i = (refined.mesh.positions[k].as_dvec3() - eye).normalize();
        let cos = -i.dot(DVec3::Y);
        let ray = vertex_ray(i, DVec3::Y, DVec3::Y, optic);
        if 2.0 * (1.0 - cos * cos).sqrt() > 1.0 {
            assert!((ray - (i + 2.0 * cos * DVec3::Y)).length() < 1e-9);
            reflected += 1;
        } else {
            assert!(ray.dot(DVec3::Y) < 0.0, "refracted into the plate");
            refracted += 1;
        }
    }
    assert!(reflected > 0 && refracted > 0, "{reflected} {refracted}");
    // The refined surface builds, its rays finite.
    let surface = reflector_surface(&refined.mesh, &camera, optic).unwrap();
    assert!(finite(&surface));
}

/// A vertex whose ray grazes its normal (incidence at 90 degrees) keeps the ray caster's
/// continuation; refinement around it is finite and valid.
#[test]
fn grazing_vertex_rays_refine_finitely() {
    let scene = sphere_and_cube(8);
    let camera = camera(&scene, SIZE);
    let eye = camera.basis().origin.as_vec3();
    let positions = vec![
        Vec3::new(-0.5, 0.8, 0.0),
        Vec3::new(0.5, 0.8, 0.0),
        Vec3::new(0.0, 1.4, 0.2),
    ];
    // Vertex 0's normal is perpendicular to its eye ray.
    let i0 = (positions[0] - eye).normalize();
    let n0 = i0.cross(Vec3::Y).cross(i0).normalize();
    let mesh = Mesh {
        normals: vec![n0, Vec3::Z, Vec3::Z],
        positions,
        triangles: vec![[0, 1, 2]],
        ..Mesh::default()
    };
    let refined = mirror(&mesh, &camera, 0.5);
    refined.mesh.validate().unwrap();
    assert!(refined.mesh.triangles.len() <= 4usize.pow(MAX_LEVEL));
    let surface = reflector_surface(&refined.mesh, &camera, Optic::Reflect).unwrap();
    assert!(!surface.mesh.triangles.is_empty());
    assert!(finite(&surface));
}

/// Edges beyond one side of the main image are not split, however far their rays are from
/// the exact ones: the pathological triangle of the depth-cap test moved out of view to the
/// left (still in front of the eye) stays whole.
#[test]
fn edges_outside_the_image_are_not_split() {
    let scene = sphere_and_cube(8);
    let camera = camera(&scene, SIZE);
    let mesh = splayed_triangle(-8.0);
    for p in &mesh.positions {
        let pixel = camera.project_continuous(p.as_dvec3()).unwrap().pixel;
        assert!(pixel.x < 0.0, "{pixel}");
    }
    let refined = mirror(&mesh, &camera, 1e-6);
    assert_eq!(refined.mesh.triangles, mesh.triangles);
    assert_eq!(refined.unsplit, 0);
}

#[test]
fn a_nan_tolerance_is_no_refinement() {
    let (mesh, camera) = sphere(8);
    let refined = mirror(&mesh, &camera, f64::NAN);
    assert_eq!(refined.mesh, mesh);
}

/// The example glass cap (scenes/camtri-caustic-glass.toml) seen from low down: its far side
/// curves away from the eye, and across the silhouette there the eye's ray enters the glass
/// at grazing incidence at one end of an edge (refracted to the critical angle, bent by
/// `90° - asin(1 / ior)` = 41.2 degrees) and leaves it at the other (nearly straight on):
/// the exact image jumps, and no split brings such an edge within the tolerance. They are
/// split to under a pixel and counted as silhouette edges, apart from those over the
/// tolerance (measured: 67 silhouette edges; 10 edges are still over the tolerance, with
/// both ends on one side: docs/log/glass22.md).
#[test]
fn a_glass_silhouette_is_split_to_a_pixel_and_counted_apart() {
    let scene = crate::scene::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/camtri-caustic-glass.toml"
    ))
    .unwrap();
    let lens = &scene.objects[0];
    let crate::scene::Finish::Glass { ior } = lens.material.finish else {
        panic!("not glass")
    };
    let optic = Optic::Refract {
        ior: f64::from(ior),
    };
    let entry = &scene.trilinear_reflectors[0];
    let camera = camera(&scene, (320, 240));
    let refined = refine(
        &lens.mesh,
        &camera,
        optic,
        entry.screen_map,
        entry.refine_px,
    );
    println!(
        "{} -> {} triangles, {} silhouette edges, {} over the tolerance",
        lens.mesh.triangles.len(),
        refined.mesh.triangles.len(),
        refined.silhouette,
        refined.unsplit
    );
    assert!(refined.silhouette > 20, "{}", refined.silhouette);
    let mirror = refine(
        &lens.mesh,
        &camera,
        Optic::Reflect,
        entry.screen_map,
        entry.refine_px,
    );
    assert_eq!(mirror.silhouette, 0);
}
