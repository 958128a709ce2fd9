//! The projection stage of `--method trilinear` alone (`render::bench_support::project_all`:
//! volume cull, cubics, shapes, outlines, clipping), without rasterisation
//! or shading: the cube-floor scene through the 18-projection fan grid at 800 x 800 with and
//! without scene-space clipping (the bench's cube rows), and the detail-in-context
//! visualisation surface of `scenes/trilinear-detail-in-context.toml` (686 scene triangles
//! through 512 small projection triangles at 320 x 240).
//!
//! Run with `cargo bench -p flexcam --bench trilinear_projection`; with
//! `RAYON_NUM_THREADS=1` and `-- --profile-time 10` it is also a driver for `perf record`.
//! Figures are recorded in docs/trilinear.md ("Projection stage and hierarchical culling").

use criterion::{criterion_group, criterion_main, Criterion};
use flexcam::projection::Trilinear;
use flexcam::render::bench_support::workloads::trilinear::fan_grid;
use flexcam::render::bench_support::{project_all, projection_triangles, SceneGeometry};
use flexcam::render::CurveOptions;
use flexcam::scene::{self, builtin, Scene};

/// Times `project_all` of `scene` through `projection` with `curves` as `name`.
fn bench_stage(
    c: &mut Criterion,
    name: &str,
    scene: &Scene,
    projection: &Trilinear,
    curves: CurveOptions,
) {
    let geometry = SceneGeometry::new(scene);
    let triangles = projection_triangles(projection);
    c.bench_function(name, |b| {
        b.iter(|| project_all(&triangles, &geometry, curves))
    });
}

fn projection_stage(c: &mut Criterion) {
    let cube = builtin::load("cube-floor").unwrap_or_else(|e| panic!("cube-floor: {e}"));
    let fan = fan_grid(3).unwrap_or_else(|e| panic!("fan grid: {e}"));
    let fan = Trilinear::new(&fan, 800, 800).unwrap_or_else(|e| panic!("projection: {e}"));
    let unclipped = CurveOptions {
        scene_clipping: false,
        ..CurveOptions::ADAPTIVE
    };
    bench_stage(
        c,
        "project_cube_18_clipped",
        &cube,
        &fan,
        CurveOptions::ADAPTIVE,
    );
    bench_stage(c, "project_cube_18_unclipped", &cube, &fan, unclipped);

    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/trilinear-detail-in-context.toml"
    );
    let detail = scene::load(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let (width, height) = (detail.image.width, detail.image.height);
    let built = detail
        .projection
        .build(width, height)
        .unwrap_or_else(|e| panic!("{path}: {e}"));
    let surface = built
        .trilinear()
        .unwrap_or_else(|| panic!("{path}: not a trilinear projection"));
    bench_stage(
        c,
        "project_detail_in_context",
        &detail,
        surface,
        CurveOptions::ADAPTIVE,
    );
}

criterion_group!(benches, projection_stage);
criterion_main!(benches);
