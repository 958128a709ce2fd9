//! `flexcam pick`: the object and world point the ray caster sees at image positions of a
//! scene (`flexcam::render::pick`), for collecting a fit's correspondences from a render.

use clap::Args;
use flexcam::render::{pick, Picked, PreparedScene};
use flexcam::scene::Object;
use flexcam::{Error, Result};
use glam::DVec2;
use serde_json::json;

use flexcam::scene::{self, Overrides};

/// Arguments of `flexcam pick`.
#[derive(Args, Debug)]
pub struct PickArgs {
    /// A scene file (.toml) or `builtin:NAME`.
    scene: String,
    /// Image positions in pixels, x right and y down from the image's top-left corner
    /// (continuous: pixel (i, j) covers [i, i+1) x [j, j+1), its centre is i+0.5,j+0.5).
    #[arg(
        value_name = "PIXEL_X,PIXEL_Y",
        required = true,
        num_args = 1..,
        allow_negative_numbers = true
    )]
    at: Vec<String>,
    /// Image width in pixels (overrides the scene file).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene file).
    #[arg(long)]
    height: Option<u32>,
    /// Print one JSON object per position instead of text.
    #[arg(long)]
    json: bool,
    /// Print each position as a `fit` entry of a projector grid,
    /// `{ pixel = [x, y], point = [x, y, z] },  # object`, ready to paste into a `fit` list
    /// (positions that see nothing as a comment).
    #[arg(long, conflicts_with = "json")]
    fit: bool,
}

/// Runs `flexcam pick`: one line per position, the object's name and id and the world
/// point, or that nothing is seen there.
pub fn run(args: &PickArgs) -> Result<()> {
    let positions = args
        .at
        .iter()
        .map(|text| parse_position(text))
        .collect::<Result<Vec<_>>>()?;
    let overrides = Overrides {
        width: args.width,
        height: args.height,
        ..Overrides::default()
    };
    let loaded = scene::load_with(&args.scene, &overrides)?;
    let (width, height) = (f64::from(loaded.width), f64::from(loaded.height));
    if let Some(p) = positions
        .iter()
        .find(|p| !(0.0..=width).contains(&p.x) || !(0.0..=height).contains(&p.y))
    {
        return Err(Error::new(format!(
            "{}: position {},{} is outside the {}x{} image",
            loaded.source, p.x, p.y, loaded.width, loaded.height
        )));
    }
    let prepared = PreparedScene::new(&loaded.scene);
    let mut text = String::new();
    for pixel in positions {
        let picked = pick(&prepared, loaded.projection.as_ref(), pixel);
        let object = picked.map(|p| &loaded.scene.objects[p.object]);
        let line = match (args.json, picked, object) {
            _ if args.fit => fit_entry(pixel, picked.zip(object)),
            (true, Some(p), Some(o)) => json!({
                "pixel": [pixel.x, pixel.y],
                "object": o.name,
                "id": o.id,
                "point": [p.point.x, p.point.y, p.point.z],
            })
            .to_string(),
            (true, ..) => json!({ "pixel": [pixel.x, pixel.y], "object": null }).to_string(),
            (false, Some(p), Some(o)) => format!(
                "{},{}: {} (id {}) at [{}, {}, {}]",
                pixel.x, pixel.y, o.name, o.id, p.point.x, p.point.y, p.point.z
            ),
            (false, ..) => format!("{},{}: nothing", pixel.x, pixel.y),
        };
        text += &line;
        text.push('\n');
    }
    super::print_stdout(&text)
}

/// The `fit` entry of a pick at `pixel` (see `PickArgs::fit`): the object's name in a
/// comment, or a comment alone where nothing is seen.
fn fit_entry(pixel: DVec2, picked: Option<(Picked, &Object)>) -> String {
    match picked {
        Some((p, o)) => format!(
            "{{ pixel = [{:?}, {:?}], point = [{:?}, {:?}, {:?}] }},  # {}",
            pixel.x, pixel.y, p.point.x, p.point.y, p.point.z, o.name
        ),
        None => format!("# {},{}: nothing", pixel.x, pixel.y),
    }
}

/// `X,Y` as a pixel position (two finite numbers).
fn parse_position(text: &str) -> Result<DVec2> {
    let numbers: Vec<f64> = text
        .split(',')
        .map(|n| n.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| Error::new(format!("{text}: expected PIXEL_X,PIXEL_Y (two numbers)")))?;
    match numbers[..] {
        [x, y] if x.is_finite() && y.is_finite() => Ok(DVec2::new(x, y)),
        _ => Err(Error::new(format!(
            "{text}: expected PIXEL_X,PIXEL_Y (two finite numbers)"
        ))),
    }
}
