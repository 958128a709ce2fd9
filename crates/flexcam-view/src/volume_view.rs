//! The volume view: the projection's viewing volume over the scene, seen by an orbiting
//! pinhole camera of its own, as line segments (a sketch) that the window projects and
//! draws, and the pixel steps a handle is dragged by in that view.
//!
//! The sketch holds the scene (each object's bounding box and up to [`MAX_SCENE_TRIANGLES`]
//! of its triangles' edges, every k-th), a [`SAMPLES`] x [`SAMPLES`] sample of projectors
//! (the projection's own [`Projection::projector`] at pixel positions spread over the
//! image: straight ones from start to end, polylines as they are, quadratic ones as
//! [`CURVE_STEPS`] steps), the image-plane grid through the sampled projectors, the grid of
//! their ends when they end (flexible volumes) and the control nets of the handles.
//!
//! Degenerate cases: a projector that the projection does not define (outside a fisheye's
//! circle) is left out, and so are the grid lines to it; a straight projector without an
//! end (a camera's ray) is drawn from its start to past the scene (its distance to the
//! centre of the scene's bounding box plus half the box's diagonal); an empty scene
//! frames the volume alone, and a sketch with no point at all frames the unit cube.

use flexcam::projection::{Projection, Projector};
use glam::{DVec2, DVec3};

use crate::handles::{handles, Handle, Place};
use crate::session::Session;

/// Projectors sampled per image side.
pub const SAMPLES: usize = 9;
/// Steps a quadratic projector is drawn with.
pub const CURVE_STEPS: usize = 16;
/// The most triangles whose edges are drawn, over all objects.
pub const MAX_SCENE_TRIANGLES: usize = 1500;
/// The volume view's vertical field of view, degrees.
pub const FOV_DEG: f64 = 50.0;
/// The view height (pixels) that a script's `drag` pixels are counted in.
pub const REFERENCE_HEIGHT: f64 = 480.0;

/// What a line of the sketch shows (the window colours each kind).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Scene geometry: bounding boxes and triangle edges.
    Scene,
    /// A sampled projector.
    Projector,
    /// The grid through the projectors at the image plane (their starts, or where a
    /// camera's rays cross its look-at distance).
    ImageGrid,
    /// The grid of the projectors' ends.
    FarGrid,
    /// The net of a control patch or of a projector grid's nodes.
    ControlNet,
}

/// The volume view's lines, in world space.
#[derive(Debug, Clone, Default)]
pub struct Sketch {
    /// The segments and what each shows.
    pub lines: Vec<(Kind, DVec3, DVec3)>,
    /// The points the default view frames (the scene's boxes, the image-plane grid).
    pub framing: Vec<DVec3>,
}

impl Sketch {
    /// The sketch of `session`'s scene and projection, with the control nets of `handles`.
    pub fn new(session: &Session, handles: &[Handle]) -> Sketch {
        let mut sketch = Sketch::default();
        sketch.scene(session);
        let (center, radius) = bounds_sphere(&sketch.framing);
        sketch.projectors(session, center, radius);
        sketch.nets(handles);
        sketch
    }

    fn scene(&mut self, session: &Session) {
        let objects = &session.prepared().scene().objects;
        let total: usize = objects.iter().map(|o| o.mesh.triangles.len()).sum();
        let stride = total.div_ceil(MAX_SCENE_TRIANGLES).max(1);
        for object in objects {
            let mesh = &object.mesh;
            if let Some((lo, hi)) = mesh.bounds() {
                let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
                let corner = |i: usize| {
                    DVec3::new(
                        if i & 1 == 0 { lo.x } else { hi.x },
                        if i & 2 == 0 { lo.y } else { hi.y },
                        if i & 4 == 0 { lo.z } else { hi.z },
                    )
                };
                for i in 0..8 {
                    self.framing.push(corner(i));
                    for bit in [1, 2, 4] {
                        if i & bit == 0 {
                            self.lines.push((Kind::Scene, corner(i), corner(i | bit)));
                        }
                    }
                }
            }
            for triangle in mesh.triangles.iter().step_by(stride) {
                let p = triangle.map(|i| mesh.positions[i as usize].as_dvec3());
                for k in 0..3 {
                    self.lines.push((Kind::Scene, p[k], p[(k + 1) % 3]));
                }
            }
        }
    }

