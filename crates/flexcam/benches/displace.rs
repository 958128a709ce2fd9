//! Displaced-triangle ray tracing: the min/max hierarchy (`DisplacedTriangle::intersect`)
//! against the brute force (every micro-triangle, micro-vertices computed for the ray, as the
//! recursive routine of Algorithm 6.12 does) at levels 2 to 5, on one base triangle displaced
//! by a 64 x 64 smooth random height map, 256 rays from random directions aimed at random
//! points of the triangle. Throughput is rays per second.
//!
//! Run with `cargo bench -p flexcam --bench displace` (a few seconds). Figures are recorded in
//! docs/displace.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use flexcam::displace::{
    BaseVertex, DisplacedTriangle, Displacement, HeightField, HeightMap, MicroGrid,
};
use flexcam::geometry::Ray;
use glam::{DVec2, DVec3};

/// A deterministic sequence in [0, 1).
fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

/// 64 x 64 heights: a sum of a few smooth waves with random phases, in [0, 1].
fn height_map() -> HeightMap {
    let phases = noise(6, 7);
    let size = 64;
    let values = (0..size * size)
        .map(|i| {
            let (x, y) = (
                (i % size) as f64 / size as f64,
                (i / size) as f64 / size as f64,
            );
            let tau = std::f64::consts::TAU;
            let h = (tau * (2.0 * x + phases[0])).sin()
                + (tau * (3.0 * y + phases[1])).sin()
                + 0.5 * (tau * (5.0 * (x + y) + phases[2])).sin();
            ((h + 2.5) / 5.0) as f32
        })
        .collect();
    HeightMap::from_values(size as u32, size as u32, values).expect("heights in [0, 1]")
}

fn displace(c: &mut Criterion) {
    let map = HeightField::Map(height_map());
    let corners = [
        ([0.0, 0.0, 0.0], [0.0, 0.0]),
        ([1.0, 0.0, 0.0], [1.0, 0.0]),
        ([0.0, 1.0, 0.1], [0.0, 1.0]),
    ]
    .map(|(p, uv)| BaseVertex {
        position: DVec3::from(p),
        normal: DVec3::new(0.0, -0.1, 1.0).normalize(),
        uv: DVec2::from(uv),
    });
    let r = noise(256 * 4, 3);
    let rays: Vec<Ray> = r
        .chunks(4)
        .map(|k| {
            let (s, t) = if k[0] + k[1] > 1.0 {
                (1.0 - k[0], 1.0 - k[1])
            } else {
                (k[0], k[1])
            };
            let target = DVec3::new(s, t, 0.1 * t - 0.05);
            let from = target + DVec3::new(k[2] - 0.5, k[3] - 0.5, 1.0) * 2.0;
            Ray::new(from, target - from)
        })
        .collect();
    let mut group = c.benchmark_group("displaced_triangle");
    group.sample_size(10);
    group.warm_up_time(std::time::Duration::from_millis(300));
    group.measurement_time(std::time::Duration::from_millis(700));
    group.throughput(Throughput::Elements(rays.len() as u64));
    for level in 2..=5 {
        let d = Displacement::new(map.clone(), 0.08, 1.0, level).expect("valid displacement");
        let tri = DisplacedTriangle::new(corners, &d);
        group.bench_function(format!("hierarchy_level_{level}"), |b| {
            b.iter(|| rays.iter().filter_map(|r| tri.intersect(r)).count())
        });
        group.bench_function(format!("brute_force_level_{level}"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter_map(|r| MicroGrid::new(&corners, &d).intersect(r))
                    .count()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, displace);
criterion_main!(benches);
