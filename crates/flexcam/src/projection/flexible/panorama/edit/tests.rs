//! The perspective edit: straight scene lines image straight inside the rectangle (measured
//! in pixels through the lookup inverse), rays outside its u and v ranges are unchanged, bad
//! rectangles are refused.

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::*;
use crate::projection::camera_basis::CameraBasis;
use crate::projection::flexible::panorama::lookup::PanoramaInverse;
use crate::projection::flexible::panorama::{
    Attached, CurveBlend, OutlineShape, PanoramaSurface, ProfileShape,
};
use crate::projection::flexible::presets::{Preset, PresetSpec};
use crate::projection::flexible::{Flexible, FlexibleSpec};
use crate::projection::{CameraFrame, Projection};

/// Image size the deviations are measured in.
const WIDTH: f64 = 1024.0;
const HEIGHT: f64 = 512.0;

/// A 90-degree-wide rectangle around the view direction, from -18 to 54 degrees of
/// elevation on the equirectangular profile (a slanted profile chord).
const RECT: [f64; 4] = [0.375, 0.4, 0.625, 0.8];

/// The equirectangular shape: circle + semicircle.
fn equirect() -> PanoramaShape {
    let outline = OutlineShape::Circle.curve().unwrap();
    let profile = ProfileShape::Arc {
        elevation: [-FRAC_PI_2, FRAC_PI_2],
    }
    .curve()
    .unwrap();
    PanoramaShape::single(outline, profile).unwrap()
}

/// The camera frame of every test here: at (1, 2, 3) looking at (-2, 1, 0), y up.
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

/// `preset` at the test [`frame`], with `clip`.
fn preset_spec(preset: Preset, clip: Option<[f64; 2]>) -> PresetSpec {
    PresetSpec {
        preset,
        frame: frame(),
        clip,
    }
}

fn inverse(shape: PanoramaShape) -> PanoramaInverse {
    let shape = Arc::new(shape);
    let surface = |scale| PanoramaSurface {
        basis: basis(),
        scale,
        shape: Arc::clone(&shape),
    };
    PanoramaInverse::new(&surface(0.0), &surface(1000.0)).unwrap()
}

/// The camera-local point at distance `r` in the direction of azimuth and elevation
/// (degrees).
fn local(az: f64, el: f64, r: f64) -> DVec3 {
    let (az, el) = (az.to_radians(), el.to_radians());
    r * DVec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos())
}

/// The largest distance in pixels of the image of the scene segment from `a` to `b`
/// (camera-local) from the straight line between the images of its ends; every sample must
/// image inside `rect` (u0 > u1: across the seam, where u is unwrapped).
fn deviation(inv: &PanoramaInverse, rect: [f64; 4], a: DVec3, b: DVec3) -> f64 {
    let b3 = basis();
    let across = rect[0] > rect[2];
    let pixel = |p: DVec3| {
        let (mut uv, _) = inv.solve(b3.origin + b3.to_world(p)).unwrap();
        if across && uv.x < 0.5 {
            uv.x += 1.0;
        }
        let u1 = if across { rect[2] + 1.0 } else { rect[2] };
        assert!(
            (rect[0]..=u1).contains(&uv.x) && (rect[1]..=rect[3]).contains(&uv.y),
            "{uv} outside the rectangle"
        );
        DVec2::new(uv.x * WIDTH, uv.y * HEIGHT)
    };
    let (pa, pb) = (pixel(a), pixel(b));
    let normal = (pb - pa).perp().normalize();
    (0..=200)
        .map(|k| (pixel(a.lerp(b, k as f64 / 200.0)) - pa).dot(normal).abs())
        .fold(0.0, f64::max)
}

/// Scene segments whose images lie inside [`RECT`] before and after the edit: a diagonal, a
/// horizontal line above the horizon, a slanted near-vertical one, each with ends at
/// different distances.
fn segments() -> [(DVec3, DVec3); 3] {
    [
        (local(-30.0, 5.0, 5.0), local(30.0, 35.0, 8.0)),
        (local(-35.0, 30.0, 4.0), local(35.0, 30.0, 4.0)),
        (local(-10.0, -10.0, 6.0), local(5.0, 45.0, 3.0)),
    ]
}

