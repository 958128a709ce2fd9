//! Presets against their closed forms (the notes' "Closed-form oracles"), against the
//! single-viewpoint projections, and the inverse against the rays.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::*;
use crate::projection::camera_basis::CameraBasis;
use crate::projection::{CameraFrame, ProjectionSpec};

/// The camera frame every preset test uses (also the panorama tests').
pub(super) fn frame() -> CameraFrame {
    CameraFrame {
        position: DVec3::new(1.0, 2.0, 3.0),
        look_at: DVec3::new(-2.0, 1.0, 0.0),
        up: DVec3::Y,
    }
}

/// `preset` seen from [`frame`], with optional clip distances.
pub(super) fn preset(preset: Preset, clip: Option<[f64; 2]>) -> FlexibleSpec {
    FlexibleSpec {
        source: VolumeSource::Preset(PresetSpec {
            preset,
            frame: frame(),
            clip,
        }),
        reparam: None,
    }
}

fn build(spec: &FlexibleSpec, w: u32, h: u32) -> Flexible {
    Flexible::new(spec, w, h).unwrap_or_else(|e| panic!("{spec:?}: {e}"))
}

/// For every pixel centre of a w x h image and t in {0, 0.4, 1}: the point on the ray, in
/// camera-local coordinates, satisfies `oracle(local) == image(pixel)`; `t_of(local)` (when
/// given) is the ray parameter.
fn check_oracle(
    spec: &FlexibleSpec,
    size: (u32, u32),
    image: impl Fn(&Flexible, DVec2) -> DVec2,
    oracle: impl Fn(DVec3) -> DVec2,
    t_of: Option<&dyn Fn(DVec3) -> f64>,
) {
    check_oracle_at(spec, size, &[0.0, 0.4, 1.0], image, oracle, t_of);
}

/// [`check_oracle`] at the ray parameters `ts`.
fn check_oracle_at(
    spec: &FlexibleSpec,
    (w, h): (u32, u32),
    ts: &[f64],
    image: impl Fn(&Flexible, DVec2) -> DVec2,
    oracle: impl Fn(DVec3) -> DVec2,
    t_of: Option<&dyn Fn(DVec3) -> f64>,
) {
    let f = build(spec, w, h);
    let basis = CameraBasis::new(&frame()).unwrap();
    let mut rays = 0;
    for y in 0..h {
        for x in 0..w {
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let Some(ray) = f.ray(pixel) else { continue };
            rays += 1;
            for &t in ts {
                let local = basis.to_local(ray.at(t) - basis.origin);
                let got = oracle(local);
                let want = image(&f, pixel);
                assert!(
                    (got - want).length() < 1e-9,
                    "{pixel} t {t}: {got} vs {want}"
                );
                if let Some(t_of) = t_of {
                    assert!((t_of(local) - t).abs() < 1e-9);
                }
            }
        }
    }
    assert!(rays > 0);
}

/// (U, V) = (2u - 1, 2v - 1) of a pixel.
fn centred_uv(f: &Flexible, pixel: DVec2) -> DVec2 {
    2.0 * f.uv(pixel).unwrap() - DVec2::ONE
}

/// [`check_oracle`] of the centred (U, V) for a spec clipped to depths [1, 2]: the ray
/// parameter is also checked, as the depth beyond the near plane, z - 1.
fn check_uv_clipped_to_1_2(spec: &FlexibleSpec, size: (u32, u32), oracle: impl Fn(DVec3) -> DVec2) {
    check_oracle(spec, size, centred_uv, oracle, Some(&|p: DVec3| p.z - 1.0));
}

#[test]
fn perspective_is_u_x_over_z() {
    // The thesis' squares: c_n = (0,0,1), l_n = 1; c_f = (0,0,2), l_f = 2.
    let spec = preset(Preset::Perspective { fov: 90.0 }, Some([1.0, 2.0]));
    let oracle = |p: DVec3| DVec2::new(p.x / p.z, p.y / p.z);
    check_uv_clipped_to_1_2(&spec, (8, 8), oracle);
}

#[test]
fn inverse_perspective_is_u_x_over_e_minus_z() {
    // l_n = 2 at z = 1, l_f = 1 at z = 2: the projectors meet at e = 3 (look_at, further
    // along the same axis, only aims the camera).
    let f = frame();
    let converge = f.position + 3.0 * (f.look_at - f.position).normalize();
    let spec = preset(
        Preset::InversePerspective {
            fov: 90.0,
            converge,
        },
        Some([1.0, 2.0]),
    );
    let oracle = |p: DVec3| DVec2::new(p.x, p.y) / (3.0 - p.z);
    check_uv_clipped_to_1_2(&spec, (8, 8), oracle);
}

