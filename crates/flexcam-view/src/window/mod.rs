//! The window (eframe / egui on OpenGL): a thin layer over [`Viewer`] that shows its latest
//! frame and the volume view, turns mouse and keys into camera moves, handle drags and
//! parameter edits, and runs a script's lines one per displayed frame (`window OUT.png`
//! takes a screenshot of the whole window).
//!
//! Controls (docs/viewer.md): drag with the left button to orbit, with the right or middle
//! button to pan, scroll to dolly; arrow keys orbit by 5 degrees, with Shift they pan,
//! `+` / `-` dolly; a click picks the object and world point under the pointer; Ctrl+S
//! saves into the scene file. Handles (dots in the volume view, and over the image for a
//! panorama's perspective rectangle) are dragged with the left button.
//!
//! A script's `pointer` and `scroll` lines are raw input events handed to egui before a
//! frame (as the windowing system's would be), so they reach the handlers above through
//! egui's own hit testing; `layout` writes where the last frame drew what they aim at.

mod layout;
mod params;
mod volume;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use eframe::egui;
use flexcam::image_io;
use flexcam::render::{Frame, Method, Shading};
use flexcam::{Error, Result};
use glam::{DVec2, Vec3};

use crate::camera::Navigate;
use crate::script::{self, Button, Command, PointerAction, Script};
use crate::viewer::Viewer;
use layout::Layout;

/// Degrees of orbit per pixel dragged, and per arrow-key press.
const ORBIT_DEG_PER_PX: f64 = 0.3;
const ORBIT_KEY_DEG: f64 = 5.0;
/// The window's least height (room for the parameter panel and the volume view).
const MIN_HEIGHT: f32 = 460.0;
/// The panels' margins and separators, in width.
const MARGINS: f32 = 40.0;
/// The volume view's default width.
const VOLUME_PANEL: f32 = 420.0;
/// How often the scene file's modification time is checked.
const RELOAD_POLL: Duration = Duration::from_millis(500);

/// Opens the window on `viewer` and runs until it is closed, or until `script` (if any) has
/// run its last line. The error of a failing script line, or of a window that cannot open.
pub fn run(viewer: Viewer, script: Option<Script>) -> Result<()> {
    let (width, height) = viewer.session().size();
    let title = format!("flexcam view {}", viewer.session().path().display());
    let outcome: Arc<Mutex<Option<Error>>> = Arc::default();
    let app = App {
        viewer,
        texture: None,
        shown_count: 0,
        status: String::new(),
        message: None,
        save_as: String::new(),
        dragged: [None, None],
        layout: Layout::default(),
        previous_layout: Layout::default(),
        last_poll: Instant::now(),
        script: script.map(|script| ScriptRun {
            script,
            next: 0,
            screenshot: None,
            input: Input::Idle,
        }),
        outcome: Arc::clone(&outcome),
    };
    let panel = 300.0;
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default().with_inner_size([
            (width as f32).min(1280.0) + panel + VOLUME_PANEL + MARGINS,
            ((height as f32).min(800.0) + 60.0).max(MIN_HEIGHT),
        ]),
        ..eframe::NativeOptions::default()
    };
    eframe::run_native(&title, options, Box::new(|_| Ok(Box::new(app))))
        .map_err(|e| Error::new(format!("cannot open the viewer's window: {e}")))?;
    let error = outcome.lock().unwrap_or_else(|e| e.into_inner()).take();
    error.map_or(Ok(()), Err)
}

/// A script being run by the window.
struct ScriptRun {
    script: Script,
    next: usize,
    /// The screenshot asked for by the current `window` line, once it has arrived.
    screenshot: Option<Arc<Mutex<Option<Arc<egui::ColorImage>>>>>,
    /// The input event of the current `pointer` or `scroll` line.
    input: Input,
}

/// Where the input event of a script's `pointer` or `scroll` line is.
enum Input {
    /// None is waiting.
    Idle,
    /// Made, to be handed to egui before the next frame.
    Queued(egui::Event),
    /// Handed to egui: the frame that is being drawn handles it.
    Delivered,
}