    /// The sampled projectors, the image-plane grid and the far grid.
    fn projectors(&mut self, session: &Session, center: DVec3, radius: f64) {
        let projection = session.projection();
        let (width, height) = session.size();
        let image_distance = session
            .camera()
            .map_or(1.0, |c| (c.look_at - c.position).length());
        let mut starts = vec![None; SAMPLES * SAMPLES];
        let mut ends = vec![None; SAMPLES * SAMPLES];
        let mut bounded = true;
        for row in 0..SAMPLES {
            for col in 0..SAMPLES {
                let f = |i: usize, size: u32| {
                    0.5 + i as f64 / (SAMPLES - 1) as f64 * (f64::from(size) - 1.0)
                };
                let pixel = DVec2::new(f(col, width), f(row, height));
                let Some(points) = polyline(projection.as_ref(), pixel, center, radius) else {
                    continue;
                };
                bounded &= points.1;
                let points = points.0;
                for pair in points.windows(2) {
                    self.lines.push((Kind::Projector, pair[0], pair[1]));
                }
                starts[row * SAMPLES + col] = points.first().copied();
                ends[row * SAMPLES + col] = points.last().copied();
            }
        }
        // A common eye (a camera): the image plane is where the rays cross the look-at
        // distance.
        let eye = starts.iter().flatten().next().copied();
        let spread = starts
            .iter()
            .flatten()
            .map(|p| eye.map_or(0.0, |e| (*p - e).length()))
            .fold(0.0, f64::max);
        let image: Vec<Option<DVec3>> = if spread > 1e-9 * radius.max(1.0) {
            starts
        } else {
            starts
                .iter()
                .zip(&ends)
                .map(|(&s, &e)| {
                    let (s, e) = (s?, e?);
                    Some(s + (e - s).normalize_or_zero() * image_distance)
                })
                .collect()
        };
        self.framing.extend(image.iter().flatten());
        self.grid(Kind::ImageGrid, &image);
        if bounded {
            self.grid(Kind::FarGrid, &ends);
        }
    }

    /// Lines between the neighbours of a `SAMPLES` x `SAMPLES` grid of points.
    fn grid(&mut self, kind: Kind, points: &[Option<DVec3>]) {
        for row in 0..SAMPLES {
            for col in 0..SAMPLES {
                let Some(p) = points[row * SAMPLES + col] else {
                    continue;
                };
                if let Some(Some(q)) = (col + 1 < SAMPLES).then(|| points[row * SAMPLES + col + 1])
                {
                    self.lines.push((kind, p, q));
                }
                if let Some(Some(q)) =
                    (row + 1 < SAMPLES).then(|| points[(row + 1) * SAMPLES + col])
                {
                    self.lines.push((kind, p, q));
                }
            }
        }
    }

    /// Lines between neighbouring handles of the same net.
    fn nets(&mut self, handles: &[Handle]) {
        for a in handles {
            let (Some((net, row, col)), Place::World(p)) = (&a.net, a.place) else {
                continue;
            };
            for b in handles {
                let (Some((other, r, c)), Place::World(q)) = (&b.net, b.place) else {
                    continue;
                };
                if other == net && ((*r == row + 1 && c == col) || (r == row && *c == col + 1)) {
                    self.lines.push((Kind::ControlNet, p, q));
                }
            }
        }
    }
}

/// The handles of `session`'s projection and the sketch of its volume.
pub fn volume_of(session: &Session) -> (Vec<Handle>, Sketch) {
    let list = handles(session);
    let sketch = Sketch::new(session, &list);
    (list, sketch)
}

/// One line per handle (`flexcam view SCENE --list-handles`): `NAME world X Y Z right RX RY
/// RZ down DX DY DZ` (the world steps of one pixel of a script's `drag` in the default
/// volume view `camera`, [`REFERENCE_HEIGHT`] pixels high) or `NAME image X Y` (pixel
/// position, x right, y down).
pub fn listing(handles: &[Handle], camera: &VolumeCamera) -> String {
    let v = |p: DVec3| format!("{} {} {}", p.x, p.y, p.z);
    handles
        .iter()
        .map(|h| match h.place {
            Place::World(at) => {
                let (right, down) = camera.pixel_steps(at, REFERENCE_HEIGHT);
                format!(
                    "{} world {} right {} down {}\n",
                    h.name,
                    v(at),
                    v(right),
                    v(down)
                )
            }
            Place::Image(at) => format!("{} image {} {}\n", h.name, at.x, at.y),
        })
        .collect()
}

