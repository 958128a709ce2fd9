//! Named flexible volumes built from a camera frame: the projections of the thesis (ch. 4, 6)
//! as pairs of control surfaces.
//!
//! All are described in the camera's local coordinates (x right, y up, z forward, eye at
//! `position`), with U = 2u - 1 and V = 2v - 1 in [-1, 1] and control surfaces at the
//! distances `clip = [n, f]` along the view direction (radii for the panoramas):
//! - perspective: rectangles Q_d = d (U tan(fov/2), V tan(fov/2) H/W, 1);
//! - inverse perspective: Q_d = ((e - d) U tan(fov/2) + c_x d / e,
//!   (e - d) V tan(fov/2) H/W + c_y d / e, d), the projectors converging at the point
//!   `converge` = (c_x, c_y, e) (camera-local, e > 0 its depth; n < f <= e); `look_at` only
//!   aims the camera, as for every other preset;
//! - orthographic: Q_d = (U w/2, V w/2 H/W, d);
//! - oblique: Q_d = (U w/2 - alpha d, V w/2 H/W - beta d, d): image (x + alpha z, y + beta z);
//! - pushbroom: Q_d = (U w/2, V d tan(v_fov/2), d): projectors meet the slit y = z = 0;
//! - crossed slits: Q_d = (U d tan(fov/2), V (d - s) tan(v_fov/2), d): every projector passes
//!   the vertical slit x = z = 0 and the horizontal slit y = 0, z = s;
//! - cylindrical: cylinders about the up axis, radius d, angle U h_fov/2, height
//!   V d tan(v_fov/2);
//! - equirectangular: spheres of radius d, longitude U h_fov/2, latitude V v_fov/2;
//! - cubic: the shape-defined panorama (module `panorama`) of the unit square outline and
//!   the vertical segment between elevations +-v_fov/2, scaled by d: four 90-degree
//!   perspective views side by side; rounded cubic: the square with corners rounded to
//!   quarter circles of radius `corner_radius` (0: cubic, 1: cylindrical);
//! - fisheye: spheres of radius d with the pole on the view axis, azimuth from u and angle
//!   off the axis v fov/2, with the polar re-parameterisation.
//!
//! - off-axis perspective: the perspective rectangles with the window shifted by `shift`
//!   (in half-extents): Q_d = d ((U + s_x) tan(fov/2), (V + s_y) tan(fov/2) H/W, 1);
//! - twist: the perspective volume with the far rectangle turned by `twist` about the view
//!   axis (thesis 4.2, 6.3: "rotating the far surface of a perspective projection");
//! - axonometric: the orthographic volume seen from the direction given by `azimuth` and
//!   `elevation` (`axonometric`);
//! - general linear camera: the affine combinations of three generator rays (`glc`).
//!
//! Volumes that change with depth or are made of other surfaces (built by
//! [`PresetSpec::volume`]):
//! - ortho near / perspective far and perspective-to-perspective in depth: coaxial
//!   rectangles joined piecewise-linearly or by a quadratic Bezier ([`depth_transition`]);
//! - occlusion camera: perspective to the distortion plane, then bent towards a pole
//!   ([`occlusion`]);
//! - MCOP: the columns of a camera path ([`mcop`]);
//! - long scene: the pushbroom with its far surface re-parameterised so that deep areas are
//!   seen in perspective ([`long_scene`]);
//! - depth-discontinuity occlusion camera: the perspective whose far samples are moved by a
//!   displacement map, bending between two depths ([`ddoc`]);
//! - magnifier: the perspective volume under a circular magnifying re-parameterisation
//!   ([`lens`]).
//!
//! Near distance 0 puts the near surface at the eye (a point, or the slit): the rays then
//! start where the single-viewpoint projections start theirs.

mod axonometric;
pub mod ddoc;
pub mod depth_transition;
mod glc;
pub mod lens;
pub mod long_scene;
pub mod mcop;
pub mod occlusion;
#[cfg(test)]
mod tests;

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::super::camera_basis::CameraBasis;
use super::super::params::{angle_radians, positive_length, UpTo};
use super::super::CameraFrame;
use super::blend::PiecewiseVolume;
use super::control_surface::{CylinderPatch, PolarFrame, SpherePatch, Surface};
use super::linear_volume::LinearVolume;
pub use super::panorama::DEFAULT_FAR;
use super::panorama::{OutlineShape, PanoramaShape, PanoramaSpec, ProfileShape};
use super::reparam::Reparam;
use super::volume::Volume;
use crate::error::{Error, Result};
pub use ddoc::{DdocMap, DisplacedRectangle};
use depth_transition::Station;
pub use depth_transition::{DepthStyle, DEPTH_STYLE_NAMES};
pub use lens::Magnifier;
pub use long_scene::{DeepArea, WarpedRectangle};
pub use mcop::{McopPath, PathSurface};
pub use occlusion::PinchedRectangle;

