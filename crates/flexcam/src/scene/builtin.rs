//! Built-in scenes (`builtin:NAME`), listed by `flexcam scenes`.
//!
//! The built-in scenes are the scene files in the repository's `scenes/` folder, embedded at
//! compile time and parsed like any other file, so each is also an example of the format and
//! there is no second copy to keep in step. They use analytic shapes only (no model files).

use std::path::Path;

use super::{file, Scene};
use crate::error::{Error, Result};

/// The scene `flexcam render` draws when no scene is named.
pub const DEFAULT: &str = "default";

/// One built-in scene: its name, a one-line description, and its scene-file text.
#[derive(Clone, Copy)]
struct Builtin {
    name: &'static str,
    description: &'static str,
    text: &'static str,
}

const BUILTINS: [Builtin; 6] = [
    Builtin {
        name: "default",
        description: "a teapot, mirror and glass spheres, a torus, boxes, a pillar, a cylinder and a lamp around the eye, as a 360 x 180 degree equirectangular panorama",
        text: include_str!("../../../../scenes/default.toml"),
    },
    Builtin {
        name: "cube-floor",
        description: "the cube on a checkerboard of Vallance's thesis: six differently coloured faces, 686 triangles, perspective from above",
        text: include_str!("../../../../scenes/cube-floor.toml"),
    },
    Builtin {
        name: "teapot-room",
        description: "a teapot, a box, a sphere and a cylinder on a checkerboard, with a mirror sphere and a glass sphere; perspective",
        text: include_str!("../../../../scenes/teapot-room.toml"),
    },
    Builtin {
        name: "teapot-dense",
        description: "a finely tessellated teapot on a floor, 123,554 triangles, perspective: the ray-casting benchmark scene",
        text: include_str!("../../../../scenes/teapot-dense.toml"),
    },
    Builtin {
        name: "displaced-torus",
        description: "a three-holed torus of 5,046 triangles displaced at level 5 by procedural waves (5.2 million micro-triangles, traced without tessellating), perspective; --method raycast",
        text: include_str!("../../../../scenes/displaced-torus.toml"),
    },
    Builtin {
        name: "displaced-scan",
        description: "a scanned-style model of 101,760 triangles roughened by procedural displacement at level 2, on a floor, perspective; --method raycast",
        text: include_str!("../../../../scenes/displaced-scan.toml"),
    },
];

/// (name, description) pairs of [`BUILTINS`], computed at compile time.
const fn names_and_descriptions<const N: usize>(
    builtins: [Builtin; N],
) -> [(&'static str, &'static str); N] {
    let mut out = [("", ""); N];
    let mut i = 0;
    while i < N {
        out[i] = (builtins[i].name, builtins[i].description);
        i += 1;
    }
    out
}

static LIST: [(&str, &str); BUILTINS.len()] = names_and_descriptions(BUILTINS);

/// The built-in scenes: (name, one-line description), in display order.
pub fn list() -> &'static [(&'static str, &'static str)] {
    &LIST
}

/// Loads the built-in scene `name`. An unknown name is an error listing the valid ones.
pub fn load(name: &str) -> Result<Scene> {
    load_defined(name, &[])
}