/// The points a projector is drawn through, and whether it ends by itself (`false`: a ray
/// without an end, cut at the reach: the distance from its start past the sphere
/// (`center`, `radius`)).
fn polyline(
    projection: &dyn Projection,
    pixel: DVec2,
    center: DVec3,
    radius: f64,
) -> Option<(Vec<DVec3>, bool)> {
    Some(match projection.projector(pixel)? {
        Projector::Straight(ray) => {
            let start = ray.at(ray.t_min.max(0.0));
            let reach = (start - center).length() + radius;
            let speed = ray.direction.length();
            if speed == 0.0 {
                return None;
            }
            if ray.t_max.is_finite() {
                (vec![start, ray.at(ray.t_max)], true)
            } else {
                let t_reach = ray.t_min.max(0.0) + reach / speed;
                (vec![start, ray.at(t_reach)], false)
            }
        }
        Projector::Polyline(points) => (points, true),
        Projector::QuadraticBezier([p0, p1, p2]) => {
            let points = (0..=CURVE_STEPS)
                .map(|i| {
                    let s = i as f64 / CURVE_STEPS as f64;
                    p0 * (1.0 - s) * (1.0 - s) + p1 * 2.0 * s * (1.0 - s) + p2 * s * s
                })
                .collect();
            (points, true)
        }
    })
}

/// The centre and radius of the bounding box of `points` (the unit cube's when empty).
fn bounds_sphere(points: &[DVec3]) -> (DVec3, f64) {
    let finite = points.iter().filter(|p| p.is_finite());
    let (lo, hi) = finite.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(*p), hi.max(*p))
    });
    if lo.x > hi.x {
        return (DVec3::splat(0.5), 3f64.sqrt() / 2.0);
    }
    let radius = (hi - lo).length() / 2.0;
    ((lo + hi) / 2.0, radius.max(1e-6))
}

/// The volume view's camera: a pinhole orbiting `target` at `distance`, `yaw_deg` about the
/// world's y axis (0: from +z) and `pitch_deg` above the horizon, y up on screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeCamera {
    /// The point looked at (orbited about).
    pub target: DVec3,
    /// The eye's distance from `target`.
    pub distance: f64,
    /// Azimuth of the eye about the y axis, degrees (0: on +z, 90: on +x).
    pub yaw_deg: f64,
    /// Elevation of the eye above the horizontal plane through `target`, degrees, within
    /// +-[`MAX_PITCH_DEG`].
    pub pitch_deg: f64,
}

/// The largest elevation of the volume camera (short of the y axis, where its frame would
/// lose its right axis).
pub const MAX_PITCH_DEG: f64 = 89.0;

impl VolumeCamera {
    /// The default view of `sketch`: its framing points' bounding box, whole, from 35
    /// degrees right of +z and 25 degrees up.
    pub fn framing(sketch: &Sketch) -> VolumeCamera {
        let (target, radius) = bounds_sphere(&sketch.framing);
        VolumeCamera {
            target,
            distance: radius / (FOV_DEG.to_radians() / 2.0).sin() * 1.05,
            yaw_deg: 35.0,
            pitch_deg: 25.0,
        }
    }

    /// The camera's right, up and backward (from the target to the eye) unit axes.
    pub fn axes(&self) -> (DVec3, DVec3, DVec3) {
        let (yaw, pitch) = (self.yaw_deg.to_radians(), self.pitch_deg.to_radians());
        let back = DVec3::new(
            pitch.cos() * yaw.sin(),
            pitch.sin(),
            pitch.cos() * yaw.cos(),
        );
        let right = DVec3::Y.cross(back).normalize();
        (right, back.cross(right), back)
    }

    /// The eye point.
    pub fn eye(&self) -> DVec3 {
        self.target + self.axes().2 * self.distance
    }

