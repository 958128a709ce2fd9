//! The cost of a half-edge collapse in the progressive mesh: the largest texture deviation
//! it makes (Sander et al. 2001, after Cohen et al. 1998), the distance between the points
//! of the original surface and of the simplified one at the same chart coordinates.
//!
//! It is measured at samples of the original surface, each with its chart, chart
//! coordinates and position: every vertex of every chart and every triangle's centroid.
//! Each sample lies in one face of the current mesh (by its chart coordinates); a collapse
//! moves the samples of the faces it changes into the new faces and measures them there.
//! Collapses are refused that would flip a triangle in its chart (the parameterisation
//! stays one to one at every level), fold one over in space, move a vertex of the mesh's
//! boundary (a texture seam, whose other side is another vertex), move a chart corner, or
//! move a vertex of a chart boundary other than along that boundary.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use super::topology::Topology;
use crate::displace::simplify::HalfEdgeCost;

/// A point of the original surface where deviation is measured.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    /// The chart (parameterisation patch) the sample lies in.
    pub chart: u32,
    /// The sample's parameters in that chart.
    pub uv: DVec2,
    /// The sample's point on the original surface.
    pub position: DVec3,
}

/// The deviation cost and the samples' places (module documentation).
pub struct Deviation<'a> {
    topology: &'a Topology,
    chart_of: &'a [u32],
    uvs: &'a [HashMap<u32, DVec2>],
    samples: Vec<Sample>,
    /// The samples in each face (by stable face id).
    in_face: Vec<Vec<u32>>,
}

impl<'a> Deviation<'a> {
    /// The deviation measure of `topology`, whose faces lie in charts `chart_of` with per-chart
    /// vertex parameters `uvs`: places the samples in their faces.
    pub fn new(
        topology: &'a Topology,
        chart_of: &'a [u32],
        uvs: &'a [HashMap<u32, DVec2>],
    ) -> Deviation<'a> {
        let samples = samples(topology, chart_of, uvs);
        let mut in_face = vec![Vec::new(); topology.triangles.len()];
        for (i, (_, f)) in samples.iter().enumerate() {
            in_face[*f as usize].push(i as u32);
        }
        Deviation {
            topology,
            chart_of,
            uvs,
            samples: samples.into_iter().map(|(s, _)| s).collect(),
            in_face,
        }
    }

    /// The faces of `changed` that remain, with their chart-coordinate and space corners,
    /// or `None` when one would flip in its chart or fold over in space.
    fn new_faces(&self, changed: &[(u32, Vec<u32>)]) -> Option<Vec<Placed>> {
        let mut out = Vec::new();
        for (f, list) in changed {
            if list.is_empty() {
                continue;
            }
            let chart = self.chart_of[*f as usize];
            let uvs = &self.uvs[chart as usize];
            let uv = [uvs.get(&list[0])?, uvs.get(&list[1])?, uvs.get(&list[2])?].map(|p| *p);
            let area = (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]);
            if area <= 1e-14 {
                return None;
            }
            let p = [list[0], list[1], list[2]].map(|v| self.topology.positions[v as usize]);
            let normal = (p[1] - p[0]).cross(p[2] - p[0]);
            if normal.dot(self.topology.normals[*f as usize]) <= 0.0 {
                return None;
            }
            out.push(Placed {
                face: *f,
                chart,
                uv,
                position: p,
            });
        }
        Some(out)
    }

    /// Where sample `s` lands among `faces`: the face and the deviation there.
    fn place(&self, s: u32, faces: &[Placed]) -> Option<(u32, f64)> {
        let sample = &self.samples[s as usize];
        faces
            .iter()
            .filter(|p| p.chart == sample.chart)
            .map(|p| (p, barycentric(p.uv, sample.uv)))
            .max_by(|x, y| x.1.min_element().total_cmp(&y.1.min_element()))
            .map(|(p, w)| {
                let point = surface_point(p.position, w);
                (p.face, (point - sample.position).length())
            })
    }
}

