use glam::{DVec2, DVec3, Vec2};

use super::*;
use crate::geometry::Ray;
use crate::projection::Projection;
use crate::render::normals;
use crate::render::PreparedScene;
use crate::scene::reflector_fixtures::{self as test_scenes, lens_plane, BALL_CENTER};
use crate::scene::{Mesh, Scene};

const SIZE: (u32, u32) = (160, 120);

/// The shared sphere-and-cube fixture (32-segment sphere, as in the compositing tests).
fn scene() -> Scene {
    test_scenes::sphere_and_cube(32)
}

fn camera() -> Perspective {
    test_scenes::camera(&scene(), SIZE)
}

/// The main camera's eye.
fn eye() -> DVec3 {
    camera().basis().origin
}

/// The lens of the fixtures at y = 0, normals radiating from (0, -2, 0).
fn lens() -> Mesh {
    lens_plane(0.0, 2.0)
}

#[test]
fn vertex_rays_are_the_ray_casters_mirror_reflections() {
    let scene = scene();
    let caster = PreparedScene::new(&scene);
    let ball = &scene.objects[0];
    let camera = camera();
    let surface = reflector_surface(ball.mesh.as_ref(), &camera, Optic::Reflect).unwrap();
    let mut checked = 0;
    for k in 0..surface.mesh.points.len() {
        let p = surface.mesh.points[k];
        let ray = Ray::new(eye(), p - eye());
        let Some(hit) = caster.intersect(&ray) else {
            continue;
        };
        // Only vertices the eye sees directly (not grazed past, not hidden).
        if hit.object != 0 || (ray.at(hit.t) - p).length() > 1e-5 {
            continue;
        }
        // The ray caster's mirror at exactly the vertex: the hit triangle's corner there.
        let corners =
            ball.mesh.triangles[hit.triangle].map(|i| ball.mesh.positions[i as usize].as_dvec3());
        let corner = (0..3)
            .min_by(|&a, &b| corners[a].distance(p).total_cmp(&corners[b].distance(p)))
            .unwrap();
        let at_vertex = [Vec2::ZERO, Vec2::X, Vec2::Y][corner];
        let n = normals(ball, hit.triangle, at_vertex, ray.direction.as_vec3());
        let exact = reflect(ray.direction.normalize(), n.shading.as_dvec3());
        let distance = ray.direction.length();
        let got = surface.mesh.normals[k] / distance;
        assert!(
            (got - exact).length() < 1e-6,
            "vertex {k}: {got} vs {exact}"
        );
        assert!(
            (got.length() - 1.0).abs() < 1e-12,
            "rays as long as the eye's distance"
        );
        // The screen weight is 1 / the vertex's forward depth.
        let depth = (surface.mesh.points[k] - eye()).dot(camera.basis().forward);
        assert!((surface.weights[k] * depth - 1.0).abs() < 1e-12);
        // The screen position is the main image position of the vertex: the main camera's
        // ray through it points at the vertex.
        let s = surface.mesh.screen[k];
        let pixel = DVec2::new(s.x * f64::from(SIZE.0), (1.0 - s.y) * f64::from(SIZE.1));
        let main = camera.ray(pixel).unwrap();
        assert!((main.direction - ray.direction.normalize()).length() < 1e-12);
        checked += 1;
    }
    assert!(checked > 80, "{checked} vertices checked");
}

#[test]
fn back_and_hidden_triangles_are_left_out() {
    let scene = scene();
    let ball = scene.objects[0].mesh.as_ref();
    let surface = reflector_surface(ball, &camera(), Optic::Reflect).unwrap();
    let total = ball.triangles.len();
    assert_eq!(surface.dropped + surface.mesh.triangles.len(), total);
    // The kept triangles are about the cap the eye sees: the fraction (1 - r / d) / 2 of a
    // sphere of radius r = 1 seen from distance d.
    let (center, eye) = (BALL_CENTER, eye());
    let cap = 0.5 * (1.0 - 1.0 / eye.distance(center));
    let kept = surface.mesh.triangles.len() as f64 / total as f64;
    assert!((kept - cap).abs() < 0.05, "kept {kept}, cap {cap}");
    // Every kept triangle faces the eye (outward face normal towards it), nearer first.
    let mut last = 0.0;
    for t in &surface.mesh.triangles {
        let [a, b, c] = t.map(|k| surface.mesh.points[k as usize]);
        let face = (b - a).cross(c - a);
        assert!(face.dot(a - center) > 0.0, "outward winding");
        assert!(face.dot(eye - a) > 0.0, "a back-facing triangle was kept");
        let distance = ((a + b + c) / 3.0).distance(eye);
        assert!(distance >= last);
        last = distance;
    }
    // The surface is a valid trilinear projection in the main image.
    assert!(crate::projection::Trilinear::new(&surface.mesh, SIZE.0, SIZE.1).is_ok());
}

