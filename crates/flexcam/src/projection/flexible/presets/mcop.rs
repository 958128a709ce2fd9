//! Multiple-centre-of-projection images along a camera path (Rademacher and Bishop 1998;
//! thesis 6.1.2, fig. 6.5): every image column is a slit camera at one point of the path.
//!
//! The path is a polyline C(s) parameterised by arc length, with a unit look direction F
//! at each vertex (interpolated along the segments and renormalised). Column u sits at arc
//! length s = u L (L the path's length), and its projectors leave C(s) in the vertical
//! fan F(s) + V tan(v_fov/2) U(s), V = 2v - 1, where U(s) is the scene's `up` made
//! perpendicular to F(s). The control surface at distance d is
//!
//! ```text
//! Q_d(u, v) = C(u L) + d (F(u L) + V tan(v_fov/2) U(u L)),
//! ```
//!
//! so Q_0 is the path itself (Q_n of fig. 6.5) and Q_far the far surface assembled from the
//! columns' far planes. A straight path with one direction is the pushbroom camera.
//!
//! Degenerate cases (errors): fewer than two points, a path of zero length, a direction
//! count other than the point count, a zero direction, two successive directions opposite
//! (their interpolation passes through zero), a look direction parallel to `up` anywhere
//! along the path (that column has no image up). Repeated points are allowed: a zero-length
//! segment takes no columns.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};

/// Successive unit directions count as opposite when their dot product is below -1 plus
/// this; a direction counts as parallel to `up` when the sine between them is below it.
const PARALLEL: f64 = 1e-9;

/// The camera path of an MCOP image.
#[derive(Debug, Clone, PartialEq)]
pub struct McopPath {
    points: Vec<DVec3>,
    /// Arc length at each point, from 0 to the path's length.
    lengths: Vec<f64>,
    /// Unit look direction at each point.
    directions: Vec<DVec3>,
    /// Unit up hint.
    up: DVec3,
}

impl McopPath {
    /// The path through `points` looking along `directions` (one per point), with image up
    /// from `up`. Errors: see the module's degenerate cases.
    pub fn new(points: Vec<DVec3>, directions: Vec<DVec3>, up: DVec3) -> Result<Self> {
        if points.len() < 2 {
            return Err(Error::new(format!(
                "flexible mcop path needs at least 2 points, got {}",
                points.len()
            )));
        }
        if directions.len() != points.len() {
            return Err(Error::new(format!(
                "flexible mcop needs one direction per path point: {} directions for {} \
                 points",
                directions.len(),
                points.len()
            )));
        }
        let finite = |v: &[DVec3]| v.iter().all(|p| p.is_finite());
        if !finite(&points) || !finite(&directions) || !up.is_finite() {
            return Err(Error::new("flexible mcop path must be finite"));
        }
        let mut lengths = vec![0.0];
        for w in points.windows(2) {
            lengths.push(lengths[lengths.len() - 1] + (w[1] - w[0]).length());
        }
        if lengths[lengths.len() - 1] <= 0.0 {
            return Err(Error::new("flexible mcop path has zero length"));
        }
        let directions = directions
            .iter()
            .map(|d| d.try_normalize())
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| Error::new("flexible mcop directions must not be zero"))?;
        let up = up
            .try_normalize()
            .ok_or_else(|| Error::new("flexible mcop up must not be zero"))?;
        if directions
            .windows(2)
            .any(|w| w[0].dot(w[1]) < -1.0 + PARALLEL)
        {
            return Err(Error::new(
                "flexible mcop successive directions must not be opposite",
            ));
        }
        let parallel_at = |d: DVec3| d.cross(up).length() < PARALLEL;
        let crosses_up = |a: DVec3, b: DVec3| {
            // The interpolated direction sweeps the great-circle arc from a to b; `up`
            // lies on it when it is in the arc's plane and between a and b.
            let n = a.cross(b);
            n.length() > PARALLEL
                && up.dot(n).abs() < PARALLEL * n.length()
                && a.cross(up).dot(n) >= 0.0
                && up.cross(b).dot(n) >= 0.0
        };
        if directions.iter().any(|d| parallel_at(*d))
            || directions.windows(2).any(|w| crosses_up(w[0], w[1]))
        {
            return Err(Error::new(
                "flexible mcop directions: a look direction is parallel to `up` along the \
                 path: that column has no image up",
            ));
        }
        Ok(McopPath {
            points,
            lengths,
            directions,
            up,
        })
    }

    /// The path's length L.
    pub fn length(&self) -> f64 {
        self.lengths[self.lengths.len() - 1]
    }

    /// The camera position C and unit look direction F at column `u` (arc length u L; u
    /// outside [0, 1] extrapolates the end segments).
    pub fn station(&self, u: f64) -> (DVec3, DVec3) {
        let s = u * self.length();
        let last = self.points.len() - 2;
        // The segment holding s, skipping zero-length ones (their points coincide).
        let i = self.lengths[1..=last]
            .partition_point(|&l| l <= s)
            .min(last);
        let span = self.lengths[i + 1] - self.lengths[i];
        let f = if span > 0.0 {
            (s - self.lengths[i]) / span
        } else {
            0.0
        };
        let position = self.points[i].lerp(self.points[i + 1], f);
        let look = self.directions[i]
            .lerp(self.directions[i + 1], f)
            .normalize();
        (position, look)
    }

    /// The unit image up of look direction `look`: `up` made perpendicular to it.
    fn image_up(&self, look: DVec3) -> DVec3 {
        (self.up - self.up.dot(look) * look).normalize()
    }
}