#[test]
fn straight_lines_image_straight_inside_the_rectangle() {
    let before = inverse(equirect());
    let after = inverse(make_perspective(&equirect(), RECT).unwrap());
    for (a, b) in segments() {
        let (bent, straight) = (
            deviation(&before, RECT, a, b),
            deviation(&after, RECT, a, b),
        );
        println!("deviation before {bent:.3} px, after {straight:.2e} px");
        assert!(bent > 2.0, "before the edit the line bends: {bent} px");
        assert!(
            straight < 0.01,
            "after the edit it is straight: {straight} px"
        );
    }
}

#[test]
fn rays_outside_the_rectangles_ranges_are_unchanged() {
    let old = equirect();
    let new = make_perspective(&old, RECT).unwrap();
    let (mut same, mut changed) = (0, 0);
    for i in 0..=40 {
        for j in 0..=40 {
            let uv = DVec2::new(i as f64 / 40.0, j as f64 / 40.0);
            let inside_u = (RECT[0]..=RECT[2]).contains(&uv.x);
            let inside_v = (RECT[1]..=RECT[3]).contains(&uv.y);
            let gap = (new.local(uv) - old.local(uv)).length();
            if !inside_u && !inside_v {
                assert!(gap < 1e-12, "{uv}: moved by {gap}");
                same += 1;
            } else if gap > 1e-3 {
                changed += 1;
            }
        }
    }
    assert!(
        same > 500 && changed > 300,
        "{same} unchanged, {changed} changed"
    );
    // The surface stays continuous across the rectangle's corners.
    for uv in [DVec2::new(RECT[0], RECT[1]), DVec2::new(RECT[2], RECT[3])] {
        assert!((new.local(uv) - old.local(uv)).length() < 1e-12);
    }
}

#[test]
fn a_vertical_segment_profile_stays_linear() {
    // The cubic panorama's front face is already perspective: the edit over exactly that
    // face changes nothing.
    let square = OutlineShape::Square.curve().unwrap();
    let segment = ProfileShape::Segment {
        elevation: [-0.7, 0.7],
    }
    .curve()
    .unwrap();
    let old = PanoramaShape::single(square, segment).unwrap();
    let new = make_perspective(&old, [0.375, 0.1, 0.625, 0.9]).unwrap();
    for k in 0..=20 {
        let uv = DVec2::new(0.375 + 0.25 * k as f64 / 20.0, k as f64 / 20.0);
        assert!((new.local(uv) - old.local(uv)).length() < 1e-12, "{uv}");
    }
}

/// Segments (camera-local) seen around azimuth `centre` degrees within +-30 degrees, at
/// elevations within +-20 degrees, ends at different distances.
fn segments_around(centre: f64) -> [(DVec3, DVec3); 3] {
    [
        (
            local(centre - 28.0, 5.0, 5.0),
            local(centre + 25.0, 18.0, 8.0),
        ),
        (
            local(centre - 28.0, -15.0, 4.0),
            local(centre + 28.0, -15.0, 4.0),
        ),
        (
            local(centre - 10.0, -18.0, 6.0),
            local(centre + 5.0, 18.0, 3.0),
        ),
    ]
}

/// Before and after the edit of `shape` over `rect`, the largest deviation of the segments.
fn bent_and_straight(shape: &PanoramaShape, rect: [f64; 4], centre: f64) -> (f64, f64) {
    let before = inverse(shape.clone());
    let after = inverse(make_perspective(shape, rect).unwrap());
    let worst = |inv: &PanoramaInverse| {
        segments_around(centre)
            .iter()
            .map(|&(a, b)| deviation(inv, rect, a, b))
            .fold(0.0, f64::max)
    };
    (worst(&before), worst(&after))
}

