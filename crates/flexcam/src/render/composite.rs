//! Reflections and refractions through trilinear surfaces (Vallance 2005, chapter 7), composited
//! into the main image.
//!
//! The main view is rendered with the reflectors treated as diffuse (their pixels are
//! replaced, so no exact secondary rays are spent on them). Each reflector then gets a
//! [`reflector_surface`] built from its mesh and the main camera, the scene without that
//! reflector is rendered through it, and every main-image pixel that sees the reflector takes
//! its colour from that image, which is already in main-image coordinates ([`paste`]). The
//! reflector's mesh is first refined where the surface's interpolated rays would displace
//! the reflected image by more than the reflector's tolerance in main-image pixels
//! ([`refine`]; scene-file key `trilinear_refine_px`). With `reflection = "env-map"` the
//! image through the surface is instead looked up in a cube map rendered from the
//! reflector's centre ([`env_map`]: the baseline without parallax).
//! Depth and object id stay those of the main view (the reflector's own, as for a mirror in
//! the ray caster).
//!
//! Compositing is reached only through [`crate::render::render`]
//! (`RenderOptions::composite_reflectors`); every view is rendered by the options' method
//! ([`render`]), and the trilinear methods render the perspective main view as two projection
//! triangles. The main view (the reflectors made diffuse), the scene without a reflector
//! (rendered through that reflector's surfaces) and the reflector alone (the Fresnel split)
//! are views of the prepared scene ([`PreparedScene::view`]): they share its one BVH.
//! In `lit` shading a mirror's reflected colour is tinted by its base colour, and glass mixes
//! the images through its refraction surface and through a second, reflection surface by the
//! exact Fresnel reflectance at each pixel, as the ray caster's glass does ([`FresnelSplit`],
//! [`fresnel_mix`]); in `flat` shading the image through the surface is taken as is, as the
//! flat contract asks of mirrors and glass (the refraction, or the reflection on total
//! internal reflection, without Fresnel mixing).

use std::sync::Arc;
use std::time::Instant;

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

use self::camera_mesh::camera_mesh;
pub use self::main_camera::main_camera;
use crate::error::{Error, Result};
use crate::projection::trilinear_builders::{
    reflector_surface, Optic, ReflectorSurface, SurfaceRays, SurfaceScreenMap,
};
use crate::projection::{Perspective, Projection, Trilinear, TrilinearMesh};
use crate::render::prepared::PreparedScene;
use crate::render::shading::normals;
use crate::render::shading::trace::specular;
use crate::render::{
    AtlasImage, Counter, Frame, Method, Outputs, RenderOptions, RenderWarning, Rendered, Shading,
    Stats,
};
use crate::scene::{Finish, Mesh, Object, ReflectionImage, Scene, TrilinearReflector};

/// A way of rendering a scene through a projection: a [`Method`] alone, or the trilinear
/// method with its main view through [`perspective_as_trilinear`].
type Renderer<'a> =
    dyn Fn(&PreparedScene, &dyn Projection, &RenderOptions) -> Result<(Frame, Stats)> + 'a;

