//! The surface layers of a rendered frame: for each pixel, the normals, world position and
//! texture coordinates of the surface the method drew there ([`SurfacePoint`]).
//!
//! They are derived after rendering, from the frame's own object ids and depth, the same
//! way for every method: the pixel's projector (through the sample whose depth and id the
//! pixel reports) is searched again against the object of the pixel's id alone, and its
//! first hit is taken if it lies at the pixel's depth. So the layers describe the surface
//! the method drew, never a surface a fresh ray cast of the scene would pick instead, and
//! no renderer does any per-pixel work for them unless they are asked for
//! ([`crate::render::Outputs::surface`]). For `--method raycast` the search repeats the
//! caster's own (same projector, same object), so the layers are those of its hit.
//!
//! Degenerate cases: a background pixel (id 0), and a pixel whose projector does not meet
//! its object within [`DEPTH_TOLERANCE`] of its depth (a rasteriser's pixel at a silhouette,
//! where its polygonal approximation covers the pixel and the exact object does not), get
//! [`SurfacePoint::NONE`]; the latter are counted (`surface_unresolved`).

use std::collections::BTreeSet;

use glam::{DVec2, Vec2, Vec3};
use rayon::prelude::*;

use super::raycast::{first_hit, ProjectorHit, SamplePattern};
use super::shading::{normals, texture_coordinates, Normals};
use crate::error::Result;
use crate::projection::Projection;
use crate::render::{frame_name, Frame, PixelWindow, PreparedScene};
use crate::scene::Mesh;
use crate::try_alloc;

/// What a pixel shows, in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// The unit shading normal the lit shader uses (interpolated vertex normals, or the face
    /// normal; a displaced object's micro-triangle normal), turned towards the viewer: to
    /// the side the projector arrives from.
    pub normal: Vec3,
    /// The unit face normal of the triangle hit, turned towards the viewer.
    pub geometric_normal: Vec3,
    /// The hit point.
    pub position: Vec3,
    /// The texture coordinates there, interpolated from the mesh's vertices (0, 0 for a
    /// mesh without texture coordinates, as textures are sampled).
    pub uv: Vec2,
}

impl SurfacePoint {
    /// A pixel that shows no surface: zero normals (not unit vectors, so never mistaken for
    /// one), NaN position and texture coordinates.
    pub const NONE: SurfacePoint = SurfacePoint {
        normal: Vec3::ZERO,
        geometric_normal: Vec3::ZERO,
        position: Vec3::NAN,
        uv: Vec2::NAN,
    };
}

/// How far, relative to the pixel's depth, the object's hit may lie from it and still be the
/// surface the method drew: 1e-3, well above the f32 rounding of the stored depth (about
/// 1e-7) and of the rasterisers' depth interpolation, and well below the depth step between
/// two layers of one object along a projector anywhere but at a grazing fold.
pub const DEPTH_TOLERANCE: f64 = 1e-3;

/// The surface layers of `frame`, which is `window` of `projection`'s image rendered from
/// `prepared` with `spp` samples (its depth and ids filled), and how many pixels with an
/// object id had no surface at their depth (see the module documentation). Fails when the
/// layers' memory cannot be had (module `try_alloc`).
pub(super) fn layers(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    frame: &Frame,
    window: PixelWindow,
    spp: u32,
) -> Result<(Vec<SurfacePoint>, u64)> {
    let objects = &prepared.scene().objects;
    // One view per object the frame shows, hiding every other object (sharing the BVH).
    let shown = frame
        .ids
        .par_iter()
        .filter(|&&id| id != 0)
        .fold(BTreeSet::new, |mut ids, &id| {
            ids.insert(id);
            ids
        })
        .reduce(BTreeSet::new, |mut a, b| {
            a.extend(b);
            a
        });
    let views: Vec<(u32, Option<PreparedScene>)> = shown
        .into_iter()
        .map(|id| {
            let index = objects.iter().position(|o| o.id == id);
            (id, index.map(|index| alone(prepared, index)))
        })
        .collect();
    let pattern = SamplePattern::new(spp);
    let offset = pattern.offsets[pattern.centre];
    let width = frame.width as usize;
    let mut points = try_alloc::filled(frame.ids.len(), SurfacePoint::NONE, || {
        format!(
            "the surface layers of {}",
            frame_name(frame.width, frame.height)
        )
    })?;
    let unresolved = points
        .par_iter_mut()
        .enumerate()
        .map(|(i, point)| {
            let id = frame.ids[i];
            if id == 0 {
                return 0;
            }
            let view = views
                .binary_search_by_key(&id, |(id, _)| *id)
                .ok()
                .and_then(|k| views[k].1.as_ref());
            let pixel = DVec2::new(
                (window.x0 as usize + i % width) as f64,
                (window.y0 as usize + i / width) as f64,
            ) + offset;
            let found = view.and_then(|view| {
                let found = first_hit(view, &projection.projector(pixel)?)?;
                let depth = frame.depth[i] as f64;
                ((found.depth - depth).abs() <= DEPTH_TOLERANCE * depth)
                    .then(|| surface_point(view, &found))
            });
            match found {
                Some(found) => {
                    *point = found;
                    0
                }
                None => 1,
            }
        })
        .sum();
    Ok((points, unresolved))
}

