//! Wavefront OBJ with MTL materials, through tobj (triangulated, single index).

use std::cell::RefCell;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::obj_lines::{check_face_references, check_finite_numbers, check_mtl_values};
use super::{load_texture, read_file, Model, ModelPart};
use crate::error::{Error, Result};
use crate::scene::{Finish, InputFile, Material, Mesh, Pattern, Texture};

/// One `mtllib` the OBJ asked for: where it is and the material names it defined, or why it
/// could not be loaded.
struct MtlLibrary {
    path: PathBuf,
    outcome: Result<Vec<String>>,
}

/// Loads an OBJ file and the MTL libraries it names (relative to the OBJ's folder). Each OBJ
/// object / group becomes one part; `map_Kd` textures are resolved relative to their MTL.
/// A named MTL that is missing or malformed is an error, as is a file with no faces.
pub(super) fn load_obj(path: &Path) -> Result<Model> {
    let data = read_file(path)?;
    check_finite_numbers(path, &data)?;
    check_face_references(path, &data)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let libraries = RefCell::new(Vec::new());
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let mut reader = Cursor::new(data.as_slice());
    let loaded = tobj::load_obj_buf(&mut reader, &options, |name| {
        let (library, parsed) = load_mtl(&dir.join(name));
        libraries.borrow_mut().push(library);
        parsed
    });
    let (models, materials) = match loaded {
        Ok(loaded) => loaded,
        Err(e) => return Err(obj_error(path, &data, reader.position() as usize, e)),
    };
    let libraries = libraries.into_inner();
    let mut material_dirs = HashMap::new();
    let mut named: Vec<InputFile> = Vec::new();
    for library in libraries {
        named.push(InputFile {
            what: "material library",
            path: library.path.clone(),
        });
        let names = library.outcome?;
        let mtl_dir = library.path.parent().unwrap_or(Path::new("")).to_path_buf();
        material_dirs.extend(names.into_iter().map(|name| (name, mtl_dir.clone())));
    }
    let materials = materials.unwrap_or_default();
    let mut textures = TextureCache::default();
    let mut parts = Vec::new();
    for model in models {
        let Some(mesh) = convert_mesh(&model.mesh).map_err(|e| e.or_in_file(path))? else {
            continue;
        };
        let material = match model.mesh.material_id.and_then(|id| materials.get(id)) {
            Some(m) => {
                let dir = material_dirs.get(&m.name).map_or(dir, PathBuf::as_path);
                Some(convert_material(m, dir, &mut textures)?)
            }
            None => None,
        };
        parts.push(ModelPart { mesh, material });
    }
    if parts.is_empty() {
        return Err(Error::in_file(path, "contains no faces"));
    }
    named.extend(textures.0.into_keys().map(|path| InputFile {
        what: "texture",
        path,
    }));
    Ok(Model::read_from(path, parts, named))
}

/// Reads and parses one MTL file: the record of it, and what tobj needs of it.
fn load_mtl(path: &Path) -> (MtlLibrary, tobj::MTLLoadResult) {
    let parsed = read_file(path).and_then(|data| {
        check_mtl_values(path, &data)?;
        let mut reader = Cursor::new(data.as_slice());
        tobj::load_mtl_buf(&mut reader)
            .map_err(|e| obj_error(path, &data, reader.position() as usize, e))
    });
    let path = path.to_path_buf();
    match parsed {
        Ok((materials, names)) => {
            let outcome = Ok(materials.iter().map(|m| m.name.clone()).collect());
            (MtlLibrary { path, outcome }, Ok((materials, names)))
        }
        Err(e) => {
            let library = MtlLibrary {
                path,
                outcome: Err(e),
            };
            (library, Err(tobj::LoadError::MaterialParseError))
        }
    }
}

/// A tobj error as one line naming the file, with the line number for errors tobj raises
/// while parsing a line (it reads line by line and stops there, so the reader's position
/// tells the line). Index errors are found later, when an object is complete: no line.
fn obj_error(path: &Path, data: &[u8], consumed: usize, e: tobj::LoadError) -> Error {
    use tobj::LoadError::*;
    let message = format!("malformed OBJ/MTL: {e}");
    match e {
        ReadError
        | UnrecognizedCharacter
        | PositionParseError
        | ScalingByZeroError
        | ColorParseError
        | NormalParseError
        | TexcoordParseError
        | FaceParseError
        | MaterialParseError
        | InvalidObjectName => {
            let consumed = &data[..consumed.min(data.len())];
            let newlines = consumed.iter().filter(|&&b| b == b'\n').count();
            let unterminated = consumed.last().is_some_and(|&b| b != b'\n');
            Error::at(path, newlines + usize::from(unterminated), 1, message)
        }
        _ => Error::in_file(path, message),
    }
}

