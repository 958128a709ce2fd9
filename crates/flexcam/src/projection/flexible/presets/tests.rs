//! The depth-changing, occlusion, MCOP and magnifier presets against their closed forms.

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::super::{Flexible, FlexibleSpec, VolumeSource};
use super::*;
use crate::projection::{Projection, Projector};
use crate::render::supported_chart;

const ASPECT: f64 = 0.75;

fn frame() -> CameraFrame {
    CameraFrame {
        position: DVec3::new(1.0, 2.0, 3.0),
        look_at: DVec3::new(-2.0, 1.0, 0.0),
        up: DVec3::Y,
    }
}

fn basis() -> CameraBasis {
    CameraBasis::new(&frame()).unwrap()
}

fn spec(preset: Preset, clip: [f64; 2]) -> PresetSpec {
    PresetSpec {
        preset,
        frame: frame(),
        clip: Some(clip),
    }
}

fn flexible(preset: Preset, clip: [f64; 2], w: u32, h: u32) -> Flexible {
    let spec = FlexibleSpec {
        source: VolumeSource::Preset(spec(preset, clip)),
        reparam: None,
    };
    Flexible::new(&spec, w, h).unwrap()
}

/// Q(u, v, t) in camera-local coordinates (x right, y up, z forward from the eye).
fn local(volume: &Volume, uv: DVec2, t: f64) -> DVec3 {
    let b = basis();
    b.to_local(volume.point(uv, t) - b.origin)
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-9 * (1.0 + b.length())
}

/// (U, V) = (2u - 1, 2v - 1) on a 5 x 5 grid.
fn grid() -> impl Iterator<Item = DVec2> {
    (0..5).flat_map(|i| (0..5).map(move |j| DVec2::new(f64::from(i), f64::from(j)) / 4.0))
}

fn centred(uv: DVec2) -> DVec2 {
    2.0 * uv - DVec2::ONE
}

#[test]
fn ortho_near_persp_far_is_an_orthographic_grid_then_the_perspective_frustum() {
    let tan = 30f64.to_radians().tan();
    let v = spec(
        Preset::OrthoNearPerspFar {
            fov: 60.0,
            transition: 4.0,
            style: DepthStyle::Piecewise,
        },
        [0.0, 10.0],
    )
    .volume(ASPECT)
    .unwrap();
    let knot = 0.4;
    let half = DVec2::new(4.0 * tan, 4.0 * tan * ASPECT);
    for uv in grid() {
        let c = centred(uv);
        // The near end and the transition: the same (x, y), an orthographic grid.
        let ortho = (c * half).extend(0.0);
        assert!(close(local(&v, uv, 0.0), ortho));
        assert!(close(local(&v, uv, knot), ortho + DVec3::Z * 4.0));
        // Straight in front of the transition: the midpoint is the mean of the ends.
        assert!(close(local(&v, uv, 0.2), ortho + DVec3::Z * 2.0));
        // Behind it: on the camera's own perspective ray, x/z = U tan, y/z = V tan H/W.
        for t in [knot, 0.55, 0.8, 1.0] {
            let p = local(&v, uv, t);
            assert!((p.z - 10.0 * t).abs() < 1e-9);
            let image = DVec2::new(p.x, p.y) / p.z;
            assert!((image - c * DVec2::new(tan, tan * ASPECT)).length() < 1e-9);
        }
    }
    // The projectors are polylines with the kink at the transition (off the centre).
    let uv = DVec2::new(1.0, 0.75);
    let before = v.tangent(uv, knot - 1e-6);
    let after = v.tangent(uv, knot + 1e-6);
    assert!(before.normalize().dot(after.normalize()) < 0.99);
    assert!(matches!(v.projector(uv), Some(Projector::Polyline(p)) if p.len() == 3));
}

