//! Tests of the rasteriser against brute force and against its own invariants.

use glam::{DVec2, Vec3};

use super::fill::{fill_spans, Scratch};
use super::interpolate::Varying;
use super::line::line;
use super::*;

/// A small deterministic generator (xorshift64*), so the tests need no extra dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

fn v2(x: f64, y: f64) -> Vertex<0> {
    Vertex::new(x, y, 0.0, [])
}

fn shape(points: &[(f64, f64)]) -> Vec<Vertex<0>> {
    points.iter().map(|&(x, y)| v2(x, y)).collect()
}

fn poly<const N: usize>(vertices: &[Vertex<N>]) -> Polygon<'_, N> {
    Polygon {
        vertices,
        primitive: 0,
    }
}

/// `emit(x, y, values)` for every pixel of the spans of `fill::fill_spans`, in order.
fn fill<const N: usize>(
    polygon: &Polygon<'_, N>,
    rule: FillRule,
    rows: (u32, u32),
    width: u32,
    scratch: &mut Scratch<N>,
    mut emit: impl FnMut(u32, u32, Varying<N>),
) {
    fill_spans(polygon, rule, rows, width, scratch, |span| {
        for x in span.x0..span.x1 {
            emit(x, span.y, span.at(x));
        }
    });
}

/// How often `fill` hits each pixel of a `w x h` image.
fn coverage<const N: usize>(vertices: &[Vertex<N>], rule: FillRule, w: u32, h: u32) -> Vec<u32> {
    let mut hits = vec![0; (w * h) as usize];
    fill(
        &poly(vertices),
        rule,
        (0, h),
        w,
        &mut Scratch::default(),
        |x, y, _| hits[(y * w + x) as usize] += 1,
    );
    hits
}

/// The winding number of the closed polygon around `p`, by the classic crossing test (edges
/// half-open in y, crossings at or left of `p` counted).
fn winding<const N: usize>(vertices: &[Vertex<N>], p: DVec2) -> i32 {
    let mut w = 0;
    for (i, a) in vertices.iter().enumerate() {
        let (a, b) = (a.position, vertices[(i + 1) % vertices.len()].position);
        if (a.y <= p.y) != (b.y <= p.y) && a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) <= p.x {
            w += if b.y > a.y { 1 } else { -1 };
        }
    }
    w
}

fn brute_force<const N: usize>(vertices: &[Vertex<N>], rule: FillRule, w: u32, h: u32) -> Vec<u32> {
    let mut inside = vec![0; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let n = winding(vertices, DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5));
            let hit = match rule {
                FillRule::EvenOdd => n % 2 != 0,
                FillRule::NonZero => n != 0,
            };
            inside[(y * w + x) as usize] = u32::from(hit);
        }
    }
    inside
}

const RULES: [FillRule; 2] = [FillRule::EvenOdd, FillRule::NonZero];

fn pentagram(c: (f64, f64), r: f64) -> Vec<Vertex<0>> {
    (0..5)
        .map(|i| {
            let a = -std::f64::consts::FRAC_PI_2 + f64::from(i * 2) * std::f64::consts::TAU / 5.0;
            v2(c.0 + r * a.cos(), c.1 + r * a.sin())
        })
        .collect()
}

