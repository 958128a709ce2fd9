//! Projecting a scene triangle through one trilinear projection triangle into shapes (Vallance 2005,
//! chapter 4, with the corrections of notes/trilinear.md, "Connecting projected vertices").
//!
//! # Why shapes
//!
//! At every depth `t` the parametric triangle `r1(t), r2(t), r3(t)` spans a plane, which cuts
//! the scene triangle's plane in a line. As `t` grows the line sweeps over the scene triangle;
//! it crosses a scene edge exactly while the edge's two end vertices lie on opposite sides of
//! the plane, and it passes a scene vertex exactly at a root of that vertex's cubic
//! (`point_projection`). Sorting all images of the three vertices by `t` therefore tells which
//! scene edges are crossed between consecutive images: each image of vertex `k` toggles the two
//! scene edges at `k`. Whenever no edge is crossed, the sweep has left the triangle and the
//! images so far form one closed *shape*. A scene triangle images as 1 to 4 shapes of 2 to 7
//! or 9 vertices (never 1 or 8), 3, 5, 7 or 9 vertices in all when every vertex has 1 or 3
//! images.
//!
//! # Grouping (listing 4.2, corrected)
//!
//! Edges are numbered `<V1V2, V1V3, V2V3>` (bits 0, 1, 2 of a mask); vertex masks are
//! `e(V1) = <1,1,0>`, `e(V2) = <1,0,1>`, `e(V3) = <0,1,1>`. A state `s` starts at 0, takes
//! `s ^= e(vertex)` per image in `t` order, and each return to 0 closes a shape (the last one
//! included: listing 4.2 forgets to emit it).
//!
//! # Ordering (listing 4.3, corrected)
//!
//! While a shape is open exactly two scene edges are crossed, and they share one scene vertex
//! (the *common* vertex). Each crossing point is the end of a chain of polygon vertices:
//! `left` and `right`, with designators `left_a`, `right_a` naming the other end vertex of each
//! chain's edge. At the start image of vertex `a`: `left = [it]`, `right = []`,
//! `left_a = a + 1 (mod 3)`, `right_a` the third vertex (the common vertex is `a`). Then, per
//! image of vertex `x` (0-based indices, so "the third vertex of a and b" is `3 - a - b`):
//!
//! * `x == left_a`: the left crossing reached `x` and continues along the edge from `x` to
//!   `right_a`; push to `left`; the common vertex becomes `right_a`, so
//!   `right_a = 3 - left_a - right_a`;
//! * `x == right_a`: symmetrically, push to `right`, `left_a = 3 - left_a - right_a`;
//! * otherwise `x` is the common vertex: both crossings meet there and the shape closes (it is
//!   pushed to `left`).
//!
//! The polygon is `left` followed by `right` reversed. A crossing point can come back to the
//! vertex it left (two consecutive images of `V3` on one chain image part of `V1V3` or `V2V3`,
//! not an edge "V3V3"), so each polygon edge records the scene edge its chain was on
//! ([`Shape::edges`]); view-plane clipping (4.6) needs it to compute crossings exactly.
//!
//! # When the sweep argument does not apply
//!
//! The grouping assumes that no edge is crossed at `t -> -inf` and at `t -> +inf`, and that
//! every sign change of a vertex's cubic is listed. [`project_triangle`] checks this per scene
//! triangle and otherwise returns an [`Unprojectable`] outcome (never a wrong shape):
//!
//! * **Roots lost to infinity** (`Solutions::lost_to_infinity`). Far along `t` the side of
//!   vertex `k` is the sign of the leading non-dropped coefficient of its cubic. All normals
//!   parallel (orthographic) drops two roots of every vertex and leaves the same linear
//!   coefficient for all three: accepted (one image each). Coplanar, non-parallel normals drop
//!   one root and leave `b_k t^2` with `b_k` depending on the vertex: accepted, with an *even*
//!   number of images per vertex (0 or 2), when the three `b_k` have the same sign (the plane
//!   leaves the scene triangle at both ends); otherwise the sweep is inside the triangle at
//!   infinity and the outcome is [`Unprojectable::OpenAtInfinity`]. So is any other mismatch:
//!   different numbers of lost roots for the three vertices (a root dropped as negligible for
//!   one vertex only) or leading signs that differ or vanish.
//! * **Multiple roots** (`multiplicity` 2 or 3): the image is listed that many times (equal
//!   copies, adjacent after sorting). A double root is a tangency: the vertex touches the plane
//!   and goes back, which toggles its edges twice; this is also what the solver's other
//!   possible answer for a near-double root (two close simple roots) gives, so the result does
//!   not depend on which one it chose. A tangency while no shape is open gives a 2-vertex
//!   shape with both vertices equal (zero area).
//! * **Rejected roots** (`Solutions::rejected`): a parametric triangle that degenerates at
//!   some `t` makes `t` a root for every scene point, so the three vertices flip sides
//!   together and the crossed edges do not change: such roots are dropped (perspective
//!   triangles: the double root at the eye, `t = -1`). This is exact when every vertex rejected
//!   a number of roots of the same parity; otherwise (rounding at the rejection threshold) the
//!   image counts disagree in parity and the walk ends open: [`Unprojectable::OpenShape`].
//! * **Every `t` a root** (`Solutions::is_every_t`) for some vertex: nothing is known about its
//!   side of the plane: [`Unprojectable::EveryDepth`].
//! * A non-finite scene coordinate: [`Unprojectable::NonFinite`].
//!
//! The renderer should skip an unprojectable (projection triangle, scene triangle) pair and
//! count it, or render that projection triangle by ray casting instead. All checks are exact
//! consequences of the solver's parity invariant (`geometry::roots`): for a finite cubic the
//! images with multiplicity plus the rejected and lost roots number 3 modulo 2.
//!
//! Images are taken inside the projection triangle or not and at any sign of `t`: clipping to
//! the screen triangle and to the view plane (`t >= 0`) happens after the shapes are formed.
//! Shapes of 4 or more vertices may be non-convex or self-intersecting (the filler needs an
//! explicit fill rule), and their edges are straight lines between images that should be
//! curves (section 4.5).

