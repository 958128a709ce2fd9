//! Subdivision of scene triangles into pieces small enough that filling the straight-edged
//! polygon of their projected corners approximates their curved image: a uniform grid, then
//! adaptive halving of edges.
//!
//! Crack-free by construction: every decision about an edge (split or not, and where its
//! midpoint goes) is taken from that edge's own data, its two end points and its level, in a
//! canonical order of the ends ([`canonical`]), so the two triangles sharing an edge always
//! agree and no T-junction appears. A triangle whose edges split is re-triangulated with the
//! new midpoints (one, two or three of them), and the pieces are refined again.
//!
//! The adaptive rule halves an edge when
//! - its projected midpoint lies more than `tolerance` pixels off the straight line between
//!   its projected ends (unwrapped across a panorama's seam); the midpoint is not projected
//!   for an edge whose image is too short to bend that far (see [`bends_at_most`]), or
//! - it is longer, seen from a pole's centre, than the pole's clearance and lies within twice
//!   its length of the pole: pieces containing a pole are thus brought within the clearance,
//!   where they cover no pixel centre and are dropped (see [`Refiner::is_pole_piece`]).
//!
//! Degenerate cases: an edge whose ends coincide is never split; an edge with an end or a
//! midpoint without image (on an eye or a pole) is not split by the midpoint rule (its
//! pieces are dropped when drawn); edges stop splitting at [`MAX_LEVEL`] halvings.

/// The smallest radius of curvature, in pixels, assumed for the image of a straight scene
/// edge away from the singular set (the eye, clipped away, and the poles, handled by their
/// own rule): an arc of radius R with a chord of c pixels lies at most c^2 / (8 R) off it.
/// Images of lines bend that sharply only within a pixel or so of a pole or an eye.
const MIN_BEND_RADIUS_PX: f64 = 1.0;

use glam::{DVec2, DVec3};

use super::clip::canonical;
use super::subdivision::MAX_LEVEL;
use crate::geometry::intersect_triangle;
use crate::projection::{Charted, ContinuousInverse, InverseChart, Pole};

/// A point of a scene triangle and its image (`None` on the singular set).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    pub point: DVec3,
    pub image: Option<DVec2>,
}

/// Decides and performs subdivision for one projection.
pub struct Refiner<'a> {
    inverse: &'a dyn ContinuousInverse,
    chart: &'a InverseChart,
    tolerance: Option<f64>,
}

/// `x` moved by a whole number of periods to within half a period of `reference`, and the
/// number of periods added.
pub fn unwrap(x: f64, reference: f64, period: Option<f64>) -> (f64, i64) {
    match period {
        Some(p) => {
            // Nearly every call is within a quarter period: no division then (|d| <= p/4
            // gives |d / p| <= 1/4 after rounding, so k = 0 either way), and none within half
            // a period calls `round` (a library call on this target); the result is the
            // rounded quotient's in every case.
            let k = if (reference - x).abs() <= 0.25 * p {
                0.0
            } else {
                let periods = (reference - x) / p;
                if periods.abs() < 0.5 {
                    0.0
                } else {
                    periods.round()
                }
            };
            (x + k * p, k as i64)
        }
        None => (x, 0),
    }
}

/// The angle at `origin` between `a` and `b`.
fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

impl<'a> Refiner<'a> {
    /// Refines by `inverse`'s continuous map and chart.
    pub fn new(inverse: &'a Charted<'a>, tolerance: Option<f64>) -> Self {
        Refiner {
            inverse: inverse.map,
            chart: &inverse.chart,
            tolerance,
        }
    }

    /// The node of scene point `point`.
    pub fn node(&self, point: DVec3) -> Node {
        Node {
            point,
            image: self.inverse.project_continuous(point).map(|i| i.pixel),
        }
    }

