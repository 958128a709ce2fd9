//! Shape-defined panoramas against the closed forms: circle + segment is the cylindrical
//! preset, circle + semicircle the equirectangular one, square + segment four perspective
//! views; blends; degenerate profiles.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::*;
use crate::projection::flexible::tests::{frame, preset};
use crate::projection::flexible::{Flexible, FlexibleSpec, Preset, VolumeSource};
use crate::projection::Projection;

fn single(outline: OutlineShape, profile: ProfileShape) -> PanoramaShape {
    PanoramaShape::single(outline.curve().unwrap(), profile.curve().unwrap()).unwrap()
}

fn panorama(shape: PanoramaShape, clip: Option<[f64; 2]>) -> FlexibleSpec {
    FlexibleSpec {
        source: VolumeSource::Panorama(PanoramaSpec {
            shape: Arc::new(shape),
            frame: frame(),
            clip,
        }),
        reparam: None,
    }
}

/// Every pixel centre of a w x h image has the same ray (origin and direction within `tol`)
/// in both projections, or none in both.
fn same_rays(a: &FlexibleSpec, b: &FlexibleSpec, (w, h): (u32, u32), tol: f64) {
    let (a, b) = (
        Flexible::new(a, w, h).unwrap(),
        Flexible::new(b, w, h).unwrap(),
    );
    let mut rays = 0;
    for y in 0..h {
        for x in 0..w {
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            match (a.ray(pixel), b.ray(pixel)) {
                (Some(r), Some(s)) => {
                    let scale = s.direction.length();
                    assert!((r.origin - s.origin).length() <= tol * scale, "{pixel}");
                    assert!(
                        (r.direction - s.direction).length() <= tol * scale,
                        "{pixel}: {} vs {}",
                        r.direction,
                        s.direction
                    );
                    rays += 1;
                }
                (None, None) => {}
                (r, s) => panic!("{pixel}: {r:?} vs {s:?}"),
            }
        }
    }
    assert!(rays > 0);
}

/// The cylindrical preset's v is linear in tan(elevation), as is arc length along a vertical
/// segment at distance 1: the same (u, v) gives the same ray.
#[test]
fn circle_and_segment_are_the_cylindrical_preset() {
    for (v_fov, clip) in [(90.0, None), (120.0, Some([0.5, 7.0]))] {
        let half = 0.5 * f64::to_radians(v_fov);
        let shape = single(
            OutlineShape::Circle,
            ProfileShape::Segment {
                elevation: [-half, half],
            },
        );
        let cylindrical = Preset::Cylindrical {
            h_fov: 360.0,
            v_fov,
        };
        same_rays(
            &panorama(shape, clip),
            &preset(cylindrical, clip),
            (48, 20),
            1e-12,
        );
    }
}

/// Arc length along the semicircle is linear in elevation, as the equirectangular preset's v.
#[test]
fn circle_and_semicircle_are_the_equirectangular_preset() {
    let shape = single(
        OutlineShape::Circle,
        ProfileShape::Arc {
            elevation: [-FRAC_PI_2, FRAC_PI_2],
        },
    );
    let equirectangular = Preset::Equirectangular {
        h_fov: 360.0,
        v_fov: 180.0,
    };
    same_rays(
        &panorama(shape, Some([0.0, 3.0])),
        &preset(equirectangular, Some([0.0, 3.0])),
        (40, 24),
        1e-12,
    );
}

/// The front quarter of the cubic preset (u in [3/8, 5/8]) is the 90-degree perspective
/// preset: pixel column x of a W-wide perspective image is column 3W/2 + x of the 4W-wide
/// cubic one. So scene lines on a face plane stay straight.
#[test]
fn cubic_faces_are_perspective_views() {
    let (w, h) = (16, 12);
    let v_fov = 2.0 * (0.75f64).atan().to_degrees(); // tan(v/2) H/W with H/W = 3/4
    let cubic = Flexible::new(&preset(Preset::Cubic { v_fov }, None), 4 * w, h).unwrap();
    let perspective =
        Flexible::new(&preset(Preset::Perspective { fov: 90.0 }, None), w, h).unwrap();
    for y in 0..h {
        for x in 0..w {
            let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let r = cubic
                .ray(centre + DVec2::new(1.5 * f64::from(w), 0.0))
                .unwrap();
            let s = perspective.ray(centre).unwrap();
            assert!((r.origin - s.origin).length() < 1e-12);
            assert!((r.direction - s.direction).length() < 1e-9 * s.direction.length());
        }
    }
    // The right face looks to the right: its centre column's ray is the camera's right.
    let basis = CameraBasis::new(&frame()).unwrap();
    let right = cubic.ray(DVec2::new(3.0 * f64::from(w), 0.5 * f64::from(h)));
    let direction = right.unwrap().direction.normalize();
    assert!((direction - basis.right).length() < 1e-12);
}

