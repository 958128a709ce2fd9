//! Projection triangles whose rays form a one-parameter family, drawn exactly as strips: two
//! of the three vertices share their base point and ray (the pole rows of a grid over a
//! sphere, Vallance 2005, 6.3).
//!
//! With vertices `j` and `k` equal, the ray at barycentrics `b` depends on the weight `w` of
//! the third vertex `i` only: `ray(w, t) = P(w) + t D(w)` with `P(w) = p_j + w (p_i - p_j)`
//! and `D(w) = n_j + w (n_i - n_j)`. The triangle sweeps a ruled surface, no volume, so no
//! scene point has a cubic with isolated roots (every `t` is one, or none is) and no shape
//! can be formed; yet every pixel sees along its ray. The pixels of one `w` lie on a line
//! of the screen triangle parallel to the edge `jk`, and all see along the same ray.
//!
//! Which rays hit a scene triangle `s1 s2 s3` at `t >= 0` is decided exactly on `[0, 1]`:
//! the ray meets the line of edge `s_a s_b` where `g_ab(w) = det[P(w) - s_a, s_b - s_a,
//! D(w)]` vanishes, a quadratic in `w`; a ray not parallel to the plane hits inside the
//! triangle exactly where the three `g` have one sign (each is the plane's edge function at
//! the hit times `-|n|^2 / (n . D)`, the same factor for all three), and in front where
//! `t = n . (s1 - P(w)) / n . D(w)` (linear over linear) is `>= 0`. So the set of `w` that
//! see the triangle is a union of intervals whose ends are roots of the three quadratics
//! and the two linear terms. Between consecutive roots nothing changes sign: the ray at the
//! middle decides for the whole interval. Each interval `[w0, w1]` is drawn as the strip of
//! the screen triangle between the lines of `w0` and `w1`, and the resolver finishes every
//! fragment on its own projector as for any shape.
//!
//! Degenerate cases: a scene triangle in the plane of a flat fan (every `g` zero) is seen
//! edge-on, by no ray, as by the ray caster; a ray that only grazes the scene triangle (a
//! double root) is an interval of zero width, drawn as nothing; a fan whose vertices `j`,
//! `k` differ by less than [`FAN_TOL`] of the triangle's size is treated as exact (its rays
//! differ from the pixels' own projectors by that much, far below a pixel).

use glam::{DVec2, DVec3};

use super::clip::DOMAIN_MARGIN;
use super::edge_path::OutlinePoint;
use super::resolve::plane_hit;
use crate::geometry::{solve_quadratic, Ray};
use crate::projection::ProjectionTriangleCache;

/// How close (relative to the triangle's base size and ray length) two vertices must be
/// for the triangle to be drawn as a fan.
pub const FAN_TOL: f64 = 1e-9;

/// The rays of a projection triangle with two equal vertices (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayFan {
    /// The vertex that differs (`i`) and the two equal ones (`j`, `k`), as indices 0..3.
    apex: usize,
    pair: [usize; 2],
    /// `P(w) = origin + w origin_step`, `D(w) = direction + w direction_step`.
    origin: DVec3,
    origin_step: DVec3,
    direction: DVec3,
    direction_step: DVec3,
}

/// The barycentrics `(u, v)` of the projection triangle's vertices 0, 1 and 2.
const CORNERS: [DVec2; 3] = [DVec2::ZERO, DVec2::X, DVec2::Y];

impl RayFan {
    /// The fan of the projection triangle of `cache`, `None` unless two of its vertices
    /// are equal (within [`FAN_TOL`]) and the third is not.
    pub fn of(cache: &ProjectionTriangleCache) -> Option<RayFan> {
        let p = CORNERS.map(|b| cache.tripoint(b.x, b.y));
        let n = CORNERS.map(|b| cache.trinorm(b.x, b.y));
        let size = (p[1] - p[0])
            .length()
            .max((p[2] - p[0]).length())
            .max((p[2] - p[1]).length());
        let length = n.iter().map(|d| d.length()).fold(0.0, f64::max);
        let equal = |a: usize, b: usize| {
            p[a].distance(p[b]) <= FAN_TOL * size && n[a].distance(n[b]) <= FAN_TOL * length
        };
        let apex = (0..3).find(|&i| equal((i + 1) % 3, (i + 2) % 3))?;
        let pair = [(apex + 1) % 3, (apex + 2) % 3];
        if equal(apex, pair[0]) || !(size > 0.0 || length > 0.0) {
            return None;
        }
        let j = pair[0];
        Some(RayFan {
            apex,
            pair,
            origin: p[j],
            origin_step: p[apex] - p[j],
            direction: n[j],
            direction_step: n[apex] - n[j],
        })
    }

