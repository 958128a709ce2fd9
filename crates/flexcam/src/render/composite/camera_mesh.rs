//! The camera mesh of a reflector (Hou, Wei, Shum and Guo 2006, 2.3): a coarse version of the
//! reflector's mesh whose triangles become the camera triangles of its trilinear surface.
//!
//! The coarse mesh is [`coarse_triangles`]: half-edge collapses, so every coarse vertex is a
//! vertex of the reflector with its own shading normal, and the coarse surface stays on the
//! reflector (the paper's correspondence by normal shooting is then the identity at the
//! vertices). Fewer camera triangles mean fewer (camera, scene triangle) pairs to bound, so
//! the renderer is faster; between its vertices the coarse mesh interpolates normals that may
//! differ from the reflector's, so its reflection drifts from the true mirror.
//!
//! - **Given size** (`camera_triangles = N`): the simplification to `N` triangles, used as it
//!   is ([`CameraMesh::refine`] false).
//! - **No size given, another method than camera triangles**: the reflector's own mesh, refined
//!   ([`CameraMesh::refine`] true): the trilinear method's reflection surface is the
//!   reflector's triangles (Vallance 2005, chapter 7), and the automatic search below would
//!   cost every such render a simplification that the example reflectors then discard.
//! - **Automatic size** (`--method camera-triangles`): `F/2, F/4, ...` (at least [`MIN_AUTO_TRIANGLES`]; `F` the
//!   reflector's triangles) are tried from the finest and the last whose *normal error*
//!   stays within the reflector's tolerance `trilinear_refine_px` in main-image pixels
//!   before the first that does not is taken, else the reflector's own mesh (the error
//!   grows as the mesh coarsens, so this is the smallest within the tolerance; where even
//!   `F/2` is not, as for every example reflector at the default tolerance, one
//!   simplification is all it costs);
//!   the result is then refined by the same tolerance as the reflector's own mesh is
//!   ([`super::refine`]), which bounds the error of the surface's interpolated rays against
//!   the coarse mesh's normals. The two errors add: at most about twice the tolerance
//!   against the reflector's own interpolated normals.
//!
//! The normal error is a cheap proxy of the image error, measured at the reflector's
//! vertices that the main camera can see (in front of the eye, inside the image, and for a
//! mirror facing the eye): at vertex `v` the coarse mesh's normal is interpolated at its
//! point nearest `v` (the closest point of the nearest coarse triangle whose plane faces the
//! same way as `v`'s normal); the vertex ray of that normal is compared with `v`'s own, as
//! [`vertex_ray`] makes both. The error in pixels is, as the refinement measures an edge
//! (its module doc), the angle between the two rays over the rate `sigma` at which `v`'s
//! rays turn per main-image pixel (the largest over its edges, at least the camera's pixel
//! angle at `v`), plus the distance from `v` to that nearest point over `v`'s pixel
//! footprint. The largest over the vertices must stay within the tolerance.
//!
//! Both sizes are remembered ([`Chosen`]): the last few reflectors' camera meshes are kept,
//! each with a copy of the reflector mesh, the size asked for and, for the automatic size,
//! the camera, optic and tolerance it was searched with; a render that asks again with equal
//! inputs (the frames of an animation whose reflector does not move, a viewer's re-renders)
//! reuses the result instead of simplifying anew, as the paper builds its camera mesh once.
//! The inputs are compared exactly, so a moved or edited reflector is simplified again.
//!
//! Degenerate cases: a tolerance of 0 (no refinement) keeps the reflector's own mesh, as
//! does a reflector that [`coarse_triangles`] cannot simplify (not an oriented manifold:
//! the given size refuses it instead, naming the defect), one of fewer than
//! `2 MIN_AUTO_TRIANGLES` triangles, or one whose vertices the camera sees none of.

use std::borrow::Cow;
use std::sync::{Arc, Mutex, PoisonError};

use glam::{DVec2, DVec3};

use crate::displace::simplify::coarse_triangles;
use crate::error::{Error, Result};
use crate::projection::trilinear_builders::{vertex_normals, vertex_ray, Optic};
use crate::projection::{ContinuousInverse, Perspective, Projection};
use crate::scene::{Mesh, TrilinearReflector};

/// The seed of the simplification's random edge choice: fixed, so that a scene renders the
/// same every time.
pub const SEED: u64 = 2006;

