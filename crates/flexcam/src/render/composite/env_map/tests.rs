use std::path::Path;

use glam::Vec3;

use crate::calibrate;
use crate::render::compare::compare;
use crate::render::prepared::PreparedScene;
use crate::render::{Frame, Method, RenderOptions, Shading};
use crate::scene::{self, ReflectionImage, Scene};

/// `scene` at `size` by `method` (reflectors composited) and by the ray caster's exact
/// mirror: the id agreement and relative RGB error of the whole frame, and the relative RGB
/// error over the pixels where the exact render sees object `id`.
pub(crate) fn errors(scene: &Scene, size: (u32, u32), method: Method, id: u32) -> (f64, f64, f64) {
    let (projection, _) = calibrate::build(&scene.projection, size.0, size.1).unwrap();
    let prepared = PreparedScene::new(scene);
    let render = |method, composite_reflectors| {
        let options = RenderOptions {
            method,
            composite_reflectors,
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        crate::render::render(&prepared, projection.as_ref(), &options)
            .unwrap()
            .frame
    };
    let (frame, exact) = (render(method, true), render(Method::Raycast, false));
    let whole = compare(&frame, &exact).unwrap();
    let only = |f: &Frame| {
        let color: Vec<Vec3> = (0..f.color.len())
            .filter(|&k| exact.ids[k] == id)
            .map(|k| f.color[k])
            .collect();
        Frame {
            width: color.len() as u32,
            height: 1,
            ids: vec![1; color.len()],
            depth: vec![1.0; color.len()],
            surface: Vec::new(),
            color,
        }
    };
    let reflector = compare(&only(&frame), &only(&exact)).unwrap();
    (
        whole.id_agreement,
        whole.relative_rgb_error,
        reflector.relative_rgb_error,
    )
}

fn example(name: &str) -> Scene {
    scene::load(&format!(
        "{}/../../scenes/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

fn with_env_map(mut scene: Scene) -> Scene {
    scene.trilinear_reflectors[0].reflection = ReflectionImage::EnvMap;
    scene
}

/// An environment far away (a mirror ball inside a large box of six colours) has no
/// parallax: the environment map reflects it as camera triangles do, by the ray caster or
/// by camera triangles rendering the cube map.
#[test]
fn a_distant_environment_is_reflected_as_camera_triangles_reflect_it() {
    let text = r#"
        [projection]
        type = "perspective"
        position = [0.0, 0.0, 3.0]
        look_at = [0.0, 0.0, 0.0]
        fov = 50.0
        [[object]]
        name = "ball"
        shape = "sphere"
        size = 1.0
        tessellation = 32
        material = "mirror"
        trilinear_reflector = true
        reflection = "env-map"
        [[object]]
        name = "room"
        shape = "box"
        size = [400.0, 400.0, 400.0]
        face_colors = [[0.9, 0.15, 0.1], [0.1, 0.75, 0.8], [0.2, 0.8, 0.2], [0.8, 0.2, 0.8], [0.15, 0.3, 0.9], [0.95, 0.8, 0.1]]
    "#;
    let scene = scene::file::parse(text, Path::new("room.toml")).unwrap();
    let mut surface = scene.clone();
    surface.trilinear_reflectors[0].reflection = ReflectionImage::Surface;
    for method in [Method::Raycast, Method::CameraTriangles] {
        let (_, _, env) = errors(&scene, (120, 90), method, 1);
        let (_, _, camera_triangles) = errors(&surface, (120, 90), method, 1);
        eprintln!("{method}: env map {env:.4}, camera triangles {camera_triangles:.4}");
        assert!(
            env < camera_triangles + 0.01,
            "{method}: {env} vs {camera_triangles}"
        );
    }
}

/// Nearby objects (Figure 1): on the convex and concave example scenes the environment map
/// misplaces their reflections, camera triangles do not; both against the exact mirror.
#[test]
fn nearby_objects_defeat_the_environment_map() {
    for (name, id) in [("camtri-convex", 1), ("camtri-concave", 1)] {
        let scene = example(name);
        let size = (160, 120);
        let camera_triangles = errors(&scene, size, Method::CameraTriangles, id);
        let env = errors(&with_env_map(scene), size, Method::CameraTriangles, id);
        eprintln!("{name}: camera triangles {camera_triangles:?}, env map {env:?}");
        assert!(
            env.2 > 3.0 * camera_triangles.2,
            "{name}: {env:?} {camera_triangles:?}"
        );
    }
}
