//! The photon-location map of one mirror or glass object and point light (the first pass
//! of the caustics, module doc of [`super`]): a square pinhole image from the light framing
//! the object's bounding sphere, each texel holding where the light's ray through its centre
//! lands after one reflection in the mirror (one refraction into the glass), with the
//! fraction of the light carried on, and the caustic triangles its neighbouring texels make.

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

use super::receives;
use crate::error::{Error, Result};
use crate::geometry::optics::{refract, refraction_normal};
use crate::projection::trilinear_builders::{
    reflector_surface, Optic, SurfaceRays, SurfaceScreenMap,
};
use crate::projection::{CameraFrame, Perspective, Projection, Trilinear};
use crate::render::composite::{perspective_as_trilinear, without, Reflector};
use crate::render::prepared::PreparedScene;
use crate::render::shading::normals;
use crate::render::shading::trace::specular;
use crate::render::{Frame, Method, Outputs, RenderOptions, Shading, Stats};
use crate::scene::{CausticReflector, Finish, Mesh, Scene};
use crate::try_alloc;

/// How a photon-location map is made: through the reflector's camera triangles by a method
/// that renders trilinear projections, or exactly by tracing every texel's ray.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::render) enum PhotonSource {
    /// The reflector's reflection (refraction) surface seen from the light, rendered by
    /// this method (camera triangles or trilinear).
    Surface(Method),
    /// The ray caster's exact mirror or glass: each texel's light ray reflected (refracted)
    /// about the reflector's interpolated normal where it hits it (the reference).
    Exact,
}

impl PhotonSource {
    /// The photon map of `method`. Errors: `raster`, which renders neither a trilinear
    /// surface nor traces rays.
    pub fn of(method: Method) -> Result<PhotonSource> {
        match method {
            Method::Raycast => Ok(PhotonSource::Exact),
            Method::Trilinear | Method::CameraTriangles => Ok(PhotonSource::Surface(method)),
            Method::Raster => Err(Error::new(
                "caustics are rendered by --method camera-triangles, trilinear or raycast, \
                 not raster",
            )),
        }
    }
}

/// Where one photon lands: a receiver point and the receiver's object id, and the fraction
/// of the light it carries on past the reflector (1 for a mirror; `1 - F` for glass, `F` the
/// Fresnel reflectance where the light's ray meets it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::render) struct Photon {
    pub point: DVec3,
    pub id: u32,
    pub transmittance: f64,
}

/// A triangle of light on a receiver: its corners, the receiver's id and its irradiance
/// (module doc of [`super`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::render) struct CausticTriangle {
    pub points: [DVec3; 3],
    pub id: u32,
    pub irradiance: Vec3,
}

/// A photon-location map: `size` x `size` texels from the light, rows from the top.
pub(in crate::render) struct PhotonMap {
    pub camera: Perspective,
    pub size: u32,
    pub photons: Vec<Option<Photon>>,
    /// The counters of the render through the reflector's surface (with camera
    /// triangles: `camera_triangles`, `bounding_fragments`, ...); empty for the exact map.
    pub counters: Stats,
}

impl PhotonMap {
    /// The map of `caustic`'s mirror or glass lit from `light`, made as `source` says. The
    /// scene's trilinear reflectors and caustics play no part (the map's renders are plain).
    /// Errors: those of [`light_camera`]; a reflector that is neither (see [`Reflector::of`]);
    /// the method's own; memory that cannot be had for the map (module `try_alloc`).
    pub fn render(
        prepared: &PreparedScene,
        caustic: &CausticReflector,
        light: DVec3,
        source: PhotonSource,
        options: &RenderOptions,
    ) -> Result<PhotonMap> {
        let scene = prepared.scene();
        let reflector = Reflector::of(scene, caustic.id)?;
        let camera = light_camera(light, &reflector.mesh, caustic.map_size)?;
        let (photons, counters) = match source {
            PhotonSource::Exact => (exact(prepared, caustic.id, &camera)?, Stats::new()),
            PhotonSource::Surface(method) => {
                through_surface(prepared, caustic.id, &reflector, &camera, method, options)?
            }
        };
        Ok(PhotonMap {
            camera,
            size: caustic.map_size,
            photons,
            counters,
        })
    }

