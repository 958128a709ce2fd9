//! The visualisation surfaces of Vallance 2005, chapter 6: detail in context (6.1), multiple
//! perspectives joined by a transition band (6.2) and the inward-looking sphere (6.3).

use glam::{DVec2, DVec3};

use super::camera::GridCamera;
use super::grid::GridVertex;
use crate::error::{Error, Result};
use crate::projection::flexible::{PolarFrame, SpherePatch, Surface};

/// The distortion-oriented display of 6.1: "a projection surface whose outer rays tend
/// toward a perspective projection but whose inner rays tend toward an orthographic" one.
///
/// All base points lie on the plane at distance `d` in front of the eye of a pinhole
/// `camera`, at the camera's own ray through each screen position: with `dir(s)` the
/// camera's direction at screen `s` (unit forward component),
///
/// ```text
/// ray(s, t) = eye + d dir(s) + t (dir(f) + w(r) (dir(s) - dir(f))),   r = |s - f|,
/// ```
///
/// where `f` is the focus and `w` rises from 0 to 1 across the transition band `inner <= r
/// <= outer` (a smoothstep, so the rays change continuously with a continuous slope):
/// - **focus** (`r <= inner`): parallel rays along the camera's ray through the focus, an
///   orthographic view of the base plane's patch. At forward distance `z` from the eye it
///   shows objects `z / d` times larger than the perspective view does;
///   `d = distance / magnification`, so at `distance` (the camera's look-at distance when
///   built from a scene file) the focus magnifies exactly `magnification` times;
/// - **context** (`r >= outer`): `eye + (d + t) dir(s)`, the camera's perspective rays, so
///   the context is the unchanged perspective view (the checker "the same size at its
///   edges" of Figure 6.4), seen from the base plane on;
/// - **band**: between them. At forward distance `d + t` a screen offset from the focus is
///   shown `(d + t w(r))` times its perspective offset at distance 1; that grows with `r`
///   for every `t >= 0`, so the image never folds.
///
/// Radii are in screen units (the width and height of the image are both 1). Nothing
/// nearer than the base plane (forward distance `d`) is seen, in the context too.
///
/// With [`FocusView::InversePerspective`] (6.1's other focus, set by
/// [`DetailInContext::with_focus_view`]) the focus rays are not parallel but converge on a
/// point `c` beyond the base plane: `dir(f)` above becomes `g(s) = (c - b(s)) / ((c - b(s)) .
/// forward)` with `b(s)` the base point (forward component 1, as the camera's directions), so
/// every focus ray passes through `c`, and an object between the base plane and `c` is seen
/// from around it: faces turned away from the camera's axis come into view, the far side
/// larger than the near. Beyond `c` the focus rays have crossed (the focus image of what lies
/// there is turned half round); the band blends `g(s)` into the perspective directions as
/// before, and may fold there too.
///
/// Degenerate cases, all errors: an orthographic camera (there is no perspective context);
/// `magnification` or `distance` not finite or not positive; `inner` not positive or
/// `outer <= inner`; a focus that is not finite; a convergence point that is not finite or
/// not beyond the base plane (forward distance from the eye at most `d`: the focus rays
/// would diverge or start at it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetailInContext {
    camera: GridCamera,
    eye: DVec3,
    forward: DVec3,
    focus: DVec2,
    inner: f64,
    outer: f64,
    /// Forward distance of the base plane from the eye.
    base: f64,
    focus_view: FocusView,
}

/// The rays inside a detail-in-context focus.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum FocusView {
    /// Parallel rays along the camera's ray through the focus: an orthographic view. The
    /// default.
    #[default]
    Orthographic,
    /// Rays converging on the world point `converge`: an inverse perspective view.
    InversePerspective {
        /// The point every focus ray passes through.
        converge: DVec3,
    },
}

impl DetailInContext {
    /// The detail-in-context view of pinhole `camera`: the focus at screen position `focus`,
    /// magnified `magnification` times within radius `inner`, the band out to `outer`, the base
    /// plane at forward distance `distance`. Errors: the degenerate cases above.
    pub fn new(
        camera: GridCamera,
        focus: DVec2,
        [inner, outer]: [f64; 2],
        magnification: f64,
        distance: f64,
    ) -> Result<Self> {
        let GridCamera::Perspective { basis, .. } = camera else {
            return Err(Error::new(
                "detail_in_context needs a pinhole camera (h_fov and v_fov): its context is \
                 the camera's perspective view",
            ));
        };
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
        if !distance.is_finite() || distance <= 0.0 {
            return Err(Error::new(format!(
                "detail_in_context reference distance must be positive, got {distance}"
            )));
        }
        Ok(DetailInContext {
            camera,
            eye: basis.origin,
            forward: basis.forward,
            focus,
            inner,
            outer,
            base: distance / magnification,
            focus_view: FocusView::Orthographic,
        })
    }

