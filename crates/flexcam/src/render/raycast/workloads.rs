//! The workload of Brosz 2011's Table 7.1 (frame time against the projectors' segment count), shared by `flexcam bench flexible
//! --part table` and the ray caster's tests of its culls, so that both use the same layout:
//! the Utah teapot tessellated to a given face count, seen through a perspective-to-
//! perspective volume of three rectangles (a small near square in front, a middle square
//! shifted up and to the right, a far square behind the model) placed around its bounding
//! box, with quadratic Bezier projectors or polylines of 2 to 6 segments.

use glam::{Affine3A, DVec3, Vec3};

use crate::error::{Error, Result};
use crate::projection::flexible::{Blend, Flexible, FlexibleSpec, Surface, VolumeSource};
use crate::projection::{CameraFrame, ProjectionSpec};
use crate::scene::{shapes, ImageSettings, Material, Mesh, Object, Scene};

/// The thesis's image size: 800 x 800.
pub const TABLE_SIZE: u32 = 800;

/// A scene of one teapot (id 1) whose triangle count is nearest `faces` among the
/// tessellations `64 n^2 - 8 n` (n x n quads per patch), and that count.
pub fn teapot_scene(faces: u32) -> (Scene, usize) {
    let count = |n: u32| 64 * n * n - 8 * n;
    let n = (1..=64)
        .min_by_key(|&n| count(n).abs_diff(faces))
        .unwrap_or(1);
    let mesh: Mesh = shapes::teapot(1.0, 4 * n);
    let used = mesh.triangle_count();
    let object = Object {
        id: 1,
        name: "teapot".to_string(),
        mesh: mesh.into(),
        material: Material {
            color: Vec3::new(0.85, 0.3, 0.2),
            ..Material::default()
        },
        world_to_object: Affine3A::IDENTITY,
        displacement: None,
    };
    let scene = Scene {
        objects: vec![object],
        lights: Vec::new(),
        trilinear_reflectors: Vec::new(),
        caustics: Vec::new(),
        motions: Vec::new(),
        inputs: Vec::new(),
        image: ImageSettings {
            width: TABLE_SIZE,
            height: TABLE_SIZE,
            background: Vec3::new(0.55, 0.7, 0.9),
            spp: 1,
        },
        projection: ProjectionSpec::Perspective {
            frame: CameraFrame {
                position: DVec3::Z,
                look_at: DVec3::ZERO,
                up: DVec3::Y,
            },
            fov: 60.0,
        },
        base_dir: None,
    };
    (scene, used)
}

/// The volume of the module documentation around `scene`'s bounding box, at `size` x `size`
/// pixels. `segments`: `None` for quadratic projectors, else polylines of that many
/// segments. Errors: an empty scene, or a volume [`Flexible::new`] refuses (0 segments).
pub fn table_volume(scene: &Scene, segments: Option<u32>, size: u32) -> Result<Flexible> {
    let (lo, hi) = scene
        .objects
        .iter()
        .filter_map(|o| o.mesh.bounds())
        .map(|(lo, hi)| (lo.as_dvec3(), hi.as_dvec3()))
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
        .ok_or_else(|| Error::new("the benchmark scene is empty"))?;
    let centre = 0.5 * (lo + hi);
    let r = 0.5 * (hi - lo).length();
    let square =
        |c: DVec3, half: f64| Surface::rectangle_centred(c, DVec3::X * half, DVec3::Y * half);
    let surfaces = vec![
        square(centre + DVec3::new(0.0, 0.0, 4.0 * r), 0.1 * r),
        square(centre + DVec3::new(0.4 * r, 0.3 * r, r), 0.9 * r),
        square(centre + DVec3::new(0.0, 0.0, -2.0 * r), 1.3 * r),
    ];
    let spec = FlexibleSpec {
        source: VolumeSource::Blended {
            surfaces,
            blend: Blend::Bezier { segments },
        },
        reparam: None,
    };
    Flexible::new(&spec, size, size)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::Projection;

    #[test]
    fn teapots_take_the_nearest_tessellation_and_empty_scenes_have_no_volume() {
        // 64 n^2 - 8 n: 56, 240, 552, 2256 for n = 1, 2, 3, 6.
        assert_eq!(teapot_scene(520).1, 552);
        assert_eq!(teapot_scene(2256).1, 2256);
        assert_eq!(teapot_scene(0).1, 56);
        let (mut scene, _) = teapot_scene(240);
        let volume = table_volume(&scene, Some(3), 16).unwrap();
        assert_eq!(volume.resolution(), (16, 16));
        scene.objects.clear();
        let error = table_volume(&scene, None, 16).unwrap_err().to_string();
        assert!(error.contains("empty"), "{error}");
    }
}
