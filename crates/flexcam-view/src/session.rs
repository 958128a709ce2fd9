//! A viewing session: a scene file, its prepared scene (built once, again only on a hot
//! reload) and the projection being edited.
//!
//! The edited projection lives as the scene file's text, a toml_edit document (comments and
//! layout kept). Every edit is applied to a copy of the document, whose `[image]` and
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
use flexcam::scene::{self, Overrides};
use flexcam::{Error, Result};
use glam::{DVec2, DVec3};
use toml_edit::{DocumentMut, Value};

use flexcam::projection::CameraFrame;

/// A scene file open for viewing and editing its projection.
pub struct Session {
    path: PathBuf,
    document: DocumentMut,
    prepared: Arc<PreparedScene>,
    spec: ProjectionSpec,
    projection: Arc<dyn Projection>,
    width: u32,
    height: u32,
    /// The scene file's modification time when it was read (hot reload compares it).
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
    /// Opens the scene file at `path`: loads and prepares the scene, builds its projection.
    /// A model file is refused: the session edits a scene file's text.
    pub fn open(path: &Path) -> Result<Session> {
        if scene::model_scene::is_model_file(path) {
            return Err(Error::in_file(
                path,
                "the viewer opens scene files (.toml): render a model with `flexcam render`, \
                 or view a scene that names it (shape = \"mesh\", file = ...)",
            ));
        }
        let source = path.to_str().ok_or_else(|| {
            Error::in_file(
                path,
                "the viewer needs a scene file path that is valid UTF-8",
            )
        })?;
        let modified = modified_time(path);
        let text = read_regular_text(path, "scene file", MAX_SCENE_FILE_BYTES)?;
        let document = parse_document(&text, path)?;
        let loaded = scene::load_with(source, &Overrides::default())?;
        let spec = loaded.scene.projection.clone();
        let prepared = Arc::new(PreparedScene::new(&loaded.scene));
        Ok(Session {
            path: path.to_path_buf(),
            document,
            prepared,
            spec,
            projection: Arc::from(loaded.projection),
            width: loaded.width,
            height: loaded.height,
            modified,
            generation: 1,
        })
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
        set_projection_value(&mut document, key, value, &self.path)?;
        self.apply(document)
    }

    /// Sets several keys at once (all applied, or none).
    pub fn set_all<K: AsRef<str>>(&mut self, values: &[(K, Value)]) -> Result<()> {
        let mut document = self.document.clone();
        for (key, value) in values {
            set_projection_value(&mut document, key.as_ref(), value.clone(), &self.path)?;
        }
        self.apply(document)
    }

    /// Reads the projection of `document` and builds it; on success it becomes the session's.
    fn apply(&mut self, document: DocumentMut) -> Result<()> {
        let text = document.to_string();
        let (image, spec) = scene::file::parse_projection(&text, &self.path)?;
        if (image.width, image.height) != (self.width, self.height) {
            return Err(Error::in_file(
                &self.path,
                "the image size changed: reload the scene to change it",
            ));
        }
        let (projection, _) = flexcam::calibrate::build(&spec, self.width, self.height)
            .map_err(|e| e.or_in_file(&self.path))?;
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
                &self.path,
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
    /// scene reads (a model, a texture).
    pub fn save(&mut self, out: &Path) -> Result<()> {
        let text = self.document.to_string();
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
        for file in self.prepared.scene().inputs.iter().skip(1) {
            outputs.input(&format!("the {}", file.what), &file.path)?;
        }
        outputs.stage(id, |tmp| image_io::write_bytes(tmp, text.as_bytes()))?;
        outputs.commit()?;
        if same_file(out, &self.path) {
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

fn modified_time(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}
