//! `flexcam`: render scenes through nonlinear projections from the command line.
//!
//! Every failure is reported as one line on stderr (`flexcam: FILE:LINE:COLUMN: message`)
//! with a non-zero exit status, and leaves no partial output file.

mod commands;
mod progress;
mod stats_json;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Command as ClapCommand, CommandFactory, FromArgMatches, Parser, Subcommand};

/// Renders 3D scenes through nonlinear and multi-perspective projections.
#[derive(Parser, Debug)]
#[command(name = "flexcam", version, about, after_help = EXIT_STATUS_HELP)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The exit statuses of every command (shown after the commands in `--help`).
const EXIT_STATUS_HELP: &str = "Exit status: 0 done; 1 a render or input error (one line on \
stderr, nothing written); 2 a usage error (an unknown flag, a bad flag value); 3 `compare` \
ran but missed a threshold.";

/// How every command that writes files writes them (shown after its options in `--help`).
const OUTPUTS_HELP: &str = "Outputs are written all together or not at all, never over an \
input (scene file, model, texture, photo) or another output, compared by file identity; \
missing output folders are created.";

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene file, built-in scene or model file to a PNG (and optional depth / id
    /// images).
    #[command(after_help = OUTPUTS_HELP)]
    Render(commands::render::RenderArgs),
    /// Resample a photo (equirectangular, cylindrical or fisheye) through a scene's projection
    /// into a PNG.
    #[command(after_help = OUTPUTS_HELP)]
    Reproject(commands::reproject::ReprojectArgs),
    /// Render a scene's keyframed flexible camera to numbered PNG frames and/or a GIF.
    #[command(after_help = OUTPUTS_HELP)]
    Animate(commands::animate::AnimateArgs),
    /// Fit a scene's projector grid to its `fit` correspondences and write the scene with the
    /// fitted node projectors explicit.
    #[command(after_help = OUTPUTS_HELP)]
    Fit(commands::fit::FitArgs),
    /// Print the object and world point the ray caster sees at image positions of a scene
    /// (for collecting a fit's correspondences from a render).
    Pick(commands::pick::PickArgs),
    /// List the built-in scenes: name, then a description.
    Scenes,
    /// Print every image position of a scene point through the scene's projection, one line
    /// per image, nearest first: pixel x and y (continuous: pixel (x, y) covers
    /// [x, x + 1) x [y, y + 1), y down) and the depth (the distance along that pixel's ray,
    /// as `render --depth` writes it). A trilinear mesh can image a point several times (all
    /// roots of each projection triangle's cubic) or not at all (no line); a triangle whose
    /// rays form a fan (two vertices alike) sees a point along a whole segment of pixels,
    /// listed as `x y depth x_end y_end`. Only images inside the image and in front of the
    /// view plane are listed; projections without an analytic inverse are refused.
    Project(commands::project::ProjectArgs),
    /// Write a scene projection's per-pixel rays (origin, direction, and where curved
    /// projectors end) and its STMap against a reference camera, as OpenEXR.
    #[command(after_help = OUTPUTS_HELP)]
    Raymap(commands::raymap::RaymapArgs),
    /// Render a scene with a method and with the reference ray caster, and report how closely
    /// they agree (object ids, depth, relative RGB error).
    #[command(after_help = OUTPUTS_HELP)]
    Compare(commands::compare::CompareArgs),
    /// Simplify a polygon mesh (OBJ, faces of any number of corners) by edge collapses that
    /// turn no face by more than a threshold angle, and write the coarse mesh (OBJ).
    #[command(after_help = OUTPUTS_HELP)]
    Simplify(commands::simplify::SimplifyArgs),
    /// Convert a COLMAP cameras.txt (`opencv`, `opencv_fisheye`) or the cameras of a glTF /
    /// GLB model (`perspective`, `orthographic`) into scene projection tables, one per
    /// camera, as TOML.
    #[command(after_help = OUTPUTS_HELP)]
    ImportCameras(commands::import_cameras::ImportCamerasArgs),
    /// Write a scene projection's viewing volume as geometry, OBJ with an MTL library: the
    /// control surfaces of a flexible volume (meshes), a sample of projectors (lines) and the
    /// image grid carried onto the volume (lines), each part its own material.
    #[command(after_help = OUTPUTS_HELP)]
    Volume(commands::volume::VolumeArgs),
    /// Write the displacement map of a scene's depth-discontinuity occlusion camera
    /// (`preset = "ddoc"`) as a PFM for its `map` key: the depth of its reference
    /// perspective is ray cast, and the far samples at each depth discontinuity (near side
    /// within z_near, far side beyond z_far) are pushed away from it towards the occluded side.
    #[command(after_help = OUTPUTS_HELP)]
    DdocMap(commands::ddoc_map::DdocMapArgs),
    /// Open the interactive viewer on a scene file: design its projection live, or run a
    /// script of viewer commands.
    View(commands::view::ViewArgs),
    /// Rerun a source document's timing table with flexcam's renderers.
    #[command(subcommand)]
    Bench(commands::bench::BenchCommand),
}