/// Renders `prepared` through `main` with `renderer`, compositing the reflections and
/// refractions of `scene.trilinear_reflectors` (none: exactly `renderer`'s image). The stats
/// are the main render's, plus `reflectors`, `reflector_triangles` (in the surfaces),
/// `reflector_dropped_triangles` (see [`reflector_surface`]), `reflector_pixels` (main-image
/// pixels replaced), `reflector_fresnel_rays` (lit glass: main-camera rays cast at the
/// reflector alone for the Fresnel split), `reflector_uncovered_pixels` (reflector pixels
/// that no triangle of the surface covers), `reflector_exact_pixels` (those of them ray cast
/// exactly instead: [`ExactPixels`]; none without `RenderOptions::cast_reflector_gaps`),
/// `reflector_unsplit_edges` (edges the refinement left over its tolerance at its depth cap
/// or below a pixel: [`refine`]; a [`RenderWarning::ReflectorOverTolerance`] for each
/// reflector that has such edges), `reflector_silhouette_edges` (edges across a glass's
/// silhouette, where the exact image jumps, split down to a pixel:
/// [`refine::Refinement::silhouette`]) and `reflector_render_ms` (surface refinement,
/// building and rendering).
///
/// Errors: the renderer's; a main view that is not a pinhole ([`main_camera`]);
/// a reflector id that no object has, or whose material is not mirror or glass.
fn with_renderer(
    prepared: &PreparedScene,
    main: &dyn Projection,
    options: &RenderOptions,
    renderer: &Renderer,
) -> Result<Rendered> {
    let scene = prepared.scene();
    if scene.trilinear_reflectors.is_empty() {
        let (frame, counters) = renderer(prepared, main, options)?;
        return Ok(Rendered {
            frame,
            counters,
            warnings: Vec::new(),
            atlases: Vec::new(),
        });
    }
    let camera = main_camera(scene, main)?;
    let mut main_scene = scene.clone();
    for object in &mut main_scene.objects {
        if scene.trilinear_reflectors.iter().any(|r| r.id == object.id) {
            object.material.finish = Finish::Diffuse;
        }
    }
    // The main view's ids find the reflectors' pixels; the images through the surfaces are
    // read for their colour alone.
    let main_options = RenderOptions {
        outputs: Outputs {
            ids: true,
            ..options.outputs
        },
        ..*options
    };
    let (mut frame, mut stats) = renderer(&prepared.view(main_scene), main, &main_options)?;
    let keep_atlases = options.outputs.atlases;
    let mut atlases = Vec::new();
    let options = &RenderOptions {
        outputs: Outputs::COLOR,
        ..*options
    };
    let start = Instant::now();
    let (mut triangles, mut dropped, mut pixels, mut fresnel_rays) = (0, 0, 0, 0);
    let exact = ExactPixels::new(prepared, &camera, options);
    let (mut exact_pixels, mut uncovered_pixels) = (0, 0);
    let (mut unsplit, mut silhouettes, mut warnings) = (0, 0, Vec::new());
    for entry in &scene.trilinear_reflectors {
        let (id, map) = (entry.id, entry.screen_map);
        let reflector = Reflector::of(scene, id)?;
        if entry.camera_rays == SurfaceRays::PerFragment && reflector.optic != Optic::Reflect {
            return Err(Error::new(format!(
                "trilinear reflector {id}: per-fragment camera rays need a mirror (glass is \
                 refracted by interpolated rays only)"
            )));
        }
        let (surface, mut left, silhouette) =
            refined_surface(&reflector, reflector.optic, entry, &camera, options.method)?;
        silhouettes += silhouette;
        triangles += surface.mesh.triangles.len();
        dropped += surface.dropped;
        let projection = surface_projection(&surface, map, entry.camera_rays, &camera)?;
        let mut missed = None;
        if let Some(projection) = &projection {
            let others = prepared.view(without(scene, id));
            let main_view = &frame;
            // The image through a surface of `optic`, its counters, and with the atlas the
            // pixels it missed (its atlas kept in `atlases` when wanted).
            let mut through =
                |surface: &Trilinear, optic: Optic| -> Result<(Frame, Stats, Option<Vec<usize>>)> {
                    Ok(match entry.reflection {
                        ReflectionImage::Surface => {
                            let (image, counters) = renderer(&others, surface, options)?;
                            (image, counters, None)
                        }
                        ReflectionImage::EnvMap => {
                            let (image, counters) =
                                env_map::image(&others, surface, &reflector.mesh, options)?;
                            (image, counters, None)
                        }
                        ReflectionImage::Atlas => {
                            let view = atlas::View {
                                prepared,
                                others: &others,
                                id,
                                main: main_view,
                                camera: &camera,
                            };
                            let mapped = view.image(surface, options, renderer)?;
                            if let (true, Some(image)) = (keep_atlases, mapped.atlas) {
                                atlases.push(AtlasImage { id, optic, image });
                            }
                            (mapped.image, mapped.stats, Some(mapped.missed))
                        }
                    })
                };
            let (image, counters, through_missed) = through(projection, reflector.optic)?;
            missed = through_missed;
            add_camera_triangle_counts(&mut stats, &counters);
            add_atlas_counts(&mut stats, &counters);
            pixels += match (options.shading, reflector.optic) {
                (Shading::Flat, _) => paste(&mut frame, id, &image, Vec3::ONE)?,
                (Shading::Lit | Shading::Transitions(_), Optic::Reflect) => {
                    paste(&mut frame, id, &image, reflector.tint)?
                }
                (Shading::Lit | Shading::Transitions(_), Optic::Refract { .. }) => {
                    let (mirror, mirror_left, mirror_silhouette) = refined_surface(
                        &reflector,
                        Optic::Reflect,
                        entry,
                        &camera,
                        options.method,
                    )?;
                    left += mirror_left;
                    silhouettes += mirror_silhouette;
                    let rays = entry.camera_rays;
                    let reflection = match surface_projection(&mirror, map, rays, &camera)? {
                        Some(surface) => through(&surface, Optic::Reflect)?.0,
                        None => Frame::try_new(image.width, image.height, scene.image.background)?,
                    };
                    let split = FresnelSplit::new(prepared, id, camera.clone());
                    let mixed =
                        fresnel_mix(&frame, id, &image, &reflection, &split, reflector.tint)?;
                    fresnel_rays += mixed.rays;
                    paste(&mut frame, id, &mixed.frame, Vec3::ONE)?
                }
            };
        }
        let uncovered = match missed {
            Some(missed) => missed,
            None => exact.uncovered(&frame, id, projection.as_ref()),
        };
        uncovered_pixels += uncovered.len();
        if options.cast_reflector_gaps {
            exact.cast(&mut frame, &uncovered);
            exact_pixels += uncovered.len();
        }
        unsplit += left;
        if left > 0 {
            warnings.push(RenderWarning::ReflectorOverTolerance {
                id,
                edges: left as u64,
                tolerance_px: entry.refine_px,
            });
        }
    }
    let count = |n: usize| Counter::Count(n as u64);
    stats.insert("reflectors", count(scene.trilinear_reflectors.len()));
    stats.insert("reflector_triangles", count(triangles));
    stats.insert("reflector_dropped_triangles", count(dropped));
    stats.insert("reflector_pixels", Counter::Count(pixels));
    stats.insert("reflector_fresnel_rays", Counter::Count(fresnel_rays));
    stats.insert("reflector_uncovered_pixels", count(uncovered_pixels));
    stats.insert("reflector_exact_pixels", count(exact_pixels));
    stats.insert("reflector_unsplit_edges", count(unsplit));
    stats.insert("reflector_silhouette_edges", count(silhouettes));
    stats.insert(
        "reflector_render_ms",
        Counter::Value(start.elapsed().as_secs_f64() * 1e3),
    );
    Ok(Rendered {
        frame,
        counters: stats,
        warnings,
        atlases,
    })
}