#[test]
fn rounded_cubic_interpolates_cubic_and_cylindrical() {
    let size = (40, 16);
    let v_fov = 100.0;
    let rounded = |corner_radius| {
        preset(
            Preset::RoundedCubic {
                v_fov,
                corner_radius,
            },
            None,
        )
    };
    same_rays(
        &rounded(0.0),
        &preset(Preset::Cubic { v_fov }, None),
        size,
        1e-12,
    );
    let half = 0.5 * f64::to_radians(v_fov);
    let cylinder = single(
        OutlineShape::Circle,
        ProfileShape::Segment {
            elevation: [-half, half],
        },
    );
    same_rays(&rounded(1.0), &panorama(cylinder, None), size, 1e-12);
    let e = Flexible::new(&rounded(1.5), 8, 8).unwrap_err();
    assert!(e.message.contains("corner radius"), "{e}");
}

fn two_profiles(blend: CurveBlend) -> PanoramaShape {
    let segment = ProfileShape::Segment {
        elevation: [-FRAC_PI_4, FRAC_PI_4],
    };
    let arc = ProfileShape::Arc {
        elevation: [-FRAC_PI_2, FRAC_PI_2],
    };
    let attach = |at, curve| Attached { at, curve };
    PanoramaShape::new(
        vec![attach(0.0, OutlineShape::Circle.curve().unwrap())],
        vec![
            attach(0.25, segment.curve().unwrap()),
            attach(0.75, arc.curve().unwrap()),
        ],
        blend,
    )
    .unwrap()
}

#[test]
fn profiles_blend_between_their_columns_and_wrap_at_the_seam() {
    let linear = two_profiles(CurveBlend::Linear);
    let smooth = two_profiles(CurveBlend::Smooth);
    let segment = |v: f64| DVec2::new(1.0, 2.0 * v - 1.0);
    let arc = |v: f64| {
        let a = PI * (v - 0.5);
        DVec2::new(a.cos(), a.sin())
    };
    for v in [0.0, 0.3, 1.0] {
        // Exactly the attached profile at its column.
        assert!((linear.profile(DVec2::new(0.25, v)) - segment(v)).length() < 1e-12);
        assert!((linear.profile(DVec2::new(0.75, v)) - arc(v)).length() < 1e-12);
        // s = (u - u_i) / (u_{i+1} - u_i) = 1/4 at u = 3/8.
        let want = segment(v).lerp(arc(v), 0.25);
        assert!((linear.profile(DVec2::new(0.375, v)) - want).length() < 1e-12);
        let want = segment(v).lerp(arc(v), 0.25 * 0.25 * (3.0 - 0.5));
        assert!((smooth.profile(DVec2::new(0.375, v)) - want).length() < 1e-12);
        // Across the seam, from the arc (u = 3/4) to the segment (u = 1/4 + 1): the seam is
        // half way, u = 0 and u = 1 agree.
        let want = arc(v).lerp(segment(v), 0.5);
        assert!((linear.profile(DVec2::new(0.0, v)) - want).length() < 1e-12);
        assert!((linear.profile(DVec2::new(1.0, v)) - want).length() < 1e-12);
        let want = arc(v).lerp(segment(v), 0.25);
        assert!((linear.profile(DVec2::new(0.875, v)) - want).length() < 1e-12);
    }
}

