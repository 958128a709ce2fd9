//! Scene-file text through `flexcam::scene::file::parse`, with the model loaders behind it.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| flexcam_fuzz::parse_scene(data));
