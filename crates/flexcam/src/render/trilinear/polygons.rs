//! Every scene triangle through every projection triangle, into clipped pixel polygons: cull
//! pairs outside each triangle's ray volume (`pair_cull`: whole subtrees of the scene's box
//! tree at once, then triangle by triangle), project each remaining scene vertex once (its
//! cubic), cull pairs whose images cannot be visible (through a central projection also
//! those hidden behind a scene triangle covering its whole domain, `occlusion`), form the
//! shapes, trace their curved outlines, clip them (pairs reaching a degenerate depth split
//! there, `degenerate_band`), and append them to one polygon batch.

use glam::DVec3;
use rayon::prelude::*;

use super::central;
use super::clip::clip_outline;
use super::curves::{CurveMode, CurveOptions, ADAPTIVE_TOLERANCE_PX};
use super::degenerate_band::DegenerateBand;
use super::edge_path::{EdgePath, OutlinePoint};
use super::hit_terms::TERMS;
use super::occlusion::Occlusion;
use super::outline::{
    depth_range, is_outside_domain, slice_depths, trace_outline, EdgeCrossings, ProjectionTriangle,
    Sampling,
};
use super::pair_cull::{live_pairs, LivePair, LivePairs, PairCounts, VertexCache};
use super::resolve::PIXEL_TESTED;
use super::scene_geometry::SceneGeometry;
use super::screen_map::ScreenMap;
use super::view_plane::clipping_base;
use crate::projection::{
    project_solved_triangle, ProjectionTriangleCache, Shape, Solutions, TriangleShapes, Trilinear,
};
use crate::render::huge_pages::{map_spare_capacity, reserve_mapped};
use crate::render::scan::{PolygonBatch, Vertex};

/// The projection stage's result for the whole mesh: every polygon, in projection-triangle
/// order and within it in scene-triangle order, keyed `projection << 32 | scene triangle`;
/// the counts; and, per projection triangle, whether it had an unprojectable pair (its
/// pixels are ray cast instead).
#[derive(Debug, Clone, Default)]
pub struct ProjectedScene {
    pub polygons: PolygonBatch<TERMS>,
    pub counts: PairCounts,
    pub fallback: Vec<bool>,
}

/// The projection triangles of `projection`, each with its screen placement and the
/// bounding planes of its ray volume; a collapsed base is moved along its rays first
/// (`clipping_base`).
pub fn projection_triangles(projection: &Trilinear) -> Vec<ProjectionTriangle> {
    let mesh = projection.mesh();
    // Written once, whole, into fresh memory (about 1 KB a triangle): its pages are mapped
    // at once rather than by a page fault each (`map_spare_capacity`).
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    map_spare_capacity(&mut triangles);
    let each = mesh
        .triangles
        .iter()
        .zip(projection.triangle_caches())
        .map(|(t, cache)| {
            let [i, j, k] = t.map(|x| x as usize);
            let pick = |values: &[DVec3]| [values[i], values[j], values[k]];
            let normals = pick(&mesh.normals);
            let base = clipping_base(pick(&mesh.points), normals);
            // The projection's own cache unless the base collapsed (`view_plane`).
            let cache = if base == pick(&mesh.points) {
                *cache
            } else {
                ProjectionTriangleCache::new(base, normals)
            };
            let map = ScreenMap::of_triangle(projection, [i, j, k], cache);
            ProjectionTriangle::new(base, normals, map)
        });
    triangles.extend(each);
    triangles
}

/// The least slices per shape in a projection triangle whose parametric triangle
/// degenerates at some depth: near that depth an edge's image swings far out and back
/// between two slices, and few slices miss it (measured on the crossing rays above
/// cube-floor's cube, the test
/// `projection_triangles_degenerating_inside_the_scene_are_split_there`: 10 slices 0.001
/// relative RGB error, 50 exact). Adaptive sampling needs no such floor: its error bound
/// covers the whole piece (`edge_path::refine`).
const LEAST_SLICES_NEAR_DEGENERATE: u32 = 64;

