//! The trilinear projection (seed 000) as a ray generator: a mesh of projection triangles
//! whose screen triangles tile (part of) the image.
//!
//! Vertex k has base point p_k, ray direction n_k and screen position S_k. A screen point at
//! barycentrics (u, v) of a triangle's screen triangle emits the ray
//! tripoint(u, v) + t * trinorm(u, v), t >= 0, where tripoint and trinorm interpolate the
//! p_k and n_k linearly (trinorm is never renormalised: its length is the depth scale).
//! The inverse (a cubic per triangle) belongs to the trilinear renderer: `has_inverse` is
//! false here.

mod obj;
mod screen_locator;

use glam::{DVec2, DVec3};

use super::image_coords::Resolution;
use super::{Projection, TrilinearMesh};
use crate::error::{Error, Result};
use crate::geometry::Ray;
use screen_locator::ScreenLocator;

/// A screen triangle counts as degenerate when twice its area is below this fraction of the
/// product of its two edge lengths from the first vertex (the sine of its angle there).
const DEGENERATE_SINE: f64 = 1e-12;

/// A validated trilinear mesh bound to an image size.
#[derive(Debug, Clone, PartialEq)]
pub struct Trilinear {
    mesh: TrilinearMesh,
    locator: ScreenLocator,
    resolution: Resolution,
}

impl Trilinear {
    /// Validates `mesh` and prepares the screen lookup. Errors: an empty image; no
    /// triangles; `points`, `normals` and `screen` of different lengths; a vertex index out
    /// of range; a non-finite value; a zero-length normal; a zero-area (degenerate) screen
    /// triangle. Screen triangles may overlap (the lowest index wins) and have either
    /// orientation; screen positions outside [0,1]^2 simply fall outside the image.
    pub fn new(mesh: &TrilinearMesh, width: u32, height: u32) -> Result<Self> {
        let resolution = Resolution::new(width, height)?;
        validate(mesh)?;
        let screen_triangles = mesh
            .triangles
            .iter()
            .map(|t| t.map(|k| mesh.screen[k as usize]))
            .collect();
        Ok(Trilinear {
            mesh: mesh.clone(),
            locator: ScreenLocator::new(screen_triangles),
            resolution,
        })
    }

    /// The projection mesh.
    pub fn mesh(&self) -> &TrilinearMesh {
        &self.mesh
    }
}

fn validate(mesh: &TrilinearMesh) -> Result<()> {
    if mesh.triangles.is_empty() {
        return Err(Error::new("trilinear projection has no triangles"));
    }
    let count = mesh.points.len();
    if mesh.normals.len() != count || mesh.screen.len() != count {
        return Err(Error::new(format!(
            "trilinear points, normals and screen must have the same length, got {}, {} and {}",
            count,
            mesh.normals.len(),
            mesh.screen.len()
        )));
    }
    for k in 0..count {
        let finite =
            mesh.points[k].is_finite() && mesh.normals[k].is_finite() && mesh.screen[k].is_finite();
        if !finite {
            return Err(Error::new(format!(
                "trilinear vertex {k} has a non-finite point, normal or screen value"
            )));
        }
        if mesh.normals[k] == DVec3::ZERO {
            return Err(Error::new(format!(
                "trilinear normal {k} has zero length: every vertex needs a ray direction"
            )));
        }
    }
    for (index, triangle) in mesh.triangles.iter().enumerate() {
        if let Some(&k) = triangle.iter().find(|&&k| k as usize >= count) {
            return Err(Error::new(format!(
                "trilinear triangle {index} refers to vertex {k}, \
                 but there are only {count} vertices"
            )));
        }
        let [a, b, c] = triangle.map(|k| mesh.screen[k as usize]);
        let (e1, e2) = (b - a, c - a);
        if e1.perp_dot(e2).abs() <= DEGENERATE_SINE * e1.length() * e2.length() {
            return Err(Error::new(format!(
                "trilinear triangle {index} has a zero-area (degenerate) screen triangle"
            )));
        }
    }
    Ok(())
}

impl Projection for Trilinear {
    fn kind(&self) -> &'static str {
        "trilinear"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    /// Pixel (x, y) is screen (x / W, 1 - y / H). `None` where no screen triangle covers it,
    /// and where the interpolated direction trinorm is exactly zero (possible inside a
    /// triangle whose normals point in opposing directions: the projector is a single point).
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let size = self.resolution.size();
        let screen = DVec2::new(pixel.x / size.x, 1.0 - pixel.y / size.y);
        let hit = self.locator.locate(screen)?;
        let [i, j, k] = self.mesh.triangles[hit.triangle].map(|k| k as usize);
        let w = 1.0 - hit.u - hit.v;
        let interpolate = |values: &[DVec3]| w * values[i] + hit.u * values[j] + hit.v * values[k];
        let direction = interpolate(&self.mesh.normals);
        if direction == DVec3::ZERO {
            return None;
        }
        Some(Ray::new(interpolate(&self.mesh.points), direction))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::linear::Perspective;
    use crate::projection::CameraFrame;

    /// A 2 x 2 quad grid (8 triangles) on the image plane at distance 1 in front of `eye`
    /// (looking down -z), with n_k = p_k - eye: a pinhole camera with horizontal half-angle
    /// tangent `half_w` and vertical `half_h`.
    fn pinhole_mesh(eye: DVec3, half_w: f64, half_h: f64) -> TrilinearMesh {
        let mut mesh = TrilinearMesh::default();
        for j in 0..3 {
            for i in 0..3 {
                let s = DVec2::new(i as f64, j as f64) / 2.0;
                let p =
                    eye + DVec3::new((2.0 * s.x - 1.0) * half_w, (2.0 * s.y - 1.0) * half_h, -1.0);
                mesh.points.push(p);
                mesh.normals.push(p - eye);
                mesh.screen.push(s);
            }
        }
        for j in 0..2u32 {
            for i in 0..2u32 {
                let a = j * 3 + i;
                mesh.triangles.push([a, a + 1, a + 4]);
                mesh.triangles.push([a, a + 4, a + 3]);
            }
        }
        mesh
    }