    /// The ray of weight `w`.
    fn ray(&self, w: f64) -> Ray {
        Ray::new(
            self.origin + w * self.origin_step,
            self.direction + w * self.direction_step,
        )
    }

    /// Where the ray of weight `w` hits the scene triangle `scene` at `t >= 0`: its `t`.
    fn hit(&self, scene: [DVec3; 3], w: f64) -> Option<f64> {
        let (t, u, v) = plane_hit(&self.ray(w), scene)?;
        (t >= 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0).then_some(t)
    }

    /// The weights in `(0, 1)` where a ray starts or stops seeing `scene` (module doc),
    /// unsorted, into `out`.
    fn breaks(&self, scene: [DVec3; 3], out: &mut Vec<f64>) {
        let (a, b) = (self.origin, self.origin_step);
        let (c, e) = (self.direction, self.direction_step);
        let mut keep = |w: f64| {
            if w > 0.0 && w < 1.0 {
                out.push(w);
            }
        };
        for (s, edge) in [(0, 1), (1, 2), (2, 0)].map(|(x, y)| (scene[x], scene[y] - scene[x])) {
            // det[P(w) - s, edge, D(w)] = (A + w B) . (edge x (C + w E)).
            let (ec, ee) = (edge.cross(c), edge.cross(e));
            let (a0, b0) = (a - s, b);
            let roots = solve_quadratic(b0.dot(ee), a0.dot(ee) + b0.dot(ec), a0.dot(ec));
            roots.iter().for_each(&mut keep);
        }
        let normal = (scene[1] - scene[0]).cross(scene[2] - scene[0]);
        // n . (s1 - P(w)) and n . D(w): each zero at one weight, if any.
        for (constant, slope) in [
            (normal.dot(scene[0] - a), -normal.dot(b)),
            (normal.dot(c), normal.dot(e)),
        ] {
            if slope != 0.0 {
                keep(-constant / slope);
            }
        }
    }

    /// Calls `draw` with the outline of each strip of the screen triangle whose rays see
    /// the scene triangle `scene` at `t >= 0` (module doc), in barycentrics with the depth
    /// of each corner's ray. `breaks` is reused storage. Returns the number of strips.
    pub fn outlines(
        &self,
        scene: [DVec3; 3],
        breaks: &mut Vec<f64>,
        mut draw: impl FnMut(&[OutlinePoint]),
    ) -> u64 {
        breaks.clear();
        breaks.push(0.0);
        self.breaks(scene, breaks);
        breaks.push(1.0);
        breaks.sort_unstable_by(f64::total_cmp);
        let mut strips = 0;
        let mut open: Option<f64> = None;
        for pair in breaks.windows(2) {
            let (w0, w1) = (pair[0], pair[1]);
            let seen = w1 > w0 && self.hit(scene, 0.5 * (w0 + w1)).is_some();
            match (seen, open) {
                (true, None) => open = Some(w0),
                (false, Some(start)) => {
                    draw(&self.strip(scene, start, w0));
                    strips += 1;
                    open = None;
                }
                _ => {}
            }
        }
        if let Some(start) = open {
            draw(&self.strip(scene, start, 1.0));
            strips += 1;
        }
        strips
    }