/// A named volume and its own parameters (angles in degrees).
#[derive(Debug, Clone, PartialEq)]
pub enum Preset {
    /// A pinhole as a volume: straight projectors from the eye.
    Perspective {
        /// Horizontal angle of view, degrees.
        fov: f64,
    },
    /// Rectangles shrinking with distance, the projectors meeting at `converge`: far things
    /// look larger.
    InversePerspective {
        /// Horizontal angle at which the projectors converge, degrees.
        fov: f64,
        /// The world point where the projectors meet, in front of the eye (its depth along
        /// the view direction is where the volume ends).
        converge: DVec3,
    },
    /// Parallel projectors along the view direction.
    Orthographic {
        /// Horizontal extent of the view, world units.
        width: f64,
    },
    /// Parallel projectors sheared off the view direction (cavalier, cabinet views).
    Oblique {
        /// Horizontal extent of the view, world units.
        width: f64,
        /// [a, b]: a camera-local point (x, y, z) lands at (x + a z, y + b z).
        shear: DVec2,
    },
    /// Orthographic across, perspective up and down: a line camera moved sideways.
    Pushbroom {
        /// Horizontal extent of the view, world units.
        width: f64,
        /// Vertical angle of view, degrees.
        v_fov: f64,
    },
    /// `v_fov` defaults to the perspective one (from `fov` and the aspect ratio);
    /// `slit_distance` is s, the signed distance from `position` to the horizontal slit.
    CrossedSlits {
        /// Angle of the fan through the vertical slit at `position`, degrees.
        fov: f64,
        /// Angle of the fan through the horizontal slit, degrees (`None`: the perspective
        /// one).
        v_fov: Option<f64>,
        /// s: signed distance from the eye to the horizontal slit, world units.
        slit_distance: f64,
    },
    /// Longitude linear in x, tan(latitude) linear in y, as a volume.
    Cylindrical {
        /// Longitude range across the image, degrees.
        h_fov: f64,
        /// Vertical angle at the image centre, degrees.
        v_fov: f64,
    },
    /// Longitude linear in x, latitude linear in y, as a volume.
    Equirectangular {
        /// Longitude range across the image, degrees.
        h_fov: f64,
        /// Latitude range down the image, degrees.
        v_fov: f64,
    },
    /// The angular fisheye as a volume.
    Fisheye {
        /// Angle across the image circle, degrees.
        fov: f64,
    },
    /// The cubic panorama (360 degrees around, `v_fov` through the middle of each face).
    Cubic {
        /// Vertical angle through the middle of each face, degrees.
        v_fov: f64,
    },
    /// The cubic panorama with rounded corners: `corner_radius` in [0, 1] of the half-width.
    RoundedCubic {
        /// Vertical angle through the middle of each face, degrees.
        v_fov: f64,
        /// Corner radius as a fraction of the half-width, in [0, 1].
        corner_radius: f64,
    },
    /// Perspective with the window shifted by `shift` half-widths and half-heights.
    OffAxis {
        /// Horizontal angle of view of the unshifted window, degrees.
        fov: f64,
        /// Window shift in half-widths (x) and half-heights (y).
        shift: DVec2,
    },
    /// Perspective with the far surface turned by `twist` degrees about the view axis
    /// (counter-clockwise as seen from the eye).
    Twist {
        /// Horizontal angle of view, degrees.
        fov: f64,
        /// Turn of the far surface about the view axis, degrees.
        twist: f64,
    },
    /// Orthographic, looking at `look_at` from the world direction at `azimuth` degrees
    /// about +y (0 = from +z) and `elevation` degrees above the x-z plane; `position` only
    /// gives the distance of the near clip origin from `look_at`.
    Axonometric {
        /// Horizontal extent of the view, world units.
        width: f64,
        /// Direction of view about +y, degrees (0 = from +z).
        azimuth: f64,
        /// Direction of view above the x-z plane, degrees.
        elevation: f64,
    },
    /// General linear camera (Yu and McMillan): generator k = [x0, y0, x1, y1] is the ray
    /// through the camera-local points (x0, y0, 0) and (x1, y1, 1); the image plane z = 0
    /// spans `width` across.
    Glc {
        /// Width of the image plane z = 0, camera-local units.
        width: f64,
        /// The three generator rays, each [x0, y0, x1, y1].
        generators: [[f64; 4]; 3],
    },
    /// Orthographic in front of distance `transition`, the camera's perspective of `fov`
    /// behind it (thesis fig. 4.10); see [`depth_transition`].
    OrthoNearPerspFar {
        /// Horizontal angle of the far perspective, degrees.
        fov: f64,
        /// Distance from the eye where orthographic turns perspective, world units.
        transition: f64,
        /// How the projectors bend at the transition.
        style: DepthStyle,
    },
    /// Perspective views one after another in depth (figs. 7.7, 7.8): view k of `fovs[k]`
    /// from `transitions[k - 1]` to `transitions[k]`; see [`depth_transition`].
    DepthTransition {
        /// Horizontal angle of each view, degrees, near to far.
        fovs: Vec<f64>,
        /// Distances where one view hands over to the next, increasing, world units.
        transitions: Vec<f64>,
        /// How the projectors bend at each transition.
        style: DepthStyle,
    },
    /// The occlusion camera: perspective of `fov` up to distance `transition`, then bent
    /// towards `pole` (image (u, v)) so that the far plane is seen `strength` image widths
    /// further from the pole; see [`occlusion`].
    Occlusion {
        /// Horizontal angle of the near perspective, degrees.
        fov: f64,
        /// Distance where the bend starts, world units.
        transition: f64,
        /// Image position (u, v) the far plane is pushed away from.
        pole: DVec2,
        /// How far the far plane moves from the pole, image widths.
        strength: f64,
    },
    /// A multiple-centre-of-projection camera along the polyline `path` (world points),
    /// looking along `directions` (one per point; `None`: look_at - position everywhere),
    /// each column a vertical fan of `v_fov`; see [`mcop`].
    Mcop {
        /// The centres of projection, a polyline of world points.
        path: Vec<DVec3>,
        /// The view direction at each path point (`None`: look_at - position everywhere).
        directions: Option<Vec<DVec3>>,
        /// Vertical angle of each column's fan, degrees.
        v_fov: f64,
    },
    /// A pushbroom of slit length `width` whose far surface spreads the projectors of the
    /// `deep` areas into perspective fans (Agarwala et al.'s long scenes); see
    /// [`long_scene`].
    LongScene {
        /// Length of the slit, world units.
        width: f64,
        /// Vertical angle of each column's fan, degrees.
        v_fov: f64,
        /// The areas seen in perspective across.
        deep: Vec<DeepArea>,
    },
    /// The depth-discontinuity occlusion camera: the perspective of `fov` up to `z_near`,
    /// its samples beyond `z_far` seen displaced by `map` (`None`: no displacement, the
    /// perspective), the projectors bending in between; see [`ddoc`].
    Ddoc {
        /// Horizontal angle of view, degrees.
        fov: f64,
        /// Distance where the bend starts, world units.
        z_near: f64,
        /// Distance where the displacement is complete, world units.
        z_far: f64,
        /// The displacement of the far samples, image fractions.
        map: Option<Arc<DdocMap>>,
    },
    /// The perspective of `fov` seen through a circular magnifying lens; see [`lens`].
    Magnifier {
        /// Horizontal angle of view, degrees.
        fov: f64,
        /// Where the lens is, its size and its magnification.
        lens: Magnifier,
    },
}

