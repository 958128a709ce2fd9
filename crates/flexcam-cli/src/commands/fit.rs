//! `flexcam fit`: fits a scene's projector grid to its correspondences and writes the scene
//! with the fitted node projectors explicit (see `flexcam::scene::file::fit_scene`), and with
//! `--overlay` a picture of the fit over the painting (module `overlay`).

mod marks;
mod overlay;

use std::path::PathBuf;

use clap::Args;
use flexcam::file_read::{read_regular_text, MAX_SCENE_FILE_BYTES};
use flexcam::image_io::{self, ColorEncoding, OutputSet};
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
    /// Also write a PNG of the fitted scene rendered at the painting's size, blended with the
    /// painting (`painting` in the `projectors` table; the render alone without one), each
    /// correspondence marked where it was given and where the fit images its point, coloured
    /// by the distance between the two (green 0, yellow 2, red 4 px or more).
    #[arg(long, value_name = "OUT.png")]
    overlay: Option<PathBuf>,
}

/// Runs `flexcam fit`: reads and fits the scene, prints the residual, and writes the fitted
/// scene atomically (never over the fitting scene, with its correspondences, nor over a
/// file the scene names).
pub fn run(args: &FitArgs) -> Result<()> {
    let mut outputs = OutputSet::new();
    let output = outputs.output("the output", &args.output, &["toml"])?;
    let overlay_output = (args.overlay.as_ref())
        .map(|path| outputs.output("the overlay", path, &["png"]))
        .transpose()?;
    outputs.input("the fitting scene", &args.scene)?;
    let text = read_regular_text(&args.scene, "scene file", MAX_SCENE_FILE_BYTES)?;
    let fitted = fit_scene(&text, &args.scene, &args.output)?;
    super::declare_scene_inputs(&mut outputs, &fitted.inputs)?;
    let overlay = match overlay_output {
        Some(id) => {
            let painting = (fitted.painting.as_ref())
                .map(|p| image_io::read_linear_image(p))
                .transpose()?;
            Some((id, overlay::draw(&fitted, &args.output, painting.as_ref())?))
        }
        None => None,
    };
    outputs.stage(output, |tmp| {
        image_io::write_bytes(tmp, fitted.text.as_bytes())
    })?;
    if let Some((id, drawn)) = &overlay {
        outputs.stage(*id, |tmp| {
            image_io::write_color_png(&drawn.frame, tmp, ColorEncoding::Srgb)
        })?;
    }
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
    if let (Some((_, drawn)), Some(path)) = (&overlay, &args.overlay) {
        super::print_stdout(&format!(
            "overlay: {}; wrote {}\n",
            overlay::summary(&drawn.residuals),
            path.display()
        ))?;
    }
    // The warning only once the command has succeeded: a failing command prints one line.
    if let Some(warning) = r.warning() {
        eprintln!("flexcam: warning: {}: {warning}", args.scene.display());
    }
    Ok(())
}