    /// The nearest depth drawn (segments are cut there).
    fn near(&self) -> f64 {
        self.distance * 1e-3
    }

    /// The camera-space (x right, y up, depth ahead) coordinates of `p`.
    fn view(&self, p: DVec3) -> DVec3 {
        let (right, up, back) = self.axes();
        let v = p - self.eye();
        DVec3::new(v.dot(right), v.dot(up), -v.dot(back))
    }

    /// Focal length in pixels for a view `height` pixels high.
    fn focal(height: f64) -> f64 {
        height / 2.0 / (FOV_DEG.to_radians() / 2.0).tan()
    }

    fn to_screen(v: DVec3, size: DVec2) -> DVec2 {
        let f = Self::focal(size.y);
        DVec2::new(size.x / 2.0 + f * v.x / v.z, size.y / 2.0 - f * v.y / v.z)
    }

    /// Where `p` is seen in a view of `size` pixels (x right, y down from the top left);
    /// `None` behind the near depth.
    pub fn project(&self, p: DVec3, size: DVec2) -> Option<DVec2> {
        let v = self.view(p);
        (v.z >= self.near()).then(|| Self::to_screen(v, size))
    }

    /// The segment `a`-`b` on the screen, cut at the near depth; `None` when wholly behind.
    pub fn segment(&self, a: DVec3, b: DVec3, size: DVec2) -> Option<(DVec2, DVec2)> {
        let (mut va, mut vb) = (self.view(a), self.view(b));
        let near = self.near();
        if va.z < near && vb.z < near {
            return None;
        }
        if va.z < near {
            va = va + (vb - va) * ((near - va.z) / (vb.z - va.z));
        } else if vb.z < near {
            vb = vb + (va - vb) * ((near - vb.z) / (va.z - vb.z));
        }
        Some((Self::to_screen(va, size), Self::to_screen(vb, size)))
    }

    /// The world steps of one pixel right and one pixel down in the plane through `at`
    /// facing the camera, for a view `height` pixels high (at the near depth when `at` is
    /// nearer): dragging a point by (dx, dy) pixels moves it by `dx * right + dy * down`,
    /// keeping it under the pointer.
    pub fn pixel_steps(&self, at: DVec3, height: f64) -> (DVec3, DVec3) {
        let depth = self.view(at).z.max(self.near());
        let size = depth / Self::focal(height);
        let (right, up, _) = self.axes();
        (right * size, -up * size)
    }

    /// Orbits by `yaw_deg` about the y axis and `pitch_deg` up (pitch kept within
    /// +-[`MAX_PITCH_DEG`]).
    pub fn orbit(&mut self, yaw_deg: f64, pitch_deg: f64) {
        self.yaw_deg = (self.yaw_deg + yaw_deg) % 360.0;
        self.pitch_deg = (self.pitch_deg + pitch_deg).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
    }