/// Adds the atlas counters of a reflector image made through its texture atlas
/// (`atlas_width`, `atlas_height`, `atlas_cell_px` of the last atlas, `atlas_missed_pixels`
/// summed over reflectors); nothing for other images.
fn add_atlas_counts(stats: &mut Stats, surface: &Stats) {
    for name in ["atlas_width", "atlas_height", "atlas_cell_px"] {
        if let Some(&value) = surface.get(name) {
            stats.insert(name, value);
        }
    }
    if let Some(Counter::Count(missed)) = surface.get("atlas_missed_pixels") {
        let before = match stats.get("atlas_missed_pixels") {
            Some(Counter::Count(n)) => *n,
            _ => 0,
        };
        stats.insert("atlas_missed_pixels", Counter::Count(before + missed));
    }
}

/// Adds the counts and stage times of a reflector surface rendered by camera triangles
/// (`camera_triangles`, `bounding_fragments`, `rendered_fragments`, `culled_pairs`,
/// `bounding_regions`, `owner_ms`, `bound_ms`) to `stats`, with its `pairs`, `raster_ms` and
/// `shade_ms` as `surface_pairs`, `surface_raster_ms` and `surface_shade_ms` (the main view
/// has its own), and sets `overdraw` to bounding over rendered fragments of all surfaces so far.
pub(super) fn add_camera_triangle_counts(stats: &mut Stats, surface: &Stats) {
    const SUMMED: [(&str, &str); 10] = [
        ("camera_triangles", "camera_triangles"),
        ("bounding_fragments", "bounding_fragments"),
        ("rendered_fragments", "rendered_fragments"),
        ("pairs", "surface_pairs"),
        ("culled_pairs", "culled_pairs"),
        ("bounding_regions", "bounding_regions"),
        ("owner_ms", "owner_ms"),
        ("bound_ms", "bound_ms"),
        ("raster_ms", "surface_raster_ms"),
        ("shade_ms", "surface_shade_ms"),
    ];
    if surface.get("camera_triangles").is_none() {
        return;
    }
    for (name, as_name) in SUMMED {
        let sum = match (surface.get(name), stats.get(as_name)) {
            (Some(Counter::Count(n)), Some(Counter::Count(m))) => Counter::Count(n + m),
            (Some(Counter::Count(n)), _) => Counter::Count(*n),
            (Some(Counter::Value(n)), Some(Counter::Value(m))) => Counter::Value(n + m),
            (Some(Counter::Value(n)), _) => Counter::Value(*n),
            _ => continue,
        };
        stats.insert(as_name, sum);
    }
    if let (Some(Counter::Count(b)), Some(Counter::Count(r))) = (
        stats.get("bounding_fragments"),
        stats.get("rendered_fragments"),
    ) {
        let overdraw = if *r > 0 { *b as f64 / *r as f64 } else { 0.0 };
        stats.insert("overdraw", Counter::Value(overdraw));
    }
}

