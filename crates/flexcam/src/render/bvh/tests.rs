use glam::DVec3;

use super::build::MAX_LEAF;
use super::triangle::{FastRay, PackedTriangle};
use super::*;
use crate::geometry::Ray;

/// A deterministic generator for test inputs (SplitMix64).
pub(super) struct Rng(pub(super) u64);

impl Rng {
    pub(super) fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    pub(super) fn vec(&mut self, scale: f32) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next()) * 2.0 * scale - scale
    }
}

pub(super) fn soup(rng: &mut Rng, n: usize) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = rng.vec(10.0);
            [c + rng.vec(1.5), c + rng.vec(1.5), c + rng.vec(1.5)]
        })
        .collect()
}

/// The closest hit by testing every triangle with the same f32 routine.
fn brute_force(triangles: &[[Vec3; 3]], ray: &FastRay) -> Option<(u32, f32)> {
    brute_force_of(triangles, ray, |_| true)
}

/// The closest hit among the triangles whose index `keeps` accepts, by testing each.
fn brute_force_of(
    triangles: &[[Vec3; 3]],
    ray: &FastRay,
    keeps: impl Fn(u32) -> bool,
) -> Option<(u32, f32)> {
    let mut best: Option<(u32, f32)> = None;
    for (i, &[a, b, c]) in triangles.iter().enumerate() {
        if !keeps(i as u32) {
            continue;
        }
        let Some(tri) = PackedTriangle::new(a.into(), b.into(), c.into()) else {
            continue;
        };
        let t_max = best.map_or(ray.t_max, |b| b.1);
        if let Some(h) = tri.intersect(ray, t_max) {
            best = Some((i as u32, h.t));
        }
    }
    best
}

/// A masked query finds what testing only the kept triangles finds, one ray or four at once,
/// and an any-hit query sees only them.
#[test]
fn masked_queries_see_only_the_kept_triangles() {
    let mut rng = Rng(11);
    let triangles = soup(&mut rng, 3000);
    let bvh = Bvh::build(&triangles);
    let keeps = |id: u32| id % 3 != 0 && !(1000..1600).contains(&id);
    let mask = TriangleMask::by_id(&bvh, keeps);
    let mut hidden_hits = 0;
    for k in 0..300 {
        let origin = rng.vec(15.0).as_dvec3();
        let rays: [FastRay; 4] = std::array::from_fn(|lane| {
            let target = (rng.vec(8.0) + lane as f32 * 0.01).as_dvec3();
            FastRay::new(&Ray::new(origin, target - origin)).unwrap()
        });
        let packet = bvh.closest4(rays.each_ref().map(Some), &mask);
        for (ray, got) in rays.iter().zip(packet) {
            let expected = brute_force_of(&triangles, ray, keeps);
            let single = bvh.closest(ray, &mask).map(|h| (h.id, h.hit.t));
            assert_eq!(single, expected, "ray {k}");
            assert_eq!(got.map(|h| (h.id, h.hit.t)), expected, "packet {k}");
            assert_eq!(bvh.occluded(ray, &mask), expected.is_some());
            let all = bvh.closest(ray, &AllTriangles).map(|h| h.id);
            hidden_hits += usize::from(all.is_some_and(|id| !keeps(id)));
        }
    }
    assert!(hidden_hits > 50, "{hidden_hits}");
}

/// A mask hiding a compact object (a cluster of small triangles, as a mirror sphere is) clears
/// the child bits of the subtrees holding only it, so that queries skip them; built with the
/// object in a group of its own, the hidden part is one child of the root. The answers stay
/// those of testing only the kept triangles, including rays aimed at the cluster.
#[test]
fn masked_queries_skip_the_subtrees_of_a_hidden_object() {
    for grouped in [false, true] {
        masked_queries_skip_a_hidden_cluster(grouped);
    }
}

