//! Our BVH against the `obvhs` crate (a compressed 8-wide BVH, CWBVH, built by PLOC) on the
//! same mesh and the same rays: closest hits of the 640,000 perspective primary rays of an
//! 800x800 image of `teapot-dense` (over 100,000 triangles), on one thread, plus build times.
//!
//! Run with `cargo bench -p flexcam --bench bvh_crates`. Figures are recorded in
//! docs/raycast.md; the ray caster keeps whichever BVH is faster.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use flexcam::geometry::Ray;
use flexcam::render::PreparedScene;
use flexcam::scene::{builtin, Scene};
use glam::DVec2;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::RayHit;
use obvhs::BvhBuildParams;

const SIZE: u32 = 800;

fn scene() -> Scene {
    builtin::load("teapot-dense").unwrap_or_else(|e| panic!("teapot-dense: {e}"))
}

/// The primary rays of the scene's own projection, pixel centres, row by row.
fn primary_rays(scene: &Scene) -> Vec<Ray> {
    let projection = scene
        .projection
        .build(SIZE, SIZE)
        .unwrap_or_else(|e| panic!("teapot-dense projection: {e}"));
    (0..SIZE * SIZE)
        .filter_map(|i| {
            projection.ray(DVec2::new((i % SIZE) as f64 + 0.5, (i / SIZE) as f64 + 0.5))
        })
        .collect()
}

/// The scene's world-space triangles in `obvhs`'s form.
fn obvhs_triangles(scene: &Scene) -> Vec<obvhs::triangle::Triangle> {
    let mut out = Vec::with_capacity(scene.triangle_count());
    for object in &scene.objects {
        let p = &object.mesh.positions;
        out.extend(
            object
                .mesh
                .triangles
                .iter()
                .map(|t| obvhs::triangle::Triangle {
                    v0: p[t[0] as usize].to_array().into(),
                    v1: p[t[1] as usize].to_array().into(),
                    v2: p[t[2] as usize].to_array().into(),
                }),
        );
    }
    out
}

fn compare(c: &mut Criterion) {
    let scene = scene();
    let rays = primary_rays(&scene);
    let tris = obvhs_triangles(&scene);
    let ours = PreparedScene::new(&scene);
    let theirs = build_cwbvh_from_tris(
        &tris,
        BvhBuildParams::medium_build(),
        &mut Duration::default(),
    );
    let their_rays: Vec<obvhs::ray::Ray> = rays
        .iter()
        .map(|r| {
            let o = r.origin.as_vec3().to_array();
            let d = r.direction.as_vec3().to_array();
            obvhs::ray::Ray::new(o.into(), d.into(), r.t_min as f32, r.t_max as f32)
        })
        .collect();

    let mut group = c.benchmark_group("bvh_closest_hit_1_thread");
    group.sample_size(10);
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function("flexcam", |b| {
        b.iter(|| rays.iter().filter(|r| ours.intersect(r).is_some()).count())
    });
    group.bench_function("obvhs_cwbvh", |b| {
        b.iter(|| {
            their_rays
                .iter()
                .filter(|&&ray| {
                    let mut hit = RayHit::none();
                    theirs.ray_traverse(ray, &mut hit, |ray, id| {
                        tris[theirs.primitive_indices[id] as usize].intersect(ray)
                    })
                })
                .count()
        })
    });
    group.finish();

    let mut group = c.benchmark_group("bvh_build_teapot_dense");
    group.sample_size(10);
    group.throughput(Throughput::Elements(tris.len() as u64));
    group.bench_function("flexcam", |b| {
        b.iter(|| PreparedScene::new(black_box(&scene)))
    });
    group.bench_function("obvhs_cwbvh_medium", |b| {
        b.iter(|| {
            build_cwbvh_from_tris(
                black_box(&tris),
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, compare);
criterion_main!(benches);
