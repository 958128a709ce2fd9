//! Projection triangles whose rays all meet in one point, drawn exactly as central
//! projections (the inward-looking sphere of Vallance 2005, 6.3, whose rays all pass through its
//! centre).
//!
//! With every vertex ray through the focus `F` at one depth `t0 > 0` (`p_i + t0 n_i = F`),
//! every ray of the triangle passes through `F` at `t0`: `ray(b, t) = F + (1 - t / t0)
//! (P(b) - F)` with `P(b)` the base point. So a scene point `X` is seen at the barycentrics
//! of the base point on the line through `F` and `X`, and only there: scene to screen is a
//! central projection from `F`, as a pinhole camera's is from its eye, with the difference
//! that the scene reaches both sides of the plane through `F` (parallel to the base), which
//! is imaged at infinity. Points between the base and `F` are seen on the way in, points
//! beyond `F` on the way out, turned by 180 degrees. The cubic of a scene point then has a
//! double root at `t0`, and the outlines of scene-edge images cannot enclose the image of a
//! scene triangle reaching across that plane (two unbounded pieces; the reason such
//! triangles cannot be drawn by their shapes, `ProjectionTriangleCache::degenerates_before`).
//!
//! Drawn here instead, in homogeneous coordinates: with `Y = X - F`, the base-point
//! barycentrics times `w` and `w` itself are linear in `Y` (`u w = U . Y`, `v w = V . Y`,
//! `w = A . Y`, with `w = 1` on the base and `0` on the plane through `F`), and the depth is
//! affine, `t = t0 (1 - w)`. A scene triangle is cut into its part with `w > 0` and its part
//! with `w < 0`; each is clipped in scene space to the projection triangle's domain (each
//! domain line is a plane through `F`, a linear half-space in `Y` on either side, with the
//! margin of [`clip`](super::clip)) and, on the near side, to the view plane `t >= 0`. The
//! domain of a bounded screen triangle meets the plane through `F` only at `F`, so every
//! clipped point has `w` away from zero unless it is `F` itself, and its image `(U . Y / w,
//! V . Y / w)` is finite. Lines map to lines under a central projection, so the clipped
//! polygons have straight edges and are exact: no curve tracing, no cubic.
//!
//! Degenerate cases (each has a test):
//! * rays that meet only nearly (further apart than [`MEETING_TOL`] of the triangle's size),
//!   or at different depths (directions of different lengths: a fold): no central
//!   projection; the renderer ray casts such triangles as before;
//! * the focus on or behind the base plane (`t0 <= 0`, a pinhole, clipped at the view plane
//!   as any triangle) or parallel directions (no focus): none;
//! * a scene triangle through the focus: its clipped part reaches `w = 0`, where its image
//!   is undefined (it is seen edge-on, a line through the whole image): reported as
//!   [`ThroughFocus`], and the renderer ray casts the projection triangle's pixels.

use glam::{DVec2, DVec3};

use super::clip::DOMAIN_MARGIN;
use super::edge_path::OutlinePoint;
use super::volume_bounds::BoxSide;
use crate::projection::ProjectionTriangleCache;

/// How close (relative to the largest distance from a base point to the focus) the three
/// vertex rays must come to one point at one depth for the triangle to be drawn as a
/// central projection: far above the rounding of coordinates computed in `f64`, far below
/// anything a pixel resolves.
pub const MEETING_TOL: f64 = 1e-9;

/// How far (relative to the scale of its terms) a box's least or greatest value of a
/// half-space must be from zero for [`BoxTest::side`] to decide for every
/// point in the box: far above the rounding of the two ways the value is computed (per
/// vertex and per box), so the box test never contradicts the vertices' own.
const BOX_MARGIN: f64 = 1e-9;

/// The half-spaces of [`ClipPoint::sides`] the points seen in each cone must be
/// in: before the focus (bits 0 to 4), beyond it (bits 5 to 8).
const NEAR_CONE: u32 = 0x1f;
const FAR_CONE: u32 = 0x1e0;

