use glam::{DVec2, Vec3};
use image::{GrayImage, ImageBuffer, Luma, RgbImage};

use super::{HeightField, HeightMap};
use crate::scene::Texture;

/// A small deterministic pseudo-random sequence in [0, 1).
fn noise(n: usize, seed: u64) -> Vec<f32> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect()
}

fn uv_points(seed: u64) -> Vec<DVec2> {
    let r = noise(400, seed);
    r.chunks(2)
        .map(|p| DVec2::new(p[0] as f64 * 6.0 - 3.0, p[1] as f64 * 6.0 - 3.0))
        .collect()
}

#[test]
fn samples_bit_for_bit_as_a_texture_of_the_same_grey_image() {
    let (w, h) = (7, 5);
    let values = noise(w * h, 3);
    let map = HeightMap::from_values(w as u32, h as u32, values.clone()).unwrap();
    let texture = Texture {
        width: w as u32,
        height: h as u32,
        texels: values.iter().map(|&g| Vec3::splat(g)).collect(),
    };
    for uv in uv_points(5) {
        let want = texture.bilinear(uv.as_vec2()).x;
        assert_eq!(map.sample(uv), want as f64, "at {uv}");
    }
    // v = 1 is the top row: the centre of the top-left texel.
    let top_left = DVec2::new(0.5 / w as f64, 1.0 - 0.5 / h as f64);
    assert!((map.sample(top_left) - values[0] as f64).abs() < 1e-6);
    assert_eq!(map.max(), values.iter().copied().fold(0.0, f32::max) as f64);
}

#[test]
fn loads_8_and_16_bit_grey_pngs_linearly() {
    let dir = tempfile::tempdir().unwrap();
    let p8 = dir.path().join("h8.png");
    GrayImage::from_raw(2, 1, vec![0, 255])
        .unwrap()
        .save(&p8)
        .unwrap();
    let map = HeightMap::load(&p8).unwrap();
    // The right texel's centre, and the midpoint of the two centres (no sRGB decoding).
    assert_eq!(map.sample(DVec2::new(0.75, 0.5)), 1.0);
    assert_eq!(map.sample(DVec2::new(0.5, 0.5)), 0.5);
    let p16 = dir.path().join("h16.png");
    let img: ImageBuffer<Luma<u16>, Vec<u16>> =
        ImageBuffer::from_raw(1, 2, vec![65535, 13107]).unwrap();
    img.save(&p16).unwrap();
    let map = HeightMap::load(&p16).unwrap();
    assert_eq!(map.sample(DVec2::new(0.5, 0.75)), 1.0);
    assert_eq!(
        map.sample(DVec2::new(0.5, 0.25)),
        (13107.0f32 / 65535.0) as f64
    );
    assert_eq!(map.max(), 1.0);
}

#[test]
fn refuses_non_grey_and_unreadable_files_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let rgb = dir.path().join("colour.png");
    RgbImage::new(2, 2).save(&rgb).unwrap();
    let e = HeightMap::load(&rgb).unwrap_err().to_string();
    assert!(
        e.starts_with(&rgb.display().to_string()) && e.contains("grey PNG"),
        "{e}"
    );
    let jpeg = dir.path().join("grey.jpg");
    GrayImage::new(2, 2).save(&jpeg).unwrap();
    let e = HeightMap::load(&jpeg).unwrap_err().to_string();
    assert!(e.contains("grey.jpg") && e.contains("Jpeg"), "{e}");
    let junk = dir.path().join("junk.png");
    std::fs::write(&junk, b"not an image").unwrap();
    assert!(HeightMap::load(&junk)
        .unwrap_err()
        .to_string()
        .contains("junk.png"));
    let missing = dir.path().join("missing.png");
    assert!(HeightMap::load(&missing)
        .unwrap_err()
        .to_string()
        .contains("cannot read"));
    assert!(HeightMap::from_values(0, 3, vec![]).is_err());
    assert!(HeightMap::from_values(2, 2, vec![0.5; 3]).is_err());
    assert!(HeightMap::from_values(1, 2, vec![0.5, 1.5]).is_err());
    assert!(HeightMap::from_values(1, 1, vec![f32::NAN]).is_err());
}

#[test]
fn ranges_bound_every_sample_in_the_rectangle() {
    for (w, h, seed) in [(1, 1, 1), (5, 3, 2), (16, 16, 3), (37, 20, 4)] {
        let values = noise(w * h, seed);
        let map = HeightField::Map(HeightMap::from_values(w as u32, h as u32, values).unwrap());
        let corners = uv_points(seed + 10);
        for (i, pair) in corners.chunks(2).enumerate() {
            let size = DVec2::new(0.7, 0.4) * 0.5f64.powi(i as i32 % 9) * (pair[1].x.abs() + 0.1);
            let (min, max) = (pair[0], pair[0] + size);
            let [lo, hi] = map.range(min, max);
            for a in 0..=24 {
                for b in 0..=24 {
                    let uv = min + size * DVec2::new(a as f64 / 24.0, b as f64 / 24.0);
                    let s = map.sample(uv);
                    assert!(lo <= s && s <= hi, "{s} outside [{lo}, {hi}] at {uv}");
                }
            }
        }
        // Huge and non-finite rectangles give the whole map's range.
        let whole = map.range(DVec2::splat(-1e300), DVec2::splat(1e300));
        assert!(whole[1] >= map.max() && whole[1] < map.max() + 1e-5);
        assert_eq!(map.range(DVec2::NAN, DVec2::NAN), whole);
    }
}

#[test]
fn small_rectangles_get_tight_ranges() {
    // A ramp 64 texels wide: a rectangle a few texels across is bounded within a few texels'
    // worth of the ramp (the pyramid block a small rectangle falls in is at most 4x its size).
    let values: Vec<f32> = (0..64 * 8).map(|i| (i % 64) as f32 / 63.0).collect();
    let map = HeightMap::from_values(64, 8, values).unwrap();
    let [lo, hi] = map.range(DVec2::new(0.5, 0.2), DVec2::new(0.52, 0.3));
    assert!(hi - lo < 12.0 / 63.0, "[{lo}, {hi}]");
    assert!(lo <= map.sample(DVec2::new(0.51, 0.25)));
}