/// Renders `prepared` through `main` by `options.method`, compositing the scene's trilinear
/// reflectors ([`with_renderer`]): what [`crate::render::render`] does with
/// `RenderOptions::composite_reflectors`. With [`Method::Trilinear`] (or [`Method::CameraTriangles`], whose
/// reflector surfaces are rendered by camera triangles) and reflectors, the main view (a perspective
/// camera, which that method does not render) is rendered through
/// [`perspective_as_trilinear`], the same pinhole as two projection triangles, so that the
/// whole frame, main view and reflections, is rendered by the trilinear method (Vallance 2005,
/// chapter 7: the reflection surfaces are meant for the fast renderer). Without reflectors
/// this is `method.render` unchanged (a perspective scene is still refused by the trilinear
/// method). Errors: as [`with_renderer`].
pub(super) fn render(
    prepared: &PreparedScene,
    main: &dyn Projection,
    options: &RenderOptions,
) -> Result<Rendered> {
    let method = options.method;
    let renderer =
        |s: &PreparedScene, p: &dyn Projection, o: &RenderOptions| method.render(s, p, o);
    let scene = prepared.scene();
    // Camera triangles render the reflectors' surfaces; their main view (a pinhole, which
    // camera triangles could only bound loosely) is the trilinear method's exact one.
    let main_method = match method {
        Method::Trilinear | Method::CameraTriangles => Method::Trilinear,
        _ => return with_renderer(prepared, main, options, &renderer),
    };
    if scene.trilinear_reflectors.is_empty() {
        return with_renderer(prepared, main, options, &renderer);
    }
    let pinhole = perspective_as_trilinear(&main_camera(scene, main)?)?;
    let main_as_trilinear = |s: &PreparedScene, p: &dyn Projection, o: &RenderOptions| {
        // The main pass is the only one through a projection that is not trilinear.
        if p.trilinear().is_none() {
            main_method.render(s, &pinhole, o)
        } else {
            method.render(s, p, o)
        }
    };
    with_renderer(prepared, main, options, &main_as_trilinear)
}

