//! A viewing session: a scene file (or a model file in its default scene, or a built-in
//! scene), its prepared scene (built once, again only on a hot reload) and the projection
//! being edited.
//!
//! The edited projection lives as the scene's text (the file's, the model's default
//! scene's as `flexcam render MODEL` makes it, the built-in scene's), a toml_edit document
//! (comments and layout kept). Every edit is applied to a copy of the document, whose `[image]` and
//! `[projection]` are read again ([`scene::file::parse_projection`]) and built at the image
//! size; only an edit that builds replaces the session's projection, so the last valid
//! projection stays in place when an edit is refused. Since the projection is always what
//! the document's text loads to, a saved file renders, by `flexcam render`, what the
//! session shows.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use flexcam::file_read::{read_regular_text, MAX_SCENE_FILE_BYTES};
use flexcam::geometry::Ray;
use flexcam::image_io::{self, OutputSet};
use flexcam::projection::{Projection, ProjectionSpec, Projector};
use flexcam::render::PreparedScene;
use flexcam::scene::file::edit::{
    float_array, parse_document, projection_value, set_projection_value,
};
use flexcam::scene::{self, Overrides, Scene};
use flexcam::{Error, Result};
use glam::{DVec2, DVec3};
use toml_edit::{DocumentMut, Item, Value};

use flexcam::projection::CameraFrame;

/// What a session views: the source its text came from, which decides where saving may
/// write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// A scene file: saving may write back into it.
    SceneFile,
    /// A model file (.obj, .gltf, .glb, .ply) in the default scene flexcam makes for it
    /// (`flexcam render MODEL` draws the same): saving writes a new scene file naming the
    /// model, never the model.
    Model,
    /// A built-in scene (`builtin:NAME`): saving writes a new scene file.
    Builtin,
}

/// A scene open for viewing and editing its projection: a scene file, a model file in its
/// default scene, or a built-in scene.
pub struct Session {
    /// The source as given: the scene file, the model file, or `builtin:NAME`.
    path: PathBuf,
    origin: Origin,
    /// The name the text is parsed under (errors name it; relative paths resolve from its
    /// folder): the scene file, `MODEL (default scene)` beside the model, `builtin:NAME`.
    text_path: PathBuf,
    document: DocumentMut,
    prepared: Arc<PreparedScene>,
    spec: ProjectionSpec,
    projection: Arc<dyn Projection>,
    width: u32,
    height: u32,
    /// The source file's modification time when it was read (hot reload compares it; none
    /// for a built-in scene).
    modified: Option<SystemTime>,
    /// Counts the changes of the projection or the scene: the render loop's job number.
    generation: u64,
}

/// What a pixel sees: the object (1-based id and name) and the world point of the first hit.
#[derive(Debug, Clone, PartialEq)]
pub struct Pick {
    pub id: u32,
    pub name: String,
    pub point: DVec3,
}

impl Session {
    /// Opens `path`: a scene file, a model file (by its extension, in the default scene
    /// `flexcam render` makes for it) or `builtin:NAME`. Loads and prepares the scene and
    /// builds its projection.
    pub fn open(path: &Path) -> Result<Session> {
        let source = path.to_str().ok_or_else(|| {
            Error::in_file(path, "the viewer needs a scene path that is valid UTF-8")
        })?;
        let modified = modified_time(path);
        let origin = if source.starts_with("builtin:") {
            Origin::Builtin
        } else if scene::model_scene::is_model_file(path) {
            Origin::Model
        } else {
            Origin::SceneFile
        };
        let loaded = |source| -> Result<Loaded> {
            let loaded = scene::load_with(source, &Overrides::default())?;
            Ok((loaded.scene, loaded.projection, loaded.width, loaded.height))
        };
        let (text_path, text, (scene, projection, width, height)) = match origin {
            Origin::Builtin => {
                let text = scene::builtin::text(&source["builtin:".len()..])?;
                (path.to_path_buf(), text.to_string(), loaded(source)?)
            }
            // The model is read once: its scene and the scene's text together.
            Origin::Model => {
                let request = scene::ModelRequest::default();
                let (text, scene, _) = scene::model_scene::load_with_text(path, &[], &request)?;
                let text_path = scene::model_scene::text_path(path);
                (text_path, text, loaded_model(path, scene)?)
            }
            Origin::SceneFile => {
                let text = read_regular_text(path, "scene file", MAX_SCENE_FILE_BYTES)?;
                (path.to_path_buf(), text, loaded(source)?)
            }
        };
        let document = parse_document(&text, &text_path)?;
        let spec = scene.projection.clone();
        let prepared = Arc::new(PreparedScene::new(&scene));
        Ok(Session {
            path: path.to_path_buf(),
            origin,
            text_path,
            document,
            prepared,
            spec,
            projection: Arc::from(projection),
            width,
            height,
            modified,
            generation: 1,
        })
    }

    /// What the session views.
    pub fn origin(&self) -> Origin {
        self.origin
    }

