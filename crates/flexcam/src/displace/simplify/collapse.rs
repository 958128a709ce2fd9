//! One edge collapse on the working mesh: planning it (the faces it changes), its
//! normal-deviation cost, the checks that keep the mesh a manifold, and performing it while
//! recording the vertex split that undoes it.
//!
//! Vertices and faces keep their ids for the whole simplification: a collapse kills vertices
//! and empties faces but never renumbers, and a full-edge collapse appends its new vertex.
//! A face through both ends of the edge loses one corner (a triangle disappears, a quad
//! becomes a triangle); every other face through an end is pointed at the kept vertex.

use glam::{Vec2, Vec3};

use super::fan::{fan, Fan};
use super::polymesh::polygon_normal;
use super::split::{Simplified, SplitVertex, Stable, VertexSplit};
use super::PolyMesh;

/// Which vertex an edge collapses into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CollapseKind {
    /// Into one of its ends: vertices stay where they were on the original surface, which a
    /// parameterisation or a surface-touching coarse mesh needs; touches the faces of one end.
    Half,
    /// Into a new vertex at its midpoint (mean attributes): smoother results, since each end
    /// moves half as far; touches the faces of both ends.
    Full,
}

/// The mesh being simplified; see the module documentation.
#[derive(Debug, Clone)]
pub(super) struct Work {
    pub mesh: Stable,
    /// The faces through each vertex.
    pub around: Vec<Vec<u32>>,
    pub live_faces: usize,
    /// Bumped whenever a face through the vertex changes: a cached cost of an edge stays
    /// valid while the stamps of both its ends do.
    pub stamp: Vec<u32>,
}

/// A collapse worked out but not performed.
#[derive(Debug, Clone)]
pub(super) struct Plan {
    /// The end that goes (a half-edge collapse keeps `b`; a full-edge one removes both).
    pub a: u32,
    pub b: u32,
    pub kind: CollapseKind,
    /// The vertex the edge becomes: `b`, or the next new id.
    pub into: u32,
    pub position: Vec3,
    /// Faces the collapse changes, with their new vertex lists (empty when removed).
    pub changed: Vec<(u32, Vec<u32>)>,
}

impl Work {
    pub fn new(mesh: &PolyMesh) -> Work {
        let n = mesh.vertex_count();
        let mut around = vec![Vec::new(); n];
        for (f, face) in mesh.faces.iter().enumerate() {
            for &v in face {
                around[v as usize].push(f as u32);
            }
        }
        Work {
            mesh: Stable {
                positions: mesh.positions.clone(),
                normals: mesh.normals.clone(),
                uvs: mesh.uvs.clone(),
                colors: mesh.colors.clone(),
                alive: vec![true; n],
                faces: mesh.faces.clone(),
            },
            around,
            live_faces: mesh.face_count(),
            stamp: vec![0; n],
        }
    }

    /// The fan of `v` with the faces of `changed` replaced by their new lists.
    fn fan_after(&self, v: u32, changed: &[(u32, Vec<u32>)]) -> Option<Fan> {
        let faces = self.around[v as usize].iter().filter_map(|&f| {
            match changed.iter().find(|c| c.0 == f) {
                Some((_, new)) => (!new.is_empty()).then_some(new.as_slice()),
                None => Some(self.mesh.faces[f as usize].as_slice()),
            }
        });
        fan(v, faces)
    }

    /// The fan of `v` now.
    fn fan_now(&self, v: u32) -> Option<Fan> {
        fan(
            v,
            self.around[v as usize]
                .iter()
                .map(|&f| self.mesh.faces[f as usize].as_slice()),
        )
    }

    /// Works out the collapse of the edge `a`-`b` (`a` going, for [`CollapseKind::Half`]).
    /// `None` when a face through both ends but not along the edge would be pinched.
    pub fn plan(&self, a: u32, b: u32, kind: CollapseKind) -> Option<Plan> {
        let (into, position, touched) = match kind {
            CollapseKind::Half => (b, self.mesh.positions[b as usize], vec![a]),
            CollapseKind::Full => (
                self.mesh.positions.len() as u32,
                (self.mesh.positions[a as usize] + self.mesh.positions[b as usize]) * 0.5,
                vec![a, b],
            ),
        };
        let mut changed: Vec<(u32, Vec<u32>)> = Vec::new();
        for &v in &touched {
            for &f in &self.around[v as usize] {
                if changed.iter().any(|c| c.0 == f) {
                    continue;
                }
                let new = merged(&self.mesh.faces[f as usize], a, b, into)?;
                changed.push((f, new));
            }
        }
        Some(Plan {
            a,
            b,
            kind,
            into,
            position,
            changed,
        })
    }