/// The perspective camera `camera` as an exact trilinear projection: two projection
/// triangles over the image's corners, each ray the corner's pixel ray scaled to unit
/// forward component `D`, each base point `eye + NEAR D`. A pinhole's ray direction (so
/// scaled) is affine in the screen position, which is what a projection triangle
/// interpolates, so every pixel gets the camera's own ray, starting on the plane at forward
/// distance `NEAR` (depth is measured from there: smaller than the perspective view's by at
/// most `NEAR` times the ray's length per unit forward distance).
///
/// Degenerate case: base points exactly at the eye (a projection triangle whose base
/// triangle is a point) make the trilinear rasteriser misplace scene triangles that cross
/// the eye's plane (a floor running under and behind the camera: ids 80.5 % instead of
/// 100 %; docs/robustness.md, audit 3), hence the small offset; anything nearer the eye
/// than `NEAR` (relative to the eye's distance from the origin) is not seen. Errors: a
/// camera without a ray at a corner or at the centre (not a valid pinhole).
pub fn perspective_as_trilinear(camera: &Perspective) -> Result<Trilinear> {
    let (width, height) = camera.resolution();
    let (w, h) = (f64::from(width), f64::from(height));
    let ray = |pixel: DVec2| {
        camera
            .ray(pixel)
            .ok_or_else(|| Error::new("the main camera has no ray at an image corner"))
    };
    let centre = ray(DVec2::new(w / 2.0, h / 2.0))?;
    let forward = centre.direction;
    // Screen (0, 0) is the bottom-left corner, pixel row 0 the top.
    let screen = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let eye = centre.origin;
    let near = NEAR * (1.0 + eye.abs().max_element());
    let mut normals = Vec::with_capacity(4);
    for &(sx, sy) in &screen {
        let direction: DVec3 = ray(DVec2::new(sx * w, (1.0 - sy) * h))?.direction;
        normals.push(direction / direction.dot(forward));
    }
    let mesh = TrilinearMesh {
        points: normals.iter().map(|&d| eye + near * d).collect(),
        normals,
        screen: screen.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    Trilinear::new(&mesh, width, height)
}

/// Forward distance of [`perspective_as_trilinear`]'s base points from the eye, relative to
/// `1 + ` the eye's largest coordinate.
const NEAR: f64 = 1e-6;

/// A reflector object: its parts' meshes merged, its optic and its base colour.
#[derive(Debug, Clone)]
pub struct Reflector {
    pub mesh: Mesh,
    pub optic: Optic,
    pub tint: Vec3,
}

impl Reflector {
    /// The reflector with object id `id`. Errors: no object has the id; a part that is
    /// neither mirror nor glass.
    pub fn of(scene: &Scene, id: u32) -> Result<Reflector> {
        let parts: Vec<&Object> = scene.objects.iter().filter(|o| o.id == id).collect();
        let first = parts.first().ok_or_else(|| {
            Error::new(format!("trilinear reflector {id}: no object has this id"))
        })?;
        let optic = match first.material.finish {
            Finish::Mirror => Optic::Reflect,
            Finish::Glass { ior } => Optic::Refract {
                ior: f64::from(ior),
            },
            _ => {
                return Err(Error::new(format!(
                    "trilinear reflector \"{}\" must be a mirror or glass",
                    first.name
                )))
            }
        };
        let mut mesh = Mesh::default();
        for part in &parts {
            if part.material.finish != first.material.finish {
                return Err(Error::new(format!(
                    "trilinear reflector \"{}\" has parts of different materials",
                    first.name
                )));
            }
            mesh.append(&part.mesh);
        }
        Ok(Reflector {
            mesh,
            optic,
            tint: first.material.color,
        })
    }
}

/// The surface of `reflector` for `optic` seen by `camera`, rendered by `method`: its camera
/// mesh ([`camera_mesh`]: the given size as it is, or, refined with `entry`'s screen map and
/// tolerance ([`refine`]), the automatic size for camera triangles and the reflector's own
/// mesh for the other methods), the number of edges left over the tolerance and the number
/// split down to a pixel across a glass's silhouette (see [`refine::Refinement`]).
fn refined_surface(
    reflector: &Reflector,
    optic: Optic,
    entry: &TrilinearReflector,
    camera: &Perspective,
    method: Method,
) -> Result<(ReflectorSurface, usize, usize)> {
    let automatic = method == Method::CameraTriangles;
    let chosen = camera_mesh(&reflector.mesh, entry, camera, optic, automatic)?;
    if !chosen.refine {
        return Ok((reflector_surface(&*chosen.mesh, camera, optic)?, 0, 0));
    }
    let refined = refine::refine(
        &chosen.mesh,
        camera,
        optic,
        entry.screen_map,
        entry.refine_px,
    );
    Ok((
        reflector_surface(&refined.mesh, camera, optic)?,
        refined.unsplit,
        refined.silhouette,
    ))
}

/// Renders `others` (the scene without a reflector: [`without`]) through `surface` with
/// screen map `map` at the main camera's resolution: the reflected or refracted view in
/// main-image coordinates; `None` when the surface has no triangles (the main camera does
/// not see the reflector). The tests' way through a surface (compositing goes through
/// [`surface_projection`] and the reflector's own way of imaging it).
#[cfg(test)]
pub fn render_through(
    others: &PreparedScene,
    surface: &ReflectorSurface,
    map: SurfaceScreenMap,
    camera: &Perspective,
    options: &RenderOptions,
    renderer: &Renderer,
) -> Result<Option<Frame>> {
    surface_projection(surface, map, SurfaceRays::Interpolated, camera)?
        .map(|projection| Ok(renderer(others, &projection, options)?.0))
        .transpose()
}

/// `scene` without object `id` (its parts keep their places, with empty meshes: a view of
/// the prepared scene, [`PreparedScene::view`]) and without reflectors: what a reflector's
/// surface sees.
pub fn without(scene: &Scene, id: u32) -> Scene {
    only(scene, |o| o.id != id)
}

/// `scene` with only the objects `shown` accepts (the others keep their places, with empty
/// meshes) and without reflectors to composite.
fn only(scene: &Scene, shown: impl Fn(&Object) -> bool) -> Scene {
    let mut part = scene.clone();
    for object in &mut part.objects {
        if !shown(object) {
            object.mesh = Arc::default();
        }
    }
    part.trilinear_reflectors.clear();
    part
}

/// The trilinear projection of `surface` with screen map `map` and rays `rays` at the main
/// camera's resolution; `None` when the surface has no triangles.
fn surface_projection(
    surface: &ReflectorSurface,
    map: SurfaceScreenMap,
    rays: SurfaceRays,
    camera: &Perspective,
) -> Result<Option<Trilinear>> {
    let (width, height) = camera.resolution();
    surface.projection(map, rays, width, height)
}

/// Exact ray casting of the reflector pixels a surface does not cover: the ray caster's own
/// mirror or glass (or, in flat shading, its passing on of the ray) at the main camera's
/// pixel-centre ray, traced through the whole prepared scene.
pub struct ExactPixels<'a> {
    prepared: &'a PreparedScene,
    camera: &'a Perspective,
    options: &'a RenderOptions<'a>,
}

