//! Model and texture loaders: OBJ with MTL (tobj), glTF 2.0 / GLB (gltf), PLY (ply-rs), and
//! PNG / JPEG textures (image).

use std::path::Path;

use super::{Material, Mesh, Texture};
use crate::error::Result;

/// One part of a loaded model: a mesh and the material the file gives it, if any.
#[derive(Debug, Clone)]
pub struct ModelPart {
    pub mesh: Mesh,
    pub material: Option<Material>,
}

/// Loads an OBJ (with its MTL), glTF / GLB or PLY file, chosen by extension. Errors name the
/// file (and line where the format allows).
pub fn load_model(path: &Path) -> Result<Vec<ModelPart>> {
    let _ = path;
    todo!("loaders::load_model")
}

/// Loads a PNG or JPEG image as a linear-colour texture (sRGB decoded).
pub fn load_texture(path: &Path) -> Result<Texture> {
    let _ = path;
    todo!("loaders::load_texture")
}
