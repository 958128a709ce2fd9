//! Tests of the scene-file format: defaults, conversions and every kind of error.

use std::path::Path;

use glam::{Affine3A, DVec3, Vec3};

use super::*;
use crate::projection::flexible::{Preset, VolumeSource};
use crate::projection::ProjectionSpec;
use crate::scene::{Finish, Light, Pattern};

/// A valid projection table of five lines, so objects written after it start on line 6.
const CAMERA: &str = "[projection]
type = \"perspective\"
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 60
";

fn parse_text(text: &str) -> Result<Scene> {
    parse(text, Path::new("dir/s.toml"))
}

pub(super) fn scene(text: &str) -> Scene {
    parse_text(text).unwrap_or_else(|e| panic!("scene should parse: {e}"))
}

/// The one-line error message of an invalid scene.
fn error(text: &str) -> String {
    match parse_text(text) {
        Ok(_) => panic!("scene should not parse:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// Asserts the error starts with `dir/s.toml:LINE:COLUMN:` and mentions `needle`.
pub(super) fn assert_error_at(text: &str, line: usize, column: usize, needle: &str) {
    let message = error(text);
    let prefix = format!("dir/s.toml:{line}:{column}: ");
    assert!(
        message.starts_with(&prefix),
        "expected {prefix}... got: {message}"
    );
    assert!(
        message.contains(needle),
        "expected {needle:?} in: {message}"
    );
    assert!(!message.contains('\n'), "not one line: {message}");
}

/// Asserts the error is positioned in the file and mentions `needle`.
fn assert_error(text: &str, needle: &str) {
    let message = error(text);
    assert!(message.starts_with("dir/s.toml:"), "no file in: {message}");
    assert!(
        message.contains(needle),
        "expected {needle:?} in: {message}"
    );
}

fn object(body: &str) -> String {
    format!("{CAMERA}[[object]]\n{body}")
}

#[test]
fn minimal_scene_gets_defaults() {
    let s = scene(CAMERA);
    assert_eq!(s.image, ImageSettings::default());
    assert!(s.objects.is_empty() && s.lights.is_empty());
    assert_eq!(s.base_dir.as_deref(), Some(Path::new("dir")));
    match s.projection {
        ProjectionSpec::Perspective { frame, fov } => {
            assert_eq!(fov, 60.0);
            assert_eq!(frame.up, DVec3::Y);
            assert_eq!(frame.position, DVec3::new(0.0, 0.0, 5.0));
        }
        other => panic!("wrong projection {other:?}"),
    }
}

#[test]
fn image_settings_are_read() {
    let s = scene(&format!(
        "[image]\nwidth = 320\nheight = 200\nbackground = [0.5, 0, 1]\n{CAMERA}"
    ));
    assert_eq!((s.image.width, s.image.height), (320, 200));
    assert_eq!(s.image.background, Vec3::new(0.5, 0.0, 1.0));
}

#[test]
fn syntax_error_is_positioned() {
    assert_error_at("[image\nwidth = 3\n", 1, 7, "");
    assert_error_at(&format!("{CAMERA}fov = = 3\n"), 6, 7, "");
}

#[test]
fn unknown_keys_are_errors_everywhere() {
    assert_error_at(
        &format!("{CAMERA}[camera]\n"),
        6,
        2,
        "unknown key `camera`; did you mean `image`?",
    );
    assert_error_at(
        "[image]\nwidht = 3\n",
        2,
        1,
        "unknown key `widht`; did you mean `width`?",
    );
    assert_error_at(
        &object("shape = \"sphere\"\nradius = 2\n"),
        8,
        1,
        "unknown key `radius`; did you mean",
    );
    assert_error(
        &object("shape = \"plane\"\nchecker = { colour = [0, 0, 0] }\n"),
        "unknown key `colour`; did you mean `color`?",
    );
    assert_error(
        &format!("{CAMERA}[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\npower = 2\n"),
        "`power`",
    );
    assert_error_at(
        &format!("{CAMERA}lookat = [0, 0, 0]\n"),
        6,
        1,
        "unknown key `lookat`; did you mean `look_at`?",
    );
}

#[test]
fn keys_of_another_type_are_errors() {
    let text = "[projection]\ntype = \"orthographic\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 60\n";
    assert_error_at(
        text,
        5,
        7,
        "`fov` is not a parameter of orthographic projections",
    );
    assert_error_at(
        &object("shape = \"sphere\"\nfile = \"a.obj\"\n"),
        8,
        8,
        "`file` does not apply",
    );
    assert_error_at(
        &object(
            "shape = \"sphere\"\nface_colors = [[1,0,0],[1,0,0],[1,0,0],[1,0,0],[1,0,0],[1,0,0]]\n",
        ),
        8,
        15,
        "`face_colors`",
    );
    assert_error(
        &object("shape = \"mesh\"\nfile = \"a.obj\"\nsize = 2\n"),
        "`size` does not apply",
    );
    assert_error(
        &object("shape = \"mesh\"\nfile = \"a.obj\"\ntessellation = 8\n"),
        "`tessellation` does not apply",
    );
    assert_error(
        &object("shape = \"sphere\"\nior = 1.3\n"),
        "`ior` applies only to material = \"glass\"",
    );
    assert_error(&format!("{CAMERA}[[light]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nposition = [0, 1, 0]\n"), "`position` does not apply to directional lights");
}

#[test]
fn wrong_types_are_positioned() {
    assert_error_at("[image]\nwidth = \"big\"\n", 2, 9, "expected u32");
    assert_error_at("[image]\nwidth = -3\n", 2, 9, "expected u32");
    assert_error_at("[image]\nbackground = [1, 2]\n", 2, 14, "length 3");
    assert_error(
        &object("shape = \"box\"\nscale = \"big\"\n"),
        "a number or an array of numbers",
    );
}

#[test]
fn unknown_names_list_the_valid_ones() {
    let message = error("[projection]\ntype = \"fisheyes\"\n");
    assert!(
        message.starts_with("dir/s.toml:2:8: unknown projection type \"fisheyes\""),
        "{message}"
    );
    for name in [
        "perspective",
        "orthographic",
        "fisheye",
        "equirectangular",
        "cylindrical",
        "trilinear",
        "flexible",
    ] {
        assert!(message.contains(name), "{name} missing in {message}");
    }
    assert_error_at(
        &object("shape = \"cube\"\n"),
        7,
        9,
        "expected one of: plane, box, sphere, cylinder, torus, teapot, walker, mesh",
    );
    assert_error_at(
        &object("shape = \"box\"\nmaterial = \"metal\"\n"),
        8,
        12,
        "expected one of: diffuse, mirror, glass, emissive",
    );
    assert_error_at(
        &format!("{CAMERA}[[light]]\ntype = \"spot\"\n"),
        7,
        8,
        "expected one of: point, directional",
    );
}

#[test]
fn flexible_presets_and_surfaces_parse() {
    let s = scene(
        "[projection]\ntype = \"flexible\"\npreset = \"pushbroom\"\nposition = [0, 1, 5]\n\
         look_at = [0, 1, 0]\nwidth = 4\nv_fov = 60\nclip = [0, 50]\n",
    );
    assert_eq!(s.projection.kind(), "flexible");
    let s = scene(
        "[projection]\ntype = \"flexible\"\nreparam = \"lens\"\n\
         near = { surface = \"point\", point = [0, 1, 0] }\n\
         far = { surface = \"hemisphere\", center = [0, 1, 0], radius = 30, axis = [0, 0, -1], front = [1, 0, 0] }\n",
    );
    let ProjectionSpec::Flexible(spec) = &s.projection else {
        panic!("not flexible");
    };
    assert_eq!(spec.reparam.as_ref().map(|r| r.name()), Some("lens"));
    scene(
        "[projection]\ntype = \"flexible\"\n\
         near = { surface = \"line\", start = [-1, 0, 0], end = [1, 0, 0] }\n\
         far = { surface = \"rectangle\", corner = [-2, -1, -5], u_edge = [4, 0, 0], v_edge = [0, 3, 0] }\n",
    );
    scene(
        "[projection]\ntype = \"flexible\"\n\
         near = { surface = \"cylinder\", center = [0, 0, 0], radius = 0.5, height = [-0.5, 0.5] }\n\
         far = { surface = \"bilinear\", corners = [[-2, -1, -5], [2, -1, -5], [2, 2, -6], [-2, 2, -6]] }\n",
    );
}

#[test]
fn flexible_errors_have_positions() {
    let head = "[projection]\ntype = \"flexible\"\n";
    assert_error_at(
        &format!("{head}preset = \"fishbowl\"\n"),
        3,
        10,
        "unknown flexible preset \"fishbowl\"; expected one of: perspective,",
    );
    assert_error_at(
        &format!("{head}preset = \"perspective\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 60\nwidth = 3\n"),
        7,
        9,
        "`width` is not a parameter of flexible preset \"perspective\"",
    );
    assert_error_at(
        &format!("{head}preset = \"perspective\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 60\nclip = [5, 1]\n"),
        7,
        8,
        "`clip` must be [near, far]",
    );
    assert_error_at(
        &format!("{head}near = {{ surface = \"disc\", center = [0, 0, 0] }}\nfar = {{ surface = \"point\", point = [0, 0, 1] }}\n"),
        3,
        20,
        "unknown surface \"disc\"; expected one of: rectangle, bilinear,",
    );
    assert_error_at(
        &format!("{head}near = {{ surface = \"point\", point = [0, 0, 0] }}\nfar = {{ surface = \"sphere\", center = [0, 0, 0], radius = 2, latitude = [0, 120] }}\n"),
        4,
        72,
        "far sphere latitude must lie within [-90, 90]",
    );
    assert_error_at(
        &format!("{head}near = {{ surface = \"point\", point = [0, 0, 0], radius = 1 }}\nfar = {{ surface = \"point\", point = [0, 0, 1] }}\n"),
        3,
        57,
        "`radius` is not a parameter of point surfaces",
    );
    assert_error_at(
        &format!("{head}near = {{ surface = \"point\", point = [0, 0, 0] }}\n"),
        1,
        1,
        "flexible projection needs `far`",
    );
    assert_error_at(
        &format!("{head}reparam = \"swirl\"\nnear = {{ surface = \"point\", point = [0, 0, 0] }}\nfar = {{ surface = \"point\", point = [0, 0, 1] }}\n"),
        3,
        11,
        "unknown reparam \"swirl\"; expected one of: linear, polar, lens, mercator",
    );
    // Degenerate volumes are found by the build and reported at the table.
    assert_error_at(
        &format!("{head}near = {{ surface = \"point\", point = [0, 0, 0] }}\nfar = {{ surface = \"point\", point = [0, 0, 0] }}\n"),
        1,
        1,
        "every projector has zero length",
    );
    assert_error_at(
        &format!("{head}fov = 60\nnear = {{ surface = \"point\", point = [0, 0, 0] }}\n"),
        3,
        7,
        "`fov` is not a parameter of flexible projections without a `preset`",
    );
}

#[test]
fn new_flexible_presets_parse_with_their_keys() {
    let head = "[projection]\ntype = \"flexible\"\nposition = [0, 1, 5]\nlook_at = [0, 1, 0]\n";
    for body in [
        "preset = \"off_axis\"\nfov = 60\nshift = [0.5, -0.25]\n",
        "preset = \"twist\"\nfov = 60\ntwist = 45\nclip = [0, 20]\n",
        "preset = \"axonometric\"\nwidth = 4\nazimuth = 45\nelevation = 35.264\n",
        "preset = \"glc\"\nwidth = 2\ngenerators = [[-1, -1, -2, -2], [1, -1, 2, -2], [0, 1, 0, 2]]\n",
        "preset = \"equirectangular\"\nreparam = \"equal_area\"\nmax_latitude = 80\n",
    ] {
        let s = scene(&format!("{head}{body}"));
        assert_eq!(s.projection.kind(), "flexible", "{body}");
    }
}

/// `converge` of the inverse perspective: required, the missing key's message spelling out
/// the line that keeps a scene written before it existed (its look_at); the projectors meet
/// there, not at look_at; `converge` belongs to that preset only.
#[test]
fn inverse_perspective_needs_converge() {
    let head = "[projection]\ntype = \"flexible\"\nposition = [0, 1, 5]\nlook_at = [0, 1, 0]\n";
    let body = "preset = \"inverse_perspective\"\nfov = 40\n";
    assert_error_at(
        &format!("{head}{body}"),
        1,
        1,
        "needs `converge = [x, y, z]`, the point its projectors meet (look_at only aims the \
         camera): add converge = [0.0, 1.0, 0.0] (this table's look_at",
    );
    let s = scene(&format!("{head}{body}converge = [0, 1, -20]\n"));
    let ProjectionSpec::Flexible(spec) = &s.projection else {
        panic!("{:?}", s.projection);
    };
    let VolumeSource::Preset(p) = &spec.source else {
        panic!("{:?}", spec.source);
    };
    assert_eq!(
        p.preset,
        Preset::InversePerspective {
            fov: 40.0,
            converge: DVec3::new(0.0, 1.0, -20.0),
        }
    );
    assert_error_at(
        &format!("{head}preset = \"perspective\"\nfov = 40\nconverge = [0, 1, -20]\n"),
        7,
        12,
        "`converge` is not a parameter of flexible preset \"perspective\"",
    );
}

#[test]
fn equiangular_perspective_takes_its_angle_from_the_preset() {
    let head = "[projection]\ntype = \"flexible\"\nposition = [0, 1, 5]\nlook_at = [0, 1, 0]\n";
    let s = scene(&format!(
        "{head}preset = \"perspective\"\nfov = 90\nreparam = \"equiangular\"\n"
    ));
    let ProjectionSpec::Flexible(spec) = &s.projection else {
        panic!("not flexible");
    };
    let Some(crate::projection::flexible::Reparam::Equiangular { half_fov }) = spec.reparam else {
        panic!("not equiangular: {:?}", spec.reparam);
    };
    assert!((half_fov - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
    assert_error_at(
        &format!("{head}preset = \"fisheye\"\nfov = 180\nreparam = \"equiangular\"\n"),
        7,
        11,
        "reparam \"equiangular\" belongs to the perspective preset",
    );
    assert_error_at(
        &format!("{head}preset = \"perspective\"\nfov = 180\nreparam = \"equiangular\"\n"),
        6,
        7,
        "equiangular perspective fov must be in (0, 180) degrees, got 180",
    );
}

#[test]
fn equisolid_fisheye_takes_its_angle_from_the_preset() {
    let head = "[projection]\ntype = \"flexible\"\nposition = [0, 1, 5]\nlook_at = [0, 1, 0]\n";
    let s = scene(&format!(
        "{head}preset = \"fisheye\"\nfov = 360\nreparam = \"equisolid\"\n"
    ));
    let ProjectionSpec::Flexible(spec) = &s.projection else {
        panic!("not flexible");
    };
    let Some(crate::projection::flexible::Reparam::Equisolid { max_angle }) = spec.reparam else {
        panic!("not equisolid: {:?}", spec.reparam);
    };
    assert!((max_angle - std::f64::consts::PI).abs() < 1e-15);
    assert_error_at(
        &format!("{head}preset = \"perspective\"\nfov = 60\nreparam = \"equisolid\"\n"),
        7,
        11,
        "reparam \"equisolid\" belongs to the fisheye preset",
    );
    assert_error_at(
        &format!("{head}preset = \"fisheye\"\nfov = 400\nreparam = \"equisolid\"\n"),
        6,
        7,
        "equisolid fisheye fov must be in (0, 360] degrees, got 400",
    );
    assert_error_at(
        &format!("{head}preset = \"fisheye\"\nreparam = \"equisolid\"\n"),
        1,
        1,
        "needs `fov`",
    );
}

/// A re-parameterisation whose (u, v) the preset's volume does not have is one error at the
/// `reparam` key naming both; the matching pairs parse.
#[test]
fn meaningless_reparam_and_preset_pairs_are_refused() {
    let head = "[projection]\ntype = \"flexible\"\nposition = [0, 1, 5]\nlook_at = [0, 1, 0]\n";
    for (preset, map) in [
        ("fisheye", "mercator"),
        ("fisheye", "equal_area"),
        ("perspective", "polar"),
        ("perspective", "lens"),
        ("equirectangular", "polar"),
        ("cylindrical", "mercator"),
        ("orthographic", "lens"),
    ] {
        assert_error_at(
            &format!("{head}preset = \"{preset}\"\nfov = 60\nreparam = \"{map}\"\n"),
            7,
            11,
            &format!("reparam \"{map}\" does not go with preset \"{preset}\""),
        );
    }
    for (preset, map) in [
        ("fisheye", "polar"),
        ("fisheye", "lens"),
        ("equirectangular", "mercator"),
        ("equirectangular", "equal_area"),
        ("perspective", "linear"),
    ] {
        let fov = if preset == "equirectangular" {
            ""
        } else {
            "fov = 60\n"
        };
        let s = scene(&format!(
            "{head}preset = \"{preset}\"\n{fov}reparam = \"{map}\"\n"
        ));
        assert_eq!(s.projection.kind(), "flexible", "{preset} {map}");
    }
}

#[test]
fn new_flexible_preset_errors_have_positions() {
    let head = "[projection]\ntype = \"flexible\"\nposition = [0, 1, 5]\nlook_at = [0, 1, 0]\n";
    assert_error_at(
        &format!("{head}preset = \"glc\"\nwidth = 2\ngenerators = [[0, 0, 0, 0], [1, 1, 1, 1]]\n"),
        7,
        14,
        "`generators` must hold exactly three rays",
    );
    assert_error_at(
        &format!("{head}preset = \"glc\"\nwidth = 2\ngenerators = [[0, 0, 0, 0], [1, 1, 1, 1], [2, 2, 0, 0]]\n"),
        1,
        1,
        "not on one line",
    );
    assert_error_at(
        &format!("{head}preset = \"axonometric\"\nwidth = 2\nazimuth = 0\nelevation = 10\nup = [0, 0, 1]\n"),
        9,
        6,
        "`up` is not a parameter of flexible preset \"axonometric\"",
    );
    assert_error_at(
        &format!("{head}preset = \"twist\"\nfov = 60\n"),
        1,
        1,
        "flexible projection needs `twist`",
    );
    assert_error_at(
        &format!(
            "{head}preset = \"equirectangular\"\nreparam = \"equal_area\"\nmax_latitude = 95\n"
        ),
        7,
        16,
        "equal_area max_latitude must be in (0, 90] degrees, got 95",
    );
    assert_error_at(
        &format!("{head}preset = \"twist\"\nfov = 60\ntwist = 10\nmax_latitude = 10\n"),
        8,
        16,
        "`max_latitude` is not a parameter",
    );
}

#[test]
fn missing_required_parameters() {
    assert_eq!(
        error("[image]\nwidth = 10\n"),
        "dir/s.toml: missing [projection] table: a scene needs exactly one"
    );
    assert_error_at(
        "[projection]\ntype = \"perspective\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n",
        1,
        1,
        "perspective projection needs `fov`",
    );
    assert_error_at(
        "[projection]\ntype = \"fisheye\"\nlook_at = [0, 0, 0]\nfov = 180\n",
        1,
        1,
        "needs `position`",
    );
    assert_error_at(
        "[projection]\ntype = \"orthographic\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n",
        1,
        1,
        "needs `width`",
    );
    assert_error_at(
        &object("color = [1, 0, 0]\n"),
        6,
        1,
        "missing field `shape`",
    );
    assert_error_at(
        &object("shape = \"mesh\"\n"),
        6,
        1,
        "shape \"mesh\" needs `file`",
    );
    assert_error(
        &format!("{CAMERA}[[light]]\ntype = \"point\"\n"),
        "point light needs `position`",
    );
    assert_error(
        &format!("{CAMERA}[[light]]\nposition = [0, 1, 0]\n"),
        "missing field `type`",
    );
}

#[test]
fn non_finite_numbers_are_rejected() {
    assert_error_at(
        &CAMERA.replace("fov = 60", "fov = nan"),
        5,
        7,
        "`fov` must be a finite number, not NaN",
    );
    assert_error_at(
        &object("shape = \"box\"\ntranslate = [0, inf, 0]\n"),
        8,
        13,
        "`translate` must be a finite number",
    );
    assert_error(
        &object("shape = \"sphere\"\nsize = -inf\n"),
        "`size` must be a finite number",
    );
    assert_error(
        &object("shape = \"box\"\nscale = [1, nan, 1]\n"),
        "`scale` must be a finite number",
    );
    assert_error(
        &format!("{CAMERA}[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = inf\n"),
        "`intensity`",
    );
    assert_error(
        &object("shape = \"box\"\ntranslate = [0, 1e300, 0]\n"),
        "`translate` value 1e300 is out of range",
    );
    assert_error(
        "[image]\nbackground = [0, nan, 0]\n[projection]\ntype = \"perspective\"\n",
        "`background`",
    );
}

#[test]
fn non_positive_sizes_are_rejected() {
    assert_error_at(
        &object("shape = \"sphere\"\nsize = 0\n"),
        8,
        8,
        "`size` must be positive, not 0",
    );
    assert_error(
        &object("shape = \"box\"\nsize = [1, -1, 1]\n"),
        "`size` must be positive, not -1",
    );
    assert_error(
        &object("shape = \"cylinder\"\nsize = 1\n"),
        "`size` of a cylinder is [radius, height]",
    );
    assert_error(
        &object("shape = \"torus\"\nsize = [1, 0.2, 3]\n"),
        "`size` of a torus is [major radius, minor radius]",
    );
    assert_error(
        &object("shape = \"plane\"\nchecker = { color = [0, 0, 0], size = 0 }\n"),
        "`checker.size` must be positive",
    );
    assert_error(
        &object("shape = \"box\"\nscale = 0\n"),
        "`scale` must not be zero",
    );
    assert_error(
        &object("shape = \"box\"\nscale = [1, 0, 1]\n"),
        "`scale` must not be zero",
    );
    assert_error(
        &object("shape = \"box\"\nscale = [1, 2]\n"),
        "`scale` is a number or [x, y, z]",
    );
    assert_error(
        &object("shape = \"box\"\ncolor = [1, -0.5, 0]\n"),
        "`color` components must not be negative",
    );
    assert_error(
        &format!("{CAMERA}[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = -1\n"),
        "must not be negative",
    );
    assert_error(
        &format!("{CAMERA}[[light]]\ntype = \"directional\"\ndirection = [0, 0, 0]\n"),
        "`direction` must not be zero",
    );
}

#[test]
fn tessellation_out_of_range() {
    assert_error_at(
        &object("shape = \"sphere\"\ntessellation = 2\n"),
        8,
        16,
        "must be in 3..=1024, not 2",
    );
    assert_error(
        &object("shape = \"teapot\"\ntessellation = 5000\n"),
        "must be in 4..=1024, not 5000",
    );
    assert_error(
        &object("shape = \"plane\"\ntessellation = 0\n"),
        "must be in 1..=1024, not 0",
    );
}

#[test]
fn ior_must_be_positive() {
    assert_error_at(
        &object("shape = \"sphere\"\nmaterial = \"glass\"\nior = 0\n"),
        9,
        7,
        "`ior` must be positive",
    );
    assert_error(
        &object("shape = \"sphere\"\nmaterial = \"glass\"\nior = -1.5\n"),
        "`ior` must be positive",
    );
}

#[test]
fn absurd_resolutions_are_rejected() {
    assert_error_at(
        &format!("[image]\nwidth = 0\n{CAMERA}"),
        2,
        9,
        "image width 0 is out of range",
    );
    assert_error_at(
        &format!("[image]\nwidth = 10\nheight = 20000\n{CAMERA}"),
        3,
        10,
        "image height 20000",
    );
    assert!(validate_resolution(16384, 16384).is_ok());
    assert!(validate_resolution(1, 1).is_ok());
    assert!(validate_resolution(16385, 1).is_err());
    assert!(validate_resolution(640, 0).is_err());
}

#[test]
fn duplicate_names_are_rejected() {
    let text = object("name = \"a\"\nshape = \"box\"\n[[object]]\nname = \"b\"\nshape = \"box\"\n[[object]]\nname = \"a\"\nshape = \"box\"\n");
    assert_error_at(
        &text,
        13,
        8,
        "duplicate object name \"a\" (first used on line 7)",
    );
}

#[test]
fn degenerate_projection_is_reported_at_its_table() {
    let text = format!(
        "[image]\nwidth = 10\n{}",
        CAMERA.replace("fov = 60", "fov = 0")
    );
    assert_error_at(&text, 3, 1, "");
    let text = format!(
        "[image]\nwidth = 10\n{}",
        CAMERA.replace("look_at = [0, 0, 0]", "look_at = [0, 0, 5]")
    );
    assert_error_at(&text, 3, 1, "");
}

#[test]
fn missing_model_and_texture_files_name_the_file() {
    let message = error(&object("shape = \"mesh\"\nfile = \"models/none.obj\"\n"));
    assert!(message.contains("none.obj"), "{message}");
    let message = error(&object("shape = \"plane\"\ntexture = \"none.png\"\n"));
    assert!(message.contains("none.png"), "{message}");
    // An empty name resolves to the scene's folder: refused at the value, not as a folder
    // that cannot be read under an empty name.
    let text = object("shape = \"plane\"\ntexture = \"\"\n");
    let message = error(&text);
    assert!(message.contains("texture \"\" is not a file"), "{message}");
    assert!(message.starts_with("dir/s.toml:"), "{message}");
    assert_error(
        &object("shape = \"plane\"\ntexture = \"a.png\"\nchecker = { color = [0, 0, 0] }\n"),
        "`texture` and `checker` cannot be combined",
    );
}

#[test]
fn load_names_a_missing_file() {
    let message = load(Path::new("no/such/scene.toml"))
        .err()
        .map(|e| e.to_string());
    let message = message.unwrap_or_default();
    assert!(
        message.starts_with("no/such/scene.toml: cannot read scene file"),
        "{message}"
    );
}

#[test]
fn panorama_defaults() {
    let frame = "position = [0, 1, 0]\nlook_at = [0, 1, -1]\n";
    match scene(&format!(
        "[projection]\ntype = \"equirectangular\"\n{frame}"
    ))
    .projection
    {
        ProjectionSpec::Equirectangular { h_fov, v_fov, .. } => {
            assert_eq!((h_fov, v_fov), (360.0, 180.0))
        }
        other => panic!("{other:?}"),
    }
    match scene(&format!("[projection]\ntype = \"cylindrical\"\n{frame}")).projection {
        ProjectionSpec::Cylindrical { h_fov, v_fov, .. } => {
            assert_eq!((h_fov, v_fov), (360.0, 90.0))
        }
        other => panic!("{other:?}"),
    }
    match scene(&format!(
        "[projection]\ntype = \"cylindrical\"\n{frame}h_fov = 180\nv_fov = 60\nup = [1, 0, 0]\n"
    ))
    .projection
    {
        ProjectionSpec::Cylindrical {
            h_fov,
            v_fov,
            frame,
        } => {
            assert_eq!((h_fov, v_fov), (180.0, 60.0));
            assert_eq!(frame.up, DVec3::X);
        }
        other => panic!("{other:?}"),
    }
}

/// A trilinear table with one triangle of inline arrays; `extra` is appended.
fn inline_trilinear(triangles: &str, extra: &str) -> String {
    format!(
        "[projection]\ntype = \"trilinear\"\npoints = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n\
         normals = [[0, 0, -1], [0, 0, -1], [0, 0, -1]]\nscreen = [[0, 0], [1, 0], [0, 1]]\n\
         triangles = {triangles}\n{extra}"
    )
}

#[test]
fn trilinear_inline_arrays() {
    match scene(&inline_trilinear("[[0, 1, 2]]", "")).projection {
        ProjectionSpec::Trilinear(mesh) => {
            assert_eq!(mesh.points[1], DVec3::X);
            assert_eq!(mesh.normals[2], DVec3::NEG_Z);
            assert_eq!(mesh.screen[2], glam::DVec2::Y);
            assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        }
        other => panic!("{other:?}"),
    }
    assert_error_at(
        &inline_trilinear("[[0, 1, 3]]", ""),
        6,
        13,
        "triangle 0 [0, 1, 3] refers to a vertex beyond the 3",
    );
    assert_error_at(
        &inline_trilinear("[[0, 1, 2]]", "surface = \"s.obj\"\n"),
        3,
        10,
        "`points` cannot be combined with `surface`",
    );
    assert_error_at(
        &inline_trilinear("[[0, 1, 2]]", "").replace("[[0, 0], [1, 0], [0, 1]]", "[[0, 0]]"),
        5,
        10,
        "`screen` has 1 entries but `points` has 3",
    );
    assert_error(
        &inline_trilinear("[[0, 1, 2]]", "").replace("[0, 0, -1]]", "[0, 0, nan]]"),
        "`normals` must be a finite number",
    );
    assert_error_at(
        "[projection]\ntype = \"trilinear\"\n",
        1,
        1,
        "needs `surface` or the inline",
    );
    assert_error_at(
        &inline_trilinear("[[0, 1, 2]]", "")
            .replace("normals = [[0, 0, -1], [0, 0, -1], [0, 0, -1]]\n", ""),
        1,
        1,
        "needs `normals`",
    );
    assert_error_at(
        &inline_trilinear("[[0, 1, 2]]", "position = [0, 0, 0]\n"),
        7,
        12,
        "`position` is not a parameter of trilinear",
    );
}

#[test]
fn trilinear_surface_is_relative_to_the_scene_file() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 -1\nf 1/1/1 2/2/1 3/3/1\n";
    std::fs::create_dir(dir.path().join("surfaces")).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(dir.path().join("surfaces/tri.obj"), obj).unwrap_or_else(|e| panic!("{e}"));
    let path = dir.path().join("s.toml");
    std::fs::write(
        &path,
        "[projection]\ntype = \"trilinear\"\nsurface = \"surfaces/tri.obj\"\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    match load(&path).unwrap_or_else(|e| panic!("{e}")).projection {
        ProjectionSpec::Trilinear(mesh) => assert_eq!(mesh.triangles.len(), 1),
        other => panic!("{other:?}"),
    }
    // A missing file is reported at the scene's value, with the path looked for.
    assert_error_at(
        "[projection]\ntype = \"trilinear\"\nsurface = \"missing.obj\"\n",
        3,
        11,
        "trilinear surface \"missing.obj\" is not a file (looked for dir/missing.obj)",
    );
}

#[test]
fn objects_get_ids_in_file_order_and_default_names() {
    let s = scene(&object(
        "shape = \"box\"\n[[object]]\nname = \"ball\"\nshape = \"sphere\"\ntessellation = 8\n",
    ));
    let ids: Vec<(u32, &str)> = s.objects.iter().map(|o| (o.id, o.name.as_str())).collect();
    assert_eq!(ids, vec![(1, "box"), (2, "ball")]);
}

#[test]
fn material_defaults_and_keys() {
    let s = scene(&object(
        "shape = \"box\"\n[[object]]\nshape = \"sphere\"\nmaterial = \"glass\"\n\
         [[object]]\nshape = \"sphere\"\nmaterial = \"glass\"\nior = 1.33\ncolor = [1, 0.5, 0]\n\
         [[object]]\nshape = \"plane\"\nchecker = { color = [0.1, 0.2, 0.3] }\nmaterial = \"mirror\"\n\
         [[object]]\nshape = \"torus\"\nmaterial = \"emissive\"\n",
    ));
    let m: Vec<_> = s.objects.iter().map(|o| &o.material).collect();
    assert_eq!(
        (m[0].color, m[0].finish, &m[0].pattern),
        (Vec3::splat(0.8), Finish::Diffuse, &Pattern::Solid)
    );
    assert_eq!(m[1].finish, Finish::Glass { ior: 1.5 });
    assert_eq!(
        (m[2].finish, m[2].color),
        (Finish::Glass { ior: 1.33 }, Vec3::new(1.0, 0.5, 0.0))
    );
    assert_eq!(
        m[3].pattern,
        Pattern::Checker {
            other: Vec3::new(0.1, 0.2, 0.3),
            size: 1.0
        }
    );
    assert_eq!(m[3].finish, Finish::Mirror);
    assert_eq!(m[4].finish, Finish::Emissive);
}

#[test]
fn lights_defaults_and_types() {
    let s = scene(&format!(
        "{CAMERA}[[light]]\ntype = \"point\"\nposition = [1, 2, 3]\n\
         [[light]]\ntype = \"directional\"\ndirection = [0, -2, 0]\nintensity = 0.5\ncolor = [1, 0.9, 0.8]\n"
    ));
    assert_eq!(
        s.lights,
        vec![
            Light::Point {
                position: Vec3::new(1.0, 2.0, 3.0),
                color: Vec3::ONE,
                intensity: 1.0
            },
            Light::Directional {
                direction: Vec3::NEG_Y,
                color: Vec3::new(1.0, 0.9, 0.8),
                intensity: 0.5
            },
        ]
    );
}

#[test]
fn transform_is_translate_rotate_xyz_scale() {
    let s = scene(&object(
        "shape = \"box\"\ntranslate = [1, 2, 3]\nrotate = [90, 90, 0]\nscale = 2\n",
    ));
    let o = &s.objects[0];
    let object_to_world: Affine3A = o.world_to_object.inverse();
    // R = Rz * Ry * Rx: Rx(90) takes +y to +z, then Ry(90) takes +z to +x.
    let y = object_to_world.transform_point3(Vec3::Y);
    assert!((y - Vec3::new(3.0, 2.0, 3.0)).length() < 1e-5, "{y}");
    let x = object_to_world.transform_point3(Vec3::X);
    assert!((x - Vec3::new(1.0, 2.0, 1.0)).length() < 1e-5, "{x}");
    // The mesh is in world space: a unit box scaled by 2 around (1, 2, 3).
    let (lo, hi) = o.mesh.bounds().unwrap_or_default();
    assert!(
        (lo - Vec3::new(0.0, 1.0, 2.0)).length() < 1e-5
            && (hi - Vec3::new(2.0, 3.0, 4.0)).length() < 1e-5
    );
}

#[test]
fn nonuniform_scale_keeps_normals_perpendicular() {
    let s = scene(&object(
        "shape = \"sphere\"\nscale = [2, 1, 0.5]\ntessellation = 16\n",
    ));
    let mesh = &s.objects[0].mesh;
    assert!(!mesh.normals.is_empty());
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        // The gradient of the ellipsoid (x/2)^2 + y^2 + (2z)^2 = 1.
        let gradient = Vec3::new(p.x / 4.0, p.y, 4.0 * p.z).normalize();
        assert!(n.dot(gradient) > 0.999, "normal {n} at {p}");
    }
}

#[test]
fn box_is_tessellated_and_face_coloured() {
    let colors = "[[1,0,0],[0,1,0],[0,0,1],[1,1,0],[0,1,1],[1,0,1]]";
    let s = scene(&object(&format!(
        "shape = \"box\"\nsize = [2, 4, 6]\ntessellation = 3\nface_colors = {colors}\n"
    )));
    let o = &s.objects[0];
    assert_eq!(o.mesh.triangle_count(), 6 * 2 * 9);
    assert_eq!(o.material.color, Vec3::ONE);
    let (lo, hi) = o.mesh.bounds().unwrap_or_default();
    assert_eq!(
        (lo, hi),
        (Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0))
    );
    let expected = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ];
    let face_color = [
        Vec3::X,
        Vec3::Y,
        Vec3::Z,
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
    ];
    for (p, c) in o.mesh.positions.iter().zip(&o.mesh.colors) {
        // Each vertex lies on the face its colour belongs to.
        let face = face_color.iter().position(|f| f == c).unwrap_or(usize::MAX);
        let normal = expected[face];
        assert!(
            (p.dot(normal) - (hi * normal.abs()).element_sum()).abs() < 1e-5,
            "{p} not on face {face}"
        );
    }
    for (p, n) in o.mesh.positions.iter().zip(&o.mesh.normals) {
        assert!(
            (p.abs() * n.abs() - hi * n.abs()).length() < 1e-5,
            "normal {n} at {p} not outward"
        );
        assert!(p.dot(*n) > 0.0);
    }
}

/// Writes `files` (relative path, contents) into a fresh folder and loads `scene` from it.
fn load_with_files(scene_text: &str, files: &[(&str, &[u8])]) -> Result<Scene> {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    for (name, contents) in files {
        let path = dir.path().join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).unwrap_or_else(|e| panic!("{e}"));
        }
        std::fs::write(path, contents).unwrap_or_else(|e| panic!("{e}"));
    }
    let path = dir.path().join("s.toml");
    std::fs::write(&path, scene_text).unwrap_or_else(|e| panic!("{e}"));
    load(&path)
}

