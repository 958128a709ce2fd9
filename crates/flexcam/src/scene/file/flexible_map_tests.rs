//! Scene-file tests of the user-defined grid map (`reparam = "grid"`), the refusal of
//! spherical maps on flat surfaces, and the static blend `[projection.interpolate]`.

use std::path::Path;

use super::tests::{assert_error_at, scene};
use super::*;
use crate::projection::flexible::reparam::SampleInterpolation;
use crate::projection::flexible::{FlexibleSpec, Reparam, VolumeSource};
use crate::projection::ProjectionSpec;

const HEAD: &str = "[projection]\ntype = \"flexible\"\npreset = \"perspective\"\n\
                    position = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 60\n";

/// The 1-based line and column of the first `needle` in `text`.
fn position(text: &str, needle: &str) -> (usize, usize) {
    let offset = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle} not in {text}"));
    super::source::Source::new(text, Path::new("s.toml")).line_column(offset)
}

/// Asserts that `text` is refused at the first `at` with a message containing `needle`.
fn refused_at(text: &str, at: &str, needle: &str) {
    let (line, column) = position(text, at);
    assert_error_at(text, line, column, needle);
}

fn flexible(text: &str) -> FlexibleSpec {
    match scene(text).projection {
        ProjectionSpec::Flexible(spec) => *spec,
        other => panic!("not flexible: {}", other.kind()),
    }
}

/// A 3 x 2 grid map table with the samples `uv`.
fn grid(uv: &str, extra: &str) -> String {
    format!("{HEAD}reparam = \"grid\"\nreparam_grid = {{ size = [3, 2], {extra}uv = [{uv}] }}\n")
}

const SAMPLES: &str = "[0, 0], [0.4, 0], [1, 0], [0, 1], [0.6, 1], [1, 1]";

#[test]
fn grid_maps_parse_inline() {
    let spec = flexible(&grid(SAMPLES, "interpolation = \"bicubic\", "));
    let Some(Reparam::Grid(map)) = spec.reparam else {
        panic!("not a grid: {:?}", spec.reparam);
    };
    assert_eq!((map.columns(), map.rows()), (3, 2));
    assert_eq!(map.interpolation(), SampleInterpolation::Bicubic);
    let spec = flexible(&grid(SAMPLES, ""));
    assert!(matches!(
        spec.reparam,
        Some(Reparam::Grid(ref g)) if g.interpolation() == SampleInterpolation::Bilinear
    ));
}

#[test]
fn bad_grid_maps_are_refused_at_their_values() {
    // The middle bottom sample beyond the right one: cell (1, 0) folds.
    let folded = "[0, 0], [1.2, 0], [1, 0], [0, 1], [0.6, 1], [1, 1]";
    let text = grid(folded, "");
    refused_at(&text, "[1.2, 0]", "cell (1, 0)");
    let text = grid("[0, 0], [0.4, 0], [1, 0], [0, 1], [0.6, 1]", "");
    refused_at(&text, "[[0, 0]", "needs 6 samples [u, v], got 5");
    let text = grid("[0, 0], [0.4, nan], [1, 0], [0, 1], [0.6, 1], [1, 1]", "");
    refused_at(&text, "[0.4, nan]", "`uv`");
    let text = grid(SAMPLES, "interpolation = \"cubic\", ");
    refused_at(
        &text,
        "\"cubic\"",
        "unknown uv grid interpolation \"cubic\"",
    );
    let text = grid(SAMPLES, "").replace("size = [3, 2]", "size = [1, 2]");
    refused_at(&text, "[1, 2]", "must each be 2 to 129, got 1");
    let text = format!("{HEAD}reparam = \"grid\"\n");
    refused_at(&text, "\"grid\"", "reparam = \"grid\" needs `reparam_grid");
    let text = format!("{HEAD}reparam_grid = {{ size = [2, 2], uv = [] }}\n");
    refused_at(
        &text,
        "{ size",
        "`reparam_grid` belongs to reparam = \"grid\"",
    );
    let text = grid(SAMPLES, "file = \"g.txt\", ");
    refused_at(&text, "[[0, 0]", "either `uv` or `file`, not both");
    let text = format!("{HEAD}reparam = \"grid\"\nreparam_grid = {{ size = [2, 2] }}\n");
    refused_at(&text, "{ size", "needs its samples");
}

#[test]
fn grid_files_are_read_and_their_folds_named_by_line_and_column() {
    let dir = tempfile::TempDir::new().unwrap();
    let text =
        format!("{HEAD}reparam = \"grid\"\nreparam_grid = {{ size = [3, 2], file = \"g.txt\" }}\n");
    let path = dir.path().join("s.toml");
    std::fs::write(
        dir.path().join("g.txt"),
        "# bottom row\n0 0  0.4 0  1 0\n0 1  0.6 1  1 1\n",
    )
    .unwrap();
    let spec = parse(&text, &path).unwrap();
    let ProjectionSpec::Flexible(spec) = spec.projection else {
        panic!("not flexible");
    };
    assert!(matches!(spec.reparam, Some(Reparam::Grid(_))));
    std::fs::write(
        dir.path().join("g.txt"),
        "0 0  0.4 0  1 0\n0 1  1.6 1  1 1\n",
    )
    .unwrap();
    let e = parse(&text, &path).unwrap_err().to_string();
    let want = format!(
        "{}:1:6: uv grid cell (1, 0)",
        dir.path().join("g.txt").display()
    );
    assert!(e.starts_with(&want), "{e}");
}