/// The cubic and rounded cubic presets take the edit as panoramas: a rectangle from the view
/// direction to the right (u in [0.5, 0.75], azimuths 0 to 90 degrees) across the
/// front-right corner makes the lines across the corner straight.
#[test]
fn cubic_presets_take_the_edit_across_a_corner() {
    let spec = |preset| preset_spec(preset, None);
    let rect = [0.5, 0.2, 0.75, 0.8];
    for preset in [
        Preset::Cubic { v_fov: 100.0 },
        Preset::RoundedCubic {
            v_fov: 100.0,
            corner_radius: 0.3,
        },
    ] {
        let name = preset.name();
        let source = edit_source(&VolumeSource::Preset(spec(preset.clone())), rect).unwrap();
        let VolumeSource::Panorama(edited) = source else {
            panic!("{name}: not a panorama");
        };
        let plain = spec(preset).panorama().unwrap().unwrap();
        assert_eq!(
            *edited.shape,
            make_perspective(&plain.shape, rect).unwrap(),
            "{name}"
        );
        let (bent, straight) = bent_and_straight(&plain.shape, rect, 45.0);
        println!("{name}: deviation before {bent:.3} px, after {straight:.2e} px");
        assert!(
            bent > 2.0,
            "{name}: before the edit the lines bend: {bent} px"
        );
        assert!(straight < 0.01, "{name}: after the edit: {straight} px");
    }
    // Other volumes are refused.
    let perspective = VolumeSource::Preset(spec(Preset::Perspective { fov: 60.0 }));
    let e = edit_source(&perspective, rect).unwrap_err();
    assert!(e.message.contains("not the perspective preset"), "{e}");
}

/// A rectangle across the seam (u in [0.875, 1] + [0, 0.125]: 90 degrees behind the eye)
/// is flattened as one chord: lines behind the eye image straight (in unwrapped u); rays
/// outside its u and v ranges are unchanged.
#[test]
fn a_rectangle_across_the_seam_is_one_perspective_view() {
    let rect = [0.875, 0.3, 0.125, 0.8];
    let (bent, straight) = bent_and_straight(&equirect(), rect, 180.0);
    println!("across the seam: deviation before {bent:.3} px, after {straight:.2e} px");
    assert!(bent > 2.0, "{bent} px");
    assert!(straight < 0.01, "{straight} px");
    let old = equirect();
    let new = make_perspective(&old, rect).unwrap();
    for uv in [
        DVec2::new(0.5, 0.1),
        DVec2::new(0.3, 0.2),
        DVec2::new(0.7, 0.9),
    ] {
        assert!((new.local(uv) - old.local(uv)).length() < 1e-12, "{uv}");
    }
    // The seam column moved onto the chord (the middle of the range: the chord's nearest
    // point, straight behind the eye at distance cos 45 degrees), and u = 0 and 1 agree.
    let seam = new.outline(DVec2::new(0.0, 0.5));
    assert!((seam - DVec2::new(0.0, -(0.5f64.sqrt()))).length() < 1e-12);
    assert!((new.local(DVec2::new(1.0, 0.3)) - new.local(DVec2::new(0.0, 0.3))).length() < 1e-12);
}

#[test]
fn bad_rectangles_are_refused() {
    let shape = equirect();
    for rect in [
        [-0.1, 0.4, 0.6, 0.8],
        [0.4, 0.4, 0.6, 1.2],
        [0.4, 0.6, 0.6, 0.4],
        [0.4, 0.5, 0.6, 0.5],
        [0.5, 0.4, 0.5, 0.8],
        [1.0, 0.4, 0.0, 0.8],
        [f64::NAN, 0.4, 0.6, 0.8],
    ] {
        let e = make_perspective(&shape, rect).unwrap_err();
        assert!(e.message.contains("needs u0, u1, v0, v1 in [0, 1]"), "{e}");
    }
    // 216 degrees of the circle: the chord passes the eye.
    let e = make_perspective(&shape, [0.2, 0.4, 0.8, 0.6]).unwrap_err();
    assert!(e.message.contains("turns 216.0 degrees"), "{e}");
    // Across the seam likewise: [0.6, 1] + [0, 0.4] turns 288 degrees.
    let e = make_perspective(&shape, [0.6, 0.4, 0.4, 0.8]).unwrap_err();
    assert!(e.message.contains("turns 288.0 degrees"), "{e}");
    // Exactly half the circle: the chord runs through the eye.
    assert!(make_perspective(&shape, [0.25, 0.4, 0.75, 0.6]).is_err());
    // The whole height of the semicircle ends at the poles, on the axis.
    let e = make_perspective(&shape, [0.4, 0.0, 0.6, 0.6]).unwrap_err();
    assert!(e.message.contains("up axis"), "{e}");
    let behind = ProfileShape::Points(vec![
        DVec2::new(-0.5, -1.0),
        DVec2::ONE,
        DVec2::new(1.0, 2.0),
    ]);
    let shape = PanoramaShape::single(
        OutlineShape::Circle.curve().unwrap(),
        behind.curve().unwrap(),
    )
    .unwrap();
    assert!(make_perspective(&shape, [0.4, 0.0, 0.6, 0.5]).is_err());
    assert!(make_perspective(&shape, [0.4, 0.4, 0.6, 0.5]).is_ok());
}

