//! glTF 2.0 (`.gltf` with embedded or external buffers, and binary `.glb`), through gltf.
//!
//! The gltf crate validates the document's indices, but not what it reads: every accessor,
//! image view, node transform and named file is checked first (module `gltf_checks` and
//! here), so that a malformed file is an error naming what is wrong, never a panic.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use ::gltf::buffer::Data as BufferData;
use ::gltf::image::Format;
use ::gltf::mesh::Mode;
use ::gltf::{Document, Node, Primitive};
use glam::{Affine3A, Mat4, Vec2, Vec3};

use super::gltf_cameras::ModelCamera;
use super::gltf_checks::{check_images, check_nodes, check_primitive, check_version, check_view};
use super::texture::{srgb_to_linear, texture_from_texels};
use super::{read_file, Model, ModelPart};
use crate::error::{Error, Result};
use crate::scene::{InputFile, Material, Mesh, Pattern, Texture};

/// Loads the triangle primitives of the default scene (the first scene if none is marked
/// default; every mesh untransformed if the file has no scene), with node transforms
/// applied. Each primitive becomes one part; a primitive with a material gets
/// `baseColorFactor` as its colour and `baseColorTexture` (sRGB decoded) as its pattern.
/// Point and line primitives are skipped; a file without triangles is an error. The cameras
/// the scene's nodes place come with the model (module `gltf_cameras`).
pub(super) fn load_gltf(path: &Path) -> Result<Model> {
    let fail = |e: ::gltf::Error| Error::in_file(path, format!("malformed glTF: {e}"));
    let bytes = read_file(path)?;
    check_glb_length(&bytes).map_err(|e| e.or_in_file(path))?;
    let ::gltf::Gltf { document, blob } = open_validated(&bytes).map_err(fail)?;
    let in_file = |e: Error| Error::in_file(path, e.message);
    check_version(&document).map_err(in_file)?;
    check_nodes(&document).map_err(in_file)?;
    check_images(&document).map_err(in_file)?;
    let base = path.parent().unwrap_or(Path::new(""));
    for buffer in document.buffers() {
        if let ::gltf::buffer::Source::Uri(uri) = buffer.source() {
            check_named_file(base, uri, &format!("buffer {}", buffer.index())).map_err(in_file)?;
        }
    }
    let buffers = ::gltf::import_buffers(&document, Some(base), blob).map_err(fail)?;
    let buffer_files = document
        .buffers()
        .filter_map(|buffer| match buffer.source() {
            ::gltf::buffer::Source::Uri(uri) => uri_file(base, uri),
            ::gltf::buffer::Source::Bin => None,
        });
    let mut loader = Loader {
        path,
        base,
        buffers: &buffers,
        textures: HashMap::new(),
        parts: Vec::new(),
        cameras: Vec::new(),
        files: buffer_files
            .map(|path| InputFile {
                what: "model buffer",
                path,
            })
            .collect(),
    };
    match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => loader.add_nodes(&document, scene.nodes())?,
        None => {
            for mesh in document.meshes() {
                loader.add_mesh(&mesh, &Affine3A::IDENTITY)?;
            }
        }
    }
    if loader.parts.is_empty() {
        return Err(Error::in_file(path, "contains no triangle meshes"));
    }
    let mut model = Model::read_from(path, loader.parts, loader.files);
    model.cameras = loader.cameras;
    Ok(model)
}

/// The file a glTF URI names, resolved as the gltf crate resolves it when it reads the
/// file: a `data:` or other non-file scheme names none, `file:` and `file://` URIs are
/// paths, anything else is a percent-encoded path relative to the glTF file's folder.
fn uri_file(base: &Path, uri: &str) -> Option<PathBuf> {
    if uri.contains(':') {
        let path = uri
            .strip_prefix("file://")
            .or_else(|| uri.strip_prefix("file:"))?;
        return Some(PathBuf::from(path));
    }
    Some(base.join(percent_decode(uri)?))
}