/// The mesh of one tobj model, or `None` when it has no triangles (only points or lines, or
/// only degenerate faces).
/// Attributes that do not cover every vertex are dropped; normals are normalised (zero
/// stays zero: "use the face normal").
fn convert_mesh(mesh: &tobj::Mesh) -> Result<Option<Mesh>> {
    if mesh.indices.len() % 3 != 0 {
        return Err(Error::new("face list is not made of triangles"));
    }
    let positions: Vec<Vec3> = mesh
        .positions
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect();
    let n = positions.len();
    let per_vertex = |data: &[f32], width: usize| data.len() == n * width;
    let result = Mesh {
        normals: if per_vertex(&mesh.normals, 3) {
            let normals = mesh.normals.chunks_exact(3).map(Vec3::from_slice);
            normals.map(Vec3::normalize_or_zero).collect()
        } else {
            Vec::new()
        },
        uvs: if per_vertex(&mesh.texcoords, 2) {
            mesh.texcoords
                .chunks_exact(2)
                .map(Vec2::from_slice)
                .collect()
        } else {
            Vec::new()
        },
        colors: if per_vertex(&mesh.vertex_color, 3) {
            mesh.vertex_color
                .chunks_exact(3)
                .map(Vec3::from_slice)
                .collect()
        } else {
            Vec::new()
        },
        // A face with a repeated vertex (tobj turns a two-vertex `f` into one) has no area.
        triangles: mesh
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .filter(|&[a, b, c]| a != b && b != c && c != a)
            .collect(),
        positions,
    };
    if result.triangles.is_empty() {
        return Ok(None);
    }
    result.validate()?;
    Ok(Some(result))
}

/// Textures loaded so far, so that materials sharing an image share one texture.
#[derive(Default)]
struct TextureCache(HashMap<PathBuf, Arc<Texture>>);

impl TextureCache {
    fn get(&mut self, path: PathBuf) -> Result<Arc<Texture>> {
        if let Some(texture) = self.0.get(&path) {
            return Ok(texture.clone());
        }
        let texture = Arc::new(load_texture(&path)?);
        self.0.insert(path, texture.clone());
        Ok(texture)
    }
}

