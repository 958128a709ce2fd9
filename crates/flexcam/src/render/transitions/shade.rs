//! Shading of a ray whose first hit is on a displaced object's hull, by the method the
//! transition function chooses for it ([`crate::displace::transition`]).
//!
//! All three methods shade with the same normals, after Becker and Max: the normal of the
//! height field at the hit's texture coordinates ([`Chart::normal`], the bump normal),
//! redistributed so that over the surface it is distributed as the displaced surface's
//! visible normals from this ray's view angle. Redistributed bump mapping shades the
//! undisplaced surface with it; partial displacement by `s` traces the surface displaced by
//! `s` and redistributes from the corrected angle `atan(s tan theta_V)`; full displacement
//! traces the displaced surface and keeps the normal (from the angle to itself); the BRDF
//! shades the undisplaced surface with the table, the mean of what the bump normals give.
//! Light is diffuse: ambient plus, per light a shadow ray reaches, the Lambert term of the
//! normal (or the BRDF); no highlight (the tables are diffuse). Shadow rays of displaced
//! geometry meet the displaced objects displaced; those of the bump and BRDF methods, where
//! the relief is under a few footprints, meet them undisplaced (their hulls: cheap, and the
//! shadows differ by less than the relief).

use glam::{DVec2, DVec3, Vec3};

use super::{Renderer, TransitionMethod};
use crate::displace::normal_distribution::rotate;
use crate::displace::transition::{self, partial_view_angle, Blend};
use crate::geometry::Ray;
use crate::render::displaced::{ObjectTables, PARTIAL_STEPS};
use crate::render::prepared::Hit;
use crate::render::shading::trace::LightTerms;
use crate::render::shading::{base_color, TextureFilter};
use crate::scene::{Object, Scene};

/// Ambient fraction of the base colour (as in lit shading).
const AMBIENT: f32 = 0.1;

/// The frame of the undisplaced surface at a hit: unit normal facing the ray, a tangent
/// along increasing u, the third axis, and the texture coordinates there.
struct SurfaceFrame {
    normal: DVec3,
    tangent: DVec3,
    bitangent: DVec3,
    /// +1 where the bitangent runs along increasing v, -1 where the uvs are mirrored.
    v_sign: f64,
    uv: DVec2,
}