/// The inverse perspective's projectors all end at `converge` (default clip: up to its
/// depth), also off the view axis, where the volume leans towards it; `converge` on or
/// behind the eye's plane is refused.
#[test]
fn inverse_perspective_projectors_meet_at_converge() {
    let f = frame();
    let basis = CameraBasis::new(&f).unwrap();
    let converge = f.position + basis.to_world(DVec3::new(1.5, -0.5, 6.0));
    let spec = preset(
        Preset::InversePerspective {
            fov: 70.0,
            converge,
        },
        None,
    );
    let flexible = build(&spec, 12, 8);
    for (x, y) in [(0.0, 0.0), (12.0, 8.0), (3.5, 6.25), (6.0, 4.0)] {
        let end = flexible.point(DVec2::new(x, y), 1.0).unwrap();
        assert!((end - converge).length() < 1e-12, "{x} {y}: {end}");
    }
    // The image centre's projector starts at the eye and runs straight to converge.
    let start = flexible.point(DVec2::new(6.0, 4.0), 0.0).unwrap();
    assert!((start - f.position).length() < 1e-12);
    for depth in [0.0, -2.0] {
        let behind = f.position + basis.to_world(DVec3::new(1.0, 0.0, depth));
        let spec = preset(
            Preset::InversePerspective {
                fov: 70.0,
                converge: behind,
            },
            None,
        );
        let e = Flexible::new(&spec, 12, 8).unwrap_err();
        assert!(e.message.contains("must lie in front of the eye"), "{e}");
    }
}

#[test]
fn orthographic_and_oblique_are_affine() {
    let spec = preset(Preset::Orthographic { width: 2.0 }, Some([1.0, 2.0]));
    let oracle = |p: DVec3| DVec2::new(p.x, p.y);
    check_uv_clipped_to_1_2(&spec, (6, 6), oracle);
    let shear = DVec2::new(0.5, -0.25);
    let spec = preset(Preset::Oblique { width: 2.0, shear }, Some([1.0, 2.0]));
    let oracle = |p: DVec3| DVec2::new(p.x + shear.x * p.z, p.y + shear.y * p.z);
    check_oracle(&spec, (6, 6), centred_uv, oracle, None);
}

#[test]
fn pushbroom_is_x_and_y_over_z() {
    // Q_n = (u, v, 1), Q_f = (u, 2v, 2).
    let spec = preset(
        Preset::Pushbroom {
            width: 2.0,
            v_fov: 90.0,
        },
        Some([1.0, 2.0]),
    );
    let oracle = |p: DVec3| DVec2::new(p.x, p.y / p.z);
    check_uv_clipped_to_1_2(&spec, (6, 6), oracle);
    // The notes' numbers (2,2,1) -> (2,2), (3,3,2) -> (3,1.5), (4,4,3) -> (4,4/3), through
    // the inverse: half width 4 and tan(v_fov/2) = 4 put them inside the image.
    let v_fov = 2.0 * 4f64.atan().to_degrees();
    let spec = preset(Preset::Pushbroom { width: 8.0, v_fov }, Some([0.5, 4.0]));
    let f = build(&spec, 10, 10);
    let basis = CameraBasis::new(&frame()).unwrap();
    for (local, want) in [
        (DVec3::new(2.0, 2.0, 1.0), DVec2::new(2.0, 2.0)),
        (DVec3::new(3.0, 3.0, 2.0), DVec2::new(3.0, 1.5)),
        (DVec3::new(4.0, 4.0, 3.0), DVec2::new(4.0, 4.0 / 3.0)),
    ] {
        let mut out = Vec::new();
        f.inverse()
            .unwrap()
            .project(basis.origin + basis.to_world(local), &mut out);
        assert_eq!(out.len(), 1);
        let got = 4.0 * centred_uv(&f, out[0].pixel);
        assert!((got - want).length() < 1e-9, "{local}: {got}");
    }
}

#[test]
fn crossed_slits_meet_both_slits() {
    let preset_ = Preset::CrossedSlits {
        fov: 90.0,
        v_fov: Some(90.0),
        slit_distance: -1.0,
    };
    let spec = preset(preset_, Some([1.0, 2.0]));
    let oracle = |p: DVec3| DVec2::new(p.x / p.z, p.y / (p.z + 1.0));
    check_uv_clipped_to_1_2(&spec, (8, 6), oracle);
}

#[test]
fn cylindrical_and_equirectangular_closed_forms() {
    let spec = preset(
        Preset::Cylindrical {
            h_fov: 180.0,
            v_fov: 90.0,
        },
        Some([1.0, 2.0]),
    );
    let oracle = |p: DVec3| DVec2::new(p.x.atan2(p.z) / FRAC_PI_2, p.y / p.x.hypot(p.z));
    check_oracle(&spec, (8, 6), centred_uv, oracle, None);
    let spec = preset(
        Preset::Equirectangular {
            h_fov: 360.0,
            v_fov: 180.0,
        },
        Some([0.5, 2.0]),
    );
    let oracle = |p: DVec3| DVec2::new(p.x.atan2(p.z) / PI, p.y.atan2(p.x.hypot(p.z)) / FRAC_PI_2);
    check_oracle(&spec, (8, 6), centred_uv, oracle, None);
}

#[test]
fn angular_fisheye_radius_is_proportional_to_the_angle() {
    let spec = preset(Preset::Fisheye { fov: 200.0 }, Some([0.5, 2.0]));
    let half = 100f64.to_radians();
    let image = |f: &Flexible, pixel: DVec2| {
        let (w, h) = f.resolution();
        f.resolution.centred(pixel) / (0.5 * f64::from(w.min(h)))
    };
    let oracle = |p: DVec3| {
        let lateral = DVec2::new(p.x, p.y);
        let angle = lateral.length().atan2(p.z);
        lateral.normalize_or_zero() * angle / half
    };
    check_oracle(&spec, (9, 7), image, oracle, None);
}

