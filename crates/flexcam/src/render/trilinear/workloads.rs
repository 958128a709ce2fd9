//! The scenes and projection meshes of the timing study of Vallance 2005 (chapter 8, appendix D),
//! shared by `flexcam bench trilinear` and the criterion benches, so that both time the same
//! work.
//!
//! - [`fan_grid`]: a regular screen grid of `2 cells^2` projection triangles over a bent base
//!   patch near (0, 1, 5) whose rays fan out over 100 x 70 degrees looking along -z, with
//!   lengths growing to the right: the projection the renderer's accuracy tests use on the
//!   cube-floor scene (the thesis's cube scene through 2, 8, 18, 32, 50 projections).
//! - [`random_grid`] and [`random_triangles`]: the thesis's random data (8.1.1): "random
//!   points and normals corresponding to a regular mesh on screen space", and disconnected
//!   vertex-coloured triangles "constrained such that some of the scene triangle should be
//!   rendered on the screen". Both are seeded and deterministic (`SplitMix64`).

use glam::{Affine3A, DVec2, DVec3, Vec3};

use crate::error::Result;
use crate::projection::trilinear_builders::{screen_grid, GridVertex};
use crate::projection::{CameraFrame, ProjectionSpec, TrilinearMesh};
use crate::scene::{ImageSettings, Material, Mesh, Object, Scene};

/// The fan projection of the module doc, `cells x cells` screen cells. Errors: `cells`
/// outside the grid's accepted range.
pub fn fan_grid(cells: u32) -> Result<TrilinearMesh> {
    screen_grid(cells, |s| {
        let bend = 0.3 * (s.x - 0.5) * (s.x - 0.5) + 0.1 * s.y * s.y;
        let (lon, lat) = (
            (s.x - 0.5) * 100f64.to_radians(),
            (s.y - 0.5) * 70f64.to_radians(),
        );
        let direction = DVec3::new(lon.sin() * lat.cos(), lat.sin(), -lon.cos() * lat.cos());
        GridVertex {
            point: DVec3::new(-0.2 + 0.4 * s.x, 0.85 + 0.3 * s.y, 5.0 + bend),
            direction: direction * (1.0 + 0.3 * s.x),
        }
    })
}

/// The nominal (unjittered) ray of screen position `s` of the random data: base points on the
/// square `[-1, 1]^2` of the plane `z = 0`, directions spreading by 0.6 per unit towards -z
/// (a 62-degree field of view).
fn nominal_vertex(s: DVec2) -> GridVertex {
    let c = 2.0 * s - DVec2::ONE;
    GridVertex {
        point: DVec3::new(c.x, c.y, 0.0),
        direction: DVec3::new(0.6 * c.x, 0.6 * c.y, -1.0),
    }
}

/// A regular screen grid of `cells x cells` cells whose base points and directions are the
/// nominal ones jittered at random (points by up to 0.1, directions by up to 0.15 per
/// component), seeded by `seed`. Errors: `cells` outside the grid's accepted range.
pub fn random_grid(cells: u32, seed: u64) -> Result<TrilinearMesh> {
    let rng = std::cell::RefCell::new(SplitMix64::new(seed));
    screen_grid(cells, |s| {
        let mut rng = rng.borrow_mut();
        let nominal = nominal_vertex(s);
        GridVertex {
            point: nominal.point + 0.1 * rng.in_cube(),
            direction: nominal.direction + 0.15 * rng.in_cube(),
        }
    })
}

/// `count` disconnected triangles with random vertex colours, each around a point on the
/// nominal ray of a random screen position at a random depth 2 to 8, with vertices up to 0.3
/// times that depth away from it (so that some of each triangle is on screen), seeded by
/// `seed`; one object (id 1), flat-shaded through its vertex colours.
pub fn random_triangles(count: u32, seed: u64) -> Scene {
    let mut rng = SplitMix64::new(seed);
    let mut mesh = Mesh::default();
    for k in 0..count {
        let screen = DVec2::new(rng.unit(), rng.unit());
        let ray = nominal_vertex(screen);
        let depth = 2.0 + 6.0 * rng.unit();
        let centre = ray.point + depth * ray.direction;
        for _ in 0..3 {
            let corner = centre + 0.3 * depth * rng.in_cube();
            mesh.positions.push(corner.as_vec3());
            mesh.colors.push(Vec3::new(
                rng.unit() as f32,
                rng.unit() as f32,
                rng.unit() as f32,
            ));
        }
        mesh.triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    Scene {
        objects: vec![Object {
            id: 1,
            name: "random triangles".to_string(),
            mesh: mesh.into(),
            material: Material::default(),
            world_to_object: Affine3A::IDENTITY,
            displacement: None,
        }],
        lights: Vec::new(),
        image: ImageSettings {
            width: 640,
            height: 640,
            background: Vec3::ZERO,
            spp: 1,
        },
        projection: ProjectionSpec::Perspective {
            frame: CameraFrame {
                position: DVec3::ZERO,
                look_at: -DVec3::Z,
                up: DVec3::Y,
            },
            fov: 62.0,
        },
        base_dir: None,
        trilinear_reflectors: Vec::new(),
        caustics: Vec::new(),
        motions: Vec::new(),
        inputs: Vec::new(),
    }
}

/// A small seeded generator (SplitMix64): reproducible benchmark data without a dependency.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// The generator started at `seed`.
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in the cube `[-1, 1)^3`.
    pub fn in_cube(&mut self) -> DVec3 {
        DVec3::new(self.unit(), self.unit(), self.unit()) * 2.0 - DVec3::ONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::Trilinear;

    #[test]
    fn meshes_have_the_thesis_projection_counts_and_valid_rays() {
        for (cells, triangles) in [(1, 2), (2, 8), (3, 18), (4, 32), (5, 50)] {
            for mesh in [fan_grid(cells).unwrap(), random_grid(cells, 7).unwrap()] {
                assert_eq!(mesh.triangles.len(), triangles);
                assert!(Trilinear::new(&mesh, 64, 64).is_ok());
            }
        }
        assert!(fan_grid(0).is_err());
    }

    #[test]
    fn random_data_is_reproducible_and_disconnected() {
        let (a, b) = (random_triangles(50, 3), random_triangles(50, 3));
        assert_eq!(a.objects[0].mesh.positions, b.objects[0].mesh.positions);
        assert_ne!(
            a.objects[0].mesh.positions,
            random_triangles(50, 4).objects[0].mesh.positions
        );
        let mesh = &a.objects[0].mesh;
        assert_eq!(mesh.triangle_count(), 50);
        assert_eq!(mesh.positions.len(), 150);
        assert!(mesh.validate().is_ok());
        let mut rng = SplitMix64::new(1);
        assert!((0..1000)
            .map(|_| rng.unit())
            .all(|x| (0.0..1.0).contains(&x)));
    }
}
