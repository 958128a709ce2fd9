//! Test fixtures shared by the reflector-surface tests and the compositing tests
//! (`render::composite`): the thesis's sphere-reflects-cube scene (7.4) and its lens plane
//! (Figure 7.6), so that both test suites look at the same reflectors.

use std::path::Path;

use glam::Vec3;

use crate::projection::{Perspective, ProjectionSpec};
use crate::scene::{file, Mesh, Scene};

/// Object id of the mirror sphere in [`sphere_and_cube`].
pub const BALL: u32 = 1;

/// Centre of the mirror sphere (radius 1) in [`sphere_and_cube`].
pub const BALL_CENTER: glam::DVec3 = glam::DVec3::new(0.0, 1.0, 0.0);

/// A fixture scene, described by what differs between the fixtures; the rest is shared: the
/// sky-blue background, a 60-degree perspective camera, a cube with six face colours and a
/// 12 x 12 m checker floor (colours 0.9 and 0.1). Object 1 is the reflector.
pub struct ReflectorFixture<'a> {
    /// The camera's eye.
    pub eye: [f64; 3],
    /// The point the camera looks at.
    pub look_at: [f64; 3],
    /// The lines of object 1's `[[object]]` table: the reflector.
    pub reflector: &'a str,
    /// The lines of the cube's `[[object]]` table besides its shape and face colours: its
    /// size and placement.
    pub cube: &'a str,
    /// The edge of the floor's checker cells, in metres.
    pub cell: f64,
}

impl ReflectorFixture<'_> {
    /// The scene, parsed as if from the file `name`.
    pub fn scene(&self, name: &str) -> Scene {
        let ReflectorFixture {
            eye,
            look_at,
            reflector,
            cube,
            cell,
        } = self;
        let text = format!(
            r#"
            [image]
            background = [0.3, 0.4, 0.6]
            [projection]
            type = "perspective"
            position = {eye:?}
            look_at = {look_at:?}
            fov = 60.0
            [[object]]
            {reflector}
            [[object]]
            shape = "box"
            face_colors = [[0.9, 0.15, 0.1], [0.1, 0.75, 0.8], [0.2, 0.8, 0.2],
                           [0.8, 0.2, 0.8], [0.15, 0.3, 0.9], [0.95, 0.8, 0.1]]
            {cube}
            [[object]]
            shape = "plane"
            size = [12.0, 12.0]
            color = [0.9, 0.9, 0.9]
            checker = {{ color = [0.1, 0.1, 0.1], size = {cell:?} }}
            "#
        );
        file::parse(&text, Path::new(name)).expect("the fixture parses")
    }
}

/// The thesis's sphere-reflects-cube (7.4): a mirror sphere of radius 1 at [`BALL_CENTER`]
/// with `segments` tessellation, a cube with six face colours beside it and a checker
/// floor, seen by a perspective camera close to the sphere. The reflector list is left
/// empty: tests choose whether to composite.
pub fn sphere_and_cube(segments: u32) -> Scene {
    let ball = format!(
        r#"name = "ball"
        shape = "sphere"
        size = 1.0
        tessellation = {segments}
        material = "mirror"
        translate = [0.0, 1.0, 0.0]"#
    );
    ReflectorFixture {
        eye: [0.4, 1.4, 2.6],
        look_at: [0.0, 1.0, 0.0],
        reflector: &ball,
        cube: r#"size = [1.2, 1.2, 1.2]
        translate = [1.6, 0.6, 1.6]
        rotate = [0.0, 30.0, 0.0]"#,
        cell: 1.0,
    }
    .scene("sphere-and-cube.toml")
}

/// The perspective camera of a fixture scene at `width` x `height`.
pub fn camera(scene: &Scene, (width, height): (u32, u32)) -> Perspective {
    let ProjectionSpec::Perspective { frame, fov } = &scene.projection else {
        panic!("the fixture scenes use a perspective camera");
    };
    Perspective::new(frame, *fov, width, height).expect("a valid camera")
}

/// The thesis's lens (7.4, Figure 7.6): a 5 x 5-cell plane at height `y` (x, z in [-1, 1])
/// whose vertex normals radiate from the point `depth` below its centre.
pub fn lens_plane(y: f32, depth: f32) -> Mesh {
    let mut mesh = Mesh::default();
    let source = Vec3::new(0.0, y - depth, 0.0);
    for j in 0..6 {
        for i in 0..6 {
            let p = Vec3::new(-1.0 + 0.4 * i as f32, y, -1.0 + 0.4 * j as f32);
            mesh.positions.push(p);
            mesh.normals.push((p - source).normalize());
        }
    }
    for j in 0..5 {
        for i in 0..5 {
            let a = j * 6 + i;
            mesh.triangles.push([a, a + 6, a + 7]);
            mesh.triangles.push([a, a + 7, a + 1]);
        }
    }
    mesh
}
