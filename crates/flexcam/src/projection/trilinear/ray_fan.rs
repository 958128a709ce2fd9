//! Projection triangles whose rays form a one-parameter family: two of the three vertices
//! share their base point and ray (the pole rows of a grid over a sphere, Vallance 2005,
//! 6.3). The renderer draws them as strips (`render::trilinear::ray_fan`); here they are
//! described and inverted.
//!
//! With vertices `j` and `k` equal, the ray at barycentrics `b` depends on the weight `w` of
//! the third vertex `i` only: `ray(w, t) = P(w) + t D(w)` with `P(w) = p_j + w (p_i - p_j)`
//! and `D(w) = n_j + w (n_i - n_j)`. The triangle sweeps a ruled surface, no volume: the
//! cubic of every scene point vanishes identically ([`super::Solutions::is_every_t`]), and
//! a point on the surface is seen along a whole segment of the screen triangle, the line of
//! its `w` (parallel to the edge `jk`), every pixel of it seeing along the same ray.
//!
//! The inverse ([`RayFan::project_point`]): `q = ps - p_j = w A + t D(w)` (`A = p_i - p_j`)
//! holds where `(q - w A) x D(w) = 0`, a vector quadratic in `w`,
//! `-w^2 (A x E) + w (q x E - A x C) + q x C = 0` (`C = n_j`, `E = n_i - n_j`). Dotted with
//! its largest coefficient vector it is a scalar quadratic that is not identically zero and
//! that every solution satisfies; each of its roots in `[0, 1]` gives `t` by least squares
//! along `D(w)` and is kept where `P(w) + t D(w)` meets the point (relative
//! [`ON_RAY_TOL`]), which removes the roots the dot product let in.
//!
//! Degenerate cases (each tested): a point at the shared base point `p_j` is seen at `t = 0`
//! on the edge `jk`; a point off the surface has no solution; where all three coefficient
//! vectors vanish (every ray of the fan on one line through the point) nothing is listed;
//! `w = 1` is the apex alone, a point, not a segment; a ray of zero direction is skipped.

use glam::{DVec2, DVec3};

use super::point_projection::ProjectionTriangleCache;
use crate::geometry::{solve_quadratic, Ray};

/// How close (relative to the triangle's base size and ray length) two vertices must be
/// for the triangle to be treated as a fan.
pub const FAN_TOL: f64 = 1e-9;

/// How near (relative to the sizes involved) `P(w) + t D(w)` must come to the point for a
/// root of the inverse's quadratic to be a solution.
pub const ON_RAY_TOL: f64 = 1e-9;

/// The barycentrics `(u, v)` of the projection triangle's vertices 0, 1 and 2.
const CORNERS: [DVec2; 3] = [DVec2::ZERO, DVec2::X, DVec2::Y];

/// The rays of a projection triangle with two equal vertices (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayFan {
    /// The vertex that differs (`i`) and the two equal ones (`j`, `k`), as indices 0..3.
    pub(crate) apex: usize,
    pub(crate) pair: [usize; 2],
    /// `P(w) = origin + w origin_step`, `D(w) = direction + w direction_step`.
    pub(crate) origin: DVec3,
    pub(crate) origin_step: DVec3,
    pub(crate) direction: DVec3,
    pub(crate) direction_step: DVec3,
}

/// One solution of the fan's inverse: the point is on the ray of apex weight `w`, at `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FanSolution {
    /// The apex weight, in `[0, 1]`.
    pub w: f64,
    /// The ray parameter along the unnormalised `D(w)` (any sign).
    pub t: f64,
}

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

    /// The ray of apex weight `w`.
    pub fn ray(&self, w: f64) -> Ray {
        Ray::new(
            self.origin + w * self.origin_step,
            self.direction + w * self.direction_step,
        )
    }

    /// The barycentrics `(u, v)` of the two ends of the screen triangle's line of apex
    /// weight `w`: on the edges from the two equal vertices to the apex.
    pub fn line_ends(&self, w: f64) -> [DVec2; 2] {
        let apex = CORNERS[self.apex];
        self.pair.map(|j| CORNERS[j].lerp(apex, w))
    }

    /// Every `(w, t)` with `w` in `[0, 1]` whose ray reaches `point` (module doc), at most
    /// two, ascending in `w`.
    pub fn project_point(&self, point: DVec3) -> Vec<FanSolution> {
        let q = point - self.origin;
        let (a, c, e) = (self.origin_step, self.direction, self.direction_step);
        let coefficients = [-a.cross(e), q.cross(e) - a.cross(c), q.cross(c)];
        let Some(m) = coefficients
            .iter()
            .copied()
            .max_by(|x, y| x.length_squared().total_cmp(&y.length_squared()))
            .filter(|m| m.length_squared() > 0.0)
        else {
            return Vec::new();
        };
        let [qa, qb, qc] = coefficients.map(|k| k.dot(m));
        let mut out = Vec::new();
        for root in solve_quadratic(qa, qb, qc).iter() {
            // Roots within rounding of the ends belong to the triangle.
            let w = if (-1e-12..0.0).contains(&root) {
                0.0
            } else if (1.0..1.0 + 1e-12).contains(&root) {
                1.0
            } else {
                root
            };
            if !(0.0..=1.0).contains(&w) {
                continue;
            }
            let ray = self.ray(w);
            let d2 = ray.direction.length_squared();
            if d2 == 0.0 {
                continue;
            }
            let t = (point - ray.origin).dot(ray.direction) / d2;
            let miss = (ray.origin + t * ray.direction - point).length();
            let scale = point.abs().max_element()
                + ray.origin.abs().max_element()
                + (t * ray.direction).abs().max_element();
            if miss <= ON_RAY_TOL * scale {
                out.push(FanSolution { w, t });
            }
        }
        out
    }
}

