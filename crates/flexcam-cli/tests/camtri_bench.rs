//! End-to-end tests of `flexcam bench camera-triangles` at a tiny image size: Table 1 with its
//! caustics row, Figure 6 (quality per camera mesh size) and Figure 7 (frames per second
//! without and with acceleration) print their rows and write their CSV; the CSV's values are
//! those of the printed table; bad arguments are one error line.

use std::fs;

use tempfile::TempDir;

mod common;
use common::{run, run_ok};

/// The repository's scene folder.
fn scenes() -> String {
    format!("{}/../../scenes", env!("CARGO_MANIFEST_DIR"))
}

/// Runs the bench at 64 x 48 with one timed render per row and `extra` arguments; its
/// standard output.
fn bench(dir: &TempDir, extra: &[&str]) -> String {
    let scenes = scenes();
    let mut args = vec![
        "bench",
        "camera-triangles",
        "--repeat",
        "1",
        "--width",
        "64",
        "--height",
        "48",
        "--scenes",
        &scenes,
    ];
    args.extend_from_slice(extra);
    String::from_utf8(run_ok(dir, &args).stdout).unwrap()
}

/// The cells of the markdown table rows of `text` that start with `first`.
fn table_rows<'a>(text: &'a str, first: &str) -> Vec<Vec<&'a str>> {
    text.lines()
        .filter(|l| l.starts_with(&format!("| {first} |")))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect()
}

/// The CSV at `path`: its header and rows, split at commas.
fn csv(path: &std::path::Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| l.split(',').map(String::from).collect());
    (lines.next().unwrap(), lines.collect())
}

/// The numbers of Table 1's row `name` (an application scene) in the bench's output:
/// camera and scene triangles, bounding and rendered fragments, overdraw, ms, fps, cpu ms,
/// then the paper's six; checks that there are fragments and that the overdraw is bounding
/// over rendered.
fn application_row(out: &str, name: &str) -> Vec<f64> {
    let (_, section) = out
        .split_once(&format!("Table 1, {name}"))
        .unwrap_or_else(|| panic!("no {name} row: {out}"));
    let row: Vec<f64> = section
        .lines()
        .nth(2)
        .unwrap()
        .split(['|', ' '])
        .filter_map(|c| c.parse().ok())
        .collect();
    assert_eq!(row.len(), 14, "{section}");
    assert!(row[3] > 0.0 && row[2] >= row[3], "{section}");
    assert!((row[4] - row[2] / row[3]).abs() < 0.01, "{section}");
    row
}

/// Table 1: three reflection tessellations x two bounds x culling off and on, the caustics
/// row with its photon map's camera triangles and an overdraw that is bounding over
/// rendered, the visualisation row's 400 camera triangles around the walker, and the
/// 5,000-triangle target's rows.
#[test]
fn table_1_has_reflection_caustics_and_visualisation_rows() {
    let dir = TempDir::new().unwrap();
    let out = bench(&dir, &[]);
    let reflection = out
        .lines()
        .filter(|l| l.contains(" paper ") || l.contains(" tight "))
        .count();
    assert_eq!(reflection, 12, "{out}");
    let caustics = application_row(&out, "caustics");
    assert!(caustics[0] > 0.0, "camera triangles: {out}");
    assert!(caustics[7] > 0.0, "cpu ms: {out}");
    assert_eq!(&caustics[8..], [400.0, 2.0, 945962.0, 475852.0, 2.0, 35.0]);
    let visualisation = application_row(&out, "visualization");
    // The 400 camera triangles around the walker (6,864 triangles) and the floor (2).
    assert_eq!(&visualisation[..2], [400.0, 6866.0], "{out}");
    assert_eq!(
        &visualisation[8..],
        [400.0, 6841.0, 213248.0, 213248.0, 1.0, 46.0]
    );
    mirror_sphere_rows(&out);
}

/// The 5,000-triangle mirror sphere's table: one row per camera mesh, each with camera
/// triangles, overdraw, ms and its ratio, cpu ms and its ratio, the agreement over its
/// pixels, then over those without self-reflection (at most as many) and the RGB error.
fn mirror_sphere_rows(out: &str) {
    let (_, sphere) = out
        .split_once("Mirror sphere (80 triangles) over 5012 scene triangles")
        .unwrap_or_else(|| panic!("no mirror sphere: {out}"));
    assert!(sphere.contains("cpu ms"), "{sphere}");
    for name in ["own mesh", "refined 8 px", "automatic"] {
        let row = sphere
            .lines()
            .find_map(|l| l.trim_start().strip_prefix(name))
            .unwrap_or_else(|| panic!("no {name} row: {sphere}"));
        let n: Vec<f64> = row
            .split(['|', ' '])
            .filter_map(|c| c.parse().ok())
            .collect();
        assert_eq!(n.len(), 11, "{name}: {row}");
        assert!(n[0] > 0.0 && n[1] >= 1.0, "{name}: {row}");
        for agreement in [n[6], n[8]] {
            assert!((0.0..=1.0).contains(&agreement), "{name}: {row}");
        }
        assert!(n[9] <= n[7], "{name}: {row}");
    }
}

