use std::path::Path;

use super::*;
use crate::render::compare::compare;
use crate::render::{Method, Shading};
use crate::scene::{self, ReflectionImage, Scene};

fn load(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(format!("{name}.toml"));
    scene::file::load(&path).unwrap()
}

/// Every atlas triangle lies inside the atlas, and no texel centre is inside two of them
/// (a cell's pair is one texel apart along the hypotenuse), for counts that fill the last
/// row or not.
#[test]
fn atlas_triangles_lie_inside_the_atlas_and_apart() {
    for (triangles, leg) in [(1, 3.0), (2, 8.0), (7, 20.5), (50, 9.0)] {
        let layout = Layout::new(triangles, leg).unwrap();
        assert!(layout.cell >= MIN_CELL);
        let (w, h) = layout.size();
        let mut owner = vec![None; (w * h) as usize];
        for k in 0..triangles {
            let [a, b, c] = layout.corners(k);
            for p in [a, b, c] {
                assert!(p.x >= 0.0 && p.y >= 0.0 && p.x <= f64::from(w) && p.y <= f64::from(h));
            }
            let inside = |q: DVec2| {
                let s = [(a, b), (b, c), (c, a)].map(|(p, r)| (r - p).perp_dot(q - p));
                s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0)
            };
            for y in 0..h {
                for x in 0..w {
                    if inside(DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5)) {
                        let slot = &mut owner[(y * w + x) as usize];
                        assert_eq!(*slot, None, "texel ({x}, {y}) in two triangles");
                        *slot = Some(k);
                    }
                }
            }
        }
        // Each triangle holds about S^2 / 2 texel centres.
        let cell = f64::from(layout.cell);
        for k in 0..triangles {
            let n = owner.iter().filter(|&&o| o == Some(k)).count() as f64;
            assert!((n - cell * cell / 2.0).abs() <= 2.0 * cell, "{k}: {n}");
        }
    }
    // More triangles than the largest atlas holds at the smallest cell.
    assert!(Layout::new(1_000_000, 10.0).is_err());
    // A NaN leg takes the smallest cell.
    assert_eq!(Layout::new(4, f64::NAN).unwrap().cell, MIN_CELL);
}

/// The application scenes through the atlas against the exact ray caster: the reflection is
/// the same scene (relative RGB error of the atlas's resampling and correspondence, measured
/// 0.8 to 3.1 % at 160 x 120), every reflector pixel found by normal shooting on the convex ball, and the
/// atlas sized by the module's rule.
#[test]
fn atlas_reflections_match_the_exact_ray_caster() {
    for (name, max_rgb) in [
        ("camtri-convex", 0.035),
        ("camtri-mixed", 0.035),
        ("camtri-refract", 0.035),
    ] {
        let mut scene = load(name);
        scene.trilinear_reflectors[0].reflection = ReflectionImage::Atlas;
        let main = scene.projection.build(160, 120).unwrap();
        let options = RenderOptions {
            method: Method::CameraTriangles,
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        let ours =
            crate::render::render(&PreparedScene::new(&scene), main.as_ref(), &options).unwrap();
        let reference = super::super::exact_flat_reference(&scene, main.as_ref());
        let c = compare(&ours.frame, &reference).unwrap();
        let counter = |key: &str| match ours.counters.get(key) {
            Some(Counter::Count(n)) => *n,
            other => panic!("{name} {key}: {other:?}"),
        };
        println!(
            "{name}: {c:?}, atlas {} x {}, cell {}, missed {}",
            counter("atlas_width"),
            counter("atlas_height"),
            counter("atlas_cell_px"),
            counter("atlas_missed_pixels")
        );
        assert!(c.relative_rgb_error < max_rgb, "{name}: {c:?}");
        assert!(counter("atlas_cell_px") >= u64::from(MIN_CELL));
        if name == "camtri-convex" {
            assert_eq!(counter("atlas_missed_pixels"), 0);
        }
    }
}
