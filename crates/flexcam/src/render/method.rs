//! Rendering methods by name (`--method`), and the dispatch to them that
//! [`crate::render::render`] and reflector compositing share.

use std::fmt;
use std::str::FromStr;

use glam::DVec2;

use crate::error::{Error, Result};
use crate::projection::{Projection, Projector};
use crate::render::raster;
use crate::render::trilinear::TrilinearRenderer;
use crate::render::{
    camera_triangles, raycast, transitions, Frame, PreparedScene, RenderOptions, Shading, Stats,
};

/// A way of rendering a projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// The reference ray caster; renders every projection.
    #[default]
    Raycast,
    /// Rasterisation by the analytic inverse with subdivision
    /// ([`RenderOptions::subdivision`]); projections with a continuous inverse only.
    Raster,
    /// Trilinear rasterisation (Vallance 2005), curved edges followed as `options.curves` says;
    /// renders trilinear projections only.
    Trilinear,
    /// Camera triangles (Hou, Wei, Shum and Guo 2006): each projection triangle a
    /// multi-perspective camera, scene triangles drawn through bounding regions and exact
    /// per-fragment hits; renders trilinear projections only.
    CameraTriangles,
}

impl Method {
    /// Every method with its command-line name.
    pub const ALL: [(&'static str, Method); 4] = [
        ("raycast", Method::Raycast),
        ("raster", Method::Raster),
        ("trilinear", Method::Trilinear),
        ("camera-triangles", Method::CameraTriangles),
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Raycast => "raycast",
            Method::Raster => "raster",
            Method::Trilinear => "trilinear",
            Method::CameraTriangles => "camera-triangles",
        }
    }

    /// Renders `prepared` through `projection` by this method alone (no reflector
    /// compositing). Fails, rather than producing a wrong image, when the method cannot
    /// render that projection. The returned stats hold the method's own counters.
    pub(crate) fn render(
        self,
        prepared: &PreparedScene,
        projection: &dyn Projection,
        options: &RenderOptions,
    ) -> Result<(Frame, Stats)> {
        if options.spp == 0 {
            return Err(Error::new("samples per pixel must be at least 1"));
        }
        check_displaced(prepared, self, projection)?;
        if let Shading::Transitions(shading) = options.shading {
            if self != Method::Raycast {
                return Err(Error::new(format!(
                    "--shading transitions and transition-lit render with --method raycast \
                     only, not {self}"
                )));
            }
            return transitions::render(prepared, projection, options, shading);
        }
        match self {
            Method::Raycast => raycast::render(prepared, projection, options),
            Method::Raster => raster::render(prepared, projection, options),
            Method::Trilinear => {
                let trilinear = projection.trilinear().ok_or_else(|| {
                    Error::new(format!(
                        "the trilinear method renders only trilinear projections, \
                         not a {} projection",
                        projection.kind()
                    ))
                })?;
                if trilinear.fragment_mirror().is_some() {
                    return Err(Error::new(
                        "the trilinear method renders interpolated rays only: a reflector with \
                         camera_rays = \"per-fragment\" needs --method camera-triangles or raycast",
                    ));
                }
                TrilinearRenderer::new(prepared).render(trilinear, options, options.curves)
            }
            Method::CameraTriangles => camera_triangles::render(prepared, projection, options),
        }
    }
}

/// Fails, naming the first displaced object, where `method` cannot render the displaced
/// objects of `prepared` through `projection`: `raster` and `trilinear` draw base triangles
/// (they are refused rather than showing the undisplaced surface), and the ray caster does
/// not trace quadratic Bezier projectors through micro-geometry (the projector of the image
/// centre decides: a projection's projectors are all of one kind).
fn check_displaced(
    prepared: &PreparedScene,
    method: Method,
    projection: &dyn Projection,
) -> Result<()> {
    let Some(name) = prepared.first_displaced() else {
        return Ok(());
    };
    if method != Method::Raycast {
        return Err(Error::new(format!(
            "object \"{name}\" is displaced, and displaced objects render with --method \
             raycast only (method {method} would draw the undisplaced triangles)"
        )));
    }
    let (width, height) = projection.resolution();
    let centre = DVec2::new(width as f64 / 2.0, height as f64 / 2.0);
    if let Some(Projector::QuadraticBezier(_)) = projection.projector(centre) {
        return Err(Error::new(format!(
            "object \"{name}\" is displaced, and displaced objects are not traced along \
             quadratic projectors (use straight or polyline projectors)"
        )));
    }
    Ok(())
}

impl FromStr for Method {
    type Err = Error;

    fn from_str(s: &str) -> Result<Method> {
        Method::ALL
            .iter()
            .find(|(name, _)| *name == s)
            .map(|(_, m)| *m)
            .ok_or_else(|| {
                let names: Vec<_> = Method::ALL.iter().map(|(n, _)| *n).collect();
                Error::new(format!(
                    "unknown method \"{s}\" (available: {})",
                    names.join(", ")
                ))
            })
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_is_listed() {
        for (name, m) in Method::ALL {
            assert_eq!(name.parse::<Method>().unwrap(), m);
            assert_eq!(m.to_string(), name);
        }
        let e = "raster-ish".parse::<Method>().unwrap_err();
        assert!(
            e.to_string()
                .contains("available: raycast, raster, trilinear, camera-triangles"),
            "{e}"
        );
    }

    #[test]
    fn trilinear_refuses_other_projections() {
        let scene = crate::scene::load("builtin:cube-floor").unwrap();
        let projection = scene.projection.build(8, 8).unwrap();
        let e = Method::Trilinear
            .render(
                &PreparedScene::new(&scene),
                projection.as_ref(),
                &RenderOptions::default(),
            )
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "the trilinear method renders only trilinear projections, not a {} projection",
                projection.kind()
            )
        );
    }
}
