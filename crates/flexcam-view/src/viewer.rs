//! The viewer without its window: a session and its render loop, and every action a person
//! (through the window) or a script can take. The window is a thin layer over it.

use std::path::Path;

use flexcam::image_io::{self, ColorEncoding, OutputSet};
use flexcam::render::Method;
use flexcam::Result;
use toml_edit::Value;

use crate::render_loop::{Job, RenderLoop, Settings};
use crate::session::Session;
use flexcam::projection::CameraFrame;

/// A session, its render loop and the view's settings.
pub struct Viewer {
    session: Session,
    render: RenderLoop,
    settings: Settings,
}

impl Viewer {
    /// Opens the scene file at `path` and starts rendering it.
    pub fn open(path: &Path, settings: Settings) -> Result<Viewer> {
        let viewer = Viewer {
            session: Session::open(path)?,
            render: RenderLoop::new(),
            settings,
        };
        viewer.submit();
        Ok(viewer)
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
        if reloaded {
            self.submit();
        }
        Ok(reloaded)
    }
}