impl<'a> ExactPixels<'a> {
    pub fn new(
        prepared: &'a PreparedScene,
        camera: &'a Perspective,
        options: &'a RenderOptions<'a>,
    ) -> Self {
        ExactPixels {
            prepared,
            camera,
            options,
        }
    }

    /// The pixels of `frame` that see object `id` and whose centre no screen triangle of
    /// `surface` covers (all of them when there is no surface): the back of an open
    /// reflector, whose triangles are all left out (see [`reflector_surface`]), or a
    /// silhouette pixel that the surface's screen triangles miss. Such a pixel would
    /// otherwise keep the reflector's diffuse colour or show the background.
    ///
    /// The surface's coverage is found along rows ([`Trilinear::covered_pixels`]), the same
    /// test as [`Trilinear::locate`] at each pixel centre; the pixels are then filtered in
    /// chunks of [`FILTER_CHUNK`], each a plain loop (a parallel filter per pixel cost more
    /// than the test). The result is in pixel order.
    pub fn uncovered(&self, frame: &Frame, id: u32, surface: Option<&Trilinear>) -> Vec<usize> {
        let covered = surface.map(|s| s.covered_pixels(frame.width, frame.height));
        let covered = covered.as_deref();
        frame
            .ids
            .par_chunks(FILTER_CHUNK)
            .enumerate()
            .flat_map_iter(|(chunk, ids)| {
                let first = chunk * FILTER_CHUNK;
                ids.iter().enumerate().filter_map(move |(i, &seen)| {
                    let k = first + i;
                    (seen == id && covered.is_none_or(|c| !c[k])).then_some(k)
                })
            })
            .collect()
    }