/// A projection triangle's rays as a central projection from their common point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentralProjection {
    /// The point `F` every ray passes through.
    focus: DVec3,
    /// The depth `t0` at which they pass through it.
    depth: f64,
    /// `u w = u . (X - F)`, `v w = v . (X - F)`, `w = w . (X - F)` (module doc).
    u: DVec3,
    v: DVec3,
    w: DVec3,
}

/// The box test of a [`CentralProjection`] ([`BoxTest::side`]), its terms formed once per
/// cull rather than at every node of the cull tree, and kept out of the projection itself
/// (every projection triangle carries one's room, whose memory a small frame pays for).
#[derive(Debug, Clone, Copy)]
pub struct BoxTest {
    focus: DVec3,
    /// The scale of the half-spaces' terms for the margin: `(2 + m)` (the largest
    /// coefficient sum in `sides`) times the sum of the absolute values of the components of
    /// `u`, `v` and `w` (at least their lengths).
    scale: f64,
    /// The near cone's half-spaces of [`ClipPoint::sides`] (bits 0 to 4) as `normal . y +
    /// offset >= 0`, stored by component (`normals[0][k]` is the x of half-space `k`'s
    /// normal), with the absolute values of the normals' components in `sizes`: the five are
    /// evaluated side by side, one component at a time, at every node of the cull tree.
    normals: [[f64; 5]; 3],
    sizes: [[f64; 5]; 3],
    offsets: [f64; 5],
}

/// A scene triangle reaching the focus: its image through a central projection is not a
/// region of the screen triangle (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ThroughFocus;

impl CentralProjection {
    /// The central projection of the projection triangle `cache`, if its three vertex rays
    /// meet in one point at one depth `t0 > 0` (module doc, degenerate cases).
    pub fn of(cache: &ProjectionTriangleCache) -> Option<CentralProjection> {
        let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
        let p = corners.map(|(u, v)| cache.tripoint(u, v));
        let n = corners.map(|(u, v)| cache.trinorm(u, v));
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (f1, f2) = (n[1] - n[0], n[2] - n[0]);
        // The depth at which the base edges, moved along the rays, shrink most: zero there
        // if the rays meet.
        let spread = f1.length_squared() + f2.length_squared();
        let depth = -(e1.dot(f1) + e2.dot(f2)) / spread;
        if !(depth > 0.0 && depth.is_finite()) {
            return None;
        }
        let meets = [0, 1, 2].map(|i| p[i] + depth * n[i]);
        let focus = (meets[0] + meets[1] + meets[2]) / 3.0;
        let size = p.iter().map(|q| q.distance(focus)).fold(0.0, f64::max);
        if meets.iter().any(|m| m.distance(focus) > MEETING_TOL * size) {
            return None;
        }
        let normal = e1.cross(e2);
        let across = normal.dot(p[0] - focus);
        if across.is_nan() || across.abs() <= MEETING_TOL * normal.length() * size {
            return None;
        }
        let w = normal / across;
        // The dual basis of the base edges in the base plane, for the barycentrics.
        let area2 = normal.length_squared();
        let (gu, gv) = (e2.cross(normal) / area2, normal.cross(e1) / area2);
        let to_focus = focus - p[0];
        let (u, v) = (gu + gu.dot(to_focus) * w, gv + gv.dot(to_focus) * w);
        Some(CentralProjection {
            focus,
            depth,
            u,
            v,
            w,
        })
    }

    /// The half-spaces of the two cones the rays fill that the scene point `x` is strictly
    /// outside of, as the bits of [`ClipPoint::sides`] (0 to 4 the cone before the focus, 5 to
    /// 8 the one beyond it). The planes are those [`Self::outlines`] clips to, so a scene
    /// triangle whose corners share a bit of each cone ([`Self::culled`]) has no image.
    pub fn outside(&self, x: DVec3) -> u16 {
        let sides = self.point(x - self.focus).sides();
        (0..9).fold(0, |mask, k| mask | u16::from(sides[k] < 0.0) << k)
    }

