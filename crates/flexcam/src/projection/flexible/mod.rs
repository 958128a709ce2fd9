//! The flexible projection (Brosz 2011, Flexible Projection): a parametric viewing volume
//! Q(u, v, t) between control surfaces, mapped to the image by a re-parameterisation.
//!
//! - [`control_surface`]: control surfaces Q_i(u, v) on the shared domain (u, v) in [0, 1]^2, u to the
//!   right of the image, v up;
//! - [`volume`]: the volume Q(u, v, t) and dQ/dt over every kind of projector, and
//!   `linear_volume`: Q(u, v, t) = (1 - t) Q_near + t Q_far (straight projectors);
//! - [`blend`]: volumes of two or more surfaces blended in t, piecewise-linear (polyline
//!   projectors) or Bernstein (Bezier projectors);
//! - `patch`: bicubic Bezier and uniform cubic B-spline control surfaces;
//! - [`nurbs`]: NURBS control surfaces (degree, knots, weights);
//! - [`reparam`]: pixel <-> (u, v) (linear, polar fisheye, lens-like, equisolid, Mercator);
//! - [`presets`]: named volumes from a camera frame (perspective, pushbroom, crossed slits, ...);
//! - [`projector_grid`]: a volume interpolated from a grid of placed projectors (5.2), aimed
//!   at point correspondences by a [`GridFitter`] (the fit itself is `crate::calibrate`'s);
//! - [`panorama`]: shape-defined panoramas (ch. 9), outlines and profiles by arc length;
//! - `inverse`: (u, v, t) from a scene point for the analytic class (parallel planes, a
//!   plane and a piecewise-linearly warped plane, nested spheres, coaxial cylinders), and
//!   `displaced_inverse`: the depth-discontinuity occlusion camera's, by a contraction;
//! - [`blend`]: Q = a Q1 + (1 - a) Q2, interpolation and extrapolation between volumes;
//! - [`animation`]: keyframed flexible cameras, a blend of neighbouring keys per frame;
//! - [`pieces`]: discontinuous projections, several flexible projections each owning an
//!   image rectangle.
//!
//! A pixel's projector starts on the near (first) surface and reaches the far (last) surface at
//! t = 1; t is limited to [0, 1] (the per-projector near and far clip of the framework).

pub mod animation;
pub mod blend;
mod chart;
pub mod control_surface;
#[cfg(test)]
mod cross_map_tests;
mod displaced_inverse;
#[cfg(test)]
mod displaced_inverse_tests;
pub mod interpolate;
mod inverse;
mod linear_volume;
pub mod nurbs;
pub mod panorama;
mod patch;
pub mod pieces;
pub mod presets;
pub mod projector_grid;
mod quadratic_inverse;
pub mod reparam;
mod section;
#[cfg(test)]
mod tests;
pub mod volume;

use glam::{DVec2, DVec3};

pub use animation::{Animation, Easing, Keyframe};
pub use blend::{BezierVolume, PiecewiseVolume};
pub use control_surface::{
    BSplinePatch, BezierPatch, CylinderPatch, LineParam, NurbsPatch, NurbsSpec, PolarFrame,
    SpherePatch, Surface,
};
pub use linear_volume::LinearVolume;
pub use panorama::{PanoramaShape, PanoramaSpec};
pub use pieces::{FlexiblePieces, Piece};
pub use presets::{DepthStyle, Magnifier, McopPath, Preset, PresetSpec};
pub use projector_grid::{
    Aim, Correspondence, GridFitter, GridInterpolation, GridVolume, NodeProjector, ProjectorGrid,
    ProjectorGridSpec, Starts,
};
pub use reparam::Reparam;
pub use volume::{ControlSurface, InterpolatedVolume, RemappedVolume, Volume};

use self::inverse::{BoundInverse, Inverse};
use self::quadratic_inverse::QuadraticPlanes;
use super::image_coords::Resolution;
use super::{
    AnalyticInverse, BuildReport, NoInverse, Projection, Projector, ProjectorHull, Trilinear,
};
use crate::error::{Error, Result};
use crate::geometry::Ray;

