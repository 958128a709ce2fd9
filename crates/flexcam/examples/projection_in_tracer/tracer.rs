//! A minimal ray tracer of its own (spheres, one directional light, Lambert shading) that
//! takes its camera from flexcam: each pixel's projector comes from the public
//! [`Projection`] API, so any flexcam projection (a fisheye built in code, the projection of
//! a scene file, a curved flexible volume) drives it.

use std::path::Path;

use flexcam::geometry::Ray;
use flexcam::glam::{DVec2, DVec3, Vec3};
use flexcam::image_io::{write_color_png, ColorEncoding};
use flexcam::projection::{Projection, Projector};
use flexcam::render::Frame;

/// Straight pieces a quadratic Bezier projector is followed by.
const BEZIER_PIECES: usize = 32;

/// A sphere of the tracer's own scene.
#[derive(Debug, Clone, Copy)]
pub struct Sphere {
    /// Centre, world units.
    pub centre: DVec3,
    /// Radius, world units (positive).
    pub radius: f64,
    /// Linear RGB albedo.
    pub colour: Vec3,
}

/// Where a projector first meets a sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Index of the sphere in the scene's list.
    pub sphere: usize,
    /// The hit point.
    pub point: DVec3,
    /// The parameter of the hit on the (straight) ray or segment that reached it.
    pub t: f64,
}

/// The first hit of `ray` within its interval `[t_min, t_max]` among `spheres`: the
/// smaller root of |o + t d - c|^2 = r^2 that lies in the interval (the larger one when the
/// ray starts inside a sphere). `direction` need not be unit length; a zero direction hits
/// nothing.
pub fn intersect(ray: &Ray, spheres: &[Sphere]) -> Option<Hit> {
    let a = ray.direction.length_squared();
    if a == 0.0 {
        return None;
    }
    let mut best: Option<Hit> = None;
    for (index, sphere) in spheres.iter().enumerate() {
        let oc = ray.origin - sphere.centre;
        let half_b = oc.dot(ray.direction);
        let c = oc.length_squared() - sphere.radius * sphere.radius;
        let discriminant = half_b * half_b - a * c;
        if discriminant < 0.0 {
            continue;
        }
        let root = discriminant.sqrt();
        let nearest = [(-half_b - root) / a, (-half_b + root) / a]
            .into_iter()
            .find(|t| (ray.t_min..=ray.t_max).contains(t));
        if let Some(t) = nearest {
            if best.is_none_or(|b| t < b.t) {
                best = Some(Hit {
                    sphere: index,
                    point: ray.at(t),
                    t,
                });
            }
        }
    }
    best
}

/// The first hit along a projector: a straight one is one ray; a curved one is followed
/// segment by segment (a Bezier through [`BEZIER_PIECES`] chords), the first segment with a
/// hit deciding.
pub fn trace(projector: &Projector, spheres: &[Sphere]) -> Option<Hit> {
    let segments = |points: &[DVec3]| {
        points.windows(2).find_map(|pair| {
            let segment = Ray {
                t_max: 1.0,
                ..Ray::new(pair[0], pair[1] - pair[0])
            };
            intersect(&segment, spheres)
        })
    };
    match projector {
        Projector::Straight(ray) => intersect(ray, spheres),
        Projector::Polyline(points) => segments(points),
        Projector::QuadraticBezier([p0, p1, p2]) => {
            let points: Vec<DVec3> = (0..=BEZIER_PIECES)
                .map(|i| {
                    let s = i as f64 / BEZIER_PIECES as f64;
                    (1.0 - s) * (1.0 - s) * *p0 + 2.0 * s * (1.0 - s) * *p1 + s * s * *p2
                })
                .collect();
            segments(&points)
        }
    }
}

/// The first hit seen through each pixel centre (x + 0.5, y + 0.5) of `projection`, row by
/// row from the top; `None` where the pixel sees no sphere or the projection gives it no
/// projector.
pub fn hits(projection: &dyn Projection, spheres: &[Sphere]) -> Vec<Option<Hit>> {
    let (width, height) = projection.resolution();
    let mut hits = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            hits.push(
                projection
                    .projector(pixel)
                    .and_then(|projector| trace(&projector, spheres)),
            );
        }
    }
    hits
}

/// Shades `hits` (of a `width` x `height` image) as Lambert surfaces lit from `light` (a
/// unit direction towards the light) with a little ambient light; misses get `background`.
/// The result is a flexcam [`Frame`], so flexcam's image writers save it.
pub fn shade(
    hits: &[Option<Hit>],
    spheres: &[Sphere],
    (width, height): (u32, u32),
    light: DVec3,
    background: Vec3,
) -> Frame {
    let mut frame = Frame::new(width, height, background);
    for (pixel, hit) in frame.color.iter_mut().zip(hits) {
        if let Some(hit) = hit {
            let sphere = &spheres[hit.sphere];
            let normal = (hit.point - sphere.centre) / sphere.radius;
            let lambert = normal.dot(light).max(0.0) as f32;
            *pixel = sphere.colour * (0.15 + 0.85 * lambert);
        }
    }
    frame
}

/// The example's scene: three spheres on a huge ground sphere, around the origin.
pub fn demo_spheres() -> Vec<Sphere> {
    let sphere = |centre: [f64; 3], radius, colour: [f32; 3]| Sphere {
        centre: DVec3::from_array(centre),
        radius,
        colour: Vec3::from_array(colour),
    };
    vec![
        sphere([0.0, -1000.0, 0.0], 1000.0, [0.6, 0.6, 0.55]),
        sphere([0.0, 0.7, 0.0], 0.7, [0.8, 0.2, 0.15]),
        sphere([1.6, 0.5, 0.4], 0.5, [0.2, 0.6, 0.85]),
        sphere([-1.5, 0.6, -0.6], 0.6, [0.3, 0.75, 0.3]),
    ]
}

/// Traces [`demo_spheres`] through `projection`, lit from above, into the PNG `out`; returns
/// every pixel's hit (what [`hits`] gives).
pub fn render_png(projection: &dyn Projection, out: &Path) -> flexcam::Result<Vec<Option<Hit>>> {
    let spheres = demo_spheres();
    let hits = hits(projection, &spheres);
    let light = DVec3::new(0.4, 1.0, 0.6).normalize();
    let background = Vec3::new(0.55, 0.7, 0.9);
    let frame = shade(&hits, &spheres, projection.resolution(), light, background);
    write_color_png(&frame, out, ColorEncoding::Srgb)?;
    Ok(hits)
}