    /// Whether a scene triangle whose corners are all outside the half-spaces of the bits
    /// `common` (the `&` of their [`Self::outside`]) has no image: it is outside one
    /// half-space of each cone.
    pub fn culled(common: u16) -> bool {
        let common = u32::from(common);
        common & NEAR_CONE != 0 && common & FAR_CONE != 0
    }

    /// Every half-space of [`ClipPoint::sides`] (bit `k` for half-space `k`): where a box test
    /// starts.
    pub const ALL_SIDES: u32 = NEAR_CONE | FAR_CONE;

    /// The terms of its box test ([`BoxTest::side`]), for one cull.
    pub fn box_test(&self) -> BoxTest {
        let (u, v, w) = (self.u, self.v, self.w);
        let terms = [u, v, w].map(|a| a.abs().element_sum());
        let half_spaces = near_half_spaces(u, v, w);
        let component = |c: usize, f: fn(DVec3) -> DVec3| half_spaces.map(|(n, _)| f(n)[c]);
        let by_component = |f: fn(DVec3) -> DVec3| [0, 1, 2].map(|c| component(c, f));
        BoxTest {
            focus: self.focus,
            scale: (2.0 + DOMAIN_MARGIN) * (terms[0] + terms[1] + terms[2]),
            normals: by_component(|n| n),
            sizes: by_component(DVec3::abs),
            offsets: half_spaces.map(|(_, offset)| offset),
        }
    }

    /// The point `y = X - F` with its homogeneous coordinates `u w`, `v w` and `w` (module
    /// doc), from which its [`ClipPoint::sides`] and image follow.
    fn point(&self, y: DVec3) -> ClipPoint {
        ClipPoint {
            y,
            u: self.u.dot(y),
            v: self.v.dot(y),
            w: self.w.dot(y),
        }
    }

    /// The scene point `x`'s `w` (1 on the base, 0 at the focus: its depth is `t0 (1 -
    /// w)`) and its image, the barycentrics `(u, v)` it is seen at (module doc; not finite
    /// where `w` is 0): what the occlusion cull (`occlusion`) compares.
    pub fn depth_and_image(&self, x: DVec3) -> (f64, DVec2) {
        let p = self.point(x - self.focus);
        (p.w, DVec2::new(p.u / p.w, p.v / p.w))
    }

    /// Whether [`Self::outlines`] might refuse the scene triangle `scene` as reaching the
    /// focus ([`ThroughFocus`]): unless its corners' `w` all have one sign and keep twice
    /// that test's distance from zero, which every clipped point (a convex combination of
    /// the corners) then keeps too. The occlusion cull hides no such pair, so that the
    /// projection triangles ray cast for one stay so. NaN corners: true.
    pub fn may_reach_focus(&self, scene: [DVec3; 3]) -> bool {
        let y = scene.map(|x| x - self.focus);
        let reach = y.iter().map(|y| y.length()).fold(0.0, f64::max);
        let w = y.map(|y| self.w.dot(y));
        let least = 2.0 * MEETING_TOL * self.w.length() * reach;
        let clear = w.iter().all(|&w| w > least) || w.iter().all(|&w| w < -least);
        !clear
    }

    /// The depth `t0` at which the rays meet (read by the tests).
    #[cfg(test)]
    pub fn depth(&self) -> f64 {
        self.depth
    }