#[test]
fn raster_fill_matches_brute_force_on_named_shapes() {
    let shapes = [
        // Convex pentagon.
        shape(&[
            (3.3, 2.1),
            (25.7, 4.2),
            (29.1, 20.6),
            (14.4, 29.3),
            (2.2, 17.9),
        ]),
        // Non-convex L shape.
        shape(&[
            (2.3, 2.2),
            (10.7, 2.2),
            (10.7, 20.1),
            (28.4, 20.1),
            (28.4, 28.6),
            (2.3, 28.6),
        ]),
        // Self-intersecting bow-tie.
        shape(&[(2.2, 3.1), (29.7, 27.4), (29.7, 3.1), (2.2, 27.4)]),
        pentagram((16.3, 15.7), 14.2),
    ];
    for vertices in &shapes {
        for rule in RULES {
            let got = coverage(vertices, rule, 32, 32);
            assert_eq!(
                got,
                brute_force(vertices, rule, 32, 32),
                "{rule:?} {vertices:?}"
            );
            assert!(got.iter().sum::<u32>() > 50);
        }
    }
    // The pentagram's centre is wound twice: a hole under even-odd, filled under non-zero.
    let star = pentagram((16.3, 15.7), 14.2);
    let centre = (15 * 32 + 16) as usize;
    assert_eq!(coverage(&star, FillRule::EvenOdd, 32, 32)[centre], 0);
    assert_eq!(coverage(&star, FillRule::NonZero, 32, 32)[centre], 1);
    // The bow-tie has winding +-1 everywhere: both rules agree.
    assert_eq!(
        coverage(&shapes[2], FillRule::EvenOdd, 32, 32),
        coverage(&shapes[2], FillRule::NonZero, 32, 32)
    );
}

#[test]
fn raster_fill_matches_brute_force_on_random_polygons() {
    let mut rng = Rng(0x1234_5678);
    for _ in 0..300 {
        let n = 3 + (rng.next() * 14.0) as usize;
        let vertices: Vec<_> = (0..n)
            .map(|_| v2(rng.range(-8.0, 48.0), rng.range(-8.0, 40.0)))
            .collect();
        for rule in RULES {
            assert_eq!(
                coverage(&vertices, rule, 40, 32),
                brute_force(&vertices, rule, 40, 32),
                "{rule:?} {vertices:?}"
            );
        }
    }
}

#[test]
fn raster_tie_rule_is_top_left() {
    // Edges exactly through pixel centres: left and top edges are in, right and bottom out.
    let rect = shape(&[(2.5, 1.5), (5.5, 1.5), (5.5, 4.5), (2.5, 4.5)]);
    let hits = coverage(&rect, FillRule::EvenOdd, 8, 8);
    for y in 0..8 {
        for x in 0..8 {
            let inside = (2..5).contains(&x) && (1..4).contains(&y);
            assert_eq!(hits[y * 8 + x], u32::from(inside), "({x}, {y})");
        }
    }
    // The same far from the origin, where x - 0.5 must stay exact.
    let big = 1u32 << 30;
    let far = shape(&[(1.5, 0.5), (2.5, 0.5), (2.5, 1.5), (1.5, 1.5)])
        .into_iter()
        .map(|v| v2(v.position.x + f64::from(big), v.position.y))
        .collect::<Vec<_>>();
    let mut got = Vec::new();
    fill(
        &poly(&far),
        FillRule::EvenOdd,
        (0, 4),
        big + 4,
        &mut Scratch::default(),
        |x, y, _| got.push((x, y)),
    );
    assert_eq!(got, vec![(big + 1, 0)]);
}

/// Splits the image into a jittered grid of quads, each cut into two triangles (alternating
/// diagonals and windings), or kept as a quad.
fn tiling(
    rng: &mut Rng,
    w: u32,
    h: u32,
    cells: u32,
    jitter: f64,
    quads: bool,
) -> Vec<Vec<Vertex<0>>> {
    let grid = |i: u32, j: u32, rng: &mut Rng| {
        let x = f64::from(i * w) / f64::from(cells);
        let y = f64::from(j * h) / f64::from(cells);
        let dx = if i == 0 || i == cells {
            0.0
        } else {
            rng.range(-jitter, jitter)
        };
        let dy = if j == 0 || j == cells {
            0.0
        } else {
            rng.range(-jitter, jitter)
        };
        v2(x + dx, y + dy)
    };
    let points: Vec<Vec<_>> = (0..=cells)
        .map(|j| (0..=cells).map(|i| grid(i, j, rng)).collect())
        .collect();
    let mut out = Vec::new();
    for j in 0..cells as usize {
        for i in 0..cells as usize {
            let [a, b, c, d] = [
                points[j][i],
                points[j][i + 1],
                points[j + 1][i + 1],
                points[j + 1][i],
            ];
            if quads {
                out.push(vec![a, b, c, d]);
            } else if (i + j) % 2 == 0 {
                out.push(vec![a, b, c]);
                out.push(vec![a, d, c]); // clockwise on screen: the other winding
            } else {
                out.push(vec![a, b, d]);
                out.push(vec![b, c, d]);
            }
        }
    }
    out
}

