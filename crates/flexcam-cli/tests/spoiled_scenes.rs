//! Bad input through the binary: every example scene, spoiled in small ways (the mutations
//! of the library's `scene_mutations` test, from another seed), is either rendered (exit 0,
//! the image written) or refused with exit status 1, exactly one line on stderr naming the
//! scene file, and no image written: never a panic, a backtrace or a partial output.

use std::fs;
use std::path::Path;

use tempfile::TempDir;

mod common;
#[path = "../../flexcam/tests/mutations/mod.rs"]
mod mutations;

use common::run;
use mutations::{example_scenes, mutate, scenes_dir, Rng};

/// Mutations per example scene (each one a run of the binary).
const MUTATIONS: usize = 6;

/// Copies the folder `from` into `to` (the models, surfaces and photos the scenes name
/// relatively).
fn copy_dir(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for entry in fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let target = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_dir(&path, &target);
        } else {
            fs::copy(&path, &target).unwrap();
        }
    }
}

#[test]
fn spoiled_scenes_render_or_fail_with_one_line_naming_the_file() {
    let dir = TempDir::new().unwrap();
    for folder in ["models", "surfaces", "photos"] {
        copy_dir(&scenes_dir().join(folder), &dir.path().join(folder));
    }
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let (mut failures, mut rendered, mut refused) = (Vec::new(), 0, 0);
    for path in example_scenes() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let text = fs::read_to_string(&path).unwrap();
        for _ in 0..MUTATIONS {
            let (what, spoiled) = mutate(&text, &mut rng);
            fs::write(dir.path().join(&name), &spoiled).unwrap();
            let image = dir.path().join("out.png");
            let _ = fs::remove_file(&image);
            let args = [
                "render",
                &name,
                "--width",
                "8",
                "--height",
                "6",
                "--shading",
                "flat",
                "-o",
                "out.png",
            ];
            let out = run(&dir, &args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            let lines = stderr.trim_end().lines().count();
            let problem = match out.status.code() {
                Some(0) if image.exists() => {
                    rendered += 1;
                    None
                }
                Some(0) => Some("exit 0 without the image".to_string()),
                Some(1) if image.exists() => Some("an image written despite the error".into()),
                Some(1) if lines != 1 => Some(format!("{lines} lines on stderr")),
                Some(1) if !stderr.contains(&name) => {
                    Some("the error does not name the file".into())
                }
                Some(1) => {
                    refused += 1;
                    None
                }
                code => Some(format!("exit status {code:?}")),
            };
            if let Some(problem) = problem {
                failures.push(format!("{name}: {what}: {problem}: {}", stderr.trim_end()));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} spoiled scenes mishandled:\n{}",
        failures.len(),
        rendered + refused + failures.len(),
        failures.join("\n")
    );
    // As in the library's test: if few mutations still render, the test checks little.
    assert!(
        4 * rendered >= rendered + refused,
        "only {rendered} of {} rendered",
        rendered + refused
    );
}
