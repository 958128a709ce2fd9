//! Outputs never lose data: every command refuses, before any work, an output that is one of
//! its inputs (the scene file, a model and the files it names, a texture, a trilinear
//! surface, the photo) or another of its outputs, whatever the spelling (`./`, `../dir/`,
//! absolute, symlink, hard link); creates missing output folders; and writes all its outputs
//! or none, leaving no temporary file behind.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use tempfile::TempDir;

const SCENES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");

/// A folder `work/` holding copies of the example scenes `models.toml` (as `scene.png`, so
/// that a PNG output can be aimed at it), `trilinear-fan.toml` and `flexible-animation.toml`
/// (as `anim_0000.png`) with the files they name, a photo, and links to inputs.
struct Setup {
    root: TempDir,
}

impl Setup {
    fn new() -> Setup {
        let root = TempDir::new().unwrap();
        let work = root.path().join("work");
        fs::create_dir_all(work.join("models")).unwrap();
        fs::create_dir_all(work.join("surfaces")).unwrap();
        for name in [
            "octahedron.obj",
            "octahedron.mtl",
            "checker.png",
            "pyramid.ply",
            "tetra-quad.glb",
        ] {
            fs::copy(
                Path::new(SCENES).join("models").join(name),
                work.join("models").join(name),
            )
            .unwrap();
        }
        fs::copy(
            Path::new(SCENES).join("surfaces/fan18.obj"),
            work.join("surfaces/fan18.obj"),
        )
        .unwrap();
        let copy = |from: &str, to: &str| {
            fs::copy(Path::new(SCENES).join(from), work.join(to)).unwrap();
        };
        copy("models.toml", "scene.png");
        copy("trilinear-fan.toml", "fan.toml");
        copy("flexible-animation.toml", "anim_0000.png");
        copy("models/checker.png", "photo.png");
        let link = |target: &str, name: &str| {
            fs::hard_link(work.join(target), work.join(name)).unwrap();
        };
        link("models/pyramid.ply", "pyramid-link.png");
        link("models/octahedron.mtl", "mtl-link.txt");
        link("surfaces/fan18.obj", "fan-link.png");
        link("models/checker.png", "checker-link.exr");
        link("anim_0000.png", "anim-link.gif");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink("scene.png", work.join("scene-symlink.png")).unwrap();
            std::os::unix::fs::symlink("photo.png", work.join("photo-symlink.png")).unwrap();
        }
        Setup { root }
    }

    fn work(&self) -> PathBuf {
        self.root.path().join("work")
    }

    /// The absolute path of `name` in `work/`, as a string.
    fn absolute(&self, name: &str) -> String {
        self.work().join(name).to_string_lossy().into_owned()
    }

    /// Every file under the root with its bytes (links as their targets' bytes).
    fn snapshot(&self) -> BTreeMap<PathBuf, Vec<u8>> {
        let mut files = BTreeMap::new();
        let mut folders = vec![self.root.path().to_path_buf()];
        while let Some(folder) = folders.pop() {
            for entry in fs::read_dir(&folder).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    folders.push(path);
                } else {
                    files.insert(path.clone(), fs::read(&path).unwrap_or_default());
                }
            }
        }
        files
    }

    /// Runs `flexcam ARGS` in `work/`, expecting one error line that contains `expected`,
    /// and no file created, changed or removed anywhere.
    fn refused(&self, args: &[&str], expected: &str) {
        let before = self.snapshot();
        let out = run_in(&self.work(), args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(before == self.snapshot(), "{args:?} changed the files");
    }
}

/// Runs `flexcam ARGS` in `folder`, which must succeed.
fn succeeds(folder: &Path, args: &[&str]) {
    let out = run_in(folder, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?}: {stderr}");
}