    /// Multiplies the distance to the target by `factor` (ignored unless finite and > 0).
    pub fn zoom(&mut self, factor: f64) {
        if factor.is_finite() && factor > 0.0 {
            self.distance *= factor;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::scratch;

    fn count(sketch: &Sketch, kind: Kind) -> usize {
        sketch.lines.iter().filter(|l| l.0 == kind).count()
    }

    #[test]
    fn a_flexible_volume_is_sketched_from_near_to_far_and_a_camera_to_its_image_plane() {
        let (_dir, session) = scratch(
            "type = \"flexible\"\n\
             near = { surface = \"rectangle\", center = [0.0, 0.0, 1.0], u_axis = [0.5, 0.0, 0.0], v_axis = [0.0, 0.4, 0.0] }\n\
             far = { surface = \"rectangle\", center = [0.0, 0.0, -4.0], u_axis = [3.0, 0.0, 0.0], v_axis = [0.0, 2.0, 0.0] }",
        );
        let (handles, sketch) = volume_of(&session);
        assert_eq!(handles.len(), 6);
        let grid_lines = 2 * SAMPLES * (SAMPLES - 1);
        assert_eq!(count(&sketch, Kind::Projector), SAMPLES * SAMPLES);
        assert_eq!(count(&sketch, Kind::ImageGrid), grid_lines);
        assert_eq!(count(&sketch, Kind::FarGrid), grid_lines);
        // Every projector runs from the near rectangle (z = 1) to the far one (z = -4).
        for &(kind, a, b) in &sketch.lines {
            if kind == Kind::Projector {
                assert!(
                    (a.z - 1.0).abs() < 1e-12 && (b.z + 4.0).abs() < 1e-12,
                    "{a} {b}"
                );
            }
        }
        // The sphere's box and some of its triangles.
        assert!(count(&sketch, Kind::Scene) > 12);

        let (_dir, session) = scratch(
            "type = \"perspective\"\nposition = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 1.0]\nfov = 60.0",
        );
        let (_, sketch) = volume_of(&session);
        assert_eq!(count(&sketch, Kind::Projector), SAMPLES * SAMPLES);
        assert_eq!(count(&sketch, Kind::FarGrid), 0);
        // The image plane grid of a camera lies at its look-at distance (2) from the eye.
        for &(kind, a, _) in &sketch.lines {
            if kind == Kind::ImageGrid {
                assert!(((a - DVec3::new(0.0, 0.0, 3.0)).length() - 2.0).abs() < 1e-12);
            }
        }
    }

    fn camera() -> VolumeCamera {
        VolumeCamera {
            target: DVec3::new(1.0, 2.0, 3.0),
            distance: 10.0,
            yaw_deg: 30.0,
            pitch_deg: 20.0,
        }
    }

    #[test]
    fn the_target_is_at_the_centre_and_a_pixel_step_moves_one_pixel() {
        let c = camera();
        let size = DVec2::new(640.0, 480.0);
        let centre = c.project(c.target, size).unwrap();
        assert!((centre - size / 2.0).length() < 1e-9, "{centre}");
        let p = DVec3::new(2.0, 1.0, 0.5);
        let (right, down) = c.pixel_steps(p, size.y);
        let at = c.project(p, size).unwrap();
        let moved = c.project(p + right * 3.0 + down * -2.0, size).unwrap();
        assert!(
            (moved - at - DVec2::new(3.0, -2.0)).length() < 1e-9,
            "{moved} {at}"
        );
        // The steps lie in the plane facing the camera.
        let (_, _, back) = c.axes();
        assert!(right.dot(back).abs() < 1e-15 && down.dot(back).abs() < 1e-15);
    }

    #[test]
    fn segments_are_cut_at_the_near_depth() {
        let c = camera();
        let size = DVec2::new(100.0, 100.0);
        let eye = c.eye();
        let behind = eye + c.axes().2 * 5.0;
        assert!(c.project(behind, size).is_none());
        assert!(c.segment(behind, behind + c.axes().0, size).is_none());
        // A segment from behind the eye to the target keeps its visible end.
        let (a, b) = c.segment(behind, c.target, size).unwrap();
        assert!((b - size / 2.0).length() < 1e-9);
        assert!(a.is_finite());
    }

    #[test]
    fn the_default_view_frames_the_points_and_orbit_stops_short_of_the_pole() {
        let sketch = Sketch {
            lines: Vec::new(),
            framing: vec![DVec3::new(-1.0, 0.0, -1.0), DVec3::new(1.0, 2.0, 1.0)],
        };
        let mut c = VolumeCamera::framing(&sketch);
        assert_eq!(c.target, DVec3::new(0.0, 1.0, 0.0));
        let size = DVec2::new(480.0, 480.0);
        for p in &sketch.framing {
            let s = c.project(*p, size).unwrap();
            assert!(
                s.x > 0.0 && s.y > 0.0 && s.x < size.x && s.y < size.y,
                "{s}"
            );
        }
        c.orbit(0.0, 500.0);
        assert_eq!(c.pitch_deg, MAX_PITCH_DEG);
        assert!(c.axes().0.is_finite());
        c.zoom(0.0);
        c.zoom(f64::NAN);
        assert_eq!(c.distance, VolumeCamera::framing(&sketch).distance);
    }

    #[test]
    fn an_empty_sketch_frames_the_unit_cube() {
        let c = VolumeCamera::framing(&Sketch::default());
        assert_eq!(c.target, DVec3::splat(0.5));
        assert!(c.distance.is_finite() && c.distance > 0.0);
    }
}
