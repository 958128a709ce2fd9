//! Floater's mean-value parameterisation of one chart (Floater 2003; Ramsey 2005, section
//! 6.2): the chart's boundary loop on the unit circle by arc length, each inner vertex the
//! mean-value-weighted mean of its neighbours,
//!
//! ```text
//! w_j = (tan(a_{j-1} / 2) + tan(a_j / 2)) / |v_j - v|,
//! ```
//!
//! `a_j` the angle at `v` between its neighbours `v_j` and `v_{j+1}`, normalised to sum 1.
//! The weights are positive, so on a convex boundary the map is one to one (Floater's
//! theorem): no triangle flips. The system is solved by Gauss-Seidel iterations (the matrix
//! is diagonally dominant), started from the boundary's mean, to a change under 1e-13.

use std::collections::HashMap;

use glam::DVec2;

use super::topology::{Topology, NONE};
use crate::error::{Error, Result};

/// Most Gauss-Seidel sweeps before giving up.
const MAX_SWEEPS: usize = 200_000;

/// The texture coordinates of the vertices of the chart made of `faces` (a disc; `inside`
/// says which faces are in it), counter-clockwise as its triangles wind. Errors: the chart
/// has a degenerate triangle (no angle), or the iterations do not settle.
pub fn parameterize(
    topology: &Topology,
    faces: &[u32],
    inside: impl Fn(u32) -> bool,
) -> Result<HashMap<u32, DVec2>> {
    // Boundary half-edges in the faces' winding: the interior lies on their left.
    let mut next: HashMap<u32, u32> = HashMap::new();
    let mut vertices: Vec<u32> = Vec::new();
    for &f in faces {
        for (v, w) in topology.edges(f) {
            vertices.push(v);
            let g = topology.across(f, v, w);
            if g == NONE || !inside(g) {
                next.insert(v, w);
            }
        }
    }
    vertices.sort_unstable();
    vertices.dedup();
    let start = *next
        .keys()
        .min()
        .ok_or_else(|| Error::new("a chart has no boundary"))?;
    let mut lengths = Vec::new();
    let mut loop_ = vec![start];
    let mut at = start;
    loop {
        let w = next[&at];
        lengths.push(topology.length(at, w));
        if w == start {
            break;
        }
        if loop_.len() > next.len() {
            return Err(Error::new("a chart's boundary is not one loop"));
        }
        loop_.push(w);
        at = w;
    }
    let perimeter: f64 = lengths.iter().sum();
    if perimeter <= 0.0 || loop_.len() < 3 {
        return Err(Error::new("a chart's boundary has no length"));
    }
    let mut uv: HashMap<u32, DVec2> = HashMap::new();
    let mut travelled = 0.0;
    for (&v, &l) in loop_.iter().zip(&lengths) {
        let angle = std::f64::consts::TAU * travelled / perimeter;
        uv.insert(v, DVec2::new(angle.cos(), angle.sin()));
        travelled += l;
    }
    let inner: Vec<u32> = vertices
        .iter()
        .copied()
        .filter(|v| !uv.contains_key(v))
        .collect();
    let index: HashMap<u32, usize> = inner.iter().enumerate().map(|(i, &v)| (v, i)).collect();
    let rows: Vec<Vec<(u32, f64)>> = inner
        .iter()
        .map(|&v| weights(topology, v))
        .collect::<Result<_>>()?;
    let centre = loop_.iter().map(|v| uv[v]).sum::<DVec2>() / loop_.len() as f64;
    let mut x = vec![centre; inner.len()];
    let value = |x: &[DVec2], w: u32| index.get(&w).map_or_else(|| uv[&w], |&j| x[j]);
    for _ in 0..MAX_SWEEPS {
        let mut change = 0.0f64;
        for (i, row) in rows.iter().enumerate() {
            let new: DVec2 = row.iter().map(|&(w, weight)| value(&x, w) * weight).sum();
            change = change.max((new - x[i]).abs().max_element());
            x[i] = new;
        }
        if change < 1e-13 {
            for (&v, &p) in inner.iter().zip(&x) {
                uv.insert(v, p);
            }
            return Ok(uv);
        }
    }
    Err(Error::new("a chart's parameterisation did not converge"))
}

/// The normalised mean-value weights of inner vertex `v`'s neighbours.
fn weights(topology: &Topology, v: u32) -> Result<Vec<(u32, f64)>> {
    let p = topology.positions[v as usize];
    let mut row: Vec<(u32, f64)> = Vec::new();
    for &f in &topology.vertex_faces[v as usize] {
        let t = topology.triangles[f as usize];
        let k = t.iter().position(|&x| x == v).unwrap_or(0);
        let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
        let (ea, eb) = (
            topology.positions[a as usize] - p,
            topology.positions[b as usize] - p,
        );
        let (la, lb) = (ea.length(), eb.length());
        let angle = ea.angle_between(eb);
        if la == 0.0 || lb == 0.0 || !angle.is_finite() || angle <= 0.0 {
            return Err(Error::new("a chart has a degenerate triangle"));
        }
        let half = (angle / 2.0).tan();
        for (w, l) in [(a, la), (b, lb)] {
            match row.iter_mut().find(|e| e.0 == w) {
                Some(e) => e.1 += half / l,
                None => row.push((w, half / l)),
            }
        }
    }
    let total: f64 = row.iter().map(|e| e.1).sum();
    for e in &mut row {
        e.1 /= total;
    }
    row.sort_unstable_by_key(|e| e.0);
    Ok(row)
}
