//! Built-in analytic shapes, tessellated into meshes in object space (y up, centred on the
//! origin unless stated). `tessellation` is the number of segments around a full circle.

use glam::Vec3;

use super::Mesh;

/// A `width` x `depth` rectangle in the xz plane at y = 0, normal +y, split into
/// `tessellation` x `tessellation` quads.
pub fn plane(width: f32, depth: f32, tessellation: u32) -> Mesh {
    let _ = (width, depth, tessellation);
    todo!("shapes::plane")
}

/// An axis-aligned box with edge lengths `size`, centred on the origin, flat-shaded faces.
pub fn cuboid(size: Vec3) -> Mesh {
    let _ = size;
    todo!("shapes::cuboid")
}

/// A UV sphere of `radius` centred on the origin.
pub fn sphere(radius: f32, tessellation: u32) -> Mesh {
    let _ = (radius, tessellation);
    todo!("shapes::sphere")
}

/// A capped cylinder about the y axis, from y = -height/2 to y = height/2.
pub fn cylinder(radius: f32, height: f32, tessellation: u32) -> Mesh {
    let _ = (radius, height, tessellation);
    todo!("shapes::cylinder")
}

/// A torus about the y axis with the given major (ring) and minor (tube) radii.
pub fn torus(major: f32, minor: f32, tessellation: u32) -> Mesh {
    let _ = (major, minor, tessellation);
    todo!("shapes::torus")
}

/// The Utah teapot from Newell's Bezier patches, y up, resting on y = 0, uniformly scaled by
/// `scale`; each patch is tessellated into `tessellation/4` x `tessellation/4` quads (at least 1).
pub fn teapot(scale: f32, tessellation: u32) -> Mesh {
    let _ = (scale, tessellation);
    todo!("shapes::teapot")
}
