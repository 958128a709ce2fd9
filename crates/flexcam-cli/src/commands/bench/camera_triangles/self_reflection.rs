//! The reflector pixels whose exact reflection shows the reflector itself.
//!
//! A concave or mixed mirror (a torus's inner ring, a teapot's body beside its spout)
//! reflects parts of itself: the exact ray caster's reflected ray meets another part of the
//! mirror. Camera triangles render the reflection of the scene *without* the reflector
//! (the reflector's surface is the camera, not an object it sees), so there they show what
//! lies beyond, and no camera mesh size or ray rule can agree. (Near a faceted mirror's
//! silhouette the interpolated normal may lean so far that its mirror image points into
//! the facet; the ray caster lifts such a ray out of the face, `reflect_above`, so a convex
//! mirror reflects nothing of itself.) The bench
//! reports the agreement over all reflector pixels and, separately, over the pixels whose
//! exact reflection does not meet the reflector, so that the two causes of disagreement
//! (self-reflection; the reflection of the rest of the scene) are told apart.
//!
//! Found per pixel from the exact render's surface layers: the eye ray through the pixel
//! centre, reflected at the drawn point as the ray caster reflects it (`reflect_above`,
//! about the shading normal, kept out of the face), searched from that
//! point (past [`SPAWN`] world units) against the exact scene. Degenerate cases: a pixel
//! without a camera ray, without a resolved surface point or not of the reflector is not
//! marked; a reflected ray that hits nothing is not marked.

use flexcam::geometry::{reflect_above, Ray};
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
            let g = point.geometric_normal.as_dvec3().normalize();
            let reflected = reflect_above(d, n, g);
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

    /// The marks of a mirror `shape` of `size` (TOML) at `tessellation` over a floor, seen
    /// from the front and above: (marked pixels, the mirror's pixels); every mark on the
    /// mirror.
    fn marks_of(shape: &str, size: &str, tessellation: u32) -> (u64, u64) {
        let scene = scene::file::parse(
            &format!(
                r#"
[image]
width = 96
height = 72
[projection]
type = "perspective"
position = [0.0, 2.0, 3.0]
look_at = [0.0, 1.0, 0.0]
fov = 50.0
[[object]]
name = "mirror"
shape = "{shape}"
size = {size}
tessellation = {tessellation}
material = "mirror"
translate = [0.0, 1.0, 0.0]
rotate = [30.0, 0.0, 0.0]
[[object]]
name = "floor"
shape = "plane"
size = [8.0, 8.0]
"#
            ),
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
        for (k, m) in marks.iter().enumerate() {
            if *m {
                assert_eq!(frame.ids[k], id);
            }
        }
        let mirror = frame.ids.iter().filter(|i| **i == id).count() as u64;
        (marked(&marks), mirror)
    }

    /// A coarse convex ball reflects nothing of itself (the rays its rim's leaning normals
    /// would send into its facets are lifted out of them), a torus some of its own ring,
    /// but not most of its pixels.
    #[test]
    fn a_torus_reflects_itself_a_convex_ball_does_not() {
        let (ball, ball_pixels) = marks_of("sphere", "1.0", 6);
        assert!(ball_pixels > 500, "{ball_pixels}");
        assert_eq!(ball, 0);
        let (torus, torus_pixels) = marks_of("torus", "[1.0, 0.35]", 24);
        assert!(
            torus > 0 && torus < torus_pixels / 2,
            "{torus} of {torus_pixels}"
        );
    }
}
