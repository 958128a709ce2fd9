use glam::{DVec2, DVec3};

use super::*;
use crate::projection::camera_basis::CameraBasis;
use crate::projection::flexible::{Blend, FlexibleSpec, Preset, PresetSpec, Surface, VolumeSource};
use crate::projection::{CameraFrame, ProjectionSpec};

fn frame() -> CameraFrame {
    CameraFrame {
        position: DVec3::new(1.0, 2.0, 3.0),
        look_at: DVec3::new(-1.0, 1.0, -2.0),
        up: DVec3::Y,
    }
}

fn options(projectors: u32) -> VolumeOptions {
    VolumeOptions {
        projectors,
        surface_steps: 4,
        grid_cells: 4,
        grid_at: None,
        reach: 7.0,
    }
}

fn names(g: &VolumeGeometry) -> Vec<&str> {
    g.parts.iter().map(|p| p.name.as_str()).collect()
}

fn part<'a>(g: &'a VolumeGeometry, name: &str) -> &'a Part {
    g.parts.iter().find(|p| p.name == name).unwrap()
}

/// The polylines of a part's segments (consecutive segments sharing a vertex joined).
fn polylines(part: &Part) -> Vec<Vec<DVec3>> {
    let mut lines: Vec<Vec<DVec3>> = Vec::new();
    let mut last = None;
    for &[a, b] in &part.segments {
        if last != Some(a) {
            lines.push(vec![part.points[a]]);
        }
        lines.last_mut().unwrap().push(part.points[b]);
        last = Some(b);
    }
    lines
}

fn flexible(preset: Preset, clip: [f64; 2]) -> Box<dyn Projection> {
    let spec = FlexibleSpec {
        source: VolumeSource::Preset(PresetSpec {
            preset,
            frame: frame(),
            clip: Some(clip),
        }),
        reparam: None,
    };
    ProjectionSpec::Flexible(Box::new(spec))
        .build(40, 30)
        .unwrap()
}

/// A single-viewpoint camera has no control surfaces: its projectors start at the eye, run
/// `reach` along the camera's own rays, and the image grid lies at 1/5 of that by default.
#[test]
fn a_pinhole_is_drawn_as_rays_from_its_eye() {
    let f = frame();
    let camera = ProjectionSpec::Perspective {
        frame: f,
        fov: 60.0,
    }
    .build(40, 30)
    .unwrap();
    let g = VolumeGeometry::of(camera.as_ref(), &options(5)).unwrap();
    assert_eq!(names(&g), ["projectors", "image_grid"]);
    let rays = polylines(part(&g, "projectors"));
    assert_eq!(rays.len(), 25);
    let corner = camera.ray(DVec2::ZERO).unwrap().direction.normalize();
    for (k, ray) in rays.iter().enumerate() {
        assert_eq!(ray.len(), 2);
        assert!((ray[0] - f.position).length() < 1e-12);
        assert!(((ray[1] - ray[0]).length() - 7.0).abs() < 1e-9);
        if k == 0 {
            assert!(((ray[1] - ray[0]).normalize() - corner).length() < 1e-12);
        }
    }
    let grid = part(&g, "image_grid");
    assert!(grid.segments.len() >= 2 * 5 * 4 * GRID_LINE_STEPS as usize);
    for p in &grid.points {
        assert!(((*p - f.position).length() - 1.4).abs() < 1e-9, "{p}");
    }
}