fn masked_queries_skip_a_hidden_cluster(grouped: bool) {
    let mut rng = Rng(23);
    let mut triangles = soup(&mut rng, 1500);
    let cluster = triangles.len() as u32;
    triangles.extend((0..1500).map(|_| {
        let c = Vec3::new(2.0, 1.0, -1.0) + rng.vec(1.0);
        [c + rng.vec(0.3), c + rng.vec(0.3), c + rng.vec(0.3)]
    }));
    let bvh = match grouped {
        true => Bvh::build_grouped(&triangles, |id| u32::from(id >= cluster)),
        false => Bvh::build(&triangles),
    };
    let keeps = |id: u32| id < cluster;
    let mask = TriangleMask::by_id(&bvh, keeps);
    let skipped = (mask.children.iter())
        .map(|b| (b ^ 0b11).count_ones())
        .sum::<u32>();
    assert!(skipped > 100 || grouped, "only {skipped} subtrees skipped");
    if grouped {
        assert_eq!(mask.children[bvh.root.index as usize], 0b01);
    }
    let mut through_cluster = 0;
    for k in 0..300 {
        let origin = rng.vec(15.0).as_dvec3();
        let rays: [FastRay; 4] = std::array::from_fn(|lane| {
            let aim = if k % 2 == 0 {
                Vec3::new(2.0, 1.0, -1.0)
            } else {
                Vec3::ZERO
            };
            let target = (aim + rng.vec(1.0) + lane as f32 * 0.01).as_dvec3();
            FastRay::new(&Ray::new(origin, target - origin)).unwrap()
        });
        let packet = bvh.closest4(rays.each_ref().map(Some), &mask);
        for (ray, got) in rays.iter().zip(packet) {
            let expected = brute_force_of(&triangles, ray, keeps);
            assert_eq!(
                bvh.closest(ray, &mask).map(|h| (h.id, h.hit.t)),
                expected,
                "ray {k}"
            );
            assert_eq!(got.map(|h| (h.id, h.hit.t)), expected, "packet {k}");
            assert_eq!(bvh.occluded(ray, &mask), expected.is_some(), "any hit {k}");
            let all = bvh.closest(ray, &AllTriangles).map(|h| h.id);
            through_cluster += usize::from(all.is_some_and(|id| !keeps(id)));
        }
    }
    assert!(through_cluster > 100, "{through_cluster}");
}

#[test]
fn closest_hit_equals_brute_force_on_random_soups() {
    let mut rng = Rng(7);
    let mut hits = 0;
    for n in [1, 2, 5, 40, 700, 9000] {
        let triangles = soup(&mut rng, n);
        let bvh = Bvh::build(&triangles);
        for k in 0..400 {
            // Unnormalised directions; every fourth ray has a finite interval.
            let origin = rng.vec(15.0).as_dvec3();
            let target = rng.vec(8.0).as_dvec3();
            let scale = 0.1 + 3.0 * rng.next() as f64;
            let mut ray = Ray::new(origin, (target - origin) * scale);
            if k % 4 == 0 {
                ray.t_min = 0.3 / scale;
                ray.t_max = 0.9 / scale;
            }
            let fast = FastRay::new(&ray).unwrap();
            let expected = brute_force(&triangles, &fast);
            let got = bvh.closest(&fast, &AllTriangles).map(|h| (h.id, h.hit.t));
            assert_eq!(got, expected, "soup of {n}, ray {k}");
            assert_eq!(bvh.occluded(&fast, &AllTriangles), expected.is_some());
            if let Some((_, t)) = got {
                assert!(t as f64 >= ray.t_min as f32 as f64 && t as f64 <= ray.t_max);
                hits += 1;
            }
        }
    }
    assert!(hits > 200, "too few hits ({hits}) to test anything");
}

