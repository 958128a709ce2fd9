use std::f64::consts::PI;
use std::path::Path;

use glam::{DVec2, DVec3, Vec3};

use super::photon_map::{
    light_camera, solid_angle, triangle_area, CausticTriangle, Photon, PhotonMap, PhotonSource,
};
use super::splat::splat;
use crate::projection::{Perspective, Projection, ProjectionSpec};
use crate::render::prepared::PreparedScene;
use crate::render::{Counter, Method, Outputs, RenderOptions, Shading, Stats};
use crate::scene::{self, Light, Mesh, Scene};

/// The two photon maps compared: through camera triangles, and exact.
pub(super) const SOURCES: [PhotonSource; 2] = [
    PhotonSource::Surface(Method::CameraTriangles),
    PhotonSource::Exact,
];

fn caustics_scene() -> Scene {
    scene::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/camtri-caustics.toml"
    ))
    .unwrap()
}

/// The scene's first point light: position and radiant intensity.
pub(super) fn point_light(scene: &Scene) -> (DVec3, Vec3) {
    scene
        .lights
        .iter()
        .find_map(|l| match *l {
            Light::Point {
                position,
                color,
                intensity,
            } => Some((position.as_dvec3(), color * intensity)),
            Light::Directional { .. } => None,
        })
        .unwrap()
}

pub(super) fn map_of(scene: &Scene, source: PhotonSource) -> PhotonMap {
    let prepared = PreparedScene::new(scene);
    let (light, _) = point_light(scene);
    PhotonMap::render(
        &prepared,
        &scene.caustics[0],
        light,
        source,
        &RenderOptions::default(),
    )
    .unwrap()
}

/// The scene's pinhole at `width` x `height`.
pub(super) fn eye(scene: &Scene, width: u32, height: u32) -> Perspective {
    let ProjectionSpec::Perspective { frame, fov } = &scene.projection else {
        panic!("not perspective")
    };
    Perspective::new(frame, *fov, width, height).unwrap()
}

/// The power `Σ E A` the caustic triangles of `scene`'s first caustic object carry (red
/// channel), the light tinted by `tint`, photons from `source`.
pub(super) fn caustic_power(scene: &Scene, source: PhotonSource, tint: Vec3) -> f64 {
    map_of(scene, source)
        .caustic_triangles(tint)
        .iter()
        .map(|t| f64::from(t.irradiance.x) * triangle_area(t.points))
        .sum()
}

/// The caustic irradiance splatted into the eye's view (`eye`, `width` x `height`), per
/// pixel, from each photon source of [`SOURCES`] in turn (the light tinted by the first
/// object's colour); both splat onto the exact main view's ids and depth.
pub(super) fn eye_irradiance(scene: &Scene, width: u32, height: u32) -> [Vec<Vec3>; 2] {
    let eye = eye(scene, width, height);
    let prepared = PreparedScene::new(scene);
    let options = RenderOptions {
        composite_reflectors: false,
        shading: Shading::Flat,
        outputs: Outputs::ALL,
        ..RenderOptions::default()
    };
    let main = Method::Raycast.render(&prepared, &eye, &options).unwrap().0;
    let (_, intensity) = point_light(scene);
    let tint = intensity * scene.objects[0].material.color;
    SOURCES.map(|source| {
        let triangles = map_of(scene, source).caustic_triangles(tint);
        let mut e = vec![Vec3::ZERO; main.color.len()];
        splat(&eye, &main.ids, &main.depth, &triangles, &mut e).unwrap();
        e
    })
}

