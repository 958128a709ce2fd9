use super::*;
use proptest::prelude::*;

fn triple(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    a.dot(b.cross(c))
}

/// The notes' formulas literally, in global coordinates.
fn notes_coefficients(p: [DVec3; 3], n: [DVec3; 3], ps: DVec3) -> [f64; 4] {
    let (e1, e2, f1, f2) = (p[1] - p[0], p[2] - p[0], n[1] - n[0], n[2] - n[0]);
    let n0 = e1.cross(e2);
    let n1 = e1.cross(f2) + f1.cross(e2);
    let n2 = f1.cross(f2);
    let k3 = triple(n[0], n[1], n[2]);
    let k2 = triple(p[0], n[1], n[2]) + triple(n[0], p[1], n[2]) + triple(n[0], n[1], p[2]);
    let k1 = triple(n[0], p[1], p[2]) + triple(p[0], n[1], p[2]) + triple(p[0], p[1], n[2]);
    let k0 = triple(p[0], p[1], p[2]);
    [k3, k2 - n2.dot(ps), k1 - n1.dot(ps), k0 - n0.dot(ps)]
}

/// The notes' barycentric formulas literally (Gram form).
fn notes_barycentrics(p: [DVec3; 3], n: [DVec3; 3], ps: DVec3, t: f64) -> (f64, f64) {
    let r = [0, 1, 2].map(|i| p[i] + t * n[i]);
    let (e1, e2, e3) = (r[1] - r[0], r[2] - r[0], ps - r[0]);
    let (d11, d22, d12) = (e1.dot(e1), e2.dot(e2), e1.dot(e2));
    let (a1, a2) = (e3.dot(e1), e3.dot(e2));
    let det = d11 * d22 - d12 * d12;
    ((a1 * d22 - a2 * d12) / det, (a2 * d11 - a1 * d12) / det)
}

fn sample() -> ([DVec3; 3], [DVec3; 3]) {
    (
        [
            DVec3::new(0.1, -0.2, 0.05),
            DVec3::new(1.2, 0.1, -0.1),
            DVec3::new(-0.1, 0.9, 0.2),
        ],
        [
            DVec3::new(-0.2, -0.1, 1.0),
            DVec3::new(0.4, 0.0, 1.1),
            DVec3::new(0.0, 0.5, 0.8),
        ],
    )
}

fn find(s: &Solutions, t: f64) -> TriangleSolution {
    *s.as_slice()
        .iter()
        .find(|x| (x.t - t).abs() <= 1e-9 * t.abs().max(1.0))
        .unwrap_or_else(|| panic!("no solution at t = {t}: {s:?}"))
}

#[test]
fn cached_coefficients_and_barycentrics_match_the_notes() {
    let (p, n) = sample();
    let cache = ProjectionTriangleCache::new(p, n);
    let ps = cache.ray_point(0.3, 0.25, 2.5);
    let ours = cache.coefficients(ps);
    let notes = notes_coefficients(p, n, ps);
    let scale = notes.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    for (x, y) in ours.iter().zip(notes) {
        assert!((x - y).abs() <= 1e-13 * scale, "{ours:?} vs {notes:?}");
    }
    let s = cache.project_point(ps);
    let hit = find(&s, 2.5);
    assert!((hit.u - 0.3).abs() < 1e-12 && (hit.v - 0.25).abs() < 1e-12);
    assert!(hit.inside && hit.multiplicity == 1);
    for x in s.iter() {
        let (u, v) = notes_barycentrics(p, n, ps, x.t);
        assert!(
            (x.u - u).abs() < 1e-9 && (x.v - v).abs() < 1e-9,
            "{x:?} vs {u} {v}"
        );
        assert!((cache.ray_point(x.u, x.v, x.t) - ps).length() < 1e-12);
    }
}