/// Where the control surfaces of a flexible projection come from.
#[derive(Debug, Clone, PartialEq)]
pub enum VolumeSource {
    /// A named volume placed by a camera frame.
    Preset(PresetSpec),
    /// A shape-defined panorama (outlines and profiles) placed by a camera frame.
    Panorama(PanoramaSpec),
    /// Two explicit control surfaces, straight projectors between them.
    Surfaces {
        /// Where the projectors start (t = 0).
        near: Surface,
        /// Where the projectors end (t = 1).
        far: Surface,
    },
    /// Two or more explicit control surfaces blended in t: curved projectors.
    Blended {
        /// The control surfaces, from near (t = 0) to far (t = 1).
        surfaces: Vec<Surface>,
        /// How they are blended in t.
        blend: Blend,
    },
    /// `weight` Q1 + (1 - `weight`) Q2 of two flexible projections (module [`interpolate`]),
    /// on their shared re-parameterisation, or, where their maps differ, on the image's
    /// own domain (each volume seen through its own map, [`RemappedVolume`]).
    Interpolated {
        /// The share of `first`; outside [0, 1] the blend extrapolates.
        weight: f64,
        /// The projection weighted by `weight`.
        first: Box<FlexibleSpec>,
        /// The projection weighted by `1 - weight`.
        second: Box<FlexibleSpec>,
    },
    /// A projector grid sampled from `base` (straight projectors), re-aimed and fitted
    /// (module [`projector_grid`]); the re-parameterisation is `base`'s unless overridden.
    ProjectorGrid {
        /// The volume the grid's projectors are sampled from.
        base: Box<FlexibleSpec>,
        /// The grid's size, aims and fitting.
        grid: ProjectorGridSpec,
    },
    /// Several flexible projections, each owning a rectangle of the image (module
    /// [`pieces`]): a projection of its own ([`FlexiblePieces`]), not one volume, so it is
    /// built by [`build_projection`] and refused where one volume is needed (an
    /// interpolation, an animation key, a projector grid's base).
    Pieces(Vec<Piece>),
}

/// How the control surfaces of [`VolumeSource::Blended`] are blended in t.
#[derive(Debug, Clone, PartialEq)]
pub enum Blend {
    /// Linear between surfaces at `knots` (`None`: equally spaced): polyline projectors.
    Piecewise {
        /// The t of each surface, increasing from 0 to 1.
        knots: Option<Vec<f64>>,
    },
    /// Bernstein polynomials: Bezier projectors, rendered as polylines of `segments` steps
    /// when given (quadratic ones are analytic otherwise).
    Bezier {
        /// Steps of the polyline a projector is rendered as.
        segments: Option<u32>,
    },
}

/// A parsed flexible projection: the volume and the re-parameterisation (`None`: the
/// preset's own, linear for explicit surfaces).
#[derive(Debug, Clone, PartialEq)]
pub struct FlexibleSpec {
    /// The viewing volume: where its control surfaces come from.
    pub source: VolumeSource,
    /// How image positions map to the volume's (u, v) parameters.
    pub reparam: Option<Reparam>,
}

/// A flexible projection bound to an image size.
#[derive(Debug, Clone, PartialEq)]
pub struct Flexible {
    volume: Volume,
    reparam: Reparam,
    resolution: Resolution,
    /// The analytic inverse, or why there is none (a panorama shape outside the lookup's
    /// class names its reason, for the refusal of `--method raster`).
    inverse: std::result::Result<BoundInverse, NoInverse>,
}

impl Flexible {
    /// Builds the volume. Errors: an empty image; a bad preset parameter or camera frame; an
    /// invalid surface; control surfaces that coincide everywhere; bad knots or segments of
    /// a blended volume (see [`PiecewiseVolume::new`], [`BezierVolume::new`]); a map latitude
    /// out of range; a non-finite interpolation weight; a projector grid with
    /// correspondences (see [`Flexible::build`]).
    pub fn new(spec: &FlexibleSpec, width: u32, height: u32) -> Result<Self> {
        Self::build(spec, width, height, None, &mut BuildReport::default())
    }

    /// [`Flexible::new`] where projector grids may have correspondences: `fitter` fits them
    /// and what it reports is added to `report`.
    pub fn build(
        spec: &FlexibleSpec,
        width: u32,
        height: u32,
        fitter: Option<&dyn GridFitter>,
        report: &mut BuildReport,
    ) -> Result<Self> {
        let resolution = Resolution::new(width, height)?;
        let (volume, reparam) = build_volume(spec, &resolution, fitter, report)?;
        let classified = match &volume {
            Volume::Linear(v) => Inverse::classify(&v.near, &v.far),
            Volume::Piecewise(v)
                if v.surfaces()
                    .iter()
                    .any(|s| matches!(s, Surface::Displaced(_))) =>
            {
                Inverse::classify_displaced(v.surfaces(), v.knots()).map(Some)
            }
            Volume::Piecewise(v) => Ok(Inverse::classify_layers(v.surfaces(), v.knots())),
            Volume::Bezier(v) if v.is_quadratic() => {
                QuadraticPlanes::classify(v.surfaces()).map(|q| Some(Inverse::Quadratic(q)))
            }
            _ => Ok(None),
        };
        let inverse = match classified {
            Ok(Some(solver)) => Ok(BoundInverse {
                solver,
                reparam: reparam.clone(),
                resolution,
            }),
            Ok(None) => Err(NoInverse {
                reason: Some(no_inverse_reason(&volume).to_string()),
            }),
            Err(e) => Err(NoInverse {
                reason: Some(e.message),
            }),
        };
        Ok(Flexible {
            inverse,
            volume,
            reparam,
            resolution,
        })
    }

