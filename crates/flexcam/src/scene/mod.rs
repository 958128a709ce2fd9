//! The scene model: objects (a world-space mesh and a material), lights, image settings and
//! the projection named by the scene, with loaders for model files, built-in shapes and
//! scenes, and the TOML scene-file format.

pub mod displacement;
mod light;
mod material;
mod mesh;
mod motion;
pub mod texel;

pub use displacement::DisplacementSpec;
pub use light::Light;
pub use material::{Finish, Material, Pattern, Texture};
pub use mesh::Mesh;
pub use motion::{ObjectMotion, Orbit};

use std::path::PathBuf;
use std::sync::Arc;

use glam::{Affine3A, Vec3};

use crate::projection::trilinear_builders::{SurfaceRays, SurfaceScreenMap};
use crate::projection::ProjectionSpec;

/// One object of a scene. Its id (1-based, in file order; 0 is the background) is what the
/// `--ids` image holds.
#[derive(Debug, Clone)]
pub struct Object {
    /// The object's id: 1-based in file order, 0 being the background.
    pub id: u32,
    /// The scene file's `name`, or else the shape's (`sphere`, `mesh`, ...); for messages.
    pub name: String,
    /// The mesh, already transformed into world space. Shared: copies of a scene (a prepared
    /// scene's own, the views reflector compositing renders) share every mesh instead of
    /// copying it; `Arc::make_mut` edits one copy's mesh alone.
    pub mesh: Arc<Mesh>,
    /// Colour, pattern and finish of the whole object.
    pub material: Material,
    /// World to object space, for patterns defined in object space (the checker).
    pub world_to_object: Affine3A,
    /// Displacement of the mesh's triangles (scene key `displacement`): the mesh then has
    /// texture coordinates and vertex normals, and renderers see its micro-geometry.
    pub displacement: Option<Arc<DisplacementSpec>>,
}

/// Image settings of a scene; CLI flags override them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Linear RGB of pixels whose ray hits nothing (or that no projector covers).
    pub background: Vec3,
    /// Samples per pixel a command renders with unless told otherwise (`--spp`).
    pub spp: u32,
}

impl ImageSettings {
    /// The image size with the caller's `width` and `height` (`None` keeps the scene's):
    /// one side alone keeps the scene's aspect ratio, the other side rounded to the nearest
    /// pixel (at least 1).
    pub fn size_with(&self, width: Option<u32>, height: Option<u32>) -> (u32, u32) {
        // round(a * b / c) in integers, at least 1.
        let scaled = |a: u32, b: u32, c: u32| {
            let exact = (u64::from(a) * u64::from(b) + u64::from(c) / 2) / u64::from(c);
            u32::try_from(exact).unwrap_or(u32::MAX).max(1)
        };
        match (width, height) {
            (Some(w), Some(h)) => (w, h),
            (Some(w), None) => (w, scaled(w, self.height, self.width)),
            (None, Some(h)) => (scaled(h, self.width, self.height), h),
            (None, None) => (self.width, self.height),
        }
    }
}

impl Default for ImageSettings {
    fn default() -> Self {
        ImageSettings {
            width: 800,
            height: 600,
            background: Vec3::ZERO,
            spp: 1,
        }
    }
}

/// A loaded scene: everything a renderer needs, plus the projection the scene asks for.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Every object, in id order.
    pub objects: Vec<Object>,
    /// The lights of `lit` shading.
    pub lights: Vec<Light>,
    /// Size, background and samples per pixel.
    pub image: ImageSettings,
    /// The projection the scene names, to be built at an image size.
    pub projection: ProjectionSpec,
    /// The folder relative paths in the scene (models, textures, projection surfaces) are
    /// resolved against; `None` for built-in scenes.
    pub base_dir: Option<PathBuf>,
    /// The mirror and glass objects whose reflection or refraction is rendered through a
    /// trilinear surface and composited into the main image (scene-file key
    /// `trilinear_reflector`; composited by [`crate::render::render`]). Empty: plain rendering.
    pub trilinear_reflectors: Vec<TrilinearReflector>,
    /// The mirrors that focus the scene's point lights into caustics on the surfaces they
    /// light (scene-file key `caustics`; added in `lit` shading by [`crate::render::render`]).
    /// Empty: no caustics.
    pub caustics: Vec<CausticReflector>,
    /// The objects that move over an animation's time (scene-file key `orbit`); a render
    /// shows time 0, `flexcam animate` each frame's [`Scene::at_time`]. Empty: a still scene.
    pub motions: Vec<ObjectMotion>,
    /// Every file the scene was read from (the scene file, models and the files they name,
    /// textures, surfaces), so that a command can refuse to write over any of them. Empty
    /// for built-in scenes (they name no files) and scenes built in code.
    pub inputs: Vec<InputFile>,
}

/// A file a scene was read from, and what it was to the scene.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputFile {
    /// What the file is, for messages: "scene file", "model file", "material library",
    /// "texture", "model buffer", "trilinear surface".
    pub what: &'static str,
    /// The file's path, as the scene resolved it.
    pub path: PathBuf,
}

