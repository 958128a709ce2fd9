//! OBJ bytes through `flexcam::scene::loaders::load_model`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| flexcam_fuzz::load_model(data, "obj"));
