//! The discrete levels of detail of a prepared scene's displaced objects (Ramsey 2005,
//! section 6.3): each object's progressive mesh ([`crate::displace::progressive`]) cut at
//! [`LOD_PERCENTS`] of its faces, each level with its own tree of displacement shells (a
//! [`DisplacedSet`] over the scene with every displaced object's mesh replaced by that
//! level's), and one bound per object shared by all levels: the union of every level's
//! shells, which holds the detailed mesh displaced anywhere between its minimum and maximum
//! displacement.
//!
//! A ray picks its level ([`LodSelection`]): by the dissertation's distance rule, or by its
//! own footprint: the coarsest level whose texture deviation is at most
//! [`FOOTPRINT_SHARE`] of the ray's width where it meets the surface, which needs no eye
//! point and so holds under every projection.

use std::sync::Arc;

use glam::DVec3;

use super::DisplacedSet;
use crate::displace::progressive::{ProgressiveMesh, LOD_PERCENTS};
use crate::scene::{Object, Scene};

/// A level may deviate from the detailed surface by at most this share of the footprint.
pub const FOOTPRINT_SHARE: f64 = 0.5;

/// How a ray on a displaced object picks its level of detail.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LodSelection {
    /// The coarsest level whose texture deviation is at most half (`FOOTPRINT_SHARE`) of the
    /// ray's footprint at the surface.
    #[default]
    Footprint,
    /// Ramsey's rule by the distance `d` from the ray's origin to the object's centre, less
    /// `m`, the distance from the centre to the farthest corner of the shared bound (which
    /// holds the surface at every level and displacement), in units of `m`: below 0.1 `M20` (inside
    /// the object's bound), then `M100` to 1.25, `M80` to 1.66, `M60` to 2.5, `M40` to 5,
    /// `M20` beyond.
    Distance,
    /// Always the detailed mesh.
    Finest,
    /// Always level `k` of [`LOD_PERCENTS`] (0 the detailed mesh, 4 `M20`; larger indices
    /// mean the coarsest).
    Level(usize),
}

/// One displaced object's place in the levels: its centre, size, bound and the texture
/// deviation of each level.
#[derive(Debug, Clone)]
struct ObjectLods {
    centre: DVec3,
    /// The union of every level's shell boxes: the shared bound.
    bound: [DVec3; 2],
    deviations: Vec<f64>,
}

/// One level: the scene with its displaced objects' meshes at that level, and its set.
#[derive(Debug)]
pub(in crate::render) struct Level {
    pub scene: Scene,
    pub set: Arc<DisplacedSet>,
}

/// The levels of detail of a scene's displaced objects (module documentation).
#[derive(Debug)]
pub(in crate::render) struct Lods {
    /// Finest first, as [`LOD_PERCENTS`]; the first is the scene itself.
    pub levels: Vec<Level>,
    objects: Vec<Option<ObjectLods>>,
    /// Objects whose progressive mesh could not be built (they keep their detailed mesh at
    /// every level), with the reason.
    pub failures: Vec<String>,
}

impl Lods {
    /// The levels of `scene`'s displaced objects (those `set` holds).
    pub fn new(scene: &Scene, set: &DisplacedSet) -> Lods {
        let mut failures = Vec::new();
        let meshes: Vec<Option<ProgressiveMesh>> = scene
            .objects
            .iter()
            .enumerate()
            .map(|(i, object)| {
                set.displacement(i)?;
                ProgressiveMesh::new(&object.mesh)
                    .map_err(|e| failures.push(format!("{}: {e}", object.name)))
                    .ok()
            })
            .collect();
        let levels: Vec<Level> = (0..LOD_PERCENTS.len())
            .map(|k| {
                let mut level = scene.clone();
                for (object, pm) in level.objects.iter_mut().zip(&meshes) {
                    if let Some(pm) = pm {
                        object.mesh = Arc::new(pm.lods[k].mesh.clone());
                    }
                }
                let set = DisplacedSet::new(&level).expect("the scene has displaced objects");
                Level { scene: level, set }
            })
            .collect();
        let objects = scene
            .objects
            .iter()
            .enumerate()
            .map(|(i, object)| {
                set.displacement(i)?;
                let deviations = match &meshes[i] {
                    Some(pm) => pm.lods.iter().map(|l| l.deviation).collect(),
                    None => vec![0.0; LOD_PERCENTS.len()],
                };
                Some(object_lods(object, &levels, i, deviations))
            })
            .collect();
        Lods {
            levels,
            objects,
            failures,
        }
    }

    /// The level of detail of a ray from `origin` whose footprint at displaced object
    /// `object` is `footprint`, by `selection`.
    pub fn select(
        &self,
        selection: LodSelection,
        object: usize,
        origin: DVec3,
        footprint: f64,
    ) -> usize {
        let Some(o) = &self.objects[object] else {
            return 0;
        };
        match selection {
            LodSelection::Finest => 0,
            LodSelection::Level(k) => k.min(LOD_PERCENTS.len() - 1),
            LodSelection::Footprint => {
                let allowed = FOOTPRINT_SHARE * footprint;
                (0..o.deviations.len())
                    .rev()
                    .find(|&k| o.deviations[k] <= allowed)
                    .unwrap_or(0)
            }
            LodSelection::Distance => {
                let m = (0..8)
                    .map(|k| {
                        let b = &o.bound;
                        let corner = DVec3::new(b[k & 1].x, b[(k >> 1) & 1].y, b[(k >> 2) & 1].z);
                        (corner - o.centre).length()
                    })
                    .fold(0.0, f64::max);
                let d = ((origin - o.centre).length() - m) / m.max(f64::MIN_POSITIVE);
                let last = LOD_PERCENTS.len() - 1;
                match d {
                    d if d < 0.1 => last,
                    d if d < 1.25 => 0,
                    d if d < 1.66 => 1.min(last),
                    d if d < 2.5 => 2.min(last),
                    d if d < 5.0 => 3.min(last),
                    _ => last,
                }
            }
        }
    }

    /// The shared bound of displaced object `object` (module documentation).
    #[cfg(test)]
    pub fn bound(&self, object: usize) -> Option<[DVec3; 2]> {
        self.objects[object].as_ref().map(|o| o.bound)
    }

    /// The texture deviation of each level of object `object` (empty if not displaced).
    #[cfg(test)]
    pub fn deviations(&self, object: usize) -> &[f64] {
        self.objects[object]
            .as_ref()
            .map_or(&[], |o| o.deviations.as_slice())
    }
}

/// The centre, size and shared bound of displaced object `index` over `levels`.
fn object_lods(
    object: &Object,
    levels: &[Level],
    index: usize,
    deviations: Vec<f64>,
) -> ObjectLods {
    let mesh = &object.mesh;
    let n = mesh.positions.len().max(1) as f64;
    let centre = mesh.positions.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / n;
    let bound = levels
        .iter()
        .filter_map(|l| l.set.object_bound(index))
        .fold(
            [DVec3::INFINITY, DVec3::NEG_INFINITY],
            |[lo, hi], [a, b]| [lo.min(a), hi.max(b)],
        );
    ObjectLods {
        centre,
        bound,
        deviations,
    }
}
