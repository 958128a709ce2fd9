use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::{BilinearPatch, PatchHit};
use crate::geometry::Ray;

/// z = uv over the unit square: a hyperbolic paraboloid, its edges rulings.
const TWISTED: BilinearPatch = BilinearPatch {
    p00: DVec3::ZERO,
    p10: DVec3::X,
    p01: DVec3::Y,
    p11: DVec3::ONE,
};

fn ray(origin: [f64; 3], direction: [f64; 3]) -> Ray {
    Ray::new(DVec3::from(origin), DVec3::from(direction))
}

fn assert_hit(hit: Option<PatchHit>, t: f64, uv: [f64; 2]) {
    let hit = hit.expect("a hit");
    assert!((hit.t - t).abs() < 1e-12, "t {} != {t}", hit.t);
    assert!(
        (hit.uv - DVec2::from(uv)).length() < 1e-12,
        "uv {} != {uv:?}",
        hit.uv
    );
}

#[test]
fn hits_the_twisted_patch_on_every_axis() {
    // Down z (largest component z), and along x and y through the same point.
    assert_hit(
        TWISTED.intersect(&ray([0.5, 0.25, 3.0], [0.0, 0.0, -1.0])),
        2.875,
        [0.5, 0.25],
    );
    let p = TWISTED.point(0.3, 0.6);
    let dir = DVec3::new(-0.9, 0.1, 0.2);
    assert_hit(
        TWISTED.intersect(&Ray::new(p - 2.0 * dir, dir)),
        2.0,
        [0.3, 0.6],
    );
    // Its other crossing is at v within rounding of 0 (t = -0.1): a root pair with a ratio
    // beyond 1/EPSILON, both meaningful.
    let dir = DVec3::new(0.1, 1.0, 0.3);
    assert_hit(
        TWISTED.intersect(&Ray::new(p - 0.5 * dir, dir)),
        0.5,
        [0.3, 0.6],
    );
}

#[test]
fn a_ray_crossing_twice_gets_the_nearer_hit_and_the_farther_after_it() {
    // The line x = y = s, z = ... crosses z = uv at the points where z = s^2.
    let patch = TWISTED;
    let r2 = ray([0.0, 0.0, 0.1], [1.0, 1.0, 0.7]);
    // s^2 = 0.1 + 0.7 s: s = (0.7 +- sqrt(0.49 + 0.4)) / 2, one root in [0, 1].
    let s = (0.7 + 0.89f64.sqrt()) / 2.0;
    assert_hit(patch.intersect(&r2), s, [s, s]);
    // A ray with two roots inside: x = y = s, z = 0.6 s - 0.05: s^2 - 0.6 s + 0.05 = 0.
    let r3 = ray([0.0, 0.0, -0.05], [1.0, 1.0, 0.6]);
    let (s1, s2) = (0.1, 0.5);
    assert_hit(patch.intersect(&r3), s1, [s1, s1]);
    let later = Ray { t_min: 0.2, ..r3 };
    assert_hit(patch.intersect(&later), s2, [s2, s2]);
    let between = Ray {
        t_max: 0.3,
        ..later
    };
    assert!(patch.intersect(&between).is_none());
}

#[test]
fn linear_case_parallelogram() {
    // a = 0: the v^2 term vanishes for every ray.
    let patch = BilinearPatch {
        p00: DVec3::ZERO,
        p10: DVec3::new(2.0, 0.0, 0.0),
        p01: DVec3::new(0.5, 1.0, 0.0),
        p11: DVec3::new(2.5, 1.0, 0.0),
    };
    assert_hit(
        patch.intersect(&ray([1.0, 0.5, 2.0], [0.0, 0.0, -2.0])),
        1.0,
        [0.375, 0.5],
    );
    // From below, with an oblique direction.
    assert_hit(
        patch.intersect(&ray([1.0, 0.5, -1.0], [0.5, 0.0, 1.0])),
        1.0,
        [0.625, 0.5],
    );
    assert!(patch
        .intersect(&ray([3.0, 0.5, 2.0], [0.0, 0.0, -1.0]))
        .is_none());
}

