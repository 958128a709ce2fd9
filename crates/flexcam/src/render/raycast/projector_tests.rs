//! Ray casting along curved projectors (flexible volumes blended in t), checked against
//! straight projectors and against each other with `render::compare`.

use glam::{DVec2, DVec3};

use super::shade::Tracer;
use crate::projection::flexible::{Blend, Flexible, FlexibleSpec, Surface, VolumeSource};
use crate::projection::Projection;
use crate::render::compare::{compare, Comparison};
use crate::render::prepared::PreparedScene;
use crate::render::{raycast, Frame, RenderOptions, Shading};
use crate::scene::builtin;

const W: u32 = 96;
const H: u32 = 72;

/// A rectangle facing -z centred at `c`, half extents 4:3.
fn rect(c: DVec3, half_width: f64) -> Surface {
    Surface::rectangle_centred(c, DVec3::X * half_width, DVec3::Y * half_width * 0.75)
}

fn near() -> Surface {
    rect(DVec3::new(0.0, 2.6, 6.0), 0.2)
}

fn far() -> Surface {
    rect(DVec3::new(0.0, 0.2, -5.0), 5.5)
}

/// A middle surface that bends the projectors sideways and up.
fn bent() -> Surface {
    rect(DVec3::new(2.0, 2.8, 0.5), 3.0)
}

/// The surface halfway between `near` and `far` (rectangles are linear in centre and size).
fn halfway() -> Surface {
    rect(DVec3::new(0.0, 1.4, 0.5), 2.85)
}

fn render(source: VolumeSource, shading: Shading) -> Frame {
    let spec = FlexibleSpec {
        source,
        reparam: None,
    };
    let projection = Flexible::new(&spec, W, H).unwrap();
    let scene = builtin::load("teapot-room").unwrap();
    let options = RenderOptions {
        shading,
        ..RenderOptions::default()
    };
    raycast::render(&PreparedScene::new(&scene), &projection, &options)
        .unwrap()
        .0
}

fn straight(shading: Shading) -> Frame {
    render(
        VolumeSource::Surfaces {
            near: near(),
            far: far(),
        },
        shading,
    )
}

fn blended(surfaces: Vec<Surface>, blend: Blend, shading: Shading) -> Frame {
    render(VolumeSource::Blended { surfaces, blend }, shading)
}

fn assert_same(c: Comparison, what: &str) {
    // Edge pixels may differ: the straight search is f32 Moller-Trumbore, the curved one
    // f64 plane roots; a few pixels out of 6912 graze an edge.
    assert!(c.id_agreement >= 0.998, "{what}: {c:?}");
    assert!(c.depth_max < 1e-4, "{what}: {c:?}");
    assert!(c.relative_rgb_error < 0.01, "{what}: {c:?}");
}

#[test]
fn a_quadratic_with_collinear_control_points_renders_as_the_straight_projector() {
    for shading in [Shading::Flat, Shading::Lit] {
        let reference = straight(shading);
        let quadratic = blended(
            vec![near(), halfway(), far()],
            Blend::Bezier { segments: None },
            shading,
        );
        assert!(reference.ids.iter().any(|&id| id != 0));
        assert_same(compare(&quadratic, &reference).unwrap(), "quadratic");
    }
}

#[test]
fn polylines_through_collinear_or_repeated_surfaces_render_as_the_straight_projector() {
    let reference = straight(Shading::Lit);
    let polyline = blended(
        vec![near(), halfway(), far()],
        Blend::Piecewise { knots: None },
        Shading::Lit,
    );
    assert_same(compare(&polyline, &reference).unwrap(), "polyline");
    // A zero-length first segment (two equal surfaces) sees nothing and changes nothing.
    let repeated = blended(
        vec![near(), near(), far()],
        Blend::Piecewise {
            knots: Some(vec![0.0, 0.3, 1.0]),
        },
        Shading::Lit,
    );
    assert_same(
        compare(&repeated, &reference).unwrap(),
        "zero-length segment",
    );
}