impl SurfaceFrame {
    fn at(object: &Object, triangle: usize, barycentric: DVec2, incoming: DVec3) -> SurfaceFrame {
        let mesh = &object.mesh;
        let [a, b, c] = mesh.triangles[triangle].map(|i| i as usize);
        let w = [
            1.0 - barycentric.x - barycentric.y,
            barycentric.x,
            barycentric.y,
        ];
        let p = [a, b, c].map(|i| mesh.positions[i].as_dvec3());
        let t = [a, b, c].map(|i| mesh.uvs[i].as_dvec2());
        let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        let interpolated = [a, b, c]
            .iter()
            .zip(w)
            .map(|(&i, w)| match mesh.normals[i].as_dvec3() {
                DVec3::ZERO => face * w,
                n => n * w,
            })
            .sum::<DVec3>()
            .normalize_or_zero();
        let mut normal = if interpolated == DVec3::ZERO {
            face
        } else {
            interpolated
        };
        if normal.dot(incoming) > 0.0 {
            normal = -normal;
        }
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (t[1] - t[0], t[2] - t[0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        let (du, dv) = if det != 0.0 && det.is_finite() {
            ((e1 * d2.y - e2 * d1.y) / det, (e2 * d1.x - e1 * d2.x) / det)
        } else {
            (e1, e2)
        };
        let tangent = (du - normal * normal.dot(du))
            .try_normalize()
            .unwrap_or_else(|| normal.any_orthonormal_vector());
        let bitangent = normal.cross(tangent);
        SurfaceFrame {
            normal,
            tangent,
            bitangent,
            v_sign: if bitangent.dot(dv) < 0.0 { -1.0 } else { 1.0 },
            uv: t[0] * w[0] + t[1] * w[1] + t[2] * w[2],
        }
    }

    fn local(&self, v: DVec3) -> DVec3 {
        DVec3::new(
            v.dot(self.tangent),
            v.dot(self.bitangent),
            v.dot(self.normal),
        )
    }

    fn world(&self, v: DVec3) -> DVec3 {
        self.tangent * v.x + self.bitangent * v.y + self.normal * v.z
    }
}

/// What a ray on a displaced object's hull became: its colour, the hit it was shaded at
/// (`None`: it passed through the partly displaced surface to the background), and the
/// blend of methods.
pub(super) struct Shaded {
    pub color: Vec3,
    pub hit: Option<Hit>,
    pub blend: Blend,
}

impl<'a> Renderer<'a> {
    /// The scene whose displaced objects have the meshes of level of detail `level`: the
    /// prepared scene itself for the detailed level.
    fn level_scene(&self, level: usize) -> &'a Scene {
        match (level, self.data) {
            (0, _) | (_, None) => &self.prepared.scene,
            (k, Some(data)) => &data.lods.levels[k].scene,
        }
    }

    /// Shades `ray`, whose first hit `hull` is on the hull of a displaced object, seen by
    /// the pixel at `pixel`.
    pub(super) fn shade_displaced(&mut self, ray: &Ray, hull: Hit, pixel: DVec2) -> Shaded {
        let data = self.data.expect("a displaced object has transition data");
        let object = &self.prepared.scene.objects[hull.object];
        let tables = data.tables.get(hull.object).expect("a displaced object");
        let view = -ray.direction.normalize();
        let frame = SurfaceFrame::at(object, hull.triangle, hull.barycentric.as_dvec2(), -view);
        let cos_view = frame.normal.dot(view).clamp(0.0, 1.0);
        let footprint = super::footprint::footprint(self.projection, pixel, ray.at(hull.t));
        let blend = self.method.forced_blend().unwrap_or_else(|| {
            transition::blend(transition::value(
                tables.relief(),
                tables.wavelength(),
                footprint,
                self.d,
                cos_view,
            ))
        });
        let step = (blend.fraction * PARTIAL_STEPS as f64).round() as usize;
        let level = if step == 0 {
            0
        } else {
            data.lods
                .select(self.lod, hull.object, ray.origin, footprint)
        };
        let lod = &data.lods.levels[level];
        let scene = self.level_scene(level);
        let hit = if step == 0 {
            Some(hull)
        } else {
            self.levels[level] += 1;
            if step == PARTIAL_STEPS && level == 0 {
                // Full displacement: the prepared scene's own search, with its kept boxes.
                self.prepared.intersect(ray)
            } else if step == PARTIAL_STEPS {
                self.prepared.intersect_level(ray, &lod.scene, &lod.set)
            } else {
                self.partial_rays += 1;
                self.prepared.intersect_partial(ray, scene, &lod.set, |o| {
                    data.tables
                        .get(o)
                        .expect("a displaced object")
                        .partial(step)
                })
            }
        };
        let color = match hit {
            None => self.prepared.scene.image.background,
            Some(hit) => match data.tables.get(hit.object) {
                None => self.lit.shade_hit(ray, hit),
                Some(tables) => {
                    let s = step as f64 / PARTIAL_STEPS as f64;
                    self.shade_surface(ray, hit, level, tables, &blend, s)
                }
            },
        };
        Shaded { color, hit, blend }
    }

    /// The colour of displaced-object hit `hit` on `ray` shaded by `blend`, its geometry
    /// displaced by fraction `s` at level of detail `level` (module docs).
    fn shade_surface(
        &mut self,
        ray: &Ray,
        hit: Hit,
        level: usize,
        tables: &ObjectTables,
        blend: &Blend,
        s: f64,
    ) -> Vec3 {
        let object = &self.level_scene(level).objects[hit.object];
        let barycentric = hit.barycentric.as_dvec2();
        let view = -ray.direction.normalize();
        let frame = SurfaceFrame::at(object, hit.triangle, barycentric, -view);
        let base = base_color(
            object,
            hit.triangle,
            hit.barycentric,
            TextureFilter::Bilinear,
        );
        let local_view = frame.local(view);
        let theta_v = local_view.z.clamp(-1.0, 1.0).acos();
        let phi_v = local_view.y.atan2(local_view.x);
        let mut bump = tables.chart.normal(frame.uv);
        bump.y *= frame.v_sign;
        let normal = if self.method == TransitionMethod::Bump {
            frame.world(bump)
        } else {
            let moved = tables.redistribution.map(
                rotate(bump, -phi_v),
                partial_view_angle(theta_v, s),
                theta_v,
            );
            frame.world(rotate(moved, phi_v))
        };
        let reflect = |to_light: DVec3| {
            let bump_term = normal.dot(to_light).max(0.0);
            let brdf_term = if blend.brdf > 0.0 {
                let light = rotate(frame.local(to_light), -phi_v);
                tables.brdf.lookup(theta_v, light)
            } else {
                0.0
            };
            (blend.brdf * brdf_term + (1.0 - blend.brdf) * bump_term) as f32
        };
        let position = ray.at(hit.t);
        let lights = &self.prepared.scene.lights;
        if lights.is_empty() {
            return base * (AMBIENT + reflect(view));
        }
        let mut color = base * AMBIENT;
        for light in lights {
            let terms = LightTerms::of(light);
            let (to_light, t_max) = terms.to_light(position);
            let radiance = terms.radiance;
            let term = reflect(to_light.normalize_or_zero());
            if term <= 0.0 {
                continue;
            }
            let mut shadow = self.prepared.spawn(position, frame.normal, to_light);
            shadow.t_max = t_max;
            self.shadow_rays += 1;
            let blocked = if s == 0.0 {
                self.prepared.occluded_hull(&shadow)
            } else if level == 0 {
                self.prepared.occluded(&shadow)
            } else {
                let lod = &self.data.expect("transition data").lods.levels[level];
                self.prepared.occluded_level(&shadow, &lod.scene, &lod.set)
            };
            if !blocked {
                color += base * radiance * term;
            }
        }
        color
    }
}