    /// Ray casts the pixels `pixels` of `frame` ([`ExactPixels::uncovered`]). Degenerate
    /// case: a pixel whose ray misses the whole scene (the main view saw the reflector at a
    /// grazing edge that the exact test rejects) takes the background.
    pub fn cast(&self, frame: &mut Frame, pixels: &[usize]) {
        let width = frame.width as usize;
        let caster = self.prepared;
        let colors: Vec<Vec3> = pixels
            .par_iter()
            .map(|&k| {
                let ray = self.camera.ray(pixel_centre(k, width));
                match ray.as_ref().and_then(|r| Some((r, caster.intersect(r)?))) {
                    Some((ray, hit)) => caster.shade_hit(ray, hit, self.options).0,
                    None => caster.scene.image.background,
                }
            })
            .collect();
        for (&k, color) in pixels.iter().zip(colors) {
            frame.color[k] = color;
        }
    }
}

/// Pixels per chunk of [`ExactPixels::uncovered`]'s filter.
const FILTER_CHUNK: usize = 1 << 15;

/// The centre of pixel `k` (row-major) of an image `width` pixels wide.
fn pixel_centre(k: usize, width: usize) -> DVec2 {
    DVec2::new((k % width) as f64 + 0.5, (k / width) as f64 + 0.5)
}

/// Replaces the colour of every pixel of `main` that sees object `id` by `tint` times the
/// same pixel of `reflection`; returns the number of pixels replaced. Pixels that no
/// triangle of the surface covers hold `reflection`'s background. Errors: frames of
/// different sizes.
pub fn paste(main: &mut Frame, id: u32, reflection: &Frame, tint: Vec3) -> Result<u64> {
    check_size(main, reflection)?;
    let mut replaced = 0;
    for (k, color) in main.color.iter_mut().enumerate() {
        if main.ids[k] == id {
            *color = tint * reflection.color[k];
            replaced += 1;
        }
    }
    Ok(replaced)
}

/// How a lit glass reflector splits light at one main-image pixel, as the ray caster's glass
/// does at the pixel's first hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GlassSplit {
    /// Refraction weighted `1 - R` (and tinted), reflection weighted `R`: the exact Fresnel
    /// reflectance `R` at the hit.
    Fresnel(f32),
    /// Total internal reflection at the hit: the reflection alone, untinted.
    TotalReflection,
    /// The pixel's ray misses the reflector (the main view saw it at a grazing edge that the
    /// f64 test rejects): the refraction alone, tinted, as without Fresnel.
    Missed,
}

