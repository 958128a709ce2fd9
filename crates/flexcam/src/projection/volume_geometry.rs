//! A projection's viewing volume as geometry, for inspecting it in a 3D tool (the diagrams of
//! Brosz 2011): the control surfaces of a flexible volume as triangle meshes, a sample of
//! projectors as line segments, and the image's grid lines carried onto the volume, written
//! as Wavefront OBJ with an MTL library that gives each part its own material
//! (`flexcam volume`).
//!
//! - Control surfaces (flexible volumes only, [`crate::projection::flexible::Volume::control_surfaces`]):
//!   each sampled on a regular grid of its (u, v) domain [0, 1]^2, two triangles per cell;
//!   triangles of zero area are left out, so a near surface that is a point (the eye of a
//!   preset with near clip 0) or a line (a slit) has none and is not written.
//! - Projectors: those of an evenly spaced grid of image positions, edges included, as
//!   polylines: a flexible projector over its whole t in [0, 1] (straight, polyline, or a
//!   quadratic Bezier in [`CURVE_STEPS`] steps); the unbounded rays of the other
//!   projections from their start to the distance `reach`. A position without a projector
//!   (outside a fisheye's circle) is skipped.
//! - The image grid: the image's rows and columns at `grid_cells` equal steps, each line
//!   followed in [`GRID_LINE_STEPS`] steps per cell and carried to the point at fraction
//!   `grid_at` along each projector (the volume's Q(u, v, t) at t = `grid_at` for a flexible
//!   volume; the distance `grid_at` x `reach` along other rays); a line breaks where the
//!   image has no projector.
//!
//! Lines are written as OBJ `l` elements of two vertices each (every OBJ reader takes
//! those; readers that triangulate, flexcam's own included, would read longer `l` runs as
//! faces), or, with [`VolumeGeometry::with_tubes`], as thin square tubes of triangles that
//! any renderer draws.

use std::fmt::Write;

use glam::{DVec2, DVec3};

use super::{Projection, Projector};
use crate::error::{Error, Result};

/// Steps a quadratic Bezier projector is drawn in.
pub const CURVE_STEPS: usize = 32;

/// Steps per grid cell in which a line of the image grid is followed.
pub const GRID_LINE_STEPS: u32 = 16;

/// The largest sample counts the options take (bounded output: about 10^6 vertices).
pub const MAX_SAMPLES: u32 = 256;

/// What of the volume to sample, and how finely.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeOptions {
    /// Projectors drawn across and down the image: `n` x `n`, 1 to [`MAX_SAMPLES`].
    pub projectors: u32,
    /// Cells along each side of a control surface's mesh, 1 to [`MAX_SAMPLES`].
    pub surface_steps: u32,
    /// Cells of the image grid along each side, 1 to [`MAX_SAMPLES`].
    pub grid_cells: u32,
    /// Where along the projectors the image grid lies, in [0, 1]; `None`: a flexible
    /// volume's near surface, or its far surface when the near one has no area (a point or
    /// a line), and 1/5 of the way along the rays of other projections.
    pub grid_at: Option<f64>,
    /// How far the unbounded rays of projections other than flexible volumes are drawn,
    /// world units (finite and positive).
    pub reach: f64,
}

/// Which part of the volume a [`Part`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartKind {
    /// A control surface (triangles).
    ControlSurface,
    /// The sampled projectors (segments).
    Projectors,
    /// The image grid carried onto the volume (segments).
    ImageGrid,
}

/// One part of the volume's geometry: its own OBJ object and material.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The OBJ object's and material's name (`near_surface`, `surface_2`, ...,
    /// `far_surface`, `projectors`, `image_grid`).
    pub name: String,
    /// What the part is.
    pub kind: PartKind,
    /// The material's diffuse colour (linear RGB).
    pub colour: [f32; 3],
    /// Vertex positions, world units.
    pub points: Vec<DVec3>,
    /// Triangles, indices into `points`.
    pub triangles: Vec<[usize; 3]>,
    /// Line segments, indices into `points`.
    pub segments: Vec<[usize; 2]>,
}

impl Part {
    fn new(name: String, kind: PartKind, colour: [f32; 3]) -> Part {
        Part {
            name,
            kind,
            colour,
            points: Vec::new(),
            triangles: Vec::new(),
            segments: Vec::new(),
        }
    }

