//! The parameter panel: every key of the scene's `[projection]` table as a typed widget
//! (numbers as drag values within their valid ranges, presets as a choice, vectors as rows
//! of numbers, nested tables as collapsible sections). A change is returned as the key and
//! its new value for the viewer to apply.

use std::ops::RangeInclusive;

use eframe::egui;
use flexcam::projection::flexible::presets::PRESET_NAMES;
use toml_edit::{Item, Value};

/// The valid range of a number key of projection type `kind` (`variant`: its `preset` or
/// fisheye `mapping`), where the scene format bounds it (angles in degrees, as
/// [`crate::ranges::angle`]); unbounded otherwise.
fn range(kind: &str, variant: Option<&str>, key: &str) -> RangeInclusive<f64> {
    if let Some([low, high]) = crate::ranges::angle(kind, variant, key) {
        return low..=high;
    }
    match key {
        "width" => 1e-6..=f64::MAX,
        // The axonometric view has no up at +-90 degrees.
        "elevation" => -89.9..=89.9,
        "corner_radius" => 0.0..=1.0,
        _ => f64::MIN..=f64::MAX,
    }
}

/// The drag speed of a number: a fraction of its size, at least a small step.
fn speed(value: f64) -> f64 {
    (value.abs() * 0.005).max(0.001)
}

/// Shows the widgets of `table` (the projection table, or a table in it at `prefix`) and
/// returns the first change made this frame.
pub fn show(ui: &mut egui::Ui, kind: &str, prefix: &str, item: &Item) -> Option<(String, Value)> {
    let table = item.as_table_like()?;
    // The projection table's preset or fisheye mapping, which some ranges depend on.
    let variant = ["preset", "mapping"]
        .into_iter()
        .find_map(|key| table.get(key)?.as_str());
    shown(ui, kind, variant, prefix, table)
}

/// [`show`] of `table` with its projection's `variant`.
fn shown(
    ui: &mut egui::Ui,
    kind: &str,
    variant: Option<&str>,
    prefix: &str,
    table: &dyn toml_edit::TableLike,
) -> Option<(String, Value)> {
    let mut change = None;
    for (key, item) in table.iter() {
        let path = if prefix.is_empty() {
            key.to_string()
        } else {
            format!("{prefix}.{key}")
        };
        let edited = if item.is_table_like() {
            egui::CollapsingHeader::new(key)
                .id_salt(&path)
                .show(ui, |ui| {
                    shown(ui, kind, variant, &path, item.as_table_like()?)
                })
                .body_returned
                .flatten()
        } else if let Some(value) = item.as_value() {
            ui.horizontal(|ui| {
                ui.label(key);
                value_widget(ui, key, range(kind, variant, key), value)
            })
            .inner
            .map(|v| (path, v))
        } else {
            // An array of tables (projector nodes, keyframes): listed, edited in the file.
            ui.label(format!(
                "{key}: {} entries",
                item.as_array_of_tables().map_or(0, |a| a.len())
            ));
            None
        };
        change = change.or(edited);
    }
    change
}

/// The widget of one value; its new value when changed.
fn value_widget(
    ui: &mut egui::Ui,
    key: &str,
    range: RangeInclusive<f64>,
    value: &Value,
) -> Option<Value> {
    match value {
        Value::Float(f) => {
            let mut v = *f.value();
            let step = speed(v);
            let r = ui.add(
                egui::DragValue::new(&mut v)
                    .speed(step)
                    .range(range.clone()),
            );
            r.changed().then(|| Value::from(v))
        }
        Value::Integer(i) => {
            let mut v = *i.value();
            ui.add(egui::DragValue::new(&mut v))
                .changed()
                .then(|| Value::from(v))
        }
        Value::Boolean(b) => {
            let mut v = *b.value();
            ui.checkbox(&mut v, "").changed().then(|| Value::from(v))
        }
        Value::String(s) if key == "preset" => {
            let mut chosen = s.value().clone();
            egui::ComboBox::from_id_salt(key)
                .selected_text(chosen.as_str())
                .show_ui(ui, |ui| {
                    for name in PRESET_NAMES {
                        ui.selectable_value(&mut chosen, name.to_string(), name);
                    }
                });
            (chosen != *s.value()).then(|| Value::from(chosen))
        }
        Value::String(s) => {
            ui.label(format!("\"{}\"", s.value()));
            None
        }
        Value::Array(array) => {
            let numbers: Option<Vec<f64>> = array
                .iter()
                .map(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
                .collect();
            match numbers {
                Some(mut numbers) if numbers.len() <= 4 => {
                    let mut changed = false;
                    for v in &mut numbers {
                        let step = speed(*v);
                        let value = egui::DragValue::new(v).speed(step).range(range.clone());
                        changed |= ui.add(value).changed();
                    }
                    changed.then(|| flexcam::scene::file::edit::float_array(&numbers))
                }
                _ => {
                    ui.label(format!("{} values", array.len()));
                    None
                }
            }
        }
        Value::InlineTable(_) | Value::Datetime(_) => {
            ui.label(value.to_string());
            None
        }
    }
}
