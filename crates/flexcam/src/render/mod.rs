//! Renderers and what they produce: a [`Frame`] (colour, depth, object ids) and counters.
//!
//! The one entry point is [`render`]: a [`PreparedScene`] (built once per scene and command)
//! through a projection with [`RenderOptions`] (method, shading, samples, the methods'
//! tunings, reflector compositing, progress) gives a [`Rendered`] frame and its report.
//!
//! The renderers (the ray caster, `raster`, `trilinear`, camera triangles, reflector
//! compositing) and what they share (the scan converter, shading, the BVH) are private
//! modules; this module re-exports what a program needs: the entry point and its types, each
//! method's options ([`Subdivision`], [`CurveOptions`], [`CameraTriangleOptions`]), the
//! prepared scene's queries ([`PreparedScene::intersect`], [`Hit`]), frame comparison
//! ([`compare`]) and photo reprojection ([`reproject`]). The bench scenes and the stages the
//! benches time apart are in `bench_support`, with the `workloads` feature only.

use std::collections::BTreeMap;

use glam::Vec3;

use crate::error::Result;
use crate::projection::trilinear_builders::Optic;
use crate::projection::Projection;
use crate::try_alloc;

/// How surfaces are shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shading {
    /// The base colour of the first surface hit, mirrors and glass passing the ray on (the
    /// exact contract of the scene-and-CLI spec).
    Flat,
    /// Lambert + Phong with hard shadows, recursive reflection and refraction with Fresnel.
    #[default]
    Lit,
    /// Displaced objects shaded by the per-ray transition system (BRDF, redistributed bump,
    /// displacement), or coloured by the method chosen; `--method raycast` only (module
    /// `transitions`).
    Transitions(TransitionShading),
}

/// What [`render`] does: the method and everything that tunes it.
#[derive(Clone, Copy)]
pub struct RenderOptions<'a> {
    /// The renderer (`--method`).
    pub method: Method,
    /// Composite the scene's trilinear reflectors (scene key `trilinear_reflector`) into the
    /// main view, each reflection rendered by `method` (module `composite`); `false` renders them
    /// as the method's own mirrors and glass (the reference of a comparison).
    pub composite_reflectors: bool,
    /// With composited reflectors, ray cast exactly the reflector pixels that no triangle of
    /// the reflection surface covers (its silhouette's gaps, its back); `false` leaves them
    /// as they are without it (the background of the image through the surface, or the
    /// reflector's own colour where it has no surface), so that a measurement sees what the
    /// surface alone renders (`flexcam bench camera-triangles --figure 6`).
    pub cast_reflector_gaps: bool,
    /// How surfaces are shaded (`--shading`).
    pub shading: Shading,
    /// Samples per pixel (1 = one ray through each pixel centre).
    pub spp: u32,
    /// Maximum number of specular bounces.
    pub max_bounces: u32,
    /// How method `raster` subdivides triangles (other methods ignore it).
    pub subdivision: Subdivision,
    /// How method trilinear follows curved edges.
    pub curves: CurveOptions,
    /// The buffers the caller wants besides colour; the others come back empty.
    pub outputs: Outputs,
    /// The bound and culling of method camera-triangles.
    pub camera_triangles: CameraTriangleOptions,
    /// Called from worker threads with (work units done, total) as rendering progresses.
    pub progress: Option<&'a (dyn Fn(u64, u64) + Sync)>,
    /// Render only this rectangle of the image (`--crop`): the frame is that rectangle of
    /// the whole frame, byte for byte (module `window`). `None`: the whole image.
    pub crop: Option<PixelWindow>,
}

impl Default for RenderOptions<'_> {
    fn default() -> Self {
        RenderOptions {
            method: Method::Raycast,
            composite_reflectors: true,
            cast_reflector_gaps: true,
            shading: Shading::Lit,
            spp: 1,
            max_bounces: 8,
            subdivision: Subdivision::default(),
            curves: CurveOptions::ADAPTIVE,
            outputs: Outputs::ALL,
            camera_triangles: CameraTriangleOptions::default(),
            progress: None,
            crop: None,
        }
    }
}