/// Volumes of perspective A (fov 60) to 5, then B (fov 30) to 20, from 1.
fn two_views(style: DepthStyle) -> Volume {
    spec(
        Preset::DepthTransition {
            fovs: vec![60.0, 30.0],
            transitions: vec![5.0],
            style,
        },
        [1.0, 20.0],
    )
    .volume(ASPECT)
    .unwrap()
}

#[test]
fn piecewise_depth_transition_is_perspective_a_then_perspective_b() {
    let (ta, tb) = (30f64.to_radians().tan(), 15f64.to_radians().tan());
    // B's rays meet on the axis at e = 5 - 5 ta / tb.
    let eye_b = 5.0 - 5.0 * ta / tb;
    let v = two_views(DepthStyle::Piecewise);
    let knot = 4.0 / 19.0;
    for uv in grid() {
        let c = centred(uv);
        for t in [0.0, 0.1, knot] {
            let p = local(&v, uv, t);
            assert!((p.z - (1.0 + 19.0 * t)).abs() < 1e-9);
            let image = DVec2::new(p.x, p.y) / p.z;
            assert!((image - c * DVec2::new(ta, ta * ASPECT)).length() < 1e-9);
        }
        for t in [knot, 0.5, 1.0] {
            let p = local(&v, uv, t);
            let image = DVec2::new(p.x, p.y) / (p.z - eye_b);
            assert!((image - c * DVec2::new(tb, tb * ASPECT)).length() < 1e-9);
        }
    }
    // A kink at the knot: the tangent jumps from A's direction to B's.
    let uv = DVec2::new(0.9, 0.2);
    let c = centred(uv);
    let dir_a = DVec3::new(c.x * ta, c.y * ta * ASPECT, 1.0).normalize();
    let dir_b = DVec3::new(c.x * tb, c.y * tb * ASPECT, 1.0).normalize();
    let b = basis();
    let before = b.to_local(v.tangent(uv, knot - 1e-9)).normalize();
    let after = b.to_local(v.tangent(uv, knot + 1e-9)).normalize();
    assert!(close(before, dir_a) && close(after, dir_b));
    assert!(before.dot(after) < 0.999);
}

#[test]
fn quadratic_depth_transition_is_smooth_and_tangent_to_both_views_at_its_ends() {
    let (ta, tb) = (30f64.to_radians().tan(), 15f64.to_radians().tan());
    let v = two_views(DepthStyle::Quadratic);
    let b = basis();
    for uv in grid() {
        let c = centred(uv);
        let dir_a = DVec3::new(c.x * ta, c.y * ta * ASPECT, 1.0).normalize();
        let dir_b = DVec3::new(c.x * tb, c.y * tb * ASPECT, 1.0).normalize();
        // Starts on A's near rectangle along A's ray, ends on B's far one along B's.
        let start = local(&v, uv, 0.0);
        assert!(close(start, DVec3::new(c.x * ta, c.y * ta * ASPECT, 1.0)));
        assert!(close(b.to_local(v.tangent(uv, 0.0)).normalize(), dir_a));
        assert!(close(b.to_local(v.tangent(uv, 1.0)).normalize(), dir_b));
        // No kink anywhere: the tangent's direction changes by O(h) over a step h.
        for t in [0.1, 4.0 / 19.0, 0.5, 0.9] {
            let before = v.tangent(uv, t - 1e-6).normalize();
            let after = v.tangent(uv, t + 1e-6).normalize();
            assert!(before.dot(after) > 1.0 - 1e-9, "{uv} {t}");
        }
    }
    assert!(matches!(
        v.projector(DVec2::splat(0.3)),
        Some(Projector::QuadraticBezier(_))
    ));
}