#[test]
fn raster_shared_edges_cover_every_pixel_exactly_once() {
    let (w, h) = (48, 40);
    let mut rng = Rng(99);
    let mut cases = vec![
        // Grid lines through pixel centres and corners: every tie at once.
        tiling(&mut rng, w, h, 8, 0.0, false),
        tiling(&mut rng, w, h, 16, 0.0, true),
    ];
    for _ in 0..20 {
        cases.push(tiling(&mut rng, w, h, 7, 1.2, false));
    }
    // Vertices snapped to pixel centres and corners.
    let mut snapped = tiling(&mut rng, w, h, 6, 1.2, false);
    for v in snapped.iter_mut().flatten() {
        v.position = (v.position * 2.0).round() / 2.0;
    }
    cases.push(snapped);
    // A fan around a vertex exactly on a pixel centre.
    let c = v2(20.5, 17.5);
    let rim = shape(&[
        (0.0, 0.0),
        (20.5, 0.0),
        (48.0, 0.0),
        (48.0, 17.5),
        (48.0, 40.0),
        (20.5, 40.0),
        (0.0, 40.0),
        (0.0, 17.5),
    ]);
    cases.push(
        (0..rim.len())
            .map(|i| vec![c, rim[i], rim[(i + 1) % rim.len()]])
            .collect(),
    );
    for (case, tiles) in cases.iter().enumerate() {
        // The premise: the tiles do not fold over each other.
        let area: f64 = tiles.iter().map(|t| signed_area(t).abs()).sum();
        assert!(
            (area - f64::from(w * h)).abs() < 1e-9,
            "case {case}: area {area}"
        );
        for rule in RULES {
            let mut total = vec![0; (w * h) as usize];
            for t in tiles {
                for (sum, hit) in total.iter_mut().zip(coverage(t, rule, w, h)) {
                    *sum += hit;
                }
            }
            let bad: Vec<_> = total.iter().enumerate().filter(|(_, &n)| n != 1).collect();
            assert!(bad.is_empty(), "{rule:?}: case {case}, {bad:?}");
        }
    }
}

/// The signed area of a polygon (positive when clockwise on screen, y down).
fn signed_area<const N: usize>(vertices: &[Vertex<N>]) -> f64 {
    let n = vertices.len();
    (0..n)
        .map(|i| {
            let (a, b) = (vertices[i].position, vertices[(i + 1) % n].position);
            a.x * b.y - a.y * b.x
        })
        .sum::<f64>()
        / 2.0
}

/// The barycentrics of `p` in triangle `abc`, computed directly.
fn barycentric(a: DVec2, b: DVec2, c: DVec2, p: DVec2) -> (f64, f64) {
    let cross = |u: DVec2, v: DVec2| u.x * v.y - u.y * v.x;
    let area = cross(b - a, c - a);
    (cross(p - a, c - a) / area, cross(b - a, p - a) / area)
}

#[test]
fn raster_triangle_interpolation_is_exact_barycentric() {
    let mut rng = Rng(7);
    let mut checked = 0;
    for _ in 0..200 {
        let p: [DVec2; 3] =
            std::array::from_fn(|_| DVec2::new(rng.range(-10.0, 70.0), rng.range(-10.0, 60.0)));
        let depth: [f64; 3] = std::array::from_fn(|_| rng.range(0.1, 100.0));
        let tri = [
            Vertex {
                position: p[0],
                varying: Varying {
                    depth: depth[0],
                    attributes: [0.0, 0.0],
                },
            },
            Vertex {
                position: p[1],
                varying: Varying {
                    depth: depth[1],
                    attributes: [1.0, 0.0],
                },
            },
            Vertex {
                position: p[2],
                varying: Varying {
                    depth: depth[2],
                    attributes: [0.0, 1.0],
                },
            },
        ];
        fill(
            &poly(&tri),
            FillRule::EvenOdd,
            (0, 50),
            60,
            &mut Scratch::default(),
            |x, y, v| {
                let c = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let (b1, b2) = barycentric(p[0], p[1], p[2], c);
                let d = (1.0 - b1 - b2) * depth[0] + b1 * depth[1] + b2 * depth[2];
                assert!(
                    (v.attributes[0] - b1).abs() < 1e-9,
                    "{} {b1}",
                    v.attributes[0]
                );
                assert!(
                    (v.attributes[1] - b2).abs() < 1e-9,
                    "{} {b2}",
                    v.attributes[1]
                );
                assert!((v.depth - d).abs() < 1e-9 * 100.0, "{} {d}", v.depth);
                checked += 1;
            },
        );
    }
    assert!(checked > 10_000);
}