/// Same rays (directions up to normalisation; origins too where the near surface is the
/// eye or the view plane) as the single-viewpoint projection at every pixel centre.
fn check_same_rays(flexible: Preset, existing: ProjectionSpec, same_origin: bool) {
    let (w, h) = (9, 7);
    let f = build(&preset(flexible.clone(), None), w, h);
    let e = existing.build(w, h).unwrap();
    for y in 0..h {
        for x in 0..w {
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            match (f.ray(pixel), e.ray(pixel)) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    let (da, db) = (a.direction.normalize(), b.direction.normalize());
                    assert!(
                        (da - db).length() < 1e-12,
                        "{flexible:?} {pixel}: {da} {db}"
                    );
                    if same_origin {
                        assert!((a.origin - b.origin).length() < 1e-12);
                    }
                    assert_eq!((a.t_min, a.t_max), (0.0, 1.0));
                }
                (a, b) => panic!("{flexible:?} {pixel}: {a:?} vs {b:?}"),
            }
        }
    }
}

#[test]
fn presets_reproduce_the_single_viewpoint_projections() {
    let frame = frame();
    check_same_rays(
        Preset::Perspective { fov: 70.0 },
        ProjectionSpec::Perspective { frame, fov: 70.0 },
        true,
    );
    check_same_rays(
        Preset::Orthographic { width: 3.0 },
        ProjectionSpec::Orthographic { frame, width: 3.0 },
        true,
    );
    check_same_rays(
        Preset::Fisheye { fov: 250.0 },
        ProjectionSpec::Fisheye { frame, fov: 250.0 },
        true,
    );
    check_same_rays(
        Preset::Equirectangular {
            h_fov: 360.0,
            v_fov: 180.0,
        },
        ProjectionSpec::Equirectangular {
            frame,
            h_fov: 360.0,
            v_fov: 180.0,
        },
        true,
    );
    check_same_rays(
        Preset::Cylindrical {
            h_fov: 300.0,
            v_fov: 100.0,
        },
        ProjectionSpec::Cylindrical {
            frame,
            h_fov: 300.0,
            v_fov: 100.0,
        },
        true,
    );
    // Crossed slits with the slits together is a perspective camera.
    check_same_rays(
        Preset::CrossedSlits {
            fov: 70.0,
            v_fov: None,
            slit_distance: 0.0,
        },
        ProjectionSpec::Perspective { frame, fov: 70.0 },
        true,
    );
}

#[test]
fn builds_through_projection_spec_and_checks_parameters() {
    let spec = ProjectionSpec::Flexible(Box::new(preset(Preset::Perspective { fov: 60.0 }, None)));
    let p = spec.build(20, 10).unwrap();
    assert_eq!((p.kind(), spec.kind()), ("flexible", "flexible"));
    assert!(p.inverse().is_ok());
    for (bad, needle) in [
        (
            Preset::Perspective { fov: 180.0 },
            "flexible perspective fov",
        ),
        (
            Preset::Orthographic { width: 0.0 },
            "flexible orthographic width",
        ),
        (Preset::Fisheye { fov: 400.0 }, "flexible fisheye fov"),
    ] {
        let e = Flexible::new(&preset(bad, None), 8, 8).unwrap_err();
        assert!(e.message.starts_with(needle), "{e}");
    }
    let e = Flexible::new(
        &preset(Preset::Perspective { fov: 60.0 }, Some([2.0, 1.0])),
        8,
        8,
    );
    assert!(e.unwrap_err().message.contains("clip"));
    let e = Flexible::new(
        &preset(
            Preset::InversePerspective {
                fov: 60.0,
                converge: frame().look_at,
            },
            Some([0.0, 100.0]),
        ),
        8,
        8,
    );
    assert!(e.unwrap_err().message.contains("beyond"));
    assert!(Flexible::new(&preset(Preset::Perspective { fov: 60.0 }, None), 0, 8).is_err());
}

#[test]
fn a_point_near_surface_is_a_pinhole() {
    // Point near surface + far rectangle = the perspective preset with clip [0, 2].
    let basis = CameraBasis::new(&frame()).unwrap();
    let far = Surface::rectangle_centred(
        basis.origin + 2.0 * basis.forward,
        2.0 * basis.right,
        2.0 * basis.up,
    );
    let custom = FlexibleSpec {
        source: VolumeSource::Surfaces {
            near: Surface::Point(basis.origin),
            far,
        },
        reparam: None,
    };
    let a = build(&custom, 5, 5);
    let b = build(
        &preset(Preset::Perspective { fov: 90.0 }, Some([0.0, 2.0])),
        5,
        5,
    );
    let pixel = DVec2::new(1.5, 3.5);
    let (ra, rb) = (a.ray(pixel).unwrap(), b.ray(pixel).unwrap());
    assert!((ra.origin - rb.origin).length() < 1e-12);
    assert!((ra.direction - rb.direction).length() < 1e-12);
    assert!(a.inverse().is_ok());
    // The eye itself: every projector meets there, no single image.
    let mut out = Vec::new();
    a.inverse().unwrap().project(basis.origin, &mut out);
    assert!(out.is_empty());
}

