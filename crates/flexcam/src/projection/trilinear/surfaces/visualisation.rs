//! The visualisation surfaces of seed 000, chapter 6: detail in context (6.1), multiple
//! perspectives joined by a transition band (6.2) and the inward-looking sphere (6.3).

use glam::{DVec2, DVec3};

use super::camera::GridCamera;
use super::grid::GridVertex;
use crate::error::{Error, Result};
use crate::projection::flexible::{PolarFrame, SpherePatch, Surface};

/// A distortion-oriented display (6.1): a camera whose view is magnified by `magnification`
/// inside a circle of screen radius `inner` around `focus` (the inset), unchanged beyond
/// radius `outer` (the context), and compressed in the ring between so that the image is
/// continuous everywhere (the surround).
///
/// Screen position `s` at distance `r` from the focus is shown as the camera's view at
/// `focus + (s - focus) rho(r) / r`, with `rho(r) = r / m` inside, `r` outside and linear in
/// between. Radii are in screen units (the width and height of the image are both 1).
/// Degenerate cases, all errors: `magnification` not finite or not positive; `inner` not
/// positive; `outer <= inner`; and `inner / magnification >= outer` (a magnification below 1
/// so strong that the ring would fold back over the inset).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetailInContext {
    camera: GridCamera,
    focus: DVec2,
    inner: f64,
    outer: f64,
    magnification: f64,
}

impl DetailInContext {
    pub fn new(
        camera: GridCamera,
        focus: DVec2,
        [inner, outer]: [f64; 2],
        magnification: f64,
    ) -> Result<Self> {
        if !magnification.is_finite() || magnification <= 0.0 {
            return Err(Error::new(format!(
                "detail_in_context magnification must be positive, got {magnification}"
            )));
        }
        if !(focus.is_finite() && inner > 0.0 && outer > inner && outer.is_finite()) {
            return Err(Error::new(format!(
                "detail_in_context inset must be [inner, outer] with 0 < inner < outer, \
                 got [{inner}, {outer}]"
            )));
        }
        if inner / magnification >= outer {
            return Err(Error::new(format!(
                "detail_in_context magnification {magnification} is too small for the inset \
                 [{inner}, {outer}]: the ring would fold back over the inset"
            )));
        }
        Ok(DetailInContext {
            camera,
            focus,
            inner,
            outer,
            magnification,
        })
    }

    /// The screen position of the camera's view shown at `screen`.
    pub fn source(&self, screen: DVec2) -> DVec2 {
        let offset = screen - self.focus;
        let r = offset.length();
        if r <= self.inner {
            return self.focus + offset / self.magnification;
        }
        if r >= self.outer {
            return screen;
        }
        let start = self.inner / self.magnification;
        let rho = start + (r - self.inner) * (self.outer - start) / (self.outer - self.inner);
        self.focus + offset * (rho / r)
    }

    /// The base point and ray at `screen`.
    pub fn vertex(&self, screen: DVec2) -> GridVertex {
        self.camera.vertex(self.source(screen))
    }
}

/// Two views joined by a transition band (6.2): below screen height `band[0]` the image is
/// `first`'s view, above `band[1]` it is `second`'s, and across the band base points and unit
/// ray directions are blended with a smoothstep weight, so the rays change continuously from
/// one view to the other (each view maps the whole screen; the band picks which part of each
/// is shown). Degenerate cases: a band outside [0, 1] or with `band[0] >= band[1]` is an
/// error; where the blend of opposite directions vanishes the grid has no ray there and
/// [`super::screen_grid`] reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoViews {
    first: GridCamera,
    second: GridCamera,
    band: [f64; 2],
}

impl TwoViews {
    pub fn new(first: GridCamera, second: GridCamera, band: [f64; 2]) -> Result<Self> {
        let [low, high] = band;
        if !(0.0 <= low && low < high && high <= 1.0) {
            return Err(Error::new(format!(
                "two_views band must be [low, high] with 0 <= low < high <= 1, got {band:?}"
            )));
        }
        Ok(TwoViews {
            first,
            second,
            band,
        })
    }

