//! Shape-defined panoramas (thesis ch. 9): a control surface built from an outline P_o(u)
//! (closed, arc length) and a profile P_p(v) (open, arc length),
//!
//! ```text
//! Q_d(u, v) = d (P_o(u)_x P_p(v)_x,  P_p(v)_y,  P_o(u)_y P_p(v)_x)
//! ```
//!
//! in camera-local (right, up, forward) coordinates around the eye: the outline is drawn in
//! the (right, forward) plane and the profile in the (distance from the up axis, height)
//! half-plane (module [`shape`]). u = 1/2 looks along the view direction, u = 0 and 1 are the
//! seam behind the eye, v = 0 is the bottom of the image. A windowed shape
//! ([`PanoramaShape::windowed`]) spans only part of the outline across the image: a panorama
//! of less than a full turn, with image edges instead of a seam. Circle + vertical segment is the
//! cylindrical panorama, circle + semicircle the equirectangular one, square + segment the
//! cubic one.
//!
//! Several outlines may be attached at profile parameters v_i and several profiles at outline
//! parameters u_j (the brief's choice; the thesis attaches them at spherical angles). Between
//! neighbours the curves are blended pointwise with s = (x - x_i) / (x_{i+1} - x_i) (the
//! printed formula is reversed), linearly or by smoothstep 3 s^2 - 2 s^3. Outlines are held
//! constant below the first and above the last; profiles wrap across the seam (between the
//! last and the first).
//!
//! Degenerate cases: a profile point on the axis (P_p(v)_x = 0) puts the whole row u at one
//! point of the axis (a pole, as in the equirectangular panorama); a profile crossing the
//! axis (P_p(v)_x < 0) mirrors those rows to the opposite side of the eye, so the image
//! folds: ray casting draws it as specified, the lookup inverse refuses it (module
//! [`lookup`]).

pub mod curve;
pub mod edit;
pub mod lookup;
pub mod shape;

use std::sync::Arc;

use glam::{DVec2, DVec3};

pub use self::curve::ArcCurve;
pub use self::edit::{edit_source, make_perspective};
pub use self::shape::{OutlineShape, ProfileShape};
use super::super::camera_basis::CameraBasis;
use super::super::CameraFrame;
use super::control_surface::Surface;
use crate::error::{Error, Result};

/// The default far clip distance of the presets and shape-defined panoramas, in world units.
pub const DEFAULT_FAR: f64 = 1000.0;

/// How neighbouring outlines (or profiles) are blended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CurveBlend {
    /// Weight s.
    #[default]
    Linear,
    /// Weight 3 s^2 - 2 s^3: each curve keeps its shape over more of the image (the thesis's
    /// "ease-in, ease-out").
    Smooth,
}

impl CurveBlend {
    /// The weight of the second curve at fraction `s` in [0, 1] between two.
    pub fn weight(self, s: f64) -> f64 {
        match self {
            CurveBlend::Linear => s,
            CurveBlend::Smooth => s * s * (3.0 - 2.0 * s),
        }
    }
}

/// A curve attached at a parameter of the other curve family.
#[derive(Debug, Clone, PartialEq)]
pub struct Attached {
    /// v for an outline, u for a profile, in [0, 1].
    pub at: f64,
    /// The outline or profile itself.
    pub curve: ArcCurve,
}

/// The outlines and profiles of a panorama, with the blend between neighbours and the part
/// of the outlines the image spans.
#[derive(Debug, Clone, PartialEq)]
pub struct PanoramaShape {
    outlines: Vec<Attached>,
    profiles: Vec<Attached>,
    blend: CurveBlend,
    /// The outline fractions [s0, s1] at the image's left and right edges (u = 0 and 1): the
    /// image's u maps linearly onto them. `None`: the whole outline, [0, 1], with the seam
    /// at the image's edges.
    window: Option<[f64; 2]>,
}

/// The narrowest window, as a fraction of the outline (0.00036 degrees of a circle): u is
/// found as (s - s0) / (s1 - s0) from an outline fraction s known to about 1e-16, so a
/// narrower window would lose the lookup's accuracy in u.
pub const MIN_WINDOW: f64 = 1e-6;

