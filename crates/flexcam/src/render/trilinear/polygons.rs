//! Every scene triangle through one projection triangle, into clipped pixel polygons: cull
//! pairs outside the triangle's ray volume (`volume_bounds`; first a whole cluster of
//! scene triangles at once by its box, then triangle by triangle), project each remaining scene
//! vertex once (its cubic), cull pairs whose images cannot be visible, form the shapes, trace
//! their curved outlines, clip them, and append them to a polygon batch.

use glam::DVec3;

use super::clip::clip_outline;
use super::curves::{CurveMode, CurveOptions, ADAPTIVE_TOLERANCE_PX};
use super::edge_path::{EdgePath, OutlinePoint};
use super::hit_terms::{HitTerms, TERMS};
use super::outline::{slice_depths, trace_outline, ProjectionTriangle, Sampling};
use super::scene_geometry::SceneGeometry;
use crate::projection::{project_solved_triangle, Shape, Solutions};
use crate::render::raster::{PolygonBatch, Vertex};
use crate::render::{Counter, Stats};

/// What projecting the scene through projection triangles did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PairCounts {
    /// Scene vertices projected (one cubic each).
    pub vertices_projected: u64,
    /// (projection triangle, scene triangle) pairs considered.
    pub pairs: u64,
    /// Pairs culled because the scene triangle lies beyond one bounding plane of the
    /// projection triangle's ray volume (no cubic solved).
    pub culled_volume: u64,
    /// Pairs culled because every vertex image is behind the view plane.
    pub culled_behind: u64,
    /// Pairs culled because every vertex image is outside one domain line and no scene
    /// edge crosses that line's edge surface.
    pub culled_outside: u64,
    /// Pairs skipped because the scene triangle has zero area: no plane, nothing to draw.
    pub culled_zero_area: u64,
    /// Pairs (or tessellated sub-triangles) that could not be cut into shapes; their
    /// projection triangle is ray cast instead.
    pub unprojectable: u64,
    /// Shapes formed.
    pub shapes: u64,
    /// Shapes with nothing left after clipping.
    pub clipped_away: u64,
    /// Outline points of the shapes drawn (after clipping).
    pub outline_points: u64,
}

impl PairCounts {
    pub fn add(&mut self, o: &PairCounts) {
        self.vertices_projected += o.vertices_projected;
        self.pairs += o.pairs;
        self.culled_volume += o.culled_volume;
        self.culled_behind += o.culled_behind;
        self.culled_outside += o.culled_outside;
        self.culled_zero_area += o.culled_zero_area;
        self.unprojectable += o.unprojectable;
        self.shapes += o.shapes;
        self.clipped_away += o.clipped_away;
        self.outline_points += o.outline_points;
    }

    /// Inserts the counters into `stats`.
    pub fn record(&self, stats: &mut Stats) {
        for (name, value) in [
            ("vertices_projected", self.vertices_projected),
            ("pairs", self.pairs),
            ("culled_volume", self.culled_volume),
            ("culled_behind", self.culled_behind),
            ("culled_outside", self.culled_outside),
            ("culled_zero_area", self.culled_zero_area),
            ("unprojectable", self.unprojectable),
            ("shapes", self.shapes),
            ("clipped_away", self.clipped_away),
            ("outline_points", self.outline_points),
        ] {
            stats.insert(name, Counter::Count(value));
        }
    }
}

/// The result for one projection triangle: polygons whose vertices carry the scene
/// triangle's hit terms (`hit_terms`), and what was done.
#[derive(Debug, Clone, Default)]
pub struct Projected {
    pub polygons: PolygonBatch<TERMS>,
    pub counts: PairCounts,
}

/// Why a pair is skipped without forming its shapes.
enum Cull {
    Behind,
    Outside,
}

/// Reused buffers.
#[derive(Default)]
struct Scratch {
    outline: Vec<OutlinePoint>,
    clipped: Vec<OutlinePoint>,
    slices: Vec<f64>,
    pixels: Vec<Vertex<TERMS>>,
    grid: Vec<DVec3>,
    grid_solutions: Vec<Solutions>,
}

