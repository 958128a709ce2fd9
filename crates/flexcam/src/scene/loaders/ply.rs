//! Stanford PLY (ASCII and binary), through ply-rs.

use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs::parser::Parser;
use ply_rs::ply::{DefaultElement, Property};

use super::read_file;
use super::texture::srgb_to_linear;
use super::{Model, ModelPart};
use crate::error::{Error, Result};
use crate::scene::Mesh;

/// Loads the `vertex` and `face` elements of a PLY file as one part (PLY has no materials).
///
/// Vertices: `x y z`, optional `nx ny nz`, texture coordinates `u v`, `s t` or
/// `texture_u texture_v`, and colours `red green blue`: integer colours are taken as
/// sRGB-encoded and decoded to linear, floating-point colours as linear. Faces:
/// `vertex_indices` or `vertex_index` lists, fan-triangulated.
pub(super) fn load_ply(path: &Path) -> Result<Model> {
    let data = read_file(path)?;
    check_header(path, &data)?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut data.as_slice())
        .map_err(|e| ply_error(path, &e.to_string()))?;
    let no_element = |name: &str| Error::in_file(path, format!("has no \"{name}\" element"));
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| no_element("vertex"))?;
    let faces = ply.payload.get("face").ok_or_else(|| no_element("face"))?;
    let mesh = convert(vertices, faces).map_err(|e| e.or_in_file(path))?;
    if mesh.triangles.is_empty() {
        return Err(Error::in_file(path, "contains no faces"));
    }
    let part = ModelPart {
        mesh,
        material: None,
    };
    Ok(Model::read_from(path, vec![part], Vec::new()))
}

/// Checks the header before ply-rs sees it. Each `element NAME COUNT` line: ply-rs panics
/// on a count that does not fit 64 bits, and would loop over a huge count of empty
/// elements; every element takes at least one byte, so a count above the file size is
/// malformed. The `format` line: ply-rs accepts any version, but only PLY 1.0 is defined.
fn check_header(path: &Path, data: &[u8]) -> Result<()> {
    let header = data
        .split(|&b| b == b'\n')
        .take_while(|line| !line.starts_with(b"end_header"));
    for (k, line) in header.enumerate() {
        let line = String::from_utf8_lossy(line);
        let words: Vec<&str> = line.split_whitespace().collect();
        if let ["element", name, count, ..] = words[..] {
            let fits = count.parse::<u64>().is_ok_and(|n| n <= data.len() as u64);
            if !fits {
                let column = line.rfind(count).map_or(1, |c| c + 1);
                let message = format!("element \"{name}\" has an impossible count \"{count}\"");
                return Err(Error::at(path, k + 1, column, message));
            }
        }
        if let ["format", _, version, ..] = words[..] {
            if version != "1.0" {
                let column = line.rfind(version).map_or(1, |c| c + 1);
                let message = format!("PLY version \"{version}\" is not supported (only 1.0)");
                return Err(Error::at(path, k + 1, column, message));
            }
        }
    }
    Ok(())
}

/// A ply-rs error as one line: ply-rs prefixes parse errors with "Line N: ", N counted
/// from 1 (from 0 for the magic first line, reported here as line 1).
fn ply_error(path: &Path, message: &str) -> Error {
    let first_line = message.lines().next().unwrap_or(message);
    let located = first_line.strip_prefix("Line ").and_then(|rest| {
        let (line, text) = rest.split_once(": ")?;
        Some((line.parse::<usize>().ok()?, text))
    });
    match located {
        Some((line, text)) => Error::at(path, line.max(1), 1, format!("malformed PLY: {text}")),
        None => Error::in_file(path, format!("malformed PLY: {first_line}")),
    }
}