/// Which of a frame's buffers besides colour a caller wants ([`RenderOptions::outputs`]);
/// the unwanted ones come back empty. The ray caster neither allocates nor fills them
/// (a colour-only frame is 12 bytes a pixel instead of 20); raster and trilinear resolve
/// depth and ids in the same pass as colour (their depth test needs them), and drop the
/// unwanted buffers at the end. Reflector compositing renders the reflected images in
/// colour only, and the main view's ids whatever the caller wants (it finds the
/// reflector's pixels by them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outputs {
    /// [`Frame::depth`].
    pub depth: bool,
    /// [`Frame::ids`].
    pub ids: bool,
    /// [`Frame::surface`]: normals, world position and texture coordinates, derived after
    /// the method has drawn the frame from its ids and depth (module `surface`), so that no
    /// renderer does per-pixel work for them.
    pub surface: bool,
    /// [`Rendered::atlases`]: the joint texture atlas of every trilinear reflector with
    /// `reflection = "atlas"`, as rendered (kept rather than dropped after the final pass).
    pub atlases: bool,
}

impl Outputs {
    /// Colour, depth and object ids (not the surface layers, which cost a pass of their own).
    pub const ALL: Outputs = Outputs {
        depth: true,
        ids: true,
        surface: false,
        atlases: false,
    };
    /// Colour alone.
    pub const COLOR: Outputs = Outputs {
        depth: false,
        ids: false,
        surface: false,
        atlases: false,
    };

    /// The length of a buffer of `pixels` pixels: `pixels` if `wanted`, else 0.
    fn len(wanted: bool, pixels: usize) -> usize {
        if wanted {
            pixels
        } else {
            0
        }
    }
}

/// A rendered image with its arbitrary output variables, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB.
    pub color: Vec<Vec3>,
    /// Distance from the projector's origin to the first hit, along the projector;
    /// `f32::INFINITY` where nothing is hit. Empty when not wanted ([`Outputs`]).
    pub depth: Vec<f32>,
    /// Object id of the first hit, 0 for background. Empty when not wanted ([`Outputs`]).
    pub ids: Vec<u32>,
    /// The surface each pixel shows (normals, position, uv; [`SurfacePoint`]). Empty when
    /// not wanted ([`Outputs::surface`]).
    pub surface: Vec<SurfacePoint>,
}

impl Frame {
    /// A frame filled with `background`, infinite depth and id 0. Panics when the memory
    /// cannot be had; a frame whose size comes from the input is made by
    /// [`Frame::try_new`].
    pub fn new(width: u32, height: u32, background: Vec3) -> Self {
        Frame::try_new(width, height, background).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`Frame::new`] that fails, naming the bytes asked for, when the memory cannot be had
    /// (module `try_alloc`).
    pub fn try_new(width: u32, height: u32, background: Vec3) -> Result<Self> {
        let n = width as usize * height as usize;
        let what = || frame_name(width, height);
        Ok(Frame {
            width,
            height,
            color: try_alloc::filled(n, background, what)?,
            depth: try_alloc::filled(n, f32::INFINITY, what)?,
            ids: try_alloc::zeroed(n, what)?,
            surface: Vec::new(),
        })
    }

    /// A copy of this frame that fails, naming the bytes asked for, when the memory cannot be
    /// had (module `try_alloc`).
    pub(crate) fn try_clone(&self) -> Result<Frame> {
        let what = || frame_name(self.width, self.height);
        Ok(Frame {
            width: self.width,
            height: self.height,
            color: try_alloc::copied(&self.color, what)?,
            depth: try_alloc::copied(&self.depth, what)?,
            ids: try_alloc::copied(&self.ids, what)?,
            surface: try_alloc::copied(&self.surface, what)?,
        })
    }

    /// A frame of zero bits in every channel (black, depth 0, id 0), for a renderer that
    /// then overwrites every pixel. The buffers come zeroed from the allocator
    /// (`alloc_zeroed`), so a frame-sized allocation of fresh memory is zero pages that no
    /// clearing pass writes: their first touch (page faults) is the renderer's own writes,
    /// in the threads that make them, and the 20 bytes a pixel are written once, not twice
    /// (memory the allocator reuses is cleared by it, in the calling thread).
    /// Large buffers are mapped with transparent huge pages where the system allows
    /// ([`huge_pages::advise_huge_pages`]): far fewer page faults on that first touch.
    /// Only the buffers `outputs` asks for are allocated (the others are empty).
    /// Fails, naming the bytes asked for, when the memory cannot be had (module `try_alloc`).
    pub(crate) fn zeroed(width: u32, height: u32, outputs: Outputs) -> Result<Self> {
        let n = width as usize * height as usize;
        let what = || frame_name(width, height);
        let mut frame = Frame {
            width,
            height,
            color: try_alloc::zeroed(n, what)?,
            depth: try_alloc::zeroed(Outputs::len(outputs.depth, n), what)?,
            ids: try_alloc::zeroed(Outputs::len(outputs.ids, n), what)?,
            surface: Vec::new(),
        };
        huge_pages::advise_huge_pages(&mut frame.color);
        huge_pages::advise_huge_pages(&mut frame.depth);
        huge_pages::advise_huge_pages(&mut frame.ids);
        Ok(frame)
    }

