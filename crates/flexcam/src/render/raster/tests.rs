//! Method raster against the ray caster: refusals, coverage without cracks, and the accuracy
//! per subdivision level on the built-in scenes (the table of docs/raster.md).

use std::path::Path;

use glam::{DVec2, DVec3};

use super::*;
use crate::projection::flexible::{FlexibleSpec, Preset, PresetSpec, VolumeSource};
use crate::projection::{CameraFrame, ProjectionSpec, TrilinearMesh};
use crate::render::compare::{compare, Comparison};
use crate::render::{Method, PreparedScene};
use crate::scene::{self, file};

fn flat(subdivision: Subdivision) -> RenderOptions<'static> {
    RenderOptions {
        shading: Shading::Flat,
        subdivision,
        ..RenderOptions::default()
    }
}

fn flexible(preset: Preset, frame: CameraFrame) -> ProjectionSpec {
    ProjectionSpec::Flexible(Box::new(FlexibleSpec {
        source: VolumeSource::Preset(PresetSpec {
            preset,
            frame,
            clip: None,
        }),
        reparam: None,
    }))
}

/// Every projection (and flexible preset) with a chart, placed by `frame`.
fn invertible(frame: CameraFrame, fov: f64) -> Vec<(&'static str, ProjectionSpec)> {
    vec![
        ("perspective", ProjectionSpec::Perspective { frame, fov }),
        (
            "orthographic",
            ProjectionSpec::Orthographic { frame, width: 9.0 },
        ),
        ("fisheye 180", ProjectionSpec::Fisheye { frame, fov: 180.0 }),
        (
            "equirectangular",
            ProjectionSpec::Equirectangular {
                frame,
                h_fov: 360.0,
                v_fov: 180.0,
            },
        ),
        (
            "cylindrical",
            ProjectionSpec::Cylindrical {
                frame,
                h_fov: 360.0,
                v_fov: 120.0,
            },
        ),
        (
            "flex perspective",
            flexible(Preset::Perspective { fov }, frame),
        ),
        (
            "flex inverse persp.",
            flexible(
                Preset::InversePerspective {
                    fov: 40.0,
                    converge: frame.look_at,
                },
                frame,
            ),
        ),
        (
            "flex oblique",
            flexible(
                Preset::Oblique {
                    width: 9.0,
                    shear: DVec2::new(0.2, 0.1),
                },
                frame,
            ),
        ),
        (
            "flex pushbroom",
            flexible(
                Preset::Pushbroom {
                    width: 9.0,
                    v_fov: 60.0,
                },
                frame,
            ),
        ),
        (
            "flex crossed slits",
            flexible(
                Preset::CrossedSlits {
                    fov: fov + 10.0,
                    v_fov: None,
                    slit_distance: -2.0,
                },
                frame,
            ),
        ),
        (
            "flex cylindrical",
            flexible(
                Preset::Cylindrical {
                    h_fov: 360.0,
                    v_fov: 120.0,
                },
                frame,
            ),
        ),
        (
            "flex equirectangular",
            flexible(
                Preset::Equirectangular {
                    h_fov: 360.0,
                    v_fov: 180.0,
                },
                frame,
            ),
        ),
        (
            "flex fisheye 220",
            flexible(Preset::Fisheye { fov: 220.0 }, frame),
        ),
    ]
}

fn scene_camera(scene: &Scene) -> (CameraFrame, f64) {
    match &scene.projection {
        ProjectionSpec::Perspective { frame, fov } => (*frame, *fov),
        other => panic!(
            "built-in scenes use perspective cameras, got {}",
            other.kind()
        ),
    }
}

fn render(
    method: Method,
    scene: &Scene,
    spec: &ProjectionSpec,
    size: (u32, u32),
    options: &RenderOptions,
) -> Frame {
    let projection = spec.build(size.0, size.1).unwrap();
    method
        .render(&PreparedScene::new(scene), projection.as_ref(), options)
        .unwrap_or_else(|e| panic!("{}: {e}", spec.kind()))
        .0
}