/// The preset names of scene files, in order.
pub const PRESET_NAMES: [&str; 22] = [
    "perspective",
    "inverse_perspective",
    "orthographic",
    "oblique",
    "pushbroom",
    "crossed_slits",
    "cylindrical",
    "equirectangular",
    "fisheye",
    "off_axis",
    "twist",
    "axonometric",
    "glc",
    "cubic",
    "rounded_cubic",
    "ortho_near_persp_far",
    "depth_transition",
    "occlusion",
    "mcop",
    "long_scene",
    "magnifier",
    "ddoc",
];

/// A preset placed in the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct PresetSpec {
    /// The named volume and its parameters.
    pub preset: Preset,
    /// The eye, view direction and up it is placed by.
    pub frame: CameraFrame,
    /// Near and far control-surface distances; `None` for [0, 1000], or [0, e] for the
    /// inverse perspective.
    pub clip: Option<[f64; 2]>,
}

impl Preset {
    /// The scene-file name.
    pub fn name(&self) -> &'static str {
        match self {
            Preset::Perspective { .. } => "perspective",
            Preset::InversePerspective { .. } => "inverse_perspective",
            Preset::Orthographic { .. } => "orthographic",
            Preset::Oblique { .. } => "oblique",
            Preset::Pushbroom { .. } => "pushbroom",
            Preset::CrossedSlits { .. } => "crossed_slits",
            Preset::Cylindrical { .. } => "cylindrical",
            Preset::Equirectangular { .. } => "equirectangular",
            Preset::Fisheye { .. } => "fisheye",
            Preset::OffAxis { .. } => "off_axis",
            Preset::Twist { .. } => "twist",
            Preset::Axonometric { .. } => "axonometric",
            Preset::Glc { .. } => "glc",
            Preset::Cubic { .. } => "cubic",
            Preset::RoundedCubic { .. } => "rounded_cubic",
            Preset::OrthoNearPerspFar { .. } => "ortho_near_persp_far",
            Preset::DepthTransition { .. } => "depth_transition",
            Preset::Occlusion { .. } => "occlusion",
            Preset::Mcop { .. } => "mcop",
            Preset::LongScene { .. } => "long_scene",
            Preset::Magnifier { .. } => "magnifier",
            Preset::Ddoc { .. } => "ddoc",
        }
    }

    /// The re-parameterisation the preset is meant for (polar for the fisheye).
    pub fn default_reparam(&self) -> Reparam {
        match self {
            Preset::Fisheye { .. } => Reparam::Polar,
            Preset::Magnifier { lens, .. } => Reparam::Magnifier(*lens),
            _ => Reparam::Linear,
        }
    }
}

