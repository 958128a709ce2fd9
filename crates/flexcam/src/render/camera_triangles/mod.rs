//! `--method camera-triangles`: multi-perspective rendering by camera triangles (Hou, Wei,
//! Shum and Guo 2006), the feed-forward counterpart of ray casting a trilinear projection.
//!
//! Every projection triangle of a trilinear projection is a camera triangle (`camera`):
//! its pixels' rays interpolate the corner rays barycentrically. Per camera triangle (in
//! parallel) and scene triangle, a bounding region of the scene triangle's curved image is
//! computed (`bound`: the paper's bounding triangle or our tighter hull, `--bound`), after
//! culling clusters of scene triangles whose boxes the camera triangle cannot see (section
//! 2.4; with the tight bound per quarter of the camera triangle, `quarter_cull`). The regions are scan-converted band by band (`render::scan`), and every fragment
//! intersects its pixel's ray with its scene triangle's plane, is killed outside the triangle
//! and z-tested on its exact depth (`fragment`); each pixel's winner is then shaded by the
//! shared shading (`shade`). Nothing is ray cast to find first hits: the scene is only
//! pushed through the cameras, so the result is exact up to rounding (the same first hits as
//! the ray caster) whatever the bound, and the bound only decides how many fragments are
//! wasted (`overdraw`, bounding over rendered fragments, as in the paper's Table 1).
//!
//! Reflections and refractions (`trilinear_reflector = true` objects) are trilinear
//! surfaces composited into the main view (`render::composite`); with this method their
//! surfaces are rendered by camera triangles. A mirror's surface may reflect the eye's ray
//! per fragment about the interpolated vertex normals instead of interpolating the vertex
//! rays (the paper's reflection variant, section 3.1; `camera_rays = "per-fragment"`): the
//! bounds then project along a cone enclosing those rays (`mirror_cone`).

mod bound;
mod camera;
mod convex;
mod fragment;
mod mirror_cone;
mod owners;
#[cfg(test)]
mod per_fragment_tests;
mod quarter_cull;
mod shade;
#[cfg(test)]
mod tests;

use std::time::Instant;

use rayon::prelude::*;

pub use bound::Bound;

use self::camera::Camera;
use self::convex::Convex;
use self::fragment::{BandBuffer, FragmentCounts, Stage};
use self::shade::Shader;
use crate::error::{Error, Result};
use crate::projection::{Projection, Trilinear};
use crate::render::prepared::PreparedScene;
use crate::render::scan::{band_rows_for, for_each_band, PolygonBatch, Vertex};
use crate::render::shading::triangle_color::TriangleColor;
use crate::render::trilinear::{self, SceneGeometry};
use crate::render::{Counter, Frame, Outputs, RenderOptions, Shading, Stats};

/// How the method runs (`--bound`; culling is switched off only to measure it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Options {
    /// The bounding region each scene triangle is drawn through (`--bound`).
    pub bound: Bound,
    /// Cull clusters of scene triangles per camera triangle (section 2.4's object culling).
    pub cull: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            bound: Bound::Tight,
            cull: true,
        }
    }
}

/// A prepared scene made ready for camera-triangle rendering: its triangles in f64 and the
/// flat colour of each, built once for any number of renders.
pub struct CameraTriangleRenderer<'a> {
    prepared: &'a PreparedScene,
    scene: SceneGeometry,
    groups: quarter_cull::Groups,
    flat_colors: Vec<Option<TriangleColor>>,
}

/// What projecting the scene into the camera triangles counted.
#[derive(Debug, Clone, Copy, Default)]
struct PairCounts {
    /// (camera, scene triangle) pairs whose bound was computed.
    pairs: u64,
    /// Pairs culled with their cluster.
    culled: u64,
    /// Bounding regions emitted.
    regions: u64,
}

impl std::ops::Add for PairCounts {
    type Output = PairCounts;

    fn add(self, o: PairCounts) -> PairCounts {
        PairCounts {
            pairs: self.pairs + o.pairs,
            culled: self.culled + o.culled,
            regions: self.regions + o.regions,
        }
    }
}