#[test]
fn projections_without_a_chart_are_refused_in_one_line() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let trilinear = ProjectionSpec::Trilinear(TrilinearMesh {
        points: vec![DVec3::ZERO; 3],
        normals: vec![DVec3::NEG_Z; 3],
        screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
        triangles: vec![[0, 1, 2]],
    });
    let (frame, _) = scene_camera(&scene);
    // Crossed slits with the horizontal slit between the near and far surfaces.
    let inside_slit = flexible(
        Preset::CrossedSlits {
            fov: 60.0,
            v_fov: None,
            slit_distance: 2.0,
        },
        frame,
    );
    for spec in [trilinear, inside_slit] {
        let projection = spec.build(16, 16).unwrap();
        let e = Method::Raster
            .render(
                &PreparedScene::new(&scene),
                projection.as_ref(),
                &flat(Subdivision::default()),
            )
            .unwrap_err();
        assert!(
            e.message.starts_with("method raster needs a projection"),
            "{e}"
        );
        assert!(e.message.contains(spec.kind()) && e.message.contains("--method raycast"));
        assert!(!e.message.contains('\n'));
    }
    let twisted = ProjectionSpec::Flexible(Box::new(FlexibleSpec {
        source: VolumeSource::Surfaces {
            near: crate::projection::flexible::Surface::Point(DVec3::ZERO),
            far: crate::projection::flexible::Surface::Bilinear {
                corners: [
                    DVec3::new(-1.0, -1.0, -1.0),
                    DVec3::new(1.0, -1.0, -2.0),
                    DVec3::new(1.0, 1.0, -1.0),
                    DVec3::new(-1.0, 1.0, -2.0),
                ],
            },
        },
        reparam: None,
    }));
    let projection = twisted.build(8, 8).unwrap();
    assert!(projection.inverse().is_err());
    let e = InverseRaster::new(
        &PreparedScene::new(&scene),
        projection.as_ref(),
        &flat(Subdivision::default()),
    )
    .err()
    .unwrap();
    assert_eq!(
        e.message,
        "method raster needs a projection with an analytic inverse; flexible has none: its \
         near and far control surfaces are outside the scanline class (planes sharing a \
         normal, a plane and a long scene's warped plane, nested spheres or coaxial \
         cylinders) (use --method raycast)"
    );
}

/// Renderers of one prepared scene hand their z-buffer, bins and projector tiles on
/// ([`PreparedScene::keep_spare`]), and every other frame is drawn into the frame before it
/// ([`recycle_frame`]: the last one's pixels, of another size, and without depth and ids
/// half of the time): each frame of a sequence through every invertible projection, at
/// two sizes, lit and flat, is the frame a fresh prepared scene renders.
#[test]
fn frames_reusing_an_earlier_renderers_memory_are_fresh_frames() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let (frame, fov) = scene_camera(&scene);
    let prepared = PreparedScene::new(&scene);
    for (k, (name, spec)) in invertible(frame, fov).into_iter().enumerate() {
        let size = if k % 2 == 0 { (48, 32) } else { (40, 44) };
        let shading = if k % 3 == 0 {
            Shading::Lit
        } else {
            Shading::Flat
        };
        let options = RenderOptions {
            shading,
            ..flat(Subdivision::default())
        };
        let projection = spec.build(size.0, size.1).unwrap();
        let reused = Method::Raster
            .render(&prepared, projection.as_ref(), &options)
            .unwrap()
            .0;
        assert_eq!(
            reused,
            render(Method::Raster, &scene, &spec, size, &options),
            "{name}"
        );
        if k % 4 < 2 {
            let mut spent = reused;
            if k % 4 == 1 {
                (spent.depth, spent.ids) = (Vec::new(), Vec::new());
            }
            recycle_frame(&prepared, spent);
        }
    }
}

#[test]
fn bad_options_are_refused() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let projection = scene.projection.build(8, 8).unwrap();
    let four = RenderOptions {
        spp: 4,
        ..flat(Subdivision::default())
    };
    let e = InverseRaster::new(&PreparedScene::new(&scene), projection.as_ref(), &four)
        .err()
        .unwrap();
    assert!(e.message.contains("one sample per pixel"), "{e}");
    let bad = flat(Subdivision::uniform(0));
    assert!(InverseRaster::new(&PreparedScene::new(&scene), projection.as_ref(), &bad).is_err());
}