#[test]
fn outside_the_domain_there_is_no_ray() {
    let f = build(&preset(Preset::Perspective { fov: 60.0 }, None), 10, 10);
    assert!(f.ray(DVec2::new(-0.5, 5.0)).is_none());
    assert!(f.ray(DVec2::new(5.0, 10.5)).is_none());
    assert!(f.ray(DVec2::new(10.0, 0.0)).is_some());
    let g = build(&preset(Preset::Fisheye { fov: 180.0 }, None), 20, 10);
    assert!(g.ray(DVec2::new(1.0, 1.0)).is_none());
}

fn custom(near: Surface, far: Surface) -> Flexible {
    build(
        &FlexibleSpec {
            source: VolumeSource::Surfaces { near, far },
            reparam: None,
        },
        16,
        12,
    )
}

#[test]
fn volumes_outside_the_analytic_class_have_no_inverse() {
    let rect = |z: f64| Surface::rectangle_centred(DVec3::Z * z, DVec3::X, DVec3::Y);
    let twisted = Surface::Bilinear {
        corners: [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.5),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ],
    };
    let tilted = Surface::rectangle_centred(DVec3::Z * 2.0, DVec3::X, DVec3::new(0.0, 1.0, 0.3));
    let sphere = Surface::Sphere(SpherePatch {
        center: DVec3::ZERO,
        radius: 3.0,
        frame: PolarFrame::new(DVec3::Y, DVec3::Z).unwrap(),
        longitude: [-1.0, 1.0],
        latitude: [-0.5, 0.5],
    });
    for (near, far) in [
        (twisted, rect(2.0)),
        (rect(0.0), tilted),
        (rect(0.0), sphere),
    ] {
        let f = custom(near.clone(), far.clone());
        // Outside the analytic class, which the reason names.
        assert!(
            matches!(f.inverse(), Err(NoInverse { reason: Some(r) }) if r.contains("scanline class")),
            "{near:?} {far:?}"
        );
    }
    // A flat (parallelogram) bilinear quad is affine: invertible.
    let flat = Surface::Bilinear {
        corners: [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ],
    };
    assert!(custom(flat, rect(2.0)).inverse().is_ok());
}

/// The invertible volumes of the proptest: every preset, and custom planes, spheres and
/// cylinders whose surfaces differ in more than their size.
fn invertible() -> Vec<Flexible> {
    let mut all: Vec<Flexible> = [
        Preset::Perspective { fov: 80.0 },
        Preset::InversePerspective {
            fov: 50.0,
            converge: frame().look_at,
        },
        Preset::Orthographic { width: 3.0 },
        Preset::Oblique {
            width: 3.0,
            shear: DVec2::new(0.4, 0.2),
        },
        Preset::Pushbroom {
            width: 3.0,
            v_fov: 70.0,
        },
        Preset::CrossedSlits {
            fov: 70.0,
            v_fov: Some(50.0),
            slit_distance: 1.5,
        },
        Preset::Cylindrical {
            h_fov: 360.0,
            v_fov: 120.0,
        },
        Preset::Equirectangular {
            h_fov: 360.0,
            v_fov: 180.0,
        },
        Preset::Fisheye { fov: 300.0 },
        Preset::OffAxis {
            fov: 60.0,
            shift: DVec2::new(0.5, -0.3),
        },
        Preset::Twist {
            fov: 60.0,
            twist: 70.0,
        },
        Preset::Axonometric {
            width: 3.0,
            azimuth: 45.0,
            elevation: ISOMETRIC_ELEVATION,
        },
        Preset::Glc {
            width: 2.0,
            generators: GLC_GENERATORS,
        },
    ]
    .into_iter()
    .map(|p| {
        let far = match p {
            Preset::InversePerspective { .. } => 4.0, // the projectors meet at 4.36
            _ => 20.0,
        };
        build(&preset(p, Some([0.0, far])), 16, 12)
    })
    .collect();
    let frame = PolarFrame::new(DVec3::new(0.2, 1.0, 0.1), DVec3::X).unwrap();
    let sphere = |radius: f64| {
        Surface::Sphere(SpherePatch {
            center: DVec3::new(1.0, -2.0, 0.5),
            radius,
            frame,
            longitude: [2.5, -1.0],
            latitude: [1.2, -0.3],
        })
    };
    let cylinder = |center: DVec3, radius: f64, height: [f64; 2]| {
        Surface::Cylinder(CylinderPatch {
            center,
            radius,
            frame,
            angle: [-3.0, 2.0],
            height,
        })
    };
    let line = Surface::Line {
        start: DVec3::new(-1.0, 0.0, 0.0),
        end: DVec3::new(1.0, 0.0, 0.0),
        along: LineParam::U,
    };
    let far = Surface::Rectangle {
        corner: DVec3::new(-2.0, -3.0, 4.0),
        u_edge: DVec3::new(5.0, 1.0, 0.0),
        v_edge: DVec3::new(-1.0, 4.0, 0.0),
    };
    let mut ball = preset(Preset::Fisheye { fov: 360.0 }, Some([0.0, 20.0]));
    ball.reparam = Some(Reparam::Equisolid { max_angle: PI });
    all.push(build(&ball, 16, 12));
    let mut face = preset(Preset::Perspective { fov: 90.0 }, Some([0.5, 20.0]));
    face.reparam = Some(Reparam::Equiangular {
        half_fov: FRAC_PI_4,
    });
    all.push(build(&face, 16, 12));
    all.push(custom(sphere(5.0), sphere(1.0)));
    all.push(custom(
        cylinder(DVec3::ZERO, 0.5, [-1.0, 1.0]),
        cylinder(frame.axis * 2.0, 4.0, [-5.0, 3.0]),
    ));
    all.push(custom(line, far));
    let pairs = blend_pairs();
    all.push(build(
        &blend_of(0.3, pairs[0].0.clone(), pairs[0].1.clone()),
        16,
        12,
    ));
    all.push(build(
        &blend_of(-0.4, pairs[2].0.clone(), pairs[2].1.clone()),
        16,
        12,
    ));
    all
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn project_then_ray_gives_the_point_back(
        x in 0.0..16.0f64, y in 0.0..12.0f64, t in 0.01..1.0f64
    ) {
        for f in invertible() {
            prop_assert!(f.inverse().is_ok());
            let Some(ray) = f.ray(DVec2::new(x, y)) else { continue };
            let p = ray.at(t);
            let mut out = Vec::new();
            f.inverse().unwrap().project(p, &mut out);
            prop_assert_eq!(out.len(), 1, "{:?} {}", f.volume(), p);
            let back = f.ray(out[0].pixel);
            prop_assert!(back.is_some());
            let q = back.unwrap().at(out[0].t);
            let scale = 1.0 + p.length() + ray.direction.length();
            prop_assert!((q - p).length() <= 1e-9 * scale, "{:?}: {} vs {}", f.volume(), p, q);
        }
    }
}