impl PanoramaShape {
    /// Errors: no outline or no profile, an outline that is not closed or a profile that is,
    /// attachment parameters outside [0, 1] or not strictly increasing (profiles: also not
    /// both 0 and 1, which are the same column).
    pub fn new(
        outlines: Vec<Attached>,
        profiles: Vec<Attached>,
        blend: CurveBlend,
    ) -> Result<Self> {
        for (what, list, closed) in [("outline", &outlines, true), ("profile", &profiles, false)] {
            if list.is_empty() {
                return Err(Error::new(format!("a panorama needs at least one {what}")));
            }
            if list.iter().any(|a| a.curve.is_closed() != closed) {
                let shape = if closed { "closed" } else { "open" };
                return Err(Error::new(format!("every {what} must be an {shape} curve")));
            }
            if list.iter().any(|a| !(0.0..=1.0).contains(&a.at)) {
                return Err(Error::new(format!(
                    "{what} attachment parameters `at` must lie in [0, 1]"
                )));
            }
            if list.windows(2).any(|w| w[0].at >= w[1].at) {
                return Err(Error::new(format!(
                    "{what} attachment parameters `at` must increase strictly"
                )));
            }
        }
        if profiles.len() > 1 && profiles[profiles.len() - 1].at - profiles[0].at >= 1.0 {
            return Err(Error::new(
                "profiles at u = 0 and u = 1 are attached to the same column (the seam)",
            ));
        }
        Ok(PanoramaShape {
            outlines,
            profiles,
            blend,
            window: None,
        })
    }

    /// The shape with its image spanning only the outline fractions `[s0, s1]` (u = 0 at
    /// s0, u = 1 at s1; profiles stay attached at image columns u): a panorama of less than
    /// a full turn, such as a cylindrical or equirectangular view of `h_fov` < 360 degrees
    /// (the circle's fractions 1/2 -+ h_fov / 720). The image then has edges instead of a
    /// seam: u outside [0, 1] continues around the outline, one turn every 1 / (s1 - s0).
    /// Errors: fractions outside [0, 1], or a window narrower than [`MIN_WINDOW`]
    /// (degenerate: u would lose its accuracy) or s0 >= s1; several profiles (they blend
    /// across the image's edges, which a window makes two different columns).
    pub fn windowed(self, [s0, s1]: [f64; 2]) -> Result<Self> {
        if self.profiles.len() > 1 {
            return Err(Error::new(
                "a panorama windowed to part of its outline takes one profile",
            ));
        }
        let unit = |s: f64| (0.0..=1.0).contains(&s);
        if !(unit(s0) && unit(s1) && s1 - s0 >= MIN_WINDOW) {
            return Err(Error::new(format!(
                "a panorama's window of outline fractions [s0, s1] needs 0 <= s0 < s1 <= 1 and \
                 s1 - s0 >= {MIN_WINDOW} (a horizontal field of view of at least {:.5} \
                 degrees around a circle), got [{s0}, {s1}]",
                MIN_WINDOW * 360.0
            )));
        }
        Ok(PanoramaShape {
            window: Some([s0, s1]),
            ..self
        })
    }

    /// The window of [`PanoramaShape::windowed`], `None` for the whole outline.
    pub fn window(&self) -> Option<[f64; 2]> {
        self.window
    }

    /// The outline fraction at image column `u`.
    pub fn fraction(&self, u: f64) -> f64 {
        match self.window {
            Some([s0, s1]) => s0 + u * (s1 - s0),
            None => u,
        }
    }

    /// The image column of outline fraction `s` (the inverse of [`PanoramaShape::fraction`]):
    /// with a window, `s` is first moved by whole turns to within half a turn of the
    /// window's middle, so that u is continuous across the image and jumps by one turn
    /// (1 / (s1 - s0)) only straight opposite it.
    pub fn column(&self, s: f64) -> f64 {
        match self.window {
            Some([s0, s1]) => {
                let s = s + (0.5 * (s0 + s1) - s).round();
                (s - s0) / (s1 - s0)
            }
            None => s,
        }
    }

    /// One outline and one profile.
    pub fn single(outline: ArcCurve, profile: ArcCurve) -> Result<Self> {
        let attach = |curve| Attached { at: 0.0, curve };
        PanoramaShape::new(
            vec![attach(outline)],
            vec![attach(profile)],
            CurveBlend::Linear,
        )
    }

    /// The outlines, by increasing v.
    pub fn outlines(&self) -> &[Attached] {
        &self.outlines
    }

    /// The profiles, by increasing u.
    pub fn profiles(&self) -> &[Attached] {
        &self.profiles
    }

    /// How neighbouring outlines and profiles are blended.
    pub fn blend(&self) -> CurveBlend {
        self.blend
    }

    /// The outlines blended at row `v`: the indices of the two neighbours and the weight of
    /// the second (below the first and above the last outline: that one twice, weight 0).
    pub fn outline_blend(&self, v: f64) -> (usize, usize, f64) {
        let list = &self.outlines;
        let next = list.partition_point(|a| a.at <= v);
        if next == 0 {
            return (0, 0, 0.0);
        }
        if next == list.len() {
            return (next - 1, next - 1, 0.0);
        }
        let (a, b) = (list[next - 1].at, list[next].at);
        (next - 1, next, self.blend.weight((v - a) / (b - a)))
    }