    /// The strip of weights `w0..w1`, widened by [`DOMAIN_MARGIN`] on either side within
    /// `[0, 1]`: its corners on the edges from the two equal vertices to the apex, each
    /// with the depth of its ray's hit with the scene triangle's plane (clamped to
    /// `t >= 0`, which the interval's rays satisfy up to rounding). The margin does for
    /// the strips of two scene triangles sharing an edge what it does for two projection
    /// triangles: their ends are computed from different quadratics and differ by
    /// rounding, and a line of pixel centres exactly on the edge's ray (a symmetric scene
    /// seen along its axis) fell into the gap; with it both strips cover that line, and
    /// the resolver gives each fragment to the triangle its ray hits.
    fn strip(&self, scene: [DVec3; 3], w0: f64, w1: f64) -> [OutlinePoint; 4] {
        let (w0, w1) = ((w0 - DOMAIN_MARGIN).max(0.0), (w1 + DOMAIN_MARGIN).min(1.0));
        let apex = CORNERS[self.apex];
        let depth = |w: f64| {
            plane_hit(&self.ray(w), scene)
                .map(|(t, _, _)| t.max(0.0))
                .unwrap_or(0.0)
        };
        let corner = |side: usize, w: f64| {
            let uv = CORNERS[self.pair[side]].lerp(apex, w);
            OutlinePoint {
                u: uv.x,
                v: uv.y,
                t: depth(w),
            }
        };
        [corner(0, w0), corner(0, w1), corner(1, w1), corner(1, w0)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn fan(p: [DVec3; 3], n: [DVec3; 3]) -> Option<RayFan> {
        RayFan::of(&ProjectionTriangleCache::new(p, n))
    }

    /// A pole-row triangle of an inward-looking sphere: vertices 1 and 2 both at the pole
    /// (0, 1, 0) looking at the centre, vertex 0 further down, also looking at the centre.
    fn pole() -> ([DVec3; 3], [DVec3; 3]) {
        let pole = DVec3::Y;
        let low = DVec3::new(0.5, 0.8660254037844386, 0.0);
        ([low, pole, pole], [-low, -pole, -pole])
    }

    #[test]
    fn only_two_equal_vertices_make_a_fan() {
        let (p, n) = pole();
        let rays = fan(p, n).expect("a fan");
        assert_eq!((rays.apex, rays.pair), (0, [1, 2]));
        // Rotated: the apex is found wherever it is.
        let rays = fan([p[1], p[0], p[2]], [n[1], n[0], n[2]]).expect("a fan");
        assert_eq!(rays.apex, 1);
        // Three distinct vertices, or three equal ones, or equal points with other rays.
        assert!(fan([p[0], p[1], DVec3::X], [n[0], n[1], -DVec3::X]).is_none());
        assert!(fan([p[1]; 3], [n[1]; 3]).is_none());
        assert!(fan(p, [n[0], n[1], DVec3::X]).is_none());
    }

    proptest! {
        /// Every pixel position's own projector (the projection triangle's interpolated ray)
        /// hits the scene triangle at `t >= 0` exactly where a strip covers it, away from
        /// the strips' edges.
        #[test]
        fn strips_cover_exactly_the_rays_that_hit(
            corners in proptest::array::uniform3(
                (-0.8..0.8f64, -0.8..0.9f64, -0.8..0.8f64)
            ),
            samples in proptest::collection::vec((0.0..1.0f64, 0.0..1.0f64), 64),
        ) {
            let (p, n) = pole();
            let rays = fan(p, n).unwrap();
            let cache = ProjectionTriangleCache::new(p, n);
            let scene = corners.map(|(x, y, z)| DVec3::new(x, y, z));
            let mut strips = Vec::new();
            rays.outlines(scene, &mut Vec::new(), |s| strips.push([s[0], s[1], s[2], s[3]]));
            for (a, b) in samples {
                let (u, v) = if a + b <= 1.0 { (a, b) } else { (1.0 - a, 1.0 - b) };
                // The apex is vertex 0, so the weight of a point is 1 - u - v.
                let w = 1.0 - u - v;
                let near_an_end = strips.iter().any(|s| {
                    let (w0, w1) = (1.0 - s[0].u - s[0].v, 1.0 - s[1].u - s[1].v);
                    (w - w0).abs() < 1e-8 || (w - w1).abs() < 1e-8
                });
                if near_an_end {
                    continue;
                }
                let covered = strips.iter().any(|s| {
                    let (w0, w1) = (1.0 - s[0].u - s[0].v, 1.0 - s[1].u - s[1].v);
                    w0 <= w && w <= w1
                });
                let ray = Ray::new(cache.tripoint(u, v), cache.trinorm(u, v));
                let hit = plane_hit(&ray, scene)
                    .is_some_and(|(t, b1, b2)| t >= 0.0 && b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0);
                prop_assert_eq!(covered, hit, "{:?} at ({}, {})", scene, u, v);
            }
        }
    }

    #[test]
    fn a_triangle_across_the_fan_gives_one_strip_with_its_depths() {
        let (p, n) = pole();
        let rays = fan(p, n).unwrap();
        // A wall at y = 0.5 between x = 0.1 and x = 0.3, across the fan's plane z = 0.
        let scene = [
            DVec3::new(0.1, 0.5, -1.0),
            DVec3::new(0.3, 0.5, -1.0),
            DVec3::new(0.2, 0.5, 1.0),
        ];
        let mut strips = Vec::new();
        let count = rays.outlines(scene, &mut Vec::new(), |s| strips.push(s.to_vec()));
        assert_eq!(count, 1);
        for corner in &strips[0] {
            let cache = ProjectionTriangleCache::new(p, n);
            let point = cache.ray_point(corner.u, corner.v, corner.t);
            assert!((point.y - 0.5).abs() < 1e-12, "{point}");
            assert!((0.1 - 1e-9..=0.3 + 1e-9).contains(&point.x), "{point}");
        }
    }
}
