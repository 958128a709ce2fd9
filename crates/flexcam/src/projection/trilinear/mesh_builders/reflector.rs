//! Reflection and refraction surfaces (Vallance 2005, chapter 7): a trilinear projection whose
//! base triangles are a reflector's (or lens's) triangles and whose vertex rays are the
//! reflected (refracted) rays of the eye's rays at the vertices.
//!
//! Each vertex's screen position is where the main camera images it, so the image rendered
//! through the surface is already in the main image's coordinates: a pixel that sees the
//! reflector in the main image sees, through the surface, the interpolated vertex rays of the
//! reflector point under it (exact at the vertices, an approximation in between: 7.2.2).
//! "Under it" is exact with the projective screen map ([`SurfaceScreenMap::Projective`],
//! weights `1 / depth` of the vertices from the eye); the thesis's screen-space (affine)
//! map meets the reflector at the eye ray's point only at the vertices.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::geometry::optics::{reflect, refract};
use crate::geometry::MeshView;
use crate::projection::trilinear::is_degenerate_screen_triangle;
use crate::projection::{
    AnalyticInverse, FragmentMirror, ImagePoint, Perspective, Projection, Trilinear, TrilinearMesh,
};

/// What the reflector does to the eye's rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Optic {
    /// A mirror: r = i - 2 (n . i) n.
    Reflect,
    /// A refracting surface between air (index 1, the side the vertex normals point to) and a
    /// material of index `ior` (behind the surface).
    Refract {
        /// Index of refraction of the material behind the surface.
        ior: f64,
    },
}

/// The vertex ray of unit incident direction `incident` (eye to vertex) at a vertex with unit
/// shading normal `normal` and outward face normal `face` (the winding's; any length), as the
/// ray caster's mirror and glass treat a hit there:
///
/// - the shading normal is first turned to the side of the face the ray arrives from;
/// - [`Optic::Reflect`]: `incident - 2 (normal . incident) normal`; grazing incidence
///   (`normal . incident = 0`) gives the incident direction itself;
/// - [`Optic::Refract`]: Snell's law in vector form with `eta = 1 / ior` when the ray enters
///   (arrives against `face`) and `eta = ior` when it leaves; on total internal reflection
///   (`eta sin(incidence) > 1`) the vertex ray is the mirror reflection. A shading normal
///   that faces away from the ray (bent normals seen at grazing angles) counts as grazing
///   incidence (cos = 0), as in the ray caster.
///
/// A zero `face` (a vertex of degenerate triangles only) takes `normal` as the face.
pub fn vertex_ray(incident: DVec3, normal: DVec3, face: DVec3, optic: Optic) -> DVec3 {
    let face = if face == DVec3::ZERO { normal } else { face };
    let entering = enters(incident, normal, face);
    let towards_ray = if entering { face } else { -face };
    let normal = if normal.dot(towards_ray) < 0.0 {
        -normal
    } else {
        normal
    };
    match optic {
        Optic::Reflect => reflect(incident, normal),
        Optic::Refract { ior } => {
            let eta = if entering { 1.0 / ior } else { ior };
            refract(incident, normal, eta)
                .map_or_else(|| reflect(incident, normal), |r| r.direction)
        }
    }
}

/// Whether a ray of direction `incident` arrives at a vertex against its face normal `face`
/// (a zero `face` takes the shading normal `normal`), entering a glass rather than leaving
/// it: the side [`vertex_ray`] refracts from.
pub fn enters(incident: DVec3, normal: DVec3, face: DVec3) -> bool {
    let face = if face == DVec3::ZERO { normal } else { face };
    incident.dot(face) <= 0.0
}

/// How a surface's screen positions map to barycentrics of its projection triangles.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SurfaceScreenMap {
    /// Perspective-correct: each main-image pixel takes the vertex rays interpolated at the
    /// point of the reflector its eye ray meets (screen weights `1 / depth`,
    /// [`Trilinear::with_screen_weights`]); with straight vertex rays (`ior` 1) or a flat
    /// mirror the surface is exact. Not the default: its longer vertex rays make curved
    /// mirrors seen from close by and strong lenses worse than the affine map
    /// (docs/trilinear-surfaces.md).
    Projective,
    /// Screen-space interpolation as in Vallance 2005, 7.2.2, with unit vertex rays as in the
    /// thesis: exact at the vertices only. The default.
    #[default]
    Affine,
}

