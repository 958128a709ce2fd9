//! The first half of the projection stage, per projection triangle: which scene triangles
//! can have an image in it (the live pairs), each with its vertices' cubics solved.
//!
//! The cull is hierarchical: the box tree over the scene's clusters (`cull_tree`) skips
//! whole subtrees beyond one bounding plane of the triangle's ray volume
//! (`volume_bounds`); the triangles of the clusters left are tested one by one by their
//! vertices' plane masks, each vertex's mask computed once, against the planes that still
//! cut its cluster's box only. Both levels cull exactly the
//! pairs the triangle-by-triangle test alone culls (tested in `cull_tests`), so the images
//! do not depend on the tree. The pairs left are listed in scene-triangle order, as the
//! renderer's determinism requires.

use super::central::CentralProjection;
use super::outline::ProjectionTriangle;
use super::scene_geometry::SceneGeometry;
use crate::projection::Solutions;
use crate::render::{Counter, Stats};

/// What projecting the scene through projection triangles did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PairCounts {
    /// Scene vertices projected (one cubic each).
    pub vertices_projected: u64,
    /// (projection triangle, scene triangle) pairs considered.
    pub pairs: u64,
    /// Pairs culled because the scene triangle lies beyond one bounding plane of the
    /// projection triangle's ray volume (no cubic solved), by the box tree or one by one.
    pub culled_volume: u64,
    /// Of `culled_volume`, the pairs culled with a whole subtree of the box tree
    /// (`cull_tree`), without a test of their own.
    pub culled_tree: u64,
    /// Pairs culled because every vertex image is behind the view plane.
    pub culled_behind: u64,
    /// Pairs culled because every vertex image is outside one domain line and no scene
    /// edge crosses that line's edge surface.
    pub culled_outside: u64,
    /// Pairs skipped because the scene triangle has zero area: no plane, nothing to draw.
    pub culled_zero_area: u64,
    /// Pairs of a central projection not drawn because their scene triangle lies wholly
    /// behind one that covers the projection triangle's whole domain (`occlusion`).
    pub culled_hidden: u64,
    /// Pairs (or tessellated sub-triangles) that could not be cut into shapes; their
    /// projection triangle is ray cast instead.
    pub unprojectable: u64,
    /// Pairs with a shape reaching across a depth where the projection triangle's
    /// parametric triangle degenerates, drawn split there (`degenerate_band`).
    pub split_pairs: u64,
    /// Pairs of such a projection triangle with no shapes (a scene vertex at the degenerate
    /// depth itself), drawn pixel tested at every depth (`degenerate_band`).
    pub tested_pairs: u64,
    /// Shapes formed.
    pub shapes: u64,
    /// Shapes with nothing left after clipping.
    pub clipped_away: u64,
    /// Of `clipped_away`, the shapes known to be clipped away before their outline was
    /// traced: every vertex behind the view plane (`polygons::is_behind`).
    pub skipped_behind: u64,
    /// Of `clipped_away`, the shapes known to be clipped away before their outline was
    /// traced because it lies beyond a domain line (`outline::is_outside_domain`).
    pub skipped_outside: u64,
    /// Outline points of the shapes drawn (after clipping).
    pub outline_points: u64,
}

impl PairCounts {
    pub fn add(&mut self, o: &PairCounts) {
        self.vertices_projected += o.vertices_projected;
        self.pairs += o.pairs;
        self.culled_volume += o.culled_volume;
        self.culled_tree += o.culled_tree;
        self.culled_behind += o.culled_behind;
        self.culled_outside += o.culled_outside;
        self.culled_zero_area += o.culled_zero_area;
        self.culled_hidden += o.culled_hidden;
        self.unprojectable += o.unprojectable;
        self.split_pairs += o.split_pairs;
        self.tested_pairs += o.tested_pairs;
        self.shapes += o.shapes;
        self.clipped_away += o.clipped_away;
        self.skipped_behind += o.skipped_behind;
        self.skipped_outside += o.skipped_outside;
        self.outline_points += o.outline_points;
    }

    /// Inserts the counters into `stats`.
    pub fn record(&self, stats: &mut Stats) {
        for (name, value) in [
            ("vertices_projected", self.vertices_projected),
            ("pairs", self.pairs),
            ("culled_volume", self.culled_volume),
            ("culled_tree", self.culled_tree),
            ("culled_behind", self.culled_behind),
            ("culled_outside", self.culled_outside),
            ("culled_zero_area", self.culled_zero_area),
            ("culled_hidden", self.culled_hidden),
            ("unprojectable", self.unprojectable),
            ("split_pairs", self.split_pairs),
            ("tested_pairs", self.tested_pairs),
            ("shapes", self.shapes),
            ("clipped_away", self.clipped_away),
            ("skipped_behind", self.skipped_behind),
            ("skipped_outside", self.skipped_outside),
            ("outline_points", self.outline_points),
        ] {
            stats.insert(name, Counter::Count(value));
        }
    }
}

