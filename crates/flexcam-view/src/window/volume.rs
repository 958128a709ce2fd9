//! The window's handle drawing and dragging: the volume view (the sketch of the viewing
//! volume over the scene, projected by the volume camera, its world handles as dots) and
//! the image handles drawn over the image. A drag that starts on a handle moves it through
//! [`Viewer::drag_in`], the same call a script's `drag` makes; elsewhere in the volume view
//! it orbits the volume camera, and the wheel zooms it.

use eframe::egui::{self, Color32, Pos2, Rect, Sense, Stroke};
use flexcam::Result;
use glam::DVec2;

use super::layout::Layout;
use crate::handles::Place;
use crate::viewer::Viewer;
use crate::volume_view::Kind;

/// How near (screen pixels) the pointer must be to a handle to pick it.
const PICK_RADIUS: f32 = 8.0;
/// Degrees of volume-camera orbit per pixel dragged.
const ORBIT_DEG_PER_PX: f64 = 0.4;

fn color(kind: Kind) -> Color32 {
    match kind {
        Kind::Scene => Color32::from_gray(120),
        // Translucent: 81 of them would hide the rest.
        Kind::Projector => Color32::from_rgba_unmultiplied(200, 170, 60, 110),
        Kind::ImageGrid => Color32::from_rgb(90, 170, 255),
        Kind::FarGrid => Color32::from_rgb(120, 120, 210),
        Kind::ControlNet => Color32::from_rgb(255, 140, 40),
    }
}

fn pos(rect: Rect, p: DVec2) -> Pos2 {
    rect.min + egui::vec2(p.x as f32, p.y as f32)
}

/// The handle whose screen position (`points`) is nearest `at`, within [`PICK_RADIUS`].
fn nearest(points: &[(String, Pos2)], at: Option<Pos2>) -> Option<String> {
    let at = at?;
    points
        .iter()
        .map(|(name, p)| (p.distance(at), name))
        .filter(|(d, _)| *d <= PICK_RADIUS)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, name)| name.clone())
}

/// Draws the handles at `points` (the hovered or dragged one highlighted, with its name).
fn draw_handles(painter: &egui::Painter, points: &[(String, Pos2)], hot: Option<&str>) {
    for (name, p) in points {
        let is_hot = hot == Some(name.as_str());
        let fill = if is_hot {
            Color32::from_rgb(255, 70, 70)
        } else {
            Color32::WHITE
        };
        painter.circle(*p, 3.5, fill, Stroke::new(1.0, Color32::BLACK));
        if is_hot {
            painter.text(
                *p + egui::vec2(6.0, -6.0),
                egui::Align2::LEFT_BOTTOM,
                name,
                egui::FontId::proportional(13.0),
                Color32::WHITE,
            );
        }
    }
}

/// Starts, continues or ends a handle drag in `response`; the handle being dragged is
/// `active`. `to_pixels` turns a screen delta into the drag's pixels, `view_height` is what
/// [`Viewer::drag_in`] takes. Returns whether the pointer drags a handle (else the caller's
/// own drag applies) and the drag's result.
fn drag(
    ui: &egui::Ui,
    response: &egui::Response,
    points: &[(String, Pos2)],
    active: &mut Option<String>,
    viewer: &mut Viewer,
    (to_pixels, view_height): (f64, f64),
) -> (bool, Result<()>) {
    if response.drag_started_by(egui::PointerButton::Primary) {
        *active = nearest(points, ui.input(|i| i.pointer.press_origin()));
    }
    let mut result = Ok(());
    let dragging = active.is_some();
    if let Some(name) = active.as_deref() {
        let delta = response.drag_delta();
        if delta != egui::Vec2::ZERO {
            let (dx, dy) = (
                f64::from(delta.x) * to_pixels,
                f64::from(delta.y) * to_pixels,
            );
            result = viewer.drag_in(name, dx, dy, view_height);
        }
    }
    if response.drag_stopped() || !response.dragged() {
        *active = None;
    }
    (dragging, result)
}

/// The volume view filling the rest of `ui`; adds its rectangle and where it draws each
/// handle to `layout`.
pub fn volume_view(
    ui: &mut egui::Ui,
    viewer: &mut Viewer,
    active: &mut Option<String>,
    layout: &mut Layout,
) -> Result<()> {
    let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, Color32::from_gray(18));
    let size = DVec2::new(f64::from(rect.width()), f64::from(rect.height()));
    let camera = *viewer.volume_camera();
    let (handles, sketch) = viewer.volume();
    for &(kind, a, b) in &sketch.lines {
        if let Some((a, b)) = camera.segment(a, b, size) {
            painter.line_segment([pos(rect, a), pos(rect, b)], Stroke::new(1.0, color(kind)));
        }
    }
    let points: Vec<(String, Pos2)> = handles
        .iter()
        .filter_map(|h| match h.place {
            Place::World(p) => Some((h.name.clone(), pos(rect, camera.project(p, size)?))),
            Place::Image(_) => None,
        })
        .collect();
    let (dragging, result) = drag(ui, &response, &points, active, viewer, (1.0, size.y));
    let hot = active
        .clone()
        .or_else(|| nearest(&points, response.hover_pos()));
    draw_handles(&painter, &points, hot.as_deref());
    layout.volume = Some(rect);
    layout.handles.extend(points);
    let delta = response.drag_delta();
    if !dragging && response.dragged_by(egui::PointerButton::Primary) {
        viewer.volume_camera().orbit(
            -f64::from(delta.x) * ORBIT_DEG_PER_PX,
            f64::from(delta.y) * ORBIT_DEG_PER_PX,
        );
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            viewer
                .volume_camera()
                .zoom((-f64::from(scroll) * 0.002).exp());
        }
    }
    result
}

/// The image handles over the image drawn at `rect` (`scale` screen pixels per image pixel),
/// and their drag; adds where it draws them to `layout`. Returns whether a handle is being
/// dragged (then the image's own drag, the orbit, does not apply) and the drag's result.
pub fn image_handles(
    ui: &egui::Ui,
    response: &egui::Response,
    (rect, scale): (Rect, f32),
    viewer: &mut Viewer,
    active: &mut Option<String>,
    layout: &mut Layout,
) -> (bool, Result<()>) {
    let (handles, _) = viewer.volume();
    let points: Vec<(String, Pos2)> = handles
        .iter()
        .filter_map(|h| match h.place {
            Place::Image(p) => Some((h.name.clone(), pos(rect, p * f64::from(scale)))),
            Place::World(_) => None,
        })
        .collect();
    if points.is_empty() {
        return (false, Ok(()));
    }
    let painter = ui.painter_at(rect);
    // The rectangle's outline through its corners (named `rect.corner.K`).
    let corners: Vec<Pos2> = points
        .iter()
        .filter(|(name, _)| name.starts_with("rect.corner."))
        .map(|(_, p)| *p)
        .collect();
    for (k, a) in corners.iter().enumerate() {
        let b = corners[(k + 1) % corners.len()];
        painter.line_segment([*a, b], Stroke::new(1.5, Color32::from_rgb(255, 200, 40)));
    }
    let result = drag(
        ui,
        response,
        &points,
        active,
        viewer,
        (1.0 / f64::from(scale), 0.0),
    );
    let hot = active
        .clone()
        .or_else(|| nearest(&points, response.hover_pos()));
    draw_handles(&painter, &points, hot.as_deref());
    layout.handles.extend(points);
    result
}