/// The automatic size never goes below this many triangles.
pub const MIN_AUTO_TRIANGLES: usize = 8;

/// A reflector's camera mesh and whether the reflector's tolerance refines it.
#[derive(Debug, Clone)]
pub struct CameraMesh<'a> {
    pub mesh: Cow<'a, Mesh>,
    /// False for a given size (`camera_triangles = N`: used as it is).
    pub refine: bool,
}

/// The camera mesh of `reflector` (its world-space mesh) for `entry`, seen by `camera`
/// (module doc); `automatic`: search the automatic size when `entry` gives none (the
/// camera-triangle method), else keep the reflector's own mesh. Errors: a given size for a
/// mesh that [`coarse_triangles`] refuses (the message names the reflector and the defect).
pub fn camera_mesh<'a>(
    reflector: &'a Mesh,
    entry: &TrilinearReflector,
    camera: &Perspective,
    optic: Optic,
    automatic: bool,
) -> Result<CameraMesh<'a>> {
    match entry.camera_triangles {
        Some(n) if n < reflector.triangles.len() => {
            let mesh = Chosen::remembered(reflector, Request::Size(n), || {
                coarse_triangles(reflector, n, SEED).map(Some).map_err(|e| {
                    Error::new(format!(
                        "reflector {}: cannot simplify its mesh to {n} camera triangles: {e}",
                        entry.id
                    ))
                })
            })?;
            Ok(CameraMesh {
                mesh: mesh.map_or(Cow::Borrowed(reflector), |m| Cow::Owned((*m).clone())),
                refine: false,
            })
        }
        Some(_) => Ok(CameraMesh {
            mesh: Cow::Borrowed(reflector),
            refine: false,
        }),
        None if automatic => {
            let request = Request::Automatic {
                camera: camera.clone(),
                optic,
                tolerance_px: entry.refine_px,
            };
            let mesh = Chosen::remembered(reflector, request, || {
                Ok(
                    match automatic_size(reflector, camera, optic, entry.refine_px) {
                        Cow::Owned(coarse) => Some(coarse),
                        Cow::Borrowed(_) => None,
                    },
                )
            })?;
            Ok(CameraMesh {
                mesh: mesh.map_or(Cow::Borrowed(reflector), |m| Cow::Owned((*m).clone())),
                refine: true,
            })
        }
        None => Ok(CameraMesh {
            mesh: Cow::Borrowed(reflector),
            refine: true,
        }),
    }
}

/// What a camera mesh was chosen for, besides the reflector's mesh.
#[derive(Debug, Clone, PartialEq)]
enum Request {
    /// A given number of triangles.
    Size(usize),
    /// The automatic size for this camera, optic and tolerance (module doc).
    Automatic {
        camera: Perspective,
        optic: Optic,
        tolerance_px: f64,
    },
}

/// A remembered choice: the reflector mesh and request it answers, and the coarse mesh
/// chosen (`None`: the reflector's own mesh).
struct Chosen {
    reflector: Arc<Mesh>,
    request: Request,
    coarse: Option<Arc<Mesh>>,
}

/// How many choices are remembered (the most recent first).
const REMEMBERED: usize = 4;

/// The remembered choices, most recent first.
static CHOSEN: Mutex<Vec<Chosen>> = Mutex::new(Vec::new());

impl Chosen {
    /// The camera mesh for `reflector` and `request`: a remembered one whose inputs are
    /// equal, else `choose()`'s, remembered unless it is an error. A poisoned lock (a panic
    /// elsewhere while it was held) is taken as it is: the list holds only complete entries.
    fn remembered(
        reflector: &Mesh,
        request: Request,
        choose: impl FnOnce() -> Result<Option<Mesh>>,
    ) -> Result<Option<Arc<Mesh>>> {
        let lock = || CHOSEN.lock().unwrap_or_else(PoisonError::into_inner);
        {
            let mut chosen = lock();
            let hit = chosen
                .iter()
                .position(|c| c.request == request && *c.reflector == *reflector);
            if let Some(k) = hit {
                let entry = chosen.remove(k);
                let coarse = entry.coarse.clone();
                chosen.insert(0, entry);
                return Ok(coarse);
            }
        }
        // Chosen without the lock held: other renders go on meanwhile.
        let coarse = choose()?.map(Arc::new);
        let mut chosen = lock();
        chosen.insert(
            0,
            Chosen {
                reflector: Arc::new(reflector.clone()),
                request,
                coarse: coarse.clone(),
            },
        );
        chosen.truncate(REMEMBERED);
        Ok(coarse)
    }
}