/// A parameter check with the preset's name in the message.
fn angle(preset: &Preset, key: &str, degrees: f64, max: UpTo) -> Result<f64> {
    angle_radians(&format!("flexible {}", preset.name()), key, degrees, max)
}

/// Where a preset's surfaces go: the camera basis and the clip distances.
struct Placement {
    basis: CameraBasis,
    near: f64,
    far: f64,
}

impl Placement {
    /// The rectangle at distance `d` along the view axis with half-extents `half`, its
    /// centre moved by `shift` (camera x, y).
    fn rect(&self, d: f64, half: DVec2, shift: DVec2) -> Surface {
        let [corner, u_edge, v_edge] = self.rect_edges(d, half, shift);
        Surface::Rectangle {
            corner,
            u_edge,
            v_edge,
        }
    }

    /// [`Placement::rect`] as corner, u edge and v edge.
    fn rect_edges(&self, d: f64, half: DVec2, shift: DVec2) -> [DVec3; 3] {
        let b = &self.basis;
        let centre = b.origin + d * b.forward + shift.x * b.right + shift.y * b.up;
        let (u_axis, v_axis) = (half.x * b.right, half.y * b.up);
        [centre - u_axis - v_axis, 2.0 * u_axis, 2.0 * v_axis]
    }

    /// The knots (fractions of the clip range) of surfaces at distances `depths`.
    fn knots(&self, depths: &[f64]) -> Vec<f64> {
        depths
            .iter()
            .map(|d| (d - self.near) / (self.far - self.near))
            .collect()
    }
}

/// The inverse perspective's `converge` in camera-local coordinates (x right, y up, z the
/// depth along the view direction). Errors: a point on or behind the eye's plane (z <= 0:
/// the projectors would meet behind the camera), or not finite.
fn converge_local(basis: &CameraBasis, converge: DVec3) -> Result<DVec3> {
    let local = basis.to_local(converge - basis.origin);
    if !(local.is_finite() && local.z > 0.0) {
        return Err(Error::new(format!(
            "flexible inverse_perspective converge [{}, {}, {}] must lie in front of the eye \
             (its depth along the view direction is {})",
            converge.x, converge.y, converge.z, local.z
        )));
    }
    Ok(local)
}

