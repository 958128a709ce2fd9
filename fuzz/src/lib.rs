//! What the fuzz targets share: each writes the fuzzer's bytes to a file in a folder of its
//! own process and loads it as flexcam would, under a small memory budget (so that a count
//! the loaders accept still fits the fuzzer's memory limit). Any panic, abort, hang or
//! runaway allocation is a finding; an error is the expected outcome for most inputs.

use std::path::{Path, PathBuf};
use std::sync::Once;

/// The memory budget of a fuzzed load (see `flexcam::scene::budget`).
const FUZZ_MAX_MEMORY: u64 = 256 << 20;

/// A folder of this process's own under the system's temporary folder.
pub fn work_dir() -> PathBuf {
    static INIT: Once = Once::new();
    let dir = std::env::temp_dir().join(format!("flexcam-fuzz-{}", std::process::id()));
    INIT.call_once(|| {
        std::fs::create_dir_all(&dir).expect("create the fuzzing folder");
        flexcam::scene::budget::set_max_memory(FUZZ_MAX_MEMORY);
    });
    dir
}

/// Writes `data` to `name` in [`work_dir`] and returns its path.
pub fn write(name: &str, data: &[u8]) -> PathBuf {
    let path = work_dir().join(name);
    std::fs::write(&path, data).expect("write the fuzzed file");
    path
}

/// Loads `data` as a model file with extension `extension`.
pub fn load_model(data: &[u8], extension: &str) {
    let path = write(&format!("model.{extension}"), data);
    let _ = flexcam::scene::loaders::load_model(&path);
}

/// Parses `data` as a scene file placed in `scenes/` (so that the example scenes of the
/// seed corpus find their models and surfaces).
pub fn parse_scene(data: &[u8]) {
    work_dir();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/fuzzed.toml");
    let _ = flexcam::scene::file::parse(text, &path);
}