#[test]
fn every_real_root_is_returned_inside_or_not() {
    let (p, n) = sample();
    let cache = ProjectionTriangleCache::new(p, n);
    for ps in [
        cache.ray_point(0.3, 0.25, 2.5),
        cache.ray_point(-1.5, 2.0, -3.0),
        DVec3::new(5.0, -3.0, 0.7),
    ] {
        let s = cache.project_point(ps);
        let [a, b, c, d] = cache.coefficients(ps);
        let roots = solve_cubic(a, b, c, d);
        assert_eq!(s.len() + s.rejected(), roots.len());
        assert_eq!(s.rejected(), 0);
        for x in s.iter() {
            let expected = x.u >= 0.0 && x.v >= 0.0 && x.u + x.v <= 1.0;
            assert_eq!(x.inside, expected);
            assert!((cache.ray_point(x.u, x.v, x.t) - ps).length() < 1e-10 * (1.0 + x.t.abs()));
        }
    }
    // Outside solutions are still reported.
    let s = cache.project_point(cache.ray_point(-1.5, 2.0, -3.0));
    let hit = find(&s, -3.0);
    assert!(!hit.inside && (hit.u + 1.5).abs() < 1e-10 && (hit.v - 2.0).abs() < 1e-10);
}

#[test]
fn parallel_normals_give_one_root() {
    let (p, _) = sample();
    let dir = DVec3::new(0.1, -0.2, 1.0);
    // Equal normals: exact degree drop.
    let cache = ProjectionTriangleCache::new(p, [dir; 3]);
    let ps = cache.ray_point(0.2, 0.5, 3.0);
    let s = cache.project_point(ps);
    assert_eq!(s.len(), 1);
    assert_eq!(s.lost_to_infinity(), 2);
    let hit = find(&s, 3.0);
    assert!(hit.inside && (hit.u - 0.2).abs() < 1e-12 && (hit.v - 0.5).abs() < 1e-12);
    // Parallel normals of different lengths (t is then not a common distance).
    let cache = ProjectionTriangleCache::new(p, [dir, 2.0 * dir, 0.5 * dir]);
    let ps = cache.ray_point(0.6, 0.1, 4.0);
    let s = cache.project_point(ps);
    assert_eq!(s.len(), 1, "{s:?}");
    assert_eq!(s.lost_to_infinity() + s.rejected(), 2);
    let hit = find(&s, 4.0);
    assert!((hit.u - 0.6).abs() < 1e-12 && (hit.v - 0.1).abs() < 1e-12);
}

#[test]
fn coplanar_normals_give_a_quadratic() {
    // n3 = n1 + n2 (exact in binary): [n1, n2, n3] = 0, the normals are not parallel.
    let (p, _) = sample();
    let n = [
        DVec3::new(-0.5, 0.25, 1.0),
        DVec3::new(0.5, 0.5, 1.0),
        DVec3::new(0.0, 0.75, 2.0),
    ];
    let cache = ProjectionTriangleCache::new(p, n);
    assert_eq!(cache.coefficients(DVec3::ONE)[0], 0.0);
    let ps = cache.ray_point(0.25, 0.5, 2.0);
    let s = cache.project_point(ps);
    assert_eq!(s.lost_to_infinity(), 1);
    assert_eq!(s.len(), 2, "{s:?}");
    let hit = find(&s, 2.0);
    assert!((hit.u - 0.25).abs() < 1e-12 && (hit.v - 0.5).abs() < 1e-12 && hit.inside);
    // A point with no real root: the quadratic's discriminant is negative. Search a few.
    let none = (0..200)
        .map(|k| DVec3::new(0.3, -3.0 + 0.03 * f64::from(k), -0.5))
        .find(|&q| {
            let [_, b, c, d] = cache.coefficients(q);
            c * c - 4.0 * b * d < -1e-6 * (c * c + (4.0 * b * d).abs())
        });
    let q = none.expect("a point with two complex roots");
    let s = cache.project_point(q);
    assert!(s.is_empty() && s.lost_to_infinity() == 1, "{s:?}");
}

fn perspective_triangle(eye: DVec3) -> ([DVec3; 3], [DVec3; 3]) {
    let p = [
        eye + DVec3::new(-0.4, -0.3, -1.0),
        eye + DVec3::new(0.5, -0.2, -1.0),
        eye + DVec3::new(0.0, 0.45, -1.0),
    ];
    (p, p.map(|x| x - eye))
}

