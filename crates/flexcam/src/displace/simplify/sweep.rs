//! The simplification driver: random candidate edges, the best by normal deviation, in sweeps.
//!
//! As in Ramsey et al.'s method (chapter 6 of Ramsey 2005): every step draws a number of
//! candidate edges at random (a fraction of the input's edges), computes for each the cost
//! of collapsing it (the smallest cosine between a face's normal before and after), and
//! collapses the one that turns its faces least, if that cosine is above the threshold. The
//! faces a collapse changes are tagged altered, and edges of altered faces wait for the next
//! sweep, so that each sweep removes a spread of independent edges across the mesh rather
//! than eating into one region. No priority queue is kept: a cost, once computed, is cached
//! with the edge until a face around either end changes.

use super::collapse::{CollapseKind, Plan, Work};
use super::halfedge::{Defect, HalfEdgeMesh, NONE};
use super::split::Simplified;
use super::PolyMesh;

/// How to simplify.
#[derive(Debug, Clone, PartialEq)]
pub struct SimplifyOptions {
    /// Stop once at most this many faces are left (or no edge may collapse).
    pub target_faces: usize,
    /// The largest angle, in degrees, by which a collapse may turn any face's normal
    /// (the dissertation's tau = 0.99 as a cosine is about 8.1 degrees). A face turning by
    /// 90 degrees or more (a fold-over) is refused whatever the threshold.
    pub threshold_degrees: f32,
    /// The fraction of the input's edges drawn as candidates for each collapse (the
    /// dissertation uses 1 %); at least one.
    pub candidate_fraction: f32,
    /// Half-edge collapses (a vertex kept) or full-edge ones (a new vertex).
    pub collapse: CollapseKind,
    /// Seed of the candidate draws: the same input and options give the same result.
    pub seed: u64,
}

impl SimplifyOptions {
    /// The dissertation's settings (tau = 0.99, 1 % of the edges per draw), full-edge
    /// collapses, down to `target_faces`.
    pub fn to_faces(target_faces: usize) -> SimplifyOptions {
        SimplifyOptions {
            target_faces,
            threshold_degrees: 0.99f32.acos().to_degrees(),
            candidate_fraction: 0.01,
            collapse: CollapseKind::Full,
            seed: 1,
        }
    }
}

/// Simplifies `mesh` as [`SimplifyOptions`] say; see the module documentation. Refuses a mesh
/// that is not an oriented manifold ([`HalfEdgeMesh::build`]).
pub fn simplify(mesh: &PolyMesh, options: &SimplifyOptions) -> Result<Simplified, Defect> {
    HalfEdgeMesh::build(mesh)?;
    let mut work = Work::new(mesh);
    let min_cos = options.threshold_degrees.to_radians().cos();
    let mut rng = SplitMix(options.seed);
    let mut splits = Vec::new();
    let mut sweeps = 0;
    let mut pool = candidates(&work);
    let draws = ((options.candidate_fraction * pool.len() as f32).round() as usize).max(1);
    while work.live_faces > options.target_faces {
        sweeps += 1;
        if sweeps > 1 {
            pool = candidates(&work);
        }
        let mut altered = vec![false; work.mesh.faces.len()];
        let before = splits.len();
        while !pool.is_empty() && work.live_faces > options.target_faces {
            // Draws with replacement: an edge drawn twice is evaluated once (cached).
            let all = pool.len() <= draws;
            let count = if all { pool.len() } else { draws };
            let mut dropped = Vec::new();
            let mut best: Option<(f32, usize, bool)> = None;
            for k in 0..count {
                let i = if all { k } else { rng.below(pool.len()) };
                let c = &mut pool[i];
                let stale = c.faces.iter().any(|&f| {
                    f != NONE && (altered[f as usize] || work.mesh.faces[f as usize].is_empty())
                });
                match if stale {
                    None
                } else {
                    c.evaluate(&work, options.collapse, min_cos)
                } {
                    Some((cost, reversed)) if cost >= min_cos && cost > 0.0 => {
                        if best.is_none_or(|b| cost > b.0) {
                            best = Some((cost, i, reversed));
                        }
                    }
                    _ => dropped.push(i),
                }
            }
            if let Some((_, i, reversed)) = best {
                let c = &pool[i];
                let (a, b) = if reversed { (c.b, c.a) } else { (c.a, c.b) };
                if let Some(plan) = work.plan(a, b, options.collapse) {
                    if work.topology_allows(&plan) {
                        splits.push(work.apply(plan, &mut altered));
                    }
                }
                dropped.push(i);
            }
            dropped.sort_unstable_by(|x, y| y.cmp(x));
            dropped.dedup();
            for i in dropped {
                pool.swap_remove(i);
            }
        }
        if splits.len() == before {
            break;
        }
    }
    Ok(work.finish(splits, sweeps))
}

/// An edge that may collapse, with its faces (one is [`NONE`] on the boundary) and its
/// cached evaluation.
struct Candidate {
    a: u32,
    b: u32,
    faces: [u32; 2],
    cached: Option<Cached>,
}

/// An evaluation and the stamps of the ends it was computed at.
struct Cached {
    stamps: (u32, u32),
    value: Option<(f32, bool)>,
}

impl Candidate {
    /// The cost of the best allowed direction (`true`: `b` goes) before the topology check,
    /// or `None` when no direction is allowed.
    fn evaluate(&mut self, work: &Work, kind: CollapseKind, min_cos: f32) -> Option<(f32, bool)> {
        let stamps = (work.stamp[self.a as usize], work.stamp[self.b as usize]);
        if let Some(c) = &self.cached {
            if c.stamps == stamps {
                return c.value;
            }
        }
        let score = |plan: Option<Plan>| -> Option<f32> {
            let plan = plan?;
            if !work.boundary_allows(&plan, min_cos) {
                return None;
            }
            work.cost(&plan)
        };
        let forward = score(work.plan(self.a, self.b, kind)).map(|c| (c, false));
        let value = match kind {
            CollapseKind::Full => forward,
            CollapseKind::Half => {
                let backward = score(work.plan(self.b, self.a, kind)).map(|c| (c, true));
                match (forward, backward) {
                    (Some(f), Some(b)) => Some(if b.0 > f.0 { b } else { f }),
                    (f, b) => f.or(b),
                }
            }
        };
        self.cached = Some(Cached { stamps, value });
        value
    }
}

/// Every edge of the working mesh, once.
fn candidates(work: &Work) -> Vec<Candidate> {
    let mut sides: Vec<(u32, u32, u32)> = Vec::new();
    for (f, face) in work.mesh.faces.iter().enumerate() {
        for (i, &v) in face.iter().enumerate() {
            let w = face[(i + 1) % face.len()];
            sides.push((v.min(w), v.max(w), f as u32));
        }
    }
    sides.sort_unstable();
    let mut out: Vec<Candidate> = Vec::new();
    for (a, b, f) in sides {
        match out.last_mut() {
            Some(c) if (c.a, c.b) == (a, b) => c.faces[1] = f,
            _ => out.push(Candidate {
                a,
                b,
                faces: [f, NONE],
                cached: None,
            }),
        }
    }
    out
}

/// SplitMix64 (Steele, Lea and Flood 2014): small, fast, and the same on every platform.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (n > 0), by Lemire's multiply-shift.
    fn below(&mut self, n: usize) -> usize {
        ((self.next() as u128 * n as u128) >> 64) as usize
    }
}
