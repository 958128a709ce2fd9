use glam::{DVec2, DVec3};

use super::*;
use crate::projection::trilinear::mesh_builders::screen_grid;
use crate::projection::{CameraFrame, Trilinear};

const CENTER: DVec3 = DVec3::new(0.0, 1.0, 0.0);
const EYE: DVec3 = DVec3::new(0.3, 1.4, 1.5);

/// A pinhole 1.58 from the centre of a unit ball (angular radius 39 degrees) whose view
/// (corners 31 degrees off axis) lies inside the ball's outline.
fn camera() -> GridCamera {
    let frame = CameraFrame {
        position: EYE,
        look_at: CENTER,
        up: DVec3::Y,
    };
    GridCamera::perspective(&frame, 50.0, 40.0).unwrap()
}

fn mirror() -> BallView {
    BallView::new(camera(), CENTER, 1.0, BallOptic::Mirror).unwrap()
}

fn glass(ior: f64) -> BallView {
    BallView::new(camera(), CENTER, 1.0, BallOptic::Glass { ior }).unwrap()
}

/// A 9 x 9 lattice of screen positions over the whole view, corners included.
fn screens() -> impl Iterator<Item = DVec2> {
    (0..81).map(|k| DVec2::new(f64::from(k % 9), f64::from(k / 9)) / 8.0)
}

/// The camera's unit direction at `s` and where it first meets the ball (solved here
/// independently of the view).
fn entry(s: DVec2) -> (DVec3, DVec3) {
    let d = camera().vertex(s).direction.normalize();
    let o = EYE - CENTER;
    let b = d.dot(o);
    let t = -b - (b * b - o.length_squared() + 1.0).sqrt();
    (d, EYE + t * d)
}

fn sine(a: DVec3, b: DVec3) -> f64 {
    a.normalize().cross(b.normalize()).length()
}

#[test]
fn mirror_rays_obey_the_law_of_reflection() {
    let view = mirror();
    for s in screens() {
        let v = view.ray(s).unwrap();
        let (d, p) = entry(s);
        assert!(v.point.distance(p) < 1e-12, "{s}: {} {p}", v.point);
        let n = v.point - CENTER;
        assert!((n.length() - 1.0).abs() < 1e-12);
        assert!(d.dot(n) < 0.0, "{s}: the near side");
        assert!((v.direction.length() - 1.0).abs() < 1e-12);
        // Equal angles, and d - r along the normal (the plane of incidence).
        assert!((d.dot(n) + v.direction.dot(n)).abs() < 1e-12, "{s}");
        assert!((d - v.direction).cross(n).length() < 1e-12, "{s}");
        assert_eq!(view.vertex(s), v);
    }
}

#[test]
fn glass_rays_obey_snell_at_both_surfaces() {
    let ior = 1.5;
    let view = glass(ior);
    for s in screens() {
        let v = view.ray(s).unwrap();
        let (d, p) = entry(s);
        let q = v.point;
        assert!((q.distance(CENTER) - 1.0).abs() < 1e-12, "{s}");
        let inside = q - p;
        assert!(inside.length() > 1e-3, "{s}: a chord");
        let (np, nq) = (p - CENTER, q - CENTER);
        assert!(
            (sine(d, np) - ior * sine(inside, np)).abs() < 1e-12,
            "{s}: in"
        );
        assert!(
            (ior * sine(inside, nq) - sine(v.direction, nq)).abs() < 1e-12,
            "{s}: out"
        );
        assert!(v.direction.dot(nq) > 0.0, "{s}: leaves the ball");
        // Everything stays in the plane of the eye ray and the centre.
        let plane = d.cross(np);
        if plane.length() > 1e-9 {
            let plane = plane.normalize();
            assert!(inside.normalize().dot(plane).abs() < 1e-12, "{s}");
            assert!(v.direction.dot(plane).abs() < 1e-12, "{s}");
        }
    }
    // Index 1: the ray goes straight through, leaving on the camera ray's far side.
    let plain = glass(1.0);
    for s in screens() {
        let v = plain.ray(s).unwrap();
        let (d, p) = entry(s);
        assert!((v.direction - d).length() < 1e-12, "{s}");
        assert!((v.point - p).cross(d).length() < 1e-12, "{s}");
    }
}