/// Projects every triangle of `scene` through `triangle` (number `index` in the mesh, which
/// keys its polygons: `index << 32 | scene triangle`).
pub fn project_scene(
    triangle: &ProjectionTriangle,
    index: u32,
    scene: &SceneGeometry,
    curves: CurveOptions,
) -> Projected {
    let cache = triangle.map.cache();
    // Each vertex's mask of bounding planes it is beyond, computed when first needed.
    let mut outside: Vec<u32> = vec![UNKNOWN_MASK; scene.vertices.len()];
    // Each vertex's cubic, solved when a pair first needs it.
    let mut solutions: Vec<Option<Solutions>> = vec![None; scene.vertices.len()];
    let mut out = Projected::default();
    let mut scratch = Scratch::default();
    for cluster in &scene.clusters {
        let run = cluster.triangles.len() as u64;
        out.counts.pairs += run;
        if beyond_one_plane(cluster.box_corners.map(|c| triangle.bounds.outside(c))) {
            out.counts.culled_volume += run;
            continue;
        }
        for k in cluster.triangles.clone() {
            let corners = &scene.triangles[k];
            let masks = corners.map(|i| {
                let mask = &mut outside[i as usize];
                if *mask == UNKNOWN_MASK {
                    *mask = triangle.bounds.outside(scene.vertices[i as usize]);
                }
                *mask
            });
            if beyond_one_plane(masks) {
                out.counts.culled_volume += 1;
                continue;
            }
            let positions = scene.corners(k);
            let Some(terms) = HitTerms::new(positions) else {
                out.counts.culled_zero_area += 1;
                continue;
            };
            let solved = corners.map(|i| {
                *solutions[i as usize].get_or_insert_with(|| {
                    out.counts.vertices_projected += 1;
                    cache.project_point(scene.vertices[i as usize])
                })
            });
            match cull(triangle, positions, &solved) {
                Some(Cull::Behind) => out.counts.culled_behind += 1,
                Some(Cull::Outside) => out.counts.culled_outside += 1,
                None => {
                    let key = (u64::from(index) << 32) | k as u64;
                    let id = scene.owners[k].id;
                    let pair = Pair {
                        triangle,
                        key,
                        id,
                        curves,
                        terms,
                    };
                    if curves.mode == CurveMode::Tessellate {
                        pair.tessellated(positions, &mut out, &mut scratch);
                    } else {
                        pair.whole(positions, solved, &mut out, &mut scratch);
                    }
                }
            }
        }
    }
    out
}

/// The entry of a vertex whose plane mask is not computed yet: no mask has all 32 bits, as a
/// volume has at most 26 bounding planes.
const UNKNOWN_MASK: u32 = u32::MAX;

/// Whether points with plane masks `masks` ([`super::volume_bounds::VolumeBounds::outside`]) are all beyond one
/// bounding plane, so that their convex hull is outside the projection triangle's volume.
fn beyond_one_plane<const N: usize>(masks: [u32; N]) -> bool {
    masks.iter().fold(u32::MAX, |common, &m| common & m) != 0
}

/// Whether a pair can be skipped. Only decided when every vertex's cubic kept all three
/// roots (none lost to infinity or rejected), so that the shapes are exactly the vertex
/// images joined by edge curves whose depths lie between theirs:
/// - all images at `t < 0`: every shape is behind the view plane;
/// - all images strictly outside one domain line and no scene edge crossing that line's edge
///   surface: every closed outline lies in the outer half-plane, and so does its inside.
fn cull(triangle: &ProjectionTriangle, scene: [DVec3; 3], solved: &[Solutions; 3]) -> Option<Cull> {
    let complete = solved
        .iter()
        .all(|s| s.lost_to_infinity() == 0 && s.rejected() == 0 && !s.is_every_t());
    if !complete {
        return None;
    }
    let images = || solved.iter().flat_map(|s| s.iter());
    if images().all(|x| x.t < 0.0) {
        return Some(Cull::Behind);
    }
    let lines: [fn(f64, f64) -> f64; 3] = [|u, _| u, |_, v| v, |u, v| 1.0 - u - v];
    for (line, surface) in lines.iter().zip(&triangle.surfaces) {
        if !images().all(|x| line(x.u, x.v) < 0.0) {
            continue;
        }
        let crossed = [(0, 1), (0, 2), (1, 2)].iter().any(|&(i, j)| {
            let path = EdgePath {
                cache: triangle.map.cache(),
                a: scene[i],
                b: scene[j],
            };
            surface.crossing_depths(scene[i], scene[j]).any(|t| {
                path.segment_parameter(t)
                    .is_none_or(|s| (0.0..=1.0).contains(&s))
            })
        });
        if !crossed {
            return Some(Cull::Outside);
        }
    }
    None
}

