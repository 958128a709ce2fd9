//! Panorama rasterisation throughput (`--method raster`) against the ray caster in the same
//! run: `teapot-dense` (123,554 triangles) as a 1280 x 720 equirectangular (360 x 180)
//! panorama from the scene's own camera position, flat shading. Throughput is frames per
//! second. `raster_first_frame` is a new renderer and its first frame (the pixel projectors
//! it needs are computed during the frame); `raster_frame` is a later frame of the same
//! renderer (projectors kept, as the BVH is built once per scene); `raycast_frame` is one
//! ray-cast frame with the BVH prebuilt. `flexcam bench flexible --part panorama` prints the
//! same measurements as a table.
//!
//! Run with `cargo bench -p flexcam --bench raster`. Figures are recorded in docs/raster.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use flexcam::projection::ProjectionSpec;
use flexcam::render::inverse_raster::InverseRaster;
use flexcam::render::raycast::RayCaster;
use flexcam::render::{RenderOptions, Shading};
use flexcam::scene::builtin;

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;

fn panorama(c: &mut Criterion) {
    let scene = builtin::load("teapot-dense").unwrap_or_else(|e| panic!("teapot-dense: {e}"));
    let frame = match &scene.projection {
        ProjectionSpec::Perspective { frame, .. } => *frame,
        other => panic!(
            "teapot-dense should have a perspective camera, not {}",
            other.kind()
        ),
    };
    let spec = ProjectionSpec::Equirectangular {
        frame,
        h_fov: 360.0,
        v_fov: 180.0,
    };
    let projection = spec
        .build(WIDTH, HEIGHT)
        .unwrap_or_else(|e| panic!("equirectangular: {e}"));
    let options = RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let mut group = c.benchmark_group("panorama_teapot-dense_1280x720");
    group.sample_size(10);
    group.throughput(Throughput::Elements(1));
    let raster = InverseRaster::new(&scene, projection.as_ref(), &options)
        .unwrap_or_else(|e| panic!("raster: {e}"));
    group.bench_function("raster_frame", |b| b.iter(|| raster.render()));
    group.bench_function("raster_first_frame", |b| {
        b.iter(|| {
            InverseRaster::new(&scene, projection.as_ref(), &options).map(|fresh| fresh.render())
        })
    });
    let caster = RayCaster::new(&scene);
    group.bench_function("raycast_frame", |b| {
        b.iter(|| caster.render(projection.as_ref(), &options))
    });
    group.finish();
}

criterion_group!(benches, panorama);
criterion_main!(benches);
