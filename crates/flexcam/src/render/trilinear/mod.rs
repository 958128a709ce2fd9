//! `--method trilinear`: the fast renderer of trilinear projections (seed 000, chapters 4
//! and 5). Instead of casting a ray per pixel it projects the scene into each projection
//! triangle and rasterises the result; docs/trilinear.md has the design and measurements.
//!
//! Per projection triangle (in parallel), [`polygons`]: scene triangles beyond a bounding
//! plane of the triangle's ray volume are culled ([`volume_bounds`]), each remaining scene
//! vertex is projected once (its cubic), pairs whose images cannot be visible are culled, each scene triangle is cut into
//! shapes (`projection::project_solved_triangle`), each shape's curved edges are sampled along
//! the exact images of their scene edges ([`edge_path`], [`outline`], by the [`curves`]
//! mode), with exact anchors at the view plane and at the projection triangle's edge surfaces,
//! and the outline is clipped ([`clip`]) and mapped to pixels ([`screen_map`]), each vertex
//! carrying the terms of its projector's hit with the scene triangle's plane that are affine
//! in pixel position ([`hit_terms`]). All polygons are then rasterised (`render::raster`,
//! non-zero fill, z-buffer), every fragment finished to its exact hit from its interpolated
//! terms before its z-test, and each pixel's winner shaded once ([`shade`]).
//!
//! Unprojectable pairs (see `projection::Unprojectable`) are counted and their projection
//! triangle is ray cast instead, so they never silently vanish.

pub mod clip;
#[cfg(test)]
mod cull_tests;
pub mod cull_tree;
pub mod curves;
pub mod edge_path;
pub mod hit_terms;
pub mod outline;
pub mod pair_cull;
pub mod polygons;
pub mod scene_geometry;
pub mod screen_map;
pub mod shade;
#[cfg(test)]
mod tests;
pub mod volume_bounds;
pub mod workloads;

use std::time::Instant;

use glam::{DVec2, Vec3};

pub use curves::{CurveMode, CurveOptions};

use self::polygons::{project_all, projection_triangles, ProjectedScene};
use self::scene_geometry::SceneGeometry;
use self::screen_map::ScreenMap;
use self::shade::{stored_barycentrics, Resolver, ShadeCounts, Shader};
use crate::error::{Error, Result};
use crate::projection::{Projection, Trilinear};
use crate::render::raster::{
    band_rows_for, new_frame, rasterize_into_frame, FillRule, RasterStats,
};
use crate::render::raycast::{RayCaster, SamplePattern};
use crate::render::{Counter, Frame, RenderOptions, Stats};
use crate::scene::Scene;

/// A scene prepared for trilinear rendering: its triangles in f64 and the ray caster used
/// for shading (shadows, mirrors, glass) and for fallback pixels, built once.
pub struct TrilinearRenderer {
    scene: SceneGeometry,
    caster: RayCaster,
    background: Vec3,
}

impl TrilinearRenderer {
    pub fn new(scene: &Scene) -> TrilinearRenderer {
        TrilinearRenderer {
            scene: SceneGeometry::new(scene),
            caster: RayCaster::new(scene),
            background: scene.image.background,
        }
    }

