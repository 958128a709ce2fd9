//! Objects that move over an animation's time (scene key `orbit`): a rigid turn of the whole
//! object about a fixed line, at a constant speed. `flexcam animate` renders frame f of a
//! scene with moving objects from [`Scene::at_time`] of the frame's time, so every renderer
//! sees the frame's geometry as if it were a still scene (the paper of Hou et al. 2006, its
//! Figure 7: a mirror teapot reflecting objects that move around it).
//!
//! Invariants: time 0 is the scene as written (the transform is exactly the identity, so a
//! still render of the file and frame 0 agree bit for bit); a whole period later the object
//! is back where it started (the angle is taken from the time modulo the period, in double
//! precision, so a long animation does not drift). Lights and the camera do not move with
//! objects.

use std::f64::consts::TAU;
use std::sync::Arc;

use glam::{Affine3A, DVec3};

use super::{Object, Scene};

/// A turn about the line through `center` along `axis`, one full turn every `period` seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// A point of the axis line, world space.
    pub center: DVec3,
    /// The axis direction, unit length. Seen from its tip, a positive period turns
    /// counter-clockwise (right-hand rule).
    pub axis: DVec3,
    /// Seconds per turn; finite and non-zero, negative turning the other way.
    pub period: f64,
}

impl Orbit {
    /// The turn's angle at `time` seconds, radians in [0, 2 pi) (negative periods: in
    /// (-2 pi, 0]).
    pub fn angle(&self, time: f64) -> f64 {
        let turns = (time / self.period.abs()).rem_euclid(1.0);
        TAU * turns * self.period.signum()
    }

    /// The world-space motion at `time` seconds: exactly the identity at angle 0.
    pub fn transform(&self, time: f64) -> Affine3A {
        let angle = self.angle(time);
        if angle == 0.0 {
            return Affine3A::IDENTITY;
        }
        let turn = glam::DAffine3::from_translation(self.center)
            * glam::DAffine3::from_axis_angle(self.axis, angle)
            * glam::DAffine3::from_translation(-self.center);
        Affine3A::from_mat4(glam::DMat4::from(turn).as_mat4())
    }
}

/// The motion of the object(s) with id `id` (every part of a model file moves together).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectMotion {
    /// The moving object's id.
    pub id: u32,
    /// How it moves.
    pub orbit: Orbit,
}

impl Object {
    /// Moves the object rigidly by `motion` (world space): its mesh (positions and normals;
    /// a copy of the mesh if it is shared) and its object-space patterns with it.
    pub fn move_by(&mut self, motion: &Affine3A) {
        Arc::make_mut(&mut self.mesh).transform(motion);
        self.world_to_object *= motion.inverse();
    }
}

impl Scene {
    /// The scene at `time` seconds: each moving object turned by its orbit; the objects that
    /// do not move keep sharing their meshes with `self`. Without motions, a copy of `self`.
    pub fn at_time(&self, time: f64) -> Scene {
        let mut moved = self.clone();
        for motion in &self.motions {
            let transform = motion.orbit.transform(time);
            if transform == Affine3A::IDENTITY {
                continue;
            }
            for object in moved.objects.iter_mut().filter(|o| o.id == motion.id) {
                object.move_by(&transform);
            }
        }
        moved
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use proptest::prelude::*;

    use super::*;
    use crate::scene::builtin;

    fn orbit(period: f64) -> Orbit {
        Orbit {
            center: DVec3::new(1.0, 0.0, 0.0),
            axis: DVec3::Y,
            period,
        }
    }

    #[test]
    fn time_zero_and_whole_periods_are_the_identity() {
        for period in [4.0, -4.0, 0.3] {
            let o = orbit(period);
            assert_eq!(o.transform(0.0), Affine3A::IDENTITY);
            assert_eq!(o.transform(5.0 * period.abs()), Affine3A::IDENTITY);
        }
    }

    #[test]
    fn a_quarter_period_turns_a_quarter_about_the_axis_line() {
        // About +y through (1, 0, 0): (2, 0, 0) turns to (1, 0, -1) counter-clockwise seen
        // from above, to (1, 0, 1) for a negative period.
        let p = Vec3::new(2.0, 0.0, 0.0);
        let ccw = orbit(4.0).transform(1.0).transform_point3(p);
        assert!((ccw - Vec3::new(1.0, 0.0, -1.0)).length() < 1e-6, "{ccw}");
        let cw = orbit(-4.0).transform(1.0).transform_point3(p);
        assert!((cw - Vec3::new(1.0, 0.0, 1.0)).length() < 1e-6, "{cw}");
        // A point on the axis line stays put.
        let on_axis = orbit(4.0)
            .transform(1.0)
            .transform_point3(Vec3::new(1.0, 5.0, 0.0));
        assert!((on_axis - Vec3::new(1.0, 5.0, 0.0)).length() < 1e-6);
    }

    #[test]
    fn a_long_animation_does_not_drift() {
        // An hour at 24 frames per second: the angle still comes from the time modulo the
        // period.
        let o = orbit(2.5);
        let late = o
            .transform(3600.0 + 0.625)
            .transform_point3(Vec3::new(2.0, 0.0, 0.0));
        let early = o
            .transform(0.625)
            .transform_point3(Vec3::new(2.0, 0.0, 0.0));
        assert!((late - early).length() < 1e-6);
    }

    #[test]
    fn moving_a_scene_moves_only_its_moving_objects_and_their_patterns() {
        let mut scene = builtin::load("cube-floor").unwrap();
        let id = scene.objects[0].id;
        scene.motions.push(ObjectMotion {
            id,
            orbit: orbit(4.0),
        });
        let moved = scene.at_time(1.0);
        let turn = orbit(4.0).transform(1.0);
        for (before, after) in scene.objects.iter().zip(&moved.objects) {
            if before.id == id {
                for (p, q) in before.mesh.positions.iter().zip(&after.mesh.positions) {
                    assert!((turn.transform_point3(*p) - *q).length() < 1e-5);
                    // The object-space point under the moved surface is the same.
                    let a = before.world_to_object.transform_point3(*p);
                    let b = after.world_to_object.transform_point3(*q);
                    assert!((a - b).length() < 1e-4, "{a} {b}");
                }
            } else {
                assert!(Arc::ptr_eq(&before.mesh, &after.mesh));
            }
        }
        // Time 0: the same scene, meshes shared.
        let still = scene.at_time(0.0);
        assert!(Arc::ptr_eq(&still.objects[0].mesh, &scene.objects[0].mesh));
    }

    proptest! {
        /// The inverse: turning by time t and then by -t is the identity.
        #[test]
        fn turning_back_undoes_the_turn(
            time in -100.0f64..100.0,
            period in prop_oneof![-20.0f64..-0.05, 0.05f64..20.0],
            axis in (-1.0f64..1.0, -1.0f64..1.0, 0.2f64..1.0),
        ) {
            let o = Orbit {
                center: DVec3::new(0.5, -1.0, 2.0),
                axis: DVec3::new(axis.0, axis.1, axis.2).normalize(),
                period,
            };
            let p = Vec3::new(1.0, 2.0, 3.0);
            let back = o.transform(-time) * o.transform(time);
            prop_assert!((back.transform_point3(p) - p).length() < 1e-4);
            // Distances to the axis line are kept (a rigid turn about it).
            let q = o.transform(time).transform_point3(p).as_dvec3();
            let off = |x: DVec3| (x - o.center).reject_from(o.axis).length();
            prop_assert!((off(q) - off(p.as_dvec3())).abs() < 1e-4);
        }
    }
}
