use super::*;
use crate::projection::flexible::presets::{Preset, PresetSpec};
use crate::projection::CameraFrame;

/// A perspective volume with horizontal field of view `fov` (degrees), aspect 3:4, its
/// control surfaces at the distances `clip`: the test fixture of grids and fits.
pub(crate) fn perspective_volume(fov: f64, clip: [f64; 2]) -> LinearVolume {
    preset_volume(Preset::Perspective { fov }, clip)
}

/// `preset` seen from the fixture's camera, aspect 3:4, its control surfaces at the
/// distances `clip`.
pub(crate) fn preset_volume(preset: Preset, clip: [f64; 2]) -> LinearVolume {
    let spec = PresetSpec {
        preset,
        frame: CameraFrame {
            position: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
        },
        clip: Some(clip),
    };
    let (near, far) = spec.surfaces(0.75).unwrap();
    LinearVolume::new(near, far).unwrap()
}

fn uv_samples() -> impl Iterator<Item = DVec2> {
    (0..=12).flat_map(|i| (0..=12).map(move |j| DVec2::new(i as f64, j as f64) / 12.0))
}

#[test]
fn a_bilinear_grid_reproduces_a_perspective_volume_exactly() {
    let volume = perspective_volume(70.0, [1.0, 50.0]);
    let grid = ProjectorGrid::sample(&volume, (5, 5), GridInterpolation::Bilinear).unwrap();
    for uv in uv_samples() {
        for t in [0.0, 0.3, 1.0] {
            let (a, b) = (grid.point(uv, t), volume.point(uv, t));
            assert!((a - b).length() < 1e-12 * b.length().max(1.0), "{uv} {t}");
        }
    }
}

#[test]
fn a_bezier_grid_of_a_bilinear_volume_is_that_volume_too() {
    // Degree elevation: control points sampled from a (bi)linear function on a uniform
    // grid are that function's Bezier control points, so the patch reproduces it.
    let volume = perspective_volume(40.0, [1.0, 50.0]);
    let grid = ProjectorGrid::sample(&volume, (5, 4), GridInterpolation::Bezier).unwrap();
    for uv in uv_samples() {
        let (a, b) = (grid.point(uv, 1.0), volume.point(uv, 1.0));
        assert!((a - b).length() < 1e-9 * b.length(), "{uv}: {a} vs {b}");
    }
}

#[test]
fn weights_are_a_partition_of_unity_and_bilinear_meets_every_node() {
    let volume = perspective_volume(60.0, [1.0, 50.0]);
    for interpolation in [GridInterpolation::Bilinear, GridInterpolation::Bezier] {
        let grid = ProjectorGrid::sample(&volume, (4, 3), interpolation).unwrap();
        for uv in uv_samples().chain([DVec2::new(-0.5, 2.0)]) {
            let mut sum = 0.0;
            grid.for_each_weight(uv, |_, w| sum += w);
            assert!((sum - 1.0).abs() < 1e-12, "{interpolation:?} {uv}");
        }
    }
    let mut grid = ProjectorGrid::sample(&volume, (4, 3), GridInterpolation::Bilinear).unwrap();
    grid.aim(2, 1, DVec3::new(3.0, 2.0, 0.0)).unwrap();
    let uv = grid.node_uv(2, 1);
    let ray = grid.ray(uv).unwrap();
    let to_hit = DVec3::new(3.0, 2.0, 0.0) - ray.origin;
    assert!(ray.direction.normalize().dot(to_hit.normalize()) > 1.0 - 1e-12);
}

#[test]
fn bezier_meets_only_the_corner_projectors() {
    let volume = perspective_volume(60.0, [1.0, 50.0]);
    let mut grid = ProjectorGrid::sample(&volume, (5, 5), GridInterpolation::Bezier).unwrap();
    let before = grid.point(grid.node_uv(2, 2), 1.0);
    grid.aim(2, 2, DVec3::new(4.0, 0.0, 0.0)).unwrap();
    let after = grid.point(grid.node_uv(2, 2), 1.0);
    assert!((after - before).length() > 1e-3, "the centre moved");
    assert_ne!(
        after,
        grid.ends()[12],
        "the centre is approximated, not met"
    );
    for (c, r) in [(0, 0), (4, 0), (0, 4), (4, 4)] {
        let j = r * 5 + c;
        let p = grid.point(grid.node_uv(c, r), 1.0);
        assert!((p - grid.ends()[j]).length() < 1e-12);
    }
}