    /// The viewing volume.
    pub fn volume(&self) -> &Volume {
        &self.volume
    }

    /// The re-parameterisation in use.
    pub fn reparam(&self) -> &Reparam {
        &self.reparam
    }

    /// The (u, v) of continuous pixel position `pixel`, `None` outside the map's domain.
    pub fn uv(&self, pixel: DVec2) -> Option<DVec2> {
        self.reparam.to_uv(&self.resolution, pixel)
    }

    /// Q(u, v, t) for a pixel: the point at depth t on its projector.
    pub fn point(&self, pixel: DVec2, t: f64) -> Option<DVec3> {
        self.uv(pixel).map(|uv| self.volume.point(uv, t))
    }
}

/// The projection `spec` describes: a [`FlexiblePieces`] for `pieces`, else a
/// [`Flexible`] (see [`Flexible::build`]).
pub fn build_projection(
    spec: &FlexibleSpec,
    width: u32,
    height: u32,
    fitter: Option<&dyn GridFitter>,
    report: &mut BuildReport,
) -> Result<Box<dyn Projection>> {
    Ok(match &spec.source {
        VolumeSource::Pieces(_) if spec.reparam.is_some() => {
            return Err(Error::new(
                "a flexible projection made of `pieces` takes no `reparam` of its own: each \
                 piece has its own",
            ))
        }
        VolumeSource::Pieces(pieces) => Box::new(FlexiblePieces::build(
            pieces, width, height, fitter, report,
        )?),
        _ => Box::new(Flexible::build(spec, width, height, fitter, report)?),
    })
}

/// Why `volume` has no analytic inverse when `Inverse::classify` finds none: the scanline
/// class of Brosz 2011 (7.3) is control surfaces of one type with a closed-form inverse
/// whose depth follows from the point (parallel planes, nested spheres, coaxial cylinders),
/// straight, polyline or quadratic projectors between them.
fn no_inverse_reason(volume: &Volume) -> &'static str {
    match volume {
        Volume::Linear(_) => {
            "its near and far control surfaces are outside the scanline class (planes \
             sharing a normal, a plane and a long scene's warped plane, nested spheres or \
             coaxial cylinders)"
        }
        Volume::Piecewise(_) => {
            "its projectors are polylines through control surfaces that are not all flat, \
             parallel and in order along the projectors, with no closed-form inverse"
        }
        Volume::Bezier(_) => {
            "its projectors are Bezier curves of degree above 2 or drawn as polylines \
             (`segments`), with no closed-form inverse (quadratic projectors through three \
             flat parallel surfaces have one)"
        }
        Volume::Interpolated(v) if !matches!(v.first, Volume::Remapped(_)) => {
            "it interpolates two volumes of different structure, with no closed-form inverse"
        }
        Volume::Interpolated(_) | Volume::Remapped(_) => {
            "it interpolates volumes on different re-parameterisations, with no closed-form \
             inverse"
        }
        Volume::Grid(_) => {
            "its projectors are interpolated from a projector grid's nodes, with no \
             closed-form inverse"
        }
    }
}