#[test]
fn raster_polygon_interpolation_reproduces_affine_values() {
    // Scanline edge interpolation is exact for values affine over the polygon, whatever its
    // shape.
    let f = |p: DVec2| (0.25 * p.x - 0.75 * p.y + 3.0, -0.5 * p.x + 0.125 * p.y);
    let with_values = |vertices: Vec<Vertex<0>>| -> Vec<Vertex<1>> {
        vertices
            .iter()
            .map(|v| {
                let (d, a) = f(v.position);
                Vertex::new(v.position.x, v.position.y, d, [a])
            })
            .collect()
    };
    let shapes = [
        with_values(shape(&[
            (2.3, 2.2),
            (10.7, 2.2),
            (10.7, 20.1),
            (28.4, 20.1),
            (28.4, 28.6),
            (2.3, 28.6),
        ])),
        with_values(shape(&[(2.2, 3.1), (29.7, 27.4), (29.7, 3.1), (2.2, 27.4)])),
        with_values(pentagram((16.3, 15.7), 14.2)),
    ];
    for vertices in &shapes {
        for rule in RULES {
            let mut n = 0;
            fill(
                &poly(vertices),
                rule,
                (0, 32),
                32,
                &mut Scratch::default(),
                |x, y, v| {
                    let (d, a) = f(DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5));
                    assert!((v.depth - d).abs() < 1e-12 && (v.attributes[0] - a).abs() < 1e-12);
                    n += 1;
                },
            );
            assert!(n > 100);
        }
    }
}

/// Stepping along a span (`start + k step`, added pixel by pixel) gives the values
/// interpolated at each pixel centre, up to rounding, on the random scene's polygons and
/// lines; the start is exactly the interpolated value at `x0`.
#[test]
fn raster_span_steps_reproduce_the_interpolated_values() {
    let shapes = batch(&scene(31, 300, 64.0, 48.0));
    let mut scratch = Scratch::default();
    let mut pixels = 0;
    for polygon in shapes.iter() {
        spans(
            &polygon,
            FillRule::NonZero,
            (0, 48),
            64,
            &mut scratch,
            |span| {
                let (start, step) = span.start_and_step();
                assert_eq!(start, span.at(span.x0));
                let mut values = start;
                for x in span.x0..span.x1 {
                    let expected = span.at(x);
                    assert!(
                        (values.depth - expected.depth).abs() < 1e-12,
                        "depth at {x}"
                    );
                    for (a, b) in values.attributes.iter().zip(expected.attributes) {
                        assert!((a - b).abs() < 1e-12, "attribute at {x}");
                    }
                    values.depth += step.depth;
                    for (a, d) in values.attributes.iter_mut().zip(step.attributes) {
                        *a += d;
                    }
                    pixels += 1;
                }
            },
        );
    }
    assert!(pixels > 10_000, "{pixels}");
}