#[test]
fn polylines_converge_to_the_quadratic_as_segments_grow() {
    let surfaces = vec![near(), bent(), far()];
    let analytic = blended(
        surfaces.clone(),
        Blend::Bezier { segments: None },
        Shading::Lit,
    );
    // The bend is visible: the curved image differs from the straight one.
    let straight_vs_curved = compare(&straight(Shading::Lit), &analytic).unwrap();
    assert!(
        straight_vs_curved.id_agreement < 0.9,
        "{straight_vs_curved:?}"
    );
    let errors: Vec<Comparison> = [2, 4, 8, 16, 64]
        .into_iter()
        .map(|n| {
            let polyline = blended(
                surfaces.clone(),
                Blend::Bezier { segments: Some(n) },
                Shading::Lit,
            );
            compare(&polyline, &analytic).unwrap()
        })
        .collect();
    for pair in errors.windows(2) {
        assert!(
            pair[1].relative_rgb_error < pair[0].relative_rgb_error
                && pair[1].depth_mean < pair[0].depth_mean,
            "{errors:#?}"
        );
    }
    let last = errors[errors.len() - 1];
    assert!(
        last.id_agreement > 0.995 && last.depth_mean < 1e-3,
        "{last:?}"
    );
}

/// A 2x2 quad of polyline projectors shares one BVH traversal per segment, with exactly the
/// samples (colour, depth, id) and ray counts of tracing each projector alone, lit and flat;
/// quads with a pixel outside the volume's image mix polylines and absent projectors.
#[test]
fn polyline_quads_sample_exactly_like_single_projectors() {
    let spec = FlexibleSpec {
        source: VolumeSource::Blended {
            surfaces: vec![near(), bent(), far()],
            blend: Blend::Bezier { segments: Some(3) },
        },
        reparam: None,
    };
    let projection = Flexible::new(&spec, W, H).unwrap();
    let scene = builtin::load("teapot-room").unwrap();
    let caster = PreparedScene::new(&scene);
    for shading in [Shading::Flat, Shading::Lit] {
        let options = RenderOptions {
            shading,
            ..RenderOptions::default()
        };
        let (mut quad, mut single) = (
            Tracer::new(&caster, &options),
            Tracer::new(&caster, &options),
        );
        for y in (0..H).step_by(2) {
            for x in (0..W).step_by(2) {
                let projectors = [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)]
                    .map(|(x, y)| projection.projector(DVec2::new(x as f64, y as f64) + 0.5));
                let together = quad.sample4_projectors(&projectors);
                let alone = projectors
                    .each_ref()
                    .map(|p| single.sample_projector(p.as_ref()));
                assert_eq!(together, alone, "quad at ({x}, {y}), {shading:?}");
            }
        }
        assert_eq!(quad.shader.counts, single.shader.counts);
        assert!(quad.shader.counts.primary > 0);
    }
}

/// Segments of polyline projectors that pass in front of or behind a small model are culled
/// by the scene's box before any traversal ([`PreparedScene::misses_scene_box`]): on the layout
/// of `flexcam bench flexible` (a teapot inside a bent perspective-to-perspective volume,
/// six segments) most segments are culled, and every segment, culled or not, finds exactly
/// the hit of an unculled BVH search; the rendered image is that of tracing each projector
/// alone.
#[test]
fn segments_outside_the_scene_box_are_culled_without_changing_any_hit() {
    let (scene, _) = super::workloads::teapot_scene(240);
    let caster = PreparedScene::new(&scene);
    let (w, h) = (48, 48);
    let projection = super::workloads::table_volume(&scene, Some(6), w).unwrap();
    let (mut culled, mut hits, mut segments) = (0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let pixel = DVec2::new(x as f64, y as f64) + 0.5;
            let Some(crate::projection::Projector::Polyline(points)) = projection.projector(pixel)
            else {
                panic!("pixel ({x}, {y}) has no polyline projector");
            };
            for pair in points.windows(2) {
                let ray = crate::geometry::Ray {
                    origin: pair[0],
                    direction: pair[1] - pair[0],
                    t_min: 0.0,
                    t_max: 1.0,
                };
                let uncull = crate::render::bvh::triangle::FastRay::new(&ray)
                    .and_then(|fast| caster.bvh.closest(&fast, &crate::render::bvh::AllTriangles))
                    .map(|found| caster.hit32(found));
                assert_eq!(caster.intersect_f32(&ray), uncull, "pixel ({x}, {y})");
                segments += 1;
                if caster.misses_scene_box(&ray) {
                    culled += 1;
                    assert_eq!(uncull, None);
                }
                hits += usize::from(uncull.is_some());
            }
        }
    }
    assert!(
        hits > 0 && 2 * culled > segments,
        "{culled} of {segments}, {hits} hits"
    );
    // The quads of the renderer against each projector alone.
    let options = RenderOptions {
        shading: Shading::Lit,
        ..RenderOptions::default()
    };
    let frame = raycast::render(&caster, &projection, &options).unwrap().0;
    let mut tracer = Tracer::new(&caster, &options);
    for y in 0..h {
        for x in 0..w {
            let projector = projection.projector(DVec2::new(x as f64, y as f64) + 0.5);
            let alone = tracer.sample_projector(projector.as_ref());
            let i = (y * w + x) as usize;
            assert_eq!(
                (frame.color[i], frame.depth[i], frame.ids[i]),
                (alone.color, alone.depth, alone.id)
            );
        }
    }
}

