//! Loading a trilinear projection mesh from an OBJ file: `v` is the base point, `vn` the
//! ray direction and `vt` the screen position of each face corner.

use std::path::Path;

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::file_read::{read_regular, MAX_DATA_FILE_BYTES};
use crate::projection::TrilinearMesh;

impl TrilinearMesh {
    /// Loads a trilinear projection mesh from an OBJ file: `v` = base point, `vn` = ray
    /// direction, `vt` = screen position; every face corner needs all three. Polygons are
    /// triangulated as fans and points and lines ignored (tobj's single-index GPU options);
    /// all objects and groups of the file form one mesh. Errors name the file, and the line
    /// of a `vn` of zero length (no ray direction). The mesh is not validated further here:
    /// [`crate::projection::ProjectionSpec::build`] does that.
    pub fn load_obj(path: &Path) -> Result<TrilinearMesh> {
        let text = read_regular(path, "trilinear surface", MAX_DATA_FILE_BYTES)?;
        check_ray_directions(path, &text)?;
        let (models, _materials) = tobj::load_obj(path, &tobj::GPU_LOAD_OPTIONS)
            .map_err(|e| Error::in_file(path, format!("cannot read trilinear surface OBJ: {e}")))?;
        let mut mesh = TrilinearMesh::default();
        for model in &models {
            append_model(&mut mesh, &model.mesh)
                .map_err(|message| Error::in_file(path, message))?;
        }
        if mesh.triangles.is_empty() {
            return Err(Error::in_file(path, "trilinear surface OBJ has no faces"));
        }
        Ok(mesh)
    }
}

/// Fails at the first `vn` line of `text` (the OBJ file at `path`) whose direction is zero:
/// every vertex of a trilinear surface needs a ray direction, and the mesh's own check could
/// name only the vertex (tobj renumbers them), not the line. Lines whose numbers do not read
/// are tobj's to refuse.
fn check_ray_directions(path: &Path, text: &[u8]) -> Result<()> {
    for (number, line) in text.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        let mut words = line.split_whitespace();
        if words.next() != Some("vn") {
            continue;
        }
        let values: Vec<f64> = words.filter_map(|w| w.parse().ok()).collect();
        if values.len() == 3 && values.iter().all(|&v| v == 0.0) {
            return Err(Error::at(
                path,
                number + 1,
                1,
                "`vn` has zero length: every vertex of a trilinear surface needs a ray direction",
            ));
        }
    }
    Ok(())
}

/// Appends one OBJ object's vertices and triangles to `mesh`, offsetting its indices.
fn append_model(mesh: &mut TrilinearMesh, model: &tobj::Mesh) -> std::result::Result<(), String> {
    let count = model.positions.len() / 3;
    if model.normals.len() != 3 * count || model.texcoords.len() != 2 * count {
        return Err(
            "every face corner of a trilinear surface needs a position, a vt (screen position) \
             and a vn (ray direction): write faces as f v/vt/vn"
                .to_string(),
        );
    }
    let offset = u32::try_from(mesh.points.len())
        .map_err(|_| "trilinear surface OBJ has too many vertices".to_string())?;
    mesh.points
        .extend(model.positions.chunks_exact(3).map(vec3));
    mesh.normals.extend(model.normals.chunks_exact(3).map(vec3));
    mesh.screen
        .extend(model.texcoords.chunks_exact(2).map(vec2));
    mesh.triangles.extend(
        model
            .indices
            .chunks_exact(3)
            .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]),
    );
    Ok(())
}

/// tobj stores f32, or f64 with its `use_f64` feature: accept both.
fn vec3<F: Copy + Into<f64>>(c: &[F]) -> DVec3 {
    DVec3::new(c[0].into(), c[1].into(), c[2].into())
}