/// Random overlapping triangles and polygons with varying depths (some tied), and a few
/// lines, each with its own primitive key.
fn scene(seed: u64, count: usize, w: f64, h: f64) -> Vec<(Vec<Vertex<2>>, u64)> {
    let mut rng = Rng(seed);
    (0..count)
        .map(|i| {
            let n = match i % 10 {
                0 => 2,
                1..=6 => 3,
                _ => 4 + (rng.next() * 6.0) as usize,
            };
            let c = DVec2::new(rng.range(-5.0, w + 5.0), rng.range(-5.0, h + 5.0));
            let flat = rng.next() < 0.3;
            let base = (rng.next() * 4.0).floor();
            let vertices = (0..n)
                .map(|_| {
                    let p = c + DVec2::new(rng.range(-12.0, 12.0), rng.range(-12.0, 12.0));
                    let depth = if flat { base } else { base + rng.next() };
                    Vertex::new(p.x, p.y, depth, [rng.next(), rng.next()])
                })
                .collect();
            (vertices, i as u64)
        })
        .collect()
}

fn batch(shapes: &[(Vec<Vertex<2>>, u64)]) -> PolygonBatch<2> {
    let mut batch = PolygonBatch::new();
    for (vertices, primitive) in shapes {
        batch.push(vertices, *primitive);
    }
    batch
}

fn shade(f: &Fragment<2>) -> Vec3 {
    let [a, b] = f.varying.attributes;
    Vec3::new(a as f32, b as f32, (f.primitive % 13) as f32 / 13.0)
}

#[test]
fn raster_zbuffer_is_independent_of_input_order() {
    let mut shapes = scene(5, 400, 64.0, 48.0);
    let mut reference = Target::new(64, 48, Vec3::ZERO);
    let stats = rasterize(&mut reference, &batch(&shapes), FillRule::NonZero, &shade);
    assert!(stats.fragments > stats.covered && stats.writes > stats.covered);
    let mut rng = Rng(11);
    for _ in 0..5 {
        // Fisher-Yates.
        for i in (1..shapes.len()).rev() {
            shapes.swap(i, (rng.next() * (i + 1) as f64) as usize);
        }
        let mut target = Target::new(64, 48, Vec3::ZERO);
        let shuffled = rasterize(&mut target, &batch(&shapes), FillRule::NonZero, &shade);
        assert!(target == reference);
        assert_eq!(shuffled.fragments, stats.fragments);
    }
}

#[test]
fn raster_parallel_equals_serial_bit_for_bit() {
    let shapes = batch(&scene(17, 2000, 97.0, 83.0));
    for rule in RULES {
        let mut serial = Target::new(97, 83, Vec3::splat(0.5));
        let serial_stats = rasterize(&mut serial, &shapes, rule, &shade);
        for threads in [1, 3, 8] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            for band_rows in [1, 7, BAND_ROWS, 1000] {
                let mut target = Target::new(97, 83, Vec3::splat(0.5));
                let stats = pool
                    .install(|| rasterize_parallel(&mut target, &shapes, rule, band_rows, &shade));
                assert!(target == serial, "{threads} threads, {band_rows} rows");
                // Bitwise, depth included (== would equate 0.0 and -0.0).
                assert!(target
                    .depth()
                    .iter()
                    .zip(serial.depth())
                    .all(|(a, b)| a.to_bits() == b.to_bits()));
                assert_eq!(stats, serial_stats);
            }
        }
    }
}

/// The pixels of a line with (depth, attribute), sorted.
fn line_pixels(a: Vertex<1>, b: Vertex<1>, w: u32, h: u32) -> Vec<(u32, u32, f64, f64)> {
    let mut out = Vec::new();
    line(&a, &b, (0, h), w, |x, y, v| {
        out.push((x, y, v.depth, v.attributes[0]))
    });
    // Along the major axis.
    let d = (b.position - a.position).abs();
    out.sort_by_key(|p| if d.x >= d.y { (p.0, p.1) } else { (p.1, p.0) });
    out
}