#[test]
fn perspective_double_root_at_minus_one_is_rejected() {
    let eye = DVec3::new(0.3, -0.7, 2.0);
    let (p, n) = perspective_triangle(eye);
    let cache = ProjectionTriangleCache::new(p, n);
    for (u, v, t) in [
        (0.2, 0.3, 1.5),
        (0.7, 0.1, 0.0),
        (-0.5, 0.9, 7.0),
        (0.3, 0.3, -0.5),
    ] {
        let ps = cache.ray_point(u, v, t);
        let s = cache.project_point(ps);
        assert_eq!(s.len(), 1, "only the genuine root survives: {s:?}");
        assert_eq!(s.rejected(), 2, "{s:?}");
        let hit = s.as_slice()[0];
        assert!((hit.t - t).abs() < 1e-12 * (1.0 + t.abs()));
        assert!((hit.u - u).abs() < 1e-12 && (hit.v - v).abs() < 1e-12);
        // The rejected root is at -1, whatever ps: f(-1) = 0.
        let [a, b, c, d] = cache.coefficients(ps);
        let scale = a.abs() + b.abs() + c.abs() + d.abs();
        assert!((-a + b - c + d).abs() < 1e-14 * scale);
    }
    // The eye itself: a triple root at -1, no image.
    let s = cache.project_point(eye);
    assert!(s.is_empty() && s.rejected() == 3, "{s:?}");
    // Same rule at a very different scale (the test is relative).
    let big = 1e6;
    let (p, n) = perspective_triangle(eye);
    let cache = ProjectionTriangleCache::new(p.map(|x| x * big), n.map(|x| x * big));
    let ps = cache.ray_point(0.2, 0.3, 1.5);
    let s = cache.project_point(ps);
    assert_eq!((s.len(), s.rejected()), (1, 2), "{s:?}");
    let small = 1e-6;
    let cache = ProjectionTriangleCache::new(p.map(|x| x * small), n.map(|x| x * small));
    let s = cache.project_point(cache.ray_point(0.2, 0.3, 1.5));
    assert_eq!((s.len(), s.rejected()), (1, 2), "{s:?}");
}

#[test]
fn converging_rays_collapse_in_front_and_image_beyond_the_crossing() {
    // Rays through one point F (n_i = F - p_i): the perspective case with t negated. The
    // parametric triangle collapses to F at t = +1, in front of the base (a rejected
    // double root), and is point-reflected beyond it; every scene point, before or
    // beyond F, keeps exactly one image, on its own ray. (Audit 4: POV-Ray and the ray
    // caster agree on such projections; this pins the point projection's part.)
    let p = [
        DVec3::new(-1.45764322, 0.477759585, 5.5424479),
        DVec3::new(1.54085543, 0.51293406, 6.46326127),
        DVec3::new(-1.51028013, 2.4670385, 5.55334929),
    ];
    let f = DVec3::new(0.0, 1.8, 3.8);
    let cache = ProjectionTriangleCache::new(p, p.map(|q| f - q));
    for (u, v, t) in [
        (0.2, 0.3, 0.5),
        (0.2, 0.3, 3.5),
        (-0.4, 1.2, 2.0),
        (0.9, 0.05, 40.0),
    ] {
        let ps = cache.ray_point(u, v, t);
        let s = cache.project_point(ps);
        assert_eq!((s.len(), s.rejected()), (1, 2), "{s:?}");
        let hit = s.as_slice()[0];
        assert!((hit.t - t).abs() < 1e-12 * (1.0 + t.abs()), "{hit:?}");
        assert!(
            (hit.u - u).abs() < 1e-11 && (hit.v - v).abs() < 1e-11,
            "{hit:?}"
        );
    }
    // F itself: a triple root at 1, no image.
    let s = cache.project_point(f);
    assert!(s.is_empty() && s.rejected() == 3, "{s:?}");
}

#[test]
fn collapse_to_a_segment_is_rejected() {
    // r2(t) and r3(t) meet at t = 1: the triangle is a segment there, f(1) = 0 for all ps.
    let p = [DVec3::ZERO, DVec3::X, DVec3::new(0.0, 1.0, 0.0)];
    let n = [
        DVec3::Z,
        DVec3::new(-0.5, 0.5, 1.0),
        DVec3::new(0.5, -0.5, 1.0),
    ];
    let cache = ProjectionTriangleCache::new(p, n);
    for ps in [DVec3::new(0.3, 0.3, 2.0), DVec3::new(-2.0, 1.0, 0.5)] {
        let s = cache.project_point(ps);
        assert!(s.iter().all(|x| (x.t - 1.0).abs() > 1e-6), "{s:?}");
        assert!(s.rejected() >= 1, "{s:?}");
        let [a, b, c, d] = cache.coefficients(ps);
        assert!((a + b + c + d).abs() < 1e-14);
    }
}