    /// Makes this frame `width` x `height` with the buffers of `outputs` for a renderer that
    /// overwrites every pixel: a frame of that size and those buffers (each holding
    /// `width * height` pixels, the unwanted ones empty) is kept as it is, contents and all,
    /// so a caller drawing frame after frame pays neither its allocation nor the first touch
    /// of its pages again; any other is replaced by [`Frame::zeroed`]. On failure (no
    /// memory) the frame is left as it was.
    pub(crate) fn fit(&mut self, width: u32, height: u32, outputs: Outputs) -> Result<()> {
        let n = width as usize * height as usize;
        let fits = (self.width, self.height) == (width, height)
            && [self.color.len(), self.depth.len(), self.ids.len()]
                == [
                    n,
                    Outputs::len(outputs.depth, n),
                    Outputs::len(outputs.ids, n),
                ];
        if !fits {
            *self = Frame::zeroed(width, height, outputs)?;
        }
        Ok(())
    }

    /// Drops the buffers `outputs` does not ask for.
    fn keep_only(&mut self, outputs: Outputs) {
        if !outputs.depth {
            self.depth = Vec::new();
        }
        if !outputs.ids {
            self.ids = Vec::new();
        }
        if !outputs.surface {
            self.surface = Vec::new();
        }
    }
}

/// How the errors of a failed buffer allocation name a frame-sized buffer.
pub(crate) fn frame_name(width: u32, height: u32) -> String {
    format!("the {width} x {height} frame")
}

/// A rendered frame and what rendering it counted.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    /// The image and its buffers.
    pub frame: Frame,
    /// The method's counters (rays cast, build times, ...), for `--stats`; with reflectors
    /// composited, also the compositing's (`reflector_pixels` and the like).
    pub counters: Stats,
    /// What the user should be told about this frame (none when everything asked held).
    pub warnings: Vec<RenderWarning>,
    /// The reflectors' texture atlases, in the order of the scene's trilinear reflectors
    /// (with `Outputs::atlases`; otherwise empty).
    pub atlases: Vec<AtlasImage>,
}

/// The joint texture atlas of one trilinear reflector as rendered (docs/camera-triangles.md,
/// "The joint texture atlas"): each camera triangle's image in its right triangle, the
/// background between them.
#[derive(Debug, Clone, PartialEq)]
pub struct AtlasImage {
    /// The reflector's object id.
    pub id: u32,
    /// The light path rendered into it: the reflection, or for glass the refraction (and,
    /// in lit shading, a second atlas of its Fresnel reflection).
    pub optic: Optic,
    /// The atlas, colour only, `atlas_width` x `atlas_height` texels (`--stats`).
    pub image: Frame,
}

/// Renders `prepared` through `projection` as `options` say: the one entry point of every
/// method. Fails, rather than producing a wrong image, when the method cannot render that
/// projection (with one line naming why), on zero samples per pixel, on a crop window that
/// is empty or does not fit in the image, or when the memory of a frame-sized buffer cannot
/// be had (the bytes and the buffer named: module `try_alloc`).
///
/// ```
/// use flexcam::render::{self, Method, PreparedScene, RenderOptions, Shading};
///
/// let scene = flexcam::scene::load("builtin:cube-floor")?;
/// let projection = scene.projection.build(40, 30)?;
/// let prepared = PreparedScene::new(&scene);
/// let options = RenderOptions { shading: Shading::Flat, ..RenderOptions::default() };
/// let rendered = render::render(&prepared, projection.as_ref(), &options)?;
/// assert_eq!((rendered.frame.width, rendered.frame.height), (40, 30));
/// assert!(rendered.frame.ids.iter().any(|&id| id != 0), "the view sees the scene");
///
/// // A method that cannot render the projection fails with a reason, never a wrong image.
/// let trilinear = RenderOptions { method: Method::Trilinear, ..options };
/// assert!(render::render(&prepared, projection.as_ref(), &trilinear).is_err());
/// # Ok::<(), flexcam::Error>(())
/// ```
pub fn render(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
) -> Result<Rendered> {
    let wanted = options.outputs;
    if !wanted.surface {
        return render_buffers(prepared, projection, options);
    }
    // The surface layers are found from the method's own ids and depth.
    let buffers = RenderOptions {
        outputs: Outputs {
            depth: true,
            ids: true,
            surface: false,
            ..wanted
        },
        ..*options
    };
    let mut rendered = render_buffers(prepared, projection, &buffers)?;
    let window = (options.crop)
        .unwrap_or_else(|| PixelWindow::whole(rendered.frame.width, rendered.frame.height));
    let (surface, unresolved) =
        surface::layers(prepared, projection, &rendered.frame, window, options.spp)?;
    rendered.frame.surface = surface;
    rendered
        .counters
        .insert("surface_unresolved", Counter::Count(unresolved));
    rendered.frame.keep_only(wanted);
    Ok(rendered)
}

