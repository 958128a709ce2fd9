//! `flexcam simplify`: simplify a polygon mesh (OBJ, n-gons kept) by edge collapses.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use flexcam::displace::simplify::{
    simplify, write_obj, CollapseKind, ObjPolygons, SimplifyOptions,
};
use flexcam::image_io::{self, OutputSet};
use flexcam::{Error, Result};
use serde_json::{json, Value};

use crate::OutputTarget;

/// Arguments of `flexcam simplify`.
#[derive(Args, Debug)]
pub struct SimplifyArgs {
    /// The OBJ mesh to simplify (faces of any number of corners; an oriented manifold).
    input: PathBuf,
    /// The simplified mesh to write (OBJ).
    #[arg(short, long)]
    output: PathBuf,
    /// Stop at this many faces (or sooner where no edge may collapse).
    #[arg(long, value_name = "N", conflicts_with = "ratio")]
    faces: Option<usize>,
    /// Stop at this fraction of the input's faces (default 0.1).
    #[arg(long, value_name = "R")]
    ratio: Option<f64>,
    /// Largest angle in degrees by which a collapse may turn a face's normal (the
    /// dissertation's cosine 0.99).
    #[arg(long, value_name = "DEG", default_value_t = 0.99f32.acos().to_degrees())]
    threshold: f32,
    /// Fraction of the edges drawn as candidates for each collapse.
    #[arg(long, value_name = "F", default_value_t = 0.01)]
    candidates: f32,
    /// Collapse into the edge's midpoint (`full`) or into one of its ends (`half`).
    #[arg(long, value_enum, default_value_t = CollapseArg::Full)]
    collapse: CollapseArg,
    /// Seed of the random candidate draws.
    #[arg(long, value_name = "S", default_value_t = 1)]
    seed: u64,
    /// Write statistics as one JSON object to FILE, or to standard output with `-`.
    #[arg(long, value_name = "FILE|-")]
    stats: Option<OutputTarget>,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum CollapseArg {
    Full,
    Half,
}

/// Runs `flexcam simplify`.
pub fn run(args: &SimplifyArgs) -> Result<()> {
    let mut outputs = OutputSet::new();
    outputs.input("the input mesh", &args.input)?;
    let output = outputs.output("the output", &args.output, &["obj"])?;
    let stats = match &args.stats {
        Some(OutputTarget::File(path)) => {
            Some(outputs.output("the stats output", path, &["json", "txt", ""])?)
        }
        _ => None,
    };
    let options = options(args)?;
    let start = Instant::now();
    let obj = ObjPolygons::read(&args.input)?;
    let read_ms = start.elapsed().as_secs_f64() * 1e3;
    let faces_in = obj.mesh.face_count();
    let target = match (args.faces, args.ratio) {
        (Some(n), _) => n,
        (None, ratio) => (ratio.unwrap_or(0.1) * faces_in as f64).round() as usize,
    };
    let options = SimplifyOptions {
        target_faces: target,
        ..options
    };
    let start = Instant::now();
    let simplified =
        simplify(&obj.mesh, &options).map_err(|d| obj.defect_error(&args.input, &d))?;
    let simplify_ms = start.elapsed().as_secs_f64() * 1e3;
    let coarse = &simplified.coarse;
    outputs.stage(output, |tmp| {
        let mut bytes = Vec::new();
        write_obj(coarse, &mut bytes).map_err(|e| Error::in_file(tmp, e.to_string()))?;
        image_io::write_bytes(tmp, &bytes)
    })?;
    let json: Value = json!({
        "input": args.input.display().to_string(),
        "faces_in": faces_in,
        "vertices_in": obj.mesh.vertex_count(),
        "faces_out": coarse.face_count(),
        "vertices_out": coarse.vertex_count(),
        "target_faces": target,
        "splits": simplified.splits.len(),
        "sweeps": simplified.sweeps,
        "collapse": match args.collapse { CollapseArg::Full => "full", CollapseArg::Half => "half" },
        "threshold_degrees": decimal(args.threshold),
        "candidate_fraction": decimal(args.candidates),
        "seed": args.seed,
        "dropped_attributes": obj.dropped,
        "read_ms": read_ms,
        "simplify_ms": simplify_ms,
    });
    super::commit_with_stats(outputs, stats, args.stats.as_ref(), &json.to_string())
}

/// The options the flags give, target aside; refuses values out of range.
fn options(args: &SimplifyArgs) -> Result<SimplifyOptions> {
    if !(args.threshold > 0.0 && args.threshold <= 180.0) {
        return Err(Error::new(format!(
            "--threshold {} is not an angle in (0, 180] degrees",
            args.threshold
        )));
    }
    if !(args.candidates > 0.0 && args.candidates <= 1.0) {
        return Err(Error::new(format!(
            "--candidates {} is not a fraction in (0, 1]",
            args.candidates
        )));
    }
    if let Some(r) = args.ratio {
        if !(0.0..=1.0).contains(&r) {
            return Err(Error::new(format!(
                "--ratio {r} is not a fraction in [0, 1]"
            )));
        }
    }
    Ok(SimplifyOptions {
        threshold_degrees: args.threshold,
        candidate_fraction: args.candidates,
        collapse: match args.collapse {
            CollapseArg::Full => CollapseKind::Full,
            CollapseArg::Half => CollapseKind::Half,
        },
        seed: args.seed,
        ..SimplifyOptions::to_faces(0)
    })
}

/// An `f32` flag value as the decimal it was typed as (0.01, not 0.009999999776482582).
fn decimal(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::NAN)
}