#[test]
fn point_on_the_base_triangle_has_t_zero() {
    let (p, n) = sample();
    let cache = ProjectionTriangleCache::new(p, n);
    // Exactly a vertex: d is exactly 0, so t is exactly 0.
    let s = cache.project_point(p[0]);
    let hit = find(&s, 0.0);
    assert_eq!((hit.t, hit.u, hit.v), (0.0, 0.0, 0.0));
    assert!(hit.inside);
    let ps = cache.tripoint(0.4, 0.35);
    let s = cache.project_point(ps);
    let hit = find(&s, 0.0);
    assert!(hit.t.abs() < 1e-14 && hit.inside);
    assert!((hit.u - 0.4).abs() < 1e-14 && (hit.v - 0.35).abs() < 1e-14);
}

#[test]
fn point_on_a_vertex_ray() {
    let (p, n) = sample();
    let cache = ProjectionTriangleCache::new(p, n);
    let bary = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
    for k in 0..3 {
        for s_param in [0.0, 0.7, 3.0] {
            let ps = p[k] + s_param * n[k];
            let s = cache.project_point(ps);
            let hit = find(&s, s_param);
            assert!(hit.inside, "vertex {k} at {s_param}: {hit:?}");
            assert!((hit.u - bary[k].0).abs() < 1e-12 && (hit.v - bary[k].1).abs() < 1e-12);
        }
    }
    // For vertex 1 the other roots do not depend on the position along the ray.
    let others = |s_param: f64| {
        let s = cache.project_point(p[0] + s_param * n[0]);
        s.iter()
            .map(|x| x.t)
            .filter(|t| (t - s_param).abs() > 1e-6)
            .collect::<Vec<_>>()
    };
    let (x, y) = (others(0.7), others(3.0));
    assert_eq!(x.len(), y.len());
    for (a, b) in x.iter().zip(&y) {
        assert!((a - b).abs() < 1e-9 * (1.0 + a.abs()));
    }
}

#[test]
fn folded_triangle_images_a_point_several_times() {
    // Along u the rays x = u + t (1 - 3u), z = t (1 + 2u) cross (a fold): the point
    // (0.3, y, 1) is seen from u = (2.6 +- sqrt(1.16)) / 4 (at v ~ y). n3 tilts in y so
    // that the cubic keeps its degree.
    let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let n = [
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(-2.0, 0.0, 3.0),
        DVec3::new(1.0, 0.05, 1.0),
    ];
    let cache = ProjectionTriangleCache::new(p, n);
    let ps = DVec3::new(0.3, 0.02, 1.0);
    let s = cache.project_point(ps);
    let visible: Vec<_> = s.iter().filter(|x| x.inside && x.t >= 0.0).collect();
    assert_eq!(visible.len(), 2, "{s:?}");
    for x in s.iter() {
        assert!(
            (cache.ray_point(x.u, x.v, x.t) - ps).length() < 1e-12,
            "{x:?}"
        );
    }
    // Without the tilt: exactly the two predicted images (and a quadratic).
    let cache = ProjectionTriangleCache::new(p, [n[0], n[1], n[0]]);
    let s = cache.project_point(ps);
    assert_eq!(s.lost_to_infinity(), 1);
    let mut us: Vec<f64> = s.iter().filter(|x| x.inside).map(|x| x.u).collect();
    us.sort_by(f64::total_cmp);
    let root = 1.16_f64.sqrt();
    assert_eq!(us.len(), 2, "{s:?}");
    assert!((us[0] - (2.6 - root) / 4.0).abs() < 1e-12);
    assert!((us[1] - (2.6 + root) / 4.0).abs() < 1e-12);
    assert!(s.iter().all(|x| (x.v - 0.02).abs() < 1e-12));
}

