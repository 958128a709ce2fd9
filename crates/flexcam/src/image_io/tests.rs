use std::fs;

use super::*;

fn frame() -> Frame {
    let mut f = Frame::new(3, 2, Vec3::new(0.2, 0.4, 0.6));
    f.depth[0] = 1.5;
    f.ids[0] = 7;
    f
}

#[test]
fn linear_encoding_round_trips_flat_colours() {
    for k in 0..=255u8 {
        assert_eq!(encode_channel(k as f32 / 255.0, ColorEncoding::Linear), k);
    }
    assert_eq!(encode_channel(f32::NAN, ColorEncoding::Srgb), 0);
    assert_eq!(encode_channel(0.5, ColorEncoding::Srgb), 188);
}

#[test]
fn png_ids_and_pfm_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("c.png");
    write_color_png(&frame(), &png, ColorEncoding::Linear).unwrap();
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.get_pixel(2, 1).0, [51, 102, 153]);

    let ids = dir.path().join("i.png");
    write_ids_png(&frame(), &ids).unwrap();
    let img = image::open(&ids).unwrap().to_luma16();
    assert_eq!(img.get_pixel(0, 0).0, [7]);

    let pfm = dir.path().join("d.pfm");
    write_depth(&frame(), &pfm, DepthFormat::of(&pfm).unwrap()).unwrap();
    let bytes = fs::read(&pfm).unwrap();
    let header = b"Pf\n3 2\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    // Pixel (0,0) is in the top row, which PFM stores last.
    let top_row = header.len() + 3 * 4;
    assert_eq!(
        f32::from_le_bytes(bytes[top_row..top_row + 4].try_into().unwrap()),
        1.5
    );
    assert!(
        f32::from_le_bytes(bytes[header.len()..header.len() + 4].try_into().unwrap()).is_infinite()
    );
}

#[test]
fn gif_frames_read_back_in_order_with_their_delay() {
    use image::AnimationDecoder;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.gif");
    let mut gif = GifFrames::default();
    let mut second = frame();
    second
        .color
        .iter_mut()
        .for_each(|c| *c = Vec3::new(0.0, 0.0, 1.0));
    gif.push(&frame(), ColorEncoding::Linear).unwrap();
    gif.push(&second, ColorEncoding::Linear).unwrap();
    gif.write(&path, 25.0).unwrap();
    let file = std::io::BufReader::new(fs::File::open(&path).unwrap());
    let decoded = image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
    assert_eq!(decoded.len(), 2);
    assert_eq!(decoded[0].delay().numer_denom_ms(), (40, 1));
    assert_eq!(decoded[1].buffer().get_pixel(0, 0).0, [0, 0, 255, 255]);
}

#[test]
fn exr_depth_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("d.exr");
    write_depth(&frame(), &exr, DepthFormat::Exr).unwrap();
    let image = exr::prelude::read_all_flat_layers_from_file(&exr).unwrap();
    let samples = &image.layer_data[0].channel_data.list[0].sample_data;
    assert_eq!(samples.value_by_flat_index(0).to_f32(), 1.5);
    assert!(samples.value_by_flat_index(1).to_f32().is_infinite());
    assert!(DepthFormat::of(&dir.path().join("d.tif")).is_err());
}

/// The names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Stages `bytes` for output `id` of `set`.
fn stage(set: &mut OutputSet, id: OutputId, bytes: &'static [u8]) {
    set.stage(id, |tmp| {
        fs::write(tmp, bytes).map_err(|e| crate::Error::new(e.to_string()))
    })
    .unwrap();
}

#[test]
fn outputs_appear_only_on_commit_in_new_folders() {
    let dir = tempfile::tempdir().unwrap();
    let mut set = OutputSet::new();
    let a = set
        .output("the output", &dir.path().join("a.txt"), &["txt"])
        .unwrap();
    let b = set
        .output("the stats output", &dir.path().join("n/m/b.txt"), &["txt"])
        .unwrap();
    stage(&mut set, a, b"a");
    stage(&mut set, b, b"b");
    assert!(!dir.path().join("a.txt").exists());
    assert!(!dir.path().join("n").exists());
    set.commit().unwrap();
    assert_eq!(listing(dir.path()), ["a.txt", "n"]);
    assert_eq!(fs::read(dir.path().join("n/m/b.txt")).unwrap(), b"b");
}

#[test]
fn a_failed_commit_restores_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let old = dir.path().join("old.txt");
    fs::write(&old, b"old").unwrap();
    // A folder where the last output should go: its rename fails after the others moved.
    fs::create_dir_all(dir.path().join("blocked.txt/inside")).unwrap();
    let mut set = OutputSet::new();
    let ids = [
        set.output("the output", &old, &["txt"]).unwrap(),
        set.output("the new output", &dir.path().join("n/new.txt"), &["txt"])
            .unwrap(),
        set.output(
            "the blocked output",
            &dir.path().join("blocked.txt"),
            &["txt"],
        )
        .unwrap(),
    ];
    for id in ids {
        stage(&mut set, id, b"new");
    }
    let e = set.commit().unwrap_err().to_string();
    assert!(e.contains("blocked.txt: cannot write"), "{e}");
    assert_eq!(fs::read(&old).unwrap(), b"old");
    assert_eq!(listing(dir.path()), ["blocked.txt", "old.txt"]);
    assert_eq!(listing(&dir.path().join("blocked.txt")), ["inside"]);
}

