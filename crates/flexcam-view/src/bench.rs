//! The viewer's frame rate while a parameter is dragged: the render loop driven as the
//! window drives it, one projection edit per frame, each frame waited for until its first
//! (fast) stage is shown (`flexcam bench view`).

use std::path::Path;
use std::time::Instant;

use flexcam::scene::file::edit::parse_document;
use flexcam::{Error, Result};
use toml_edit::{value, Value};

use crate::camera::Navigate;
use crate::render_loop::Settings;
use crate::viewer::Viewer;

/// What a drag measured.
#[derive(Debug, Clone, PartialEq)]
pub struct DragReport {
    pub frames: usize,
    /// Wall time from the first edit to the last frame shown, in milliseconds.
    pub total_ms: f64,
    /// The stage (method) the frames were shown by.
    pub label: String,
}

impl DragReport {
    pub fn fps(&self) -> f64 {
        self.frames as f64 / (self.total_ms / 1e3)
    }
}

/// Scene-file text `text` at image size `width` x `height`, with projection keys `keys` set
/// (each as in a scene file; other keys of the projection removed when `replace` is true).
pub fn scene_variant(
    text: &str,
    (width, height): (u32, u32),
    keys: &[(&str, Value)],
    replace: bool,
) -> Result<String> {
    let mut document = parse_document(text, Path::new("variant.toml"))?;
    document["image"]["width"] = value(i64::from(width));
    document["image"]["height"] = value(i64::from(height));
    let projection = document["projection"]
        .as_table_mut()
        .ok_or_else(|| Error::new("the scene has no [projection] table"))?;
    if replace {
        projection.clear();
    }
    for (key, v) in keys {
        projection[*key] = toml_edit::Item::Value(v.clone());
    }
    Ok(document.to_string())
}

/// Opens the scene file at `path` with `settings`, waits for its first refinement, then sets
/// projection key `key` to each of `values` in turn, waiting after each for the frame's
/// first stage.
pub fn drag(path: &Path, settings: Settings, key: &str, values: &[f64]) -> Result<DragReport> {
    frames(path, settings, values.len(), |viewer, k| {
        viewer.set(key, Value::from(values[k]))
    })
}

/// Opens the scene file at `path` with `settings`, waits for its first refinement, then drags handle
/// `name` by (`dx`, `dy`) pixels (as a script's `drag`) `count` times, waiting after each
/// for the frame's first stage. The handles and the volume view's sketch are made again
/// for every frame, as the window does.
pub fn drag_handle(
    path: &Path,
    settings: Settings,
    name: &str,
    (dx, dy): (f64, f64),
    count: usize,
) -> Result<DragReport> {
    frames(path, settings, count, |viewer, _| viewer.drag(name, dx, dy))
}

/// Opens the scene file at `path` with `settings`, waits for its first refinement, then orbits the camera
/// by (`yaw`, `pitch`) degrees (as a script's `orbit`) `count` times, waiting after each for
/// the frame's first stage: the camera moved as a mouse drag in the image moves it.
pub fn orbit(
    path: &Path,
    settings: Settings,
    (yaw, pitch): (f64, f64),
    count: usize,
) -> Result<DragReport> {
    frames(path, settings, count, |viewer, _| {
        viewer.move_camera(|c| c.orbit(yaw, pitch))
    })
}

/// Runs `count` edits (`edit(viewer, k)`), each waited for until its first stage is shown.
fn frames(
    path: &Path,
    settings: Settings,
    count: usize,
    mut edit: impl FnMut(&mut Viewer, usize) -> Result<()>,
) -> Result<DragReport> {
    let mut viewer = Viewer::open(path, settings)?;
    viewer.idle()?;
    let start = Instant::now();
    let mut label = String::new();
    for k in 0..count {
        edit(&mut viewer, k)?;
        let shown = viewer
            .render_loop()
            .wait_shown(viewer.session().generation())?;
        label = shown.label;
    }
    Ok(DragReport {
        frames: count,
        total_ms: start.elapsed().as_secs_f64() * 1e3,
        label,
    })
}