/// A pole-row triangle of an inward-looking sphere, for tests: vertices 1 and 2 both at the
/// pole (0, 1, 0) looking at the centre, vertex 0 further down, also looking at the centre.
#[cfg(test)]
pub(crate) fn pole_row() -> ([DVec3; 3], [DVec3; 3]) {
    let pole = DVec3::Y;
    let low = DVec3::new(0.5, 0.8660254037844386, 0.0);
    ([low, pole, pole], [-low, -pole, -pole])
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn fan(p: [DVec3; 3], n: [DVec3; 3]) -> Option<RayFan> {
        RayFan::of(&ProjectionTriangleCache::new(p, n))
    }

    fn pole() -> ([DVec3; 3], [DVec3; 3]) {
        pole_row()
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

    #[test]
    fn a_point_at_the_shared_base_point_is_seen_at_zero_on_the_pair_edge() {
        let (p, n) = pole();
        let rays = fan(p, n).unwrap();
        assert_eq!(
            rays.project_point(p[1]),
            vec![FanSolution { w: 0.0, t: 0.0 }]
        );
        assert_eq!(rays.line_ends(0.0), [DVec2::X, DVec2::Y]);
    }

    #[test]
    fn a_point_off_the_fans_plane_has_no_solution() {
        let (p, n) = pole();
        let rays = fan(p, n).unwrap();
        // The fan lies in the plane z = 0.
        assert!(rays.project_point(DVec3::new(0.1, 0.2, 0.05)).is_empty());
    }

    #[test]
    fn a_fan_whose_rays_all_lie_on_one_line_lists_nothing() {
        // Base points along the y axis, every ray along it: each point of the line is on
        // every ray, no isolated solution.
        let p = [DVec3::Y, DVec3::ZERO, DVec3::ZERO];
        let n = [-DVec3::Y, -DVec3::Y * 2.0, -DVec3::Y * 2.0];
        let rays = fan(p, n).expect("a fan");
        assert!(rays.project_point(DVec3::new(0.0, -1.0, 0.0)).is_empty());
    }

    #[test]
    fn the_apex_ray_is_weight_one() {
        let (p, n) = pole();
        let rays = fan(p, n).unwrap();
        let point = p[0] + 0.7 * n[0];
        let solutions = rays.project_point(point);
        assert_eq!(solutions.len(), 1);
        assert!((solutions[0].w - 1.0).abs() < 1e-12 && (solutions[0].t - 0.7).abs() < 1e-12);
        let ends = rays.line_ends(solutions[0].w);
        assert!(ends[0].distance(ends[1]) < 1e-12);
    }

    proptest! {
        /// The inverse of `ray(w, t)`: a point on a fan's ray (planar or twisted fans) is
        /// found at that `w` and `t`, and every solution's ray reaches the point.
        #[test]
        fn project_point_inverts_the_ray(
            apex in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
            shared in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
            apex_ray in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
            shared_ray in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
            w in 0.0..1.0f64,
            t in 0.0..3.0f64,
        ) {
            let v = |(x, y, z): (f64, f64, f64)| DVec3::new(x, y, z);
            let (pi, pj, ni, nj) = (v(apex), v(shared), v(apex_ray), v(shared_ray));
            prop_assume!(pi.distance(pj) > 0.05 && (ni - nj).length() > 0.05);
            let rays = fan([pi, pj, pj], [ni, nj, nj]).unwrap();
            prop_assume!(rays.ray(w).direction.length() > 0.05);
            let point = rays.ray(w).at(t);
            let solutions = rays.project_point(point);
            let found = solutions
                .iter()
                .any(|s| (s.w - w).abs() < 1e-6 && (s.t - t).abs() < 1e-6 * (1.0 + t));
            prop_assert!(found, "w {} t {} -> {:?}", w, t, solutions);
            for s in &solutions {
                let miss = rays.ray(s.w).at(s.t).distance(point);
                prop_assert!(miss < 1e-8 * (1.0 + point.length()), "{:?} misses by {}", s, miss);
            }
        }
    }
}