/// Live pairs per parallel work item of the drawing half. Pairs differ in cost by orders of
/// magnitude (culled at once, or many curved shapes), so items are small and many: rayon
/// balances them over the cores, where one item per projection triangle (18 on the cube
/// bench) left one core idle at the end.
const PAIRS_PER_ITEM: usize = 4;

/// Projects every triangle of `scene` through every projection triangle (number `i` is
/// `triangles[i]`), in two parallel passes: the cull per projection triangle
/// (`pair_cull::live_pairs`, which also solves the cubics, then
/// `occlusion::Occlusion::cull_hidden`), then the shapes, outlines and clipping of the live
/// pairs in small items. The result does not depend on the number of
/// threads or on how the work was split.
pub fn project_all(
    triangles: &[ProjectionTriangle],
    scene: &SceneGeometry,
    curves: CurveOptions,
) -> ProjectedScene {
    let culled: Vec<(LivePairs, PairCounts)> = triangles
        .par_iter()
        .enumerate()
        .map_init(
            || {
                let vertices = scene.vertices.len();
                (VertexCache::new(vertices), Occlusion::new(vertices))
            },
            |(cache, occlusion), (index, triangle)| {
                let (mut live, mut counts) = live_pairs(triangle, index as u32, scene, cache);
                if let Some(central) = &triangle.central {
                    counts.culled_hidden = occlusion.cull_hidden(central, scene, &mut live);
                }
                (live, counts)
            },
        )
        .collect();
    let mut counts = PairCounts::default();
    for (_, c) in &culled {
        counts.add(c);
    }
    let live: Vec<LivePairs> = culled.into_iter().map(|(live, _)| live).collect();
    draw_all(triangles, scene, &live, curves, counts)
}

/// The drawing half of [`project_all`]: the polygons of the live pairs `live` (in order,
/// projection `live[i].projection` being `triangles[...]`), with `counts` of the cull added
/// to those of drawing. The work items are runs of [`PAIRS_PER_ITEM`] pairs of one
/// projection triangle (referring to its pairs in place); each worker draws a contiguous
/// range of items into one part of its own with one set of buffers (the shapes' clipped
/// outlines), and the parts are then turned into one polygon batch in order
/// ([`Drawn::polygons`]).
pub(super) fn draw_all(
    triangles: &[ProjectionTriangle],
    scene: &SceneGeometry,
    live: &[LivePairs],
    curves: CurveOptions,
    counts: PairCounts,
) -> ProjectedScene {
    let items: Vec<(&LivePairs, &[LivePair])> = live
        .iter()
        .flat_map(|group| {
            group
                .pairs
                .chunks(PAIRS_PER_ITEM)
                .map(move |run| (group, run))
        })
        .collect();
    let jobs: Vec<Drawn> = items
        .par_iter()
        .fold(
            || (Drawn::default(), Scratch::default()),
            |(mut out, mut scratch), &(group, pairs)| {
                draw_pairs(
                    triangles,
                    scene,
                    group,
                    pairs,
                    curves,
                    &mut out,
                    &mut scratch,
                );
                (out, scratch)
            },
        )
        .map(|(out, _)| out)
        .collect();
    let mut out = ProjectedScene {
        polygons: Drawn::polygons(&jobs, triangles, scene),
        counts,
        fallback: vec![false; triangles.len()],
    };
    for part in &jobs {
        out.counts.add(&part.counts);
        for &index in &part.fallback {
            out.fallback[index as usize] = true;
        }
    }
    out
}

/// What drawing some live pairs gave: the clipped outline of each shape (in pair order),
/// the counts of the drawing half, and the projection triangles with an unprojectable pair
/// among them. The outlines are kept as barycentrics and depth (24 bytes a point) and turned
/// into pixel vertices (80 bytes) only once the parts are joined ([`Drawn::polygons`]): each
/// part's storage is fresh memory, and building the vertices in the parts and then copying
/// them into one batch wrote them twice, which cost more in page faults and copies than
/// computing them (mostly the inward sphere's 36,000 outline points).
#[derive(Debug, Clone, Default)]
struct Drawn {
    points: Vec<OutlinePoint>,
    shapes: Vec<DrawnShape>,
    counts: PairCounts,
    fallback: Vec<u32>,
}

