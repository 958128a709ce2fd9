//! The stage run on each rasterised fragment before its z-test: the exact hit of the pixel
//! sample's projector with the fragment's scene triangle (or a neighbour's).
//!
//! A fragment's key names its projection triangle and scene triangle. Its depth and scene
//! barycentrics are not interpolated over the polygon (the map from screen to scene is not
//! affine, so interpolation would be wrong inside every curved shape): the pixel sample's
//! projector is intersected with the scene triangle's plane, in f64. The polygon's vertices
//! carry the terms of that intersection that are affine in pixel position ([`super::hit_terms`]),
//! so the rasteriser hands each fragment the terms of its own projector and the stage finishes
//! the hit with a division ([`super::gbuffer::GBuffer::draw`]). Only a fragment outside its
//! own triangle takes the general path, which builds the projector and intersects it with
//! the neighbours ([`Resolver::hit`]).
//!
//! - Inside the triangle at `t >= 0`: an **exact** fragment; the z-test compares exact ray
//!   parameters `t`, and the frame's depth is `t |trinorm|`, the distance the ray caster
//!   writes for the same projector.
//! - Outside it across an edge no other triangle shares (a silhouette): discarded, so a
//!   chord that bulges outside the true curved edge draws nothing wrong.
//! - Outside it only across edges another triangle shares, inside the **neighbour** across
//!   one of them: an exact fragment of the neighbour (its key is rewritten). Where a chord
//!   cuts inside a curved edge, the pixels between chord and curve belong to the neighbour,
//!   whose own polygon misses them, while this triangle's chord bulges over them.
//! - Outside it only across shared edges and outside those neighbours too (a pixel near a
//!   vertex where several triangles meet): a **crack filler**, shaded at the nearest point
//!   of the triangle (barycentrics clamped) with its depth pushed behind every exact
//!   fragment (`+ CRACK_FILL_DEPTH`), so that it never hides an exact fragment.
//! - Behind the view plane, or a projector parallel to the plane: discarded.
//!
//! A polygon keyed with [`PIXEL_TESTED`] (the band of a pair split at a degenerate depth,
//! `degenerate_band`) is not an outline of its scene triangle but a superset of where it may
//! be seen: its fragments inside the triangle are exact hits like any other, and every
//! fragment outside it is discarded (no neighbour, no crack filler: the pixel need not be
//! near the triangle at all). The flag is taken off the key of a kept fragment.

use glam::{DVec2, DVec3};

use super::hit_terms;
use super::outline::ProjectionTriangle;
use super::scene_geometry::SceneGeometry;
use super::screen_map::ScreenMap;
use crate::geometry::Ray;
/// Added to the depth of crack fillers: behind any exact fragment (depths are ray
/// parameters, far below this for any scene within the rasteriser's limits).
pub(super) const CRACK_FILL_DEPTH: f64 = 1e200;

/// The bit of a polygon's key that marks it as pixel tested (module doc). Keys are
/// `projection << 32 | scene triangle`, and projection indices are far below `2^31`.
pub(super) const PIXEL_TESTED: u64 = 1 << 63;

/// Finds the hit of a keyed fragment (module doc).
pub struct Resolver<'a> {
    /// The projection triangles, numbered as the keys' projection indices: their screen
    /// maps are read in place ([`Resolver::map`]), not copied out per render.
    pub triangles: &'a [ProjectionTriangle],
    pub scene: &'a SceneGeometry,
    /// Where in each pixel this pass samples, in `[0, 1)^2` (`(0.5, 0.5)`: the centre). The
    /// polygons of the pass are drawn moved so that their pixel centres are these samples
    /// (see `PolygonBatch::translated`).
    pub sample: DVec2,
}

/// A fragment's hit: the projector, the key of the triangle hit (the fragment's own, or a
/// neighbour's), the ray parameter, the barycentrics (clamped into the triangle for a crack
/// filler) and whether it is exact.
#[derive(Debug, Clone, Copy)]
pub struct FragmentHit {
    pub ray: Ray,
    pub key: u64,
    pub t: f64,
    pub barycentric: DVec2,
    pub exact: bool,
}