    /// Appends the polyline through `points` as segments (nothing for fewer than two).
    fn add_polyline(&mut self, points: &[DVec3]) {
        if points.len() < 2 {
            return;
        }
        let base = self.points.len();
        self.points.extend_from_slice(points);
        self.segments
            .extend((1..points.len()).map(|k| [base + k - 1, base + k]));
    }

    /// The triangles' total area.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|&[a, b, c]| {
                let (a, b, c) = (self.points[a], self.points[b], self.points[c]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Whether the part has anything to draw.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty() && self.segments.is_empty()
    }
}

/// A projection's viewing volume as geometry (see the module).
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeGeometry {
    /// Control surfaces near to far, then the projectors, then the image grid. A control
    /// surface without area is kept, empty, so that a caller can say so.
    pub parts: Vec<Part>,
}

const NEAR_COLOUR: [f32; 3] = [0.25, 0.45, 0.95];
const INNER_COLOUR: [f32; 3] = [0.65, 0.4, 0.85];
const FAR_COLOUR: [f32; 3] = [0.95, 0.6, 0.2];
const PROJECTOR_COLOUR: [f32; 3] = [0.85, 0.1, 0.1];
const GRID_COLOUR: [f32; 3] = [0.1, 0.75, 0.25];

/// Relative area under which a near surface counts as a point or a line (for the image
/// grid's default place).
const NO_AREA: f64 = 1e-9;

/// The share of the way along the rays of non-flexible projections where the image grid
/// lies by default.
const RAY_GRID_AT: f64 = 0.2;

impl VolumeGeometry {
    /// The geometry of `projection`'s volume. Errors: a sample count outside 1 to
    /// [`MAX_SAMPLES`], `grid_at` outside [0, 1], a `reach` that is not finite and
    /// positive, and a projection with no projector at any sampled position.
    pub fn of(projection: &dyn Projection, options: &VolumeOptions) -> Result<Self> {
        check_options(options)?;
        let mut parts = control_surfaces(projection, options.surface_steps);
        let grid_at = options.grid_at.unwrap_or_else(|| match &parts[..] {
            [] => RAY_GRID_AT,
            [near, .., far] if near.area() <= NO_AREA * far.area() => 1.0,
            _ => 0.0,
        });
        let projectors = projectors(projection, options);
        if projectors.is_empty() {
            return Err(Error::new(format!(
                "no projector at any of the {0} x {0} sampled image positions",
                options.projectors
            )));
        }
        parts.push(projectors);
        parts.push(image_grid(projection, options, grid_at));
        Ok(VolumeGeometry { parts })
    }

    /// The geometry with every segment replaced by a square tube of `radius` (four sides of
    /// two triangles, open ends) around it, so that renderers that draw only triangles show
    /// the lines. Zero-length segments are dropped. Errors: a radius that is not finite and
    /// positive.
    pub fn with_tubes(&self, radius: f64) -> Result<Self> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::new(format!(
                "the tube radius must be finite and positive, got {radius}"
            )));
        }
        let parts = self
            .parts
            .iter()
            .map(|part| {
                // The lines' own vertices go with them; a part with triangles keeps its.
                let mut tubes = Part {
                    points: if part.triangles.is_empty() {
                        Vec::new()
                    } else {
                        part.points.clone()
                    },
                    segments: Vec::new(),
                    ..part.clone()
                };
                for &[a, b] in &part.segments {
                    add_tube(&mut tubes, part.points[a], part.points[b], radius);
                }
                tubes
            })
            .collect();
        Ok(VolumeGeometry { parts })
    }

    /// The OBJ text: a comment line per `header` line, `mtllib mtl_name`, then per non-empty
    /// part an object `o NAME` with `usemtl NAME`, its vertices, faces and `l` segments.
    pub fn obj(&self, header: &[String], mtl_name: &str) -> String {
        let mut text = String::new();
        for line in header {
            let _ = writeln!(text, "# {line}");
        }
        let _ = writeln!(text, "mtllib {mtl_name}");
        let mut base = 1;
        for part in self.parts.iter().filter(|p| !p.is_empty()) {
            let _ = writeln!(text, "o {0}\nusemtl {0}", part.name);
            for p in &part.points {
                let _ = writeln!(text, "v {} {} {}", p.x, p.y, p.z);
            }
            for t in &part.triangles {
                let _ = writeln!(text, "f {} {} {}", t[0] + base, t[1] + base, t[2] + base);
            }
            for s in &part.segments {
                let _ = writeln!(text, "l {} {}", s[0] + base, s[1] + base);
            }
            base += part.points.len();
        }
        text
    }

    /// The MTL text: a material per non-empty part, its colour as `Kd`; the surfaces half
    /// transparent (`d 0.5`) for the tools that show it, the lines also emitting their
    /// colour (`Ke`), so that they show unlit (flexcam renders `Ke` as an emitter).
    pub fn mtl(&self) -> String {
        let mut text = String::new();
        for part in self.parts.iter().filter(|p| !p.is_empty()) {
            let [r, g, b] = part.colour;
            let _ = writeln!(text, "newmtl {}\nKd {r} {g} {b}", part.name);
            match part.kind {
                PartKind::ControlSurface => text.push_str("d 0.5\n"),
                PartKind::Projectors | PartKind::ImageGrid => {
                    let _ = writeln!(text, "Ke {r} {g} {b}");
                }
            }
        }
        text
    }
}

