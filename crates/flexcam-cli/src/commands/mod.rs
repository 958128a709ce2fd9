//! The subcommands.

pub mod animate;
pub mod atlas_outputs;
pub mod bench;
pub mod compare;
pub mod ddoc_map;
pub mod fit;
pub mod frame_list;
pub mod import_cameras;
pub mod pick;
pub mod project;
pub mod raymap;
pub mod render;
pub mod reproject;
pub mod scene_args;
pub mod scenes;
pub mod simplify;
pub mod view;
pub mod volume;

/// Reports a command's failure, one line on stderr, and gives exit status 1 (a render or
/// input error; 2 is a usage error, found before any command runs).
pub fn fail(e: &flexcam::Error) -> std::process::ExitCode {
    eprintln!("flexcam: {e}");
    std::process::ExitCode::FAILURE
}

/// Declares the scene file a command was given (a path; nothing for `builtin:NAME`) as an
/// input of `outputs`, so that an output aimed at it is refused before the scene is read.
pub fn declare_scene_file(
    outputs: &mut flexcam::image_io::OutputSet,
    source: &str,
) -> flexcam::Result<()> {
    if source.starts_with("builtin:") {
        return Ok(());
    }
    outputs.input("the scene file", std::path::Path::new(source))
}

/// Declares every file a loaded scene was read from as an input of `outputs`.
pub fn declare_scene_inputs(
    outputs: &mut flexcam::image_io::OutputSet,
    inputs: &[flexcam::scene::InputFile],
) -> flexcam::Result<()> {
    inputs
        .iter()
        .try_for_each(|file| outputs.input(&format!("the {}", file.what), &file.path))
}

/// Writes `text` to standard output and flushes it. A closed pipe (say `flexcam render
/// --stats - | head -c 0`) is then one error line and a non-zero exit, not the panic of
/// `print!`.
pub fn print_stdout(text: &str) -> flexcam::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| flexcam::Error::new(format!("cannot write to standard output: {e}")))
}

/// Finishes a command with a `--stats FILE|-` flag: the JSON line `json` is staged as the
/// output `file` (declared for a file target) and every output committed together, or, for
/// `-`, printed once the outputs are committed.
pub fn commit_with_stats(
    mut outputs: flexcam::image_io::OutputSet,
    file: Option<flexcam::image_io::OutputId>,
    target: Option<&crate::OutputTarget>,
    json: &str,
) -> flexcam::Result<()> {
    let line = format!("{json}\n");
    if let Some(id) = file {
        outputs.stage(id, |tmp| {
            flexcam::image_io::write_bytes(tmp, line.as_bytes())
        })?;
    }
    outputs.commit()?;
    if let Some(crate::OutputTarget::Stdout) = target {
        print_stdout(&line)?;
    }
    Ok(())
}