/// [`load`] with `definitions` (`-D KEY=VALUE`) written into the scene's text
/// ([`file::parse_defined`]).
pub fn load_defined(name: &str, definitions: &[file::Definition]) -> Result<Scene> {
    let builtin = BUILTINS.iter().find(|b| b.name == name).ok_or_else(|| {
        let names: Vec<&str> = BUILTINS.iter().map(|b| b.name).collect();
        Error::new(format!(
            "unknown built-in scene \"{name}\"; expected one of: {}",
            names.join(", ")
        ))
    })?;
    let path = format!("builtin:{name}");
    let (mut scene, _) = file::parse_defined(builtin.text, Path::new(&path), definitions)?;
    scene.base_dir = None;
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Loads built-in `name` and checks its ids run 1..=N over its objects.
    fn load_checked(name: &str) -> Scene {
        let scene = load(name).unwrap_or_else(|e| panic!("builtin:{name}: {e}"));
        assert!(scene.base_dir.is_none());
        let mut ids: Vec<u32> = scene.objects.iter().map(|o| o.id).collect();
        ids.dedup();
        let expected: Vec<u32> = (1..=ids.len() as u32).collect();
        assert_eq!(ids, expected, "builtin:{name} ids");
        scene
    }

    #[test]
    fn list_names_every_builtin_once_with_a_description() {
        let names: Vec<&str> = list().iter().map(|(name, _)| *name).collect();
        assert_eq!(
            names,
            [
                "default",
                "cube-floor",
                "teapot-room",
                "teapot-dense",
                "displaced-torus",
                "displaced-scan"
            ]
        );
        assert!(names.contains(&DEFAULT));
        assert!(list()
            .iter()
            .all(|(_, d)| !d.is_empty() && !d.contains('\n')));
    }

    #[test]
    fn unknown_name_lists_the_valid_ones() {
        let message = load("nope")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            message.contains("unknown built-in scene \"nope\""),
            "{message}"
        );
        assert!(
            message.contains(
                "default, cube-floor, teapot-room, teapot-dense, displaced-torus, displaced-scan"
            ),
            "{message}"
        );
        let via_scene = crate::scene::load("builtin:nope")
            .err()
            .map(|e| e.to_string());
        assert_eq!(via_scene, Some(message));
    }

    #[test]
    fn default_is_a_panorama_surrounded_by_objects() {
        let scene = load_checked(DEFAULT);
        assert_eq!(scene.projection.kind(), "equirectangular");
        assert_eq!((scene.image.width, scene.image.height), (1024, 512));
        assert!(scene.objects.len() >= 8 && scene.lights.len() == 2);
        let surfaces: Vec<_> = scene.objects.iter().map(|o| o.material.finish).collect();
        assert!(surfaces.contains(&crate::scene::Finish::Mirror));
        assert!(surfaces
            .iter()
            .any(|s| matches!(s, crate::scene::Finish::Glass { .. })));
        assert!(
            (5_000..200_000).contains(&scene.triangle_count()),
            "{}",
            scene.triangle_count()
        );
    }

    #[test]
    fn cube_floor_has_the_686_triangles_of_seed_000() {
        let scene = load_checked("cube-floor");
        assert_eq!(scene.triangle_count(), 686);
        assert_eq!(scene.objects.len(), 2);
        assert_eq!(scene.projection.kind(), "perspective");
        // Six distinct face colours.
        let mut colors = scene.objects[1].mesh.colors.clone();
        colors.sort_by(|a, b| {
            a.to_array()
                .partial_cmp(&b.to_array())
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        colors.dedup();
        assert_eq!(colors.len(), 6);
    }

    #[test]
    fn teapot_room_has_a_mirror_and_a_glass_object() {
        let scene = load_checked("teapot-room");
        let named = |name: &str| {
            scene
                .objects
                .iter()
                .find(|o| o.name == name)
                .map(|o| o.material.finish)
        };
        assert_eq!(named("mirror"), Some(crate::scene::Finish::Mirror));
        assert!(matches!(
            named("glass"),
            Some(crate::scene::Finish::Glass { .. })
        ));
        assert!(named("teapot").is_some());
        assert!(
            (5_000..100_000).contains(&scene.triangle_count()),
            "{}",
            scene.triangle_count()
        );
    }

    #[test]
    fn teapot_dense_has_over_100k_triangles() {
        let scene = load_checked("teapot-dense");
        assert!(
            (100_000..200_000).contains(&scene.triangle_count()),
            "{}",
            scene.triangle_count()
        );
    }

    #[test]
    fn scene_load_accepts_builtin_prefix() {
        let scene = crate::scene::load("builtin:cube-floor").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(scene.triangle_count(), 686);
    }
}