#[test]
fn aiming_keeps_the_length_unless_the_hit_is_farther() {
    let volume = perspective_volume(60.0, [1.0, 50.0]);
    let mut grid = ProjectorGrid::sample(&volume, (3, 3), GridInterpolation::Bilinear).unwrap();
    let length = (grid.ends()[4] - grid.starts()[4]).length();
    let near_hit = grid.starts()[4] + DVec3::new(1.0, 0.0, 0.0);
    grid.aim(1, 1, near_hit).unwrap();
    assert!(((grid.ends()[4] - grid.starts()[4]).length() - length).abs() < 1e-9);
    let far_hit = grid.starts()[4] + DVec3::new(0.0, 0.0, -10.0 * length);
    grid.aim(1, 1, far_hit).unwrap();
    let new_length = (grid.ends()[4] - grid.starts()[4]).length();
    assert!((new_length - 10.1 * length).abs() < 1e-9 * new_length);
}

#[test]
fn degenerate_grids_and_aims_are_errors() {
    let volume = perspective_volume(60.0, [1.0, 50.0]);
    let bilinear = GridInterpolation::Bilinear;
    for size in [(1, 5), (5, 10), (0, 0)] {
        let e = ProjectorGrid::sample(&volume, size, bilinear).unwrap_err();
        assert!(e.message.contains("must be from 2 to 9"), "{e}");
    }
    let e = ProjectorGrid::new((2, 2), vec![DVec3::ZERO; 4], vec![DVec3::ZERO; 3], bilinear)
        .unwrap_err();
    assert!(e.message.contains("needs 4 start and end points"), "{e}");
    let e = ProjectorGrid::new((2, 2), vec![DVec3::ZERO; 4], vec![DVec3::ZERO; 4], bilinear)
        .unwrap_err();
    assert!(e.message.contains("node (0, 0) has zero length"), "{e}");
    let mut ends = vec![DVec3::ONE; 4];
    ends[3] = DVec3::NAN;
    let e = ProjectorGrid::new((2, 2), vec![DVec3::ZERO; 4], ends, bilinear).unwrap_err();
    assert!(
        e.message.contains("node (1, 1) has a non-finite point"),
        "{e}"
    );
    let mut grid = ProjectorGrid::sample(&volume, (3, 3), bilinear).unwrap();
    assert!(grid.aim(3, 0, DVec3::ZERO).is_err());
    let start = grid.starts()[0];
    let e = grid.aim(0, 0, start).unwrap_err();
    assert!(e.message.contains("cannot be aimed"), "{e}");
}

/// A 3 x 3 bilinear grid of the test perspective with node (1, 1) curved sideways.
fn curved_grid(tangent: DVec3) -> ProjectorGrid {
    let volume = perspective_volume(60.0, [1.0, 30.0]);
    let mut grid = ProjectorGrid::sample(&volume, (3, 3), GridInterpolation::Bilinear).unwrap();
    let (start, end) = (grid.starts()[4], grid.ends()[4]);
    grid.set_projector((1, 1), start, end, Some(tangent))
        .unwrap();
    grid
}

