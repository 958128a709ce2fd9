//! A shape's outline: its polygon of vertex images with every curved edge sampled along the
//! exact image of its scene edge (`edge_path`): anchors at `t = 0` and at the crossings with
//! the projection triangle's edge surfaces, then the curve samples of the chosen mode.

use glam::DVec3;

use super::central::CentralProjection;
use super::clip::DOMAIN_MARGIN;
use super::edge_path::{refine_around, CrossingQuadratic, EdgePath, EdgeSurface, OutlinePoint};
use super::ray_fan::RayFan;
use super::screen_map::ScreenMap;
use super::volume_bounds::VolumeBounds;
use crate::geometry::Roots;
use crate::projection::{SceneEdge, Shape, ShapeVertex};

/// How a polygon edge is sampled between its anchors.
#[derive(Debug, Clone, Copy)]
pub enum Sampling<'a> {
    /// Anchors only (the edges of tessellated sub-triangles are short).
    Anchors,
    /// The given depths (the shape's slices, ascending), where they fall on the edge.
    Slices(&'a [f64]),
    /// Bisection to the screen tolerance, bounded over each whole piece, at most `levels`
    /// deep (`edge_path::refine`).
    Adaptive { tolerance: f64, levels: u32 },
}

/// One projection triangle as the outline tracer needs it.
#[derive(Debug, Clone, Copy)]
pub struct ProjectionTriangle {
    pub map: ScreenMap,
    /// The surfaces swept by the three edges, in the order of their domain lines `u = 0`
    /// (vertices 1-3), `v = 0` (vertices 1-2) and `u + v = 1` (vertices 2-3).
    pub surfaces: [EdgeSurface; 3],
    /// Its base points and ray directions, from which the cull forms its bounding planes
    /// ([`Self::bounds`]) once per render: stored, the planes (about 850 bytes) made the
    /// projection triangles the largest piece of fresh memory a small frame touches.
    base: [DVec3; 3],
    directions: [DVec3; 3],
    /// Whether the renderer ray casts its pixels instead of projecting the scene into it
    /// (set by the renderer, which knows the scene's depth; false from [`Self::new`]): it
    /// then has no live pairs.
    pub ray_cast: bool,
    /// Where its rays all meet in one point inside the scene's reach: the central
    /// projection its pairs are drawn with instead of their cubics and outlines (set by
    /// the renderer; `None` from [`Self::new`]).
    pub central: Option<CentralProjection>,
    /// Where two of its vertices share base point and ray (its rays a one-parameter
    /// family, sweeping no volume): the fan its pairs are drawn with as strips instead of
    /// their cubics and outlines (set by the renderer; `None` from [`Self::new`]).
    pub fan: Option<RayFan>,
    /// The depths at which its parametric triangle degenerates, first and last
    /// (`ProjectionTriangleCache::degenerate_depths`): a shape reaching across them has an
    /// outline through infinity, and its pair is split at the depths around them
    /// (`degenerate_band`).
    pub degenerate: Option<(f64, f64)>,
}

impl ProjectionTriangle {
    /// The triangle with base points `p`, directions `n` and screen placement `map`.
    pub fn new(p: [DVec3; 3], n: [DVec3; 3], map: ScreenMap) -> ProjectionTriangle {
        let vertex = |k: usize| (p[k], n[k]);
        ProjectionTriangle {
            map,
            surfaces: [
                EdgeSurface::new(vertex(0), vertex(2)),
                EdgeSurface::new(vertex(0), vertex(1)),
                EdgeSurface::new(vertex(1), vertex(2)),
            ],
            base: p,
            directions: n,
            ray_cast: false,
            central: None,
            fan: None,
            degenerate: map.cache().degenerate_depths(),
        }
    }

    /// Bounding planes of the volume its rays sweep at `t >= 0` (the cull).
    pub fn bounds(&self) -> VolumeBounds {
        VolumeBounds::new(self.base, self.directions)
    }
}

/// At most one view-plane anchor, two crossings with each of three edge surfaces and the two
/// ends of a degenerate band.
const MAX_ANCHORS: usize = 9;