use std::fmt;

use glam::DVec3;

use super::{ProjectionTriangleCache, Solutions};

/// At most three images per scene vertex (counted with multiplicity), three vertices.
const MAX_VERTICES: usize = 9;

/// At most four shapes: every shape has at least two vertices.
const MAX_SHAPES: usize = 4;

/// Edge mask `e(k)` of scene vertex `k` (0-based) over the edge bits `<V1V2, V1V3, V2V3>`.
const VERTEX_MASK: [u8; 3] = [0b011, 0b101, 0b110];

/// A scene triangle's edge, named by its end vertices (`V1, V2, V3` are the scene vertices
/// 0, 1, 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SceneEdge {
    /// The edge from scene vertex 0 to vertex 1.
    V1V2,
    /// The edge from scene vertex 0 to vertex 2.
    V1V3,
    /// The edge from scene vertex 1 to vertex 2.
    V2V3,
}

impl SceneEdge {
    /// The edge between the distinct 0-based scene vertices `a` and `b`.
    fn between(a: u8, b: u8) -> SceneEdge {
        debug_assert!(a != b && a < 3 && b < 3);
        match a + b {
            1 => SceneEdge::V1V2,
            2 => SceneEdge::V1V3,
            _ => SceneEdge::V2V3,
        }
    }

    /// Its position in `[V1V2, V1V3, V2V3]` (tables indexed by scene edge).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The 0-based scene vertices at its ends, ascending.
    pub fn vertices(self) -> [u8; 2] {
        match self {
            SceneEdge::V1V2 => [0, 1],
            SceneEdge::V1V3 => [0, 2],
            SceneEdge::V2V3 => [1, 2],
        }
    }

    /// Whether scene vertex `k` (0-based) is one of its ends.
    pub fn contains(self, k: u8) -> bool {
        self.vertices().contains(&k)
    }
}

/// One image of a scene vertex: a solution of its cubic, a vertex of a shape's polygon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeVertex {
    /// Barycentric weight of the projection triangle's second vertex (its screen triangle is
    /// `(1 - u - v) S1 + u S2 + v S3`).
    pub u: f64,
    /// Barycentric weight of the third vertex.
    pub v: f64,
    /// Depth along the unnormalised `trinorm(u, v)`; negative behind the view plane.
    pub t: f64,
    /// The scene vertex imaged: 0, 1 or 2 for `V1`, `V2`, `V3`.
    pub scene_vertex: u8,
    /// `(u, v)` is inside the projection triangle (`TriangleSolution::inside`).
    pub inside: bool,
}

/// One shape: a closed polygon in the projection triangle's `(u, v)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape<'a> {
    /// The polygon's vertices in order (2 to 7 or 9 of them). A 2-vertex shape is a closed
    /// polygon of two edges (both images of the same scene vertex, joined by images of its two
    /// edges): it has no area in this linear approximation.
    pub vertices: &'a [ShapeVertex],
    /// `edges[i]` is the scene edge that the polygon edge from `vertices[i]` to
    /// `vertices[(i + 1) % len]` images (part of). Between images of two different scene
    /// vertices it is the edge joining them; between two images of the same vertex `k` it is
    /// one of the two edges at `k`. The two polygon edges at an image of `k` always image the
    /// two different scene edges at `k`.
    pub edges: &'a [SceneEdge],
}

impl Shape<'_> {
    /// Number of vertices (and of edges).
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Always `false`: a shape has at least two vertices.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }
}

/// The shapes of one scene triangle in one projection triangle, in ascending `t` order of
/// their first image (shapes do not overlap in `t`). Fixed capacity, no allocation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleShapes {
    /// The polygons of all shapes, one after the other.
    vertices: [ShapeVertex; MAX_VERTICES],
    /// `edges[i]` belongs to `vertices[i]` (see [`Shape::edges`]).
    edges: [SceneEdge; MAX_VERTICES],
    /// Exclusive end of each shape in `vertices`.
    ends: [u8; MAX_SHAPES],
    count: u8,
}

impl TriangleShapes {
    const EMPTY: TriangleShapes = TriangleShapes {
        vertices: [ShapeVertex {
            u: 0.0,
            v: 0.0,
            t: 0.0,
            scene_vertex: 0,
            inside: false,
        }; MAX_VERTICES],
        edges: [SceneEdge::V1V2; MAX_VERTICES],
        ends: [0; MAX_SHAPES],
        count: 0,
    };

    /// Number of shapes (0 to 4; 0 only when no vertex has an image, which needs roots lost
    /// to infinity).
    pub fn len(&self) -> usize {
        self.count as usize
    }

