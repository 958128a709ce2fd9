//! The scene's triangles in one flat f64 list, numbered like the ray caster's BVH (objects in
//! order, each object's triangles in order), with the owner and plane of each, the
//! triangles that meet at each edge, and clusters of consecutive triangles with their
//! bounding boxes under a box tree (`cull_tree`).

use std::collections::HashMap;

use glam::{DVec3, Vec2};

use super::cull_tree::{Cluster, CullTree};
use super::hit_terms::HitTerms;
use crate::render::prepared::Hit;
use crate::scene::Scene;

/// Which object triangle a scene triangle is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Owner {
    /// Index in `scene.objects`.
    pub object: u32,
    /// The object's id (what the id buffer holds).
    pub id: u32,
    /// Index of the triangle in the object's mesh.
    pub triangle: u32,
}

impl Owner {
    /// The hit on this triangle at ray parameter `t` and `barycentric`, as the ray caster
    /// reports one (for its shading).
    pub fn hit(&self, t: f64, barycentric: Vec2) -> Hit {
        Hit {
            t,
            object: self.object as usize,
            triangle: self.triangle as usize,
            barycentric,
        }
    }
}

/// Every scene vertex (f64, world space) and triangle.
#[derive(Debug, Clone, Default)]
pub struct SceneGeometry {
    /// Every scene vertex, world space, in f64.
    pub vertices: Vec<DVec3>,
    /// Indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// `owners[k]` is where `triangles[k]` comes from.
    pub owners: Vec<Owner>,
    /// The id of each object, by index in `scene.objects`.
    pub object_ids: Vec<u32>,
    /// Per triangle, the edges `<V1V2, V1V3, V2V3>` (bits 0, 1, 2) that another triangle
    /// shares (same end positions, any object): the surface continues across them.
    pub shared_edges: Vec<u8>,
    /// Runs of at most `CLUSTER_SIZE` consecutive triangles of one object, each with the
    /// corners of its bounding box: a projection triangle can cull a whole run at once.
    pub clusters: Vec<Cluster>,
    /// The box tree over `clusters`: a projection triangle skips whole subtrees.
    pub tree: CullTree,
    /// Per triangle, its plane as the terms of a projector's hit (`HitTerms::new`), built
    /// once rather than for every projection triangle it is live in; `None` for a triangle
    /// without a plane (zero area or a non-finite corner), which has nothing to draw.
    pub hit_terms: Vec<Option<HitTerms>>,
    /// Per triangle, the numbers of its edges `<V1V2, V1V3, V2V3>` in `edge_users`.
    edges: Vec<[u32; 3]>,
    /// The triangles using each edge.
    edge_users: EdgeUsers,
}

/// The triangles using each edge (by end positions), in triangle order, all lists in one
/// vector: edge `e`'s are `users[start[e]..start[e + 1]]`. A triangle is listed once for
/// each of its edges that is this edge (twice where two of its edges coincide: a degenerate
/// triangle).
#[derive(Debug, Clone, Default)]
struct EdgeUsers {
    start: Vec<u32>,
    users: Vec<u32>,
}

impl EdgeUsers {
    /// Numbers the edges of `triangles` (given by their corners) in order of first use;
    /// returns the users of every edge and, per triangle, the numbers of its edges
    /// `<V1V2, V1V3, V2V3>`.
    fn new(triangles: impl Iterator<Item = [DVec3; 3]>) -> (EdgeUsers, Vec<[u32; 3]>) {
        let mut numbers: HashMap<[u64; 6], u32> = HashMap::new();
        let mut counts: Vec<u32> = Vec::new();
        let edges: Vec<[u32; 3]> = triangles
            .map(|c| {
                EDGES.map(|(i, j)| {
                    let next = numbers.len() as u32;
                    let edge = *numbers.entry(edge_key(c[i], c[j])).or_insert(next);
                    if edge == next {
                        counts.push(0);
                    }
                    counts[edge as usize] += 1;
                    edge
                })
            })
            .collect();
        let mut start = Vec::with_capacity(counts.len() + 1);
        start.push(0);
        for count in counts {
            start.push(start[start.len() - 1] + count);
        }
        let mut free = start.clone();
        let mut users = vec![0; start[start.len() - 1] as usize];
        for (k, triangle_edges) in edges.iter().enumerate() {
            for &edge in triangle_edges {
                users[free[edge as usize] as usize] = k as u32;
                free[edge as usize] += 1;
            }
        }
        (EdgeUsers { start, users }, edges)
    }