#[test]
fn degenerate_triangles_are_never_hit() {
    let line = [Vec3::ZERO, Vec3::ONE, Vec3::splat(2.0)];
    let point = [Vec3::ONE; 3];
    let bvh = Bvh::build(&[line, point]);
    assert_eq!(bvh.node_count(), 0);
    for d in [DVec3::X, DVec3::ONE, DVec3::new(-1.0, 1.0, 0.0)] {
        let ray = Ray::new(DVec3::ONE - d, d);
        assert!(bvh
            .closest(&FastRay::new(&ray).unwrap(), &AllTriangles)
            .is_none());
    }
    // Mixed with a proper triangle, only that one is found.
    let good = [
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(3.0, -1.0, 1.0),
        Vec3::new(-1.0, 3.0, 1.0),
    ];
    let bvh = Bvh::build(&[line, good, point]);
    let ray = Ray::new(DVec3::new(1.0, 1.0, 5.0), DVec3::NEG_Z);
    assert_eq!(
        bvh.closest(&FastRay::new(&ray).unwrap(), &AllTriangles)
            .unwrap()
            .id,
        1
    );
}

#[test]
fn rays_parallel_to_a_triangle_miss_it() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let bvh = Bvh::build(&[tri]);
    for origin in [DVec3::new(-1.0, 0.25, 0.0), DVec3::new(-1.0, 0.25, 1e-3)] {
        let ray = Ray::new(origin, DVec3::X);
        assert!(bvh
            .closest(&FastRay::new(&ray).unwrap(), &AllTriangles)
            .is_none());
    }
}

#[test]
fn interval_limits_are_honoured() {
    let tri = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(2.0, -1.0, 0.0),
        Vec3::new(-1.0, 2.0, 0.0),
    ];
    let bvh = Bvh::build(&[tri]);
    let mut ray = Ray::new(DVec3::new(0.0, 0.0, 4.0), DVec3::new(0.0, 0.0, -2.0));
    let t = bvh
        .closest(&FastRay::new(&ray).unwrap(), &AllTriangles)
        .unwrap()
        .hit
        .t;
    assert_eq!(t, 2.0);
    ray.t_max = 1.99;
    assert!(bvh
        .closest(&FastRay::new(&ray).unwrap(), &AllTriangles)
        .is_none());
    ray.t_max = 3.0;
    ray.t_min = 2.01;
    assert!(bvh
        .closest(&FastRay::new(&ray).unwrap(), &AllTriangles)
        .is_none());
    ray.t_min = 3.5;
    assert!(FastRay::new(&ray).is_none(), "empty interval");
    ray.t_min = f64::NAN;
    assert!(FastRay::new(&ray).is_none(), "NaN bound");
}

#[test]
fn coincident_triangles_build_a_bounded_tree() {
    // Many copies of one triangle: no axis to bin on, so median splits.
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let bvh = Bvh::build(&vec![tri; 1000]);
    let ray = Ray::new(DVec3::new(0.2, 0.2, 1.0), DVec3::NEG_Z);
    let hit = bvh
        .closest(&FastRay::new(&ray).unwrap(), &AllTriangles)
        .unwrap();
    assert_eq!(hit.hit.t, 1.0);
    assert!(bvh
        .nodes
        .iter()
        .flat_map(|n| n.children)
        .all(|c| c.count as usize <= MAX_LEAF));
}

/// `closest4` must give bit for bit what `closest` gives ray by ray, and `occluded4` what
/// `occluded` does.
fn assert_packet_matches(bvh: &Bvh, rays: [Option<FastRay>; 4], what: &str) -> usize {
    let key = |h: Option<BvhHit>| {
        h.map(|h| {
            (
                h.id,
                h.hit.t.to_bits(),
                h.hit.u.to_bits(),
                h.hit.v.to_bits(),
            )
        })
    };
    let got = bvh.closest4([0, 1, 2, 3].map(|i| rays[i].as_ref()), &AllTriangles);
    let blocked = bvh.occluded4([0, 1, 2, 3].map(|i| rays[i].as_ref()), &AllTriangles);
    let mut hits = 0;
    for ((r, got), blocked) in rays.iter().zip(got).zip(blocked) {
        let expected = r.as_ref().and_then(|r| bvh.closest(r, &AllTriangles));
        assert_eq!(key(got), key(expected), "{what}");
        let single = r.as_ref().is_some_and(|r| bvh.occluded(r, &AllTriangles));
        assert_eq!(blocked, single, "{what}: any hit");
        hits += usize::from(expected.is_some());
    }
    hits
}

