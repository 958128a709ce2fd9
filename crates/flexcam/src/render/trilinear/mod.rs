//! `--method trilinear`: the fast renderer of trilinear projections (Vallance 2005, chapters 4
//! and 5). Instead of casting a ray per pixel it projects the scene into each projection
//! triangle and rasterises the result; docs/trilinear.md has the design and measurements.
//!
//! Per projection triangle (in parallel), `polygons`: scene triangles beyond a bounding
//! plane of the triangle's ray volume are culled (`volume_bounds`), each remaining scene
//! vertex is projected once (its cubic), pairs whose images cannot be visible are culled, each scene triangle is cut into
//! shapes (`projection::project_solved_triangle`), each shape's curved edges are sampled along
//! the exact images of their scene edges (`edge_path`, `outline`, by the `curves`
//! mode), with exact anchors at the view plane and at the projection triangle's edge surfaces,
//! and the outline is clipped (`clip`) and mapped to pixels (`screen_map`), each vertex
//! carrying the terms of its projector's hit with the scene triangle's plane that are affine
//! in pixel position (`hit_terms`). All polygons are then rasterised (`render::scan`,
//! non-zero fill, z-buffer), every fragment finished to its exact hit from its interpolated
//! terms before its z-test, and each pixel's winner shaded once (`shade`).
//!
//! Projection triangles whose rays fold are drawn so too (the sweep by depth covers each pixel
//! once, see `projection::trilinear::point_projection::fold`); those whose rays meet in one
//! point are drawn as central projections (`central`), and those with two equal vertices,
//! which sweep no volume, as strips of one ray each (`ray_fan`). A pair with a shape reaching
//! across a depth where the parametric triangle degenerates is split at the depths around it
//! (`degenerate_band`). Unprojectable pairs (see `projection::Unprojectable`) are counted and
//! their projection triangle is ray cast instead, so they never silently vanish;
//! docs/trilinear-raster.md lists these cases.

mod central;
mod chord_error;
mod clip;
#[cfg(test)]
mod cull_tests;
mod cull_tree;
mod curves;
mod degenerate_band;
mod edge_path;
mod gbuffer;
mod hit_terms;
mod occlusion;
mod outline;
mod pair_cull;
mod polygons;
mod ray_fan;
mod resolve;
mod scene_geometry;
mod screen_map;
mod shade;
#[cfg(test)]
mod tests;
mod view_plane;
mod volume_bounds;
// Bench scenes, for `flexcam bench` and the criterion benches only (`bench_support`).
#[cfg(any(test, feature = "workloads"))]
pub mod workloads;

use std::time::Instant;

use glam::{DVec2, DVec3, Vec3};

pub use curves::{CurveMode, CurveOptions};
pub(in crate::render) use gbuffer::{band_name, GBuffer};
pub use polygons::{project_all, projection_triangles};
pub(crate) use resolve::plane_hit;
pub use scene_geometry::SceneGeometry;
pub use screen_map::ScreenMap;

use self::central::CentralProjection;
use self::polygons::ProjectedScene;
use self::ray_fan::RayFan;
use self::resolve::Resolver;
use self::shade::{ShadeCounts, Shader};
use crate::error::{Error, Result};
use crate::projection::{Projection, Trilinear};
use crate::render::prepared::PreparedScene;
use crate::render::raycast::SamplePattern;
use crate::render::scan::{band_rows_for, for_each_band, RasterStats, Scratch};
use crate::render::shading::triangle_color::TriangleColor;
use crate::render::shading::TextureFilter;
use crate::render::{frame_name, Counter, Frame, Outputs, RenderOptions, Shading, Stats};
use crate::try_alloc;