#[test]
fn points_outside_the_volume_have_no_image() {
    let f = build(
        &preset(Preset::Perspective { fov: 60.0 }, Some([1.0, 2.0])),
        8,
        8,
    );
    let basis = CameraBasis::new(&frame()).unwrap();
    let mut out = Vec::new();
    for local in [
        DVec3::new(0.0, 0.0, 0.5), // before the near clip
        DVec3::new(0.0, 0.0, 3.0), // beyond the far clip
        DVec3::new(5.0, 0.0, 1.5), // outside the frustum
    ] {
        f.inverse()
            .unwrap()
            .project(basis.origin + basis.to_world(local), &mut out);
    }
    assert!(out.is_empty());
    f.inverse()
        .unwrap()
        .project(basis.origin + 1.5 * basis.forward, &mut out);
    assert_eq!(out.len(), 1);
    assert!((out[0].pixel - DVec2::new(4.0, 4.0)).length() < 1e-9);
    assert!((out[0].t - 0.5).abs() < 1e-12);
}

/// The elevation of the isometric view: asin(tan 30 degrees) = 35.264 degrees.
const ISOMETRIC_ELEVATION: f64 = 35.264_389_682_754_654;

/// Three generator rays of a general (non-degenerate, non-pinhole) linear camera.
const GLC_GENERATORS: [[f64; 4]; 3] = [
    [-1.0, -0.5, -1.5, -0.25],
    [1.0, -0.5, 1.25, -1.0],
    [0.0, 1.0, 0.5, 1.75],
];

#[test]
fn off_axis_matches_the_gl_frustum_matrix() {
    // glFrustum(l, r, b, t, n, f): x_ndc = 2 n x / ((r - l) z) - (r + l) / (r - l) for a
    // point at depth z in front of the eye, with the window [l, r] x [b, t] at depth n.
    let shift = DVec2::new(0.5, -0.25);
    let spec = preset(Preset::OffAxis { fov: 90.0, shift }, Some([1.0, 2.0]));
    let (w, h) = (8u32, 6u32);
    let n = 1.0;
    let (l, r) = (n * (-1.0 + shift.x), n * (1.0 + shift.x));
    let a = f64::from(h) / f64::from(w);
    let (b, t) = (n * a * (-1.0 + shift.y), n * a * (1.0 + shift.y));
    let oracle = |p: DVec3| {
        DVec2::new(
            2.0 * n * p.x / ((r - l) * p.z) - (r + l) / (r - l),
            2.0 * n * p.y / ((t - b) * p.z) - (t + b) / (t - b),
        )
    };
    check_uv_clipped_to_1_2(&spec, (w, h), oracle);
}

#[test]
fn twist_turns_the_far_image_about_the_axis() {
    // Near surface at the eye: every projector is a perspective ray turned by the twist
    // angle, so turning a point back by -angle gives the perspective image (x/z, y/z).
    let angle = 30.0f64;
    let spec = preset(
        Preset::Twist {
            fov: 90.0,
            twist: angle,
        },
        Some([0.0, 2.0]),
    );
    let (sin, cos) = angle.to_radians().sin_cos();
    let oracle = |p: DVec3| {
        let back = DVec2::new(cos * p.x + sin * p.y, -sin * p.x + cos * p.y);
        back / p.z
    };
    let image = |f: &Flexible, pixel: DVec2| centred_uv(f, pixel) * DVec2::new(1.0, 0.75);
    check_oracle_at(&spec, (8, 6), &[0.4, 1.0], image, oracle, None);
    // With a near rectangle, t = 0 is the untwisted perspective window.
    let spec = preset(
        Preset::Twist {
            fov: 90.0,
            twist: angle,
        },
        Some([1.0, 2.0]),
    );
    let oracle = |p: DVec3| DVec2::new(p.x / p.z, p.y / p.z);
    check_oracle_at(&spec, (8, 6), &[0.0], image, oracle, None);
}