    /// The smallest cosine between a changed face's unit normal before and after `plan`
    /// (Ramsey et al.'s cost: 1 for a collapse that turns no face), or `None` when a face
    /// would lose its area. Faces of no area before have no direction to keep and are skipped.
    pub fn cost(&self, plan: &Plan) -> Option<f32> {
        let before = |v: u32| self.mesh.positions[v as usize];
        let after = |v: u32| {
            if v == plan.into {
                plan.position
            } else {
                self.mesh.positions[v as usize]
            }
        };
        let mut smallest = 1.0f32;
        for (f, new) in &plan.changed {
            if new.is_empty() {
                continue;
            }
            let n0 = polygon_normal(&self.mesh.faces[*f as usize], before).normalize_or_zero();
            if n0 == Vec3::ZERO {
                continue;
            }
            let n1 = polygon_normal(new, after).normalize_or_zero();
            if n1 == Vec3::ZERO {
                return None;
            }
            smallest = smallest.min(n0.dot(n1));
        }
        Some(smallest)
    }

    /// Whether the ends may move as `plan` moves them: a vertex on the boundary only along a
    /// boundary edge, and only where the outline turns by less than the angle whose cosine is
    /// `min_cos` (the outline counterpart of the normal-deviation cost).
    pub fn boundary_allows(&self, plan: &Plan, min_cos: f32) -> bool {
        let moving: &[u32] = match plan.kind {
            CollapseKind::Half => &[plan.a],
            CollapseKind::Full => &[plan.a, plan.b],
        };
        let edge_faces = plan
            .changed
            .iter()
            .filter(|(f, _)| {
                super::halfedge::has_edge(&self.mesh.faces[*f as usize], plan.a, plan.b)
            })
            .count();
        for &v in moving {
            let Some(Fan {
                boundary: Some((p, s)),
                ..
            }) = self.fan_now(v)
            else {
                continue;
            };
            if edge_faces != 1 {
                return false;
            }
            let at = self.mesh.positions[v as usize];
            let d0 = (at - self.mesh.positions[p as usize]).normalize_or_zero();
            let d1 = (self.mesh.positions[s as usize] - at).normalize_or_zero();
            if d0.dot(d1) < min_cos {
                return false;
            }
        }
        true
    }

    /// Whether the mesh after `plan` is still a manifold the simplifier supports: one fan
    /// around the new vertex and around every other vertex of a changed face, no two faces
    /// through the new vertex with the same vertices (what collapsing a tetrahedron's edge
    /// would leave), no vertex left without faces, and no interior vertex newly left with
    /// fewer than three faces.
    pub fn topology_allows(&self, plan: &Plan) -> bool {
        let around_new: Vec<&[u32]> = plan
            .changed
            .iter()
            .map(|(_, new)| new.as_slice())
            .chain(
                self.around[plan.b as usize]
                    .iter()
                    .filter(|f| !plan.changed.iter().any(|c| c.0 == **f))
                    .map(|&f| self.mesh.faces[f as usize].as_slice()),
            )
            .filter(|new| !new.is_empty())
            .collect();
        let Some(new_fan) = fan(plan.into, around_new.iter().copied()) else {
            return false;
        };
        if new_fan.faces == 0 || (new_fan.boundary.is_none() && new_fan.faces < 3) {
            return false;
        }
        let mut sorted: Vec<Vec<u32>> = around_new
            .iter()
            .map(|f| {
                let mut s = f.to_vec();
                s.sort_unstable();
                s
            })
            .collect();
        sorted.sort();
        if sorted.windows(2).any(|w| w[0] == w[1]) {
            return false;
        }
        let mut others: Vec<u32> = plan
            .changed
            .iter()
            .flat_map(|(f, _)| self.mesh.faces[*f as usize].iter().copied())
            .filter(|&v| v != plan.a && v != plan.b)
            .collect();
        others.sort_unstable();
        others.dedup();
        others.iter().all(|&v| {
            let before = self.around[v as usize].len();
            match self.fan_after(v, &plan.changed) {
                None => false,
                Some(f) => {
                    f.faces > 0 && (f.boundary.is_some() || f.faces >= 3 || f.faces >= before)
                }
            }
        })
    }