/// The crossings of one scene triangle's three edges with one projection triangle's three
/// edge surfaces (scene-space clipping's anchors), shared by every polygon edge of the
/// triangle's shapes: a scene edge is imaged by several polygon edges (about 5 polygon edges
/// over 1.6 shapes per live pair on cube-floor through the 18-projection fan), and each
/// crossing quadratic depends on the scene edge and the surface only, not on the polygon
/// edge's depth range. So each quadratic is formed once, tested once over the depth range
/// of all the shapes' vertices (a quadratic clear of roots there is clear for every polygon
/// edge, whose range lies inside), and solved at most once, when a polygon edge's own range
/// is not clear of it. The anchors found are the same, bit for bit, as solving per polygon
/// edge: the same coefficients and solver, the roots kept by the same strict range test.
pub struct EdgeCrossings {
    /// `[scene edge][surface]`: the quadratic, `None` where it is clear of roots over the
    /// shapes' depth range (or without scene-space clipping).
    quadratics: [[Option<CrossingQuadratic>; 3]; 3],
    /// Its roots, once a polygon edge needed them.
    roots: [[Option<Roots>; 3]; 3],
    /// Depths at which every edge is anchored as well (the ends of a degenerate band, where
    /// the outline is cut: `degenerate_band`).
    depths: [Option<f64>; 2],
    /// Whether the quadratics were formed (scene-space clipping): without them nothing is
    /// known about the crossings, and [`EdgeCrossings::misses`] says so.
    formed: bool,
}

impl EdgeCrossings {
    /// No crossings: outlines without scene-space clipping.
    pub fn none() -> EdgeCrossings {
        EdgeCrossings {
            quadratics: [[None; 3]; 3],
            roots: [[None; 3]; 3],
            depths: [None; 2],
            formed: false,
        }
    }

    /// The same crossings, with every polygon edge also anchored at the depths `lo` and
    /// `hi` where it passes them (exact outline points there, so that a cut at either depth
    /// passes through them).
    pub fn anchored_at(self, (lo, hi): (f64, f64)) -> EdgeCrossings {
        EdgeCrossings {
            depths: [Some(lo), Some(hi)],
            ..self
        }
    }

    /// The crossings of the edges of the scene triangle `scene` with the edge surfaces of
    /// `triangle`, for polygon edges whose depths lie in `[lo, hi]`: the range of the depths
    /// of all the shapes' vertices ([`depth_range`]). Degenerate cases: an empty range
    /// (`lo >= hi`: no vertex, or all at one depth) has no polygon edge with a depth strictly
    /// between its ends, so no crossing is kept, and none is formed (every quadratic would
    /// be found clear of roots there, [`CrossingQuadratic::clear_between`]: a pair whose
    /// shapes are all behind the view plane forms none of its nine); a NaN bound is such a
    /// range too; an infinite one tests nothing clear.
    pub fn new(triangle: &ProjectionTriangle, scene: [DVec3; 3], (lo, hi): (f64, f64)) -> Self {
        let mut crossings = EdgeCrossings {
            formed: true,
            ..EdgeCrossings::none()
        };
        let has_inside = lo < hi;
        if !has_inside {
            return crossings;
        }
        for edge in [SceneEdge::V1V2, SceneEdge::V1V3, SceneEdge::V2V3] {
            let [a, b] = edge.vertices().map(|k| scene[k as usize]);
            for (slot, surface) in crossings.quadratics[edge.index()]
                .iter_mut()
                .zip(&triangle.surfaces)
            {
                let quadratic = surface.crossing_quadratic(a, b);
                *slot = (!quadratic.clear_between(lo, hi)).then_some(quadratic);
            }
        }
        crossings
    }

    /// Whether scene edge `edge` provably does not cross edge surface number `surface` (of
    /// [`ProjectionTriangle::surfaces`]) at a depth strictly between `from` and `to` (a
    /// polygon edge's, inside the depth range the crossings were formed for): its
    /// quadratic is clear of roots there ([`CrossingQuadratic::clear_between`]). `false`
    /// whenever that is not known: crossings formed without scene-space clipping
    /// ([`EdgeCrossings::none`]).
    pub fn misses(&self, edge: SceneEdge, surface: usize, from: f64, to: f64) -> bool {
        self.formed
            && self.quadratics[edge.index()][surface]
                .is_none_or(|q| q.clear_between(from.min(to), from.max(to)))
    }

