//! The subcommands.

pub mod animate;
pub mod bench;
pub mod compare;
pub mod fit;
pub mod render;
pub mod reproject;
pub mod scene_args;
pub mod scenes;

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
