use glam::Vec3;

use super::*;
use crate::projection::{CameraFrame, ProjectionSpec};
use crate::render::{render, Method, Outputs};
use crate::scene;

/// The built-in displaced torus at `level`, its camera at `fraction` of its distance.
fn scene_at(level: u32, fraction: f64) -> (crate::scene::Scene, ProjectionSpec) {
    let mut scene = scene::load("builtin:displaced-torus").unwrap();
    for object in &mut scene.objects {
        if let Some(spec) = &object.displacement {
            object.displacement = Some(std::sync::Arc::new(crate::scene::DisplacementSpec {
                level,
                ..crate::scene::DisplacementSpec::clone(spec)
            }));
        }
    }
    let ProjectionSpec::Perspective { frame, fov } = scene.projection else {
        panic!("a perspective camera");
    };
    let spec = ProjectionSpec::Perspective {
        frame: CameraFrame {
            position: frame.look_at + (frame.position - frame.look_at) * fraction,
            ..frame
        },
        fov,
    };
    (scene, spec)
}

fn frame(
    prepared: &PreparedScene,
    spec: &ProjectionSpec,
    size: u32,
    shading: Shading,
) -> Vec<Vec3> {
    let projection = spec.build(size, size).unwrap();
    let options = RenderOptions {
        method: Method::Raycast,
        shading,
        outputs: Outputs::COLOR,
        ..RenderOptions::default()
    };
    render(prepared, projection.as_ref(), &options)
        .unwrap()
        .frame
        .color
}

fn mean_difference(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).abs().element_sum())
        .sum::<f32>()
        / a.len() as f32
}

/// The seam test: a slow sweep of the camera distance carries the torus through every
/// threshold (displacement near, bump, BRDF far); consecutive transition-lit images differ
/// by no more than the same steps differ when every ray is fully displaced (`D` very
/// negative: `T` is always above 1), so no method switches with a visible jump.
#[test]
fn a_sweep_of_the_camera_distance_shows_no_seam() {
    // At 40 x 40 the relief spans about 0.8 footprints at the scene's distance: D = 0.9 puts
    // the near end of the sweep in displacement and the far end's grazing parts in the BRDF.
    let transition = Shading::Transitions(TransitionShading::new(false, 0.9).unwrap());
    let displaced = Shading::Transitions(TransitionShading::new(false, -1e9).unwrap());
    let methods = Shading::Transitions(TransitionShading::new(true, 0.9).unwrap());
    let (scene, _) = scene_at(2, 1.0);
    let prepared = PreparedScene::new(&scene);
    let steps: Vec<f64> = (0..=16).map(|k| 0.4 + k as f64 * 0.1).collect();
    let mut last: Option<(Vec<Vec3>, Vec<Vec3>)> = None;
    let mut seen = [false; 3];
    for fraction in steps {
        let (_, spec) = scene_at(2, fraction);
        let t = frame(&prepared, &spec, 40, transition);
        let d = frame(&prepared, &spec, 40, displaced);
        for c in frame(&prepared, &spec, 40, methods) {
            for (k, channel) in [c.x, c.z, c.y].into_iter().enumerate() {
                seen[k] |= channel > 0.99;
            }
        }
        if let Some((lt, ld)) = &last {
            let (dt, dd) = (mean_difference(&t, lt), mean_difference(&d, ld));
            assert!(dt <= 1.5 * dd + 0.005, "at {fraction}: {dt} against {dd}");
        }
        last = Some((t, d));
    }
    // The sweep crossed every method: BRDF, bump and displacement each chosen alone somewhere.
    assert_eq!(seen, [true; 3]);
}

#[test]
fn refuses_other_methods_and_bad_constants() {
    assert!(TransitionShading::new(true, f64::NAN).is_err());
    let (scene, spec) = scene_at(1, 1.0);
    let prepared = PreparedScene::new(&scene);
    let projection = spec.build(8, 8).unwrap();
    let options = RenderOptions {
        method: Method::Raster,
        shading: Shading::Transitions(TransitionShading::with_default_d(true)),
        ..RenderOptions::default()
    };
    assert!(render(&prepared, projection.as_ref(), &options).is_err());
}

/// Rays that displace trace coarser levels of detail where their footprint allows, and the
/// image stays close to the one traced on the detailed mesh everywhere.
#[test]
fn coarser_levels_where_the_footprint_allows() {
    let (scene, spec) = scene_at(2, 1.0);
    let prepared = PreparedScene::new(&scene);
    let displaced = TransitionShading::new(false, -1e9).unwrap();
    let projection = spec.build(48, 48).unwrap();
    let run = |lod| {
        let options = RenderOptions {
            method: Method::Raycast,
            shading: Shading::Transitions(displaced.with_lod(lod)),
            outputs: Outputs::COLOR,
            ..RenderOptions::default()
        };
        render(&prepared, projection.as_ref(), &options).unwrap()
    };
    let finest = run(LodSelection::Finest);
    let footprint = run(LodSelection::Footprint);
    let count = |r: &crate::render::Rendered, key: &str| match r.counters.get(key) {
        Some(crate::render::Counter::Count(n)) => *n,
        _ => panic!("no {key}"),
    };
    let coarse: u64 = LEVEL_KEYS[1..].iter().map(|k| count(&footprint, k)).sum();
    assert!(coarse > 0, "no ray traced a coarser level");
    let finest_coarse: u64 = LEVEL_KEYS[1..].iter().map(|k| count(&finest, k)).sum();
    assert_eq!(finest_coarse, 0);
    assert!(count(&finest, LEVEL_KEYS[0]) > 0);
    let difference = mean_difference(&finest.frame.color, &footprint.frame.color);
    assert!(difference < 0.05, "{difference}");
}
