//! Per-fragment mirror rays (the paper's reflection variant) by camera triangles: both bounds
//! hold every fragment, the image is the ray caster's of the same rays, and against the
//! exact mirror the variant is at least as accurate as interpolated rays.

use super::tests::{count, fragments_in_bounds, load, mirror_surface, options};
use super::*;
use crate::projection::trilinear_builders::SurfaceRays;
use crate::render::compare::compare;
use crate::render::composite::env_map::tests::errors;
use crate::render::Method;
use crate::scene::Scene;

/// Mirror scenes whose reflector is curved: convex, concave, saddle-shaped, bumpy normals.
const MIRRORS: [&str; 5] = [
    "reflect-sphere-cube",
    "reflect-funny-mirror",
    "camtri-convex",
    "camtri-concave",
    "camtri-mixed",
];

/// A reflector's camera mesh: simplified to a size, or its own mesh refined to a tolerance in
/// pixels (0: unrefined). The concave mirror's mesh cannot be simplified (its faces are not
/// consistently oriented), so it is measured at its own mesh.
#[derive(Debug, Clone, Copy)]
enum CameraMesh {
    Size(usize),
    RefinePx(f64),
}

/// `scene` with its (first) reflector's camera rays set to `rays` and its camera mesh to
/// `mesh` (`None`: as the file says).
fn with_rays(mut scene: Scene, rays: SurfaceRays, mesh: Option<CameraMesh>) -> Scene {
    let entry = &mut scene.trilinear_reflectors[0];
    entry.camera_rays = rays;
    match mesh {
        Some(CameraMesh::Size(n)) => entry.camera_triangles = Some(n),
        Some(CameraMesh::RefinePx(px)) => entry.refine_px = px,
        None => {}
    }
    scene
}

/// The relative RGB error over the reflector's pixels of `name` with rays `rays` and camera
/// mesh `mesh` against the exact mirror, rendered by camera triangles at `size`, flat.
fn reflector_error(name: &str, rays: SurfaceRays, mesh: CameraMesh, size: (u32, u32)) -> f64 {
    let scene = with_rays(load(name), rays, Some(mesh));
    let (ids, _, rgb) = errors(&scene, size, Method::CameraTriangles, 1);
    assert!(rgb.is_finite() && ids > 0.99, "{name}: ids {ids}");
    rgb
}

/// Every pixel whose per-fragment ray hits a scene triangle lies in a region of either bound
/// (brute force, pair by pair), on reflection surfaces whose rays diverge, converge and
/// cross.
#[test]
fn bounds_hold_every_per_fragment_ray() {
    for name in MIRRORS {
        let (projection, scene) = mirror_surface(name, SurfaceRays::PerFragment);
        assert!(projection.fragment_mirror().is_some());
        let checked = fragments_in_bounds(name, &projection, &scene);
        assert!(checked > 100, "{name}: {checked}");
        // The cone is the usual case, the whole camera triangle the exception.
        let cameras = Camera::all(&projection);
        let coned = cameras.iter().filter(|c| c.cone(camera::CORNERS).is_some());
        assert!(coned.count() * 2 > cameras.len(), "{name}");
    }
}

