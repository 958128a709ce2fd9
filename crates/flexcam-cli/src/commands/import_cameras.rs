//! `flexcam import-cameras`: COLMAP's cameras.txt, or the cameras of a glTF / GLB model, to
//! scene projection tables.

use std::path::{Path, PathBuf};

use clap::Args;
use flexcam::image_io::{self, OutputSet};
use flexcam::projection::colmap::{projection_tables, read_cameras};
use flexcam::scene::loaders::load_model;
use flexcam::scene::model_scene::camera_tables;
use flexcam::{Error, Result};

/// Arguments of `flexcam import-cameras`.
#[derive(Args, Debug)]
pub struct ImportCamerasArgs {
    /// COLMAP cameras.txt, or a glTF / GLB model (.gltf, .glb). COLMAP models
    /// SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV and FULL_OPENCV become `type =
    /// "opencv"`, OPENCV_FISHEYE `type = "opencv_fisheye"`; any other model is refused with
    /// its line. glTF cameras become `perspective` (yfov kept for the camera's aspect ratio,
    /// or a 4:3 image) and `orthographic` (width 2 xmag) tables placed by their nodes.
    input: PathBuf,
    /// Write the tables to this TOML file instead of standard output.
    #[arg(short, long, value_name = "OUT.toml")]
    output: Option<PathBuf>,
}

/// Runs `flexcam import-cameras`.
pub fn run(args: &ImportCamerasArgs) -> Result<()> {
    let mut outputs = OutputSet::new();
    outputs.input("the cameras file", &args.input)?;
    let output = match &args.output {
        Some(path) => Some(outputs.output("the output", path, &["toml"])?),
        None => None,
    };
    let source = args.input.display().to_string();
    let tables = if is_gltf(&args.input) {
        let model = load_model(&args.input)?;
        camera_tables(&model, &source).map_err(|e| Error::in_file(&args.input, e.message))?
    } else {
        let text = std::fs::read_to_string(&args.input)
            .map_err(|e| Error::in_file(&args.input, format!("cannot read: {e}")))?;
        projection_tables(&read_cameras(&text, &args.input)?, &source)
    };
    match output {
        Some(id) => {
            outputs.stage(id, |tmp| image_io::write_bytes(tmp, tables.as_bytes()))?;
            outputs.commit()
        }
        None => super::print_stdout(&tables),
    }
}

/// Whether `path` names a glTF or GLB file (by extension, any case).
fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}
