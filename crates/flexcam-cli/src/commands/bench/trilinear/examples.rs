//! `flexcam bench trilinear --study examples`: Table 8.1 of Vallance 2005, every row: each
//! example projection of chapters 6 and 7 rendered by the ray caster and by the trilinear
//! rasteriser, side by side in one run, same scene, projection and size, beside the thesis's
//! times (800 MHz Athlon, GeForce 2 MX, a ray tracer without acceleration structure).
//!
//! The rows and the scenes that stand for them:
//! - 6.4 `trilinear-detail-in-context.toml`, 6.7 `trilinear-two-views.toml`, 6.9
//!   `trilinear-inward-sphere.toml`: the visualisation surfaces of chapter 6 (our grids are
//!   finer than the thesis's 18, 6 and 200 projections: the column `projections` says how
//!   many ours has).
//! - 7.4 (b)-(f): the thesis's cube reflected in a sphere through 1 x 1 to 5 x 5 surfaces:
//!   `trilinear-sphere-mirror.toml` (the view through a mirror ball) with `grid` 1 to 5 (2 to
//!   50 projections); 7.4 (sphere): `reflect-sphere-cube.toml`, the reflection composited
//!   into a perspective view (the sphere's own refined surface, not an N x N grid).
//! - 7.5 `reflect-funny-mirror.toml` (the 5 x 5 mirror with perturbed normals).
//! - 7.6 (b)-(f): `refract-lens.toml` with its lens made of 1 x 1 to 5 x 5 cells (2 to 50
//!   projections, `trilinear_refine_px = 0`: the cells alone, as in the thesis).
//!
//! The reflector rows composite the reflection into the main view by each method: the ray
//! caster casts the surface's interpolated rays, so both render the same frame.

use std::path::Path;
use std::sync::Arc;

use flexcam::projection::Projection;
use flexcam::render::{CurveOptions, PreparedScene};
use flexcam::scene::file::Definition;
use flexcam::scene::{self, Mesh, Scene};
use flexcam::{Error, Result};
use glam::Vec3;

use super::study::{against, fixed, reference, Table};