#[cfg(unix)]
#[test]
fn a_dropped_set_leaves_nothing_and_a_read_only_folder_fails_before_commit() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let mut set = OutputSet::new();
    let a = set
        .output("the output", &dir.path().join("a.txt"), &["txt"])
        .unwrap();
    stage(&mut set, a, b"a");
    drop(set);
    assert!(listing(dir.path()).is_empty());

    // Made read-only between staging and commit: the first output is placed, the second
    // cannot be, and the first is taken back.
    let locked = dir.path().join("locked");
    fs::create_dir(&locked).unwrap();
    let mut set = OutputSet::new();
    let a = set
        .output("the output", &dir.path().join("a.txt"), &["txt"])
        .unwrap();
    let b = set
        .output("the ids output", &locked.join("n/b.txt"), &["txt"])
        .unwrap();
    stage(&mut set, a, b"a");
    stage(&mut set, b, b"b");
    fs::set_permissions(&locked, fs::Permissions::from_mode(0o555)).unwrap();
    let writable = fs::create_dir(locked.join("probe")).is_ok();
    let result = set.commit();
    fs::set_permissions(&locked, fs::Permissions::from_mode(0o755)).unwrap();
    if writable {
        // Permissions do not bind this user (root): nothing to observe.
        return;
    }
    let e = result.unwrap_err().to_string();
    assert!(e.contains("cannot create the folder"), "{e}");
    assert_eq!(listing(dir.path()), ["locked"]);
}

#[test]
fn outputs_aimed_at_inputs_or_each_other_are_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.png");
    fs::write(&scene, b"scene").unwrap();
    let mut set = OutputSet::new();
    set.input("the scene file", &scene).unwrap();
    let e = set
        .output("the ids output", &dir.path().join("./x/../s.png"), &["png"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the ids output would overwrite the scene file"),
        "{e}"
    );

    let mut set = OutputSet::new();
    set.output("the output", &dir.path().join("o.png"), &["png"])
        .unwrap();
    let e = set
        .output("the ids output", &dir.path().join(".//o.png"), &["png"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the ids output is the same file as the output"),
        "{e}"
    );
    // An input declared after the output is caught too, named the same way round.
    let e = set
        .input("the photo", &scene)
        .and_then(|()| set.input("the texture", &dir.path().join("o.png")));
    assert!(e.is_ok(), "o.png does not exist yet: not an input");
    fs::write(dir.path().join("o.png"), b"").unwrap();
    let e = set
        .input("the texture", &dir.path().join("o.png"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("the output would overwrite the texture"), "{e}");
}

/// A frame whose colours leave [0, 1] (HDR) and differ per pixel, with depth and ids.
fn hdr_frame() -> Frame {
    let mut f = Frame::new(3, 2, Vec3::ZERO);
    for (i, c) in f.color.iter_mut().enumerate() {
        let k = i as f32;
        *c = Vec3::new(0.25 * k, 7.5 - k, -0.125 * k);
    }
    f.depth[1] = 2.5;
    f.ids[1] = 70_000;
    f.ids[4] = 3;
    f
}

/// The channels of the first layer of the EXR at `path`, by name, as read by the exr crate.
fn exr_channels(path: &std::path::Path) -> Vec<(String, exr::prelude::FlatSamples)> {
    let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    let layer = &image.layer_data[0];
    assert_eq!((layer.size.0, layer.size.1), (3, 2));
    layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.clone()))
        .collect()
}

fn f32_samples(samples: &exr::prelude::FlatSamples) -> Vec<f32> {
    match samples {
        exr::prelude::FlatSamples::F32(v) => v.clone(),
        other => panic!("not f32: {other:?}"),
    }
}

#[test]
fn colour_exr_reads_back_as_the_linear_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.exr");
    let f = hdr_frame();
    let format = ColorFormat::of(&path, PngBits::Eight).unwrap();
    write_color(&f, &path, format, ColorEncoding::Srgb).unwrap();
    let channels = exr_channels(&path);
    let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["B", "G", "R"]);
    for (name, k) in [("R", 0), ("G", 1), ("B", 2)] {
        let (_, samples) = channels.iter().find(|(n, _)| n == name).unwrap();
        let expected: Vec<f32> = f.color.iter().map(|c| c[k]).collect();
        assert_eq!(f32_samples(samples), expected, "{name}");
    }
}

