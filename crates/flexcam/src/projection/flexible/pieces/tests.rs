//! Pieces against the closed forms: two off-axis halves of a perspective are that
//! perspective, ray for ray; pixels outside every piece see nothing; the inverse gives each
//! pixel's point back in its own piece only; bad lists are refused with the pieces named.

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::*;
use crate::projection::flexible::tests::{frame, preset};
use crate::projection::flexible::{Preset, Reparam, Surface, VolumeSource};
use crate::projection::ProjectionSpec;

fn pieces(list: Vec<Piece>) -> ProjectionSpec {
    ProjectionSpec::Flexible(Box::new(FlexibleSpec {
        source: VolumeSource::Pieces(list),
        reparam: None,
    }))
}

/// The perspective of horizontal angle `fov` as two off-axis pieces: the left half of the
/// window is the window of angle 2 atan(tan(fov/2) / 2) shifted one half-width left, the
/// right half the same shifted right; each half's vertical extent follows from its aspect.
fn split_perspective(fov: f64, clip: Option<[f64; 2]>) -> ProjectionSpec {
    let half = 2.0 * (0.5 * (0.5 * fov).to_radians().tan()).atan().to_degrees();
    let side = |shift: f64, rect: [f64; 4]| Piece {
        rect,
        spec: preset(
            Preset::OffAxis {
                fov: half,
                shift: DVec2::new(shift, 0.0),
            },
            clip,
        ),
    };
    pieces(vec![
        side(-1.0, [0.0, 0.0, 0.5, 1.0]),
        side(1.0, [0.5, 0.0, 1.0, 1.0]),
    ])
}

#[test]
fn two_off_axis_halves_are_the_perspective() {
    let fov = 70.0;
    let whole = ProjectionSpec::Flexible(Box::new(preset(
        Preset::Perspective { fov },
        Some([0.5, 9.0]),
    )))
    .build(40, 30)
    .unwrap();
    let split = split_perspective(fov, Some([0.5, 9.0]))
        .build(40, 30)
        .unwrap();
    for y in 0..30 {
        for x in 0..40 {
            for offset in [0.5, 0.0, 0.999] {
                let pixel = DVec2::new(f64::from(x) + offset, f64::from(y) + offset);
                let (a, b) = (whole.ray(pixel).unwrap(), split.ray(pixel).unwrap());
                assert!((a.origin - b.origin).length() < 1e-12, "{pixel}");
                assert!((a.direction - b.direction).length() < 1e-12, "{pixel}");
            }
        }
    }
}

#[test]
fn pixels_outside_every_piece_see_nothing() {
    let spec = pieces(vec![Piece {
        rect: [0.25, 0.5, 0.75, 1.0],
        spec: preset(Preset::Perspective { fov: 50.0 }, None),
    }]);
    let p = spec.build(8, 4).unwrap();
    // Columns 2..6, rows 0..2 (v up: the top half).
    for y in 0..4 {
        for x in 0..8 {
            let inside = (2..6).contains(&x) && y < 2;
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            assert_eq!(p.ray(pixel).is_some(), inside, "{x} {y}");
        }
    }
    // The piece is the perspective at the tile's size: its centre looks at look_at.
    let centre = p.ray(DVec2::new(4.0, 1.0)).unwrap();
    let view = (frame().look_at - frame().position).normalize();
    assert!((centre.direction.normalize() - view).length() < 1e-12);
}

#[test]
fn rects_snap_to_pixel_edges_and_empty_ones_are_refused() {
    // 0.3 of 10 pixels is 3: the first piece owns columns 0..3.
    let spec = pieces(vec![
        Piece {
            rect: [0.0, 0.0, 0.3, 1.0],
            spec: preset(Preset::Perspective { fov: 40.0 }, None),
        },
        Piece {
            rect: [0.3, 0.0, 1.0, 1.0],
            spec: preset(Preset::Orthographic { width: 2.0 }, None),
        },
    ]);
    let p = spec.build(10, 5).unwrap();
    let views = p.views();
    assert_eq!(views.len(), 2);
    assert_eq!(
        (views[0].offset, views[0].projection.resolution()),
        ([0, 0], (3, 5))
    );
    assert_eq!(
        (views[1].offset, views[1].projection.resolution()),
        ([3, 0], (7, 5))
    );
    let thin = pieces(vec![Piece {
        rect: [0.5, 0.0, 0.52, 1.0],
        spec: preset(Preset::Perspective { fov: 40.0 }, None),
    }]);
    let e = thin.build(10, 5).err().unwrap().message;
    assert!(
        e.contains("piece 1") && e.contains("covers no whole pixel"),
        "{e}"
    );
    assert!(thin.build(100, 5).is_ok());
}

