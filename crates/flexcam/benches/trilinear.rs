//! Trilinear rasterisation (`--method trilinear`) against the ray caster of the same
//! projection: the cube-floor scene (686 triangles) through the 18-projection fan grid
//! (`render::bench_support::workloads::trilinear::fan_grid(3)`) at 800 x 800, flat shading: the trilinear
//! renderer's speed target (at least 10x the ray caster, under 33 ms). Both renderers are prepared once
//! (BVH, scene geometry); each iteration is one frame. `trilinear_frame` uses the default
//! adaptive curves with scene-space clipping, `trilinear_unclipped` the thesis's cheaper
//! screen-space clipping only, `trilinear_kept_unclipped` the same into a frame kept from
//! iteration to iteration (`TrilinearRenderer::render_into`, a program's later frames);
//! `raycast_frame` (the entry point, `render::render`) and `raycast_kept` the ray caster into
//! a new frame and into a kept one (`bench_support::raycast_into`).
//!
//! Run with `cargo bench -p flexcam --bench trilinear`. Figures are recorded in
//! docs/trilinear.md (with `flexcam bench trilinear`, which prints the thesis's tables).

use criterion::{criterion_group, criterion_main, Criterion};
use flexcam::projection::Trilinear;
use flexcam::render::bench_support::workloads::trilinear::fan_grid;
use flexcam::render::bench_support::{raycast_into, TrilinearRenderer};
use flexcam::render::{self, CurveOptions, PreparedScene, RenderOptions, Shading};
use flexcam::scene::builtin;

const SIDE: u32 = 800;

fn cube_floor_18(c: &mut Criterion) {
    let scene = builtin::load("cube-floor").unwrap_or_else(|e| panic!("cube-floor: {e}"));
    let mesh = fan_grid(3).unwrap_or_else(|e| panic!("fan grid: {e}"));
    let projection =
        Trilinear::new(&mesh, SIDE, SIDE).unwrap_or_else(|e| panic!("projection: {e}"));
    let options = RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let mut group = c.benchmark_group("trilinear_cube-floor_18_800x800");
    group.sample_size(10);
    // The scene is prepared once for both renderers.
    let caster = PreparedScene::new(&scene);
    let renderer = TrilinearRenderer::new(&caster);
    let unclipped = CurveOptions {
        scene_clipping: false,
        ..CurveOptions::ADAPTIVE
    };
    for (name, curves) in [
        ("trilinear_frame", CurveOptions::ADAPTIVE),
        ("trilinear_unclipped", unclipped),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| renderer.render(&projection, &options, curves))
        });
    }
    // Later frames of a program drawing frame after frame into one frame it keeps.
    let mut kept = renderer
        .render(&projection, &options, unclipped)
        .unwrap_or_else(|e| panic!("render: {e}"))
        .0;
    group.bench_function("trilinear_kept_unclipped", |b| {
        b.iter(|| renderer.render_into(&mut kept, &projection, &options, unclipped))
    });
    group.bench_function("raycast_frame", |b| {
        b.iter(|| render::render(&caster, &projection, &options))
    });
    // The ray caster's later frames into a frame it keeps: like for like with
    // `trilinear_kept_unclipped`.
    let mut kept = render::render(&caster, &projection, &options)
        .unwrap_or_else(|e| panic!("render: {e}"))
        .frame;
    group.bench_function("raycast_kept", |b| {
        b.iter(|| raycast_into(&caster, &mut kept, &projection, &options))
    });
    group.finish();
}

criterion_group!(benches, cube_floor_18);
criterion_main!(benches);