/// The pixel offsets, in world units, of the images of the three world axes from the image
/// of `look_at` under an axonometric preset.
fn axonometric_axes(azimuth: f64, elevation: f64) -> [DVec2; 3] {
    let (w, width) = (100u32, 4.0);
    let spec = preset(
        Preset::Axonometric {
            width,
            azimuth,
            elevation,
        },
        None,
    );
    let f = build(&spec, w, w);
    let image = |p: DVec3| {
        let mut out = Vec::new();
        f.inverse().unwrap().project(p, &mut out);
        assert_eq!(out.len(), 1, "{p}");
        out[0].pixel * (width / f64::from(w))
    };
    let centre = frame().look_at;
    [DVec3::X, DVec3::Y, DVec3::Z].map(|axis| image(centre + axis) - image(centre))
}

#[test]
fn axonometric_foreshortening_follows_the_drafting_formulas() {
    // Foreshortening of the world axes for azimuth a and elevation e (Carlbom and Paciorek):
    // f_x = sqrt(cos^2 a + sin^2 a sin^2 e), f_y = cos e, f_z = sqrt(sin^2 a + cos^2 a sin^2 e).
    for (a, e) in [
        (45.0, ISOMETRIC_ELEVATION),
        (45.0, 20.0),
        (30.0, 25.0),
        (-120.0, -40.0),
    ] {
        let (sa, ca) = f64::to_radians(a).sin_cos();
        let (se, ce) = f64::to_radians(e).sin_cos();
        let want = [
            (ca * ca + sa * sa * se * se).sqrt(),
            ce,
            (sa * sa + ca * ca * se * se).sqrt(),
        ];
        let got = axonometric_axes(a, e).map(|v| v.length());
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() < 1e-9, "{a} {e}: {got:?} {want:?}");
        }
    }
    // Isometric: equal foreshortening sqrt(2/3) and the axes 120 degrees apart on the image.
    let iso = axonometric_axes(45.0, ISOMETRIC_ELEVATION);
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        assert!((iso[i].length() - (2.0f64 / 3.0).sqrt()).abs() < 1e-9);
        let cos = iso[i].dot(iso[j]) / (iso[i].length() * iso[j].length());
        assert!((cos + 0.5).abs() < 1e-9, "{i} {j}: {cos}");
    }
    // The image y axis is the world up: +y goes straight up the image (pixel y down).
    assert!(iso[1].x.abs() < 1e-12 && iso[1].y < 0.0);
    let e = Flexible::new(
        &preset(
            Preset::Axonometric {
                width: 1.0,
                azimuth: 0.0,
                elevation: 90.0,
            },
            None,
        ),
        8,
        8,
    );
    assert!(e.unwrap_err().message.contains("elevation"));
}

#[test]
fn glc_rays_are_the_affine_combinations_of_the_generators() {
    let (w, h) = (8u32, 6u32);
    let width = 2.0;
    let spec = preset(
        Preset::Glc {
            width,
            generators: GLC_GENERATORS,
        },
        Some([0.0, 3.0]),
    );
    let f = build(&spec, w, h);
    let basis = CameraBasis::new(&frame()).unwrap();
    let g = GLC_GENERATORS.map(|r| (DVec2::new(r[0], r[1]), DVec2::new(r[2], r[3])));
    let cross = |a: DVec2, b: DVec2| a.x * b.y - a.y * b.x;
    let area = cross(g[1].0 - g[0].0, g[2].0 - g[0].0);
    for y in 0..h {
        for x in 0..w {
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let s = centred_uv(&f, pixel) * 0.5 * DVec2::new(width, width * 0.75);
            // Barycentric coordinates of s in the generators' image-plane triangle (ratios
            // of signed areas), then the same combination of their z = 1 crossings.
            let l0 = cross(g[1].0 - s, g[2].0 - s) / area;
            let l1 = cross(g[2].0 - s, g[0].0 - s) / area;
            let l2 = 1.0 - l0 - l1;
            let q = l0 * g[0].1 + l1 * g[1].1 + l2 * g[2].1;
            let ray = f.ray(pixel).unwrap();
            for t in [0.0, 0.5, 1.0] {
                let local = basis.to_local(ray.at(t) - basis.origin);
                let want = s.lerp(q, local.z).extend(local.z);
                assert!(
                    (local - want).length() < 1e-9,
                    "{pixel} {t}: {local} {want}"
                );
                assert!((local.z - 3.0 * t).abs() < 1e-9);
            }
        }
    }
    // Three generators through one point (0, 0, -1): a pinhole camera one unit behind the
    // image plane, image (x, y) / (z + 1).
    let pinhole = [
        [-1.0, -1.0, -2.0, -2.0],
        [1.0, -1.0, 2.0, -2.0],
        [0.0, 1.0, 0.0, 2.0],
    ];
    let spec = preset(
        Preset::Glc {
            width: 2.0,
            generators: pinhole,
        },
        Some([0.0, 2.0]),
    );
    let oracle = |p: DVec3| DVec2::new(p.x, p.y / 0.75) / (p.z + 1.0);
    check_oracle(&spec, (8, 6), centred_uv, oracle, None);
    // Generators crossing the image plane on one line: no camera.
    let line = [
        [0.0, 0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0, 1.0],
        [2.0, 2.0, 0.0, 1.0],
    ];
    let e = Flexible::new(
        &preset(
            Preset::Glc {
                width: 2.0,
                generators: line,
            },
            None,
        ),
        8,
        8,
    );
    assert!(e.unwrap_err().message.contains("not on one line"));
}

