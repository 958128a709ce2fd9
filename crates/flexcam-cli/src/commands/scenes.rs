//! `flexcam scenes`: the built-in scenes, one per line: name, then a description.

use flexcam::scene::builtin;

/// Prints the built-in scenes, names padded to a column.
pub fn run() -> flexcam::Result<()> {
    let scenes = builtin::list();
    let width = scenes.iter().map(|(name, _)| name.len()).max().unwrap_or(0);
    for (name, description) in scenes {
        super::print_stdout(&format!("{name:width$}  {description}\n"))?;
    }
    Ok(())
}
