//! `flexcam bench simplify`: Table 6.2 of Ramsey 2005 (simplification of
//! arbitrary polygon meshes, Ramsey et al.'s method) with flexcam's simplifier.
//!
//! The dissertation simplified four scanned models with 1 % of the edges searched per
//! collapse and tau = 0.99 (single 2003-era processor). Its models are not available; the
//! rows here are meshes we have: the built-in teapot at several tessellations (32 unwelded
//! patches, so with boundaries), closed tori of quads and of triangles (the larger of
//! scanned-model size), and the repository's OBJ models. Each is simplified to a tenth of its
//! faces (the bunny's ratio) with the dissertation's settings and full-edge collapses; the
//! face count reached is printed, since tau stops curved meshes early.

use std::path::Path;

use clap::Args;
use flexcam::displace::simplify::{closed_torus, simplify, ObjPolygons, PolyMesh, SimplifyOptions};
use flexcam::scene::shapes::teapot;
use flexcam::{Error, Result};

use super::timing::measure;

/// Table 6.2: model, faces in, faces out, seconds.
const DISSERTATION: [(&str, usize, usize, f64); 4] = [
    ("Dragon", 871_414, 48_584, 42.9),
    ("Bunny", 69_451, 6_958, 4.11),
    ("Crocodile", 21_590, 11_695, 3.67),
    ("Venus", 4_254, 711, 0.31),
];

/// Arguments of `flexcam bench simplify`.
#[derive(Args, Debug)]
pub struct SimplifyBenchArgs {
    /// Timed runs per mesh, after one warm-up run; the median is reported.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// Fraction of the faces to simplify to.
    #[arg(long, default_value_t = 0.1)]
    ratio: f64,
}

/// Runs `flexcam bench simplify`.
pub fn run(args: &SimplifyBenchArgs) -> Result<()> {
    if !(0.0..=1.0).contains(&args.ratio) {
        return Err(Error::new(format!(
            "--ratio {} is not a fraction in [0, 1]",
            args.ratio
        )));
    }
    println!("Table 6.2 (dissertation): 1 % of the edges searched per collapse, tau = 0.99");
    println!(
        "{:<28} {:>9} {:>9} {:>9}",
        "model", "faces in", "faces out", "s"
    );
    for (name, faces_in, faces_out, seconds) in DISSERTATION {
        println!("{name:<28} {faces_in:>9} {faces_out:>9} {seconds:>9.2}");
    }
    println!();
    println!(
        "flexcam: the same settings, full-edge collapses, target {} of the faces; median of {} runs",
        args.ratio, args.repeat
    );
    println!(
        "{:<28} {:>9} {:>9} {:>9} {:>7} {:>7}",
        "mesh", "faces in", "faces out", "s", "splits", "sweeps"
    );
    for (name, mesh) in meshes()? {
        let options = SimplifyOptions::to_faces((args.ratio * mesh.face_count() as f64) as usize);
        let (timing, result) = measure(args.repeat, || {
            simplify(&mesh, &options).map_err(|d| Error::new(format!("{name}: {}", Error::from(d))))
        })?;
        println!(
            "{name:<28} {:>9} {:>9} {:>9.3} {:>7} {:>7}",
            mesh.face_count(),
            result.coarse.face_count(),
            timing.median,
            result.splits.len(),
            result.sweeps
        );
    }
    Ok(())
}

/// The meshes of the table, smallest first.
fn meshes() -> Result<Vec<(String, PolyMesh)>> {
    let mut out = Vec::new();
    for file in ["scenes/models/funny-mirror.obj", "scenes/models/lens.obj"] {
        let path = Path::new(file);
        if path.exists() {
            out.push((file.to_string(), ObjPolygons::read(path)?.mesh));
        }
    }
    for tessellation in [16, 32, 64, 128] {
        out.push((
            format!("teapot, tessellation {tessellation}"),
            PolyMesh::from_triangles(&teapot(1.0, tessellation)),
        ));
    }
    out.push((
        "torus, 100 x 50 quads".to_string(),
        closed_torus(1.0, 0.4, 100, 50, false),
    ));
    out.push((
        "torus, 2 x 320 x 160 triangles".to_string(),
        closed_torus(1.0, 0.4, 320, 160, true),
    ));
    Ok(out)
}
