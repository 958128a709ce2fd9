//! The viewer without its window: a session and its render loop, and every action a person
//! (through the window) or a script can take. The window is a thin layer over it.

use std::path::Path;

use flexcam::image_io::{self, ColorEncoding, OutputSet};
use flexcam::render::Method;
use flexcam::Result;
use toml_edit::Value;

use crate::handles::{Handle, Place};
use crate::render_loop::{Job, RenderLoop, Settings};
use crate::session::Session;
use crate::volume_view::{volume_of, Sketch, VolumeCamera, REFERENCE_HEIGHT};
use flexcam::projection::CameraFrame;
use flexcam::Error;

/// A session, its render loop, the view's settings and the volume view.
pub struct Viewer {
    session: Session,
    render: RenderLoop,
    settings: Settings,
    /// The handles and the volume view's sketch of the session's generation `.0`.
    volume: (u64, Vec<Handle>, Sketch),
    camera: VolumeCamera,
}

impl Viewer {
    /// Opens the scene file at `path` and starts rendering it.
    pub fn open(path: &Path, settings: Settings) -> Result<Viewer> {
        let session = Session::open(path)?;
        let (list, sketch) = volume_of(&session);
        let viewer = Viewer {
            camera: VolumeCamera::framing(&sketch),
            volume: (session.generation(), list, sketch),
            session,
            render: RenderLoop::new(),
            settings,
        };
        viewer.submit();
        Ok(viewer)
    }

    /// The handles of the current projection and the volume view's sketch of it.
    pub fn volume(&mut self) -> (&[Handle], &Sketch) {
        if self.volume.0 != self.session.generation() {
            let (list, sketch) = volume_of(&self.session);
            self.volume = (self.session.generation(), list, sketch);
        }
        (&self.volume.1, &self.volume.2)
    }

    /// The volume view's camera.
    pub fn volume_camera(&mut self) -> &mut VolumeCamera {
        &mut self.camera
    }

    /// Drags handle `name` by (`dx`, `dy`) pixels (see [`Viewer::drag_in`]) in a volume view
    /// [`REFERENCE_HEIGHT`] pixels high: a script's `drag`.
    pub fn drag(&mut self, name: &str, dx: f64, dy: f64) -> Result<()> {
        self.drag_in(name, dx, dy, REFERENCE_HEIGHT)
    }

    /// Drags handle `name` by (`dx`, `dy`) pixels (x right, y down): a world handle in the
    /// volume view's plane through it (a view `view_height` pixels high), an image handle
    /// over the image (image pixels). The last valid projection stays on an error.
    pub fn drag_in(&mut self, name: &str, dx: f64, dy: f64, view_height: f64) -> Result<()> {
        let camera = self.camera;
        let (list, _) = self.volume();
        let Some(handle) = list.iter().find(|h| h.name == name).cloned() else {
            return Err(no_handle(name, list));
        };
        let delta = match handle.place {
            Place::World(at) => {
                let (right, down) = camera.pixel_steps(at, view_height);
                Place::World(right * dx + down * dy)
            }
            Place::Image(_) => Place::Image(glam::DVec2::new(dx, dy)),
        };
        let edits = handle.edits(&self.session, delta)?;
        self.session.set_all(&edits)?;
        self.submit();
        Ok(())
    }

    pub fn session(&self) -> &Session {
        &self.session
    }

    pub fn render_loop(&self) -> &RenderLoop {
        &self.render
    }

    pub fn settings(&self) -> Settings {
        self.settings
    }

    /// Hands the session's current state to the render loop.
    fn submit(&self) {
        self.render.submit(Job {
            generation: self.session.generation(),
            prepared: self.session.prepared().clone(),
            spec: self.session.spec().clone(),
            projection: self.session.projection().clone(),
            settings: self.settings,
        });
    }

    /// Renders from now on with `settings` (a new job even when the projection is the same).
    pub fn set_settings(&mut self, settings: Settings) {
        self.settings = settings;
        self.session.touch();
        self.submit();
    }

    /// Renders the final frame by `method` from now on.
    pub fn set_method(&mut self, method: Method) {
        self.set_settings(Settings {
            method,
            ..self.settings
        });
    }

    /// Sets projection key `key` (see [`Session::set`]); the last valid projection stays on
    /// an error.
    pub fn set(&mut self, key: &str, value: Value) -> Result<()> {
        self.session.set(key, value)?;
        self.submit();
        Ok(())
    }

    /// Moves the camera frame (see [`Session::move_camera`]).
    pub fn move_camera(&mut self, change: impl FnOnce(CameraFrame) -> CameraFrame) -> Result<()> {
        self.session.move_camera(change)?;
        self.submit();
        Ok(())
    }

    /// Waits until the current state is rendered and refined; the final stage's error, if
    /// the method refuses the projection.
    pub fn idle(&self) -> Result<()> {
        self.render.wait_refined()
    }

    /// Writes the final frame of the current state as an 8-bit PNG at `out`: the bytes
    /// `flexcam render` writes for the saved scene with the same method, shading and
    /// samples per pixel. Never over the scene file or a file it reads.
    pub fn write_frame(&self, out: &Path) -> Result<()> {
        let frame = self.render.final_frame()?;
        let mut outputs = OutputSet::new();
        let id = outputs.output("the frame", out, &["png"])?;
        for file in &self.session.prepared().scene().inputs {
            outputs.input(&format!("the {}", file.what), &file.path)?;
        }
        let encoding = ColorEncoding::of_shading(self.settings.shading);
        outputs.stage(id, |tmp| image_io::write_color_png(&frame, tmp, encoding))?;
        outputs.commit()
    }

    /// Saves the edited scene (see [`Session::save`]).
    pub fn save(&mut self, out: &Path) -> Result<()> {
        self.session.save(out)
    }

    /// Reloads the scene when its file changed on disk (see [`Session::reload_if_changed`]).
    pub fn reload_if_changed(&mut self) -> Result<bool> {
        let reloaded = self.session.reload_if_changed()?;
        // The handles and sketch follow the new generation; the volume view stays put.
        if reloaded {
            self.submit();
        }
        Ok(reloaded)
    }
}

/// The error of a drag of a handle the projection does not have, naming some it has.
fn no_handle(name: &str, list: &[Handle]) -> Error {
    const SHOWN: usize = 8;
    let names: Vec<&str> = list.iter().take(SHOWN).map(|h| h.name.as_str()).collect();
    let more = if list.len() > SHOWN {
        format!(
            ", ... ({} in all; `flexcam view SCENE --list-handles` lists them)",
            list.len()
        )
    } else {
        String::new()
    };
    if list.is_empty() {
        Error::new(format!(
            "no handle `{name}`: this projection has no handles"
        ))
    } else {
        Error::new(format!(
            "no handle `{name}` (this projection's handles: {}{more})",
            names.join(", ")
        ))
    }
}
