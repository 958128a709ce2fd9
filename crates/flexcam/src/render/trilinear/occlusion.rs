//! The occlusion cull of a projection triangle drawn as a central projection: where scene
//! triangles before its focus cover its whole domain, its live pairs lying wholly behind
//! them are not drawn.
//!
//! Through a central projection the depth is affine in the scene point (`t = t0 (1 - w)`,
//! module `central`, `w` 1 on the base and 0 at the focus), so a scene triangle is nowhere
//! nearer than its corner of greatest `w`. The covers are the live pairs with every corner
//! before the focus and beyond the base (`w` in `(HIDDEN_MARGIN, 1 - HIDDEN_MARGIN)`) and an
//! image of non-zero area: the image of each is the triangle of its corners' images. Covers
//! sharing an edge (the same two scene vertices) with their images on either side of it are
//! joined into sets; an edge not so shared is a boundary edge of its covers' set. The union
//! of a set holds the whole domain (widened by [`COVER_MARGIN`] beyond the clipping's margin)
//! when the domain's centre lies strictly inside one of its covers and none of its boundary
//! edges comes within [`COVER_MARGIN`] of the domain: away from those edges the union is
//! open and closed in the domain, which is connected. Every ray of the projection triangle
//! then meets a cover of the set in front of the view plane, at `w` no less than the least
//! `w` of the set's corners. A live pair whose corners all lie below that (for the best such
//! set) by more than
//! [`HIDDEN_MARGIN`] has every fragment it could draw (its polygons are clipped to the
//! domain) beaten in the z-test by a cover's exact fragment at the same pixel, so dropping
//! it changes no pixel: the frame is the same, with less drawn. On the inward-looking
//! sphere, whose focus lies inside the cube, the cube's faces hide what lies beyond the
//! focus, and the floor hides the cube's underside from below.
//!
//! Degenerate cases (each has a test): a projection triangle whose covers leave part of the
//! domain open culls nothing (a set is only as good as its own edges: a small triangle in
//! front of a cover is a set of its own); a pair with a NaN corner
//! is never hidden; a scene triangle seen edge on (image of zero area), or reaching beyond
//! the focus or the base, covers nothing; covers meeting only at a vertex, or folded over
//! an edge, or a mesh whose triangles do not share their vertices, leave a boundary edge
//! there; a pair that may reach the focus (`CentralProjection::may_reach_focus`) is never
//! hidden, so that a projection triangle ray cast for one is ray cast as before.

use glam::DVec2;

use super::central::CentralProjection;
use super::pair_cull::LivePairs;
use super::scene_geometry::SceneGeometry;

/// How far (in barycentric units) the covers' boundary edges must keep off the domain, the
/// domain's centre inside a cover, and how far the domain is widened: far above
/// [`super::clip`]'s domain margin (1e-9), the rounding of the images and of the clipped
/// outlines, and the distance at which the projection triangle's own rays (meeting only
/// within `central::MEETING_TOL`) pass the central projection's.
const COVER_MARGIN: f64 = 1e-6;

/// How far (in `w`) a pair must lie behind the covers to be hidden, and a cover's corners
/// inside `(0, 1)`: far above the rounding of the exact hits its fragments are resolved to
/// and of the rays' meeting at the focus.
const HIDDEN_MARGIN: f64 = 1e-6;

/// A scene vertex as one central projection sees it: its `w` and its image.
#[derive(Debug, Clone, Copy)]
struct Seen {
    /// The projection triangle this entry belongs to (the cull's generation).
    stamp: u32,
    w: f64,
    image: DVec2,
}

/// An edge of a cover: its vertices (the lesser first), the cover's third vertex and the
/// cover (its index in [`Occlusion::covers`]).
type CoverEdge = ((u32, u32), u32, u32);

/// A cover while the sets are formed: its set (union-find parent: itself at a set's root),
/// and for a root, of the whole set: the least `w` of the corners, whether the domain's
/// centre lies inside one of them, and whether a boundary edge comes near the domain.
#[derive(Debug, Clone, Copy)]
struct Cover {
    set: u32,
    least: f64,
    centred: bool,
    open: bool,
}

/// The root of cover `c`'s set, shortening the path on the way.
fn set_of(covers: &mut [Cover], mut c: u32) -> u32 {
    while covers[c as usize].set != c {
        let parent = covers[c as usize].set;
        covers[c as usize].set = covers[parent as usize].set;
        c = parent;
    }
    c
}