#[test]
fn colour_pfm_reads_back_as_the_linear_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.PFM");
    let f = hdr_frame();
    let format = ColorFormat::of(&path, PngBits::Eight).unwrap();
    assert_eq!(format, ColorFormat::Pfm);
    write_color(&f, &path, format, ColorEncoding::Linear).unwrap();
    // A PFM reader: three header lines, then little-endian (negative scale) floats, the
    // bottom row first.
    let bytes = fs::read(&path).unwrap();
    let mut header = bytes.splitn(4, |&b| b == b'\n');
    assert_eq!(header.next().unwrap(), b"PF");
    assert_eq!(header.next().unwrap(), b"3 2");
    let scale: f32 = std::str::from_utf8(header.next().unwrap())
        .unwrap()
        .parse()
        .unwrap();
    assert!(scale < 0.0);
    let data = header.next().unwrap();
    assert_eq!(data.len(), 3 * 2 * 3 * 4);
    let values: Vec<f32> = data
        .chunks(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    for (row_in_file, row) in values.chunks(9).enumerate() {
        let y = 1 - row_in_file;
        for x in 0..3 {
            let c = f.color[y * 3 + x];
            assert_eq!(&row[3 * x..3 * x + 3], &c.to_array(), "pixel ({x}, {y})");
        }
    }
}

#[test]
fn png16_holds_the_encoded_channels() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.png");
    let mut f = frame();
    f.color[1] = Vec3::new(0.5, 2.0, -1.0);
    let format = ColorFormat::of(&path, PngBits::Sixteen).unwrap();
    write_color(&f, &path, format, ColorEncoding::Srgb).unwrap();
    let img = image::open(&path).unwrap();
    assert_eq!(img.color(), image::ColorType::Rgb16);
    let img = img.to_rgb16();
    assert_eq!(img.get_pixel(1, 0).0, [48_192, 65_535, 0]);
    assert_eq!(
        img.get_pixel(2, 1).0[0],
        encode_channel16(0.2, ColorEncoding::Srgb)
    );
    write_color(&f, &path, format, ColorEncoding::Linear).unwrap();
    let img = image::open(&path).unwrap().to_rgb16();
    assert_eq!(img.get_pixel(2, 1).0, [13_107, 26_214, 39_321]);
    // The 8-bit PNG is unchanged by the choice of format.
    let eight = dir.path().join("c8.png");
    let format = ColorFormat::of(&eight, PngBits::Eight).unwrap();
    write_color(&f, &eight, format, ColorEncoding::Linear).unwrap();
    let direct = dir.path().join("d8.png");
    write_color_png(&f, &direct, ColorEncoding::Linear).unwrap();
    assert_eq!(fs::read(eight).unwrap(), fs::read(direct).unwrap());
    let e = ColorFormat::of(std::path::Path::new("x.tif"), PngBits::Eight).unwrap_err();
    assert!(
        e.to_string().contains("x.tif") && e.to_string().contains(".exr"),
        "{e}"
    );
}

#[test]
fn aov_exr_holds_colour_depth_and_ids() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.exr");
    let f = hdr_frame();
    write_aovs_exr(&f, &path).unwrap();
    let channels = exr_channels(&path);
    let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["B", "G", "R", "Z", "id"]);
    let get = |name: &str| &channels.iter().find(|(n, _)| n == name).unwrap().1;
    let red: Vec<f32> = f.color.iter().map(|c| c.x).collect();
    assert_eq!(f32_samples(get("R")), red);
    let z = f32_samples(get("Z"));
    assert_eq!(z[1], 2.5);
    assert!(z[0].is_infinite() && z[5].is_infinite());
    match get("id") {
        exr::prelude::FlatSamples::U32(ids) => assert_eq!(ids, &f.ids),
        other => panic!("id is not u32: {other:?}"),
    }
    let mut colour_only = f.clone();
    colour_only.ids.clear();
    let e = write_aovs_exr(&colour_only, &path).unwrap_err();
    assert!(e.to_string().contains("depth and ids"), "{e}");
}

#[test]
fn ids_preview_colours_are_fixed_visible_and_distinct() {
    assert_eq!(id_preview_color(0), [0, 0, 0]);
    let colours: Vec<[u8; 3]> = (1..=255).map(id_preview_color).collect();
    assert!(colours.iter().all(|c| c.iter().all(|&v| v >= 64)));
    let distinct: std::collections::HashSet<_> = colours.iter().collect();
    assert_eq!(distinct.len(), colours.len());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.png");
    let f = hdr_frame();
    write_ids_preview_png(&f, &path).unwrap();
    let img = image::open(&path).unwrap();
    assert_eq!(img.color(), image::ColorType::Rgb8);
    let img = img.to_rgb8();
    assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0]);
    assert_eq!(img.get_pixel(1, 0).0, id_preview_color(70_000));
    assert_eq!(img.get_pixel(1, 1).0, id_preview_color(3));
}
