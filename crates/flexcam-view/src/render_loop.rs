//! The viewer's render loop: a background thread that renders each new state of the session
//! first by the fastest method that supports its projection, then refines it, progressively,
//! while nothing changes.
//!
//! A job (a prepared scene, a projection and the view's settings) goes through a ladder of
//! stages ([`stages`]):
//! 1. a preview by the fast method: `trilinear` for trilinear projections, `raster` for
//!    projections with an analytic inverse, otherwise the ray caster at a reduced size; a
//!    raster preview is drawn at the size that fits one 60 Hz display frame
//!    ([`PREVIEW_BUDGET_MS`], judged by the last raster preview's time per pixel), and
//!    when that is reduced, again at full size as the next stage;
//! 2. the final frame: the view's method at the scene's size and samples per pixel, the frame
//!    `flexcam render` draws with the same method, shading and `--spp`;
//! 3. a supersampled ray-cast refinement, for the window only, when the view's method is the
//!    ray caster and `refine_spp` is above its samples per pixel.
//!
//! Each stage after the first starts once the job has been the newest for [`SETTLE`] more
//! (a drag's next edit makes it stale first). Submitting a new job cancels the running one:
//! ray-cast stages see the projection through [`Cancellable`], which answers "no projector"
//! to every pixel once the job is stale, so a cancelled stage ends at the cost of a loop over
//! the remaining pixels; other stages run to their (short) end. A stale stage's frame is dropped. The renderers run on rayon's pool,
//! never on the caller's thread, so a window stays responsive during a refinement.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use flexcam::image_io::{ByteEncoder, ColorEncoding, RgbEncoder};
use flexcam::projection::{
    AnalyticInverse, NoInverse, Projection, ProjectionSpec, Projector, ProjectorHull, Trilinear,
    View,
};
use flexcam::render::{self, Frame, Method, Outputs, PreparedScene, RenderOptions, Shading};
use flexcam::{try_alloc, Error, Result};
use glam::DVec2;
use rayon::prelude::*;

/// How the view renders: the final method, shading and samples per pixel (those of the
/// `flexcam render` the final frame matches) and the supersampling of the idle refinement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    pub method: Method,
    pub shading: Shading,
    pub spp: u32,
    /// Samples per pixel of the window's last refinement (ray caster only); no refinement
    /// stage at or below `spp`.
    pub refine_spp: u32,
    /// Raster previews always at the scene's image size, never reduced to fit a display
    /// frame (`flexcam bench view --full-size`: the frame rate of full-size frames).
    pub full_size_previews: bool,
}

impl Settings {
    /// The view's defaults: the ray caster, lit, one sample per pixel (as `flexcam render`),
    /// refined with 4 samples per pixel when idle.
    pub const DEFAULT: Settings = Settings {
        method: Method::Raycast,
        shading: Shading::Lit,
        spp: 1,
        refine_spp: 4,
        full_size_previews: false,
    };
}

/// One state of the session to render.
pub struct Job {
    /// Grows with every job submitted ([`crate::Session::generation`]).
    pub generation: u64,
    pub prepared: Arc<PreparedScene>,
    pub spec: ProjectionSpec,
    pub projection: Arc<dyn Projection>,
    pub settings: Settings,
}

/// A stage of the ladder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// The fast method; `scale` divides the scene's image sides (1 = full size).
    Preview { method: Method, scale: u32 },
    /// The view's method at the scene's size and samples per pixel.
    Final,
    /// The ray caster at `spp` samples per pixel.
    Refine { spp: u32 },
}

impl Stage {
    /// A short description for a status line.
    pub fn describe(self, settings: &Settings) -> String {
        match self {
            Stage::Preview { method, scale: 1 } => format!("preview, {method}"),
            Stage::Preview { method, scale } => format!("preview, {method} at 1/{scale} size"),
            Stage::Final => format!("{}, {} spp", settings.method, settings.spp),
            Stage::Refine { spp } => format!("raycast, {spp} spp, supersampled"),
        }
    }
}