    /// `true` when there is no shape.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Shape `index` (`index < len()`).
    pub fn shape(&self, index: usize) -> Shape<'_> {
        let start = if index == 0 {
            0
        } else {
            self.ends[index - 1] as usize
        };
        let end = self.ends[..self.len()][index] as usize;
        Shape {
            vertices: &self.vertices[start..end],
            edges: &self.edges[start..end],
        }
    }

    /// The shapes in order.
    pub fn iter(&self) -> impl Iterator<Item = Shape<'_>> + '_ {
        (0..self.len()).map(|i| self.shape(i))
    }

    /// Total number of images over all shapes (3, 5, 7 or 9 when no root was lost to
    /// infinity).
    pub fn vertex_count(&self) -> usize {
        self.ends[..self.len()].last().map_or(0, |&e| e as usize)
    }
}

/// Why a scene triangle cannot be cut into shapes by one projection triangle (module doc,
/// "When the sweep argument does not apply"). The pair should be skipped (and counted) or
/// rendered another way; no shape is produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unprojectable {
    /// A scene vertex has a non-finite coordinate.
    NonFinite,
    /// The cubic of scene vertex `vertex` (0-based) vanishes identically: every depth images
    /// it (the parametric triangle is degenerate at every `t`, or its planes share a line
    /// through the vertex).
    EveryDepth {
        /// The scene vertex, 0-based.
        vertex: u8,
    },
    /// The plane of the parametric triangle still crosses the scene triangle at `t -> -inf`
    /// or `+inf`: the vertices' cubics lost different numbers of roots to infinity (listed
    /// per vertex), or their leading non-dropped coefficients differ in sign (coplanar
    /// normals with the scene triangle straddling the limit plane).
    OpenAtInfinity {
        /// The roots each vertex's cubic lost to infinity.
        lost_to_infinity: [u8; 3],
    },
    /// The sorted images do not close: their counts per vertex (listed, with multiplicity)
    /// differ in parity, from a degenerate-triangle root rejected for some vertices only.
    OpenShape {
        /// The images of each vertex.
        images: [u8; 3],
    },
}

impl fmt::Display for Unprojectable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Unprojectable::NonFinite => write!(f, "scene triangle has a non-finite coordinate"),
            Unprojectable::EveryDepth { vertex } => write!(
                f,
                "scene vertex {} is imaged at every depth (degenerate parametric triangle)",
                vertex + 1
            ),
            Unprojectable::OpenAtInfinity { lost_to_infinity } => write!(
                f,
                "the parametric plane crosses the scene triangle at infinite depth \
                 (roots lost to infinity per vertex: {lost_to_infinity:?})"
            ),
            Unprojectable::OpenShape { images } => write!(
                f,
                "the vertex images do not close into shapes (images per vertex: {images:?})"
            ),
        }
    }
}

impl std::error::Error for Unprojectable {}

/// Projects the scene triangle `scene` (vertices `V1, V2, V3`) through the projection
/// triangle of `cache` into shapes (module doc): every image of every vertex, inside the
/// projection triangle or not, at any sign of `t`.
pub fn project_triangle(
    cache: &ProjectionTriangleCache,
    scene: [DVec3; 3],
) -> Result<TriangleShapes, Unprojectable> {
    if !scene.iter().all(|v| v.is_finite()) {
        return Err(Unprojectable::NonFinite);
    }
    project_solved_triangle(cache, scene, scene.map(|v| cache.project_point(v)))
}

/// [`project_triangle`] with the vertices already projected (`solutions[k]` is
/// `cache.project_point(scene[k])`): a renderer projects each scene vertex once per projection
/// triangle and reuses it for every scene triangle sharing the vertex.
pub fn project_solved_triangle(
    cache: &ProjectionTriangleCache,
    scene: [DVec3; 3],
    solutions: [Solutions; 3],
) -> Result<TriangleShapes, Unprojectable> {
    if !scene.iter().all(|v| v.is_finite()) {
        return Err(Unprojectable::NonFinite);
    }
    if let Some(vertex) = solutions.iter().position(Solutions::is_every_t) {
        return Err(Unprojectable::EveryDepth {
            vertex: vertex as u8,
        });
    }
    let lost = solutions.map(|s| s.lost_to_infinity() as u8);
    // The side of each vertex far along t: the sign of its leading non-dropped coefficient
    // (the same coefficient, K3, for all three when nothing was lost).
    let leading = [0, 1, 2].map(|k| {
        let coefficients = cache.coefficients(scene[k]);
        coefficients
            .get(lost[k] as usize)
            .map_or(0.0, |c| c.signum())
    });
    let consistent = lost[1] == lost[0]
        && lost[2] == lost[0]
        && leading[0] != 0.0
        && leading[1] == leading[0]
        && leading[2] == leading[0];
    if !consistent {
        return Err(Unprojectable::OpenAtInfinity {
            lost_to_infinity: lost,
        });
    }

    let mut images = [TriangleShapes::EMPTY.vertices[0]; MAX_VERTICES];
    let mut len = 0;
    for (k, s) in solutions.iter().enumerate() {
        for x in s.iter() {
            for _ in 0..x.multiplicity {
                images[len] = ShapeVertex {
                    u: x.u,
                    v: x.v,
                    t: x.t,
                    scene_vertex: k as u8,
                    inside: x.inside,
                };
                len += 1;
            }
        }
    }
    let images = &mut images[..len];
    sort_by_depth(images);
    connect(images)
}