/// A shape in [`Drawn`]: its outline is `points[previous shape's end..end]`, of the pair of
/// projection triangle `projection` and scene triangle `triangle`; `tested` for a pixel-tested
/// band (`degenerate_band`), keyed [`PIXEL_TESTED`].
#[derive(Debug, Clone, Copy)]
struct DrawnShape {
    end: usize,
    projection: u32,
    triangle: u32,
    tested: bool,
}

impl Drawn {
    /// Records the clipped outline `outline` of a shape of the pair (`projection`,
    /// `triangle`).
    fn push(&mut self, outline: &[OutlinePoint], projection: u32, triangle: u32) {
        self.push_keyed(outline, projection, triangle, false);
    }

    /// Records `outline` for the pair (`projection`, `triangle`), pixel tested or not.
    fn push_keyed(
        &mut self,
        outline: &[OutlinePoint],
        projection: u32,
        triangle: u32,
        tested: bool,
    ) {
        reserve_mapped(&mut self.points, outline.len());
        self.points.extend_from_slice(outline);
        self.shapes.push(DrawnShape {
            end: self.points.len(),
            projection,
            triangle,
            tested,
        });
    }

    /// The pixel polygons of the shapes of `parts`, one after the other, in one batch: each
    /// vertex at its pixel with the hit terms of its projector through the scene
    /// triangle's plane (of the whole triangle, also for tessellated pieces), keyed
    /// `projection << 32 | scene triangle`, with the scene triangle's object id.
    fn polygons(
        parts: &[Drawn],
        triangles: &[ProjectionTriangle],
        scene: &SceneGeometry,
    ) -> PolygonBatch<TERMS> {
        let mut polygons = PolygonBatch::with_capacity(
            parts.iter().map(|part| part.points.len()).sum(),
            parts.iter().map(|part| part.shapes.len()).sum(),
        );
        for part in parts {
            let mut start = 0;
            for shape in &part.shapes {
                let outline = &part.points[start..shape.end];
                start = shape.end;
                let k = shape.triangle as usize;
                let map = &triangles[shape.projection as usize].map;
                // Only pairs with a plane are drawn (`draw_pairs`).
                let terms = scene.hit_terms[k].expect("a drawn scene triangle has a plane");
                let pixels = outline.iter().map(|p| {
                    let pixel = map.pixel(p.u, p.v);
                    Vertex::new(pixel.x, pixel.y, p.t, terms.at(map, p.u, p.v))
                });
                let tested = if shape.tested { PIXEL_TESTED } else { 0 };
                let key = (u64::from(shape.projection) << 32) | k as u64 | tested;
                polygons.push_from(pixels, key);
            }
        }
        polygons
    }
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
    /// A traced outline being cut at a degenerate band.
    traced: Vec<OutlinePoint>,
    slices: Vec<f64>,
    grid: Vec<DVec3>,
    grid_solutions: Vec<Solutions>,
    central: central::Scratch,
    fan_breaks: Vec<f64>,
}