    /// The midpoint node of edge `a b` at `level` halvings if the edge must be split;
    /// `poles`: whether the pole rule applies (`false` only for edges of a triangle that
    /// [`Refiner::far_from_poles`] clears, where it can never split).
    fn split(&self, a: &Node, b: &Node, level: u32, poles: bool) -> Option<Node> {
        let (a, b, bendable) = self.candidate(a, b, level)?;
        let near_pole = poles && self.near_pole(a.point, b.point);
        if !bendable && !near_pole {
            return None;
        }
        let mid = self.node(0.5 * (a.point + b.point));
        let curved = bendable
            && match (self.tolerance, a.image, b.image, mid.image) {
                (Some(tolerance), Some(pa), Some(pb), Some(pm)) => {
                    self.deviation(pa, pb, pm) > tolerance
                }
                _ => false,
            };
        (curved || near_pole).then_some(mid)
    }

    /// The ends of edge `a b` at `level` halvings in canonical order and whether the
    /// midpoint rule may split it (both images, and an image long enough to bend by more
    /// than the tolerance: most edges of a finely tessellated model are too short to), or
    /// `None` for an edge that is never split (the level limit, coinciding ends).
    fn candidate<'n>(
        &self,
        a: &'n Node,
        b: &'n Node,
        level: u32,
    ) -> Option<(&'n Node, &'n Node, bool)> {
        if level >= MAX_LEVEL || a.point == b.point {
            return None;
        }
        let (a, b) = if canonical(a.point, b.point) {
            (a, b)
        } else {
            (b, a)
        };
        let bendable = match (self.tolerance, a.image, b.image) {
            (Some(tolerance), Some(pa), Some(pb)) => !self.bends_at_most(pa, pb, tolerance),
            _ => false,
        };
        Some((a, b, bendable))
    }

    /// Whether [`Refiner::refine`] emits the triangle `nodes` whole when the pole rule does
    /// not apply (a triangle cleared by [`Refiner::far_from_poles`]): no edge's image is
    /// long enough to bend by more than the tolerance, so no midpoint is even projected. A
    /// `false` proves nothing (the edge may still turn out straight enough).
    ///
    /// Most edges are settled without ordering their ends: within a quarter period of each
    /// other in x, [`unwrap`] moves neither end, so [`Refiner::bends_at_most`] gives the same
    /// answer from either end ([`Refiner::short`]).
    pub fn stays_whole(&self, nodes: &[Node; 3]) -> bool {
        let Some(tolerance) = self.tolerance else {
            return true;
        };
        let [a, b, c] = nodes;
        [(a, b), (b, c), (c, a)].into_iter().all(|(p, q)| {
            let (Some(pa), Some(pb)) = (p.image, q.image) else {
                return true;
            };
            self.short(pa, pb, tolerance)
                || self
                    .candidate(p, q, 0)
                    .is_none_or(|(_, _, bendable)| !bendable)
        })
    }

    /// Whether images `pa` and `pb` lie within a quarter period of each other in x and
    /// within the bend bound of each other: then `bends_at_most(pa, pb)` and
    /// `bends_at_most(pb, pa)` both hold (neither end is unwrapped, and the distance is the
    /// same both ways).
    fn short(&self, pa: DVec2, pb: DVec2, tolerance: f64) -> bool {
        let near = self
            .chart
            .period
            .is_none_or(|p| (pa.x - pb.x).abs() <= 0.25 * p);
        near && pa.distance_squared(pb) <= 8.0 * MIN_BEND_RADIUS_PX * tolerance
    }

    /// Whether the image of an edge whose ends project to `pa` and `pb` (unwrapped next to
    /// `pa`) stays within `tolerance` pixels of its chord by the bend bound of
    /// [`MIN_BEND_RADIUS_PX`]: chord^2 / (8 R) <= tolerance.
    fn bends_at_most(&self, pa: DVec2, pb: DVec2, tolerance: f64) -> bool {
        let pb = DVec2::new(unwrap(pb.x, pa.x, self.chart.period).0, pb.y);
        pa.distance_squared(pb) <= 8.0 * MIN_BEND_RADIUS_PX * tolerance
    }

    /// How far `pm` is from the line through `pa` and `pb`, all unwrapped next to `pa`.
    fn deviation(&self, pa: DVec2, pb: DVec2, pm: DVec2) -> f64 {
        let period = self.chart.period;
        let pb = DVec2::new(unwrap(pb.x, pa.x, period).0, pb.y);
        let pm = DVec2::new(unwrap(pm.x, pa.x, period).0, pm.y);
        let chord = pb - pa;
        let length = chord.length();
        if length == 0.0 {
            (pm - pa).length()
        } else {
            chord.perp_dot(pm - pa).abs() / length
        }
    }

    /// Whether edge `a b` is longer than some pole's clearance and within twice its length
    /// of that pole (angles at the pole's origin).
    ///
    /// Most edges are far from every pole: they are rejected first by bounds on the angles
    /// from chords of unit vectors (an angle is at least its chord and at most pi/2 times
    /// it), without trigonometry.
    fn near_pole(&self, a: DVec3, b: DVec3) -> bool {
        self.chart.poles.iter().any(|pole| {
            let (oa, ob) = (a - pole.origin, b - pole.origin);
            let (Some(ua), Some(ub)) = (oa.try_normalize(), ob.try_normalize()) else {
                return false;
            };
            let longest = std::f64::consts::FRAC_PI_2 * (ua - ub).length();
            let nearest = (ua - pole.direction)
                .length()
                .min((ub - pole.direction).length());
            if longest <= pole.clearance || nearest >= 2.0 * longest {
                return false;
            }
            let length = angle_between(oa, ob);
            length > pole.clearance
                && angle_between(oa, pole.direction).min(angle_between(ob, pole.direction))
                    < 2.0 * length
        })
    }

    /// Whether no part of triangle `points` comes near a pole: then no edge of any piece
    /// of it (pieces of the uniform grid, of adaptive refinement or of clipping all lie in
    /// the triangle) is split by the pole rule of [`Refiner::near_pole`], and no piece is
    /// crossed by a pole ray ([`Refiner::is_pole_piece`]), so neither need be tested piece
    /// by piece. Most triangles of a scene are far from both poles.
    ///
    /// The bound: the triangle lies in the ball of radius r around its centroid c. Seen from
    /// a pole's origin o at distance D = |c - o| > r, every point of the ball lies within
    /// a = asin(r / D) of the direction of c, so every piece's edge is at most 2a long and
    /// every point at least (theta - a) from the pole, theta being c's angle from the pole.
    /// The pole rule needs an edge end within twice the edge's length, theta - a < 4a; a
    /// pole crossing needs theta - a <= 0. Both are impossible when theta > 5a, which holds
    /// when `chord * D > 5 (pi / 2) r`, chord = |unit(c - o) - direction| (theta >= chord
    /// and a <= (pi / 2) r / D; the chord is at most 2, so this also implies D > r). It is
    /// evaluated squared and without the division, as `|(c - o) - D direction|^2 >
    /// (5 pi / 2)^2 r^2` (chord * D = |(c - o) - D direction|): one square root per pole
    /// origin (the two poles of a panorama share the eye: one) and none for r, as this runs
    /// once per scene triangle.
    ///
    /// Degenerate cases: a triangle around a pole's origin (D <= r), or whose centroid is
    /// the origin (D = 0, where the left side is 0), is not far; neither is a zero-size
    /// triangle on a pole ray (r = 0 and chord = 0: the inequality is strict); a non-finite
    /// point makes every comparison false, so it is not far either (the exact tests decide).
    pub fn far_from_poles(&self, points: [DVec3; 3]) -> bool {
        const BOUND: f64 = 2.5 * std::f64::consts::PI;
        let centre = (points[0] + points[1] + points[2]) / 3.0;
        let radius_squared = points
            .iter()
            .map(|&p| p.distance_squared(centre))
            .fold(0.0, f64::max);
        // The offset from the previous pole's origin and its length, reused by a pole with
        // the same origin.
        let mut seen: Option<(DVec3, DVec3, f64)> = None;
        self.chart.poles.iter().all(|pole| {
            let (offset, distance) = match seen {
                Some((origin, offset, distance)) if origin == pole.origin => (offset, distance),
                _ => {
                    let offset = centre - pole.origin;
                    let distance = offset.length();
                    seen = Some((pole.origin, offset, distance));
                    (offset, distance)
                }
            };
            (offset - distance * pole.direction).length_squared() > BOUND * BOUND * radius_squared
        })
    }

    /// Whether the piece `[a, b, c]` is crossed by a pole ray; such pieces are not drawn (by
    /// the edge rule they lie within the pole's clearance, unless the level limit stopped
    /// the splitting).
    pub fn is_pole_piece(&self, [a, b, c]: [DVec3; 3]) -> bool {
        self.chart.poles.iter().any(|pole: &Pole| {
            intersect_triangle(pole.origin, pole.direction, [a, b, c]).is_some_and(|h| h.t >= 0.0)
        })
    }

    /// Whether the piece `[a, b, c]` lies wholly within some pole's clearance: every corner
    /// strictly less than `min(clearance, pi / 2)` from the pole's direction, seen from its
    /// origin. That cone is convex (at pi / 2 an open half-space), so the whole piece lies
    /// in it, its exact image covers no pixel centre, and it is not drawn: the straight
    /// polygon of its corner images would be no image of it at all, since near a pole a
    /// small piece's image spans a wide arc (a fisheye's axis behind the eye maps to a whole
    /// circle around the image), and its chords cut into the image (issue: an object
    /// pierced by the axis behind a fisheye drew a ring inside the image circle).
    ///
    /// Degenerate cases: a corner on a pole's origin has no direction and keeps the piece
    /// (for that pole); so does a non-finite corner (every comparison is false).
    pub fn is_within_clearance(&self, points: [DVec3; 3]) -> bool {
        self.chart.poles.iter().any(|pole| {
            let cone = pole.clearance.min(std::f64::consts::FRAC_PI_2);
            points.iter().all(|&p| {
                let offset = p - pole.origin;
                offset != DVec3::ZERO && angle_between(offset, pole.direction) < cone
            })
        })
    }

    /// Calls `emit` with the pieces of triangle `nodes` whose edges have been halved
    /// `levels` times, after adaptive refinement; `poles`: whether the pole rule applies
    /// (see [`Refiner::split`]).
    pub fn refine(
        &self,
        nodes: [Node; 3],
        levels: [u32; 3],
        poles: bool,
        emit: &mut impl FnMut([Node; 3]),
    ) {
        let [a, b, c] = nodes;
        let splits = [
            self.split(&a, &b, levels[0], poles),
            self.split(&b, &c, levels[1], poles),
            self.split(&c, &a, levels[2], poles),
        ];
        // Rotate so that the split edges come first: ab, then bc, then ca.
        let count = splits.iter().filter(|s| s.is_some()).count();
        if count == 0 {
            emit(nodes);
            return;
        }
        let rotation = (0..3)
            .find(|&r| (0..count).all(|k| splits[(r + k) % 3].is_some()))
            .unwrap_or(0);
        let n = |k: usize| nodes[(rotation + k) % 3];
        let l = |k: usize| levels[(rotation + k) % 3];
        let m = |k: usize| splits[(rotation + k) % 3].unwrap_or(n(k));
        let inner = 1 + levels.into_iter().max().unwrap_or(0);
        let (a, b, c) = (n(0), n(1), n(2));
        match count {
            1 => {
                let ab = m(0);
                self.refine([a, ab, c], [l(0) + 1, inner, l(2)], poles, emit);
                self.refine([ab, b, c], [l(0) + 1, l(1), inner], poles, emit);
            }
            2 => {
                let (ab, bc) = (m(0), m(1));
                self.refine([ab, b, bc], [l(0) + 1, l(1) + 1, inner], poles, emit);
                self.refine([a, ab, bc], [l(0) + 1, inner, inner], poles, emit);
                self.refine([a, bc, c], [inner, l(1) + 1, l(2)], poles, emit);
            }
            _ => {
                let (ab, bc, ca) = (m(0), m(1), m(2));
                self.refine([a, ab, ca], [l(0) + 1, inner, l(2) + 1], poles, emit);
                self.refine([ab, b, bc], [l(0) + 1, l(1) + 1, inner], poles, emit);
                self.refine([ca, bc, c], [inner, l(1) + 1, l(2) + 1], poles, emit);
                self.refine([ab, bc, ca], [inner, inner, inner], poles, emit);
            }
        }
    }

    /// Cuts `corners` into `n` x `n` pieces by the regular grid of barycentric steps 1/n
    /// (grid points on an edge from the edge's ends in canonical order) and calls `emit`
    /// with each piece's nodes. `grid` is scratch space.
    pub fn uniform(
        &self,
        corners: [Node; 3],
        n: u32,
        grid: &mut Vec<Node>,
        emit: &mut impl FnMut([Node; 3]),
    ) {
        if n <= 1 {
            emit(corners);
            return;
        }
        let [a, b, c] = corners.map(|c| c.point);
        let on_edge = |p: DVec3, q: DVec3, k: u32| {
            let (p, q, k) = if canonical(p, q) {
                (p, q, k)
            } else {
                (q, p, n - k)
            };
            p + (q - p) * (f64::from(k) / f64::from(n))
        };
        grid.clear();
        // Row j holds points (i, j), i = 0..=n-j: weight i/n on b, j/n on c.
        for j in 0..=n {
            for i in 0..=n - j {
                let corner = match (i, j) {
                    (0, 0) => Some(corners[0]),
                    (i, 0) if i == n => Some(corners[1]),
                    (0, j) if j == n => Some(corners[2]),
                    _ => None,
                };
                grid.push(corner.unwrap_or_else(|| {
                    let point = if j == 0 {
                        on_edge(a, b, i)
                    } else if i == 0 {
                        on_edge(a, c, j)
                    } else if i + j == n {
                        on_edge(b, c, j)
                    } else {
                        let (s, t) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                        a + (b - a) * s + (c - a) * t
                    };
                    self.node(point)
                }));
            }
        }
        let index = |i: u32, j: u32| (j * (2 * n + 3 - j) / 2 + i) as usize;
        for j in 0..n {
            for i in 0..n - j {
                emit([
                    grid[index(i, j)],
                    grid[index(i + 1, j)],
                    grid[index(i, j + 1)],
                ]);
                if i + j + 1 < n {
                    emit([
                        grid[index(i + 1, j)],
                        grid[index(i + 1, j + 1)],
                        grid[index(i, j + 1)],
                    ]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::{CameraFrame, Projection, ProjectionSpec};

    fn panorama() -> Box<dyn Projection> {
        let frame = CameraFrame {
            position: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        let spec = ProjectionSpec::Equirectangular {
            frame,
            h_fov: 360.0,
            v_fov: 180.0,
        };
        spec.build(360, 180).unwrap()
    }

    #[test]
    fn curved_edges_split_and_straight_or_degenerate_ones_do_not() {
        let projection = panorama();
        let charted = projection.inverse().unwrap().charted().unwrap();
        let refiner = Refiner::new(&charted, Some(0.5));
        let node = |p: DVec3| refiner.node(p);
        // A horizontal edge 90 degrees wide above the horizon bends in the panorama.
        let (a, b) = (
            node(DVec3::new(-1.0, 0.5, -1.0)),
            node(DVec3::new(1.0, 0.5, -1.0)),
        );
        assert!(refiner.split(&a, &b, 0, true).is_some());
        // The same decision from either end, with the same midpoint.
        assert_eq!(
            refiner.split(&a, &b, 0, true),
            refiner.split(&b, &a, 0, true)
        );
        // Degenerate: the level limit, and an edge whose ends coincide.
        assert!(refiner.split(&a, &b, MAX_LEVEL, true).is_none());
        assert!(refiner.split(&a, &a, 0, true).is_none());
        // A short vertical edge straight ahead, far from the poles, stays straight (a
        // column of the panorama).
        let (c, d) = (
            node(DVec3::new(0.0, -0.1, -1.0)),
            node(DVec3::new(0.0, 0.1, -1.0)),
        );
        assert!(refiner.split(&c, &d, 0, true).is_none());
        // A piece of the curved edge under a pixel long is too short to bend by the
        // tolerance: not split (its midpoint is not even projected), and indeed its midpoint
        // lies well within the tolerance of its chord. Its long parent edge is tested.
        let (short, tiny) = (
            node(DVec3::new(-0.01, 0.5, -1.0)),
            node(DVec3::new(0.0, 0.5, -1.0)),
        );
        let image = |n: &Node| n.image.unwrap();
        assert!(image(&short).distance(image(&tiny)) < 1.0);
        assert!(refiner.bends_at_most(image(&short), image(&tiny), 0.5));
        assert!(refiner.split(&short, &tiny, 0, true).is_none());
        let mid = image(&node(DVec3::new(-0.005, 0.5, -1.0)));
        assert!(refiner.deviation(image(&short), image(&tiny), mid) < 0.01);
        assert!(!refiner.bends_at_most(image(&a), image(&b), 0.5));
        // Degenerate: an end on the eye has no image; the midpoint rule does not split.
        let eye = node(DVec3::ZERO);
        assert!(eye.image.is_none());
        assert!(refiner.split(&eye, &c, 0, true).is_none());
    }

    #[test]
    fn pieces_around_a_pole_are_found_and_shrunk() {
        let projection = panorama();
        let charted = projection.inverse().unwrap().charted().unwrap();
        let refiner = Refiner::new(&charted, Some(0.5));
        let ceiling = [
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(1.0, 1.0, -1.0),
            DVec3::new(0.0, 1.0, 1.0),
        ];
        assert!(refiner.is_pole_piece(ceiling));
        assert!(!refiner.is_pole_piece(ceiling.map(|p| p + DVec3::X * 5.0)));
        // Refined, only pieces within the pole's clearance still contain the pole.
        let clearance = charted.chart.poles[0].clearance;
        let mut pole_pieces = 0;
        refiner.refine(
            ceiling.map(|p| refiner.node(p)),
            [0; 3],
            true,
            &mut |piece| {
                let points = piece.map(|n| n.point);
                if refiner.is_pole_piece(points) {
                    pole_pieces += 1;
                    let widest = points
                        .iter()
                        .map(|&p| angle_between(p, DVec3::Y))
                        .fold(0.0, f64::max);
                    assert!(widest <= clearance, "{widest} > {clearance}");
                }
            },
        );
        assert!(pole_pieces >= 1);
    }

    /// A fisheye's pole is the axis behind the eye; pieces wholly within its clearance (no
    /// pixel centre's projector comes that near the axis) are found, pieces reaching out of
    /// it, or around the eye, are not; the cone is capped at 90 degrees (a half-space) where
    /// the clearance is wider.
    #[test]
    fn pieces_within_a_poles_clearance_are_found() {
        let fisheye = |fov: f64| {
            let frame = CameraFrame {
                position: DVec3::ZERO,
                look_at: DVec3::NEG_Z,
                up: DVec3::Y,
            };
            ProjectionSpec::Fisheye { frame, fov }
                .build(80, 60)
                .unwrap()
        };
        for fov in [220.0, 300.0, 360.0] {
            let projection = fisheye(fov);
            let charted = projection.inverse().unwrap().charted().unwrap();
            let clearance = charted.chart.poles[0].clearance;
            let refiner = Refiner::new(&charted, Some(0.5));
            // A small piece on the axis behind, and one beside it, both well within.
            let r = 0.2 * clearance.tan();
            let behind = [
                DVec3::new(-r, -r, 1.0),
                DVec3::new(r, -r, 1.0),
                DVec3::new(0.0, r, 1.0),
            ];
            assert!(refiner.is_within_clearance(behind), "{fov}");
            assert!(refiner.is_within_clearance(behind.map(|p| p + DVec3::X * r)));
            // Reaching out of the clearance, in front, or with a corner on the eye: kept.
            let wide = behind.map(|p| p * DVec3::new(10.0, 10.0, 1.0));
            assert!(!refiner.is_within_clearance(wide), "{fov}");
            assert!(!refiner.is_within_clearance(behind.map(|p| -p)));
            assert!(!refiner.is_within_clearance([DVec3::ZERO, behind[1], behind[2]]));
            let nan = [DVec3::NAN, behind[1], behind[2]];
            assert!(!refiner.is_within_clearance(nan));
        }
        // Fisheye 180: the clearance is just over 90 degrees, the cone is the half-space
        // behind the eye plane (strictly).
        let projection = fisheye(180.0);
        let charted = projection.inverse().unwrap().charted().unwrap();
        assert!(charted.chart.poles[0].clearance > std::f64::consts::FRAC_PI_2);
        let refiner = Refiner::new(&charted, Some(0.5));
        let side = [
            DVec3::new(-5.0, 0.0, 0.1),
            DVec3::new(5.0, 0.0, 0.1),
            DVec3::new(0.0, 5.0, 0.1),
        ];
        assert!(refiner.is_within_clearance(side));
        assert!(!refiner.is_within_clearance(side.map(|p| p * DVec3::new(1.0, 1.0, 0.0))));
    }

    /// Pieces of triangles cleared by `far_from_poles` are refined the same with and without
    /// the pole rule, and none is crossed by a pole; triangles at or around a pole are not
    /// cleared, and neither are the degenerate cases of its documentation.
    #[test]
    fn triangles_far_from_the_poles_need_no_pole_tests() {
        let projection = panorama();
        let charted = projection.inverse().unwrap().charted().unwrap();
        let refiner = Refiner::new(&charted, Some(0.5));
        let pieces = |points: [DVec3; 3], poles: bool| {
            let mut out = Vec::new();
            refiner.refine(
                points.map(|p| refiner.node(p)),
                [0; 3],
                poles,
                &mut |piece| out.push(piece),
            );
            out
        };
        // Triangles of sizes 1e-3 to 1 (unit distance) at elevations from the horizon up to
        // the pole: far ones refine identically without the pole rule and hold no pole
        // piece; the bound clears the small ones well away from the pole and not the ones
        // whose pieces the pole rule splits.
        let (mut far, mut near) = (0, 0);
        for size in [1e-3, 1e-2, 0.1, 1.0] {
            for step in 0..=40 {
                let elevation = f64::from(step) / 40.0 * std::f64::consts::FRAC_PI_2;
                let centre = DVec3::new(0.0, elevation.sin(), -elevation.cos());
                let points = [
                    centre + DVec3::new(-size, 0.0, 0.0),
                    centre + DVec3::new(size, 0.0, 0.3 * size),
                    centre + DVec3::new(0.2 * size, size, -size),
                ];
                if refiner.far_from_poles(points) {
                    far += 1;
                    let with = pieces(points, true);
                    assert_eq!(with, pieces(points, false), "{size} {elevation}");
                    assert!(with
                        .iter()
                        .all(|p| !refiner.is_pole_piece(p.map(|n| n.point))));
                } else {
                    near += 1;
                }
            }
        }
        assert!(far >= 90 && near >= 40, "{far} far, {near} near");
        let tiny = [
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(1e-3, 0.0, -1.0),
            DVec3::new(0.0, 1e-3, -1.0),
        ];
        assert!(refiner.far_from_poles(tiny));
        // A triangle the pole crosses, and one with a corner on the pole ray, are not far.
        let ceiling = [
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(1.0, 1.0, -1.0),
            DVec3::new(0.0, 1.0, 1.0),
        ];
        assert!(refiner.is_pole_piece(ceiling) && !refiner.far_from_poles(ceiling));
        assert!(!refiner.far_from_poles([
            DVec3::Y,
            DVec3::new(0.01, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.01)
        ]));
        // Degenerate: around the origin, centroid on the origin, a point on the pole ray, a
        // non-finite corner. A point off the poles is far.
        let around = [
            DVec3::new(-1.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, 0.0, 2.0),
        ];
        assert!(!refiner.far_from_poles(around));
        assert!(!refiner.far_from_poles([DVec3::X, -DVec3::X, DVec3::ZERO]));
        assert!(!refiner.far_from_poles([DVec3::Y; 3]));
        assert!(!refiner.far_from_poles([DVec3::NEG_Z, DVec3::NEG_Z, DVec3::splat(f64::NAN)]));
        assert!(refiner.far_from_poles([DVec3::NEG_Z; 3]));
    }

    proptest::proptest! {
        /// A triangle `stays_whole` says refinement emits whole is emitted whole (without the
        /// pole rule): small and large triangles in every direction, across the seam too;
        /// both answers occur.
        #[test]
        fn triangles_that_stay_whole_are_emitted_whole(
            centre in proptest::array::uniform3(-3.0f64..3.0),
            offsets in proptest::array::uniform6(-1.0f64..1.0),
            size in proptest::prop_oneof![0.001f64..0.01, 0.01f64..1.0],
        ) {
            let projection = panorama();
            let charted = projection.inverse().unwrap().charted().unwrap();
            let refiner = Refiner::new(&charted, Some(0.5));
            let centre = DVec3::from_array(centre);
            let corner =
                |k: usize| centre + size * DVec3::new(offsets[2 * k], offsets[2 * k + 1], 0.5);
            let nodes = [0, 1, 2].map(|k| refiner.node(corner(k)));
            let mut pieces = Vec::new();
            refiner.refine(nodes, [0; 3], false, &mut |piece| pieces.push(piece));
            if refiner.stays_whole(&nodes) {
                proptest::prop_assert_eq!(pieces, vec![nodes]);
            }
        }
    }

    /// Both answers of `stays_whole`, and the degenerate cases: no tolerance (uniform
    /// subdivision only), a corner without image, ends a quarter period apart.
    #[test]
    fn stays_whole_cases() {
        let projection = panorama();
        let charted = projection.inverse().unwrap().charted().unwrap();
        let refiner = Refiner::new(&charted, Some(0.5));
        let nodes = |points: [DVec3; 3]| points.map(|p| refiner.node(p));
        let tiny = nodes([
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(1e-3, 0.0, -1.0),
            DVec3::new(0.0, 1e-3, -1.0),
        ]);
        assert!(refiner.stays_whole(&tiny));
        // Behind the eye, across the seam (x near 0 and near 360): still whole.
        let seam = nodes([
            DVec3::new(-1e-3, 0.0, 1.0),
            DVec3::new(1e-3, 0.0, 1.0),
            DVec3::new(0.0, 1e-3, 1.0),
        ]);
        let xs = seam.map(|n| n.image.unwrap().x);
        assert!(
            xs.iter().any(|&x| x < 1.0) && xs.iter().any(|&x| x > 359.0),
            "{xs:?}"
        );
        assert!(refiner.stays_whole(&seam));
        let wide = nodes([
            DVec3::new(-1.0, 0.5, -1.0),
            DVec3::new(1.0, 0.5, -1.0),
            DVec3::new(0.0, 1.0, -1.0),
        ]);
        assert!(!refiner.stays_whole(&wide));
        let mut with_eye = tiny;
        with_eye[0] = refiner.node(DVec3::ZERO);
        assert!(with_eye[0].image.is_none() && refiner.stays_whole(&with_eye));
        let uniform_only = Refiner::new(&charted, None);
        assert!(uniform_only.stays_whole(&wide));
    }

    #[test]
    fn uniform_grid_makes_n_squared_pieces() {
        let projection = panorama();
        let charted = projection.inverse().unwrap().charted().unwrap();
        let refiner = Refiner::new(&charted, None);
        let corners = [
            DVec3::new(-1.0, 0.0, -2.0),
            DVec3::new(1.0, 0.0, -2.0),
            DVec3::new(0.0, 1.0, -2.0),
        ]
        .map(|p| refiner.node(p));
        for n in [1, 2, 3, 8] {
            let mut pieces = Vec::new();
            refiner.uniform(corners, n, &mut Vec::new(), &mut |p| pieces.push(p));
            assert_eq!(pieces.len() as u32, n * n);
            let area: f64 = pieces
                .iter()
                .map(|[a, b, c]| 0.5 * (b.point - a.point).cross(c.point - a.point).length())
                .sum();
            assert!((area - 1.0).abs() < 1e-12, "{n}: {area}");
        }
    }
}