/// Shadow rays of 2x2 quads of surface points towards a point light (segments ending at
/// the light) and a directional one (parallel rays): `occluded4` answers each as `occluded`
/// does, through soups where some are blocked and some are not, and with masks.
#[test]
fn shadow_packets_are_blocked_exactly_as_single_rays() {
    let mut rng = Rng(23);
    let (mut blocked, mut free) = (0, 0);
    for n in [5, 200, 5000] {
        let triangles = soup(&mut rng, n);
        let bvh = Bvh::build(&triangles);
        let mask = TriangleMask::by_id(&bvh, |id| id % 3 != 1);
        for k in 0..400 {
            let light = rng.vec(14.0).as_dvec3();
            let corner = rng.vec(12.0).as_dvec3();
            let step = [1e-3, 0.05, 0.5][k % 3];
            let rays = [(0.0, 0.0), (step, 0.0), (0.0, step), (step, step)].map(|(x, z)| {
                let from = corner + DVec3::new(x, 0.0, z);
                let ray = if k % 2 == 0 {
                    Ray {
                        t_max: 1.0,
                        ..Ray::new(from, light - from)
                    }
                } else {
                    Ray::new(from, light)
                };
                FastRay::new(&ray)
            });
            let lanes = [0, 1, 2, 3].map(|i| rays[i].as_ref());
            let got = bvh.occluded4(lanes, &AllTriangles);
            let masked = bvh.occluded4(lanes, &mask);
            for (r, (got, masked)) in rays.iter().zip(got.into_iter().zip(masked)) {
                let r = r.as_ref().unwrap();
                assert_eq!(got, bvh.occluded(r, &AllTriangles), "soup {n}, quad {k}");
                assert_eq!(masked, bvh.occluded(r, &mask), "soup {n}, quad {k}, masked");
                if got {
                    blocked += 1;
                } else {
                    free += 1;
                }
            }
        }
    }
    assert!(
        blocked > 500 && free > 500,
        "{blocked} blocked, {free} free"
    );
}

#[test]
fn packets_find_exactly_the_single_ray_hits() {
    let mut rng = Rng(11);
    let mut hits = 0;
    for n in [1, 3, 60, 2000, 20000] {
        let triangles = soup(&mut rng, n);
        let bvh = Bvh::build(&triangles);
        for k in 0..300 {
            // A pinhole quad: one origin, four directions a small angle apart (an
            // occasional ray of the quad set far off, or missing, or with an interval).
            let origin = rng.vec(15.0).as_dvec3();
            let target = rng.vec(8.0).as_dvec3();
            let spread = [1e-4, 1e-2, 0.3][k % 3];
            let mut rays = [0; 4].map(|_| {
                let d = (target - origin).normalize() + rng.vec(spread).as_dvec3();
                let mut ray = Ray::new(origin, d * (0.5 + rng.next() as f64));
                if k % 7 == 0 {
                    ray.t_min = 5.0;
                    ray.t_max = 20.0;
                }
                FastRay::new(&ray)
            });
            match k % 10 {
                1 => rays[2] = None,
                2 => rays[1] = FastRay::new(&Ray::new(origin, -(target - origin))),
                3 => {
                    rays[3] =
                        FastRay::new(&Ray::new(rng.vec(15.0).as_dvec3(), rng.vec(1.0).as_dvec3()))
                }
                _ => {}
            }
            hits += assert_packet_matches(&bvh, rays, &format!("soup of {n}, quad {k}"));
        }
    }
    assert!(hits > 1000, "too few hits ({hits}) to test anything");
}