/// Culls (behind the view plane, outside a domain line) or draws each of `pairs` (live
/// pairs of `group`) in order, into `out`.
fn draw_pairs(
    triangles: &[ProjectionTriangle],
    scene: &SceneGeometry,
    group: &LivePairs,
    pairs: &[LivePair],
    curves: CurveOptions,
    out: &mut Drawn,
    scratch: &mut Scratch,
) {
    let triangle = &triangles[group.projection as usize];
    for live in pairs {
        let k = live.triangle as usize;
        // Live pairs have a plane (the cull skips the others).
        if scene.hit_terms[k].is_none() {
            continue;
        }
        let positions = scene.corners(k);
        let pair = || Pair {
            triangle,
            projection: group.projection,
            scene_triangle: live.triangle,
            curves,
        };
        let unprojectable = out.counts.unprojectable;
        if let Some(central) = &triangle.central {
            let drawn = central.outlines(positions, &mut scratch.central, |outline| {
                out.counts.shapes += 1;
                out.push(outline, group.projection, live.triangle);
                out.counts.outline_points += outline.len() as u64;
            });
            if drawn.is_err() {
                out.counts.unprojectable += 1;
            }
        } else if let Some(fan) = &triangle.fan {
            let strips = fan.outlines(positions, &mut scratch.fan_breaks, |outline| {
                out.push(outline, group.projection, live.triangle);
                out.counts.outline_points += outline.len() as u64;
            });
            out.counts.shapes += strips;
        } else {
            let solved = group.solved(live);
            match cull(triangle, positions, &solved) {
                Some(Cull::Behind) => out.counts.culled_behind += 1,
                Some(Cull::Outside) => out.counts.culled_outside += 1,
                None if curves.mode == CurveMode::Tessellate => {
                    pair().tessellated(positions, out, scratch);
                }
                None => pair().whole(positions, solved, out, scratch),
            }
        }
        if out.counts.unprojectable > unprojectable {
            out.fallback.push(group.projection);
        }
    }
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

/// Whether every vertex of `shape` lies behind the view plane (`t < 0`), so that its
/// clipped outline is empty and tracing it can be skipped: every point of the outline
/// [`trace_outline`] would give has `t < 0` too (an edge's points have depths between its
/// ends', its anchors lie strictly between them, so no `t = 0` anchor, and no curve sample
/// is taken on a piece at `t < 0`), and clipping to `t >= 0` leaves nothing. Exact, no
/// margin: the tracer would compare the same depths with `0`. Degenerate cases: a depth of
/// `-0.0` or NaN is not `< 0`, so such a shape is traced as before. Shapes at negative depth
/// are the images through the cubics' negative roots; on cube-floor through the 18-triangle
/// fan they are about 97-99 % of the shapes clipped away.
fn is_behind(shape: &Shape) -> bool {
    shape.vertices.iter().all(|x| x.t < 0.0)
}

/// Whether a shape's outline is traced: the negation of [`is_behind`].
fn is_drawn(shape: &Shape) -> bool {
    !is_behind(shape)
}

/// One (projection triangle, scene triangle) pair being drawn.
struct Pair<'a> {
    triangle: &'a ProjectionTriangle,
    /// Its index in the mesh, and the scene triangle's: the shapes' keys.
    projection: u32,
    scene_triangle: u32,
    curves: CurveOptions,
}