/// The Fresnel split of a glass reflector at main-image pixels: the main camera's pixel-centre
/// ray is intersected exactly with the reflector alone (a prepared scene of its parts only),
/// and the ray caster's own [`specular`] gives the reflectance at the hit, from the
/// interpolated shading normal and the side the ray arrives from. One primary ray per
/// reflector pixel; no secondary rays.
pub struct FresnelSplit {
    caster: PreparedScene,
    camera: Perspective,
}

impl FresnelSplit {
    /// The split of reflector `id` of `prepared` seen by `camera`.
    pub fn new(prepared: &PreparedScene, id: u32, camera: Perspective) -> FresnelSplit {
        FresnelSplit {
            caster: prepared.view(only(prepared.scene(), |o| o.id == id)),
            camera,
        }
    }

    /// The split at the centre of pixel `(x, y)`.
    pub fn at(&self, x: u32, y: u32) -> GlassSplit {
        let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
        let Some(ray) = self.camera.ray(centre) else {
            return GlassSplit::Missed;
        };
        let Some(hit) = self.caster.intersect(&ray) else {
            return GlassSplit::Missed;
        };
        let part = &self.caster.scene.objects[hit.object];
        let seen = normals(part, hit.triangle, hit.barycentric, ray.direction.as_vec3());
        match specular(&ray, &seen, part.material.finish).fresnel {
            Some((_, reflectance)) => GlassSplit::Fresnel(reflectance),
            None => GlassSplit::TotalReflection,
        }
    }
}

/// A lit glass reflector's image in main-image coordinates, and the rays its split cast.
pub struct FresnelMix {
    pub frame: Frame,
    pub rays: u64,
}

/// At every pixel of `main` that sees object `id`, the ray caster's glass colour made from
/// the images through the refraction and reflection surfaces: `tint (1 - R) refraction +
/// R reflection` by the pixel's [`GlassSplit`] (other pixels hold `refraction` unchanged).
/// Errors: frames of different sizes; memory that cannot be had for the mixed frame.
pub fn fresnel_mix(
    main: &Frame,
    id: u32,
    refraction: &Frame,
    reflection: &Frame,
    split: &FresnelSplit,
    tint: Vec3,
) -> Result<FresnelMix> {
    for other in [refraction, reflection] {
        check_size(main, other)?;
    }
    let width = main.width as usize;
    let mut frame = refraction.try_clone()?;
    let rays = frame
        .color
        .par_iter_mut()
        .enumerate()
        .map(|(k, color)| {
            if main.ids[k] != id {
                return 0;
            }
            let (through, mirrored) = (refraction.color[k], reflection.color[k]);
            *color = match split.at((k % width) as u32, (k / width) as u32) {
                GlassSplit::Fresnel(r) => tint * (1.0 - r) * through + r * mirrored,
                GlassSplit::TotalReflection => mirrored,
                GlassSplit::Missed => tint * through,
            };
            1
        })
        .sum();
    Ok(FresnelMix { frame, rays })
}

/// Fails unless `other` has `main`'s size.
fn check_size(main: &Frame, other: &Frame) -> Result<()> {
    if (main.width, main.height) != (other.width, other.height) {
        return Err(Error::new(format!(
            "cannot paste a {}x{} reflection into a {}x{} image",
            other.width, other.height, main.width, main.height
        )));
    }
    Ok(())
}

/// The exact reference of a reflector scene's render: `scene` without trilinear reflectors
/// (its mirrors and glass by exact secondary rays), ray cast flat through `main`.
#[cfg(test)]
pub fn exact_flat_reference(scene: &Scene, main: &dyn Projection) -> Frame {
    let mut exact = scene.clone();
    exact.trilinear_reflectors.clear();
    let options = RenderOptions {
        method: Method::Raycast,
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    crate::render::render(&PreparedScene::new(&exact), main, &options)
        .unwrap()
        .frame
}

pub mod atlas;
pub mod camera_mesh;
pub mod env_map;
pub mod main_camera;
pub mod refine;
#[cfg(test)]
mod tests;
