//! Which scene triangles [`Refiner::far_from_poles`] clears, kept from frame to frame while
//! the projection's poles stay put.
//!
//! The answer for a triangle depends only on its corners and on the poles' origins and
//! directions, not on the rest of the projection: while a panorama's field of view or image
//! size is dragged in a viewer, its eye and poles do not move, so the test (a square root
//! per scene triangle, about 5 % of a 123,554-triangle panorama's frame) is answered from
//! the last frame's results. Kept with the renderer's other buffers, which go from renderer
//! to renderer of one prepared scene (and so of the same triangles). The poles are compared
//! bit for bit, so a reused answer is the one the test would give.

use glam::DVec3;
use rayon::prelude::*;

use super::kept::KeptPerObject;
use super::refine::Refiner;
use crate::projection::Pole;
use crate::scene::Scene;

/// Per object, per triangle: whether [`Refiner::far_from_poles`] clears it, for the poles
/// (each origin and direction, as bits).
#[derive(Debug, Default)]
pub struct PoleClearance {
    far: KeptPerObject<Vec<[u64; 6]>, bool>,
}

/// The bits of the pole data that [`Refiner::far_from_poles`] reads.
fn key(poles: &[Pole]) -> Vec<[u64; 6]> {
    poles
        .iter()
        .map(|pole| {
            let [a, b, c] = pole.origin.to_array().map(f64::to_bits);
            let [d, e, f] = pole.direction.to_array().map(f64::to_bits);
            [a, b, c, d, e, f]
        })
        .collect()
}

impl PoleClearance {
    /// The answers for `scene`'s triangles through `refiner`, whose chart has `poles`:
    /// those kept when they were computed for the same poles and triangle counts, else
    /// computed again (in parallel) and kept.
    pub fn update(&mut self, scene: &Scene, refiner: &Refiner<'_>, poles: &[Pole]) -> &[Vec<bool>] {
        self.far.update(
            key(poles),
            scene,
            |mesh| mesh.triangles.len(),
            |mesh, far| {
                mesh.triangles
                    .par_iter()
                    .map(|t| {
                        let points: [DVec3; 3] = t.map(|i| mesh.positions[i as usize].as_dvec3());
                        refiner.far_from_poles(points)
                    })
                    .collect_into_vec(far);
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::{CameraFrame, ProjectionSpec};

    /// The kept answers are the test's own for every triangle: after a first computation,
    /// after a change that keeps the poles (the field of view), after one that moves them
    /// (the eye), and for a projection without poles.
    #[test]
    fn kept_answers_are_the_tests_answers() {
        let scene = crate::scene::builtin::load("cube-floor").unwrap();
        let equirect = |position: DVec3, h_fov: f64| ProjectionSpec::Equirectangular {
            frame: CameraFrame {
                position,
                look_at: DVec3::new(0.0, 0.5, 0.0),
                up: DVec3::Y,
            },
            h_fov,
            v_fov: 180.0,
        };
        let mut kept = PoleClearance::default();
        let mut near_counts = Vec::new();
        for spec in [
            equirect(DVec3::new(0.0, 2.0, 4.0), 360.0),
            equirect(DVec3::new(0.0, 2.0, 4.0), 300.0),
            equirect(DVec3::new(1.0, 3.0, -2.0), 300.0),
            scene.projection.clone(),
        ] {
            let projection = spec.build(64, 32).unwrap();
            let inverse = projection.inverse().unwrap();
            let charted = inverse.charted().unwrap();
            let refiner = Refiner::new(&charted, Some(0.5));
            let far = kept.update(&scene, &refiner, &charted.chart.poles);
            assert_eq!(far.len(), scene.objects.len());
            let mut near = 0;
            for (object, far) in scene.objects.iter().zip(far) {
                assert_eq!(far.len(), object.mesh.triangles.len());
                for (t, &answer) in object.mesh.triangles.iter().zip(far) {
                    let points = t.map(|i| object.mesh.positions[i as usize].as_dvec3());
                    assert_eq!(answer, refiner.far_from_poles(points));
                    near += usize::from(!answer);
                }
            }
            near_counts.push(near);
        }
        // The floor lies across the panoramas' lower pole; a perspective has no pole.
        assert!(near_counts[..3].iter().all(|&n| n > 0), "{near_counts:?}");
        assert_eq!(near_counts[3], 0);
    }
}
