//! What the chapter 8 studies of `flexcam bench trilinear --study` share: rendering one frame
//! by the ray caster and by the trilinear rasteriser side by side in one run, the measures
//! of the second against the first, and the table both are printed as (markdown on stdout,
//! CSV with `--csv`).

use flexcam::projection::Projection;
use flexcam::render::{
    self, compare, interior_id_agreement, Comparison, Counter, CurveOptions, Frame, Method,
    PreparedScene, RenderOptions, Shading, Stats,
};
use flexcam::Result;

use super::super::timing::{measure, Timing};

/// Flat shading, as in the thesis ("no lighting or texture mapping"), by `method` with
/// `curves` (trilinear only); every buffer, for the comparison.
fn options(method: Method, curves: CurveOptions) -> RenderOptions<'static> {
    RenderOptions {
        method,
        shading: Shading::Flat,
        curves,
        ..RenderOptions::default()
    }
}

/// The ray caster's frame of `projection` (the reference), with its [`Timing`].
pub fn reference(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    repeat: u32,
) -> Result<(Timing, Frame)> {
    let options = options(Method::Raycast, CurveOptions::default());
    measure(repeat, || {
        Ok(render::render(prepared, projection, &options)?.frame)
    })
}

/// One trilinear render of a frame measured against the ray caster's.
pub struct Measured {
    /// The trilinear render's timing.
    pub timing: Timing,
    /// Every measure of [`compare`].
    pub comparison: Comparison,
    /// The id agreement away from id edges and the number of such pixels
    /// ([`interior_id_agreement`]).
    pub interior: (f64, u64),
    /// The trilinear renderer's counters (shapes, fallback triangles, ...).
    pub stats: Stats,
}

impl Measured {
    /// The count `name` of the counters, 0 when absent (a renderer that did not reach the
    /// stage that counts it).
    pub fn count(&self, name: &str) -> u64 {
        match self.stats.get(name) {
            Some(Counter::Count(n)) => *n,
            _ => 0,
        }
    }
}

/// Times the trilinear render of `projection` with `curves` and measures its median frame
/// against `reference` (the ray caster's frame of the same projection and size).
pub fn against(
    reference: &Frame,
    prepared: &PreparedScene,
    projection: &dyn Projection,
    curves: CurveOptions,
    repeat: u32,
) -> Result<Measured> {
    let options = options(Method::Trilinear, curves);
    let (timing, rendered) = measure(repeat, || render::render(prepared, projection, &options))?;
    let frame = &rendered.frame;
    let (width, height) = (reference.width, reference.height);
    Ok(Measured {
        timing,
        comparison: compare(frame, reference)?,
        interior: interior_id_agreement(width, height, &frame.ids, &reference.ids)?,
        stats: rendered.counters,
    })
}

/// A study's table: named columns and rows of formatted cells, printed as markdown and
/// written as CSV from the same cells.
pub struct Table {
    columns: &'static [&'static str],
    rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with `columns`.
    pub fn new(columns: &'static [&'static str]) -> Table {
        Table {
            columns,
            rows: Vec::new(),
        }
    }

    /// Appends a row, one cell per column (a bug otherwise: the studies build fixed rows).
    pub fn push(&mut self, row: Vec<String>) {
        assert_eq!(row.len(), self.columns.len(), "{row:?}");
        self.rows.push(row);
    }

    /// The table as markdown.
    pub fn markdown(&self) -> String {
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        let header: Vec<String> = self.columns.iter().map(|c| c.to_string()).collect();
        let mut text = line(&header);
        text += &line(&vec!["---".to_string(); self.columns.len()]);
        for row in &self.rows {
            text += &line(row);
        }
        text
    }

    /// The table as CSV (no cell holds a comma, a quote or a line break: names and numbers).
    pub fn csv(&self) -> String {
        let mut text = self.columns.join(",") + "\n";
        for row in &self.rows {
            text += &(row.join(",") + "\n");
        }
        text
    }
}

/// `value` with `decimals` decimals.
pub fn fixed(value: f64, decimals: usize) -> String {
    format!("{value:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Markdown and CSV show the same cells under the same columns.
    #[test]
    fn table_prints_markdown_and_csv() {
        let mut table = Table::new(&["a", "b"]);
        table.push(vec!["1".into(), fixed(0.123456, 3)]);
        assert_eq!(
            table.markdown(),
            "| a | b |\n| --- | --- |\n| 1 | 0.123 |\n"
        );
        assert_eq!(table.csv(), "a,b\n1,0.123\n");
    }
}
