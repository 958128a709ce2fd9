//! Ray-casting throughput: primary rays per second with flat shading at 800x800 on the
//! built-in scenes (`teapot-dense` has over 100,000 triangles), each through a perspective
//! and a 180-degree fisheye projection from the scene's own camera; and the BVH build time.
//!
//! Run with `cargo bench -p flexcam --bench raycast`. Figures are recorded in docs/raycast.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use flexcam::projection::{CameraFrame, ProjectionSpec};
use flexcam::render::{self, PreparedScene, RenderOptions, Shading};
use flexcam::scene::{builtin, Scene};

const SIZE: u32 = 800;
const SCENES: [&str; 3] = ["cube-floor", "teapot-room", "teapot-dense"];

/// The scene's own camera placement and, if it has one, horizontal field of view.
fn camera(scene: &Scene) -> (CameraFrame, f64) {
    match &scene.projection {
        ProjectionSpec::Perspective { frame, fov } => (*frame, *fov),
        ProjectionSpec::Orthographic { frame, .. }
        | ProjectionSpec::Fisheye { frame, .. }
        | ProjectionSpec::Equirectangular { frame, .. }
        | ProjectionSpec::Cylindrical { frame, .. } => (*frame, 60.0),
        other => panic!("benchmark scenes need a camera frame, got {}", other.kind()),
    }
}

fn load(name: &str) -> Scene {
    builtin::load(name).unwrap_or_else(|e| panic!("built-in scene {name}: {e}"))
}

fn primary_rays(c: &mut Criterion) {
    let options = RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let mut group = c.benchmark_group("raycast_flat_800x800");
    group.sample_size(10);
    group.throughput(Throughput::Elements(u64::from(SIZE * SIZE)));
    for name in SCENES {
        let scene = load(name);
        let caster = PreparedScene::new(&scene);
        let (frame, fov) = camera(&scene);
        let specs = [
            ("perspective", ProjectionSpec::Perspective { frame, fov }),
            ("fisheye", ProjectionSpec::Fisheye { frame, fov: 180.0 }),
        ];
        for (label, spec) in specs {
            let projection = spec
                .build(SIZE, SIZE)
                .unwrap_or_else(|e| panic!("{name} {label}: {e}"));
            group.bench_function(format!("{name}/{label}"), |b| {
                b.iter(|| render::render(&caster, projection.as_ref(), &options))
            });
        }
    }
    group.finish();
}

fn bvh_build(c: &mut Criterion) {
    let mut group = c.benchmark_group("bvh_build");
    group.sample_size(10);
    for name in SCENES {
        let scene = load(name);
        group.throughput(Throughput::Elements(scene.triangle_count() as u64));
        group.bench_function(name, |b| b.iter(|| PreparedScene::new(&scene)));
    }
    group.finish();
}

criterion_group!(benches, primary_rays, bvh_build);
criterion_main!(benches);
