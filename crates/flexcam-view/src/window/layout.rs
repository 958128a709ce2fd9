//! The window's layout, as a script's `layout` line writes it.

use std::path::Path;

use eframe::egui::{Pos2, Rect};
use flexcam::image_io::OutputSet;
use flexcam::{Error, Result};

/// Where a frame drew the image, the volume view and the handles (window points): what a
/// script's `layout` line writes, so that its `pointer` lines can aim at them.
#[derive(Debug, Default, PartialEq)]
pub struct Layout {
    pub image: Option<Rect>,
    pub volume: Option<Rect>,
    pub handles: Vec<(String, Pos2)>,
}

impl Layout {
    /// The text of a `layout` file at `pixels_per_point`: `image X0 Y0 X1 Y1`, `volume X0
    /// Y0 X1 Y1` (the rectangles' corners) and `handle NAME X Y`, in window pixels.
    fn text(&self, pixels_per_point: f32) -> String {
        let px = |v: f32| v * pixels_per_point;
        let mut text = String::new();
        for (name, rect) in [("image", self.image), ("volume", self.volume)] {
            if let Some(r) = rect {
                text += &format!(
                    "{name} {} {} {} {}\n",
                    px(r.min.x),
                    px(r.min.y),
                    px(r.max.x),
                    px(r.max.y)
                );
            }
        }
        for (name, p) in &self.handles {
            text += &format!("handle {name} {} {}\n", px(p.x), px(p.y));
        }
        text
    }

    /// Writes [`Layout::text`] at `out` (as every output is written: whole or not at all).
    pub fn write(&self, pixels_per_point: f32, out: &Path) -> Result<()> {
        let text = self.text(pixels_per_point);
        let mut outputs = OutputSet::new();
        let id = outputs.output("the layout", out, &["txt"])?;
        outputs.stage(id, |tmp| {
            std::fs::write(tmp, &text)
                .map_err(|e| Error::new(format!("cannot write {}: {e}", out.display())))
        })?;
        outputs.commit()
    }
}
