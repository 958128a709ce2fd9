//! The `shape` key: the shape names, what their `size` and `tessellation` mean, and building
//! the object-space mesh of an analytic shape.

use glam::{Affine3A, Mat3, Vec3};

use crate::scene::{shapes, Mesh};

/// A shape a scene object can have.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Shape {
    Plane,
    Box,
    Sphere,
    Cylinder,
    Torus,
    Teapot,
    /// A walking figure ([`shapes::walker`]).
    Walker,
    /// Loaded from a model file.
    Mesh,
}

/// Shape names as written in scene files.
const SHAPES: [(&str, Shape); 8] = [
    ("plane", Shape::Plane),
    ("box", Shape::Box),
    ("sphere", Shape::Sphere),
    ("cylinder", Shape::Cylinder),
    ("torus", Shape::Torus),
    ("teapot", Shape::Teapot),
    ("walker", Shape::Walker),
    ("mesh", Shape::Mesh),
];

/// The largest accepted `tessellation`: beyond it meshes run to millions of triangles.
pub(super) const MAX_TESSELLATION: u32 = 1024;

/// What `size` holds for an analytic shape.
pub(super) struct SizeForm {
    /// How the value is written, for error messages (`[width, depth]`).
    pub written: &'static str,
    /// The value when `size` is absent; its length is the number of values `size` needs.
    pub default: &'static [f32],
}

impl Shape {
    pub fn parse(name: &str) -> Option<Shape> {
        SHAPES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, shape)| shape)
    }

    pub fn name(self) -> &'static str {
        SHAPES
            .iter()
            .find(|(_, s)| *s == self)
            .map_or("", |(n, _)| n)
    }

    /// Every shape name, for error messages.
    pub fn all_names() -> [&'static str; SHAPES.len()] {
        SHAPES.map(|(name, _)| name)
    }

    /// The form of `size`; `None` for model files, which take no size.
    pub fn size_form(self) -> Option<SizeForm> {
        let (written, default): (&str, &[f32]) = match self {
            Shape::Plane => ("[width, depth]", &[10.0, 10.0]),
            Shape::Box => ("[x, y, z]", &[1.0, 1.0, 1.0]),
            Shape::Sphere => ("a radius", &[1.0]),
            Shape::Cylinder => ("[radius, height]", &[0.5, 1.0]),
            Shape::Torus => ("[major radius, minor radius]", &[1.0, 0.25]),
            Shape::Teapot => ("a scale factor", &[1.0]),
            Shape::Walker => ("a height", &[1.8]),
            Shape::Mesh => return None,
        };
        Some(SizeForm { written, default })
    }

    /// The default `tessellation` and the smallest accepted one; `None` for model files.
    /// Flat shapes need no subdivision (1 quad per face); curved ones need enough segments
    /// around a circle to look round.
    pub fn tessellation_default_and_min(self) -> Option<(u32, u32)> {
        match self {
            Shape::Plane | Shape::Box => Some((1, 1)),
            Shape::Sphere | Shape::Cylinder | Shape::Torus => Some((48, 3)),
            Shape::Teapot => Some((32, 4)),
            Shape::Walker => Some((24, 3)),
            Shape::Mesh => None,
        }
    }
}

impl Shape {
    /// An upper bound of the triangles [`analytic_mesh`] builds at `tessellation`, known
    /// before building it (for the memory budget); 0 for model files.
    pub fn triangle_bound(self, tessellation: u32) -> u64 {
        let t = u64::from(tessellation.max(1));
        match self {
            Shape::Plane => 2 * t * t,
            Shape::Box => 12 * t * t,
            // Rows of quads from pole to pole, two triangles each.
            Shape::Sphere | Shape::Torus => 2 * t * t,
            Shape::Cylinder => 4 * t.max(3),
            // 32 patches of n x n quads, n = max(t / 4, 1).
            Shape::Teapot => 64 * (t / 4).max(1).pow(2),
            // One sphere's rows per part.
            Shape::Walker => u64::from(shapes::WALKER_PARTS) * 2 * t * t,
            Shape::Mesh => 0,
        }
    }
}

/// The object-space mesh of an analytic shape, `None` for [`Shape::Mesh`]. `size` holds the
/// shape's [`SizeForm`] values in order (unused entries are ignored); `face_colors` (boxes
/// only) colours the faces +x, -x, +y, -y, +z, -z.
pub(super) fn analytic_mesh(
    shape: Shape,
    size: [f32; 3],
    tessellation: u32,
    face_colors: Option<[Vec3; 6]>,
) -> Option<Mesh> {
    let [a, b, c] = size;
    Some(match shape {
        Shape::Plane => shapes::plane(a, b, tessellation),
        Shape::Box => tessellated_box(Vec3::new(a, b, c), tessellation, face_colors),
        Shape::Sphere => shapes::sphere(a, tessellation),
        Shape::Cylinder => shapes::cylinder(a, b, tessellation),
        Shape::Torus => shapes::torus(a, b, tessellation),
        Shape::Teapot => shapes::teapot(a, tessellation),
        Shape::Walker => shapes::walker(a, tessellation),
        Shape::Mesh => return None,
    })
}

/// A box centred on the origin whose faces are `tessellation` x `tessellation` grids, built
/// from six planes so that faces can be subdivided (as the 686-triangle cube scene of Vallance 2005
/// needs) and coloured one by one.
fn tessellated_box(size: Vec3, tessellation: u32, face_colors: Option<[Vec3; 6]>) -> Mesh {
    let mut mesh = Mesh::default();
    for face in 0..6 {
        let axis = face / 2;
        let sign = if face % 2 == 0 { 1.0 } else { -1.0 };
        // Map the plane's (x, y, z) to (u, n, v) with u = n x v, so the map is a rotation
        // (winding and normals stay consistent): n the face normal, v and u the next axes.
        let n = Vec3::AXES[axis] * sign;
        let v = Vec3::AXES[(axis + 1) % 3];
        let u = n.cross(v);
        let (width, depth) = (size[(axis + 2) % 3], size[(axis + 1) % 3]);
        let mut plane = shapes::plane(width, depth, tessellation);
        plane.transform(&Affine3A::from_mat3_translation(
            Mat3::from_cols(u, n, v),
            n * (size[axis] / 2.0),
        ));
        if let Some(colors) = face_colors {
            plane.colors = vec![colors[face]; plane.positions.len()];
        }
        mesh.append(&plane);
    }
    mesh
}
