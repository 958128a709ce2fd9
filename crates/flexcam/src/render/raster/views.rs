//! `--method raster` of a projection made of several views (the eyes of a stereo pair, see
//! [`Projection::views`]): each view has one continuous inverse, so each is drawn by its own
//! [`InverseRaster`] and pasted into its tile. A view's [`KeepClear`] region, where its
//! inverse jumps, is checked against every scene triangle first: a scene touching it is
//! refused, never drawn wrong.

use super::InverseRaster;
use crate::error::{Error, Result};
use crate::projection::{KeepClear, Projection};
use crate::render::prepared::PreparedScene;
use crate::render::{Counter, Frame, RenderOptions, Stats};
use crate::scene::Scene;

/// Counters that are settings, equal in every view: reported once, not summed.
const SETTINGS: [&str; 2] = ["raster_uniform", "raster_tolerance_px"];

/// Renders `projection` by the analytic inverse: a single view directly, several view by
/// view (the eyes of a stereo pair, the pieces of a discontinuous flexible projection; the
/// pixels outside every view keep the background). The stats of several views are summed (times and counts), settings kept once.
/// Errors: those of [`InverseRaster::new`] and [`InverseRaster::render`] for any view; a
/// scene triangle touching a view's keep-clear region (one line naming the object and the
/// region); memory that cannot be had for the whole frame.
pub fn render(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
) -> Result<(Frame, Stats)> {
    let views = projection.views();
    if views.is_empty() {
        return InverseRaster::new(prepared, projection, options)?.render();
    }
    // A projection of views without an inverse (a piece without one) is refused whole,
    // with its own reason, before any view is drawn.
    if let Err(none) = projection.inverse() {
        return Err(super::no_inverse(projection.kind(), none));
    }
    let scene = prepared.scene();
    for region in views.iter().filter_map(|v| v.keep_clear) {
        refuse_touching(scene, projection.kind(), &region)?;
    }
    let (width, height) = projection.resolution();
    let mut frame = Frame::try_new(width, height, scene.image.background)?;
    let mut stats = Stats::new();
    for view in &views {
        let (part, part_stats) =
            InverseRaster::new(prepared, view.projection, options)?.render()?;
        paste(&mut frame, &part, view.offset);
        for (name, counter) in part_stats {
            let merged = match (stats.get(name), counter) {
                (Some(_), _) if SETTINGS.contains(&name) => continue,
                (Some(Counter::Count(a)), Counter::Count(b)) => Counter::Count(a + b),
                (Some(Counter::Value(a)), Counter::Value(b)) => Counter::Value(a + b),
                _ => counter,
            };
            stats.insert(name, merged);
        }
    }
    Ok((frame, stats))
}

/// Fails, naming the first object with a triangle touching `region`.
fn refuse_touching(scene: &Scene, kind: &str, region: &KeepClear) -> Result<()> {
    for object in &scene.objects {
        let mesh = &object.mesh;
        let touching = mesh
            .triangles
            .iter()
            .any(|t| region.touches(t.map(|i| mesh.positions[i as usize].as_dvec3())));
        if touching {
            return Err(Error::new(format!(
                "method raster cannot draw object \"{}\" through this {kind} projection: it \
                 touches {}, where the inverse jumps or has no image (move the camera or the \
                 object, or use --method raycast)",
                object.name,
                region.describe()
            )));
        }
    }
    Ok(())
}

/// Copies `part` into `frame` with its top-left pixel at `offset` (the part lies inside);
/// the buffers `part` does not have are left as they are.
fn paste(frame: &mut Frame, part: &Frame, offset: [u32; 2]) {
    let (w, pw) = (frame.width as usize, part.width as usize);
    let [x0, y0] = offset.map(|v| v as usize);
    for row in 0..part.height as usize {
        let to = (y0 + row) * w + x0;
        let from = row * pw;
        frame.color[to..to + pw].copy_from_slice(&part.color[from..from + pw]);
        if !part.depth.is_empty() {
            frame.depth[to..to + pw].copy_from_slice(&part.depth[from..from + pw]);
        }
        if !part.ids.is_empty() {
            frame.ids[to..to + pw].copy_from_slice(&part.ids[from..from + pw]);
        }
    }
}