#[test]
fn outlines_blend_in_v_and_hold_beyond_the_ends() {
    let attach = |at, outline: OutlineShape| Attached {
        at,
        curve: outline.curve().unwrap(),
    };
    let shape = PanoramaShape::new(
        vec![
            attach(0.2, OutlineShape::Square),
            attach(0.6, OutlineShape::Circle),
        ],
        vec![Attached {
            at: 0.0,
            curve: ProfileShape::Segment {
                elevation: [-FRAC_PI_4, FRAC_PI_4],
            }
            .curve()
            .unwrap(),
        }],
        CurveBlend::Linear,
    )
    .unwrap();
    let front = |v| shape.outline(DVec2::new(0.5 + 1.0 / 16.0, v));
    let square = DVec2::new(0.5, 1.0);
    let a = FRAC_PI_4 / 2.0;
    let circle = DVec2::new(a.sin(), a.cos());
    assert!((front(0.0) - square).length() < 1e-12);
    assert!((front(0.2) - square).length() < 1e-12);
    assert!((front(0.3) - square.lerp(circle, 0.25)).length() < 1e-12);
    assert!((front(0.6) - circle).length() < 1e-12);
    assert!((front(1.0) - circle).length() < 1e-12);
}

#[test]
fn bad_attachments_are_errors() {
    let circle = || OutlineShape::Circle.curve().unwrap();
    let segment = || {
        ProfileShape::Segment {
            elevation: [-0.5, 0.5],
        }
        .curve()
        .unwrap()
    };
    let attach = |at, curve| Attached { at, curve };
    let new = |o, p| PanoramaShape::new(o, p, CurveBlend::Linear);
    assert!(new(vec![], vec![attach(0.0, segment())]).is_err());
    assert!(new(vec![attach(0.0, circle())], vec![]).is_err());
    // Swapped families: a closed profile, an open outline.
    assert!(new(vec![attach(0.0, segment())], vec![attach(0.0, segment())]).is_err());
    assert!(new(vec![attach(0.0, circle())], vec![attach(0.0, circle())]).is_err());
    let e = new(
        vec![attach(0.5, circle()), attach(0.5, circle())],
        vec![attach(0.0, segment())],
    )
    .unwrap_err();
    assert!(e.message.contains("increase"), "{e}");
    assert!(new(vec![attach(1.5, circle())], vec![attach(0.0, segment())]).is_err());
    let e = new(
        vec![attach(0.0, circle())],
        vec![attach(0.0, segment()), attach(1.0, segment())],
    )
    .unwrap_err();
    assert!(e.message.contains("same column"), "{e}");
}

/// A profile reaching the axis makes a pole row; one crossing it looks over the pole to the
/// other side of the eye (the image folds; ray casting draws it as given).
#[test]
fn profiles_on_and_across_the_axis() {
    let profile = |points: &[[f64; 2]]| {
        ProfileShape::Points(points.iter().map(|&p| DVec2::from_array(p)).collect())
    };
    let shape = single(
        OutlineShape::Circle,
        profile(&[[1.0, 0.0], [0.0, 1.0], [-1.0, 2.0]]),
    );
    let top = shape.local(DVec2::new(0.5, 0.5));
    assert_eq!(top, DVec3::new(0.0, 1.0, 0.0));
    // At v = 1 the front column (u = 1/2) looks backwards and up.
    let over = shape.local(DVec2::new(0.5, 1.0));
    assert!((over - DVec3::new(0.0, 2.0, -1.0)).length() < 1e-12);
    let f = Flexible::new(&panorama(shape, None), 16, 8).unwrap();
    let pole_row = f.ray(DVec2::new(8.0, 4.0)).unwrap().direction;
    let up = CameraBasis::new(&frame()).unwrap().up;
    assert!((pole_row.normalize() - up).length() < 1e-12);
}