/// Where a row's scene and projection come from.
#[derive(Clone, Copy)]
enum Source {
    /// A scene file of the scenes folder, through its own projection.
    File(&'static str),
    /// `trilinear-sphere-mirror.toml` as an `n x n` grid (`projection.grid = n`).
    MirrorBall(u32),
    /// `refract-lens.toml` with an `n x n`-cell lens and no refinement.
    Lens(u32),
}

/// One row of Table 8.1.
struct Example {
    figure: &'static str,
    source: Source,
    /// The thesis's resolution.
    size: (u32, u32),
    /// The thesis's trilinear projections, ray-traced and trilinear ms (NaN: none given).
    thesis: (u32, f64, f64),
}

const fn row(
    figure: &'static str,
    source: Source,
    size: (u32, u32),
    thesis: (u32, f64, f64),
) -> Example {
    Example {
        figure,
        source,
        size,
        thesis,
    }
}

/// Table 8.1, in the thesis's order.
const EXAMPLES: [Example; 15] = [
    row(
        "6.4",
        Source::File("trilinear-detail-in-context.toml"),
        (800, 800),
        (18, 226906.0, 164.6),
    ),
    row(
        "6.7",
        Source::File("trilinear-two-views.toml"),
        (900, 300),
        (6, 92163.0, 49.6),
    ),
    row(
        "6.9",
        Source::File("trilinear-inward-sphere.toml"),
        (600, 600),
        (200, 40518.0, 1242.0),
    ),
    row(
        "7.4 (b)",
        Source::MirrorBall(1),
        (800, 800),
        (2, 177926.0, 24.4),
    ),
    row(
        "7.4 (c)",
        Source::MirrorBall(2),
        (800, 800),
        (8, 177926.0, 70.1),
    ),
    row(
        "7.4 (d)",
        Source::MirrorBall(3),
        (800, 800),
        (18, 177926.0, 150.1),
    ),
    row(
        "7.4 (e)",
        Source::MirrorBall(4),
        (800, 800),
        (32, 177926.0, 230.2),
    ),
    row(
        "7.4 (f)",
        Source::MirrorBall(5),
        (800, 800),
        (50, 177926.0, 360.7),
    ),
    row(
        "7.4 (sphere)",
        Source::File("reflect-sphere-cube.toml"),
        (800, 800),
        (0, 177926.0, f64::NAN),
    ),
    row(
        "7.5",
        Source::File("reflect-funny-mirror.toml"),
        (800, 800),
        (50, 254066.0, 410.7),
    ),
    row("7.6 (b)", Source::Lens(1), (800, 800), (2, 247576.0, 18.5)),
    row("7.6 (c)", Source::Lens(2), (800, 800), (8, 247576.0, 72.3)),
    row(
        "7.6 (d)",
        Source::Lens(3),
        (800, 800),
        (18, 247576.0, 167.0),
    ),
    row(
        "7.6 (e)",
        Source::Lens(4),
        (800, 800),
        (32, 247576.0, 287.8),
    ),
    row(
        "7.6 (f)",
        Source::Lens(5),
        (800, 800),
        (50, 247576.0, 467.3),
    ),
];

/// The table's columns: ours (times in ms: median wall, mean CPU of all threads) and the
/// thesis's.
pub const COLUMNS: &[&str] = &[
    "figure",
    "scene",
    "width",
    "height",
    "projections",
    "raycast_ms",
    "trilinear_ms",
    "speedup",
    "raycast_cpu_ms",
    "trilinear_cpu_ms",
    "cpu_speedup",
    "ids_interior",
    "ids",
    "depth_mean",
    "depth_max",
    "rgb_error",
    "thesis_projections",
    "thesis_ray_ms",
    "thesis_trilinear_ms",
    "thesis_speedup",
];

/// Measures every row at the thesis's resolution, or at width `size` (the height keeping the
/// thesis's aspect), with the scenes of folder `scenes`.
pub fn run(scenes: &Path, size: Option<u32>, repeat: u32) -> Result<Table> {
    let mut table = Table::new(COLUMNS);
    for example in &EXAMPLES {
        let (width, height) = match size {
            Some(w) => (w, (w * example.size.1 / example.size.0).max(3)),
            None => example.size,
        };
        let (name, scene, projection) = load(scenes, example.source, width, height)?;
        let prepared = PreparedScene::new(&scene);
        let (raycast, frame) = reference(&prepared, projection.as_ref(), repeat)?;
        let m = against(
            &frame,
            &prepared,
            projection.as_ref(),
            CurveOptions::default(),
            repeat,
        )?;
        let projections = if scene.trilinear_reflectors.is_empty() {
            m.count("projection_triangles")
        } else {
            m.count("reflector_triangles")
        };
        let (thesis_projections, thesis_ray, thesis_ms) = example.thesis;
        let c = &m.comparison;
        table.push(vec![
            example.figure.to_string(),
            name,
            width.to_string(),
            height.to_string(),
            projections.to_string(),
            fixed(raycast.median_ms(), 2),
            fixed(m.timing.median_ms(), 2),
            fixed(raycast.median / m.timing.median, 2),
            fixed(raycast.cpu_ms(), 1),
            fixed(m.timing.cpu_ms(), 1),
            fixed(raycast.cpu_ms() / m.timing.cpu_ms(), 2),
            fixed(m.interior.0, 5),
            fixed(c.id_agreement, 5),
            format!("{:.2e}", c.depth_mean),
            format!("{:.2e}", c.depth_max),
            fixed(c.relative_rgb_error, 6),
            if thesis_projections == 0 {
                "-".to_string()
            } else {
                thesis_projections.to_string()
            },
            fixed(thesis_ray, 1),
            fixed(thesis_ms, 1),
            fixed(thesis_ray / thesis_ms, 0),
        ]);
    }
    Ok(table)
}

/// The scene of `source`, its name for the table and its projection at `width x height`.
fn load(
    scenes: &Path,
    source: Source,
    width: u32,
    height: u32,
) -> Result<(String, Scene, Box<dyn Projection>)> {
    let file = |name: &str| scene::load(&scenes.join(name).to_string_lossy());
    let (name, scene) = match source {
        Source::File(name) => (name.to_string(), file(name)?),
        Source::MirrorBall(n) => {
            let name = "trilinear-sphere-mirror.toml";
            let grid = format!("projection.grid={n}").parse::<Definition>()?;
            let path = scenes.join(name);
            let scene = scene::load_defined(&path.to_string_lossy(), &[grid])?;
            (format!("{name} {n}x{n}"), scene)
        }
        Source::Lens(n) => {
            let mut scene = file("refract-lens.toml")?;
            with_lens_cells(&mut scene, n)?;
            (format!("refract-lens.toml {n}x{n}"), scene)
        }
    };
    let projection = scene.projection.build(width, height)?;
    Ok((name, scene, projection))
}

/// Replaces the mesh of `scene`'s object `lens` (a flat 2 x 2 plane of object space, y = 0,
/// facing +y, its vertex normals radiating from (0, -2, 0): `scenes/models/lens.obj`) by the
/// same plane of `n x n` cells, and makes its reflector surface those cells alone
/// (`trilinear_refine_px = 0`).
fn with_lens_cells(scene: &mut Scene, n: u32) -> Result<()> {
    let object = scene
        .objects
        .iter_mut()
        .find(|o| o.name == "lens")
        .ok_or_else(|| Error::new("refract-lens.toml has no object named lens"))?;
    let to_world = object.world_to_object.inverse();
    let side = n as usize + 1;
    let (mut positions, mut normals) = (Vec::new(), Vec::new());
    for row in 0..side {
        for column in 0..side {
            let along = |k: usize| -1.0 + 2.0 * k as f32 / n as f32;
            let local = Vec3::new(along(column), 0.0, -along(row));
            positions.push(to_world.transform_point3(local));
            let normal = local - Vec3::new(0.0, -2.0, 0.0);
            normals.push(to_world.transform_vector3(normal).normalize());
        }
    }
    let mut triangles = Vec::new();
    for row in 0..n {
        for column in 0..n {
            let a = row * (n + 1) + column;
            let below = a + n + 1;
            triangles.push([a, a + 1, below + 1]);
            triangles.push([a, below + 1, below]);
        }
    }
    let mesh = Mesh {
        positions,
        normals,
        uvs: Vec::new(),
        colors: Vec::new(),
        triangles,
    };
    mesh.validate()?;
    object.mesh = Arc::new(mesh);
    let id = object.id;
    for reflector in scene.trilinear_reflectors.iter_mut().filter(|r| r.id == id) {
        reflector.refine_px = 0.0;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lens_scene() -> Scene {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/refract-lens.toml");
        scene::load(&path.to_string_lossy()).unwrap()
    }

    /// The 5 x 5 lens built in code is the scene's own lens (models/lens.obj): the same
    /// triangles with the same corner positions and normals; other sizes have 2 n^2 triangles and no refinement.
    #[test]
    fn lens_cells_rebuild_the_scene_lens() {
        let original = lens_scene();
        let lens = |scene: &Scene| {
            let object = scene.objects.iter().find(|o| o.name == "lens").unwrap();
            (object.mesh.clone(), object.id)
        };
        let (mesh, id) = lens(&original);
        let mut rebuilt = lens_scene();
        with_lens_cells(&mut rebuilt, 5).unwrap();
        let (cells, _) = lens(&rebuilt);
        // The OBJ loader numbers vertices in the order the faces first use them, so the
        // meshes are compared triangle by triangle, corner by corner.
        assert_eq!(cells.positions.len(), mesh.positions.len());
        assert_eq!(cells.triangles.len(), mesh.triangles.len());
        for (k, (s, t)) in cells.triangles.iter().zip(&mesh.triangles).enumerate() {
            for (&i, &j) in s.iter().zip(t) {
                let (a, b) = (cells.positions[i as usize], mesh.positions[j as usize]);
                assert!(a.distance(b) < 1e-5, "triangle {k}: {a} {b}");
                let (a, b) = (cells.normals[i as usize], mesh.normals[j as usize]);
                assert!(a.dot(b) > 0.99999, "triangle {k}: {a} {b}");
            }
        }
        let refine_px = |s: &Scene| {
            let reflector = s.trilinear_reflectors.iter().find(|r| r.id == id);
            reflector.unwrap().refine_px
        };
        assert!(refine_px(&original) > 0.0);
        assert_eq!(refine_px(&rebuilt), 0.0);
        for n in [1, 3] {
            let mut scene = lens_scene();
            with_lens_cells(&mut scene, n).unwrap();
            assert_eq!(lens(&scene).0.triangles.len(), 2 * (n * n) as usize);
        }
    }
}