/// A mirror or glass object rendered through a trilinear surface (Vallance 2005, chapter 7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrilinearReflector {
    /// The object's id.
    pub id: u32,
    /// How the surface maps main-image pixels to its triangles (scene-file key
    /// `trilinear_screen_map`).
    pub screen_map: SurfaceScreenMap,
    /// The surface's refinement tolerance in main-image pixels, 0 for none (scene-file key
    /// `trilinear_refine_px`; used by the reflector compositing of [`crate::render::render`]).
    pub refine_px: f64,
    /// The size of the reflector's camera mesh (scene-file key `camera_triangles`): a
    /// simplification of its mesh to this many triangles, used as it is; `None` chooses
    /// the size automatically and refines the result by [`Self::refine_px`]
    /// (docs/camera-triangles.md).
    pub camera_triangles: Option<usize>,
    /// How the image through the reflector's surface is made (scene-file key `reflection`).
    pub reflection: ReflectionImage,
    /// The rays of the reflector's surface (scene-file key `camera_rays`): the vertex rays
    /// interpolated (the default), or per fragment, the eye's ray reflected about the
    /// interpolated vertex normals (mirrors; docs/camera-triangles.md).
    pub camera_rays: SurfaceRays,
}

/// How a trilinear reflector's reflection (refraction) image is made (scene-file key
/// `reflection`; docs/camera-triangles.md).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ReflectionImage {
    /// Rendered through the surface in main-image pixels (`"surface"`, the default).
    #[default]
    Surface,
    /// An environment cube map rendered from the reflector's centre, looked up along the
    /// surface's rays (`"env-map"`): the baseline camera triangles are measured against.
    EnvMap,
    /// Rendered through the surface into the joint texture atlas of its camera triangles,
    /// which is then mapped onto the reflector by normal shooting (`"atlas"`).
    Atlas,
}

/// A mirror whose reflection of each point light is rendered as a caustic (Hou, Wei, Shum and
/// Guo 2006, section 3.3; docs/camera-triangles.md, "Caustics").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CausticReflector {
    /// The mirror's object id.
    pub id: u32,
    /// The side of the square photon-location map rendered from each light (scene-file key
    /// `caustic_map`).
    pub map_size: u32,
}

impl CausticReflector {
    /// The default of [`CausticReflector::map_size`].
    pub const DEFAULT_MAP_SIZE: u32 = 256;
    /// The bounds of [`CausticReflector::map_size`].
    pub const MAP_SIZES: std::ops::RangeInclusive<u32> = 8..=2048;
}

impl TrilinearReflector {
    /// The default of [`TrilinearReflector::refine_px`] (docs/trilinear-surfaces.md).
    pub const DEFAULT_REFINE_PX: f64 = 0.5;

    /// Object `id` with the default screen map and refinement.
    pub fn new(id: u32) -> TrilinearReflector {
        TrilinearReflector {
            id,
            screen_map: SurfaceScreenMap::default(),
            refine_px: Self::DEFAULT_REFINE_PX,
            camera_triangles: None,
            reflection: ReflectionImage::Surface,
            camera_rays: SurfaceRays::Interpolated,
        }
    }
}

impl Scene {
    /// Total number of triangles over all objects.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.mesh.triangle_count()).sum()
    }
}

pub mod budget;
pub mod builtin;
pub mod file;
mod loaded;
pub mod loaders;
pub mod model_scene;
pub mod model_view;
#[cfg(test)]
pub(crate) mod reflector_fixtures;
pub mod shapes;

pub use file::validate_resolution;
pub use loaded::{check_budget, load_with, LoadedScene, Overrides};
pub use model_scene::ModelRequest;

/// Loads a scene from `source`: `builtin:NAME` names a built-in scene, a path with a model
/// file's extension (.obj, .gltf, .glb, .ply) a model seen by its default scene
/// ([`model_scene`]), anything else is the path of a scene file. This is the SCENE argument
/// of `flexcam render`.
pub fn load(source: &str) -> crate::Result<Scene> {
    load_defined(source, &[])
}

/// [`load`] with `definitions` (`-D KEY=VALUE`) written into the scene's text, as if the
/// file said so ([`file::parse_defined`]).
pub fn load_defined(source: &str, definitions: &[file::Definition]) -> crate::Result<Scene> {
    load_requested(source, definitions, &ModelRequest::default())
}

/// [`load_defined`], with the image size and camera a model file's default scene is made
/// for (`request`; naming a camera is an error for the other sources).
pub fn load_requested(
    source: &str,
    definitions: &[file::Definition],
    request: &ModelRequest,
) -> crate::Result<Scene> {
    match source.strip_prefix("builtin:") {
        Some(name) => {
            request.refuse_camera(source)?;
            builtin::load_defined(name, definitions)
        }
        None => {
            load_file(std::path::Path::new(source), definitions, request).map(|(scene, _)| scene)
        }
    }
}

/// The scene of the file at `path`, a model ([`model_scene::load`]) or a scene file
/// ([`file::load_animated_defined`]), with the keyframed camera of its `[animation]` table.
pub fn load_file(
    path: &std::path::Path,
    definitions: &[file::Definition],
    request: &ModelRequest,
) -> crate::Result<(Scene, Option<crate::projection::flexible::Animation>)> {
    if model_scene::is_model_file(path) {
        return model_scene::load(path, definitions, request);
    }
    request.refuse_camera(&path.display().to_string())?;
    file::load_animated_defined(path, definitions)
}