struct App {
    viewer: Viewer,
    texture: Option<egui::TextureHandle>,
    shown_count: u64,
    status: String,
    /// The last error (an invalid edit, a failed reload or save) or pick, shown until the next.
    message: Option<String>,
    save_as: String,
    /// The handle being dragged, if any, in the volume view and over the image (each
    /// view's own, so that one view's idle pointer does not end the other's drag).
    dragged: [Option<String>; 2],
    /// Where the frame being drawn put the image, the volume view and the handles, and
    /// where the frame before it did.
    layout: Layout,
    previous_layout: Layout,
    last_poll: Instant,
    script: Option<ScriptRun>,
    outcome: Arc<Mutex<Option<Error>>>,
}

impl eframe::App for App {
    /// Hands a script's `pointer` or `scroll` event to egui, before the frame that handles it.
    fn raw_input_hook(&mut self, ctx: &egui::Context, raw_input: &mut egui::RawInput) {
        let Some(run) = &mut self.script else { return };
        // A script's press and release at one place make a click however long the frames
        // between them take on a loaded machine (egui counts at most 0.8 s by default).
        ctx.options_mut(|o| o.input_options.max_click_duration = f64::INFINITY);
        if let Input::Queued(event) = &run.input {
            raw_input.events.push(event.clone());
            run.input = Input::Delivered;
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.poll_reload();
        self.upload_frame(&ctx);
        self.previous_layout = std::mem::take(&mut self.layout);
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.label(&self.status);
            if let Some(message) = &self.message {
                ui.colored_label(egui::Color32::LIGHT_RED, message);
            }
        });
        egui::Panel::left("parameters")
            .resizable(true)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.side_panel(ui));
            });
        egui::Panel::right("volume")
            .resizable(true)
            .default_size(VOLUME_PANEL)
            .show(ui, |ui| {
                ui.label("Viewing volume: drag a dot to move it, elsewhere to orbit");
                let result = volume::volume_view(
                    ui,
                    &mut self.viewer,
                    &mut self.dragged[0],
                    &mut self.layout,
                );
                self.report_error(result);
            });
        egui::CentralPanel::default().show(ui, |ui| self.image_panel(ui));
        self.keys(&ctx);
        // After the panels: a `pointer` line's event has been handled by this frame.
        self.step_script(&ctx);
        if !self.viewer.render_loop().is_refined() || self.script.is_some() {
            ctx.request_repaint_after(Duration::from_millis(15));
        } else {
            ctx.request_repaint_after(RELOAD_POLL);
        }
    }
}

impl App {
    /// Shows `result`'s error in the window (the last valid state is kept).
    fn report(&mut self, result: Result<()>) {
        match result {
            Ok(()) => self.message = None,
            Err(e) => self.message = Some(e.to_string()),
        }
    }

    /// Shows `result`'s error, if any, leaving an earlier message otherwise.
    fn report_error(&mut self, result: Result<()>) {
        if let Err(e) = result {
            self.message = Some(e.to_string());
        }
    }

    fn poll_reload(&mut self) {
        if self.last_poll.elapsed() < RELOAD_POLL {
            return;
        }
        self.last_poll = Instant::now();
        match self.viewer.reload_if_changed() {
            Ok(true) => self.message = Some("reloaded the scene file".into()),
            Ok(false) => {}
            Err(e) => self.message = Some(format!("reload failed, kept the last scene: {e}")),
        }
    }

