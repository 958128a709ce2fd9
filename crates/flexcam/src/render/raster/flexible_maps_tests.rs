//! Method raster against the ray caster on flexible projections whose inverse goes through a
//! user-defined grid map (Newton's method) or a static blend of two volumes (eq. 6.1): the
//! ids agree at every pixel away from object edges.

use std::path::Path;

use super::*;
use crate::render::{Method, PreparedScene};
use crate::scene::file;

/// A floor, a box and a ball seen by the flexible projection `projection` (the lines of a
/// `[projection]` table after its header).
fn scene(projection: &str) -> Scene {
    let text = format!(
        "[image]\nwidth = 96\nheight = 72\n[projection]\n{projection}\n\
         [[object]]\nshape = \"plane\"\nsize = [8.0, 8.0]\ntessellation = 8\n\
         [[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\ntranslate = [-0.8, 0.5, 0.0]\n\
         rotate = [0.0, 30.0, 0.0]\ntessellation = 4\n\
         [[object]]\nshape = \"sphere\"\nscale = 0.6\ntranslate = [1.0, 0.6, 0.4]\n"
    );
    file::parse(&text, Path::new("maps.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// The pixels whose 3 x 3 neighbourhood in `reference` shows one id, and how many of them
/// `raster` shows another id at.
fn interior_disagreement(reference: &Frame, raster: &Frame) -> (usize, usize) {
    let (w, h) = (reference.width as usize, reference.height as usize);
    let mut interior = 0;
    let mut wrong = Vec::new();
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let id = reference.ids[y * w + x];
            let uniform = (y - 1..=y + 1)
                .all(|yy| (x - 1..=x + 1).all(|xx| reference.ids[yy * w + xx] == id));
            if uniform {
                interior += 1;
                if raster.ids[y * w + x] != id {
                    wrong.push((x, y, id, raster.ids[y * w + x]));
                }
            }
        }
    }
    if !wrong.is_empty() {
        eprintln!("disagreeing pixels (x, y, reference, raster): {wrong:?}");
    }
    (interior, wrong.len())
}

/// Renders `scene` by both methods and asserts full agreement away from edges.
fn agrees_away_from_edges(name: &str, scene: &Scene) {
    let prepared = PreparedScene::new(scene);
    let projection = scene.projection.build(96, 72).unwrap();
    let options = RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let frame = |method: Method| {
        method
            .render(&prepared, projection.as_ref(), &options)
            .unwrap_or_else(|e| panic!("{name}, {method:?}: {e}"))
            .0
    };
    let (reference, raster) = (frame(Method::Raycast), frame(Method::Raster));
    let (interior, wrong) = interior_disagreement(&reference, &raster);
    assert!(interior > 96 * 72 / 2, "{name}: {interior} interior pixels");
    let objects = reference.ids.iter().filter(|&&id| id > 1).count();
    assert!(
        objects > 200,
        "{name}: the box and ball cover {objects} pixels"
    );
    assert_eq!(
        wrong, 0,
        "{name}: {wrong} of {interior} interior pixels differ"
    );
}

const PERSPECTIVE: &str = "type = \"flexible\"\npreset = \"perspective\"\n\
                           position = [0.0, 2.5, 5.0]\nlook_at = [0.0, 0.4, 0.0]\nfov = 60.0\n";

#[test]
fn a_grid_map_rasterises_as_it_ray_casts() {
    // A 6 x 5 grid that squeezes the image towards the centre column and bends the rows.
    let mut uv = Vec::new();
    for j in 0..5 {
        for i in 0..6 {
            let (s, t) = (f64::from(i) / 5.0, f64::from(j) / 4.0);
            let u = 0.5 + 0.45 * (std::f64::consts::PI * (s - 0.5)).sin();
            uv.push(format!("[{u}, {}]", t * (0.85 + 0.15 * s)));
        }
    }
    for interpolation in ["bilinear", "bicubic"] {
        let projection = format!(
            "{PERSPECTIVE}reparam = \"grid\"\nreparam_grid = {{ size = [6, 5], interpolation = \
             \"{interpolation}\", uv = [{}] }}\n",
            uv.join(", ")
        );
        agrees_away_from_edges(interpolation, &scene(&projection));
    }
}

#[test]
fn static_blends_and_extrapolations_rasterise_as_they_ray_cast() {
    // Perspective with pushbroom (fig. 4.5), interpolated and extrapolated both ways, the
    // pushbroom's width chosen so that no extrapolated cross-section turns over between the
    // clip planes (where one does, the projectors cross and raster refuses the volume).
    for (weight, width) in [(0.3, 4.0), (1.4, 1.5), (-0.3, 10.0)] {
        let projection = format!(
            "type = \"flexible\"\n[projection.interpolate]\nweight = {weight}\n\
             [projection.interpolate.first]\n{PERSPECTIVE}clip = [0.5, 10.0]\n\
             [projection.interpolate.second]\ntype = \"flexible\"\npreset = \"pushbroom\"\n\
             position = [0.0, 2.5, 5.0]\nlook_at = [0.0, 0.4, 0.0]\nwidth = {width}\n\
             v_fov = 60.0\nclip = [0.5, 10.0]\n"
        );
        agrees_away_from_edges(&format!("weight {weight}"), &scene(&projection));
    }
}
