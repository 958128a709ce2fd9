//! The script language of `flexcam view SCENE --script FILE`: one command per line, run in
//! order (docs/viewer.md lists them). Blank lines and lines starting with `#` are skipped.
//!
//! The whole script is parsed before anything runs, so a malformed line is reported (one
//! line `FILE:LINE:COLUMN: message`) before any output is written. A command that fails
//! when it runs (an edit that makes the projection invalid, a method that refuses the
//! projection) ends the script with the same kind of line, naming where the command is.

use std::path::{Path, PathBuf};

use flexcam::render::Method;
use flexcam::{Error, Result};
use toml_edit::Value;

use crate::camera::Navigate;
use crate::viewer::Viewer;

/// One command of a script.
#[derive(Debug, Clone)]
pub enum Command {
    /// `set KEY VALUE`: a projection key (dotted for nested tables) and a TOML value; a bare
    /// word is a string.
    Set { key: String, value: Value },
    /// `method NAME`: the method of the final frame.
    Method(Method),
    /// `orbit DX DY`: turn the eye about the look-at point, degrees (yaw, pitch).
    Orbit { dx: f64, dy: f64 },
    /// `pan DX DY`: move eye and look-at point sideways, in eye distances.
    Pan { dx: f64, dy: f64 },
    /// `dolly FACTOR`: multiply the eye's distance to the look-at point.
    Dolly(f64),
    /// `drag HANDLE DX DY`: move a handle by (DX, DY) pixels (of the volume view at its
    /// reference height for a world handle, of the image for an image handle).
    Drag { handle: String, dx: f64, dy: f64 },
    /// `idle`: wait until the current state is refined.
    Idle,
    /// `frame OUT.png`: write the final frame.
    Frame(PathBuf),
    /// `window OUT.png`: write a screenshot of the whole window.
    Window(PathBuf),
    /// `save OUT.toml`: write the edited scene.
    Save(PathBuf),
    /// `pointer press|move|release X Y [BUTTON]`: a raw pointer event at window pixel
    /// (X, Y), fed to the window's next frame as a mouse would (window only).
    Pointer {
        action: PointerAction,
        x: f64,
        y: f64,
        button: Button,
    },
    /// `scroll DY`: a mouse wheel turned by DY points (positive: up) where the pointer is
    /// (window only).
    Scroll(f64),
    /// `layout OUT.txt`: write where the window draws the image, the volume view and each
    /// handle, in window pixels (window only).
    Layout(PathBuf),
}

/// What a `pointer` line does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointerAction {
    Press,
    Move,
    Release,
}

/// The mouse button of a `pointer` line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Button {
    Left,
    Right,
    Middle,
}

impl Command {
    /// Whether the command acts on the window (a script with one opens it).
    pub fn needs_window(&self) -> bool {
        matches!(
            self,
            Command::Window(_) | Command::Pointer { .. } | Command::Scroll(_) | Command::Layout(_)
        )
    }
}

/// A command and where it is: 1-based line and the column of its first word.
#[derive(Debug, Clone)]
pub struct Line {
    pub line: usize,
    pub column: usize,
    pub command: Command,
}

/// A parsed script.
#[derive(Debug, Clone)]
pub struct Script {
    pub path: PathBuf,
    pub lines: Vec<Line>,
}

impl Script {
    /// Reads and parses the script at `path`.
    pub fn load(path: &Path) -> Result<Script> {
        let text = flexcam::file_read::read_regular_text(path, "script", 1 << 20)?;
        Script::parse(&text, path)
    }

    /// Parses script text (`path` names it in errors).
    pub fn parse(text: &str, path: &Path) -> Result<Script> {
        let mut lines = Vec::new();
        for (index, line) in text.lines().enumerate() {
            let words = words(line);
            let Some(&(column, first)) = words.first() else {
                continue;
            };
            if first.starts_with('#') {
                continue;
            }
            let at = |column: usize, message: String| Error::at(path, index + 1, column, message);
            let command = parse_command(line, &words).map_err(|(column, m)| at(column, m))?;
            lines.push(Line {
                line: index + 1,
                column,
                command,
            });
        }
        Ok(Script {
            path: path.to_path_buf(),
            lines,
        })
    }