fn check_options(options: &VolumeOptions) -> Result<()> {
    for (name, n) in [
        ("projectors", options.projectors),
        ("surface steps", options.surface_steps),
        ("grid cells", options.grid_cells),
    ] {
        if !(1..=MAX_SAMPLES).contains(&n) {
            return Err(Error::new(format!(
                "{name} must be 1 to {MAX_SAMPLES}, got {n}"
            )));
        }
    }
    if let Some(at) = options.grid_at {
        if !(0.0..=1.0).contains(&at) {
            return Err(Error::new(format!(
                "the image grid's place along the projectors must be in [0, 1], got {at}"
            )));
        }
    }
    if !(options.reach.is_finite() && options.reach > 0.0) {
        return Err(Error::new(format!(
            "the reach of the rays must be finite and positive, got {}",
            options.reach
        )));
    }
    Ok(())
}

/// The control surfaces of a flexible volume as meshes (none for other projections).
fn control_surfaces(projection: &dyn Projection, steps: u32) -> Vec<Part> {
    let Some(flexible) = projection.flexible() else {
        return Vec::new();
    };
    let surfaces = flexible.volume().control_surfaces();
    let last = surfaces.len() - 1;
    let n = steps as usize;
    surfaces
        .iter()
        .enumerate()
        .map(|(i, surface)| {
            let (name, colour) = match i {
                0 => ("near_surface".to_string(), NEAR_COLOUR),
                i if i == last => ("far_surface".to_string(), FAR_COLOUR),
                i => (format!("surface_{}", i + 1), INNER_COLOUR),
            };
            let mut part = Part::new(name, PartKind::ControlSurface, colour);
            for row in 0..=n {
                for col in 0..=n {
                    let uv = DVec2::new(col as f64, row as f64) / n as f64;
                    part.points.push(surface.point(uv));
                }
            }
            let index = |col: usize, row: usize| row * (n + 1) + col;
            for row in 0..n {
                for col in 0..n {
                    let corners = [
                        index(col, row),
                        index(col + 1, row),
                        index(col + 1, row + 1),
                        index(col, row + 1),
                    ];
                    for t in [
                        [corners[0], corners[1], corners[2]],
                        [corners[0], corners[2], corners[3]],
                    ] {
                        let [a, b, c] = t.map(|k| part.points[k]);
                        if (b - a).cross(c - a) != DVec3::ZERO {
                            part.triangles.push(t);
                        }
                    }
                }
            }
            part
        })
        .collect()
}

/// `count` evenly spaced positions over [0, `size`], both ends included (the middle for 1).
fn spaced(count: u32, size: u32) -> impl Iterator<Item = f64> {
    let size = f64::from(size);
    (0..count).map(move |i| match count {
        1 => 0.5 * size,
        _ => size * f64::from(i) / f64::from(count - 1),
    })
}

