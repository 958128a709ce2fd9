//! `flexcam bench trilinear --study`: each chapter 8 study runs end to end at a tiny size,
//! prints its table and writes the same table as CSV, with agreement figures that say the
//! trilinear rasteriser draws what the ray caster does (timings are not checked: they
//! belong to benches).

use std::collections::HashMap;
use std::path::Path;

use tempfile::TempDir;

mod common;
use common::{run, run_ok};

/// The scenes folder of the repository.
fn scenes() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .to_string_lossy()
        .into_owned()
}

/// Runs `--study study` at width `size` with one timed render per cell, and returns the CSV's rows
/// as column -> cell maps, after checking the header and that stdout prints the same
/// columns as a markdown table.
fn study(study: &str, size: u32, extra: &[&str], columns: &[&str]) -> Vec<HashMap<String, String>> {
    table("--study", study, size, extra, columns)
}

/// As [`study`], for `flag` (`--study` or `--sweep`) with value `study`.
fn table(
    flag: &str,
    study: &str,
    size: u32,
    extra: &[&str],
    columns: &[&str],
) -> Vec<HashMap<String, String>> {
    let dir = TempDir::new().unwrap();
    let scenes = scenes();
    let size = size.to_string();
    let mut args = vec!["bench", "trilinear", flag, study, "--size", &size];
    args.extend_from_slice(&["--repeat", "1", "--scenes", &scenes, "--csv", "t.csv"]);
    args.extend_from_slice(extra);
    let stdout = String::from_utf8(run_ok(&dir, &args).stdout).unwrap();
    let text = std::fs::read_to_string(dir.path().join("t.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header, columns, "{study}");
    assert!(
        stdout.contains(&format!("| {} |", columns.join(" | "))),
        "{study}: {stdout}"
    );
    let rows: Vec<HashMap<String, String>> = lines
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            assert_eq!(cells.len(), header.len(), "{line}");
            header
                .iter()
                .zip(cells)
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect()
        })
        .collect();
    // Every CSV row is a row of the printed table.
    for row in &rows {
        let first = format!("| {} | {} |", row[columns[0]], row[columns[1]]);
        assert!(stdout.contains(&first), "{study}: {first}");
    }
    rows
}

fn number(row: &HashMap<String, String>, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column}: {:?}", row[column]))
}

#[test]
fn examples_table_has_every_row_of_table_8_1() {
    let columns = [
        "figure",
        "scene",
        "width",
        "height",
        "projections",
        "raycast_ms",
        "trilinear_ms",
        "speedup",
        "raycast_cpu_ms",
        "trilinear_cpu_ms",
        "cpu_speedup",
        "ids_interior",
        "ids",
        "depth_mean",
        "depth_max",
        "rgb_error",
        "thesis_projections",
        "thesis_ray_ms",
        "thesis_trilinear_ms",
        "thesis_speedup",
    ];
    let rows = study("examples", 64, &[], &columns);
    let figures: Vec<&str> = rows.iter().map(|r| r["figure"].as_str()).collect();
    assert_eq!(
        figures,
        [
            "6.4",
            "6.7",
            "6.9",
            "7.4 (b)",
            "7.4 (c)",
            "7.4 (d)",
            "7.4 (e)",
            "7.4 (f)",
            "7.4 (sphere)",
            "7.5",
            "7.6 (b)",
            "7.6 (c)",
            "7.6 (d)",
            "7.6 (e)",
            "7.6 (f)"
        ]
    );
    for row in &rows {
        let what = format!("{row:?}");
        // The size asked for, the thesis's aspect kept (900 x 300 for 6.7).
        assert_eq!(row["width"], "64", "{what}");
        let height = if row["figure"] == "6.7" { "21" } else { "64" };
        assert_eq!(row["height"], height, "{what}");
        assert!(number(row, "projections") >= 2.0, "{what}");
        assert!(number(row, "ids_interior") >= 0.99, "{what}");
        assert!(number(row, "ids") >= 0.9, "{what}");
        assert!(number(row, "rgb_error") < 0.05, "{what}");
        assert!(number(row, "raycast_ms") > 0.0 && number(row, "trilinear_ms") > 0.0);
    }
    // The swept rows have the thesis's 2 n^2 projections: the mirror ball's grid and the
    // lens cells.
    for (k, n) in (1..=5).enumerate() {
        for first in [3, 10] {
            let row = &rows[first + k];
            assert_eq!(number(row, "projections"), f64::from(2 * n * n), "{row:?}");
            assert_eq!(row["thesis_projections"], row["projections"], "{row:?}");
        }
    }
}

#[test]
fn configurations_are_drawn_by_their_shapes() {
    let columns = [
        "configuration",
        "pixels",
        "shapes",
        "fallback_triangles",
        "fallback_rays",
        "raycast_ms",
        "trilinear_ms",
        "speedup",
        "ids_interior",
        "interior_pixels",
        "ids",
        "rgb_error",
        "thesis_ray_ms",
        "thesis_trilinear_ms",
    ];
    let rows = study("configurations", 48, &[], &columns);
    let names: Vec<&str> = rows.iter().map(|r| r["configuration"].as_str()).collect();
    assert_eq!(
        names,
        ["2-2-2-3", "2-7", "3-3-3", "4-2-3", "4-5", "6-3", "9"]
    );
    for row in &rows {
        let what = format!("{row:?}");
        assert_eq!(row["pixels"], "2304", "{what}");
        assert!(number(row, "shapes") >= 1.0, "{what}");
        assert_eq!(row["fallback_triangles"], "0", "{what}");
        assert_eq!(row["fallback_rays"], "0", "{what}");
        assert!(number(row, "interior_pixels") > 0.0, "{what}");
        assert!(number(row, "ids_interior") >= 0.99, "{what}");
    }
}