impl PresetSpec {
    /// The camera basis and clip range (the inverse perspective's default ends at the depth
    /// of `converge`). Errors: a degenerate frame, a clip range that is not 0 <= near < far,
    /// an inverse perspective's `converge` not in front of the eye.
    fn placement(&self) -> Result<Placement> {
        let frame = match self.preset {
            Preset::Axonometric {
                azimuth, elevation, ..
            } => axonometric::frame(&self.frame, azimuth, elevation)?,
            _ => self.frame,
        };
        let basis = CameraBasis::new(&frame)?;
        let default_far = match self.preset {
            Preset::InversePerspective { converge, .. } => converge_local(&basis, converge)?.z,
            _ => DEFAULT_FAR,
        };
        let [near, far] = self.clip.unwrap_or([0.0, default_far]);
        if !(near.is_finite() && far.is_finite() && 0.0 <= near && near < far) {
            return Err(Error::new(format!(
                "flexible clip must be [near, far] with 0 <= near < far, got [{near}, {far}]"
            )));
        }
        Ok(Placement { basis, near, far })
    }

    /// The presets that are shape-defined panoramas, as those panoramas, with the preset's
    /// frame and clip: `cubic` and `rounded_cubic` (the square or rounded-square outline and
    /// the vertical segment profile between elevations +-`v_fov`/2), and the `cylindrical`
    /// (circle and vertical segment) and `equirectangular` (circle and the arc between
    /// elevations +-`v_fov`/2) presets, whose rays these
    /// panoramas repeat (module `panorama`, tests `circle_and_*`), and with `h_fov` < 360
    /// those panoramas windowed to the preset's azimuths ([`PanoramaShape::windowed`]).
    /// `None` for the other presets. Errors: a bad `h_fov`, `v_fov` or corner radius.
    pub fn panorama(&self) -> Option<Result<PanoramaSpec>> {
        let shape = match self.preset {
            Preset::Cubic { v_fov } => cubic_shape(&self.preset, v_fov, OutlineShape::Square),
            Preset::RoundedCubic {
                v_fov,
                corner_radius,
            } => cubic_shape(
                &self.preset,
                v_fov,
                OutlineShape::RoundedSquare {
                    radius: corner_radius,
                },
            ),
            Preset::Cylindrical { h_fov, v_fov } | Preset::Equirectangular { h_fov, v_fov } => {
                round_shape(&self.preset, h_fov, v_fov)
            }
            _ => return None,
        };
        Some(shape.map(|shape| PanoramaSpec {
            shape: Arc::new(shape),
            frame: self.frame,
            clip: self.clip,
        }))
    }

    /// The viewing volume for an image of aspect ratio `aspect` = height / width: two
    /// surfaces with straight projectors ([`PresetSpec::surfaces`]), or the blended volumes
    /// of the depth transitions and the occlusion camera. Errors: those of
    /// [`PresetSpec::surfaces`], transitions outside (near, far), a bad pole, strength, path
    /// or style (see the modules).
    pub fn volume(&self, aspect: f64) -> Result<Volume> {
        let p = &self.preset;
        let half_tan =
            |key: &str, fov: f64| Ok((0.5 * angle(p, key, fov, UpTo::Below(180.0))?).tan());
        let place = self.placement()?;
        let station = |s: Station| place.rect(s.d, DVec2::new(s.h, s.h * aspect), DVec2::ZERO);
        match p {
            Preset::OrthoNearPerspFar {
                fov,
                transition,
                style,
            } => {
                let tan = half_tan("fov", *fov)?;
                let stations = depth_transition::ortho_near_persp_far(
                    tan,
                    *transition,
                    place.near,
                    place.far,
                )?;
                depth_transition::volume(&stations, *style, station)
            }
            Preset::DepthTransition {
                fovs,
                transitions,
                style,
            } => {
                let tans = fovs
                    .iter()
                    .map(|f| half_tan("fovs", *f))
                    .collect::<Result<Vec<_>>>()?;
                let stations =
                    depth_transition::perspective_chain(&tans, transitions, place.near, place.far)?;
                depth_transition::volume(&stations, *style, station)
            }
            Preset::Occlusion {
                fov,
                transition,
                pole,
                strength,
            } => {
                let tan = half_tan("fov", *fov)?;
                let (near, far) = (place.near, place.far);
                if !(near < *transition && *transition < far) {
                    return Err(Error::new(format!(
                        "flexible occlusion transition must lie strictly between the near and far clip distances ({near}, {far}), got {transition}"
                    )));
                }
                let half = |d: f64| DVec2::new(d * tan, d * tan * aspect);
                let far_edges = place.rect_edges(far, half(far), DVec2::ZERO);
                let pinched = PinchedRectangle::new(far_edges, *pole, *strength, aspect)?;
                let surfaces = vec![
                    station(Station {
                        d: near,
                        h: near * tan,
                    }),
                    station(Station {
                        d: *transition,
                        h: transition * tan,
                    }),
                    Surface::Pinched(Box::new(pinched)),
                ];
                let knots = place.knots(&[near, *transition, far]);
                Ok(Volume::Piecewise(PiecewiseVolume::new(
                    surfaces,
                    Some(knots),
                )?))
            }
            Preset::Ddoc {
                fov,
                z_near,
                z_far,
                map,
            } => {
                let tan = half_tan("fov", *fov)?;
                ddoc::check_depths(*z_near, *z_far)?;
                let (near, far) = (place.near, place.far);
                if !(near < *z_near && *z_far < far) {
                    return Err(Error::new(format!(
                        "flexible ddoc z_near and z_far must lie strictly between the near and \
                         far clip distances ({near}, {far}), got {z_near} and {z_far}"
                    )));
                }
                let half = |d: f64| DVec2::new(d * tan, d * tan * aspect);
                let rect = |d: f64| place.rect(d, half(d), DVec2::ZERO);
                let displaced = |d: f64| match map {
                    None => rect(d),
                    Some(map) => {
                        let [corner, u_edge, v_edge] = place.rect_edges(d, half(d), DVec2::ZERO);
                        Surface::Displaced(Box::new(DisplacedRectangle {
                            corner,
                            u_edge,
                            v_edge,
                            map: map.clone(),
                        }))
                    }
                };
                let surfaces = vec![rect(near), rect(*z_near), displaced(*z_far), displaced(far)];
                let knots = place.knots(&[near, *z_near, *z_far, far]);
                Ok(Volume::Piecewise(PiecewiseVolume::new(
                    surfaces,
                    Some(knots),
                )?))
            }
            _ => {
                let (near, far) = self.surfaces(aspect)?;
                Ok(Volume::Linear(Box::new(LinearVolume::new(near, far)?)))
            }
        }
    }