    /// The scene file saving writes back into: `None` for a model or a built-in scene (they
    /// are saved as a new scene file).
    pub fn scene_file(&self) -> Option<&Path> {
        (self.origin == Origin::SceneFile).then_some(self.path.as_path())
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn prepared(&self) -> &Arc<PreparedScene> {
        &self.prepared
    }

    pub fn projection(&self) -> &Arc<dyn Projection> {
        &self.projection
    }

    pub fn spec(&self) -> &ProjectionSpec {
        &self.spec
    }

    /// The image size of the scene file.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The number of the current state: it grows with every change of the projection or
    /// the scene.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Starts a new generation without a change of the projection (the view's settings
    /// changed: the state must be rendered again).
    pub fn touch(&mut self) {
        self.generation += 1;
    }

    /// The edited scene file's text.
    pub fn document(&self) -> &DocumentMut {
        &self.document
    }

    /// The value of projection key `key` (dotted for nested tables), if set.
    pub fn value(&self, key: &str) -> Option<&Value> {
        projection_value(&self.document, key)
    }

    /// Sets projection key `key` to `value` when the projection then builds; otherwise
    /// returns why and keeps the projection as it was.
    pub fn set(&mut self, key: &str, value: Value) -> Result<()> {
        let mut document = self.document.clone();
        set_projection_value(&mut document, key, value, &self.text_path)?;
        self.apply(document)
    }

    /// Sets several keys at once (all applied, or none).
    pub fn set_all<K: AsRef<str>>(&mut self, values: &[(K, Value)]) -> Result<()> {
        let mut document = self.document.clone();
        for (key, value) in values {
            set_projection_value(&mut document, key.as_ref(), value.clone(), &self.text_path)?;
        }
        self.apply(document)
    }

    /// Reads the projection of `document` and builds it; on success it becomes the session's.
    fn apply(&mut self, document: DocumentMut) -> Result<()> {
        let text = document.to_string();
        let (image, spec) = scene::file::parse_projection(&text, &self.text_path)?;
        if (image.width, image.height) != (self.width, self.height) {
            return Err(Error::in_file(
                &self.text_path,
                "the image size changed: reload the scene to change it",
            ));
        }
        let (projection, _) = flexcam::calibrate::build(&spec, self.width, self.height)
            .map_err(|e| e.or_in_file(&self.text_path))?;
        self.document = document;
        self.spec = spec;
        self.projection = Arc::from(projection);
        self.generation += 1;
        Ok(())
    }

    /// The projection's camera frame (`position`, `look_at`, `up`), for projections that
    /// have one.
    pub fn camera(&self) -> Result<CameraFrame> {
        let vector = |key: &str| -> Option<DVec3> {
            let array = self.value(key)?.as_array()?;
            let numbers: Vec<f64> = array
                .iter()
                .map(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
                .collect::<Option<_>>()?;
            <[f64; 3]>::try_from(numbers).ok().map(DVec3::from)
        };
        match (vector("position"), vector("look_at")) {
            (Some(position), Some(look_at)) => Ok(CameraFrame {
                position,
                look_at,
                up: vector("up").unwrap_or(DVec3::Y),
            }),
            _ => Err(Error::in_file(
                &self.text_path,
                format!(
                    "the {} projection has no `position` and `look_at` to move",
                    self.spec.kind()
                ),
            )),
        }
    }

    /// Moves the camera frame by `change` (see [`crate::camera::Navigate`]); `up` is left as written.
    pub fn move_camera(&mut self, change: impl FnOnce(CameraFrame) -> CameraFrame) -> Result<()> {
        let moved = change(self.camera()?);
        self.set_all(&[
            ("position", float_array(&moved.position.to_array())),
            ("look_at", float_array(&moved.look_at.to_array())),
        ])
    }

    /// Writes the edited scene to `out` (the scene file itself, or a new file) keeping the
    /// file's comments and layout. Refused when the text would load a different projection
    /// from there (relative paths resolve from the file's folder). Never over a file the
    /// scene reads (a model, a texture): a model's session is saved as a new scene file,
    /// whose object names the model relative to `out`'s folder (by its file name beside it,
    /// else by its absolute path).
    pub fn save(&mut self, out: &Path) -> Result<()> {
        let mut document = self.document.clone();
        if self.origin == Origin::Model {
            name_model(&mut document, &self.path, out)?;
        }
        let text = document.to_string();
        let (_, spec) = scene::file::parse_projection(&text, out).map_err(|e| {
            Error::in_file(
                out,
                format!(
                    "the scene would not load from here ({e}); save it next to the original \
                     so its relative paths still resolve"
                ),
            )
        })?;
        if spec != self.spec {
            return Err(Error::in_file(
                out,
                "the scene would load a different projection from here; save it next to the \
                 original so its relative paths still resolve",
            ));
        }
        let mut outputs = OutputSet::new();
        let id = outputs.output("the saved scene", out, &["toml"])?;
        // Every file the scene reads, but the scene file itself (first of a scene file's
        // inputs), which saving may write back into.
        let own = usize::from(self.origin == Origin::SceneFile);
        for file in self.prepared.scene().inputs.iter().skip(own) {
            outputs.input(&format!("the {}", file.what), &file.path)?;
        }
        if self.origin == Origin::Model {
            outputs.input("the model file", &self.path)?;
        }
        outputs.stage(id, |tmp| image_io::write_bytes(tmp, text.as_bytes()))?;
        outputs.commit()?;
        if self.scene_file().is_some_and(|own| same_file(out, own)) {
            self.modified = modified_time(&self.path);
        }
        Ok(())
    }

    /// Reloads the whole scene when its file changed on disk since it was read: `Ok(true)`
    /// when reloaded. A file that no longer loads is reported once (until it changes again)
    /// and the session stays as it was.
    pub fn reload_if_changed(&mut self) -> Result<bool> {
        let now = modified_time(&self.path);
        if now == self.modified {
            return Ok(false);
        }
        self.modified = now;
        let reloaded = Session::open(&self.path)?;
        *self = Session {
            generation: self.generation + 1,
            ..reloaded
        };
        Ok(true)
    }

    /// The object and world point seen at pixel position `pixel` (the first hit of its
    /// projector, as the ray caster finds it); `None` where nothing is hit. Errors for a
    /// curved (Bezier) projector, whose hit the ray caster finds by its own subdivision.
    pub fn pick(&self, pixel: DVec2) -> Result<Option<Pick>> {
        let segments: Vec<Ray> = match self.projection.projector(pixel) {
            None => return Ok(None),
            Some(Projector::Straight(ray)) => vec![ray],
            Some(Projector::Polyline(points)) => points
                .windows(2)
                .map(|w| Ray {
                    t_max: 1.0,
                    ..Ray::new(w[0], w[1] - w[0])
                })
                .collect(),
            Some(Projector::QuadraticBezier(_)) => {
                return Err(Error::new(
                    "picking along curved (quadratic) projectors is not supported",
                ))
            }
        };
        let scene = self.prepared.scene();
        Ok(segments.iter().find_map(|ray| {
            let hit = self.prepared.intersect(ray)?;
            let object = &scene.objects[hit.object];
            Some(Pick {
                id: object.id,
                name: object.name.clone(),
                point: ray.at(hit.t),
            })
        }))
    }
}

/// A session (for tests) on a scene file, in a new folder, whose `[projection]` is
/// `projection`, at 40 x 30, with one sphere.
#[cfg(test)]
pub(crate) fn scratch(projection: &str) -> (tempfile::TempDir, Session) {
    let dir = tempfile::TempDir::new().unwrap();
    let path = dir.path().join("scene.toml");
    let text = format!(
        "[image]\nwidth = 40\nheight = 30\n\n[projection]\n{projection}\n\n\
         [[object]]\nshape = \"sphere\"\ntranslate = [0.0, 0.0, -2.0]\n"
    );
    std::fs::write(&path, text).unwrap();
    let session = Session::open(&path).unwrap();
    (dir, session)
}

/// A loaded scene, its projection and the image size it is built at.
type Loaded = (Scene, Box<dyn Projection>, u32, u32);

/// The scene of model file `path` checked against the memory budget, with its projection
/// built at the scene's image size (what [`scene::load_with`] does for a scene file).
fn loaded_model(path: &Path, scene: Scene) -> Result<Loaded> {
    let (width, height) = (scene.image.width, scene.image.height);
    scene::check_budget(&scene, width, height, 0).map_err(|e| e.or_in_file(path))?;
    let (projection, _) = flexcam::calibrate::build(&scene.projection, width, height)
        .map_err(|e| e.or_in_file(path))?;
    Ok((scene, projection, width, height))
}

/// Sets the `file` of `document`'s model object (the default scene's one object) to
/// `model` as seen from the folder of `out`: its file name when `out` is beside it, else its
/// absolute path.
fn name_model(document: &mut DocumentMut, model: &Path, out: &Path) -> Result<()> {
    let folder = |p: &Path| {
        let parent = p.parent().filter(|f| !f.as_os_str().is_empty());
        parent.unwrap_or(Path::new(".")).canonicalize().ok()
    };
    let absolute = model
        .canonicalize()
        .map_err(|e| Error::in_file(model, format!("cannot resolve the model's path: {e}")))?;
    let beside = folder(out).is_some_and(|f| Some(f) == absolute.parent().map(Path::to_path_buf));
    let named = if beside {
        absolute.file_name().map(PathBuf::from).unwrap_or_default()
    } else {
        absolute.clone()
    };
    let named = named.to_str().ok_or_else(|| {
        Error::in_file(
            model,
            "the model's path is not valid UTF-8: it cannot be named in a scene file",
        )
    })?;
    let file = document
        .get_mut("object")
        .and_then(Item::as_array_of_tables_mut)
        .and_then(|objects| objects.get_mut(0))
        .and_then(|object| object.get_mut("file"))
        .ok_or_else(|| Error::in_file(model, "the default scene has no model object"))?;
    *file = toml_edit::value(named);
    Ok(())
}

fn modified_time(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}