    /// Calls `draw` with the outline of each part of the image of the scene triangle
    /// `scene` inside the projection triangle's domain at `t >= 0` (at most two: before and
    /// beyond the focus; fewer than 2 points are not passed on), each point with its
    /// barycentrics and depth. `scratch` is reused storage. Fails, drawing nothing, when
    /// the scene triangle reaches the focus (module doc).
    pub fn outlines(
        &self,
        scene: [DVec3; 3],
        scratch: &mut Scratch,
        mut draw: impl FnMut(&[OutlinePoint]),
    ) -> Result<(), ThroughFocus> {
        let corners = scene.map(|x| self.point(x - self.focus));
        // The corners' sides, for the tests that need no clipping: computed as the clipping
        // computes them, so the tests agree with it bit for bit.
        let sides = [0, 1, 2].map(|i| corners[i].sides());
        let mut reach = None;
        let Scratch {
            polygon,
            clipped,
            pieces,
        } = scratch;
        // Per cone: the side `w` is on, where `side * w` is in `sides`, and the half-spaces
        // clipped to.
        let cones: [(f64, usize, &[usize]); 2] = [(1.0, 4, &[0, 1, 2, 3]), (-1.0, 8, &[5, 6, 7])];
        for ((side, w_at, half_spaces), piece) in cones.into_iter().zip(pieces.iter_mut()) {
            piece.clear();
            // No corner on this cone's side of the plane through the focus (`side * w`
            // is `sides[w_at]`, exactly: a sign change), or all corners outside one of its
            // half-spaces: no image in it. Clipping would give no polygon either (the
            // half-spaces are linear, their cut points convex combinations of the corners).
            let all = |k: usize, inside: fn(f64) -> bool| sides.iter().all(|s| inside(s[k]));
            if all(w_at, |s| s <= 0.0) || half_spaces.iter().any(|&k| all(k, |s| s < 0.0)) {
                continue;
            }
            polygon.clear();
            polygon.extend_from_slice(&corners);
            // While the polygon is still the scene triangle, its corners' sides decide
            // whether a half-space cuts it (most live pairs lie wholly inside the cone).
            let mut whole = true;
            for &k in half_spaces {
                if whole && all(k, |s| s >= 0.0) {
                    continue;
                }
                whole = false;
                clip_polygon(polygon, clipped, |y| self.point(y), |p| p.sides()[k]);
            }
            if polygon.is_empty() {
                continue;
            }
            let reach = *reach
                .get_or_insert_with(|| corners.iter().map(|c| c.y.length()).fold(0.0, f64::max));
            for &ClipPoint { u, v, w, .. } in polygon.iter() {
                // Away from the focus `side * w` is positive (module doc); at it the image
                // is undefined.
                if w.is_nan() || side * w <= MEETING_TOL * self.w.length() * reach {
                    return Err(ThroughFocus);
                }
                piece.push(OutlinePoint {
                    u: u / w,
                    v: v / w,
                    t: self.depth * (1.0 - w),
                });
            }
        }
        for piece in pieces.iter().filter(|p| p.len() >= 2) {
            draw(piece);
        }
        Ok(())
    }
}

/// A point of a polygon clipped in scene space: its offset `y = X - F` from the focus and
/// its dot products with the projection's `u`, `v` and `w` ([`CentralProjection::point`]),
/// computed once per point, since every half-space it is tested against and its image are
/// made of these three (the clipping tests a point against up to four half-spaces).
#[derive(Debug, Clone, Copy)]
struct ClipPoint {
    y: DVec3,
    u: f64,
    v: f64,
    w: f64,
}

impl ClipPoint {
    /// The values of the half-spaces the point must be in (`>= 0`) to be seen, in the cone
    /// before the focus (bits 0 to 4: the domain's three planes with the clipping margin,
    /// the view plane `w <= 1`, and `w >= 0`, which the three imply but which culls a scene
    /// triangle beyond the focus as a whole) and in the cone beyond it (bits 5 to 8: the
    /// domain's planes turned round, and `w <= 0`).
    fn sides(&self) -> [f64; 9] {
        // Spelled out (no array maps): called per scene vertex and clipped point.
        let (u, v, w) = (self.u, self.v, self.w);
        let m = DOMAIN_MARGIN;
        let [a, b, c] = [u + m * w, v + m * w, (1.0 + m) * w - u - v];
        [a, b, c, 1.0 - w, w, -a, -b, -c, -w]
    }
}

/// Reused buffers of [`CentralProjection::outlines`].
#[derive(Debug, Default)]
pub struct Scratch {
    polygon: Vec<ClipPoint>,
    clipped: Vec<ClipPoint>,
    /// The parts before and beyond the focus.
    pieces: [Vec<OutlinePoint>; 2],
}

