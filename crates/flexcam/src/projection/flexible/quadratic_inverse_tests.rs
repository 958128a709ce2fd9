//! The quadratic inverse: each volume point back to its pixel and t, the degenerate cases,
//! the refusals with their reasons, and the chart.

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::QuadraticPlanes;
use crate::projection::flexible::{Blend, Flexible, FlexibleSpec, Surface, VolumeSource};
use crate::projection::Projection;

const WIDTH: u32 = 64;
const HEIGHT: u32 = 48;

/// A rectangle centred at `offset` along `normal` (shifted by `shift` in its plane), with
/// half-axes `half` along two directions perpendicular to `normal`.
fn plane_rectangle(normal: DVec3, offset: f64, shift: DVec2, half: DVec2) -> Surface {
    let (x, y) = normal.any_orthonormal_pair();
    Surface::rectangle_centred(
        offset * normal + shift.x * x + shift.y * y,
        half.x * x,
        half.y * y,
    )
}

fn bezier(surfaces: Vec<Surface>, segments: Option<u32>) -> Flexible {
    let spec = FlexibleSpec {
        source: VolumeSource::Blended {
            surfaces,
            blend: Blend::Bezier { segments },
        },
        reparam: None,
    };
    Flexible::new(&spec, WIDTH, HEIGHT).unwrap()
}

fn reason(f: &Flexible) -> String {
    f.inverse().err().unwrap().reason.unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Q(u, v, t) of a pixel's projector goes back to that pixel and t, for volumes of
    /// any normal, plane offsets in either order along it and rectangles of any size and
    /// shift (equal spacing included), at any t in [0, 1] and on the image's edges.
    #[test]
    fn the_quadratic_inverse_returns_each_point_to_its_pixel(
        normal in (-1.0..1.0f64, -1.0..1.0f64, 0.2..1.0f64),
        gaps in (0.1..4.0f64, 0.1..4.0f64),
        sign in prop::bool::ANY,
        start in -3.0..3.0f64,
        shifts in prop::array::uniform3((-2.0..2.0f64, -2.0..2.0f64)),
        halves in prop::array::uniform3((0.1..3.0f64, 0.1..3.0f64)),
        x in 0.0..=64.0f64, y in 0.0..=48.0f64, t in 0.0..=1.0f64,
    ) {
        let n = DVec3::from(normal).normalize();
        let s = if sign { 1.0 } else { -1.0 };
        let offsets = [start, start + s * gaps.0, start + s * (gaps.0 + gaps.1)];
        let surfaces = (0..3)
            .map(|k| plane_rectangle(n, offsets[k], shifts[k].into(), halves[k].into()))
            .collect();
        let f = bezier(surfaces, None);
        let inverse = f.inverse().unwrap();
        let pixel = DVec2::new(x, y);
        let p = f.point(pixel, t).unwrap();
        let mut out = Vec::new();
        inverse.project(p, &mut out);
        prop_assert_eq!(out.len(), 1, "{}", p);
        prop_assert!((out[0].pixel - pixel).length() < 1e-6, "{} vs {}", out[0].pixel, pixel);
        prop_assert!((out[0].t - t).abs() < 1e-9, "{} vs {}", out[0].t, t);
        prop_assert!(inverse.charted().is_some());
    }
}

/// Equally spaced planes: the depth is linear in t (the quadratic's leading coefficient is
/// 0), t = (p . n - d0) / (d2 - d0) exactly as the root formula gives it.
#[test]
fn equally_spaced_planes_make_the_depth_linear() {
    let surfaces: Vec<Surface> = [0.0, 2.0, 4.0]
        .iter()
        .zip([1.0, 3.0, 2.0])
        .map(|(z, h)| plane_rectangle(DVec3::Z, *z, DVec2::new(h - 1.0, 0.0), DVec2::splat(h)))
        .collect();
    let q = QuadraticPlanes::classify(&surfaces).unwrap();
    for depth in [0.0, 0.5, 1.7, 4.0, -1.0, 5.0] {
        let t = q.t(DVec3::new(0.3, -0.2, depth)).unwrap();
        assert_eq!(t, depth / 4.0, "{depth}");
    }
}