/// The full cylindrical and equirectangular presets (camera [`frame`]).
fn round_presets() -> [PresetSpec; 2] {
    let spec = |preset| preset_spec(preset, Some([0.0, 50.0]));
    [
        spec(Preset::Cylindrical {
            h_fov: 360.0,
            v_fov: 100.0,
        }),
        spec(Preset::Equirectangular {
            h_fov: 360.0,
            v_fov: 180.0,
        }),
    ]
}

/// The preset edited over `rect`, as a flexible projection of `w` x `h` pixels.
fn edited_flexible(spec: &PresetSpec, rect: [f64; 4], (w, h): (u32, u32)) -> Flexible {
    let source = edit_source(&VolumeSource::Preset(spec.clone()), rect).unwrap();
    let spec = FlexibleSpec {
        source,
        reparam: None,
    };
    Flexible::new(&spec, w, h).unwrap()
}

/// The cylindrical and equirectangular presets take the edit as the panoramas they are, in
/// front of the eye and across the seam: lines inside the rectangle image straight.
#[test]
fn cylindrical_and_equirectangular_presets_take_the_edit() {
    let cases = [
        ([0.375, 0.3, 0.625, 0.7], 0.0),
        ([0.875, 0.3, 0.125, 0.7], 180.0),
    ];
    for spec in round_presets() {
        for (rect, centre) in cases {
            assert_the_preset_edit_straightens(&spec, rect, centre);
        }
    }
}

/// Edits `spec` to make `rect` perspective and checks the edit is `make_perspective` of the
/// preset's own panorama shape and that scene lines around `centre` degrees bend before
/// the edit (more than 2 px) and image straight after (under 0.01 px). Returns the plain
/// and the edited shapes for further checks.
fn assert_the_preset_edit_straightens(
    spec: &PresetSpec,
    rect: [f64; 4],
    centre: f64,
) -> (Arc<PanoramaShape>, Arc<PanoramaShape>) {
    let name = spec.preset.name();
    let plain = spec.panorama().unwrap().unwrap();
    let source = edit_source(&VolumeSource::Preset(spec.clone()), rect).unwrap();
    let VolumeSource::Panorama(edited) = source else {
        panic!("{name}: not a panorama");
    };
    assert_eq!(
        *edited.shape,
        make_perspective(&plain.shape, rect).unwrap(),
        "{name}"
    );
    let (bent, straight) = bent_and_straight(&plain.shape, rect, centre);
    println!("{name} {rect:?}: deviation before {bent:.3} px, after {straight:.2e} px");
    assert!(
        bent > 2.0,
        "{name}: before the edit the lines bend: {bent} px"
    );
    assert!(straight < 0.01, "{name}: after the edit: {straight} px");
    (plain.shape, edited.shape)
}