#[test]
fn raster_lines() {
    let v = |x: f64, y: f64, d: f64| Vertex::new(x, y, d, [2.0 * d]);
    // Horizontal, depth = x: sampled at column centres clamped to the segment.
    let got = line_pixels(v(1.2, 3.7, 1.2), v(9.8, 3.7, 9.8), 16, 8);
    assert_eq!(got.len(), 9);
    for (i, &(x, y, d, a)) in got.iter().enumerate() {
        assert_eq!((x, y), (i as u32 + 1, 3));
        let expected = (f64::from(x) + 0.5).clamp(1.2, 9.8);
        assert!((d - expected).abs() < 1e-12 && (a - 2.0 * expected).abs() < 1e-12);
    }
    // A line and its reverse draw the same fragments, bit for bit.
    let mut rng = Rng(3);
    for _ in 0..200 {
        let a = v(rng.range(-5.0, 25.0), rng.range(-5.0, 25.0), rng.next());
        let b = v(rng.range(-5.0, 25.0), rng.range(-5.0, 25.0), rng.next());
        let forward = line_pixels(a, b, 20, 20);
        assert_eq!(forward, line_pixels(b, a, 20, 20));
        // One pixel per step of the major axis, neighbours touching.
        let d = (b.position - a.position).abs();
        let major = |p: &(u32, u32, f64, f64)| if d.x >= d.y { (p.0, p.1) } else { (p.1, p.0) };
        for pair in forward.windows(2) {
            let (m0, n0) = major(&pair[0]);
            let (m1, n1) = major(&pair[1]);
            assert_eq!(m1, m0 + 1);
            assert!(n0.abs_diff(n1) <= 1);
        }
    }
    // Diagonal, vertical, and shorter than a pixel.
    let diagonal: Vec<_> = line_pixels(v(0.5, 0.5, 0.0), v(10.5, 10.5, 1.0), 16, 16)
        .iter()
        .map(|p| (p.0, p.1))
        .collect();
    assert_eq!(diagonal, (0..=10).map(|i| (i, i)).collect::<Vec<_>>());
    let vertical: Vec<_> = line_pixels(v(4.9, 2.0, 0.0), v(4.9, 6.5, 1.0), 16, 16)
        .iter()
        .map(|p| (p.0, p.1))
        .collect();
    assert_eq!(vertical, (2..=6).map(|i| (4, i)).collect::<Vec<_>>());
    assert_eq!(
        line_pixels(v(3.2, 4.3, 0.5), v(3.4, 4.6, 0.5), 8, 8),
        vec![(3, 4, 0.5, 1.0)]
    );
    // Huge coordinates are clipped to the image, values stay finite.
    let across = line_pixels(v(-1e200, 5.5, -1e200), v(1e200, 5.5, 1e200), 16, 8);
    assert_eq!(
        across.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>(),
        (0..16).map(|x| (x, 5)).collect::<Vec<_>>()
    );
    assert!(across.iter().all(|p| p.2.is_finite()));
    assert!(line_pixels(v(-50.0, -3.0, 0.0), v(-2.0, 40.0, 0.0), 16, 8).is_empty());
}

