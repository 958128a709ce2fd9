//! Volumes that change their projection with depth (thesis 4.2, fig. 4.10; 7.2, figs. 7.7 and
//! 7.8): coaxial rectangles ("stations") at increasing distances along the view axis, joined
//! piecewise-linearly (polyline projectors, a kink at every inner station) or, for three
//! stations, by one quadratic Bezier (smooth projectors).
//!
//! A station is (d, h): the rectangle at distance d from the eye with half-width h (and
//! half-height h H/W). Between two stations (d_a, h_a) and (d_b, h_b) the straight projectors
//! all pass through the point on the axis at distance d_a - h_a (d_b - d_a) / (h_b - h_a)
//! (the centre of the homothety between the rectangles): that piece of the volume is a
//! perspective view with half-angle atan((h_b - h_a) / (d_b - d_a)), or an orthographic one
//! when h_b = h_a.
//!
//! - ortho near / perspective far: stations (n, m tan(fov/2)), (m, m tan(fov/2)),
//!   (f, f tan(fov/2)) for the transition distance m: orthographic (width 2 m tan(fov/2))
//!   in front of m, exactly the camera's own perspective frustum behind it;
//! - perspective to perspective: views k = 0 .. N-1 with half-angles a_k and transitions
//!   m_1 < ... < m_{N-1}: h(n) = n tan a_0 and h grows by tan a_k per unit of distance
//!   between m_k and m_{k+1} (m_0 = n, m_N = f): view 0 is the camera's perspective, view
//!   k a perspective whose eye lies on the axis where its rays meet.

use super::super::blend::{BezierVolume, PiecewiseVolume};
use super::super::control_surface::Surface;
use super::super::volume::Volume;
use crate::error::{Error, Result};

/// How the stations of a depth transition are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DepthStyle {
    /// Polyline projectors, exact at every station (a kink at each inner one).
    Piecewise,
    /// One quadratic Bezier through the first and last station, the middle one its control
    /// point: tangent to the first view at the near end and to the last at the far end.
    Quadratic,
}

/// The `style` names of scene files, in order.
pub const DEPTH_STYLE_NAMES: [&str; 2] = ["piecewise", "quadratic"];

impl DepthStyle {
    /// The scene-file name.
    pub fn name(&self) -> &'static str {
        match self {
            DepthStyle::Piecewise => "piecewise",
            DepthStyle::Quadratic => "quadratic",
        }
    }
}

/// A rectangle at distance `d` from the eye with half-width `h`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Station {
    pub d: f64,
    pub h: f64,
}

/// Checks `near < m_1 < ... < far` for the transitions `between` (preset `name`).
fn check_order(name: &str, near: f64, between: &[f64], far: f64) -> Result<()> {
    let all: Vec<f64> = std::iter::once(near)
        .chain(between.iter().copied())
        .chain(std::iter::once(far))
        .collect();
    if between.iter().all(|m| m.is_finite()) && all.windows(2).all(|w| w[0] < w[1]) {
        Ok(())
    } else {
        Err(Error::new(format!(
            "flexible {name} transitions must lie strictly between the near and far clip \
             distances, increasing: near {near}, transitions {between:?}, far {far}"
        )))
    }
}

/// The stations of the ortho-near / perspective-far volume (`tan` = tan(fov/2)). Errors: a
/// transition outside (near, far).
pub(super) fn ortho_near_persp_far(
    tan: f64,
    transition: f64,
    near: f64,
    far: f64,
) -> Result<Vec<Station>> {
    check_order("ortho_near_persp_far", near, &[transition], far)?;
    let h = transition * tan;
    Ok(vec![
        Station { d: near, h },
        Station { d: transition, h },
        Station {
            d: far,
            h: far * tan,
        },
    ])
}