#[test]
fn parallel_and_in_plane_rays_on_planar_patches_miss() {
    let square = BilinearPatch {
        p00: DVec3::ZERO,
        p10: DVec3::X,
        p01: DVec3::Y,
        p11: DVec3::new(1.0, 1.0, 0.0),
    };
    assert!(square
        .intersect(&ray([0.5, -1.0, 0.5], [0.0, 1.0, 0.0]))
        .is_none());
    assert!(square
        .intersect(&ray([0.5, -1.0, 0.0], [0.0, 1.0, 0.0]))
        .is_none());
    assert!(square
        .intersect(&ray([-1.0, 0.5, 0.0], [1.0, 0.2, 0.0]))
        .is_none());
}

#[test]
fn rays_along_rulings_hit_the_nearest_point_of_the_segment() {
    // Along the edge v = 0 (both u denominators vanish) and the edge u = 0 (the v equation
    // vanishes identically), from outside the patch.
    assert_hit(
        TWISTED.intersect(&ray([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0])),
        1.0,
        [0.0, 0.0],
    );
    assert_hit(
        TWISTED.intersect(&ray([0.0, -1.0, 0.0], [0.0, 2.0, 0.0])),
        0.5,
        [0.0, 0.0],
    );
    // Backwards along the edge u = 1 (z = v), from beyond the far corner.
    assert_hit(
        TWISTED.intersect(&ray([1.0, 3.0, 3.0], [0.0, -1.0, -1.0])),
        2.0,
        [1.0, 1.0],
    );
    // Along the interior ruling v = 0.5 (z = u / 2), starting on it: the origin itself.
    assert_hit(
        TWISTED.intersect(&ray([0.25, 0.5, 0.125], [1.0, 0.0, 0.5])),
        0.0,
        [0.25, 0.5],
    );
    // Along a ruling's line, pointing away from the patch.
    assert!(TWISTED
        .intersect(&ray([-1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]))
        .is_none());
}

#[test]
fn triangle_shaped_patch_hits_near_its_collapsed_corner() {
    // p11 = p10: the line u = 1 shrinks to a point; p(u, v) = (u, (1 - u) v, 0) covers the
    // triangle (0,0,0), (1,0,0), (0,1,0).
    let patch = BilinearPatch {
        p00: DVec3::ZERO,
        p10: DVec3::X,
        p01: DVec3::Y,
        p11: DVec3::X,
    };
    let hit = patch
        .intersect(&ray([0.9, 0.05, 1.0], [0.0, 0.0, -1.0]))
        .unwrap();
    assert!((hit.t - 1.0).abs() < 1e-12);
    let p = patch.point(hit.uv.x, hit.uv.y);
    assert!((p - DVec3::new(0.9, 0.05, 0.0)).length() < 1e-12);
    // The collapsed corner itself.
    let hit = patch
        .intersect(&ray([1.0, 0.0, 1.0], [0.0, 0.0, -1.0]))
        .unwrap();
    assert!((hit.t - 1.0).abs() < 1e-12 && hit.uv.x == 1.0);
    assert!(patch
        .intersect(&ray([0.6, 0.6, 1.0], [0.0, 0.0, -1.0]))
        .is_none());
}

#[test]
fn collapsed_patches_and_bad_input_never_hit() {
    let segment = BilinearPatch {
        p00: DVec3::ZERO,
        p10: DVec3::X,
        p01: DVec3::ZERO,
        p11: DVec3::X,
    };
    assert!(segment
        .intersect(&ray([0.5, 0.0, 1.0], [0.0, 0.0, -1.0]))
        .is_none());
    assert!(segment
        .intersect(&ray([0.5, 1.0, 1.0], [0.0, 0.0, -1.0]))
        .is_none());
    let point = BilinearPatch {
        p00: DVec3::ONE,
        p10: DVec3::ONE,
        p01: DVec3::ONE,
        p11: DVec3::ONE,
    };
    assert!(point
        .intersect(&ray([1.0, 1.0, 3.0], [0.0, 0.0, -1.0]))
        .is_none());
    let down = [0.0, 0.0, -1.0];
    assert!(TWISTED.intersect(&ray([0.5, 0.5, 1.0], [0.0; 3])).is_none());
    assert!(TWISTED
        .intersect(&ray([f64::NAN, 0.5, 1.0], down))
        .is_none());
    assert!(TWISTED
        .intersect(&ray([0.5, 0.5, 1.0], [f64::INFINITY, 0.0, -1.0]))
        .is_none());
    let nan_patch = BilinearPatch {
        p11: DVec3::NAN,
        ..TWISTED
    };
    assert!(nan_patch.intersect(&ray([0.5, 0.5, 1.0], down)).is_none());
}