    /// The same view with the focus rays of `focus_view`. Errors: a convergence point that
    /// is not finite or not beyond the base plane.
    pub fn with_focus_view(self, focus_view: FocusView) -> Result<Self> {
        if let FocusView::InversePerspective { converge } = focus_view {
            let depth = (converge - self.eye).dot(self.forward);
            if !converge.is_finite() || depth <= self.base {
                return Err(Error::new(format!(
                    "detail_in_context converge must lie beyond the base plane (forward \
                     distance {} from the eye, the look-at distance over the \
                     magnification), got {converge} at forward distance {depth}",
                    self.base
                )));
            }
        }
        Ok(DetailInContext { focus_view, ..self })
    }

    /// The weight of the perspective direction at screen distance `r` from the focus: 0 in
    /// the focus, 1 in the context, smoothstep across the band.
    pub fn weight(&self, r: f64) -> f64 {
        let x = ((r - self.inner) / (self.outer - self.inner)).clamp(0.0, 1.0);
        x * x * (3.0 - 2.0 * x)
    }

    /// Forward distance of the base plane from the eye.
    pub fn base_distance(&self) -> f64 {
        self.base
    }

    /// The base point and ray at `screen` (the formula of the type's doc).
    pub fn vertex(&self, screen: DVec2) -> GridVertex {
        let here = self.camera.vertex(screen).direction;
        let point = self.eye + self.base * here;
        let inner = match self.focus_view {
            FocusView::Orthographic => self.camera.vertex(self.focus).direction,
            FocusView::InversePerspective { converge } => {
                // Forward component 1 like `here`; positive, as `converge` lies beyond the
                // base plane.
                let to = converge - point;
                to / to.dot(self.forward)
            }
        };
        let w = self.weight((screen - self.focus).length());
        GridVertex {
            point,
            direction: inner + w * (here - inner),
        }
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
    /// `first` below screen height `band[0]`, `second` above `band[1]`. Errors: the degenerate
    /// cases above.
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
    use crate::projection::trilinear::mesh_builders::{between_surfaces, screen_grid};
    use crate::projection::{AnalyticInverse, CameraFrame, Projection, Trilinear};

    fn camera() -> GridCamera {
        let frame = CameraFrame {
            position: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        };
        GridCamera::perspective(&frame, 60.0, 60.0).unwrap()
    }

    const FOCUS: DVec2 = DVec2::new(0.4, 0.5);
    const EYE: DVec3 = DVec3::new(0.0, 0.0, 5.0);

    /// Focus radius 0.1, band to 0.3, magnified 2.5 times at the look-at distance 5: the
    /// base plane at forward distance 2.
    fn detail() -> DetailInContext {
        DetailInContext::new(camera(), FOCUS, [0.1, 0.3], 2.5, 5.0).unwrap()
    }

    #[test]
    fn detail_in_context_focus_is_parallel_and_magnified() {
        let view = detail();
        assert_eq!(view.base_distance(), 2.0);
        let axis = camera().vertex(FOCUS).direction;
        for s in [
            FOCUS,
            FOCUS + DVec2::new(0.06, -0.03),
            FOCUS + DVec2::new(0.0, 0.0999),
        ] {
            let v = view.vertex(s);
            assert!((v.direction - axis).length() < 1e-15, "parallel at {s}");
            let on_plane = EYE + 2.0 * camera().vertex(s).direction;
            assert!((v.point - on_plane).length() < 1e-12, "base plane at {s}");
        }
        // At the look-at distance (forward 5, t = 3 from the base plane) two focus rays are
        // 1 / 2.5 as far apart as the camera's perspective rays through the same positions.
        let (a, b) = (FOCUS, FOCUS + DVec2::new(0.05, 0.02));
        let focus_at = |s: DVec2| {
            let v = view.vertex(s);
            v.point + 3.0 * v.direction
        };
        let perspective_at = |s: DVec2| EYE + 5.0 * camera().vertex(s).direction;
        let ratio =
            perspective_at(a).distance(perspective_at(b)) / focus_at(a).distance(focus_at(b));
        assert!((ratio - 2.5).abs() < 1e-12, "{ratio}");
    }

    #[test]
    fn detail_in_context_context_is_the_perspective_view() {
        let view = detail();
        for s in [
            DVec2::new(0.95, 0.1),
            DVec2::new(0.4, 0.8),
            DVec2::new(0.0, 1.0),
            FOCUS + DVec2::new(0.3, 0.0),
        ] {
            let (v, c) = (view.vertex(s), camera().vertex(s));
            assert!((v.direction - c.direction).length() < 1e-15, "{s}");
            // On the camera's ray: the line from the eye along its direction.
            assert!((v.point - EYE).cross(c.direction).length() < 1e-12, "{s}");
            assert!((v.point - EYE).dot(c.direction) > 0.0, "{s}");
        }
    }

    #[test]
    fn detail_in_context_is_continuous_across_the_band() {
        let view = detail();
        assert_eq!((view.weight(0.1), view.weight(0.3)), (0.0, 1.0));
        assert!((view.weight(0.2) - 0.5).abs() < 1e-12);
        // Along a radius through the band, steps of 1e-4 in screen change the ray by little
        // (the two ends differ by about 0.3 in direction).
        let dir = DVec2::new(0.6, -0.8);
        let mut previous = view.vertex(FOCUS + 0.05 * dir);
        for k in 1..=3000 {
            let v = view.vertex(FOCUS + (0.05 + 1e-4 * f64::from(k)) * dir);
            assert!(
                (v.direction - previous.direction).length() < 1e-3,
                "step {k}"
            );
            assert!((v.point - previous.point).length() < 1e-3, "step {k}");
            previous = v;
        }
        // The grid of projection triangles over it is a valid, continuous trilinear mesh.
        let mesh = screen_grid(16, |s| view.vertex(s)).unwrap();
        let trilinear = Trilinear::new(&mesh, 64, 64).unwrap();
        let mut previous = trilinear.ray(DVec2::new(0.05, 32.5)).unwrap();
        for step in 1..640 {
            let ray = trilinear
                .ray(DVec2::new(0.05 + 0.1 * f64::from(step), 32.5))
                .unwrap();
            assert!(
                (ray.direction - previous.direction).length() < 0.01,
                "step {step}"
            );
            assert!(
                (ray.origin - previous.origin).length() < 0.02,
                "step {step}"
            );
            previous = ray;
        }
    }

    /// The point the inverse-perspective focus of [`inverse`] converges on: 2 beyond the
    /// look-at distance on the camera's ray through the focus, nudged off it.
    fn converge() -> DVec3 {
        EYE + 7.0 * camera().vertex(FOCUS).direction + DVec3::new(0.1, -0.05, 0.0)
    }

    fn inverse() -> DetailInContext {
        detail()
            .with_focus_view(FocusView::InversePerspective {
                converge: converge(),
            })
            .unwrap()
    }

    #[test]
    fn inverse_perspective_focus_rays_meet_at_the_convergence_point() {
        let view = inverse();
        for s in [
            FOCUS,
            FOCUS + DVec2::new(0.06, -0.03),
            FOCUS + DVec2::new(0.0, 0.0999),
        ] {
            let v = view.vertex(s);
            let to = converge() - v.point;
            assert!(to.cross(v.direction).length() < 1e-12 * to.length(), "{s}");
            assert!(to.dot(v.direction) > 0.0, "{s}: ahead of the base point");
            let on_plane = EYE + 2.0 * camera().vertex(s).direction;
            assert!((v.point - on_plane).length() < 1e-12, "base plane at {s}");
        }
        // Seen from around: two focus rays that start apart on the base plane come together.
        let (a, b) = (
            view.vertex(FOCUS),
            view.vertex(FOCUS + DVec2::new(0.08, 0.0)),
        );
        let gap = |t: f64| (a.point + t * a.direction).distance(b.point + t * b.direction);
        assert!(gap(2.0) < gap(0.0) && gap(4.0) < gap(2.0));
        // The context is still the camera's perspective view.
        let s = DVec2::new(0.95, 0.1);
        assert!((view.vertex(s).direction - camera().vertex(s).direction).length() < 1e-15);
        // The orthographic focus is the default, and with_focus_view(Orthographic) gives it.
        assert_eq!(
            inverse().with_focus_view(FocusView::Orthographic).unwrap(),
            detail()
        );
    }

    #[test]
    fn inverse_perspective_convergence_must_lie_beyond_the_base_plane() {
        let at_plane = EYE + 2.0 * camera().vertex(FOCUS).direction;
        for converge in [at_plane, EYE, EYE - DVec3::Z, DVec3::NAN] {
            let e = detail()
                .with_focus_view(FocusView::InversePerspective { converge })
                .unwrap_err();
            assert!(e.message.contains("beyond the base plane"), "{e}");
        }
        let beyond = at_plane + 1e-6 * camera().vertex(FOCUS).direction;
        assert!(detail()
            .with_focus_view(FocusView::InversePerspective { converge: beyond })
            .is_ok());
    }

    #[test]
    fn detail_in_context_degenerate_parameters_are_errors() {
        let (c, f) = (camera(), DVec2::splat(0.5));
        assert!(DetailInContext::new(c, f, [0.1, 0.3], 0.0, 5.0).is_err());
        assert!(DetailInContext::new(c, f, [0.1, 0.3], f64::NAN, 5.0).is_err());
        assert!(DetailInContext::new(c, f, [0.3, 0.3], 2.0, 5.0).is_err());
        assert!(DetailInContext::new(c, f, [0.0, 0.3], 2.0, 5.0).is_err());
        assert!(DetailInContext::new(c, DVec2::NAN, [0.1, 0.3], 2.0, 5.0).is_err());
        let e = DetailInContext::new(c, f, [0.1, 0.3], 2.0, 0.0).unwrap_err();
        assert!(e.message.contains("distance"), "{e}");
        let frame = CameraFrame {
            position: DVec3::new(0.0, 8.0, 0.0),
            look_at: DVec3::ZERO,
            up: DVec3::NEG_Z,
        };
        let parallel = GridCamera::orthographic(&frame, 8.0, 8.0).unwrap();
        let e = DetailInContext::new(parallel, f, [0.1, 0.3], 2.0, 5.0).unwrap_err();
        assert!(e.message.contains("pinhole"), "{e}");
        assert!(
            DetailInContext::new(c, f, [0.2, 0.5], 0.5, 5.0).is_ok(),
            "a minifier: the base plane beyond the look-at distance"
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
            /// The detail-in-context surface never folds: at every depth `t >= 0` from the
            /// base plane, the image of a screen position lies on the focus ray's side of the
            /// same direction and farther out the farther the position is from the focus.
            #[test]
            fn detail_in_context_does_not_fold(
                inner in 0.01..0.4f64,
                width in 0.01..0.4f64,
                magnification in 0.3..8.0f64,
                angle in 0.0..6.3f64,
                (r1, r2) in (0.0..0.9f64, 0.0..0.9f64),
                t in 0.0..20.0f64,
            ) {
                let view = DetailInContext::new(camera(), FOCUS, [inner, inner + width], magnification, 5.0).unwrap();
                let dir = DVec2::from_angle(angle);
                let at = |r: f64| {
                    let v = view.vertex(FOCUS + r * dir);
                    v.point + t * v.direction
                };
                let centre = at(0.0);
                let (a, b) = (at(r1) - centre, at(r2) - centre);
                prop_assert!(a.dot(b) >= -1e-12);
                if r1 < r2 {
                    prop_assert!(a.length() < b.length(), "{r1} {r2}: {a} {b}");
                }
            }

            /// Project a point seen through the detail-in-context mesh (either focus), cast
            /// the ray at each image position found: the ray reaches the point, and one of the images is the
            /// pixel and depth the point was made from.
            #[test]
            fn detail_in_context_projection_round_trips(
                sx in 1.0..63.0f64,
                sy in 1.0..63.0f64,
                t in 0.0..10.0f64,
                inverse_focus in proptest::bool::ANY,
            ) {
                let view = if inverse_focus { inverse() } else { detail() };
                let mesh = screen_grid(6, |s| view.vertex(s)).unwrap();
                let trilinear = Trilinear::new(&mesh, 64, 64).unwrap();
                let pixel = DVec2::new(sx, sy);
                let point = trilinear.ray(pixel).unwrap().at(t);
                let mut images = Vec::new();
                trilinear.project(point, &mut images);
                prop_assert!(images
                    .iter()
                    .any(|i| i.pixel.distance(pixel) < 1e-6 && (i.t - t).abs() < 1e-6 * (1.0 + t)),
                    "{pixel} {t}: {images:?}");
                for image in images {
                    if let Some(ray) = trilinear.ray(image.pixel) {
                        prop_assert!(ray.at(image.t).distance(point) < 1e-6 * (1.0 + point.length()),
                            "{point}: {image:?}");
                    }
                }
            }
        }
    }
}