/// A 5 x 5 projector grid sampled from a perspective camera looking into the teapot room, with
/// `tangents(start, end)` giving each node's tangent (all nodes set explicitly).
fn grid_frame(tangents: impl Fn(DVec3, DVec3) -> Option<DVec3>) -> Frame {
    use crate::projection::flexible::presets::{Preset, PresetSpec};
    use crate::projection::flexible::{
        GridInterpolation, NodeProjector, ProjectorGrid, ProjectorGridSpec, Volume,
    };
    use crate::projection::CameraFrame;
    let base = FlexibleSpec {
        source: VolumeSource::Preset(PresetSpec {
            preset: Preset::Perspective { fov: 70.0 },
            frame: CameraFrame {
                position: DVec3::new(0.0, 2.6, 6.0),
                look_at: DVec3::new(0.0, 0.5, 0.0),
                up: DVec3::Y,
            },
            clip: Some([0.5, 30.0]),
        }),
        reparam: None,
    };
    let Volume::Linear(sampled) = Flexible::new(&base, W, H).unwrap().volume().clone() else {
        panic!("a perspective preset has straight projectors");
    };
    let sample = ProjectorGrid::sample(&sampled, (5, 5), GridInterpolation::Bilinear).unwrap();
    let projectors = sample
        .starts()
        .iter()
        .zip(sample.ends())
        .enumerate()
        .map(|(j, (&start, &end))| NodeProjector {
            node: (j % 5, j / 5),
            start: None,
            end: None,
            tangent: tangents(start, end),
            through: None,
        })
        .collect();
    render(
        VolumeSource::ProjectorGrid {
            base: Box::new(base),
            grid: ProjectorGridSpec {
                size: (5, 5),
                interpolation: GridInterpolation::Bilinear,
                projectors,
                aims: Vec::new(),
                correspondences: Vec::new(),
                starts: Default::default(),
            },
        },
        Shading::Flat,
    )
}

#[test]
fn grid_tangents_along_the_chords_give_the_straight_grid_image_and_others_bend_it() {
    let straight = grid_frame(|_, _| None);
    assert!(straight.ids.iter().any(|&id| id != 0));
    let along = grid_frame(|start, end| Some(2.5 * (end - start)));
    assert_eq!(along.ids, straight.ids);
    assert_eq!(along.color, straight.color);
    // Tangents a hair off the chords: every projector is a quadratic (the curve caster), still
    // the same picture up to edge pixels.
    let nearly = grid_frame(|start, end| {
        let chord = end - start;
        Some(chord + 1e-7 * chord.length() * chord.any_orthonormal_vector())
    });
    assert_same(compare(&nearly, &straight).unwrap(), "nearly straight grid");
    // Tangents turned 20 degrees to the left bend the whole image.
    let turned = grid_frame(|start, end| {
        let chord = end - start;
        Some(chord.normalize() + 0.36 * DVec3::X)
    });
    let bent = compare(&turned, &straight).unwrap();
    assert!(bent.id_agreement < 0.9, "{bent:?}");
}