/// Rays grazing the sphere: the mirror returns the ray itself, the glass ball's leaving ray
/// is tangent to the sphere at the exit (the grazing limit, where rounding may put the exit
/// past the critical angle), or the ray just misses.
#[test]
fn grazing_rays_are_tangent_or_miss() {
    let axis = (CENTER - EYE).normalize();
    let distance = EYE.distance(CENTER);
    // Turn the axis by the ball's angular radius about a perpendicular: a tangent ray.
    let side = axis.cross(DVec3::Y).normalize();
    let angle = (1.0 / distance).asin();
    let tangent = axis * angle.cos() + side * angle.sin();
    let frame = CameraFrame {
        position: EYE,
        look_at: EYE + tangent,
        up: DVec3::Y,
    };
    let camera = GridCamera::perspective(&frame, 1.0, 1.0).unwrap();
    for optic in [BallOptic::Mirror, BallOptic::Glass { ior: 1.5 }] {
        // Built directly: the view's corners miss, so `new` refuses it.
        let view = BallView {
            camera,
            eye: EYE,
            center: CENTER,
            radius: 1.0,
            optic,
            second: None,
        };
        if let Some(v) = view.ray(DVec2::splat(0.5)) {
            let n = (v.point - CENTER).normalize();
            assert!(v.direction.dot(n).abs() < 1e-6, "{optic:?}: {v:?}");
            assert!((v.direction.length() - 1.0).abs() < 1e-12);
        }
    }
}

/// A second mirror ball 2 beyond the eye on the line from the first ball's centre, 0.6 to
/// the side: the reflections off the middle of the first ball meet it, those off its rim
/// do not.
fn second_center() -> DVec3 {
    EYE + 2.0 * (EYE - CENTER).normalize() + DVec3::new(0.6, 0.0, 0.0)
}

#[test]
fn second_ball_reflects_the_reflections_that_meet_it() {
    let (one, c2, r2) = (mirror(), second_center(), 0.7);
    let two = one.with_second_ball(c2, r2).unwrap();
    let (mut met, mut missed) = (0, 0);
    for s in screens() {
        let first = one.ray(s).unwrap();
        let v = two.ray(s).unwrap();
        // Where the first reflection meets the second ball, solved here on its own.
        let o = first.point - c2;
        let b = first.direction.dot(o);
        let disc = b * b - o.length_squared() + r2 * r2;
        if disc > 1e-9 && b < 0.0 {
            met += 1;
            let q = first.point + (-b - disc.sqrt()) * first.direction;
            assert!(v.point.distance(q) < 1e-12, "{s}");
            let n = (q - c2) / r2;
            assert!(
                (first.direction.dot(n) + v.direction.dot(n)).abs() < 1e-12,
                "{s}"
            );
            assert!(
                (first.direction - v.direction).cross(n).length() < 1e-12,
                "{s}"
            );
        } else if disc < -1e-9 || b > 0.0 {
            missed += 1;
            assert_eq!(v, first, "{s}");
        }
    }
    assert!(met > 0 && missed > 0, "{met} {missed}");
}

#[test]
fn degenerate_second_balls_are_errors() {
    let message = |r: Result<BallView>| r.unwrap_err().message;
    let c2 = second_center();
    assert!(message(glass(1.5).with_second_ball(c2, 0.7)).contains("sphere_mirror"));
    for (center, radius) in [(c2, 0.0), (c2, f64::INFINITY), (DVec3::NAN, 0.7)] {
        assert!(message(mirror().with_second_ball(center, radius)).contains("positive radius"));
    }
    let touching = CENTER + DVec3::new(1.6, 0.0, 0.0);
    assert!(message(mirror().with_second_ball(touching, 0.7)).contains("overlaps"));
    assert!(mirror()
        .with_second_ball(touching + DVec3::new(0.2, 0.0, 0.0), 0.7)
        .is_ok());
    assert!(message(mirror().with_second_ball(EYE, 0.1)).contains("inside the second ball"));
}