/// A flat mirror focuses nothing: its caustic is the mirrored light's direct light,
/// `E = R I cos θ / d²` from the light mirrored in the mirror's plane (module doc). The
/// mirror (1 x 1, facing down at y = 2) over a floor at y = 0, the light at y = 1 between
/// them: every caustic triangle's irradiance is the closed form at its centroid, to the
/// second-order difference between a triangle's mean and its centroid's value.
#[test]
fn flat_mirror_gives_the_mirrored_light() {
    let text = r#"
        [projection]
        type = "perspective"
        position = [0.0, 1.0, 6.0]
        look_at = [0.0, 0.0, 0.0]
        fov = 60.0
        [[object]]
        name = "mirror"
        shape = "plane"
        size = [1.0, 1.0]
        material = "mirror"
        color = [0.8, 0.7, 0.6]
        rotate = [180.0, 0.0, 0.0]
        translate = [0.0, 2.0, 0.0]
        caustics = true
        caustic_map = 96
        [[object]]
        name = "floor"
        shape = "plane"
        size = [20.0, 20.0]
        [[light]]
        type = "point"
        position = [0.2, 1.0, 0.1]
        intensity = 2.0
    "#;
    let scene = scene::file::parse(text, Path::new("flat-mirror.toml")).unwrap();
    let mirrored = DVec3::new(0.2, 3.0, 0.1);
    let reflected = Vec3::new(0.8, 0.7, 0.6) * 2.0;
    for source in SOURCES {
        let triangles = map_of(&scene, source).caustic_triangles(reflected);
        // The mirror spans half the map's width (tan 0.5 of tan 45.5 degrees) each way: about
        // a quarter of its 95^2 squares, two triangles each.
        assert!(triangles.len() > 4000, "{source:?}: {}", triangles.len());
        let mut worst = 0.0f64;
        for t in &triangles {
            let c = (t.points[0] + t.points[1] + t.points[2]) / 3.0;
            assert!(c.y.abs() < 1e-5, "{source:?}: lands off the floor at {c}");
            let d = (c - mirrored).length();
            let closed = (mirrored.y - c.y) / d / (d * d);
            for channel in 0..3 {
                let want = f64::from(reflected[channel]) * closed;
                let got = f64::from(t.irradiance[channel]);
                worst = worst.max((got - want).abs() / want);
            }
        }
        assert!(worst < 2e-4, "{source:?}: relative error {worst}");
    }
}

/// The solid angle of an octant (three orthogonal axes) is a quarter of a hemisphere.
#[test]
fn solid_angle_of_an_octant() {
    let octant = solid_angle([DVec3::X, DVec3::Y, DVec3::Z]);
    assert!((octant - PI / 2.0).abs() < 1e-12, "{octant}");
    assert_eq!(solid_angle([DVec3::X, DVec3::Y, DVec3::X]), 0.0);
}

/// Energy: the light the caustic triangles carry to the receivers, `Σ E A`, is the power the
/// light sends into the mirror's solid angle times the reflectance, `I R Ω_mirror`, up to the
/// map triangles lost at the mirror's rim (a triangle needs all three texels on the mirror)
/// and at the ball's outline (its photons split between ball and floor). `Ω_mirror` is
/// computed independently, from the mirror's own triangles as seen from the light (all face
/// it; none hides another: the light lies inside the mirror's sphere).
#[test]
fn caustics_carry_the_light_the_mirror_reflects() {
    let scene = caustics_scene();
    let (light, intensity) = point_light(&scene);
    let mirror = &scene.objects[0];
    let mesh = &mirror.mesh;
    let mirror_angle: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            solid_angle(t.map(|i| (mesh.positions[i as usize].as_dvec3() - light).normalize()))
        })
        .sum();
    let reflected = intensity * mirror.material.color;
    for source in SOURCES {
        let power = caustic_power(&scene, source, reflected);
        let want = f64::from(reflected.x) * mirror_angle;
        let lost = 1.0 - power / want;
        eprintln!("{source:?}: power {power:.5}, I R Ω_mirror {want:.5}, lost {lost:.5}");
        // Measured: 1.0 % lost, by both maps.
        assert!((0.0..0.02).contains(&lost), "{source:?}: lost {lost}");
    }
}

