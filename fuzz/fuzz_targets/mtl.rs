//! MTL bytes, as the material library of a one-triangle OBJ that uses its material `a`.
#![no_main]

use libfuzzer_sys::fuzz_target;

const OBJ: &[u8] = b"mtllib model.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl a\nf 1/1 2/1 3/1\n";

fuzz_target!(|data: &[u8]| {
    flexcam_fuzz::write("model.mtl", data);
    flexcam_fuzz::load_model(OBJ, "obj");
});