/// One (projection triangle, scene triangle) pair being drawn.
struct Pair<'a> {
    triangle: &'a ProjectionTriangle,
    key: u64,
    id: u32,
    curves: CurveOptions,
    /// The scene triangle's plane (of the whole triangle, also for tessellated pieces).
    terms: HitTerms,
}

impl Pair<'_> {
    /// Slicing (fixed or adaptive) of the whole scene triangle.
    fn whole(
        &self,
        scene: [DVec3; 3],
        solved: [Solutions; 3],
        out: &mut Projected,
        scratch: &mut Scratch,
    ) {
        let cache = self.triangle.map.cache();
        let Ok(shapes) = project_solved_triangle(cache, scene, solved) else {
            out.counts.unprojectable += 1;
            return;
        };
        for shape in shapes.iter() {
            let mut slices = std::mem::take(&mut scratch.slices);
            let sampling = match self.curves.mode {
                CurveMode::Slice => {
                    slice_depths(&shape, self.curves.steps, &mut slices);
                    Sampling::Slices(&slices)
                }
                _ => Sampling::Adaptive {
                    tolerance: ADAPTIVE_TOLERANCE_PX,
                    levels: self.curves.steps.next_power_of_two().trailing_zeros(),
                },
            };
            self.draw_shape(&shape, scene, sampling, out, scratch);
            scratch.slices = slices;
        }
    }

    /// Scene-triangle tessellation: `steps^2` sub-triangles on a barycentric grid, each
    /// vertex projected once, each sub-triangle's shapes drawn with straight edges between
    /// their anchors, under the whole triangle's key.
    fn tessellated(&self, scene: [DVec3; 3], out: &mut Projected, scratch: &mut Scratch) {
        let n = self.curves.steps;
        let cache = self.triangle.map.cache();
        scratch.grid.clear();
        for i in 0..=n {
            for j in 0..=n - i {
                let (a, b) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                scratch
                    .grid
                    .push(scene[0] + a * (scene[1] - scene[0]) + b * (scene[2] - scene[0]));
            }
        }
        scratch.grid_solutions.clear();
        scratch
            .grid_solutions
            .extend(scratch.grid.iter().map(|&p| cache.project_point(p)));
        out.counts.vertices_projected += scratch.grid.len() as u64;
        // Row i of the grid starts at index i (n + 1) - i (i - 1) / 2.
        let at = |i: u32, j: u32| (i * (n + 1) - i * (i.saturating_sub(1)) / 2 + j) as usize;
        for i in 0..n {
            for j in 0..n - i {
                let upright = [at(i, j), at(i + 1, j), at(i, j + 1)];
                let inverted =
                    (i + j + 1 < n).then(|| [at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                for sub in std::iter::once(upright).chain(inverted) {
                    let corners = sub.map(|k| scratch.grid[k]);
                    let solved = sub.map(|k| scratch.grid_solutions[k]);
                    match project_solved_triangle(cache, corners, solved) {
                        Ok(shapes) => {
                            for shape in shapes.iter() {
                                self.draw_shape(&shape, corners, Sampling::Anchors, out, scratch);
                            }
                        }
                        Err(_) => out.counts.unprojectable += 1,
                    }
                }
            }
        }
    }

    /// Traces, clips and appends one shape, each vertex with the hit terms of its projector.
    fn draw_shape(
        &self,
        shape: &Shape,
        scene: [DVec3; 3],
        sampling: Sampling,
        out: &mut Projected,
        scratch: &mut Scratch,
    ) {
        out.counts.shapes += 1;
        scratch.outline.clear();
        let mode = (sampling, self.curves.scene_clipping);
        trace_outline(self.triangle, shape, scene, mode, &mut scratch.outline);
        clip_outline(&mut scratch.outline, &mut scratch.clipped);
        if scratch.outline.len() < 2 {
            out.counts.clipped_away += 1;
            return;
        }
        out.counts.outline_points += scratch.outline.len() as u64;
        scratch.pixels.clear();
        let cache = self.triangle.map.cache();
        scratch.pixels.extend(scratch.outline.iter().map(|p| {
            let pixel = self.triangle.map.pixel(p.u, p.v);
            Vertex::new(pixel.x, pixel.y, p.t, self.terms.at(cache, p.u, p.v))
        }));
        out.polygons.push(&scratch.pixels, self.id, self.key);
    }
}