/// Two parts, one without a material, then one red (from the MTL).
const TWO_PART_OBJ: &[u8] = b"mtllib m.mtl
v 0 0 0
v 1 0 0
v 0 1 0
o plain
f 1 3 2
o red
usemtl red
f 1 2 3
";
const RED_MTL: &[u8] = b"newmtl red\nKd 1 0 0\n";

#[test]
fn mesh_parts_share_the_id_and_keep_file_materials() {
    let text = object("shape = \"box\"\n[[object]]\nshape = \"mesh\"\nfile = \"models/two.obj\"\ntranslate = [0, 0, 1]\n");
    let files: [(&str, &[u8]); 2] = [("models/two.obj", TWO_PART_OBJ), ("models/m.mtl", RED_MTL)];
    let s = load_with_files(&text, &files).unwrap_or_else(|e| panic!("{e}"));
    let ids: Vec<u32> = s.objects.iter().map(|o| o.id).collect();
    assert_eq!(ids, vec![1, 2, 2]);
    assert_eq!(s.objects[1].material, crate::scene::Material::default());
    assert_eq!(s.objects[2].material.color, Vec3::X);
    assert_eq!(
        s.objects[1].mesh.positions[0],
        Vec3::Z,
        "mesh moved to world space"
    );
}

#[test]
fn object_keys_override_file_materials() {
    let text =
        object("shape = \"mesh\"\nfile = \"two.obj\"\ncolor = [0, 1, 0]\nmaterial = \"mirror\"\n");
    let files: [(&str, &[u8]); 2] = [("two.obj", TWO_PART_OBJ), ("m.mtl", RED_MTL)];
    let s = load_with_files(&text, &files).unwrap_or_else(|e| panic!("{e}"));
    for o in &s.objects {
        assert_eq!(
            (o.material.color, o.material.finish),
            (Vec3::Y, Finish::Mirror)
        );
    }
}