    /// The profiles blended at column `u` (wrapping across the seam): the indices of the two
    /// neighbours and the weight of the second (one profile: itself twice, weight 0).
    pub fn profile_blend(&self, u: f64) -> (usize, usize, f64) {
        let list = &self.profiles;
        if list.len() == 1 {
            return (0, 0, 0.0);
        }
        let u = u.rem_euclid(1.0);
        let next = list.partition_point(|a| a.at <= u);
        let (i, j) = if next == 0 || next == list.len() {
            (list.len() - 1, 0)
        } else {
            (next - 1, next)
        };
        let span = (list[j].at - list[i].at).rem_euclid(1.0);
        let s = (u - list[i].at).rem_euclid(1.0) / span;
        (i, j, self.blend.weight(s))
    }

    /// The blended outline point at (u, v).
    pub fn outline(&self, uv: DVec2) -> DVec2 {
        self.outline_at(self.fraction(uv.x), uv.y)
    }

    /// The blended outline point at outline fraction `s` of row `v`.
    pub fn outline_at(&self, s: f64, v: f64) -> DVec2 {
        blended(&self.outlines, self.outline_blend(v), s)
    }

    /// The blended profile point at (u, v); profiles wrap across the seam.
    pub fn profile(&self, uv: DVec2) -> DVec2 {
        blended(&self.profiles, self.profile_blend(uv.x), uv.y)
    }

    /// Q_1(u, v): the surface point at scale 1 in camera-local (right, up, forward)
    /// coordinates.
    pub fn local(&self, uv: DVec2) -> DVec3 {
        let o = self.outline(uv);
        let p = self.profile(uv);
        DVec3::new(o.x * p.x, p.y, o.y * p.x)
    }
}

/// The point at fraction `s` of the blend `(i, j, w)` of the curves of `list`.
fn blended(list: &[Attached], (i, j, w): (usize, usize, f64), s: f64) -> DVec2 {
    let a = list[i].curve.at(s);
    if i == j || w == 0.0 {
        a
    } else {
        a.lerp(list[j].curve.at(s), w)
    }
}

/// A panorama control surface: `scale` Q_1(u, v) around the eye of `basis`, in world space.
#[derive(Debug, Clone, PartialEq)]
pub struct PanoramaSurface {
    /// The eye and the camera axes the shape's local coordinates are in.
    pub basis: CameraBasis,
    /// The distance factor d of Q_d, at least 0.
    pub scale: f64,
    /// The outlines and profiles.
    pub shape: Arc<PanoramaShape>,
}

impl PanoramaSurface {
    /// The surface point Q_d(u, v).
    pub fn point(&self, uv: DVec2) -> DVec3 {
        self.basis.origin + self.scale * self.basis.to_world(self.shape.local(uv))
    }

    /// Checks the numbers: a finite eye and basis, a finite scale of at least 0.
    pub fn validate(&self) -> Result<()> {
        let b = &self.basis;
        if !(b.origin.is_finite()
            && b.right.is_finite()
            && b.up.is_finite()
            && b.forward.is_finite())
        {
            return Err(Error::new("panorama surface has a non-finite coordinate"));
        }
        if !(self.scale.is_finite() && self.scale >= 0.0) {
            return Err(Error::new(format!(
                "panorama surface scale must be finite and at least 0, got {}",
                self.scale
            )));
        }
        Ok(())
    }
}

/// A shape-defined panorama placed by a camera frame: straight projectors from the surface at
/// distance `clip[0]` (0: the eye) to the one at `clip[1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct PanoramaSpec {
    /// The outlines and profiles.
    pub shape: Arc<PanoramaShape>,
    /// The eye, view direction and up the shape is placed by.
    pub frame: CameraFrame,
    /// Near and far scales; `None` for [0, 1000] (as the presets).
    pub clip: Option<[f64; 2]>,
}

impl PanoramaSpec {
    /// The near and far control surfaces. Errors: a degenerate frame, a clip range that is
    /// not 0 <= near < far.
    pub fn surfaces(&self) -> Result<(Surface, Surface)> {
        let basis = CameraBasis::new(&self.frame)?;
        let [near, far] = self.clip.unwrap_or([0.0, DEFAULT_FAR]);
        if !(near.is_finite() && far.is_finite() && 0.0 <= near && near < far) {
            return Err(Error::new(format!(
                "flexible clip must be [near, far] with 0 <= near < far, got [{near}, {far}]"
            )));
        }
        let surface = |scale| {
            Surface::Panorama(Box::new(PanoramaSurface {
                basis,
                scale,
                shape: Arc::clone(&self.shape),
            }))
        };
        Ok((surface(near), surface(far)))
    }
}

#[cfg(test)]
mod tests;