/// A prepared scene made ready for trilinear rendering: its triangles in f64 and the flat base
/// colour of each, built once for any number of renders; shading (shadows, mirrors, glass)
/// and fallback pixels trace through the prepared scene's BVH.
pub struct TrilinearRenderer<'a> {
    prepared: &'a PreparedScene,
    scene: SceneGeometry,
    /// Per scene triangle (numbered as `scene.triangles`), its base colour where flat
    /// shading shows it (see `Shader::flat_colors`).
    flat_colors: Vec<Option<TriangleColor>>,
    /// A sphere (centre, radius) around every scene vertex, `None` for a scene without
    /// vertices: how deep a projection triangle's rays can meet the scene.
    bounding_sphere: Option<(DVec3, f64)>,
}

impl<'a> TrilinearRenderer<'a> {
    /// The renderer of `prepared`, with the scene's f64 geometry and its bounding sphere.
    pub fn new(prepared: &'a PreparedScene) -> TrilinearRenderer<'a> {
        let scene = prepared.scene();
        let geometry = SceneGeometry::new(scene);
        let flat_colors = flat_colors(prepared, &geometry);
        let bounding_sphere = bounding_sphere(&geometry.vertices);
        TrilinearRenderer {
            prepared,
            bounding_sphere,
            scene: geometry,
            flat_colors,
        }
    }

    /// Renders the scene through `projection` with `curves` into a new frame (see
    /// [`TrilinearRenderer::render_into`]). The frame starts as zeroed memory
    /// (`Frame::zeroed`), not cleared to the background: `render_into` writes every pixel,
    /// so no clearing pass runs and each page is first touched by the shading that fills it.
    pub fn render(
        &self,
        projection: &Trilinear,
        options: &RenderOptions,
        curves: CurveOptions,
    ) -> Result<(Frame, Stats)> {
        let (width, height) = projection.resolution();
        let mut frame = Frame::zeroed(width, height, Outputs::ALL)?;
        let stats = self.render_into(&mut frame, projection, options, curves)?;
        Ok((frame, stats))
    }

    /// Renders the scene through `projection` with `curves` into `frame`, every pixel of it
    /// overwritten: a caller drawing frame after frame keeps one frame and pays neither its
    /// allocation nor the first touch of its pages again (12.8 MB at 800 x 800). A frame of
    /// another size than the projection's resolution (or whose buffers do not match its
    /// size) is replaced by one of the right size.
    /// With `options.spp` samples per pixel (0 counts as 1) the polygons are projected once
    /// and rasterised, resolved and shaded once per sample of the ray caster's pattern
    /// (`SamplePattern`): the pixel averages its samples' colours and reports the depth and
    /// id of the sample nearest its centre, as the ray caster does. Errors: a mesh of more
    /// than 2^31 projection triangles or a scene of more than 2^32 triangles (the fragment
    /// keys, whose top bit is `resolve::PIXEL_TESTED`), `frame` then left as it was; memory that cannot be had for a new frame, the
    /// scratch frame of several samples or the band buffers (module `try_alloc`).
    pub fn render_into(
        &self,
        frame: &mut Frame,
        projection: &Trilinear,
        options: &RenderOptions,
        curves: CurveOptions,
    ) -> Result<Stats> {
        let mesh = projection.mesh();
        if mesh.triangles.len() > (u32::MAX >> 1) as usize
            || u32::try_from(self.scene.triangles.len()).is_err()
        {
            return Err(Error::new(
                "the trilinear method handles at most 2^31 projection and 2^32 scene triangles",
            ));
        }
        let start = Instant::now();
        let (width, height) = projection.resolution();
        let mut triangles = projection_triangles(projection);
        // Projection triangles whose rays fold are drawn by their shapes like any other
        // (the module doc of `projection::trilinear::point_projection::fold` says why that
        // is exact). Two kinds are not. One whose rays meet in one point at a depth the
        // scene reaches (its parametric triangle degenerates there, `degenerates_before`,
        // and the plane through the point is imaged at infinity) is drawn as a central
        // projection (`central`); where it degenerates otherwise (to a segment), the pairs
        // with a shape reaching across that depth are split there (`degenerate_band`). One that
        // sweeps a surface, not a volume, projects no scene point and is drawn as a fan of
        // rays where two of its vertices are equal (`ray_fan`); the pixels of the others
        // are ray cast, and their pairs are not projected.
        for triangle in &mut triangles {
            let cache = *triangle.map.cache();
            if cache.sweeps_no_volume() {
                triangle.fan = RayFan::of(&cache);
                triangle.ray_cast = triangle.fan.is_none();
                continue;
            }
            let degenerates = self.bounding_sphere.is_some_and(|(center, radius)| {
                cache.degenerates_before(cache.depth_reaching(center, radius))
            });
            if degenerates {
                triangle.central = CentralProjection::of(&cache);
            }
        }
        let ProjectedScene {
            polygons,
            counts,
            mut fallback,
        } = project_all(&triangles, &self.scene, curves);
        for (f, triangle) in fallback.iter_mut().zip(&triangles) {
            *f |= triangle.ray_cast;
        }
        let project_ms = start.elapsed().as_secs_f64() * 1e3;

        let pattern = SamplePattern::new(options.spp);
        frame.fit(width, height, Outputs::ALL)?;
        let mut samples = Samples::new(frame, &pattern)?;
        let flat_colors = (options.shading == Shading::Flat).then_some(&self.flat_colors[..]);
        let mut raster = RasterStats::default();
        let (mut raster_ms, mut shade_ms) = (0.0, 0.0);
        for &sample in &pattern.offsets {
            let pass = Instant::now();
            let resolver = Resolver {
                triangles: &triangles,
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
                prepared: self.prepared,
                projection,
                options,
                fallback: &fallback,
                background: self.prepared.scene.image.background,
                flat_colors,
            };
            // Drawn and shaded band by band, straight into the frame.
            let band_rows = band_rows_for(width);
            let done = for_each_band(
                samples.target(),
                batch,
                band_rows,
                || Ok((GBuffer::new(width, band_rows)?, Scratch::default())),
                |(buffer, scratch), shapes, rows| {
                    let start = Instant::now();
                    buffer.start_band(rows.rows);
                    let mut raster = RasterStats::default();
                    for &k in shapes {
                        raster.add(&buffer.draw(&batch.get(k), &shader.resolver, scratch));
                    }
                    let finishing = Instant::now();
                    let counts = shader.rows(buffer, rows);
                    BandWork {
                        raster,
                        counts,
                        draw_s: (finishing - start).as_secs_f64(),
                        shade_s: finishing.elapsed().as_secs_f64(),
                    }
                },
            )?;
            raster.add(&done.raster);
            samples.add(done.counts);
            // The pass's wall time, split by the CPU time its bands spent drawing and shading.
            let wall = pass.elapsed().as_secs_f64() * 1e3;
            let busy = done.draw_s + done.shade_s;
            let drawing = if busy > 0.0 { done.draw_s / busy } else { 1.0 };
            raster_ms += wall * drawing;
            shade_ms += wall * (1.0 - drawing);
        }
        let shaded = samples.finish();

        let mut stats = Stats::new();
        counts.record(&mut stats);
        let shapes = RasterStats::of_shapes(&polygons);
        raster.polygons = shapes.polygons * pattern.offsets.len() as u64;
        raster.lines = shapes.lines * pattern.offsets.len() as u64;
        raster.skipped = shapes.skipped * pattern.offsets.len() as u64;
        raster.record(&mut stats);
        let count = |n: usize| Counter::Count(n as u64);
        stats.insert("triangles", count(self.scene.triangles.len()));
        stats.insert("projection_triangles", count(triangles.len()));
        stats.insert(
            "central_triangles",
            count(triangles.iter().filter(|t| t.central.is_some()).count()),
        );
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
        Ok(stats)
    }
}

/// Per scene triangle of `geometry` (a [`SceneGeometry`] of `prepared`'s scene), its base
/// colour where flat shading shows it (nearest texel), `None` for mirrors and glass: what
/// the rasterising renderers read instead of the ray caster's per-hit `base_color`.
pub(crate) fn flat_colors(
    prepared: &PreparedScene,
    geometry: &SceneGeometry,
) -> Vec<Option<TriangleColor>> {
    let scene = prepared.scene();
    geometry
        .owners
        .iter()
        .map(|owner| {
            let object = owner.object as usize;
            prepared.flat_shows_base_color(object).then(|| {
                let triangle = owner.triangle as usize;
                TriangleColor::new(&scene.objects[object], triangle, TextureFilter::Nearest)
            })
        })
        .collect()
}

/// What drawing and shading some bands did, and their CPU time (summed over threads).
#[derive(Debug, Clone, Copy, Default)]
struct BandWork {
    raster: RasterStats,
    counts: ShadeCounts,
    draw_s: f64,
    shade_s: f64,
}

impl std::ops::Add for BandWork {
    type Output = BandWork;