/// `text` with each `%XX` replaced by the byte it encodes; `None` when the result is not
/// UTF-8 (the gltf crate cannot read such a file either).
fn percent_decode(text: &str) -> Option<String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(byte)) => {
                out.push(byte);
                i += 3;
            }
            (byte, _) => {
                out.push(byte);
                i += 1;
            }
        }
    }
    String::from_utf8(out).ok()
}

/// Fails when a file named by a glTF URI (a buffer or image, `what`) is not a regular file,
/// naming the URI and where it was looked for (the gltf crate's own error names neither).
fn check_named_file(base: &Path, uri: &str, what: &str) -> Result<()> {
    match uri_file(base, uri) {
        Some(file) if !file.is_file() => Err(Error::new(format!(
            "{what}: \"{uri}\" is not a file (looked for {})",
            file.display()
        ))),
        _ => Ok(()),
    }
}

/// A GLB header's size: magic, version and total length, 4 bytes each.
const GLB_HEADER_BYTES: u32 = 12;

/// Fails when a GLB header claims more bytes than the file holds (the gltf crate's reader
/// would allocate the claimed length first) or fewer than the 12-byte header itself (the
/// crate subtracts the header's size from the claim, which underflows).
fn check_glb_length(bytes: &[u8]) -> Result<()> {
    let Some(claimed) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    else {
        return Ok(());
    };
    if claimed < GLB_HEADER_BYTES {
        return Err(Error::new(format!(
            "malformed GLB: its header claims {claimed} bytes, less than the header's own \
             {GLB_HEADER_BYTES}"
        )));
    }
    if claimed as usize > bytes.len() {
        return Err(Error::new(format!(
            "malformed GLB: its header claims {claimed} bytes, the file holds {}",
            bytes.len()
        )));
    }
    Ok(())
}

/// Parses and validates glTF or GLB bytes as `gltf::Gltf::open` does, but checks first
/// that every primitive's `POSITION` accessor exists: gltf-json's validation indexes the
/// accessor list with it unchecked and panics on an index past its end.
fn open_validated(bytes: &[u8]) -> std::result::Result<::gltf::Gltf, ::gltf::Error> {
    use ::gltf::json::validation::{Checked, Error as Invalid};
    use ::gltf::json::Path as JsonPath;
    let ::gltf::Gltf { document, blob } = ::gltf::Gltf::from_slice_without_validation(bytes)?;
    let json = document.into_json();
    let positions = Checked::Valid(::gltf::json::mesh::Semantic::Positions);
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive.attributes.get(&positions) {
                if index.value() >= json.accessors.len() {
                    let at = JsonPath::new()
                        .field("meshes")
                        .index(m)
                        .field("primitives")
                        .index(p)
                        .field("attributes")
                        .key("POSITION");
                    return Err(::gltf::Error::Validation(vec![(
                        at,
                        Invalid::IndexOutOfBounds,
                    )]));
                }
            }
        }
    }
    let document = Document::from_json(json)?;
    Ok(::gltf::Gltf { document, blob })
}

/// State of one glTF load.
struct Loader<'a> {
    path: &'a Path,
    base: &'a Path,
    buffers: &'a [BufferData],
    /// Textures by glTF image index, so that primitives sharing an image share it.
    textures: HashMap<usize, Arc<Texture>>,
    parts: Vec<ModelPart>,
    /// The cameras placed by the nodes met so far.
    cameras: Vec<ModelCamera>,
    /// The files read besides the glTF itself: buffers, then images as they are decoded.
    files: Vec<InputFile>,
}

