//! The depth-discontinuity occlusion camera's inverse (module `displaced_inverse`): round
//! trips over random maps, the map's slope, and the degenerate cases.

use std::sync::Arc;

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::displaced_inverse::{undisplace, MAX_SLOPE, TOLERANCE};
use super::inverse::Inverse;
use super::presets::DdocMap;
use super::tests::frame;
use super::*;
use crate::projection::{ImagePoint, Projection};
use crate::render::supported_chart;

const SIZE: (u32, u32) = (40, 30);

fn build(preset: Preset, clip: [f64; 2]) -> Flexible {
    let spec = tests::preset(preset, Some(clip));
    Flexible::new(&spec, SIZE.0, SIZE.1).unwrap_or_else(|e| panic!("{e}"))
}

/// A DDOC with z_near 4, z_far 8 (`depths`) and `map`.
fn ddoc(map: DdocMap, depths: [f64; 2], clip: [f64; 2]) -> Flexible {
    let preset = Preset::Ddoc {
        fov: 60.0,
        z_near: depths[0],
        z_far: depths[1],
        map: Some(Arc::new(map)),
    };
    build(preset, clip)
}

/// A `w` x `h` map of the samples `f(x, y)` scaled to slope `slope` (unless it is flat).
fn map_of(w: u32, h: u32, slope: f64, f: impl Fn(u32, u32) -> DVec2) -> DdocMap {
    let raw: Vec<DVec2> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| f(x, y))
        .collect();
    let most = raw
        .iter()
        .map(|d| d.abs().max_element())
        .fold(0.0, f64::max);
    let raw: Vec<DVec2> = raw.iter().map(|d| *d / most.max(1.0)).collect();
    let unscaled = DdocMap::new(w, h, raw.clone()).unwrap();
    let (s, _) = unscaled.slope();
    let scale = if s > 0.0 { slope / s } else { 1.0 };
    let samples: Vec<DVec2> = raw.iter().map(|d| *d * scale).collect();
    // Keep every displacement within the map's bound.
    let big = samples
        .iter()
        .map(|d| d.abs().max_element())
        .fold(0.0, f64::max);
    let fit = if big > 1.0 { 1.0 / big } else { 1.0 };
    DdocMap::new(w, h, samples.iter().map(|d| *d * fit).collect()).unwrap()
}

/// The images of `point` by the bounded inverse.
fn images(f: &Flexible, point: DVec3) -> Vec<ImagePoint> {
    let mut out = Vec::new();
    f.inverse().unwrap().project(point, &mut out);
    out
}

/// The continuous image of `point`.
fn continuous(f: &Flexible, point: DVec3) -> Option<ImagePoint> {
    supported_chart(f).unwrap().map.project_continuous(point)
}

proptest! {
    /// inverse(forward(pixel, t)) is the pixel and t, over random maps of slope up to 0.85,
    /// any depths of the bend, t anywhere in the volume and on the bend's two planes.
    #[test]
    fn the_ddoc_inverse_returns_each_point_to_its_pixel(
        seed in proptest::collection::vec(-1.0f64..1.0, 2 * 7 * 5),
        (w, h) in (2u32..8, 1u32..6),
        slope in 0.0f64..0.85,
        x in 0.0f64..40.0,
        y in 0.0f64..30.0,
        t in 0.0f64..1.0,
        station in 0usize..3,
        z_near in 1.0f64..6.0,
        bend in 0.5f64..8.0,
    ) {
        let map = map_of(w, h, slope, |x, y| {
            let k = 2 * (y * 7 + x) as usize;
            DVec2::new(seed[k], seed[k + 1]) * 0.05
        });
        let (near, far) = (0.5, 20.0);
        let z_far = z_near + bend;
        let f = ddoc(map, [z_near, z_far], [near, far]);
        let knot = |z: f64| (z - near) / (far - near);
        let t = [t, knot(z_near), knot(z_far)][station];
        let pixel = DVec2::new(x, y);
        let point = f.point(pixel, t).unwrap();
        let found = images(&f, point);
        prop_assert_eq!(found.len(), 1);
        // TOLERANCE in image fractions is 4e-11 pixels here; the forward map rounds too.
        prop_assert!((found[0].pixel - pixel).length() < 1e-7, "{} {}", found[0].pixel, pixel);
        prop_assert!((found[0].t - t).abs() < 1e-9, "{} {}", found[0].t, t);
        let c = continuous(&f, point).unwrap();
        prop_assert!((c.pixel - found[0].pixel).length() < 1e-12);
    }
}