    /// The users of edge `edge`, in triangle order.
    fn of(&self, edge: u32) -> &[u32] {
        let e = edge as usize;
        &self.users[self.start[e] as usize..self.start[e + 1] as usize]
    }
}

/// Most triangles in a [`Cluster`], a leaf of the [`CullTree`]. Meshes list neighbouring
/// triangles near each other (the built-in shapes and tessellations row by row), so
/// consecutive runs are compact; short runs keep the triangle-by-triangle tests behind a
/// visited leaf few (8 rather than 32: `project_ms` of the detail-in-context scene, see
/// docs/trilinear.md).
pub const CLUSTER_SIZE: usize = 8;

/// The edges `<V1V2, V1V3, V2V3>` as vertex pairs.
const EDGES: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

/// An edge by its end positions, order-independent.
fn edge_key(a: DVec3, b: DVec3) -> [u64; 6] {
    let bits = |p: DVec3| p.to_array().map(f64::to_bits);
    let (a, b) = (bits(a), bits(b));
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}

impl SceneGeometry {
    /// The vertices and triangles of every object of `scene`, in f64.
    pub fn new(scene: &Scene) -> SceneGeometry {
        let mut out = SceneGeometry::default();
        for (index, object) in scene.objects.iter().enumerate() {
            out.object_ids.push(object.id);
            let first = out.vertices.len() as u32;
            out.vertices
                .extend(object.mesh.positions.iter().map(|p| p.as_dvec3()));
            for (k, triangle) in object.mesh.triangles.iter().enumerate() {
                out.triangles.push(triangle.map(|i| first + i));
                out.owners.push(Owner {
                    object: index as u32,
                    id: object.id,
                    triangle: k as u32,
                });
            }
        }
        (out.edge_users, out.edges) =
            EdgeUsers::new((0..out.triangles.len()).map(|k| out.corners(k)));
        out.clusters = out.clusters();
        out.tree = CullTree::new(&out.clusters);
        out.hit_terms = (0..out.triangles.len())
            .map(|k| HitTerms::new(out.corners(k)))
            .collect();
        out.shared_edges = (0..out.triangles.len())
            .map(|k| {
                (0..3).fold(0, |mask, edge| {
                    mask | (u8::from(out.across(k, edge).next().is_some()) << edge)
                })
            })
            .collect();
        out
    }

    /// Every triangle across edge `edge` (0, 1, 2 for `<V1V2, V1V3, V2V3>`) of triangle `k`,
    /// in triangle order: none on a boundary, one inside a manifold surface, several where
    /// three or more triangles meet at the edge (non-manifold). These are the edge's users
    /// but for this use of it, so a degenerate triangle with two coinciding edges is across
    /// itself.
    pub fn across(&self, k: usize, edge: usize) -> impl Iterator<Item = usize> + '_ {
        let users = self.edge_users.of(self.edges[k][edge]);
        let own = users.iter().position(|&n| n as usize == k);
        users
            .iter()
            .enumerate()
            .filter(move |&(i, _)| Some(i) != own)
            .map(|(_, &n)| n as usize)
    }

    /// The triangles cut into [`Cluster`]s: runs of [`CLUSTER_SIZE`] within each object.
    fn clusters(&self) -> Vec<Cluster> {
        let mut clusters = Vec::new();
        let mut start = 0;
        while start < self.triangles.len() {
            let object = self.owners[start].object;
            let end = (start..self.triangles.len().min(start + CLUSTER_SIZE))
                .take_while(|&k| self.owners[k].object == object)
                .last()
                .map_or(start + 1, |k| k + 1);
            let corners = || (start..end).flat_map(|k| self.corners(k));
            let (lo, hi) = if corners().all(|v| v.is_finite()) {
                corners().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                })
            } else {
                (DVec3::NEG_INFINITY, DVec3::INFINITY)
            };
            let box_corners = std::array::from_fn(|c| {
                DVec3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                )
            });
            clusters.push(Cluster {
                triangles: start..end,
                box_corners,
            });
            start = end;
        }
        clusters
    }

    /// The vertices of triangle `k`.
    pub fn corners(&self, k: usize) -> [DVec3; 3] {
        self.triangles[k].map(|i| self.vertices[i as usize])
    }
}

#[cfg(test)]
mod tests {
    use glam::{Affine3A, Vec3};