fn vec2<F: Copy + Into<f64>>(c: &[F]) -> DVec2 {
    DVec2::new(c[0].into(), c[1].into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn obj_file(text: &str) -> tempfile::NamedTempFile {
        let mut file = tempfile::Builder::new().suffix(".obj").tempfile().unwrap();
        file.write_all(text.as_bytes()).unwrap();
        file
    }

    #[test]
    fn loads_points_normals_and_screen_per_corner() {
        let file = obj_file(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
             vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
             vn 0 0 -1\nvn 0.5 0 -1\n\
             f 1/1/1 2/2/2 3/3/2 4/4/1\n",
        );
        let mesh = TrilinearMesh::load_obj(file.path()).unwrap();
        assert_eq!(mesh.triangles.len(), 2);
        assert_eq!(mesh.points.len(), 4);
        assert_eq!(mesh.points[2], DVec3::new(1.0, 1.0, 0.0));
        assert_eq!(mesh.screen[2], DVec2::new(1.0, 1.0));
        assert_eq!(mesh.normals[2], DVec3::new(0.5, 0.0, -1.0));
        assert_eq!(mesh.triangles[1], [0, 2, 3]);
    }

    #[test]
    fn several_objects_form_one_mesh() {
        let file = obj_file(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n\
             o a\nf 1/1/1 2/2/1 3/3/1\no b\nf 3/3/1 2/2/1 1/1/1\n",
        );
        let mesh = TrilinearMesh::load_obj(file.path()).unwrap();
        // The second object's corners get fresh vertices, numbered in order of use.
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(mesh.points[3], mesh.points[2]);
        assert_eq!(mesh.points[5], mesh.points[0]);
    }

    #[test]
    fn faces_without_vt_or_vn_are_errors_naming_the_file() {
        for faces in ["f 1//1 2//1 3//1\n", "f 1/1 2/2 3/3\n", "f 1 2 3\n"] {
            let file = obj_file(&format!(
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n{faces}"
            ));
            let e = TrilinearMesh::load_obj(file.path()).unwrap_err();
            let text = e.to_string();
            assert!(
                text.starts_with(&file.path().display().to_string()),
                "{text}"
            );
            assert!(text.contains("f v/vt/vn"), "{text}");
        }
    }

    /// A zero ray direction is refused at its `vn` line, not at the vertex the mesh check
    /// would name.
    #[test]
    fn a_zero_ray_direction_is_an_error_at_its_line() {
        let file = obj_file(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 0 0.0 -0\n\
             f 1/1/1 2/2/2 3/3/1\n",
        );
        let e = TrilinearMesh::load_obj(file.path()).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}:8:1: `vn` has zero length: every vertex of a trilinear surface needs a ray \
                 direction",
                file.path().display()
            )
        );
    }

    #[test]
    fn missing_unreadable_and_empty_files_are_errors() {
        let missing = Path::new("/nonexistent/surface.obj");
        let e = TrilinearMesh::load_obj(missing).unwrap_err().to_string();
        assert!(
            e.starts_with("/nonexistent/surface.obj: cannot read"),
            "{e}"
        );
        let broken = obj_file("v 0 0 0\nf 1/1/1 2/2/2 3/3/3\n");
        assert!(TrilinearMesh::load_obj(broken.path()).is_err());
        let empty = obj_file("v 0 0 0\n");
        let e = TrilinearMesh::load_obj(empty.path())
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("trilinear surface OBJ has no faces"), "{e}");
    }

    fn shipped_surface(name: &str) -> TrilinearMesh {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes/surfaces")
            .join(name);
        TrilinearMesh::load_obj(&path).unwrap()
    }

    #[test]
    fn grid2_reproduces_its_perspective_view() {
        use crate::projection::{CameraFrame, ProjectionSpec};
        let mesh = shipped_surface("grid2.obj");
        assert_eq!(mesh.triangles.len(), 2);
        let trilinear = ProjectionSpec::Trilinear(mesh).build(80, 60).unwrap();
        let frame = CameraFrame {
            position: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
        };
        let perspective = ProjectionSpec::Perspective { frame, fov: 90.0 }
            .build(80, 60)
            .unwrap();
        for y in 0..60 {
            for x in 0..80 {
                let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let a = trilinear.ray(pixel).unwrap().direction.normalize();
                let b = perspective.ray(pixel).unwrap().direction;
                assert!((a - b).length() < 1e-6, "pixel {pixel}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn fan18_covers_the_whole_image_and_looks_ahead_in_the_middle() {
        use crate::projection::ProjectionSpec;
        let mesh = shipped_surface("fan18.obj");
        assert_eq!(mesh.triangles.len(), 18);
        let fan = ProjectionSpec::Trilinear(mesh).build(90, 60).unwrap();
        for y in 0..60 {
            for x in 0..90 {
                let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                assert!(fan.ray(pixel).is_some(), "crack at {pixel}");
            }
        }
        let centre = fan.ray(DVec2::new(45.0, 30.0)).unwrap();
        assert!((centre.direction.normalize() - DVec3::NEG_Z).length() < 1e-6);
        let left = fan.ray(DVec2::new(0.0, 30.0)).unwrap().direction;
        assert!((left.normalize().angle_between(DVec3::NEG_Z).to_degrees() - 60.0).abs() < 1e-3);
    }
}