    /// Calls `keep` with the crossings of scene edge `edge` that may lie strictly between
    /// `lo` and `hi` (the caller tests that), surface by surface, each surface's in the
    /// solver's order.
    fn each(&mut self, edge: SceneEdge, (lo, hi): (f64, f64), mut keep: impl FnMut(f64)) {
        let (quadratics, roots) = (
            &self.quadratics[edge.index()],
            &mut self.roots[edge.index()],
        );
        for (quadratic, roots) in quadratics.iter().zip(roots) {
            let Some(quadratic) = quadratic else { continue };
            if quadratic.clear_between(lo, hi) {
                continue;
            }
            let roots = roots.get_or_insert_with(|| quadratic.roots());
            roots.as_slice().iter().for_each(|&t| keep(t));
        }
    }
}

/// The range of the depths of the vertices of `shapes`, `(INFINITY, NEG_INFINITY)` when
/// there are none (NaN depths are passed over, as `f64::min` does).
pub fn depth_range<'a>(shapes: impl IntoIterator<Item = Shape<'a>>) -> (f64, f64) {
    shapes
        .into_iter()
        .flat_map(|shape| shape.vertices.iter())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x.t), hi.max(x.t))
        })
}

/// Whether the outline [`trace_outline`] would give for `shape` lies wholly beyond one
/// domain line, past the clip's margin, so that clipping leaves nothing and tracing it can
/// be skipped. The test of the pair cull (`polygons::cull`), per shape: every vertex image
/// strictly beyond the line `u = 0`, `v = 0` or `u + v = 1` by more than
/// [`DOMAIN_MARGIN`], and no polygon edge crossing that line's edge surface within its
/// depths (`crossings`, those of [`EdgeCrossings::new`] for the shapes of `shape`'s pair:
/// each edge's image is then a continuous curve in `(u, v)` that keeps to one side of the
/// line, as its ends do, and so does the closed outline and its inside).
///
/// Degenerate cases: a shape whose depths reach a depth in `degenerate` (where the
/// projection triangle's parametric triangle degenerates) is never skipped: its edges'
/// images may pass through infinity there and come back on the other side of a line
/// without crossing it; crossings formed without scene-space clipping know nothing and skip
/// nothing; a NaN coordinate is not beyond a line. Rounding: a point the tracer computes
/// may land within the margin of a line its quadratic says the edge does not cross
/// ([`CrossingQuadratic::clear_between`] keeps `1e-9` of the terms' size off zero), where
/// the clip would have kept a sliver some `1e-9` of the triangle wide, covering no pixel
/// centre but by coincidence.
pub fn is_outside_domain(
    shape: &Shape,
    crossings: &EdgeCrossings,
    degenerate: Option<(f64, f64)>,
) -> bool {
    let (lo, hi) = depth_range([*shape]);
    if degenerate.is_some_and(|(first, last)| lo <= last && hi >= first) {
        return false;
    }
    // In the order of the edge surfaces ([`ProjectionTriangle::surfaces`]).
    let beyond: [fn(&ShapeVertex) -> bool; 3] = [
        |x| x.u < -DOMAIN_MARGIN,
        |x| x.v < -DOMAIN_MARGIN,
        |x| x.u + x.v > 1.0 + DOMAIN_MARGIN,
    ];
    let n = shape.len();
    beyond.iter().enumerate().any(|(surface, beyond)| {
        shape.vertices.iter().all(beyond)
            && (0..n).all(|i| {
                let (from, to) = (shape.vertices[i].t, shape.vertices[(i + 1) % n].t);
                crossings.misses(shape.edges[i], surface, from, to)
            })
    })
}