#[test]
fn raster_degenerate_inputs_never_panic() {
    let big = 1e200;
    let mut batch = PolygonBatch::<2>::new();
    let v = |x: f64, y: f64| Vertex::new(x, y, 1.0, [0.0, 0.0]);
    // Zero area: collinear, and all vertices equal.
    batch.push(&[v(1.0, 1.0), v(5.0, 5.0), v(9.0, 9.0)], 0);
    batch.push(&[v(3.5, 3.5); 4], 1);
    // Entirely off-screen.
    batch.push(&[v(-20.0, -20.0), v(-10.0, -20.0), v(-10.0, -5.0)], 2);
    batch.push(&[v(100.0, 2.0), v(120.0, 2.0), v(110.0, 9.0)], 3);
    // NaN, infinite and beyond-LIMIT components: skipped.
    batch.push(&[v(1.0, 1.0), v(f64::NAN, 5.0), v(9.0, 2.0)], 4);
    batch.push(&[v(1.0, 1.0), v(5.0, f64::INFINITY), v(9.0, 2.0)], 5);
    batch.push(&[v(1.0, 1.0), v(5.0, 2e300), v(9.0, 2.0)], 6);
    batch.push(
        &[
            v(1.0, 1.0),
            Vertex::new(5.0, 5.0, f64::NAN, [0.0, 0.0]),
            v(9.0, 2.0),
        ],
        7,
    );
    batch.push(
        &[
            v(1.0, 1.0),
            Vertex::new(5.0, 5.0, 0.0, [0.0, f64::NAN]),
            v(9.0, 2.0),
        ],
        8,
    );
    // Too few vertices: skipped.
    batch.push(&[v(1.0, 1.0)], 9);
    batch.push(&[], 10);
    let mut target = Target::new(16, 12, Vec3::ZERO);
    let stats = rasterize(&mut target, &batch, FillRule::EvenOdd, &|_| Vec3::ONE);
    assert_eq!((stats.polygons, stats.lines, stats.skipped), (4, 0, 7));
    assert_eq!((stats.fragments, stats.covered), (0, 0));
    assert_eq!(stats.overdraw(), 0.0);
    // A huge triangle covering the image is clipped, with finite interpolated values.
    let mut huge = PolygonBatch::<2>::new();
    huge.push(
        &[
            Vertex::new(-big, -big, -big, [0.0, 0.0]),
            Vertex::new(3.0 * big, -big, big, [1.0, 0.0]),
            Vertex::new(-big, 3.0 * big, big, [0.0, 1.0]),
        ],
        0,
    );
    let mut target = Target::new(16, 12, Vec3::ZERO);
    let stats = rasterize_parallel(&mut target, &huge, FillRule::NonZero, 5, &|_| Vec3::ONE);
    assert_eq!(stats.covered, 16 * 12);
    assert!(
        target.depth().iter().all(|d| d.is_finite())
            && (0..12).all(|y| (0..16).all(|x| target.primitive(x, y) == Some(0)))
    );
    // Empty targets.
    for (w, h) in [(0, 0), (0, 5), (5, 0)] {
        let mut empty = Target::new(w, h, Vec3::ZERO);
        assert_eq!(
            rasterize_parallel(&mut empty, &huge, FillRule::EvenOdd, 4, &|_| Vec3::ONE).fragments,
            0
        );
        assert_eq!(
            rasterize(&mut empty, &huge, FillRule::EvenOdd, &|_| Vec3::ONE).fragments,
            0
        );
    }
}

#[test]
fn raster_stats_and_frame() {
    let mut batch = PolygonBatch::<0>::new();
    // Two overlapping squares, the second nearer; a line in front of both.
    let square = |x0: f64, y0: f64, d: f64| -> Vec<Vertex<0>> {
        [
            (x0, y0),
            (x0 + 4.0, y0),
            (x0 + 4.0, y0 + 4.0),
            (x0, y0 + 4.0),
        ]
        .iter()
        .map(|&(x, y)| Vertex::new(x, y, d, []))
        .collect()
    };
    batch.push(&square(0.0, 0.0, 2.0), 0);
    batch.push(&square(2.0, 2.0, 1.0), 1);
    batch.push(
        &[
            Vertex::new(0.5, 7.5, 0.5, []),
            Vertex::new(7.5, 7.5, 0.5, []),
        ],
        2,
    );
    let mut target = Target::new(8, 8, Vec3::ZERO);
    let stats = rasterize(&mut target, &batch, FillRule::EvenOdd, &|f| {
        Vec3::splat((f.primitive + 1) as f32)
    });
    assert_eq!((stats.polygons, stats.lines, stats.skipped), (2, 1, 0));
    assert_eq!(
        (stats.fragments, stats.writes, stats.covered),
        (16 + 16 + 8, 40, 28 + 8)
    );
    assert_eq!(target.primitive(3, 3), Some(1));
    assert_eq!(target.primitive(7, 0), None);
    let mut counters = crate::render::Stats::new();
    stats.record(&mut counters);
    assert_eq!(
        counters["raster_fragments"],
        crate::render::Counter::Count(40)
    );
    assert_eq!(
        counters["raster_overdraw"],
        crate::render::Counter::Value(40.0 / 36.0)
    );
    let depth = target.depth().to_vec();
    let frame = target.into_frame();
    assert_eq!(
        frame.depth,
        depth.iter().map(|&d| d as f32).collect::<Vec<_>>()
    );
    assert_eq!(
        (frame.ids[3 * 8 + 3], frame.ids[0], frame.ids[7 * 8]),
        (2, 1, 3)
    );
    assert_eq!(
        (frame.depth[3 * 8 + 3], frame.depth[7]),
        (1.0, f32::INFINITY)
    );
    assert_eq!(frame.color[0], Vec3::ONE);
}

