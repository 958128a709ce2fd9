//! Model and texture loaders: OBJ with MTL (tobj), glTF 2.0 / GLB (gltf), PLY (ply-rs), and
//! PNG / JPEG textures (image).
//!
//! Every loader returns meshes that pass [`Mesh::validate`], and reports every problem with
//! its input (missing, unreadable or malformed file, bad index) as one error line naming the
//! file, with a line number where the format and library give one. None panics on
//! malformed input.

mod gltf_cameras;
mod gltf_checks;
mod gltf_loader;
mod obj;
mod obj_lines;
mod ply;
mod texture;

use std::path::Path;

use super::{InputFile, Material, Mesh};
use crate::error::{Error, Result};
use crate::file_read::{read_regular, MAX_DATA_FILE_BYTES};

pub use gltf_cameras::{CameraLens, ModelCamera};
pub use obj_lines::check_obj_file;
pub use texture::load_texture;

/// One part of a loaded model: a mesh and the material the file gives it, if any.
#[derive(Debug, Clone)]
pub struct ModelPart {
    /// The part's triangles, in the model file's coordinates.
    pub mesh: Mesh,
    /// The material the file assigns the part (`None`: the scene object's).
    pub material: Option<Material>,
}

/// A loaded model: its parts, every file the load read (the model file first, then the
/// files it names: material libraries, textures, buffers) and the cameras it places (glTF
/// only; in the order the loader meets their nodes, depth first in file order).
#[derive(Debug, Clone)]
pub struct Model {
    /// The model's meshes, each with its material.
    pub parts: Vec<ModelPart>,
    /// Every file read, the model file first.
    pub files: Vec<InputFile>,
    /// The glTF file's cameras placed by its nodes, in the file's camera order (none for
    /// OBJ and PLY).
    pub cameras: Vec<ModelCamera>,
}

impl Model {
    /// A model read from `path` and the `named` files.
    fn read_from(path: &Path, parts: Vec<ModelPart>, named: Vec<InputFile>) -> Model {
        let model_file = InputFile {
            what: "model file",
            path: path.to_path_buf(),
        };
        Model {
            parts,
            files: std::iter::once(model_file).chain(named).collect(),
            cameras: Vec::new(),
        }
    }
}

/// Model file extensions [`load_model`] accepts (compared case-insensitively).
pub const MODEL_EXTENSIONS: [&str; 4] = ["obj", "gltf", "glb", "ply"];

/// Loads an OBJ (with its MTL), glTF / GLB or PLY file, chosen by extension. Errors name the
/// file (and line where the format allows).
pub fn load_model(path: &Path) -> Result<Model> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("obj") => obj::load_obj(path),
        Some("gltf" | "glb") => gltf_loader::load_gltf(path),
        Some("ply") => ply::load_ply(path),
        _ => Err(Error::in_file(
            path,
            format!(
                "unsupported model format; expected one of .{}",
                MODEL_EXTENSIONS.join(", .")
            ),
        )),
    }
}

/// The bytes of a regular file, or an error naming it.
fn read_file(path: &Path) -> Result<Vec<u8>> {
    read_regular(path, "file", MAX_DATA_FILE_BYTES)
}

/// Helpers for the loader tests.
#[cfg(test)]
pub(super) mod test_files {
    use std::path::{Path, PathBuf};

    /// An example model shipped in `scenes/models/`.
    pub fn example(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes/models")
            .join(name)
    }

    /// What each file `model` was read from is, and its path.
    pub fn listed(model: &super::Model) -> Vec<(&'static str, PathBuf)> {
        model
            .files
            .iter()
            .map(|f| (f.what, f.path.clone()))
            .collect()
    }

    /// Writes `contents` to `name` in `dir` and returns its path.
    pub fn write(dir: &tempfile::TempDir, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let path = dir.path().join(name);
        std::fs::write(&path, contents).expect("write test file");
        path
    }
}

#[cfg(test)]
mod tests {
    use super::test_files::{example, write};
    use super::*;

    #[test]
    fn dispatch_is_case_insensitive() {
        let dir = tempfile::tempdir().unwrap();
        let ply = std::fs::read(example("pyramid.ply")).unwrap();
        let upper = write(&dir, "PYRAMID.PLY", ply);
        let model = load_model(&upper).unwrap();
        assert_eq!(model.parts[0].mesh.triangle_count(), 6);
        assert_eq!(
            model.files,
            [InputFile {
                what: "model file",
                path: upper
            }]
        );
    }

    #[test]
    fn unsupported_extension_names_file_and_formats() {
        for name in ["model.stl", "model"] {
            let e = load_model(Path::new(name)).unwrap_err().to_string();
            assert!(e.starts_with(name), "{e}");
            assert!(e.contains(".obj, .gltf, .glb, .ply"), "{e}");
        }
    }

    #[test]
    fn missing_files_name_the_file() {
        for name in ["nope.obj", "nope.gltf", "nope.glb", "nope.ply"] {
            let e = load_model(Path::new(name)).unwrap_err().to_string();
            assert!(e.starts_with(name) && !e.contains('\n'), "{e}");
        }
    }
}