#[test]
fn sweeping_no_volume() {
    let v = DVec3::new;
    // Two vertices sharing base point and ray (a sphere grid's pole row): a surface.
    let p = [v(0.0, 6.0, 0.0), v(0.0, 6.0, 0.0), v(0.8, 5.9, 0.1)];
    let n = [v(0.0, -1.0, 0.0), v(0.0, -1.0, 0.0), v(-0.8, -0.9, -0.1)];
    assert!(ProjectionTriangleCache::new(p, n).sweeps_no_volume());
    // The same within rounding (longitude -180 and 180 on a sphere of radius 6).
    let q = v(6.0 * std::f64::consts::PI.sin(), 0.0, -6.0);
    let r = v(6.0 * (-std::f64::consts::PI).sin(), 0.0, -6.0);
    assert_ne!(q, r);
    let far = v(0.0, 1.0, 0.0);
    let cache = ProjectionTriangleCache::new(
        [q, r, v(0.0, 3.0, -5.0)],
        [far - q, far - r, far - v(0.0, 3.0, -5.0)],
    );
    assert!(cache.sweeps_no_volume());
    // Collinear base points with coplanar rays in one plane: a planar sweep.
    let p = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0)];
    let n = [v(0.0, 1.0, 0.0), v(0.5, 1.0, 0.0), v(1.0, 1.0, 0.0)];
    assert!(ProjectionTriangleCache::new(p, n).sweeps_no_volume());
    // Base points and rays in one plane (x = 0), the parametric triangle never
    // degenerate: rays from a sphere's longitudes 0 and 180 to its centre.
    let centre = v(0.0, 1.0, 0.0);
    let p = [v(0.0, -4.2, 3.0), v(0.0, -4.2, -3.0), v(0.0, 2.0, -5.9)];
    let cache = ProjectionTriangleCache::new(p, p.map(|x| centre - x));
    assert!(cache.plane_at(0.5).1.length() > 1.0);
    assert!(cache.sweeps_no_volume());
    // Not degenerate: a perspective triangle, an orthographic one, a base that is a
    // point (a pinhole), two vertices sharing a base point only, and a thin but real one.
    let (p, n) = perspective_triangle(v(0.0, 0.0, 5.0));
    assert!(!ProjectionTriangleCache::new(p, n).sweeps_no_volume());
    let p = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
    assert!(!ProjectionTriangleCache::new(p, [v(0.0, 0.0, -1.0); 3]).sweeps_no_volume());
    let n = [v(0.0, 0.0, -1.0), v(0.1, 0.0, -1.0), v(0.0, 0.1, -1.0)];
    assert!(!ProjectionTriangleCache::new([DVec3::ZERO; 3], n).sweeps_no_volume());
    let p = [v(0.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
    assert!(!ProjectionTriangleCache::new(p, n).sweeps_no_volume());
    let p = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.5, 1e-3, 0.0)];
    assert!(!ProjectionTriangleCache::new(p, [v(0.0, 0.0, -1.0); 3]).sweeps_no_volume());
    // A NaN vertex is left to the renderer's own checks.
    let p = [v(f64::NAN, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.5, 1.0, 0.0)];
    assert!(!ProjectionTriangleCache::new(p, [v(0.0, 0.0, -1.0); 3]).sweeps_no_volume());
}

#[test]
fn identically_zero_cubic() {
    // A base triangle that is a segment and equal normals: the parametric triangle is a
    // segment at every t, so f vanishes identically for every point.
    let p = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
    let cache = ProjectionTriangleCache::new(p, [DVec3::Z; 3]);
    for ps in [DVec3::new(0.5, 0.0, 3.0), DVec3::new(0.5, 1.0, 3.0)] {
        let s = cache.project_point(ps);
        assert!(s.is_every_t() && s.is_empty(), "{s:?}");
    }
}

/// Points with each coordinate in `(-range, range)`: the strategy of the projection
/// tests' random triangles.
pub(in crate::projection::trilinear) fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// Uniform barycentrics inside the triangle (the square folded along its diagonal).
fn inside_uv() -> impl Strategy<Value = (f64, f64)> {
    (0.0..=1.0f64, 0.0..=1.0f64).prop_map(|(a, b)| {
        if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        }
    })
}