    /// The near and far surfaces for an image of aspect ratio `aspect` = height / width,
    /// for the presets with straight projectors between two surfaces. Errors: a degenerate
    /// frame, a parameter out of range (as the single-viewpoint types), a clip range that is
    /// not 0 <= near < far (and far <= e for the inverse perspective), a preset made of more
    /// than two surfaces (use [`PresetSpec::volume`]).
    pub fn surfaces(&self, aspect: f64) -> Result<(Surface, Surface)> {
        let p = &self.preset;
        let place = self.placement()?;
        let (b, near, far) = (&place.basis, place.near, place.far);
        let centre = |d: f64| b.origin + d * b.forward;
        let rect = |d: f64, half: DVec2, shift: DVec2| place.rect(d, half, shift);
        let pair = |f: &dyn Fn(f64) -> Surface| (f(near), f(far));
        Ok(match *p {
            Preset::OrthoNearPerspFar { .. }
            | Preset::DepthTransition { .. }
            | Preset::Occlusion { .. }
            | Preset::Ddoc { .. } => {
                return Err(Error::new(format!(
                    "flexible {} is made of more than two control surfaces",
                    p.name()
                )))
            }
            Preset::Mcop {
                ref path,
                ref directions,
                v_fov,
            } => {
                let t = (0.5 * angle(p, "v_fov", v_fov, UpTo::Below(180.0))?).tan();
                let looks = directions
                    .clone()
                    .unwrap_or_else(|| vec![b.forward; path.len()]);
                let path = McopPath::new(path.clone(), looks, self.frame.up)?;
                pair(&|d| {
                    Surface::Path(Box::new(PathSurface {
                        path: path.clone(),
                        tan_half_v: t,
                        depth: d,
                    }))
                })
            }
            Preset::Perspective { fov } | Preset::Magnifier { fov, .. } => {
                let h = (0.5 * angle(p, "fov", fov, UpTo::Below(180.0))?).tan();
                pair(&|d| rect(d, d * DVec2::new(h, h * aspect), DVec2::ZERO))
            }
            Preset::InversePerspective { fov, converge } => {
                let h = (0.5 * angle(p, "fov", fov, UpTo::Below(180.0))?).tan();
                let c = converge_local(b, converge)?;
                if far > c.z {
                    return Err(Error::new(format!(
                        "flexible inverse_perspective far clip {far} is beyond the point \
                         the projectors meet (converge, at depth {} along the view)",
                        c.z
                    )));
                }
                let towards = DVec2::new(c.x, c.y) / c.z;
                pair(&|d| rect(d, (c.z - d) * DVec2::new(h, h * aspect), d * towards))
            }
            Preset::Orthographic { width } | Preset::Axonometric { width, .. } => {
                let w = 0.5 * positive_length(&format!("flexible {}", p.name()), "width", width)?;
                pair(&|d| rect(d, DVec2::new(w, w * aspect), DVec2::ZERO))
            }
            Preset::Oblique { width, shear } => {
                let w = 0.5 * positive_length("flexible oblique", "width", width)?;
                if !shear.is_finite() {
                    return Err(Error::new("flexible oblique shear must be finite"));
                }
                pair(&|d| rect(d, DVec2::new(w, w * aspect), -d * shear))
            }
            Preset::Pushbroom { width, v_fov } => {
                let w = 0.5 * positive_length("flexible pushbroom", "width", width)?;
                let t = (0.5 * angle(p, "v_fov", v_fov, UpTo::Below(180.0))?).tan();
                pair(&|d| rect(d, DVec2::new(w, d * t), DVec2::ZERO))
            }
            Preset::LongScene {
                width,
                v_fov,
                ref deep,
            } => {
                let w = positive_length("flexible long_scene", "width", width)?;
                let t = (0.5 * angle(p, "v_fov", v_fov, UpTo::Below(180.0))?).tan();
                let knots = long_scene::far_knots(w, near, far, deep)?;
                let far_surface = WarpedRectangle {
                    corner: centre(far) - far * t * b.up,
                    along: b.right,
                    v_edge: 2.0 * far * t * b.up,
                    knots,
                };
                (
                    rect(near, DVec2::new(0.5 * w, near * t), DVec2::ZERO),
                    Surface::Warped(Box::new(far_surface)),
                )
            }
            Preset::CrossedSlits {
                fov,
                v_fov,
                slit_distance,
            } => {
                let h = (0.5 * angle(p, "fov", fov, UpTo::Below(180.0))?).tan();
                let t = match v_fov {
                    Some(v) => (0.5 * angle(p, "v_fov", v, UpTo::Below(180.0))?).tan(),
                    None => h * aspect,
                };
                if !slit_distance.is_finite() {
                    return Err(Error::new(
                        "flexible crossed_slits slit_distance must be finite",
                    ));
                }
                pair(&|d| rect(d, DVec2::new(d * h, (d - slit_distance) * t), DVec2::ZERO))
            }
            Preset::Cylindrical { h_fov, v_fov } => {
                let half = 0.5 * angle(p, "h_fov", h_fov, UpTo::Including(360.0))?;
                let t = (0.5 * angle(p, "v_fov", v_fov, UpTo::Below(180.0))?).tan();
                let frame = PolarFrame::new(b.up, b.forward)?;
                pair(&|d| {
                    Surface::Cylinder(CylinderPatch {
                        center: b.origin,
                        radius: d,
                        frame,
                        angle: [-half, half],
                        height: [-d * t, d * t],
                    })
                })
            }
            Preset::Equirectangular { h_fov, v_fov } => {
                let h = 0.5 * angle(p, "h_fov", h_fov, UpTo::Including(360.0))?;
                let v = 0.5 * angle(p, "v_fov", v_fov, UpTo::Including(180.0))?;
                let frame = PolarFrame::new(b.up, b.forward)?;
                pair(&|d| sphere(b.origin, d, frame, [-h, h], [-v, v]))
            }
            Preset::Cubic { .. } | Preset::RoundedCubic { .. } => match self.panorama() {
                Some(panorama) => panorama?.surfaces()?,
                None => return Err(Error::new("flexible cubic preset without its panorama")),
            },
            Preset::Fisheye { fov } => {
                let half = 0.5 * angle(p, "fov", fov, UpTo::Including(360.0))?;
                // Pole on the view axis, longitude 0 to the right, +90 up: the polar map's
                // azimuth atan2(py, px) is then the longitude.
                let frame = PolarFrame::new(b.forward, b.right)?;
                let lat = [0.5 * PI, 0.5 * PI - half];
                pair(&|d| sphere(b.origin, d, frame, [-PI, PI], lat))
            }
            Preset::OffAxis { fov, shift } => {
                let h = (0.5 * angle(p, "fov", fov, UpTo::Below(180.0))?).tan();
                if !shift.is_finite() {
                    return Err(Error::new("flexible off_axis shift must be finite"));
                }
                let half = DVec2::new(h, h * aspect);
                pair(&|d| rect(d, d * half, d * shift * half))
            }
            Preset::Twist { fov, twist } => {
                let h = (0.5 * angle(p, "fov", fov, UpTo::Below(180.0))?).tan();
                if !twist.is_finite() {
                    return Err(Error::new("flexible twist angle must be finite"));
                }
                let (sin, cos) = twist.to_radians().sin_cos();
                let (right, up) = (cos * b.right + sin * b.up, cos * b.up - sin * b.right);
                let turned = |d: f64| {
                    Surface::rectangle_centred(centre(d), d * h * right, d * h * aspect * up)
                };
                (
                    rect(near, near * DVec2::new(h, h * aspect), DVec2::ZERO),
                    turned(far),
                )
            }
            Preset::Glc { width, generators } => {
                let w = 0.5 * positive_length("flexible glc", "width", width)?;
                let camera = glc::GeneralLinearCamera::new(generators)?;
                let at = |d: f64, corner: DVec2| {
                    let local = camera.point(corner * DVec2::new(w, w * aspect), d);
                    b.origin + b.to_world(local)
                };
                pair(&|d| {
                    let origin = at(d, DVec2::NEG_ONE);
                    Surface::Rectangle {
                        corner: origin,
                        u_edge: at(d, DVec2::new(1.0, -1.0)) - origin,
                        v_edge: at(d, DVec2::new(-1.0, 1.0)) - origin,
                    }
                })
            }
        })
    }
}

