//! Checks of a glTF document made before anything is read from its buffers.
//!
//! The gltf crate reads accessors by slicing buffers with unchecked arithmetic and matches
//! their component types with `unreachable!()` for the combinations glTF 2.0 (section
//! 3.7.2.1, "Meshes") does not allow, and it reads `POSITION` as f32 triplets whatever the
//! accessor says. So every accessor a primitive uses is checked here against its buffer and
//! against the types and shapes the specification allows for its role, every node
//! transform for finite, invertible values, and the asset version: a malformed file is an
//! error naming the accessor or node, never a panic and never silently misread.

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::buffer::Data as BufferData;
use ::gltf::mesh::Semantic;
use ::gltf::{Accessor, Document, Primitive};
use glam::Mat4;

use crate::error::{Error, Result};

/// Fails unless the document is glTF 2.x (`asset.version` "2.0", or a later minor).
pub(super) fn check_version(document: &Document) -> Result<()> {
    let version = &document.as_json().asset.version;
    let major = version.split('.').next();
    if major != Some("2") {
        return Err(Error::new(format!(
            "asset.version \"{version}\" is not supported (glTF 2.x only)"
        )));
    }
    Ok(())
}

/// Fails on an image with neither a URI nor a buffer view, or a buffer view without a MIME
/// type (required there by glTF 2.0; the gltf crate unwraps it).
pub(super) fn check_images(document: &Document) -> Result<()> {
    for (index, image) in document.as_json().images.iter().enumerate() {
        let problem = match (&image.uri, &image.buffer_view, &image.mime_type) {
            (None, None, _) => "has neither a uri nor a bufferView",
            (_, Some(_), None) => "has a bufferView but no mimeType",
            _ => continue,
        };
        return Err(Error::new(format!("image {index} {problem}")));
    }
    Ok(())
}

/// Fails unless the transform of every node is finite in f32 and invertible (a singular
/// matrix flattens its meshes and has no normal transform).
pub(super) fn check_nodes(document: &Document) -> Result<()> {
    for node in document.nodes() {
        let matrix = Mat4::from_cols_array_2d(&node.transform().matrix());
        let problem = if !matrix.is_finite() {
            "has a value that is not finite in single precision"
        } else if is_singular(&matrix) {
            "is singular (it flattens its meshes)"
        } else {
            continue;
        };
        return Err(Error::new(format!(
            "node {}: transform {problem}",
            node.index()
        )));
    }
    Ok(())
}

/// Whether the linear part of the finite `matrix` has no inverse, relative to its column
/// lengths.
fn is_singular(matrix: &Mat4) -> bool {
    let [x, y, z] = [matrix.x_axis, matrix.y_axis, matrix.z_axis].map(|c| c.truncate());
    let scale = f64::from(x.length()) * f64::from(y.length()) * f64::from(z.length());
    let determinant = f64::from(x.dot(y.cross(z)));
    determinant.abs() <= 1e-12 * scale
}

/// Checks every accessor `primitive` uses (attributes and indices): its type and shape for
/// its role, and every element inside its buffer view and the view inside its buffer.
pub(super) fn check_primitive(primitive: &Primitive, buffers: &[BufferData]) -> Result<()> {
    for (semantic, accessor) in primitive.attributes() {
        check_role(&accessor, &semantic)?;
        check_bounds(&accessor, buffers)?;
    }
    if let Some(indices) = primitive.indices() {
        let unsigned = matches!(
            indices.data_type(),
            DataType::U8 | DataType::U16 | DataType::U32
        );
        if !unsigned || indices.dimensions() != Dimensions::Scalar || indices.normalized() {
            return Err(wrong_type(&indices, "indices", "u8, u16 or u32 SCALAR"));
        }
        check_bounds(&indices, buffers)?;
    }
    Ok(())
}

/// The component types and shapes glTF 2.0 allows for each vertex attribute.
fn check_role(accessor: &Accessor, semantic: &Semantic) -> Result<()> {
    use DataType::{F32, U16, U8};
    let (kind, dimensions) = (accessor.data_type(), accessor.dimensions());
    let normalized = accessor.normalized();
    let float_or_normalized = kind == F32 || (matches!(kind, U8 | U16) && normalized);
    let (ok, allowed) = match semantic {
        Semantic::Positions | Semantic::Normals => {
            (kind == F32 && dimensions == Dimensions::Vec3, "f32 VEC3")
        }
        Semantic::Tangents => (kind == F32 && dimensions == Dimensions::Vec4, "f32 VEC4"),
        Semantic::TexCoords(_) => (
            float_or_normalized && dimensions == Dimensions::Vec2,
            "VEC2 of f32, or of normalized u8 or u16",
        ),
        Semantic::Colors(_) => (
            float_or_normalized && matches!(dimensions, Dimensions::Vec3 | Dimensions::Vec4),
            "VEC3 or VEC4 of f32, or of normalized u8 or u16",
        ),
        Semantic::Joints(_) => (
            matches!(kind, U8 | U16) && !normalized && dimensions == Dimensions::Vec4,
            "u8 or u16 VEC4",
        ),
        Semantic::Weights(_) => (
            float_or_normalized && dimensions == Dimensions::Vec4,
            "VEC4 of f32, or of normalized u8 or u16",
        ),
    };
    if ok {
        return Ok(());
    }
    Err(wrong_type(accessor, &semantic.to_string(), allowed))
}

fn wrong_type(accessor: &Accessor, role: &str, allowed: &str) -> Error {
    let normalized = if accessor.normalized() {
        "normalized "
    } else {
        ""
    };
    Error::new(format!(
        "accessor {} ({role}) is {normalized}{:?} {:?}; glTF 2.0 allows {allowed}",
        accessor.index(),
        accessor.data_type(),
        accessor.dimensions(),
    ))
}

/// Checks that every element of `accessor` lies inside its buffer view and the view
/// inside its buffer. Sparse accessors (used for morph targets) are not supported.
fn check_bounds(accessor: &Accessor, buffers: &[BufferData]) -> Result<()> {
    let index = accessor.index();
    if accessor.sparse().is_some() {
        return Err(Error::new(format!(
            "accessor {index} is sparse, which is not supported"
        )));
    }
    let Some(view) = accessor.view() else {
        return Err(Error::new(format!("accessor {index} has no buffer view")));
    };
    let element = accessor.size();
    let stride = view.stride().unwrap_or(element);
    let end = accessor.count().checked_sub(1).and_then(|last| {
        stride
            .checked_mul(last)?
            .checked_add(element)?
            .checked_add(accessor.offset())
    });
    match end {
        Some(end) if end <= view.length() => check_view(&view, buffers),
        _ => Err(Error::new(format!(
            "accessor {index} is empty or reaches past its buffer view"
        ))),
    }
}

/// Checks that `view` lies inside its buffer.
pub(super) fn check_view(view: &::gltf::buffer::View, buffers: &[BufferData]) -> Result<()> {
    let buffer_len = buffers.get(view.buffer().index()).map_or(0, |b| b.len());
    match view.offset().checked_add(view.length()) {
        Some(end) if end <= buffer_len => Ok(()),
        _ => Err(Error::new(format!(
            "buffer view {} reaches past its buffer",
            view.index()
        ))),
    }
}