/// A scene triangle that survived the volume cull of one projection triangle: what drawing
/// the pair needs. Its vertices' solutions are kept once per vertex in the projection
/// triangle's pool ([`LivePairs::solutions`]) and named here by index, so a pair is small
/// (a vertex is shared by about six triangles) and nothing large is copied between the cull
/// and the drawing.
#[derive(Debug, Clone, Copy)]
pub struct LivePair {
    /// Index of the scene triangle; it has a plane (`SceneGeometry::hit_terms`: zero-area
    /// triangles are not live), looked up where the pair is drawn, so that a pair stays
    /// 16 bytes (the live pairs of a frame are written once and read once).
    pub triangle: u32,
    /// Where its three vertices' solutions are in [`LivePairs::solutions`]; not solved
    /// (`u32::MAX`) for a projection triangle drawn as a central projection
    /// ([`ProjectionTriangle::central`]) or a fan of rays ([`ProjectionTriangle::fan`]),
    /// which need none.
    pub solved: [u32; 3],
}

/// The live pairs of one projection triangle, in scene-triangle order, with the solutions
/// of their vertices' cubics through it.
#[derive(Debug, Clone, Default)]
pub struct LivePairs {
    /// Index of the projection triangle in the mesh.
    pub projection: u32,
    pub pairs: Vec<LivePair>,
    /// The solutions [`LivePair::solved`] names.
    pub solutions: Vec<Solutions>,
}

impl LivePairs {
    /// The solutions of the three vertices of `pair` (one of `self.pairs`).
    pub fn solved(&self, pair: &LivePair) -> [Solutions; 3] {
        pair.solved.map(|i| self.solutions[i as usize])
    }
}

/// Per-vertex state of the projection triangle being culled, reused from one projection
/// triangle to the next by one worker (no clearing: an entry is valid only if stamped with
/// the current generation).
pub struct VertexCache {
    states: Vec<VertexState>,
    generation: u32,
    /// The clusters the tree kept, each with the planes that still cut its box, reused.
    clusters: Vec<(u32, u32)>,
    /// The live pairs of the projection triangle as they are found, reused.
    pairs: Vec<LivePair>,
    /// The solutions of their vertices' cubics as they are solved, reused.
    solutions: Vec<Solutions>,
}

/// [`VertexState::solved`] of a vertex whose cubic no live pair has needed yet.
const NOT_SOLVED: u32 = u32::MAX;

#[derive(Debug, Clone, Copy)]
struct VertexState {
    /// The generation this entry belongs to.
    stamp: u32,
    /// The bounding planes the vertex is beyond (`VolumeBounds::outside`), computed among
    /// the planes cutting the box of the first kept cluster that uses it (it is beyond none
    /// of the others: `VolumeBounds::outside_of`); for a central projection, the
    /// half-spaces of its cones the vertex is outside of (`CentralProjection::outside`).
    mask: u32,
    /// Index of its cubic's solutions in the pool of the live pairs, or [`NOT_SOLVED`].
    solved: u32,
}

impl VertexCache {
    /// A cache for a scene of `vertices` vertices.
    pub fn new(vertices: usize) -> VertexCache {
        let unused = VertexState {
            stamp: 0,
            mask: 0,
            solved: NOT_SOLVED,
        };
        VertexCache {
            states: vec![unused; vertices],
            generation: 0,
            clusters: Vec::new(),
            pairs: Vec::new(),
            solutions: Vec::new(),
        }
    }

    /// Starts a new projection triangle: every entry becomes stale. When the generation
    /// counter wraps (after 2^32 - 1 triangles) the stamps are cleared once.
    fn next_generation(&mut self) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.states.iter_mut().for_each(|s| s.stamp = 0);
            self.generation = 1;
        }
    }
}