    fn add(self, o: BandWork) -> BandWork {
        let mut raster = self.raster;
        raster.add(&o.raster);
        BandWork {
            raster,
            counts: self.counts + o.counts,
            draw_s: self.draw_s + o.draw_s,
            shade_s: self.shade_s + o.shade_s,
        }
    }
}

/// The samples of one render reduced into the output frame as the ray caster reduces its
/// samples: colours averaged, depth and id of the sample nearest the pixel centre. With one
/// sample per pixel it is drawn straight into the output frame; with more, each is drawn
/// into a scratch frame and added up.
struct Samples<'a> {
    out: &'a mut Frame,
    /// The scratch frame of the current sample and the sum of the samples' colours; `None`
    /// with one sample per pixel.
    scratch: Option<(Frame, Vec<Vec3>)>,
    count: u32,
    centre: usize,
    counts: ShadeCounts,
}

impl<'a> Samples<'a> {
    /// Fails when the scratch frame's memory cannot be had.
    fn new(out: &'a mut Frame, pattern: &SamplePattern) -> Result<Samples<'a>> {
        let scratch = if pattern.offsets.len() > 1 {
            let (width, height) = (out.width, out.height);
            let frame = Frame::zeroed(width, height, Outputs::ALL)?;
            let sum = try_alloc::zeroed(out.color.len(), || frame_name(width, height))?;
            Some((frame, sum))
        } else {
            None
        };
        Ok(Samples {
            out,
            scratch,
            count: 0,
            centre: pattern.centre,
            counts: ShadeCounts::default(),
        })
    }

    /// The frame the next sample is drawn into (every pixel of it is overwritten).
    fn target(&mut self) -> &mut Frame {
        match &mut self.scratch {
            Some((frame, _)) => frame,
            None => &mut *self.out,
        }
    }

    /// Takes in the sample just drawn (samples come in pattern order).
    fn add(&mut self, counts: ShadeCounts) {
        if let Some((frame, sum)) = &mut self.scratch {
            for (sum, c) in sum.iter_mut().zip(&frame.color) {
                *sum += *c;
            }
            if self.count as usize == self.centre {
                self.out.depth.copy_from_slice(&frame.depth);
                self.out.ids.copy_from_slice(&frame.ids);
            }
        }
        self.count += 1;
        self.counts = self.counts + counts;
    }

    /// Writes the averaged colours; returns the rays all samples cast.
    fn finish(self) -> ShadeCounts {
        if let Some((_, sum)) = self.scratch {
            let scale = 1.0 / self.count.max(1) as f32;
            for (out, sum) in self.out.color.iter_mut().zip(sum) {
                *out = sum * scale;
            }
        }
        self.counts
    }
}

/// The centre and half diagonal of the bounding box of the finite `vertices`, `None`
/// without any.
fn bounding_sphere(vertices: &[DVec3]) -> Option<(DVec3, f64)> {
    let mut finite = vertices.iter().filter(|p| p.is_finite());
    let first = *finite.next()?;
    let (lo, hi) = finite.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let center = (lo + hi) / 2.0;
    Some((center, (hi - center).length()))
}