/// The sampled projectors as polylines.
fn projectors(projection: &dyn Projection, options: &VolumeOptions) -> Part {
    let (w, h) = projection.resolution();
    let mut part = Part::new(
        "projectors".to_string(),
        PartKind::Projectors,
        PROJECTOR_COLOUR,
    );
    for y in spaced(options.projectors, h) {
        for x in spaced(options.projectors, w) {
            if let Some(projector) = projection.projector(DVec2::new(x, y)) {
                part.add_polyline(&drawn(&projector, options.reach));
            }
        }
    }
    part
}

/// The end of an unbounded straight ray's drawn part: `reach` along its direction.
fn ray_end(ray: &crate::geometry::Ray, reach: f64) -> f64 {
    if ray.t_max.is_finite() {
        ray.t_max
    } else {
        ray.t_min + reach / ray.direction.length()
    }
}

/// The points `projector` is drawn through.
fn drawn(projector: &Projector, reach: f64) -> Vec<DVec3> {
    match projector {
        Projector::Straight(ray) => vec![ray.at(ray.t_min), ray.at(ray_end(ray, reach))],
        Projector::Polyline(points) => points.clone(),
        Projector::QuadraticBezier(_) => (0..=CURVE_STEPS)
            .map(|k| along(projector, k as f64 / CURVE_STEPS as f64, reach))
            .collect(),
    }
}

/// The point at fraction `s` in [0, 1] of `projector`'s drawn part: of a straight ray's
/// parameter range, of a Bezier's parameter, of a polyline's vertex run.
fn along(projector: &Projector, s: f64, reach: f64) -> DVec3 {
    match projector {
        Projector::Straight(ray) => ray.at(ray.t_min + s * (ray_end(ray, reach) - ray.t_min)),
        Projector::QuadraticBezier([a, b, c]) => {
            let (ab, bc) = (a.lerp(*b, s), b.lerp(*c, s));
            ab.lerp(bc, s)
        }
        Projector::Polyline(points) => {
            let x = s * (points.len() - 1) as f64;
            let k = (x.floor() as usize).min(points.len().saturating_sub(2));
            points[k].lerp(points[(k + 1).min(points.len() - 1)], x - k as f64)
        }
    }
}

/// The image grid carried to fraction `grid_at` along the projectors.
fn image_grid(projection: &dyn Projection, options: &VolumeOptions, grid_at: f64) -> Part {
    let (w, h) = projection.resolution();
    let cells = options.grid_cells;
    let steps = cells * GRID_LINE_STEPS;
    let at = |pixel: DVec2| match projection.flexible() {
        Some(flexible) => flexible.point(pixel, grid_at),
        None => projection
            .projector(pixel)
            .map(|p| along(&p, grid_at, options.reach)),
    };
    let mut part = Part::new("image_grid".to_string(), PartKind::ImageGrid, GRID_COLOUR);
    let lines = spaced(cells + 1, w)
        .map(|x| (x, true))
        .chain(spaced(cells + 1, h).map(|y| (y, false)));
    for (fixed, vertical) in lines {
        let length = if vertical { h } else { w };
        let mut run = Vec::new();
        for s in spaced(steps + 1, length) {
            let pixel = if vertical {
                DVec2::new(fixed, s)
            } else {
                DVec2::new(s, fixed)
            };
            match at(pixel) {
                Some(p) => run.push(p),
                None => {
                    part.add_polyline(&run);
                    run.clear();
                }
            }
        }
        part.add_polyline(&run);
    }
    part
}

/// Appends a square tube of `radius` around the segment from `a` to `b` to `part`.
fn add_tube(part: &mut Part, a: DVec3, b: DVec3, radius: f64) {
    let axis = b - a;
    if axis == DVec3::ZERO || !axis.is_finite() {
        return;
    }
    let unit = axis.normalize();
    let e1 = unit.any_orthonormal_vector() * radius;
    let e2 = unit.cross(e1);
    let base = part.points.len();
    let corners = [e1, e2, -e1, -e2];
    for end in [a, b] {
        part.points.extend(corners.iter().map(|c| end + *c));
    }
    for k in 0..4 {
        let (i, j) = (base + k, base + (k + 1) % 4);
        part.triangles.push([i, j, j + 4]);
        part.triangles.push([i, j + 4, i + 4]);
    }
}

#[cfg(test)]
mod tests;