/// Composited by camera triangles with either bound, the per-fragment surfaces give the image
/// of the ray caster following the same rays (`Trilinear::ray` reflects per fragment too):
/// both render the same rays exactly. The stats count fragments.
#[test]
fn per_fragment_surfaces_render_as_the_ray_caster_does() {
    for name in MIRRORS {
        let scene = with_rays(load(name), SurfaceRays::PerFragment, None);
        let main = scene.projection.build(160, 120).unwrap();
        let prepared = PreparedScene::new(&scene);
        let raycast = RenderOptions {
            method: Method::Raycast,
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        let reference = crate::render::render(&prepared, main.as_ref(), &raycast).unwrap();
        let mut images = Vec::new();
        for bound in [Bound::Tight, Bound::Paper] {
            let ours =
                crate::render::render(&prepared, main.as_ref(), &options(Shading::Flat, bound))
                    .unwrap();
            let c = compare(&ours.frame, &reference.frame).unwrap();
            println!("{name} {bound:?}: {c:?}");
            assert!(c.id_agreement == 1.0, "{name}: {c:?}");
            assert!(c.relative_rgb_error < 0.002, "{name}: {c:?}");
            assert!(count(&ours.counters, "rendered_fragments") > 0, "{name}");
            images.push(ours.frame);
        }
        assert_eq!(images[0].color, images[1].color, "{name}");
    }
}

/// Against the exact mirror (the ray caster with no trilinear reflector), the relative RGB
/// error over the reflector's pixels of per-fragment rays is at most that of interpolated
/// rays, at camera meshes from coarse to the object's own, on the convex, concave and mixed
/// mirrors (the paper's claim for its reflection variant).
#[test]
fn per_fragment_rays_are_at_least_as_accurate() {
    use CameraMesh::{RefinePx, Size};
    for (name, mesh) in [
        ("camtri-convex", Size(64)),
        ("camtri-convex", Size(256)),
        ("camtri-concave", RefinePx(0.0)),
        ("camtri-mixed", Size(256)),
        ("camtri-mixed", Size(1024)),
    ] {
        let error = |rays| reflector_error(name, rays, mesh, (160, 120));
        let (interpolated, per_fragment) = (
            error(SurfaceRays::Interpolated),
            error(SurfaceRays::PerFragment),
        );
        println!("{name} {mesh:?}: interpolated {interpolated:.4}, per fragment {per_fragment:.4}");
        assert!(
            per_fragment <= interpolated,
            "{name} {mesh:?}: {per_fragment} > {interpolated}"
        );
    }
}

/// The trilinear method renders interpolated rays only and says so; glass refuses
/// per-fragment rays.
#[test]
fn per_fragment_rays_are_refused_where_they_are_not_rendered() {
    let scene = with_rays(load("camtri-convex"), SurfaceRays::PerFragment, None);
    let main = scene.projection.build(32, 24).unwrap();
    let trilinear = RenderOptions {
        method: Method::Trilinear,
        ..RenderOptions::default()
    };
    let e = crate::render::render(&PreparedScene::new(&scene), main.as_ref(), &trilinear);
    assert_eq!(
        e.unwrap_err().to_string(),
        "the trilinear method renders interpolated rays only: a reflector with camera_rays = \
         \"per-fragment\" needs --method camera-triangles or raycast"
    );
    let glass = with_rays(load("camtri-refract"), SurfaceRays::PerFragment, None);
    let main = glass.projection.build(32, 24).unwrap();
    let e = crate::render::render(
        &PreparedScene::new(&glass),
        main.as_ref(),
        &options(Shading::Flat, Bound::Tight),
    );
    let id = glass.trilinear_reflectors[0].id;
    assert_eq!(
        e.unwrap_err().to_string(),
        format!(
            "trilinear reflector {id}: per-fragment camera rays need a mirror (glass is \
             refracted by interpolated rays only)"
        )
    );
}

/// The figures of docs/camera-triangles.md: per camera mesh size, the relative RGB error
/// over the reflector's pixels of both modes against the exact mirror (320 x 240, flat;
/// `None`: the automatic size, refined).
/// `cargo test --release -p flexcam --lib per_fragment_accuracy_table -- --ignored --nocapture`
#[test]
#[ignore = "a measurement for the docs (minutes)"]
fn per_fragment_accuracy_table() {
    use CameraMesh::{RefinePx, Size};
    for (name, meshes) in [
        ("camtri-convex", [Size(16), Size(64), Size(256), Size(528)]),
        (
            "camtri-concave",
            [RefinePx(0.0), RefinePx(2.0), RefinePx(0.5), RefinePx(0.25)],
        ),
        (
            "camtri-mixed",
            [Size(64), Size(256), Size(1024), Size(2048)],
        ),
    ] {
        for mesh in meshes {
            let [a, b] = [SurfaceRays::Interpolated, SurfaceRays::PerFragment]
                .map(|rays| reflector_error(name, rays, mesh, (320, 240)));
            println!("| {name} | {mesh:?} | {a:.4} | {b:.4} |");
        }
    }
}
