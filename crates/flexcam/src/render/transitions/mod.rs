//! Shading by the transition system (Becker and Max 1993; Ramsey 2005, chapter 7): each ray
//! that meets a displaced object is shaded by full displacement, redistributed bump mapping
//! or the surface's BRDF, or a blend of two, as the transition function chooses from the
//! ray's own footprint and view angle ([`crate::displace::transition`], [`footprint`]).
//! `--shading transition-lit` shows the result; `--shading transitions` colours each pixel
//! by the methods chosen (red BRDF, blue redistributed bump, green displacement, mixed in
//! the blends), as the dissertation's figures do.
//!
//! A ray is first traced with the displaced objects undisplaced (their base triangles are
//! the outer hull of the displaced surface); at a hull hit the transition function decides,
//! and where it asks for (partial) displacement the ray is traced again with the displaced
//! objects displaced by that fraction, and may pass through to what lies behind. Only the
//! rays that need the displaced surface pay for it. Other objects are shaded as by `lit`
//! (their colour map shows their lit shading in grey). Primary projectors only: mirrors
//! and glass see displaced objects fully displaced, by lit shading. Straight and polyline
//! projectors; quadratic ones are refused.

mod footprint;
mod shade;

use std::time::Instant;

use glam::{DVec2, DVec3, Vec3};

use crate::displace::progressive::LOD_PERCENTS;
use crate::displace::transition::Blend;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::geometry::Ray;
use crate::projection::{Projection, Projector};
use crate::render::displaced::{LodSelection, ObjectTables, TransitionData};
use crate::render::prepared::PreparedScene;
use crate::render::raycast::pieces::polyline_segment;
use crate::render::raycast::SamplePattern;
use crate::render::shading::trace::HitShader;
use crate::render::{frame_name, Counter, Frame, RenderOptions, Shading, Stats};
use crate::try_alloc;

/// What `--shading transitions` and `transition-lit` show, and the transition function's
/// user constant `D` (see [`crate::displace::transition`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TransitionShading {
    /// Colour by method (`transitions`) rather than the lit image (`transition-lit`).
    pub methods: bool,
    d_bits: u64,
    /// How rays that displace pick the level of detail they trace.
    pub lod: LodSelection,
    /// The method every ray on a displaced object takes: the transition function's choice,
    /// or one method forced everywhere (the rows of the dissertation's Table 8.1).
    pub method: TransitionMethod,
}

/// Which method shades the rays that meet a displaced object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TransitionMethod {
    /// The transition function's choice per ray (its blends included).
    #[default]
    Auto,
    /// Full displacement everywhere.
    Displacement,
    /// Redistributed bump mapping everywhere: the undisplaced surface with the bump normals
    /// redistributed to the displaced surface's visible normals (Becker and Max).
    RedistributedBump,
    /// Plain bump mapping everywhere: the undisplaced surface with the height field's own
    /// normals, not redistributed (what redistribution corrects at grazing views).
    Bump,
    /// The BRDF table everywhere, on the undisplaced surface.
    Brdf,
}

impl TransitionMethod {
    /// The blend a forced method gives every ray; `None` for [`TransitionMethod::Auto`].
    fn forced_blend(self) -> Option<Blend> {
        let (brdf, bump, displacement) = match self {
            TransitionMethod::Auto => return None,
            TransitionMethod::Displacement => (0.0, 0.0, 1.0),
            TransitionMethod::RedistributedBump | TransitionMethod::Bump => (0.0, 1.0, 0.0),
            TransitionMethod::Brdf => (1.0, 0.0, 0.0),
        };
        Some(Blend {
            brdf,
            bump,
            displacement,
            fraction: displacement,
        })
    }
}

impl TransitionShading {
    /// The default `D`: relief of 3 footprints or more seen head on is displaced; below 1
    /// footprint of relief the bumps' width decides between bump mapping and the BRDF.
    pub const DEFAULT_D: f64 = 2.0;

    /// Errors: a `d` that is not finite.
    pub fn new(methods: bool, d: f64) -> Result<TransitionShading> {
        if !d.is_finite() {
            return Err(Error::new(format!(
                "--transition-d must be finite, not {d}"
            )));
        }
        Ok(TransitionShading {
            methods,
            d_bits: d.to_bits(),
            lod: LodSelection::default(),
            method: TransitionMethod::default(),
        })
    }

