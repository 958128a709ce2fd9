//! `flexcam project`: every image position of one scene point through a scene's projection,
//! by the projection's analytic inverse (for a trilinear mesh, every root of every projection
//! triangle's cubic, Vallance 2005, chapter 3).

use clap::Args;
use flexcam::projection::projector::quadratic_arc_length;
use flexcam::projection::{ImagePoint, Projector, SAME_IMAGE_PIXELS};
use flexcam::{Error, Result};
use glam::{DVec2, DVec3};
use serde_json::json;

use super::scene_args::SceneArgs;

/// Arguments of `flexcam project`.
#[derive(Args, Debug)]
pub struct ProjectArgs {
    /// The projection: the scene file's `[projection]` and `[image]` (objects are ignored).
    #[command(flatten)]
    scene: SceneArgs,
    /// The scene point, as three numbers separated by commas (a leading minus sign is
    /// part of the point, not an option).
    #[arg(value_name = "X,Y,Z", allow_hyphen_values = true)]
    point: String,
    /// Print one JSON object (`point`, `images`: each with `x`, `y`, `depth`, `t`, and for an
    /// image along a segment of pixels `x_end`, `y_end`) instead of one line per image.
    #[arg(long)]
    json: bool,
}

/// One image of the point: its continuous pixel position (x right, y down, pixel (x, y)
/// covering [x, x + 1) x [y, y + 1)), the distance along its pixel's ray (or polyline or
/// curved projector, by arc length) from its start (what `render --depth` writes there when
/// nothing is in front) and the ray parameter (a flexible volume's t); for an image along a
/// whole segment of pixels (a trilinear triangle whose rays form a fan), the segment's other
/// end, every position between seeing the point along the same ray.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Image {
    pixel: DVec2,
    depth: f64,
    t: f64,
    end: Option<DVec2>,
}

/// Runs `flexcam project`: loads the scene's projection, finds every image of the point
/// inside the image in front of the view plane (`t >= 0`), nearest first, and prints them.
/// A projection without an analytic inverse, or a point that is not three finite numbers,
/// is one error line.
pub fn run(args: &ProjectArgs) -> Result<()> {
    let coordinates: Vec<f64> = args
        .point
        .split(',')
        .map(|c| c.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .unwrap_or_default();
    let point = match coordinates[..] {
        [x, y, z] if [x, y, z].iter().all(|c| c.is_finite()) => DVec3::new(x, y, z),
        _ => {
            return Err(Error::new(format!(
                "the point must be three finite numbers X,Y,Z, got '{}'",
                args.point
            )))
        }
    };
    let loaded = args.scene.load()?;
    let projection = loaded.projection.as_ref();
    let inverse = projection.inverse().map_err(|e| {
        let reason = e.reason.map(|r| format!(": {r}")).unwrap_or_default();
        Error::new(format!(
            "{}: the {} projection has no analytic inverse{reason}",
            loaded.source,
            projection.kind()
        ))
    })?;
    let mut found = Vec::new();
    inverse.project(point, &mut found);
    let mut segments = Vec::new();
    inverse.project_segments(point, &mut segments);
    let size = DVec2::new(f64::from(loaded.width), f64::from(loaded.height));
    let depth_at = |pixel: DVec2, t: f64| match projection.projector(pixel) {
        Some(Projector::Polyline(points)) => arc_length_to(&points, point),
        // A quadratic volume's t is the curve parameter s of B(s) (the point is B(t)).
        Some(Projector::QuadraticBezier(curve)) => quadratic_arc_length(&curve, t),
        _ => {
            let speed = projection
                .ray(pixel)
                .map_or(1.0, |ray| ray.direction.length());
            t * speed
        }
    };
    // A fan triangle's neighbours see the point at its segment's ends: one image.
    let on_a_segment = |pixel: DVec2| {
        segments
            .iter()
            .flat_map(|s| s.ends)
            .any(|end| end.distance(pixel) <= SAME_IMAGE_PIXELS)
    };
    let points = found
        .iter()
        .filter(|image| image.t >= 0.0 && !on_a_segment(image.pixel))
        .filter(|image| {
            let p = image.pixel;
            p.x >= 0.0 && p.y >= 0.0 && p.x <= size.x && p.y <= size.y
        })
        .map(|&ImagePoint { pixel, t }| Image {
            pixel,
            depth: depth_at(pixel, t),
            t,
            end: None,
        });
    let lines = segments
        .iter()
        .filter(|segment| segment.t >= 0.0)
        .filter_map(|segment| {
            let [a, b] = clip_to_image(segment.ends, size)?;
            Some(Image {
                pixel: a,
                depth: depth_at(0.5 * (a + b), segment.t),
                t: segment.t,
                end: Some(b),
            })
        });
    let mut images: Vec<Image> = points.chain(lines).collect();
    images.sort_by(|a, b| a.depth.total_cmp(&b.depth));
    let text = if args.json {
        let images: Vec<_> = images
            .iter()
            .map(|i| {
                let mut image = json!({"x": i.pixel.x, "y": i.pixel.y, "depth": i.depth, "t": i.t});
                if let Some(end) = i.end {
                    image["x_end"] = json!(end.x);
                    image["y_end"] = json!(end.y);
                }
                image
            })
            .collect();
        let object = json!({
            "scene": loaded.source,
            "projection": projection.kind(),
            "point": [point.x, point.y, point.z],
            "images": images,
        });
        format!("{object}\n")
    } else {
        images
            .iter()
            .map(|i| match i.end {
                None => format!("{} {} {}\n", i.pixel.x, i.pixel.y, i.depth),
                Some(end) => format!(
                    "{} {} {} {} {}\n",
                    i.pixel.x, i.pixel.y, i.depth, end.x, end.y
                ),
            })
            .collect()
    };
    super::print_stdout(&text)
}

/// The part of the segment `ends` inside the image `[0, size.x] x [0, size.y]` (Liang and
/// Barsky's clip), `None` where none is.
fn clip_to_image(ends: [DVec2; 2], size: DVec2) -> Option<[DVec2; 2]> {
    let [a, b] = ends;
    let d = b - a;
    let (mut enter, mut leave) = (0.0_f64, 1.0_f64);
    // Each side as p s <= q for the segment's parameter s in [0, 1].
    for (p, q) in [
        (-d.x, a.x),
        (d.x, size.x - a.x),
        (-d.y, a.y),
        (d.y, size.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else if p < 0.0 {
            enter = enter.max(q / p);
        } else {
            leave = leave.min(q / p);
        }
    }
    (enter <= leave).then(|| [a + enter * d, a + leave * d])
}

/// The arc length along polyline projector `points` from its start to `point`, which lies on
/// it: the lengths of the segments before the one nearest `point`, plus the distance along
/// that one (the depth the ray caster gives a hit there).
fn arc_length_to(points: &[DVec3], point: DVec3) -> f64 {
    let nearest = |a: DVec3, b: DVec3| {
        let d = b - a;
        let s = if d == DVec3::ZERO {
            0.0
        } else {
            ((point - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        };
        (a + s * d).distance(point)
    };
    let k = (0..points.len() - 1)
        .min_by(|&i, &j| {
            nearest(points[i], points[i + 1]).total_cmp(&nearest(points[j], points[j + 1]))
        })
        .unwrap_or(0);
    let before: f64 = points[..=k].windows(2).map(|w| w[0].distance(w[1])).sum();
    before + points[k].distance(point)
}