/// The occlusion cull's reused state, one per worker: the scene vertices as the current
/// projection triangle sees them (each computed once, valid when stamped with the current
/// generation; allocated on the first cull, so that a worker that draws no central
/// projection allocates nothing) and the covers' edges.
pub struct Occlusion {
    vertices: usize,
    seen: Vec<Seen>,
    generation: u32,
    edges: Vec<CoverEdge>,
    covers: Vec<Cover>,
}

/// The domain widened by [`COVER_MARGIN`], counterclockwise.
const DOMAIN: [DVec2; 3] = [
    DVec2::new(-COVER_MARGIN, -COVER_MARGIN),
    DVec2::new(1.0 + 2.0 * COVER_MARGIN, -COVER_MARGIN),
    DVec2::new(-COVER_MARGIN, 1.0 + 2.0 * COVER_MARGIN),
];

impl Occlusion {
    /// The cull's state for a scene of `vertices` vertices.
    pub fn new(vertices: usize) -> Occlusion {
        Occlusion {
            vertices,
            seen: Vec::new(),
            generation: 0,
            edges: Vec::new(),
            covers: Vec::new(),
        }
    }

    /// Drops from `live` (the live pairs with `scene` of a projection triangle drawn as the
    /// central projection `central`) the pairs hidden behind the covers (module doc),
    /// keeping the others in order; returns how many were dropped.
    pub fn cull_hidden(
        &mut self,
        central: &CentralProjection,
        scene: &SceneGeometry,
        live: &mut LivePairs,
    ) -> u64 {
        if self.seen.is_empty() {
            let unseen = Seen {
                stamp: 0,
                w: 0.0,
                image: DVec2::ZERO,
            };
            self.seen = vec![unseen; self.vertices];
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.seen.iter_mut().for_each(|s| s.stamp = 0);
            self.generation = 1;
        }
        let Some(cover) = self.cover(central, scene, live) else {
            return 0;
        };
        let behind = cover - HIDDEN_MARGIN;
        let before = live.pairs.len();
        live.pairs.retain(|pair| {
            let w = self.corners(central, scene, pair.triangle).map(|s| s.w);
            // A NaN corner fails the comparison: kept.
            let hidden = w[0] < behind && w[1] < behind && w[2] < behind;
            !hidden || central.may_reach_focus(scene.corners(pair.triangle as usize))
        });
        (before - live.pairs.len()) as u64
    }

    /// Where a set of covers among `live`'s pairs holds the whole domain (module doc), the
    /// greatest least `w` of the corners of such a set.
    fn cover(
        &mut self,
        central: &CentralProjection,
        scene: &SceneGeometry,
        live: &LivePairs,
    ) -> Option<f64> {
        let mut edges = std::mem::take(&mut self.edges);
        let mut covers = std::mem::take(&mut self.covers);
        edges.clear();
        covers.clear();
        let centre = DVec2::splat(1.0 / 3.0);
        for pair in &live.pairs {
            let corners = self.corners(central, scene, pair.triangle);
            let ahead = |s: &Seen| s.w > HIDDEN_MARGIN && s.w < 1.0 - HIDDEN_MARGIN;
            if !corners.iter().all(ahead) {
                continue;
            }
            let image = corners.map(|s| s.image);
            let area = (image[1] - image[0]).perp_dot(image[2] - image[0]);
            if !(area.is_finite() && area != 0.0) {
                continue;
            }
            let c = covers.len() as u32;
            covers.push(Cover {
                set: c,
                least: corners.iter().fold(f64::INFINITY, |l, s| l.min(s.w)),
                centred: clearly_inside(image, area.signum(), centre),
                open: false,
            });
            let v = scene.triangles[pair.triangle as usize];
            for i in 0..3 {
                let (a, b) = (v[i], v[(i + 1) % 3]);
                edges.push(((a.min(b), a.max(b)), v[(i + 2) % 3], c));
            }
        }
        // Covers joined across their shared edges into sets; a set with a boundary edge
        // near the domain leaves it open.
        edges.sort_unstable();
        let image = |i: u32| self.seen[i as usize].image;
        for shared in edges.chunk_by(|x, y| x.0 == y.0) {
            let (a, b) = (image(shared[0].0 .0), image(shared[0].0 .1));
            let side = |c: u32| (b - a).perp_dot(image(c) - a);
            if shared.len() == 2 && side(shared[0].1) * side(shared[1].1) < 0.0 {
                let (x, y) = (
                    set_of(&mut covers, shared[0].2),
                    set_of(&mut covers, shared[1].2),
                );
                covers[x as usize].set = y;
            } else if !clear_of_domain(a, b) {
                shared.iter().for_each(|e| covers[e.2 as usize].open = true);
            }
        }
        for c in 0..covers.len() as u32 {
            let set = set_of(&mut covers, c) as usize;
            let Cover {
                least,
                centred,
                open,
                ..
            } = covers[c as usize];
            let whole = &mut covers[set];
            whole.least = whole.least.min(least);
            whole.centred |= centred;
            whole.open |= open;
        }
        let best = covers
            .iter()
            .enumerate()
            .filter(|&(c, cover)| cover.set == c as u32 && cover.centred && !cover.open)
            .map(|(_, cover)| cover.least)
            .fold(f64::NEG_INFINITY, f64::max);
        self.edges = edges;
        self.covers = covers;
        (best > f64::NEG_INFINITY).then_some(best)
    }

