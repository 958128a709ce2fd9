//! The viewing volume Q(u, v, t) of a flexible projection, whatever its projectors: one type
//! over the straight volume between two surfaces ([`LinearVolume`]), the blended volumes
//! with polyline or Bezier projectors (module `blend`), the mix of two volumes
//! ([`InterpolatedVolume`]), a volume moved onto the image's domain to be mixed with one on
//! another map ([`RemappedVolume`]) and the projector grid (module `projector_grid`).
//! Everything that only needs Q and dQ/dt works with all of them.

use glam::{DVec2, DVec3};

use super::blend::{BezierVolume, PiecewiseVolume};
use super::control_surface::Surface;
use super::linear_volume::{check_projectors, LinearVolume};
use super::projector_grid::GridVolume;
use crate::error::Result;
use crate::geometry::Ray;
use crate::projection::{Projector, ProjectorHull};

mod interpolated;
mod remapped;
pub(super) use interpolated::mix;
pub use interpolated::{InterpolatedVolume, MIXED_SEGMENTS};
pub use remapped::RemappedVolume;

/// A viewing volume.
#[derive(Debug, Clone, PartialEq)]
pub enum Volume {
    /// Straight projectors between two surfaces (boxed: two surfaces inline are large).
    Linear(Box<LinearVolume>),
    /// Polyline projectors through two or more surfaces.
    Piecewise(PiecewiseVolume),
    /// Bezier projectors from three or more surfaces.
    Bezier(BezierVolume),
    /// a Q1 + (1 - a) Q2 of two volumes that do not blend into a simpler one (module
    /// `interpolate`).
    Interpolated(Box<InterpolatedVolume>),
    /// A volume on the image's domain through its own re-parameterisation, for a mix with
    /// a volume on another (module `remapped`).
    Remapped(Box<RemappedVolume>),
    /// Straight or quadratic projectors interpolated from a grid of placed or fitted node
    /// projectors (module `projector_grid`).
    Grid(Box<GridVolume>),
}

impl Volume {
    /// Q(u, v, t).
    pub fn point(&self, uv: DVec2, t: f64) -> DVec3 {
        match self {
            Volume::Linear(v) => v.point(uv, t),
            Volume::Piecewise(v) => v.point(uv, t),
            Volume::Bezier(v) => v.point(uv, t),
            Volume::Interpolated(v) => v.point(uv, t),
            Volume::Remapped(v) => v.volume.point(v.own_uv(uv), t),
            Volume::Grid(v) => v.grid.point(uv, t),
        }
    }

    /// dQ/dt at (u, v, t): the projector's tangent, the view direction for shading.
    pub fn tangent(&self, uv: DVec2, t: f64) -> DVec3 {
        match self {
            Volume::Linear(v) => v.tangent(uv),
            Volume::Piecewise(v) => v.tangent(uv, t),
            Volume::Bezier(v) => v.tangent(uv, t),
            Volume::Interpolated(v) => v.tangent(uv, t),
            Volume::Remapped(v) => v.volume.tangent(v.own_uv(uv), t),
            Volume::Grid(v) => v.grid.tangent(uv, t),
        }
    }

    /// The projector of (u, v) when it is a straight ray; `None` when it has zero length or
    /// is curved (see [`Volume::projector`]).
    pub fn ray(&self, uv: DVec2) -> Option<Ray> {
        self.sees(uv).then(|| self.ray_continued(uv)).flatten()
    }

    /// The projector of (u, v), straight or curved; `None` when it has zero length.
    pub fn projector(&self, uv: DVec2) -> Option<Projector> {
        self.sees(uv)
            .then(|| self.projector_continued(uv))
            .flatten()
    }

    /// Whether the volume sees (u, v): everywhere but where a remapped volume's own map has
    /// no (u, v) (outside a fisheye's circle); a mix sees where either of its volumes does.
    pub fn sees(&self, uv: DVec2) -> bool {
        match self {
            Volume::Remapped(v) => v.sees(uv),
            Volume::Interpolated(v) => v.first.sees(uv) || v.second.sees(uv),
            Volume::Linear(_) | Volume::Piecewise(_) | Volume::Bezier(_) | Volume::Grid(_) => true,
        }
    }