#[test]
fn bad_lists_are_refused_naming_the_pieces() {
    let piece = |rect| Piece {
        rect,
        spec: preset(Preset::Perspective { fov: 40.0 }, None),
    };
    let cases: Vec<(Vec<Piece>, &str)> = vec![
        (vec![], "1 to 64 pieces"),
        (
            (0..65).map(|_| piece([0.0, 0.0, 1.0, 1.0])).collect(),
            "1 to 64 pieces, got 65",
        ),
        (
            vec![piece([0.5, 0.0, 0.5, 1.0])],
            "piece 1: a piece's `rect`",
        ),
        (vec![piece([0.0, 0.0, 1.0, 1.5])], "0 <= v0 < v1 <= 1"),
        (vec![piece([0.0, f64::NAN, 1.0, 1.0])], "piece 1"),
        (
            vec![
                piece([0.0, 0.0, 0.5, 1.0]),
                piece([0.5, 0.0, 1.0, 0.5]),
                piece([0.4, 0.5, 1.0, 1.0]),
            ],
            "pieces 1 and 3 overlap",
        ),
    ];
    for (list, expected) in cases {
        let e = pieces(list).build(20, 10).err().unwrap().message;
        assert!(e.contains(expected), "{e} (expected {expected})");
    }
    // Touching rectangles (an edge, a corner) are fine.
    let touching = vec![
        piece([0.0, 0.0, 0.5, 0.5]),
        piece([0.5, 0.5, 1.0, 1.0]),
        piece([0.5, 0.0, 1.0, 0.5]),
    ];
    assert!(pieces(touching).build(20, 10).is_ok());
    // A piece's own error comes with its number; a map of its own belongs to the piece.
    let bad = pieces(vec![
        piece([0.0, 0.0, 0.5, 1.0]),
        Piece {
            rect: [0.5, 0.0, 1.0, 1.0],
            spec: preset(Preset::Perspective { fov: 200.0 }, None),
        },
    ]);
    let e = bad.build(20, 10).err().unwrap().message;
    assert!(e.starts_with("piece 2: "), "{e}");
    let mapped = ProjectionSpec::Flexible(Box::new(FlexibleSpec {
        source: VolumeSource::Pieces(vec![piece([0.0, 0.0, 1.0, 1.0])]),
        reparam: Some(Reparam::Polar),
    }));
    let e = mapped.build(20, 10).err().unwrap().message;
    assert!(e.contains("takes no `reparam` of its own"), "{e}");
}

#[test]
fn pieces_are_not_one_volume() {
    let spec = FlexibleSpec {
        source: VolumeSource::Pieces(vec![Piece {
            rect: [0.0, 0.0, 1.0, 1.0],
            spec: preset(Preset::Perspective { fov: 40.0 }, None),
        }]),
        reparam: None,
    };
    let e = Flexible::new(&spec, 8, 8).err().unwrap().message;
    assert!(e.contains("not one volume"), "{e}");
}

#[test]
fn a_piece_without_an_inverse_is_named() {
    let spec = pieces(vec![
        Piece {
            rect: [0.0, 0.0, 0.5, 1.0],
            spec: preset(Preset::Perspective { fov: 40.0 }, None),
        },
        Piece {
            rect: [0.5, 0.0, 1.0, 1.0],
            // Quadratic projectors drawn as polylines: the analytic inverse does not hold.
            spec: FlexibleSpec {
                source: VolumeSource::Blended {
                    surfaces: [1.0, 2.0, 4.0]
                        .map(|z| Surface::rectangle_centred(DVec3::Z * z, DVec3::X, DVec3::Y))
                        .to_vec(),
                    blend: crate::projection::flexible::Blend::Bezier { segments: Some(8) },
                },
                reparam: None,
            },
        },
    ]);
    let p = spec.build(20, 10).unwrap();
    let reason = p.inverse().err().unwrap().reason.unwrap();
    assert!(
        reason.starts_with("piece 2 (rect [0.5, 0.0, 1.0, 1.0])"),
        "{reason}"
    );
    assert!(reason.contains("drawn as polylines"), "{reason}");
}