/// A view of `prepared` showing object `index` alone.
fn alone(prepared: &PreparedScene, index: usize) -> PreparedScene {
    let mut scene = prepared.scene().clone();
    let empty = std::sync::Arc::new(Mesh::default());
    for (k, object) in scene.objects.iter_mut().enumerate() {
        if k != index {
            object.mesh = empty.clone();
        }
    }
    prepared.view(scene)
}

/// The surface at `found`, a hit in `view`.
fn surface_point(view: &PreparedScene, found: &ProjectorHit) -> SurfacePoint {
    let hit = &found.hit;
    let object = &view.scene().objects[hit.object];
    let incoming = found.ray.direction.as_vec3();
    let Normals {
        geometric, shading, ..
    } = match view.displaced_face_normal(hit) {
        Some(face) => Normals::of_face(face, incoming),
        None => normals(object, hit.triangle, hit.barycentric, incoming),
    };
    SurfacePoint {
        normal: shading,
        geometric_normal: geometric,
        position: found.point().as_vec3(),
        uv: texture_coordinates(object, hit.triangle, hit.barycentric),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{pick, render, Counter, Method, Outputs, RenderOptions, Shading};
    use crate::scene;

    fn options(method: Method) -> RenderOptions<'static> {
        RenderOptions {
            method,
            shading: Shading::Flat,
            composite_reflectors: false,
            outputs: Outputs {
                depth: false,
                ids: true,
                surface: true,
                atlases: false,
            },
            ..RenderOptions::default()
        }
    }

    fn scene_file(name: &str) -> scene::Scene {
        scene::load(&format!(
            "{}/../../scenes/{name}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap()
    }

    /// The ray caster's layers are its own hits: the position is the point `pick` (the
    /// caster's search) finds through the pixel centre, the normal the shader's.
    #[test]
    fn raycast_layers_are_its_hits() {
        let scene = scene::load("builtin:cube-floor").unwrap();
        let projection = scene.projection.build(40, 40).unwrap();
        let prepared = PreparedScene::new(&scene);
        let rendered = render(&prepared, projection.as_ref(), &options(Method::Raycast)).unwrap();
        let frame = &rendered.frame;
        assert!(frame.depth.is_empty(), "depth was not asked for");
        assert_eq!(frame.surface.len(), 40 * 40);
        for (i, point) in frame.surface.iter().enumerate() {
            let pixel = DVec2::new((i % 40) as f64 + 0.5, (i / 40) as f64 + 0.5);
            match pick(&prepared, projection.as_ref(), pixel) {
                Some(picked) => {
                    assert_eq!(frame.ids[i], objects_id(&scene, picked.object));
                    assert_eq!(point.position, picked.point.as_vec3(), "pixel {i}");
                    assert!((point.normal.length() - 1.0).abs() < 1e-6);
                }
                None => assert_eq!(point.normal, Vec3::ZERO),
            }
        }
        assert!(matches!(
            rendered.counters["surface_unresolved"],
            crate::render::Counter::Count(0)
        ));
    }

    fn objects_id(scene: &scene::Scene, index: usize) -> u32 {
        scene.objects[index].id
    }

    /// Asserts that `methods` draw the surfaces the ray caster does on scene file `name` at
    /// `w` x `h`, away from id edges (where the methods may draw different objects).
    fn assert_methods_draw_the_ray_casters_surfaces(
        name: &str,
        (w, h): (usize, usize),
        methods: &[Method],
    ) {
        let scene = scene_file(name);
        let projection = scene.projection.build(w as u32, h as u32).unwrap();
        let prepared = PreparedScene::new(&scene);
        let frame = |method| {
            let rendered = render(&prepared, projection.as_ref(), &options(method)).unwrap();
            let unresolved = rendered.counters["surface_unresolved"];
            (rendered.frame, unresolved)
        };
        let (reference, _) = frame(Method::Raycast);
        let ids = &reference.ids;
        let inner = |i: usize| {
            let (x, y) = (i % w, i / w);
            (1..w - 1).contains(&x)
                && (1..h - 1).contains(&y)
                && [i - 1, i + 1, i - w, i + w]
                    .iter()
                    .all(|&j| ids[j] == ids[i])
        };
        for &method in methods {
            let (other, unresolved) = frame(method);
            let same = |i: &usize| ids[*i] != 0 && other.ids[*i] == ids[*i] && inner(*i);
            let mut compared = 0;
            for i in (0..ids.len()).filter(same) {
                let (a, b) = (reference.surface[i], other.surface[i]);
                let scale = a.position.length().max(1.0);
                let what = format!("{name} {method} pixel {i}: {a:?} {b:?}");
                assert!(a.position.distance(b.position) < 1e-3 * scale, "{what}");
                assert!(a.normal.dot(b.normal) > 0.9999, "{what}");
                assert!(a.uv.distance(b.uv) < 1e-3, "{what}");
                compared += 1;
            }
            assert!(compared > ids.len() / 4, "{name} {method}: {compared}");
            assert!(matches!(unresolved, Counter::Count(0)), "{name} {method}");
        }
    }

    /// The trilinear methods' layers describe the surfaces the ray caster's do on a
    /// trilinear projection (raster is compared in the CLI test `surface_layers`).
    #[test]
    fn every_method_draws_the_ray_casters_surfaces() {
        assert_methods_draw_the_ray_casters_surfaces(
            "trilinear-fan.toml",
            (90, 60),
            &[Method::Trilinear, Method::CameraTriangles],
        );
    }

    /// A crop's layers are that window of the whole frame's, bit for bit; asking for them
    /// changes neither colour, depth nor ids.
    #[test]
    fn crops_cut_the_layers_and_the_other_buffers_do_not_change() {
        let scene = scene_file("reflect-sphere-cube.toml");
        let projection = scene.projection.build(32, 24).unwrap();
        let prepared = PreparedScene::new(&scene);
        for (method, composite_reflectors) in [(Method::Raycast, false), (Method::Raster, false)] {
            let options = |outputs, crop| RenderOptions {
                method,
                composite_reflectors,
                outputs,
                crop,
                ..RenderOptions::default()
            };
            let all = Outputs {
                surface: true,
                ..Outputs::ALL
            };
            let whole = render(&prepared, projection.as_ref(), &options(all, None)).unwrap();
            let plain = render(&prepared, projection.as_ref(), &options(Outputs::ALL, None));
            let plain = plain.unwrap().frame;
            assert!(plain.surface.is_empty());
            assert_eq!(
                (&plain.color, &plain.depth, &plain.ids),
                (&whole.frame.color, &whole.frame.depth, &whole.frame.ids)
            );
            let window = PixelWindow {
                x0: 5,
                y0: 3,
                x1: 29,
                y1: 20,
            };
            let crop = render(&prepared, projection.as_ref(), &options(all, Some(window)));
            let bits = |points: &[SurfacePoint]| -> Vec<[u32; 11]> {
                points
                    .iter()
                    .map(|p| {
                        let v = [p.normal, p.geometric_normal, p.position];
                        let f = v.map(|v| v.to_array()).concat();
                        std::array::from_fn(|k| if k < 9 { f[k] } else { p.uv[k - 9] }.to_bits())
                    })
                    .collect()
            };
            assert_eq!(
                bits(&crop.unwrap().frame.surface),
                bits(&window.cut(&whole.frame).unwrap().surface),
                "{method}"
            );
        }
    }
}