impl Loader<'_> {
    /// Adds the meshes and cameras under `roots`, depth first in file order. A node hierarchy deeper
    /// than the number of nodes must contain a cycle (invalid glTF): an error.
    fn add_nodes<'d>(
        &mut self,
        document: &'d Document,
        roots: impl Iterator<Item = Node<'d>>,
    ) -> Result<()> {
        let max_depth = document.nodes().len();
        let mut stack: Vec<(Node, Affine3A, usize)> =
            roots.map(|n| (n, Affine3A::IDENTITY, 0)).collect();
        stack.reverse();
        while let Some((node, parent, depth)) = stack.pop() {
            if depth >= max_depth {
                return Err(Error::in_file(self.path, "node hierarchy contains a cycle"));
            }
            let local = Mat4::from_cols_array_2d(&node.transform().matrix());
            let world = parent * Affine3A::from_mat4(local);
            if !world.is_finite() {
                let message = format!(
                    "node {}: transform, composed with its parents', is not finite in single \
                     precision",
                    node.index()
                );
                return Err(Error::in_file(self.path, message));
            }
            if let Some(mesh) = node.mesh() {
                self.add_mesh(&mesh, &world)?;
            }
            self.cameras
                .extend(ModelCamera::of_node(document, &node, &world));
            let first_child = stack.len();
            stack.extend(node.children().map(|child| (child, world, depth + 1)));
            stack[first_child..].reverse();
        }
        Ok(())
    }

    fn add_mesh(&mut self, mesh: &::gltf::Mesh, world: &Affine3A) -> Result<()> {
        let path = self.path;
        for primitive in mesh.primitives() {
            let context = |e: Error| {
                let message = format!(
                    "mesh {} primitive {}: {}",
                    mesh.index(),
                    primitive.index(),
                    e.message
                );
                Error::in_file(path, message)
            };
            if let Some(part) = self.convert_primitive(&primitive, world).map_err(context)? {
                self.parts.push(part);
            }
        }
        Ok(())
    }

    /// One triangle primitive as a world-space part, or `None` for points and lines.
    fn convert_primitive(
        &mut self,
        primitive: &Primitive,
        world: &Affine3A,
    ) -> Result<Option<ModelPart>> {
        let Some(triangulate) = triangulation(primitive.mode()) else {
            return Ok(None);
        };
        check_primitive(primitive, self.buffers)?;
        let material = primitive.material();
        let texture = material.pbr_metallic_roughness().base_color_texture();
        let uv_set = texture.as_ref().map_or(0, |t| t.tex_coord());

        let buffers = self.buffers;
        let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| Error::new("has no POSITION attribute"))?
            .map(Vec3::from)
            .collect();
        let vertex_count = positions.len();
        let order: Vec<u32> = match reader.read_indices() {
            Some(indices) => indices.into_u32().collect(),
            None => (0..vertex_count as u32).collect(),
        };
        let mut mesh = Mesh {
            normals: reader.read_normals().map_or_else(Vec::new, |n| {
                n.map(|n| Vec3::from(n).normalize_or_zero()).collect()
            }),
            uvs: reader.read_tex_coords(uv_set).map_or_else(Vec::new, |uv| {
                // glTF's (0,0) is the image's top-left; flexcam's (OBJ's) is its bottom-left.
                uv.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect()
            }),
            colors: reader
                .read_colors(0)
                .map_or_else(Vec::new, |c| c.into_rgb_f32().map(Vec3::from).collect()),
            triangles: triangulate(&order),
            positions,
        };
        mesh.validate()?;
        mesh.transform(world);
        if world.matrix3.determinant() < 0.0 {
            // A mirroring transform turns counter-clockwise triangles clockwise (glTF 3.7.2.1).
            for t in &mut mesh.triangles {
                t.swap(1, 2);
            }
        }
        let material = match material.index() {
            // The glTF default material: leave the colour to the scene.
            None => None,
            Some(_) => {
                let pbr = material.pbr_metallic_roughness();
                let [r, g, b, _] = pbr.base_color_factor();
                let pattern = match texture {
                    Some(info) => {
                        if mesh.uvs.is_empty() {
                            return Err(Error::new(format!(
                                "has a base colour texture but no TEXCOORD_{uv_set}"
                            )));
                        }
                        Pattern::Texture(self.texture(info.texture().source())?)
                    }
                    None => Pattern::Solid,
                };
                Some(Material {
                    color: Vec3::new(r, g, b),
                    pattern,
                    ..Material::default()
                })
            }
        };
        Ok(Some(ModelPart { mesh, material }))
    }

    /// The texture of a glTF image, decoded once per image.
    fn texture(&mut self, image: ::gltf::Image) -> Result<Arc<Texture>> {
        if let Some(texture) = self.textures.get(&image.index()) {
            return Ok(texture.clone());
        }
        if let ::gltf::image::Source::View { view, .. } = image.source() {
            check_view(&view, self.buffers)?;
        }
        if let ::gltf::image::Source::Uri { uri, .. } = image.source() {
            check_named_file(self.base, uri, &format!("image {}", image.index()))?;
        }
        let data = ::gltf::image::Data::from_source(image.source(), Some(self.base), self.buffers)
            .map_err(|e| Error::new(format!("image {}: {e}", image.index())))?;
        if let ::gltf::image::Source::Uri { uri, .. } = image.source() {
            self.files
                .extend(uri_file(self.base, uri).map(|path| InputFile {
                    what: "texture",
                    path,
                }));
        }
        let texture = Arc::new(texture_from_gltf_image(&data)?);
        self.textures.insert(image.index(), texture.clone());
        Ok(texture)
    }
}

