//! Panorama rasterisation throughput (`--method raster`) against the ray caster in the same
//! run, on the workload of `render::bench_support::workloads::raster` (`teapot-dense`, 123,554
//! triangles, as a 1280 x 720 equirectangular panorama), flat shading. Throughput is frames
//! per second. `raster_first_frame` is a new renderer and its first frame (the pixel
//! projectors it needs are computed during the frame); `raster_frame` is a later frame of
//! the same renderer into the same frame buffers (projectors and buffers kept, as the BVH is
//! built once per scene); `raycast_frame` is one ray-cast frame with the BVH prebuilt.
//! `flexcam bench flexible --part panorama` prints the same measurements as a table.
//!
//! Run with `cargo bench -p flexcam --bench raster`. Figures are recorded in docs/raster.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use flexcam::render::bench_support::workloads::raster::{teapot_dense_panorama, PanoramaWorkload};
use flexcam::render::bench_support::InverseRaster;
use flexcam::render::{self, PreparedScene, RenderOptions, Shading};

fn panorama(c: &mut Criterion) {
    let PanoramaWorkload { scene, projection } =
        teapot_dense_panorama().unwrap_or_else(|e| panic!("panorama workload: {e}"));
    let options = RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let mut group = c.benchmark_group("panorama_teapot-dense_1280x720");
    group.sample_size(10);
    group.throughput(Throughput::Elements(1));
    // The scene is prepared once for every renderer of the group.
    let prepared = PreparedScene::new(&scene);
    let raster = InverseRaster::new(&prepared, projection.as_ref(), &options)
        .unwrap_or_else(|e| panic!("raster: {e}"));
    let mut frame = raster.render().unwrap().0;
    group.bench_function("raster_frame", |b| {
        b.iter(|| raster.render_into(&mut frame))
    });
    group.bench_function("raster_first_frame", |b| {
        b.iter(|| {
            InverseRaster::new(&prepared, projection.as_ref(), &options)
                .and_then(|fresh| fresh.render())
        })
    });
    group.bench_function("raycast_frame", |b| {
        b.iter(|| render::render(&prepared, projection.as_ref(), &options))
    });
    group.finish();
}

criterion_group!(benches, panorama);
criterion_main!(benches);