    /// The corners of scene triangle `k` as `central` sees them, each computed once per
    /// projection triangle.
    fn corners(&mut self, central: &CentralProjection, scene: &SceneGeometry, k: u32) -> [Seen; 3] {
        let generation = self.generation;
        scene.triangles[k as usize].map(|i| {
            let seen = &mut self.seen[i as usize];
            if seen.stamp != generation {
                let (w, image) = central.depth_and_image(scene.vertices[i as usize]);
                *seen = Seen {
                    stamp: generation,
                    w,
                    image,
                };
            }
            *seen
        })
    }
}

/// Whether `point` lies inside the triangle `image` (of orientation `turn`, the sign of its
/// area) by more than [`COVER_MARGIN`].
fn clearly_inside(image: [DVec2; 3], turn: f64, point: DVec2) -> bool {
    (0..3).all(|i| {
        let (a, edge) = (image[i], image[(i + 1) % 3] - image[i]);
        turn * edge.perp_dot(point - a) > COVER_MARGIN * edge.length()
    })
}

/// Whether the segment from `a` to `b` keeps more than [`COVER_MARGIN`] off the widened
/// domain: both ends beyond one of its edges, or all its corners on one side of the
/// segment's line (separating axes). A segment of zero length is clear only beyond an
/// edge.
fn clear_of_domain(a: DVec2, b: DVec2) -> bool {
    let beyond_an_edge = (0..3).any(|i| {
        let (p, edge) = (DOMAIN[i], DOMAIN[(i + 1) % 3] - DOMAIN[i]);
        let clear = COVER_MARGIN * edge.length();
        edge.perp_dot(a - p) < -clear && edge.perp_dot(b - p) < -clear
    });
    let edge = b - a;
    let clear = COVER_MARGIN * edge.length();
    let sides = DOMAIN.map(|c| edge.perp_dot(c - a));
    beyond_an_edge || sides.iter().all(|&s| s > clear) || sides.iter().all(|&s| s < -clear)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::projection::ProjectionTriangleCache;
    use crate::render::trilinear::pair_cull::LivePair;

    const V: fn(f64, f64, f64) -> DVec3 = DVec3::new;

    /// Rays from a base triangle in `z = 0` meeting at `(0, 0, 4)`: `w` is 1 at `z = 0`, 0.5
    /// at `z = 2` (where the domain's rays pass within 0.5 of the axis), negative beyond 4.
    fn central() -> CentralProjection {
        let focus = V(0.0, 0.0, 4.0);
        let p = [V(-1.0, -1.0, 0.0), V(1.0, -1.0, 0.0), V(0.0, 1.0, 0.0)];
        let cache = ProjectionTriangleCache::new(p, p.map(|x| focus - x));
        CentralProjection::of(&cache).expect("central")
    }

    /// A triangle in the plane `z`, around the axis, `size` across.
    fn flat(z: f64, size: f64) -> [DVec3; 3] {
        [V(-size, -size, z), V(size, -size, z), V(0.0, size, z)]
    }

    /// The scene of `vertices` and `triangles`, every pair live.
    fn scene(vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> (SceneGeometry, LivePairs) {
        let live = LivePairs {
            pairs: (0..triangles.len() as u32)
                .map(|triangle| LivePair {
                    triangle,
                    solved: [u32::MAX; 3],
                })
                .collect(),
            ..LivePairs::default()
        };
        let mut geometry = SceneGeometry::default();
        (geometry.vertices, geometry.triangles) = (vertices, triangles);
        (geometry, live)
    }

    /// The scene of separate triangles (no shared vertices).
    fn separate(triangles: &[[DVec3; 3]]) -> (SceneGeometry, LivePairs) {
        let vertices = triangles.iter().flatten().copied().collect();
        let k = 0..triangles.len() as u32;
        scene(vertices, k.map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect())
    }

    /// The scene triangles kept by the cull.
    fn kept((geometry, mut live): (SceneGeometry, LivePairs)) -> Vec<u32> {
        let mut occlusion = Occlusion::new(geometry.vertices.len());
        let dropped = occlusion.cull_hidden(&central(), &geometry, &mut live);
        let kept: Vec<u32> = live.pairs.iter().map(|p| p.triangle).collect();
        assert_eq!(kept.len() as u64 + dropped, geometry.triangles.len() as u64);
        kept
    }

    /// Behind a cover at `z = 2` (holding the whole domain): a triangle at `z = 3` and one
    /// beyond the focus are hidden; one reaching from behind the cover across the focus's
    /// plane (it may reach the focus), one in front, one reaching in front of it, and one
    /// with a NaN corner are kept.
    #[test]
    fn triangles_wholly_behind_a_cover_are_hidden() {
        let mut nan = flat(3.0, 0.2);
        nan[1].z = f64::NAN;
        let triangles = [
            flat(2.0, 5.0),
            flat(3.0, 0.2),
            flat(6.0, 3.0),
            [V(-1.0, 0.0, 3.0), V(1.0, 0.0, 5.0), V(0.0, 1.0, 3.5)],
            flat(1.0, 0.2),
            [V(-1.0, 0.0, 3.0), V(1.0, 0.0, 1.9), V(0.0, 1.0, 3.5)],
            nan,
        ];
        assert_eq!(kept(separate(&triangles)), vec![0, 3, 4, 5, 6]);
    }

    /// A cover too small for the domain, one reaching beyond the base or beyond the focus,
    /// and one seen edge on (in a plane through the focus) hide nothing.
    #[test]
    fn covers_that_leave_part_of_the_domain_open_hide_nothing() {
        let behind = flat(3.0, 0.2);
        let mut beyond_base = flat(2.0, 5.0);
        beyond_base[2].z = -1.0;
        let mut beyond_focus = flat(2.0, 5.0);
        beyond_focus[2].z = 5.0;
        let edge_on = [V(0.0, -5.0, 0.5), V(0.0, 5.0, 0.5), V(0.0, 0.0, 3.5)];
        for cover in [flat(2.0, 0.3), beyond_base, beyond_focus, edge_on] {
            assert_eq!(kept(separate(&[cover, behind])), vec![0, 1], "{cover:?}");
        }
    }

    /// Two covers sharing the edge across the domain hold it together (the square they make
    /// hides the triangle behind); the same two triangles with their own vertices, folded
    /// over the edge (both on one side), or meeting only at a vertex, leave a boundary edge
    /// in the domain and hide nothing.
    #[test]
    fn covers_hold_the_domain_together_only_across_shared_edges() {
        let square = [
            V(-5.0, -4.0, 2.0),
            V(5.0, -6.0, 2.0),
            V(5.0, 5.0, 2.0),
            V(-5.0, 5.0, 2.0),
        ];
        let behind = flat(3.0, 0.2);
        let mut vertices = square.to_vec();
        vertices.extend(behind);
        let shared = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]];
        assert_eq!(kept(scene(vertices.clone(), shared)), vec![0, 1]);
        let halves = [
            [square[0], square[1], square[2]],
            [square[0], square[2], square[3]],
        ];
        assert_eq!(
            kept(separate(&[halves[0], halves[1], behind])),
            vec![0, 1, 2]
        );
        // The second triangle's third corner moved across the shared edge.
        vertices[3] = V(5.0, -20.0, 2.0);
        let folded = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]];
        assert_eq!(kept(scene(vertices.clone(), folded)), vec![0, 1, 2]);
        // Two triangles meeting at the axis, each holding half the domain around it.
        let centre = V(0.0, -0.1, 2.0);
        let bow_tie = vec![
            centre,
            V(-5.0, -5.0, 2.0),
            V(5.0, -5.0, 2.0),
            V(5.0, 5.0, 2.0),
            V(-5.0, 5.0, 2.0),
        ];
        let mut bow_tie = bow_tie;
        bow_tie.extend(behind);
        let triangles = vec![[0, 1, 2], [0, 3, 4], [5, 6, 7]];
        assert_eq!(kept(scene(bow_tie, triangles)), vec![0, 1, 2]);
    }
}