/// The mesh of the vertex and face elements.
fn convert(vertices: &[DefaultElement], faces: &[DefaultElement]) -> Result<Mesh> {
    let mut mesh = Mesh::default();
    let has = |names: &[&str]| {
        vertices
            .first()
            .is_some_and(|v| names.iter().all(|n| v.contains_key(*n)))
    };
    let uv_names = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"]]
        .into_iter()
        .find(|names| has(names));
    let has_normals = has(&["nx", "ny", "nz"]);
    let has_colors = has(&["red", "green", "blue"]);
    for (k, vertex) in vertices.iter().enumerate() {
        let get = |name: &str| {
            vertex
                .get(name)
                .and_then(scalar)
                .ok_or_else(|| Error::new(format!("vertex {k} has no numeric \"{name}\"")))
        };
        let vec3 = |[a, b, c]: [&str; 3]| Ok::<_, Error>(Vec3::new(get(a)?, get(b)?, get(c)?));
        mesh.positions.push(vec3(["x", "y", "z"])?);
        if has_normals {
            mesh.normals
                .push(vec3(["nx", "ny", "nz"])?.normalize_or_zero());
        }
        if let Some([u, v]) = uv_names {
            mesh.uvs.push(Vec2::new(get(u)?, get(v)?));
        }
        if has_colors {
            let channel = |name: &str| {
                vertex
                    .get(name)
                    .and_then(color_channel)
                    .ok_or_else(|| Error::new(format!("vertex {k} has no colour \"{name}\"")))
            };
            mesh.colors.push(Vec3::new(
                channel("red")?,
                channel("green")?,
                channel("blue")?,
            ));
        }
    }
    let vertex_count = mesh.positions.len();
    for (k, face) in faces.iter().enumerate() {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(index_list)
            .ok_or_else(|| Error::new(format!("face {k} has no integer vertex_indices list")))?;
        if list.len() < 3 {
            return Err(Error::new(format!(
                "face {k} has only {} vertices",
                list.len()
            )));
        }
        let index = |i: i64| {
            u32::try_from(i)
                .ok()
                .filter(|&i| (i as usize) < vertex_count)
                .ok_or_else(|| {
                    Error::new(format!(
                        "face {k} refers to vertex {i}, but the file has {vertex_count} vertices"
                    ))
                })
        };
        let first = index(list[0])?;
        for pair in list[1..].windows(2) {
            mesh.triangles
                .push([first, index(pair[0])?, index(pair[1])?]);
        }
    }
    mesh.validate()?;
    Ok(mesh)
}

/// A scalar property as f32.
fn scalar(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Char(x) => f32::from(x),
        Property::UChar(x) => f32::from(x),
        Property::Short(x) => f32::from(x),
        Property::UShort(x) => f32::from(x),
        Property::Int(x) => x as f32,
        Property::UInt(x) => x as f32,
        Property::Float(x) => x,
        Property::Double(x) => x as f32,
        _ => return None,
    })
}

/// A colour channel as linear [0,1]: unsigned integers are sRGB-encoded over their range,
/// floats are linear.
fn color_channel(p: &Property) -> Option<f32> {
    match *p {
        Property::UChar(x) => Some(srgb_to_linear(f32::from(x) / 255.0)),
        Property::UShort(x) => Some(srgb_to_linear(f32::from(x) / 65535.0)),
        Property::Float(x) => Some(x),
        Property::Double(x) => Some(x as f32),
        _ => None,
    }
}