#[test]
fn depth_transition_with_three_views_and_bad_parameters() {
    let p = |fovs: Vec<f64>, transitions: Vec<f64>, style| {
        spec(
            Preset::DepthTransition {
                fovs,
                transitions,
                style,
            },
            [1.0, 20.0],
        )
        .volume(ASPECT)
    };
    let v = p(
        vec![60.0, 30.0, 90.0],
        vec![5.0, 10.0],
        DepthStyle::Piecewise,
    )
    .unwrap();
    assert!(matches!(v.projector(DVec2::ZERO), Some(Projector::Polyline(q)) if q.len() == 4));
    assert!(p(
        vec![60.0, 30.0, 90.0],
        vec![5.0, 10.0],
        DepthStyle::Quadratic
    )
    .is_err());
    assert!(p(vec![60.0, 30.0], vec![25.0], DepthStyle::Piecewise).is_err());
    assert!(p(vec![60.0, 180.0], vec![5.0], DepthStyle::Piecewise).is_err());
    assert!(p(vec![60.0], vec![], DepthStyle::Piecewise).is_err());
}

/// Occlusion camera of fov 60: distortion from 4 to the far clip 10, pole at the image
/// centre, strength 0.1 image widths.
fn occlusion(pole: DVec2) -> Volume {
    spec(
        Preset::Occlusion {
            fov: 60.0,
            transition: 4.0,
            pole,
            strength: 0.1,
        },
        [0.0, 10.0],
    )
    .volume(ASPECT)
    .unwrap()
}

#[test]
fn occlusion_displacement_matches_the_closed_form() {
    let tan = 30f64.to_radians().tan();
    let pole = DVec2::new(0.5, 0.5);
    let v = occlusion(pole);
    let perspective = spec(Preset::Perspective { fov: 60.0 }, [0.0, 10.0])
        .volume(ASPECT)
        .unwrap();
    let knot = 0.4;
    let far_width = 2.0 * 10.0 * tan;
    for uv in [
        DVec2::new(0.9, 0.5),
        DVec2::new(0.2, 0.9),
        DVec2::new(0.0, 0.0),
    ] {
        let offset = (uv - pole) * DVec2::new(1.0, ASPECT);
        let unit = offset.normalize();
        for t in [0.0, 0.2, knot] {
            assert!(close(local(&v, uv, t), local(&perspective, uv, t)));
        }
        // Behind the distortion plane the projector is pulled towards the pole by
        // s k W_far, s = (t - t1) / (1 - t1): half of it half way, all of it at the far end.
        for (t, s) in [((knot + 1.0) / 2.0, 0.5), (1.0, 1.0)] {
            let d = local(&v, uv, t) - local(&perspective, uv, t);
            let want = (-s * 0.1 * far_width * unit).extend(0.0);
            assert!(close(d, want), "{uv} {t}: {d} vs {want}");
        }
    }
    // Inside the disc of radius k round the pole every projector ends at the pole's far
    // point.
    let far_pole = local(&v, pole, 1.0);
    assert!(close(far_pole, DVec3::Z * 10.0));
    assert!(close(local(&v, DVec2::new(0.55, 0.52), 1.0), far_pole));
}