#[test]
fn surface_validation() {
    let shape = Arc::new(single(
        OutlineShape::Square,
        ProfileShape::Segment {
            elevation: [-0.5, 0.5],
        },
    ));
    let basis = CameraBasis::new(&frame()).unwrap();
    let surface = |scale| PanoramaSurface {
        basis,
        scale,
        shape: Arc::clone(&shape),
    };
    assert!(surface(0.0).validate().is_ok());
    assert!(surface(-1.0).validate().is_err());
    assert!(surface(f64::NAN).validate().is_err());
    // A zero-scale surface is the eye.
    assert_eq!(surface(0.0).point(DVec2::new(0.3, 0.8)), basis.origin);
    let spec = PanoramaSpec {
        shape,
        frame: frame(),
        clip: Some([2.0, 1.0]),
    };
    assert!(spec.surfaces().unwrap_err().message.contains("clip"));
}

/// The points `p` as a list of 2D points.
fn points(p: &[[f64; 2]]) -> Vec<DVec2> {
    p.iter().map(|&q| DVec2::from_array(q)).collect()
}

/// The shape of `scenes/flexible-panorama-custom.toml`: a flattened circle and two profiles
/// blended smoothly, an arc at the seam and a segment in front.
fn custom_example() -> PanoramaShape {
    let outline = OutlineShape::Points(points(&[
        [0.0, -1.0],
        [-0.7, -0.7],
        [-1.0, 0.0],
        [-0.6, 0.8],
        [0.6, 0.8],
        [1.0, 0.0],
        [0.7, -0.7],
    ]));
    let attach = |at, curve| Attached { at, curve };
    let degrees = |a: f64, b: f64| [a.to_radians(), b.to_radians()];
    PanoramaShape::new(
        vec![attach(0.0, outline.curve().unwrap())],
        vec![
            attach(
                0.0,
                ProfileShape::Arc {
                    elevation: degrees(-90.0, 90.0),
                }
                .curve()
                .unwrap(),
            ),
            attach(
                0.5,
                ProfileShape::Segment {
                    elevation: degrees(-50.0, 50.0),
                }
                .curve()
                .unwrap(),
            ),
        ],
        CurveBlend::Smooth,
    )
    .unwrap()
}

/// Two outlines (a square low, an off-centre polygon high) and three profiles, blended
/// linearly: u and v are coupled.
fn two_outlines_three_profiles() -> PanoramaShape {
    let attach = |at, curve| Attached { at, curve };
    let polygon = OutlineShape::Points(points(&[
        [1.5, -1.0],
        [2.0, 2.5],
        [-1.0, 1.5],
        [-1.2, -0.8],
    ]));
    let profile = |p: &[[f64; 2]]| ProfileShape::Points(points(p)).curve().unwrap();
    PanoramaShape::new(
        vec![
            attach(0.25, OutlineShape::Square.curve().unwrap()),
            attach(0.7, polygon.curve().unwrap()),
        ],
        vec![
            attach(0.1, profile(&[[1.0, -1.5], [1.2, 0.0], [0.8, 1.2]])),
            attach(
                0.45,
                ProfileShape::Arc {
                    elevation: [-1.4, 1.4],
                }
                .curve()
                .unwrap(),
            ),
            attach(
                0.8,
                ProfileShape::Segment {
                    elevation: [-0.9, 1.0],
                }
                .curve()
                .unwrap(),
            ),
        ],
        CurveBlend::Linear,
    )
    .unwrap()
}

/// The panoramas of the lookup inverse's round-trip tests: exact shapes, a polyline outline
/// off the eye's centre (non-unit rho) and a polyline profile, blended profiles, blended
/// outlines and profiles, and a perspective edit across the seam.
fn invertible_panoramas() -> Vec<(&'static str, FlexibleSpec)> {
    let custom = single(
        OutlineShape::Points(points(&[
            [2.0, -1.0],
            [2.5, 3.0],
            [-1.0, 2.0],
            [-1.5, -0.5],
        ])),
        ProfileShape::Points(points(&[[1.0, -2.0], [1.5, 0.0], [1.0, 1.0], [0.2, 1.5]])),
    );
    let across_seam = make_perspective(&two_outlines_three_profiles(), [0.9, 0.2, 0.1, 0.6]);
    vec![
        ("cubic", preset(Preset::Cubic { v_fov: 100.0 }, None)),
        (
            "rounded cubic",
            preset(
                Preset::RoundedCubic {
                    v_fov: 90.0,
                    corner_radius: 0.4,
                },
                Some([0.5, 20.0]),
            ),
        ),
        (
            "sphere",
            panorama(
                single(
                    OutlineShape::Circle,
                    ProfileShape::Arc {
                        elevation: [-FRAC_PI_2, FRAC_PI_2],
                    },
                ),
                None,
            ),
        ),
        ("custom", panorama(custom, Some([0.1, 50.0]))),
        ("custom example", panorama(custom_example(), None)),
        (
            "two outlines",
            panorama(two_outlines_three_profiles(), Some([0.2, 30.0])),
        ),
        (
            "edited across the seam",
            panorama(across_seam.unwrap(), None),
        ),
    ]
}