/// The shape of a cubic panorama with outline `outline` and the vertical segment profile
/// between elevations +-`v_fov`/2. Errors: a bad `v_fov` or outline parameter.
fn cubic_shape(preset: &Preset, v_fov: f64, outline: OutlineShape) -> Result<PanoramaShape> {
    let half = 0.5 * angle(preset, "v_fov", v_fov, UpTo::Below(180.0))?;
    let outline = outline
        .curve()
        .map_err(|e| Error::new(format!("flexible {} {}", preset.name(), e.message)))?;
    let profile = ProfileShape::Segment {
        elevation: [-half, half],
    }
    .curve()?;
    PanoramaShape::single(outline, profile)
}

/// The shape of the cylindrical (circle and vertical segment) or equirectangular (circle
/// and arc) panorama between elevations +-`v_fov`/2: the whole circle for `h_fov` = 360,
/// otherwise windowed to the circle's fractions 1/2 -+ `h_fov` / 720 (azimuths -+`h_fov`/2
/// around the view direction, as the preset's own surfaces). Errors: a bad `h_fov` or
/// `v_fov`; degenerate: an `h_fov` narrower than the window's minimum
/// ([`super::panorama::MIN_WINDOW`] of a turn).
fn round_shape(preset: &Preset, h_fov: f64, v_fov: f64) -> Result<PanoramaShape> {
    let h = angle(preset, "h_fov", h_fov, UpTo::Including(360.0))?;
    let turn = h / (2.0 * PI);
    let profile = match preset {
        Preset::Cylindrical { .. } => {
            let half = 0.5 * angle(preset, "v_fov", v_fov, UpTo::Below(180.0))?;
            ProfileShape::Segment {
                elevation: [-half, half],
            }
        }
        _ => {
            let half = 0.5 * angle(preset, "v_fov", v_fov, UpTo::Including(180.0))?;
            ProfileShape::Arc {
                elevation: [-half, half],
            }
        }
    };
    let whole = PanoramaShape::single(OutlineShape::Circle.curve()?, profile.curve()?)?;
    if (turn - 1.0).abs() <= 1e-12 {
        return Ok(whole);
    }
    whole
        .windowed([0.5 - 0.5 * turn, 0.5 + 0.5 * turn])
        .map_err(|e| {
            Error::new(format!(
                "flexible {} h_fov = {h_fov} as a panorama: {}",
                preset.name(),
                e.message
            ))
        })
}

fn sphere(
    center: DVec3,
    radius: f64,
    frame: PolarFrame,
    longitude: [f64; 2],
    latitude: [f64; 2],
) -> Surface {
    Surface::Sphere(SpherePatch {
        center,
        radius,
        frame,
        longitude,
        latitude,
    })
}