/// [`render`] of the colour, depth and id buffers (`options.outputs.surface` is not read).
fn render_buffers(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
) -> Result<Rendered> {
    if let Some(window) = options.crop {
        window.check(projection.resolution())?;
        // Only the plain ray caster renders a window's pixels alone (module `window`).
        let raycast_alone = options.method == Method::Raycast
            && !matches!(options.shading, Shading::Transitions(_))
            && (!options.composite_reflectors || prepared.scene().trilinear_reflectors.is_empty())
            && !caustics::wanted(prepared.scene(), options);
        if !raycast_alone {
            let whole = RenderOptions {
                crop: None,
                ..*options
            };
            let mut rendered = render_buffers(prepared, projection, &whole)?;
            rendered.frame = window.cut(&rendered.frame)?;
            return Ok(rendered);
        }
    }
    // Caustics are splatted where the main view's ids and depth show their receivers.
    let caustics = caustics::wanted(prepared.scene(), options);
    let wanted_outputs = options.outputs;
    let main_options = RenderOptions {
        outputs: if caustics {
            Outputs::ALL
        } else {
            options.outputs
        },
        ..*options
    };
    let options = &main_options;
    let mut rendered = if options.composite_reflectors {
        composite::render(prepared, projection, options)?
    } else {
        let (frame, counters) = options.method.render(prepared, projection, options)?;
        Rendered {
            frame,
            counters,
            warnings: Vec::new(),
            atlases: Vec::new(),
        }
    };
    if caustics {
        caustics::add(prepared, projection, options, &mut rendered)?;
    }
    rendered.frame.keep_only(wanted_outputs);
    Ok(rendered)
}

/// A colour image in linear RGB, rows from the top: a photo to reproject
/// ([`Photo`]), as `image_io` reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB, row-major, top row first.
    pub pixels: Vec<Vec3>,
}

/// One counter of a renderer's statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Counter {
    /// A number of things (rays, triangles, pixels).
    Count(u64),
    /// A measure (milliseconds, a ratio).
    Value(f64),
}

/// Named counters a renderer reports (rays cast, build times, ...), for `--stats`.
pub type Stats = BTreeMap<&'static str, Counter>;
#[cfg(feature = "workloads")]
pub mod bench_support;
pub(crate) mod bvh;
mod camera_triangles;
/// Caustics of curved mirrors (scene key `caustics`), added in `lit` shading by [`render`].
mod caustics;
mod compare;
/// Reflector compositing, reached only through [`render`] (`RenderOptions::composite_reflectors`).
mod composite;
mod displaced;
mod huge_pages;
mod method;
mod prepared;
mod raster;
mod raycast;
mod reproject;
mod scan;
mod shading;
mod stmap;
mod surface;
mod transitions;
mod trilinear;
mod warning;
mod window;

pub use camera_triangles::{Bound as CameraTriangleBound, Options as CameraTriangleOptions};
pub use compare::{compare, interior_id_agreement, Comparison};
pub use displaced::LodSelection;
pub use method::Method;
pub use prepared::{Hit, PreparedScene};
pub use raster::{recycle_frame, Subdivision};
pub use raycast::{pick, Picked};
pub use reproject::{reproject, Photo, PhotoProjection, PHOTO_PROJECTION_NAMES};
pub use stmap::{st_map, StMap, StPoints};
pub use surface::SurfacePoint;
pub use transitions::{TransitionMethod, TransitionShading};
pub use trilinear::{CurveMode, CurveOptions};
pub use warning::RenderWarning;
pub use window::PixelWindow;