/// The live pairs of `triangle` (number `index` in the mesh) with every triangle of `scene`,
/// in scene-triangle order, and the counts of the cull (`pairs`, `culled_volume`,
/// `culled_tree`, `culled_zero_area`, `vertices_projected`). None, and no pair counted, for
/// a triangle the renderer ray casts ([`ProjectionTriangle::ray_cast`]).
pub fn live_pairs(
    triangle: &ProjectionTriangle,
    index: u32,
    scene: &SceneGeometry,
    cache: &mut VertexCache,
) -> (LivePairs, PairCounts) {
    if triangle.ray_cast {
        let live = LivePairs {
            projection: index,
            ..LivePairs::default()
        };
        return (live, PairCounts::default());
    }
    if let Some(central) = &triangle.central {
        return central_live_pairs(central, index, scene, cache);
    }
    let bounds = triangle.bounds();
    let projector = triangle.map.cache();
    cache.next_generation();
    let (mut live, mut counts) = no_pairs_yet(index, scene);
    let mut kept = std::mem::take(&mut cache.clusters);
    kept.clear();
    counts.culled_tree = scene
        .tree
        .visit(&bounds, |cluster, cutting| kept.push((cluster, cutting)));
    counts.culled_volume = counts.culled_tree;
    kept.sort_unstable();
    // Gathered in reused storage and copied out at their exact size (as for a central
    // projection below): every projection triangle's pairs and solutions are kept until
    // they are drawn, and growing vectors would leave their slack and copies behind in
    // fresh memory.
    let mut pairs = std::mem::take(&mut cache.pairs);
    pairs.clear();
    let mut solutions = std::mem::take(&mut cache.solutions);
    solutions.clear();
    let generation = cache.generation;
    for &(cluster, cutting) in &kept {
        for k in scene.clusters[cluster as usize].triangles.clone() {
            let corners = scene.triangles[k];
            let masks = corners.map(|i| {
                let state = &mut cache.states[i as usize];
                if state.stamp != generation {
                    *state = VertexState {
                        stamp: generation,
                        mask: bounds.outside_of(scene.vertices[i as usize], cutting),
                        solved: NOT_SOLVED,
                    };
                }
                state.mask
            });
            if masks.iter().fold(u32::MAX, |common, &m| common & m) != 0 {
                counts.culled_volume += 1;
                continue;
            }
            if scene.hit_terms[k].is_none() {
                counts.culled_zero_area += 1;
                continue;
            }
            // A fan of rays projects no scene point: its pairs need no cubic.
            let solved = corners.map(|i| {
                let state = &mut cache.states[i as usize];
                if triangle.fan.is_some() {
                    return NOT_SOLVED;
                }
                if state.solved == NOT_SOLVED {
                    counts.vertices_projected += 1;
                    state.solved = solutions.len() as u32;
                    solutions.push(projector.project_point(scene.vertices[i as usize]));
                }
                state.solved
            });
            pairs.push(LivePair {
                triangle: k as u32,
                solved,
            });
        }
    }
    live.pairs = pairs.clone();
    live.solutions = solutions.clone();
    cache.pairs = pairs;
    cache.solutions = solutions;
    cache.clusters = kept;
    (live, counts)
}

/// The start of the cull of projection triangle `index`: no live pair, every pair of it
/// with `scene` counted as considered.
fn no_pairs_yet(index: u32, scene: &SceneGeometry) -> (LivePairs, PairCounts) {
    let live = LivePairs {
        projection: index,
        ..LivePairs::default()
    };
    let counts = PairCounts {
        pairs: scene.triangles.len() as u64,
        ..PairCounts::default()
    };
    (live, counts)
}

/// [`live_pairs`] for a projection triangle drawn as the central projection `central`: its
/// rays fill two cones from the focus, which the volume bounds of a triangle (one convex
/// region) cover only loosely, so the scene's triangles are culled by the cones' own
/// planes instead ([`CentralProjection::culled`]), hierarchically as the volume cull: the
/// tree skips the subtrees whose boxes are outside one plane of each cone
/// ([`BoxTest::side`](super::central::BoxTest::side), which culls no pair the vertices
/// keep), and the triangles of the clusters left are tested by their vertices' masks, each
/// computed once.
/// No cubic is solved: the pairs' `solved` are [`NOT_SOLVED`].
fn central_live_pairs(
    central: &CentralProjection,
    index: u32,
    scene: &SceneGeometry,
    cache: &mut VertexCache,
) -> (LivePairs, PairCounts) {
    cache.next_generation();
    let (mut live, mut counts) = no_pairs_yet(index, scene);
    let mut kept = std::mem::take(&mut cache.clusters);
    kept.clear();
    let box_test = central.box_test();
    counts.culled_tree = scene.tree.visit_boxes(
        CentralProjection::ALL_SIDES,
        |centre, half, active| box_test.side(centre, half, active),
        |cluster, _| kept.push((cluster, 0)),
    );
    counts.culled_volume = counts.culled_tree;
    kept.sort_unstable();
    // Gathered in reused storage and copied out at their exact size: one small allocation
    // per projection triangle, not a growing vector's several (every projection
    // triangle's pairs are kept until they are drawn).
    let mut pairs = std::mem::take(&mut cache.pairs);
    pairs.clear();
    let generation = cache.generation;
    for &(cluster, _) in &kept {
        for k in scene.clusters[cluster as usize].triangles.clone() {
            let common = scene.triangles[k].iter().fold(u16::MAX, |common, &i| {
                let state = &mut cache.states[i as usize];
                if state.stamp != generation {
                    *state = VertexState {
                        stamp: generation,
                        mask: u32::from(central.outside(scene.vertices[i as usize])),
                        solved: NOT_SOLVED,
                    };
                }
                // The mask of a central projection has 9 bits.
                common & state.mask as u16
            });
            if CentralProjection::culled(common) {
                counts.culled_volume += 1;
                continue;
            }
            if scene.hit_terms[k].is_none() {
                counts.culled_zero_area += 1;
                continue;
            }
            pairs.push(LivePair {
                triangle: k as u32,
                solved: [NOT_SOLVED; 3],
            });
        }
    }
    live.pairs = pairs.clone();
    cache.pairs = pairs;
    cache.clusters = kept;
    (live, counts)
}