/// What one band's drawing and shading did.
#[derive(Debug, Clone, Copy, Default)]
struct BandWork {
    fragments: FragmentCounts,
    shading_rays: u64,
    draw_s: f64,
    shade_s: f64,
}

impl std::ops::Add for BandWork {
    type Output = BandWork;

    fn add(self, o: BandWork) -> BandWork {
        BandWork {
            fragments: self.fragments + o.fragments,
            shading_rays: self.shading_rays + o.shading_rays,
            draw_s: self.draw_s + o.draw_s,
            shade_s: self.shade_s + o.shade_s,
        }
    }
}

impl<'a> CameraTriangleRenderer<'a> {
    pub fn new(prepared: &'a PreparedScene) -> CameraTriangleRenderer<'a> {
        let geometry = SceneGeometry::new(prepared.scene());
        let flat_colors = trilinear::flat_colors(prepared, &geometry);
        CameraTriangleRenderer {
            prepared,
            groups: quarter_cull::Groups::new(&geometry),
            scene: geometry,
            flat_colors,
        }
    }

    /// Renders the scene through `projection`'s camera triangles. Errors: more than one
    /// sample per pixel; more than 2^32 camera or scene triangles (the fragment keys);
    /// memory that cannot be had for the frame, its pixels' owners or the band buffers
    /// (module `try_alloc`).
    pub fn render(
        &self,
        projection: &Trilinear,
        options: &RenderOptions,
        method: Options,
    ) -> Result<(Frame, Stats)> {
        if options.spp != 1 {
            return Err(Error::new(format!(
                "method camera-triangles renders one sample per pixel; got --spp {}",
                options.spp
            )));
        }
        if u32::try_from(projection.mesh().triangles.len()).is_err()
            || u32::try_from(self.scene.triangles.len()).is_err()
        {
            return Err(Error::new(
                "the camera-triangles method handles at most 2^32 camera and scene triangles",
            ));
        }
        let start = Instant::now();
        let (width, height) = projection.resolution();
        let cameras = Camera::all(projection);
        let owners = owners::owners(&cameras, width, height)?;
        let owner_ms = start.elapsed().as_secs_f64() * 1e3;

        let start = Instant::now();
        let (regions, pairs) = self.bound_all(&cameras, method);
        let bound_ms = start.elapsed().as_secs_f64() * 1e3;

        let start = Instant::now();
        let mut frame = Frame::zeroed(width, height, Outputs::ALL)?;
        let stage = Stage {
            cameras: &cameras,
            owners: &owners,
            scene: &self.scene,
            width,
        };
        let flat_colors = (options.shading == Shading::Flat).then_some(&self.flat_colors[..]);
        let shader = Shader {
            cameras: &cameras,
            scene: &self.scene,
            prepared: self.prepared,
            options,
            background: self.prepared.scene.image.background,
            flat_colors,
        };
        let band_rows = band_rows_for(width);
        let done = for_each_band(
            &mut frame,
            &regions,
            band_rows,
            || BandBuffer::new(width, band_rows),
            |buffer, shapes, rows| {
                let start = Instant::now();
                buffer.start_band(rows.rows);
                let mut fragments = FragmentCounts::default();
                for &k in shapes {
                    fragments = fragments + stage.draw(buffer, &regions.get(k));
                }
                let shading = Instant::now();
                let shading_rays = shader.rows(buffer, rows);
                BandWork {
                    fragments,
                    shading_rays,
                    draw_s: (shading - start).as_secs_f64(),
                    shade_s: shading.elapsed().as_secs_f64(),
                }
            },
        )?;
        let wall = start.elapsed().as_secs_f64() * 1e3;
        let busy = done.draw_s + done.shade_s;
        let drawing = if busy > 0.0 { done.draw_s / busy } else { 1.0 };

        let mut stats = Stats::new();
        let count = |n: u64| Counter::Count(n);
        let FragmentCounts { bounding, rendered } = done.fragments;
        stats.insert("triangles", count(self.scene.triangles.len() as u64));
        stats.insert("camera_triangles", count(cameras.len() as u64));
        stats.insert("bounding_fragments", count(bounding));
        stats.insert("rendered_fragments", count(rendered));
        stats.insert(
            "overdraw",
            Counter::Value(if rendered > 0 {
                bounding as f64 / rendered as f64
            } else {
                0.0
            }),
        );
        stats.insert("pairs", count(pairs.pairs));
        stats.insert("culled_pairs", count(pairs.culled));
        stats.insert("bounding_regions", count(pairs.regions));
        stats.insert("shading_rays", count(done.shading_rays));
        stats.insert("owner_ms", Counter::Value(owner_ms));
        stats.insert("bound_ms", Counter::Value(bound_ms));
        stats.insert("raster_ms", Counter::Value(wall * drawing));
        stats.insert("shade_ms", Counter::Value(wall * (1.0 - drawing)));
        Ok((frame, stats))
    }

    /// The bounding regions of every (camera, scene triangle) pair in pixels, keyed
    /// `camera << 32 | triangle`, in camera order (computed per camera in parallel), each
    /// pair's regions consecutive. The tight bound with culling culls per quarter of the
    /// camera triangle ([`quarter_cull`]); otherwise clusters are culled against the whole
    /// camera triangle.
    fn bound_all(&self, cameras: &[Camera], method: Options) -> (PolygonBatch<0>, PairCounts) {
        let scene = &self.scene;
        let per_camera: Vec<(PolygonBatch<0>, PairCounts)> = cameras
            .par_iter()
            .enumerate()
            .map_init(quarter_cull::Buffers::default, |buffers, (c, camera)| {
                let mut batch = PolygonBatch::new();
                let mut counts = PairCounts::default();
                let mut push = |k: usize, region: &Convex| {
                    batch.push_from(
                        region
                            .points()
                            .iter()
                            .map(|p| Vertex::new(p.x, p.y, 0.0, [])),
                        ((c as u64) << 32) | k as u64,
                    );
                    counts.regions += 1;
                };
                if method.cull && method.bound == Bound::Tight {
                    counts.pairs = quarter_cull::pieces(camera, scene, &self.groups, buffers);
                    counts.culled = scene.triangles.len() as u64 - counts.pairs;
                    // A triangle's pieces are consecutive: its corners and plane are
                    // found once for all of them.
                    let mut last = None;
                    for piece in &buffers.pieces {
                        let k = piece.triangle as usize;
                        let (q, plane) = match last {
                            Some((at, q, plane)) if at == k => (q, plane),
                            _ => {
                                let q = scene.corners(k);
                                (q, bound::tight_plane(camera, &q))
                            }
                        };
                        last = Some((k, q, plane));
                        bound::tight_in(
                            camera,
                            &q,
                            plane.as_ref(),
                            piece.sub,
                            piece.depth,
                            &mut |region| push(k, region),
                        );
                    }
                } else {
                    let mut test = bound::PieceTest::new(camera, camera::CORNERS);
                    for cluster in &scene.clusters {
                        let size = cluster.triangles.len() as u64;
                        if method.cull && test.misses(&cluster.box_corners) {
                            counts.culled += size;
                            continue;
                        }
                        counts.pairs += size;
                        for k in cluster.triangles.clone() {
                            bound::regions(camera, &scene.corners(k), method.bound, &mut |r| {
                                push(k, r)
                            });
                        }
                    }
                }
                (batch, counts)
            })
            .collect();
        // Sized once: growing it while appending would copy the batch so far each time.
        let mut all = PolygonBatch::with_capacity(
            per_camera.iter().map(|(b, _)| b.vertex_count()).sum(),
            per_camera.iter().map(|(b, _)| b.len()).sum(),
        );
        let mut counts = PairCounts::default();
        for (batch, c) in &per_camera {
            all.append(batch);
            counts = counts + *c;
        }
        (all, counts)
    }
}

/// Renders `prepared` through `projection` by camera triangles; refuses a projection that is
/// not trilinear with one line.
pub fn render(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
) -> Result<(Frame, Stats)> {
    let trilinear = projection.trilinear().ok_or_else(|| {
        Error::new(format!(
            "the camera-triangles method renders only trilinear projections (and trilinear \
             reflectors in a perspective view), not a {} projection",
            projection.kind()
        ))
    })?;
    CameraTriangleRenderer::new(prepared).render(trilinear, options, options.camera_triangles)
}
