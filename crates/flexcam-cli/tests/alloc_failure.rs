//! A frame allocation that fails (memory taken by others after the budget allowed the
//! scene): one line naming the scene file and the bytes asked for, exit status 1, no output
//! written; never an abort. The failure is injected by the library's test hook
//! (`flexcam::try_alloc`, environment variable `FLEXCAM_TEST_ALLOC_LIMIT`): every buffer
//! allocation above the limit fails as the allocator's refusal would.

use std::fs;
use std::process::Output;

use assert_cmd::Command;
use tempfile::TempDir;

/// Larger than every buffer of a scene's loading, smaller than a 400 x 300 frame's colour
/// (1.44 MB).
const LIMIT: &str = "1000000";

/// A 400 x 300 perspective view of a box (`scene.toml`).
const SCENE: &str = "[image]\nwidth = 400\nheight = 300\n\n[projection]\ntype = \"perspective\"\n\
                     position = [0, 1, 4]\nlook_at = [0, 0, 0]\nfov = 60\n\n[[object]]\n\
                     shape = \"box\"\nsize = [1, 1, 1]\n";

/// The same view as a 400 x 300 animation of two keys (`anim.toml`).
const ANIMATION: &str = "[image]\nwidth = 400\nheight = 300\n\n[projection]\n\
                         type = \"perspective\"\nposition = [0, 1, 4]\nlook_at = [0, 0, 0]\n\
                         fov = 60\n\n[[object]]\nshape = \"box\"\n\
                         size = [1, 1, 1]\n\n[animation]\nframes = 2\nfps = 1.0\n\n\
                         [[animation.key]]\ntime = 0.0\n[animation.key.projection]\n\
                         type = \"flexible\"\npreset = \"perspective\"\nfov = 60.0\n\
                         position = [0, 1, 4]\nlook_at = [0, 0, 0]\n\n\
                         [[animation.key]]\ntime = 1.0\n[animation.key.projection]\n\
                         type = \"flexible\"\npreset = \"perspective\"\nfov = 40.0\n\
                         position = [0, 1, 4]\nlook_at = [0, 0, 0]\n";

/// The colour buffer of the 400 x 300 frame, the first allocation that fails.
const FRAME_LINE: &str = "out of memory: cannot allocate 1.4 MB for the 400 x 300 frame";

/// Runs `flexcam ARGS` in `dir` with allocations above `limit` bytes failing (`None`: the
/// hook unset).
fn run(dir: &TempDir, limit: Option<&str>, args: &[&str]) -> Output {
    let mut command = Command::cargo_bin("flexcam").expect("flexcam binary");
    command.current_dir(dir.path()).args(args);
    match limit {
        Some(limit) => command.env("FLEXCAM_TEST_ALLOC_LIMIT", limit),
        None => command.env_remove("FLEXCAM_TEST_ALLOC_LIMIT"),
    };
    command.output().expect("flexcam runs")
}

/// A folder holding `scene.toml`, a copy of it `ref.toml` and `anim.toml`.
fn scenes() -> TempDir {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("scene.toml"), SCENE).unwrap();
    fs::write(dir.path().join("ref.toml"), SCENE).unwrap();
    fs::write(dir.path().join("anim.toml"), ANIMATION).unwrap();
    dir
}

/// Asserts that `flexcam ARGS` under the hook's limit exits 1 with exactly `line` on stderr
/// and leaves no file but the scenes in its folder, and that it succeeds without the hook.
fn fails_cleanly(args: &[&str], line: &str) {
    let dir = scenes();
    let out = run(&dir, Some(LIMIT), args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert_eq!(stderr, format!("flexcam: {line}\n"), "{args:?}");
    let mut left: Vec<String> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(
        left,
        ["anim.toml", "ref.toml", "scene.toml"],
        "{args:?} wrote output"
    );
    let out = run(&dir, None, args);
    assert!(
        out.status.success(),
        "{args:?} without the hook: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn render_names_the_scene_and_the_frame_for_every_method() {
    let line = format!("scene.toml: {FRAME_LINE}");
    for method in ["raycast", "raster"] {
        let args = ["render", "scene.toml", "--method", method, "-o", "out.png"];
        fails_cleanly(&args, &line);
    }
    // The surface layers and the crop window go through the same frame first.
    fails_cleanly(
        &[
            "render",
            "scene.toml",
            "-o",
            "out.png",
            "--aovs",
            "aovs.exr",
        ],
        &line,
    );
    fails_cleanly(
        &["render", "scene.toml", "-o", "out.exr", "--spp", "4"],
        &line,
    );
}

#[test]
fn compare_animate_and_raymap_fail_alike() {
    let line = format!("scene.toml: {FRAME_LINE}");
    fails_cleanly(
        &[
            "compare",
            "scene.toml",
            "--method",
            "raster",
            "--diff",
            "diff.png",
        ],
        &line,
    );
    fails_cleanly(
        &[
            "animate",
            "anim.toml",
            "-o",
            "frame_#.png",
            "--gif",
            "a.gif",
        ],
        &format!("anim.toml: {FRAME_LINE}"),
    );
    fails_cleanly(
        &["raymap", "scene.toml", "-o", "rays.exr"],
        "scene.toml: out of memory: cannot allocate 12.5 MB for the ray map of the 400 x 300 \
         image",
    );
    fails_cleanly(
        &[
            "raymap",
            "scene.toml",
            "--stmap",
            "st.exr",
            "--reference",
            "ref.toml",
        ],
        "scene.toml: out of memory: cannot allocate 2.9 MB for the STMap of the 400 x 300 frame",
    );
}
