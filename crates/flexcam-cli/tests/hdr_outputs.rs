//! The colour output by extension (PNG 8- or 16-bit, linear float OpenEXR and PFM), the
//! multi-channel AOV EXR and the ids preview of `flexcam render`, read back by other readers
//! (the exr crate, a PFM parser, the image crate) and compared with each other and with the
//! flat PNG, whose bytes are round(255 * colour).

use std::fs;
use std::path::Path;

use exr::prelude::FlatSamples;
use tempfile::TempDir;

mod common;
use common::{run, run_ok};

/// Renders the default scene, 32 x 24, flat, to `outputs` in `dir`.
fn render_ok(dir: &TempDir, outputs: &[&str]) {
    let small = [
        "render",
        "--width",
        "32",
        "--height",
        "24",
        "--shading",
        "flat",
    ];
    run_ok(dir, &[&small[..], outputs].concat());
}

/// The channels of the EXR at `path` (one layer of 32 x 24 pixels), sorted by name.
fn exr_channels(path: &Path) -> Vec<(String, FlatSamples)> {
    let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    assert_eq!(image.layer_data.len(), 1);
    let layer = &image.layer_data[0];
    assert_eq!((layer.size.0, layer.size.1), (32, 24));
    layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.clone()))
        .collect()
}

fn floats(channels: &[(String, FlatSamples)], name: &str) -> Vec<f32> {
    match &channels.iter().find(|(n, _)| n == name).unwrap().1 {
        FlatSamples::F32(v) => v.clone(),
        other => panic!("{name} is not f32: {other:?}"),
    }
}

/// The float channels `R`, `G` and `B` of `channels`.
fn rgb_of(channels: &[(String, FlatSamples)]) -> [Vec<f32>; 3] {
    ["R", "G", "B"].map(|name| floats(channels, name))
}

/// Asserts that the flat (linear 8-bit) PNG `png` holds round(255 * value) of `rgb`.
fn assert_flat_png_holds(rgb: &[Vec<f32>; 3], png: &image::RgbImage) {
    for (i, pixel) in png.pixels().enumerate() {
        let expected = rgb.each_ref().map(|c| (255.0 * c[i]).round() as u8);
        assert_eq!(pixel.0, expected, "pixel {i}");
    }
}

/// The samples of a PFM, row by row from the top, and its channel count.
fn read_pfm(path: &Path) -> (usize, Vec<f32>) {
    let bytes = fs::read(path).unwrap();
    let mut parts = bytes.splitn(4, |&b| b == b'\n');
    let channels = match parts.next().unwrap() {
        b"PF" => 3,
        b"Pf" => 1,
        other => panic!("not a PFM: {other:?}"),
    };
    assert_eq!(parts.next().unwrap(), b"32 24");
    assert_eq!(parts.next().unwrap(), b"-1.0");
    let values: Vec<f32> = parts
        .next()
        .unwrap()
        .chunks(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(values.len(), 32 * 24 * channels);
    let top_first = values.chunks(32 * channels).rev().flatten().copied();
    (channels, top_first.collect())
}

#[test]
fn float_colour_and_aovs_agree_with_the_png_outputs() {
    let dir = TempDir::new().unwrap();
    let d = dir.path();
    render_ok(
        &dir,
        &[
            "-o",
            "c.png",
            "--ids",
            "ids.png",
            "--depth",
            "z.pfm",
            "--ids-preview",
            "p.png",
        ],
    );
    render_ok(&dir, &["-o", "c.exr", "--aovs", "aovs.exr"]);
    render_ok(&dir, &["-o", "c.PFM"]);
    render_ok(&dir, &["-o", "c16.png", "--png-bits", "16"]);

    let png = image::open(d.join("c.png")).unwrap().to_rgb8();
    let colour = exr_channels(&d.join("c.exr"));
    let names: Vec<&str> = colour.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["B", "G", "R"]);
    let rgb = rgb_of(&colour);
    assert_flat_png_holds(&rgb, &png);
    let (channels, pfm) = read_pfm(&d.join("c.PFM"));
    assert_eq!(channels, 3);
    for (i, v) in pfm.iter().enumerate() {
        assert_eq!(v.to_bits(), rgb[i % 3][i / 3].to_bits(), "sample {i}");
    }
    let png16 = image::open(d.join("c16.png")).unwrap().to_rgb16();
    for (i, pixel) in png16.pixels().enumerate() {
        let expected = rgb
            .each_ref()
            .map(|c| (65535.0 * c[i].clamp(0.0, 1.0)).round() as u16);
        assert_eq!(pixel.0, expected, "pixel {i}");
    }

    let aovs = exr_channels(&d.join("aovs.exr"));
    let names: Vec<&str> = aovs.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "B", "G", "N.X", "N.Y", "N.Z", "Ng.X", "Ng.Y", "Ng.Z", "P.X", "P.Y", "P.Z", "R", "Z",
            "id", "uv.U", "uv.V"
        ]
    );
    for (k, name) in ["R", "G", "B"].into_iter().enumerate() {
        assert_eq!(floats(&aovs, name), rgb[k], "{name}");
    }
    let (_, depth) = read_pfm(&d.join("z.pfm"));
    let z = floats(&aovs, "Z");
    assert!(z
        .iter()
        .zip(&depth)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    assert!(z.iter().any(|v| v.is_finite()));
    let ids = image::open(d.join("ids.png")).unwrap().to_luma16();
    let FlatSamples::U32(aov_ids) = &aovs.iter().find(|(n, _)| n == "id").unwrap().1 else {
        panic!("id is not u32");
    };
    let png_ids: Vec<u32> = ids.pixels().map(|p| u32::from(p.0[0])).collect();
    assert_eq!(aov_ids, &png_ids);
    assert!(png_ids.iter().any(|&id| id != 0) && png_ids.contains(&0));

    let preview = image::open(d.join("p.png")).unwrap().to_rgb8();
    for (pixel, &id) in preview.pixels().zip(&png_ids) {
        assert_eq!(pixel.0, flexcam::image_io::id_preview_color(id));
    }
}