/// The slope is the largest derivative: exactly the ramp's for a linear map, and the
/// derivative the Newton steps use agrees with finite differences inside a cell.
#[test]
fn the_map_slope_is_its_largest_derivative() {
    // m = (0.3 u, -0.1 v) sampled at the pixel centres of an 8 x 6 map.
    let ramp = DdocMap::new(
        8,
        6,
        (0..48)
            .map(|k| {
                let (x, y) = ((k % 8) as f64, (k / 8) as f64);
                DVec2::new(0.3 * (x + 0.5) / 8.0, -0.1 * (1.0 - (y + 0.5) / 6.0))
            })
            .collect(),
    )
    .unwrap();
    let (s, _) = ramp.slope();
    assert!((s - 0.3).abs() < 1e-12, "{s}");
    // A bump: the derivative against central differences, inside cells.
    let bump = map_of(9, 7, 0.6, |x, y| {
        DVec2::new(
            (f64::from(x) * 0.9).sin(),
            (f64::from(y) * 1.3 + f64::from(x)).cos(),
        )
    });
    let (s, (cx, cy)) = bump.slope();
    assert!((s - 0.6).abs() < 1e-12 && cx < 8 && cy < 6, "{s}");
    for uv in [
        DVec2::new(0.31, 0.47),
        DVec2::new(0.77, 0.2),
        DVec2::new(0.52, 0.83),
    ] {
        let (_, d) = bump.sample_with_slope(uv);
        let e = 1e-7;
        for (axis, column) in [(DVec2::X, d.x_axis), (DVec2::Y, d.y_axis)] {
            let fd = (bump.sample(uv + e * axis) - bump.sample(uv - e * axis)) / (2.0 * e);
            assert!((fd - column).length() < 1e-6, "{uv}: {fd} against {column}");
            assert!(column.length() <= s + 1e-9);
        }
    }
    // Beyond the map's pixel centres it is the border samples: no slope across the border.
    let (_, d) = bump.sample_with_slope(DVec2::new(-0.5, 0.5));
    assert_eq!(d.x_axis, DVec2::ZERO);
    assert!(d.y_axis != DVec2::ZERO);
    // A one-pixel map is constant.
    let one = DdocMap::new(1, 1, vec![DVec2::new(0.2, 0.1)]).unwrap();
    assert_eq!(one.slope().0, 0.0);
}

/// The iteration meets its tolerance: q - h m(q) = w to TOLERANCE (1 - h L), so q is
/// within TOLERANCE of the exact solution, also at the largest accepted slope.
#[test]
fn undisplacing_meets_the_tolerance_at_the_largest_slope() {
    let slope = MAX_SLOPE - 1e-6;
    let map = map_of(12, 9, slope, |x, y| {
        DVec2::new(
            (f64::from(x) * 1.7).sin(),
            (f64::from(x + 2 * y) * 0.8).cos(),
        )
    });
    let (s, _) = map.slope();
    for h in [0.0, 0.25, 0.5, 1.0] {
        for k in 0..50 {
            let w = DVec2::new(
                f64::from(k % 10) * 0.13 - 0.1,
                f64::from(k / 10) * 0.27 - 0.05,
            );
            let q = undisplace(&map, w, h, s).expect("converges");
            let r = q - h * map.sample(q) - w;
            assert!(r.length() <= TOLERANCE * (1.0 - h * s), "h {h}, w {w}: {r}");
        }
    }
}

/// Degenerate cases. The eye (a volume starting there) has no image, a point behind it none
/// in the bounded inverse and a continuous one with t < 0 (the raster's chart clips it); a
/// point beyond the image's side is seen through the border samples and dropped by the
/// bounded inverse; points just before and after each plane of the bend have images that
/// agree (the inverse is continuous there).
#[test]
fn the_ddoc_inverse_at_its_degenerate_points() {
    let m = DVec2::new(0.04, -0.03);
    let f = ddoc(
        DdocMap::new(3, 2, vec![m; 6]).unwrap(),
        [4.0, 8.0],
        [0.0, 20.0],
    );
    let b = crate::projection::CameraBasis::new(&frame()).unwrap();
    assert!(images(&f, b.origin).is_empty());
    assert!(continuous(&f, b.origin).is_none());
    let behind = b.origin - 2.0 * b.forward + 0.3 * b.right;
    assert!(images(&f, behind).is_empty());
    assert!(continuous(&f, behind).unwrap().t < 0.0);
    // Beyond the bend a constant map shifts every image by m: q = w + m (u right, v up).
    let side = b.origin + 10.0 * b.forward + 9.0 * b.right;
    assert!(images(&f, side).is_empty());
    let perspective = build(Preset::Perspective { fov: 60.0 }, [0.0, 20.0]);
    let w = supported_chart(&perspective)
        .unwrap()
        .map
        .project_continuous(side)
        .unwrap();
    let q = continuous(&f, side).unwrap();
    let shift = DVec2::new(m.x * 40.0, -m.y * 30.0);
    assert!(
        q.pixel.x > 40.0 && (q.pixel - (w.pixel + shift)).length() < 1e-9,
        "{}",
        q.pixel
    );
    // Across the planes of the bend, along a line through the volume.
    for depth in [4.0, 8.0] {
        let on = b.origin + depth * (b.forward + 0.2 * b.right - 0.1 * b.up);
        let images: Vec<DVec2> = [-1e-9, 0.0, 1e-9]
            .iter()
            .map(|e| continuous(&f, on + *e * b.forward).unwrap().pixel)
            .collect();
        assert!((images[0] - images[1]).length() < 1e-6, "{images:?}");
        assert!((images[2] - images[1]).length() < 1e-6, "{images:?}");
    }
}