/// A frame rendered by one stage, ready for display.
#[derive(Clone)]
pub struct Shown {
    pub generation: u64,
    pub stage: Stage,
    pub label: String,
    /// Wall time of the stage's render, in milliseconds.
    pub ms: f64,
    pub width: u32,
    pub height: u32,
    /// 8-bit RGBA, rows from the top, encoded as the PNG of the same shading would be.
    pub rgba: Arc<Vec<u8>>,
}

/// The stages a job goes through, in order (see the module docs); `raster_ms_per_pixel` is
/// the wall time per pixel of the last raster preview of the loop, if any.
pub fn stages(
    projection: &dyn Projection,
    settings: &Settings,
    raster_ms_per_pixel: Option<f64>,
) -> Vec<Stage> {
    let mut ladder = Vec::new();
    if settings.method == Method::Raycast {
        let method = fast_method(projection);
        let scale = match method {
            Method::Raycast => preview_scale(projection.resolution()),
            Method::Raster if settings.full_size_previews => 1,
            Method::Raster => budget_scale(projection.resolution(), raster_ms_per_pixel),
            _ => 1,
        };
        ladder.push(Stage::Preview { method, scale });
        if scale > 1 && method != Method::Raycast {
            ladder.push(Stage::Preview { method, scale: 1 });
        }
    }
    ladder.push(Stage::Final);
    if settings.method == Method::Raycast && settings.refine_spp > settings.spp {
        ladder.push(Stage::Refine {
            spp: settings.refine_spp,
        });
    }
    ladder
}

/// The fastest method that renders `projection`.
pub fn fast_method(projection: &dyn Projection) -> Method {
    if projection.trilinear().is_some() {
        Method::Trilinear
    } else if projection.inverse().is_ok() {
        Method::Raster
    } else {
        Method::Raycast
    }
}

/// The divisor of the image sides for a ray-cast preview: the smallest that leaves at most
/// [`PREVIEW_PIXELS`] pixels.
fn preview_scale((width, height): (u32, u32)) -> u32 {
    let pixels = u64::from(width) * u64::from(height);
    (1..=16)
        .find(|s| pixels / (s * s) <= PREVIEW_PIXELS)
        .map_or(16, |s| s as u32)
}

/// The most pixels of a ray-cast preview (a quarter of 1280 x 720).
const PREVIEW_PIXELS: u64 = 230_400;

/// The wall time a raster preview aims at: one frame of a 60 Hz display, so that a drag
/// keeps up with the pointer.
pub const PREVIEW_BUDGET_MS: f64 = 1000.0 / 60.0;

/// The largest raster preview divisor of the image sides: half size still shows the
/// composition being designed, and below it the scene's fixed costs per frame (projecting
/// every vertex, building the pieces) rather than the pixels set the time.
const MAX_BUDGET_SCALE: u32 = 2;

/// The divisor of the image sides for a raster preview: the smallest (1 to
/// [`MAX_BUDGET_SCALE`]) whose pixels, at `ms_per_pixel` each, fit [`PREVIEW_BUDGET_MS`];
/// 1 before any raster preview was timed. A time per pixel measured on a reduced frame
/// carries that frame's fixed costs (the scene's vertices are projected whatever the size),
/// so it overestimates a larger frame: the scale errs towards smaller previews. At the
/// largest divisor a preview may still miss the budget (fixed costs that do not shrink).
fn budget_scale((width, height): (u32, u32), ms_per_pixel: Option<f64>) -> u32 {
    let Some(cost) = ms_per_pixel.filter(|c| c.is_finite() && *c > 0.0) else {
        return 1;
    };
    let pixels = f64::from(width) * f64::from(height);
    (1..=MAX_BUDGET_SCALE)
        .find(|&s| cost * pixels / f64::from(s * s) <= PREVIEW_BUDGET_MS)
        .unwrap_or(MAX_BUDGET_SCALE)
}

/// The render loop: a worker thread and what it shares with its owner.
pub struct RenderLoop {
    shared: Arc<Shared>,
    worker: Option<JoinHandle<()>>,
}

struct Shared {
    state: Mutex<State>,
    changed: Condvar,
    /// The newest job's generation (read by [`Cancellable`] without the lock).
    newest: AtomicU64,
}