/// The automatic camera mesh (module doc).
fn automatic_size<'a>(
    reflector: &'a Mesh,
    camera: &Perspective,
    optic: Optic,
    tolerance_px: f64,
) -> Cow<'a, Mesh> {
    let own = reflector.triangles.len();
    if tolerance_px.is_nan() || tolerance_px <= 0.0 || own < 2 * MIN_AUTO_TRIANGLES {
        return Cow::Borrowed(reflector);
    }
    let seen = SeenVertices::new(reflector, camera, optic);
    if seen.vertices.is_empty() {
        return Cow::Borrowed(reflector);
    }
    let sizes = std::iter::successors(Some(own / 2), |n| Some(n / 2))
        .take_while(|&n| n >= MIN_AUTO_TRIANGLES);
    let mut chosen = Cow::Borrowed(reflector);
    for n in sizes {
        let Ok(coarse) = coarse_triangles(reflector, n, SEED) else {
            return Cow::Borrowed(reflector);
        };
        if seen.normal_error_px(&coarse, optic) > tolerance_px {
            break;
        }
        chosen = Cow::Owned(coarse);
    }
    chosen
}

/// A reflector vertex the main camera sees, with what the normal error compares against.
#[derive(Debug, Clone, Copy)]
struct SeenVertex {
    point: DVec3,
    /// Unit shading normal.
    normal: DVec3,
    /// Its face normal (area-weighted, any length): the side rays arrive from.
    face: DVec3,
    /// Unit vertex ray.
    ray: DVec3,
    /// Radians the vertex rays turn per main-image pixel around it (module doc).
    sigma: f64,
    /// The pixel's footprint at the vertex (distance to the eye times the pixel angle).
    footprint: f64,
}

/// The reflector's vertices the main camera sees (module doc).
struct SeenVertices {
    eye: DVec3,
    vertices: Vec<SeenVertex>,
}

impl SeenVertices {
    fn new(reflector: &Mesh, camera: &Perspective, optic: Optic) -> SeenVertices {
        let eye = camera.basis().origin;
        let (width, height) = camera.resolution();
        let size = DVec2::new(f64::from(width), f64::from(height));
        let normals = vertex_normals(reflector);
        // Each vertex's ray, pixel and pixel angle, where the camera images it.
        let sample = |k: usize| {
            let point = reflector.positions[k].as_dvec3();
            let (shading, face) = normals[k];
            let normal = shading.try_normalize()?;
            let incident = (point - eye).try_normalize()?;
            let pixel = camera.project_continuous(point)?.pixel;
            let here = camera.ray(pixel)?.direction.normalize();
            let beside = camera.ray(pixel + DVec2::X)?.direction.normalize();
            let ray = vertex_ray(incident, normal, face, optic);
            Some((point, normal, ray, pixel, here.angle_between(beside), face))
        };
        let samples: Vec<_> = (0..reflector.positions.len()).map(sample).collect();
        let mut sigma: Vec<f64> = samples.iter().map(|s| s.map_or(0.0, |s| s.4)).collect();
        for t in &reflector.triangles {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let (a, b) = (a as usize, b as usize);
                let (Some(sa), Some(sb)) = (samples[a], samples[b]) else {
                    continue;
                };
                let pixels = sa.3.distance(sb.3);
                if pixels > 0.0 {
                    let turn = sa.2.angle_between(sb.2) / pixels;
                    sigma[a] = sigma[a].max(turn);
                    sigma[b] = sigma[b].max(turn);
                }
            }
        }
        let vertices = samples
            .iter()
            .zip(&sigma)
            .filter_map(|(s, &sigma)| {
                let (point, normal, ray, pixel, angle, face) = (*s)?;
                let inside = pixel.cmpge(DVec2::ZERO).all() && pixel.cmple(size).all();
                let facing = optic != Optic::Reflect || face.dot(eye - point) > 0.0;
                (inside && facing && sigma > 0.0).then_some(SeenVertex {
                    point,
                    normal,
                    face,
                    ray,
                    sigma,
                    footprint: point.distance(eye) * angle,
                })
            })
            .collect();
        SeenVertices { eye, vertices }
    }

    /// The largest normal error of `coarse` over the seen vertices, in main-image pixels
    /// (module doc); infinite where a vertex finds no coarse triangle facing its way.
    fn normal_error_px(&self, coarse: &Mesh, optic: Optic) -> f64 {
        let normals = vertex_normals(coarse);
        let triangles: Vec<CoarseTriangle> = coarse
            .triangles
            .iter()
            .map(|t| CoarseTriangle::new(coarse, &normals, *t))
            .collect();
        let mut worst: f64 = 0.0;
        for v in &self.vertices {
            let nearest = triangles
                .iter()
                .filter(|t| t.face.dot(v.normal) > 0.0)
                .map(|t| (t.closest(v.point), t))
                .min_by(|a, b| a.0 .1.total_cmp(&b.0 .1));
            let Some(((weights, distance), t)) = nearest else {
                return f64::INFINITY;
            };
            let Some(normal) = t.normal(weights) else {
                return f64::INFINITY;
            };
            let Some(incident) = (v.point - self.eye).try_normalize() else {
                continue;
            };
            let ray = vertex_ray(incident, normal, v.face, optic);
            // atan2 rather than acos: exact for the small angles compared here.
            let angle = ray.cross(v.ray).length().atan2(ray.dot(v.ray));
            let error = angle / v.sigma + distance / v.footprint;
            worst = worst.max(if error.is_nan() { f64::INFINITY } else { error });
        }
        worst
    }
}