/// Runs `flexcam ARGS` in `folder`.
fn run_in(folder: &Path, args: &[&str]) -> std::process::Output {
    assert_cmd::Command::cargo_bin("flexcam")
        .unwrap()
        .current_dir(folder)
        .args(args)
        .output()
        .unwrap()
}

const SMALL: [&str; 4] = ["--width", "16", "--height", "12"];

fn render<'a>(scene: &'a str, outputs: &[&'a str]) -> Vec<&'a str> {
    [&["render", scene][..], &SMALL, outputs].concat()
}

#[test]
fn outputs_aimed_at_the_scene_file_are_refused_in_every_spelling() {
    let s = Setup::new();
    let absolute = s.absolute("scene.png");
    let mut spellings = vec![
        "scene.png",
        "./scene.png",
        ".//scene.png",
        "models/../scene.png",
        "./models/./../scene.png",
        "../work/scene.png",
        &absolute,
    ];
    if cfg!(unix) {
        spellings.push("scene-symlink.png");
    }
    for spelling in spellings {
        for flag in ["-o", "--ids"] {
            let mut args = render("scene.png", &[flag, spelling]);
            if flag == "--ids" {
                args.extend(["-o", "out.png"]);
            }
            s.refused(&args, "would overwrite the scene file");
        }
        s.refused(
            &render("./scene.png", &["-o", spelling]),
            "would overwrite the scene file",
        );
        s.refused(
            &[
                "compare",
                "scene.png",
                "--method",
                "raster",
                "--diff",
                spelling,
            ],
            "the diff output would overwrite the scene file",
        );
    }
    s.refused(
        &render("scene-symlink.png", &["-o", "scene.png"]),
        "the output would overwrite the scene file",
    );
    // The frames of an animation and its GIF.
    s.refused(
        &[
            &["animate", "anim_0000.png", "-o", "anim_####.png"][..],
            &SMALL,
        ]
        .concat(),
        "frame 0 of the output would overwrite the scene file",
    );
    s.refused(
        &[
            &["animate", "anim_0000.png", "--gif", "anim-link.gif"][..],
            &SMALL,
        ]
        .concat(),
        "the GIF output would overwrite the scene file",
    );
    s.refused(
        &["fit", "fan.toml", "-o", "../work/./fan.toml"],
        "would overwrite the fitting scene",
    );
}

#[test]
fn outputs_aimed_at_models_textures_surfaces_and_photos_are_refused() {
    let s = Setup::new();
    let texture = s.absolute("models/checker.png");
    for (outputs, expected) in [
        (
            vec!["-o", "pyramid-link.png"],
            "the output would overwrite the model file",
        ),
        (
            vec!["--stats", "mtl-link.txt"],
            "the stats output would overwrite the material library",
        ),
        (
            vec!["-o", "models/checker.png"],
            "the output would overwrite the texture",
        ),
        (
            vec!["--ids", "./models/../models/checker.png"],
            "the ids output would overwrite the texture",
        ),
        (
            vec!["--ids", &texture],
            "the ids output would overwrite the texture",
        ),
        (
            vec!["--depth", "checker-link.exr"],
            "the depth output would overwrite the texture",
        ),
    ] {
        s.refused(&render("scene.png", &outputs), expected);
    }
    s.refused(
        &render("fan.toml", &["-o", "fan-link.png"]),
        "the output would overwrite the trilinear surface",
    );
    let photo = s.absolute("photo.png");
    let mut spellings = vec!["photo.png", "./photo.png", "../work/photo.png", &photo];
    if cfg!(unix) {
        spellings.push("photo-symlink.png");
    }
    for spelling in spellings {
        for input in ["photo.png", "./photo.png"] {
            s.refused(
                &["reproject", "--input", input, "-o", spelling],
                "the output would overwrite the photo",
            );
        }
    }
    s.refused(
        &[
            "reproject",
            "--input",
            "photo.png",
            "scene.png",
            "-o",
            "models/checker.png",
        ],
        "the output would overwrite the texture",
    );
}

#[test]
fn two_outputs_aimed_at_each_other_are_refused() {
    let s = Setup::new();
    let out = s.absolute("out.png");
    s.refused(
        &render("scene.png", &["-o", "out.png", "--ids", "./out.png"]),
        "the ids output is the same file as the output out.png",
    );
    s.refused(
        &render("scene.png", &["-o", "new/../out.png", "--ids", &out]),
        "the ids output is the same file as the output",
    );
    fs::write(s.work().join("old.png"), b"old").unwrap();
    fs::hard_link(s.work().join("old.png"), s.work().join("old-link.png")).unwrap();
    s.refused(
        &render("scene.png", &["-o", "old.png", "--ids", "old-link.png"]),
        "the ids output is the same file as the output old.png",
    );
}

#[test]
fn missing_output_folders_are_created() {
    let s = Setup::new();
    let work = s.work();
    succeeds(
        &work,
        &render(
            "scene.png",
            &[
                "-o",
                "a/b/c.png",
                "--depth",
                "a/d/depth.exr",
                "--ids",
                "e/./ids.png",
                "--stats",
                "f/g/../stats.json",
            ],
        ),
    );
    for made in ["a/b/c.png", "a/d/depth.exr", "e/ids.png", "f/stats.json"] {
        assert!(work.join(made).is_file(), "{made}");
    }
    assert!(!work.join("f/g").exists(), "f/g/.. needs no folder g");
    succeeds(
        &work,
        &[
            &[
                "animate",
                "anim_0000.png",
                "-o",
                "frames/x/f_####.png",
                "--gif",
                "gif/a.gif",
            ][..],
            &SMALL,
        ]
        .concat(),
    );
    assert!(work.join("frames/x/f_0000.png").is_file());
    assert!(work.join("gif/a.gif").is_file());
    succeeds(
        &work,
        &[
            "reproject",
            "--input",
            "photo.png",
            "-o",
            "re/p.png",
            "--width",
            "8",
            "--height",
            "4",
        ],
    );
    assert!(work.join("re/p.png").is_file());
    succeeds(
        &work,
        &[
            &[
                "compare",
                "scene.png",
                "--method",
                "raster",
                "--diff",
                "diff/d.png",
            ][..],
            &SMALL,
        ]
        .concat(),
    );
    assert!(work.join("diff/d.png").is_file());
    // Nothing but the outputs: no temporary, no backup.
    let strays: Vec<_> = s
        .snapshot()
        .into_keys()
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect();
    assert!(strays.is_empty(), "{strays:?}");
}

/// A failure after every output is staged (the ids output's path is a folder) leaves the
/// old outputs as they were, no new file or folder, and no temporary or backup.
#[test]
fn a_failed_commit_leaves_the_old_outputs() {
    let s = Setup::new();
    let work = s.work();
    fs::write(work.join("old.png"), b"old image").unwrap();
    fs::write(work.join("stats.json"), b"old stats").unwrap();
    fs::create_dir_all(work.join("ids.png/inside")).unwrap();
    let before = s.snapshot();
    let args = render(
        "scene.png",
        &[
            "-o",
            "old.png",
            "--stats",
            "stats.json",
            "--depth",
            "new/depth.pfm",
            "--ids",
            "ids.png",
        ],
    );
    let out = run_in(&work, &args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("ids.png: cannot write"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(before == s.snapshot(), "the files changed");
    assert!(!work.join("new").exists());

    // The same outputs with the folder gone: all written, the old ones replaced.
    fs::remove_dir_all(work.join("ids.png")).unwrap();
    succeeds(&work, &args);
    assert_ne!(fs::read(work.join("old.png")).unwrap(), b"old image");
    assert!(fs::read_to_string(work.join("stats.json"))
        .unwrap()
        .starts_with('{'));
    assert!(work.join("new/depth.pfm").is_file() && work.join("ids.png").is_file());
}