    /// Texels holding a photon.
    pub fn photon_count(&self) -> u64 {
        self.photons.iter().filter(|p| p.is_some()).count() as u64
    }

    /// The unit direction from the light through the centre of texel `(x, y)`.
    fn direction(&self, x: u32, y: u32) -> DVec3 {
        let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
        // A pinhole has a ray at every image position.
        self.camera.ray(centre).map_or(DVec3::ZERO, |r| r.direction)
    }

    /// The caustic triangles of the map for a light whose radiant intensity times the
    /// reflector's tint is `reflected` (per channel): every texel square `(x, y)`,
    /// `(x + 1, y + 1)` split along its diagonal from `(x + 1, y)` to `(x, y + 1)`, each half
    /// whose three photons lie on one object, with irradiance `reflected Ω_a T / A`, `T` the
    /// mean of its photons' transmittances (module doc of [`super`]); halves of zero area
    /// are left out.
    pub fn caustic_triangles(&self, reflected: Vec3) -> Vec<CausticTriangle> {
        let n = self.size;
        let at = |x: u32, y: u32| self.photons[(y * n + x) as usize];
        (0..n.saturating_sub(1))
            .into_par_iter()
            .flat_map_iter(|y| {
                (0..n - 1).flat_map(move |x| {
                    let halves = [
                        [(x, y), (x + 1, y), (x, y + 1)],
                        [(x + 1, y), (x + 1, y + 1), (x, y + 1)],
                    ];
                    halves.into_iter().filter_map(move |texels| {
                        let photons = texels.map(|(x, y)| at(x, y));
                        let [Some(p0), Some(p1), Some(p2)] = photons else {
                            return None;
                        };
                        if p1.id != p0.id || p2.id != p0.id {
                            return None;
                        }
                        let points = [p0.point, p1.point, p2.point];
                        let area = triangle_area(points);
                        if area.is_nan() || area <= 0.0 {
                            return None;
                        }
                        let beam = solid_angle(texels.map(|(x, y)| self.direction(x, y)));
                        let carried =
                            (p0.transmittance + p1.transmittance + p2.transmittance) / 3.0;
                        Some(CausticTriangle {
                            points,
                            id: p0.id,
                            irradiance: reflected * (beam * carried / area) as f32,
                        })
                    })
                })
            })
            .collect()
    }
}

/// The area of triangle `p`.
pub(in crate::render) fn triangle_area(p: [DVec3; 3]) -> f64 {
    0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
}

/// The solid angle of the spherical triangle of unit directions `d` (Van Oosterom and
/// Strackee 1983): `2 atan2(|d0 · (d1 × d2)|, 1 + d0·d1 + d1·d2 + d2·d0)`; 0 for coplanar
/// directions.
pub(in crate::render) fn solid_angle(d: [DVec3; 3]) -> f64 {
    let triple = d[0].dot(d[1].cross(d[2])).abs();
    let denominator = 1.0 + d[0].dot(d[1]) + d[1].dot(d[2]) + d[2].dot(d[0]);
    2.0 * triple.atan2(denominator)
}