/// Outside the rectangle's u and v bands every pixel of the preset `spec` edited over
/// `rect` keeps the preset's own ray (the preset's cylinder or sphere surfaces, not its
/// panorama form); inside, rays move (at least `moved` pixels of 96 x 48 by over 1e-6).
fn assert_rays_kept_outside(spec: &PresetSpec, rect: [f64; 4], moved_at_least: usize) {
    let (w, h) = (96, 48);
    let name = spec.preset.name();
    let preset = FlexibleSpec {
        source: VolumeSource::Preset(spec.clone()),
        reparam: None,
    };
    let preset = Flexible::new(&preset, w, h).unwrap();
    let edited = edited_flexible(spec, rect, (w, h));
    let across = rect[0] > rect[2];
    let in_u = |u: f64| {
        if across {
            u >= rect[0] || u <= rect[2]
        } else {
            (rect[0]..=rect[2]).contains(&u)
        }
    };
    let (mut same, mut moved) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let uv = preset.uv(pixel).unwrap();
            let (a, b) = (preset.ray(pixel).unwrap(), edited.ray(pixel).unwrap());
            let gap = (a.origin - b.origin).length() + (a.direction - b.direction).length();
            let scale = a.direction.length();
            if !in_u(uv.x) && !(rect[1]..=rect[3]).contains(&uv.y) {
                assert!(gap <= 1e-12 * scale, "{name} {rect:?} {pixel}: moved {gap}");
                same += 1;
            } else if gap > 1e-6 * scale {
                moved += 1;
            }
        }
    }
    assert!(
        same > 1000 && moved >= moved_at_least,
        "{name} {rect:?}: {same} same, {moved} moved"
    );
}

/// Outside the rectangle's u and v bands every pixel keeps the preset's own ray; inside,
/// rays move: full presets (in front and across the seam) and 200-degree ones (in front and
/// up to the image's edge, where the windowed panorama repeats the partial preset).
#[test]
fn edited_round_presets_keep_their_rays_outside_the_rectangle() {
    for spec in round_presets() {
        for rect in [[0.375, 0.3, 0.625, 0.7], [0.875, 0.3, 0.125, 0.7]] {
            assert_rays_kept_outside(&spec, rect, 1000);
        }
    }
    for spec in partial_presets(200.0) {
        for (rect, _) in PARTIAL_RECTS {
            assert_rays_kept_outside(&spec, rect, 1000);
        }
    }
}

/// The cylindrical and equirectangular presets of `h_fov` degrees (camera [`frame`]).
fn partial_presets(h_fov: f64) -> [PresetSpec; 2] {
    round_presets().map(|mut spec| {
        match &mut spec.preset {
            Preset::Cylindrical { h_fov: h, .. } | Preset::Equirectangular { h_fov: h, .. } => {
                *h = h_fov
            }
            _ => unreachable!(),
        }
        spec
    })
}

/// Rectangles of the 200-degree presets with the azimuth (degrees) of their middle: around
/// the view direction, and reaching the image's left edge (degenerate: the window's end).
const PARTIAL_RECTS: [([f64; 4], f64); 2] =
    [([0.3, 0.3, 0.7, 0.7], 0.0), ([0.0, 0.3, 0.45, 0.7], -55.0)];

/// Less than 360 degrees: the presets take the edit as the circle windowed to their
/// azimuths, inside the image and up to its edge: lines inside the rectangle image straight
/// (pixels of the windowed image, u measured across the 200 degrees).
#[test]
fn partial_round_presets_take_the_edit() {
    for spec in partial_presets(200.0) {
        for (rect, centre) in PARTIAL_RECTS {
            let (plain, edited) = assert_the_preset_edit_straightens(&spec, rect, centre);
            assert_eq!(
                plain.window(),
                Some([0.5 - 100.0 / 360.0, 0.5 + 100.0 / 360.0])
            );
            assert_eq!(edited.window(), plain.window());
        }
    }
}

/// Less than 360 degrees, refused in one line: a rectangle across the seam (the windowed
/// image has edges instead), and a window narrower than `MIN_WINDOW` of a turn.
#[test]
fn partial_round_presets_refuse_what_has_no_meaning() {
    for spec in partial_presets(200.0) {
        let e = edit_source(&VolumeSource::Preset(spec), [0.8, 0.3, 0.2, 0.7]).unwrap_err();
        assert!(
            e.message.contains("across the seam") && e.message.contains("200.0 degrees"),
            "{e}"
        );
    }
    for spec in partial_presets(1e-4) {
        let e = edit_source(&VolumeSource::Preset(spec.clone()), RECT).unwrap_err();
        assert!(
            e.message.contains(spec.preset.name()) && e.message.contains("s1 - s0 >= "),
            "{e}"
        );
    }
}