/// The caustic through camera triangles against the exact one, in the eye's view (160 x 120,
/// photon maps of 128 texels; the exact main view's ids and depth for both): the relative
/// error `Σ |E - E_exact| / Σ E_exact` over the pixels either lights (the interpolated rays
/// of the mirror's 360 camera triangles against its exact reflection; a caustic magnifies
/// direction errors where it focuses).
#[test]
fn camera_triangle_caustic_matches_the_exact_one() {
    let mut scene = caustics_scene();
    scene.caustics[0].map_size = 128;
    let [ours, exact] = eye_irradiance(&scene, 160, 120);
    let (mut difference, mut total, mut lit) = (0.0, 0.0, 0);
    for (a, b) in ours.iter().zip(&exact) {
        if *a != Vec3::ZERO || *b != Vec3::ZERO {
            difference += f64::from((*a - *b).abs().element_sum());
            total += f64::from(b.element_sum());
            lit += 1;
        }
    }
    let error = difference / total;
    eprintln!("caustic: relative error {error:.4} over {lit} pixels");
    // Measured: 4.4 % over 466 pixels.
    assert!(lit > 300, "{lit} pixels lit");
    assert!(error < 0.06, "relative error {error}");
}

/// Degenerate map triangles carry no light: three photons on a line (zero area), or on two
/// objects; a texel without a photon leaves out both triangles that use it.
#[test]
fn degenerate_map_triangles_carry_no_light() {
    let mesh = Mesh {
        positions: vec![Vec3::new(-1.0, 2.0, -1.0), Vec3::new(1.0, 2.0, 1.0)],
        ..Mesh::default()
    };
    let camera = light_camera(DVec3::ZERO, &mesh, 3).unwrap();
    let photon = |x: f64, z: f64, id: u32| {
        Some(Photon {
            point: DVec3::new(x, 0.0, z),
            id,
            transmittance: 1.0,
        })
    };
    // Texel (x, y) at k = 3 y + x. The row y = 0 collinear with (0, 1); (2, 1) on object 2.
    let photons = vec![
        photon(0.0, 0.0, 1),
        photon(1.0, 0.0, 1),
        photon(2.0, 0.0, 1),
        photon(0.0, 0.0, 1),
        photon(1.0, 1.0, 1),
        photon(2.0, 1.0, 2),
        None,
        photon(1.0, 2.0, 1),
        photon(2.0, 2.0, 1),
    ];
    let map = PhotonMap {
        camera,
        size: 3,
        photons,
        counters: Stats::new(),
    };
    let triangles = map.caustic_triangles(Vec3::ONE);
    // Square (0, 0): first half (0,0) (1,0) (0,1) on a line; second (1,0) (1,1) (0,1) kept.
    // Square (1, 0): first half (1,0) (2,0) (1,1) kept; second touches (2, 1) on object 2.
    // Square (0, 1): both halves touch the empty texel (0, 2). Square (1, 1): the first
    // touches (2, 1), the second (2,1) (2,2) (1,2) too.
    assert_eq!(triangles.len(), 2, "{triangles:?}");
    let kept = triangles[0];
    assert_eq!(
        kept.points,
        [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::ZERO
        ]
    );
    assert_eq!(triangles[1].points[1], DVec3::new(2.0, 0.0, 0.0));
    let beam = solid_angle([(1, 0), (1, 1), (0, 1)].map(|(x, y)| {
        map.camera
            .ray(DVec2::new(x as f64 + 0.5, y as f64 + 0.5))
            .unwrap()
            .direction
    }));
    let want = beam / 0.5;
    assert!((f64::from(kept.irradiance.x) - want).abs() < 1e-6 * want);
}

/// A light inside the mirror's bounding sphere has no pinhole image framing the mirror: the
/// map refuses it with one line.
#[test]
fn a_light_inside_the_mirror_sphere_is_refused() {
    let mesh = Mesh {
        positions: vec![Vec3::new(-1.0, 2.0, -1.0), Vec3::new(1.0, 2.0, 1.0)],
        ..Mesh::default()
    };
    let error = light_camera(DVec3::new(0.0, 2.5, 0.0), &mesh, 16).unwrap_err();
    assert!(
        error
            .message
            .contains("inside the reflector's bounding sphere"),
        "{}",
        error.message
    );
    assert!(light_camera(DVec3::new(0.0, -2.0, 0.0), &mesh, 16).is_ok());
}