/// The pinhole at `light` looking at the centre of `mesh`'s bounding box, its square image
/// of `size` texels just framing the sphere around that centre through the mesh's farthest
/// vertex (the horizontal field `2 asin(r / d)`, 1 % wider). Errors: `light` inside or on
/// that sphere (no pinhole image frames it), or an empty mesh.
pub(in crate::render) fn light_camera(light: DVec3, mesh: &Mesh, size: u32) -> Result<Perspective> {
    let points = || mesh.positions.iter().map(|p| p.as_dvec3());
    let (lo, hi) = points().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p), hi.max(p))
    });
    let centre = (lo + hi) / 2.0;
    let radius = points().map(|p| (p - centre).length()).fold(0.0, f64::max);
    let distance = (centre - light).length();
    if distance.is_nan() || distance <= radius || !centre.is_finite() {
        return Err(Error::new(format!(
            "a caustic's point light at ({}, {}, {}) lies inside the reflector's bounding \
             sphere (centre ({:.3}, {:.3}, {:.3}), radius {radius:.3}): move it out to map \
             the reflector from it",
            light.x, light.y, light.z, centre.x, centre.y, centre.z
        )));
    }
    let half = (radius / distance).asin();
    let fov = (2.0 * half * 1.01).to_degrees().min(179.0);
    let forward = (centre - light) / distance;
    let up = if forward.y.abs() < 0.9 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let frame = CameraFrame {
        position: light,
        look_at: centre,
        up,
    };
    Perspective::new(&frame, fov, size, size)
}

/// Options for the plain renders of a map: flat, every buffer, nothing composited.
fn plain<'a>(method: Method, options: &RenderOptions<'a>) -> RenderOptions<'a> {
    RenderOptions {
        method,
        composite_reflectors: false,
        shading: Shading::Flat,
        outputs: Outputs::ALL,
        progress: None,
        crop: None,
        ..*options
    }
}

/// The photons of reflector `id`'s reflection or refraction surface seen from `camera`
/// (built from the reflector's mesh, optic and the light, projective screen map: each texel
/// takes the surface's rays at the reflector point its light ray meets), the scene without
/// the reflector rendered through it by `method`; a texel holds a photon where the scene
/// from the light (the reflector made diffuse, by the trilinear method through the pinhole
/// as two projection triangles) sees the reflector first and the surface's ray lands on a
/// receiver. A refracted photon carries [`surface_transmittance`]; a texel where that has
/// none holds no photon. Also the counters of the render through the surface (none where
/// the light sees no surface).
fn through_surface(
    prepared: &PreparedScene,
    id: u32,
    reflector: &Reflector,
    camera: &Perspective,
    method: Method,
    options: &RenderOptions,
) -> Result<(Vec<Option<Photon>>, Stats)> {
    let scene = prepared.scene();
    let n = camera.resolution().0 as usize;
    let Some(surface) = reflector_surface(&reflector.mesh, camera, reflector.optic)?.projection(
        SurfaceScreenMap::Projective,
        SurfaceRays::Interpolated,
        n as u32,
        n as u32,
    )?
    else {
        return Ok((photons(n, |_| None)?, Stats::new()));
    };
    let mut diffuse = plain_scene(scene);
    for object in &mut diffuse.objects {
        if object.id == id {
            object.material.finish = Finish::Diffuse;
        }
    }
    let pinhole = perspective_as_trilinear(camera)?;
    let seen = Method::Trilinear
        .render(
            &prepared.view(diffuse),
            &pinhole,
            &plain(Method::Trilinear, options),
        )?
        .0;
    let others = prepared.view(plain_scene(&without(scene, id)));
    let (reflected, counters): (Frame, Stats) =
        method.render(&others, &surface, &plain(method, options))?;
    let photon = |k: usize| {
        let receiver = reflected.ids[k];
        if seen.ids[k] != id || receiver == 0 || !receives(scene, receiver) {
            return None;
        }
        let centre = DVec2::new((k % n) as f64 + 0.5, (k / n) as f64 + 0.5);
        let ray = surface.ray(centre)?;
        let direction = ray.direction.normalize();
        let transmittance = match reflector.optic {
            Optic::Reflect => 1.0,
            Optic::Refract { ior } => {
                let incident = camera.ray(centre)?.direction;
                surface_transmittance(&surface, centre, incident, direction, ior)?
            }
        };
        Some(Photon {
            point: ray.origin + direction * f64::from(reflected.depth[k]),
            id: receiver,
            transmittance,
        })
    };
    Ok((photons(n, photon)?, counters))
}

