//! `flexcam`: render scenes through nonlinear projections from the command line.
//!
//! Every failure is reported as one line on stderr (`flexcam: FILE:LINE:COLUMN: message`)
//! with a non-zero exit status, and leaves no partial output file.

mod commands;
mod progress;
mod stats_json;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Renders 3D scenes through nonlinear and multi-perspective projections.
#[derive(Parser, Debug)]
#[command(name = "flexcam", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// How every command that writes files writes them (shown after its options in `--help`).
const OUTPUTS_HELP: &str = "Outputs are written all together or not at all, never over an \
input (scene file, model, texture, photo) or another output, compared by file identity; \
missing output folders are created.";

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene file or built-in scene to a PNG (and optional depth / id images).
    #[command(after_help = OUTPUTS_HELP)]
    Render(commands::render::RenderArgs),
    /// Resample an equirectangular photo through a scene's projection into a PNG.
    #[command(after_help = OUTPUTS_HELP)]
    Reproject(commands::reproject::ReprojectArgs),
    /// Render a scene's keyframed flexible camera to numbered PNG frames and/or a GIF.
    #[command(after_help = OUTPUTS_HELP)]
    Animate(commands::animate::AnimateArgs),
    /// Fit a scene's projector grid to its `fit` correspondences and write the scene with the
    /// fitted node projectors explicit.
    #[command(after_help = OUTPUTS_HELP)]
    Fit(commands::fit::FitArgs),
    /// List the built-in scenes: name, then a description.
    Scenes,
    /// Render a scene with a method and with the reference ray caster, and report how closely
    /// they agree (object ids, depth, relative RGB error).
    #[command(after_help = OUTPUTS_HELP)]
    Compare(commands::compare::CompareArgs),
    /// Simplify a polygon mesh (OBJ, faces of any number of corners) by edge collapses that
    /// turn no face by more than a threshold angle, and write the coarse mesh (OBJ).
    #[command(after_help = OUTPUTS_HELP)]
    Simplify(commands::simplify::SimplifyArgs),
    /// Convert a COLMAP cameras.txt into scene projection tables (`opencv`, `opencv_fisheye`),
    /// one per camera, as TOML.
    #[command(after_help = OUTPUTS_HELP)]
    ImportCameras(commands::import_cameras::ImportCamerasArgs),
    /// Rerun a source document's timing table with flexcam's renderers.
    #[command(subcommand)]
    Bench(commands::bench::BenchCommand),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return report_usage_error(e),
    };
    let result = match cli.command {
        Command::Render(args) => commands::render::run(&args),
        Command::Animate(args) => commands::animate::run(&args),
        Command::Reproject(args) => commands::reproject::run(&args),
        Command::Fit(args) => commands::fit::run(&args),
        Command::Scenes => commands::scenes::run(),
        Command::Compare(args) => commands::compare::run(&args),
        Command::Simplify(args) => commands::simplify::run(&args),
        Command::ImportCameras(args) => commands::import_cameras::run(&args),
        Command::Bench(command) => commands::bench::run(&command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("flexcam: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Help and version go to stdout as usual; a usage error is cut to its first line (clap adds
/// usage text and hints on further lines) so that every error is one line.
fn report_usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        let _ = e.print();
        return ExitCode::SUCCESS;
    }
    let text = e.render().to_string();
    let first = text
        .lines()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("invalid arguments");
    let first = first.trim_start_matches("error: ");
    eprintln!("flexcam: {first}");
    ExitCode::from(2)
}

/// A path argument that may be `-` for standard output.
#[derive(Debug, Clone, PartialEq)]
enum OutputTarget {
    Stdout,
    File(PathBuf),
}

impl std::str::FromStr for OutputTarget {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(if s == "-" {
            OutputTarget::Stdout
        } else {
            OutputTarget::File(PathBuf::from(s))
        })
    }
}
