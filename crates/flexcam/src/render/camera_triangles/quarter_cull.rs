//! Object culling per quarter of the camera triangle (Hou et al. 2006, 2.4, carried down the
//! tight bound's quartering): the camera triangle is quartered recursively while clusters of
//! scene triangles survive, each piece testing only the clusters its parent kept
//! ([`bound::misses`] on the piece: a piece is itself a camera triangle, with a narrower
//! cone of rays), and each scene triangle of a cluster that survives down to a piece is
//! bounded from that piece on ([`bound::tight_in`]). A small scene triangle far from most of
//! a wide camera triangle then costs the quartering of the pieces near it only, shared by
//! the triangles of its cluster, instead of a quartering of the whole camera triangle per
//! triangle. Exact: a cluster is dropped from a piece only where the hull argument proves
//! the piece cannot see it, and the pieces of a quartering cover the camera triangle.

use glam::DVec2;

use super::bound::{self, quarters};
use super::camera::{Camera, CORNERS};
use crate::render::trilinear::SceneGeometry;

/// Clusters are carried down to pieces of this quartering depth at most.
const CLUSTER_DEPTH: u32 = 3;

/// A piece of fewer pixels than this is not quartered further for culling.
const MIN_SPLIT_PIXELS: f64 = 256.0;

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
pub fn pieces(camera: &Camera, scene: &SceneGeometry, buffers: &mut Buffers) -> u64 {
    buffers.kept.clear();
    buffers.pieces.clear();
    buffers.kept.extend(0..scene.clusters.len() as u32);
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
    for i in parent {
        let c = buffers.kept[i];
        if !bound::misses(camera, sub, &scene.clusters[c as usize].box_corners) {
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