    /// Performs `plan`, marking the faces it changes in `altered`, and returns the vertex
    /// split that undoes it.
    pub fn apply(&mut self, plan: Plan, altered: &mut [bool]) -> VertexSplit {
        let (a, b, into) = (plan.a, plan.b, plan.into);
        let split = VertexSplit {
            into,
            ends: [self.vertex(a), self.vertex(b)],
            faces: plan
                .changed
                .iter()
                .map(|(f, _)| (*f, self.mesh.faces[*f as usize].clone()))
                .collect(),
        };
        if plan.kind == CollapseKind::Full {
            let mean = |list: &mut Vec<Vec3>| {
                if !list.is_empty() {
                    let m = (list[a as usize] + list[b as usize]) * 0.5;
                    list.push(m);
                }
            };
            mean(&mut self.mesh.colors);
            mean(&mut self.mesh.normals);
            if let Some(n) = self.mesh.normals.last_mut() {
                *n = n.normalize_or_zero();
            }
            if !self.mesh.uvs.is_empty() {
                let m = (self.mesh.uvs[a as usize] + self.mesh.uvs[b as usize]) * 0.5;
                self.mesh.uvs.push(m);
            }
            self.mesh.positions.push(plan.position);
            self.mesh.alive.push(true);
            self.around.push(Vec::new());
            self.stamp.push(0);
            self.mesh.alive[b as usize] = false;
        }
        self.mesh.alive[a as usize] = false;
        let mut around_into: Vec<u32> = self.around[b as usize].clone();
        around_into.extend(self.around[a as usize].iter().copied());
        for (f, new) in plan.changed {
            altered[f as usize] = true;
            if new.is_empty() {
                self.live_faces -= 1;
                for &v in &self.mesh.faces[f as usize] {
                    self.around[v as usize].retain(|&g| g != f);
                }
                around_into.retain(|&g| g != f);
            }
            self.mesh.faces[f as usize] = new;
        }
        around_into.sort_unstable();
        around_into.dedup();
        self.around[a as usize].clear();
        self.around[b as usize].clear();
        for &f in &around_into {
            for &v in &self.mesh.faces[f as usize] {
                self.stamp[v as usize] = self.stamp[v as usize].wrapping_add(1);
            }
        }
        self.around[into as usize] = around_into;
        split
    }

    /// The simplification that `splits` (the collapses performed, in order) made of the
    /// input, in `sweeps` sweeps.
    pub fn finish(self, splits: Vec<VertexSplit>, sweeps: usize) -> Simplified {
        let (coarse, vertex_ids, face_ids) = self.mesh.compact_with_ids();
        Simplified {
            coarse,
            splits,
            vertex_ids,
            face_ids,
            vertex_id_count: self.mesh.alive.len(),
            face_id_count: self.mesh.faces.len(),
            sweeps,
        }
    }

    /// A vertex with its attributes, for a split record.
    pub fn vertex(&self, v: u32) -> SplitVertex {
        let i = v as usize;
        SplitVertex {
            id: v,
            position: self.mesh.positions[i],
            normal: self.mesh.normals.get(i).copied().unwrap_or(Vec3::ZERO),
            uv: self.mesh.uvs.get(i).copied().unwrap_or(Vec2::ZERO),
            color: self.mesh.colors.get(i).copied().unwrap_or(Vec3::ZERO),
        }
    }
}

/// `face` with `a` and `b` replaced by `into` and a corner merged where they were adjacent;
/// empty when fewer than three corners remain, `None` when `into` would appear twice.
fn merged(face: &[u32], a: u32, b: u32, into: u32) -> Option<Vec<u32>> {
    let mapped: Vec<u32> = face
        .iter()
        .map(|&v| if v == a || v == b { into } else { v })
        .collect();
    let n = mapped.len();
    let new: Vec<u32> = (0..n)
        .filter(|&i| !(mapped[i] == into && mapped[(i + 1) % n] == into))
        .map(|i| mapped[i])
        .collect();
    if new.iter().filter(|&&v| v == into).count() > 1 {
        return None;
    }
    Some(if new.len() < 3 { Vec::new() } else { new })
}