#[test]
fn packets_and_single_rays_break_ties_alike() {
    // Stacked copies of a triangle and a grid of triangles sharing edges: every ray
    // meets several triangles at exactly the same `t`; the lowest stored index wins.
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let mut triangles = vec![tri; 300];
    for i in 0..20 {
        for j in 0..20 {
            let c = Vec3::new(i as f32, j as f32, -1.0);
            triangles.push([c, c + Vec3::X, c + Vec3::Y]);
            triangles.push([c + Vec3::X, c + Vec3::ONE - Vec3::Z, c + Vec3::Y]);
        }
    }
    let bvh = Bvh::build(&triangles);
    let mut rng = Rng(5);
    let mut hits = 0;
    for k in 0..400 {
        let origin = DVec3::new(0.3, 0.3, 4.0) + rng.vec(0.5).as_dvec3() * 4.0;
        let target = DVec3::new(rng.next() as f64 * 20.0, rng.next() as f64 * 20.0, -1.0);
        // Pixel-like steps, some of them through shared edges and vertices.
        let step = [0.0, 0.5, 1.0][k % 3];
        let rays = [(0.0, 0.0), (step, 0.0), (0.0, step), (step, step)]
            .map(|(x, y)| FastRay::new(&Ray::new(origin, target + DVec3::new(x, y, 0.0) - origin)));
        hits += assert_packet_matches(&bvh, rays, &format!("ray {k}"));
    }
    assert!(hits > 1000);
    // The stacked copies: the same one of the 300 wins (the first stored), whatever the
    // ray, the order of traversal depending on the ray's direction.
    let ids: Vec<u32> = [
        DVec3::NEG_Z,
        DVec3::new(0.3, 0.2, -1.0),
        DVec3::new(-0.2, -0.1, -1.0),
    ]
    .map(|d| {
        let ray = FastRay::new(&Ray::new(DVec3::new(0.2, 0.2, 0.0) - d, d)).unwrap();
        bvh.closest(&ray, &AllTriangles).unwrap().id
    })
    .to_vec();
    assert!(
        ids[0] < 300 && ids.iter().all(|&id| id == ids[0]),
        "{ids:?}"
    );
}

#[test]
fn boxes_apart_from_every_leaf_are_apart_from_every_triangle() {
    let mut rng = Rng(7);
    let triangles = soup(&mut rng, 300);
    let bvh = Bvh::build(&triangles);
    let (mut apart, mut root_only) = (0, 0);
    for _ in 0..4000 {
        let (c, half) = (rng.vec(12.0).as_dvec3(), rng.vec(1.0).abs().as_dvec3());
        let (min, max) = (c - half, c + half);
        let touched = triangles.iter().any(|t| {
            let lo = t[0].min(t[1]).min(t[2]).as_dvec3();
            let hi = t[0].max(t[1]).max(t[2]).as_dvec3();
            lo.cmple(max).all() && hi.cmpge(min).all()
        });
        if !bvh.leaves_overlap(min, max) {
            assert!(!touched, "box [{min}, {max}] touches a triangle");
            apart += 1;
            root_only += usize::from(bvh.root_overlaps(min, max));
        } else {
            assert!(bvh.root_overlaps(min, max));
        }
    }
    // Both outcomes occur, and the leaves reject boxes inside the root's box.
    assert!(apart > 100 && root_only > 10, "{apart} {root_only}");
    assert!(bvh.leaves_overlap(DVec3::splat(f64::NAN), DVec3::ZERO));
    assert!(!Bvh::build(&[]).leaves_overlap(DVec3::ZERO, DVec3::ONE));
}

#[test]
fn four_segments_meet_a_box_exactly_when_each_does_alone() {
    let mut rng = Rng(11);
    let segment = |rng: &mut Rng| {
        let origin = rng.vec(6.0).as_dvec3();
        // Some directions with a zero component, some segments of zero length.
        let mut direction = rng.vec(4.0).as_dvec3();
        match (rng.next() * 4.0) as u32 {
            0 => direction.y = 0.0,
            1 => direction = DVec3::ZERO,
            _ => {}
        }
        NearSegment::new(origin, direction, f64::from(rng.next()) * 0.5).unwrap()
    };
    let (mut met, mut missed) = (0, 0);
    for _ in 0..2000 {
        let lanes: [NearSegment; 4] = std::array::from_fn(|_| segment(&mut rng));
        let present = (rng.next() * 16.0) as u32;
        let four = NearSegments4::new(std::array::from_fn(|i| {
            (present >> i & 1 == 1).then_some(&lanes[i])
        }));
        let (c, half) = (rng.vec(3.0), rng.vec(3.0).abs());
        let mask = four.meets(c - half, c + half);
        for (i, lane) in lanes.iter().enumerate() {
            let alone = present >> i & 1 == 1 && lane.meets(c - half, c + half);
            assert_eq!(mask >> i & 1 == 1, alone, "lane {i}");
            if alone {
                met += 1;
            } else {
                missed += 1;
            }
        }
    }
    // Both outcomes occur often (about 5 % of the present lanes meet their box).
    assert!(met > 100 && missed > 1000, "{met} {missed}");
}