/// Turns a primitive's vertex order into counter-clockwise triangles.
type Triangulate = fn(&[u32]) -> Vec<[u32; 3]>;

/// How a primitive's vertex order becomes counter-clockwise triangles, or `None` for
/// primitives without area (points, lines).
fn triangulation(mode: Mode) -> Option<Triangulate> {
    match mode {
        Mode::Triangles => Some(|v| v.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()),
        // glTF 3.7.2.1: triangle i of a strip is (v_i, v_{i+1+i%2}, v_{i+2-i%2}).
        Mode::TriangleStrip => Some(|v| {
            (0..v.len().saturating_sub(2))
                .map(|i| [v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]])
                .collect()
        }),
        // Triangle i of a fan is (v_{i+1}, v_{i+2}, v_0).
        Mode::TriangleFan => Some(|v| {
            (0..v.len().saturating_sub(2))
                .map(|i| [v[i + 1], v[i + 2], v[0]])
                .collect()
        }),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => None,
    }
}

/// A linear texture from a decoded glTF image (PNG or JPEG, so sRGB-encoded integers);
/// grey images are spread to RGB, alpha is dropped.
fn texture_from_gltf_image(data: &::gltf::image::Data) -> Result<Texture> {
    crate::scene::budget::check_image(data.width, data.height)?;
    let (channels, bytes) = match data.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        Format::R32G32B32FLOAT => (3, 4),
        Format::R32G32B32A32FLOAT => (4, 4),
    };
    let value = |b: &[u8]| match *b {
        [x] => f32::from(x) / 255.0,
        [x, y] => f32::from(u16::from_ne_bytes([x, y])) / 65535.0,
        [x, y, z, w] => f32::from_ne_bytes([x, y, z, w]),
        _ => 0.0,
    };
    let texels = data
        .pixels
        .chunks_exact(channels * bytes)
        .map(|pixel| {
            let channel = |k: usize| value(&pixel[k * bytes..(k + 1) * bytes]);
            let rgb = if channels < 3 {
                Vec3::splat(channel(0))
            } else {
                Vec3::new(channel(0), channel(1), channel(2))
            };
            rgb.map(srgb_to_linear)
        })
        .collect();
    texture_from_texels(data.width, data.height, texels)
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::super::test_files::{example, listed, write};
    use super::*;

    fn bounds(part: &ModelPart) -> (Vec3, Vec3) {
        part.mesh.bounds().unwrap()
    }

    #[test]
    fn uris_name_files_as_the_gltf_crate_reads_them() {
        let base = Path::new("m");
        assert_eq!(uri_file(base, "a%20b.bin"), Some(base.join("a b.bin")));
        assert_eq!(uri_file(base, "t/x%2.png"), Some(base.join("t/x%2.png")));
        assert_eq!(
            uri_file(base, "file:///abs/t.png"),
            Some(PathBuf::from("/abs/t.png"))
        );
        assert_eq!(
            uri_file(base, "data:application/octet-stream;base64,AA"),
            None
        );
        assert_eq!(uri_file(base, "https://example.org/t.png"), None);
        assert_eq!(uri_file(base, "%ff.bin"), None);
    }

    /// A glTF with its buffer and image in files of their own names both as inputs.
    #[test]
    fn external_buffers_and_images_are_listed() {
        let dir = tempfile::tempdir().unwrap();
        let triangle: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .chain(
                [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0]
                    .iter()
                    .flat_map(|v| v.to_le_bytes()),
            )
            .collect();
        write(&dir, "tri angle.bin", &triangle);
        std::fs::copy(example("checker.png"), dir.path().join("tex.png")).unwrap();
        let gltf = r#"{
            "asset": {"version": "2.0"},
            "buffers": [{"byteLength": 60, "uri": "tri%20angle.bin"}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
            "images": [{"uri": "tex.png"}],
            "textures": [{"source": 0}],
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}]
        }"#;
        let path = write(&dir, "m.gltf", gltf);
        let model = load_gltf(&path).unwrap();
        assert_eq!(
            listed(&model),
            [
                ("model file", path.clone()),
                ("model buffer", dir.path().join("tri angle.bin")),
                ("texture", dir.path().join("tex.png")),
            ]
        );
    }

    #[test]
    fn loads_gltf_and_glb_alike() {
        for name in ["tetra-quad.gltf", "tetra-quad.glb"] {
            let parts = load_gltf(&example(name)).unwrap().parts;
            assert_eq!(parts.len(), 2, "{name}");
            let (tetra, quad) = (&parts[0], &parts[1]);
            tetra.mesh.validate().unwrap();
            quad.mesh.validate().unwrap();

            // Node transforms: root moves up by 1, the tetrahedron is halved, the quad is
            // moved back down and doubled in x and z.
            let (lo, hi) = bounds(tetra);
            assert!(
                (lo - Vec3::new(-0.5, 0.5, -0.5)).length() < 1e-6,
                "{name} {lo}"
            );
            assert!(
                (hi - Vec3::new(0.5, 1.5, 0.5)).length() < 1e-6,
                "{name} {hi}"
            );
            let (lo, hi) = bounds(quad);
            assert!(
                (lo - Vec3::new(-2.0, 0.0, -2.0)).length() < 1e-6,
                "{name} {lo}"
            );
            assert!(
                (hi - Vec3::new(2.0, 0.0, 2.0)).length() < 1e-6,
                "{name} {hi}"
            );

            // COLOR_0 is linear and kept as is.
            assert_eq!(tetra.mesh.colors[0], Vec3::X);
            assert_eq!(tetra.mesh.colors[3], Vec3::ONE);
            assert_eq!(tetra.material.as_ref().unwrap().color, Vec3::ONE);

            // The quad's normal is +y and its triangles wind counter-clockwise about it.
            assert!(quad.mesh.normals.iter().all(|n| *n == Vec3::Y));
            for t in &quad.mesh.triangles {
                let [a, b, c] = t.map(|k| quad.mesh.positions[k as usize]);
                assert!((b - a).cross(c - a).y > 0.0);
            }

            // The texture's top-left texel (red) sits at glTF uv (0,0), vertex 0.
            let material = quad.material.as_ref().unwrap();
            assert_eq!(material.color, Vec3::splat(0.5));
            let Pattern::Texture(texture) = &material.pattern else {
                panic!("{name}: quad has no texture");
            };
            let inward = (Vec2::splat(0.5) - quad.mesh.uvs[0]) * 0.1;
            assert_eq!(texture.nearest(quad.mesh.uvs[0] + inward), Vec3::X);
            assert_eq!(quad.mesh.uvs[0], Vec2::new(0.0, 1.0));
        }
    }

    /// The example glTF document, edited by `edit`, written to a temporary file.
    fn edited(dir: &tempfile::TempDir, edit: impl Fn(&str) -> String) -> std::path::PathBuf {
        let text = std::fs::read_to_string(example("tetra-quad.gltf")).unwrap();
        let changed = edit(&text);
        assert_ne!(changed, text, "edit did not apply");
        write(dir, "edited.gltf", changed)
    }

    #[test]
    fn accessor_past_its_buffer_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = edited(&dir, |t| t.replacen("\"count\": 4", "\"count\": 4000", 1));
        let e = load_gltf(&path).unwrap_err().to_string();
        assert!(e.contains("edited.gltf") && !e.contains('\n'), "{e}");
    }

    #[test]
    fn node_cycle_is_an_error_not_a_hang() {
        let dir = tempfile::tempdir().unwrap();
        let path = edited(&dir, |t| {
            t.replacen("\"mesh\": 0,", "\"mesh\": 0, \"children\": [0],", 1)
        });
        let e = load_gltf(&path).unwrap_err().to_string();
        assert!(e.contains("edited.gltf"), "{e}");
    }

    #[test]
    fn garbage_and_truncated_glb_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let garbage = write(
            &dir,
            "garbage.glb",
            b"glTF\x02\x00\x00\x00 this is not a glb",
        );
        let e = load_gltf(&garbage).unwrap_err().to_string();
        assert!(e.starts_with(&garbage.display().to_string()), "{e}");
        let glb = std::fs::read(example("tetra-quad.glb")).unwrap();
        for cut in [0, 11, 20, glb.len() / 2, glb.len() - 4] {
            let path = write(&dir, "cut.glb", &glb[..cut]);
            assert!(load_gltf(&path).is_err(), "cut at {cut}");
        }
        let json = write(&dir, "bad.gltf", "{ \"asset\": { \"version\": \"2.0\" }, ");
        let e = load_gltf(&json).unwrap_err().to_string();
        assert!(e.contains("bad.gltf") && e.contains("malformed"), "{e}");
    }

    /// gltf-json's own validation panics on this (an index into the accessor list it does
    /// not check); the loader reports it.
    #[test]
    fn position_accessor_past_the_accessor_list_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(
            &dir,
            "bad-position.gltf",
            r#"{"asset": {"version": "2.0"},
                "meshes": [{"primitives": [{"attributes": {"POSITION": 5}}]}]}"#,
        );
        let e = load_gltf(&path).unwrap_err().to_string();
        assert!(
            e.contains("bad-position.gltf") && e.contains("POSITION") && !e.contains('\n'),
            "{e}"
        );
    }

    #[test]
    fn file_without_triangles_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(&dir, "empty.gltf", r#"{"asset": {"version": "2.0"}}"#);
        let e = load_gltf(&path).unwrap_err().to_string();
        assert!(e.contains("no triangle meshes"), "{e}");
    }

    #[test]
    fn strips_and_fans_triangulate_counter_clockwise() {
        let strip = triangulation(Mode::TriangleStrip).unwrap();
        assert_eq!(strip(&[0, 1, 2, 3]), vec![[0, 1, 2], [1, 3, 2]]);
        let fan = triangulation(Mode::TriangleFan).unwrap();
        assert_eq!(fan(&[0, 1, 2, 3]), vec![[1, 2, 0], [2, 3, 0]]);
        assert!(strip(&[0, 1]).is_empty());
        assert!(triangulation(Mode::Lines).is_none());
    }
}