#[test]
fn raster_stage_rewrites_depth_or_discards_before_the_z_test() {
    // Two equal squares at depths 3 and 5; the stage moves the far one to depth 1 on its
    // left half and discards it on its right half, so it wins only on the left.
    let square = |depth| {
        [(0.0, 0.0), (8.0, 0.0), (8.0, 4.0), (0.0, 4.0)].map(|(x, y)| Vertex::new(x, y, depth, []))
    };
    let mut batch = PolygonBatch::<0>::new();
    batch.push(&square(3.0), 0);
    batch.push(&square(5.0), 1);
    let mut merged = PolygonBatch::<0>::new();
    merged.append(&batch);
    assert_eq!(merged.len(), 2);
    let stage = |f: &mut Fragment<0>| {
        if f.primitive == 0 {
            return true;
        }
        f.varying.depth = 1.0;
        f.x < 4
    };
    let mut target = Target::new(8, 4, Vec3::ZERO);
    let stats =
        rasterize_parallel_resolved(&mut target, &merged, FillRule::NonZero, 2, &stage, &|_| {
            Vec3::ONE
        });
    assert_eq!((stats.fragments, stats.discarded), (64, 16));
    for y in 0..4 {
        for x in 0..8 {
            let expected = if x < 4 { 1 } else { 0 };
            assert_eq!(target.primitive(x, y), Some(expected), "({x}, {y})");
        }
    }
}

/// Drawing the spans of each band's shapes into a band-local z-buffer ([`for_each_band`],
/// [`spans`]) gives exactly the rows of the serial target, bit for bit, whatever the thread
/// count or band size.
#[test]
fn raster_bands_drawn_by_spans_are_the_rows_of_the_serial_target() {
    let shapes = batch(&scene(23, 1500, 91.0, 77.0));
    let mut serial = Target::new(91, 77, Vec3::ZERO);
    let serial_stats = rasterize(&mut serial, &shapes, FillRule::NonZero, &shade);
    let expected = serial.into_frame();
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        for band_rows in [1, 7, band_rows_for(91), 1000] {
            let mut frame = crate::render::Frame::new(91, 77, Vec3::ONE);
            // Per band: a z-buffer of (depth, key) per pixel, written to the frame's rows.
            let band = |scratch: &mut Scratch<2>, bin: &[usize], out: FrameRows<'_>| {
                let mut zbuffer = vec![(f64::INFINITY, NO_PRIMITIVE, 0, Vec3::ZERO); out.ids.len()];
                let mut fragments = 0u64;
                for &k in bin {
                    let polygon = shapes.get(k);
                    spans(&polygon, FillRule::NonZero, out.rows, 91, scratch, |span| {
                        for x in span.x0..span.x1 {
                            let fragment = Fragment {
                                x,
                                y: span.y,
                                varying: span.at(x),
                                primitive: polygon.primitive,
                            };
                            fragments += 1;
                            let i = ((span.y - out.rows.0) * 91 + x) as usize;
                            let (depth, key, _, _) = zbuffer[i];
                            let d = fragment.varying.depth;
                            if d < depth || (d == depth && fragment.primitive < key) {
                                zbuffer[i] = (
                                    d,
                                    fragment.primitive,
                                    id_of(fragment.primitive),
                                    shade(&fragment),
                                );
                            }
                        }
                    });
                }
                for (i, &(depth, _, id, color)) in zbuffer.iter().enumerate() {
                    out.color[i] = color;
                    out.depth[i] = depth as f32;
                    out.ids[i] = id;
                }
                fragments
            };
            let fragments = pool
                .install(|| {
                    let init = || Ok(Scratch::default());
                    for_each_band(&mut frame, &shapes, band_rows, init, band)
                })
                .unwrap();
            assert!(frame == expected, "{threads} threads, {band_rows} rows");
            assert_eq!(fragments, serial_stats.fragments);
        }
    }
}