#[derive(Default)]
struct State {
    job: Option<Arc<Job>>,
    /// The last frame rendered for display (of the newest job, or of an older one until the
    /// newest has its first).
    shown: Option<Shown>,
    /// The final stage's frame of the newest job, once rendered.
    final_frame: Option<(u64, Arc<Frame>)>,
    /// The generation whose ladder is complete, and the error that ended it, if any.
    done: Option<(u64, Option<Error>)>,
    /// Changes whenever `shown` does (for a display to see that it must upload).
    shown_count: u64,
    /// Wall milliseconds per pixel of the last raster preview (see [`budget_scale`]).
    raster_ms_per_pixel: Option<f64>,
    quit: bool,
}

impl Default for RenderLoop {
    fn default() -> Self {
        RenderLoop::new()
    }
}

impl RenderLoop {
    /// Starts the worker thread (idle until the first job).
    pub fn new() -> RenderLoop {
        let shared = Arc::new(Shared {
            state: Mutex::new(State::default()),
            changed: Condvar::new(),
            newest: AtomicU64::new(0),
        });
        let worker_shared = Arc::clone(&shared);
        let worker = std::thread::Builder::new()
            .name("flexcam-view render".into())
            .spawn(move || work(&worker_shared))
            .expect("spawning the render thread");
        RenderLoop {
            shared,
            worker: Some(worker),
        }
    }

    /// Renders `job` from now on, cancelling the job in progress.
    pub fn submit(&self, job: Job) {
        let mut state = self.shared.lock();
        self.shared.newest.store(job.generation, Ordering::SeqCst);
        state.job = Some(Arc::new(job));
        state.final_frame = None;
        self.shared.changed.notify_all();
    }

    /// The latest frame for display and a number that changes whenever it does.
    pub fn shown(&self) -> (u64, Option<Shown>) {
        let state = self.shared.lock();
        (state.shown_count, state.shown.clone())
    }

    /// Whether the newest job's ladder is complete.
    pub fn is_refined(&self) -> bool {
        let state = self.shared.lock();
        matches!(&state.done, Some((g, _)) if Some(*g) == state.job.as_ref().map(|j| j.generation))
    }

    /// Waits until the newest job's ladder is complete; its error, if a stage failed.
    pub fn wait_refined(&self) -> Result<()> {
        let mut state = self.shared.lock();
        loop {
            let newest = state.job.as_ref().map(|j| j.generation);
            if let Some((generation, error)) = &state.done {
                if Some(*generation) == newest {
                    return error.clone().map_or(Ok(()), Err);
                }
            }
            if newest.is_none() {
                return Ok(());
            }
            state = self.shared.wait(state);
        }
    }

    /// Waits for the first frame shown of job `generation` (its preview, or its final frame
    /// when it has no preview); the error that ended its ladder before any frame.
    pub fn wait_shown(&self, generation: u64) -> Result<Shown> {
        let mut state = self.shared.lock();
        loop {
            if let Some(shown) = state.shown.as_ref().filter(|s| s.generation == generation) {
                return Ok(shown.clone());
            }
            if let Some((done, error)) = &state.done {
                if *done == generation {
                    return Err(error
                        .clone()
                        .unwrap_or_else(|| Error::new("the job showed no frame")));
                }
            }
            if self.shared.is_stale(generation) {
                return Err(Error::new("a newer job replaced the one waited for"));
            }
            state = self.shared.wait(state);
        }
    }

    /// Waits for the newest job's final frame (the frame `flexcam render` draws).
    pub fn final_frame(&self) -> Result<Arc<Frame>> {
        let mut state = self.shared.lock();
        loop {
            let newest = state.job.as_ref().map(|j| j.generation);
            if let Some((generation, frame)) = &state.final_frame {
                if Some(*generation) == newest {
                    return Ok(Arc::clone(frame));
                }
            }
            if let Some((generation, Some(error))) = &state.done {
                if Some(*generation) == newest {
                    return Err(error.clone());
                }
            }
            if newest.is_none() {
                return Err(Error::new("nothing rendered yet"));
            }
            state = self.shared.wait(state);
        }
    }
}