#[test]
fn texture_is_loaded_relative_to_the_scene() {
    let mut png = Vec::new();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 0, 0]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap_or_else(|e| panic!("{e}"));
    let text = object("shape = \"plane\"\ntexture = \"textures/red.png\"\n");
    let s = load_with_files(&text, &[("textures/red.png", &png)]).unwrap_or_else(|e| panic!("{e}"));
    match &s.objects[0].material.pattern {
        Pattern::Texture(t) => assert_eq!((t.width, t.height, t.texels[0]), (2, 2, Vec3::X)),
        other => panic!("{other:?}"),
    }
}

/// Three rectangles for blended flexible volumes, as a `surfaces` value on one line.
const THREE: &str = "surfaces = [{ surface = \"rectangle\", center = [0, 0, 1], u_axis = [1, 0, 0], v_axis = [0, 1, 0] }, { surface = \"rectangle\", center = [1, 0, 2], u_axis = [1, 0, 0], v_axis = [0, 1, 0] }, { surface = \"rectangle\", center = [0, 0, 3], u_axis = [2, 0, 0], v_axis = [0, 2, 0] }]\n";

#[test]
fn flexible_blended_surfaces_and_patches_parse() {
    use crate::projection::flexible::{Blend, Surface as Control, VolumeSource};
    let head = "[projection]\ntype = \"flexible\"\n";
    let source = |text: &str| match scene(text).projection {
        ProjectionSpec::Flexible(f) => f.source,
        other => panic!("not flexible: {other:?}"),
    };
    match source(&format!("{head}blend = \"bezier\"\nsegments = 4\n{THREE}")) {
        VolumeSource::Blended { surfaces, blend } => {
            assert_eq!(surfaces.len(), 3);
            assert_eq!(blend, Blend::Bezier { segments: Some(4) });
        }
        other => panic!("{other:?}"),
    }
    match source(&format!("{head}knots = [0, 0.25, 1]\n{THREE}")) {
        VolumeSource::Blended { blend, .. } => assert_eq!(
            blend,
            Blend::Piecewise {
                knots: Some(vec![0.0, 0.25, 1.0])
            }
        ),
        other => panic!("{other:?}"),
    }
    let row = |z: f64| format!("[[0, 0, {z}], [1, 0, {z}], [2, 0, {z}], [3, 0, {z}]]");
    let grid = |rows: usize| {
        (0..rows)
            .map(|r| row(r as f64))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let text = format!(
        "{head}surfaces = [{{ surface = \"bezier\", control = [{}] }}, {{ surface = \"bspline\", control = [{}] }}]\n",
        grid(4),
        grid(5)
    );
    match source(&text) {
        VolumeSource::Blended { surfaces, .. } => {
            assert!(matches!(surfaces[0], Control::Bezier(_)));
            assert!(matches!(&surfaces[1], Control::BSpline(b) if b.size() == (5, 4)));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn flexible_blended_errors_have_positions() {
    let head = "[projection]\ntype = \"flexible\"\n";
    assert_error_at(
        &format!("{head}blend = \"spline\"\n{THREE}"),
        3,
        9,
        "unknown blend \"spline\"; expected one of: piecewise, bezier",
    );
    assert_error_at(
        &format!("{head}knots = [0, 0.7, 0.5]\n{THREE}"),
        3,
        9,
        "flexible knots must increase strictly from 0 to 1",
    );
    assert_error_at(
        &format!("{head}knots = [0, 1]\n{THREE}"),
        3,
        9,
        "2 knots for 3 surfaces",
    );
    assert_error_at(
        &format!("{head}segments = 3\n{THREE}"),
        3,
        12,
        "`segments` belongs to blend = \"bezier\"",
    );
    assert_error_at(
        &format!("{head}blend = \"bezier\"\nsegments = 0\n{THREE}"),
        4,
        12,
        "segments must be at least 1",
    );
    assert_error_at(
        &format!("{head}near = {{ surface = \"point\", point = [0, 0, 0] }}\n{THREE}"),
        3,
        8,
        "`near` is not a parameter of flexible projections given by `surfaces`",
    );
    assert_error_at(
        &format!("{head}blend = \"bezier\"\nsurfaces = [{{ surface = \"point\", point = [0, 0, 0] }}, {{ surface = \"point\", point = [0, 0, 1] }}]\n"),
        4,
        12,
        "a bezier flexible volume needs at least 3 surfaces",
    );
    assert_error_at(
        &format!("{head}surfaces = [{{ surface = \"point\", point = [0, 0, 0] }}, {{ surface = \"bezier\", control = [[[0, 0, 0]]] }}]\n"),
        3,
        87,
        "surface 2 bezier surface needs 4 rows of 4 control points, got 1 x 1",
    );
    assert_error_at(
        &format!("{head}surfaces = [{{ surface = \"point\", point = [0, 0, 0] }}, {{ surface = \"bspline\", control = [[[0, 0, 0]]] }}]\n"),
        3,
        88,
        "surface 2 bspline surface needs at least 4 x 4 control points, got 1 x 1",
    );
    assert_error(
        &format!("{head}blend = \"bezier\"\n"),
        "flexible projection needs `surfaces`",
    );
}

/// A flexible key table at `time` with the perspective preset of field of view `fov`.
fn animation_key(time: &str, fov: &str) -> String {
    format!(
        "[[animation.key]]\ntime = {time}\n[animation.key.projection]\ntype = \"flexible\"\n\
         preset = \"perspective\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = {fov}\n"
    )
}

#[test]
fn animation_tables_parse_into_keyframes() {
    let text = format!(
        "{CAMERA}[animation]\nframes = 3\nfps = 10\ninterpolation = \"smooth\"\n{}{}",
        animation_key("0", "40"),
        animation_key("0.5", "70")
    );
    let (_, animation) = parse_animated(&text, Path::new("dir/s.toml")).unwrap();
    let animation = animation.expect("an animation");
    assert_eq!((animation.frames(), animation.fps()), (3, 10.0));
    assert_eq!(animation.keys().len(), 2);
    assert_eq!(animation.keys()[1].time, 0.5);
    // Without [animation] there is none; `parse` checks the table but leaves it out.
    assert!(parse_animated(CAMERA, Path::new("s.toml"))
        .unwrap()
        .1
        .is_none());
    scene(&text);
}

#[test]
fn animation_errors_have_positions() {
    let head = format!("{CAMERA}[animation]\nframes = 3\n");
    // Line 6 is [animation], 7 frames; keys start on line 8 (time on line 9).
    assert_error_at(
        &format!(
            "{head}{}{}",
            animation_key("1", "40"),
            animation_key("1", "50")
        ),
        17,
        8,
        "animation key time 1 must be later than the key before it (1)",
    );
    assert_error_at(
        &format!("{head}{}", animation_key("-2", "40")),
        9,
        8,
        "at least 0 seconds",
    );
    assert_error_at(
        &format!("{head}{}", animation_key("inf", "40")),
        9,
        8,
        "`time`",
    );
    assert_error_at(
        &format!("{head}{}", animation_key("0", "200")),
        10,
        1,
        "flexible perspective fov",
    );
    assert_error_at(
        &format!(
            "{CAMERA}[animation]\nframes = 0\n{}",
            animation_key("0", "40")
        ),
        7,
        10,
        "`frames` must be in 1..=100000, not 0",
    );
    assert_error_at(
        &format!(
            "{CAMERA}[animation]\nframes = 2\ninterpolation = \"cubic\"\n{}",
            animation_key("0", "40")
        ),
        8,
        17,
        "unknown interpolation \"cubic\"",
    );
    assert_error_at(&head, 6, 1, "needs at least one [[animation.key]]");
    let perspective_key = "[[animation.key]]\ntime = 0\n[animation.key.projection]\n\
                           type = \"perspective\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 40\n";
    assert_error_at(
        &format!("{head}{perspective_key}"),
        11,
        8,
        "animation keys need type = \"flexible\"",
    );
    // Keys on different maps blend on the image's domain (fig. 6.16).
    let fisheye = animation_key("1", "40").replace("perspective", "fisheye");
    parse_text(&format!("{head}{}{fisheye}", animation_key("0", "40"))).unwrap();
    // An orthographic view and its mirror through the eye: halfway, every projector
    // vanishes.
    let mirrored = |time: &str, z: &str| {
        format!(
            "[[animation.key]]\ntime = {time}\n[animation.key.projection]\ntype = \"flexible\"\n\
             preset = \"orthographic\"\nposition = [0, 0, 0]\nlook_at = [0, 0, {z}]\nwidth = 2\n\
             clip = [0, 1]\n"
        )
    };
    assert_error_at(
        &format!("{head}{}{}", mirrored("0", "1"), mirrored("1", "-1")),
        19,
        1,
        "keys 0 and 1 cannot be interpolated",
    );
}

#[test]
fn flexible_projector_grids_parse_and_fit() {
    use crate::projection::flexible::{GridInterpolation, VolumeSource};
    let head = "[projection]\ntype = \"flexible\"\npreset = \"perspective\"\n\
                position = [0, 5, 7]\nlook_at = [0, 0, 0]\nfov = 60\n";
    let text = format!(
        "{head}projectors = {{ size = [3, 4], interpolation = \"bezier\", \
         aim = [{{ node = [2, 3], at = [1, 0, 0] }}], \
         fit = [{{ uv = [0.5, 0.5], point = [0, 0, 0] }}] }}\n"
    );
    let ProjectionSpec::Flexible(spec) = scene(&text).projection else {
        panic!("not flexible");
    };
    let VolumeSource::ProjectorGrid { base, grid } = &spec.source else {
        panic!("no grid: {spec:?}");
    };
    assert!(matches!(base.source, VolumeSource::Preset(_)));
    assert_eq!(grid.size, (3, 4));
    assert_eq!(grid.interpolation, GridInterpolation::Bezier);
    assert_eq!(grid.aims[0].node, (2, 3));
    assert_eq!(grid.correspondences.len(), 1);
    // The fit's residual is reported with the projection.
    let (_, report) = crate::calibrate::build(&ProjectionSpec::Flexible(spec), 32, 24).unwrap();
    let counters = report.counters;
    assert!(
        counters.contains(&("fit_correspondences", 1.0)),
        "{counters:?}"
    );

    let with = |projectors: &str| format!("{head}projectors = {projectors}\n");
    assert_error_at(
        &with("{ size = [1, 5] }"),
        7,
        23,
        "projector grid `size` must be from 2 to 9 nodes per side, not [1, 5]",
    );
    assert_error_at(
        &with("{ aim = [{ node = [5, 0], at = [0, 0, 0] }] }"),
        7,
        32,
        "projector node [5, 0] is outside the 5 x 5 grid",
    );
    assert_error_at(
        &with("{ fit = [{ uv = [0.5, 1.5], point = [0, 0, 0] }] }"),
        7,
        30,
        "`uv` must lie in [0, 1] x [0, 1], not [0.5, 1.5]",
    );
    assert_error_at(
        &with("{ interpolation = \"cubic\" }"),
        7,
        32,
        "unknown interpolation \"cubic\"; expected one of: bilinear, bezier",
    );
    assert_error(
        &with("{ fit = [{ uv = [0.5, 0.5], point = [0, 5, 7] }] }"),
        "correspondence 1: the point",
    );
}

#[test]
fn flexible_projector_grid_nodes_with_tangents() {
    use crate::projection::flexible::{NodeProjector, Volume, VolumeSource};
    let head = "[projection]\ntype = \"flexible\"\npreset = \"perspective\"\n\
                position = [0, 5, 7]\nlook_at = [0, 0, 0]\nfov = 60\n";
    let text = format!(
        "{head}[projection.projectors]\nsize = [3, 3]\nprojector = [\n\
         {{ node = [1, 1], tangent = [1, -1, -2] }},\n\
         {{ node = [0, 0], start = [-1, 4, 6], end = [-9, -3, -9] }},\n]\n"
    );
    let ProjectionSpec::Flexible(spec) = scene(&text).projection else {
        panic!("not flexible");
    };
    let VolumeSource::ProjectorGrid { grid, .. } = &spec.source else {
        panic!("no grid: {spec:?}");
    };
    assert_eq!(
        grid.projectors[1],
        NodeProjector {
            node: (0, 0),
            start: Some(DVec3::new(-1.0, 4.0, 6.0)),
            end: Some(DVec3::new(-9.0, -3.0, -9.0)),
            tangent: None,
            through: None,
        }
    );
    let flexible = crate::projection::flexible::Flexible::new(&spec, 32, 24).unwrap();
    let Volume::Grid(volume) = flexible.volume() else {
        panic!("not a grid volume");
    };
    assert!(volume.grid.is_curved());
    assert_eq!(volume.grid.starts()[0], DVec3::new(-1.0, 4.0, 6.0));
    let tangent = DVec3::new(1.0, -1.0, -2.0).normalize();
    assert_eq!(volume.grid.tangents()[4], Some(tangent));

    let with = |projectors: &str| format!("{head}projectors = {projectors}\n");
    assert_error_at(
        &with("{ projector = [{ node = [0, 5], tangent = [1, 0, 0] }] }"),
        7,
        38,
        "projector node [0, 5] is outside the 5 x 5 grid",
    );
    assert_error_at(
        &with("{ projector = [{ node = [0, 0], tangent = [nan, 0, 0] }] }"),
        7,
        56,
        "`tangent`",
    );
    // Tangents with `fit`: a curved fit. The two correspondences, at the centre node and
    // two depths, lie on its straight projector already, so the fit keeps that node
    // straight; the corner node that no correspondence constrains keeps its tangent.
    let ProjectionSpec::Flexible(spec) = scene(&with(
        "{ projector = [{ node = [0, 0], tangent = [1, 0, 0] }], \
         fit = [{ uv = [0.5, 0.5], point = [0, 0, 0] }, \
         { uv = [0.5, 0.5], point = [0, 1, 1.4] }] }",
    ))
    .projection
    else {
        panic!("not flexible");
    };
    let (flexible, reports) = crate::calibrate::build_flexible(&spec, 32, 24).unwrap();
    let Volume::Grid(volume) = flexible.volume() else {
        panic!("not a grid volume");
    };
    assert_eq!(volume.grid.tangents()[0], Some(DVec3::X));
    assert_eq!(volume.grid.tangents()[12], None);
    assert!(reports[0].max_angle_deg < 1e-9);
    // One correspondence cannot fix a node's end direction and tangent (four angles).
    assert_error(
        &with(
            "{ projector = [{ node = [0, 0], tangent = [1, 0, 0] }], \
             fit = [{ uv = [0.5, 0.5], point = [0, 0, 0] }] }",
        ),
        "got 1, add 1 more",
    );
    // A tangent from the end back to the start: named by node, in the file.
    assert_error(
        &with("{ projector = [{ node = [2, 2], start = [0, 0, 0], end = [0, 0, -5], tangent = [0, 0, 3] }] }"),
        "node (2, 2): the tangent",
    );
}

#[test]
fn trilinear_screen_map_key() {
    use crate::projection::trilinear_builders::SurfaceScreenMap;
    use crate::scene::TrilinearReflector;
    let mirror = |extra: &str| {
        format!("{CAMERA}[[object]]\nshape = \"sphere\"\nmaterial = \"mirror\"\n{extra}\n")
    };
    let reflectors = |extra: &str| scene(&mirror(extra)).trilinear_reflectors;
    let with = |screen_map| {
        vec![TrilinearReflector {
            screen_map,
            ..TrilinearReflector::new(1)
        }]
    };
    assert_eq!(
        reflectors("trilinear_reflector = true"),
        with(SurfaceScreenMap::Affine)
    );
    assert_eq!(
        reflectors("trilinear_reflector = true\ntrilinear_screen_map = \"affine\""),
        with(SurfaceScreenMap::Affine)
    );
    assert_eq!(
        reflectors("trilinear_reflector = true\ntrilinear_screen_map = \"projective\""),
        with(SurfaceScreenMap::Projective)
    );
    assert_error_at(
        &mirror("trilinear_reflector = true\ntrilinear_screen_map = \"screen\""),
        10,
        24,
        "unknown trilinear_screen_map \"screen\"",
    );
    assert_error_at(
        &mirror("trilinear_screen_map = \"affine\""),
        9,
        24,
        "needs `trilinear_reflector = true`",
    );
}

#[test]
fn camera_triangles_key() {
    let mirror = |extra: &str| {
        format!(
            "{CAMERA}[[object]]\nshape = \"sphere\"\ntessellation = 8\nmaterial = \"mirror\"\n{extra}\n"
        )
    };
    let size = |extra: &str| {
        scene(&mirror(&format!("trilinear_reflector = true\n{extra}"))).trilinear_reflectors[0]
            .camera_triangles
    };
    assert_eq!(size(""), None);
    assert_eq!(size("camera_triangles = 20"), Some(20));
    let own = scene(&mirror("")).objects[0].mesh.triangles.len();
    assert_eq!(size(&format!("camera_triangles = {own}")), Some(own));
    let at = |extra: &str, message: &str| {
        assert_error_at(
            &mirror(&format!("trilinear_reflector = true\n{extra}")),
            11,
            20,
            message,
        )
    };
    at(
        "camera_triangles = 0",
        &format!("`camera_triangles` must be between 1 and the object's {own} triangles, not 0"),
    );
    at(
        &format!("camera_triangles = {}", own + 1),
        &format!(
            "must be between 1 and the object's {own} triangles, not {}",
            own + 1
        ),
    );
    at("camera_triangles = -3", "invalid value");
    at("camera_triangles = 2.5", "invalid type");
    at("camera_triangles = \"auto\"", "invalid type");
    assert_error_at(
        &mirror("trilinear_reflector = true\ntrilinear_refine_px = 0.25\ncamera_triangles = 20"),
        12,
        20,
        "leave out `trilinear_refine_px`",
    );
    assert_error_at(
        &mirror("camera_triangles = 20"),
        10,
        20,
        "`camera_triangles` needs `trilinear_reflector = true`",
    );
}

#[test]
fn camera_rays_key() {
    use crate::projection::trilinear_builders::SurfaceRays;
    let object = |material: &str, extra: &str| {
        format!("{CAMERA}[[object]]\nshape = \"sphere\"\nmaterial = \"{material}\"\n{extra}\n")
    };
    let rays = |extra: &str| {
        scene(&object(
            "mirror",
            &format!("trilinear_reflector = true\n{extra}"),
        ))
        .trilinear_reflectors[0]
            .camera_rays
    };
    assert_eq!(rays(""), SurfaceRays::Interpolated);
    assert_eq!(
        rays("camera_rays = \"interpolated\""),
        SurfaceRays::Interpolated
    );
    assert_eq!(
        rays("camera_rays = \"per-fragment\""),
        SurfaceRays::PerFragment
    );
    assert_error_at(
        &object(
            "mirror",
            "trilinear_reflector = true\ncamera_rays = \"exact\"",
        ),
        10,
        15,
        "unknown camera_rays \"exact\"; expected one of: interpolated, per-fragment",
    );
    assert_error_at(
        &object(
            "glass",
            "trilinear_reflector = true\ncamera_rays = \"per-fragment\"",
        ),
        10,
        15,
        "`camera_rays = \"per-fragment\"` needs material \"mirror\"",
    );
    assert_error_at(
        &object("mirror", "camera_rays = \"per-fragment\""),
        9,
        15,
        "`camera_rays` needs `trilinear_reflector = true`",
    );
    // Glass keeps its interpolated rays.
    let glass = scene(&object(
        "glass",
        "trilinear_reflector = true\ncamera_rays = \"interpolated\"",
    ));
    assert_eq!(
        glass.trilinear_reflectors[0].camera_rays,
        SurfaceRays::Interpolated
    );
}

#[test]
fn trilinear_refine_px_key() {
    use crate::scene::TrilinearReflector;
    let mirror = |extra: &str| {
        format!("{CAMERA}[[object]]\nshape = \"sphere\"\nmaterial = \"mirror\"\n{extra}\n")
    };
    let refine_px = |extra: &str| {
        scene(&mirror(&format!("trilinear_reflector = true\n{extra}"))).trilinear_reflectors[0]
            .refine_px
    };
    assert_eq!(refine_px(""), TrilinearReflector::DEFAULT_REFINE_PX);
    assert_eq!(refine_px("trilinear_refine_px = 0.25"), 0.25);
    assert_eq!(refine_px("trilinear_refine_px = 0"), 0.0);
    assert_error_at(
        &mirror("trilinear_reflector = true\ntrilinear_refine_px = -1.0"),
        10,
        23,
        "`trilinear_refine_px` must be at least 0 (0: no refinement), not -1",
    );
    assert_error_at(
        &mirror("trilinear_reflector = true\ntrilinear_refine_px = nan"),
        10,
        23,
        "trilinear_refine_px",
    );
    assert_error_at(
        &mirror("trilinear_reflector = true\ntrilinear_refine_px = \"adaptive\""),
        10,
        23,
        "invalid type",
    );
    assert_error_at(
        &mirror("trilinear_refine_px = 0.5"),
        9,
        23,
        "needs `trilinear_reflector = true`",
    );
}

/// A scene lists every file it was read from: itself, its models with the files they name,
/// its textures and its trilinear surface.
#[test]
fn scenes_list_the_files_they_were_read_from() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let inputs = |name: &str| -> Vec<(&'static str, String)> {
        let scene = load(&scenes.join(name)).unwrap();
        let mut files: Vec<_> = scene
            .inputs
            .iter()
            .map(|f| {
                let path = f.path.strip_prefix(&scenes).unwrap();
                (f.what, path.to_string_lossy().into_owned())
            })
            .collect();
        files.dedup();
        files
    };
    assert_eq!(
        inputs("models.toml"),
        [
            ("scene file", "models.toml"),
            ("model file", "models/octahedron.obj"),
            ("material library", "models/octahedron.mtl"),
            ("texture", "models/checker.png"),
            ("model file", "models/pyramid.ply"),
            ("model file", "models/tetra-quad.glb"),
            ("texture", "models/checker.png"),
        ]
        .map(|(what, path)| (what, path.to_string()))
    );
    assert_eq!(
        inputs("trilinear-fan.toml"),
        [
            ("scene file", "trilinear-fan.toml".to_string()),
            ("trilinear surface", "surfaces/fan18.obj".to_string())
        ]
    );
    assert!(scene(CAMERA).inputs.is_empty());
}