#[test]
fn tessellation_factors_converge_on_the_ray_caster() {
    let columns = [
        "configuration",
        "mode",
        "factor",
        "pixels",
        "trilinear_ms",
        "raycast_ms",
        "rgb_error",
        "ids_interior",
        "depth_mean",
        "thesis_ms",
        "thesis_rgb_error",
    ];
    let rows = study("tessellation", 48, &["--quick"], &columns);
    // 7 configurations and their mean, 2 modes, factors 1, 10 and 100.
    assert_eq!(rows.len(), 8 * 2 * 3);
    let mean = |mode: &str, factor: &str| {
        let row = rows
            .iter()
            .find(|r| r["configuration"] == "mean" && r["mode"] == mode && r["factor"] == factor)
            .unwrap_or_else(|| panic!("no mean row {mode} {factor}"));
        (number(row, "rgb_error"), number(row, "thesis_rgb_error"))
    };
    for mode in ["tessellate", "slice"] {
        let (coarse, thesis_coarse) = mean(mode, "1");
        let (fine, thesis_fine) = mean(mode, "100");
        // At 48 x 48 the edge pixels weigh much more than at the thesis's 640 x 640.
        assert!(fine <= coarse, "{mode}: {coarse} -> {fine}");
        assert!(fine < 0.03, "{mode}: {fine}");
        assert!(thesis_fine < thesis_coarse, "{mode}");
    }
    for row in rows.iter().filter(|r| r["configuration"] != "mean") {
        assert!(number(row, "ids_interior") >= 0.9, "{row:?}");
    }
}

const SWEEP_COLUMNS: [&str; 13] = [
    "n",
    "projections",
    "width",
    "height",
    "trilinear_ms",
    "raycast_ms",
    "ids_interior",
    "interior_pixels",
    "rgb_error",
    "shapes",
    "split_pairs",
    "fallback_triangles",
    "thesis_ms",
];

/// Figure 7.4's sweep: the mirror ball's N x N grid against the exact mirror ball, N = 1, 4
/// and 16 at 96 x 72 pixels: the relative RGB error falls with N (about as 1 / N^2: more
/// than 20 times from 1 to 16) and the ids agree away from id edges ever more; the mirror
/// rays never cross, so nothing is ray cast.
#[test]
fn reflection_sweep_converges_on_the_exact_mirror_ball() {
    let rows = table("--sweep", "reflection", 96, &["--quick"], &SWEEP_COLUMNS);
    let ns: Vec<&str> = rows.iter().map(|r| r["n"].as_str()).collect();
    assert_eq!(ns, ["1", "4", "16"]);
    let errors: Vec<f64> = rows.iter().map(|r| number(r, "rgb_error")).collect();
    assert!(errors[1] < errors[0] && errors[2] < errors[1], "{errors:?}");
    assert!(errors[2] < errors[0] / 20.0, "{errors:?}");
    let ids: Vec<f64> = rows.iter().map(|r| number(r, "ids_interior")).collect();
    assert!(ids[0] <= ids[2] && ids[2] >= 0.995, "{ids:?}");
    for (row, n) in rows.iter().zip([1.0, 4.0, 16.0]) {
        assert_eq!(number(row, "projections"), 2.0 * n * n, "{row:?}");
        assert_eq!(
            (row["width"].as_str(), row["height"].as_str()),
            ("96", "72")
        );
        assert_eq!(row["fallback_triangles"], "0", "{row:?}");
        assert!(number(row, "interior_pixels") > 1000.0, "{row:?}");
    }
    assert_eq!(rows[0]["thesis_ms"], "24.4");
    assert_eq!(rows[2]["thesis_ms"], "-");
}

/// The refraction sweep: the glass ball's grid against the exact glass ball; the error falls
/// with N, and the pairs reaching across a depth where the rays of a projection triangle
/// cross inside the scene are split there and counted, none ray cast.
#[test]
fn refraction_sweep_converges_on_the_exact_glass_ball() {
    let rows = table("--sweep", "refraction", 96, &["--quick"], &SWEEP_COLUMNS);
    let errors: Vec<f64> = rows.iter().map(|r| number(r, "rgb_error")).collect();
    assert!(
        errors[2] < errors[1] && errors[2] < errors[0] / 5.0,
        "{errors:?}"
    );
    assert!(number(&rows[2], "ids_interior") >= 0.99, "{rows:?}");
    let split: f64 = rows.iter().map(|r| number(r, "split_pairs")).sum();
    assert!(split > 0.0, "{rows:?}");
    let fallback: f64 = rows.iter().map(|r| number(r, "fallback_triangles")).sum();
    assert_eq!(fallback, 0.0, "{rows:?}");
}

/// `--csv` and `--size` need a study or a sweep, and a study and a sweep do not go together.
#[test]
fn csv_needs_one_table() {
    let dir = TempDir::new().unwrap();
    for args in [
        &["bench", "trilinear", "--csv", "t.csv"][..],
        &["bench", "trilinear", "--size", "64"],
        &[
            "bench",
            "trilinear",
            "--study",
            "examples",
            "--sweep",
            "reflection",
        ],
    ] {
        let out = run(&dir, args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(!dir.path().join("t.csv").exists());
    }
}

/// A scenes folder without the study's scenes fails with one line naming the missing file,
/// and no CSV is written.
#[test]
fn a_missing_scene_fails_and_writes_nothing() {
    let dir = TempDir::new().unwrap();
    let out = run(
        &dir,
        &[
            "bench",
            "trilinear",
            "--study",
            "configurations",
            "--scenes",
            "nowhere",
            "--csv",
            "t.csv",
        ],
    );
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("2-2-2-3.toml"), "{stderr}");
    assert!(!dir.path().join("t.csv").exists());
}