fn main() -> ExitCode {
    restore_broken_pipe_default();
    let parsed = accept_negative_values(Cli::command())
        .try_get_matches()
        .and_then(|matches| Cli::from_arg_matches(&matches));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) => return report_usage_error(e),
    };
    let result = match cli.command {
        Command::Render(args) => commands::render::run(&args),
        Command::Animate(args) => commands::animate::run(&args),
        Command::Reproject(args) => commands::reproject::run(&args),
        Command::Fit(args) => commands::fit::run(&args),
        Command::Pick(args) => commands::pick::run(&args),
        Command::Scenes => commands::scenes::run(),
        Command::Project(args) => commands::project::run(&args),
        Command::Raymap(args) => commands::raymap::run(&args),
        Command::Compare(args) => return commands::compare::run(&args),
        Command::Simplify(args) => commands::simplify::run(&args),
        Command::ImportCameras(args) => commands::import_cameras::run(&args),
        Command::View(args) => commands::view::run(&args),
        Command::Volume(args) => commands::volume::run(&args),
        Command::DdocMap(args) => commands::ddoc_map::run(&args),
        Command::Bench(command) => commands::bench::run(&command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => commands::fail(&e),
    }
}

/// Gives SIGPIPE its default action back (Rust's runtime ignores it, which turns a write to
/// a closed pipe into a panic in `println!`): `flexcam scenes | head` then ends as other
/// command-line tools do, quietly, when the reader stops reading.
fn restore_broken_pipe_default() {
    #[cfg(unix)]
    // SAFETY: called first in `main`, before any thread is started; SIG_DFL is a valid action
    // for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// `command` with every option that takes a value accepting a negative number as that value
/// (in every subcommand), so that `--width -1` is reported as a bad `--width` value, not as
/// an unknown argument `-1` that names no option.
fn accept_negative_values(command: ClapCommand) -> ClapCommand {
    command
        .mut_args(|arg| {
            if arg.get_action().takes_values() {
                arg.allow_negative_numbers(true)
            } else {
                arg
            }
        })
        .mut_subcommands(accept_negative_values)
}

/// Help and version go to stdout as usual; a usage error is folded into one line: clap's
/// message lines up to the usage text, without its tips (a message such as "the following
/// required arguments were not provided:" goes on to name them on the next line).
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
    eprintln!("flexcam: {}", usage_error_line(&e.render().to_string()));
    ExitCode::from(2)
}

/// The one line of a rendered clap error (see [`report_usage_error`]).
fn usage_error_line(text: &str) -> String {
    let message: Vec<&str> = text
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty() && !l.starts_with("tip:"))
        .collect();
    match message.join(" ").trim_start_matches("error: ") {
        "" => "invalid arguments".to_string(),
        line => line.to_string(),
    }
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
