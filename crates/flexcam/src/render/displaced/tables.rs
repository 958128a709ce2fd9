//! What the transition system (`render::transitions`) precomputes per displaced object: the
//! chart of its height field, its normal distribution, BRDF and redistribution tables
//! (module [`crate::displace`]), and its partial displacements.
//!
//! The chart is one for the whole object: the height field over one uv period laid flat at
//! the object's mean world size of that period (the area-weighted means of `|dP/du|` and
//! `|dP/dv|` over its base triangles), on [`CHART_CELLS`] x [`CHART_CELLS`] nodes. Where a
//! base triangle's own metric differs (the inner and outer rings of a torus), its bump
//! normals are steeper or flatter than the chart's; the redistribution still maps them
//! through the chart's distribution (an approximation, as any single table per surface is).
//! An object whose uvs give no metric (all triangles degenerate in uv) gets a flat chart.

use std::sync::OnceLock;

use glam::DVec2;

use super::DisplacedSet;
use crate::displace::brdf_table::BrdfTable;
use crate::displace::bump::Redistribution;
use crate::displace::normal_distribution::{Chart, NormalDistribution};
use crate::displace::Displacement;
use crate::scene::{Object, Scene};

/// Chart nodes per side.
const CHART_CELLS: usize = 128;
/// Rays per side per view azimuth and view angle for the normal distributions.
const RAYS: usize = 24;
/// Partial displacement is traced at fractions `k / PARTIAL_STEPS` of the object's (`k` the
/// nearest to the ray's `s`): a step moves the surface by 1/64 of its relief, under a tenth
/// of a pixel footprint wherever partial displacement is chosen (relief below 3 footprints
/// at `T < 1` with the default `D`).
pub(in crate::render) const PARTIAL_STEPS: usize = 64;

/// The tables of one displaced object.
pub(in crate::render) struct ObjectTables {
    pub chart: Chart,
    pub redistribution: Redistribution,
    pub brdf: BrdfTable,
    wavelength: f64,
    full: Displacement,
    partial: Vec<OnceLock<Displacement>>,
}

impl ObjectTables {
    fn new(object: &Object, displacement: &Displacement) -> ObjectTables {
        let scale = displacement.scale() * displacement.fraction();
        let height = displacement.height();
        let chart = mean_period_size(object)
            .and_then(|size| Chart::new(height, scale, size, CHART_CELLS).ok())
            .or_else(|| Chart::new(height, 0.0, DVec2::ONE, CHART_CELLS).ok())
            .expect("a chart of positive size and zero scale is valid");
        let distribution = NormalDistribution::new(&chart, RAYS);
        ObjectTables {
            redistribution: Redistribution::new(&distribution),
            brdf: BrdfTable::new(&distribution),
            wavelength: chart.wavelength(),
            chart,
            full: displacement.clone(),
            partial: (0..=PARTIAL_STEPS).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Highest minus lowest displacement (world units).
    pub fn relief(&self) -> f64 {
        self.chart.relief()
    }

    /// The bumps' mean wavelength (world units, [`Chart::wavelength`]), computed with the
    /// chart.
    pub fn wavelength(&self) -> f64 {
        self.wavelength
    }

    /// The object's displacement at fraction `step / PARTIAL_STEPS` of its own, made on
    /// first use.
    pub fn partial(&self, step: usize) -> &Displacement {
        self.partial[step].get_or_init(|| {
            self.full
                .with_fraction(self.full.fraction() * step as f64 / PARTIAL_STEPS as f64)
        })
    }
}

/// The tables of every displaced object of a prepared scene (by object index).
pub(in crate::render) struct Tables {
    objects: Vec<Option<ObjectTables>>,
}

impl Tables {
    pub fn new(scene: &Scene, set: &DisplacedSet) -> Tables {
        let objects = scene
            .objects
            .iter()
            .enumerate()
            .map(|(index, object)| {
                let displacement = set.displacement(index)?;
                Some(ObjectTables::new(object, displacement))
            })
            .collect();
        Tables { objects }
    }

    /// The tables of object `object`, if it is displaced.
    pub fn get(&self, object: usize) -> Option<&ObjectTables> {
        self.objects[object].as_ref()
    }
}

/// The area-weighted means of `|dP/du|` and `|dP/dv|` over the triangles of `object` (world
/// units per uv unit); `None` when no triangle has a uv metric.
fn mean_period_size(object: &Object) -> Option<DVec2> {
    let mesh = &object.mesh;
    let mut sum = DVec2::ZERO;
    let mut weight = 0.0;
    for triangle in &mesh.triangles {
        let [a, b, c] = triangle.map(|i| i as usize);
        let (p0, p1, p2) = (
            mesh.positions[a].as_dvec3(),
            mesh.positions[b].as_dvec3(),
            mesh.positions[c].as_dvec3(),
        );
        let (t0, t1, t2) = (
            mesh.uvs[a].as_dvec2(),
            mesh.uvs[b].as_dvec2(),
            mesh.uvs[c].as_dvec2(),
        );
        let (e1, e2) = (p1 - p0, p2 - p0);
        let (d1, d2) = (t1 - t0, t2 - t0);
        let det = d1.x * d2.y - d2.x * d1.y;
        let area = e1.cross(e2).length() * 0.5;
        if det == 0.0 || !det.is_finite() || area == 0.0 {
            continue;
        }
        let du = (e1 * d2.y - e2 * d1.y) / det;
        let dv = (e2 * d1.x - e1 * d2.x) / det;
        sum += DVec2::new(du.length(), dv.length()) * area;
        weight += area;
    }
    (weight > 0.0)
        .then(|| sum / weight)
        .filter(|s| s.is_finite())
}
