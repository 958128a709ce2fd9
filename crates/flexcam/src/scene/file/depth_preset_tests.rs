//! Scene syntax of the depth-transition, occlusion, MCOP and magnifier presets: they parse
//! with their keys, and bad values fail at their own FILE:LINE:COLUMN.

use super::tests::{assert_error_at, scene};
use crate::projection::flexible::{DepthStyle, Preset, VolumeSource};
use crate::projection::ProjectionSpec;

/// A flexible preset table: lines 1 to 5 are fixed, the preset's own keys start on line 6.
fn preset(name: &str, keys: &str) -> String {
    format!(
        "[projection]\ntype = \"flexible\"\npreset = \"{name}\"\nposition = [0, 1, 5]\n\
         look_at = [0, 1, 0]\n{keys}"
    )
}

fn parsed(text: &str) -> Preset {
    let s = scene(text);
    let ProjectionSpec::Flexible(spec) = &s.projection else {
        panic!("not flexible");
    };
    let VolumeSource::Preset(p) = &spec.source else {
        panic!("not a preset");
    };
    // Every example builds.
    s.projection.build(64, 48).unwrap();
    p.preset.clone()
}

#[test]
fn the_new_presets_parse_with_their_keys() {
    let p = parsed(&preset(
        "ortho_near_persp_far",
        "fov = 50\ntransition = 4\nclip = [0, 20]\n",
    ));
    assert_eq!(
        p,
        Preset::OrthoNearPerspFar {
            fov: 50.0,
            transition: 4.0,
            style: DepthStyle::Piecewise
        }
    );
    let p = parsed(&preset(
        "depth_transition",
        "fovs = [60, 20]\ntransitions = [5]\nstyle = \"quadratic\"\nclip = [0.5, 20]\n",
    ));
    assert!(matches!(
        p,
        Preset::DepthTransition {
            style: DepthStyle::Quadratic,
            ..
        }
    ));
    parsed(&preset(
        "occlusion",
        "fov = 60\ntransition = 4\npole = [0.5, 0.5]\nstrength = 0.1\nclip = [0, 10]\n",
    ));
    let p = parsed(&preset(
        "mcop",
        "path = [[-1, 1, 5], [1, 1, 5], [2, 1, 4]]\nv_fov = 40\nclip = [0, 30]\n",
    ));
    assert!(matches!(
        p,
        Preset::Mcop {
            directions: None,
            ..
        }
    ));
    parsed(&preset(
        "mcop",
        "path = [[-1, 1, 5], [1, 1, 5]]\ndirections = [[0, 0, -1], [0.3, 0, -1]]\n",
    ));
    parsed(&preset(
        "magnifier",
        "fov = 60\ncenter = [0.5, 0.5]\nradius = 0.2\nmagnification = 2\n",
    ));
}

#[test]
fn bad_values_fail_at_their_key() {
    let cases = [
        (
            preset("ortho_near_persp_far", "fov = 50\ntransition = 40\nclip = [0, 20]\n"),
            (7, 14),
            "transitions must lie strictly between",
        ),
        (
            preset(
                "depth_transition",
                "fovs = [60, 20, 30]\ntransitions = [5, 8]\nstyle = \"quadratic\"\n",
            ),
            (8, 9),
            "joins exactly two views",
        ),
        (
            preset("depth_transition", "fovs = [60, 20]\ntransitions = [5, 8]\n"),
            (6, 8),
            "one transition fewer than fovs",
        ),
        (
            preset("depth_transition", "fovs = [60]\ntransitions = []\nstyle = \"curvy\"\n"),
            (8, 9),
            "unknown style \"curvy\"; expected one of: piecewise, quadratic",
        ),
        (
            preset(
                "occlusion",
                "fov = 60\ntransition = 4\npole = [1.5, 0.5]\nstrength = 0.1\n",
            ),
            (8, 8),
            "pole must lie in the image",
        ),
        (
            preset(
                "occlusion",
                "fov = 60\ntransition = 4\npole = [0.5, 0.5]\nstrength = -1\n",
            ),
            (9, 12),
            "strength must be finite and at least 0",
        ),
        (
            preset("mcop", "path = [[0, 1, 5]]\n"),
            (6, 8),
            "path needs at least 2 points",
        ),
        (
            preset(
                "mcop",
                "path = [[0, 1, 5], [1, 1, 5]]\ndirections = [[0, 0, -1]]\n",
            ),
            (7, 14),
            "one direction per path point",
        ),
        (
            preset(
                "mcop",
                "path = [[0, 1, 5], [1, 1, 5]]\ndirections = [[0, 1, 0], [0, 1, 0]]\n",
            ),
            (7, 14),
            "parallel to `up`",
        ),
        (
            preset(
                "magnifier",
                "fov = 60\ncenter = [0.5, 0.5]\nradius = 0.2\nmagnification = 0.1\n",
            ),
            (9, 17),
            "magnification must be above 1/4",
        ),
        (
            preset(
                "magnifier",
                "fov = 60\ncenter = [0.5, 0.5]\nradius = 0\nmagnification = 2\n",
            ),
            (8, 10),
            "radius must be positive",
        ),
        (
            preset(
                "magnifier",
                "fov = 60\ncenter = [0.5, 0.5]\nradius = 0.2\nmagnification = 2\nreparam = \"polar\"\n",
            ),
            (10, 11),
            "`reparam` is not a parameter of flexible preset \"magnifier\" (it takes: preset, \
             position, look_at, up, clip, fov,",
        ),
        (
            preset("occlusion", "fov = 60\ntransition = 4\nstrength = 0.1\n"),
            (1, 1),
            "flexible projection needs `pole`",
        ),
    ];
    for (text, (line, column), needle) in cases {
        assert_error_at(&text, line, column, needle);
    }
}