/// The Fresnel transmittance `1 - F` of a refraction surface of index `ior` at screen point
/// `centre` of `surface` (a map texel), where the light's unit ray `incident` becomes the
/// surface's interpolated unit ray `refracted`. The normal it was refracted about follows
/// from the two directions ([`refraction_normal`]); the side (entering, relative index
/// `1 / ior`, or leaving, `ior`) from the winding of the surface's triangle there, as the
/// ray caster decides it by the face hit. `None` where no normal refracts `incident` into
/// `refracted` (an interpolation of total internal reflections, which the surface's vertex
/// rays turn into mirror reflections, or no triangle there); `1` for `ior` 1 (no
/// interface).
fn surface_transmittance(
    surface: &Trilinear,
    centre: DVec2,
    incident: DVec3,
    refracted: DVec3,
    ior: f64,
) -> Option<f64> {
    if ior == 1.0 {
        return Some(1.0);
    }
    let (triangle, _, _) = surface.locate(centre)?;
    let mesh = surface.mesh();
    let [a, b, c] = mesh.triangles[triangle].map(|k| mesh.points[k as usize]);
    let entering = incident.dot((b - a).cross(c - a)) <= 0.0;
    let eta = if entering { 1.0 / ior } else { ior };
    let normal = refraction_normal(incident, refracted, eta)?;
    refract(incident, normal, eta).map(|r| 1.0 - r.reflectance)
}

/// `scene` without trilinear reflectors or caustics: what a map's renders see.
fn plain_scene(scene: &Scene) -> Scene {
    let mut plain = scene.clone();
    plain.trilinear_reflectors.clear();
    plain.caustics.clear();
    plain
}

/// The exact photons of reflector `id` seen from `camera`: each texel's light ray through
/// the whole scene; where its first hit is the reflector, reflected or refracted about its
/// interpolated shading normal there as the ray caster's mirror and glass do
/// ([`specular`]), carrying the glass's Fresnel transmittance, and traced through the scene
/// without the reflector (one refraction, as the refraction surface has it). A texel under
/// total internal reflection holds no photon (the light stays on the light's side).
fn exact(prepared: &PreparedScene, id: u32, camera: &Perspective) -> Result<Vec<Option<Photon>>> {
    let scene = prepared.scene();
    let others = prepared.view(without(scene, id));
    let n = camera.resolution().0 as usize;
    let photon = |k: usize| {
        let centre = DVec2::new((k % n) as f64 + 0.5, (k / n) as f64 + 0.5);
        let ray = camera.ray(centre)?;
        let hit = prepared.intersect(&ray)?;
        let reflector = &scene.objects[hit.object];
        if reflector.id != id {
            return None;
        }
        let seen = normals(
            reflector,
            hit.triangle,
            hit.barycentric,
            ray.direction.as_vec3(),
        );
        let finish = reflector.material.finish;
        let sent = specular(&ray, &seen, finish);
        let transmittance = match (finish, sent.fresnel) {
            (Finish::Glass { .. }, Some((_, reflectance))) => 1.0 - f64::from(reflectance),
            (Finish::Glass { .. }, None) => return None,
            _ => 1.0,
        };
        let out = prepared.spawn(ray.at(hit.t), seen.geometric.as_dvec3(), sent.main);
        let landed = others.intersect(&out)?;
        let receiver = scene.objects[landed.object].id;
        receives(scene, receiver).then(|| Photon {
            point: out.at(landed.t),
            id: receiver,
            transmittance,
        })
    };
    photons(n, photon)
}

/// The photons of an `n` x `n` map, texel `k` (row-major) holding `photon(k)`, found in
/// parallel. Fails when the map's memory cannot be had (module `try_alloc`).
fn photons(
    n: usize,
    photon: impl Fn(usize) -> Option<Photon> + Sync,
) -> Result<Vec<Option<Photon>>> {
    let mut photons = try_alloc::filled(n * n, None, || format!("a {n} x {n} photon map"))?;
    photons
        .par_iter_mut()
        .enumerate()
        .for_each(|(k, slot)| *slot = photon(k));
    Ok(photons)
}