/// A perspective half, an orthographic quarter and a twisted quarter, with a gap: every
/// piece has an inverse.
fn collage() -> Box<dyn Projection> {
    pieces(vec![
        Piece {
            rect: [0.0, 0.0, 0.5, 1.0],
            spec: preset(Preset::Perspective { fov: 60.0 }, Some([0.2, 30.0])),
        },
        Piece {
            rect: [0.5, 0.5, 1.0, 1.0],
            spec: preset(Preset::Orthographic { width: 4.0 }, Some([0.0, 30.0])),
        },
        Piece {
            rect: [0.5, 0.0, 0.9, 0.5],
            spec: preset(
                Preset::Twist {
                    fov: 50.0,
                    twist: 40.0,
                },
                Some([0.1, 20.0]),
            ),
        },
    ])
    .build(24, 16)
    .unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The point at t on a pixel's projector projects back to that pixel, and every image
    /// the inverse gives lies in the piece whose ray reaches the point.
    #[test]
    fn project_then_ray_gives_the_point_back(
        x in 0.0..24.0f64, y in 0.0..16.0f64, t in 0.01..1.0f64
    ) {
        let p = collage();
        let inverse = p.inverse().unwrap();
        prop_assert!(inverse.charted().is_none());
        let Some(ray) = p.ray(DVec2::new(x, y)) else {
            // Only the gap (columns 22..24 of the bottom half) sees nothing.
            prop_assert!(x >= 22.0 && y >= 8.0);
            return Ok(());
        };
        let point = ray.at(t);
        let mut out = Vec::new();
        inverse.project(point, &mut out);
        let scale = 1.0 + point.length() + ray.direction.length();
        let mine = out.iter().find(|image| (image.pixel - DVec2::new(x, y)).length() < 1e-6);
        prop_assert!(mine.is_some(), "{:?} at {} {}", out, x, y);
        for image in &out {
            let back = p.ray(image.pixel);
            prop_assert!(back.is_some());
            let q = back.unwrap().at(image.t);
            prop_assert!((q - point).length() <= 1e-9 * scale, "{} vs {}", q, point);
        }
    }
}

/// The projection of `scenes/NAME` at its own image size.
fn example(name: &str) -> Box<dyn Projection> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let scene = crate::scene::file::parse(&text, &path).unwrap();
    scene
        .projection
        .build(scene.image.width, scene.image.height)
        .unwrap()
}

/// The line of `ray` as a point on it and a unit direction, to compare rays whatever their
/// start and length.
fn line(ray: Ray) -> (DVec3, DVec3) {
    let d = ray.direction.normalize();
    // The point of the line nearest the origin.
    (ray.origin - d * ray.origin.dot(d), d)
}

/// `scenes/flexible-glc-mosaic.toml`: three GLC tiles whose rays agree on the edges they
/// share (the mosaic is continuous), and whose middle tile is a perspective from the eye
/// 1 m behind the image plane.
#[test]
fn the_glc_mosaic_shares_its_edge_rays() {
    let p = example("flexible-glc-mosaic.toml");
    assert_eq!(p.resolution(), (480, 160));
    assert_eq!(p.views().len(), 3);
    for edge in [160.0, 320.0] {
        for y in [0.0, 0.5, 40.25, 80.0, 159.999] {
            let left = p.ray(DVec2::new(edge - 1e-9, y)).unwrap();
            let right = p.ray(DVec2::new(edge, y)).unwrap();
            let (a, b) = (line(left), line(right));
            assert!((a.1 - b.1).length() < 1e-7, "{edge} {y}: {a:?} {b:?}");
            assert!((a.0 - b.0).length() < 1e-7, "{edge} {y}: {a:?} {b:?}");
        }
    }
    // Rays a column apart differ much more than across the shared edge (the left tile is a
    // pushbroom across: parallel rays, moved along the image plane).
    let (a, b) = (
        line(p.ray(DVec2::new(150.0, 80.0)).unwrap()),
        line(p.ray(DVec2::new(151.0, 80.0)).unwrap()),
    );
    let step = (a.0 - b.0).length() + (a.1 - b.1).length();
    assert!(step > 1e-4, "{step}");
    let forward = DVec3::new(0.0, -0.25, -1.0).normalize();
    let eye = DVec3::new(0.0, 1.6, 6.0) - forward;
    for pixel in [
        DVec2::new(170.5, 10.5),
        DVec2::new(240.0, 80.0),
        DVec2::new(319.5, 150.5),
    ] {
        let ray = p.ray(pixel).unwrap();
        let to_eye = (eye - ray.origin).normalize();
        let d = ray.direction.normalize();
        assert!(
            (to_eye + d).length() < 1e-9,
            "{pixel}: the middle tile's rays meet at the eye"
        );
    }
}

/// `scenes/flexible-single-centre.toml`: every projector starts at the one eye; the top
/// half and the bottom half see overlapping parts of the scene.
#[test]
fn the_single_centre_example_has_one_centre() {
    let p = example("flexible-single-centre.toml");
    let eye = DVec3::new(0.0, 2.5, 7.0);
    for y in (0..240).step_by(7) {
        for x in (0..320).step_by(11) {
            let ray = p
                .ray(DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5))
                .unwrap();
            assert!((ray.origin - eye).length() < 1e-12);
        }
    }
    // The top half's lowest row looks further down than the bottom half's highest row:
    // the band between is imaged twice (figure 6.2's regions o).
    let down = |y: f64| -p.ray(DVec2::new(160.0, y)).unwrap().direction.normalize().y;
    assert!(down(119.5) > down(120.5), "{} {}", down(119.5), down(120.5));
}