impl Drop for RenderLoop {
    fn drop(&mut self) {
        self.shared.lock().quit = true;
        self.shared.newest.fetch_add(1, Ordering::SeqCst);
        self.shared.changed.notify_all();
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn wait<'a>(&self, guard: MutexGuard<'a, State>) -> MutexGuard<'a, State> {
        self.changed.wait(guard).unwrap_or_else(|e| e.into_inner())
    }

    fn is_stale(&self, generation: u64) -> bool {
        self.newest.load(Ordering::SeqCst) != generation
    }

    /// Waits up to `time` for a job newer than `job` (or the loop's end); whether one came.
    fn superseded_within(&self, job: &Job, time: Duration) -> bool {
        let deadline = Instant::now() + time;
        let mut state = self.lock();
        loop {
            if state.quit || self.is_stale(job.generation) {
                return true;
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return false;
            }
            state = (self.changed.wait_timeout(state, left))
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }
}

/// How long a job's later stages wait after its first frame is shown, for an edit that
/// would make them stale: while something is dragged the next edit comes within a few
/// milliseconds of a shown frame, and a final ray-cast stage started in between would only
/// be cancelled, after allocating its frame and tracing rays on every core the next
/// preview needs. Small against the later stages themselves (a final frame of a 1280 x 720
/// view takes hundreds of milliseconds).
const SETTLE: Duration = Duration::from_millis(40);

/// The worker thread: takes the newest job and runs its ladder, stage by stage, until a
/// newer job arrives or the loop is dropped.
fn work(shared: &Shared) {
    let mut last_started = 0;
    loop {
        let job = {
            let mut state = shared.lock();
            loop {
                if state.quit {
                    return;
                }
                match &state.job {
                    Some(job) if job.generation != last_started => break Arc::clone(job),
                    _ => state = shared.wait(state),
                }
            }
        };
        last_started = job.generation;
        let error = run_ladder(shared, &job).err();
        let mut state = shared.lock();
        if !shared.is_stale(job.generation) {
            state.done = Some((job.generation, error));
            shared.changed.notify_all();
        }
    }
}

/// Runs the stages of `job`, publishing each frame; stops early when the job goes stale. A
/// failed preview is skipped (the final stage says what the method refuses); a failed final
/// stage ends the ladder with its error.
fn run_ladder(shared: &Shared, job: &Job) -> Result<()> {
    let raster_ms_per_pixel = shared.lock().raster_ms_per_pixel;
    for (k, stage) in stages(job.projection.as_ref(), &job.settings, raster_ms_per_pixel)
        .into_iter()
        .enumerate()
    {
        if shared.is_stale(job.generation) || (k > 0 && shared.superseded_within(job, SETTLE)) {
            return Ok(());
        }
        let start = Instant::now();
        let rendered = render_stage(shared, job, stage);
        let ms = start.elapsed().as_secs_f64() * 1e3;
        if shared.is_stale(job.generation) {
            return Ok(());
        }
        let frame = match (rendered, stage) {
            (Ok(frame), _) => Arc::new(frame),
            (Err(_), Stage::Preview { .. }) => continue,
            (Err(e), _) => return Err(e),
        };
        let shown = Shown {
            generation: job.generation,
            stage,
            label: stage.describe(&job.settings),
            ms,
            width: frame.width,
            height: frame.height,
            rgba: Arc::new(rgba(&frame, job.settings.shading)?),
        };
        let mut state = shared.lock();
        if let Stage::Preview {
            method: Method::Raster,
            ..
        } = stage
        {
            let pixels = f64::from(frame.width) * f64::from(frame.height);
            state.raster_ms_per_pixel = Some(ms / pixels.max(1.0));
        }
        if stage == Stage::Final {
            state.final_frame = Some((job.generation, frame));
        } else if let Ok(frame) = Arc::try_unwrap(frame) {
            // Shown and no longer needed: the next raster preview draws into its memory.
            render::recycle_frame(&job.prepared, frame);
        }
        state.shown = Some(shown);
        state.shown_count += 1;
        shared.changed.notify_all();
    }
    Ok(())
}