/// Without a bound, the ordered walk of four segments visits each lane's triangles
/// exactly once each, and exactly those of the leaves a tree-order walk of the lane's
/// segment alone meets (empty lanes: none); with a bound, a lane visits no triangle
/// beyond it: after `visit` returns a bound of 0 for a lane, the lane sees only
/// triangles of leaves its segment enters at its start.
#[test]
fn ordered_walks_visit_each_lane_s_leaves_and_stop_at_the_bound() {
    let mut rng = Rng(13);
    let (mut visits, mut bounded) = (0, 0);
    for n in [1, 40, 700] {
        let triangles = soup(&mut rng, n);
        let bvh = Bvh::build(&triangles);
        // The box of each stored triangle's leaf.
        let mut leaf_boxes = vec![(bvh.root_bounds.min, bvh.root_bounds.max); bvh.triangles.len()];
        for node in &bvh.nodes {
            for (k, child) in node.children.iter().enumerate() {
                let first = child.index as usize;
                leaf_boxes[first..first + child.count as usize].fill(node.child_box(k));
            }
        }
        for _ in 0..200 {
            let base = rng.vec(12.0).as_dvec3();
            let lanes: [NearSegment; 4] = std::array::from_fn(|_| {
                let origin = base + rng.vec(1.0).as_dvec3();
                NearSegment::new(origin, rng.vec(8.0).as_dvec3(), f64::from(rng.next())).unwrap()
            });
            let present = (rng.next() * 16.0) as u32;
            let four = NearSegments4::new(std::array::from_fn(|i| {
                (present >> i & 1 == 1).then_some(&lanes[i])
            }));
            let mut seen: Vec<(usize, usize)> = Vec::new();
            bvh.visit_near_segments4(&four, |lane, stored| {
                seen.push((lane, stored));
                f32::MAX
            });
            seen.sort_unstable();
            let mut alone: Vec<(usize, usize)> = Vec::new();
            for (i, lane) in lanes
                .iter()
                .enumerate()
                .filter(|(i, _)| present >> i & 1 == 1)
            {
                bvh.walk_leaves(
                    |min, max| lane.meets(min, max),
                    |leaf| {
                        let first = leaf.index as usize;
                        alone.extend((first..first + leaf.count as usize).map(|t| (i, t)));
                        false
                    },
                );
            }
            // The root leaf of a one-triangle tree is entered by `walk_leaves` unasked.
            if bvh.root.count > 0 {
                let root = bvh.root_bounds;
                alone.retain(|&(i, _)| lanes[i].meets(root.min, root.max));
            }
            alone.sort_unstable();
            assert_eq!(seen, alone);
            visits += seen.len();
            // A bound of 0 after the first visit of each lane: what the lane sees
            // afterwards lies in leaves whose padded box its segment enters at its start.
            let mut stopped = [false; 4];
            bvh.visit_near_segments4(&four, |lane, stored| {
                if stopped[lane] {
                    let (min, max) = leaf_boxes[stored];
                    let alone = NearSegments4::new([Some(&lanes[lane]), None, None, None]);
                    assert_eq!(alone.entries(min, max)[0], 0.0);
                    bounded += 1;
                }
                stopped[lane] = true;
                0.0
            });
        }
    }
    assert!(visits > 1000 && bounded > 10, "{visits} {bounded}");
}

#[test]
fn nodes_are_one_cache_line() {
    assert_eq!(std::mem::size_of::<Node>(), 64);
}
