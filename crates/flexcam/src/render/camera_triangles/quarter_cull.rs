//! Object culling per quarter of the camera triangle (Hou et al. 2006, 2.4, carried down the
//! tight bound's quartering): the camera triangle is quartered recursively while clusters of
//! scene triangles survive, each piece testing only the clusters its parent kept
//! ([`bound::PieceTest`] on the piece: a piece is itself a camera triangle, with a narrower
//! cone of rays), and each scene triangle of a cluster that survives down to a piece is
//! bounded from that piece on ([`bound::tight_in`]). A small scene triangle far from most of
//! a wide camera triangle then costs the quartering of the pieces near it only, shared by
//! the triangles of its cluster, instead of a quartering of the whole camera triangle per
//! triangle. The whole camera triangle first tests [`Groups`] of consecutive clusters, so
//! that a group it cannot see costs one test instead of one per cluster. Exact: a cluster is dropped from a piece only where the hull argument proves
//! the piece cannot see it, and the pieces of a quartering cover the camera triangle.

use std::ops::Range;

use glam::{DVec2, DVec3};

use super::bound::{self, quarters};
use super::camera::{Camera, CORNERS};
use crate::render::trilinear::SceneGeometry;

/// Clusters are carried down to pieces of this quartering depth at most (2 rather than 3:
/// on the bench's reflection scenes a third level of cluster tests cost more than the
/// quartering it spared the tight bound).
const CLUSTER_DEPTH: u32 = 2;

/// A piece of fewer pixels than this is not quartered further for culling.
const MIN_SPLIT_PIXELS: f64 = 256.0;

/// Clusters per [`Groups`] entry.
const GROUP_SIZE: usize = 8;

/// Runs of [`GROUP_SIZE`] consecutive clusters of the scene, each with the box around their
/// boxes (the eight corners of the componentwise minimum and maximum of theirs, so that it
/// holds every point of theirs exactly; a cluster's infinite box makes the group's
/// infinite), built once per renderer.
#[derive(Debug, Clone, Default)]
pub struct Groups {
    groups: Vec<(Range<usize>, [DVec3; 8])>,
}

impl Groups {
    pub fn new(scene: &SceneGeometry) -> Groups {
        let groups = scene
            .clusters
            .chunks(GROUP_SIZE)
            .enumerate()
            .map(|(g, chunk)| {
                let (lo, hi) = chunk
                    .iter()
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), c| {
                        (lo.min(c.box_corners[0]), hi.max(c.box_corners[7]))
                    });
                let corners = std::array::from_fn(|c| {
                    DVec3::new(
                        if c & 1 == 0 { lo.x } else { hi.x },
                        if c & 2 == 0 { lo.y } else { hi.y },
                        if c & 4 == 0 { lo.z } else { hi.z },
                    )
                });
                let start = g * GROUP_SIZE;
                (start..start + chunk.len(), corners)
            })
            .collect();
        Groups { groups }
    }

    /// Each group's clusters (indices into `SceneGeometry::clusters`) and box corners.
    #[cfg(test)]
    pub fn iter(&self) -> impl Iterator<Item = &(Range<usize>, [DVec3; 8])> {
        self.groups.iter()
    }
}

/// A scene triangle to bound inside one piece of the camera triangle.
#[derive(Debug, Clone, Copy)]
pub struct Piece {
    pub triangle: u32,
    pub sub: [DVec2; 3],
    pub depth: u32,
}

/// Reused buffers of [`pieces`] (no allocation per piece).
#[derive(Debug, Default)]
pub struct Buffers {
    /// A stack of cluster indices: each piece's survivors follow its parent's.
    kept: Vec<u32>,
    pub pieces: Vec<Piece>,
}

/// Fills `buffers.pieces` with the (scene triangle, piece) pairs `camera` must bound, the
/// pieces of each triangle consecutive and in quartering order (so that one pair's regions
/// are drawn one after the other, as the fragment stage's counting expects); returns the
/// number of distinct scene triangles among them.
pub fn pieces(
    camera: &Camera,
    scene: &SceneGeometry,
    groups: &Groups,
    buffers: &mut Buffers,
) -> u64 {
    buffers.kept.clear();
    buffers.pieces.clear();
    let mut test = bound::PieceTest::new(camera, CORNERS);
    for (clusters, corners) in &groups.groups {
        if !test.misses(corners) {
            buffers
                .kept
                .extend(clusters.start as u32..clusters.end as u32);
        }
    }
    let all = 0..buffers.kept.len();
    descend(camera, scene, CORNERS, 0, all, buffers);
    buffers.pieces.sort_by_key(|p| p.triangle);
    let mut distinct = 0;
    let mut last = None;
    for p in &buffers.pieces {
        if last != Some(p.triangle) {
            distinct += 1;
            last = Some(p.triangle);
        }
    }
    distinct
}

/// Keeps the clusters of `buffers.kept[parent]` that piece `sub` may see, then quarters it
/// or hands their triangles to the tight bound.
fn descend(
    camera: &Camera,
    scene: &SceneGeometry,
    sub: [DVec2; 3],
    depth: u32,
    parent: std::ops::Range<usize>,
    buffers: &mut Buffers,
) {
    let start = buffers.kept.len();
    let mut test = bound::PieceTest::new(camera, sub);
    for i in parent {
        let c = buffers.kept[i];
        if !test.misses(&scene.clusters[c as usize].box_corners) {
            buffers.kept.push(c);
        }
    }
    let survivors = start..buffers.kept.len();
    if survivors.is_empty() {
        return;
    }
    let pixels = (sub[1] - sub[0]).perp_dot(sub[2] - sub[0]).abs() / 2.0 * camera.pixels_per_area;
    if depth >= CLUSTER_DEPTH.min(bound::MAX_DEPTH) || pixels < MIN_SPLIT_PIXELS {
        for i in survivors {
            let cluster = &scene.clusters[buffers.kept[i] as usize];
            for k in cluster.triangles.clone() {
                buffers.pieces.push(Piece {
                    triangle: k as u32,
                    sub,
                    depth,
                });
            }
        }
    } else {
        for quarter in quarters(sub) {
            descend(
                camera,
                scene,
                quarter,
                depth + 1,
                survivors.clone(),
                buffers,
            );
        }
    }
    buffers.kept.truncate(start);
}