/// Stable insertion sort (at most 9 items) by `t`, ties by scene vertex: deterministic.
fn sort_by_depth(images: &mut [ShapeVertex]) {
    for i in 1..images.len() {
        let item = images[i];
        let mut j = i;
        while j > 0 && {
            let prev = &images[j - 1];
            prev.t
                .total_cmp(&item.t)
                .then(prev.scene_vertex.cmp(&item.scene_vertex))
                .is_gt()
        } {
            images[j] = images[j - 1];
            j -= 1;
        }
        images[j] = item;
    }
}

/// One side of an open shape: its images in order and, per image, the scene edge the
/// crossing point travelled along to reach it (for the start image, a placeholder that is
/// never read).
struct Chain {
    items: [(ShapeVertex, SceneEdge); MAX_VERTICES],
    len: usize,
}

impl Chain {
    fn new() -> Chain {
        Chain {
            items: [(TriangleShapes::EMPTY.vertices[0], SceneEdge::V1V2); MAX_VERTICES],
            len: 0,
        }
    }

    fn push(&mut self, vertex: ShapeVertex, arrived_along: SceneEdge) {
        self.items[self.len] = (vertex, arrived_along);
        self.len += 1;
    }

    fn as_slice(&self) -> &[(ShapeVertex, SceneEdge)] {
        &self.items[..self.len]
    }
}

