//! `flexcam fit`: fits a scene's projector grid to its correspondences and writes the scene
//! with the fitted node projectors explicit (see `flexcam::scene::file::fit_scene`).

use std::path::PathBuf;

use clap::Args;
use flexcam::file_read::{read_regular_text, MAX_SCENE_FILE_BYTES};
use flexcam::image_io::{self, OutputSet};
use flexcam::scene::file::fit_scene;
use flexcam::Result;

/// Arguments of `flexcam fit`.
#[derive(Args, Debug)]
pub struct FitArgs {
    /// A scene file (.toml) whose flexible projection has a `projectors` table with `fit`
    /// correspondences.
    scene: PathBuf,
    /// The scene file to write (.toml): the same scene with one explicit `projector` entry per
    /// node instead of `fit` and `aim`. Relative model paths are resolved from its folder.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `flexcam fit`: reads and fits the scene, prints the residual, and writes the fitted
/// scene atomically (never over the fitting scene, with its correspondences, nor over a
/// file the scene names).
pub fn run(args: &FitArgs) -> Result<()> {
    let mut outputs = OutputSet::new();
    let output = outputs.output("the output", &args.output, &["toml"])?;
    outputs.input("the fitting scene", &args.scene)?;
    let text = read_regular_text(&args.scene, "scene file", MAX_SCENE_FILE_BYTES)?;
    let fitted = fit_scene(&text, &args.scene, &args.output)?;
    super::declare_scene_inputs(&mut outputs, &fitted.inputs)?;
    outputs.stage(output, |tmp| {
        image_io::write_bytes(tmp, fitted.text.as_bytes())
    })?;
    outputs.commit()?;
    let r = fitted.report;
    super::print_stdout(&format!(
        "fitted {} correspondences ({} nodes unconstrained): residual max {:e} degrees, rms \
         {:e} degrees, {}; wrote {}\n",
        r.correspondences,
        r.unconstrained_nodes,
        r.max_angle_deg,
        r.rms_angle_deg,
        r.model(),
        args.output.display()
    ))?;
    // The warning only once the command has succeeded: a failing command prints one line.
    if let Some(warning) = r.warning() {
        eprintln!("flexcam: warning: {}: {warning}", args.scene.display());
    }
    Ok(())
}