    /// Uploads the render loop's latest frame as the image texture, if it changed.
    fn upload_frame(&mut self, ctx: &egui::Context) {
        let (count, shown) = self.viewer.render_loop().shown();
        let Some(shown) = shown else { return };
        let refined = if self.viewer.render_loop().is_refined() {
            "refined"
        } else {
            "refining"
        };
        self.status = format!("{}: {:.1} ms, {refined}", shown.label, shown.ms);
        if count == self.shown_count {
            return;
        }
        self.shown_count = count;
        let size = [shown.width as usize, shown.height as usize];
        let image = egui::ColorImage::from_rgba_unmultiplied(size, &shown.rgba);
        match &mut self.texture {
            Some(texture) => texture.set(image, egui::TextureOptions::LINEAR),
            None => {
                self.texture = Some(ctx.load_texture("frame", image, egui::TextureOptions::LINEAR))
            }
        }
    }

    fn side_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Projection");
        let kind = self.viewer.session().spec().kind();
        let change = self
            .viewer
            .session()
            .document()
            .get("projection")
            .and_then(|item| params::show(ui, kind, "", item));
        if let Some((key, value)) = change {
            let result = self.viewer.set(&key, value);
            self.report(result);
        }
        ui.separator();
        ui.heading("Rendering");
        let mut settings = self.viewer.settings();
        egui::ComboBox::from_label("method")
            .selected_text(settings.method.name())
            .show_ui(ui, |ui| {
                for (name, method) in Method::ALL {
                    ui.selectable_value(&mut settings.method, method, name);
                }
            });
        egui::ComboBox::from_label("shading")
            .selected_text(if settings.shading == Shading::Flat {
                "flat"
            } else {
                "lit"
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut settings.shading, Shading::Lit, "lit");
                ui.selectable_value(&mut settings.shading, Shading::Flat, "flat");
            });
        ui.horizontal(|ui| {
            ui.label("refine spp");
            ui.add(egui::DragValue::new(&mut settings.refine_spp).range(1..=64));
        });
        if settings != self.viewer.settings() {
            self.viewer.set_settings(settings);
        }
        ui.separator();
        if ui.button("Save into the scene file (Ctrl+S)").clicked() {
            self.save(None);
        }
        ui.horizontal(|ui| {
            ui.text_edit_singleline(&mut self.save_as);
            if ui.button("Save as").clicked() && !self.save_as.is_empty() {
                self.save(Some(PathBuf::from(&self.save_as)));
            }
        });
    }

    /// Saves to `to`, or (`None`) into the scene file: a model or built-in scene has none,
    /// and is saved only as a new scene file (*Save as*), never over the model.
    fn save(&mut self, to: Option<PathBuf>) {
        let session = self.viewer.session();
        let Some(out) = to.or_else(|| session.scene_file().map(Path::to_path_buf)) else {
            self.message = Some(format!(
                "{} is not a scene file: save the edited scene as a new .toml file (Save as)",
                session.path().display()
            ));
            return;
        };
        let result = self.viewer.save(&out);
        self.message = Some(match result {
            Ok(()) => format!("saved {}", out.display()),
            Err(e) => e.to_string(),
        });
    }

    fn image_panel(&mut self, ui: &mut egui::Ui) {
        let Some(texture) = &self.texture else {
            ui.label("rendering...");
            return;
        };
        let (width, height) = self.viewer.session().size();
        let available = ui.available_size();
        let scale = (available.x / width as f32)
            .min(available.y / height as f32)
            .min(1.0);
        let size = egui::vec2(width as f32 * scale, height as f32 * scale);
        let (rect, response) = ui.allocate_exact_size(size, egui::Sense::click_and_drag());
        self.layout.image = Some(rect);
        let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        ui.painter()
            .image(texture.id(), rect, uv, egui::Color32::WHITE);
        let (on_handle, result) = volume::image_handles(
            ui,
            &response,
            (rect, scale),
            &mut self.viewer,
            &mut self.dragged[1],
            &mut self.layout,
        );
        self.report_error(result);
        // A drag that moves a handle does not also orbit or pan.
        let delta = if on_handle {
            egui::Vec2::ZERO
        } else {
            response.drag_delta()
        };
        if response.dragged_by(egui::PointerButton::Primary) && delta != egui::Vec2::ZERO {
            let (dx, dy) = (f64::from(delta.x), f64::from(delta.y));
            let result = self
                .viewer
                .move_camera(|c| c.orbit(-dx * ORBIT_DEG_PER_PX, dy * ORBIT_DEG_PER_PX));
            self.report(result);
        } else if (response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle))
            && delta != egui::Vec2::ZERO
        {
            let (dx, dy) = (f64::from(delta.x / size.x), f64::from(delta.y / size.y));
            let result = self.viewer.move_camera(|c| c.pan(-dx, dy));
            self.report(result);
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                let result = self
                    .viewer
                    .move_camera(|c| c.dolly((-f64::from(scroll) * 0.002).exp()));
                self.report(result);
            }
        }
        if response.clicked() {
            if let Some(pos) = response.interact_pointer_pos() {
                let pixel = (pos - rect.min) / scale;
                self.pick(DVec2::new(f64::from(pixel.x), f64::from(pixel.y)));
            }
        }
    }

    /// Shows what pixel position `pixel` sees; a script run also prints it on standard
    /// output (one line), so that a scripted click can be checked.
    fn pick(&mut self, pixel: DVec2) {
        let message = match self.viewer.session().pick(pixel) {
            Ok(Some(p)) => format!(
                "pixel ({:.0}, {:.0}): object {} \"{}\" at ({:.4}, {:.4}, {:.4})",
                pixel.x, pixel.y, p.id, p.name, p.point.x, p.point.y, p.point.z
            ),
            Ok(None) => format!("pixel ({:.0}, {:.0}): background", pixel.x, pixel.y),
            Err(e) => e.to_string(),
        };
        if self.script.is_some() {
            println!("{message}");
        }
        self.message = Some(message);
    }

    fn keys(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let (shift, ctrl) = ctx.input(|i| (i.modifiers.shift, i.modifiers.command));
        let pressed = |key| ctx.input(|i| i.key_pressed(key));
        if ctrl && pressed(egui::Key::S) {
            self.save(None);
            return;
        }
        let arrows = [
            (egui::Key::ArrowLeft, -1.0, 0.0),
            (egui::Key::ArrowRight, 1.0, 0.0),
            (egui::Key::ArrowUp, 0.0, 1.0),
            (egui::Key::ArrowDown, 0.0, -1.0),
        ];
        for (key, x, y) in arrows {
            if pressed(key) {
                let result = if shift {
                    self.viewer.move_camera(|c| c.pan(x * 0.05, y * 0.05))
                } else {
                    self.viewer
                        .move_camera(|c| c.orbit(x * ORBIT_KEY_DEG, y * ORBIT_KEY_DEG))
                };
                self.report(result);
            }
        }
        for (key, factor) in [(egui::Key::Plus, 0.9), (egui::Key::Minus, 1.0 / 0.9)] {
            if pressed(key) {
                let result = self.viewer.move_camera(|c| c.dolly(factor));
                self.report(result);
            }
        }
    }

    /// Runs the script's next line (one per displayed frame, so that each `window` shows
    /// the state the lines before it made), and closes the window after the last.
    fn step_script(&mut self, ctx: &egui::Context) {
        let Some(run) = &mut self.script else { return };
        let Some(line) = run.script.lines.get(run.next).cloned() else {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        };
        let result = match &line.command {
            Command::Window(out) => match &run.screenshot {
                None => {
                    // The refined frame must be on screen first.
                    if let Err(e) = self.viewer.idle() {
                        Err(e)
                    } else if self.shown_count != self.viewer.render_loop().shown().0 {
                        return;
                    } else {
                        let slot: Arc<Mutex<Option<Arc<egui::ColorImage>>>> = Arc::default();
                        let filled = Arc::clone(&slot);
                        let repaint = ctx.clone();
                        ctx.request_screenshot(move |image| {
                            *filled.lock().unwrap_or_else(|e| e.into_inner()) = Some(image);
                            repaint.request_repaint();
                        });
                        run.screenshot = Some(slot);
                        return;
                    }
                }
                Some(slot) => {
                    let Some(image) = slot.lock().unwrap_or_else(|e| e.into_inner()).take() else {
                        return;
                    };
                    run.screenshot = None;
                    write_screenshot(&image, out)
                }
            },
            &Command::Pointer {
                action,
                x,
                y,
                button,
            } => {
                let event = pointer_event(ctx, action, (x, y), button);
                let Some(done) = input_step(run, ctx, event) else {
                    return;
                };
                done
            }
            &Command::Scroll(dy) => {
                let Some(done) = input_step(run, ctx, scroll_event(dy)) else {
                    return;
                };
                done
            }
            // The panels settle over a frame or two (egui sizes them from the frame before).
            Command::Layout(_) if self.layout != self.previous_layout => return,
            Command::Layout(out) => self.layout.write(ctx.pixels_per_point(), out),
            command => script::run_line(&mut self.viewer, command),
        };
        let Some(run) = &mut self.script else { return };
        run.next += 1;
        if let Err(e) = result {
            *self.outcome.lock().unwrap_or_else(|e| e.into_inner()) =
                Some(run.script.error_at(&line, &e));
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}

/// Steps a script's `pointer` or `scroll` line whose event is `event`: queues it for the
/// next frame, then waits for the frame that handled it (and, for a wheel's turn, which
/// egui spreads over frames, until all of it has been handled). `None` while waiting.
fn input_step(run: &mut ScriptRun, ctx: &egui::Context, event: egui::Event) -> Option<Result<()>> {
    match run.input {
        Input::Idle => {
            run.input = Input::Queued(event);
            ctx.request_repaint();
            None
        }
        Input::Queued(_) => None,
        Input::Delivered if ctx.input(|i| i.is_scrolling()) => None,
        Input::Delivered => {
            run.input = Input::Idle;
            Some(Ok(()))
        }
    }
}

/// The egui event of a `pointer` line at window pixel `(x, y)` (made points).
fn pointer_event(
    ctx: &egui::Context,
    action: PointerAction,
    (x, y): (f64, f64),
    button: Button,
) -> egui::Event {
    let scale = ctx.pixels_per_point();
    let pos = egui::pos2(x as f32 / scale, y as f32 / scale);
    let button = match button {
        Button::Left => egui::PointerButton::Primary,
        Button::Right => egui::PointerButton::Secondary,
        Button::Middle => egui::PointerButton::Middle,
    };
    match action {
        PointerAction::Move => egui::Event::PointerMoved(pos),
        PointerAction::Press | PointerAction::Release => egui::Event::PointerButton {
            pos,
            button,
            pressed: action == PointerAction::Press,
            modifiers: egui::Modifiers::NONE,
        },
    }
}

/// The egui event of a `scroll` line: the wheel turned by `dy` points.
fn scroll_event(dy: f64) -> egui::Event {
    egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, dy as f32),
        phase: egui::TouchPhase::Move,
        modifiers: egui::Modifiers::NONE,
        source: egui::MouseWheelSource::Wheel,
    }
}

/// Writes a screenshot as an 8-bit RGB PNG (alpha dropped): each byte goes through the
/// linear encoding unchanged (round(255 * v / 255) = v).
fn write_screenshot(image: &egui::ColorImage, out: &std::path::Path) -> Result<()> {
    let [width, height] = image.size;
    let mut frame = Frame::try_new(width as u32, height as u32, Vec3::ZERO)?;
    for (pixel, color) in frame.color.iter_mut().zip(&image.pixels) {
        *pixel = Vec3::new(
            f32::from(color.r()),
            f32::from(color.g()),
            f32::from(color.b()),
        ) / 255.0;
    }
    let mut outputs = image_io::OutputSet::new();
    let id = outputs.output("the screenshot", out, &["png"])?;
    outputs.stage(id, |tmp| {
        image_io::write_color_png(&frame, tmp, image_io::ColorEncoding::Linear)
    })?;
    outputs.commit()
}
