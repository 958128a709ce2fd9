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
