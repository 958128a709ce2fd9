//! The surface layers of `flexcam render --aovs` (normals `N`, `Ng`, position `P`, texture
//! coordinates `uv`), read back with the exr crate: on a plane and a sphere they equal the
//! closed forms of a perspective camera's rays, and `--method raster` draws the same
//! surfaces as the ray caster away from object edges.

use glam::{DVec3, Vec3};
use std::fs;
use tempfile::TempDir;

mod common;
use common::{plane_and_sphere, run_ok, Layers};

const W: usize = 64;
const H: usize = 48;
const EYE: DVec3 = DVec3::new(0.0, 3.0, 6.0);
const LOOK_AT: DVec3 = DVec3::new(0.0, 0.5, 0.0);
const FOV: f64 = 60.0;
const CENTRE: DVec3 = DVec3::new(0.0, 1.0, 0.0);

/// The plane and sphere of [`plane_and_sphere`] in perspective from above.
fn scene() -> String {
    let projection = format!(
        "type = \"perspective\"\nposition = [{}, {}, {}]\nlook_at = [{}, {}, {}]\nfov = {FOV}",
        EYE.x, EYE.y, EYE.z, LOOK_AT.x, LOOK_AT.y, LOOK_AT.z
    );
    plane_and_sphere(W as u32, H as u32, &projection)
}

/// The unit direction of the perspective ray through the centre of pixel `i`, written from
/// the projection's definition: horizontal `FOV`, square pixels, y up.
fn ray_direction(i: usize) -> DVec3 {
    let forward = (LOOK_AT - EYE).normalize();
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    let half = (0.5 * FOV.to_radians()).tan();
    let (x, y) = ((i % W) as f64 + 0.5, (i / W) as f64 + 0.5);
    let sx = (2.0 * x / W as f64 - 1.0) * half;
    let sy = (1.0 - 2.0 * y / H as f64) * half * H as f64 / W as f64;
    (forward + sx * right + sy * up).normalize()
}

fn render_aovs(dir: &TempDir, method: &str, out: &str) -> Layers {
    run_ok(
        dir,
        &[
            "render",
            "scene.toml",
            "--shading",
            "flat",
            "--method",
            method,
            "-o",
            "c.png",
            "--aovs",
            out,
        ],
    );
    Layers::read(&dir.path().join(out), (W, H))
}

#[test]
fn normals_and_positions_are_the_closed_forms_on_a_plane_and_a_sphere() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("scene.toml"), scene()).unwrap();
    let layers = render_aovs(&dir, "raycast", "aovs.exr");
    assert_eq!(
        layers.names(),
        [
            "B", "G", "N.X", "N.Y", "N.Z", "Ng.X", "Ng.Y", "Ng.Z", "P.X", "P.Y", "P.Z", "R", "Z",
            "id", "uv.U", "uv.V"
        ]
    );
    let (ids, depth) = (layers.ids(), layers.floats("Z"));
    let (n, ng, p) = (
        layers.vectors("N"),
        layers.vectors("Ng"),
        layers.vectors("P"),
    );
    let (u, v) = (layers.floats("uv.U"), layers.floats("uv.V"));
    let mut seen = [0; 3];
    for i in 0..W * H {
        let d = ray_direction(i);
        let point = p[i].as_dvec3();
        seen[ids[i] as usize] += 1;
        match ids[i] {
            0 => {
                assert_eq!((n[i], ng[i]), (Vec3::ZERO, Vec3::ZERO), "pixel {i}");
                assert!(p[i].is_nan() && u[i].is_nan() && v[i].is_nan(), "pixel {i}");
                continue;
            }
            1 => {
                // The floor: where the ray meets y = 0, normal +y (the camera is above).
                let hit = EYE + d * (-EYE.y / d.y);
                assert!(point.distance(hit) < 1e-4 * hit.distance(EYE), "pixel {i}");
                assert!(n[i].distance(Vec3::Y) < 1e-6 && ng[i].distance(Vec3::Y) < 1e-6);
                let uv = (hit.x / 20.0 + 0.5, 0.5 - hit.z / 20.0);
                assert!((u[i] as f64 - uv.0).abs() < 1e-5, "pixel {i}");
                assert!((v[i] as f64 - uv.1).abs() < 1e-5, "pixel {i}");
            }
            2 => {
                // The sphere: on the ray at the depth, on the unit sphere up to its
                // tessellation (96 segments, 48 rings: triangles sag up to about 1.1e-3),
                // the shading normal radial up to the same.
                let radial = point - CENTRE;
                assert!(
                    (radial.length() - 1.0).abs() < 1.5e-3,
                    "pixel {i}: {radial}"
                );
                let analytic = (radial / radial.length()).as_vec3();
                assert!(
                    n[i].dot(analytic) > 0.9999,
                    "pixel {i}: {} {analytic}",
                    n[i]
                );
                assert!(ng[i].dot(analytic) > 0.999, "pixel {i}");
                assert!(ng[i].dot(d.as_vec3()) < 0.0, "pixel {i}: faces the camera");
            }
            other => panic!("unexpected id {other}"),
        }
        let on_ray = EYE + d * depth[i] as f64;
        assert!(point.distance(on_ray) < 1e-4 * depth[i] as f64, "pixel {i}");
        assert!((n[i].length() - 1.0).abs() < 1e-6 && (ng[i].length() - 1.0).abs() < 1e-6);
    }
    assert!(seen.iter().all(|&count| count > 100), "{seen:?}");
}

#[test]
fn raster_draws_the_surfaces_the_ray_caster_does_away_from_edges() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("scene.toml"), scene()).unwrap();
    let raycast = render_aovs(&dir, "raycast", "raycast.exr");
    let raster = render_aovs(&dir, "raster", "raster.exr");
    let ids = raycast.ids();
    let raster_ids = raster.ids();
    let differ = (0..W * H).filter(|&i| raster_ids[i] != ids[i]).count();
    assert!(differ < W * H / 100, "{differ} ids differ");
    let inner = |i: usize| {
        let (x, y) = (i % W, i / W);
        x > 0
            && y > 0
            && x + 1 < W
            && y + 1 < H
            && [i - 1, i + 1, i - W, i + W]
                .iter()
                .all(|&j| ids[j] == ids[i])
    };
    let depth = raycast.floats("Z");
    let (p, q) = (raycast.vectors("P"), raster.vectors("P"));
    let (n, m) = (raycast.vectors("N"), raster.vectors("N"));
    let (u, v) = (raycast.floats("uv.U"), raster.floats("uv.U"));
    let mut compared = 0;
    for i in (0..W * H).filter(|&i| ids[i] != 0 && raster_ids[i] == ids[i] && inner(i)) {
        assert!(
            p[i].distance(q[i]) < 1e-3 * depth[i],
            "pixel {i}: {} {}",
            p[i],
            q[i]
        );
        assert!(n[i].dot(m[i]) > 0.9999, "pixel {i}");
        assert!((u[i] - v[i]).abs() < 1e-4, "pixel {i}");
        compared += 1;
    }
    assert!(compared > W * H / 2, "{compared}");
}
