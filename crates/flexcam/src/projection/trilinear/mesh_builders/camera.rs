//! Cameras placed in the world that give a ray for every screen position, independent of the
//! image size (both extents are given), for the visualisation surfaces.

use glam::{DVec2, DVec3};

use super::grid::GridVertex;
use crate::error::Result;
use crate::projection::params::{angle_radians, positive_length, UpTo};
use crate::projection::{CameraBasis, CameraFrame};

/// A pinhole or parallel camera mapping screen [0, 1]^2 ((0, 0) bottom-left) onto its view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GridCamera {
    /// Rays from the eye through a plane at distance 1; `half` holds tan(h_fov / 2) and
    /// tan(v_fov / 2). Base points lie on that plane, so depth t counts from it in units of
    /// the distance from the eye.
    Perspective {
        /// The eye and the view axes.
        basis: CameraBasis,
        /// tan(h_fov / 2) and tan(v_fov / 2).
        half: DVec2,
    },
    /// Parallel rays along the view direction from a `2 half.x` by `2 half.y` rectangle
    /// centred on the eye; directions are unit length.
    Orthographic {
        /// The rectangle's centre and the view axes.
        basis: CameraBasis,
        /// Half the rectangle's width and height, world units.
        half: DVec2,
    },
}

impl GridCamera {
    /// A pinhole with horizontal and vertical angles in degrees. Errors: a degenerate frame,
    /// an angle outside (0, 180).
    pub fn perspective(frame: &CameraFrame, h_fov: f64, v_fov: f64) -> Result<Self> {
        let h = angle_radians("perspective camera", "h_fov", h_fov, UpTo::Below(180.0))?;
        let v = angle_radians("perspective camera", "v_fov", v_fov, UpTo::Below(180.0))?;
        Ok(GridCamera::Perspective {
            basis: CameraBasis::new(frame)?,
            half: DVec2::new((0.5 * h).tan(), (0.5 * v).tan()),
        })
    }

    /// A parallel camera `width` by `height` world units. Errors: a degenerate frame, a
    /// non-positive or non-finite extent.
    pub fn orthographic(frame: &CameraFrame, width: f64, height: f64) -> Result<Self> {
        let w = positive_length("orthographic camera", "width", width)?;
        let h = positive_length("orthographic camera", "height", height)?;
        Ok(GridCamera::Orthographic {
            basis: CameraBasis::new(frame)?,
            half: 0.5 * DVec2::new(w, h),
        })
    }

    /// The base point and ray at screen position `screen` (extrapolated outside [0, 1]^2).
    pub fn vertex(&self, screen: DVec2) -> GridVertex {
        match *self {
            GridCamera::Perspective { basis, half } => {
                let c = (2.0 * screen - DVec2::ONE) * half;
                let direction = basis.to_world(DVec3::new(c.x, c.y, 1.0));
                GridVertex {
                    point: basis.origin + direction,
                    direction,
                }
            }
            GridCamera::Orthographic { basis, half } => {
                let c = (2.0 * screen - DVec2::ONE) * half;
                GridVertex {
                    point: basis.origin + basis.to_world(DVec3::new(c.x, c.y, 0.0)),
                    direction: basis.forward,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::trilinear::mesh_builders::screen_grid;
    use crate::projection::{Perspective, Projection, Trilinear};

    fn frame() -> CameraFrame {
        CameraFrame {
            position: DVec3::new(0.5, 1.0, 4.0),
            look_at: DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
        }
    }

    #[test]
    fn perspective_grid_is_the_perspective_projection() {
        // 64 x 48 at a 60 degree horizontal angle: the vertical angle that keeps pixels square.
        let (width, height) = (64u32, 48u32);
        let h_fov = 60.0_f64;
        let v_fov = 2.0
            * ((0.5 * h_fov.to_radians()).tan() * 0.75)
                .atan()
                .to_degrees();
        let camera = GridCamera::perspective(&frame(), h_fov, v_fov).unwrap();
        let mesh = screen_grid(3, |s| camera.vertex(s)).unwrap();
        let grid = Trilinear::new(&mesh, width, height).unwrap();
        let reference = Perspective::new(&frame(), h_fov, width, height).unwrap();
        for (x, y) in [(0.5, 0.5), (31.5, 20.5), (63.5, 47.5), (10.0, 16.0)] {
            let pixel = DVec2::new(x, y);
            let a = grid.ray(pixel).unwrap();
            let b = reference.ray(pixel).unwrap();
            assert!(
                (a.direction.normalize() - b.direction).length() < 1e-12,
                "{pixel}"
            );
            assert!((a.origin - a.direction - b.origin).length() < 1e-12);
        }
    }

    #[test]
    fn orthographic_rays_are_parallel_and_span_the_extent() {
        let camera = GridCamera::orthographic(&frame(), 4.0, 2.0).unwrap();
        let (a, b) = (camera.vertex(DVec2::ZERO), camera.vertex(DVec2::ONE));
        assert_eq!(a.direction, b.direction);
        assert!(((b.point - a.point).length() - 20f64.sqrt()).abs() < 1e-12);
        assert!((camera.vertex(DVec2::splat(0.5)).point - frame().position).length() < 1e-12);
    }

    #[test]
    fn bad_angles_extents_and_frames_are_errors() {
        assert!(GridCamera::perspective(&frame(), 180.0, 40.0).is_err());
        assert!(GridCamera::perspective(&frame(), 60.0, 0.0).is_err());
        assert!(GridCamera::orthographic(&frame(), 1.0, -1.0).is_err());
        let blind = CameraFrame {
            look_at: frame().position,
            ..frame()
        };
        assert!(GridCamera::perspective(&blind, 60.0, 40.0).is_err());
    }
}