    use super::*;
    use crate::scene::{self, Material, Mesh, Object};

    /// A scene of one object per entry of `objects`, each a list of triangles by corners.
    fn scene_of(objects: &[&[[Vec3; 3]]]) -> Scene {
        let mut scene = scene::load("builtin:cube-floor").unwrap();
        scene.objects = objects
            .iter()
            .enumerate()
            .map(|(index, triangles)| {
                let mut mesh = Mesh::default();
                for (k, corners) in triangles.iter().enumerate() {
                    mesh.positions.extend(corners);
                    let first = 3 * k as u32;
                    mesh.triangles.push([first, first + 1, first + 2]);
                }
                Object {
                    id: index as u32 + 1,
                    name: format!("o{index}"),
                    mesh: mesh.into(),
                    material: Material::default(),
                    world_to_object: Affine3A::IDENTITY,
                    displacement: None,
                }
            })
            .collect();
        scene
    }

    fn across(geometry: &SceneGeometry, k: usize, edge: usize) -> Vec<usize> {
        geometry.across(k, edge).collect()
    }

    /// Three triangles meeting at the edge from the origin to +x (a fin: not a manifold
    /// surface), the third in another object: each edge user has the two others across it,
    /// in triangle order; the outer edges have none.
    #[test]
    fn a_non_manifold_edge_lists_every_triangle_across_it() {
        let (o, x) = (Vec3::ZERO, Vec3::X);
        let scene = scene_of(&[&[[o, x, Vec3::Y], [x, o, Vec3::NEG_Y]], &[[o, x, Vec3::Z]]]);
        let geometry = SceneGeometry::new(&scene);
        // The shared edge is V1V2 (edge 0) of every triangle.
        assert_eq!(across(&geometry, 0, 0), [1, 2]);
        assert_eq!(across(&geometry, 1, 0), [0, 2]);
        assert_eq!(across(&geometry, 2, 0), [0, 1]);
        assert_eq!(geometry.shared_edges, [0b001; 3]);
        for k in 0..3 {
            for edge in [1, 2] {
                assert_eq!(across(&geometry, k, edge), Vec::<usize>::new());
            }
        }
        assert_eq!(geometry.owners[2].id, 2);
    }

    /// Two triangles of a square share its diagonal (V1V3 of the first, V1V2 of the
    /// second) and nothing else; a degenerate triangle whose edges V1V3 and V2V3 coincide
    /// (V1 = V2) is across itself there, and its V1V2, of zero length, has nothing across.
    #[test]
    fn manifold_and_degenerate_edges() {
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
        let e = Vec3::new(5.0, 0.0, 0.0);
        let scene = scene_of(&[&[[a, b, c], [a, c, d], [e, e, b]]]);
        let geometry = SceneGeometry::new(&scene);
        assert_eq!(across(&geometry, 0, 1), [1]);
        assert_eq!(across(&geometry, 1, 0), [0]);
        assert_eq!(geometry.shared_edges[..2], [0b010, 0b001]);
        assert_eq!(across(&geometry, 2, 0), Vec::<usize>::new());
        assert_eq!(across(&geometry, 2, 1), [2]);
        assert_eq!(across(&geometry, 2, 2), [2]);
        assert_eq!(geometry.shared_edges[2], 0b110);
    }

    /// The cube-floor scene's clusters: consecutive runs of at most `CLUSTER_SIZE`
    /// triangles of one object each, covering every triangle once in order, each box
    /// holding every vertex of its run.
    #[test]
    fn clusters_cover_the_triangles_in_order_within_objects() {
        let geometry = SceneGeometry::new(&scene::load("builtin:cube-floor").unwrap());
        let mut next = 0;
        for cluster in &geometry.clusters {
            let run = cluster.triangles.clone();
            assert_eq!(run.start, next);
            assert!(!run.is_empty() && run.len() <= CLUSTER_SIZE);
            let object = geometry.owners[run.start].object;
            let (lo, hi) = (cluster.box_corners[0], cluster.box_corners[7]);
            for k in run.clone() {
                assert_eq!(geometry.owners[k].object, object);
                for v in geometry.corners(k) {
                    assert!(v.cmpge(lo).all() && v.cmple(hi).all());
                }
            }
            next = run.end;
        }
        assert_eq!(next, geometry.triangles.len());
        assert!(geometry.clusters.len() >= 686 / CLUSTER_SIZE);
    }
}