#[test]
fn occlusion_sees_a_point_hidden_behind_the_occluder() {
    // An occluding ball of radius 0.3 on the axis at distance 4.5 hides the axis behind it
    // from the eye; the point on the axis at the far clip is seen by the occlusion camera.
    let (centre, radius) = (DVec3::Z * 4.5, 0.3);
    let hidden = DVec3::Z * 10.0;
    let v = occlusion(DVec2::splat(0.5));
    let misses = |a: DVec3, b: DVec3| {
        let d = b - a;
        let s = ((centre - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
        (a + s * d - centre).length() > radius
    };
    let uv = DVec2::new(0.5 + 0.095, 0.5);
    let (q0, q1, q2) = (local(&v, uv, 0.0), local(&v, uv, 0.4), local(&v, uv, 1.0));
    assert!(close(q2, hidden));
    assert!(misses(q0, q1) && misses(q1, q2));
    // The perspective ray to the same point passes through the ball.
    assert!(!misses(DVec3::ZERO, hidden));
}

#[test]
fn occlusion_parameters_are_checked() {
    let p = |transition: f64, pole: DVec2, strength: f64| {
        spec(
            Preset::Occlusion {
                fov: 60.0,
                transition,
                pole,
                strength,
            },
            [0.0, 10.0],
        )
        .volume(ASPECT)
    };
    assert!(p(4.0, DVec2::splat(0.5), 0.1).is_ok());
    assert!(p(10.0, DVec2::splat(0.5), 0.1).is_err());
    assert!(p(4.0, DVec2::new(0.5, -0.1), 0.1).is_err());
    assert!(p(4.0, DVec2::splat(0.5), -0.1).is_err());
}

fn pushbroom_path(width: f64, directions: Option<Vec<DVec3>>) -> Preset {
    let b = basis();
    Preset::Mcop {
        path: vec![
            b.origin - 0.5 * width * b.right,
            b.origin + 0.5 * width * b.right,
        ],
        directions,
        v_fov: 50.0,
    }
}

#[test]
fn a_straight_mcop_path_with_one_direction_is_the_pushbroom() {
    let (w, h) = (16, 12);
    let mcop = flexible(pushbroom_path(6.0, None), [0.0, 50.0], w, h);
    let forward = vec![basis().forward * 3.0; 2];
    let given = flexible(pushbroom_path(6.0, Some(forward)), [0.0, 50.0], w, h);
    let pushbroom = flexible(
        Preset::Pushbroom {
            width: 6.0,
            v_fov: 50.0,
        },
        [0.0, 50.0],
        w,
        h,
    );
    for y in 0..h {
        for x in 0..w {
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let want = pushbroom.ray(pixel).unwrap();
            for f in [&mcop, &given] {
                let got = f.ray(pixel).unwrap();
                assert!(close(got.origin, want.origin), "{pixel}");
                assert!(close(got.direction, want.direction), "{pixel}");
            }
        }
    }
}

#[test]
fn every_mcop_column_starts_at_its_path_point() {
    // An L-shaped path: 3 along +x looking -z, then 1 along -z looking +x.
    let points = vec![DVec3::ZERO, DVec3::X * 3.0, DVec3::new(3.0, 0.0, -1.0)];
    let looks = vec![DVec3::NEG_Z, DVec3::NEG_Z, DVec3::X];
    let path = McopPath::new(points.clone(), looks.clone(), DVec3::Y).unwrap();
    let f = flexible(
        Preset::Mcop {
            path: points,
            directions: Some(looks),
            v_fov: 40.0,
        },
        [0.0, 100.0],
        40,
        10,
    );
    for x in 0..40 {
        let u = (f64::from(x) + 0.5) / 40.0;
        let (start, look) = path.station(u);
        let expected = match u * 4.0 {
            s if s <= 3.0 => DVec3::X * s,
            s => DVec3::new(3.0, 0.0, 3.0 - s),
        };
        assert!(close(start, expected), "{x}");
        for y in 0..10 {
            let ray = f
                .ray(DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5))
                .unwrap();
            assert!(close(ray.origin, start));
            // Each column is a vertical fan about its look direction.
            let d = ray.direction.normalize();
            assert!(d.dot(look.cross(DVec3::Y)).abs() < 1e-12);
            assert!(d.dot(look) > 0.9);
        }
    }
    // Not in the analytic class: method raster refuses it with the one-line message.
    let e = supported_chart(&f).unwrap_err();
    assert!(
        e.message.contains("has none: its ") && e.message.ends_with("(use --method raycast)"),
        "{e}"
    );
}

fn magnifier(m: f64) -> Preset {
    Preset::Magnifier {
        fov: 60.0,
        lens: Magnifier {
            center: DVec2::new(0.5, 0.5),
            radius: 0.25,
            magnification: m,
        },
    }
}

#[test]
fn magnifier_is_perspective_outside_and_magnifies_the_centre() {
    let (w, h) = (80, 60);
    let lens = flexible(magnifier(3.0), [0.0, 100.0], w, h);
    let plain = flexible(Preset::Perspective { fov: 60.0 }, [0.0, 100.0], w, h);
    // Outside the circle (radius 15 pixels round (40, 30)): exactly the perspective rays.
    for pixel in [
        DVec2::new(5.5, 5.5),
        DVec2::new(60.5, 30.5),
        DVec2::new(40.5, 50.5),
    ] {
        assert_eq!(lens.ray(pixel), plain.ray(pixel));
    }
    // At the centre: a scene point's image moves 3 times as far as in the perspective.
    let b = basis();
    let at = |dx: f64, dy: f64| b.origin + b.forward * 10.0 + b.right * dx + b.up * dy;
    let image = |f: &Flexible, p: DVec3| {
        let mut out = Vec::new();
        f.inverse().unwrap().project(p, &mut out);
        out[0].pixel
    };
    let centre = DVec2::new(40.0, 30.0);
    assert!((image(&lens, at(0.0, 0.0)) - centre).length() < 1e-9);
    for (dx, dy) in [(1e-6, 0.0), (0.0, 1e-6), (-7e-7, 7e-7)] {
        let moved = image(&lens, at(dx, dy)) - centre;
        let plain_moved = image(&plain, at(dx, dy)) - centre;
        let ratio = moved.length() / plain_moved.length();
        assert!((ratio - 3.0).abs() < 1e-3, "{ratio}");
    }
    // In the analytic class: method raster accepts it.
    assert!(supported_chart(&lens).is_ok());
}

proptest! {
    #[test]
    fn magnifier_inverse_recovers_the_pixel(
        x in 0.0f64..80.0, y in 0.0f64..60.0, t in 0.05f64..1.0, m in 0.3f64..8.0,
    ) {
        let lens = flexible(magnifier(m), [0.5, 50.0], 80, 60);
        let pixel = DVec2::new(x, y);
        let point = lens.ray(pixel).unwrap().at(t);
        let mut out = Vec::new();
        lens.inverse().unwrap().project(point, &mut out);
        prop_assert_eq!(out.len(), 1);
        prop_assert!((out[0].pixel - pixel).length() < 1e-6, "{} {}", out[0].pixel, pixel);
        prop_assert!((out[0].t - t).abs() < 1e-9);
    }
}

/// The quadratic depth styles are in the scanline class of curved projectors (three flat
/// parallel surfaces) and have a chart; the occlusion camera's bent projectors do not.
#[test]
fn quadratic_presets_have_a_chart_and_the_occlusion_camera_is_refused() {
    let quadratic = [
        Preset::OrthoNearPerspFar {
            fov: 50.0,
            transition: 4.0,
            style: DepthStyle::Quadratic,
        },
        Preset::DepthTransition {
            fovs: vec![60.0, 30.0],
            transitions: vec![5.0],
            style: DepthStyle::Quadratic,
        },
    ];
    for preset in quadratic {
        let f = flexible(preset, [1.0, 20.0], 16, 12);
        if let Err(e) = supported_chart(&f) {
            panic!("{e}");
        }
    }
    let occlusion = Preset::Occlusion {
        fov: 60.0,
        transition: 4.0,
        pole: DVec2::splat(0.5),
        strength: 0.1,
    };
    let e = supported_chart(&flexible(occlusion, [1.0, 20.0], 16, 12)).unwrap_err();
    assert!(
        e.message.contains("has none: its ") && e.message.ends_with("(use --method raycast)"),
        "{e}"
    );
}

fn ddoc(map: Option<DdocMap>) -> Flexible {
    let preset = Preset::Ddoc {
        fov: 60.0,
        z_near: 4.0,
        z_far: 8.0,
        map: map.map(Arc::new),
    };
    flexible(preset, [0.5, 20.0], 40, 30)
}

fn constant_map(d: DVec2) -> DdocMap {
    DdocMap::new(4, 3, vec![d; 12]).unwrap()
}

/// With a zero map (or none) every projector of the DDOC lies on the perspective's ray: the
/// directions of its three segments agree with the perspective preset's to 1e-9, and it
/// starts where the perspective does.
#[test]
fn a_zero_ddoc_map_is_the_perspective() {
    let perspective = flexible(Preset::Perspective { fov: 60.0 }, [0.5, 20.0], 40, 30);
    for f in [ddoc(Some(constant_map(DVec2::ZERO))), ddoc(None)] {
        for (x, y) in [(0.5, 0.5), (13.25, 7.5), (20.0, 15.0), (39.5, 29.5)] {
            let pixel = DVec2::new(x, y);
            let ray = perspective.ray(pixel).unwrap();
            let Some(Projector::Polyline(points)) = f.projector(pixel) else {
                panic!("a polyline projector at {pixel}");
            };
            assert_eq!(points.len(), 4);
            assert!(close(points[0], ray.origin), "{pixel}");
            let d = ray.direction.normalize();
            for w in points.windows(2) {
                let s = (w[1] - w[0]).normalize();
                assert!((s - d).length() < 1e-9, "{pixel}: {s} against {d}");
            }
            assert!(close(points[3], ray.origin + ray.direction), "{pixel}");
        }
    }
}

/// A constant map m: up to z_near the projector is the perspective's; from z_far on it is
/// the perspective ray through image position q - m (a line through the eye).
#[test]
fn a_ddoc_map_moves_the_far_samples() {
    let m = DVec2::new(0.05, -0.02);
    let f = ddoc(Some(constant_map(m)));
    let perspective = flexible(Preset::Perspective { fov: 60.0 }, [0.5, 20.0], 40, 30);
    let b = basis();
    for (x, y) in [(3.5, 4.5), (20.0, 15.0), (35.25, 28.0)] {
        let pixel = DVec2::new(x, y);
        let Some(Projector::Polyline(points)) = f.projector(pixel) else {
            panic!("a polyline projector at {pixel}");
        };
        let own = perspective.ray(pixel).unwrap();
        let depth = |p: DVec3| b.to_local(p - b.origin).z;
        let on = |ray: &crate::geometry::Ray, p: DVec3| {
            let t = (depth(p) - depth(ray.origin)) / b.to_local(ray.direction).z;
            close(ray.at(t), p)
        };
        assert!(on(&own, points[1]) && (depth(points[1]) - 4.0).abs() < 1e-9);
        // q - m in pixels: u right, v up (y down).
        let moved = pixel - DVec2::new(m.x * 40.0, -m.y * 30.0);
        let far = perspective.ray(moved).unwrap();
        assert!(on(&far, points[2]) && on(&far, points[3]), "{pixel}");
        assert!((depth(points[2]) - 8.0).abs() < 1e-9);
    }
}

#[test]
fn ddoc_parameters_are_checked() {
    let cases = [
        ((4.0, 3.0), "0 < z_near < z_far"),
        ((0.2, 8.0), "strictly between the near and far clip"),
        ((4.0, 30.0), "strictly between the near and far clip"),
    ];
    for ((z_near, z_far), expected) in cases {
        let preset = Preset::Ddoc {
            fov: 60.0,
            z_near,
            z_far,
            map: None,
        };
        let e = spec(preset, [0.5, 20.0])
            .volume(ASPECT)
            .unwrap_err()
            .message;
        assert!(e.contains(expected), "{e} (expected {expected})");
    }
    // The raster inverts it (its refusal of steep maps: `displaced_inverse_tests`).
    assert!(supported_chart(&ddoc(Some(constant_map(DVec2::ZERO)))).is_ok());
}

/// The piecewise depth volumes: polylines through coaxial rectangles.
fn piecewise_depth_presets() -> [Preset; 2] {
    [
        Preset::OrthoNearPerspFar {
            fov: 50.0,
            transition: 4.0,
            style: DepthStyle::Piecewise,
        },
        Preset::DepthTransition {
            fovs: vec![60.0, 20.0, 45.0],
            transitions: vec![5.0, 9.0],
            style: DepthStyle::Piecewise,
        },
    ]
}

proptest! {
    /// The inverse of a polyline volume between parallel planes (one parallel-planes inverse
    /// per segment, picked by depth) returns every point Q(u, v, t) to its pixel and t, also
    /// on the stations where the segments meet.
    #[test]
    fn piecewise_depth_inverse_returns_each_point_to_its_pixel(
        x in 0.0f64..40.0,
        y in 0.0f64..30.0,
        t in 0.0f64..1.0,
        on_station in proptest::bool::ANY,
        which in 0usize..2,
    ) {
        let preset = piecewise_depth_presets()[which].clone();
        // clip [1, 20]: the transition at 4 m is at t = 3 / 19.
        let t = if on_station { 3.0 / 19.0 } else { t };
        let f = flexible(preset, [1.0, 20.0], 40, 30);
        let pixel = DVec2::new(x, y);
        let point = f.point(pixel, t).unwrap();
        let mut images = Vec::new();
        f.inverse().unwrap().project(point, &mut images);
        prop_assert_eq!(images.len(), 1);
        prop_assert!((images[0].pixel - pixel).length() < 1e-6, "{} {}", images[0].pixel, pixel);
        prop_assert!((images[0].t - t).abs() < 1e-9, "{} {}", images[0].t, t);
    }
}

/// Both piecewise depth volumes have a chart for the raster; a transition whose station
/// degenerates (perspective views meeting at a point inside the volume) has none; surfaces
/// going back, not flat or not parallel have no layered inverse.
#[test]
fn piecewise_depth_volumes_have_a_chart() {
    for preset in piecewise_depth_presets() {
        let f = flexible(preset, [1.0, 20.0], 16, 12);
        assert!(supported_chart(&f).is_ok());
    }
    // A near station of width 0 inside the volume (clip from 0 with a first view ending at
    // the eye's own point is the only way to reach it through a preset): surfaces given by
    // hand instead, a rectangle, a point and a rectangle along one axis.
    let rect = |z: f64, h: f64| Surface::Rectangle {
        corner: DVec3::new(-h, -h, z),
        u_edge: DVec3::new(2.0 * h, 0.0, 0.0),
        v_edge: DVec3::new(0.0, 2.0 * h, 0.0),
    };
    use super::super::inverse::Inverse;
    let knots = [0.0, 0.5, 1.0];
    let pinched = vec![rect(0.0, 1.0), rect(2.0, 0.0), rect(4.0, 1.0)];
    let inverse = Inverse::classify_layers(&pinched, &knots).expect("parallel planes in order");
    let resolution = crate::projection::image_coords::Resolution::new(16, 12).unwrap();
    assert!(inverse.chart(&Reparam::Linear, &resolution).is_none());
    // No inverse: planes that go back along the axis (a projector would cross a depth
    // twice), a surface that is not flat, planes that are not parallel.
    let back = vec![rect(0.0, 1.0), rect(4.0, 2.0), rect(2.0, 3.0)];
    assert!(Inverse::classify_layers(&back, &knots).is_none());
    let bent = Surface::Bilinear {
        corners: [
            DVec3::new(-1.0, -1.0, 2.0),
            DVec3::new(1.0, -1.0, 2.0),
            DVec3::new(1.0, 1.0, 3.0),
            DVec3::new(-1.0, 1.0, 2.0),
        ],
    };
    let curved = vec![rect(0.0, 1.0), bent, rect(4.0, 1.0)];
    assert!(Inverse::classify_layers(&curved, &knots).is_none());
    let tilted = Surface::Rectangle {
        corner: DVec3::new(-1.0, -1.0, 4.0),
        u_edge: DVec3::new(2.0, 0.0, 1.0),
        v_edge: DVec3::new(0.0, 2.0, 0.0),
    };
    let turned = vec![rect(0.0, 1.0), rect(2.0, 1.0), tilted];
    assert!(Inverse::classify_layers(&turned, &knots).is_none());
}
