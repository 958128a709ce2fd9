//! The `--stats` JSON object.

use flexcam::image_io::OutputSet;
use flexcam::render::{Counter, Stats};
use serde_json::{Map, Number, Value};

/// The fields every `--stats` object has, besides the renderer's own counters.
pub struct RunFacts<'a> {
    pub method: &'a str,
    pub scene: &'a str,
    pub projection: &'a str,
    pub shading: &'a str,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub triangles: usize,
    pub load_ms: f64,
    pub render_ms: f64,
    /// The warnings printed on stderr (the scene's load, the render), one line each.
    pub warnings: &'a [String],
    /// Wall time of the whole command up to the stats, loading and writing included.
    pub wall_ms: f64,
    /// Every file the command writes (the stats file included), as the user named them.
    pub outputs: Vec<String>,
}

/// One JSON object: the run's facts (with the flexcam version and the number of threads
/// rendered with), then the renderer's counters (which never override a
/// fact of the same name).
pub fn to_json(facts: &RunFacts, counters: &Stats) -> Value {
    let mut map = Map::new();
    map.insert("version".into(), env!("CARGO_PKG_VERSION").into());
    map.insert("threads".into(), rayon::current_num_threads().into());
    map.insert("method".into(), facts.method.into());
    map.insert("scene".into(), facts.scene.into());
    map.insert("projection".into(), facts.projection.into());
    map.insert("shading".into(), facts.shading.into());
    map.insert("width".into(), facts.width.into());
    map.insert("height".into(), facts.height.into());
    map.insert("spp".into(), facts.spp.into());
    map.insert("triangles".into(), facts.triangles.into());
    map.insert("load_ms".into(), number(facts.load_ms));
    map.insert("render_ms".into(), number(facts.render_ms));
    map.insert("wall_ms".into(), number(facts.wall_ms));
    map.insert("outputs".into(), facts.outputs.clone().into());
    map.insert("warnings".into(), facts.warnings.into());
    for (name, counter) in counters {
        let value = match *counter {
            Counter::Count(n) => Value::from(n),
            Counter::Value(v) => number(v),
        };
        map.entry(name.to_string()).or_insert(value);
    }
    Value::Object(map)
}

/// The paths of the files `outputs` declares (a stats file among them), for
/// [`RunFacts::outputs`].
pub fn shown(outputs: &OutputSet) -> Vec<String> {
    outputs
        .output_paths()
        .map(|p| p.display().to_string())
        .collect()
}

/// A float as JSON; non-finite values (which JSON cannot hold) become null.
fn number(v: f64) -> Value {
    Number::from_f64(v).map_or(Value::Null, Value::Number)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counters_follow_facts_and_never_override_them() {
        let facts = RunFacts {
            method: "raycast",
            scene: "builtin:cube-floor",
            projection: "perspective",
            shading: "flat",
            width: 4,
            height: 3,
            spp: 1,
            triangles: 686,
            load_ms: 1.0,
            render_ms: 2.5,
            warnings: &["a warning".to_string()],
            wall_ms: 3.0,
            outputs: vec!["out.png".to_string()],
        };
        let mut counters = Stats::new();
        counters.insert("rays_cast", Counter::Count(12));
        counters.insert("width", Counter::Count(99));
        counters.insert("bvh_build_ms", Counter::Value(f64::NAN));
        let v = to_json(&facts, &counters);
        assert_eq!(v["width"], 4);
        assert_eq!(v["rays_cast"], 12);
        assert_eq!(v["render_ms"], 2.5);
        assert!(v["bvh_build_ms"].is_null());
        assert_eq!(v["warnings"], serde_json::json!(["a warning"]));
        assert_eq!(v["outputs"], serde_json::json!(["out.png"]));
        assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
        assert_eq!(v["threads"], rayon::current_num_threads());
    }
}