/// A zero map is the perspective: the same pixel and t for points all over the volume.
#[test]
fn a_zero_map_inverts_as_the_perspective() {
    let f = ddoc(
        DdocMap::new(4, 3, vec![DVec2::ZERO; 12]).unwrap(),
        [4.0, 8.0],
        [0.5, 20.0],
    );
    let perspective = build(Preset::Perspective { fov: 60.0 }, [0.5, 20.0]);
    let b = crate::projection::CameraBasis::new(&frame()).unwrap();
    for k in 0..60 {
        let (x, y, z) = (
            f64::from(k % 5) - 2.0,
            f64::from(k % 3) - 1.0,
            0.7 + f64::from(k) * 0.3,
        );
        let p = b.origin + z * b.forward + 0.2 * z * (x * b.right + y * b.up);
        let (a, e) = (images(&f, p), images(&perspective, p));
        assert_eq!(a.len(), e.len());
        for (a, e) in a.iter().zip(&e) {
            assert!((a.pixel - e.pixel).length() < 1e-9 && (a.t - e.t).abs() < 1e-12);
        }
    }
}

/// A map whose slope reaches MAX_SLOPE is refused by the raster with the slope, where it is
/// and the method that works; one just below it has a chart.
#[test]
fn a_steep_map_is_refused_by_the_raster() {
    let steep = map_of(6, 5, MAX_SLOPE + 1e-6, |x, y| {
        DVec2::new(f64::from(x * x), f64::from(y))
    });
    let e = supported_chart(&ddoc(steep, [4.0, 8.0], [0.5, 20.0]))
        .unwrap_err()
        .message;
    assert!(
        e.contains("slope reaches 0.900 (at map pixel (4, 0)")
            && e.contains("below 0.9")
            && e.ends_with("(use --method raycast)"),
        "{e}"
    );
    let gentle = map_of(6, 5, MAX_SLOPE - 1e-3, |x, y| {
        DVec2::new(f64::from(x * x), f64::from(y))
    });
    assert!(supported_chart(&ddoc(gentle, [4.0, 8.0], [0.5, 20.0])).is_ok());
}

/// Surfaces that are not similar rectangles, or displaced by different maps, are refused
/// with the reason.
#[test]
fn displaced_surfaces_that_do_not_separate_are_refused() {
    let map = |d: f64| Arc::new(DdocMap::new(2, 2, vec![DVec2::splat(d); 4]).unwrap());
    let rect = |z: f64, w: f64, h: f64| Surface::Rectangle {
        corner: DVec3::new(-w, -h, z),
        u_edge: DVec3::new(2.0 * w, 0.0, 0.0),
        v_edge: DVec3::new(0.0, 2.0 * h, 0.0),
    };
    let displaced = |z: f64, w: f64, h: f64, m: Arc<DdocMap>| {
        let Surface::Rectangle {
            corner,
            u_edge,
            v_edge,
        } = rect(z, w, h)
        else {
            unreachable!()
        };
        Surface::Displaced(Box::new(presets::DisplacedRectangle {
            corner,
            u_edge,
            v_edge,
            map: m,
        }))
    };
    let knots = [0.0, 0.5, 1.0];
    let cases = [
        (
            [1.0, 2.0, 4.0],
            3.0,
            [0.1, 0.1],
            false,
            "not similar rectangles",
        ),
        ([1.0, 2.0, 4.0], 4.0, [0.1, 0.2], true, "different maps"),
        (
            [1.0, 4.0, 2.0],
            4.0,
            [0.1, 0.1],
            false,
            "in order along the projectors",
        ),
    ];
    for (z, height, maps, middle_displaced, expected) in cases {
        let middle = if middle_displaced {
            displaced(z[1], 2.0, 2.0, map(maps[0]))
        } else {
            rect(z[1], 2.0, 2.0)
        };
        let surfaces = [
            rect(z[0], 1.0, 1.0),
            middle,
            displaced(z[2], 4.0, height, map(maps[1])),
        ];
        let e = Inverse::classify_displaced(&surfaces, &knots)
            .unwrap_err()
            .message;
        assert!(e.contains(expected), "{e} (expected {expected})");
    }
    let fine = [
        rect(1.0, 1.0, 1.0),
        rect(2.0, 2.0, 2.0),
        displaced(4.0, 4.0, 4.0, map(0.1)),
    ];
    assert!(Inverse::classify_displaced(&fine, &knots).is_ok());
}