/// The volume and re-parameterisation of `spec` for an image of `resolution`.
/// Projector grids with correspondences are fitted by `fitter` (see [`GridVolume::build`]).
/// Two volumes with different re-parameterisations are interpolated on the image's own
/// domain (each a [`RemappedVolume`], the blend's map linear).
fn build_volume(
    spec: &FlexibleSpec,
    resolution: &Resolution,
    fitter: Option<&dyn GridFitter>,
    report: &mut BuildReport,
) -> Result<(Volume, Reparam)> {
    let aspect = f64::from(resolution.height) / f64::from(resolution.width);
    let linear = |near, far| LinearVolume::new(near, far).map(|v| Volume::Linear(Box::new(v)));
    let (volume, default_reparam) = match &spec.source {
        VolumeSource::Preset(p) => (p.volume(aspect)?, p.preset.default_reparam()),
        VolumeSource::Panorama(p) => {
            let (near, far) = p.surfaces()?;
            (linear(near, far)?, Reparam::Linear)
        }
        VolumeSource::Surfaces { near, far } => {
            (linear(near.clone(), far.clone())?, Reparam::Linear)
        }
        VolumeSource::Blended { surfaces, blend } => {
            let volume = match blend {
                Blend::Piecewise { knots } => {
                    Volume::Piecewise(PiecewiseVolume::new(surfaces.clone(), knots.clone())?)
                }
                Blend::Bezier { segments } => {
                    Volume::Bezier(BezierVolume::new(surfaces.clone(), *segments)?)
                }
            };
            (volume, Reparam::Linear)
        }
        VolumeSource::Interpolated {
            weight,
            first,
            second,
        } => {
            let (a, map_a) = build_volume(first, resolution, fitter, report)?;
            let (b, map_b) = build_volume(second, resolution, fitter, report)?;
            if map_a == map_b {
                (interpolate::interpolate(*weight, a, b)?, map_a)
            } else {
                let remap = |volume, map| {
                    Volume::Remapped(Box::new(RemappedVolume {
                        volume,
                        map,
                        resolution: *resolution,
                    }))
                };
                let (a, b) = (remap(a, map_a), remap(b, map_b));
                (interpolate::interpolate(*weight, a, b)?, Reparam::Linear)
            }
        }
        VolumeSource::Pieces(_) => {
            return Err(Error::new(
                "a flexible projection made of `pieces` is not one volume: it cannot be \
                 interpolated, animated or the base of a projector grid",
            ))
        }
        VolumeSource::ProjectorGrid { base, grid } => {
            let (base_volume, base_reparam) = build_volume(base, resolution, fitter, report)?;
            let Volume::Linear(linear) = &base_volume else {
                return Err(Error::new(
                    "a projector grid starts from a volume with straight projectors (a preset \
                     or near and far surfaces), not from blended surfaces",
                ));
            };
            let volume = GridVolume::build(grid, linear, fitter, report)?;
            (Volume::Grid(Box::new(volume)), base_reparam)
        }
    };
    let reparam = spec.reparam.clone().unwrap_or(default_reparam);
    reparam.validate()?;
    Ok((volume, reparam))
}

impl Projection for Flexible {
    fn kind(&self) -> &'static str {
        "flexible"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    /// Origin Q_near(u, v), direction Q_far - Q_near (unnormalised: the ray parameter is t),
    /// t in [0, 1]. `None` outside the re-parameterisation's domain and for zero-length
    /// projectors. Curved volumes have no straight ray (`None`): see
    /// [`Projection::projector`].
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        self.volume.ray(self.uv(pixel)?)
    }

    /// The straight, polyline or quadratic Bezier projector of the pixel's (u, v), t in
    /// [0, 1]; `None` outside the re-parameterisation's domain and for zero-length projectors.
    fn projector(&self, pixel: DVec2) -> Option<Projector> {
        self.volume.projector(self.uv(pixel)?)
    }

    /// [`Flexible::projector`] written into `out`, reusing its polyline's vertex buffer
    /// (see [`Volume::projector_into`]).
    fn projector_into(&self, pixel: DVec2, out: &mut Option<Projector>) {
        match self.uv(pixel) {
            Some(uv) => self.volume.projector_into(uv, out),
            None => *out = None,
        }
    }

    /// The volume's hull over the (u, v) rectangle of `[lo, hi]` (see
    /// [`Volume::projector_hull`]), under the linear map only: its u = x / W and
    /// v = 1 - y / H are monotonic also as rounded, so the (u, v) of every sample position
    /// in `[lo, hi]` lies in the rectangle spanned by the corners' (u, v).
    fn projector_hull(&self, lo: DVec2, hi: DVec2) -> Option<ProjectorHull> {
        if self.reparam != Reparam::Linear {
            return None;
        }
        let (a, b) = (self.uv(lo)?, self.uv(hi)?);
        self.volume.projector_hull(a.min(b), a.max(b))
    }

    /// The analytic class: parallel planes sharing a normal, nested spheres, coaxial
    /// cylinders, star-shaped panoramas (see the `inverse` module); for a linear volume
    /// outside it, the reason.
    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        match &self.inverse {
            Ok(inverse) => Ok(inverse),
            Err(none) => Err(none.clone()),
        }
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }

    fn flexible(&self) -> Option<&Flexible> {
        Some(self)
    }
}