/// A coarse triangle: its corners, their shading normals and its face normal.
struct CoarseTriangle {
    corners: [DVec3; 3],
    normals: [DVec3; 3],
    face: DVec3,
}

impl CoarseTriangle {
    fn new(mesh: &Mesh, normals: &[(DVec3, DVec3)], t: [u32; 3]) -> CoarseTriangle {
        let corners = t.map(|k| mesh.positions[k as usize].as_dvec3());
        CoarseTriangle {
            corners,
            normals: t.map(|k| normals[k as usize].0.normalize_or_zero()),
            face: (corners[1] - corners[0]).cross(corners[2] - corners[0]),
        }
    }

    /// The unit shading normal interpolated at barycentric weights `w` (`None` where it
    /// vanishes).
    fn normal(&self, w: [f64; 3]) -> Option<DVec3> {
        (w[0] * self.normals[0] + w[1] * self.normals[1] + w[2] * self.normals[2]).try_normalize()
    }

    /// The barycentric weights of the triangle's point closest to `p`, and its distance
    /// (Ericson 2005, 5.1.5).
    fn closest(&self, p: DVec3) -> ([f64; 3], f64) {
        let [a, b, c] = self.corners;
        let at = |w: [f64; 3]| (w, (w[0] * a + w[1] * b + w[2] * c).distance(p));
        let (ab, ac, ap) = (b - a, c - a, p - a);
        let (d1, d2) = (ab.dot(ap), ac.dot(ap));
        if d1 <= 0.0 && d2 <= 0.0 {
            return at([1.0, 0.0, 0.0]);
        }
        let bp = p - b;
        let (d3, d4) = (ab.dot(bp), ac.dot(bp));
        if d3 >= 0.0 && d4 <= d3 {
            return at([0.0, 1.0, 0.0]);
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            let s = d1 / (d1 - d3);
            return at([1.0 - s, s, 0.0]);
        }
        let cp = p - c;
        let (d5, d6) = (ab.dot(cp), ac.dot(cp));
        if d6 >= 0.0 && d5 <= d6 {
            return at([0.0, 0.0, 1.0]);
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            let s = d2 / (d2 - d6);
            return at([1.0 - s, 0.0, s]);
        }
        let va = d3 * d6 - d5 * d4;
        if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            let s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            return at([0.0, 1.0 - s, s]);
        }
        let denom = va + vb + vc;
        if denom == 0.0 || !denom.is_finite() {
            return at([1.0, 0.0, 0.0]);
        }
        let (v, w) = (vb / denom, vc / denom);
        at([1.0 - v - w, v, w])
    }
}

#[cfg(test)]
mod tests;
