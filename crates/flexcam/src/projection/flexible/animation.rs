//! Keyframed flexible cameras (thesis 8.1: animated transitions between projections): keys
//! hold a time and a flexible projection; frame f is shown at time f / fps, and between two
//! keys the volume is their blend Q = a Q_i + (1 - a) Q_{i+1} ([`super::blend`]), with a
//! going from 1 to 0 linearly in time or along the smoothstep 3s^2 - 2s^3 (zero speed at
//! every key). Before the first key and after the last the camera holds still. An animation
//! without keys is a timeline alone (frames and their times): its camera is the scene's own
//! projection, and what moves are the scene's objects ([`crate::scene::Orbit`]).

use super::{FlexibleSpec, VolumeSource};
use crate::error::{Error, Result};

/// How the blend weight follows time between two keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Easing {
    /// Weight linear in time: piecewise-linear motion of every volume point.
    Linear,
    /// Smoothstep of the linear fraction: the camera eases out of and into each key.
    Smooth,
}

/// One key: the projection shown at `time` seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct Keyframe {
    /// The key's time, seconds.
    pub time: f64,
    /// The projection shown at `time`.
    pub projection: FlexibleSpec,
}

/// A keyframed camera (or none) over `frames` frames at `fps` frames per second.
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    frames: u32,
    fps: f64,
    easing: Easing,
    keys: Vec<Keyframe>,
}

impl Animation {
    /// Errors (one line each, naming the key by its index from 0): no frames; `fps` not
    /// finite and positive; a key time that is not finite, or not later than the
    /// key before it.
    pub fn new(frames: u32, fps: f64, easing: Easing, keys: Vec<Keyframe>) -> Result<Self> {
        if frames == 0 {
            return Err(Error::new("animation frames must be at least 1"));
        }
        if !(fps.is_finite() && fps > 0.0) {
            return Err(Error::new(format!(
                "animation fps must be a positive number, got {fps}"
            )));
        }
        for (i, key) in keys.iter().enumerate() {
            if !key.time.is_finite() {
                return Err(Error::new(format!(
                    "animation key {i} time must be finite, got {}",
                    key.time
                )));
            }
            if let Some(before) = i.checked_sub(1).map(|j| keys[j].time) {
                if key.time <= before {
                    return Err(Error::new(format!(
                        "animation key {i} time {} must be later than the key before it ({before})",
                        key.time
                    )));
                }
            }
        }
        Ok(Animation {
            frames,
            fps,
            easing,
            keys,
        })
    }

    /// The number of frames.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Frames per second.
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// The keys, in time order; empty when the camera is the scene's projection.
    pub fn keys(&self) -> &[Keyframe] {
        &self.keys
    }

    /// The time of frame `frame`, in seconds.
    pub fn time(&self, frame: u32) -> f64 {
        f64::from(frame) / self.fps
    }

    /// The projection at `time`: the key itself at (or outside) the ends and at key times,
    /// else the blend of the two keys around it with weight a on the earlier one; `None`
    /// without keys (the scene's own projection).
    pub fn projection_at(&self, time: f64) -> Option<FlexibleSpec> {
        let after = self.keys.partition_point(|k| k.time <= time);
        let (Some(before), Some(next)) = (after.checked_sub(1), self.keys.get(after)) else {
            let end = after
                .saturating_sub(1)
                .min(self.keys.len().saturating_sub(1));
            return self.keys.get(end).map(|key| key.projection.clone());
        };
        let (a, b) = (&self.keys[before], next);
        let s = (time - a.time) / (b.time - a.time);
        if s == 0.0 {
            return Some(a.projection.clone());
        }
        let s = match self.easing {
            Easing::Linear => s,
            Easing::Smooth => s * s * (3.0 - 2.0 * s),
        };
        Some(FlexibleSpec {
            source: VolumeSource::Interpolated {
                weight: 1.0 - s,
                first: Box::new(a.projection.clone()),
                second: Box::new(b.projection.clone()),
            },
            reparam: None,
        })
    }