#[test]
fn tangent_ray_touches_once() {
    // z = uv along u = v = s is z = s^2; the line z = s - 1/4 touches it at s = 1/2.
    let hit = TWISTED
        .intersect(&ray([0.0, 0.0, -0.25], [1.0, 1.0, 1.0]))
        .unwrap();
    assert!((hit.t - 0.5).abs() < 1e-7, "{hit:?}");
}

/// The reference: Newton's method on `p(u, v) - r - t q = 0` from a dense grid of starts,
/// keeping converged solutions inside the patch; the nearest.
fn newton_reference(patch: &BilinearPatch, ray: &Ray) -> Option<PatchHit> {
    let [a, b, c, _] = patch.coefficients();
    let (r, q) = (ray.origin, ray.direction);
    let mut best: Option<PatchHit> = None;
    const STARTS: usize = 12;
    for si in 0..=STARTS {
        for sj in 0..=STARTS {
            let (mut u, mut v) = (si as f64 / STARTS as f64, sj as f64 / STARTS as f64);
            let mut t = (patch.point(u, v) - r).dot(q) / q.length_squared();
            for _ in 0..40 {
                let f = patch.point(u, v) - r - t * q;
                let jac = glam::DMat3::from_cols(v * a + b, u * a + c, -q);
                if jac.determinant().abs() < 1e-300 {
                    break;
                }
                let step = jac.inverse() * f;
                u -= step.x;
                v -= step.y;
                t -= step.z;
                if step.length() < 1e-15 {
                    break;
                }
            }
            let residual = (patch.point(u, v) - r - t * q).length();
            let inside = (-1e-12..=1.0 + 1e-12).contains(&u) && (-1e-12..=1.0 + 1e-12).contains(&v);
            if residual < 1e-10 && inside && t >= 0.0 && best.is_none_or(|h| t < h.t) {
                best = Some(PatchHit {
                    t,
                    uv: DVec2::new(u, v),
                });
            }
        }
    }
    best
}

fn coord() -> impl Strategy<Value = f64> {
    -1.0..1.0f64
}

fn point() -> impl Strategy<Value = DVec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// Distance of `uv` from the patch boundary: hits closer than the reference's tolerance to it
/// may be found by one method and not the other.
fn boundary_distance(uv: DVec2) -> f64 {
    uv.x.min(uv.y).min(1.0 - uv.x).min(1.0 - uv.y)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// Random patches and random rays aimed near them: the robust intersection and the
    /// Newton reference agree on whether there is a hit and on the nearest one.
    #[test]
    fn agrees_with_newton_reference(
        p00 in point(), p10 in point(), p01 in point(), p11 in point(),
        origin in point(), aim in point(),
    ) {
        let patch = BilinearPatch { p00, p10, p01, p11 };
        let origin = origin * 3.0;
        let direction = aim - origin;
        prop_assume!(direction.length() > 1e-3);
        let ray = Ray::new(origin, direction);
        let got = patch.intersect(&ray);
        let want = newton_reference(&patch, &ray);
        match (got, want) {
            (Some(g), Some(w)) => {
                let near_edge = boundary_distance(g.uv).min(boundary_distance(w.uv)) < 1e-7;
                prop_assert!(
                    (g.t - w.t).abs() <= 1e-7 * (1.0 + w.t) || near_edge,
                    "t {} vs reference {} (uv {} vs {})", g.t, w.t, g.uv, w.uv
                );
            }
            (Some(g), None) => {
                // Only a hit at the rim (the reference's tolerance) or a near-tangency, where
                // Newton converges too slowly, may be missing from the reference.
                let p = patch.point(g.uv.x, g.uv.y);
                prop_assert!((p - ray.at(g.t)).length() < 1e-9 * (1.0 + g.t * direction.length()));
                prop_assert!(boundary_distance(g.uv) < 1e-7, "reference missed {g:?}");
            }
            (None, Some(w)) => {
                prop_assert!(boundary_distance(w.uv) < 1e-7, "missed the reference hit {w:?}");
            }
            (None, None) => {}
        }
    }
}
