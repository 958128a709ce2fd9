//! The first half of the projection stage, per projection triangle: which scene triangles
//! can have an image in it (the live pairs), each with its vertices' cubics solved.
//!
//! The cull is hierarchical: the box tree over the scene's clusters (`cull_tree`) skips
//! whole subtrees beyond one bounding plane of the triangle's ray volume
//! (`volume_bounds`); the triangles of the clusters left are tested one by one by their
//! vertices' plane masks, each vertex's mask computed once. Both levels cull exactly the
//! pairs the triangle-by-triangle test alone culls (tested in `cull_tests`), so the images
//! do not depend on the tree. The pairs left are listed in scene-triangle order, as the
//! renderer's determinism requires.

use super::hit_terms::HitTerms;
use super::outline::ProjectionTriangle;
use super::polygons::PairCounts;
use super::scene_geometry::SceneGeometry;
use crate::projection::Solutions;

/// A (projection triangle, scene triangle) pair that survived the volume cull: what drawing
/// it needs.
#[derive(Debug, Clone, Copy)]
pub struct LivePair {
    /// Index of the projection triangle in the mesh.
    pub projection: u32,
    /// Index of the scene triangle.
    pub triangle: u32,
    /// The scene triangle's plane (it has one: zero-area triangles are not live).
    pub terms: HitTerms,
    /// Its three vertices' solutions through the projection triangle.
    pub solved: [Solutions; 3],
}

/// Per-vertex state of the projection triangle being culled, reused from one projection
/// triangle to the next by one worker (no clearing: an entry is valid only if stamped with
/// the current generation).
pub struct VertexCache {
    states: Vec<VertexState>,
    generation: u32,
    /// The clusters the tree kept, reused.
    clusters: Vec<u32>,
}

#[derive(Debug, Clone, Copy)]
struct VertexState {
    /// The generation this entry belongs to.
    stamp: u32,
    /// The bounding planes the vertex is beyond (`VolumeBounds::outside`).
    mask: u32,
    /// Its cubic's solutions, once a live pair needed them.
    solved: Option<Solutions>,
}

impl VertexCache {
    /// A cache for a scene of `vertices` vertices.
    pub fn new(vertices: usize) -> VertexCache {
        let unused = VertexState {
            stamp: 0,
            mask: 0,
            solved: None,
        };
        VertexCache {
            states: vec![unused; vertices],
            generation: 0,
            clusters: Vec::new(),
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

/// Appends the live pairs of `triangle` (number `index` in the mesh) with every triangle of
/// `scene` to `live`, in scene-triangle order; returns the counts of the cull (`pairs`,
/// `culled_volume`, `culled_tree`, `culled_zero_area`, `vertices_projected`).
pub fn live_pairs(
    triangle: &ProjectionTriangle,
    index: u32,
    scene: &SceneGeometry,
    cache: &mut VertexCache,
    live: &mut Vec<LivePair>,
) -> PairCounts {
    let bounds = &triangle.bounds;
    let projector = triangle.map.cache();
    cache.next_generation();
    let mut counts = PairCounts {
        pairs: scene.triangles.len() as u64,
        ..PairCounts::default()
    };
    let mut kept = std::mem::take(&mut cache.clusters);
    kept.clear();
    counts.culled_tree = scene.tree.visit(bounds, |cluster| kept.push(cluster));
    counts.culled_volume = counts.culled_tree;
    kept.sort_unstable();
    let generation = cache.generation;
    for &cluster in &kept {
        for k in scene.clusters[cluster as usize].triangles.clone() {
            let corners = scene.triangles[k];
            let masks = corners.map(|i| {
                let state = &mut cache.states[i as usize];
                if state.stamp != generation {
                    *state = VertexState {
                        stamp: generation,
                        mask: bounds.outside(scene.vertices[i as usize]),
                        solved: None,
                    };
                }
                state.mask
            });
            if masks.iter().fold(u32::MAX, |common, &m| common & m) != 0 {
                counts.culled_volume += 1;
                continue;
            }
            let Some(terms) = HitTerms::new(scene.corners(k)) else {
                counts.culled_zero_area += 1;
                continue;
            };
            let solved = corners.map(|i| {
                *cache.states[i as usize].solved.get_or_insert_with(|| {
                    counts.vertices_projected += 1;
                    projector.project_point(scene.vertices[i as usize])
                })
            });
            live.push(LivePair {
                projection: index,
                triangle: k as u32,
                terms,
                solved,
            });
        }
    }
    cache.clusters = kept;
    counts
}