/// A closed box around the eye, finely enough tessellated that its triangles share edges
/// everywhere: every pixel with a projector must see it. Seam, poles, clipping and adaptive
/// splits that differ from triangle to triangle would all show as background pixels.
#[test]
fn a_closed_box_around_the_eye_covers_every_pixel() {
    let text = r#"
        [projection]
        type = "perspective"
        position = [0.3, 0.2, 0.1]
        look_at = [0.0, 0.0, -1.0]
        fov = 60.0
        [[object]]
        shape = "box"
        size = [4.0, 3.0, 5.0]
        tessellation = 5
        rotate = [10.0, 20.0, 5.0]
    "#;
    let scene = file::parse(text, Path::new("box.toml")).unwrap();
    let (frame, fov) = scene_camera(&scene);
    for subdivision in [
        Subdivision::default(),
        Subdivision::uniform(1),
        Subdivision::uniform(3),
    ] {
        let options = flat(subdivision);
        for (name, spec) in invertible(frame, fov) {
            let reference = render(Method::Raycast, &scene, &spec, (96, 64), &options);
            let raster = render(Method::Raster, &scene, &spec, (96, 64), &options);
            // The inverse perspective's projectors end at look_at, inside the box.
            let sees = reference.ids.iter().any(|&id| id != 0);
            assert_eq!(sees, !name.contains("inverse"), "{name}");
            let holes = (0..reference.ids.len())
                .filter(|&i| reference.ids[i] != 0 && raster.ids[i] == 0)
                .count();
            if holes > 0 {
                let at: Vec<(usize, usize, f32)> = (0..reference.ids.len())
                    .filter(|&i| reference.ids[i] != 0 && raster.ids[i] == 0)
                    .map(|i| (i % 96, i / 96, reference.depth[i]))
                    .collect();
                eprintln!("{name}: {at:?}");
            }
            assert_eq!(holes, 0, "{name} with {subdivision:?}");
            let extra = (0..reference.ids.len())
                .filter(|&i| reference.ids[i] == 0 && raster.ids[i] != 0)
                .count();
            assert_eq!(extra, 0, "{name} with {subdivision:?}");
        }
    }
}

/// The agreement of the raster render with subdivision `s` with the reference.
fn measure(scene: &Scene, spec: &ProjectionSpec, reference: &Frame, s: Subdivision) -> Comparison {
    let size = (reference.width, reference.height);
    let raster = render(Method::Raster, scene, spec, size, &flat(s));
    compare(&raster, reference).unwrap()
}

/// Figure 7.9 with numbers: id disagreement and relative RGB error per subdivision level for
/// every invertible projection on two built-in scenes. Errors fall with subdivision, and the
/// adaptive default reaches the 99.5 % id agreement target.
#[test]
fn raster_converges_to_the_ray_caster() {
    let levels = [
        ("1", Subdivision::uniform(1)),
        ("2", Subdivision::uniform(2)),
        ("4", Subdivision::uniform(4)),
        ("8", Subdivision::uniform(8)),
        ("adaptive", Subdivision::default()),
    ];
    let size = (320, 240);
    for name in ["cube-floor", "teapot-room"] {
        let scene = scene::load(&format!("builtin:{name}")).unwrap();
        let (frame, fov) = scene_camera(&scene);
        for (label, spec) in invertible(frame, fov) {
            let reference = render(Method::Raycast, &scene, &spec, size, &flat(levels[0].1));
            let rows: Vec<Comparison> = levels
                .iter()
                .map(|(_, s)| measure(&scene, &spec, &reference, *s))
                .collect();
            let line: Vec<String> = rows
                .iter()
                .map(|c| {
                    format!(
                        "{:.3}% / {:.4}",
                        100.0 * (1.0 - c.id_agreement),
                        c.relative_rgb_error
                    )
                })
                .collect();
            eprintln!("| {name} | {label} | {} |", line.join(" | "));
            let error = |c: &Comparison| 1.0 - c.id_agreement;
            assert!(
                error(&rows[3]) <= error(&rows[0]),
                "{name} {label}: uniform 8 worse than 1"
            );
            assert!(
                rows[3].relative_rgb_error <= rows[0].relative_rgb_error,
                "{name} {label}: uniform 8 worse than 1 in colour"
            );
            assert!(
                rows[4].id_agreement >= 0.995,
                "{name} {label}: adaptive agreement {}",
                rows[4].id_agreement
            );
            // Depth is reconstructed per pixel: where the ids agree it is the ray caster's
            // but for silhouettes within one object (another triangle of it).
            assert!(
                rows[4].depth_mean < 1e-4,
                "{name} {label}: {}",
                rows[4].depth_mean
            );
        }
    }
}

