//! Projection triangles whose rays form a one-parameter family (two of the three vertices
//! share their base point and ray: [`RayFan`], whose module doc has the rays `ray(w, t) =
//! P(w) + t D(w)`), drawn exactly as strips: no scene point has a cubic with isolated roots
//! there, so no shape can be formed, yet every pixel sees along its ray, and the pixels of
//! one apex weight `w` lie on a line of the screen triangle, all seeing along the same ray.
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
//! `k` differ by less than [`FAN_TOL`](crate::projection::trilinear_fan::FAN_TOL) of the
//! triangle's size is treated as exact (its rays
//! differ from the pixels' own projectors by that much, far below a pixel).

use glam::DVec3;

use super::clip::DOMAIN_MARGIN;
use super::edge_path::OutlinePoint;
use super::resolve::plane_hit;
use crate::geometry::solve_quadratic;
pub use crate::projection::RayFan;

impl RayFan {
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
        let depth = |w: f64| {
            plane_hit(&self.ray(w), scene)
                .map(|(t, _, _)| t.max(0.0))
                .unwrap_or(0.0)
        };
        let corner = |side: usize, w: f64| {
            let uv = self.line_ends(w)[side];
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

    use crate::geometry::Ray;
    use crate::projection::trilinear_fan::pole_row as pole;
    use crate::projection::ProjectionTriangleCache;

    fn fan(p: [DVec3; 3], n: [DVec3; 3]) -> Option<RayFan> {
        RayFan::of(&ProjectionTriangleCache::new(p, n))
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