#[test]
fn a_tangent_curves_its_node_projector_from_start_to_end() {
    let tangent = DVec3::new(3.0, 1.0, -1.0);
    let grid = curved_grid(tangent);
    assert!(grid.is_curved());
    let uv = grid.node_uv(1, 1);
    let (start, end) = (grid.starts()[4], grid.ends()[4]);
    assert!((grid.point(uv, 0.0) - start).length() < 1e-12 * start.length());
    assert!((grid.point(uv, 1.0) - end).length() < 1e-12 * end.length());
    let leaving = grid.tangent(uv, 0.0).normalize();
    assert!(
        leaving.cross(tangent.normalize()).length() < 1e-12,
        "{leaving}"
    );
    assert!(leaving.dot(tangent) > 0.0);
    // Halfway it is off the straight chord, and dQ/dt is the derivative of Q.
    let mid = grid.point(uv, 0.5);
    let off = (mid - start).cross((end - start).normalize()).length();
    assert!(off > 0.1, "{off}");
    let h = 1e-6;
    for t in [0.0, 0.3, 1.0] {
        let numeric = (grid.point(uv, t + h) - grid.point(uv, t - h)) / (2.0 * h);
        let exact = grid.tangent(uv, t);
        assert!((numeric - exact).length() < 1e-6 * exact.length(), "{t}");
    }
    // The projector is the quadratic of the blended control points; the neighbours'
    // control points are their midpoints, so the curve fades out across the cells.
    let p = grid.control_points(uv);
    assert_eq!(grid.projector(uv), Some(Projector::QuadraticBezier(p)));
    assert_eq!(grid.ray(uv), None);
    let corner = grid.control_points(DVec2::ZERO);
    assert!((corner[1] - 0.5 * (corner[0] + corner[2])).length() < 1e-12 * corner[1].length());
    let between = grid.control_points(DVec2::new(0.25, 0.5));
    let straight_between = 0.5 * (between[0] + between[2]);
    assert!((between[1] - straight_between).length() > 1e-3);
}

#[test]
fn zero_and_along_the_chord_tangents_are_straight_and_opposite_ones_are_errors() {
    let volume = perspective_volume(60.0, [1.0, 30.0]);
    let straight = ProjectorGrid::sample(&volume, (3, 3), GridInterpolation::Bilinear).unwrap();
    let (start, end) = (straight.starts()[4], straight.ends()[4]);
    for tangent in [DVec3::ZERO, 3.7 * (end - start), (end - start) / 11.0] {
        let mut grid = straight.clone();
        grid.set_projector((1, 1), start, end, Some(tangent))
            .unwrap();
        assert_eq!(grid, straight, "{tangent}");
    }
    for tangent in [start - end, -0.01 * (end - start)] {
        let mut grid = straight.clone();
        let e = grid
            .set_projector((1, 1), start, end, Some(tangent))
            .unwrap_err();
        assert!(e.message.contains("node (1, 1): the tangent"), "{e}");
        assert!(e.message.contains("fold it over itself"), "{e}");
    }
    // Nearly opposite is a (sharp) curve, not an error.
    let nearly = start - end + DVec3::new(0.0, 1e-3, 0.0);
    assert!(curved_grid(nearly).is_curved());
    let mut grid = straight.clone();
    let e = grid
        .set_projector((1, 1), start, end, Some(DVec3::new(f64::NAN, 0.0, 0.0)))
        .unwrap_err();
    assert!(e.message.contains("non-finite point or tangent"), "{e}");
    assert!(grid.set_projector((3, 1), start, end, None).is_err());
}

#[test]
fn aiming_and_new_ends_keep_a_tangent() {
    let tangent = DVec3::new(1.0, 0.5, -1.0).normalize();
    let mut grid = curved_grid(tangent);
    grid.aim(1, 1, DVec3::new(2.0, 0.0, -3.0)).unwrap();
    assert_eq!(grid.tangents()[4], stable_unit(tangent));
    let moved = grid.with_ends(grid.ends().to_vec()).unwrap();
    assert_eq!(moved, grid);
    assert!(!grid.straightened().is_curved());
    assert_eq!(grid.straightened().ends(), grid.ends());
}

#[test]
fn stored_tangents_are_stored_again_unchanged() {
    for k in 0..200 {
        let k = f64::from(k);
        let v = DVec3::new((k * 0.37).sin(), (k * 1.91).cos() * 3.0, 0.1 + k.sqrt());
        let unit = stable_unit(v).unwrap();
        assert_eq!(stable_unit(unit), Some(unit), "{v}");
        assert!((unit - v.normalize()).length() < 1e-15);
    }
    assert_eq!(stable_unit(DVec3::ZERO), None);
}

#[test]
fn opposite_node_projectors_can_cancel_to_no_ray() {
    let bilinear = GridInterpolation::Bilinear;
    let starts = vec![DVec3::ZERO; 4];
    let ends = vec![DVec3::X, DVec3::X, -DVec3::X, -DVec3::X];
    let grid = ProjectorGrid::new((2, 2), starts, ends, bilinear).unwrap();
    assert_eq!(grid.ray(DVec2::new(0.5, 0.5)), None);
    assert!(grid.ray(DVec2::new(0.3, 0.25)).is_some());
}
