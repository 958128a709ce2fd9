//! The first stage of a [`StagedInverse`] for every scene vertex, kept from frame to frame
//! while its key stays the same.
//!
//! A panorama's longitude and latitude of a vertex (two `atan2` and a square root, about
//! 5 % of a 123,554-triangle panorama's frame) depend on the eye and its frame alone: while
//! a field of view or the image size is dragged in a viewer they do not change, and each
//! frame only divides them by the new angle per pixel. Kept with the renderer's other
//! buffers, which go from renderer to renderer of one prepared scene (and so of the same
//! vertices); the key is compared bit for bit and the vertex counts too, so kept
//! coordinates are the ones the first stage would give.

use glam::DVec2;
use rayon::prelude::*;

use super::kept::KeptPerObject;
use crate::projection::{StageKey, StagedInverse};
use crate::scene::Scene;

/// Per object, per vertex: the first stage's coordinates (`None` on the singular set), for
/// the first stage's key.
#[derive(Debug, Default)]
pub struct KeptCoordinates {
    coordinates: KeptPerObject<StageKey, Option<DVec2>>,
}

impl KeptCoordinates {
    /// The coordinates of `scene`'s vertices through `staged`: those kept when they were
    /// computed for the same key and vertex counts, else computed again (in parallel) and
    /// kept.
    pub fn update(&mut self, scene: &Scene, staged: &dyn StagedInverse) -> &[Vec<Option<DVec2>>] {
        self.coordinates.update(
            staged.key(),
            scene,
            |mesh| mesh.positions.len(),
            |mesh, kept| {
                mesh.positions
                    .par_iter()
                    .map(|p| staged.coordinates(p.as_dvec3()))
                    .collect_into_vec(kept);
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::projection::{CameraFrame, ProjectionSpec};

    /// After each frame the kept coordinates are the first stage's own for every vertex,
    /// and the pixels made from them are the continuous inverse's, bit for bit: after a
    /// first computation, after a change that keeps the key (the fields of view, the image
    /// size), after one that moves the eye, one that turns the frame, and one that changes
    /// the kind with the same frame.
    #[test]
    fn kept_coordinates_are_fresh_ones() {
        let scene = crate::scene::builtin::load("cube-floor").unwrap();
        let frame = |position: DVec3, look_at: DVec3| CameraFrame {
            position,
            look_at,
            up: DVec3::Y,
        };
        let eye = DVec3::new(0.0, 2.0, 4.0);
        let ahead = DVec3::new(0.0, 0.5, 0.0);
        let equirect =
            |frame: CameraFrame, h_fov: f64, v_fov: f64| ProjectionSpec::Equirectangular {
                frame,
                h_fov,
                v_fov,
            };
        let cylindrical = |frame: CameraFrame, h_fov: f64| ProjectionSpec::Cylindrical {
            frame,
            h_fov,
            v_fov: 120.0,
        };
        let specs = [
            (equirect(frame(eye, ahead), 360.0, 180.0), 64, true),
            (equirect(frame(eye, ahead), 250.0, 120.0), 80, false),
            (
                equirect(frame(DVec3::new(1.0, 3.0, -2.0), ahead), 250.0, 120.0),
                80,
                true,
            ),
            (
                equirect(frame(DVec3::new(1.0, 3.0, -2.0), DVec3::X), 250.0, 120.0),
                80,
                true,
            ),
            (
                cylindrical(frame(DVec3::new(1.0, 3.0, -2.0), DVec3::X), 250.0),
                80,
                true,
            ),
            (
                cylindrical(frame(DVec3::new(1.0, 3.0, -2.0), DVec3::X), 90.0),
                40,
                false,
            ),
        ];
        let mut kept = KeptCoordinates::default();
        let mut previous: Option<Vec<Vec<Option<DVec2>>>> = None;
        for (spec, width, recomputed) in specs {
            let projection = spec.build(width, 32).unwrap();
            let inverse = projection.inverse().unwrap();
            let charted = inverse.charted().unwrap();
            let staged = charted.map.staged().unwrap();
            let coordinates = kept.update(&scene, staged).to_vec();
            assert_eq!(coordinates.len(), scene.objects.len());
            for (object, coordinates) in scene.objects.iter().zip(&coordinates) {
                assert_eq!(coordinates.len(), object.mesh.positions.len());
                for (p, &c) in object.mesh.positions.iter().zip(coordinates) {
                    let p = p.as_dvec3();
                    let fresh = staged.coordinates(p);
                    assert_eq!(
                        c.map(|c| c.to_array().map(f64::to_bits)),
                        fresh.map(|c| c.to_array().map(f64::to_bits))
                    );
                    let pixel = c.map(|c| staged.pixel(c).to_array().map(f64::to_bits));
                    let direct = charted.map.project_continuous(p);
                    assert_eq!(pixel, direct.map(|i| i.pixel.to_array().map(f64::to_bits)));
                }
            }
            if let Some(previous) = previous {
                assert_eq!(previous == coordinates, !recomputed);
            }
            previous = Some(coordinates);
        }
    }
}