/// A flexible preset between clip planes 1 and 5: the near and far rectangles lie on those
/// planes, each projector runs from one to the other, and the image grid lies on the near
/// surface (or at `grid_at`).
#[test]
fn a_flexible_volume_is_drawn_between_its_control_surfaces() {
    let basis = CameraBasis::new(&frame()).unwrap();
    let depth = |p: DVec3| basis.to_local(p - basis.origin).z;
    let camera = flexible(Preset::Perspective { fov: 60.0 }, [1.0, 5.0]);
    let g = VolumeGeometry::of(camera.as_ref(), &options(3)).unwrap();
    assert_eq!(
        names(&g),
        ["near_surface", "far_surface", "projectors", "image_grid"]
    );
    for (name, d) in [("near_surface", 1.0), ("far_surface", 5.0)] {
        let s = part(&g, name);
        assert_eq!(s.points.len(), 25);
        assert_eq!(s.triangles.len(), 32);
        assert!(s.points.iter().all(|p| (depth(*p) - d).abs() < 1e-12));
    }
    // The far rectangle is 5 times as wide as the near one: 25 times the area.
    let ratio = part(&g, "far_surface").area() / part(&g, "near_surface").area();
    assert!((ratio - 25.0).abs() < 1e-9, "{ratio}");
    for line in polylines(part(&g, "projectors")) {
        assert!((depth(line[0]) - 1.0).abs() < 1e-12);
        assert!((depth(*line.last().unwrap()) - 5.0).abs() < 1e-12);
    }
    let grid = part(&g, "image_grid");
    assert!(grid.points.iter().all(|p| (depth(*p) - 1.0).abs() < 1e-12));
    let halfway = VolumeOptions {
        grid_at: Some(0.5),
        ..options(3)
    };
    let g = VolumeGeometry::of(camera.as_ref(), &halfway).unwrap();
    let grid = part(&g, "image_grid");
    assert!(grid.points.iter().all(|p| (depth(*p) - 3.0).abs() < 1e-12));
}

/// Degenerate: a near surface that is the eye (clip from 0) has no triangles, is not
/// written, and the image grid goes to the far surface.
#[test]
fn a_point_near_surface_is_left_out_and_the_grid_goes_far() {
    let basis = CameraBasis::new(&frame()).unwrap();
    let camera = flexible(Preset::Perspective { fov: 60.0 }, [0.0, 5.0]);
    let g = VolumeGeometry::of(camera.as_ref(), &options(3)).unwrap();
    assert!(part(&g, "near_surface").is_empty());
    let grid = part(&g, "image_grid");
    assert!(grid
        .points
        .iter()
        .all(|p| (basis.to_local(*p - basis.origin).z - 5.0).abs() < 1e-12));
    let obj = g.obj(&[], "v.mtl");
    assert!(!obj.contains("near_surface"), "{obj}");
    assert!(!g.mtl().contains("near_surface"));
}

/// Three rectangles blended as a quadratic Bezier volume: three control surfaces (the
/// middle one a control net), each projector drawn in CURVE_STEPS steps from Q(u, v, 0) to
/// Q(u, v, 1) through Q(u, v, 1/2).
#[test]
fn curved_projectors_are_drawn_in_steps() {
    let rect = |z: f64, x: f64, half: f64| {
        Surface::rectangle_centred(
            DVec3::new(x, 0.0, z),
            DVec3::new(half, 0.0, 0.0),
            DVec3::new(0.0, 0.75 * half, 0.0),
        )
    };
    let spec = FlexibleSpec {
        source: VolumeSource::Blended {
            surfaces: vec![
                rect(0.0, 0.0, 1.0),
                rect(-2.0, 1.5, 2.0),
                rect(-4.0, 0.0, 4.0),
            ],
            blend: Blend::Bezier { segments: None },
        },
        reparam: None,
    };
    let camera = ProjectionSpec::Flexible(Box::new(spec))
        .build(40, 30)
        .unwrap();
    let g = VolumeGeometry::of(camera.as_ref(), &options(2)).unwrap();
    assert_eq!(
        names(&g),
        [
            "near_surface",
            "surface_2",
            "far_surface",
            "projectors",
            "image_grid"
        ]
    );
    let flexible = camera.flexible().unwrap();
    let lines = polylines(part(&g, "projectors"));
    assert_eq!(lines.len(), 4);
    let pixels = [(0.0, 0.0), (40.0, 0.0), (0.0, 30.0), (40.0, 30.0)];
    for (line, (x, y)) in lines.iter().zip(pixels) {
        assert_eq!(line.len(), CURVE_STEPS + 1);
        let pixel = DVec2::new(x, y);
        for (k, t) in [(0, 0.0), (CURVE_STEPS / 2, 0.5), (CURVE_STEPS, 1.0)] {
            let want = flexible.point(pixel, t).unwrap();
            assert!((line[k] - want).length() < 1e-12, "{x} {y} {t}");
        }
    }
}