/// Appends the outline of `shape` (of the scene triangle with vertices `scene`) to `out`:
/// per polygon edge, its start image, then its anchors and curve samples in travel order.
/// The anchors are `t = 0` and the edge-surface crossings of `crossings` (none without
/// `scene_clipping`: the crossings are then left to the clip's interpolation).
pub fn trace_outline(
    triangle: &ProjectionTriangle,
    shape: &Shape,
    scene: [DVec3; 3],
    (sampling, scene_clipping): (Sampling, bool),
    crossings: &mut EdgeCrossings,
    out: &mut Vec<OutlinePoint>,
) {
    let point = |x: &ShapeVertex| OutlinePoint {
        u: x.u,
        v: x.v,
        t: x.t,
    };
    let n = shape.len();
    for i in 0..n {
        let (start, end) = (
            point(&shape.vertices[i]),
            point(&shape.vertices[(i + 1) % n]),
        );
        out.push(start);
        let edge = shape.edges[i];
        let [a, b] = edge.vertices().map(|k| scene[k as usize]);
        let path = EdgePath {
            cache: triangle.map.cache(),
            a,
            b,
        };
        let mut previous = start;
        let piece = |out: &mut Vec<OutlinePoint>, ends| {
            sample_piece(triangle, &path, ends, (sampling, scene_clipping), out)
        };
        for t in anchors(crossings, edge, start.t, end.t).iter().flatten() {
            if let Some(anchor) = path.at(*t) {
                piece(out, (previous, anchor));
                out.push(anchor);
                previous = anchor;
            }
        }
        piece(out, (previous, end));
    }
}

/// The anchor depths strictly between `from` and `to`, in travel order (unused slots `None`):
/// `t = 0`, the crossings of scene edge `edge` in `crossings` and its anchoring depths.
fn anchors(
    crossings: &mut EdgeCrossings,
    edge: SceneEdge,
    from: f64,
    to: f64,
) -> [Option<f64>; MAX_ANCHORS] {
    let (lo, hi) = (from.min(to), from.max(to));
    let mut found = [None; MAX_ANCHORS];
    let mut count = 0;
    let mut keep = |t: f64| {
        if lo < t && t < hi && count < MAX_ANCHORS {
            found[count] = Some(t);
            count += 1;
        }
    };
    crossings.each(edge, (lo, hi), &mut keep);
    crossings.depths.iter().flatten().for_each(|&t| keep(t));
    keep(0.0);
    let slots = &mut found[..count];
    slots.sort_by(|x, y| x.unwrap_or(0.0).total_cmp(&y.unwrap_or(0.0)));
    if from > to {
        slots.reverse();
    }
    found
}

/// Appends the curve samples of the piece between two consecutive outline points (excluded)
/// if the piece is visible: between anchors a piece is wholly visible or wholly clipped, so
/// the image at its middle depth decides (and is the first bisection point of adaptive
/// sampling, not computed twice). Without `scene_clipping` only the `t = 0` anchor
/// separates pieces, so only a piece behind the view plane is skipped.
fn sample_piece(
    triangle: &ProjectionTriangle,
    path: &EdgePath,
    (a, b): (OutlinePoint, OutlinePoint),
    (sampling, scene_clipping): (Sampling, bool),
    out: &mut Vec<OutlinePoint>,
) {
    if matches!(sampling, Sampling::Anchors) {
        return;
    }
    let Some(middle) = path.at(0.5 * (a.t + b.t)) else {
        return;
    };
    let visible = if scene_clipping {
        middle.is_visible(0.0)
    } else {
        middle.t >= 0.0
    };
    if !visible {
        return;
    }
    match sampling {
        Sampling::Anchors => {}
        Sampling::Slices(depths) => {
            let (lo, hi) = (a.t.min(b.t), a.t.max(b.t));
            let inside = depths.iter().filter(|&&t| lo < t && t < hi);
            let before = out.len();
            out.extend(inside.filter_map(|&t| path.at(t)));
            if a.t > b.t {
                out[before..].reverse();
            }
        }
        Sampling::Adaptive { tolerance, levels } => {
            refine_around(path, &triangle.map, (a, middle, b), tolerance, levels, out)
        }
    }
}

