//! The chart-based progressive mesh of a displaced object and its discrete levels of detail
//! (Ramsey 2005, sections 6.2 and 6.3, after Sander et al. 2001):
//!
//! 1. the mesh is divided into charts, each a disc, merged by planarity and compactness, and
//!    their boundaries straightened by shortest paths ([`charts`]);
//! 2. each chart gets Floater's mean-value parameterisation, its boundary on the unit
//!    circle ([`mean_value`]);
//! 3. half-edge collapses are performed cheapest first by the largest texture deviation
//!    they make, measured in those charts ([`deviation`], driven by
//!    [`crate::displace::simplify::collapse_in_order`], whose vertex splits rebuild the
//!    mesh);
//! 4. the meshes at [`LOD_PERCENTS`] of the faces are the levels of detail, `M100` being the
//!    input itself.
//!
//! Half-edge collapses keep every coarse vertex a vertex of the input, with its own normal
//! and texture coordinates, so each level is displaced by the same height field over the
//! same texture coordinates. Vertices of the mesh's boundary (which in a scene mesh include
//! its texture seams, where a position appears twice) never move, so seams do not open.

pub mod charts;
pub mod deviation;
pub mod mean_value;
pub mod topology;

use std::collections::HashMap;

use glam::DVec2;

use self::deviation::{barycentric, samples, surface_point, Deviation};
use self::topology::Topology;
use crate::displace::simplify::{collapse_in_order, HalfEdgeMesh, PolyMesh};
use crate::error::{Error, Result};
use crate::scene::Mesh;

/// The levels of detail, in percent of the input's faces, finest first.
pub const LOD_PERCENTS: [usize; 5] = [100, 80, 60, 40, 20];

/// Mean faces per chart that merging aims at.
pub const CHART_FACES: usize = 200;

/// One level of detail.
#[derive(Debug, Clone)]
pub struct Lod {
    /// Its share of the input's faces it aims at (it may keep more where collapses run out).
    pub percent: usize,
    /// The mesh: input vertices with their attributes, fewer triangles.
    pub mesh: Mesh,
    /// The input face each triangle of `mesh` stands in for (its chart is that face's).
    pub faces: Vec<u32>,
    /// The input vertex of each vertex of `mesh`.
    pub vertices: Vec<u32>,
    /// Its largest texture deviation from the input (world units), as
    /// [`ProgressiveMesh::deviation`] measures it.
    pub deviation: f64,
}

/// A mesh's charts, their parameterisations and its levels of detail (module docs).
#[derive(Debug, Clone)]
pub struct ProgressiveMesh {
    /// The chart of each input triangle.
    pub charts: Vec<u32>,
    /// Each chart's texture coordinates of its vertices (by input vertex).
    pub chart_uvs: Vec<HashMap<u32, DVec2>>,
    /// One per [`LOD_PERCENTS`], finest first.
    pub lods: Vec<Lod>,
    topology: Topology,
}

impl ProgressiveMesh {
    /// The progressive mesh of triangle mesh `mesh`. Errors (naming the element): the mesh
    /// is not an oriented manifold, or a chart cannot be parameterised (degenerate
    /// triangles).
    pub fn new(mesh: &Mesh) -> Result<ProgressiveMesh> {
        let poly = PolyMesh::from_triangles(mesh);
        HalfEdgeMesh::build(&poly).map_err(Error::from)?;
        let topology = Topology::new(mesh);
        let faces = mesh.triangles.len();
        let charts = charts::build_charts(&topology, faces.div_ceil(CHART_FACES));
        let chart_count = charts.iter().max().map_or(0, |&c| c as usize + 1);
        let mut members = vec![Vec::new(); chart_count];
        for (f, &c) in charts.iter().enumerate() {
            members[c as usize].push(f as u32);
        }
        let chart_uvs = members
            .iter()
            .enumerate()
            .map(|(c, list)| {
                mean_value::parameterize(&topology, list, |g| charts[g as usize] == c as u32)
                    .map_err(|e| Error::new(format!("chart {c}: {e}")))
            })
            .collect::<Result<Vec<_>>>()?;
        let counts: Vec<usize> = LOD_PERCENTS
            .iter()
            .map(|&p| (faces * p).div_ceil(100))
            .collect();
        let mut cost = Deviation::new(&topology, &charts, &chart_uvs);
        let ordered = collapse_in_order(&poly, &counts, &mut cost).map_err(Error::from)?;
        let total = ordered.simplified.splits.len();
        let mut pm = ProgressiveMesh {
            charts,
            chart_uvs,
            lods: Vec::new(),
            topology,
        };
        for (&percent, &done) in LOD_PERCENTS.iter().zip(&ordered.reached) {
            let (coarse, vertices, faces) = ordered.simplified.refine_with_ids(total - done);
            let mut lod = Lod {
                percent,
                mesh: coarse.to_triangles(),
                faces,
                vertices,
                deviation: 0.0,
            };
            lod.deviation = pm.deviation(&lod);
            pm.lods.push(lod);
        }
        Ok(pm)
    }

    /// The largest texture deviation of `lod` from the input: over every vertex of every
    /// chart and every input triangle's centroid, the distance to the point of `lod` at the
    /// same chart coordinates (found among all of `lod`'s triangles of that chart; a point
    /// outside them all is measured at the nearest border).
    pub fn deviation(&self, lod: &Lod) -> f64 {
        // Per chart: each triangle's corners in the chart and in space.
        type Corners = ([DVec2; 3], [glam::DVec3; 3]);
        let mut by_chart: HashMap<u32, Vec<Corners>> = HashMap::new();
        for (t, &f) in lod.mesh.triangles.iter().zip(&lod.faces) {
            let chart = self.charts[f as usize];
            let ids = t.map(|v| lod.vertices[v as usize]);
            let uvs = &self.chart_uvs[chart as usize];
            by_chart.entry(chart).or_default().push((
                ids.map(|v| uvs[&v]),
                ids.map(|v| self.topology.positions[v as usize]),
            ));
        }
        samples(&self.topology, &self.charts, &self.chart_uvs)
            .iter()
            .map(|(s, _)| {
                by_chart.get(&s.chart).map_or(f64::INFINITY, |list| {
                    list.iter()
                        .map(|(uv, p)| (barycentric(*uv, s.uv), p))
                        .max_by(|x, y| x.0.min_element().total_cmp(&y.0.min_element()))
                        .map_or(f64::INFINITY, |(w, p)| {
                            (surface_point(*p, w) - s.position).length()
                        })
                })
            })
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests;