#[test]
fn spherical_maps_on_flat_surfaces_are_refused_naming_both() {
    let surfaces = "near = { surface = \"point\", point = [0, 0, 0] }\n\
                    far = { surface = \"rectangle\", center = [0, 0, -1], u_axis = [1, 0, 0], \
                    v_axis = [0, 1, 0] }\n";
    for map in ["polar", "lens", "mercator", "equal_area"] {
        let text = format!("[projection]\ntype = \"flexible\"\n{surfaces}reparam = \"{map}\"\n");
        refused_at(
            &text,
            &format!("\"{map}\""),
            &format!("reparam \"{map}\" does not go with flat control surfaces (point, rectangle)"),
        );
    }
    let blended = "[projection]\ntype = \"flexible\"\nreparam = \"polar\"\nsurfaces = [\
                   { surface = \"point\", point = [0, 0, 0] }, \
                   { surface = \"rectangle\", center = [0, 0, -1], u_axis = [1, 0, 0], v_axis = [0, 1, 0] }, \
                   { surface = \"rectangle\", center = [0, 0, -2], u_axis = [2, 0, 0], v_axis = [0, 2, 0] }]\n";
    refused_at(blended, "\"polar\"", "(point, rectangle, rectangle)");
    // A hemisphere among them gives the map its angles.
    let fisheye = "[projection]\ntype = \"flexible\"\nreparam = \"polar\"\n\
                   near = { surface = \"point\", point = [0, 0, 0] }\n\
                   far = { surface = \"hemisphere\", center = [0, 0, 0], radius = 5, axis = [0, 0, -1], front = [1, 0, 0] }\n";
    assert_eq!(flexible(fisheye).reparam, Some(Reparam::Polar));
}

/// `[projection.interpolate]` of `weight` between a perspective and `second` (the lines of a
/// flexible table after `type`).
fn blend(weight: &str, second: &str) -> String {
    format!(
        "[projection]\ntype = \"flexible\"\n[projection.interpolate]\nweight = {weight}\n\
         [projection.interpolate.first]\n{}\n[projection.interpolate.second]\n\
         type = \"flexible\"\n{second}",
        &HEAD["[projection]\n".len()..]
    )
}

const FISHEYE: &str =
    "preset = \"fisheye\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 180\n";

const PUSHBROOM: &str = "preset = \"pushbroom\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n\
                         width = 3\nv_fov = 60\n";

#[test]
fn static_blends_parse_with_any_weight() {
    for weight in ["0.25", "1.5", "-0.75"] {
        let spec = flexible(&blend(weight, PUSHBROOM));
        let VolumeSource::Interpolated {
            weight: a,
            first,
            second,
        } = spec.source
        else {
            panic!("not a blend");
        };
        assert_eq!(a, weight.parse::<f64>().unwrap());
        assert!(matches!(first.source, VolumeSource::Preset(_)));
        assert!(matches!(second.source, VolumeSource::Preset(_)));
    }
}

#[test]
fn bad_static_blends_are_refused_at_their_place() {
    let text = blend("nan", FISHEYE);
    refused_at(&text, "nan", "`weight`");
    let text = blend("0.5", FISHEYE).replace(
        "[projection.interpolate]",
        "fov = 40\n[projection.interpolate]",
    );
    refused_at(
        &text,
        "40\n[projection.interpolate]",
        "`fov` is not a parameter of flexible projections given by `interpolate`",
    );
    let text = blend("0.5", FISHEYE).replace(
        "type = \"flexible\"\npreset = \"fisheye\"",
        "type = \"fisheye\"",
    );
    refused_at(
        &text,
        "\"fisheye\"",
        "`interpolate`'s `first` and `second` need type = \"flexible\"",
    );
    // An orthographic view and its mirror through the eye: halfway every projector vanishes.
    let ortho = |z: &str| {
        format!(
            "preset = \"orthographic\"\nposition = [0, 0, 0]\nlook_at = [0, 0, {z}]\nwidth = 2\n\
             clip = [0, 1]\n"
        )
    };
    let text = format!(
        "[projection]\ntype = \"flexible\"\n[projection.interpolate]\nweight = 0.5\n\
         [projection.interpolate.first]\ntype = \"flexible\"\n{}\
         [projection.interpolate.second]\ntype = \"flexible\"\n{}",
        ortho("1"),
        ortho("-1")
    );
    refused_at(&text, "[projection.interpolate]\n", "interpolation");
}