    /// With the default `D`.
    pub fn with_default_d(methods: bool) -> TransitionShading {
        TransitionShading {
            methods,
            d_bits: Self::DEFAULT_D.to_bits(),
            lod: LodSelection::default(),
            method: TransitionMethod::default(),
        }
    }

    /// `D`.
    pub fn d(self) -> f64 {
        f64::from_bits(self.d_bits)
    }

    /// With level-of-detail selection `lod`.
    pub fn with_lod(self, lod: LodSelection) -> TransitionShading {
        TransitionShading { lod, ..self }
    }

    /// With method `method` on displaced objects.
    pub fn with_method(self, method: TransitionMethod) -> TransitionShading {
        TransitionShading { method, ..self }
    }
}

/// One render's state in a worker: the scene, the tables and levels of detail, the shader
/// of other objects and the counts.
struct Renderer<'a> {
    prepared: &'a PreparedScene,
    projection: &'a dyn Projection,
    /// `None` when the scene has no displaced objects.
    data: Option<&'a TransitionData>,
    lit: HitShader<'a>,
    d: f64,
    methods: bool,
    lod: LodSelection,
    method: TransitionMethod,
    /// Samples that traced each level of detail (displacing ones only).
    levels: [u64; LOD_PERCENTS.len()],
    primary_rays: u64,
    partial_rays: u64,
    shadow_rays: u64,
    /// Summed method weights of the samples on displaced objects: BRDF, bump, displacement.
    weights: DVec3,
}

/// The statistics keys of the samples that traced each level of detail.
const LEVEL_KEYS: [&str; LOD_PERCENTS.len()] = [
    "lod_100_samples",
    "lod_80_samples",
    "lod_60_samples",
    "lod_40_samples",
    "lod_20_samples",
];

/// One sample: colour, depth, object id.
type Sample = (Vec3, f32, u32);

impl<'a> Renderer<'a> {
    /// The tables of object `object`, if it is displaced.
    fn tables(&self, object: usize) -> Option<&'a ObjectTables> {
        self.data?.tables.get(object)
    }

    fn sample(&mut self, pixel: DVec2) -> Sample {
        let background = (self.prepared.scene.image.background, f32::INFINITY, 0);
        self.primary_rays += 1;
        match self.projection.projector(pixel) {
            Some(Projector::Straight(ray)) => match self.prepared.intersect_hull(&ray) {
                Some(hit) => self.shade(&ray, hit, 0.0, pixel),
                None => background,
            },
            Some(Projector::Polyline(points)) => {
                let mut before = 0.0;
                for k in 0..points.len().saturating_sub(1) {
                    let ray = polyline_segment(&points, k);
                    if let Some(hit) = self.prepared.intersect_hull(&ray) {
                        return self.shade(&ray, hit, before, pixel);
                    }
                    before += ray.direction.length();
                }
                background
            }
            _ => background,
        }
    }

    /// The sample of `ray` (after `before` of its projector) whose hull hit is `hit`.
    fn shade(
        &mut self,
        ray: &Ray,
        hit: crate::render::prepared::Hit,
        before: f64,
        pixel: DVec2,
    ) -> Sample {
        let id = |index: usize| self.prepared.scene.objects[index].id;
        let depth = |t: f64| (before + t * ray.direction.length()) as f32;
        if self.tables(hit.object).is_none() {
            let color = self.lit.shade_hit(ray, hit);
            let color = if self.methods {
                Vec3::splat(0.5 * color.dot(Vec3::new(0.2126, 0.7152, 0.0722)))
            } else {
                color
            };
            return (color, depth(hit.t), id(hit.object));
        }
        let shaded = self.shade_displaced(ray, hit, pixel);
        let b = shaded.blend;
        self.weights += DVec3::new(b.brdf, b.bump, b.displacement);
        let Some(hit) = shaded.hit else {
            return (self.prepared.scene.image.background, f32::INFINITY, 0);
        };
        let color = if self.methods {
            Vec3::new(b.brdf as f32, b.displacement as f32, b.bump as f32)
        } else {
            shaded.color
        };
        (color, depth(hit.t), id(hit.object))
    }
}

