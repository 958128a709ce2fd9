//! `flexcam view MODEL` and `flexcam view builtin:NAME`: the scene `flexcam render` draws for
//! the same argument, edited and saved as a new scene file whose render is the script's
//! frame byte for byte; the model itself never written.

mod common;

use common::{run, run_ok};
use tempfile::TempDir;

/// An octahedron of half-diagonal 1 round (0, 0.5, 0), as OBJ text.
const OCTAHEDRON: &str = "v 1 0.5 0\nv -1 0.5 0\nv 0 1.5 0\nv 0 -0.5 0\nv 0 0.5 1\nv 0 0.5 -1\n\
    f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

fn read(dir: &TempDir, name: &str) -> Vec<u8> {
    std::fs::read(dir.path().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// A folder holding the model `m.obj` and the script `view.txt`.
fn model_dir(script: &str) -> TempDir {
    let dir = TempDir::new().unwrap();
    std::fs::write(dir.path().join("m.obj"), OCTAHEDRON).unwrap();
    std::fs::write(dir.path().join("view.txt"), script).unwrap();
    dir
}

#[test]
fn a_model_is_viewed_in_its_default_scene_and_saved_as_a_new_scene_file() {
    let script = "method raster\nset fov 35\norbit 15 5\nframe f.png\nsave s.toml\n";
    let dir = model_dir(script);
    run_ok(&dir, &["view", "m.obj", "--script", "view.txt"]);
    // The saved scene names the model beside it, and renders the script's frame.
    let saved = String::from_utf8(read(&dir, "s.toml")).unwrap();
    assert!(saved.contains("file = \"m.obj\""), "{saved}");
    assert!(saved.contains("fov = 35.0"), "{saved}");
    run_ok(
        &dir,
        &["render", "s.toml", "--method", "raster", "-o", "r.png"],
    );
    assert_eq!(read(&dir, "f.png"), read(&dir, "r.png"));
    // Unedited, the view is the model's default scene: what `render m.obj` draws.
    std::fs::write(dir.path().join("plain.txt"), "method raster\nframe p.png\n").unwrap();
    run_ok(&dir, &["view", "m.obj", "--script", "plain.txt"]);
    run_ok(
        &dir,
        &["render", "m.obj", "--method", "raster", "-o", "m.png"],
    );
    assert_eq!(read(&dir, "p.png"), read(&dir, "m.png"));
    assert_ne!(read(&dir, "f.png"), read(&dir, "m.png"));
    assert_eq!(read(&dir, "m.obj"), OCTAHEDRON.as_bytes());
}

#[test]
fn saving_a_model_session_never_writes_the_model() {
    // Onto the model itself, by its name, another spelling of it, or a hard link to it
    // named as a scene file: one error line, the model untouched, nothing written.
    for out in ["m.obj", "./m.obj", "alias.toml"] {
        let dir = model_dir(&format!("set fov 30\nsave {out}\nframe f.png\n"));
        std::fs::hard_link(dir.path().join("m.obj"), dir.path().join("alias.toml")).unwrap();
        let result = run(&dir, &["view", "m.obj", "--script", "view.txt"]);
        let stderr = String::from_utf8(result.stderr).unwrap();
        assert!(!result.status.success(), "{out}");
        assert_eq!(stderr.lines().count(), 1, "{out}: {stderr}");
        assert!(stderr.contains("view.txt:2:1:"), "{out}: {stderr}");
        assert_eq!(read(&dir, "m.obj"), OCTAHEDRON.as_bytes(), "{out}");
        assert_eq!(read(&dir, "alias.toml"), OCTAHEDRON.as_bytes(), "{out}");
        assert!(!dir.path().join("f.png").exists(), "{out}");
    }
    // Into another folder: the model named by its absolute path, so the scene still loads.
    let dir = model_dir("method raster\nset fov 30\nframe f.png\nsave sub/s.toml\n");
    run_ok(&dir, &["view", "m.obj", "--script", "view.txt"]);
    let saved = String::from_utf8(read(&dir, "sub/s.toml")).unwrap();
    let model = dir.path().join("m.obj").canonicalize().unwrap();
    let named = toml_edit::Value::from(model.to_str().unwrap()).to_string();
    assert!(saved.contains(&format!("file = {named}")), "{saved}");
    run_ok(
        &dir,
        &["render", "sub/s.toml", "--method", "raster", "-o", "r.png"],
    );
    assert_eq!(read(&dir, "f.png"), read(&dir, "r.png"));
    assert_eq!(read(&dir, "m.obj"), OCTAHEDRON.as_bytes());
}

#[test]
fn a_builtin_scene_is_viewed_and_saved_as_a_new_scene_file() {
    let dir = TempDir::new().unwrap();
    let script = "method raster\nset fov 44\nframe f.png\nsave s.toml\n";
    std::fs::write(dir.path().join("view.txt"), script).unwrap();
    run_ok(
        &dir,
        &["view", "builtin:cube-floor", "--script", "view.txt"],
    );
    run_ok(
        &dir,
        &["render", "s.toml", "--method", "raster", "-o", "r.png"],
    );
    assert_eq!(read(&dir, "f.png"), read(&dir, "r.png"));
    // The built-in scene's text, comments kept, with the one edit.
    let text = include_str!("../../../scenes/cube-floor.toml");
    let saved = String::from_utf8(read(&dir, "s.toml")).unwrap();
    assert_eq!(saved, text.replace("fov = 50.0", "fov = 44.0"));
    // An unknown name is one error line naming the known ones.
    let out = run(&dir, &["view", "builtin:nope", "--script", "view.txt"]);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success());
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("unknown built-in scene \"nope\""),
        "{stderr}"
    );
}