/// The count of `name` in `stats` (0 when absent).
fn count(stats: &Stats, name: &str) -> u64 {
    match stats.get(name) {
        Some(Counter::Count(n)) => *n,
        _ => 0,
    }
}

/// Lit shading is delegated per visible pixel to the ray caster, whose shadow rays are
/// counted in the stats like the ray caster's own; flat shading of diffuse surfaces casts
/// none.
#[test]
fn delegated_shading_rays_are_counted() {
    let scene = scene::load("builtin:cube-floor").unwrap();
    let projection = scene.projection.build(64, 48).unwrap();
    let options = |shading| RenderOptions {
        shading,
        ..RenderOptions::default()
    };
    let (_, lit) = Method::Raster
        .render(
            &PreparedScene::new(&scene),
            projection.as_ref(),
            &options(Shading::Lit),
        )
        .unwrap();
    let (_, cast) = Method::Raycast
        .render(
            &PreparedScene::new(&scene),
            projection.as_ref(),
            &options(Shading::Lit),
        )
        .unwrap();
    let reference = count(&cast, "secondary_rays") + count(&cast, "shadow_rays");
    let rays = count(&lit, "shading_rays");
    assert!(reference > 0);
    // The same visible hits but at a few silhouette pixels: the same rays within 2 %.
    assert!(
        rays.abs_diff(reference) * 50 <= reference,
        "raster {rays}, raycast {reference}"
    );
    let (_, flat) = Method::Raster
        .render(
            &PreparedScene::new(&scene),
            projection.as_ref(),
            &options(Shading::Flat),
        )
        .unwrap();
    assert_eq!(flat.get("shading_rays"), Some(&Counter::Count(0)));
}
/// The shape-defined panoramas (lookup-table inverse): the example scenes (the rounded
/// cubic preset, blended profiles, the rounded cubic preset edited across the seam) and the
/// cubic and rounded cubic presets on a built-in scene reach the 99.5 % id agreement target
/// with adaptive subdivision, and errors fall with uniform subdivision.
#[test]
fn panoramas_by_lookup_converge_to_the_ray_caster() {
    let example = |name: &str| {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/");
        scene::load(&format!("{dir}{name}")).unwrap()
    };
    let example_scene = example("flexible-panorama-cubic.toml");
    let custom = example("flexible-panorama-custom.toml");
    let edited = example("flexible-panorama-cubic-edit.toml");
    let teapot = scene::load("builtin:teapot-room").unwrap();
    let (frame, _) = scene_camera(&teapot);
    let cases = [
        (
            "example",
            &example_scene,
            example_scene.projection.clone(),
            (320, 120),
        ),
        (
            "custom example",
            &custom,
            custom.projection.clone(),
            (320, 160),
        ),
        (
            "edited across the seam",
            &edited,
            edited.projection.clone(),
            (320, 120),
        ),
        (
            "cubic",
            &teapot,
            flexible(Preset::Cubic { v_fov: 100.0 }, frame),
            (320, 120),
        ),
        (
            "rounded cubic",
            &teapot,
            flexible(
                Preset::RoundedCubic {
                    v_fov: 90.0,
                    corner_radius: 0.5,
                },
                frame,
            ),
            (320, 120),
        ),
    ];
    for (name, scene, spec, size) in cases {
        let reference = render(
            Method::Raycast,
            scene,
            &spec,
            size,
            &flat(Subdivision::uniform(1)),
        );
        let one = measure(scene, &spec, &reference, Subdivision::uniform(1));
        let eight = measure(scene, &spec, &reference, Subdivision::uniform(8));
        let adaptive = measure(scene, &spec, &reference, Subdivision::default());
        eprintln!(
            "| {name} | {:.3}% | {:.3}% | {:.3}% |",
            100.0 * (1.0 - one.id_agreement),
            100.0 * (1.0 - eight.id_agreement),
            100.0 * (1.0 - adaptive.id_agreement)
        );
        assert!(eight.id_agreement >= one.id_agreement, "{name}");
        assert!(
            adaptive.id_agreement >= 0.995,
            "{name}: adaptive agreement {}",
            adaptive.id_agreement
        );
    }
}