/// A window maps image columns onto outline fractions and back (across the turn opposite
/// it too, where u jumps by one turn); bad windows are refused.
#[test]
fn windows_map_columns_to_outline_fractions() {
    let quarter = equirect().windowed([0.375, 0.625]).unwrap();
    for u in [-1.0, 0.0, 0.3, 1.0, 2.4] {
        let s = quarter.fraction(u);
        assert!((quarter.column(s) - u).abs() < 1e-12, "{u}");
        // The same direction one turn on.
        assert!((quarter.column(s + 1.0) - u).abs() < 1e-12, "{u}");
    }
    assert_eq!(quarter.fraction(0.5), 0.5);
    // Straight behind (s = 0 or 1) is two turns' halves from the middle: u = -1.5 or 2.5.
    assert!((quarter.column(0.0) - 2.5).abs() < 1e-12 || (quarter.column(0.0) + 1.5).abs() < 1e-12);
    assert_eq!(equirect().column(0.3), 0.3);
    for bad in [
        [0.6, 0.4],
        [-0.1, 0.5],
        [0.5, 1.5],
        [0.5, 0.5 + 1e-7],
        [f64::NAN, 0.5],
    ] {
        let e = equirect().windowed(bad).unwrap_err();
        assert!(e.message.contains("needs 0 <= s0 < s1 <= 1"), "{e}");
    }
    let two_profiles = PanoramaShape::new(
        vec![Attached {
            at: 0.0,
            curve: OutlineShape::Circle.curve().unwrap(),
        }],
        [0.0, 0.5]
            .map(|at| Attached {
                at,
                curve: ProfileShape::Segment {
                    elevation: [-0.5, 0.5],
                }
                .curve()
                .unwrap(),
            })
            .to_vec(),
        CurveBlend::Linear,
    )
    .unwrap();
    let e = two_profiles.windowed([0.25, 0.75]).unwrap_err();
    assert!(e.message.contains("takes one profile"), "{e}");
}

/// Degenerate: a tiny `h_fov` (half a degree, 0.0014 of a turn) still takes the edit: the
/// chord is nearly the arc, rays outside the rectangle's bands are the preset's, and points
/// project back to their pixels through the windowed lookup.
#[test]
fn a_tiny_h_fov_takes_the_edit() {
    let rect = [0.4, 0.4, 0.6, 0.6];
    for spec in partial_presets(0.5) {
        let name = spec.preset.name();
        assert_rays_kept_outside(&spec, rect, 0);
        let f = edited_flexible(&spec, rect, (64, 32));
        for (x, y, t) in [
            (0.5, 0.5, 0.3),
            (32.0, 16.0, 0.5),
            (63.5, 31.5, 0.9),
            (20.0, 5.0, 0.01),
        ] {
            let pixel = DVec2::new(x, y);
            let p = f.ray(pixel).unwrap().at(t);
            let mut images = Vec::new();
            f.inverse().unwrap().project(p, &mut images);
            assert_eq!(images.len(), 1, "{name} {pixel}");
            assert!(
                (images[0].pixel - pixel).length() < 1e-6 * 64.0,
                "{name} {pixel} {}",
                images[0].pixel
            );
            assert!((images[0].t - t).abs() < 1e-6, "{name} {t} {}", images[0].t);
        }
    }
}

mod round_trip {
    use proptest::prelude::*;