/// Renders one stage of `job` (colour only).
fn render_stage(shared: &Shared, job: &Job, stage: Stage) -> Result<Frame> {
    let settings = &job.settings;
    let (method, spp, outputs) = match stage {
        // Depth and ids too (the raster draws them anyway), so that the frame comes back
        // whole to the raster's next preview ([`render::recycle_frame`]).
        Stage::Preview {
            method: Method::Raster,
            ..
        } => (Method::Raster, 1, Outputs::ALL),
        Stage::Preview { method, .. } => (method, 1, Outputs::COLOR),
        Stage::Final => (settings.method, settings.spp, Outputs::COLOR),
        Stage::Refine { spp } => (Method::Raycast, spp, Outputs::COLOR),
    };
    let options = RenderOptions {
        method,
        shading: settings.shading,
        spp,
        outputs,
        ..RenderOptions::default()
    };
    let reduced;
    let projection: &dyn Projection = match stage {
        Stage::Preview { scale, .. } if scale > 1 => {
            let (width, height) = job.projection.resolution();
            let (built, _) = flexcam::calibrate::build(
                &job.spec,
                (width / scale).max(1),
                (height / scale).max(1),
            )?;
            reduced = built;
            reduced.as_ref()
        }
        _ => job.projection.as_ref(),
    };
    let rendered = if method == Method::Raycast {
        let cancellable = Cancellable {
            inner: projection,
            shared,
            generation: job.generation,
        };
        render::render(&job.prepared, &cancellable, &options)
    } else {
        render::render(&job.prepared, projection, &options)
    };
    rendered.map(|r| r.frame)
}

/// 8-bit RGBA of `frame`'s colour, encoded as a PNG of `shading` is (the same bytes, by
/// [`ByteEncoder`]), rows in parallel. Fails when its memory cannot be had.
pub fn rgba(frame: &Frame, shading: Shading) -> Result<Vec<u8>> {
    let encoder = ByteEncoder::of(ColorEncoding::of_shading(shading));
    let mut bytes = Vec::new();
    try_alloc::resize(&mut bytes, frame.color.len() * 4, 0, || {
        format!("the shown {} x {} image", frame.width, frame.height)
    })?;
    let row = (frame.width as usize).max(1);
    bytes
        .par_chunks_mut(row * 4)
        .zip(frame.color.par_chunks(row))
        .for_each(|(out, colors)| {
            let mut encoder = RgbEncoder::new(encoder);
            for (out, &c) in out.chunks_exact_mut(4).zip(colors) {
                let [r, g, b] = encoder.rgb(c);
                out.copy_from_slice(&[r, g, b, 255]);
            }
        });
    Ok(bytes)
}

/// A projection that sees nothing once its job is stale: lets a running ray-cast stage end
/// early. Until then it is the inner projection exactly (same rays, same bounds), so an
/// uncancelled stage renders what the inner projection renders.
struct Cancellable<'a> {
    inner: &'a dyn Projection,
    shared: &'a Shared,
    generation: u64,
}

impl Cancellable<'_> {
    fn live(&self) -> bool {
        !self.shared.is_stale(self.generation)
    }
}

