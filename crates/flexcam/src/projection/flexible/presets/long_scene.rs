//! The long-scene projection (Agarwala et al. 2006; Brosz 2011, 6.2.1, figures 6.8 to 6.11):
//! a pushbroom along a street whose far surface has a non-uniform parameterisation across
//! its width, so that deep areas (the streets that cross it) are seen with perspective
//! foreshortening in both directions while the facades stay a pushbroom image.
//!
//! In the camera's local coordinates (x along the slit, y up, z the view direction) the
//! near surface is the pushbroom's, uniform: x_n(u) = (u - 1/2) W at depth n. The far
//! surface at depth f is the pushbroom's rectangle with x re-parameterised by a
//! piecewise-linear map x_f(u) (figure 6.10): x_f = x_n at the image's ends, and a deep area
//! centred at image position c, w image widths wide, seen with horizontal angle phi, has
//!
//! ```text
//! x_f(c -+ w/2) = x_n(c) -+ (w W / 2 + (f - n) tan(phi / 2)),
//! ```
//!
//! linear in between: its projectors all pass through one point, the virtual eye
//! (x_n(c), n - e) with e = w W / (2 tan(phi / 2)) behind the near surface, and its edge
//! projectors are phi apart: a perspective view across, the pushbroom's slit up and down.
//! Between deep areas x_f is linear again, so the projectors there are drawn together (the
//! shallow facades take the compression). Vertically every projector is the pushbroom's.
//!
//! Degenerate cases, refused: more than [`MAX_DEEP`] areas; an area not strictly inside the
//! image or of zero width; two areas touching or overlapping; an angle outside (0, 180)
//! degrees; areas whose fans reach past their neighbours' on the far surface (x_f would
//! decrease: projectors would cross in front of the far surface).

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};

/// The most deep areas a long scene may have.
pub const MAX_DEEP: usize = 32;

/// One deep area of a long scene, in image fractions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeepArea {
    /// The image position u of its middle.
    pub center: f64,
    /// Its width, a fraction of the image width.
    pub width: f64,
    /// The horizontal angle it is seen with, degrees.
    pub fov: f64,
}

/// A rectangle whose u is re-parameterised by a piecewise-linear map: the point at (u, v)
/// is `corner + x(u) along + v v_edge`, x(u) interpolating `knots` (u, x) (extrapolating
/// the end pieces outside them).
#[derive(Debug, Clone, PartialEq)]
pub struct WarpedRectangle {
    /// The point at x = 0, v = 0.
    pub corner: DVec3,
    /// The unit direction x is measured along.
    pub along: DVec3,
    /// The step from v = 0 to v = 1.
    pub v_edge: DVec3,
    /// (u, x), both strictly increasing, u from 0 to 1.
    pub knots: Vec<DVec2>,
}

impl WarpedRectangle {
    /// The surface point at (u, v).
    pub fn point(&self, uv: DVec2) -> DVec3 {
        let k = &self.knots;
        let i = k
            .partition_point(|knot| knot.x <= uv.x)
            .clamp(1, k.len() - 1);
        let (a, b) = (k[i - 1], k[i]);
        let x = a.y + (uv.x - a.x) / (b.x - a.x) * (b.y - a.y);
        self.corner + x * self.along + uv.y * self.v_edge
    }

    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        self.corner.is_finite()
            && self.along.is_finite()
            && self.v_edge.is_finite()
            && self.knots.iter().all(|k| k.is_finite())
    }
}

