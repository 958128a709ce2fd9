//! `flexcam import-cameras`: COLMAP's cameras.txt to scene projection tables.

use std::path::PathBuf;

use clap::Args;
use flexcam::image_io::{self, OutputSet};
use flexcam::projection::colmap::{projection_tables, read_cameras};
use flexcam::{Error, Result};

/// Arguments of `flexcam import-cameras`.
#[derive(Args, Debug)]
pub struct ImportCamerasArgs {
    /// COLMAP cameras.txt. Models SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV and
    /// FULL_OPENCV become `type = "opencv"`, OPENCV_FISHEYE `type = "opencv_fisheye"`; any
    /// other model is refused with its line.
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
    let text = std::fs::read_to_string(&args.input)
        .map_err(|e| Error::in_file(&args.input, format!("cannot read: {e}")))?;
    let cameras = read_cameras(&text, &args.input)?;
    let tables = projection_tables(&cameras, &args.input.display().to_string());
    match output {
        Some(id) => {
            outputs.stage(id, |tmp| image_io::write_bytes(tmp, tables.as_bytes()))?;
            outputs.commit()
        }
        None => super::print_stdout(&tables),
    }
}