impl Resolver<'_> {
    /// The screen map of projection triangle `projection`, `None` past the last.
    pub fn map(&self, projection: usize) -> Option<&ScreenMap> {
        self.triangles.get(projection).map(|t| &t.map)
    }

    /// The image position of pixel `(x, y)`'s sample.
    pub fn position(&self, x: u32, y: u32) -> DVec2 {
        DVec2::new(f64::from(x), f64::from(y)) + self.sample
    }

    /// The hit of the projector through pixel position `pixel` of the projection triangle
    /// named by `key` with the scene triangle named by `key`, or with a neighbour of it
    /// (module doc); `None` for a discarded fragment.
    pub fn hit(&self, key: u64, pixel: DVec2) -> Option<FragmentHit> {
        let map = self.map((key >> 32) as usize)?;
        let k = (key & u64::from(u32::MAX)) as usize;
        let ray = map.ray(pixel)?;
        let (t, u, v) = plane_hit(&ray, self.scene.corners(k))?;
        if t < 0.0 {
            return None;
        }
        let outside = outside_edges(u, v);
        if outside == 0 {
            return Some(FragmentHit {
                ray,
                key,
                t,
                barycentric: DVec2::new(u, v),
                exact: true,
            });
        }
        if outside & !self.scene.shared_edges[k] != 0 {
            return None;
        }
        // Across a shared edge: the pixel may be the neighbour's, missed by the neighbour's
        // own polygon where its chord cuts inside the curved edge.
        // Where several triangles meet at the edge (non-manifold), each is tried in turn.
        for edge in (0..3).filter(|e| outside & (1 << e) != 0) {
            for n in self.scene.across(k, edge) {
                let Some((t, u, v)) = plane_hit(&ray, self.scene.corners(n)) else {
                    continue;
                };
                if t >= 0.0 && outside_edges(u, v) == 0 {
                    return Some(FragmentHit {
                        ray,
                        key: (key & !u64::from(u32::MAX)) | n as u64,
                        t,
                        barycentric: DVec2::new(u, v),
                        exact: true,
                    });
                }
            }
        }
        Some(FragmentHit {
            ray,
            key,
            t,
            barycentric: clamp_to_triangle(u, v),
            exact: false,
        })
    }

    /// The stage of the rasteriser for a fragment of the shape keyed `key` at pixel
    /// `(x, y)` whose hit terms there solve to `solved` ([`super::hit_terms::solve`], not
    /// yet tested for finite values): the key of the triangle hit (its own, or a
    /// neighbour's), its depth (the exact `t`, pushed back for a crack filler) and the hit's
    /// barycentrics; `None` to discard it (module doc, [`Stage::of`]).
    #[inline]
    pub fn staged(
        &self,
        key: u64,
        solved: (f64, f64, f64),
        x: u32,
        y: u32,
    ) -> Option<(u64, f64, DVec2)> {
        let (t, b1, b2) = solved;
        match Stage::of(solved) {
            Stage::Exact => Some((key & !PIXEL_TESTED, t, DVec2::new(b1, b2))),
            Stage::Discarded => None,
            Stage::Outside if key & PIXEL_TESTED != 0 => None,
            Stage::Outside => self.hit(key, self.position(x, y)).map(|hit| {
                let behind = if hit.exact { 0.0 } else { CRACK_FILL_DEPTH };
                (hit.key, hit.t + behind, hit.barycentric)
            }),
        }
    }
}

/// What the stage does with a fragment's solved hit `(t, b1, b2)` (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// Finite, `t >= 0`, inside its triangle (boundary included): kept as it is.
    Exact,
    /// A value not finite (a projector parallel to the plane), or behind the view plane.
    Discarded,
    /// Finite, in front, outside its triangle: resolved by [`Resolver::hit`].
    Outside,
}

