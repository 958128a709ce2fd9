//! A shape's outline: its polygon of vertex images with every curved edge sampled along the
//! exact image of its scene edge (`edge_path`): anchors at `t = 0` and at the crossings with
//! the projection triangle's edge surfaces, then the curve samples of the chosen mode.

use glam::DVec3;

use super::edge_path::{refine_around, EdgePath, EdgeSurface, OutlinePoint};
use super::screen_map::ScreenMap;
use super::volume_bounds::VolumeBounds;
use crate::projection::{Shape, ShapeVertex};

/// How a polygon edge is sampled between its anchors.
#[derive(Debug, Clone, Copy)]
pub enum Sampling<'a> {
    /// Anchors only (the edges of tessellated sub-triangles are short).
    Anchors,
    /// The given depths (the shape's slices, ascending), where they fall on the edge.
    Slices(&'a [f64]),
    /// Bisection to the screen tolerance, at most `levels` deep (`edge_path::refine`).
    Adaptive { tolerance: f64, levels: u32 },
}

/// One projection triangle as the outline tracer needs it.
#[derive(Debug, Clone, Copy)]
pub struct ProjectionTriangle {
    pub map: ScreenMap,
    /// The surfaces swept by the three edges, in the order of their domain lines `u = 0`
    /// (vertices 1-3), `v = 0` (vertices 1-2) and `u + v = 1` (vertices 2-3).
    pub surfaces: [EdgeSurface; 3],
    /// Bounding planes of the volume its rays sweep at `t >= 0` (the cull).
    pub bounds: VolumeBounds,
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
            bounds: VolumeBounds::new(p, n),
        }
    }
}

/// At most one view-plane anchor and two crossings with each of three edge surfaces.
const MAX_ANCHORS: usize = 7;

/// Appends the outline of `shape` (of the scene triangle with vertices `scene`) to `out`:
/// per polygon edge, its start image, then its anchors and curve samples in travel order.
/// Without `scene_clipping` the only anchors are at `t = 0` (the edge-surface crossings are
/// left to the clip's interpolation).
pub fn trace_outline(
    triangle: &ProjectionTriangle,
    shape: &Shape,
    scene: [DVec3; 3],
    (sampling, scene_clipping): (Sampling, bool),
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
        let [a, b] = shape.edges[i].vertices().map(|k| scene[k as usize]);
        let path = EdgePath {
            cache: triangle.map.cache(),
            a,
            b,
        };
        let mut previous = start;
        let surfaces: &[EdgeSurface] = if scene_clipping {
            &triangle.surfaces
        } else {
            &[]
        };
        let piece = |out: &mut Vec<OutlinePoint>, ends| {
            sample_piece(triangle, &path, ends, (sampling, scene_clipping), out)
        };
        for t in anchors(surfaces, &path, start.t, end.t).iter().flatten() {
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
/// `t = 0` and the crossings with `surfaces`.
fn anchors(
    surfaces: &[EdgeSurface],
    path: &EdgePath,
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
    // Plain loops rather than a chain of iterator adapters: the adapters' state (the
    // solver's roots inside nested options) was copied through memory on every polygon edge.
    for surface in surfaces {
        if let Some(roots) = surface.crossing_depths_between(path.a, path.b, (lo, hi)) {
            roots.as_slice().iter().for_each(|&t| keep(t));
        }
    }
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