#[test]
fn lens_fisheye_angle_is_the_thesis_polynomial_of_the_radius() {
    // Fig. 4.12: v = r/4 + 3 r^2/4 of the normalised image radius r, and the angle off the
    // axis is v fov/2 (the angular fisheye's v = r).
    let mut spec = preset(Preset::Fisheye { fov: 180.0 }, Some([0.5, 2.0]));
    spec.reparam = Some(Reparam::Lens);
    let image = |f: &Flexible, pixel: DVec2| {
        let (w, h) = f.resolution();
        let p = f.resolution.centred(pixel) / (0.5 * f64::from(w.min(h)));
        let r = p.length();
        p.normalize_or_zero() * (0.25 * r + 0.75 * r * r)
    };
    let oracle = |p: DVec3| {
        let lateral = DVec2::new(p.x, p.y);
        lateral.normalize_or_zero() * lateral.length().atan2(p.z) / FRAC_PI_2
    };
    check_oracle(&spec, (9, 7), image, oracle, None);
}

#[test]
fn equisolid_fisheye_radius_is_the_sine_of_half_the_angle() {
    // The equisolid-angle lens: image radius proportional to sin(theta / 2), the rim at
    // theta = fov / 2; here fov 250 (rim 125 degrees off the axis).
    let half = 125f64.to_radians();
    let mut spec = preset(Preset::Fisheye { fov: 250.0 }, Some([0.5, 2.0]));
    spec.reparam = Some(Reparam::Equisolid { max_angle: half });
    let image = |f: &Flexible, pixel: DVec2| {
        let (w, h) = f.resolution();
        let p = f.resolution.centred(pixel) / (0.5 * f64::from(w.min(h)));
        let theta = 2.0 * (p.length() * (0.5 * half).sin()).asin();
        p.normalize_or_zero() * theta / half
    };
    let oracle = |p: DVec3| {
        let lateral = DVec2::new(p.x, p.y);
        lateral.normalize_or_zero() * lateral.length().atan2(p.z) / half
    };
    check_oracle(&spec, (9, 7), image, oracle, None);
}

#[test]
fn equiangular_perspective_has_angles_linear_in_the_image() {
    // An equi-angular cubemap face (90 degrees, Cycles' EQUIANGULAR_CUBEMAP_FACE) and a
    // 70-degree 9 x 7 image: atan(x / z) and atan(y / z) of every point on a pixel's ray are
    // linear in the pixel's centred position, reaching the horizontal half angle at the
    // frame's sides and the pinhole's vertical half angle at its top and bottom.
    for (fov, size) in [(90.0, (8, 8)), (70.0, (9, 7))] {
        let half = 0.5 * f64::to_radians(fov);
        let mut spec = preset(Preset::Perspective { fov }, Some([0.5, 2.0]));
        spec.reparam = Some(Reparam::Equiangular { half_fov: half });
        let half_y = (half.tan() * f64::from(size.1) / f64::from(size.0)).atan();
        let image = |f: &Flexible, pixel: DVec2| {
            let (w, h) = f.resolution();
            f.resolution.centred(pixel) / (0.5 * DVec2::new(f64::from(w), f64::from(h)))
        };
        let oracle = |p: DVec3| DVec2::new(p.x.atan2(p.z) / half, p.y.atan2(p.z) / half_y);
        check_oracle(&spec, size, image, oracle, None);
    }
}

#[test]
fn equal_area_map_rows_follow_the_sine_of_the_latitude() {
    // Lambert cylindrical equal-area: x = longitude, y = sin(latitude) (unit sphere).
    let mut spec = preset(
        Preset::Equirectangular {
            h_fov: 360.0,
            v_fov: 180.0,
        },
        Some([0.5, 2.0]),
    );
    spec.reparam = Some(Reparam::EqualArea {
        max_latitude: FRAC_PI_2,
    });
    let image = |f: &Flexible, pixel: DVec2| {
        let (w, h) = f.resolution();
        f.resolution.centred(pixel) / (0.5 * DVec2::new(f64::from(w), f64::from(h)))
    };
    let oracle = |p: DVec3| DVec2::new(p.x.atan2(p.z) / PI, p.y / p.length());
    check_oracle(&spec, (8, 6), image, oracle, None);
}