/// Groups images sorted by `t` into shapes (XOR masks) and orders each into a polygon (two
/// chains), tagging every polygon edge with its scene edge (module doc). Errors with
/// [`Unprojectable::OpenShape`] when the last shape does not close.
fn connect(images: &[ShapeVertex]) -> Result<TriangleShapes, Unprojectable> {
    let mut out = TriangleShapes::EMPTY;
    let mut written = 0;
    let mut state = 0u8;
    let (mut left, mut right) = (Chain::new(), Chain::new());
    // Designators and the edge each chain is on (only meaningful while a shape is open).
    let (mut left_a, mut right_a) = (0u8, 0u8);
    let (mut left_edge, mut right_edge) = (SceneEdge::V1V2, SceneEdge::V1V2);
    for &image in images {
        let x = image.scene_vertex;
        if state == 0 {
            left = Chain::new();
            right = Chain::new();
            left_a = (x + 1) % 3;
            right_a = 3 - x - left_a;
            left_edge = SceneEdge::between(x, left_a);
            right_edge = SceneEdge::between(x, right_a);
            // The start image's "arrival" edge is never read: it opens the polygon.
            left.push(image, left_edge);
            state ^= VERTEX_MASK[x as usize];
            continue;
        }
        state ^= VERTEX_MASK[x as usize];
        let common = 3 - left_a - right_a;
        if x == left_a {
            left.push(image, left_edge);
            left_edge = SceneEdge::between(x, right_a);
            right_a = common;
        } else if x == right_a {
            right.push(image, right_edge);
            right_edge = SceneEdge::between(x, left_a);
            left_a = common;
        } else {
            debug_assert!(x == common && state == 0);
            left.push(image, left_edge);
            // Polygon: left, then right reversed. Edge i runs from vertex i to vertex i + 1.
            let start = written;
            let lefts = left.as_slice();
            for (i, &(vertex, _)) in lefts.iter().enumerate() {
                out.vertices[written] = vertex;
                // Left chain edges: from left[i] to left[i + 1], along left[i + 1]'s arrival;
                // from the closing image to the end of the right chain along the right edge.
                out.edges[written] = lefts.get(i + 1).map_or(right_edge, |next| next.1);
                written += 1;
            }
            // Right chain reversed: from right[j] back to right[j - 1] (or to the start
            // image), along right[j]'s arrival edge.
            for &(vertex, arrived) in right.as_slice().iter().rev() {
                out.vertices[written] = vertex;
                out.edges[written] = arrived;
                written += 1;
            }
            debug_assert!(written - start >= 2);
            out.ends[out.count as usize] = written as u8;
            out.count += 1;
        }
    }
    if state != 0 {
        let mut counts = [0u8; 3];
        for image in images {
            counts[image.scene_vertex as usize] += 1;
        }
        return Err(Unprojectable::OpenShape { images: counts });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::trilinear::point_projection::tests::vec3;
    use proptest::prelude::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    /// One example of appendix C: the view triangle (Table C.2: points, normals) and the scene
    /// triangle (Table C.1), as printed (2 and 3 significant digits).
    struct Example {
        name: &'static str,
        p: [DVec3; 3],
        n: [DVec3; 3],
        scene: [DVec3; 3],
    }

    fn appendix_c() -> [Example; 7] {
        [
            Example {
                name: "2,2,2,3",
                p: [
                    v(0.51, -0.96, 0.74),
                    v(-0.73, 0.82, 0.06),
                    v(-0.44, -0.70, -0.53),
                ],
                n: [
                    v(0.81, 0.26, -0.52),
                    v(0.06, -0.83, -0.56),
                    v(-0.11, 0.70, 0.70),
                ],
                scene: [
                    v(1.58e-1, -3.19e-1, 5.22e-2),
                    v(-2.17e-1, -4.18e-1, -4.91e-2),
                    v(2.50e-2, -2.30e-1, -2.02e-1),
                ],
            },
            Example {
                name: "3,3,3",
                p: [
                    v(0.82, 0.46, -0.80),
                    v(-0.25, 0.14, 0.67),
                    v(0.12, -0.20, -0.09),
                ],
                n: [
                    v(-0.43, -0.04, 0.90),
                    v(0.36, -0.62, -0.70),
                    v(-0.47, -0.61, -0.64),
                ],
                scene: [
                    v(9.62e-2, -4.57e-2, -1.10e-2),
                    v(5.35e-2, -1.44e-1, -3.84e-2),
                    v(7.26e-2, -1.48e-1, -1.07e-1),
                ],
            },
            Example {
                name: "4,2,3",
                p: [
                    v(-0.85, -0.64, 0.77),
                    v(0.55, 0.60, -0.83),
                    v(0.44, 0.72, -0.08),
                ],
                n: [
                    v(-0.14, -0.02, 0.99),
                    v(-0.87, 0.38, 0.31),
                    v(0.70, -0.70, -0.16),
                ],
                scene: [
                    v(1.71e-1, 9.28e-2, 2.21e-1),
                    v(1.52e-2, 9.31e-2, 2.44e-1),
                    v(-2.13e-1, -7.65e-2, 4.45e-1),
                ],
            },
            Example {
                name: "4,5",
                p: [
                    v(0.97, -0.37, -0.39),
                    v(-0.05, 0.45, 0.76),
                    v(-0.83, -0.71, -0.38),
                ],
                n: [
                    v(-0.85, -0.42, 0.31),
                    v(-0.20, 0.80, -0.57),
                    v(0.55, -0.19, 0.82),
                ],
                scene: [
                    v(-2.36e-1, -1.43e-1, 1.30e-1),
                    v(-2.42e-1, 7.43e-1, 1.84e-1),
                    v(-3.35e-1, -1.31e-1, 1.66e-1),
                ],
            },
            Example {
                name: "6,3",
                p: [
                    v(-0.07, -0.91, 0.77),
                    v(-0.13, 0.26, 0.49),
                    v(0.28, -0.25, -0.98),
                ],
                n: [
                    v(-0.32, -0.67, -0.67),
                    v(0.73, 0.68, 0.08),
                    v(0.08, 0.68, 0.73),
                ],
                scene: [
                    v(3.13e-1, 2.99e-1, 5.95e-2),
                    v(5.15e-1, 6.30e-1, 3.60e-1),
                    v(3.91e-1, 3.82e-1, 2.10e-1),
                ],
            },
            Example {
                name: "2,7",
                p: [
                    v(0.68, -0.00, -0.39),
                    v(-0.43, -0.85, 0.77),
                    v(-0.61, 0.95, -0.39),
                ],
                n: [
                    v(0.26, 0.71, 0.65),
                    v(-0.77, -0.56, -0.32),
                    v(0.59, -0.74, 0.33),
                ],
                scene: [
                    v(-6.70e-1, -8.24e-1, 3.47e-1),
                    v(-7.29e-1, -7.87e-1, 3.78e-1),
                    v(-1.17e-1, -3.88e-1, 2.65e-1),
                ],
            },
            Example {
                name: "9",
                p: [
                    v(-0.45, 0.44, -0.43),
                    v(0.58, -0.75, -0.58),
                    v(0.00, 0.81, -0.26),
                ],
                n: [
                    v(0.34, 0.54, -0.77),
                    v(-0.74, -0.52, -0.43),
                    v(0.37, 0.52, 0.77),
                ],
                scene: [
                    v(7.04e-2, 4.79e-1, 1.62e-1),
                    v(-1.70e-1, -3.64e-1, -3.52e-1),
                    v(9.62e-2, -4.57e-2, -1.10e-2),
                ],
            },
        ]
    }

    fn sizes(shapes: &TriangleShapes) -> Vec<usize> {
        shapes.iter().map(|s| s.len()).collect()
    }

    /// Checks every invariant of a successful projection against the vertices' own
    /// solutions: image counts per vertex (with multiplicity), sizes, shape count, XOR
    /// closure, disjoint `t` ranges in order, and the scene-edge tags of every polygon edge.
    fn check_invariants(
        cache: &ProjectionTriangleCache,
        scene: [DVec3; 3],
        shapes: &TriangleShapes,
    ) -> Result<(), String> {
        let solutions = scene.map(|x| cache.project_point(x));
        let mut counts = [0usize; 3];
        let mut last_t = f64::NEG_INFINITY;
        for shape in shapes.iter() {
            let n = shape.len();
            if !(2..=7).contains(&n) && n != 9 {
                return Err(format!("shape of {n} vertices"));
            }
            let mut state = 0;
            let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
            for (i, x) in shape.vertices.iter().enumerate() {
                counts[x.scene_vertex as usize] += 1;
                state ^= VERTEX_MASK[x.scene_vertex as usize];
                (low, high) = (low.min(x.t), high.max(x.t));
                // The image is one of the vertex's solutions.
                let found = solutions[x.scene_vertex as usize]
                    .iter()
                    .any(|s| (s.t, s.u, s.v, s.inside) == (x.t, x.u, x.v, x.inside));
                if !found {
                    return Err(format!("{x:?} is not a solution"));
                }
                let next = shape.vertices[(i + 1) % n].scene_vertex;
                let edge = shape.edges[i];
                let consistent = if next == x.scene_vertex {
                    edge.contains(next)
                } else {
                    edge == SceneEdge::between(x.scene_vertex, next)
                };
                if !consistent {
                    return Err(format!("edge {i} tagged {edge:?} in {shape:?}"));
                }
                // The two polygon edges at an image of k are the two scene edges at k.
                let previous = shape.edges[(i + n - 1) % n];
                if previous == edge || !previous.contains(x.scene_vertex) {
                    return Err(format!("vertex {i} between {previous:?} and {edge:?}"));
                }
            }
            if state != 0 {
                return Err(format!("shape does not close: {shape:?}"));
            }
            if low < last_t {
                return Err(format!("shapes overlap in t: {shapes:?}"));
            }
            last_t = high;
        }
        if shapes.len() > MAX_SHAPES || shapes.vertex_count() != counts.iter().sum::<usize>() {
            return Err(format!("bad shape bookkeeping: {shapes:?}"));
        }
        let expected = solutions.map(|s| s.total_multiplicity());
        if counts != expected {
            return Err(format!(
                "images per vertex {counts:?}, cubics say {expected:?}"
            ));
        }
        // Each vertex has an odd number of images (1 or 3 with multiplicity) unless a root was
        // lost to infinity or rejected by the degenerate-triangle rule.
        let all_roots_listed = solutions
            .iter()
            .all(|s| s.lost_to_infinity() == 0 && s.rejected() == 0);
        if all_roots_listed && shapes.vertex_count() % 2 == 0 {
            return Err(format!("even total without lost roots: {shapes:?}"));
        }
        Ok(())
    }

    fn project_checked(cache: &ProjectionTriangleCache, scene: [DVec3; 3]) -> TriangleShapes {
        let shapes = project_triangle(cache, scene).unwrap();
        check_invariants(cache, scene, &shapes).unwrap();
        shapes
    }

    #[test]
    fn appendix_c_exact_configurations() {
        // With the printed data these four come out exactly as named, shapes in t order, and
        // every vertex has three real images.
        for e in appendix_c()
            .iter()
            .filter(|e| ["2,2,2,3", "3,3,3", "4,2,3", "2,7"].contains(&e.name))
        {
            let cache = ProjectionTriangleCache::new(e.p, e.n);
            let shapes = project_checked(&cache, e.scene);
            let name: Vec<String> = sizes(&shapes).iter().map(|s| s.to_string()).collect();
            assert_eq!(name.join(","), e.name);
            assert_eq!(shapes.vertex_count(), 9, "{}", e.name);
        }
    }

    /// xorshift64 in [-0.5, 0.5): deterministic perturbations.
    fn perturbations() -> impl FnMut() -> f64 {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// The example with every value moved by at most half a unit of its last printed digit
    /// (0.005 for the view data, 3 significant digits for the scene data).
    fn perturbed(e: &Example, next: &mut impl FnMut() -> f64) -> Example {
        let mut view = |x: DVec3| x + 0.01 * DVec3::new(next(), next(), next());
        let (p, n) = (e.p.map(&mut view), e.n.map(&mut view));
        let unit = |c: f64| 10f64.powf(c.abs().log10().floor() - 2.0);
        let scene = e
            .scene
            .map(|x| x + DVec3::new(next() * unit(x.x), next() * unit(x.y), next() * unit(x.z)));
        Example {
            name: e.name,
            p,
            n,
            scene,
        }
    }

    #[test]
    fn appendix_c_rounding_sensitive_configurations() {
        // The printed data of (4,5) and (6,3) give other valid configurations; perturbing
        // every value within its printed rounding gives the named one in about 13% (4,5) and
        // 29% (6,3) of draws (the rest are mostly the printed data's result). The printed (9)
        // gives (2,3) under every perturbation tried (200000): its third scene vertex repeats
        // the first of (3,3,3), a likely transcription error, so only validity is checked.
        let examples = appendix_c();
        let mut next = perturbations();
        for (name, printed) in [
            ("4,5", [4, 3].as_slice()),
            ("6,3", &[3, 3, 3]),
            ("9", &[2, 3]),
        ] {
            let e = examples.iter().find(|e| e.name == name).unwrap();
            let cache = ProjectionTriangleCache::new(e.p, e.n);
            assert_eq!(sizes(&project_checked(&cache, e.scene)), printed, "{name}");
            if name == "9" {
                continue;
            }
            let target: Vec<usize> = name.split(',').map(|s| s.parse().unwrap()).collect();
            let hit = (0..1000).any(|_| {
                let q = perturbed(e, &mut next);
                let cache = ProjectionTriangleCache::new(q.p, q.n);
                sizes(&project_checked(&cache, q.scene)) == target
            });
            assert!(hit, "{name} not reached within the rounding");
        }
    }

    /// A pinhole projection triangle: base points on the plane one unit in front of the eye
    /// (looking down -z), n_i = p_i - eye.
    fn pinhole(eye: DVec3) -> ([DVec3; 3], [DVec3; 3]) {
        let p = [v(-1.0, -1.0, -1.0), v(1.5, -1.0, -1.0), v(0.0, 1.2, -1.0)].map(|x| eye + x);
        (p, p.map(|x| x - eye))
    }

    #[test]
    fn pinhole_triangle_images_like_a_perspective_camera() {
        let eye = v(0.2, -0.1, 1.0);
        let (p, n) = pinhole(eye);
        let cache = ProjectionTriangleCache::new(p, n);
        let scene = [v(0.3, -0.5, -3.0), v(1.0, 0.2, -4.0), v(-0.4, 0.9, -5.5)];
        let shapes = project_checked(&cache, scene);
        assert_eq!(sizes(&shapes), [3]);
        let shape = shapes.shape(0);
        for x in shape.vertices {
            let k = x.scene_vertex as usize;
            // Perspective: the ray from the eye meets the base plane (z = eye.z - 1) at
            // eye + d / -d.z, at distance ratio -d.z = 1 + t.
            let d = scene[k] - eye;
            let hit = eye + d / -d.z;
            let (e1, e2, w) = (p[1] - p[0], p[2] - p[0], hit - p[0]);
            let det = e1.x * e2.y - e1.y * e2.x;
            let u = (w.x * e2.y - w.y * e2.x) / det;
            let vv = (e1.x * w.y - e1.y * w.x) / det;
            assert!((x.u - u).abs() < 1e-12 && (x.v - vv).abs() < 1e-12, "{x:?}");
            assert!((x.t - (-d.z - 1.0)).abs() < 1e-12 && x.inside, "{x:?}");
        }
        // The double root at the eye (t = -1) was rejected for every vertex.
        assert!(scene
            .iter()
            .all(|&x| cache.project_point(x).rejected() == 2));
        let mut seen: Vec<u8> = shape.vertices.iter().map(|x| x.scene_vertex).collect();
        seen.sort();
        assert_eq!(seen, [0, 1, 2]);
    }

    #[test]
    fn orthographic_triangle_gives_one_shape() {
        // Parallel normals of different lengths: two roots of every vertex are lost.
        let p = [v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(0.0, 2.0, 0.0)];
        let d = v(0.0, 0.0, 1.0);
        let cache = ProjectionTriangleCache::new(p, [d, 2.0 * d, 0.5 * d]);
        let scene = [v(0.5, 0.25, 3.0), v(1.0, 0.5, 2.0), v(0.25, 1.0, 4.0)];
        let shapes = project_checked(&cache, scene);
        assert_eq!(sizes(&shapes), [3]);
        for x in shapes.shape(0).vertices {
            let s = scene[x.scene_vertex as usize];
            assert!((x.u - s.x / 2.0).abs() < 1e-12 && (x.v - s.y / 2.0).abs() < 1e-12);
        }
    }

    /// Rays (x, y, 0) + t (1 - 3x, 0, 1 + 2x) over x, y in [0, 1] (coplanar normals, so
    /// every cubic loses one root to infinity): they cross, and the point (-3, y, 5) lies on
    /// the fold, imaged by a double root (x = 2, t = 1).
    fn folded() -> ProjectionTriangleCache {
        let (left, right) = (v(1.0, 0.0, 1.0), v(-2.0, 0.0, 3.0));
        ProjectionTriangleCache::new(
            [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
            [left, right, left],
        )
    }

    #[test]
    fn coplanar_normals_with_consistent_ends_give_even_totals() {
        let cache = folded();
        let scene = [v(-3.0, 0.25, 5.0), v(0.5, 0.5, 1.0), v(0.2, 0.1, 2.0)];
        let double = cache.project_point(scene[0]);
        assert_eq!(double.lost_to_infinity(), 1);
        assert_eq!(double.len(), 1, "{double:?}");
        assert_eq!(double.as_slice()[0].multiplicity, 2);
        let shapes = project_checked(&cache, scene);
        assert_eq!(shapes.vertex_count() % 2, 0, "{shapes:?}");
        // The double root's two copies are adjacent and equal.
        let images: Vec<&ShapeVertex> = shapes
            .iter()
            .flat_map(|s| s.vertices.iter())
            .filter(|x| x.scene_vertex == 0)
            .collect();
        assert_eq!(images.len(), 2);
        assert_eq!(images[0], images[1]);
        assert!((images[0].t - 1.0).abs() < 1e-9 && (images[0].u - 2.0).abs() < 1e-6);
    }

    #[test]
    fn coplanar_normals_open_at_infinity_are_unprojectable() {
        // Normals in the plane z = 0: far along t the parametric plane tends to a plane
        // through the direction z, and scene vertices on both sides of it (z = +-10 here)
        // leave the triangle crossed at t = +-inf.
        let p = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.3), v(0.0, 1.0, -0.2)];
        let n = [v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(1.0, 1.0, 0.0)];
        let cache = ProjectionTriangleCache::new(p, n);
        let scene = [v(0.3, 0.3, 10.0), v(0.5, 0.2, -10.0), v(0.1, 0.6, 10.0)];
        assert_eq!(
            project_triangle(&cache, scene),
            Err(Unprojectable::OpenAtInfinity {
                lost_to_infinity: [1, 1, 1]
            })
        );
    }

    #[test]
    fn degenerate_inputs_are_unprojectable() {
        // A base triangle that is a segment, equal normals: every t is a root.
        let p = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0)];
        let cache = ProjectionTriangleCache::new(p, [v(0.0, 0.0, 1.0); 3]);
        let scene = [v(0.5, 1.0, 3.0), v(0.2, 0.0, 1.0), v(0.3, 2.0, 1.0)];
        assert_eq!(
            project_triangle(&cache, scene),
            Err(Unprojectable::EveryDepth { vertex: 0 })
        );
        let (p, n) = pinhole(DVec3::ZERO);
        let cache = ProjectionTriangleCache::new(p, n);
        let mut scene = [v(0.1, 0.1, -3.0), v(0.2, 0.1, -3.0), v(0.1, 0.2, -3.0)];
        scene[2].y = f64::NAN;
        assert_eq!(
            project_triangle(&cache, scene),
            Err(Unprojectable::NonFinite)
        );
        assert!(!Unprojectable::NonFinite.to_string().is_empty());
    }

    fn image(scene_vertex: u8, t: f64) -> ShapeVertex {
        ShapeVertex {
            u: t,
            v: 0.0,
            t,
            scene_vertex,
            inside: true,
        }
    }

    #[test]
    fn unbalanced_images_are_an_open_shape() {
        // Counts of different parity (as from a degenerate-triangle root rejected for one
        // vertex only) cannot close.
        let images = [image(0, 0.0), image(1, 1.0), image(2, 2.0), image(2, 3.0)];
        assert_eq!(
            connect(&images),
            Err(Unprojectable::OpenShape { images: [1, 1, 2] })
        );
    }

    #[test]
    fn thesis_walkthrough_orders_the_five_vertex_shape() {
        // Section 4.3: <v2, v3, v3, v1, v3> is one 5-vertex shape; the thesis's polygon is
        // v2 v1 v3 v3 v3 (left = v2 v1 v3, right = v3 v3), ours the same cycle reversed.
        let images = [
            image(1, 0.0),
            image(2, 1.0),
            image(2, 2.0),
            image(0, 3.0),
            image(2, 4.0),
        ];
        let shapes = connect(&images).unwrap();
        assert_eq!(shapes.len(), 1);
        let shape = shapes.shape(0);
        let order: Vec<f64> = shape.vertices.iter().map(|x| x.t).collect();
        assert_eq!(order, [0.0, 1.0, 2.0, 4.0, 3.0]);
        use SceneEdge::*;
        // v2 -> v3 along v2v3; v3 -> v3 is a return along v1v3; v3 -> v3 along v2v3; the
        // closing v3 -> v1 along v1v3; v1 -> v2 along v1v2.
        assert_eq!(shape.edges, [V2V3, V1V3, V2V3, V1V3, V1V2]);
        // A tangency outside any shape: a zero-area 2-shape along both edges at the vertex.
        let shapes = connect(&[image(0, 1.0), image(0, 1.0)]).unwrap();
        assert_eq!(shapes.shape(0).edges, [V1V2, V1V3]);
        // The last shape is emitted (listing 4.2 forgets it).
        let shapes = connect(&[
            image(2, 0.0),
            image(2, 0.5),
            image(0, 1.0),
            image(1, 2.0),
            image(2, 3.0),
        ]);
        assert_eq!(sizes(&shapes.unwrap()), [2, 3]);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        /// Random projection and scene triangles: generic draws (no root lost, none
        /// rejected) always project, with every invariant of `check_invariants`; the
        /// projectable rest too.
        #[test]
        fn random_triangles_keep_the_shape_invariants(
            p in [vec3(2.0), vec3(2.0), vec3(2.0)],
            n in [vec3(1.5), vec3(1.5), vec3(1.5)],
            scene in [vec3(3.0), vec3(3.0), vec3(3.0)],
        ) {
            let cache = ProjectionTriangleCache::new(p, n);
            let solutions = scene.map(|x| cache.project_point(x));
            let generic = solutions
                .iter()
                .all(|s| s.lost_to_infinity() == 0 && s.rejected() == 0 && !s.is_every_t());
            match project_triangle(&cache, scene) {
                Ok(shapes) => {
                    prop_assert!(check_invariants(&cache, scene, &shapes).is_ok(),
                        "{:?}", check_invariants(&cache, scene, &shapes));
                    if generic {
                        prop_assert!([3, 5, 7, 9].contains(&shapes.vertex_count()));
                    }
                }
                Err(e) => prop_assert!(!generic, "{e}"),
            }
        }

        /// The shapes agree with the sweep itself: between consecutive images the crossed
        /// scene edges are those whose end vertices' cubics differ in sign (skipping depths
        /// where a cubic is within rounding of zero).
        #[test]
        fn shapes_follow_the_sign_changes_of_the_cubics(
            p in [vec3(2.0), vec3(2.0), vec3(2.0)],
            n in [vec3(1.5), vec3(1.5), vec3(1.5)],
            scene in [vec3(3.0), vec3(3.0), vec3(3.0)],
        ) {
            let cache = ProjectionTriangleCache::new(p, n);
            let Ok(shapes) = project_triangle(&cache, scene) else { return Ok(()) };
            let coefficients = scene.map(|x| cache.coefficients(x));
            let crossed = |t: f64| {
                let side = coefficients.map(|[a, b, c, d]| {
                    let f = ((a * t + b) * t + c) * t + d;
                    let scale = ((a.abs() * t.abs() + b.abs()) * t.abs() + c.abs()) * t.abs()
                        + d.abs();
                    (f.abs() > 1e-9 * scale).then_some(f > 0.0)
                });
                let [Some(s1), Some(s2), Some(s3)] = side else { return None };
                Some(u8::from(s1 != s2) | u8::from(s1 != s3) << 1 | u8::from(s2 != s3) << 2)
            };
            let mut ts: Vec<(f64, u8, bool)> = Vec::new();
            for (index, shape) in shapes.iter().enumerate() {
                for x in shape.vertices {
                    ts.push((x.t, x.scene_vertex, index + 1 == shape.len()));
                }
            }
            ts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let mut state = 0;
            for pair in ts.windows(2) {
                state ^= VERTEX_MASK[pair[0].1 as usize];
                if pair[1].0 - pair[0].0 > 1e-6 * (1.0 + pair[0].0.abs()) {
                    if let Some(edges) = crossed(0.5 * (pair[0].0 + pair[1].0)) {
                        prop_assert_eq!(edges, state, "{:?}", ts);
                    }
                }
            }
            // Nothing is crossed beyond the images.
            if let (Some(first), Some(last)) = (ts.first(), ts.last()) {
                for t in [first.0 - 1.0 - first.0.abs(), last.0 + 1.0 + last.0.abs()] {
                    prop_assert!(crossed(t).unwrap_or(0) == 0);
                }
            }
        }
    }
}