    /// Whether the script needs the window (it has a `window`, `pointer`, `scroll` or
    /// `layout` line).
    pub fn needs_window(&self) -> bool {
        self.lines.iter().any(|l| l.command.needs_window())
    }

    /// An error of the command at `line`, as one line naming the script, line and column.
    pub fn error_at(&self, line: &Line, error: &Error) -> Error {
        Error::at(&self.path, line.line, line.column, error.to_string())
    }
}

/// The words of `line` with their 1-based columns (in characters), split at white space.
fn words(line: &str) -> Vec<(usize, &str)> {
    let mut words = Vec::new();
    let mut start = None;
    for (i, (byte, c)) in line.char_indices().enumerate() {
        match (c.is_whitespace(), start) {
            (false, None) => start = Some((i + 1, byte)),
            (true, Some((column, from))) => {
                words.push((column, &line[from..byte]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some((column, from)) = start {
        words.push((column, &line[from..]));
    }
    words
}

/// An error at a column.
type ColumnError = (usize, String);

fn parse_command(line: &str, words: &[(usize, &str)]) -> std::result::Result<Command, ColumnError> {
    let (column, name) = words[0];
    let args = &words[1..];
    let count = |n: usize, usage: &str| {
        if args.len() == n {
            Ok(())
        } else {
            let column = args.get(n).map_or(column + name.len(), |w| w.0);
            Err((column, format!("`{name}` takes {n} argument(s): {usage}")))
        }
    };
    let number = |(column, word): (usize, &str)| {
        word.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or((column, format!("expected a number, got `{word}`")))
    };
    let path = |(column, word): (usize, &str)| {
        if word.is_empty() {
            Err((column, "expected a file path".to_string()))
        } else {
            Ok(PathBuf::from(word))
        }
    };
    Ok(match name {
        "set" => {
            let Some(&(key_column, key)) = args.first() else {
                return Err((
                    column + 3,
                    "`set` takes a key and a value: set KEY VALUE".into(),
                ));
            };
            let Some(&(value_column, _)) = args.get(1) else {
                return Err((
                    key_column + key.chars().count(),
                    format!("`set {key}` needs a value"),
                ));
            };
            // The value is the rest of the line (an array may hold spaces).
            let byte = line
                .char_indices()
                .nth(value_column - 1)
                .map_or(line.len(), |c| c.0);
            Command::Set {
                key: key.to_string(),
                value: parse_value(line[byte..].trim_end()).map_err(|m| (value_column, m))?,
            }
        }
        "method" => {
            count(1, "method NAME")?;
            Command::Method(
                args[0]
                    .1
                    .parse()
                    .map_err(|e: Error| (args[0].0, e.message))?,
            )
        }
        "orbit" | "pan" => {
            count(2, &format!("{name} DX DY"))?;
            let (dx, dy) = (number(args[0])?, number(args[1])?);
            if name == "orbit" {
                Command::Orbit { dx, dy }
            } else {
                Command::Pan { dx, dy }
            }
        }
        "dolly" => {
            count(1, "dolly FACTOR")?;
            let factor = number(args[0])?;
            if factor <= 0.0 {
                return Err((
                    args[0].0,
                    format!("the dolly factor must be positive, got {factor}"),
                ));
            }
            Command::Dolly(factor)
        }
        "drag" => {
            count(3, "drag HANDLE DX DY")?;
            Command::Drag {
                handle: args[0].1.to_string(),
                dx: number(args[1])?,
                dy: number(args[2])?,
            }
        }
        "idle" => {
            count(0, "idle")?;
            Command::Idle
        }
        "frame" => {
            count(1, "frame OUT.png")?;
            Command::Frame(path(args[0])?)
        }
        "window" => {
            count(1, "window OUT.png")?;
            Command::Window(path(args[0])?)
        }
        "save" => {
            count(1, "save OUT.toml")?;
            Command::Save(path(args[0])?)
        }
        "layout" => {
            count(1, "layout OUT.txt")?;
            Command::Layout(path(args[0])?)
        }
        "scroll" => {
            count(1, "scroll DY")?;
            Command::Scroll(number(args[0])?)
        }
        "pointer" => {
            let usage = "pointer press|move|release X Y [left|right|middle]";
            if !(3..=4).contains(&args.len()) {
                let column = args.get(4).map_or(column + name.len(), |w| w.0);
                return Err((column, format!("`pointer` takes 3 or 4 arguments: {usage}")));
            }
            let action = match args[0].1 {
                "press" => PointerAction::Press,
                "move" => PointerAction::Move,
                "release" => PointerAction::Release,
                other => {
                    return Err((
                        args[0].0,
                        format!("unknown pointer action `{other}` (press, move, release)"),
                    ))
                }
            };
            let button = match args.get(3).map(|w| w.1) {
                None | Some("left") => Button::Left,
                Some("right") => Button::Right,
                Some("middle") => Button::Middle,
                Some(other) => {
                    return Err((
                        args[3].0,
                        format!("unknown button `{other}` (left, right, middle)"),
                    ))
                }
            };
            Command::Pointer {
                action,
                x: number(args[1])?,
                y: number(args[2])?,
                button,
            }
        }
        other => {
            return Err((
                column,
                format!(
                    "unknown command `{other}` (available: set, method, orbit, pan, dolly, \
                     drag, idle, frame, window, save, pointer, scroll, layout)"
                ),
            ))
        }
    })
}

/// A TOML value, or a bare word (letters, digits, `_`, `-`, `.`) as a string.
fn parse_value(text: &str) -> std::result::Result<Value, String> {
    if let Ok(value) = text.parse::<Value>() {
        return Ok(value);
    }
    let bare = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'));
    if bare {
        Ok(Value::from(text))
    } else {
        Err(format!("`{text}` is not a TOML value"))
    }
}

/// Runs `line` on `viewer`; the lines that act on the window are the window's to run
/// ([`run_headless`] refuses them).
pub fn run_line(viewer: &mut Viewer, command: &Command) -> Result<()> {
    match command {
        Command::Set { key, value } => viewer.set(key, value.clone()),
        Command::Method(method) => {
            viewer.set_method(*method);
            Ok(())
        }
        Command::Orbit { dx, dy } => viewer.move_camera(|c| c.orbit(*dx, *dy)),
        Command::Pan { dx, dy } => viewer.move_camera(|c| c.pan(*dx, *dy)),
        Command::Dolly(factor) => viewer.move_camera(|c| c.dolly(*factor)),
        Command::Drag { handle, dx, dy } => viewer.drag(handle, *dx, *dy),
        Command::Idle => viewer.idle(),
        Command::Frame(out) => viewer.write_frame(out),
        Command::Save(out) => viewer.save(out),
        Command::Window(_) | Command::Pointer { .. } | Command::Scroll(_) | Command::Layout(_) => {
            Err(Error::new("this line needs the window"))
        }
    }
}

/// Runs every line of `script` on `viewer` without a window.
pub fn run_headless(viewer: &mut Viewer, script: &Script) -> Result<()> {
    for line in &script.lines {
        run_line(viewer, &line.command).map_err(|e| script.error_at(line, &e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Script> {
        Script::parse(text, Path::new("s.view"))
    }

    #[test]
    fn every_command_parses() {
        let script = parse(
            "# a comment\n\nset fov 100\nset position [0, 1, 5.5]\nset preset cubic\n\
             method raster\norbit 10 -5\npan 0.1 0\ndolly 0.5\ndrag p0 3 4\nidle\n\
             frame out.png\n  window w.png\nsave out.toml\npointer press 10 20.5\n\
             pointer move 30 -4 right\nscroll -120\nlayout l.txt\n",
        )
        .unwrap();
        let commands: Vec<_> = script.lines.iter().map(|l| l.command.clone()).collect();
        assert_eq!(commands.len(), 16);
        let set = |c: &Command| match c {
            Command::Set { key, value } => format!("{key}={value}"),
            other => panic!("{other:?}"),
        };
        assert_eq!(set(&commands[0]), "fov=100");
        assert_eq!(set(&commands[1]), "position=[0, 1, 5.5]");
        assert_eq!(set(&commands[2]), "preset=\"cubic\"");
        assert!(matches!(commands[3], Command::Method(Method::Raster)));
        assert!(matches!(commands[4], Command::Orbit { dx: 10.0, dy: -5.0 }));
        assert!(
            matches!(&commands[7], Command::Drag { handle, dx: 3.0, dy: 4.0 } if handle == "p0")
        );
        assert!(matches!(&commands[10], Command::Window(p) if p == Path::new("w.png")));
        assert_eq!((script.lines[10].line, script.lines[10].column), (13, 3));
        assert!(script.needs_window());
        assert!(matches!(
            commands[12],
            Command::Pointer {
                action: PointerAction::Press,
                x: 10.0,
                y: 20.5,
                button: Button::Left
            }
        ));
        assert!(matches!(
            commands[13],
            Command::Pointer {
                action: PointerAction::Move,
                x: 30.0,
                y: -4.0,
                button: Button::Right
            }
        ));
        assert!(matches!(commands[14], Command::Scroll(-120.0)));
        assert!(matches!(&commands[15], Command::Layout(p) if p == Path::new("l.txt")));
        // Each window line alone opens the window; the others do not.
        for line in [
            "pointer release 1 2",
            "scroll 3",
            "layout l.txt",
            "window w.png",
        ] {
            assert!(parse(line).unwrap().needs_window(), "{line}");
        }
        assert!(!parse("idle\nframe f.png\nsave s.toml")
            .unwrap()
            .needs_window());
    }

    #[test]
    fn bad_lines_name_line_and_column() {
        let cases = [
            ("idle\nfly 1 2\n", "s.view:2:1: unknown command `fly`"),
            ("orbit 1 x\n", "s.view:1:9: expected a number, got `x`"),
            (
                "orbit 1\n",
                "s.view:1:6: `orbit` takes 2 argument(s): orbit DX DY",
            ),
            ("idle now\n", "s.view:1:6: `idle` takes 0 argument(s): idle"),
            ("method fast\n", "s.view:1:8: unknown method \"fast\""),
            ("set fov\n", "s.view:1:8: `set fov` needs a value"),
            ("set fov [1,\n", "s.view:1:9: `[1,` is not a TOML value"),
            (
                "dolly 0\n",
                "s.view:1:7: the dolly factor must be positive, got 0",
            ),
            ("orbit 1 inf\n", "s.view:1:9: expected a number, got `inf`"),
            (
                "pointer hold 1 2\n",
                "s.view:1:9: unknown pointer action `hold` (press, move, release)",
            ),
            (
                "pointer press 1 2 side\n",
                "s.view:1:19: unknown button `side` (left, right, middle)",
            ),
            (
                "pointer press 1\n",
                "s.view:1:8: `pointer` takes 3 or 4 arguments",
            ),
            (
                "scroll\n",
                "s.view:1:7: `scroll` takes 1 argument(s): scroll DY",
            ),
        ];
        for (text, expected) in cases {
            let message = parse(text).unwrap_err().to_string();
            assert!(message.starts_with(expected), "{text:?}: {message}");
        }
    }
}