/// Renders `projection` with displaced objects shaded by the transition system (module
/// docs). Errors: a projection with quadratic projectors; memory that cannot be had for the
/// frame or its rows of samples (module `try_alloc`).
pub(in crate::render) fn render(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
    shading: TransitionShading,
) -> Result<(Frame, Stats)> {
    let (width, height) = projection.resolution();
    let centre = DVec2::new(width as f64 / 2.0, height as f64 / 2.0);
    if let Some(Projector::QuadraticBezier(_)) = projection.projector(centre) {
        return Err(Error::new(
            "--shading transitions and transition-lit trace straight or polyline projectors \
             only, not quadratic ones",
        ));
    }
    // Built once per prepared scene, on its first transition render.
    let start = Instant::now();
    let data = prepared
        .displaced
        .as_ref()
        .map(|set| set.transition_data(&prepared.scene));
    let table_ms = start.elapsed().as_secs_f64() * 1e3;
    // The frame first: a frame whose memory cannot be had fails before any work.
    let mut frame = Frame::zeroed(width, height, options.outputs)?;
    let pattern = SamplePattern::new(options.spp);
    let lit_options = RenderOptions {
        shading: Shading::Lit,
        ..*options
    };
    type Row = (Vec<Sample>, [u64; 4], DVec3, [u64; LOD_PERCENTS.len()]);
    let rows: Vec<Row> = (0..height)
        .into_par_iter()
        .map(|y| {
            let mut renderer = Renderer {
                prepared,
                projection,
                data,
                lit: HitShader::new(prepared, &lit_options),
                d: shading.d(),
                methods: shading.methods,
                lod: shading.lod,
                method: shading.method,
                levels: [0; LOD_PERCENTS.len()],
                primary_rays: 0,
                partial_rays: 0,
                shadow_rays: 0,
                weights: DVec3::ZERO,
            };
            let scale = 1.0 / pattern.offsets.len() as f32;
            let mut samples = Vec::new();
            try_alloc::reserve(&mut samples, width as usize, || {
                format!("a row of samples of {}", frame_name(width, height))
            })?;
            samples.extend((0..width).map(|x| {
                let mut color = Vec3::ZERO;
                let mut centre = (Vec3::ZERO, f32::INFINITY, 0);
                for (k, offset) in pattern.offsets.iter().enumerate() {
                    let sample = renderer.sample(DVec2::new(x as f64, y as f64) + *offset);
                    color += sample.0;
                    if k == pattern.centre {
                        centre = sample;
                    }
                }
                (color * scale, centre.1, centre.2)
            }));
            let counts = renderer.lit.counts;
            Ok((
                samples,
                [
                    renderer.primary_rays,
                    renderer.partial_rays,
                    renderer.shadow_rays + counts.shadow,
                    counts.secondary,
                ],
                renderer.weights,
                renderer.levels,
            ))
        })
        .collect::<Result<_>>()?;
    let mut totals = [0u64; 4];
    let mut weights = DVec3::ZERO;
    let mut levels = [0u64; LOD_PERCENTS.len()];
    for (y, (samples, counts, w, l)) in rows.into_iter().enumerate() {
        for (x, (color, depth, id)) in samples.into_iter().enumerate() {
            let i = y * width as usize + x;
            frame.color[i] = color;
            if let Some(d) = frame.depth.get_mut(i) {
                *d = depth;
            }
            if let Some(d) = frame.ids.get_mut(i) {
                *d = id;
            }
        }
        for (t, c) in totals.iter_mut().zip(counts) {
            *t += c;
        }
        weights += w;
        for (t, c) in levels.iter_mut().zip(l) {
            *t += c;
        }
    }
    let mut stats = Stats::from([
        ("primary_rays", Counter::Count(totals[0])),
        ("partial_displacement_rays", Counter::Count(totals[1])),
        ("shadow_rays", Counter::Count(totals[2])),
        ("secondary_rays", Counter::Count(totals[3])),
        ("transition_table_ms", Counter::Value(table_ms)),
        ("transition_brdf_weight", Counter::Value(weights.x)),
        ("transition_bump_weight", Counter::Value(weights.y)),
        ("transition_displacement_weight", Counter::Value(weights.z)),
    ]);
    for (key, count) in LEVEL_KEYS.into_iter().zip(levels) {
        stats.insert(key, Counter::Count(count));
    }
    if let Some(data) = data {
        stats.insert(
            "lod_failures",
            Counter::Count(data.lods.failures.len() as u64),
        );
    }
    Ok((frame, stats))
}

#[cfg(test)]
mod tests;