impl Stage {
    /// The common case, an exact fragment, is decided first by one test of five
    /// comparisons without branches between them: `0 <= t < inf`, `b1 >= 0`, `b2 >= 0` and
    /// `b1 + b2 <= 1` hold for finite values exactly where `t >= 0` and [`outside_edges`]
    /// is 0, and fail for any NaN or infinity (every comparison with NaN is false, and an
    /// infinite `b1` or `b2` makes the sum infinite or NaN).
    #[inline(always)]
    fn of((t, b1, b2): (f64, f64, f64)) -> Stage {
        let in_front = (0.0..f64::INFINITY).contains(&t);
        if in_front & (b1 >= 0.0) & (b2 >= 0.0) & (b1 + b2 <= 1.0) {
            return Stage::Exact;
        }
        match hit_terms::finite((t, b1, b2)) {
            Some((t, _, _)) if t >= 0.0 => Stage::Outside,
            _ => Stage::Discarded,
        }
    }
}

/// Where `ray` meets the plane of triangle `[a, b, c]`: `(t, u, v)` with `u`, `v` the
/// barycentrics of `b` and `c`, unbounded (Moller-Trumbore without the inside tests).
/// `None` for a projector parallel to the plane, a degenerate triangle or non-finite input.
pub(crate) fn plane_hit(ray: &Ray, [a, b, c]: [DVec3; 3]) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (b - a, c - a);
    let p = ray.direction.cross(e2);
    let det = e1.dot(p);
    let inv = 1.0 / det;
    let s = ray.origin - a;
    let q = s.cross(e1);
    let (u, v, t) = (s.dot(p) * inv, ray.direction.dot(q) * inv, e2.dot(q) * inv);
    (det != 0.0 && u.is_finite() && v.is_finite() && t.is_finite()).then_some((t, u, v))
}

/// The edges of a triangle that a point with barycentrics `(u, v)` lies beyond, as bits of
/// `<V1V2, V1V3, V2V3>`: `v < 0` is beyond V1V2, `u < 0` beyond V1V3, `u + v > 1` beyond
/// V2V3. 0 for a point inside or on the boundary.
fn outside_edges(u: f64, v: f64) -> u8 {
    u8::from(v < 0.0) | (u8::from(u < 0.0) << 1) | (u8::from(u + v > 1.0) << 2)
}

/// The barycentrics of the point of the triangle nearest (in barycentric space) to `(u, v)`.
fn clamp_to_triangle(u: f64, v: f64) -> DVec2 {
    let (u, v) = (u.max(0.0), v.max(0.0));
    let sum = u + v;
    if sum > 1.0 {
        DVec2::new(u / sum, v / sum)
    } else {
        DVec2::new(u, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// [`Stage::of`] as the stage decided it before the single test: finite values first,
    /// then `t >= 0` and [`outside_edges`].
    fn stage_in_order(solved: (f64, f64, f64)) -> Stage {
        match hit_terms::finite(solved) {
            Some((t, b1, b2)) if t >= 0.0 && outside_edges(b1, b2) == 0 => Stage::Exact,
            Some((t, _, _)) if t < 0.0 => Stage::Discarded,
            None => Stage::Discarded,
            Some(_) => Stage::Outside,
        }
    }

    /// Values at and around the tests' boundaries, and the non-finite ones.
    const SPECIAL: [f64; 16] = [
        0.0,
        -0.0,
        5e-324,
        -5e-324,
        0.5,
        0.5 + f64::EPSILON / 2.0,
        1.0,
        1.0 + f64::EPSILON,
        1.0 - f64::EPSILON / 2.0,
        -1.0,
        2.0,
        f64::MAX,
        f64::MIN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];

    #[test]
    fn one_test_stages_as_the_tests_in_order_on_special_values() {
        let mut seen = [false; 3];
        for t in SPECIAL {
            for b1 in SPECIAL {
                for b2 in SPECIAL {
                    let stage = stage_in_order((t, b1, b2));
                    assert_eq!(Stage::of((t, b1, b2)), stage, "{t} {b1} {b2}");
                    seen[stage as usize] = true;
                }
            }
        }
        assert_eq!(seen, [true; 3]);
    }

    proptest! {
        #[test]
        fn one_test_stages_as_the_tests_in_order(
            t in prop_oneof![-2.0..2.0f64, proptest::num::f64::ANY],
            b1 in prop_oneof![-0.5..1.5f64, proptest::num::f64::ANY],
            b2 in prop_oneof![-0.5..1.5f64, proptest::num::f64::ANY],
        ) {
            prop_assert_eq!(Stage::of((t, b1, b2)), stage_in_order((t, b1, b2)));
        }
    }
}