#[test]
fn reflectors_behind_the_camera_give_an_empty_surface() {
    let scene = scene();
    let mut ball = (*scene.objects[0].mesh).clone();
    ball.transform(&glam::Affine3A::from_translation(glam::Vec3::new(
        0.0, 0.0, 10.0,
    )));
    let surface = reflector_surface(&ball, &camera(), Optic::Reflect).unwrap();
    assert!(surface.mesh.triangles.is_empty() && surface.mesh.points.is_empty());
    // Partly behind: the eye plane cuts the sphere (centred on it, 1.5 to the right of the
    // eye), the triangles across it are left out.
    let basis = *camera().basis();
    let mut ball = (*scene.objects[0].mesh).clone();
    let shift = basis.origin + 1.5 * basis.right - BALL_CENTER;
    ball.transform(&glam::Affine3A::from_translation(shift.as_vec3()));
    let surface = reflector_surface(&ball, &camera(), Optic::Reflect).unwrap();
    assert!(!surface.mesh.triangles.is_empty(), "the front half is seen");
    for p in &surface.mesh.points {
        assert!((*p - basis.origin).dot(basis.forward) > 0.0);
    }
    assert!(surface.dropped > 0);
}

#[test]
fn meshes_without_normals_use_face_normals() {
    let mut plane = lens();
    plane.normals.clear();
    let surface = reflector_surface(&plane, &camera(), Optic::Reflect).unwrap();
    assert_eq!(surface.mesh.triangles.len(), 50);
    for (p, r) in surface.mesh.points.iter().zip(&surface.mesh.normals) {
        // The mirror image of the eye's ray to the vertex, as long as it.
        let i = *p - eye();
        let expected = DVec3::new(i.x, -i.y, i.z);
        assert!((*r - expected).length() < 1e-12, "a flat mirror flips y");
    }
}

#[test]
fn snell_at_the_vertices_of_a_lens() {
    let ior = 1.5;
    let lens = lens();
    let surface = reflector_surface(&lens, &camera(), Optic::Refract { ior }).unwrap();
    assert_eq!(surface.mesh.triangles.len(), 50);
    let mut checked = 0;
    for (k, (p, q)) in surface
        .mesh
        .points
        .iter()
        .zip(&surface.mesh.normals)
        .enumerate()
    {
        assert!((q.length() - p.distance(eye())).abs() < 1e-9, "vertex {k}");
        let q = &q.normalize();
        assert!(q.y < 0.0, "vertex {k}: transmitted through the plane");
        let n = (*p - DVec3::new(0.0, -2.0, 0.0)).normalize();
        let i = (*p - eye()).normalize();
        if i.dot(n) >= 0.0 {
            continue; // the bent normal faces away: grazing incidence, as in the ray caster
        }
        // Independent check by angles: sin(theta_t) = sin(theta_i) / ior, in the plane of
        // incidence, on the far side of the surface, tangential part in the same direction.
        let sin_i = i.cross(n).length();
        let sin_t = q.cross(n).length();
        assert!(
            (sin_t - sin_i / ior).abs() < 1e-6,
            "vertex {k}: {sin_t} vs {}",
            sin_i / ior
        );
        assert!(
            q.dot(i.cross(n)).abs() < 1e-6,
            "vertex {k}: out of the plane of incidence"
        );
        assert!(q.dot(n) < 0.0, "vertex {k}: transmitted into the lens");
        assert!((*q - q.dot(n) * n).dot(i - i.dot(n) * n) >= 0.0);
        checked += 1;
    }
    assert!(checked >= 20, "{checked}");
    let e = reflector_surface(&lens, &camera(), Optic::Refract { ior: 0.0 }).unwrap_err();
    assert!(e.message.contains("index of refraction"), "{e}");
}

#[test]
fn total_internal_reflection_falls_back_to_reflection() {
    let n = DVec3::Y;
    let refract = Optic::Refract { ior: 1.5 };
    // Leaving glass (the ray travels along the outward normal): eta = 1.5, critical angle
    // asin(1 / 1.5) = 41.8 degrees.
    let steep = DVec3::new(0.5, 1.0, 0.0).normalize(); // 26.6 degrees from the normal
    let out = vertex_ray(steep, n, n, refract);
    assert!((out.cross(n).length() - 1.5 * steep.cross(n).length()).abs() < 1e-12);
    assert!(out.y > 0.0, "leaves on the far side");
    let shallow = DVec3::new(1.0, 0.5, 0.0).normalize(); // 63.4 degrees: beyond critical
    let reflected = vertex_ray(shallow, n, n, refract);
    assert!((reflected - DVec3::new(shallow.x, -shallow.y, 0.0)).length() < 1e-12);
    // An index below 1 (a bubble) reflects totally even when entering.
    let bubble = vertex_ray(-shallow, n, n, Optic::Refract { ior: 0.5 });
    assert!((bubble - DVec3::new(-shallow.x, shallow.y, 0.0)).length() < 1e-12);
    // Entering, the same shallow ray refracts (no total reflection from the thin side).
    let entering = vertex_ray(-shallow, n, n, refract);
    assert!((entering.cross(n).length() - shallow.cross(n).length() / 1.5).abs() < 1e-12);
    // Enter or leave follows the face, not the orientation of the shading normal.
    assert_eq!(vertex_ray(-shallow, -n, n, refract), entering);
    // A mirror: either normal orientation; grazing keeps the incident direction; a zero face
    // falls back to the shading normal.
    assert_eq!(
        vertex_ray(shallow, n, n, Optic::Reflect),
        vertex_ray(shallow, -n, n, Optic::Reflect)
    );
    assert_eq!(vertex_ray(DVec3::X, n, n, Optic::Reflect), DVec3::X);
    assert_eq!(
        vertex_ray(shallow, n, DVec3::ZERO, Optic::Reflect),
        reflected
    );
}