    #[test]
    fn pinhole_mesh_matches_the_perspective_projection() {
        let eye = DVec3::new(0.5, 1.0, 4.0);
        let (width, height) = (64, 48);
        let fov = 70.0_f64;
        let half_w = (0.5 * fov.to_radians()).tan();
        let half_h = half_w * f64::from(height) / f64::from(width);
        let trilinear = Trilinear::new(&pinhole_mesh(eye, half_w, half_h), width, height).unwrap();
        let frame = CameraFrame {
            position: eye,
            look_at: eye + DVec3::NEG_Z,
            up: DVec3::Y,
        };
        let perspective = Perspective::new(&frame, fov, width, height).unwrap();
        for y in 0..height {
            for x in 0..width {
                let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let tri = trilinear.ray(pixel).unwrap();
                let persp = perspective.ray(pixel).unwrap();
                let direction = tri.direction.normalize();
                assert!(
                    (direction - persp.direction).length() < 1e-12,
                    "pixel {pixel}"
                );
                // The origin lies on the perspective ray, one unit of trinorm from the eye.
                assert!((tri.origin - tri.direction - eye).length() < 1e-12);
            }
        }
    }

    #[test]
    fn covering_mesh_leaves_no_cracks() {
        // Every pixel centre and every pixel corner (which lie on the shared edges and
        // vertices of the 2 x 2 grid for even sizes) gets exactly one ray.
        let mesh = pinhole_mesh(DVec3::ZERO, 1.0, 1.0);
        let trilinear = Trilinear::new(&mesh, 16, 16).unwrap();
        for y in 0..32 {
            for x in 0..32 {
                let pixel = DVec2::new(f64::from(x), f64::from(y)) * 0.5;
                assert!(trilinear.ray(pixel).is_some(), "crack at {pixel}");
            }
        }
        assert!(
            trilinear.ray(DVec2::new(16.0, 3.0)).is_none(),
            "right edge is outside"
        );
        assert!(
            trilinear.ray(DVec2::new(3.0, 16.0)).is_none(),
            "bottom edge is outside"
        );
    }

    #[test]
    fn uncovered_pixels_and_zero_directions_see_nothing() {
        let mesh = TrilinearMesh {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: vec![DVec3::Z, DVec3::NEG_Z, DVec3::Z],
            screen: vec![DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)],
            triangles: vec![[0, 1, 2]],
        };
        let t = Trilinear::new(&mesh, 10, 10).unwrap();
        assert!(
            t.ray(DVec2::new(9.5, 0.5)).is_none(),
            "upper-right half is uncovered"
        );
        // Where u = 1/2 the interpolated normal (1 - 2u) z vanishes.
        assert!(t.ray(DVec2::new(5.0, 7.5)).is_none());
        assert!(t.ray(DVec2::new(5.5, 7.5)).is_some());
        let r = t.ray(DVec2::new(2.0, 8.0)).unwrap();
        assert!((r.origin - DVec3::new(0.2, 0.2, 0.0)).length() < 1e-12);
        assert!(
            (r.direction - DVec3::new(0.0, 0.0, 0.6)).length() < 1e-12,
            "not renormalised"
        );
    }

    fn triangle_mesh() -> TrilinearMesh {
        TrilinearMesh {
            points: vec![DVec3::ZERO; 3],
            normals: vec![DVec3::Z; 3],
            screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
            triangles: vec![[0, 1, 2]],
        }
    }

    fn error_of(mesh: TrilinearMesh) -> String {
        Trilinear::new(&mesh, 8, 8).unwrap_err().message
    }

    #[test]
    fn validation_errors() {
        assert!(Trilinear::new(&triangle_mesh(), 8, 8).is_ok());
        assert!(Trilinear::new(&triangle_mesh(), 0, 8).is_err());
        let mut m = triangle_mesh();
        m.triangles.clear();
        assert_eq!(error_of(m), "trilinear projection has no triangles");
        let mut m = triangle_mesh();
        m.normals.pop();
        assert!(error_of(m).contains("same length, got 3, 2 and 3"));
        let mut m = triangle_mesh();
        m.triangles[0][1] = 7;
        assert!(error_of(m).contains("triangle 0 refers to vertex 7"));
        let mut m = triangle_mesh();
        m.normals[2] = DVec3::ZERO;
        assert!(error_of(m).contains("normal 2 has zero length"));
        let mut m = triangle_mesh();
        m.points[1].y = f64::NAN;
        assert!(error_of(m).contains("vertex 1 has a non-finite"));
        let mut m = triangle_mesh();
        m.screen[0] = DVec2::new(f64::INFINITY, 0.0);
        assert!(error_of(m).contains("vertex 0 has a non-finite"));
        let mut m = triangle_mesh();
        m.triangles.push([0, 1, 1]);
        assert!(error_of(m).contains("triangle 1 has a zero-area"));
        let mut m = triangle_mesh();
        m.screen[2] = DVec2::new(0.5, 0.0); // collinear
        assert!(error_of(m).contains("triangle 0 has a zero-area"));
    }
}