/// Which rays a reflector surface sends (scene-file key `camera_rays`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SurfaceRays {
    /// The vertex rays interpolated barycentrically (Vallance 2005, 7.2.2; the camera
    /// triangles of Hou et al. 2006, section 2). The default.
    #[default]
    Interpolated,
    /// The eye's ray reflected per screen point about the interpolated vertex normals (Hou
    /// et al. 2006, 3.1: [`FragmentMirror`]); mirrors only.
    PerFragment,
}

/// A reflection or refraction surface and what was left out of it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReflectorSurface {
    /// The projection mesh: used reflector vertices only, vertex rays as long as the
    /// vertex's distance from the eye, screen positions in the main image; triangles ordered
    /// for visibility (see [`reflector_surface`]).
    pub mesh: TrilinearMesh,
    /// The screen weight of each mesh vertex: 1 / its forward depth from the eye (finite and
    /// positive: vertices on or behind the eye's plane have no ray).
    pub weights: Vec<f64>,
    /// Reflector triangles left out (see [`reflector_surface`]).
    pub dropped: usize,
    /// The unit shading normal of each mesh vertex (the reflector's, as the ray caster
    /// interpolates them), for [`SurfaceRays::PerFragment`].
    pub shading_normals: Vec<DVec3>,
    /// The eye whose rays the surface reflects or refracts.
    pub eye: DVec3,
}

impl ReflectorSurface {
    /// The surface as a trilinear projection of `width` x `height` pixels with screen map
    /// `map` (for [`SurfaceScreenMap::Affine`] with the vertex rays normalised, the thesis's
    /// surface) and rays `rays` (per fragment: the surface's [`FragmentMirror`], which only a
    /// mirror's surface may ask for); `None` when it has no triangles. Errors: those of
    /// [`Trilinear::new`].
    pub fn projection(
        &self,
        map: SurfaceScreenMap,
        rays: SurfaceRays,
        width: u32,
        height: u32,
    ) -> Result<Option<Trilinear>> {
        if self.mesh.triangles.is_empty() {
            return Ok(None);
        }
        let projection = match map {
            SurfaceScreenMap::Affine => {
                let mut unit = self.mesh.clone();
                unit.normals.iter_mut().for_each(|r| *r = r.normalize());
                Trilinear::new(&unit, width, height)
            }
            SurfaceScreenMap::Projective => {
                Trilinear::with_screen_weights(&self.mesh, &self.weights, width, height)
            }
        }?;
        match rays {
            SurfaceRays::Interpolated => Ok(Some(projection)),
            SurfaceRays::PerFragment => projection
                .with_fragment_mirror(FragmentMirror {
                    eye: self.eye,
                    normals: self.shading_normals.clone(),
                })
                .map(Some),
        }
    }
}

