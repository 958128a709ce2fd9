//! `flexcam view`: an interactive viewer in which a projection is designed live.
//!
//! Layers, each over the one below: [`camera`] (orbit, pan, dolly of a camera frame);
//! [`session`] (a scene file, model or built-in scene, its prepared scene and the
//! projection edited as the scene's text); [`render_loop`] (a background thread rendering
//! each state fast, then refining it); [`viewer`] (a session and its render loop, every
//! action a person or a script takes); [`script`] (the `--script` language); and the window
//! (eframe / egui), a thin layer over the viewer. Everything but the window runs without a
//! display.

pub mod bench;
pub mod camera;
pub mod handles;
pub mod ranges;
pub mod render_loop;
pub mod script;
pub mod session;
pub mod viewer;
pub mod volume_view;
mod window;

use std::path::PathBuf;

use flexcam::Result;

pub use render_loop::Settings;
pub use session::Session;
pub use viewer::Viewer;

/// What `flexcam view` was asked to do.
#[derive(Debug, Clone)]
pub struct Options {
    /// What to view: a scene file, a model file (in its default scene) or `builtin:NAME`.
    pub scene: PathBuf,
    /// A script to run instead of waiting for a person (see [`script`]).
    pub script: Option<PathBuf>,
    pub settings: Settings,
    /// Print the projection's handles (see [`volume_view::listing`]) instead of viewing.
    pub list_handles: bool,
}

/// Runs the viewer: the window until it is closed, or the script's lines. A script without
/// a `window` line runs without opening a window (no display needed).
pub fn run(options: &Options) -> Result<()> {
    if options.list_handles {
        let session = Session::open(&options.scene)?;
        let (list, sketch) = volume_view::volume_of(&session);
        let camera = volume_view::VolumeCamera::framing(&sketch);
        print!("{}", volume_view::listing(&list, &camera));
        return Ok(());
    }
    let script = options
        .script
        .as_deref()
        .map(script::Script::load)
        .transpose()?;
    let mut viewer = Viewer::open(&options.scene, options.settings)?;
    match script {
        Some(script) if !script.needs_window() => script::run_headless(&mut viewer, &script),
        script => window::run(viewer, script),
    }
}
