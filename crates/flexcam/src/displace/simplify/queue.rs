//! Greedy half-edge collapses by a cost the caller computes, from a priority queue: the
//! progressive mesh's order (Ramsey 2005, section 6.2, after Sander et al. 2001): every
//! half-edge collapse is queued with its cost, the cheapest is performed, and the collapses
//! out of every vertex whose faces changed are queued again with their new costs.
//!
//! The collapses themselves, their manifold checks and their vertex-split records are those
//! of the sweep simplifier ([`super::simplify`]); only the order and the cost differ.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::collapse::{CollapseKind, Work};
use super::halfedge::{Defect, HalfEdgeMesh};
use super::split::Simplified;
use super::PolyMesh;

/// The cost of half-edge collapses, and what it keeps up to date as they happen.
pub trait HalfEdgeCost {
    /// The cost of moving vertex `a` onto its neighbour `b` (smaller is better), or `None`
    /// when that collapse is not allowed. `changed` lists every face through `a` with its
    /// vertex list after the collapse (empty: the face goes); `faces` are the current faces
    /// by stable id (the input's face indices).
    fn cost(&self, a: u32, b: u32, changed: &[(u32, Vec<u32>)], faces: &[Vec<u32>]) -> Option<f64>;

    /// The collapse of `a` onto `b` was performed: `faces` are the faces after it.
    fn collapsed(&mut self, a: u32, b: u32, changed: &[(u32, Vec<u32>)], faces: &[Vec<u32>]);
}

/// A simplification in cost order, with the cost of each collapse (in split order).
#[derive(Debug, Clone)]
pub struct Ordered {
    /// The coarse mesh and the splits back to the input.
    pub simplified: Simplified,
    /// The cost of each collapse, in split order.
    pub costs: Vec<f64>,
    /// After how many collapses the mesh first had at most each of the face counts asked
    /// for (the collapses done in all where it never got there).
    pub reached: Vec<usize>,
}

/// Collapses half-edges of `mesh`, cheapest first by `cost`, until at most the smallest of
/// `face_counts` faces are left or no collapse is allowed; records when each of
/// `face_counts` was reached. Refuses a mesh that is not an oriented manifold.
pub fn collapse_in_order(
    mesh: &PolyMesh,
    face_counts: &[usize],
    cost: &mut impl HalfEdgeCost,
) -> Result<Ordered, Defect> {
    HalfEdgeMesh::build(mesh)?;
    let mut work = Work::new(mesh);
    let target = face_counts.iter().copied().min().unwrap_or(0);
    let mut reached: Vec<Option<usize>> = face_counts
        .iter()
        .map(|&n| (work.live_faces <= n).then_some(0))
        .collect();
    let mut heap = BinaryHeap::new();
    for v in 0..mesh.vertex_count() as u32 {
        push_out_of(&work, v, cost, &mut heap);
    }
    let mut splits = Vec::new();
    let mut costs = Vec::new();
    while work.live_faces > target {
        let Some((Reverse((bits, a, b)), stamp)) = heap.pop() else {
            break;
        };
        let (ai, bi) = (a as usize, b as usize);
        if !work.mesh.alive[ai] || !work.mesh.alive[bi] || work.stamp[ai] != stamp {
            continue;
        }
        let Some(plan) = work.plan(a, b, CollapseKind::Half) else {
            continue;
        };
        if !work.topology_allows(&plan) {
            continue;
        }
        let changed = plan.changed.clone();
        let mut altered = vec![false; work.mesh.faces.len()];
        splits.push(work.apply(plan, &mut altered));
        costs.push(f64::from_bits(bits));
        cost.collapsed(a, b, &changed, &work.mesh.faces);
        for (slot, &n) in reached.iter_mut().zip(face_counts) {
            if slot.is_none() && work.live_faces <= n {
                *slot = Some(splits.len());
            }
        }
        let mut touched: Vec<u32> = work.around[bi]
            .iter()
            .flat_map(|&f| work.mesh.faces[f as usize].iter().copied())
            .collect();
        touched.sort_unstable();
        touched.dedup();
        for v in touched {
            push_out_of(&work, v, cost, &mut heap);
        }
    }
    let done = splits.len();
    Ok(Ordered {
        simplified: work.finish(splits, 1),
        costs,
        reached: reached.into_iter().map(|r| r.unwrap_or(done)).collect(),
    })
}

/// Queue entries: (cost bits, going vertex, kept vertex) smallest first, and the going
/// vertex's stamp when the cost was computed. Costs are finite and not negative, so their
/// bits order as they do.
type Queue = BinaryHeap<(Reverse<(u64, u32, u32)>, u32)>;

/// Queues every allowed half-edge collapse out of vertex `v`.
fn push_out_of(work: &Work, v: u32, cost: &impl HalfEdgeCost, heap: &mut Queue) {
    // The vertices next to `v` along an edge of one of its faces.
    let mut neighbours: Vec<u32> = work.around[v as usize]
        .iter()
        .flat_map(|&f| {
            let face = &work.mesh.faces[f as usize];
            let n = face.len();
            let i = face.iter().position(|&x| x == v).unwrap_or(0);
            [face[(i + 1) % n], face[(i + n - 1) % n]]
        })
        .collect();
    neighbours.sort_unstable();
    neighbours.dedup();
    for w in neighbours {
        let Some(plan) = work.plan(v, w, CollapseKind::Half) else {
            continue;
        };
        if let Some(c) = cost.cost(v, w, &plan.changed, &work.mesh.faces) {
            if c.is_finite() && c >= 0.0 {
                heap.push((Reverse((c.to_bits(), v, w)), work.stamp[v as usize]));
            }
        }
    }
}