/// The stations of a chain of perspective views (`tans` = tan of each view's half-angle,
/// `transitions` one fewer). Errors: a count mismatch, fewer than two views, transitions not
/// increasing strictly inside (near, far).
pub(super) fn perspective_chain(
    tans: &[f64],
    transitions: &[f64],
    near: f64,
    far: f64,
) -> Result<Vec<Station>> {
    if tans.len() < 2 || transitions.len() + 1 != tans.len() {
        return Err(Error::new(format!(
            "flexible depth_transition needs at least two fovs and one transition fewer \
             than fovs, got {} fovs and {} transitions",
            tans.len(),
            transitions.len()
        )));
    }
    check_order("depth_transition", near, transitions, far)?;
    let mut stations = vec![Station {
        d: near,
        h: near * tans[0],
    }];
    let ends = transitions.iter().chain(std::iter::once(&far));
    for (tan, &d) in tans.iter().zip(ends) {
        let last = stations[stations.len() - 1];
        stations.push(Station {
            d,
            h: last.h + (d - last.d) * tan,
        });
    }
    Ok(stations)
}

/// The volume through `stations` (`rect(station)` gives its surface). The piecewise knots
/// are the stations' fractions of the depth range, so t is proportional to the distance
/// along the axis. Errors: the quadratic style with other than three stations.
pub(super) fn volume(
    stations: &[Station],
    style: DepthStyle,
    rect: impl Fn(Station) -> Surface,
) -> Result<Volume> {
    let surfaces: Vec<Surface> = stations.iter().map(|s| rect(*s)).collect();
    match style {
        DepthStyle::Piecewise => {
            let (near, far) = (stations[0].d, stations[stations.len() - 1].d);
            let knots = stations
                .iter()
                .map(|s| (s.d - near) / (far - near))
                .collect();
            Ok(Volume::Piecewise(PiecewiseVolume::new(
                surfaces,
                Some(knots),
            )?))
        }
        DepthStyle::Quadratic if stations.len() == 3 => {
            Ok(Volume::Bezier(BezierVolume::new(surfaces, None)?))
        }
        DepthStyle::Quadratic => Err(Error::new(format!(
            "flexible style \"quadratic\" joins exactly two views (one transition), got {} \
             stations; use style = \"piecewise\" for more",
            stations.len()
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ortho_near_persp_far_stations() {
        let s = ortho_near_persp_far(0.5, 4.0, 0.0, 10.0).unwrap();
        assert_eq!(
            s,
            vec![
                Station { d: 0.0, h: 2.0 },
                Station { d: 4.0, h: 2.0 },
                Station { d: 10.0, h: 5.0 },
            ]
        );
        for bad in [0.0, 10.0, -1.0, 12.0, f64::NAN] {
            assert!(ortho_near_persp_far(0.5, bad, 0.0, 10.0).is_err(), "{bad}");
        }
    }

    #[test]
    fn perspective_chain_continues_each_view_from_the_last_station() {
        let s = perspective_chain(&[1.0, 0.25, 2.0], &[2.0, 6.0], 1.0, 7.0).unwrap();
        let h: Vec<f64> = s.iter().map(|s| s.h).collect();
        assert_eq!(h, vec![1.0, 2.0, 3.0, 5.0]);
        assert!(perspective_chain(&[1.0], &[], 1.0, 7.0).is_err());
        assert!(perspective_chain(&[1.0, 2.0], &[2.0, 3.0], 1.0, 7.0).is_err());
        assert!(perspective_chain(&[1.0, 2.0, 3.0], &[4.0, 3.0], 1.0, 7.0).is_err());
    }

    #[test]
    fn quadratic_needs_three_stations() {
        let s = perspective_chain(&[1.0, 0.25, 2.0], &[2.0, 6.0], 1.0, 7.0).unwrap();
        let rect = |s: Station| {
            Surface::rectangle_centred(
                glam::DVec3::new(0.0, 0.0, s.d),
                glam::DVec3::X * s.h,
                glam::DVec3::Y * s.h,
            )
        };
        let e = volume(&s, DepthStyle::Quadratic, rect).unwrap_err();
        assert!(e.message.contains("exactly two views"), "{e}");
        assert!(volume(&s, DepthStyle::Piecewise, rect).is_ok());
        assert!(volume(&s[1..], DepthStyle::Quadratic, rect).is_ok());
    }
}