    /// Renders the scene through `projection` with `curves`. With `options.spp` samples
    /// per pixel (0 counts as 1) the polygons are projected once and rasterised, resolved
    /// and shaded once per sample of the ray caster's pattern (`SamplePattern`): the pixel
    /// averages its samples' colours and reports the depth and id of the sample nearest its
    /// centre, as the ray caster does. Errors: a mesh of more than 2^32 projection triangles
    /// or a scene of more than 2^32 triangles (the fragment keys).
    pub fn render(
        &self,
        projection: &Trilinear,
        options: &RenderOptions,
        curves: CurveOptions,
    ) -> Result<(Frame, Stats)> {
        let mesh = projection.mesh();
        if u32::try_from(mesh.triangles.len()).is_err()
            || u32::try_from(self.scene.triangles.len()).is_err()
        {
            return Err(Error::new(
                "the trilinear method handles at most 2^32 projection and scene triangles",
            ));
        }
        let start = Instant::now();
        let (width, height) = projection.resolution();
        let triangles = projection_triangles(projection);
        let ProjectedScene {
            polygons,
            counts,
            fallback,
        } = project_all(&triangles, &self.scene, curves);
        let project_ms = start.elapsed().as_secs_f64() * 1e3;

        let maps: Vec<ScreenMap> = triangles.iter().map(|t| t.map).collect();
        let pattern = SamplePattern::new(options.spp);
        let mut samples = Samples::new(width, height, &pattern);
        let mut raster = RasterStats::default();
        let (mut raster_ms, mut shade_ms) = (0.0, 0.0);
        for &sample in &pattern.offsets {
            let pass = Instant::now();
            let resolver = Resolver {
                maps: &maps,
                scene: &self.scene,
                sample,
            };
            // Pixel centres of the moved polygons are the samples of the original ones.
            let shift = DVec2::splat(0.5) - sample;
            let moved;
            let batch = if shift == DVec2::ZERO {
                &polygons
            } else {
                moved = polygons.translated(shift);
                &moved
            };
            let shader = Shader {
                resolver,
                caster: &self.caster,
                projection,
                options,
                fallback: &fallback,
                background: self.background,
            };
            // Drawn and shaded band by band, straight into the frame.
            let mut frame = new_frame(width, height, self.background);
            let (stats, counts, times) = rasterize_into_frame(
                &mut frame,
                batch,
                FillRule::NonZero,
                band_rows_for(width),
                self.background,
                &|f| shader.resolver.stage(f),
                &stored_barycentrics,
                &|drawn, rows| shader.rows(drawn, rows),
            );
            raster.add(&stats);
            samples.add(frame, counts);
            // The pass's wall time, split by the CPU time its bands spent drawing and shading.
            let wall = pass.elapsed().as_secs_f64() * 1e3;
            let busy = times.draw_s + times.finish_s;
            let drawing = if busy > 0.0 { times.draw_s / busy } else { 1.0 };
            raster_ms += wall * drawing;
            shade_ms += wall * (1.0 - drawing);
        }
        let (frame, shaded) = samples.finish();

        let mut stats = Stats::new();
        counts.record(&mut stats);
        raster.record(&mut stats);
        let count = |n: usize| Counter::Count(n as u64);
        stats.insert("triangles", count(self.scene.triangles.len()));
        stats.insert("projection_triangles", count(triangles.len()));
        stats.insert(
            "fallback_triangles",
            count(fallback.iter().filter(|&&f| f).count()),
        );
        stats.insert("fallback_rays", Counter::Count(shaded.fallback_rays));
        stats.insert("shading_rays", Counter::Count(shaded.shading_rays));
        stats.insert("curve_steps", Counter::Count(u64::from(curves.steps)));
        stats.insert("project_ms", Counter::Value(project_ms));
        stats.insert("raster_ms", Counter::Value(raster_ms));
        stats.insert("shade_ms", Counter::Value(shade_ms));
        Ok((frame, stats))
    }
}

/// The frames of the samples of one render, reduced as the ray caster reduces its samples:
/// colours averaged, depth and id of the sample nearest the pixel centre.
struct Samples {
    /// The sum of the samples' colours; empty with one sample per pixel, whose frame is
    /// kept whole.
    color: Vec<Vec3>,
    count: u32,
    centre: usize,
    kept: Option<Frame>,
    counts: ShadeCounts,
    size: (u32, u32),
}

impl Samples {
    fn new(width: u32, height: u32, pattern: &SamplePattern) -> Samples {
        let summed = if pattern.offsets.len() > 1 {
            width as usize * height as usize
        } else {
            0
        };
        Samples {
            color: vec![Vec3::ZERO; summed],
            count: 0,
            centre: pattern.centre,
            kept: None,
            counts: ShadeCounts::default(),
            size: (width, height),
        }
    }

    /// Adds the next sample's frame (samples come in pattern order).
    fn add(&mut self, frame: Frame, counts: ShadeCounts) {
        for (sum, c) in self.color.iter_mut().zip(&frame.color) {
            *sum += *c;
        }
        if self.count as usize == self.centre {
            self.kept = Some(frame);
        }
        self.count += 1;
        self.counts = self.counts + counts;
    }

    /// The pixel frame and the rays all samples cast.
    fn finish(self) -> (Frame, ShadeCounts) {
        let scale = 1.0 / self.count.max(1) as f32;
        let mut frame = self
            .kept
            .unwrap_or_else(|| Frame::new(self.size.0, self.size.1, Vec3::ZERO));
        if self.count > 1 {
            frame.color = self.color.iter().map(|c| *c * scale).collect();
        }
        (frame, self.counts)
    }
}