/// Sine of the angle of the system's Jacobian [E1, E2, trinorm] at (u, v, t): the volume
/// it spans over the product of the lengths. Zero where two solutions merge (a fold) or
/// the parametric triangle degenerates.
fn conditioning(cache: &ProjectionTriangleCache, u: f64, v: f64, t: f64) -> f64 {
    let e1 = cache.e1 + t * cache.f1;
    let e2 = cache.e2 + t * cache.f2;
    let n = cache.trinorm(u, v);
    triple(e1, e2, n).abs() / (e1.length() * e2.length() * n.length())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Random triangles and rays: ps = ray(u, v, t) is found again. Skipped draws: the
    /// Jacobian sine `conditioning` below 1e-3 (near a fold or a degenerate triangle,
    /// where (u, v, t) is ill-conditioned), or a base triangle thinner than sine 1e-3.
    #[test]
    fn random_rays_round_trip(
        p in [vec3(2.0), vec3(2.0), vec3(2.0)],
        n in [vec3(1.5), vec3(1.5), vec3(1.5)],
        offset in vec3(100.0),
        (u, v) in inside_uv(),
        t in 0.0..10.0f64,
    ) {
        let p = p.map(|x| x + offset);
        let cache = ProjectionTriangleCache::new(p, n);
        let base = cache.e1.cross(cache.e2).length()
            / (cache.e1.length() * cache.e2.length());
        prop_assume!(base > 1e-3);
        prop_assume!(conditioning(&cache, u, v, t) > 1e-3);
        let ps = cache.ray_point(u, v, t);
        let s = cache.project_point(ps);
        let hit = s.iter().min_by(|a, b| {
            let da = (a.t - t).abs() + (a.u - u).abs() + (a.v - v).abs();
            let db = (b.t - t).abs() + (b.u - u).abs() + (b.v - v).abs();
            da.total_cmp(&db)
        });
        let hit = hit.ok_or_else(|| TestCaseError::fail(format!("no solution {s:?}")))?;
        prop_assert!((hit.t - t).abs() <= 1e-9 * t.max(1.0), "t {} vs {t}: {s:?}", hit.t);
        let uv_error = (hit.u - u).abs().max((hit.v - v).abs());
        prop_assert!(uv_error <= 1e-9, "{hit:?} vs {u} {v}");
        prop_assert!(hit.inside);
        // Every reported solution is a genuine image.
        let scale = ps.length() + cache.base_size + cache.trinorm(u, v).length() * t;
        for x in s.iter() {
            let err = (cache.ray_point(x.u, x.v, x.t) - ps).length();
            let bound = 1e-9 * (scale + x.t.abs() * cache.trinorm(x.u, x.v).length());
            prop_assert!(err <= bound, "{x:?} err {err}");
        }
    }
}

/// Accuracy report (run with `--ignored --nocapture`): the round trip of
/// `random_rays_round_trip` over many draws, worst errors of t (relative to max(1, t))
/// and of (u, v), and how many draws the conditioning filter skipped.
#[test]
#[ignore]
fn accuracy_report() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut vec = |r: f64| DVec3::new(next(), next(), next()) * 2.0 * r - DVec3::splat(r);
    for threshold in [1e-3, 1e-5, 0.0] {
        let (mut worst_t, mut worst_uv, mut skipped, mut missed) = (0.0_f64, 0.0_f64, 0, 0);
        let draws = 200_000;
        for _ in 0..draws {
            let offset = vec(100.0);
            let p = [vec(2.0) + offset, vec(2.0) + offset, vec(2.0) + offset];
            let n = [vec(1.5), vec(1.5), vec(1.5)];
            let w = vec(0.5) + DVec3::splat(0.5);
            let (mut u, mut v) = (w.x, w.y);
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let t = 10.0 * w.z;
            let cache = ProjectionTriangleCache::new(p, n);
            let base = cache.e1.cross(cache.e2).length() / (cache.e1.length() * cache.e2.length());
            if base <= threshold || conditioning(&cache, u, v, t) <= threshold {
                skipped += 1;
                continue;
            }
            let s = cache.project_point(cache.ray_point(u, v, t));
            let best = s.iter().map(|x| {
                (
                    (x.t - t).abs() / t.max(1.0),
                    (x.u - u).abs().max((x.v - v).abs()),
                )
            });
            match best.min_by(|a, b| (a.0 + a.1).total_cmp(&(b.0 + b.1))) {
                Some((et, euv)) => {
                    worst_t = worst_t.max(et);
                    worst_uv = worst_uv.max(euv);
                }
                None => missed += 1,
            }
        }
        println!(
            "threshold {threshold:e}: {draws} draws, {skipped} skipped, {missed} missed: \
         worst t error {worst_t:.3e}, worst (u, v) error {worst_uv:.3e}"
        );
    }
    // Rough throughput (optimised test profile; not a benchmark).
    let (p, n) = sample();
    let cache = ProjectionTriangleCache::new(p, n);
    let points: Vec<DVec3> = (0..1000).map(|_| vec(3.0)).collect();
    let start = std::time::Instant::now();
    let mut count = 0;
    for _ in 0..1000 {
        for &ps in &points {
            count += std::hint::black_box(cache.project_point(ps)).len();
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    println!(
        "project_point: {:.1} ns per call ({count} solutions)",
        elapsed * 1e9 / 1e6
    );
}