pub(super) fn blend_of(weight: f64, first: FlexibleSpec, second: FlexibleSpec) -> FlexibleSpec {
    FlexibleSpec {
        source: VolumeSource::Interpolated {
            weight,
            first: Box::new(first),
            second: Box::new(second),
        },
        reparam: None,
    }
}

/// Pairs of volumes on one (u, v) domain: rectangles with rectangles (blended surface by
/// surface), spheres with rectangles (blended point by point), spheres with spheres.
fn blend_pairs() -> Vec<(FlexibleSpec, FlexibleSpec)> {
    let persp = preset(Preset::Perspective { fov: 70.0 }, Some([0.5, 20.0]));
    let push = preset(
        Preset::Pushbroom {
            width: 3.0,
            v_fov: 60.0,
        },
        Some([0.0, 15.0]),
    );
    let equi = |clip| {
        preset(
            Preset::Equirectangular {
                h_fov: 200.0,
                v_fov: 120.0,
            },
            Some(clip),
        )
    };
    vec![
        (persp.clone(), push),
        (equi([0.0, 10.0]), persp),
        (equi([0.0, 10.0]), equi([1.0, 30.0])),
    ]
}

/// Every pixel-centre ray of `spec` at t in {0, 0.3, 1}, `None` where there is no ray.
fn ray_points(spec: &FlexibleSpec) -> Vec<Option<[DVec3; 3]>> {
    let f = build(spec, 9, 7);
    let mut out = Vec::new();
    for y in 0..7 {
        for x in 0..9 {
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            out.push(f.ray(pixel).map(|r| [0.0, 0.3, 1.0].map(|t| r.at(t))));
        }
    }
    out
}

#[test]
fn blend_weights_one_and_zero_reproduce_the_volumes_exactly() {
    for (a, b) in blend_pairs() {
        assert_eq!(
            ray_points(&blend_of(1.0, a.clone(), b.clone())),
            ray_points(&a)
        );
        assert_eq!(
            ray_points(&blend_of(0.0, a.clone(), b.clone())),
            ray_points(&b)
        );
        // The point-by-point form is exact at the ends too (a x + 0 y = x).
        let (va, vb) = (build(&a, 9, 7).volume, build(&b, 9, 7).volume);
        let mixed = InterpolatedVolume {
            weight: 1.0,
            first: va.clone(),
            second: vb,
        };
        let uv = DVec2::new(0.3, 0.8);
        assert_eq!(mixed.point(uv, 0.7), va.point(uv, 0.7));
    }
}

#[test]
fn blends_are_affine_in_the_weight_inside_and_outside_zero_to_one() {
    // a = 1/2: midpoints; a = 2 and a = -1: extrapolation 2 Q1 - Q2 and 2 Q2 - Q1.
    for (a, b) in blend_pairs() {
        let (pa, pb) = (ray_points(&a), ray_points(&b));
        for weight in [0.5, 0.25, 2.0, -1.0] {
            let blended = ray_points(&blend_of(weight, a.clone(), b.clone()));
            for ((q, p1), p2) in blended.iter().zip(&pa).zip(&pb) {
                let (Some(q), Some(p1), Some(p2)) = (q, p1, p2) else {
                    assert!(q.is_none(), "a ray where a part has none");
                    continue;
                };
                for k in 0..3 {
                    let want = weight * p1[k] + (1.0 - weight) * p2[k];
                    let scale = 1.0 + p1[k].length() + p2[k].length();
                    assert!(
                        (q[k] - want).length() < 1e-12 * scale,
                        "{weight}: {} {want}",
                        q[k]
                    );
                }
            }
        }
    }
}

#[test]
fn blends_of_matching_surfaces_stay_invertible() {
    let pairs = blend_pairs();
    for (i, weight) in [(0, 0.3), (0, 1.7), (2, 0.5), (2, -0.2)] {
        let (a, b) = pairs[i].clone();
        let f = build(&blend_of(weight, a, b), 9, 7);
        assert!(matches!(f.volume, Volume::Linear(_)), "{i} {weight}");
        assert!(f.inverse().is_ok(), "{i} {weight}");
    }
    let (a, b) = pairs[1].clone();
    let f = build(&blend_of(0.5, a, b), 9, 7);
    assert!(matches!(f.volume, Volume::Interpolated(_)));
    assert!(f.inverse().is_err());
}

#[test]
fn incompatible_blends_are_errors() {
    let persp = preset(Preset::Perspective { fov: 70.0 }, None);
    let e = Flexible::new(&blend_of(f64::NAN, persp.clone(), persp.clone()), 8, 8).unwrap_err();
    assert!(e.message.contains("weight must be finite"), "{e}");
    // a = 1/2 between a volume and its mirror through the eye: every projector vanishes.
    let looking = |z: f64| FlexibleSpec {
        source: VolumeSource::Preset(PresetSpec {
            preset: Preset::Orthographic { width: 2.0 },
            frame: CameraFrame {
                position: DVec3::ZERO,
                look_at: DVec3::Z * z,
                up: DVec3::Y,
            },
            clip: Some([0.0, 1.0]),
        }),
        reparam: None,
    };
    let e = Flexible::new(&blend_of(0.5, looking(1.0), looking(-1.0)), 8, 8).unwrap_err();
    assert!(e.message.contains("interpolation"), "{e}");
}
