//! [`ProjectionSpec::build`]: from a parsed description to a validated projection.

use super::dome_master::dome_master;
use super::fisheye::Fisheye;
use super::flexible::{build_projection, GridFitter};
use super::kannala_brandt::KannalaBrandt;
use super::linear::{Orthographic, Perspective};
use super::ods::ods;
use super::opencv::Opencv;
use super::panoramic::{Cylindrical, Equirectangular};
use super::trilinear::mesh_builders::BallProjection;
use super::trilinear::Trilinear;
use super::vr180::vr180;
use super::{BuildReport, Projection, ProjectionSpec};
use crate::error::Result;

impl ProjectionSpec {
    /// Validates the description and builds the projection for a `width` x `height` image.
    /// Degenerate descriptions are errors with a one-line message (the scene-file parser adds
    /// the location): an empty image; a non-finite number; `look_at == position`; `up` zero
    /// or parallel to the view direction; an angle or extent out of range (perspective fov in
    /// (0, 180), fisheye fov in (0, 360] or its mapping's range, dome_master tilt in
    /// [-90, 90], orthographic width > 0, equirectangular h_fov in
    /// (0, 360] and v_fov in (0, 180], cylindrical h_fov in (0, 360] and v_fov in (0, 180));
    /// ods and vr180 with an `ipd` that is not a positive length or an odd image height
    /// (ods) or width (vr180), ods pole merging outside 0 <= from < to <= 90;
    /// calibrated intrinsics that are not finite or have a focal length <= 0, or are rendered
    /// at a size other than the scene's without a calibration size;
    /// a trilinear mesh with no triangles, mismatched arrays, an index out of range, a
    /// zero-length normal or a zero-area screen triangle; a flexible volume with a bad preset
    /// parameter or surface, or whose near and far surfaces coincide everywhere; a projector
    /// grid with correspondences (those need [`ProjectionSpec::build_fitted`]).
    pub fn build(&self, width: u32, height: u32) -> Result<Box<dyn Projection>> {
        self.build_with(width, height, None, &mut BuildReport::default())
    }

    /// [`ProjectionSpec::build`] where projector grids may have correspondences, fitted by
    /// `fitter` (`crate::calibrate` provides it), with the build's report.
    pub fn build_fitted(
        &self,
        width: u32,
        height: u32,
        fitter: &dyn GridFitter,
    ) -> Result<(Box<dyn Projection>, BuildReport)> {
        let mut report = BuildReport::default();
        let projection = self.build_with(width, height, Some(fitter), &mut report)?;
        Ok((projection, report))
    }

    fn build_with(
        &self,
        width: u32,
        height: u32,
        fitter: Option<&dyn GridFitter>,
        report: &mut BuildReport,
    ) -> Result<Box<dyn Projection>> {
        Ok(match self {
            ProjectionSpec::Perspective { frame, fov } => {
                Box::new(Perspective::new(frame, *fov, width, height)?)
            }
            ProjectionSpec::Orthographic {
                frame,
                width: extent,
            } => Box::new(Orthographic::new(frame, *extent, width, height)?),
            ProjectionSpec::Fisheye { frame, fov } => {
                Box::new(Fisheye::new(frame, *fov, width, height)?)
            }
            ProjectionSpec::MappedFisheye { frame, fov, lens } => Box::new(Fisheye::with_lens(
                "fisheye", frame, *fov, lens, width, height,
            )?),
            ProjectionSpec::DomeMaster { frame, fov, tilt } => {
                Box::new(dome_master(frame, *fov, *tilt, width, height)?)
            }
            ProjectionSpec::Equirectangular {
                frame,
                h_fov,
                v_fov,
            } => Box::new(Equirectangular::new(frame, *h_fov, *v_fov, width, height)?),
            ProjectionSpec::Cylindrical {
                frame,
                h_fov,
                v_fov,
            } => Box::new(Cylindrical::new(frame, *h_fov, *v_fov, width, height)?),
            ProjectionSpec::Opencv { camera, distortion } => {
                Box::new(Opencv::new(camera, *distortion, width, height)?)
            }
            ProjectionSpec::OpencvFisheye { camera, k } => {
                Box::new(KannalaBrandt::new(camera, *k, width, height)?)
            }
            ProjectionSpec::Ods {
                frame,
                ipd,
                pole_merge,
            } => Box::new(ods(frame, *ipd, *pole_merge, width, height)?),
            ProjectionSpec::Vr180 { frame, ipd } => Box::new(vr180(frame, *ipd, width, height)?),
            ProjectionSpec::Trilinear(mesh) => Box::new(Trilinear::new(mesh, width, height)?),
            ProjectionSpec::ExactBall(view) => Box::new(BallProjection::new(*view, width, height)),
            ProjectionSpec::Flexible(spec) => {
                build_projection(spec, width, height, fitter, report)?
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec2, DVec3};

    use crate::projection::{CameraFrame, TrilinearMesh};

    use super::*;

    fn frame() -> CameraFrame {
        CameraFrame {
            position: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
        }
    }

    fn all_specs(frame: CameraFrame) -> Vec<ProjectionSpec> {
        vec![
            ProjectionSpec::Perspective { frame, fov: 60.0 },
            ProjectionSpec::Orthographic { frame, width: 3.0 },
            ProjectionSpec::Fisheye { frame, fov: 180.0 },
            ProjectionSpec::Equirectangular {
                frame,
                h_fov: 360.0,
                v_fov: 180.0,
            },
            ProjectionSpec::Cylindrical {
                frame,
                h_fov: 360.0,
                v_fov: 90.0,
            },
        ]
    }

    #[test]
    fn builds_every_kind_with_its_name_and_size() {
        for spec in all_specs(frame()) {
            let projection = spec.build(40, 30).unwrap();
            assert_eq!(projection.kind(), spec.kind());
            assert_eq!(projection.resolution(), (40, 30));
            assert!(projection.inverse().is_ok());
            let centre = projection.ray(DVec2::new(20.0, 15.0)).unwrap();
            let forward = (frame().look_at - frame().position).normalize();
            assert!(
                (centre.direction - forward).length() < 1e-12,
                "{}",
                spec.kind()
            );
        }
        let trilinear = ProjectionSpec::Trilinear(TrilinearMesh {
            points: vec![DVec3::ZERO; 3],
            normals: vec![DVec3::Z; 3],
            screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
            triangles: vec![[0, 1, 2]],
        });
        let projection = trilinear.build(8, 8).unwrap();
        assert_eq!(projection.kind(), "trilinear");
        assert!(projection.inverse().is_ok());
    }

    #[test]
    fn every_kind_rejects_empty_images_and_degenerate_frames() {
        let bad_frames = [
            CameraFrame {
                look_at: frame().position,
                ..frame()
            },
            CameraFrame {
                up: DVec3::new(0.0, -1.0, -10.0),
                ..frame()
            },
            CameraFrame {
                up: DVec3::ZERO,
                ..frame()
            },
            CameraFrame {
                position: DVec3::new(0.0, f64::NAN, 0.0),
                ..frame()
            },
        ];
        for spec in all_specs(frame()) {
            assert!(spec.build(0, 10).is_err(), "{}", spec.kind());
            assert!(spec.build(10, 0).is_err(), "{}", spec.kind());
        }
        for bad in bad_frames {
            for spec in all_specs(bad) {
                let e = spec.build(10, 10).err().unwrap();
                assert!(e.message.starts_with("projection "), "{e}");
                assert!(!e.message.contains('\n'));
            }
        }
    }
}