    /// [`Volume::ray`] where the volume does not see (u, v) too (a remapped volume
    /// continued beyond its map's domain), for mixing.
    pub fn ray_continued(&self, uv: DVec2) -> Option<Ray> {
        match self {
            Volume::Linear(v) => v.ray(uv),
            Volume::Interpolated(v) => v.ray(uv),
            Volume::Remapped(v) => v.volume.ray_continued(v.own_uv(uv)),
            Volume::Grid(v) => v.grid.ray(uv),
            Volume::Piecewise(_) | Volume::Bezier(_) => None,
        }
    }

    /// [`Volume::projector`] where the volume does not see (u, v) too, for mixing.
    pub fn projector_continued(&self, uv: DVec2) -> Option<Projector> {
        match self {
            Volume::Linear(v) => v.ray(uv).map(Projector::Straight),
            Volume::Piecewise(v) => v.projector(uv),
            Volume::Bezier(v) => v.projector(uv),
            Volume::Interpolated(v) => v.projector(uv),
            Volume::Remapped(v) => v.volume.projector_continued(v.own_uv(uv)),
            Volume::Grid(v) => v.grid.projector(uv),
        }
    }

    /// Sets `out` to [`Volume::projector`] of (u, v); piecewise and Bezier volumes refill
    /// the vertex buffer of a polyline already in `out` (no allocation once it is large
    /// enough), the others replace `out`.
    pub fn projector_into(&self, uv: DVec2, out: &mut Option<Projector>) {
        match self {
            Volume::Piecewise(v) => v.projector_into(uv, out),
            Volume::Bezier(v) => v.projector_into(uv, out),
            Volume::Linear(_) | Volume::Interpolated(_) | Volume::Remapped(_) | Volume::Grid(_) => {
                *out = self.projector(uv)
            }
        }
    }

    /// A bound on the projectors of every (u, v) in the rectangle `[lo, hi]`, each of which
    /// has a projector (see [`ProjectorHull`]): for piecewise and Bezier volumes of surfaces
    /// bilinear in (u, v) (see [`PiecewiseVolume::projector_hull`],
    /// [`BezierVolume::projector_hull`]); `None` for the others.
    pub fn projector_hull(&self, lo: DVec2, hi: DVec2) -> Option<ProjectorHull> {
        match self {
            Volume::Piecewise(v) => v.projector_hull(lo, hi),
            Volume::Bezier(v) => v.projector_hull(lo, hi),
            Volume::Linear(_) | Volume::Interpolated(_) | Volume::Remapped(_) | Volume::Grid(_) => {
                None
            }
        }
    }

    /// The control surfaces, near to far, for drawing the volume: a linear volume's near
    /// and far surfaces; a piecewise or Bezier volume's surfaces (a Bezier volume's inner
    /// ones are control nets, off the volume); for a mix of two volumes and a projector grid,
    /// whose own surfaces are mixed or interpolated, the volume's points at t = 0 and t = 1.
    pub fn control_surfaces(&self) -> Vec<ControlSurface<'_>> {
        match self {
            Volume::Linear(v) => vec![ControlSurface::Own(&v.near), ControlSurface::Own(&v.far)],
            Volume::Piecewise(v) => v.surfaces().iter().map(ControlSurface::Own).collect(),
            Volume::Bezier(v) => v.surfaces().iter().map(ControlSurface::Own).collect(),
            Volume::Interpolated(_) | Volume::Remapped(_) | Volume::Grid(_) => [0.0, 1.0]
                .map(|t| ControlSurface::At { volume: self, t })
                .into(),
        }
    }

    /// Errors when every projector on a 17 x 17 grid of (u, v) has zero length at t = 0
    /// and t = 1 (nothing can be seen: near and far surfaces coincide).
    pub fn check_projectors(&self) -> Result<()> {
        check_projectors(|uv, t| self.tangent(uv, t))
    }
}

/// One control surface of a volume as [`Volume::control_surfaces`] gives it.
#[derive(Debug, Clone, Copy)]
pub enum ControlSurface<'a> {
    /// A surface of the volume's own.
    Own(&'a Surface),
    /// The volume's points Q(u, v, t) at one t.
    At {
        /// The volume.
        volume: &'a Volume,
        /// Where along the projectors, in [0, 1].
        t: f64,
    },
}

impl ControlSurface<'_> {
    /// The surface's point at (u, v).
    pub fn point(&self, uv: DVec2) -> DVec3 {
        match self {
            ControlSurface::Own(surface) => surface.point(uv),
            ControlSurface::At { volume, t } => volume.point(uv, *t),
        }
    }
}