/// An integer list property.
fn index_list(p: &Property) -> Option<Vec<i64>> {
    fn widen<T: Copy + Into<i64>>(v: &[T]) -> Vec<i64> {
        v.iter().map(|&x| x.into()).collect()
    }
    match p {
        Property::ListChar(v) => Some(widen(v)),
        Property::ListUChar(v) => Some(widen(v)),
        Property::ListShort(v) => Some(widen(v)),
        Property::ListUShort(v) => Some(widen(v)),
        Property::ListInt(v) => Some(widen(v)),
        Property::ListUInt(v) => Some(widen(v)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_files::{example, write};
    use super::*;

    const HEADER: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
                          property float y\nproperty float z\nelement face 1\n\
                          property list uchar int vertex_indices\nend_header\n";

    #[test]
    fn loads_the_coloured_pyramid() {
        let parts = load_ply(&example("pyramid.ply")).unwrap().parts;
        assert_eq!(parts.len(), 1);
        let mesh = &parts[0].mesh;
        assert_eq!(mesh.positions.len(), 5);
        assert_eq!(mesh.triangle_count(), 6, "four sides and a fan-split quad");
        assert!(mesh.normals.is_empty() && mesh.uvs.is_empty());
        assert_eq!(mesh.colors[0], Vec3::X);
        assert_eq!(mesh.colors[3], Vec3::new(1.0, 1.0, 0.0));
        assert!(parts[0].material.is_none());
        // Counter-clockwise from outside: every face normal points away from the centre.
        let centre = Vec3::new(0.0, 0.5, 0.0);
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
            assert!((b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) > 0.0);
        }
    }

    #[test]
    fn binary_with_float_colours_normals_and_uvs() {
        let header = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n\
                      property float x\nproperty float y\nproperty float z\n\
                      property float nx\nproperty float ny\nproperty float nz\n\
                      property float s\nproperty float t\n\
                      property float red\nproperty float green\nproperty float blue\n\
                      element face 1\nproperty list uchar uint vertex_index\nend_header\n";
        let mut bytes = header.as_bytes().to_vec();
        for (p, uv) in [
            ([0.0f32, 0.0, 0.0], [0.0f32, 0.0]),
            ([1.0, 0.0, 0.0], [1.0, 0.0]),
            ([0.0, 1.0, 0.0], [0.0, 1.0]),
        ] {
            let values = [
                p[0], p[1], p[2], 0.0, 0.0, 2.0, uv[0], uv[1], 0.5, 0.25, 1.0,
            ];
            bytes.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        }
        bytes.push(3);
        bytes.extend([0u32, 1, 2].iter().flat_map(|v| v.to_le_bytes()));
        let dir = tempfile::tempdir().unwrap();
        let parts = load_ply(&write(&dir, "bin.ply", bytes)).unwrap().parts;
        let mesh = &parts[0].mesh;
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(mesh.normals[0], Vec3::Z, "normalised");
        assert_eq!(mesh.uvs[2], Vec2::new(0.0, 1.0));
        assert_eq!(
            mesh.colors[1],
            Vec3::new(0.5, 0.25, 1.0),
            "float colours are linear"
        );
    }

    #[test]
    fn bad_header_is_an_error_with_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(
            &dir,
            "bad.ply",
            HEADER.replace("property float y", "property flaot y"),
        );
        let e = load_ply(&path).unwrap_err();
        assert_eq!(
            e.location.as_ref().unwrap().line_column,
            Some((5, 1)),
            "{e}"
        );
        assert!(!e.to_string().contains('\n'));
        let path = write(
            &dir,
            "payload.ply",
            format!("{HEADER}0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"),
        );
        let e = load_ply(&path).unwrap_err();
        assert_eq!(e.location.unwrap().line_column, Some((11, 1)));
        let path = write(&dir, "notply.ply", "solid stl\nfacet normal 0 0 1\n");
        assert!(load_ply(&path)
            .unwrap_err()
            .to_string()
            .contains("notply.ply"));
    }

    #[test]
    fn impossible_counts_are_errors_not_panics() {
        let dir = tempfile::tempdir().unwrap();
        for count in ["99999999999999999999999", "1000000", "-3", "x"] {
            let text = HEADER.replace("element vertex 3", &format!("element vertex {count}"));
            let path = write(&dir, "count.ply", text);
            let e = load_ply(&path).unwrap_err();
            assert_eq!(e.location.unwrap().line_column, Some((3, 16)), "{count}");
        }
    }

    #[test]
    fn versions_other_than_1_0_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let text = HEADER.replace("format ascii 1.0", "format ascii 2.0");
        assert_ne!(text, HEADER);
        let path = write(&dir, "v2.ply", text);
        let e = load_ply(&path).unwrap_err().to_string();
        assert!(
            e.ends_with("v2.ply:2:14: PLY version \"2.0\" is not supported (only 1.0)"),
            "{e}"
        );
    }

    #[test]
    fn bad_faces_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let body = "0 0 0\n1 0 0\n0 1 0\n";
        for (face, expected) in [
            ("3 0 1 7", "refers to vertex 7"),
            ("3 0 1 -1", "refers to vertex -1"),
            ("2 0 1", "only 2 vertices"),
        ] {
            let path = write(&dir, "face.ply", format!("{HEADER}{body}{face}\n"));
            let e = load_ply(&path).unwrap_err().to_string();
            assert!(e.contains("face.ply") && e.contains(expected), "{e}");
        }
        // Truncated payload.
        let path = write(&dir, "cut.ply", format!("{HEADER}0 0 0\n1 0"));
        assert!(load_ply(&path).is_err());
        // No face element.
        let header = HEADER.replace(
            "element face 1\nproperty list uchar int vertex_indices\n",
            "",
        );
        let path = write(&dir, "noface.ply", format!("{header}{body}"));
        assert!(load_ply(&path)
            .unwrap_err()
            .to_string()
            .contains("\"face\""));
    }
}