impl Projection for Cancellable<'_> {
    fn kind(&self) -> &'static str {
        self.inner.kind()
    }

    fn resolution(&self) -> (u32, u32) {
        self.inner.resolution()
    }

    fn ray(&self, pixel: DVec2) -> Option<flexcam::geometry::Ray> {
        self.inner.ray(pixel).filter(|_| self.live())
    }

    fn projector(&self, pixel: DVec2) -> Option<Projector> {
        self.inner.projector(pixel).filter(|_| self.live())
    }

    fn projector_into(&self, pixel: DVec2, out: &mut Option<Projector>) {
        if self.live() {
            self.inner.projector_into(pixel, out);
        } else {
            *out = None;
        }
    }

    fn projector_hull(&self, lo: DVec2, hi: DVec2) -> Option<ProjectorHull> {
        self.inner.projector_hull(lo, hi)
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        self.inner.inverse()
    }

    /// The inner projection's views, not cancellable themselves.
    fn views(&self) -> Vec<View<'_>> {
        self.inner.views()
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        self.inner.trilinear()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexcam::projection::CameraFrame;
    use glam::DVec3;

    fn perspective(width: u32, height: u32) -> Arc<dyn Projection> {
        let frame = CameraFrame {
            position: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        };
        let projection = ProjectionSpec::Perspective { frame, fov: 60.0 }
            .build(width, height)
            .unwrap();
        Arc::from(projection)
    }

    /// The smallest divisor that fits the budget; full size before anything was timed, and
    /// for a time that is no time (zero, negative, not finite); at most the cap.
    #[test]
    fn raster_previews_shrink_to_fit_one_display_frame() {
        let size = (1280, 720);
        let pixels = 1280.0 * 720.0;
        let per_pixel = |ms: f64| Some(ms / pixels);
        assert_eq!(budget_scale(size, None), 1);
        assert_eq!(budget_scale(size, per_pixel(10.0)), 1);
        assert_eq!(budget_scale(size, per_pixel(PREVIEW_BUDGET_MS)), 1);
        assert_eq!(budget_scale(size, per_pixel(20.0)), 2);
        assert_eq!(budget_scale(size, per_pixel(4.0 * PREVIEW_BUDGET_MS)), 2);
        assert_eq!(budget_scale(size, per_pixel(84.0)), MAX_BUDGET_SCALE);
        assert_eq!(budget_scale(size, per_pixel(1e6)), MAX_BUDGET_SCALE);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(budget_scale(size, Some(bad)), 1, "{bad}");
        }
        // A one-pixel image is never divided below the budget it already fits.
        assert_eq!(budget_scale((1, 1), per_pixel(84.0)), 1);
    }

    /// A reduced raster preview is followed by the full-size one, then the final frame and
    /// the refinement; a preview that fits stays alone at full size.
    #[test]
    fn a_reduced_preview_is_followed_by_the_full_size_one() {
        let projection = perspective(1280, 720);
        let settings = Settings::DEFAULT;
        let slow = Some(84.0 / (1280.0 * 720.0));
        let raster = |scale| Stage::Preview {
            method: Method::Raster,
            scale,
        };
        assert_eq!(
            stages(projection.as_ref(), &settings, slow),
            vec![raster(2), raster(1), Stage::Final, Stage::Refine { spp: 4 }]
        );
        assert_eq!(
            stages(projection.as_ref(), &settings, None),
            vec![raster(1), Stage::Final, Stage::Refine { spp: 4 }]
        );
        // Another final method has no preview to shrink.
        let direct = Settings {
            method: Method::Raster,
            ..settings
        };
        assert_eq!(
            stages(projection.as_ref(), &direct, slow),
            vec![Stage::Final]
        );
        // Full-size previews stay full size however slow the last one was.
        let full = Settings {
            full_size_previews: true,
            ..settings
        };
        assert_eq!(
            stages(projection.as_ref(), &full, slow),
            vec![raster(1), Stage::Final, Stage::Refine { spp: 4 }]
        );
    }

    /// The render loop times each raster preview (for the next job's scale).
    #[test]
    fn the_loop_times_raster_previews() {
        let scene = flexcam::scene::builtin::load("cube-floor").unwrap();
        let prepared = Arc::new(PreparedScene::new(&scene));
        let render_loop = RenderLoop::new();
        let frame = CameraFrame {
            position: DVec3::new(0.0, 5.5, 7.0),
            look_at: DVec3::new(0.0, 0.4, 0.0),
            up: DVec3::Y,
        };
        let spec = ProjectionSpec::Perspective { frame, fov: 50.0 };
        let projection: Arc<dyn Projection> = Arc::from(spec.build(64, 48).unwrap());
        render_loop.submit(Job {
            generation: 1,
            prepared: Arc::clone(&prepared),
            spec: spec.clone(),
            projection,
            settings: Settings::DEFAULT,
        });
        let shown = render_loop.wait_shown(1).unwrap();
        assert_eq!(
            shown.stage,
            Stage::Preview {
                method: Method::Raster,
                scale: 1
            }
        );
        render_loop.wait_refined().unwrap();
        let timed = render_loop.shared.lock().raster_ms_per_pixel;
        assert!(timed.is_some_and(|t| t > 0.0), "{timed:?}");
    }
}