#[test]
fn degenerate_balls_and_cameras_are_errors() {
    let c = camera();
    let message = |r: Result<BallView>| r.unwrap_err().message;
    let frame = CameraFrame {
        position: EYE,
        look_at: CENTER,
        up: DVec3::Y,
    };
    let parallel = GridCamera::orthographic(&frame, 0.5, 0.5).unwrap();
    assert!(message(BallView::new(parallel, CENTER, 1.0, BallOptic::Mirror)).contains("pinhole"));
    for (center, radius) in [(CENTER, 0.0), (CENTER, f64::NAN), (DVec3::NAN, 1.0)] {
        assert!(message(BallView::new(c, center, radius, BallOptic::Mirror)).contains("radius"));
    }
    for ior in [0.9, f64::INFINITY, f64::NAN] {
        assert!(message(BallView::new(c, CENTER, 1.0, BallOptic::Glass { ior })).contains("ior"));
    }
    assert!(message(BallView::new(c, CENTER, 2.0, BallOptic::Mirror)).contains("inside"));
    let wide_frame = GridCamera::perspective(&frame, 100.0, 80.0).unwrap();
    let e = message(BallView::new(wide_frame, CENTER, 1.0, BallOptic::Mirror));
    assert!(e.contains("misses the ball"), "{e}");
    // A smaller ball whose outline (35 degrees) still holds the view's corners (31).
    assert!(BallView::new(c, CENTER, 0.9, BallOptic::Mirror).is_ok());
}

/// The exact projection's ray at a pixel is the view's at the pixel's screen position, and
/// it has no inverse.
#[test]
fn exact_projection_maps_pixels_to_screen() {
    let view = glass(1.5);
    let projection = BallProjection::new(view, 40, 30);
    assert_eq!(
        (projection.kind(), projection.resolution()),
        ("trilinear", (40, 30))
    );
    let ray = projection.ray(DVec2::new(10.0, 3.0)).unwrap();
    let v = view.ray(DVec2::new(0.25, 0.9)).unwrap();
    assert_eq!((ray.origin, ray.direction), (v.point, v.direction));
    let reason = projection.inverse().err().and_then(|e| e.reason).unwrap();
    assert!(reason.contains("grid"), "{reason}");
}

/// The N x N grid is exact at its vertices and converges on the exact view between them
/// about as 1 / N^2 (Vallance 2005, Figure 7.4): over a dense sample of pixels, the largest
/// error of the interpolated ray (its direction, and its base point) falls at least 8 times
/// from N = 4 to N = 16 and 2.5 times per doubling.
#[test]
fn grids_converge_on_the_exact_view() {
    let side = 96u32;
    for view in [mirror(), glass(1.5)] {
        let exact = BallProjection::new(view, side, side);
        let mut errors = Vec::new();
        for n in [4u32, 8, 16] {
            let mesh = screen_grid(n, |s| view.vertex(s)).unwrap();
            let grid = Trilinear::new(&mesh, side, side).unwrap();
            // Vertex (i, j) sits at pixel (i side / n, side - j side / n).
            for (i, j) in [(1, 2), (n / 2, n - 1), (n - 1, 1)] {
                let pixel = DVec2::new(f64::from(i), f64::from(n - j)) * f64::from(side / n);
                let (a, b) = (grid.ray(pixel).unwrap(), exact.ray(pixel).unwrap());
                assert!(a.origin.distance(b.origin) < 1e-9, "{n}: {i} {j}");
                assert!((a.direction.normalize() - b.direction).length() < 1e-9);
            }
            let mut worst = [0.0f64; 2];
            for k in 0..side * side {
                let pixel = DVec2::new(f64::from(k % side), f64::from(k / side)) + 0.5;
                let (a, b) = (grid.ray(pixel).unwrap(), exact.ray(pixel).unwrap());
                worst[0] = worst[0].max((a.direction.normalize() - b.direction).length());
                worst[1] = worst[1].max(a.origin.distance(b.origin));
            }
            errors.push(worst);
        }
        for m in 0..2 {
            let [e4, e8, e16] = [errors[0][m], errors[1][m], errors[2][m]];
            assert!(
                e8 < e4 / 2.5 && e16 < e8 / 2.5 && e16 < e4 / 8.0,
                "{view:?}: {errors:?}"
            );
            assert!(e4 > 1e-6, "the grid interpolates: {errors:?}");
        }
    }
}