/// One Sutherland-Hodgman pass in scene space: `polygon` becomes its part where `inside >=
/// 0` (`inside` linear in the points' offsets, so the cut points are exact up to rounding);
/// a cut point is made from its offset by `point`; `scratch` is reused storage.
/// Consecutive equal points are merged.
fn clip_polygon(
    polygon: &mut Vec<ClipPoint>,
    scratch: &mut Vec<ClipPoint>,
    point: impl Fn(DVec3) -> ClipPoint,
    inside: impl Fn(&ClipPoint) -> f64,
) {
    if polygon.iter().all(|p| inside(p) >= 0.0) {
        return;
    }
    scratch.clear();
    let Some(&last) = polygon.last() else {
        return;
    };
    let (mut previous, mut previous_side) = (last, inside(&last));
    for &current in polygon.iter() {
        let side = inside(&current);
        if (side >= 0.0) != (previous_side >= 0.0) {
            let s = previous_side / (previous_side - side);
            push_distinct(scratch, point(previous.y + s * (current.y - previous.y)));
        }
        if side >= 0.0 {
            push_distinct(scratch, current);
        }
        (previous, previous_side) = (current, side);
    }
    if scratch.len() > 1 && scratch.first().map(|p| p.y) == scratch.last().map(|p| p.y) {
        scratch.pop();
    }
    std::mem::swap(polygon, scratch);
}

/// Appends `p` unless its offset equals the last point's (equal offsets have equal
/// products).
fn push_distinct(out: &mut Vec<ClipPoint>, p: ClipPoint) {
    if out.last().map(|q| q.y) != Some(p.y) {
        out.push(p);
    }
}

impl BoxTest {
    /// The hierarchical form of [`CentralProjection::culled`] for `cull_tree`:
    /// [`BoxSide::Outside`] only when every point of the axis-aligned box (centre and
    /// half-extents) is outside one half-space of each cone by more than [`BOX_MARGIN`] of
    /// the scale, so that every scene vertex in it has those bits in its
    /// [`CentralProjection::outside`] mask and every triangle in it would be culled one by
    /// one too (the tree culls no pair the vertices keep). Otherwise [`BoxSide::Within`] the
    /// half-spaces of `active` that do not hold the whole box by that margin (no point below
    /// can be outside the others). Degenerate boxes: a box of zero extent is tested like any
    /// other; one with a non-finite coordinate is never outside (its comparisons fail).
    pub fn side(&self, centre: DVec3, half: DVec3, active: u32) -> BoxSide {
        let y = centre - self.focus;
        // The sums of absolute values bound the lengths (no square root per node).
        let margin = BOX_MARGIN * (self.scale * (y.abs().element_sum() + half.element_sum()) + 1.0);
        // Each half-space's least and greatest value over the box, `middle -+ reach`, with
        // `middle = normal . y + offset` and `reach = |normal| . half` summed in the order
        // of `DVec3::dot`.
        let (n, s) = (&self.normals, &self.sizes);
        let mut near_outside = 0;
        let mut near_inside = 0;
        for k in 0..5 {
            let middle = n[0][k] * y.x + n[1][k] * y.y + n[2][k] * y.z + self.offsets[k];
            let reach = s[0][k] * half.x + s[1][k] * half.y + s[2][k] * half.z;
            near_outside |= u32::from(middle + reach < -margin) << k;
            near_inside |= u32::from(middle - reach > margin) << k;
        }
        // The far cone's half-spaces that are the near ones turned round: `k + 5` for the
        // domain planes (bits 0 to 2), 8 for `w >= 0` (bit 4); none for the view plane.
        let far = |near: u32| (near & 0b111) << 5 | (near & 0b1_0000) << 4;
        let outside = near_outside | far(near_inside);
        let inside = near_inside | far(near_outside);
        let outside = outside & active;
        if outside & NEAR_CONE != 0 && outside & FAR_CONE != 0 {
            BoxSide::Outside
        } else {
            BoxSide::Within(active & !inside)
        }
    }
}

