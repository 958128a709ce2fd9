//! Bad input never panics: every example scene in `scenes/`, spoiled in many small ways (a
//! number replaced by an extreme or meaningless one, a string emptied, an array emptied or
//! shortened, a line deleted, the text cut short), is loaded, its projection built and, where
//! that succeeds, rendered at 8 x 6 by every method that renders it. Each step may refuse
//! the input with an error (that is what it should do); none may panic. The mutations are
//! drawn from a fixed seed, so a failure names a mutation that reproduces.
//!
//! What this does not check: that the error is one line naming the file (the binary's test
//! `crates/flexcam-cli/tests/spoiled_scenes.rs` does, with the same mutations), and workloads that are merely large: the replacement
//! numbers are small (at most 2) or huge or non-finite, which the loader's limits (with
//! their own tests) refuse for sizes such as `tessellation`, so no mutation asks for a long
//! render.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use flexcam::render::{self, Method, PreparedScene, RenderOptions, Shading};
use flexcam::scene::file;

mod mutations;

use mutations::{example_scenes, mutate, Rng};

/// Mutations per example scene.
const MUTATIONS: usize = 24;

/// Loads, builds and renders `text` as if it were the file `path`; errors are fine.
/// Returns whether it got as far as rendering.
fn exercise(text: &str, path: &Path) -> bool {
    let Ok((scene, _animation)) = file::parse_animated(text, path) else {
        return false;
    };
    let Ok(projection) = scene.projection.build(8, 6) else {
        return false;
    };
    let options = RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let mut methods = vec![Method::Raycast];
    if projection.inverse().is_ok() {
        methods.push(Method::Raster);
    }
    if projection.trilinear().is_some() {
        methods.push(Method::Trilinear);
    }
    let prepared = PreparedScene::new(&scene);
    for method in methods {
        let options = RenderOptions { method, ..options };
        let _ = render::render(&prepared, projection.as_ref(), &options);
    }
    true
}

#[test]
fn spoiled_example_scenes_are_refused_or_rendered_never_a_panic() {
    let scenes = example_scenes();
    assert!(scenes.len() >= 20, "found only {} scenes", scenes.len());
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut panics, mut rendered) = (Vec::new(), 0);
    for path in &scenes {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{e}"));
        for _ in 0..MUTATIONS {
            let (what, spoiled) = mutate(&text, &mut rng);
            match catch_unwind(AssertUnwindSafe(|| exercise(&spoiled, path))) {
                Ok(reached_render) => rendered += usize::from(reached_render),
                Err(_) => panics.push(format!("{}: {what}", path.display())),
            }
        }
    }
    assert!(
        panics.is_empty(),
        "{} panics:\n{}",
        panics.len(),
        panics.join("\n")
    );
    // Most mutations keep a loadable scene (a changed colour or position): if few reach the
    // renderers, the mutations (or the paths the scenes resolve models against) are broken
    // and the test checks nothing past the parser.
    let total = scenes.len() * MUTATIONS;
    assert!(
        4 * rendered >= total,
        "only {rendered} of {total} mutations were rendered"
    );
    eprintln!("{rendered} of {total} spoiled scenes loaded and rendered, the rest refused");
}