/// The control surface Q_d of the module: the path's columns at distance `depth`.
#[derive(Debug, Clone, PartialEq)]
pub struct PathSurface {
    /// The camera path and its look directions.
    pub path: McopPath,
    /// tan(v_fov / 2).
    pub tan_half_v: f64,
    /// d.
    pub depth: f64,
}

impl PathSurface {
    /// Q_d(u, v).
    pub fn point(&self, uv: DVec2) -> DVec3 {
        let (position, look) = self.path.station(uv.x);
        let up = self.path.image_up(look);
        position + self.depth * (look + (2.0 * uv.y - 1.0) * self.tan_half_v * up)
    }

    /// Whether the numbers are finite.
    pub fn is_finite(&self) -> bool {
        self.tan_half_v.is_finite() && self.depth.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn l_path() -> McopPath {
        McopPath::new(
            vec![
                DVec3::ZERO,
                DVec3::X * 3.0,
                DVec3::X * 3.0,
                DVec3::new(3.0, 0.0, 1.0),
            ],
            vec![DVec3::NEG_Z, DVec3::NEG_Z, DVec3::X, DVec3::X],
            DVec3::Y,
        )
        .unwrap()
    }

    #[test]
    fn columns_follow_the_path_by_arc_length() {
        let p = l_path();
        assert_eq!(p.length(), 4.0);
        let (c, f) = p.station(0.5);
        assert!((c - DVec3::X * 2.0).length() < 1e-15);
        assert!((f - DVec3::NEG_Z).length() < 1e-15);
        // The repeated point takes no columns: just past 3/4 the last segment starts,
        // looking along +x.
        let (c, f) = p.station(0.875);
        assert!((c - DVec3::new(3.0, 0.0, 0.5)).length() < 1e-15);
        assert!((f - DVec3::X).length() < 1e-15);
    }

    #[test]
    fn the_surface_at_distance_zero_is_the_path() {
        let s = PathSurface {
            path: l_path(),
            tan_half_v: 0.5,
            depth: 0.0,
        };
        for v in [0.0, 0.3, 1.0] {
            assert!((s.point(DVec2::new(0.25, v)) - DVec3::X).length() < 1e-15);
        }
        let far = PathSurface { depth: 2.0, ..s };
        let top = far.point(DVec2::new(0.25, 1.0));
        assert!((top - DVec3::new(1.0, 1.0, -2.0)).length() < 1e-15);
    }

    #[test]
    fn degenerate_paths_are_errors() {
        let two = vec![DVec3::ZERO, DVec3::X];
        let look = vec![DVec3::NEG_Z; 2];
        assert!(McopPath::new(vec![DVec3::ZERO], vec![DVec3::NEG_Z], DVec3::Y).is_err());
        assert!(McopPath::new(vec![DVec3::X; 2], look.clone(), DVec3::Y).is_err());
        assert!(McopPath::new(two.clone(), vec![DVec3::NEG_Z], DVec3::Y).is_err());
        assert!(McopPath::new(two.clone(), vec![DVec3::ZERO, DVec3::Z], DVec3::Y).is_err());
        let opposite = vec![DVec3::Z, DVec3::NEG_Z];
        assert!(McopPath::new(two.clone(), opposite, DVec3::Y).is_err());
        assert!(McopPath::new(two.clone(), vec![DVec3::Y; 2], DVec3::Y).is_err());
        // Turning from -z to +z over the top passes through +y = up.
        let over = vec![DVec3::new(0.0, 1.0, -1e-3), DVec3::new(0.0, 1.0, 1e-3)];
        let e = McopPath::new(two.clone(), over, DVec3::Y).unwrap_err();
        assert!(e.message.contains("parallel to `up`"), "{e}");
        let nan = vec![DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0)];
        assert!(McopPath::new(nan, look, DVec3::Y).is_err());
    }
}
