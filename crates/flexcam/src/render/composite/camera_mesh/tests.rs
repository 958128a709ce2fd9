use std::borrow::Cow;

use glam::DVec3;

use super::*;
use crate::render::composite::Reflector;
use crate::scene::reflector_fixtures::{camera, sphere_and_cube};

/// The mirror ball of the sphere-and-cube fixture at `segments`, its camera at 320 x 240.
fn ball(segments: u32) -> (Reflector, Perspective) {
    let scene = sphere_and_cube(segments);
    (
        Reflector::of(&scene, 1).unwrap(),
        camera(&scene, (320, 240)),
    )
}

#[test]
fn a_given_size_is_the_simplification_used_as_it_is() {
    let (ball, camera) = ball(24);
    let entry = TrilinearReflector {
        camera_triangles: Some(100),
        ..TrilinearReflector::new(1)
    };
    let chosen = camera_mesh(&ball.mesh, &entry, &camera, Optic::Reflect, true).unwrap();
    assert!(!chosen.refine);
    let n = chosen.mesh.triangles.len();
    assert!((90..=100).contains(&n), "{n} triangles");
    // Every coarse vertex is a vertex of the ball, with its normal.
    for (p, normal) in chosen.mesh.positions.iter().zip(&chosen.mesh.normals) {
        let k = ball.mesh.positions.iter().position(|q| q == p).unwrap();
        assert_eq!(ball.mesh.normals[k], *normal);
    }
    // The whole mesh asked for: the ball's own.
    let all = TrilinearReflector {
        camera_triangles: Some(ball.mesh.triangles.len()),
        ..entry
    };
    let own = camera_mesh(&ball.mesh, &all, &camera, Optic::Reflect, true).unwrap();
    assert!(matches!(own.mesh, Cow::Borrowed(_)));
}

/// A smooth ball is simplified below its own triangles within a tolerance of 4 pixels, not
/// at all within the default half pixel, a coarse one not at all, and the chosen size is
/// the smallest of the candidates within the tolerance.
#[test]
fn the_automatic_size_is_the_smallest_within_the_tolerance() {
    let entry = TrilinearReflector {
        refine_px: 4.0,
        ..TrilinearReflector::new(1)
    };
    let tolerance = entry.refine_px;
    let (smooth, camera) = ball(64);
    let own = smooth.mesh.triangles.len();
    let chosen = camera_mesh(&smooth.mesh, &entry, &camera, Optic::Reflect, true).unwrap();
    assert!(chosen.refine);
    let n = chosen.mesh.triangles.len();
    assert!(n <= own / 4, "{n} of {own} triangles");
    // The other methods keep the reflector's own mesh, to be refined.
    let kept = camera_mesh(&smooth.mesh, &entry, &camera, Optic::Reflect, false).unwrap();
    assert!(kept.refine && matches!(kept.mesh, Cow::Borrowed(_)));
    let seen = SeenVertices::new(&smooth.mesh, &camera, Optic::Reflect);
    assert!(!seen.vertices.is_empty());
    assert!(seen.normal_error_px(&chosen.mesh, Optic::Reflect) <= tolerance);
    let half = coarse_triangles(&smooth.mesh, (n / 2).max(1), SEED).unwrap();
    let error = seen.normal_error_px(&half, Optic::Reflect);
    assert!(error > tolerance, "half the size: {error} px");
    // The own mesh against itself: no error (up to rounding).
    assert!(seen.normal_error_px(&smooth.mesh, Optic::Reflect) < 1e-6);

    let (coarse, camera) = ball(6);
    let chosen = camera_mesh(&coarse.mesh, &entry, &camera, Optic::Reflect, true).unwrap();
    assert!(matches!(chosen.mesh, Cow::Borrowed(_)));
    let (smooth_ball, camera) = ball(64);
    let default = TrilinearReflector::new(1);
    let chosen = camera_mesh(&smooth_ball.mesh, &default, &camera, Optic::Reflect, true).unwrap();
    assert!(matches!(chosen.mesh, Cow::Borrowed(_)));
    // No tolerance: no simplification.
    let exact = TrilinearReflector {
        refine_px: 0.0,
        ..entry
    };
    let (smooth, camera) = ball(64);
    let chosen = camera_mesh(&smooth.mesh, &exact, &camera, Optic::Reflect, true).unwrap();
    assert!(matches!(chosen.mesh, Cow::Borrowed(_)));
}

/// The closest point agrees with a dense sampling of the triangle.
#[test]
fn closest_point_is_the_nearest_of_the_triangle() {
    let t = CoarseTriangle {
        corners: [
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.5, 1.5, 0.3),
        ],
        normals: [DVec3::Z; 3],
        face: DVec3::Z,
    };
    let points = [
        DVec3::new(0.7, 0.4, 1.0),
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(3.0, 0.2, -0.5),
        DVec3::new(0.2, 2.0, 0.0),
        DVec3::new(1.5, 1.5, 0.5),
        DVec3::new(1.0, -2.0, 0.1),
    ];
    for p in points {
        let (w, d) = t.closest(p);
        assert!(w.iter().all(|&x| x >= -1e-12) && (w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let mut best = f64::INFINITY;
        let n = 400;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let q = (1.0 - u - v) * t.corners[0] + u * t.corners[1] + v * t.corners[2];
                best = best.min(q.distance(p));
            }
        }
        assert!(
            d <= best + 1e-12 && d >= best - 1e-2,
            "{p}: {d} against {best}"
        );
    }
}

/// A remembered camera mesh is the one a fresh simplification gives, and a reflector that
/// moved (or a request that changed) is simplified anew, not given the remembered mesh.
#[test]
fn remembered_camera_meshes_are_those_of_their_own_inputs() {
    let (ball, camera) = ball(20);
    let given = TrilinearReflector {
        camera_triangles: Some(64),
        ..TrilinearReflector::new(1)
    };
    let fresh = coarse_triangles(&ball.mesh, 64, SEED).unwrap();
    for _ in 0..2 {
        let chosen = camera_mesh(&ball.mesh, &given, &camera, Optic::Reflect, true).unwrap();
        assert_eq!(*chosen.mesh, fresh);
    }
    let mut moved = ball.mesh.clone();
    moved.transform(&glam::Affine3A::from_translation(glam::Vec3::new(
        0.25, 0.0, 0.0,
    )));
    let chosen = camera_mesh(&moved, &given, &camera, Optic::Reflect, true).unwrap();
    assert_eq!(*chosen.mesh, coarse_triangles(&moved, 64, SEED).unwrap());
    let other_size = TrilinearReflector {
        camera_triangles: Some(32),
        ..given
    };
    let chosen = camera_mesh(&ball.mesh, &other_size, &camera, Optic::Reflect, true).unwrap();
    assert_eq!(
        *chosen.mesh,
        coarse_triangles(&ball.mesh, 32, SEED).unwrap()
    );
    // The automatic size, remembered per camera: the same choice as a first search.
    let tolerant = TrilinearReflector {
        refine_px: 4.0,
        ..TrilinearReflector::new(1)
    };
    let first = camera_mesh(&ball.mesh, &tolerant, &camera, Optic::Reflect, true).unwrap();
    let again = camera_mesh(&ball.mesh, &tolerant, &camera, Optic::Reflect, true).unwrap();
    assert_eq!(first.mesh, again.mesh);
    assert_eq!(
        *first.mesh,
        automatic_size(&ball.mesh, &camera, Optic::Reflect, 4.0).into_owned()
    );
}