/// The thesis's slice depths of a shape: `count` depths evenly spaced strictly inside
/// `[max(0, t_min), t_max]` of its vertices (none when that range is empty), into `out`.
pub fn slice_depths(shape: &Shape, count: u32, out: &mut Vec<f64>) {
    out.clear();
    let (lo, hi) = shape
        .vertices
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x.t), hi.max(x.t))
        });
    let lo = lo.max(0.0);
    if hi > lo {
        let step = (hi - lo) / f64::from(count + 1);
        out.extend((1..=count).map(|i| lo + step * f64::from(i)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::{project_triangle, ProjectionTriangleCache};
    use crate::render::trilinear::polygons::tests::test_triangle;
    use glam::DVec2;
    use proptest::prelude::*;

    /// The anchors of one polygon edge solved on their own, as before the crossings were
    /// shared: every surface's roots strictly inside the edge's depth range, then `t = 0`,
    /// sorted in travel order.
    fn anchors_alone(
        triangle: &ProjectionTriangle,
        (a, b): (DVec3, DVec3),
        from: f64,
        to: f64,
    ) -> Vec<f64> {
        let (lo, hi) = (from.min(to), from.max(to));
        let mut found: Vec<f64> = triangle
            .surfaces
            .iter()
            .flat_map(|surface| surface.crossing_depths(a, b))
            .chain([0.0])
            .filter(|&t| lo < t && t < hi)
            .take(MAX_ANCHORS)
            .collect();
        found.sort_by(f64::total_cmp);
        if from > to {
            found.reverse();
        }
        found
    }

    proptest! {
        /// The anchors found through the shared crossings of a scene triangle are those of
        /// each polygon edge solved on its own, bit for bit, for every polygon edge of every
        /// shape, including scene triangles straddling the view plane and the domain lines.
        #[test]
        fn shared_crossings_give_each_edge_its_own_anchors(
            corners in proptest::array::uniform3(
                (-2.0..2.0f64, -2.0..2.0f64, -1.0..6.0f64)
            ),
        ) {
            let (triangle, cache) = test_triangle();
            let scene = corners.map(|(x, y, z)| DVec3::new(x, y, z));
            let Ok(shapes) = project_triangle(&cache, scene) else { return Ok(()) };
            let mut crossings = EdgeCrossings::new(&triangle, scene, depth_range(shapes.iter()));
            for shape in shapes.iter() {
                let count = shape.len();
                for i in 0..count {
                    let (from, to) = (shape.vertices[i].t, shape.vertices[(i + 1) % count].t);
                    let edge = shape.edges[i];
                    let [a, b] = edge.vertices().map(|k| scene[k as usize]);
                    let shared: Vec<f64> =
                        anchors(&mut crossings, edge, from, to).iter().flatten().copied().collect();
                    prop_assert_eq!(shared, anchors_alone(&triangle, (a, b), from, to));
                }
            }
        }
    }

    /// Without scene-space clipping the only anchor is the view plane's.
    #[test]
    fn no_crossings_leave_the_view_plane_anchor() {
        let mut none = EdgeCrossings::none();
        let found = anchors(&mut none, SceneEdge::V1V3, 2.0, -1.0);
        assert_eq!(found.iter().flatten().copied().collect::<Vec<_>>(), [0.0]);
        assert!(anchors(&mut none, SceneEdge::V1V2, 1.0, 3.0)
            .iter()
            .all(Option::is_none));
    }

    /// No shape vertex (an empty depth range), or all at one depth: no polygon edge has a
    /// depth strictly between its ends, and no quadratic is kept.
    #[test]
    fn an_empty_depth_range_keeps_no_quadratic() {
        assert_eq!(depth_range([]), (f64::INFINITY, f64::NEG_INFINITY));
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let n = [
            DVec3::Z,
            DVec3::new(0.1, 0.0, 1.0),
            DVec3::new(0.0, 0.1, 1.0),
        ];
        let cache = ProjectionTriangleCache::new(p, n);
        let screen = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let triangle =
            ProjectionTriangle::new(p, n, ScreenMap::new(screen, DVec2::splat(8.0), cache));
        // A scene triangle across the edge surface u = 0 at every depth.
        let scene = [
            DVec3::new(-1.0, 0.3, 2.0),
            DVec3::new(1.0, 0.3, 2.0),
            DVec3::new(0.5, 0.6, 3.0),
        ];
        let live =
            |crossings: &EdgeCrossings| crossings.quadratics.iter().flatten().flatten().count();
        assert!(live(&EdgeCrossings::new(&triangle, scene, (0.0, 10.0))) > 0);
        for range in [(f64::INFINITY, f64::NEG_INFINITY), (2.0, 2.0), (3.0, 1.0)] {
            assert_eq!(
                live(&EdgeCrossings::new(&triangle, scene, range)),
                0,
                "{range:?}"
            );
        }
    }
}