    /// The weight of the second view at screen height `y`: 0 below the band, 1 above it,
    /// smoothstep between.
    pub fn weight(&self, y: f64) -> f64 {
        let x = ((y - self.band[0]) / (self.band[1] - self.band[0])).clamp(0.0, 1.0);
        x * x * (3.0 - 2.0 * x)
    }

    /// The base point and ray at `screen`.
    pub fn vertex(&self, screen: DVec2) -> GridVertex {
        let (a, b) = (self.first.vertex(screen), self.second.vertex(screen));
        let w = self.weight(screen.y);
        GridVertex {
            point: a.point.lerp(b.point, w),
            direction: a.direction.normalize().lerp(b.direction.normalize(), w),
        }
    }
}

/// The mapping surface of 6.3: a sphere patch of `radius` around `center` whose rays point
/// inwards to the centre, so that the image is a map of what lies inside the sphere (u to
/// longitude, v to latitude, in radians, as [`SpherePatch`]). Pass the result to
/// [`super::screen_grid`] with [`super::between_surfaces`].
///
/// Degenerate cases: at latitude +-90 degrees a whole row of grid vertices collapses to one
/// point with parallel rays (the zigzag the thesis shows at the poles; the projection
/// triangles there are degenerate in the scene but not on screen, so they still render);
/// radius 0 gives zero directions, which the grid rejects.
pub fn inward_sphere(
    center: DVec3,
    radius: f64,
    frame: PolarFrame,
    longitude: [f64; 2],
    latitude: [f64; 2],
) -> (Surface, Surface) {
    let near = Surface::Sphere(SpherePatch {
        center,
        radius,
        frame,
        longitude,
        latitude,
    });
    (near, Surface::Point(center))
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::projection::trilinear::surfaces::{between_surfaces, screen_grid};
    use crate::projection::{CameraFrame, Projection, Trilinear};

    fn camera() -> GridCamera {
        let frame = CameraFrame {
            position: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        };
        GridCamera::perspective(&frame, 60.0, 60.0).unwrap()
    }

    #[test]
    fn detail_in_context_magnifies_inside_and_keeps_the_context() {
        let focus = DVec2::new(0.4, 0.5);
        let view = DetailInContext::new(camera(), focus, [0.1, 0.3], 3.0).unwrap();
        // Inside: distances from the focus shrink by 3 (the view is magnified 3x).
        let s = focus + DVec2::new(0.06, -0.03);
        assert!((view.source(s) - (focus + DVec2::new(0.02, -0.01))).length() < 1e-15);
        assert_eq!(view.source(focus), focus);
        // Outside the ring: unchanged; continuous at both radii.
        let far = DVec2::new(0.95, 0.1);
        assert_eq!(view.source(far), far);
        for r in [0.1, 0.3] {
            let dir = DVec2::new(0.6, 0.8);
            let (a, b) = (focus + dir * (r - 1e-9), focus + dir * (r + 1e-9));
            assert!((view.source(a) - view.source(b)).length() < 1e-8, "r {r}");
        }
        // Monotone along a radius: no fold.
        let mut last = 0.0;
        for k in 1..100 {
            let s = focus + DVec2::new(0.004 * f64::from(k), 0.0);
            let r = (view.source(s) - focus).length();
            assert!(r > last);
            last = r;
        }
    }

    #[test]
    fn detail_in_context_degenerate_parameters_are_errors() {
        let c = camera();
        let f = DVec2::splat(0.5);
        assert!(DetailInContext::new(c, f, [0.1, 0.3], 0.0).is_err());
        assert!(DetailInContext::new(c, f, [0.1, 0.3], f64::NAN).is_err());
        assert!(DetailInContext::new(c, f, [0.3, 0.3], 2.0).is_err());
        assert!(DetailInContext::new(c, f, [0.0, 0.3], 2.0).is_err());
        let e = DetailInContext::new(c, f, [0.2, 0.3], 0.5).unwrap_err();
        assert!(e.message.contains("fold"), "{e}");
        assert!(
            DetailInContext::new(c, f, [0.2, 0.5], 0.5).is_ok(),
            "a mild minifier"
        );
    }

    #[test]
    fn two_views_switch_across_the_band() {
        let frame = CameraFrame {
            position: DVec3::new(0.0, 8.0, 0.0),
            look_at: DVec3::ZERO,
            up: DVec3::NEG_Z,
        };
        let top = GridCamera::orthographic(&frame, 8.0, 8.0).unwrap();
        let views = TwoViews::new(camera(), top, [0.4, 0.6]).unwrap();
        let low = DVec2::new(0.3, 0.2);
        assert_eq!(views.vertex(low).point, camera().vertex(low).point);
        let high = DVec2::new(0.3, 0.8);
        assert_eq!(views.vertex(high).point, top.vertex(high).point);
        assert_eq!(views.weight(0.5), 0.5);
        // Continuous: steps of a tenth of a pixel change the ray a little everywhere (the
        // two views differ by about 1.4 in direction and 8 in base point, so a jump at the
        // band would show; the smoothstep's steepest slope gives at most ~0.03 and ~0.15).
        let mesh = screen_grid(20, |s| views.vertex(s)).unwrap();
        let trilinear = Trilinear::new(&mesh, 40, 40).unwrap();
        let mut previous = trilinear.ray(DVec2::new(10.5, 0.05)).unwrap();
        for step in 1..400 {
            let ray = trilinear
                .ray(DVec2::new(10.5, 0.05 + 0.1 * f64::from(step)))
                .unwrap();
            assert!(
                (ray.direction - previous.direction).length() < 0.05,
                "step {step}"
            );
            assert!((ray.origin - previous.origin).length() < 0.3, "step {step}");
            previous = ray;
        }
        assert!(TwoViews::new(camera(), top, [0.6, 0.4]).is_err());
        assert!(TwoViews::new(camera(), top, [-0.1, 0.4]).is_err());
    }

    #[test]
    fn inward_sphere_rays_meet_at_the_centre() {
        let center = DVec3::new(0.0, 1.0, 0.0);
        let frame = PolarFrame::new(DVec3::Y, DVec3::NEG_Z).unwrap();
        let (near, far) = inward_sphere(center, 6.0, frame, [-PI, PI], [-0.5 * PI, 0.5 * PI]);
        let mesh = screen_grid(8, between_surfaces(&near, &far)).unwrap();
        for (p, n) in mesh.points.iter().zip(&mesh.normals) {
            assert!(((*p - center).length() - 6.0).abs() < 1e-12);
            assert!(
                (*p + *n - center).length() < 1e-12,
                "each ray reaches the centre at t = 1"
            );
        }
        // The poles: the bottom row collapses to one point.
        assert!((mesh.points[0] - mesh.points[8]).length() < 1e-12);
        assert!(Trilinear::new(&mesh, 32, 16).is_ok());
        let (near, far) = inward_sphere(center, 0.0, frame, [-PI, PI], [-1.0, 1.0]);
        assert!(screen_grid(2, between_surfaces(&near, &far)).is_err());
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            /// The detail-in-context map is invertible: it keeps the direction from the
            /// focus and is strictly increasing in the distance, so no two screen positions
            /// show the same view (no fold) for any valid inset.
            #[test]
            fn detail_in_context_is_radially_monotone(
                inner in 0.01..0.4f64,
                width in 0.01..0.4f64,
                magnification in 0.3..8.0f64,
                angle in 0.0..6.3f64,
                (r1, r2) in (0.0..0.9f64, 0.0..0.9f64),
            ) {
                let focus = DVec2::new(0.45, 0.55);
                let outer = inner + width;
                prop_assume!(inner / magnification < outer);
                let view = DetailInContext::new(camera(), focus, [inner, outer], magnification).unwrap();
                let dir = DVec2::from_angle(angle);
                let (a, b) = (view.source(focus + r1 * dir) - focus, view.source(focus + r2 * dir) - focus);
                prop_assert!(a.perp_dot(dir).abs() <= 1e-12 && b.perp_dot(dir).abs() <= 1e-12);
                prop_assert!(a.dot(dir) >= 0.0 && b.dot(dir) >= 0.0);
                if r1 < r2 {
                    prop_assert!(a.length() < b.length(), "{r1} {r2}: {a} {b}");
                }
            }
        }
    }
}