    use super::*;
    use crate::projection::flexible::panorama::lookup::ACCURACY;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Edited cylindrical and equirectangular presets (full: in front and across the
        /// seam; 200 degrees: in front and up to the image's edge): a point at depth t on
        /// the ray of pixel q projects back to q and t, and the ray of the projected pixel
        /// reaches the point.
        #[test]
        fn project_then_cast(
            which in 0usize..2,
            seam in any::<bool>(),
            partial in any::<bool>(),
            x in 0.0f64..1.0,
            y in 0.02f64..0.98,
            t in 0.0f64..1.0,
        ) {
            // Partial (200 degrees): the rectangle reaching the left edge instead of the seam.
            let rect = match (seam, partial) {
                (true, false) => [0.8, 0.25, 0.15, 0.7],
                (true, true) => [0.0, 0.25, 0.45, 0.7],
                (false, _) => [0.35, 0.25, 0.6, 0.7],
            };
            let (w, h) = (360, 180);
            let spec = if partial { partial_presets(200.0) } else { round_presets() };
            let f = edited_flexible(&spec[which], rect, (w, h));
            prop_assert!(f.inverse().is_ok());
            let pixel = DVec2::new(x * f64::from(w), y * f64::from(h));
            let ray = f.ray(pixel).unwrap();
            let p = ray.at(t);
            let mut images = Vec::new();
            f.inverse().unwrap().project(p, &mut images);
            prop_assert_eq!(images.len(), 1);
            let image = images[0];
            let dx = (image.pixel.x - pixel.x).abs();
            let dx = dx.min(f64::from(w) - dx);
            prop_assert!(dx <= ACCURACY * f64::from(w), "x {} vs {}", image.pixel, pixel);
            prop_assert!((image.pixel.y - pixel.y).abs() <= ACCURACY * f64::from(h));
            prop_assert!((image.t - t).abs() <= ACCURACY, "t {} vs {}", image.t, t);
            let back = f.ray(image.pixel).unwrap().at(image.t);
            let reach = (p - ray.origin).length().max(ray.direction.length() * 1e-3);
            prop_assert!((back - p).length() <= 10.0 * ACCURACY * reach, "{} vs {}", back, p);
        }
    }
}

/// The example scenes of the edited equirectangular (in front), cylindrical (across the
/// seam) and 200-degree cylindrical presets, and the last as a 200-degree equirectangular
/// one (preset and `v_fov` replaced): method raster with adaptive subdivision agrees with
/// the ray caster on at least 99.5 % of the object ids, and uniform subdivision 8 on no
/// fewer than 1.
#[test]
fn edited_round_presets_raster_like_the_ray_caster() {
    use crate::render::compare;
    use crate::render::Subdivision;
    use crate::render::{Frame, Method, RenderOptions, Shading};
    use crate::scene::file::parse;

    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/");
    // The 200-degree scene once more as an equirectangular preset.
    let as_equirect = |text: &str| {
        let replaced = text
            .replace("preset = \"cylindrical\"", "preset = \"equirectangular\"")
            .replace("v_fov = 100.0", "v_fov = 120.0");
        assert!(
            replaced.contains("preset = \"equirectangular\"\n")
                && replaced.contains("v_fov = 120.0")
        );
        replaced
    };
    for (file, equirect) in [
        ("flexible-panorama-equirect-edit.toml", false),
        ("flexible-panorama-cylindrical-edit.toml", false),
        ("flexible-panorama-partial-edit.toml", false),
        ("flexible-panorama-partial-edit.toml", true),
    ] {
        let name = format!(
            "{file}{}",
            if equirect { " as equirectangular" } else { "" }
        );
        let path = format!("{dir}{file}");
        let text = std::fs::read_to_string(&path).unwrap();
        let text = if equirect { as_equirect(&text) } else { text };
        let scene = parse(&text, std::path::Path::new(&path)).unwrap();
        let projection = scene
            .projection
            .build(scene.image.width, scene.image.height)
            .unwrap();
        let prepared = crate::render::PreparedScene::new(&scene);
        let render = |method: Method, subdivision| -> Frame {
            let options = RenderOptions {
                shading: Shading::Flat,
                subdivision,
                ..RenderOptions::default()
            };
            method
                .render(&prepared, projection.as_ref(), &options)
                .unwrap()
                .0
        };
        let reference = render(Method::Raycast, Subdivision::default());
        let agreement = |subdivision| {
            compare(&render(Method::Raster, subdivision), &reference)
                .unwrap()
                .id_agreement
        };
        let (one, eight, adaptive) = (
            agreement(Subdivision::uniform(1)),
            agreement(Subdivision::uniform(8)),
            agreement(Subdivision::default()),
        );
        println!(
            "{name}: id disagreement uniform 1 {:.3} %, 8 {:.3} %, adaptive {:.3} %",
            100.0 * (1.0 - one),
            100.0 * (1.0 - eight),
            100.0 * (1.0 - adaptive)
        );
        assert!(eight >= one, "{name}");
        assert!(adaptive >= 0.995, "{name}: adaptive agreement {adaptive}");
    }
}