// What the tests of the projection layer check against a renderer.
#[cfg(test)]
pub(crate) use raster::supported_chart;
#[cfg(test)]
pub(crate) use shading::normals;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene;

    fn flat(method: Method) -> RenderOptions<'static> {
        RenderOptions {
            method,
            shading: Shading::Flat,
            ..RenderOptions::default()
        }
    }

    /// The entry point refuses what a method cannot render with the method's own line, and
    /// zero samples per pixel, composited or not.
    #[test]
    fn refuses_what_the_method_cannot_render() {
        let scene = scene::load("builtin:cube-floor").unwrap();
        let projection = scene.projection.build(8, 8).unwrap();
        let prepared = PreparedScene::new(&scene);
        for composite_reflectors in [true, false] {
            let render = |options: RenderOptions| {
                let options = RenderOptions {
                    composite_reflectors,
                    ..options
                };
                render(&prepared, projection.as_ref(), &options)
                    .unwrap_err()
                    .to_string()
            };
            assert_eq!(
                render(flat(Method::Trilinear)),
                format!(
                    "the trilinear method renders only trilinear projections, not a {} \
                     projection",
                    projection.kind()
                )
            );
            assert_eq!(
                render(RenderOptions {
                    spp: 4,
                    ..flat(Method::Raster)
                }),
                "method raster renders one sample per pixel; got --spp 4 (use --spp 1, or \
                 --method raycast for more samples)"
            );
            assert_eq!(
                render(RenderOptions {
                    spp: 0,
                    ..flat(Method::Raycast)
                }),
                "samples per pixel must be at least 1"
            );
        }
    }

    /// A caller asking for fewer outputs gets the same colour and the buffers it asked for,
    /// the others empty, by every method, with reflectors composited or not.
    #[test]
    fn unwanted_outputs_come_back_empty() {
        let scene = scene::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/reflect-sphere-cube.toml"
        ))
        .unwrap();
        let main = scene.projection.build(32, 24).unwrap();
        let prepared = PreparedScene::new(&scene);
        for (method, composite_reflectors) in [
            (Method::Raycast, true),
            (Method::Raycast, false),
            (Method::Raster, false),
            (Method::Trilinear, true),
        ] {
            let options = |outputs| RenderOptions {
                method,
                composite_reflectors,
                outputs,
                ..RenderOptions::default()
            };
            let all = render(&prepared, main.as_ref(), &options(Outputs::ALL)).unwrap();
            assert_eq!(all.frame.depth.len(), 32 * 24);
            for (depth, ids) in [(false, false), (true, false), (false, true)] {
                let wanted = Outputs {
                    depth,
                    ids,
                    ..Outputs::COLOR
                };
                let got = render(&prepared, main.as_ref(), &options(wanted)).unwrap();
                let what = format!("{method} {composite_reflectors} {wanted:?}");
                assert_eq!(got.frame.color, all.frame.color, "{what}");
                let depth_want = if depth {
                    all.frame.depth.clone()
                } else {
                    vec![]
                };
                assert_eq!(got.frame.depth, depth_want, "{what}");
                let ids_want = if ids { all.frame.ids.clone() } else { vec![] };
                assert_eq!(got.frame.ids, ids_want, "{what}");
            }
        }
    }

    /// Reflector compositing is an option of the entry point: with it the reflector's pixels
    /// are replaced (counted in `reflector_pixels`), without it the reflector is the method's
    /// own mirror, exactly [`Method::render`]'s frame. Both renders share one prepared scene
    /// and its one BVH: the compositing's parts of the scene are views of it.
    #[test]
    fn compositing_is_an_option_giving_the_composite_frame() {
        let scene = scene::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/reflect-sphere-cube.toml"
        ))
        .unwrap();
        assert!(!scene.trilinear_reflectors.is_empty());
        let main = scene.projection.build(48, 36).unwrap();
        let prepared = PreparedScene::new(&scene);
        let options = flat(Method::Raycast);
        let Rendered {
            frame, counters, ..
        } = render(&prepared, main.as_ref(), &options).unwrap();
        assert!(matches!(counters["reflector_pixels"], Counter::Count(n) if n > 0));
        assert_eq!(prepared.bvh_builds(), 1);
        let plain = RenderOptions {
            composite_reflectors: false,
            ..options
        };
        let mirror = render(&prepared, main.as_ref(), &plain).unwrap();
        assert_eq!(
            mirror.frame,
            Method::Raycast
                .render(&prepared, main.as_ref(), &plain)
                .unwrap()
                .0
        );
        assert_ne!(mirror.frame.color, frame.color);
        assert!(!mirror.counters.contains_key("reflectors"));
        assert_eq!(prepared.bvh_builds(), 1);
    }
}
