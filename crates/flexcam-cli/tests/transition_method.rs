//! `flexcam render --shading transition-lit --transition-method METHOD` on the displaced
//! torus: each forced method shades every sample on the torus (the method weights of
//! `--stats`), the surface-only methods see the undisplaced hull (their ids and depths are
//! the same), and plain bump mapping differs from redistributed bump mapping only in colour.

mod common;

use std::path::Path;

use common::{ids, run_json};
use tempfile::TempDir;

const WEIGHTS: [&str; 3] = [
    "transition_brdf_weight",
    "transition_bump_weight",
    "transition_displacement_weight",
];

/// The torus example at 48 x 48 by `method`; its method weights (BRDF, bump, displacement).
fn render(dir: &TempDir, method: &str) -> [f64; 3] {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/displaced-torus.toml");
    let stats = run_json(
        dir,
        &[
            "render",
            scene.to_str().unwrap(),
            "--width",
            "48",
            "--height",
            "48",
            "--shading",
            "transition-lit",
            "--transition-method",
            method,
            "-o",
            &format!("{method}.png"),
            "--ids",
            &format!("{method}-ids.png"),
            "--depth",
            &format!("{method}.pfm"),
            "--stats",
            "-",
        ],
    );
    WEIGHTS.map(|k| {
        stats[k]
            .as_f64()
            .unwrap_or_else(|| panic!("{k} in {stats}"))
    })
}

#[test]
fn each_forced_method_shades_every_sample_on_the_torus() {
    let dir = TempDir::new().unwrap();
    let auto = render(&dir, "auto");
    let total: f64 = auto.iter().sum();
    assert!(total > 500.0, "the torus is seen: {auto:?}");
    for (method, k) in [
        ("brdf", 0),
        ("bump", 1),
        ("redistributed-bump", 1),
        ("displacement", 2),
    ] {
        let weights = render(&dir, method);
        assert_eq!(
            weights[k],
            weights.iter().sum::<f64>(),
            "{method}: {weights:?}"
        );
        assert!(weights[k] > 500.0, "{method}: {weights:?}");
    }
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    // The surface-only methods shade the hull: the same pixels, ids and depths.
    for name in ["ids.png", ".pfm"] {
        let sep = if name.starts_with('.') { "" } else { "-" };
        let of = |m: &str| read(&format!("{m}{sep}{name}"));
        assert_eq!(of("brdf"), of("bump"), "{name}");
        assert_eq!(of("bump"), of("redistributed-bump"), "{name}");
        assert_ne!(
            of("bump"),
            of("displacement"),
            "{name}: displacement moves the surface"
        );
    }
    // Redistribution changes the normals, so the colours, not what is seen.
    assert_ne!(read("bump.png"), read("redistributed-bump.png"));
    let (w, h, torus) = ids(&dir.path().join("bump-ids.png"));
    assert_eq!((w, h), (48, 48));
    assert!(torus.iter().any(|&id| id != 0));
}