/// Beyond the depth's extremum (outside the volume) there is no t; inside, the root is on
/// the branch through [0, 1].
#[test]
fn a_point_beyond_the_depths_extremum_has_no_t() {
    // Offsets 0, 3, 4: depth(t) = 6 t - 2 t^2, rising over [0, 1] to its maximum 4.5 at
    // t = 1.5.
    let surfaces: Vec<Surface> = [0.0, 3.0, 4.0]
        .iter()
        .map(|z| plane_rectangle(DVec3::Z, *z, DVec2::ZERO, DVec2::ONE))
        .collect();
    let q = QuadraticPlanes::classify(&surfaces).unwrap();
    assert_eq!(q.t(DVec3::new(0.0, 0.0, 4.6)), None);
    assert_eq!(q.t(DVec3::new(0.0, 0.0, 4.0)), Some(1.0));
    let t = q.t(DVec3::new(0.0, 0.0, 4.4)).unwrap();
    assert!(t > 1.0 && t < 1.5, "{t}");
    assert_eq!(q.t(DVec3::new(0.0, 0.0, 0.0)), Some(0.0));
}

/// Outside the class, each refusal names its reason: a middle plane on the near one, or
/// beyond the far one; planes that are not parallel; a twisted surface; points and lines
/// only; a Bezier drawn as polylines or of degree 3.
#[test]
fn volumes_outside_the_class_are_refused_with_the_reason() {
    let square = |z: f64| plane_rectangle(DVec3::Z, z, DVec2::ZERO, DVec2::ONE);
    let middle = "middle plane does not lie strictly between";
    for (surfaces, why) in [
        (vec![square(0.0), square(0.0), square(2.0)], middle),
        (vec![square(0.0), square(3.0), square(2.0)], middle),
        (
            vec![
                square(0.0),
                plane_rectangle(
                    DVec3::new(0.0, 0.1, 1.0).normalize(),
                    1.0,
                    DVec2::ZERO,
                    DVec2::ONE,
                ),
                square(2.0),
            ],
            "not parallel planes",
        ),
        (
            vec![
                square(0.0),
                Surface::Bilinear {
                    corners: [
                        DVec3::new(-1.0, -1.0, 1.0),
                        DVec3::new(1.0, -1.0, 1.2),
                        DVec3::new(1.0, 1.0, 1.0),
                        DVec3::new(-1.0, 1.0, 1.0),
                    ],
                },
                square(2.0),
            ],
            "surface 2 is not flat",
        ),
        (
            vec![
                Surface::Point(DVec3::ZERO),
                Surface::Point(DVec3::Z),
                Surface::Point(DVec3::new(1.0, 0.0, 2.0)),
            ],
            "none spans a plane",
        ),
    ] {
        let why_not = reason(&bezier(surfaces, None));
        assert!(why_not.contains(why), "{why_not}");
        assert!(why_not.contains("outside the scanline class"), "{why_not}");
    }
    let polylines = reason(&bezier(
        vec![square(0.0), square(1.0), square(2.0)],
        Some(8),
    ));
    assert!(polylines.contains("drawn as polylines"), "{polylines}");
    let cubic = reason(&bezier(
        vec![square(0.0), square(1.0), square(2.0), square(3.0)],
        None,
    ));
    assert!(cubic.contains("degree above 2"), "{cubic}");
}

/// The chart: a pinhole near surface is clipped just behind it (its image at infinity); a
/// middle surface mirrored so that the cross-section turns over inside the volume has an
/// inverse but no chart.
#[test]
fn the_chart_clips_at_a_pinhole_and_refuses_a_turning_cross_section() {
    let pinhole = bezier(
        vec![
            Surface::Point(DVec3::ZERO),
            plane_rectangle(DVec3::Z, 1.0, DVec2::ZERO, DVec2::ONE),
            plane_rectangle(DVec3::Z, 3.0, DVec2::ZERO, DVec2::splat(2.0)),
        ],
        None,
    );
    let chart = pinhole.inverse().unwrap().charted().unwrap().chart;
    assert_eq!(chart.clip.len(), 2);
    let near = chart.clip[0];
    assert_eq!(near.normal, DVec3::Z);
    assert!(near.offset > 0.0 && near.offset < 1e-8, "{near:?}");
    let mirrored = bezier(
        vec![
            plane_rectangle(DVec3::Z, 0.0, DVec2::ZERO, DVec2::ONE),
            plane_rectangle(DVec3::Z, 1.0, DVec2::ZERO, DVec2::new(-3.0, 1.0)),
            plane_rectangle(DVec3::Z, 2.0, DVec2::ZERO, DVec2::ONE),
        ],
        None,
    );
    assert!(mirrored.inverse().unwrap().charted().is_none());
}