/// The far surface's knots (u, x_f(u)) for a slit of length `width` from depth `near` to
/// `far` (see the module doc). Errors: the degenerate cases of the module doc, naming the
/// areas by their number in `deep` (from 1).
pub fn far_knots(width: f64, near: f64, far: f64, deep: &[DeepArea]) -> Result<Vec<DVec2>> {
    if deep.len() > MAX_DEEP {
        return Err(Error::new(format!(
            "flexible long_scene takes at most {MAX_DEEP} `deep` areas, got {}",
            deep.len()
        )));
    }
    let x_near = |u: f64| (u - 0.5) * width;
    for (i, area) in deep.iter().enumerate() {
        let (lo, hi) = (
            area.center - 0.5 * area.width,
            area.center + 0.5 * area.width,
        );
        if !(area.center.is_finite() && area.width.is_finite() && area.width > 0.0) {
            return Err(Error::new(format!(
                "flexible long_scene deep area {} needs a finite centre and a width above 0, \
                 got [{}, {}, {}]",
                i + 1,
                area.center,
                area.width,
                area.fov
            )));
        }
        if !(0.0 < lo && hi < 1.0) {
            return Err(Error::new(format!(
                "flexible long_scene deep area {} must lie strictly inside the image: it spans \
                 u = {lo} to {hi}",
                i + 1
            )));
        }
        if !(area.fov.is_finite() && 0.0 < area.fov && area.fov < 180.0) {
            return Err(Error::new(format!(
                "flexible long_scene deep area {} fov must be in (0, 180) degrees, got {}",
                i + 1,
                area.fov
            )));
        }
    }
    let mut order: Vec<usize> = (0..deep.len()).collect();
    order.sort_by(|&a, &b| deep[a].center.total_cmp(&deep[b].center));
    for pair in order.windows(2) {
        let (a, b) = (&deep[pair[0]], &deep[pair[1]]);
        if a.center + 0.5 * a.width >= b.center - 0.5 * b.width {
            return Err(Error::new(format!(
                "flexible long_scene deep areas {} and {} touch or overlap: leave a gap of \
                 facade between them",
                pair[0] + 1,
                pair[1] + 1
            )));
        }
    }
    let mut knots = vec![DVec2::new(0.0, x_near(0.0))];
    let mut owner = vec![None];
    for &i in &order {
        let area = &deep[i];
        let spread = 0.5 * area.width * width + (far - near) * (0.5 * area.fov.to_radians()).tan();
        let middle = x_near(area.center);
        knots.push(DVec2::new(area.center - 0.5 * area.width, middle - spread));
        knots.push(DVec2::new(area.center + 0.5 * area.width, middle + spread));
        owner.extend([Some(i), Some(i)]);
    }
    knots.push(DVec2::new(1.0, x_near(1.0)));
    owner.push(None);
    if let Some(k) = (1..knots.len()).find(|&k| knots[k].y <= knots[k - 1].y) {
        let name = |o: Option<usize>| {
            o.map_or("the image's end".to_string(), |i| {
                format!("deep area {}", i + 1)
            })
        };
        return Err(Error::new(format!(
            "flexible long_scene: {} and {} fold the far surface (their fans cross before \
             the far clip at {far}): narrow the fov, the far clip or the area",
            name(owner[k - 1]),
            name(owner[k])
        )));
    }
    Ok(knots)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::flexible::{Flexible, FlexibleSpec, Preset, PresetSpec, VolumeSource};
    use crate::projection::{CameraFrame, Projection};

    /// The long scene of the example's numbers (a 60 m slit at z = 8 looking along -z, far
    /// clip 24) with `deep`, 720 x 180.
    fn street(deep: Vec<DeepArea>, preset: Option<Preset>) -> Flexible {
        let spec = FlexibleSpec {
            source: VolumeSource::Preset(PresetSpec {
                preset: preset.unwrap_or(Preset::LongScene {
                    width: 60.0,
                    v_fov: 60.0,
                    deep,
                }),
                frame: CameraFrame {
                    position: DVec3::new(0.0, 1.6, 8.0),
                    look_at: DVec3::new(0.0, 1.6, 0.0),
                    up: DVec3::Y,
                },
                clip: Some([0.0, 24.0]),
            }),
            reparam: None,
        };
        Flexible::new(&spec, 720, 180).unwrap()
    }

    #[test]
    fn without_deep_areas_it_is_the_pushbroom() {
        let long = street(Vec::new(), None);
        let pushbroom = street(
            Vec::new(),
            Some(Preset::Pushbroom {
                width: 60.0,
                v_fov: 60.0,
            }),
        );
        for pixel in [
            DVec2::new(0.5, 0.5),
            DVec2::new(300.25, 90.0),
            DVec2::new(719.5, 179.5),
        ] {
            let (a, b) = (long.ray(pixel).unwrap(), pushbroom.ray(pixel).unwrap());
            assert!((a.origin - b.origin).length() < 1e-12, "{pixel}");
            assert!((a.direction - b.direction).length() < 1e-12, "{pixel}");
        }
    }

    /// Inside a deep area every projector passes, seen from above, through the virtual eye
    /// e = w W / (2 tan(phi / 2)) behind the slit, and the area's edge projectors are phi
    /// apart; vertically they are the pushbroom's (through the slit).
    #[test]
    fn a_deep_area_is_a_perspective_across() {
        let area = DeepArea {
            center: 1.0 / 3.0,
            width: 1.0 / 15.0,
            fov: 30.0,
        };
        let long = street(vec![area], None);
        let e = 4.0 / (2.0 * 15f64.to_radians().tan());
        let eye = DVec2::new(-10.0, 8.0 + e); // (x, z): behind the slit, which looks along -z
        let columns = (240.0 - 24.0, 240.0 + 24.0);
        for x in [columns.0, 230.5, 240.0, 251.25, columns.1] {
            for y in [10.5, 90.0, 170.5] {
                let ray = long.ray(DVec2::new(x, y)).unwrap();
                let (o, d) = (
                    DVec2::new(ray.origin.x, ray.origin.z),
                    DVec2::new(ray.direction.x, ray.direction.z),
                );
                let to_eye = eye - o;
                assert!(
                    d.perp_dot(to_eye).abs() < 1e-9 * d.length() * to_eye.length(),
                    "{x} {y}"
                );
                // Up and down through the slit: the origin is on it.
                assert!((ray.origin.y - 1.6).abs() < 1e-12 && (ray.origin.z - 8.0).abs() < 1e-12);
            }
        }
        let side = |x: f64| {
            let d = long.ray(DVec2::new(x, 90.0)).unwrap().direction;
            d.x.atan2(-d.z)
        };
        let angle = (side(columns.1) - side(columns.0)).to_degrees();
        assert!((angle - 30.0).abs() < 1e-9, "{angle}");
        // Between the areas the projectors are drawn together: narrower than the slit.
        let spread = long.ray(DVec2::new(600.0, 90.0)).unwrap().direction.x
            - long.ray(DVec2::new(400.0, 90.0)).unwrap().direction.x;
        assert!(spread < 0.0, "{spread}");
    }

    /// Two deep areas 0.08 image widths wide at u = 0.3 and 0.7, seen at 30 degrees.
    fn two_streets() -> Flexible {
        let area = |center| DeepArea {
            center,
            width: 0.08,
            fov: 30.0,
        };
        street(vec![area(0.3), area(0.7)], None)
    }

    proptest::proptest! {
        /// The inverse of the long scene (a parallel-planes inverse per piece of the far
        /// surface) returns every point Q(u, v, t) of the volume to its pixel and t, in the
        /// deep areas, on their edges (the knots) and between them.
        #[test]
        fn the_inverse_returns_each_volume_point_to_its_pixel(
            x in 0.0f64..720.0,
            y in 0.0f64..180.0,
            t in 0.001f64..1.0,
            knot in proptest::bool::ANY,
        ) {
            let long = two_streets();
            // Half the cases exactly on a knot column (an area's edge, 0.3 - 0.04 of 720).
            let x = if knot { 187.2 } else { x };
            let pixel = DVec2::new(x, y);
            let point = long.point(pixel, t).unwrap();
            let inverse = long.inverse().unwrap();
            let mut images = Vec::new();
            inverse.project(point, &mut images);
            proptest::prop_assert_eq!(images.len(), 1);
            let image = images[0];
            proptest::prop_assert!((image.pixel - pixel).length() < 1e-6, "{} {}", image.pixel, pixel);
            proptest::prop_assert!((image.t - t).abs() < 1e-9, "{} {}", image.t, t);
        }
    }

    /// Raster has a continuous chart for the long scene: the pieces agree on their clip
    /// planes and orientation.
    #[test]
    fn the_long_scene_has_a_chart() {
        let long = two_streets();
        let charted = long.inverse().unwrap().charted();
        assert!(charted.is_some());
    }

    #[test]
    fn without_deep_areas_the_far_surface_is_the_pushbroom_s() {
        let knots = far_knots(10.0, 0.0, 30.0, &[]).unwrap();
        assert_eq!(knots, vec![DVec2::new(0.0, -5.0), DVec2::new(1.0, 5.0)]);
    }

    #[test]
    fn a_deep_area_fans_out_by_its_angle() {
        let area = DeepArea {
            center: 0.4,
            width: 0.1,
            fov: 90.0,
        };
        let knots = far_knots(100.0, 1.0, 21.0, &[area]).unwrap();
        // x_n(0.4) = -10, half the area 5 m, plus 20 m tan 45.
        assert_eq!(knots.len(), 4);
        assert!((knots[1] - DVec2::new(0.35, -10.0 - 25.0)).length() < 1e-12);
        assert!((knots[2] - DVec2::new(0.45, -10.0 + 25.0)).length() < 1e-12);
    }

    #[test]
    fn bad_areas_are_refused() {
        let area = |center, width, fov| DeepArea { center, width, fov };
        let cases = [
            (vec![area(0.05, 0.1, 60.0)], "strictly inside the image"),
            (vec![area(0.5, 0.0, 60.0)], "width above 0"),
            (vec![area(0.5, 0.1, 180.0)], "fov must be in (0, 180)"),
            (
                vec![area(0.5, 0.1, 60.0), area(0.3, 0.4, 60.0)],
                "deep areas 2 and 1 touch or overlap",
            ),
            (
                vec![area(0.3, 0.05, 60.0), area(0.5, 0.05, 60.0)],
                "deep area 1 and deep area 2 fold the far surface",
            ),
            (
                vec![area(0.1, 0.05, 60.0)],
                "the image's end and deep area 1 fold",
            ),
            (vec![area(0.5, 0.01, 1.0); 33], "at most 32"),
        ];
        for (deep, expected) in cases {
            let e = far_knots(100.0, 0.0, 30.0, &deep).unwrap_err().message;
            assert!(e.contains(expected), "{e} (expected {expected})");
        }
    }

    #[test]
    fn the_warped_rectangle_follows_its_knots() {
        let r = WarpedRectangle {
            corner: DVec3::new(0.0, -1.0, -5.0),
            along: DVec3::X,
            v_edge: DVec3::Y * 2.0,
            knots: vec![
                DVec2::new(0.0, -4.0),
                DVec2::new(0.5, 0.0),
                DVec2::new(1.0, 8.0),
            ],
        };
        assert!((r.point(DVec2::new(0.25, 0.5)) - DVec3::new(-2.0, 0.0, -5.0)).length() < 1e-12);
        assert!((r.point(DVec2::new(0.75, 0.0)) - DVec3::new(4.0, -1.0, -5.0)).length() < 1e-12);
        assert!((r.point(DVec2::new(1.0, 1.0)) - DVec3::new(8.0, 1.0, -5.0)).length() < 1e-12);
    }
}