/// A face of the mesh after a collapse, in its chart and in space.
struct Placed {
    face: u32,
    chart: u32,
    uv: [DVec2; 3],
    position: [DVec3; 3],
}

impl HalfEdgeCost for Deviation<'_> {
    fn cost(&self, a: u32, _b: u32, changed: &[(u32, Vec<u32>)], _: &[Vec<u32>]) -> Option<f64> {
        if self.topology.on_boundary(a) {
            return None;
        }
        let mut charts: Vec<u32> = changed
            .iter()
            .map(|(f, _)| self.chart_of[*f as usize])
            .collect();
        charts.sort_unstable();
        charts.dedup();
        match charts.len() {
            1 => {}
            2 => {
                // Along the boundary of the two charts: the edge's faces are one of each.
                let mut removed: Vec<u32> = changed
                    .iter()
                    .filter(|(_, l)| l.is_empty())
                    .map(|(f, _)| self.chart_of[*f as usize])
                    .collect();
                removed.sort_unstable();
                if removed.len() != 2 || removed[0] == removed[1] {
                    return None;
                }
            }
            _ => return None,
        }
        let faces = self.new_faces(changed)?;
        let mut worst = 0.0f64;
        for (f, _) in changed {
            for &s in &self.in_face[*f as usize] {
                worst = worst.max(self.place(s, &faces)?.1);
            }
        }
        Some(worst)
    }

    fn collapsed(&mut self, _a: u32, _b: u32, changed: &[(u32, Vec<u32>)], _: &[Vec<u32>]) {
        let faces = self.new_faces(changed).unwrap_or_default();
        let moving: Vec<u32> = changed
            .iter()
            .flat_map(|(f, _)| std::mem::take(&mut self.in_face[*f as usize]))
            .collect();
        for s in moving {
            // The cost found a place for every sample of these faces.
            if let Some((face, _)) = self.place(s, &faces) {
                self.in_face[face as usize].push(s);
            }
        }
    }
}

/// Every chart's vertices and every triangle's centroid, each with the face it starts in.
pub fn samples(
    topology: &Topology,
    chart_of: &[u32],
    uvs: &[HashMap<u32, DVec2>],
) -> Vec<(Sample, u32)> {
    let mut seen: HashMap<(u32, u32), ()> = HashMap::new();
    let mut out = Vec::new();
    for (f, t) in topology.triangles.iter().enumerate() {
        let chart = chart_of[f];
        let map = &uvs[chart as usize];
        let mut centre = (DVec2::ZERO, DVec3::ZERO);
        for &v in t {
            let (uv, position) = (map[&v], topology.positions[v as usize]);
            centre.0 += uv / 3.0;
            centre.1 += position / 3.0;
            if seen.insert((chart, v), ()).is_none() {
                out.push((
                    Sample {
                        chart,
                        uv,
                        position,
                    },
                    f as u32,
                ));
            }
        }
        out.push((
            Sample {
                chart,
                uv: centre.0,
                position: centre.1,
            },
            f as u32,
        ));
    }
    out
}

/// The barycentric weights of `p` in the triangle `uv` (negative outside).
pub fn barycentric(uv: [DVec2; 3], p: DVec2) -> glam::DVec3 {
    let (e1, e2, d) = (uv[1] - uv[0], uv[2] - uv[0], p - uv[0]);
    let det = e1.perp_dot(e2);
    let (b1, b2) = (d.perp_dot(e2) / det, e1.perp_dot(d) / det);
    DVec3::new(1.0 - b1 - b2, b1, b2)
}

/// The point of triangle `p` at weights `w`, clamped into the triangle (a sample just
/// outside its chart's shrunken outline is measured at the nearest place on its border).
pub fn surface_point(p: [DVec3; 3], w: DVec3) -> DVec3 {
    let w = w.max(DVec3::ZERO);
    let w = w / w.element_sum().max(f64::MIN_POSITIVE);
    p[0] * w.x + p[1] * w.y + p[2] * w.z
}