/// Builds the surface of `reflector` (a world-space mesh) seen by the main camera `camera`
/// (whose eye is the eye of the first-hit reflections) with `optic`.
///
/// Vertex `k` at `p` gets the ray `|p - eye| vertex_ray(i, n)` with `i = (p - eye) / |p - eye|`
/// and `n` its unit vertex normal (the length makes the interpolated direction at the point
/// `P` the eye sees exact where the optic is linear: `P - eye` itself for straight rays, its
/// mirror image for a flat mirror; unit rays would interpolate unit vectors, which bend), the screen position `(x / W, 1 - y / H)` of its pixel
/// position `(x, y)` in the main image (outside [0, 1]^2 when it is outside the image), and
/// the screen weight `1 / ((p - eye) . forward)` of the projective screen map.
///
/// Degenerate cases:
/// - a mesh without vertex normals, or a zero normal: the area-weighted mean of the adjacent
///   face normals is used; a vertex with no usable normal at all has no ray;
/// - a vertex at the eye, or on or behind the plane of the eye (the main camera does not
///   image it), or so near that plane that its screen weight is not finite: no ray and no
///   screen position;
/// - a triangle is left out when a vertex has no ray, when the eye is not on the side of its
///   plane that its vertex normals point to (the back of a closed reflector, hidden in the
///   main image, or the back of an open one; also when the normals lie in the plane), or
///   when its screen triangle has zero area (seen edge on). A vertex normal may still face
///   away from the eye (grazing views of bent normals): its ray is the continuation above;
/// - kept triangles can overlap on screen (a reflector that hides part of itself); the
///   trilinear projection then uses the first, so nearer triangles (centroid distance from
///   the eye) come first. The front-facing triangles of a convex reflector do not overlap,
///   and they cover its whole image, silhouette included.
///
/// A reflector that the camera does not see gives a surface without triangles. Errors: a
/// refractive index that is not finite and positive.
pub fn reflector_surface<'a>(
    reflector: impl Into<MeshView<'a>>,
    camera: &Perspective,
    optic: Optic,
) -> Result<ReflectorSurface> {
    let reflector = reflector.into();
    if let Optic::Refract { ior } = optic {
        if !ior.is_finite() || ior <= 0.0 {
            return Err(Error::new(format!(
                "index of refraction must be finite and positive, got {ior}"
            )));
        }
    }
    let eye = camera.basis().origin;
    let forward = camera.basis().forward;
    let normals = vertex_normals(reflector);
    let size = {
        let (w, h) = camera.resolution();
        DVec2::new(f64::from(w), f64::from(h))
    };
    let mut images = Vec::new();
    let vertices: Vec<Option<SurfaceVertex>> = reflector
        .positions
        .iter()
        .zip(&normals)
        .map(|(p, &(normal, face))| {
            let point = p.as_dvec3();
            let distance = point.distance(eye);
            let incident = (point - eye).try_normalize()?;
            let normal = normal.try_normalize()?;
            images.clear();
            camera.project(point, &mut images);
            let &ImagePoint { pixel, .. } = images.first()?;
            let weight = 1.0 / (point - eye).dot(forward);
            (weight.is_finite() && weight > 0.0).then_some(SurfaceVertex {
                point,
                normal,
                direction: distance * vertex_ray(incident, normal, face, optic),
                screen: DVec2::new(pixel.x / size.x, 1.0 - pixel.y / size.y),
                weight,
            })
        })
        .collect();

    let mut kept: Vec<(f64, [u32; 3])> = Vec::new();
    for triangle in reflector.triangles {
        let [Some(a), Some(b), Some(c)] = triangle.map(|k| vertices[k as usize]) else {
            continue;
        };
        let face = (b.point - a.point).cross(c.point - a.point);
        let reflecting_side = face.dot(a.normal + b.normal + c.normal);
        let eye_side = face.dot(eye - a.point);
        if reflecting_side * eye_side <= 0.0
            || is_degenerate_screen_triangle([a.screen, b.screen, c.screen])
        {
            continue;
        }
        let centroid = (a.point + b.point + c.point) / 3.0;
        kept.push((centroid.distance(eye), *triangle));
    }
    kept.sort_by(|x, y| x.0.total_cmp(&y.0));

    let mut mesh = TrilinearMesh::default();
    let mut weights = Vec::new();
    let mut shading_normals = Vec::new();
    let mut new_index = vec![u32::MAX; vertices.len()];
    for &(_, triangle) in &kept {
        let mapped = triangle.map(|k| {
            let slot = &mut new_index[k as usize];
            if *slot == u32::MAX {
                // Kept triangles only use vertices that have a ray.
                if let Some(v) = vertices[k as usize] {
                    *slot = mesh.points.len() as u32;
                    mesh.points.push(v.point);
                    mesh.normals.push(v.direction);
                    mesh.screen.push(v.screen);
                    weights.push(v.weight);
                    shading_normals.push(v.normal);
                }
            }
            *slot
        });
        mesh.triangles.push(mapped);
    }
    Ok(ReflectorSurface {
        dropped: reflector.triangles.len() - mesh.triangles.len(),
        mesh,
        weights,
        shading_normals,
        eye,
    })
}

/// A reflector vertex that has a ray.
#[derive(Debug, Clone, Copy)]
struct SurfaceVertex {
    point: DVec3,
    /// The unit vertex normal.
    normal: DVec3,
    direction: DVec3,
    screen: DVec2,
    /// 1 / forward depth from the eye.
    weight: f64,
}

/// The shading and face normals of each vertex of `mesh` (not normalised): the face normal is
/// the sum of the adjacent faces' normals weighted by area (outward for an outward winding);
/// the shading normal is the mesh's own where present and non-zero, else the face normal.
/// Both are zero for a vertex of no triangle. Also the normals that
/// [`crate::render::composite`]'s refinement interpolates.
pub(crate) fn vertex_normals<'a>(mesh: impl Into<MeshView<'a>>) -> Vec<(DVec3, DVec3)> {
    let mesh = mesh.into();
    let mut from_faces = vec![DVec3::ZERO; mesh.positions.len()];
    for t in mesh.triangles {
        let [a, b, c] = t.map(|k| mesh.positions[k as usize].as_dvec3());
        let area_normal = (b - a).cross(c - a);
        for &k in t {
            from_faces[k as usize] += area_normal;
        }
    }
    from_faces
        .into_iter()
        .enumerate()
        .map(|(k, face)| match mesh.normals.get(k) {
            Some(n) if *n != glam::Vec3::ZERO => (n.as_dvec3(), face),
            _ => (face, face),
        })
        .collect()
}

#[cfg(test)]
mod tests;