/// Refusals come before any rendering, in one line, and leave no file behind; a failure
/// while committing the outputs leaves none of them.
#[test]
fn bad_outputs_are_refused_and_nothing_is_written() {
    let dir = TempDir::new().unwrap();
    let d = dir.path();
    let refused = |args: &[&str], expected: &str| {
        let out = run(
            &dir,
            &[&["render", "--width", "8", "--height", "8"][..], args].concat(),
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert_eq!(fs::read_dir(d).unwrap().count(), 0, "{args:?} left files");
    };
    refused(
        &["-o", "c.tif"],
        "c.tif: unsupported output extension \"tif\"",
    );
    refused(&["-o", "c.exr", "--png-bits", "16"], "c.exr: --png-bits 16");
    refused(
        &["-o", "c.exr", "--aovs", "a.pfm"],
        "a.pfm: unsupported output",
    );
    refused(
        &["-o", "c.exr", "--ids-preview", "p.exr"],
        "p.exr: unsupported",
    );
    refused(
        &["-o", "c.exr", "--aovs", "./c.exr"],
        "the AOV output is the same file as the output",
    );
    refused(&["--png-bits", "12"], "12");

    // The AOV path is a folder: the colour and preview outputs are not written either.
    fs::create_dir_all(d.join("a.exr/inside")).unwrap();
    let out = run(
        &dir,
        &[
            "render",
            "--width",
            "8",
            "--height",
            "8",
            "-o",
            "c.exr",
            "--ids-preview",
            "new/p.png",
            "--aovs",
            "a.exr",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("a.exr: cannot write"), "{stderr}");
    let left: Vec<_> = fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["a.exr"]);
}

#[test]
fn animate_writes_float_frames_by_extension() {
    let dir = TempDir::new().unwrap();
    let d = dir.path();
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/flexible-animation.toml"
    );
    for pattern in ["f_##.exr", "f_##.png"] {
        let args = [
            "animate",
            scene,
            "--width",
            "32",
            "--height",
            "24",
            "--shading",
            "flat",
            "-o",
            pattern,
        ];
        run_ok(&dir, &args);
    }
    let colour = exr_channels(&d.join("f_01.exr"));
    let png = image::open(d.join("f_01.png")).unwrap().to_rgb8();
    let rgb = rgb_of(&colour);
    assert_flat_png_holds(&rgb, &png);
}
