//! The reflector pixels whose exact reflection shows the reflector itself.
//!
//! A faceted mirror with interpolated vertex normals reflects some eye rays *into* itself:
//! near its silhouette the interpolated normal leans so far from the facet's that the
//! reflected ray points below the facet's plane (or, on a concave or mixed reflector, it
//! meets another part of the mirror). The exact ray caster follows such a ray into the
//! mirror; on a closed convex mesh it can never leave again and ends as the background
//! after the last bounce. Camera triangles render the reflection of the scene *without*
//! the reflector (the reflector's surface is the camera, not an object it sees), so there
//! they show what lies beyond, and no camera mesh size or ray rule can agree. The bench
//! reports the agreement over all reflector pixels and, separately, over the pixels whose
//! exact reflection does not meet the reflector, so that the two causes of disagreement
//! (self-reflection; the reflection of the rest of the scene) are told apart.
//!
//! Found per pixel from the exact render's surface layers: the eye ray through the pixel
//! centre, reflected about the shading normal at the drawn point, searched from that
//! point (past [`SPAWN`] world units) against the exact scene. Degenerate cases: a pixel
//! without a camera ray, without a resolved surface point or not of the reflector is not
//! marked; a reflected ray that hits nothing is not marked.

use flexcam::geometry::Ray;
use flexcam::projection::Projection;
use flexcam::render::{Frame, PreparedScene, SurfacePoint};
use glam::{DVec2, Vec3};

/// How far along the reflected ray the search starts, in world units: past the f32
/// rounding of the surface point (the bench's scenes span about ten units, so rounding is
/// below 1e-6) and far shorter than any path to another facet of a mirror.
const SPAWN: f64 = 1e-4;

/// For each pixel of `reference` (rendered through `main` from `exact`, with its surface
/// layers), whether it shows the object of index `reflector` (id `id`) and the ray
/// reflected there meets that object again.
pub fn self_reflected_pixels(
    exact: &PreparedScene,
    main: &dyn Projection,
    reference: &Frame,
    reflector: usize,
    id: u32,
) -> Vec<bool> {
    let width = reference.width as usize;
    (0..reference.ids.len())
        .map(|k| {
            if reference.ids[k] != id {
                return false;
            }
            let point = reference
                .surface
                .get(k)
                .copied()
                .unwrap_or(SurfacePoint::NONE);
            if point.normal == Vec3::ZERO {
                return false;
            }
            let pixel = DVec2::new((k % width) as f64, (k / width) as f64) + 0.5;
            let Some(eye) = main.ray(pixel) else {
                return false;
            };
            let d = eye.direction.normalize();
            let n = point.normal.as_dvec3().normalize();
            let reflected = d - 2.0 * d.dot(n) * n;
            let mut ray = Ray::new(point.position.as_dvec3(), reflected);
            ray.t_min = SPAWN;
            exact
                .intersect(&ray)
                .is_some_and(|hit| hit.object == reflector)
        })
        .collect()
}

/// The number of marked pixels.
pub fn marked(marks: &[bool]) -> u64 {
    marks.iter().filter(|m| **m).count() as u64
}

#[cfg(test)]
mod tests {
    use flexcam::render::{self, Outputs, RenderOptions, Shading};
    use flexcam::scene;

    use super::*;

    /// A coarse mirror ball over a floor: only the ball's pixels can be marked, some near
    /// its silhouette are (their reflected rays go below the facets), and none near the
    /// centre of its image (the eye ray meets the ball head on and goes back).
    #[test]
    fn a_coarse_ball_reflects_itself_near_its_silhouette_only() {
        let scene = scene::file::parse(
            r#"
[image]
width = 96
height = 72
[projection]
type = "perspective"
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
fov = 50.0
[[object]]
name = "ball"
shape = "sphere"
size = 1.0
tessellation = 6
material = "mirror"
translate = [0.0, 1.0, 0.0]
[[object]]
name = "floor"
shape = "plane"
size = [8.0, 8.0]
"#,
            std::path::Path::new("test"),
        )
        .unwrap();
        let prepared = PreparedScene::new(&scene);
        let main = scene.projection.build(96, 72).unwrap();
        let options = RenderOptions {
            shading: Shading::Flat,
            outputs: Outputs {
                surface: true,
                ..Outputs::ALL
            },
            ..RenderOptions::default()
        };
        let frame = render::render(&prepared, main.as_ref(), &options)
            .unwrap()
            .frame;
        let id = scene.objects[0].id;
        let marks = self_reflected_pixels(&prepared, main.as_ref(), &frame, 0, id);
        let ball = frame.ids.iter().filter(|i| **i == id).count() as u64;
        let n = marked(&marks);
        assert!(n > 0 && n < ball / 4, "{n} of {ball}");
        for (k, m) in marks.iter().enumerate() {
            if *m {
                assert_eq!(frame.ids[k], id);
            }
        }
        // The image centre sees the ball head on.
        assert!(!marks[36 * 96 + 48]);
    }
}