/// The flexcam material of an MTL material.
///
/// `Kd` is the colour (white when only `map_Kd` is given, so the texture shows as is; the
/// default grey when neither is); `map_Kd` an image texture, relative to `dir`, the MTL's
/// folder (`map_Kd` options such as `-s 1 1 1` are skipped: the file name is the last word).
/// Hints: a non-black `Ke` makes the surface emissive with that colour; `illum` 3 or 5 (ray
/// traced reflection) a mirror; `illum` 6 or 7 (refraction) glass with index `Ni` (1.5 when
/// absent).
fn convert_material(
    m: &tobj::Material,
    dir: &Path,
    textures: &mut TextureCache,
) -> Result<Material> {
    let pattern = match m.diffuse_texture.as_deref().map(str::trim) {
        Some(map) if !map.is_empty() => {
            let file = if map.starts_with('-') {
                map.split_whitespace().last().unwrap_or(map)
            } else {
                map
            };
            Pattern::Texture(textures.get(dir.join(file))?)
        }
        _ => Pattern::Solid,
    };
    let default_color = match pattern {
        Pattern::Texture(_) => Vec3::ONE,
        _ => Material::default().color,
    };
    let emission = m.emissive.map(Vec3::from).filter(|e| e.max_element() > 0.0);
    let color = emission
        .or(m.diffuse.map(Vec3::from))
        .unwrap_or(default_color);
    let finish = match (emission, m.illumination_model) {
        (Some(_), _) => Finish::Emissive,
        (None, Some(3 | 5)) => Finish::Mirror,
        (None, Some(6 | 7)) => Finish::Glass {
            ior: m
                .optical_density
                .filter(|n| n.is_finite() && *n > 0.0)
                .unwrap_or(1.5),
        },
        _ => Finish::Diffuse,
    };
    Ok(Material {
        color,
        pattern,
        finish,
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_files::{example, listed, write};
    use super::*;

    #[test]
    fn loads_the_textured_octahedron() {
        let model = load_obj(&example("octahedron.obj")).unwrap();
        assert_eq!(
            listed(&model),
            [
                ("model file", example("octahedron.obj")),
                ("material library", example("octahedron.mtl")),
                ("texture", example("checker.png")),
            ]
        );
        let parts = model.parts;
        let triangles: usize = parts.iter().map(|p| p.mesh.triangle_count()).sum();
        assert_eq!(triangles, 8);
        assert_eq!(parts.len(), 2, "one part per material");
        for part in &parts {
            part.mesh.validate().unwrap();
            assert_eq!(part.mesh.normals.len(), part.mesh.positions.len());
            assert_eq!(part.mesh.uvs.len(), part.mesh.positions.len());
            assert!(part
                .mesh
                .normals
                .iter()
                .all(|n| (n.length() - 1.0).abs() < 1e-6));
            // Faces wind counter-clockwise about their normals.
            for t in &part.mesh.triangles {
                let [a, b, c] = t.map(|k| part.mesh.positions[k as usize]);
                assert!((b - a).cross(c - a).dot(part.mesh.normals[t[0] as usize]) > 0.0);
            }
        }
        let checker = parts[0].material.as_ref().unwrap();
        assert_eq!(checker.color, Vec3::ONE);
        let Pattern::Texture(texture) = &checker.pattern else {
            panic!("checker material has no texture: {checker:?}");
        };
        assert_eq!((texture.width, texture.height), (8, 8));
        assert_eq!(texture.texels[0], Vec3::ONE, "top-left cell is white");
        let red = parts[1].material.as_ref().unwrap();
        assert_eq!(red.color, Vec3::new(0.8, 0.1, 0.1));
        assert_eq!(
            (&red.pattern, red.finish),
            (&Pattern::Solid, Finish::Diffuse)
        );
    }

    #[test]
    fn parse_errors_carry_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(&dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 zero 0\nf 1 2 3\n");
        let e = load_obj(&path).unwrap_err();
        assert_eq!(e.location.unwrap().line_column, Some((3, 1)));
        // Truncated mid-line, without a final newline.
        let path = write(&dir, "cut.obj", "v 0 0 0\nv 1 0");
        let e = load_obj(&path).unwrap_err();
        assert_eq!(e.location.unwrap().line_column, Some((2, 1)));
        // Truncated inside the face list: the two-vertex face has no area.
        let path = write(&dir, "cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2");
        let e = load_obj(&path).unwrap_err().to_string();
        assert!(e.contains("cut.obj") && e.contains("no faces"), "{e}");
    }

    #[test]
    fn out_of_range_face_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        for face in ["f 1 2 7", "f 1 2 0", "f 1 2 -9"] {
            let path = write(
                &dir,
                "range.obj",
                format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\n"),
            );
            let e = load_obj(&path).unwrap_err().to_string();
            assert!(e.starts_with(&path.display().to_string()), "{e}");
            assert!(e.contains("out of bounds"), "{face}: {e}");
        }
    }

    #[test]
    fn no_faces_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(&dir, "points.obj", "v 0 0 0\nv 1 0 0\np 1 2\n");
        let e = load_obj(&path).unwrap_err().to_string();
        assert!(e.contains("no faces"), "{e}");
        let path = write(&dir, "empty.obj", "");
        assert!(load_obj(&path).is_err());
    }

    #[test]
    fn material_problems_name_the_right_file() {
        let dir = tempfile::tempdir().unwrap();
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
        let path = write(&dir, "nomtl.obj", format!("mtllib absent.mtl\n{tri}"));
        let e = load_obj(&path).unwrap_err().to_string();
        assert!(e.contains("absent.mtl") && e.contains("cannot read"), "{e}");

        write(&dir, "notex.mtl", "newmtl m\nKd 1 0 0\nmap_Kd absent.png\n");
        let path = write(&dir, "notex.obj", format!("mtllib notex.mtl\n{tri}"));
        let e = load_obj(&path).unwrap_err().to_string();
        assert!(e.contains("absent.png"), "{e}");

        write(&dir, "badkd.mtl", "newmtl m\nKd 1 zero\n");
        let path = write(&dir, "badkd.obj", format!("mtllib badkd.mtl\n{tri}"));
        let e = load_obj(&path).unwrap_err();
        let location = e.location.unwrap();
        assert!(location.file.ends_with("badkd.mtl"));
        assert_eq!(location.line_column, Some((2, 1)));
    }

    #[test]
    fn material_hints_and_texture_options() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::copy(example("checker.png"), dir.path().join("c.png")).unwrap();
        write(
            &dir,
            "hints.mtl",
            "newmtl glass\nKd 1 1 1\nNi 1.33\nillum 7\n\
             newmtl mirror\nillum 3\n\
             newmtl lamp\nKe 2 2 1\n\
             newmtl tex\nmap_Kd -s 2 2 1 c.png\n",
        );
        let mut obj = String::from("mtllib hints.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
        for m in ["glass", "mirror", "lamp", "tex"] {
            obj += &format!("o {m}\nusemtl {m}\nf 1 2 3\n");
        }
        let parts = load_obj(&write(&dir, "hints.obj", obj)).unwrap().parts;
        let materials: Vec<Material> = parts.into_iter().map(|p| p.material.unwrap()).collect();
        assert_eq!(materials[0].finish, Finish::Glass { ior: 1.33 });
        assert_eq!(materials[1].finish, Finish::Mirror);
        assert_eq!(materials[2].finish, Finish::Emissive);
        assert_eq!(materials[2].color, Vec3::new(2.0, 2.0, 1.0));
        assert!(matches!(materials[3].pattern, Pattern::Texture(_)));
        assert_eq!(materials[3].color, Vec3::ONE);
    }

    #[test]
    fn faces_without_material_have_none() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(
            &dir,
            "plain.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n",
        );
        let parts = load_obj(&path).unwrap().parts;
        assert_eq!(parts.len(), 1);
        assert!(parts[0].material.is_none());
        assert_eq!(parts[0].mesh.triangle_count(), 2, "quad triangulated");
        assert!(parts[0].mesh.normals.is_empty() && parts[0].mesh.uvs.is_empty());
    }
}