impl Pair<'_> {
    /// Slicing (fixed or adaptive) of the whole scene triangle.
    fn whole(
        &self,
        scene: [DVec3; 3],
        solved: [Solutions; 3],
        out: &mut Drawn,
        scratch: &mut Scratch,
    ) {
        let cache = self.triangle.map.cache();
        let Ok(shapes) = project_solved_triangle(cache, scene, solved) else {
            self.shapeless(scene, out, scratch);
            return;
        };
        let band = self
            .band_reached_by(&shapes)
            .or_else(|| self.band_touched_by(scene));
        let mut crossings =
            self.crossings(scene, band, || depth_range(shapes.iter().filter(is_drawn)));
        for shape in shapes.iter() {
            let mut slices = std::mem::take(&mut scratch.slices);
            let sampling = match self.curves.mode {
                CurveMode::Slice => {
                    slice_depths(
                        &shape,
                        self.curves.steps.max(self.least_slices()),
                        &mut slices,
                    );
                    Sampling::Slices(&slices)
                }
                _ => {
                    let levels = self.curves.steps.next_power_of_two().trailing_zeros();
                    Sampling::Adaptive {
                        tolerance: ADAPTIVE_TOLERANCE_PX,
                        levels,
                    }
                }
            };
            self.draw_shape(
                &shape,
                scene,
                sampling,
                (&mut crossings, band),
                out,
                scratch,
            );
            scratch.slices = slices;
        }
        if let Some(band) = band {
            out.counts.split_pairs += 1;
            self.draw_tested(band, scene, out, scratch);
        }
    }

    /// A pair (or tessellated piece) the cubics cannot cut into shapes: drawn pixel tested
    /// at every depth where its projection triangle degenerates (a scene vertex at that
    /// depth, `degenerate_band`), unprojectable otherwise.
    fn shapeless(&self, scene: [DVec3; 3], out: &mut Drawn, scratch: &mut Scratch) {
        if self.triangle.degenerate.is_some() {
            out.counts.tested_pairs += 1;
            self.draw_tested(DegenerateBand::everywhere(), scene, out, scratch);
        } else {
            out.counts.unprojectable += 1;
        }
    }

    /// Scene-triangle tessellation: `steps^2` sub-triangles on a barycentric grid, each
    /// vertex projected once, each sub-triangle's shapes drawn with straight edges between
    /// their anchors, under the whole triangle's key.
    fn tessellated(&self, scene: [DVec3; 3], out: &mut Drawn, scratch: &mut Scratch) {
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
        let (mut split, mut shapeless) = (None, false);
        for i in 0..n {
            for j in 0..n - i {
                let upright = [at(i, j), at(i + 1, j), at(i, j + 1)];
                let inverted =
                    (i + j + 1 < n).then(|| [at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                for sub in std::iter::once(upright).chain(inverted) {
                    let corners = sub.map(|k| scratch.grid[k]);
                    let solved = sub.map(|k| scratch.grid_solutions[k]);
                    let Ok(shapes) = project_solved_triangle(cache, corners, solved) else {
                        shapeless = true;
                        continue;
                    };
                    let band = self.band_reached_by(&shapes);
                    split = split.or(band);
                    let mut crossings = self.crossings(corners, band, || {
                        depth_range(shapes.iter().filter(is_drawn))
                    });
                    for shape in shapes.iter() {
                        let crossings = (&mut crossings, band);
                        let sampling = Sampling::Anchors;
                        self.draw_shape(&shape, corners, sampling, crossings, out, scratch);
                    }
                }
            }
        }
        // The band's pixels are tested against the whole triangle (the key's), whose plane
        // every piece shares: one band for the pair (every depth if a piece had no shapes).
        if shapeless {
            self.shapeless(scene, out, scratch);
        } else if let Some(band) = split.or_else(|| self.band_touched_by(scene)) {
            out.counts.split_pairs += 1;
            self.draw_tested(band, scene, out, scratch);
        }
    }

    /// The least slices per shape: [`LEAST_SLICES_NEAR_DEGENERATE`] in a projection
    /// triangle whose parametric triangle degenerates at some depth, none elsewhere.
    fn least_slices(&self) -> u32 {
        if self.triangle.degenerate.is_some() {
            LEAST_SLICES_NEAR_DEGENERATE
        } else {
            0
        }
    }

    /// The band around the depths at which the projection triangle's parametric triangle
    /// degenerates ([`ProjectionTriangle::degenerate`]) where a shape of `shapes` reaches
    /// from before to beyond them: its outline runs through infinity there, and the pair is
    /// split at the band (`degenerate_band`). `None` where no shape does: shapes ending
    /// before or starting beyond it are bounded and exact.
    fn band_reached_by(&self, shapes: &TriangleShapes) -> Option<DegenerateBand> {
        let band = DegenerateBand::around(self.triangle.degenerate?);
        band.is_reached_by_any(shapes).then_some(band)
    }

    /// The band around the depths at which the projection triangle's parametric triangle
    /// degenerates where the scene triangle `scene` meets the plane at such a depth
    /// ([`DegenerateBand::is_touched_by`]).
    fn band_touched_by(&self, scene: [DVec3; 3]) -> Option<DegenerateBand> {
        let band = DegenerateBand::around(self.triangle.degenerate?);
        band.is_touched_by(self.triangle.map.cache(), scene)
            .then_some(band)
    }

    /// The edge-surface crossings of the scene triangle (or piece) `scene` for its shapes,
    /// whose vertices' depth range `range` gives (computed only with scene-space clipping):
    /// that of the shapes whose outlines are traced, the others' edges need no crossing.
    /// With a `band`, every edge is also anchored at its ends.
    fn crossings(
        &self,
        scene: [DVec3; 3],
        band: Option<DegenerateBand>,
        range: impl FnOnce() -> (f64, f64),
    ) -> EdgeCrossings {
        let crossings = if self.curves.scene_clipping {
            EdgeCrossings::new(self.triangle, scene, range())
        } else {
            EdgeCrossings::none()
        };
        match band {
            Some(band) => crossings.anchored_at((band.lo, band.hi)),
            None => crossings,
        }
    }

    /// Appends the pixel-tested band of the pair with scene triangle `scene`
    /// ([`DegenerateBand::outlines`]).
    fn draw_tested(
        &self,
        band: DegenerateBand,
        scene: [DVec3; 3],
        out: &mut Drawn,
        scratch: &mut Scratch,
    ) {
        let buffers = (&mut scratch.outline, &mut scratch.clipped);
        band.outlines(self.triangle.map.cache(), scene, buffers, |outline| {
            out.counts.outline_points += outline.len() as u64;
            out.push_keyed(outline, self.projection, self.scene_triangle, true);
        });
    }

    /// Traces, clips and appends one shape, each vertex with the hit terms of its projector;
    /// `crossings` are those of [`Pair::crossings`] for the shapes of `scene`, with the band
    /// they are anchored at: a shape reaching it is cut into its parts before and beyond it
    /// ([`DegenerateBand::cut`]). A shape behind the view plane ([`is_behind`]) or beyond
    /// a domain line ([`is_outside_domain`]) is counted as clipped away without tracing.
    fn draw_shape(
        &self,
        shape: &Shape,
        scene: [DVec3; 3],
        sampling: Sampling,
        (crossings, band): (&mut EdgeCrossings, Option<DegenerateBand>),
        out: &mut Drawn,
        scratch: &mut Scratch,
    ) {
        out.counts.shapes += 1;
        if is_behind(shape) {
            out.counts.clipped_away += 1;
            out.counts.skipped_behind += 1;
            return;
        }
        if is_outside_domain(shape, crossings, self.triangle.degenerate) {
            out.counts.clipped_away += 1;
            out.counts.skipped_outside += 1;
            return;
        }
        scratch.outline.clear();
        let mode = (sampling, self.curves.scene_clipping);
        let outline = &mut scratch.outline;
        trace_outline(self.triangle, shape, scene, mode, crossings, outline);
        if let Some(band) = band.filter(|band| band.is_reached_by(shape)) {
            std::mem::swap(&mut scratch.outline, &mut scratch.traced);
            let mut parts = 0;
            let buffers = (&mut scratch.outline, &mut scratch.clipped);
            band.cut(&scratch.traced, buffers, |part| {
                parts += 1;
                out.counts.outline_points += part.len() as u64;
                out.push(part, self.projection, self.scene_triangle);
            });
            if parts == 0 {
                out.counts.clipped_away += 1;
            }
            return;
        }
        clip_outline(&mut scratch.outline, &mut scratch.clipped);
        if scratch.outline.len() < 2 {
            out.counts.clipped_away += 1;
            return;
        }
        out.counts.outline_points += scratch.outline.len() as u64;
        out.push(&scratch.outline, self.projection, self.scene_triangle);
    }
}

#[cfg(test)]
pub(super) mod tests {
    use glam::DVec2;

    use super::*;
    use crate::projection::{project_triangle, ProjectionTriangleCache};
    use crate::render::trilinear::workloads::fan_grid;
    use crate::scene::builtin;
    use proptest::prelude::*;

    /// Every way an outline can be sampled and clipped: the three samplings (slices at
    /// `depths`), each with and without scene-space clipping.
    fn modes(depths: &[f64]) -> [(Sampling<'_>, bool); 6] {
        let adaptive = Sampling::Adaptive {
            tolerance: ADAPTIVE_TOLERANCE_PX,
            levels: 8,
        };
        [Sampling::Anchors, Sampling::Slices(depths), adaptive]
            .map(|sampling| [(sampling, true), (sampling, false)])
            .concat()
            .try_into()
            .unwrap_or_else(|_| unreachable!("six modes"))
    }

    proptest! {
        /// Soundness of the skip: every shape [`is_behind`] says to skip, traced and clipped
        /// the slow way (crossings over the depth range of all the shapes, every sampling,
        /// with and without scene-space clipping), leaves nothing. Scene triangles reach
        /// from behind the base plane to in front of it, so that the cubics have roots of
        /// both signs; `behind_shapes_occur` checks that such shapes do occur.
        #[test]
        fn a_shape_behind_the_view_plane_clips_to_nothing(
            corners in proptest::array::uniform3(
                (-3.0..3.0f64, -3.0..3.0f64, -4.0..6.0f64)
            ),
        ) {
            let (triangle, cache) = test_triangle();
            let scene = corners.map(|(x, y, z)| DVec3::new(x, y, z));
            let Ok(shapes) = project_triangle(&cache, scene) else { return Ok(()) };
            let range = depth_range(shapes.iter());
            let (mut outline, mut scratch, mut depths) = (Vec::new(), Vec::new(), Vec::new());
            for shape in shapes.iter().filter(is_behind) {
                slice_depths(&shape, 8, &mut depths);
                for mode in modes(&depths) {
                    let mut crossings = EdgeCrossings::new(&triangle, scene, range);
                    outline.clear();
                    trace_outline(&triangle, &shape, scene, mode, &mut crossings, &mut outline);
                    clip_outline(&mut outline, &mut scratch);
                    prop_assert!(outline.is_empty(), "{:?} {:?}", shape.vertices, outline);
                }
            }
        }
    }

    proptest! {
        /// Soundness of the skip beyond a domain line: every shape [`is_outside_domain`]
        /// says to skip, traced (every sampling, scene-space clipping on, as the skip
        /// requires) and clipped, leaves nothing. Scene triangles reach well past the
        /// projection triangle's domain; `outside_shapes_occur` checks that such shapes do
        /// occur.
        #[test]
        fn a_shape_beyond_a_domain_line_clips_to_nothing(
            corners in proptest::array::uniform3(
                (-6.0..6.0f64, -6.0..6.0f64, 0.5..8.0f64)
            ),
        ) {
            let (triangle, cache) = test_triangle();
            let scene = corners.map(|(x, y, z)| DVec3::new(x, y, z));
            let Ok(shapes) = project_triangle(&cache, scene) else { return Ok(()) };
            let range = depth_range(shapes.iter().filter(is_drawn));
            let (mut outline, mut scratch, mut depths) = (Vec::new(), Vec::new(), Vec::new());
            for shape in shapes.iter().filter(is_drawn) {
                let skipped = EdgeCrossings::new(&triangle, scene, range);
                if !is_outside_domain(&shape, &skipped, triangle.degenerate) {
                    continue;
                }
                slice_depths(&shape, 8, &mut depths);
                for (sampling, _) in modes(&depths).into_iter().filter(|(_, clipping)| *clipping) {
                    let mut crossings = EdgeCrossings::new(&triangle, scene, range);
                    outline.clear();
                    let mode = (sampling, true);
                    trace_outline(&triangle, &shape, scene, mode, &mut crossings, &mut outline);
                    clip_outline(&mut outline, &mut scratch);
                    prop_assert!(outline.is_empty(), "{:?} {:?}", shape.vertices, outline);
                }
            }
        }
    }

    /// The proptest's triangle sees shapes beyond a domain line (the skip is exercised); a
    /// shape inside is not skipped, crossings formed without scene-space clipping skip
    /// nothing, and a shape reaching a degenerate depth is not skipped.
    #[test]
    fn outside_shapes_occur() {
        let (triangle, cache) = test_triangle();
        // Far to the side of the triangle's rays (x beyond every ray at these depths).
        let outside = [
            DVec3::new(9.0, 0.0, 2.0),
            DVec3::new(10.0, 0.5, 2.5),
            DVec3::new(9.5, -0.5, 3.0),
        ];
        let inside = [
            DVec3::new(-0.1, -0.1, 2.0),
            DVec3::new(0.2, -0.1, 2.5),
            DVec3::new(0.0, 0.2, 3.0),
        ];
        let in_domain =
            |s: &Shape| (s.vertices.iter()).all(|x| x.u > 0.0 && x.v > 0.0 && x.u + x.v < 1.0);
        for (scene, outside) in [(outside, true), (inside, false)] {
            let shapes = project_triangle(&cache, scene).expect("projectable");
            let range = depth_range(shapes.iter().filter(is_drawn));
            let crossings = EdgeCrossings::new(&triangle, scene, range);
            // The shapes beyond the domain (outside), or wholly in it (inside).
            let drawn: Vec<Shape> = (shapes.iter().filter(is_drawn))
                .filter(|s| outside || in_domain(s))
                .collect();
            assert!(!drawn.is_empty(), "{scene:?}");
            let skipped = |c: &EdgeCrossings, degenerate| {
                drawn.iter().any(|s| is_outside_domain(s, c, degenerate))
            };
            assert_eq!(skipped(&crossings, None), outside, "{scene:?}");
            assert!(!skipped(&EdgeCrossings::none(), None));
            assert!(!skipped(&crossings, Some((0.0, f64::INFINITY))));
        }
    }

    /// A projection triangle with directions of unequal slopes (rays that do not meet), so
    /// that scene vertices have one or three images.
    pub(in crate::render::trilinear) fn test_triangle(
    ) -> (ProjectionTriangle, ProjectionTriangleCache) {
        let p = [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.1),
            DVec3::new(0.0, 1.0, -0.1),
        ];
        let n = [
            DVec3::new(-0.4, -0.3, 1.0),
            DVec3::new(0.5, -0.2, 1.2),
            DVec3::new(0.1, 0.6, 0.9),
        ];
        let cache = ProjectionTriangleCache::new(p, n);
        let screen = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let map = ScreenMap::new(screen, DVec2::splat(400.0), cache);
        (ProjectionTriangle::new(p, n, map), cache)
    }

    /// The proptest's triangle sees shapes behind the view plane (the skip is exercised)
    /// next to shapes in front of it, and a depth of `-0.0` or NaN is not "behind".
    #[test]
    fn behind_shapes_occur() {
        let (_, cache) = test_triangle();
        // A triangle behind the base plane, and one straddling it.
        let behind = [
            DVec3::new(-0.2, -0.2, -2.0),
            DVec3::new(0.3, -0.1, -2.5),
            DVec3::new(0.0, 0.3, -1.5),
        ];
        let shapes = project_triangle(&cache, behind).expect("projectable");
        assert!(shapes.iter().count() > 0 && shapes.iter().all(|s| is_behind(&s)));
        let straddling = [behind[0], DVec3::new(0.3, -0.1, 2.5), behind[2]];
        let shapes = project_triangle(&cache, straddling).expect("projectable");
        assert!(shapes.iter().any(|s| is_drawn(&s)));
        let vertex = |t: f64| crate::projection::ShapeVertex {
            u: 0.2,
            v: 0.2,
            t,
            scene_vertex: 0,
            inside: true,
        };
        let edges = [crate::projection::SceneEdge::V1V2; 2];
        for t in [-0.0, f64::NAN] {
            let vertices = [vertex(-1.0), vertex(t)];
            let shape = Shape {
                vertices: &vertices,
                edges: &edges,
            };
            assert!(!is_behind(&shape), "{t}");
        }
    }

    /// On cube-floor through the 18-triangle fan most shapes clipped away are behind the
    /// view plane and skipped untraced; `skipped_behind` is part of `clipped_away`, and
    /// every other shape is drawn or clipped away after tracing.
    #[test]
    fn cube_floor_skips_shapes_behind_the_view_plane() {
        let scene = builtin::load("cube-floor").expect("builtin scene");
        let projection = Trilinear::new(&fan_grid(3).expect("fan"), 200, 200).expect("mesh");
        let triangles = projection_triangles(&projection);
        let geometry = SceneGeometry::new(&scene);
        for curves in [
            CurveOptions::ADAPTIVE,
            CurveOptions {
                scene_clipping: false,
                ..CurveOptions::ADAPTIVE
            },
        ] {
            let c = project_all(&triangles, &geometry, curves).counts;
            assert!(c.skipped_behind <= c.clipped_away, "{c:?}");
            assert!(2 * c.skipped_behind > c.clipped_away, "{c:?}");
            assert!(c.shapes > c.clipped_away, "{c:?}");
        }
    }
}