/// The near cone's half-spaces of [`ClipPoint::sides`] (bits 0 to 4) for the terms `u`,
/// `v`, `w` of a [`CentralProjection`], as `normal . y + offset >= 0`; the far cone's are
/// the first three and the last turned round.
fn near_half_spaces(u: DVec3, v: DVec3, w: DVec3) -> [(DVec3, f64); 5] {
    let m = DOMAIN_MARGIN;
    [
        (u + m * w, 0.0),
        (v + m * w, 0.0),
        ((1.0 + m) * w - u - v, 0.0),
        (-w, 1.0),
        (w, 0.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const V: fn(f64, f64, f64) -> DVec3 = DVec3::new;

    /// A base triangle and its directions to `focus`, met at depth `depth`.
    fn converging(focus: DVec3, depth: f64) -> ([DVec3; 3], [DVec3; 3]) {
        let p = [V(-1.0, -0.8, 0.0), V(1.2, -0.6, 0.2), V(0.1, 1.0, -0.1)];
        (p, p.map(|x| (focus - x) / depth))
    }

    fn central(p: [DVec3; 3], n: [DVec3; 3]) -> Option<CentralProjection> {
        CentralProjection::of(&ProjectionTriangleCache::new(p, n))
    }

    #[test]
    fn rays_meeting_in_one_point_make_a_central_projection() {
        let focus = V(0.3, 0.2, 3.0);
        let (p, n) = converging(focus, 1.5);
        let c = central(p, n).expect("central");
        assert!((c.depth() - 1.5).abs() < 1e-12 && c.focus.distance(focus) < 1e-12);
        // The base's own points are seen at their barycentrics and depth 0.
        let mut scratch = Scratch::default();
        let base = [p[0], p[1], p[2]];
        let mut outlines = Vec::new();
        let drawn = c.outlines(base, &mut scratch, |o| outlines.push(o.to_vec()));
        assert_eq!(drawn, Ok(()));
        assert_eq!(outlines.len(), 1);
        for (point, (u, v)) in outlines[0].iter().zip([(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]) {
            assert!(
                (point.u - u).abs() < 1e-12 && (point.v - v).abs() < 1e-12,
                "{point:?}"
            );
            assert!(point.t.abs() < 1e-12, "{point:?}");
        }
    }

    #[test]
    fn rays_that_do_not_meet_in_one_point_at_one_depth_are_not_central() {
        let focus = V(0.3, 0.2, 3.0);
        let (p, n) = converging(focus, 1.0);
        // Nearly meeting: one direction off by 1e-6 of the triangle's size.
        let mut off = n;
        off[1].x += 1e-6 * 3.0;
        assert!(central(p, off).is_none());
        // Meeting in one point at different depths (a fold).
        let unequal = [n[0], n[1] * 2.0, n[2] * 0.5];
        assert!(central(p, unequal).is_none());
        // A pinhole: the rays meet behind the base (t0 < 0).
        let eye = V(0.2, -0.1, -3.0);
        assert!(central(p, p.map(|x| x - eye)).is_none());
        // Parallel rays, and rays through a line (a cylinder's axis).
        assert!(central(p, [V(0.1, 0.0, 1.0); 3]).is_none());
        let ring = [V(1.0, 0.0, 0.0), V(0.0, 1.0, 0.5), V(-1.0, 0.0, 1.0)];
        assert!(central(ring, ring.map(|x| V(-x.x, -x.y, 0.0))).is_none());
    }

    #[test]
    fn a_scene_triangle_through_the_focus_is_refused() {
        let focus = V(0.3, 0.2, 3.0);
        let (p, n) = converging(focus, 1.0);
        let c = central(p, n).expect("central");
        let scene = [
            focus + V(-1.0, -1.0, 0.5),
            focus + V(1.0, -1.0, -0.5),
            focus + V(0.0, 1.0, 0.0),
        ];
        let mut drawn = 0;
        let result = c.outlines(scene, &mut Scratch::default(), |_| drawn += 1);
        assert_eq!((result, drawn), (Err(ThroughFocus), 0));
    }

    /// The box test decides both ways on clear cases: a box beside the focus but off the
    /// cones is outside, one around the focus (which every half-space through it cuts) and
    /// one with an infinite extent (degenerate) are not, a box of zero extent (a point) is
    /// tested as its point.
    #[test]
    fn boxes_off_the_cones_are_outside_and_others_not() {
        let focus = V(0.3, 0.2, 3.0);
        let (p, n) = converging(focus, 1.0);
        let c = central(p, n).expect("central");
        let all = CentralProjection::ALL_SIDES;
        // The cones open along the base's normal (z): a box far to the side of the focus.
        let side = focus + V(20.0, 0.0, 0.0);
        assert_eq!(
            c.box_test().side(side, V(1.0, 1.0, 1.0), all),
            BoxSide::Outside
        );
        let BoxSide::Within(active) = c.box_test().side(focus, V(0.5, 0.5, 0.5), all) else {
            panic!("a box around the focus is culled");
        };
        assert_eq!(
            active & 0x1f7,
            0x1f7,
            "every plane through the focus cuts it"
        );
        let infinite = V(f64::INFINITY, 1.0, 1.0);
        assert!(matches!(
            c.box_test().side(side, infinite, all),
            BoxSide::Within(_)
        ));
        let point = c.box_test().side(side, DVec3::ZERO, all) == BoxSide::Outside;
        assert_eq!(point, CentralProjection::culled(c.outside(side)));
        assert!(point);
    }

    /// Where `point` is against the convex polygon `polygon`: `Some(true)` inside by more
    /// than `margin`, `Some(false)` outside by more than it, `None` near its boundary.
    fn inside_convex(polygon: &[OutlinePoint], u: f64, v: f64, margin: f64) -> Option<bool> {
        let area: f64 = (0..polygon.len())
            .map(|i| {
                let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
                a.u * b.v - b.u * a.v
            })
            .sum();
        if area.abs() < 1e-12 {
            return Some(false);
        }
        let mut near = false;
        for i in 0..polygon.len() {
            let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
            let (eu, ev) = (b.u - a.u, b.v - a.v);
            let length = eu.hypot(ev);
            if length == 0.0 {
                continue;
            }
            let side = area.signum() * (eu * (v - a.v) - ev * (u - a.u)) / length;
            if side < -margin {
                return Some(false);
            }
            near |= side <= margin;
        }
        (!near).then_some(true)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The image of a scene triangle is exactly where the projection triangle's own rays
        /// (tripoint + t trinorm of the cache, not the central formulas) meet it at t >= 0:
        /// on a 15 x 15 grid of the domain, a ray meeting the scene triangle strictly
        /// inside is inside an outline and one missing it is outside all of them, before
        /// and beyond the focus; and every outline point's ray passes through the scene
        /// triangle's plane at its depth (the inverse: project, cast, get the point back).
        #[test]
        fn outlines_are_where_the_rays_meet_the_scene_triangle(
            focus in (-1.0..1.0f64, -1.0..1.0f64, 1.0..4.0f64),
            depth in 0.5..2.0f64,
            corners in proptest::array::uniform3((-4.0..4.0f64, -4.0..4.0f64, -2.0..8.0f64)),
        ) {
            let focus = V(focus.0, focus.1, focus.2);
            let (p, n) = converging(focus, depth);
            let cache = ProjectionTriangleCache::new(p, n);
            let c = CentralProjection::of(&cache).expect("central");
            let scene = corners.map(|(x, y, z)| V(x, y, z));
            let normal = (scene[1] - scene[0]).cross(scene[2] - scene[0]);
            prop_assume!(normal.length() > 1e-3);
            let mut outlines = Vec::new();
            let drawn = c.outlines(scene, &mut Scratch::default(), |o| outlines.push(o.to_vec()));
            prop_assume!(drawn.is_ok());
            for point in outlines.iter().flatten() {
                let x = cache.ray_point(point.u, point.v, point.t);
                prop_assert!(normal.normalize().dot(x - scene[0]).abs() < 1e-8, "{point:?}");
                prop_assert!(point.t >= -1e-12, "{point:?}");
            }
            for i in 0..=14 {
                for j in 0..=14 - i {
                    let (u, v) = ((f64::from(i) + 0.3) / 15.5, (f64::from(j) + 0.4) / 15.5);
                    let (origin, direction) = (cache.tripoint(u, v), cache.trinorm(u, v));
                    let t = normal.dot(scene[0] - origin) / normal.dot(direction);
                    let hit = origin + t * direction;
                    // Barycentrics of the hit in the scene triangle, by areas.
                    let weights = [0, 1, 2].map(|k| {
                        let (a, b) = (scene[(k + 1) % 3], scene[(k + 2) % 3]);
                        (b - a).cross(hit - a).dot(normal) / normal.length_squared()
                    });
                    let clear = 1e-6;
                    let seen = t > clear && weights.iter().all(|&w| w > clear);
                    let unseen = t < -clear || weights.iter().any(|&w| w < -clear);
                    let found: Vec<Option<bool>> =
                        outlines.iter().map(|o| inside_convex(o, u, v, 1e-7)).collect();
                    if seen && found.iter().all(|f| f.is_some()) {
                        prop_assert!(found.contains(&Some(true)), "({u}, {v}) t {t} {outlines:?}");
                    }
                    if unseen {
                        prop_assert!(!found.contains(&Some(true)), "({u}, {v}) t {t} {outlines:?}");
                    }
                }
            }
        }

        /// The box test is sound against the vertices' own masks: every point of a box it
        /// calls outside (its corners and random points) is outside one half-space of each
        /// cone, so the tree culls no scene triangle the vertices keep; and no point of a
        /// box is outside a half-space it drops.
        #[test]
        fn box_side_agrees_with_the_points_in_the_box(
            focus in (-1.0..1.0f64, -1.0..1.0f64, 1.0..4.0f64),
            depth in 0.5..2.0f64,
            centre in (-8.0..8.0f64, -8.0..8.0f64, -6.0..12.0f64),
            half in (0.0..3.0f64, 0.0..3.0f64, 0.0..3.0f64),
            inside in proptest::collection::vec((-1.0..=1.0f64, -1.0..=1.0f64, -1.0..=1.0f64), 8),
        ) {
            let (p, n) = converging(V(focus.0, focus.1, focus.2), depth);
            let c = central(p, n).expect("central");
            let (centre, half) = (V(centre.0, centre.1, centre.2), V(half.0, half.1, half.2));
            let corners = (0..8).map(|k| {
                V([-1.0, 1.0][k & 1], [-1.0, 1.0][(k >> 1) & 1], [-1.0, 1.0][k >> 2])
            });
            let points: Vec<DVec3> = corners
                .chain(inside.iter().map(|&(x, y, z)| V(x, y, z)))
                .map(|f| centre + f * half)
                .collect();
            let masks: Vec<u16> = points.iter().map(|&x| c.outside(x)).collect();
            match c.box_test().side(centre, half, CentralProjection::ALL_SIDES) {
                BoxSide::Outside => {
                    let common = masks.iter().fold(u16::MAX, |m, &x| m & x);
                    prop_assert!(CentralProjection::culled(common), "{masks:?}");
                }
                BoxSide::Within(active) => {
                    let dropped = CentralProjection::ALL_SIDES & !active;
                    for m in masks {
                        prop_assert_eq!(u32::from(m) & dropped, 0, "{:b}", dropped);
                    }
                }
            }
        }

        /// The cull is sound: a scene triangle it culls has no outline.
        #[test]
        fn culled_scene_triangles_have_no_image(
            focus in (-1.0..1.0f64, -1.0..1.0f64, 1.0..4.0f64),
            corners in proptest::array::uniform3((-6.0..6.0f64, -6.0..6.0f64, -4.0..10.0f64)),
        ) {
            let focus = V(focus.0, focus.1, focus.2);
            let (p, n) = converging(focus, 1.0);
            let c = central(p, n).expect("central");
            let scene = corners.map(|(x, y, z)| V(x, y, z));
            let common = scene.iter().fold(u16::MAX, |m, &x| m & c.outside(x));
            if CentralProjection::culled(common) {
                let mut drawn = 0;
                let _ = c.outlines(scene, &mut Scratch::default(), |_| drawn += 1);
                prop_assert_eq!(drawn, 0);
            }
        }
    }
}