/// The stated accuracy of the lookup (image positions as a fraction of the image, and t).
const LOOKUP_TOLERANCE: f64 = super::lookup::ACCURACY;

mod round_trip {
    use proptest::prelude::*;

    use super::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// A point on the projector of pixel q at depth t projects back to q and t, and the
        /// ray of the projected pixel reaches the point at the projected t.
        #[test]
        fn project_then_cast(which in 0usize..7, x in 0.0f64..1.0, y in 0.02f64..0.98, t in 0.0f64..1.0) {
            let (name, spec) = &invertible_panoramas()[which];
            let (w, h) = (360, 180);
            let f = Flexible::new(spec, w, h).unwrap();
            prop_assert!(f.inverse().is_ok(), "{}", name);
            let pixel = DVec2::new(x * f64::from(w), y * f64::from(h));
            let ray = f.ray(pixel).unwrap();
            let p = ray.at(t);
            let mut images = Vec::new();
            f.inverse().unwrap().project(p, &mut images);
            prop_assert_eq!(images.len(), 1, "{}", name);
            let image = images[0];
            // u wraps: compare across the seam.
            let dx = (image.pixel.x - pixel.x).abs();
            let dx = dx.min(f64::from(w) - dx);
            prop_assert!(dx <= LOOKUP_TOLERANCE * f64::from(w), "{} x {} vs {}", name, image.pixel, pixel);
            prop_assert!((image.pixel.y - pixel.y).abs() <= LOOKUP_TOLERANCE * f64::from(h), "{}", name);
            prop_assert!((image.t - t).abs() <= LOOKUP_TOLERANCE, "{} t {} vs {}", name, image.t, t);
            let back = f.ray(image.pixel).unwrap().at(image.t);
            let reach = (p - ray.origin).length().max(ray.direction.length() * 1e-3);
            prop_assert!((back - p).length() <= 10.0 * LOOKUP_TOLERANCE * reach, "{}: {} vs {}", name, back, p);
        }
    }
}

