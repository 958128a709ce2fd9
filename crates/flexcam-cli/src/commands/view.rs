//! `flexcam view`: the interactive viewer (crate `flexcam-view`) on a scene file, a model
//! file or a built-in scene.

use std::path::PathBuf;

use clap::Args;
use flexcam::Result;
use flexcam_view::{Options, Settings};

use super::scene_args::ShadingArg;

/// Arguments of `flexcam view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// What to view: a scene file (.toml; saving writes the edited projection back into
    /// it), a model file (.obj, .gltf, .glb, .ply) in the default scene `flexcam render`
    /// draws for it, or `builtin:NAME`; the last two are saved only as a new scene file.
    scene: PathBuf,
    /// Run the script's lines (`set KEY VALUE`, `method NAME`, `orbit DX DY`, `pan DX DY`,
    /// `dolly F`, `drag HANDLE DX DY`, `idle`, `frame OUT.png`, `window OUT.png`, `save
    /// OUT.toml`) and exit after the last. Without a `window` line no window is opened.
    #[arg(long, value_name = "FILE")]
    script: Option<PathBuf>,
    /// The method of the final frame (the one `frame` writes): `raycast` (default, after a
    /// fast preview), `raster`, `trilinear` or `camera-triangles`.
    #[arg(long, default_value = "raycast")]
    method: String,
    /// Shading, as for `flexcam render`.
    #[arg(long, value_enum, default_value_t = ShadingArg::Lit)]
    shading: ShadingArg,
    /// Samples per pixel of the final frame.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    spp: u32,
    /// Samples per pixel of the ray caster's last refinement while idle (shown, not written
    /// by `frame`); no refinement at or below --spp.
    #[arg(long, default_value_t = Settings::DEFAULT.refine_spp,
          value_parser = clap::value_parser!(u32).range(1..=4096))]
    refine_spp: u32,
    /// Print the names of the projection's draggable handles (for `drag` lines), where each
    /// is and the world step of one pixel of a script's drag, then exit.
    #[arg(long)]
    list_handles: bool,
}

/// Runs `flexcam view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    flexcam_view::run(&Options {
        scene: args.scene.clone(),
        script: args.script.clone(),
        settings: Settings {
            method: args.method.parse()?,
            shading: args.shading.shading(),
            spp: args.spp,
            refine_spp: args.refine_spp,
            full_size_previews: false,
        },
        list_handles: args.list_handles,
    })
}