/// Splatting: a pixel centre on the edge two caustic triangles share takes the irradiance of
/// exactly one of them, and a pixel whose depth is not the triangle's (a nearer object of
/// the same id) takes none.
#[test]
fn splat_counts_a_shared_edge_once_and_tests_depth() {
    let text = r#"
        [image]
        width = 8
        height = 8
        [projection]
        type = "perspective"
        position = [0.0, 4.0, 0.0]
        look_at = [0.0, 0.0, 0.0]
        up = [0.0, 0.0, -1.0]
        fov = 90.0
        [[object]]
        shape = "plane"
        size = [20.0, 20.0]
    "#;
    let scene = scene::file::parse(text, Path::new("splat.toml")).unwrap();
    let eye = eye(&scene, 8, 8);
    // The square over the whole image at y = 0 (half-width 4 at distance 4), split along a
    // diagonal through pixel centres.
    let c =
        [(-4.0, -4.0), (4.0, -4.0), (4.0, 4.0), (-4.0, 4.0)].map(|(x, z)| DVec3::new(x, 0.0, z));
    let triangle = |points| CausticTriangle {
        points,
        id: 1,
        irradiance: Vec3::ONE,
    };
    let triangles = [triangle([c[0], c[1], c[2]]), triangle([c[0], c[2], c[3]])];
    let ids = vec![1; 64];
    let mut depth = vec![0.0f32; 64];
    for (k, d) in depth.iter_mut().enumerate() {
        let centre = DVec2::new((k % 8) as f64 + 0.5, (k / 8) as f64 + 0.5);
        let ray = eye.ray(centre).unwrap();
        *d = (4.0 / -ray.direction.y) as f32;
    }
    depth[9] *= 0.5;
    let mut e = vec![Vec3::ZERO; 64];
    splat(&eye, &ids, &depth, &triangles, &mut e).unwrap();
    for (k, v) in e.iter().enumerate() {
        let want = if k == 9 { 0.0 } else { 1.0 };
        assert_eq!(v.x, want, "pixel {k}");
    }
}

/// A map through camera triangles keeps its render's counters, reported as `caustic_*` with
/// the overdraw their ratio (Table 1's caustics row); the exact map renders nothing through
/// camera triangles and reports none.
#[test]
fn camera_triangle_maps_report_their_fragments() {
    let mut scene = caustics_scene();
    scene.caustics[0].map_size = 64;
    let prepared = PreparedScene::new(&scene);
    let projection = scene.projection.build(80, 60).unwrap();
    let counters = |method| {
        let options = RenderOptions {
            method,
            shading: Shading::Lit,
            ..RenderOptions::default()
        };
        crate::render::render(&prepared, projection.as_ref(), &options)
            .unwrap()
            .counters
    };
    let ours = counters(Method::CameraTriangles);
    let count = |name| match ours.get(name) {
        Some(Counter::Count(n)) => *n,
        other => panic!("{name}: {other:?}"),
    };
    assert!(count("caustic_camera_triangles") > 0, "{ours:?}");
    let (bounding, rendered) = (
        count("caustic_bounding_fragments"),
        count("caustic_rendered_fragments"),
    );
    assert!(rendered > 0 && bounding >= rendered, "{ours:?}");
    assert_eq!(
        ours.get("caustic_overdraw"),
        Some(&Counter::Value(bounding as f64 / rendered as f64))
    );
    let exact = counters(Method::Raycast);
    assert!(exact.contains_key("caustic_photons"), "{exact:?}");
    assert!(!exact.contains_key("caustic_camera_triangles"), "{exact:?}");
}