#[test]
fn lookup_inverse_is_refused_outside_its_class() {
    let profile = |p: &[[f64; 2]]| ProfileShape::Points(points(p));
    let across = single(OutlineShape::Circle, profile(&[[1.0, 0.0], [-1.0, 2.0]]));
    let folded = single(
        OutlineShape::Circle,
        profile(&[[1.0, 0.0], [1.0, 2.0], [3.0, 1.0]]),
    );
    // Not star-shaped around the eye: a notch whose azimuth runs backwards.
    let notch = OutlineShape::Points(points(&[
        [0.0, -1.0],
        [-1.0, 0.0],
        [0.0, 1.0],
        [0.2, 0.3],
        [0.4, 1.0],
        [1.0, 0.0],
    ]));
    let star = single(notch, profile(&[[1.0, -1.0], [1.0, 1.0]]));
    // Two star-shaped outlines whose blend is not: the circle, and a circle with a long
    // spike to the right (tip at x = 7.5), three times as long, so that by arc length its
    // points near the start run up to 175 degrees ahead of the circle's, three times as
    // fast: the blend turns back there.
    let on_circle = |degrees: i32| {
        let a = f64::from(degrees).to_radians();
        DVec2::new(a.sin(), a.cos())
    };
    let mut spiked: Vec<DVec2> = (-18..=8).map(|k| on_circle(10 * k)).collect();
    spiked.extend([DVec2::new(7.5, 0.1), DVec2::new(7.5, -0.1)]);
    spiked.extend((10..=17).map(|k| on_circle(10 * k)));
    let spiked = OutlineShape::Points(spiked);
    let attach = |at, curve| Attached { at, curve };
    let segment = || profile(&[[1.0, -1.0], [1.0, 1.0]]).curve().unwrap();
    let outlines = PanoramaShape::new(
        vec![
            attach(0.2, OutlineShape::Circle.curve().unwrap()),
            attach(0.8, spiked.curve().unwrap()),
        ],
        vec![attach(0.0, segment())],
        CurveBlend::Smooth,
    )
    .unwrap();
    // Two rising profiles whose blend dips: one rises early (then climbs far up near the
    // axis), the other late (after coming up from far below): at one v their points are
    // 160 degrees apart and the late one's is far from the eye.
    let early = profile(&[[1.0, -1.0], [0.2, 5.0], [0.2, 50.0]]);
    let late = profile(&[[0.2, -50.0], [0.2, -5.0], [1.0, 1.0]]);
    let profiles = PanoramaShape::new(
        vec![attach(0.0, OutlineShape::Circle.curve().unwrap())],
        vec![
            attach(0.2, early.curve().unwrap()),
            attach(0.6, late.curve().unwrap()),
        ],
        CurveBlend::Linear,
    )
    .unwrap();
    for (name, shape, reason) in [
        ("across", across, "profile reaches behind the up axis"),
        ("folded", folded, "profile does not rise strictly"),
        ("notch", star, "outline is not star-shaped around the eye"),
        (
            "outline blend",
            outlines,
            "blend of the panorama's outlines at v = 0.2 and 0.8 is not star-shaped",
        ),
        (
            "profile blend",
            profiles,
            "blend of the panorama's profiles at u = 0.2 and 0.6 does not rise strictly",
        ),
    ] {
        let f = Flexible::new(&panorama(shape, None), 32, 16).unwrap();
        assert!(f.inverse().is_err(), "{name}");
        let why = f.inverse().err().unwrap().reason.unwrap();
        assert!(why.contains(reason), "{name}: {why}");
        // Ray casting still works.
        assert!(f.ray(DVec2::new(16.0, 8.0)).is_some(), "{name}");
    }
}

#[test]
fn blended_panoramas_have_a_lookup_inverse() {
    for shape in [
        two_profiles(CurveBlend::Linear),
        two_profiles(CurveBlend::Smooth),
        custom_example(),
        two_outlines_three_profiles(),
    ] {
        let f = Flexible::new(&panorama(shape, None), 32, 16).unwrap();
        assert!(f.inverse().unwrap().charted().is_some());
    }
}

#[test]
fn lookup_chart_wraps_the_width_and_keeps_the_poles_clear() {
    let f = Flexible::new(&preset(Preset::Cubic { v_fov: 90.0 }, None), 64, 16).unwrap();
    let chart = f.inverse().unwrap().charted().unwrap().chart;
    assert_eq!(chart.period, Some(64.0));
    assert!(chart.clip.is_empty());
    // The top pixel-centre row at v = 1 - 1/32: height tan(45) (1 - 1/16) at the corners
    // (distance sqrt 2) and at the face centres (distance 1, the highest elevation).
    let top = (1.0 - 1.0 / 16.0f64).atan();
    let basis = CameraBasis::new(&frame()).unwrap();
    assert_eq!(chart.poles.len(), 2);
    assert!((chart.poles[0].direction - basis.up).length() < 1e-12);
    assert!((chart.poles[0].clearance - (FRAC_PI_2 - top)).abs() < 1e-12);
    assert!((chart.poles[1].clearance - (FRAC_PI_2 - top)).abs() < 1e-12);
    // Points on the axis have no image.
    let mut out = Vec::new();
    f.inverse()
        .unwrap()
        .project(basis.origin + 3.0 * basis.up, &mut out);
    assert!(out.is_empty());
    // Other re-parameterisations have no chart.
    let mut polar = preset(Preset::Cubic { v_fov: 90.0 }, None);
    polar.reparam = Some(crate::projection::flexible::Reparam::Polar);
    assert!(Flexible::new(&polar, 16, 16)
        .unwrap()
        .inverse()
        .unwrap()
        .charted()
        .is_none());
}