    /// The projection of frame `frame` (`None` without keys).
    pub fn projection(&self, frame: u32) -> Option<FlexibleSpec> {
        self.projection_at(self.time(frame))
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::projection::flexible::{Preset, PresetSpec};
    use crate::projection::CameraFrame;

    fn key(time: f64, fov: f64) -> Keyframe {
        Keyframe {
            time,
            projection: FlexibleSpec {
                source: VolumeSource::Preset(PresetSpec {
                    preset: Preset::Perspective { fov },
                    frame: CameraFrame {
                        position: DVec3::ZERO,
                        look_at: DVec3::NEG_Z,
                        up: DVec3::Y,
                    },
                    clip: None,
                }),
                reparam: None,
            },
        }
    }

    fn weight(spec: &FlexibleSpec) -> f64 {
        match &spec.source {
            VolumeSource::Interpolated { weight, .. } => *weight,
            other => panic!("not a blend: {other:?}"),
        }
    }

    #[test]
    fn keys_are_shown_at_their_times_and_held_outside() {
        let keys = vec![key(1.0, 40.0), key(2.0, 60.0), key(4.0, 90.0)];
        let a = Animation::new(10, 2.0, Easing::Linear, keys.clone()).unwrap();
        assert_eq!(a.time(3), 1.5);
        assert_eq!(a.projection_at(0.0).unwrap(), keys[0].projection);
        assert_eq!(a.projection_at(1.0).unwrap(), keys[0].projection);
        assert_eq!(a.projection_at(2.0).unwrap(), keys[1].projection);
        assert_eq!(a.projection_at(4.0).unwrap(), keys[2].projection);
        assert_eq!(a.projection_at(9.0).unwrap(), keys[2].projection);
        // Between keys: the weight on the earlier key falls linearly from 1 to 0.
        assert_eq!(weight(&a.projection_at(1.5).unwrap()), 0.5);
        assert_eq!(weight(&a.projection_at(3.5).unwrap()), 0.25);
        let VolumeSource::Interpolated { first, second, .. } = a.projection(7).unwrap().source
        else {
            panic!("frame 7 (3.5 s) lies between keys 1 and 2");
        };
        assert_eq!(
            (*first, *second),
            (keys[1].projection.clone(), keys[2].projection.clone())
        );
    }

    #[test]
    fn smooth_easing_is_the_smoothstep_of_the_time_fraction() {
        let a =
            Animation::new(5, 1.0, Easing::Smooth, vec![key(0.0, 40.0), key(4.0, 80.0)]).unwrap();
        // s = 1/4: 3 s^2 - 2 s^3 = 0.15625.
        assert!((weight(&a.projection_at(1.0).unwrap()) - (1.0 - 0.15625)).abs() < 1e-15);
        assert_eq!(weight(&a.projection_at(2.0).unwrap()), 0.5);
    }

    #[test]
    fn without_keys_the_camera_is_the_scenes_own() {
        let a = Animation::new(4, 2.0, Easing::Linear, Vec::new()).unwrap();
        assert_eq!((a.frames(), a.time(3)), (4, 1.5));
        assert_eq!(a.projection(3), None);
    }

    #[test]
    fn bad_timings_are_errors() {
        let e = |frames, fps, keys| Animation::new(frames, fps, Easing::Linear, keys).unwrap_err();
        assert!(e(0, 24.0, vec![key(0.0, 40.0)]).message.contains("frames"));
        assert!(e(3, 0.0, vec![key(0.0, 40.0)]).message.contains("fps"));
        assert!(e(3, f64::NAN, vec![key(0.0, 40.0)]).message.contains("fps"));
        let m = e(3, 24.0, vec![key(1.0, 40.0), key(1.0, 50.0)]).message;
        assert!(m.contains("key 1 time 1 must be later"), "{m}");
        let m = e(3, 24.0, vec![key(f64::INFINITY, 40.0)]).message;
        assert!(m.contains("key 0 time must be finite"), "{m}");
    }
}