/// Figure 6: every reflector scene gets the series 8, 16, ... up to its own triangle count
/// and the automatic size, and a ray-cast line; the CSV holds the sized rows with the
/// table's values; the finest mesh agrees better with the exact mirror than the coarsest.
#[test]
fn figure_6_prints_the_series_and_writes_its_csv() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("out/figure6.csv");
    let out = bench(&dir, &["--figure", "6", "--csv", path.to_str().unwrap()]);
    let (header, rows) = csv(&path);
    assert_eq!(
        header,
        [
            "scene",
            "camera_mesh",
            "camera_triangles",
            "agreement",
            "rgb_error",
            "uncovered_pixels",
            "ms"
        ]
    );
    for (scene, own) in [
        ("reflection", 960),
        ("camtri-convex", 528),
        ("camtri-mixed", 2048),
    ] {
        let table = table_rows(&out, scene);
        let sizes: Vec<&str> = table.iter().map(|r| r[1]).collect();
        let mut want: Vec<String> = (3..)
            .map(|p| 1usize << p)
            .take_while(|&n| n < own)
            .map(|n| n.to_string())
            .collect();
        want.push(own.to_string());
        want.push("auto".into());
        want.push(format!("exact mirror (raycast, {own} triangles)"));
        assert_eq!(sizes, want, "{out}");
        let sized: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == scene).collect();
        assert_eq!(sized.len(), want.len() - 2, "{scene}");
        for (csv_row, table_row) in sized.iter().zip(&table) {
            assert_eq!(csv_row[1], table_row[1]);
            assert_eq!(csv_row[2], table_row[2]);
            let agreement: f64 = csv_row[3].parse().unwrap();
            assert!((agreement - table_row[3].parse::<f64>().unwrap()).abs() < 1e-4);
            assert!((0.0..=1.0).contains(&agreement));
        }
        let rgb = |r: &Vec<String>| r[4].parse::<f64>().unwrap();
        assert!(
            rgb(sized.last().unwrap()) < rgb(sized[0]),
            "{scene}: the finest mesh is not better than the coarsest: {out}"
        );
    }
}

/// Figure 7: the paper's eight cells with the paper's frame rates, each without and with
/// acceleration; culling bounds fewer pairs; the CSV has a line per cell and acceleration.
#[test]
fn figure_7_prints_the_grid_with_and_without_acceleration() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("figure7.csv");
    let out = bench(&dir, &["--figure", "7", "--csv", path.to_str().unwrap()]);
    let cells: Vec<Vec<&str>> = out
        .lines()
        .filter(|l| l.starts_with("| ") && l[2..].starts_with(|c: char| c.is_ascii_digit()))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect();
    let grid: Vec<(&str, &str)> = cells.iter().map(|c| (c[0], c[1])).collect();
    assert_eq!(
        grid,
        [
            ("802", "100"),
            ("1202", "100"),
            ("1602", "100"),
            ("402", "256"),
            ("802", "256"),
            ("1202", "256"),
            ("402", "512"),
            ("802", "512"),
        ],
        "{out}"
    );
    for cell in &cells {
        let pairs = |i: usize| cell[i].parse::<u64>().unwrap();
        assert!(pairs(9) < pairs(5), "culling bounds fewer pairs: {cell:?}");
    }
    assert_eq!((cells[0][14], cells[0][15]), ("4.5", "20.1"));
    let uncovered = |cell: &Vec<&str>| cell[12].parse::<u64>().unwrap();
    let teapot = |cell: &Vec<&str>| cell[13].parse::<u64>().unwrap();
    // A finer camera mesh leaves fewer teapot pixels uncovered.
    assert!(uncovered(&cells[6]) < uncovered(&cells[3]), "{out}");
    assert!(uncovered(&cells[3]) < uncovered(&cells[0]), "{out}");
    assert!(cells.iter().all(|c| uncovered(c) < teapot(c)), "{out}");
    let (header, rows) = csv(&path);
    assert_eq!(header[3], "acceleration");
    assert_eq!(rows.len(), 16);
    assert_eq!((rows[0][3].as_str(), rows[1][3].as_str()), ("off", "on"));
}

/// The standard error of a run that must fail (without a panic).
fn failure(dir: &TempDir, args: &[&str]) -> String {
    let out = run(dir, args);
    assert!(!out.status.success(), "expected failure for {args:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

/// Bad arguments are refused (clap's usage message), and a missing scene folder is one line
/// naming the file, with no CSV written.
#[test]
fn bad_bench_arguments_are_refused() {
    let dir = TempDir::new().unwrap();
    let expect_failure = failure;
    let e = expect_failure(&dir, &["bench", "camera-triangles", "--csv", "f.csv"]);
    assert!(e.contains("--figure"), "{e}");
    let e = expect_failure(&dir, &["bench", "camera-triangles", "--figure", "5"]);
    assert!(e.contains("'5'"), "{e}");
    let e = expect_failure(
        &dir,
        &[
            "bench",
            "camera-triangles",
            "--figure",
            "6",
            "--width",
            "32",
            "--height",
            "24",
            "--scenes",
            "nowhere",
            "--csv",
            "f.csv",
        ],
    );
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    assert!(e.contains("camtri-convex.toml"), "{e}");
    assert!(!dir.path().join("f.csv").exists());
}
