//! The panorama throughput workload (frames per second of `--method raster` on a large scene), shared by `flexcam bench flexible
//! --part panorama` and the criterion bench `raster`, so that both time the same work:
//! `builtin:teapot-dense` (123,554 triangles) as a 1280 x 720 equirectangular (360 x 180)
//! panorama from the position of the scene's own camera, looking where it looks.

use crate::error::{Error, Result};
use crate::projection::{Projection, ProjectionSpec};
use crate::scene::{builtin, Scene};

/// The panorama's image size in pixels.
pub const PANORAMA_SIZE: (u32, u32) = (1280, 720);

/// The scene and projection of the panorama workload.
pub struct PanoramaWorkload {
    /// `builtin:teapot-dense`.
    pub scene: Scene,
    /// The panorama projection, built at [`PANORAMA_SIZE`].
    pub projection: Box<dyn Projection>,
}

/// Loads the workload of the module documentation. Errors: the built-in scene no longer
/// has a perspective camera to take the panorama's frame from.
pub fn teapot_dense_panorama() -> Result<PanoramaWorkload> {
    let scene = builtin::load("teapot-dense")?;
    let frame = match &scene.projection {
        ProjectionSpec::Perspective { frame, .. } => *frame,
        other => {
            return Err(Error::new(format!(
                "teapot-dense should have a perspective camera, not {}",
                other.kind()
            )))
        }
    };
    let spec = ProjectionSpec::Equirectangular {
        frame,
        h_fov: 360.0,
        v_fov: 180.0,
    };
    let projection = spec.build(PANORAMA_SIZE.0, PANORAMA_SIZE.1)?;
    Ok(PanoramaWorkload { scene, projection })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_panorama_workload_is_the_dense_teapot_in_a_full_sphere() {
        let workload = teapot_dense_panorama().unwrap();
        assert_eq!(workload.scene.triangle_count(), 123_554);
        assert_eq!(workload.projection.kind(), "equirectangular");
        assert_eq!(workload.projection.resolution(), PANORAMA_SIZE);
    }
}