/// A 180-degree fisheye on a square image sees nothing in the corners: the corner
/// projectors are skipped and the grid's edge lines break (only the middle of each edge
/// line touches the circle).
#[test]
fn positions_without_projectors_are_skipped() {
    let camera = ProjectionSpec::Fisheye {
        frame: frame(),
        fov: 180.0,
    }
    .build(30, 30)
    .unwrap();
    let g = VolumeGeometry::of(camera.as_ref(), &options(3)).unwrap();
    // Of the 3 x 3 positions the four corners have no projector.
    assert_eq!(polylines(part(&g, "projectors")).len(), 5);
    let grid = part(&g, "image_grid");
    let full = 2 * 5 * (4 * GRID_LINE_STEPS as usize);
    assert!(grid.segments.len() < full, "{}", grid.segments.len());
    assert!(!grid.segments.is_empty());
}

/// Tubes: eight triangles per segment, every corner at the radius from the segment's line,
/// the segments gone; a zero-length segment gives none.
#[test]
fn tubes_surround_the_segments() {
    let mut part = Part::new("p".to_string(), PartKind::Projectors, [1.0, 0.0, 0.0]);
    part.add_polyline(&[
        DVec3::ZERO,
        DVec3::new(1.0, 2.0, 2.0),
        DVec3::new(1.0, 2.0, 2.0),
    ]);
    let g = VolumeGeometry { parts: vec![part] }
        .with_tubes(0.01)
        .unwrap();
    let tube = &g.parts[0];
    assert!(tube.segments.is_empty());
    assert_eq!(tube.triangles.len(), 8);
    let axis = DVec3::new(1.0, 2.0, 2.0) / 3.0;
    for p in &tube.points {
        let off_axis = *p - p.dot(axis) * axis;
        assert!((off_axis.length() - 0.01).abs() < 1e-12, "{p}");
    }
    assert!(tube.area() > 0.0);
    assert!(g.with_tubes(0.0).is_err());
    assert!(g.with_tubes(f64::NAN).is_err());
}

/// The OBJ names its MTL and has one object with its material per non-empty part, a `v` per
/// point, an `f` per triangle and an `l` of two vertices per segment, indices counted
/// across parts; the MTL defines each material.
#[test]
fn obj_and_mtl_text() {
    let camera = flexible(Preset::Perspective { fov: 60.0 }, [1.0, 5.0]);
    let g = VolumeGeometry::of(camera.as_ref(), &options(2)).unwrap();
    let obj = g.obj(&["made by a test".to_string()], "v.mtl");
    let count = |word: &str| obj.lines().filter(|l| l.starts_with(word)).count();
    let points: usize = g.parts.iter().map(|p| p.points.len()).sum();
    let triangles: usize = g.parts.iter().map(|p| p.triangles.len()).sum();
    let segments: usize = g.parts.iter().map(|p| p.segments.len()).sum();
    assert!(obj.starts_with("# made by a test\nmtllib v.mtl\n"), "{obj}");
    assert_eq!(
        (count("v "), count("f "), count("l ")),
        (points, triangles, segments)
    );
    assert_eq!(count("o "), 4);
    let mtl = g.mtl();
    for part in &g.parts {
        assert!(obj.contains(&format!("o {0}\nusemtl {0}\n", part.name)));
        assert!(mtl.contains(&format!("newmtl {}\nKd ", part.name)));
    }
    let top = obj
        .lines()
        .filter_map(|l| l.strip_prefix("l "))
        .flat_map(|l| l.split(' ').map(|i| i.parse::<usize>().unwrap()))
        .max();
    assert_eq!(top, Some(points));
    assert_eq!(mtl.matches("Ke ").count(), 2);
    assert_eq!(mtl.matches("d 0.5").count(), 2);
}

#[test]
fn options_out_of_range_are_refused() {
    let camera = flexible(Preset::Perspective { fov: 60.0 }, [1.0, 5.0]);
    for bad in [
        VolumeOptions {
            projectors: 0,
            ..options(3)
        },
        VolumeOptions {
            surface_steps: MAX_SAMPLES + 1,
            ..options(3)
        },
        VolumeOptions {
            grid_cells: 0,
            ..options(3)
        },
        VolumeOptions {
            grid_at: Some(1.5),
            ..options(3)
        },
        VolumeOptions {
            reach: 0.0,
            ..options(3)
        },
        VolumeOptions {
            reach: f64::INFINITY,
            ..options(3)
        },
    ] {
        assert!(
            VolumeGeometry::of(camera.as_ref(), &bad).is_err(),
            "{bad:?}"
        );
    }
}
